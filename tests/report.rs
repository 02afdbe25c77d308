//! The statistics report of a small city per preset: complete, finite, compared with the
//! city the preset imitates. (Whether the presets land in their real city's bands is
//! asserted in `tests/realism_bands.rs`.)

#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic on failure

use polis::{CityConfig, Pipeline};

/// Every number of the report is finite: serde_json writes NaN as null, and only the
/// optional parts may be null.
fn assert_finite(v: &serde_json::Value, path: &str) {
    match v {
        serde_json::Value::Null => {
            let optional = ["grade", "realism", "real", "band", "in_band"];
            assert!(optional.iter().any(|k| path.ends_with(k)), "null at {path}");
        }
        serde_json::Value::Number(n) => {
            assert!(n.as_f64().is_some_and(f64::is_finite), "{path} = {n}")
        }
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                assert_finite(x, &format!("{path}[{i}]"));
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                assert_finite(x, &format!("{path}.{k}"));
            }
        }
        _ => {}
    }
}

#[test]
fn every_preset_reports_completely_against_its_city() {
    for name in CityConfig::preset_names() {
        let mut c = CityConfig::preset(name).unwrap();
        c.size_m = c.size_m.min(1200.0);
        c.roads.max_segments = 200;
        c.facades.enabled = false;
        let city = Pipeline::default().with_scene(false).generate(&c).unwrap();
        let report = city.statistics().unwrap();
        let imitates = polis::reference_city_name(&c).expect("every preset names its city");
        let realism = report.realism.as_ref().expect("compared");
        assert!(realism.city.eq_ignore_ascii_case(imitates), "{name}");
        assert_eq!(realism.rows.len(), 8, "{name}");
        // Every reference city has at least φ and the four-way share.
        assert!(realism.in_band + realism.out_of_band >= 2, "{name}");
        // Counts agree with the city's layers.
        assert_eq!(report.streets.segments, city.roads.edge_count(), "{name}");
        assert_eq!(report.blocks.count, city.blocks.len(), "{name}");
        assert_eq!(report.lots.count, city.lots.len(), "{name}");
        assert_eq!(report.buildings.count, city.buildings.len(), "{name}");
        assert!(
            report.streets.streets > 0 && report.streets.nodes > 0,
            "{name}"
        );
        assert!(report.streets.grade.is_some(), "{name}");
        assert!(report.streets.land_area_km2 > 0.0, "{name}");
        let kinds: usize = report.buildings.kinds.values().sum();
        assert_eq!(kinds, city.buildings.len(), "{name}");
        assert_finite(&serde_json::to_value(&report).unwrap(), name);
        let table = report.to_string();
        assert!(table.contains("realism against"), "{name}");
    }
}

#[test]
fn unknown_reference_city_is_an_error() {
    let mut c = CityConfig::preset("default").unwrap();
    c.size_m = 500.0;
    c.roads.max_segments = 60;
    c.facades.enabled = false;
    c.imitates = Some("Atlantis".into());
    let city = Pipeline::default().with_scene(false).generate(&c).unwrap();
    let err = city.statistics().unwrap_err();
    assert!(matches!(err, polis::Error::Stats(_)), "{err}");
    c.imitates = None;
    let city = Pipeline::default().with_scene(false).generate(&c).unwrap();
    assert!(city.statistics().unwrap().realism.is_none());
}

/// No building stands in a road corridor, in a small city of every preset. Lots used to
/// be laid across the filaments (dead ends and connectors inside a cell, which the
/// blocks are not cut along): 6 buildings in `default`, 31 in `citygen`, 62 in
/// `old_town` at this size before the lot stage kept lots out of their corridors.
#[test]
fn no_building_in_a_road_corridor_in_any_preset() {
    for name in CityConfig::preset_names() {
        let mut c = CityConfig::preset(name).unwrap();
        c.size_m = c.size_m.min(1500.0);
        c.roads.max_segments = 400;
        c.facades.enabled = false;
        let city = Pipeline::default().with_scene(false).generate(&c).unwrap();
        let report = city.statistics().unwrap();
        assert!(report.buildings.count > 0, "{name}: no buildings");
        assert_eq!(report.defects.buildings_in_road_corridor, 0, "{name}");
    }
}

/// Manhattan's buildings are mostly mid-rise on narrow lots, with a minority of towers:
/// the median building is 5–13 storeys (15–45 m; the real median is about six storeys),
/// fewer than 15 % are skyscrapers, lots are 25 ft wide (7.6 m frontage median within
/// ±25 %) and their median area is 120–300 m² (a 25 × 100 ft lot is 232 m²; the blocks
/// here are shallower than 200 ft, so depth comes out short), and buildings cover
/// 60–95 % of their lots (walk-ups keep yards, towers fill their lots). Before the
/// zoning and lots of the preset were changed: median height 259 m, 71 % skyscrapers,
/// lot median 472 m², coverage 0.96.
#[test]
fn manhattan_is_mid_rise_on_narrow_lots() {
    // The whole island (the preset's own size): a small city would be downtown only.
    let mut c = CityConfig::preset("manhattan").unwrap();
    c.facades.enabled = false;
    let city = Pipeline::default().with_scene(false).generate(&c).unwrap();
    let r = city.statistics().unwrap();
    let b = &r.buildings;
    let towers = b.kinds.get("skyscraper").copied().unwrap_or(0) as f64 / b.count as f64;
    eprintln!(
        "manhattan: height median {:.1} m, towers {:.3}, lot median {:.1} m², frontage {:.2} m, coverage {:.3}, {} buildings",
        b.height_m.median,
        towers,
        r.lots.area_m2.median,
        r.lots.frontage_m.median,
        b.coverage,
        b.count
    );
    assert!(b.count > 100, "{}", b.count);
    assert!(
        (15.0..=45.0).contains(&b.height_m.median),
        "{}",
        b.height_m.median
    );
    assert!(towers < 0.15, "{towers}");
    assert!(
        (5.7..=9.5).contains(&r.lots.frontage_m.median),
        "{}",
        r.lots.frontage_m.median
    );
    assert!(
        (120.0..=300.0).contains(&r.lots.area_m2.median),
        "{}",
        r.lots.area_m2.median
    );
    assert!((0.6..=0.95).contains(&b.coverage), "{}", b.coverage);
}
