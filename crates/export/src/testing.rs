//! Test fixtures and independent readers shared by the unit and property tests.
//!
//! Each item needs the features of what it reads or writes; with some writers left out
//! (`--no-default-features`) the fixtures of the others go unused.
#![cfg_attr(
    not(all(
        feature = "gltf",
        feature = "obj",
        feature = "svg",
        feature = "geojson"
    )),
    allow(dead_code, unused_imports)
)]

use std::collections::BTreeMap;

#[cfg(feature = "gltf")]
use gltf::accessor::{DataType, Dimensions};
use polis_geom::glam::{DQuat, DVec3};
use polis_geom::mesh::prism;
use polis_geom::scene::{
    Filter, Image, ImageData, Material, MaterialId, NodeId, Scene, Texture, Transform, Wrap,
};
use polis_geom::{DVec2, Mesh, Polygon};

#[cfg(feature = "png")]
/// A scene with textures (raw and PNG), three materials, an instanced prism, a mesh without
/// material, an empty mesh, metadata, and a transform hierarchy.
pub fn sample_scene() -> Scene {
    let mut s = Scene::new();
    let raw = s.add_image(Image {
        name: "brick".into(),
        data: ImageData::Rgba8 {
            width: 4,
            height: 2,
            pixels: (0..32).map(|i| (i * 7) as u8).collect(),
        },
    });
    let png = crate::images::png_bytes(
        0,
        &Image {
            name: String::new(),
            data: ImageData::Rgba8 {
                width: 1,
                height: 1,
                pixels: vec![10, 20, 30, 255],
            },
        },
    )
    .unwrap()
    .into_owned();
    let nrm = s.add_image(Image {
        name: "normal map".into(),
        data: ImageData::Png(png),
    });
    let t0 = s
        .add_texture(Texture {
            name: "brick".into(),
            image: raw,
            ..Texture::default()
        })
        .unwrap();
    let t1 = s
        .add_texture(Texture {
            name: "bumps".into(),
            image: nrm,
            wrap_u: Wrap::ClampToEdge,
            wrap_v: Wrap::MirroredRepeat,
            filter: Filter::Nearest,
        })
        .unwrap();
    let brick = s.add_material(Material {
        base_color_texture: Some(t0),
        normal_texture: Some(t1),
        ..Material::new("brick wall", [0.7, 0.4, 0.3, 1.0])
    });
    let glass = s.add_material(Material {
        metallic: 0.8,
        roughness: 0.1,
        double_sided: true,
        ..Material::new("glass", [0.5, 0.6, 0.7, 0.4])
    });
    let _unused = s.add_material(Material::new("", [1.0, 1.0, 1.0, 1.0]));
    let house = s.add_mesh(
        prism(
            &Polygon::rect(DVec2::ZERO, DVec2::new(8.0, 12.0)).into(),
            0.0,
            9.0,
            Some(brick),
        )
        .unwrap(),
    );
    let roof = s.add_mesh(
        prism(
            &Polygon::regular(6, DVec2::new(4.0, 6.0), 3.0).into(),
            9.0,
            10.0,
            Some(glass),
        )
        .unwrap(),
    );
    let plain = s.add_mesh(
        prism(
            &Polygon::rect(DVec2::new(-5.0, -5.0), DVec2::new(5.0, 5.0)).into(),
            -1.0,
            0.0,
            None,
        )
        .unwrap(),
    );
    let empty = s.add_mesh(Mesh::new(Some(brick)));
    let city = s.add_root("city");
    s.attach_mesh(city, plain).unwrap();
    s.set_metadata(city, "seed", 42.0).unwrap();
    let block = s.add_node(city, "block 1").unwrap();
    s.node_mut(block).unwrap().transform = Transform::Trs {
        translation: DVec3::new(0.0, 1.0, 0.0),
        rotation: DQuat::from_rotation_y(0.3),
        scale: DVec3::splat(2.0),
    };
    for k in 0..3 {
        let b = s.add_node(block, format!("house {k}")).unwrap();
        s.attach_mesh(b, house).unwrap();
        if k != 1 {
            s.attach_mesh(b, roof).unwrap();
        }
        s.attach_mesh(b, empty).unwrap();
        s.set_metadata(b, "kind", "residential").unwrap();
        s.set_metadata(b, "height", 9.0 + k as f64).unwrap();
        s.set_metadata(b, "lot", k as f64).unwrap();
        s.set_metadata(b, "corner", k == 0).unwrap();
        s.node_mut(b).unwrap().transform =
            Transform::from_translation(DVec3::new(10.0 * k as f64, 0.0, 0.0));
    }
    // A mirrored building with a matrix transform, and an empty grouping node.
    let mirrored = s.add_node(city, "mirror").unwrap();
    s.attach_mesh(mirrored, house).unwrap();
    s.node_mut(mirrored).unwrap().transform =
        Transform::Matrix(polis_geom::glam::DMat4::from_scale_rotation_translation(
            DVec3::new(-1.0, 1.0, 1.0),
            DQuat::IDENTITY,
            DVec3::new(-30.0, 0.0, 5.0),
        ));
    let _group = s.add_node(city, "empty group").unwrap();
    s.validate().unwrap();
    s
}

/// A scene of `n` unit-ish boxes under one parent, alternating two materials: for batching
/// and size tests.
pub fn grid_scene(n: usize) -> Scene {
    let mut s = Scene::new();
    let a = s.add_material(Material::new("a", [0.2, 0.3, 0.4, 1.0]));
    let b = s.add_material(Material::new("b", [0.9, 0.8, 0.7, 1.0]));
    let root = s.add_root("city");
    let cell = s.add_node(root, "cell").unwrap();
    for i in 0..n {
        let m = prism(
            &Polygon::rect(DVec2::ZERO, DVec2::new(1.0 + (i % 3) as f64, 2.0)).into(),
            0.0,
            3.0 + (i % 5) as f64,
            Some(if i % 2 == 0 { a } else { b }),
        )
        .unwrap();
        let id = s.add_mesh(m);
        let node = s.add_node(cell, format!("box {i}")).unwrap();
        s.attach_mesh(node, id).unwrap();
        s.set_metadata(node, "index", i as f64).unwrap();
        s.node_mut(node).unwrap().transform = Transform::from_translation(DVec3::new(
            (i % 10) as f64 * 4.0,
            0.0,
            (i / 10) as f64 * 4.0,
        ));
    }
    s
}

#[cfg(feature = "gltf")]
/// One primitive read back from a glb, decoded from the BIN chunk by hand.
#[derive(Debug, Clone)]
pub struct Prim {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub indices: Vec<u32>,
    pub wide: bool,
    pub material: Option<usize>,
}

#[cfg(feature = "gltf")]
/// A node read back: name, mesh, children, extras.
pub type NodeInfo = (
    Option<String>,
    Option<usize>,
    Vec<usize>,
    Option<serde_json::Value>,
);

#[cfg(feature = "gltf")]
/// A glb read back with the `gltf` crate and checked.
#[derive(Debug)]
pub struct Decoded {
    pub nodes: usize,
    pub meshes: usize,
    pub materials: usize,
    pub textures: usize,
    pub images: usize,
    pub samplers: usize,
    /// Per glTF mesh, its primitives.
    pub prims: Vec<Vec<Prim>>,
    /// Per node: name, mesh, children, extras.
    pub node_info: Vec<NodeInfo>,
    pub mesh_extras: Vec<Option<serde_json::Value>>,
    pub roots: Vec<usize>,
    pub json: serde_json::Value,
    /// Primitives with a `TANGENT` attribute.
    pub tangent_prims: usize,
}

#[cfg(feature = "gltf")]
fn extras(e: &gltf::json::Extras) -> Option<serde_json::Value> {
    e.as_ref()
        .map(|raw| serde_json::from_str(raw.get()).unwrap())
}

#[cfg(feature = "gltf")]
/// Reads a glb with `gltf::Gltf::from_slice` (which validates the document) and checks
/// what glTF requires and the reader does not: the container matches what
/// `gltf::binary::Glb::to_writer` writes; accessors lie inside their views and are aligned;
/// `POSITION` bounds equal the data's; normals are unit; indices are in range, of the
/// narrowest type the writer promises and never the restart value; images are PNG files.
pub fn decode_glb(bytes: &[u8]) -> Decoded {
    let gltf = gltf::Gltf::from_slice(bytes).expect("the gltf crate reads and validates the glb");
    // Same bytes as the gltf crate's own writer for the same chunks.
    let glb = gltf::binary::Glb::from_slice(bytes).unwrap();
    assert_eq!(
        glb.to_vec().unwrap(),
        bytes,
        "container differs from Glb::to_writer"
    );
    assert_eq!(glb.header.length as usize, bytes.len());
    let json: serde_json::Value = serde_json::from_slice(&glb.json).unwrap();
    let blob = gltf.blob.clone().unwrap_or_default();
    if let Some(buffer) = gltf.buffers().next() {
        assert_eq!(buffer.length(), blob.len());
        assert!(matches!(buffer.source(), gltf::buffer::Source::Bin));
    }
    let slice = |acc: &gltf::Accessor<'_>| -> &[u8] {
        let view = acc.view().unwrap();
        let size = acc.size();
        let start = view.offset() + acc.offset();
        assert_eq!(start % acc.data_type().size(), 0, "misaligned accessor");
        assert_eq!(view.offset() % 4, 0, "views start on 4-byte boundaries");
        if view.target() == Some(gltf::buffer::Target::ArrayBuffer) {
            assert_eq!(start % 4, 0, "vertex attributes start on 4-byte boundaries");
            // Read back to back below: the arrays read here are not interleaved.
            assert_eq!(
                view.stride().unwrap_or(size),
                size,
                "stride of {size}-byte elements"
            );
        }
        let end = start + acc.count() * size;
        assert!(acc.offset() + acc.count() * size <= view.length());
        assert!(view.offset() + view.length() <= blob.len());
        &blob[start..end]
    };
    let floats = |acc: &gltf::Accessor<'_>| -> Vec<f32> {
        assert_eq!(acc.data_type(), DataType::F32);
        slice(acc)
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let mut prims = Vec::new();
    let mut tangent_prims = 0;
    for mesh in gltf.meshes() {
        let mut out = Vec::new();
        for p in mesh.primitives() {
            assert_eq!(p.mode(), gltf::mesh::Mode::Triangles);
            let pos = p.get(&gltf::Semantic::Positions).unwrap();
            let nrm = p.get(&gltf::Semantic::Normals).unwrap();
            // Written only for materials that use them.
            let uv = p.get(&gltf::Semantic::TexCoords(0));
            let idx = p.indices().unwrap();
            assert_eq!(pos.dimensions(), Dimensions::Vec3);
            assert_eq!(nrm.dimensions(), Dimensions::Vec3);
            if let Some(uv) = &uv {
                assert_eq!(uv.dimensions(), Dimensions::Vec2);
            }
            assert_eq!(idx.dimensions(), Dimensions::Scalar);
            let n = pos.count();
            assert!(n > 0 && nrm.count() == n && uv.as_ref().is_none_or(|uv| uv.count() == n));
            let positions: Vec<[f32; 3]> = floats(&pos)
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect();
            let normals: Vec<[f32; 3]> = floats(&nrm)
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]])
                .collect();
            let uvs: Vec<[f32; 2]> = uv
                .as_ref()
                .map(|uv| floats(uv).chunks_exact(2).map(|c| [c[0], c[1]]).collect())
                .unwrap_or_default();
            // Bounds.
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for q in &positions {
                for k in 0..3 {
                    lo[k] = lo[k].min(q[k]);
                    hi[k] = hi[k].max(q[k]);
                }
            }
            let as_f32 = |v: serde_json::Value| -> Vec<f32> {
                v.as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap() as f32)
                    .collect()
            };
            assert_eq!(as_f32(pos.min().unwrap()), lo.to_vec(), "POSITION min");
            assert_eq!(as_f32(pos.max().unwrap()), hi.to_vec(), "POSITION max");
            for q in &normals {
                let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                assert!((l - 1.0).abs() < 1e-5, "normal of length {l}");
            }
            if let Some(tan) = p.get(&gltf::Semantic::Tangents) {
                assert_eq!(tan.dimensions(), Dimensions::Vec4);
                assert_eq!(tan.count(), n);
                let t = floats(&tan);
                for (q, nr) in t.chunks_exact(4).zip(&normals) {
                    let l = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
                    assert!((l - 1.0).abs() < 1e-5, "tangent of length {l}");
                    assert!(q[3] == 1.0 || q[3] == -1.0, "handedness {}", q[3]);
                    let dot = q[0] * nr[0] + q[1] * nr[1] + q[2] * nr[2];
                    assert!(dot.abs() < 1e-4, "tangent not orthogonal to the normal");
                }
                tangent_prims += 1;
            }
            let raw = slice(&idx);
            let (indices, wide): (Vec<u32>, bool) = match idx.data_type() {
                DataType::U16 => (
                    raw.chunks_exact(2)
                        .map(|c| u32::from(u16::from_le_bytes([c[0], c[1]])))
                        .collect(),
                    false,
                ),
                DataType::U32 => (
                    raw.chunks_exact(4)
                        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                        .collect(),
                    true,
                ),
                other => panic!("index type {other:?}"),
            };
            assert_eq!(wide, n > 65_535, "u16 indices exactly when they fit");
            assert!(indices.len() % 3 == 0 && !indices.is_empty());
            assert!(
                indices.iter().all(|&i| (i as usize) < n),
                "index out of range"
            );
            assert!(!wide || indices.iter().all(|&i| i != u32::MAX));
            out.push(Prim {
                positions,
                normals,
                uvs,
                indices,
                wide,
                material: p.material().index(),
            });
        }
        prims.push(out);
    }
    for img in gltf.images() {
        match img.source() {
            gltf::image::Source::View { view, mime_type } => {
                assert_eq!(mime_type, "image/png");
                let bytes = &blob[view.offset()..view.offset() + view.length()];
                let decoder = png::Decoder::new(std::io::Cursor::new(bytes.to_vec()));
                decoder.read_info().expect("embedded image decodes as PNG");
            }
            gltf::image::Source::Uri { .. } => panic!("images must be embedded"),
        }
    }
    let node_info = gltf
        .nodes()
        .map(|n| {
            (
                n.name().map(str::to_string),
                n.mesh().map(|m| m.index()),
                n.children().map(|c| c.index()).collect(),
                extras(n.extras()),
            )
        })
        .collect();
    let mesh_extras = gltf.meshes().map(|m| extras(m.extras())).collect();
    let roots = gltf
        .default_scene()
        .map(|s| s.nodes().map(|n| n.index()).collect())
        .unwrap_or_default();
    Decoded {
        nodes: gltf.nodes().count(),
        meshes: gltf.meshes().count(),
        materials: gltf.materials().count(),
        textures: gltf.textures().count(),
        images: gltf.images().count(),
        samplers: gltf.samplers().count(),
        prims,
        node_info,
        mesh_extras,
        roots,
        json,
        tangent_prims,
    }
}

#[cfg(feature = "serde")]
/// The metadata of a node as the JSON object the writers put in `extras`.
pub fn metadata_json(scene: &Scene, node: NodeId) -> Option<serde_json::Value> {
    let m = &scene.nodes[node.index()].metadata;
    (!m.is_empty()).then(|| serde_json::to_value(m).unwrap())
}

/// Triangle count per material over the whole scene as drawn (instances counted).
pub fn drawn_triangles(scene: &Scene) -> BTreeMap<Option<MaterialId>, usize> {
    let mut out = BTreeMap::new();
    for n in &scene.nodes {
        for m in &n.meshes {
            let mesh = &scene.meshes[m.index()];
            *out.entry(mesh.material).or_insert(0) += mesh.triangle_count();
        }
    }
    out
}

/// A map with every layer: water with an island (hole), a clockwise park, blocks, lots,
/// roads of every class including a bridge and an oddly named class, footprints of every
/// kind.
pub fn sample_map() -> crate::map::MapLayers {
    use crate::map::*;
    use polis_geom::PolygonWithHoles;
    let rect = |x0: f64, y0: f64, x1: f64, y1: f64| -> PolygonWithHoles {
        Polygon::rect(DVec2::new(x0, y0), DVec2::new(x1, y1)).into()
    };
    let mut m = MapLayers::default();
    let mut island = Polygon::rect(DVec2::new(210.0, 20.0), DVec2::new(230.0, 40.0));
    island.make_cw();
    m.water.push(PolygonWithHoles::new(
        Polygon::rect(DVec2::new(200.0, 0.0), DVec2::new(260.0, 100.0)),
        vec![island],
    ));
    let mut park = Polygon::regular(7, DVec2::new(50.0, 150.0), 20.0);
    park.make_cw();
    m.parks.push(park.into());
    for b in 0..2u64 {
        let x = b as f64 * 100.0;
        m.blocks.push(MapBlock {
            id: 10 + b,
            polygon: rect(x + 5.0, 5.0, x + 95.0, 95.0),
        });
        for l in 0..3u64 {
            let lx = x + 5.0 + l as f64 * 30.0;
            m.lots.push(MapLot {
                id: 100 + 3 * b + l,
                block: (b == 0).then_some(10 + b),
                polygon: rect(lx, 5.0, lx + 30.0, 50.0),
            });
            let kind = match (b * 3 + l) % 5 {
                0 => BuildingKind::Residential,
                1 => BuildingKind::Commercial,
                2 => BuildingKind::Industrial,
                3 => BuildingKind::Skyscraper,
                _ => BuildingKind::Other("church & <hall>".into()),
            };
            m.footprints.push(MapFootprint {
                id: 1000 + 3 * b + l,
                polygon: rect(lx + 5.0, 10.0, lx + 25.0, 40.0),
                kind,
                height_m: 6.0 + l as f64 * 3.5,
                floors: Some(2 + l as u32),
                lot: Some(100 + 3 * b + l),
            });
        }
    }
    let road = |id: u64, pts: &[(f64, f64)], class: RoadClass, w: f64, bridge: bool| MapRoad {
        id,
        points: pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
        class,
        width_m: w,
        bridge,
        tunnel: false,
        profile: None,
    };
    m.roads.push(road(
        1,
        &[(0.0, 100.0), (300.0, 100.0)],
        RoadClass::Highway,
        16.0,
        false,
    ));
    m.roads.push(road(
        2,
        &[(190.0, 50.0), (270.0, 50.0)],
        RoadClass::Major,
        12.0,
        true,
    ));
    m.roads.push(road(
        3,
        &[(100.0, 0.0), (100.0, 100.0)],
        RoadClass::Street,
        8.0,
        false,
    ));
    m.roads.push(road(
        4,
        &[(0.0, 0.0), (50.0, 2.5), (100.0, 0.0)],
        RoadClass::Footpath,
        2.0,
        false,
    ));
    m.roads.push(road(
        5,
        &[(-10.0, -10.0), (-10.0, 60.0)],
        RoadClass::Other("tram \"line\"".into()),
        3.0,
        false,
    ));
    m.validate().unwrap();
    m
}

/// A minimal XML well-formedness check: one root element, properly nested tags,
/// attributes `name="value"` without duplicates, no raw `<` in values, entities limited to
/// the five predefined ones, only whitespace and comments outside elements, and the XML
/// declaration first. Returns the element names in document order with their attributes.
pub fn check_xml(text: &str) -> Vec<(String, Vec<(String, String)>)> {
    let mut elements = Vec::new();
    let mut stack: Vec<String> = Vec::new();
    let mut roots = 0;
    let mut rest = text;
    assert!(rest.starts_with("<?xml "), "declaration first");
    let end = rest.find("?>").unwrap();
    rest = &rest[end + 2..];
    let check_text = |t: &str, inside: bool| {
        if !inside {
            assert!(t.trim().is_empty(), "text outside the root: {t:?}");
        }
        assert!(!t.contains('>') || inside, "stray '>'");
        check_entities(t);
    };
    while !rest.is_empty() {
        let lt = rest.find('<').unwrap_or(rest.len());
        check_text(&rest[..lt], !stack.is_empty());
        rest = &rest[lt..];
        if rest.is_empty() {
            break;
        }
        if let Some(r) = rest.strip_prefix("<!--") {
            let e = r.find("-->").expect("closed comment");
            assert!(!r[..e].contains("--"), "'--' inside a comment");
            rest = &r[e + 3..];
            continue;
        }
        let gt = rest.find('>').expect("closed tag");
        let tag = &rest[1..gt];
        rest = &rest[gt + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack.pop().expect("close without open");
            assert_eq!(open, name.trim(), "mismatched close tag");
            continue;
        }
        let (body, self_closing) = match tag.strip_suffix('/') {
            Some(b) => (b, true),
            None => (tag, false),
        };
        let name_end = body.find(char::is_whitespace).unwrap_or(body.len());
        let name = &body[..name_end];
        assert!(
            !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == ':'),
            "element name {name:?}"
        );
        let mut attrs: Vec<(String, String)> = Vec::new();
        let mut a = body[name_end..].trim_start();
        while !a.is_empty() {
            let eq = a.find('=').expect("attribute has a value");
            let key = a[..eq].trim();
            assert!(
                key.chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | ':' | '_')),
                "attribute name {key:?}"
            );
            let v = &a[eq + 1..];
            assert!(v.starts_with('"'), "quoted value");
            let close = v[1..].find('"').expect("closed value") + 1;
            let value = &v[1..close];
            assert!(!value.contains('<'), "raw '<' in a value");
            check_entities(value);
            assert!(
                attrs.iter().all(|(k, _)| k != key),
                "duplicate attribute {key}"
            );
            attrs.push((key.to_string(), value.to_string()));
            let after = &v[close + 1..];
            assert!(
                after.is_empty() || after.starts_with(char::is_whitespace),
                "attributes separated by space"
            );
            a = after.trim_start();
        }
        if stack.is_empty() {
            roots += 1;
        }
        elements.push((name.to_string(), attrs));
        if !self_closing {
            stack.push(name.to_string());
        }
    }
    assert!(stack.is_empty(), "unclosed {stack:?}");
    assert_eq!(roots, 1, "exactly one root element");
    elements
}

fn check_entities(t: &str) {
    let mut s = t;
    while let Some(i) = s.find('&') {
        let r = &s[i..];
        assert!(
            ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
                .iter()
                .any(|e| r.starts_with(e)),
            "bad entity in {t:?}"
        );
        s = &r[1..];
    }
}
