//! The working copy of the input graph: a compact half-edge rotation system with O(1)
//! edge removal.
//!
//! Nodes are renumbered by their *rank* in Eberly's sweep order (`(x, y)`, ties by id), and
//! half-edges by their slot in a compressed adjacency array grouped by origin rank: the
//! sweep then works on memory close to the sweep line, which matters more than anything
//! else for speed on large graphs. Slot `k` runs from `origin[k]` to `target[k]`; `twin[k]`
//! is the reverse; `node[r]` and `edge[k]` give the input graph's ids back. Around every
//! node the live half-edges leaving it form a circular doubly linked list in
//! counter-clockwise order, copied from the graph's exact rotation system.

use polis_geom::predicates::{AngleStart, ccw_cmp};
use polis_geom::{DVec2, EdgeId, NodeId, PlanarGraph};

use crate::error::Error;
use crate::output::{DropReason, DroppedEdge, ExtractionReport, NodeMerge};
use crate::params::{CellParams, CoincidentNodes};

/// "No index".
pub(crate) const NONE: u32 = u32::MAX;

/// The working graph. See the module docs.
#[derive(Debug, Default)]
pub(crate) struct Topology {
    /// Position by rank.
    pub(crate) pos: Vec<DVec2>,
    /// Input node id (raw) by rank.
    pub(crate) node: Vec<u32>,
    /// Half-edges leaving rank `r` are the slots `adj_start[r]..adj_start[r + 1]`,
    /// counter-clockwise.
    pub(crate) adj_start: Vec<u32>,
    /// Degree before extraction, by rank.
    pub(crate) deg0: Vec<u32>,
    /// Live degree, by rank.
    pub(crate) deg: Vec<u32>,
    /// Some live half-edge leaving the node, `NONE` when isolated.
    pub(crate) head: Vec<u32>,
    /// The clockwise-most live half-edge leaving the node seen from straight down, once
    /// computed (`NONE` before).
    pub(crate) first: Vec<u32>,
    /// By slot: origin rank, target rank, reverse slot, input edge id (raw).
    pub(crate) origin: Vec<u32>,
    pub(crate) target: Vec<u32>,
    pub(crate) twin: Vec<u32>,
    pub(crate) edge: Vec<u32>,
    /// Counter-clockwise / clockwise successor of a slot around its origin, among live ones.
    pub(crate) nxt: Vec<u32>,
    pub(crate) prv: Vec<u32>,
    /// Whether the slot's edge is still in the working graph (both slots of an edge agree).
    pub(crate) live: Vec<bool>,
    /// The input graph's node and edge bounds.
    pub(crate) node_bound: usize,
    pub(crate) edge_bound: usize,
    // Build buffers.
    keyed: Vec<(u64, u64, u32)>,
    rank_of: Vec<u32>,
    ends: Vec<[u32; 2]>,
    kept: Vec<u32>,
    slot_of: Vec<[u32; 2]>,
    around: Vec<(u32, u32)>,
}

/// The largest edge bound supported (slot indices must fit in `u32`).
pub(crate) const MAX_EDGES: usize = (u32::MAX / 2 - 1) as usize;

impl Topology {
    /// Position of rank `r`.
    #[inline]
    pub(crate) fn p(&self, r: u32) -> DVec2 {
        self.pos[r as usize]
    }

    /// Number of nodes (ranks).
    pub(crate) fn len(&self) -> usize {
        self.pos.len()
    }

    /// Number of half-edge slots.
    pub(crate) fn slots(&self) -> usize {
        self.origin.len()
    }

    /// Rebuilds the working graph from the edges of `g` that `keep` accepts, merging or
    /// rejecting coincident nodes.
    pub(crate) fn build<N, E>(
        &mut self,
        g: &PlanarGraph<N, E>,
        params: &CellParams,
        keep: &impl Fn(&E) -> bool,
        report: &mut ExtractionReport,
    ) -> Result<(), Error> {
        let n = g.node_bound();
        let m = g.edge_bound();
        if m > MAX_EDGES || n > MAX_EDGES {
            return Err(Error::TooLarge {
                edges: m,
                limit: MAX_EDGES,
            });
        }
        self.node_bound = n;
        self.edge_bound = m;

        // Sweep order on integer keys that order like the coordinates (-0 and +0 are the
        // same coordinate: adding +0.0 turns -0.0 into +0.0); ties by id.
        let key = |x: f64| {
            let bits = (x + 0.0).to_bits();
            if bits >> 63 == 1 {
                !bits
            } else {
                bits | (1 << 63)
            }
        };
        let unkey = |k: u64| f64::from_bits(if k >> 63 == 1 { k & !(1 << 63) } else { !k });
        self.keyed.clear();
        self.keyed
            .extend(g.nodes().map(|(id, p, _)| (key(p.x), key(p.y), id.raw())));
        self.keyed.sort_unstable();

        // Ranks; coincident nodes are neighbours in the order and join the first (smallest
        // id) of their run.
        self.rank_of.clear();
        self.rank_of.resize(n, NONE);
        self.pos.clear();
        self.node.clear();
        for k in 0..self.keyed.len() {
            let (kx, ky, id) = self.keyed[k];
            if k > 0 && self.keyed[k - 1].0 == kx && self.keyed[k - 1].1 == ky {
                let r = self.pos.len() as u32 - 1;
                let into = self.node[r as usize];
                let point = self.pos[r as usize];
                if params.coincident_nodes == CoincidentNodes::Reject {
                    return Err(Error::CoincidentNodes {
                        first: NodeId::from_raw(into),
                        second: NodeId::from_raw(id),
                        point,
                    });
                }
                self.rank_of[id as usize] = r;
                report.merged_nodes.push(NodeMerge {
                    node: NodeId::from_raw(id),
                    into: NodeId::from_raw(into),
                    point,
                });
                continue;
            }
            self.rank_of[id as usize] = self.pos.len() as u32;
            self.pos.push(DVec2::new(unkey(kx), unkey(ky)));
            self.node.push(id);
        }
        let merged = !report.merged_nodes.is_empty();
        let rn = self.pos.len();

        // Edges in rank space.
        self.ends.clear();
        self.ends.resize(m, [NONE; 2]);
        self.kept.clear();
        for (e, a, b, payload) in g.edges() {
            if !keep(payload) {
                continue;
            }
            let (ra, rb) = (self.rank_of[a.index()], self.rank_of[b.index()]);
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
            self.kept.push(e.raw());
        }
        if merged {
            self.drop_duplicates(report);
        }

        // Compressed adjacency, counter-clockwise around every rank.
        self.deg0.clear();
        self.deg0.resize(rn, 0);
        for &e in &self.kept {
            let [a, b] = self.ends[e as usize];
            self.deg0[a as usize] += 1;
            self.deg0[b as usize] += 1;
        }
        self.adj_start.clear();
        self.adj_start.reserve(rn + 1);
        let mut acc = 0u32;
        for r in 0..rn {
            self.adj_start.push(acc);
            acc += self.deg0[r];
        }
        self.adj_start.push(acc);
        let h = acc as usize;
        for v in [
            &mut self.origin,
            &mut self.target,
            &mut self.twin,
            &mut self.edge,
            &mut self.nxt,
            &mut self.prv,
        ] {
            v.clear();
            v.resize(h, NONE);
        }
        self.slot_of.clear();
        self.slot_of.resize(m, [NONE; 2]);
        if merged {
            // Gather from all merged nodes, then sort exactly.
            let mut lists: Vec<Vec<(u32, u32)>> = vec![Vec::new(); rn];
            for &e in &self.kept {
                let [a, b] = self.ends[e as usize];
                lists[a as usize].push((e, b));
                lists[b as usize].push((e, a));
            }
            for (r, list) in lists.into_iter().enumerate() {
                let o = self.pos[r];
                let pos = &self.pos;
                self.around = list;
                self.around.sort_unstable_by(|x, y| {
                    ccw_cmp(o, pos[x.1 as usize], pos[y.1 as usize], AngleStart::East)
                        .then(x.0.cmp(&y.0))
                });
                self.place(r);
            }
            for &e in &self.kept {
                let [k0, k1] = self.slot_of[e as usize];
                self.twin[k0 as usize] = k1;
                self.twin[k1 as usize] = k0;
            }
        } else {
            // In the graph's id order (its memory order); the two slots of an edge pair
            // up in the order they are met.
            // The other end comes from `ends` (just written, in rank space) rather than
            // from the graph's edge table.
            for (id, _, _) in g.nodes() {
                let r = self.rank_of[id.index()];
                let s = self.adj_start[r as usize] as usize;
                let mut k = s;
                for &e in g.edges_at(id)? {
                    let [a, b] = self.ends.get(e.index()).copied().unwrap_or([NONE; 2]);
                    if a == NONE {
                        if g.edge_payload(e).is_ok_and(|p| !keep(p)) {
                            continue; // left out by the caller
                        }
                        return Err(Error::Internal(format!("edge {e} has no ends")));
                    }
                    self.origin[k] = r;
                    self.target[k] = if a == r { b } else { a };
                    self.edge[k] = e.raw();
                    let first = self.slot_of[e.index()][0];
                    if first == NONE {
                        self.slot_of[e.index()][0] = k as u32;
                    } else {
                        self.twin[k] = first;
                        self.twin[first as usize] = k as u32;
                    }
                    k += 1;
                }
            }
        }

        self.live.clear();
        self.live.resize(h, true);
        self.head.clear();
        self.head.resize(rn, NONE);
        self.first.clear();
        self.first.resize(rn, NONE);
        self.deg.clear();
        self.deg.extend_from_slice(&self.deg0);
        for r in 0..rn {
            let (s, t) = (self.adj_start[r], self.adj_start[r + 1]);
            if s == t {
                continue;
            }
            self.head[r] = s;
            for k in s..t {
                let k2 = if k + 1 == t { s } else { k + 1 };
                self.nxt[k as usize] = k2;
                self.prv[k2 as usize] = k;
            }
        }
        Ok(())
    }

    /// Writes `around` (edge, neighbour rank), in counter-clockwise order, into the slots
    /// of rank `r`.
    fn place(&mut self, r: usize) {
        let s = self.adj_start[r] as usize;
        for (i, &(e, w)) in self.around.iter().enumerate() {
            let k = s + i;
            self.origin[k] = r as u32;
            self.target[k] = w;
            self.edge[k] = e;
            let d = usize::from(self.ends[e as usize][0] != r as u32);
            self.slot_of[e as usize][d] = k as u32;
        }
    }

    /// Drops all but the smallest-id edge of every pair of nodes joined more than once
    /// (possible only after merging coincident nodes).
    fn drop_duplicates(&mut self, report: &mut ExtractionReport) {
        let mut keyed: Vec<(u32, u32, u32)> = self
            .kept
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
        let ends = &self.ends;
        self.kept.retain(|&e| ends[e as usize][0] != NONE);
    }

    /// The clockwise-most live half-edge leaving `r` when arriving from straight above
    /// (Eberly's start at the leftmost vertex: the edge with the smallest angle in
    /// `(-90°, 90°]`). `r` must have a live edge.
    pub(crate) fn clockwise_most(&mut self, r: u32) -> u32 {
        let ri = r as usize;
        if self.first[ri] != NONE {
            return self.first[ri];
        }
        let o = self.pos[ri];
        // When every live edge goes to a later rank (always so at the sweep's leftmost
        // live node), the slots' counter-clockwise order from east gives the answer
        // without an angular comparison: the first live slot going down (into the
        // fourth quadrant), else the first live slot.
        let (s, t) = (self.adj_start[ri], self.adj_start[ri + 1]);
        let (mut first_live, mut first_down) = (NONE, NONE);
        let mut all_later = true;
        for k in s..t {
            if !self.live[k as usize] {
                continue;
            }
            let w = self.target[k as usize];
            all_later &= w > r;
            if first_live == NONE {
                first_live = k;
            }
            if first_down == NONE && self.p(w).y < o.y {
                first_down = k;
            }
        }
        if all_later && first_live != NONE {
            let best = if first_down != NONE {
                first_down
            } else {
                first_live
            };
            self.first[ri] = best;
            return best;
        }
        let start = self.head[ri];
        let mut best = start;
        let mut k = self.nxt[start as usize];
        while k != start && k != NONE {
            let (pk, pb) = (
                self.p(self.target[k as usize]),
                self.p(self.target[best as usize]),
            );
            if ccw_cmp(o, pk, pb, AngleStart::South).is_lt() {
                best = k;
            }
            k = self.nxt[k as usize];
        }
        self.first[ri] = best;
        best
    }

    /// Removes the edge of slot `k` (both slots) from the live lists.
    pub(crate) fn remove_edge(&mut self, k: u32) {
        if !self.live[k as usize] {
            return;
        }
        for h in [k, self.twin[k as usize]] {
            self.live[h as usize] = false;
            let v = self.origin[h as usize] as usize;
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
                assert_eq!(ccw_cmp(o, dirs[i], dirs[j], AngleStart::South), i.cmp(&j));
            }
        }
    }

    #[test]
    fn ranks_slots_and_clockwise_most() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let up = g.add_node(v(0.0, 1.0), ()).unwrap();
        let c = g.add_node(v(0.0, 0.0), ()).unwrap();
        let ne = g.add_node(v(1.0, 1.0), ()).unwrap();
        let se = g.add_node(v(1.0, -2.0), ()).unwrap();
        let z = g.add_node(v(-0.0, -1.0), ()).unwrap();
        g.remove_node(z).unwrap();
        let e_up = g.add_edge(c, up, ()).unwrap();
        let _e_ne = g.add_edge(c, ne, ()).unwrap();
        let e_se = g.add_edge(se, c, ()).unwrap();
        let mut t = Topology::default();
        let mut r = ExtractionReport::default();
        t.build(&g, &CellParams::default(), &|_| true, &mut r)
            .unwrap();
        assert_eq!(t.node, vec![c.raw(), up.raw(), se.raw(), ne.raw()]);
        assert_eq!(t.slots(), 6);
        for k in 0..6 {
            let w = t.twin[k] as usize;
            assert_eq!(t.twin[w] as usize, k);
            assert_eq!(t.origin[k], t.target[w]);
            assert_eq!(t.edge[k], t.edge[w]);
        }
        let k = t.clockwise_most(0);
        assert_eq!(t.edge[k as usize], e_se.raw());
        t.remove_edge(k);
        let k = t.clockwise_most(0);
        assert_eq!(t.node[t.target[k as usize] as usize], ne.raw());
        assert_eq!(t.deg[0], 2);
        t.remove_edge(t.twin[k as usize]);
        let k = t.clockwise_most(0);
        assert_eq!(t.edge[k as usize], e_up.raw());
    }

    #[test]
    fn merges_coincident_nodes_and_duplicates() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let a = g.add_node(v(0.0, 0.0), ()).unwrap();
        let b = g.add_node(v(1.0, 0.0), ()).unwrap();
        let a2 = g.add_node(v(-0.0, 0.0), ()).unwrap();
        let c = g.add_node(v(0.0, 1.0), ()).unwrap();
        let e0 = g.add_edge(a, b, ()).unwrap();
        let e1 = g.add_edge(a2, b, ()).unwrap();
        g.add_edge(a2, c, ()).unwrap();
        let mut t = Topology::default();
        let mut r = ExtractionReport::default();
        t.build(&g, &CellParams::default(), &|_| true, &mut r)
            .unwrap();
        assert_eq!(r.merged_nodes.len(), 1);
        assert_eq!(r.merged_nodes[0].node, a2);
        assert_eq!(r.merged_nodes[0].into, a);
        assert_eq!(r.dropped_edges.len(), 1);
        assert_eq!(r.dropped_edges[0].edge, e1);
        assert_eq!(
            r.dropped_edges[0].reason,
            DropReason::Duplicate { kept: e0 }
        );
        assert_eq!(t.len(), 3);
        assert_eq!(t.deg[0], 2);
        // Counter-clockwise from east around the merged node: b, then c.
        assert_eq!(t.node[t.target[0] as usize], b.raw());
        assert_eq!(t.node[t.target[1] as usize], c.raw());
        let reject = CellParams {
            coincident_nodes: CoincidentNodes::Reject,
            ..CellParams::default()
        };
        let mut r = ExtractionReport::default();
        assert!(matches!(
            t.build(&g, &reject, &|_| true, &mut r),
            Err(Error::CoincidentNodes { .. })
        ));
    }
}
