//! Property tests: random small scenes and maps, biased towards degenerate cases (empty
//! meshes, nodes without meshes, mirroring and tiny/huge scales, coordinates far from the
//! origin, clockwise rings, one-segment roads), export and read back.

use polis_geom::glam::{DQuat, DVec3};
use polis_geom::mesh::prism;
use polis_geom::scene::{Material, MaterialId, Scene, Transform};
use polis_geom::{DVec2, Mesh, Polygon, PolygonWithHoles};
use proptest::prelude::*;

use crate::glb::{Batching, GlbOptions, write_glb};
use crate::map::{BuildingKind, MapFootprint, MapLayers, MapRoad, RoadClass};
use crate::obj::{ObjOptions, write_obj};
use crate::sink::MemorySink;
use crate::testing::{check_xml, decode_glb, drawn_triangles};

#[derive(Debug, Clone)]
enum Shape {
    Box { w: f64, d: f64, h: f64 },
    Ngon { n: usize, r: f64, h: f64 },
    Triangle([[f64; 3]; 3]),
    Empty,
}

fn shape() -> impl Strategy<Value = Shape> {
    let len = prop_oneof![Just(1e-2), 0.5..50.0f64, Just(1e3)];
    prop_oneof![
        3 => (len.clone(), len.clone(), len.clone()).prop_map(|(w, d, h)| Shape::Box { w, d, h }),
        2 => (3usize..9, len.clone(), len).prop_map(|(n, r, h)| Shape::Ngon { n, r, h }),
        2 => prop::array::uniform3(prop::array::uniform3(-100.0..100.0f64)).prop_map(Shape::Triangle),
        1 => Just(Shape::Empty),
    ]
}

fn build(shape: &Shape, offset: f64, material: Option<MaterialId>) -> Mesh {
    let o = DVec2::splat(offset);
    match *shape {
        Shape::Box { w, d, h } => prism(
            &Polygon::rect(o, o + DVec2::new(w, d)).into(),
            0.0,
            h,
            material,
        )
        .unwrap(),
        Shape::Ngon { n, r, h } => {
            prism(&Polygon::regular(n, o, r).into(), -h, h, material).unwrap()
        }
        Shape::Triangle(p) => {
            let mut m = Mesh::new(material);
            let p = p.map(|q| DVec3::from(q) + DVec3::new(offset, 0.0, 0.0));
            // Collinear random corners are skipped by the builder: an empty mesh then.
            let _ = m.add_triangle(p, [DVec2::ZERO, DVec2::X, DVec2::Y]);
            m
        }
        Shape::Empty => Mesh::new(material),
    }
}

#[derive(Debug, Clone)]
struct NodeSpec {
    parent: usize,
    meshes: Vec<usize>,
    translation: [f64; 3],
    angle: f64,
    scale: f64,
    mirror: bool,
    meta: Option<(String, f64)>,
}

fn node() -> impl Strategy<Value = NodeSpec> {
    (
        any::<usize>(),
        prop::collection::vec(any::<usize>(), 0..3),
        prop::array::uniform3(-1e4..1e4f64),
        -3.2..3.2f64,
        prop_oneof![Just(1.0), Just(1e-3), 0.1..10.0f64],
        prop::bool::weighted(0.2),
        prop::option::of(("[a-z ]{0,6}", -1e6..1e6f64)),
    )
        .prop_map(
            |(parent, meshes, translation, angle, scale, mirror, meta)| NodeSpec {
                parent,
                meshes,
                translation,
                angle,
                scale,
                mirror,
                meta,
            },
        )
}

fn scene() -> impl Strategy<Value = Scene> {
    (
        prop::collection::vec(
            (shape(), prop_oneof![Just(0.0), -1e4..1e4f64], 0usize..4),
            0..5,
        ),
        prop::collection::vec(node(), 1..8),
    )
        .prop_map(|(shapes, nodes)| {
            let mut s = Scene::new();
            let mats = [
                s.add_material(Material::new("a", [0.1, 0.2, 0.3, 1.0])),
                s.add_material(Material::new("b b", [0.9, 0.8, 0.7, 0.5])),
            ];
            let meshes: Vec<_> = shapes
                .iter()
                .map(|(sh, off, m)| s.add_mesh(build(sh, *off, mats.get(*m).copied())))
                .collect();
            let mut ids = Vec::new();
            for (k, spec) in nodes.iter().enumerate() {
                let id = if k == 0 || spec.parent % 4 == 0 {
                    s.add_root(format!("n{k}"))
                } else {
                    s.add_node(ids[spec.parent % ids.len()], format!("n{k}"))
                        .unwrap()
                };
                ids.push(id);
                if !meshes.is_empty() {
                    for &m in &spec.meshes {
                        s.attach_mesh(id, meshes[m % meshes.len()]).unwrap();
                    }
                }
                let sx = if spec.mirror { -spec.scale } else { spec.scale };
                s.node_mut(id).unwrap().transform = Transform::Trs {
                    translation: DVec3::from(spec.translation),
                    rotation: DQuat::from_rotation_y(spec.angle),
                    scale: DVec3::new(sx, spec.scale, spec.scale),
                };
                if let Some((key, value)) = &spec.meta {
                    s.set_metadata(id, key.clone(), *value).unwrap();
                }
            }
            s
        })
}

fn ring() -> impl Strategy<Value = PolygonWithHoles> {
    prop_oneof![
        (
            prop::array::uniform2(-1e5..1e5f64),
            0.01..500.0f64,
            3usize..12,
            any::<bool>()
        )
            .prop_map(|(c, r, n, cw)| {
                let mut p = Polygon::regular(n, DVec2::from(c), r);
                if cw {
                    p.make_cw();
                }
                p.into()
            }),
        // Arbitrary (possibly self-intersecting) rings: writers do not need simplicity.
        prop::collection::vec(prop::array::uniform2(-1e3..1e3f64), 3..8)
            .prop_map(|pts| Polygon::new(pts.into_iter().map(DVec2::from).collect()).into()),
    ]
}

fn map() -> impl Strategy<Value = MapLayers> {
    let class = prop_oneof![
        Just(RoadClass::Highway),
        Just(RoadClass::Major),
        Just(RoadClass::Street),
        Just(RoadClass::Footpath),
        "[a-z<&\" ]{0,5}".prop_map(RoadClass::Other),
    ];
    let kind = prop_oneof![
        Just(BuildingKind::Residential),
        Just(BuildingKind::Skyscraper),
        "[a-z<&' ]{0,5}".prop_map(BuildingKind::Other),
    ];
    (
        prop::collection::vec(ring(), 0..3),
        prop::collection::vec(
            (
                prop::collection::vec(prop::array::uniform2(-1e4..1e4f64), 2..5),
                class,
                prop_oneof![Just(0.0), 0.5..30.0f64],
                any::<bool>(),
            ),
            0..5,
        ),
        prop::collection::vec((ring(), kind, 0.0..300.0f64), 0..5),
    )
        .prop_map(|(water, roads, footprints)| MapLayers {
            water,
            roads: roads
                .into_iter()
                .enumerate()
                .map(|(i, (pts, class, width_m, bridge))| MapRoad {
                    id: i as u64,
                    points: pts.into_iter().map(DVec2::from).collect(),
                    class,
                    width_m,
                    bridge,
                    tunnel: false,
                    profile: None,
                })
                .collect(),
            footprints: footprints
                .into_iter()
                .map(|(p, k, h)| MapFootprint::new(p, k, h))
                .collect(),
            ..MapLayers::default()
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn random_scenes_export_and_read_back(scene in scene()) {
        prop_assume!(scene.validate().is_ok());
        let drawn: usize = drawn_triangles(&scene).values().sum();
        for batching in [Batching::PerNode, Batching::PerParentAndMaterial, Batching::Tiled] {
            let mut a = Vec::new();
            let report = write_glb(&scene, &GlbOptions::with_batching(batching), &mut a).unwrap();
            let d = decode_glb(&a);
            prop_assert_eq!(d.nodes, report.nodes);
            prop_assert_eq!(d.meshes, report.meshes);
            // Exactly the materials some drawn primitive uses.
            let used: std::collections::BTreeSet<usize> =
                d.prims.iter().flatten().filter_map(|p| p.material).collect();
            prop_assert_eq!(d.materials, used.len());
            prop_assert_eq!(report.materials, used.len());
            // Every drawn triangle is drawn once by the glTF node tree.
            let tris = |m: usize| d.prims[m].iter().map(|p| p.indices.len() / 3).sum::<usize>();
            let rendered: usize = d.node_info.iter().filter_map(|n| n.1).map(tris).sum();
            prop_assert_eq!(rendered, drawn);
            if batching == Batching::PerNode {
                prop_assert_eq!(d.nodes, scene.nodes.len());
            } else {
                // Batches are copies: every geometry is drawn exactly once.
                let stored: usize = d.prims.iter().flatten().map(|p| p.indices.len() / 3).sum();
                prop_assert_eq!(stored, report.triangles);
                prop_assert_eq!(stored, drawn);
            }
            let mut b = Vec::new();
            write_glb(&scene, &GlbOptions::with_batching(batching), &mut b).unwrap();
            prop_assert_eq!(a, b);
        }
        let mut obj = Vec::new();
        let mut files = MemorySink::new();
        let report = write_obj(&scene, &ObjOptions::default(), &mut obj, &mut files).unwrap();
        prop_assert_eq!(report.triangles, drawn);
        // Byte for byte the serial `writeln!` writer, with any batch size.
        let reference = crate::obj::tests::reference_obj(&scene, &ObjOptions::default().stem);
        prop_assert_eq!(&obj, &reference);
        let mut small = Vec::new();
        crate::obj::write_obj_in_batches(&crate::SharedScene::new(&scene), &ObjOptions::default(), &mut small, &mut MemorySink::new(), 3).unwrap();
        prop_assert_eq!(&small, &reference);
        if drawn > 0 {
            let (models, _) = crate::obj::tests::load(&obj, &files);
            let tris: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
            prop_assert_eq!(tris, drawn);
            for m in &models {
                let n = m.mesh.positions.len() / 3;
                prop_assert!(m.mesh.indices.iter().all(|&i| (i as usize) < n));
                prop_assert!(m.mesh.positions.iter().all(|x| x.is_finite()));
            }
        }
    }

    #[test]
    fn road_surfaces_are_valid_meshes_that_export(map in map(), tilt in -0.2..0.2f64) {
        let terrain = polis_geom::field::FnField::new(move |p: DVec2| tilt * p.x);
        let mesh = crate::surfaces::road_surfaces(
            &map.roads,
            &terrain,
            &crate::surfaces::RoadSurfaceOptions::default(),
            None,
        )
        .unwrap();
        prop_assert!(mesh.validate().is_ok());
        // Straight roads: the ribbon's area is length × width.
        for r in map.roads.iter().filter(|r| r.points.len() == 2 && r.width_m > 0.0) {
            let flat = crate::surfaces::RoadSurfaceOptions {
                end_cap: crate::surfaces::EndCap::Flat,
                ..Default::default()
            };
            let one = crate::surfaces::road_surfaces(
                std::slice::from_ref(r),
                &polis_geom::field::Constant(0.0),
                &flat,
                None,
            )
            .unwrap();
            let len = (r.points[1] - r.points[0]).length();
            let want = len * r.width_m;
            prop_assert!((one.surface_area() - want).abs() <= 1e-3 * want.max(1.0));
        }
        let mut scene = Scene::new();
        let root = scene.add_root("roads");
        if !mesh.is_empty() {
            let id = scene.add_mesh(mesh);
            scene.attach_mesh(root, id).unwrap();
        }
        let mut bytes = Vec::new();
        write_glb(&scene, &GlbOptions::default(), &mut bytes).unwrap();
        decode_glb(&bytes);
    }

    #[test]
    fn random_maps_give_well_formed_svg_and_geojson(map in map()) {
        let mut svg = Vec::new();
        crate::svg::write_svg(&map, &crate::svg::SvgOptions::default(), &mut svg).unwrap();
        let text = String::from_utf8(svg).unwrap();
        let els = check_xml(&text);
        let paths = els.iter().filter(|e| e.0 == "path").count();
        let bridges = map.roads.iter().filter(|r| r.bridge).count();
        prop_assert_eq!(paths, map.water.len() + map.roads.len() + bridges + map.footprints.len());

        let mut gj = Vec::new();
        let report = crate::geojson::write_geojson(
            &map,
            &crate::geojson::GeoJsonOptions::default(),
            &mut gj,
        )
        .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&gj).unwrap();
        let features = v["features"].as_array().unwrap();
        prop_assert_eq!(features.len(), report.features);
        prop_assert_eq!(features.len(), map.water.len() + map.roads.len() + map.footprints.len());
        for (f, r) in features[map.water.len()..].iter().zip(&map.roads) {
            let c = f["geometry"]["coordinates"].as_array().unwrap();
            prop_assert_eq!(c.len(), r.points.len());
            for (q, p) in c.iter().zip(&r.points) {
                prop_assert_eq!(q[0].as_f64().unwrap(), p.x);
                prop_assert_eq!(q[1].as_f64().unwrap(), p.y);
            }
        }
    }
}
