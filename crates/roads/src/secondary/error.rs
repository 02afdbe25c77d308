//! The error type of secondary road growth.

use polis_geom::GeomError;

/// Everything that can go wrong while growing one cell's secondary roads.
///
/// [`SecondaryError::is_skip`] tells a pipeline which errors concern one cell only (count
/// the cell as skipped and go on) and which are configuration errors (stop).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SecondaryError {
    /// A [`SecondaryParams`](super::SecondaryParams) field is out of its documented range.
    #[error("invalid secondary road parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The field's name.
        name: &'static str,
        /// What was wrong and what to use instead.
        reason: String,
    },
    /// The cell's boundary is not a valid polygon with holes (self-crossing, touching
    /// rings, too few vertices, non-finite coordinates).
    #[error("cell {cell}: invalid boundary: {source}")]
    InvalidCell {
        /// The cell's stable id.
        cell: u64,
        /// What the polygon check found.
        source: GeomError,
    },
    /// The cell has no boundary side long enough to start one segment from (every side
    /// is shorter than twice the snap size, or the cell is narrower than one segment).
    #[error(
        "cell {cell} is too small for secondary roads: {reason}; use a smaller segment or \
         snap size for small cells"
    )]
    CellTooSmall {
        /// The cell's stable id.
        cell: u64,
        /// Which measure was too small.
        reason: String,
    },
    /// A neighbourhood preset's data did not parse (a bug in the shipped JSON, or a
    /// user's preset file).
    #[error("neighbourhood preset `{name}` does not parse: {message}")]
    Preset {
        /// The preset's name.
        name: String,
        /// The parser's message.
        message: String,
    },
    /// The planar graph refused an operation (an internal failure).
    #[error("geometry error while growing secondary roads: {0}")]
    Geometry(#[from] GeomError),
}

impl SecondaryError {
    /// Whether the error concerns one cell only, so that a city pipeline should skip the
    /// cell (and count it) rather than stop: [`InvalidCell`](Self::InvalidCell) and
    /// [`CellTooSmall`](Self::CellTooSmall).
    pub fn is_skip(&self) -> bool {
        matches!(
            self,
            SecondaryError::InvalidCell { .. } | SecondaryError::CellTooSmall { .. }
        )
    }
}

impl From<SecondaryError> for crate::RoadError {
    fn from(e: SecondaryError) -> Self {
        match e {
            SecondaryError::InvalidParameter { name, reason } => {
                crate::RoadError::InvalidParameter { name, reason }
            }
            SecondaryError::Geometry(g) => crate::RoadError::Geometry(g),
            other => crate::RoadError::InvalidParameter {
                name: "secondary",
                reason: other.to_string(),
            },
        }
    }
}
