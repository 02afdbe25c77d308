//! Tests of the tiled layout, feature ids, shared meshes, LOD nodes and the profiles.

use std::collections::{BTreeMap, BTreeSet};

use super::*;
use polis_geom::glam::{DMat4, DVec3, Vec2};
use polis_geom::hash::splitmix64;
use polis_geom::mesh::prism;
use polis_geom::scene::{Material, MaterialId, MetaValue};
use polis_geom::{DVec2, Mesh, Polygon};

const TILE: f64 = 250.0;

/// A town 1 km across: a road sheet over all of it (cut into tiles), and `n` buildings
/// (wall and roof materials, three wall colours) and blocks spread over it, under cells.
fn town(n: usize) -> Scene {
    let mut s = Scene::new();
    let asphalt = s.add_material(Material::new("asphalt", [0.2, 0.2, 0.2, 1.0]));
    let pavement = s.add_material(Material::new("pavement", [0.5, 0.5, 0.5, 1.0]));
    let walls = [0.3, 0.5, 0.7].map(|c| s.add_material(Material::new("wall", [c, 0.4, 0.4, 1.0])));
    let roof = s.add_material(Material::new("roof", [0.5, 0.2, 0.1, 1.0]));
    let root = s.add_root("town");
    s.set_metadata(root, "seed", 7.0).unwrap();
    // Roads: a 20 × 20 grid of 50 m quads, y = 0.
    let mut sheet = Mesh::new(Some(asphalt));
    for i in 0..20 {
        for j in 0..20 {
            let (x, z) = (i as f64 * 50.0, j as f64 * 50.0);
            let c = [[x, z], [x, z + 50.0], [x + 50.0, z + 50.0], [x + 50.0, z]]
                .map(|[x, z]| DVec3::new(x, 0.0, z));
            sheet
                .add_quad(c, [DVec2::ZERO, DVec2::Y, DVec2::ONE, DVec2::X])
                .unwrap();
        }
    }
    let roads = s.add_node(root, "roads").unwrap();
    let sheet = s.add_mesh(sheet);
    s.attach_mesh(roads, sheet).unwrap();
    for cell in 0..4 {
        let c = s.add_node(root, format!("cell {cell}")).unwrap();
        s.set_metadata(c, "cell", cell as f64).unwrap();
    }
    for i in 0..n {
        let h = splitmix64(i as u64);
        let (x, z) = ((h % 970) as f64 + 5.0, ((h >> 20) % 970) as f64 + 5.0);
        let cell = polis_geom::scene::NodeId(1 + 1 + (i % 4) as u32);
        let fp = Polygon::rect(DVec2::ZERO, DVec2::new(8.0 + (i % 4) as f64, 10.0));
        let block = s.add_node(cell, format!("block {i}")).unwrap();
        s.set_metadata(block, "layer", "blocks").unwrap();
        s.set_metadata(block, "id", format!("{i}").as_str())
            .unwrap();
        let plinth = s.add_mesh(prism(&fp.clone().into(), -0.5, 0.15, Some(pavement)).unwrap());
        s.attach_mesh(block, plinth).unwrap();
        s.node_mut(block).unwrap().transform = Transform::from_translation(DVec3::new(x, 0.0, z));
        let b = s.add_node(cell, format!("building {i}")).unwrap();
        s.set_metadata(b, "layer", "buildings").unwrap();
        s.set_metadata(b, "id", format!("{}", u64::MAX - i as u64).as_str())
            .unwrap();
        s.set_metadata(b, "height", 6.0 + (i % 7) as f64).unwrap();
        let body = prism(&fp.clone().into(), 0.0, 6.0, Some(walls[i % 3])).unwrap();
        let top = prism(&fp.into(), 6.0, 6.5, Some(roof)).unwrap();
        for m in [body, top] {
            let m = s.add_mesh(m);
            s.attach_mesh(b, m).unwrap();
        }
        s.node_mut(b).unwrap().transform = Transform::from_translation(DVec3::new(x, 0.15, z));
    }
    s
}

fn write(scene: &Scene, options: &GlbOptions) -> (Vec<u8>, GlbReport) {
    let mut out = Vec::new();
    let report = write_glb(scene, options, &mut out).unwrap();
    assert_eq!(report.bytes as usize, out.len());
    (out, report)
}

fn tiled() -> GlbOptions {
    GlbOptions {
        tile_size_m: TILE,
        ..GlbOptions::default()
    }
}

/// The JSON chunk and the binary chunk of a glb.
fn chunks(bytes: &[u8]) -> (serde_json::Value, &[u8]) {
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = bytes.get(20 + json_len + 8..).unwrap_or_default();
    (json, bin)
}

/// One accessor's values as f64, read by hand from a plain-profile binary chunk.
fn read(json: &serde_json::Value, bin: &[u8], accessor: u64) -> Vec<Vec<f64>> {
    let a = &json["accessors"][accessor as usize];
    let v = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let count = a["count"].as_u64().unwrap() as usize;
    let comps = match a["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        _ => 4,
    };
    let size = match a["componentType"].as_u64().unwrap() {
        5121 => 1,
        5123 => 2,
        _ => 4,
    };
    let stride = v["byteStride"]
        .as_u64()
        .map_or(comps * size, |s| s as usize);
    let base = v["byteOffset"].as_u64().unwrap_or(0) as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    (0..count)
        .map(|i| {
            (0..comps)
                .map(|k| {
                    let o = base + i * stride + k * size;
                    let b = &bin[o..o + size];
                    match (a["componentType"].as_u64().unwrap(), size) {
                        (5126, _) => f32::from_le_bytes(b.try_into().unwrap()) as f64,
                        (_, 1) => b[0] as f64,
                        (_, 2) => u16::from_le_bytes(b.try_into().unwrap()) as f64,
                        _ => u32::from_le_bytes(b.try_into().unwrap()) as f64,
                    }
                })
                .collect()
        })
        .collect()
}

/// One accessor of a web-profile file decoded by meshoptimizer-rs's decoder: its
/// elements' bytes (the view's stream decoded whole, then the accessor's range of it),
/// the element stride and the view's meshopt filter.
#[cfg(feature = "web")]
fn decode_accessor(
    json: &serde_json::Value,
    bin: &[u8],
    accessor: u64,
    ws: &mut meshoptimizer_rs::Workspace,
) -> (Vec<u8>, usize, String) {
    use meshoptimizer_rs::codec::{Filter, Mode, decode_buffer_view};
    let a = &json["accessors"][accessor as usize];
    let v = &json["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let e = &v["extensions"]["EXT_meshopt_compression"];
    let (o, l) = (
        e["byteOffset"].as_u64().unwrap() as usize,
        e["byteLength"].as_u64().unwrap() as usize,
    );
    let filter = e["filter"].as_str().unwrap_or("NONE").to_string();
    let stride = e["byteStride"].as_u64().unwrap() as usize;
    let count = e["count"].as_u64().unwrap() as usize;
    assert_eq!(
        v["byteLength"].as_u64().unwrap() as usize,
        count * stride,
        "the fallback view holds the decoded stream"
    );
    let raw = decode_buffer_view(
        Mode::parse(e["mode"].as_str().unwrap()).unwrap(),
        Filter::parse(&filter).unwrap(),
        count,
        stride,
        &bin[o..o + l],
        ws,
    )
    .unwrap();
    let offset = a["byteOffset"].as_u64().unwrap_or(0) as usize;
    let n = a["count"].as_u64().unwrap() as usize;
    assert_eq!(offset % stride, 0, "accessors start on an element");
    (raw[offset..offset + n * stride].to_vec(), stride, filter)
}

#[test]
fn tiled_draw_calls_are_materials_per_layer_tile_and_tree_has_layers_and_tiles() {
    let scene = town(200);
    let (bytes, report) = write(&scene, &tiled());
    gltf::Gltf::from_slice(&bytes).unwrap();
    let (json, _) = chunks(&bytes);
    let nodes = json["nodes"].as_array().unwrap();
    // root → layers → tiles.
    let root = &nodes[json["scenes"][0]["nodes"][0].as_u64().unwrap() as usize];
    assert_eq!(root["name"], "town");
    assert_eq!(root["extras"]["seed"], 7.0);
    let layer_names: Vec<&str> = root["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            nodes[c.as_u64().unwrap() as usize]["name"]
                .as_str()
                .unwrap()
        })
        .collect();
    assert_eq!(layer_names, ["roads", "blocks", "buildings"]);
    // The root lists the layers that have nodes, not its cells (nodes under it without
    // a `layer` entry or geometry of their own).
    assert_eq!(root["extras"]["layers"], serde_json::json!(layer_names));
    let mut tiles = 0;
    let mut expected_calls = 0;
    for c in root["children"].as_array().unwrap() {
        let layer = &nodes[c.as_u64().unwrap() as usize];
        assert!(
            layer.get("mesh").is_none(),
            "a layer node draws nothing itself"
        );
        let name = layer["name"].as_str().unwrap();
        for t in layer["children"].as_array().unwrap() {
            let tile = &nodes[t.as_u64().unwrap() as usize];
            let [i, j] = [0, 1].map(|k| tile["extras"]["tile"][k].as_i64().unwrap());
            assert_eq!(tile["name"], format!("{name} {i},{j}"));
            assert!((0..4).contains(&i) && (0..4).contains(&j), "{i},{j}");
            let mesh = &json["meshes"][tile["mesh"].as_u64().unwrap() as usize];
            let materials: BTreeSet<u64> = mesh["primitives"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| p["material"].as_u64().unwrap())
                .collect();
            assert_eq!(
                materials.len(),
                mesh["primitives"].as_array().unwrap().len()
            );
            expected_calls += materials.len();
            tiles += 1;
        }
    }
    // Roads cut into all 16 tiles; 200 buildings fill most of the 16.
    assert_eq!(report.tiles, tiles);
    assert!(tiles > 40, "{tiles} tiles");
    assert_eq!(report.draw_calls, expected_calls);
    let materials = report.materials;
    assert_eq!(materials, 6);
    assert!(report.draw_calls <= materials * tiles);
    // Per cell it is one mesh per cell and material: fewer, larger cells here.
    let (_, per_node) = write(&scene, &GlbOptions::with_batching(Batching::PerNode));
    assert!(per_node.draw_calls > 4 * report.draw_calls);
    // Every triangle is drawn exactly once.
    assert_eq!(report.triangles, scene.triangle_count());
}

/// Every building and block triangle carries its object's feature id; the table holds
/// the records; after shuffling the triangles of every primitive, grouping by feature id
/// still gives back each building's exact triangles.
#[test]
fn feature_ids_cover_every_object_triangle_and_survive_a_shuffle() {
    let scene = town(120);
    let (bytes, report) = write(&scene, &tiled());
    let (json, bin) = chunks(&bytes);
    let root = &json["nodes"][json["scenes"][0]["nodes"][0].as_u64().unwrap() as usize];
    let table = root["extras"]["features"].as_array().unwrap();
    assert_eq!(table.len(), 240, "120 buildings and 120 blocks");
    assert_eq!(report.features, 240);
    let null = root["extras"]["null_feature_id"].as_u64().unwrap();
    assert_eq!(null, 240);
    let b7 = table.iter().find(|r| r["name"] == "building 7").unwrap();
    assert_eq!(b7["layer"], "buildings");
    assert_eq!(
        b7["id"],
        (u64::MAX - 7).to_string(),
        "ids above 2^53 kept as text"
    );
    assert_eq!(b7["height"], 6.0);
    // Triangles per feature, as sorted world-space vertex triples, after a shuffle.
    let mut found: BTreeMap<u64, Vec<[[i64; 3]; 3]>> = BTreeMap::new();
    let mut seed = 1u64;
    for mesh in json["meshes"].as_array().unwrap() {
        for p in mesh["primitives"].as_array().unwrap() {
            let a = &p["attributes"];
            let pos = read(&json, bin, a["POSITION"].as_u64().unwrap());
            let idx = read(&json, bin, p["indices"].as_u64().unwrap());
            let Some(f) = a.get("_FEATURE_ID_0") else {
                continue;
            };
            let fid = read(&json, bin, f.as_u64().unwrap());
            let mut tris: Vec<[usize; 3]> = idx
                .chunks_exact(3)
                .map(|t| [0, 1, 2].map(|k| t[k][0] as usize))
                .collect();
            // Fisher–Yates with splitmix64: the order an optimiser might leave.
            for i in (1..tris.len()).rev() {
                seed = splitmix64(seed);
                tris.swap(i, (seed % (i as u64 + 1)) as usize);
            }
            for t in tris {
                let ids: BTreeSet<u64> = t.iter().map(|&v| fid[v][0] as u64).collect();
                assert_eq!(ids.len(), 1, "a triangle's vertices share their feature");
                let id = *ids.first().unwrap();
                assert!(id < null, "object geometry never gets the null id");
                let mut tri = t.map(|v| [0, 1, 2].map(|k| (pos[v][k] * 1000.0).round() as i64));
                tri.sort();
                found.entry(id).or_default().push(tri);
            }
        }
    }
    let world = scene.world_matrices();
    for (k, record) in table.iter().enumerate() {
        let name = record["name"].as_str().unwrap();
        let node = scene.nodes.iter().position(|n| n.name == name).unwrap();
        let mut expect = Vec::new();
        for &m in &scene.nodes[node].meshes {
            let mut mesh = scene.meshes[m.index()].clone();
            mesh.transform(&world[node]).unwrap();
            for t in mesh.indices.chunks_exact(3) {
                let mut tri = [0, 1, 2].map(|c| {
                    let p = mesh.positions[t[c] as usize];
                    [p.x, p.y, p.z].map(|x| (x as f64 * 1000.0).round() as i64)
                });
                tri.sort();
                expect.push(tri);
            }
        }
        let mut got = found.remove(&(k as u64)).unwrap_or_default();
        got.sort();
        expect.sort();
        assert_eq!(got, expect, "{name}");
    }
    assert!(found.is_empty());
}

#[test]
fn identical_meshes_are_stored_once_and_referenced_by_many_nodes() {
    let mut s = Scene::new();
    let brick = s.add_material(Material::new("brick", [0.6, 0.3, 0.2, 1.0]));
    let root = s.add_root("street");
    for i in 0..5 {
        // Five separate but identical scene meshes (a template placed five times).
        let m = prism(
            &Polygon::rect(DVec2::ZERO, DVec2::new(6.0, 9.0)).into(),
            0.0,
            7.0,
            Some(brick),
        )
        .unwrap();
        let m = s.add_mesh(m);
        let n = s.add_node(root, format!("house {i}")).unwrap();
        s.attach_mesh(n, m).unwrap();
        s.node_mut(n).unwrap().transform =
            Transform::from_translation(DVec3::new(10.0 * i as f64, 0.0, 0.0));
    }
    let (bytes, report) = write(&s, &GlbOptions::with_batching(Batching::PerNode));
    let doc = gltf::Gltf::from_slice(&bytes).unwrap();
    assert_eq!(doc.meshes().count(), 1);
    assert_eq!(report.shared_geometries, 1);
    assert_eq!(report.triangles, 12, "stored once");
    let users = doc.nodes().filter(|n| n.mesh().is_some()).count();
    assert!(users >= 2);
    assert_eq!(users, 5);
}

#[test]
fn lod_levels_become_nodes_per_tile_with_switch_distances() {
    let mut s = town(30);
    // Give each building a coarse LOD 0 box beside its detailed LOD 1 meshes.
    let buildings: Vec<usize> = (0..s.nodes.len())
        .filter(|&i| s.nodes[i].name.starts_with("building"))
        .collect();
    for b in buildings {
        let meshes = std::mem::take(&mut s.nodes[b].meshes);
        let fine = s
            .add_node(polis_geom::scene::NodeId(b as u32), "lod 1")
            .unwrap();
        s.set_metadata(fine, "lod", MetaValue::Number(1.0)).unwrap();
        s.nodes[fine.index()].meshes = meshes;
        let coarse = s
            .add_node(polis_geom::scene::NodeId(b as u32), "lod 0")
            .unwrap();
        s.set_metadata(coarse, "lod", 0.0).unwrap();
        let m = s.add_mesh(
            prism(
                &Polygon::rect(DVec2::ZERO, DVec2::new(8.0, 10.0)).into(),
                0.0,
                6.5,
                None,
            )
            .unwrap(),
        );
        s.attach_mesh(coarse, m).unwrap();
    }
    let (bytes, report) = write(&s, &tiled());
    gltf::Gltf::from_slice(&bytes).unwrap();
    let (json, _) = chunks(&bytes);
    let nodes = json["nodes"].as_array().unwrap();
    let mut levels = 0;
    for n in nodes {
        if let Some(l) = n["extras"].get("lod") {
            levels += 1;
            let range = &n["extras"]["lod_range_m"];
            if l == 1 {
                assert_eq!(range, &serde_json::json!([0.0, 300.0]));
            } else {
                assert_eq!(range, &serde_json::json!([300.0, null]));
            }
            assert!(n["name"].as_str().unwrap().starts_with("buildings "));
        }
    }
    assert!(levels >= 4 && levels % 2 == 0, "{levels}");
    // One feature per building (its LOD children share it), one per block.
    assert_eq!(report.features, 60);
}

/// The tiled options in every layout and profile.
fn every_layout_and_profile() -> Vec<GlbOptions> {
    let mut out = Vec::new();
    for batching in [
        Batching::Tiled,
        Batching::PerParentAndMaterial,
        Batching::PerNode,
    ] {
        for profile in [GlbProfile::Plain, GlbProfile::Web] {
            out.push(GlbOptions {
                batching,
                profile,
                ..tiled()
            });
        }
    }
    out
}

#[test]
fn every_layout_and_profile_reads_back_with_the_gltf_crate() {
    let scene = town(60);
    for options in every_layout_and_profile() {
        let profile = options.profile;
        let (bytes, report) = write(&scene, &options);
        let (a, _) = write(&scene, &options);
        assert_eq!(a, bytes, "deterministic");
        let doc = match profile {
            GlbProfile::Plain => gltf::Gltf::from_slice(&bytes).unwrap(),
            GlbProfile::Web => {
                let doc = gltf::Gltf::from_slice_without_validation(&bytes).unwrap();
                let mut errors = Vec::new();
                let root = doc.document.as_json();
                gltf::json::validation::Validate::validate(
                    root,
                    root,
                    gltf::json::Path::new,
                    &mut |path, error| errors.push((path(), error)),
                );
                // The only complaint: the gltf crate does not decode these extensions.
                for (path, error) in &errors {
                    assert_eq!(*error, gltf::json::validation::Error::Unsupported);
                    assert!(path.as_str().starts_with("extensionsRequired"), "{path}");
                }
                assert_eq!(errors.len(), 2);
                doc
            }
        };
        let drawn: usize = doc
            .nodes()
            .filter_map(|n| n.mesh())
            .map(|m| m.primitives().len())
            .sum();
        assert_eq!(drawn, report.draw_calls);
    }
}

/// The web profile decodes (meshoptimizer-rs's decoder) to the plain profile's
/// triangles on the quantisation grid, at a fraction of its size.
#[cfg(feature = "web")]
#[test]
fn web_profile_decodes_to_the_plain_geometry() {
    let scene = town(80);
    let (plain, _) = write(&scene, &tiled());
    let web_options = GlbOptions {
        profile: GlbProfile::Web,
        ..tiled()
    };
    let (web, _) = write(&scene, &web_options);
    let (pj, pbin) = chunks(&plain);
    let (wj, wbin) = chunks(&web);
    // The binary chunk (the JSON, mostly the feature table here, is the same).
    assert!(
        wbin.len() * 3 < pbin.len(),
        "{} vs {}",
        wbin.len(),
        pbin.len()
    );
    assert_eq!(wj["extensionsRequired"], serde_json::json!(web::EXTENSIONS));
    assert!(
        pj.get("extensionsUsed").is_none(),
        "plain uses no extension"
    );
    let mut ws = meshoptimizer_rs::Workspace::default();
    let decode = |accessor: u64, ws: &mut meshoptimizer_rs::Workspace| {
        let (raw, stride, _) = decode_accessor(&wj, wbin, accessor, ws);
        (raw, stride)
    };
    let f32s = |v: &serde_json::Value, default: f32| {
        v.as_array().map_or([default; 3], |s| {
            [0, 1, 2].map(|i| s[i].as_f64().unwrap() as f32)
        })
    };
    for (k, (pm, wm)) in pj["meshes"]
        .as_array()
        .unwrap()
        .iter()
        .zip(wj["meshes"].as_array().unwrap())
        .enumerate()
    {
        // The node drawing mesh k: its scale and translation dequantize.
        let node = wj["nodes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|n| n["mesh"] == k)
            .unwrap();
        let (scale, offset) = (f32s(&node["scale"], 1.0), f32s(&node["translation"], 0.0));
        assert!(
            scale[0] == scale[1] && scale[1] == scale[2],
            "uniform: normals keep direction"
        );
        for (pp, wp) in pm["primitives"]
            .as_array()
            .unwrap()
            .iter()
            .zip(wm["primitives"].as_array().unwrap())
        {
            // Plain triangles snapped to the grid the way the writer snaps them.
            let pos = read(&pj, pbin, pp["attributes"]["POSITION"].as_u64().unwrap());
            let idx = read(&pj, pbin, pp["indices"].as_u64().unwrap());
            let mut expect: Vec<[[u16; 3]; 3]> = idx
                .chunks_exact(3)
                .map(|t| {
                    let mut c = [0, 1, 2].map(|j| {
                        let p = &pos[t[j][0] as usize];
                        [0, 1, 2].map(|a| {
                            ((p[a] as f32 - offset[a]) / scale[a])
                                .round()
                                .clamp(0.0, 65535.0) as u16
                        })
                    });
                    c.sort();
                    c
                })
                .collect();
            let (qpos, stride) = decode(wp["attributes"]["POSITION"].as_u64().unwrap(), &mut ws);
            assert_eq!(stride, 8);
            let (qidx, isize) = decode(wp["indices"].as_u64().unwrap(), &mut ws);
            let index = |i: usize| -> usize {
                if isize == 2 {
                    u16::from_le_bytes([qidx[2 * i], qidx[2 * i + 1]]) as usize
                } else {
                    u32::from_le_bytes(qidx[4 * i..4 * i + 4].try_into().unwrap()) as usize
                }
            };
            let mut got: Vec<[[u16; 3]; 3]> = (0..qidx.len() / isize / 3)
                .map(|t| {
                    let mut c = [0, 1, 2].map(|j| {
                        let v = index(3 * t + j);
                        [0, 1, 2].map(|a| {
                            u16::from_le_bytes([qpos[8 * v + 2 * a], qpos[8 * v + 2 * a + 1]])
                        })
                    });
                    c.sort();
                    c
                })
                .collect();
            expect.sort();
            got.sort();
            assert_eq!(got, expect, "mesh {k}");
            // Normals (octahedral filter, signed bytes): every decoded normal is within
            // a few degrees of a plain normal of the same primitive; the faces of these
            // boxes have six directions.
            let filter = &wj["bufferViews"][wj["accessors"]
                [wp["attributes"]["NORMAL"].as_u64().unwrap() as usize]["bufferView"]
                .as_u64()
                .unwrap() as usize]["extensions"]["EXT_meshopt_compression"]["filter"];
            assert_eq!(filter, "OCTAHEDRAL");
            let plain_normals = read(&pj, pbin, pp["attributes"]["NORMAL"].as_u64().unwrap());
            let (qn, nstride) = decode(wp["attributes"]["NORMAL"].as_u64().unwrap(), &mut ws);
            assert_eq!(nstride, 4);
            for q in qn.chunks_exact(4) {
                let d = [0, 1, 2].map(|a| f64::from(q[a] as i8) / 127.0);
                let best = plain_normals
                    .iter()
                    .map(|p| p[0] * d[0] + p[1] * d[1] + p[2] * d[2])
                    .fold(f64::MIN, f64::max);
                assert!(best > 0.998, "normal {d:?} off by more than 3.6°");
            }
        }
    }
}

/// The local matrix of a glTF node (or of one instance: the same TRS fields).
fn local_matrix(n: &serde_json::Value) -> DMat4 {
    if let Some(m) = n["matrix"].as_array() {
        let c: Vec<f64> = m.iter().map(|x| x.as_f64().unwrap()).collect();
        return DMat4::from_cols_slice(&c);
    }
    let v = |key: &str, d: [f64; 4]| -> [f64; 4] {
        n[key].as_array().map_or(d, |a| {
            let mut out = d;
            for (o, x) in out.iter_mut().zip(a) {
                *o = x.as_f64().unwrap();
            }
            out
        })
    };
    let t = v("translation", [0.0; 4]);
    let r = v("rotation", [0.0, 0.0, 0.0, 1.0]);
    let s = v("scale", [1.0; 4]);
    DMat4::from_scale_rotation_translation(
        DVec3::new(s[0], s[1], s[2]),
        polis_geom::glam::DQuat::from_xyzw(r[0], r[1], r[2], r[3]),
        DVec3::new(t[0], t[1], t[2]),
    )
}

/// Every triangle a plain-profile glb draws, in world space (instances expanded), as
/// sorted corner triples rounded to 0.1 mm, sorted.
fn world_triangles(bytes: &[u8]) -> Vec<[[i64; 3]; 3]> {
    let (j, bin) = chunks(bytes);
    let mut out = Vec::new();
    let mut stack: Vec<(u64, DMat4)> = j["scenes"][0]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| (n.as_u64().unwrap(), DMat4::IDENTITY))
        .collect();
    while let Some((i, parent)) = stack.pop() {
        let n = &j["nodes"][i as usize];
        let world = parent * local_matrix(n);
        for c in n["children"].as_array().into_iter().flatten() {
            stack.push((c.as_u64().unwrap(), world));
        }
        let Some(mesh) = n["mesh"].as_u64() else {
            continue;
        };
        let placements: Vec<DMat4> =
            match n["extensions"]["EXT_mesh_gpu_instancing"]["attributes"].as_object() {
                None => vec![world],
                Some(a) => {
                    let t = read(&j, bin, a["TRANSLATION"].as_u64().unwrap());
                    let r = read(&j, bin, a["ROTATION"].as_u64().unwrap());
                    let s = read(&j, bin, a["SCALE"].as_u64().unwrap());
                    (0..t.len())
                        .map(|k| {
                            world
                                * DMat4::from_scale_rotation_translation(
                                    DVec3::new(s[k][0], s[k][1], s[k][2]),
                                    polis_geom::glam::DQuat::from_xyzw(
                                        r[k][0], r[k][1], r[k][2], r[k][3],
                                    ),
                                    DVec3::new(t[k][0], t[k][1], t[k][2]),
                                )
                        })
                        .collect()
                }
            };
        for p in j["meshes"][mesh as usize]["primitives"].as_array().unwrap() {
            let pos = read(&j, bin, p["attributes"]["POSITION"].as_u64().unwrap());
            let idx = read(&j, bin, p["indices"].as_u64().unwrap());
            for m in &placements {
                for t in idx.chunks_exact(3) {
                    let mut tri = [0, 1, 2].map(|k| {
                        let q = &pos[t[k][0] as usize];
                        let w = m.transform_point3(DVec3::new(q[0], q[1], q[2]));
                        [w.x, w.y, w.z].map(|c| (c * 1e4).round() as i64)
                    });
                    tri.sort();
                    out.push(tri);
                }
            }
        }
    }
    out.sort();
    out
}

#[test]
fn gpu_instancing_expands_to_the_same_triangles_as_the_per_node_layout() {
    let scene = town(60);
    let plain = GlbOptions::with_batching(Batching::PerNode);
    let (a, ra) = write(&scene, &plain);
    let instanced = GlbOptions {
        gpu_instancing: true,
        ..plain.clone()
    };
    let (b, rb) = write(&scene, &instanced);
    assert_eq!(ra.instances, 0);
    assert!(rb.instances > 0 && rb.nodes < ra.nodes, "{rb:?}");
    assert_eq!(world_triangles(&a), world_triangles(&b));
    // Loads with the gltf crate; the extension is used, not required.
    gltf::Gltf::from_slice(&b).unwrap();
    let (j, bin) = chunks(&b);
    assert_eq!(
        j["extensionsUsed"],
        serde_json::json!(["EXT_mesh_gpu_instancing"])
    );
    assert!(j.get("extensionsRequired").is_none());
    // Each instanced node lists its instances, numbered by _FEATURE_ID_0, and every
    // building of the scene is still named once (as a node or an instance).
    let mut names = BTreeSet::new();
    let mut instances = 0;
    for n in j["nodes"].as_array().unwrap() {
        let Some(a) = n["extensions"]["EXT_mesh_gpu_instancing"]["attributes"].as_object() else {
            if let Some(name) = n["name"].as_str() {
                names.insert(name.to_string());
            }
            continue;
        };
        let records = n["extras"]["instances"].as_array().unwrap();
        let ids = read(&j, bin, a["_FEATURE_ID_0"].as_u64().unwrap());
        assert_eq!(ids.len(), records.len());
        for (k, (id, r)) in ids.iter().zip(records).enumerate() {
            assert_eq!(id[0], k as f64);
            assert!(names.insert(r["name"].as_str().unwrap().to_string()));
        }
        instances += records.len();
    }
    assert_eq!(instances, rb.instances);
    for i in 0..60 {
        assert!(names.contains(&format!("building {i}")), "building {i}");
    }
    // The web profile's instances carry the dequantisation: the same triangles on the
    // grid, read back with the gltf crate's structure checks.
    let web = GlbOptions {
        profile: GlbProfile::Web,
        ..instanced
    };
    let (w, rw) = write(&scene, &web);
    assert_eq!(rw.instances, rb.instances);
    gltf::Gltf::from_slice_without_validation(&w).unwrap();
}

#[test]
fn bad_options_are_typed_errors() {
    let scene = town(3);
    for bad in [0.0, -5.0, f64::NAN, f64::INFINITY] {
        let o = GlbOptions {
            tile_size_m: bad,
            ..GlbOptions::default()
        };
        assert!(matches!(
            write_glb(&scene, &o, Vec::new()),
            Err(ExportError::InvalidOption { .. })
        ));
    }
    let mut s = town(3);
    let b = s.nodes.iter().position(|n| n.name == "building 1").unwrap();
    s.nodes[b].metadata.insert("lod", 1.5);
    assert!(matches!(
        write_glb(&s, &tiled(), Vec::new()),
        Err(ExportError::InvalidOption { name: "lod", .. })
    ));
    assert_eq!("web".parse::<GlbProfile>().unwrap(), GlbProfile::Web);
    assert!("zip".parse::<GlbProfile>().is_err());
    let _ = Vec2::ZERO;
}

/// The web profile's feature table, by column, holds exactly the plain profile's records.
#[cfg(feature = "web")]
#[test]
fn web_feature_table_by_column_holds_the_plain_records() {
    let scene = town(40);
    let web_options = GlbOptions {
        profile: GlbProfile::Web,
        ..tiled()
    };
    let table = |bytes: &[u8]| {
        let (json, _) = chunks(bytes);
        let root = json["scenes"][0]["nodes"][0].as_u64().unwrap() as usize;
        json["nodes"][root]["extras"]["features"].clone()
    };
    let rows = table(&write(&scene, &tiled()).0);
    let columns = table(&write(&scene, &web_options).0);
    let rows = rows.as_array().unwrap();
    let columns = columns.as_object().unwrap();
    assert!(columns.contains_key("id") && columns.contains_key("height"));
    assert!(
        columns
            .keys()
            .zip(columns.keys().skip(1))
            .all(|(a, b)| a < b)
    );
    for (k, record) in rows.iter().enumerate() {
        let mut rebuilt = serde_json::Map::new();
        for (key, column) in columns {
            let column = column.as_array().unwrap();
            assert_eq!(column.len(), rows.len(), "{key}");
            if !column[k].is_null() {
                rebuilt.insert(key.clone(), column[k].clone());
            }
        }
        let record = record.as_object().unwrap();
        assert_eq!(rebuilt.len(), record.len(), "record {k}");
        for (key, v) in record {
            let w = &rebuilt[key];
            match v.as_f64() {
                Some(x) => assert_eq!(w.as_f64(), Some(x), "record {k} {key}"),
                None => assert_eq!(w, v, "record {k} {key}"),
            }
        }
    }
}

/// Texture coordinates of the web profile decode to the plain ones within 1/4096 of a
/// repeat: within [0, 1] as normalized 16-bit, beyond through the exponential filter.
#[cfg(feature = "web")]
#[test]
fn web_texture_coordinates_decode_close_to_the_plain_ones() {
    let mut s = Scene::new();
    let image = s.add_image(polis_geom::scene::Image {
        name: "grey".into(),
        data: polis_geom::scene::ImageData::Rgba8 {
            width: 2,
            height: 2,
            pixels: vec![128; 16],
        },
    });
    let texture = s
        .add_texture(polis_geom::scene::Texture {
            name: "grey".into(),
            image,
            ..Default::default()
        })
        .unwrap();
    let root = s.add_root("map");
    // Unit coordinates over a 600 m sheet (a map-wide texture) and metre coordinates
    // on a road strip 1.9 km long, both cut by tiles.
    let mut unit = Mesh::new(Some(s.add_material(Material {
        base_color_texture: Some(texture),
        ..Material::new("ground", [1.0; 4])
    })));
    let mut metres = Mesh::new(Some(s.add_material(Material {
        base_color_texture: Some(texture),
        ..Material::new("paving", [1.0; 4])
    })));
    for i in 0..12 {
        for j in 0..12 {
            let (x, z) = (i as f64 * 50.0, j as f64 * 50.0);
            let c = [[x, z], [x, z + 50.0], [x + 50.0, z + 50.0], [x + 50.0, z]];
            unit.add_quad(
                c.map(|[x, z]| DVec3::new(x, 0.0, z)),
                c.map(|[x, z]| DVec2::new(x / 600.0, z / 600.0)),
            )
            .unwrap();
        }
    }
    for i in 0..38 {
        let x = i as f64 * 50.0 - 950.0;
        let c = [[x, 0.0], [x, 7.0], [x + 50.0, 7.0], [x + 50.0, 0.0]];
        metres
            .add_quad(
                c.map(|[x, z]| DVec3::new(x, 0.1, z)),
                c.map(|[x, z]| DVec2::new(x + 0.37, z * 1.13)),
            )
            .unwrap();
    }
    for (name, m) in [("ground", unit), ("roads", metres)] {
        let n = s.add_node(root, name).unwrap();
        let m = s.add_mesh(m);
        s.attach_mesh(n, m).unwrap();
    }
    let web_options = GlbOptions {
        profile: GlbProfile::Web,
        ..tiled()
    };
    let (plain, _) = write(&s, &tiled());
    let (web, _) = write(&s, &web_options);
    let (pj, pbin) = chunks(&plain);
    let (wj, wbin) = chunks(&web);
    let mut ws = meshoptimizer_rs::Workspace::default();
    let mut codings = BTreeSet::new();
    let materials = |j: &serde_json::Value, p: &serde_json::Value| {
        j["materials"][p["material"].as_u64().unwrap() as usize]["name"].clone()
    };
    let mut expect: BTreeMap<String, Vec<[f64; 2]>> = BTreeMap::new();
    for m in pj["meshes"].as_array().unwrap() {
        for p in m["primitives"].as_array().unwrap() {
            let uv = read(&pj, pbin, p["attributes"]["TEXCOORD_0"].as_u64().unwrap());
            expect
                .entry(materials(&pj, p).to_string())
                .or_default()
                .extend(uv.iter().map(|t| [t[0], t[1]]));
        }
    }
    let mut got: BTreeMap<String, Vec<[f64; 2]>> = BTreeMap::new();
    for m in wj["meshes"].as_array().unwrap() {
        for p in m["primitives"].as_array().unwrap() {
            let uv = p["attributes"]["TEXCOORD_0"].as_u64().unwrap();
            let a = &wj["accessors"][uv as usize];
            let (raw, stride, filter) = decode_accessor(&wj, wbin, uv, &mut ws);
            let component = a["componentType"].as_u64().unwrap();
            codings.insert((materials(&wj, p).to_string(), component, filter.to_string()));
            let uvs = raw.chunks_exact(stride).map(|t| match component {
                5123 => {
                    assert_eq!(a["normalized"], true);
                    [0, 2].map(|k| f64::from(u16::from_le_bytes([t[k], t[k + 1]])) / 65_535.0)
                }
                _ => [0, 4].map(|k| f64::from(f32::from_le_bytes(t[k..k + 4].try_into().unwrap()))),
            });
            got.entry(materials(&wj, p).to_string())
                .or_default()
                .extend(uvs);
        }
    }
    let codings: Vec<_> = codings.into_iter().collect();
    assert_eq!(
        codings,
        [
            ("\"ground\"".to_string(), 5123, "NONE".to_string()),
            ("\"paving\"".to_string(), 5126, "EXPONENTIAL".to_string())
        ]
    );
    for (material, expect) in &expect {
        let got = &got[material];
        // Every decoded coordinate lies within 1/4096 of a plain one and back (the web
        // profile reorders and may drop unused vertices, never adds any).
        for (from, to) in [(got, expect), (expect, got)] {
            for t in from {
                let best = to
                    .iter()
                    .map(|u| (t[0] - u[0]).abs().max((t[1] - u[1]).abs()))
                    .fold(f64::INFINITY, f64::min);
                assert!(best <= 1.0 / 4096.0, "{material}: {t:?} is {best} away");
            }
        }
    }
}

/// Buffer views hold the arrays of a batch of meshes back to back, one view per kind:
/// far fewer views than accessors, every accessor inside its view, aligned (vertex
/// attributes on 4 bytes, indices on their size) and on a stride that is a multiple of 4,
/// accessors of a view not overlapping, and the views of a file disjoint.
#[test]
fn buffer_views_are_shared_by_aligned_disjoint_accessors() {
    let scene = town(60);
    for options in every_layout_and_profile() {
        let (batching, profile) = (options.batching, options.profile);
        let (bytes, _) = write(&scene, &options);
        let (j, _) = chunks(&bytes);
        let views = j["bufferViews"].as_array().unwrap();
        let accessors = j["accessors"].as_array().unwrap();
        let geometry_views: BTreeSet<u64> = accessors
            .iter()
            .map(|a| a["bufferView"].as_u64().unwrap())
            .collect();
        let label = format!("{batching:?} {profile}");
        assert!(
            4 * geometry_views.len() <= accessors.len(),
            "{label}: {} views for {} accessors",
            geometry_views.len(),
            accessors.len()
        );
        let mut ranges: BTreeMap<u64, Vec<(u64, u64)>> = BTreeMap::new();
        for a in accessors {
            let vi = a["bufferView"].as_u64().unwrap();
            let v = &views[vi as usize];
            let offset = a["byteOffset"].as_u64().unwrap_or(0);
            let count = a["count"].as_u64().unwrap();
            let component = match a["componentType"].as_u64().unwrap() {
                5120 | 5121 => 1,
                5122 | 5123 => 2,
                _ => 4,
            };
            let comps = match a["type"].as_str().unwrap() {
                "SCALAR" => 1,
                "VEC2" => 2,
                "VEC3" => 3,
                _ => 4,
            };
            let element = component * comps;
            let stride = v["byteStride"].as_u64().unwrap_or(element);
            let start = v["byteOffset"].as_u64().unwrap_or(0) + offset;
            assert_eq!(start % component, 0, "{label}: accessor alignment");
            if v["target"] == 34962 {
                assert_eq!(start % 4, 0, "{label}: vertex attribute alignment");
                assert_eq!(stride % 4, 0, "{label}: stride");
                assert!(stride >= element);
            } else {
                assert_eq!(v["target"], 34963, "{label}: indices");
                assert!(v.get("byteStride").is_none(), "{label}: index view stride");
            }
            let end = offset + stride * (count - 1) + element;
            assert!(
                end <= v["byteLength"].as_u64().unwrap(),
                "{label}: accessor past its view"
            );
            ranges
                .entry(vi)
                .or_default()
                .push((offset, offset + stride * count));
        }
        for (vi, mut r) in ranges {
            r.sort_unstable();
            for w in r.windows(2) {
                // Shared geometry (per node) is one accessor, not two.
                assert!(
                    w[0].1 <= w[1].0,
                    "{label}: view {vi} has overlapping arrays"
                );
            }
        }
        let mut spans: Vec<(u64, u64, u64)> = views
            .iter()
            .map(|v| {
                let o = v["byteOffset"].as_u64().unwrap_or(0);
                (
                    v["buffer"].as_u64().unwrap(),
                    o,
                    o + v["byteLength"].as_u64().unwrap(),
                )
            })
            .collect();
        spans.sort_unstable();
        for w in spans.windows(2) {
            assert!(
                w[0].0 < w[1].0 || w[0].2 <= w[1].1,
                "{label}: views overlap"
            );
        }
    }
}

/// A smooth-shaded hilly sheet of `n` × `n` quads of `step` metres from layout point
/// `(origin, origin)`, placed as the terrain places it (layout `y` is world `−z`, so a
/// row at `y = 0` has `z = −0`), each quad a fan of four up-facing triangles around its
/// centre (so triangles straddle every tile border), with texture coordinates: a ground
/// as the terrain builds it.
fn hills(n: usize, step: f64, origin: f64, material: Option<MaterialId>) -> Mesh {
    let mut m = Mesh::new(material);
    let at = |x: f64, y: f64| {
        let h = (x * 0.013).sin() * 4.0 + (y * 0.021).cos() * 3.0;
        polis_geom::to_world(DVec2::new(x, y), h)
    };
    let uv = |p: DVec3| DVec2::new(p.x / 1000.0, -p.z / 1000.0);
    let corner = |i: usize, j: usize| at(origin + i as f64 * step, origin + j as f64 * step);
    let mut ids = vec![0u32; (n + 1) * (n + 1)];
    for j in 0..=n {
        for i in 0..=n {
            let p = corner(i, j);
            ids[j * (n + 1) + i] = m.add_vertex(p, DVec3::Y, uv(p));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let c = at(
                origin + (i as f64 + 0.5) * step,
                origin + (j as f64 + 0.5) * step,
            );
            let centre = m.add_vertex(c, DVec3::Y, uv(c));
            let ring =
                [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(a, b)| ids[b * (n + 1) + a]);
            for k in 0..4 {
                m.push_triangle(centre, ring[k], ring[(k + 1) % 4]).unwrap();
            }
        }
    }
    m.compute_smooth_normals().unwrap();
    m
}

/// A ground cut into tiles where it is built ([`Mesh::cut_into_tiles`], one mesh per
/// tile on its node) is written by the tiled layout byte for byte as the same ground in
/// one mesh, in both profiles (the writer appends each ready tile whole instead of
/// cutting it); a mesh cut for another tile size is cut again and still covers the
/// same triangles.
#[test]
fn a_ground_cut_in_advance_writes_the_bytes_of_the_whole_ground() {
    let build = |tiles: Option<f64>| {
        let mut s = town(40);
        let root = s.roots[0];
        let grass = s.add_material(Material::new("grass", [0.3, 0.6, 0.2, 1.0]));
        let ground = s.add_node(root, "ground").unwrap();
        s.set_metadata(ground, "max_error_m", 0.2).unwrap();
        let sheet = hills(29, 37.0, -74.0, Some(grass));
        let parts = match tiles {
            None => vec![sheet],
            Some(size) => sheet
                .cut_into_tiles(size)
                .into_iter()
                .map(|(_, m, _)| m)
                .collect(),
        };
        for m in parts {
            let m = s.add_mesh(m);
            s.attach_mesh(ground, m).unwrap();
        }
        s
    };
    let (whole, cut, other) = (build(None), build(Some(TILE)), build(Some(170.0)));
    assert!(
        cut.meshes.len() > whole.meshes.len() + 8,
        "the ground spans many tiles"
    );
    for profile in [GlbProfile::Plain, GlbProfile::Web] {
        let options = GlbOptions { profile, ..tiled() };
        let (a, ra) = write(&whole, &options);
        let (b, _) = write(&cut, &options);
        assert!(a == b, "{profile}: the cut ground changed the bytes");
        let (c, rc) = write(&other, &options);
        assert_eq!(
            (rc.triangles, rc.tiles),
            (ra.triangles, ra.tiles),
            "{profile}"
        );
        if profile == GlbProfile::Plain {
            assert_eq!(
                world_triangles(&a),
                world_triangles(&c),
                "cut again, the same triangles"
            );
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// The counting sort of the cut gives what sorting (tile, triangle) pairs gives,
    /// on dense sheets and on sparse ones (a far triangle takes the sorted-map path).
    #[test]
    fn triangles_by_tile_matches_sorting_pairs(
        corners in proptest::collection::vec(
            ((-900.0f32..900.0, -900.0f32..900.0), (-9.0f32..9.0, -9.0f32..9.0)),
            1..80,
        ),
        far in proptest::prelude::any::<bool>(),
        size in 20.0f64..300.0,
    ) {
        let mut m = Mesh::new(None);
        for ((x, z), (dx, dz)) in corners {
            let base = m.positions.len() as u32;
            for p in [Vec3::new(x, 0.0, z), Vec3::new(x + dx, 1.0, z), Vec3::new(x, 0.0, z + dz)] {
                m.positions.push(p);
                m.normals.push(Vec3::Y);
            }
            m.indices.extend([base, base + 1, base + 2]);
        }
        if far {
            let base = m.positions.len() as u32;
            for x in [1.0e7f32, 1.0e7 + 3.0, 1.0e7] {
                m.positions.push(Vec3::new(x, 0.0, -4.0e6));
                m.normals.push(Vec3::Y);
            }
            m.indices.extend([base, base + 1, base + 2]);
        }
        let mut pairs: Vec<((i64, i64), u32)> = m
            .indices
            .chunks_exact(3)
            .enumerate()
            .map(|(t, tri)| {
                let c = (m.positions[tri[0] as usize]
                    + m.positions[tri[1] as usize]
                    + m.positions[tri[2] as usize])
                    / 3.0;
                let tile = |v: f32| (f64::from(v) / size).floor() as i64;
                ((tile(c.x), tile(c.z)), t as u32)
            })
            .collect();
        pairs.sort_unstable();
        let mut expect: Vec<((i64, i64), Vec<u32>)> = Vec::new();
        for run in pairs.chunk_by(|a, b| a.0 == b.0) {
            expect.push((run[0].0, run.iter().map(|p| p.1).collect()));
        }
        proptest::prop_assert_eq!(polis_geom::mesh::triangles_by_tile(&m, size), expect);
    }
}
