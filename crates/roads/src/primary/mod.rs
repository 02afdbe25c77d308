//! Kelly's primary road network (Citygen, 2008, §4.2, §5.3–5.4): control nodes joined by
//! *adaptive roads* plotted across the terrain, and a validity-checked edit API.
//!
//! ```text
//!  high-level graph   ControlNode ──PrimaryRoad(spec)── ControlNode      (topology, ids)
//!        │ plot (§4.2.2): two fronts, fans of n_sample over ±θ_dev at d_sample,
//!        │                strategy picks (§4.2.3), join within d_snap
//!        ▼ spline: cubic Hermite, Catmull–Rom tangents, every segment_draw_size metres
//!  low-level graph    RoadPath (draped polyline per road) ──to_road_network──▶ RoadNetwork
//! ```
//!
//! | type | what |
//! |---|---|
//! | [`PrimaryNetwork`] | the two graphs: [`ControlNode`]s, [`PrimaryRoad`]s with their [`RoadPath`]s; serde, invariants |
//! | [`AdaptiveParams`], [`Strategy`], [`RoadPreset`], [`RoadSpec`] | how a road is plotted; §6.2's presets |
//! | [`Terrain`] | elevation + legality maps the roads are plotted on |
//! | [`plot()`], [`plot_traced`], [`plot_path`] | bidirectional plotting, with the fans for debugging |
//! | [`Edit`], [`Preview`], [`ChangeSet`], [`Correction`] | propose → preview → commit (§5.3.2) |
//! | [`PrimaryEditor`], [`EditLog`] | an editing session with undo / redo / replay |
//! | [`PrimarySpec`], [`PrimaryNetwork::from_geojson`], [`PrimaryNetwork::from_highways`] | sources |
//! | [`LowLevelGraph`] | [`PrimaryNetwork::to_road_network`]: the planar `RoadNetwork` for polis-cells, with edge → road ids |
//!
//! # Example
//!
//! ```
//! use polis_roads::geom::{Aabb2, DVec2};
//! use polis_roads::primary::{Edit, EditOptions, Endpoint, PrimaryEditor, RoadPreset, Terrain};
//!
//! let terrain = Terrain::flat(Aabb2::new(DVec2::splat(-1000.0), DVec2::splat(1000.0)))?;
//! let mut ed = PrimaryEditor::new(terrain, EditOptions::default())?;
//! let spec = RoadPreset::InnerCity.spec();
//! let at = |x, y| Endpoint::At(DVec2::new(x, y));
//! ed.apply(&Edit::AddRoad { from: at(-500.0, 0.0), to: at(500.0, 0.0), spec })?;
//! // A second road across the first: validity checking inserts a junction on both.
//! let preview = ed.propose(&Edit::AddRoad { from: at(0.0, -500.0), to: at(0.0, 500.0), spec })?;
//! assert_eq!(preview.corrections().len(), 1);
//! let changes = ed.commit(&preview)?;
//! assert_eq!(changes.nodes_added.len(), 3); // two ends and the junction
//! assert_eq!(ed.network().road_count(), 4);
//! ed.network().check_invariants()?;
//! ed.undo()?;
//! assert_eq!(ed.network().road_count(), 1);
//! let low = ed.network().to_road_network()?;
//! low.network.check_invariants()?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Guarantees
//!
//! * Plotting terminates for every accepted parameter set on any terrain, and is
//!   commutative: `plot(b → a)` is `plot(a → b)` reversed, bit for bit ([`plot()`]).
//! * The spline passes through every plot point exactly ([`spline`]).
//! * Both graphs are planar after every commit: a path meets another only at a shared
//!   node ([`PrimaryNetwork::check_invariants`]).
//! * A refused edit changes nothing; a commit writes exactly its preview; undo restores
//!   the serialised network byte for byte; replaying a log gives the identical network.
//! * Deterministic: no randomness, no hash-map order; ids are monotonic counters.
//!
//! # Limitations
//!
//! * Moves and parameter changes refuse to cross other roads instead of inserting
//!   junctions ([`edit`] explains why).
//! * Legality is sampled every [`Terrain::legality_step_m`] along each plot step; thinner
//!   obstacles can be missed, and the spline between two plot points (a few metres off
//!   their chord at sharp turns) is not tested again. Bridges are flagged on the path and draped on the ground
//!   like the rest (no deck profile).
//! * A split road keeps its piece of the old path; its spec applies again only when it
//!   is re-plotted (an end moves, or its spec changes).
//!
//! # References
//!
//! G. Kelly, *An Interactive System for Procedural City Generation*, 2008: §4.2 (graphs,
//! adaptive roads, sampling, strategies, spline), §5.3–5.4 (node and road edits,
//! validity checking), §6.1–6.2 (Milan, Paris; road presets).

pub mod edit;
pub mod error;
pub mod history;
pub mod io;
pub mod network;
pub mod params;
pub mod plot;
pub mod spline;
pub mod terrain;
mod validity;

pub use edit::{ChangeSet, Correction, Edit, Endpoint, Preview};
pub use error::PrimaryError;
pub use history::{EditLog, LogEntry, PrimaryEditor};
pub use io::{LowLevelGraph, NodeSpec, PrimarySpec, RoadEntry};
pub use network::{ControlId, ControlNode, Patch, PrimaryNetwork, PrimaryRoad, RoadId};
pub use params::{AdaptiveParams, EditOptions, MAX_PLOT_STEPS, RoadPreset, RoadSpec, Strategy};
pub use plot::{Fan, Plot, RoadPath, path_from_plot, plot, plot_path, plot_traced};
pub use terrain::{DEFAULT_LEGALITY_STEP_M, Ground, Terrain};
