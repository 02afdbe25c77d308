//! Integration tests of the one-call pipeline: every preset on a small city.

#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic on failure

use std::collections::HashMap;

use polis::geom::{DVec2, PointLocation, Polygon, PolygonWithHoles, SegmentIntersection};
use polis::stages::{CellInput, CellLots, LotStage, StageContext};
use polis::{City, CityConfig, Pipeline, Stage};

/// A preset shrunk to a small city that still has every layer.
fn small(name: &str) -> CityConfig {
    let mut c = CityConfig::preset(name).unwrap();
    c.size_m = c.size_m.min(1600.0);
    c.roads.max_segments = 260;
    c.facades.pixels_per_metre = 6.0;
    c
}

fn glb_bytes(city: &City) -> Vec<u8> {
    let mut out = Vec::new();
    city.write_glb(&mut out).unwrap();
    out
}

fn map_bytes(city: &City) -> (Vec<u8>, Vec<u8>) {
    let map = city.map_layers().unwrap();
    let mut svg = Vec::new();
    polis::export::svg::write_svg(&map, &Default::default(), &mut svg).unwrap();
    let mut json = Vec::new();
    polis::export::geojson::write_geojson(&map, &Default::default(), &mut json).unwrap();
    (svg, json)
}

fn distance_to_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + d * t)
}

/// `p` lies in `region` or within `tol` metres of its boundary.
fn inside(region: &PolygonWithHoles, p: DVec2, tol: f64) -> bool {
    region.locate(p) != PointLocation::Outside
        || region
            .rings()
            .flat_map(|(_, ring)| ring.edges())
            .any(|(a, b)| distance_to_segment(p, a, b) <= tol)
}

fn polygon_inside(inner: &Polygon, outer: &PolygonWithHoles, tol: f64) -> bool {
    inner.points().iter().all(|&p| inside(outer, p, tol))
}

fn check_city(name: &str, city: &City) {
    // The road graph is planar: graph invariants, and no two edges cross (brute force on
    // a small city).
    city.roads.check_invariants().unwrap();
    let segs: Vec<_> = city
        .roads
        .edges()
        .map(|(e, a, b, _)| (city.roads.segment(e).unwrap(), a, b))
        .collect();
    for (i, ((p0, p1), a0, b0)) in segs.iter().enumerate() {
        for ((q0, q1), a1, b1) in &segs[i + 1..] {
            let shared = [a0, b0].iter().filter(|n| **n == a1 || **n == b1).count();
            match polis::geom::segment_intersection(*p0, *p1, *q0, *q1) {
                SegmentIntersection::Disjoint => {}
                SegmentIntersection::Touching { .. } if shared > 0 => {}
                other => panic!("{name}: roads cross or touch: {other:?}"),
            }
        }
    }
    assert!(city.stats.road_segments > 50, "{name}: {:?}", city.stats);
    assert!(city.stats.buildings > 20, "{name}: {:?}", city.stats);

    // Every lot inside its block, every footprint inside its lot.
    let blocks: HashMap<u64, &PolygonWithHoles> =
        city.blocks.iter().map(|b| (b.id(), &b.polygon)).collect();
    for l in &city.lots {
        let block = blocks.get(&l.lot.block_id).expect("the lot's block exists");
        assert!(
            polygon_inside(&l.lot.polygon, block, 1e-6),
            "{name}: lot {} leaves block {}",
            l.id,
            l.lot.block_id
        );
    }
    let lots: HashMap<u64, &Polygon> = city.lots.iter().map(|l| (l.id, &l.lot.polygon)).collect();
    for b in &city.buildings {
        let lot = PolygonWithHoles::from((*lots.get(&b.lot_id).expect("lot exists")).clone());
        assert!(
            polygon_inside(&b.footprint, &lot, 1e-6),
            "{name}: building {} leaves its lot",
            b.id
        );
        // Every building mesh is a closed 2-manifold.
        for (k, part) in b.parts.iter().enumerate() {
            part.mesh
                .check_closed()
                .unwrap_or_else(|e| panic!("{name}: building {} part {k}: {e}", b.id));
        }
        assert!(b.height.is_finite() && b.height > 0.0);
    }

    // No NaN anywhere in the scene (validate checks every value and index).
    city.scene.validate().unwrap();
    for mesh in &city.scene.meshes {
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
        assert!(mesh.normals.iter().all(|n| n.is_finite()));
        assert!(mesh.uvs.iter().all(|t| t.is_finite()));
    }
    for l in &city.lots {
        assert!(l.lot.polygon.points().iter().all(|p| p.is_finite()));
    }

    // The glb reads back with the gltf crate: as many materials and images as the scene,
    // indices in range.
    let bytes = glb_bytes(city);
    let doc = polis::export::gltf::Gltf::from_slice(&bytes).unwrap();
    assert!(doc.meshes().count() > 0);
    check_glb_hygiene(name, city, &doc);
    let stats_tris = city.stats.scene_triangles;
    assert!(stats_tris > 0);
    assert_eq!(city.scene.triangle_count(), stats_tris);
    check_solids(name, city);
}

/// What the Khronos validator would list as unused is not there: no material without a
/// primitive, no texture without a material, no image without a texture, no
/// `TEXCOORD_0` on a primitive whose material has no texture (except the road material,
/// whose metre coordinates are kept on purpose); and a building's `kind` is the same word
/// in the glb as in the GeoJSON.
fn check_glb_hygiene(name: &str, city: &City, doc: &polis::export::gltf::Gltf) {
    use polis::export::gltf::Semantic;
    let mut material_used = vec![false; doc.materials().count()];
    for mesh in doc.meshes() {
        for p in mesh.primitives() {
            let m = p.material();
            if let Some(i) = m.index() {
                material_used[i] = true;
            }
            let textured = m.pbr_metallic_roughness().base_color_texture().is_some()
                || m.normal_texture().is_some();
            let road = m.name() == Some("asphalt");
            let uvs = p.get(&Semantic::TexCoords(0)).is_some();
            assert_eq!(
                uvs,
                textured || road,
                "{name}: TEXCOORD_0 on {:?}",
                m.name()
            );
        }
    }
    assert!(material_used.iter().all(|&u| u), "{name}: unused materials");
    let mut texture_used = vec![false; doc.textures().count()];
    for m in doc.materials() {
        for t in [
            m.pbr_metallic_roughness()
                .base_color_texture()
                .map(|t| t.texture().index()),
            m.normal_texture().map(|t| t.texture().index()),
            m.pbr_metallic_roughness()
                .metallic_roughness_texture()
                .map(|t| t.texture().index()),
        ]
        .into_iter()
        .flatten()
        {
            texture_used[t] = true;
        }
    }
    assert!(texture_used.iter().all(|&u| u), "{name}: unused textures");
    let mut image_used = vec![false; doc.images().count()];
    for t in doc.textures() {
        image_used[t.source().index()] = true;
    }
    assert!(image_used.iter().all(|&u| u), "{name}: unused images");
    // Samplers that suit their images: repeating or mipmapped sampling (what WebGL 1 and
    // the Khronos validator's IMAGE_NPOT_DIMENSIONS ask of) only on power-of-two images.
    let blob = doc.blob.as_deref().unwrap_or_default();
    let mut sampled_as_tiles = 0;
    for t in doc.textures() {
        use polis::export::gltf::image::Source;
        use polis::export::gltf::texture::{MinFilter, WrappingMode};
        let s = t.sampler();
        let repeats = [s.wrap_s(), s.wrap_t()]
            .iter()
            .any(|w| *w != WrappingMode::ClampToEdge);
        let mipmaps = !matches!(
            s.min_filter(),
            None | Some(MinFilter::Nearest) | Some(MinFilter::Linear)
        );
        let Source::View { view, mime_type } = t.source().source() else {
            panic!("{name}: an image outside the glb");
        };
        assert_eq!(mime_type, "image/png", "{name}");
        let png = &blob[view.offset()..view.offset() + view.length()];
        let (w, h) = (
            u32::from_be_bytes(png[16..20].try_into().unwrap()),
            u32::from_be_bytes(png[20..24].try_into().unwrap()),
        );
        if repeats || mipmaps {
            sampled_as_tiles += 1;
            assert!(
                w.is_power_of_two() && h.is_power_of_two(),
                "{name}: image {} is {w} × {h} under a repeating or mipmapped sampler",
                t.source().index()
            );
        }
    }
    assert!(
        doc.textures().count() == 0 || sampled_as_tiles > 0,
        "{name}: no texture is sampled as a repeating tile"
    );
    // One name for building kinds.
    let (svg, json) = map_bytes(city);
    let json: serde_json::Value = serde_json::from_slice(&json).unwrap();
    let mut map_kinds: Vec<String> = json["features"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["properties"]["kind"].as_str().map(str::to_string))
        .filter(|k| ["residential", "commercial", "industrial", "skyscraper"].contains(&k.as_str()))
        .collect();
    // Building nodes carry the kind in their extras; batched, the merged meshes' objects.
    let extras = |e: &polis::export::gltf::json::Extras| -> Option<serde_json::Value> {
        serde_json::from_str(e.as_ref()?.get()).ok()
    };
    let mut glb_kinds: Vec<String> = doc
        .nodes()
        .filter(|n| n.name().is_some_and(|n| n.starts_with("building ")))
        .filter_map(|n| extras(n.extras())?["kind"].as_str().map(str::to_string))
        .collect();
    for m in doc.meshes() {
        if let Some(objects) = extras(m.extras()).and_then(|v| v["objects"].as_array().cloned()) {
            glb_kinds.extend(objects.iter().filter_map(|o| {
                o["name"].as_str().filter(|n| n.starts_with("building "))?;
                o["metadata"]["kind"].as_str().map(str::to_string)
            }));
        }
    }
    // Tiled (the default): the records of the city node's feature table.
    for n in doc.nodes() {
        if let Some(table) = extras(n.extras()).and_then(|v| v["features"].as_array().cloned()) {
            glb_kinds.extend(
                table
                    .iter()
                    .filter(|r| r["layer"] == "buildings")
                    .filter_map(|r| r["kind"].as_str().map(str::to_string)),
            );
        }
    }
    map_kinds.sort();
    map_kinds.dedup();
    glb_kinds.sort();
    glb_kinds.dedup();
    assert!(
        !glb_kinds.is_empty(),
        "{name}: no building kinds in the glb"
    );
    assert_eq!(glb_kinds, map_kinds, "{name}: building kinds differ");
    // The SVG's footprints (the paths with a height) carry the kind as their class.
    let svg = String::from_utf8(svg).unwrap();
    let mut svg_kinds: Vec<String> = svg
        .lines()
        .filter(|l| l.contains("data-height="))
        .filter_map(|l| {
            let rest = &l[l.find("class=\"")? + 7..];
            Some(rest[..rest.find('"')?].to_string())
        })
        .collect();
    svg_kinds.sort();
    svg_kinds.dedup();
    assert_eq!(
        svg_kinds, map_kinds,
        "{name}: building kinds differ in the SVG"
    );
}

/// A scene node's untextured meshes: a building's mass or a block's plinth (the
/// textured ones are facade skins).
fn solid_meshes<'a>(city: &'a City, node: &polis::geom::scene::Node) -> Vec<&'a polis::geom::Mesh> {
    node.meshes
        .iter()
        .map(|id| &city.scene.meshes[id.0 as usize])
        .filter(|m| {
            m.material.is_none_or(|k| {
                city.scene.materials[k.0 as usize]
                    .base_color_texture
                    .is_none()
            })
        })
        .collect()
}

/// 100 % of building masses and block plinths are one closed, 2-manifold, outward solid
/// each, by the edge-use check: the merged solids the buildings stage offers and what the
/// scene exports (a building node's untextured meshes, the textured ones being its
/// facade skins, surfaces of their own; a block node's paved plinth).
fn check_solids(name: &str, city: &City) {
    use polis::geom::mesh::edge_use;
    let mut failed = Vec::new();
    for b in &city.buildings {
        let solid = b.merged_solid();
        let report = edge_use(solid.meshes.iter().map(|(_, m)| m));
        if !(solid.closed && report.is_solid()) {
            failed.push((b.id, solid.unmerged_because, report.open.len()));
            continue;
        }
        let parts: f64 = b.parts.iter().map(|p| p.mesh.signed_volume()).sum();
        assert!(
            (report.signed_volume - parts).abs() <= 1e-3 * parts,
            "{name}: building {}: merged volume {} m³, parts {parts} m³",
            b.id,
            report.signed_volume
        );
    }
    assert!(
        failed.is_empty(),
        "{name}: {} of {} buildings not closed: {failed:?}",
        failed.len(),
        city.buildings.len()
    );
    let (mut buildings, mut blocks) = (0, 0);
    for node in &city.scene.nodes {
        let is_building = node.name.starts_with("building ");
        if !(is_building || node.name.starts_with("block ")) {
            continue;
        }
        // A block's plinth is paved (a textured material since the street textures of
        // issue 27) and is the block's whole solid; a building's textured meshes are its
        // facade skins, surfaces of their own.
        let meshes = if is_building {
            solid_meshes(city, node)
        } else {
            node.meshes
                .iter()
                .map(|id| &city.scene.meshes[id.0 as usize])
                .collect()
        };
        let report = edge_use(meshes);
        assert!(report.is_solid(), "{name}: {}: {report:?}", node.name);
        if is_building {
            buildings += 1;
        } else {
            blocks += 1;
        }
    }
    assert_eq!(buildings, city.buildings.len(), "{name}");
    assert_eq!(blocks, city.blocks.len(), "{name}");
}

#[test]
fn every_preset_makes_a_valid_city() {
    for name in CityConfig::preset_names() {
        let config = small(name);
        let city = polis::generate(&config).unwrap();
        check_city(name, &city);
        assert!(city.stats.dressed_buildings > 0, "{name}: no facades");
        assert_eq!(city.stats.timings.len(), Stage::ALL.len());
    }
}

#[test]
fn two_runs_and_any_thread_count_give_identical_bytes() {
    for name in ["default", "paris", "milan"] {
        let mut config = small(name);
        config.threads = Some(1);
        let a = polis::generate(&config).unwrap();
        let b = polis::generate(&config).unwrap();
        config.threads = Some(3);
        let c = polis::generate(&config).unwrap();
        let (ga, gb, gc) = (glb_bytes(&a), glb_bytes(&b), glb_bytes(&c));
        assert!(ga == gb, "{name}: two serial runs differ");
        assert!(ga == gc, "{name}: serial and parallel runs differ");
        assert_eq!(map_bytes(&a), map_bytes(&c), "{name}: maps differ");
        // And the other seed gives another city.
        config.seed += 1;
        let d = polis::generate(&config).unwrap();
        assert!(glb_bytes(&d) != ga);
    }
}

/// A deliberately trivial lot stage: each block's parcels become lots as they are.
struct WholeParcels;

impl LotStage for WholeParcels {
    fn lots(&self, input: &CellInput<'_>, cx: &StageContext<'_>) -> polis::Result<CellLots> {
        let mut out = CellLots::default();
        let Ok(blocks) = polis::lots::blocks(&input.region, &cx.config.blocks) else {
            return Ok(out);
        };
        for block in blocks {
            for parcel in &block.parcels {
                let polygon = Polygon::new(parcel.outer.points.clone());
                let area = polygon.area();
                out.lots.push(std::sync::Arc::new(polis::lots::Lot {
                    street_edges: (0..polygon.len())
                        .filter(|&i| parcel.outer.street.get(i).copied().unwrap_or(false))
                        .collect(),
                    polygon,
                    block_id: block.id(),
                    area,
                }));
            }
            out.blocks.push(std::sync::Arc::new(block));
        }
        Ok(out)
    }
}

#[test]
fn a_replaced_lot_stage_is_used() {
    let config = small("default");
    let default = polis::generate(&config).unwrap();
    let custom = Pipeline::default()
        .with_lots(WholeParcels)
        .generate(&config)
        .unwrap();
    // One lot per parcel: far fewer lots than Kelly's subdivision, each a whole parcel.
    assert!(custom.lots.len() < default.lots.len() / 2);
    let parcels: usize = custom.blocks.iter().map(|b| b.parcels.len()).sum();
    assert_eq!(custom.lots.len(), parcels);
    check_city("custom lots", &custom);
}

#[test]
fn streamed_chunks_hold_exactly_what_generate_keeps() {
    let config = small("manhattan");
    let whole = Pipeline::default()
        .with_scene(false)
        .generate(&config)
        .unwrap();
    // Small chunks, so the city comes in many of them.
    let mut chunks = Vec::new();
    let streamed = Pipeline::default()
        .stream(&config, 7, |chunk| {
            chunks.push(chunk);
            Ok(())
        })
        .unwrap();
    assert!(chunks.len() > 3, "{} chunks", chunks.len());
    let cells: Vec<u64> = chunks.iter().flat_map(|c| c.cells.clone()).collect();
    assert!(cells.windows(2).all(|w| w[0] < w[1]), "cells in order");
    assert_eq!(cells.len(), whole.cells.cells.len());
    let lots: Vec<_> = chunks.iter().flat_map(|c| c.lots.clone()).collect();
    let blocks: Vec<_> = chunks.iter().flat_map(|c| c.blocks.clone()).collect();
    let buildings: Vec<_> = chunks.iter().flat_map(|c| c.buildings.clone()).collect();
    let dresses: Vec<_> = chunks.iter().flat_map(|c| c.dresses.clone()).collect();
    let building_cells: Vec<_> = chunks
        .iter()
        .flat_map(|c| c.building_cells.clone())
        .collect();
    assert_eq!(lots, whole.lots);
    assert_eq!(blocks, whole.blocks);
    assert_eq!(buildings, whole.buildings);
    assert_eq!(dresses, whole.dresses);
    assert_eq!(building_cells, whole.building_cells);
    assert!(!buildings.is_empty());
    // The returned city has the whole-city layers and counts, not the streamed ones.
    assert!(streamed.buildings.is_empty() && streamed.lots.is_empty());
    assert_eq!(streamed.stats.buildings, whole.stats.buildings);
    assert_eq!(streamed.stats.lots, whole.stats.lots);
    assert_eq!(
        streamed.stats.building_triangles,
        whole.stats.building_triangles
    );
    assert_eq!(streamed.report, whole.report);
    assert_eq!(streamed.tile_sets.len(), whole.tile_sets.len());
    // A sink's error stops the run; a chunk size of 0 is a configuration error.
    let err = Pipeline::default()
        .stream(&config, 7, |_| Err(polis::Error::config("sink", "full")))
        .unwrap_err();
    assert!(err.to_string().contains("full"), "{err}");
    assert!(matches!(
        Pipeline::default().stream(&config, 0, |_| Ok(())),
        Err(polis::Error::Config { .. })
    ));
}

#[test]
fn progress_reaches_every_stage_and_ends_at_one() {
    use std::sync::{Arc, Mutex};
    let seen: Arc<Mutex<Vec<(Stage, f64)>>> = Arc::default();
    let log = Arc::clone(&seen);
    let config = small("old_town");
    Pipeline::default()
        .with_progress(move |s, f| log.lock().unwrap().push((s, f)))
        .generate(&config)
        .unwrap();
    let seen = seen.lock().unwrap();
    for stage in Stage::ALL {
        let fractions: Vec<f64> = seen
            .iter()
            .filter(|(s, _)| *s == stage)
            .map(|(_, f)| *f)
            .collect();
        assert_eq!(fractions.last(), Some(&1.0), "{stage}");
        assert!(fractions.iter().all(|f| (0.0..=1.0).contains(f)));
        let done = fractions.iter().filter(|f| **f == 1.0).count();
        assert_eq!(done, 1, "{stage} reported done {done} times: {fractions:?}");
    }
}

#[test]
fn bad_configurations_are_errors_not_panics() {
    let mut c = small("default");
    c.size_m = f64::NAN;
    assert!(matches!(
        polis::generate(&c),
        Err(polis::Error::Config { .. })
    ));
    let mut c = small("default");
    c.threads = Some(0);
    assert!(polis::generate(&c).is_err());
    let mut c = small("default");
    c.lod = Some(c.buildings.max_lod + 1);
    assert!(matches!(
        polis::generate(&c),
        Err(polis::Error::Config { .. })
    ));
    let mut c = small("default");
    c.facades.style_of.house = "no such style".into();
    let err = polis::generate(&c).unwrap_err();
    assert!(err.to_string().contains("no such style"), "{err}");
    let mut c = small("default");
    c.roads.street_length_m = -1.0;
    assert!(polis::generate(&c).is_err());
    let mut c = small("default");
    c.scene.tile_size_m = 0.0;
    assert!(matches!(
        polis::generate(&c),
        Err(polis::Error::Config { .. })
    ));
    let mut c = small("default");
    c.maps.water = Some(polis::MapSpec::png(
        "/no/such/file.png",
        polis::geom::Aabb2::new(DVec2::ZERO, DVec2::ONE),
    ));
    assert!(polis::generate(&c).is_err());
}

#[test]
fn write_all_writes_every_file_and_the_obj_names_its_mtl() {
    let city = polis::generate(&small("suburbia")).unwrap();
    let dir = std::env::temp_dir().join(format!("polis-write-all-{}", std::process::id()));
    let written = city.write_all(&dir, polis::Formats::ALL).unwrap();
    for name in [
        "city.svg",
        "city.geojson",
        "city.glb",
        "city.obj",
        "city.mtl",
    ] {
        let path = dir.join(name);
        assert!(written.files.contains(&path), "{name} not reported");
        assert!(
            std::fs::metadata(&path).unwrap().len() > 0,
            "{name} is empty"
        );
    }
    let obj = std::fs::read_to_string(dir.join("city.obj")).unwrap();
    assert!(obj.lines().any(|l| l == "mtllib city.mtl"));
    // The glb on disk is the bytes of write_glb.
    assert_eq!(
        std::fs::read(dir.join("city.glb")).unwrap(),
        glb_bytes(&city)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Water bodies are flat surfaces at their shore's lowest point, in a `water` node, with
/// the area of the smooth water layer of the maps; the flag leaves them out.
#[test]
fn water_is_a_surface_and_the_maps_trace_it_smoothly() {
    let mut config = small("manhattan");
    config.facades.pixels_per_metre = 2.0;
    let city = polis::generate(&config).unwrap();
    let map = city.map_layers().unwrap();
    assert!(!map.water.is_empty());
    for p in &map.water {
        p.validate().unwrap();
    }
    let water_area: f64 = map.water.iter().map(|p| p.area()).sum();
    let node = city
        .scene
        .nodes
        .iter()
        .find(|n| n.name == "water")
        .expect("a water node");
    let mesh = &city.scene.meshes[node.meshes[0].0 as usize];
    mesh.validate().unwrap();
    assert!((mesh.surface_area() - water_area).abs() < 1e-3 * water_area);
    // Manhattan's ground is flat at 5 m: the water lies flat, the freeboard below it.
    let level = (5.0 - polis::WATER_FREEBOARD_M) as f32;
    assert!(mesh.positions.iter().all(|p| p.y == level));
    assert!(mesh.normals.iter().all(|n| n.y == 1.0));
    // Smooth: no staircase of 10 m cells (far fewer vertices than a cell outline).
    let vertices: usize = map.water.iter().map(|p| p.outer.len()).sum();
    let perimeter: f64 = map.water.iter().map(|p| p.outer.perimeter()).sum();
    assert!(
        (vertices as f64) < perimeter / 10.0,
        "{vertices} vertices, {perimeter} m"
    );
    config.scene.water_surfaces = false;
    let dry = polis::generate(&config).unwrap();
    assert!(dry.scene.nodes.iter().all(|n| n.name != "water"));
}

/// Buildings on slopes: with `Highest` and `Follow` no building floats or is buried at
/// its footprint's corners (within 1 cm); `Lowest` stands into the slope by at most the
/// footprint's relief. Every mass stays one closed solid.
#[test]
fn buildings_are_seated_on_slopes() {
    use polis::Foundation;
    use polis::geom::Transform;
    use polis::geom::mesh::edge_use;
    const TOL: f64 = 0.01;
    for mode in [
        Foundation::Highest,
        Foundation::Follow,
        Foundation::Lowest,
        Foundation::Average,
    ] {
        let mut config = small("san_francisco");
        config.facades.pixels_per_metre = 2.0;
        config.scene.foundations = [mode; 6];
        // The foundation modes on the elevation map itself: graded roads would reshape
        // the ground near them, and a terrain mesh makes masses reach below it by its
        // error allowance (seating on the terrain and graded ground is tests/ground.rs's).
        config.scene.grade_roads = false;
        config.scene.terrain = false;
        let city = polis::generate(&config).unwrap();
        let elevation = city.maps.inputs.elevation.as_ref();
        let nodes: HashMap<&str, &polis::geom::scene::Node> = city
            .scene
            .nodes
            .iter()
            .map(|n| (n.name.as_str(), n))
            .collect();
        let mut sloped = 0;
        for b in &city.buildings {
            let node = nodes[format!("building {}", b.id).as_str()];
            let Transform::Trs { translation, .. } = node.transform else {
                panic!("building nodes are placed by translation");
            };
            let base = translation.y;
            let ground: Vec<f64> = b
                .footprint
                .points()
                .iter()
                .map(|&p| elevation.sample(p))
                .collect();
            let (lo, hi) = ground
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, z), &g| {
                    (a.min(g), z.max(g))
                });
            sloped += usize::from(hi - lo > 0.5);
            let mass = solid_meshes(&city, node);
            assert!(
                edge_use(mass.iter().copied()).is_solid(),
                "{mode:?}: building {}",
                b.id
            );
            // The lowest point of the mass at each footprint corner, in world height.
            let bottom_at = |p: polis::geom::DVec2| {
                let local = p - b.origin;
                mass.iter()
                    .flat_map(|m| m.positions.iter())
                    .filter(|q| {
                        (f64::from(q.x) - local.x).abs() < 1e-3
                            && (f64::from(-q.z) - local.y).abs() < 1e-3
                    })
                    .map(|q| base + f64::from(q.y))
                    .fold(f64::INFINITY, f64::min)
            };
            for (&p, &g) in b.footprint.points().iter().zip(&ground) {
                let bottom = bottom_at(p);
                match mode {
                    Foundation::Highest | Foundation::Follow => {
                        assert!(base >= g - TOL, "{mode:?}: building {} buried", b.id);
                        assert!(bottom <= g + TOL, "{mode:?}: building {} floats", b.id);
                        if mode == Foundation::Follow {
                            assert!(bottom >= g - TOL, "{mode:?}: {} digs in", b.id);
                        }
                    }
                    Foundation::Lowest | Foundation::Average => {
                        assert!(bottom <= g + TOL, "{mode:?}: building {} floats", b.id);
                        assert!(base >= lo - TOL && g - base <= hi - lo + TOL);
                    }
                }
            }
        }
        assert!(sloped > 20, "{mode:?}: only {sloped} buildings on slopes");
        // Block plinths follow the ground: every vertex a kerb above it or a foot below.
        let kerb = config.scene.kerb_height_m;
        let mut plinths = 0;
        for node in city
            .scene
            .nodes
            .iter()
            .filter(|n| n.name.starts_with("block "))
        {
            for m in solid_meshes(&city, node) {
                for p in &m.positions {
                    let (q, h) = polis::geom::to_layout(p.as_dvec3());
                    let above = h - elevation.sample(q);
                    assert!(
                        (above - kerb).abs() < 1e-3 || (above + 0.5).abs() < 1e-3,
                        "{}: a vertex {above} m above the ground",
                        node.name
                    );
                }
            }
            plinths += 1;
        }
        assert_eq!(plinths, city.blocks.len());
    }
}

/// The city's glb in the default tiled layout: `city → layers → tiles`, every building
/// a record of the feature table reached by the `_FEATURE_ID_0` of its vertices, and
/// with `scene.coarse_lod` two LOD nodes per building tile with switch distances; the
/// web profile is smaller and declares its extensions.
#[test]
fn tiled_glb_has_layers_tiles_features_and_lod_levels() {
    use polis::export::glb::GlbProfile;
    let mut c = small("default");
    c.scene.coarse_lod = true;
    let city = polis::generate(&c).unwrap();
    let mut plain = Vec::new();
    let report = city.write_glb(&mut plain).unwrap();
    let doc = polis::export::gltf::Gltf::from_slice(&plain).unwrap();
    let root = doc.scenes().next().unwrap().nodes().next().unwrap();
    let layers: Vec<String> = root
        .children()
        .map(|n| n.name().unwrap_or_default().to_string())
        .collect();
    for want in ["roads", "blocks", "buildings"] {
        assert!(layers.iter().any(|l| l == want), "{layers:?}");
    }
    let extras: serde_json::Value =
        serde_json::from_str(root.extras().as_ref().unwrap().get()).unwrap();
    let table = extras["features"].as_array().unwrap();
    let buildings = table.iter().filter(|r| r["layer"] == "buildings").count();
    assert_eq!(buildings, city.buildings.len());
    for r in table.iter().filter(|r| r["layer"] == "buildings") {
        assert!(r["id"].is_string() && r["id_number"].is_number() && r["kind"].is_string());
        assert!(r["height"].is_number() && r["floors"].is_number() && r["lot"].is_number());
    }
    // Two levels per building tile, the finest first.
    let lod_nodes: Vec<serde_json::Value> = doc
        .nodes()
        .filter_map(|n| serde_json::from_str::<serde_json::Value>(n.extras().as_ref()?.get()).ok())
        .filter(|e| e.get("lod").is_some())
        .collect();
    assert!(!lod_nodes.is_empty());
    assert!(lod_nodes.iter().any(|e| e["lod_range_m"][1].is_null()));
    assert_eq!(report.features, table.len());
    // Draw calls stay within 4 × materials × tiles (both levels counted).
    assert!(report.draw_calls <= 4 * report.materials * report.tiles);
    let mut web = Vec::new();
    city.write_glb_with(&mut web, GlbProfile::Web).unwrap();
    assert!(web.len() < plain.len());
}
