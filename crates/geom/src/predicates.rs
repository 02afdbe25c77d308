//! Exact geometric predicates and stable segment intersection.
//!
//! Every left/right/on decision in polis goes through [`orient2d`], which uses Shewchuk's
//! adaptive-precision determinant (the `robust` crate): the *sign* it returns is exact for
//! any finite input. Intersection *points* are then computed in floating point, but only
//! after the exact predicates have decided *whether* and *how* two segments meet, so the
//! topology never depends on rounding.

use glam::DVec2;

/// The turn direction of three points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Orientation {
    /// `c` lies to the left of the directed line `a → b`.
    CounterClockwise,
    /// `c` lies to the right of the directed line `a → b`.
    Clockwise,
    /// The three points lie on one line (exactly).
    Collinear,
}

#[inline]
fn coord(p: DVec2) -> robust::Coord<f64> {
    robust::Coord { x: p.x, y: p.y }
}

/// Twice the signed area of the triangle `a, b, c`, with an exactly correct sign.
///
/// Positive when `a, b, c` turn counter-clockwise, negative when clockwise, and exactly
/// zero when collinear. The magnitude is accurate to a few ulps.
///
/// The common case is decided inline: the plain floating-point determinant is returned
/// when it lies outside the proven error bound of Ozaki, Bünger, Ogita, Oishi and Rump
/// ("Simple floating-point filters for the two-dimensional orientation problem", BIT
/// 2016): with `l = (a.x − c.x)(b.y − c.y)` and `r = (a.y − c.y)(b.x − c.x)` computed in
/// binary64, the sign of `l − r` is correct whenever `|l − r| ≥ θ |l + r|`, θ just
/// under 3u (u = 2⁻⁵³), barring underflow. This is the same filter, with the same
/// determinant, that `robust::orient2d` applies first, so the value is the one it
/// returns; every input the filter does not decide goes to `robust::orient2d` whole
/// (its filter rejects it too, and its adaptive exact stages decide the sign).
#[inline(always)]
pub fn orient2d_value(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let left = (a.x - c.x) * (b.y - c.y);
    let right = (a.y - c.y) * (b.x - c.x);
    let det = left - right;
    let bound = ORIENT2D_FILTER * (left + right).abs();
    if det >= bound || -det >= bound {
        det
    } else {
        orient2d_exact(a, b, c)
    }
}

/// θ of the orientation filter in [`orient2d_value`] (Ozaki et al. 2016), as
/// `robust` 1.2 uses it.
const ORIENT2D_FILTER: f64 = 3.330_669_062_177_372_2e-16;

/// The adaptive exact orientation determinant, out of line: the rare inputs the filter
/// of [`orient2d_value`] leaves undecided.
#[cold]
#[inline(never)]
fn orient2d_exact(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    robust::orient2d(coord(a), coord(b), coord(c))
}

/// The exact orientation of `c` relative to the directed line `a → b`.
#[inline]
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> Orientation {
    let d = orient2d_value(a, b, c);
    if d > 0.0 {
        Orientation::CounterClockwise
    } else if d < 0.0 {
        Orientation::Clockwise
    } else {
        Orientation::Collinear
    }
}

/// Where the counter-clockwise angular order of [`ccw_cmp`] starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum AngleStart {
    /// At the positive x axis (angle 0), which comes first.
    #[default]
    East,
    /// At the negative y axis (straight down), which comes first.
    South,
}

/// Which half of the turn, from `start`, the direction `o → p` lies in: 0 for the first
/// half-turn (including `start` itself), 1 for the second. Exact; `p != o`.
#[inline]
fn half_turn(o: DVec2, p: DVec2, start: AngleStart) -> u8 {
    let first = match start {
        AngleStart::East => p.y > o.y || (p.y == o.y && p.x > o.x),
        AngleStart::South => p.x > o.x || (p.x == o.x && p.y < o.y),
    };
    u8::from(!first)
}

/// Compares the directions `o → p` and `o → q` by their angle measured counter-clockwise
/// from `start`, exactly: first by half-turn (coordinate comparisons), then by the exact
/// sign of [`orient2d`]. No angle is ever computed, so the order agrees with every other
/// predicate. `Equal` only for identical directions. `p` and `q` must differ from `o`.
///
/// This is the rotation order of [`PlanarGraph`](crate::PlanarGraph) adjacency lists
/// (`AngleStart::East`), and what face walks and the minimum cycle basis step along.
#[inline]
pub fn ccw_cmp(o: DVec2, p: DVec2, q: DVec2, start: AngleStart) -> std::cmp::Ordering {
    use std::cmp::Ordering;
    half_turn(o, p, start)
        .cmp(&half_turn(o, q, start))
        .then_with(|| match orient2d(o, p, q) {
            // q lies counter-clockwise of p (less than π further): p comes first.
            Orientation::CounterClockwise => Ordering::Less,
            Orientation::Clockwise => Ordering::Greater,
            Orientation::Collinear => Ordering::Equal,
        })
}

/// Whether `d` lies strictly inside the circle through `a, b, c` (given counter-clockwise).
/// Exact sign; returns `false` for points on the circle.
#[inline]
pub fn in_circle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    robust::incircle(coord(a), coord(b), coord(c), coord(d)) > 0.0
}

/// Whether `p` lies on the closed segment `a–b` (exact).
pub fn point_on_segment(p: DVec2, a: DVec2, b: DVec2) -> bool {
    within_box(p, a, b) && orient2d_value(a, b, p) == 0.0
}

/// Whether `p` lies in the axis-aligned box spanned by `a` and `b` (inclusive, exact).
#[inline]
fn within_box(p: DVec2, a: DVec2, b: DVec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// The point of segment `a–b` closest to `p`, and its parameter `t ∈ [0, 1]` along the segment.
///
/// A zero-length segment returns `(a, 0.0)`.
pub fn closest_point_on_segment(p: DVec2, a: DVec2, b: DVec2) -> (DVec2, f64) {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return (a, 0.0);
    }
    let t = ((p - a).dot(d) / len2).clamp(0.0, 1.0);
    (lerp_stable(a, b, t), t)
}

/// Distance from `p` to the closed segment `a–b`.
pub fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    closest_point_on_segment(p, a, b).0.distance(p)
}

/// `a + t (b - a)`, evaluated from the nearer end so that `t = 0` and `t = 1` give the
/// endpoints exactly and the error stays small near both.
#[inline]
pub fn lerp_stable(a: DVec2, b: DVec2, t: f64) -> DVec2 {
    if t <= 0.5 {
        a + (b - a) * t
    } else {
        b - (b - a) * (1.0 - t)
    }
}

/// How two closed segments `a0–a1` and `b0–b1` meet, decided exactly.
///
/// Parameters `t` (along `a`) and `u` (along `b`) are in `[0, 1]`. For [`Touching`]
/// results, a shared endpoint is returned bit-exactly, with `t`/`u` exactly `0` or `1` on
/// the segment it ends.
///
/// [`Touching`]: SegmentIntersection::Touching
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SegmentIntersection {
    /// The segments have no point in common.
    Disjoint,
    /// The segments cross at a single point interior to both.
    Crossing {
        /// The crossing point (computed stably; clamped to both segments' boxes).
        point: DVec2,
        /// Parameter along `a`, strictly between 0 and 1 in exact arithmetic.
        t: f64,
        /// Parameter along `b`, strictly between 0 and 1 in exact arithmetic.
        u: f64,
    },
    /// The segments share exactly one point, which is an endpoint of at least one of them.
    Touching {
        /// The shared point (an input endpoint, bit-exact).
        point: DVec2,
        /// Parameter along `a`.
        t: f64,
        /// Parameter along `b`.
        u: f64,
    },
    /// The segments are collinear and share a piece of positive length.
    Overlap {
        /// Start of the shared piece (an input endpoint), the end nearer `a0`.
        start: DVec2,
        /// End of the shared piece (an input endpoint), the end nearer `a1`.
        end: DVec2,
        /// Parameters of `start` and `end` along `a`.
        t: (f64, f64),
    },
}

impl SegmentIntersection {
    /// Whether the segments have any point in common.
    #[inline]
    pub fn intersects(&self) -> bool {
        !matches!(self, SegmentIntersection::Disjoint)
    }
}

/// Parameter of `p` along `a → b` (projection), clamped to `[0, 1]`, exact at the ends.
fn param(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    if p == a {
        return 0.0;
    }
    if p == b {
        return 1.0;
    }
    let d = b - a;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return 0.0;
    }
    ((p - a).dot(d) / len2).clamp(0.0, 1.0)
}

/// Classifies how the closed segments `a0–a1` and `b0–b1` meet. See [`SegmentIntersection`].
///
/// Zero-length segments are treated as points. All decisions use exact predicates.
pub fn segment_intersection(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2) -> SegmentIntersection {
    use SegmentIntersection::*;
    // Points as degenerate segments.
    if a0 == a1 || b0 == b1 {
        let (p, s0, s1, p_is_a) = if a0 == a1 {
            (a0, b0, b1, true)
        } else {
            (b0, a0, a1, false)
        };
        if point_on_segment(p, s0, s1) {
            let along = param(p, s0, s1);
            return if p_is_a {
                Touching {
                    point: p,
                    t: 0.0,
                    u: along,
                }
            } else {
                Touching {
                    point: p,
                    t: along,
                    u: 0.0,
                }
            };
        }
        return Disjoint;
    }
    // Quick reject on boxes (exact comparisons).
    if a0.x.max(a1.x) < b0.x.min(b1.x)
        || b0.x.max(b1.x) < a0.x.min(a1.x)
        || a0.y.max(a1.y) < b0.y.min(b1.y)
        || b0.y.max(b1.y) < a0.y.min(a1.y)
    {
        return Disjoint;
    }
    let o1 = orient2d_value(a0, a1, b0);
    let o2 = orient2d_value(a0, a1, b1);
    // `b` strictly on one side of `a`'s line: no need for the other two orientations.
    if (o1 > 0.0 && o2 > 0.0) || (o1 < 0.0 && o2 < 0.0) {
        return Disjoint;
    }
    let o3 = orient2d_value(b0, b1, a0);
    let o4 = orient2d_value(b0, b1, a1);
    if (o3 > 0.0 && o4 > 0.0) || (o3 < 0.0 && o4 < 0.0) {
        return Disjoint;
    }
    if o1 == 0.0 && o2 == 0.0 {
        return collinear_overlap(a0, a1, b0, b1);
    }
    if o1 != 0.0 && o2 != 0.0 && o3 != 0.0 && o4 != 0.0 {
        // Proper crossing: signs strictly opposite on both sides. The parameters come
        // from the edge vectors, `t = (w × db) / (da × db)`, whose rounding error scales
        // with the segments' own lengths. (`o3 / (o3 - o4)` would carry the error of the
        // orientation values, which are differences of products of distances to the far
        // segment: relative to a short segment crossed by a long one it grows as
        // long / short, and moved crossing points 1e-8 m off both lines; fuzzing finding
        // of issue 22.)
        let (da, db, w) = (a1 - a0, b1 - b0, b0 - a0);
        let den = da.perp_dot(db);
        let (t, u) = if den != 0.0 {
            (w.perp_dot(db) / den, w.perp_dot(da) / den)
        } else {
            // Exactly non-parallel, but the product rounds to 0: the orientation values.
            (o3 / (o3 - o4), o1 / (o1 - o2))
        };
        let (t, u) = (t.clamp(0.0, 1.0), u.clamp(0.0, 1.0));
        let mut p = lerp_stable(a0, a1, t);
        // Keep the point inside both segments' boxes despite rounding.
        let lo = a0.min(a1).max(b0.min(b1));
        let hi = a0.max(a1).min(b0.max(b1));
        p = p.clamp(lo, hi);
        return Crossing { point: p, t, u };
    }
    // Exactly one endpoint lies on the other segment's line: that endpoint is the contact.
    if o1 == 0.0 {
        Touching {
            point: b0,
            t: param(b0, a0, a1),
            u: 0.0,
        }
    } else if o2 == 0.0 {
        Touching {
            point: b1,
            t: param(b1, a0, a1),
            u: 1.0,
        }
    } else if o3 == 0.0 {
        Touching {
            point: a0,
            t: 0.0,
            u: param(a0, b0, b1),
        }
    } else {
        Touching {
            point: a1,
            t: 1.0,
            u: param(a1, b0, b1),
        }
    }
}

/// Overlap of two collinear, non-degenerate segments.
fn collinear_overlap(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2) -> SegmentIntersection {
    // Order along a's dominant axis: exact, since all four points are on one line.
    let d = a1 - a0;
    let key = |p: DVec2| {
        if d.x.abs() >= d.y.abs() {
            if d.x > 0.0 { p.x } else { -p.x }
        } else if d.y > 0.0 {
            p.y
        } else {
            -p.y
        }
    };
    let (ka0, ka1) = (key(a0), key(a1));
    let (bl, bh) = if key(b0) <= key(b1) {
        (b0, b1)
    } else {
        (b1, b0)
    };
    let start = if key(bl) > ka0 { bl } else { a0 };
    let end = if key(bh) < ka1 { bh } else { a1 };
    let (ks, ke) = (key(start), key(end));
    if ks > ke {
        SegmentIntersection::Disjoint
    } else if ks == ke {
        SegmentIntersection::Touching {
            point: start,
            t: param(start, a0, a1),
            u: param(start, b0, b1),
        }
    } else {
        SegmentIntersection::Overlap {
            start,
            end,
            t: (param(start, a0, a1), param(end, a0, a1)),
        }
    }
}

/// Whether the closed segments `a0–a1` and `b0–b1` have any point in common (exact).
#[inline]
pub fn segments_intersect(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2) -> bool {
    segment_intersection(a0, a1, b0, b1).intersects()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn orientation_basic() {
        assert_eq!(
            orient2d(v(0., 0.), v(1., 0.), v(0., 1.)),
            Orientation::CounterClockwise
        );
        assert_eq!(
            orient2d(v(0., 0.), v(1., 0.), v(0., -1.)),
            Orientation::Clockwise
        );
        assert_eq!(
            orient2d(v(0., 0.), v(1., 1.), v(3., 3.)),
            Orientation::Collinear
        );
    }

    #[test]
    fn orientation_is_exact_near_degenerate() {
        // Classic failure case for naive evaluation: points nearly on a line.
        let a = v(0.5, 0.5);
        let b = v(12.0, 12.0);
        let c = v(24.0, 24.0);
        assert_eq!(orient2d(a, b, c), Orientation::Collinear);
        let c2 = v(24.0, 24.0 + 1e-14);
        assert_eq!(orient2d(a, b, c2), Orientation::CounterClockwise);
    }

    #[test]
    fn ccw_order_of_eight_directions_from_east_and_south() {
        use std::cmp::Ordering;
        let o = v(1.0, 1.0);
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
        let pts: Vec<DVec2> = dirs.iter().map(|&(x, y)| o + v(x, y)).collect();
        for (i, &p) in pts.iter().enumerate() {
            for (j, &q) in pts.iter().enumerate() {
                assert_eq!(ccw_cmp(o, p, q, AngleStart::East), i.cmp(&j), "{i} vs {j}");
                // From the south, straight down (index 6) comes first.
                let (si, sj) = ((i + 2) % 8, (j + 2) % 8);
                assert_eq!(
                    ccw_cmp(o, p, q, AngleStart::South),
                    si.cmp(&sj),
                    "{i} vs {j}"
                );
            }
        }
        assert_eq!(
            ccw_cmp(o, o + v(2.0, 2.0), o + v(5.0, 5.0), AngleStart::East),
            Ordering::Equal
        );
    }

    #[test]
    fn ccw_order_tells_nearly_equal_directions_apart() {
        use std::cmp::Ordering;
        let o = DVec2::ZERO;
        let p = v(1.0, 1e-300);
        let q = v(1.0, 0.0);
        assert_eq!(ccw_cmp(o, q, p, AngleStart::East), Ordering::Less);
        let r = v(1.0, -1e-300);
        assert_eq!(ccw_cmp(o, p, r, AngleStart::East), Ordering::Less);
        assert_eq!(ccw_cmp(o, r, q, AngleStart::East), Ordering::Greater);
    }

    #[test]
    fn crossing() {
        match segment_intersection(v(0., 0.), v(2., 2.), v(0., 2.), v(2., 0.)) {
            SegmentIntersection::Crossing { point, t, u } => {
                assert_eq!(point, v(1., 1.));
                assert!((t - 0.5).abs() < 1e-15 && (u - 0.5).abs() < 1e-15);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn touching_t_junction_and_shared_end() {
        let r = segment_intersection(v(0., 0.), v(2., 0.), v(1., 0.), v(1., 5.));
        assert_eq!(
            r,
            SegmentIntersection::Touching {
                point: v(1., 0.),
                t: 0.5,
                u: 0.0
            }
        );
        let r = segment_intersection(v(0., 0.), v(2., 0.), v(2., 0.), v(3., 5.));
        assert!(
            matches!(r, SegmentIntersection::Touching { point, t, u } if point == v(2.,0.) && t == 1.0 && u == 0.0)
        );
    }

    #[test]
    fn collinear_cases() {
        let r = segment_intersection(v(0., 0.), v(4., 0.), v(2., 0.), v(6., 0.));
        assert_eq!(
            r,
            SegmentIntersection::Overlap {
                start: v(2., 0.),
                end: v(4., 0.),
                t: (0.5, 1.0)
            }
        );
        // Reversed b, overlap within.
        let r = segment_intersection(v(0., 0.), v(4., 0.), v(3., 0.), v(1., 0.));
        assert!(
            matches!(r, SegmentIntersection::Overlap { start, end, .. } if start == v(1.,0.) && end == v(3.,0.))
        );
        // End to end.
        let r = segment_intersection(v(0., 0.), v(1., 1.), v(1., 1.), v(2., 2.));
        assert!(matches!(r, SegmentIntersection::Touching { point, .. } if point == v(1.,1.)));
        // Collinear but apart.
        let r = segment_intersection(v(0., 0.), v(1., 1.), v(2., 2.), v(3., 3.));
        assert_eq!(r, SegmentIntersection::Disjoint);
    }

    #[test]
    fn degenerate_points() {
        let r = segment_intersection(v(1., 1.), v(1., 1.), v(0., 0.), v(2., 2.));
        assert!(matches!(r, SegmentIntersection::Touching { point, .. } if point == v(1.,1.)));
        let r = segment_intersection(v(1., 1.), v(1., 1.), v(1., 1.), v(1., 1.));
        assert!(r.intersects());
        let r = segment_intersection(v(1., 2.), v(1., 2.), v(0., 0.), v(2., 2.));
        assert_eq!(r, SegmentIntersection::Disjoint);
    }

    fn coordinate() -> impl Strategy<Value = f64> {
        // Small integer grids produce many exact degeneracies.
        prop_oneof![
            (-4i32..=4).prop_map(f64::from),
            -1e3f64..1e3,
            (-4i32..=4).prop_map(|i| f64::from(i) * 0.1),
        ]
    }
    fn point() -> impl Strategy<Value = DVec2> {
        (coordinate(), coordinate()).prop_map(|(x, y)| DVec2::new(x, y))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        #[test]
        fn symmetric_classification(a0 in point(), a1 in point(), b0 in point(), b1 in point()) {
            let r1 = segment_intersection(a0, a1, b0, b1);
            let r2 = segment_intersection(b0, b1, a0, a1);
            let kind = |r: &SegmentIntersection| std::mem::discriminant(r);
            prop_assert_eq!(kind(&r1), kind(&r2));
        }

        #[test]
        fn reported_points_lie_on_both(a0 in point(), a1 in point(), b0 in point(), b1 in point()) {
            match segment_intersection(a0, a1, b0, b1) {
                SegmentIntersection::Touching { point, .. } => {
                    prop_assert!(point_on_segment(point, a0, a1));
                    prop_assert!(point_on_segment(point, b0, b1));
                }
                SegmentIntersection::Crossing { point, .. } => {
                    let scale = 1.0 + a0.abs().max(a1.abs()).max(b0.abs()).max(b1.abs()).max_element();
                    prop_assert!(distance_to_segment(point, a0, a1) <= 1e-12 * scale);
                    prop_assert!(distance_to_segment(point, b0, b1) <= 1e-12 * scale);
                }
                SegmentIntersection::Overlap { start, end, .. } => {
                    prop_assert!(start != end);
                    for p in [start, end] {
                        prop_assert!(point_on_segment(p, a0, a1));
                        prop_assert!(point_on_segment(p, b0, b1));
                    }
                }
                SegmentIntersection::Disjoint => {
                    // No endpoint may lie on the other segment.
                    prop_assert!(!point_on_segment(a0, b0, b1) && !point_on_segment(a1, b0, b1));
                    prop_assert!(!point_on_segment(b0, a0, a1) && !point_on_segment(b1, a0, a1));
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(500))]
        /// A long segment crossed by a very short one (1 mm down to 1 nm): the crossing
        /// point is within a few units in the last place of both, not off by the long
        /// segment's rounding magnified by long / short.
        #[test]
        fn a_short_segment_crossing_a_long_one_is_met_within_rounding(
            a0 in point(), a1 in point(), s in 0.05f64..0.95, angle in 0.1f64..3.0,
            exponent in 3i32..9, along in 0.1f64..0.9,
        ) {
            prop_assume!(a0.distance(a1) > 1.0);
            let m = lerp_stable(a0, a1, s);
            let d = DVec2::from_angle(angle).rotate((a1 - a0).normalize()) * 10f64.powi(-exponent);
            let (b0, b1) = (m - d * along, m + d * (1.0 - along));
            if let SegmentIntersection::Crossing { point, .. } = segment_intersection(a0, a1, b0, b1) {
                let scale = a0.abs().max(a1.abs()).max_element().max(1.0);
                prop_assert!(distance_to_segment(point, a0, a1) <= 1e-14 * scale);
                prop_assert!(distance_to_segment(point, b0, b1) <= 1e-14 * scale);
            }
        }
    }

    /// The fuzzing finding behind the test above, exactly: the true crossing is
    /// (0.23076931113609508, -1.8846153111819532); the point was (0.2307692932603539,
    /// -1.8846153111819532), 1.8e-8 m away.
    #[test]
    fn crossing_of_an_11_m_segment_and_a_50_nm_piece() {
        let (a0, a1) = (v(-4.0, -3.999999909), v(6.000000091, 1.0));
        let (b0, b1) = (
            v(0.2307692932603539, -1.8846152620236674),
            v(0.2307693111360951, -1.8846153111819532),
        );
        let SegmentIntersection::Crossing { point, .. } = segment_intersection(a0, a1, b0, b1)
        else {
            panic!("a proper crossing");
        };
        assert!(point.distance(v(0.23076931113609508, -1.8846153111819532)) < 1e-15);
    }
}
