//! Closed slabs draped on an elevation field: block plinths and kerbs that follow the
//! ground instead of standing level above its lowest point.

use glam::DVec2;

use super::extrude::check_height;
use super::{Mesh, RefineOptions, to_world, triangulate_refined};
use crate::{GeomError, PolygonWithHoles};

impl Mesh {
    /// Appends a closed slab draped on the elevation function `height`: the polygon
    /// (holes allowed) triangulated with [`triangulate_refined`], a top cap at
    /// `height(p) + top` facing up, a bottom cap at `height(p) + bottom` facing down
    /// (`bottom < top`, metres relative to the ground), and vertical walls along every
    /// boundary edge of the refined triangulation (boundary points added by refinement
    /// included, so walls and caps share every edge).
    ///
    /// # Guarantees
    /// A closed, consistently wound, outward solid (edge-use check) whenever the heights
    /// are finite; at every vertex the top lies exactly `top` above the ground and the
    /// bottom `bottom` below it (up to `f32` rounding). Between vertices the caps are
    /// planar triangles of at most `options.max_area` m², so their distance to a smooth
    /// ground deviates by at most `h²·κ/8` for triangle size `h` and ground curvature `κ`.
    ///
    /// Fails, leaving the mesh unchanged, on an invalid polygon or options, heights that
    /// are not finite or in range, or `bottom ≥ top`.
    pub fn add_draped_slab(
        &mut self,
        polygon: &PolygonWithHoles,
        options: &RefineOptions,
        height: impl Fn(DVec2) -> f64,
        bottom: f64,
        top: f64,
    ) -> Result<(), GeomError> {
        if !(bottom.is_finite() && top.is_finite() && bottom < top) {
            return Err(GeomError::InvalidParameter {
                name: "bottom",
                reason: format!("{bottom} must be finite and below top {top}"),
            });
        }
        let refined = triangulate_refined(polygon, options)?;
        let mut ground = Vec::with_capacity(refined.points.len());
        for &p in &refined.points {
            let g = height(p);
            check_height("height", g + top)?;
            check_height("height", g + bottom)?;
            ground.push(g);
        }
        let at = |i: u32, offset: f64| {
            let k = i as usize;
            to_world(refined.points[k], ground[k] + offset)
        };
        let mark = self.mark();
        let first_triangle = self.triangle_count();
        // Caps: flat-shaded triangles with their own vertices (the ground bends between
        // them), texture coordinates on the map as for flat caps.
        for t in &refined.triangles {
            for (offset, up) in [(top, true), (bottom, false)] {
                let [a, b, c] = t.map(|i| at(i, offset));
                let [pa, pb, pc] = t.map(|i| refined.points[i as usize]);
                let (p, uv) = if up {
                    ([a, b, c], [pa, pb, pc].map(|q| DVec2::new(q.x, -q.y)))
                } else {
                    ([a, c, b], [pa, pc, pb])
                };
                if let Err(e) = self.add_triangle(p, uv) {
                    self.rollback(mark);
                    return Err(e);
                }
            }
        }
        // Walls along the boundary edges (used by one triangle), in the triangles'
        // direction: region on the left, so the wall faces out.
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(3 * refined.triangles.len());
        for t in &refined.triangles {
            for k in 0..3 {
                edges.push((t[k], t[(k + 1) % 3]));
            }
        }
        let mut undirected: Vec<(u32, u32)> =
            edges.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
        undirected.sort_unstable();
        let once = |a: u32, b: u32| {
            let key = (a.min(b), a.max(b));
            let i = undirected.partition_point(|e| *e < key);
            undirected.get(i + 1) != Some(&key)
        };
        for &(a, b) in &edges {
            if !once(a, b) {
                continue;
            }
            let (pa, pb) = (refined.points[a as usize], refined.points[b as usize]);
            let len = pa.distance(pb);
            let quad = [at(a, bottom), at(b, bottom), at(b, top), at(a, top)];
            let uv = [
                DVec2::new(0.0, -quad[0].y),
                DVec2::new(len, -quad[1].y),
                DVec2::new(len, -quad[2].y),
                DVec2::new(0.0, -quad[3].y),
            ];
            if let Err(e) = self.add_quad(quad, uv) {
                self.rollback(mark);
                return Err(e);
            }
        }
        self.keep_if_sound(mark, first_triangle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Polygon;

    #[test]
    fn a_slab_on_a_slope_is_closed_and_follows_the_ground() {
        let block = PolygonWithHoles::new(
            Polygon::rect(DVec2::ZERO, DVec2::new(60.0, 40.0)),
            vec![Polygon::rect(
                DVec2::new(20.0, 10.0),
                DVec2::new(40.0, 30.0),
            )],
        );
        let ground = |p: DVec2| 0.1 * p.x + 0.02 * p.y * p.y / 40.0;
        let options = RefineOptions {
            max_area: 50.0,
            ..RefineOptions::default()
        };
        let mut m = Mesh::new(None);
        m.add_draped_slab(&block, &options, ground, -0.5, 0.15)
            .unwrap();
        m.validate().unwrap();
        let r = m.edge_use();
        assert!(r.is_solid(), "{r:?}");
        // Volume: area × thickness on a ruled surface pair (the caps are the same
        // triangulation shifted vertically).
        let area = block.area();
        assert!((r.signed_volume - area * 0.65).abs() < 1e-3 * area);
        // Every vertex lies on its ground plus the top or minus the bottom.
        for p in &m.positions {
            let (q, h) = crate::to_layout(p.as_dvec3());
            let above = h - ground(q);
            assert!(
                (above - 0.15).abs() < 1e-4 || (above + 0.5).abs() < 1e-4,
                "{above}"
            );
        }
        let before = m.clone();
        assert!(
            m.add_draped_slab(&block, &options, ground, 0.2, 0.1)
                .is_err()
        );
        assert!(
            m.add_draped_slab(&block, &options, |_| f64::NAN, -1.0, 0.1)
                .is_err()
        );
        assert_eq!(m, before);
    }
}
