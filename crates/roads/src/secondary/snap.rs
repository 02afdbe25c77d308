//! Kelly's snap algorithm for secondary growth (§4.3.3), on a cell's private graph.
//!
//! The query is a proposed segment `a–b` from an existing node `a` and a snap size. The
//! answer is the single highest-priority *snap event*, priority being closeness to the
//! root `a`, measured by the parameter `r` along `a–b`:
//!
//! 1. **Extended bounding box exclusion** (§4.3.3.1): only roads whose boxes meet the box
//!    of `a–b` grown by the snap size are tested (candidates come from a flat grid over
//!    the cell that lists every road with its ends, so the search reads no graph; then
//!    Kelly's box test decides), and only their end nodes that lie in that box (every
//!    node of a cell graph ends a road, so no node search is needed).
//! 2. **Test 1, node proximity** (§4.3.3.3): for each node, `r = ap·ab / |ab|²` and
//!    `s = ap⊥·ab / |ab|²`; a node with `0 < r ≤ 1` and `|s|·|ab| ≤ snap` is an event at
//!    `r`; one with `1 < r ≤ 1 + snap/|ab|` is an event if it lies within the snap size of
//!    `b`. The best `r` so far is the benchmark: only smaller `r` are tested further.
//! 3. **Test 2, segment intersection** (§4.3.3.4): only roads whose boxes meet the box
//!    of `a–b` itself (not grown) can cross it, so only their ends get test 1's `r` and
//!    `s` and an exact side (the other roads' ends, often outside the extended box, are
//!    never computed). A road whose end nodes lie strictly on opposite sides of the line
//!    `ab` (the sign of `s`, decided exactly by `orient2d`) meets the line at
//!    `r = (r_u·|s_v| + r_v·|s_u|) / (|s_u| + |s_v|)`, known without computing the
//!    intersection; only when that `r` beats the benchmark is the exact crossing test run.
//! 4. **Test 3, segment proximity** (§4.3.3.5): only if tests 1 and 2 found nothing,
//!    the road nearest to `b` within the snap size gives a road event at `b`'s end.
//!
//! Events on the root's own roads (a node adjacent to `a`, a road at `a`) are reported
//! as [`SnapEvent::Blocked`]: joining them would duplicate or fold onto an existing road.
//! Before step 1, **test 0** (ours, not Kelly's) looks at the root's own roads only: a
//! proposal with one of them in its snap area (the road's other end by test 1's rule, or
//! `b` within the snap size of the road) is `Blocked` at once. With degree 18 most
//! directions of a suburban node are such folds; answering them without the grid
//! search roughly halves the growth's time. It differs from the full search only when a
//! non-adjacent node or road lies in the snap area nearer to the root than the fold,
//! which the full search would have joined instead. Growth answers test 0 before the
//! proposal's draws where the fold holds for every draw the proposal could make (its
//! `FoldBound`), stepping the generator past them, so the roads are the same.
//!
//! A proposal that passes test 0 has none of the root's neighbours in its snap area by
//! test 1's own arithmetic (and the root itself has `r = 0`), and test 2 cannot cross a
//! road at the root; so the grid walk leaves the root's roads out of the candidates of
//! tests 1 and 2 (it stamps them as reported before it starts), and only test 3 and
//! [`candidates`](Snapper::candidates) read them, from the grid's table. About 30 % of
//! the road ends test 1 met were those of the root's roads, and whether a road was one
//! followed no pattern a processor could predict.

use polis_geom::predicates::{Orientation, lerp_stable, orient2d};
use polis_geom::{Aabb2, DVec2, EdgeId, NodeId};

use super::grid::{GridRoad, SnapGrid};
use crate::network::RoadNetwork;

/// The outcome of one snap query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SnapEvent {
    /// Nothing within the snap area: the segment may end at `b` as proposed.
    None,
    /// An existing node within the snap area (test 1).
    Node(NodeId),
    /// The segment crosses road `edge` at `point` (test 2).
    Cross(EdgeId, DVec2),
    /// `b` lies within the snap size of road `edge`, whose closest point is `point`
    /// (test 3).
    Road(EdgeId, DVec2),
    /// The first event is on a road at the root: the proposal would fold onto it.
    Blocked,
}

/// The snap algorithm with its per-query scratch (reused between queries).
#[derive(Debug, Default, Clone)]
pub struct Snapper {
    /// By node id: the query that last met the node in its extended box.
    seen: Vec<u32>,
    query: u32,
    roads: Vec<GridRoad>,
    /// The root of the last query, when it searched the grid (its roads are not in
    /// `roads`).
    root: Option<NodeId>,
    /// Scratch of [`snap`](Self::snap): the root's roads' far ends.
    root_ends: Vec<(NodeId, DVec2)>,
    /// Exact segment-intersection tests run (the rest were excluded by `r`/`s`).
    pub exact_tests: u64,
    /// Roads that passed the extended bounding box.
    pub box_hits: u64,
    /// Queries answered by test 0 (the proposal folds onto a road at its root).
    pub folded: u64,
    /// The flat grid of the graph being grown (see [`begin_cell`](Self::begin_cell)).
    grid: SnapGrid,
}

impl Snapper {
    /// Lays the snap search's flat grid over `bounds` (the cell graph's box) in squares of
    /// about `square_m` metres, and empties it. Every query until the next call must be on
    /// the same graph, which may only gain roads, and split or remove roads reported with
    /// [`touched`](Self::touched) before the next query (as growth does); the grid then
    /// lists every road of the graph as it is. Without a call, the first query lays a grid
    /// of 64 m squares over its graph.
    pub fn begin_cell(&mut self, bounds: Aabb2, square_m: f64) {
        self.grid.reset(bounds, square_m);
    }

    fn begin(&mut self, nodes: usize) {
        if self.seen.len() < nodes {
            self.seen.resize(nodes, 0);
        }
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.seen.fill(0);
            self.query = 1;
        }
    }

    /// Whether node `n` is met for the first time in this query (then marked).
    #[inline]
    fn first_sight(&mut self, n: NodeId) -> bool {
        match self.seen.get_mut(n.index()) {
            Some(mark) if *mark == self.query => false,
            Some(mark) => {
                *mark = self.query;
                true
            }
            None => true,
        }
    }

    /// The roads the last query gathered (those whose boxes meet its extended box), with
    /// their ends, each once, in no particular order: the roads of tests 1 and 2, then
    /// the roads at its root (`g` is the graph it searched, unchanged since); none after
    /// a query answered by test 0.
    pub(crate) fn candidates<'s>(
        &'s self,
        g: &'s RoadNetwork,
    ) -> impl Iterator<Item = GridRoad> + 's {
        let at_root = self
            .root
            .into_iter()
            .flat_map(move |root| roads_at(&self.grid, g, root));
        self.roads.iter().copied().chain(at_root)
    }

    /// Counts a proposal that growth found folding onto a road at its root (test 0)
    /// without asking: as [`snap`](Self::snap) counts one it answers by test 0.
    pub(crate) fn count_fold(&mut self) {
        self.folded += 1;
        self.roads.clear();
        self.root = None;
    }

    /// Appends to `out` every road of `g` whose box meets `b`, with its ends, as the
    /// snap grid lists it (each once; the last query's candidates stay as they were).
    pub(crate) fn roads_in(&mut self, g: &RoadNetwork, b: &Aabb2, out: &mut Vec<GridRoad>) {
        self.grid.sync(g);
        self.grid.gather(b, out);
    }

    /// Road `e` of `g` was split or removed since the last query (see
    /// [`begin_cell`](Self::begin_cell)).
    pub fn touched(&mut self, g: &RoadNetwork, e: EdgeId) {
        self.grid.refresh(g, e);
    }

    /// The highest-priority snap event of the proposal from node `root` (at `a`) to `b`
    /// with snap size `radius` (metres, ≥ 0).
    pub fn snap(
        &mut self,
        g: &RoadNetwork,
        root: NodeId,
        a: DVec2,
        b: DVec2,
        radius: f64,
    ) -> SnapEvent {
        let mut ends = std::mem::take(&mut self.root_ends);
        root_ends(g, root, &mut ends);
        let event = self.snap_from(g, root, &ends, a, b, radius);
        self.root_ends = ends;
        event
    }

    /// [`snap`](Self::snap) with the root's roads given: `ends` holds the far end (node
    /// and position) of every road at `root`, in any order, as [`root_ends`] reads them.
    /// Growth keeps them for the node it expands, so test 0 and the adjacency checks
    /// read no graph.
    pub(crate) fn snap_from(
        &mut self,
        g: &RoadNetwork,
        root: NodeId,
        ends: &[(NodeId, DVec2)],
        a: DVec2,
        b: DVec2,
        radius: f64,
    ) -> SnapEvent {
        debug_assert!(
            {
                let mut now = Vec::new();
                root_ends(g, root, &mut now);
                let mut given = ends.to_vec();
                let key = |x: &(NodeId, DVec2)| (x.0, x.1.x.to_bits(), x.1.y.to_bits());
                now.sort_unstable_by_key(key);
                given.sort_unstable_by_key(key);
                now == given
            },
            "the root's roads given are not those of the graph"
        );
        let d = b - a;
        let len2 = d.length_squared();
        if !(len2 > 0.0 && len2.is_finite()) {
            return SnapEvent::Blocked;
        }
        let len = len2.sqrt();
        let radius = radius.max(0.0);
        if folds_onto_root(ends, a, b, radius) {
            self.count_fold();
            return SnapEvent::Blocked;
        }
        self.begin(g.node_bound());
        let ext = Aabb2::new(a, b).expanded(radius);
        // Extended bounding box exclusion: the roads whose boxes meet the extended box.
        // Every node of a cell graph ends a road, and a node in the extended box ends a
        // road whose box meets it, so the ends of these roads are test 1's candidates too.
        // The roads at the root (all of them meet the box, which holds `a`) are left out:
        // after test 0 none of their ends is a node event of test 1 (the root has
        // `r = 0`; a far end in the snap area would have folded by the same arithmetic),
        // and test 2 cannot cross them. Test 3 and `candidates` read them apart.
        let mut roads = std::mem::take(&mut self.roads);
        roads.clear();
        self.grid.sync(g);
        let at_root = g.edges_at(root).unwrap_or_default();
        self.grid.gather_apart(&ext, at_root, &mut roads);
        self.root = Some(root);
        debug_assert!(
            roads.iter().all(|r| r.u != root
                && r.v != root
                && GridRoad::of(g, r.edge)
                    .is_some_and(|c| (c.u, c.v, c.pu, c.pv) == (r.u, r.v, r.pu, r.pv))),
            "the snap grid is out of date: a split or removed road was not reported"
        );
        // The grid reports each road once, in an order fixed by the growth so far; every
        // choice below breaks ties by id, so the order does not matter.
        self.box_hits += (roads.len() + ends.len()) as u64;
        // Test 1: node proximity, over the ends of these roads in the extended box (each
        // node once; only `r` and `s` are needed here).
        let mut best: Option<(f64, NodeId)> = None;
        let mut best_r = 1.0 + radius / len;
        let mut node = |n: NodeId, p: DVec2| {
            if !ext.contains(p) {
                return;
            }
            // `r` (as `along` computes it) is positive only for a positive `ap·ab`: the
            // nodes behind the root need no division and no mark.
            let ap = p - a;
            let dot = ap.dot(d);
            let ahead = dot > 0.0;
            if !ahead || !self.first_sight(n) {
                return;
            }
            let r = dot / len2;
            let better = r < best_r || (r == best_r && best.is_some_and(|(_, m)| n < m));
            if !(r > 0.0 && better) {
                return;
            }
            let hit = if r <= 1.0 {
                (d.perp_dot(ap) / len2).abs() * len <= radius
            } else {
                p.distance_squared(b) <= radius * radius
            };
            if hit {
                best_r = r;
                best = Some((r, n));
            }
        };
        for road in &roads {
            node(road.u, road.pu);
            node(road.v, road.pv);
        }
        // Test 2: segment intersection before the benchmark. A road that crosses `a–b`
        // meets the segment's own box, so only those roads are tested (the exact test
        // below would refuse the others).
        let limit = best_r.min(1.0);
        let segment_box = Aabb2::new(a, b);
        let mut cross: Option<(f64, usize, DVec2)> = None;
        for (i, road) in roads.iter().enumerate() {
            let (pu, pv) = (road.pu, road.pv);
            if !Aabb2::new(pu, pv).intersects(&segment_box) {
                continue;
            }
            // The exact sides first: most roads here lie on one side of the line ab, and
            // their `r` and `s` (two divisions each) are not needed.
            if side(pu, a, b) * side(pv, a, b) >= 0 {
                continue; // same side of the line ab, or touching it (a node event)
            }
            let (ru, su) = along(pu, a, d, len2);
            let (rv, sv) = along(pv, a, d, len2);
            let (wu, wv) = (su.abs(), sv.abs());
            let r = (ru * wv + rv * wu) / (wu + wv);
            let bound = cross.map_or(limit, |(cr, _, _)| cr);
            if !(r > 0.0 && r <= bound) {
                continue;
            }
            self.exact_tests += 1;
            let oa = orient2d(pu, pv, a);
            let ob = orient2d(pu, pv, b);
            let opposite = matches!(
                (oa, ob),
                (Orientation::Clockwise, Orientation::CounterClockwise)
                    | (Orientation::CounterClockwise, Orientation::Clockwise)
            );
            if !opposite {
                continue;
            }
            let better = cross.is_none_or(|(cr, ci, _)| {
                r < cr || (r == cr && roads.get(ci).is_none_or(|c| road.edge < c.edge))
            });
            if better {
                let point = pu + (pv - pu) * (wu / (wu + wv));
                cross = Some((r, i, point));
            }
        }
        // A node is adjacent to the root when it ends one of the root's roads.
        let adjacent = |n: NodeId| ends.iter().any(|&(m, _)| m == n);
        // A crossing within the snap size of an end of the crossed road joins that end
        // (the nearer one) instead of splitting the road next to it.
        let cross = cross.and_then(|(r, i, p)| {
            let road = roads.get(i)?;
            let (du, dv) = (road.pu.distance_squared(p), road.pv.distance_squared(p));
            let (n, dn) = if (du, road.u) <= (dv, road.v) {
                (road.u, du)
            } else {
                (road.v, dv)
            };
            Some((r, road.edge, p, (dn <= radius * radius).then_some(n)))
        });
        let cross_event = |e: EdgeId, p: DVec2, end: Option<NodeId>| match end {
            Some(n) if adjacent(n) => SnapEvent::Blocked,
            Some(n) => SnapEvent::Node(n),
            None => SnapEvent::Cross(e, p),
        };
        let decided = match (best, cross) {
            (Some((r, n)), Some((cr, e, p, end))) => Some(if cr < r {
                cross_event(e, p, end)
            } else if adjacent(n) {
                SnapEvent::Blocked
            } else {
                SnapEvent::Node(n)
            }),
            (Some((_, n)), None) => Some(if adjacent(n) {
                SnapEvent::Blocked
            } else {
                SnapEvent::Node(n)
            }),
            (None, Some((_, e, p, end))) => Some(cross_event(e, p, end)),
            (None, None) => None,
        };
        if let Some(ev) = decided {
            self.roads = roads;
            return ev;
        }
        // Test 3: proximity of b to a road. Every road within the snap size of `b` meets
        // the extended box, so the roads gathered for tests 1 and 2 and the roads at the
        // root are the candidates.
        let around = Aabb2::new(b, b).expanded(radius);
        let r2 = radius * radius;
        let mut near: Option<(f64, GridRoad, DVec2)> = None;
        for road in roads.iter().copied().chain(roads_at(&self.grid, g, root)) {
            let (u, v) = (road.pu, road.pv);
            if !Aabb2::new(u, v).intersects(&around) {
                continue;
            }
            let c = closest_point(b, u, v);
            let dist = c.distance_squared(b);
            let better =
                near.is_none_or(|(bd, o, _)| dist < bd || (dist == bd && road.edge < o.edge));
            if dist <= r2 && better {
                near = Some((dist, road, c));
            }
        }
        let event = match near.map(|(_, road, c)| (road, c)) {
            None => SnapEvent::None,
            Some((road, _)) if road.u == root || road.v == root => SnapEvent::Blocked,
            Some((road, c)) => {
                // The closest point is an end of the road: that is a node event.
                match [(road.u, road.pu), (road.v, road.pv)]
                    .into_iter()
                    .find(|&(_, p)| p == c)
                {
                    Some((n, _)) if adjacent(n) => SnapEvent::Blocked,
                    Some((n, _)) => SnapEvent::Node(n),
                    None => SnapEvent::Road(road.edge, c),
                }
            }
        };
        self.roads = roads;
        event
    }
}

/// The roads at `root`, as the grid lists them (the grid current for `g`).
fn roads_at<'s>(
    grid: &'s SnapGrid,
    g: &'s RoadNetwork,
    root: NodeId,
) -> impl Iterator<Item = GridRoad> + 's {
    g.edges_at(root)
        .into_iter()
        .flatten()
        .filter_map(|&e| grid.road(e))
}

/// The point of segment `u–v` closest to `p`: the arithmetic of
/// [`closest_point_on_segment`], here where it can be inlined into the hot loops.
#[inline]
fn closest_point(p: DVec2, u: DVec2, v: DVec2) -> DVec2 {
    let d = v - u;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return u;
    }
    let t = ((p - u).dot(d) / len2).clamp(0.0, 1.0);
    lerp_stable(u, v, t)
}

/// Test 0: whether the proposal `a–b` from `root` runs within `radius` of one of the
/// root's own roads: that road's other end is in the snap area (test 1's condition), or
/// `b` is within `radius` of the road (test 3's). Such a proposal can only fold onto the
/// road it starts beside, so it is answered before the grid is searched.
pub(super) fn folds_onto_root(ends: &[(NodeId, DVec2)], a: DVec2, b: DVec2, radius: f64) -> bool {
    let d = b - a;
    let len2 = d.length_squared();
    let len = len2.sqrt();
    let r2 = radius * radius;
    ends.iter().any(|&(_, p)| {
        let ap = p - a;
        let along = ap.dot(d);
        if along <= 0.0 {
            // A road at a right angle or more to the proposal: `r ≤ 0` (no node event),
            // and the road's point closest to `b` is `a` itself (the same arithmetic as
            // below: the same dot product, clamped to 0).
            return len2 <= r2;
        }
        let r = along / len2;
        let node = if r > 0.0 && r <= 1.0 {
            (d.perp_dot(ap) / len2).abs() * len <= radius
        } else {
            r > 1.0 && p.distance_squared(b) <= r2
        };
        node || closest_point(b, a, p).distance_squared(b) <= r2
    })
}

/// Fills `out` with the far end (node and position) of every road of `g` at `root`, in
/// the order of its adjacency (empty for a dead node).
pub(crate) fn root_ends(g: &RoadNetwork, root: NodeId, out: &mut Vec<(NodeId, DVec2)>) {
    out.clear();
    let Ok(edges) = g.edges_at(root) else {
        return;
    };
    for &e in edges {
        if let Ok(n) = g.other_end(e, root)
            && let Ok(p) = g.position(n)
        {
            out.push((n, p));
        }
    }
}

/// The exact side of `p` against the directed line `a → b`: 1 left, −1 right, 0 on it.
#[inline]
fn side(p: DVec2, a: DVec2, b: DVec2) -> i8 {
    match orient2d(a, b, p) {
        Orientation::CounterClockwise => 1,
        Orientation::Clockwise => -1,
        Orientation::Collinear => 0,
    }
}

/// Kelly's `r` and `s` of `p` against the segment from `a` along `ab` (`len2 = |ab|²`).
#[inline]
fn along(p: DVec2, a: DVec2, ab: DVec2, len2: f64) -> (f64, f64) {
    let ap = p - a;
    (ap.dot(ab) / len2, ab.perp_dot(ap) / len2)
}

#[cfg(test)]
pub(super) mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::network::{Junction, Road, RoadClass};
    use polis_geom::graph::SnapOptions;

    type Seg = ((f64, f64), (f64, f64));

    /// An 8 m street of step 0 (the payload of the test graphs here and in the grid's).
    pub(in crate::secondary) fn street() -> Road {
        Road {
            class: RoadClass::Street,
            width: 8.0,
            bridge: false,
            tunnel: false,
            step: 0,
        }
    }

    fn net(segs: &[Seg]) -> RoadNetwork {
        let mut n = RoadNetwork::new();
        let road = street();
        for &((ax, ay), (bx, by)) in segs {
            n.insert_segment_with(
                DVec2::new(ax, ay),
                DVec2::new(bx, by),
                road,
                &SnapOptions::default(),
                |_| Junction::default(),
            )
            .unwrap();
        }
        n
    }

    fn node_at(g: &RoadNetwork, x: f64, y: f64) -> NodeId {
        g.nearest_node(DVec2::new(x, y), 1e-9).unwrap().0
    }

    #[test]
    fn the_three_tests_in_priority_order() {
        // A root at (0, 0) with a road going west; a road x = 50 crossing the proposal
        // and a node near the proposal further on.
        let g = net(&[
            ((0.0, 0.0), (-30.0, 0.0)),
            ((50.0, -20.0), (50.0, 20.0)),
            ((80.0, 3.0), (80.0, 30.0)),
            ((200.0, -50.0), (200.0, 50.0)),
        ]);
        let root = node_at(&g, 0.0, 0.0);
        let a = DVec2::ZERO;
        let mut s = Snapper::default();
        s.begin_cell(g.bbox(), 64.0);
        // The crossing at x = 50 comes first.
        let ev = s.snap(&g, root, a, DVec2::new(100.0, 0.0), 5.0);
        assert!(
            matches!(ev, SnapEvent::Cross(_, p) if p == DVec2::new(50.0, 0.0)),
            "{ev:?}"
        );
        // A short proposal ending near the node (80, 3): node event.
        let g2 = net(&[((0.0, 0.0), (-30.0, 0.0)), ((80.0, 3.0), (80.0, 30.0))]);
        let root2 = node_at(&g2, 0.0, 0.0);
        s.begin_cell(g2.bbox(), 64.0);
        let ev = s.snap(&g2, root2, a, DVec2::new(78.0, 0.0), 5.0);
        assert_eq!(ev, SnapEvent::Node(node_at(&g2, 80.0, 3.0)));
        // Ending near the road x = 200 but not near a node: road event at the foot.
        s.begin_cell(g.bbox(), 64.0);
        let ev = s.snap(
            &g,
            root,
            DVec2::new(120.0, 0.0),
            DVec2::new(196.0, 0.0),
            5.0,
        );
        assert!(
            matches!(ev, SnapEvent::Road(_, p) if p == DVec2::new(200.0, 0.0)),
            "{ev:?}"
        );
        // Nothing around: none.
        let ev = s.snap(&g, root, a, DVec2::new(0.0, 40.0), 5.0);
        assert_eq!(ev, SnapEvent::None);
        // Back along its own road: blocked.
        let ev = s.snap(&g, root, a, DVec2::new(-20.0, 1.0), 5.0);
        assert_eq!(ev, SnapEvent::Blocked);
    }

    #[test]
    fn a_node_before_a_crossing_wins() {
        let g = net(&[
            ((0.0, 0.0), (-30.0, 0.0)),
            ((30.0, 2.0), (30.0, 40.0)),
            ((60.0, -20.0), (60.0, 20.0)),
        ]);
        let root = node_at(&g, 0.0, 0.0);
        let ev = Snapper::default().snap(&g, root, DVec2::ZERO, DVec2::new(100.0, 0.0), 5.0);
        assert_eq!(ev, SnapEvent::Node(node_at(&g, 30.0, 2.0)));
    }
}
