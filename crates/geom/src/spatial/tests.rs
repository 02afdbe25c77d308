//! Tests of both spatial-index backends against a brute-force scan.

use std::collections::BTreeMap;

use glam::DVec2;
use proptest::prelude::*;

use super::*;
use crate::predicates::{distance_to_segment, point_on_segment};

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// The reference: a plain map scanned in full for every query.
#[derive(Default)]
struct Brute(BTreeMap<u32, Shape>);

impl Brute {
    fn query_box(&self, b: &Aabb2) -> Vec<u32> {
        self.0
            .iter()
            .filter(|(_, s)| match **s {
                Shape::Point(p) => b.contains(p),
                Shape::Segment(s0, s1) => {
                    // Independent test: an end inside, or an intersection with a side.
                    let c = [b.min, v(b.max.x, b.min.y), b.max, v(b.min.x, b.max.y)];
                    b.contains(s0)
                        || b.contains(s1)
                        || (0..4).any(|i| segments_intersect_ref(s0, s1, c[i], c[(i + 1) % 4]))
                }
            })
            .map(|(&k, _)| k)
            .collect()
    }
    fn points_within(&self, p: DVec2, r: f64) -> Vec<(u32, f64)> {
        let mut out: Vec<(u32, f64)> = self
            .0
            .iter()
            .filter_map(|(&k, s)| match *s {
                Shape::Point(q) if q.distance(p) <= r => Some((k, q.distance(p))),
                _ => None,
            })
            .collect();
        out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        out
    }
    fn segments_within(&self, p: DVec2, r: f64) -> Vec<(u32, f64)> {
        let mut out: Vec<(u32, f64)> = self
            .0
            .iter()
            .filter_map(|(&k, s)| match *s {
                Shape::Segment(a, b) if distance_to_segment(p, a, b) <= r => {
                    Some((k, distance_to_segment(p, a, b)))
                }
                _ => None,
            })
            .collect();
        out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        out
    }
    fn crossing(&self, a: DVec2, b: DVec2) -> Vec<(u32, f64)> {
        let mut out: Vec<(u32, f64)> = self
            .0
            .iter()
            .filter_map(|(&k, s)| match *s {
                Shape::Segment(s0, s1) => classify_hit(k, a, b, s0, s1).map(|h| (k, h.t)),
                Shape::Point(_) => None,
            })
            .collect();
        out.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        out
    }
}

/// Whether two closed segments meet, by the textbook four-orientation test.
fn segments_intersect_ref(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2) -> bool {
    use crate::predicates::orient2d_value as o;
    let (d1, d2, d3, d4) = (o(a0, a1, b0), o(a0, a1, b1), o(b0, b1, a0), o(b0, b1, a1));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && point_on_segment(b0, a0, a1))
        || (d2 == 0.0 && point_on_segment(b1, a0, a1))
        || (d3 == 0.0 && point_on_segment(a0, b0, b1))
        || (d4 == 0.0 && point_on_segment(a1, b0, b1))
}

#[derive(Debug, Clone)]
enum Op {
    Insert(u32, Shape),
    Remove(u32),
}

fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => (-6i32..=6).prop_map(f64::from),
        2 => -40.0f64..40.0,
        1 => (-6i32..=6).prop_map(|i| f64::from(i) * 0.5 + 1e-9),
    ]
}

fn point() -> impl Strategy<Value = DVec2> {
    (coord(), coord()).prop_map(|(x, y)| v(x, y))
}

fn shape() -> impl Strategy<Value = Shape> {
    prop_oneof![
        1 => point().prop_map(Shape::Point),
        3 => (point(), point()).prop_map(|(a, b)| Shape::Segment(a, b)),
    ]
}

fn ops() -> impl Strategy<Value = Vec<Op>> {
    prop::collection::vec(
        prop_oneof![
            4 => (0u32..30, shape()).prop_map(|(k, s)| Op::Insert(k, s)),
            1 => (0u32..30).prop_map(Op::Remove),
        ],
        0..60,
    )
}

fn check_backend<I: SpatialIndex<u32>>(
    index: &mut I,
    ops: &[Op],
    queries: &[(DVec2, DVec2, f64)],
) -> Result<(), TestCaseError> {
    let mut brute = Brute::default();
    for op in ops {
        match *op {
            Op::Insert(k, s) => {
                prop_assert_eq!(index.insert(k, s).unwrap(), brute.0.insert(k, s));
            }
            Op::Remove(k) => prop_assert_eq!(index.remove(k), brute.0.remove(&k)),
        }
        prop_assert_eq!(index.len(), brute.0.len());
    }
    for &(a, b, r) in queries {
        let bx = Aabb2::new(a, b);
        prop_assert_eq!(index.query_box(&bx), brute.query_box(&bx));
        let pw: Vec<(u32, f64)> = index
            .points_within(a, r)
            .iter()
            .map(|n| (n.key, n.distance))
            .collect();
        prop_assert_eq!(&pw, &brute.points_within(a, r));
        prop_assert_eq!(
            index.nearest_point(a, r).map(|n| (n.key, n.distance)),
            pw.first().copied()
        );
        let sw: Vec<(u32, f64)> = index
            .segments_within(a, r)
            .iter()
            .map(|n| (n.key, n.distance))
            .collect();
        prop_assert_eq!(&sw, &brute.segments_within(a, r));
        prop_assert_eq!(
            index.nearest_segment(a, r).map(|n| (n.key, n.distance)),
            sw.first().copied()
        );
        let cr: Vec<(u32, f64)> = index
            .segments_crossing(a, b)
            .iter()
            .map(|h| (h.key, h.t))
            .collect();
        prop_assert_eq!(&cr, &brute.crossing(a, b));
        // The first crossing under a filter is the first of the sorted, filtered list.
        for m in [1, 2, 3] {
            let first = index
                .first_crossing(a, b, |h| h.key % m == 0)
                .map(|h| (h.key, h.t));
            prop_assert_eq!(first, cr.iter().copied().find(|&(k, _)| k % m == 0));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn grid_matches_brute_force(
        ops in ops(),
        queries in prop::collection::vec((point(), point(), prop_oneof![Just(0.0), 0.0f64..10.0]), 1..8),
        cell in prop_oneof![Just(0.5), Just(1.0), Just(3.0), Just(32.0)],
    ) {
        let mut g = GridIndex::new(GridOptions { cell_size: cell }).unwrap();
        check_backend(&mut g, &ops, &queries)?;
    }

    #[test]
    fn rtree_matches_brute_force(
        ops in ops(),
        queries in prop::collection::vec((point(), point(), prop_oneof![Just(0.0), 0.0f64..10.0]), 1..8),
    ) {
        let mut t = RTreeIndex::new();
        check_backend(&mut t, &ops, &queries)?;
    }
}

/// `for_each_candidate(_along)` report every key at most once, and every shape that
/// meets the query among them.
fn check_candidates_once(
    g: &GridIndex<u32>,
    brute: &Brute,
    a: DVec2,
    b: DVec2,
) -> Result<(), TestCaseError> {
    let mut along = Vec::new();
    g.for_each_candidate_along(a, b, |k, _| along.push(k));
    let mut boxed = Vec::new();
    let bx = Aabb2::new(a, b);
    g.for_each_candidate(&bx, |k, _| boxed.push(k));
    for (name, mut keys, must) in [
        (
            "along",
            along,
            brute.crossing(a, b).iter().map(|h| h.0).collect::<Vec<_>>(),
        ),
        ("box", boxed, brute.query_box(&bx)),
    ] {
        let n = keys.len();
        keys.sort_unstable();
        keys.dedup();
        prop_assert_eq!(keys.len(), n, "{} reported a key twice", name);
        for k in must {
            prop_assert!(keys.binary_search(&k).is_ok(), "{} missed {}", name, k);
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn grid_candidates_are_reported_once(
        ops in ops(),
        queries in prop::collection::vec((point(), point()), 1..8),
        cell in prop_oneof![Just(0.5), Just(1.0), Just(3.0), Just(32.0)],
    ) {
        let mut g = GridIndex::new(GridOptions { cell_size: cell }).unwrap();
        let mut brute = Brute::default();
        for op in &ops {
            match *op {
                Op::Insert(k, s) => {
                    g.insert(k, s).unwrap();
                    brute.0.insert(k, s);
                }
                Op::Remove(k) => {
                    g.remove(k);
                    brute.0.remove(&k);
                }
            }
        }
        for &(a, b) in &queries {
            check_candidates_once(&g, &brute, a, b)?;
        }
    }
}

#[test]
fn crossing_order_is_by_parameter_then_key() {
    let mut g = SegmentIndex::<u32>::default();
    // Three verticals crossing the x axis, one overlapping piece, one touching at the end.
    g.insert_segment(9, v(3.0, -1.0), v(3.0, 1.0)).unwrap();
    g.insert_segment(4, v(1.0, -1.0), v(1.0, 1.0)).unwrap();
    g.insert_segment(7, v(1.0, 0.0), v(1.0, 5.0)).unwrap(); // touches at t = 0.1
    g.insert_segment(2, v(5.0, 0.0), v(7.0, 0.0)).unwrap(); // overlap from t = 0.5
    g.insert_segment(5, v(10.0, 0.0), v(12.0, 3.0)).unwrap(); // touches the end
    g.insert_segment(6, v(0.0, 1.0), v(10.0, 1.0)).unwrap(); // parallel, misses
    g.insert_point(8, v(2.0, 0.0)).unwrap(); // points are not segments
    let hits = g.segments_crossing(v(0.0, 0.0), v(10.0, 0.0));
    let keys: Vec<u32> = hits.iter().map(|h| h.key).collect();
    assert_eq!(keys, vec![4, 7, 9, 2, 5]);
    assert!(matches!(hits[3].kind, SegmentIntersection::Overlap { .. }));
    assert_eq!(hits[4].t, 1.0);
}

#[test]
fn bad_input_is_refused_or_empty() {
    let mut g = SegmentIndex::<u32>::default();
    assert!(g.insert_point(1, v(f64::NAN, 0.0)).is_err());
    assert!(g.insert_segment(1, v(0.0, 0.0), v(1e12, 0.0)).is_err());
    assert!(g.is_empty());
    g.insert_segment(1, v(0.0, 0.0), v(1.0, 0.0)).unwrap();
    assert!(g.nearest_segment(v(f64::NAN, 0.0), 1.0).is_none());
    assert!(g.nearest_segment(v(0.0, 0.0), f64::NAN).is_none());
    assert!(g.nearest_segment(v(0.0, 0.0), -1.0).is_none());
    assert!(
        g.segments_crossing(v(f64::NAN, 0.0), v(1.0, 1.0))
            .is_empty()
    );
    assert!(g.query_box(&Aabb2::EMPTY).is_empty());
    // An infinite box or radius finds everything without trouble.
    let all = Aabb2::new(DVec2::splat(f64::NEG_INFINITY), DVec2::splat(f64::INFINITY));
    assert_eq!(g.query_box(&all), vec![1]);
    assert_eq!(
        g.nearest_segment(v(500.0, 0.0), f64::INFINITY)
            .map(|n| n.key),
        Some(1)
    );
    assert!(GridIndex::<u32>::new(GridOptions { cell_size: 0.0 }).is_err());
    assert!(
        GridIndex::<u32>::new(GridOptions {
            cell_size: f64::NAN
        })
        .is_err()
    );
}

#[test]
fn long_segment_far_from_origin() {
    // A segment crossing thousands of 1 m cells near the coordinate limit.
    let mut g = GridIndex::<u32>::new(GridOptions { cell_size: 1.0 }).unwrap();
    let a = v(9.0e7, 9.0e7);
    let b = v(9.0e7 + 2000.0, 9.0e7 + 1333.0);
    g.insert_segment(3, a, b).unwrap();
    let mid = (a + b) * 0.5;
    assert_eq!(
        g.nearest_segment(mid + v(0.0, 0.01), 0.1).map(|n| n.key),
        Some(3)
    );
    let hits = g.segments_crossing(mid + v(-1.0, 1.0), mid + v(1.0, -1.0));
    assert_eq!(hits.len(), 1);
    assert_eq!(g.remove(3), Some(Shape::Segment(a, b)));
    assert_eq!(g.occupied_cells(), 0);
}

#[test]
fn very_long_segments_live_outside_the_cells() {
    // 10 km on 1 m cells: kept in the list of big segments, found by every query kind.
    let mut g = GridIndex::<u32>::new(GridOptions { cell_size: 1.0 }).unwrap();
    g.insert_segment(1, v(0.0, 0.0), v(10_000.0, 5_000.0))
        .unwrap();
    g.insert_segment(2, v(100.0, 49.0), v(100.0, 52.0)).unwrap();
    assert_eq!(g.occupied_cells(), 4);
    let b = Aabb2::new(v(99.0, 48.0), v(101.0, 53.0));
    assert_eq!(g.query_box(&b), vec![1, 2]);
    // Far from every small segment: outside the occupied extent, still found.
    assert_eq!(
        g.query_box(&Aabb2::new(v(8000.0, 3990.0), v(8010.0, 4010.0))),
        vec![1]
    );
    assert_eq!(
        g.nearest_segment(v(6000.0, 3000.5), 1.0).map(|n| n.key),
        Some(1)
    );
    let hits = g.segments_crossing(v(99.0, 52.0), v(101.0, 49.0));
    assert_eq!(hits.iter().map(|h| h.key).collect::<Vec<_>>(), vec![2, 1]);
    assert_eq!(
        g.remove(1),
        Some(Shape::Segment(v(0.0, 0.0), v(10_000.0, 5_000.0)))
    );
    assert_eq!(g.query_box(&b), vec![2]);
    assert_eq!(g.len(), 1);
}
