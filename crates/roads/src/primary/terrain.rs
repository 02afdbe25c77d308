//! [`Terrain`]: the elevation the roads are draped on and the ground they may use.

use std::sync::Arc;

use polis_geom::field::Constant;
use polis_geom::{Aabb2, DVec2, Field};

use crate::inputs::RoadInputs;
use crate::legality::{Illegal, Legality};
use crate::params::RoadParams;
use crate::primary::error::PrimaryError;

/// What a step of a road crosses, sampled every [`Terrain::legality_step_m`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Ground {
    /// Dry, free land all the way.
    Legal,
    /// Some water (and nothing worse): a bridge.
    Water,
    /// A park, the map edge or an undefined map value: impassable.
    Blocked(Illegal),
}

/// The maps a primary network is plotted on: elevation (metres) and the legality maps of
/// polis-roads (water and parks, illegal where ≥ 0.5; outside the bounds). Not serde
/// data: fields are code. Cheap to clone (shared maps).
///
/// Slope is not a legality rule here: adaptive roads handle it through their strategy.
#[derive(Clone)]
pub struct Terrain {
    elevation: Arc<dyn Field>,
    legality: Legality,
    bounds: Aabb2,
    legality_step_m: f64,
}

impl std::fmt::Debug for Terrain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Terrain")
            .field("bounds", &self.bounds)
            .field("legality_step_m", &self.legality_step_m)
            .finish_non_exhaustive()
    }
}

/// Default spacing of legality samples along a step, in metres.
pub const DEFAULT_LEGALITY_STEP_M: f64 = 10.0;

impl Terrain {
    /// The terrain of `inputs` (elevation, water, parks) inside `bounds`.
    ///
    /// # Errors
    /// [`PrimaryError::InvalidParameter`] (`bounds`) for an empty, inverted or non-finite
    /// box, or one beyond a quarter of [`polis_geom::MAX_COORDINATE`].
    pub fn new(inputs: &RoadInputs, bounds: Aabb2) -> Result<Self, PrimaryError> {
        let lim = polis_geom::MAX_COORDINATE / 4.0;
        let ok = bounds.min.is_finite()
            && bounds.max.is_finite()
            && bounds.min.x < bounds.max.x
            && bounds.min.y < bounds.max.y
            && bounds.min.abs().max_element() <= lim
            && bounds.max.abs().max_element() <= lim;
        if !ok {
            return Err(PrimaryError::InvalidParameter {
                name: "bounds",
                reason: format!(
                    "{:?}–{:?}; use a finite, non-empty box within ±{lim} m",
                    bounds.min, bounds.max
                ),
            });
        }
        let params = RoadParams {
            bounds_min: bounds.min.to_array(),
            bounds_max: bounds.max.to_array(),
            ..RoadParams::default()
        };
        Ok(Terrain {
            elevation: inputs.elevation.clone(),
            legality: Legality::new(inputs, &params),
            bounds,
            legality_step_m: DEFAULT_LEGALITY_STEP_M,
        })
    }

    /// Dry, park-free land with the given elevation map.
    ///
    /// # Errors
    /// As [`Terrain::new`].
    pub fn with_elevation(elevation: Arc<dyn Field>, bounds: Aabb2) -> Result<Self, PrimaryError> {
        let mut inputs = RoadInputs::flat(Arc::new(Constant(1.0)));
        inputs.elevation = elevation;
        Self::new(&inputs, bounds)
    }

    /// Flat, dry land.
    ///
    /// # Errors
    /// As [`Terrain::new`].
    pub fn flat(bounds: Aabb2) -> Result<Self, PrimaryError> {
        Self::with_elevation(Arc::new(Constant(0.0)), bounds)
    }

    /// The same terrain with legality sampled every `step_m` metres along each step.
    /// Default: [`DEFAULT_LEGALITY_STEP_M`].
    ///
    /// # Errors
    /// [`PrimaryError::InvalidParameter`] (`legality_step_m`) unless `step_m ≥ 0.01`.
    pub fn with_legality_step(mut self, step_m: f64) -> Result<Self, PrimaryError> {
        if !(step_m.is_finite() && step_m >= 0.01) {
            return Err(PrimaryError::InvalidParameter {
                name: "legality_step_m",
                reason: format!("{step_m} m; use a finite spacing ≥ 0.01 m"),
            });
        }
        self.legality_step_m = step_m;
        Ok(self)
    }

    /// The map box.
    pub fn bounds(&self) -> Aabb2 {
        self.bounds
    }

    /// The spacing of legality samples along a step, metres.
    pub fn legality_step_m(&self) -> f64 {
        self.legality_step_m
    }

    /// Elevation at `p` in metres (NaN where the map is undefined).
    #[inline]
    pub fn elevation(&self, p: DVec2) -> f64 {
        self.elevation.sample(p)
    }

    /// Why a node or road may not stand at `p` (outside, water, park), or `None`.
    #[inline]
    pub fn point(&self, p: DVec2) -> Option<Illegal> {
        self.legality.point(p)
    }

    /// What the straight step `a → b` crosses (samples every legality step, `a` itself
    /// excluded, `b` included): the worst of legal < water < blocked; the first blocked
    /// sample names the obstacle.
    pub fn step(&self, a: DVec2, b: DVec2) -> Ground {
        let len = a.distance(b);
        let n = (len / self.legality_step_m).ceil();
        let n = if n.is_finite() && n >= 1.0 {
            (n as usize).min(1_000_000)
        } else {
            1
        };
        let mut ground = Ground::Legal;
        // The far end first: most blocked steps end in the obstacle.
        for i in std::iter::once(n).chain(1..n) {
            let p = if i == n {
                b
            } else {
                a + (b - a) * (i as f64 / n as f64)
            };
            match self.point(p) {
                None => {}
                Some(Illegal::Water) => ground = Ground::Water,
                Some(other) => return Ground::Blocked(other),
            }
        }
        ground
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::field::FnField;

    #[test]
    fn steps_are_classified() {
        let mut inputs = RoadInputs::flat(Arc::new(Constant(1.0)));
        inputs.water = Arc::new(FnField::new(|p: DVec2| {
            f64::from(p.x > 100.0 && p.x < 150.0)
        }));
        inputs.parks = Arc::new(FnField::new(|p: DVec2| f64::from(p.y > 500.0)));
        let t = Terrain::new(
            &inputs,
            Aabb2::new(DVec2::splat(-1000.0), DVec2::splat(1000.0)),
        )
        .unwrap();
        let o = DVec2::ZERO;
        assert_eq!(t.step(o, DVec2::new(90.0, 0.0)), Ground::Legal);
        assert_eq!(t.step(o, DVec2::new(200.0, 0.0)), Ground::Water);
        assert_eq!(
            t.step(o, DVec2::new(0.0, 600.0)),
            Ground::Blocked(Illegal::Park)
        );
        assert_eq!(
            t.step(o, DVec2::new(-1200.0, 0.0)),
            Ground::Blocked(Illegal::Outside)
        );
        assert!(Terrain::flat(Aabb2::new(DVec2::ZERO, DVec2::ZERO)).is_err());
        assert!(t.clone().with_legality_step(0.0).is_err());
    }
}
