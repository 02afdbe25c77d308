//! Configuration sanity (issue 22): settings that are valid but leave the city empty are
//! reported as warnings in the city's report.

use polis::{CityConfig, MapSpec, Pipeline};

#[test]
fn a_city_without_buildings_says_why() {
    let mut config = CityConfig {
        size_m: 600.0,
        threads: Some(1),
        ..CityConfig::default()
    };
    config.maps.max_height = Some(MapSpec::constant(0.0));
    config.facades.enabled = false;
    let city = Pipeline::default()
        .with_scene(false)
        .generate(&config)
        .unwrap();
    let w = &city.report.warnings;
    assert!(w.iter().any(|w| w.contains("maps.max_height")), "{w:?}");
    assert!(city.stats.road_segments > 0);
    assert_eq!(
        city.stats.buildings, 0,
        "a 0 m height limit leaves no building"
    );
    assert!(w.iter().any(|w| w.contains("no building")), "{w:?}");
}
