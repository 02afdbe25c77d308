//! Per-vertex tangents for normal-mapped primitives (glTF `TANGENT`, `VEC4`).
//!
//! glTF requires a tangent space for normal textures and lets viewers generate one when
//! `TANGENT` is missing, which the Khronos validator flags as non-portable; so the writer
//! supplies tangents for every geometry whose material has a normal texture.
//!
//! Method (Lengyel 2001): per triangle, the directions in which `u` and image-up (`−v`:
//! glTF's `v` runs down the image) increase, accumulated on its corners; per vertex the
//! tangent is the accumulated `u` direction made orthogonal to the normal (Gram–Schmidt)
//! and normalised, and `w = ±1` says whether `normal × tangent` points image-up. Where the
//! texture mapping is degenerate (no triangle with non-zero UV area touches the vertex),
//! any unit vector orthogonal to the normal is used.

use polis_geom::Mesh;
use polis_geom::glam::{Vec2, Vec3, Vec4};

/// Below this |UV-area · 2|, a triangle's texture mapping is degenerate.
const UV_AREA_TOLERANCE: f32 = 1e-12;

/// Below this squared length, an accumulated tangent counts as zero.
const TANGENT_TOLERANCE: f32 = 1e-12;

/// One unit tangent with handedness per vertex of `m` (whose normals are unit length).
#[cfg_attr(not(feature = "web"), allow(dead_code))]
pub(crate) fn tangents(m: &Mesh) -> Vec<Vec4> {
    tangents_of(&m.positions, &m.normals, &m.uvs, &m.indices)
}

/// [`tangents`] of the mesh with these arrays (three indices per triangle).
pub(crate) fn tangents_of(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    indices: &[u32],
) -> Vec<Vec4> {
    let n = positions.len();
    let mut tan = vec![Vec3::ZERO; n];
    let mut bit = vec![Vec3::ZERO; n];
    for tri in indices.chunks_exact(3) {
        let (a, b, c) = (tri[0] as usize, tri[1] as usize, tri[2] as usize);
        let (Some(&pa), Some(&pb), Some(&pc)) =
            (positions.get(a), positions.get(b), positions.get(c))
        else {
            continue;
        };
        let (Some(&ta), Some(&tb), Some(&tc)) = (uvs.get(a), uvs.get(b), uvs.get(c)) else {
            continue;
        };
        let (e1, e2) = (pb - pa, pc - pa);
        // Image-up coordinates: (u, −v).
        let (d1x, d1y) = (tb.x - ta.x, ta.y - tb.y);
        let (d2x, d2y) = (tc.x - ta.x, ta.y - tc.y);
        let r = d1x * d2y - d2x * d1y;
        if r.abs() <= UV_AREA_TOLERANCE || !r.is_finite() {
            continue;
        }
        let t = (e1 * d2y - e2 * d1y) / r;
        let s = (e2 * d1x - e1 * d2x) / r;
        if !(t.is_finite() && s.is_finite()) {
            continue;
        }
        for k in [a, b, c] {
            tan[k] += t;
            bit[k] += s;
        }
    }
    (0..n)
        .map(|i| {
            let normal = normals
                .get(i)
                .copied()
                .unwrap_or(Vec3::Y)
                .normalize_or(Vec3::Y);
            let mut t = tan[i] - normal * normal.dot(tan[i]);
            if t.length_squared() <= TANGENT_TOLERANCE || !t.is_finite() {
                t = normal.any_orthonormal_vector();
            }
            let t = t.normalize_or(normal.any_orthonormal_vector());
            let w = if normal.cross(t).dot(bit[i]) < 0.0 {
                -1.0
            } else {
                1.0
            };
            t.extend(w)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::glam::{DVec2, DVec3};

    #[test]
    fn upward_face_has_tangent_x_and_bitangent_north() {
        // An upward face with (u, v) = (x, −y_layout) = (x, z): u along +X, image-up = −v
        // = layout north = world −Z.
        let mut m = Mesh::new(None);
        m.add_quad(
            [
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, -1.0),
                DVec3::new(0.0, 0.0, -1.0),
            ],
            [
                DVec2::new(0.0, 0.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(1.0, -1.0),
                DVec2::new(0.0, -1.0),
            ],
        )
        .unwrap();
        for t in tangents(&m) {
            assert!((t.truncate() - Vec3::X).length() < 1e-6, "{t}");
            // normal × tangent = Y × X = −Z = north: w = +1.
            assert_eq!(t.w, 1.0);
        }
    }

    #[test]
    fn mirrored_uvs_flip_handedness_and_degenerate_uvs_fall_back() {
        let mut m = Mesh::new(None);
        m.add_triangle(
            [DVec3::ZERO, DVec3::X, DVec3::new(0.0, 0.0, -1.0)],
            [DVec2::ZERO, DVec2::X, DVec2::new(0.0, 1.0)],
        )
        .unwrap();
        let t = tangents(&m);
        assert_eq!(t[0].w, -1.0);
        let mut d = Mesh::new(None);
        d.add_triangle([DVec3::ZERO, DVec3::X, DVec3::Z], [DVec2::ZERO; 3])
            .unwrap();
        for t in tangents(&d) {
            let n = d.normals[0];
            assert!((t.truncate().length() - 1.0).abs() < 1e-6);
            assert!(t.truncate().dot(n).abs() < 1e-6);
        }
    }
}
