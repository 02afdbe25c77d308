//! # polis-cells
//!
//! City cells from a planar road graph: the **minimal cycle basis** of the graph (David
//! Eberly's algorithm), with the filaments (dead ends, trees, connectors) and the nesting of
//! cycles, grouped into self-contained cells.
//!
//! In Kelly's *Citygen* (§4.3.1), cells are the regions enclosed by the primary roads;
//! secondary roads grow inside each cell independently (in parallel), and the blocks are
//! later extracted from the secondary network the same way (§4.4).
//!
//! ```text
//!  PlanarGraph<N, E> ──extract──▶ CellDecomposition
//!                                   ├─ cells: Vec<Cell>     one per bounded face, left to right
//!                                   │    ├─ boundary: Ring  the minimal cycle, counter-clockwise
//!                                   │    ├─ holes: Vec<Ring> island outlines, clockwise
//!                                   │    ├─ filaments        dead ends, connectors inside it
//!                                   │    ├─ parent / children / depth   the containment tree
//!                                   │    ├─ polygon_with_holes()  its region, valid for polis-lots
//!                                   │    └─ road_graph(&g)   its private road graph (payloads cloned)
//!                                   ├─ outer_filaments, outer_isolated_nodes, outlines
//!                                   └─ report: merged nodes, dropped edges, counts
//! ```
//!
//! Key types: [`extract`] / [`extract_with`] (one call) and [`CellExtractor`] (keeps its
//! buffers between runs), [`extract_planarized`] for graphs that may cross themselves,
//! [`CellParams`], [`CellDecomposition`], [`Cell`], [`Ring`], [`Filament`],
//! [`ExtractionReport`], [`Error`]. For the stages downstream, [`Cell::polygon_with_holes`]
//! gives every cell's region as a [`geom::PolygonWithHoles`] that passes
//! `validate` (islands touching the boundary at a node are moved off it by
//! [`TOUCH_SEPARATION`]).
//!
//! ## Example
//!
//! ```
//! use polis_cells::{extract, FilamentKind};
//! use polis_cells::geom::{DVec2, PlanarGraph};
//!
//! // A 3 × 3 grid of junctions (4 blocks) with a cul-de-sac into the first block.
//! let mut g: PlanarGraph<(), &str> = PlanarGraph::new();
//! let mut id = Vec::new();
//! for j in 0..3 {
//!     for i in 0..3 {
//!         id.push(g.add_node(DVec2::new(100.0 * i as f64, 100.0 * j as f64), ())?);
//!     }
//! }
//! for j in 0..3 {
//!     for i in 0..3 {
//!         if i < 2 { g.add_edge(id[3 * j + i], id[3 * j + i + 1], "street")?; }
//!         if j < 2 { g.add_edge(id[3 * j + i], id[3 * j + i + 3], "street")?; }
//!     }
//! }
//! let end = g.add_node(DVec2::new(50.0, 40.0), ())?;
//! let lane = g.add_edge(id[1], end, "cul-de-sac")?;
//!
//! let cells = extract(&g)?;
//! assert_eq!(cells.cells.len(), 4);
//! let first = &cells.cells[0];
//! assert_eq!(first.boundary.area(), 10_000.0);
//! assert_eq!(first.filaments.len(), 1);
//! assert_eq!(first.filaments[0].kind, FilamentKind::DeadEnd);
//! // Payloads stay reachable through the ids.
//! assert_eq!(*g.edge_payload(first.filaments[0].edges[0])?, "cul-de-sac");
//! assert_eq!(first.filaments[0].edges[0], lane);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Guarantees
//!
//! * One cell per bounded face of the embedding: `E − V + C` cells for `C` connected
//!   components. Each boundary is a simple counter-clockwise cycle whose nodes and edges
//!   are the input graph's ids; every edge lies on 0, 1 or 2 boundaries, and the edges on
//!   none are exactly the filament edges.
//! * The interiors of two boundaries are disjoint or nested; `parent` is the innermost
//!   boundary containing a cell, `holes` outline its islands (the union of its children),
//!   and a cell's own region is its boundary minus its holes.
//! * Every left/right decision uses the exact predicates of `polis-geom` (through the
//!   graph's exact rotation system); the containment of whole components comes from an
//!   exact line sweep (the edge directly below each component's leftmost node). Output
//!   order is deterministic (sweep order, then ids).
//! * [`Cell::polygon_with_holes`] always passes `PolygonWithHoles::validate`; only hole
//!   vertices touching another ring move, by [`TOUCH_SEPARATION`] into their hole.
//! * `O(n log n)`: one sort of the nodes, one line sweep (the planarity check, and the
//!   containment of components), then every half-edge is walked once.
//! * Non-planar input (crossings, overlaps, nodes inside edges) is rejected with
//!   [`Error::NotPlanar`] naming the edges (or planarised on request with
//!   [`extract_planarized`]); coincident nodes are merged (and reported) or rejected, see
//!   [`CellParams`]. The check is an exact Shamos–Hoey sweep, skipped for graphs that are
//!   planar by construction (`PlanarGraph::is_planar_by_construction`: built only by
//!   planar insertion).
//!
//! ## Limitations
//!
//! * No tolerance: nodes are merged only at exactly equal positions, and nearly touching
//!   edges count as apart. Snap with the graph's planar insertion first.
//! * [`extract`] rejects non-planar input; [`extract_planarized`] rebuilds it with the
//!   graph's planar insertion first (snapping moves geometry by up to the snap distance,
//!   and the cells then refer to the rebuilt graph's ids).
//! * Listing the conflicts of a non-planar graph (after the `O(n log n)` sweep has found
//!   one) buckets edges in a uniform grid: fast on road graphs, slow for nodes of very high
//!   degree (thousands of edges at one junction).
//!
//! ## References
//!
//! * D. Eberly, *The Minimal Cycle Basis for a Planar Graph*, Geometric Tools, 2005
//!   (revised 2020 as *Constructing a Cycle Basis for a Planar Graph*).
//! * G. Kelly, *An Interactive System for Procedural City Generation*, 2008, §4.3.1, §4.4.
//! * M. I. Shamos, D. Hoey, *Geometric intersection problems*, FOCS 1976 (the planarity
//!   sweep).

mod assemble;
mod cell_graph;
mod eberly;
pub mod error;
mod output;
pub mod params;
mod planarity;
mod planarize;
mod region;
mod sweep_line;
mod topology;

pub use polis_geom as geom;

pub use cell_graph::CellGraph;
pub use error::{CellsError, Conflict, Error};
pub use output::{
    Cell, CellDecomposition, CellId, DropReason, DroppedEdge, ExtractionReport, Filament,
    FilamentKind, IsolatedNode, NodeMerge, Ring,
};
pub use params::{CellParams, CoincidentNodes};
pub use planarity::MAX_REPORTED_CONFLICTS;
pub use planarize::{Planarized, extract_planarized};
pub use region::TOUCH_SEPARATION;

use polis_geom::PlanarGraph;

/// Extracts the cells of `graph` with default [`CellParams`].
///
/// # Errors
/// See [`extract_with`].
pub fn extract<N, E>(graph: &PlanarGraph<N, E>) -> Result<CellDecomposition, Error> {
    CellExtractor::new().extract(graph, &CellParams::default())
}

/// Extracts the cells of `graph`.
///
/// # Errors
/// [`Error::NotPlanar`] when edges cross, overlap or pass through nodes (with
/// `check_planarity`); [`Error::CoincidentNodes`] when nodes share a position and
/// `coincident_nodes` is `Reject`; [`Error::TooLarge`] beyond 2³¹ edges.
pub fn extract_with<N, E>(
    graph: &PlanarGraph<N, E>,
    params: &CellParams,
) -> Result<CellDecomposition, Error> {
    CellExtractor::new().extract(graph, params)
}

/// [`extract_with`] on the edges of `graph` whose payload `keep` accepts; the others are
/// left out as if absent (and not listed as dropped in the report). A road graph leaves
/// out its tunnels this way: the ground above a tunnel is one piece of land, not the
/// boundary of two cells.
///
/// # Errors
/// See [`extract_with`].
pub fn extract_where<N, E>(
    graph: &PlanarGraph<N, E>,
    params: &CellParams,
    keep: impl Fn(&E) -> bool,
) -> Result<CellDecomposition, Error> {
    CellExtractor::new().extract_where(graph, params, keep)
}

/// A reusable cell extractor: keeps its working buffers between runs, so extracting many
/// graphs (e.g. the secondary network of every cell) allocates only for the output.
#[derive(Debug, Default)]
pub struct CellExtractor {
    topo: topology::Topology,
    sweep: eberly::Sweep,
    line: sweep_line::SweepLine,
    check: planarity::PlanarityCheck,
}

impl CellExtractor {
    /// A new extractor with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Extracts the cells of `graph`. See [`extract_with`].
    ///
    /// # Errors
    /// See [`extract_with`].
    pub fn extract<N, E>(
        &mut self,
        graph: &PlanarGraph<N, E>,
        params: &CellParams,
    ) -> Result<CellDecomposition, Error> {
        self.extract_where(graph, params, |_| true)
    }

    /// Extracts the cells of the edges of `graph` that `keep` accepts. See
    /// [`extract_where`].
    ///
    /// # Errors
    /// See [`extract_with`].
    pub fn extract_where<N, E>(
        &mut self,
        graph: &PlanarGraph<N, E>,
        params: &CellParams,
        keep: impl Fn(&E) -> bool,
    ) -> Result<CellDecomposition, Error> {
        let mut report = ExtractionReport::default();
        self.topo.build(graph, params, &keep, &mut report)?;
        // The line sweep certifies planarity and, on the way, finds the edge below every
        // node (for the containment of components). Only when it finds a contact does the
        // slower grid check run, to list every conflict.
        // A graph built only by planar insertion vouches for itself.
        let mut below_known = false;
        if params.check_planarity && !graph.is_planar_by_construction() {
            below_known = self.line.run(&self.topo, true);
            if !below_known {
                self.check.check(&self.topo)?;
            }
        }
        self.sweep.run(&mut self.topo)?;
        if !below_known && self.sweep.components.len() > 1 {
            self.line.run(&self.topo, false);
        }
        Ok(assemble::assemble(
            &self.topo,
            &self.sweep,
            &self.line,
            report,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_send_sync_clone<T: Send + Sync + Clone>() {}

    /// A unit square split by a diagonal: two cells; with the diagonal left out, one
    /// (the square), and the diagonal's edge is not reported as dropped.
    #[test]
    fn extract_where_leaves_out_the_rejected_edges() {
        use polis_geom::DVec2;
        let mut g: PlanarGraph<(), bool> = PlanarGraph::new();
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let n: Vec<_> = corners
            .iter()
            .map(|&(x, y)| g.add_node(DVec2::new(x, y), ()).unwrap())
            .collect();
        for i in 0..4 {
            g.add_edge(n[i], n[(i + 1) % 4], false).unwrap();
        }
        let diagonal = g.add_edge(n[0], n[2], true).unwrap();
        let params = CellParams::default();
        assert_eq!(extract_with(&g, &params).unwrap().cells.len(), 2);
        let kept = extract_where(&g, &params, |&tunnel| !tunnel).unwrap();
        assert_eq!(kept.cells.len(), 1);
        assert!((kept.cells[0].boundary.polygon.area() - 1.0).abs() < 1e-12);
        assert!(kept.cells[0].boundary.edges.iter().all(|&e| e != diagonal));
        assert!(kept.report.dropped_edges.is_empty());
    }

    #[test]
    fn output_is_send_sync_clone() {
        assert_send_sync_clone::<Cell>();
        assert_send_sync_clone::<CellDecomposition>();
        assert_send_sync_clone::<Filament>();
    }
}
