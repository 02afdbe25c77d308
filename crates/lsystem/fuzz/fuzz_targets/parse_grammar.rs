//! Arbitrary text must never panic the grammar parser; whatever parses must print and
//! parse back to the same syntax tree, and derive a few steps without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polis_lsystem::{DeriveOptions, Grammar};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(g) = Grammar::parse(text) else {
        return;
    };
    let printed = g.to_text();
    let again = Grammar::parse(&printed).expect("printed grammar must parse");
    assert_eq!(g.ast(), again.ast(), "round trip changed the grammar:\n{printed}");
    let mut d = g.derivation(DeriveOptions {
        max_len: 10_000,
        max_steps: 8,
        ..DeriveOptions::default()
    });
    let _ = d.derive(4);
    let mut sink = polis_lsystem::Geometry::default();
    let _ = d.interpret(&mut sink);
});
