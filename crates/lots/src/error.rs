//! The error type of `polis-lots`.

use polis_geom::{GeomError, Ring};

/// What went wrong in a `polis-lots` operation.
///
/// Every message says what was wrong and what to do about it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LotsError {
    /// The input polygon is not valid (self-intersecting, zero area, NaN, repeated vertex …).
    #[error(
        "invalid input polygon: {0}; fix the geometry (see polis_geom::PolygonWithHoles::validate)"
    )]
    InvalidPolygon(#[from] GeomError),
    /// A ring runs the wrong way round.
    #[error(
        "the {ring} runs the wrong way round; outer rings must be counter-clockwise and holes clockwise (call PolygonWithHoles::normalize first)"
    )]
    WrongOrientation {
        /// The ring that is reversed.
        ring: Ring,
    },
    /// The number of per-edge values (weights, road widths, street flags) does not match.
    #[error("{what}: expected {expected} values (one per edge of every ring), got {got}")]
    EdgeCountMismatch {
        /// What the values are.
        what: &'static str,
        /// How many edges the polygon has.
        expected: usize,
        /// How many values were given.
        got: usize,
    },
    /// A per-edge weight or width is not a finite positive number.
    #[error("{what} of edge {edge} is {value}; it must be finite and greater than zero")]
    InvalidEdgeValue {
        /// What the value is.
        what: &'static str,
        /// The edge it belongs to.
        edge: usize,
        /// The offending value.
        value: f64,
    },
    /// A scalar parameter is out of range.
    #[error("invalid parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// Why it is invalid.
        reason: String,
    },
    /// An input vertex where the ring turns back on itself: its two edges are antiparallel
    /// to within a sine of `1e-8` (an interior angle within about `1e-6`° of 0° or 360°,
    /// a needle or a crack one rounding error wide). The wavefront vertex there would move
    /// more than 10⁸ times faster than its edges, which `f64` cannot follow, so the
    /// skeleton and every inset refuse such a polygon alike.
    #[error(
        "vertex {vertex} of the {ring} is a needle: its edges turn back on each other (sine of the angle between them {sine:e}); remove the spike or make it at least 1e-8 radians wide"
    )]
    NeedleVertex {
        /// The ring.
        ring: Ring,
        /// The vertex's index in the ring.
        vertex: usize,
        /// The sine of the angle between the two edge directions.
        sine: f64,
    },
    /// The wavefront simulation could not finish (a numerical breakdown on near-degenerate
    /// input). Nothing is returned rather than a wrong skeleton.
    #[error(
        "the straight skeleton could not be completed ({reason}); the input is numerically near-degenerate: snap nearly coincident vertices or nearly collinear edges and retry"
    )]
    SkeletonFailed {
        /// What broke.
        reason: &'static str,
    },
}

/// Checks that `value` is finite and positive (a weight or a width).
pub(crate) fn check_positive(what: &'static str, edge: usize, value: f64) -> Result<(), LotsError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(LotsError::InvalidEdgeValue { what, edge, value })
    }
}
