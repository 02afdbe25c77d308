//! Profile functions over one interval: where inside an interval a layer is active.
//!
//! Parish & Müller §4.3 assign "a simple PULSE function" to the intervals of an interval
//! group; `PULSE(a, b, x) = step(a, x) − step(b, x)` (Ebert et al., *Texturing and
//! Modeling*). Combining the profile values of the two interval groups of a layer with
//! AND (minimum) or OR (maximum) gives the active area. Profiles with soft edges give
//! non-rectangular active areas.

use crate::error::{FacadeError, Result};

/// A function over one interval of length `len`, evaluated at a local position `x ∈ [0, len]`
/// (metres from the interval's start). Values ≥ 0.5 count as active.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum Profile {
    /// 0 everywhere: the interval is never active (walls, piers, margins).
    #[default]
    Off,
    /// 1 everywhere: the whole interval is active.
    Full,
    /// `PULSE(from·len, to·len, x)`: active on a fraction of the interval that scales with it.
    Pulse {
        /// Start, as a fraction of the interval length in `[0, 1]`.
        from: f64,
        /// End, as a fraction in `[from, 1]`.
        to: f64,
    },
    /// Active except for fixed margins at both ends (metres): grows with the interval.
    Inset {
        /// Inactive margin at the start, metres.
        start_m: f64,
        /// Inactive margin at the end, metres.
        end_m: f64,
    },
    /// Active on a fixed size starting at a fixed offset from the interval's start (a sill
    /// height and a window height). Clipped to the interval.
    At {
        /// Offset from the interval start, metres.
        offset_m: f64,
        /// Active length, metres.
        size_m: f64,
    },
    /// Active on a fixed size centred in the interval (clipped to the interval).
    Centered {
        /// Active length, metres.
        size_m: f64,
    },
    /// A pulse with smooth-step edges of width `soft_m` (metres) centred on the fractional
    /// bounds: a continuous profile for rounded or faded active areas.
    Smooth {
        /// Start fraction in `[0, 1]`.
        from: f64,
        /// End fraction in `[from, 1]`.
        to: f64,
        /// Edge width, metres.
        soft_m: f64,
    },
}

#[inline]
fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    if e1 <= e0 {
        return if x >= e0 { 1.0 } else { 0.0 };
    }
    let k = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    k * k * (3.0 - 2.0 * k)
}

impl Profile {
    /// The sub-range `[a, b)` of `[0, len]` (local metres) where the profile is ≥ 0.5, or
    /// `None` if it is nowhere active.
    pub fn active_range(&self, len: f64) -> Option<(f64, f64)> {
        let (a, b) = match *self {
            Profile::Off => return None,
            Profile::Full => (0.0, len),
            Profile::Pulse { from, to } | Profile::Smooth { from, to, .. } => {
                (from * len, to * len)
            }
            Profile::Inset { start_m, end_m } => (start_m, len - end_m),
            Profile::At { offset_m, size_m } => (offset_m, offset_m + size_m),
            Profile::Centered { size_m } => ((len - size_m) * 0.5, (len + size_m) * 0.5),
        };
        let (a, b) = (a.max(0.0), b.min(len));
        (b > a).then_some((a, b))
    }

    /// The profile value at local position `x` of an interval of length `len`.
    pub fn value(&self, x: f64, len: f64) -> f32 {
        match *self {
            Profile::Off => 0.0,
            Profile::Full => 1.0,
            Profile::Smooth { from, to, soft_m } => {
                let h = soft_m * 0.5;
                let (a, b) = (from * len, to * len);
                (smoothstep(a - h, a + h, x) * (1.0 - smoothstep(b - h, b + h, x))) as f32
            }
            _ => match self.active_range(len) {
                Some((a, b)) if x >= a && x < b => 1.0,
                _ => 0.0,
            },
        }
    }

    /// Checks the parameters: finite, fractions in `[0, 1]` and ordered, sizes ≥ 0.
    pub fn validate(&self) -> Result<()> {
        let bad = |reason: &str| {
            Err(FacadeError::InvalidStyle {
                style: format!("{self:?}"),
                reason: reason.to_string(),
            })
        };
        let finite_nonneg = |v: f64| v.is_finite() && v >= 0.0;
        match *self {
            Profile::Off | Profile::Full => Ok(()),
            Profile::Pulse { from, to } | Profile::Smooth { from, to, .. }
                if !(finite_nonneg(from) && to.is_finite() && from <= to && to <= 1.0) =>
            {
                bad("profile fractions must satisfy 0 ≤ from ≤ to ≤ 1")
            }
            Profile::Smooth { soft_m, .. } if !finite_nonneg(soft_m) => bad("soft_m must be ≥ 0"),
            Profile::Inset { start_m, end_m }
                if !(finite_nonneg(start_m) && finite_nonneg(end_m)) =>
            {
                bad("insets must be finite and ≥ 0 metres")
            }
            Profile::At { offset_m, size_m }
                if !(finite_nonneg(offset_m) && finite_nonneg(size_m)) =>
            {
                bad("offset_m and size_m must be finite and ≥ 0 metres")
            }
            Profile::Centered { size_m } if !finite_nonneg(size_m) => {
                bad("size_m must be finite and ≥ 0 metres")
            }
            _ => Ok(()),
        }
    }

    /// Whether the profile's value is exactly 0 or 1 everywhere (a box profile), so the
    /// active range alone decides activity.
    pub fn is_box(&self) -> bool {
        !matches!(self, Profile::Smooth { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pulse_is_step_difference() {
        let p = Profile::Pulse {
            from: 0.25,
            to: 0.75,
        };
        assert_eq!(p.value(0.9, 4.0), 0.0);
        assert_eq!(p.value(1.0, 4.0), 1.0);
        assert_eq!(p.value(2.99, 4.0), 1.0);
        assert_eq!(p.value(3.0, 4.0), 0.0);
        assert_eq!(p.active_range(4.0), Some((1.0, 3.0)));
    }

    #[test]
    fn fixed_size_profiles_clip_to_interval() {
        assert_eq!(
            Profile::At {
                offset_m: 0.9,
                size_m: 1.5
            }
            .active_range(2.0),
            Some((0.9, 2.0))
        );
        assert_eq!(
            Profile::Centered { size_m: 1.0 }.active_range(3.0),
            Some((1.0, 2.0))
        );
        assert_eq!(
            Profile::Centered { size_m: 5.0 }.active_range(3.0),
            Some((0.0, 3.0))
        );
        assert_eq!(
            Profile::Inset {
                start_m: 2.0,
                end_m: 2.0
            }
            .active_range(3.0),
            None
        );
        assert_eq!(Profile::Off.active_range(3.0), None);
    }

    #[test]
    fn smooth_profile_is_half_at_bounds() {
        let p = Profile::Smooth {
            from: 0.2,
            to: 0.8,
            soft_m: 0.2,
        };
        assert!((p.value(2.0, 10.0) - 0.5).abs() < 1e-6);
        assert!(p.value(5.0, 10.0) > 0.99);
        assert!(p.value(0.5, 10.0) < 0.01);
        assert!(!p.is_box());
    }

    #[test]
    fn validation_rejects_nonsense() {
        assert!(Profile::Pulse { from: 0.8, to: 0.2 }.validate().is_err());
        assert!(
            Profile::At {
                offset_m: f64::NAN,
                size_m: 1.0
            }
            .validate()
            .is_err()
        );
        assert!(
            Profile::Inset {
                start_m: -1.0,
                end_m: 0.0
            }
            .validate()
            .is_err()
        );
        assert!(Profile::Full.validate().is_ok());
    }
}
