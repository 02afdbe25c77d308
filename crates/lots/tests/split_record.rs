//! The lot subdivision's split record (Kelly §5.5.1's debug view): one split line per
//! subdivision step, in order, each lying inside the piece it cut.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis_geom::predicates::distance_to_segment;
use polis_geom::{DVec2, PointLocation, Polygon};
use polis_lots::{LotParams, LotStrategy, Region, Subdivider, TaggedRing};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

fn region(p: &Polygon) -> Region {
    Region {
        outer: TaggedRing {
            points: p.points().to_vec(),
            street: vec![true; p.len()],
        },
        holes: vec![],
    }
}

fn params(strategy: LotStrategy, w: f64, d: f64, dev: f64) -> LotParams {
    LotParams {
        strategy,
        lot_width: w,
        lot_depth: d,
        deviance: dev,
        min_area: 0.0,
        max_area: w * d,
        ..LotParams::default()
    }
}

/// A 60 × 20 block with 20 × 20 targets: Kelly cuts twice (three lots), at x = 40 then at
/// x = 20, full height; without recording, nothing is recorded and the lots are the same.
#[test]
fn kelly_rectangle_records_two_cuts_in_order() {
    let r = region(&Polygon::rect(DVec2::ZERO, DVec2::new(60.0, 20.0)));
    let p = params(LotStrategy::Kelly, 20.0, 20.0, 0.0);
    let mut w = Subdivider::new();
    let plain = w
        .subdivide(&r, 1, &p, &mut Pcg64Mcg::seed_from_u64(3))
        .unwrap();
    assert!(plain.splits.is_empty());
    w.record_splits(true);
    let s = w
        .subdivide(&r, 1, &p, &mut Pcg64Mcg::seed_from_u64(3))
        .unwrap();
    assert_eq!(s.lots, plain.lots);
    assert_eq!(s.lots.len(), 3);
    assert_eq!(s.splits.len(), 2);
    let xs: Vec<f64> = s.splits.iter().map(|l| l.chords[0][0].x).collect();
    assert!(
        (xs[0] - 40.0).abs() < 1e-3 && (xs[1] - 20.0).abs() < 1e-3,
        "{xs:?}"
    );
    for l in &s.splits {
        assert_eq!(l.chords.len(), 1);
        let [a, b] = l.chords[0];
        assert!((a.distance(b) - 20.0).abs() < 1e-9, "{a} {b}");
    }
}

/// A concave (U-shaped) block cut across both arms records one split line of two chords.
#[test]
fn concave_cut_is_one_line_of_several_chords() {
    let u = Polygon::new(vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(90.0, 0.0),
        DVec2::new(90.0, 150.0),
        DVec2::new(60.0, 150.0),
        DVec2::new(60.0, 20.0),
        DVec2::new(30.0, 20.0),
        DVec2::new(30.0, 150.0),
        DVec2::new(0.0, 150.0),
    ]);
    let p = params(LotStrategy::Kelly, 25.0, 25.0, 0.0);
    let mut w = Subdivider::new();
    w.record_splits(true);
    let s = w
        .subdivide(&region(&u), 1, &p, &mut Pcg64Mcg::seed_from_u64(1))
        .unwrap();
    // The first cut runs across both arms: perpendicular to the inner 130 m side (from
    // (60, 150) down to (60, 20)) at its middle-most fifth, 3/5 of the way (y = 72): the
    // longest street side with at most 2.5 lot depths behind it (the outer 150 m sides
    // have the whole 90 m width behind them).
    let first = &s.splits[0];
    assert_eq!(first.chords.len(), 2, "{:?}", s.splits);
    for [a, b] in &first.chords {
        assert!(
            (a.y - 72.0).abs() < 1e-3 && (b.y - 72.0).abs() < 1e-3,
            "{a} {b}"
        );
        assert!((a.distance(*b) - 30.0).abs() < 1e-9);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// On convex blocks every step turns one piece into two: pieces = steps + 1, i.e.
    /// exactly one split line per subdivision step; every chord's ends lie on the block's
    /// boundary or inside it, and its midpoint inside.
    #[test]
    fn one_split_line_per_step_on_convex_blocks(
        w in 20.0f64..200.0,
        h in 20.0f64..200.0,
        turn in 0.0f64..std::f64::consts::PI,
        pm in any::<bool>(),
        dev in 0.0f64..1.0,
        seed in any::<u64>(),
    ) {
        let (c, s) = (turn.cos(), turn.sin());
        let rot = |x: f64, y: f64| DVec2::new(c * x - s * y, s * x + c * y);
        let poly = Polygon::new(vec![rot(0.0, 0.0), rot(w, 0.0), rot(w, h), rot(0.0, h)]);
        let strategy = if pm { LotStrategy::ParishMueller } else { LotStrategy::Kelly };
        let p = params(strategy, 15.0, 25.0, dev);
        let mut sub = Subdivider::new();
        sub.record_splits(true);
        let out = sub
            .subdivide(&region(&poly), 7, &p, &mut Pcg64Mcg::seed_from_u64(seed))
            .unwrap();
        let pieces = out.lots.len() + out.discarded.len() + out.green_spaces.len();
        prop_assert_eq!(pieces, out.splits.len() + 1);
        let tol = 1e-6 * w.max(h);
        for l in &out.splits {
            prop_assert_eq!(l.chords.len(), 1);
            let [a, b] = l.chords[0];
            prop_assert!(a.distance(b) > 0.0);
            for q in [a, b] {
                let on_edge = (0..4).any(|i| {
                    let (u, v) = (poly.points()[i], poly.points()[(i + 1) % 4]);
                    distance_to_segment(q, u, v) <= tol
                });
                prop_assert!(on_edge || poly.locate(q) == PointLocation::Inside);
            }
            prop_assert_ne!(poly.locate((a + b) * 0.5), PointLocation::Outside);
        }
    }
}
