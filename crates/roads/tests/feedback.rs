//! Population feedback (P&M §3.2.1): street ends use up the population around them, so on
//! a uniform population map the streets no longer fill the map edge to edge.

#![allow(clippy::unwrap_used)]

use std::collections::BTreeSet;
use std::sync::Arc;

use polis_geom::field::Constant;
use polis_roads::*;

/// Share of the map's 50 m cells that a street passes through (sampled every 10 m).
fn street_cover(net: &RoadNetwork, params: &RoadParams) -> f64 {
    let cell = 50.0;
    let [x0, y0] = params.bounds_min;
    let [x1, y1] = params.bounds_max;
    let (nx, ny) = (((x1 - x0) / cell) as i64, ((y1 - y0) / cell) as i64);
    let mut hit = BTreeSet::new();
    for (e, _, _, r) in net.edges() {
        if r.class != RoadClass::Street {
            continue;
        }
        let (a, b) = net.segment(e).unwrap();
        let n = (a.distance(b) / 10.0).ceil().max(1.0) as usize;
        for k in 0..=n {
            let p = a.lerp(b, k as f64 / n as f64);
            hit.insert((((p.x - x0) / cell) as i64, ((p.y - y0) / cell) as i64));
        }
    }
    hit.len() as f64 / (nx * ny) as f64
}

fn grow(feedback: f64) -> (Generated, RoadParams) {
    let params = RoadParams {
        seed: 5,
        bounds_min: [-800.0, -800.0],
        bounds_max: [800.0, 800.0],
        max_segments: 6000,
        max_steps: 400,
        population_feedback: feedback,
        feedback_radius_m: 120.0,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::flat(Arc::new(Constant(0.3)));
    (generate(&params, &inputs).unwrap(), params)
}

#[test]
fn feedback_stops_streets_before_a_uniform_map_is_filled() {
    let (plain, params) = grow(0.0);
    let (fed, _) = grow(0.2);
    let (a, b) = (
        street_cover(&plain.network, &params),
        street_cover(&fed.network, &params),
    );
    eprintln!(
        "cover without feedback {a:.3} ({} segments, {:?}), with {b:.3} ({} segments, {:?})",
        plain.report.segments, plain.report.stop, fed.report.segments, fed.report.stop
    );
    // Without feedback the streets fill the map; with it they stop where the population
    // is used up, long before, and by themselves (not by a budget).
    assert!(a > 0.5, "{a}");
    assert!(b < 0.75 * a, "{b} vs {a}");
    assert!(fed.report.segments < plain.report.segments);
    assert_eq!(fed.report.stop, StopReason::NothingLeft);
    fed.network.check_invariants().unwrap();
    // Deterministic.
    let (again, _) = grow(0.2);
    assert_eq!(again.report.segments, fed.report.segments);
}

/// An all-zero population map grows no street (documented behaviour: streets need
/// population); the generator neither panics nor loops.
#[test]
fn an_all_zero_population_grows_no_street() {
    let params = RoadParams {
        bounds_min: [-500.0, -500.0],
        bounds_max: [500.0, 500.0],
        max_segments: 500,
        population_feedback: 0.1,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::flat(Arc::new(Constant(0.0)));
    match generate(&params, &inputs) {
        Ok(g) => assert!(
            g.network
                .edges()
                .all(|(_, _, _, r)| r.class != RoadClass::Street)
        ),
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}
