//! [`Error`]: everything the pipeline can report, one variant per source.

use std::path::PathBuf;

/// The boxed error a user-written stage may return.
pub type BoxError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// An error of the city pipeline: bad configuration, a failed stage, or I/O.
///
/// Degenerate single items (a cell whose blocks cannot be built, a lot too small for a
/// building) are not errors: they are skipped and counted in
/// [`SkipReport`](crate::SkipReport).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A configuration value is out of range or inconsistent.
    #[error("invalid configuration: {field}: {reason}")]
    Config {
        /// The offending field, as a path (`roads.max_segments`).
        field: String,
        /// What is wrong and what to do.
        reason: String,
    },
    /// A configuration file could not be parsed.
    #[error("cannot parse the configuration {source_name}: {message}")]
    Parse {
        /// The file or preset name.
        source_name: String,
        /// The parser's message (with line and column).
        message: String,
    },
    /// No preset of that name is built in.
    #[error("no preset named {name:?}; the built-in presets are: {known}")]
    UnknownPreset {
        /// The name asked for.
        name: String,
        /// The names that exist, comma-separated.
        known: String,
    },
    /// Reading or writing a file failed.
    #[error("I/O error on {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A geometry-kernel error (an invalid map, a bad scene).
    #[error(transparent)]
    Geom(#[from] polis_geom::GeomError),
    /// The road generator failed.
    #[error("roads: {0}")]
    Roads(#[from] polis_roads::RoadError),
    /// Cell extraction failed (the road graph is not planar, …).
    #[error("cells: {0}")]
    Cells(#[from] polis_cells::Error),
    /// Block or lot construction failed outside a skippable cell.
    #[error("lots: {0}")]
    Lots(#[from] polis_lots::LotsError),
    /// The building stage failed (grammar, parameters).
    #[error("buildings: {0}")]
    Buildings(#[from] polis_buildings::BuildingsError),
    /// The facade stage failed (style, rasterisation).
    #[error("facades: {0}")]
    Facades(#[from] polis_facades::FacadeError),
    /// Writing an output failed.
    #[error("export: {0}")]
    Export(#[from] polis_export::ExportError),
    /// The statistics report failed (unknown reference city, unmeasurable layers).
    #[error("stats: {0}")]
    Stats(#[from] polis_stats::StatsError),
    /// A user-supplied stage failed.
    #[error("stage {stage}: {source}")]
    Stage {
        /// The stage that failed.
        stage: crate::Stage,
        /// Its error.
        #[source]
        source: BoxError,
    },
    /// An edit names a node, road, cell or lot that does not exist
    /// ([`CityEditor`](crate::editor::CityEditor)); nothing was changed.
    #[error("no {kind} with id {id}: pick one of the city's current {kind}s")]
    UnknownId {
        /// What kind of item (`node`, `road`, `cell`, `lot`).
        kind: &'static str,
        /// The id asked for.
        id: u64,
    },
    /// An edit's value is out of range, not finite or outside the map; nothing was
    /// changed.
    #[error("invalid edit: {field}: {reason}")]
    InvalidEdit {
        /// The offending field of the edit.
        field: String,
        /// What is wrong and what to do.
        reason: String,
    },
    /// Undo or redo with nothing to undo or redo; nothing was changed.
    #[error("nothing to {0}")]
    NothingTo(&'static str),
    /// The thread pool for parallel work could not be built.
    #[error("cannot start {threads} worker threads: {message}")]
    Threads {
        /// Threads asked for.
        threads: usize,
        /// Why it failed.
        message: String,
    },
}

impl Error {
    /// A [`Error::Config`] for `field`.
    pub fn config(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Config {
            field: field.into(),
            reason: reason.into(),
        }
    }
}

/// Result alias of the facade.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// [`Error`] under the `<Crate>Error` name every polis crate's error follows
/// (`polis_roads::RoadsError`, `polis_cells::CellsError`, …).
pub type PolisError = Error;
