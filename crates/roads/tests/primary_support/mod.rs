//! Shared set-up of the primary-network tests: terrains, editors, the planarity check.

#![allow(dead_code, clippy::unwrap_used)]

use std::sync::Arc;

use polis_geom::field::{Constant, Fbm, FbmParams, FnField};
use polis_geom::{Aabb2, DVec2, FieldExt};
use polis_roads::RoadInputs;
use polis_roads::primary::{
    EditOptions, Endpoint, PrimaryEditor, PrimaryNetwork, RoadPreset, RoadSpec, Terrain,
};

pub const HALF: f64 = 2000.0;

pub fn bounds() -> Aabb2 {
    Aabb2::new(DVec2::splat(-HALF), DVec2::splat(HALF))
}

/// fBm hills up to about ±60 m.
pub fn hills(seed: u64) -> Terrain {
    let f = Fbm::new(FbmParams {
        seed,
        octaves: 4,
        wavelength_m: 900.0,
        ..FbmParams::default()
    })
    .unwrap()
    .scaled(60.0);
    Terrain::with_elevation(f.shared(), bounds()).unwrap()
}

/// Hills, a river along x ≈ 600 m and a park around (−900, 900).
pub fn landscape(seed: u64) -> Terrain {
    let mut inputs = RoadInputs::flat(Arc::new(Constant(1.0)));
    inputs.elevation = Fbm::new(FbmParams {
        seed,
        octaves: 3,
        wavelength_m: 800.0,
        ..FbmParams::default()
    })
    .unwrap()
    .scaled(50.0)
    .shared();
    inputs.water = Arc::new(FnField::new(|p: DVec2| {
        f64::from((p.x - 600.0 - 0.05 * p.y).abs() < 40.0)
    }));
    inputs.parks = Arc::new(FnField::new(|p: DVec2| {
        f64::from(p.distance(DVec2::new(-900.0, 900.0)) < 250.0)
    }));
    Terrain::new(&inputs, bounds()).unwrap()
}

pub fn check_planar(net: &PrimaryNetwork) {
    net.check_invariants().unwrap();
    let low = net.to_road_network().unwrap();
    low.network.check_invariants().unwrap();
    // Every edge maps back to a live road.
    for (e, _, _, _) in low.network.edges() {
        net.road(low.road_of(e).unwrap()).unwrap();
    }
}

pub fn flat_editor() -> PrimaryEditor {
    PrimaryEditor::new(Terrain::flat(bounds()).unwrap(), EditOptions::default()).unwrap()
}

pub fn straight() -> RoadSpec {
    let mut s = RoadPreset::InnerCity.spec();
    s.params.strategy = polis_roads::primary::Strategy::Straight;
    s
}

pub fn at(x: f64, y: f64) -> Endpoint {
    Endpoint::At(DVec2::new(x, y))
}
