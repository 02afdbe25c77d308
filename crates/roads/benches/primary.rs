//! Kelly's primary network: plotting one 2 km adaptive road, and moving a node with six
//! roads in a 500-road network (re-plot and validate).
//!
//! `cargo bench -p polis-roads --bench primary`. Terrain: 5-octave fBm hills (±60 m,
//! 1 km wavelength), evaluated directly (no lattice cache).

#![allow(clippy::unwrap_used)]

use std::hint::black_box;

use polis_geom::DVec2;
use polis_roads::primary::{Edit, Strategy, plot, plot_path};

#[path = "common/primary_city.rs"]
mod primary_city;
use primary_city::{ROAD_2KM, STRATEGIES, city, params, terrain, terrain_lattice};

fn main() {
    divan::main();
}

/// Plot points only (sampling and selection), one 2 km road.
#[divan::bench(args = STRATEGIES)]
fn plot_2km(bencher: divan::Bencher<'_, '_>, s: Strategy) {
    let t = terrain();
    let p = params(s);
    let (a, b) = ROAD_2KM;
    bencher.bench_local(|| plot(black_box(a), black_box(b), &p, &t).unwrap());
}

/// [`plot_2km`] on the lattice-cached fBm.
#[divan::bench(args = STRATEGIES)]
fn plot_2km_lattice(bencher: divan::Bencher<'_, '_>, s: Strategy) {
    let t = terrain_lattice();
    let p = params(s);
    let (a, b) = ROAD_2KM;
    plot(a, b, &p, &t).unwrap();
    bencher.bench_local(|| plot(black_box(a), black_box(b), &p, &t).unwrap());
}

/// Plot, spline every 10 m and drape: the whole low-level path of one 2 km road.
#[divan::bench(args = STRATEGIES)]
fn plot_path_2km(bencher: divan::Bencher<'_, '_>, s: Strategy) {
    let t = terrain();
    let p = params(s);
    let (a, b) = ROAD_2KM;
    bencher.bench_local(|| plot_path(black_box(a), black_box(b), &p, &t).unwrap());
}

/// Propose a move of the six-road node by 12 m (alternating directions): re-plots its
/// six roads and validates them against the network.
#[divan::bench(sample_count = 200)]
fn move_node_6_roads_in_500(bencher: divan::Bencher<'_, '_>) {
    let (ed, c) = city();
    let home = ed.network().node(c).unwrap().pos;
    let mut k = 0u32;
    bencher.bench_local(|| {
        k += 1;
        let to = home + DVec2::from_angle(f64::from(k % 8) * 0.785) * 12.0;
        black_box(ed.propose(&Edit::MoveNode { node: c, to }).unwrap())
    });
}

/// The same move proposed, committed and undone (the network's indexes updated twice).
#[divan::bench(sample_count = 200)]
fn move_commit_undo_6_roads_in_500(bencher: divan::Bencher<'_, '_>) {
    let (mut ed, c) = city();
    let home = ed.network().node(c).unwrap().pos;
    let mut k = 0u32;
    bencher.bench_local(|| {
        k += 1;
        let to = home + DVec2::from_angle(f64::from(k % 8) * 0.785) * 12.0;
        let p = ed.propose(&Edit::MoveNode { node: c, to }).unwrap();
        ed.commit(&p).unwrap();
        ed.undo().unwrap();
    });
}
