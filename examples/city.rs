//! The main job: generate a city and write it out.
//!
//! ```text
//! cargo run --release --example city -- [--preset NAME | --config FILE] [--seed N]
//!     [--size METRES] [--lod N] [--segments N] [--threads N] [--out DIR]
//!     [--population PNG] [--water PNG] [--parks PNG] [--elevation PNG METRES]
//!     [--zoning PNG] [--max-height PNG METRES] [--report]
//!     [--formats glb,obj,svg,geojson] [--anchor LON,LAT] [--glb-profile plain|web]
//!     [--debug-layers plot,fans,blocks,lots,splits]
//! cargo run --release --example city -- --help
//! ```
//!
//! With no arguments it builds the `default` preset and writes `out/city.glb`,
//! `out/city.obj` (+ `city.mtl` and the facade textures in `out/textures/`),
//! `out/city.svg` and `out/city.geojson`, then prints counts, per-stage timings, the wall
//! time of generating and of writing (and on Linux the process's CPU time of each) and
//! every file written. `--formats` picks the outputs; `--anchor LON,LAT` writes the GeoJSON in
//! WGS 84 longitude/latitude around that point (local metres otherwise). A grey-scale PNG map
//! covers the whole city square (top row = north edge); its values in [0, 1] are used as
//! they are, except elevation and maximum height, which are scaled to the given metres
//! and zoning, which is scaled to the six building kinds (0 skyscraper … 5 industrial).
//! `--report` prints the city's statistics report (street network, blocks, lots,
//! buildings, plan defects, realism against the city it imitates) and writes it to
//! `report.json` in the output folder.
//!
//! Flags are parsed by `clap`: `--help` lists them, `--seed=7` and `--seed 7` are the
//! same, a mistyped flag gets a suggestion, and out-of-range values (a `--lod` above the
//! configuration's `buildings.max_lod`, a zero `--threads`) are errors, never clamped.
//! The progress bar (indicatif) is drawn only when both standard output and standard
//! error are terminals, so logs stay free of carriage returns.
//!
//! The example uses mimalloc as its global allocator: the pipeline allocates millions of
//! small meshes and polygons from several threads, and mimalloc generates cities 10–20 %
//! faster than the system allocator (BENCHMARKS.md, "Whole city"). Applications that
//! embed polis can do the same.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::Instant;

#[path = "../benches/common/process.rs"]
mod process;

#[allow(dead_code)]
#[path = "common/cli.rs"]
mod cli;

use clap::error::ErrorKind;
use clap::{CommandFactory, Parser};
use indicatif::{ProgressBar, ProgressStyle};
use polis::geom::Aabb2;
use polis::geom::field::FieldSpec;
use polis::{CityConfig, Formats, MapSpec, Pipeline, Stage, WriteOptions};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Generate a procedural city and write it as glb, OBJ + MTL, SVG and GeoJSON.
#[derive(Debug, Parser)]
#[command(name = "city", version)]
struct Cli {
    /// Start from a built-in preset (the other flags override it). Default: default.
    #[arg(long, value_name = "NAME", value_parser = cli::preset_names(), conflicts_with = "config")]
    preset: Option<String>,
    /// Start from a JSON configuration file (the other flags override it).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// The city seed: same seed and configuration, same bytes.
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Side of the square map in metres (10 to 1,000,000).
    #[arg(long, value_name = "METRES", value_parser = cli::metres)]
    size: Option<f64>,
    /// Level of detail of the buildings, 0 to the configuration's `buildings.max_lod`.
    #[arg(long, value_name = "N")]
    lod: Option<usize>,
    /// Maximum number of road segments the road growth may place.
    #[arg(long, value_name = "N")]
    segments: Option<usize>,
    /// Worker threads (at least 1). Default: all cores.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
    /// Folder for the output files (created if missing).
    #[arg(long, value_name = "DIR", default_value = "out")]
    out: PathBuf,
    /// Population density map: grey-scale PNG over the whole city square.
    #[arg(long, value_name = "PNG")]
    population: Option<PathBuf>,
    /// Water map (white = water): grey-scale PNG.
    #[arg(long, value_name = "PNG")]
    water: Option<PathBuf>,
    /// Parks map (white = park): grey-scale PNG.
    #[arg(long, value_name = "PNG")]
    parks: Option<PathBuf>,
    /// Zoning map: grey-scale PNG, 0 skyscraper … 1 industrial (six kinds).
    #[arg(long, value_name = "PNG")]
    zoning: Option<PathBuf>,
    /// Terrain: grey-scale PNG, white = METRES above black.
    #[arg(long, num_args = 2, value_names = ["PNG", "METRES"])]
    elevation: Option<Vec<String>>,
    /// Maximum building height: grey-scale PNG, white = METRES.
    #[arg(long, num_args = 2, value_names = ["PNG", "METRES"])]
    max_height: Option<Vec<String>>,
    /// Print the city statistics report and write `report.json` beside the outputs.
    #[arg(long)]
    report: bool,
    /// Leave the ground (the terrain mesh textured by land use) out of the glb and OBJ.
    #[arg(long)]
    no_terrain: bool,
    /// Output formats to write, comma-separated: glb, obj, svg, geojson (or all).
    #[arg(long, value_name = "LIST", default_value = "all")]
    formats: Formats,
    /// Where the layout origin is on Earth (degrees): the GeoJSON is then written in WGS 84
    /// longitude/latitude (RFC 7946) instead of local metres.
    #[arg(long, value_name = "LON,LAT", allow_hyphen_values = true, value_parser = lon_lat)]
    anchor: Option<[f64; 2]>,
    /// The glb's profile: plain (core glTF 2.0, every engine) or web (quantized and
    /// meshopt-compressed, for three.js and glTFast).
    #[arg(long, value_name = "PROFILE", default_value = "plain")]
    glb_profile: polis::export::glb::GlbProfile,
    /// Debug overlays in the SVG, comma-separated: plot, fans (the primary roads' plot
    /// samples and fans, Citygen mode), blocks, lots (boundaries), splits (the lot
    /// subdivision's split lines in order), or all.
    #[arg(long, value_name = "LIST", default_value = "none")]
    debug_layers: polis::export::svg::SvgDebug,
}

/// `LON,LAT` in degrees, inside WGS 84 bounds.
fn lon_lat(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{e}; give LON,LAT in degrees"))?;
    match parts[..] {
        [lon, lat] if (-180.0..=180.0).contains(&lon) && lat > -90.0 && lat < 90.0 => {
            Ok([lon, lat])
        }
        [_, _] => Err("give a longitude in [-180, 180] and a latitude in (-90, 90)".into()),
        _ => Err("give two numbers, LON,LAT".into()),
    }
}

struct Args {
    config: CityConfig,
    out: PathBuf,
    report: bool,
    write: WriteOptions,
}

/// Builds the configuration from the parsed flags; a bad combination or value becomes a
/// clap error (printed with the usage line, exit status 2).
fn configure(cli: Cli) -> Result<Args, clap::Error> {
    let mut cmd = Cli::command();
    let fail = |cmd: &mut clap::Command, kind, msg: String| cmd.error(kind, msg);
    // The base configuration first, so the other flags override it.
    let mut config = match (&cli.preset, &cli.config) {
        (_, Some(path)) => CityConfig::from_path(path)
            .map_err(|e| fail(&mut cmd, ErrorKind::Io, format!("--config: {e}")))?,
        (name, None) => CityConfig::preset(name.as_deref().unwrap_or("default"))
            .map_err(|e| fail(&mut cmd, ErrorKind::InvalidValue, format!("--preset: {e}")))?,
    };
    if let Some(seed) = cli.seed {
        config.seed = seed;
    }
    if let Some(size) = cli.size {
        config.size_m = size;
    }
    if let Some(lod) = cli.lod {
        let max = config.buildings.max_lod;
        if lod > max {
            return Err(fail(
                &mut cmd,
                ErrorKind::ValueValidation,
                format!(
                    "--lod {lod} is above this configuration's most detailed level \
                     ({max}); give 0..={max}, or raise buildings.max_lod in --config"
                ),
            ));
        }
        config.lod = Some(lod);
    }
    if let Some(n) = cli.segments {
        config.roads.max_segments = n;
    }
    if let Some(n) = cli.threads {
        config.threads = Some(usize::from(n));
    }
    if cli.no_terrain {
        config.scene.terrain = false;
    }
    let h = config.size_m * 0.5;
    let extent = Aabb2::new(
        polis::geom::DVec2::new(-h, -h),
        polis::geom::DVec2::new(h, h),
    );
    let scaled = |path: &PathBuf, factor: f64| match MapSpec::png(path.clone(), extent) {
        MapSpec::Field(f) => MapSpec::Field(FieldSpec::Scaled {
            field: Box::new(f),
            factor,
        }),
        other => other,
    };
    let pair = |cmd: &mut clap::Command, flag: &str, v: &[String]| match v {
        [path, m] => cli::metres(m)
            .map(|m| (PathBuf::from(path), m))
            .map_err(|e| fail(cmd, ErrorKind::ValueValidation, format!("{flag}: {e}"))),
        _ => Err(fail(
            cmd,
            ErrorKind::WrongNumberOfValues,
            format!("{flag} takes PNG METRES"),
        )),
    };
    if let Some(p) = &cli.population {
        config.maps.population = MapSpec::png(p.clone(), extent);
    }
    if let Some(p) = &cli.water {
        config.maps.water = Some(MapSpec::png(p.clone(), extent));
    }
    if let Some(p) = &cli.parks {
        config.maps.parks = Some(MapSpec::png(p.clone(), extent));
    }
    if let Some(p) = &cli.zoning {
        config.maps.zoning = Some(scaled(p, 5.0));
    }
    if let Some(v) = &cli.elevation {
        let (p, m) = pair(&mut cmd, "--elevation", v)?;
        config.maps.elevation = Some(scaled(&p, m));
    }
    if let Some(v) = &cli.max_height {
        let (p, m) = pair(&mut cmd, "--max-height", v)?;
        config.maps.max_height = Some(scaled(&p, m));
    }
    config
        .validate()
        .map_err(|e| fail(&mut cmd, ErrorKind::ValueValidation, e.to_string()))?;
    Ok(Args {
        config,
        out: cli.out,
        report: cli.report,
        write: WriteOptions {
            formats: cli.formats,
            anchor_lon_lat: cli.anchor,
            glb_profile: cli.glb_profile,
            svg_debug: cli.debug_layers,
        },
    })
}

/// The progress display: one indicatif bar per stage on standard error, or nothing when
/// standard output or standard error is not a terminal.
#[derive(Clone, Default)]
struct Progress {
    current: Arc<Mutex<Option<(Stage, ProgressBar)>>>,
}

impl Progress {
    fn callback(&self) -> Option<impl Fn(Stage, f64) + Send + Sync + 'static> {
        if !(std::io::stdout().is_terminal() && std::io::stderr().is_terminal()) {
            return None;
        }
        let current = Arc::clone(&self.current);
        let style = ProgressStyle::with_template("{msg:<10} [{bar:30}] {percent:>3} %")
            .ok()?
            .progress_chars("#>.");
        Some(move |stage: Stage, done: f64| {
            let Ok(mut current) = current.lock() else {
                return;
            };
            if current.as_ref().map(|(s, _)| *s) != Some(stage) {
                if let Some((_, bar)) = current.take() {
                    bar.finish();
                }
                let bar = ProgressBar::new(1000).with_style(style.clone());
                bar.set_message(stage.name());
                *current = Some((stage, bar));
            }
            if let Some((_, bar)) = current.as_ref() {
                bar.set_position((done.clamp(0.0, 1.0) * 1000.0).round() as u64);
                if done >= 1.0 {
                    bar.finish();
                }
            }
        })
    }

    /// Ends the last bar: kept when the run succeeded, cleared on an error so the message
    /// starts on its own line.
    fn end(&self, ok: bool) {
        if let Ok(mut current) = self.current.lock()
            && let Some((_, bar)) = current.take()
        {
            if ok {
                bar.finish();
            } else {
                bar.finish_and_clear();
            }
        }
    }
}

fn main() {
    let args = match configure(Cli::parse()) {
        Ok(args) => args,
        Err(e) => e.exit(),
    };
    let progress = Progress::default();
    let result = run(&args, &progress);
    progress.end(result.is_ok());
    if let Err(e) = result {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args, progress: &Progress) -> Result<(), Box<dyn std::error::Error>> {
    let c = &args.config;
    println!(
        "polis: {} city, seed {}, {:.1} km × {:.1} km",
        c.name,
        c.seed,
        c.size_m / 1000.0,
        c.size_m / 1000.0
    );
    let mut pipeline = Pipeline::default();
    if let Some(callback) = progress.callback() {
        pipeline = pipeline.with_progress(callback);
    }
    let city = pipeline.generate(c)?;
    progress.end(true);
    // The process's CPU (user + system, all threads) at the end of the generation and
    // of the writing (Linux; nothing printed elsewhere): beside the wall times below,
    // what a machine shared with other jobs leaves of each phase.
    let cpu_generated = process::cpu_seconds();
    let t = Instant::now();
    let written = city.write_all_with(&args.out, &args.write)?;
    let write_time = t.elapsed();
    let cpu_written = process::cpu_seconds();

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
    if let (Some(generated), Some(written)) = (cpu_generated, cpu_written) {
        println!("  {:<15} {:>7.0} ms", "generate (CPU)", generated * 1e3);
        println!(
            "  {:<15} {:>7.0} ms",
            "write (CPU)",
            (written - generated) * 1e3
        );
    }
    for f in &written.files {
        println!("wrote {}", f.display());
    }
    if args.report {
        let t = Instant::now();
        let report = city.statistics()?;
        let report_time = t.elapsed();
        print!("{report}");
        println!(
            "  {:<15} {:>7.1} ms",
            "report",
            report_time.as_secs_f64() * 1e3
        );
        let path = args.out.join("report.json");
        std::fs::write(&path, serde_json::to_string_pretty(&report)?)?;
        println!("wrote {}", path.display());
    }
    // The process ends here and its memory goes back to the system whole: the city is
    // not dropped piece by piece (millions of frees, many on another thread than the
    // one that allocated: about a tenth of a LOD 1 run's CPU).
    std::mem::forget(city);
    Ok(())
}
