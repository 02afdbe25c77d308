//! Building grammars: text L-systems over the shape modules, and the shipped defaults.
//!
//! A building grammar is a [`polis_lsystem`] text grammar. The shape modules are declared
//! for you (a one-line `#module` prelude); declare your own non-terminals with `#module`
//! when their names are longer than one character. The derivation starts from the axiom
//! `Lot(h, w, d, n)`: the building's bounding volume, `h` metres high (drawn from the
//! height distribution under the maximum-height map), `w` × `d` metres along and across
//! the primary street edge, with `n` storeys. Any axiom written in the text is replaced.
//!
//! | module | effect on the current shape (footprint, base, height) |
//! |---|---|
//! | `Extrude(h)` | height := `h` m |
//! | `Scale(sx, sy, sz)` | footprint scaled about its centroid along / across the street; height × `sz` |
//! | `Move(dx, dy, dz)` | footprint moved along / across the street; base + `dz` |
//! | `Up` | base := base + height (the next part stands on this one) |
//! | `Setback(d)` | footprint inset by `d` m (straight skeleton; the largest piece) |
//! | `Taper(f)` | footprint scaled by `f` about its centroid |
//! | `[` `]` | branch: save / restore the shape |
//! | `%` | terminate the rest of the branch (cut) |
//! | `Box` | emit the shape as a closed prism (a mass with facades) |
//! | `Flat` | flat roof slab filling the shape |
//! | `Hip(a)`, `Gable(a)` | hip / gable roof at pitch `a` degrees from the straight skeleton, within the shape's height |
//! | `Mansard(d, a)` | mansard roof: a steep lower slope from the straight skeleton cut at the inset by `d` m (any number of pieces), a shallow hip of pitch `a` degrees (default 15; 0 for flat) over every piece left |
//! | `Pyramid` | pyramid roof to the shape's top |
//! | `Spire(r)` | octagonal spire of radius `r` m at the centroid |
//! | `Antenna(r)` | square mast of half-width `r` m at the centroid |
//! | `Template(i)` | user template `i` fitted into the shape's box |
//!
//! Every other upper-case module (a non-terminal, `Lot` included) is drawn as its bounding
//! volume: the current shape as a box. This is what makes levels of detail free
//! (Parish & Müller §4.2): the string after `k` steps, drawn, is LOD `k`.
//!
//! Parts are clipped to the building's volume: anything above `h` is cut down or dropped,
//! and a footprint that leaves the lot terminates that part.

use std::cell::RefCell;
use std::sync::Arc;

use polis_lsystem::{Derivation, DeriveOptions, Grammar, LsystemError, ParamString};

use crate::BuildingsError;
use crate::generate::MAX_BUILDING_MODULES;
use crate::params::BuildingKind;

/// The shape modules, declared in front of every building grammar.
pub const SHAPE_MODULES: [&str; 16] = [
    "Lot", "Extrude", "Scale", "Move", "Up", "Setback", "Taper", "Box", "Flat", "Gable", "Hip",
    "Mansard", "Pyramid", "Antenna", "Spire", "Template",
];

/// What a symbol does in the shape interpreter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Op {
    Extrude,
    Scale,
    Move,
    Up,
    Setback,
    Taper,
    Box,
    Flat,
    Gable,
    Hip,
    Mansard,
    Pyramid,
    Antenna,
    Spire,
    Template,
    Push,
    Pop,
    /// A non-terminal: drawn as the current volume.
    Volume,
    Ignore,
}

/// A compiled building grammar.
#[derive(Debug, Clone)]
pub struct BuildingGrammar {
    name: String,
    /// Shared with the per-thread derivations that reuse their buffers.
    grammar: Arc<Grammar>,
    ops: Vec<Op>,
    lot: u32,
}

impl BuildingGrammar {
    /// Parses a building grammar text (see the [module docs](self) for the modules).
    ///
    /// Errors carry the line and column in `text`.
    pub fn parse(name: &str, text: &str) -> Result<Self, BuildingsError> {
        let prelude = format!("#module {}\n", SHAPE_MODULES.join(" "));
        let grammar = Grammar::parse(&(prelude + text)).map_err(|e| BuildingsError::Grammar {
            name: name.to_string(),
            source: match e {
                LsystemError::Parse {
                    line,
                    column,
                    message,
                    snippet,
                } => LsystemError::Parse {
                    line: line.saturating_sub(1),
                    column,
                    message,
                    snippet,
                },
                other => other,
            },
        })?;
        let lot = grammar
            .symbol_id("Lot")
            .ok_or_else(|| BuildingsError::GrammarContent {
                name: name.to_string(),
                reason: "no production for `Lot(h, w, d, n)`, the axiom; write one".into(),
            })?;
        let mut ops = Vec::new();
        let mut id = 0u32;
        while let Some(sym) = grammar.symbol_name(id) {
            let op = match sym {
                "Extrude" => Op::Extrude,
                "Scale" => Op::Scale,
                "Move" => Op::Move,
                "Up" => Op::Up,
                "Setback" => Op::Setback,
                "Taper" => Op::Taper,
                "Box" => Op::Box,
                "Flat" => Op::Flat,
                "Gable" => Op::Gable,
                "Hip" => Op::Hip,
                "Mansard" => Op::Mansard,
                "Pyramid" => Op::Pyramid,
                "Antenna" => Op::Antenna,
                "Spire" => Op::Spire,
                "Template" => Op::Template,
                "[" => Op::Push,
                "]" => Op::Pop,
                "F" | "G" => Op::Ignore,
                s if s.starts_with(|c: char| c.is_ascii_uppercase()) => Op::Volume,
                _ => Op::Ignore,
            };
            ops.push(op);
            id += 1;
        }
        Ok(BuildingGrammar {
            name: name.to_string(),
            grammar: Arc::new(grammar),
            ops,
            lot,
        })
    }

    /// The default grammar of a building kind (the text files in `crates/buildings/grammars/`).
    pub fn default_for(kind: BuildingKind) -> Result<Self, BuildingsError> {
        Self::parse(kind.name(), default_text(kind))
    }

    /// The grammar's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The compiled L-system.
    pub fn grammar(&self) -> &Grammar {
        &self.grammar
    }

    pub(crate) fn op(&self, symbol: u32) -> Op {
        self.ops.get(symbol as usize).copied().unwrap_or(Op::Ignore)
    }
}

/// The text of a kind's default grammar.
pub fn default_text(kind: BuildingKind) -> &'static str {
    match kind {
        BuildingKind::Skyscraper => include_str!("../grammars/skyscraper.lsys"),
        BuildingKind::Office => include_str!("../grammars/office.lsys"),
        BuildingKind::MidRise => include_str!("../grammars/mid_rise.lsys"),
        BuildingKind::House => include_str!("../grammars/house.lsys"),
        BuildingKind::Apartment => include_str!("../grammars/apartment.lsys"),
        BuildingKind::Industrial => include_str!("../grammars/industrial.lsys"),
    }
}

/// Derivations kept per thread (one per grammar met, the most recent last).
const KEPT_DERIVATIONS: usize = 8;

thread_local! {
    static DERIVATIONS: RefCell<Vec<Derivation<Arc<Grammar>>>> = const { RefCell::new(Vec::new()) };
}

/// The options of every building derivation with `seed`.
fn options(seed: u64) -> DeriveOptions {
    DeriveOptions {
        seed,
        max_len: MAX_BUILDING_MODULES,
        ..DeriveOptions::default()
    }
}

impl BuildingGrammar {
    /// Runs `f` on the derivation of this grammar from the axiom `Lot(axiom)` with
    /// `seed`: this thread's kept derivation of the grammar, restarted in place with the
    /// seed (it derives what a fresh `Derivation::new` would), so its string buffers and
    /// scratch space serve every building. `error` wraps an error of writing the axiom.
    pub(crate) fn derive<T>(
        &self,
        seed: u64,
        axiom: &[f64],
        error: impl Fn(LsystemError) -> BuildingsError,
        f: impl FnOnce(&mut Derivation<Arc<Grammar>>) -> Result<T, BuildingsError>,
    ) -> Result<T, BuildingsError> {
        let kept = DERIVATIONS.with(|k| {
            let mut k = k.try_borrow_mut().ok()?;
            let i = k
                .iter()
                .position(|d| Arc::ptr_eq(d.rules(), &self.grammar))?;
            Some(k.remove(i))
        });
        let mut d = kept.unwrap_or_else(|| {
            Derivation::new(Arc::clone(&self.grammar), ParamString::new(), options(seed))
        });
        // Restart without giving up the string's buffers: take them out, restart from
        // the empty string (a copy that allocates nothing), write the axiom back in.
        let mut start = std::mem::take(d.string_mut());
        d.restart_seeded(&ParamString::new(), seed);
        polis_lsystem::ModuleString::clear(&mut start);
        start.push(self.lot, axiom).map_err(&error)?;
        *d.string_mut() = start;
        let out = f(&mut d);
        DERIVATIONS.with(|k| {
            if let Ok(mut k) = k.try_borrow_mut() {
                if k.len() >= KEPT_DERIVATIONS {
                    k.remove(0);
                }
                k.push(d);
            }
        });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The strings of a fresh derivation with `seed`, step by step.
    fn fresh(g: &BuildingGrammar, seed: u64, axiom: &[f64], steps: usize) -> Vec<ParamString> {
        let mut start = ParamString::new();
        start.push(g.lot, axiom).unwrap();
        let mut d = Derivation::new(g.grammar(), start, options(seed));
        let mut out = vec![d.string().clone()];
        for _ in 0..steps {
            d.step().unwrap();
            out.push(d.string().clone());
        }
        out
    }

    #[test]
    fn kept_derivations_derive_what_fresh_ones_do() {
        // Interleaved kinds and seeds, so every kept derivation is restarted many times
        // after strings of other lengths; stochastic grammars show any generator drift.
        let grammars: Vec<BuildingGrammar> = BuildingKind::ALL
            .iter()
            .map(|&k| BuildingGrammar::default_for(k).unwrap())
            .collect();
        for round in 0..3u64 {
            for (gi, g) in grammars.iter().enumerate() {
                for seed in 0..20u64 {
                    let seed = seed * 7919 + round + gi as u64 * 1_000_003;
                    let axiom = [40.0 + seed as f64 % 90.0, 20.0, 30.0, 12.0];
                    let steps = (seed % 7) as usize;
                    let want = fresh(g, seed, &axiom, steps);
                    let got = g
                        .derive(
                            seed,
                            &axiom,
                            |source| BuildingsError::Derivation {
                                kind: "test".into(),
                                source,
                            },
                            |d| {
                                let mut out = vec![d.string().clone()];
                                for _ in 0..steps {
                                    d.step().unwrap();
                                    out.push(d.string().clone());
                                }
                                Ok(out)
                            },
                        )
                        .unwrap();
                    assert_eq!(got, want, "{} seed {seed}", g.name());
                }
            }
        }
        // Only the grammars met are kept, at most `KEPT_DERIVATIONS`.
        DERIVATIONS.with(|k| assert!(k.borrow().len() <= KEPT_DERIVATIONS));
    }
}
