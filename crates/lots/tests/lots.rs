//! Lot subdivision: known results, partition properties, determinism, errors.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use common::*;
use polis_geom::predicates::distance_to_segment;
use polis_geom::{PointLocation, Polygon, PolygonWithHoles};
use polis_lots::{
    BlockParams, Cell, LotParams, LotStrategy, Region, Subdivision, TaggedRing, blocks, subdivide,
    subdivide_block,
};
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

fn kelly(w: f64, d: f64, dev: f64) -> LotParams {
    LotParams {
        strategy: LotStrategy::Kelly,
        lot_width: w,
        lot_depth: d,
        deviance: dev,
        min_area: 0.0,
        ..LotParams::default()
    }
}

fn pieces(s: &Subdivision) -> Vec<PolygonWithHoles> {
    s.lots
        .iter()
        .map(|l| PolygonWithHoles::from(l.polygon.clone()))
        .chain(s.discarded.iter().map(|d| d.polygon.clone()))
        .chain(s.green_spaces.iter().cloned())
        .collect()
}

/// The pieces partition `area` of the region: areas add up, every piece is simple, and no
/// two overlap.
fn check_partition(r: &PolygonWithHoles, s: &Subdivision) -> Result<(), String> {
    let ps = pieces(s);
    let total: f64 = ps.iter().map(PolygonWithHoles::area).sum();
    if (total - r.area()).abs() > 1e-9 * r.area() {
        return Err(format!("pieces add up to {total}, region is {}", r.area()));
    }
    for (i, p) in ps.iter().enumerate() {
        p.validate()
            .map_err(|e| format!("piece {i} invalid: {e}"))?;
        let tol = 1e-7 * r.bbox().width().max(r.bbox().height());
        for &q in p.outer.points() {
            let near = r
                .outer
                .edges()
                .any(|(e0, e1)| distance_to_segment(q, e0, e1) <= tol);
            if !near && !r.contains(q) {
                return Err(format!("piece {i} vertex {q:?} outside the region"));
            }
        }
    }
    // Coverage by sampling: a point inside the region and clear of every piece boundary
    // lies inside exactly one piece. (Edge-crossing tests would flag the ulp-level
    // T-junctions that rounded split points leave between neighbours.)
    let bb = r.bbox();
    let tol = 1e-7 * bb.width().max(bb.height());
    let k = 48;
    for gx in 0..k {
        for gy in 0..k {
            let q = bb.min
                + (bb.max - bb.min)
                    * v((gx as f64 + 0.37) / k as f64, (gy as f64 + 0.61) / k as f64);
            let near = ps.iter().any(|p| {
                p.rings().any(|(_, ring)| {
                    ring.edges()
                        .any(|(e0, e1)| distance_to_segment(q, e0, e1) <= tol)
                })
            });
            if near {
                continue;
            }
            let count = ps
                .iter()
                .filter(|p| p.locate(q) == PointLocation::Inside)
                .count();
            let want = usize::from(r.locate(q) == PointLocation::Inside);
            if count != want {
                return Err(format!("{q:?} is inside {count} pieces, want {want}"));
            }
        }
    }
    Ok(())
}

#[test]
fn sixty_by_twenty_gives_three_lots() {
    let r = region(&Polygon::rect(v(0., 0.), v(60., 20.)));
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let s = subdivide(&r, 1, &kelly(20.0, 20.0, 0.0), &mut rng).unwrap();
    assert_eq!(s.lots.len(), 3);
    for l in &s.lots {
        assert!((l.area - 400.0).abs() < 1e-9);
        assert!(!l.street_edges.is_empty());
        assert_eq!(l.block_id, 1);
    }
    assert!(s.discarded.is_empty());
}

#[test]
fn inner_lots_without_access_are_dropped() {
    // 60 × 60 with 20 × 20 targets: the middle lot has no street.
    let r = region(&Polygon::rect(v(0., 0.), v(60., 60.)));
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let s = subdivide(&r, 1, &kelly(20.0, 20.0, 0.0), &mut rng).unwrap();
    assert_eq!(s.lots.len(), 8);
    assert_eq!(s.discarded.len(), 1);
    assert!((s.discarded[0].area - 400.0).abs() < 1e-9);
    check_partition(&Polygon::rect(v(0., 0.), v(60., 60.)).into(), &s).unwrap();
    let green = LotParams {
        green_space: true,
        ..kelly(20.0, 20.0, 0.0)
    };
    let s = subdivide(&r, 1, &green, &mut rng).unwrap();
    assert_eq!(s.green_spaces.len(), 1);
}

/// A Manhattan block (67 × 230 m of land inside its footpaths, streets all round) with
/// 25 × 100 ft lots (7.62 × 30.48 m): every lot is cut across the long sides through to
/// the middle of the block, so every lot reaches at least 0.75 lot depths behind one of
/// its street edges. (Kelly's longest-street-edge rule alone cut the ends of the block
/// along the cross streets into lots one or two widths deep.)
#[test]
fn a_long_block_gets_full_depth_lots_at_its_ends() {
    let r = region(&Polygon::rect(v(0., 0.), v(230., 67.)));
    let p = kelly(7.62, 30.48, 0.0);
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let s = subdivide(&r, 1, &p, &mut rng).unwrap();
    check_partition(&Polygon::rect(v(0., 0.), v(230., 67.)).into(), &s).unwrap();
    assert!(s.discarded.is_empty());
    for l in &s.lots {
        let pts = l.polygon.points();
        let reach = l
            .street_edges
            .iter()
            .map(|&i| {
                let (a, b) = l.polygon.edge(i);
                let d = (b - a).normalize();
                pts.iter()
                    .map(|q| d.perp_dot(*q - a).abs())
                    .fold(0.0, f64::max)
            })
            .fold(0.0, f64::max);
        assert!(reach >= 0.75 * 30.48, "{:?}", l.polygon);
        // No shallow strip along a cross street: at least 0.65 of a full lot.
        assert!(l.area >= 0.65 * 7.62 * 30.48, "{}", l.area);
    }
    // About 30 lots along each long side (Kelly's middle-most fractions are not all
    // equal), and a few along the cross streets where an end piece was deep enough.
    assert!((60..=70).contains(&s.lots.len()), "{}", s.lots.len());
}

#[test]
fn street_access_is_tracked() {
    // Only the bottom edge is a street: lots are strips standing on it.
    let mut r = region(&Polygon::rect(v(0., 0.), v(60., 30.)));
    r.outer.street = vec![true, false, false, false];
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let s = subdivide(&r, 1, &kelly(20.0, 30.0, 0.0), &mut rng).unwrap();
    assert_eq!(s.lots.len(), 3);
    for l in &s.lots {
        assert_eq!(l.street_edges.len(), 1);
        let (a, b) = l.polygon.edge(l.street_edges[0]);
        assert!(a.y == 0.0 && b.y == 0.0);
    }
}

#[test]
fn concave_u_block() {
    let u = poly(&[
        (0., 0.),
        (60., 0.),
        (60., 60.),
        (40., 60.),
        (40., 20.),
        (20., 20.),
        (20., 60.),
        (0., 60.),
    ]);
    let r = region(&u);
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let s = subdivide(&r, 1, &kelly(10.0, 20.0, 0.3), &mut rng).unwrap();
    check_partition(&u.clone().into(), &s).unwrap();
    assert!(s.lots.len() > 10);
    assert!(s.lots.iter().all(|l| !l.street_edges.is_empty()));
}

#[test]
fn parish_mueller_manhattan() {
    let b = Polygon::rect(v(0., 0.), v(60., 240.));
    let p = LotParams {
        strategy: LotStrategy::ParishMueller,
        max_area: 7.6 * 30.0 * 1.5,
        min_area: 20.0,
        ..LotParams::default()
    };
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let s = subdivide(&region(&b), 4, &p, &mut rng).unwrap();
    check_partition(&b.into(), &s).unwrap();
    assert!(s.lots.len() >= 32);
    assert!(s.lots.iter().all(|l| l.area <= p.max_area));
}

#[test]
fn block_with_hole_and_footpath() {
    let mut hole = Polygon::rect(v(40., 40.), v(60., 60.));
    hole.reverse();
    let cell = Cell {
        id: 3,
        polygon: PolygonWithHoles::new(Polygon::rect(v(0., 0.), v(100., 100.)), vec![hole]),
        road_widths: vec![10.0; 8],
    };
    let bs = blocks(&cell, &BlockParams::default()).unwrap();
    assert_eq!(bs.len(), 1);
    let mut rng = Pcg64Mcg::seed_from_u64(bs[0].id());
    let s = subdivide_block(&bs[0], &kelly(10.0, 20.0, 0.2), &mut rng).unwrap();
    let parcel: f64 = bs[0].parcels.iter().map(Region::area).sum();
    let total: f64 = pieces(&s).iter().map(PolygonWithHoles::area).sum();
    assert!((total - parcel).abs() < 1e-9 * parcel);
    assert!(!s.lots.is_empty());
}

#[test]
fn bad_input() {
    let mut rng = Pcg64Mcg::seed_from_u64(0);
    let bow = region(&poly(&[(0., 0.), (1., 1.), (1., 0.), (0., 1.)]));
    assert!(subdivide(&bow, 0, &LotParams::default(), &mut rng).is_err());
    let mut r = region(&Polygon::rect(v(0., 0.), v(10., 10.)));
    r.outer.street.pop();
    assert!(subdivide(&r, 0, &LotParams::default(), &mut rng).is_err());
    let r = region(&Polygon::rect(v(0., 0.), v(10., 10.)));
    let bad = LotParams {
        lot_width: -1.0,
        ..LotParams::default()
    };
    assert!(subdivide(&r, 0, &bad, &mut rng).is_err());
    let nan = region(&poly(&[(0., 0.), (f64::NAN, 0.), (0., 1.)]));
    assert!(subdivide(&nan, 0, &LotParams::default(), &mut rng).is_err());
}

/// Case count: `default`, or `LOTS_CASES` to stress.
fn cases(default: u32) -> u32 {
    std::env::var("LOTS_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn blob(n: usize, seeds: &[(f64, f64)]) -> Polygon {
    let pts = (0..n)
        .map(|i| {
            let (da, r) = seeds[i % seeds.len()];
            let a = std::f64::consts::TAU * (i as f64 + 0.8 * da) / n as f64;
            v(r * a.cos(), r * a.sin())
        })
        .collect();
    Polygon::new(pts)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(48)))]

    #[test]
    fn partition_and_access(
        n in 3usize..24,
        seeds in prop::collection::vec((0.0f64..1.0, 30.0f64..120.0), 1..24),
        w in 5.0f64..30.0, d in 10.0f64..40.0, dev in 0.0f64..1.0, seed in any::<u64>(),
        pm in any::<bool>(),
    ) {
        let p = blob(n, &seeds);
        let pw: PolygonWithHoles = p.clone().into();
        prop_assume!(pw.validate().is_ok());
        let params = LotParams {
            strategy: if pm { LotStrategy::ParishMueller } else { LotStrategy::Kelly },
            lot_width: w, lot_depth: d, deviance: dev, min_area: 10.0, max_area: w * d,
            ..LotParams::default()
        };
        let s = subdivide(&region(&p), 7, &params, &mut Pcg64Mcg::seed_from_u64(seed)).unwrap();
        if let Err(e) = check_partition(&pw, &s) { prop_assert!(false, "{}", e); }
        for l in &s.lots {
            prop_assert!(!l.street_edges.is_empty());
            prop_assert!(l.polygon.is_ccw());
        }
        let again = subdivide(&region(&p), 7, &params, &mut Pcg64Mcg::seed_from_u64(seed)).unwrap();
        prop_assert_eq!(&s, &again);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(32)))]

    #[test]
    fn cells_to_blocks_to_lots(
        n in 3usize..16,
        seeds in prop::collection::vec((0.0f64..1.0, 60.0f64..150.0), 1..16),
        widths in prop::collection::vec(prop_oneof![Just(10.0), Just(20.0), 4.0f64..30.0], 16),
        footpath in prop_oneof![Just(0.0), 1.0f64..4.0],
        seed in any::<u64>(),
    ) {
        let p = blob(n, &seeds);
        let pw: PolygonWithHoles = p.clone().into();
        prop_assume!(pw.validate().is_ok());
        let cell = Cell { id: seed, polygon: pw.clone(), road_widths: (0..p.len()).map(|i| widths[i % widths.len()]).collect() };
        let bs = blocks(&cell, &BlockParams { footpath_width: footpath }).unwrap();
        for b in &bs {
            prop_assert!(b.polygon.validate().is_ok());
            let parcels: f64 = b.parcels.iter().map(Region::area).sum();
            let strips: f64 = b.footpath.strips.iter().map(PolygonWithHoles::area).sum();
            if footpath > 0.0 {
                prop_assert!((parcels + strips - b.polygon.area()).abs() < 1e-9 * b.polygon.area(), "{} + {} != {}", parcels, strips, b.polygon.area());
                for s in &b.footpath.strips {
                    prop_assert!(s.validate().is_ok());
                }
            }
            for parcel in &b.parcels {
                let s = subdivide(parcel, b.id(), &kelly(10.0, 25.0, 0.5), &mut Pcg64Mcg::seed_from_u64(seed)).unwrap();
                let ppw = PolygonWithHoles::new(
                    Polygon::new(parcel.outer.points.clone()),
                    parcel.holes.iter().map(|h| Polygon::new(h.points.clone())).collect(),
                );
                if let Err(e) = check_partition(&ppw, &s) { prop_assert!(false, "{}", e); }
                prop_assert!(s.lots.iter().all(|l| !l.street_edges.is_empty()));
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases(64)))]

    /// Garbage in (NaN, infinities, repeats, spikes, empty rings): errors out, never panics.
    #[test]
    fn never_panics_on_garbage(pts in prop::collection::vec((prop_oneof![
        Just(f64::NAN), Just(f64::INFINITY), Just(0.0), -5.0f64..5.0, (-3i32..3).prop_map(f64::from)
    ], (-3i32..3).prop_map(f64::from)), 0..12), flags in prop::collection::vec(any::<bool>(), 0..12)) {
        let ring = TaggedRing { points: pts.iter().map(|&(x, y)| v(x, y)).collect(), street: flags };
        let r = Region { outer: ring.clone(), holes: vec![] };
        let _ = polis_lots::split_by_line(&r, v(0.1, -9.0), v(0.3, 9.0));
        let _ = subdivide(&r, 0, &LotParams::default(), &mut Pcg64Mcg::seed_from_u64(1));
        let p: PolygonWithHoles = Polygon::new(ring.points.clone()).into();
        let _ = polis_lots::StraightSkeleton::new(&p);
        let _ = polis_lots::inset(&p, 0.5);
        let cell = Cell { id: 0, polygon: p, road_widths: vec![2.0; ring.points.len()] };
        let _ = blocks(&cell, &BlockParams::default());
    }
}
