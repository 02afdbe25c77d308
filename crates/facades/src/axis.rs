//! Axis styles: interval groups that adapt to any length.
//!
//! A style texture "can scale to any width or height" (Parish & Müller §4.3, fig. 15). An
//! [`AxisStyle`] describes one axis of a facade as fixed, irregular segments at the start
//! (margins, plinth, ground floor), a module repeated `n` times (a bay, a storey) and fixed
//! segments at the end (margin, cornice, attic). [`AxisStyle::fit`] chooses `n` and the
//! segment lengths for a given length `L`:
//!
//! 1. `n` is the repetition count whose nominal length is closest to `L`, limited to what
//!    fits when every segment shrinks to its minimum (and to `min_repeats..=max_repeats`, or
//!    to a requested count such as the building's floor count when that fits).
//! 2. The difference between `L` and the nominal length is shared among the *flexible*
//!    segments in proportion to their `flex` weights; shrinking stops at each segment's
//!    minimum (water filling). Rigid segments (`flex = 0`) — windows — keep their exact
//!    size, so a window is never stretched, squeezed or cut by the facade's edge. This is
//!    the "best fit" of Kelly §4.4.3.3: whole modules, never a fraction of one.
//! 3. If no segment is flexible, every segment scales uniformly (Kelly's tile fit).

use std::sync::Arc;

use crate::error::{FacadeError, Result, check_range};
use crate::interval::{Interval, IntervalGroup, Part};
use crate::profile::Profile;
use crate::{MAX_INTERVALS, MAX_LENGTH_M, MIN_SEGMENT_M};

/// One segment of an [`AxisStyle`]: becomes one interval.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Segment {
    /// The row/column kind (`"window"`, `"pier"`, `"ground"`, `"cornice"` …), used by
    /// layer selections. Default: `"wall"`.
    #[cfg_attr(feature = "serde", serde(default = "default_name"))]
    pub name: String,
    /// Nominal length, metres (> 0).
    pub length_m: f64,
    /// Weight with which this segment absorbs extra or missing length; 0 = rigid.
    /// Default: 0.
    #[cfg_attr(feature = "serde", serde(default))]
    pub flex: f64,
    /// Smallest length a flexible segment may shrink to, metres. Default: half of
    /// `length_m` for flexible segments; rigid segments never shrink.
    #[cfg_attr(feature = "serde", serde(default))]
    pub min_m: Option<f64>,
    /// The interval's profile for layers that use it. Default: [`Profile::Off`].
    #[cfg_attr(feature = "serde", serde(default))]
    pub profile: Profile,
    /// Whether this segment is a storey (rows only). Default: false.
    #[cfg_attr(feature = "serde", serde(default))]
    pub floor: bool,
}

#[cfg_attr(not(feature = "serde"), allow(dead_code))]
fn default_name() -> String {
    "wall".into()
}

impl Segment {
    /// A rigid segment.
    pub fn rigid(name: &str, length_m: f64, profile: Profile) -> Self {
        Segment {
            name: name.into(),
            length_m,
            flex: 0.0,
            min_m: None,
            profile,
            floor: false,
        }
    }

    /// A flexible segment with weight 1.
    pub fn flexible(name: &str, length_m: f64, profile: Profile) -> Self {
        Segment {
            flex: 1.0,
            ..Segment::rigid(name, length_m, profile)
        }
    }

    /// Marks the segment as a storey.
    pub fn storey(mut self) -> Self {
        self.floor = true;
        self
    }

    /// Sets the minimum length.
    pub fn with_min(mut self, min_m: f64) -> Self {
        self.min_m = Some(min_m);
        self
    }

    /// The smallest length this segment may take, metres.
    pub fn min_len(&self) -> f64 {
        if self.flex > 0.0 {
            self.min_m.unwrap_or(self.length_m * 0.5).min(self.length_m)
        } else {
            self.length_m
        }
    }

    fn validate(&self, axis: &str) -> Result<()> {
        let bad = |reason: String| FacadeError::InvalidStyle {
            style: format!("{axis}/{}", self.name),
            reason,
        };
        if !(self.length_m.is_finite()
            && self.length_m >= MIN_SEGMENT_M
            && self.length_m <= MAX_LENGTH_M)
        {
            return Err(bad(format!(
                "length_m {} must be between {MIN_SEGMENT_M} and {MAX_LENGTH_M} m",
                self.length_m
            )));
        }
        if !(self.flex.is_finite() && self.flex >= 0.0) {
            return Err(bad(format!("flex {} must be finite and ≥ 0", self.flex)));
        }
        if let Some(m) = self.min_m
            && !(m.is_finite() && m >= MIN_SEGMENT_M)
        {
            return Err(bad(format!("min_m {m} must be ≥ {MIN_SEGMENT_M} m")));
        }
        self.profile.validate()
    }
}

/// One axis of a facade style (columns or rows): start segments, a repeated module, end
/// segments. See the [module docs](self) for the fitting rule.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct AxisStyle {
    /// Fixed segments at the start (left margin; plinth and ground floor for rows).
    /// Default: none.
    #[cfg_attr(feature = "serde", serde(default))]
    pub start: Vec<Segment>,
    /// The module repeated `n` times (a bay; a storey). Default: none.
    #[cfg_attr(feature = "serde", serde(default))]
    pub module: Vec<Segment>,
    /// Fixed segments at the end (right margin; cornice, attic). Default: none.
    #[cfg_attr(feature = "serde", serde(default))]
    pub end: Vec<Segment>,
    /// Fewest repetitions of the module. Default: 0.
    #[cfg_attr(feature = "serde", serde(default))]
    pub min_repeats: u32,
    /// Most repetitions of the module (`None`: unlimited). Default: `None`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub max_repeats: Option<u32>,
}

impl AxisStyle {
    /// Validates every segment and the repeat bounds.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] naming the bad segment.
    pub fn validate(&self, axis: &str) -> Result<()> {
        for s in self.start.iter().chain(&self.module).chain(&self.end) {
            s.validate(axis)?;
        }
        if self.start.is_empty() && self.module.is_empty() && self.end.is_empty() {
            return Err(FacadeError::InvalidStyle {
                style: axis.into(),
                reason: "an axis needs at least one segment".into(),
            });
        }
        if self.module.is_empty() && self.min_repeats > 0 {
            return Err(FacadeError::InvalidStyle {
                style: axis.into(),
                reason: "min_repeats > 0 needs a non-empty module".into(),
            });
        }
        if let Some(max) = self.max_repeats
            && max < self.min_repeats
        {
            return Err(FacadeError::InvalidStyle {
                style: axis.into(),
                reason: format!(
                    "max_repeats {max} is below min_repeats {}",
                    self.min_repeats
                ),
            });
        }
        Ok(())
    }

    fn fixed(&self) -> impl Iterator<Item = &Segment> {
        self.start.iter().chain(&self.end)
    }

    /// The fewest module repetitions: `min_repeats`, but at least 1 when the axis has no
    /// fixed segments (an axis must produce an interval).
    pub fn effective_min_repeats(&self) -> u32 {
        if self.start.is_empty() && self.end.is_empty() {
            self.min_repeats.max(1)
        } else {
            self.min_repeats
        }
    }

    /// The smallest length this axis can fill: every segment at its minimum with
    /// [`effective_min_repeats`](Self::effective_min_repeats) modules.
    pub fn min_length(&self) -> f64 {
        self.fixed().map(Segment::min_len).sum::<f64>()
            + f64::from(self.effective_min_repeats())
                * self.module.iter().map(Segment::min_len).sum::<f64>()
    }

    /// The nominal length with `n` modules.
    pub fn nominal_length(&self, n: u32) -> f64 {
        self.fixed().map(|s| s.length_m).sum::<f64>()
            + f64::from(n) * self.module.iter().map(|s| s.length_m).sum::<f64>()
    }

    /// Storeys contributed by the start and end segments.
    pub fn fixed_floors(&self) -> u32 {
        self.fixed().filter(|s| s.floor).count() as u32
    }

    /// Storeys per module repetition.
    pub fn module_floors(&self) -> u32 {
        self.module.iter().filter(|s| s.floor).count() as u32
    }

    /// The repetition count [`fit`](Self::fit) picks for `length` (see the module docs),
    /// preferring `wanted` when it fits.
    ///
    /// # Errors
    /// [`FacadeError::TooShort`] when `length` < [`min_length`](Self::min_length);
    /// [`FacadeError::TooManyIntervals`] when the count would exceed [`MAX_INTERVALS`].
    pub fn repeat_count(&self, length: f64, wanted: Option<u32>) -> Result<u32> {
        self.sums().repeat_count(length, wanted)
    }

    /// The sums [`repeat_count`](Self::repeat_count) reads, computed once for many fits.
    pub(crate) fn sums(&self) -> AxisSums {
        AxisSums {
            min_length: self.min_length(),
            module_min: self.module.iter().map(Segment::min_len).sum(),
            module_nom: self.module.iter().map(|s| s.length_m).sum(),
            fixed_min: self.fixed().map(Segment::min_len).sum(),
            fixed_nom: self.fixed().map(|s| s.length_m).sum(),
            module_len: self.module.len(),
            max_repeats: self.max_repeats,
            min_repeats: self.effective_min_repeats(),
            module_floors: self.module_floors(),
            fixed_floors: self.fixed_floors(),
        }
    }

    /// Fits the axis to `length` metres and returns its interval group (see module docs).
    ///
    /// `wanted` asks for a given number of module repetitions (e.g. a building's floor
    /// count); it is used when it fits between the style's bounds and the length, else the
    /// best-fitting count is used.
    ///
    /// # Errors
    /// [`FacadeError::TooShort`], [`FacadeError::TooManyIntervals`],
    /// [`FacadeError::InvalidStyle`], [`FacadeError::InvalidNumber`].
    pub fn fit(&self, length: f64, wanted: Option<u32>) -> Result<IntervalGroup> {
        self.validate("axis")?;
        let n = self.repeat_count(length, wanted)?;
        // The distinct segments with their multiplicity: the water filling works on these,
        // so it costs O(segments) however many modules there are.
        let mult: Vec<(&Segment, f64)> = self
            .start
            .iter()
            .map(|s| (s, 1.0))
            .chain(self.module.iter().map(|s| (s, f64::from(n))))
            .chain(self.end.iter().map(|s| (s, 1.0)))
            .collect();
        let any_flex = mult.iter().any(|(s, m)| s.flex > 0.0 && *m > 0.0);
        // Per-distinct-segment: (weight, min, nominal).
        let params: Vec<(f64, f64, f64)> = mult
            .iter()
            .map(|(s, _)| {
                if any_flex {
                    (s.flex, s.min_len(), s.length_m)
                } else {
                    // Uniform scaling: weight by length, and allow shrinking to the
                    // smallest size that still fits.
                    (s.length_m, s.min_len(), s.length_m)
                }
            })
            .collect();
        let lens = distribute(&mult, &params, length - self.nominal_length(n));
        let total = mult.len() - self.module.len() + self.module.len() * n as usize;
        let mut out = Vec::with_capacity(total);
        let mut at = 0.0;
        let mut push = |seg: &Segment, len: f64, part: Part, repeat: u32| {
            out.push(Interval {
                start: at,
                end: at + len,
                name: Arc::from(seg.name.as_str()),
                profile: seg.profile,
                part,
                repeat,
                floor: seg.floor,
            });
            at += len;
        };
        let ns = self.start.len();
        let nm = self.module.len();
        for (k, seg) in self.start.iter().enumerate() {
            push(seg, lens[k], Part::Start, 0);
        }
        for r in 0..n {
            for (k, seg) in self.module.iter().enumerate() {
                push(seg, lens[ns + k], Part::Repeat, r);
            }
        }
        for (k, seg) in self.end.iter().enumerate() {
            push(seg, lens[ns + nm + k], Part::End, 0);
        }
        if out.is_empty() {
            return Err(FacadeError::InvalidStyle {
                style: "axis".into(),
                reason:
                    "the axis produced no interval (module with zero repeats and no fixed segments)"
                        .into(),
            });
        }
        // Pin the end exactly to `length` (the sums drift by a few ulps).
        if let Some(last) = out.last_mut() {
            last.end = length;
        }
        IntervalGroup::from_intervals(out)
    }
}

/// Water filling: shares `delta` (metres, may be negative) among segments by weight,
/// never shrinking one below its minimum. `mult[k].1` is the multiplicity of segment k.
fn distribute(mult: &[(&Segment, f64)], params: &[(f64, f64, f64)], delta: f64) -> Vec<f64> {
    let mut lens: Vec<f64> = params.iter().map(|p| p.2).collect();
    let mut remaining = delta;
    let mut free: Vec<bool> = params
        .iter()
        .zip(mult)
        .map(|(p, (_, m))| p.0 > 0.0 && *m > 0.0)
        .collect();
    for _ in 0..=params.len() {
        if remaining.abs() < 1e-12 {
            break;
        }
        let w: f64 = params
            .iter()
            .zip(mult)
            .zip(&free)
            .filter(|(_, f)| **f)
            .map(|((p, (_, m)), _)| p.0 * m)
            .sum();
        if w <= 0.0 {
            break;
        }
        let per_weight = remaining / w;
        let mut used = 0.0;
        for k in 0..params.len() {
            if !free[k] {
                continue;
            }
            let (weight, min, _) = params[k];
            let m = mult[k].1;
            let want = lens[k] + per_weight * weight;
            let new = if want < min {
                free[k] = false;
                min
            } else {
                want
            };
            used += (new - lens[k]) * m;
            lens[k] = new;
        }
        remaining -= used;
    }
    lens
}

/// The per-style sums of an [`AxisStyle`] that fitting a length reads: computed once by
/// [`AxisStyle::sums`] (a prepared style keeps them) instead of once per face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AxisSums {
    /// [`AxisStyle::min_length`].
    min_length: f64,
    /// One module at its minimum and at its nominal length.
    module_min: f64,
    module_nom: f64,
    /// The start and end segments at their minimum and nominal lengths.
    fixed_min: f64,
    fixed_nom: f64,
    /// Segments per module.
    module_len: usize,
    max_repeats: Option<u32>,
    /// [`AxisStyle::effective_min_repeats`].
    min_repeats: u32,
    /// [`AxisStyle::module_floors`] and [`AxisStyle::fixed_floors`].
    module_floors: u32,
    fixed_floors: u32,
}

impl AxisSums {
    /// The module repetitions asked for by a face of `floors` storeys with these rows.
    pub(crate) fn wanted_rows(&self, floors: Option<u32>) -> Option<u32> {
        floors.and_then(|f| {
            let (per, fixed) = (self.module_floors, self.fixed_floors);
            (per > 0 && f >= fixed).then(|| (f - fixed) / per)
        })
    }

    /// [`AxisStyle::repeat_count`] from the sums.
    pub(crate) fn repeat_count(&self, length: f64, wanted: Option<u32>) -> Result<u32> {
        check_range("axis length", length, 0.0, MAX_LENGTH_M, "[0, 100000] m")?;
        let minimum = self.min_length;
        // A tolerance of a micrometre absorbs rounding in the sums.
        if length + 1e-6 < minimum {
            return Err(FacadeError::TooShort { length, minimum });
        }
        if self.module_len == 0 {
            return Ok(0);
        }
        let fit_max = ((length - self.fixed_min + 1e-6) / self.module_min)
            .floor()
            .max(0.0);
        let cap = (MAX_INTERVALS / self.module_len) as f64;
        let mut hi = fit_max.min(cap);
        if let Some(m) = self.max_repeats {
            hi = hi.min(f64::from(m));
        }
        let lo = f64::from(self.min_repeats);
        if fit_max > cap && hi >= cap {
            return Err(FacadeError::TooManyIntervals {
                count: (fit_max as usize).saturating_mul(self.module_len),
                limit: MAX_INTERVALS,
            });
        }
        let n = match wanted {
            Some(w) if f64::from(w) >= lo && f64::from(w) <= hi => f64::from(w),
            _ => ((length - self.fixed_nom) / self.module_nom)
                .round()
                .clamp(lo, hi.max(lo)),
        };
        Ok(n as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bays() -> AxisStyle {
        AxisStyle {
            start: vec![Segment::flexible("margin", 0.8, Profile::Off).with_min(0.3)],
            module: vec![
                Segment::flexible("pier", 0.5, Profile::Off).with_min(0.2),
                Segment::rigid("window", 1.2, Profile::Full),
                Segment::flexible("pier", 0.5, Profile::Off).with_min(0.2),
            ],
            end: vec![Segment::flexible("margin", 0.8, Profile::Off).with_min(0.3)],
            min_repeats: 1,
            max_repeats: None,
        }
    }

    #[test]
    fn fits_whole_windows() {
        let a = bays();
        assert!((a.min_length() - (0.6 + 1.6)).abs() < 1e-12);
        for len in [2.2, 3.0, 5.7, 10.0, 33.3, 100.0] {
            let g = a.fit(len, None).unwrap();
            g.check_invariants().unwrap();
            assert_eq!(g.length(), len);
            for iv in g.intervals().iter().filter(|iv| &*iv.name == "window") {
                assert!((iv.len() - 1.2).abs() < 1e-9, "window resized at L={len}");
                assert!(iv.start >= 0.0 && iv.end <= len);
            }
        }
        assert_eq!(a.fit(10.0, None).unwrap().repeat_count(), 4);
    }

    #[test]
    fn too_short_is_an_error() {
        assert!(matches!(
            bays().fit(2.0, None),
            Err(FacadeError::TooShort { .. })
        ));
    }

    #[test]
    fn wanted_count_used_when_it_fits() {
        let rows = AxisStyle {
            start: vec![Segment::flexible("ground", 4.0, Profile::Full).storey()],
            module: vec![
                Segment::flexible("floor", 3.0, Profile::Full)
                    .storey()
                    .with_min(2.4),
            ],
            end: vec![],
            min_repeats: 0,
            max_repeats: None,
        };
        let g = rows.fit(20.0, Some(6)).unwrap();
        assert_eq!(g.floor_count(), 7);
        // 20 m cannot hold 10 upper floors of ≥ 2.4 m after a ≥ 2 m ground floor.
        let g = rows.fit(20.0, Some(10)).unwrap();
        assert_eq!(g.repeat_count(), 5);
    }

    #[test]
    fn rigid_axes_scale_uniformly() {
        let a = AxisStyle {
            module: vec![Segment::rigid("tile", 2.0, Profile::Full)],
            min_repeats: 1,
            ..AxisStyle::default()
        };
        // Rigid-only modules: min length is exact, so the fit can only pick n with n·2 ≤ L
        // and scales up the tiles to cover L.
        let g = a.fit(7.0, None).unwrap();
        assert_eq!(g.len(), 3);
        for iv in g.intervals() {
            assert!((iv.len() - 7.0 / 3.0).abs() < 1e-9);
        }
    }
}
