//! A small Citygen city is not empty: when the P&M highways of a small map enclose no
//! cell, the map's edge closes them (issue 18).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis::CityConfig;

#[test]
fn a_small_suburbia_has_cells_streets_and_houses() {
    let mut c = CityConfig::preset("suburbia").unwrap();
    c.size_m = 900.0;
    c.roads.max_segments = 160;
    // Few highway branches (the P&M default; the preset branches more), so the
    // highways of this small map enclose no cell and the map's edge must close them.
    c.roads.highway_branch_probability = 0.06;
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

/// The small Suburbia's cells grow their own streets (issue 18: a 900 m Suburbia once
/// had a cell with no secondary roads). Every cell whose longest side exceeds twice the
/// largest snap size (the growth's own lower bound, `CellTooSmall` below it) and whose
/// area is at least 5 ha gets Suburbia streets joined to its boundary, for seeds 1–5.
#[test]
fn every_cell_of_a_small_suburbia_grows_streets() {
    use polis::citygen::citygen_network;
    use polis::roads::RoadClass;
    use polis::stages::{Stage, StageContext};
    for seed in 1..=5 {
        let mut c = CityConfig::preset("suburbia").unwrap();
        c.size_m = 900.0;
        c.roads.max_segments = 160;
        c.seed = seed;
        let maps =
            polis::CityMaps::build(&c.maps, polis::seed::sub_seed(seed, Stage::Maps, 0)).unwrap();
        let cx = StageContext {
            config: &c,
            maps: &maps,
        };
        let (net, _) = citygen_network(&cx).unwrap();
        assert!(!net.cells.is_empty(), "seed {seed}: no cell grown");
        let mut streets_total = 0;
        for (cell, d) in net.cells.iter().zip(&net.districts) {
            let streets = cell
                .network
                .edges()
                .filter(|(_, _, _, r)| r.class == RoadClass::Street)
                .count();
            streets_total += streets;
            let area = d.region.area();
            if area >= 50_000.0 {
                assert!(
                    streets > 0,
                    "seed {seed}: a {area:.0} m² cell grew no street: {:?}",
                    cell.report
                );
            }
        }
        assert!(streets_total >= 5, "seed {seed}: {streets_total} streets");
    }
}
