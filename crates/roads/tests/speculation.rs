//! Speculative evaluation (`RoadGenerator::with_speculation`): a pass's proposals are
//! answered ahead on the thread pool against the network as the pass found it, and an
//! answer is used only where no segment inserted earlier in the pass changed the network
//! near what it read. The network, every id and every bit of it, and the report must be
//! those of serial evaluation, on every workload: bridges and tunnels, the four patterns,
//! population feedback, the peer's long segments. The workloads are big enough that both
//! kinds of answer occur (used as they were, and evaluated again).

#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use polis_geom::DVec2;
use polis_geom::field::{Constant, FnField};
use polis_roads::*;

#[path = "../benches/common/peer.rs"]
mod peer;
use peer::peer_params;

/// Every node (id, position bits, payload) and edge (id, ends, payload) in id order.
type Whole = (
    Vec<(usize, u64, u64, Junction)>,
    Vec<(usize, usize, usize, Road)>,
);

fn whole(net: &RoadNetwork) -> Whole {
    let nodes = net
        .nodes()
        .map(|(n, p, j)| (n.index(), p.x.to_bits(), p.y.to_bits(), *j))
        .collect();
    let edges = net
        .edges()
        .map(|(e, u, v, r)| (e.index(), u.index(), v.index(), *r))
        .collect();
    (nodes, edges)
}

/// Grows `params` over `inputs` serially and speculatively; asserts both give the same
/// network and report, and returns what speculation did and the report.
fn agree(params: &RoadParams, inputs: &RoadInputs) -> (SpeculationStats, GrowthReport) {
    let serial = RoadGenerator::new(params, inputs)
        .unwrap()
        .with_speculation(false)
        .run()
        .unwrap();
    let mut generator = RoadGenerator::new(params, inputs)
        .unwrap()
        .with_speculation(true);
    let ahead = generator.run().unwrap();
    assert_eq!(serial.report, ahead.report);
    assert!(whole(&serial.network) == whole(&ahead.network));
    ahead.network.check_invariants().unwrap();
    let s = generator.speculation();
    if polis_geom::par::PARALLEL {
        assert!(s.used + s.redone <= s.evaluated, "{s:?}");
        assert!(s.used > 0, "{s:?} {:?}", ahead.report);
    } else {
        assert_eq!(s, SpeculationStats::default());
    }
    (s, ahead.report)
}

#[test]
fn the_peer_workload_is_the_same_speculated() {
    let (params, inputs) = peer_params(15_000);
    let (s, _) = agree(&params, &inputs);
    if polis_geom::par::PARALLEL {
        assert!(s.redone > 0, "{s:?}");
    }
}

#[test]
fn every_pattern_with_procedural_maps_is_the_same_speculated() {
    for (pattern, seed) in [
        (Pattern::Basic, 1),
        (Pattern::NewYork, 7),
        (Pattern::Paris, 3),
        (Pattern::SanFrancisco, 11),
    ] {
        let params = RoadParams {
            pattern,
            seed,
            max_segments: 2500,
            ..RoadParams::default()
        };
        let inputs = RoadInputs::procedural(params.seed, &params).unwrap();
        let (s, report) = agree(&params, &inputs);
        assert!(report.segments > 1000, "{pattern:?}: {report:?}");
        if polis_geom::par::PARALLEL {
            assert!(s.redone > 0, "{pattern:?}: {s:?}");
        }
    }
}

#[test]
fn population_feedback_is_the_same_speculated() {
    let params = RoadParams {
        population_feedback: 0.05,
        max_segments: 2500,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::procedural(params.seed, &params).unwrap();
    let (s, report) = agree(&params, &inputs);
    assert!(report.segments > 1000, "{report:?}");
    if polis_geom::par::PARALLEL {
        assert!(s.redone > 0, "{s:?}");
    }
}

#[test]
fn bridges_and_tunnels_are_the_same_speculated() {
    // Water in a strip across the map (highways bridge it), a park strip (highways
    // tunnel under it).
    let mut inputs = RoadInputs::flat(Arc::new(Constant(0.5)));
    inputs.water = Arc::new(FnField::new(|p: DVec2| {
        if (-500.0..=-400.0).contains(&p.x) {
            1.0
        } else {
            0.0
        }
    }));
    inputs.parks = Arc::new(FnField::new(|p: DVec2| {
        if (300.0..=450.0).contains(&p.x) {
            1.0
        } else {
            0.0
        }
    }));
    let params = RoadParams {
        start: Some([0.0, 0.0]),
        start_angle_deg: Some(0.0),
        max_segments: 2000,
        max_tunnel_length_m: 300.0,
        ..RoadParams::default()
    };
    let (_, report) = agree(&params, &inputs);
    let c = report.constraints;
    assert!(c.tunnels > 0 && c.bridges > 0, "{c:?}");
}
