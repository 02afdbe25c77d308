//! Road growth on the JavaScript peer's workload (phiresky/procedural-cities, `PEERS.md`;
//! the mapping of its settings is in `common/peer.rs`): 15,000 segments, timed like the
//! peer — the first run in this fresh process ("cold") and runs 2–11 ("warm") — by wall
//! time and by this thread's CPU time, printed as segments per second beside the peer's
//! figures.
//!
//! Run: `cargo bench -p polis-roads --bench peer` (`-- once` grows one network and exits:
//! for profilers and fresh-process timings; `-- serial` turns speculative evaluation off,
//! `RoadGenerator::with_speculation`). The process's CPU time (all threads) is printed
//! beside the thread's: with speculative evaluation the thread pool does part of the work.

#![allow(clippy::unwrap_used)]

use std::time::Instant;

use polis_roads::RoadGenerator;

#[path = "common/peer.rs"]
mod peer;
use peer::{PEER_COLD_MS, PEER_SEGMENTS, PEER_WARM_MS, peer_params};

/// CPU time of this thread in seconds (`/proc/thread-self/schedstat`).
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

/// CPU time of the whole process (all threads) in seconds (`/proc/self/stat`, clock
/// ticks of 10 ms: only meaningful over many runs).
fn process_cpu_s() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the command name (which is in parentheses): utime and stime are the
    // 12th and 13th of them.
    let rest = s.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|x| x.parse().ok())
        .collect();
    if f.len() == 2 {
        (f[0] + f[1]) / 100.0
    } else {
        f64::NAN
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn main() {
    let (params, inputs) = peer_params(PEER_SEGMENTS);
    let once = std::env::args().any(|a| a == "once");
    let serial = std::env::args().any(|a| a == "serial");
    let process0 = process_cpu_s();
    let (mut walls, mut cpus) = (Vec::new(), Vec::new());
    let mut last = None;
    let mut speculation = Default::default();
    for _ in 0..if once { 1 } else { 11 } {
        drop(last.take());
        let (w0, c0) = (Instant::now(), cpu_s());
        let mut generator = RoadGenerator::new(&params, &inputs)
            .unwrap()
            .with_speculation(!serial);
        let g = generator.run().unwrap();
        cpus.push(cpu_s() - c0);
        speculation = generator.speculation();
        walls.push(w0.elapsed().as_secs_f64());
        last = Some(g);
    }
    let runs = walls.len() as f64;
    let process = process_cpu_s() - process0;
    let g = last.unwrap();
    let seg = g.report.segments as f64;
    println!(
        "peer workload: {} segments, {} edges, {} steps",
        g.report.segments,
        g.network.edge_count(),
        g.report.steps
    );
    let row = |name: &str, wall: f64, cpu: f64, peer_ms: f64| {
        println!(
            "{name:<5} wall {:>7.1} ms ({:>6.0} k seg/s) CPU {:>7.1} ms ({:>6.0} k seg/s) | peer {:>6.1} ms ({:>4.0} k seg/s) | ×{:.2} wall, ×{:.2} CPU",
            wall * 1e3,
            seg / wall / 1e3,
            cpu * 1e3,
            seg / cpu / 1e3,
            peer_ms,
            PEER_SEGMENTS as f64 / peer_ms,
            peer_ms * 1e-3 / wall,
            peer_ms * 1e-3 / cpu,
        );
    };
    println!("speculative evaluation (last run): {speculation:?}");
    println!(
        "process CPU per run (all threads, mean of {runs} runs incl. set-up): {:.1} ms; thread CPU mean {:.1} ms",
        process / runs * 1e3,
        cpus.iter().sum::<f64>() / runs * 1e3
    );
    row("cold", walls[0], cpus[0], PEER_COLD_MS);
    if !once {
        row(
            "warm",
            median(walls[1..].to_vec()),
            median(cpus[1..].to_vec()),
            PEER_WARM_MS,
        );
    }
}
