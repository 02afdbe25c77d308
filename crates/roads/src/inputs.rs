//! [`RoadInputs`]: the input maps (population, water, parks, elevation, pattern weights).

use std::sync::Arc;

use polis_geom::field::{Constant, Fbm, FbmParams, FnField, Population, PopulationParams};
use polis_geom::{DVec2, Field, FieldExt};

use crate::error::Result;
use crate::params::{Pattern, RoadParams};

/// The input maps of Parish & Müller (§2, §3.2–3.3) as [`Field`]s.
///
/// Conventions: `water` and `parks` are illegal where they are ≥ 0.5; `elevation` is in
/// metres; pattern weights are grey-scale maps (any non-negative scale: they are
/// normalised where they are sampled).
#[derive(Clone)]
pub struct RoadInputs {
    /// Population density (highways climb it; streets branch above the threshold).
    pub population: Arc<dyn Field>,
    /// Water: illegal where ≥ 0.5 (highways may bridge it).
    pub water: Arc<dyn Field>,
    /// Parks and other no-build areas: illegal where ≥ 0.5.
    pub parks: Arc<dyn Field>,
    /// Ground elevation in metres (slope limit, San Francisco pattern).
    pub elevation: Arc<dyn Field>,
    /// Pattern-weight maps (paper Fig. 7). Empty = [`RoadParams::pattern`] everywhere.
    /// Where every weight is ≤ 0 the Basic rule applies.
    pub pattern_weights: Vec<(Pattern, Arc<dyn Field>)>,
    /// Local New York grid angle in degrees; `None` = [`RoadParams::grid_angle_deg`].
    pub grid_angle: Option<Arc<dyn Field>>,
}

impl std::fmt::Debug for RoadInputs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RoadInputs")
            .field(
                "pattern_weights",
                &self
                    .pattern_weights
                    .iter()
                    .map(|(p, _)| *p)
                    .collect::<Vec<_>>(),
            )
            .field("grid_angle", &self.grid_angle.is_some())
            .finish_non_exhaustive()
    }
}

impl RoadInputs {
    /// Flat, dry land with the given population map and nothing illegal.
    pub fn flat(population: Arc<dyn Field>) -> Self {
        RoadInputs {
            population,
            water: Arc::new(Constant(0.0)),
            parks: Arc::new(Constant(0.0)),
            elevation: Arc::new(Constant(0.0)),
            pattern_weights: Vec::new(),
            grid_angle: None,
        }
    }

    /// The procedural defaults: the slides' layered-simplex population (`unit_m = 100`),
    /// a noise coastline with the sea toward the east edge of `params`' map, rolling
    /// hills up to ~60 m, no parks. All noise is seeded from `seed`.
    ///
    /// # Errors
    /// Only if the noise parameters were rejected (they are constants here).
    pub fn procedural(seed: u64, params: &RoadParams) -> Result<Self> {
        let population = Population::new(PopulationParams {
            seed,
            unit_m: 100.0,
        })?;
        let b = params.bounds();
        let centre = b.center();
        let half = (b.width() * 0.5).max(1.0);
        let coast = Fbm::new(FbmParams {
            seed: seed ^ 0x000c_0a57_u64,
            octaves: 4,
            wavelength_m: 1800.0,
            ..FbmParams::default()
        })?;
        let water = FnField::new(move |p: DVec2| {
            let x = (p.x - centre.x) / half;
            let v = x + 0.45 * coast.sample(p);
            if v.is_nan() {
                f64::NAN
            } else if v > 0.72 {
                1.0
            } else {
                0.0
            }
        });
        let hills = Fbm::new(FbmParams {
            seed: seed ^ 0x0e1e_u64,
            octaves: 4,
            wavelength_m: 1500.0,
            ..FbmParams::default()
        })?;
        let elevation = hills.scaled(30.0).offset(30.0);
        Ok(RoadInputs {
            population: Arc::new(population),
            water: Arc::new(water),
            parks: Arc::new(Constant(0.0)),
            elevation: Arc::new(elevation),
            pattern_weights: Vec::new(),
            grid_angle: None,
        })
    }

    /// Replaces the pattern-weight maps (builder style).
    pub fn with_pattern_weights(mut self, weights: Vec<(Pattern, Arc<dyn Field>)>) -> Self {
        self.pattern_weights = weights;
        self
    }
}
