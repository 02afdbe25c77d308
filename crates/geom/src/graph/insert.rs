//! Planar insertion: [`PlanarGraph::insert_segment`] and [`PlanarGraph::insert_point`].
//!
//! A new segment `p–q` is added so that the graph stays a planar straight-line graph:
//!
//! 1. Each end is *anchored*: to the nearest node within [`SnapOptions::snap_distance`];
//!    else to the nearest edge within that distance (or an edge it lies on exactly),
//!    which is split there (a T-junction); else a new node.
//! 2. The anchored ends are joined by walking from the first to the second. At each step
//!    the first *event* along the straight line from the current node to the current
//!    target is handled, in order of position (ties: following an edge, then a node, then
//!    a crossing, then by id):
//!    * an existing edge overlapping the line from the current node (collinear overlap)
//!      is *followed*: reused, not duplicated;
//!    * an existing node on the line (or within rounding of it) is routed through (it
//!      becomes an intermediate target); so is a node within the snap distance of the
//!      line and of the caller's segment, if the straight detour to it meets no edge;
//!    * an existing edge crossing the line is split at the crossing point, which becomes
//!      an intermediate target (if an end of that edge lies within the snap distance of
//!      the crossing and the detour to it meets no edge, that end is used instead);
//!    * with no event left, a straight edge joins the current node to the target.
//!
//! All decisions (crossing, touching, overlap, on-segment) use exact predicates; crossing
//! points are computed in floating point afterwards, so a split edge may bend by a few
//! units in the last place. Edges passing within that rounding distance
//! ([`ROUNDING_TOLERANCE`]) of a new crossing node are bent through it, so several
//! segments through one point share one node; no node is created within that distance of
//! another (the edge is bent through the existing node), and every piece a split creates is
//! bent through any node it passes within that distance of (but a node already joined to
//! one of the piece's ends: at that scale the bend would only give the piece back; an edge
//! the walk would follow past its target, within rounding of it, is bent through the
//! target instead). A bend moves an edge by up to
//! that distance, so its two legs are inserted by this same walk (splitting any edge the
//! move takes them across); all edges passing within rounding of the node are bent together.
//! Every created or split edge is checked against the edge index before the call returns
//! (the walk's last edge by the very query that found its leg free, when nothing changed
//! after it).
//!
//! # Guarantees
//! * After every successful call the graph is planar in the sense of
//!   [`PlanarGraph::check_invariants`] (property-tested on integer-grid inputs full of
//!   collinear overlaps, shared ends and T-junctions, and on random floats).
//! * Every crossing of the new segment with an existing edge becomes a node; overlapped
//!   edges are reused, never duplicated.
//! * Deterministic: the result depends only on the graph and the arguments.
//!
//! # Limitations
//! * Snapping moves geometry by up to [`SnapOptions::snap_distance`]: the new segment's
//!   ends move onto nearby nodes or edges and it bends through nodes near it, but every
//!   node of its route lies within the snap distance of the segment as given (so does
//!   every point of the route), however many nodes it passes (property-tested on chains
//!   of collinear edges). Existing nodes never move. A crossing of two inserted segments
//!   can move by about `snap / sin(angle)` along them.
//! * The result depends on insertion order where snapping is involved (which node was
//!   there first).
//! * On [`GeomError::GraphCorrupt`] (a graph that was not planar before the call) the
//!   graph may be left partly modified.
//! * Cost per segment: a handful of index queries plus one per crossing; nodes within the
//!   snap distance of a long segment are found through its bounding box. A caller that
//!   knows the start node passes it in [`InsertHints`] to save the first end's search.
//!   An *uncontested* segment (nothing within twice the snap distance of it but nodes
//!   exactly at its ends and their edges, which stay that far from it; see
//!   `insert_uncontested`) is added after two box queries, without the walk, with the
//!   walk's result (ids included; property-tested against the walk alone). Most streets
//!   inserted into a city's union graph are (at least 88 % on the `citygen` preset).

use glam::DVec2;

use super::{EdgeId, NodeId, PlanarGraph};
use crate::error::{GeomError, validate_point};
use crate::inline_vec::InlineVec;
use crate::predicates::{SegmentIntersection, closest_point_on_segment, point_on_segment};
use crate::spatial::{SegmentHit, Shape, SpatialIndex, classify_hit};

/// Relative size of floating-point rounding in computed points (crossings, projections):
/// at a point `p`, distances up to `ROUNDING_TOLERANCE · max(1, |p.x|, |p.y|)` metres are
/// treated as zero by planar insertion, whatever [`SnapOptions::snap_distance`] says.
///
/// A crossing point is rounded to the nearest `f64`, so it lies a few units in the last
/// place off both lines; a third line through the same exact point then misses the
/// rounded node by about that much. Such near-misses are merged, so that three or more
/// segments through one point give one node. `1e-12` is about 5,000 ulps: a 10 nm margin
/// at 10 km from the origin.
pub const ROUNDING_TOLERANCE: f64 = 1e-12;

/// How many bends may nest inside one another (a bend's walk meeting a crossing that
/// bends another edge, …) before insertion reports [`GeomError::GraphCorrupt`].
const MAX_BEND_DEPTH: usize = 16;

/// Whether a planar insertion that returned `result` left a planar graph planar: it did
/// unless it reports a corrupt graph (the other errors leave the graph unchanged).
fn keeps_planarity<T>(result: &Result<T, GeomError>) -> bool {
    !matches!(result, Err(GeomError::GraphCorrupt(_)))
}

/// The rounding tolerance at `p`, in metres (see [`ROUNDING_TOLERANCE`]).
fn rounding_eps(p: DVec2) -> f64 {
    ROUNDING_TOLERANCE * p.abs().max_element().max(1.0)
}

/// Tolerances of planar insertion ([`PlanarGraph::insert_segment`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct SnapOptions {
    /// Distance, in metres, within which a segment end snaps to an existing node (first)
    /// or onto an existing edge (splitting it); existing nodes within this distance of a
    /// new segment are routed through where the detour to them crosses no edge; and a
    /// segment whose snapped ends are this close or
    /// closer is refused as zero-length. `0` snaps only coincidences up to rounding (see
    /// [`ROUNDING_TOLERANCE`]). Must be finite and non-negative. Default: 0.01 m.
    pub snap_distance: f64,
}

impl Default for SnapOptions {
    fn default() -> Self {
        SnapOptions {
            snap_distance: 0.01,
        }
    }
}

impl SnapOptions {
    fn validate(&self) -> Result<(), GeomError> {
        let d = self.snap_distance;
        if d.is_finite() && d >= 0.0 {
            Ok(())
        } else {
            Err(GeomError::InvalidParameter {
                name: "snap_distance",
                reason: format!("{d} m; use a finite distance of at least 0"),
            })
        }
    }
}

/// What [`PlanarGraph::insert_segment`] did.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Insertion {
    /// The nodes the new segment runs through, from the (snapped) first end to the last.
    pub nodes: Vec<NodeId>,
    /// The edges from `nodes[i]` to `nodes[i + 1]`: created by this call or existing edges
    /// the segment overlaps.
    pub path: Vec<EdgeId>,
    /// The edges this call created for the segment (a subset of `path`, in path order).
    pub created: Vec<EdgeId>,
    /// Existing edges split by this call, as `(edge, new piece)`: see
    /// [`PlanarGraph::split_edge`]. The pieces carry clones of the edge's payload. (In the
    /// rare case that a rounded crossing point lands within rounding of an existing node,
    /// or a split piece passes within rounding of one, the edge is replaced by new edges
    /// through that node, each listed as `(removed edge, new edge)`.)
    pub split: Vec<(EdgeId, EdgeId)>,
}

/// Answers a caller may already know about a segment it inserts
/// ([`PlanarGraph::insert_segment_hinted`]). Each is checked exactly before it is used
/// and ignored when it does not hold, so hints change the cost of an insertion, never its
/// result.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct InsertHints {
    /// The node the segment starts at: taken as the first end's anchor, without a search,
    /// when the node sits exactly at the first end and the graph is planar by construction
    /// ([`PlanarGraph::is_planar_by_construction`]: its planar insertions never put two
    /// nodes at one position, so the node is the nearest one there).
    pub start: Option<NodeId>,
}

/// Where a point lands after snapping.
#[derive(Debug, Clone, Copy)]
enum Anchor {
    Node(NodeId),
    OnEdge(EdgeId, DVec2),
    Free(DVec2),
}

/// The next thing in the way of a straight connection.
#[derive(Debug, Clone, Copy)]
enum Event {
    /// Reuse an existing edge leaving the current node along the line, to its other end.
    Follow(EdgeId, NodeId),
    /// Route through a node near the line.
    Node(NodeId),
    /// Split an edge crossing the line at this point.
    Cross(EdgeId, DVec2),
}

impl Event {
    fn rank(&self) -> u8 {
        match self {
            Event::Follow(..) => 0,
            Event::Node(_) => 1,
            Event::Cross(..) => 2,
        }
    }
    fn id(&self) -> u32 {
        match *self {
            Event::Follow(e, _) | Event::Cross(e, _) => e.raw(),
            Event::Node(n) => n.raw(),
        }
    }
}

/// The walk's stack of targets ([`PlanarGraph::connect`]): almost always one or two
/// nodes, kept inline (no allocation).
type Targets = InlineVec<NodeId, 4>;

impl<N, E: Clone> PlanarGraph<N, E> {
    /// Inserts the segment `p–q` keeping the graph planar; new nodes get `N::default()`.
    /// See [`insert_segment_with`](Self::insert_segment_with).
    pub fn insert_segment(
        &mut self,
        p: DVec2,
        q: DVec2,
        payload: E,
        options: &SnapOptions,
    ) -> Result<Insertion, GeomError>
    where
        N: Default,
    {
        self.insert_segment_with(p, q, payload, options, |_| N::default())
    }

    /// Inserts the segment `p–q` keeping the graph planar: snaps its ends to nodes or
    /// edges within [`SnapOptions::snap_distance`], splits existing edges where it crosses
    /// them, reuses existing edges it overlaps, and routes through nodes lying within the
    /// snap distance of it where the detour crosses no edge (see the [module docs](self)). New nodes get
    /// `make_node(position)`; new edges get clones of `payload`.
    ///
    /// # Errors
    /// [`GeomError::NonFinite`] / [`GeomError::OutOfRange`] for bad coordinates,
    /// [`GeomError::InvalidParameter`] for bad options, [`GeomError::ZeroLengthEdge`] when
    /// the snapped ends are within the snap distance of each other; the graph is unchanged
    /// in these cases. [`GeomError::GraphCorrupt`] if the graph was not planar to begin
    /// with (or on an internal failure); the graph may then be partly modified.
    pub fn insert_segment_with(
        &mut self,
        p: DVec2,
        q: DVec2,
        payload: E,
        options: &SnapOptions,
        make_node: impl FnMut(DVec2) -> N,
    ) -> Result<Insertion, GeomError> {
        self.insert_segment_hinted(p, q, payload, options, &InsertHints::default(), make_node)
    }

    /// [`insert_segment_with`](Self::insert_segment_with) given what the caller knows
    /// about the segment ([`InsertHints`]): the same result, with less searching where
    /// the hints hold.
    ///
    /// # Errors
    /// As [`insert_segment_with`](Self::insert_segment_with).
    pub fn insert_segment_hinted(
        &mut self,
        p: DVec2,
        q: DVec2,
        payload: E,
        options: &SnapOptions,
        hints: &InsertHints,
        make_node: impl FnMut(DVec2) -> N,
    ) -> Result<Insertion, GeomError> {
        self.insert_segment_marked(p, q, payload, options, hints, true, make_node)
    }

    /// [`insert_segment_unmarked`](Self::insert_segment_unmarked) with the bookkeeping of
    /// [`is_planar_by_construction`](Self::is_planar_by_construction). The tests call it
    /// without the fast path (`fast: false`, the walk alone) to show that the fast path
    /// changes nothing.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn insert_segment_marked(
        &mut self,
        p: DVec2,
        q: DVec2,
        payload: E,
        options: &SnapOptions,
        hints: &InsertHints,
        fast: bool,
        make_node: impl FnMut(DVec2) -> N,
    ) -> Result<Insertion, GeomError> {
        let planar = self.planar_by_construction;
        let result = self.insert_segment_unmarked(p, q, payload, options, hints, fast, make_node);
        self.planar_by_construction = planar && keeps_planarity(&result);
        result
    }

    /// [`insert_segment_with`](Self::insert_segment_with) without the bookkeeping of
    /// [`is_planar_by_construction`](Self::is_planar_by_construction); `fast` tries
    /// [`insert_uncontested`](Self::insert_uncontested) first.
    #[allow(clippy::too_many_arguments)]
    fn insert_segment_unmarked(
        &mut self,
        p: DVec2,
        q: DVec2,
        payload: E,
        options: &SnapOptions,
        hints: &InsertHints,
        fast: bool,
        mut make_node: impl FnMut(DVec2) -> N,
    ) -> Result<Insertion, GeomError> {
        validate_point(0, p)?;
        validate_point(1, q)?;
        options.validate()?;
        let snap = options.snap_distance;
        let scale = p.abs().max(q.abs()).max_element().max(1.0);
        let snap = snap.max(ROUNDING_TOLERANCE * scale);
        // A node exactly at p is the nearest node to p (the only one there, in a graph
        // planar by construction): `anchor` would find it first.
        if fast && let Some(out) = self.insert_uncontested(p, q, &payload, snap, &mut make_node)? {
            return Ok(out);
        }
        let ap = match hints.start {
            Some(n) if self.planar_by_construction && self.position(n).is_ok_and(|x| x == p) => {
                Anchor::Node(n)
            }
            _ => self.anchor(p, snap),
        };
        let aq = self.anchor(q, snap);
        let (pp, pq) = (self.anchor_position(ap)?, self.anchor_position(aq)?);
        let same_node = matches!((ap, aq), (Anchor::Node(x), Anchor::Node(y)) if x == y);
        if same_node || pp == pq || pp.distance(pq) <= snap || q.distance(pp) <= snap {
            return Err(GeomError::ZeroLengthEdge { a: pp, b: pq });
        }
        let mut out = Insertion::default();
        let a = self.realize(ap, &mut make_node, &mut out)?;
        // Re-anchor q: realising p may have split the edge q snaps to. (A node anchor
        // realises to itself and changes nothing: q's anchor stands.)
        let b = if matches!(ap, Anchor::Node(_)) {
            aq
        } else {
            self.anchor(q, snap)
        };
        let b = self.realize(b, &mut make_node, &mut out)?;
        if a == b {
            return Err(GeomError::ZeroLengthEdge { a: pp, b: pq });
        }
        let checked = self.connect(a, b, (p, q), &payload, snap, &mut make_node, &mut out, 0)?;
        // The created edges, then both pieces of each split that still exist (no list
        // built: one allocation less per segment). The walk's last edge is left out when
        // the walk already found it clean (see `connect`): nothing has changed since.
        let split = out.split.iter().flat_map(|&(e, piece)| [e, piece]);
        let touched = out
            .created
            .iter()
            .copied()
            .filter(|&e| Some(e) != checked)
            .chain(split.filter(|&x| self.contains_edge(x)));
        self.check_local(touched)?;
        Ok(out)
    }

    /// The insertion of `p–q` when nothing contests it, found with two box queries
    /// instead of the walk's dozen; `None` (graph untouched) when that cannot be shown.
    ///
    /// Uncontested means: every node within `2 · snap` of the segment sits exactly at `p`
    /// or `q`; every edge within that distance ends at such a node, and then its far end
    /// and the segment's other end are each farther than `2 · snap` from the other
    /// segment (so it neither overlaps the segment nor lies near its other end); the ends
    /// are more than `2 · snap` apart and not already joined. The walk (`anchor`,
    /// `realize`, `connect`) then anchors each end to the node exactly there or to a new
    /// node (nothing else is within `snap` of it, not even within rounding), finds no
    /// event on the way (no node or edge within `snap` of the line but those ending at
    /// its ends, which meet it only there) and adds one edge: exactly what this does, in
    /// the same order (new node at `p`, new node at `q`, the edge), so ids, positions
    /// and payloads are the walk's. The factor 2 keeps the floating-point distances here
    /// (a few ulps off) far from the walk's exact and rounded decisions at `snap`.
    pub(crate) fn insert_uncontested(
        &mut self,
        p: DVec2,
        q: DVec2,
        payload: &E,
        snap: f64,
        make_node: &mut impl FnMut(DVec2) -> N,
    ) -> Result<Option<Insertion>, GeomError> {
        let r = 2.0 * snap;
        if p.distance(q) <= r {
            return Ok(None);
        }
        let bx = crate::Aabb2::new(p, q).expanded(r);
        let near =
            |x: DVec2, a: DVec2, b: DVec2| crate::predicates::distance_to_segment(x, a, b) <= r;
        // The nodes at the ends, if any; any other node near the segment contests it.
        let (mut at_p, mut at_q) = (None, None);
        let mut contested = false;
        self.node_index().for_each_candidate(&bx, |n, shape| {
            let Shape::Point(x) = *shape else { return };
            if contested {
                return;
            }
            if x == p && at_p.is_none() {
                at_p = Some(n);
            } else if x == q && at_q.is_none() {
                at_q = Some(n);
            } else if near(x, p, q) {
                contested = true;
            }
        });
        if contested {
            return Ok(None);
        }
        let ends = |e: EdgeId| self.endpoints(e).ok();
        self.edge_index().for_each_candidate(&bx, |e, shape| {
            let Shape::Segment(s0, s1) = *shape else {
                return;
            };
            if contested {
                return;
            }
            let Some((a, b)) = ends(e) else {
                contested = true;
                return;
            };
            let at = |x: Option<NodeId>| x.is_some_and(|x| x == a || x == b);
            contested = match (at(at_p), at(at_q)) {
                // Already joined: the walk would reuse the edge.
                (true, true) => true,
                // An edge at `p`: its far end away from the segment, `q` away from it.
                (true, false) => {
                    let far = if s0 == p { s1 } else { s0 };
                    near(far, p, q) || near(q, s0, s1)
                }
                (false, true) => {
                    let far = if s0 == q { s1 } else { s0 };
                    near(far, p, q) || near(p, s0, s1)
                }
                // Any other edge: away from the segment (disjoint, and every end of
                // either farther than `r` from the other, which for two disjoint
                // segments is their distance).
                (false, false) => {
                    !matches!(
                        crate::predicates::segment_intersection(p, q, s0, s1),
                        SegmentIntersection::Disjoint
                    ) || near(s0, p, q)
                        || near(s1, p, q)
                        || near(p, s0, s1)
                        || near(q, s0, s1)
                }
            };
        });
        if contested {
            return Ok(None);
        }
        let a = match at_p {
            Some(n) => n,
            None => self.add_node(p, make_node(p))?,
        };
        let b = match at_q {
            Some(n) => n,
            None => self.add_node(q, make_node(q))?,
        };
        let e = self.add_edge(a, b, payload.clone())?;
        Ok(Some(Insertion {
            nodes: vec![a, b],
            path: vec![e],
            created: vec![e],
            split: Vec::new(),
        }))
    }

    /// The node at `p` after snapping (to a node, else onto an edge, splitting it, else a
    /// new node with `N::default()`). Returns the node and the split, if any.
    pub fn insert_point(
        &mut self,
        p: DVec2,
        options: &SnapOptions,
    ) -> Result<(NodeId, Option<(EdgeId, EdgeId)>), GeomError>
    where
        N: Default,
    {
        self.insert_point_with(p, options, |_| N::default())
    }

    /// [`insert_point`](Self::insert_point) with new-node payloads from `make_node`.
    pub fn insert_point_with(
        &mut self,
        p: DVec2,
        options: &SnapOptions,
        mut make_node: impl FnMut(DVec2) -> N,
    ) -> Result<(NodeId, Option<(EdgeId, EdgeId)>), GeomError> {
        validate_point(0, p)?;
        options.validate()?;
        let planar = self.planar_by_construction;
        let mut out = Insertion::default();
        let snap = options.snap_distance.max(rounding_eps(p));
        let anchor = self.anchor(p, snap);
        let result = self.realize(anchor, &mut make_node, &mut out);
        // A split bends the edge by rounding: vouch for planarity only if the pieces meet
        // nothing (the same check as insert_segment's, without changing the result).
        let pieces_ok = out
            .split
            .iter()
            .all(|&(e, piece)| self.check_local([e, piece]).is_ok());
        self.planar_by_construction = planar && keeps_planarity(&result) && pieces_ok;
        Ok((result?, out.split.first().copied()))
    }

    fn anchor(&self, p: DVec2, snap: f64) -> Anchor {
        if let Some((n, _)) = self.nearest_node(p, snap) {
            return Anchor::Node(n);
        }
        // Exactly on an edge (exact test, independent of the distance rounding).
        let on: Option<EdgeId> = self
            .edge_index()
            .first_crossing(p, p, |_| true)
            .map(|h| h.key);
        if let Some(e) = on {
            return self.anchor_on_edge(e, p);
        }
        if let Some(near) = self.nearest_edge(p, snap) {
            return self.anchor_on_edge(near.key, near.closest);
        }
        Anchor::Free(p)
    }

    /// Anchor at `c` on edge `e`, or at an end of `e` if `c` coincides with it.
    fn anchor_on_edge(&self, e: EdgeId, c: DVec2) -> Anchor {
        match self.endpoints(e) {
            Ok((a, b)) => {
                if self.position(a).is_ok_and(|pa| pa == c) {
                    Anchor::Node(a)
                } else if self.position(b).is_ok_and(|pb| pb == c) {
                    Anchor::Node(b)
                } else {
                    Anchor::OnEdge(e, c)
                }
            }
            Err(_) => Anchor::Free(c),
        }
    }

    fn anchor_position(&self, a: Anchor) -> Result<DVec2, GeomError> {
        match a {
            Anchor::Node(n) => self.position(n),
            Anchor::OnEdge(_, c) | Anchor::Free(c) => Ok(c),
        }
    }

    fn realize(
        &mut self,
        a: Anchor,
        make_node: &mut impl FnMut(DVec2) -> N,
        out: &mut Insertion,
    ) -> Result<NodeId, GeomError> {
        match a {
            Anchor::Node(n) => Ok(n),
            Anchor::Free(p) => self.add_node(p, make_node(p)),
            Anchor::OnEdge(e, c) => self.split_or_end(e, c, make_node, out, 0),
        }
    }

    /// Splits `e` at `c`; if `c` cannot split it (it rounds onto or beyond an end), the
    /// end of `e` nearer to `c`.
    ///
    /// No node is ever created within rounding ([`ROUNDING_TOLERANCE`]) of an existing
    /// one: two nodes a few ulps apart have fans of edges that cross each other. If a
    /// node lies within rounding of `c` (an end of `e`, an end of the current leg, or any
    /// other node the computed point landed beside), `e` is bent through that node
    /// instead and the node is returned.
    fn split_or_end(
        &mut self,
        e: EdgeId,
        c: DVec2,
        make_node: &mut impl FnMut(DVec2) -> N,
        out: &mut Insertion,
        depth: usize,
    ) -> Result<NodeId, GeomError> {
        let (a, b) = self.endpoints(e)?;
        let (pa, pb) = (self.position(a)?, self.position(b)?);
        if let Some((n, _)) = self.nearest_node(c, rounding_eps(c)) {
            if n != a && n != b {
                self.reroute_through(e, n, make_node, out, depth)?;
            }
            return Ok(n);
        }
        let d = pb - pa;
        let t = (c - pa).dot(d) / d.length_squared();
        if c != pa && c != pb && t > 0.0 && t < 1.0 {
            let (m, piece) = self.split_edge(e, c, make_node(c))?;
            out.split.push((e, piece));
            // The pieces first: a walk of a bend that `absorb_edges_near` makes must not
            // meet a piece that still runs through a node (it would follow it past).
            self.settle(&[e, piece], make_node, out, depth)?;
            self.absorb_edges_near(m, make_node, out, depth)?;
            Ok(m)
        } else if c.distance_squared(pa) <= c.distance_squared(pb) {
            Ok(a)
        } else {
            Ok(b)
        }
    }

    /// Joins node `from` to node `to` by the walk described in the module docs; `line` is
    /// the segment as the caller gave it, which every node of the route stays within the
    /// snap distance of.
    ///
    /// Returns the edge the walk created last if it was its last step and the query that
    /// found its leg free already showed it meets no edge away from its ends: exactly
    /// what [`check_local`](Self::check_local) would find for it, since the graph has not
    /// changed since but for the edge itself.
    #[allow(clippy::too_many_arguments)]
    fn connect(
        &mut self,
        from: NodeId,
        to: NodeId,
        line: (DVec2, DVec2),
        payload: &E,
        snap: f64,
        make_node: &mut impl FnMut(DVec2) -> N,
        out: &mut Insertion,
        depth: usize,
    ) -> Result<Option<EdgeId>, GeomError> {
        out.nodes.push(from);
        let mut checked = None;
        let mut cur = from;
        let mut targets = Targets::new(to);
        targets.push(to);
        let limit = 64 + 8 * (self.node_count() + self.edge_count());
        let mut steps = 0usize;
        while let Some(target) = targets.last() {
            steps += 1;
            if steps > limit {
                return Err(GeomError::GraphCorrupt(format!(
                    "planar insertion from node {from} to node {to} did not converge; check_invariants() may tell why"
                )));
            }
            if cur == target {
                targets.pop();
                continue;
            }
            checked = None;
            let (event, clean) =
                self.next_event(cur, target, line, snap, &out.nodes, targets.as_slice())?;
            match event {
                None => {
                    let e = match self.find_edge(cur, target) {
                        Some(e) => e,
                        None => {
                            let e = self.add_edge(cur, target, payload.clone())?;
                            out.created.push(e);
                            if clean {
                                checked = Some(e);
                            }
                            e
                        }
                    };
                    out.path.push(e);
                    out.nodes.push(target);
                    cur = target;
                    targets.pop();
                }
                Some(Event::Follow(e, x)) => {
                    // An edge bent by rounding may pass through a node (the target, say)
                    // until it is settled; following it would go past that node.
                    self.settle(&[e], make_node, out, depth)?;
                    if !self.contains_edge(e) {
                        continue;
                    }
                    // The target inside the edge (a split made it on the edge, within
                    // rounding, and joined it to the edge's far end by a piece that
                    // `settle` leaves alone): the edge is bent through the target first.
                    // Followed, it would pass the target, and the walk from its far end
                    // would follow it back past the target, for ever.
                    if x != target && self.passes_within_rounding(e, target)? {
                        self.reroute_through(e, target, make_node, out, depth)?;
                        continue;
                    }
                    out.path.push(e);
                    out.nodes.push(x);
                    cur = x;
                }
                Some(Event::Node(x)) => targets.push(x),
                Some(Event::Cross(e, c)) => {
                    let x = self.split_or_end(e, c, make_node, out, depth)?;
                    targets.push(x);
                }
            }
        }
        Ok(checked)
    }

    /// The first event on the straight line from `cur` to `target`, if any. Nodes already
    /// on the path (`visited`) or waiting as targets (`pending`) are never routed through
    /// again, which rules out cycles.
    ///
    /// A node near the line is routed through only if it is also within the snap distance
    /// of the caller's segment `line`. Measured from the current leg alone, each detour
    /// would let the next one go a snap distance further: a slanted segment near a row of
    /// collinear nodes used to be pulled from node to node along the row. And a node
    /// merely within the snap distance (not within rounding) is a detour taken only where
    /// the straight detour meets no edge ([`sees`](Self::sees)).
    ///
    /// Also returns whether the leg `cur–target` meets every edge only at `cur` or
    /// `target` by an edge ending there ([`meets_elsewhere`](Self::meets_elsewhere)
    /// finds nothing): the same query, read the same way.
    fn next_event(
        &self,
        cur: NodeId,
        target: NodeId,
        line: (DVec2, DVec2),
        snap: f64,
        visited: &[NodeId],
        pending: &[NodeId],
    ) -> Result<(Option<Event>, bool), GeomError> {
        let fresh =
            |n: NodeId| n != cur && n != target && !visited.contains(&n) && !pending.contains(&n);
        let (pc, pt) = (self.position(cur)?, self.position(target)?);
        let snap = snap.max(rounding_eps(pc.abs().max(pt.abs())));
        let near_line =
            |x: DVec2| crate::predicates::distance_to_segment(x, line.0, line.1) <= snap;
        let mut best: Option<(f64, Event)> = None;
        let mut offer = |t: f64, ev: Event| {
            let better = match best {
                None => true,
                Some((bt, bev)) => (t, ev.rank(), ev.id()) < (bt, bev.rank(), bev.id()),
            };
            if better {
                best = Some((t, ev));
            }
        };
        // Nodes within the snap distance of the open segment.
        // Candidates come in no particular order: `offer` keeps the least event by
        // (t, rank, id), so the answer does not depend on it.
        let bx = crate::Aabb2::new(pc, pt).expanded(snap);
        self.node_index().for_each_candidate(&bx, |n, shape| {
            let Shape::Point(pn) = *shape else { return };
            if !bx.contains(pn) || !fresh(n) {
                return;
            }
            let (closest, t) = closest_point_on_segment(pn, pc, pt);
            let on = point_on_segment(pn, pc, pt);
            // Within rounding of the leg, a node is on it whatever the snap bound says.
            let touching = closest.distance(pn) <= rounding_eps(pn);
            if !(t > 0.0 && t < 1.0) {
                return;
            }
            // A node merely within the snap distance is a detour, taken only where the
            // detour meets no edge: in a corridor of nearly parallel edges, detours to
            // every node within the snap distance zigzag across the corridor, and each
            // zig splits the edges it crosses into more nodes within the snap distance
            // of the next segment — growth without bound over a few insertions.
            if on
                || touching
                || (closest.distance(pn) <= snap && near_line(pn) && self.sees((cur, pc), (n, pn)))
            {
                offer(t, Event::Node(n));
            }
        });
        // Edges meeting the segment (in no particular order either; a corrupt graph is
        // reported whichever offending edge comes first).
        let mut failure: Option<GeomError> = None;
        let mut clean = true;
        let mut visit = |hit: SegmentHit<EdgeId>| -> Result<(), GeomError> {
            match hit.kind {
                SegmentIntersection::Crossing { point, .. } => {
                    let (a, b) = self.endpoints(hit.key)?;
                    let (pa, pb) = (self.position(a)?, self.position(b)?);
                    // An end of the crossed edge close to the crossing: go through it.
                    // Within rounding of the crossing, the end is where the edges meet
                    // (the leg passes the end on the wrong side by a few ulps), whatever
                    // the snap bound says: a node split off beside it would make a
                    // zero-length edge that other edges cross.
                    let (da, db) = (point.distance(pa), point.distance(pb));
                    if da.min(db) <= snap {
                        let (n, pn) = if da <= db { (a, pa) } else { (b, pb) };
                        let coincident = da.min(db) <= rounding_eps(pn);
                        if fresh(n)
                            && (coincident || (near_line(pn) && self.sees((cur, pc), (n, pn))))
                        {
                            offer(hit.t, Event::Node(n));
                            return Ok(());
                        }
                    }
                    offer(hit.t, Event::Cross(hit.key, point));
                }
                SegmentIntersection::Overlap { start, .. } if start == pc => {
                    let (a, b) = self.endpoints(hit.key)?;
                    if a != cur && b != cur {
                        return Err(GeomError::GraphCorrupt(format!(
                            "node {cur} lies inside edge {}; the graph was not planar",
                            hit.key
                        )));
                    }
                    let x = if a == cur { b } else { a };
                    offer(0.0, Event::Follow(hit.key, x));
                }
                // Touching points and other overlaps start at nodes on the line: those
                // are node events.
                _ => {}
            }
            Ok(())
        };
        self.edge_index()
            .for_each_candidate_along(pc, pt, |key, s| {
                if failure.is_none()
                    && let Shape::Segment(s0, s1) = *s
                    && let Some(hit) = classify_hit(key, pc, pt, s0, s1)
                {
                    clean = clean && self.meets_at_ends(&hit, (cur, pc), (target, pt));
                    if let Err(e) = visit(hit) {
                        failure = Some(e);
                    }
                }
            });
        if let Some(e) = failure {
            return Err(e);
        }
        Ok((best.map(|(_, ev)| ev), clean))
    }

    /// Bends every edge passing within rounding distance of the new node `m` (but not
    /// ending at it) through `m`, so that a computed point on several lines becomes one
    /// node of all of them.
    fn absorb_edges_near(
        &mut self,
        m: NodeId,
        make_node: &mut impl FnMut(DVec2) -> N,
        out: &mut Insertion,
        depth: usize,
    ) -> Result<(), GeomError> {
        let near = self.edges_passing_near(m, None)?;
        self.reroute_through_all(&near, m, make_node, out, depth)
    }

    /// The edges passing within rounding distance of node `m` without ending at it or
    /// within rounding of it, in index order, plus `also` (first) if given.
    fn edges_passing_near(
        &self,
        m: NodeId,
        also: Option<EdgeId>,
    ) -> Result<Vec<EdgeId>, GeomError> {
        let pm = self.position(m)?;
        let eps = rounding_eps(pm);
        let mut near: Vec<EdgeId> = also.into_iter().collect();
        for hit in self.edge_index().segments_within(pm, eps) {
            if near.contains(&hit.key) || !self.contains_edge(hit.key) {
                continue;
            }
            let (a, b) = self.endpoints(hit.key)?;
            if a == m || b == m {
                continue;
            }
            let (pa, pb) = (self.position(a)?, self.position(b)?);
            if pa.distance(pm) <= eps || pb.distance(pm) <= eps {
                // Passes near m only at its end: two nodes within rounding; leave them.
                continue;
            }
            if closest_point_on_segment(pm, pa, pb).0.distance(pm) > eps {
                continue;
            }
            near.push(hit.key);
        }
        Ok(near)
    }

    /// Edges made by a split leave the line of the edge they replace by a few units in
    /// the last place, and so may pass within rounding of a node they do not end at — on
    /// its wrong side, where a later edge from that node crosses them. Bends each such
    /// edge through the node nearest its first end ([`reroute_through`], whose walk takes
    /// its pieces through any further such node).
    ///
    /// [`reroute_through`]: Self::reroute_through
    fn settle(
        &mut self,
        work: &[EdgeId],
        make_node: &mut impl FnMut(DVec2) -> N,
        out: &mut Insertion,
        depth: usize,
    ) -> Result<(), GeomError> {
        for &e in work {
            if !self.contains_edge(e) {
                continue;
            }
            let (a, b) = self.endpoints(e)?;
            let (pa, pb) = (self.position(a)?, self.position(b)?);
            let eps = rounding_eps(pa.abs().max(pb.abs()));
            let bx = crate::Aabb2::new(pa, pb).expanded(eps);
            // The least (t, id): independent of the index's candidate order.
            let mut best: Option<(f64, NodeId)> = None;
            self.node_index().for_each_candidate(&bx, |n, shape| {
                let Shape::Point(pn) = *shape else { return };
                if n == a || n == b || !bx.contains(pn) {
                    return;
                }
                // A node already joined to an end lies on a route around the edge at
                // rounding scale: bending through it would give that route back (its
                // second leg passes within rounding of the first end and goes through
                // it), for ever. The edge and the two-edge route are equally good.
                if self.find_edge(a, n).is_some() || self.find_edge(n, b).is_some() {
                    return;
                }
                let (closest, t) = closest_point_on_segment(pn, pa, pb);
                let better = best.is_none_or(|(bt, bn)| (t, n.raw()) < (bt, bn.raw()));
                if t > 0.0 && t < 1.0 && closest.distance(pn) <= eps && better {
                    best = Some((t, n));
                }
            });
            if let Some((_, n)) = best {
                self.reroute_through(e, n, make_node, out, depth)?;
            }
        }
        Ok(())
    }

    /// Replaces edge `e = a–b` by a route `a → n → b` — and, with it, every other edge
    /// passing within rounding of `n` ([`reroute_through_all`]).
    ///
    /// [`reroute_through_all`]: Self::reroute_through_all
    fn reroute_through(
        &mut self,
        e: EdgeId,
        n: NodeId,
        make_node: &mut impl FnMut(DVec2) -> N,
        out: &mut Insertion,
        depth: usize,
    ) -> Result<(), GeomError> {
        let near = self.edges_passing_near(n, Some(e))?;
        self.reroute_through_all(&near, n, make_node, out, depth)
    }

    /// Replaces each edge `e = a–b` of `edges` by a route `a → n → b`, recording each new
    /// edge as `(e, piece)` in `out.split`.
    ///
    /// Moving an edge onto a node moves it by up to the rounding distance, which can take
    /// it across other edges that pass just as close (fans of nearly parallel edges out of
    /// one node). So the two legs are not added blindly: each is *inserted*, by the same
    /// walk as a new segment with no snapping beyond rounding — existing pieces are
    /// followed, nodes within rounding of a leg are routed through, and edges the leg
    /// crosses are split.
    ///
    /// All of `edges` are removed before any leg is walked. An edge that a leg `a → n`
    /// crosses passes between `n` and the old edge `a–b`, so within rounding of `n`: it
    /// belongs in `edges` itself. Bent one at a time, a bend's legs would cross the next
    /// edge to be bent, far from `n` where it runs nearly parallel, and every such
    /// crossing is a new node whose own absorptions bend further edges — in a dense
    /// tangle, a cascade of thousands of nodes. Walks still nest (a crossing met by a leg
    /// can bend another edge); past [`MAX_BEND_DEPTH`] levels the insertion gives up with
    /// [`GeomError::GraphCorrupt`].
    fn reroute_through_all(
        &mut self,
        edges: &[EdgeId],
        n: NodeId,
        make_node: &mut impl FnMut(DVec2) -> N,
        out: &mut Insertion,
        depth: usize,
    ) -> Result<(), GeomError> {
        if edges.is_empty() {
            return Ok(());
        }
        if depth >= MAX_BEND_DEPTH {
            return Err(GeomError::GraphCorrupt(format!(
                "bending edge {} through node {n} nested more than {MAX_BEND_DEPTH} bends deep; check_invariants() may tell why",
                edges[0]
            )));
        }
        let mut removed = Vec::with_capacity(edges.len());
        for &e in edges {
            let (a, b) = self.endpoints(e)?;
            removed.push((e, a, b, self.remove_edge(e)?));
        }
        for (e, a, b, payload) in removed {
            let mut legs = Insertion::default();
            for (from, to) in [(a, n), (n, b)] {
                let line = (self.position(from)?, self.position(to)?);
                self.connect(
                    from,
                    to,
                    line,
                    &payload,
                    0.0,
                    make_node,
                    &mut legs,
                    depth + 1,
                )?;
                // Each leg is a walk of its own: its route does not bar the other's nodes.
                legs.nodes.clear();
            }
            out.split
                .extend(legs.created.iter().map(|&piece| (e, piece)));
            out.split.extend(legs.split);
        }
        Ok(())
    }

    /// Whether edge `e` passes within rounding of node `n` strictly between its ends
    /// (`n` not an end of it).
    fn passes_within_rounding(&self, e: EdgeId, n: NodeId) -> Result<bool, GeomError> {
        let (a, b) = self.endpoints(e)?;
        if n == a || n == b {
            return Ok(false);
        }
        let (pa, pb, pn) = (self.position(a)?, self.position(b)?, self.position(n)?);
        let (closest, t) = closest_point_on_segment(pn, pa, pb);
        Ok(t > 0.0 && t < 1.0 && closest.distance(pn) <= rounding_eps(pn))
    }

    /// Checks that the given edges meet other edges only at common end nodes.
    fn check_local(&self, edges: impl IntoIterator<Item = EdgeId>) -> Result<(), GeomError> {
        for e in edges {
            let (a, b) = self.endpoints(e)?;
            let (pa, pb) = (self.position(a)?, self.position(b)?);
            if let Some(hit) = self.meets_elsewhere((a, pa), (b, pb), Some(e)) {
                return Err(GeomError::GraphCorrupt(format!(
                    "after insertion, edge {e} meets edge {} away from a common node ({:?}); please report this input",
                    hit.key, hit.kind
                )));
            }
        }
        Ok(())
    }

    /// Whether the straight leg from node `a` to node `b` would meet no edge but at those
    /// two nodes (an edge `a–b` itself is no obstacle).
    fn sees(&self, a: (NodeId, DVec2), b: (NodeId, DVec2)) -> bool {
        let skip = self.find_edge(a.0, b.0);
        self.meets_elsewhere(a, b, skip).is_none()
    }

    /// The first edge (in candidate order: no allocation, no sorting) other than `skip`
    /// that meets the segment between nodes `a` and `b` anywhere but at `a` or `b` by an
    /// edge ending there.
    fn meets_elsewhere(
        &self,
        (a, pa): (NodeId, DVec2),
        (b, pb): (NodeId, DVec2),
        skip: Option<EdgeId>,
    ) -> Option<SegmentHit<EdgeId>> {
        let mut bad: Option<SegmentHit<EdgeId>> = None;
        self.edge_index()
            .for_each_candidate_along(pa, pb, |key, s| {
                if bad.is_some() || Some(key) == skip {
                    return;
                }
                let Shape::Segment(s0, s1) = *s else { return };
                let Some(hit) = classify_hit(key, pa, pb, s0, s1) else {
                    return;
                };
                if !self.meets_at_ends(&hit, (a, pa), (b, pb)) {
                    bad = Some(hit);
                }
            });
        bad
    }

    /// Whether `hit` (of an edge with the segment between nodes `a` and `b`) is a touch
    /// at `a` or `b` by an edge ending there: the only allowed way to meet.
    fn meets_at_ends(
        &self,
        hit: &SegmentHit<EdgeId>,
        (a, pa): (NodeId, DVec2),
        (b, pb): (NodeId, DVec2),
    ) -> bool {
        match hit.kind {
            SegmentIntersection::Touching { point, .. } => {
                self.endpoints(hit.key).is_ok_and(|(c, d)| {
                    (point == pa && (c == a || d == a)) || (point == pb && (c == b || d == b))
                })
            }
            _ => false,
        }
    }
}
