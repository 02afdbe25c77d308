//! The course report's grid road builders in one 500 m × 500 m cell, per shipped rule
//! set (Downtown, Residential), on flat dry land: the whole call (validation, grid,
//! builders, planar graph) with a reused worker, over a few seeds.
//!
//! `cargo bench -p polis-roads --bench grid_builders`; divan reports the time per cell
//! (and cells/s as item throughput).
//!
//! For whole-process timings, `POLIS_GRID_CELLS=N` (optionally with
//! `POLIS_GRID_RULES=downtown` or `residential`) grows N cells per rule set with seeds
//! 0..N, prints the in-process time and exits without divan:
//! `POLIS_GRID_CELLS=2000 POLIS_GRID_RULES=downtown cargo bench -p polis-roads --bench grid_builders`.

#![allow(clippy::unwrap_used)]

use divan::counter::ItemsCount;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use polis_roads::grid_builders::{GridBuilderGrowth, GridMaps, GridParams};

/// Grows `n` cells per selected rule set and reports the time (whole-process mode).
fn batch(n: u64, only: Option<&str>) {
    let maps = GridMaps::none();
    let mut worker = GridBuilderGrowth::new();
    for params in [GridParams::downtown(), GridParams::residential()] {
        if only.is_some_and(|o| !params.rules.name.eq_ignore_ascii_case(o)) {
            continue;
        }
        let t = std::time::Instant::now();
        let mut edges = 0;
        for seed in 0..n {
            edges += worker
                .grow(&cell(), &[], &maps, &params, seed)
                .unwrap()
                .network
                .edge_count();
        }
        let s = t.elapsed().as_secs_f64();
        println!(
            "{:<12} {n} cells: {:.3} s, {:.1} µs per cell, {:.1} edges per cell",
            params.rules.name,
            s,
            s * 1e6 / n as f64,
            edges as f64 / n as f64
        );
    }
}

fn main() {
    if let Some(n) = std::env::var("POLIS_GRID_CELLS")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        batch(n, std::env::var("POLIS_GRID_RULES").ok().as_deref());
        return;
    }
    // Per-seed table first: the time of one cell varies with how far the builders get.
    let maps = GridMaps::none();
    let mut worker = GridBuilderGrowth::new();
    for params in [GridParams::downtown(), GridParams::residential()] {
        for seed in 1..16 {
            let t = std::time::Instant::now();
            let roads = worker.grow(&cell(), &[], &maps, &params, seed).unwrap();
            eprintln!(
                "{:<12} seed {seed:>2}: {:>8.1} µs, {} edges, {} steps",
                params.rules.name,
                t.elapsed().as_secs_f64() * 1e6,
                roads.network.edge_count(),
                roads.report.steps
            );
        }
    }
    divan::main();
}

fn cell() -> PolygonWithHoles {
    Polygon::rect(DVec2::ZERO, DVec2::splat(500.0)).into()
}

fn run(params: &GridParams, bencher: divan::Bencher<'_, '_>) {
    let cell = cell();
    let maps = GridMaps::none();
    let mut worker = GridBuilderGrowth::new();
    let mut seed = 0u64;
    bencher.counter(ItemsCount::new(1usize)).bench_local(|| {
        seed = seed.wrapping_add(1) % 16;
        let roads = worker.grow(&cell, &[], &maps, params, seed).unwrap();
        divan::black_box(roads.network.edge_count())
    });
}

#[divan::bench]
fn downtown_500m(bencher: divan::Bencher<'_, '_>) {
    run(&GridParams::downtown(), bencher);
}

#[divan::bench]
fn residential_500m(bencher: divan::Bencher<'_, '_>) {
    run(&GridParams::residential(), bencher);
}
