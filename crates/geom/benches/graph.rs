//! Planar insertion into `PlanarGraph`: 100,000 random short segments into an empty graph.
//!
//! Run: `cargo bench -p polis-geom --bench graph`. Every segment is inserted with
//! `insert_segment` (snap 1 cm), so each one pays for snapping, crossing search, splits
//! and index updates. Items/s = input segments per second.

use divan::{black_box, counter::ItemsCount};
use polis_geom::DVec2;
use polis_geom::graph::{PlanarGraph, SnapOptions};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

const N: usize = 100_000;

fn main() {
    divan::main();
}

/// 100,000 segments of 5–50 m, uniform start and direction, in a 10 km square.
fn random_segments() -> Vec<(DVec2, DVec2)> {
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    (0..N)
        .map(|_| {
            let a = DVec2::new(
                rng.random_range(0.0..10_000.0),
                rng.random_range(0.0..10_000.0),
            );
            let len = rng.random_range(5.0..50.0);
            let ang = rng.random_range(0.0..std::f64::consts::TAU);
            (a, a + DVec2::new(ang.cos(), ang.sin()) * len)
        })
        .collect()
}

/// 100,000 axis-aligned segments of 1–5 blocks on a 10 m lattice in a 2 km square: many
/// collinear overlaps, shared ends and T-junctions (a street grid drawn many times over).
fn lattice_segments() -> Vec<(DVec2, DVec2)> {
    let mut rng = Pcg64Mcg::seed_from_u64(8);
    (0..N)
        .map(|_| {
            let a = DVec2::new(
                f64::from(rng.random_range(0..200i32)) * 10.0,
                f64::from(rng.random_range(0..200i32)) * 10.0,
            );
            let len = f64::from(rng.random_range(1..=5i32)) * 10.0;
            let d = match rng.random_range(0..4u8) {
                0 => DVec2::X,
                1 => DVec2::Y,
                2 => -DVec2::X,
                _ => -DVec2::Y,
            };
            (a, a + d * len)
        })
        .collect()
}

fn insert_all(segs: &[(DVec2, DVec2)]) -> PlanarGraph<(), u32> {
    let mut g = PlanarGraph::new();
    let opts = SnapOptions::default();
    for (i, &(p, q)) in segs.iter().enumerate() {
        let _ = black_box(g.insert_segment(p, q, i as u32, &opts));
    }
    g
}

#[divan::bench(sample_count = 3, sample_size = 1, counter = ItemsCount::new(N))]
fn insert_100k_random_short(b: divan::Bencher<'_, '_>) {
    let segs = random_segments();
    b.bench(|| insert_all(&segs));
}

#[divan::bench(sample_count = 3, sample_size = 1, counter = ItemsCount::new(N))]
fn insert_100k_lattice(b: divan::Bencher<'_, '_>) {
    let segs = lattice_segments();
    b.bench(|| insert_all(&segs));
}

/// A full `check_invariants` of the random-segment graph (for scale).
#[divan::bench(sample_count = 3, sample_size = 1)]
fn check_invariants_random(b: divan::Bencher<'_, '_>) {
    let g = insert_all(&random_segments());
    b.bench(|| g.check_invariants().is_ok());
}
