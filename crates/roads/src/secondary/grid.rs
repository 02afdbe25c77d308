//! A flat grid of one cell's roads for the snap algorithm's extended-box search: sized to
//! the cell once, with no hashing, append-only while the cell grows.
//!
//! Each road is entered, by its id alone, in every grid square its segment passes
//! through (a conservative cover, column by column); coordinates outside the grid clamp
//! to its border squares, so the cover stays conservative for any road. A table by road
//! id holds each road's end nodes and their positions as they are now, so a search reads
//! no graph at all, and the query stamp that reports each road once per search.
//!
//! Growth only adds roads, except where it splits a road (a secondary road joining it)
//! or removes one (an undone start split). Road ids are never reused by the graph, so
//! the new roads to enter are exactly the ids above the last one entered
//! ([`SnapGrid::sync`]); a road that changed is reported with [`SnapGrid::refresh`],
//! which copies its current ends into the table and enters its current segment again
//! (a removed road is marked dead). Squares the road has left keep its id: a search
//! that meets it there reads the table's current segment, which the caller's box test
//! then judges, so such an entry costs a look-up, never a wrong answer.

use polis_geom::{Aabb2, DVec2, EdgeId, NodeId};

use crate::network::RoadNetwork;

/// The most squares the grid is made of (the square size grows to keep within it).
const MAX_SQUARES: usize = 1 << 16;

/// A road as the grid lists it: its id, end nodes and their positions.
#[derive(Debug, Clone, Copy)]
pub(crate) struct GridRoad {
    /// The road.
    pub(crate) edge: EdgeId,
    /// Its first end.
    pub(crate) u: NodeId,
    /// Its second end.
    pub(crate) v: NodeId,
    /// The first end's position.
    pub(crate) pu: DVec2,
    /// The second end's position.
    pub(crate) pv: DVec2,
}

impl GridRoad {
    /// Road `e` of `g` as it is now (`None` for a dead id).
    pub(crate) fn of(g: &RoadNetwork, e: EdgeId) -> Option<GridRoad> {
        let (u, v) = g.endpoints(e).ok()?;
        Some(GridRoad {
            edge: e,
            u,
            v,
            pu: g.position(u).ok()?,
            pv: g.position(v).ok()?,
        })
    }
}

/// Per road id: the road as it is now, whether it is alive, and the query that last
/// reported it.
#[derive(Debug, Clone, Copy)]
struct Slot {
    road: GridRoad,
    alive: bool,
    stamp: u32,
}

impl Default for Slot {
    fn default() -> Self {
        Slot {
            road: GridRoad {
                edge: EdgeId::from_raw(0),
                u: NodeId::from_raw(0),
                v: NodeId::from_raw(0),
                pu: DVec2::ZERO,
                pv: DVec2::ZERO,
            },
            alive: false,
            stamp: 0,
        }
    }
}

/// See the [module docs](self).
#[derive(Debug, Default, Clone)]
pub(crate) struct SnapGrid {
    origin: DVec2,
    size: f64,
    inv: f64,
    nx: usize,
    ny: usize,
    /// The ids of the roads entered in each square.
    squares: Vec<Vec<u32>>,
    /// Roads with ids below this are entered.
    entered: usize,
    /// By road id.
    slots: Vec<Slot>,
    query: u32,
}

impl SnapGrid {
    /// Empties the grid and lays it over `bounds` in squares of about `square_m` metres.
    /// Keeps the allocations of earlier cells.
    pub(crate) fn reset(&mut self, bounds: Aabb2, square_m: f64) {
        let w = (bounds.max.x - bounds.min.x).max(0.0);
        let h = (bounds.max.y - bounds.min.y).max(0.0);
        let mut size = if square_m.is_finite() && square_m > 0.0 {
            square_m
        } else {
            64.0
        };
        if !(w.is_finite() && h.is_finite() && bounds.min.is_finite()) {
            // Unusable bounds: one square holds everything (still correct).
            self.origin = DVec2::ZERO;
            self.nx = 1;
            self.ny = 1;
            size = 1.0;
        } else {
            let count = |s: f64| ((w / s).floor() as usize + 1, (h / s).floor() as usize + 1);
            let (mut nx, mut ny) = count(size);
            while nx.saturating_mul(ny) > MAX_SQUARES {
                size *= 2.0;
                (nx, ny) = count(size);
            }
            self.origin = bounds.min;
            self.nx = nx;
            self.ny = ny;
        }
        self.size = size;
        self.inv = 1.0 / size;
        let n = self.nx * self.ny;
        for s in self.squares.iter_mut().take(n) {
            s.clear();
        }
        if self.squares.len() < n {
            self.squares.resize_with(n, Vec::new);
        }
        self.entered = 0;
        self.slots.clear();
        self.query = 0;
    }

    /// The column of `x` (clamped to the grid; `⌊·⌋` by truncation, as the value is not
    /// negative where it is used; the conversion saturates at `u32::MAX`, far above any
    /// column count).
    #[inline]
    fn col(&self, x: f64) -> usize {
        let c = (x - self.origin.x) * self.inv;
        if c >= 0.0 {
            (c as u32 as usize).min(self.nx - 1)
        } else {
            0
        }
    }

    /// The row of `y`, as [`col`](Self::col).
    #[inline]
    fn row(&self, y: f64) -> usize {
        let c = (y - self.origin.y) * self.inv;
        if c >= 0.0 {
            (c as u32 as usize).min(self.ny - 1)
        } else {
            0
        }
    }

    /// Enters every road of `g` not entered yet.
    pub(crate) fn sync(&mut self, g: &RoadNetwork) {
        let bound = g.edge_bound();
        if self.nx == 0 {
            self.reset(g.bbox(), 64.0);
        }
        if self.slots.len() < bound {
            self.slots.resize(bound, Slot::default());
        }
        for i in self.entered..bound {
            self.enter(g, EdgeId::from_raw(i as u32));
        }
        self.entered = self.entered.max(bound);
    }

    /// Road `e` (entered before) was split or removed: its slot takes its current ends
    /// (or marks it dead) and its current segment, if it is still alive, is entered
    /// again.
    pub(crate) fn refresh(&mut self, g: &RoadNetwork, e: EdgeId) {
        if e.index() >= self.entered {
            return; // not entered yet: `sync` will read its current segment
        }
        self.enter(g, e);
    }

    /// Copies road `e`'s current ends into its slot (marking it dead for a dead id) and
    /// enters its current segment in every square the segment passes through.
    fn enter(&mut self, g: &RoadNetwork, e: EdgeId) {
        let Some(slot) = self.slots.get_mut(e.index()) else {
            return;
        };
        let Some(road) = GridRoad::of(g, e) else {
            slot.alive = false;
            return;
        };
        slot.road = road;
        slot.alive = true;
        let id = e.index() as u32;
        let (a, b) = (road.pu, road.pv);
        let (c0, c1) = (self.col(a.x.min(b.x)), self.col(a.x.max(b.x)));
        let (r0, r1) = (self.row(a.y.min(b.y)), self.row(a.y.max(b.y)));
        let dx = b.x - a.x;
        // In one row or one column the cover is the box's squares.
        if r0 == r1 || c0 == c1 || dx == 0.0 {
            for r in r0..=r1 {
                if let Some(row) = self.squares.get_mut(r * self.nx + c0..=r * self.nx + c1) {
                    for s in row {
                        s.push(id);
                    }
                }
            }
            return;
        }
        // A margin that covers the rounding of the slab ends' y values.
        let eps = 1e-9 * (self.size + a.abs().max_element() + b.abs().max_element());
        for c in c0..=c1 {
            let (lo, hi) = {
                // The segment's y range over this column's x slab (the border columns
                // reach to infinity, as coordinates clamp).
                let x_lo = if c == c0 {
                    a.x.min(b.x)
                } else {
                    self.origin.x + c as f64 * self.size
                };
                let x_hi = if c == c1 {
                    a.x.max(b.x)
                } else {
                    self.origin.x + (c + 1) as f64 * self.size
                };
                let y_at = |x: f64| a.y + (b.y - a.y) * ((x - a.x) / dx);
                let (ya, yb) = (y_at(x_lo), y_at(x_hi));
                (
                    self.row(ya.min(yb) - eps).max(r0),
                    self.row(ya.max(yb) + eps).min(r1),
                )
            };
            for r in lo..=hi {
                if let Some(s) = self.squares.get_mut(r * self.nx + c) {
                    s.push(id);
                }
            }
        }
    }

    /// Appends to `out` every live road whose box meets `b`, each once, as its current
    /// segment (the roads [`for_each_in`](Self::for_each_in) reports whose boxes meet
    /// `b`, in the same order).
    ///
    /// The walk decides without branching: every entry is stamped, and a copy of its road
    /// appended then kept or dropped by one flag (first seen in this query, alive, and
    /// its box meeting `b`). Which entries are repeats, dead or out of the box follows no
    /// pattern a processor can predict, and a wrong guess costs more than the few
    /// instructions of deciding all three every time.
    pub(crate) fn gather(&mut self, b: &Aabb2, out: &mut Vec<GridRoad>) {
        self.gather_apart(b, &[], out);
    }

    /// [`gather`](Self::gather) without the roads `apart` (the snap search tests the
    /// roads at its root apart from the others, see
    /// [`Snapper::snap`](super::snap::Snapper::snap)): they are stamped with the query
    /// before the walk, so the walk takes them for roads it has reported already, at no
    /// cost an entry.
    pub(crate) fn gather_apart(&mut self, b: &Aabb2, apart: &[EdgeId], out: &mut Vec<GridRoad>) {
        if self.nx == 0 || b.is_empty() {
            return;
        }
        let query = self.next_query();
        for e in apart {
            if let Some(slot) = self.slots.get_mut(e.index()) {
                slot.stamp = query;
            }
        }
        let (c0, c1) = (self.col(b.min.x), self.col(b.max.x));
        let (r0, r1) = (self.row(b.min.y), self.row(b.max.y));
        let (lo, hi) = (b.min, b.max);
        for r in r0..=r1 {
            let Some(row) = self.squares.get(r * self.nx + c0..=r * self.nx + c1) else {
                continue;
            };
            for s in row {
                for &id in s {
                    let Some(slot) = self.slots.get_mut(id as usize) else {
                        continue;
                    };
                    let fresh = slot.stamp != query;
                    slot.stamp = query;
                    let road = slot.road;
                    // The road's box meets `b` (positions are finite: `min(p, q) ≤ h` is
                    // `p ≤ h | q ≤ h`, without `min`'s NaN handling).
                    let (p, q) = (road.pu, road.pv);
                    let meets = ((p.x <= hi.x) | (q.x <= hi.x))
                        & ((lo.x <= p.x) | (lo.x <= q.x))
                        & ((p.y <= hi.y) | (q.y <= hi.y))
                        & ((lo.y <= p.y) | (lo.y <= q.y));
                    let keep = fresh & slot.alive & meets;
                    out.push(road);
                    let len = out.len() - usize::from(!keep);
                    out.truncate(len);
                }
            }
        }
    }

    /// Road `e` as the grid lists it now (`None` for a dead or unknown id; the grid is
    /// current after [`sync`](Self::sync) and the changes reported since).
    #[inline]
    pub(crate) fn road(&self, e: EdgeId) -> Option<GridRoad> {
        self.slots
            .get(e.index())
            .filter(|s| s.alive && e.index() < self.entered)
            .map(|s| s.road)
    }

    /// The next query's stamp (every slot's stamp is reset when the counter wraps).
    fn next_query(&mut self) -> u32 {
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            for slot in &mut self.slots {
                slot.stamp = 0;
            }
            self.query = 1;
        }
        self.query
    }

    /// Calls `f` once with every live road entered in a square under `b` (each road
    /// once per call, as its current segment): every road whose segment meets `b` is
    /// among them, and roads near `b` may be too.
    #[cfg(test)]
    pub(crate) fn for_each_in(&mut self, b: &Aabb2, mut f: impl FnMut(&GridRoad)) {
        if self.nx == 0 || b.is_empty() {
            return;
        }
        self.next_query();
        let (c0, c1) = (self.col(b.min.x), self.col(b.max.x));
        let (r0, r1) = (self.row(b.min.y), self.row(b.max.y));
        for r in r0..=r1 {
            let Some(row) = self.squares.get(r * self.nx + c0..=r * self.nx + c1) else {
                continue;
            };
            for s in row {
                for &id in s {
                    if let Some(slot) = self.slots.get_mut(id as usize)
                        && slot.stamp != self.query
                    {
                        slot.stamp = self.query;
                        if slot.alive {
                            f(&slot.road);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::network::Junction;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// Whether the segment `p–q` meets the box `b` (clipping the segment's parameter range
    /// to each slab).
    fn meets(p: DVec2, q: DVec2, b: &Aabb2) -> bool {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (s, d, lo, hi) in [
            (p.x, q.x - p.x, b.min.x, b.max.x),
            (p.y, q.y - p.y, b.min.y, b.max.y),
        ] {
            if d == 0.0 {
                if s < lo || s > hi {
                    return false;
                }
            } else {
                let (ta, tb) = ((lo - s) / d, (hi - s) / d);
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
        }
        t0 <= t1
    }

    /// By brute force, in id order: the live roads whose segments meet `b`, and those
    /// whose boxes meet it.
    fn brute(g: &RoadNetwork, b: &Aabb2) -> (Vec<EdgeId>, Vec<EdgeId>) {
        let (mut meet, mut boxed) = (Vec::new(), Vec::new());
        for (e, ..) in g.edges() {
            let (u, v) = g.segment(e).unwrap();
            if meets(u, v, b) {
                meet.push(e);
            }
            if Aabb2::new(u, v).intersects(b) {
                boxed.push(e);
            }
        }
        (meet, boxed)
    }

    /// The grid's roads whose boxes meet `b`, each checked against the graph.
    /// [`SnapGrid::gather`] gives the same roads in the same order.
    fn listed(grid: &mut SnapGrid, g: &RoadNetwork, b: &Aabb2) -> Vec<EdgeId> {
        grid.sync(g);
        let mut out = Vec::new();
        grid.for_each_in(b, |r| {
            let now = GridRoad::of(g, r.edge).unwrap();
            assert_eq!((now.u, now.v, now.pu, now.pv), (r.u, r.v, r.pu, r.pv));
            if Aabb2::new(r.pu, r.pv).intersects(b) {
                out.push(r.edge);
            }
        });
        let mut gathered = vec![Slot::default().road; 3];
        grid.gather(b, &mut gathered);
        let gathered: Vec<EdgeId> = gathered.iter().skip(3).map(|r| r.edge).collect();
        assert_eq!(gathered, out);
        out.sort_unstable();
        out
    }

    /// Through added, split and removed roads (some reaching beyond the grid), every box
    /// query lists every live road that meets the box, each once and as it is now, and
    /// no road that is dead or whose box misses it.
    #[test]
    fn the_grid_lists_every_live_road_as_it_is() {
        let mut rng = Pcg64Mcg::seed_from_u64(18);
        let road = super::super::snap::tests::street();
        let mut g = RoadNetwork::new();
        let mut grid = SnapGrid::default();
        grid.reset(
            Aabb2::new(DVec2::new(0.0, 0.0), DVec2::new(400.0, 300.0)),
            37.0,
        );
        let point = |rng: &mut Pcg64Mcg| {
            DVec2::new(
                rng.random::<f64>() * 500.0 - 50.0,
                rng.random::<f64>() * 400.0 - 50.0,
            )
        };
        for round in 0..400 {
            let (p, q) = (point(&mut rng), point(&mut rng));
            let q = p + (q - p) * 0.2;
            let u = g.add_node(p, Junction::default()).unwrap();
            let v = g.add_node(q, Junction::default()).unwrap();
            g.add_edge(u, v, road).unwrap();
            let live: Vec<EdgeId> = g.edge_ids().collect();
            if round % 3 == 0 {
                let e = live[rng.random_range(0..live.len())];
                let (a, b) = g.segment(e).unwrap();
                g.split_edge(e, a.lerp(b, 0.37), Junction::default())
                    .unwrap();
                grid.refresh(&g, e);
            }
            if round % 7 == 0 {
                let e = live[rng.random_range(0..live.len())];
                if g.contains_edge(e) {
                    g.remove_edge(e).unwrap();
                    grid.refresh(&g, e);
                }
            }
            let c = point(&mut rng);
            let b = Aabb2::new(c, c).expanded(rng.random::<f64>() * 60.0);
            let got = listed(&mut grid, &g, &b);
            let (meet, boxed) = brute(&g, &b);
            assert!(
                meet.iter().all(|e| got.contains(e)),
                "round {round}: a road is missing"
            );
            assert!(
                got.iter().all(|e| boxed.contains(e)),
                "round {round}: a dead road"
            );
        }
    }
}
