//! Road generation throughput and peak memory: 15,000 and 100,000 segments with the
//! procedural default maps (population, noise coastline, hills).
//!
//! `cargo bench -p polis-roads`; segments/s is divan's item throughput. Before divan
//! starts, a table gives each size's best and median CPU and wall time over several runs
//! (`POLIS_ROADS_REPEATS`, default 5; `POLIS_ROADS_MAX_N` skips larger sizes) and its
//! peak memory: the growth of the peak resident set (`VmHWM`) of a fresh process doing
//! one run (see `child_peak_mib`).

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

/// Runs per size of the table (`POLIS_ROADS_REPEATS`, default 5).
fn table_repeats() -> usize {
    std::env::var("POLIS_ROADS_REPEATS")
        .ok()
        .and_then(|v| v.parse().ok())
        .filter(|&r| r > 0)
        .unwrap_or(5)
}

/// Largest size in the table (`POLIS_ROADS_MAX_N`, default: all).
fn max_table_size() -> usize {
    std::env::var("POLIS_ROADS_MAX_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(usize::MAX)
}

/// The table's runs: size, pattern, population map only.
const TABLE: [(usize, Pattern, bool); 4] = [
    (15_000, Pattern::Basic, true),
    (15_000, Pattern::Basic, false),
    (15_000, Pattern::NewYork, false),
    (100_000, Pattern::Basic, false),
];

fn inputs_for(n: usize, pattern: Pattern, flat: bool) -> (RoadParams, RoadInputs) {
    if flat {
        setup_flat(n)
    } else {
        setup(n, pattern)
    }
}

/// Peak memory of one run of table row `row`, measured in a fresh child process (this
/// executable, re-run with `POLIS_ROADS_CHILD=row`): the growth of the peak resident set
/// (`VmHWM`) over the resident set after the maps were built. A fresh process is needed
/// because the allocator keeps freed memory, which would hide a second run's growth.
fn child_peak_mib(row: usize) -> f64 {
    std::env::current_exe()
        .ok()
        .and_then(|exe| {
            std::process::Command::new(exe)
                .env("POLIS_ROADS_CHILD", row.to_string())
                .output()
                .ok()
        })
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|s| s.trim().parse::<f64>().ok())
        .unwrap_or(f64::NAN)
}

fn main() {
    if let Some(row) = std::env::var("POLIS_ROADS_CHILD")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        let (n, pattern, flat) = TABLE[row];
        let (params, inputs) = inputs_for(n, pattern, flat);
        let base = status_kib("VmRSS:");
        let city = generate(&params, &inputs).unwrap();
        let peak = status_kib("VmHWM:").saturating_sub(base);
        println!("{}", peak as f64 / 1024.0);
        drop(city);
        return;
    }
    for (row, &(n, pattern, flat)) in TABLE.iter().enumerate() {
        if n > max_table_size() {
            continue;
        }
        let (params, inputs) = inputs_for(n, pattern, flat);
        // Several runs (fewer for the big size): the machine is shared, so the best CPU
        // and wall times are the better guide; the median is printed too.
        let repeats = if n > 50_000 { 3 } else { table_repeats() };
        let (mut cpus, mut walls) = (Vec::new(), Vec::new());
        let mut city = None;
        for _ in 0..repeats {
            // Free the previous run's network before timing the next one.
            drop(city.take());
            let t = std::time::Instant::now();
            let c0 = cpu_s();
            let run = generate(&params, &inputs).unwrap();
            cpus.push(cpu_s() - c0);
            walls.push(t.elapsed().as_secs_f64());
            city = Some(run);
        }
        let Some(city) = city else { continue };
        cpus.sort_by(f64::total_cmp);
        walls.sort_by(f64::total_cmp);
        let (cpu, cpu_med) = (cpus[0], cpus[cpus.len() / 2]);
        println!(
            "{n:>7} segments {pattern:?}{}: got {} segments, {} edges, {repeats} runs: wall best {:.1} ms / median {:.1} ms, CPU best {:.1} ms / median {:.1} ms, {:.0} segments/CPU-s (best), peak RSS +{:.1} MiB",
            if flat { " (population only)" } else { "" },
            city.report.segments,
            city.network.edge_count(),
            walls[0] * 1e3,
            walls[walls.len() / 2] * 1e3,
            cpu * 1e3,
            cpu_med * 1e3,
            city.report.segments as f64 / cpu,
            child_peak_mib(row),
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
