//! Kelly's primary network: plotting one 2 km adaptive road, and moving a node with six
//! roads in a 500-road network (re-plot and validate).
//!
//! `cargo bench -p polis-roads --bench primary`. Terrain: 5-octave fBm hills (±60 m,
//! 1 km wavelength), evaluated directly (no lattice cache).

#![allow(clippy::unwrap_used)]

use std::hint::black_box;
use std::sync::Arc;

use polis_geom::Field;
use polis_roads::LazyLattice;

use polis_geom::field::{Fbm, FbmParams};
use polis_geom::{Aabb2, DVec2, FieldExt};
use polis_roads::primary::{
    AdaptiveParams, ControlId, Edit, EditOptions, Endpoint, PrimaryEditor, RoadPreset, RoadSpec,
    Strategy, Terrain, plot, plot_path,
};

fn main() {
    divan::main();
}

fn bounds() -> Aabb2 {
    Aabb2::new(DVec2::splat(-5000.0), DVec2::splat(5000.0))
}

fn hills() -> Arc<dyn Field> {
    Fbm::new(FbmParams {
        seed: 11,
        octaves: 5,
        wavelength_m: 1000.0,
        ..FbmParams::default()
    })
    .unwrap()
    .scaled(60.0)
    .shared()
}

/// The fBm evaluated at every sample.
fn terrain() -> Terrain {
    Terrain::with_elevation(hills(), bounds()).unwrap()
}

/// The same fBm through a [`LazyLattice`] with 20 m spacing (how polis-roads treats its
/// procedural hills), warmed up.
fn terrain_lattice() -> Terrain {
    let lattice = LazyLattice::new(hills(), 20.0, bounds()).unwrap();
    Terrain::with_elevation(Arc::new(lattice), bounds()).unwrap()
}

/// `n_sample` 7, `d_sample` 20 m, `θ_dev` 25°, `d_snap` 20 m.
fn params(strategy: Strategy) -> AdaptiveParams {
    AdaptiveParams {
        strategy,
        sample_size_m: 20.0,
        samples: 7,
        deviation_deg: 25.0,
        snap_m: 20.0,
        segment_draw_size_m: 10.0,
        max_bridge_m: 100.0,
    }
}

const STRATEGIES: [Strategy; 4] = [
    Strategy::Straight,
    Strategy::MinimumElevation,
    Strategy::MinimumElevationDifference,
    Strategy::EvenElevationDifference,
];

/// Plot points only (sampling and selection), one 2 km road.
#[divan::bench(args = STRATEGIES)]
fn plot_2km(bencher: divan::Bencher<'_, '_>, s: Strategy) {
    let t = terrain();
    let p = params(s);
    let (a, b) = (DVec2::new(-1000.0, -200.0), DVec2::new(960.0, 200.0));
    bencher.bench_local(|| plot(black_box(a), black_box(b), &p, &t).unwrap());
}

/// [`plot_2km`] on the lattice-cached fBm.
#[divan::bench(args = STRATEGIES)]
fn plot_2km_lattice(bencher: divan::Bencher<'_, '_>, s: Strategy) {
    let t = terrain_lattice();
    let p = params(s);
    let (a, b) = (DVec2::new(-1000.0, -200.0), DVec2::new(960.0, 200.0));
    plot(a, b, &p, &t).unwrap();
    bencher.bench_local(|| plot(black_box(a), black_box(b), &p, &t).unwrap());
}

/// Plot, spline every 10 m and drape: the whole low-level path of one 2 km road.
#[divan::bench(args = STRATEGIES)]
fn plot_path_2km(bencher: divan::Bencher<'_, '_>, s: Strategy) {
    let t = terrain();
    let p = params(s);
    let (a, b) = (DVec2::new(-1000.0, -200.0), DVec2::new(960.0, 200.0));
    bencher.bench_local(|| plot_path(black_box(a), black_box(b), &p, &t).unwrap());
}

/// A 16 × 16 grid of nodes 150 m apart with its 480 grid roads, two diagonals through
/// the node near the centre (six roads there) and 18 more: 500 roads of 20 m samples. Returns the editor and the centre node.
fn city() -> (PrimaryEditor, ControlId) {
    // Meandering 150 m roads meet at shallow angles now and then: allow 5°.
    let options = EditOptions {
        min_angle_deg: 5.0,
        ..EditOptions::default()
    };
    let mut ed = PrimaryEditor::new(terrain(), options).unwrap();
    let spec = RoadSpec {
        params: AdaptiveParams {
            deviation_deg: 12.0,
            ..params(Strategy::EvenElevationDifference)
        },
        ..RoadPreset::InnerCity.spec()
    };
    let (nx, ny) = (16, 16);
    let at =
        |i: i32, j: i32| DVec2::new(f64::from(i - nx / 2) * 150.0, f64::from(j - ny / 2) * 150.0);
    let mut id = vec![vec![ControlId(0); ny as usize]; nx as usize];
    for i in 0..nx {
        for j in 0..ny {
            id[i as usize][j as usize] = ed.network().next_node_id();
            ed.apply(&Edit::AddNode {
                at: at(i, j),
                label: None,
            })
            .unwrap();
        }
    }
    let node = |i: i32, j: i32| Endpoint::Node(id[i as usize][j as usize]);
    let road = |ed: &mut PrimaryEditor, a: (i32, i32), b: (i32, i32)| {
        ed.apply(&Edit::AddRoad {
            from: node(a.0, a.1),
            to: node(b.0, b.1),
            spec,
        })
        .unwrap();
    };
    for i in 0..nx {
        for j in 0..ny {
            if i + 1 < nx {
                road(&mut ed, (i, j), (i + 1, j));
            }
            if j + 1 < ny {
                road(&mut ed, (i, j), (i, j + 1));
            }
        }
    }
    let (ci, cj) = (nx / 2, ny / 2);
    road(&mut ed, (ci, cj), (ci + 1, cj + 1));
    road(&mut ed, (ci, cj), (ci - 1, cj - 1));
    for k in 0..18 {
        let (i, j) = (1 + 3 * (k % 5), [1, 4, 10, 13][k as usize / 5]);
        road(&mut ed, (i, j + 1), (i + 1, j));
    }
    assert_eq!(ed.network().road_count(), 500);
    let c = id[ci as usize][cj as usize];
    assert_eq!(ed.network().roads_at(c).len(), 6);
    (ed, c)
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
