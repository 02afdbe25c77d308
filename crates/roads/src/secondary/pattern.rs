//! The extension point: a neighbourhood pattern grows one cell's roads.

use super::cell::{CellMaps, SecondaryCell};
use super::error::SecondaryError;
use super::growth::{SecondaryGrowth, SecondaryRoads};
use super::params::SecondaryParams;

/// A road pattern that fills one city cell: Kelly's growth ([`SecondaryGrowth`]) is one;
/// other generators (grid road builders, templates) implement the same contract and plug
/// into the same per-cell pipeline.
///
/// # Contract
///
/// Input: the cell (region with holes, filaments, stable id), the maps, a seed (the
/// implementation mixes in the cell id). Output: [`SecondaryRoads`] whose network holds
/// the cell boundary and filaments as [`RoadClass::Highway`](crate::RoadClass) edges and
/// the new roads as [`RoadClass::Street`](crate::RoadClass) edges; it must be planar,
/// every street must lie inside the region and out of water and parks, and every street
/// component must touch the boundary or a filament. Errors for which
/// [`SecondaryError::is_skip`] holds are counted as skipped cells by the pipeline.
pub trait CellPattern: Send + Sync {
    /// Grows the roads of `cell`.
    ///
    /// # Errors
    /// See the trait's contract.
    fn grow(
        &self,
        cell: &SecondaryCell,
        maps: &CellMaps<'_>,
        seed: u64,
    ) -> Result<SecondaryRoads, SecondaryError>;
}

impl CellPattern for SecondaryParams {
    fn grow(
        &self,
        cell: &SecondaryCell,
        maps: &CellMaps<'_>,
        seed: u64,
    ) -> Result<SecondaryRoads, SecondaryError> {
        SecondaryGrowth::new(self.clone())?.grow(cell, maps, seed)
    }
}
