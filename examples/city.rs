//! The main job: generate a city and write it out.
//!
//! ```text
//! cargo run --release --example city -- [--preset NAME | --config FILE] [--seed N]
//!     [--size METRES] [--lod N] [--segments N] [--threads N] [--out DIR]
//!     [--population PNG] [--water PNG] [--parks PNG] [--elevation PNG METRES]
//!     [--zoning PNG] [--max-height PNG METRES]
//! ```
//!
//! With no arguments it builds the `default` preset and writes `out/city.glb`,
//! `out/city.obj` (+ `city.mtl` and the facade textures), `out/city.svg` and
//! `out/city.geojson`, then prints counts and per-stage timings. A grey-scale PNG map
//! covers the whole city square (top row = north edge); its values in [0, 1] are used as
//! they are, except elevation and maximum height, which are scaled to the given metres
//! and zoning, which is scaled to the six building kinds (0 skyscraper … 5 industrial).
//!
//! The example uses mimalloc as its global allocator: the pipeline allocates millions of
//! small meshes and polygons from several threads, and mimalloc generates cities 10–20 %
//! faster than the system allocator (BENCHMARKS.md, "Whole city"). Applications that
//! embed polis can do the same.

use std::io::Write;
use std::path::PathBuf;
use std::sync::Mutex;
use std::time::Instant;

use polis::geom::Aabb2;
use polis::geom::field::FieldSpec;
use polis::{CityConfig, MapSpec, Pipeline, Stage};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

const USAGE: &str = "usage: city [--preset NAME | --config FILE] [--seed N] [--size METRES] \
    [--lod N] [--segments N] [--threads N] [--out DIR] [--population PNG] [--water PNG] \
    [--parks PNG] [--elevation PNG METRES] [--zoning PNG] [--max-height PNG METRES]";

struct Args {
    config: CityConfig,
    out: PathBuf,
}

fn parse_args() -> Result<Args, Box<dyn std::error::Error>> {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    // The base configuration first, so the other flags override it.
    let mut config = CityConfig::preset("default")?;
    let mut i = 0;
    while i < raw.len() {
        match raw[i].as_str() {
            "--preset" | "--config" if i + 1 >= raw.len() => {
                return Err(format!("{} needs a value", raw[i]).into());
            }
            "--preset" => config = CityConfig::preset(&raw[i + 1])?,
            "--config" => config = CityConfig::from_path(&raw[i + 1])?,
            "-h" | "--help" => return Err(USAGE.into()),
            _ => {}
        }
        i += 1;
    }
    let mut out = PathBuf::from("out");
    let mut maps: Vec<(String, PathBuf, f64)> = Vec::new();
    let mut it = raw.iter();
    while let Some(flag) = it.next() {
        let mut value = || {
            it.next()
                .cloned()
                .ok_or_else(|| format!("{flag} needs a value; {USAGE}"))
        };
        let num = |v: String| -> Result<f64, String> {
            v.parse::<f64>().map_err(|e| format!("{flag}: {e}"))
        };
        match flag.as_str() {
            "--preset" | "--config" => {
                value()?;
            }
            "--seed" => config.seed = value()?.parse().map_err(|e| format!("--seed: {e}"))?,
            "--size" => config.size_m = num(value()?)?,
            "--lod" => config.lod = Some(value()?.parse().map_err(|e| format!("--lod: {e}"))?),
            "--segments" => {
                config.roads.max_segments =
                    value()?.parse().map_err(|e| format!("--segments: {e}"))?
            }
            "--threads" => {
                config.threads = Some(value()?.parse().map_err(|e| format!("--threads: {e}"))?)
            }
            "--out" => out = PathBuf::from(value()?),
            "--population" | "--water" | "--parks" | "--zoning" => {
                maps.push((flag.clone(), PathBuf::from(value()?), 1.0))
            }
            "--elevation" | "--max-height" => {
                let path = PathBuf::from(value()?);
                let scale = num(value()?)?;
                maps.push((flag.clone(), path, scale));
            }
            other => return Err(format!("unknown flag {other}; {USAGE}").into()),
        }
    }
    let h = config.size_m * 0.5;
    let extent = Aabb2::new(
        polis::geom::DVec2::new(-h, -h),
        polis::geom::DVec2::new(h, h),
    );
    for (flag, path, scale) in maps {
        let png = MapSpec::png(path, extent);
        let scaled = |factor: f64| match &png {
            MapSpec::Field(f) => MapSpec::Field(FieldSpec::Scaled {
                field: Box::new(f.clone()),
                factor,
            }),
            other => other.clone(),
        };
        match flag.as_str() {
            "--population" => config.maps.population = png,
            "--water" => config.maps.water = Some(png),
            "--parks" => config.maps.parks = Some(png),
            "--zoning" => config.maps.zoning = Some(scaled(5.0)),
            "--elevation" => config.maps.elevation = Some(scaled(scale)),
            "--max-height" => config.maps.max_height = Some(scaled(scale)),
            _ => {}
        }
    }
    config.validate()?;
    Ok(Args { config, out })
}

/// A one-line progress bar on standard error.
fn progress_bar() -> impl Fn(Stage, f64) + Send + Sync + 'static {
    let last = Mutex::new((None::<Stage>, -1i64));
    move |stage, done| {
        let Ok(mut last) = last.lock() else { return };
        let pct = (done * 100.0).round() as i64;
        if last.0 == Some(stage) && last.1 == pct {
            return;
        }
        *last = (Some(stage), pct);
        let filled = (done * 30.0).round().clamp(0.0, 30.0) as usize;
        let mut err = std::io::stderr().lock();
        let _ = write!(
            err,
            "\r{:<10} [{}{}] {:>3} %",
            stage.name(),
            "#".repeat(filled),
            ".".repeat(30 - filled),
            pct
        );
        if done >= 1.0 {
            let _ = writeln!(err);
        }
        let _ = err.flush();
    }
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = parse_args()?;
    let c = &args.config;
    println!(
        "polis: {} city, seed {}, {:.1} km × {:.1} km",
        c.name,
        c.seed,
        c.size_m / 1000.0,
        c.size_m / 1000.0
    );
    let city = Pipeline::default()
        .with_progress(progress_bar())
        .generate(c)?;
    let t = Instant::now();
    let written = city.write_all(&args.out)?;
    let write_time = t.elapsed();

    let s = &city.stats;
    println!("  road segments   {:>9}", s.road_segments);
    println!("  junctions       {:>9}", s.junctions);
    println!("  cells           {:>9}", s.cells);
    println!("  blocks          {:>9}", s.blocks);
    println!("  lots            {:>9}", s.lots);
    println!("  buildings       {:>9}", s.buildings);
    println!("  dressed         {:>9}", s.dressed_buildings);
    println!("  facade tiles    {:>9}", s.facade_tiles);
    println!(
        "  texture memory  {:>7.1} MiB",
        s.texture_bytes as f64 / 1048576.0
    );
    println!("  triangles       {:>9}", s.scene_triangles);
    println!("  skipped         {:>9}", city.report.skipped.len());
    for w in &city.report.warnings {
        println!("warning: {w}");
    }
    for stage in Stage::ALL {
        println!(
            "  {:<15} {:>7.1} ms",
            stage.name(),
            s.time(stage).as_secs_f64() * 1e3
        );
    }
    println!(
        "  {:<15} {:>7.1} ms",
        "generate (wall)",
        s.total_time().as_secs_f64() * 1e3
    );
    println!(
        "  {:<15} {:>7.1} ms",
        "write files",
        write_time.as_secs_f64() * 1e3
    );
    for f in &written.files {
        println!("wrote {}", f.display());
    }
    Ok(())
}
