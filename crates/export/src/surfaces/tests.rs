//! Unit tests of the road surfaces.

use super::junctions::{Plan, plan};
use super::*;
use crate::map::RoadClass;
use polis_geom::field::{Constant, FnField};
use polis_geom::glam::Vec3;
use polis_geom::polygon::ring_signed_area;
use polis_geom::predicates::distance_to_segment;
use polis_geom::{PlanarGraph, Polygon, SnapOptions};
use proptest::prelude::*;

fn road(points: &[(f64, f64)], class: RoadClass, w: f64) -> MapRoad {
    MapRoad::new(
        points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
        class,
        w,
    )
}

#[test]
fn straight_and_mitred_ribbons_have_exact_area() {
    let o = RoadSurfaceOptions {
        end_cap: EndCap::Flat,
        ..Default::default()
    };
    let straight = road(&[(0.0, 0.0), (100.0, 0.0)], RoadClass::Street, 8.0);
    let m = road_surfaces(&[straight], &Constant(0.0), &o, None).unwrap();
    m.validate().unwrap();
    assert_eq!(m.triangle_count(), 2 * 10, "subdivided every 10 m");
    assert!((m.surface_area() - 800.0).abs() < 1e-3);
    assert!(
        m.normals.iter().all(|n| (*n - Vec3::Y).length() < 1e-6),
        "faces up"
    );
    // An L turn (90°) and a 120° turn: miters keep area = length × width.
    for (pts, len) in [
        (vec![(0.0, 0.0), (50.0, 0.0), (50.0, 40.0)], 90.0),
        (
            vec![(0.0, 0.0), (30.0, 0.0), (15.0, 25.980762113533157)],
            60.0,
        ),
    ] {
        let r = road(&pts, RoadClass::Major, 6.0);
        let m = road_surfaces(&[r], &Constant(2.0), &o, None).unwrap();
        m.validate().unwrap();
        assert!(
            (m.surface_area() - len * 6.0).abs() < 1e-2,
            "{} vs {}",
            m.surface_area(),
            len * 6.0
        );
        let lift = 2.0 + o.lift_m + o.class_lift_m * 3.0;
        assert!(
            m.positions
                .iter()
                .all(|p| (f64::from(p.y) - lift).abs() < 1e-5)
        );
    }
}

#[test]
fn drapes_on_terrain_and_bridges_span() {
    let o = RoadSurfaceOptions {
        max_segment_m: 5.0,
        lift_m: 0.0,
        class_lift_m: 0.0,
        ..Default::default()
    };
    let slope = FnField::new(|p: DVec2| 0.1 * p.x);
    let r = road(&[(0.0, 0.0), (40.0, 0.0)], RoadClass::Street, 4.0);
    let m = road_surfaces(std::slice::from_ref(&r), &slope, &o, None).unwrap();
    m.validate().unwrap();
    for p in &m.positions {
        assert!((p.y - 0.1 * p.x).abs() < 1e-5, "{p}");
    }
    // A valley 10 m deep between x = 10 and 30: the road dips, the bridge does not.
    let valley = FnField::new(|p: DVec2| {
        if (10.0..=30.0).contains(&p.x) {
            -10.0
        } else {
            0.0
        }
    });
    let m = road_surfaces(std::slice::from_ref(&r), &valley, &o, None).unwrap();
    assert!(m.positions.iter().any(|p| p.y == -10.0));
    let bridge = MapRoad { bridge: true, ..r };
    let m = road_surfaces(std::slice::from_ref(&bridge), &valley, &o, None).unwrap();
    assert!(m.positions.iter().all(|p| p.y == 0.0));
    // With a profile (a hump 4 m high at 20 m), the bridge follows it: linear between
    // its pairs at every station inside the ribbon, the ground at its ends.
    let hump = vec![
        (0.0, 0.0),
        (10.0, 3.0),
        (20.0, 4.0),
        (30.0, 3.0),
        (40.0, 0.0),
    ];
    let humped = MapRoad {
        profile: Some(hump),
        ..bridge
    };
    assert_eq!(humped.profile_height(25.0), Some(3.5));
    assert_eq!(humped.profile_height(-1.0), Some(0.0));
    let m = road_surfaces(std::slice::from_ref(&humped), &valley, &o, None).unwrap();
    m.validate().unwrap();
    for p in &m.positions {
        let want = humped.profile_height(f64::from(p.x)).unwrap();
        assert!((f64::from(p.y) - want).abs() < 1e-5, "{p} {want}");
    }
    assert!(m.positions.iter().any(|p| p.y == 4.0));
    // A road that is not a bridge ignores its profile.
    let ignored = MapRoad {
        bridge: false,
        ..humped
    };
    let m = road_surfaces(&[ignored], &valley, &o, None).unwrap();
    assert!(m.positions.iter().any(|p| p.y == -10.0));
}

#[test]
fn larger_classes_lie_on_top_at_crossings() {
    let o = RoadSurfaceOptions::default();
    let a = road(&[(-20.0, 0.0), (20.0, 0.0)], RoadClass::Highway, 10.0);
    let b = road(&[(0.0, -20.0), (0.0, 20.0)], RoadClass::Footpath, 2.0);
    let ha = road_surfaces(&[a], &Constant(0.0), &o, None)
        .unwrap()
        .positions[0]
        .y;
    let hb = road_surfaces(&[b], &Constant(0.0), &o, None)
        .unwrap()
        .positions[0]
        .y;
    assert!(ha > hb);
}

#[test]
fn degenerate_and_bad_input() {
    let o = RoadSurfaceOptions::default();
    // Zero width, repeated points, a U-turn: no panic, valid mesh.
    let roads = [
        road(&[(0.0, 0.0), (10.0, 0.0)], RoadClass::Street, 0.0),
        road(
            &[(0.0, 0.0), (0.0, 0.0), (10.0, 0.0), (10.0, 0.0)],
            RoadClass::Street,
            3.0,
        ),
        road(
            &[(0.0, 0.0), (10.0, 0.0), (0.0, 0.0)],
            RoadClass::Street,
            3.0,
        ),
        road(
            &[(0.0, 0.0), (10.0, 0.0), (0.0, 0.5)],
            RoadClass::Street,
            3.0,
        ),
    ];
    let m = road_surfaces(&roads, &Constant(0.0), &o, None).unwrap();
    m.validate().unwrap();
    assert!(m.triangle_count() > 0);
    let nan = FnField::new(|_p: DVec2| f64::NAN);
    assert!(matches!(
        road_surfaces(&roads[1..2], &nan, &o, None),
        Err(ExportError::InvalidMap { .. })
    ));
    let bad = RoadSurfaceOptions {
        max_segment_m: 0.0,
        ..o.clone()
    };
    assert!(road_surfaces(&roads, &Constant(0.0), &bad, None).is_err());
    let nan_road = road(&[(0.0, f64::NAN), (1.0, 0.0)], RoadClass::Street, 3.0);
    assert!(road_surfaces(&[nan_road], &Constant(0.0), &o, None).is_err());
}

// ---------------------------------------------------------------------------------------
// Junctions.

fn flat() -> RoadSurfaceOptions {
    RoadSurfaceOptions {
        end_cap: EndCap::Flat,
        lift_m: 0.0,
        class_lift_m: 0.0,
        ..Default::default()
    }
}

/// Every surface piece of a plan as layout triangles (f64): ribbons as two triangles per
/// segment, junctions as triangulated.
fn pieces(p: &Plan) -> Vec<[DVec2; 3]> {
    let mut out = Vec::new();
    for e in p.edges.iter().filter(|e| !e.dropped && !e.internal) {
        if e.len - e.trim[0] - e.trim[1] > e.len * 1e-12 {
            let ([ra, la], [rb, lb]) = (e.cut_a, e.cut_b);
            out.push([ra, rb, lb]);
            out.push([ra, lb, la]);
        }
    }
    for j in &p.junctions {
        for t in &j.triangles {
            out.push(t.map(|i| j.ring[i as usize]));
        }
    }
    out
}

fn area(ring: &[DVec2]) -> f64 {
    ring_signed_area(ring)
}

/// The intersection of two counter-clockwise convex polygons (Sutherland–Hodgman).
fn clip(subject: &[DVec2], clipper: &[DVec2]) -> Vec<DVec2> {
    let mut out = subject.to_vec();
    for k in 0..clipper.len() {
        let (a, b) = (clipper[k], clipper[(k + 1) % clipper.len()]);
        let inside = |p: DVec2| (b - a).perp_dot(p - a) >= 0.0;
        let input = std::mem::take(&mut out);
        for i in 0..input.len() {
            let (p, q) = (input[i], input[(i + 1) % input.len()]);
            let (ip, iq) = (inside(p), inside(q));
            if ip {
                out.push(p);
            }
            if ip != iq {
                let (dp, dq) = ((b - a).perp_dot(p - a), (b - a).perp_dot(q - a));
                out.push(p + (q - p) * (dp / (dp - dq)));
            }
        }
        if out.is_empty() {
            break;
        }
    }
    out
}

/// The largest overlap area between two pieces, with the pair.
fn worst_overlap(tris: &[[DVec2; 3]]) -> (f64, usize, usize) {
    let mut worst = (0.0, 0, 0);
    for i in 0..tris.len() {
        for j in i + 1..tris.len() {
            let o = clip(&tris[i], &tris[j]);
            if o.len() >= 3 {
                let a = area(&o);
                if a > worst.0 {
                    worst = (a, i, j);
                }
            }
        }
    }
    worst
}

fn total_area(tris: &[[DVec2; 3]]) -> f64 {
    tris.iter().map(|t| area(t)).sum()
}

fn check_plan(p: &Plan, scale: f64) {
    let tris = pieces(p);
    for t in &tris {
        assert!(t.iter().all(|q| q.is_finite()), "NaN in {t:?}");
        assert!(area(t) > 0.0, "piece not counter-clockwise: {t:?}");
    }
    let (o, i, j) = worst_overlap(&tris);
    assert!(
        o <= 1e-9 * scale * scale,
        "pieces {i} and {j} overlap by {o}: {:?} {:?}",
        tris[i],
        tris[j]
    );
}

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

#[test]
fn crossing_t_and_y_have_the_union_area() {
    let o = flat();
    let h = 4.0;
    // A crossing: 2·L·w − w².
    let a = road(
        &[(-50.0, 0.0), (0.0, 0.0), (50.0, 0.0)],
        RoadClass::Street,
        2.0 * h,
    );
    let b = road(
        &[(0.0, -50.0), (0.0, 0.0), (0.0, 50.0)],
        RoadClass::Street,
        2.0 * h,
    );
    let p = plan(&[a.clone(), b.clone()], &o);
    check_plan(&p, 50.0);
    assert_eq!(p.junctions.len(), 1);
    assert!((area(&p.junctions[0].ring) - 64.0).abs() < 1e-9);
    assert!((total_area(&pieces(&p)) - (1600.0 - 64.0)).abs() < 1e-9);
    let m = road_surfaces(&[a, b], &Constant(0.0), &o, None).unwrap();
    m.validate().unwrap();
    assert!((m.surface_area() - 1536.0).abs() < 1e-2);
    // A T: the through road and 46 m of the branch.
    let t = [
        road(&[(-50.0, 0.0), (50.0, 0.0)], RoadClass::Street, 8.0),
        road(&[(0.0, 0.0), (0.0, 50.0)], RoadClass::Street, 8.0),
    ];
    // The through road has no point at the T: it must be split there to meet (planar
    // input). Split it.
    let p = plan(&t, &o);
    assert_eq!(p.junctions.len(), 0, "no shared point, no junction");
    let t = [
        road(
            &[(-50.0, 0.0), (0.0, 0.0), (50.0, 0.0)],
            RoadClass::Street,
            8.0,
        ),
        road(&[(0.0, 0.0), (0.0, 50.0)], RoadClass::Street, 8.0),
    ];
    let p = plan(&t, &o);
    check_plan(&p, 50.0);
    assert_eq!(p.junctions.len(), 1);
    assert!((total_area(&pieces(&p)) - (800.0 + 46.0 * 8.0)).abs() < 1e-9);
    // A Y at 120°: 6·h·L − √3·h².
    let dirs = [0.0f64, 120.0, 240.0].map(|deg| {
        let r = deg.to_radians();
        v(r.cos(), r.sin()) * 50.0
    });
    let y: Vec<MapRoad> = dirs
        .iter()
        .map(|d| MapRoad::new(vec![DVec2::ZERO, *d], RoadClass::Street, 2.0 * h))
        .collect();
    let p = plan(&y, &o);
    check_plan(&p, 50.0);
    let want = 6.0 * h * 50.0 - 3f64.sqrt() * h * h;
    assert!((total_area(&pieces(&p)) - want).abs() < 1e-9);
    assert_eq!(p.junctions[0].ring.len(), 3, "corners shared: a triangle");
}

#[test]
fn every_cut_lies_on_its_junction() {
    let roads = [
        road(&[(0.0, 0.0), (40.0, 3.0)], RoadClass::Major, 12.0),
        road(&[(0.0, 0.0), (-5.0, 30.0)], RoadClass::Street, 6.0),
        road(&[(0.0, 0.0), (-30.0, -2.0)], RoadClass::Street, 8.0),
        road(&[(0.0, 0.0), (3.0, -40.0)], RoadClass::Footpath, 2.0),
    ];
    let p = plan(&roads, &flat());
    check_plan(&p, 40.0);
    let j = &p.junctions[0];
    for e in &p.edges {
        for c in e.cut_a {
            assert!(j.ring.contains(&c), "{c} not a junction vertex");
        }
    }
    // In 3-D: ribbon and junction share their edges, on a slope too.
    let slope = FnField::new(|p: DVec2| 0.3 * p.x - 0.1 * p.y);
    let m = road_surfaces(&roads, &slope, &RoadSurfaceOptions::default(), None).unwrap();
    m.validate().unwrap();
    let ring: Vec<Vec3> = j
        .ring
        .iter()
        .map(|&q| {
            let h = 0.3 * q.x - 0.1 * q.y + 0.05 + 0.02 * 3.0;
            to_world(q, h).as_vec3()
        })
        .collect();
    for q in &ring {
        assert!(m.positions.iter().any(|p| (*p - *q).length() < 1e-4));
    }
}

#[test]
fn bends_wide_meets_narrow_and_near_parallel_roads() {
    let o = flat();
    // Bends between 1° and 179°, both ways, equal and unequal widths.
    for deg in [
        1.0f64, 10.0, 45.0, 90.0, 119.0, 120.0, 121.0, 150.0, 179.0, 179.999,
    ] {
        for (w0, w1) in [(8.0, 8.0), (12.0, 3.0), (3.0, 12.0)] {
            for sign in [1.0, -1.0] {
                let r = (180.0 - deg).to_radians() * sign;
                let far = v(r.cos(), r.sin()) * 1000.0;
                let roads = [
                    road(&[(-1000.0, 0.0), (0.0, 0.0)], RoadClass::Street, w0),
                    MapRoad::new(vec![DVec2::ZERO, far], RoadClass::Street, w1),
                ];
                let p = plan(&roads, &o);
                assert_eq!(p.report.clamped_segments, 0, "{deg}° {w0}/{w1}");
                assert_eq!(p.report.approximated_junctions, 0, "{deg}° {w0}/{w1}");
                check_plan(&p, 10.0);
                let m = road_surfaces(&roads, &Constant(1.0), &o, None).unwrap();
                m.validate().unwrap();
            }
        }
    }
    // A wide road with narrow ones at ±135°: their corners lie behind the node.
    let roads = [
        road(&[(0.0, 0.0), (100.0, 0.0)], RoadClass::Highway, 30.0),
        road(&[(0.0, 0.0), (-70.0, 70.0)], RoadClass::Street, 4.0),
        road(&[(0.0, 0.0), (-70.0, -70.0)], RoadClass::Street, 4.0),
    ];
    let p = plan(&roads, &o);
    check_plan(&p, 30.0);
    assert_eq!(p.report.approximated_junctions, 0);
    // Near-parallel roads (0.5°) that are long enough: a long thin junction.
    let r = 0.5f64.to_radians();
    let roads = [
        MapRoad::new(vec![DVec2::ZERO, v(2000.0, 0.0)], RoadClass::Street, 6.0),
        MapRoad::new(
            vec![DVec2::ZERO, v(r.cos(), r.sin()) * 2000.0],
            RoadClass::Street,
            6.0,
        ),
    ];
    let p = plan(&roads, &o);
    assert_eq!(p.report.clamped_segments, 0);
    check_plan(&p, 10.0);
    let trim = p.edges[0].trim[0];
    assert!((trim - 3.0 / (r / 2.0).tan()).abs() < 1e-6, "{trim}");
}

#[test]
fn short_segments_overlapping_roads_and_caps() {
    // Near-parallel roads on short segments: trims clamped, the junction approximated,
    // still a valid mesh.
    let roads = [
        road(&[(0.0, 0.0), (10.0, 0.0)], RoadClass::Street, 8.0),
        road(&[(0.0, 0.0), (10.0, 0.5)], RoadClass::Street, 8.0),
        road(
            &[(0.0, 0.0), (0.0, 0.0), (-1.0, 0.0)],
            RoadClass::Street,
            8.0,
        ),
        // The same segment twice (one wider) and a collinear overlap.
        road(&[(0.0, 0.0), (0.0, 5.0)], RoadClass::Street, 3.0),
        road(&[(0.0, 5.0), (0.0, 0.0)], RoadClass::Major, 5.0),
        road(&[(0.0, 0.0), (0.0, 2.0)], RoadClass::Street, 3.0),
    ];
    let (m, report) =
        road_surfaces_with_report(&roads, &Constant(0.0), &RoadSurfaceOptions::default(), None)
            .unwrap();
    m.validate().unwrap();
    assert!(report.clamped_segments > 0, "{report:?}");
    assert_eq!(report.duplicate_segments, 1);
    assert!(report.approximated_junctions > 0);
    assert!(m.triangle_count() > 0);
    // Caps: flat, square, round with m segments (exact half-polygon areas).
    let one = [road(&[(0.0, 0.0), (30.0, 0.0)], RoadClass::Street, 4.0)];
    for (cap, extra) in [
        (EndCap::Flat, 0.0),
        (EndCap::Square, 2.0 * 2.0 * 4.0),
        (
            EndCap::Round { segments: 6 },
            2.0 * 3.0 * 4.0 * (std::f64::consts::PI / 6.0).sin(),
        ),
    ] {
        let o = RoadSurfaceOptions {
            end_cap: cap,
            ..flat()
        };
        let p = plan(&one, &o);
        check_plan(&p, 30.0);
        assert!(
            (total_area(&pieces(&p)) - (120.0 + extra)).abs() < 1e-9,
            "{cap:?}"
        );
        let m = road_surfaces(&one, &Constant(0.0), &o, None).unwrap();
        m.validate().unwrap();
        assert!((m.surface_area() - (120.0 + extra)).abs() < 1e-3);
    }
}

#[test]
fn close_junctions_merge_into_one_polygon() {
    let o = flat();
    // A crossing split into two T's 2.85 m apart (a jog), 8 m streets: one polygon.
    let (a, b) = (v(0.0, 0.0), v(2.85, 0.1));
    let roads = [
        MapRoad::new(
            vec![v(-80.0, 0.0), a, b, v(90.0, 0.0)],
            RoadClass::Street,
            8.0,
        ),
        MapRoad::new(vec![a, v(1.0, -70.0)], RoadClass::Street, 8.0),
        MapRoad::new(vec![b, v(3.0, 75.0)], RoadClass::Street, 8.0),
    ];
    let p = plan(&roads, &o);
    assert_eq!(p.report.merged_junctions, 1, "{:?}", p.report);
    assert_eq!(p.report.approximated_junctions, 0);
    assert_eq!(p.report.clamped_segments, 0);
    assert_eq!(p.junctions.len(), 1, "flat caps: the merged junction only");
    check_plan(&p, 10.0);
    // The merged polygon covers the jog: both nodes and the ribbon the short segment
    // would have had.
    let ring = Polygon::new(p.junctions[0].ring.clone());
    for q in [
        a,
        b,
        a.lerp(b, 0.5),
        a.lerp(b, 0.5) + v(0.0, 3.9),
        a.lerp(b, 0.5) - v(0.0, 3.9),
    ] {
        assert!(ring.contains(q), "{q} outside {:?}", ring.points());
    }
    let m = road_surfaces(&roads, &Constant(0.0), &RoadSurfaceOptions::default(), None).unwrap();
    m.validate().unwrap();
    // A fork on a short stem and a wide road meeting two close side streets.
    let roads = [
        MapRoad::new(
            vec![v(0.0, -60.0), v(0.0, 0.0), v(0.0, 3.0)],
            RoadClass::Major,
            12.0,
        ),
        MapRoad::new(vec![v(0.0, 3.0), v(-50.0, 60.0)], RoadClass::Street, 7.0),
        MapRoad::new(vec![v(0.0, 3.0), v(50.0, 60.0)], RoadClass::Street, 7.0),
        MapRoad::new(vec![v(0.0, 0.0), v(60.0, -5.0)], RoadClass::Street, 7.0),
        MapRoad::new(vec![v(0.0, 0.0), v(-60.0, -5.0)], RoadClass::Street, 7.0),
    ];
    let p = plan(&roads, &o);
    assert_eq!(p.report.merged_junctions, 1, "{:?}", p.report);
    assert_eq!(p.report.approximated_junctions, 0);
    check_plan(&p, 10.0);
    let (m, _) =
        road_surfaces_with_report(&roads, &Constant(0.0), &RoadSurfaceOptions::default(), None)
            .unwrap();
    m.validate().unwrap();
}

#[test]
fn decks_of_bridges_are_flat_at_their_nodes() {
    // A bridge in two segments over a 10 m valley: the junction at the middle is a deck.
    let valley = FnField::new(|p: DVec2| if p.x.abs() < 20.0 { -10.0 } else { 0.0 });
    let bridge = MapRoad {
        bridge: true,
        ..road(
            &[(-30.0, 0.0), (0.0, 1.0), (30.0, 0.0)],
            RoadClass::Major,
            8.0,
        )
    };
    let m = road_surfaces(&[bridge], &valley, &flat(), None).unwrap();
    m.validate().unwrap();
    assert!(m.positions.iter().all(|p| p.y.abs() < 1e-6), "no dip");
    // The same bridge as three roads (a graph's edges), from 0 m up to 6 m: the deck
    // rises straight along the chain and never dips into the valley.
    let ramp = FnField::new(|p: DVec2| {
        if p.x.abs() < 25.0 {
            -10.0
        } else {
            0.1 * (p.x + 30.0)
        }
    });
    let pts = [v(-30.0, 0.0), v(-10.0, 0.0), v(10.0, 0.0), v(30.0, 0.0)];
    let roads: Vec<MapRoad> = pts
        .windows(2)
        .map(|w| MapRoad {
            bridge: true,
            ..MapRoad::new(w.to_vec(), RoadClass::Major, 8.0)
        })
        .collect();
    let m = road_surfaces(&roads, &ramp, &flat(), None).unwrap();
    m.validate().unwrap();
    for p in &m.positions {
        if p.x.abs() < 25.0 {
            let want = 0.1 * (p.x + 30.0);
            assert!((p.y - want).abs() < 1e-3, "{p}: want {want}");
        }
    }
}

/// A segment between two lattice points.
type LatticeSegment = ((i32, i32), (i32, i32));

/// Random planar graphs: segments on a small integer lattice (collinear runs, shared
/// ends, crossings, T's), inserted with `PlanarGraph::insert_segment`.
fn lattice_segments() -> impl Strategy<Value = Vec<LatticeSegment>> {
    let pt = (0i32..12, 0i32..12);
    prop::collection::vec((pt.clone(), pt), 1..14)
}

fn graph_roads(segs: &[LatticeSegment], unit: f64) -> Vec<(DVec2, DVec2)> {
    let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
    for &((ax, ay), (bx, by)) in segs {
        let (a, b) = (
            v(f64::from(ax), f64::from(ay)) * unit,
            v(f64::from(bx), f64::from(by)) * unit,
        );
        if a != b {
            let _ = g.insert_segment(a, b, (), &SnapOptions::default());
        }
    }
    g.check_invariants().unwrap();
    g.edge_ids()
        .map(|e| g.segment(e).unwrap())
        .collect::<Vec<_>>()
}

/// The largest half-width for which no segment of the graph is clamped and roads that
/// do not meet keep apart (see the module docs' guarantee).
fn safe_half_width(segs: &[(DVec2, DVec2)]) -> f64 {
    let mut w = f64::INFINITY;
    // Around every node: roads at an acute angle θ want cuts of (1 + cos θ)/sin θ · w; at
    // an obtuse one at most the wider half-width.
    let mut at: std::collections::BTreeMap<(u64, u64), Vec<(DVec2, f64)>> = Default::default();
    for &(a, b) in segs {
        let len = (b - a).length();
        at.entry((a.x.to_bits(), a.y.to_bits()))
            .or_default()
            .push((b - a, len));
        at.entry((b.x.to_bits(), b.y.to_bits()))
            .or_default()
            .push((a - b, len));
    }
    for ds in at.values() {
        for (i, &(di, li)) in ds.iter().enumerate() {
            for &(dj, lj) in &ds[i + 1..] {
                let (di, dj) = (di.normalize(), dj.normalize());
                let sin = di.perp_dot(dj).abs();
                let cos = di.dot(dj);
                let want = if cos <= 0.0 { 1.0 } else { (1.0 + cos) / sin };
                w = w.min(li.min(lj) / 2.0 / want);
            }
        }
    }
    // Segments that share no node: far enough apart for miters and caps.
    for (i, &(a, b)) in segs.iter().enumerate() {
        for &(c, d) in &segs[i + 1..] {
            if a == c || a == d || b == c || b == d {
                continue;
            }
            let dist = distance_to_segment(a, c, d)
                .min(distance_to_segment(b, c, d))
                .min(distance_to_segment(c, a, b))
                .min(distance_to_segment(d, a, b));
            w = w.min(dist / 4.0);
        }
    }
    w.min(10.0)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// On random planar graphs with widths that fit, ribbons and junctions have
    /// pairwise-disjoint interiors, so the total area is the area of their union; every
    /// value is finite and the mesh valid.
    #[test]
    fn planar_graphs_give_disjoint_pieces(
        segs in lattice_segments(),
        unit in prop_oneof![Just(1.0), Just(7.5), Just(1e3)],
        fractions in prop::collection::vec(0.3..1.0f64, 64),
        cap in prop_oneof![Just(EndCap::Flat), Just(EndCap::Square), Just(EndCap::Round { segments: 5 })],
    ) {
        let segs = graph_roads(&segs, unit);
        prop_assume!(!segs.is_empty());
        let w = 0.95 * safe_half_width(&segs);
        prop_assert!(w > 0.0);
        let roads: Vec<MapRoad> = segs
            .iter()
            .enumerate()
            .map(|(i, &(a, b))| {
                MapRoad::new(vec![a, b], RoadClass::Street, 2.0 * w * fractions[i % 64])
            })
            .collect();
        let o = RoadSurfaceOptions { end_cap: cap, ..flat() };
        let p = plan(&roads, &o);
        prop_assert_eq!(p.report.clamped_segments, 0);
        prop_assert_eq!(p.report.approximated_junctions, 0);
        prop_assert_eq!(p.report.skipped_junctions, 0);
        check_plan(&p, w);
        // Watertight: each ribbon's cut is an edge of its junction.
        for e in p.edges.iter().filter(|e| !e.dropped) {
            for (node, cut) in [(e.a, e.cut_a), (e.b, e.cut_b)] {
                if let Some(j) = p.junctions.iter().find(|j| j.node == node) {
                    prop_assert!(cut.iter().all(|c| j.ring.contains(c)), "{cut:?} {:?}", j.ring);
                }
            }
        }
        let m = road_surfaces(&roads, &FnField::new(|q: DVec2| 1e-3 * q.x), &o, None).unwrap();
        prop_assert!(m.validate().is_ok());
    }

    /// Any widths, including far too wide for the graph: no panic, no NaN, a valid mesh.
    #[test]
    fn any_widths_give_valid_meshes(
        segs in lattice_segments(),
        widths in prop::collection::vec(prop_oneof![Just(1e-3), 0.1..30.0f64, Just(200.0)], 64),
        flags in prop::collection::vec((any::<bool>(), 0u8..5), 64),
        raw in prop::collection::vec(((-20i32..20, -20i32..20), 0.0..12.0f64), 0..12),
    ) {
        let segs = graph_roads(&segs, 5.0);
        let class = |k: u8| match k {
            0 => RoadClass::Highway,
            1 => RoadClass::Major,
            2 => RoadClass::Street,
            3 => RoadClass::Footpath,
            _ => RoadClass::Other("lane".into()),
        };
        let mut roads: Vec<MapRoad> = segs
            .iter()
            .enumerate()
            .map(|(i, &(a, b))| MapRoad {
                bridge: flags[i % 64].0,
                ..MapRoad::new(vec![a, b], class(flags[i % 64].1), widths[i % 64])
            })
            .collect();
        // Plus one raw polyline, not planar with the rest: crossings, repeats, U-turns.
        if raw.len() >= 2 {
            let pts = raw.iter().map(|&((x, y), _)| v(f64::from(x), f64::from(y)) * 2.0).collect();
            roads.push(MapRoad::new(pts, RoadClass::Street, raw[0].1));
        }
        let (m, _) = road_surfaces_with_report(
            &roads,
            &FnField::new(|q: DVec2| 0.1 * q.y + (q.x / 9.0).sin()),
            &RoadSurfaceOptions::default(),
            None,
        )
        .unwrap();
        prop_assert!(m.validate().is_ok());
        prop_assert!(m.positions.iter().all(|p| p.is_finite()));
    }
}

/// The parts are the same surface split apart: ribbons grouped by class and width (in
/// rank order), junction plates on their own with layout-position coordinates; the
/// triangles and the area add up to the one-mesh surface's.
#[test]
fn parts_split_the_same_surface_into_ribbon_groups_and_junction_plates() {
    let roads = [
        road(
            &[(-60.0, 0.0), (0.0, 0.0), (60.0, 0.0)],
            RoadClass::Highway,
            16.0,
        ),
        road(&[(0.0, 0.0), (0.0, 70.0)], RoadClass::Street, 8.0),
        road(&[(0.0, 0.0), (0.0, -50.0)], RoadClass::Street, 6.0),
        road(&[(60.0, 0.0), (90.0, 40.0)], RoadClass::Street, 8.0),
    ];
    let o = RoadSurfaceOptions::default();
    let whole = road_surfaces(&roads, &Constant(0.0), &o, None).unwrap();
    let parts = road_surface_parts(&roads, &Constant(0.0), &o).unwrap();
    let keys: Vec<(&str, f64)> = parts
        .ribbons
        .iter()
        .map(|g| (g.class.as_str(), g.width_m))
        .collect();
    assert_eq!(keys, [("street", 6.0), ("street", 8.0), ("highway", 16.0)]);
    let tris: usize = parts
        .ribbons
        .iter()
        .map(|g| g.mesh.triangle_count())
        .sum::<usize>()
        + parts.junctions.triangle_count();
    assert_eq!(tris, whole.triangle_count());
    let area: f64 = parts
        .ribbons
        .iter()
        .map(|g| g.mesh.surface_area())
        .sum::<f64>()
        + parts.junctions.surface_area();
    assert!((area - whole.surface_area()).abs() < 1e-6 * area);
    for g in &parts.ribbons {
        g.mesh.validate().unwrap();
        for uv in &g.mesh.uvs {
            let v = f64::from(uv.y);
            assert!(
                v <= 1e-6 && v >= -g.width_m - 1e-4,
                "v {v} across a {} m road",
                g.width_m
            );
        }
    }
    parts.junctions.validate().unwrap();
    assert!(parts.report.junctions >= 3);
    for (p, uv) in parts.junctions.positions.iter().zip(&parts.junctions.uvs) {
        // World (x, y, z) = layout (x, h, −y): uv = (x, −y) = (world x, world z).
        assert!((uv.x - p.x).abs() < 1e-3 && (uv.y - p.z).abs() < 1e-3);
    }
}
