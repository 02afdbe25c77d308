//! # polis-roads
//!
//! Road networks grown by Parish & Müller's extended open L-system (*Procedural Modeling
//! of Cities*, SIGGRAPH 2001, §3) on [`polis_lsystem`], with Kelly's snap algorithm
//! (Citygen, 2008, §4.3.3) for the self-sensitive constraints. The output is a planar
//! [`RoadNetwork`] (`PlanarGraph<Junction, Road>`) for the cells stage.
//!
//! ```text
//!  R ?I ──p2: GlobalGoals (population rays, patterns blended by maps)──▶ B B R ?I
//!           ?I ──p8: environment: LocalConstraints (legal? prune/bridge/rotate;
//!                    snap: crossing / junction / road; min angle)──▶ SUCCEED → graph
//! ```
//!
//! ## Key types
//!
//! | type | what |
//! |---|---|
//! | [`RoadParams`] | every knob, with units and defaults (serde) |
//! | [`RoadInputs`] | the input maps as [`polis_geom::Field`]s; [`RoadInputs::procedural`] needs no files |
//! | [`LazyLattice`] | a map sampled once per lattice point and interpolated: cheap legality tests on costly maps |
//! | [`GlobalGoals`], [`DefaultGoals`] | `globalGoals` of p2: highways, streets, patterns ([`Pattern`]) |
//! | [`LocalConstraints`], [`DefaultConstraints`] | `localConstraints` of p8 |
//! | [`RoadGenerator`], [`generate`], [`generate_default`] | run the L-system |
//! | [`RoadNetwork`], [`Junction`], [`Road`], [`RoadClass`] | the output |
//! | [`tunnels`]: [`Portal`], [`portals`], [`portal_mesh`] | highways under parks and hills (P&M §3.3's "two tunnel entrances") |
//! | [`StreetRules`] | per pattern: branching, crossroads or T, culs-de-sac, curved links of several segments, spread of street lengths |
//! | [`modules`] | the modules `R`, `B`, `?I` and productions p1–p9 |
//! | [`primary`]: [`PrimaryNetwork`], [`PrimaryEditor`] | Kelly's primary network: adaptive roads over terrain, validity-checked edits, undo (Citygen §4.2, §5.3) |
//! | [`grid_builders`]: [`GridBuilderGrowth`], [`grow_grid_roads`], [`GridRules`], [`GridParams`] | the course report's grid road builders in one cell (rules from JSON; Downtown, Residential) |
//!
//! ## Example
//!
//! ```
//! use polis_roads::{Pattern, RoadParams, generate_default, network_stats};
//!
//! let params = RoadParams { pattern: Pattern::NewYork, max_segments: 300, ..RoadParams::default() };
//! let city = generate_default(&params)?;
//! city.network.check_invariants()?; // planar: every crossing is a junction
//! assert!(city.report.segments <= 300);
//! assert!(network_stats(&city.network).street_length_m > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Guarantees
//!
//! * The network is always a valid planar straight-line graph (insertion through
//!   `PlanarGraph::insert_segment`, which splits at every crossing with exact predicates).
//! * No road other than a bridge or a tunnel has a legality sample (every
//!   `legality_step_m`) in water, a park, outside the map or above the slope limit;
//!   bridges are at most `max_bridge_length_m`, tunnels ([`tunnels`]) at most
//!   `max_tunnel_length_m` and under water only with `tunnel_under_water`.
//! * Deterministic: same parameters, maps and seed give the same graph, ids included.
//! * Never panics on parameters: [`RoadParams::validate`] rejects bad values with a
//!   typed [`RoadError`].
//!
//! ## Limitations
//!
//! * Legality is sampled (every `legality_step_m`, default 5 m; slope over `slope_step_m`): a sliver of water
//!   thinner than that can be missed.
//! * Streets lower the population around them (the open-L-system feedback the paper
//!   mentions, [`PopulationFeedback`]) only with `population_feedback` above 0 (off by
//!   default); otherwise the population threshold alone stops them.
//! * The turtle modules `+F` and the brackets of p5 are not kept in the string (see
//!   [`modules`]).
//! * Roads stop where a proposal fails (illegal with no prune/rotate/bridge variant, or
//!   below the minimum angle), so dead ends remain at the fringe of the city, as in the
//!   paper's figures; there is no pass that removes or reconnects them.
//! * Speed (see the polis repository's `BENCHMARKS.md`): 15,000 segments take about 100 ms of CPU with the
//!   procedural maps, whose coastline and hills are sampled on lazily cached 40 m
//!   [`LazyLattice`]s. Maps given as other fields are sampled as they are, at every
//!   legality sample (a few hundred thousand for 15,000 segments): an expensive water or
//!   park map (many-octave noise, a closure doing real work) is worth wrapping in a
//!   [`LazyLattice`] first.
//!
//! ## References
//!
//! * Y. I. H. Parish, P. Müller, *Procedural Modeling of Cities*, SIGGRAPH 2001, §3.
//! * G. Kelly, *An Interactive System for Procedural City Generation*, 2008, §3.4.1, §4.3.3.
//! * The priority-queue slides (initialisation with two opposite segments, branch delay,
//!   population threshold) after S. Barrett, *L-Systems Considered Harmful*, 2008.

pub use polis_geom as geom;
pub use polis_lsystem as lsystem;

pub mod constraints;
pub mod error;
pub mod feedback;
pub mod generator;
pub mod goals;
pub mod grading;
pub mod grid_builders;
pub mod inputs;
pub mod lattice;
pub mod legality;
pub mod modules;
pub mod network;
pub mod params;
pub mod primary;
pub mod secondary;
pub mod smooth;
pub mod snap;
pub mod street_rules;
pub mod tunnels;

pub use constraints::{ConstraintStats, DefaultConstraints, LocalConstraints};
pub use error::{Result, RoadError, RoadsError};
pub use feedback::PopulationFeedback;
pub use generator::{
    Generated, GrowthReport, RoadGenerator, StopReason, generate, generate_default,
};
pub use goals::{DefaultGoals, GlobalGoals};
pub use grading::{Earthworks, GradeParams, GradedGround, grade_roads};
pub use grid_builders::{GridBuilderGrowth, GridParams, GridRoads, GridRules, grow_grid_roads};
pub use inputs::{RoadInputs, procedural_lattice_m};
pub use lattice::LazyLattice;
pub use modules::{Proposal, QueryState, RoadAttr, RoadModule, RuleAttr};
pub use network::{Junction, NetworkStats, Road, RoadClass, RoadNetwork, network_stats};
pub use params::{Pattern, RoadParams};
pub use primary::{PrimaryEditor, PrimaryError, PrimaryNetwork};
pub use street_rules::{BranchChoice, DeadEndLinks, StreetRules};
pub use tunnels::{Portal, portal_mesh, portals};
