//! The crate's error type.

use polis_geom::GeomError;
use polis_lsystem::LsystemError;

/// Everything that can go wrong while growing a road network.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RoadsError {
    /// A [`RoadParams`](crate::RoadParams) field is out of its documented range.
    #[error("invalid road parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The field's name.
        name: &'static str,
        /// What was wrong and what to use instead.
        reason: String,
    },
    /// No legal starting point: the whole map is water, park, too steep or unpopulated.
    #[error(
        "no legal start for the road network inside the map: give `start` explicitly or \
         change the water/park maps"
    )]
    NoLegalStart,
    /// The planar graph or the geometry kernel refused an operation (a bug or a corrupt
    /// graph handed in by the caller).
    #[error("geometry error while growing roads: {0}")]
    Geometry(#[from] GeomError),
    /// The L-system engine failed (a growth guard fired).
    #[error("L-system derivation failed: {0}; raise `max_steps` or lower `max_segments`")]
    Lsystem(#[from] LsystemError),
}

/// `Result` with [`RoadError`].
pub type Result<T> = core::result::Result<T, RoadError>;

/// The former name of [`RoadsError`], kept so existing code compiles: every polis crate
/// names its error `<Crate>Error`.
pub type RoadError = RoadsError;
