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
        Legality {
            inputs: inputs.clone(),
            bounds: params.bounds(),
            max_slope: params.max_slope,
            step: params.legality_step_m,
            slope_step: params.slope_step_m,
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

    /// Whether every sample of `a–b` is legal.
    pub fn segment_ok(&self, a: DVec2, b: DVec2) -> bool {
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
        let n = self.samples(a.distance(b));
        (1..=n).all(|i| {
            let p = a + (b - a) * (i as f64 / n as f64);
            matches!(self.point(p), None | Some(Illegal::Water))
        })
    }

    /// The sample spacing.
    pub fn step(&self) -> f64 {
        self.step
    }
}
