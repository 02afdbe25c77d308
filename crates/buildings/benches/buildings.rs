//! Buildings on 57,000 lots (the size of Citygen's city, Kelly 2008 §6.5): boxes at LOD 0
//! and 1, and full grammar buildings with roofs (LOD 6), mixed kinds.
//!
//! Run: `cargo bench -p polis-buildings` — divan reports buildings/s; the table printed
//! after it gives buildings/s and triangles/s of one timed pass each.

use std::time::Instant;

use rayon::prelude::*;

use polis_buildings::{BuildingGenerator, BuildingKind, BuildingParams};
use polis_geom::{DVec2, Polygon};
use polis_lots::Lot;

const LOTS: usize = 57_000;

/// A city-like mix: rectangles of varied size and rotation, trapezoids and L-shapes.
fn lots() -> Vec<(Lot, BuildingKind)> {
    (0..LOTS)
        .map(|i| {
            let (gx, gy) = ((i % 240) as f64, (i / 240) as f64);
            let o = DVec2::new(gx * 50.0, gy * 50.0);
            let w = 14.0 + (i * 7 % 13) as f64;
            let d = 22.0 + (i * 5 % 17) as f64;
            let pts: Vec<DVec2> = match i % 4 {
                0 | 1 => {
                    let a = (i % 9) as f64 * 0.1;
                    let (x, y) = (DVec2::from_angle(a), DVec2::from_angle(a).perp());
                    vec![o, o + x * w, o + x * w + y * d, o + y * d]
                }
                2 => vec![
                    o,
                    o + DVec2::new(w, 0.0),
                    o + DVec2::new(w * 0.8, d),
                    o + DVec2::new(w * 0.1, d * 0.9),
                ],
                _ => vec![
                    o,
                    o + DVec2::new(w, 0.0),
                    o + DVec2::new(w, d * 0.4),
                    o + DVec2::new(w * 0.5, d * 0.4),
                    o + DVec2::new(w * 0.5, d),
                    o + DVec2::new(0.0, d),
                ],
            };
            let polygon = Polygon::new(pts);
            let kind = BuildingKind::ALL[(i * 31 + i / 240) % 6];
            (
                Lot {
                    area: polygon.area(),
                    polygon,
                    street_edges: vec![0],
                    block_id: 0,
                },
                kind,
            )
        })
        .collect()
}

/// Builds every lot at `lod`; returns (buildings, triangles).
fn run(g: &BuildingGenerator, lots: &[(Lot, BuildingKind)], lod: usize) -> (usize, usize) {
    let (mut n, mut t) = (0, 0);
    for (i, (lot, kind)) in lots.iter().enumerate() {
        if let Ok(Some(b)) = g.build(lot, i as u64, *kind, 300.0, lod) {
            n += 1;
            t += b.triangle_count();
        }
    }
    (n, t)
}

fn main() {
    divan::main();
    let g = BuildingGenerator::new(BuildingParams::default()).unwrap_or_else(|e| panic!("{e}"));
    let lots = lots();
    println!(
        "\n{:<24} {:>9} {:>12} {:>14} {:>16}",
        "pass (57,000 lots)", "built", "seconds", "buildings/s", "triangles/s"
    );
    let start = Instant::now();
    let planned = lots
        .iter()
        .enumerate()
        .filter(|(i, (l, k))| matches!(g.plan(l, *i as u64, *k, 300.0), Ok(Some(_))))
        .count();
    let s = start.elapsed().as_secs_f64();
    println!(
        "{:<24} {planned:>9} {s:>12.3} {:>14.0} {:>16}",
        "plan only",
        planned as f64 / s,
        "-"
    );
    for (name, lod) in [
        ("LOD 0 (bounding box)", 0),
        ("LOD 1", 1),
        ("full grammar (LOD 6)", 6),
    ] {
        let start = Instant::now();
        let (n, t) = run(&g, &lots, lod);
        let s = start.elapsed().as_secs_f64();
        println!(
            "{name:<24} {n:>9} {s:>12.3} {:>14.0} {:>16.0}",
            n as f64 / s,
            t as f64 / s
        );
    }
    // The same passes on every core (rayon; buildings are independent and deterministic
    // per lot, so the output is the same).
    let threads = rayon::current_num_threads();
    for (name, lod) in [
        ("LOD 0, parallel", 0),
        ("LOD 1, parallel", 1),
        ("LOD 6, parallel", 6),
    ] {
        let start = Instant::now();
        let (n, t) = lots
            .par_iter()
            .enumerate()
            .map(
                |(i, (lot, kind))| match g.build(lot, i as u64, *kind, 300.0, lod) {
                    Ok(Some(b)) => (1, b.triangle_count()),
                    _ => (0, 0),
                },
            )
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        let s = start.elapsed().as_secs_f64();
        let name = format!("{name} ({threads} thr)");
        println!(
            "{name:<24} {n:>9} {s:>12.3} {:>14.0} {:>16.0}",
            n as f64 / s,
            t as f64 / s
        );
    }
}

#[divan::bench(args = [0, 1, 6], sample_count = 3, sample_size = 1)]
fn buildings_57k(bencher: divan::Bencher<'_, '_>, lod: usize) {
    let g = BuildingGenerator::new(BuildingParams::default()).unwrap_or_else(|e| panic!("{e}"));
    let lots = lots();
    bencher
        .counter(divan::counter::ItemsCount::new(LOTS))
        .bench(|| run(&g, &lots, lod));
}
