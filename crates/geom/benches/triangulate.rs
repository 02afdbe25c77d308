//! Constrained Delaunay triangulation and prism extrusion throughput.
//!
//! Run with `cargo bench -p polis-geom --bench triangulate`.

use divan::counter::ItemsCount;
use divan::{Bencher, black_box};
use polis_geom::mesh::{Facing, Mesh, RefineOptions, prism};
use polis_geom::{DVec2, Polygon, PolygonWithHoles, triangulate};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

fn main() {
    divan::main();
}

/// A random star-shaped polygon around the origin: one vertex per angular sector, random
/// angle within it, random radius in [50, 100] m.
fn star(n: usize, seed: u64) -> Polygon {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    Polygon::new(
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * (i as f64 + 0.9 * rng.random::<f64>()) / n as f64;
                let r = rng.random_range(50.0..100.0);
                DVec2::new(r * a.cos(), r * a.sin())
            })
            .collect(),
    )
}

/// A comb of `teeth` 1 m teeth, 50 m deep: `4·teeth + 2` vertices, long reflex pockets.
fn comb(teeth: usize) -> Polygon {
    let mut pts = Vec::with_capacity(4 * teeth + 2);
    for i in 0..teeth {
        let x = 2.0 * i as f64;
        pts.extend([
            DVec2::new(x, 0.0),
            DVec2::new(x + 1.0, 0.0),
            DVec2::new(x + 1.0, 50.0),
            DVec2::new(x + 2.0, 50.0),
        ]);
    }
    pts.push(DVec2::new(2.0 * teeth as f64, -10.0));
    pts.push(DVec2::new(0.0, -10.0));
    Polygon::new(pts)
}

fn bench_triangulate(bencher: Bencher<'_, '_>, p: PolygonWithHoles) {
    let n: usize = p.rings().map(|(_, r)| r.len()).sum();
    bencher
        .counter(ItemsCount::new(n))
        .bench(|| triangulate(black_box(&p)));
}

/// 10,000-vertex random star (counter: vertices/s, including validation).
#[divan::bench]
fn triangulate_star_10k(bencher: Bencher<'_, '_>) {
    bench_triangulate(bencher, star(10_000, 1).into());
}

/// 10,002-vertex comb (counter: vertices/s, including validation).
#[divan::bench]
fn triangulate_comb_10k(bencher: Bencher<'_, '_>) {
    bench_triangulate(bencher, comb(2_500).into());
}

/// A batch of 64 small seeded polygons of `n` vertices each (convex: on a rotated
/// 12 × 8 m ellipse at random angles, like a junction polygon; star: random angle per
/// sector and radius in [6, 12] m, reflex vertices).
fn small_batch(n: usize, convex: bool) -> Vec<PolygonWithHoles> {
    let mut rng = Pcg64Mcg::seed_from_u64(n as u64 * 2 + u64::from(convex));
    (0..64)
        .map(|k| {
            let centre = DVec2::new(60.0 * k as f64, -35.0 * k as f64);
            let tilt: f64 = rng.random_range(0.0..std::f64::consts::PI);
            let (s, c) = tilt.sin_cos();
            let pts = (0..n)
                .map(|i| {
                    let a =
                        std::f64::consts::TAU * (i as f64 + 0.9 * rng.random::<f64>()) / n as f64;
                    let q = if convex {
                        DVec2::new(12.0 * a.cos(), 8.0 * a.sin())
                    } else {
                        rng.random_range(6.0..12.0) * DVec2::new(a.cos(), a.sin())
                    };
                    centre + DVec2::new(c * q.x - s * q.y, s * q.x + c * q.y)
                })
                .collect();
            Polygon::new(pts).into()
        })
        .collect()
}

fn bench_small(bencher: Bencher<'_, '_>, n: usize, convex: bool) {
    let batch = small_batch(n, convex);
    bencher.counter(ItemsCount::new(batch.len())).bench(|| {
        for p in &batch {
            let _ = black_box(triangulate(black_box(p)));
        }
    });
}

/// Small convex polygons, `n` vertices (counter: polygons/s, including validation).
#[divan::bench(args = [4, 6, 8, 12, 16, 24, 32, 48, 64])]
fn small_convex(bencher: Bencher<'_, '_>, n: usize) {
    bench_small(bencher, n, true);
}

/// Small star-shaped polygons with reflex vertices (counter: polygons/s).
#[divan::bench(args = [6, 8, 12, 16, 24, 32, 48, 64])]
fn small_star(bencher: Bencher<'_, '_>, n: usize) {
    bench_small(bencher, n, false);
}

/// 64 axis-aligned rectangles (co-circular corners: the Delaunay tie).
#[divan::bench]
fn small_rect(bencher: Bencher<'_, '_>) {
    let batch: Vec<PolygonWithHoles> = (0..64)
        .map(|k| {
            let min = DVec2::new(13.0 * k as f64, 0.5 * k as f64);
            Polygon::rect(min, min + DVec2::new(8.0 + 0.25 * k as f64, 20.0)).into()
        })
        .collect();
    bencher.counter(ItemsCount::new(batch.len())).bench(|| {
        for p in &batch {
            let _ = black_box(triangulate(black_box(p)));
        }
    });
}

/// The worst shapes for ear clipping at the direct path's size limit: a comb of 15 teeth
/// (62 vertices, 30 reflex) and a spiral corridor (64 vertices, 32 reflex).
#[divan::bench(args = ["comb_62", "spiral_64"])]
fn small_worst(bencher: Bencher<'_, '_>, shape: &str) {
    let p: PolygonWithHoles = match shape {
        "comb_62" => comb(15),
        _ => spiral(32),
    }
    .into();
    assert!(p.validate().is_ok(), "{shape} is not a valid polygon");
    bencher
        .counter(ItemsCount::new(1usize))
        .bench(|| triangulate(black_box(&p)));
}

/// A spiral corridor 1 m wide, 8 vertices per turn on each wall: `2·points` vertices,
/// the inner wall's all reflex.
fn spiral(points: usize) -> Polygon {
    let at = |k: usize, inset: f64| {
        let a = std::f64::consts::TAU * k as f64 / 8.0;
        (3.0 + a - inset) * DVec2::new(a.cos(), a.sin())
    };
    let outer = (0..points).map(|k| at(k, 0.0));
    let inner = (0..points).rev().map(|k| at(k, 1.0));
    Polygon::new(outer.chain(inner).collect())
}

/// Validation alone on small polygons, to separate its share (counter: polygons/s).
#[divan::bench(args = [6, 12, 24])]
fn small_validate(bencher: Bencher<'_, '_>, n: usize) {
    let batch = small_batch(n, true);
    bencher.counter(ItemsCount::new(batch.len())).bench(|| {
        for p in &batch {
            let _ = black_box(black_box(p).validate());
        }
    });
}

/// Validation alone on the 10,000-vertex star, to separate its share.
#[divan::bench]
fn validate_star_10k(bencher: Bencher<'_, '_>) {
    let p: PolygonWithHoles = star(10_000, 1).into();
    bencher
        .counter(ItemsCount::new(10_000usize))
        .bench(|| black_box(&p).validate());
}

/// A closed prism from a 10 × 20 m box footprint: the LOD-0 building (counter: prisms/s).
#[divan::bench]
fn prism_box(bencher: Bencher<'_, '_>) {
    let p: PolygonWithHoles = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 20.0)).into();
    bencher
        .counter(ItemsCount::new(1usize))
        .bench(|| prism(black_box(&p), 0.0, 12.0, None));
}

/// A closed prism from the 10,000-vertex star (counter: footprint vertices/s).
#[divan::bench]
fn prism_star_10k(bencher: Bencher<'_, '_>) {
    let p: PolygonWithHoles = star(10_000, 1).into();
    bencher
        .counter(ItemsCount::new(10_000usize))
        .bench(|| prism(black_box(&p), 0.0, 12.0, None));
}

/// A 100 × 100 m block refined to triangles of at most 25 m² and draped on a smooth
/// elevation function (counter: blocks/s).
#[divan::bench]
fn drape_block_1ha(bencher: Bencher<'_, '_>) {
    let p: PolygonWithHoles = Polygon::rect(DVec2::ZERO, DVec2::splat(100.0)).into();
    let options = RefineOptions::default();
    bencher.counter(ItemsCount::new(1usize)).bench(|| {
        let mut m = Mesh::new(None);
        m.add_draped_polygon(
            black_box(&p),
            &options,
            |q| 0.05 * q.x + (0.1 * q.y).sin(),
            0.0,
            Facing::Up,
        )
        .map(|()| m)
    });
}
