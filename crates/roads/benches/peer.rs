//! Road growth on the JavaScript peer's workload (phiresky/procedural-cities, `PEERS.md`;
//! the mapping of its settings is in `common/peer.rs`): 15,000 segments, timed like the
//! peer — the first run in this fresh process ("cold") and runs 2–11 ("warm") — by wall
//! time and by this thread's CPU time, printed as segments per second beside the peer's
//! figures.
//!
//! Run: `cargo bench -p polis-roads --bench peer` (`-- once` grows one network and exits:
//! for profilers and fresh-process timings).

#![allow(clippy::unwrap_used)]

use std::time::Instant;

use polis_roads::generate;

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

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn main() {
    let (params, inputs) = peer_params(PEER_SEGMENTS);
    let once = std::env::args().any(|a| a == "once");
    let (mut walls, mut cpus) = (Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..if once { 1 } else { 11 } {
        drop(last.take());
        let (w0, c0) = (Instant::now(), cpu_s());
        let g = generate(&params, &inputs).unwrap();
        cpus.push(cpu_s() - c0);
        walls.push(w0.elapsed().as_secs_f64());
        last = Some(g);
    }
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
