//! Value stability of the Parish & Müller generator: the whole network (node and edge
//! ids, positions to the bit, road class, width, bridge flag and step, junction steps)
//! pinned as digests for a few workloads, so speed work on candidate queries, legality
//! and snapping provably changes nothing.

#![allow(clippy::unwrap_used)]

use polis_roads::*;

#[path = "../benches/common/peer.rs"]
mod peer;
use peer::peer_params;

/// FNV-1a over everything the network holds, in id order.
fn digest(net: &RoadNetwork) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |v: u64| {
        for b in v.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for (n, p, j) in net.nodes() {
        eat(n.index() as u64);
        eat(p.x.to_bits());
        eat(p.y.to_bits());
        eat(u64::from(j.step));
    }
    for (e, u, v, r) in net.edges() {
        eat(e.index() as u64);
        eat(u.index() as u64);
        eat(v.index() as u64);
        eat(matches!(r.class, RoadClass::Highway) as u64);
        eat(r.width.to_bits());
        eat(u64::from(r.bridge));
        eat(u64::from(r.step));
    }
    h
}

fn run(params: &RoadParams, inputs: &RoadInputs) -> (usize, usize, u64) {
    let g = generate(params, inputs).unwrap();
    (
        g.report.segments,
        g.network.edge_count(),
        digest(&g.network),
    )
}

#[test]
fn default_city_with_procedural_maps() {
    let params = RoadParams {
        max_segments: 1500,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::procedural(params.seed, &params).unwrap();
    let got = run(&params, &inputs);
    assert_eq!(got, (1500, 1784, 0xfaf9_37e5_a5c4_6f92), "{got:x?}");
}

#[test]
fn new_york_with_procedural_maps() {
    let params = RoadParams {
        pattern: Pattern::NewYork,
        max_segments: 1000,
        seed: 7,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::procedural(params.seed, &params).unwrap();
    let got = run(&params, &inputs);
    assert_eq!(got, (1000, 1055, 0x18d2_e9ac_cd5a_8b80), "{got:x?}");
}

#[test]
fn peer_workload() {
    let (params, inputs) = peer_params(2000);
    let got = run(&params, &inputs);
    assert_eq!(got, (2000, 2280, 0x619d_760c_b063_5dff), "{got:x?}");
}
