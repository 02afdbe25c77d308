//! Listing the planarity conflicts: no two edges may share a point other than a common end
//! node, and no node may lie inside an edge.
//!
//! The line sweep of [`crate::sweep_line`] decides *whether* the graph is planar; this
//! check runs only when it is not, to name every conflict.
//!
//! Edges are bucketed in a uniform grid (each edge in the cells its segment passes
//! through, found conservatively column by column); every pair sharing a bucket is
//! classified once with the exact [`segment_intersection`]. No sorting: expected `O(n)` on
//! road-like graphs, `O(d²)` around a node of degree `d`.

use std::cmp::Ordering;

use polis_geom::predicates::{SegmentIntersection, point_on_segment, segment_intersection};
use polis_geom::{DVec2, EdgeId, NodeId};

use crate::error::{Conflict, Error};
use crate::topology::Topology;
use polis_geom::predicates::{AngleStart, ccw_cmp};

/// At most this many conflicts are listed in [`Error::NotPlanar`].
pub const MAX_REPORTED_CONFLICTS: usize = 16;

/// Buffers of the planarity check.
#[derive(Debug, Default)]
pub(crate) struct PlanarityCheck {
    /// Bucket `c` holds `items[start[c]..start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
    /// For every item, the last item it was tested against (deduplicates pairs).
    stamp: Vec<u32>,
    isolated: Vec<u32>,
    /// One slot per edge (the smaller of the two).
    edges: Vec<u32>,
}

/// The segment of slot `k`.
fn seg_points(topo: &Topology, k: u32) -> (DVec2, DVec2) {
    (
        topo.p(topo.origin[k as usize]),
        topo.p(topo.target[k as usize]),
    )
}

/// The uniform grid over the graph's bounding box.
struct Grid {
    lo: DVec2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// Slack added around every segment's y-range, covering rounding in `y_at`.
    eps: f64,
}

impl Grid {
    fn col(&self, x: f64) -> usize {
        (((x - self.lo.x) / self.cell).max(0.0) as usize).min(self.nx - 1)
    }

    fn row(&self, y: f64) -> usize {
        (((y - self.lo.y) / self.cell).max(0.0) as usize).min(self.ny - 1)
    }

    /// Calls `f` with every bucket the segment `a–b` passes through, conservatively: a
    /// bucket it comes within `eps` of may be included, none it touches is missed (the
    /// column range is widened by one on each side against rounding in `col`).
    fn for_each_cell(&self, a: DVec2, b: DVec2, mut f: impl FnMut(usize)) {
        let (xmin, xmax) = (a.x.min(b.x), a.x.max(b.x));
        let c0 = self.col(xmin).saturating_sub(1);
        let c1 = (self.col(xmax) + 1).min(self.nx - 1);
        let y_at = |x: f64| {
            let t = ((x - a.x) / (b.x - a.x)).clamp(0.0, 1.0);
            a.y + (b.y - a.y) * t
        };
        for c in c0..=c1 {
            let xa = (self.lo.x + c as f64 * self.cell - self.eps).max(xmin);
            let xb = (self.lo.x + (c + 1) as f64 * self.cell + self.eps).min(xmax);
            if xa > xb {
                continue;
            }
            let (ylo, yhi) = if xmin == xmax {
                (a.y.min(b.y), a.y.max(b.y))
            } else {
                let (ya, yb) = (y_at(xa), y_at(xb));
                (ya.min(yb), ya.max(yb))
            };
            let (r0, r1) = (self.row(ylo - self.eps), self.row(yhi + self.eps));
            for r in r0..=r1 {
                f(r * self.nx + c);
            }
        }
    }
}

impl PlanarityCheck {
    /// Checks the working graph; `Err(NotPlanar)` lists the conflicts.
    pub(crate) fn check(&mut self, topo: &Topology) -> Result<(), Error> {
        let m = topo.slots();
        self.isolated.clear();
        self.isolated
            .extend((0..topo.len() as u32).filter(|&v| topo.deg0[v as usize] == 0));
        self.edges.clear();
        self.edges
            .extend((0..m as u32).filter(|&k| k < topo.twin[k as usize]));
        let count = self.edges.len() + self.isolated.len();
        if count < 2 {
            return Ok(());
        }
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        let mut total_len = 0.0;
        for &e in &self.edges {
            let (pa, pb) = seg_points(topo, e);
            lo = lo.min(pa.min(pb));
            hi = hi.max(pa.max(pb));
            total_len += (pb - pa).abs().max_element();
        }
        for &v in &self.isolated {
            lo = lo.min(topo.p(v));
            hi = hi.max(topo.p(v));
        }
        if lo.x > hi.x {
            return Ok(());
        }
        // Cell size: about the mean edge extent, at most ~4 cells per item, at most 4096
        // cells per side.
        let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let mean = if self.edges.is_empty() {
            extent
        } else {
            total_len / self.edges.len() as f64
        };
        let min_cell = extent / (2.0 * (count as f64).sqrt()).max(1.0);
        let cell = mean
            .max(min_cell)
            .max(extent / 4096.0)
            .max(f64::MIN_POSITIVE);
        let grid = Grid {
            lo,
            cell,
            nx: (((hi.x - lo.x) / cell) as usize + 1).min(4096),
            ny: (((hi.y - lo.y) / cell) as usize + 1).min(4096),
            eps: 1e-9 * cell + 1e-12 * lo.abs().max(hi.abs()).max_element(),
        };

        // Buckets as CSR, by counting.
        let buckets = grid.nx * grid.ny;
        self.start.clear();
        self.start.resize(buckets + 1, 0);
        for &e in &self.edges {
            let (a, b) = seg_points(topo, e);
            grid.for_each_cell(a, b, |c| self.start[c + 1] += 1);
        }
        for &v in &self.isolated {
            let p = topo.p(v);
            self.start[grid.row(p.y) * grid.nx + grid.col(p.x) + 1] += 1;
        }
        for c in 0..buckets {
            self.start[c + 1] += self.start[c];
        }
        self.items.clear();
        self.items.resize(self.start[buckets] as usize, 0);
        {
            let mut fill: Vec<u32> = self.start[..buckets].to_vec();
            let items = &mut self.items;
            for &e in &self.edges {
                let (a, b) = seg_points(topo, e);
                grid.for_each_cell(a, b, |c| {
                    items[fill[c] as usize] = e;
                    fill[c] += 1;
                });
            }
            for &v in &self.isolated {
                let p = topo.p(v);
                let c = grid.row(p.y) * grid.nx + grid.col(p.x);
                items[fill[c] as usize] = m as u32 + v;
                fill[c] += 1;
            }
        }

        // Every item against the later items sharing a bucket, each pair once.
        self.stamp.clear();
        self.stamp.resize(m + topo.len(), u32::MAX);
        let mut conflicts = Vec::new();
        let mut total = 0;
        rotation_overlaps(topo, &mut total, &mut conflicts);
        let (start, items, stamp) = (&self.start, &self.items, &mut self.stamp);
        let mut test = |x: u32, c: usize, total: &mut usize, conflicts: &mut Vec<Conflict>| {
            for &y in &items[start[c] as usize..start[c + 1] as usize] {
                if y <= x || stamp[y as usize] == x || (x as usize >= m && y as usize >= m) {
                    continue;
                }
                stamp[y as usize] = x;
                if let Some(k) = classify(topo, m as u32, x, y) {
                    *total += 1;
                    if conflicts.len() < MAX_REPORTED_CONFLICTS {
                        conflicts.push(k);
                    }
                }
            }
        };
        for &e in &self.edges {
            let (a, b) = seg_points(topo, e);
            grid.for_each_cell(a, b, |c| {
                test(e, c, &mut total, &mut conflicts);
            });
        }
        if total > 0 {
            conflicts.sort_by_key(|c| match *c {
                Conflict::Crossing { first, second, .. } | Conflict::Overlap { first, second } => {
                    (first.raw(), second.raw())
                }
                Conflict::NodeOnEdge { node, edge, .. } => (edge.raw(), u32::MAX - node.raw()),
            });
            return Err(Error::NotPlanar { conflicts, total });
        }
        Ok(())
    }
}

/// Whether two edges have a common end node.
fn shares_end(a: [u32; 2], b: [u32; 2]) -> bool {
    a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1]
}

/// Overlaps of edges sharing an end node: they leave it in exactly the same direction,
/// so they are neighbours in the node's exact counter-clockwise order.
fn rotation_overlaps(topo: &Topology, total: &mut usize, conflicts: &mut Vec<Conflict>) {
    for r in 0..topo.len() {
        let (s, t) = (topo.adj_start[r], topo.adj_start[r + 1]);
        if t - s < 2 {
            continue;
        }
        let o = topo.pos[r];
        // With two edges the wrap-around pair is the same pair.
        let last = if t - s == 2 { s + 1 } else { t };
        for k in s..last {
            let k2 = if k + 1 == t { s } else { k + 1 };
            let (p, q) = (
                topo.p(topo.target[k as usize]),
                topo.p(topo.target[k2 as usize]),
            );
            if ccw_cmp(o, p, q, AngleStart::East) == Ordering::Equal {
                let (e, f) = (topo.edge[k as usize], topo.edge[k2 as usize]);
                *total += 1;
                if conflicts.len() < MAX_REPORTED_CONFLICTS {
                    conflicts.push(Conflict::Overlap {
                        first: EdgeId::from_raw(e.min(f)),
                        second: EdgeId::from_raw(e.max(f)),
                    });
                }
            }
        }
    }
}

/// The conflict between two grid items (edge slot `k` as `k`, isolated node of rank `v`
/// as `m + v`, `m` the number of slots), if any.
fn classify(topo: &Topology, m: u32, x: u32, y: u32) -> Option<Conflict> {
    let seg = |e: u32| {
        let (a, b) = (topo.origin[e as usize], topo.target[e as usize]);
        ([a, b], topo.p(a), topo.p(b))
    };
    if x >= m || y >= m {
        let (e, v) = if x < m { (x, y - m) } else { (y, x - m) };
        let (_, a, b) = seg(e);
        let p = topo.p(v);
        return point_on_segment(p, a, b).then_some(Conflict::NodeOnEdge {
            node: NodeId::from_raw(topo.node[v as usize]),
            edge: EdgeId::from_raw(topo.edge[e as usize]),
            point: p,
        });
    }
    let (e, f) = (x, y);
    let (ee, a0, a1) = seg(e);
    let (fe, b0, b1) = seg(f);
    let (ie, jf) = (topo.edge[e as usize], topo.edge[f as usize]);
    let first = EdgeId::from_raw(ie.min(jf));
    let second = EdgeId::from_raw(ie.max(jf));
    // Edges sharing an end node meet elsewhere only when they overlap, leaving the node
    // in the same direction: `rotation_overlaps` finds those.
    if shares_end(ee, fe) {
        return None;
    }
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
            if ee.iter().any(|n| fe.contains(n) && topo.p(*n) == point) {
                return None;
            }
            let node_of = |ends: [u32; 2]| ends.into_iter().find(|&n| topo.p(n) == point);
            if let Some(n) = node_of(ee) {
                Some(Conflict::NodeOnEdge {
                    node: NodeId::from_raw(topo.node[n as usize]),
                    edge: EdgeId::from_raw(jf),
                    point,
                })
            } else if let Some(n) = node_of(fe) {
                Some(Conflict::NodeOnEdge {
                    node: NodeId::from_raw(topo.node[n as usize]),
                    edge: EdgeId::from_raw(ie),
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
