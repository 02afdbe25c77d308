//! Validity checking of primary-network edits (Kelly §5.3.2): junctions at crossings,
//! node snap, T-junctions, refusals, bridges, moves, sources and loading.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod primary_support;

use polis_geom::{Aabb2, DVec2};
use polis_roads::legality::Illegal;
use polis_roads::primary::{
    ControlId, Correction, Edit, EditOptions, Endpoint, PrimaryEditor, PrimaryError,
    PrimaryNetwork, PrimarySpec, RoadId, RoadPreset, Terrain,
};
use primary_support::{at, bounds, check_planar, flat_editor, hills, landscape, straight};

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
    // Passing half a metre from a lone node.
    let mut lone = flat_editor();
    lone.apply(&Edit::AddNode {
        at: DVec2::ZERO,
        label: None,
    })
    .unwrap();
    let e = refuse(
        &lone,
        Edit::AddRoad {
            from: at(-500.0, 0.5),
            to: at(500.0, 0.5),
            spec: s,
        },
    );
    assert!(
        matches!(
            e,
            PrimaryError::PassesNode {
                node: ControlId(0),
                ..
            }
        ),
        "{e:?}"
    );
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
    // A 30 km road drawn every centimetre would have 3 million vertices: refused.
    let big = Terrain::flat(Aabb2::new(DVec2::splat(-20_000.0), DVec2::splat(20_000.0))).unwrap();
    let huge = PrimaryEditor::new(big, EditOptions::default()).unwrap();
    bad = s;
    bad.params.segment_draw_size_m = 0.01;
    bad.params.sample_size_m = 5000.0;
    bad.params.snap_m = 5000.0;
    let e = refuse(
        &huge,
        Edit::AddRoad {
            from: at(-15_000.0, 0.0),
            to: at(15_000.0, 0.0),
            spec: bad,
        },
    );
    assert!(matches!(
        e,
        PrimaryError::InvalidParameter {
            name: "segment_draw_size_m",
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

/// Loading checks every invariant: a tampered file is refused with a reason.
#[test]
fn loading_a_tampered_network_is_refused() {
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
    let json = ed.network().to_json().unwrap();
    PrimaryNetwork::from_json(&json).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&json).unwrap();
    // A node moved without its roads.
    let mut moved = v.clone();
    moved["nodes"]["2"]["pos"] = serde_json::json!([0.0, -100.0]);
    assert!(matches!(
        PrimaryNetwork::from_json(&moved.to_string()),
        Err(PrimaryError::BadData(_))
    ));
    // A path bent across the other road.
    let pts = v["roads"]["1"]["path"]["points"].as_array_mut().unwrap();
    pts[1] = serde_json::json!([0.0, -50.0]);
    let e = PrimaryNetwork::from_json(&v.to_string()).unwrap_err();
    assert!(matches!(e, PrimaryError::BadData(_)), "{e}");
    // An id at or above the counter.
    let mut v: serde_json::Value = serde_json::from_str(&json).unwrap();
    v["next_node"] = serde_json::json!(1);
    assert!(PrimaryNetwork::from_json(&v.to_string()).is_err());
}
