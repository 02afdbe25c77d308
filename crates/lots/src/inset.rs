//! Insetting (inward offsetting) by the straight skeleton's wavefront.
//!
//! The inset of a polygon by `d` is its wavefront at time `d`: every edge moved inwards by
//! `d · w_e`. The event loop stops at time `d` (Kelly 2008 §4.4.1.1's partial run), but,
//! unlike Kelly's, split events are handled, so the result is exact: the wavefront may
//! split into several polygons, holes may merge with the outside, and parts vanish.
//!
//! # Guarantees
//!
//! * Every returned polygon is simple and lies inside the input.
//! * Each of its edges that comes from input edge `e` (see [`InsetRing::sources`]) lies on
//!   the line at distance exactly `d · w_e` (up to rounding) from `e`'s supporting line.
//! * The area does not increase with `d`, and the result is empty once the skeleton's
//!   last event has passed.
//!
//! # Limitations
//!
//! Between two consecutive parallel input edges of different weights the inset has a short
//! step edge with no source (`None`). An event that rounding puts a hair after `d` (less
//! than the time the fastest edge needs to move `1e-9` of the polygon's size) counts as
//! happening at `d`, so that two pieces meeting exactly at `d` come out separated, not
//! lying on each other.
//!
//! Where the wavefront touches itself at `d` (within `1e-9` of the polygon's size: two
//! vertices, or a vertex on an edge — weighted steps can hold such a contact over a
//! whole range of distances), pieces side by side come out as separate polygons sharing
//! that point, and a hole touching the ring around it is opened by moving each visit of
//! the point `2e-9` of the size into its own corner.

use polis_geom::lines::innermost_ring_containing;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};

use crate::LotsError;
use polis_geom::predicates::{Orientation, orient2d};

use crate::skeleton::events::{COINCIDENCE_REL, Engine};
use crate::skeleton::wavefront::{EdgeLine, Motion, motion};
use crate::skeleton::{check_input, reset_checked};

/// One ring of an inset shape, with the input edge each of its edges comes from.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct InsetRing {
    /// The vertices (counter-clockwise for outer rings, clockwise for holes).
    pub points: Vec<DVec2>,
    /// `sources[i]` is the input edge (numbered ring by ring, outer first) that edge
    /// `points[i] → points[i + 1]` is an offset of; `None` for a step between parallel
    /// edges of different weights.
    pub sources: Vec<Option<usize>>,
}

/// One connected piece of an inset, with edge sources.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct InsetShape {
    /// The outer ring.
    pub outer: InsetRing,
    /// The holes inside it.
    pub holes: Vec<InsetRing>,
}

impl InsetShape {
    /// The shape as a plain polygon with holes.
    pub fn to_polygon(&self) -> PolygonWithHoles {
        PolygonWithHoles::new(
            Polygon::new(self.outer.points.clone()),
            self.holes
                .iter()
                .map(|h| Polygon::new(h.points.clone()))
                .collect(),
        )
    }
}

/// The inset of `polygon` by distance `d` (metres): zero, one or several polygons.
///
/// The polygon must be valid and normalised (counter-clockwise outer ring, clockwise holes).
///
/// ```
/// use polis_geom::{DVec2, Polygon};
/// let square = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 10.0));
/// let inner = polis_lots::inset(&square.into(), 2.0)?;
/// assert_eq!(inner.len(), 1);
/// assert!((inner[0].area() - 36.0).abs() < 1e-9);
/// # Ok::<(), polis_lots::LotsError>(())
/// ```
pub fn inset(polygon: &PolygonWithHoles, d: f64) -> Result<Vec<PolygonWithHoles>, LotsError> {
    Ok(inset_shapes(polygon, None, d)?
        .iter()
        .map(InsetShape::to_polygon)
        .collect())
}

/// The weighted inset: edge `e` moves inwards by `d · weights[e]`.
pub fn inset_weighted(
    polygon: &PolygonWithHoles,
    weights: &[f64],
    d: f64,
) -> Result<Vec<PolygonWithHoles>, LotsError> {
    Ok(inset_shapes(polygon, Some(weights), d)?
        .iter()
        .map(InsetShape::to_polygon)
        .collect())
}

/// The (optionally weighted) inset with the source edge of every output edge.
pub fn inset_shapes(
    polygon: &PolygonWithHoles,
    weights: Option<&[f64]>,
    d: f64,
) -> Result<Vec<InsetShape>, LotsError> {
    Inset::default().shapes(polygon, weights, d)
}

/// A reusable insetting worker: keeps its buffers between calls.
#[derive(Debug, Default)]
pub struct Inset {
    engine: Engine,
}

impl Inset {
    /// A worker with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Same as [`inset_shapes`], reusing this worker's buffers.
    pub fn shapes(
        &mut self,
        polygon: &PolygonWithHoles,
        weights: Option<&[f64]>,
        d: f64,
    ) -> Result<Vec<InsetShape>, LotsError> {
        if !(d.is_finite() && d >= 0.0) {
            return Err(LotsError::InvalidParameter {
                name: "d",
                reason: format!("the inset distance is {d}; it must be finite and not negative"),
            });
        }
        check_input(polygon, weights)?;
        if let Some(shapes) = convex_before_any_event(polygon, weights, d) {
            return Ok(shapes);
        }
        reset_checked(&mut self.engine, polygon, weights);
        self.engine.run_through(d)?;
        wavefront_at(&self.engine, d)
    }
}

/// Convex polygons with at most this many vertices may skip the event engine.
const CONVEX_FAST_VERTICES: usize = 32;

/// The inset of a convex polygon without holes when no edge of its wavefront vanishes
/// before `d` (the common case of a setback much smaller than the lot): every vertex is
/// moved along its (weighted) bisector by exactly the engine's arithmetic, so the result
/// is the engine's, without building its event queue. `None` when that does not hold —
/// a hole, a reflex or straight vertex, parallel neighbours, an edge that vanishes before
/// `d` or within a safety margin after it — and the engine decides.
///
/// Convexity makes this exact: the wavefront of a convex polygon stays the intersection
/// of the moving half-planes, whose structure changes only when an edge shrinks to zero,
/// and no split event can happen without a reflex vertex.
fn convex_before_any_event(
    polygon: &PolygonWithHoles,
    weights: Option<&[f64]>,
    d: f64,
) -> Option<Vec<InsetShape>> {
    let pts = polygon.outer.points();
    let n = pts.len();
    if !polygon.holes.is_empty() || !(3..=CONVEX_FAST_VERTICES).contains(&n) {
        return None;
    }
    let weight = |i: usize| weights.map_or(Some(1.0), |w| w.get(i).copied());
    let mut edges = [None; CONVEX_FAST_VERTICES];
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let mut wmax = 0.0f64;
    for i in 0..n {
        let (a, b, c) = (pts[i], pts[(i + 1) % n], pts[(i + 2) % n]);
        if orient2d(a, b, c) != Orientation::CounterClockwise {
            return None;
        }
        let w = weight(i)?;
        wmax = wmax.max(w);
        lo = lo.min(a);
        hi = hi.max(a);
        edges[i] = Some(EdgeLine::new(a, b, w));
    }
    // Vertex i joins edge i − 1 (in) and edge i (out), as in the engine.
    let mut velocity = [DVec2::ZERO; CONVEX_FAST_VERTICES];
    for (i, v) in velocity.iter_mut().enumerate().take(n) {
        let (ein, eout) = (edges[(i + n - 1) % n]?, edges[i]?);
        match motion(&ein, &eout) {
            Motion::Moving(m) if m.is_finite() => *v = m,
            _ => return None,
        }
    }
    // The engine's tolerances; an edge must outlive `d` by a wide margin.
    let size = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let eps = COINCIDENCE_REL * size;
    let time_eps = eps / wmax.max(f64::MIN_POSITIVE);
    let safe_until = (d + time_eps) * (1.0 + 1e-6) + 16.0 * time_eps;
    for i in 0..n {
        let j = (i + 1) % n;
        let along = pts[j] - pts[i];
        let length = along.length();
        // How fast the edge shrinks: its end closing in on its start along it.
        let closing = (velocity[i] - velocity[j]).dot(along) / length;
        if !(length > 0.0 && closing.is_finite())
            || (closing > 0.0 && length / closing <= safe_until)
        {
            return None;
        }
    }
    let ring = InsetRing {
        points: (0..n).map(|i| pts[i] + velocity[i] * (d - 0.0)).collect(),
        sources: (0..n).map(Some).collect(),
    };
    // A convex wavefront does not touch itself: one ring or nothing.
    Some(
        finish_ring(ring, eps)
            .into_iter()
            .filter(|(_, outer)| *outer)
            .map(|(outer, _)| InsetShape {
                outer,
                holes: Vec::new(),
            })
            .collect(),
    )
}

/// The rings of the wavefront at time `d`, grouped into shapes. A ring made of weighted
/// steps alone is refused (`STEPS_ENCLOSE`, as the skeleton refuses it): nothing moves
/// it, so it would come out unchanged at every later distance.
fn wavefront_at(engine: &Engine, d: f64) -> Result<Vec<InsetShape>, LotsError> {
    let mut seen = vec![false; engine.verts.len()];
    let mut outers: Vec<InsetRing> = Vec::new();
    let mut holes: Vec<InsetRing> = Vec::new();
    for start in 0..engine.verts.len() {
        if seen[start] || !engine.verts[start].alive {
            continue;
        }
        let mut ring = InsetRing {
            points: Vec::new(),
            sources: Vec::new(),
        };
        let mut v = start;
        loop {
            seen[v] = true;
            let x = &engine.verts[v];
            ring.points.push(x.at(d));
            let e = x.out_edge as usize;
            ring.sources.push((e < engine.input_edges()).then_some(e));
            v = x.next as usize;
            if v == start || seen[v] || ring.points.len() > engine.verts.len() * 2 {
                break;
            }
        }
        if ring.sources.iter().all(Option::is_none) {
            return Err(LotsError::SkeletonFailed {
                reason: crate::skeleton::STEPS_ENCLOSE,
            });
        }
        for (ring, outer) in finish_ring(ring, engine.eps) {
            if outer {
                outers.push(ring);
            } else {
                holes.push(ring);
            }
        }
    }
    let mut shapes: Vec<InsetShape> = outers
        .into_iter()
        .map(|outer| InsetShape {
            outer,
            holes: Vec::new(),
        })
        .collect();
    for h in holes {
        let outers = shapes.iter().map(|s| &s.outer.points[..]);
        if let Some(i) = innermost_ring_containing(outers, h.points[0]) {
            shapes[i].holes.push(h);
        }
    }
    Ok(shapes)
}

/// Cleans a wavefront ring (zero-length edges, pinches) into simple rings, each with
/// whether it is an outer ring (`true`) or a hole (`false`); rings of no area are dropped.
fn finish_ring(mut ring: InsetRing, eps: f64) -> Vec<(InsetRing, bool)> {
    clean_ring(&mut ring, eps);
    // One sort by x serves the touch sweep and the pinch search (made again only when
    // the ring changes).
    let mut order = x_order(&ring.points);
    if add_touch_points(&mut ring, &order, eps) {
        order = x_order(&ring.points);
    }
    let mut finished = Vec::new();
    let mut pending = vec![(ring, Some(order))];
    while let Some((mut ring, order)) = pending.pop() {
        let order = order.unwrap_or_else(|| x_order(&ring.points));
        let pairs = pinch_pairs(&ring, &order, eps);
        if let Some((a, b)) = split_lobes(&ring, &pairs, eps) {
            // Depth first, the first piece next: the order follows the ring's.
            pending.push((b, None));
            pending.push((a, None));
            continue;
        }
        separate_pinches(&mut ring, &pairs, eps);
        if ring.points.len() < 3 {
            continue;
        }
        let area = polis_geom::polygon::ring_signed_area(&ring.points);
        if area.abs() > eps * eps {
            finished.push((ring, area > 0.0));
        }
    }
    finished
}

/// A ring can also touch itself where one of its vertices lies on another of its edges
/// (within `eps` of the edge, not of its ends): that edge gets a copy of the vertex, so
/// the touch is a point the ring visits twice, which [`split_lobes`] and
/// [`separate_pinches`] then treat as any other. Both halves of the edge keep its source.
/// A sweep over `x` (the vertices in `order`, [`x_order`]) with the edges whose extent
/// covers the vertex: about `n log n` for a ring of `n` vertices. Whether any edge got a
/// vertex.
fn add_touch_points(ring: &mut InsetRing, order: &[usize], eps: f64) -> bool {
    let n = ring.points.len();
    if n < 4 {
        return false;
    }
    let pts = &ring.points;
    let end = |e: usize| pts[if e + 1 < n { e + 1 } else { 0 }];
    let lo_x = |e: usize| pts[e].x.min(end(e).x);
    let mut edges: Vec<usize> = (0..n).collect();
    edges.sort_by(|&a, &b| lo_x(a).total_cmp(&lo_x(b)).then(a.cmp(&b)));
    let mut active: Vec<usize> = Vec::new();
    let mut next = 0;
    // (edge, position along it, vertex)
    let mut touches: Vec<(usize, f64, usize)> = Vec::new();
    for &v in order {
        let p = pts[v];
        while next < n && lo_x(edges[next]) <= p.x + eps {
            active.push(edges[next]);
            next += 1;
        }
        active.retain(|&e| pts[e].x.max(end(e).x) >= p.x - eps);
        for &e in &active {
            let (a, b) = (pts[e], end(e));
            if e == v
                || (e + 1) % n == v
                || a.distance(p) <= eps
                || b.distance(p) <= eps
                || polis_geom::predicates::distance_to_segment(p, a, b) > eps
            {
                continue;
            }
            touches.push((e, (p - a).dot(b - a), v));
        }
    }
    if touches.is_empty() {
        return false;
    }
    touches.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut points = Vec::with_capacity(n + touches.len());
    let mut sources = Vec::with_capacity(n + touches.len());
    let mut t = touches.iter().peekable();
    for e in 0..n {
        points.push(ring.points[e]);
        sources.push(ring.sources[e]);
        while let Some(&(_, _, v)) = t.next_if(|x| x.0 == e) {
            points.push(ring.points[v]);
            sources.push(ring.sources[e]);
        }
    }
    ring.points = points;
    ring.sources = sources;
    true
}

/// The indices of `points` sorted by `x`, then `y`, then index.
fn x_order(points: &[DVec2]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        let (p, q) = (points[a], points[b]);
        p.x.total_cmp(&q.x)
            .then(p.y.total_cmp(&q.y))
            .then(a.cmp(&b))
    });
    order
}

/// Points of `ring` within `eps` of another point of it (each pair once, `i < j`), in
/// the order of the sweep by `x` over `order` ([`x_order`]).
fn pinch_pairs(ring: &InsetRing, order: &[usize], eps: f64) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        let p = ring.points[i];
        for &j in &order[k + 1..] {
            let q = ring.points[j];
            if q.x - p.x > eps {
                break;
            }
            if p.distance(q) <= eps {
                pairs.push((i.min(j), i.max(j)));
            }
        }
    }
    pairs
}

/// A ring that touches itself in a point is two loops joined there. When the loops lie
/// side by side — two outer lobes (a part about to separate from another), an island
/// inside a hole, or a loop of no area (a spike out and back) — the exact answer is two
/// rings, returned here: the loop from the first visit to the second, and the rest.
/// `None` when there is no such point; a hole loop inside an outer loop (or two holes
/// touching) is left to [`separate_pinches`], which keeps it one ring.
fn split_lobes(
    ring: &InsetRing,
    pairs: &[(usize, usize)],
    eps: f64,
) -> Option<(InsetRing, InsetRing)> {
    let n = ring.points.len();
    if n < 4 {
        return None;
    }
    let tiny = eps * eps;
    let sign = |a: f64| {
        if a > tiny {
            1
        } else if a < -tiny {
            -1
        } else {
            0
        }
    };
    let area = polis_geom::polygon::ring_signed_area;
    for &(i, j) in pairs {
        if j - i < 2 || n - (j - i) < 2 {
            // Neighbours within `eps` are merged by `clean_ring`; a loop needs two edges.
            continue;
        }
        let inner = area(&ring.points[i..j]);
        let rest: Vec<DVec2> = ring.points[j..]
            .iter()
            .chain(&ring.points[..i])
            .copied()
            .collect();
        let outer = area(&rest);
        let split = match (sign(inner), sign(outer)) {
            (0, _) | (_, 0) | (1, 1) => true,
            // One loop inside the other: a hole in an outer ring stays one ring; an
            // outer loop inside a hole is an island of its own.
            (a, b) if a != b => inner + outer < 0.0,
            _ => false,
        };
        if split {
            let piece = |range: &mut dyn Iterator<Item = usize>| {
                let (points, sources) = range.map(|k| (ring.points[k], ring.sources[k])).unzip();
                InsetRing { points, sources }
            };
            return Some((piece(&mut (i..j)), piece(&mut (j..n).chain(0..i))));
        }
    }
    None
}

/// A ring can touch itself in a point where a hole loop meets the outer loop around it
/// (or two hole loops meet). Each visit of such a point is moved by `2·eps` into its own
/// corner — there the visits' corners are the ring's separate interior wedges — which
/// makes the ring simple and changes no edge by more than that. (Loops side by side are
/// split apart first by [`split_lobes`]: their visits' corners overlap.)
fn separate_pinches(ring: &mut InsetRing, pairs: &[(usize, usize)], eps: f64) {
    let n = ring.points.len();
    if n < 4 {
        return;
    }
    let mut pinched: Vec<usize> = pairs.iter().flat_map(|&(i, j)| [i, j]).collect();
    pinched.sort_unstable();
    pinched.dedup();
    let moved: Vec<(usize, DVec2)> = pinched
        .iter()
        .map(|&i| {
            let p = ring.points[i];
            let a = ring.points[(i + n - 1) % n];
            let b = ring.points[(i + 1) % n];
            let inward = (p - a).normalize_or_zero().perp() + (b - p).normalize_or_zero().perp();
            let dir = inward
                .try_normalize()
                .unwrap_or_else(|| (p - a).normalize_or_zero().perp());
            (i, p + dir * (2.0 * eps))
        })
        .collect();
    for (i, p) in moved {
        ring.points[i] = p;
    }
}

/// Removes zero-length edges: the surviving edge keeps the source of the edge that had
/// length.
fn clean_ring(ring: &mut InsetRing, eps: f64) {
    let mut points: Vec<DVec2> = Vec::with_capacity(ring.points.len());
    let mut sources: Vec<Option<usize>> = Vec::with_capacity(ring.points.len());
    for (&p, &s) in ring.points.iter().zip(&ring.sources) {
        if points.last().is_some_and(|&last| last.distance(p) <= eps) {
            if let Some(ls) = sources.last_mut() {
                *ls = s;
            }
            continue;
        }
        points.push(p);
        sources.push(s);
    }
    while points.len() > 1 {
        let (Some(&first), Some(&last)) = (points.first(), points.last()) else {
            break;
        };
        if first.distance(last) > eps {
            break;
        }
        points.pop();
        sources.pop();
    }
    ring.points = points;
    ring.sources = sources;
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The engine's inset, never the fast path.
    fn engine_shapes(
        polygon: &PolygonWithHoles,
        weights: Option<&[f64]>,
        d: f64,
    ) -> Vec<InsetShape> {
        let mut engine = Engine::default();
        crate::skeleton::prepare(&mut engine, polygon, weights).unwrap();
        engine.run_through(d).unwrap();
        wavefront_at(&engine, d).unwrap()
    }

    fn ring(points: &[(f64, f64)]) -> InsetRing {
        InsetRing {
            points: points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            sources: (0..points.len()).map(Some).collect(),
        }
    }

    fn is_valid(r: &InsetRing) -> bool {
        PolygonWithHoles::from(Polygon::new(r.points.clone()))
            .validate()
            .is_ok()
    }

    #[test]
    fn lobes_side_by_side_are_split_at_the_point_they_touch() {
        // Two squares touching corner to corner, as one ring; both visits of the
        // origin are reflex corners, so moving them into their corners would cross.
        let eps = 1e-9;
        let eight = ring(&[
            (0.0, 0.0),
            (1.0, -1.0),
            (2.0, 0.0),
            (1.0, 1.0),
            (0.0, 0.0),
            (-1.0, 1.0),
            (-2.0, 0.0),
            (-1.0, -1.0),
        ]);
        let rings = finish_ring(eight, eps);
        assert_eq!(rings.len(), 2);
        for (r, outer) in &rings {
            assert!(outer);
            assert!(is_valid(r));
            assert_eq!(r.points.len(), 4);
            assert!((ring_area(r) - 2.0).abs() < 1e-15);
            // The sources follow their edges: each ring's are consecutive edges.
            assert_eq!(r.sources[1], r.sources[0].map(|s| s + 1));
        }
        // The visits are within `eps` but not equal: still split, nothing moved.
        let mut near = ring(&[
            (0.0, 0.0),
            (1.0, -1.0),
            (2.0, 0.0),
            (1.0, 1.0),
            (3e-10, -4e-10),
            (-1.0, 1.0),
            (-2.0, 0.0),
            (-1.0, -1.0),
        ]);
        let before = near.points.clone();
        let rings = finish_ring(std::mem::replace(&mut near, ring(&[])), eps);
        assert_eq!(rings.len(), 2);
        for (r, _) in &rings {
            assert!(is_valid(r));
            assert!(r.points.iter().all(|p| before.contains(p)));
        }
    }

    #[test]
    fn a_vertex_touching_another_edge_splits_the_ring_there() {
        // A 2 × 1 rectangle above the x axis and a triangle below it, one ring: the
        // ring leaves the origin along the rectangle and comes back down its left side
        // through the origin (an edge from (0, 1) to (0, −1)), then round the triangle
        // to the origin, a vertex on that edge.
        let eps = 1e-9;
        let touching = ring(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (0.0, 1.0),
            (0.0, -1.0),
            (2.0, -1.0),
        ]);
        assert!(!is_valid(&touching));
        let rings = finish_ring(touching, eps);
        assert_eq!(rings.len(), 2);
        let mut areas: Vec<f64> = rings.iter().map(|(r, _)| ring_area(r)).collect();
        areas.sort_by(f64::total_cmp);
        assert_eq!(areas, [1.0, 2.0]);
        for (r, outer) in &rings {
            assert!(outer);
            assert!(is_valid(r), "{:?}", r.points);
            assert!(r.points.contains(&DVec2::ZERO));
        }
        // The split edge's two halves keep its source (edge 3).
        let sources: Vec<Option<usize>> =
            rings.iter().flat_map(|(r, _)| r.sources.clone()).collect();
        assert_eq!(sources.iter().filter(|&&s| s == Some(3)).count(), 2);
    }

    #[test]
    fn a_hole_touching_its_outer_ring_stays_one_simple_ring() {
        // A 4 × 4 square whose bottom edge touches, at (2, 0), a diamond hole above it.
        let eps = 1e-9;
        let pinched = ring(&[
            (0.0, 0.0),
            (2.0, 0.0),
            (1.0, 1.0),
            (2.0, 2.0),
            (3.0, 1.0),
            (2.0, 0.0),
            (4.0, 0.0),
            (4.0, 4.0),
            (0.0, 4.0),
        ]);
        let rings = finish_ring(pinched, eps);
        assert_eq!(rings.len(), 1);
        let (r, outer) = &rings[0];
        assert!(outer);
        assert!(is_valid(r), "{:?}", r.points);
        assert!((ring_area(r) - 14.0).abs() < 1e-7);
    }

    #[test]
    fn a_spike_out_and_back_is_dropped() {
        let eps = 1e-9;
        let spiked = ring(&[
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 4.0),
            (2.0, 4.0),
            (2.0, 6.0),
            (2.0, 4.0),
            (0.0, 4.0),
        ]);
        let rings = finish_ring(spiked, eps);
        assert_eq!(rings.len(), 1);
        let r = &rings[0].0;
        assert!(is_valid(r));
        // The square, with the spike's foot left as a straight vertex.
        assert_eq!(r.points.len(), 5);
        assert!(!r.points.contains(&DVec2::new(2.0, 6.0)));
        assert_eq!(ring_area(r), 16.0);
    }

    fn ring_area(r: &InsetRing) -> f64 {
        polis_geom::polygon::ring_signed_area(&r.points)
    }

    #[test]
    fn a_lot_with_a_small_setback_takes_the_fast_path() {
        let lot: PolygonWithHoles = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.5),
            DVec2::new(9.5, 18.0),
            DVec2::new(-0.5, 17.0),
        ])
        .into();
        let weights = [3.0, 1.0, 1.0, 1.0];
        for w in [None, Some(&weights[..])] {
            for d in [0.0, 1.0, 1.6] {
                let fast = convex_before_any_event(&lot, w, d).expect("no event before d");
                assert_eq!(fast, engine_shapes(&lot, w, d));
                assert_eq!(Inset::new().shapes(&lot, w, d).unwrap(), fast);
            }
        }
        // Past the first edge event the engine decides.
        assert!(convex_before_any_event(&lot, None, 5.5).is_none());
        // Not convex, or with a hole: the engine.
        let l: PolygonWithHoles = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 4.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(4.0, 10.0),
            DVec2::new(0.0, 10.0),
        ])
        .into();
        assert!(convex_before_any_event(&l, None, 0.5).is_none());
    }

    fn convex_polygon() -> impl Strategy<Value = Vec<DVec2>> {
        // Points on an ellipse in angular order (convex), some nearly collinear triples
        // from angles close together; or a lot-like quadrilateral.
        prop_oneof![
            (
                prop::collection::vec(0.0f64..1.0, 3..14),
                1.0f64..60.0,
                0.05f64..1.0,
                0.0f64..3.2
            )
                .prop_map(|(mut t, a, ratio, rot)| {
                    t.sort_by(f64::total_cmp);
                    let (s, c) = rot.sin_cos();
                    t.iter()
                        .map(|&u| {
                            let ang = std::f64::consts::TAU * u;
                            let p = DVec2::new(a * ang.cos(), a * ratio * ang.sin());
                            DVec2::new(c * p.x - s * p.y + 100.0, s * p.x + c * p.y - 40.0)
                        })
                        .collect()
                }),
            (2.0f64..30.0, 2.0f64..40.0, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(w, h, dx, dy)| {
                vec![
                    DVec2::new(0.0, 0.0),
                    DVec2::new(w, dy),
                    DVec2::new(w + dx, h),
                    DVec2::new(0.0, h + dy),
                ]
            }),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Whenever the fast path answers, its answer is exactly the engine's (every bit),
        /// for any weights and distances up to and past the polygon's collapse.
        #[test]
        fn the_fast_path_answers_exactly_as_the_engine(
            pts in convex_polygon(),
            weights in prop::collection::vec(prop_oneof![Just(1.0), Just(2.0), 0.2f64..4.0], 14),
            weighted in any::<bool>(),
            frac in prop_oneof![Just(0.0), 0.0f64..0.05, 0.0f64..1.2],
        ) {
            let polygon: PolygonWithHoles = Polygon::new(pts).into();
            prop_assume!(check_input(&polygon, None).is_ok());
            let n = polygon.outer.len();
            let w = weighted.then(|| &weights[..n]);
            let size = polygon.outer.bbox().size().max_element();
            let d = frac * size;
            if let Some(fast) = convex_before_any_event(&polygon, w, d) {
                prop_assert_eq!(&fast, &engine_shapes(&polygon, w, d));
            }
            prop_assert_eq!(Inset::new().shapes(&polygon, w, d).unwrap(), engine_shapes(&polygon, w, d));
        }
    }
}
