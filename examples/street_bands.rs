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
//! size.

use polis::CityConfig;

struct Args {
    presets: Vec<String>,
    files: Vec<String>,
    seeds: (u64, u64),
    size: Option<f64>,
}

fn parse_args() -> Result<Args, Box<dyn std::error::Error>> {
    let mut args = Args {
        presets: Vec::new(),
        files: Vec::new(),
        seeds: (1, 5),
        size: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{flag} needs a value"));
        match flag.as_str() {
            "--preset" => args.presets.push(value()?),
            "--config" => args.files.push(value()?),
            "--seeds" => {
                let v = value()?;
                let (a, b) = v.split_once('-').unwrap_or((&v, &v));
                args.seeds = (a.parse()?, b.parse()?);
            }
            "--size" => args.size = Some(value()?.parse()?),
            other => return Err(format!("unknown flag {other}").into()),
        }
    }
    Ok(args)
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = parse_args()?;
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
        for seed in args.seeds.0..=args.seeds.1 {
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
