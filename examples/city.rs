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
//! 5. **export** — an SVG map, GeoJSON layers, and a glb/OBJ of the blocks as kerb-high
//!    plinths.
//!
//! Buildings and facades are not generated yet (their stages are still being written);
//! the 3-D output holds only the blocks. Everything is deterministic for a seed.

use std::fs::File;
use std::io::BufWriter;
use std::path::PathBuf;
use std::time::Instant;

use polis::export::map::{MapBlock, MapLayers, MapLot, MapRoad, RoadClass as MapClass};
use polis::export::{geojson, glb, obj, sink::DirSink, svg};
use polis::geom::scene::Material;
use polis::geom::{PolygonWithHoles, Scene, mesh::prism};
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
    let mut lot_count = 0usize;
    for block in &all_blocks {
        let mut rng = Pcg64Mcg::seed_from_u64(args.seed ^ block.id());
        let sub = subdivide_block(block, &lot_params, &mut rng)?;
        for (i, lot) in sub.lots.into_iter().enumerate() {
            map.lots.push(MapLot {
                id: block.id().wrapping_mul(1 << 16).wrapping_add(i as u64),
                block: Some(block.id()),
                polygon: lot.polygon.into(),
            });
            lot_count += 1;
        }
        map.blocks.push(MapBlock {
            id: block.id(),
            polygon: block.polygon.clone(),
        });
        map.parks.extend(sub.green_spaces);
    }
    timings.push(("blocks + lots", t.elapsed().as_secs_f64()));

    // 5. Export.
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
    println!("  lots           {:>8}", lot_count);
    println!("  (buildings and facades: stages not landed yet)");
    for (stage, secs) in &timings {
        println!("  {stage:<14} {:>8.1} ms", secs * 1e3);
    }
    println!(
        "wrote {}/city.{{svg,geojson,glb,obj,mtl}}",
        args.out.display()
    );
    Ok(())
}
