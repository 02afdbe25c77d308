//! Legal territory (§3.3): inside the map, not in water, not in a park, not too steep.

use polis_geom::{Aabb2, DVec2};

use crate::inputs::RoadInputs;
use crate::params::RoadParams;

/// Why a point or a piece of road is illegal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Illegal {
    /// Outside the map (or a map value is NaN there).
    Outside,
    /// In water (`water ≥ 0.5`).
    Water,
    /// In a park (`parks ≥ 0.5`).
    Park,
    /// Steeper than [`RoadParams::max_slope`].
    Slope,
}

/// Legality tests against the input maps.
#[derive(Debug, Clone)]
pub struct Legality {
    inputs: RoadInputs,
    bounds: Aabb2,
    max_slope: f64,
    step: f64,
    slope_step: f64,
    /// When water, parks and elevation are constant and legal everywhere: the map box
    /// shrunk by a margin far above the rounding of a sample point. A segment with both
    /// ends inside it has every sample inside the map, so it is legal without sampling.
    flat_inner: Option<Aabb2>,
}

/// The first illegal place along a segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// Parameter along the segment (0 at its start) of the first illegal sample.
    pub t: f64,
    /// Parameter of the last legal sample before it.
    pub t_legal: f64,
    /// What is wrong there.
    pub what: Illegal,
}

impl Legality {
    /// Tests for `inputs` under `params`.
    pub fn new(inputs: &RoadInputs, params: &RoadParams) -> Self {
        let bounds = params.bounds();
        Legality {
            inputs: inputs.clone(),
            bounds,
            max_slope: params.max_slope,
            step: params.legality_step_m,
            slope_step: params.slope_step_m,
            flat_inner: flat_inner(inputs, params.max_slope, bounds),
        }
    }

    /// The map box.
    pub fn bounds(&self) -> Aabb2 {
        self.bounds
    }

    /// Why `p` is illegal, or `None` when roads may be built there (slope is a property
    /// of segments and is not tested here).
    pub fn point(&self, p: DVec2) -> Option<Illegal> {
        if !(p.is_finite() && self.bounds.contains(p)) {
            return Some(Illegal::Outside);
        }
        let w = self.inputs.water.sample(p);
        if w.is_nan() {
            return Some(Illegal::Outside);
        }
        if w >= 0.5 {
            return Some(Illegal::Water);
        }
        let k = self.inputs.parks.sample(p);
        if k.is_nan() {
            return Some(Illegal::Outside);
        }
        if k >= 0.5 {
            return Some(Illegal::Park);
        }
        None
    }

    /// Whether the point is in water (and inside the map).
    pub fn is_water(&self, p: DVec2) -> bool {
        self.point(p) == Some(Illegal::Water)
    }

    /// Number of samples along a segment of length `len`.
    fn samples(&self, len: f64) -> usize {
        let n = (len / self.step).ceil();
        if n.is_finite() && n >= 1.0 {
            (n as usize).min(1_000_000)
        } else {
            1
        }
    }

    /// The first violation along `a–b` (samples every `legality_step_m`, the start
    /// excluded), or `None` when the whole segment is legal. Slope is tested over runs of
    /// [`RoadParams::slope_step_m`] (and at the end).
    pub fn segment(&self, a: DVec2, b: DVec2) -> Option<Violation> {
        if self.trivially_legal(a, b) {
            return None;
        }
        let len = a.distance(b);
        let n = self.samples(len);
        self.segment_walk(a, b, len, n)
    }

    fn segment_walk(&self, a: DVec2, b: DVec2, len: f64, n: usize) -> Option<Violation> {
        let mut prev_t = 0.0;
        // Elevation is compared over runs of at least `slope_step` (grade over a baseline).
        let (mut h_t, mut h0) = (0.0, f64::NAN);
        for i in 1..=n {
            let t = i as f64 / n as f64;
            let p = a + (b - a) * t;
            if let Some(what) = self.point(p) {
                return Some(Violation {
                    t,
                    t_legal: prev_t,
                    what,
                });
            }
            let run = len * (t - h_t);
            if i == n || run >= self.slope_step {
                if h0.is_nan() {
                    h0 = self.inputs.elevation.sample(a);
                }
                let h = self.inputs.elevation.sample(p);
                if !(h.is_finite() && h0.is_finite()) {
                    return Some(Violation {
                        t,
                        t_legal: prev_t,
                        what: Illegal::Outside,
                    });
                }
                if run > 0.0 && (h - h0).abs() > self.max_slope * run {
                    return Some(Violation {
                        t,
                        t_legal: h_t,
                        what: Illegal::Slope,
                    });
                }
                h_t = t;
                h0 = h;
            }
            prev_t = t;
        }
        None
    }

    /// Whether `a–b` is known legal without sampling: the maps are constant and legal
    /// and both ends lie well inside the map box (the box is convex, and a sample
    /// `a + (b − a)·t` is off the segment by rounding only, far below the margin).
    #[inline]
    fn trivially_legal(&self, a: DVec2, b: DVec2) -> bool {
        self.flat_inner
            .is_some_and(|inner| inner.contains(a) && inner.contains(b))
    }

    /// Whether every sample of `a–b` is legal.
    pub fn segment_ok(&self, a: DVec2, b: DVec2) -> bool {
        if self.trivially_legal(a, b) {
            return true;
        }
        // Most illegal proposals fail at their far end (water ahead, map edge): test the
        // end point first.
        self.point(b).is_none() && self.segment(a, b).is_none()
    }

    /// Checks that `a–b` only crosses water (no park, slope or map edge) and lands on
    /// legal ground: the test for a bridge.
    pub fn bridgeable(&self, a: DVec2, b: DVec2) -> bool {
        if self.point(b).is_some() {
            return false;
        }
        if self.trivially_legal(a, b) {
            return true;
        }
        let n = self.samples(a.distance(b));
        (1..=n).all(|i| {
            let p = a + (b - a) * (i as f64 / n as f64);
            matches!(self.point(p), None | Some(Illegal::Water))
        })
    }

    /// The landing of a bridge leaving `a` in the unit direction `d` whose first water
    /// sample lies `water_at` metres along: one sample step past the first legal sample
    /// within `reach` metres of `a` (capped at `reach`), if the span from `a` only crosses
    /// water ([`bridgeable`](Self::bridgeable)); `None` when no land lies within reach or
    /// the span crosses something else.
    pub fn bridge_landing(&self, a: DVec2, d: DVec2, water_at: f64, reach: f64) -> Option<DVec2> {
        let step = self.step;
        let mut s = water_at;
        while s + step <= reach {
            s += step;
            if self.point(a + d * s).is_none() {
                let landing = a + d * (s + step).min(reach);
                return self.bridgeable(a, landing).then_some(landing);
            }
        }
        None
    }

    /// The sample spacing.
    pub fn step(&self) -> f64 {
        self.step
    }

    /// Ground elevation at `p`, metres (NaN where the map has none).
    pub fn elevation(&self, p: DVec2) -> f64 {
        self.inputs.elevation.sample(p)
    }

    /// The baseline over which slope is measured, metres.
    pub fn slope_step(&self) -> f64 {
        self.slope_step
    }

    /// The slope limit (rise over run).
    pub fn max_slope(&self) -> f64 {
        self.max_slope
    }
}

/// The inner box of [`Legality::flat_inner`], or `None` unless water and parks are
/// constants below 0.5, elevation is a finite constant (so no slope), the slope limit is
/// not negative and the map box is finite.
fn flat_inner(inputs: &RoadInputs, max_slope: f64, bounds: Aabb2) -> Option<Aabb2> {
    let legal_mask = |v: Option<f64>| v.is_some_and(|v| v < 0.5);
    let flat = legal_mask(inputs.water.constant_value())
        && legal_mask(inputs.parks.constant_value())
        && inputs
            .elevation
            .constant_value()
            .is_some_and(f64::is_finite)
        && max_slope >= 0.0;
    if !(flat && bounds.min.is_finite() && bounds.max.is_finite()) {
        return None;
    }
    // Rounding of a sample is a few ulps of the largest coordinate: 1e-9 relative is
    // millions of ulps.
    let margin = 1e-9
        * bounds
            .min
            .abs()
            .max(bounds.max.abs())
            .max_element()
            .max(1.0);
    let inner = Aabb2 {
        min: bounds.min + margin,
        max: bounds.max - margin,
    };
    (!inner.is_empty()).then_some(inner)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::sync::Arc;

    use polis_geom::field::{Constant, FnField};
    use proptest::prelude::*;

    use super::*;

    /// The same constant maps, once as [`Constant`]s (fast path) and once hidden in
    /// closures (always sampled).
    fn pair(params: &RoadParams) -> (Legality, Legality) {
        let fast = RoadInputs::flat(Arc::new(Constant(0.5)));
        let mut slow = fast.clone();
        slow.water = Arc::new(FnField::new(|_| 0.0));
        slow.parks = Arc::new(FnField::new(|_| 0.0));
        slow.elevation = Arc::new(FnField::new(|_| 3.0));
        (Legality::new(&fast, params), Legality::new(&slow, params))
    }

    #[test]
    fn constant_maps_take_the_fast_path_only_when_legal() {
        let p = RoadParams::default();
        let (fast, slow) = pair(&p);
        assert!(fast.flat_inner.is_some() && slow.flat_inner.is_none());
        let mut wet = RoadInputs::flat(Arc::new(Constant(0.5)));
        wet.water = Arc::new(Constant(0.7));
        assert!(Legality::new(&wet, &p).flat_inner.is_none());
        wet.water = Arc::new(Constant(f64::NAN));
        assert!(Legality::new(&wet, &p).flat_inner.is_none());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        /// Segments ending on, near and beyond the map edge: the fast path answers
        /// exactly as the sampling walk.
        #[test]
        fn fast_path_equals_the_walk(
            ax in -1.0f64..1.0, ay in -1.0f64..1.0,
            bx in -1.0f64..1.0, by in -1.0f64..1.0,
            snap_edge in 0u8..4,
        ) {
            let p = RoadParams::default();
            let (fast, slow) = pair(&p);
            let b = p.bounds();
            let map = |u: f64, lo: f64, hi: f64| lo + (hi - lo) * (0.5 + 0.55 * u);
            let mut a = DVec2::new(map(ax, b.min.x, b.max.x), map(ay, b.min.y, b.max.y));
            let mut e = DVec2::new(map(bx, b.min.x, b.max.x), map(by, b.min.y, b.max.y));
            match snap_edge {
                0 => a.x = b.max.x,
                1 => e.y = b.min.y,
                2 => e.x = b.max.x - 1e-12,
                _ => {}
            }
            prop_assert_eq!(fast.segment(a, e), slow.segment(a, e));
            prop_assert_eq!(fast.segment_ok(a, e), slow.segment_ok(a, e));
            prop_assert_eq!(fast.bridgeable(a, e), slow.bridgeable(a, e));
        }
    }
}
