//! Shared set-up of the primary-network benchmark and the `primary_timing` example:
//! fBm terrain, the 2 km road's parameters, the 500-road city.

#![allow(dead_code, clippy::unwrap_used)]

use std::sync::Arc;

use polis_geom::field::{Fbm, FbmParams};
use polis_geom::{Aabb2, DVec2, Field, FieldExt};
use polis_roads::LazyLattice;
use polis_roads::primary::{
    AdaptiveParams, ControlId, Edit, EditOptions, Endpoint, PrimaryEditor, RoadPreset, RoadSpec,
    Strategy, Terrain,
};

/// The ends of the 2 km road.
pub const ROAD_2KM: (DVec2, DVec2) = (DVec2::new(-1000.0, -200.0), DVec2::new(960.0, 200.0));

pub fn bounds() -> Aabb2 {
    Aabb2::new(DVec2::splat(-5000.0), DVec2::splat(5000.0))
}

pub fn hills() -> Arc<dyn Field> {
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
pub fn terrain() -> Terrain {
    Terrain::with_elevation(hills(), bounds()).unwrap()
}

/// The same fBm through a [`LazyLattice`] with 20 m spacing (how polis-roads treats its
/// procedural hills), warmed up.
pub fn terrain_lattice() -> Terrain {
    let lattice = LazyLattice::new(hills(), 20.0, bounds()).unwrap();
    Terrain::with_elevation(Arc::new(lattice), bounds()).unwrap()
}

/// `n_sample` 7, `d_sample` 20 m, `θ_dev` 25°, `d_snap` 20 m.
pub fn params(strategy: Strategy) -> AdaptiveParams {
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

pub const STRATEGIES: [Strategy; 4] = [
    Strategy::Straight,
    Strategy::MinimumElevation,
    Strategy::MinimumElevationDifference,
    Strategy::EvenElevationDifference,
];

/// A 16 × 16 grid of nodes 150 m apart with its 480 grid roads, two diagonals through
/// the node near the centre (six roads there) and 18 more: 500 roads of 20 m samples. Returns the editor and the centre node.
pub fn city() -> (PrimaryEditor, ControlId) {
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
