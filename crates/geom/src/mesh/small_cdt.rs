//! The constrained Delaunay triangulation of a small simple polygon without holes, built
//! directly: ear clipping with exact orientation tests, then Lawson flips with the exact
//! in-circle test. [`triangulate`](super::triangulate) uses it up to
//! [`MAX_VERTICES`] vertices instead of building a spade triangulation, which costs more
//! than the whole triangulation for junction polygons and building footprints.
//!
//! # Why the result is the constrained Delaunay triangulation
//! * Ear clipping triangulates any simple polygon without adding vertices: clipping only
//!   *strictly* convex vertices whose closed ear triangle holds no other remaining vertex
//!   leaves a simple polygon of positive area, and such a polygon always has an ear (any
//!   of its triangulations without zero-area triangles has two leaf triangles, and those
//!   are ears), so the walk never gets stuck. Vertices where the ring runs straight on
//!   (validation allows them) are never clipped while they are straight: no triangle has
//!   zero area.
//! * Only vertices that are not strictly convex need the containment test: if any other
//!   vertex lies in the closed ear triangle, take the one nearest the ear's tip (measured
//!   from the line through the ear's two neighbours). No edge can leave it towards the
//!   tip, and the polygon's inside lies on the tip's side of it, so its inside angle is at
//!   least 180°: it is not strictly convex, and it blocks the ear.
//! * A Lawson flip replaces the diagonal of two triangles when the fourth vertex lies
//!   *strictly* inside the circumcircle of the first triangle. Then the quadrilateral is
//!   strictly convex, so both new triangles have positive area. Each flip raises the
//!   sorted angle vector, so flipping ends (the in-circle test is exact); when no interior
//!   diagonal can be flipped every edge is locally Delaunay, and a triangulation of a
//!   polygon whose interior edges are all locally Delaunay is a constrained Delaunay one
//!   (Lee and Lin 1986, Chew 1989). Co-circular quadruples are never flipped, so which of
//!   the equally good triangulations comes out depends only on the input.
//!
//! # References
//! C. L. Lawson, *Software for C¹ surface interpolation*, Mathematical Software III (1977);
//! D. T. Lee and A. K. Lin, *Generalized Delaunay triangulation for planar graphs*, Discrete Comput. Geom. 1 (1986); G. H. Meisters,
//! *Polygons have ears*, Amer. Math. Monthly 82 (1975); D. Eberly, *Triangulation by ear
//! clipping* (Geometric Tools, 2002).

use glam::DVec2;

use crate::predicates::{in_circle, orient2d_value};

/// The most vertices the direct path takes (the bit sets below are `u64`); larger
/// polygons and polygons with holes go through spade. Chosen by measurement
/// (the repository's BENCHMARKS.md, polis-geom): the direct path is faster at every size up to here.
pub(super) const MAX_VERTICES: usize = 64;

/// No triangle: the boundary of the polygon, in the adjacency table.
const NONE: u8 = u8::MAX;

/// A triangle's corners, counter-clockwise, as positions in the working ring.
type Tri = [u8; 3];

/// Triangulates the simple ring `ring` (either orientation, already validated, at most
/// [`MAX_VERTICES`] vertices) into its constrained Delaunay triangulation: `n − 2`
/// counter-clockwise triangles of indices into `ring`. `None` when the ring does not fit
/// or, which validation rules out, the ear walk or the flips do not finish; the caller
/// then takes the general path.
pub(super) fn triangulate_ring(ring: &[DVec2]) -> Option<Vec<[u32; 3]>> {
    let n = ring.len();
    if !(3..=MAX_VERTICES).contains(&n) {
        return None;
    }
    let mut work = Work::new(ring)?;
    work.clip_ears()?;
    work.flip_to_delaunay()?;
    let count = n - 2;
    let mut out = Vec::with_capacity(count);
    for t in &work.tris[..count] {
        out.push(t.map(|k| u32::from(work.index[usize::from(k)])));
    }
    Some(out)
}

/// Edges waiting for the in-circle check, as triangle slots `3·t + e` (the edge of `t`
/// opposite its corner `e`), each at most once: a stack in a fixed buffer.
struct Pending {
    stack: [u8; 3 * MAX_VERTICES],
    len: usize,
    queued: [u64; 3],
}

impl Default for Pending {
    fn default() -> Self {
        Pending {
            stack: [0; 3 * MAX_VERTICES],
            len: 0,
            queued: [0; 3],
        }
    }
}

impl Pending {
    fn push(&mut self, slot: usize) {
        let bit = 1u64 << (slot % 64);
        if self.queued[slot / 64] & bit == 0 {
            self.queued[slot / 64] |= bit;
            self.stack[self.len] = slot as u8;
            self.len += 1;
        }
    }

    fn pop(&mut self) -> Option<usize> {
        self.len = self.len.checked_sub(1)?;
        let slot = usize::from(self.stack[self.len]);
        self.queued[slot / 64] &= !(1u64 << (slot % 64));
        Some(slot)
    }
}

/// The working state: the ring counter-clockwise, its triangles and their adjacency, all
/// in fixed buffers (no allocation but the result).
struct Work<'a> {
    /// Vertex count.
    n: usize,
    /// The input ring.
    ring: &'a [DVec2],
    /// Input index of each working position (positions run counter-clockwise).
    index: [u8; MAX_VERTICES],
    /// Triangles so far, counter-clockwise.
    tris: [Tri; MAX_VERTICES],
    /// `adj[t][e]`: the triangle across the edge of `t` opposite corner `e`, or [`NONE`].
    adj: [Tri; MAX_VERTICES],
}

impl<'a> Work<'a> {
    /// Numbers the ring's vertices counter-clockwise; `None` if its orientation is not
    /// decided (a valid ring always has it).
    fn new(ring: &'a [DVec2]) -> Option<Work<'a>> {
        let n = ring.len();
        // The lexicographically least vertex is strictly convex in a valid ring: its
        // neighbours both lie on one side, and they cannot both lie on one ray from it
        // (the edges would overlap), so the exact turn there is the ring's orientation.
        let mut low = 0;
        for (i, p) in ring.iter().enumerate() {
            let q = ring[low];
            if p.x < q.x || (p.x == q.x && p.y < q.y) {
                low = i;
            }
        }
        let turn = orient2d_value(ring[(low + n - 1) % n], ring[low], ring[(low + 1) % n]);
        if turn == 0.0 {
            return None;
        }
        let mut w = Work {
            n,
            ring,
            index: [0; MAX_VERTICES],
            tris: [[0; 3]; MAX_VERTICES],
            adj: [[NONE; 3]; MAX_VERTICES],
        };
        for k in 0..n {
            // Clockwise rings are walked backwards from vertex 0.
            let i = if turn > 0.0 { k } else { (n - k) % n };
            w.index[k] = i as u8;
        }
        Some(w)
    }

    fn turns_left(&self, a: u8, b: u8, c: u8) -> bool {
        orient2d_value(self.p(a), self.p(b), self.p(c)) > 0.0
    }

    fn p(&self, k: u8) -> DVec2 {
        self.ring[usize::from(self.index[usize::from(k)])]
    }

    /// Ear clipping into `tris` and `adj`. `None` if no ear is found in a whole turn of
    /// the remaining ring (impossible for a simple ring, see the module docs).
    fn clip_ears(&mut self) -> Option<()> {
        let n = self.n;
        let mut next = [0u8; MAX_VERTICES];
        let mut prev = [0u8; MAX_VERTICES];
        // `beyond[v]`: the triangle (and its corner opposite the edge) already clipped
        // off across the current ring edge from `v` to `next[v]`.
        let mut beyond = [(NONE, 0u8); MAX_VERTICES];
        for k in 0..n {
            next[k] = ((k + 1) % n) as u8;
            prev[k] = ((k + n - 1) % n) as u8;
        }
        // Vertices that are not strictly convex (reflex, or where the ring runs straight
        // on): the only ones that can block an ear.
        let mut blocking = 0u64;
        for k in 0..n as u8 {
            if !self.turns_left(prev[usize::from(k)], k, next[usize::from(k)]) {
                blocking |= 1 << k;
            }
        }
        let mut left = n;
        let mut t = 0usize;
        let mut cur = 0u8;
        let mut misses = 0usize;
        while left > 3 {
            let c = usize::from(cur);
            let (p, q) = (prev[c], next[c]);
            if !self.is_ear(p, cur, q, blocking) {
                misses += 1;
                if misses > left {
                    return None;
                }
                cur = q;
                continue;
            }
            misses = 0;
            // Triangle (p, cur, q): corner 0 = p faces edge cur→q, corner 1 = cur faces
            // the new diagonal q→p, corner 2 = q faces edge p→cur.
            self.tris[t] = [p, cur, q];
            self.link(t, 0, beyond[c]);
            self.link(t, 2, beyond[usize::from(p)]);
            beyond[usize::from(p)] = (t as u8, 1);
            t += 1;
            next[usize::from(p)] = q;
            prev[usize::from(q)] = p;
            blocking &= !(1u64 << cur);
            for v in [p, q] {
                let vi = usize::from(v);
                if self.turns_left(prev[vi], v, next[vi]) {
                    blocking &= !(1u64 << v);
                } else {
                    blocking |= 1 << v;
                }
            }
            left -= 1;
            // Step past the neighbour: ears spread around the ring instead of fanning
            // from one vertex, which leaves fewer flips to do.
            cur = next[usize::from(q)];
        }
        let a = cur;
        let b = next[usize::from(a)];
        let c = next[usize::from(b)];
        if !self.turns_left(a, b, c) {
            return None;
        }
        self.tris[t] = [a, b, c];
        self.link(t, 0, beyond[usize::from(b)]);
        self.link(t, 1, beyond[usize::from(c)]);
        self.link(t, 2, beyond[usize::from(a)]);
        Some(())
    }

    /// Whether `c` (between `p` and `q`) is an ear: strictly convex, and no blocking
    /// vertex other than the three lies in the closed triangle.
    fn is_ear(&self, p: u8, c: u8, q: u8, blocking: u64) -> bool {
        if blocking & (1 << c) != 0 {
            return false;
        }
        let mut rest = blocking & !(1u64 << p) & !(1u64 << q);
        if rest == 0 {
            return true;
        }
        let (a, b, d) = (self.p(p), self.p(c), self.p(q));
        // The triangle's box: a cheap, exact rejection before the orientation tests.
        let (low, high) = (a.min(b).min(d), a.max(b).max(d));
        while rest != 0 {
            let r = self.p(rest.trailing_zeros() as u8);
            rest &= rest - 1;
            if r.cmpge(low).all()
                && r.cmple(high).all()
                && orient2d_value(a, b, r) >= 0.0
                && orient2d_value(b, d, r) >= 0.0
                && orient2d_value(d, a, r) >= 0.0
            {
                return false;
            }
        }
        true
    }

    /// Makes triangle `t`'s edge opposite corner `e` and `other`'s edge opposite its
    /// corner neighbours (nothing if `other` is the boundary).
    fn link(&mut self, t: usize, e: usize, other: (u8, u8)) {
        let (u, f) = other;
        if u == NONE {
            return;
        }
        self.adj[t][e] = u;
        self.adj[usize::from(u)][usize::from(f)] = t as u8;
    }

    /// Lawson flips until every interior edge is locally Delaunay: every diagonal is
    /// checked once, and after a flip the four outer edges of its quadrilateral again
    /// (the new diagonal is locally Delaunay). `None` after more than `n − 2 + 2n²` flips
    /// (Lawson: at most `n(n − 1)/2`; cannot happen).
    fn flip_to_delaunay(&mut self) -> Option<()> {
        let count = self.n - 2;
        let mut pending = Pending::default();
        for t in 0..count {
            for e in 0..3 {
                let u = usize::from(self.adj[t][e]);
                if u < count && u > t {
                    pending.push(3 * t + e);
                }
            }
        }
        let mut budget = count + 2 * self.n * self.n;
        while let Some(slot) = pending.pop() {
            let (t, e) = (slot / 3, slot % 3);
            let u = usize::from(self.adj[t][e]);
            if u >= count || !self.flip_if_illegal(t, e, u) {
                continue;
            }
            budget = budget.checked_sub(1)?;
            // New t = (a, b, d): outer edges opposite corners 0 and 2; new u = (a, d, c):
            // opposite corners 0 and 1.
            for s in [3 * t, 3 * t + 2, 3 * u, 3 * u + 1] {
                pending.push(s);
            }
        }
        Some(())
    }

    /// Flips the edge of `t` opposite its corner `e` (shared with `u`) if `u`'s far
    /// corner lies strictly inside `t`'s circumcircle.
    fn flip_if_illegal(&mut self, t: usize, e: usize, u: usize) -> bool {
        let [a, b, c] = [0, 1, 2].map(|k| self.tris[t][(e + k) % 3]);
        let Some(f) = (0..3).find(|&k| usize::from(self.adj[u][k]) == t) else {
            return false;
        };
        let d = self.tris[u][f];
        if !in_circle(self.p(a), self.p(b), self.p(c), self.p(d)) {
            return false;
        }
        // t = (a, b, c) and u = (d, c, b) up to rotation; the quadrilateral a, b, d, c is
        // strictly convex. New t = (a, b, d), new u = (a, d, c).
        let n_ab = self.adj[t][(e + 2) % 3];
        let n_ca = self.adj[t][(e + 1) % 3];
        // In u, corner f + 1 is c (facing the edge b→d) and corner f + 2 is b.
        let n_bd = self.adj[u][(f + 1) % 3];
        let n_dc = self.adj[u][(f + 2) % 3];
        self.tris[t] = [a, b, d];
        self.adj[t] = [n_bd, u as u8, n_ab];
        self.tris[u] = [a, d, c];
        self.adj[u] = [n_dc, n_ca, t as u8];
        self.repoint(n_bd, u, t);
        self.repoint(n_ca, t, u);
        true
    }

    /// In triangle `w` (if any), makes the neighbour `from` the neighbour `to`.
    fn repoint(&mut self, w: u8, from: usize, to: usize) {
        if w == NONE {
            return;
        }
        for slot in &mut self.adj[usize::from(w)] {
            if usize::from(*slot) == from {
                *slot = to as u8;
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::triangulate::spade_triangles;
    use crate::mesh::triangulate::tests::{orthogonal, star};
    use crate::{Polygon, PolygonWithHoles, triangulate};
    use proptest::prelude::*;

    fn poly(pts: &[(f64, f64)]) -> Polygon {
        Polygon::new(pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect())
    }

    /// The directed edges of the ring, counter-clockwise (reversed for a clockwise ring),
    /// as index pairs.
    fn ccw_ring_edges(ring: &Polygon) -> Vec<(u32, u32)> {
        let n = ring.len() as u32;
        let ccw = ring.signed_area() > 0.0;
        (0..n)
            .map(|i| {
                let j = (i + 1) % n;
                if ccw { (i, j) } else { (j, i) }
            })
            .collect()
    }

    /// Every guarantee of `triangulate` for the direct path's output on a valid ring, and
    /// its local Delaunay property (exact). Returns the triangles.
    fn check_direct(ring: &Polygon) -> Vec<[u32; 3]> {
        let pts = ring.points();
        let n = pts.len();
        let tris = triangulate_ring(pts).unwrap();
        // Deterministic, and what the public function returns.
        assert_eq!(triangulate_ring(pts).unwrap(), tris);
        assert_eq!(triangulate(&ring.clone().into()).unwrap(), tris);
        assert_eq!(tris.len(), n - 2);
        let at = |i: u32| pts[i as usize];
        let mut sum = 0.0;
        let mut directed: Vec<(u32, u32, u32)> = Vec::new();
        for &[a, b, c] in &tris {
            let twice = orient2d_value(at(a), at(b), at(c));
            assert!(twice > 0.0, "triangle {a} {b} {c} is not counter-clockwise");
            sum += 0.5 * twice;
            directed.extend([(a, b, c), (b, c, a), (c, a, b)]);
        }
        let area = ring.area();
        assert!(
            (sum - area).abs() <= 1e-9 * area,
            "triangles cover {sum}, polygon has {area}"
        );
        // Each ring edge is used once, in its counter-clockwise direction, never
        // backwards; every other edge is an interior diagonal used once each way.
        let boundary = ccw_ring_edges(ring);
        for &(a, b, c) in &directed {
            let forward = directed.iter().filter(|e| (e.0, e.1) == (a, b)).count();
            assert_eq!(forward, 1, "edge {a}→{b} used {forward} times");
            let back: Vec<u32> = directed
                .iter()
                .filter(|e| (e.0, e.1) == (b, a))
                .map(|e| e.2)
                .collect();
            if boundary.contains(&(a, b)) {
                assert!(back.is_empty(), "ring edge {a}→{b} has a triangle outside");
            } else {
                assert!(!boundary.contains(&(b, a)), "{a}→{b} runs against the ring");
                assert_eq!(back.len(), 1, "diagonal {a}–{b} is not shared");
                // Locally Delaunay: the opposite vertex is not strictly inside.
                assert!(
                    !in_circle(at(a), at(b), at(c), at(back[0])),
                    "diagonal {a}–{b} is not locally Delaunay"
                );
            }
        }
        for e in &boundary {
            assert!(
                directed.iter().any(|d| (d.0, d.1) == *e),
                "ring edge {e:?} unused"
            );
        }
        tris
    }

    fn min_angle(pts: &[DVec2], tris: &[[u32; 3]]) -> f64 {
        let mut least = f64::INFINITY;
        for t in tris {
            let [a, b, c] = t.map(|i| pts[i as usize]);
            for (o, u, v) in [(a, b, c), (b, c, a), (c, a, b)] {
                let (p, q) = (u - o, v - o);
                least = least.min(p.perp_dot(q).abs().atan2(p.dot(q)));
            }
        }
        least
    }

    /// Triangles as a sorted list of rotated triples (smallest index first).
    fn as_set(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
        let mut s: Vec<[u32; 3]> = tris
            .iter()
            .map(|t| {
                let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
                [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
            })
            .collect();
        s.sort_unstable();
        s
    }

    /// Checks the direct path against spade's: both constrained Delaunay, so the same
    /// smallest angle; the same triangles when `same_set`.
    fn check_against_spade(ring: &Polygon, same_set: bool) {
        let direct = check_direct(ring);
        let p: PolygonWithHoles = ring.clone().into();
        let spade = spade_triangles(&p).unwrap();
        let (a, b) = (
            min_angle(ring.points(), &direct),
            min_angle(ring.points(), &spade),
        );
        assert!((a - b).abs() <= 1e-9, "smallest angle {a} vs spade's {b}");
        if same_set {
            assert_eq!(as_set(&direct), as_set(&spade));
        }
    }

    /// The 32 integer points on the circle x² + y² = 1105 (exactly co-circular), in
    /// counter-clockwise order.
    fn lattice_circle() -> Vec<DVec2> {
        let mut pts = Vec::new();
        for x in -33i32..=33 {
            for y in -33i32..=33 {
                if x * x + y * y == 1105 {
                    pts.push(DVec2::new(x.into(), y.into()));
                }
            }
        }
        pts.sort_by(|a, b| a.y.atan2(a.x).total_cmp(&b.y.atan2(b.x)));
        pts
    }

    #[test]
    fn triangle_and_square_both_ways() {
        let tri = poly(&[(0., 0.), (1., 0.), (0., 1.)]);
        assert_eq!(check_direct(&tri), vec![[0, 1, 2]]);
        let mut cw = tri.clone();
        cw.reverse();
        assert_eq!(check_direct(&cw), vec![[0, 2, 1]]);
        let sq = Polygon::rect(DVec2::ZERO, DVec2::splat(2.0));
        check_against_spade(&sq, false);
        let mut sq_cw = sq.clone();
        sq_cw.reverse();
        check_against_spade(&sq_cw, false);
    }

    #[test]
    fn collinear_side_forces_a_fan() {
        // Eleven vertices on the base, one apex: the only triangulation fans from it.
        let mut pts: Vec<(f64, f64)> = (0..=10).map(|i| (f64::from(i), 0.0)).collect();
        pts.push((5.0, 3.0));
        let p = poly(&pts);
        let tris = check_direct(&p);
        assert!(tris.iter().all(|t| t.contains(&11)));
        check_against_spade(&p, true);
        // Collinear runs on every side of a square, clockwise.
        let mut sq = Vec::new();
        for i in 0..4 {
            sq.push((f64::from(i), 0.0));
        }
        for i in 0..4 {
            sq.push((4.0, f64::from(i)));
        }
        for i in 0..4 {
            sq.push((4.0 - f64::from(i), 4.0));
        }
        for i in 0..4 {
            sq.push((0.0, 4.0 - f64::from(i)));
        }
        let mut sq = poly(&sq);
        check_against_spade(&sq, false);
        sq.reverse();
        check_against_spade(&sq, false);
    }

    #[test]
    fn vertex_on_the_diagonal_blocks_the_ear() {
        // The ear at (2, 2) would cut along y = 0, through the reflex vertex (2, 0).
        let p = poly(&[
            (4., 0.),
            (2., 2.),
            (0., 0.),
            (0., -2.),
            (1., -2.),
            (2., 0.),
            (3., -2.),
            (4., -2.),
        ]);
        let tris = check_direct(&p);
        assert!(
            !tris
                .iter()
                .any(|t| t.contains(&0) && t.contains(&2) && t.contains(&1))
        );
        check_against_spade(&p, false);
    }

    #[test]
    fn spiral_and_comb() {
        // A square spiral corridor: many reflex vertices, few ears.
        let spiral = poly(&[
            (0., 0.),
            (10., 0.),
            (10., 10.),
            (2., 10.),
            (2., 4.),
            (6., 4.),
            (6., 6.),
            (4., 6.),
            (4., 8.),
            (8., 8.),
            (8., 2.),
            (0., 2.),
        ]);
        check_against_spade(&spiral, false);
        let comb = orthogonal(
            &[-1, -3, -1, -3, -1, -3],
            &[3, 1, 3, 1, 3, 1],
            1.0,
            DVec2::ZERO,
        );
        check_against_spade(&comb, false);
    }

    #[test]
    fn co_circular_vertices_are_deterministic() {
        let circle = lattice_circle();
        assert_eq!(circle.len(), 32);
        let p = Polygon::new(circle);
        // Every triangulation of it is Delaunay; the direct path picks one, always the
        // same one.
        let first = check_direct(&p);
        check_against_spade(&p, false);
        assert_eq!(triangulate_ring(p.points()).unwrap(), first);
        let hexagon = Polygon::regular(6, DVec2::new(3.0, -2.0), 5.0);
        check_against_spade(&hexagon, false);
    }

    #[test]
    fn too_many_vertices_are_left_to_spade() {
        let p = Polygon::regular(MAX_VERTICES + 1, DVec2::ZERO, 10.0);
        assert!(triangulate_ring(p.points()).is_none());
        assert_eq!(
            triangulate(&p.clone().into()).unwrap(),
            spade_triangles(&p.into()).unwrap()
        );
    }

    /// Scale and offset applied to a test polygon: unit, tiny, huge, far from the origin.
    fn placement() -> impl Strategy<Value = (f64, DVec2)> {
        prop_oneof![
            Just((1.0, DVec2::ZERO)),
            Just((1e-20, DVec2::ZERO)),
            Just((1e-3, DVec2::new(1.0, -2.0))),
            Just((1e6, DVec2::ZERO)),
            Just((1.0, DVec2::new(-3e7, 9e7))),
            (0.01f64..100.0, -1e4f64..1e4).prop_map(|(s, o)| (s, DVec2::splat(o))),
        ]
    }

    fn place(p: &Polygon, (scale, offset): (f64, DVec2), clockwise: bool) -> Polygon {
        let mut q = p.map_points(|v| v * scale + offset);
        if clockwise {
            q.reverse();
        }
        q
    }

    fn radii_and_jitter(
        n: std::ops::RangeInclusive<usize>,
    ) -> impl Strategy<Value = (Vec<f64>, Vec<f64>)> {
        prop::collection::vec(
            (
                prop_oneof![Just(5.0), Just(9.0), 5.0f64..9.0],
                prop_oneof![Just(0.0), Just(0.5), 0.0f64..1.0],
            ),
            n,
        )
        .prop_map(|v| v.into_iter().unzip())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Random stars: co-circular quadruples have probability 0, so the triangles are
        /// exactly spade's.
        #[test]
        fn random_stars_equal_spade(
            (radii, jitter) in radii_and_jitter(3..=MAX_VERTICES),
            clockwise in any::<bool>(),
        ) {
            let p = place(&star(&radii, &jitter, None), (1.0, DVec2::ZERO), clockwise);
            prop_assume!(p.validate().is_ok());
            check_against_spade(&p, true);
        }

        /// Degenerate stars: snapped to a grid (collinear runs, co-circular quadruples,
        /// equal radii), both orientations, tiny to huge coordinates.
        #[test]
        fn degenerate_stars(
            (radii, jitter) in radii_and_jitter(3..=MAX_VERTICES),
            snap in prop_oneof![Just(0.25), Just(0.5), Just(1.0)],
            at in placement(),
            clockwise in any::<bool>(),
        ) {
            let p = place(&star(&radii, &jitter, Some(snap)), at, clockwise);
            prop_assume!(p.validate().is_ok());
            check_against_spade(&p, false);
        }

        /// Convex polygons: on an ellipse, exact lattice points on a circle (all
        /// co-circular), rectangles and regular polygons.
        #[test]
        fn convex_and_co_circular(
            kind in 0u8..4,
            n in 3usize..=MAX_VERTICES,
            angles in prop::collection::vec(0.0f64..1.0, MAX_VERTICES),
            keep in prop::collection::vec(any::<bool>(), 32),
            size in (0.5f64..30.0, 0.5f64..30.0),
            at in placement(),
            clockwise in any::<bool>(),
        ) {
            let base = match kind {
                0 => {
                    let mut a: Vec<f64> = angles[..n].to_vec();
                    a.sort_by(f64::total_cmp);
                    Polygon::new(a.iter().map(|&t| {
                        let t = std::f64::consts::TAU * t;
                        DVec2::new(size.0 * t.cos(), size.1 * t.sin())
                    }).collect())
                }
                1 => Polygon::new(
                    lattice_circle().into_iter().zip(&keep).filter(|(_, k)| **k)
                        .map(|(v, _)| v).collect(),
                ),
                2 => Polygon::rect(DVec2::ZERO, DVec2::new(size.0, size.1)),
                _ => Polygon::regular(n, DVec2::ZERO, size.0),
            };
            let p = place(&base, at, clockwise);
            prop_assume!(p.validate().is_ok());
            check_against_spade(&p, false);
        }

        /// Orthogonal polygons: collinear runs, reflex corners, co-circular rectangles.
        #[test]
        fn orthogonal_polygons(
            cols in prop::collection::vec((-4i32..=-1, 1i32..=4), 1..=14),
            at in placement(),
            clockwise in any::<bool>(),
        ) {
            let (bottom, top): (Vec<i32>, Vec<i32>) = cols.into_iter().unzip();
            let p = place(&orthogonal(&bottom, &top, 1.0, DVec2::ZERO), at, clockwise);
            prop_assume!(p.len() <= MAX_VERTICES && p.validate().is_ok());
            check_against_spade(&p, false);
        }
    }
}
