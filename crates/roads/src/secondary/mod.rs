//! Kelly's secondary road growth inside city cells (Citygen, 2008, §4.3).
//!
//! The primary network encloses *city cells* (polis-cells finds them); each cell grows
//! its own secondary roads from its boundary inwards with a small parameter set
//! ([`SecondaryParams`]; presets in [`Neighbourhood`]). The pieces:
//!
//! | module | what |
//! |---|---|
//! | [`params`] | the control parameters and their deviances (§4.3.2, §5.5.1, §6.3) |
//! | [`presets`] | Manhattan, Suburbia, Industrial (Fig. 76), Raster, Organic (Fig. 44) as JSON |
//! | [`cell`] | the input: [`SecondaryCell`] (region, filaments, stable id) and [`CellMaps`] |
//! | [`growth`] | the growth of Fig. 42: [`SecondaryGrowth`], [`grow_cell`] |
//! | [`bend`] | streets bowed between their ends ([`SecondaryParams::bow`], ours) |
//! | [`snap`] | the snap algorithm of §4.3.3 (extended box, three ordered tests, `r`/`s` reuse) |
//! | [`pattern`] | [`CellPattern`]: where other per-cell road generators plug in |
//! | [`stats`] | junction statistics ([`StreetStats`]) |
//!
//! ```
//! use polis_roads::geom::{DVec2, Polygon};
//! use polis_roads::secondary::{CellMaps, Neighbourhood, SecondaryCell, StreetStats, grow_cell};
//!
//! let square = Polygon::new(vec![
//!     DVec2::new(0.0, 0.0), DVec2::new(600.0, 0.0),
//!     DVec2::new(600.0, 600.0), DVec2::new(0.0, 600.0),
//! ]);
//! let params = Neighbourhood::Manhattan.params()?;
//! let roads = grow_cell(&params, &SecondaryCell::new(7, square), &CellMaps::none(), 1)?;
//! roads.network.check_invariants()?;
//! let stats = StreetStats::of(&roads.network);
//! assert!(stats.four_way_or_boundary_share() > 0.8);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod bend;
pub mod cell;
pub mod error;
mod grid;
pub mod growth;
mod join;
pub mod params;
pub mod pattern;
pub mod presets;
pub mod snap;
pub mod stats;

pub use cell::{CellMaps, SecondaryCell};
pub use error::SecondaryError;
pub use growth::{
    CellGrowthReport, CellTraits, SecondaryGrowth, SecondaryRoads, estimated_work, grow_cell,
};
pub use params::{BuildingHint, Deviated, SecondaryParams};
pub use pattern::CellPattern;
pub use presets::{CITYGEN_UNIT_M, Neighbourhood, NeighbourhoodPreset};
pub use stats::StreetStats;

#[cfg(test)]
mod tests;
