//! Prints a table of cell-extraction times: perturbed grids and random planar graphs from
//! 10³ to 10⁶ edges, with and without the planarity check.
//!
//! Run: `cargo run --release -p polis-cells --example cells_table`.
//!
//! Besides wall-clock time it reports the CPU time of the measuring thread (Linux
//! `/proc/thread-self/schedstat`), which stays meaningful on a loaded machine where the
//! thread waits for a core: wall time is the minimum over the repetitions, CPU time the
//! mean. Filters: `cells_table [grid|random] [edges]`.

#![allow(clippy::unwrap_used)]

use std::time::Instant;

use polis_cells::geom::{DVec2, NodeId, PlanarGraph};
use polis_cells::{CellExtractor, CellParams};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use spade::{DelaunayTriangulation, Point2, Triangulation};

/// CPU time of this thread in nanoseconds, if the kernel reports it.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

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

fn main() {
    // Optional filters: `cells_table [grid|random] [edges]`.
    let args: Vec<String> = std::env::args().skip(1).collect();
    let only_graph = args.first().cloned();
    let only_size: Option<usize> = args.get(1).and_then(|s| s.parse().ok());
    let sizes: Vec<usize> = [1_000usize, 10_000, 100_000, 1_000_000]
        .into_iter()
        .filter(|&s| only_size.is_none_or(|o| o == s))
        .collect();
    println!("| graph | edges | cells | check | wall ms | cpu ms | edges/s (cpu) | cpu ns/edge |");
    println!("|---|---:|---:|---|---:|---:|---:|---:|");
    let mut x = CellExtractor::new();
    for (name, make) in [
        (
            "perturbed grid",
            perturbed_grid as fn(usize, u64) -> PlanarGraph<(), ()>,
        ),
        ("random planar", random_planar),
    ] {
        if only_graph
            .as_ref()
            .is_some_and(|o| !name.contains(o.as_str()))
        {
            continue;
        }
        for &size in &sizes {
            let g = make(size, 7);
            for check in [false, true] {
                let params = CellParams {
                    check_planarity: check,
                    ..CellParams::default()
                };
                let reps = (2_000_000 / size).clamp(3, 50);
                let (mut wall, mut cpu) = (f64::INFINITY, 0.0);
                let mut cells = 0;
                for _ in 0..reps {
                    let (t0, c0) = (Instant::now(), cpu_ns());
                    let d = x.extract(&g, &params).unwrap();
                    let (t1, c1) = (Instant::now(), cpu_ns());
                    cells = d.cells.len();
                    drop(d);
                    wall = wall.min((t1 - t0).as_secs_f64() * 1e3);
                    if let (Some(a), Some(b)) = (c0, c1) {
                        cpu += (b - a) as f64 / 1e6;
                    }
                }
                cpu /= reps as f64;
                let e = g.edge_count();
                println!(
                    "| {name} | {e} | {cells} | {} | {wall:.2} | {cpu:.2} | {:.2e} | {:.0} |",
                    if check { "yes" } else { "no" },
                    e as f64 / (cpu / 1e3),
                    cpu * 1e6 / e as f64,
                );
            }
        }
    }
}
