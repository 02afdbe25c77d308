//! Population feedback (Parish & Müller §3.2.1): "the created street ends still lower the
//! population density in their environment, usually within the area of the block,
//! according to the mechanisms proposed for Open L-systems. When an area with no
//! population is reached, the streets stop growing."
//!
//! [`PopulationFeedback`] is the environment's population: a [`Field`] that is the input
//! population less what the accepted street ends have used up. Each accepted street
//! segment's end takes [`RoadParams::population_feedback`] from the population within
//! [`RoadParams::feedback_radius_m`] of it, falling off linearly to zero at that radius
//! (the block around the end). The generator wraps the population map in it when the
//! amount is above zero, so the global goals (street branching above
//! [`RoadParams::population_threshold`], streets stopping below
//! [`RoadParams::street_min_population`]) and the highways' population rays read the
//! lowered density: streets stop where the population is used up, not only where the map
//! is empty.
//!
//! # Guarantees
//! * The lowered population is `max(base − used, 0)`: never negative, never above the map.
//! * Deterministic: the ends are kept in insertion order per bucket and summed in that
//!   order; the generator inserts them in derivation order.
//!
//! # Limitations
//! * Only the default goals and constraints read the fed-back population through the
//!   inputs; goals replaced with [`RoadGenerator::with_goals`](crate::RoadGenerator::with_goals)
//!   see it only if they sample the inputs the generator hands them.
//! * Highway ends use up nothing (the paper names street ends).
//!
//! # References
//! Parish & Müller 2001 §3.2.1; Měch & Prusinkiewicz 1996 (open L-systems).

use std::collections::BTreeMap;
use std::sync::{Arc, RwLock};

use polis_geom::{DVec2, Field};

use crate::params::RoadParams;

/// The population less what street ends used up (see the [module docs](self)).
pub struct PopulationFeedback {
    base: Arc<dyn Field>,
    amount: f64,
    radius: f64,
    /// Street ends by bucket (`radius`-sized cells), in insertion order.
    ends: RwLock<BTreeMap<(i64, i64), Vec<DVec2>>>,
}

impl std::fmt::Debug for PopulationFeedback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PopulationFeedback")
            .field("amount", &self.amount)
            .field("radius", &self.radius)
            .finish_non_exhaustive()
    }
}

impl PopulationFeedback {
    /// Feedback over `base` with the amount and radius of `params`; `None` when the
    /// amount is zero (feedback off) or the radius is not positive.
    pub fn new(base: Arc<dyn Field>, params: &RoadParams) -> Option<Self> {
        let (amount, radius) = (params.population_feedback, params.feedback_radius_m);
        (amount > 0.0 && radius > 0.0 && amount.is_finite() && radius.is_finite()).then(|| {
            PopulationFeedback {
                base,
                amount,
                radius,
                ends: RwLock::new(BTreeMap::new()),
            }
        })
    }

    fn bucket(&self, p: DVec2) -> (i64, i64) {
        let k = |v: f64| (v / self.radius).floor().clamp(-1e15, 1e15) as i64;
        (k(p.x), k(p.y))
    }

    /// Records a street end at `p`: the population around it is lowered from now on.
    /// Non-finite points are ignored.
    pub fn use_up(&self, p: DVec2) {
        if !p.is_finite() {
            return;
        }
        let key = self.bucket(p);
        // A poisoned lock only means another thread panicked mid-push; the map is intact.
        let mut ends = self.ends.write().unwrap_or_else(|e| e.into_inner());
        ends.entry(key).or_default().push(p);
    }

    /// Street ends recorded so far.
    pub fn ends(&self) -> usize {
        let ends = self.ends.read().unwrap_or_else(|e| e.into_inner());
        ends.values().map(Vec::len).sum()
    }

    /// The population used up at `p`.
    pub fn used(&self, p: DVec2) -> f64 {
        let (bx, by) = self.bucket(p);
        let ends = self.ends.read().unwrap_or_else(|e| e.into_inner());
        let mut used = 0.0;
        for dx in -1..=1 {
            for dy in -1..=1 {
                let Some(list) = ends.get(&(bx + dx, by + dy)) else {
                    continue;
                };
                for &e in list {
                    let d = e.distance(p);
                    if d < self.radius {
                        used += self.amount * (1.0 - d / self.radius);
                    }
                }
            }
        }
        used
    }
}

impl Field for PopulationFeedback {
    fn sample(&self, p: DVec2) -> f64 {
        let base = self.base.sample(p);
        if !base.is_finite() {
            return base;
        }
        (base - self.used(p)).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::field::Constant;

    #[test]
    fn ends_lower_the_population_within_the_radius_only() {
        let params = RoadParams {
            population_feedback: 0.2,
            feedback_radius_m: 100.0,
            ..RoadParams::default()
        };
        let f = PopulationFeedback::new(Arc::new(Constant(0.5)), &params).unwrap();
        assert_eq!(f.sample(DVec2::ZERO), 0.5);
        f.use_up(DVec2::ZERO);
        f.use_up(DVec2::new(f64::NAN, 0.0));
        assert_eq!(f.ends(), 1);
        assert!((f.sample(DVec2::ZERO) - 0.3).abs() < 1e-12);
        assert!((f.sample(DVec2::new(50.0, 0.0)) - 0.4).abs() < 1e-12);
        assert_eq!(f.sample(DVec2::new(100.0, 0.0)), 0.5);
        assert_eq!(f.sample(DVec2::new(-150.0, 30.0)), 0.5);
        for _ in 0..5 {
            f.use_up(DVec2::new(1.0, 1.0));
        }
        assert_eq!(f.sample(DVec2::ZERO), 0.0, "never below zero");
        let off = RoadParams {
            population_feedback: 0.0,
            ..params
        };
        assert!(PopulationFeedback::new(Arc::new(Constant(0.5)), &off).is_none());
    }
}
