//! # polis
//!
//! Procedural city generation after Parish & Müller (*Procedural Modeling of Cities*,
//! SIGGRAPH 2001) and Kelly (*Citygen*, 2008): road networks, city cells, blocks, lots,
//! buildings with facades, exported to glTF, OBJ, SVG and GeoJSON.
//!
//! This facade re-exports the stage crates. The one-call pipeline (`CityConfig`,
//! `Pipeline`, `generate`) is not written yet; until then use the stage crates directly.

pub use polis_buildings as buildings;
pub use polis_cells as cells;
pub use polis_export as export;
pub use polis_facades as facades;
pub use polis_geom as geom;
pub use polis_lots as lots;
pub use polis_lsystem as lsystem;
pub use polis_roads as roads;

// Compile the README's code blocks as doctests so the embedding example stays true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
