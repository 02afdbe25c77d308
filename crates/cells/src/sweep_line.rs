//! A left-to-right line sweep over the working graph (Shamos & Hoey, 1976) that
//! certifies planarity and finds, for every node, the edge directly below it.
//!
//! The events are the nodes in rank order (`(x, y)` lexicographic order, which the
//! [`Topology`] already holds), so no event queue or sort is needed, and vertical edges
//! need no special case. The *status* is the list of active edges (those whose left end
//! has been passed and whose right end has not) ordered bottom to top; while no two
//! edges have met, every comparison in it is one exact orientation test of a node against
//! an edge.
//!
//! At node `p`:
//! 1. the status edges through `p` are located: they must be exactly the edges ending at
//!    `p` (any other one has `p` inside it: a node on an edge), and the edges just outside
//!    them must pass strictly below and above `p`; the edge just below is recorded as
//!    `below[p]`. An edge ending at `p` is looked for near the index where it was
//!    inserted (it drifts only as edges below it come and go); a node with no edge from
//!    the left (a local leftmost point) is placed by binary search;
//! 2. they are replaced by the edges starting at `p`, bottom to top (the graph's exact
//!    rotation order); two of those leaving in the same direction overlap;
//! 3. the new neighbours in the status are tested for contact with the exact segment
//!    test (edges sharing an end node skip it: they can only overlap, which steps 1–2
//!    catch).
//!
//! If any two edges meet other than at a common end node, then just before the leftmost
//! such point two of them are neighbours in the status, or a node lies on an edge: so the
//! sweep reports a contact if and only if the graph is not planar. It stops at the first
//! contact (the order beyond it would not be consistent); listing *all* conflicts is the
//! job of the slower grid check in [`crate::planarity`].
//!
//! Cost: `O(n log n)` worst case (binary searches), in practice about three orientation
//! tests and two segment tests per node; the status is a plain vector (about `√n` edges on
//! a city-like graph), changed by one splice per node.
//!
//! The `below` table gives the containment of connected components without a spatial
//! index: the face just above the edge below a component's leftmost node is the face
//! containing that component (see [`crate::assemble`]).

use polis_geom::DVec2;
use polis_geom::predicates::{orient2d_value, segments_intersect};

use crate::topology::{NONE, Topology};

/// An active edge: its ends in sweep order and its slot (leaving the left end).
#[derive(Debug, Clone, Copy)]
struct Seg {
    a: DVec2,
    b: DVec2,
    slot: u32,
    /// Its index in the status when inserted (the index drifts as edges below it come
    /// and go).
    hint: u32,
}

/// Buffers and results of the sweep.
#[derive(Debug, Default)]
pub(crate) struct SweepLine {
    /// The active edges' geometry, referred to by the status. Entries of edges that ended
    /// are reused (`free`), so this stays as small as the status and in cache, unlike the
    /// nodes' positions.
    segs: Vec<Seg>,
    free: Vec<u32>,
    /// By slot leaving an edge's left end: its entry in `segs` while it is active.
    seg_of: Vec<u32>,
    /// Active edges bottom to top, as indices into `segs`.
    status: Vec<u32>,
    /// Edges starting at the current node, bottom to top, as indices into `segs`.
    starting: Vec<u32>,
    /// By rank: the slot (leaving its left end) of the edge directly below the node, or
    /// `NONE`. Valid after [`SweepLine::run`] returned `true` (or when run untested on a
    /// planar graph).
    pub(crate) below: Vec<u32>,
}

impl SweepLine {
    /// Sweeps the working graph. With `test`, returns `false` at the first pair of edges
    /// that meet other than at a common end node (or a node inside an edge), `true` when
    /// there is none. Without `test`, only fills `below` (meaningful for planar graphs;
    /// on other input it is unspecified, but the sweep never panics) and returns `true`.
    pub(crate) fn run(&mut self, topo: &Topology, test: bool) -> bool {
        let n = topo.len();
        self.status.clear();
        self.segs.clear();
        self.free.clear();
        self.seg_of.clear();
        self.seg_of.resize(topo.slots(), NONE);
        self.below.clear();
        self.below.resize(n, NONE);
        for r in 0..n as u32 {
            let p = topo.p(r);
            let (s, t) = (topo.adj_start[r as usize], topo.adj_start[r as usize + 1]);
            let segs = &self.segs;

            // 1. The status edges through p. Where an edge ends at p, its place in the
            // status is found near where it was inserted, and the block of edges ending
            // at p grows from there; the edges just outside the block must not pass
            // through p. Otherwise a binary search finds the first edge not below p.
            let ending_here = (s..t)
                .find(|&k| topo.target[k as usize] < r)
                .and_then(|k| self.seg_of.get(topo.twin[k as usize] as usize))
                .and_then(|&i| find_near(&self.status, segs, i));
            let (lo, hi) = if let Some(j) = ending_here {
                let (mut lo, mut hi) = (j, j + 1);
                while lo > 0 && segs[self.status[lo - 1] as usize].b == p {
                    lo -= 1;
                }
                while hi < self.status.len() && segs[self.status[hi] as usize].b == p {
                    hi += 1;
                }
                if test {
                    let side = |x: usize| {
                        let e = &segs[self.status[x] as usize];
                        orient2d_value(e.a, e.b, p)
                    };
                    if (lo > 0 && side(lo - 1) <= 0.0)
                        || (hi < self.status.len() && side(hi) >= 0.0)
                    {
                        return false;
                    }
                }
                (lo, hi)
            } else {
                let lo = self.status.partition_point(|&i| {
                    let e = &segs[i as usize];
                    orient2d_value(e.a, e.b, p) > 0.0
                });
                let mut hi = lo;
                while let Some(&i) = self.status.get(hi) {
                    let e = &segs[i as usize];
                    if e.b != p && (!test || orient2d_value(e.a, e.b, p) != 0.0) {
                        break;
                    }
                    hi += 1;
                }
                (lo, hi)
            };
            if lo > 0 {
                self.below[r as usize] = segs[self.status[lo - 1] as usize].slot;
            }
            // 2. The edges starting at p, bottom to top: counter-clockwise from straight
            // down, i.e. first those going down-right, then those going right or up (the
            // slots are counter-clockwise from east).
            self.starting.clear();
            let mut ending = 0;
            let mut down = 0;
            for k in s..t {
                let w = topo.target[k as usize];
                if w < r {
                    ending += 1;
                    continue;
                }
                let q = topo.p(w);
                let seg = Seg {
                    a: p,
                    b: q,
                    slot: k,
                    hint: 0,
                };
                let i = match self.free.pop() {
                    Some(i) => {
                        self.segs[i as usize] = seg;
                        i
                    }
                    None => {
                        self.segs.push(seg);
                        self.segs.len() as u32 - 1
                    }
                };
                if let Some(x) = self.seg_of.get_mut(k as usize) {
                    *x = i;
                }
                if q.y < p.y {
                    self.starting.insert(down, i);
                    down += 1;
                } else {
                    self.starting.push(i);
                }
            }
            if test && hi - lo != ending {
                return false;
            }
            self.free.extend_from_slice(&self.status[lo..hi]);
            for (d, &i) in self.starting.iter().enumerate() {
                if let Some(e) = self.segs.get_mut(i as usize) {
                    e.hint = (lo + d) as u32;
                }
            }
            let segs = &self.segs;
            if test {
                for pair in self.starting.windows(2) {
                    let (q0, q1) = (segs[pair[0] as usize].b, segs[pair[1] as usize].b);
                    // Two directions into the right half-plane are collinear with p only
                    // when they are the same direction.
                    if orient2d_value(p, q0, q1) == 0.0 {
                        return false;
                    }
                }
            }
            splice(&mut self.status, lo, hi, &self.starting);

            // 3. New neighbours.
            if test {
                let top = lo + self.starting.len();
                let mut pairs = [(lo.wrapping_sub(1), lo), (usize::MAX, usize::MAX)];
                if !self.starting.is_empty() {
                    pairs[1] = (top - 1, top);
                }
                for (i, j) in pairs {
                    let (Some(&e), Some(&f)) = (self.status.get(i), self.status.get(j)) else {
                        continue;
                    };
                    if meet(&segs[e as usize], &segs[f as usize]) {
                        return false;
                    }
                }
            }
        }
        true
    }
}

/// Whether two edges have a point in common other than a shared end node (nodes have
/// distinct positions, so shared ends are equal points).
fn meet(e: &Seg, f: &Seg) -> bool {
    if e.a == f.a || e.a == f.b || e.b == f.a || e.b == f.b {
        return false;
    }
    segments_intersect(e.a, e.b, f.a, f.b)
}

/// How far from its insertion index an edge is looked for before falling back to the
/// binary search.
const NEAR: usize = 24;

/// The index of entry `i` in `status`, looked for within [`NEAR`] of its hint.
fn find_near(status: &[u32], segs: &[Seg], i: u32) -> Option<usize> {
    let n = status.len();
    if n == 0 {
        return None;
    }
    let h = (segs.get(i as usize)?.hint as usize).min(n - 1);
    for d in 0..=NEAR {
        if h + d < n && status[h + d] == i {
            return Some(h + d);
        }
        if d <= h && status[h - d] == i {
            return Some(h - d);
        }
    }
    None
}

/// Replaces `v[lo..hi]` by `with`, moving the tail once.
fn splice(v: &mut Vec<u32>, lo: usize, hi: usize, with: &[u32]) {
    let (old, new) = (hi - lo, with.len());
    if new > old {
        let len = v.len();
        v.resize(len + new - old, 0);
        v.copy_within(hi..len, hi + new - old);
    } else if new < old {
        v.copy_within(hi.., lo + new);
        v.truncate(v.len() - (old - new));
    }
    v[lo..lo + new].copy_from_slice(with);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::ExtractionReport;
    use crate::params::CellParams;
    use crate::planarity::PlanarityCheck;
    use polis_geom::{NodeId, PlanarGraph};
    use proptest::prelude::*;

    fn topo(g: &PlanarGraph<(), ()>) -> Topology {
        let mut t = Topology::default();
        let mut r = ExtractionReport::default();
        t.build(g, &CellParams::default(), &|_| true, &mut r)
            .unwrap();
        t
    }

    /// Edges between points of a small lattice (collinear overlaps, vertical edges,
    /// T-junctions, high degrees), plus off-lattice points and isolated nodes.
    fn soup(points: &[(i32, i32)], edges: &[(usize, usize)], scale: f64) -> PlanarGraph<(), ()> {
        let mut g = PlanarGraph::new();
        let mut ids: Vec<NodeId> = Vec::new();
        let mut seen = Vec::new();
        for &(x, y) in points {
            if !seen.contains(&(x, y)) {
                seen.push((x, y));
                ids.push(
                    g.add_node(DVec2::new(f64::from(x) * scale, f64::from(y) * scale), ())
                        .unwrap(),
                );
            }
        }
        for &(a, b) in edges {
            let (a, b) = (ids[a % ids.len()], ids[b % ids.len()]);
            if a != b && g.find_edge(a, b).is_none() {
                g.add_edge(a, b, ()).unwrap();
            }
        }
        g
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The sweep's verdict equals the exhaustive grid check's on degenerate input.
        #[test]
        fn sweep_agrees_with_the_grid_check(
            points in prop::collection::vec((0i32..5, 0i32..5), 2..16),
            edges in prop::collection::vec((0usize..16, 0usize..16), 0..14),
            scale in prop::sample::select(vec![1.0, 0.1, 1e3]),
        ) {
            let g = soup(&points, &edges, scale);
            let t = topo(&g);
            let mut line = SweepLine::default();
            let mut grid = PlanarityCheck::default();
            prop_assert_eq!(line.run(&t, true), grid.check(&t).is_ok());
        }
    }

    #[test]
    fn below_and_star_and_vertical_edges() {
        // A star with 8 spokes (two vertical), a horizontal segment under it, an isolated
        // node above it.
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let c = g.add_node(DVec2::new(0.0, 0.0), ()).unwrap();
        for (x, y) in [
            (1, 0),
            (1, 1),
            (0, 1),
            (-1, 1),
            (-1, 0),
            (-1, -1),
            (0, -1),
            (1, -1),
        ] {
            let m = g
                .add_node(DVec2::new(f64::from(x), f64::from(y)), ())
                .unwrap();
            g.add_edge(c, m, ()).unwrap();
        }
        let a = g.add_node(DVec2::new(-3.0, -5.0), ()).unwrap();
        let b = g.add_node(DVec2::new(3.0, -5.0), ()).unwrap();
        let low = g.add_edge(a, b, ()).unwrap();
        let top = g.add_node(DVec2::new(0.5, 3.0), ()).unwrap();
        let t = topo(&g);
        let mut line = SweepLine::default();
        assert!(line.run(&t, true));
        let rank = |n: NodeId| t.node.iter().position(|&x| x == n.raw()).unwrap();
        // Below the centre: not the spokes ending there, but the segment a–b.
        assert_eq!(t.edge[line.below[rank(c)] as usize], low.raw());
        // Above the star: the edge below the isolated node at (0.5, 3) is the spoke from
        // the centre to (1, 1).
        let ne = g.find_edge(c, NodeId::from_raw(2)).unwrap();
        assert_eq!(t.edge[line.below[rank(top)] as usize], ne.raw());
        // A node on the vertical spoke makes it non-planar.
        g.add_node(DVec2::new(0.0, 0.5), ()).unwrap();
        assert!(!line.run(&topo(&g), true));
    }
}
