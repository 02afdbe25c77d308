//! Field sampling throughput: the input maps are read at every road-growth step (P&M
//! global goals sample population along rays; local constraints test water and parks).
//!
//! Run: `cargo bench -p polis-geom --bench field`. Each iteration samples 10,000 seeded
//! random points in a 10 km × 10 km square, so items/s = samples per second.

use std::sync::LazyLock;

use divan::{Bencher, black_box, counter::ItemsCount};
use polis_geom::field::{
    Fbm, FbmParams, Field, FieldExt, Population, PopulationParams, Raster, SimplexNoise,
};
use polis_geom::{Aabb2, DVec2};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

const N: usize = 10_000;
const SIZE: f64 = 10_000.0;

fn main() {
    divan::main();
}

static POINTS: LazyLock<Vec<DVec2>> = LazyLock::new(|| {
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    (0..N)
        .map(|_| DVec2::new(rng.random_range(0.0..SIZE), rng.random_range(0.0..SIZE)))
        .collect()
});

fn fbm(octaves: u32) -> Fbm {
    Fbm::new(FbmParams {
        seed: 3,
        octaves,
        ..FbmParams::default()
    })
    .unwrap_or_else(|e| panic!("{e}"))
}

fn raster() -> Raster {
    let extent = Aabb2::new(DVec2::ZERO, DVec2::splat(SIZE));
    Raster::from_field(&fbm(5), 1024, 1024, extent).unwrap_or_else(|e| panic!("{e}"))
}

fn run<F: Field + ?Sized>(bencher: Bencher<'_, '_>, field: &F, gradient: bool) {
    let points = &*POINTS;
    bencher.counter(ItemsCount::new(N)).bench(|| {
        let mut acc = 0.0;
        for &p in points {
            if gradient {
                let (v, g) = field.sample_with_gradient(black_box(p));
                acc += v + g.x;
            } else {
                acc += field.sample(black_box(p));
            }
        }
        acc
    });
}

#[divan::bench(args = [false, true])]
fn simplex(bencher: Bencher<'_, '_>, gradient: bool) {
    run(bencher, &SimplexNoise::new(1).magnified(500.0), gradient);
}

#[divan::bench(args = [1, 5, 8])]
fn fbm_octaves(bencher: Bencher<'_, '_>, octaves: u32) {
    run(bencher, &fbm(octaves), false);
}

#[divan::bench]
fn fbm_5_with_gradient(bencher: Bencher<'_, '_>) {
    run(bencher, &fbm(5), true);
}

#[divan::bench(args = [false, true])]
fn population(bencher: Bencher<'_, '_>, gradient: bool) {
    let pop = Population::new(PopulationParams::default()).unwrap_or_else(|e| panic!("{e}"));
    run(bencher, &pop, gradient);
}

#[divan::bench(args = [false, true])]
fn raster_1024(bencher: Bencher<'_, '_>, gradient: bool) {
    run(bencher, &raster(), gradient);
}

/// A typical legality map behind a trait object: water where fBm dips, as roads hold it.
#[divan::bench]
fn boxed_threshold_chain(bencher: Bencher<'_, '_>) {
    let water: Box<dyn Field> = fbm(5).threshold(-0.3).scaled(-1.0).offset(1.0).boxed();
    run(bencher, &water, false);
}
