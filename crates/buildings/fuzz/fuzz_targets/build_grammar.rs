//! Arbitrary text as a building grammar: parsing must never panic; whatever parses is
//! derived and drawn at every LOD up to 4 on a concave lot, which must give a typed
//! error or buildings whose parts are valid, closed and of positive volume, under the
//! height limit.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polis_buildings::{BuildingGenerator, BuildingGrammar, BuildingKind, BuildingParams};
use polis_geom::{DVec2, Polygon};
use polis_lots::Lot;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(grammar) = BuildingGrammar::parse("fuzz", text) else {
        return;
    };
    let Ok(mut generator) = BuildingGenerator::new(BuildingParams {
        max_lod: 4,
        ..BuildingParams::default()
    }) else {
        return;
    };
    generator.set_grammar(BuildingKind::Office, grammar);
    let polygon = Polygon::new(
        [
            (0.0, 0.0),
            (30.0, 0.0),
            (30.0, 12.0),
            (14.0, 12.0),
            (14.0, 28.0),
            (0.0, 28.0),
        ]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec(),
    );
    let lot = Lot {
        area: polygon.area(),
        polygon,
        street_edges: vec![0],
        block_id: 0,
    };
    let Ok(lods) = generator.lods(&lot, 11, BuildingKind::Office, 80.0) else {
        return;
    };
    for b in &lods {
        assert!(b.height <= 80.0);
        for p in &b.parts {
            p.mesh.validate().expect("valid mesh");
            p.mesh.check_closed().expect("closed mesh");
            assert!(p.mesh.signed_volume() > 0.0, "positive volume");
            assert!(f64::from(p.mesh.bbox().max.y) <= b.height + 1e-3);
        }
    }
});
