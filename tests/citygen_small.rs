//! A small Citygen city is not empty: when the P&M highways of a small map enclose no
//! cell, the map's edge closes them (issue 18).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis::CityConfig;

#[test]
fn a_small_suburbia_has_cells_streets_and_houses() {
    let mut c = CityConfig::preset("suburbia").unwrap();
    c.size_m = 900.0;
    c.roads.max_segments = 160;
    c.facades.pixels_per_metre = 4.0;
    let city = polis::generate(&c).unwrap();
    assert!(city.stats.cells > 0, "{:?}", city.report);
    assert!(city.stats.buildings > 0, "{:?}", city.report);
    assert!(
        city.report.warnings.is_empty(),
        "{:?}",
        city.report.warnings
    );
    // The map's edge is part of the primary network (every cell is enclosed), and the
    // road graph stays planar.
    let h = c.size_m * 0.5;
    assert!(
        city.roads
            .nodes()
            .any(|(_, p, _)| p == polis::geom::DVec2::new(-h, -h)),
        "the map's corner is a junction"
    );
    city.roads.check_invariants().unwrap();
}
