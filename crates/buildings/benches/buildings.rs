//! Buildings on 57,000 lots (the size of Citygen's city, Kelly 2008 §6.5): boxes at LOD 0
//! and 1, and full grammar buildings with roofs (LOD 6), mixed kinds.
//!
//! Run: `cargo bench -p polis-buildings` — divan reports buildings/s; the table printed
//! after it gives buildings/s and triangles/s of one timed pass each.

use std::time::Instant;

use rayon::prelude::*;

use polis_buildings::{BuildingGenerator, BuildingKind, BuildingParams};
use polis_lots::Lot;

#[path = "common/lots.rs"]
mod city_lots;
use city_lots::{LOTS, lots};

/// Builds every lot at `lod`; returns (buildings, triangles).
fn run(g: &BuildingGenerator, lots: &[(Lot, BuildingKind)], lod: usize) -> (usize, usize) {
    let (mut n, mut t) = (0, 0);
    for (i, (lot, kind)) in lots.iter().enumerate() {
        if let Ok(Some(b)) = g.build(lot, i as u64, *kind, 300.0, lod) {
            n += 1;
            t += b.triangle_count();
        }
    }
    (n, t)
}

/// The calling thread's on-CPU time, seconds (Linux `schedstat`; 0 elsewhere). On a
/// machine shared with other jobs, wall-clock throughput drops with the load; CPU time
/// shows what the code does on a core it has to itself.
fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

/// Median of a small sample.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

const RUNS: usize = 5;

fn main() {
    divan::main();
    let g = BuildingGenerator::new(BuildingParams::default()).unwrap_or_else(|e| panic!("{e}"));
    let lots = lots();
    println!(
        "\n{:<26} {:>7} {:>13} {:>13} {:>13} {:>13}",
        "pass (57,000 lots), 1 thr",
        "built",
        "bldg/s wall",
        "bldg/s CPU",
        "tri/s wall",
        "tri/s CPU"
    );
    println!("(medians of {RUNS} runs; best run in brackets)");
    type Pass<'a> = (&'a str, Box<dyn Fn() -> (usize, usize) + 'a>);
    let passes: Vec<Pass<'_>> = vec![
        (
            "plan (footprint + height)",
            Box::new(|| {
                let n = lots
                    .iter()
                    .enumerate()
                    .filter(|(i, (l, k))| matches!(g.plan(l, *i as u64, *k, 300.0), Ok(Some(_))))
                    .count();
                (n, 0)
            }),
        ),
        ("LOD 0 (bounding box)", Box::new(|| run(&g, &lots, 0))),
        ("LOD 1", Box::new(|| run(&g, &lots, 1))),
        ("full grammar (LOD 6)", Box::new(|| run(&g, &lots, 6))),
    ];
    for (name, pass) in &passes {
        let (mut wall, mut cpu) = (Vec::new(), Vec::new());
        let (mut n, mut t) = (0, 0);
        for _ in 0..RUNS {
            let (start, c0) = (Instant::now(), thread_cpu_seconds());
            (n, t) = pass();
            wall.push(start.elapsed().as_secs_f64());
            cpu.push(thread_cpu_seconds() - c0);
        }
        let best_wall = wall.iter().copied().fold(f64::INFINITY, f64::min);
        let best_cpu = cpu.iter().copied().fold(f64::INFINITY, f64::min);
        let (mw, mc) = (median(wall), median(cpu));
        let rate = |count: usize, s: f64| {
            if s > 0.0 {
                format!("{:.0}k", count as f64 / s / 1e3)
            } else {
                "-".into()
            }
        };
        println!(
            "{name:<26} {n:>7} {:>13} {:>13} {:>13} {:>13}",
            format!("{} [{}]", rate(n, mw), rate(n, best_wall)),
            format!("{} [{}]", rate(n, mc), rate(n, best_cpu)),
            if t > 0 { rate(t, mw) } else { "-".into() },
            if t > 0 { rate(t, mc) } else { "-".into() },
        );
    }
    // The same passes on every core (rayon; buildings are independent and deterministic
    // per lot, so the output is the same).
    let threads = rayon::current_num_threads();
    for (name, lod) in [
        ("LOD 0, parallel", 0),
        ("LOD 1, parallel", 1),
        ("LOD 6, parallel", 6),
    ] {
        let start = Instant::now();
        let (n, t) = lots
            .par_iter()
            .enumerate()
            .map(
                |(i, (lot, kind))| match g.build(lot, i as u64, *kind, 300.0, lod) {
                    Ok(Some(b)) => (1, b.triangle_count()),
                    _ => (0, 0),
                },
            )
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        let s = start.elapsed().as_secs_f64();
        let name = format!("{name} ({threads} thr)");
        println!(
            "{name:<26} {n:>7} {:>13} {:>13} {:>13} {:>13}",
            format!("{:.0}k", n as f64 / s / 1e3),
            "-",
            format!("{:.0}k", t as f64 / s / 1e3),
            "-"
        );
    }
}

#[divan::bench(args = [0, 1, 6], sample_count = 3, sample_size = 1)]
fn buildings_57k(bencher: divan::Bencher<'_, '_>, lod: usize) {
    let g = BuildingGenerator::new(BuildingParams::default()).unwrap_or_else(|e| panic!("{e}"));
    let lots = lots();
    bencher
        .counter(divan::counter::ItemsCount::new(LOTS))
        .bench(|| run(&g, &lots, lod));
}
