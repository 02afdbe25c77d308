//! polis-cells: the minimum cycle basis of a planar road graph (Eberly), giving city cells with holes and filaments.
//!
//! **Status: not yet implemented.** This crate is a placeholder in the workspace; the
//! issue tracker names what it will own. Nothing here pretends to work yet.

pub use polis_geom as geom;
