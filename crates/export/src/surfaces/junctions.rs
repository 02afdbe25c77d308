//! The 2-D plan of a road network's surface: the graph of road segments, the cut of every
//! ribbon end, and one polygon per junction, all in layout coordinates (f64).
//!
//! At every node the incident segments are sorted counter-clockwise
//! ([`ccw_cmp`](polis_geom::predicates::ccw_cmp)); between two consecutive roads `i` and
//! `j` lies a *gap*. In a gap narrower than a half-turn the left border of `i` meets the
//! right border of `j` at a corner `P`; each ribbon is cut square at the farthest corner
//! along it, and the junction polygon runs cut, corner, cut, … around the node. Gaps wider
//! than a half-turn get a miter (or a bevel beyond [`MITER_LIMIT`]), a straight gap a step
//! between the two borders, a dead end a cap.

use std::collections::{BTreeMap, HashMap};

use polis_geom::hash::{FxBuild, point_key as key};
use polis_geom::mesh::triangulate;
use polis_geom::polygon::ring_signed_area;
use polis_geom::predicates::{AngleStart, Orientation, ccw_cmp, orient2d, orient2d_value};
use polis_geom::{DVec2, Polygon, PolygonWithHoles};

use super::{EndCap, MITER_LIMIT, RoadSurfaceOptions, RoadSurfaceReport};
use crate::map::MapRoad;

/// The shortest cut of a ribbon end at a junction, in half-widths: keeps the node strictly
/// inside its junction polygon.
pub const MIN_TRIM_HALF_WIDTHS: f64 = 0.05;

/// Relative slack on the miter limit, so a turn exactly at the limit (120° for
/// [`MITER_LIMIT`] = 2) keeps its miter despite rounding.
const MITER_SLACK: f64 = 1e-9;

/// Relative distance under which a cut and a corner count as the same point (the corner
/// then is the cut's vertex, so the polygon has no sliver edge).
const SNAP: f64 = 1e-9;

/// Relative sine under which two vertices of a junction seen from its node lie on one ray.
const COLLINEAR: f64 = 1e-9;

/// A road segment of the plan: one piece of a road's centre line between two nodes.
#[derive(Debug, Clone)]
pub(crate) struct PlanEdge {
    /// The road (index into the input) it belongs to.
    pub road: usize,
    /// Its nodes.
    pub a: usize,
    pub b: usize,
    /// Length of the road's centre line before `a`, metres.
    pub s_a: f64,
    /// Length of the segment, metres.
    pub len: f64,
    /// Half the road's width, metres.
    pub half: f64,
    /// The ribbon's cut at `a`: its right and left corner (seen going from `a` to `b`).
    pub cut_a: [DVec2; 2],
    /// The ribbon's cut at `b`: its right and left corner (seen going from `a` to `b`).
    pub cut_b: [DVec2; 2],
    /// Trim at each end, metres from the node along the segment.
    pub trim: [f64; 2],
    /// Dropped as a duplicate of another segment between the same nodes.
    pub dropped: bool,
    /// Inside a merged junction (too short for the cuts at its ends): no ribbon.
    pub internal: bool,
}

/// A node of the plan.
#[derive(Debug, Clone)]
pub(crate) struct PlanNode {
    /// Its position.
    pub pos: DVec2,
    /// Incident kept segments: (edge, whether the edge starts here), counter-clockwise.
    pub ends: Vec<(usize, bool)>,
}

/// A junction polygon (or dead-end cap), counter-clockwise, and its triangles.
#[derive(Debug, Clone)]
pub(crate) struct Junction {
    /// The node.
    pub node: usize,
    /// The ring.
    pub ring: Vec<DVec2>,
    /// Triangles as indices into `ring`, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
}

/// The whole plan.
#[derive(Debug, Clone, Default)]
pub(crate) struct Plan {
    pub nodes: Vec<PlanNode>,
    /// The node whose junction each node belongs to (itself, or the first node of its
    /// merged junction).
    pub rep: Vec<usize>,
    /// Whether the node is part of a merged junction.
    pub merged: Vec<bool>,
    pub edges: Vec<PlanEdge>,
    pub junctions: Vec<Junction>,
    pub report: RoadSurfaceReport,
}

/// The left unit normal of the direction `d`.
pub(crate) fn left(d: DVec2) -> DVec2 {
    DVec2::new(-d.y, d.x)
}

/// One incident segment seen from its node.
#[derive(Debug, Clone, Copy)]
struct End {
    edge: usize,
    starts: bool,
    /// The other end's position.
    far: DVec2,
    /// Unit direction away from the node.
    d: DVec2,
    /// Half-width.
    w: f64,
}

impl End {
    fn n(&self) -> DVec2 {
        left(self.d)
    }
}

/// The kind of the gap between two consecutive roads at a node.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Gap {
    /// Narrower than a half-turn: the borders meet at `c + t·dᵢ + wᵢ·nᵢ` (`s` along `dⱼ`),
    /// both ahead of the node.
    Convex { t: f64, s: f64 },
    /// Narrower than a half-turn, but `i` is so much wider that the borders would meet
    /// behind the node on `i`'s side (`i_wide`), or the reverse: the narrow road's border
    /// meets the wide road's end line (through the node) at `s0` along the narrow road.
    Wide { i_wide: bool, s0: f64 },
    /// Exactly a half-turn.
    Straight,
    /// Wider than a half-turn; the borders' crossing if they are not parallel.
    Reflex { ts: Option<(f64, f64)> },
    /// The two roads leave in the same direction (overlapping segments).
    Same,
}

/// Where the left border of `i` (offset `wᵢ`) meets the right border of `j` (offset `wⱼ`):
/// distances along `dᵢ` and `dⱼ`. `None` when parallel.
///
/// `wⱼ + wᵢ·cos θ` is evaluated as `wⱼ·(1 + cos θ) + (wᵢ − wⱼ)·cos θ` with
/// `1 + cos θ = |dᵢ + dⱼ|² / 2`, which stays accurate for nearly opposite roads (a road
/// that bends a little), where `1 + cos θ` alone would cancel.
fn border_crossing(i: &End, j: &End) -> Option<(f64, f64)> {
    let sin = i.d.perp_dot(j.d);
    if sin == 0.0 {
        return None;
    }
    let cos = i.d.dot(j.d);
    let one_plus_cos = (i.d + j.d).length_squared() / 2.0;
    let t = (j.w * one_plus_cos + (i.w - j.w) * cos) / sin;
    let s = (i.w * one_plus_cos + (j.w - i.w) * cos) / sin;
    (t.is_finite() && s.is_finite()).then_some((t, s))
}

fn classify(c: DVec2, i: &End, j: &End) -> Gap {
    match orient2d(c, i.far, j.far) {
        // Exactly a left turn, but parallel (or turned back) in floating point: straight.
        Orientation::CounterClockwise if i.d.perp_dot(j.d) <= 0.0 => Gap::Straight,
        Orientation::CounterClockwise => match border_crossing(i, j) {
            Some((t, s)) if t >= 0.0 && s >= 0.0 => Gap::Convex { t, s },
            Some((t, _)) => {
                // cos θ < 0 here (t or s negative needs an obtuse gap): the narrow road's
                // border crosses the wide one's end line at w·sin θ / (−cos θ).
                let (sin, cos) = (i.d.perp_dot(j.d), i.d.dot(j.d));
                let i_wide = t < 0.0;
                let w = if i_wide { j.w } else { i.w };
                let s0 = (w * sin / -cos).max(0.0);
                if s0.is_finite() {
                    Gap::Wide { i_wide, s0 }
                } else {
                    Gap::Same
                }
            }
            None => Gap::Same,
        },
        Orientation::Clockwise => Gap::Reflex {
            ts: border_crossing(i, j),
        },
        Orientation::Collinear => {
            if (i.far - c).dot(j.far - c) < 0.0 {
                Gap::Straight
            } else {
                Gap::Same
            }
        }
    }
}

/// Builds the plan: segments, trims, cuts and junction polygons.
pub(crate) fn plan(roads: &[MapRoad], o: &RoadSurfaceOptions) -> Plan {
    let mut p = Plan::default();
    // Room for every point and segment (an upper bound); the maps are looked up only,
    // never iterated, so their order does not reach the plan.
    let points: usize = roads.iter().map(|r| r.points.len()).sum();
    p.nodes.reserve(points);
    p.edges.reserve(points);
    let mut index: HashMap<[u64; 2], usize, FxBuild> =
        HashMap::with_capacity_and_hasher(points, FxBuild::default());
    let mut node = |nodes: &mut Vec<PlanNode>, q: DVec2| -> usize {
        *index.entry(key(q)).or_insert_with(|| {
            nodes.push(PlanNode {
                pos: q,
                ends: Vec::new(),
            });
            nodes.len() - 1
        })
    };
    let mut pair: HashMap<(usize, usize), usize, FxBuild> =
        HashMap::with_capacity_and_hasher(points, FxBuild::default());
    for (r, road) in roads.iter().enumerate() {
        let half = road.width_m / 2.0;
        if half.is_nan() || half <= 0.0 {
            continue;
        }
        let mut s = 0.0;
        let mut prev: Option<DVec2> = None;
        for &q in &road.points {
            let Some(a) = prev.filter(|&a| a != q) else {
                prev = Some(q);
                continue;
            };
            let len = (q - a).length();
            let (na, nb) = (node(&mut p.nodes, a), node(&mut p.nodes, q));
            let e = p.edges.len();
            p.edges.push(PlanEdge {
                road: r,
                a: na,
                b: nb,
                s_a: s,
                len,
                half,
                cut_a: [a; 2],
                cut_b: [q; 2],
                trim: [0.0; 2],
                dropped: false,
                internal: false,
            });
            // Two segments between the same nodes: keep the wider one.
            let k = (na.min(nb), na.max(nb));
            match pair.get(&k) {
                Some(&other) if p.edges[other].half >= half => p.edges[e].dropped = true,
                Some(&other) => {
                    p.edges[other].dropped = true;
                    pair.insert(k, e);
                }
                None => {
                    pair.insert(k, e);
                }
            }
            s += len;
            prev = Some(q);
        }
    }
    p.report.duplicate_segments = p.edges.iter().filter(|e| e.dropped).count();
    for (e, edge) in p.edges.iter().enumerate() {
        if !edge.dropped {
            p.nodes[edge.a].ends.push((e, true));
            p.nodes[edge.b].ends.push((e, false));
        }
    }
    // Every node's ends sorted around it, and the gaps between them, in flat arrays.
    let kept = 2 * p.edges.iter().filter(|e| !e.dropped).count();
    let mut ends: PerNode<End> = PerNode::with_capacity(p.nodes.len(), kept);
    for n in &mut p.nodes {
        sorted_ends(n, &p.edges, &mut ends);
    }
    // Pass 1: the trim each junction wants.
    let mut gaps: PerNode<Gap> = PerNode::with_capacity(p.nodes.len(), kept);
    for (v, es) in ends.iter().enumerate() {
        let c = p.nodes[v].pos;
        let k = es.len();
        if k >= 2 {
            gaps.push_node((0..k).map(|i| classify(c, &es[i], &es[(i + 1) % k])));
        } else {
            gaps.push_node(std::iter::empty());
        }
        let g = &gaps[v];
        if !is_straight(g) {
            for (i, gap) in g.iter().enumerate() {
                want_gap(&mut p.edges, &es[i], &es[(i + 1) % k], *gap);
            }
            if k >= 2 {
                for end in es {
                    want_trim(&mut p.edges, end, MIN_TRIM_HALF_WIDTHS * end.w);
                }
            }
        }
    }
    // Pass 1b: junctions joined by a segment shorter than the cuts they want at its ends
    // merge into one polygon around both (a jogged crossing, a fork on a short stem).
    // One round: merging can lengthen the cuts of the merged junction's roads and make
    // another segment too short; that one is clamped (merging again would grow groups
    // around faces, which are left unmerged, and lose more than it gains).
    p.rep = (0..p.nodes.len()).collect();
    p.merged = vec![false; p.nodes.len()];
    let clusters = find_clusters(&p, &ends);
    apply_clusters(&mut p, &ends, &gaps, &clusters);
    p.report.merged_junctions = clusters.len();
    // Pass 2: a segment too short for both trims is shared in proportion.
    for e in p.edges.iter_mut().filter(|e| !e.dropped && !e.internal) {
        let sum = e.trim[0] + e.trim[1];
        if sum > e.len {
            let f = e.len / sum;
            e.trim = [e.trim[0] * f, e.trim[1] * f];
            p.report.clamped_segments += 1;
        }
    }
    // Pass 3: cuts and polygons.
    for (v, es) in ends.iter().enumerate() {
        let c = p.nodes[v].pos;
        if p.merged[v] {
            continue;
        }
        let ring = match es.len() {
            0 => continue,
            1 => dead_end(c, &es[0], &mut p.edges, o.end_cap),
            _ if is_straight(&gaps[v]) => {
                for end in es {
                    set_cut(&mut p.edges, end, cut(c, end, 0.0));
                }
                continue;
            }
            _ => junction(c, es, &gaps[v], &mut p.edges, &mut p.report),
        };
        let Some(ring) = ring else { continue };
        push_junction(&mut p, v, ring);
    }
    for cl in &clusters {
        let ring = cluster_junction(&p.nodes, &ends, &gaps, cl, &mut p.edges, &mut p.report);
        if let Some(ring) = ring {
            push_junction(&mut p, cl.nodes[0], ring);
        }
    }
    p.report.junctions = p.junctions.len();
    p
}

/// Triangulates a junction ring and keeps it (or counts it as skipped).
fn push_junction(p: &mut Plan, v: usize, ring: Vec<DVec2>) {
    let polygon = PolygonWithHoles::new(Polygon::new(ring.clone()), Vec::new());
    match triangulate(&polygon) {
        Ok(triangles) if !triangles.is_empty() => p.junctions.push(Junction {
            node: v,
            ring,
            triangles,
        }),
        _ => p.report.skipped_junctions += 1,
    }
}

/// Whether the gaps are those of a node where one road simply continues (two roads,
/// exactly opposite): no junction polygon, the ribbons meet at a square cut.
fn is_straight(gaps: &[Gap]) -> bool {
    gaps.len() == 2 && gaps.iter().all(|g| *g == Gap::Straight)
}

/// Appends node `n`'s ends, sorted counter-clockwise, to `ends` (and puts `n.ends` in
/// that order).
fn sorted_ends(n: &mut PlanNode, edges: &[PlanEdge], ends: &mut PerNode<End>) {
    let c = n.pos;
    let es = ends.push_node(n.ends.iter().map(|&(edge, starts)| {
        let e = &edges[edge];
        let far = if starts { e.cut_b[0] } else { e.cut_a[0] };
        End {
            edge,
            starts,
            far,
            d: (far - c) / e.len,
            w: e.half,
        }
    }));
    // Stable: equal directions (overlapping segments) keep the input order.
    es.sort_by(|x, y| ccw_cmp(c, x.far, y.far, AngleStart::East));
    for (slot, e) in n.ends.iter_mut().zip(es.iter()) {
        *slot = (e.edge, e.starts);
    }
}

/// Lists of every node in one flat array: node `v`'s are `items[start[v]..start[v + 1]]`
/// (one allocation for all nodes instead of one per node).
#[derive(Debug)]
struct PerNode<T> {
    items: Vec<T>,
    start: Vec<usize>,
}

impl<T> PerNode<T> {
    fn with_capacity(nodes: usize, items: usize) -> Self {
        let mut start = Vec::with_capacity(nodes + 1);
        start.push(0);
        PerNode {
            items: Vec::with_capacity(items),
            start,
        }
    }

    /// Adds the next node's list and returns it.
    fn push_node(&mut self, list: impl IntoIterator<Item = T>) -> &mut [T] {
        let from = self.items.len();
        self.items.extend(list);
        self.start.push(self.items.len());
        &mut self.items[from..]
    }

    /// Each node's list, in node order.
    fn iter(&self) -> impl Iterator<Item = &[T]> {
        self.start.windows(2).map(|w| &self.items[w[0]..w[1]])
    }
}

impl<T> std::ops::Index<usize> for PerNode<T> {
    type Output = [T];
    fn index(&self, v: usize) -> &[T] {
        &self.items[self.start[v]..self.start[v + 1]]
    }
}

fn slot(end: &End) -> usize {
    usize::from(!end.starts)
}

fn want_trim(edges: &mut [PlanEdge], end: &End, t: f64) {
    let tr = &mut edges[end.edge].trim[slot(end)];
    if t > *tr {
        *tr = t;
    }
}

fn trim_of(edges: &[PlanEdge], end: &End) -> f64 {
    edges[end.edge].trim[slot(end)]
}

/// The cut of `end` at distance `t`: its right and left corner seen from the node.
fn cut(c: DVec2, end: &End, t: f64) -> [DVec2; 2] {
    let m = c + end.d * t;
    let n = end.n() * end.w;
    [m - n, m + n]
}

/// Stores a cut given as seen from the node: the ribbon's corners seen from `a` to `b` are
/// the same at `a` and swapped at `b`.
fn set_cut(edges: &mut [PlanEdge], end: &End, [r, l]: [DVec2; 2]) {
    let e = &mut edges[end.edge];
    if end.starts {
        e.cut_a = [r, l];
    } else {
        e.cut_b = [l, r];
    }
}

fn dead_end(c: DVec2, end: &End, edges: &mut [PlanEdge], cap: EndCap) -> Option<Vec<DVec2>> {
    let [r, l] = cut(c, end, 0.0);
    set_cut(edges, end, [r, l]);
    let (n, back) = (end.n() * end.w, -end.d * end.w);
    let mut ring = vec![r, l];
    match cap {
        EndCap::Flat => return None,
        EndCap::Square => ring.extend([l + back, r + back]),
        EndCap::Round { segments } => {
            let m = segments.max(2);
            for k in 1..m {
                let phi = std::f64::consts::PI * f64::from(k) / f64::from(m);
                ring.push(c + n * phi.cos() + back * phi.sin());
            }
        }
    }
    Some(ring)
}

fn junction(
    c: DVec2,
    es: &[End],
    gaps: &[Gap],
    edges: &mut [PlanEdge],
    report: &mut RoadSurfaceReport,
) -> Option<Vec<DVec2>> {
    let k = es.len();
    let trims: Vec<f64> = es.iter().map(|e| trim_of(edges, e)).collect();
    let mut cuts: Vec<[DVec2; 2]> = es.iter().zip(&trims).map(|(e, &t)| cut(c, e, t)).collect();
    let mut extra: Vec<Vec<DVec2>> = vec![Vec::new(); k];
    let mut clean = true;
    for i in 0..k {
        let j = (i + 1) % k;
        let ends = [(&es[i], trims[i], cuts[i]), (&es[j], trims[j], cuts[j])];
        let (ci, cj, ok) = gap_corner(c, ends, gaps[i], &mut extra[i], report);
        cuts[i] = ci;
        cuts[j] = cj;
        clean &= ok;
    }
    let mut ring: Vec<DVec2> = Vec::with_capacity(4 * k);
    for i in 0..k {
        ring.extend(cuts[i]);
        ring.extend(&extra[i]);
    }
    dedup_ring(&mut ring);
    for (e, cut) in es.iter().zip(&cuts) {
        set_cut(edges, e, *cut);
    }
    if clean && star_shaped(c, &ring) {
        return Some(ring);
    }
    // Overlapping or clamped roads: the convex hull of every corner covers the junction.
    report.approximated_junctions += 1;
    let hull = convex_hull(ring);
    (hull.len() >= 3).then_some(hull)
}

/// The corner in the gap between end `i` and the next end `j` (counter-clockwise) at node
/// `c`, each given with its trim and cut: pushes the ring vertices between `i`'s cut and
/// `j`'s onto `extra` and returns both cuts, a cut corner moved onto the gap's corner when
/// they coincide. `false` in the last place when the gap cannot be joined (overlapping
/// roads).
fn gap_corner(
    c: DVec2,
    [(ei, ti, mut ci), (ej, tj, mut cj)]: [(&End, f64, [DVec2; 2]); 2],
    gap: Gap,
    extra: &mut Vec<DVec2>,
    report: &mut RoadSurfaceReport,
) -> ([DVec2; 2], [DVec2; 2], bool) {
    let bevel = [c + ei.n() * ei.w, c - ej.n() * ej.w];
    match gap {
        Gap::Convex { t, s } => {
            let corner = c + ei.d * t + ei.n() * ei.w;
            join_at(corner, (t, ti), (s, tj), (&mut ci, &mut cj), extra, report);
        }
        Gap::Wide { i_wide, s0 } => {
            // Along the wide road's end line to the narrow road's border, then out.
            let (wide, narrow, tn) = if i_wide { (ei, ej, tj) } else { (ej, ei, ti) };
            let end = if i_wide { bevel[0] } else { bevel[1] };
            let side = if i_wide { -1.0 } else { 1.0 };
            let meet = c + narrow.d * s0 + narrow.n() * (side * narrow.w);
            let tol = SNAP * (wide.w + narrow.w + s0);
            if s0 > tn + tol {
                report.clamped_corners += 1;
                extra.push(end);
            } else if i_wide {
                extra.push(end);
                if tn - s0 <= tol {
                    cj[0] = meet;
                } else {
                    extra.push(meet);
                }
            } else {
                if tn - s0 <= tol {
                    ci[1] = meet;
                } else {
                    extra.push(meet);
                }
                extra.push(end);
            }
        }
        Gap::Straight => extra.extend(bevel),
        Gap::Reflex { ts } => {
            let miter = ts.and_then(|(t, s)| {
                let q = c + ei.d * t + ei.n() * ei.w;
                let limit = MITER_LIMIT * ei.w.max(ej.w) * (1.0 + MITER_SLACK);
                (t <= ti && s <= tj && (q - c).length() <= limit).then_some(q)
            });
            match miter {
                Some(q) => extra.push(q),
                None => extra.extend(bevel),
            }
        }
        Gap::Same => return (ci, cj, false),
    }
    (ci, cj, true)
}

/// Joins the left border of `i` to the right border of `j` at `corner`, `t` along `i`
/// and `s` along `j` (with their trims `ti`, `tj`): a cut corner that coincides with it
/// becomes it, else it is an extra ring vertex; a chord if a trim was clamped short of it.
fn join_at(
    corner: DVec2,
    (t, ti): (f64, f64),
    (s, tj): (f64, f64),
    (ci, cj): (&mut [DVec2; 2], &mut [DVec2; 2]),
    extra: &mut Vec<DVec2>,
    report: &mut RoadSurfaceReport,
) {
    let tol = SNAP * ((ci[1] - ci[0]).length() + (cj[1] - cj[0]).length() + t + s);
    if t <= ti + tol && s <= tj + tol {
        match (ti - t <= tol, tj - s <= tol) {
            (true, true) => cj[0] = ci[1],
            (true, false) => {}
            (false, true) => cj[0] = corner,
            (false, false) => extra.push(corner),
        }
    } else {
        // Trims clamped by a short segment: the corner lies beyond a cut.
        report.clamped_corners += 1;
    }
}

/// Marks the merged junctions: their nodes, their inner segments, and the cuts their
/// outside roads want (recomputed from the merged polygon's corners).
fn apply_clusters(p: &mut Plan, ends: &PerNode<End>, gaps: &PerNode<Gap>, clusters: &[Cluster]) {
    p.rep = (0..p.nodes.len()).collect();
    p.merged = vec![false; p.nodes.len()];
    for e in &mut p.edges {
        e.internal = false;
    }
    for cl in clusters {
        for &v in &cl.nodes {
            p.rep[v] = cl.nodes[0];
            p.merged[v] = true;
        }
        for &e in &cl.internal {
            p.edges[e].internal = true;
        }
        for &(v, k) in &cl.seq {
            let end = &ends[v][k];
            p.edges[end.edge].trim[slot(end)] = 0.0;
        }
        let m = cl.seq.len();
        for i in 0..m {
            let (a, b) = (cl.seq[i], cl.seq[(i + 1) % m]);
            let (ea, eb) = (&ends[a.0][a.1], &ends[b.0][b.1]);
            match link(&p.nodes, ends, gaps, a, b) {
                Link::Node(gap) => want_gap(&mut p.edges, ea, eb, gap),
                Link::Cross(Some((t, s))) => {
                    want_trim(&mut p.edges, ea, t);
                    want_trim(&mut p.edges, eb, s);
                }
                Link::Cross(None) => {}
            }
        }
        for &(v, k) in &cl.seq {
            let end = &ends[v][k];
            want_trim(&mut p.edges, end, MIN_TRIM_HALF_WIDTHS * end.w);
        }
    }
}

/// Records the trims a gap between `ei` and the next end `ej` wants.
fn want_gap(edges: &mut [PlanEdge], ei: &End, ej: &End, gap: Gap) {
    match gap {
        Gap::Convex { t, s } => {
            want_trim(edges, ei, t);
            want_trim(edges, ej, s);
        }
        Gap::Wide { i_wide: true, s0 } => want_trim(edges, ej, s0),
        Gap::Wide { i_wide: false, s0 } => want_trim(edges, ei, s0),
        _ => {}
    }
}

/// Nodes joined by segments too short for their cuts, the segments, and the outside
/// ends in counter-clockwise order around them as `(node, index into its ends)`.
#[derive(Debug)]
struct Cluster {
    nodes: Vec<usize>,
    internal: Vec<usize>,
    seq: Vec<(usize, usize)>,
}

fn root(parent: &mut [usize], mut v: usize) -> usize {
    while parent[v] != v {
        parent[v] = parent[parent[v]];
        v = parent[v];
    }
    v
}

fn far_node(edges: &[PlanEdge], end: &End) -> usize {
    let e = &edges[end.edge];
    if end.starts { e.b } else { e.a }
}

/// Merges the ends of every segment whose two cuts overlap (neither end a dead end) and
/// keeps the groups whose short segments form a tree (a group around a face, or with
/// another segment inside, stays as it is: its segments are clamped).
fn find_clusters(p: &Plan, ends: &PerNode<End>) -> Vec<Cluster> {
    let n = p.nodes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    for e in p.edges.iter().filter(|e| !e.dropped) {
        if e.trim[0] + e.trim[1] > e.len && ends[e.a].len() >= 2 && ends[e.b].len() >= 2 {
            let (a, b) = (root(&mut parent, e.a), root(&mut parent, e.b));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let roots: Vec<usize> = (0..n).map(|v| root(&mut parent, v)).collect();
    // Only sets of two nodes or more can merge: no group (and no allocation) for the
    // others. A set's nodes in ascending order (its root, the least, first).
    let mut size = vec![0u32; n];
    for &r in &roots {
        size[r] += 1;
    }
    let mut groups: BTreeMap<usize, Cluster> = BTreeMap::new();
    for (v, &r) in roots.iter().enumerate() {
        if size[r] < 2 {
            continue;
        }
        groups
            .entry(r)
            .or_insert_with(|| Cluster {
                nodes: Vec::new(),
                internal: Vec::new(),
                seq: Vec::new(),
            })
            .nodes
            .push(v);
    }
    for (e, edge) in p.edges.iter().enumerate().filter(|(_, e)| !e.dropped) {
        if roots[edge.a] == roots[edge.b]
            && let Some(g) = groups.get_mut(&roots[edge.a])
        {
            g.internal.push(e);
        }
    }
    let mut out = Vec::new();
    for (r, mut g) in groups {
        if g.nodes.len() < 2 || g.internal.len() + 1 != g.nodes.len() {
            continue;
        }
        if let Some(seq) = walk_outside(&p.edges, ends, &roots, r, &g.nodes) {
            g.seq = seq;
            out.push(g);
        }
    }
    out
}

/// The outside ends of a tree of short segments in counter-clockwise order: around each
/// node in its order, crossing every inner segment to continue after it at its far node.
fn walk_outside(
    edges: &[PlanEdge],
    ends: &PerNode<End>,
    roots: &[usize],
    r: usize,
    nodes: &[usize],
) -> Option<Vec<(usize, usize)>> {
    let start = nodes.iter().find_map(|&v| {
        ends[v]
            .iter()
            .position(|x| roots[far_node(edges, x)] != r)
            .map(|k| (v, k))
    })?;
    let limit = 2 * nodes.iter().map(|&v| ends[v].len()).sum::<usize>() + 2;
    let (mut v, mut k) = start;
    let mut seq = Vec::new();
    for _ in 0..limit {
        let end = ends[v].get(k)?;
        let u = far_node(edges, end);
        if roots[u] == r {
            let twin = ends[u].iter().position(|x| x.edge == end.edge)?;
            v = u;
            k = (twin + 1) % ends[u].len();
        } else {
            seq.push((v, k));
            k = (k + 1) % ends[v].len();
        }
        if (v, k) == start {
            return Some(seq);
        }
    }
    None
}

/// How two consecutive outside ends of a merged junction meet.
enum Link {
    /// At one node, next to each other: the gap between them.
    Node(Gap),
    /// From different nodes: where the left border of the first meets the right border
    /// of the second (distances along each from its node), unless far behind either.
    Cross(Option<(f64, f64)>),
}

fn link(
    nodes: &[PlanNode],
    ends: &PerNode<End>,
    gaps: &PerNode<Gap>,
    (v, k): (usize, usize),
    (u, l): (usize, usize),
) -> Link {
    if v == u
        && ends[v].len() >= 2
        && l == (k + 1) % ends[v].len()
        && let Some(&g) = gaps[v].get(k)
    {
        return Link::Node(g);
    }
    let (ei, ej) = (&ends[v][k], &ends[u][l]);
    let denom = ei.d.perp_dot(ej.d);
    if denom <= 0.0 {
        return Link::Cross(None);
    }
    let q = (nodes[u].pos - ej.n() * ej.w) - (nodes[v].pos + ei.n() * ei.w);
    let (t, s) = (q.perp_dot(ej.d) / denom, q.perp_dot(ei.d) / denom);
    // The crossing may lie a little behind a road's node (towards the other node, as at a
    // jogged crossing), not far behind (nearly parallel roads).
    let reach = (nodes[u].pos - nodes[v].pos).length() + ei.w + ej.w;
    let ok = t.is_finite() && s.is_finite() && t >= -reach && s >= -reach;
    Link::Cross(ok.then_some((t, s)))
}

/// The polygon of a merged junction: the cuts of its outside ends joined by their
/// corners; the convex hull if that is not a simple counter-clockwise ring.
fn cluster_junction(
    nodes: &[PlanNode],
    ends: &PerNode<End>,
    gaps: &PerNode<Gap>,
    cl: &Cluster,
    edges: &mut [PlanEdge],
    report: &mut RoadSurfaceReport,
) -> Option<Vec<DVec2>> {
    let m = cl.seq.len();
    let es: Vec<&End> = cl.seq.iter().map(|&(v, k)| &ends[v][k]).collect();
    let origin: Vec<DVec2> = cl.seq.iter().map(|&(v, _)| nodes[v].pos).collect();
    let trims: Vec<f64> = es.iter().map(|e| trim_of(edges, e)).collect();
    let mut cuts: Vec<[DVec2; 2]> = (0..m).map(|i| cut(origin[i], es[i], trims[i])).collect();
    let mut extra: Vec<Vec<DVec2>> = vec![Vec::new(); m];
    let mut clean = true;
    for i in 0..m {
        let j = (i + 1) % m;
        let (ei, ej) = (es[i], es[j]);
        match link(nodes, ends, gaps, cl.seq[i], cl.seq[j]) {
            Link::Node(gap) => {
                let pair = [(ei, trims[i], cuts[i]), (ej, trims[j], cuts[j])];
                let (ci, cj, ok) = gap_corner(origin[i], pair, gap, &mut extra[i], report);
                cuts[i] = ci;
                cuts[j] = cj;
                clean &= ok;
            }
            Link::Cross(Some((t, s))) => {
                let corner = origin[i] + ei.d * t + ei.n() * ei.w;
                let (mut ci, mut cj) = (cuts[i], cuts[j]);
                join_at(
                    corner,
                    (t, trims[i]),
                    (s, trims[j]),
                    (&mut ci, &mut cj),
                    &mut extra[i],
                    report,
                );
                cuts[i] = ci;
                cuts[j] = cj;
            }
            Link::Cross(None) => {
                extra[i].extend([origin[i] + ei.n() * ei.w, origin[j] - ej.n() * ej.w]);
            }
        }
    }
    let mut ring: Vec<DVec2> = Vec::with_capacity(4 * m);
    for i in 0..m {
        ring.extend(cuts[i]);
        ring.extend(&extra[i]);
    }
    dedup_ring(&mut ring);
    for (e, cut) in es.iter().zip(&cuts) {
        set_cut(edges, e, *cut);
    }
    let simple = ring.len() >= 3
        && ring_signed_area(&ring) > 0.0
        && Polygon::new(ring.clone()).validate().is_ok();
    if clean && simple {
        return Some(ring);
    }
    report.approximated_junctions += 1;
    ring.extend(cl.nodes.iter().map(|&v| nodes[v].pos));
    let hull = convex_hull(ring);
    (hull.len() >= 3).then_some(hull)
}

/// Drops consecutive repeated points (and a closing repeat).
fn dedup_ring(ring: &mut Vec<DVec2>) {
    ring.dedup();
    while ring.len() > 1 && ring.first() == ring.last() {
        ring.pop();
    }
}

/// Whether every vertex sees the next counter-clockwise from `c` (turning less than a
/// half-turn; decided exactly) and the ring winds once around `c`: then the ring is simple
/// and star-shaped from `c`.
pub(crate) fn star_shaped(c: DVec2, ring: &[DVec2]) -> bool {
    if ring.len() < 3 {
        return false;
    }
    // Each step turns by less than a half-turn, so the sum of the turns (within rounding)
    // tells one winding from none or two.
    let mut turned = 0.0;
    for (k, &a) in ring.iter().enumerate() {
        let b = ring[(k + 1) % ring.len()];
        if a == c || b == c {
            return false;
        }
        let (da, db) = (a - c, b - c);
        if orient2d(c, a, b) != Orientation::CounterClockwise {
            // Two points on one ray from `c` (a step along a road's end line, computed
            // points off the ray by rounding) are allowed; anything turning back is not.
            let along = da.dot(db) > 0.0
                && orient2d_value(c, a, b).abs() <= COLLINEAR * da.length() * db.length();
            if !along {
                return false;
            }
        }
        turned += da.perp_dot(db).atan2(da.dot(db));
    }
    (turned - std::f64::consts::TAU).abs() < 1e-6
}

/// The convex hull, counter-clockwise, without collinear points (Andrew's monotone chain
/// on exact orientations).
pub(crate) fn convex_hull(mut pts: Vec<DVec2>) -> Vec<DVec2> {
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let mut hull: Vec<DVec2> = Vec::with_capacity(pts.len() + 1);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && orient2d(hull[hull.len() - 2], hull[hull.len() - 1], q)
                    != Orientation::CounterClockwise
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}
