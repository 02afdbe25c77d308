//! Planar faces in any orientation: a 2-D polygon drawn in a plane of the world.

use glam::{DVec2, DVec3};

use super::{Mesh, to_world, triangulate};
use crate::{GeomError, MAX_COORDINATE, PolygonWithHoles};

/// How far from orthonormal the axes of a [`PlaneFrame`] may be (in length and dot
/// product) before [`Mesh::add_planar_polygon`] rejects them.
pub const FRAME_TOLERANCE: f64 = 1e-9;

/// An orthonormal frame of a plane in world space: 2-D coordinates `(x, y)` in the plane
/// are the world point `origin + x·u + y·v`. The front of the plane is on the side of
/// `u × v`, so counter-clockwise polygons in `(x, y)` face the front.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PlaneFrame {
    /// The world point at `(0, 0)`, metres.
    pub origin: DVec3,
    /// The unit world direction of the plane's `x` axis.
    pub u: DVec3,
    /// The unit world direction of the plane's `y` axis, perpendicular to `u`.
    pub v: DVec3,
}

impl PlaneFrame {
    /// The vertical wall standing on the layout edge `a → b` at elevation `base`: `x`
    /// runs from `a` towards `b` (metres along the edge), `y` upwards (metres above
    /// `base`). Its front faces the right of the edge, which is the outside of a
    /// counter-clockwise outer ring or a clockwise hole, the same side as the walls of
    /// [`Mesh::add_walls`]. Use it for gable ends and for facades with window openings.
    ///
    /// Fails if `a == b` or a value is not finite.
    pub fn wall(a: DVec2, b: DVec2, base: f64) -> Result<PlaneFrame, GeomError> {
        let d = b - a;
        let len = d.length();
        if !(len > 0.0 && len.is_finite() && base.is_finite()) {
            return Err(GeomError::InvalidParameter {
                name: "a, b",
                reason: format!("the wall from {a} to {b} at {base} m has no finite direction"),
            });
        }
        Ok(PlaneFrame {
            origin: to_world(a, base),
            u: to_world(d / len, 0.0),
            v: DVec3::Y,
        })
    }

    /// The horizontal plane at elevation `h` with layout coordinates: `(x, y)` is the
    /// layout point `(x, y)`; the front faces up.
    pub fn horizontal(h: f64) -> PlaneFrame {
        PlaneFrame {
            origin: to_world(DVec2::ZERO, h),
            u: to_world(DVec2::X, 0.0),
            v: to_world(DVec2::Y, 0.0),
        }
    }

    /// The world point at plane coordinates `p`.
    #[inline]
    pub fn point(&self, p: DVec2) -> DVec3 {
        self.origin + p.x * self.u + p.y * self.v
    }

    /// The unit normal of the front side, `u × v`.
    #[inline]
    pub fn normal(&self) -> DVec3 {
        self.u.cross(self.v)
    }

    fn check(&self) -> Result<(), GeomError> {
        let bad = |reason: &str| GeomError::InvalidParameter {
            name: "frame",
            reason: reason.to_string(),
        };
        if !(self.origin.is_finite() && self.u.is_finite() && self.v.is_finite()) {
            return Err(bad("a value is not finite"));
        }
        if self.origin.abs().max_element() > MAX_COORDINATE {
            return Err(bad("the origin lies outside the coordinate range"));
        }
        if (self.u.length() - 1.0).abs() > FRAME_TOLERANCE
            || (self.v.length() - 1.0).abs() > FRAME_TOLERANCE
            || self.u.dot(self.v).abs() > FRAME_TOLERANCE
        {
            return Err(bad("u and v must be perpendicular unit vectors"));
        }
        Ok(())
    }
}

impl Mesh {
    /// Appends a polygon with holes drawn in the plane `frame` as one flat-shaded face with
    /// normal `u × v`: a gable wall, a facade with window openings, a sloped roof plane.
    ///
    /// Triangulated with [`triangulate`] in plane coordinates (any ring orientation; the
    /// triangles face the front). Texture coordinates are in metres:
    /// `(x + uv_offset.x, −(y + uv_offset.y))`, so with a [`PlaneFrame::wall`] frame and
    /// `uv_offset = (distance along the ring, base elevation)` they continue those of
    /// [`Mesh::add_walls`].
    ///
    /// Fails, leaving the mesh unchanged, on an invalid polygon, a frame that is not
    /// orthonormal, or triangles that collapse when rounded to `f32`.
    pub fn add_planar_polygon(
        &mut self,
        frame: &PlaneFrame,
        polygon: &PolygonWithHoles,
        uv_offset: DVec2,
    ) -> Result<(), GeomError> {
        frame.check()?;
        if !uv_offset.is_finite() {
            return Err(GeomError::InvalidParameter {
                name: "uv_offset",
                reason: "must be finite".to_string(),
            });
        }
        let triangles = triangulate(polygon)?;
        let normal = frame.normal();
        let mark = self.mark();
        let first_triangle = self.triangle_count();
        let base = self.positions.len() as u32;
        for (_, ring) in polygon.rings() {
            for &p in ring.points() {
                let t = p + uv_offset;
                self.add_vertex(frame.point(p), normal, DVec2::new(t.x, -t.y));
            }
        }
        for t in &triangles {
            self.indices.extend(t.iter().map(|&i| base + i));
        }
        self.keep_if_sound(mark, first_triangle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Polygon;
    use crate::mesh::Facing;
    use glam::Vec3;

    #[test]
    fn wall_frame_matches_prism_walls() {
        let fp = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 6.0));
        let mut walls = Mesh::new(None);
        walls.add_walls(&fp.clone().into(), 0.0, 3.0).unwrap();
        // The first wall of add_walls against the same face built by hand.
        let frame = PlaneFrame::wall(DVec2::ZERO, DVec2::new(10.0, 0.0), 0.0).unwrap();
        assert_eq!(frame.normal(), DVec3::Z);
        let mut hand = Mesh::new(None);
        let quad = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 3.0));
        hand.add_planar_polygon(&frame, &quad.into(), DVec2::ZERO)
            .unwrap();
        hand.validate().unwrap();
        assert_eq!(hand.normals[0], walls.normals[0]);
        for k in 0..4 {
            let i = hand
                .positions
                .iter()
                .position(|&p| p == walls.positions[k])
                .unwrap();
            assert_eq!(hand.uvs[i], walls.uvs[k]);
        }
    }

    #[test]
    fn gable_house_is_closed() {
        // A 10 × 6 m house, eaves at 3 m, ridge along x at 5 m: walls, two gable
        // pentagons, two roof planes, a floor.
        let (w, d, eave, ridge) = (10.0, 6.0, 3.0, 5.0);
        let v = DVec2::new;
        let mut m = Mesh::new(None);
        // Long walls (south: y = 0, north: y = d) as quads.
        for (a, b, along) in [(v(0., 0.), v(w, 0.), 0.0), (v(w, d), v(0., d), w + d)] {
            let f = PlaneFrame::wall(a, b, 0.0).unwrap();
            m.add_planar_polygon(
                &f,
                &Polygon::rect(v(0., 0.), v(w, eave)).into(),
                v(along, 0.0),
            )
            .unwrap();
        }
        // Gable ends (east: x = w, west: x = 0) as pentagons.
        let gable: PolygonWithHoles = Polygon::new(vec![
            v(0., 0.),
            v(d, 0.),
            v(d, eave),
            v(d / 2., ridge),
            v(0., eave),
        ])
        .into();
        for (a, b, along) in [(v(w, 0.), v(w, d), w), (v(0., d), v(0., 0.), 2. * w + d)] {
            let f = PlaneFrame::wall(a, b, 0.0).unwrap();
            m.add_planar_polygon(&f, &gable, v(along, 0.0)).unwrap();
        }
        // Roof planes as lifted polygons.
        let south = Polygon::rect(v(0., 0.), v(w, d / 2.));
        m.add_lifted_polygon(&south.into(), &[eave, eave, ridge, ridge], Facing::Up)
            .unwrap();
        let north = Polygon::rect(v(0., d / 2.), v(w, d));
        m.add_lifted_polygon(&north.into(), &[ridge, ridge, eave, eave], Facing::Up)
            .unwrap();
        m.add_flat_polygon(&Polygon::rect(v(0., 0.), v(w, d)).into(), 0.0, Facing::Down)
            .unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        let volume = w * d * eave + 0.5 * d * (ridge - eave) * w;
        assert!((m.signed_volume() - volume).abs() < 1e-9);
        // The pentagon's apex sits on the ridge.
        assert!(
            m.positions
                .contains(&Vec3::new(w as f32, ridge as f32, -(d / 2.) as f32))
        );
    }

    #[test]
    fn facade_with_window_hole() {
        let f = PlaneFrame::wall(DVec2::ZERO, DVec2::new(8.0, 0.0), 0.0).unwrap();
        let wall = Polygon::rect(DVec2::ZERO, DVec2::new(8.0, 3.0));
        let window = Polygon::rect(DVec2::new(3.0, 1.0), DVec2::new(5.0, 2.2));
        let mut m = Mesh::new(None);
        m.add_planar_polygon(&f, &PolygonWithHoles::new(wall, vec![window]), DVec2::ZERO)
            .unwrap();
        m.validate().unwrap();
        assert!((m.surface_area() - (24.0 - 2.4)).abs() < 1e-5);
        assert!(m.normals.iter().all(|&n| n == Vec3::Z));
    }

    #[test]
    fn bad_frames_are_rejected() {
        let sq: PolygonWithHoles = Polygon::rect(DVec2::ZERO, DVec2::ONE).into();
        let mut m = Mesh::new(None);
        assert!(PlaneFrame::wall(DVec2::ONE, DVec2::ONE, 0.0).is_err());
        assert!(PlaneFrame::wall(DVec2::ZERO, DVec2::ONE, f64::NAN).is_err());
        let skew = PlaneFrame {
            origin: DVec3::ZERO,
            u: DVec3::X,
            v: DVec3::new(1.0, 1.0, 0.0).normalize(),
        };
        assert!(m.add_planar_polygon(&skew, &sq, DVec2::ZERO).is_err());
        let h = PlaneFrame::horizontal(2.0);
        assert!(m.add_planar_polygon(&h, &sq, DVec2::NAN).is_err());
        assert!(m.is_empty());
        m.add_planar_polygon(&h, &sq, DVec2::ZERO).unwrap();
        assert!(m.normals.iter().all(|&n| n == Vec3::Y));
    }
}
