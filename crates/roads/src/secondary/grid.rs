//! A flat grid of one cell's roads for the snap algorithm's extended-box search: sized to
//! the cell once, with no hashing, append-only while the cell grows.
//!
//! Each road is entered in every grid square its segment passes through (a conservative
//! cover, column by column); coordinates outside the grid clamp to its border squares, so
//! the cover stays conservative for any road. A road split or removed during growth
//! keeps its old entries: the search reads each candidate's current segment and drops
//! dead ids, so stale entries cost a test, never an answer. Road ids are never reused by
//! the graph, so the roads to enter are exactly the ids above the last one entered.

use polis_geom::{Aabb2, DVec2, EdgeId};

use crate::network::RoadNetwork;

/// The most squares the grid is made of (the square size grows to keep within it).
const MAX_SQUARES: usize = 1 << 16;

/// See the [module docs](self).
#[derive(Debug, Default, Clone)]
pub(crate) struct SnapGrid {
    origin: DVec2,
    size: f64,
    inv: f64,
    nx: usize,
    ny: usize,
    squares: Vec<Vec<EdgeId>>,
    /// Roads with ids below this are entered.
    entered: usize,
    /// Per road id: the query that last reported it (de-duplication).
    stamp: Vec<u32>,
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
        self.stamp.clear();
        self.query = 0;
    }

    fn col(&self, x: f64) -> usize {
        let c = ((x - self.origin.x) * self.inv).floor();
        if c >= 0.0 {
            (c as usize).min(self.nx - 1)
        } else {
            0
        }
    }

    fn row(&self, y: f64) -> usize {
        let c = ((y - self.origin.y) * self.inv).floor();
        if c >= 0.0 {
            (c as usize).min(self.ny - 1)
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
        for i in self.entered..bound {
            let e = EdgeId::from_raw(i as u32);
            if let Ok((a, b)) = g.segment(e) {
                self.enter(e, a, b);
            }
        }
        self.entered = self.entered.max(bound);
        if self.stamp.len() < bound {
            self.stamp.resize(bound, 0);
        }
    }

    /// Enters road `e` from `a` to `b` in every square its segment passes through.
    fn enter(&mut self, e: EdgeId, a: DVec2, b: DVec2) {
        let (c0, c1) = (self.col(a.x.min(b.x)), self.col(a.x.max(b.x)));
        let (r0, r1) = (self.row(a.y.min(b.y)), self.row(a.y.max(b.y)));
        let dx = b.x - a.x;
        // A margin that covers the rounding of the slab ends' y values.
        let eps = 1e-9 * (self.size + a.abs().max_element() + b.abs().max_element());
        for c in c0..=c1 {
            let (lo, hi) = if c0 == c1 || dx == 0.0 {
                (r0, r1)
            } else {
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
                    s.push(e);
                }
            }
        }
    }

    /// Calls `f` once with every road entered in a square under `b` (each id once per
    /// call; possibly dead or split since: the caller reads the current segment).
    pub(crate) fn for_each_in(&mut self, b: &Aabb2, mut f: impl FnMut(EdgeId)) {
        if self.nx == 0 || b.is_empty() {
            return;
        }
        self.query = self.query.wrapping_add(1);
        if self.query == 0 {
            self.stamp.fill(0);
            self.query = 1;
        }
        let (c0, c1) = (self.col(b.min.x), self.col(b.max.x));
        let (r0, r1) = (self.row(b.min.y), self.row(b.max.y));
        for r in r0..=r1 {
            for c in c0..=c1 {
                let Some(s) = self.squares.get(r * self.nx + c) else {
                    continue;
                };
                for &e in s {
                    if let Some(m) = self.stamp.get_mut(e.index())
                        && *m != self.query
                    {
                        *m = self.query;
                        f(e);
                    }
                }
            }
        }
    }
}
