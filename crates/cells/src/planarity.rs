//! The planarity check: no two edges may share a point other than a common end node, and
//! no node may lie inside an edge.
//!
//! Edges are bucketed in a uniform grid (each edge in the cells its segment passes
//! through, found conservatively column by column); pairs sharing a bucket are classified
//! with the exact [`segment_intersection`]. Expected `O(n)` on road-like graphs.

use polis_geom::predicates::{SegmentIntersection, point_on_segment, segment_intersection};
use polis_geom::{DVec2, EdgeId, NodeId};

use crate::error::{Conflict, Error};
use crate::topology::Topology;

/// At most this many conflicts are listed in [`Error::NotPlanar`].
pub const MAX_REPORTED_CONFLICTS: usize = 16;

/// Buffers of the planarity check.
#[derive(Debug, Default)]
pub(crate) struct PlanarityCheck {
    start: Vec<u32>,
    items: Vec<u32>,
    cell_of: Vec<(u32, u32)>,
    pairs: Vec<(u32, u32)>,
}

/// An item of the grid: edge `e` as `2e`, isolated node `v` as `2v + 1`.
#[inline]
fn edge_item(e: u32) -> u32 {
    e << 1
}

impl PlanarityCheck {
    /// Checks the working graph; `Err(NotPlanar)` lists the conflicts.
    pub(crate) fn check(&mut self, topo: &Topology) -> Result<(), Error> {
        let m = topo.edge_list.len();
        if m < 2 && topo.order.len() < 2 {
            return Ok(());
        }
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        let mut total_len = 0.0;
        for &e in &topo.edge_list {
            let [a, b] = topo.ends[e as usize];
            let (pa, pb) = (topo.p(a), topo.p(b));
            lo = lo.min(pa.min(pb));
            hi = hi.max(pa.max(pb));
            total_len += (pb - pa).abs().max_element();
        }
        let isolated: Vec<u32> = topo
            .order
            .iter()
            .copied()
            .filter(|&v| topo.deg0[v as usize] == 0)
            .collect();
        for &v in &isolated {
            lo = lo.min(topo.p(v));
            hi = hi.max(topo.p(v));
        }
        if lo.x > hi.x {
            return Ok(());
        }
        // Cell size: about the mean edge extent, with at most ~4 cells per item.
        let items = (m + isolated.len()).max(1);
        let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let mean = if m > 0 { total_len / m as f64 } else { extent };
        let min_cell = extent / (2.0 * (items as f64).sqrt()).max(1.0);
        let cell = mean
            .max(min_cell)
            .max(extent / 4096.0)
            .max(f64::MIN_POSITIVE);
        let nx = (((hi.x - lo.x) / cell) as usize + 1).min(4096);
        let ny = (((hi.y - lo.y) / cell) as usize + 1).min(4096);
        let col = |x: f64| (((x - lo.x) / cell) as usize).min(nx - 1);
        let row = |y: f64| (((y - lo.y) / cell) as usize).min(ny - 1);

        // Buckets: (cell, item) pairs, then sorted into CSR.
        self.cell_of.clear();
        for &e in &topo.edge_list {
            let [a, b] = topo.ends[e as usize];
            let (pa, pb) = (topo.p(a), topo.p(b));
            let (c0, c1) = (col(pa.x.min(pb.x)), col(pa.x.max(pb.x)));
            for c in c0..=c1 {
                // y-range of the segment over this column, widened by one row.
                let (r0, r1) = if c0 == c1 {
                    (row(pa.y.min(pb.y)), row(pa.y.max(pb.y)))
                } else {
                    let xa = lo.x + c as f64 * cell;
                    let xb = xa + cell;
                    let y_at = |x: f64| {
                        let t = ((x - pa.x) / (pb.x - pa.x)).clamp(0.0, 1.0);
                        pa.y + (pb.y - pa.y) * t
                    };
                    let (ya, yb) = (y_at(xa), y_at(xb));
                    (
                        row(ya.min(yb)).saturating_sub(1),
                        (row(ya.max(yb)) + 1).min(ny - 1),
                    )
                };
                for r in r0..=r1 {
                    self.cell_of.push(((r * nx + c) as u32, edge_item(e)));
                }
            }
        }
        for &v in &isolated {
            let p = topo.p(v);
            self.cell_of
                .push(((row(p.y) * nx + col(p.x)) as u32, (v << 1) | 1));
        }
        self.cell_of.sort_unstable();
        self.start.clear();
        self.items.clear();
        let mut k = 0;
        while k < self.cell_of.len() {
            let c = self.cell_of[k].0;
            self.start.push(self.items.len() as u32);
            while k < self.cell_of.len() && self.cell_of[k].0 == c {
                self.items.push(self.cell_of[k].1);
                k += 1;
            }
        }
        self.start.push(self.items.len() as u32);

        // Candidate pairs from every bucket, deduplicated.
        self.pairs.clear();
        for w in self.start.windows(2) {
            let bucket = &self.items[w[0] as usize..w[1] as usize];
            for (i, &x) in bucket.iter().enumerate() {
                for &y in &bucket[i + 1..] {
                    if x & 1 == 1 && y & 1 == 1 {
                        continue;
                    }
                    self.pairs.push((x.min(y), x.max(y)));
                }
            }
        }
        self.pairs.sort_unstable();
        self.pairs.dedup();

        let mut conflicts = Vec::new();
        let mut total = 0;
        for &(x, y) in &self.pairs {
            if let Some(c) = classify(topo, x, y) {
                total += 1;
                if conflicts.len() < MAX_REPORTED_CONFLICTS {
                    conflicts.push(c);
                }
            }
        }
        if total > 0 {
            return Err(Error::NotPlanar { conflicts, total });
        }
        Ok(())
    }
}

/// The conflict between two grid items, if any.
fn classify(topo: &Topology, x: u32, y: u32) -> Option<Conflict> {
    let seg = |i: u32| {
        let [a, b] = topo.ends[(i >> 1) as usize];
        ([a, b], topo.p(a), topo.p(b))
    };
    match (x & 1, y & 1) {
        (0, 0) => {
            let (e, f) = (x >> 1, y >> 1);
            let (ee, a0, a1) = seg(x);
            let (fe, b0, b1) = seg(y);
            let first = EdgeId::from_raw(e.min(f));
            let second = EdgeId::from_raw(e.max(f));
            match segment_intersection(a0, a1, b0, b1) {
                SegmentIntersection::Disjoint => None,
                SegmentIntersection::Crossing { point, .. } => Some(Conflict::Crossing {
                    first,
                    second,
                    point,
                }),
                SegmentIntersection::Overlap { .. } => Some(Conflict::Overlap { first, second }),
                SegmentIntersection::Touching { point, .. } => {
                    // Fine only at a node both edges end at.
                    let shared = ee.iter().any(|n| fe.contains(n) && topo.p(*n) == point);
                    if shared {
                        return None;
                    }
                    let node_of = |ends: [u32; 2]| ends.into_iter().find(|&n| topo.p(n) == point);
                    if let Some(n) = node_of(ee) {
                        Some(Conflict::NodeOnEdge {
                            node: NodeId::from_raw(n),
                            edge: EdgeId::from_raw(f),
                            point,
                        })
                    } else if let Some(n) = node_of(fe) {
                        Some(Conflict::NodeOnEdge {
                            node: NodeId::from_raw(n),
                            edge: EdgeId::from_raw(e),
                            point,
                        })
                    } else {
                        Some(Conflict::Crossing {
                            first,
                            second,
                            point,
                        })
                    }
                }
            }
        }
        (0, _) | (_, 0) => {
            let (ei, vi) = if x & 1 == 0 { (x, y) } else { (y, x) };
            let v = vi >> 1;
            let (_, a, b) = seg(ei);
            let p = topo.p(v);
            point_on_segment(p, a, b).then_some(Conflict::NodeOnEdge {
                node: NodeId::from_raw(v),
                edge: EdgeId::from_raw(ei >> 1),
                point: p,
            })
        }
        _ => None,
    }
}
