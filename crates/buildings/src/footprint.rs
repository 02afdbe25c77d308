//! Footprints from lots by building type (Kelly 2008 §4.4.3.1): zero inset downtown, a
//! weighted inset with a deeper street setback for suburban kinds (and a rectangle fit
//! for houses), a uniform inset for industrial kinds.
//!
//! # Guarantees
//! The footprint is a valid counter-clockwise polygon inside the lot (insets lie inside
//! their input; the fitted rectangle is checked against the region exactly).
//!
//! # Limitations
//! When an inset splits the lot into several pieces, the largest piece is kept; holes of
//! the inset (impossible for simple lots) are dropped.

use polis_geom::{
    DVec2, Orientation, Polygon, PolygonWithHoles, SegmentIntersection, orient2d,
    segment_intersection,
};
use polis_lots::Lot;

use crate::BuildingsError;
use crate::params::{FootprintParams, FootprintStrategy};

/// Cuts the footprint of a building from `lot` with `strategy`. `Ok(None)` when nothing
/// of at least `params.min_area` remains.
pub fn footprint(
    lot: &Lot,
    lot_id: u64,
    strategy: FootprintStrategy,
    params: &FootprintParams,
) -> Result<Option<Polygon>, BuildingsError> {
    let lot_err = |reason: String| BuildingsError::Lot { lot_id, reason };
    let mut ring = lot.polygon.clone();
    ring.validate()
        .map_err(|e| lot_err(format!("invalid lot polygon: {e}")))?;
    ring.make_ccw();
    let n = ring.len();
    // `make_ccw` reverses when needed; street edge i then becomes edge n − 2 − i.
    let reversed = !lot.polygon.is_ccw();
    let street: Vec<usize> = lot
        .street_edges
        .iter()
        .filter(|&&e| e < n)
        .map(|&e| if reversed { (2 * n - 2 - e) % n } else { e })
        .collect();
    let poly: PolygonWithHoles = ring.clone().into();
    let ring_edge = |p: &Polygon, e: usize, rev: bool| {
        let (a, b) = p.edge(if rev { (2 * n - 2 - e) % n } else { e });
        if rev { (b, a) } else { (a, b) }
    };
    let region = match strategy {
        FootprintStrategy::Downtown => Some(ring),
        FootprintStrategy::Industrial => {
            largest(polis_lots::inset(&poly, params.industrial_setback)?)
        }
        FootprintStrategy::Suburban | FootprintStrategy::SuburbanRectangle => {
            if params.side_setback <= 0.0 {
                Some(ring)
            } else {
                let w: Vec<f64> = (0..n)
                    .map(|i| {
                        if street.contains(&i) {
                            params.street_setback / params.side_setback
                        } else {
                            1.0
                        }
                    })
                    .collect();
                largest(polis_lots::inset_weighted(&poly, &w, params.side_setback)?)
            }
        }
    };
    let Some(region) = region else {
        return Ok(None);
    };
    let region = if strategy == FootprintStrategy::SuburbanRectangle {
        let primary = street.first().copied().unwrap_or(0);
        let (a, b) = ring_edge(&lot.polygon, primary, reversed);
        match fit_rectangle(&region, b - a) {
            Some(r) => r,
            None => return Ok(None),
        }
    } else {
        region
    };
    if region.area() < params.min_area.max(1e-6) || region.validate().is_err() {
        return Ok(None);
    }
    Ok(Some(region))
}

/// The largest outer ring of an inset result.
fn largest(pieces: Vec<PolygonWithHoles>) -> Option<Polygon> {
    pieces
        .into_iter()
        .map(|p| p.outer)
        .max_by(|a, b| a.area().total_cmp(&b.area()))
}

/// Kelly's rectangle fit: a rectangle aligned with `dir` (the primary street edge),
/// centred on the region's centroid (or a vertex-average fallback inside it), with
/// half-extents from the nearest boundary hits along and across `dir`, shrunk until it
/// lies inside the region.
pub fn fit_rectangle(region: &Polygon, dir: DVec2) -> Option<Polygon> {
    let len = dir.length();
    if !(len > 0.0 && len.is_finite()) {
        return None;
    }
    let x = dir / len;
    let y = DVec2::new(-x.y, x.x);
    let mut c = region.centroid();
    if !region.contains(c) {
        // A concave region: try midpoints of diagonals from the first vertex.
        c = (1..region.len())
            .map(|i| (region.vertex(0) + region.vertex(i)) * 0.5)
            .find(|&p| region.contains(p))?;
    }
    let span = region.bbox().size().length() * 2.0;
    let hit = |d: DVec2| -> f64 {
        let far = c + d * span;
        region
            .edges()
            .filter_map(|(a, b)| match segment_intersection(c, far, a, b) {
                SegmentIntersection::Disjoint => None,
                SegmentIntersection::Crossing { point, .. } => Some(point.distance(c)),
                _ => Some(a.distance(c).min(b.distance(c))),
            })
            .fold(f64::INFINITY, f64::min)
    };
    let mut hw = hit(x).min(hit(-x));
    let mut hd = hit(y).min(hit(-y));
    if !(hw.is_finite() && hd.is_finite()) {
        return None;
    }
    for _ in 0..40 {
        let corners = [
            c - x * hw - y * hd,
            c + x * hw - y * hd,
            c + x * hw + y * hd,
            c - x * hw + y * hd,
        ];
        if rect_inside(region, &corners) {
            let r = Polygon::new(corners.to_vec());
            return (r.area() > 0.0 && r.validate().is_ok()).then_some(r);
        }
        hw *= 0.9;
        hd *= 0.9;
    }
    None
}

/// Whether the convex quad `q` lies strictly inside `region`: corners inside, no region
/// vertex inside or on the quad, no crossing.
fn rect_inside(region: &Polygon, q: &[DVec2; 4]) -> bool {
    if !q.iter().all(|&p| region.contains(p)) {
        return false;
    }
    let inside_q =
        |p: DVec2| (0..4).all(|i| orient2d(q[i], q[(i + 1) % 4], p) != Orientation::Clockwise);
    if region.points().iter().any(|&p| inside_q(p)) {
        return false;
    }
    (0..4).all(|i| {
        region.edges().all(|(a, b)| {
            segment_intersection(q[i], q[(i + 1) % 4], a, b) == SegmentIntersection::Disjoint
        })
    })
}
