//! Road generation throughput and peak memory: 15,000 and 100,000 segments with the
//! procedural default maps (population, noise coastline, hills).
//!
//! `cargo bench -p polis-roads`; segments/s is divan's item throughput. Peak memory is
//! the growth of the process's peak resident set (`VmHWM`) over its resident set before
//! the first run; sizes run in increasing order, so each figure is that size's peak.

#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use divan::counter::ItemsCount;
use polis_geom::field::{Population, PopulationParams};
use polis_roads::{Pattern, RoadInputs, RoadParams, generate};

/// A field of `/proc/self/status` in KiB (0 where unavailable).
fn status_kib(key: &str) -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(key))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse().ok())
        })
        .unwrap_or(0)
}

/// CPU time of this thread in seconds (`/proc/thread-self/schedstat`, ns on CPU): the
/// machine is shared, so wall time overstates the cost under load.
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| {
            s.split_whitespace()
                .next()
                .and_then(|v| v.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

fn main() {
    let base = status_kib("VmRSS:");
    for &(n, pattern, flat) in &[
        (15_000, Pattern::Basic, true),
        (15_000, Pattern::Basic, false),
        (15_000, Pattern::NewYork, false),
        (100_000, Pattern::Basic, false),
    ] {
        let (params, inputs) = if flat {
            setup_flat(n)
        } else {
            setup(n, pattern)
        };
        let t = std::time::Instant::now();
        let c0 = cpu_s();
        let city = generate(&params, &inputs).unwrap();
        let cpu = cpu_s() - c0;
        let dt = t.elapsed().as_secs_f64();
        let peak = status_kib("VmHWM:").saturating_sub(base);
        println!(
            "{n:>7} segments {pattern:?}{}: got {} segments, {} edges, wall {:.1} ms, CPU {:.1} ms, {:.0} segments/CPU-s, peak RSS +{:.1} MiB",
            if flat { " (population only)" } else { "" },
            city.report.segments,
            city.network.edge_count(),
            dt * 1e3,
            cpu * 1e3,
            city.report.segments as f64 / cpu,
            peak as f64 / 1024.0
        );
        println!("        {:?}", city.report.constraints);
    }
    divan::main();
}

/// A map big enough for `n` segments (street density of the default city).
fn setup(n: usize, pattern: Pattern) -> (RoadParams, RoadInputs) {
    let half = 2000.0 * (n as f64 / 1500.0).sqrt().max(1.0);
    let params = RoadParams {
        pattern,
        bounds_min: [-half, -half],
        bounds_max: [half, half],
        max_segments: n,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::procedural(params.seed, &params).unwrap();
    (params, inputs)
}

/// Population map only (no water, parks or hills): the generator's own cost without
/// legality sampling of noise maps.
fn setup_flat(n: usize) -> (RoadParams, RoadInputs) {
    let (params, _) = setup(n, Pattern::Basic);
    let pop = Population::new(PopulationParams {
        seed: params.seed,
        unit_m: 100.0,
    })
    .unwrap();
    (params, RoadInputs::flat(Arc::new(pop)))
}

#[divan::bench(args = [15_000], sample_count = 3, sample_size = 1)]
fn basic_population_only(bencher: divan::Bencher<'_, '_>, n: usize) {
    let (params, inputs) = setup_flat(n);
    bencher
        .counter(ItemsCount::new(n))
        .bench(|| generate(&params, &inputs).unwrap());
}

#[divan::bench(args = [15_000, 100_000], sample_count = 3, sample_size = 1)]
fn basic(bencher: divan::Bencher<'_, '_>, n: usize) {
    let (params, inputs) = setup(n, Pattern::Basic);
    bencher
        .counter(ItemsCount::new(n))
        .bench(|| generate(&params, &inputs).unwrap());
}

#[divan::bench(args = [15_000], sample_count = 3, sample_size = 1)]
fn new_york(bencher: divan::Bencher<'_, '_>, n: usize) {
    let (params, inputs) = setup(n, Pattern::NewYork);
    bencher
        .counter(ItemsCount::new(n))
        .bench(|| generate(&params, &inputs).unwrap());
}
