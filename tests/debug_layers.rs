//! The SVG's debug overlays on a generated city (Kelly §5.4.1, §5.5.1): the lot
//! subdivision's split lines, one per subdivision step and in order, and the primary
//! roads' plot points and fans in the Citygen mode.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis::citygen::{InlinePrimary, PrimarySource, RoadMode};
use polis::export::svg::SvgDebug;
use polis::geom::{Aabb2, DVec2};
use polis::roads::primary::{Edit, EditOptions, PrimaryEditor, RoadPreset, Strategy, Terrain};
use polis::{CityConfig, Formats, WriteOptions};

#[test]
fn city_svg_lists_one_split_line_per_subdivision_step() {
    let mut c = CityConfig::preset("default").unwrap();
    c.size_m = 700.0;
    c.roads.max_segments = 120;
    c.scene.terrain = false;
    let city = polis::generate(&c).unwrap();
    assert!(!city.lots.is_empty());
    // Every kept lot came out of a split or is a whole block, so there are at least as
    // many pieces as split lines plus blocks, minus the lots dropped beside roads.
    assert!(!city.lot_splits.is_empty());
    let blocks: std::collections::BTreeSet<u64> = city.blocks.iter().map(|b| b.id()).collect();
    assert!(city.lot_splits.iter().all(|(b, _)| blocks.contains(b)));
    let dir = std::env::temp_dir().join(format!("polis-debug-layers-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let plain = WriteOptions {
        formats: Formats {
            svg: true,
            ..Formats::NONE
        },
        ..WriteOptions::default()
    };
    city.write_all_with(&dir, &plain).unwrap();
    let text = std::fs::read_to_string(dir.join("city.svg")).unwrap();
    assert!(!text.contains("debug-"), "off by default");
    let on = WriteOptions {
        svg_debug: "splits,lots,blocks".parse().unwrap(),
        ..plain
    };
    city.write_all_with(&dir, &on).unwrap();
    let text = std::fs::read_to_string(dir.join("city.svg")).unwrap();
    let orders: Vec<usize> = text
        .lines()
        .filter(|l| l.contains("class=\"split\""))
        .map(|l| {
            let at = l.find("data-order=\"").unwrap() + 12;
            l[at..at + l[at..].find('"').unwrap()].parse().unwrap()
        })
        .collect();
    assert_eq!(orders.len(), city.lot_splits.len());
    assert!(orders.iter().enumerate().all(|(i, &o)| i == o));
    assert!(text.contains("<g id=\"debug-lots\"") && text.contains("<g id=\"debug-blocks\""));
    assert!("plot,bogus".parse::<SvgDebug>().is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn citygen_debug_map_has_plot_points_and_fans() {
    let terrain = Terrain::flat(Aabb2::new(DVec2::splat(-400.0), DVec2::splat(400.0))).unwrap();
    let mut ed = PrimaryEditor::new(terrain, EditOptions::default()).unwrap();
    let mut spec = RoadPreset::InnerCity.spec();
    spec.params.strategy = Strategy::Straight;
    let first = ed.network().next_node_id();
    ed.apply(&Edit::AddNode {
        at: DVec2::new(-300.0, -300.0),
        label: None,
    })
    .unwrap();
    let mut at = first;
    for (x, y) in [
        (300.0, -300.0),
        (300.0, 300.0),
        (-300.0, 300.0),
        (-300.0, -300.0),
    ] {
        let p = ed
            .propose(&Edit::Chain {
                from: at,
                to: DVec2::new(x, y),
                spec,
            })
            .unwrap();
        at = p.end_node().unwrap();
        ed.commit(&p).unwrap();
    }
    let net = ed.into_network();
    let mut c = CityConfig::preset("milan").unwrap();
    c.size_m = 800.0;
    c.road_mode = RoadMode::Citygen;
    c.citygen.primary = PrimarySource::Kelly {
        network: InlinePrimary(Box::new(net.clone())),
    };
    c.citygen.by_population.clear();
    c.citygen.overrides.clear();
    c.scene.terrain = false;
    let city = polis::generate(&c).unwrap();
    let debug = city.debug_map().unwrap();
    let plot: usize = net.roads().map(|(_, r)| r.path.plot.len()).sum();
    assert_eq!(debug.plot_points.len(), plot);
    assert!(!debug.fans.is_empty());
    for f in &debug.fans {
        assert!(f.chosen < f.samples.len());
        // Samples lie one sample step from the head.
        let d = f.from.distance(f.samples[0]);
        assert!(
            f.samples
                .iter()
                .all(|s| (s.distance(f.from) - d).abs() < 1e-6)
        );
    }
    assert_eq!(debug.splits.len(), city.lot_splits.len());
}
