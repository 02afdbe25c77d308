//! Cell extraction throughput on perturbed grids and random planar graphs.
//!
//! Run: `cargo bench -p polis-cells --bench cells`. Sizes are edge counts (`CELLS_SIZES`
//! picks some, e.g. `CELLS_SIZES=100000`). "unchecked" skips the planarity check, as
//! extraction does for graphs that are planar by construction.

#![allow(clippy::unwrap_used)]

use divan::{Bencher, black_box};
use polis_cells::geom::{DVec2, NodeId, PlanarGraph};
use polis_cells::{CellExtractor, CellParams};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use spade::{DelaunayTriangulation, Point2, Triangulation};

fn main() {
    divan::main();
}

/// A grid of about `edges` edges, nodes jittered by up to 0.25 of the spacing, 5% of the
/// edges removed.
fn perturbed_grid(edges: usize, seed: u64) -> PlanarGraph<(), ()> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let n = ((edges as f64 / 2.0).sqrt().ceil() as usize).max(2);
    let mut g = PlanarGraph::new();
    let mut id: Vec<NodeId> = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let p = DVec2::new(
                i as f64 * 10.0 + rng.random_range(-2.5..2.5),
                j as f64 * 10.0 + rng.random_range(-2.5..2.5),
            );
            id.push(g.add_node(p, ()).unwrap());
        }
    }
    for j in 0..n {
        for i in 0..n {
            if i + 1 < n && rng.random_range(0.0..1.0) > 0.05 {
                g.add_edge(id[j * n + i], id[j * n + i + 1], ()).unwrap();
            }
            if j + 1 < n && rng.random_range(0.0..1.0) > 0.05 {
                g.add_edge(id[j * n + i], id[(j + 1) * n + i], ()).unwrap();
            }
        }
    }
    g
}

/// A Delaunay triangulation of random points with 35% of its edges removed: about
/// `edges` edges, with dead ends, bridges and islands.
fn random_planar(edges: usize, seed: u64) -> PlanarGraph<(), ()> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let points = ((edges as f64 / 0.65 / 3.0) as usize).max(3);
    let side = (points as f64).sqrt() * 10.0;
    let pts: Vec<Point2<f64>> = (0..points)
        .map(|_| Point2::new(rng.random_range(0.0..side), rng.random_range(0.0..side)))
        .collect();
    let tri = DelaunayTriangulation::<Point2<f64>>::bulk_load(pts).unwrap();
    let mut g = PlanarGraph::new();
    let mut id = Vec::new();
    for v in tri.vertices() {
        let p = v.position();
        id.push(g.add_node(DVec2::new(p.x, p.y), ()).unwrap());
    }
    for e in tri.undirected_edges() {
        if rng.random_range(0.0..1.0) < 0.35 {
            continue;
        }
        let [a, b] = e.vertices();
        g.add_edge(id[a.fix().index()], id[b.fix().index()], ())
            .unwrap();
    }
    g
}

/// Edge counts: 10³ … 10⁶, or the comma-separated list in `CELLS_SIZES` (to time one size
/// alone, e.g. under `perf stat -e task-clock` on a loaded machine).
fn sizes() -> Vec<usize> {
    let all = vec![1_000, 10_000, 100_000, 1_000_000];
    match std::env::var("CELLS_SIZES") {
        Ok(s) => s.split(',').filter_map(|x| x.trim().parse().ok()).collect(),
        Err(_) => all,
    }
}

#[divan::bench(args = sizes(), sample_count = 10, sample_size = 1)]
fn grid(bencher: Bencher<'_, '_>, edges: usize) {
    let g = perturbed_grid(edges, 7);
    let mut x = CellExtractor::new();
    let params = CellParams::default();
    bencher
        .counter(divan::counter::ItemsCount::new(g.edge_count()))
        .bench_local(|| black_box(x.extract(&g, &params).unwrap()));
}

#[divan::bench(args = sizes(), sample_count = 10, sample_size = 1)]
fn grid_unchecked(bencher: Bencher<'_, '_>, edges: usize) {
    let g = perturbed_grid(edges, 7);
    let mut x = CellExtractor::new();
    let params = CellParams {
        check_planarity: false,
        ..CellParams::default()
    };
    bencher
        .counter(divan::counter::ItemsCount::new(g.edge_count()))
        .bench_local(|| black_box(x.extract(&g, &params).unwrap()));
}

#[divan::bench(args = sizes(), sample_count = 10, sample_size = 1)]
fn random(bencher: Bencher<'_, '_>, edges: usize) {
    let g = random_planar(edges, 11);
    let mut x = CellExtractor::new();
    let params = CellParams::default();
    bencher
        .counter(divan::counter::ItemsCount::new(g.edge_count()))
        .bench_local(|| black_box(x.extract(&g, &params).unwrap()));
}

#[divan::bench(args = sizes(), sample_count = 10, sample_size = 1)]
fn random_unchecked(bencher: Bencher<'_, '_>, edges: usize) {
    let g = random_planar(edges, 11);
    let mut x = CellExtractor::new();
    let params = CellParams {
        check_planarity: false,
        ..CellParams::default()
    };
    bencher
        .counter(divan::counter::ItemsCount::new(g.edge_count()))
        .bench_local(|| black_box(x.extract(&g, &params).unwrap()));
}
