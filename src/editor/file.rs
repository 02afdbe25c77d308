//! [`EditingFile`]: an editing session as data (base configuration + edit log), saved as
//! JSON and replayed to the identical city.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::edit::Edit;
use super::state::CityEditor;
use crate::CityConfig;
use crate::error::{Error, Result};

/// A saved editing session: the configuration the editor started from and its edits.
/// [`replay`](Self::replay) gives an editor with the identical city, configuration,
/// primary network (ids and counters included) and undo/redo history.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EditingFile {
    /// The starting configuration (Citygen mode, primary network inline).
    pub base: CityConfig,
    /// The edits in effect, in order.
    pub edits: Vec<Edit>,
    /// Undone edits that can be redone, next first. Default: none.
    #[serde(default)]
    pub undone: Vec<Edit>,
}

impl EditingFile {
    /// Replays the session: applies `edits`, then applies and undoes `undone` so they
    /// can be redone.
    ///
    /// # Errors
    /// The first edit that fails (the file does not belong to this base).
    pub fn replay(&self) -> Result<CityEditor> {
        let mut editor = CityEditor::new(self.base.clone())?;
        for e in &self.edits {
            editor.apply(e.clone())?;
        }
        for e in &self.undone {
            editor.apply(e.clone())?;
        }
        for _ in &self.undone {
            editor.undo()?;
        }
        Ok(editor)
    }

    /// The file as pretty JSON.
    ///
    /// # Errors
    /// [`Error::Parse`] if a value cannot be written (a non-finite number).
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self).map_err(|e| Error::Parse {
            source_name: "editing file".into(),
            message: e.to_string(),
        })
    }

    /// Reads a file from JSON text; `source_name` names it in errors.
    ///
    /// # Errors
    /// [`Error::Parse`] with line and column; [`Error::Config`] for a bad base.
    pub fn from_json(text: &str, source_name: &str) -> Result<Self> {
        let file: EditingFile = serde_json::from_str(text).map_err(|e| Error::Parse {
            source_name: source_name.into(),
            message: e.to_string(),
        })?;
        file.base.validate()?;
        Ok(file)
    }

    /// Writes the file.
    ///
    /// # Errors
    /// [`Error::Io`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        std::fs::write(path, self.to_json()?).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads a file.
    ///
    /// # Errors
    /// [`Error::Io`], then as [`from_json`](Self::from_json).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json(&text, &path.display().to_string())
    }
}
