//! Every Parish & Müller preset, and `suburbia` (Citygen mode: Kelly's Suburbia
//! growing inside P&M highway cells), lands in its real city's bands (issue 19): φ ± 0.10,
//! `k̄` ± 0.20, dead-end share ± 0.05, four-way share ± 0.08, median segment ± 25 %,
//! circuity ± 0.02, wherever Boeing 2019's table has the value.
//!
//! Street metrics depend on the road network alone, so each check runs the maps and the
//! road stage at the preset's own size (`polis::road_statistics`: no lots or buildings,
//! well under a second per city in a debug build) and measures the network with
//! polis-stats' realism comparison, as `City::statistics` does.
//!
//! Seeds 1–5 are checked; the presets were retuned on them after the plan-defect work
//! of issue 19 (fringe stubs pruned, park maps), which had pushed 13 rows out of band;
//! seeds 6–10 are the held-out check (BENCHMARKS.md, "Issue 19"). The misses that remain
//! are listed in [`KNOWN_MISSES`] and the test demands exactly them: a new miss fails it,
//! and so does a listed miss that has gone (update the list and BENCHMARKS.md then).
//! `default` seed 2 used to start on the tip of a coastal peninsula: its highways ran into
//! the map's edge and into water no bridge spans, and the city stayed a pocket of a few
//! hundred streets (seed 6 of the held-out set: 26 streets, its start in a corner). Since
//! session 13 highway rays count no population in water or parks and the axiom's second
//! highway takes an open ray (`polis_roads::DefaultGoals::ray_open`), so both grow whole
//! networks; seed 2 kept one miss, its circuity (1.073 against 1.045 ± 0.02), until
//! session 16 retuned `default` on seeds 1–40 and checked it on 41–200 (streets curving
//! 16° instead of 36°, more dead ends, and smaller grid patches that average out over the
//! city, so its orientation order no longer swings with the seed): see BENCHMARKS.md.
//! `old_town`'s culs-de-sac became side streets one link long in session 17
//! (`dead_end_links: "first"`; before, a cul-de-sac could end any street and with it the
//! growth front behind it, so the network's size and circuity swung with the seed), its
//! Basic streets retuned on seeds 1–40 and 41–120.
//! Tunnels (issue 27) changed `san_francisco` seeds 1–2: highways pass under the hills
//! they used to stop at. `citygen_us` and `milan` joined the test in session 11 (their
//! Citygen units and neighbourhood parameters retuned on seeds 1–5; `citygen_us` kept
//! one circuity miss, seed 1's until session 13's highway rays, seed 2's since, until
//! session 20 bowed its streets between their junctions, `SecondaryParams::bow`: seeds
//! 1–200 all in the circuity band). `citygen` itself is Kelly's test city
//! (issue 18: 16 km², ≥ 15,000 roads, ≥ 57,000 buildings, the workload of issue 25's
//! timings), whose street density no real city's band admits; it is not tested here.
//!
//! Determinism: the misses are the same in every fresh process and with one or two
//! threads (checked with `street_bands --preset default` three times each with
//! `RAYON_NUM_THREADS=1` and with the default pool: identical output). An earlier note
//! that `default` gave one of two miss lists compared two different builds; the two
//! lists it saw are together the list below, so every preset is held to its exact list.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis::{CityConfig, road_statistics};

/// The banded rows out of band, as "metric = value (real)".
fn misses(preset: &str, seed: u64) -> Vec<String> {
    let mut config = CityConfig::preset(preset).unwrap();
    config.seed = seed;
    assert!(config.imitates.is_some(), "{preset} names its city");
    let report = road_statistics(&config).unwrap();
    let realism = report.realism.unwrap();
    // At least φ and the four-way share (all Manhattan's row has) get a verdict.
    assert!(realism.in_band >= 2, "{preset}: {realism:?}");
    realism
        .rows
        .iter()
        .filter(|r| r.in_band == Some(false))
        .map(|r| {
            format!(
                "{} = {:.3} (real {:.3})",
                r.metric,
                r.polis,
                r.real.unwrap_or(f64::NAN)
            )
        })
        .collect()
}

/// (preset, seed, metric) out of band today; everything else must be in band.
const KNOWN_MISSES: &[(&str, u64, &str)] = &[];

fn check(preset: &str) {
    let mut unexpected = Vec::new();
    let mut gone = Vec::new();
    for seed in 1..=5 {
        let got = misses(preset, seed);
        for m in &got {
            let known = KNOWN_MISSES.iter().any(|&(p, s, metric)| {
                p == preset && s == seed && m.starts_with(&format!("{metric} ="))
            });
            if !known {
                unexpected.push(format!("seed {seed}: {m}"));
            }
        }
        for &(p, s, metric) in KNOWN_MISSES {
            if p == preset
                && s == seed
                && !got.iter().any(|m| m.starts_with(&format!("{metric} =")))
            {
                gone.push(format!("seed {seed}: {metric} is in band now"));
            }
        }
    }
    assert!(
        unexpected.is_empty(),
        "{preset} out of band: {unexpected:#?}"
    );
    assert!(gone.is_empty(), "{preset}: update KNOWN_MISSES: {gone:#?}");
}

#[test]
fn default_is_in_the_us_canada_band() {
    check("default");
}

#[test]
fn manhattan_is_in_manhattans_band() {
    check("manhattan");
}

#[test]
fn paris_is_in_paris_band() {
    check("paris");
}

#[test]
fn san_francisco_is_in_san_franciscos_band() {
    check("san_francisco");
}

#[test]
fn old_town_is_in_romes_band() {
    check("old_town");
}

/// Kelly's Suburbia against Charlotte (dead-end share 0.288 ± 0.05, issue 18): the
/// preset tunes its connectivity (0.035, Kelly's 0.05) and branches more highways, so
/// the primary network encloses enough cells for the statistics to settle.
#[test]
fn suburbia_is_in_charlottes_band() {
    check("suburbia");
}

/// The Citygen pipeline against the US/Canada mean (`citygen_us`: Kelly's test city's
/// configuration — P&M highways, cells grown by a zoning map of Manhattan, Raster,
/// Industrial and Suburbia — at a real city's street spacing). Its Citygen unit
/// is 26 m (Manhattan's 5-unit segments are 130 m, so junctions come about 100 m apart),
/// its highways lean to a grid (New York weight 0.7), and Industrial and Suburbia
/// meander more (Kelly §6.3). Its streets bow between their junctions (`bow`: grids
/// 0.10, Suburbia 0.16 and Industrial 0.12 of the street, ± 50 %); straight, they left
/// seed 2 at circuity 1.020 against 1.045 ± 0.02 (its grid cells carry more of the
/// length).
#[test]
fn citygen_us_is_in_the_us_canada_band() {
    check("citygen_us");
}

/// Milan (Kelly §6.1's ring network) against the Europe mean: Citygen unit 28 m, no road
/// meets another more sharply than 70° (`min_angle`, so no five-way junctions and
/// T-junctions where the fabric is not a grid), suburbs and industry connected at 0.25.
#[test]
fn milan_is_in_the_europe_band() {
    check("milan");
}

/// `road_statistics` measures the same streets as the whole city's statistics: every
/// realism row agrees (a small `paris` and `san_francisco`, whose maps are salted per
/// seed, so a mismatch in the maps would show).
#[test]
fn road_statistics_agree_with_the_whole_city() {
    for name in ["paris", "san_francisco"] {
        let mut c = CityConfig::preset(name).unwrap();
        c.size_m = 1200.0;
        c.roads.max_segments = 300;
        c.facades.enabled = false;
        c.seed = 4;
        let fast = road_statistics(&c).unwrap();
        let city = polis::Pipeline::default()
            .with_scene(false)
            .generate(&c)
            .unwrap();
        let full = city.statistics().unwrap();
        assert!(fast.streets.streets > 0, "{name}");
        assert_eq!(fast.streets.segments, city.roads.edge_count(), "{name}");
        assert_eq!(
            fast.realism.unwrap().rows,
            full.realism.unwrap().rows,
            "{name}"
        );
    }
}

/// Bridges where the island needs them (issue 19: `manhattan` had none but chance
/// crossings of coves). The preset's water is the island's sea up to a mainland beyond
/// the East River (`min_of` an island and a coast: the river 400–550 m wide along the middle
/// of the island, within the 700 m bridge limit, wider toward its tips; the Hudson side
/// stays open water to the map's edge). On seeds 1–5
/// the road stage bridges the river and grows streets on the far bank, which nothing but
/// a bridge reaches: no road crosses water otherwise.
#[test]
fn manhattan_bridges_the_east_river() {
    use polis::geom::DVec2;
    use polis::stages::{RoadStage, StageContext};
    // Across the island toward the East River (the island's axis is at 75°).
    let east = DVec2::from_angle((-15f64).to_radians());
    for seed in 1..=5 {
        let mut config = CityConfig::preset("manhattan").unwrap();
        config.seed = seed;
        let maps = polis::CityMaps::build(
            &config.maps,
            polis::seed::sub_seed(seed, polis::Stage::Maps, 0),
        )
        .unwrap();
        let water = |p: DVec2| maps.inputs.water.sample(p) >= 0.5;
        // The river: land on the island's shore side, water, then the mainland.
        assert!(!water(east * 600.0) && water(east * 1150.0) && !water(east * 1600.0));
        let cx = StageContext {
            config: &config,
            maps: &maps,
        };
        let net = polis::citygen::ConfiguredRoads::default()
            .roads(&cx)
            .unwrap()
            .network;
        let max = config.effective_road_params().max_bridge_length_m;
        let mut bridges = 0;
        let mut mainland = 0;
        for (e, _, _, r) in net.edges() {
            let (a, b) = net.segment(e).unwrap();
            if r.bridge {
                bridges += 1;
                assert!(a.distance(b) <= max + 1e-6, "seed {seed}: bridge {a} {b}");
            } else if a.dot(east) > 1500.0 && b.dot(east) > 1500.0 {
                mainland += 1;
            }
        }
        assert!(bridges > 0, "seed {seed}: no bridge");
        assert!(mainland > 0, "seed {seed}: no road on the mainland");
    }
}

/// Manhattan's blocks are long across the island, its lots 25 × 100 ft, its
/// median building mid-rise (issue 19's table: it was 259 m with 71 % skyscrapers and a
/// coverage of 0.96). On a 2 km `manhattan` (the island is at 75°, so across it is 165°).
#[test]
fn manhattan_blocks_lots_and_heights() {
    let mut c = CityConfig::preset("manhattan").unwrap();
    c.size_m = 2000.0;
    c.facades.enabled = false;
    let city = polis::Pipeline::default()
        .with_scene(false)
        .generate(&c)
        .unwrap();
    let r = city.statistics().unwrap();
    let across = (r.blocks.long_axis_deg - 165.0).abs();
    assert!(across < 15.0, "block long axis {}°", r.blocks.long_axis_deg);
    assert!(
        r.blocks.long_axis_order > 0.6,
        "{}",
        r.blocks.long_axis_order
    );
    // 25 ft = 7.62 m of frontage.
    assert!(
        (r.lots.frontage_m.median - 7.62).abs() < 1.0,
        "{}",
        r.lots.frontage_m.median
    );
    // 25 × 100 ft = 232 m² (the median was 172 m² before block ends were cut into
    // full-depth lots; 225 m² now), 100 ft = 30.5 m deep.
    assert!(
        (r.lots.area_m2.median - 232.0).abs() < 0.15 * 232.0,
        "lot area median {}",
        r.lots.area_m2.median
    );
    assert!(
        (r.lots.depth_m.median - 30.48).abs() < 4.0,
        "lot depth median {}",
        r.lots.depth_m.median
    );
    assert!(
        (15.0..40.0).contains(&r.buildings.height_m.median),
        "median height {}",
        r.buildings.height_m.median
    );
    let towers = r.buildings.kinds.get("skyscraper").copied().unwrap_or(0);
    assert!(
        (towers as f64) < 0.12 * r.buildings.count as f64,
        "{towers} of {}",
        r.buildings.count
    );
    assert!(r.buildings.coverage < 0.96, "{}", r.buildings.coverage);
}
