//! Kelly's secondary road growth (§4.3.2, Fig. 42) inside one city cell.

use std::collections::VecDeque;

use polis_geom::graph::SnapOptions;
use polis_geom::hash::splitmix64;
use polis_geom::{DVec2, EdgeId, NodeId, PointLocation, PolygonWithHoles};
use rand::{Rng, RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use super::bend;
use super::cell::{CellMaps, SecondaryCell};
use super::error::SecondaryError;
use super::grid::GridRoad;
use super::join::{self, Join};
use super::params::{BuildingHint, Deviated, SecondaryParams};
use super::snap::{SnapEvent, Snapper};
use crate::network::{Junction, Road, RoadClass, RoadNetwork};

/// What one cell's growth did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct CellGrowthReport {
    /// Nodes taken from the queue (growth steps).
    pub steps: u32,
    /// Segments proposed (`placeSegment` calls).
    pub proposals: u32,
    /// Segments placed with no snap event (a new node).
    pub placed_free: u32,
    /// Segments joined to a road (road snap or crossing: the road is split).
    pub placed_road: u32,
    /// Segments joined to an existing node.
    pub placed_node: u32,
    /// Proposals dropped by the connectivity draw.
    pub refused_connectivity: u32,
    /// Proposals dropped because they folded onto a road at their root, or were blocked
    /// by a road after snapping.
    pub refused_blocked: u32,
    /// Proposals dropped because they left the cell.
    pub refused_outside: u32,
    /// Proposals dropped because they ran into water or a park.
    pub refused_map: u32,
    /// Proposals dropped because they would meet a road at their root or where they
    /// join at a sharper angle than [`SecondaryParams::min_angle_deg`].
    pub refused_angle: u32,
    /// Whether growth stopped at the step limit or the segment guard, not on an empty
    /// queue.
    pub stopped_early: bool,
}

/// Kelly keeps these per cell for the lot and building stages (§5.5.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CellTraits {
    /// Lot width and its deviance, metres.
    pub lot_size_m: Deviated,
    /// Building height and its deviance, metres.
    pub building_height_m: Deviated,
    /// The building hint.
    pub building_hint: BuildingHint,
}

/// One cell's secondary roads.
#[derive(Debug, Clone)]
pub struct SecondaryRoads {
    /// The cell's id.
    pub cell: u64,
    /// The cell's private graph: the boundary rings and filaments as
    /// [`RoadClass::Highway`] edges (split where secondary roads join them) and the
    /// secondary roads as [`RoadClass::Street`] edges. Planar.
    pub network: RoadNetwork,
    /// What the growth did.
    pub report: CellGrowthReport,
    /// Lot and building parameters of the cell.
    pub traits: CellTraits,
}

impl SecondaryRoads {
    /// The secondary roads (street edges) as segments, in edge-id order.
    pub fn segments(&self) -> impl Iterator<Item = (DVec2, DVec2, &Road)> + '_ {
        self.network.edges().filter_map(|(e, _, _, r)| {
            if r.class != RoadClass::Street {
                return None;
            }
            let (a, b) = self.network.segment(e).ok()?;
            Some((a, b, r))
        })
    }
}

/// Kelly's secondary road growth: a reusable worker holding one parameter set and the
/// snap algorithm's scratch.
///
/// # Algorithm (Fig. 42)
///
/// 1. The `start_sides` longest boundary sides (of any ring) are split at a *deviated
///    midpoint* and grow a first segment along their *deviated* inward perpendicular.
///    When no side can place its first segment (a small cell), the sides are tried
///    again, up to [`START_RETRIES`] rounds, with fresh draws (ours: Kelly tries once).
/// 2. A FIFO queue of `(node, direction)`; each node taken tries `degree` directions,
///    the incoming one turned by `i · 360° / degree` and deviated.
/// 3. `placeSegment` draws a deviated length (with the block aspect), asks the
///    [snap algorithm](super::snap) and acts on its single event: none → a new node
///    (queued); road → with probability *connectivity*, split the road and join it;
///    node → with probability *connectivity*, join the node; otherwise the proposal is
///    dropped, the road stops short of what it met, and a node whose every direction
///    stops is a cul-de-sac. Joined nodes are queued too, as in Kelly's pseudo-code.
///    With [`min_angle_deg`](SecondaryParams::min_angle_deg) above 0 (ours), a
///    proposal that would meet a road at a sharper angle at either end is dropped.
///
/// # Guarantees
///
/// * The cell's graph stays planar (every road goes in after the exact checks below: a
///   free end or a joined node as it is, a join onto a road as the split and the edge
///   that [`PlanarGraph::insert_segment`](polis_geom::PlanarGraph::insert_segment)
///   would make — checked by the insertion's rules, and left to the insertion itself
///   where one of them could do more) and every secondary road lies inside the cell
///   region: a
///   proposal that touches or crosses anything other than its own two ends, or whose
///   midpoint is not strictly inside the region (exact point location), is dropped.
/// * Every secondary road is connected to the boundary: growth starts from boundary
///   nodes and only ever extends from nodes already connected.
/// * No secondary road has a sample (every [`CellMaps::step_m`]) in water or a park.
/// * Deterministic: the result depends only on the parameters, the cell (its id
///   sub-seeds the generator), the maps and the seed.
///
/// # Limitations
///
/// * Growth stops at `max_steps`, or at a guard of `16 · area / segment² + 64` segments
///   that only pathological parameters reach (reported as `stopped_early`).
/// * The direction deviation is taken from the degree deviance; Kelly does not say which
///   deviance turns the directions.
/// * The connectivity draw is made once per expanded node and road or junction met
///   (Kelly's pseudo-code draws per proposal). With Suburbia's degree 18 a frontier node
///   aims about ten directions at its neighbours, and per-proposal draws at 0.05 joined
///   about a third of them: 15 % dead ends on the test cells where Kelly describes
///   "almost all roads terminating at dead ends" (37 % now; Charlotte 29 %).
///
/// # References
///
/// G. Kelly, *An Interactive System for Procedural City Generation*, 2008: §4.3.2
/// (Fig. 42), §4.3.3, §5.5.1 (Fig. 76), §6.3.
#[derive(Debug, Clone)]
pub struct SecondaryGrowth {
    params: SecondaryParams,
    snapper: Snapper,
    buffers: Buffers,
    joins: (u64, u64),
}

/// The growth's own buffers, kept between cells so that a worker that grows many cells
/// (one per thread of a pool) allocates them once.
#[derive(Debug, Clone, Default)]
struct Buffers {
    /// Scratch of [`join::plan`].
    scratch: Vec<GridRoad>,
    /// The FIFO queue of Fig. 42: `(node, incoming direction)`.
    queue: VecDeque<(NodeId, DVec2)>,
    /// By node id: whether the node has branched.
    expanded: Vec<bool>,
    /// The connectivity decisions of the node being expanded, per road or junction met.
    decided: Vec<(JoinKey, bool)>,
    /// The roads of the node read last as (unit direction, length), for
    /// [`Run::folds_for_sure`].
    root_roads: Vec<(DVec2, f64)>,
    /// The far end (node and position) of every road at that node, for the snap search.
    root_ends: Vec<(NodeId, DVec2)>,
}

impl Buffers {
    /// Notes the road from the node read (at `a`) to node `n` at `p` in `root_ends` and,
    /// unless it has no length, in `root_roads`.
    #[inline]
    fn add_root_road(&mut self, a: DVec2, n: NodeId, p: DVec2) {
        self.root_ends.push((n, p));
        let ap = p - a;
        let len = ap.length();
        if len > 0.0 {
            self.root_roads.push((ap / len, len));
        }
    }
}

/// Planar insertion's snap distance, relative to the segment size: ends and nodes closer
/// than this are merged, so no road shorter than it is ever made (1 mm per metre of
/// segment size, at least 1 mm).
pub const INSERT_TOLERANCE: f64 = 1e-3;

/// More rounds over the start sides when none could start a first segment (see
/// [`SecondaryGrowth::grow`]).
pub const START_RETRIES: u32 = 8;

/// Mixed into the seed of the bows' generator ([`SecondaryParams::bow`]).
const BOW_STREAM: u64 = 0x626f_775f_7374_7265;

/// A placed segment's end, for the queue.
struct Placed {
    node: NodeId,
}

/// Where the proposal will end.
enum Target {
    Free(DVec2),
    Node(NodeId),
    OnEdge(EdgeId, DVec2),
}

impl SecondaryGrowth {
    /// A worker for `params`.
    ///
    /// # Errors
    /// [`SecondaryError::InvalidParameter`] from [`SecondaryParams::validate`].
    pub fn new(params: SecondaryParams) -> Result<Self, SecondaryError> {
        params.validate()?;
        Ok(SecondaryGrowth {
            params,
            snapper: Snapper::default(),
            buffers: Buffers::default(),
            joins: (0, 0),
        })
    }

    /// Takes `params` for the next growths, keeping the worker's buffers (a pool thread
    /// that grows cells of several neighbourhoods keeps one worker).
    ///
    /// # Errors
    /// [`SecondaryError::InvalidParameter`] from [`SecondaryParams::validate`]; the
    /// worker's parameters are then unchanged.
    pub fn set_params(&mut self, params: SecondaryParams) -> Result<(), SecondaryError> {
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// The parameters.
    pub fn params(&self) -> &SecondaryParams {
        &self.params
    }

    /// Exact segment-intersection tests run so far and roads that passed the extended
    /// bounding box (Kelly's measure of the `r`/`s` optimisation).
    pub fn snap_counters(&self) -> (u64, u64) {
        (self.snapper.exact_tests, self.snapper.box_hits)
    }

    /// Joins onto a road so far: made directly (a split and an edge) and left to planar
    /// insertion (see [`SecondaryGrowth::grow`]'s guarantees).
    pub fn join_counters(&self) -> (u64, u64) {
        self.joins
    }

    /// Grows the secondary roads of `cell`. `seed` is mixed with the cell's id.
    ///
    /// # Errors
    /// [`SecondaryError::InvalidCell`] for an invalid region,
    /// [`SecondaryError::CellTooSmall`] when no boundary side can start a segment (both
    /// are [`is_skip`](SecondaryError::is_skip)); [`SecondaryError::Geometry`] on an
    /// internal failure.
    pub fn grow(
        &mut self,
        cell: &SecondaryCell,
        maps: &CellMaps<'_>,
        seed: u64,
    ) -> Result<SecondaryRoads, SecondaryError> {
        let mut region = cell.region.clone();
        region
            .validate()
            .map_err(|source| SecondaryError::InvalidCell {
                cell: cell.id,
                source,
            })?;
        region.normalize();
        let p = self.params.clone();
        let mut rng = Pcg64Mcg::seed_from_u64(splitmix64(seed ^ splitmix64(cell.id)));
        let mut g = RoadNetwork::new();
        let primary = Road {
            class: RoadClass::Highway,
            width: 0.0,
            bridge: false,
            tunnel: false,
            step: 0,
        };
        // The boundary rings, and their sides with inward normals.
        let mut sides: Vec<(f64, usize, EdgeId, DVec2)> = Vec::new();
        for (_, ring) in region.rings() {
            let pts = ring.points();
            let ids = pts
                .iter()
                .map(|&q| g.add_node(q, Junction::default()))
                .collect::<Result<Vec<_>, _>>()?;
            for i in 0..ids.len() {
                let j = (i + 1) % ids.len();
                let (Some(&u), Some(&v)) = (ids.get(i), ids.get(j)) else {
                    continue;
                };
                let e = g.add_edge(u, v, primary)?;
                let (pu, pv) = (g.position(u)?, g.position(v)?);
                let d = pv - pu;
                sides.push((d.length(), sides.len(), e, d.perp().normalize_or_zero()));
            }
        }
        for f in &cell.filaments {
            // A filament that coincides with a boundary piece is already there.
            match g.insert_segment_with(f[0], f[1], primary, &SnapOptions::default(), |_| {
                Junction::default()
            }) {
                Ok(_) | Err(polis_geom::GeomError::ZeroLengthEdge { .. }) => {}
                Err(e) => return Err(e.into()),
            }
        }
        // Growth asks the graph no spatial question (the snap grid below answers them):
        // the graph's own spatial index, which the filaments' insertion built, is freed
        // and not kept up to date on every change.
        g.release_spatial_index();
        // The snap search's flat grid over the cell, in squares of the segment size plus
        // twice the snap size: about the extent of a proposal's extended box, so that a
        // search walks two squares or so each way (squares of the segment size alone
        // made it walk three or four, and cost 5 % more time; the roads found are the
        // same, as the grid's cover is conservative at any square size).
        let square = p.segment_size_m.value.max(1.0) + 2.0 * p.snap_size_m.value.max(0.0);
        self.snapper.begin_cell(g.bbox(), square);
        let area = region.area();
        let seg_min =
            (p.segment_size_m.value * (1.0 - p.segment_size_m.deviance) * p.aspect.min(1.0))
                .max(1e-3);
        let guard = (16.0 * area / (seg_min * seg_min) + 64.0).min(4.0e6) as u32;
        // The main axis for the aspect: the longest side.
        sides.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        let axis = sides
            .first()
            .and_then(|s| g.segment(s.2).ok())
            .map_or(DVec2::X, |(a, b)| (b - a).normalize_or(DVec2::X));
        let snap_max = p.snap_size_m.value * (1.0 + p.snap_size_m.deviance);
        let long_enough = |len: f64| len > 2.0 * snap_max && len > 1e-6;
        if !sides.iter().any(|s| long_enough(s.0)) {
            return Err(SecondaryError::CellTooSmall {
                cell: cell.id,
                reason: format!(
                    "the longest side is {:.2} m, not more than twice the snap size ({:.2} m)",
                    sides.first().map_or(0.0, |s| s.0),
                    snap_max
                ),
            });
        }
        let mut run = Run {
            p: &p,
            g,
            region: &region,
            maps,
            rng: &mut rng,
            snapper: &mut self.snapper,
            axis,
            report: CellGrowthReport::default(),
            edges: 0,
            guard,
            tolerance: (p.segment_size_m.value * INSERT_TOLERANCE).max(1e-3),
            buffers: std::mem::take(&mut self.buffers),
            root: (None, (0, 0)),
            joins: (0, 0),
        };
        run.buffers.decided.clear();
        run.buffers.root_roads.clear();
        run.buffers.root_ends.clear();
        let mut queue = std::mem::take(&mut run.buffers.queue);
        queue.clear();
        let mut expanded = std::mem::take(&mut run.buffers.expanded);
        expanded.clear();
        // Initial segments from deviated midpoints of the longest sides: the first
        // `start_sides` sides, longest first, whose first segment can be placed.
        let mut started = 0;
        // Kelly tries each of the longest sides once. In a small cell (sides a few snap
        // sizes long) every first segment may end within the snap size of the side it
        // leaves or of a neighbouring side and be refused, and the cell would grow
        // nothing: only then are the sides tried again, up to `START_RETRIES` more rounds
        // with fresh draws. A cell that starts in the first round draws exactly as
        // Kelly's algorithm does.
        for round in 0..=START_RETRIES {
            if round > 0 && started > 0 {
                break;
            }
            for side in 0..sides.len() {
                let Some(&(len, _, e, inward)) = sides.get(side) else {
                    break;
                };
                if started >= p.start_sides || !long_enough(len) {
                    break;
                }
                let (a, b) = run.g.segment(e)?;
                let u: f64 = run.rng.random::<f64>();
                let t = 0.5 + p.segment_size_m.deviance * (u - 0.5);
                let t = t.clamp(snap_max / len, 1.0 - snap_max / len);
                let mid = a.lerp(b, t);
                run.buffers.decided.clear();
                // The perpendicular deviates by up to ± degree deviance × 45°.
                let dir = run.deviate(inward, std::f64::consts::FRAC_PI_2);
                // Split the side only if the first segment fits.
                let Ok((source, piece)) = run.g.split_edge(e, mid, Junction::default()) else {
                    continue;
                };
                run.snapper.touched(&run.g, e);
                if let Some(placed) = run.place_segment(source, dir)? {
                    queue.push_back((placed.node, dir));
                    started += 1;
                } else {
                    // Undo the split: the side stays one road (a new edge id).
                    let far = run.g.other_end(piece, source)?;
                    let near = run.g.other_end(e, source)?;
                    run.g.remove_node(source)?;
                    run.snapper.touched(&run.g, e);
                    run.snapper.touched(&run.g, piece);
                    let whole = run.g.add_edge(near, far, primary)?;
                    if let Some(s) = sides.get_mut(side) {
                        s.2 = whole;
                    }
                }
            }
        }
        // Road growth.
        let mut turns: Vec<Turn> = Vec::new();
        while let Some((source, dir)) = queue.pop_front() {
            if p.max_steps.is_some_and(|m| run.report.steps >= m)
                || run.edges >= run.guard
                || run.report.steps >= run.guard.saturating_mul(4)
            {
                run.report.stopped_early = true;
                break;
            }
            // Each node branches once: a node queued again (a join onto a node that has
            // grown already) is passed over.
            if let Some(seen) = expanded.get_mut(source.index()) {
                if *seen {
                    continue;
                }
                *seen = true;
            } else {
                expanded.resize(source.index() + 1, false);
                if let Some(seen) = expanded.get_mut(source.index()) {
                    *seen = true;
                }
            }
            run.report.steps += 1;
            let du: f64 = run.rng.random::<f64>();
            let degree = ((p.degree as f64) * (1.0 + p.degree_deviance * (2.0 * du - 1.0)))
                .round()
                .max(1.0) as u32;
            run.buffers.decided.clear();
            // Direction i is `dir` turned by i steps: one rotation applied i times. The
            // step, its rotation and its fold bound depend on the degree alone, so they
            // are computed once per degree drawn in this cell.
            let turn = match turns.iter().find(|t| t.degree == degree) {
                Some(t) => *t,
                None => {
                    let t = Turn::new(&p, degree);
                    turns.push(t);
                    t
                }
            };
            let (step, sin, cos, certain) = (turn.step, turn.sin, turn.cos, turn.certain);
            let mut turned = dir;
            for _ in 0..degree {
                // A direction that folds onto a road at the node whatever its draws is
                // refused without them (test 0's answer; the generator steps past them).
                let folds = match &certain {
                    Some(bound) => run.folds_for_sure(source, turned, bound)?,
                    None => false,
                };
                let new_dir = if folds {
                    run.skip_fold();
                    None
                } else {
                    Some(run.deviate(turned, step))
                };
                turned = DVec2::new(
                    turned.x * cos - turned.y * sin,
                    turned.x * sin + turned.y * cos,
                );
                if let Some(new_dir) = new_dir
                    && let Some(placed) = run.place_segment(source, new_dir)?
                {
                    queue.push_back((placed.node, new_dir));
                }
            }
        }
        // Streets bowed between their ends (ours; off at a bow of 0), from a generator
        // of their own so that the growth above draws as it does without them.
        if p.bow.value > 0.0 {
            let mut bow_rng =
                Pcg64Mcg::seed_from_u64(splitmix64(seed ^ splitmix64(cell.id) ^ BOW_STREAM));
            bend::bow_streets(&mut run.g, &p, maps, &mut bow_rng)?;
            run.g.release_spatial_index();
        }
        let report = run.report;
        self.joins.0 += run.joins.0;
        self.joins.1 += run.joins.1;
        self.buffers = run.buffers;
        self.buffers.queue = queue;
        self.buffers.expanded = expanded;
        let network = run.g;
        Ok(SecondaryRoads {
            cell: cell.id,
            network,
            report,
            traits: CellTraits {
                lot_size_m: p.lot_size_m,
                building_height_m: p.building_height_m,
                building_hint: p.building_hint,
            },
        })
    }
}

/// An estimate of the work of growing a cell of `area_m2` square metres with `params`:
/// the segments of the mean size that would tile it (`area / size²`). Only for
/// scheduling cells on a thread pool, largest first: it is deterministic (the inputs
/// alone), never the cells' measured times, and the grown roads do not depend on it.
pub fn estimated_work(params: &SecondaryParams, area_m2: f64) -> f64 {
    let size = params.segment_size_m.value.max(1e-3);
    let work = area_m2 / (size * size);
    if work.is_finite() { work.max(0.0) } else { 0.0 }
}

/// Grows the secondary roads of one cell with `params` (the one-call form of
/// [`SecondaryGrowth`]).
///
/// # Errors
/// As [`SecondaryGrowth::new`] and [`SecondaryGrowth::grow`].
pub fn grow_cell(
    params: &SecondaryParams,
    cell: &SecondaryCell,
    maps: &CellMaps<'_>,
    seed: u64,
) -> Result<SecondaryRoads, SecondaryError> {
    SecondaryGrowth::new(params.clone())?.grow(cell, maps, seed)
}

/// The turn between the directions of a node of one degree: the step (radians), its
/// sine and cosine, and the fold bound of its directions.
#[derive(Clone, Copy)]
struct Turn {
    degree: u32,
    step: f64,
    sin: f64,
    cos: f64,
    certain: Option<FoldBound>,
}

impl Turn {
    fn new(p: &SecondaryParams, degree: u32) -> Turn {
        let step = std::f64::consts::TAU / f64::from(degree);
        let (sin, cos) = step.sin_cos();
        Turn {
            degree,
            step,
            sin,
            cos,
            certain: FoldBound::new(p, step),
        }
    }
}

/// `v` turned by `angle` radians (counter-clockwise).
///
/// The deviations of growth's directions are small angles (at most the degree deviance
/// times half the step: 45° at the most for the start segments and for every degree of
/// 4 or more), so up to 45° the sine and cosine are their Taylor polynomials to the 15th
/// and 16th power (the first term left out is under 5·10⁻¹⁷, below half an ulp of
/// either there; the results are within a few ulps of the exact values), evaluated by
/// Horner's rule without fused multiply-adds: the same bits on every machine (libm
/// picks its `sin_cos` by the processor), in fewer instructions than libm's call.
/// Larger angles take `sin_cos`.
fn rotate(v: DVec2, angle: f64) -> DVec2 {
    let (s, c) = if angle.abs() <= std::f64::consts::FRAC_PI_4 {
        small_sin_cos(angle)
    } else {
        angle.sin_cos()
    };
    DVec2::new(v.x * c - v.y * s, v.x * s + v.y * c)
}

/// The sine and cosine of `x` (|x| ≤ π/4) by their Taylor polynomials (see [`rotate`]).
#[inline]
fn small_sin_cos(x: f64) -> (f64, f64) {
    // 1/n! with the Taylor series' signs, rounded once each at compile time.
    const S: [f64; 7] = [
        -1.0 / 6.0,
        1.0 / 120.0,
        -1.0 / 5_040.0,
        1.0 / 362_880.0,
        -1.0 / 39_916_800.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 1_307_674_368_000.0,
    ];
    const C: [f64; 8] = [
        -1.0 / 2.0,
        1.0 / 24.0,
        -1.0 / 720.0,
        1.0 / 40_320.0,
        -1.0 / 3_628_800.0,
        1.0 / 479_001_600.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 20_922_789_888_000.0,
    ];
    let x2 = x * x;
    let s = S.iter().rev().fold(0.0, |acc, &k| acc * x2 + k);
    let c = C.iter().rev().fold(0.0, |acc, &k| acc * x2 + k);
    (x + x * (x2 * s), 1.0 + x2 * c)
}

/// What every proposal of one expanded node can be, for test 0 before the draws: the
/// longest segment (the deviated size at its largest, on the aspect ellipse), the
/// smallest snap size, and the widest deviation of a direction, each widened by a
/// relative margin of 10⁻⁹ (far above the rounding of the test's arithmetic).
///
/// A proposal in direction `d` (unit) and of length `l` from node `a` folds onto the
/// node's road `a–p` (test 0, [`snap`](super::snap)) when the angle `θ` between `d` and
/// `p − a` is below 90° and `min(l, |p − a|) · sin θ` is at most the snap size: shorter
/// than the road, its end is within `l · sin θ` of it; longer, `p` is within
/// `|p − a| · sin θ` of the segment, before its end. With `|θ|` at most the angle of the
/// undeviated direction plus the widest deviation, this holds for every draw when it
/// holds for the bounds.
#[derive(Clone, Copy)]
struct FoldBound {
    len_max: f64,
    radius_min: f64,
    sin_dev: f64,
    cos_dev: f64,
}

impl FoldBound {
    /// The bounds for a node whose directions are `step` radians apart, or `None` when
    /// a draw could give a zero-length segment or snap size (no proposal is certain).
    fn new(p: &SecondaryParams, step: f64) -> Option<FoldBound> {
        const MARGIN: f64 = 1e-9;
        let size = p.segment_size_m;
        let len_min = size.value * (1.0 - size.deviance) * p.aspect.min(1.0);
        let len_max = size.value * (1.0 + size.deviance) * p.aspect.max(1.0) * (1.0 + MARGIN);
        let radius_min = p.snap_size_m.value * (1.0 - p.snap_size_m.deviance) * (1.0 - MARGIN);
        let dev = p.degree_deviance * 0.5 * step * (1.0 + MARGIN) + MARGIN;
        let ok = len_min > 0.0
            && len_max.is_finite()
            && radius_min > 0.0
            && dev < std::f64::consts::FRAC_PI_2;
        let (sin_dev, cos_dev) = dev.sin_cos();
        ok.then_some(FoldBound {
            len_max,
            radius_min,
            sin_dev,
            cos_dev,
        })
    }

    /// Whether every proposal deviated from `turned` folds onto the road of unit
    /// direction `w` and length `len`.
    fn folds(&self, turned: DVec2, w: DVec2, len: f64) -> bool {
        let cos = turned.dot(w);
        if cos <= 0.0 {
            // A road at a right angle or more: `cos_min` below is at most 0.
            return false;
        }
        let sin = turned.perp_dot(w).abs();
        // sin and cos of the angle plus the widest deviation.
        let sin_max = sin * self.cos_dev + cos * self.sin_dev;
        let cos_min = cos * self.cos_dev - sin * self.sin_dev;
        cos_min > 1e-9 && self.len_max.min(len) * sin_max <= self.radius_min
    }
}

/// One growth run's state.
struct Run<'a> {
    p: &'a SecondaryParams,
    g: RoadNetwork,
    region: &'a PolygonWithHoles,
    maps: &'a CellMaps<'a>,
    rng: &'a mut Pcg64Mcg,
    snapper: &'a mut Snapper,
    axis: DVec2,
    report: CellGrowthReport,
    edges: u32,
    guard: u32,
    tolerance: f64,
    /// The worker's buffers.
    buffers: Buffers,
    /// The node whose roads the buffers hold, and the graph's edge bound and count they
    /// were read at.
    root: (Option<NodeId>, (usize, usize)),
    /// Joins onto a road made directly and by planar insertion.
    joins: (u64, u64),
}

/// What a snap event would join: the connectivity draw is made once per pair of the
/// expanded node and this.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum JoinKey {
    Node(NodeId),
    Road(EdgeId),
}

impl Run<'_> {
    /// Whether every proposal from `source` in a direction deviated from `turned` (as
    /// [`deviate`](Self::deviate) draws it) folds onto a road at `source` by test 0,
    /// whatever its length and snap size draws (see [`FoldBound`]).
    #[inline]
    fn folds_for_sure(
        &mut self,
        source: NodeId,
        turned: DVec2,
        bound: &FoldBound,
    ) -> Result<bool, SecondaryError> {
        self.read_root(source)?;
        Ok(self
            .buffers
            .root_roads
            .iter()
            .any(|&(w, len)| bound.folds(turned, w, len)))
    }

    /// Reads the roads at `source` into the buffers' `root_ends` and `root_roads`, unless they were read at this node and the graph
    /// has made or removed no road since (a change of the edge bound or count).
    #[inline]
    fn read_root(&mut self, source: NodeId) -> Result<(), SecondaryError> {
        let roads = (self.g.edge_bound(), self.g.edge_count());
        if self.root == (Some(source), roads) {
            return Ok(());
        }
        self.read_root_again(source, roads)
    }

    /// [`read_root`](Self::read_root)'s reading, when the roads read are out of date.
    #[inline(never)]
    fn read_root_again(
        &mut self,
        source: NodeId,
        roads: (usize, usize),
    ) -> Result<(), SecondaryError> {
        self.buffers.root_roads.clear();
        self.buffers.root_ends.clear();
        let a = self.g.position(source)?;
        for &e in self.g.edges_at(source)? {
            let n = self.g.other_end(e, source)?;
            let p = self.g.position(n)?;
            self.buffers.add_root_road(a, n, p);
        }
        self.root = (Some(source), roads);
        Ok(())
    }

    /// The road from `source` (at `a`) to `end` was just added, with no other change at
    /// `source` (a free end, a joined node, or a split of a road not at `source`: events
    /// on the root's own roads are refused): if the buffers held `source`'s roads as
    /// they were at `before` (the graph's edge bound and count), the new road joins
    /// them, as [`read_root_again`](Self::read_root_again) would read it (the order of
    /// the roads does not matter to their readers), instead of reading them all again.
    #[inline]
    fn root_gained(
        &mut self,
        source: NodeId,
        a: DVec2,
        before: (usize, usize),
        end: NodeId,
    ) -> Result<(), SecondaryError> {
        if self.root != (Some(source), before) {
            return Ok(());
        }
        let p = self.g.position(end)?;
        self.buffers.add_root_road(a, end, p);
        self.root = (Some(source), (self.g.edge_bound(), self.g.edge_count()));
        Ok(())
    }

    /// A proposal [`folds_for_sure`](Self::folds_for_sure): counted as test 0 counts it,
    /// and the generator stepped past its four draws (direction, length, snap size,
    /// width), so that every later draw is the one it would have been.
    fn skip_fold(&mut self) {
        self.report.proposals += 1;
        self.report.refused_blocked += 1;
        self.snapper.count_fold();
        for _ in 0..4 {
            self.rng.next_u64();
        }
    }

    /// `dir` turned by up to ± degree deviance × half of `step` (radians).
    fn deviate(&mut self, dir: DVec2, step: f64) -> DVec2 {
        let u: f64 = self.rng.random::<f64>();
        rotate(dir, self.p.degree_deviance * (2.0 * u - 1.0) * 0.5 * step)
    }

    /// The segment length in direction `dir`: the deviated size on the aspect ellipse.
    fn length(&mut self, dir: DVec2) -> f64 {
        let size = self.p.segment_size_m.sample(self.rng);
        let along = size * self.p.aspect;
        let (c, s) = (dir.dot(self.axis), dir.perp_dot(self.axis));
        along * size
            / ((size * c).powi(2) + (along * s).powi(2))
                .sqrt()
                .max(f64::MIN_POSITIVE)
    }

    /// Kelly's `placeSegment`: returns the node to queue, or `None` when the proposal is
    /// dropped.
    fn place_segment(
        &mut self,
        source: NodeId,
        dir: DVec2,
    ) -> Result<Option<Placed>, SecondaryError> {
        self.report.proposals += 1;
        let len = self.length(dir);
        let snap = self.p.snap_size_m.sample(self.rng).max(0.0);
        let width = self.p.road_width_m.sample(self.rng);
        let a = self.g.position(source)?;
        let b = a + dir * len;
        self.read_root(source)?;
        let target =
            match self
                .snapper
                .snap_from(&self.g, source, &self.buffers.root_ends, a, b, snap)
            {
                SnapEvent::None => Target::Free(b),
                SnapEvent::Blocked => {
                    self.report.refused_blocked += 1;
                    return Ok(None);
                }
                ev => {
                    if !self.may_join(ev) {
                        self.report.refused_connectivity += 1;
                        return Ok(None);
                    }
                    match ev {
                        SnapEvent::Node(n) => Target::Node(n),
                        SnapEvent::Cross(e, q) | SnapEvent::Road(e, q) => Target::OnEdge(e, q),
                        SnapEvent::None | SnapEvent::Blocked => return Ok(None),
                    }
                }
            };
        let t = match target {
            Target::Free(q) | Target::OnEdge(_, q) => q,
            Target::Node(n) => self.g.position(n)?,
        };
        if !t.is_finite() || t == a {
            self.report.refused_blocked += 1;
            return Ok(None);
        }
        // A free end met nothing in the snap area, so the segment crosses and touches
        // nothing (tests 1 and 2); a snapped end needs the exact check.
        if !matches!(target, Target::Free(_)) && !self.clear(source, a, t, &target) {
            self.report.refused_blocked += 1;
            return Ok(None);
        }
        // A segment that touches the boundary nowhere else stays on one side of it: only
        // segments from or to a primary road can leave the cell.
        let on_primary = self.touches_primary(source)
            || match target {
                Target::Free(_) => false,
                Target::Node(n) => self.touches_primary(n),
                Target::OnEdge(e, _) => self.is_primary(e),
            };
        if on_primary && self.region.locate(a.lerp(t, 0.5)) != PointLocation::Inside {
            self.report.refused_outside += 1;
            return Ok(None);
        }
        if self.p.min_angle_deg > 0.0 && self.too_sharp(source, a, t, &target)? {
            self.report.refused_angle += 1;
            return Ok(None);
        }
        if !self.maps.segment_legal(a, t) {
            self.report.refused_map += 1;
            return Ok(None);
        }
        // A road snap ends on the road: planar insertion anchors the end onto it (splits
        // it), within the insertion tolerance.
        let t = match target {
            Target::Node(n) => self.g.position(n)?,
            Target::Free(q) | Target::OnEdge(_, q) => q,
        };
        let road = Road {
            class: RoadClass::Street,
            width,
            bridge: false,
            tunnel: false,
            step: self.report.steps,
        };
        let step = self.report.steps;
        // A free end met nothing within the snap size and a node target passed the exact
        // check, so the road goes in as it is; a road target splits the road through
        // planar insertion, which anchors the end onto it.
        let before = (self.g.edge_bound(), self.g.edge_count());
        let end = match target {
            Target::Free(q) => {
                let n = self.g.add_node(q, Junction { step })?;
                self.g.add_edge(source, n, road)?;
                self.root_gained(source, a, before, n)?;
                n
            }
            Target::Node(n) => match self.g.add_edge(source, n, road) {
                Ok(_) => {
                    self.root_gained(source, a, before, n)?;
                    n
                }
                Err(
                    polis_geom::GeomError::DuplicateEdge { .. }
                    | polis_geom::GeomError::ZeroLengthEdge { .. },
                ) => {
                    self.report.refused_blocked += 1;
                    return Ok(None);
                }
                Err(e) => return Err(e.into()),
            },
            Target::OnEdge(e, _) => {
                let plan = join::plan(
                    &self.g,
                    self.snapper,
                    &mut self.buffers.scratch,
                    source,
                    (a, t),
                    e,
                    self.tolerance,
                );
                match plan {
                    Join::Split { edge, point } => {
                        self.joins.0 += 1;
                        let (m, _) = self.g.split_edge(edge, point, Junction { step })?;
                        self.snapper.touched(&self.g, edge);
                        self.g.add_edge(source, m, road)?;
                        self.root_gained(source, a, before, m)?;
                        m
                    }
                    Join::ZeroLength => {
                        self.report.refused_blocked += 1;
                        return Ok(None);
                    }
                    Join::General => {
                        self.joins.1 += 1;
                        match self.insert(a, t, road)? {
                            Some(n) => n,
                            None => {
                                self.report.refused_blocked += 1;
                                return Ok(None);
                            }
                        }
                    }
                }
            }
        };
        self.edges += 1;
        match target {
            Target::Free(_) => self.report.placed_free += 1,
            Target::Node(_) => self.report.placed_node += 1,
            Target::OnEdge(..) => self.report.placed_road += 1,
        }
        Ok(Some(Placed { node: end }))
    }

    /// Adds the road `a–t` by planar insertion (a join onto a road that
    /// [`join::plan`] leaves to it): returns its last node, or `None` when the
    /// insertion refuses it or only follows existing roads. The graph's spatial index,
    /// which the insertion builds, is freed again: nothing else in growth reads it.
    fn insert(&mut self, a: DVec2, t: DVec2, road: Road) -> Result<Option<NodeId>, SecondaryError> {
        let step = road.step;
        let ins = self.g.insert_segment_with(
            a,
            t,
            road,
            &SnapOptions {
                snap_distance: self.tolerance,
            },
            |_| Junction { step },
        );
        self.g.release_spatial_index();
        let ins = match ins {
            Ok(ins) => ins,
            Err(polis_geom::GeomError::ZeroLengthEdge { .. }) => return Ok(None),
            Err(e) => return Err(e.into()),
        };
        for &(split, _) in &ins.split {
            self.snapper.touched(&self.g, split);
        }
        if ins.created.is_empty() {
            // The road exists already (the insertion followed existing roads).
            return Ok(None);
        }
        self.edges += ins.created.len() as u32 - 1;
        Ok(ins.nodes.last().copied())
    }

    /// Whether the road `a–t` from `source` would make an angle sharper than
    /// `min_angle_deg` with a road at `a`, or with a road at its target: the node's roads,
    /// or both halves of the road it splits.
    fn too_sharp(
        &self,
        source: NodeId,
        a: DVec2,
        t: DVec2,
        target: &Target,
    ) -> Result<bool, SecondaryError> {
        let cos_min = self.p.min_angle_deg.to_radians().cos();
        // Whether the directions `d` and `q - p` (both from `p`) are within the angle.
        let sharp = |p: DVec2, d: DVec2, q: DVec2| {
            let e = q - p;
            let (ld, le) = (d.length(), e.length());
            ld > 0.0 && le > 0.0 && d.dot(e) > cos_min * ld * le
        };
        let roads_at = |n: NodeId, p: DVec2, d: DVec2| -> Result<bool, SecondaryError> {
            for &e in self.g.edges_at(n)? {
                let q = self.g.position(self.g.other_end(e, n)?)?;
                if sharp(p, d, q) {
                    return Ok(true);
                }
            }
            Ok(false)
        };
        if roads_at(source, a, t - a)? {
            return Ok(true);
        }
        match *target {
            Target::Free(_) => Ok(false),
            Target::Node(n) => roads_at(n, t, a - t),
            Target::OnEdge(e, q) => {
                let (u, v) = self.g.segment(e)?;
                Ok(sharp(q, a - q, u) || sharp(q, a - q, v))
            }
        }
    }

    /// Kelly's connectivity test for a snap event of the node being expanded: with
    /// probability *connectivity* the proposal joins what it met. The draw is made once
    /// per road or junction met: the node's other directions that meet the same one get
    /// the same answer, so a high degree does not multiply the chances to connect.
    fn may_join(&mut self, ev: SnapEvent) -> bool {
        let key = match ev {
            SnapEvent::Node(n) => JoinKey::Node(n),
            SnapEvent::Cross(e, _) | SnapEvent::Road(e, _) => JoinKey::Road(e),
            SnapEvent::None | SnapEvent::Blocked => return false,
        };
        if let Some(&(_, join)) = self.buffers.decided.iter().find(|(k, _)| *k == key) {
            return join;
        }
        let connectivity = self.p.connectivity.sample(self.rng).clamp(0.0, 1.0);
        let join = self.rng.random::<f64>() < connectivity;
        self.buffers.decided.push((key, join));
        join
    }

    fn is_primary(&self, e: EdgeId) -> bool {
        self.g
            .edge_payload(e)
            .is_ok_and(|r| r.class == RoadClass::Highway)
    }

    fn touches_primary(&self, n: NodeId) -> bool {
        self.g
            .edges_at(n)
            .is_ok_and(|es| es.iter().any(|&e| self.is_primary(e)))
    }

    /// Whether the straight road `a–t` meets nothing but its root's roads at `a` and its
    /// target (the node, or the road it ends on) at `t`.
    ///
    /// The target lies in the last snap query's extended box, so every road that can meet
    /// `a–t` is among that query's candidates.
    fn clear(&self, source: NodeId, a: DVec2, t: DVec2, target: &Target) -> bool {
        use polis_geom::predicates::{SegmentIntersection as X, segment_intersection};
        let reach = polis_geom::Aabb2::new(a, t);
        for road in self.snapper.candidates(&self.g) {
            let (key, u, v, pu, pv) = (road.edge, road.u, road.v, road.pu, road.pv);
            // Segments whose boxes do not meet are disjoint (the intersection's own first
            // test, here without the call).
            if !reach.intersects(&polis_geom::Aabb2::new(pu, pv)) {
                continue;
            }
            let at_end = |p: DVec2| p == a || p == t;
            let ok = match (segment_intersection(a, t, pu, pv), target) {
                (X::Overlap { .. }, _) | (X::Crossing { .. }, Target::Free(_)) => false,
                (X::Crossing { .. }, Target::Node(_)) => false,
                (X::Crossing { .. }, Target::OnEdge(e, _)) => key == *e,
                (X::Touching { point, .. }, Target::OnEdge(e, _)) => {
                    key == *e || ((u == source || v == source) && point == a)
                }
                (X::Touching { point, .. }, Target::Node(n)) => {
                    (u == *n || v == *n || u == source || v == source) && at_end(point)
                }
                (X::Touching { point, .. }, Target::Free(_)) => {
                    (u == source || v == source) && point == a
                }
                (X::Disjoint, _) => true,
            };
            if !ok {
                return false;
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::secondary::Neighbourhood;
    use crate::secondary::snap::{folds_onto_root, root_ends};

    /// The deviations' sine and cosine polynomials are within two ulps of libm's up to
    /// 45° (at the bounds, at zero, and at random), and a rotation keeps a unit vector's
    /// length to within a few ulps; beyond 45° `rotate` is libm's.
    #[test]
    fn small_angles_turn_as_sin_cos_does() {
        let mut rng = Pcg64Mcg::seed_from_u64(18);
        let quarter = std::f64::consts::FRAC_PI_4;
        let mut xs = vec![0.0, -0.0, quarter, -quarter, 1e-300, 1e-8, 0.3];
        xs.extend((0..100_000).map(|_| (2.0 * rng.random::<f64>() - 1.0) * quarter));
        for x in xs {
            let (s, c) = small_sin_cos(x);
            let (ls, lc) = x.sin_cos();
            assert!(
                (s - ls).abs() <= 2.0 * f64::EPSILON * ls.abs().max(f64::MIN_POSITIVE),
                "sin {x}: {s} {ls}"
            );
            assert!(
                (c - lc).abs() <= 2.0 * f64::EPSILON * lc,
                "cos {x}: {c} {lc}"
            );
            let v = rotate(DVec2::from_angle(x * 7.0), x);
            assert!((v.length() - 1.0).abs() <= 4.0 * f64::EPSILON, "{x}: {v}");
        }
        let v = DVec2::new(0.6, -0.8);
        assert_eq!(rotate(v, 1.0), {
            let (s, c) = 1.0f64.sin_cos();
            DVec2::new(v.x * c - v.y * s, v.x * s + v.y * c)
        });
    }

    /// Where [`FoldBound`] says a direction folds for every draw, test 0 folds every
    /// proposal drawn in it (directions deviated, lengths on the aspect ellipse and snap
    /// sizes, all at random and at their extremes), on random roads at the root; and the
    /// bound is not empty.
    #[test]
    fn a_certain_fold_folds_for_every_draw() {
        let mut rng = Pcg64Mcg::seed_from_u64(15);
        let mut certain = 0;
        for n in Neighbourhood::ALL {
            let mut p = n.params().unwrap();
            p.aspect = [1.0, 0.4, 2.5][rng.random_range(0..3)];
            let axis = DVec2::from_angle(rng.random::<f64>() * 6.0);
            for degree in [3u32, 4, 6, 18] {
                let step = std::f64::consts::TAU / f64::from(degree);
                let Some(bound) = FoldBound::new(&p, step) else {
                    continue;
                };
                for _ in 0..400 {
                    let mut g = RoadNetwork::new();
                    let a = DVec2::new(rng.random::<f64>() * 100.0, rng.random::<f64>() * 100.0);
                    let root = g.add_node(a, Junction::default()).unwrap();
                    let dir = DVec2::from_angle(rng.random::<f64>() * 6.3);
                    // A road near the direction, of a length around the segment size.
                    let off = (rng.random::<f64>() - 0.5) * 1.2;
                    let len = p.segment_size_m.value * (0.05 + 2.0 * rng.random::<f64>());
                    let w = DVec2::from_angle(off).rotate(dir);
                    let far = g.add_node(a + w * len, Junction::default()).unwrap();
                    g.add_edge(root, far, crate::secondary::snap::tests::street())
                        .unwrap();
                    if !bound.folds(dir, w, len) {
                        continue;
                    }
                    certain += 1;
                    for k in 0..40 {
                        // Extremes first, then random draws.
                        let (u, s, r) = match k {
                            0 => (0.0, 1.0, 0.0),
                            1 => (1.0 - 1e-16, 1.0, 0.0),
                            2 => (0.0, 1.0 - 1e-16, 0.0),
                            3 => (1.0 - 1e-16, 1.0 - 1e-16, 0.0),
                            _ => (rng.random(), rng.random(), rng.random()),
                        };
                        let angle = p.degree_deviance * (2.0 * u - 1.0) * 0.5 * step;
                        let d = rotate(dir, angle);
                        let size = p.segment_size_m.value
                            * (1.0 + p.segment_size_m.deviance * (2.0 * s - 1.0));
                        let along = size * p.aspect;
                        let (c, sn) = (d.dot(axis), d.perp_dot(axis));
                        let l = along * size / ((size * c).powi(2) + (along * sn).powi(2)).sqrt();
                        let radius =
                            p.snap_size_m.value * (1.0 + p.snap_size_m.deviance * (2.0 * r - 1.0));
                        let mut ends = Vec::new();
                        root_ends(&g, root, &mut ends);
                        assert!(
                            folds_onto_root(&ends, a, a + d * l, radius),
                            "{n:?} degree {degree}: {dir} {w} {len} {l} {radius}"
                        );
                    }
                }
            }
        }
        assert!(certain > 500, "{certain}");
    }
}
