//! Mixed zones and lot-area height caps (Parish & Müller §2, §4.1) on generated cities.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;

use polis::buildings::BuildingKind;
use polis::{AreaCap, CityConfig, MapSpec};

fn small() -> CityConfig {
    let mut c = CityConfig::preset("default").unwrap();
    c.size_m = 700.0;
    c.roads.max_segments = 120;
    c.scene.terrain = false;
    c
}

#[test]
fn a_mixed_zone_yields_both_residential_and_commercial_buildings() {
    let mut c = small();
    c.maps.zoning = Some(MapSpec::constant(polis::MIXED_ZONE));
    let city = polis::generate(&c).unwrap();
    let mut kinds: BTreeMap<String, usize> = BTreeMap::new();
    for b in &city.buildings {
        *kinds.entry(format!("{:?}", b.kind)).or_default() += 1;
    }
    let offices = kinds.get("Office").copied().unwrap_or(0);
    let flats = kinds.get("Apartment").copied().unwrap_or(0);
    assert_eq!(offices + flats, city.buildings.len(), "{kinds:?}");
    assert!(offices > 0 && flats > 0, "{kinds:?}");
    // Unknown grey levels are refused when the configuration is checked.
    c.maps.zoning = Some(MapSpec::constant(9.0));
    let e = c.validate().unwrap_err().to_string();
    assert!(e.contains("maps.zoning"), "{e}");
    assert!(polis::generate(&c).is_err());
    // A zone index keeps its one kind.
    c.maps.zoning = Some(MapSpec::constant(3.0));
    let city = polis::generate(&c).unwrap();
    assert!(city.buildings.iter().all(|b| b.kind == BuildingKind::House));
}

#[test]
fn the_height_cap_follows_lot_area() {
    let mut c = small();
    // Everything tall by the bands, so only the caps decide.
    for b in &mut c.zoning.bands {
        b.kind = BuildingKind::Office;
        b.max_height_m = 120.0;
    }
    c.zoning.fallback_kind = BuildingKind::Office;
    c.zoning.fallback_max_height_m = 120.0;
    let base = polis::generate(&c).unwrap();
    c.zoning.area_caps = vec![
        AreaCap {
            max_area_m2: 2000.0,
            max_height_m: 30.0,
        },
        AreaCap {
            max_area_m2: 500.0,
            max_height_m: 9.0,
        },
    ];
    let city = polis::generate(&c).unwrap();
    let area: BTreeMap<u64, f64> = city.lots.iter().map(|l| (l.id, l.lot.area)).collect();
    let (mut small_lots, mut mid_lots, mut tall_mid) = (0, 0, 0);
    for b in &city.buildings {
        let a = area[&b.lot_id];
        let cap = if a <= 500.0 {
            small_lots += 1;
            9.0
        } else if a <= 2000.0 {
            mid_lots += 1;
            if b.height > 9.0 {
                tall_mid += 1;
            }
            30.0
        } else {
            120.0
        };
        assert!(b.height <= cap + 1e-6, "{} m on a {a} m² lot", b.height);
    }
    assert!(small_lots > 0 && mid_lots > 0, "{small_lots} {mid_lots}");
    assert!(
        tall_mid > 0,
        "mid-size lots build above the small lots' cap"
    );
    // Without caps the same lots build taller.
    let max_small = |city: &polis::City| {
        let area: BTreeMap<u64, f64> = city.lots.iter().map(|l| (l.id, l.lot.area)).collect();
        city.buildings
            .iter()
            .filter(|b| area[&b.lot_id] <= 500.0)
            .map(|b| b.height)
            .fold(0.0, f64::max)
    };
    assert!(max_small(&base) > 9.0);
    c.zoning.area_caps[0].max_area_m2 = f64::INFINITY;
    assert!(c.validate().is_err());
}
