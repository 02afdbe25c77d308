//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong while building or rendering a facade.
///
/// Messages say what was wrong and what to do about it.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FacadesError {
    /// A length, size or resolution was NaN, infinite, negative or out of range.
    #[error("{what} must be a finite number in {range}, got {value}; fix the input")]
    InvalidNumber {
        /// Which quantity.
        what: &'static str,
        /// The value received.
        value: f64,
        /// The accepted range, in words.
        range: &'static str,
    },
    /// A facade axis is shorter than the smallest length its style can fill.
    #[error(
        "an axis of {length} m is shorter than the style minimum of {minimum} m; \
         use a longer face or a style with smaller or more flexible segments"
    )]
    TooShort {
        /// The requested length, metres.
        length: f64,
        /// The smallest length the style accepts, metres.
        minimum: f64,
    },
    /// An axis or facade would need more intervals than the crate allows.
    #[error("{count} intervals needed, more than the limit of {limit}; use larger modules")]
    TooManyIntervals {
        /// Intervals the request would create.
        count: usize,
        /// The limit ([`crate::MAX_INTERVALS`]).
        limit: usize,
    },
    /// A style (or a hand-built layer, interval group or image) is malformed.
    #[error("invalid style `{style}`: {reason}")]
    InvalidStyle {
        /// Name of the style, layer or axis at fault.
        style: String,
        /// What is wrong and how to fix it.
        reason: String,
    },
    /// An influence or selection names a layer that does not exist.
    #[error("no layer named `{name}` in this stack; influences must name layers of the same stack")]
    UnknownLayer {
        /// The missing name.
        name: String,
    },
    /// A texture would exceed [`crate::MAX_TEXTURE_TEXELS`].
    #[error(
        "a {width}×{height} texture exceeds the limit of {limit} texels; \
         lower pixels_per_metre or use the shared tile set"
    )]
    TextureTooLarge {
        /// Width in texels.
        width: u64,
        /// Height in texels.
        height: u64,
        /// The limit.
        limit: u64,
    },
    /// PNG encoding or decoding failed.
    #[error("PNG error: {0}")]
    Png(String),
}

/// Shorthand for results of this crate.
pub type Result<T, E = FacadeError> = std::result::Result<T, E>;

/// Checks that `value` is finite and within `[lo, hi]`.
pub(crate) fn check_range(
    what: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    range: &'static str,
) -> Result<f64> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(FacadeError::InvalidNumber { what, value, range })
    }
}

/// The former name of [`FacadesError`], kept so existing code compiles: every polis crate
/// names its error `<Crate>Error`.
pub type FacadeError = FacadesError;
