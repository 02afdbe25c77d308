//! The street network of each preset against its real city, fast: only the maps and the
//! road stage run (no blocks, lots or buildings), then polis-stats' street metrics and
//! realism bands. One line per preset and seed, the verdict of each banded metric
//! (`*` = out of band), and a summary of seeds in band per metric.
//!
//! ```text
//! cargo run --release --example street_bands -- [--preset NAME]... [--seeds FIRST-LAST]
//!     [--size METRES] [--config FILE]...
//! ```
//!
//! `--config` reads a configuration file instead of a preset. Without either: every preset
//! that names a reference city, in either road mode (Parish & Müller, or Citygen's
//! secondary growth per cell). `--seeds` defaults to 1-5, `--size` to each preset's own
//! size. Flags are parsed by clap (`--help` lists them).

use clap::Parser;
use polis::CityConfig;

#[allow(dead_code)]
#[path = "common/cli.rs"]
mod cli;

/// The street network of each preset against its real city (maps and roads only).
#[derive(Debug, Parser)]
#[command(name = "street_bands")]
struct Args {
    /// A preset to measure (repeat for several). Without `--preset` or `--config`:
    /// every preset that names a reference city.
    #[arg(long = "preset", value_name = "NAME", value_parser = cli::preset_names())]
    presets: Vec<String>,
    /// A configuration file to measure instead of a preset (repeatable).
    #[arg(long = "config", value_name = "FILE")]
    files: Vec<String>,
    /// The seeds: N or FIRST-LAST.
    #[arg(long, value_name = "FIRST-LAST", default_value = "1-5", value_parser = cli::seeds)]
    seeds: cli::Seeds,
    /// The city's size, metres (default: each preset's own).
    #[arg(long, value_name = "METRES", value_parser = cli::metres)]
    size: Option<f64>,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = Args::parse();
    let explicit = !(args.presets.is_empty() && args.files.is_empty());
    let mut configs = Vec::new();
    for name in &args.presets {
        configs.push((name.clone(), CityConfig::preset(name)?));
    }
    for file in &args.files {
        configs.push((file.clone(), CityConfig::from_path(file)?));
    }
    if !explicit {
        for name in CityConfig::preset_names() {
            configs.push((name.to_string(), CityConfig::preset(name)?));
        }
    }
    for (name, mut config) in configs {
        let Some(city) = config.imitates.clone() else {
            continue;
        };
        if let Some(s) = args.size {
            config.size_m = s;
        }
        println!("## {name} ({} m) against {city}", config.size_m);
        let mut tally: Vec<(String, usize, usize)> = Vec::new();
        for seed in args.seeds.iter() {
            config.seed = seed;
            let report = polis::road_statistics(&config)?;
            let mut line = format!("seed {seed}:");
            if let Some(r) = &report.realism {
                for row in &r.rows {
                    let Some(ok) = row.in_band else { continue };
                    let real = row.real.unwrap_or(f64::NAN);
                    line += &format!(
                        " {}={:.3}{}({:.3})",
                        row.metric,
                        row.polis,
                        if ok { "" } else { "*" },
                        real
                    );
                    match tally.iter_mut().find(|t| t.0 == row.metric) {
                        Some(t) => {
                            t.1 += usize::from(ok);
                            t.2 += 1;
                        }
                        None => tally.push((row.metric.clone(), usize::from(ok), 1)),
                    }
                }
            }
            line += &format!(
                " P3={:.3} P5+={:.3} simplified_edges={}",
                report.streets.share_3way, report.streets.share_5plus, report.streets.streets
            );
            println!("{line}");
        }
        let summary: Vec<String> = tally
            .iter()
            .map(|(m, ok, n)| format!("{m} {ok}/{n}"))
            .collect();
        println!("in band: {}\n", summary.join(", "));
    }
    Ok(())
}
