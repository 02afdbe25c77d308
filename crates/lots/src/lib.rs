//! # polis-lots
//!
//! From a city cell to building lots: the straight skeleton (weighted, with split events),
//! insets, blocks with footpaths, and lot subdivision with street access.
//!
//! | module | what |
//! |---|---|
//! | [`skeleton`] | [`StraightSkeleton`]: nodes with times, arcs, and the face each input edge sweeps |
//! | [`inset`](mod@inset) | [`inset`], [`inset_weighted`], [`inset_shapes`]: the wavefront at a time |
//!
//! ## Example
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
//! ## References
//!
//! Felkel & Obdržálek 1998; Aichholzer et al. 1995; Eppstein & Erickson 1999; Kelly 2008
//! §4.4; Parish & Müller 2001 §4.1.

pub use polis_geom as geom;

pub mod block;
mod error;
pub mod inset;
pub mod polygon_split;
pub mod skeleton;
pub mod subdivision;

pub use block::{Block, BlockParams, Cell, Footpath, TexturedRing, blocks};
pub use error::LotsError;
pub use inset::{Inset, InsetRing, InsetShape, inset, inset_shapes, inset_weighted};
pub use polygon_split::{Region, TaggedRing, split_by_line};
pub use skeleton::{EdgeRef, SkeletonArc, SkeletonNode, StraightSkeleton};
pub use subdivision::{
    DiscardReason, Discarded, Lot, LotParams, LotStrategy, Subdivider, Subdivision, subdivide,
    subdivide_block,
};
