//! The course report's grid road builders (*L-Systems for Cities*, final project report):
//! "snake heads" that walk a square grid laid over a city cell, each step choosing a
//! movement by rule probabilities read from JSON, branching out to their sides, crossing
//! or T-ing into the streets they meet, and (Downtown) refusing dead ends. One more
//! neighbourhood pattern for a cell, beside Kelly's secondary growth: same input (the
//! cell with holes and filaments, the water and park maps, parameters, a seed), same
//! output (the cell's planar streets, joined to its boundary; [`GridRoads::cell_graph`]
//! adds the boundary and filaments as highway edges, the shape of Kelly's cell graph).
//!
//! ```text
//!  rules JSON ─▶ GridRules ─┐
//!  cell, filaments, maps ───┼─▶ grid over the cell (axis: longest edge) ─▶ builders at
//!  seed (rand_pcg) ─────────┘   the longest edges' midpoints, FIFO queue ─▶ street map
//!                               ─▶ straight runs + joins, inserted with exact predicates
//!                               ─▶ RoadNetwork (streets) + boundary nodes
//! ```
//!
//! ## Algorithm (report, "The road creation algorithm", Snippet 3)
//!
//! 1. The grid: step [`GridParams::grid_size_m`], first axis along the cell's longest
//!    boundary edge (or [`GridParams::orientation_deg`]), origin at that edge's midpoint.
//! 2. The axiom: a builder at the first grid point inside the cell in front of the
//!    midpoint of the longest edge, facing inwards (the report's builder at the south
//!    edge facing north), joined to the edge; [`GridParams::starts`] > 1 adds one per
//!    next-longest edge.
//! 3. Breadth-first: pop the front builder; draw a movement (`CS`/`TR`/`TL`/`STOP`); if
//!    the move is valid, the new point becomes a street and the builder goes to the back
//!    of the queue. Constraints: inside the cell and out of water and parks;
//!    a street ahead is crossed (cross-intersection probability, if the point beyond is
//!    valid) or ends the builder in a T; no street beside the new point, so parallel
//!    streets keep a block between them; the boundary counts as a street, so a builder
//!    reaching it joins it.
//! 4. A builder that stops or is blocked where its street would end in a dead end draws
//!    the dead-end rule; when dead ends are not allowed it tries the other movements
//!    (the report's loop over `getAvailableMovementActions`), and if none is valid its
//!    street is removed back to the last junction.
//! 5. Then, from the builder's previous position, branch out left and right, each with
//!    the branch-out probability: a new builder takes one step sideways and is queued.
//! 6. The street map becomes a planar graph: one segment per straight run, one per
//!    boundary join, all through planar insertion.
//!
//! ## Example
//!
//! ```
//! use polis_roads::grid_builders::{GridMaps, GridParams, grow_grid_roads, street_stats};
//! use polis_roads::geom::{DVec2, Polygon, PolygonWithHoles};
//! use polis_roads::geom::field::FnField;
//!
//! let cell = PolygonWithHoles::from(Polygon::rect(DVec2::ZERO, DVec2::new(300.0, 240.0)));
//! // A pond in one corner: 1 = water.
//! let pond = FnField(|p: DVec2| if p.distance(DVec2::new(250.0, 200.0)) < 40.0 { 1.0 } else { 0.0 });
//! let maps = GridMaps { water: Some(&pond), ..GridMaps::none() };
//! let roads = grow_grid_roads(&cell, &maps, &GridParams::downtown(), 7)?;
//! roads.network.check_invariants()?; // planar
//! let stats = street_stats(&roads.network, &roads.boundary_nodes, &cell)?;
//! assert_eq!(stats.dead_ends, 0); // Downtown allows none
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Guarantees
//!
//! * The network is planar ([`PlanarGraph::check_invariants`](polis_geom::PlanarGraph::check_invariants)
//!   holds) and every street lies in the cell: grid points are strictly inside and at
//!   least [`GridParams::boundary_clearance`] steps from the boundary, and a street
//!   reaching the boundary ends on it (its end is the computed crossing point, off the
//!   exact boundary by rounding only).
//! * Every connected component reaches the boundary (it grew from a start joined to it;
//!   pruning removes only whole dead-end branches).
//! * With a dead-end probability of 0 (Downtown) there is no interior dead end; with 1
//!   (Residential) builders may stop anywhere.
//! * No street has a legality sample (every [`GridParams::legality_step_m`]) in water or
//!   a park.
//! * Deterministic: the same cell, maps, parameters and seed give the same graph, ids
//!   included; randomness is one `Pcg64Mcg` seeded with the caller's `seed`.
//! * Bad rules and parameters are typed errors ([`GridError`]), never panics.
//!
//! ## Limitations
//!
//! * Streets run only along the two grid axes and turn by 90° (the report's limitation);
//!   at the boundary the last step runs on to the boundary at whatever angle it meets it.
//! * The grid is global to the cell: a cell whose boundary bends strongly gets streets
//!   meeting some edges at an angle; give [`GridParams::orientation_deg`] per cell to
//!   choose.
//! * Water and parks are sampled, not intersected: a sliver narrower than
//!   `legality_step_m` can be crossed.
//! * A street never runs on to the boundary at less than about 11.5° (such a join is
//!   refused like any blocked move): where a grid line runs into a reflex corner along
//!   one of the corner's edges, it would run along the boundary.
//! * A region of the cell that no builder reaches (behind water, or a narrow neck of a
//!   concave cell) stays empty; more [`GridParams::starts`] help. With the report's
//!   probabilities builders die out early in small cells (the report's own limitation:
//!   "the created layout is useless" when early builders fail), so coverage varies from
//!   seed to seed.
//! * The loop is bounded by [`MAX_POPS_PER_POINT`] pops per grid point (pruned points
//!   can be built again, so termination is otherwise only almost sure); a run that
//!   reaches it ends its queued builders under the dead-end rule and says so in
//!   [`GridReport::truncated`].
//!
//! ## Departures from the report
//!
//! * The report's city is a square map; here the grid is laid over any cell (concave,
//!   with holes and filaments), and the boundary acts as an existing street.
//! * The report applies the no-dead-end rule only to blocked moves; here it also applies
//!   to `STOP`, and a builder that cannot avoid a forbidden dead end is pruned back, so
//!   the rule holds for the whole network. (Both shipped rule sets behave as in the
//!   report: Downtown never stops, Residential allows every dead end.)
//! * The report's exceptions to the side constraint are not listed; the one kept here
//!   lets a street end that points at the new grid point join it (a T).
//! * The report starts one builder; here [`GridParams::starts`] (default 4) start at the
//!   midpoints of the longest edges, as Kelly's growth does, since a cell is surrounded
//!   by roads on every side.
//! * A branch takes its first step at once (the report does not show
//!   `branchOutToSide`); one that would step straight onto a street is dropped (it would
//!   close a block one step wide).
//! * Streets running on to the boundary may not cross one another (each reserves the
//!   grid point it passes).
//!
//! ## References
//!
//! * *L-Systems for Cities*, final project report (CS354, University of Texas at Austin):
//!   "Road generation system", Snippets 3–5, "Constraints enforcement", "Limitations".
//! * Y. I. H. Parish, P. Müller, *Procedural Modeling of Cities*, SIGGRAPH 2001, §3.3
//!   (constraints on proposed roads, which the report adopts).
//! * G. Kelly, *An Interactive System for Procedural City Generation*, 2008, §4.3
//!   (growth inside city cells from the longest boundary sides).

mod error;
mod graph;
mod growth;
mod lattice;
mod maps;
mod params;
pub mod rules;
mod stats;

use std::collections::VecDeque;

use polis_geom::{DVec2, NodeId, PolygonWithHoles};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

pub use error::{GridError, Result};
pub use graph::BOUNDARY_ROAD;
pub use maps::GridMaps;
pub use params::GridParams;
pub use rules::{
    BranchOut, CrossIntersection, DOWNTOWN_JSON, DeadEnd, GridRules, Movement,
    PROBABILITY_SUM_TOLERANCE, RESIDENTIAL_JSON, Rule, RuleAction,
};
pub use stats::{StreetStats, street_stats};

use growth::{Builder, Counts, Growth};
use lattice::{Dir, Frame, Ground, Site};

use crate::network::RoadNetwork;

/// What the builders did in one cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct GridReport {
    /// Grid points over the cell's bounding box.
    pub grid_points: usize,
    /// Builders that started at the boundary.
    pub starts: u32,
    /// Builders created in all (starts and branches).
    pub builders: u32,
    /// Queue pops (builder steps).
    pub steps: u32,
    /// Successful branch-outs (including branches that joined the boundary at once).
    pub branches: u32,
    /// Intersections crossed (cross junctions made).
    pub crossings: u32,
    /// Builders that ended in a T at a street.
    pub t_junctions: u32,
    /// Streets joined to the boundary (starts included).
    pub boundary_joins: u32,
    /// Street ends joined from the side (the side-constraint exception).
    pub side_joins: u32,
    /// Moves refused by a constraint.
    pub blocked: u32,
    /// Builders saved from a forbidden dead end by another movement.
    pub rescued: u32,
    /// Dead ends left because the rules allowed them.
    pub dead_ends_allowed: u32,
    /// Forbidden dead ends removed back to their junction.
    pub dead_ends_pruned: u32,
    /// Grid points those removals cleared.
    pub pruned_points: u32,
    /// The growth hit its guard of [`MAX_POPS_PER_POINT`] queue pops per grid point and
    /// ended the builders still queued (never seen in practice; see the module docs).
    pub truncated: bool,
}

/// The growth guard: at most this many queue pops per grid point. Every pop makes a
/// street point or ends a builder, but pruned points can be built again, so the loop is
/// bounded explicitly; real runs use about one pop per street point.
pub const MAX_POPS_PER_POINT: usize = 16;

/// The grid builders' result for one cell.
#[derive(Debug, Clone)]
pub struct GridRoads {
    /// The cell's streets: planar, class [`Street`](crate::RoadClass::Street), width
    /// [`GridParams::street_width_m`]; the cell boundary itself is not included.
    pub network: RoadNetwork,
    /// The nodes of `network` on the cell boundary (where streets join the boundary
    /// roads), sorted.
    pub boundary_nodes: Vec<NodeId>,
    /// What happened.
    pub report: GridReport,
}

/// The grid road builders of one cell (Snippet 3 of the report). See the [module
/// documentation](self).
///
/// A reusable worker: it keeps its grid, join list and queue between cells, so a
/// pipeline growing thousands of cells allocates them once per thread.
#[derive(Debug, Default)]
pub struct GridBuilderGrowth {
    sites: Vec<Site>,
    joins: Vec<(usize, DVec2)>,
    queue: VecDeque<Builder>,
    /// Width of the last cell's grid (for tests that print the street map).
    width: usize,
}

/// The cell's edges, longest first (ties by ring, then edge order): `(a, b)` with the
/// cell on the left of `a → b`.
fn edges_longest_first(cell: &PolygonWithHoles) -> Vec<(DVec2, DVec2)> {
    let mut edges: Vec<(f64, usize, DVec2, DVec2)> = cell
        .rings()
        .flat_map(|(_, ring)| ring.edges())
        .enumerate()
        .map(|(i, (a, b))| (a.distance_squared(b), i, a, b))
        .collect();
    edges.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    edges.into_iter().map(|(_, _, a, b)| (a, b)).collect()
}

impl GridBuilderGrowth {
    /// A worker with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// The last grown cell's street map as text, north (the grid's second axis) up, one
    /// character per grid point: `*` a street, `J` a street joined to the boundary, `.`
    /// anything else — the report's console print of a layout (its Images 2.1 and 2.2).
    /// Empty before the first [`grow`](Self::grow).
    pub fn street_map(&self) -> String {
        let mut out = String::new();
        if self.width == 0 {
            return out;
        }
        for row in self.sites.chunks(self.width).rev() {
            out.extend(row.iter().map(|s| match (s.street, s.joined) {
                (false, _) => '.',
                (true, false) => '*',
                (true, true) => 'J',
            }));
            out.push('\n');
        }
        out
    }

    /// Grows the streets of `cell` (see [`grow_grid_roads`]); `filaments` are road
    /// segments inside the cell (dead-end roads of the graph the cell came from), which
    /// the builders treat like the boundary: they join them and keep clear of them.
    ///
    /// # Errors
    /// [`GridError::InvalidParameter`] and the rule errors for bad `params`;
    /// [`GridError::InvalidCell`] for an invalid cell or filament;
    /// [`GridError::TooManyLatticePoints`]; [`GridError::NoStart`] for a cell too small
    /// or too wet for one grid step.
    pub fn grow(
        &mut self,
        cell: &PolygonWithHoles,
        filaments: &[[DVec2; 2]],
        maps: &GridMaps<'_>,
        params: &GridParams,
        seed: u64,
    ) -> Result<GridRoads> {
        self.grow_guarded(cell, filaments, maps, params, seed, None)
    }

    /// [`grow`](Self::grow) with the pop guard `max_pops` (`None`: [`MAX_POPS_PER_POINT`]
    /// per grid point).
    fn grow_guarded(
        &mut self,
        cell: &PolygonWithHoles,
        filaments: &[[DVec2; 2]],
        maps: &GridMaps<'_>,
        params: &GridParams,
        seed: u64,
        max_pops: Option<u32>,
    ) -> Result<GridRoads> {
        params.validate()?;
        let mut cell = cell.clone();
        cell.normalize();
        cell.validate().map_err(GridError::InvalidCell)?;
        let edges = edges_longest_first(&cell);
        let Some(&(a, b)) = edges.first() else {
            return Err(GridError::NoStart {
                grid_size_m: params.grid_size_m,
            });
        };
        // The first axis: along the longest edge (no trigonometry), or the given angle.
        let axis = match params.orientation_deg {
            Some(deg) => DVec2::from_angle(deg.to_radians()),
            None => (b - a).normalize(),
        };
        let frame = Frame::covering(
            &cell,
            a.midpoint(b),
            axis,
            params.grid_size_m,
            params.max_lattice_points,
        )?;
        let ground = Ground::new(&cell, filaments, *maps, params.legality_step_m)?;
        self.sites.clear();
        self.sites.resize(frame.len(), Site::default());
        self.width = frame.width;
        self.joins.clear();
        self.queue.clear();
        let mut growth = Growth {
            frame,
            sites: &mut self.sites,
            joins: &mut self.joins,
            ground: &ground,
            rules: &params.rules,
            rng: Pcg64Mcg::seed_from_u64(seed),
            clearance: params.boundary_clearance * params.grid_size_m,
            queue: &mut self.queue,
            max_pops: max_pops.unwrap_or_else(|| {
                u32::try_from(frame.len().saturating_mul(MAX_POPS_PER_POINT)).unwrap_or(u32::MAX)
            }),
            counts: Counts::default(),
        };
        let mut starts = 0;
        for &(a, b) in edges.iter().take(params.starts as usize) {
            if place_start(&mut growth, a, b) {
                starts += 1;
            }
        }
        if starts == 0 {
            return Err(GridError::NoStart {
                grid_size_m: params.grid_size_m,
            });
        }
        growth.run();
        let c = growth.counts;
        let (network, boundary_nodes) =
            graph::to_network(&frame, &self.sites, &self.joins, params.street_width_m)?;
        Ok(GridRoads {
            network,
            boundary_nodes,
            report: GridReport {
                grid_points: frame.len(),
                starts,
                builders: c.builders,
                steps: c.pops,
                branches: c.branches,
                crossings: c.crossings,
                t_junctions: c.t_junctions,
                boundary_joins: c.boundary_joins,
                side_joins: c.side_joins,
                blocked: c.blocked,
                rescued: c.rescued,
                dead_ends_allowed: c.dead_ends_allowed,
                dead_ends_pruned: c.dead_ends_pruned,
                pruned_points: c.pruned_points,
                truncated: c.truncated,
            },
        })
    }
}

/// Starts a builder in front of the midpoint of edge `a → b` (cell on its left), facing
/// the grid direction closest to the edge's inward normal, on the nearest grid line.
/// Returns whether one started.
fn place_start(growth: &mut Growth<'_, '_>, a: DVec2, b: DVec2) -> bool {
    let frame = growth.frame;
    let inward = (b - a).perp();
    let dir = Dir::ALL
        .into_iter()
        .max_by(|&x, &y| {
            frame
                .vector(x)
                .dot(inward)
                .total_cmp(&frame.vector(y).dot(inward))
                // Ties: the earlier direction.
                .then((y as u8).cmp(&(x as u8)))
        })
        .unwrap_or(Dir::North);
    let g = frame.grid_coords(a.midpoint(b));
    let (di, dj) = dir.delta();
    // The grid line through the midpoint's nearest line, then the first grid point
    // strictly beyond the midpoint along `dir`.
    let (line, along) = if di == 0 {
        (g.x.round(), g.y)
    } else {
        (g.y.round(), g.x)
    };
    let sign = (di + dj) as f64;
    let first = if sign > 0.0 {
        along.floor() + 1.0
    } else {
        along.ceil() - 1.0
    };
    let reach = 3.0 * frame.step + growth.clearance;
    for k in 0..3 {
        let t = first + sign * k as f64;
        let (i, j) = if di == 0 { (line, t) } else { (t, line) };
        let Some(site) = frame.index(i as i64, j as i64) else {
            return false;
        };
        let p = frame.position(site);
        if !growth.ground.inside(p) || !growth.ground.clear(p, growth.clearance) {
            continue;
        }
        let Some((hit, true)) = growth.ground.first_hit(p, p - frame.vector(dir) * reach) else {
            return false;
        };
        // The grid points the join passes: none may be a street or passed by another.
        let mut passes = Vec::new();
        let mut q = site;
        while let Some(n) = frame.neighbor(q, dir.opposite()) {
            if frame.position(n).distance(p) >= hit.distance(p) {
                break;
            }
            let s = growth.sites[n];
            if s.street || s.passed {
                return false;
            }
            passes.push(n);
            q = n;
        }
        if growth.sites[site].street || growth.sites[site].passed {
            return false;
        }
        return match growth.fresh(site, dir, hit) {
            Some(tips) => {
                growth.start(site, dir, hit, &passes, tips);
                true
            }
            None => false,
        };
    }
    false
}

/// Grows the course report's grid streets in one `cell` (a polygon with holes; any
/// orientation, possibly concave), keeping out of water and parks (`maps`), with `params`' rules, seeded by `seed` (the caller derives it
/// from the city seed and the cell's stable id). The one-call form of
/// [`GridBuilderGrowth::grow`] without filaments.
///
/// # Errors
/// See [`GridBuilderGrowth::grow`].
pub fn grow_grid_roads(
    cell: &PolygonWithHoles,
    maps: &GridMaps<'_>,
    params: &GridParams,
    seed: u64,
) -> Result<GridRoads> {
    GridBuilderGrowth::new().grow(cell, &[], maps, params, seed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::Polygon;

    #[test]
    fn the_pop_guard_ends_builders_under_the_dead_end_rule() {
        let cell = PolygonWithHoles::from(Polygon::rect(DVec2::ZERO, DVec2::new(500.0, 400.0)));
        let maps = GridMaps::none();
        let params = GridParams::downtown();
        for seed in 0..10 {
            let mut w = GridBuilderGrowth::new();
            let full = w.grow(&cell, &[], &maps, &params, seed).unwrap();
            assert!(!full.report.truncated);
            let cut = w
                .grow_guarded(&cell, &[], &maps, &params, seed, Some(25))
                .unwrap();
            assert!(cut.report.truncated, "{}", w.street_map());
            assert_eq!(cut.report.steps, 25);
            cut.network.check_invariants().unwrap();
            for s in w.sites.iter().filter(|s| s.street) {
                assert!(
                    s.degree() >= 2,
                    "dead end after the guard\n{}",
                    w.street_map()
                );
            }
        }
    }

    #[test]
    fn street_map_links_are_symmetric_and_downtown_has_no_dead_end_points() {
        let cell = PolygonWithHoles::from(Polygon::rect(DVec2::ZERO, DVec2::new(500.0, 400.0)));
        let maps = GridMaps::none();
        for (params, dead_ends_allowed) in [
            (GridParams::downtown(), false),
            (GridParams::residential(), true),
        ] {
            for seed in 0..10 {
                let mut w = GridBuilderGrowth::new();
                let r = w.grow(&cell, &[], &maps, &params, seed).unwrap();
                let rows = w.sites.len() / w.width;
                let at = |x: i64, y: i64| {
                    (x >= 0 && y >= 0 && (x as usize) < w.width && (y as usize) < rows)
                        .then(|| w.sites[y as usize * w.width + x as usize])
                };
                let mut streets = 0;
                for (k, s) in w.sites.iter().enumerate() {
                    let (x, y) = ((k % w.width) as i64, (k / w.width) as i64);
                    for d in Dir::ALL {
                        if s.links & d.bit() != 0 {
                            let (dx, dy) = d.delta();
                            let n = at(x + dx, y + dy).unwrap();
                            assert!(s.street && n.street, "{}", w.street_map());
                            assert!(n.links & d.opposite().bit() != 0, "{}", w.street_map());
                        }
                    }
                    if s.street {
                        streets += 1;
                        assert!(s.degree() >= 1, "isolated street point\n{}", w.street_map());
                        if !dead_ends_allowed {
                            assert!(s.degree() >= 2, "dead end\n{}", w.street_map());
                        }
                    }
                }
                assert!(streets > 10, "{}", w.street_map());
                assert_eq!(r.report.grid_points, w.sites.len());
            }
        }
    }
}
