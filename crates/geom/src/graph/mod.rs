//! [`PlanarGraph`]: a planar straight-line graph with stable ids and user payloads.
//!
//! Nodes carry a position ([`DVec2`], metres) and a payload `N`; undirected edges join two
//! distinct nodes with a straight segment and carry a payload `E`. The road generator builds
//! one (`PlanarGraph<Junction, Road>`), the cell extractor walks its faces.
//!
//! # Ids
//!
//! [`NodeId`] and [`EdgeId`] are indices into slot vectors with **tombstones**: removing a
//! node or edge empties its slot, and slots are never reused, so an id names the same
//! element for the whole life of the graph (and across serde round trips; for bit-exact
//! positions through JSON, serde_json needs its `float_roundtrip` feature). Iteration is in
//! increasing id order, hence deterministic. [`PlanarGraph::node_bound`] and
//! [`PlanarGraph::edge_bound`] give the slot counts for id-indexed side tables.
//!
//! # Rotation system
//!
//! The edges around every node are kept sorted counter-clockwise by the direction in which
//! they leave the node, starting from the positive x axis. The order is decided exactly
//! (half-plane test, then [`orient2d`](crate::predicates::orient2d); no `atan2`), and kept
//! sorted on every change. [`PlanarGraph::next_ccw`] / [`PlanarGraph::next_cw`] step around
//! a node, which is all a face walk or a minimum-cycle-basis extraction needs.
//!
//! # Planarity
//!
//! The raw operations ([`add_node`](PlanarGraph::add_node), [`add_edge`](PlanarGraph::add_edge),
//! [`split_edge`](PlanarGraph::split_edge)) check ids, coordinates, zero length and
//! duplicates, but not crossings: they are for callers who know their input is planar.
//! [`insert_segment`](PlanarGraph::insert_segment) keeps the graph planar whatever the
//! input: it snaps, splits at crossings and merges collinear overlaps (algorithm,
//! guarantees and limitations: [`insert`]).
//! [`check_invariants`](PlanarGraph::check_invariants) verifies everything.
//!
//! The graph keeps spatial indexes ([`SegmentIndex`]) of its nodes and edges:
//! [`nearest_node`](PlanarGraph::nearest_node),
//! [`nearest_edge`](PlanarGraph::nearest_edge), [`edges_crossing`](PlanarGraph::edges_crossing),
//! [`nodes_in_box`](PlanarGraph::nodes_in_box), [`edges_in_box`](PlanarGraph::edges_in_box)
//! and planar insertion use them. They are built from the graph by the first call that
//! needs them and updated on every change from then on; a graph made only of raw
//! changes and never asked a spatial question never builds them, and
//! [`release_spatial_index`](PlanarGraph::release_spatial_index) frees them until the
//! next such call. Answers do not depend on when the indexes were built.
//!
//! # Example
//!
//! ```
//! use polis_geom::{DVec2, graph::PlanarGraph};
//!
//! let mut g: PlanarGraph<(), &str> = PlanarGraph::new();
//! let o = g.add_node(DVec2::new(0.0, 0.0), ())?;
//! let east = g.add_node(DVec2::new(10.0, 0.0), ())?;
//! let north = g.add_node(DVec2::new(0.0, 10.0), ())?;
//! let e1 = g.add_edge(o, east, "high street")?;
//! let e2 = g.add_edge(o, north, "church lane")?;
//! assert_eq!(g.edges_at(o)?, &[e1, e2]); // counter-clockwise from east
//! assert_eq!(g.next_ccw(o, e1)?, e2);
//! g.check_invariants()?;
//! # Ok::<(), polis_geom::GeomError>(())
//! ```
//!
//! Planar insertion:
//!
//! ```
//! use polis_geom::{DVec2, graph::{PlanarGraph, SnapOptions}};
//!
//! let mut g: PlanarGraph<(), u32> = PlanarGraph::new();
//! let opts = SnapOptions::default(); // 1 cm snap
//! g.insert_segment(DVec2::new(0.0, 0.0), DVec2::new(10.0, 10.0), 1, &opts)?;
//! let r = g.insert_segment(DVec2::new(0.0, 10.0), DVec2::new(10.0, 0.0), 2, &opts)?;
//! assert_eq!(r.nodes.len(), 3); // through the new crossing node
//! assert_eq!(g.position(r.nodes[1])?, DVec2::new(5.0, 5.0));
//! assert_eq!((g.node_count(), g.edge_count()), (5, 4));
//! // An end 4 mm from the crossing snaps onto it.
//! let r = g.insert_segment(DVec2::new(5.004, 5.0), DVec2::new(5.0, 20.0), 3, &opts)?;
//! assert_eq!(g.degree(r.nodes[0])?, 5);
//! g.check_invariants()?;
//! # Ok::<(), polis_geom::GeomError>(())
//! ```

pub mod insert;
#[cfg(test)]
mod insert_tests;
mod invariants;
#[cfg(feature = "serde")]
mod serde_impl;

use std::sync::OnceLock;

use glam::DVec2;

use crate::bbox::Aabb2;
use crate::error::{GeomError, validate_point};
use crate::predicates::{AngleStart, ccw_cmp};
use crate::spatial::{GridOptions, SegmentHit, SegmentIndex, SegmentNear, SpatialIndex};

pub use insert::{InsertHints, Insertion, ROUNDING_TOLERANCE, SnapOptions};

/// The id of a node of a [`PlanarGraph`]. Stable: never reused after removal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct NodeId(u32);

/// The id of an edge of a [`PlanarGraph`]. Stable: never reused after removal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct EdgeId(u32);

macro_rules! id_methods {
    ($t:ident) => {
        impl $t {
            /// Wraps a raw index (no check that it names a live element).
            #[inline]
            pub const fn from_raw(raw: u32) -> Self {
                $t(raw)
            }
            /// The raw index.
            #[inline]
            pub const fn raw(self) -> u32 {
                self.0
            }
            /// The index as `usize`, for id-indexed side tables of length
            /// [`PlanarGraph::node_bound`] / [`PlanarGraph::edge_bound`].
            #[inline]
            pub const fn index(self) -> usize {
                self.0 as usize
            }
        }
        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }
    };
}
id_methods!(NodeId);
id_methods!(EdgeId);

#[derive(Debug, Clone)]
pub(crate) struct Node<N> {
    pub(crate) pos: DVec2,
    pub(crate) payload: N,
    /// Incident edges, sorted counter-clockwise by direction from the positive x axis.
    pub(crate) adj: Vec<EdgeId>,
}

#[derive(Debug, Clone)]
pub(crate) struct Edge<E> {
    pub(crate) ends: [NodeId; 2],
    pub(crate) payload: E,
}

/// A planar straight-line graph with node payloads `N` and edge payloads `E`.
///
/// See the [module documentation](self) for ids, the rotation system and planarity.
#[derive(Debug, Clone)]
pub struct PlanarGraph<N, E> {
    pub(crate) nodes: Vec<Option<Node<N>>>,
    pub(crate) edges: Vec<Option<Edge<E>>>,
    node_count: usize,
    edge_count: usize,
    /// The options of the spatial indexes.
    index_options: GridOptions,
    /// The spatial indexes, once built (see the [module docs](self)).
    index: OnceLock<Indexes>,
    /// Every change so far kept the graph planar by construction (see
    /// [`PlanarGraph::is_planar_by_construction`]).
    pub(crate) planar_by_construction: bool,
}

/// The spatial indexes of a [`PlanarGraph`].
#[derive(Debug, Clone)]
pub(crate) struct Indexes {
    /// Every live node as a point.
    pub(crate) nodes: SegmentIndex<NodeId>,
    /// Every live edge as a segment.
    pub(crate) edges: SegmentIndex<EdgeId>,
}

impl<N, E> Default for PlanarGraph<N, E> {
    fn default() -> Self {
        Self::new()
    }
}

fn bad_node(n: NodeId) -> GeomError {
    GeomError::InvalidId {
        what: "node",
        index: n.0,
    }
}

fn bad_edge(e: EdgeId) -> GeomError {
    GeomError::InvalidId {
        what: "edge",
        index: e.0,
    }
}

impl<N, E> PlanarGraph<N, E> {
    /// An empty graph (its spatial indexes use [`GridOptions::default`]).
    pub fn new() -> Self {
        PlanarGraph {
            nodes: Vec::new(),
            edges: Vec::new(),
            node_count: 0,
            edge_count: 0,
            index_options: GridOptions::default(),
            index: OnceLock::new(),
            planar_by_construction: true,
        }
    }

    /// Whether the graph is planar *by construction*: every change since it was created
    /// empty was a planar insertion ([`insert_segment`](Self::insert_segment),
    /// [`insert_point`](Self::insert_point) and their `_with` forms, which guarantee
    /// planarity), a removal, or a payload edit. Any raw [`add_node`](Self::add_node),
    /// [`add_edge`](Self::add_edge) or [`split_edge`](Self::split_edge) call, a
    /// [`GeomError::GraphCorrupt`] from an insertion, and deserialisation clear it for
    /// good (the graph may still be planar, but nothing vouches for it).
    ///
    /// Consumers that would otherwise verify planarity (e.g. polis-cells' check) may skip
    /// that work when this is `true`.
    pub fn is_planar_by_construction(&self) -> bool {
        self.planar_by_construction
    }

    /// An empty graph whose spatial indexes use `options` (a speed knob only).
    ///
    /// # Errors
    /// [`GeomError::InvalidParameter`] for a bad cell size.
    pub fn with_index_options(options: GridOptions) -> Result<Self, GeomError> {
        // Checks the options now; the indexes themselves are built when first needed.
        SegmentIndex::<NodeId>::new(options)?;
        Ok(PlanarGraph {
            index_options: options,
            ..Self::new()
        })
    }

    // ----- spatial queries -------------------------------------------------------------

    /// The spatial indexes, built from the graph if they are not yet.
    fn indexes(&self) -> &Indexes {
        self.index.get_or_init(|| {
            // The options were checked when the graph was made (`with_index_options`).
            let mut ix = Indexes {
                nodes: SegmentIndex::new(self.index_options).unwrap_or_default(),
                edges: SegmentIndex::new(self.index_options).unwrap_or_default(),
            };
            // Every position was checked on entry (`add_node`, `split_edge`), so no
            // insertion below can fail.
            for (n, p, _) in self.nodes() {
                let _ = ix.nodes.insert_point(n, p);
            }
            for (e, a, b, _) in self.edges() {
                if let (Ok(pa), Ok(pb)) = (self.position(a), self.position(b)) {
                    let _ = ix.edges.insert_segment(e, pa, pb);
                }
            }
            ix
        })
    }

    /// The spatial indexes if they are built, for updating them.
    fn indexes_mut(&mut self) -> Option<&mut Indexes> {
        self.index.get_mut()
    }

    /// Frees the spatial indexes. Nothing else changes: the next spatial query or planar
    /// insertion builds them again from the graph, and answers do not depend on when
    /// they were built. For a caller about to make many raw changes
    /// ([`add_node`](Self::add_node), [`add_edge`](Self::add_edge),
    /// [`split_edge`](Self::split_edge), removals) with no spatial question between them:
    /// those changes then skip the indexes' upkeep.
    pub fn release_spatial_index(&mut self) {
        self.index.take();
    }

    /// Whether the spatial indexes are built now (see
    /// [`release_spatial_index`](Self::release_spatial_index)).
    pub fn has_spatial_index(&self) -> bool {
        self.index.get().is_some()
    }

    /// The spatial index of the live nodes (as points), for queries beyond the ones below.
    pub fn node_index(&self) -> &SegmentIndex<NodeId> {
        &self.indexes().nodes
    }

    /// The spatial index of the live edges (as segments).
    pub fn edge_index(&self) -> &SegmentIndex<EdgeId> {
        &self.indexes().edges
    }

    /// The node nearest to `p` within `radius` metres (inclusive; ties by smaller id),
    /// with its distance.
    pub fn nearest_node(&self, p: DVec2, radius: f64) -> Option<(NodeId, f64)> {
        self.node_index()
            .nearest_point(p, radius)
            .map(|n| (n.key, n.distance))
    }

    /// The edge nearest to `p` within `radius` metres (inclusive; ties by smaller id).
    pub fn nearest_edge(&self, p: DVec2, radius: f64) -> Option<SegmentNear<EdgeId>> {
        self.edge_index().nearest_segment(p, radius)
    }

    /// Nodes inside the closed box `b`, in id order.
    pub fn nodes_in_box(&self, b: &Aabb2) -> Vec<NodeId> {
        self.node_index().query_box(b)
    }

    /// Edges sharing a point with the closed box `b`, in id order.
    pub fn edges_in_box(&self, b: &Aabb2) -> Vec<EdgeId> {
        self.edge_index().query_box(b)
    }

    /// Edges that cross, touch or overlap the segment `a–b`, ordered along it (see
    /// [`SpatialIndex::segments_crossing`]).
    pub fn edges_crossing(&self, a: DVec2, b: DVec2) -> Vec<SegmentHit<EdgeId>> {
        self.edge_index().segments_crossing(a, b)
    }

    // ----- sizes and iteration -------------------------------------------------------

    /// Number of live nodes.
    pub fn node_count(&self) -> usize {
        self.node_count
    }

    /// Number of live edges.
    pub fn edge_count(&self) -> usize {
        self.edge_count
    }

    /// One more than the largest node id ever issued: the length of a node-indexed table.
    pub fn node_bound(&self) -> usize {
        self.nodes.len()
    }

    /// One more than the largest edge id ever issued: the length of an edge-indexed table.
    pub fn edge_bound(&self) -> usize {
        self.edges.len()
    }

    /// Whether the graph has no nodes.
    pub fn is_empty(&self) -> bool {
        self.node_count == 0
    }

    /// Whether `n` names a live node.
    pub fn contains_node(&self, n: NodeId) -> bool {
        self.node(n).is_ok()
    }

    /// Whether `e` names a live edge.
    pub fn contains_edge(&self, e: EdgeId) -> bool {
        self.edge(e).is_ok()
    }

    /// Live node ids in increasing order.
    pub fn node_ids(&self) -> impl Iterator<Item = NodeId> + '_ {
        self.nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| n.is_some())
            .map(|(i, _)| NodeId(i as u32))
    }

    /// Live edge ids in increasing order.
    pub fn edge_ids(&self) -> impl Iterator<Item = EdgeId> + '_ {
        self.edges
            .iter()
            .enumerate()
            .filter(|(_, e)| e.is_some())
            .map(|(i, _)| EdgeId(i as u32))
    }

    /// Live nodes in increasing id order: `(id, position, payload)`.
    pub fn nodes(&self) -> impl Iterator<Item = (NodeId, DVec2, &N)> + '_ {
        self.nodes
            .iter()
            .enumerate()
            .filter_map(|(i, n)| n.as_ref().map(|n| (NodeId(i as u32), n.pos, &n.payload)))
    }

    /// Live edges in increasing id order: `(id, first end, second end, payload)`.
    pub fn edges(&self) -> impl Iterator<Item = (EdgeId, NodeId, NodeId, &E)> + '_ {
        self.edges.iter().enumerate().filter_map(|(i, e)| {
            e.as_ref()
                .map(|e| (EdgeId(i as u32), e.ends[0], e.ends[1], &e.payload))
        })
    }

    /// The bounding box of all nodes (empty for an empty graph).
    pub fn bbox(&self) -> Aabb2 {
        Aabb2::from_points(self.nodes().map(|(_, p, _)| p))
    }

    // ----- accessors -----------------------------------------------------------------

    pub(crate) fn node(&self, n: NodeId) -> Result<&Node<N>, GeomError> {
        self.nodes
            .get(n.index())
            .and_then(Option::as_ref)
            .ok_or_else(|| bad_node(n))
    }

    fn node_mut(&mut self, n: NodeId) -> Result<&mut Node<N>, GeomError> {
        self.nodes
            .get_mut(n.index())
            .and_then(Option::as_mut)
            .ok_or_else(|| bad_node(n))
    }

    pub(crate) fn edge(&self, e: EdgeId) -> Result<&Edge<E>, GeomError> {
        self.edges
            .get(e.index())
            .and_then(Option::as_ref)
            .ok_or_else(|| bad_edge(e))
    }

    /// The position of node `n`, in metres.
    pub fn position(&self, n: NodeId) -> Result<DVec2, GeomError> {
        Ok(self.node(n)?.pos)
    }

    /// The payload of node `n`.
    pub fn node_payload(&self, n: NodeId) -> Result<&N, GeomError> {
        Ok(&self.node(n)?.payload)
    }

    /// The payload of node `n`, mutably.
    pub fn node_payload_mut(&mut self, n: NodeId) -> Result<&mut N, GeomError> {
        Ok(&mut self.node_mut(n)?.payload)
    }

    /// The payload of edge `e`.
    pub fn edge_payload(&self, e: EdgeId) -> Result<&E, GeomError> {
        Ok(&self.edge(e)?.payload)
    }

    /// The payload of edge `e`, mutably.
    pub fn edge_payload_mut(&mut self, e: EdgeId) -> Result<&mut E, GeomError> {
        self.edges
            .get_mut(e.index())
            .and_then(Option::as_mut)
            .map(|e| &mut e.payload)
            .ok_or_else(|| bad_edge(e))
    }

    /// The two ends of edge `e`, in the order they were given when it was created.
    pub fn endpoints(&self, e: EdgeId) -> Result<(NodeId, NodeId), GeomError> {
        let ed = self.edge(e)?;
        Ok((ed.ends[0], ed.ends[1]))
    }

    /// The segment of edge `e`: the positions of its two ends, in [`endpoints`](Self::endpoints) order.
    pub fn segment(&self, e: EdgeId) -> Result<(DVec2, DVec2), GeomError> {
        let (a, b) = self.endpoints(e)?;
        Ok((self.position(a)?, self.position(b)?))
    }

    /// Length of edge `e`, in metres.
    pub fn edge_length(&self, e: EdgeId) -> Result<f64, GeomError> {
        let (a, b) = self.segment(e)?;
        Ok(a.distance(b))
    }

    /// The end of edge `e` that is not `n`; an error if `n` is not an end of `e`.
    pub fn other_end(&self, e: EdgeId, n: NodeId) -> Result<NodeId, GeomError> {
        let ed = self.edge(e)?;
        if ed.ends[0] == n {
            Ok(ed.ends[1])
        } else if ed.ends[1] == n {
            Ok(ed.ends[0])
        } else {
            Err(GeomError::InvalidParameter {
                name: "n",
                reason: format!("node {n} is not an end of edge {e}"),
            })
        }
    }

    /// Number of edges at node `n`.
    pub fn degree(&self, n: NodeId) -> Result<usize, GeomError> {
        Ok(self.node(n)?.adj.len())
    }

    /// The edges at node `n`, sorted counter-clockwise by their direction leaving `n`,
    /// starting from the positive x axis (direction `(1, 0)` first, if present).
    pub fn edges_at(&self, n: NodeId) -> Result<&[EdgeId], GeomError> {
        Ok(&self.node(n)?.adj)
    }

    /// The neighbours of `n` as `(edge, neighbour)` pairs, in counter-clockwise order
    /// (see [`edges_at`](Self::edges_at)).
    pub fn neighbors(
        &self,
        n: NodeId,
    ) -> Result<impl ExactSizeIterator<Item = (EdgeId, NodeId)> + '_, GeomError> {
        let node = self.node(n)?;
        Ok(node.adj.iter().map(move |&e| {
            let ends = self.edges[e.index()].as_ref().map_or([n, n], |ed| ed.ends);
            (e, if ends[0] == n { ends[1] } else { ends[0] })
        }))
    }

    fn adj_position(&self, n: NodeId, e: EdgeId) -> Result<(&[EdgeId], usize), GeomError> {
        let adj = self.edges_at(n)?;
        let i = adj
            .iter()
            .position(|&x| x == e)
            .ok_or_else(|| GeomError::InvalidParameter {
                name: "e",
                reason: format!("edge {e} is not incident to node {n}"),
            })?;
        Ok((adj, i))
    }

    /// The edge that follows `e` counter-clockwise around node `n` (`e` itself if it is
    /// the only edge at `n`).
    pub fn next_ccw(&self, n: NodeId, e: EdgeId) -> Result<EdgeId, GeomError> {
        let (adj, i) = self.adj_position(n, e)?;
        Ok(adj[(i + 1) % adj.len()])
    }

    /// The edge that follows `e` clockwise around node `n` (`e` itself if it is the only
    /// edge at `n`).
    pub fn next_cw(&self, n: NodeId, e: EdgeId) -> Result<EdgeId, GeomError> {
        let (adj, i) = self.adj_position(n, e)?;
        Ok(adj[(i + adj.len() - 1) % adj.len()])
    }

    /// The edge joining `a` and `b` (in either direction), if any.
    pub fn find_edge(&self, a: NodeId, b: NodeId) -> Option<EdgeId> {
        let (na, nb) = (self.node(a).ok()?, self.node(b).ok()?);
        let (from, adj) = if na.adj.len() <= nb.adj.len() {
            (a, &na.adj)
        } else {
            (b, &nb.adj)
        };
        let to = if from == a { b } else { a };
        adj.iter().copied().find(|&e| {
            self.edges[e.index()]
                .as_ref()
                .is_some_and(|ed| ed.ends == [from, to] || ed.ends == [to, from])
        })
    }

    // ----- mutation --------------------------------------------------------------------

    /// Adds an isolated node at `pos`.
    ///
    /// # Errors
    /// [`GeomError::NonFinite`] / [`GeomError::OutOfRange`] for a bad position (see
    /// [`MAX_COORDINATE`](crate::MAX_COORDINATE)); [`GeomError::InvalidParameter`] when
    /// all `u32` ids are used up.
    ///
    /// This raw operation does not check that `pos` is free: a node placed on another node
    /// or inside an edge is reported by [`check_invariants`](Self::check_invariants).
    /// Use [`insert_segment`](Self::insert_segment) or [`insert_point`](Self::insert_point)
    /// to snap instead.
    pub fn add_node(&mut self, pos: DVec2, payload: N) -> Result<NodeId, GeomError> {
        validate_point(self.nodes.len(), pos)?;
        let id = next_id(self.nodes.len(), "node")?;
        if let Some(ix) = self.indexes_mut() {
            ix.nodes.insert_point(NodeId(id), pos)?;
        }
        self.planar_by_construction = false;
        self.nodes.push(Some(Node {
            pos,
            payload,
            adj: Vec::new(),
        }));
        self.node_count += 1;
        Ok(NodeId(id))
    }

    /// Adds the straight edge `a–b`.
    ///
    /// # Errors
    /// [`GeomError::InvalidId`] for a dead id; [`GeomError::ZeroLengthEdge`] when
    /// `a == b` or both nodes sit at the same position; [`GeomError::DuplicateEdge`] when
    /// `a` and `b` are already joined.
    ///
    /// This raw operation does not check for crossings; see the [module docs](self).
    pub fn add_edge(&mut self, a: NodeId, b: NodeId, payload: E) -> Result<EdgeId, GeomError> {
        let (pa, pb) = (self.position(a)?, self.position(b)?);
        if a == b || pa == pb {
            return Err(GeomError::ZeroLengthEdge { a: pa, b: pb });
        }
        if let Some(existing) = self.find_edge(a, b) {
            return Err(GeomError::DuplicateEdge {
                a: a.0,
                b: b.0,
                existing: existing.0,
            });
        }
        let id = EdgeId(next_id(self.edges.len(), "edge")?);
        if let Some(ix) = self.indexes_mut() {
            ix.edges.insert_segment(id, pa, pb)?;
        }
        self.planar_by_construction = false;
        self.edges.push(Some(Edge {
            ends: [a, b],
            payload,
        }));
        self.edge_count += 1;
        self.attach(a, id);
        self.attach(b, id);
        Ok(id)
    }

    /// Inserts `e` into the sorted adjacency of `n` (both live, `e` incident to `n`).
    fn attach(&mut self, n: NodeId, e: EdgeId) {
        let Some(Some(node)) = self.nodes.get(n.index()) else {
            return;
        };
        let o = node.pos;
        let key = |x: EdgeId| self.far_position(x, n);
        let Some(pe) = key(e) else { return };
        let pos = node.adj.partition_point(|&x| match key(x) {
            Some(px) => ccw_cmp(o, px, pe, AngleStart::East).then(x.cmp(&e)).is_lt(),
            None => true,
        });
        if let Some(Some(node)) = self.nodes.get_mut(n.index()) {
            node.adj.insert(pos, e);
        }
    }

    /// Removes `e` from the adjacency of `n`, if present.
    fn detach(&mut self, n: NodeId, e: EdgeId) {
        if let Some(Some(node)) = self.nodes.get_mut(n.index()) {
            node.adj.retain(|&x| x != e);
        }
    }

    /// Position of the end of `e` that is not `n`.
    pub(crate) fn far_position(&self, e: EdgeId, n: NodeId) -> Option<DVec2> {
        let ed = self.edges.get(e.index())?.as_ref()?;
        let other = if ed.ends[0] == n {
            ed.ends[1]
        } else {
            ed.ends[0]
        };
        Some(self.nodes.get(other.index())?.as_ref()?.pos)
    }

    /// Removes edge `e` and returns its payload. Its end nodes stay (possibly isolated).
    pub fn remove_edge(&mut self, e: EdgeId) -> Result<E, GeomError> {
        let ends = self.edge(e)?.ends;
        self.detach(ends[0], e);
        self.detach(ends[1], e);
        let ed = self
            .edges
            .get_mut(e.index())
            .and_then(Option::take)
            .ok_or_else(|| bad_edge(e))?;
        if let Some(ix) = self.indexes_mut() {
            ix.edges.remove(e);
        }
        self.edge_count -= 1;
        Ok(ed.payload)
    }

    /// Removes node `n` together with all its edges and returns its payload.
    pub fn remove_node(&mut self, n: NodeId) -> Result<N, GeomError> {
        let adj = self.node(n)?.adj.clone();
        for e in adj {
            self.remove_edge(e)?;
        }
        let node = self
            .nodes
            .get_mut(n.index())
            .and_then(Option::take)
            .ok_or_else(|| bad_node(n))?;
        if let Some(ix) = self.indexes_mut() {
            ix.nodes.remove(n);
        }
        self.node_count -= 1;
        Ok(node.payload)
    }

    /// The connected components: each is the list of its node ids in increasing order,
    /// and components are ordered by their smallest node id. Isolated nodes are
    /// components of their own.
    pub fn connected_components(&self) -> Vec<Vec<NodeId>> {
        let mut seen = vec![false; self.nodes.len()];
        let mut out = Vec::new();
        let mut stack = Vec::new();
        for start in self.node_ids() {
            if seen[start.index()] {
                continue;
            }
            seen[start.index()] = true;
            stack.push(start);
            let mut comp = Vec::new();
            while let Some(n) = stack.pop() {
                comp.push(n);
                if let Ok(nb) = self.neighbors(n) {
                    for (_, m) in nb {
                        if let Some(s) = seen.get_mut(m.index())
                            && !*s
                        {
                            *s = true;
                            stack.push(m);
                        }
                    }
                }
            }
            comp.sort_unstable();
            out.push(comp);
        }
        out
    }
}

impl<N, E: Clone> PlanarGraph<N, E> {
    /// Splits edge `e` at `point` with a new node carrying `node_payload`.
    ///
    /// Edge `e` keeps its id and becomes the piece from its first end to the new node;
    /// the returned new edge (a clone of `e`'s payload) runs from the new node to `e`'s
    /// second end. Returns `(new node, new edge)`.
    ///
    /// `point` should lie on the edge (e.g. from [`crate::predicates`]); the graph stores
    /// it as given and re-sorts the adjacency of both ends.
    ///
    /// # Errors
    /// [`GeomError::InvalidId`] for a dead `e`; [`GeomError::NonFinite`] /
    /// [`GeomError::OutOfRange`] for a bad point; [`GeomError::ZeroLengthEdge`] if `point`
    /// equals an end of `e`; [`GeomError::InvalidParameter`] if `point` does not project
    /// strictly inside the edge.
    pub fn split_edge(
        &mut self,
        e: EdgeId,
        point: DVec2,
        node_payload: N,
    ) -> Result<(NodeId, EdgeId), GeomError> {
        let ed = self.edge(e)?;
        let [a, b] = ed.ends;
        let payload = ed.payload.clone();
        let (pa, pb) = (self.position(a)?, self.position(b)?);
        validate_point(0, point)?;
        if point == pa || point == pb {
            return Err(GeomError::ZeroLengthEdge { a: pa, b: point });
        }
        let d = pb - pa;
        let t = (point - pa).dot(d) / d.length_squared();
        if !(t > 0.0 && t < 1.0) {
            return Err(GeomError::InvalidParameter {
                name: "point",
                reason: format!(
                    "{point} does not lie between the ends {pa} and {pb} of edge {e}; split at a point on the edge"
                ),
            });
        }
        // Check there is room for one more edge id before changing anything.
        next_id(self.edges.len() + 1, "edge")?;
        let new_edge = EdgeId(self.edges.len() as u32);
        self.planar_by_construction = false;
        let m = self.add_node(point, node_payload)?;
        if let Some(ix) = self.indexes_mut() {
            ix.edges.insert_segment(e, pa, point)?;
            ix.edges.insert_segment(new_edge, point, pb)?;
        }
        // Re-wire: e becomes a–m, new edge m–b.
        self.detach(b, e);
        if let Some(Some(ed)) = self.edges.get_mut(e.index()) {
            ed.ends = [a, m];
        }
        self.edges.push(Some(Edge {
            ends: [m, b],
            payload,
        }));
        self.edge_count += 1;
        // The direction from a changes slightly if point is off the line: re-sort at a.
        self.detach(a, e);
        self.attach(a, e);
        self.attach(m, e);
        self.attach(m, new_edge);
        self.attach(b, new_edge);
        Ok((m, new_edge))
    }
}

fn next_id(len: usize, what: &'static str) -> Result<u32, GeomError> {
    u32::try_from(len)
        .ok()
        .filter(|&i| i < u32::MAX)
        .ok_or_else(|| GeomError::InvalidParameter {
            name: what,
            reason: format!("all {} {what} ids are used; build a new graph", u32::MAX),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    /// A star: centre 0 and eight spokes, added in a scrambled order.
    fn star() -> (PlanarGraph<u32, u32>, NodeId, Vec<NodeId>) {
        let mut g = PlanarGraph::new();
        let c = g.add_node(v(0.0, 0.0), 0).unwrap();
        let dirs = [
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
        ];
        let spokes: Vec<NodeId> = dirs
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| g.add_node(v(x, y), i as u32 + 1).unwrap())
            .collect();
        for &i in &[5usize, 2, 7, 0, 3, 6, 1, 4] {
            g.add_edge(spokes[i], c, i as u32).unwrap();
        }
        (g, c, spokes)
    }

    #[test]
    fn adjacency_is_ccw_from_east() {
        let (g, c, spokes) = star();
        let around: Vec<NodeId> = g.neighbors(c).unwrap().map(|(_, m)| m).collect();
        assert_eq!(around, spokes);
        let adj = g.edges_at(c).unwrap().to_vec();
        for i in 0..8 {
            assert_eq!(g.next_ccw(c, adj[i]).unwrap(), adj[(i + 1) % 8]);
            assert_eq!(g.next_cw(c, adj[(i + 1) % 8]).unwrap(), adj[i]);
        }
        assert_eq!(g.degree(c).unwrap(), 8);
        g.check_invariants().unwrap();
    }

    #[test]
    fn removal_keeps_ids_and_order() {
        let (mut g, c, spokes) = star();
        let e = g.find_edge(c, spokes[2]).unwrap();
        assert_eq!(g.remove_edge(e).unwrap(), 2);
        assert!(!g.contains_edge(e));
        assert!(g.find_edge(c, spokes[2]).is_none());
        assert_eq!(g.degree(c).unwrap(), 7);
        assert_eq!(g.remove_node(spokes[5]).unwrap(), 6);
        assert_eq!(g.degree(c).unwrap(), 6);
        assert_eq!(g.node_count(), 8);
        assert_eq!(g.edge_count(), 6);
        assert_eq!(g.node_bound(), 9);
        assert_eq!(g.edge_bound(), 8);
        // Surviving ids still name the same things.
        assert_eq!(*g.node_payload(spokes[7]).unwrap(), 8);
        let around: Vec<NodeId> = g.neighbors(c).unwrap().map(|(_, m)| m).collect();
        let expect: Vec<NodeId> = [0, 1, 3, 4, 6, 7].iter().map(|&i| spokes[i]).collect();
        assert_eq!(around, expect);
        assert!(matches!(
            g.position(spokes[5]),
            Err(GeomError::InvalidId { what: "node", .. })
        ));
        // A new node gets a fresh id, never a reused one.
        let n = g.add_node(v(5.0, 5.0), 99).unwrap();
        assert_eq!(n.index(), 9);
        g.check_invariants().unwrap();
    }

    #[test]
    fn add_edge_refuses_bad_input() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let a = g.add_node(v(0.0, 0.0), ()).unwrap();
        let b = g.add_node(v(1.0, 0.0), ()).unwrap();
        let a2 = g.add_node(v(0.0, 0.0), ()).unwrap();
        assert!(matches!(
            g.add_edge(a, a, ()),
            Err(GeomError::ZeroLengthEdge { .. })
        ));
        assert!(matches!(
            g.add_edge(a, a2, ()),
            Err(GeomError::ZeroLengthEdge { .. })
        ));
        g.add_edge(a, b, ()).unwrap();
        assert!(matches!(
            g.add_edge(b, a, ()),
            Err(GeomError::DuplicateEdge { .. })
        ));
        assert!(matches!(
            g.add_edge(a, NodeId::from_raw(77), ()),
            Err(GeomError::InvalidId { .. })
        ));
        assert!(matches!(
            g.add_node(v(f64::NAN, 0.0), ()),
            Err(GeomError::NonFinite { .. })
        ));
        assert!(matches!(
            g.add_node(v(1e12, 0.0), ()),
            Err(GeomError::OutOfRange { .. })
        ));
        assert_eq!(g.edge_count(), 1);
    }

    #[test]
    fn split_edge_rewires() {
        let mut g: PlanarGraph<u8, &str> = PlanarGraph::new();
        let a = g.add_node(v(0.0, 0.0), 0).unwrap();
        let b = g.add_node(v(4.0, 0.0), 1).unwrap();
        let c = g.add_node(v(2.0, 3.0), 2).unwrap();
        let e = g.add_edge(a, b, "main").unwrap();
        g.add_edge(b, c, "side").unwrap();
        let (m, e2) = g.split_edge(e, v(1.0, 0.0), 7).unwrap();
        assert_eq!(g.endpoints(e).unwrap(), (a, m));
        assert_eq!(g.endpoints(e2).unwrap(), (m, b));
        assert_eq!(*g.edge_payload(e2).unwrap(), "main");
        assert_eq!(g.degree(m).unwrap(), 2);
        assert_eq!(g.find_edge(a, b), None);
        // At b: edges to c (up-left) and to m (west): ccw from east, c first.
        let at_b: Vec<NodeId> = g.neighbors(b).unwrap().map(|(_, x)| x).collect();
        assert_eq!(at_b, vec![c, m]);
        assert!(g.split_edge(e, v(0.0, 0.0), 0).is_err());
        assert!(g.split_edge(e, v(5.0, 0.0), 0).is_err());
        assert!(g.split_edge(e, v(f64::INFINITY, 0.0), 0).is_err());
        g.check_invariants().unwrap();
    }

    #[test]
    fn planar_by_construction_survives_only_planar_changes() {
        let opts = SnapOptions::default();
        let mut g: PlanarGraph<(), u8> = PlanarGraph::new();
        assert!(g.is_planar_by_construction());
        g.insert_segment(v(0.0, 0.0), v(10.0, 10.0), 1, &opts)
            .unwrap();
        let r = g
            .insert_segment(v(0.0, 10.0), v(10.0, 0.0), 2, &opts)
            .unwrap();
        g.insert_point(v(2.0, 2.0), &opts).unwrap();
        g.insert_point(v(20.0, 2.0), &opts).unwrap();
        // Refused input leaves the graph (and the flag) unchanged.
        assert!(
            g.insert_segment(v(0.0, 0.0), v(0.0, 0.0), 3, &opts)
                .is_err()
        );
        g.remove_edge(r.path[0]).unwrap();
        *g.edge_payload_mut(r.path[1]).unwrap() = 7;
        assert!(g.is_planar_by_construction());
        g.check_invariants().unwrap();
        let clone = g.clone();
        assert!(clone.is_planar_by_construction());

        let mut raw = g.clone();
        raw.add_node(v(5.0, 6.0), ()).unwrap();
        assert!(!raw.is_planar_by_construction());
        // Planar insertion afterwards does not restore it.
        raw.insert_segment(v(30.0, 0.0), v(40.0, 0.0), 4, &opts)
            .unwrap();
        assert!(!raw.is_planar_by_construction());

        let mut raw = g.clone();
        let (a, b) = (g.node_ids().next().unwrap(), g.node_ids().last().unwrap());
        if raw.find_edge(a, b).is_none() {
            raw.add_edge(a, b, 0).unwrap();
            assert!(!raw.is_planar_by_construction());
        }
        let mut raw = g.clone();
        let e = raw.edge_ids().next().unwrap();
        let (pa, pb) = raw.segment(e).unwrap();
        raw.split_edge(e, pa.lerp(pb, 0.5), ()).unwrap();
        assert!(!raw.is_planar_by_construction());
    }

    /// The spatial indexes are built by the first question, skipped by raw changes while
    /// released, and give the same answers and insertions whenever they were built.
    #[test]
    fn a_released_index_is_rebuilt_with_the_same_answers() {
        let opts = SnapOptions::default();
        let mut kept: PlanarGraph<(), u8> = PlanarGraph::new();
        assert!(!kept.has_spatial_index());
        kept.insert_segment(v(0.0, 0.0), v(10.0, 10.0), 1, &opts)
            .unwrap();
        assert!(kept.has_spatial_index());
        let mut released = kept.clone();
        released.release_spatial_index();
        assert!(!released.has_spatial_index());
        // The same raw changes to both: a split, an edge, a removal.
        for g in [&mut kept, &mut released] {
            let e = g.edge_ids().next().unwrap();
            let (m, _) = g.split_edge(e, v(4.0, 4.0), ()).unwrap();
            let n = g.add_node(v(4.0, -6.0), ()).unwrap();
            let f = g.add_edge(m, n, 2).unwrap();
            let far = g.add_node(v(30.0, 30.0), ()).unwrap();
            g.remove_node(far).unwrap();
            g.remove_edge(f).unwrap();
            g.add_edge(m, n, 3).unwrap();
        }
        assert!(kept.has_spatial_index() && !released.has_spatial_index());
        assert_eq!(
            kept.nearest_edge(v(5.0, -1.0), 3.0),
            released.nearest_edge(v(5.0, -1.0), 3.0)
        );
        assert!(released.has_spatial_index());
        let b = Aabb2::new(v(-1.0, -7.0), v(6.0, 5.0));
        assert_eq!(kept.nodes_in_box(&b), released.nodes_in_box(&b));
        assert_eq!(kept.edges_in_box(&b), released.edges_in_box(&b));
        // Planar insertion gives the same graph either way.
        released.release_spatial_index();
        let a = kept.insert_segment(v(0.0, 8.0), v(9.0, -3.0), 4, &opts);
        let b = released.insert_segment(v(0.0, 8.0), v(9.0, -3.0), 4, &opts);
        assert_eq!(a.unwrap(), b.unwrap());
        assert_eq!(
            kept.edges()
                .map(|(e, u, w, p)| (e, u, w, *p))
                .collect::<Vec<_>>(),
            released
                .edges()
                .map(|(e, u, w, p)| (e, u, w, *p))
                .collect::<Vec<_>>()
        );
        kept.check_invariants().unwrap();
        released.check_invariants().unwrap();
    }

    #[test]
    fn components_in_id_order() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let n: Vec<NodeId> = (0..6)
            .map(|i| g.add_node(v(f64::from(i), f64::from(i * i)), ()).unwrap())
            .collect();
        g.add_edge(n[4], n[0], ()).unwrap();
        g.add_edge(n[2], n[5], ()).unwrap();
        g.add_edge(n[5], n[3], ()).unwrap();
        let comps = g.connected_components();
        assert_eq!(
            comps,
            vec![vec![n[0], n[4]], vec![n[1]], vec![n[2], n[3], n[5]]]
        );
    }
}
