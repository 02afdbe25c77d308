//! The working copy of the input graph: a compact half-edge rotation system with O(1)
//! edge removal.
//!
//! Node indices are the raw [`NodeId`]s of the input graph and edge indices its raw
//! [`EdgeId`]s, so no id translation is needed on output. Edge `e` has the two half-edges
//! `2e` (from its first end to its second) and `2e + 1` (back); the twin of `h` is `h ^ 1`.
//! Around every node the live half-edges leaving it form a circular doubly linked list in
//! counter-clockwise order, copied from the graph's exact rotation system.

use std::cmp::Ordering;

use polis_geom::predicates::{Orientation, orient2d};
use polis_geom::{DVec2, EdgeId, NodeId, PlanarGraph};

use crate::error::Error;
use crate::output::{DropReason, DroppedEdge, ExtractionReport, NodeMerge};
use crate::params::{CellParams, CoincidentNodes};

/// "No index".
pub(crate) const NONE: u32 = u32::MAX;

/// Which half-plane the direction `o → p` lies in, for an order that starts at `start`.
#[derive(Clone, Copy)]
pub(crate) enum Start {
    /// Counter-clockwise from the positive x axis.
    East,
    /// Counter-clockwise from straight down (the negative y axis).
    Down,
}

fn half(o: DVec2, p: DVec2, start: Start) -> u8 {
    let upper = match start {
        Start::East => p.y > o.y || (p.y == o.y && p.x > o.x),
        Start::Down => p.x > o.x || (p.x == o.x && p.y < o.y),
    };
    if upper { 0 } else { 1 }
}

/// Exact counter-clockwise order of the directions `o → p` and `o → q`, starting at
/// `start`. Equal only for identical directions.
pub(crate) fn ccw_cmp(o: DVec2, p: DVec2, q: DVec2, start: Start) -> Ordering {
    half(o, p, start)
        .cmp(&half(o, q, start))
        .then_with(|| match orient2d(o, p, q) {
            Orientation::CounterClockwise => Ordering::Less,
            Orientation::Clockwise => Ordering::Greater,
            Orientation::Collinear => Ordering::Equal,
        })
}

/// The working graph. See the module docs.
#[derive(Debug, Default)]
pub(crate) struct Topology {
    /// Position by node index.
    pub(crate) pos: Vec<DVec2>,
    /// Representative of each node index after merging (itself if not merged); `NONE`
    /// for dead slots.
    pub(crate) rep: Vec<u32>,
    /// Ends by edge index (`[NONE; 2]` for dead or dropped edges).
    pub(crate) ends: Vec<[u32; 2]>,
    /// Whether the edge is still in the working graph.
    pub(crate) live: Vec<bool>,
    /// Original adjacency (CSR): half-edges leaving node `v` are
    /// `adj[adj_start[v]..adj_start[v + 1]]`, counter-clockwise.
    pub(crate) adj_start: Vec<u32>,
    pub(crate) adj: Vec<u32>,
    /// Counter-clockwise successor of a half-edge around its origin, among live ones.
    pub(crate) nxt: Vec<u32>,
    /// Clockwise successor (counter-clockwise predecessor).
    pub(crate) prv: Vec<u32>,
    /// Some live half-edge leaving the node, `NONE` when isolated.
    pub(crate) head: Vec<u32>,
    /// Live degree.
    pub(crate) deg: Vec<u32>,
    /// Degree in the working graph before extraction started.
    pub(crate) deg0: Vec<u32>,
    /// The clockwise-most live half-edge leaving the node seen from straight down, once
    /// computed (`NONE` before).
    pub(crate) first: Vec<u32>,
    /// Representative nodes sorted by `(x, y)`, ties by index: Eberly's sweep order.
    pub(crate) order: Vec<u32>,
    /// Live edge indices of the working graph, increasing.
    pub(crate) edge_list: Vec<u32>,
    /// Sort buffer.
    keyed: Vec<(u64, u64, u32)>,
}

/// The largest edge bound supported (half-edge indices must fit in `u32`).
pub(crate) const MAX_EDGES: usize = (u32::MAX / 2 - 1) as usize;

impl Topology {
    #[inline]
    pub(crate) fn origin(&self, h: u32) -> u32 {
        self.ends[(h >> 1) as usize][(h & 1) as usize]
    }

    #[inline]
    pub(crate) fn target(&self, h: u32) -> u32 {
        self.ends[(h >> 1) as usize][((h & 1) ^ 1) as usize]
    }

    #[inline]
    pub(crate) fn p(&self, v: u32) -> DVec2 {
        self.pos[v as usize]
    }

    /// Rebuilds the working graph from `g`, merging or rejecting coincident nodes.
    pub(crate) fn build<N, E>(
        &mut self,
        g: &PlanarGraph<N, E>,
        params: &CellParams,
        report: &mut ExtractionReport,
    ) -> Result<(), Error> {
        let n = g.node_bound();
        let m = g.edge_bound();
        if m > MAX_EDGES {
            return Err(Error::TooLarge {
                edges: m,
                limit: MAX_EDGES,
            });
        }
        self.pos.clear();
        self.pos.resize(n, DVec2::ZERO);
        self.rep.clear();
        self.rep.resize(n, NONE);
        self.order.clear();
        for (id, p, _) in g.nodes() {
            let i = id.index();
            self.pos[i] = p;
            self.rep[i] = id.raw();
            self.order.push(id.raw());
        }
        // Sort by (x, y, id) on integer keys that order like the coordinates (-0 and +0
        // are the same coordinate: adding +0.0 turns -0.0 into +0.0).
        let key = |x: f64| {
            let bits = (x + 0.0).to_bits();
            if bits >> 63 == 1 {
                !bits
            } else {
                bits | (1 << 63)
            }
        };
        self.keyed.clear();
        self.keyed.extend(self.order.iter().map(|&v| {
            let p = self.pos[v as usize];
            (key(p.x), key(p.y), v)
        }));
        self.keyed.sort_unstable();
        self.order.clear();
        self.order.extend(self.keyed.iter().map(|k| k.2));

        // Coincident nodes are neighbours in the sorted order; the first of a run has the
        // smallest id.
        let mut merged = false;
        for k in 1..self.order.len() {
            let (a, b) = (self.order[k - 1], self.order[k]);
            if self.pos[a as usize] == self.pos[b as usize] {
                let into = self.rep[a as usize];
                if params.coincident_nodes == CoincidentNodes::Reject {
                    return Err(Error::CoincidentNodes {
                        first: NodeId::from_raw(into),
                        second: NodeId::from_raw(b),
                        point: self.pos[b as usize],
                    });
                }
                self.rep[b as usize] = into;
                merged = true;
                report.merged_nodes.push(NodeMerge {
                    node: NodeId::from_raw(b),
                    into: NodeId::from_raw(into),
                    point: self.pos[b as usize],
                });
            }
        }
        if merged {
            let rep = &self.rep;
            self.order.retain(|&v| rep[v as usize] == v);
        }

        // Edges.
        self.ends.clear();
        self.ends.resize(m, [NONE; 2]);
        self.live.clear();
        self.live.resize(m, false);
        self.edge_list.clear();
        for (e, a, b, _) in g.edges() {
            let (ra, rb) = (self.rep[a.index()], self.rep[b.index()]);
            if ra == NONE || rb == NONE {
                return Err(Error::Internal(format!("edge {e} ends at a dead node")));
            }
            if ra == rb {
                report.dropped_edges.push(DroppedEdge {
                    edge: e,
                    reason: DropReason::ZeroLength,
                });
                continue;
            }
            self.ends[e.index()] = [ra, rb];
            self.live[e.index()] = true;
            self.edge_list.push(e.raw());
        }
        if merged {
            self.drop_duplicates(report);
        }

        // Adjacency, counter-clockwise around every representative node.
        self.deg0.clear();
        self.deg0.resize(n, 0);
        for &e in &self.edge_list {
            let [a, b] = self.ends[e as usize];
            self.deg0[a as usize] += 1;
            self.deg0[b as usize] += 1;
        }
        self.adj_start.clear();
        self.adj_start.reserve(n + 1);
        let mut acc = 0u32;
        for v in 0..n {
            self.adj_start.push(acc);
            acc += self.deg0[v];
        }
        self.adj_start.push(acc);
        self.adj.clear();
        self.adj.resize(acc as usize, NONE);
        if merged {
            let mut fill: Vec<u32> = self.adj_start[..n].to_vec();
            for &e in &self.edge_list {
                for d in 0..2u32 {
                    let v = self.ends[e as usize][d as usize] as usize;
                    self.adj[fill[v] as usize] = 2 * e + d;
                    fill[v] += 1;
                }
            }
            for v in 0..n {
                let (s, t) = (self.adj_start[v] as usize, self.adj_start[v + 1] as usize);
                if t - s < 2 {
                    continue;
                }
                let o = self.pos[v];
                let (pos, ends) = (&self.pos, &self.ends);
                let far = |h: u32| pos[ends[(h >> 1) as usize][((h & 1) ^ 1) as usize] as usize];
                self.adj[s..t].sort_unstable_by(|&h1, &h2| {
                    ccw_cmp(o, far(h1), far(h2), Start::East).then(h1.cmp(&h2))
                });
            }
        } else {
            for v in 0..n {
                if self.rep[v] != v as u32 {
                    continue;
                }
                let s = self.adj_start[v] as usize;
                for (k, &e) in g.edges_at(NodeId::from_raw(v as u32))?.iter().enumerate() {
                    let d = u32::from(self.ends[e.index()][0] != v as u32);
                    self.adj[s + k] = 2 * e.raw() + d;
                }
            }
        }

        // Live circular lists.
        let hcount = 2 * m;
        self.nxt.clear();
        self.nxt.resize(hcount, NONE);
        self.prv.clear();
        self.prv.resize(hcount, NONE);
        self.head.clear();
        self.head.resize(n, NONE);
        self.first.clear();
        self.first.resize(n, NONE);
        self.deg.clear();
        self.deg.extend_from_slice(&self.deg0);
        for v in 0..n {
            let (s, t) = (self.adj_start[v] as usize, self.adj_start[v + 1] as usize);
            if s == t {
                continue;
            }
            self.head[v] = self.adj[s];
            for k in s..t {
                let h = self.adj[k];
                let h2 = self.adj[if k + 1 == t { s } else { k + 1 }];
                self.nxt[h as usize] = h2;
                self.prv[h2 as usize] = h;
            }
        }
        Ok(())
    }

    /// Drops all but the smallest-id edge of every pair of nodes joined more than once
    /// (possible only after merging coincident nodes).
    fn drop_duplicates(&mut self, report: &mut ExtractionReport) {
        let mut keyed: Vec<(u32, u32, u32)> = self
            .edge_list
            .iter()
            .map(|&e| {
                let [a, b] = self.ends[e as usize];
                (a.min(b), a.max(b), e)
            })
            .collect();
        keyed.sort_unstable();
        let mut k = 0;
        while k < keyed.len() {
            let (a, b, kept) = keyed[k];
            let mut j = k + 1;
            while j < keyed.len() && keyed[j].0 == a && keyed[j].1 == b {
                let e = keyed[j].2;
                self.live[e as usize] = false;
                self.ends[e as usize] = [NONE; 2];
                report.dropped_edges.push(DroppedEdge {
                    edge: EdgeId::from_raw(e),
                    reason: DropReason::Duplicate {
                        kept: EdgeId::from_raw(kept),
                    },
                });
                j += 1;
            }
            k = j;
        }
        let live = &self.live;
        self.edge_list.retain(|&e| live[e as usize]);
    }

    /// The clockwise-most live half-edge leaving `v` when arriving from straight above
    /// (Eberly's start at the leftmost vertex: the edge with the smallest angle in
    /// `(-90°, 90°]`). `v` must have a live edge.
    pub(crate) fn clockwise_most(&mut self, v: u32) -> u32 {
        let vi = v as usize;
        if self.first[vi] != NONE {
            return self.first[vi];
        }
        let o = self.pos[vi];
        let start = self.head[vi];
        let mut best = start;
        let mut h = self.nxt[start as usize];
        while h != start && h != NONE {
            if ccw_cmp(
                o,
                self.p(self.target(h)),
                self.p(self.target(best)),
                Start::Down,
            )
            .is_lt()
            {
                best = h;
            }
            h = self.nxt[h as usize];
        }
        self.first[vi] = best;
        best
    }

    /// Removes edge `e` from the live lists (its ids stay valid for output).
    pub(crate) fn remove_edge(&mut self, e: u32) {
        if !self.live[e as usize] {
            return;
        }
        self.live[e as usize] = false;
        for d in 0..2u32 {
            let h = 2 * e + d;
            let v = self.origin(h) as usize;
            let (p, n) = (self.prv[h as usize], self.nxt[h as usize]);
            if self.deg[v] <= 1 {
                self.head[v] = NONE;
                self.first[v] = NONE;
            } else {
                self.nxt[p as usize] = n;
                self.prv[n as usize] = p;
                if self.head[v] == h {
                    self.head[v] = n;
                }
                if self.first[v] == h {
                    // The next counter-clockwise edge is the new clockwise-most.
                    self.first[v] = n;
                }
            }
            self.deg[v] = self.deg[v].saturating_sub(1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn ccw_order_from_down() {
        let o = v(0.0, 0.0);
        let dirs = [
            v(0.0, -1.0),
            v(1.0, -1.0),
            v(1.0, 0.0),
            v(1.0, 1.0),
            v(0.0, 1.0),
        ];
        for i in 0..dirs.len() {
            for j in 0..dirs.len() {
                assert_eq!(ccw_cmp(o, dirs[i], dirs[j], Start::Down), i.cmp(&j));
            }
        }
    }

    #[test]
    fn clockwise_most_and_removal() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let c = g.add_node(v(0.0, 0.0), ()).unwrap();
        let up = g.add_node(v(0.0, 1.0), ()).unwrap();
        let ne = g.add_node(v(1.0, 1.0), ()).unwrap();
        let se = g.add_node(v(1.0, -2.0), ()).unwrap();
        let e_up = g.add_edge(c, up, ()).unwrap();
        let _e_ne = g.add_edge(c, ne, ()).unwrap();
        let e_se = g.add_edge(se, c, ()).unwrap();
        let mut t = Topology::default();
        let mut r = ExtractionReport::default();
        t.build(&g, &CellParams::default(), &mut r).unwrap();
        assert_eq!(t.order[0], c.raw());
        let h = t.clockwise_most(c.raw());
        assert_eq!(h, 2 * e_se.raw() + 1);
        t.remove_edge(e_se.raw());
        let h = t.clockwise_most(c.raw());
        assert_eq!(t.target(h), ne.raw());
        assert_eq!(t.deg[c.index()], 2);
        t.remove_edge(h >> 1);
        assert_eq!(t.clockwise_most(c.raw()), 2 * e_up.raw());
    }

    #[test]
    fn merges_coincident_nodes_and_duplicates() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let a = g.add_node(v(0.0, 0.0), ()).unwrap();
        let b = g.add_node(v(1.0, 0.0), ()).unwrap();
        let a2 = g.add_node(v(0.0, 0.0), ()).unwrap();
        let c = g.add_node(v(0.0, 1.0), ()).unwrap();
        let e0 = g.add_edge(a, b, ()).unwrap();
        let e1 = g.add_edge(a2, b, ()).unwrap();
        g.add_edge(a2, c, ()).unwrap();
        let mut t = Topology::default();
        let mut r = ExtractionReport::default();
        t.build(&g, &CellParams::default(), &mut r).unwrap();
        assert_eq!(r.merged_nodes.len(), 1);
        assert_eq!(r.merged_nodes[0].node, a2);
        assert_eq!(r.merged_nodes[0].into, a);
        assert_eq!(r.dropped_edges.len(), 1);
        assert_eq!(r.dropped_edges[0].edge, e1);
        assert_eq!(
            r.dropped_edges[0].reason,
            DropReason::Duplicate { kept: e0 }
        );
        assert_eq!(t.deg[a.index()], 2);
        assert_eq!(t.order.len(), 3);
        let reject = CellParams {
            coincident_nodes: CoincidentNodes::Reject,
            ..CellParams::default()
        };
        let mut r = ExtractionReport::default();
        assert!(matches!(
            t.build(&g, &reject, &mut r),
            Err(Error::CoincidentNodes { .. })
        ));
    }
}
