//! Spatial-index throughput over 100,000 road-like segments: the hashed uniform grid
//! (`GridIndex`, the default) against the R*-tree (`RTreeIndex`, `rstar`).
//!
//! Run: `cargo bench -p polis-geom --bench spatial`. Data: 100,000 segments of 5–50 m
//! with uniform random start and direction in a 10 km × 10 km square (seeded). Each query
//! benchmark runs 1,000 queries per iteration, so items/s = queries per second.

use std::sync::LazyLock;

use divan::{Bencher, black_box, counter::ItemsCount};
use polis_geom::spatial::{GridIndex, GridOptions, RTreeIndex, Shape, SpatialIndex};
use polis_geom::{Aabb2, DVec2};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

const N: usize = 100_000;
const Q: usize = 1_000;
const SIZE: f64 = 10_000.0;

fn main() {
    divan::main();
}

fn random_segment(rng: &mut Pcg64Mcg) -> (DVec2, DVec2) {
    let a = DVec2::new(rng.random_range(0.0..SIZE), rng.random_range(0.0..SIZE));
    let len = rng.random_range(5.0..50.0);
    let ang = rng.random_range(0.0..std::f64::consts::TAU);
    (a, a + DVec2::new(ang.cos(), ang.sin()) * len)
}

static SEGMENTS: LazyLock<Vec<(u32, Shape)>> = LazyLock::new(|| {
    let mut rng = Pcg64Mcg::seed_from_u64(1);
    (0..N as u32)
        .map(|k| {
            let (a, b) = random_segment(&mut rng);
            (k, Shape::Segment(a, b))
        })
        .collect()
});

static QUERIES: LazyLock<Vec<(DVec2, DVec2)>> = LazyLock::new(|| {
    let mut rng = Pcg64Mcg::seed_from_u64(2);
    (0..Q).map(|_| random_segment(&mut rng)).collect()
});

/// A backend under test, with one shared index holding the 100,000 segments.
trait Backend: SpatialIndex<u32> + Sized + Sync + 'static {
    fn empty() -> Self;
    fn shared() -> &'static Self;
}

static GRID: LazyLock<GridIndex<u32>> = LazyLock::new(build::<GridIndex<u32>>);
// The R*-tree queried in its best shape: bulk-loaded.
static RTREE: LazyLock<RTreeIndex<u32>> =
    LazyLock::new(|| RTreeIndex::bulk_load(SEGMENTS.iter().copied()).unwrap_or_default());

impl Backend for GridIndex<u32> {
    fn empty() -> Self {
        GridIndex::default()
    }
    fn shared() -> &'static Self {
        &GRID
    }
}

impl Backend for RTreeIndex<u32> {
    fn empty() -> Self {
        RTreeIndex::new()
    }
    fn shared() -> &'static Self {
        &RTREE
    }
}

fn build<T: Backend>() -> T {
    let mut index = T::empty();
    for &(k, s) in SEGMENTS.iter() {
        let _ = index.insert(k, s);
    }
    index
}

/// Inserting 100,000 segments one by one into an empty index.
#[divan::bench(types = [GridIndex<u32>, RTreeIndex<u32>], sample_count = 5, sample_size = 1, counter = ItemsCount::new(N))]
fn insert_100k<T: Backend>() -> T {
    build::<T>()
}

/// Bulk loading the R*-tree (for comparison with one-by-one insertion).
#[divan::bench(sample_count = 5, sample_size = 1, counter = ItemsCount::new(N))]
fn rtree_bulk_load_100k() -> RTreeIndex<u32> {
    RTreeIndex::bulk_load(SEGMENTS.iter().copied()).unwrap_or_default()
}

/// Box queries: a 100 m × 100 m box around each query point.
#[divan::bench(types = [GridIndex<u32>, RTreeIndex<u32>], counter = ItemsCount::new(Q))]
fn query_box_100m<T: Backend>(b: Bencher<'_, '_>) {
    let index = T::shared();
    b.bench(|| {
        let mut n = 0;
        for &(a, _) in QUERIES.iter() {
            n += index.query_box(&Aabb2::new(a, a).expanded(50.0)).len();
        }
        black_box(n)
    });
}

/// Nearest segment within 25 m of each query point.
#[divan::bench(types = [GridIndex<u32>, RTreeIndex<u32>], counter = ItemsCount::new(Q))]
fn nearest_segment_25m<T: Backend>(b: Bencher<'_, '_>) {
    let index = T::shared();
    b.bench(|| {
        let mut n = 0;
        for &(a, _) in QUERIES.iter() {
            n += usize::from(index.nearest_segment(a, 25.0).is_some());
        }
        black_box(n)
    });
}

/// Nearest point within 25 m (the index holds only segments here, so this measures the
/// candidate walk alone).
#[divan::bench(types = [GridIndex<u32>, RTreeIndex<u32>], counter = ItemsCount::new(Q))]
fn nearest_point_25m<T: Backend>(b: Bencher<'_, '_>) {
    let index = T::shared();
    b.bench(|| {
        let mut n = 0;
        for &(a, _) in QUERIES.iter() {
            n += usize::from(index.nearest_point(a, 25.0).is_some());
        }
        black_box(n)
    });
}

/// All segments crossing a 5–50 m query segment, ordered along it.
#[divan::bench(types = [GridIndex<u32>, RTreeIndex<u32>], counter = ItemsCount::new(Q))]
fn segments_crossing<T: Backend>(b: Bencher<'_, '_>) {
    let index = T::shared();
    b.bench(|| {
        let mut n = 0;
        for &(a, c) in QUERIES.iter() {
            n += index.segments_crossing(a, c).len();
        }
        black_box(n)
    });
}

/// All segments crossing a 1 km query segment (a long highway probe).
#[divan::bench(types = [GridIndex<u32>, RTreeIndex<u32>], counter = ItemsCount::new(Q / 10))]
fn segments_crossing_1km<T: Backend>(b: Bencher<'_, '_>) {
    let index = T::shared();
    b.bench(|| {
        let mut n = 0;
        for &(a, c) in QUERIES.iter().take(Q / 10) {
            let far = a + (c - a).normalize_or_zero() * 1000.0;
            n += index.segments_crossing(a, far).len();
        }
        black_box(n)
    });
}

/// Removing and re-inserting 1,000 segments of a full index.
#[divan::bench(types = [GridIndex<u32>, RTreeIndex<u32>], sample_count = 20, counter = ItemsCount::new(Q))]
fn remove_reinsert<T: Backend + Clone>(b: Bencher<'_, '_>) {
    b.with_inputs(|| T::shared().clone())
        .bench_local_values(|mut index| {
            for &(k, s) in SEGMENTS.iter().take(Q) {
                index.remove(k);
                let _ = index.insert(k, s);
            }
            index
        });
}

/// One query of each kind (100 m box, nearest segment within 25 m, crossing a 5–50 m
/// segment) per query point, so items/s = mixed-query triples per second.
fn mixed<T: SpatialIndex<u32>>(index: &T) -> usize {
    let mut n = 0;
    for &(a, c) in QUERIES.iter() {
        n += index.query_box(&Aabb2::new(a, a).expanded(50.0)).len();
        n += usize::from(index.nearest_segment(a, 25.0).is_some());
        n += index.segments_crossing(a, c).len();
    }
    n
}

/// The mixed workload on grids of different cell sizes (metres), to choose the default.
#[divan::bench(args = [8.0, 16.0, 32.0, 64.0, 128.0], counter = ItemsCount::new(Q))]
fn mixed_grid_cell_size(b: Bencher<'_, '_>, cell: f64) {
    let mut index = GridIndex::new(GridOptions { cell_size: cell }).unwrap_or_default();
    for &(k, s) in SEGMENTS.iter() {
        let _ = index.insert(k, s);
    }
    b.bench(|| black_box(mixed(&index)));
}

/// The mixed workload on the bulk-loaded R*-tree.
#[divan::bench(counter = ItemsCount::new(Q))]
fn mixed_rtree(b: Bencher<'_, '_>) {
    let index = RTreeIndex::<u32>::shared();
    b.bench(|| black_box(mixed(index)));
}
