//! The straight skeleton of a polygon with holes, weighted or not.
//!
//! Every input edge moves inwards, parallel to itself, at the speed of its weight (all
//! ones for the ordinary skeleton). The skeleton is the set of paths traced by the
//! wavefront's vertices; each input edge sweeps one *face*. The algorithm is the
//! event-driven wavefront simulation of Felkel & Obdržálek (1998): a set of circular lists
//! of active vertices (one per wavefront component), a priority queue of edge events and
//! split events, and a general collapse rule (see the private `events` module) that also
//! handles vertex events, multi-splits, simultaneous events, parallel edges meeting and
//! collinear edges, all in a deterministic order.
//!
//! # Guarantees
//!
//! * Every node at time `t` lies at distance `t · w_e` from the supporting line of each
//!   input edge `e` whose face it bounds (up to rounding).
//! * The faces tile the polygon: their areas add up to the polygon's area (up to rounding),
//!   and face `e` is a counter-clockwise polygon that starts with input edge `e`.
//! * Split events are never skipped: every edge line a reflex vertex can reach is a
//!   candidate (found by a scan or an index that give the same candidates, see
//!   `candidates`), and a hit is confirmed against the wavefront as it is at the moment
//!   of the hit.
//!
//! # Limitations
//!
//! * Consecutive parallel edges with *different* weights (in the input, or once the edge
//!   between them has vanished) have no weighted bisector. The wavefront gets a
//!   perpendicular step there: a virtual edge of weight 0 along the common normal, with one
//!   vertex on each offset line; once an input edge parallel to the step reaches it, that
//!   edge sweeps the step away. Arcs along a step are flagged ([`SkeletonArc::step`]) and
//!   reported as separating the input edges on either side; the distance guarantee above
//!   holds for one of their two lines only (at each end of the arc). A vertex between two
//!   steps (an input edge ran head-on into a step, or two steps met in line) stands
//!   still: its arc has no length in the plane and is vertical in the roof, and it names
//!   an input edge through its start node and one through its end node. Insets stay exact
//!   (the step edge has no source, see [`inset_shapes`](crate::inset_shapes)).
//! * Steps can enclose a region between them: when every input edge around a part of the
//!   wavefront has vanished and only steps bound it (orthogonal outlines whose parallel
//!   neighbours have different weights, about one polygon in 3,000 of the property test
//!   `weighted_steps_interacting`), nothing moves it and nothing sweeps the region. The
//!   skeleton and every inset from then on are refused with
//!   [`LotsError::SkeletonFailed`] and the reason [`STEPS_ENCLOSE`] rather than returned
//!   without that region's faces or with a ring that never shrinks.
//! * Points closer than `1e-9` times the polygon's size at the same time are merged into
//!   one event; nearly simultaneous events are therefore treated as simultaneous (an inset
//!   within that time of the last collapse may come out empty).
//! * A vertex whose edges turn back on each other to within a sine of `1e-8` (a needle or
//!   crack) is refused with [`LotsError::NeedleVertex`] by the skeleton and the insets
//!   alike: its wavefront vertex would move more than 10⁸ times faster than its edges.
//!
//! # References
//!
//! Aichholzer, Aurenhammer, Alberts, Gärtner, *A Novel Type of Skeleton for Polygons*
//! (J. UCS 1995); Felkel, Obdržálek, *Straight Skeleton Implementation* (SCCG 1998);
//! Eppstein, Erickson, *Raising Roofs, Crashing Cycles, and Playing Pool* (DCG 1999) for
//! weighted skeletons; Kelly 2008 §4.4.1.1 and §4.4.3.1.

/// The reason [`LotsError::SkeletonFailed`] gives when weighted steps alone enclose a
/// part of the wavefront (see the limitations above).
pub const STEPS_ENCLOSE: &str =
    "weighted steps alone enclose a part of the wavefront, which nothing sweeps";

mod candidates;
pub(crate) mod events;
pub(crate) mod wavefront;

use polis_geom::{DVec2, Polygon, PolygonWithHoles, Ring};

use crate::LotsError;
use crate::error::check_positive;
use events::Engine;

/// A skeleton node: where wavefront vertices meet (or an input vertex, at time 0).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SkeletonNode {
    /// Position in metres.
    pub position: DVec2,
    /// The time the wavefront reached it: the offset distance for unit weights.
    pub time: f64,
}

/// A skeleton arc: the straight path of one wavefront vertex, or a ridge where two
/// wavefront edges met face to face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SkeletonArc {
    /// Index of the start node (the earlier one).
    pub from: usize,
    /// Index of the end node.
    pub to: usize,
    /// The input edge whose face lies to the left of `from → to`.
    pub left_edge: usize,
    /// The input edge whose face lies to the right of `from → to`.
    pub right_edge: usize,
    /// Whether the arc runs along a weighted step (between parallel neighbours of
    /// different weights): one of its sides is then the step's zero-area sliver, and
    /// `left_edge`/`right_edge` name the input edges beyond it. Each end of such an arc
    /// lies on the offset line of one of them, not necessarily both. An arc between two
    /// steps stands still (`from` and `to` are at the same place): `left_edge` is then an
    /// input edge through `from` and `right_edge` one through `to`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub step: bool,
}

/// Which ring an input edge belongs to, and its index in that ring.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct EdgeRef {
    /// The ring.
    pub ring: Ring,
    /// Edge index within the ring (edge `i` runs from vertex `i` to vertex `i + 1`).
    pub index: usize,
}

/// The straight skeleton of a [`PolygonWithHoles`].
///
/// Input edges are numbered ring by ring: the outer ring's edges first, then each hole's.
/// Nodes `0..n` are the input vertices in the same order (node `i` is the start of edge
/// `i`); later nodes are events.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StraightSkeleton {
    nodes: Vec<SkeletonNode>,
    arcs: Vec<SkeletonArc>,
    faces: Vec<Polygon>,
    weights: Vec<f64>,
    ring_starts: Vec<usize>,
}

impl StraightSkeleton {
    /// The ordinary (unweighted) straight skeleton.
    ///
    /// The polygon must be valid ([`PolygonWithHoles::validate`]) with a counter-clockwise
    /// outer ring and clockwise holes ([`PolygonWithHoles::normalize`]).
    pub fn new(polygon: &PolygonWithHoles) -> Result<Self, LotsError> {
        Self::build(polygon, None)
    }

    /// The weighted straight skeleton: edge `e` moves at speed `weights[e]` (> 0), edges
    /// numbered ring by ring (outer first).
    pub fn weighted(polygon: &PolygonWithHoles, weights: &[f64]) -> Result<Self, LotsError> {
        Self::build(polygon, Some(weights))
    }

    fn build(polygon: &PolygonWithHoles, weights: Option<&[f64]>) -> Result<Self, LotsError> {
        let mut engine = Engine::default();
        let weights = prepare(&mut engine, polygon, weights)?;
        engine.run(f64::INFINITY)?;
        if engine.steps_enclose_a_region() {
            return Err(LotsError::SkeletonFailed {
                reason: STEPS_ENCLOSE,
            });
        }
        if engine.any_alive() {
            return Err(LotsError::SkeletonFailed {
                reason: "part of the wavefront never collapsed",
            });
        }
        let faces = assemble_faces(&engine);
        let n_in = engine.input_edges();
        // An input edge through each node: a raw arc with an input edge on one side lies on
        // that edge's offset line from end to end, so both its nodes do.
        let mut through = vec![usize::MAX; engine.nodes.len()];
        for a in &engine.arcs {
            for e in [a.left_edge, a.right_edge] {
                if e < n_in {
                    through[a.from] = through[a.from].min(e);
                    through[a.to] = through[a.to].min(e);
                }
            }
        }
        // A node that only steps meet (a stationary vertex split by a step edge lying
        // over it) has no input edge of its own; an event at the same point and time (the
        // one that made the vertex) has, and its input edge passes through both.
        loop {
            let mut changed = false;
            for a in &engine.arcs {
                let (f, t) = (a.from, a.to);
                if (through[f] == usize::MAX) == (through[t] == usize::MAX) {
                    continue;
                }
                let (nf, nt) = (engine.nodes[f], engine.nodes[t]);
                if nf.position.distance(nt.position) <= engine.eps
                    && (nf.time - nt.time).abs() <= engine.time_eps
                {
                    let e = through[f].min(through[t]);
                    through[f] = e;
                    through[t] = e;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        // Arcs along a weighted step separate the two input edges the step joins.
        let arcs = engine
            .arcs
            .iter()
            .map(|a| {
                let mut a = *a;
                if a.left_edge >= n_in && a.right_edge >= n_in {
                    // A vertex between two steps (an input edge ran into a step, or two
                    // steps met in line) stands still: its arc is vertical in the roof,
                    // from the face of the event that made it to the face of the event
                    // that ends it. Neither step's pair describes it.
                    let (lo, hi) = (through[a.from], through[a.to]);
                    if lo < n_in && hi < n_in {
                        a.left_edge = lo;
                        a.right_edge = hi;
                        a.step = true;
                        return a;
                    }
                }
                // A step may join a step edge and a parallel input edge: map until the
                // edge is an input edge.
                while let Some((before, _)) = engine.step_pair(a.left_edge) {
                    a.left_edge = before as usize;
                    a.step = true;
                }
                while let Some((_, after)) = engine.step_pair(a.right_edge) {
                    a.right_edge = after as usize;
                    a.step = true;
                }
                a
            })
            .collect();
        Ok(StraightSkeleton {
            nodes: engine.nodes,
            arcs,
            faces,
            weights,
            ring_starts: engine.ring_starts,
        })
    }

    /// All nodes; the first [`input_vertex_count`](Self::input_vertex_count) are the input
    /// vertices.
    pub fn nodes(&self) -> &[SkeletonNode] {
        &self.nodes
    }

    /// All arcs, including the ridges. Zero-length arcs may occur where events coincide.
    pub fn arcs(&self) -> &[SkeletonArc] {
        &self.arcs
    }

    /// The face swept by each input edge, counter-clockwise, starting with the edge itself.
    pub fn faces(&self) -> &[Polygon] {
        &self.faces
    }

    /// The face of input edge `edge`, if it exists.
    pub fn face(&self, edge: usize) -> Option<&Polygon> {
        self.faces.get(edge)
    }

    /// The weight of each input edge (all ones for [`new`](Self::new)).
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Number of input vertices (= input edges).
    pub fn input_vertex_count(&self) -> usize {
        self.ring_starts.last().copied().unwrap_or(0)
    }

    /// The ring and in-ring index of input edge `edge`.
    pub fn edge_ref(&self, edge: usize) -> Option<EdgeRef> {
        let r = self
            .ring_starts
            .windows(2)
            .position(|w| edge >= w[0] && edge < w[1])?;
        let ring = if r == 0 {
            Ring::Outer
        } else {
            Ring::Hole(r - 1)
        };
        Some(EdgeRef {
            ring,
            index: edge - self.ring_starts[r],
        })
    }

    /// Checks the structure's own consistency: arcs join existing nodes forward in time,
    /// every face starts with its input edge (the input vertices are the first nodes) and
    /// has no negative area, and the faces' areas add up to `polygon_area` within the
    /// relative tolerance `tol`. Returns what is wrong.
    pub fn check_invariants(&self, polygon_area: f64, tol: f64) -> Result<(), String> {
        let n = self.input_vertex_count();
        if self.faces.len() != n || self.weights.len() != n || self.nodes.len() < n {
            return Err(format!(
                "{} faces, {} weights and {} nodes for {n} input edges",
                self.faces.len(),
                self.weights.len(),
                self.nodes.len()
            ));
        }
        for (k, a) in self.arcs.iter().enumerate() {
            let (Some(from), Some(to)) = (self.nodes.get(a.from), self.nodes.get(a.to)) else {
                return Err(format!("arc {k} names a node that does not exist"));
            };
            if to.time < from.time - tol * from.time.abs().max(1.0) {
                return Err(format!("arc {k} runs backwards in time"));
            }
            if a.left_edge >= n || a.right_edge >= n {
                return Err(format!("arc {k} names an edge that does not exist"));
            }
        }
        let mut total = 0.0;
        for (e, f) in self.faces.iter().enumerate() {
            let next = if e + 1
                == self
                    .ring_starts
                    .iter()
                    .copied()
                    .find(|&s| s > e)
                    .unwrap_or(n)
            {
                self.ring_starts
                    .iter()
                    .copied()
                    .filter(|&s| s <= e)
                    .max()
                    .unwrap_or(0)
            } else {
                e + 1
            };
            let pts = f.points();
            if pts.len() < 3
                || pts[0] != self.nodes[e].position
                || pts[1] != self.nodes[next].position
            {
                return Err(format!("face {e} does not start with its input edge"));
            }
            let a = f.signed_area();
            if a < -tol * polygon_area {
                return Err(format!("face {e} has negative area {a}"));
            }
            total += a;
        }
        if (total - polygon_area).abs() > tol * polygon_area {
            return Err(format!(
                "the faces cover {total} m², the polygon {polygon_area} m²"
            ));
        }
        Ok(())
    }

    /// The time of the last event: when the polygon has vanished completely.
    pub fn max_time(&self) -> f64 {
        self.nodes.iter().map(|n| n.time).fold(0.0, f64::max)
    }
}

/// Validates the polygon and weights and loads them into the engine. Returns the weights.
pub(crate) fn prepare(
    engine: &mut Engine,
    polygon: &PolygonWithHoles,
    weights: Option<&[f64]>,
) -> Result<Vec<f64>, LotsError> {
    check_input(polygon, weights)?;
    Ok(reset_checked(engine, polygon, weights))
}

/// [`prepare`] of an input that passed [`check_input`].
pub(crate) fn reset_checked(
    engine: &mut Engine,
    polygon: &PolygonWithHoles,
    weights: Option<&[f64]>,
) -> Vec<f64> {
    let total: usize = polygon.rings().map(|(_, r)| r.len()).sum();
    let weights = match weights {
        Some(w) => w.to_vec(),
        None => vec![1.0; total],
    };
    let rings: Vec<&[DVec2]> = polygon.rings().map(|(_, r)| r.points()).collect();
    engine.reset(&rings, &weights);
    weights
}

/// The checks of [`prepare`]: a valid polygon, normalised (counter-clockwise outer ring,
/// clockwise holes), with one positive finite weight per edge if weights are given.
pub(crate) fn check_input(
    polygon: &PolygonWithHoles,
    weights: Option<&[f64]>,
) -> Result<(), LotsError> {
    polygon.validate()?;
    if polygon.outer.signed_area() <= 0.0 {
        return Err(LotsError::WrongOrientation { ring: Ring::Outer });
    }
    for (i, h) in polygon.holes.iter().enumerate() {
        if h.signed_area() >= 0.0 {
            return Err(LotsError::WrongOrientation {
                ring: Ring::Hole(i),
            });
        }
    }
    for (ring, r) in polygon.rings() {
        let pts = r.points();
        let n = pts.len();
        for i in 0..n {
            let (a, b, c) = (pts[(i + n - 1) % n], pts[i], pts[(i + 1) % n]);
            let (ein, eout) = (
                wavefront::EdgeLine::new(a, b, 1.0),
                wavefront::EdgeLine::new(b, c, 1.0),
            );
            if wavefront::turns_back(&ein, &eout) {
                return Err(LotsError::NeedleVertex {
                    ring,
                    vertex: i,
                    sine: ein.dir.perp_dot(eout.dir),
                });
            }
        }
    }
    if let Some(w) = weights {
        let total: usize = polygon.rings().map(|(_, r)| r.len()).sum();
        if w.len() != total {
            return Err(LotsError::EdgeCountMismatch {
                what: "weights",
                expected: total,
                got: w.len(),
            });
        }
        for (e, &x) in w.iter().enumerate() {
            check_positive("weight", e, x)?;
        }
    }
    Ok(())
}

/// Builds each face from the arcs that bound it.
fn assemble_faces(engine: &Engine) -> Vec<Polygon> {
    let n_edges = engine.edges.len();
    let mut per_face: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n_edges];
    for arc in &engine.arcs {
        if arc.from == arc.to {
            continue;
        }
        per_face[arc.left_edge].push((arc.from, arc.to));
        per_face[arc.right_edge].push((arc.to, arc.from));
    }
    let mut faces = Vec::with_capacity(n_edges);
    for r in 0..engine.ring_starts.len().saturating_sub(1) {
        let (s, e) = (engine.ring_starts[r], engine.ring_starts[r + 1]);
        for (i, list) in per_face.iter_mut().enumerate().take(e).skip(s) {
            let start = i;
            let end = s + (i + 1 - s) % (e - s);
            list.sort_unstable();
            let mut used = vec![false; list.len()];
            let mut points = vec![engine.nodes[start].position, engine.nodes[end].position];
            let mut prev = start;
            let mut cur = end;
            for _ in 0..=list.len() {
                if cur == start {
                    break;
                }
                // Where the face touches itself (weighted faces can wrap around others),
                // several arcs leave `cur`: take the first clockwise from the way back, which
                // keeps the face on the left.
                let from = list.partition_point(|&(f, _)| f < cur);
                let here = engine.nodes[cur].position;
                let back = engine.nodes[prev].position - here;
                let mut best: Option<usize> = None;
                for k in from..list.len() {
                    if list[k].0 != cur {
                        break;
                    }
                    if used[k] {
                        continue;
                    }
                    let d = engine.nodes[list[k].1].position - here;
                    let better = best.is_none_or(|b| {
                        let db = engine.nodes[list[b].1].position - here;
                        polis_geom::lines::ccw_cmp_from(back, d, db) == std::cmp::Ordering::Greater
                    });
                    if better {
                        best = Some(k);
                    }
                }
                let Some(k) = best else {
                    break;
                };
                used[k] = true;
                prev = cur;
                cur = list[k].1;
                if cur != start {
                    points.push(engine.nodes[cur].position);
                }
            }
            points.dedup_by(|a, b| a == b);
            if points.len() > 1 && points.first() == points.last() {
                points.pop();
            }
            faces.push(Polygon::new(points));
        }
    }
    faces
}
