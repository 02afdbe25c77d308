//! Building gallery: every building kind × eight seeds side by side on rectangular and
//! concave lots, a row of mansards on concave and splitting footprints, and one
//! skyscraper's levels of detail 0–6; written as glb and OBJ + MTL through polis-export
//! (`out/buildings_gallery.glb`, `out/buildings_gallery.obj`, `out/buildings_gallery.mtl`;
//! Y up, metres, one node per building with its kind, height, floors and LOD as metadata).
//!
//! Run: `cargo run -p polis-buildings --release --example gallery`

use std::fs::File;
use std::io::BufWriter;

use polis_buildings::geom::mesh::to_world;
use polis_buildings::geom::scene::{Material, MaterialId, NodeId, Scene, Transform};
use polis_buildings::geom::{DVec2, Polygon};
use polis_buildings::{
    Building, BuildingGenerator, BuildingGrammar, BuildingKind, BuildingParams, PartRole,
};
use polis_export::{glb, obj, sink::DirSink};
use polis_lots::Lot;

/// Lot shapes: a rectangle, an L, a T and a dumbbell (two squares and a corridor).
fn lot_at(origin: DVec2, shape: usize) -> Lot {
    let pts: &[(f64, f64)] = match shape % 4 {
        0 => &[(0.0, 0.0), (30.0, 0.0), (30.0, 40.0), (0.0, 40.0)],
        1 => &[
            (0.0, 0.0),
            (40.0, 0.0),
            (40.0, 16.0),
            (20.0, 16.0),
            (20.0, 40.0),
            (0.0, 40.0),
        ],
        2 => &[
            (12.0, 0.0),
            (28.0, 0.0),
            (28.0, 22.0),
            (40.0, 22.0),
            (40.0, 40.0),
            (0.0, 40.0),
            (0.0, 22.0),
            (12.0, 22.0),
        ],
        _ => &[
            (0.0, 0.0),
            (18.0, 0.0),
            (18.0, 7.0),
            (26.0, 7.0),
            (26.0, 0.0),
            (44.0, 0.0),
            (44.0, 22.0),
            (26.0, 22.0),
            (26.0, 15.0),
            (18.0, 15.0),
            (18.0, 22.0),
            (0.0, 22.0),
        ],
    };
    let polygon = Polygon::new(
        pts.iter()
            .map(|&(x, y)| origin + DVec2::new(x, y))
            .collect(),
    );
    Lot {
        area: polygon.area(),
        polygon,
        street_edges: vec![0],
        block_id: 0,
    }
}

struct Materials {
    wall: MaterialId,
    roof: MaterialId,
    detail: MaterialId,
}

fn add_building(
    scene: &mut Scene,
    root: NodeId,
    m: &Materials,
    b: &Building,
    name: String,
) -> Result<(), Box<dyn std::error::Error>> {
    let node = scene.add_node(root, name)?;
    scene.node_mut(node)?.transform = Transform::from_translation(to_world(b.origin, 0.0));
    scene.set_metadata(node, "kind", b.kind.name())?;
    scene.set_metadata(node, "height", b.height)?;
    scene.set_metadata(node, "floors", f64::from(b.floors))?;
    scene.set_metadata(node, "lod", b.lod as f64)?;
    for part in &b.parts {
        let mut mesh = part.mesh.clone();
        mesh.material = Some(match part.role {
            PartRole::Mass => m.wall,
            PartRole::Roof => m.roof,
            PartRole::Detail | PartRole::Template => m.detail,
        });
        let mesh = scene.add_mesh(mesh);
        scene.attach_mesh(node, mesh)?;
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let g = BuildingGenerator::new(BuildingParams::default())?;
    let mut scene = Scene::new();
    let m = Materials {
        wall: scene.add_material(Material::new("wall", [0.78, 0.74, 0.68, 1.0])),
        roof: scene.add_material(Material::new("roof", [0.45, 0.25, 0.2, 1.0])),
        detail: scene.add_material(Material::new("detail", [0.3, 0.3, 0.32, 1.0])),
    };
    let root = scene.add_root("gallery");
    println!(
        "{:<11} {:>5} {:>9} {:>6} {:>9} {:>9}",
        "row", "built", "height", "parts", "triangles", "fallbacks"
    );
    let row_stats = |name: &str, built: &[Building]| {
        let n = built.len();
        println!(
            "{:<11} {:>5} {:>8.1}m {:>6} {:>9} {:>9}",
            name,
            n,
            built.iter().map(|b| b.height).sum::<f64>() / n.max(1) as f64,
            built.iter().map(|b| b.parts.len()).sum::<usize>(),
            built.iter().map(Building::triangle_count).sum::<usize>(),
            built.iter().map(|b| b.fallbacks).sum::<u32>(),
        );
    };
    // Every kind × eight seeds, the lot shape cycling.
    for (row, kind) in BuildingKind::ALL.into_iter().enumerate() {
        let mut built = Vec::new();
        for col in 0..8u64 {
            let origin = DVec2::new(col as f64 * 60.0, row as f64 * 60.0);
            let l = lot_at(origin, col as usize);
            let id = row as u64 * 1000 + col;
            if let Some(b) = g.build(&l, id, kind, 250.0, 6)? {
                add_building(&mut scene, root, &m, &b, format!("{} {id}", kind.name()))?;
                built.push(b);
            }
        }
        row_stats(kind.name(), &built);
    }
    // Mansards on concave footprints: the steep part follows the skeleton, the inset
    // loses edges or splits (the dumbbell), and a shallow hip stands on every piece.
    let mut mansards = g.clone();
    mansards.set_grammar(
        BuildingKind::MidRise,
        BuildingGrammar::parse(
            "mansard",
            "p1: Lot(h, w, d, n) -> Extrude(h * 0.75) Box Up Extrude(h * 0.25) Mansard(3.5, 18)\n",
        )?,
    );
    let mut built = Vec::new();
    for col in 0..8u64 {
        let row = BuildingKind::ALL.len() as f64;
        let l = lot_at(DVec2::new(col as f64 * 60.0, row * 60.0), col as usize);
        if let Some(b) = mansards.build(&l, 9000 + col, BuildingKind::MidRise, 40.0, 6)? {
            add_building(&mut scene, root, &m, &b, format!("mansard {col}"))?;
            built.push(b);
        }
    }
    row_stats("mansard", &built);
    // Levels of detail of one skyscraper, left to right.
    let row = BuildingKind::ALL.len() as f64 + 1.0;
    for (k, b) in g
        .lods(&lot_at(DVec2::ZERO, 0), 4, BuildingKind::Skyscraper, 250.0)?
        .into_iter()
        .enumerate()
    {
        let mut moved = b;
        moved.origin += DVec2::new(k as f64 * 60.0, row * 60.0);
        println!(
            "skyscraper LOD {k}: {} parts, {} triangles",
            moved.parts.len(),
            moved.triangle_count()
        );
        add_building(&mut scene, root, &m, &moved, format!("skyscraper lod {k}"))?;
    }
    std::fs::create_dir_all("out")?;
    let report = glb::write_glb(
        &scene,
        &glb::GlbOptions::default(),
        BufWriter::new(File::create("out/buildings_gallery.glb")?),
    )?;
    println!(
        "wrote out/buildings_gallery.glb ({} nodes, {} triangles)",
        report.nodes, report.triangles
    );
    let report = obj::write_obj(
        &scene,
        &obj::ObjOptions {
            stem: "buildings_gallery".into(),
            ..obj::ObjOptions::default()
        },
        BufWriter::new(File::create("out/buildings_gallery.obj")?),
        &mut DirSink::new("out"),
    )?;
    println!(
        "wrote out/buildings_gallery.obj + .mtl ({} groups, {} triangles)",
        report.groups, report.triangles
    );
    Ok(())
}
