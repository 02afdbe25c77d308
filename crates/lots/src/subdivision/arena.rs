//! Simple rings with street flags, stored back to back in one buffer so that splitting a
//! block into dozens of lots allocates (almost) nothing.

use polis_geom::DVec2;
use polis_geom::polygon::ring_signed_area;
use polis_geom::predicates::{lerp_stable, orient2d_value};

use crate::polygon_split::{Region, TaggedRing, split_by_line};

/// A ring in the arena.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piece {
    start: u32,
    len: u32,
    /// Known to be convex (then every split of it is convex too).
    pub convex: bool,
}

/// The buffer of rings.
#[derive(Debug, Default)]
pub(crate) struct Arena {
    pts: Vec<DVec2>,
    street: Vec<bool>,
    side: Vec<f64>,
}

impl Arena {
    pub fn clear(&mut self) {
        self.pts.clear();
        self.street.clear();
    }

    /// Adds a ring; `convex` may be `None` to have it computed.
    pub fn push(&mut self, ring: &TaggedRing, convex: Option<bool>) -> Piece {
        let start = self.pts.len() as u32;
        self.pts.extend_from_slice(&ring.points);
        self.street.extend_from_slice(&ring.street);
        let len = ring.points.len() as u32;
        let mut p = Piece {
            start,
            len,
            convex: false,
        };
        p.convex = convex.unwrap_or_else(|| self.is_convex(p));
        p
    }

    #[inline]
    pub fn points(&self, p: Piece) -> &[DVec2] {
        &self.pts[p.start as usize..(p.start + p.len) as usize]
    }

    #[inline]
    pub fn street(&self, p: Piece) -> &[bool] {
        &self.street[p.start as usize..(p.start + p.len) as usize]
    }

    #[inline]
    pub fn area(&self, p: Piece) -> f64 {
        ring_signed_area(self.points(p))
    }

    #[inline]
    pub fn has_street(&self, p: Piece) -> bool {
        self.street(p).iter().any(|&s| s)
    }

    #[inline]
    pub fn edge(&self, p: Piece, i: usize) -> (DVec2, DVec2) {
        let pts = self.points(p);
        let n = pts.len();
        let i = if i < n { i } else { i % n };
        (pts[i], pts[if i + 1 == n { 0 } else { i + 1 }])
    }

    pub fn region(&self, p: Piece) -> Region {
        Region {
            outer: TaggedRing {
                points: self.points(p).to_vec(),
                street: self.street(p).to_vec(),
            },
            holes: Vec::new(),
        }
    }

    /// Every turn of the (simple) ring is to the left or straight, decided exactly.
    fn is_convex(&self, p: Piece) -> bool {
        let pts = self.points(p);
        let n = pts.len();
        (0..n).all(|i| orient2d_value(pts[i], pts[(i + 1) % n], pts[(i + 2) % n]) >= 0.0)
    }

    /// The longest edge among those `filter` accepts: (index, squared length).
    #[inline]
    pub fn longest_edge(&self, p: Piece, filter: impl Fn(usize) -> bool) -> Option<(usize, f64)> {
        let pts = self.points(p);
        let n = pts.len();
        let mut best: Option<(usize, f64)> = None;
        for i in 0..n {
            if !filter(i) {
                continue;
            }
            // Squared lengths compare the same (the caller takes the root if it needs it).
            let j = if i + 1 == n { 0 } else { i + 1 };
            let l2 = pts[i].distance_squared(pts[j]);
            if best.is_none_or(|(_, bl)| l2 > bl) {
                best = Some((i, l2));
            }
        }
        best
    }

    /// Splits piece `p` by the line perpendicular to `a → b` through the point at fraction
    /// `t` from `a`. If a vertex lies (almost) on that line the point is moved a little
    /// along the edge, so a split never runs along an edge or through a vertex. The pieces
    /// go to `out` (just `p` again if the line misses). Returns the cut line as two points
    /// on it (`q`, `q + (b − a)⊥`).
    pub fn split_across(
        &mut self,
        p: Piece,
        a: DVec2,
        b: DVec2,
        t: f64,
        out: &mut Vec<Piece>,
    ) -> (DVec2, DVec2) {
        out.clear();
        let d = b - a;
        let len2 = d.length_squared();
        let tol = 1e-7 * len2;
        let mut t = t;
        let mut q = lerp_stable(a, b, t);
        for attempt in 0..8 {
            q = lerp_stable(a, b, t);
            if !self.points(p).iter().any(|&v| (v - q).dot(d).abs() <= tol) {
                break;
            }
            t += 1e-5 * (attempt as f64 + 1.0) * if attempt % 2 == 0 { 1.0 } else { -1.0 };
        }
        let r = q + d.perp();
        if p.convex && self.split_convex(p, q, r, out) {
            return (q, r);
        }
        out.clear();
        let pieces = split_by_line(&self.region(p), q, r);
        if pieces.len() < 2 {
            out.push(p);
            return (q, r);
        }
        for piece in pieces {
            let np = self.push(&piece.outer, None);
            out.push(np);
        }
        (q, r)
    }

    /// The parts of the line through `q` and `r` that lie inside piece `p`: its crossings
    /// with the ring, sorted along the line and paired (even–odd rule). The split line a
    /// subdivision step cut, for the debug record ([`super::SplitLine`]).
    pub fn chords(&self, p: Piece, q: DVec2, r: DVec2) -> Vec<[DVec2; 2]> {
        let pts = self.points(p);
        let n = pts.len();
        let dir = r - q;
        let len2 = dir.length_squared();
        if len2 == 0.0 {
            return Vec::new();
        }
        let mut hits: Vec<(f64, DVec2)> = Vec::new();
        for i in 0..n {
            let (u, v) = (pts[i], pts[if i + 1 == n { 0 } else { i + 1 }]);
            let (su, sv) = (orient2d_value(q, r, u), orient2d_value(q, r, v));
            // Half-open rule: a vertex on the line counts for the edge leaving it upward.
            if (su > 0.0) == (sv > 0.0) {
                continue;
            }
            let x = lerp_stable(u, v, su / (su - sv));
            hits.push(((x - q).dot(dir) / len2, x));
        }
        hits.sort_by(|x, y| x.0.total_cmp(&y.0));
        hits.chunks_exact(2).map(|c| [c[0].1, c[1].1]).collect()
    }

    /// The fast split of a convex ring: one exit and one entry crossing.
    fn split_convex(&mut self, p: Piece, a: DVec2, b: DVec2, out: &mut Vec<Piece>) -> bool {
        let (s, n) = (p.start as usize, p.len as usize);
        let mut side = std::mem::take(&mut self.side);
        side.clear();
        side.extend(self.pts[s..s + n].iter().map(|&v| orient2d_value(a, b, v)));
        let mut exit = None;
        let mut enter = None;
        let mut changes = 0;
        for k in 0..n {
            let k1 = if k + 1 == n { 0 } else { k + 1 };
            let (l0, l1) = (side[k] > 0.0, side[k1] > 0.0);
            if l0 && !l1 {
                exit = Some(k);
                changes += 1;
            } else if !l0 && l1 {
                enter = Some(k);
                changes += 1;
            }
        }
        let (Some(i), Some(j), 2) = (exit, enter, changes) else {
            self.side = side;
            return false;
        };
        let next = |k: usize| if k + 1 == n { 0 } else { k + 1 };
        let (i1, j1) = (next(i), next(j));
        let cross = |pts: &[DVec2], k0: usize, k1: usize| -> DVec2 {
            let t = side[k0] / (side[k0] - side[k1]);
            lerp_stable(pts[s + k0], pts[s + k1], t)
        };
        let x = if side[i1] == 0.0 {
            self.pts[s + i1]
        } else {
            cross(&self.pts, i, i1)
        };
        let y = if side[j] == 0.0 {
            self.pts[s + j]
        } else {
            cross(&self.pts, j, j1)
        };
        self.side = side;
        self.pts.reserve(n + 4);
        self.street.reserve(n + 4);
        // Left piece: Y, p[j+1] ..= p[i], X.
        let start = self.pts.len() as u32;
        self.pts.push(y);
        self.street.push(self.street[s + j]);
        let mut k = j1;
        loop {
            let (pk, sk) = (self.pts[s + k], self.street[s + k]);
            self.pts.push(pk);
            self.street.push(sk);
            if k == i {
                break;
            }
            k = next(k);
        }
        if x != self.pts[s + i] {
            self.pts.push(x);
            self.street.push(false);
        } else if let Some(last) = self.street.last_mut() {
            *last = false;
        }
        let left = Piece {
            start,
            len: self.pts.len() as u32 - start,
            convex: true,
        };
        // Right piece: X, p[i+1] ..= p[j], Y.
        let start = self.pts.len() as u32;
        if x != self.pts[s + i1] {
            self.pts.push(x);
            self.street.push(self.street[s + i]);
        }
        let mut k = i1;
        loop {
            let (pk, sk) = (self.pts[s + k], self.street[s + k]);
            self.pts.push(pk);
            self.street.push(sk);
            if k == j {
                break;
            }
            k = next(k);
        }
        if y != self.pts[s + j] {
            self.pts.push(y);
            self.street.push(false);
        } else if let Some(last) = self.street.last_mut() {
            *last = false;
        }
        let right = Piece {
            start,
            len: self.pts.len() as u32 - start,
            convex: true,
        };
        if left.len < 3 || right.len < 3 {
            return false;
        }
        out.push(left);
        out.push(right);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn convex_split_keeps_flags() {
        let mut arena = Arena::default();
        let ring = TaggedRing {
            points: vec![v(0., 0.), v(4., 0.), v(4., 2.), v(0., 2.)],
            street: vec![true, false, true, false],
        };
        let p = arena.push(&ring, None);
        assert!(p.convex);
        let mut out = Vec::new();
        arena.split_across(p, v(0., 0.), v(4., 0.), 0.25, &mut out);
        assert_eq!(out.len(), 2);
        let areas: Vec<f64> = out.iter().map(|&q| arena.area(q)).collect();
        assert!((areas[0] + areas[1] - 8.0).abs() < 1e-12);
        for &q in &out {
            assert_eq!(arena.points(q).len(), 4);
            assert_eq!(arena.street(q).iter().filter(|&&s| s).count(), 2);
        }
    }
}
