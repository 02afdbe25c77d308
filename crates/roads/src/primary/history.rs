//! Undo and redo through a serde edit log, and [`PrimaryEditor`], which keeps a network,
//! its terrain, the edit options and the log together.

use serde::{Deserialize, Serialize};

use crate::primary::edit::{ChangeSet, Edit, Preview};
use crate::primary::error::PrimaryError;
use crate::primary::network::{Patch, PrimaryNetwork};
use crate::primary::params::EditOptions;
use crate::primary::terrain::Terrain;

/// One committed edit: the edit as proposed, the state it overwrote and the state it
/// wrote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LogEntry {
    /// The edit.
    pub edit: Edit,
    /// The touched items before the commit (id counters included).
    pub before: Patch,
    /// The touched items after it.
    pub after: Patch,
}

/// The edit log: committed edits in order, and how many of them are applied (the rest
/// can be redone). Serde data.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct EditLog {
    /// The entries.
    pub entries: Vec<LogEntry>,
    /// Entries `[0, applied)` are in effect.
    pub applied: usize,
}

impl EditLog {
    /// The edits in effect, in order.
    pub fn applied_edits(&self) -> impl Iterator<Item = &Edit> + '_ {
        self.entries.iter().take(self.applied).map(|e| &e.edit)
    }
}

/// A primary network being edited: propose / commit / undo / redo (Kelly §5.3–5.4).
///
/// Undo writes back exactly the state an edit overwrote, id counters included, so the
/// serialised network after any edits and as many undos is byte-identical to before
/// them; a new commit after an undo drops the redo tail (and may hand out the ids of
/// the undone elements again: they no longer exist anywhere in the network's history
/// from that point on).
#[derive(Debug, Clone)]
pub struct PrimaryEditor {
    network: PrimaryNetwork,
    terrain: Terrain,
    options: EditOptions,
    log: EditLog,
}

impl PrimaryEditor {
    /// An editor of an empty network.
    ///
    /// # Errors
    /// [`PrimaryError::InvalidParameter`] for bad options.
    pub fn new(terrain: Terrain, options: EditOptions) -> Result<Self, PrimaryError> {
        Self::with_network(PrimaryNetwork::new(), terrain, options)
    }

    /// An editor of `network` (with an empty log).
    ///
    /// # Errors
    /// [`PrimaryError::InvalidParameter`] for bad options.
    pub fn with_network(
        network: PrimaryNetwork,
        terrain: Terrain,
        options: EditOptions,
    ) -> Result<Self, PrimaryError> {
        options.validate()?;
        Ok(PrimaryEditor {
            network,
            terrain,
            options,
            log: EditLog::default(),
        })
    }

    /// The network.
    pub fn network(&self) -> &PrimaryNetwork {
        &self.network
    }

    /// The terrain.
    pub fn terrain(&self) -> &Terrain {
        &self.terrain
    }

    /// Replaces the terrain later edits are checked and plotted on (the maps changed);
    /// the network and the log stay as they are (existing roads are not re-plotted).
    pub fn set_terrain(&mut self, terrain: Terrain) {
        self.terrain = terrain;
    }

    /// The edit options.
    pub fn options(&self) -> &EditOptions {
        &self.options
    }

    /// The log.
    pub fn log(&self) -> &EditLog {
        &self.log
    }

    /// Takes the network out.
    pub fn into_network(self) -> PrimaryNetwork {
        self.network
    }

    /// Validity-checks an edit (see [`PrimaryNetwork::propose`]).
    ///
    /// # Errors
    /// A typed refusal.
    pub fn propose(&self, edit: &Edit) -> Result<Preview, PrimaryError> {
        self.network.propose(edit, &self.terrain, &self.options)
    }

    /// Commits a preview and logs it; drops any redo tail.
    ///
    /// # Errors
    /// [`PrimaryError::StalePreview`].
    pub fn commit(&mut self, preview: &Preview) -> Result<ChangeSet, PrimaryError> {
        let changes = self.network.commit(preview)?;
        self.log.entries.truncate(self.log.applied);
        let (before, after) = preview.patches();
        self.log.entries.push(LogEntry {
            edit: preview.edit().clone(),
            before: before.clone(),
            after: after.clone(),
        });
        self.log.applied += 1;
        Ok(changes)
    }

    /// Proposes and commits.
    ///
    /// # Errors
    /// As [`propose`](Self::propose).
    pub fn apply(&mut self, edit: &Edit) -> Result<ChangeSet, PrimaryError> {
        let p = self.propose(edit)?;
        self.commit(&p)
    }

    /// Undoes the last applied edit.
    ///
    /// # Errors
    /// [`PrimaryError::NothingTo`] when nothing is applied.
    pub fn undo(&mut self) -> Result<ChangeSet, PrimaryError> {
        let i = self
            .log
            .applied
            .checked_sub(1)
            .ok_or(PrimaryError::NothingTo("undo"))?;
        let e = &self.log.entries[i];
        let changes = self.network.swap_patch(&e.after, &e.before)?;
        self.log.applied = i;
        Ok(changes)
    }

    /// Redoes the next undone edit.
    ///
    /// # Errors
    /// [`PrimaryError::NothingTo`] when nothing is undone.
    pub fn redo(&mut self) -> Result<ChangeSet, PrimaryError> {
        let i = self.log.applied;
        let e = self
            .log
            .entries
            .get(i)
            .ok_or(PrimaryError::NothingTo("redo"))?;
        let changes = self.network.swap_patch(&e.before, &e.after)?;
        self.log.applied = i + 1;
        Ok(changes)
    }

    /// Replays the applied edits of `log` on `start` by proposing and committing each
    /// again: the result equals the network the log was recorded on.
    ///
    /// # Errors
    /// The first refusal (the log does not belong to this start, terrain or options).
    pub fn replay(
        start: PrimaryNetwork,
        log: &EditLog,
        terrain: Terrain,
        options: EditOptions,
    ) -> Result<Self, PrimaryError> {
        let mut ed = Self::with_network(start, terrain, options)?;
        for edit in log.applied_edits() {
            ed.apply(edit)?;
        }
        Ok(ed)
    }
}
