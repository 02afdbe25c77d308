//! The event loop: edge events, split events and every simultaneous or degenerate
//! combination of them, handled by one general rule.
//!
//! # The collapse rule
//!
//! Every event is a *collapse at a point `P` at time `t`*: some active vertices arrive at
//! `P` (the two ends of a vanishing edge; a reflex vertex; several vertices at once), and
//! possibly one wavefront edge passes through `P` (the edge a reflex vertex splits). The
//! vertices at `P` form maximal runs ("chains") along their circular lists. Each chain
//! brings one incoming wavefront edge into `P` and takes one outgoing edge out of it; an
//! edge through `P` brings both. Sorted counter-clockwise around `P` (exactly, on the input
//! edge directions), every outgoing edge is joined to the next incoming edge after it: the
//! wavefront region near `P` after the event is the intersection of the chains' interior
//! wedges, and each of its angular pieces starts at an outgoing edge and ends at an
//! incoming one. One rule therefore covers edge events, split events, vertex events
//! (several reflex vertices meeting), multi-splits and whole lists collapsing at once.
//!
//! Arrivals at one point at one moment that the queue delivers as separate events (the
//! reflex tips of a wheel's spokes reaching its hub) are resolved together: a collapse
//! also takes every vertex an earlier collapse created at the same point and time, so the
//! last of them applies the rule to all the rays there at once.
//!
//! Two wavefront edges that point in opposite directions and lie on top of each other (two
//! parallel edges meeting, like the long sides of a rectangle) give a *fold* vertex; it is
//! zipped closed at once, along the overlap, into a skeleton arc.
//!
//! Events are processed in a total order: time, then kind, then vertex ids, so the result
//! never depends on anything but the input.

use std::cmp::{Ordering, Reverse};
use std::collections::{BinaryHeap, HashMap};

use polis_geom::DVec2;

use super::candidates::{
    Bounds, Candidate, CandidateBatch, Query, SplitLines, TOUCH_SLOPE_REL, line_hit,
};
use super::wavefront::{EdgeLine, Motion, Vertex, angle_cmp, is_reflex, meet, motion};
use super::{SkeletonArc, SkeletonNode};
use crate::LotsError;

/// Relative tolerance (times the polygon's size) within which two wavefront points at the
/// same time count as one point.
pub(crate) const COINCIDENCE_REL: f64 = 1e-9;

const NONE: u32 = u32::MAX;

/// A new vertex is moved onto the exact crossing of its two offset lines when that is
/// within this many coincidence tolerances of the event point.
const SNAP_REL: f64 = 1e3;

#[derive(Debug, Clone, Copy)]
struct Event {
    t: f64,
    /// 0 = edge event (a = start vertex, b = end vertex); 1 = split candidate (a = vertex,
    /// b = edge); 2 = extra split candidate against a step edge created later.
    kind: u8,
    a: u32,
    b: u32,
}

impl PartialEq for Event {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Event {}
impl PartialOrd for Event {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Event {
    fn cmp(&self, other: &Self) -> Ordering {
        self.t
            .total_cmp(&other.t)
            .then(self.kind.cmp(&other.kind))
            .then(self.a.cmp(&other.a))
            .then(self.b.cmp(&other.b))
    }
}

/// One incoming or outgoing wavefront edge at a collapse point.
#[derive(Debug, Clone, Copy)]
struct Ray {
    /// Direction away from the collapse point.
    dir: DVec2,
    outgoing: bool,
    edge: u32,
    /// For an incoming edge, the vertex it comes from; for an outgoing one, where it goes.
    other: u32,
}

/// The whole simulation state. Buffers are kept between runs.
#[derive(Debug, Default)]
pub(crate) struct Engine {
    pub edges: Vec<EdgeLine>,
    /// Index of the first edge of each ring, plus the total at the end.
    pub ring_starts: Vec<usize>,
    pub verts: Vec<Vertex>,
    pub nodes: Vec<SkeletonNode>,
    pub arcs: Vec<SkeletonArc>,
    queue: BinaryHeap<Reverse<Event>>,
    candidates: Vec<CandidateBatch>,
    /// The supporting lines of all edges, for split candidates.
    pub(crate) lines: SplitLines,
    /// For each virtual step edge (after the input edges): the input edges it joins.
    step_pairs: Vec<(u32, u32)>,
    /// For each input edge, vertices that started a wavefront piece of it.
    pieces: Vec<Vec<u32>>,
    mark: Vec<u32>,
    stamp: u32,
    pub now: f64,
    pub eps: f64,
    /// The time the fastest edge needs to move `eps`: events this close after a time
    /// count as at that time (see [`Engine::run_through`]).
    pub time_eps: f64,
    /// No event can happen after this time (the polygon is gone by then).
    horizon: f64,
    bbox_min: DVec2,
    bbox_max: DVec2,
    uniform: bool,
    collapses: usize,
    budget: usize,
    scratch_set: Vec<u32>,
    scratch_rays: Vec<Ray>,
    scratch_new: Vec<u32>,
    /// Vertices created at the current event time, by grid cell of side `4 · eps` (only
    /// looked up, never iterated into output): see [`Engine::join_recent`].
    recent: HashMap<(i64, i64), Vec<u32>>,
    /// The event time the vertices in `recent` were created at.
    recent_t: f64,
}

impl Engine {
    /// Resets the engine for rings that are already validated and oriented, with one
    /// positive weight per edge (ring by ring).
    pub fn reset(&mut self, rings: &[&[DVec2]], weights: &[f64]) {
        self.edges.clear();
        self.ring_starts.clear();
        self.verts.clear();
        self.nodes.clear();
        self.arcs.clear();
        self.queue.clear();
        self.candidates.clear();
        self.step_pairs.clear();
        self.lines.clear();
        self.pieces.clear();
        self.mark.clear();
        self.stamp = 0;
        self.now = 0.0;
        self.collapses = 0;
        self.recent.clear();
        self.recent_t = 0.0;
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for ring in rings {
            self.ring_starts.push(self.edges.len());
            let n = ring.len();
            for i in 0..n {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                lo = lo.min(a);
                hi = hi.max(a);
                let w = weights[self.edges.len()];
                self.edges.push(EdgeLine::new(a, b, w));
            }
        }
        self.ring_starts.push(self.edges.len());
        let size = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        self.eps = COINCIDENCE_REL * size;
        self.bbox_min = lo - DVec2::splat(self.eps);
        self.bbox_max = hi + DVec2::splat(self.eps);
        let wmin = weights.iter().copied().fold(f64::INFINITY, f64::min);
        self.uniform = weights.iter().all(|&w| w == weights[0]);
        // Every wavefront point stays inside the box, so its distance to any edge line, and
        // hence any event time times the weight, is at most the box diagonal.
        self.horizon = (hi - lo).length() / wmin * (1.0 + 1e-9) + self.eps;
        let wmax = weights.iter().copied().fold(0.0, f64::max);
        self.time_eps = self.eps / wmax.max(f64::MIN_POSITIVE);
        self.pieces.resize(self.edges.len(), Vec::new());
        let n_edges = self.edges.len();
        self.budget = 16 * n_edges + 256;
        // One vertex and one node per input vertex, in edge order.
        for r in 0..rings.len() {
            let (s, e) = (self.ring_starts[r], self.ring_starts[r + 1]);
            let n = e - s;
            for i in 0..n {
                let id = (s + i) as u32;
                let prev = (s + (i + n - 1) % n) as u32;
                let next = (s + (i + 1) % n) as u32;
                let p = self.edges[s + i].a;
                self.nodes.push(SkeletonNode {
                    position: p,
                    time: 0.0,
                });
                self.verts.push(Vertex {
                    p0: p,
                    t0: 0.0,
                    motion: Motion::Fold,
                    in_edge: prev,
                    out_edge: id,
                    prev,
                    next,
                    node: id,
                    alive: true,
                });
            }
        }
        self.candidates
            .resize(self.verts.len(), CandidateBatch::default());
        for e in &self.edges {
            self.lines.push(e);
        }
        let bounds = self.bounds();
        self.lines.build_index(&self.edges, &bounds);
        self.mark.resize(self.verts.len(), 0);
        for v in 0..self.verts.len() as u32 {
            let ein = &self.edges[self.verts[v as usize].in_edge as usize];
            let eout = &self.edges[self.verts[v as usize].out_edge as usize];
            self.verts[v as usize].motion = motion(ein, eout);
        }
        let initial = self.verts.len() as u32;
        for v in 0..initial {
            if matches!(self.verts[v as usize].motion, Motion::Step(_)) {
                self.split_step(v);
            }
        }
        for v in 0..self.verts.len() as u32 {
            if self.verts[v as usize].alive {
                self.pieces[self.verts[v as usize].out_edge as usize].push(v);
            }
        }
        for v in 0..self.verts.len() as u32 {
            if self.verts[v as usize].alive {
                self.push_edge_event(v);
                self.push_split_candidates(v);
            }
        }
    }

    /// The number of input edges; later edges are virtual step edges.
    pub fn input_edges(&self) -> usize {
        self.ring_starts.last().copied().unwrap_or(0)
    }

    /// Replaces vertex `v` between two parallel edges of different weights by a step: a
    /// virtual wavefront edge of weight 0 along their common normal, with one vertex on
    /// each of the two lines. Returns the two new vertices.
    fn split_step(&mut self, v: u32) -> (u32, u32) {
        let x = *self.vert(v);
        let ea = self.edges[x.in_edge as usize];
        let eb = self.edges[x.out_edge as usize];
        let n = (ea.normal + eb.normal).normalize();
        // The step runs from the line that is ahead back to the one behind.
        let dir = if ea.weight > eb.weight { -n } else { n };
        let p = x.p0;
        let step = EdgeLine::new(p, p + dir, 0.0);
        self.edges.push(step);
        self.lines.push(&step);
        self.pieces.push(Vec::new());
        self.step_pairs.push((x.in_edge, x.out_edge));
        let s = (self.edges.len() - 1) as u32;
        let base = self.verts.len() as u32;
        let (va, vb) = (base, base + 1);
        self.verts.push(Vertex {
            p0: p,
            t0: x.t0,
            motion: motion(&ea, &step),
            in_edge: x.in_edge,
            out_edge: s,
            prev: x.prev,
            next: vb,
            node: x.node,
            alive: true,
        });
        self.verts.push(Vertex {
            p0: p,
            t0: x.t0,
            motion: motion(&step, &eb),
            in_edge: s,
            out_edge: x.out_edge,
            prev: va,
            next: x.next,
            node: x.node,
            alive: true,
        });
        self.candidates.push(CandidateBatch::default());
        self.candidates.push(CandidateBatch::default());
        self.mark.push(0);
        self.mark.push(0);
        self.vert_mut(x.prev).next = va;
        self.vert_mut(x.next).prev = vb;
        self.vert_mut(v).alive = false;
        // Vertices scanned before this edge existed may still run into it.
        let step_line = self.edges[s as usize];
        for u in 0..self.verts.len() as u32 {
            let y = self.verts[u as usize];
            if !y.alive || u == va || u == vb {
                continue;
            }
            let vel = y.velocity();
            let slope = step_line.normal.dot(vel);
            // The step does not move: measured now, the vertex is where it is now.
            let ahead = step_line.ahead(y.at(self.now), self.now);
            let tol = TOUCH_SLOPE_REL * vel.length();
            let t = line_hit(slope, ahead, self.now, self.eps, tol);
            if t.is_finite() && t >= self.now && t <= self.horizon {
                self.queue.push(Reverse(Event {
                    t,
                    kind: 2,
                    a: u,
                    b: s,
                }));
            }
        }
        (va, vb)
    }

    /// Vertex `v` joins a virtual step edge and a parallel input edge `c` that points the
    /// same way: `c` moves on and sweeps the step's piece, which vanishes. The vertex at the
    /// piece's far end is replaced by one joining `c` and the edge beyond; returns it (or
    /// `NONE` if the list collapsed).
    fn absorb_step(&mut self, v: u32) -> u32 {
        let t = self.now;
        let x = *self.vert(v);
        let n_in = self.input_edges() as u32;
        if x.out_edge >= n_in {
            // c → s: the piece of s runs from v to its successor y (s → d).
            let y = x.next;
            let vy = *self.vert(y);
            if y == x.prev {
                self.vert_mut(v).alive = false;
                let q = self.pos(y, t);
                let qn = self.add_node(q, t);
                self.end_vertex(y, qn);
                return NONE;
            }
            let q = self.pos(y, t);
            let qn = self.add_node(q, t);
            self.end_vertex(y, qn);
            self.arcs.push(SkeletonArc {
                from: x.node as usize,
                to: qn as usize,
                left_edge: x.in_edge as usize,
                right_edge: x.out_edge as usize,
                step: false,
            });
            self.vert_mut(v).alive = false;
            self.new_vertex(q, x.in_edge, vy.out_edge, x.prev, vy.next, qn)
        } else {
            // s → c: the piece of s runs from the predecessor w (d → s) to v.
            let w = x.prev;
            let vw = *self.vert(w);
            if w == x.next {
                self.vert_mut(v).alive = false;
                let q = self.pos(w, t);
                let qn = self.add_node(q, t);
                self.end_vertex(w, qn);
                return NONE;
            }
            let q = self.pos(w, t);
            let qn = self.add_node(q, t);
            self.end_vertex(w, qn);
            self.arcs.push(SkeletonArc {
                from: qn as usize,
                to: x.node as usize,
                left_edge: x.out_edge as usize,
                right_edge: x.in_edge as usize,
                step: false,
            });
            self.vert_mut(v).alive = false;
            self.new_vertex(q, vw.in_edge, x.out_edge, vw.prev, x.next, qn)
        }
    }

    /// For a virtual step edge, the input edges before and after it.
    pub fn step_pair(&self, e: usize) -> Option<(u32, u32)> {
        e.checked_sub(self.input_edges())
            .and_then(|k| self.step_pairs.get(k).copied())
    }

    fn vert(&self, v: u32) -> &Vertex {
        &self.verts[v as usize]
    }

    fn vert_mut(&mut self, v: u32) -> &mut Vertex {
        &mut self.verts[v as usize]
    }

    fn pos(&self, v: u32, t: f64) -> DVec2 {
        self.vert(v).at(t)
    }

    fn add_node(&mut self, position: DVec2, time: f64) -> u32 {
        self.nodes.push(SkeletonNode { position, time });
        (self.nodes.len() - 1) as u32
    }

    /// Ends vertex `v` at node `node`: records the arc it traced and removes it.
    fn end_vertex(&mut self, v: u32, node: u32) {
        let x = *self.vert(v);
        self.arcs.push(SkeletonArc {
            from: x.node as usize,
            to: node as usize,
            left_edge: x.in_edge as usize,
            right_edge: x.out_edge as usize,
            step: false,
        });
        self.vert_mut(v).alive = false;
    }

    fn new_vertex(
        &mut self,
        p: DVec2,
        in_edge: u32,
        out_edge: u32,
        prev: u32,
        next: u32,
        node: u32,
    ) -> u32 {
        let (ea, eb) = (
            &self.edges[in_edge as usize],
            &self.edges[out_edge as usize],
        );
        let m = motion(ea, eb);
        // In exact arithmetic `p` is on both lines; snapping to their crossing keeps the
        // offset distances exact (and places the vertex right after a weighted step).
        // Nearly antiparallel lines cross far away in an ill-conditioned spot: snap only
        // when the crossing is where the event put the vertex.
        let p = match meet(ea, eb, self.now, p) {
            Some(q) if q.distance(p) <= SNAP_REL * self.eps => q,
            _ => p,
        };
        self.verts.push(Vertex {
            p0: p,
            t0: self.now,
            motion: m,
            in_edge,
            out_edge,
            prev,
            next,
            node,
            alive: true,
        });
        self.candidates.push(CandidateBatch::default());
        self.mark.push(0);
        let id = (self.verts.len() - 1) as u32;
        self.vert_mut(prev).next = id;
        self.vert_mut(next).prev = id;
        if self.now > self.recent_t + self.time_eps {
            self.recent.clear();
            self.recent_t = self.now;
        }
        let cell = self.recent_cell(p);
        self.recent.entry(cell).or_default().push(id);
        id
    }

    fn recent_cell(&self, p: DVec2) -> (i64, i64) {
        let k = 4.0 * self.eps;
        ((p.x / k).floor() as i64, (p.y / k).floor() as i64)
    }

    /// Adds to the collapse at `p` (time `now`) every live vertex that an earlier collapse
    /// created at the same time within `eps` of `p`, whatever list it is in.
    ///
    /// Several wavefront pieces can reach one point at one moment (spokes meeting at a
    /// wheel's hub). The event queue delivers them as separate pairwise events, each of
    /// which joins its own chains; the vertices it creates sit on the point with the other
    /// arrivals, and resolving the next pair without them lets wedges overlap, whose
    /// vertices then split each other again at the same point without end. Joining them
    /// makes the last of these events resolve every ray at the point at once, by the one
    /// collapse rule, exactly as if all had arrived in one event.
    fn join_recent(&mut self, p: DVec2, set: &mut Vec<u32>) {
        if self.now > self.recent_t + self.time_eps || self.recent.is_empty() {
            return;
        }
        let (cx, cy) = self.recent_cell(p);
        let t = self.now;
        for dx in -1..=1 {
            for dy in -1..=1 {
                let Some(list) = self.recent.get(&(cx + dx, cy + dy)) else {
                    continue;
                };
                for &r in list {
                    let x = &self.verts[r as usize];
                    if x.alive
                        && self.mark[r as usize] != self.stamp
                        && x.at(t).distance(p) <= self.eps
                    {
                        self.mark[r as usize] = self.stamp;
                        set.push(r);
                    }
                }
            }
        }
    }

    /// Schedules the collapse of the wavefront edge from `u` to its successor.
    fn push_edge_event(&mut self, u: u32) {
        let x = *self.vert(u);
        let w = x.next;
        if w == u || !x.alive {
            return;
        }
        let y = *self.vert(w);
        if matches!(x.motion, Motion::Fold) || matches!(y.motion, Motion::Fold) || x.node == y.node
        {
            return;
        }
        let e = &self.edges[x.out_edge as usize];
        let t = self.now;
        let (pu, pw) = (x.at(t), y.at(t));
        let gap = e.dir.dot(pw - pu);
        let time = if gap <= self.eps || pu.distance(pw) <= self.eps {
            t
        } else {
            let closing = e.dir.dot(x.velocity() - y.velocity());
            if closing <= 0.0 {
                return;
            }
            let tau = gap / closing;
            let time = t + tau;
            if !time.is_finite() || time > self.horizon {
                return;
            }
            time
        };
        self.queue.push(Reverse(Event {
            t: time,
            kind: 0,
            a: u,
            b: w,
        }));
    }

    /// Finds the input edge lines vertex `v` will reach and queues the earliest.
    fn push_split_candidates(&mut self, v: u32) {
        let x = *self.vert(v);
        if !x.alive || matches!(x.motion, Motion::Fold) {
            return;
        }
        let din = self.edges[x.in_edge as usize].raw;
        let dout = self.edges[x.out_edge as usize].raw;
        // Unweighted, only reflex vertices can hit a non-adjacent edge; weighted, a convex
        // vertex can too (Kelly 2008 §4.4.3.1), so every vertex is tested.
        if self.uniform && !is_reflex(din, dout) {
            return;
        }
        self.candidates[v as usize] = self.scan_candidates(&x, None);
        self.push_next_candidate(v);
    }

    /// The `CANDIDATE_BATCH` earliest hits of vertex `x` on edge lines after `after` (in
    /// the order time, then edge).
    fn scan_candidates(&mut self, x: &Vertex, after: Option<Candidate>) -> CandidateBatch {
        let vel = x.velocity();
        let q = Query {
            p0: x.p0,
            t0: x.t0,
            vel,
            speed: vel.length(),
            in_edge: x.in_edge,
            out_edge: x.out_edge,
            after,
        };
        let bounds = self.bounds();
        self.lines.batch(&q, &bounds)
    }

    fn bounds(&self) -> Bounds {
        Bounds {
            horizon: self.horizon,
            eps: self.eps,
            bbox_min: self.bbox_min,
            bbox_max: self.bbox_max,
        }
    }

    fn push_next_candidate(&mut self, v: u32) {
        let mut b = self.candidates[v as usize];
        if b.next == b.len {
            if b.complete || b.len == 0 {
                return;
            }
            let last = b.items[b.len as usize - 1];
            let x = *self.vert(v);
            b = self.scan_candidates(&x, Some(last));
            if b.len == 0 {
                self.candidates[v as usize] = b;
                return;
            }
        }
        let c = b.items[b.next as usize];
        b.next += 1;
        self.candidates[v as usize] = b;
        self.queue.push(Reverse(Event {
            t: c.t,
            kind: 1,
            a: v,
            b: c.edge,
        }));
    }

    /// Runs events up to and including time `until`, and those that rounding put a hair
    /// after it (within the time the fastest edge needs to move the coincidence
    /// tolerance): at `until` the wavefront then has no two pieces lying on each other
    /// that an event a rounding error later would have separated.
    pub fn run_through(&mut self, until: f64) -> Result<(), LotsError> {
        self.run(until + self.time_eps)
    }

    /// Runs events up to and including time `until`. Afterwards `now` is the time of the
    /// last processed event (at most `until`).
    pub fn run(&mut self, until: f64) -> Result<(), LotsError> {
        while let Some(Reverse(ev)) = self.queue.peek().copied() {
            if ev.t > until {
                break;
            }
            self.queue.pop();
            match ev.kind {
                0 => {
                    let (u, w) = (ev.a, ev.b);
                    if !self.vert(u).alive || !self.vert(w).alive || self.vert(u).next != w {
                        continue;
                    }
                    self.now = self.now.max(ev.t);
                    let p = (self.pos(u, self.now) + self.pos(w, self.now)) * 0.5;
                    self.collapse(p, &[u, w], NONE)?;
                }
                _ => {
                    let v = ev.a;
                    if !self.vert(v).alive {
                        continue;
                    }
                    let t = self.now.max(ev.t);
                    match self.validate_split(v, ev.b, t) {
                        Some((seeds, through)) => {
                            self.now = t;
                            let p = self.pos(v, t);
                            let seeds: Vec<u32> =
                                seeds.into_iter().filter(|&s| s != NONE).collect();
                            self.collapse(p, &seeds, through)?;
                        }
                        // An extra candidate (kind 2, against a step edge created after the
                        // vertex's own scan) has no successor in the vertex's batch.
                        None if ev.kind == 1 => self.push_next_candidate(v),
                        None => {}
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether vertex `v` really hits a wavefront piece of input edge `e` at time `t`.
    /// Returns the seed vertices (v and any piece end at the hit point) and the piece it
    /// passes through, if it hits a piece's interior.
    fn validate_split(&mut self, v: u32, e: u32, t: f64) -> Option<([u32; 3], u32)> {
        let p = self.pos(v, t);
        let edge = self.edges[e as usize];
        let sp = edge.along(p);
        let mut pieces = std::mem::take(&mut self.pieces[e as usize]);
        pieces.retain(|&u| {
            let x = &self.verts[u as usize];
            x.alive && x.out_edge == e
        });
        let mut found = None;
        for &u in &pieces {
            let w = self.vert(u).next;
            if u == v || w == v {
                continue;
            }
            let (pu, pw) = (self.pos(u, t), self.pos(w, t));
            let (su, sw) = (edge.along(pu), edge.along(pw));
            if su > sw + self.eps {
                continue;
            }
            if sp < su - self.eps || sp > sw + self.eps {
                continue;
            }
            // The hit point must be on the piece itself, not just on its line.
            if edge.ahead(p, t).abs() > 1e3 * self.eps {
                continue;
            }
            let at_u = p.distance(pu) <= self.eps || sp <= su + self.eps;
            let at_w = p.distance(pw) <= self.eps || sp >= sw - self.eps;
            // Vertices born at the same node were already sorted out by the event that
            // created them: touching there is not a new event.
            let node = self.vert(v).node;
            if (at_u && self.vert(u).node == node) || (at_w && self.vert(w).node == node) {
                continue;
            }
            found = Some(match (at_u, at_w) {
                (false, false) => ([v, NONE, NONE], u),
                (true, false) => ([v, u, NONE], NONE),
                (false, true) => ([v, w, NONE], NONE),
                (true, true) => ([v, u, w], NONE),
            });
            break;
        }
        self.pieces[e as usize] = pieces;
        found
    }

    fn marked(&self, v: u32) -> bool {
        self.mark[v as usize] == self.stamp
    }

    /// The general event: the given vertices (and any neighbours at the same point) meet at
    /// `p` at time `now`; `through` is a vertex whose outgoing wavefront piece passes
    /// through `p`, or `NONE`.
    fn collapse(&mut self, p: DVec2, seeds: &[u32], through: u32) -> Result<(), LotsError> {
        self.collapses += 1;
        if self.collapses > self.budget {
            return Err(LotsError::SkeletonFailed {
                reason: "too many events",
            });
        }
        let t = self.now;
        self.stamp = self.stamp.wrapping_add(1);
        let mut set = std::mem::take(&mut self.scratch_set);
        set.clear();
        for &s in seeds {
            if self.vert(s).alive && !self.marked(s) {
                self.mark[s as usize] = self.stamp;
                set.push(s);
            }
        }
        self.join_recent(p, &mut set);
        // Grow along the lists: neighbours at the same point join the collapse.
        let mut i = 0;
        while i < set.len() {
            let x = *self.vert(set[i]);
            for n in [x.prev, x.next] {
                if !self.marked(n) && self.pos(n, t).distance(p) <= self.eps {
                    self.mark[n as usize] = self.stamp;
                    set.push(n);
                }
            }
            i += 1;
        }
        set.sort_unstable();
        let node = self.add_node(p, t);
        // Chains and their rays.
        let mut rays = std::mem::take(&mut self.scratch_rays);
        rays.clear();
        for &x in &set {
            let vx = *self.vert(x);
            if self.marked(vx.prev) {
                continue;
            }
            let mut last = x;
            while self.marked(self.vert(last).next) {
                last = self.vert(last).next;
            }
            let vl = *self.vert(last);
            rays.push(Ray {
                dir: -self.edges[vx.in_edge as usize].raw,
                outgoing: false,
                edge: vx.in_edge,
                other: vx.prev,
            });
            rays.push(Ray {
                dir: self.edges[vl.out_edge as usize].raw,
                outgoing: true,
                edge: vl.out_edge,
                other: vl.next,
            });
        }
        if through != NONE
            && self.vert(through).alive
            && !self.marked(through)
            && !self.marked(self.vert(through).next)
        {
            let u = *self.vert(through);
            let d = self.edges[u.out_edge as usize].raw;
            rays.push(Ray {
                dir: -d,
                outgoing: false,
                edge: u.out_edge,
                other: through,
            });
            rays.push(Ray {
                dir: d,
                outgoing: true,
                edge: u.out_edge,
                other: u.next,
            });
        }
        for &x in &set {
            self.end_vertex(x, node);
        }
        // Counter-clockwise around p; at equal angles an outgoing edge comes first (the
        // zero-width wedge between them is a fold), then by edge id.
        rays.sort_by(|a, b| {
            angle_cmp(a.dir, b.dir)
                .then(b.outgoing.cmp(&a.outgoing))
                .then(a.edge.cmp(&b.edge))
                .then(a.other.cmp(&b.other))
        });
        // Join each outgoing edge to the next incoming edge after it (cyclic matching).
        let mut new = std::mem::take(&mut self.scratch_new);
        new.clear();
        let k = rays.len();
        let mut used = vec![false; k];
        let mut stack: Vec<usize> = Vec::new();
        for step in 0..2 * k {
            let r = step % k;
            if used[r] {
                continue;
            }
            if rays[r].outgoing {
                if step < k {
                    stack.push(r);
                }
            } else if let Some(o) = stack.pop() {
                used[o] = true;
                used[r] = true;
                let (inc, out) = (rays[r], rays[o]);
                let id = self.new_vertex(p, inc.edge, out.edge, inc.other, out.other, node);
                new.push(id);
            }
        }
        if used.iter().any(|u| !u) {
            self.scratch_set = set;
            self.scratch_rays = rays;
            self.scratch_new = new;
            return Err(LotsError::SkeletonFailed {
                reason: "inconsistent wavefront at an event",
            });
        }
        for &n in &new {
            self.settle(n);
        }
        self.scratch_set = set;
        self.scratch_rays = rays;
        self.scratch_new = new;
        Ok(())
    }

    /// Brings a freshly created vertex into a consistent state: closes two-vertex lists,
    /// zips folds, and schedules the events of whatever vertex remains.
    fn settle(&mut self, mut v: u32) {
        let t = self.now;
        loop {
            let x = *self.vert(v);
            if !x.alive {
                return;
            }
            if x.next == v {
                self.vert_mut(v).alive = false;
                return;
            }
            if x.next == x.prev {
                // Two vertices joined by two edges: the region between them has no area.
                let m = x.next;
                let q = self.pos(m, t);
                let pv = self.pos(v, t);
                let qn = if q.distance(pv) <= self.eps {
                    x.node
                } else {
                    self.add_node(q, t)
                };
                self.end_vertex(m, qn);
                self.arcs.push(SkeletonArc {
                    from: x.node as usize,
                    to: qn as usize,
                    left_edge: self.vert(m).out_edge as usize,
                    right_edge: x.out_edge as usize,
                    step: false,
                });
                self.vert_mut(v).alive = false;
                return;
            }
            if matches!(x.motion, Motion::Step(_)) {
                let n_in = self.input_edges() as u32;
                if (x.in_edge >= n_in) != (x.out_edge >= n_in) {
                    v = self.absorb_step(v);
                    if v == NONE {
                        return;
                    }
                    continue;
                }
                let (va, vb) = self.split_step(v);
                self.settle(va);
                self.settle(vb);
                return;
            }
            if !matches!(x.motion, Motion::Fold) {
                self.pieces[x.out_edge as usize].push(v);
                self.push_edge_event(x.prev);
                self.push_edge_event(v);
                self.push_split_candidates(v);
                return;
            }
            // A fold: the incoming and outgoing wavefront edges overlap from here towards
            // the nearer of their far ends. Zip them closed.
            let p = x.p0;
            let (a, b) = (x.prev, x.next);
            let u = self.edges[x.out_edge as usize].dir;
            let (pa, pb) = (self.pos(a, t), self.pos(b, t));
            let (da, db) = (u.dot(pa - p), u.dot(pb - p));
            let va = *self.vert(a);
            let vb = *self.vert(b);
            if (da - db).abs() <= self.eps {
                let q = (pa + pb) * 0.5;
                let qn = self.add_node(q, t);
                self.end_vertex(v, qn);
                self.end_vertex(a, qn);
                self.end_vertex(b, qn);
                if va.prev == b {
                    return;
                }
                v = self.new_vertex(q, va.in_edge, vb.out_edge, va.prev, vb.next, qn);
            } else if da < db {
                let qn = self.add_node(pa, t);
                self.end_vertex(v, qn);
                self.end_vertex(a, qn);
                v = self.new_vertex(pa, va.in_edge, x.out_edge, va.prev, b, qn);
            } else {
                let qn = self.add_node(pb, t);
                self.end_vertex(v, qn);
                self.end_vertex(b, qn);
                v = self.new_vertex(pb, x.in_edge, vb.out_edge, a, vb.next, qn);
            }
        }
    }

    /// Whether some wavefront component is bounded by weighted steps alone. Nothing moves
    /// such a component (a step has weight 0 and only an input edge parallel to it can
    /// sweep it away), so no event will ever collapse it: the region it encloses is never
    /// swept under the step convention (see the module docs' limitations).
    pub fn steps_enclose_a_region(&self) -> bool {
        let n_in = self.input_edges() as u32;
        if self.edges.len() == n_in as usize {
            return false;
        }
        let mut seen = vec![false; self.verts.len()];
        for start in 0..self.verts.len() {
            if seen[start] || !self.verts[start].alive {
                continue;
            }
            let mut only_steps = true;
            let mut v = start;
            while !seen[v] {
                seen[v] = true;
                let x = &self.verts[v];
                only_steps &= x.out_edge >= n_in;
                v = x.next as usize;
            }
            if only_steps {
                return true;
            }
        }
        false
    }

    /// Whether any vertex is still active.
    pub fn any_alive(&self) -> bool {
        self.verts.iter().any(|v| v.alive)
    }
}
