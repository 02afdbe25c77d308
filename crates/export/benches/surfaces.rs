//! Road surfaces (ribbons + junction polygons + dead-end caps) of a ~15,000-segment
//! network, and footpath meshes of ~7,500 blocks.
//!
//! The network is an 88 × 88 grid of nodes 60 m apart, jittered by up to ±12 m (a
//! deterministic hash, no RNG), every 8th row and column a 16 m highway, the rest 8 m
//! streets, 2 % of the segments removed (T-junctions and dead ends), 5 % of the
//! crossings jogged (the roads east and north leave 3 m east of the node, joined to it by
//! a short segment: merged junctions), one two-point road per segment (as the pipeline
//! passes graph edges). Terrain: gentle waves.
//!
//! Run: `cargo bench -p polis-export --bench surfaces`.

#![allow(clippy::unwrap_used)]

use std::sync::LazyLock;

use divan::Bencher;
use divan::counter::ItemsCount;
use polis_export::footpaths::{FootpathOptions, footpath_meshes};
use polis_export::geom::field::FnField;
use polis_export::geom::{DVec2, Polygon, PolygonWithHoles};
use polis_export::map::{MapRoad, RoadClass};
use polis_export::surfaces::{RoadSurfaceOptions, road_surface_parts, road_surfaces_with_report};

fn main() {
    let (mesh, report) =
        road_surfaces_with_report(&ROADS, &terrain(), &RoadSurfaceOptions::default(), None)
            .unwrap();
    println!(
        "network: {} segments, {} triangles, {report:?}",
        ROADS.len(),
        mesh.triangle_count()
    );
    let paths = footpath_meshes(&STRIPS, &terrain(), &FootpathOptions::default(), None).unwrap();
    println!(
        "footpaths: {} strips, {} triangles",
        STRIPS.len(),
        paths.triangle_count()
    );
    divan::main();
}

const N: usize = 88;
const SPACING: f64 = 60.0;

/// A deterministic value in [−1, 1) from two integers.
fn hash(i: usize, j: usize, salt: u64) -> f64 {
    let mut x = (i as u64) << 32 ^ (j as u64) ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    x ^= x >> 33;
    x = x.wrapping_mul(0xFF51_AFD7_ED55_8CCD);
    x ^= x >> 33;
    x = x.wrapping_mul(0xC4CE_B9FE_1A85_EC53);
    x ^= x >> 33;
    (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

fn node(i: usize, j: usize) -> DVec2 {
    DVec2::new(
        i as f64 * SPACING + 12.0 * hash(i, j, 1),
        j as f64 * SPACING + 12.0 * hash(i, j, 2),
    )
}

fn terrain() -> FnField<impl Fn(DVec2) -> f64> {
    FnField::new(|p: DVec2| 8.0 * (p.x / 700.0).sin() * (p.y / 900.0).cos())
}

/// Whether the crossing at `(i, j)` is jogged: the roads east and north leave from a
/// point 3 m east, joined to the node by a short segment (a merged junction).
fn jog(i: usize, j: usize) -> bool {
    hash(i, j, 5) > 0.9
}

/// Where the roads east and north of node `(i, j)` start.
fn start(i: usize, j: usize) -> DVec2 {
    node(i, j)
        + if jog(i, j) {
            DVec2::new(3.0, 0.3)
        } else {
            DVec2::ZERO
        }
}

static ROADS: LazyLock<Vec<MapRoad>> = LazyLock::new(|| {
    let mut roads = Vec::new();
    for i in 0..N {
        for j in 0..N {
            if jog(i, j) {
                let mut r = MapRoad::new(vec![node(i, j), start(i, j)], RoadClass::Street, 8.0);
                r.id = roads.len() as u64;
                roads.push(r);
            }
            for (di, dj, salt) in [(1, 0, 3), (0, 1, 4)] {
                let (k, l) = (i + di, j + dj);
                if k >= N || l >= N || hash(i, j, salt) < -0.96 {
                    continue;
                }
                let major = if di == 1 { j % 8 == 0 } else { i % 8 == 0 };
                let (class, width) = if major {
                    (RoadClass::Highway, 16.0)
                } else {
                    (RoadClass::Street, 8.0)
                };
                let mut r = MapRoad::new(vec![start(i, j), node(k, l)], class, width);
                r.id = roads.len() as u64;
                roads.push(r);
            }
        }
    }
    roads
});

/// One footpath strip per grid cell: a 44 m square block with a 2.5 m footpath.
static STRIPS: LazyLock<Vec<PolygonWithHoles>> = LazyLock::new(|| {
    let mut strips = Vec::new();
    for i in 0..N - 1 {
        for j in 0..N - 1 {
            let o = DVec2::new(i as f64 * SPACING + 8.0, j as f64 * SPACING + 8.0);
            let outer = Polygon::rect(o, o + DVec2::splat(44.0));
            let mut inner = Polygon::rect(o + DVec2::splat(2.5), o + DVec2::splat(41.5));
            inner.make_cw();
            strips.push(PolygonWithHoles::new(outer, vec![inner]));
        }
    }
    strips
});

#[divan::bench(sample_count = 10)]
fn road_surfaces_15k(b: Bencher<'_, '_>) {
    let field = terrain();
    b.counter(ItemsCount::new(ROADS.len())).bench(|| {
        road_surfaces_with_report(&ROADS, &field, &RoadSurfaceOptions::default(), None).unwrap()
    });
}

#[divan::bench(sample_count = 10)]
fn road_surface_parts_15k(b: Bencher<'_, '_>) {
    let field = terrain();
    b.counter(ItemsCount::new(ROADS.len()))
        .bench(|| road_surface_parts(&ROADS, &field, &RoadSurfaceOptions::default()).unwrap());
}

#[divan::bench(sample_count = 10)]
fn footpaths_7569_blocks(b: Bencher<'_, '_>) {
    let field = terrain();
    b.counter(ItemsCount::new(STRIPS.len()))
        .bench(|| footpath_meshes(&STRIPS, &field, &FootpathOptions::default(), None).unwrap());
}
