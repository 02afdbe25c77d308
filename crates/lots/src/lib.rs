//! # polis-lots
//!
//! From a city cell to building lots: the straight skeleton (weighted, with split events,
//! holes), exact insets, blocks with footpaths, and lot subdivision with street access.
//!
//! ```text
//! Cell (boundary, holes, road width per edge)
//!   │  weighted inset by half of each road width      (straight skeleton wavefront)
//!   ▼
//! Block ── footpath strip (inset by the footpath width, lengths for texture coordinates)
//!   │  parcels: the land inside the footpath, every edge facing a street
//!   ▼
//! Lots (Kelly 2008 or Parish & Müller 2001), street edges tracked through every split
//! ```
//!
//! | module | what |
//! |---|---|
//! | [`skeleton`] | [`StraightSkeleton`]: nodes with times, arcs, the face each input edge sweeps |
//! | [`inset`](mod@inset) | [`inset`](fn@inset), [`inset_weighted`], [`inset_shapes`], [`Inset`]: the wavefront at a time |
//! | [`block`] | [`Cell`] → [`Block`]s with [`Footpath`]s and parcels ([`blocks`]) |
//! | [`subdivision`] | [`subdivide`], [`subdivide_block`], [`Subdivider`]: [`Lot`]s ([`LotParams`]) |
//! | [`polygon_split`] | [`split_by_line`]: a region cut by a line into all its pieces |
//! | [`slits`] | [`with_filaments`]: roads inside a cell on no cycle cut into its boundary, so lots face them |
//!
//! ## Example
//!
//! ```
//! use polis_geom::{DVec2, Polygon};
//! use polis_lots::{BlockParams, Cell, LotParams, blocks, subdivide_block};
//! use rand::SeedableRng;
//!
//! // A 100 m square cell with 10 m roads all round.
//! let cell = Cell {
//!     id: 1,
//!     polygon: Polygon::rect(DVec2::ZERO, DVec2::new(100.0, 100.0)).into(),
//!     road_widths: vec![10.0; 4],
//! };
//! let block = &blocks(&cell, &BlockParams::default())?[0];
//! assert!((block.polygon.area() - 90.0 * 90.0).abs() < 1e-9);
//! let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(block.id());
//! let lots = subdivide_block(block, &LotParams::default(), &mut rng)?;
//! assert!(!lots.lots.is_empty());
//! assert!(lots.lots.iter().all(|lot| !lot.street_edges.is_empty()));
//! # Ok::<(), polis_lots::LotsError>(())
//! ```
//!
//! The skeleton on its own:
//!
//! ```
//! use polis_geom::{DVec2, Polygon};
//! use polis_lots::StraightSkeleton;
//!
//! let square = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 10.0));
//! let sk = StraightSkeleton::new(&square.into())?;
//! // The four corners meet at the centre at time 5.
//! assert!((sk.max_time() - 5.0).abs() < 1e-12);
//! assert_eq!(sk.faces().len(), 4);
//! # Ok::<(), polis_lots::LotsError>(())
//! ```
//!
//! ## Guarantees
//!
//! * Input is validated ([`polis_geom::PolygonWithHoles::validate`], orientation, one
//!   positive finite value per edge); bad input is a [`LotsError`], never a panic.
//! * Skeleton nodes lie at distance `time · weight` from the lines of the edges whose faces
//!   they bound; the faces tile the polygon. Insets are simple, inside the input, at the
//!   exact offset, shrinking with the distance. Split events are never skipped.
//! * Lots and discarded pieces partition the subdivided region; kept lots face a street.
//! * Deterministic: no hash-map order or time reaches the output; randomness only from the
//!   generator the caller passes.
//!
//! ## Numeric policy
//!
//! Every side, turn and angular-order decision uses `polis_geom`'s exact predicates.
//! Wavefront points closer than `1e-9` of the polygon's size at the same time are one
//! point; edges within a sine of `1e-8` of parallel are parallel (see
//! [`skeleton`]'s limitations).
//!
//! ## Limitations
//!
//! * Split candidates of a reflex vertex are the edge lines it reaches, found through an
//!   index of the lines by direction and offset (from 256 edges on) that visits only the
//!   lines that can come first; the worst case is still O(n) per reflex vertex (the
//!   Felkel–Obdržálek bound, O(n·r) in all), met by vertices that cross a region where
//!   many lines pass (see the polis repository's `BENCHMARKS.md` for the growth on stars and combs).
//! * Consecutive parallel edges with different weights meet in a perpendicular step (a
//!   virtual edge of weight 0), the convention for this case, which has no bisector. An arc
//!   along a step lies on the offset line of one of the two input edges it names, not both
//!   ([`SkeletonArc::step`]). Unweighted input has no steps.
//!
//! ## References
//!
//! Aichholzer, Aurenhammer, Alberts, Gärtner, *A Novel Type of Skeleton for Polygons*
//! (1995); Felkel, Obdržálek, *Straight Skeleton Implementation* (1998); Eppstein,
//! Erickson, *Raising Roofs, Crashing Cycles, and Playing Pool* (1999); Kelly, *An
//! Interactive System for Procedural City Generation* (2008) §4.4.1–4.4.3; Parish, Müller,
//! *Procedural Modeling of Cities* (2001) §4.1.

pub use polis_geom as geom;
/// The random-number crates of this crate's public signatures (`Rng` bounds, `Pcg64Mcg`),
/// re-exported so callers never match their versions by hand.
pub use rand;
#[doc(no_inline)]
pub use rand_pcg;

pub mod block;
mod error;
pub mod inset;
pub mod polygon_split;
pub mod skeleton;
pub mod slits;
pub mod subdivision;

pub use block::{Block, BlockParams, Cell, Footpath, TexturedRing, blocks};
pub use error::LotsError;
pub use inset::{Inset, InsetRing, InsetShape, inset, inset_shapes, inset_weighted};
pub use polygon_split::{Region, TaggedRing, split_by_line};
pub use skeleton::{EdgeRef, SkeletonArc, SkeletonNode, StraightSkeleton};
pub use slits::{FilamentRoad, SLIT_HALF_M, with_filaments};
pub use subdivision::{
    DiscardReason, Discarded, Lot, LotParams, LotStrategy, SplitLine, Subdivider, Subdivision,
    subdivide, subdivide_block,
};
