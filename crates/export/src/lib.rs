//! polis-export: writers for glTF 2.0 binary, OBJ + MTL, SVG maps and GeoJSON layers.
//!
//! **Status: not yet implemented.** This crate is a placeholder in the workspace; the
//! issue tracker names what it will own. Nothing here pretends to work yet.

pub use polis_geom as geom;
