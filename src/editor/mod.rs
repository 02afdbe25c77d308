//! The editable city (Kelly 2008 §4.1, §5, §6.5): a [`CityEditor`] holds a Citygen
//! city, its configuration and its primary network, takes [`Edit`]s (primary nodes and
//! roads, per-cell presets and parameters, per-lot and per-building overrides, map
//! paint, global settings), regenerates only the work an edit touches, reports what
//! changed ([`ChangeEvents`]), undoes and redoes, and saves its history as an
//! [`EditingFile`].
//!
//! ```no_run
//! use polis::editor::{CityEditor, Edit};
//!
//! let mut config = polis::CityConfig::preset("citygen")?;
//! config.size_m = 1500.0;
//! let mut editor = CityEditor::new(config)?;
//! let cell = editor.cells()[0].id;
//! let events = editor.apply(Edit::SetCellPattern {
//!     cell,
//!     pattern: polis::roads::secondary::Neighbourhood::Suburbia.into(),
//! })?;
//! println!("{} cells regrown, {} buildings changed", events.cells.len(), events.buildings.len());
//! editor.undo()?;
//! # Ok::<(), polis::Error>(())
//! ```
//!
//! # How only the affected work is redone
//!
//! Every edit changes the editor's state, which is plain configuration: the primary
//! network inline in [`CitygenConfig::primary`](crate::CitygenConfig), per-cell settings
//! ([`CitygenConfig::cells`](crate::CitygenConfig)), lot overrides and map paint. The
//! city is then made by the pipeline with each per-item stage wrapped in a memo (see
//! `memo.rs`): a city cell's secondary growth, a road-graph cell's blocks and lots, a
//! lot's building and a building's skin are keyed by a 128-bit digest of the exact bits
//! of everything they read, and redone only when that digest is new. A road-graph
//! cell's buildings and skins are also kept whole, keyed by its lot stage's input, the
//! city cells its lots can lie in, the lot overrides that can reach them and the rest of
//! the configuration: a cell an edit leaves alone costs one look-up, not one per lot.
//! The dirty set of an
//! edit is therefore exactly the work whose inputs it changed: cells whose boundary,
//! parameters, seed or maps changed, cells created, split or merged, and, downstream,
//! road-graph cells whose ring or nearby roads changed.
//!
//! Lot edits that change only lot overrides (pin a kind or a height, reseed a lot, clear
//! an override, and their undo and redo) do not run the pipeline at all: the editor
//! builds and dresses the buildings of the lots whose override changed and replaces
//! their scene leaves in the city it holds (see `patch.rs`). It falls back to the
//! pipeline where that could differ from it: a building appearing or disappearing (a
//! removal), a pinned style added or dropped, roads graded into the ground, a lot whose
//! building or skin failed.
//!
//! Two whole stages are reused as well. The road and cell stages read the configuration
//! but for the lot overrides, the facade settings and the level of detail, so an edit of
//! lots, buildings or styles keeps the union graph and its cells whole (keyed by a digest
//! of what they read). And the 3-D scene is spliced (see `splice.rs`): it is assembled
//! again, but every road-graph cell whose blocks, buildings and skins are those before
//! the edit (same scene-wide settings and ground) takes its whole subtree from the scene
//! before the edit, one run of nodes and one of meshes moved and renumbered, instead of
//! being meshed again; a cell with any change has all its leaves made again.
//!
//! # Stable identity
//!
//! A city cell's id (and so its growth seed) is a hash of the ids of the primary roads
//! around it: moving a node re-plots its roads but keeps their ids, so the cells around
//! it keep their ids and seeds and cells elsewhere are untouched. A road-graph cell's id
//! is a hash of its ring, so a lot (`cell id << 24 | index`) and its building keep id
//! and seed unless their cell was regenerated. Lot overrides are anchored to the lot id
//! and a point ([`LotOverride`]); an override whose lot is gone is re-anchored by point
//! or reported orphaned.
//!
//! # Guarantees
//!
//! * The edited city is byte for byte the city [`generate`](crate::generate) makes of
//!   [`CityEditor::config`] (glb, GeoJSON and every layer; tested on random edit
//!   sequences).
//! * A rejected edit (unknown id, NaN, out of range, outside the map, refused by the
//!   primary network's validity checks) or undo with nothing to undo returns a typed
//!   error and leaves the editor unchanged. So does an edit, undo or redo whose run
//!   fails in a stage: the city before it is kept, byte for byte (when the run failed
//!   before the scene was assembled, the same city with the scene it lent to the
//!   splice put back; otherwise made again from the memo).
//! * Replaying an [`EditingFile`] gives the identical city and history.
//!
//! # Limitations
//!
//! * A lot edit made in place costs what it touches: about 10 ms of CPU on the full
//!   `citygen` preset (64,000 buildings). An edit of the primary network or of a cell
//!   still runs the pipeline: it builds the union graph and its cell decomposition whole
//!   (their inputs are the whole city), looks up every road-graph cell's lots in the
//!   memo and copies them out (a cell whose inputs are unchanged then takes its
//!   buildings and skins whole, in one look-up), meshes the road surfaces again (a memo
//!   of their pieces was measured to save nothing: their cost is the plan of the whole
//!   network and the pass that writes its meshes, not the pieces; they are made beside the
//!   scene's cells, off the critical path where the cells take longer), assembles
//!   the scene again (a cell left alone moves its subtree's runs of nodes and meshes
//!   out of the old scene, without a look-up per leaf, but every node and mesh of the
//!   city is still moved into the new scene's arrays; the terrain is
//!   reused while the water bed under it is unchanged, the water bodies with their
//!   shores' grid while the maps are) and the change events pair off the lots and
//!   buildings of the two cities cell by cell (a pointer comparison per item where the
//!   edit shared them) and sort and compare only those of the cells that changed (the
//!   blocks, a few thousand, are all compared).
//!   Its cost is therefore still proportional to the city's size, not to the dirty set:
//!   about 0.4 s of CPU per node move on that preset (session 20), far from Kelly's 60 ms per cell;
//!   BENCHMARKS.md gives the profile. With roads graded into an elevation map the scene
//!   is not spliced and the terrain not reused (the ground depends on every road).
//! * Painting parks or water-like values does not re-check existing primary roads; it
//!   changes where later road edits are legal.
//! * Only Citygen-mode cities are editable ([`RoadMode::Citygen`](crate::RoadMode)).
//!
//! # References
//!
//! Kelly, *An Interactive System for Procedural City Generation* (2008): §4.1 (editing
//! any stage, results propagating), §5.3–5.5 (node, road and cell modes, the property
//! inspector, presets), §6.5–6.7 (per-cell regeneration). Lipp et al., *Interactive
//! Modeling of City Layouts using Layers of Procedural Content* (2011): anchored
//! assignments.

mod diff;
mod edit;
mod file;
pub(crate) mod key;
mod memo;
mod patch;
mod splice;
mod state;

pub use edit::{ChangeEvents, Delta, Edit, End, Preview, PreviewRoad, Regenerated};
pub use file::EditingFile;
pub use state::{CellInfo, CellParams, CityEditor};

pub use crate::citygen::{CellParam, CellSettings, LotOverride, MapPaint, PaintLayer};
