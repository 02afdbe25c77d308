//! [`RoadInputs`]: the input maps (population, water, parks, elevation, pattern weights).

use std::sync::Arc;

use polis_geom::field::{Constant, Fbm, FbmParams, FnField, Population, PopulationParams};
use polis_geom::{DVec2, Field, FieldExt};

use crate::error::Result;
use crate::lattice::LazyLattice;
use crate::params::{Pattern, RoadParams};

/// The procedural coastline: water where `x / half-width + 0.45 · fBm` exceeds this.
const COAST_THRESHOLD: f64 = 0.72;

/// The lattice spacing of [`RoadInputs::procedural`]'s coastline and hills for `params`'
/// map: 40 m (the finest noise octaves, 190–225 m across, get five lattice points per
/// wavelength), or coarser for maps over 80 km across so that each lattice's cache stays
/// within about 2,000 × 2,000 points (16 MiB).
pub fn procedural_lattice_m(params: &RoadParams) -> f64 {
    let b = params.bounds();
    let widest = b.width().max(b.height());
    if widest.is_finite() {
        (widest / 2000.0).max(40.0)
    } else {
        40.0
    }
}

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
    /// The coastline and the hills are [`LazyLattice`] maps with [`procedural_lattice_m`]
    /// spacing (40 m up to 80 km wide maps): their fBm is evaluated once per lattice
    /// point, where roads are tested, and interpolated bilinearly between; water is where
    /// the interpolated coast value exceeds the threshold. The network is grown and tested
    /// on exactly these maps. Their finest noise octaves are 190–225 m across, so against
    /// the raw fBm the lattice moves the coastline by at most about 9 m and the hills by
    /// about 1 m (tested): detail far below the 90–240 m road segments, and a third of
    /// the generator's time saved (the polis repository's `BENCHMARKS.md`). [`RoadInputs::procedural_with_lattice`]
    /// takes another spacing, or `None` for the raw fBm maps.
    ///
    /// # Errors
    /// Only if the noise parameters were rejected (they are constants here).
    pub fn procedural(seed: u64, params: &RoadParams) -> Result<Self> {
        Self::procedural_with_lattice(seed, params, Some(procedural_lattice_m(params)))
    }

    /// [`RoadInputs::procedural`] with the coastline and hills on a lattice of the given
    /// spacing in metres, or sampled straight from their fBm noise with `None` (slower:
    /// the legality tests then evaluate four noise octaves per sample).
    ///
    /// # Errors
    /// [`RoadError::InvalidParameter`](crate::RoadError::InvalidParameter) for a spacing
    /// that is not finite and positive.
    pub fn procedural_with_lattice(
        seed: u64,
        params: &RoadParams,
        lattice_m: Option<f64>,
    ) -> Result<Self> {
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
        // The continuous coast value; water where it exceeds COAST_THRESHOLD.
        let coast_value: Arc<dyn Field> = Arc::new(FnField::new(move |p: DVec2| {
            (p.x - centre.x) / half + 0.45 * coast.sample(p)
        }));
        let hills = Fbm::new(FbmParams {
            seed: seed ^ 0x0e1e_u64,
            octaves: 4,
            wavelength_m: 1500.0,
            ..FbmParams::default()
        })?;
        let raw_elevation: Arc<dyn Field> = Arc::new(hills.scaled(30.0).offset(30.0));
        let (coast_value, elevation): (Arc<dyn Field>, Arc<dyn Field>) = match lattice_m {
            Some(s) => (
                Arc::new(LazyLattice::new(coast_value, s, b.expanded(s))?),
                Arc::new(LazyLattice::new(raw_elevation, s, b.expanded(s))?),
            ),
            None => (coast_value, raw_elevation),
        };
        let water = FnField::new(move |p: DVec2| {
            let v = coast_value.sample(p);
            if v.is_nan() {
                f64::NAN
            } else if v > COAST_THRESHOLD {
                1.0
            } else {
                0.0
            }
        });
        Ok(RoadInputs {
            population: Arc::new(population),
            water: Arc::new(water),
            parks: Arc::new(Constant(0.0)),
            elevation,
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    /// Distance from `p` to the nearest point of the other water state of `water`, along
    /// the eight compass directions in 5 cm steps, up to `max` metres.
    fn distance_to_shore(water: &dyn Field, p: DVec2, max: f64) -> f64 {
        let here = water.sample(p);
        let mut best = f64::INFINITY;
        for k in 0..8 {
            let d = DVec2::from_angle(f64::from(k) * std::f64::consts::FRAC_PI_4);
            let mut s = 0.05;
            while s <= max.min(best) {
                if water.sample(p + d * s) != here {
                    best = best.min(s);
                    break;
                }
                s += 0.05;
            }
        }
        best
    }

    #[test]
    fn the_lattice_maps_stay_close_to_the_raw_fbm_maps() {
        let params = RoadParams::default();
        let s = procedural_lattice_m(&params);
        assert_eq!(s, 40.0);
        let lat = RoadInputs::procedural(params.seed, &params).unwrap();
        let raw = RoadInputs::procedural_with_lattice(params.seed, &params, None).unwrap();
        let b = params.bounds();
        let (mut differ, mut water, mut worst) = (0, 0, 0.0f64);
        let n = 400;
        for j in 0..n {
            for i in 0..n {
                let p = b.min + b.size() * DVec2::new(i as f64 + 0.37, j as f64 + 0.61) / n as f64;
                let w = lat.water.sample(p);
                water += usize::from(w == 1.0);
                if w != raw.water.sample(p) {
                    differ += 1;
                    // Wherever they disagree, the raw coastline is near: within 12 m
                    // (8.6 m measured for this seed, against 40 m lattice cells).
                    let d = distance_to_shore(raw.water.as_ref(), p, 20.0);
                    worst = worst.max(d);
                    assert!(d <= 12.0, "{p}: {d} m from the fBm coast");
                }
                // Elevation (0–60 m): within 1.5 m (1.09 m measured).
                let (he, hr) = (lat.elevation.sample(p), raw.elevation.sample(p));
                assert!((he - hr).abs() < 1.5, "{p}: {he} vs {hr}");
            }
        }
        assert!(
            water > n * n / 20,
            "the map has a sea: {water} water samples"
        );
        assert!(differ * 1000 < n * n, "{differ} samples disagree");
        eprintln!(
            "{differ} of {} samples differ; farthest {worst} m from the fBm coast",
            n * n
        );
    }
}
