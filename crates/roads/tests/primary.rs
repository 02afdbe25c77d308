//! The primary network (Kelly §4.2, §5.3): plotting properties, validity checking,
//! planarity under random edits, undo byte for byte, sources and the low-level graph.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::sync::Arc;

use polis_geom::field::{Constant, Fbm, FbmParams, FnField};
use polis_geom::{Aabb2, DVec2, FieldExt};
use polis_roads::RoadInputs;
use polis_roads::legality::Illegal;
use polis_roads::primary::{
    AdaptiveParams, ControlId, Correction, Edit, EditLog, EditOptions, Endpoint, PrimaryEditor,
    PrimaryError, PrimaryNetwork, PrimarySpec, RoadId, RoadPreset, RoadSpec, Terrain,
    path_from_plot, plot, plot_path,
};
use proptest::prelude::*;

const HALF: f64 = 2000.0;

fn bounds() -> Aabb2 {
    Aabb2::new(DVec2::splat(-HALF), DVec2::splat(HALF))
}

/// fBm hills up to about ±60 m.
fn hills(seed: u64) -> Terrain {
    let f = Fbm::new(FbmParams {
        seed,
        octaves: 4,
        wavelength_m: 900.0,
        ..FbmParams::default()
    })
    .unwrap()
    .scaled(60.0);
    Terrain::with_elevation(f.shared(), bounds()).unwrap()
}

/// Hills, a river along x ≈ 600 m and a park around (−900, 900).
fn landscape(seed: u64) -> Terrain {
    let mut inputs = RoadInputs::flat(Arc::new(Constant(1.0)));
    inputs.elevation = Fbm::new(FbmParams {
        seed,
        octaves: 3,
        wavelength_m: 800.0,
        ..FbmParams::default()
    })
    .unwrap()
    .scaled(50.0)
    .shared();
    inputs.water = Arc::new(FnField::new(|p: DVec2| {
        f64::from((p.x - 600.0 - 0.05 * p.y).abs() < 40.0)
    }));
    inputs.parks = Arc::new(FnField::new(|p: DVec2| {
        f64::from(p.distance(DVec2::new(-900.0, 900.0)) < 250.0)
    }));
    Terrain::new(&inputs, bounds()).unwrap()
}

fn strategy() -> impl proptest::strategy::Strategy<Value = polis_roads::primary::Strategy> {
    prop_oneof![
        Just(polis_roads::primary::Strategy::Straight),
        Just(polis_roads::primary::Strategy::MinimumElevation),
        Just(polis_roads::primary::Strategy::MinimumElevationDifference),
        Just(polis_roads::primary::Strategy::EvenElevationDifference),
    ]
}

fn params() -> impl Strategy<Value = AdaptiveParams> {
    (
        strategy(),
        10.0..300.0f64,
        1u32..10,
        0.0..44.9f64,
        1.0001..1.6f64,
    )
        .prop_map(|(s, d, n, dev, k)| AdaptiveParams {
            strategy: s,
            sample_size_m: d,
            samples: n,
            deviation_deg: dev,
            snap_m: d * dev.to_radians().cos() * k,
            segment_draw_size_m: 10.0,
            max_bridge_m: 300.0,
        })
}

fn point() -> impl Strategy<Value = DVec2> {
    (-1900.0..1900.0f64, -1900.0..1900.0f64).prop_map(|(x, y)| DVec2::new(x, y))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// plot(a → b) == reverse(plot(b → a)), bit for bit, failures included; the path too.
    #[test]
    fn plotting_commutes(a in point(), b in point(), p in params(), seed in 0u64..4) {
        let t = landscape(seed);
        let ab = plot(a, b, &p, &t);
        let ba = plot(b, a, &p, &t);
        match (ab, ba) {
            (Ok(x), Ok(y)) => {
                let mut rev = y.points.clone();
                rev.reverse();
                prop_assert_eq!(&x.points, &rev);
                let mut rb = y.bridge.clone();
                rb.reverse();
                prop_assert_eq!(&x.bridge, &rb);
                let pa = plot_path(a, b, &p, &t).unwrap();
                let pb = plot_path(b, a, &p, &t).unwrap();
                prop_assert_eq!(pa, pb.reversed());
            }
            (Err(x), Err(y)) => prop_assert_eq!(std::mem::discriminant(&x), std::mem::discriminant(&y)),
            (x, y) => prop_assert!(false, "{x:?} vs {y:?}"),
        }
    }

    /// Plotting ends on any terrain the fields make (steep, spiky, undefined patches), with
    /// steps of `d_sample` and a join within `d_snap`; the spline passes through every plot
    /// point.
    #[test]
    fn plotting_terminates_and_the_spline_hits_every_plot_point(
        a in point(), b in point(), p in params(), amp in 0.0..5000.0f64, freq in 0.0..0.2f64, holes in any::<bool>(),
    ) {
        let f = FnField::new(move |q: DVec2| {
            let v = amp * (q.x * freq).sin() * (q.y * freq * 0.7).cos();
            if holes && (q.x * 0.01).sin() > 0.995 { f64::NAN } else { v }
        });
        let t = Terrain::with_elevation(Arc::new(f), bounds()).unwrap();
        match plot(a, b, &p, &t) {
            Ok(pl) => {
                prop_assert_eq!(pl.points.first(), Some(&a));
                prop_assert_eq!(pl.points.last(), Some(&b));
                let n = pl.points.len();
                prop_assert_eq!(pl.bridge.len(), n - 1);
                let max_bound = p.sample_size_m.max(p.snap_m) * (1.0 + 1e-9);
                // Every step is d_sample long; only the join may be longer (heads that turned
                // away are dropped before it).
                let long = pl.points.windows(2).filter(|w| w[0].distance(w[1]) > max_bound).count();
                prop_assert!(long <= 1, "{long} long steps");
                if let Ok(path) = path_from_plot(&pl, p.segment_draw_size_m, &t) {
                    let mut distinct = pl.points.clone();
                    distinct.dedup();
                    prop_assert_eq!(path.plot.len(), distinct.len());
                    for (k, &i) in path.plot.iter().enumerate() {
                        prop_assert_eq!(path.points[i as usize], distinct[k]);
                    }
                }
            }
            Err(PrimaryError::Blocked { what: Illegal::Outside, .. }
                | PrimaryError::OutsideMap { .. }) => prop_assert!(holes),
            Err(e) => prop_assert!(false, "{e}"),
        }
    }
}

/// One random edit, in terms of the current network.
#[derive(Debug, Clone)]
enum Op {
    Road(DVec2, DVec2),
    Chain(usize, DVec2),
    Connect(usize, usize),
    Move(usize, DVec2),
    DeleteNode(usize),
    DeleteRoad(usize),
    Node(DVec2),
    Set(usize, u8),
}

fn op() -> impl Strategy<Value = Op> {
    let q = || (-1500.0..1500.0f64, -1500.0..1500.0f64).prop_map(|(x, y)| DVec2::new(x, y));
    prop_oneof![
        4 => (q(), q()).prop_map(|(a, b)| Op::Road(a, b)),
        2 => (any::<usize>(), q()).prop_map(|(i, b)| Op::Chain(i, b)),
        2 => (any::<usize>(), any::<usize>()).prop_map(|(i, j)| Op::Connect(i, j)),
        4 => (any::<usize>(), q()).prop_map(|(i, b)| Op::Move(i, b)),
        1 => any::<usize>().prop_map(Op::DeleteNode),
        1 => any::<usize>().prop_map(Op::DeleteRoad),
        1 => q().prop_map(Op::Node),
        1 => (any::<usize>(), 0u8..3).prop_map(|(i, k)| Op::Set(i, k)),
    ]
}

fn spec(k: u8) -> RoadSpec {
    let mut s = RoadPreset::ALL[k as usize % 3].spec();
    // Smaller samples so roads bend within the test map.
    s.params.sample_size_m = s.params.sample_size_m.min(260.0) * 0.5;
    s.params.snap_m = s.params.sample_size_m;
    s.params.segment_draw_size_m = 20.0;
    s
}

fn to_edit(net: &PrimaryNetwork, op: &Op) -> Option<Edit> {
    let nodes: Vec<ControlId> = net.nodes().map(|(id, _)| id).collect();
    let roads: Vec<RoadId> = net.roads().map(|(id, _)| id).collect();
    let pick_n = |i: usize| (!nodes.is_empty()).then(|| nodes[i % nodes.len()]);
    let pick_r = |i: usize| (!roads.is_empty()).then(|| roads[i % roads.len()]);
    Some(match *op {
        Op::Road(a, b) => Edit::AddRoad {
            from: Endpoint::At(a),
            to: Endpoint::At(b),
            spec: spec(1),
        },
        Op::Chain(i, b) => Edit::Chain {
            from: pick_n(i)?,
            to: b,
            spec: spec(2),
        },
        Op::Connect(i, j) => Edit::AddRoad {
            from: Endpoint::Node(pick_n(i)?),
            to: Endpoint::Node(pick_n(j)?),
            spec: spec(1),
        },
        Op::Move(i, to) => Edit::MoveNode {
            node: pick_n(i)?,
            to,
        },
        Op::DeleteNode(i) => Edit::DeleteNode { node: pick_n(i)? },
        Op::DeleteRoad(i) => Edit::DeleteRoad { road: pick_r(i)? },
        Op::Node(at) => Edit::AddNode {
            at,
            label: Some("x".into()),
        },
        Op::Set(i, k) => Edit::SetRoad {
            road: pick_r(i)?,
            spec: spec(k),
        },
    })
}

fn check_planar(net: &PrimaryNetwork) {
    net.check_invariants().unwrap();
    let low = net.to_road_network().unwrap();
    low.network.check_invariants().unwrap();
    // Every edge maps back to a live road.
    for (e, _, _, _) in low.network.edges() {
        net.road(low.road_of(e).unwrap()).unwrap();
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// After any sequence of edits (crossing roads, moves that would cross, deletions) both
    /// graphs are planar; a refused edit changes nothing; undoing everything restores the
    /// serialised network byte for byte; redo and replay give the final network again.
    #[test]
    fn random_edits_keep_both_graphs_planar_and_undo_exactly(ops in prop::collection::vec(op(), 1..14), seed in 0u64..3) {
        let t = hills(seed);
        let mut ed = PrimaryEditor::new(t.clone(), EditOptions::default()).unwrap();
        let start = ed.network().to_json().unwrap();
        let mut states = vec![start.clone()];
        for o in &ops {
            let Some(edit) = to_edit(ed.network(), o) else { continue };
            let before = ed.network().to_json().unwrap();
            match ed.propose(&edit) {
                Ok(p) => {
                    let changes = ed.commit(&p).unwrap();
                    prop_assert_eq!(&changes, p.changes());
                    // The commit wrote exactly the preview.
                    for (id, road) in p.roads() {
                        prop_assert_eq!(ed.network().road(*id).ok(), road.as_ref());
                    }
                    for (id, node) in p.nodes() {
                        prop_assert_eq!(ed.network().node(*id).ok(), node.as_ref());
                    }
                    states.push(ed.network().to_json().unwrap());
                }
                Err(_) => prop_assert_eq!(ed.network().to_json().unwrap(), before),
            }
            check_planar(ed.network());
        }
        let last = ed.network().to_json().unwrap();
        // Undo step by step: each state comes back byte for byte.
        for want in states.iter().rev().skip(1) {
            ed.undo().unwrap();
            prop_assert_eq!(&ed.network().to_json().unwrap(), want);
        }
        prop_assert!(ed.undo().is_err());
        while ed.redo().is_ok() {}
        prop_assert_eq!(&ed.network().to_json().unwrap(), &last);
        // The log is serde data; replaying it from the start gives the same network.
        let log: EditLog = serde_json::from_str(&serde_json::to_string(ed.log()).unwrap()).unwrap();
        let again = PrimaryEditor::replay(PrimaryNetwork::new(), &log, t, EditOptions::default()).unwrap();
        prop_assert_eq!(again.network().to_json().unwrap(), last.clone());
        // And the network reloads to the same bytes.
        let back = PrimaryNetwork::from_json(&last).unwrap();
        prop_assert_eq!(back.to_json().unwrap(), last);
    }
}

fn flat_editor() -> PrimaryEditor {
    PrimaryEditor::new(Terrain::flat(bounds()).unwrap(), EditOptions::default()).unwrap()
}

fn straight() -> RoadSpec {
    let mut s = RoadPreset::InnerCity.spec();
    s.params.strategy = polis_roads::primary::Strategy::Straight;
    s
}

fn at(x: f64, y: f64) -> Endpoint {
    Endpoint::At(DVec2::new(x, y))
}

#[test]
fn crossings_become_junctions_on_both_roads() {
    let mut ed = flat_editor();
    ed.apply(&Edit::AddRoad {
        from: at(-500.0, 0.0),
        to: at(500.0, 0.0),
        spec: straight(),
    })
    .unwrap();
    ed.apply(&Edit::AddRoad {
        from: at(-400.0, 300.0),
        to: at(-400.0, -300.0),
        spec: straight(),
    })
    .unwrap();
    let p = ed
        .propose(&Edit::AddRoad {
            from: at(200.0, 300.0),
            to: at(200.0, -300.0),
            spec: straight(),
        })
        .unwrap();
    // The first road was split at x = −400 by the second: its east piece is road 3.
    assert!(
        matches!(
            p.corrections(),
            [Correction::Junction {
                road: RoadId(3),
                ..
            }]
        ),
        "{:?}",
        p.corrections()
    );
    let c = ed.commit(&p).unwrap();
    assert_eq!(c.roads_replotted, vec![RoadId(3)]);
    assert_eq!(c.nodes_added.len(), 3);
    assert_eq!(c.roads_added.len(), 3); // two new pieces + the split-off piece
    let net = ed.network();
    assert_eq!((net.node_count(), net.road_count()), (8, 7));
    let junction = c.nodes_added[2];
    assert_eq!(net.node(junction).unwrap().pos, DVec2::new(200.0, 0.0));
    assert_eq!(net.roads_at(junction).len(), 4);
    check_planar(net);
}

#[test]
fn snaps_and_t_junctions() {
    let mut ed = flat_editor();
    ed.apply(&Edit::AddRoad {
        from: at(-500.0, 0.0),
        to: at(500.0, 0.0),
        spec: straight(),
    })
    .unwrap();
    // An end 5 m from a node snaps to it; an end 6 m from the road becomes a T-junction.
    let p = ed
        .propose(&Edit::AddRoad {
            from: at(-496.0, 3.0),
            to: at(-500.0, 400.0),
            spec: straight(),
        })
        .unwrap();
    assert!(matches!(
        p.corrections(),
        [Correction::SnappedToNode {
            node: ControlId(0),
            ..
        }]
    ));
    let p = ed
        .propose(&Edit::AddRoad {
            from: at(0.0, 400.0),
            to: at(10.0, 6.0),
            spec: straight(),
        })
        .unwrap();
    assert!(matches!(
        p.corrections(),
        [Correction::OnRoad {
            road: RoadId(0),
            ..
        }]
    ));
    ed.commit(&p).unwrap();
    let t = ed
        .network()
        .nodes()
        .find(|(_, n)| n.pos.distance(DVec2::new(10.0, 0.0)) < 1e-9)
        .unwrap()
        .0;
    assert_eq!(ed.network().roads_at(t).len(), 3);
    check_planar(ed.network());
    // The chain tool continues from the road's end node.
    let p = ed
        .propose(&Edit::Chain {
            from: ControlId(0),
            to: DVec2::new(-500.0, 500.0),
            spec: straight(),
        })
        .unwrap();
    let next = p.end_node().unwrap();
    ed.commit(&p).unwrap();
    let p = ed
        .propose(&Edit::Chain {
            from: next,
            to: DVec2::new(-100.0, 700.0),
            spec: straight(),
        })
        .unwrap();
    ed.commit(&p).unwrap();
    assert_eq!(ed.network().roads_at(next).len(), 2);
    check_planar(ed.network());
}

#[test]
fn refusals_are_typed_and_change_nothing() {
    let mut ed = flat_editor();
    ed.apply(&Edit::AddRoad {
        from: at(-500.0, 0.0),
        to: at(500.0, 0.0),
        spec: straight(),
    })
    .unwrap();
    let json = ed.network().to_json().unwrap();
    let refuse = |ed: &PrimaryEditor, e: Edit| ed.propose(&e).unwrap_err();
    let s = straight();
    let (n0, n1) = (ControlId(0), ControlId(1));
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: Endpoint::Node(n0),
                to: Endpoint::Node(n0),
                spec: s
            }
        ),
        PrimaryError::SelfLoop(_)
    ));
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: Endpoint::Node(n0),
                to: Endpoint::Node(n1),
                spec: s
            }
        ),
        PrimaryError::DuplicateRoad { .. }
    ));
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: at(f64::NAN, 0.0),
                to: at(0.0, 100.0),
                spec: s
            }
        ),
        PrimaryError::BadCoordinate { .. }
    ));
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddNode {
                at: DVec2::new(1e300, 0.0),
                label: None
            }
        ),
        PrimaryError::BadCoordinate { .. }
    ));
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddNode {
                at: DVec2::new(3000.0, 0.0),
                label: None
            }
        ),
        PrimaryError::OutsideMap { .. }
    ));
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddNode {
                at: DVec2::new(-505.0, 0.0),
                label: None
            }
        ),
        PrimaryError::NodeTooClose { .. }
    ));
    assert!(matches!(
        refuse(
            &ed,
            Edit::MoveNode {
                node: ControlId(9),
                to: DVec2::ZERO
            }
        ),
        PrimaryError::UnknownNode(_)
    ));
    assert!(matches!(
        refuse(&ed, Edit::DeleteRoad { road: RoadId(7) }),
        PrimaryError::UnknownRoad(_)
    ));
    // Along the road: overlap.
    let e = refuse(
        &ed,
        Edit::AddRoad {
            from: at(-300.0, 2.0),
            to: at(300.0, 2.0),
            spec: s,
        },
    );
    assert!(matches!(e, PrimaryError::CollinearOverlap { .. }), "{e:?}");
    // A shallow crossing and a shallow meeting at a node.
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: at(-300.0, -40.0),
                to: at(300.0, 40.0),
                spec: s
            }
        ),
        PrimaryError::AngleTooSmall { .. }
    ));
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: Endpoint::Node(n1),
                to: at(-100.0, 40.0),
                spec: s
            }
        ),
        PrimaryError::AngleTooSmall { .. }
    ));
    // Crossing right next to a node.
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: at(492.0, 300.0),
                to: at(492.0, -300.0),
                spec: s
            }
        ),
        PrimaryError::CrossingNearNode { .. }
    ));
    // Zero length after snapping.
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: at(100.0, 100.0),
                to: at(100.5, 100.0),
                spec: s
            }
        ),
        PrimaryError::ZeroLength { .. }
    ));
    // Bad parameters name the field.
    let mut bad = s;
    bad.params.deviation_deg = 50.0;
    assert!(matches!(
        refuse(
            &ed,
            Edit::AddRoad {
                from: at(0.0, 100.0),
                to: at(0.0, 400.0),
                spec: bad
            }
        ),
        PrimaryError::InvalidParameter {
            name: "deviation_deg",
            ..
        }
    ));
    bad = s;
    bad.width_m = -1.0;
    assert!(matches!(
        refuse(
            &ed,
            Edit::SetRoad {
                road: RoadId(0),
                spec: bad
            }
        ),
        PrimaryError::InvalidParameter {
            name: "width_m",
            ..
        }
    ));
    assert_eq!(ed.network().to_json().unwrap(), json);
    // A stale preview is refused.
    let p = ed
        .propose(&Edit::AddNode {
            at: DVec2::new(0.0, 300.0),
            label: None,
        })
        .unwrap();
    ed.apply(&Edit::AddNode {
        at: DVec2::new(0.0, -300.0),
        label: None,
    })
    .unwrap();
    assert_eq!(ed.commit(&p).unwrap_err(), PrimaryError::StalePreview);
}

#[test]
fn nodes_in_water_or_parks_and_long_bridges_are_refused() {
    let mut ed = PrimaryEditor::new(landscape(0), EditOptions::default()).unwrap();
    assert!(matches!(
        ed.propose(&Edit::AddNode {
            at: DVec2::new(600.0, 0.0),
            label: None
        }),
        Err(PrimaryError::IllegalNode {
            what: Illegal::Water,
            ..
        })
    ));
    assert!(matches!(
        ed.propose(&Edit::AddNode {
            at: DVec2::new(-900.0, 900.0),
            label: None
        }),
        Err(PrimaryError::IllegalNode {
            what: Illegal::Park,
            ..
        })
    ));
    // Across the river: a bridge, flagged on the path.
    let mut s = RoadPreset::InnerCity.spec();
    ed.apply(&Edit::AddRoad {
        from: at(300.0, 0.0),
        to: at(900.0, 0.0),
        spec: s,
    })
    .unwrap();
    let r = ed.network().roads().next().unwrap().1;
    assert!(r.path.bridge.iter().any(|&b| b));
    s.params.max_bridge_m = 20.0;
    assert!(matches!(
        ed.propose(&Edit::AddRoad {
            from: at(300.0, 500.0),
            to: at(900.0, 500.0),
            spec: s
        }),
        Err(PrimaryError::BridgeTooLong { .. })
    ));
}

#[test]
fn a_move_that_would_cross_is_refused_and_a_clear_one_replots() {
    let mut ed = flat_editor();
    ed.apply(&Edit::AddRoad {
        from: at(-500.0, 0.0),
        to: at(500.0, 0.0),
        spec: straight(),
    })
    .unwrap();
    ed.apply(&Edit::AddRoad {
        from: at(0.0, 100.0),
        to: at(0.0, 500.0),
        spec: straight(),
    })
    .unwrap();
    let low = ed
        .network()
        .nodes()
        .find(|(_, n)| n.pos == DVec2::new(0.0, 100.0))
        .unwrap()
        .0;
    let json = ed.network().to_json().unwrap();
    // Dragging the lower end below the first road would cross it.
    let e = ed
        .propose(&Edit::MoveNode {
            node: low,
            to: DVec2::new(0.0, -100.0),
        })
        .unwrap_err();
    assert!(
        matches!(
            e,
            PrimaryError::WouldCross {
                other: RoadId(0),
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(ed.network().to_json().unwrap(), json);
    // Onto the road itself.
    assert!(matches!(
        ed.propose(&Edit::MoveNode {
            node: low,
            to: DVec2::new(30.0, 4.0)
        }),
        Err(PrimaryError::OnRoad { .. })
    ));
    // A clear move re-plots the node's road and reports it.
    let c = ed
        .apply(&Edit::MoveNode {
            node: low,
            to: DVec2::new(50.0, 60.0),
        })
        .unwrap();
    assert_eq!(c.nodes_moved, vec![low]);
    assert_eq!(c.roads_replotted, vec![RoadId(1)]);
    assert_eq!(
        ed.network().road(RoadId(1)).unwrap().path.points[0],
        DVec2::new(50.0, 60.0)
    );
    check_planar(ed.network());
}

/// On a fixed hillside, the even-elevation-difference strategy spreads the climb: its
/// steepest grade is well below that of minimum elevation difference, which keeps both
/// fronts level and climbs where they meet (Kelly §4.2.3.2–3). Measured and pinned.
#[test]
fn even_elevation_difference_has_the_gentler_steepest_grade() {
    // A 120 m escarpment across x = 0 with a bump: one end low, the other high.
    let f = FnField::new(|p: DVec2| {
        120.0 / (1.0 + (-p.x / 250.0).exp())
            + 25.0 * (-(p - DVec2::new(-300.0, 300.0)).length_squared() / 1.0e5).exp()
    });
    let t = Terrain::with_elevation(Arc::new(f), bounds()).unwrap();
    let grade = |s| {
        let p = AdaptiveParams {
            strategy: s,
            sample_size_m: 100.0,
            snap_m: 100.0,
            samples: 7,
            deviation_deg: 40.0,
            segment_draw_size_m: 10.0,
            max_bridge_m: 0.0,
        };
        plot_path(DVec2::new(-1200.0, 0.0), DVec2::new(1200.0, 0.0), &p, &t)
            .unwrap()
            .max_grade()
    };
    use polis_roads::primary::Strategy as S;
    let (even, least, straight) = (
        grade(S::EvenElevationDifference),
        grade(S::MinimumElevationDifference),
        grade(S::Straight),
    );
    println!("max grade: even {even:.4}, least difference {least:.4}, straight {straight:.4}");
    assert!(even < least, "even {even} least {least}");
    // Pinned (measured 0.0842, 0.1200, 0.0989 on x86-64), with room for libm differences.
    assert!((0.080..0.088).contains(&even), "{even}");
    assert!((0.112..0.124).contains(&least), "{least}");
}

#[test]
fn specs_and_geojson_build_networks() {
    let json = r#"{"nodes": [{"id": 10, "x": -400, "y": 0}, {"id": 11, "x": 400, "y": 0, "label": "east"},
        {"id": 12, "x": 0, "y": -400}, {"id": 13, "x": 0, "y": 400}],
        "roads": [{"a": 10, "b": 11, "class": "InnerCity"}, {"a": 12, "b": 13}]}"#;
    let spec = PrimarySpec::from_json(json).unwrap();
    let ed = spec
        .build(Terrain::flat(bounds()).unwrap(), EditOptions::default())
        .unwrap();
    // The second road crosses the first: a junction node, four roads.
    assert_eq!(ed.network().road_count(), 4);
    assert_eq!(
        ed.network().node(ControlId(1)).unwrap().label.as_deref(),
        Some("east")
    );
    check_planar(ed.network());
    let bad = r#"{"nodes": [{"id": 1, "x": 0, "y": 0}], "roads": [{"a": 1, "b": 2}]}"#;
    assert!(matches!(
        PrimarySpec::from_json(bad)
            .unwrap()
            .build(hills(1), EditOptions::default()),
        Err(PrimaryError::BadData(_))
    ));
    let geo = r#"{"type": "FeatureCollection", "features": [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": [-500, -500]}, "properties": {"label": "a"}},
        {"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[-500, -500], [0, 0], [500, 500]]}, "properties": {"class": "Primary"}},
        {"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[-500, 500], [500, -500]]}}]}"#;
    let ed = PrimaryNetwork::from_geojson(
        geo,
        Terrain::flat(bounds()).unwrap(),
        EditOptions::default(),
    )
    .unwrap();
    assert_eq!(ed.network().road_count(), 4);
    check_planar(ed.network());
    assert!(
        PrimaryNetwork::from_geojson("{\"type\": 1}", hills(2), EditOptions::default()).is_err()
    );
    assert!(PrimaryNetwork::from_json("{\"next_node\": 0}").is_err());
}

#[test]
fn highways_of_a_grown_network_become_a_primary_network() {
    let params = polis_roads::RoadParams {
        max_segments: 400,
        ..polis_roads::RoadParams::default()
    };
    let grown = polis_roads::generate_default(&params).unwrap().network;
    let t = Terrain::flat(params.bounds()).unwrap();
    let net = PrimaryNetwork::from_highways(&grown, &t, RoadPreset::Primary.spec()).unwrap();
    assert!(net.road_count() > 0);
    check_planar(&net);
    let hw: f64 = grown
        .edges()
        .filter(|e| e.3.class == polis_roads::RoadClass::Highway)
        .map(|e| grown.edge_length(e.0).unwrap())
        .sum();
    let total: f64 = net.roads().map(|(_, r)| r.path.length()).sum();
    assert!((hw - total).abs() < 1e-6 * hw.max(1.0), "{hw} {total}");
    // Ids are stable: the same input gives the same bytes.
    let again = PrimaryNetwork::from_highways(&grown, &t, RoadPreset::Primary.spec()).unwrap();
    assert_eq!(net.to_json().unwrap(), again.to_json().unwrap());
}

/// A long seeded edit session on hills: the random-edit property with counts, showing
/// that crossings become junctions and that moves which would cross are refused.
#[test]
fn a_long_session_exercises_junctions_and_refused_crossing_moves() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
    let mut ed = PrimaryEditor::new(hills(5), EditOptions::default()).unwrap();
    let (mut junctions, mut would_cross, mut moved, mut commits) = (0, 0, 0, 0);
    for _ in 0..160 {
        let q = |rng: &mut rand_pcg::Pcg64Mcg| {
            DVec2::new(
                rng.random_range(-1500.0..1500.0),
                rng.random_range(-1500.0..1500.0),
            )
        };
        let op = match rng.random_range(0..10) {
            0..=3 => Op::Road(q(&mut rng), q(&mut rng)),
            4..=7 => Op::Move(rng.random_range(0..1000), q(&mut rng)),
            8 => Op::Chain(rng.random_range(0..1000), q(&mut rng)),
            _ => Op::DeleteRoad(rng.random_range(0..1000)),
        };
        let Some(edit) = to_edit(ed.network(), &op) else {
            continue;
        };
        match ed.propose(&edit) {
            Ok(p) => {
                junctions += p
                    .corrections()
                    .iter()
                    .filter(|c| matches!(c, Correction::Junction { .. }))
                    .count();
                moved += usize::from(matches!(edit, Edit::MoveNode { .. }));
                ed.commit(&p).unwrap();
                commits += 1;
            }
            Err(PrimaryError::WouldCross { .. }) => would_cross += 1,
            Err(_) => {}
        }
        check_planar(ed.network());
    }
    println!(
        "commits {commits}, junctions {junctions}, moves {moved}, refused crossing moves {would_cross}"
    );
    assert!(
        junctions > 5 && would_cross > 5 && moved > 5,
        "{junctions} {would_cross} {moved}"
    );
    while ed.undo().is_ok() {}
    assert_eq!(
        ed.network().to_json().unwrap(),
        PrimaryNetwork::new().to_json().unwrap()
    );
}
