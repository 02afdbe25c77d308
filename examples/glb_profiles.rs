//! The glb's layouts and profiles side by side: file size, draw calls and write time.
//!
//! ```text
//! cargo run --release --example glb_profiles -- [PRESET ...] [--runs N] [--only LAYOUT:PROFILE]
//! ```
//!
//! Generates each preset (default: `default` and `citygen`) once, then writes its glb
//! `--runs` times (default 5) per layout (`tiled`, the default; `cell`, the layout before
//! tiles; `building`) and profile (`plain`, `web`) into a sink that keeps nothing (the
//! writer's own cost: no output buffer growing, no disk), and prints, per row, the bytes,
//! the draw calls (primitives drawn by nodes, every LOD level counted), the materials and
//! tiles, the feature records, shared geometries and the median write time in
//! milliseconds, wall and CPU (user + system of all threads, from `/proc/self/stat` in
//! 10 ms ticks; `-` where it cannot be read). The last lines check the targets of issue 26: tiled draw calls ≤ 4 ×
//! materials × tiles; the web profile ≤ 25 % of the per-cell plain bytes; the tiled plain
//! write no slower than the per-cell plain write. `--only tiled:plain` writes that one
//! row, once unless `--runs` says otherwise (for whole-process timings of one
//! configuration). `--save DIR` also writes each row's file to
//! `DIR/<preset>-<layout>-<profile>.glb`. Flags are parsed by clap (`--help` lists them).

use std::time::Instant;

#[path = "../benches/common/process.rs"]
mod process;

use clap::Parser;
use polis::CityConfig;
use polis::export::glb::{Batching, GlbOptions, GlbProfile, write_glb};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[allow(dead_code)]
#[path = "common/cli.rs"]
mod cli;

const LAYOUTS: [(&str, Batching); 3] = [
    ("tiled", Batching::Tiled),
    ("cell", Batching::PerParentAndMaterial),
    ("building", Batching::PerNode),
];

/// The glb's layouts and profiles side by side: file size, draw calls and write time.
#[derive(Debug, Parser)]
#[command(name = "glb_profiles")]
struct Args {
    /// The presets to generate (default: `default` and `citygen`).
    #[arg(value_name = "PRESET", value_parser = cli::preset_names())]
    presets: Vec<String>,
    /// Writes per row (default 5; 1 with `--only`).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    runs: Option<u32>,
    /// Write only this row: LAYOUT:PROFILE, LAYOUT one of tiled, cell, building and
    /// PROFILE one of plain, web.
    #[arg(long, value_name = "LAYOUT:PROFILE", value_parser = row)]
    only: Option<(String, String)>,
    /// Also write each row's file to DIR/<preset>-<layout>-<profile>.glb.
    #[arg(long, value_name = "DIR")]
    save: Option<std::path::PathBuf>,
}

/// `LAYOUT:PROFILE`, both known.
fn row(text: &str) -> Result<(String, String), String> {
    let (l, p) = text
        .split_once(':')
        .ok_or("give LAYOUT:PROFILE, e.g. tiled:plain")?;
    if !LAYOUTS.iter().any(|(name, _)| *name == l) {
        return Err(format!("layout {l:?}: give tiled, cell or building"));
    }
    if !["plain", "web"].contains(&p) {
        return Err(format!("profile {p:?}: give plain or web"));
    }
    Ok((l.to_string(), p.to_string()))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args {
        mut presets,
        runs,
        only,
        save,
    } = Args::parse();
    if presets.is_empty() {
        presets = vec!["default".into(), "citygen".into()];
    }
    let runs = runs.unwrap_or(if only.is_some() { 1 } else { 5 }) as usize;
    for name in &presets {
        let config = CityConfig::preset(name)?;
        let city = polis::generate(&config)?;
        println!(
            "{name}: {} buildings, {} triangles, {} scene materials",
            city.stats.buildings,
            city.scene.triangle_count(),
            city.scene.materials.len()
        );
        println!(
            "{:<9} {:<6} {:>12} {:>8} {:>5} {:>6} {:>8} {:>7} {:>9} {:>7}",
            "layout",
            "profile",
            "bytes",
            "draws",
            "mats",
            "tiles",
            "features",
            "shared",
            "write ms",
            "cpu ms"
        );
        let mut rows = Vec::new();
        for (lname, batching) in LAYOUTS {
            for profile in [GlbProfile::Plain, GlbProfile::Web] {
                if let Some((l, p)) = &only
                    && (l != lname || *p != profile.to_string())
                {
                    continue;
                }
                let options = GlbOptions {
                    batching,
                    tile_size_m: config.scene.tile_size_m,
                    profile,
                    ..GlbOptions::default()
                };
                let mut times = Vec::with_capacity(runs);
                let mut cpu = Vec::with_capacity(runs);
                let mut report = None;
                for _ in 0..runs {
                    let c = process::cpu_seconds();
                    let t = Instant::now();
                    let r = write_glb(&city.scene, &options, std::io::sink())?;
                    times.push(t.elapsed().as_secs_f64() * 1e3);
                    if let (Some(a), Some(b)) = (c, process::cpu_seconds()) {
                        cpu.push((b - a) * 1e3);
                    }
                    report = Some(r);
                }
                if let Some(dir) = &save {
                    let mut out = Vec::new();
                    write_glb(&city.scene, &options, &mut out)?;
                    std::fs::write(dir.join(format!("{name}-{lname}-{profile}.glb")), out)?;
                }
                times.sort_by(f64::total_cmp);
                let ms = times[times.len() / 2];
                cpu.sort_by(f64::total_cmp);
                let cpu_ms = cpu
                    .get(cpu.len() / 2)
                    .map_or("-".to_string(), |c| format!("{c:.0}"));
                let Some(r) = report else { continue };
                println!(
                    "{:<9} {:<6} {:>12} {:>8} {:>5} {:>6} {:>8} {:>7} {:>9.1} {:>7}",
                    lname,
                    profile.to_string(),
                    r.bytes,
                    r.draw_calls,
                    r.materials,
                    r.tiles,
                    r.features,
                    r.shared_geometries,
                    ms,
                    cpu_ms
                );
                rows.push((lname, profile, r, ms, cpu.get(cpu.len() / 2).copied()));
            }
        }
        let find = |l: &str, p: GlbProfile| rows.iter().find(|r| r.0 == l && r.1 == p);
        if let (Some(tiled), Some(cell), Some(web)) = (
            find("tiled", GlbProfile::Plain),
            find("cell", GlbProfile::Plain),
            find("tiled", GlbProfile::Web),
        ) {
            let bound = 4 * tiled.2.materials * tiled.2.tiles;
            println!(
                "  draw calls {} ≤ 4 × {} materials × {} tiles = {bound}: {}",
                tiled.2.draw_calls,
                tiled.2.materials,
                tiled.2.tiles,
                tiled.2.draw_calls <= bound
            );
            println!(
                "  web {} bytes = {:.1} % of the per-cell plain {} bytes",
                web.2.bytes,
                100.0 * web.2.bytes as f64 / cell.2.bytes as f64,
                cell.2.bytes
            );
            println!(
                "  tiled plain write {:.1} ms vs per-cell {:.1} ms ({:+.0} %)",
                tiled.3,
                cell.3,
                100.0 * (tiled.3 / cell.3 - 1.0)
            );
            if let (Some(t), Some(c)) = (tiled.4, cell.4) {
                println!(
                    "  tiled plain write CPU {t:.0} ms vs per-cell {c:.0} ms ({:+.0} %)",
                    100.0 * (t / c - 1.0)
                );
            }
        }
    }
    Ok(())
}
