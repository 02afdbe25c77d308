//! polis-roads: road networks grown by Parish & Müller's extended open L-system (global goals, local constraints, road patterns).
//!
//! **Status: not yet implemented.** This crate is a placeholder in the workspace; the
//! issue tracker names what it will own. Nothing here pretends to work yet.

pub use polis_geom as geom;
