//! polis-buildings: buildings from stochastic parametric L-systems per building type, with footprints, roofs and levels of detail.
//!
//! **Status: not yet implemented.** This crate is a placeholder in the workspace; the
//! issue tracker names what it will own. Nothing here pretends to work yet.

pub use polis_geom as geom;
