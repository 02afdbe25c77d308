//! [`Shape`]: what a spatial index stores under a key.

use glam::DVec2;

use super::SegmentNear;
use crate::bbox::Aabb2;
use crate::error::{GeomError, validate_point};
use crate::predicates::{closest_point_on_segment, orient2d_value};

/// A point or a closed segment, in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Shape {
    /// A point.
    Point(DVec2),
    /// The closed segment between two points (may be degenerate).
    Segment(DVec2, DVec2),
}

impl Shape {
    /// The bounding box.
    #[inline]
    pub fn bbox(&self) -> Aabb2 {
        match *self {
            Shape::Point(p) => Aabb2::new(p, p),
            Shape::Segment(a, b) => Aabb2::new(a, b),
        }
    }

    /// Checks that every coordinate is finite and within [`MAX_COORDINATE`](crate::MAX_COORDINATE).
    pub fn validate(&self) -> Result<(), GeomError> {
        match *self {
            Shape::Point(p) => validate_point(0, p),
            Shape::Segment(a, b) => {
                validate_point(0, a)?;
                validate_point(1, b)
            }
        }
    }

    /// Whether the shape shares a point with the closed box `b` (exact).
    pub fn intersects_box(&self, b: &Aabb2) -> bool {
        match *self {
            Shape::Point(p) => b.contains(p),
            Shape::Segment(s0, s1) => {
                if !Aabb2::new(s0, s1).intersects(b) {
                    return false;
                }
                // The boxes overlap: the segment misses the box only if all four corners
                // lie strictly on one side of its line (exact signs).
                let corners = [
                    b.min,
                    DVec2::new(b.max.x, b.min.y),
                    b.max,
                    DVec2::new(b.min.x, b.max.y),
                ];
                let mut pos = false;
                let mut neg = false;
                for c in corners {
                    let o = orient2d_value(s0, s1, c);
                    pos |= o >= 0.0;
                    neg |= o <= 0.0;
                }
                pos && neg
            }
        }
    }

    /// Distance data from `p` to this shape if it is a segment.
    pub(crate) fn segment_near<K>(&self, key: K, p: DVec2) -> Option<SegmentNear<K>> {
        match *self {
            Shape::Point(_) => None,
            Shape::Segment(a, b) => {
                let (closest, t) = closest_point_on_segment(p, a, b);
                Some(SegmentNear {
                    key,
                    distance: closest.distance(p),
                    closest,
                    t,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_box_exact() {
        let b = Aabb2::new(DVec2::new(0.0, 0.0), DVec2::new(1.0, 1.0));
        let s = |x0, y0, x1, y1| Shape::Segment(DVec2::new(x0, y0), DVec2::new(x1, y1));
        assert!(s(-1.0, 0.5, 2.0, 0.5).intersects_box(&b));
        // Diagonal passing exactly through the corner (1, 1).
        assert!(s(0.0, 2.0, 2.0, 0.0).intersects_box(&b));
        // Passing just outside the corner.
        assert!(!s(0.0, 2.0 + 1e-12, 2.0 + 1e-12, 0.0).intersects_box(&b));
        // Boxes overlap but the segment misses.
        assert!(!s(0.5, 3.0, 3.0, 0.5).intersects_box(&b));
        assert!(Shape::Point(DVec2::new(1.0, 0.0)).intersects_box(&b));
        assert!(!Shape::Point(DVec2::new(1.0, -0.1)).intersects_box(&b));
        // Degenerate box (a point) on the segment.
        let pb = Aabb2::new(DVec2::new(0.5, 0.5), DVec2::new(0.5, 0.5));
        assert!(s(0.0, 0.0, 1.0, 1.0).intersects_box(&pb));
        assert!(!s(0.0, 0.0, 1.0, 1.0 + 1e-9).intersects_box(&pb));
    }
}
