//! Tunnels (P&M §3.3): a highway that meets a park or a hill no rotation avoids passes
//! under it between two portals; over the length limit, or over a valley, it is refused;
//! water stays bridged.

#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use polis_geom::DVec2;
use polis_geom::field::{Constant, Field, FnField};
use polis_roads::legality::{Illegal, Legality};
use polis_roads::tunnels::{COVER_TOLERANCE_M, tunnelable};
use polis_roads::*;
use proptest::prelude::*;

/// A mask field: 1 where `lo ≤ x ≤ hi` (the whole height of the map), else 0.
fn strip(lo: f64, hi: f64) -> Arc<dyn Field> {
    Arc::new(FnField::new(move |p: DVec2| {
        if (lo..=hi).contains(&p.x) { 1.0 } else { 0.0 }
    }))
}

/// Uniform population; a park where `lo ≤ x ≤ hi`.
fn park_strip(lo: f64, hi: f64) -> RoadInputs {
    let mut i = RoadInputs::flat(Arc::new(Constant(0.5)));
    i.parks = strip(lo, hi);
    i
}

/// Uniform population; a ridge (`rise > 0`) or a trench (`rise < 0`) across the map,
/// `rise` metres high at x = `centre`, falling linearly to 0 at `centre ± half`.
fn ridge(centre: f64, half: f64, rise: f64) -> RoadInputs {
    let mut i = RoadInputs::flat(Arc::new(Constant(0.5)));
    i.elevation = Arc::new(FnField::new(move |p: DVec2| {
        rise * (1.0 - (p.x - centre).abs() / half).max(0.0)
    }));
    i
}

/// One highway proposal from `start` along +x, `len` metres, on an empty network.
fn propose(
    params: &RoadParams,
    inputs: &RoadInputs,
    start: (f64, f64),
    len: f64,
) -> (QueryState, RoadAttr, ConstraintStats) {
    let mut c = DefaultConstraints::new(params, inputs);
    let mut r = RoadAttr::new(DVec2::new(start.0, start.1), 0.0, len, RoadClass::Highway);
    let s = c.adjust(&mut r, &RoadNetwork::new());
    (s, r, c.stats())
}

#[test]
fn a_highway_meeting_a_park_becomes_a_tunnel() {
    let p = RoadParams::default();
    let inputs = park_strip(100.0, 200.0);
    let (s, r, stats) = propose(&p, &inputs, (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Succeed);
    assert!(r.tunnel && !r.bridge, "{r:?}");
    assert!(
        r.end.x > 200.0 && r.length <= p.max_tunnel_length_m,
        "{r:?}"
    );
    assert_eq!((stats.tunnels, stats.bridges, stats.rotated), (1, 0, 0));
    let legality = Legality::new(&inputs, &p);
    assert_eq!(
        legality.point(r.end),
        None,
        "the far portal is on legal ground"
    );
    assert!(tunnelable(&legality, r.start, r.end, false));
    // Streets never tunnel.
    let mut c = DefaultConstraints::new(&p, &inputs);
    let mut st = RoadAttr::new(DVec2::new(95.0, 0.0), 0.0, 90.0, RoadClass::Street);
    assert_eq!(c.adjust(&mut st, &RoadNetwork::new()), QueryState::Failed);
}

#[test]
fn a_park_the_highway_can_go_round_is_not_tunnelled() {
    // A round park off the axis: a rotation within 30° clears it (P&M: prune, rotate,
    // then cross).
    let mut inputs = RoadInputs::flat(Arc::new(Constant(0.5)));
    inputs.parks = Arc::new(FnField::new(|p: DVec2| {
        if p.distance(DVec2::new(60.0, -10.0)) < 25.0 {
            1.0
        } else {
            0.0
        }
    }));
    let (s, r, stats) = propose(&RoadParams::default(), &inputs, (0.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Succeed);
    assert!(!r.tunnel);
    assert_eq!((stats.rotated, stats.tunnels), (1, 0));
}

#[test]
fn a_highway_meeting_a_steep_hill_becomes_a_tunnel() {
    // 60 m over 50 m: a grade of 1.2 against the limit of 0.35.
    let p = RoadParams::default();
    let inputs = ridge(150.0, 50.0, 60.0);
    let (s, r, stats) = propose(&p, &inputs, (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Succeed, "{stats:?}");
    assert!(r.tunnel && !r.bridge, "{r:?}");
    assert!(
        r.end.x > 150.0 && r.length <= p.max_tunnel_length_m,
        "{r:?}"
    );
    assert_eq!(stats.tunnels, 1);
    // The far portal opens onto climbable ground, past the crest.
    let legality = Legality::new(&inputs, &p);
    assert!(legality.segment_ok(r.end, r.end + DVec2::new(p.slope_step_m, 0.0)));
    // The bore is within the slope limit and under the ground all the way.
    let (ha, hb) = (legality.elevation(r.start), legality.elevation(r.end));
    assert!((hb - ha).abs() <= p.max_slope * r.length + 1e-9);
    for k in 1..100 {
        let t = f64::from(k) / 100.0;
        let ground = legality.elevation(r.start.lerp(r.end, t));
        assert!(ground >= ha + (hb - ha) * t - COVER_TOLERANCE_M);
    }
}

#[test]
fn a_valley_is_no_tunnel() {
    // The same shape downwards: the ground falls away under the bore, no tunnel.
    let p = RoadParams::default();
    let (s, r, stats) = propose(&p, &ridge(150.0, 50.0, -60.0), (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Failed, "{r:?}");
    assert_eq!(stats.tunnels, 0);
}

#[test]
fn a_tunnel_over_the_limit_is_refused() {
    // A park 250 m across: tunnelled with the default 300 m limit, refused with 200 m
    // and with tunnels off.
    let inputs = park_strip(100.0, 350.0);
    let (s, r, _) = propose(&RoadParams::default(), &inputs, (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Succeed);
    assert!(r.tunnel && r.length <= 300.0, "{r:?}");
    for limit in [200.0, 0.0] {
        let p = RoadParams {
            max_tunnel_length_m: limit,
            ..RoadParams::default()
        };
        let (s, r, stats) = propose(&p, &inputs, (95.0, 0.0), 90.0);
        assert_eq!(s, QueryState::Failed, "limit {limit}: {r:?}");
        assert_eq!((stats.tunnels, stats.failed_illegal), (0, 1));
    }
    // A negative or NaN limit is a typed error, not a silent setting.
    for bad in [-1.0, f64::NAN] {
        let p = RoadParams {
            max_tunnel_length_m: bad,
            ..RoadParams::default()
        };
        assert!(matches!(
            p.validate(),
            Err(RoadError::InvalidParameter {
                name: "max_tunnel_length_m",
                ..
            })
        ));
    }
}

#[test]
fn water_stays_bridged() {
    let mut inputs = RoadInputs::flat(Arc::new(Constant(0.5)));
    inputs.water = strip(100.0, 200.0);
    let (s, r, stats) = propose(&RoadParams::default(), &inputs, (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Succeed);
    assert!(r.bridge && !r.tunnel);
    assert_eq!((stats.bridges, stats.tunnels), (1, 0));
    // Water inside a park: neither a bridge (a park in the way) nor a tunnel (water).
    inputs.parks = strip(100.0, 220.0);
    inputs.water = strip(150.0, 170.0);
    let (s, r, _) = propose(&RoadParams::default(), &inputs, (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Failed, "{r:?}");
}

#[test]
fn water_is_tunnelled_where_the_parameters_say_so() {
    let mut inputs = RoadInputs::flat(Arc::new(Constant(0.5)));
    inputs.water = strip(100.0, 200.0);
    let p = RoadParams {
        tunnel_under_water: true,
        ..RoadParams::default()
    };
    let (s, r, stats) = propose(&p, &inputs, (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Succeed);
    assert!(r.tunnel && !r.bridge, "{r:?}");
    assert!(r.end.x > 200.0 && r.length <= p.max_tunnel_length_m);
    assert_eq!((stats.bridges, stats.tunnels), (0, 1));
    let legality = Legality::new(&inputs, &p);
    assert!(tunnelable(&legality, r.start, r.end, true));
    assert!(!tunnelable(&legality, r.start, r.end, false));
    // Over the tunnel limit: refused, not bridged.
    let p = RoadParams {
        max_tunnel_length_m: 80.0,
        ..p
    };
    let (s, _, stats) = propose(&p, &inputs, (95.0, 0.0), 90.0);
    assert_eq!(s, QueryState::Failed);
    assert_eq!((stats.bridges, stats.tunnels), (0, 0));
}

/// A whole network across a park strip from x = 300 to 450 (highways start at the
/// origin, heading east and west).
fn city(inputs: &RoadInputs, max_tunnel_length_m: f64) -> Generated {
    let p = RoadParams {
        start: Some([0.0, 0.0]),
        start_angle_deg: Some(0.0),
        max_segments: 1200,
        max_tunnel_length_m,
        ..RoadParams::default()
    };
    generate(&p, inputs).unwrap()
}

/// Every tunnel edge of `net`: (start, end) positions.
fn tunnels(net: &RoadNetwork) -> Vec<(DVec2, DVec2)> {
    net.edges()
        .filter(|(_, _, _, r)| r.tunnel)
        .map(|(e, _, _, _)| net.segment(e).unwrap())
        .collect()
}

#[test]
fn a_city_tunnels_under_its_park_and_nothing_meets_the_tunnel() {
    let inputs = park_strip(300.0, 450.0);
    let g = city(&inputs, 300.0);
    let net = &g.network;
    net.check_invariants().unwrap();
    let t = tunnels(net);
    assert!(!t.is_empty(), "a highway crosses the park in a tunnel");
    let legality = Legality::new(&inputs, &RoadParams::default());
    for (e, u, v, r) in net.edges() {
        if !r.tunnel {
            continue;
        }
        assert!(!r.bridge && r.class == RoadClass::Highway);
        assert!(net.edge_length(e).unwrap() <= 300.0 + 1e-9);
        let (a, b) = net.segment(e).unwrap();
        assert!(tunnelable(&legality, a, b, false) || tunnelable(&legality, b, a, false));
        // Both ends on legal ground: no road joins the tunnel inside the park.
        for n in [u, v] {
            assert_eq!(legality.point(net.position(n).unwrap()), None);
        }
    }
    // No junction inside the park: nothing crosses or joins the tunnel there.
    for (_, p, _) in net.nodes() {
        assert_ne!(legality.point(p), Some(Illegal::Park), "{p:?}");
    }
    // The city reaches beyond the park; two portals per tunnel, frames closed solids.
    assert!(net.nodes().any(|(_, p, _)| p.x > 500.0));
    let portals = portals(net).unwrap();
    assert_eq!(portals.len(), 2 * t.len());
    for q in &portals {
        assert!((q.into.length() - 1.0).abs() < 1e-9);
        assert_eq!(legality.point(q.position), None);
    }
    // Each portal's frame is three closed boxes.
    let mesh = portal_mesh(net, &Constant(0.0)).unwrap().unwrap();
    mesh.validate().unwrap();
    assert_eq!(mesh.triangle_count(), 3 * 12 * portals.len());
    assert!(network_stats(net).tunnel_length_m > 0.0);
    assert!(g.report.constraints.tunnels >= t.len());
}

#[test]
fn without_tunnels_the_park_stops_the_city() {
    let inputs = park_strip(300.0, 450.0);
    for limit in [0.0, 100.0] {
        let g = city(&inputs, limit);
        assert!(tunnels(&g.network).is_empty());
        assert!(
            g.network.nodes().all(|(_, p, _)| p.x < 300.0),
            "limit {limit}: nothing beyond the park"
        );
        assert!(portal_mesh(&g.network, &Constant(0.0)).unwrap().is_none());
    }
}

#[test]
fn a_city_tunnels_through_its_ridge() {
    // 80 m over 75 m each side (grade 1.07): no road climbs it.
    let inputs = ridge(375.0, 75.0, 80.0);
    let g = city(&inputs, 300.0);
    g.network.check_invariants().unwrap();
    let legality = Legality::new(&inputs, &RoadParams::default());
    let t = tunnels(&g.network);
    assert!(!t.is_empty());
    for (a, b) in t {
        assert!(
            tunnelable(&legality, a, b, false) || tunnelable(&legality, b, a, false),
            "{a} {b}: {} {}",
            legality.elevation(a),
            legality.elevation(b)
        );
    }
    assert!(g.network.nodes().any(|(_, p, _)| p.x > 500.0));
    // No road of the city climbs the ridge's flanks (every other edge is legal).
    for (e, _, _, r) in g.network.edges() {
        if !r.tunnel {
            let (a, b) = g.network.segment(e).unwrap();
            assert!(legality.segment_ok(a, b) || legality.segment_ok(b, a));
        }
    }
}

#[test]
fn a_park_over_the_whole_map_has_no_legal_start() {
    let mut inputs = RoadInputs::flat(Arc::new(Constant(0.5)));
    inputs.parks = Arc::new(Constant(1.0));
    let err = generate(&RoadParams::default(), &inputs).unwrap_err();
    assert!(matches!(err, RoadError::NoLegalStart), "{err}");
    // A start given inside it: a typed error naming `start`.
    let p = RoadParams {
        start: Some([0.0, 0.0]),
        ..RoadParams::default()
    };
    let err = generate(&p, &inputs).unwrap_err();
    assert!(
        matches!(err, RoadError::InvalidParameter { name: "start", .. }),
        "{err}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// For any park strip and start before it: a proposal is a tunnel only within the
    /// limit, from legal ground to legal ground, never under water, never also a bridge.
    #[test]
    fn tunnels_keep_their_limits(
        lo in 60.0f64..200.0,
        width in 1.0f64..400.0,
        start in 0.0f64..55.0,
        len in 40.0f64..260.0,
        limit in 0.0f64..400.0,
    ) {
        let p = RoadParams { max_tunnel_length_m: limit, ..RoadParams::default() };
        let inputs = park_strip(lo, lo + width);
        let (s, r, _) = propose(&p, &inputs, (start, 0.0), len);
        let legality = Legality::new(&inputs, &p);
        if s == QueryState::Succeed && r.tunnel {
            prop_assert!(!r.bridge);
            prop_assert!(r.length <= limit + 1e-9);
            prop_assert!(tunnelable(&legality, r.start, r.end, false));
        }
        if s == QueryState::Succeed && !r.tunnel {
            prop_assert!(legality.segment_ok(r.start, r.end));
        }
        // A park narrower than the limit less the approach is always crossed.
        if (lo + width + 2.0 * legality.step()) - start < limit && lo - start < 0.5 * len {
            prop_assert_eq!(s, QueryState::Succeed);
        }
    }
}

/// Two highway tunnels and two streets leave one junction: each frame stands back from
/// the junction just far enough to keep clear of the streets' corridors and of the other
/// tunnel's frame; the frames are disjoint; a portal at a junction with no other road
/// stands at the junction.
#[test]
fn portal_frames_keep_clear_of_the_junctions_other_roads() {
    use polis_geom::measure::segment_distance;
    let mut net = RoadNetwork::new();
    let mut node = |x: f64, y: f64| net.add_node(DVec2::new(x, y), Junction::default()).unwrap();
    let (o, a, b, c, d) = (
        node(0.0, 0.0),
        node(200.0, 0.0),
        node(120.0, 90.0),
        node(-200.0, 30.0),
        node(10.0, -200.0),
    );
    let road = |class, width, tunnel| Road {
        class,
        width,
        bridge: false,
        tunnel,
        step: 0,
    };
    net.add_edge(o, a, road(RoadClass::Highway, 16.0, true))
        .unwrap();
    net.add_edge(o, b, road(RoadClass::Highway, 16.0, true))
        .unwrap();
    net.add_edge(o, c, road(RoadClass::Street, 8.0, false))
        .unwrap();
    net.add_edge(o, d, road(RoadClass::Street, 8.0, false))
        .unwrap();
    let portals = portals(&net).unwrap();
    assert_eq!(portals.len(), 4);
    let at_o: Vec<_> = portals.iter().filter(|p| p.node == o).collect();
    assert_eq!(at_o.len(), 2);
    let edges = |q: [DVec2; 4]| (0..4).map(move |i| (q[i], q[(i + 1) % 4]));
    for p in &at_o {
        assert!(p.setback > 0.0 && p.setback < 50.0, "{}", p.setback);
        // Clear of the streets' corridors.
        for far in [c, d] {
            let (s0, s1) = (DVec2::ZERO, net.position(far).unwrap());
            for (e0, e1) in edges(p.footprint()) {
                assert!(segment_distance(e0, e1, s0, s1) > 4.0);
            }
        }
        // The least such setback: a quarter metre nearer, something is in the way.
        let nearer = Portal {
            setback: p.setback - 0.25,
            ..**p
        };
        let in_way = [(c, 4.0), (d, 4.0), (a, 9.0), (b, 9.0)]
            .iter()
            .any(|&(far, reach)| {
                far != net.endpoints(p.edge).unwrap().1
                    && edges(nearer.footprint()).any(|(e0, e1)| {
                        segment_distance(e0, e1, DVec2::ZERO, net.position(far).unwrap()) <= reach
                    })
            });
        assert!(in_way, "setback {} is not the least", p.setback);
    }
    // The two frames at the junction do not meet.
    for (e0, e1) in edges(at_o[0].footprint()) {
        for (f0, f1) in edges(at_o[1].footprint()) {
            assert!(segment_distance(e0, e1, f0, f1) > 0.0);
        }
    }
    // The far portals have no other road: at their junctions.
    for p in portals.iter().filter(|p| p.node != o) {
        assert_eq!(p.setback, 0.0);
        assert_eq!(p.face(), p.position);
    }
    let mesh = portal_mesh(&net, &Constant(0.0)).unwrap().unwrap();
    mesh.validate().unwrap();
    assert_eq!(mesh.triangle_count(), 3 * 12 * portals.len());
}
