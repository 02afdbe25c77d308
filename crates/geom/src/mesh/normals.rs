//! Recomputing normals, for meshes built by hand or read from files without them.

use glam::{DVec3, Vec2, Vec3};

use super::{Mesh, triangle_in_range};
use crate::GeomError;

impl Mesh {
    /// Sets every vertex normal to the area-weighted average of the normals of the
    /// triangles that use the vertex (smooth shading across shared vertices; vertices that
    /// are duplicated per face stay flat). A vertex used by no triangle, or whose
    /// triangles cancel, gets +Y.
    ///
    /// Fails, leaving the mesh unchanged, if an index is out of range.
    pub fn compute_smooth_normals(&mut self) -> Result<(), GeomError> {
        self.check_indices()?;
        let mut acc = vec![DVec3::ZERO; self.positions.len()];
        for tri in self.triangles() {
            let [a, b, c] = tri.map(|i| self.positions[i as usize].as_dvec3());
            let n = (b - a).cross(c - a);
            for i in tri {
                acc[i as usize] += n;
            }
        }
        self.normals = acc
            .into_iter()
            .map(|n| n.normalize_or(DVec3::Y).as_vec3())
            .collect();
        Ok(())
    }

    /// Gives every triangle its own three vertices with the triangle's normal (flat
    /// shading). Texture coordinates are copied (zero where the mesh has none). A
    /// zero-area triangle gets +Y (and still fails [`validate`](Self::validate)).
    ///
    /// Fails, leaving the mesh unchanged, if an index is out of range.
    pub fn split_flat(&mut self) -> Result<(), GeomError> {
        self.check_indices()?;
        let count = self.indices.len();
        let mut positions = Vec::with_capacity(count);
        let mut normals = Vec::with_capacity(count);
        let mut uvs = Vec::with_capacity(count);
        for tri in self.triangles() {
            let [a, b, c] = tri.map(|i| self.positions[i as usize].as_dvec3());
            let n = (b - a).cross(c - a).normalize_or(DVec3::Y).as_vec3();
            for i in tri {
                positions.push(self.positions[i as usize]);
                normals.push(n);
                uvs.push(self.uvs.get(i as usize).copied().unwrap_or(Vec2::ZERO));
            }
        }
        self.positions = positions;
        self.normals = normals;
        self.uvs = uvs;
        self.indices = (0..count as u32).collect();
        Ok(())
    }

    /// A mesh from bare positions and triangle indices (counter-clockwise fronts), with
    /// smooth normals ([`compute_smooth_normals`](Self::compute_smooth_normals)) and zero
    /// texture coordinates: for geometry from other tools, e.g. OBJ templates.
    pub fn from_triangles(positions: Vec<Vec3>, indices: Vec<u32>) -> Result<Mesh, GeomError> {
        let n = positions.len();
        let mut m = Mesh {
            positions,
            normals: vec![Vec3::Y; n],
            uvs: vec![Vec2::ZERO; n],
            indices,
            material: None,
        };
        if !m.indices.len().is_multiple_of(3) {
            return Err(GeomError::MeshIndexCount {
                len: m.indices.len(),
            });
        }
        m.compute_smooth_normals()?;
        Ok(m)
    }

    fn check_indices(&self) -> Result<(), GeomError> {
        let n = self.positions.len();
        for (t, tri) in self.triangles().enumerate() {
            triangle_in_range(t, tri, n)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A regular tetrahedron with shared vertices, counter-clockwise from outside.
    fn tetrahedron() -> Mesh {
        let p = vec![
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(-1.0, -1.0, 1.0),
        ];
        Mesh::from_triangles(p, vec![0, 1, 2, 0, 3, 1, 0, 2, 3, 1, 3, 2]).unwrap()
    }

    #[test]
    fn smooth_normals_point_away_from_the_centre() {
        let m = tetrahedron();
        m.validate().unwrap();
        m.check_closed().unwrap();
        assert!((m.signed_volume() - 8.0 / 3.0).abs() < 1e-6);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            // By symmetry the smooth normal of each corner is its direction from the centre.
            assert!((p.normalize() - *n).length() < 1e-6);
        }
    }

    #[test]
    fn flat_split_keeps_the_solid() {
        let mut m = tetrahedron();
        m.split_flat().unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        assert_eq!(m.vertex_count(), 12);
        assert!((m.signed_volume() - 8.0 / 3.0).abs() < 1e-6);
        for tri in m.triangles() {
            let [a, b, c] = tri.map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a).normalize();
            for i in tri {
                assert!((m.normals[i as usize] - face).length() < 1e-6);
            }
        }
    }

    #[test]
    fn bad_indices_are_errors() {
        assert!(Mesh::from_triangles(vec![Vec3::ZERO; 3], vec![0, 1, 5]).is_err());
        assert!(Mesh::from_triangles(vec![Vec3::ZERO; 3], vec![0, 1]).is_err());
        let mut m = tetrahedron();
        m.indices[4] = 40;
        let before = m.clone();
        assert!(m.split_flat().is_err());
        assert!(m.compute_smooth_normals().is_err());
        assert_eq!(m, before);
    }
}
