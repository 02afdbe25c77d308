//! Painting polygons into a pixel grid over a rectangle of the layout: class maps such as
//! a terrain's land-use texture.
//!
//! A [`ClassGrid`] is `width × height` bytes, row 0 at the rectangle's top (largest `y`:
//! north up, as images are drawn). [`ClassGrid::fill`] sets every pixel whose *centre*
//! lies inside a polygon (even–odd over its outer ring and holes) by scanlines: each row's
//! centre line is crossed with the polygon's edges, the crossings sorted, and the spans
//! between pairs filled.
//!
//! # Guarantees
//! * A pixel is painted exactly when its centre is inside the polygon (centres on an edge
//!   count as inside on an edge's lower/left side by the half-open crossing rule, so two
//!   polygons sharing an edge never both miss nor both take a centre on it).
//! * Deterministic, never panics; non-finite coordinates are skipped.

use glam::DVec2;

use crate::{Aabb2, PolygonWithHoles};

/// A grid of class bytes over a rectangle (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClassGrid {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Row-major bytes, row 0 at the top (largest `y`).
    pub cells: Vec<u8>,
    bounds_min: [u64; 2],
    bounds_max: [u64; 2],
}

impl ClassGrid {
    /// A `width × height` grid over `bounds`, every pixel `fill` (sizes of 0 become 1).
    pub fn new(width: u32, height: u32, bounds: Aabb2, fill: u8) -> ClassGrid {
        let (width, height) = (width.max(1), height.max(1));
        ClassGrid {
            width,
            height,
            cells: vec![fill; width as usize * height as usize],
            bounds_min: [bounds.min.x.to_bits(), bounds.min.y.to_bits()],
            bounds_max: [bounds.max.x.to_bits(), bounds.max.y.to_bits()],
        }
    }

    /// The rectangle covered.
    pub fn bounds(&self) -> Aabb2 {
        Aabb2 {
            min: DVec2::new(
                f64::from_bits(self.bounds_min[0]),
                f64::from_bits(self.bounds_min[1]),
            ),
            max: DVec2::new(
                f64::from_bits(self.bounds_max[0]),
                f64::from_bits(self.bounds_max[1]),
            ),
        }
    }

    /// The layout point at the centre of pixel `(column, row)`.
    pub fn centre(&self, column: u32, row: u32) -> DVec2 {
        let b = self.bounds();
        let size = b.max - b.min;
        DVec2::new(
            b.min.x + (f64::from(column) + 0.5) * size.x / f64::from(self.width),
            b.max.y - (f64::from(row) + 0.5) * size.y / f64::from(self.height),
        )
    }

    /// The class at pixel `(column, row)`, if inside the grid.
    pub fn get(&self, column: u32, row: u32) -> Option<u8> {
        if column >= self.width || row >= self.height {
            return None;
        }
        self.cells
            .get(row as usize * self.width as usize + column as usize)
            .copied()
    }

    /// Sets every pixel whose centre lies inside `polygon` to `class`.
    pub fn fill(&mut self, polygon: &PolygonWithHoles, class: u8) {
        let b = self.bounds();
        let size = b.max - b.min;
        if !(size.x > 0.0 && size.y > 0.0) {
            return;
        }
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        // Rows whose centre line the polygon's box reaches.
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in polygon.outer.points() {
            lo = lo.min(p.y);
            hi = hi.max(p.y);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return;
        }
        // Row r's centre: y = max.y − (r + ½)·size.y/h.
        let row_of = |y: f64| (b.max.y - y) / size.y * h - 0.5;
        let first = row_of(hi).ceil().max(0.0);
        let last = row_of(lo).floor().min(h - 1.0);
        if first > last {
            return;
        }
        let rings: Vec<&[DVec2]> = std::iter::once(polygon.outer.points())
            .chain(polygon.holes.iter().map(|r| r.points()))
            .collect();
        let mut xs: Vec<f64> = Vec::new();
        let mut row = first as u32;
        while f64::from(row) <= last {
            let y = b.max.y - (f64::from(row) + 0.5) * size.y / h;
            xs.clear();
            for ring in &rings {
                let n = ring.len();
                for i in 0..n {
                    let (a, c) = (ring[i], ring[(i + 1) % n]);
                    // Half-open in y, so a vertex on the line counts once.
                    if (a.y <= y) != (c.y <= y) {
                        let x = a.x + (y - a.y) * (c.x - a.x) / (c.y - a.y);
                        if x.is_finite() {
                            xs.push(x);
                        }
                    }
                }
            }
            xs.sort_unstable_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                // Columns whose centre lies in [x0, x1).
                let col = |x: f64| (x - b.min.x) / size.x * w - 0.5;
                let c0 = col(pair[0]).ceil().max(0.0);
                let c1 = (col(pair[1]).ceil() - 1.0).min(w - 1.0);
                if c0 > c1 {
                    continue;
                }
                let start = row as usize * self.width as usize;
                if let Some(span) = self
                    .cells
                    .get_mut(start + c0 as usize..=start + c1 as usize)
                {
                    span.fill(class);
                }
            }
            row += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{PointLocation, Polygon};

    #[test]
    fn pixels_are_painted_exactly_when_their_centre_is_inside() {
        let bounds = Aabb2::new(DVec2::new(-50.0, -40.0), DVec2::new(50.0, 60.0));
        let poly = PolygonWithHoles::new(
            Polygon::new(vec![
                DVec2::new(-30.3, -20.0),
                DVec2::new(40.0, -35.1),
                DVec2::new(10.0, 55.7),
            ]),
            vec![{
                let mut h = Polygon::rect(DVec2::new(0.0, 0.0), DVec2::new(8.0, 9.0));
                h.reverse();
                h
            }],
        );
        let mut g = ClassGrid::new(64, 50, bounds, 0);
        g.fill(&poly, 7);
        let mut inside = 0;
        for r in 0..50 {
            for c in 0..64 {
                let p = g.centre(c, r);
                let want = poly.locate(p) == PointLocation::Inside;
                let got = g.get(c, r) == Some(7);
                if poly.locate(p) != PointLocation::OnBoundary {
                    assert_eq!(want, got, "pixel {c},{r} at {p}");
                }
                inside += usize::from(got);
            }
        }
        // Area check: painted pixels ≈ polygon area.
        let px = 100.0 * 100.0 / (64.0 * 50.0);
        assert!((inside as f64 * px - poly.area()).abs() < 0.1 * poly.area());
        // Outside the grid, nothing.
        assert_eq!(g.get(64, 0), None);
    }
}
