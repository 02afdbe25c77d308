//! Mesh builders from layout polygons: flat and lifted faces, extruded prisms.

use glam::{DVec2, DVec3};

use super::{
    HORIZONTAL_FACE_TOLERANCE, Mesh, RefineOptions, to_world, triangulate, triangulate_refined,
};
use crate::scene::MaterialId;
use crate::{GeomError, MAX_COORDINATE, PolygonWithHoles};

/// Which side of a horizontal face is its front.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Facing {
    /// Seen from above: roofs, road surfaces, top caps.
    #[default]
    Up,
    /// Seen from below: bottom caps, ceilings of passages.
    Down,
}

/// One-call form of [`Mesh::add_flat_polygon`]: a new mesh with the given material.
pub fn flat_polygon(
    polygon: &PolygonWithHoles,
    elevation: f64,
    facing: Facing,
    material: Option<MaterialId>,
) -> Result<Mesh, GeomError> {
    let mut m = Mesh::new(material);
    m.add_flat_polygon(polygon, elevation, facing)?;
    Ok(m)
}

/// One-call form of [`Mesh::add_prism`]: a new closed mesh with the given material.
///
/// ```
/// use polis_geom::{DVec2, Polygon, mesh::prism};
/// let footprint = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 20.0));
/// let block = prism(&footprint.into(), 0.0, 12.0, None)?;
/// block.validate()?;
/// block.check_closed()?;
/// assert!((block.signed_volume() - 2400.0).abs() < 1e-6);
/// # Ok::<(), polis_geom::GeomError>(())
/// ```
pub fn prism(
    polygon: &PolygonWithHoles,
    bottom: f64,
    top: f64,
    material: Option<MaterialId>,
) -> Result<Mesh, GeomError> {
    let mut m = Mesh::new(material);
    m.add_prism(polygon, bottom, top)?;
    Ok(m)
}

impl Mesh {
    /// Appends the polygon as a horizontal face at `elevation` (metres), facing up or down:
    /// a road surface, a flat roof, a cap.
    ///
    /// Triangulated with [`triangulate`]; one vertex per polygon vertex, all with the
    /// normal ±Y; texture coordinates in metres (`(x, −y)` facing up, `(x, y)` facing down,
    /// so the image is not mirrored seen from its front).
    ///
    /// Fails, leaving the mesh unchanged, on an invalid polygon or elevation.
    pub fn add_flat_polygon(
        &mut self,
        polygon: &PolygonWithHoles,
        elevation: f64,
        facing: Facing,
    ) -> Result<(), GeomError> {
        check_height("elevation", elevation)?;
        self.add_polygon_with(polygon, |_, _| elevation, facing)
    }

    /// Appends the polygon lifted to a (planar) face in 3-D: vertex `i` of the polygon
    /// (counted ring by ring, outer ring first, as in [`triangulate`]) is raised to
    /// elevation `heights[i]`. For roof planes, ramps, sloped road surfaces.
    ///
    /// Triangulated in the layout plane, so the face must project one-to-one onto it (any
    /// non-vertical plane does). The face is flat-shaded with its area-weighted normal
    /// (exact for planar faces, the average for others) on the side given by `facing`;
    /// texture coordinates are in metres along the face (see the [module docs](super)), so
    /// a texture tiles at true scale on a slope.
    ///
    /// Fails, leaving the mesh unchanged, on an invalid polygon, a `heights` of the wrong
    /// length, or a non-finite or out-of-range height.
    pub fn add_lifted_polygon(
        &mut self,
        polygon: &PolygonWithHoles,
        heights: &[f64],
        facing: Facing,
    ) -> Result<(), GeomError> {
        let total: usize = polygon.rings().map(|(_, r)| r.len()).sum();
        if heights.len() != total {
            return Err(GeomError::InvalidParameter {
                name: "heights",
                reason: format!(
                    "{} heights for {total} polygon vertices; give one per vertex",
                    heights.len()
                ),
            });
        }
        for &h in heights {
            check_height("heights", h)?;
        }
        self.add_polygon_with(polygon, |i, _| heights[i], facing)
    }

    /// Appends the polygon as a surface draped on the elevation function `height` (metres
    /// above the layout point): a road or a block on terrain.
    ///
    /// The polygon is triangulated with [`triangulate_refined`] (so the surface has
    /// vertices inside to follow the ground, at most `options.max_area` m² per triangle),
    /// every vertex is lifted to `height(p) + offset`, and normals are smooth: the
    /// area-weighted average of the incident triangles' normals, on the side given by
    /// `facing`. Texture coordinates are the layout position (`(x, −y)` facing up), in
    /// metres on the map, so they stretch on steep slopes.
    ///
    /// Fails, leaving the mesh unchanged, on an invalid polygon or options, or a height
    /// that is not finite or out of range.
    pub fn add_draped_polygon(
        &mut self,
        polygon: &PolygonWithHoles,
        options: &RefineOptions,
        height: impl Fn(DVec2) -> f64,
        offset: f64,
        facing: Facing,
    ) -> Result<(), GeomError> {
        let refined = triangulate_refined(polygon, options)?;
        let mut world = Vec::with_capacity(refined.points.len());
        for &p in &refined.points {
            let h = height(p) + offset;
            check_height("height", h)?;
            world.push(to_world(p, h));
        }
        let mut normals = vec![DVec3::ZERO; world.len()];
        for t in &refined.triangles {
            let [a, b, c] = t.map(|i| world[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                normals[i as usize] += n;
            }
        }
        let sign = match facing {
            Facing::Up => 1.0,
            Facing::Down => -1.0,
        };
        let mark = self.mark();
        let first_triangle = self.triangle_count();
        let base = self.positions.len() as u32;
        for ((&w, &n), &p) in world.iter().zip(&normals).zip(&refined.points) {
            let uv = match facing {
                Facing::Up => DVec2::new(p.x, -p.y),
                Facing::Down => p,
            };
            self.add_vertex(w, sign * n.normalize_or(DVec3::Y), uv);
        }
        for t in &refined.triangles {
            let [a, b, c] = t.map(|i| base + i);
            match facing {
                Facing::Up => self.indices.extend_from_slice(&[a, b, c]),
                Facing::Down => self.indices.extend_from_slice(&[a, c, b]),
            }
        }
        self.keep_if_sound(mark, first_triangle)
    }

    /// Appends a closed prism: the polygon extruded from elevation `bottom` to `top`
    /// (metres, `bottom < top`), with walls ([`add_walls`](Self::add_walls)), a bottom cap
    /// facing down and a top cap facing up. Holes become courtyards with inward-facing walls.
    ///
    /// The rings are used counter-clockwise (outer) and clockwise (holes) whatever their
    /// given orientation, so the result always has outward normals and positive volume
    /// equal to area × height.
    ///
    /// # Guarantees
    /// A closed, consistently wound surface ([`Mesh::check_closed`]) with outward normals,
    /// `2·(n + 2h − 2) + 2n` triangles for `n` vertices and `h` holes, and no degenerate
    /// triangle (the result is checked after rounding to `f32`).
    ///
    /// Fails, leaving the mesh unchanged, on an invalid polygon or heights.
    pub fn add_prism(
        &mut self,
        polygon: &PolygonWithHoles,
        bottom: f64,
        top: f64,
    ) -> Result<(), GeomError> {
        let poly = normalized_for_walls(polygon, bottom, top)?;
        let triangles = triangulate(&poly)?;
        // Four vertices and two triangles per wall, one vertex per corner and the cap's
        // triangles on each cap.
        let corners: usize = poly.rings().map(|(_, r)| r.len()).sum();
        self.reserve(6 * corners, 2 * corners + 2 * triangles.len());
        let mark = self.mark();
        let first_triangle = self.triangle_count();
        self.push_walls(&poly, bottom, top);
        self.add_cap(&poly, &triangles, |_, _| top, Facing::Up);
        self.add_cap(&poly, &triangles, |_, _| bottom, Facing::Down);
        self.keep_if_sound(mark, first_triangle)
    }

    /// Appends only the walls of [`add_prism`](Self::add_prism): an open tube to close
    /// with roof faces ([`add_lifted_polygon`](Self::add_lifted_polygon),
    /// [`add_planar_polygon`](Self::add_planar_polygon) on gable ends) and a floor.
    ///
    /// Each wall (ring edge) is one flat-shaded quad with its own four vertices, facing
    /// outward (rings are used counter-clockwise outer, clockwise holes). Texture
    /// coordinates: `u` is the distance along the ring from its first vertex, `v` is
    /// `−elevation`, both in metres, so facade textures tile at true scale, run around
    /// corners and line up between stacked walls.
    ///
    /// Fails, leaving the mesh unchanged, on an invalid polygon or heights.
    pub fn add_walls(
        &mut self,
        polygon: &PolygonWithHoles,
        bottom: f64,
        top: f64,
    ) -> Result<(), GeomError> {
        let poly = normalized_for_walls(polygon, bottom, top)?;
        poly.validate()?;
        let mark = self.mark();
        let first_triangle = self.triangle_count();
        self.push_walls(&poly, bottom, top);
        self.keep_if_sound(mark, first_triangle)
    }

    /// The wall quads of a normalised, valid polygon.
    fn push_walls(&mut self, poly: &PolygonWithHoles, bottom: f64, top: f64) {
        for (_, ring) in poly.rings() {
            let mut along = 0.0;
            for (a, b) in ring.edges() {
                let len = a.distance(b);
                let dir = (b - a) / len;
                // Outward: to the right of the edge (outer ring CCW, holes CW).
                let normal = to_world(DVec2::new(dir.y, -dir.x), 0.0);
                let base = self.positions.len() as u32;
                let corners = [
                    (a, bottom, along),
                    (b, bottom, along + len),
                    (b, top, along + len),
                    (a, top, along),
                ];
                for (p, h, u) in corners {
                    self.add_vertex(to_world(p, h), normal, DVec2::new(u, -h));
                }
                self.indices.extend_from_slice(&[
                    base,
                    base + 1,
                    base + 2,
                    base,
                    base + 2,
                    base + 3,
                ]);
                along += len;
            }
        }
    }

    /// Triangulates `polygon` and appends it as one flat-shaded face, vertex `i` lifted to
    /// `height(i, p)`; rolls back on error.
    fn add_polygon_with(
        &mut self,
        polygon: &PolygonWithHoles,
        height: impl Fn(usize, DVec2) -> f64,
        facing: Facing,
    ) -> Result<(), GeomError> {
        let triangles = triangulate(polygon)?;
        let mark = self.mark();
        let first_triangle = self.triangle_count();
        self.add_cap(polygon, &triangles, height, facing);
        self.keep_if_sound(mark, first_triangle)
    }

    /// Appends the triangulated polygon as one flat-shaded face (vertices lifted by
    /// `height`), front side `facing`.
    fn add_cap(
        &mut self,
        polygon: &PolygonWithHoles,
        triangles: &[[u32; 3]],
        height: impl Fn(usize, DVec2) -> f64,
        facing: Facing,
    ) {
        let world: Vec<DVec3> = polygon
            .rings()
            .flat_map(|(_, r)| r.points().iter().copied())
            .enumerate()
            .map(|(i, p)| to_world(p, height(i, p)))
            .collect();
        // Area-weighted normal of the upward side (triangles are counter-clockwise seen
        // from above), relative to the first vertex to limit cancellation.
        let o = world.first().copied().unwrap_or(DVec3::ZERO);
        let mut up_normal = DVec3::ZERO;
        for t in triangles {
            let [a, b, c] = t.map(|i| world[i as usize] - o);
            up_normal += (b - a).cross(c - a);
        }
        let up_normal = up_normal.normalize_or(DVec3::Y);
        let normal = match facing {
            Facing::Up => up_normal,
            Facing::Down => -up_normal,
        };
        let (t_axis, b_axis) = face_frame(normal);
        let base = self.positions.len() as u32;
        for &p in &world {
            self.add_vertex(p, normal, DVec2::new(p.dot(t_axis), -p.dot(b_axis)));
        }
        for t in triangles {
            let [a, b, c] = t.map(|i| base + i);
            match facing {
                Facing::Up => self.indices.extend_from_slice(&[a, b, c]),
                Facing::Down => self.indices.extend_from_slice(&[a, c, b]),
            }
        }
    }

    /// Checks the triangles from `first` on for zero area after rounding to `f32`.
    pub(super) fn check_new_triangles(&self, first: usize) -> Result<(), GeomError> {
        for (t, tri) in self.triangles().enumerate().skip(first) {
            let [a, b, c] = tri.map(|i| self.positions[i as usize]);
            if super::triangle_is_degenerate(a, b, c) {
                return Err(GeomError::DegenerateTriangle { triangle: t });
            }
        }
        Ok(())
    }

    /// Keeps what was appended since `mark` if no triangle from `first` on is degenerate,
    /// and otherwise rolls the mesh back to `mark` and returns the error.
    pub(super) fn keep_if_sound(
        &mut self,
        mark: (usize, usize),
        first: usize,
    ) -> Result<(), GeomError> {
        let result = self.check_new_triangles(first);
        if result.is_err() {
            self.rollback(mark);
        }
        result
    }

    pub(super) fn mark(&self) -> (usize, usize) {
        (self.positions.len(), self.indices.len())
    }

    pub(super) fn rollback(&mut self, (vertices, indices): (usize, usize)) {
        self.positions.truncate(vertices);
        self.normals.truncate(vertices);
        self.uvs.truncate(vertices);
        self.indices.truncate(indices);
    }
}

/// The texture frame of a face with unit normal `n`: the horizontal tangent `t` (`u` axis)
/// and `b = n × t` (up the face; `v = −p · b`). See the [module docs](super).
fn face_frame(n: DVec3) -> (DVec3, DVec3) {
    let t = DVec3::Y.cross(n);
    let t = if t.length() < HORIZONTAL_FACE_TOLERANCE {
        DVec3::X
    } else {
        t.normalize()
    };
    (t, n.cross(t))
}

/// Checks the heights and returns the polygon with counter-clockwise outer ring and
/// clockwise holes.
fn normalized_for_walls(
    polygon: &PolygonWithHoles,
    bottom: f64,
    top: f64,
) -> Result<PolygonWithHoles, GeomError> {
    check_height("bottom", bottom)?;
    check_height("top", top)?;
    if bottom >= top {
        return Err(GeomError::InvalidParameter {
            name: "top",
            reason: format!("top {top} m is not above bottom {bottom} m"),
        });
    }
    let mut poly = polygon.clone();
    poly.normalize();
    Ok(poly)
}

pub(super) fn check_height(name: &'static str, h: f64) -> Result<(), GeomError> {
    if !h.is_finite() || h.abs() > MAX_COORDINATE {
        return Err(GeomError::InvalidParameter {
            name,
            reason: format!("{h} m is not a finite elevation within ±{MAX_COORDINATE} m"),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::triangulate::tests::{orthogonal, star, vertices};
    use super::*;
    use crate::Polygon;
    use glam::Vec3;
    use proptest::prelude::*;

    fn check_prism(p: &PolygonWithHoles, bottom: f64, top: f64) {
        let m = prism(p, bottom, top, None).unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        let n = vertices(p).len();
        assert_eq!(m.triangle_count(), 2 * (n + 2 * p.holes.len() - 2) + 2 * n);
        let expected = p.area() * (top - bottom);
        let vol = m.signed_volume();
        assert!(
            (vol - expected).abs() <= 1e-4 * expected.max(1.0),
            "volume {vol}, expected {expected}"
        );
        // Every face's normal agrees with its triangle's winding (front = normal side).
        for tri in m.triangles() {
            let [a, b, c] = tri.map(|i| m.positions[i as usize].as_dvec3());
            let face = (b - a).cross(c - a);
            for i in tri {
                assert!(face.dot(m.normals[i as usize].as_dvec3()) > 0.0);
            }
        }
        // Closed + consistently wound + normals on the front side + positive volume: the
        // surface is oriented outward everywhere (the courtyard walls are joined to the
        // rest through the caps, so one orientation covers all).
    }

    #[test]
    fn box_prism() {
        let p: PolygonWithHoles = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 20.0)).into();
        check_prism(&p, 0.0, 12.0);
        let m = prism(&p, 0.0, 12.0, None).unwrap();
        assert_eq!(m.triangle_count(), 12);
        let b = m.bbox();
        assert_eq!(b.min, Vec3::new(0.0, 0.0, -20.0));
        assert_eq!(b.max, Vec3::new(10.0, 12.0, 0.0));
        // First wall: edge (0,0) → (10,0), facing −y in the layout = +Z in the world.
        assert_eq!(m.normals[0], Vec3::Z);
        assert_eq!(
            m.uvs[0..4],
            [
                glam::Vec2::new(0.0, 0.0),
                glam::Vec2::new(10.0, 0.0),
                glam::Vec2::new(10.0, -12.0),
                glam::Vec2::new(0.0, -12.0)
            ]
        );
        // Second wall continues u along the ring.
        assert_eq!(m.uvs[4].x, 10.0);
        // Clockwise input gives the same solid.
        let mut cw = p.clone();
        cw.outer.reverse();
        check_prism(&cw, 0.0, 12.0);
    }

    #[test]
    fn courtyard_prism_and_bad_heights() {
        let mut hole = Polygon::rect(DVec2::splat(3.0), DVec2::splat(7.0));
        hole.reverse();
        let p = PolygonWithHoles::new(Polygon::rect(DVec2::ZERO, DVec2::splat(10.0)), vec![hole]);
        check_prism(&p, 5.0, 8.5);
        let mut m = prism(&p, 0.0, 1.0, None).unwrap();
        let before = m.clone();
        assert!(m.add_prism(&p, 1.0, 1.0).is_err());
        assert!(m.add_prism(&p, 2.0, 1.0).is_err());
        assert!(m.add_prism(&p, f64::NAN, 1.0).is_err());
        assert!(m.add_prism(&p, 0.0, 1e12).is_err());
        // Heights too close for f32 near 1000 m: degenerate walls are an error.
        assert!(m.add_prism(&p, 1000.0, 1000.0 + 1e-9).is_err());
        let bowtie = Polygon::new(vec![DVec2::ZERO, DVec2::ONE, DVec2::X, DVec2::Y]);
        assert!(m.add_prism(&bowtie.into(), 0.0, 1.0).is_err());
        assert_eq!(m, before);
    }

    #[test]
    fn flat_and_lifted_faces() {
        let sq: PolygonWithHoles = Polygon::rect(DVec2::ZERO, DVec2::splat(4.0)).into();
        let up = flat_polygon(&sq, 2.0, Facing::Up, None).unwrap();
        up.validate().unwrap();
        assert!(up.normals.iter().all(|&n| n == Vec3::Y));
        assert!((up.surface_area() - 16.0).abs() < 1e-9);
        // Up-facing uv = (x, −y) of the layout.
        assert_eq!(up.uvs[2], glam::Vec2::new(4.0, -4.0));
        let down = flat_polygon(&sq, 2.0, Facing::Down, None).unwrap();
        assert!(down.normals.iter().all(|&n| n == -Vec3::Y));
        assert_eq!(down.uvs[2], glam::Vec2::new(4.0, 4.0));
        // Up and down faces cancel: zero enclosed volume.
        let sheet = Mesh::merged(None, [&up, &down]);
        assert!(sheet.signed_volume().abs() < 1e-9);

        // A 45° roof plane rising towards +y: area grows by √2 and v runs up the slope.
        let mut roof = Mesh::new(None);
        roof.add_lifted_polygon(&sq, &[0.0, 0.0, 4.0, 4.0], Facing::Up)
            .unwrap();
        roof.validate().unwrap();
        assert!((roof.surface_area() - 16.0 * 2f64.sqrt()).abs() < 1e-5);
        let n = roof.normals[0];
        assert!((n - Vec3::new(0.0, 1.0, 1.0).normalize()).length() < 1e-6);
        // uv distances equal 3-D distances: metres along the slope.
        let d_uv = (roof.uvs[3] - roof.uvs[0]).length();
        let d_xyz = (roof.positions[3] - roof.positions[0]).length();
        assert!((d_uv - d_xyz).abs() < 1e-5);
        // The upper edge has smaller v (upright texture).
        assert!(roof.uvs[3].y < roof.uvs[0].y);
        assert!(roof.add_lifted_polygon(&sq, &[0.0; 3], Facing::Up).is_err());
        assert!(
            roof.add_lifted_polygon(&sq, &[0.0, f64::NAN, 0.0, 0.0], Facing::Up)
                .is_err()
        );
        assert_eq!(roof.triangle_count(), 2);
    }

    #[test]
    fn draped_surface_follows_the_ground() {
        // A road 8 m wide, 100 m long, on a slope of 5 % along x with a bump.
        let road: PolygonWithHoles = Polygon::rect(DVec2::ZERO, DVec2::new(100.0, 8.0)).into();
        let ground = |p: DVec2| 0.05 * p.x + (p.x * 0.1).sin();
        let options = RefineOptions {
            max_area: 4.0,
            ..RefineOptions::default()
        };
        let mut m = Mesh::new(None);
        m.add_draped_polygon(&road, &options, ground, 0.1, Facing::Up)
            .unwrap();
        m.validate().unwrap();
        assert!(m.vertex_count() > 50);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            let (lay, h) = super::super::to_layout(p.as_dvec3());
            assert!((h - ground(lay) - 0.1).abs() < 1e-4);
            assert!(n.y > 0.9, "normal {n} does not face up");
        }
        // Its plan area is the road's.
        let plan: f64 = m
            .triangles()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).y
            })
            .sum();
        assert!((plan - 800.0).abs() < 1e-2, "plan area {plan}");
        let before = m.clone();
        assert!(
            m.add_draped_polygon(&road, &options, |_| f64::NAN, 0.0, Facing::Up)
                .is_err()
        );
        assert_eq!(m, before);
        let mut under = Mesh::new(None);
        under
            .add_draped_polygon(&road, &options, ground, 0.0, Facing::Down)
            .unwrap();
        assert!(under.normals.iter().all(|n| n.y < -0.9));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn star_prisms_are_closed(
            spec in prop::collection::vec((prop_oneof![Just(5.0), Just(9.0), 5.0f64..9.0], 0.0f64..1.0), 3..40),
            snap in prop_oneof![Just(None), Just(Some(0.5))],
            with_hole in any::<bool>(),
            bottom in prop_oneof![Just(0.0), -50.0f64..50.0],
            height in prop_oneof![Just(3.0), 0.5f64..200.0],
        ) {
            let (radii, jitter): (Vec<f64>, Vec<f64>) = spec.into_iter().unzip();
            let outer = star(&radii, &jitter, snap);
            let holes = if with_hole && radii.len() >= 8 {
                vec![Polygon::rect(DVec2::splat(-2.0), DVec2::splat(2.0))]
            } else {
                vec![]
            };
            let p = PolygonWithHoles::new(outer, holes);
            if p.validate().is_ok() {
                check_prism(&p, bottom, bottom + height);
            } else {
                prop_assert!(prism(&p, bottom, bottom + height, None).is_err());
            }
        }

        #[test]
        fn orthogonal_prisms_are_closed(
            cols in prop::collection::vec((-4i32..=-1, 1i32..=4), 1..30),
            scale in prop_oneof![Just(1.0), 0.5f64..20.0],
            offset in (-1e3f64..1e3, -1e3f64..1e3),
            with_hole in any::<bool>(),
            height in 0.5f64..100.0,
        ) {
            let (bottom, top): (Vec<i32>, Vec<i32>) = cols.into_iter().unzip();
            let offset = DVec2::new(offset.0, offset.1);
            let outer = orthogonal(&bottom, &top, scale, offset);
            let holes = if with_hole {
                let h = Polygon::rect(DVec2::new(0.25, -0.5), DVec2::new(0.75, 0.5));
                vec![h.map_points(|q| q * scale + offset)]
            } else {
                vec![]
            };
            let p = PolygonWithHoles::new(outer, holes);
            check_prism(&p, 0.0, height);
        }
    }
}
