use super::*;
use crate::network::{Junction, Road};
use polis_geom::field::{Fbm, FbmParams, FieldExt, FnField};
use proptest::prelude::*;

fn road(class: RoadClass, width: f64, bridge: bool) -> Road {
    Road {
        class,
        width,
        bridge,
        tunnel: false,
        step: 0,
    }
}

/// A street from `a` to `b` through the given points.
fn chain(net: &mut RoadNetwork, pts: &[DVec2], r: Road) {
    let ids: Vec<_> = pts
        .iter()
        .map(|&p| net.add_node(p, Junction::default()).unwrap())
        .collect();
    for w in ids.windows(2) {
        net.add_edge(w[0], w[1], r).unwrap();
    }
}

fn grid(n: usize, step: f64) -> RoadNetwork {
    let mut net = RoadNetwork::new();
    let mut ids = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let p = DVec2::new(i as f64 * step, j as f64 * step);
            ids.push(net.add_node(p, Junction::default()).unwrap());
        }
    }
    for j in 0..n {
        for i in 0..n {
            let class = if j == n / 2 {
                RoadClass::Highway
            } else {
                RoadClass::Street
            };
            if i + 1 < n {
                net.add_edge(ids[j * n + i], ids[j * n + i + 1], road(class, 8.0, false))
                    .unwrap();
            }
            if j + 1 < n {
                net.add_edge(
                    ids[j * n + i],
                    ids[(j + 1) * n + i],
                    road(RoadClass::Street, 6.0, false),
                )
                .unwrap();
            }
        }
    }
    net
}

fn check_grades(g: &GradedGround<'_>, params: &GradeParams) {
    for p in g.pieces() {
        let len = p.a.distance(p.b);
        let limit = params.max_grade(p.class) * len;
        assert!(
            (p.hb - p.ha).abs() <= limit + 1e-9 * (1.0 + p.ha.abs()),
            "{p:?}"
        );
    }
    assert!(
        g.earthworks.steepest_grade <= params.max_grade_street.max(params.max_grade_highway) + 1e-9
    );
}

#[test]
fn gentle_ground_is_followed_exactly_and_moves_nothing() {
    let ground = FnField(|p: DVec2| 10.0 + 0.02 * p.x + 0.01 * p.y);
    let net = grid(5, 80.0);
    let params = GradeParams {
        smoothing_passes: 0,
        ..GradeParams::default()
    };
    let g = grade_roads(&net, &ground, &params).unwrap();
    assert!(!g.moves_ground());
    // Cut in: half a metre under a corridor, tapering to nothing 2 m beyond it.
    let cut = g.cut_in(0.5, 1.0, 1.0);
    let on_street = DVec2::new(80.0, 40.0); // on the street x = 80
    assert!((cut.sample(on_street) - (ground.sample(on_street) - 0.5)).abs() < 1e-9);
    let beside = DVec2::new(80.0 + 3.0 + 1.5, 40.0); // half width 3, 1.5 m beyond
    assert!((cut.sample(beside) - (ground.sample(beside) - 0.25)).abs() < 1e-9);
    let away = DVec2::new(80.0 + 3.0 + 2.5, 40.0);
    assert_eq!(cut.sample(away), ground.sample(away));
    // The terrain may sag by the depth over the whole cut (2 m beyond the corridor),
    // tapering to nothing one more taper (1 m) out.
    let slack = cut.slack();
    assert_eq!(slack.sample(on_street), 0.5);
    assert_eq!(slack.sample(beside), 0.5);
    assert!((slack.sample(away) - 0.25).abs() < 1e-9);
    let tapering = DVec2::new(80.0 + 3.0 + 2.0 + 0.25, 40.0);
    assert!((slack.sample(tapering) - 0.375).abs() < 1e-9);
    let past = DVec2::new(80.0 + 3.0 + 3.0 + 0.01, 40.0);
    assert_eq!(slack.sample(past), 0.0);
    assert_eq!(g.earthworks.cut_m3, 0.0);
    assert_eq!(g.earthworks.fill_m3, 0.0);
    for p in g.pieces() {
        assert!((p.ha - ground.sample(p.a)).abs() < 1e-9);
    }
    let q = DVec2::new(37.0, 41.0);
    assert_eq!(g.sample(q), ground.sample(q));
}

#[test]
fn a_steep_valley_is_filled_within_the_grade_and_banked() {
    // A 20 m deep V valley across a 400 m street: the road may drop 0.15 m per metre.
    let ground = FnField(|p: DVec2| (p.x.abs() * 0.5).min(20.0));
    let mut net = RoadNetwork::new();
    chain(
        &mut net,
        &[DVec2::new(-200.0, 0.0), DVec2::new(200.0, 0.0)],
        road(RoadClass::Street, 8.0, false),
    );
    let params = GradeParams {
        smoothing_passes: 0,
        ..GradeParams::default()
    };
    let g = grade_roads(&net, &ground, &params).unwrap();
    check_grades(&g, &params);
    assert!(g.moves_ground());
    assert!(
        g.earthworks.fill_m3 > 0.0 && g.earthworks.cut_m3 > 0.0,
        "{:?}",
        g.earthworks
    );
    // On the centre line the ground is the road; beside the corridor a 1:2 bank.
    let at0 = g.sample(DVec2::ZERO);
    assert!(at0 > 5.0, "the valley floor is filled: {at0}");
    let road_h = g
        .pieces()
        .iter()
        .find(|p| p.a.x <= 0.0 && p.b.x >= 0.0)
        .unwrap();
    let t = (0.0 - road_h.a.x) / (road_h.b.x - road_h.a.x);
    assert!((at0 - road_h.height_at(t)).abs() < 1e-9);
    let bank = g.sample(DVec2::new(0.0, 4.0 + 2.0));
    assert!((bank - (at0 - 1.0)).abs() < 1e-6, "{bank} vs {at0}");
    // Far from the road the ground is natural.
    let far = DVec2::new(0.0, 100.0);
    assert_eq!(g.sample(far), ground.sample(far));
    // The volume against a numerical integral of (graded − ground).
    let (mut fill, mut cut) = (0.0, 0.0);
    let h = 0.5;
    let mut y = -60.0;
    while y < 60.0 {
        let mut x = -200.0;
        while x < 200.0 {
            let p = DVec2::new(x + h / 2.0, y + h / 2.0);
            let d = g.sample(p) - ground.sample(p);
            if d > 0.0 {
                fill += d * h * h
            } else {
                cut -= d * h * h
            }
            x += h;
        }
        y += h;
    }
    let w = g.earthworks;
    assert!(
        (w.fill_m3 - fill).abs() < 0.15 * fill,
        "{} vs {fill}",
        w.fill_m3
    );
    assert!(
        (w.cut_m3 - cut).abs() < 0.25 * cut.max(50.0),
        "{} vs {cut}",
        w.cut_m3
    );
}

/// Where a cut's bank would run past its widest, the ground steepens into a wall face
/// and lets go of the road continuously: no step for a terrain or a road surface.
#[test]
fn a_bank_past_its_widest_ends_in_a_continuous_wall_face() {
    // The ground climbs along the road faster than a highway may, and three times as
    // fast across it as a bank: the cut's banks never meet it.
    let ground = FnField(|p: DVec2| 0.3 * p.x + 1.5 * p.y.abs());
    let mut net = RoadNetwork::new();
    let pts: Vec<DVec2> = (0..=8)
        .map(|i| DVec2::new(-200.0 + 50.0 * f64::from(i), 0.0))
        .collect();
    chain(&mut net, &pts, road(RoadClass::Highway, 8.0, false));
    let params = GradeParams::default();
    let g = grade_roads(&net, &ground, &params).unwrap();
    check_grades(&g, &params);
    let x = 150.0;
    let piece = g
        .pieces()
        .iter()
        .find(|p| p.a.x <= x && x <= p.b.x)
        .unwrap();
    let r = piece.height_at((x - piece.a.x) / (piece.b.x - piece.a.x));
    assert!(
        ground.sample(DVec2::new(x, 0.0)) - r > 5.0,
        "a cut at x = {x}"
    );
    let (hw, m, s) = (4.0, params.max_embankment_m, params.embankment_slope);
    // On the bank: the road's height plus the bank's rise.
    let on_bank = g.sample(DVec2::new(x, hw + 0.5 * m));
    assert!((on_bank - (r + s * 0.5 * m)).abs() < 1e-6, "{on_bank}");
    // Across the bank's edge and the wall band, in 1 cm steps: no jump.
    let mut prev = g.sample(DVec2::new(x, hw + m - 1.0));
    let steps = ((RETAINING_WALL_M + 2.0) / 0.01) as usize;
    let mut steepest = 0.0f64;
    for k in 1..=steps {
        let y = hw + m - 1.0 + 0.01 * k as f64;
        let h = g.sample(DVec2::new(x, y));
        let ground_h = ground.sample(DVec2::new(x, y));
        assert!(h <= ground_h + 1e-9, "a cut never rises above the ground");
        steepest = steepest.max((h - prev).abs() / 0.01);
        prev = h;
    }
    // The gap the wall closes (tens of metres here) would be one step without the face;
    // with it, no centimetre climbs more than a fortieth of it (the face is steepest
    // where it meets the ground: about gap² / (slope · RETAINING_WALL_M²)).
    let edge = DVec2::new(x, hw + m);
    let gap = ground.sample(edge) - (r + s * m);
    assert!(gap > 20.0, "gap {gap}");
    assert!(
        steepest * 0.01 < gap / 40.0,
        "steepest {steepest} m/m for a gap of {gap} m"
    );
    // Past the band the ground is left alone.
    let past = DVec2::new(x, hw + m + RETAINING_WALL_M + 1.0);
    assert_eq!(g.sample(past), ground.sample(past));
}

#[test]
fn a_grade_limit_of_zero_levels_each_network() {
    let ground = FnField(|p: DVec2| 0.1 * p.x);
    let net = grid(3, 50.0);
    let params = GradeParams {
        max_grade_highway: 0.0,
        max_grade_street: 0.0,
        ..GradeParams::default()
    };
    let g = grade_roads(&net, &ground, &params).unwrap();
    let h0 = g.pieces()[0].ha;
    for p in g.pieces() {
        assert!(p.ha.is_finite() && (p.ha - h0).abs() < 1e-9 && (p.hb - h0).abs() < 1e-9);
    }
}

#[test]
fn bridges_leave_the_ground_alone_and_run_at_their_ends_grade() {
    // Land at 10 m, a 60 m bridge over a 30 m deep channel.
    let ground = FnField(|p: DVec2| if p.x.abs() < 30.0 { -20.0 } else { 10.0 });
    let mut net = RoadNetwork::new();
    chain(
        &mut net,
        &[DVec2::new(-100.0, 0.0), DVec2::new(-30.0, 0.0)],
        road(RoadClass::Street, 8.0, false),
    );
    chain(
        &mut net,
        &[DVec2::new(30.0, 0.0), DVec2::new(100.0, 0.0)],
        road(RoadClass::Street, 8.0, false),
    );
    let a = net.nearest_node(DVec2::new(-30.0, 0.0), 0.1).unwrap().0;
    let b = net.nearest_node(DVec2::new(30.0, 0.0), 0.1).unwrap().0;
    net.add_edge(a, b, road(RoadClass::Street, 8.0, true))
        .unwrap();
    let g = grade_roads(&net, &ground, &GradeParams::default()).unwrap();
    for p in g.pieces().iter().filter(|p| p.bridge) {
        assert!(p.ha > 5.0 && p.hb > 5.0, "the deck stays up: {p:?}");
    }
    // Under the deck the channel keeps its depth.
    assert_eq!(g.sample(DVec2::new(0.0, 0.0)), -20.0);
}

#[test]
fn bad_parameters_and_ground_are_errors() {
    let net = grid(2, 50.0);
    let flat = FnField(|_| 0.0);
    for bad in [
        GradeParams {
            max_grade_street: -0.1,
            ..GradeParams::default()
        },
        GradeParams {
            max_grade_highway: f64::NAN,
            ..GradeParams::default()
        },
        GradeParams {
            sample_m: 0.0,
            ..GradeParams::default()
        },
        GradeParams {
            embankment_slope: 0.0,
            ..GradeParams::default()
        },
        GradeParams {
            smoothing_passes: 1000,
            ..GradeParams::default()
        },
    ] {
        assert!(grade_roads(&net, &flat, &bad).is_err(), "{bad:?}");
    }
    let nan = FnField(|p: DVec2| if p.x > 10.0 { f64::NAN } else { 0.0 });
    assert!(grade_roads(&net, &nan, &GradeParams::default()).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// On any ground and grade limits, every piece keeps its class's limit and the
    /// conformed ground is finite.
    #[test]
    fn every_piece_keeps_its_grade(
        seed in 0u64..500,
        amplitude in 0.0f64..200.0,
        street in 0.0f64..0.3,
        highway in 0.0f64..0.2,
        passes in 0u32..4,
    ) {
        let fbm = Fbm::new(FbmParams { seed, wavelength_m: 300.0, octaves: 3, ..FbmParams::default() }).unwrap();
        let ground = fbm.scaled(amplitude);
        let net = grid(4, 70.0);
        let params = GradeParams { max_grade_street: street, max_grade_highway: highway, smoothing_passes: passes, ..GradeParams::default() };
        let g = grade_roads(&net, &ground, &params).unwrap();
        check_grades(&g, &params);
        prop_assert!(g.earthworks.cut_m3 >= 0.0 && g.earthworks.fill_m3 >= 0.0);
        for k in 0..50 {
            let p = DVec2::new(f64::from(k) * 4.3, f64::from(k * 7 % 50) * 4.1);
            prop_assert!(g.sample(p).is_finite());
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// A batch of points, close together or spread over the map and beyond it, gets the
    /// values of one sample each, bit for bit, from the graded ground, its cut-in and the
    /// cut-in's slack.
    #[test]
    fn sampling_many_points_is_sampling_each(
        seed in 0u64..500,
        amplitude in 10.0f64..120.0,
        centre_x in -40.0f64..260.0,
        centre_y in -40.0f64..260.0,
        spread in 0.0f64..200.0,
        margin in 0.0f64..3.0,
        taper in 0.0f64..6.0,
    ) {
        let fbm = Fbm::new(FbmParams { seed, wavelength_m: 150.0, octaves: 3, ..FbmParams::default() }).unwrap();
        let ground = fbm.scaled(amplitude);
        let net = grid(4, 70.0);
        let g = grade_roads(&net, &ground, &GradeParams::default()).unwrap();
        prop_assert!(g.moves_ground());
        let cut = g.cut_in(0.3, margin, taper);
        let slack = cut.slack();
        let points: Vec<DVec2> = (0..41u32)
            .map(|k| {
                let a = f64::from(k) * 2.399;
                DVec2::new(centre_x, centre_y) + DVec2::new(a.cos(), a.sin()) * spread * f64::from(k) / 40.0
            })
            .collect();
        for field in [&g as &dyn Field, &cut, &slack] {
            let mut many = vec![f64::NAN; points.len()];
            field.sample_many(&points, &mut many);
            for (p, v) in points.iter().zip(&many) {
                prop_assert_eq!(v.to_bits(), field.sample(*p).to_bits(), "at {}", p);
            }
        }
    }
}
