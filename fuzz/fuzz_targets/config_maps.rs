//! Bytes as a city configuration (JSON text, with or without a byte-order mark) and as a
//! PNG map: parsing and validation never panic; a configuration that validates has maps
//! that build (PNG paths are not followed) and whose samples lie in the value ranges
//! `validate` checked; a PNG decodes or gives a typed error, never more than the pixel
//! limit.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polis::{CityConfig, CityMaps, MapSpec};
use polis_geom::field::{Raster, decode_png_rgba8_limited};
use polis_geom::{Aabb2, DVec2};

/// Whether a map reads a file (not followed while fuzzing).
fn reads_files(spec: &MapSpec) -> bool {
    let json = serde_json::to_string(spec).unwrap_or_default();
    json.contains("\"png\"")
}

fuzz_target!(|data: &[u8]| {
    // The map loader: any bytes as a PNG, under a small pixel limit.
    let extent = Aabb2::new(DVec2::ZERO, DVec2::new(100.0, 100.0));
    if let Ok(r) = Raster::from_png_bytes_limited(data, extent, 1 << 16) {
        assert!(r.width() * r.height() <= 1 << 16);
        assert!(r.data().iter().all(|v| (0.0..=1.0).contains(v)));
    }
    if let Ok((w, h, rgba)) = decode_png_rgba8_limited(data, 1 << 16) {
        assert_eq!(rgba.len(), w as usize * h as usize * 4);
    }
    // The configuration.
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(config) = CityConfig::from_json(text, "fuzz") else {
        return;
    };
    config.validate().expect("from_json validated it");
    let m = &config.maps;
    let mut all = vec![&m.population];
    all.extend(
        [
            &m.water,
            &m.parks,
            &m.elevation,
            &m.zoning,
            &m.max_height,
            &m.grid_angle,
        ]
        .into_iter()
        .flatten(),
    );
    all.extend(m.pattern_weights.iter().map(|p| &p.map));
    if all.iter().any(|s| reads_files(s)) {
        return;
    }
    let Ok(maps) = CityMaps::build(m, config.seed) else {
        return;
    };
    let h = config.size_m * 0.5;
    let checks: [(Option<&MapSpec>, Option<&dyn polis_geom::Field>); 3] = [
        (Some(&m.population), Some(maps.inputs.population.as_ref())),
        (m.elevation.as_ref(), Some(maps.inputs.elevation.as_ref())),
        (m.max_height.as_ref(), maps.max_height.as_deref()),
    ];
    for (spec, field) in checks {
        let (Some(spec), Some(field)) = (spec, field) else {
            continue;
        };
        let (lo, hi) = spec.value_range();
        for k in 0..9 {
            let p = DVec2::new(
                h * (f64::from(k % 3) - 1.0) * 0.7,
                h * (f64::from(k / 3) - 1.0) * 0.7,
            );
            let v = field.sample(p);
            if v.is_finite() {
                let slack = 1e-9 * (1.0 + lo.abs().max(hi.abs()));
                assert!(
                    v >= lo - slack && v <= hi + slack,
                    "{v} outside [{lo}, {hi}]"
                );
            }
        }
    }
});
