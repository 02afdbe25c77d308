//! Facade gallery: every built-in style at several facade sizes, written as PNGs.
//!
//! ```text
//! cargo run -p polis --example facade_gallery
//! ```
//!
//! Writes `out/facades/<style>_<size>_{albedo,normal,mr}.png` (a narrow house, a wide
//! office floor, a tower), the shared tile set of each style, a JSON dump of each style,
//! and prints the cells of geometry mode and the texture memory of tile sets versus
//! per-facade textures.

use std::fs;
use std::path::Path;

use polis::facades::builtin::builtin_styles;
use polis::facades::{CellRole, FacadeSpec, FaceRole, PreparedStyle, RasterOptions, TileSet};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = Path::new("out/facades");
    fs::create_dir_all(dir)?;
    let opts = RasterOptions {
        pixels_per_metre: 32.0,
        ..RasterOptions::default()
    };
    let sizes = [
        ("narrow_house", 6.5, 9.0, Some(2)),
        ("wide_office_floor", 36.0, 8.5, Some(2)),
        ("tower", 24.0, 60.0, None),
    ];
    println!(
        "{:<22} {:<18} {:>9} {:>7} {:>7} {:>7} {:>6}",
        "style", "size", "texels", "windows", "doors", "cells", "floors"
    );
    for style in builtin_styles() {
        let name = style.name.clone();
        fs::write(dir.join(format!("{name}.json")), style.to_json()?)?;
        let prepared = PreparedStyle::new(style)?;
        for (label, w, h, floors) in sizes {
            let spec = FacadeSpec {
                floors,
                role: FaceRole::Street,
                ..FacadeSpec::new(w, h, 2026)
            };
            let facade = prepared.facade(&spec)?;
            let tex = facade.rasterize(&opts)?;
            let stem = format!("{name}_{label}");
            fs::write(dir.join(format!("{stem}_albedo.png")), tex.albedo_png()?)?;
            fs::write(dir.join(format!("{stem}_normal.png")), tex.normal_png()?)?;
            fs::write(
                dir.join(format!("{stem}_mr.png")),
                tex.metallic_roughness_png()?,
            )?;
            let cells = facade.cells();
            let count = |r: CellRole| cells.iter().filter(|c| c.role == r).count();
            println!(
                "{:<22} {:<18} {:>9} {:>7} {:>7} {:>7} {:>6}",
                name,
                format!("{label} {w}×{h} m"),
                tex.width as usize * tex.height as usize,
                count(CellRole::Window) + count(CellRole::Shopfront) + count(CellRole::Glass),
                count(CellRole::Door),
                cells.len(),
                facade.report().floors
            );
            for (layer, why) in &facade.report().skipped_layers {
                println!("    (layer `{layer}` left out: {why})");
            }
        }
        // The shared tile set, and the quads that would texture a 57,000-building city.
        let tiles = TileSet::build(&prepared, &opts)?;
        for (k, t) in tiles.tiles.iter().enumerate() {
            let kind = if t.entrance {
                "entrance".to_string()
            } else {
                format!("{:?}x{:?}", t.cols, t.rows).to_lowercase()
            };
            fs::write(
                dir.join(format!("{name}_tile{k}_{kind}.png")),
                t.textures.albedo_png()?,
            )?;
        }
        let f = prepared.facade(&FacadeSpec::new(23.0, 17.0, 1))?;
        let full = f.rasterize(&opts)?;
        println!(
            "    tile set: {} tiles, {:.1} MiB for every facade of the style; one 23×17 m facade as a full texture: {:.1} MiB; its {} tile quads",
            tiles.tiles.len(),
            tiles.gpu_bytes() as f64 / 1048576.0,
            full.gpu_bytes() as f64 / 1048576.0,
            f.tile_quads(&tiles).len()
        );
    }
    println!("PNGs written to {}", dir.display());
    Ok(())
}
