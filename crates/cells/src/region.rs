//! [`Cell::polygon_with_holes`]: a cell's region as a polygon with holes that passes
//! [`PolygonWithHoles::validate`], even where islands touch the boundary or each other.
//!
//! An island attached to the cell's boundary (or to another island) at a single node
//! — a cut vertex of the road graph — gives a hole ring that shares a vertex with another
//! ring. The region is well defined, but such rings are not a valid polygon with holes
//! (rings must be disjoint), so the stages downstream (straight skeleton, insets, lot
//! subdivision) could not take it. Here every hole vertex at the position of a vertex of
//! another ring is moved *into its own hole* by [`TOUCH_SEPARATION`] along the bisector of
//! the hole's corner: the hole shrinks by a sliver, the rings come apart, and nothing
//! else changes. The boundary never moves, so neighbouring cells still share their edges
//! exactly.

use std::cmp::Ordering;

use polis_geom::predicates::orient2d_value;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};

use crate::error::Error;
use crate::output::Cell;

/// How far a hole vertex that touches another ring is moved into its hole, in metres:
/// 1 µm, far below any road or lot dimension and far above the rounding of coordinates
/// within [`polis_geom::MAX_COORDINATE`] (about 15 nm at 10⁸ m). It is capped at a
/// thousandth of the shorter of the vertex's two hole edges, and divided by 16 again
/// (at most 6 times) if the moved ring would still touch something.
pub const TOUCH_SEPARATION: f64 = 1e-6;

/// Retries with a 16 times smaller separation before giving up.
const RETRIES: usize = 6;

impl Cell {
    /// The cell's region (boundary minus islands) as a [`PolygonWithHoles`] that passes
    /// [`PolygonWithHoles::validate`]: outer ring counter-clockwise, holes clockwise, no
    /// two rings sharing a point.
    ///
    /// Equal to [`Cell::region`] except where a hole touches the boundary or another hole
    /// at a node: there the hole's copy of the vertex is moved into the hole by
    /// [`TOUCH_SEPARATION`] (so the hole loses an area of the order of
    /// `TOUCH_SEPARATION × edge length`). Vertex `j` of hole `i` still corresponds to
    /// `self.holes[i].nodes[j]`, and the outer ring is exactly `self.boundary.polygon`.
    ///
    /// # Errors
    /// [`Error::Geom`] with the validation error if the rings still touch after the
    /// retries (not expected for cells produced by [`extract`](crate::extract)).
    pub fn polygon_with_holes(&self) -> Result<PolygonWithHoles, Error> {
        let region = self.region();
        let touching = touching_hole_vertices(&region);
        if touching.is_empty() {
            region.validate()?;
            return Ok(region);
        }
        let mut scale = 1.0;
        let mut last = None;
        for _ in 0..=RETRIES {
            let mut out = region.clone();
            for &(i, j) in &touching {
                let (Some(hole), Some(moved)) = (
                    out.holes.get(i),
                    region.holes.get(i).and_then(|h| separated(h, j, scale)),
                ) else {
                    continue;
                };
                let mut points = hole.points().to_vec();
                if let Some(p) = points.get_mut(j) {
                    *p = moved;
                }
                if let Some(h) = out.holes.get_mut(i) {
                    *h = Polygon::new(points);
                }
            }
            match out.validate() {
                Ok(()) => return Ok(out),
                Err(e) => last = Some(e),
            }
            scale /= 16.0;
        }
        Err(match last {
            Some(e) => Error::Geom(e),
            None => Error::Internal("no separation was tried".into()),
        })
    }
}

/// `(hole, vertex)` of every hole vertex at the position of a vertex of another ring.
fn touching_hole_vertices(region: &PolygonWithHoles) -> Vec<(usize, usize)> {
    // (position, ring: 0 = outer, i + 1 = hole i, vertex)
    let mut all: Vec<(DVec2, usize, usize)> = Vec::new();
    for (ring, poly) in std::iter::once(&region.outer)
        .chain(region.holes.iter())
        .enumerate()
    {
        all.extend(poly.points().iter().enumerate().map(|(j, &p)| (p, ring, j)));
    }
    let by_pos = |a: &(DVec2, usize, usize), b: &(DVec2, usize, usize)| -> Ordering {
        a.0.x.total_cmp(&b.0.x).then(a.0.y.total_cmp(&b.0.y))
    };
    all.sort_by(|a, b| by_pos(a, b).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut out = Vec::new();
    let mut k = 0;
    while k < all.len() {
        let mut e = k + 1;
        while e < all.len() && all[e].0 == all[k].0 {
            e += 1;
        }
        let group = &all[k..e];
        if group.iter().any(|g| g.1 != group[0].1) {
            out.extend(group.iter().filter(|g| g.1 > 0).map(|g| (g.1 - 1, g.2)));
        }
        k = e;
    }
    out.sort_unstable();
    out
}

/// Vertex `j` of the clockwise ring `hole`, moved into the hole along the bisector of its
/// corner by `scale × TOUCH_SEPARATION` (capped at a thousandth of the shorter adjacent
/// edge). `None` for a degenerate ring.
fn separated(hole: &Polygon, j: usize, scale: f64) -> Option<DVec2> {
    let n = hole.len();
    if n < 3 || j >= n {
        return None;
    }
    let v = hole.vertex(j);
    let u = hole.vertex((j + n - 1) % n);
    let w = hole.vertex((j + 1) % n);
    let (a, b) = ((u - v).normalize_or_zero(), (w - v).normalize_or_zero());
    // The hole is clockwise: its interior is to the right of u → v → w.
    let turn = orient2d_value(u, v, w);
    let dir = if turn == 0.0 || (a + b).length_squared() < 1e-24 {
        // Straight on: the right normal of the outgoing edge.
        DVec2::new(b.y, -b.x)
    } else if turn < 0.0 {
        // A right turn: a convex corner of the hole, whose interior is between a and b.
        (a + b).normalize_or_zero()
    } else {
        -(a + b).normalize_or_zero()
    };
    let shortest = (u - v).length().min((w - v).length());
    let delta = (TOUCH_SEPARATION * scale).min(shortest * 1e-3);
    let moved = v + dir * delta;
    (moved != v && moved.is_finite()).then_some(moved)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separation_goes_into_the_hole() {
        // Clockwise unit square.
        let hole = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(1.0, 0.0),
        ]);
        for j in 0..4 {
            let p = separated(&hole, j, 1.0).unwrap();
            assert!(hole.contains(p), "{j}: {p}");
            assert!((p - hole.vertex(j)).length() <= TOUCH_SEPARATION * 1.000_001);
        }
        // A reflex corner of a clockwise L-shaped hole, and a straight vertex.
        let l = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(0.0, 2.0),
            DVec2::new(1.0, 2.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, 1.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(1.0, 0.0),
        ]);
        for j in 0..l.len() {
            let p = separated(&l, j, 1.0).unwrap();
            assert!(l.contains(p), "{j}: {p}");
        }
    }

    #[test]
    fn touching_vertices_are_found_across_rings_only() {
        let outer = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(0.0, 10.0),
        ]);
        // Hole 0 touches the outer ring at (0, 0); hole 1 touches hole 0 at (4, 4).
        let h0 = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 4.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(4.0, 2.0),
        ]);
        let h1 = Polygon::new(vec![
            DVec2::new(4.0, 4.0),
            DVec2::new(4.0, 6.0),
            DVec2::new(6.0, 6.0),
            DVec2::new(6.0, 4.0),
        ]);
        let r = PolygonWithHoles::new(outer, vec![h0, h1]);
        assert!(r.validate().is_err());
        assert_eq!(touching_hole_vertices(&r), vec![(0, 0), (0, 2), (1, 0)]);
    }
}
