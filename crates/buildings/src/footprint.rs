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
    // Insets are simple (polis-lots guarantees it) and fitted rectangles are checked, so
    // no second validation is needed.
    if region.area() < params.min_area.max(1e-6) {
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
    let span = region.bbox().size().length() * 2.0;
    let hit = |c: DVec2, d: DVec2| -> f64 {
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
    // Centre: the centroid when it is inside, else the vertex-pair midpoint inside the
    // region with the roomiest cross (concave regions).
    let n = region.len();
    let pairs = if n <= 16 { n } else { 1 };
    let candidates =
        std::iter::once(region.centroid())
            .chain((0..pairs).flat_map(|i| {
                (i + 2..n).map(move |j| (region.vertex(i) + region.vertex(j)) * 0.5)
            }));
    let mut best: Option<(f64, DVec2, f64, f64)> = None;
    for c in candidates {
        if region.locate(c) != polis_geom::PointLocation::Inside {
            continue;
        }
        let hw = hit(c, x).min(hit(c, -x));
        let hd = hit(c, y).min(hit(c, -y));
        let score = hw * hd;
        if score.is_finite() && best.is_none_or(|b| score > b.0) {
            best = Some((score, c, hw, hd));
        }
        if best.is_some() && c == region.centroid() {
            break;
        }
    }
    let (_, c, mut hw, mut hd) = best?;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn lot(points: Vec<DVec2>, street: Vec<usize>) -> Lot {
        let polygon = Polygon::new(points);
        Lot {
            area: polygon.area(),
            polygon,
            street_edges: street,
            block_id: 0,
        }
    }

    #[test]
    fn downtown_is_the_lot() {
        let l = lot(
            Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 20.0)).into_points(),
            vec![0],
        );
        let f = footprint(
            &l,
            0,
            FootprintStrategy::Downtown,
            &FootprintParams::default(),
        )
        .unwrap()
        .unwrap();
        assert_eq!(f.area(), 200.0);
    }

    #[test]
    fn suburban_retreats_further_from_the_street() {
        let l = lot(
            Polygon::rect(DVec2::ZERO, DVec2::new(20.0, 40.0)).into_points(),
            vec![0],
        );
        let p = FootprintParams::default();
        let f = footprint(&l, 0, FootprintStrategy::Suburban, &p)
            .unwrap()
            .unwrap();
        let b = f.bbox();
        assert!(
            (b.min.y - 5.0).abs() < 1e-9 && (b.max.y - 38.0).abs() < 1e-9,
            "{b:?}"
        );
        assert!((b.min.x - 2.0).abs() < 1e-9 && (b.max.x - 18.0).abs() < 1e-9);
    }

    #[test]
    fn clockwise_lots_keep_their_street_edge() {
        let mut pts = Polygon::rect(DVec2::ZERO, DVec2::new(20.0, 40.0)).into_points();
        pts.reverse(); // edges: 0 = (0,40)→(20,40)? reversed ring: (0,40),(20,40),(20,0),(0,0)
        let l = lot(pts, vec![2]); // (20,0) → (0,0): the y = 0 street
        let f = footprint(
            &l,
            0,
            FootprintStrategy::Suburban,
            &FootprintParams::default(),
        )
        .unwrap()
        .unwrap();
        assert!((f.bbox().min.y - 5.0).abs() < 1e-9, "{:?}", f.bbox());
    }

    #[test]
    fn rectangle_fit_in_a_concave_region() {
        let region = Polygon::new(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(30.0, 0.0),
            DVec2::new(30.0, 10.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(10.0, 30.0),
            DVec2::new(0.0, 30.0),
        ]);
        let r = fit_rectangle(&region, DVec2::X).unwrap();
        assert!(r.area() > 10.0);
        assert!(
            rect_inside(
                &region,
                &[r.vertex(0), r.vertex(1), r.vertex(2), r.vertex(3)]
            ) || r.points().iter().all(|&p| region.contains(p))
        );
    }

    #[test]
    fn tiny_lots_carry_nothing() {
        let l = lot(
            Polygon::rect(DVec2::ZERO, DVec2::new(6.0, 6.0)).into_points(),
            vec![0],
        );
        let p = FootprintParams::default();
        assert!(
            footprint(&l, 0, FootprintStrategy::Industrial, &p)
                .unwrap()
                .is_none()
        );
        let bad = lot(vec![DVec2::ZERO, DVec2::X, DVec2::new(2.0, 0.0)], vec![0]);
        assert!(matches!(
            footprint(&bad, 3, FootprintStrategy::Downtown, &p),
            Err(BuildingsError::Lot { lot_id: 3, .. })
        ));
    }
}
