//! Grammar fuzzing without cargo-fuzz: random and mutated building grammar texts are
//! parsed and, when they parse, derived and drawn on lots. Nothing may panic; errors are
//! typed; whatever is built keeps every mesh invariant.
//!
//! Inputs are biased to the hard cases: the shipped grammars with bytes flipped, lines
//! dropped, duplicated or spliced from another grammar; token soups of shape modules,
//! brackets, operators and extreme numbers (0, −0, 1e308, NaN-producing divisions,
//! negative sizes); deep recursion that runs into the string-length limit.

use polis_buildings::{
    BuildingGenerator, BuildingGrammar, BuildingKind, BuildingParams, BuildingsError,
};
use polis_geom::{DVec2, Polygon};
use polis_lots::Lot;
use proptest::prelude::*;

const TOKENS: &[&str] = &[
    "Lot",
    "Lot(h, w, d, n)",
    "Extrude",
    "Scale",
    "Move",
    "Up",
    "Setback",
    "Taper",
    "Box",
    "Flat",
    "Gable",
    "Hip",
    "Mansard",
    "Pyramid",
    "Antenna",
    "Spire",
    "Template",
    "A",
    "B",
    "Walls",
    "[",
    "]",
    "%",
    "(",
    ")",
    ",",
    "->",
    ":",
    "*",
    "/",
    "-",
    "+",
    "^",
    "?",
    "h",
    "w",
    "d",
    "n",
    "x",
    "0",
    "-0",
    "1",
    "0.5",
    "1e308",
    "-1e308",
    "1e-300",
    "h/0",
    "0/0",
    "99",
    "#module Walls A B",
    "#define K 3",
    "p1:",
    "p2:",
    "\n",
    " ",
    "ε",
    ";",
    "//",
    "/*",
    "*/",
    "min(",
    "max(",
    "sqrt(",
    "log(",
    "&&",
    "||",
    "==",
    "<",
    ">",
    "!",
];

fn lot() -> Lot {
    let polygon = Polygon::new(vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(30.0, 0.0),
        DVec2::new(30.0, 12.0),
        DVec2::new(14.0, 12.0),
        DVec2::new(14.0, 28.0),
        DVec2::new(0.0, 28.0),
    ]);
    Lot {
        area: polygon.area(),
        polygon,
        street_edges: vec![0],
        block_id: 0,
    }
}

/// Well-formed shape modules with extreme arguments, so that most soups parse and the
/// derivation and the interpreter get exercised.
const MODULES: &[&str] = &[
    "Extrude(h * 0.5)",
    "Extrude(0)",
    "Extrude(-5)",
    "Extrude(1e308)",
    "Extrude(h / 0)",
    "Scale(0.5, 2, 1)",
    "Scale(0, 0, 0)",
    "Scale(-1, 1, 1)",
    "Scale(1e-300, 1e300, 2)",
    "Move(3, -2, 1)",
    "Move(1e308, 0, 0)",
    "Move(0, 0, -10)",
    "Up",
    "Up Up",
    "Setback(1)",
    "Setback(1e9)",
    "Setback(-1)",
    "Taper(0.7)",
    "Taper(3)",
    "Taper(0/0)",
    "Box",
    "Flat",
    "Gable(40)",
    "Gable(89.9)",
    "Hip(0)",
    "Hip(35)",
    "Mansard(1.5)",
    "Mansard(40, 80)",
    "Mansard(0.01, 0)",
    "Pyramid",
    "Antenna(0.5)",
    "Antenna(1e9)",
    "Spire(3)",
    "Spire(-1)",
    "Template(0)",
    "A",
    "B(h, w)",
    "Walls",
    "[",
    "]",
    "%",
];

/// A token soup: a first production that usually parses, of shape modules mixed with
/// junk tokens, and a second production for `A`.
fn soup() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        24 => prop::sample::select(MODULES),
        1 => prop::sample::select(TOKENS),
    ];
    (
        prop::bool::weighted(0.8),
        prop::collection::vec(piece.clone(), 0..30),
        prop::collection::vec(piece, 0..12),
    )
        .prop_map(|(head, a, b)| {
            let mut s = String::new();
            if head {
                s.push_str("#module Walls\np1: Lot(h, w, d, n) -> ");
            }
            s.push_str(&a.join(" "));
            s.push_str("\np2: A -> ");
            s.push_str(&b.join(" "));
            s.push('\n');
            s
        })
}

/// A shipped grammar with random edits.
fn mutated() -> impl Strategy<Value = String> {
    (
        0usize..6,
        0usize..6,
        prop::collection::vec((0usize..4, any::<prop::sample::Index>(), any::<u8>()), 1..4),
    )
        .prop_map(|(k, other, edits)| {
            let mut bytes = polis_buildings::default_text(BuildingKind::ALL[k])
                .as_bytes()
                .to_vec();
            let donor = polis_buildings::default_text(BuildingKind::ALL[other]);
            for (op, at, b) in edits {
                if bytes.is_empty() {
                    break;
                }
                let i = at.index(bytes.len());
                match op {
                    0 => bytes[i] = b,
                    1 => {
                        bytes.remove(i);
                    }
                    2 => {
                        let pool = b"()[],:->*%0123456789.eE+-/\n ";
                        bytes.insert(i, pool[b as usize % pool.len()]);
                    }
                    _ => {
                        // Splice a line of another grammar in.
                        let lines: Vec<&str> = donor.lines().collect();
                        let line = lines[b as usize % lines.len()];
                        let tail = bytes.split_off(i);
                        bytes.extend_from_slice(b"\n");
                        bytes.extend_from_slice(line.as_bytes());
                        bytes.extend_from_slice(b"\n");
                        bytes.extend_from_slice(&tail);
                    }
                }
            }
            String::from_utf8_lossy(&bytes).into_owned()
        })
}

/// Parses and, when it parses, builds every LOD up to 4; checks what comes out.
fn exercise(text: &str) -> Result<(), TestCaseError> {
    let g = match BuildingGrammar::parse("fuzz", text) {
        Ok(g) => g,
        Err(e) => {
            prop_assert!(
                matches!(
                    e,
                    BuildingsError::Grammar { .. } | BuildingsError::GrammarContent { .. }
                ),
                "unexpected error kind: {e}"
            );
            prop_assert!(
                e.to_string().contains("fuzz"),
                "the message names the grammar"
            );
            return Ok(());
        }
    };
    let mut generator = BuildingGenerator::new(BuildingParams {
        max_lod: 4,
        ..BuildingParams::default()
    })
    .map_err(|e| TestCaseError::fail(e.to_string()))?;
    generator.set_grammar(BuildingKind::Office, g);
    let l = lot();
    match generator.lods(&l, 11, BuildingKind::Office, 80.0) {
        Ok(lods) => {
            for b in &lods {
                prop_assert!(b.height <= 80.0);
                for p in &b.parts {
                    p.mesh
                        .validate()
                        .map_err(|e| TestCaseError::fail(e.to_string()))?;
                    p.mesh
                        .check_closed()
                        .map_err(|e| TestCaseError::fail(e.to_string()))?;
                    prop_assert!(p.mesh.signed_volume() > 0.0);
                    prop_assert!(p.mesh.bbox().max.y as f64 <= b.height + 1e-3);
                }
                // Any grammar: the merge never panics; a merged solid passes the check,
                // an unmerged one says why.
                let solid = b.merged_solid();
                if solid.closed {
                    let report = polis_geom::mesh::edge_use(solid.meshes.iter().map(|(_, m)| m));
                    prop_assert!(report.is_solid(), "{:?}", report);
                } else {
                    prop_assert!(solid.unmerged_because.is_some());
                }
            }
        }
        Err(e) => prop_assert!(
            matches!(
                e,
                BuildingsError::Derivation { .. }
                    | BuildingsError::Lots(_)
                    | BuildingsError::Geom(_)
            ),
            "unexpected error kind: {e}"
        ),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn token_soups_never_panic(text in soup()) {
        exercise(&text)?;
    }

    #[test]
    fn mutated_shipped_grammars_never_panic(text in mutated()) {
        exercise(&text)?;
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        exercise(&text)?;
    }
}

/// Inputs once found interesting, pinned.
#[test]
fn pinned_grammar_edge_cases() {
    for text in [
        "",
        "p1: Lot(h, w, d, n) ->",
        "p1: Lot(h, w, d, n) -> Extrude(1e308) Box Up Extrude(1e308) Box",
        "p1: Lot(h, w, d, n) -> Scale(0, 0, 0) Box Scale(-1, 2, 1) Box Taper(1e-300) Hip(89)",
        "p1: Lot(h, w, d, n) -> Move(1e308, -1e308, 0) Box Setback(1e308) Box Mansard(-1, 400)",
        "p1: Lot(h, w, d, n) -> Extrude(h/0) Box Extrude(0/0) Flat Spire(0/0) Antenna(1e9)",
        "p1: Lot(h, w, d, n) -> ]]]] Box [[[[ Box Template(-1) Template(1e20)",
        "#module A\np1: Lot(h, w, d, n) -> A\np2: A -> A A A A A A A A",
        "p1: Lot(h, w, d, n) -> Lot(h, w, d, n) Lot(h, w, d, n)",
        "p1: Lot -> Box",
        "#define Lot 3\np1: Lot(h, w, d, n) -> Box",
    ] {
        exercise(text).unwrap_or_else(|e| panic!("{text:?}: {e}"));
    }
}
