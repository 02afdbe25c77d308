//! The road-growth workload of the JavaScript peer (phiresky/procedural-cities, see
//! `PEERS.md`) in polis's parameters: shared by the `peer` bench and the network digest
//! test.
//!
//! | peer setting | here |
//! |---|---|
//! | street / highway segment 300 / 400 units | `street_length_m` 300, `highway_length_m` 400 (units read as metres) |
//! | widths 6 / 16 | `street_width_m` 6, `highway_width_m` 16 |
//! | branch probability 0.4 / 0.02 | `street_branch_probability` 0.4, `highway_branch_probability` 0.02 |
//! | population threshold 0.1 | `population_threshold` 0.1 (branching) and `street_min_population` 0.1 (streets stop below it) |
//! | street branch delay from a highway 10 | `highway_street_delay` 10 |
//! | one population sample per highway proposal; straight-on ± 15° | 3 highway rays within ± 15°, one sample each, ray = one segment |
//! | branch angle 90° ± 3° | `street_deviation_deg` 3 |
//! | minimum intersection deviation 30° | `min_angle_deg` 30 |
//! | road snap distance 50 | `snap_radius_m` 50 |
//! | 3-octave simplex population at 1/10,000 and 1/20,000 | the slides' population with `unit_m` 1000 (same scales) |
//! | no legality maps | `RoadInputs::flat` (map edge only) |
//! | quadtree ±20,000 | map bounds ±20,000 m; polis's own grid index |
//!
//! Differences that remain: polis's simplex noise is its own (the map differs, its
//! statistics do not), its highways follow P&M's ray sampling instead of the peer's
//! two-candidate choice, and every crossing is split into a planar junction.

#![allow(dead_code, clippy::unwrap_used)]

use std::sync::Arc;

use polis_geom::field::{Population, PopulationParams};
use polis_roads::{RoadInputs, RoadParams};

/// Segments the peer grows in its timed run.
pub const PEER_SEGMENTS: usize = 15_000;
/// The peer's warm time for [`PEER_SEGMENTS`] (runs 2–11 in one Node 20 process), ms.
pub const PEER_WARM_MS: f64 = 128.6;
/// The peer's time in a fresh process, ms.
pub const PEER_COLD_MS: f64 = 290.0;

/// Parameters and maps of the peer workload, stopping after `segments` segments.
pub fn peer_params(segments: usize) -> (RoadParams, RoadInputs) {
    let params = RoadParams {
        bounds_min: [-20_000.0, -20_000.0],
        bounds_max: [20_000.0, 20_000.0],
        start: Some([0.0, 0.0]),
        start_angle_deg: Some(0.0),
        street_length_m: 300.0,
        highway_length_m: 400.0,
        street_width_m: 6.0,
        highway_width_m: 16.0,
        street_branch_probability: 0.4,
        highway_branch_probability: 0.02,
        population_threshold: 0.1,
        street_min_population: 0.1,
        highway_street_delay: 10,
        highway_rays: 3,
        highway_ray_samples: 1,
        highway_max_turn_deg: 15.0,
        highway_ray_length_m: 400.0,
        street_deviation_deg: 3.0,
        min_angle_deg: 30.0,
        snap_radius_m: 50.0,
        max_segments: segments,
        max_steps: 100_000,
        ..RoadParams::default()
    };
    let pop = Population::new(PopulationParams {
        seed: params.seed,
        unit_m: 1000.0,
    })
    .unwrap();
    (params, RoadInputs::flat(Arc::new(pop)))
}
