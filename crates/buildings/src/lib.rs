//! polis-buildings: buildings from stochastic parametric L-systems per building type,
//! with footprints, roofs and levels of detail (Parish & Müller 2001 §4.2; Kelly 2008
//! §4.4.3).
//!
//! ```text
//! Lot ──footprint (Kelly: downtown / suburban + rectangle / industrial)──▶ Plan
//!     ──height (max-height map, uniform ± deviance | normal | log-normal)──▶ axiom Lot(h,w,d,n)
//!     ──derivation step k (text grammar per kind)──▶ string_k ──shape interpreter──▶ Building (LOD k)
//! ```
//!
//! ## Key types
//! * [`BuildingGenerator`]: the reusable worker (grammars, templates); [`generate()`] is the
//!   one-call form over many lots.
//! * [`BuildingGrammar`]: a building rule set in the text grammar of `polis_lsystem`
//!   ([`grammar`] lists the shape modules); defaults ship for every [`BuildingKind`].
//! * [`Building`]: closed [`Part`] meshes and [`FacadeFace`]s for the facades stage.
//! * [`BuildingParams`]: the stage's options.
//! * [`footprint::largest_rectangle`]: the largest rectangle along the street inside a
//!   (possibly concave) region, the house footprint; [`footprint::fit_rectangle`] is
//!   Kelly's centre-and-ray fit.
//!
//! ## Example
//! ```
//! use polis_buildings::{BuildingGenerator, BuildingKind, BuildingParams};
//! use polis_geom::{DVec2, Polygon};
//! use polis_lots::Lot;
//!
//! let polygon = Polygon::rect(DVec2::ZERO, DVec2::new(20.0, 30.0));
//! let lot = Lot { area: polygon.area(), polygon, street_edges: vec![0], block_id: 0 };
//! let g = BuildingGenerator::new(BuildingParams::default())?;
//! let house = g.build(&lot, 7, BuildingKind::House, 50.0, 6)?.expect("a house fits");
//! for part in &house.parts {
//!     part.mesh.check_closed()?;
//!     assert!(part.mesh.signed_volume() > 0.0);
//! }
//! assert!(house.height <= 50.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Guarantees
//! * Every part is a closed, consistently wound 2-manifold with outward normals, no
//!   degenerate triangle and texture coordinates in metres (checked in tests over random
//!   convex and concave lots).
//! * The parts of a building of the shipped grammars merge into one closed 2-manifold
//!   with their total volume ([`Building::merged_solid`], [`merge`]; checked in the same
//!   tests); any grammar's parts merge or come back unmerged with the reason, never a
//!   panic (fuzzed).
//! * Every footprint lies inside its lot; nothing rises above the building's height,
//!   which never exceeds the maximum height given.
//! * LOD `k` is the string after `k` derivation steps, drawn; the axiom (LOD 0) is the
//!   bounding volume, and the default grammars only refine inside it.
//! * Deterministic per (seed, lot id), on any thread and in any order.
//! * Any grammar text gives a typed error or buildings with these guarantees, never a
//!   panic (fuzzed by property tests in `tests/grammar_fuzz.rs`).
//! * Every vector a returned [`Building`] holds (parts, facades, each mesh's vertices and
//!   indices, the footprint) is exactly sized: no spare capacity for a city to keep.
//!
//! ## Memory
//! [`BuildingGenerator::build`] allocates little beyond what the returned building
//! keeps: the derivation, the shape interpreter, the triangulations, the footprint
//! insets and the house rectangle work in per-thread buffers that are reused from one
//! building to the next. Each thread that builds keeps those buffers (sized by the
//! largest building it has built: a few kilobytes for the default grammars) and one
//! derivation per grammar it met (at most 8, each holding its grammar alive) until it
//! exits. The lot's validation and the inset engine of `polis_lots` still
//! allocate per building.
//!
//! ## Limitations
//! * One building per lot; the footprint of a suburban lot whose inset splits keeps the
//!   largest piece.
//! * The house rectangle is exact in height for every pair of sides tried and exact for
//!   orthogonal regions; otherwise its area is within `2·δ·H` of the optimum (`δ` the
//!   region's extent along the street / 16, `H` its depth), usually much closer.
//! * A template that does not fit a footprint falls back (gable → hip → flat slab) and
//!   is counted in [`Building::fallbacks`].
//! * A mansard's break line keeps 1 mm clear of skeleton events (it moves 2 mm past an
//!   event it would hit), so its top rings are never pinched.
//!
//! ## References
//! Y. Parish, P. Müller, *Procedural Modeling of Cities*, SIGGRAPH 2001, §4.2;
//! G. Kelly, *An Interactive System for Procedural City Generation*, 2008, §4.4.3, §7.4.

pub use polis_geom as geom;
/// The random-number crates of this crate's public signatures (`Rng` bounds, `Pcg64Mcg`),
/// re-exported so callers never match their versions by hand.
pub use rand;
#[doc(no_inline)]
pub use rand_pcg;

pub mod building;
mod error;
pub mod footprint;
pub mod generate;
pub mod grammar;
pub mod merge;
pub mod params;
mod roofs;
mod solid;
pub mod template;

pub use building::{Building, FacadeFace, FacadeRole, Part, PartRole};
pub use error::BuildingsError;
pub use generate::{
    BuildingGenerator, MIN_BUILDING_HEIGHT, Plan, ZoneRule, generate, kind_from_zoning, mix_seed,
};
pub use generate::{LOT_RESOLUTION_M, resolved_lot};
pub use grammar::{BuildingGrammar, SHAPE_MODULES, default_text};
pub use merge::{MergedSolid, merge_parts};
pub use params::{
    BuildingKind, BuildingParams, FootprintParams, FootprintStrategy, HeightDistribution,
};
pub use template::Template;
