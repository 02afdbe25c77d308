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
//! difference).

use std::time::Instant;

use polis::stats::{CityReport, RealismRow};
use polis::{CityConfig, generate};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

struct Args {
    presets: Vec<String>,
    seeds: (u64, u64),
    size: Option<f64>,
    report: bool,
}

fn parse_args() -> Result<Args, Box<dyn std::error::Error>> {
    let mut args = Args {
        presets: Vec::new(),
        seeds: (1, 5),
        size: None,
        report: true,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--preset" => args.presets.push(value()?),
            "--seeds" => {
                let v = value()?;
                let (a, b) = v.split_once('-').unwrap_or((&v, &v));
                args.seeds = (a.parse()?, b.parse()?);
            }
            "--size" => args.size = Some(value()?.parse()?),
            "--no-report" => args.report = false,
            other => return Err(format!("unknown flag {other}").into()),
        }
    }
    if args.presets.is_empty() {
        args.presets = CityConfig::preset_names().map(String::from).collect();
    }
    Ok(args)
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
    let args = parse_args()?;
    for name in &args.presets {
        let mut reports = Vec::new();
        let (mut gen_ms, mut rep_ms) = (Vec::new(), Vec::new());
        let mut config = CityConfig::preset(name)?;
        if let Some(s) = args.size {
            config.size_m = s;
        }
        for seed in args.seeds.0..=args.seeds.1 {
            config.seed = seed;
            let t = Instant::now();
            let city = generate(&config)?;
            gen_ms.push(t.elapsed().as_secs_f64() * 1e3);
            if args.report {
                let t = Instant::now();
                reports.push(city.statistics()?);
                rep_ms.push(t.elapsed().as_secs_f64() * 1e3);
            }
        }
        println!(
            "\n### {name} ({:.1} km, seeds {}–{}) against {}\n",
            config.size_m / 1000.0,
            args.seeds.0,
            args.seeds.1,
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
