//! Benchmarks of polis-facades: texels/s of rasterisation, cells/s of geometry mode,
//! facades/s of fitting and samples/s of point evaluation, for every built-in style.
//!
//! Run with `cargo bench -p polis-facades`.

use divan::counter::ItemsCount;
use divan::{Bencher, black_box};
use polis_facades::builtin::{builtin_style, builtin_styles};
use polis_facades::{FacadeSpec, PreparedStyle, RasterOptions, TileSet};

const STYLES: [&str; 4] = [
    "brick_house",
    "office_curtain_wall",
    "classic_stone",
    "industrial",
];

fn main() {
    divan::main();
}

fn prepared(name: &str) -> PreparedStyle {
    let style = builtin_style(name).unwrap_or_else(|| builtin_styles().remove(0));
    match PreparedStyle::new(style) {
        Ok(p) => p,
        Err(e) => panic!("built-in style failed: {e}"),
    }
}

/// A 20 m × 15 m facade at 64 texels/m: 1280 × 960 = 1.23 million texels.
#[divan::bench(args = STYLES, sample_count = 10)]
fn rasterize_20x15m_64ppm(bencher: Bencher<'_, '_>, style: &str) {
    let p = prepared(style);
    let Ok(f) = p.facade(&FacadeSpec::new(20.0, 15.0, 7)) else {
        return;
    };
    let opts = RasterOptions::default();
    bencher
        .counter(ItemsCount::new(1280usize * 960))
        .bench_local(|| black_box(f.rasterize(&opts).map(|t| t.width)));
}

/// Geometry mode on a 40 m × 60 m tower face.
#[divan::bench(args = STYLES)]
fn cells_40x60m(bencher: Bencher<'_, '_>, style: &str) {
    let p = prepared(style);
    let Ok(f) = p.facade(&FacadeSpec::new(40.0, 60.0, 7)) else {
        return;
    };
    let n = f.cells().len();
    let mut buf = Vec::new();
    bencher.counter(ItemsCount::new(n)).bench_local(|| {
        f.cells_into(&mut buf);
        black_box(buf.len())
    });
}

/// Fitting a style to a 15 m × 12 m face (interval groups, layers, influences).
#[divan::bench(args = STYLES)]
fn fit_facade_15x12m(bencher: Bencher<'_, '_>, style: &str) {
    let p = prepared(style);
    let mut seed = 0u64;
    bencher.counter(ItemsCount::new(1usize)).bench_local(|| {
        seed += 1;
        black_box(p.facade(&FacadeSpec::new(15.0, 12.0, seed)).is_ok())
    });
}

/// Random-access point evaluation (binary search per axis), 10,000 points.
#[divan::bench(args = STYLES)]
fn sample_points(bencher: Bencher<'_, '_>, style: &str) {
    let p = prepared(style);
    let Ok(f) = p.facade(&FacadeSpec::new(20.0, 15.0, 7)) else {
        return;
    };
    let pts: Vec<(f64, f64)> = (0..10_000u64)
        .map(|k| {
            let h = polis_facades::sample::mix64(k);
            (
                (h & 0xffff) as f64 / 65536.0 * 20.0,
                (h >> 16 & 0xffff) as f64 / 65536.0 * 15.0,
            )
        })
        .collect();
    bencher.counter(ItemsCount::new(pts.len())).bench_local(|| {
        let mut acc = 0.0f32;
        for &(s, t) in &pts {
            acc += f.sample(s, t).albedo[0];
        }
        black_box(acc)
    });
}

/// Building the shared tile set of a style at 64 texels/m.
#[divan::bench(args = STYLES, sample_count = 5)]
fn tile_set_64ppm(bencher: Bencher<'_, '_>, style: &str) {
    let p = prepared(style);
    let opts = RasterOptions::default();
    bencher.bench_local(|| black_box(TileSet::build(&p, &opts).map(|s| s.gpu_bytes())));
}
