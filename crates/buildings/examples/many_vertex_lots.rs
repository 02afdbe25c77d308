//! Times the building stage on lots with many vertices (issue 22): a regular n-gon lot
//! of radius 30 m for each building kind, and lots with near-duplicate vertices.
//!
//! ```text
//! cargo run --release -p polis-buildings --example many_vertex_lots -- [N ...]
//! ```
//!
//! Prints, for each kind, the build time of one lot and what happened (built, empty, or
//! the error).

use std::time::Instant;

use polis_buildings::{BuildingGenerator, BuildingKind, BuildingParams};
use polis_geom::{DVec2, Polygon};
use polis_lots::Lot;

/// A regular `n`-gon of radius `r` as a lot whose every edge faces a street.
fn regular_lot(n: usize, r: f64) -> Lot {
    let pts: Vec<DVec2> = (0..n)
        .map(|i| DVec2::from_angle(std::f64::consts::TAU * i as f64 / n as f64) * r)
        .collect();
    let polygon = Polygon::new(pts);
    Lot {
        area: polygon.area(),
        street_edges: (0..n).collect(),
        polygon,
        block_id: 0,
    }
}

/// A 20 m × 30 m lot with a second vertex `gap` metres after its first corner (a
/// near-duplicate vertex, as left by snapping or by a CAD export).
fn near_duplicate_lot(gap: f64) -> Lot {
    let polygon = Polygon::new(vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(gap, gap * 0.5),
        DVec2::new(20.0, 0.0),
        DVec2::new(20.0, 30.0),
        DVec2::new(0.0, 30.0),
    ]);
    Lot {
        area: polygon.area(),
        street_edges: vec![0, 1],
        polygon,
        block_id: 0,
    }
}

fn main() {
    let sizes: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![64, 1024, 4096, 30_000]
    } else {
        sizes
    };
    let generator = match BuildingGenerator::new(BuildingParams::default()) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let kinds = BuildingKind::ALL;
    println!("{:>9} {:<11} {:>10}  result", "vertices", "kind", "ms");
    let mut lots: Vec<(String, Lot)> = sizes
        .iter()
        .map(|&n| (n.to_string(), regular_lot(n, 30.0)))
        .collect();
    lots.push(("dup 1e-12".into(), near_duplicate_lot(1e-12)));
    for (n, lot) in &lots {
        let mut total = 0.0;
        for (k, &kind) in kinds.iter().enumerate() {
            let t = Instant::now();
            let r = generator.build(lot, k as u64, kind, 60.0, 6);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            total += ms;
            let what = match r {
                Ok(Some(b)) => format!("built, {} parts", b.parts.len()),
                Ok(None) => "empty".to_string(),
                Err(e) => format!("error: {e}"),
            };
            println!("{n:>9} {:<11} {ms:>10.2}  {what}", format!("{kind:?}"));
        }
        println!("{n:>9} {:<11} {total:>10.2}", "all six");
    }
}
