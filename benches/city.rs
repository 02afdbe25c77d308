//! The whole-city benchmarks of issue 10, printed as a table.
//!
//! ```text
//! cargo bench --bench city                # Citygen's test city (16 km²)
//! cargo bench --bench city -- lod1        # only its LOD 1 run
//! cargo bench --bench city -- metropolis  # the 1,000,000-building metropolis, streamed
//! cargo bench --bench city -- metropolis-kept  # the same kept whole in memory
//! cargo bench --bench city -- all
//! cargo bench --bench city_mimalloc [-- …] # the same with mimalloc, as the example
//! ```
//!
//! Each city is generated end to end — maps, roads, cells, blocks and lots, buildings,
//! facade tile textures and skins, and the assembled scene — by `polis::generate`; file
//! writing is timed separately. Wall-clock time is the best of the runs; CPU time (user +
//! system of the whole process during the run, from `/proc/self/stat`, Linux only) shows
//! what a loaded machine hides. Peak memory is the process's high-water mark (`VmHWM`).

use std::time::Instant;

use polis::{CityConfig, Pipeline, Stage};

#[path = "common/process.rs"]
mod process;
use process::{cpu_seconds, page_faults, peak_mib};

/// How a benchmark city is made.
#[derive(Clone, Copy, PartialEq)]
enum Mode {
    /// `Pipeline::generate`, with or without the scene: the city keeps every layer.
    Generate { scene: bool },
    /// `Pipeline::stream` in chunks of this many cells, each dropped after counting.
    Stream(usize),
}

fn run(label: &str, config: &CityConfig, runs: usize, mode: Mode) {
    let scene = mode == Mode::Generate { scene: true };
    // `POLIS_BENCH_RUNS=1` for profilers.
    let runs = std::env::var("POLIS_BENCH_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(runs);
    let mut best = f64::INFINITY;
    // The first run pays for the process's fresh memory, as a program's one call does.
    let mut first = None;
    let mut first_faults = None;
    let mut best_cpu = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs {
        let cpu0 = cpu_seconds();
        let faults0 = page_faults();
        let t = Instant::now();
        let pipeline = Pipeline::default();
        let made = match mode {
            Mode::Generate { scene } => pipeline.with_scene(scene).generate(config),
            // The sink only looks at each chunk; the chunk is dropped after it.
            Mode::Stream(cells) => pipeline.stream(config, cells, |chunk| {
                std::hint::black_box(&chunk);
                Ok(())
            }),
        };
        let city = match made {
            Ok(c) => c,
            Err(e) => {
                println!("{label}: error: {e}");
                return;
            }
        };
        let wall = t.elapsed().as_secs_f64();
        if let (Some(a), Some(b)) = (cpu0, cpu_seconds()) {
            best_cpu = best_cpu.min(b - a);
        }
        best = best.min(wall);
        first.get_or_insert(wall);
        if let (Some(a), Some(b)) = (faults0, page_faults()) {
            first_faults.get_or_insert(b - a);
        }
        last = Some(city);
    }
    let Some(city) = last else { return };
    let s = &city.stats;
    println!(
        "\n{label}: {:.1} km², lod {}",
        (config.size_m / 1000.0).powi(2),
        config.effective_lod()
    );
    println!(
        "  road segments {:>9}   buildings {:>9}   lots {:>9}",
        s.road_segments, s.buildings, s.lots
    );
    println!(
        "  triangles     {:>9}   facade tiles {:>6} ({:.1} MiB)",
        s.building_triangles,
        s.facade_tiles,
        s.texture_bytes as f64 / 1048576.0
    );
    print!("  stages (last run):");
    for stage in Stage::ALL {
        print!(
            " {} {:.0} ms,",
            stage.name(),
            s.time(stage).as_secs_f64() * 1e3
        );
    }
    println!();
    let cpu = if best_cpu.is_finite() {
        format!("{best_cpu:.2} s")
    } else {
        "n/a".into()
    };
    println!(
        "  generate: best wall {best:.2} s, best CPU {cpu} over {runs} runs (first run {:.2} s)",
        first.unwrap_or(best)
    );
    if let Some(peak) = peak_mib() {
        println!("  peak memory after generating: {peak:.0} MiB");
    }
    if let Some(f) = first_faults {
        println!(
            "  first run: {f} page faults ({:.0} MiB of fresh pages)",
            f as f64 * 4096.0 / 1048576.0
        );
    }
    // `POLIS_BENCH_GLB=0` leaves the glb out (for profiling the generation alone).
    if scene && std::env::var("POLIS_BENCH_GLB").map_or(true, |v| v != "0") {
        let t = Instant::now();
        let mut glb = Vec::new();
        match city.write_glb(&mut glb) {
            Ok(_) => println!(
                "  glb: {:.1} MiB in {:.2} s",
                glb.len() as f64 / 1048576.0,
                t.elapsed().as_secs_f64()
            ),
            Err(e) => println!("  glb: error: {e}"),
        }
    }
    if let Some(peak) = peak_mib() {
        println!("  peak memory (process high-water mark): {peak:.0} MiB");
    }
}

/// Runs the benchmarks named on the command line.
pub fn main() {
    let which: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let want = |name: &str| {
        which.is_empty() && name == "citygen" || which.iter().any(|w| w == name || w == "all")
    };
    let Ok(citygen) = CityConfig::preset("citygen") else {
        println!("the citygen preset does not parse");
        return;
    };
    if want("citygen") {
        run(
            "Citygen test city, full detail",
            &citygen,
            3,
            Mode::Generate { scene: true },
        );
    }
    if want("citygen") || want("lod1") {
        let lod1 = CityConfig {
            lod: Some(1),
            ..citygen.clone()
        };
        run(
            "Citygen test city, LOD 1 (extruded masses)",
            &lod1,
            3,
            Mode::Generate { scene: true },
        );
    }
    if want("metropolis") || want("metropolis-kept") {
        // The citygen density on a 17.5 km square: about a million buildings.
        let mut m = CityConfig {
            name: "metropolis".into(),
            size_m: 17_500.0,
            lod: Some(1),
            ..citygen.clone()
        };
        m.roads.max_segments = 300_000;
        m.roads.max_steps = 20_000;
        if want("metropolis") {
            // Streamed in chunks of 1,024 cells: only the roads, the cells and one
            // chunk are in memory at a time.
            run("metropolis (streamed)", &m, 1, Mode::Stream(1024));
        } else {
            // Kept whole, without the scene (a second copy of every mesh).
            run(
                "metropolis (kept in memory, no scene)",
                &m,
                1,
                Mode::Generate { scene: false },
            );
        }
    }
}
