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

use polis_geom::lines::innermost_ring_containing;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use serde::{Deserialize, Serialize};

use crate::LotsError;
use crate::skeleton::events::Engine;
use crate::skeleton::prepare;

/// One ring of an inset shape, with the input edge each of its edges comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InsetRing {
    /// The vertices (counter-clockwise for outer rings, clockwise for holes).
    pub points: Vec<DVec2>,
    /// `sources[i]` is the input edge (numbered ring by ring, outer first) that edge
    /// `points[i] → points[i + 1]` is an offset of; `None` for a step between parallel
    /// edges of different weights.
    pub sources: Vec<Option<usize>>,
}

/// One connected piece of an inset, with edge sources.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
        prepare(&mut self.engine, polygon, weights)?;
        self.engine.run_through(d)?;
        Ok(wavefront_at(&self.engine, d))
    }
}

/// The rings of the wavefront at time `d`, grouped into shapes.
fn wavefront_at(engine: &Engine, d: f64) -> Vec<InsetShape> {
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
        clean_ring(&mut ring, engine.eps);
        separate_pinches(&mut ring, engine.eps);
        if ring.points.len() < 3 {
            continue;
        }
        let area = polis_geom::polygon::ring_signed_area(&ring.points);
        if area.abs() <= engine.eps * engine.eps {
            continue;
        }
        if area > 0.0 {
            outers.push(ring);
        } else {
            holes.push(ring);
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
    shapes
}

/// At the exact time of an event a ring can touch itself in a point (a hole meeting the
/// outside, two parts about to separate). Each visit of such a point is moved by `2·eps`
/// into its own corner, which makes the ring simple and changes no edge by more than that.
fn separate_pinches(ring: &mut InsetRing, eps: f64) {
    let n = ring.points.len();
    if n < 4 {
        return;
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| {
        let (p, q) = (ring.points[a], ring.points[b]);
        p.x.total_cmp(&q.x)
            .then(p.y.total_cmp(&q.y))
            .then(a.cmp(&b))
    });
    let mut pinched: Vec<usize> = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        let p = ring.points[i];
        for &j in &order[k + 1..] {
            let q = ring.points[j];
            if q.x - p.x > eps {
                break;
            }
            if p.distance(q) <= eps {
                pinched.push(i);
                pinched.push(j);
            }
        }
    }
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
