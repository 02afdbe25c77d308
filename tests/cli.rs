//! The `city` and `custom_stage` example programs as a user meets them: `--help` succeeds,
//! `--x=y` is accepted, a mistyped flag gets a suggestion, an out-of-range value is an
//! error with a non-zero exit status, and the error starts its own line.
//!
//! `cargo test` builds every example next to the test binaries
//! (`target/<profile>/examples/`); the tests run those binaries. Running this file alone
//! (`cargo test --test cli`) does not build examples: run `cargo build --examples` first.
//! (The `render` example is built as a test harness, so its command line is tested by
//! its own unit tests.)

#![allow(clippy::expect_used)] // tests may panic on failure

use std::path::PathBuf;
use std::process::{Command, Output};

/// The built example `name`, beside this test's `deps/` folder.
fn example(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let profile_dir = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("test binaries live in target/<profile>/deps");
    let path = profile_dir
        .join("examples")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.is_file(),
        "{} is missing: `cargo test` builds the examples; with a target filter run \
         `cargo build --examples` first",
        path.display()
    );
    path
}

fn run(name: &str, args: &[&str]) -> Output {
    Command::new(example(name))
        .args(args)
        .output()
        .expect("the example runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn help_exits_zero_and_lists_every_flag() {
    let out = run("city", &["--help"]);
    assert!(out.status.success(), "{out:?}");
    let help = text(&out.stdout);
    for flag in [
        "--preset",
        "--config",
        "--seed",
        "--size",
        "--lod",
        "--segments",
        "--threads",
        "--out",
        "--population",
        "--water",
        "--parks",
        "--zoning",
        "--elevation <PNG> <METRES>",
        "--max-height <PNG> <METRES>",
        "--report",
        "--formats",
        "--anchor <LON,LAT>",
    ] {
        assert!(help.contains(flag), "--help misses {flag}:\n{help}");
    }
    // The presets are listed, so a user can pick one without reading the source.
    assert!(help.contains("manhattan"), "{help}");
    assert!(out.stderr.is_empty(), "{}", text(&out.stderr));
}

#[test]
fn a_mistyped_flag_gets_a_suggestion() {
    let out = run("city", &["--sede", "7"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = text(&out.stderr);
    assert!(err.starts_with("error: "), "{err}");
    assert!(
        err.contains("'--sede'") && err.contains("'--seed'"),
        "{err}"
    );

    let out = run("city", &["--preset=manhatan"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    assert!(
        text(&out.stderr).contains("'manhattan'"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn out_of_range_values_are_errors_not_clamped() {
    // `--seed=7` (the `--x=y` form) parses; the LOD above the preset's maximum fails
    // before any city is generated.
    let out = run("city", &["--seed=7", "--lod=99"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = text(&out.stderr);
    assert!(err.starts_with("error: --lod 99"), "{err}");
    assert!(err.contains("0..=6"), "{err}");
    assert!(
        out.stdout.is_empty(),
        "nothing generated: {}",
        text(&out.stdout)
    );

    for args in [
        &["--threads", "0"][..],
        &["--size", "-5"],
        &["--seed", "x"],
        &["--elevation", "a.png", "high"],
        &["--formats=glb,gltf"],
        &["--anchor", "200,10"],
        &["--anchor=-10"],
    ] {
        let out = run("city", args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {out:?}");
        assert!(text(&out.stderr).starts_with("error: "), "{args:?}");
    }
}

#[test]
fn config_errors_start_on_their_own_line() {
    // A configuration the library refuses: the message is clap's, on its own line, and
    // nothing was written to standard output (no progress bar, no half line).
    let dir = std::env::temp_dir().join(format!("polis-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bad = dir.join("bad.json");
    std::fs::write(&bad, r#"{ "size_m": -4 }"#).expect("write config");
    let out = run("city", &["--config", bad.to_str().expect("utf-8 path")]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let err = text(&out.stderr);
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains("size_m"), "{err}");
    assert!(!err.contains('\r'), "{err:?}");
    assert!(out.stdout.is_empty());
}

#[test]
fn the_custom_road_stage_makes_a_whole_city() {
    let dir = std::env::temp_dir().join(format!("polis-cli-grid-{}", std::process::id()));
    let out = run("custom_stage", &["150", dir.to_str().expect("utf-8 path")]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(stdout.starts_with("grid roads every 150 m"), "{stdout}");
    assert!(dir.join("city.svg").is_file() && dir.join("city.glb").is_file());
    assert!(!dir.join("city.obj").exists(), "only the formats asked for");
    let _ = std::fs::remove_dir_all(&dir);
    // A bad parameter is the stage's typed error, not a panic.
    let out = run("custom_stage", &["5"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).starts_with("error: stage roads: spacing 5 m"));
}

/// The GeoJSON of `city --anchor`, read back by an independent RFC 7946 reader (the
/// `geojson` crate): every position is a WGS 84 longitude/latitude inside the valid
/// ranges and within the city's reach of the anchor; the same run without `--anchor`
/// writes local metres.
#[test]
fn anchored_geojson_from_the_cli_is_wgs84() {
    fn positions(value: &geojson::Value, out: &mut Vec<Vec<f64>>) {
        match value {
            geojson::Value::Point(p) => out.push(p.clone()),
            geojson::Value::MultiPoint(ps) | geojson::Value::LineString(ps) => {
                out.extend(ps.iter().cloned())
            }
            geojson::Value::Polygon(rings) | geojson::Value::MultiLineString(rings) => {
                rings.iter().for_each(|r| out.extend(r.iter().cloned()))
            }
            geojson::Value::MultiPolygon(polys) => polys
                .iter()
                .flatten()
                .for_each(|r| out.extend(r.iter().cloned())),
            geojson::Value::GeometryCollection(gs) => {
                gs.iter().for_each(|g| positions(&g.value, out))
            }
        }
    }
    fn read(path: &std::path::Path) -> Vec<Vec<f64>> {
        let text = std::fs::read_to_string(path).expect("the GeoJSON was written");
        let parsed: geojson::GeoJson = text.parse().expect("valid GeoJSON");
        let geojson::GeoJson::FeatureCollection(fc) = parsed else {
            panic!("a FeatureCollection");
        };
        let mut all = Vec::new();
        for f in &fc.features {
            if let Some(g) = &f.geometry {
                positions(&g.value, &mut all);
            }
        }
        all
    }
    let dir = std::env::temp_dir().join(format!("polis-cli-geo-{}", std::process::id()));
    let dir_arg = dir.to_str().expect("utf-8 path");
    let common = ["--size=400", "--formats=geojson", "--out", dir_arg];
    let out = run("city", &[&common[..], &["--anchor=-73.98,40.75"]].concat());
    assert!(out.status.success(), "{}", text(&out.stderr));
    let geo = read(&dir.join("city.geojson"));
    assert!(
        !dir.join("city.glb").exists(),
        "only the GeoJSON was asked for"
    );
    let out = run("city", &common);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let local = read(&dir.join("city.geojson"));
    let _ = std::fs::remove_dir_all(&dir);

    assert!(
        geo.len() > 100,
        "a city has features: {} positions",
        geo.len()
    );
    assert_eq!(geo.len(), local.len(), "the same features in both systems");
    // 400 m of layout is about 0.005° of longitude and 0.004° of latitude at 40.75° N.
    for (g, l) in geo.iter().zip(&local) {
        let [lon, lat] = [g[0], g[1]];
        assert!((-180.0..=180.0).contains(&lon) && (-90.0..=90.0).contains(&lat));
        assert!(
            (lon + 73.98).abs() < 0.01 && (lat - 40.75).abs() < 0.01,
            "{g:?}"
        );
        // Local metres: the same point (within the projection's scale, well under 1 %).
        let north_m = (lat - 40.75).to_radians() * 6_378_137.0;
        assert!(
            (north_m - l[1]).abs() < 0.01 * l[1].abs() + 1.0,
            "{g:?} vs {l:?}"
        );
    }
}
