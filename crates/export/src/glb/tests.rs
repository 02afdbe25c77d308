use super::*;
use crate::testing::{decode_glb, drawn_triangles, grid_scene, metadata_json, sample_scene};
use polis_geom::Mesh;
use polis_geom::glam::{DQuat, DVec3, Vec2};
use polis_geom::scene::{MeshId, NodeId};

fn glb(scene: &Scene, batching: Batching) -> (Vec<u8>, GlbReport) {
    let mut out = Vec::new();
    let report = write_glb(scene, &GlbOptions::with_batching(batching), &mut out).unwrap();
    assert_eq!(report.bytes as usize, out.len());
    (out, report)
}

#[test]
fn per_node_reads_back_with_counts_bounds_and_extras() {
    let scene = sample_scene();
    let (bytes, report) = glb(&scene, Batching::PerNode);
    let d = decode_glb(&bytes);
    assert_eq!(d.nodes, scene.nodes.len());
    // The scene's third material is drawn by nothing: left out.
    assert_eq!(d.materials, 2);
    assert_eq!(report.materials, 2);
    assert_eq!(d.textures, 2);
    assert_eq!(d.images, 2);
    assert_eq!(d.samplers, 2, "two distinct samplers");
    // glTF meshes: city (plain), houses 0 and 2 (house+roof, shared), house 1 (house only),
    // mirror (house only, shares with house 1).
    assert_eq!(d.meshes, 3);
    assert_eq!(report.meshes, 3);
    assert_eq!(report.skipped_empty_meshes, 1);
    assert_eq!(report.unused_meshes, 0);
    // Each scene mesh stored once: plain, house, roof.
    assert_eq!(
        report.triangles,
        scene.meshes.iter().map(Mesh::triangle_count).sum::<usize>()
    );
    assert_eq!(d.roots, vec![0]);
    for (i, node) in scene.nodes.iter().enumerate() {
        let (name, _mesh, children, extras) = &d.node_info[i];
        assert_eq!(name.as_deref(), Some(node.name.as_str()));
        let expect: Vec<usize> = node.children.iter().map(|c| c.index()).collect();
        assert_eq!(children, &expect);
        assert_eq!(extras, &metadata_json(&scene, NodeId(i as u32)));
    }
    assert_eq!(
        d.node_info[2].1, d.node_info[4].1,
        "houses 0 and 2 share a mesh"
    );
    assert_eq!(
        d.node_info[3].1, d.node_info[5].1,
        "house 1 and mirror share a mesh"
    );
    assert_eq!(d.node_info[6].1, None, "an empty group has no mesh");
    // Only the normal-mapped brick geometry (one, shared) has tangents.
    assert_eq!(
        d.tangent_prims, 2,
        "house prism in the two meshes that draw it"
    );
    // Geometry equals the scene's, bit for bit (normals renormalised).
    let house = &scene.meshes[0];
    let prim = &d.prims[d.node_info[2].1.unwrap()][0];
    assert_eq!(
        prim.positions,
        house
            .positions
            .iter()
            .map(|p| p.to_array())
            .collect::<Vec<_>>()
    );
    assert_eq!(
        prim.uvs,
        house.uvs.iter().map(|p| p.to_array()).collect::<Vec<_>>()
    );
    assert_eq!(prim.indices, house.indices);
    assert_eq!(prim.material, Some(0));
    assert!(!prim.wide);
    // Material details.
    let mats = &d.json["materials"];
    assert_eq!(
        mats[0]["pbrMetallicRoughness"]["baseColorTexture"]["index"],
        0
    );
    assert_eq!(mats[0]["normalTexture"]["index"], 1);
    assert_eq!(mats[1]["alphaMode"], "BLEND");
    assert_eq!(mats[1]["doubleSided"], true);
    assert_eq!(mats[0]["name"], "brick wall");
    // Transforms: block TRS; mirror matrix decomposed to a negative scale.
    let nodes = &d.json["nodes"];
    assert_eq!(nodes[1]["scale"], serde_json::json!([2.0, 2.0, 2.0]));
    assert!(nodes[1]["rotation"].is_array());
    assert_eq!(nodes[5]["scale"][0], -1.0);
    assert!(nodes[5].get("matrix").is_none());
}

#[test]
fn output_is_byte_identical_and_matches_the_gltf_writer() {
    let scene = sample_scene();
    let (a, _) = glb(&scene, Batching::PerNode);
    let (b, _) = glb(&scene.clone(), Batching::PerNode);
    assert_eq!(a, b);
    let (c, _) = glb(&scene, Batching::PerParentAndMaterial);
    let (d, _) = glb(&scene, Batching::PerParentAndMaterial);
    assert_eq!(c, d);
    assert_ne!(a, c);
}

#[test]
fn batching_merges_leaves_per_material_and_keeps_their_metadata() {
    let n = 25;
    let scene = grid_scene(n);
    let (bytes, report) = glb(&scene, Batching::PerParentAndMaterial);
    let d = decode_glb(&bytes);
    // city + cell; the boxes are merged into the cell's mesh.
    assert_eq!(d.nodes, 2);
    assert_eq!(d.meshes, 1);
    assert_eq!(d.prims[0].len(), 2, "one primitive per material");
    assert_eq!(report.primitives, 2);
    let per_mat = drawn_triangles(&scene);
    for p in &d.prims[0] {
        let key = p.material.map(|m| polis_geom::scene::MaterialId(m as u32));
        assert_eq!(p.indices.len() / 3, per_mat[&key]);
    }
    // Object table: one entry per box with its metadata and triangle ranges.
    let objects = d.mesh_extras[0].as_ref().unwrap()["objects"]
        .as_array()
        .unwrap()
        .clone();
    assert_eq!(objects.len(), n);
    let mut covered = [0usize; 2];
    for (i, o) in objects.iter().enumerate() {
        assert_eq!(o["name"], format!("box {i}"));
        assert_eq!(o["metadata"]["index"], i as f64);
        for r in o["ranges"].as_array().unwrap() {
            let (p, first, count) = (
                r[0].as_u64().unwrap() as usize,
                r[1].as_u64().unwrap() as usize,
                r[2].as_u64().unwrap() as usize,
            );
            assert_eq!(first, covered[p], "ranges tile the primitive in order");
            covered[p] += count;
        }
    }
    for (p, c) in d.prims[0].iter().zip(covered) {
        assert_eq!(p.indices.len() / 3, c);
    }
    // Positions are the boxes' in the cell's frame: box 11 sits at (4, 0, 4).
    let o = &objects[11]["ranges"][0];
    let p = &d.prims[0][o[0].as_u64().unwrap() as usize];
    let first = o[1].as_u64().unwrap() as usize;
    let v = p.positions[p.indices[3 * first] as usize];
    assert!(
        v[0] >= 4.0 && v[2] <= 4.0 + 1e-6 && v[2] >= 2.0 - 1e-6,
        "{v:?}"
    );
}

#[test]
fn batching_keeps_interior_nodes_and_transforms_leaves() {
    let scene = sample_scene();
    let (bytes, _) = glb(&scene, Batching::PerParentAndMaterial);
    let d = decode_glb(&bytes);
    // city, block 1, empty group kept; the three houses and the mirror merged.
    assert_eq!(d.nodes, 3);
    let names: Vec<_> = d.node_info.iter().map(|n| n.0.clone().unwrap()).collect();
    assert_eq!(names, ["city", "block 1", "empty group"]);
    assert_eq!(d.node_info[0].2, vec![1, 2]);
    // The city's mesh: its own plain slab plus the mirror's house (brick) → 2 primitives.
    let city_mesh = d.node_info[0].1.unwrap();
    assert_eq!(d.prims[city_mesh].len(), 2);
    // The block's mesh: 3 houses (brick) + 2 roofs (glass).
    let block_mesh = d.node_info[1].1.unwrap();
    let tris: Vec<usize> = d.prims[block_mesh]
        .iter()
        .map(|p| p.indices.len() / 3)
        .collect();
    let house = scene.meshes[0].triangle_count();
    let roof = scene.meshes[1].triangle_count();
    assert_eq!(tris, vec![3 * house, 2 * roof]);
    // The mirrored house keeps counter-clockwise front faces: the face normals agree with
    // the stored normals.
    let mirror = d.prims[city_mesh]
        .iter()
        .find(|p| p.material == Some(0))
        .unwrap();
    for t in mirror.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| Vec3::from(mirror.positions[i as usize]));
        let face = (b - a).cross(c - a).normalize();
        let n = Vec3::from(mirror.normals[t[0] as usize]);
        assert!(face.dot(n) > 0.99, "winding flipped under mirroring");
        assert!(a.x <= -30.0 + 1e-4, "mirrored to x ≤ −30");
    }
}

#[test]
fn large_meshes_use_u32_indices() {
    let mut scene = Scene::new();
    let mut mesh = Mesh::new(None);
    // 70,000 vertices in a strip of triangles.
    for i in 0..35_000u32 {
        let x = f64::from(i) * 0.01;
        mesh.add_vertex(DVec3::new(x, 0.0, 0.0), DVec3::Y, polis_geom::DVec2::ZERO);
        mesh.add_vertex(DVec3::new(x, 0.0, 1.0), DVec3::Y, polis_geom::DVec2::ZERO);
        if i > 0 {
            let (a, b, c, e) = (2 * i - 2, 2 * i - 1, 2 * i, 2 * i + 1);
            mesh.push_triangle(a, b, c).unwrap();
            mesh.push_triangle(c, b, e).unwrap();
        }
    }
    let id = scene.add_mesh(mesh);
    let root = scene.add_root("strip");
    scene.attach_mesh(root, id).unwrap();
    let (bytes, _) = glb(&scene, Batching::PerNode);
    let d = decode_glb(&bytes);
    assert!(d.prims[0][0].wide);
    assert_eq!(d.prims[0][0].indices, scene.meshes[0].indices);
}

#[test]
fn invalid_scenes_are_never_written() {
    let mut out = Vec::new();
    let mut s = sample_scene();
    s.meshes[0].positions[0].x = f32::NAN;
    let e = write_glb(&s, &GlbOptions::default(), &mut out).unwrap_err();
    assert!(matches!(e, ExportError::InvalidScene(_)), "{e}");
    let mut s = sample_scene();
    s.meshes[1].indices[4] = 9999;
    assert!(matches!(
        write_glb(&s, &GlbOptions::default(), &mut out),
        Err(ExportError::InvalidScene(_))
    ));
    let mut s = sample_scene();
    s.nodes[3].meshes.push(MeshId(40));
    assert!(write_glb(&s, &GlbOptions::default(), &mut out).is_err());
    let mut s = sample_scene();
    s.set_metadata(NodeId(2), "height", f64::NAN).unwrap();
    assert!(write_glb(&s, &GlbOptions::default(), &mut out).is_err());
    assert!(out.is_empty(), "nothing was written");
}

#[test]
fn io_errors_are_typed() {
    struct Failing;
    impl Write for Failing {
        fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
            Err(std::io::Error::other("disk full"))
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let e = write_glb(&sample_scene(), &GlbOptions::default(), Failing).unwrap_err();
    assert!(matches!(e, ExportError::Io { .. }));
    assert!(e.to_string().contains("disk full"));
}

#[test]
fn empty_scene_is_a_valid_glb_without_buffer() {
    let (bytes, report) = glb(&Scene::new(), Batching::PerNode);
    let d = decode_glb(&bytes);
    assert_eq!((d.nodes, d.meshes, report.triangles), (0, 0, 0));
    assert!(d.json.get("buffers").is_none());
    let mut scene = Scene::new();
    scene.add_root("alone");
    let (bytes, _) = glb(&scene, Batching::PerParentAndMaterial);
    assert_eq!(decode_glb(&bytes).nodes, 1);
}

#[test]
fn transforms_map_to_trs_or_matrix() {
    let mut node = json::Node::default();
    set_transform(&mut node, &Transform::IDENTITY);
    assert!(node.translation.is_none() && node.rotation.is_none() && node.scale.is_none());
    let q = DQuat::from_rotation_z(1.0);
    let m = DMat4::from_scale_rotation_translation(DVec3::new(1.0, 2.0, 3.0), q, DVec3::X);
    let mut node = json::Node::default();
    set_transform(&mut node, &Transform::Matrix(m));
    assert!(node.matrix.is_none());
    let r = node.rotation.unwrap().0;
    assert!((r[2] - q.z as f32).abs() < 1e-6 && (r[3] - q.w as f32).abs() < 1e-6);
    assert_eq!(node.scale, Some([1.0, 2.0, 3.0]));
    // A shear is not a TRS: written as a matrix.
    let mut shear = DMat4::IDENTITY;
    shear.y_axis.x = 0.5;
    let mut node = json::Node::default();
    set_transform(&mut node, &Transform::Matrix(shear));
    assert_eq!(node.matrix.unwrap()[4], 0.5);
    assert!(node.translation.is_none());
}

#[test]
fn texture_coordinates_pass_through() {
    let mut scene = Scene::new();
    let mut m = Mesh::new(None);
    m.add_triangle(
        [DVec3::ZERO, DVec3::X, DVec3::Z * -1.0],
        [
            polis_geom::DVec2::ZERO,
            polis_geom::DVec2::X,
            polis_geom::DVec2::new(0.0, -1.0),
        ],
    )
    .unwrap();
    let id = scene.add_mesh(m);
    let r = scene.add_root("t");
    scene.attach_mesh(r, id).unwrap();
    let (bytes, _) = glb(&scene, Batching::PerNode);
    let d = decode_glb(&bytes);
    // The default material has no texture: no TEXCOORD_0.
    assert!(d.prims[0][0].uvs.is_empty());
    // A material that keeps its coordinates (or has a texture) gets them unchanged.
    let keep = scene.add_material(polis_geom::Material {
        keep_texture_coordinates: true,
        ..polis_geom::Material::new("road", [0.2, 0.2, 0.2, 1.0])
    });
    scene.meshes[0].material = Some(keep);
    let (bytes, _) = glb(&scene, Batching::PerNode);
    let d = decode_glb(&bytes);
    let uvs: Vec<Vec2> = d.prims[0][0].uvs.iter().map(|&u| Vec2::from(u)).collect();
    assert_eq!(uvs, vec![Vec2::ZERO, Vec2::X, Vec2::new(0.0, -1.0)]);
}

/// Only used materials, textures and images are written, renumbered, and texture
/// coordinates only where the material uses them: what the glTF validator checks.
#[test]
fn unused_objects_and_texture_coordinates_are_left_out() {
    let mut scene = sample_scene();
    // An image and texture only an unused material refers to.
    let lonely_image = scene.add_image(polis_geom::scene::Image {
        name: "lonely".into(),
        data: polis_geom::scene::ImageData::Rgba8 {
            width: 3,
            height: 5,
            pixels: vec![128; 60],
        },
    });
    let lonely = scene
        .add_texture(polis_geom::scene::Texture {
            name: "lonely".into(),
            image: lonely_image,
            ..Default::default()
        })
        .unwrap();
    scene.add_material(polis_geom::Material {
        base_color_texture: Some(lonely),
        ..polis_geom::Material::new("unused", [1.0; 4])
    });
    for batching in [Batching::PerNode, Batching::PerParentAndMaterial] {
        let (bytes, report) = glb(&scene, batching);
        let doc = gltf::Gltf::from_slice(&bytes).unwrap();
        assert_eq!(
            (report.materials, report.textures, report.images),
            (2, 2, 2)
        );
        let mut used = vec![false; doc.materials().count()];
        for p in doc
            .meshes()
            .flat_map(|m| m.primitives().collect::<Vec<_>>())
        {
            let m = p.material();
            if let Some(i) = m.index() {
                used[i] = true;
            }
            let textured = m.pbr_metallic_roughness().base_color_texture().is_some();
            assert_eq!(p.get(&gltf::Semantic::TexCoords(0)).is_some(), textured);
            if textured {
                assert!(p.get(&gltf::Semantic::Tangents).is_some());
            }
        }
        assert!(used.iter().all(|&u| u));
        assert!(doc.images().all(|i| i.name() != Some("lonely")));
        assert!(
            doc.textures()
                .all(|t| t.source().index() < doc.images().count())
        );
    }
}
