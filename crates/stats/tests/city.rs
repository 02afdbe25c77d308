//! Block, lot, building and defect metrics on hand-built cities; the reference table and
//! the realism comparison.

#![allow(clippy::unwrap_used)]

use polis_geom::field::Constant;
use polis_geom::{Aabb2, DVec2, Field, Polygon, PolygonWithHoles};
use polis_stats::{
    Band, BuildingInput, CityInput, LotInput, StatsError, StatsOptions, StreetClass, StreetEdge,
    StreetGraph, reference_cities, reference_city,
};

fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
    Polygon::rect(DVec2::new(x0, y0), DVec2::new(x1, y1))
}

fn street(a: usize, b: usize, width_m: f64) -> StreetEdge {
    StreetEdge {
        a,
        b,
        width_m,
        class: StreetClass::Street,
        bridge: false,
    }
}

#[test]
fn block_shape_factor() {
    let square = PolygonWithHoles::from(rect(0.0, 0.0, 100.0, 100.0));
    let long = PolygonWithHoles::from(rect(0.0, 0.0, 400.0, 10.0));
    let disc = PolygonWithHoles::from(Polygon::regular(720, DVec2::ZERO, 50.0));
    let empty = PolygonWithHoles::from(Polygon::new(vec![]));
    let blocks = [&square, &long, &disc, &empty];
    let b = polis_stats::parcels::block_metrics(&blocks);
    assert_eq!(b.count, 4);
    assert_eq!(b.degenerate, 1);
    let phis: Vec<f64> = blocks[..3]
        .iter()
        .map(|p| {
            polis_stats::parcels::block_metrics(&[*p])
                .shape_factor
                .median
        })
        .collect();
    assert!(
        (phis[0] - 2.0 / std::f64::consts::PI).abs() < 1e-12,
        "{phis:?}"
    );
    let long_phi = 4000.0 / (std::f64::consts::PI * (200.0f64.powi(2) + 25.0));
    assert!((phis[1] - long_phi).abs() < 1e-12);
    assert!(phis[2] > 0.999 && phis[2] <= 1.0);
    assert_eq!(b.shape_factor_histogram.counts[0], 1);
    assert_eq!(b.shape_factor_histogram.counts[6], 1);
    assert_eq!(b.shape_factor_histogram.counts[9], 1);
    assert_eq!(b.area_m2.max, 10_000.0);
    // A block with a hole: area net of the hole, circle of the outer ring.
    let holed = PolygonWithHoles::new(
        rect(0.0, 0.0, 100.0, 100.0),
        vec![{
            let mut h = rect(40.0, 40.0, 60.0, 60.0);
            h.make_cw();
            h
        }],
    );
    let b = polis_stats::parcels::block_metrics(&[&holed]);
    assert_eq!(b.area_m2.total, 9600.0);
    assert!((b.shape_factor.median - 0.96 * 2.0 / std::f64::consts::PI).abs() < 1e-12);
}

/// A rectangle `w × h` turned by `deg` about `at`, counter-clockwise.
fn turned_rect(w: f64, h: f64, deg: f64, at: DVec2) -> PolygonWithHoles {
    let (sn, c) = deg.to_radians().sin_cos();
    let pts = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)]
        .iter()
        .map(|&(x, y)| at + DVec2::new(x * c - y * sn, x * sn + y * c))
        .collect();
    PolygonWithHoles::from(Polygon::new(pts))
}

#[test]
fn block_long_axis() {
    use polis_stats::parcels::{block_metrics, long_axis};
    // A 240 × 80 m block turned by 165°: long axis at 165°, elongation (9 − 1) / 10.
    let b = turned_rect(240.0, 80.0, 165.0, DVec2::new(500.0, -300.0));
    let (angle, elongation, area) = long_axis(b.outer.points()).unwrap();
    assert!(
        (angle.to_degrees().rem_euclid(180.0) - 165.0).abs() < 1e-9,
        "{angle}"
    );
    assert!((elongation - 0.8).abs() < 1e-12, "{elongation}");
    assert!((area - 19_200.0).abs() < 1e-9);
    // Clockwise rings give the same axis.
    let mut cw = b.outer.clone();
    cw.make_cw();
    let (a2, e2, _) = long_axis(cw.points()).unwrap();
    assert!((a2 - angle).abs() < 1e-9 && (e2 - elongation).abs() < 1e-12);
    // A square has no long axis to vote with.
    let sq = turned_rect(100.0, 100.0, 20.0, DVec2::ZERO);
    assert!(long_axis(sq.outer.points()).unwrap().1 < 1e-9);
    // A grid of blocks long the same way (axes 10° and 190° agree): order 1; squares
    // and an empty ring do not change it.
    let blocks = [
        turned_rect(200.0, 60.0, 10.0, DVec2::ZERO),
        turned_rect(150.0, 70.0, 190.0, DVec2::new(400.0, 0.0)),
        sq.clone(),
        PolygonWithHoles::from(Polygon::new(vec![])),
    ];
    let refs: Vec<&PolygonWithHoles> = blocks.iter().collect();
    let m = block_metrics(&refs);
    assert!((m.long_axis_deg - 10.0).abs() < 1e-9, "{}", m.long_axis_deg);
    assert!(
        (m.long_axis_order - 1.0).abs() < 1e-12,
        "{}",
        m.long_axis_order
    );
    // Two equal blocks at right angles: no common direction.
    let cross = [
        turned_rect(200.0, 50.0, 0.0, DVec2::ZERO),
        turned_rect(200.0, 50.0, 90.0, DVec2::new(500.0, 0.0)),
    ];
    let refs: Vec<&PolygonWithHoles> = cross.iter().collect();
    assert!(block_metrics(&refs).long_axis_order < 1e-9);
    assert_eq!(block_metrics(&[]).long_axis_order, 0.0);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

    /// Any elongated rectangle, anywhere, turned any way: its long axis is its turn (mod
    /// 180°) and its elongation `(w² − h²) / (w² + h²)`.
    #[test]
    fn a_rectangles_long_axis_is_its_turn(
        w in 20.0f64..400.0,
        ratio in 0.1f64..0.8,
        deg in 0.0f64..360.0,
        x in -3000.0f64..3000.0,
        y in -3000.0f64..3000.0,
    ) {
        let h = w * ratio;
        let b = turned_rect(w, h, deg, DVec2::new(x, y));
        let (angle, elongation, _) = polis_stats::parcels::long_axis(b.outer.points()).unwrap();
        let d = (angle.to_degrees() - deg).rem_euclid(180.0);
        proptest::prop_assert!(d.min(180.0 - d) < 1e-6, "{} vs {}", angle.to_degrees(), deg);
        let want = (w * w - h * h) / (w * w + h * h);
        proptest::prop_assert!((elongation - want).abs() < 1e-9);
    }
}

#[test]
fn lot_frontage_depth_and_buildings() {
    let a = rect(0.0, 0.0, 10.0, 30.0);
    let b = rect(10.0, 0.0, 30.0, 30.0);
    let c = rect(0.0, 30.0, 30.0, 40.0);
    let edges_a = [0usize];
    let edges_b = [0usize, 1];
    let lots = [
        LotInput {
            polygon: &a,
            street_edges: &edges_a,
        },
        LotInput {
            polygon: &b,
            street_edges: &edges_b,
        },
        LotInput {
            polygon: &c,
            street_edges: &[],
        },
    ];
    let l = polis_stats::parcels::lot_metrics(&lots);
    assert_eq!(l.count, 3);
    assert_eq!(l.with_street_access, 2);
    assert!((l.street_access_share - 2.0 / 3.0).abs() < 1e-12);
    // Lot a: 10 m frontage, 30 m deep. Lot b: 20 + 30 m of frontage, its longest street
    // edge is the 30 m side, so it is 20 m deep.
    assert_eq!(l.frontage_m.min, 10.0);
    assert_eq!(l.frontage_m.max, 50.0);
    assert_eq!(l.depth_m.min, 20.0);
    assert_eq!(l.depth_m.max, 30.0);

    let fa = rect(2.0, 2.0, 8.0, 22.0);
    let fb = rect(12.0, 2.0, 28.0, 12.0);
    let buildings = [
        BuildingInput {
            footprint: &fa,
            height_m: 9.0,
            floors: 3,
            kind: "House",
        },
        BuildingInput {
            footprint: &fb,
            height_m: 100.0,
            floors: 30,
            kind: "Skyscraper",
        },
    ];
    let lot_area = 300.0 + 600.0 + 300.0;
    let m = polis_stats::parcels::building_metrics(&buildings, lot_area, 10_000.0);
    assert_eq!(m.count, 2);
    assert!((m.coverage - 280.0 / lot_area).abs() < 1e-12);
    assert!((m.ground_coverage - 0.028).abs() < 1e-12);
    assert!((m.floor_area_ratio - (120.0 * 3.0 + 160.0 * 30.0) / lot_area).abs() < 1e-12);
    assert_eq!(m.kinds.get("House"), Some(&1));
    assert_eq!(m.height_histogram.counts, vec![1, 0, 0, 0, 1, 0]);
}

/// A 200 m square block between four streets, a dead-end filament from its south edge
/// into its middle, a stub at the map edge, lots along the west half only, one building
/// in the corridor of the south street.
#[test]
fn plan_defects_on_a_hand_built_city() {
    let nodes = vec![
        DVec2::new(0.0, 0.0),     // 0
        DVec2::new(200.0, 0.0),   // 1
        DVec2::new(200.0, 200.0), // 2
        DVec2::new(0.0, 200.0),   // 3
        DVec2::new(150.0, 0.0),   // 4: filament start on the south street
        DVec2::new(150.0, 100.0), // 5: filament dead end inside the block
        DVec2::new(0.0, -95.0),   // 6: stub to the map edge (bounds y = -100)
        DVec2::new(-60.0, 200.0), // 7: stub ending in land, west
    ];
    let w = 10.0;
    let g = StreetGraph {
        nodes,
        elevations: None,
        edges: vec![
            street(0, 4, w),
            street(4, 1, w),
            street(1, 2, w),
            street(2, 3, w),
            street(3, 0, w),
            street(4, 5, w),
            street(0, 6, w),
            street(3, 7, w),
        ],
    };
    let block = PolygonWithHoles::from(rect(5.0, 5.0, 195.0, 195.0));
    let blocks = [&block];
    // Lots along the west edge of the block only.
    let lot_polys: Vec<Polygon> = (0..5)
        .map(|i| rect(5.0, 5.0 + 38.0 * i as f64, 35.0, 43.0 + 38.0 * i as f64))
        .collect();
    let lots: Vec<LotInput<'_>> = lot_polys
        .iter()
        .map(|p| LotInput {
            polygon: p,
            street_edges: &[3],
        })
        .collect();
    // One footprint reaching 2 m into the south street's 5 m half-width; one clear.
    let bad = rect(100.0, 3.0, 110.0, 20.0);
    let good = rect(10.0, 10.0, 30.0, 30.0);
    let buildings = [
        BuildingInput {
            footprint: &bad,
            height_m: 10.0,
            floors: 3,
            kind: "House",
        },
        BuildingInput {
            footprint: &good,
            height_m: 10.0,
            floors: 3,
            kind: "House",
        },
    ];
    let city = CityInput {
        streets: &g,
        blocks: &blocks,
        lots: &lots,
        buildings: &buildings,
        bounds: Some(Aabb2::new(DVec2::splat(-100.0), DVec2::splat(300.0))),
        land_area_m2: Some(160_000.0),
        water: None,
    };
    let r = polis_stats::report(&city, &StatsOptions::default()).unwrap();
    let d = &r.defects;
    assert_eq!(d.segments_inside_blocks, 1);
    assert!((d.length_inside_blocks_m - 100.0).abs() < 1e-9);
    assert_eq!(d.segments_inside_blocks_without_lots, 1);
    assert!((d.length_inside_blocks_without_lots_m - 100.0).abs() < 1e-9);
    assert_eq!(d.stubs, 3);
    assert_eq!(d.stubs_at_map_edge, 1);
    assert_eq!(d.stubs_in_land, 2);
    // The west stub starts at the block's north-west corner where lots stand: it has
    // lots along its first metres. The filament has none.
    assert_eq!(d.stubs_in_land_without_lots, 1);
    assert_eq!(d.buildings_in_road_corridor, 1);
    assert_eq!(d.buildings_in_road_corridor_share, 0.5);
    assert_eq!(r.streets.intersections, 3);
    assert!((r.streets.intersection_density_per_km2 - 3.0 / 0.16).abs() < 1e-9);

    // Lots along the filament serve it; the stub then has lots too.
    let mut more = lot_polys.clone();
    more.push(rect(160.0, 20.0, 190.0, 90.0));
    let lots2: Vec<LotInput<'_>> = more
        .iter()
        .map(|p| LotInput {
            polygon: p,
            street_edges: &[],
        })
        .collect();
    let city2 = CityInput {
        lots: &lots2,
        ..city
    };
    let d2 = polis_stats::report(&city2, &StatsOptions::default())
        .unwrap()
        .defects;
    assert_eq!(d2.segments_inside_blocks_without_lots, 0);
    assert!(d2.length_inside_blocks_without_lots_m < 20.0);
    assert_eq!(d2.stubs_in_land_without_lots, 0);

    // With water everywhere, the land stubs are in water.
    let water = Constant(1.0);
    let wet: &dyn Field = &water;
    let city3 = CityInput {
        water: Some(wet),
        ..city
    };
    let d3 = polis_stats::report(&city3, &StatsOptions::default())
        .unwrap()
        .defects;
    assert_eq!((d3.stubs_in_water, d3.stubs_in_land), (2, 0));

    // A lot naming an edge it does not have is an error.
    let bad_lot = [LotInput {
        polygon: &lot_polys[0],
        street_edges: &[9],
    }];
    let err = polis_stats::report(
        &CityInput {
            lots: &bad_lot,
            ..city
        },
        &StatsOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, StatsError::LotEdgeOutOfRange { edge: 9, .. }),
        "{err}"
    );
    let nan_building = [BuildingInput {
        height_m: f64::NAN,
        ..buildings[0]
    }];
    assert!(
        polis_stats::report(
            &CityInput {
                buildings: &nan_building,
                ..city
            },
            &StatsOptions::default()
        )
        .is_err()
    );
    // The table prints every section.
    let text = r.compare_with("Charlotte").unwrap().to_string();
    for part in [
        "streets",
        "blocks",
        "lots",
        "buildings",
        "plan defects",
        "Charlotte",
    ] {
        assert!(text.contains(part), "{part} missing:\n{text}");
    }
}

#[test]
fn reference_table_is_complete() {
    let cities = reference_cities().unwrap();
    assert_eq!(cities.len(), 100);
    let m = reference_city("manhattan").unwrap();
    assert_eq!(m.phi, Some(0.669));
    assert_eq!(m.share_4way, Some(0.572));
    assert_eq!(m.circuity, None);
    let sf = reference_city("San Francisco").unwrap();
    assert_eq!(sf.median_segment_m, Some(94.4));
    // The regional mean agrees with the paper's Table 2.
    let us = reference_city("US/Canada mean").unwrap();
    assert!((us.phi.unwrap() - 0.427).abs() < 0.01, "{:?}", us.phi);
    assert!(
        (us.share_4way.unwrap() - 0.334).abs() < 0.01,
        "{:?}",
        us.share_4way
    );
    let err = reference_city("Atlantis").unwrap_err();
    assert!(err.to_string().contains("US/Canada mean"), "{err}");
    // Every city's values are in their ranges.
    for c in &cities {
        assert!(
            c.phi.is_some_and(|p| (0.0..=1.0).contains(&p)),
            "{}",
            c.city
        );
        assert!(c.share_4way.is_some_and(|p| (0.0..=1.0).contains(&p)));
        if let Some(k) = c.average_degree {
            assert!((2.0..4.0).contains(&k));
        }
    }
    assert!(polis_stats::reference::parse_reference("city,phi\nx,1").is_err());
    let bad = "idx,region,city,phi,H_o,H_w,median_seg_len_m,circuity,k_avg,P_deadend,P_4way,provenance\n0,r,c,zero,,,,,,,,p";
    let err = polis_stats::reference::parse_reference(bad).unwrap_err();
    assert!(
        matches!(err, StatsError::Reference { line: 2, .. }),
        "{err}"
    );
}

#[test]
fn realism_bands() {
    assert!(Band::Absolute(0.1).contains(0.75, 0.669));
    assert!(!Band::Absolute(0.1).contains(0.8, 0.669));
    assert!(Band::Relative(0.25).contains(120.0, 100.0));
    assert!(!Band::Relative(0.25).contains(126.0, 100.0));
    let real = reference_city("Paris").unwrap();
    let mut s = polis_stats::StreetMetrics {
        orientation_order: 0.05,
        average_degree: 3.5,
        share_dead_end: 0.05,
        share_4way: 0.24,
        circuity: 1.023,
        ..Default::default()
    };
    s.segment_length_m.median = 71.5;
    let r = polis_stats::compare(&s, &real);
    assert_eq!(r.row("phi").unwrap().in_band, Some(true));
    assert_eq!(r.row("k_avg").unwrap().in_band, Some(false));
    assert_eq!(r.row("H_o").unwrap().in_band, None);
    assert_eq!((r.in_band, r.out_of_band), (5, 1));
    // Manhattan has no circuity: no verdict.
    let r = polis_stats::compare(&s, &reference_city("Manhattan").unwrap());
    assert_eq!(r.row("circuity").unwrap().in_band, None);
}

/// A random city: a lattice of streets, a block per lattice cell, rectangular lots along
/// the cell's south edge and a footprint on each lot, all jittered by the inputs.
struct RandomCity {
    g: StreetGraph,
    blocks: Vec<PolygonWithHoles>,
    lots: Vec<Polygon>,
    footprints: Vec<Polygon>,
}

fn random_city(n: usize, spacing: f64, jitter: &[f64], lot_w: f64, setback: f64) -> RandomCity {
    let mut g = StreetGraph::default();
    let at = |i: usize, j: usize| j * (n + 1) + i;
    for j in 0..=n {
        for i in 0..=n {
            let k = jitter[(i * 7 + j * 13) % jitter.len()];
            g.nodes
                .push(DVec2::new(i as f64 * spacing + k, j as f64 * spacing - k));
        }
    }
    for j in 0..=n {
        for i in 0..=n {
            if i < n {
                g.edges.push(street(at(i, j), at(i + 1, j), 8.0));
            }
            if j < n && jitter[(i + j) % jitter.len()] > -3.0 {
                g.edges.push(street(at(i, j), at(i, j + 1), 8.0));
            }
        }
    }
    let (mut blocks, mut lots, mut footprints) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f64 * spacing + 6.0, j as f64 * spacing + 6.0);
            let side = spacing - 12.0;
            blocks.push(PolygonWithHoles::from(rect(x, y, x + side, y + side)));
            let mut k = 0.0;
            while k + lot_w <= side {
                lots.push(rect(x + k, y, x + k + lot_w, y + side * 0.4));
                footprints.push(rect(
                    x + k + 1.0,
                    y - setback,
                    x + k + lot_w - 1.0,
                    y + side * 0.3,
                ));
                k += lot_w;
            }
        }
    }
    RandomCity {
        g,
        blocks,
        lots,
        footprints,
    }
}

fn report_of(c: &RandomCity) -> polis_stats::CityReport {
    let blocks: Vec<&PolygonWithHoles> = c.blocks.iter().collect();
    let lots: Vec<LotInput<'_>> = c
        .lots
        .iter()
        .map(|p| LotInput {
            polygon: p,
            street_edges: &[0],
        })
        .collect();
    let buildings: Vec<BuildingInput<'_>> = c
        .footprints
        .iter()
        .enumerate()
        .map(|(i, f)| BuildingInput {
            footprint: f,
            height_m: 3.0 * (i % 9) as f64,
            floors: (i % 9) as u32,
            kind: if i % 2 == 0 { "House" } else { "Apartment" },
        })
        .collect();
    let city = CityInput {
        streets: &c.g,
        blocks: &blocks,
        lots: &lots,
        buildings: &buildings,
        bounds: None,
        land_area_m2: None,
        water: None,
    };
    polis_stats::report(&city, &StatsOptions::default()).unwrap()
}

#[test]
fn any_thread_count_gives_the_same_report() {
    let c = random_city(12, 90.0, &[0.0, 3.5, -2.0, 7.0, -4.0], 13.0, 5.0);
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let one = pool(1).install(|| report_of(&c));
    let three = pool(3).install(|| report_of(&c));
    assert_eq!(one, three);
    assert!(one.defects.buildings_in_road_corridor > 0);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(40))]

    /// Shares stay in [0, 1], counts within their totals, every number finite.
    #[test]
    fn parcel_and_defect_metrics_stay_in_range(
        n in 1usize..5,
        spacing in 30.0f64..150.0,
        jitter in proptest::collection::vec(-6.0f64..6.0, 1..6),
        lot_w in 5.0f64..30.0,
        setback in -3.0f64..8.0,
    ) {
        let r = report_of(&random_city(n, spacing, &jitter, lot_w, setback));
        // serde_json writes NaN as null: only the optional parts may be null.
        let mut v = serde_json::to_value(&r).unwrap();
        v["streets"]["grade"] = serde_json::Value::Bool(false);
        v["realism"] = serde_json::Value::Bool(false);
        proptest::prop_assert!(!v.to_string().contains("null"), "{}", v);
        proptest::prop_assert!((0.0..=1.0).contains(&r.lots.street_access_share));
        proptest::prop_assert!(r.blocks.shape_factor.max <= 1.0);
        proptest::prop_assert!(r.buildings.coverage >= 0.0);
        proptest::prop_assert!(r.defects.buildings_in_road_corridor <= r.buildings.count);
        proptest::prop_assert!(r.defects.stubs_in_land_without_lots <= r.defects.stubs_in_land);
        proptest::prop_assert!(
            r.defects.length_inside_blocks_without_lots_m <= r.defects.length_inside_blocks_m + 1e-9
        );
        proptest::prop_assert_eq!(
            r.defects.stubs,
            r.defects.stubs_at_map_edge + r.defects.stubs_in_water + r.defects.stubs_in_land
        );
        let kinds: usize = r.buildings.kinds.values().sum();
        proptest::prop_assert_eq!(kinds, r.buildings.count);
        proptest::prop_assert_eq!(r.blocks.shape_factor_histogram.total(), r.blocks.shape_factor.count);
    }
}
