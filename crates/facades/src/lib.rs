//! polis-facades: layered-grid procedural facades (Parish & Müller §4.3) rendered to textures or window geometry.
//!
//! **Status: not yet implemented.** This crate is a placeholder in the workspace; the
//! issue tracker names what it will own. Nothing here pretends to work yet.

pub use polis_geom as geom;
