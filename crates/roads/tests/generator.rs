//! End-to-end properties of the generator (issue 6).

#![allow(clippy::unwrap_used)]

use std::sync::Arc;

use polis_geom::field::{Constant, FnField, Population, PopulationParams};
use polis_geom::{DVec2, Field};
use polis_lsystem::rand_pcg::Pcg64Mcg;
use polis_roads::legality::Legality;
use polis_roads::*;

fn flat_inputs(seed: u64) -> RoadInputs {
    let pop = Population::new(PopulationParams {
        seed,
        unit_m: 100.0,
    })
    .unwrap();
    RoadInputs::flat(Arc::new(pop))
}

fn edge_list(n: &RoadNetwork) -> Vec<(DVec2, DVec2, Road)> {
    n.edges()
        .map(|(e, _, _, r)| {
            let (a, b) = n.segment(e).unwrap();
            (a, b, *r)
        })
        .collect()
}

#[test]
fn every_pattern_gives_a_planar_network() {
    for pattern in [
        Pattern::Basic,
        Pattern::NewYork,
        Pattern::Paris,
        Pattern::SanFrancisco,
    ] {
        let params = RoadParams {
            pattern,
            max_segments: 800,
            ..RoadParams::default()
        };
        let city = generate_default(&params).unwrap();
        city.network.check_invariants().unwrap();
        assert!(
            city.report.segments > 100,
            "{pattern:?}: only {} segments",
            city.report.segments
        );
        assert!(city.report.segments <= 800);
        let st = network_stats(&city.network);
        assert!(
            st.highway_length_m > 0.0 && st.street_length_m > 0.0,
            "{pattern:?}: {st:?}"
        );
    }
}

#[test]
fn no_road_in_water_except_short_bridges() {
    let params = RoadParams {
        max_segments: 1500,
        ..RoadParams::default()
    };
    let inputs = RoadInputs::procedural(params.seed, &params).unwrap();
    let legality = Legality::new(&inputs, &params);
    let city = generate(&params, &inputs).unwrap();
    city.network.check_invariants().unwrap();
    let mut water_seen = false;
    for (a, b, road) in edge_list(&city.network) {
        let len = a.distance(b);
        if road.bridge {
            assert!(
                len <= params.max_bridge_length_m + 1e-6,
                "bridge of {len} m"
            );
            assert_eq!(road.class, RoadClass::Highway);
            continue;
        }
        // Samples at the legality spacing (what the constraints guarantee).
        let n = (len / params.legality_step_m).ceil().max(1.0) as usize;
        for i in 0..=n {
            let p = a + (b - a) * (i as f64 / n as f64);
            assert!(!legality.is_water(p), "road {a}–{b} in water at {p}");
        }
    }
    // The map does have water next to the city.
    for i in 0..200 {
        let p = DVec2::new(-2000.0 + 20.0 * i as f64, 0.0);
        water_seen |= legality.is_water(p);
    }
    assert!(water_seen);
}

#[test]
fn new_york_streets_follow_the_grid() {
    let grid = 17.0f64;
    let params = RoadParams {
        pattern: Pattern::NewYork,
        grid_angle_deg: grid,
        max_segments: 1500,
        ..RoadParams::default()
    };
    let city = generate(&params, &flat_inputs(3)).unwrap();
    city.network.check_invariants().unwrap();
    let (mut total, mut aligned) = (0.0, 0.0);
    for (a, b, road) in edge_list(&city.network) {
        if road.class != RoadClass::Street {
            continue;
        }
        let len = a.distance(b);
        let ang = (b - a).y.atan2((b - a).x).to_degrees();
        let off = (ang - grid).rem_euclid(90.0);
        let off = off.min(90.0 - off);
        total += len;
        if off <= 5.0 {
            aligned += len;
        }
    }
    assert!(total > 10_000.0, "street length {total}");
    assert!(
        aligned / total >= 0.8,
        "only {:.1}% on the grid",
        100.0 * aligned / total
    );
}

#[test]
fn paris_highways_are_radial_or_concentric() {
    let centre = DVec2::new(150.0, -100.0);
    let params = RoadParams {
        pattern: Pattern::Paris,
        paris_centre: Some(centre.to_array()),
        start: Some(centre.to_array()),
        highway_branch_probability: 0.25,
        max_segments: 1200,
        ..RoadParams::default()
    };
    let city = generate(&params, &flat_inputs(5)).unwrap();
    city.network.check_invariants().unwrap();
    let (mut total, mut ok) = (0.0, 0.0);
    let (mut radial, mut ring) = (0.0, 0.0);
    for (a, b, road) in edge_list(&city.network) {
        if road.class != RoadClass::Highway {
            continue;
        }
        let len = a.distance(b);
        let mid = (a + b) * 0.5 - centre;
        let cos = ((b - a).normalize().dot(mid.normalize())).abs();
        total += len;
        if cos >= 5f64.to_radians().cos() {
            ok += len;
            radial += len;
        } else if cos <= 5f64.to_radians().sin() {
            ok += len;
            ring += len;
        }
    }
    assert!(total > 2000.0, "highway length {total}");
    assert!(
        ok / total >= 0.8,
        "only {:.1}% radial/concentric",
        100.0 * ok / total
    );
    assert!(
        radial > 0.0 && ring > 0.0,
        "radial {radial} m, concentric {ring} m"
    );
}

#[test]
fn same_seed_same_network_other_seed_other_network() {
    let params = RoadParams {
        max_segments: 600,
        ..RoadParams::default()
    };
    let a = generate_default(&params).unwrap();
    let b = generate_default(&params).unwrap();
    assert_eq!(edge_list(&a.network), edge_list(&b.network));
    assert_eq!(a.report, b.report);
    let c = generate_default(&RoadParams { seed: 2, ..params }).unwrap();
    assert_ne!(edge_list(&a.network), edge_list(&c.network));
}

#[test]
fn stop_conditions() {
    let p = RoadParams {
        max_segments: 50,
        ..RoadParams::default()
    };
    let r = generate_default(&p).unwrap().report;
    assert_eq!(r.stop, StopReason::SegmentBudget);
    assert_eq!(r.segments, 50);
    let p = RoadParams {
        max_steps: 5,
        ..RoadParams::default()
    };
    let r = generate_default(&p).unwrap().report;
    assert_eq!(r.stop, StopReason::StepBudget);
    assert_eq!(r.steps, 5);
    // Nowhere to branch, nowhere populated: the two highways run out of the map.
    let p = RoadParams {
        highway_branch_probability: 0.0,
        ..RoadParams::default()
    };
    let r = generate(&p, &RoadInputs::flat(Arc::new(Constant(0.0)))).unwrap();
    assert_eq!(r.report.stop, StopReason::NothingLeft);
    assert!(r.report.segments >= 2);
    assert_eq!(network_stats(&r.network).street_length_m, 0.0);
}

/// A custom global goal: highways are pulled toward a landmark; everything else is the
/// default.
struct TowardLandmark {
    inner: DefaultGoals,
    landmark: DVec2,
}

impl GlobalGoals for TowardLandmark {
    fn axiom(&self) -> Vec<(RuleAttr, RoadAttr)> {
        self.inner.axiom()
    }
    fn successors(&self, rule: &RuleAttr, road: &RoadAttr, rng: &mut Pcg64Mcg) -> [Proposal; 3] {
        let mut out = self.inner.successors(rule, road, rng);
        if rule.class == RoadClass::Highway {
            let to = self.landmark - road.end;
            if to.length() > 1.0 {
                let a = to.y.atan2(to.x);
                out[0].road = RoadAttr::new(road.end, a, out[0].road.length, RoadClass::Highway);
            }
        }
        out
    }
}

#[test]
fn custom_goal_replaces_the_default() {
    let params = RoadParams {
        start: Some([-1500.0, -1500.0]),
        highway_branch_probability: 0.0,
        max_segments: 200,
        ..RoadParams::default()
    };
    let inputs = flat_inputs(9);
    let landmark = DVec2::new(1200.0, 1300.0);
    let goals = TowardLandmark {
        inner: DefaultGoals::new(&params, &inputs).unwrap(),
        landmark,
    };
    let city = RoadGenerator::new(&params, &inputs)
        .unwrap()
        .with_goals(Arc::new(goals))
        .run()
        .unwrap();
    city.network.check_invariants().unwrap();
    let closest = city
        .network
        .nodes()
        .map(|(_, p, _)| p.distance(landmark))
        .fold(f64::INFINITY, f64::min);
    assert!(closest <= params.highway_length_m, "closest {closest}");
}

#[test]
fn park_and_slope_are_avoided() {
    let params = RoadParams {
        max_segments: 800,
        max_slope: 0.05,
        ..RoadParams::default()
    };
    let park = FnField::new(|p: DVec2| if p.length() < 400.0 { 1.0 } else { 0.0 });
    let mut inputs = flat_inputs(4);
    inputs.parks = Arc::new(park);
    inputs.elevation = Arc::new(FnField::new(|p: DVec2| 0.2 * p.y.max(800.0)));
    let params = RoadParams {
        start: Some([700.0, 0.0]),
        ..params
    };
    let legality = Legality::new(&inputs, &params);
    let city = generate(&params, &inputs).unwrap();
    city.network.check_invariants().unwrap();
    for (a, b, road) in edge_list(&city.network) {
        assert!(!road.bridge);
        let len = a.distance(b);
        if len >= params.slope_step_m {
            assert!(
                legality.segment_ok(a, b) || legality.segment_ok(b, a),
                "{a}–{b}"
            );
        } else {
            // A piece shorter than the slope baseline (a segment split by a later
            // crossing) is held to the baseline's rise, as the sampled slope test was.
            let n = 8;
            for i in 0..=n {
                let p = a + (b - a) * (f64::from(i) / f64::from(n));
                assert!(legality.point(p).is_none(), "{p} on {a}–{b}");
            }
            let rise = (inputs.elevation.sample(b) - inputs.elevation.sample(a)).abs();
            assert!(
                rise <= params.max_slope * params.slope_step_m + 1e-9,
                "{a}–{b} rises {rise}"
            );
        }
    }
}

#[test]
fn blended_patterns_follow_their_weight_maps() {
    // Fig. 7: New York where x < 0, Paris where x > 0 (sharp switch at x = 0).
    let ny: Arc<dyn Field> = Arc::new(FnField::new(|p: DVec2| if p.x < 0.0 { 1.0 } else { 0.0 }));
    let paris: Arc<dyn Field> =
        Arc::new(FnField::new(|p: DVec2| if p.x < 0.0 { 0.0 } else { 1.0 }));
    let inputs =
        flat_inputs(3).with_pattern_weights(vec![(Pattern::NewYork, ny), (Pattern::Paris, paris)]);
    let centre = DVec2::new(1000.0, 0.0);
    let params = RoadParams {
        paris_centre: Some(centre.to_array()),
        max_segments: 2500,
        ..RoadParams::default()
    };
    let city = generate(&params, &inputs).unwrap();
    city.network.check_invariants().unwrap();
    let (mut west, mut west_grid, mut east, mut east_paris) = (0.0, 0.0, 0.0, 0.0);
    for (a, b, road) in edge_list(&city.network) {
        if road.class != RoadClass::Street {
            continue;
        }
        let (len, mid) = (a.distance(b), (a + b) * 0.5);
        let d = (b - a) / len;
        if a.x < -100.0 && b.x < -100.0 {
            west += len;
            let off = d.y.atan2(d.x).to_degrees().rem_euclid(90.0);
            if off.min(90.0 - off) <= 5.0 {
                west_grid += len;
            }
        } else if a.x > 100.0 && b.x > 100.0 {
            east += len;
            let cos = d.dot((mid - centre).normalize()).abs();
            if cos >= 5f64.to_radians().cos() || cos <= 5f64.to_radians().sin() {
                east_paris += len;
            }
        }
    }
    assert!(
        west > 5000.0 && east > 5000.0,
        "west {west} m, east {east} m"
    );
    assert!(
        west_grid / west >= 0.7,
        "west on grid {:.2}",
        west_grid / west
    );
    assert!(
        east_paris / east >= 0.6,
        "east radial/concentric {:.2}",
        east_paris / east
    );
}

/// The lattice-cached procedural maps (issue 6's speed work): for several seeds, every
/// non-bridge road is legal at every legality sample on the maps it was grown on (no
/// water, park, map edge), bridges are highways within the length limit that only cross
/// water, and against the raw (uncached) fBm maps a sample can be "in water" only within
/// the lattice's displacement of the raw coastline.
#[test]
fn lattice_maps_keep_every_legality_property() {
    for seed in 1..=3u64 {
        let params = RoadParams {
            seed,
            max_segments: 1200,
            ..RoadParams::default()
        };
        let inputs = RoadInputs::procedural(seed, &params).unwrap();
        let raw = RoadInputs::procedural_with_lattice(seed, &params, None).unwrap();
        let legality = Legality::new(&inputs, &params);
        let raw_legality = Legality::new(&raw, &params);
        let city = generate(&params, &inputs).unwrap();
        city.network.check_invariants().unwrap();
        let (mut samples, mut raw_wet) = (0usize, 0usize);
        for (a, b, road) in edge_list(&city.network) {
            let len = a.distance(b);
            if road.bridge {
                assert_eq!(road.class, RoadClass::Highway);
                assert!(
                    len <= params.max_bridge_length_m + 1e-6,
                    "bridge of {len} m"
                );
                assert!(
                    legality.bridgeable(a, b) || legality.bridgeable(b, a),
                    "bridge {a}–{b} crosses more than water"
                );
                continue;
            }
            let n = (len / params.legality_step_m).ceil().max(1.0) as usize;
            for i in 0..=n {
                let p = a + (b - a) * (i as f64 / n as f64);
                samples += 1;
                assert_eq!(legality.point(p), None, "seed {seed}: road {a}–{b} at {p}");
                if raw_legality.is_water(p) {
                    raw_wet += 1;
                    // Raw land within 12 m (the lattice moves the coast by ≤ ~9 m).
                    let near_land = (0..16).any(|k| {
                        let d = DVec2::from_angle(f64::from(k) * std::f64::consts::PI / 8.0);
                        (1..=48).any(|s| !raw_legality.is_water(p + d * (0.25 * f64::from(s))))
                    });
                    assert!(near_land, "seed {seed}: {p} is deep in the raw fBm sea");
                }
            }
        }
        assert!(samples > 10_000, "{samples}");
        assert!(
            raw_wet * 100 <= samples,
            "{raw_wet} of {samples} samples in raw water"
        );
    }
}

/// A start on a shore (issue 19, `default` seed 2): the sea counts no population for the
/// highway rays, though the population map goes on under it, and neither axiom highway
/// heads into water no bridge spans, so the network grows over the land instead of
/// stopping after a few segments.
#[test]
fn highways_leave_a_shore_start_over_land() {
    // Population peaks on the shore at the origin; the sea east of x = 20 m is 2 km wide.
    let pop = FnField::new(|p: DVec2| (-(p.length() / 800.0).powi(2)).exp());
    let mut inputs = RoadInputs::flat(Arc::new(pop));
    inputs.water = Arc::new(FnField::new(|p: DVec2| if p.x > 20.0 { 1.0 } else { 0.0 }));
    let params = RoadParams {
        max_segments: 400,
        ..RoadParams::default()
    };
    let goals = DefaultGoals::new(&params, &inputs).unwrap();
    let s = goals.start();
    assert!(s.x <= 20.0 && s.length() < 100.0, "{s}");
    // Eastward every ray sample lies in the sea: it scores nothing and is closed.
    assert_eq!(goals.ray_score(s, 0.0), 0.0);
    assert!(goals.ray_score(s, std::f64::consts::PI) > 0.0);
    assert!(!goals.ray_open(s, 0.0, true));
    assert!(goals.ray_open(s, std::f64::consts::PI, true));
    let axiom = goals.axiom();
    assert_eq!(axiom.len(), 2);
    for (_, road) in &axiom {
        assert!(
            goals.ray_open(road.start, road.angle, true),
            "{}",
            road.angle
        );
        let end = road.start + DVec2::from_angle(road.angle) * params.highway_length_m;
        assert!(end.x <= 20.0, "axiom highway into the sea: {end}");
    }
    // Both highways grow: the network is more than the axiom and its first branches.
    let g = generate(&params, &inputs).unwrap();
    let highways = g
        .network
        .edges()
        .filter(|(_, _, _, r)| r.class == RoadClass::Highway)
        .count();
    assert!(highways >= 6, "{highways} highway edges");
    assert_eq!(g.report.segments, 400);
    // Nothing was built in the sea (bridges excepted, and none spans 2 km).
    for (e, _, _, r) in g.network.edges() {
        let (a, b) = g.network.segment(e).unwrap();
        assert!(
            r.bridge || (a.x <= 20.0 + 1e-6 && b.x <= 20.0 + 1e-6),
            "{a} {b}"
        );
    }
}

/// A highway meeting a river late in its segment (issue 19, `manhattan`'s East River):
/// the constraints prune the segment to the shore and the next one bridges from there, so
/// the ray is open when the river is narrower than the bridge limit counted from the
/// shore, though the far shore lies beyond the limit counted from the highway's end; a
/// wider river stays closed. A highway sent across the narrow river crosses it.
#[test]
fn a_river_met_late_in_a_segment_is_bridged_from_the_shore() {
    let river = |far: f64| {
        let pop = FnField::new(|p: DVec2| (-(p.length() / 1500.0).powi(2)).exp());
        let mut inputs = RoadInputs::flat(Arc::new(pop));
        inputs.water = Arc::new(FnField::new(move |p: DVec2| {
            if p.x > 200.0 && p.x < far { 1.0 } else { 0.0 }
        }));
        inputs
    };
    let params = RoadParams {
        max_segments: 600,
        start: Some([0.0, 0.0]),
        start_angle_deg: Some(0.0),
        ..RoadParams::default()
    };
    // The shore lies 200 m ahead, past the prune limit (half of a 240 m segment); the
    // bridge limit is 400 m.
    assert!(params.highway_length_m * (1.0 - params.max_prune_factor) < 200.0);
    assert_eq!(params.max_bridge_length_m, 400.0);
    let p = DVec2::ZERO;
    let narrow = river(550.0);
    let goals = DefaultGoals::new(&params, &narrow).unwrap();
    assert!(goals.ray_open(p, 0.0, true), "350 m river from the shore");
    let wide = river(650.0);
    let closed = DefaultGoals::new(&params, &wide).unwrap();
    assert!(!closed.ray_open(p, 0.0, true), "450 m river");
    // A highway sent at it is pruned to the shore and bridges from there: the network
    // reaches the far bank.
    let g = generate(&params, &narrow).unwrap();
    let bridges: Vec<(DVec2, DVec2)> = g
        .network
        .edges()
        .filter(|(_, _, _, r)| r.bridge)
        .map(|(e, _, _, _)| g.network.segment(e).unwrap())
        .collect();
    assert!(!bridges.is_empty());
    for (a, b) in &bridges {
        assert!(
            a.distance(*b) <= params.max_bridge_length_m + 1e-6,
            "{a} {b}"
        );
    }
    let far_bank = g
        .network
        .edges()
        .filter(|(e, _, _, r)| {
            !r.bridge
                && g.network
                    .segment(*e)
                    .is_ok_and(|(a, b)| a.x >= 550.0 && b.x >= 550.0)
        })
        .count();
    assert!(far_bank > 0, "no road on the far bank");
}
