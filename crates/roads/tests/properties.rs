//! Property tests: random parameters and seeds never panic and always give a valid planar
//! graph (or a typed error).

#![allow(clippy::unwrap_used)]

use polis_roads::{Pattern, RoadError, RoadParams, generate_default};
use proptest::prelude::*;

fn pattern() -> impl Strategy<Value = Pattern> {
    prop_oneof![
        Just(Pattern::Basic),
        Just(Pattern::NewYork),
        Just(Pattern::Paris),
        Just(Pattern::SanFrancisco)
    ]
}

/// Values biased toward the degenerate ends of each range.
fn edgy(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    prop_oneof![Just(lo), Just(hi), lo..=hi]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_parameters_give_planar_networks(
        seed in any::<u64>(),
        pattern in pattern(),
        street in edgy(5.0, 200.0),
        highway in edgy(20.0, 500.0),
        snap in edgy(0.0, 120.0),
        min_angle in edgy(0.0, 89.0),
        prune in edgy(0.0, 1.0),
        rotate in edgy(0.0, 180.0),
        bridge in edgy(0.0, 600.0),
        half in edgy(50.0, 3000.0),
        grid in edgy(-720.0, 720.0),
        branch in edgy(0.0, 1.0),
        threshold in edgy(-1.0, 1.0),
        smooth in any::<bool>(),
    ) {
        let params = RoadParams {
            seed,
            pattern,
            street_length_m: street,
            highway_length_m: highway,
            block_length_m: street * 1.7,
            block_width_m: street,
            snap_radius_m: snap,
            min_angle_deg: min_angle,
            max_prune_factor: prune,
            max_rotate_deg: rotate,
            max_bridge_length_m: bridge,
            bounds_min: [-half, -half * 0.7],
            bounds_max: [half * 0.9, half],
            grid_angle_deg: grid,
            street_branch_probability: branch,
            highway_branch_probability: branch * 0.3,
            population_threshold: threshold,
            smooth_highways: smooth,
            max_segments: 150,
            max_steps: 60,
            ..RoadParams::default()
        };
        match generate_default(&params) {
            Ok(city) => {
                city.network.check_invariants().unwrap();
                prop_assert!(city.report.segments <= 150);
                for (e, _, _, road) in city.network.edges() {
                    if road.bridge {
                        prop_assert!(city.network.edge_length(e).unwrap() <= bridge + 1e-6);
                    }
                }
            }
            // Every parameter above is in range and the procedural maps have land.
            Err(e) => prop_assert!(false, "unexpected error {e}"),
        }
    }

    #[test]
    fn bad_numbers_are_typed_errors(v in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(-1.0), Just(0.0)]) {
        for p in [
            RoadParams { street_length_m: v, ..RoadParams::default() },
            RoadParams { snap_radius_m: v.min(-1.0), ..RoadParams::default() },
            RoadParams { bounds_max: [v, 10.0], bounds_min: [0.0, 0.0], ..RoadParams::default() },
            RoadParams { start: Some([v / 0.0, 0.0]), ..RoadParams::default() },
        ] {
            let r = generate_default(&p);
            prop_assert!(matches!(r, Err(RoadError::InvalidParameter { .. })), "{r:?}");
        }
    }
}

#[test]
fn params_round_trip_through_json() {
    let p = RoadParams {
        pattern: Pattern::Paris,
        paris_centre: Some([1.0, 2.0]),
        ..RoadParams::default()
    };
    let s = serde_json::to_string(&p).unwrap();
    let q: RoadParams = serde_json::from_str(&s).unwrap();
    assert_eq!(p, q);
    let d: RoadParams = serde_json::from_str("{}").unwrap();
    assert_eq!(d, RoadParams::default());
}
