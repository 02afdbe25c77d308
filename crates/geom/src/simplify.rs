//! [`simplify_ring`]: dropping the vertices of a ring that lie within a tolerance of the
//! chord between their kept neighbours (near-duplicate vertices, nearly straight runs).
//!
//! # Algorithm
//! From a vertex that is always kept (the lexicographically smallest, a hull vertex),
//! each step keeps the farthest vertex `m`, at most [`SIMPLIFY_MAX_RUN`] ahead, such that
//! every vertex between the last kept one `k` and `m` lies within the tolerance of the
//! segment `k–m`; vertices the caller marks as fixed are never skipped. The candidates
//! are screened by the sleeve of directions from `k` that pass within the tolerance of
//! every vertex so far (Zhao and Saalfeld's sleeve fitting), and each accepted chord is
//! confirmed by exact distances (Lang's criterion).
//!
//! # Guarantees
//! * Every dropped vertex lies within `tolerance` of the edge of the result that replaces
//!   it, so the result is within `tolerance` of the input (Hausdorff distance).
//! * Deterministic; about linear time on lots (each run is scanned until its sleeve
//!   closes), `O(n · SIMPLIFY_MAX_RUN)` screened steps at worst, plus the exact checks of
//!   the chords the sleeve admits.
//!
//! # Limitations
//! * The result is not checked for simplicity: a feature narrower than about twice the
//!   tolerance can fold; callers validate the result (and may keep the input).
//!
//! # References
//! T. Lang, *Rules for robot draughtsmen* (Geographical Magazine 42, 1969); Z. Zhao,
//! A. Saalfeld, *Linear-time sleeve-fitting polyline simplification algorithms*
//! (AutoCarto 13, 1997).

use glam::DVec2;

use crate::predicates::distance_to_segment;

/// The most consecutive vertices one kept edge of [`simplify_ring`] may replace (a bound
/// on the cost of pathological rings; straight runs of lots are far shorter).
pub const SIMPLIFY_MAX_RUN: usize = 1024;

/// The indices, ascending, of the vertices of the closed ring `points` to keep so that
/// every dropped vertex lies within `tolerance` of the chord replacing it; vertices with
/// `fixed(i)` are always kept. Fewer than 3 kept vertices means the ring has no extent
/// above the tolerance. A non-finite or negative `tolerance` keeps every vertex.
///
/// ```
/// use polis_geom::DVec2;
/// use polis_geom::simplify::simplify_ring;
/// let square_with_extras = [
///     DVec2::new(0.0, 0.0), DVec2::new(1e-12, 0.0), DVec2::new(5.0, 1e-4),
///     DVec2::new(10.0, 0.0), DVec2::new(10.0, 10.0), DVec2::new(0.0, 10.0),
/// ];
/// assert_eq!(simplify_ring(&square_with_extras, 1e-3, |_| false), vec![0, 3, 4, 5]);
/// ```
pub fn simplify_ring(
    points: &[DVec2],
    tolerance: f64,
    fixed: impl Fn(usize) -> bool,
) -> Vec<usize> {
    let n = points.len();
    if n <= 3 || !(tolerance.is_finite() && tolerance >= 0.0) {
        return (0..n).collect();
    }
    let start = (0..n)
        .min_by(|&a, &b| {
            let (p, q) = (points[a], points[b]);
            p.x.total_cmp(&q.x).then(p.y.total_cmp(&q.y))
        })
        .unwrap_or(0);
    let at = |k: usize| points[(start + k) % n];
    let mut kept = vec![start];
    let mut k = 0;
    while k < n {
        let best = farthest_chord(&at, k, n, tolerance, |j| fixed((start + j) % n));
        if best >= n {
            break;
        }
        kept.push((start + best) % n);
        k = best;
    }
    kept.sort_unstable();
    kept
}

/// From vertex `k` (positions `at(0..=n)`, `at(n)` = `at(0)`), the farthest `m` such that
/// every vertex strictly between lies within `tol` of the segment `at(k)–at(m)`: the
/// sleeve of directions from `at(k)` that pass within `tol` of every vertex so far is
/// narrowed vertex by vertex (an exact distance check confirms each chord), and the scan
/// stops when it is empty, at a fixed vertex, or after [`SIMPLIFY_MAX_RUN`] vertices.
fn farthest_chord(
    at: &impl Fn(usize) -> DVec2,
    k: usize,
    n: usize,
    tol: f64,
    fixed: impl Fn(usize) -> bool,
) -> usize {
    let a = at(k);
    // Chord ends the sleeve admits, in order; the farthest that passes the exact check
    // wins (rounding in the angles can admit one a hair too far).
    let mut admitted: Vec<usize> = Vec::new();
    // Directions as angles from the first vertex farther than `tol` (`None` until then).
    let mut reference: Option<DVec2> = None;
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut reach = 0.0f64;
    let mut m = k + 1;
    while m < n && m - k < SIMPLIFY_MAX_RUN {
        // Vertex m becomes an intermediate of the chords beyond it.
        if fixed(m) {
            break;
        }
        let d = at(m) - a;
        let r = d.length();
        reach = reach.max(r);
        if r > tol {
            let base = *reference.get_or_insert(d / r);
            let theta = base.perp_dot(d).atan2(base.dot(d));
            let half = (tol / r).asin();
            lo = lo.max(theta - half);
            hi = hi.min(theta + half);
            if lo > hi {
                break;
            }
        }
        let q = at(m + 1);
        let e = q - a;
        let inside = match reference {
            None => true,
            Some(base) => {
                let phi = base.perp_dot(e).atan2(base.dot(e));
                e.length() >= reach && phi >= lo && phi <= hi
            }
        };
        if inside {
            admitted.push(m + 1);
        }
        m += 1;
    }
    admitted
        .iter()
        .rev()
        .copied()
        .find(|&end| (k + 1..end).all(|j| distance_to_segment(at(j), a, at(end)) <= tol))
        .unwrap_or(k + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn fixed_vertices_and_short_rings_stay() {
        let pts = [v(0., 0.), v(5., 0.), v(10., 0.), v(10., 10.), v(0., 10.)];
        assert_eq!(simplify_ring(&pts, 0.1, |_| false), vec![0, 2, 3, 4]);
        assert_eq!(simplify_ring(&pts, 0.1, |i| i == 1), vec![0, 1, 2, 3, 4]);
        assert_eq!(simplify_ring(&pts[..3], 100.0, |_| false), vec![0, 1, 2]);
        assert_eq!(simplify_ring(&pts, f64::NAN, |_| false).len(), 5);
    }

    #[test]
    fn a_fine_circle_keeps_its_shape() {
        let n = 30_000;
        let pts: Vec<DVec2> = (0..n)
            .map(|i| DVec2::from_angle(std::f64::consts::TAU * i as f64 / n as f64) * 30.0)
            .collect();
        let kept = simplify_ring(&pts, 1e-3, |_| false);
        // Chords of 30 m radius within 1 mm: about 0.35 m long, ~540 of them.
        assert!(kept.len() < 1000, "{}", kept.len());
        assert!(kept.len() > 100);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]

        /// Every dropped vertex is within the tolerance of the kept edge that spans it.
        #[test]
        fn dropped_vertices_are_within_tolerance(
            raw in prop::collection::vec((-10.0f64..10.0, -10.0f64..10.0), 3..60),
            tol in prop_oneof![Just(0.0), Just(1e-3), 0.0f64..2.0],
            fixed_mod in 1usize..9,
        ) {
            let pts: Vec<DVec2> = raw.iter().map(|&(x, y)| v(x, y)).collect();
            let fixed = |i: usize| i.is_multiple_of(fixed_mod) && fixed_mod > 4;
            let kept = simplify_ring(&pts, tol, fixed);
            let n = pts.len();
            prop_assert!(kept.windows(2).all(|w| w[0] < w[1]));
            for i in (0..n).filter(|&i| fixed(i)) {
                prop_assert!(kept.contains(&i));
            }
            for (j, &a) in kept.iter().enumerate() {
                let b = kept[(j + 1) % kept.len()];
                let mut i = (a + 1) % n;
                while i != b {
                    let d = distance_to_segment(pts[i], pts[a], pts[b]);
                    prop_assert!(d <= tol, "vertex {} is {} from {}–{}", i, d, a, b);
                    i = (i + 1) % n;
                }
            }
        }
    }
}
