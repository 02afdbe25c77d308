//! Builds a small district by hand — a few extruded buildings on lots along two streets,
//! a river with a bridge, a park — and writes it with every polis-export writer:
//! `out/demo.glb`, `out/demo.obj` (+ `demo.mtl`, texture PNG), `out/demo.svg`,
//! `out/demo.geojson`.
//!
//! Run: `cargo run -p polis-export --example export_demo`.

use std::error::Error;
use std::fs::File;
use std::io::BufWriter;

use polis_export::footpaths::{FootpathOptions, footpath_mesh};
use polis_export::geojson::{GeoJsonOptions, write_geojson};
use polis_export::geom::field::FnField;
use polis_export::geom::glam::DVec3;
use polis_export::geom::mesh::{Facing, flat_polygon, prism};
use polis_export::geom::scene::{Image, ImageData, Material, Texture, Transform};
use polis_export::geom::{DVec2, Polygon, PolygonWithHoles, Scene};
use polis_export::glb::{Batching, GlbOptions, write_glb};
use polis_export::map::{
    BuildingKind, MapBlock, MapFootprint, MapLayers, MapLot, MapRoad, RoadClass,
};
use polis_export::obj::{ObjOptions, write_obj};
use polis_export::sink::DirSink;
use polis_export::surfaces::{RoadSurfaceOptions, road_surfaces_with_report};
use polis_export::svg::{SvgOptions, write_svg};

/// A 64 × 64 brick pattern: 1 texel = 1/64 m… scaled by the material's metre UVs, one
/// image tile covers 1 m × 1 m.
fn brick_texture() -> Image {
    let (w, h) = (64u32, 64u32);
    let mut pixels = Vec::with_capacity((4 * w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let row = y / 8;
            let shift = if row % 2 == 0 { 0 } else { 8 };
            let mortar = y % 8 == 0 || (x + shift) % 16 == 0;
            let (r, g, b) = if mortar {
                (200, 195, 185)
            } else {
                (150 + ((x * 7 + y * 3) % 20) as u8, 70, 50)
            };
            pixels.extend_from_slice(&[r, g, b, 255]);
        }
    }
    Image {
        name: "brick".into(),
        data: ImageData::Rgba8 {
            width: w,
            height: h,
            pixels,
        },
    }
}

struct Building {
    lot: Polygon,
    inset: f64,
    height: f64,
    kind: BuildingKind,
}

fn main() -> Result<(), Box<dyn Error>> {
    std::fs::create_dir_all("out")?;
    let mut map = MapLayers::default();
    let mut scene = Scene::new();

    // Materials.
    let brick_image = scene.add_image(brick_texture());
    let brick_tex = scene.add_texture(Texture {
        name: "brick".into(),
        image: brick_image,
        ..Texture::default()
    })?;
    let brick = scene.add_material(Material {
        base_color_texture: Some(brick_tex),
        ..Material::new("brick", [1.0, 1.0, 1.0, 1.0])
    });
    let concrete = scene.add_material(Material::new("concrete", [0.6, 0.6, 0.62, 1.0]));
    let glass = scene.add_material(Material {
        metallic: 0.6,
        roughness: 0.15,
        ..Material::new("glass", [0.35, 0.5, 0.65, 1.0])
    });
    let asphalt = scene.add_material(Material::new("asphalt", [0.2, 0.2, 0.22, 1.0]));
    let water_mat = scene.add_material(Material {
        roughness: 0.05,
        ..Material::new("water", [0.2, 0.4, 0.6, 0.8])
    });

    // Layout: two blocks south and north of an east–west street, a north–south street,
    // a river to the east crossed by a bridge.
    let city = scene.add_root("city");
    let river = Polygon::rect(DVec2::new(130.0, -60.0), DVec2::new(160.0, 80.0));
    map.water.push(river.clone().into());
    let river_node = scene.add_node(city, "river")?;
    let river_mesh = scene.add_mesh(flat_polygon(
        &river.into(),
        -0.5,
        Facing::Up,
        Some(water_mat),
    )?);
    scene.attach_mesh(river_node, river_mesh)?;

    let mut park = Polygon::regular(9, DVec2::new(90.0, 35.0), 18.0);
    park.make_ccw();
    map.parks.push(park.into());

    let roads = [
        (
            1,
            vec![
                DVec2::new(-70.0, 0.0),
                DVec2::new(50.0, 0.0),
                DVec2::new(125.0, 0.0),
            ],
            RoadClass::Major,
            12.0,
            false,
        ),
        (
            2,
            vec![DVec2::new(125.0, 0.0), DVec2::new(165.0, 0.0)],
            RoadClass::Major,
            12.0,
            true,
        ),
        (
            3,
            vec![
                DVec2::new(50.0, -60.0),
                DVec2::new(50.0, 0.0),
                DVec2::new(50.0, 62.0),
                DVec2::new(50.0, 70.0),
            ],
            RoadClass::Street,
            8.0,
            false,
        ),
        (
            4,
            vec![DVec2::new(-70.0, 62.0), DVec2::new(50.0, 62.0)],
            RoadClass::Footpath,
            2.5,
            false,
        ),
    ];
    let roads_node = scene.add_node(city, "roads")?;
    // A gentle slope rising to the north-west; the river valley does not touch the roads
    // except under the bridge, which spans it.
    let terrain = FnField::new(|p: DVec2| 0.02 * p.y - 0.01 * p.x);
    for (id, points, class, width_m, bridge) in roads {
        map.roads.push(MapRoad {
            id,
            points,
            class,
            width_m,
            bridge,
            tunnel: false,
            profile: None,
        });
    }
    // The roads meet where they share a point (the crossing at (50, 0), the T at
    // (50, 62)): one surface of ribbons, junction polygons and round dead-end caps.
    let (surface, report) = road_surfaces_with_report(
        &map.roads,
        &terrain,
        &RoadSurfaceOptions::default(),
        Some(asphalt),
    )?;
    println!("road surfaces: {} junctions and caps", report.junctions);
    let mesh = scene.add_mesh(surface);
    scene.attach_mesh(roads_node, mesh)?;
    scene.set_metadata(roads_node, "roads", map.roads.len() as f64)?;

    // Blocks and lots, each building a prism centred on its lot (mesh around a local
    // origin, placed by the node's translation).
    let blocks = [
        (
            10,
            Polygon::rect(DVec2::new(-60.0, 6.0), DVec2::new(44.0, 56.0)),
        ),
        (
            11,
            Polygon::rect(DVec2::new(-60.0, -56.0), DVec2::new(44.0, -6.0)),
        ),
    ];
    let mut lot_id = 100;
    let mut building_id = 1000;
    for (block_id, outline) in blocks {
        let block_node = scene.add_node(city, format!("block {block_id}"))?;
        scene.set_metadata(block_node, "block", block_id as f64)?;
        let (min, max) = (outline.bbox().min, outline.bbox().max);
        // A 2.5 m footpath along the block's edge, a kerb above the road.
        let mut inner = Polygon::rect(min + DVec2::splat(2.5), max - DVec2::splat(2.5));
        inner.make_cw();
        let strip = PolygonWithHoles::new(outline.clone(), vec![inner]);
        let path = footpath_mesh(
            &strip,
            &terrain,
            &FootpathOptions::default(),
            Some(concrete),
        )?;
        let path_node = scene.add_node(block_node, format!("footpath {block_id}"))?;
        let path_mesh = scene.add_mesh(path);
        scene.attach_mesh(path_node, path_mesh)?;
        map.blocks.push(MapBlock {
            id: block_id,
            polygon: outline.into(),
        });
        let lots = 4;
        let w = (max.x - min.x) / lots as f64;
        for k in 0..lots {
            let x0 = min.x + w * k as f64;
            let lot = Polygon::rect(DVec2::new(x0, min.y), DVec2::new(x0 + w, max.y));
            let b = Building {
                lot: lot.clone(),
                inset: 3.0 + k as f64,
                height: [9.0, 24.0, 12.0, 60.0][k],
                kind: [
                    BuildingKind::Residential,
                    BuildingKind::Commercial,
                    BuildingKind::Industrial,
                    BuildingKind::Skyscraper,
                ][k]
                    .clone(),
            };
            map.lots.push(MapLot {
                id: lot_id,
                block: Some(block_id),
                polygon: lot.into(),
            });
            let lb = b.lot.bbox();
            let fp = Polygon::rect(lb.min + b.inset, lb.max - b.inset);
            let centre = fp.centroid();
            let local: PolygonWithHoles = fp.translated(-centre).into();
            let material = match b.kind {
                BuildingKind::Residential => brick,
                BuildingKind::Skyscraper => glass,
                _ => concrete,
            };
            let mesh = scene.add_mesh(prism(&local, 0.0, b.height, Some(material))?);
            let node = scene.add_node(block_node, format!("building {building_id}"))?;
            scene.attach_mesh(node, mesh)?;
            scene.set_metadata(node, "kind", b.kind.as_str())?;
            scene.set_metadata(node, "height", b.height)?;
            scene.set_metadata(node, "floors", (b.height / 3.0).floor())?;
            scene.set_metadata(node, "lot", lot_id as f64)?;
            scene.node_mut(node)?.transform =
                Transform::from_translation(DVec3::new(centre.x, 0.0, -centre.y));
            map.footprints.push(MapFootprint {
                id: building_id,
                polygon: fp.into(),
                kind: b.kind,
                height_m: b.height,
                floors: Some((b.height / 3.0) as u32),
                lot: Some(lot_id),
            });
            lot_id += 1;
            building_id += 1;
        }
    }

    let per_node = write_glb(
        &scene,
        &GlbOptions::with_batching(Batching::PerNode),
        File::create("out/demo.glb")?,
    )?;
    let batched = write_glb(
        &scene,
        &GlbOptions::with_batching(Batching::PerParentAndMaterial),
        File::create("out/demo_batched.glb")?,
    )?;
    let obj = write_obj(
        &scene,
        &ObjOptions {
            stem: "demo".into(),
            ..ObjOptions::default()
        },
        File::create("out/demo.obj")?,
        &mut DirSink::new("out"),
    )?;
    write_svg(
        &map,
        &SvgOptions {
            pixels_per_metre: 4.0,
            ..SvgOptions::default()
        },
        BufWriter::new(File::create("out/demo.svg")?),
    )?;
    let gj = write_geojson(
        &map,
        &GeoJsonOptions::default(),
        File::create("out/demo.geojson")?,
    )?;
    println!(
        "out/demo.glb          {:>8} bytes, {} nodes, {} meshes, {} triangles",
        per_node.bytes, per_node.nodes, per_node.meshes, per_node.triangles
    );
    println!(
        "out/demo_batched.glb  {:>8} bytes, {} nodes, {} meshes, {} primitives",
        batched.bytes, batched.nodes, batched.meshes, batched.primitives
    );
    println!(
        "out/demo.obj          {:>8} bytes, {} groups, {} materials, {} textures",
        obj.bytes, obj.groups, obj.materials, obj.textures
    );
    println!("out/demo.svg, out/demo.geojson ({} features)", gj.features);
    Ok(())
}
