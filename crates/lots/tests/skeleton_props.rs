//! Property tests: random polygons biased to degenerate cases, checked independently.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::*;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use polis_lots::{LotsError, StraightSkeleton, inset_shapes, skeleton};
use proptest::prelude::*;

/// Star-shaped polygons; with `grid`, vertices snap to integers (collinear runs, parallel
/// edges, simultaneous events).
fn star(n: usize, seeds: &[(f64, f64)], grid: bool) -> Polygon {
    let mut pts = Vec::new();
    for i in 0..n {
        let (da, r) = seeds[i % seeds.len()];
        let a = std::f64::consts::TAU * (i as f64 + 0.8 * da) / n as f64;
        let mut p = v(r * a.cos(), r * a.sin());
        if grid {
            p = p.round();
        }
        pts.push(p);
    }
    pts.dedup();
    Polygon::new(pts)
}

/// A histogram polygon on an integer grid: many reflex vertices, collinear runs and
/// parallel edges meeting at the same time.
fn histogram(heights: &[u8]) -> Polygon {
    let mut pts = vec![v(0., 0.), v(heights.len() as f64, 0.)];
    for (i, &h) in heights.iter().enumerate().rev() {
        let x1 = (i + 1) as f64;
        let x0 = i as f64;
        let h = h as f64 + 1.0;
        pts.push(v(x1, h));
        pts.push(v(x0, h));
    }
    let mut clean: Vec<DVec2> = Vec::new();
    for p in pts {
        if clean.last() != Some(&p) {
            clean.push(p);
        }
    }
    // Drop vertices in the middle of straight runs half of the time? Keep them: collinear
    // vertices are a case to test.
    Polygon::new(clean)
}

/// An orthogonal polygon with the profile `top` above `y = 1` and `bottom` below
/// `y = -1` (the band between is always inside): collinear runs and parallel edges on both
/// sides.
fn two_sided(top: &[u8], bottom: &[u8]) -> Polygon {
    let n = top.len().min(bottom.len());
    let mut pts = Vec::new();
    for (i, &b) in bottom.iter().enumerate().take(n) {
        let y = -f64::from(b) - 1.0;
        pts.push(v(i as f64, y));
        pts.push(v(i as f64 + 1.0, y));
    }
    for (i, &t) in top.iter().enumerate().take(n).rev() {
        let y = f64::from(t) + 1.0;
        pts.push(v(i as f64 + 1.0, y));
        pts.push(v(i as f64, y));
    }
    pts.dedup();
    Polygon::new(pts)
}

fn check_insets(
    p: &PolygonWithHoles,
    weights: Option<&[f64]>,
    sk: &StraightSkeleton,
) -> Result<(), TestCaseError> {
    let edges = input_edges(p);
    let w: Vec<f64> = weights.map_or_else(|| vec![1.0; edges.len()], |w| w.to_vec());
    let tmax = sk.max_time();
    let mut last_area = p.area();
    for k in 1..6 {
        let d = tmax * k as f64 / 5.5;
        let shapes = inset_shapes(p, weights, d).unwrap();
        let mut area = 0.0;
        for s in &shapes {
            let pw = s.to_polygon();
            prop_assert!(
                pw.validate().is_ok(),
                "inset at {} invalid: {:?}",
                d,
                pw.validate()
            );
            for (ring, _) in std::iter::once((&s.outer, ())).chain(s.holes.iter().map(|h| (h, ())))
            {
                let n = ring.points.len();
                for i in 0..n {
                    let (a, b) = (ring.points[i], ring.points[(i + 1) % n]);
                    prop_assert!(p.contains(a), "inset vertex {:?} outside", a);
                    if weights.is_none() {
                        // The straight skeleton's wavefront runs ahead of the Euclidean
                        // offset: every wavefront point is at least `d` from every edge.
                        for &(ea, eb) in &edges {
                            let dist = polis_geom::predicates::distance_to_segment(a, ea, eb);
                            prop_assert!(
                                dist >= d - 1e-7 * (1.0 + d),
                                "inset vertex {:?} only {} from an edge, d = {}",
                                a,
                                dist,
                                d
                            );
                        }
                    }
                    if let Some(e) = ring.sources[i] {
                        let (ea, eb) = edges[e];
                        for x in [a, b] {
                            let dist = line_distance(x, ea, eb);
                            prop_assert!(
                                (dist - d * w[e]).abs() < 1e-7 * (1.0 + d),
                                "distance {} want {}",
                                dist,
                                d * w[e]
                            );
                        }
                    }
                }
            }
            area += pw.area();
        }
        prop_assert!(
            area <= last_area + 1e-9 * p.area(),
            "area grew: {} > {}",
            area,
            last_area
        );
        last_area = area;
    }
    prop_assert!(
        inset_shapes(p, weights, tmax * 1.001 + 1e-9)
            .unwrap()
            .is_empty()
    );
    Ok(())
}

/// A simple polygon from random points by 2-opt untangling (general shapes, not only
/// star-shaped ones); `None` if it does not settle.
fn untangled(points: &[(i32, i32)]) -> Option<Polygon> {
    let mut pts: Vec<DVec2> = points.iter().map(|&(x, y)| v(x as f64, y as f64)).collect();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    // A deterministic shuffle.
    let n = pts.len();
    if n < 3 {
        return None;
    }
    for i in 0..n {
        pts.swap(i, (i * 7 + 3) % n);
    }
    for _ in 0..2000 {
        let mut changed = false;
        'outer: for i in 0..n {
            for j in i + 2..n {
                if i == 0 && j == n - 1 {
                    continue;
                }
                let (a0, a1) = (pts[i], pts[i + 1]);
                let (b0, b1) = (pts[j], pts[(j + 1) % n]);
                if polis_geom::predicates::segments_intersect(a0, a1, b0, b1) {
                    pts[i + 1..=j].reverse();
                    changed = true;
                    break 'outer;
                }
            }
        }
        if !changed {
            let mut p = Polygon::new(pts);
            p.make_ccw();
            return Some(p);
        }
    }
    None
}

/// The weighted skeleton with weights `ws` repeated over all edges (ring by ring),
/// checked independently, and its insets.
///
/// The one refusal allowed is the documented limitation of weighted steps enclosing a
/// region (`skeleton::STEPS_ENCLOSE`); its insets must be refused the same way.
fn check_weighted(p: &PolygonWithHoles, ws: &[f64]) -> Result<(), TestCaseError> {
    let count: usize = p.rings().map(|(_, r)| r.len()).sum();
    let w: Vec<f64> = (0..count).map(|i| ws[i % ws.len()]).collect();
    let sk = match StraightSkeleton::weighted(p, &w) {
        Ok(sk) => sk,
        Err(LotsError::SkeletonFailed { reason }) if reason == skeleton::STEPS_ENCLOSE => {
            // Insets after the region is enclosed are refused too.
            prop_assert!(inset_shapes(p, Some(&w), 1e6).is_err());
            return Ok(());
        }
        Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
    };
    if let Err(e) = check_skeleton(p, &sk, 1e-8) {
        prop_assert!(false, "{}", e);
    }
    check_insets(p, Some(&w), &sk)
}

/// Case count: 96 by default, `LOTS_CASES` to stress.
fn cases() -> u32 {
    std::env::var("LOTS_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(96)
}

/// Near-degenerate: a grid polygon with every vertex moved by up to `1e-9`.
fn jitter(p: &Polygon, seeds: &[(f64, f64)]) -> Polygon {
    p.map_points(|q| {
        let k = (q.x * 7.0 + q.y * 13.0).abs() as usize;
        let (a, b) = seeds[k % seeds.len()];
        q + v(a - 0.5, b - 0.5) * 2e-9
    })
}

/// A wheel: a rim vertex at radius 10 every `360 / sectors` degrees and, centred between
/// each pair, a notch `2 · half_deg` wide at radius `rim`; where `spokes` says so (bit `k`
/// for sector `k`), the notch runs in to a spoke tip at radius `tip`. Symmetric spokes'
/// reflex tips all reach the hub at the same moment: a vertex event of many chains.
fn wheel(sectors: usize, spokes: u64, rim: f64, half_deg: f64, tip: f64) -> Polygon {
    let at = |r: f64, deg: f64| {
        let a = deg.to_radians();
        v(r * a.cos(), r * a.sin())
    };
    let step = 360.0 / sectors as f64;
    let mut pts = Vec::new();
    for k in 0..sectors {
        let a = step * k as f64;
        let c = a + step / 2.0;
        pts.push(at(10.0, a));
        pts.push(at(rim, c - half_deg));
        if spokes >> (k % 64) & 1 == 1 {
            pts.push(at(tip, c));
        }
        pts.push(at(rim, c + half_deg));
    }
    Polygon::new(pts)
}

/// Reads a polygon in CGAL's `.poly` text format (`#` comments, the number of polygons,
/// then the vertex count and coordinates); the first polygon only.
fn read_poly(path: &str) -> Polygon {
    let text = std::fs::read_to_string(path).unwrap();
    let mut nums = text
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .flat_map(str::split_whitespace)
        .map(|s| s.parse::<f64>().unwrap());
    let _polygons = nums.next().unwrap();
    let n = nums.next().unwrap() as usize;
    let pts = (0..n)
        .map(|_| v(nums.next().unwrap(), nums.next().unwrap()))
        .collect();
    let mut p = Polygon::new(pts);
    p.make_ccw();
    p
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(),
        max_global_rejects: 1 << 20,
        ..ProptestConfig::default()
    })]

    #[test]
    fn random_stars(n in 3usize..40, seeds in prop::collection::vec((0.0f64..1.0, 2.0f64..20.0), 1..40), grid in any::<bool>()) {
        let p: PolygonWithHoles = star(n, &seeds, grid).into();
        prop_assume!(p.validate().is_ok() && p.outer.signed_area() > 0.0);
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }

    #[test]
    fn random_histograms(heights in prop::collection::vec(0u8..5, 1..24)) {
        let p: PolygonWithHoles = histogram(&heights).into();
        prop_assume!(p.validate().is_ok());
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-9) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }

    #[test]
    fn random_untangled(points in prop::collection::vec((-12i32..12, -12i32..12), 3..30), offset in prop_oneof![Just(0.0), Just(5000.0)]) {
        let Some(poly) = untangled(&points) else { return Ok(()); };
        let p: PolygonWithHoles = poly.translated(v(offset, -offset)).into();
        prop_assume!(p.validate().is_ok());
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }

    #[test]
    fn weighted_histograms(heights in prop::collection::vec(0u8..5, 1..16), ws in prop::collection::vec(prop_oneof![Just(1.0), Just(2.0), Just(0.5)], 1..8)) {
        let p: PolygonWithHoles = histogram(&heights).into();
        prop_assume!(p.validate().is_ok());
        let w: Vec<f64> = (0..p.outer.len()).map(|i| ws[i % ws.len()]).collect();
        // Should the event rules ever fail to resolve interacting weighted steps, the
        // result must be an error, never a wrong skeleton or a panic (none in 5,000 cases).
        let sk = match StraightSkeleton::weighted(&p, &w) {
            Ok(sk) => sk,
            Err(polis_lots::LotsError::SkeletonFailed { .. }) => return Ok(()),
            Err(e) => return Err(TestCaseError::fail(format!("{e}"))),
        };
        // Where parallel edges of different weights meet, the skeleton has weighted steps;
        // their arcs are checked against one of their two lines (see `check_skeleton`).
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, Some(&w), &sk)?;
    }

    /// Orthogonal polygons with a profile on both sides, rectangular holes in the middle
    /// band and a weight per edge from a small set: many parallel neighbours of different
    /// weights, so steps run into input edges, into holes and into each other.
    #[test]
    fn weighted_steps_interacting(
        top in prop::collection::vec(0u8..5, 1..12),
        bottom in prop::collection::vec(0u8..5, 12),
        holes in prop::collection::vec((0usize..12, any::<bool>()), 0..3),
        ws in prop::collection::vec(prop_oneof![Just(1.0), Just(2.0), Just(0.5), Just(3.0), Just(0.25)], 1..48),
    ) {
        let outer = two_sided(&top, &bottom);
        let mut hs = Vec::new();
        for (x, wide) in holes {
            let x = (x % top.len()) as f64;
            let mut r = Polygon::rect(v(x + 0.25, -0.5), v(x + if wide { 1.75 } else { 0.75 }, 0.5));
            r.reverse();
            hs.push(r);
        }
        let p = PolygonWithHoles::new(outer, hs);
        prop_assume!(p.validate().is_ok() && p.is_normalized());
        check_weighted(&p, &ws)?;
    }

    #[test]
    fn tiny_edges_and_nearly_collinear_runs(
        n in 3usize..24,
        seeds in prop::collection::vec((0.0f64..1.0, 5.0f64..20.0), 1..24),
        tweaks in prop::collection::vec((0usize..3, -10i32..-5), 24),
    ) {
        let base = star(n, &seeds, false);
        let mut pts = Vec::new();
        for (i, (a, b)) in base.edges().enumerate() {
            pts.push(a);
            let (kind, exp) = tweaks[i % tweaks.len()];
            let tiny = 10f64.powi(exp);
            match kind {
                // A vertex a hair's breadth after this one: a tiny edge.
                0 => pts.push(a + (b - a).normalize() * tiny * 10.0),
                // A nearly collinear midpoint.
                1 => pts.push((a + b) * 0.5 + (b - a).perp().normalize() * tiny),
                _ => {}
            }
        }
        let p: PolygonWithHoles = Polygon::new(pts).into();
        prop_assume!(p.validate().is_ok() && p.outer.signed_area() > 0.0);
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-7) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }

    #[test]
    fn weighted_with_holes(n in 3usize..12, seeds in prop::collection::vec((0.0f64..1.0, 25.0f64..40.0), 1..12), holes in prop::collection::vec((-8i32..8, -8i32..8, 1i32..4, 1i32..4), 1..4), ws in prop::collection::vec(0.3f64..3.0, 1..12)) {
        let outer = star(n, &seeds, false);
        let mut hs = Vec::new();
        for (x, y, w, h) in holes {
            let (x, y) = (x as f64 * 2.0, y as f64 * 2.0);
            // Diamonds, so that no hole edge is parallel to a neighbour.
            let c = v(x + 0.5 * w as f64, y + 0.5 * h as f64);
            hs.push(Polygon::new(vec![c + v(0.0, 1.0), c + v(1.0, 0.0), c + v(0.0, -1.0), c + v(-1.0, 0.0)]));
        }
        let p = PolygonWithHoles::new(outer, hs);
        prop_assume!(p.validate().is_ok() && p.is_normalized());
        check_weighted(&p, &ws)?;
    }

    #[test]
    fn histograms_with_holes(heights in prop::collection::vec(0u8..4, 2..12), holes in prop::collection::vec((0usize..12, 0u8..3, any::<bool>()), 1..5)) {
        let base = histogram(&heights).map_points(|q| q * 4.0 + v(0.0, 8.0 * f64::from(q.y > 0.0)));
        let mut hs = Vec::new();
        for (x, y, big) in holes {
            let x = (x % heights.len()) as f64 * 4.0 + 1.0;
            let y = f64::from(y) * 2.0 + 1.0;
            let size = if big { 2.0 } else { 1.0 };
            let mut r = Polygon::rect(v(x, y), v(x + size, y + size));
            r.reverse();
            hs.push(r);
        }
        let p = PolygonWithHoles::new(base, hs);
        prop_assume!(p.validate().is_ok() && p.is_normalized());
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-9) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }

    #[test]
    fn insets_exactly_at_event_times(heights in prop::collection::vec(0u8..5, 1..16)) {
        let p: PolygonWithHoles = histogram(&heights).into();
        prop_assume!(p.validate().is_ok());
        let sk = StraightSkeleton::new(&p).unwrap();
        let mut times: Vec<f64> = sk.nodes().iter().map(|n| n.time).filter(|&t| t > 0.0).collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        for t in times {
            for s in inset_shapes(&p, None, t).unwrap() {
                let pw = s.to_polygon();
                prop_assert!(pw.validate().is_ok(), "inset at event time {} invalid: {:?} {:?}", t, pw.validate(), pw);
            }
        }
    }

    #[test]
    fn near_degenerate_histograms(heights in prop::collection::vec(0u8..4, 1..16), seeds in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0), 1..8)) {
        let p: PolygonWithHoles = jitter(&histogram(&heights), &seeds).into();
        prop_assume!(p.validate().is_ok());
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }

    #[test]
    fn rotated_regular(n in 3usize..64, angle in 0.0f64..7.0, r in 0.1f64..1000.0) {
        let p: PolygonWithHoles = Polygon::regular(n, v(3.0, -2.0), r).map_points(|q| DVec2::from_angle(angle).rotate(q)).into();
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }

    #[test]
    fn random_weighted_stars(n in 3usize..24, seeds in prop::collection::vec((0.0f64..1.0, 4.0f64..20.0), 1..24), ws in prop::collection::vec(prop_oneof![Just(1.0), Just(2.0), 0.3f64..3.0], 24)) {
        let p: PolygonWithHoles = star(n, &seeds, false).into();
        prop_assume!(p.validate().is_ok());
        let w: Vec<f64> = (0..p.outer.len()).map(|i| ws[i % ws.len()]).collect();
        let sk = StraightSkeleton::weighted(&p, &w).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, Some(&w), &sk)?;
    }

    /// Wheels with spokes in any sectors, symmetric or not, any weights.
    #[test]
    fn weighted_wheels(
        sectors in 3usize..20,
        spokes in any::<u64>(),
        tip in 1.0f64..8.0,
        half_deg in 0.5f64..4.0,
        ws in prop::collection::vec(prop_oneof![Just(1.0), Just(2.0), Just(0.5), 0.3f64..3.0], 1..6),
    ) {
        let rim = 10.0 * (std::f64::consts::PI / sectors as f64).cos() - 0.01;
        let p: PolygonWithHoles = wheel(sectors, spokes, rim, half_deg.min(90.0 / sectors as f64), tip).into();
        prop_assume!(p.validate().is_ok());
        check_weighted(&p, &ws)?;
        // One odd weight on edge 0, the rest unit (the adversarial run's case).
        let mut w = vec![1.0; p.outer.len()];
        w[0] = ws[0] + 0.25;
        let sk = StraightSkeleton::weighted(&p, &w).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, Some(&w), &sk)?;
    }

    #[test]
    fn random_holes(n in 3usize..16, seeds in prop::collection::vec((0.0f64..1.0, 25.0f64..40.0), 1..16), holes in prop::collection::vec((-8i32..8, -8i32..8, 1i32..4, 1i32..4), 0..4)) {
        let outer = star(n, &seeds, true);
        let mut hs = Vec::new();
        for (x, y, w, h) in holes {
            let (x, y) = (x as f64 * 2.0, y as f64 * 2.0);
            let mut r = Polygon::rect(v(x, y), v(x + w as f64, y + h as f64));
            r.reverse();
            hs.push(r);
        }
        let p = PolygonWithHoles::new(outer, hs);
        prop_assume!(p.validate().is_ok() && p.is_normalized());
        let sk = StraightSkeleton::new(&p).unwrap();
        if let Err(e) = check_skeleton(&p, &sk, 1e-8) { prop_assert!(false, "{}", e); }
        check_insets(&p, None, &sk)?;
    }
}

/// Weighted steps that interact: an input edge runs head-on into a step (the top notch of
/// weight 2 falls onto the step left where two vertical edges of weights 2 and 0.5 became
/// neighbours), and two steps meet in line. The vertices left between two steps stand
/// still; their arcs used to be labelled with the steps' original neighbours, whose offset
/// lines they are not on.
#[test]
fn weighted_steps_meeting_edges_and_each_other() {
    for (heights, ws) in [
        (
            &[1u8, 0, 4, 4, 4, 1, 0, 1, 2, 0][..],
            &[0.5, 2.0, 0.5, 0.5][..],
        ),
        (&[2, 3, 2, 0, 2][..], &[2.0, 2.0, 0.5, 0.5, 0.5][..]),
        (&[4, 4, 1, 0, 1, 1, 0][..], &[0.5, 2.0, 0.5, 0.5][..]),
    ] {
        let p: PolygonWithHoles = histogram(heights).into();
        let w: Vec<f64> = (0..p.outer.len()).map(|i| ws[i % ws.len()]).collect();
        let sk = StraightSkeleton::weighted(&p, &w).unwrap();
        check_skeleton(&p, &sk, 1e-8).unwrap();
        check_insets(&p, Some(&w), &sk).unwrap();
    }
    // In the second polygon the two steps meet at (1.5, 5/3) at time 3/4, where edges 5
    // and 11 close below them, and stand there until edges 7 and 9 close above at time 1.
    let p: PolygonWithHoles = histogram(&[2, 3, 2, 0, 2]).into();
    let w = [2.0, 2.0, 0.5, 0.5, 0.5, 2.0, 2.0, 0.5, 0.5, 0.5, 2.0, 2.0];
    let sk = StraightSkeleton::weighted(&p, &w).unwrap();
    let standing = sk
        .arcs()
        .iter()
        .find(|a| {
            let (f, t) = (sk.nodes()[a.from], sk.nodes()[a.to]);
            f.position.distance(v(1.5, 5.0 / 3.0)) < 1e-12
                && (f.time - 0.75).abs() < 1e-12
                && (t.time - 1.0).abs() < 1e-12
        })
        .expect("the standing vertex's arc");
    assert!(standing.step);
    assert!([5, 11].contains(&standing.left_edge), "{standing:?}");
    assert!([7, 9].contains(&standing.right_edge), "{standing:?}");
}

/// Issue 22: on the wheel with 14 spokes (tests/data/wheel_14_spokes.poly, generated as
/// [`wheel`] describes), any non-unit weight on edge 0 made the spoke tips arrive at the
/// hub as separate pairwise events whose new vertices split each other at the hub
/// without end ("too many events" from distance 0.4044 on).
#[test]
fn weighted_wheel_with_14_spokes() {
    let file = read_poly(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/wheel_14_spokes.poly"
    ));
    let made = wheel(16, !(1 | 1 << 8), 9.816, 2.28, 5.0);
    assert_eq!(file.len(), made.len());
    for (a, b) in file.points().iter().zip(made.points()) {
        assert!(a.distance(*b) < 1e-12, "{a} {b}");
    }
    let p: PolygonWithHoles = file.into();
    let n = p.outer.len();
    for w0 in [0.5, 0.9, 1.0, 1.1, 2.0, 3.0] {
        let mut w = vec![1.0; n];
        w[0] = w0;
        let sk = StraightSkeleton::weighted(&p, &w).unwrap();
        check_skeleton(&p, &sk, 1e-8).unwrap();
        check_insets(&p, Some(&w), &sk).unwrap();
        for d in [0.404445, 0.405, 0.6, 1.0] {
            let inner = polis_lots::inset_weighted(&p, &w, d).unwrap();
            assert!(!inner.is_empty(), "w0 = {w0}, d = {d}");
        }
    }
}

/// The case of `weighted_steps_interacting` (found at 3,000 cases) where steps alone come
/// to enclose a 1.32 m × 0.5 m rectangle between t = 1.5 and 2: the edges that would have swept it
/// (31, 11) ran face to face into steps and were zipped away with them, leaving four
/// stationary vertices between steps. The skeleton is refused with its documented reason,
/// so are the insets after that moment (they used to return the rectangle at any distance,
/// even 100 m), and the insets before it are valid.
#[test]
fn steps_enclosing_a_region_are_refused() {
    let top = [3u8, 1, 0, 2, 3, 3, 3, 2, 3, 0, 1];
    let bottom = [2u8, 2, 0, 1, 0, 2, 0, 1, 0, 1, 0, 0];
    let mut holes = Vec::new();
    for (x, wide) in [(8.0, false), (2.0, true)] {
        let mut r = Polygon::rect(
            v(x + 0.25, -0.5),
            v(x + if wide { 1.75 } else { 0.75 }, 0.5),
        );
        r.reverse();
        holes.push(r);
    }
    let p = PolygonWithHoles::new(two_sided(&top, &bottom), holes);
    assert_eq!(p.validate(), Ok(()));
    let ws = [
        1.0, 0.5, 0.5, 2.0, 0.25, 3.0, 2.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 3.0, 1.0, 1.0, 0.25,
        0.25, 3.0, 1.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 0.5,
    ];
    let count: usize = p.rings().map(|(_, r)| r.len()).sum();
    let w: Vec<f64> = (0..count).map(|i| ws[i % ws.len()]).collect();
    assert_eq!(
        StraightSkeleton::weighted(&p, &w).err(),
        Some(LotsError::SkeletonFailed {
            reason: skeleton::STEPS_ENCLOSE
        })
    );
    for d in [0.5, 1.0, 1.5] {
        let shapes = inset_shapes(&p, Some(&w), d).unwrap();
        assert!(!shapes.is_empty());
        for s in &shapes {
            assert_eq!(s.to_polygon().validate(), Ok(()), "at {d}");
        }
    }
    for d in [2.0, 3.0, 100.0] {
        assert!(inset_shapes(&p, Some(&w), d).is_err(), "at {d}");
    }
}
