use super::*;
use crate::testing::sample_map;
use serde_json::Value;

fn geojson(map: &MapLayers, o: &GeoJsonOptions) -> (Vec<u8>, Value) {
    let mut out = Vec::new();
    let report = write_geojson(map, o, &mut out).unwrap();
    let v: Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(v["features"].as_array().unwrap().len(), report.features);
    (out, v)
}

fn ring_area(ring: &[Value]) -> f64 {
    let pts: Vec<(f64, f64)> = ring
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    assert_eq!(pts.first(), pts.last(), "closed ring");
    pts.windows(2)
        .map(|w| w[0].0 * w[1].1 - w[1].0 * w[0].1)
        .sum::<f64>()
        / 2.0
}

#[test]
fn feature_collection_with_properties_and_crs_note() {
    let map = sample_map();
    let (_, v) = geojson(&map, &GeoJsonOptions::default());
    assert_eq!(v["type"], "FeatureCollection");
    assert_eq!(v[CRS_MEMBER]["type"], "local-metric");
    assert_eq!(v[CRS_MEMBER]["units"], "m");
    assert!(v.get("crs").is_none(), "RFC 7946 removed crs");
    let features = v["features"].as_array().unwrap();
    assert_eq!(features.len(), 1 + 1 + 2 + 6 + 5 + 6);
    let layer = |f: &Value| f["properties"]["layer"].as_str().unwrap().to_string();
    let layers: Vec<String> = features.iter().map(layer).collect();
    assert_eq!(layers[0], "water");
    assert_eq!(layers[1], "park");
    assert_eq!(layers.iter().filter(|l| *l == "building").count(), 6);
    for f in features {
        assert_eq!(f["type"], "Feature");
        assert!(f["id"].is_string());
        let g = &f["geometry"];
        match g["type"].as_str().unwrap() {
            "Polygon" => {
                let rings = g["coordinates"].as_array().unwrap();
                assert!(
                    ring_area(rings[0].as_array().unwrap()) > 0.0,
                    "outer ring ccw"
                );
                for h in &rings[1..] {
                    assert!(ring_area(h.as_array().unwrap()) < 0.0, "holes cw");
                }
            }
            "LineString" => {
                assert!(g["coordinates"].as_array().unwrap().len() >= 2);
                assert_eq!(layer(f), "road");
            }
            other => panic!("geometry {other}"),
        }
    }
    // Water keeps its island; the clockwise park was turned counter-clockwise.
    assert_eq!(
        features[0]["geometry"]["coordinates"]
            .as_array()
            .unwrap()
            .len(),
        2
    );
    // Roads.
    let bridge = features.iter().find(|f| f["id"] == "road-2").unwrap();
    assert_eq!(bridge["properties"]["class"], "major");
    assert_eq!(bridge["properties"]["width_m"], 12.0);
    assert_eq!(bridge["properties"]["bridge"], true);
    assert_eq!(
        bridge["geometry"]["coordinates"],
        serde_json::json!([[190.0, 50.0], [270.0, 50.0]])
    );
    let tram = features.iter().find(|f| f["id"] == "road-5").unwrap();
    assert_eq!(tram["properties"]["class"], "tram \"line\"");
    // Buildings and lots.
    let b = features
        .iter()
        .find(|f| f["id"] == "building-1004")
        .unwrap();
    assert_eq!(b["properties"]["kind"], "church & <hall>");
    assert_eq!(b["properties"]["floors"], 3);
    assert_eq!(b["properties"]["lot"], 104);
    assert_eq!(b["properties"]["height_m"], 9.5);
    let lot = features.iter().find(|f| f["id"] == "lot-104").unwrap();
    assert_eq!(lot["properties"]["block"], Value::Null);
    let lot = features.iter().find(|f| f["id"] == "lot-101").unwrap();
    assert_eq!(lot["properties"]["block"], 10);
}

#[test]
fn coordinates_round_trip_exactly_and_output_is_stable() {
    let mut map = MapLayers::default();
    let p = [
        DVec2::new(0.1, 1.0 / 3.0),
        DVec2::new(-1234.5678901234, 1e-9),
    ];
    map.roads.push(crate::map::MapRoad::new(
        p.to_vec(),
        crate::map::RoadClass::Street,
        7.25,
    ));
    let (bytes, v) = geojson(&map, &GeoJsonOptions::default());
    let c = &v["features"][0]["geometry"]["coordinates"];
    for (k, q) in p.iter().enumerate() {
        assert_eq!(c[k][0].as_f64().unwrap(), q.x);
        assert_eq!(c[k][1].as_f64().unwrap(), q.y);
    }
    let (again, _) = geojson(&map.clone(), &GeoJsonOptions::default());
    assert_eq!(bytes, again);
    let pretty = GeoJsonOptions {
        pretty: true,
        anchor_lon_lat: Some([13.4, 52.5]),
        ..GeoJsonOptions::default()
    };
    let (pb, pv) = geojson(&map, &pretty);
    assert!(pb.len() > bytes.len());
    assert_eq!(pv["features"], v["features"]);
    assert_eq!(
        pv[CRS_MEMBER]["anchor_lon_lat"],
        serde_json::json!([13.4, 52.5])
    );
}

#[test]
fn layers_selectable_and_errors() {
    let map = sample_map();
    let only_roads = GeoJsonOptions {
        layers: LayerSet {
            roads: true,
            ..LayerSet::NONE
        },
        ..GeoJsonOptions::default()
    };
    let (_, v) = geojson(&map, &only_roads);
    assert_eq!(v["features"].as_array().unwrap().len(), 5);
    let none = GeoJsonOptions {
        layers: LayerSet::NONE,
        ..GeoJsonOptions::default()
    };
    let (_, v) = geojson(&map, &none);
    assert_eq!(v["features"], serde_json::json!([]));

    let mut out = Vec::new();
    let bad = GeoJsonOptions {
        anchor_lon_lat: Some([200.0, 0.0]),
        ..GeoJsonOptions::default()
    };
    assert!(matches!(
        write_geojson(&map, &bad, &mut out),
        Err(ExportError::InvalidOption { .. })
    ));
    let mut m = map.clone();
    m.roads[0].width_m = f64::NAN;
    assert!(matches!(
        write_geojson(&m, &GeoJsonOptions::default(), &mut out),
        Err(ExportError::InvalidMap { .. })
    ));
    assert!(out.is_empty());
}

#[test]
fn tunnels_keep_their_flag() {
    let mut map = sample_map();
    map.roads[2].tunnel = true;
    let id = format!("road-{}", map.roads[2].id);
    let (_, v) = geojson(&map, &GeoJsonOptions::default());
    let features = v["features"].as_array().unwrap();
    let roads: Vec<&Value> = features
        .iter()
        .filter(|f| f["properties"]["layer"] == "road")
        .collect();
    assert_eq!(roads.len(), map.roads.len());
    for f in roads {
        assert_eq!(f["properties"]["tunnel"], f["id"] == id.as_str(), "{f}");
    }
}
