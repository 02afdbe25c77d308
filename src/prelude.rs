//! The names most programs need, in one `use polis::prelude::*;`: the configuration,
//! the pipeline and its stage traits, the city and its writers, and the 2-D types stages
//! exchange. `polis::Error` and `polis::Result` are left out so they never shadow
//! `std`'s; name them in full.

pub use crate::city::{City, Written};
pub use crate::config::CityConfig;
pub use crate::maps::MapSpec;
pub use crate::output::{Formats, WriteOptions};
pub use crate::pipeline::{Pipeline, generate};
pub use crate::stages::{
    BuildingStage, CellStage, FacadeStage, LotStage, RoadStage, RoadsOutput, Stage, StageContext,
};
pub use polis_geom::{DVec2, Field, Polygon, PolygonWithHoles};
