//! Analytic skeletons and the independent checker.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::*;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use polis_lots::StraightSkeleton;

fn skel(p: &Polygon) -> StraightSkeleton {
    let pw: PolygonWithHoles = p.clone().into();
    let sk = StraightSkeleton::new(&pw).unwrap();
    check_skeleton(&pw, &sk, 1e-9).unwrap();
    sk
}

#[test]
fn square_meets_at_centre() {
    let sk = skel(&Polygon::rect(v(0., 0.), v(4., 4.)));
    assert!((sk.max_time() - 2.0).abs() < 1e-12);
    let last = sk
        .nodes()
        .iter()
        .max_by(|a, b| a.time.total_cmp(&b.time))
        .unwrap();
    assert!(last.position.distance(v(2., 2.)) < 1e-12);
    for f in sk.faces() {
        assert_eq!(f.len(), 3);
        assert!((f.area() - 4.0).abs() < 1e-12);
    }
}

#[test]
fn rectangle_ridge_length() {
    let sk = skel(&Polygon::rect(v(0., 0.), v(60., 20.)));
    assert!((sk.max_time() - 10.0).abs() < 1e-12);
    let ridge: f64 = sk
        .arcs()
        .iter()
        .filter(|a| sk.nodes()[a.from].time > 0.0 && sk.nodes()[a.to].time > 0.0)
        .map(|a| {
            sk.nodes()[a.from]
                .position
                .distance(sk.nodes()[a.to].position)
        })
        .sum();
    assert!((ridge - 40.0).abs() < 1e-9, "ridge {ridge}");
    // Long sides sweep trapezoids, short sides triangles.
    assert!((sk.faces()[0].area() - 0.5 * (60.0 + 40.0) * 10.0).abs() < 1e-9);
    assert!((sk.faces()[1].area() - 100.0).abs() < 1e-9);
}

#[test]
fn l_shape() {
    let l = poly(&[(0., 0.), (4., 0.), (4., 2.), (2., 2.), (2., 4.), (0., 4.)]);
    let sk = skel(&l);
    assert!((sk.max_time() - 1.0).abs() < 1e-12);
}

#[test]
fn regular_polygons() {
    for n in 3..40 {
        let p = Polygon::regular(n, v(1., 2.), 5.0);
        let sk = skel(&p);
        let inradius = 5.0 * (std::f64::consts::PI / n as f64).cos();
        assert!((sk.max_time() - inradius).abs() < 1e-9, "n = {n}");
    }
}

#[test]
fn square_with_hole() {
    let mut hole = Polygon::rect(v(4., 4.), v(6., 6.));
    hole.reverse();
    let p = PolygonWithHoles::new(Polygon::rect(v(0., 0.), v(10., 10.)), vec![hole]);
    let sk = StraightSkeleton::new(&p).unwrap();
    check_skeleton(&p, &sk, 1e-9).unwrap();
    assert!((sk.max_time() - 2.0).abs() < 1e-9);
}

#[test]
fn collinear_edges() {
    let p = poly(&[
        (0., 0.),
        (1., 0.),
        (2., 0.),
        (3., 0.),
        (3., 1.),
        (3., 2.),
        (0., 2.),
    ]);
    let sk = skel(&p);
    assert!((sk.max_time() - 1.0).abs() < 1e-12);
}

#[test]
fn comb_with_many_reflex_vertices() {
    let mut pts = vec![(0., 0.), (20., 0.), (20., 10.)];
    for i in (0..10).rev() {
        let x = 2.0 * i as f64;
        pts.push((x + 2.0, 10.0));
        pts.push((x + 1.5, 4.0));
        pts.push((x + 0.5, 4.0));
        pts.push((x, 10.0));
    }
    pts.dedup();
    let p = poly(&pts);
    let pw: PolygonWithHoles = Polygon::new(p.points().to_vec()).into();
    pw.validate().unwrap();
    skel(&p);
}

#[test]
fn t_shape_vertex_event() {
    let p = poly(&[
        (-1., 0.),
        (1., 0.),
        (1., 10.),
        (10., 10.),
        (10., 14.),
        (-10., 14.),
        (-10., 10.),
        (-1., 10.),
    ]);
    skel(&p);
}

#[test]
fn weighted_square() {
    let p: PolygonWithHoles = Polygon::rect(v(0., 0.), v(10., 10.)).into();
    let sk = StraightSkeleton::weighted(&p, &[1.0, 2.0, 1.0, 2.0]).unwrap();
    check_skeleton(&p, &sk, 1e-9).unwrap();
    // The two fast sides meet at x = 5 at time 2.5.
    assert!((sk.max_time() - 2.5).abs() < 1e-9);
}

#[test]
fn split_event_into_two() {
    // A bow-tie-like hexagon whose reflex vertices split it.
    let p = poly(&[
        (0., 0.),
        (10., 0.),
        (10., 10.),
        (6., 5.5),
        (4., 5.5),
        (0., 10.),
    ]);
    skel(&p);
    let d = poly(&[(0., 0.), (3., 4.), (6., 0.), (6., 8.), (0., 8.)]);
    skel(&d);
}

#[test]
fn bad_input_is_an_error() {
    let bow = poly(&[(0., 0.), (1., 1.), (1., 0.), (0., 1.)]);
    assert!(StraightSkeleton::new(&bow.into()).is_err());
    let nan = poly(&[(0., 0.), (f64::NAN, 0.), (0., 1.)]);
    assert!(StraightSkeleton::new(&nan.into()).is_err());
    let flat = poly(&[(0., 0.), (1., 0.), (2., 0.)]);
    assert!(StraightSkeleton::new(&flat.into()).is_err());
    let dup = poly(&[(0., 0.), (1., 0.), (1., 0.), (0., 1.)]);
    assert!(StraightSkeleton::new(&dup.into()).is_err());
    let mut cw = Polygon::rect(v(0., 0.), v(1., 1.));
    cw.reverse();
    assert!(StraightSkeleton::new(&cw.into()).is_err());
    let sq: PolygonWithHoles = Polygon::rect(v(0., 0.), v(1., 1.)).into();
    assert!(StraightSkeleton::weighted(&sq, &[1.0, 1.0]).is_err());
    assert!(StraightSkeleton::weighted(&sq, &[1.0, 0.0, 1.0, 1.0]).is_err());
    let _ = DVec2::ZERO;
}

#[test]
fn large_random_polygons_check_out() {
    // A 2,000-vertex star (about half reflex) and a 1,000-vertex comb.
    let star = Polygon::new(
        (0..2000)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / 2000.0;
                let r = 60.0 + 40.0 * ((i * 7919) % 1000) as f64 / 1000.0;
                v(r * a.cos(), r * a.sin())
            })
            .collect(),
    );
    skel(&star);
    let mut pts = vec![(0., -10.), (500., -10.)];
    for i in (0..250).rev() {
        let x = 2.0 * i as f64;
        let depth = 1.0 + ((i * 37) % 8) as f64;
        pts.push((x + 2.0, 10.0));
        pts.push((x + 1.6, 10.0 - depth));
        pts.push((x + 0.4, 10.0 - depth));
    }
    pts.push((0., 10.));
    skel(&poly(&pts));
}

#[test]
fn deterministic() {
    let p: PolygonWithHoles = poly(&[
        (0., 0.),
        (10., 0.),
        (10., 10.),
        (6., 5.5),
        (4., 5.5),
        (0., 10.),
    ])
    .into();
    let a = StraightSkeleton::weighted(&p, &[1.0, 2.0, 0.5, 1.0, 1.5, 1.0]).unwrap();
    let b = StraightSkeleton::weighted(&p, &[1.0, 2.0, 0.5, 1.0, 1.5, 1.0]).unwrap();
    assert_eq!(a, b);
    let json = serde_json::to_string(&a).unwrap();
    let back: StraightSkeleton = serde_json::from_str(&json).unwrap();
    // serde_json's float parsing may differ in the last bit.
    assert_eq!(a.arcs(), back.arcs());
    for (x, y) in a.nodes().iter().zip(back.nodes()) {
        assert!((x.position - y.position).length() < 1e-12 && (x.time - y.time).abs() < 1e-12);
    }
}

/// Regression (property test): a 14-gon with 1 µm edges and midpoints moved by 0.1 µm
/// collapses through a cascade of nearly simultaneous events, where nearly antiparallel
/// offset lines must not pull vertices to their ill-conditioned crossing.
#[test]
fn nearly_regular_with_tiny_edges() {
    let n = 14;
    let base = Polygon::new(
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * (i as f64 + 0.8 * 0.43755901151344645) / n as f64;
                v(5.0 * a.cos(), 5.0 * a.sin())
            })
            .collect(),
    );
    let kinds = [2, 2, 0, 0, 0, 1, 0, 0, 0, 2, 2, 0, 1, 0];
    let mut pts = Vec::new();
    for (i, (a, b)) in base.edges().enumerate() {
        pts.push(a);
        match kinds[i] {
            0 => pts.push(a + (b - a).normalize() * 1e-6),
            1 => pts.push(
                (a + b) * 0.5 + (b - a).perp().normalize() * if i == 12 { 1e-8 } else { 1e-7 },
            ),
            _ => {}
        }
    }
    let p: PolygonWithHoles = Polygon::new(pts).into();
    let sk = StraightSkeleton::new(&p).unwrap();
    check_skeleton(&p, &sk, 1e-7).unwrap();
}
