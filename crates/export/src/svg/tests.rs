use super::*;
use crate::map::MapRoad;
use crate::testing::{check_xml, sample_map};

fn svg(map: &MapLayers, o: &SvgOptions) -> String {
    let mut out = Vec::new();
    write_svg(map, o, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

fn attr<'a>(e: &'a (String, Vec<(String, String)>), key: &str) -> Option<&'a str> {
    e.1.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
}

#[test]
fn sample_map_is_well_formed_with_all_layers() {
    let map = sample_map();
    let text = svg(&map, &SvgOptions::default());
    let els = check_xml(&text);
    let groups: Vec<&str> = els
        .iter()
        .filter(|e| e.0 == "g")
        .map(|e| attr(e, "id").unwrap())
        .collect();
    assert_eq!(
        groups,
        ["water", "parks", "blocks", "lots", "roads", "footprints"]
    );
    let paths = els.iter().filter(|e| e.0 == "path").count();
    // 1 water + 1 park + 2 blocks + 6 lots + 5 roads + 1 bridge casing + 6 footprints.
    assert_eq!(paths, 22);
    // The odd names are escaped and come back intact through the tokenizer.
    assert!(text.contains("class=\"church &amp; &lt;hall&gt;\""));
    assert!(text.contains("class=\"tram &quot;line&quot;\""));
    // viewBox: x from −11.5 (tram road padded by 1.5) to 300+8, y from −11.5 to 160
    // (park top at 150+20·sin(…)) — check the origin comment and the extent instead.
    let svg_el = &els[0];
    assert_eq!(svg_el.0, "svg");
    let vb: Vec<f64> = attr(svg_el, "viewBox")
        .unwrap()
        .split(' ')
        .map(|v| v.parse().unwrap())
        .collect();
    let (min, max) = map.bounds(LayerSet::ALL).unwrap();
    assert_eq!(vb[0], 0.0);
    assert!((vb[2] - (max.x - min.x + 20.0)).abs() < 0.01);
    assert!((vb[3] - (max.y - min.y + 20.0)).abs() < 0.01);
}

#[test]
fn north_is_up_and_roads_are_ordered() {
    let mut map = MapLayers::default();
    map.roads.push(MapRoad {
        bridge: true,
        ..MapRoad::new(
            vec![DVec2::new(0.0, 0.0), DVec2::new(0.0, 50.0)],
            RoadClass::Street,
            4.0,
        )
    });
    map.roads.push(MapRoad::new(
        vec![DVec2::new(-20.0, 10.0), DVec2::new(20.0, 10.0)],
        RoadClass::Highway,
        10.0,
    ));
    map.roads.push(MapRoad::new(
        vec![DVec2::new(-20.0, 20.0), DVec2::new(20.0, 20.0)],
        RoadClass::Footpath,
        2.0,
    ));
    let o = SvgOptions {
        margin_m: 0.0,
        ..SvgOptions::default()
    };
    let text = svg(&map, &o);
    let els = check_xml(&text);
    let roads: Vec<&str> = els
        .iter()
        .filter(|e| e.0 == "path")
        .map(|e| attr(e, "class").unwrap())
        .collect();
    assert_eq!(
        roads,
        ["footpath", "highway", "bridge-casing", "street bridge"]
    );
    // Extent: x −25..25 (highway padded by 5), y −2..52 (bridge padded by 2).
    // The bridge runs from layout y=0 (south) to y=50 (north): in SVG the start is lower
    // (larger y) than the end.
    let d = attr(els.iter().rfind(|e| e.0 == "path").unwrap(), "d").unwrap();
    assert_eq!(d, "M25 52 L25 2");
    assert_eq!(attr(&els[0], "viewBox"), Some("0 0 50 54"));
}

#[test]
fn layers_are_selectable_and_output_is_stable() {
    let map = sample_map();
    let only = SvgOptions {
        layers: LayerSet {
            footprints: true,
            water: true,
            ..LayerSet::NONE
        },
        ..SvgOptions::default()
    };
    let text = svg(&map, &only);
    let els = check_xml(&text);
    let groups: Vec<&str> = els
        .iter()
        .filter(|e| e.0 == "g")
        .map(|e| attr(e, "id").unwrap())
        .collect();
    assert_eq!(groups, ["water", "footprints"]);
    assert_eq!(text, svg(&map.clone(), &only), "byte-identical");
    let none = svg(
        &map,
        &SvgOptions {
            layers: LayerSet::NONE,
            ..SvgOptions::default()
        },
    );
    check_xml(&none);
    let empty = svg(&MapLayers::default(), &SvgOptions::default());
    assert!(empty.contains("viewBox=\"0 0 20 20\""));
}

#[test]
fn fixed_decimal_formatting() {
    let f = |v: f64, d: u8| {
        let mut s = String::new();
        fixed(&mut s, v, d);
        s
    };
    assert_eq!(f(12.5, 2), "12.5");
    assert_eq!(f(-1.23456, 2), "-1.23");
    assert_eq!(f(2.0, 2), "2");
    assert_eq!(f(0.05, 2), "0.05");
    assert_eq!(f(-0.001, 2), "0");
    assert_eq!(f(-0.0, 3), "0");
    assert_eq!(f(1e8, 6), "100000000");
    assert_eq!(f(0.1234567, 6), "0.123457");
    assert_eq!(f(7.77, 0), "8");
    assert_eq!(f(-0.5, 0), "-1");
}

#[test]
fn bad_input_is_rejected_before_writing() {
    let mut out = Vec::new();
    let map = sample_map();
    for o in [
        SvgOptions {
            pixels_per_metre: 0.0,
            ..SvgOptions::default()
        },
        SvgOptions {
            margin_m: f64::NAN,
            ..SvgOptions::default()
        },
        SvgOptions {
            decimals: 7,
            ..SvgOptions::default()
        },
    ] {
        assert!(matches!(
            write_svg(&map, &o, &mut out),
            Err(ExportError::InvalidOption { .. })
        ));
    }
    let mut bad = map.clone();
    bad.footprints[2].polygon.outer =
        polis_geom::Polygon::new(vec![DVec2::ZERO, DVec2::new(f64::NAN, 1.0), DVec2::ONE]);
    let e = write_svg(&bad, &SvgOptions::default(), &mut out).unwrap_err();
    assert!(e.to_string().contains("footprint 2"), "{e}");
    assert!(out.is_empty());
}

#[test]
fn escaping_and_control_characters() {
    assert_eq!(esc("plain"), "plain");
    assert_eq!(esc("a<b>&\"'"), "a&lt;b&gt;&amp;&quot;&apos;");
    assert_eq!(esc("x\u{1}y"), "x\u{FFFD}y");
    let mut map = MapLayers::default();
    map.footprints.push(crate::map::MapFootprint::new(
        polis_geom::Polygon::rect(DVec2::ZERO, DVec2::ONE).into(),
        BuildingKind::Other("bell\u{7}tower".into()),
        5.0,
    ));
    check_xml(&svg(&map, &SvgOptions::default()));
}

/// The debug overlays are off by default; on, each is its own group over the map, and the
/// split layer lists one path per split line in the order given (`data-order`), with
/// every chord of a line in that line's path.
#[test]
fn debug_layers_list_one_split_line_per_step_in_order() {
    use crate::map::{MapDebug, MapFan, MapSplit};
    let mut map = sample_map();
    let d = |x: f64, y: f64| DVec2::new(x, y);
    map.debug = MapDebug {
        plot_points: vec![d(0.0, 0.0), d(10.0, 0.0), d(20.0, 5.0)],
        fans: vec![MapFan {
            from: d(0.0, 0.0),
            samples: vec![d(9.0, -3.0), d(10.0, 0.0), d(9.0, 3.0)],
            chosen: 1,
        }],
        splits: (0..5)
            .map(|i| MapSplit {
                block: 7 + (i / 3) as u64,
                chords: (0..=(i % 2))
                    .map(|k| {
                        [
                            d(i as f64, k as f64 * 10.0),
                            d(i as f64, k as f64 * 10.0 + 5.0),
                        ]
                    })
                    .collect(),
            })
            .collect(),
    };
    let plain = svg(&map, &SvgOptions::default());
    assert!(!plain.contains("debug-"));
    let o = SvgOptions {
        debug: SvgDebug::all(),
        ..SvgOptions::default()
    };
    let text = svg(&map, &o);
    let els = check_xml(&text);
    let groups: Vec<&str> = els
        .iter()
        .filter(|e| e.0 == "g")
        .filter_map(|e| attr(e, "id"))
        .collect();
    assert_eq!(
        groups[6..],
        [
            "debug-plot",
            "debug-fans",
            "debug-blocks",
            "debug-lots",
            "debug-splits"
        ]
    );
    let splits: Vec<_> = els
        .iter()
        .filter(|e| e.0 == "path" && attr(e, "class") == Some("split"))
        .collect();
    assert_eq!(splits.len(), map.debug.splits.len());
    for (i, (e, s)) in splits.iter().zip(&map.debug.splits).enumerate() {
        assert_eq!(attr(e, "data-order"), Some(i.to_string().as_str()));
        assert_eq!(attr(e, "data-block"), Some(s.block.to_string().as_str()));
        let moves = attr(e, "d").unwrap().matches('M').count();
        assert_eq!(moves, s.chords.len());
    }
    let dots = els.iter().filter(|e| e.0 == "circle").count();
    assert_eq!(dots, 3);
    let chosen = els
        .iter()
        .filter(|e| attr(e, "class") == Some("chosen"))
        .count();
    assert_eq!(chosen, 1);
    // Outlines of every block and lot.
    let outlines = |id: &str| {
        let start = text.find(&format!("<g id=\"{id}\"")).unwrap();
        let end = start + text[start..].find("</g>").unwrap();
        text[start..end].matches("<path").count()
    };
    assert_eq!(outlines("debug-blocks"), map.blocks.len());
    assert_eq!(outlines("debug-lots"), map.lots.len());
    // A chosen index beyond the samples is refused.
    map.debug.fans[0].chosen = 3;
    let mut out = Vec::new();
    assert!(matches!(
        write_svg(&map, &o, &mut out),
        Err(ExportError::InvalidMap { .. })
    ));
}

#[test]
fn tunnels_are_dashed_under_every_other_road() {
    let mut map = MapLayers::default();
    map.roads.push(MapRoad::new(
        vec![DVec2::new(-20.0, 10.0), DVec2::new(20.0, 10.0)],
        RoadClass::Footpath,
        2.0,
    ));
    map.roads.push(MapRoad {
        tunnel: true,
        ..MapRoad::new(
            vec![DVec2::new(0.0, 0.0), DVec2::new(0.0, 50.0)],
            RoadClass::Highway,
            10.0,
        )
    });
    let text = svg(&map, &SvgOptions::default());
    let els = check_xml(&text);
    let paths: Vec<_> = els.iter().filter(|e| e.0 == "path").collect();
    let classes: Vec<&str> = paths.iter().map(|e| attr(e, "class").unwrap()).collect();
    // The tunnel first (under the footpath that crosses over it), then the footpath.
    assert_eq!(classes, ["highway tunnel", "footpath"]);
    assert_eq!(attr(paths[0], "stroke-dasharray"), Some("8 6"));
    assert_eq!(attr(paths[1], "stroke-dasharray"), None);
}
