//! Textured roads and footpaths (Kelly §4.4.1, §5.4): every road ribbon, junction plate
//! and pavement primitive of the scene has a textured PBR material and valid texture
//! coordinates, ribbons carry their class's markings across their width, and the glb
//! keeps the coordinates.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis::CityConfig;
use polis::geom::Scene;

fn textured(scene: &Scene, mesh: &polis::geom::Mesh) -> bool {
    mesh.material
        .and_then(|m| scene.materials.get(m.index()))
        .is_some_and(|m| {
            m.base_color_texture.is_some()
                && m.normal_texture.is_some()
                && m.metallic_roughness_texture.is_some()
        })
}

#[test]
fn every_road_and_footpath_primitive_is_textured_with_valid_uvs() {
    let mut c = CityConfig::preset("default").unwrap();
    c.size_m = 700.0;
    c.roads.max_segments = 120;
    let city = polis::generate(&c).unwrap();
    let scene = &city.scene;
    let roads = scene.nodes.iter().find(|n| n.name == "roads").unwrap();
    assert!(roads.meshes.len() >= 2, "ribbons and junction plates apart");
    let mut names = Vec::new();
    for &id in &roads.meshes {
        let mesh = &scene.meshes[id.index()];
        assert!(textured(scene, mesh));
        mesh.validate().unwrap();
        assert_eq!(mesh.uvs.len(), mesh.positions.len());
        assert!(mesh.uvs.iter().all(|uv| uv.is_finite()));
        let name = scene.materials[mesh.material.unwrap().index()].name.clone();
        if name != "street asphalt" {
            // Ribbons: v across the road from 0 (right edge) to 1 (left edge).
            assert!(
                mesh.uvs.iter().all(|uv| (-1e-4..=1.0001).contains(&uv.y)),
                "{name}"
            );
        }
        names.push(name);
    }
    assert!(names.iter().any(|n| n == "street asphalt"), "{names:?}");
    assert!(names.iter().any(|n| n == "street street"), "{names:?}");
    // Pavements and footpaths (block plinths) are paved.
    let mut plinths = 0;
    for n in scene.nodes.iter().filter(|n| n.name.starts_with("block ")) {
        for &id in &n.meshes {
            let mesh = &scene.meshes[id.index()];
            assert!(textured(scene, mesh));
            assert_eq!(mesh.uvs.len(), mesh.positions.len());
            plinths += 1;
        }
    }
    assert!(plinths > 0);
    // The glb writes TEXCOORD_0 on every road primitive and references the textures.
    let mut glb = Vec::new();
    city.write_glb(&mut glb).unwrap();
    let doc = polis::export::gltf::Gltf::from_slice(&glb).unwrap();
    let mut road_prims = 0;
    for mesh in doc.meshes() {
        for p in mesh.primitives() {
            let m = p.material();
            if m.name().is_some_and(|n| n.starts_with("street ")) {
                road_prims += 1;
                assert!(
                    p.get(&polis::export::gltf::Semantic::TexCoords(0))
                        .is_some()
                );
                assert!(m.pbr_metallic_roughness().base_color_texture().is_some());
            }
        }
    }
    assert!(road_prims >= 3);
}
