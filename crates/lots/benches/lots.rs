//! Benchmarks: straight skeletons and insets of random convex, star-shaped and concave
//! polygons, and lot subdivision of Manhattan-size blocks.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use polis_lots::{LotParams, LotStrategy, Region, StraightSkeleton, Subdivider, TaggedRing};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

fn main() {
    divan::main();
}

/// Polygon sizes: 10, 100, 1,000 and 10,000 vertices, or the comma-separated list in
/// `LOTS_SIZES` (to time one size alone).
fn sizes() -> Vec<usize> {
    std::env::var("LOTS_SIZES")
        .ok()
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![10, 100, 1_000, 10_000])
}

/// Points on a circle at random angles: convex.
fn convex(n: usize) -> PolygonWithHoles {
    let mut rng = Pcg64Mcg::seed_from_u64(1);
    let mut angles: Vec<f64> = (0..n)
        .map(|_| rng.random_range(0.0..std::f64::consts::TAU))
        .collect();
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    Polygon::new(
        angles
            .iter()
            .map(|a| DVec2::new(a.cos(), a.sin()) * 100.0)
            .collect(),
    )
    .into()
}

/// Random radii at evenly jittered angles: star-shaped, about half the vertices reflex.
fn star(n: usize) -> PolygonWithHoles {
    let mut rng = Pcg64Mcg::seed_from_u64(2);
    Polygon::new(
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * (i as f64 + rng.random_range(0.0..0.5)) / n as f64;
                DVec2::new(a.cos(), a.sin()) * rng.random_range(50.0..100.0)
            })
            .collect(),
    )
    .into()
}

/// A comb of random-depth teeth: concave, half the vertices reflex, many parallel edges.
fn concave(n: usize) -> PolygonWithHoles {
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let teeth = (n.max(8) - 4) / 4;
    let mut pts = vec![
        DVec2::new(0.0, -10.0),
        DVec2::new(teeth as f64 * 2.0, -10.0),
    ];
    for i in (0..teeth).rev() {
        let x = i as f64 * 2.0;
        let depth = rng.random_range(1.0..9.0);
        pts.push(DVec2::new(x + 2.0, 10.0));
        pts.push(DVec2::new(x + 1.6, 10.0 - depth));
        pts.push(DVec2::new(x + 0.4, 10.0 - depth));
    }
    pts.push(DVec2::new(0.0, 10.0));
    Polygon::new(pts).into()
}

#[divan::bench(args = sizes())]
fn skeleton_convex(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = convex(n);
    bencher.bench(|| StraightSkeleton::new(divan::black_box(&p)).unwrap());
}

#[divan::bench(args = sizes())]
fn skeleton_star(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = star(n);
    bencher.bench(|| StraightSkeleton::new(divan::black_box(&p)).unwrap());
}

#[divan::bench(args = sizes())]
fn skeleton_concave(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = concave(n);
    bencher.bench(|| StraightSkeleton::new(divan::black_box(&p)).unwrap());
}

/// Insets of the star (10 m: reflex vertices meeting, the wavefront in pieces) and of the
/// comb (0.3 m: every tooth still there), each ring cleaned of pinches and touches.
#[divan::bench(args = sizes())]
fn inset_star(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = star(n);
    bencher.bench(|| polis_lots::inset(divan::black_box(&p), 10.0).unwrap());
}

#[divan::bench(args = sizes())]
fn inset_concave(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = concave(n);
    bencher.bench(|| polis_lots::inset(divan::black_box(&p), 0.3).unwrap());
}

/// 10,000 Manhattan-size blocks (about 60 × 240 m, sizes and angles jittered).
fn manhattan_blocks() -> Vec<Region> {
    let mut rng = Pcg64Mcg::seed_from_u64(4);
    (0..10_000)
        .map(|i| {
            let w = rng.random_range(55.0..65.0);
            let h = rng.random_range(220.0..260.0);
            let rot = DVec2::from_angle(rng.random_range(0.0..std::f64::consts::PI));
            let origin = DVec2::new((i % 100) as f64 * 300.0, (i / 100) as f64 * 300.0);
            let rect = Polygon::rect(DVec2::ZERO, DVec2::new(w, h));
            Region {
                outer: TaggedRing {
                    points: rect
                        .points()
                        .iter()
                        .map(|&p| origin + rot.rotate(p))
                        .collect(),
                    street: vec![true; 4],
                },
                holes: vec![],
            }
        })
        .collect()
}

fn manhattan_params(strategy: LotStrategy) -> LotParams {
    LotParams {
        strategy,
        lot_width: 7.6,
        lot_depth: 30.0,
        deviance: 0.2,
        min_area: 20.0,
        max_area: 7.6 * 30.0 * 1.3,
        ..LotParams::default()
    }
}

fn subdivide_all(bencher: divan::Bencher<'_, '_>, strategy: LotStrategy) {
    let blocks = manhattan_blocks();
    let params = manhattan_params(strategy);
    let mut worker = Subdivider::new();
    bencher.bench_local(|| {
        let mut lots = 0;
        for (i, b) in blocks.iter().enumerate() {
            let mut rng = Pcg64Mcg::seed_from_u64(i as u64);
            lots += worker
                .subdivide(b, i as u64, &params, &mut rng)
                .unwrap()
                .lots
                .len();
        }
        lots
    });
}

/// Kelly's subdivision of 10,000 Manhattan blocks into 7.6 × 30 m lots.
#[divan::bench(sample_count = 10)]
fn subdivide_10000_blocks_kelly(bencher: divan::Bencher<'_, '_>) {
    subdivide_all(bencher, LotStrategy::Kelly);
}

/// Parish & Müller's subdivision of the same blocks (lots under 1.3 × 7.6 × 30 m²).
#[divan::bench(sample_count = 10)]
fn subdivide_10000_blocks_parish_mueller(bencher: divan::Bencher<'_, '_>) {
    subdivide_all(bencher, LotStrategy::ParishMueller);
}
