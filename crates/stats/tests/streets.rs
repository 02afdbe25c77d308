//! Street metrics: known results on hand-built graphs, bad input, and invariants on
//! random planar graphs.

#![allow(clippy::unwrap_used)]

use std::f64::consts::PI;

use polis_geom::{DVec2, PlanarGraph, SnapOptions};
use polis_stats::{
    CityInput, CityReport, StatsError, StatsOptions, StreetClass, StreetEdge, StreetGraph,
};
use proptest::prelude::*;

fn street(a: usize, b: usize) -> StreetEdge {
    StreetEdge {
        a,
        b,
        width_m: 10.0,
        class: StreetClass::Street,
        bridge: false,
    }
}

/// Graph from points and index pairs.
fn graph(nodes: Vec<DVec2>, edges: &[(usize, usize)]) -> StreetGraph {
    StreetGraph {
        nodes,
        elevations: None,
        edges: edges.iter().map(|&(a, b)| street(a, b)).collect(),
    }
}

fn run(g: &StreetGraph) -> CityReport {
    polis_stats::report(&CityInput::streets_only(g), &StatsOptions::default()).unwrap()
}

/// Every number of the report's JSON is finite (serde_json writes NaN as null; only the
/// optional parts may be null).
pub fn assert_all_finite(report: &CityReport) {
    fn walk(v: &serde_json::Value, path: &str) {
        match v {
            serde_json::Value::Null => {
                let optional = ["grade", "realism", "real", "band", "in_band"];
                assert!(
                    optional.iter().any(|k| path.ends_with(k)),
                    "null (NaN?) at {path}"
                );
            }
            serde_json::Value::Number(n) => {
                assert!(n.as_f64().is_some_and(f64::is_finite), "{path} = {n}")
            }
            serde_json::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, &format!("{path}[{i}]"));
                }
            }
            serde_json::Value::Object(o) => {
                for (k, x) in o {
                    walk(x, &format!("{path}.{k}"));
                }
            }
            _ => {}
        }
    }
    walk(&serde_json::to_value(report).unwrap(), "report");
}

/// Four horizontal and four vertical streets crossing, each running 50 m past the
/// outermost crossings: 16 four-way nodes, 16 dead ends, 40 segments of 50–100 m.
fn hash_grid() -> StreetGraph {
    let mut nodes = Vec::new();
    let mut id = std::collections::BTreeMap::new();
    let mut at = |x: i64, y: i64, nodes: &mut Vec<DVec2>| {
        *id.entry((x, y)).or_insert_with(|| {
            nodes.push(DVec2::new(x as f64, y as f64));
            nodes.len() - 1
        })
    };
    let mut edges = Vec::new();
    let stops = [-50, 0, 100, 200, 300, 350];
    for line in [0, 100, 200, 300] {
        for w in stops.windows(2) {
            let (a, b) = (at(w[0], line, &mut nodes), at(w[1], line, &mut nodes));
            edges.push((a, b));
            let (a, b) = (at(line, w[0], &mut nodes), at(line, w[1], &mut nodes));
            edges.push((a, b));
        }
    }
    graph(nodes, &edges)
}

#[test]
fn pure_grid_is_perfectly_ordered() {
    let r = run(&hash_grid()).streets;
    assert!(
        (r.orientation_order - 1.0).abs() < 1e-12,
        "{}",
        r.orientation_order
    );
    assert!((r.orientation_entropy - 4f64.ln()).abs() < 1e-12);
    assert!((r.weighted_orientation_entropy - 4f64.ln()).abs() < 1e-12);
    assert_eq!((r.nodes, r.streets), (32, 40));
    assert_eq!(r.share_4way, 0.5);
    assert_eq!(r.share_dead_end, 0.5);
    assert_eq!(r.share_3way, 0.0);
    assert_eq!(r.average_degree, 2.5);
    assert_eq!(r.circuity, 1.0);
    assert_eq!(r.segment_length_m.median, 100.0);
    // Four bins (N, E, S, W) hold a quarter of the bearings each.
    let full: Vec<usize> = (0..36)
        .filter(|&i| r.orientation_histogram[i] > 0.0)
        .collect();
    assert_eq!(full, vec![0, 9, 18, 27]);
    assert_eq!(r.intersections, 16);
}

#[test]
fn lattice_corners_merge_into_curved_streets() {
    // A 4 × 4 lattice of nodes, 100 m apart: the corners have degree 2 and merge.
    let mut nodes = Vec::new();
    for y in 0..4 {
        for x in 0..4 {
            nodes.push(DVec2::new(100.0 * x as f64, 100.0 * y as f64));
        }
    }
    let mut edges = Vec::new();
    for y in 0..4 {
        for x in 0..4 {
            let i = y * 4 + x;
            if x < 3 {
                edges.push((i, i + 1));
            }
            if y < 3 {
                edges.push((i, i + 4));
            }
        }
    }
    let r = run(&graph(nodes, &edges)).streets;
    assert_eq!((r.nodes, r.streets, r.segments), (12, 20, 24));
    assert!((r.average_degree - 40.0 / 12.0).abs() < 1e-12);
    assert!((r.share_4way - 4.0 / 12.0).abs() < 1e-12);
    assert!((r.share_3way - 8.0 / 12.0).abs() < 1e-12);
    assert_eq!(r.share_dead_end, 0.0);
    // The four corner streets are 200 m long with 141.4 m chords.
    let circuity = 2400.0 / (1600.0 + 4.0 * 100.0 * 2f64.sqrt());
    assert!((r.circuity - circuity).abs() < 1e-12);
    assert_eq!(r.segment_length_m.max, 200.0);
    assert_eq!(r.segment_length_m.median, 100.0);
    assert!((r.total_length_km - 2.4).abs() < 1e-12);
    // Bearings: 16 straight streets in 4 bins, 4 diagonals in the 45° / 135° bins.
    assert!(r.orientation_order < 1.0 && r.orientation_order > 0.8);
}

#[test]
fn tree_has_no_cycles_and_known_degrees() {
    // Root with three children, each with two leaves: 10 nodes, 9 streets.
    let mut nodes = vec![DVec2::ZERO];
    let mut edges = Vec::new();
    for k in 0..3 {
        let a = 2.0 * PI * k as f64 / 3.0;
        let child = DVec2::new(a.cos(), a.sin()) * 100.0;
        nodes.push(child);
        let c = nodes.len() - 1;
        edges.push((0, c));
        for s in [-0.5, 0.5] {
            let b = a + s;
            nodes.push(child + DVec2::new(b.cos(), b.sin()) * 60.0);
            edges.push((c, nodes.len() - 1));
        }
    }
    let r = run(&graph(nodes, &edges)).streets;
    assert_eq!((r.nodes, r.streets), (10, 9));
    assert!((r.average_degree - 1.8).abs() < 1e-12);
    assert!((r.share_dead_end - 0.6).abs() < 1e-12);
    assert!((r.share_3way - 0.4).abs() < 1e-12);
    assert!((r.circuity - 1.0).abs() < 1e-12);
    assert!((r.segment_length_m.median - 60.0).abs() < 1e-9);
    assert_eq!(r.intersections, 4);
}

/// A half circle of radius 100 m in `n` straight pieces.
fn half_circle(n: usize) -> StreetGraph {
    let nodes: Vec<DVec2> = (0..=n)
        .map(|i| {
            let a = PI * i as f64 / n as f64;
            DVec2::new(a.cos(), a.sin()) * 100.0
        })
        .collect();
    let edges: Vec<(usize, usize)> = (0..n).map(|i| (i, i + 1)).collect();
    graph(nodes, &edges)
}

#[test]
fn curved_road_keeps_its_arc_length() {
    // One street, two dead ends, whatever the number of pieces.
    for n in [2usize, 8, 64] {
        let r = run(&half_circle(n)).streets;
        assert_eq!((r.nodes, r.streets, r.segments), (2, 1, n));
        let expected = n as f64 * (PI / (2.0 * n as f64)).sin();
        assert!((r.circuity - expected).abs() < 1e-12, "{n}: {}", r.circuity);
        assert!((r.segment_length_m.median - 200.0 * expected).abs() < 1e-9);
        // The bearing is the chord's (east–west): two bins, φ of ln 2.
        assert!((r.orientation_entropy - 2f64.ln()).abs() < 1e-12);
    }
    // Many pieces approach π / 2.
    let r = run(&half_circle(2000)).streets;
    assert!((r.circuity - PI / 2.0).abs() < 1e-6);
}

#[test]
fn ring_of_degree_two_nodes_is_one_self_loop() {
    let n = 12;
    let nodes: Vec<DVec2> = (0..n)
        .map(|i| {
            let a = 2.0 * PI * i as f64 / n as f64;
            DVec2::new(a.cos(), a.sin()) * 50.0
        })
        .collect();
    let edges: Vec<(usize, usize)> = (0..n).map(|i| (i, (i + 1) % n)).collect();
    let report = run(&graph(nodes, &edges));
    let r = &report.streets;
    assert_eq!((r.nodes, r.streets, r.self_loops), (1, 1, 1));
    assert_eq!(r.average_degree, 2.0);
    // No straight-line distance, no bearing: zeros, not NaN.
    assert_eq!(r.circuity, 0.0);
    assert_eq!(r.orientation_order, 0.0);
    assert!(r.segment_length_m.median > 300.0);
    assert_all_finite(&report);
}

#[test]
fn grade_from_elevations() {
    // A T: 100 m rising 5 m, then 50 m rising 10 m, and a flat 50 m branch.
    let mut g = graph(
        vec![
            DVec2::ZERO,
            DVec2::new(100.0, 0.0),
            DVec2::new(100.0, 50.0),
            DVec2::new(100.0, -50.0),
        ],
        &[(0, 1), (1, 2), (1, 3)],
    );
    g.elevations = Some(vec![0.0, 5.0, 15.0, 5.0]);
    let grade = run(&g).streets.grade.unwrap();
    assert!((grade.max - 0.2).abs() < 1e-12);
    assert!((grade.median - 0.05).abs() < 1e-12);
    assert!((grade.mean_weighted - 15.0 / 200.0).abs() < 1e-12);
    assert!((grade.share_steeper_10pct - 0.25).abs() < 1e-12);
    assert!(run(&graph(vec![], &[])).streets.grade.is_none());
}

#[test]
fn empty_isolated_and_zero_length_give_zeros() {
    let empty = run(&StreetGraph::default());
    assert_eq!(empty.streets.nodes, 0);
    assert_eq!(empty.streets.average_degree, 0.0);
    assert_eq!(empty.streets.circuity, 0.0);
    assert_eq!(empty.buildings.coverage, 0.0);
    assert_all_finite(&empty);
    assert_all_finite(&empty.clone().compare_with("Paris").unwrap());

    let isolated = run(&graph(vec![DVec2::ZERO, DVec2::ONE, DVec2::X], &[]));
    assert_eq!(isolated.streets.isolated_nodes, 3);
    assert_eq!(isolated.streets.nodes, 0);
    assert_all_finite(&isolated);

    // Two nodes at one place joined by a zero-length edge, plus an edge a–a, plus a
    // street from the pair: the pair is one dead end.
    let p = DVec2::new(5.0, 5.0);
    let z = run(&graph(
        vec![p, p, DVec2::new(105.0, 5.0)],
        &[(0, 1), (1, 1), (1, 2)],
    ));
    assert_eq!(z.streets.zero_length_edges, 2);
    assert_eq!((z.streets.nodes, z.streets.streets), (2, 1));
    assert_eq!(z.streets.share_dead_end, 1.0);
    assert_eq!(z.streets.segment_length_m.median, 100.0);
    assert_all_finite(&z);
    // Only zero-length edges: one isolated node.
    let only_zero = run(&graph(vec![p, p], &[(0, 1)]));
    assert_eq!(only_zero.streets.isolated_nodes, 1);
    assert_all_finite(&only_zero);
}

#[test]
fn bad_input_is_a_typed_error() {
    let opt = StatsOptions::default();
    let nan = graph(vec![DVec2::new(f64::NAN, 0.0), DVec2::ONE], &[(0, 1)]);
    let err = polis_stats::report(&CityInput::streets_only(&nan), &opt).unwrap_err();
    assert!(matches!(err, StatsError::BadValue { .. }), "{err}");
    let missing = graph(vec![DVec2::ONE], &[(0, 3)]);
    let err = polis_stats::report(&CityInput::streets_only(&missing), &opt).unwrap_err();
    assert!(
        matches!(err, StatsError::NodeOutOfRange { node: 3, .. }),
        "{err}"
    );
    let mut w = graph(vec![DVec2::ZERO, DVec2::ONE], &[(0, 1)]);
    w.edges[0].width_m = -1.0;
    assert!(polis_stats::report(&CityInput::streets_only(&w), &opt).is_err());
    let mut z = graph(vec![DVec2::ZERO, DVec2::ONE], &[(0, 1)]);
    z.elevations = Some(vec![0.0]);
    let err = polis_stats::report(&CityInput::streets_only(&z), &opt).unwrap_err();
    assert!(matches!(err, StatsError::ElevationCount { .. }), "{err}");
    let far = graph(vec![DVec2::ZERO, DVec2::new(1e9, 0.0)], &[(0, 1)]);
    assert!(polis_stats::report(&CityInput::streets_only(&far), &opt).is_err());
    let bad_opt = StatsOptions {
        sample_step_m: 0.0,
        ..opt
    };
    assert!(polis_stats::report(&CityInput::streets_only(&w), &bad_opt).is_err());
}

/// Random planar graphs: random segments inserted into a planar graph (crossings split).
type Segment = ((f64, f64), (f64, f64));

fn planar_graph(segs: &[Segment]) -> StreetGraph {
    let mut pg: PlanarGraph<(), StreetClass> = PlanarGraph::new();
    for &((x0, y0), (x1, y1)) in segs {
        // Degenerate inserts are refused by the graph; that is fine here.
        let _ = pg.insert_segment(
            DVec2::new(x0, y0),
            DVec2::new(x1, y1),
            StreetClass::Street,
            &SnapOptions::default(),
        );
    }
    StreetGraph::from_planar(&pg, |c| (*c, 8.0))
}

fn coord() -> impl Strategy<Value = f64> {
    // A coarse lattice half the time, so collinear and axis-aligned cases are common.
    prop_oneof![
        (-5i32..=5).prop_map(|i| f64::from(i) * 40.0),
        -200.0f64..200.0,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(120))]

    #[test]
    fn metrics_are_finite_and_in_range(
        segs in prop::collection::vec(((coord(), coord()), (coord(), coord())), 0..25),
        extra_isolated in 0usize..3,
    ) {
        let mut g = planar_graph(&segs);
        for i in 0..extra_isolated {
            g.nodes.push(DVec2::new(1000.0 + i as f64, 0.0));
        }
        let report = run(&g);
        assert_all_finite(&report);
        let s = &report.streets;
        prop_assert!((0.0..=1.0).contains(&s.orientation_order));
        prop_assert!(s.orientation_entropy >= 0.0 && s.orientation_entropy <= 36f64.ln() + 1e-12);
        prop_assert!(s.weighted_orientation_entropy <= 36f64.ln() + 1e-12);
        let shares = s.share_dead_end + s.share_3way + s.share_4way + s.share_5plus;
        prop_assert!(shares <= 1.0 + 1e-12);
        prop_assert!(s.circuity == 0.0 || s.circuity >= 1.0 - 1e-12);
        prop_assert!(s.segment_length_m.min <= s.segment_length_m.median);
        prop_assert!(s.segment_length_m.median <= s.segment_length_m.max);
        prop_assert_eq!(s.isolated_nodes >= extra_isolated, true);
        // Simplification keeps the total length.
        let input_len: f64 = g.edges.iter().map(|e| g.nodes[e.a].distance(g.nodes[e.b])).sum();
        prop_assert!((s.total_length_km * 1000.0 - input_len).abs() <= 1e-9 * input_len.max(1.0));
        // Handshake: k̄ · n = 2 m.
        prop_assert!((s.average_degree * s.nodes as f64 - 2.0 * s.streets as f64).abs() < 1e-9);
        // The realism comparison never fails on a known city and stays finite.
        let cmp = report.clone().compare_with("Manhattan").unwrap();
        assert_all_finite(&cmp);
    }
}

/// Bridges are counted with their length, and the table names them; a graph without
/// bridge flags has none.
#[test]
fn bridges_are_counted() {
    let nodes = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(100.0, 0.0),
        DVec2::new(400.0, 0.0),
        DVec2::new(400.0, 30.0),
    ];
    let mut g = graph(nodes, &[(0, 1), (1, 2), (2, 3)]);
    assert_eq!(run(&g).streets.bridges, 0);
    g.edges[1].bridge = true;
    let r = run(&g);
    assert_eq!(r.streets.bridges, 1);
    assert!((r.streets.bridge_length_m - 300.0).abs() < 1e-9);
    assert!(r.to_string().contains("bridges"));
}
