//! # polis
//!
//! Procedural city generation after Parish & Müller (*Procedural Modeling of Cities*,
//! SIGGRAPH 2001) and Kelly (*Citygen*, 2008): road networks, city cells, blocks, lots,
//! buildings with facades, exported to glTF, OBJ, SVG and GeoJSON.
//!
//! One call makes a whole city:
//!
//! ```no_run
//! let config = polis::CityConfig::preset("manhattan")?;
//! let city = polis::generate(&config)?;
//! println!("{} roads, {} buildings", city.stats.road_segments, city.stats.buildings);
//! city.write_all("out", polis::Formats::ALL)?;
//! # Ok::<(), polis::Error>(())
//! ```
//!
//! ## The pipeline
//!
//! [`Pipeline::generate`] runs the stages in order, each a trait with the stage crate as
//! its default ([`stages`]): maps → roads ([`polis_roads`], the extended L-system) →
//! cells ([`polis_cells`], the minimal cycle basis) → blocks and lots ([`polis_lots`],
//! per cell, in parallel) → buildings ([`polis_buildings`], per lot, in parallel) →
//! facades ([`polis_facades`], shared tile sets, per building in parallel) → the scene.
//! Replace any stage with `Pipeline::default().with_lots(MyLots)` and friends.
//!
//! ## Configuration
//!
//! [`CityConfig`] is plain serde data; the built-in presets (`default`, `manhattan`,
//! `paris`, `san_francisco`, `old_town`, `suburbia`, `citygen`, `milan`) are JSON files
//! in `presets/`, compiled in. [`CityConfig::road_mode`] picks the road stage: one Parish &
//! Müller growth, or Kelly's Citygen ([`citygen`]: primary network, city cells, secondary
//! roads per cell); `suburbia`, `citygen` and `milan` use Citygen. Every map is procedural
//! and seeded unless a grey-scale PNG replaces it ([`MapSpec::png`]).
//!
//! ## Guarantees
//!
//! - **Deterministic**: the same configuration gives the same city and the same output
//!   bytes, whatever [`CityConfig::threads`] says. Every stage and item draws from its
//!   own sub-seed ([`seed::sub_seed`]) of the city seed and a stable id, and parallel
//!   results are gathered in input order.
//! - **No panics on input**: bad configurations are [`Error::Config`] naming the field;
//!   degenerate cells and lots are skipped and listed in [`City::report`].
//!
//! `use polis::prelude::*;` brings the everyday names ([`prelude`]);
//! `examples/custom_stage.rs` plugs a custom road stage into the pipeline.
//!
//! The stage crates are re-exported as modules ([`roads`], [`cells`], …) for direct use.

pub use polis_buildings as buildings;
pub use polis_cells as cells;
pub use polis_export as export;
pub use polis_facades as facades;
pub use polis_geom as geom;
pub use polis_lots as lots;
pub use polis_lsystem as lsystem;
pub use polis_roads as roads;
pub use polis_stats as stats;

mod city;
pub mod citygen;
mod clock;
mod config;
mod debug;
pub mod editor;
mod error;
mod ground;
mod maps;
mod output;
mod pipeline;
pub mod prelude;
mod prune;
mod report;
mod scene;
pub mod seed;
pub mod stages;
mod streets;
mod water;
mod zoning;

pub use city::{
    City, CityLot, CityStats, SkipReport, StageTiming, Written, smooth_mask, trace_mask,
};
pub use citygen::{CitygenConfig, RoadMode};
pub use config::{
    CityConfig, FacadeConfig, FacadeDetail, Foundation, KindStyles, SceneConfig, ZoneBand,
    ZoningConfig,
};
pub use config::{MAX_BUILDING_HEIGHT_M, MAX_ELEVATION_M, MAX_IMAGE_PIXELS, MAX_THREADS};
pub use error::{BoxError, Error, PolisError, Result};
pub use ground::{
    BRIDGE_CLEARANCE_M, BRIDGE_CURVE_M, BRIDGE_DECK_M, BRIDGE_PIER_SPACING_M, PIER_FOOT_M,
};
pub use maps::{CityMaps, MapSpec, MapsConfig, PatternMap, Shape};
pub use output::{Formats, TEXTURE_DIR, UnknownFormat, WriteOptions};
pub use pipeline::{CityChunk, Pipeline, Progress, generate};
pub use report::{reference_city_name, road_statistics, street_graph};
pub use scene::CORRIDOR_CUT_M;
pub use stages::{Skip, Stage};
pub use water::{
    WATER_BANK_M, WATER_BANK_SLOPE, WATER_BANK_WALL_M, WATER_FREEBOARD_M, WATER_LAND_MARGIN_M,
    WATER_MAX_DEPTH_M,
};
pub use zoning::{AreaCap, MAX_ZONE_VALUE, MIXED_ZONE, MixedZone};

// Compile the README's code blocks as doctests so the embedding example stays true.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
