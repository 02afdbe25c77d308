//! The exact counter-clockwise order of directions around a point.
//!
//! Directions are compared without angles: first by half-plane (the upper half, including
//! the positive x axis, comes before the lower half, which includes the negative x axis),
//! then, inside one half-plane, by the exact sign of [`orient2d`]. Both steps are exact,
//! so the order never depends on rounding and agrees with the predicates used elsewhere.

use std::cmp::Ordering;

use glam::DVec2;

use crate::predicates::{Orientation, orient2d};

/// Which half-plane the direction `o → p` points into: 0 for angles in `[0, π)`, 1 for
/// `[π, 2π)`. The direction must be non-zero (`p != o`).
#[inline]
fn half(o: DVec2, p: DVec2) -> u8 {
    if p.y > o.y || (p.y == o.y && p.x > o.x) {
        0
    } else {
        1
    }
}

/// Compares the directions `o → p` and `o → q` by their angle measured counter-clockwise
/// from the positive x axis, exactly.
///
/// Returns `Equal` only when both directions are the same (collinear and on the same
/// side of `o`). `p` and `q` must differ from `o`.
pub(crate) fn ccw_cmp(o: DVec2, p: DVec2, q: DVec2) -> Ordering {
    match half(o, p).cmp(&half(o, q)) {
        Ordering::Equal => match orient2d(o, p, q) {
            // q lies counter-clockwise of p (less than π further): p comes first.
            Orientation::CounterClockwise => Ordering::Less,
            Orientation::Clockwise => Ordering::Greater,
            Orientation::Collinear => Ordering::Equal,
        },
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sorts_eight_directions_ccw_from_east() {
        let o = DVec2::new(1.0, 1.0);
        let dirs = [
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
        ];
        let pts: Vec<DVec2> = dirs.iter().map(|&(x, y)| o + DVec2::new(x, y)).collect();
        // Every pair compares as its angle does.
        for (i, &p) in pts.iter().enumerate() {
            for (j, &q) in pts.iter().enumerate() {
                assert_eq!(ccw_cmp(o, p, q), i.cmp(&j), "{i} vs {j}");
            }
        }
        // Same direction, different length: equal.
        assert_eq!(
            ccw_cmp(o, o + DVec2::new(2.0, 2.0), o + DVec2::new(5.0, 5.0)),
            Ordering::Equal
        );
    }

    #[test]
    fn nearly_equal_directions_are_told_apart() {
        let o = DVec2::ZERO;
        let p = DVec2::new(1.0, 1e-300);
        let q = DVec2::new(1.0, 0.0);
        assert_eq!(ccw_cmp(o, q, p), Ordering::Less);
        let r = DVec2::new(1.0, -1e-300);
        assert_eq!(ccw_cmp(o, p, r), Ordering::Less);
        assert_eq!(ccw_cmp(o, r, q), Ordering::Greater);
    }
}
