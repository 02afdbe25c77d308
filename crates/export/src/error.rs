//! The error type of `polis-export`.

use polis_geom::GeomError;

/// What went wrong while exporting.
///
/// Input is checked completely before the first byte is written, so every variant except
/// [`Io`](Self::Io) means that nothing was written. An I/O error can leave a partial file
/// behind: write to a temporary file and rename it if that matters.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The writer or a file sink failed.
    #[error("writing {what} failed: {source}; check the destination (disk space, permissions)")]
    Io {
        /// What was being written (`"glb"`, `"obj"`, a file name, …).
        what: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The scene failed [`Scene::validate`](polis_geom::Scene::validate); nothing was written.
    #[error("the scene is invalid, nothing was written: {0}")]
    InvalidScene(#[from] GeomError),
    /// A map feature is unusable (a non-finite coordinate, a ring with fewer than three
    /// points, a negative width …); nothing was written.
    #[error("the map is invalid, nothing was written: {what}: {reason}")]
    InvalidMap {
        /// Which feature, e.g. `"road 3"`.
        what: String,
        /// What is wrong with it and how to fix it.
        reason: String,
    },
    /// An option is out of its documented range.
    #[error("option {name} is invalid: {reason}")]
    InvalidOption {
        /// The option's field name.
        name: &'static str,
        /// What is wrong with it.
        reason: String,
    },
    /// The output exceeds a limit of the file format (a glb is at most 4 GiB).
    #[error(
        "the {format} output would be {bytes} bytes, over the format's limit of {limit}; split the scene"
    )]
    TooLarge {
        /// The format.
        format: &'static str,
        /// The size the output would have had.
        bytes: u64,
        /// The format's limit in bytes.
        limit: u64,
    },
    /// An RGBA image could not be encoded as PNG.
    #[error("image {image} could not be encoded as PNG: {reason}")]
    Png {
        /// The image index in the scene.
        image: usize,
        /// The encoder's message.
        reason: String,
    },
    /// Serialising JSON failed (only possible through an I/O error of the writer). Only
    /// with the `serde` feature (which the JSON writers, glb and GeoJSON, turn on).
    #[cfg(feature = "serde")]
    #[error("writing JSON for {what} failed: {source}")]
    Json {
        /// What was being serialised.
        what: String,
        /// The underlying error.
        source: serde_json::Error,
    },
}

// With some writers switched off (features) some helpers have no caller.
#[cfg_attr(
    not(all(
        feature = "gltf",
        feature = "obj",
        feature = "svg",
        feature = "geojson"
    )),
    allow(dead_code)
)]
impl ExportError {
    /// An [`Io`](Self::Io) error about `what`.
    pub(crate) fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> ExportError {
        let what = what.into();
        move |source| ExportError::Io { what, source }
    }

    /// A [`Json`](Self::Json) error about `what`; I/O failures inside serde_json are
    /// reported as [`Io`](Self::Io).
    #[cfg(feature = "serde")]
    pub(crate) fn json(what: impl Into<String>) -> impl FnOnce(serde_json::Error) -> ExportError {
        let what = what.into();
        move |source| {
            if source.is_io() {
                let kind = source.io_error_kind().unwrap_or(std::io::ErrorKind::Other);
                ExportError::Io {
                    what,
                    source: std::io::Error::new(kind, source.to_string()),
                }
            } else {
                ExportError::Json { what, source }
            }
        }
    }

    /// An [`InvalidMap`](Self::InvalidMap) error.
    pub(crate) fn map(what: impl Into<String>, reason: impl Into<String>) -> ExportError {
        ExportError::InvalidMap {
            what: what.into(),
            reason: reason.into(),
        }
    }
}
