//! Building gallery: every building kind × several seeds side by side, plus one row of a
//! skyscraper's levels of detail 0–6, written to `out/building_gallery.obj` (hand-written
//! OBJ, one object per part, Y up, metres).
//!
//! Run: `cargo run -p polis --release --example building_gallery`

use std::fmt::Write as _;

use polis::buildings::geom::{DVec2, Polygon};
use polis::buildings::{Building, BuildingGenerator, BuildingKind, BuildingParams};
use polis::lots::Lot;

fn lot_at(origin: DVec2, shape: usize) -> Lot {
    let pts = match shape {
        0 => Polygon::rect(origin, origin + DVec2::new(30.0, 40.0)).into_points(),
        _ => [
            (0.0, 0.0),
            (40.0, 0.0),
            (40.0, 16.0),
            (20.0, 16.0),
            (20.0, 40.0),
            (0.0, 40.0),
        ]
        .iter()
        .map(|&(x, y)| origin + DVec2::new(x, y))
        .collect(),
    };
    let polygon = Polygon::new(pts);
    Lot {
        area: polygon.area(),
        polygon,
        street_edges: vec![0],
        block_id: 0,
    }
}

fn write_building(obj: &mut String, b: &Building, next_vertex: &mut usize) {
    for (i, part) in b.parts.iter().enumerate() {
        let _ = writeln!(
            obj,
            "o {}_{}_lod{}_part{}_{:?}",
            b.kind.name(),
            b.lot_id,
            b.lod,
            i,
            part.role
        );
        let o = DVec2::new(b.origin.x, -b.origin.y);
        for p in &part.mesh.positions {
            let _ = writeln!(
                obj,
                "v {} {} {}",
                f64::from(p.x) + o.x,
                p.y,
                f64::from(p.z) + o.y
            );
        }
        for uv in &part.mesh.uvs {
            let _ = writeln!(obj, "vt {} {}", uv.x, -uv.y);
        }
        for n in &part.mesh.normals {
            let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
        }
        for t in part.mesh.triangles() {
            let [a, b, c] = t.map(|k| k as usize + *next_vertex);
            let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        }
        *next_vertex += part.mesh.vertex_count();
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let g = BuildingGenerator::new(BuildingParams::default())?;
    let mut obj = String::from("# polis building gallery\n");
    let mut next = 1;
    println!(
        "{:<11} {:>5} {:>9} {:>9} {:>9} {:>9}",
        "kind", "built", "height", "parts", "triangles", "fallbacks"
    );
    for (row, kind) in BuildingKind::ALL.into_iter().enumerate() {
        let (mut n, mut h, mut parts, mut tris, mut fb) = (0, 0.0, 0, 0, 0);
        for col in 0..8u64 {
            let origin = DVec2::new(col as f64 * 60.0, row as f64 * 70.0);
            let l = lot_at(origin, (col % 2) as usize);
            let id = row as u64 * 1000 + col;
            if let Some(b) = g.build(&l, id, kind, 250.0, 6)? {
                n += 1;
                h += b.height;
                parts += b.parts.len();
                tris += b.triangle_count();
                fb += b.fallbacks;
                write_building(&mut obj, &b, &mut next);
            }
        }
        println!(
            "{:<11} {:>5} {:>8.1}m {:>9} {:>9} {:>9}",
            kind.name(),
            n,
            h / n.max(1) as f64,
            parts,
            tris,
            fb
        );
    }
    // Levels of detail of one skyscraper, left to right.
    let row = BuildingKind::ALL.len() as f64;
    for (k, b) in g
        .lods(&lot_at(DVec2::ZERO, 0), 4, BuildingKind::Skyscraper, 250.0)?
        .iter()
        .enumerate()
    {
        let mut moved = b.clone();
        moved.origin += DVec2::new(k as f64 * 60.0, row * 70.0);
        write_building(&mut obj, &moved, &mut next);
        println!(
            "skyscraper LOD {k}: {} parts, {} triangles",
            b.parts.len(),
            b.triangle_count()
        );
    }
    std::fs::create_dir_all("out")?;
    std::fs::write("out/building_gallery.obj", obj)?;
    println!("wrote out/building_gallery.obj");
    Ok(())
}
