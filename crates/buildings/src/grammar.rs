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

use polis_lsystem::{Grammar, LsystemError};

use crate::BuildingsError;
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
    grammar: Grammar,
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
            grammar,
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

    pub(crate) fn lot_symbol(&self) -> u32 {
        self.lot
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
