//! Interval groups: ordered, non-overlapping intervals covering `[0, L]`.
//!
//! "An interval group is a set of non-overlapping, ordered intervals. [...] rows and columns
//! can be changed by modifying single intervals" (Parish & Müller §4.3). Every interval
//! carries a name (its row or column kind: `"window"`, `"pier"`, `"ground"`, …) and a
//! [`Profile`]. Point location is a binary search over the interval starts: O(log n).

use std::sync::Arc;

use crate::error::{FacadeError, Result, check_range};
use crate::profile::Profile;
use crate::{MAX_INTERVALS, MAX_LENGTH_M};

/// Which part of an [`AxisStyle`](crate::AxisStyle) produced an interval.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Part {
    /// The fixed, irregular segments at the start (margins, plinth, ground floor).
    Start,
    /// The repeated module (bays, floors).
    Repeat,
    /// The fixed, irregular segments at the end (margins, cornice, attic).
    End,
}

/// One interval `[start, end)` of an [`IntervalGroup`] (the last one is closed at `L`).
#[derive(Debug, Clone, PartialEq)]
pub struct Interval {
    /// Start, metres from the group's origin.
    pub start: f64,
    /// End, metres; equals the next interval's start.
    pub end: f64,
    /// The row/column kind, used by selections (`"window"`, `"floor"`, …).
    pub name: Arc<str>,
    /// Where inside the interval a layer on this group is active.
    pub profile: Profile,
    /// Which part of the axis style produced it.
    pub part: Part,
    /// For [`Part::Repeat`], the index of the module repetition it belongs to; else 0.
    pub repeat: u32,
    /// Whether this interval is a storey (counts toward a facade's floor count).
    pub floor: bool,
}

impl Interval {
    /// Length in metres.
    #[inline]
    pub fn len(&self) -> f64 {
        self.end - self.start
    }

    /// Whether the interval is empty (never true in a valid group).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.end <= self.start
    }

    /// The absolute range `[a, b)` where this interval's profile is active.
    #[inline]
    pub fn active_range(&self) -> Option<(f64, f64)> {
        self.profile
            .active_range(self.len())
            .map(|(a, b)| (self.start + a, self.start + b))
    }
}

/// The result of locating a coordinate in an [`IntervalGroup`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Index of the interval.
    pub index: usize,
    /// The interval's start, metres.
    pub start: f64,
    /// The interval's end, metres.
    pub end: f64,
}

/// Ordered, non-overlapping intervals covering `[0, length]` without gaps.
///
/// Invariants (checked by [`check_invariants`](Self::check_invariants)): at least one
/// interval; the first starts at 0, the last ends at `length`; each ends where the next
/// starts; every interval has positive length.
#[derive(Debug, Clone, PartialEq)]
pub struct IntervalGroup {
    length: f64,
    starts: Vec<f64>,
    intervals: Vec<Interval>,
    /// Cached absolute active ranges of the profiles.
    active: Vec<Option<(f64, f64)>>,
}

impl IntervalGroup {
    /// Builds a group from consecutive `(length_m, name, profile)` pieces laid end to end
    /// from 0 (all [`Part::Start`], not floors). For groups that adapt to any length use
    /// [`AxisStyle::fit`](crate::AxisStyle::fit).
    ///
    /// # Errors
    /// [`FacadeError::InvalidNumber`] for a non-positive or non-finite length,
    /// [`FacadeError::InvalidStyle`] for no pieces or a bad profile.
    pub fn from_lengths<'a>(
        pieces: impl IntoIterator<Item = (f64, &'a str, Profile)>,
    ) -> Result<Self> {
        let mut out = Vec::new();
        let mut at = 0.0;
        for (len, name, profile) in pieces {
            check_range(
                "interval length",
                len,
                f64::MIN_POSITIVE,
                MAX_LENGTH_M,
                "(0, 100000] m",
            )?;
            profile.validate()?;
            out.push(Interval {
                start: at,
                end: at + len,
                name: Arc::from(name),
                profile,
                part: Part::Start,
                repeat: 0,
                floor: false,
            });
            at += len;
        }
        Self::from_intervals(out)
    }

    /// A group of one interval `[0, length]`.
    ///
    /// # Errors
    /// As [`from_lengths`](Self::from_lengths).
    pub fn single(length: f64, name: &str, profile: Profile) -> Result<Self> {
        Self::from_lengths([(length, name, profile)])
    }

    /// Builds a group from intervals, checking the invariants.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] if the intervals are empty, unordered, overlapping,
    /// gapped or do not start at 0; [`FacadeError::TooManyIntervals`] above
    /// [`MAX_INTERVALS`].
    pub fn from_intervals(intervals: Vec<Interval>) -> Result<Self> {
        if intervals.len() > MAX_INTERVALS {
            return Err(FacadeError::TooManyIntervals {
                count: intervals.len(),
                limit: MAX_INTERVALS,
            });
        }
        let length = intervals.last().map_or(0.0, |iv| iv.end);
        let group = IntervalGroup {
            length,
            starts: intervals.iter().map(|iv| iv.start).collect(),
            active: intervals.iter().map(Interval::active_range).collect(),
            intervals,
        };
        group.check_invariants()?;
        Ok(group)
    }

    /// Checks the invariants listed on the type.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] naming the first violation.
    pub fn check_invariants(&self) -> Result<()> {
        let fail = |reason: String| {
            Err(FacadeError::InvalidStyle {
                style: "interval group".into(),
                reason,
            })
        };
        let Some(first) = self.intervals.first() else {
            return fail("an interval group needs at least one interval".into());
        };
        if first.start != 0.0 {
            return fail(format!(
                "the first interval starts at {} instead of 0",
                first.start
            ));
        }
        if !(self.length.is_finite() && self.length > 0.0) {
            return fail(format!("length {} is not positive and finite", self.length));
        }
        for (k, iv) in self.intervals.iter().enumerate() {
            if !(iv.start.is_finite() && iv.end.is_finite() && iv.end > iv.start) {
                return fail(format!(
                    "interval {k} [{}, {}] is empty or not finite",
                    iv.start, iv.end
                ));
            }
            if let Some(next) = self.intervals.get(k + 1)
                && next.start != iv.end
            {
                return fail(format!(
                    "interval {k} ends at {} but the next starts at {}",
                    iv.end, next.start
                ));
            }
            if self.starts.get(k) != Some(&iv.start) {
                return fail("the start index is out of date".into());
            }
        }
        Ok(())
    }

    /// The covered length `L`, metres.
    #[inline]
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The intervals, in order.
    #[inline]
    pub fn intervals(&self) -> &[Interval] {
        &self.intervals
    }

    /// Number of intervals.
    #[inline]
    pub fn len(&self) -> usize {
        self.intervals.len()
    }

    /// Whether the group has no intervals (never true for a built group).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.intervals.is_empty()
    }

    /// The interval at `index`, if any.
    #[inline]
    pub fn get(&self, index: usize) -> Option<&Interval> {
        self.intervals.get(index)
    }

    /// Locates `x` (metres) by binary search: O(log n). `x = L` belongs to the last
    /// interval; `x` outside `[0, L]` or NaN gives `None`.
    #[inline]
    pub fn locate(&self, x: f64) -> Option<Hit> {
        if !(x >= 0.0 && x <= self.length) {
            return None;
        }
        let index = self.starts.partition_point(|&s| s <= x).checked_sub(1)?;
        self.hit(index)
    }

    /// Locates `x` starting from a cursor left by a previous call with a smaller or equal
    /// `x` (amortised O(1) for monotone sweeps, as in rasterisation). Falls back to binary
    /// search when `x` went backwards.
    #[inline]
    pub fn locate_from(&self, x: f64, cursor: &mut usize) -> Option<Hit> {
        if !(x >= 0.0 && x <= self.length) {
            return None;
        }
        let mut i = *cursor;
        match self.starts.get(i) {
            Some(&s) if s <= x => {
                while let Some(&next) = self.starts.get(i + 1) {
                    if next > x {
                        break;
                    }
                    i += 1;
                }
            }
            _ => i = self.starts.partition_point(|&s| s <= x).checked_sub(1)?,
        }
        *cursor = i;
        self.hit(i)
    }

    #[inline]
    fn hit(&self, index: usize) -> Option<Hit> {
        let iv = self.intervals.get(index)?;
        Some(Hit {
            index,
            start: iv.start,
            end: iv.end,
        })
    }

    /// The index range of intervals that overlap `[a, b]` (touching counts), O(log n).
    pub fn overlapping(&self, a: f64, b: f64) -> std::ops::Range<usize> {
        if a.is_nan() || b.is_nan() || a > b || b < 0.0 || a > self.length {
            return 0..0;
        }
        let lo = self.starts.partition_point(|&s| s < a).saturating_sub(1);
        let hi = self.starts.partition_point(|&s| s <= b);
        lo..hi.max(lo)
    }

    /// Indices of the intervals named `name`, in order.
    pub fn indices_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = usize> + 'a {
        self.intervals
            .iter()
            .enumerate()
            .filter(move |(_, iv)| &*iv.name == name)
            .map(|(i, _)| i)
    }

    /// Replaces the profile of every interval (used by layers that share a grid but need
    /// their own active area, e.g. a sill under the window column).
    pub fn with_profile(&self, profile: Profile) -> IntervalGroup {
        let mut g = self.clone();
        for iv in &mut g.intervals {
            iv.profile = profile;
        }
        g.active = g.intervals.iter().map(Interval::active_range).collect();
        g
    }

    /// The absolute active range of interval `index`'s profile (cached).
    #[inline]
    pub fn active(&self, index: usize) -> Option<(f64, f64)> {
        self.active.get(index).copied().flatten()
    }

    /// The profile value of interval `index` at absolute position `x`.
    #[inline]
    pub fn value(&self, index: usize, x: f64) -> f32 {
        match self.intervals.get(index) {
            Some(iv) if iv.profile.is_box() => match self.active(index) {
                Some((a, b)) if x >= a && x < b => 1.0,
                _ => 0.0,
            },
            Some(iv) => iv.profile.value(x - iv.start, iv.len()),
            None => 0.0,
        }
    }

    /// Number of intervals that are storeys.
    pub fn floor_count(&self) -> usize {
        self.intervals.iter().filter(|iv| iv.floor).count()
    }

    /// The range `[a, b)` covered by the intervals of one part, if present.
    pub fn part_range(&self, part: Part) -> Option<(f64, f64)> {
        let mut it = self.intervals.iter().filter(|iv| iv.part == part);
        let first = it.next()?;
        let last = it.next_back().unwrap_or(first);
        Some((first.start, last.end))
    }

    /// Number of module repetitions in the group (0 if it has no repeated part).
    pub fn repeat_count(&self) -> u32 {
        self.intervals
            .iter()
            .filter(|iv| iv.part == Part::Repeat)
            .map(|iv| iv.repeat + 1)
            .max()
            .unwrap_or(0)
    }

    /// Start and end of module repetition `k`, if present.
    pub fn repeat_range(&self, k: u32) -> Option<(f64, f64)> {
        let mut it = self
            .intervals
            .iter()
            .filter(|iv| iv.part == Part::Repeat && iv.repeat == k);
        let first = it.next()?;
        let last = it.next_back().unwrap_or(first);
        Some((first.start, last.end))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn group() -> IntervalGroup {
        IntervalGroup::from_lengths([
            (1.0, "margin", Profile::Off),
            (2.0, "window", Profile::Full),
            (0.5, "pier", Profile::Off),
            (2.0, "window", Profile::Full),
            (1.0, "margin", Profile::Off),
        ])
        .unwrap()
    }

    #[test]
    fn locate_by_binary_search() {
        let g = group();
        assert_eq!(g.length(), 6.5);
        assert_eq!(g.locate(0.0).unwrap().index, 0);
        assert_eq!(g.locate(0.999).unwrap().index, 0);
        assert_eq!(g.locate(1.0).unwrap().index, 1);
        assert_eq!(g.locate(3.2).unwrap().index, 2);
        assert_eq!(g.locate(6.5).unwrap().index, 4);
        assert!(g.locate(-0.01).is_none());
        assert!(g.locate(6.51).is_none());
        assert!(g.locate(f64::NAN).is_none());
    }

    #[test]
    fn cursor_matches_binary_search() {
        let g = group();
        let mut c = 0;
        for k in 0..=650 {
            let x = k as f64 * 0.01;
            assert_eq!(g.locate_from(x, &mut c), g.locate(x), "x={x}");
        }
        // Going backwards falls back to the binary search.
        assert_eq!(g.locate_from(0.5, &mut c), g.locate(0.5));
    }

    #[test]
    fn overlapping_ranges() {
        let g = group();
        assert_eq!(g.overlapping(0.5, 1.5), 0..2);
        assert_eq!(g.overlapping(3.0, 3.0), 1..3);
        assert_eq!(g.overlapping(-5.0, -1.0), 0..0);
        assert_eq!(g.overlapping(6.0, 100.0), 4..5);
        assert_eq!(g.indices_named("window").collect::<Vec<_>>(), vec![1, 3]);
    }

    #[test]
    fn invalid_groups_are_rejected() {
        assert!(IntervalGroup::from_lengths([]).is_err());
        assert!(IntervalGroup::from_lengths([(0.0, "x", Profile::Off)]).is_err());
        assert!(IntervalGroup::from_lengths([(f64::NAN, "x", Profile::Off)]).is_err());
        let mut ivs = group().intervals().to_vec();
        ivs[2].start += 0.1;
        assert!(IntervalGroup::from_intervals(ivs).is_err());
    }
}
