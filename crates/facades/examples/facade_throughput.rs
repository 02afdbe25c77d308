//! Rasterisation and geometry-mode throughput measured in *CPU time* of the calling thread
//! (from `/proc/thread-self/schedstat` on Linux), so the figures stay meaningful on a
//! machine shared with other jobs; wall-clock figures are printed alongside.
//!
//! ```text
//! cargo run --release -p polis-facades --example facade_throughput [style]
//! ```

use std::time::Instant;

use polis_facades::builtin::builtin_styles;
use polis_facades::{FacadeSpec, PreparedStyle, RasterOptions};

/// Nanoseconds this thread has spent on a CPU, if the kernel tells us.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Runs `f` until `min_cpu_s` of CPU time are spent: (items, CPU s, wall s, best items
/// per CPU second of a single call — the least disturbed by other jobs).
fn measure(mut f: impl FnMut() -> usize, min_cpu_s: f64) -> (usize, f64, f64, f64) {
    let mut items = 0usize;
    let wall = Instant::now();
    let cpu0 = thread_cpu_ns();
    let mut best = 0.0f64;
    let mut last = cpu0;
    loop {
        let n = f();
        items += n;
        let now = thread_cpu_ns();
        if let (Some(a), Some(b)) = (last, now)
            && b > a
        {
            best = best.max(n as f64 / ((b - a) as f64 * 1e-9));
        }
        last = now;
        let cpu = match (cpu0, now) {
            (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
            _ => wall.elapsed().as_secs_f64(),
        };
        if cpu >= min_cpu_s {
            return (items, cpu, wall.elapsed().as_secs_f64(), best);
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let only = std::env::args().nth(1);
    let opts = RasterOptions::default();
    println!(
        "{:<22} {:>16} {:>16} {:>16} {:>14} {:>14}",
        "style",
        "Mtexel/s (CPU)",
        "best call (CPU)",
        "Mtexel/s (wall)",
        "Mcell/s (CPU)",
        "Mcell/s (wall)"
    );
    for style in builtin_styles() {
        let name = style.name.clone();
        if only.as_ref().is_some_and(|o| *o != name) {
            continue;
        }
        let p = PreparedStyle::new(style)?;
        let f = p.facade(&FacadeSpec::new(20.0, 15.0, 7))?;
        let (texels, cpu, wall, best) = measure(
            || {
                f.rasterize(&opts)
                    .map(|t| t.width as usize * t.height as usize)
                    .unwrap_or(0)
            },
            2.0,
        );
        let tower = p.facade(&FacadeSpec::new(40.0, 60.0, 7))?;
        let mut buf = Vec::new();
        let (cells, ccpu, cwall, _) = measure(
            || {
                tower.cells_into(&mut buf);
                buf.len()
            },
            1.0,
        );
        println!(
            "{:<22} {:>16.1} {:>16.1} {:>16.1} {:>14.2} {:>14.2}",
            name,
            texels as f64 / cpu * 1e-6,
            best * 1e-6,
            texels as f64 / wall * 1e-6,
            cells as f64 / ccpu * 1e-6,
            cells as f64 / cwall * 1e-6
        );
    }
    Ok(())
}
