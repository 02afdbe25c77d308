//! `City::write_all`: the chosen formats only, every written file listed, textures in
//! their subfolder where the MTL finds them, and GeoJSON in WGS 84 when anchored, read
//! back by an independent GeoJSON reader.

#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic on failure

use std::path::{Path, PathBuf};

use polis::{City, CityConfig, Formats, TEXTURE_DIR, WriteOptions};

fn small_city() -> City {
    let mut c = CityConfig::preset("default").unwrap();
    c.size_m = 900.0;
    c.roads.max_segments = 160;
    c.facades.pixels_per_metre = 4.0;
    polis::generate(&c).unwrap()
}

fn temp(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polis-outputs-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Every file under `dir`, sorted.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else {
            out.push(path);
        }
    }
    out.sort();
    out
}

#[test]
fn written_lists_every_file_and_textures_sit_in_their_folder() {
    let city = small_city();
    let dir = temp("all");
    let written = city.write_all(&dir, Formats::ALL).unwrap();
    let mut listed = written.files.clone();
    listed.sort();
    assert_eq!(
        listed,
        files_under(&dir),
        "Written must list exactly what is on disk"
    );
    // No texture lies beside the OBJ; every texture the MTL names exists.
    let loose_png = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            let p = e.as_ref().unwrap().path();
            p.is_file() && p.extension().is_some_and(|x| x == "png")
        })
        .count();
    assert_eq!(loose_png, 0);
    let mtl = std::fs::read_to_string(dir.join("city.mtl")).unwrap();
    let maps: Vec<&str> = mtl
        .lines()
        .filter_map(|l| l.strip_prefix("map_Kd "))
        .collect();
    assert!(!maps.is_empty(), "the small city's facades are textured");
    for m in maps {
        assert!(m.starts_with(&format!("{TEXTURE_DIR}/")), "{m}");
        assert!(dir.join(m).is_file(), "{m} missing");
    }
    // The glb embeds its images: no external URI.
    let glb = gltf::Gltf::from_slice(&std::fs::read(dir.join("city.glb")).unwrap()).unwrap();
    assert!(glb.images().count() > 0);
    for image in glb.images() {
        assert!(matches!(image.source(), gltf::image::Source::View { .. }));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn only_the_chosen_formats_are_written() {
    let city = small_city();
    let dir = temp("some");
    let formats: Formats = "svg,geojson".parse().unwrap();
    let written = city.write_all(&dir, formats).unwrap();
    assert_eq!(
        written.files,
        vec![dir.join("city.svg"), dir.join("city.geojson")]
    );
    assert_eq!(files_under(&dir).len(), 2);
    let written = city.write_all(&dir, Formats::NONE).unwrap();
    assert!(written.files.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

fn positions(geometry: &geojson::Value, out: &mut Vec<Vec<f64>>) {
    match geometry {
        geojson::Value::LineString(line) => out.extend(line.iter().cloned()),
        geojson::Value::Polygon(rings) => {
            out.extend(rings.iter().flat_map(|r| r.iter().cloned()));
        }
        other => panic!("unexpected geometry {other:?}"),
    }
}

fn read_geojson(path: &Path) -> (usize, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let parsed: geojson::GeoJson = text.parse().unwrap();
    let geojson::GeoJson::FeatureCollection(fc) = parsed else {
        panic!("not a FeatureCollection");
    };
    let mut all = Vec::new();
    for f in &fc.features {
        positions(&f.geometry.as_ref().unwrap().value, &mut all);
    }
    (fc.features.len(), all)
}

#[test]
fn anchored_geojson_is_wgs84_and_reads_back() {
    let city = small_city();
    let dir = temp("geo");
    let only = Formats {
        geojson: true,
        ..Formats::NONE
    };
    city.write_all(&dir, only).unwrap();
    let (n_local, local) = read_geojson(&dir.join("city.geojson"));
    // Near the antimeridian and far north, where the projection is most stretched.
    for anchor in [[13.4, 52.5], [-179.99, 0.0], [179.99, -33.9], [25.0, 70.0]] {
        let options = WriteOptions {
            formats: only,
            anchor_lon_lat: Some(anchor),
            ..WriteOptions::default()
        };
        city.write_all_with(&dir, &options).unwrap();
        let (n, geo) = read_geojson(&dir.join("city.geojson"));
        assert_eq!(n, n_local, "same features in both systems");
        assert_eq!(geo.len(), local.len());
        let r = 6_378_137.0_f64;
        for (g, l) in geo.iter().zip(&local) {
            let [lon, lat] = [g[0], g[1]];
            assert!((-180.0..=180.0).contains(&lon) && (-90.0..=90.0).contains(&lat));
            // Within the city's reach of the anchor: half a kilometre of layout is at
            // most a few thousandths of a degree of latitude.
            let dlat = (lat - anchor[1]).to_radians() * r;
            assert!(
                (dlat - l[1]).abs() < 0.01 * l[1].abs() + 1.0,
                "{g:?} vs {l:?}"
            );
            let dlon = (lon - anchor[0]).to_radians() * r * anchor[1].to_radians().cos();
            assert!(
                (dlon - l[0]).abs() < 0.01 * l[0].abs() + 1.0,
                "{g:?} vs {l:?}"
            );
        }
    }
    // A city on the antimeridian itself is refused, not wrapped.
    let options = WriteOptions {
        formats: only,
        anchor_lon_lat: Some([180.0, 0.0]),
        ..WriteOptions::default()
    };
    assert!(city.write_all_with(&dir, &options).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}
