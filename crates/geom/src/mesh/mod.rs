//! Triangle meshes: the geometry that generators (buildings, roads, facades) hand to the
//! exporters (glTF, OBJ).
//!
//! A [`Mesh`] is one glTF *primitive*: `f32` positions, normals and texture coordinates, `u32`
//! triangle indices and one material. It is plain data with public fields, so anyone can
//! build one by hand; [`Mesh::validate`] checks it and [`Mesh::check_closed`] checks that it
//! bounds a solid; [`edge_use()`] reports everything that keeps a surface (one mesh or
//! several) from being a closed, 2-manifold, outward solid.
//!
//! ## Axes and units
//!
//! glTF's convention: metres, **Y up**, right-handed. A point `(x, y)` of the 2-D layout at
//! elevation `h` is the 3-D point `(x, h, −y)`: see [`to_world`], the one place this
//! mapping is written. It is a proper rotation, so a ring that runs counter-clockwise seen
//! from above in the layout runs counter-clockwise seen from above (+Y) in 3-D.
//!
//! ## Winding, normals, texture coordinates
//!
//! * Front faces are counter-clockwise seen from the side their normal points to (glTF);
//!   solids have outward normals and positive [`signed_volume`](Mesh::signed_volume).
//! * Texture coordinates are **in metres**, so a texture that covers the unit square covers
//!   1 m × 1 m and tiles at true scale. glTF's `v` runs *down* the image, so builders set
//!   `v = −(distance upwards)`: an image appears upright on walls and roofs. On a face with
//!   unit normal `n` the `u` axis is the horizontal tangent `t = normalize(Y × n)` (along a
//!   wall, in the direction its ring runs) and `v = −p · (n × t)`; on a horizontal face
//!   `t = X`, so an upward face has `(u, v) = (x, −y)` in layout coordinates. Prism walls use
//!   the length along their ring for `u`, so textures run on round corners unbroken.
//!
//! ## Builders
//!
//! * [`triangulate`]: constrained Delaunay triangulation of a [`PolygonWithHoles`];
//!   [`triangulate_refined`] adds vertices for small, well-shaped triangles.
//! * [`Mesh::add_flat_polygon`], [`Mesh::add_lifted_polygon`], [`Mesh::add_prism`] (and the
//!   one-call [`flat_polygon`], [`prism`]): road surfaces, roofs, building blocks.
//! * [`Mesh::add_draped_polygon`]: a refined, smooth-shaded surface following an elevation
//!   function (roads and blocks on terrain).
//! * [`Mesh::add_walls`] and [`Mesh::add_planar_polygon`] in a [`PlaneFrame`]: open wall
//!   tubes, gable ends, facades with window openings, any planar face.
//! * [`Mesh::add_vertex`], [`Mesh::add_triangle`], [`Mesh::add_quad`]: anything else;
//!   [`Mesh::from_triangles`], [`Mesh::compute_smooth_normals`], [`Mesh::split_flat`] for
//!   geometry from other tools.
//!
//! Builders that fail leave the mesh as it was.
//!
//! ## Limitations
//!
//! * `f32` has 24 bits of mantissa: at 100 km from the origin positions are quantised to
//!   about 8 mm and metre-based texture coordinates to the same step. Build meshes around a
//!   local origin (e.g. the block or building centre, see [`Polygon::translated`]) and put
//!   the offset in the scene node's translation.
//! * [`Mesh::check_closed`] checks edges, not vertices: two solids touching at a single
//!   vertex pass.
//!
//! [`Polygon::translated`]: crate::Polygon::translated
//! [`PolygonWithHoles`]: crate::PolygonWithHoles

use glam::{DMat3, DMat4, DVec2, DVec3, Vec2, Vec3, Vec3A};

use crate::GeomError;
use crate::scene::MaterialId;

mod drape;
pub mod edge_use;
mod extrude;
mod normals;
mod planar;
mod small_cdt;
mod survey;
mod terrain;
mod tiles;
mod triangulate;

pub use edge_use::{EdgeUseReport, ReportedEdge, edge_use};
pub use extrude::{Facing, flat_polygon, prism};
pub use planar::{FRAME_TOLERANCE, PlaneFrame};
pub use survey::MeshSurvey;
pub use terrain::{Terrain, TerrainOptions, TerrainReport};
pub use tiles::{TileIndex, tile_of, triangles_by_tile};
pub use triangulate::{RefineOptions, RefinedTriangulation, triangulate, triangulate_refined};

/// Maps a layout point `p = (x, y)` at elevation `h` to 3-D world coordinates `(x, h, −y)`.
///
/// The layout is the XY plane of every 2-D stage (roads, cells, lots), in metres; the world
/// is glTF's frame (Y up, right-handed, metres). The map is a rotation (determinant +1):
/// lengths, angles and handedness are kept, and a counter-clockwise layout ring is
/// counter-clockwise seen from above. This is the only place in polis that spells it out:
/// use this function (and [`to_layout`]) rather than rewriting it.
///
/// ```
/// use polis_geom::{DVec2, DVec3, mesh::to_world};
/// assert_eq!(to_world(DVec2::new(3.0, 4.0), 10.0), DVec3::new(3.0, 10.0, -4.0));
/// ```
#[inline]
pub fn to_world(p: DVec2, h: f64) -> DVec3 {
    DVec3::new(p.x, h, -p.y)
}

/// The inverse of [`to_world`]: a world point as its layout point and elevation.
#[inline]
pub fn to_layout(w: DVec3) -> (DVec2, f64) {
    (DVec2::new(w.x, -w.z), w.y)
}

/// Below this length of `Y × n`, a face with unit normal `n` counts as horizontal for
/// texture coordinates, and its `u` axis is world X.
pub const HORIZONTAL_FACE_TOLERANCE: f64 = 1e-9;

/// How far from 1 the length of a normal may be before [`Mesh::validate`] rejects it.
pub const NORMAL_LENGTH_TOLERANCE: f32 = 1e-3;

/// An axis-aligned box in 3-D world space (`f32`, metres).
///
/// The empty box has `min = +∞`, `max = −∞`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Aabb3 {
    /// The corner with the smallest coordinates.
    pub min: Vec3,
    /// The corner with the largest coordinates.
    pub max: Vec3,
}

impl Default for Aabb3 {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb3 {
    /// The box that contains nothing.
    pub const EMPTY: Aabb3 = Aabb3 {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// Whether the box contains no point.
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// Grows the box to contain `p`.
    pub fn extend(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The smallest box containing both.
    pub fn union(&self, other: &Aabb3) -> Aabb3 {
        Aabb3 {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Whether `p` lies in the closed box.
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// Whether `other` lies inside this box (an empty `other` lies inside any box).
    pub fn contains_box(&self, other: &Aabb3) -> bool {
        other.is_empty() || (self.contains(other.min) && self.contains(other.max))
    }

    /// The size along each axis (zero for an empty box).
    pub fn size(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }
}

/// The matrix that turns normals under the affine transform `m` (the inverse transpose
/// of its linear part) and whether `m` mirrors (a negative determinant); an error if `m`
/// is not finite, not affine or singular.
fn normal_matrix(m: &DMat4) -> Result<(DMat3, bool), GeomError> {
    let bad = |reason: &str| GeomError::InvalidParameter {
        name: "m",
        reason: reason.to_string(),
    };
    if !m.is_finite() {
        return Err(bad("the matrix has a non-finite entry"));
    }
    if m.row(3) != glam::DVec4::new(0.0, 0.0, 0.0, 1.0) {
        return Err(bad(
            "the matrix is projective; its last row must be (0, 0, 0, 1)",
        ));
    }
    let linear = DMat3::from_mat4(*m);
    let det = linear.determinant();
    if det == 0.0 || !det.is_finite() {
        return Err(bad("the matrix is singular"));
    }
    Ok((linear.inverse().transpose(), det < 0.0))
}

/// A triangle mesh with one material: one glTF primitive.
///
/// Invariants (checked by [`validate`](Self::validate), kept by every builder method):
/// `normals` and `uvs` have one entry per position; `indices` lists whole triangles of
/// existing vertices, counter-clockwise seen from the front; every value is finite; normals
/// have unit length; no triangle has zero area.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Mesh {
    /// Vertex positions in metres (world axes, see [`to_world`]).
    pub positions: Vec<Vec3>,
    /// Unit vertex normals.
    pub normals: Vec<Vec3>,
    /// Texture coordinates in metres (see the [module docs](self)).
    pub uvs: Vec<Vec2>,
    /// Vertex indices, three per triangle.
    pub indices: Vec<u32>,
    /// The material, an index into [`Scene::materials`](crate::scene::Scene::materials);
    /// `None` for the exporter's default material.
    pub material: Option<MaterialId>,
}

impl Mesh {
    /// An empty mesh with the given material.
    pub fn new(material: Option<MaterialId>) -> Self {
        Mesh {
            material,
            ..Mesh::default()
        }
    }

    /// An empty mesh with room for `vertices` vertices and `triangles` triangles.
    pub fn with_capacity(material: Option<MaterialId>, vertices: usize, triangles: usize) -> Self {
        Mesh {
            positions: Vec::with_capacity(vertices),
            normals: Vec::with_capacity(vertices),
            uvs: Vec::with_capacity(vertices),
            indices: Vec::with_capacity(3 * triangles),
            material,
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Whether the mesh has no triangles.
    pub fn is_empty(&self) -> bool {
        self.indices.len() < 3
    }

    /// The triangles as index triples.
    pub fn triangles(&self) -> impl ExactSizeIterator<Item = [u32; 3]> + '_ {
        self.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]])
    }

    /// Makes room for `vertices` more vertices and `triangles` more triangles (as
    /// `Vec::reserve`: an empty mesh gets exactly that, a growing one keeps doubling), so a
    /// mesh built in known steps is allocated once.
    pub fn reserve(&mut self, vertices: usize, triangles: usize) {
        self.positions.reserve(vertices);
        self.normals.reserve(vertices);
        self.uvs.reserve(vertices);
        self.indices.reserve(3 * triangles);
    }

    /// Appends one vertex and returns its index.
    ///
    /// The values are taken as given (rounded to `f32`); [`validate`](Self::validate)
    /// checks them.
    pub fn add_vertex(&mut self, position: DVec3, normal: DVec3, uv: DVec2) -> u32 {
        let index = self.positions.len() as u32;
        self.positions.push(position.as_vec3());
        self.normals.push(normal.as_vec3());
        self.uvs.push(uv.as_vec2());
        index
    }

    /// Appends the triangle with corners at existing vertices `a`, `b`, `c`
    /// (counter-clockwise seen from the front).
    ///
    /// Fails, leaving the mesh unchanged, if an index does not name a vertex.
    pub fn push_triangle(&mut self, a: u32, b: u32, c: u32) -> Result<(), GeomError> {
        let n = self.positions.len();
        for index in [a, b, c] {
            if index as usize >= n {
                return Err(GeomError::MeshIndexOutOfRange {
                    triangle: self.triangle_count(),
                    index,
                    vertex_count: n,
                });
            }
        }
        self.indices.extend_from_slice(&[a, b, c]);
        Ok(())
    }

    /// Appends a flat-shaded triangle with its own three vertices: corners `p`
    /// counter-clockwise seen from the front, texture coordinates `uv` (metres).
    ///
    /// The normal is the triangle's. Fails, leaving the mesh unchanged, if a value is not
    /// finite or the triangle has zero area (before or after rounding to `f32`).
    pub fn add_triangle(&mut self, p: [DVec3; 3], uv: [DVec2; 3]) -> Result<(), GeomError> {
        let normal = (p[1] - p[0]).cross(p[2] - p[0]);
        self.add_flat_face(&p, &uv, normal, &[[0, 1, 2]])
    }

    /// Appends a flat-shaded quadrilateral `p` (counter-clockwise seen from the front) as
    /// two triangles `(0, 1, 2)` and `(0, 2, 3)`, with texture coordinates `uv` (metres).
    ///
    /// The normal is the quad's area normal (Newell's method), so a slightly non-planar
    /// quad gets the average orientation. A half of zero area (two coincident corners) is
    /// left out, so a quad collapsed to a triangle stays a valid triangle. Fails, leaving
    /// the mesh unchanged, if a value is not finite or the whole quad has zero area.
    pub fn add_quad(&mut self, p: [DVec3; 4], uv: [DVec2; 4]) -> Result<(), GeomError> {
        let normal = (p[1] - p[0]).cross(p[2] - p[0]) + (p[2] - p[0]).cross(p[3] - p[0]);
        // The non-degenerate halves, without allocating.
        let mut halves = [[0, 1, 2], [0, 2, 3]];
        let mut n = 0;
        for k in 0..2 {
            let t = halves[k];
            if !triangle_is_degenerate(p[t[0]].as_vec3(), p[t[1]].as_vec3(), p[t[2]].as_vec3()) {
                halves[n] = t;
                n += 1;
            }
        }
        self.add_flat_face(&p, &uv, normal, &halves[..n])
    }

    /// Shared body of [`add_triangle`](Self::add_triangle) and [`add_quad`](Self::add_quad).
    fn add_flat_face(
        &mut self,
        p: &[DVec3],
        uv: &[DVec2],
        normal: DVec3,
        triangles: &[[usize; 3]],
    ) -> Result<(), GeomError> {
        let base = self.positions.len();
        let first_triangle = self.triangle_count();
        for (i, (&q, &t)) in p.iter().zip(uv).enumerate() {
            if !q.is_finite() {
                return Err(invalid_vertex("position", base + i, "not finite"));
            }
            if !t.is_finite() {
                return Err(invalid_vertex("uv", base + i, "not finite"));
            }
        }
        let n = normal.normalize_or_zero();
        if triangles.is_empty() || n == DVec3::ZERO || !n.is_finite() {
            return Err(GeomError::DegenerateTriangle {
                triangle: first_triangle,
            });
        }
        for (j, t) in triangles.iter().enumerate() {
            if triangle_is_degenerate(p[t[0]].as_vec3(), p[t[1]].as_vec3(), p[t[2]].as_vec3()) {
                return Err(GeomError::DegenerateTriangle {
                    triangle: first_triangle + j,
                });
            }
        }
        let base = base as u32;
        for (&q, &t) in p.iter().zip(uv) {
            self.add_vertex(q, n, t);
        }
        for t in triangles {
            self.indices.extend(t.iter().map(|&k| base + k as u32));
        }
        Ok(())
    }

    /// Appends the geometry of `other` (its material is ignored: batch only meshes that
    /// share a material).
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.uvs.extend_from_slice(&other.uvs);
        self.indices.extend(other.indices.iter().map(|&i| base + i));
    }

    /// One mesh holding the geometry of all `meshes`, with the given material.
    pub fn merged<'a>(
        material: Option<MaterialId>,
        meshes: impl IntoIterator<Item = &'a Mesh>,
    ) -> Mesh {
        let mut out = Mesh::new(material);
        for m in meshes {
            out.append(m);
        }
        out
    }

    /// Applies the affine transform `m` to positions, and its inverse transpose to normals
    /// (renormalised). A mirroring transform (negative determinant) also reverses every
    /// triangle so front faces stay counter-clockwise. Texture coordinates are unchanged.
    ///
    /// Fails, leaving the mesh unchanged, if `m` is not finite, not affine or singular.
    pub fn transform(&mut self, m: &DMat4) -> Result<(), GeomError> {
        let (normal_matrix, mirror) = normal_matrix(m)?;
        for p in &mut self.positions {
            *p = m.transform_point3(p.as_dvec3()).as_vec3();
        }
        for n in &mut self.normals {
            *n = (normal_matrix * n.as_dvec3()).normalize_or_zero().as_vec3();
        }
        if mirror {
            for t in self.indices.chunks_exact_mut(3) {
                t.swap(1, 2);
            }
        }
        Ok(())
    }

    /// Appends the geometry of `other` transformed by `m`: the bytes of appending a copy
    /// of `other` on which [`transform`](Self::transform) ran, without the copy (its
    /// material is ignored, as by [`append`](Self::append)).
    ///
    /// Fails, leaving the mesh unchanged, if `m` is not finite, not affine or singular.
    pub fn append_transformed(&mut self, other: &Mesh, m: &DMat4) -> Result<(), GeomError> {
        let (normal_matrix, mirror) = normal_matrix(m)?;
        let base = self.positions.len() as u32;
        self.positions.extend(
            other
                .positions
                .iter()
                .map(|p| m.transform_point3(p.as_dvec3()).as_vec3()),
        );
        self.normals.extend(
            other
                .normals
                .iter()
                .map(|n| (normal_matrix * n.as_dvec3()).normalize_or_zero().as_vec3()),
        );
        self.uvs.extend_from_slice(&other.uvs);
        if mirror {
            self.indices.extend(
                other
                    .indices
                    .chunks_exact(3)
                    .flat_map(|t| [base + t[0], base + t[2], base + t[1]]),
            );
        } else {
            self.indices.extend(other.indices.iter().map(|&i| base + i));
        }
        Ok(())
    }

    /// Reverses every triangle and normal: the back becomes the front.
    pub fn flip(&mut self) {
        for t in self.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        for n in &mut self.normals {
            *n = -*n;
        }
    }

    /// The bounding box of the positions (empty for no vertices).
    ///
    /// The same box, to the bit, as extending [`Aabb3::EMPTY`] by every position in
    /// order (glam's `min`/`max`, `if a < b { a } else { b }` per coordinate), on the
    /// four lanes of a `Vec3A` at once.
    pub fn bbox(&self) -> Aabb3 {
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for &p in &self.positions {
            let p = Vec3A::from(p);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        Aabb3 {
            min: lo.into(),
            max: hi.into(),
        }
    }

    /// Signed volume in m³ enclosed by the triangles (divergence theorem), computed in
    /// `f64` relative to the first vertex. Positive for a closed mesh with outward normals;
    /// meaningless for an open one. Out-of-range indices are skipped.
    pub fn signed_volume(&self) -> f64 {
        let Some(o) = self.positions.first().map(|p| p.as_dvec3()) else {
            return 0.0;
        };
        let mut six = 0.0;
        for [a, b, c] in self.triangles() {
            let (Some(a), Some(b), Some(c)) = (
                self.positions.get(a as usize),
                self.positions.get(b as usize),
                self.positions.get(c as usize),
            ) else {
                continue;
            };
            let (a, b, c) = (a.as_dvec3() - o, b.as_dvec3() - o, c.as_dvec3() - o);
            six += a.dot(b.cross(c));
        }
        six / 6.0
    }

    /// Total triangle area in m² (`f64`). Out-of-range indices are skipped.
    pub fn surface_area(&self) -> f64 {
        let mut twice = 0.0;
        for [a, b, c] in self.triangles() {
            let (Some(a), Some(b), Some(c)) = (
                self.positions.get(a as usize),
                self.positions.get(b as usize),
                self.positions.get(c as usize),
            ) else {
                continue;
            };
            let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
            twice += (b - a).cross(c - a).length();
        }
        twice * 0.5
    }

    /// Checks the invariants: attribute lengths, whole triangles, indices in range, finite
    /// values, unit normals (within [`NORMAL_LENGTH_TOLERANCE`]), no zero-area triangle.
    ///
    /// The first problem found is reported, scanning vertices then triangles in order.
    pub fn validate(&self) -> Result<(), GeomError> {
        self.check::<false>().map(|_| ())
    }

    /// Checks that the mesh is a closed, consistently oriented surface: after welding
    /// vertices at identical positions, every undirected edge is used by exactly two
    /// triangles, once in each direction.
    ///
    /// Assumes [`validate`](Self::validate) passed (out-of-range indices are reported as
    /// such). Deterministic: the reported edge is the first in position order.
    pub fn check_closed(&self) -> Result<(), GeomError> {
        let n = self.positions.len();
        // Weld: canonical id = first vertex (in sorted order) at the same position.
        let key = |i: u32| {
            let p = self.positions[i as usize] + Vec3::ZERO; // -0.0 becomes +0.0
            p.to_array()
        };
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by(|&a, &b| {
            let (ka, kb) = (key(a), key(b));
            ka[0]
                .total_cmp(&kb[0])
                .then(ka[1].total_cmp(&kb[1]))
                .then(ka[2].total_cmp(&kb[2]))
        });
        let mut canon = vec![0u32; n];
        let mut rank = 0u32;
        for (k, &v) in order.iter().enumerate() {
            if k > 0 && key(order[k - 1]) != key(v) {
                rank += 1;
            }
            canon[v as usize] = rank;
        }
        // (low, high, runs low → high)
        let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(self.indices.len());
        for (t, tri) in self.triangles().enumerate() {
            triangle_in_range(t, tri, n)?;
            let c = tri.map(|i| canon[i as usize]);
            if c[0] == c[1] || c[1] == c[2] || c[2] == c[0] {
                return Err(GeomError::DegenerateTriangle { triangle: t });
            }
            for k in 0..3 {
                let (a, b) = (c[k], c[(k + 1) % 3]);
                edges.push((a.min(b), a.max(b), a < b));
            }
        }
        edges.sort_unstable();
        // A representative vertex per canonical id, to report positions.
        let mut rep = vec![0u32; rank as usize + 1];
        for &v in order.iter().rev() {
            rep[canon[v as usize] as usize] = v;
        }
        let pos = |c: u32| self.positions[rep[c as usize] as usize];
        let mut k = 0;
        while k < edges.len() {
            let (a, b, _) = edges[k];
            let mut end = k;
            while end < edges.len() && edges[end].0 == a && edges[end].1 == b {
                end += 1;
            }
            let uses = end - k;
            if uses != 2 {
                return Err(GeomError::OpenEdge {
                    a: pos(a),
                    b: pos(b),
                    uses,
                });
            }
            if edges[k].2 == edges[k + 1].2 {
                return Err(GeomError::InconsistentWinding {
                    a: pos(a),
                    b: pos(b),
                });
            }
            k = end;
        }
        Ok(())
    }

    /// Whether [`check_closed`](Self::check_closed) passes.
    pub fn is_closed(&self) -> bool {
        self.check_closed().is_ok()
    }
}

/// Whether the triangle with these `f32` corners has zero area: the cross product of two
/// edges, computed in `f64` (where differences of `f32` values are exact), is zero.
fn triangle_is_degenerate(a: Vec3, b: Vec3, c: Vec3) -> bool {
    let (a, b, c) = (a.as_dvec3(), b.as_dvec3(), c.as_dvec3());
    (b - a).cross(c - a) == DVec3::ZERO
}

/// Triangle `t`'s indices `tri` all below the vertex count `n`, or the first that is not.
fn triangle_in_range(t: usize, tri: [u32; 3], n: usize) -> Result<(), GeomError> {
    match tri.into_iter().find(|&i| i as usize >= n) {
        Some(index) => Err(GeomError::MeshIndexOutOfRange {
            triangle: t,
            index,
            vertex_count: n,
        }),
        None => Ok(()),
    }
}

fn invalid_vertex(attribute: &'static str, vertex: usize, reason: &'static str) -> GeomError {
    GeomError::MeshInvalidVertex {
        attribute,
        vertex,
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The box of four lanes at once is the box of `Aabb3::extend` in order, to the
    /// bit, with NaN, −0 and +0 among the coordinates.
    #[test]
    fn bbox_is_extending_by_every_position_in_order() {
        let values = [
            0.0f32,
            -0.0,
            1.5,
            -2.25,
            f32::NAN,
            3.0e7,
            -1.0e-30,
            f32::INFINITY,
        ];
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            values[(state % values.len() as u64) as usize]
        };
        for n in 0..200 {
            let mut m = Mesh::new(None);
            m.positions = (0..n % 23)
                .map(|_| Vec3::new(next(), next(), next()))
                .collect();
            let mut expected = Aabb3::EMPTY;
            for &p in &m.positions {
                expected.extend(p);
            }
            let got = m.bbox();
            let bits = |b: Aabb3| {
                (
                    b.min.to_array().map(f32::to_bits),
                    b.max.to_array().map(f32::to_bits),
                )
            };
            assert_eq!(bits(got), bits(expected), "{:?}", m.positions);
        }
    }

    fn unit_cube() -> Mesh {
        // Six flat quads, outward, counter-clockwise from outside.
        let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let uv = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
        let mut m = Mesh::new(None);
        let faces = [
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)], // +z
            [c(1., 0., 0.), c(0., 0., 0.), c(0., 1., 0.), c(1., 1., 0.)], // -z
            [c(1., 0., 1.), c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.)], // +x
            [c(0., 0., 0.), c(0., 0., 1.), c(0., 1., 1.), c(0., 1., 0.)], // -x
            [c(0., 1., 1.), c(1., 1., 1.), c(1., 1., 0.), c(0., 1., 0.)], // +y
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)], // -y
        ];
        for f in faces {
            m.add_quad(f, uv).unwrap();
        }
        m
    }

    #[test]
    fn world_mapping_is_a_rotation() {
        let x = to_world(DVec2::X, 0.0);
        let y = to_world(DVec2::Y, 0.0);
        let up = to_world(DVec2::ZERO, 1.0);
        assert_eq!(x, DVec3::X);
        assert_eq!(up, DVec3::Y);
        assert_eq!(y, -DVec3::Z);
        // Right-handed: layout x × layout y = up.
        assert_eq!(x.cross(y), up);
        let p = DVec2::new(3.5, -7.25);
        assert_eq!(to_layout(to_world(p, 2.0)), (p, 2.0));
    }

    #[test]
    fn cube_is_closed_with_unit_volume() {
        let m = unit_cube();
        m.validate().unwrap();
        assert_eq!(m.triangle_count(), 12);
        m.check_closed().unwrap();
        assert!((m.signed_volume() - 1.0).abs() < 1e-12);
        assert!((m.surface_area() - 6.0).abs() < 1e-12);
        let b = m.bbox();
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::ONE));
        // Normals point outward: from the centre to the face.
        for (p, n) in m.positions.iter().zip(&m.normals) {
            let face_centre_dir = *n;
            assert!((*p - Vec3::splat(0.5)).dot(face_centre_dir) > 0.0);
        }
    }

    #[test]
    fn closedness_errors() {
        let mut open = unit_cube();
        open.indices.truncate(30);
        assert!(matches!(
            open.check_closed(),
            Err(GeomError::OpenEdge { uses: 1, .. })
        ));
        let mut flipped_one = unit_cube();
        flipped_one.indices.swap(1, 2);
        flipped_one.indices.swap(4, 5);
        assert!(matches!(
            flipped_one.check_closed(),
            Err(GeomError::InconsistentWinding { .. })
        ));
        let mut doubled = unit_cube();
        doubled.append(&unit_cube());
        assert!(matches!(
            doubled.check_closed(),
            Err(GeomError::OpenEdge { uses: 4, .. })
        ));
    }

    #[test]
    fn validation_errors() {
        let mut m = unit_cube();
        m.normals.pop();
        assert!(matches!(
            m.validate(),
            Err(GeomError::MeshAttributeLength {
                attribute: "normals",
                ..
            })
        ));
        let mut m = unit_cube();
        m.indices.push(0);
        assert!(matches!(
            m.validate(),
            Err(GeomError::MeshIndexCount { len: 37 })
        ));
        let mut m = unit_cube();
        m.indices[5] = 99;
        assert!(matches!(
            m.validate(),
            Err(GeomError::MeshIndexOutOfRange {
                triangle: 1,
                index: 99,
                ..
            })
        ));
        assert!(m.check_closed().is_err());
        let mut m = unit_cube();
        m.positions[3].y = f32::NAN;
        assert!(matches!(
            m.validate(),
            Err(GeomError::MeshInvalidVertex {
                attribute: "position",
                vertex: 3,
                ..
            })
        ));
        let mut m = unit_cube();
        m.normals[2] = Vec3::new(0.0, 2.0, 0.0);
        assert!(matches!(
            m.validate(),
            Err(GeomError::MeshInvalidVertex {
                attribute: "normal",
                vertex: 2,
                ..
            })
        ));
        let mut m = unit_cube();
        m.uvs[0].x = f32::INFINITY;
        assert!(matches!(
            m.validate(),
            Err(GeomError::MeshInvalidVertex {
                attribute: "uv",
                ..
            })
        ));
        let mut m = unit_cube();
        m.indices[7] = m.indices[6];
        assert!(matches!(
            m.validate(),
            Err(GeomError::DegenerateTriangle { triangle: 2 })
        ));
    }

    #[test]
    fn builders_reject_bad_faces_and_leave_mesh_unchanged() {
        let mut m = unit_cube();
        let before = m.clone();
        let z = DVec2::ZERO;
        let p = DVec3::new(1.0, 2.0, 3.0);
        assert!(m.add_triangle([p, p, DVec3::ZERO], [z; 3]).is_err());
        assert!(
            m.add_triangle([DVec3::ZERO, DVec3::X, DVec3::NAN], [z; 3])
                .is_err()
        );
        assert!(
            m.add_quad(
                [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X, 3.0 * DVec3::X],
                [z; 4]
            )
            .is_err()
        );
        assert!(m.push_triangle(0, 1, 1000).is_err());
        assert_eq!(m, before);
        // A quad collapsed to a triangle keeps its good half.
        m.add_quad([DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Y], [z; 4])
            .unwrap();
        assert_eq!(m.triangle_count(), before.triangle_count() + 1);
        m.validate().unwrap();
        let t = m.triangle_count();
        m.push_triangle(0, 1, 2).unwrap();
        assert_eq!(m.triangle_count(), t + 1);
    }

    #[test]
    fn transform_keeps_orientation_and_volume_sign() {
        let mut m = unit_cube();
        m.transform(&DMat4::from_scale_rotation_translation(
            DVec3::new(2.0, 3.0, 4.0),
            glam::DQuat::from_rotation_y(0.7),
            DVec3::new(10.0, 0.0, -5.0),
        ))
        .unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        assert!((m.signed_volume() - 24.0).abs() < 1e-4);
        // Mirror: still outward.
        let mut mirrored = unit_cube();
        mirrored
            .transform(&DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)))
            .unwrap();
        mirrored.check_closed().unwrap();
        assert!((mirrored.signed_volume() - 1.0).abs() < 1e-9);
        for (p, n) in mirrored.positions.iter().zip(&mirrored.normals) {
            assert!((*p - Vec3::new(-0.5, 0.5, 0.5)).dot(*n) > 0.0);
        }
        let mut m = unit_cube();
        assert!(m.transform(&DMat4::from_scale(DVec3::ZERO)).is_err());
        assert!(m.transform(&DMat4::from_scale(DVec3::NAN)).is_err());
        assert!(
            m.append_transformed(&unit_cube(), &DMat4::from_scale(DVec3::ZERO))
                .is_err()
        );
        assert_eq!(m, unit_cube());
        m.flip();
        assert!((m.signed_volume() + 1.0).abs() < 1e-9);
    }

    proptest::proptest! {
        #[test]
        fn transforms_keep_closed_solids(
            scale in (0.1f64..10.0, 0.1f64..10.0, 0.1f64..10.0),
            mirror in proptest::prelude::any::<bool>(),
            angle in -3.2f64..3.2,
            axis in (-1.0f64..1.0, 0.1f64..1.0, -1.0f64..1.0),
            shift in (-1e3f64..1e3, -1e3f64..1e3, -1e3f64..1e3),
        ) {
            let s = DVec3::new(if mirror { -scale.0 } else { scale.0 }, scale.1, scale.2);
            let m = DMat4::from_scale_rotation_translation(
                s,
                glam::DQuat::from_axis_angle(DVec3::new(axis.0, axis.1, axis.2).normalize(), angle),
                DVec3::new(shift.0, shift.1, shift.2),
            );
            let mut cube = unit_cube();
            cube.transform(&m).unwrap();
            // Appending transformed gives the bytes of appending the transformed copy.
            let mut appended = unit_cube();
            appended.append_transformed(&unit_cube(), &m).unwrap();
            let mut expected_append = unit_cube();
            expected_append.append(&cube);
            proptest::prop_assert_eq!(&appended, &expected_append);
            cube.validate().unwrap();
            cube.check_closed().unwrap();
            let expected = (s.x * s.y * s.z).abs();
            // f32 positions: each coordinate is off by up to half an ulp of the largest.
            let reach = f64::from(cube.bbox().min.abs().max(cube.bbox().max.abs()).max_element());
            let tolerance = 4.0 * cube.surface_area() * reach * f64::from(f32::EPSILON) + 1e-9;
            proptest::prop_assert!((cube.signed_volume() - expected).abs() < tolerance);
            // Normals still point away from the centre.
            let centre = m.transform_point3(DVec3::splat(0.5)).as_vec3();
            for tri in cube.triangles() {
                let [a, b, c] = tri.map(|i| cube.positions[i as usize]);
                let mid = (a + b + c) / 3.0;
                proptest::prop_assert!((mid - centre).dot(cube.normals[tri[0] as usize]) > 0.0);
            }
        }
    }

    #[test]
    fn boxes() {
        let m = unit_cube();
        let b = m.bbox();
        assert!(b.contains_box(&b));
        assert!(b.contains_box(&Aabb3::EMPTY));
        assert!(!Aabb3::EMPTY.contains_box(&b));
        let mut big = b;
        big.extend(Vec3::splat(2.0));
        assert!(big.contains_box(&b) && !b.contains_box(&big));
        assert_eq!(big.size(), Vec3::splat(2.0));
        assert_eq!(Aabb3::EMPTY.size(), Vec3::ZERO);
        assert_eq!(b.union(&Aabb3::EMPTY), b);
    }

    #[test]
    fn merge_offsets_indices() {
        let a = unit_cube();
        let mut b = unit_cube();
        b.transform(&DMat4::from_translation(DVec3::new(5.0, 0.0, 0.0)))
            .unwrap();
        let m = Mesh::merged(None, [&a, &b]);
        m.validate().unwrap();
        m.check_closed().unwrap();
        assert_eq!(m.triangle_count(), 24);
        assert!((m.signed_volume() - 2.0).abs() < 1e-9);
        assert_eq!(m.bbox().max, Vec3::new(6.0, 1.0, 1.0));
    }
}
