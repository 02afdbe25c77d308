//! Realism of the presets: generates each preset for several seeds, computes the
//! statistics report, and prints one Markdown table per preset (metric, polis mean and
//! range over the seeds, the real city's value, band, seeds in band), then the time of
//! generation and of the report.
//!
//! ```text
//! cargo run --release --example city_report -- [--preset NAME]... [--seeds FIRST-LAST]
//!     [--size METRES] [--no-report]
//! ```
//!
//! Without `--preset` every preset is measured; `--seeds` defaults to 1-5 and `--size`
//! to each preset's own size. `--no-report` only generates (to time the report by
//! difference). Flags are parsed by clap (`--help` lists them).

use std::time::Instant;

use clap::Parser;
use polis::stats::{CityReport, RealismRow};
use polis::{CityConfig, generate};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[allow(dead_code)]
#[path = "common/cli.rs"]
mod cli;

/// The statistics report of each preset against its real city, over several seeds.
#[derive(Debug, Parser)]
#[command(name = "city_report")]
struct Args {
    /// A preset to measure (repeat for several; default: every preset).
    #[arg(long = "preset", value_name = "NAME", value_parser = cli::preset_names())]
    presets: Vec<String>,
    /// The seeds: N or FIRST-LAST.
    #[arg(long, value_name = "FIRST-LAST", default_value = "1-5", value_parser = cli::seeds)]
    seeds: cli::Seeds,
    /// The city's size, metres (default: each preset's own).
    #[arg(long, value_name = "METRES", value_parser = cli::metres)]
    size: Option<f64>,
    /// Only generate (to time the report by difference).
    #[arg(long)]
    no_report: bool,
}

/// A metric beyond the realism rows: name and how to read it from a report.
type Extra = (&'static str, fn(&CityReport) -> f64);

const EXTRAS: [Extra; 12] = [
    ("P_3way", |r| r.streets.share_3way),
    ("P_5plus", |r| r.streets.share_5plus),
    ("intersections / km² land", |r| {
        r.streets.intersection_density_per_km2
    }),
    ("block area median (m²)", |r| r.blocks.area_m2.median),
    ("block Φ median", |r| r.blocks.shape_factor.median),
    ("lot area median (m²)", |r| r.lots.area_m2.median),
    ("lot frontage median (m)", |r| r.lots.frontage_m.median),
    ("building coverage of lots", |r| r.buildings.coverage),
    ("building height median (m)", |r| {
        r.buildings.height_m.median
    }),
    ("road length in blocks w/o lots (m)", |r| {
        r.defects.length_inside_blocks_without_lots_m
    }),
    ("stubs in land w/o lots", |r| {
        r.defects.stubs_in_land_without_lots as f64
    }),
    ("buildings in road corridor", |r| {
        r.defects.buildings_in_road_corridor as f64
    }),
];

fn mean_range(v: &[f64]) -> (f64, f64, f64) {
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (mean, lo, hi)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = Args::parse();
    if args.presets.is_empty() {
        args.presets = CityConfig::preset_names().map(String::from).collect();
    }
    for name in &args.presets {
        let mut reports = Vec::new();
        let (mut gen_ms, mut rep_ms) = (Vec::new(), Vec::new());
        let mut config = CityConfig::preset(name)?;
        if let Some(s) = args.size {
            config.size_m = s;
        }
        for seed in args.seeds.iter() {
            config.seed = seed;
            let t = Instant::now();
            let city = generate(&config)?;
            gen_ms.push(t.elapsed().as_secs_f64() * 1e3);
            if !args.no_report {
                let t = Instant::now();
                reports.push(city.statistics()?);
                rep_ms.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        println!(
            "\n### {name} ({:.1} km, seeds {}–{}) against {}\n",
            config.size_m / 1000.0,
            args.seeds.first,
            args.seeds.last,
            config.imitates.as_deref().unwrap_or("—")
        );
        println!(
            "generation median {:.0} ms; report median {:.1} ms ({:.1} %)\n",
            median(gen_ms.clone()),
            median(rep_ms.clone()),
            100.0 * median(rep_ms) / median(gen_ms).max(1e-9)
        );
        if reports.is_empty() {
            continue;
        }
        println!("| metric | polis mean | polis range | real | band | seeds in band |");
        println!("|---|---|---|---|---|---|");
        let rows: Vec<Vec<&RealismRow>> = reports
            .iter()
            .filter_map(|r| r.realism.as_ref().map(|x| x.rows.iter().collect()))
            .collect();
        if let Some(first) = rows.first() {
            for (k, row) in first.iter().enumerate() {
                let v: Vec<f64> = rows.iter().map(|r| r[k].polis).collect();
                let (m, lo, hi) = mean_range(&v);
                let inside = rows.iter().filter(|r| r[k].in_band == Some(true)).count();
                let verdict = match row.in_band {
                    None => "—".to_string(),
                    Some(_) => format!("{inside}/{}", rows.len()),
                };
                println!(
                    "| {} | {m:.3} | {lo:.3}–{hi:.3} | {} | {} | {verdict} |",
                    row.metric,
                    row.real.map_or("—".into(), |x| format!("{x:.3}")),
                    row.band.map_or("—".into(), |b| b.to_string()),
                );
            }
        }
        for (label, get) in EXTRAS {
            let v: Vec<f64> = reports.iter().map(get).collect();
            let (m, lo, hi) = mean_range(&v);
            println!("| {label} | {m:.3} | {lo:.3}–{hi:.3} | — | — | — |");
        }
    }
    Ok(())
}
