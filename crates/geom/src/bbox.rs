//! Axis-aligned bounding boxes.

use glam::DVec2;

/// An axis-aligned box in the XY plane, in metres.
///
/// The empty box has `min = +∞`, `max = −∞`; extending it with a point gives that point.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Aabb2 {
    /// Lower-left corner.
    pub min: DVec2,
    /// Upper-right corner.
    pub max: DVec2,
}

impl Default for Aabb2 {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb2 {
    /// The empty box: contains nothing, and is the identity of [`union`](Self::union).
    pub const EMPTY: Aabb2 = Aabb2 {
        min: DVec2::splat(f64::INFINITY),
        max: DVec2::splat(f64::NEG_INFINITY),
    };

    /// The box spanned by two corners (in any order).
    #[inline]
    pub fn new(a: DVec2, b: DVec2) -> Self {
        Aabb2 {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The smallest box containing all `points` (empty for no points).
    pub fn from_points(points: impl IntoIterator<Item = DVec2>) -> Self {
        let mut b = Self::EMPTY;
        for p in points {
            b.extend(p);
        }
        b
    }

    /// The smallest box containing the coordinates of all `points` along the axes `x`
    /// and `y` (`(p · x, p · y)`; empty for no points): an oriented bounding box in
    /// the frame those axes span, e.g. a footprint's box along its first edge.
    pub fn in_frame(points: impl IntoIterator<Item = DVec2>, x: DVec2, y: DVec2) -> Self {
        Self::from_points(points.into_iter().map(|p| DVec2::new(p.dot(x), p.dot(y))))
    }

    /// The smallest box containing all `points`, `None` when there are none or one is
    /// not finite (a NaN coordinate would otherwise vanish in `min`/`max`).
    pub fn of_finite_points(points: &[DVec2]) -> Option<Self> {
        let first = *points.first()?;
        let (lo, hi) = points
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        points
            .iter()
            .all(|p| p.is_finite())
            .then(|| Aabb2::new(lo, hi))
    }

    /// Whether the box contains no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y)
    }

    /// Grows the box to contain `p`.
    #[inline]
    pub fn extend(&mut self, p: DVec2) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The smallest box containing both.
    #[inline]
    pub fn union(&self, other: &Aabb2) -> Aabb2 {
        Aabb2 {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The overlap of both boxes (possibly empty).
    #[inline]
    pub fn intersection(&self, other: &Aabb2) -> Aabb2 {
        Aabb2 {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        }
    }

    /// Whether `p` lies in the closed box.
    #[inline]
    pub fn contains(&self, p: DVec2) -> bool {
        p.x >= self.min.x && p.x <= self.max.x && p.y >= self.min.y && p.y <= self.max.y
    }

    /// Whether the closed boxes share a point.
    #[inline]
    pub fn intersects(&self, other: &Aabb2) -> bool {
        self.min.x <= other.max.x
            && other.min.x <= self.max.x
            && self.min.y <= other.max.y
            && other.min.y <= self.max.y
    }

    /// The box grown by `margin` on every side (shrunk for negative margins).
    #[inline]
    pub fn expanded(&self, margin: f64) -> Aabb2 {
        Aabb2 {
            min: self.min - DVec2::splat(margin),
            max: self.max + DVec2::splat(margin),
        }
    }

    /// Width and height (zero for an empty box).
    #[inline]
    pub fn size(&self) -> DVec2 {
        if self.is_empty() {
            DVec2::ZERO
        } else {
            self.max - self.min
        }
    }

    /// Width (x extent).
    #[inline]
    pub fn width(&self) -> f64 {
        self.size().x
    }

    /// Height (y extent).
    #[inline]
    pub fn height(&self) -> f64 {
        self.size().y
    }

    /// The centre point.
    #[inline]
    pub fn center(&self) -> DVec2 {
        (self.min + self.max) * 0.5
    }

    /// Area in square metres (zero for an empty box).
    #[inline]
    pub fn area(&self) -> f64 {
        let s = self.size();
        s.x * s.y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn of_finite_points_refuses_none_and_non_finite() {
        let b = Aabb2::of_finite_points(&[DVec2::new(1.0, -2.0), DVec2::new(-3.0, 4.0)]).unwrap();
        assert_eq!(
            (b.min, b.max),
            (DVec2::new(-3.0, -2.0), DVec2::new(1.0, 4.0))
        );
        assert!(Aabb2::of_finite_points(&[]).is_none());
        assert!(Aabb2::of_finite_points(&[DVec2::ZERO, DVec2::new(f64::NAN, 0.0)]).is_none());
        assert!(Aabb2::of_finite_points(&[DVec2::new(f64::INFINITY, 0.0)]).is_none());
    }

    #[test]
    fn empty_and_extend() {
        let mut b = Aabb2::EMPTY;
        assert!(b.is_empty());
        assert_eq!(b.area(), 0.0);
        b.extend(DVec2::new(1.0, 2.0));
        assert!(!b.is_empty());
        b.extend(DVec2::new(-1.0, 5.0));
        assert_eq!(b.size(), DVec2::new(2.0, 3.0));
        assert!(b.contains(DVec2::new(0.0, 3.0)));
        assert!(!b.contains(DVec2::new(0.0, 6.0)));
        assert!(b.intersects(&Aabb2::new(DVec2::new(1.0, 5.0), DVec2::new(3.0, 9.0))));
        assert!(
            b.intersection(&Aabb2::new(DVec2::new(2.0, 5.0), DVec2::new(3.0, 9.0)))
                .is_empty()
        );
    }
}
