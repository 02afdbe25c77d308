//! Measures of shapes: the [minimum enclosing circle](min_enclosing_circle) of a point
//! set, and distances between [segments](segment_distance) and from a segment to a
//! [polygon](polygon_segment_distance).
//!
//! Every "do they meet" decision goes through the exact predicates
//! ([`segment_intersection`], [`Polygon::locate`]); distances are then `f64`
//! point–segment distances ([`distance_to_segment`]).

use glam::DVec2;

use crate::hash::splitmix64;
use crate::polygon::{PointLocation, Polygon};
use crate::predicates::{SegmentIntersection, distance_to_segment, segment_intersection};

/// A circle: centre and radius in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Circle {
    /// Centre.
    pub center: DVec2,
    /// Radius, metres (≥ 0).
    pub radius: f64,
}

impl Circle {
    /// Whether `p` lies in the closed disc, with a relative slack of 1e-12 of the radius
    /// plus 1e-9 m, so points on the circle that rounding puts a hair outside count as
    /// inside.
    pub fn contains(&self, p: DVec2) -> bool {
        self.center.distance(p) <= self.radius * (1.0 + 1e-12) + 1e-9
    }

    /// Area, m².
    pub fn area(&self) -> f64 {
        std::f64::consts::PI * self.radius * self.radius
    }
}

/// The smallest circle containing every finite point of `points` (non-finite points are
/// ignored); `None` when there is none.
///
/// Welzl's algorithm in its iterative move-through form: points are visited in a fixed
/// pseudo-random order (a SplitMix64 key per index, so the result is deterministic), and
/// each point outside the current circle restarts the search with that point on the
/// boundary; expected linear time.
///
/// # Guarantees
/// Every finite input point lies in the returned circle (up to [`Circle::contains`]'s
/// slack); the circle is the minimal one up to rounding. Collinear triples fall back to
/// the circle on their farthest pair, so the radius is never infinite or NaN.
///
/// # References
/// E. Welzl, *Smallest enclosing disks (balls and ellipsoids)*, LNCS 555 (1991).
pub fn min_enclosing_circle(points: &[DVec2]) -> Option<Circle> {
    let mut order: Vec<(u64, DVec2)> = points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.is_finite())
        .map(|(i, p)| (splitmix64(i as u64), *p))
        .collect();
    order.sort_unstable_by_key(|a| a.0);
    let pts: Vec<DVec2> = order.into_iter().map(|(_, p)| p).collect();
    let first = *pts.first()?;
    let mut c = Circle {
        center: first,
        radius: 0.0,
    };
    for i in 1..pts.len() {
        if c.contains(pts[i]) {
            continue;
        }
        c = Circle {
            center: pts[i],
            radius: 0.0,
        };
        for j in 0..i {
            if c.contains(pts[j]) {
                continue;
            }
            c = diameter_circle(pts[i], pts[j]);
            for k in 0..j {
                if !c.contains(pts[k]) {
                    c = circle_through(pts[i], pts[j], pts[k]);
                }
            }
        }
    }
    Some(c)
}

/// The circle with `a–b` as diameter.
fn diameter_circle(a: DVec2, b: DVec2) -> Circle {
    Circle {
        center: (a + b) * 0.5,
        radius: a.distance(b) * 0.5,
    }
}

/// The circle through three points; for (nearly) collinear points, the circle on the
/// farthest pair.
fn circle_through(a: DVec2, b: DVec2, c: DVec2) -> Circle {
    let (ab, ac) = (b - a, c - a);
    let d = 2.0 * ab.perp_dot(ac);
    let scale = ab.length_squared().max(ac.length_squared());
    if d.abs() > 1e-12 * scale && d.is_finite() {
        let (l1, l2) = (ab.length_squared(), ac.length_squared());
        let off = DVec2::new(ac.y * l1 - ab.y * l2, ab.x * l2 - ac.x * l1) / d;
        let center = a + off;
        let radius = center
            .distance(a)
            .max(center.distance(b))
            .max(center.distance(c));
        if center.is_finite() && radius.is_finite() {
            return Circle { center, radius };
        }
    }
    let candidates = [
        diameter_circle(a, b),
        diameter_circle(a, c),
        diameter_circle(b, c),
    ];
    candidates.into_iter().fold(
        candidates[0],
        |m, x| if x.radius > m.radius { x } else { m },
    )
}

/// Distance between the closed segments `a0–a1` and `b0–b1`: 0 when they meet (decided
/// exactly), else the smallest endpoint-to-segment distance.
pub fn segment_distance(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2) -> f64 {
    if !matches!(
        segment_intersection(a0, a1, b0, b1),
        SegmentIntersection::Disjoint
    ) {
        return 0.0;
    }
    distance_to_segment(a0, b0, b1)
        .min(distance_to_segment(a1, b0, b1))
        .min(distance_to_segment(b0, a0, a1))
        .min(distance_to_segment(b1, a0, a1))
}

/// Distance from the closed segment `a–b` to the closed polygon `poly` (its ring and
/// interior): 0 when the segment touches, crosses or lies in the polygon. An empty
/// polygon is infinitely far.
pub fn polygon_segment_distance(poly: &Polygon, a: DVec2, b: DVec2) -> f64 {
    if poly.is_empty() {
        return f64::INFINITY;
    }
    if poly.len() >= 3 && poly.locate(a) != PointLocation::Outside {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for (p, q) in poly.edges() {
        best = best.min(segment_distance(a, b, p, q));
        if best == 0.0 {
            break;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn circle_of_a_square_is_its_circumcircle() {
        let sq = [
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(0.0, 2.0),
            DVec2::new(1.0, 1.0),
        ];
        let c = min_enclosing_circle(&sq).unwrap();
        assert!((c.center - DVec2::new(1.0, 1.0)).length() < 1e-12);
        assert!((c.radius - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn degenerate_inputs() {
        assert_eq!(min_enclosing_circle(&[]), None);
        assert_eq!(min_enclosing_circle(&[DVec2::NAN]), None);
        let one = min_enclosing_circle(&[DVec2::new(3.0, 4.0)]).unwrap();
        assert_eq!(one.radius, 0.0);
        // Collinear points: the circle on the extreme pair.
        let line: Vec<DVec2> = (0..7)
            .map(|i| DVec2::new(i as f64, 2.0 * i as f64))
            .collect();
        let c = min_enclosing_circle(&line).unwrap();
        assert!((c.radius - line[0].distance(line[6]) / 2.0).abs() < 1e-9);
        // Repeated points.
        let c = min_enclosing_circle(&[DVec2::ONE; 5]).unwrap();
        assert_eq!(c.radius, 0.0);
    }

    #[test]
    fn segment_distances() {
        let o = DVec2::ZERO;
        let x = DVec2::new(10.0, 0.0);
        assert_eq!(
            segment_distance(o, x, DVec2::new(5.0, -1.0), DVec2::new(5.0, 1.0)),
            0.0
        );
        assert_eq!(
            segment_distance(o, x, DVec2::new(5.0, 2.0), DVec2::new(5.0, 7.0)),
            2.0
        );
        let sq = Polygon::rect(DVec2::new(0.0, 0.0), DVec2::new(4.0, 4.0));
        // Inside, crossing, outside.
        assert_eq!(
            polygon_segment_distance(&sq, DVec2::new(1.0, 1.0), DVec2::new(2.0, 2.0)),
            0.0
        );
        assert_eq!(
            polygon_segment_distance(&sq, DVec2::new(-1.0, 2.0), DVec2::new(9.0, 2.0)),
            0.0
        );
        assert_eq!(
            polygon_segment_distance(&sq, DVec2::new(7.0, -5.0), DVec2::new(7.0, 9.0)),
            3.0
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// The circle holds every point, and is no bigger than the circle on the box's
        /// diagonal (any enclosing circle's radius is at least half the diameter).
        #[test]
        fn enclosing_circle_contains_all_and_is_tight(
            pts in prop::collection::vec((-100.0f64..100.0, -100.0f64..100.0), 1..40)
        ) {
            let pts: Vec<DVec2> = pts.into_iter().map(|(x, y)| DVec2::new(x, y)).collect();
            let c = min_enclosing_circle(&pts).unwrap();
            for p in &pts {
                prop_assert!(c.center.distance(*p) <= c.radius * (1.0 + 1e-9) + 1e-7);
            }
            let mut diam: f64 = 0.0;
            for a in &pts { for b in &pts { diam = diam.max(a.distance(*b)); } }
            prop_assert!(c.radius >= diam / 2.0 - 1e-9);
            // Jung's theorem in the plane: r ≤ diameter / √3.
            prop_assert!(c.radius <= diam / 3f64.sqrt() + 1e-7);
        }
    }
}
