//! The error type of `polis-lsystem`.

/// Everything that can go wrong while parsing a grammar, building productions or deriving.
///
/// Every variant says what was wrong and what to do about it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LsystemError {
    /// The string grew beyond [`DeriveOptions::max_len`](crate::DeriveOptions::max_len).
    #[error(
        "derivation step {step} produced more than {max} modules (reached {len}); \
         derive fewer steps or raise DeriveOptions::max_len"
    )]
    StringTooLong {
        /// The 1-based step that overflowed.
        step: usize,
        /// Length reached when the guard fired.
        len: usize,
        /// The limit.
        max: usize,
    },
    /// More derivation steps were requested than [`DeriveOptions::max_steps`](crate::DeriveOptions::max_steps) allows.
    #[error(
        "step {requested} requested but DeriveOptions::max_steps is {max}; \
         raise the limit if the growth is intended"
    )]
    TooManySteps {
        /// The step number that was requested.
        requested: usize,
        /// The limit.
        max: usize,
    },
    /// The parameter arena of a [`ParamString`](crate::ParamString) overflowed its 32-bit offsets.
    #[error(
        "the string holds more than {max} numeric parameters; derive fewer steps or use fewer parameters"
    )]
    TooManyParameters {
        /// The limit.
        max: usize,
    },
    /// Decomposition or interpretation rules recursed deeper than the limit.
    #[error(
        "{what} rules recursed deeper than {max} levels; a rule probably rewrites a module into itself \
         (raise DeriveOptions::max_depth if the depth is intended)"
    )]
    DepthExceeded {
        /// `"decomposition"` or `"interpretation"`.
        what: &'static str,
        /// The limit.
        max: usize,
    },
    /// A grammar text could not be parsed or compiled.
    #[error("line {line}, column {column}: {message} (at `{snippet}`)")]
    Parse {
        /// 1-based line.
        line: usize,
        /// 1-based column, counted in characters.
        column: usize,
        /// What is wrong.
        message: String,
        /// The text at the error position (up to the end of the line, shortened).
        snippet: String,
    },
    /// A production or option given through the typed API is invalid.
    #[error("invalid {what}: {reason}")]
    Invalid {
        /// What was invalid (e.g. `"probability"`).
        what: &'static str,
        /// Why, and what to do.
        reason: String,
    },
}

/// `Result` with [`LsystemError`].
pub type Result<T> = core::result::Result<T, LsystemError>;
