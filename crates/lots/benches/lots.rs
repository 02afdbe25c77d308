//! Benchmarks: straight skeletons of random convex, star-shaped and concave polygons, and
//! lot subdivision of Manhattan-size blocks.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use polis_lots::StraightSkeleton;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

fn main() {
    divan::main();
}

const SIZES: [usize; 4] = [10, 100, 1_000, 10_000];

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

#[divan::bench(args = SIZES)]
fn skeleton_convex(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = convex(n);
    bencher.bench(|| StraightSkeleton::new(divan::black_box(&p)).unwrap());
}

#[divan::bench(args = SIZES)]
fn skeleton_star(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = star(n);
    bencher.bench(|| StraightSkeleton::new(divan::black_box(&p)).unwrap());
}

#[divan::bench(args = SIZES)]
fn skeleton_concave(bencher: divan::Bencher<'_, '_>, n: usize) {
    let p = concave(n);
    bencher.bench(|| StraightSkeleton::new(divan::black_box(&p)).unwrap());
}
