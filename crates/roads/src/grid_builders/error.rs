//! [`GridError`]: everything that can go wrong with grid road builders.

use polis_geom::GeomError;

/// Everything that can go wrong while reading grid-builder rules or growing a cell's
/// grid roads.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GridError {
    /// The rule text is not JSON of the report's shape (syntax, a missing field, an
    /// unknown action name, an unknown field).
    #[error("grid-builder rules are not valid JSON of the report's shape: {0}")]
    Json(#[from] serde_json::Error),
    /// A rule's probability is NaN or outside `[0, 1]`.
    #[error("rule `{action}` in `{group}` has probability {value}; use a number between 0 and 1")]
    InvalidProbability {
        /// The rule group (`movementActionRules`, `branchOutRules`, …).
        group: &'static str,
        /// The rule's action.
        action: &'static str,
        /// The probability given.
        value: f64,
    },
    /// The probabilities of one rule group do not add up to 1.
    #[error(
        "the probabilities of `{group}` add up to {sum}; they must add up to 1 (within {tolerance})"
    )]
    ProbabilitySum {
        /// The rule group.
        group: &'static str,
        /// Their sum.
        sum: f64,
        /// The accepted distance from 1.
        tolerance: f64,
    },
    /// An action is missing from its rule group.
    #[error("rule group `{group}` has no rule for `{action}`; give every action once")]
    MissingAction {
        /// The rule group.
        group: &'static str,
        /// The missing action.
        action: &'static str,
    },
    /// An action appears twice in its rule group.
    #[error("rule group `{group}` has two rules for `{action}`; give every action once")]
    DuplicateAction {
        /// The rule group.
        group: &'static str,
        /// The repeated action.
        action: &'static str,
    },
    /// No rule set of that name in a list of rule sets.
    #[error("no grid-builder rule set named `{name}`; known: {known}")]
    UnknownRuleSet {
        /// The name asked for.
        name: String,
        /// The names available, comma-separated.
        known: String,
    },
    /// A [`GridParams`](super::GridParams) field is out of its documented range.
    #[error("invalid grid-builder parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The field's name.
        name: &'static str,
        /// What was wrong and what to use instead.
        reason: String,
    },
    /// The cell polygon (or a filament) is not valid geometry: non-finite or
    /// out-of-range coordinates, a self-intersecting ring, a hole outside the outer ring.
    #[error("invalid cell for grid road builders: {0}")]
    InvalidCell(GeomError),
    /// The grid over the cell would have more points than
    /// [`GridParams::max_lattice_points`](super::GridParams::max_lattice_points).
    #[error(
        "the grid over this cell would have {points} points (more than the limit {max}); \
         raise `grid_size_m` or `max_lattice_points`"
    )]
    TooManyLatticePoints {
        /// Grid points needed to cover the cell's bounding box.
        points: u64,
        /// The configured limit.
        max: u64,
    },
    /// No road builder could start: the cell is too small or too narrow for one grid
    /// step clear of its boundary, or every start is in water or a park. The pipeline
    /// counts such a cell as skipped.
    #[error(
        "no road builder can start in this cell (too small or narrow for a {grid_size_m} m \
         grid step clear of the boundary, or in water/parks)"
    )]
    NoStart {
        /// The grid step, in metres.
        grid_size_m: f64,
    },
    /// The planar graph refused an operation (a bug; reported, never a panic).
    #[error("geometry error while building the grid road graph: {0}")]
    Geometry(#[from] GeomError),
}

/// `Result` with [`GridError`].
pub type Result<T> = core::result::Result<T, GridError>;
