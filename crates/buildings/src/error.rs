//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong while building.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum BuildingsError {
    /// A building grammar text did not parse or compile.
    #[error("building grammar `{name}`: {source}; fix the grammar text at that line")]
    Grammar {
        /// The grammar's name.
        name: String,
        /// The L-system error (line, column and text of the problem).
        source: polis_lsystem::LsystemError,
    },
    /// A building grammar lacks something the interpreter needs.
    #[error("building grammar `{name}`: {reason}")]
    GrammarContent {
        /// The grammar's name.
        name: String,
        /// What is missing.
        reason: String,
    },
    /// Deriving a building string failed (string too long, too many steps …).
    #[error(
        "deriving building `{kind}` failed: {source}; lower the LOD or bound the grammar's growth"
    )]
    Derivation {
        /// The building kind's name.
        kind: String,
        /// The L-system error.
        source: polis_lsystem::LsystemError,
    },
    /// The lot cannot carry a building (invalid polygon, too small after the setbacks).
    #[error("lot {lot_id}: {reason}")]
    Lot {
        /// The lot's id.
        lot_id: u64,
        /// What was wrong.
        reason: String,
    },
    /// A parameter is out of range.
    #[error("parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// What was wrong and what is allowed.
        reason: String,
    },
    /// A user template (OBJ) could not be loaded.
    #[error("template `{name}`: {reason}")]
    Template {
        /// The template's name.
        name: String,
        /// What was wrong.
        reason: String,
    },
    /// A geometry operation failed.
    #[error(transparent)]
    Geom(#[from] polis_geom::GeomError),
    /// A skeleton or inset operation failed.
    #[error(transparent)]
    Lots(#[from] polis_lots::LotsError),
}
