//! Analytic insets.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::*;
use polis_geom::{Polygon, PolygonWithHoles};
use polis_lots::{inset, inset_shapes, inset_weighted};

#[test]
fn square_inset_and_vanishing() {
    let sq: PolygonWithHoles = Polygon::rect(v(0., 0.), v(10., 10.)).into();
    let r = inset(&sq, 1.0).unwrap();
    assert_eq!(r.len(), 1);
    assert!((r[0].area() - 64.0).abs() < 1e-9);
    assert!(inset(&sq, 5.0).unwrap().is_empty());
    assert!(inset(&sq, 7.0).unwrap().is_empty());
    assert_eq!(inset(&sq, 0.0).unwrap()[0].area(), 100.0);
    assert!(inset(&sq, -1.0).is_err());
    assert!(inset(&sq, f64::NAN).is_err());
}

#[test]
fn rectangle_inset_near_collapse() {
    let r: PolygonWithHoles = Polygon::rect(v(0., 0.), v(60., 20.)).into();
    let s = inset(&r, 9.0).unwrap();
    assert_eq!(s.len(), 1);
    assert!((s[0].area() - 42.0 * 2.0).abs() < 1e-9);
}

#[test]
fn dumbbell_splits_in_two() {
    // Two 10 × 10 squares joined by a 10 × 2 corridor.
    let p: PolygonWithHoles = poly(&[
        (0., 0.),
        (10., 0.),
        (10., 4.),
        (20., 4.),
        (20., 0.),
        (30., 0.),
        (30., 10.),
        (20., 10.),
        (20., 6.),
        (10., 6.),
        (10., 10.),
        (0., 10.),
    ])
    .into();
    let s = inset(&p, 1.5).unwrap();
    assert_eq!(s.len(), 2);
    for piece in &s {
        assert!((piece.area() - 49.0).abs() < 1e-9, "{}", piece.area());
    }
    let s = inset(&p, 0.5).unwrap();
    assert_eq!(s.len(), 1);
}

#[test]
fn hole_grows_and_merges() {
    let mut hole = Polygon::rect(v(4., 4.), v(6., 6.));
    hole.reverse();
    let p = PolygonWithHoles::new(Polygon::rect(v(0., 0.), v(10., 10.)), vec![hole]);
    let s = inset(&p, 1.0).unwrap();
    assert_eq!(s.len(), 1);
    assert_eq!(s[0].holes.len(), 1);
    assert!((s[0].area() - (64.0 - 16.0)).abs() < 1e-9);
    assert!(s[0].validate().is_ok());
    assert!(inset(&p, 2.0).unwrap().is_empty());
}

#[test]
fn l_shape_inset() {
    let l: PolygonWithHoles =
        poly(&[(0., 0.), (4., 0.), (4., 2.), (2., 2.), (2., 4.), (0., 4.)]).into();
    let s = inset(&l, 0.5).unwrap();
    assert_eq!(s.len(), 1);
    // L of arm width 1 around: (3.5 × 1) + (1 × 2.5)... computed: outer 3.5 × 3.5 minus 2.5 × 2.5.
    assert!(
        (s[0].area() - (3.0 * 3.0 - 2.0 * 2.0)).abs() < 1e-9,
        "{}",
        s[0].area()
    );
}

#[test]
fn weighted_inset_and_sources() {
    let sq: PolygonWithHoles = Polygon::rect(v(0., 0.), v(10., 10.)).into();
    let w = [1.0, 2.0, 1.0, 0.5];
    let s = inset_weighted(&sq, &w, 1.0).unwrap();
    assert!((s[0].area() - (10.0 - 2.5) * 8.0).abs() < 1e-9);
    let shapes = inset_shapes(&sq, Some(&w), 1.0).unwrap();
    let srcs: Vec<_> = shapes[0].outer.sources.iter().map(|s| s.unwrap()).collect();
    assert_eq!(srcs, vec![0, 1, 2, 3]);
}

#[test]
fn parallel_edges_with_different_weights_step() {
    // A straight bottom side made of two edges with different weights.
    let p: PolygonWithHoles = poly(&[(0., 0.), (5., 0.), (10., 0.), (10., 10.), (0., 10.)]).into();
    let shapes = inset_shapes(&p, Some(&[1.0, 2.0, 1.0, 1.0, 1.0]), 1.0).unwrap();
    let poly = shapes[0].to_polygon();
    assert!(poly.validate().is_ok());
    assert!(shapes[0].outer.sources.contains(&None));
    assert!(
        (poly.area() - (4.0 * 8.0 + 4.0 * 7.0)).abs() < 1e-9,
        "{}",
        poly.area()
    );
}
