//! The main job: generate a city and write it out.
//!
//! ```text
//! cargo run --release --example city -- [--seed N] [--segments N] [--out DIR]
//! ```
//!
//! The one-call pipeline of the `polis` facade (`CityConfig`, `Pipeline`, `generate`) has
//! not landed yet, so this example chains the stage crates by hand, which is also what the
//! facade will do:
//!
//! 1. **roads** — Parish & Müller's extended L-system on the procedural default maps;
//! 2. **cells** — Eberly's minimal cycle basis of the road graph;
//! 3. **blocks** — each cell inset by half of each bounding road's width, with footpaths;
//! 4. **lots** — Kelly's subdivision with street access;
//! 5. **buildings** — one building per lot from the default building grammars; the kind
//!    and the height limit follow the population map (a simple zoning rule written
//!    here: towers where the population peaks, apartments and mid-rises around them,
//!    houses at the fringe);
//! 6. **export** — an SVG map, GeoJSON layers, and a glb/OBJ with the blocks as kerb-high
//!    plinths and every building's closed meshes.
//!
//! Facade textures are not applied yet (the facade stage exists, wiring it into the
//! scene is the pipeline's job). Everything is deterministic for a seed.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;
use std::time::Instant;

use polis::buildings::{BuildingGenerator, BuildingKind, BuildingParams, PartRole};
use polis::export::map::{
    BuildingKind as MapKind, MapBlock, MapFootprint, MapLayers, MapLot, MapRoad,
    RoadClass as MapClass,
};
use polis::export::{geojson, glb, obj, sink::DirSink, svg};
use polis::geom::scene::Material;
use polis::geom::{Field, PolygonWithHoles, Scene, Transform, mesh::prism, to_world};
use polis::lots::{BlockParams, Cell as LotCell, LotParams, blocks, subdivide_block};
use polis::roads::{RoadClass, RoadInputs, RoadParams, generate};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// Height of the block plinths (kerb height), metres.
const KERB_HEIGHT_M: f64 = 0.15;

struct Args {
    seed: u64,
    segments: Option<usize>,
    out: PathBuf,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        seed: RoadParams::default().seed,
        segments: None,
        out: PathBuf::from("out"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "--seed" => args.seed = value()?.parse().map_err(|e| format!("--seed: {e}"))?,
            "--segments" => {
                args.segments = Some(value()?.parse().map_err(|e| format!("--segments: {e}"))?)
            }
            "--out" => args.out = PathBuf::from(value()?),
            "-h" | "--help" => {
                return Err("usage: city [--seed N] [--segments N] [--out DIR]".into());
            }
            other => return Err(format!("unknown flag {other}; try --help")),
        }
    }
    Ok(args)
}

/// The example's zoning rule: building kind and height limit (metres) from the
/// population density in [0, 1].
fn zoning(density: f64) -> (BuildingKind, f64) {
    match density {
        d if d > 0.55 => (BuildingKind::Skyscraper, 180.0),
        d if d > 0.45 => (BuildingKind::Office, 90.0),
        d if d > 0.35 => (BuildingKind::MidRise, 40.0),
        d if d > 0.25 => (BuildingKind::Apartment, 25.0),
        d if d > 0.08 => (BuildingKind::House, 12.0),
        _ => (BuildingKind::Industrial, 15.0),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = parse_args()?;
    std::fs::create_dir_all(&args.out)?;
    let mut timings: Vec<(&str, f64)> = Vec::new();

    // 1. Roads.
    let t = Instant::now();
    let mut params = RoadParams {
        seed: args.seed,
        ..RoadParams::default()
    };
    if let Some(n) = args.segments {
        params.max_segments = n;
    }
    let inputs = RoadInputs::procedural(params.seed, &params)?;
    let roads = generate(&params, &inputs)?;
    let network = &roads.network;
    timings.push(("roads", t.elapsed().as_secs_f64()));

    // 2. Cells.
    let t = Instant::now();
    let cells = polis::cells::extract(network)?;
    timings.push(("cells", t.elapsed().as_secs_f64()));

    // 3–4. Blocks and lots, cell by cell (seeded per block, so order does not matter).
    let t = Instant::now();
    let block_params = BlockParams::default();
    let lot_params = LotParams::default();
    let mut map = MapLayers::default();
    let mut skipped_cells = 0usize;
    let mut all_blocks = Vec::new();
    for cell in &cells.cells {
        let holes: Vec<_> = cell.holes.iter().map(|h| h.polygon.clone()).collect();
        let mut widths = Vec::new();
        for ring in std::iter::once(&cell.boundary).chain(cell.holes.iter()) {
            for &e in &ring.edges {
                widths.push(network.edge_payload(e)?.width);
            }
        }
        let lot_cell = LotCell {
            id: cell.id.index() as u64,
            polygon: PolygonWithHoles::new(cell.boundary.polygon.clone(), holes),
            road_widths: widths,
        };
        // A cell whose islands touch its boundary at a node is not a simple polygon
        // with holes; such cells are skipped and counted.
        match blocks(&lot_cell, &block_params) {
            Ok(bs) => all_blocks.extend(bs),
            Err(_) => skipped_cells += 1,
        }
    }
    let mut lots = Vec::new();
    for block in &all_blocks {
        let mut rng = Pcg64Mcg::seed_from_u64(args.seed ^ block.id());
        let sub = subdivide_block(block, &lot_params, &mut rng)?;
        for (i, lot) in sub.lots.into_iter().enumerate() {
            let id = block.id().wrapping_mul(1 << 16).wrapping_add(i as u64);
            map.lots.push(MapLot {
                id,
                block: Some(block.id()),
                polygon: lot.polygon.clone().into(),
            });
            lots.push((id, lot));
        }
        map.blocks.push(MapBlock {
            id: block.id(),
            polygon: block.polygon.clone(),
        });
        map.parks.extend(sub.green_spaces);
    }
    timings.push(("blocks + lots", t.elapsed().as_secs_f64()));

    // 5. Buildings: kind and height limit from the population at the lot (a zoning rule
    // of this example; the pipeline will take zoning and height maps).
    let t = Instant::now();
    let generator = BuildingGenerator::new(BuildingParams::default())?;
    let lod = BuildingParams::default().max_lod;
    let mut buildings = Vec::new();
    let mut failed_lots = 0usize;
    for (id, lot) in &lots {
        let density = inputs.population.sample(lot.polygon.centroid());
        let (kind, max_height) = zoning(density);
        match generator.build(lot, *id, kind, max_height, lod) {
            Ok(Some(b)) => buildings.push(b),
            Ok(None) => {}
            // A degenerate lot is skipped and counted, not fatal.
            Err(_) => failed_lots += 1,
        }
    }
    timings.push(("buildings", t.elapsed().as_secs_f64()));

    // 6. Export.
    let t = Instant::now();
    for (e, _, _, road) in network.edges() {
        let (a, b) = network.segment(e)?;
        map.roads.push(MapRoad {
            id: u64::from(e.raw()),
            points: vec![a, b],
            class: match road.class {
                RoadClass::Highway => MapClass::Highway,
                RoadClass::Street => MapClass::Street,
            },
            width_m: road.width,
            bridge: road.bridge,
        });
    }
    let mut scene = Scene::new();
    let kerb = scene.add_material(Material::new("pavement", [0.55, 0.55, 0.52, 1.0]));
    let root = scene.add_root("city");
    for block in &all_blocks {
        let mesh = prism(&block.polygon, 0.0, KERB_HEIGHT_M, Some(kerb))?;
        let mesh = scene.add_mesh(mesh);
        let node = scene.add_node(root, format!("block {}", block.id()))?;
        scene.attach_mesh(node, mesh)?;
        scene.set_metadata(node, "cell", block.cell_id as f64)?;
    }
    let wall = scene.add_material(Material::new("wall", [0.78, 0.74, 0.68, 1.0]));
    let roof = scene.add_material(Material::new("roof", [0.45, 0.25, 0.2, 1.0]));
    let detail = scene.add_material(Material::new("detail", [0.3, 0.3, 0.32, 1.0]));
    let mut triangles = 0usize;
    for b in &buildings {
        let node = scene.add_node(root, format!("building {}", b.id))?;
        scene.node_mut(node)?.transform = Transform::from_translation(to_world(b.origin, 0.0));
        scene.set_metadata(node, "kind", format!("{:?}", b.kind))?;
        scene.set_metadata(node, "height", b.height)?;
        scene.set_metadata(node, "floors", f64::from(b.floors))?;
        scene.set_metadata(node, "lot", b.lot_id as f64)?;
        for part in &b.parts {
            let mut mesh = part.mesh.clone();
            mesh.material = Some(match part.role {
                PartRole::Mass => wall,
                PartRole::Roof => roof,
                PartRole::Detail | PartRole::Template => detail,
            });
            triangles += mesh.triangle_count();
            let mesh = scene.add_mesh(mesh);
            scene.attach_mesh(node, mesh)?;
        }
        map.footprints.push(MapFootprint {
            id: b.id,
            polygon: b.footprint.clone().into(),
            kind: match b.kind {
                BuildingKind::Skyscraper => MapKind::Skyscraper,
                BuildingKind::Office | BuildingKind::MidRise => MapKind::Commercial,
                BuildingKind::House | BuildingKind::Apartment => MapKind::Residential,
                BuildingKind::Industrial => MapKind::Industrial,
            },
            height_m: b.height,
            floors: Some(b.floors),
            lot: Some(b.lot_id),
        });
    }
    svg::write_svg(
        &map,
        &svg::SvgOptions::default(),
        BufWriter::new(File::create(args.out.join("city.svg"))?),
    )?;
    geojson::write_geojson(
        &map,
        &geojson::GeoJsonOptions::default(),
        BufWriter::new(File::create(args.out.join("city.geojson"))?),
    )?;
    glb::write_glb(
        &scene,
        &glb::GlbOptions::default(),
        BufWriter::new(File::create(args.out.join("city.glb"))?),
    )?;
    obj::write_obj(
        &scene,
        &obj::ObjOptions::default(),
        BufWriter::new(File::create(args.out.join("city.obj"))?),
        &mut DirSink::new(&args.out),
    )?;
    timings.push(("export", t.elapsed().as_secs_f64()));

    println!("polis city, seed {}", args.seed);
    println!("  road segments  {:>8}", network.edge_count());
    println!("  junctions      {:>8}", network.node_count());
    println!("  cells          {:>8}", cells.cells.len());
    println!("  cells skipped  {:>8}", skipped_cells);
    println!("  blocks         {:>8}", all_blocks.len());
    println!("  lots           {:>8}", lots.len());
    println!("  buildings      {:>8}", buildings.len());
    println!("  lots skipped   {:>8}", failed_lots);
    println!("  triangles      {:>8}", triangles);
    for (stage, secs) in &timings {
        println!("  {stage:<14} {:>8.1} ms", secs * 1e3);
    }
    println!(
        "wrote {}/city.{{svg,geojson,glb,obj,mtl}}",
        args.out.display()
    );
    Ok(())
}
