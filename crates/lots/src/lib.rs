//! polis-lots: the straight skeleton (weighted, with split events), block insets with footpaths, and lot subdivision.
//!
//! **Status: not yet implemented.** This crate is a placeholder in the workspace; the
//! issue tracker names what it will own. Nothing here pretends to work yet.

pub use polis_geom as geom;
