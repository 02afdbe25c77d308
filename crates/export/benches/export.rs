//! Export throughput: MB/s writing a 1,000,000-triangle scene to glb (per node and
//! batched) and OBJ, and a 10,000-building map to SVG and GeoJSON.
//!
//! Run: `cargo bench -p polis-export --bench export`.

#![allow(clippy::unwrap_used)]

use std::sync::LazyLock;

use divan::Bencher;
use divan::counter::BytesCount;
use polis_export::geom::glam::DVec3;
use polis_export::geom::mesh::prism;
use polis_export::geom::scene::{Material, Transform};
use polis_export::geom::{DVec2, Polygon, Scene};
use polis_export::glb::{Batching, GlbOptions, write_glb};
use polis_export::map::{BuildingKind, MapFootprint, MapLayers, MapRoad, RoadClass};
use polis_export::obj::{ObjOptions, write_obj};
use polis_export::sink::MemorySink;

fn main() {
    divan::main();
}

/// 1,000 buildings under 10 cells, each a distinct 251-gon prism of 1,000 triangles.
static SCENE: LazyLock<Scene> = LazyLock::new(|| {
    let mut s = Scene::new();
    let mats = [
        s.add_material(Material::new("brick", [0.6, 0.3, 0.2, 1.0])),
        s.add_material(Material::new("concrete", [0.7, 0.7, 0.7, 1.0])),
    ];
    let city = s.add_root("city");
    let mut cell = city;
    for i in 0..1000 {
        if i % 100 == 0 {
            cell = s.add_node(city, format!("cell {}", i / 100)).unwrap();
        }
        let poly = Polygon::regular(251, DVec2::new(0.0, 0.0), 5.0 + (i % 7) as f64);
        let mesh = prism(&poly.into(), 0.0, 10.0 + (i % 13) as f64, Some(mats[i % 2])).unwrap();
        assert_eq!(mesh.triangle_count(), 1000);
        let m = s.add_mesh(mesh);
        let b = s.add_node(cell, format!("building {i}")).unwrap();
        s.attach_mesh(b, m).unwrap();
        s.set_metadata(b, "kind", "residential").unwrap();
        s.set_metadata(b, "floors", (i % 9) as f64).unwrap();
        s.node_mut(b).unwrap().transform = Transform::from_translation(DVec3::new(
            (i % 40) as f64 * 30.0,
            0.0,
            -((i / 40) as f64) * 30.0,
        ));
    }
    assert_eq!(s.triangle_count(), 1_000_000);
    s
});

/// 10,000 footprints and 2,000 roads.
static MAP: LazyLock<MapLayers> = LazyLock::new(|| {
    let mut m = MapLayers::default();
    for i in 0..10_000 {
        let o = DVec2::new((i % 100) as f64 * 25.0, (i / 100) as f64 * 25.0);
        let mut f = MapFootprint::new(
            Polygon::rect(o, o + DVec2::new(15.0, 12.0)).into(),
            BuildingKind::Residential,
            9.0,
        );
        f.id = i;
        m.footprints.push(f);
    }
    for i in 0..2_000 {
        let y = (i / 20) as f64 * 25.0 - 4.0;
        let x = (i % 20) as f64 * 125.0;
        let mut r = MapRoad::new(
            vec![
                DVec2::new(x, y),
                DVec2::new(x + 60.0, y),
                DVec2::new(x + 125.0, y),
            ],
            RoadClass::Street,
            8.0,
        );
        r.id = i;
        m.roads.push(r);
    }
    m
});

fn glb_size(batching: Batching) -> u64 {
    write_glb(
        &SCENE,
        &GlbOptions::with_batching(batching),
        std::io::sink(),
    )
    .unwrap()
    .bytes
}

#[divan::bench(sample_count = 5)]
fn glb_per_node(b: Bencher<'_, '_>) {
    let bytes = glb_size(Batching::PerNode);
    b.counter(BytesCount::new(bytes)).bench(|| {
        write_glb(
            &SCENE,
            &GlbOptions::with_batching(Batching::PerNode),
            std::io::sink(),
        )
        .unwrap()
    });
}

#[divan::bench(sample_count = 5)]
fn glb_batched(b: Bencher<'_, '_>) {
    let bytes = glb_size(Batching::PerParentAndMaterial);
    let o = GlbOptions::with_batching(Batching::PerParentAndMaterial);
    b.counter(BytesCount::new(bytes))
        .bench(|| write_glb(&SCENE, &o, std::io::sink()).unwrap());
}

#[divan::bench(sample_count = 5)]
fn glb_into_vec(b: Bencher<'_, '_>) {
    let bytes = glb_size(Batching::PerNode);
    b.counter(BytesCount::new(bytes)).bench(|| {
        let mut v = Vec::with_capacity(bytes as usize);
        write_glb(&SCENE, &GlbOptions::default(), &mut v).unwrap();
        v
    });
}

#[divan::bench(sample_count = 5)]
fn obj(b: Bencher<'_, '_>) {
    let bytes = write_obj(
        &SCENE,
        &ObjOptions::default(),
        std::io::sink(),
        &mut MemorySink::new(),
    )
    .unwrap()
    .bytes;
    b.counter(BytesCount::new(bytes)).bench(|| {
        write_obj(
            &SCENE,
            &ObjOptions::default(),
            std::io::sink(),
            &mut MemorySink::new(),
        )
        .unwrap()
    });
}

#[divan::bench(sample_count = 10)]
fn svg_map(b: Bencher<'_, '_>) {
    let mut out = Vec::new();
    polis_export::svg::write_svg(&MAP, &Default::default(), &mut out).unwrap();
    b.counter(BytesCount::new(out.len())).bench(|| {
        polis_export::svg::write_svg(&MAP, &Default::default(), std::io::sink()).unwrap()
    });
}

#[divan::bench(sample_count = 10)]
fn geojson_map(b: Bencher<'_, '_>) {
    let mut out = Vec::new();
    polis_export::geojson::write_geojson(&MAP, &Default::default(), &mut out).unwrap();
    b.counter(BytesCount::new(out.len())).bench(|| {
        polis_export::geojson::write_geojson(&MAP, &Default::default(), std::io::sink()).unwrap()
    });
}
