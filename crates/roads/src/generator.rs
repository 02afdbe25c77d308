//! The generator: runs the road L-system ([`crate::modules`]) with an environment that
//! answers `?I` through [`LocalConstraints`] and grows the planar [`RoadNetwork`].

use std::sync::Arc;

use polis_geom::GeomError;
use polis_geom::graph::{InsertHints, SnapOptions};
use polis_geom::spatial::GridOptions;
use polis_lsystem::{Derivation, DeriveOptions, Environment, TurtleState, TypedRules};
use serde::{Deserialize, Serialize};

use crate::constraints::{ConstraintStats, DefaultConstraints, LocalConstraints};
use crate::error::{Result, RoadError};
use crate::feedback::PopulationFeedback;
use crate::goals::{DefaultGoals, GlobalGoals};
use crate::inputs::RoadInputs;
use crate::modules::{QueryState, RoadModule, road_rules};
use crate::network::{Junction, Road, RoadClass, RoadNetwork};
use crate::params::RoadParams;
use crate::smooth::smooth_highways;

/// Snap distance of the planar insertion itself: only rounding-level coincidences (the
/// meaningful snapping is done by the local constraints with the snap radius).
pub const INSERT_SNAP_M: f64 = 1e-3;

/// Cell size of the network's spatial indexes, a bit over a street segment and about half
/// a highway one. On the 15,000-segment benchmark 128 m cells ran fastest of 48, 64, 96
/// and 128 m (fewer instructions than the 64 m default, ~10 % less time, less memory).
/// A speed knob only: answers do not depend on it.
pub const INDEX_CELL_M: f64 = 128.0;

/// Why the growth stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum StopReason {
    /// [`RoadParams::max_segments`] segments were accepted.
    SegmentBudget,
    /// [`RoadParams::max_steps`] derivation steps were done.
    StepBudget,
    /// The string emptied: no road end can grow any more.
    #[default]
    NothingLeft,
}

/// What a generator run did.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct GrowthReport {
    /// Derivation steps done.
    pub steps: usize,
    /// Segments accepted (`?I` answered SUCCEED).
    pub segments: usize,
    /// Why the growth stopped.
    pub stop: StopReason,
    /// Longest module string seen.
    pub peak_string_len: usize,
    /// The local constraints' counters.
    pub constraints: ConstraintStats,
    /// Highway corners cut by smoothing.
    pub smoothed_corners: usize,
}

/// A generated network with its report.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The planar road graph.
    pub network: RoadNetwork,
    /// What happened.
    pub report: GrowthReport,
}

/// The environment of the open L-system: p8 (`?I` unassigned → localConstraints) and
/// the insertion of accepted segments into the graph.
struct RoadEnv<'a> {
    graph: &'a mut RoadNetwork,
    constraints: &'a mut dyn LocalConstraints,
    params: &'a RoadParams,
    feedback: Option<&'a PopulationFeedback>,
    step: u32,
    segments: usize,
    error: Option<RoadError>,
}

impl Environment<Vec<RoadModule>> for RoadEnv<'_> {
    fn begin_pass(&mut self, step: usize) {
        self.step = u32::try_from(step).unwrap_or(u32::MAX);
    }

    fn communicate(&mut self, s: &mut Vec<RoadModule>, i: usize, _turtle: &TurtleState) {
        let Some(RoadModule::I { road, state }) = s.get(i).copied() else {
            return;
        };
        if state != QueryState::Unassigned {
            return;
        }
        // p7 deletes a query whose road was stopped by the global goals: never answer it.
        if i > 0 && matches!(s.get(i - 1), Some(RoadModule::R { del, .. }) if *del < 0) {
            return;
        }
        let mut road = road;
        let new_state = if self.segments >= self.params.max_segments || self.error.is_some() {
            QueryState::Failed
        } else {
            match self.constraints.adjust(&mut road, self.graph) {
                QueryState::Succeed => self.insert(&mut road),
                _ => QueryState::Failed,
            }
        };
        if let Some(m) = s.get_mut(i) {
            *m = RoadModule::I {
                road,
                state: new_state,
            };
        }
    }
}

impl RoadEnv<'_> {
    fn insert(&mut self, road: &mut crate::modules::RoadAttr) -> QueryState {
        let payload = Road {
            class: road.class,
            width: match road.class {
                RoadClass::Highway => self.params.highway_width_m,
                RoadClass::Street => self.params.street_width_m,
            },
            bridge: road.bridge,
            tunnel: road.tunnel,
            step: self.step,
        };
        let step = self.step;
        let opts = SnapOptions {
            snap_distance: INSERT_SNAP_M,
        };
        // The constraints found the start junction already: the insertion checks it
        // instead of searching again.
        let hints = InsertHints {
            start: self.constraints.start_node(),
        };
        match self
            .graph
            .insert_segment_hinted(road.start, road.end, payload, &opts, &hints, |_| Junction {
                step,
            }) {
            Ok(ins) => {
                self.segments += 1;
                if let Some(p) = ins.nodes.last().and_then(|&n| self.graph.position(n).ok()) {
                    road.end = p;
                }
                if road.class == RoadClass::Street
                    && let Some(f) = self.feedback
                {
                    f.use_up(road.end);
                }
                QueryState::Succeed
            }
            Err(
                GeomError::ZeroLengthEdge { .. }
                | GeomError::NonFinite { .. }
                | GeomError::OutOfRange { .. },
            ) => QueryState::Failed,
            Err(e) => {
                self.error = Some(RoadError::Geometry(e));
                QueryState::Failed
            }
        }
    }
}

/// The Parish & Müller road generator: an extended open L-system whose parameters come
/// from [`GlobalGoals`] and are corrected by [`LocalConstraints`].
pub struct RoadGenerator {
    params: RoadParams,
    goals: Arc<dyn GlobalGoals>,
    constraints: Box<dyn LocalConstraints>,
    inputs: RoadInputs,
    feedback: Option<Arc<PopulationFeedback>>,
}

impl std::fmt::Debug for RoadGenerator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RoadGenerator")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl RoadGenerator {
    /// A generator with [`DefaultGoals`] and [`DefaultConstraints`].
    ///
    /// # Errors
    /// [`RoadError::InvalidParameter`] or [`RoadError::NoLegalStart`].
    pub fn new(params: &RoadParams, inputs: &RoadInputs) -> Result<Self> {
        params.validate()?;
        // With population feedback (§3.2.1) the goals read the population the street
        // ends lower; the map itself is never changed.
        let feedback = PopulationFeedback::new(inputs.population.clone(), params).map(Arc::new);
        let mut fed = inputs.clone();
        if let Some(f) = &feedback {
            fed.population = f.clone();
        }
        Ok(RoadGenerator {
            params: params.clone(),
            goals: Arc::new(DefaultGoals::new(params, &fed)?),
            constraints: Box::new(DefaultConstraints::new(params, &fed)),
            inputs: fed,
            feedback,
        })
    }

    /// Replaces the global goals.
    pub fn with_goals(mut self, goals: Arc<dyn GlobalGoals>) -> Self {
        self.goals = goals;
        self
    }

    /// Replaces the local constraints.
    pub fn with_constraints(mut self, constraints: Box<dyn LocalConstraints>) -> Self {
        self.constraints = constraints;
        self
    }

    /// The rules p1–p9 with this generator's goals.
    ///
    /// # Errors
    /// Only if the L-system engine refused a production.
    pub fn rules(&self) -> Result<TypedRules<'static, RoadModule>> {
        road_rules(self.goals.clone())
    }

    /// Grows the network until a stop condition holds (segment budget, step budget, or
    /// nothing left to grow), then smooths highways if asked.
    ///
    /// # Errors
    /// [`RoadError::Geometry`] if planar insertion failed internally,
    /// [`RoadError::Lsystem`] if a growth guard of the engine fired.
    pub fn run(&mut self) -> Result<Generated> {
        let rules = self.rules()?;
        let axiom: Vec<RoadModule> = self
            .goals
            .axiom()
            .into_iter()
            .flat_map(|(rule, road)| {
                [
                    RoadModule::R { del: 0, rule },
                    RoadModule::I {
                        road,
                        state: QueryState::Unassigned,
                    },
                ]
            })
            .collect();
        let mut derivation = Derivation::new(
            rules,
            axiom,
            DeriveOptions {
                seed: self.params.seed,
                max_steps: self.params.max_steps.saturating_add(1),
                ..DeriveOptions::default()
            },
        );
        let mut graph = RoadNetwork::with_index_options(GridOptions {
            cell_size: INDEX_CELL_M,
        })?;
        let mut report = GrowthReport::default();
        let mut env = RoadEnv {
            graph: &mut graph,
            constraints: self.constraints.as_mut(),
            params: &self.params,
            feedback: self.feedback.as_deref(),
            step: 0,
            segments: 0,
            error: None,
        };
        loop {
            if env.segments >= self.params.max_segments {
                report.stop = StopReason::SegmentBudget;
                break;
            }
            if derivation.steps_done() >= self.params.max_steps {
                report.stop = StopReason::StepBudget;
                break;
            }
            if derivation.string().is_empty() {
                report.stop = StopReason::NothingLeft;
                break;
            }
            let r = derivation.step_with(&mut env)?;
            report.peak_string_len = report.peak_string_len.max(r.len);
            if let Some(e) = env.error.take() {
                return Err(e);
            }
        }
        report.steps = derivation.steps_done();
        report.segments = env.segments;
        report.constraints = env.constraints.stats();
        if self.params.smooth_highways {
            report.smoothed_corners = smooth_highways(&mut graph, &self.params, &self.inputs)?;
        }
        Ok(Generated {
            network: graph,
            report,
        })
    }
}

/// One call: grow a network for `params` over `inputs` with the default goals and
/// constraints.
///
/// # Errors
/// See [`RoadGenerator::new`] and [`RoadGenerator::run`].
pub fn generate(params: &RoadParams, inputs: &RoadInputs) -> Result<Generated> {
    RoadGenerator::new(params, inputs)?.run()
}

/// One call with the procedural default maps ([`RoadInputs::procedural`], seeded by
/// `params.seed`): runs with no files.
///
/// # Errors
/// See [`generate`].
pub fn generate_default(params: &RoadParams) -> Result<Generated> {
    let inputs = RoadInputs::procedural(params.seed, params)?;
    generate(params, &inputs)
}
