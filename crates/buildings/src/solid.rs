//! Closed solids from planar faces: the mesh-building primitives every shape module uses.
//!
//! Every face is a planar polygon given by its exact world corners; faces of one solid
//! share corners bit for bit, so [`Mesh::check_closed`] welds them. Texture coordinates
//! follow `polis_geom::mesh`'s convention (metres, `u` along the horizontal tangent,
//! `v = −` distance upwards).

use polis_geom::mesh::to_world;
use polis_geom::{
    DVec2, DVec3, GeomError, Mesh, Orientation, Polygon, PolygonWithHoles, orient2d, triangulate,
};

/// Appends the planar polygon `pts` (counter-clockwise seen from its front) as one
/// flat-shaded face. Convex faces are fanned; others go through the constrained Delaunay
/// triangulation. Leaves the mesh unchanged on failure.
pub(crate) fn add_face(mesh: &mut Mesh, pts: &[DVec3]) -> Result<(), GeomError> {
    let n = pts.len();
    if n < 3 {
        return Err(GeomError::DegenerateTriangle {
            triangle: mesh.triangle_count(),
        });
    }
    // Newell normal.
    let mut nrm = DVec3::ZERO;
    for i in 0..n {
        let (a, b) = (pts[i], pts[(i + 1) % n]);
        nrm += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let nrm = nrm.normalize_or_zero();
    if nrm == DVec3::ZERO || !nrm.is_finite() {
        return Err(GeomError::DegenerateTriangle {
            triangle: mesh.triangle_count(),
        });
    }
    let t = DVec3::Y.cross(nrm);
    let t = if t.length() < 1e-9 {
        DVec3::X
    } else {
        t.normalize()
    };
    let b = nrm.cross(t);
    let plane: Vec<DVec2> = pts.iter().map(|p| DVec2::new(p.dot(t), p.dot(b))).collect();
    let convex = (0..n).all(|i| {
        orient2d(plane[i], plane[(i + 1) % n], plane[(i + 2) % n]) == Orientation::CounterClockwise
    });
    let base = mesh.positions.len() as u32;
    let first = mesh.indices.len();
    let tris: Vec<[u32; 3]> = if convex {
        (1..n as u32 - 1).map(|i| [0, i, i + 1]).collect()
    } else {
        let poly = PolygonWithHoles::from(Polygon::new(plane.clone()));
        if poly.outer.len() != n || !poly.outer.is_ccw() {
            return Err(GeomError::DegenerateTriangle {
                triangle: mesh.triangle_count(),
            });
        }
        triangulate(&poly)?
    };
    for tri in &tris {
        let [p, q, r] = tri.map(|i| pts[i as usize].as_vec3().as_dvec3());
        if (q - p).cross(r - p) == DVec3::ZERO {
            mesh.indices.truncate(first);
            return Err(GeomError::DegenerateTriangle {
                triangle: first / 3,
            });
        }
        mesh.indices.extend(tri.iter().map(|&i| base + i));
    }
    for (p, uv) in pts.iter().zip(&plane) {
        mesh.add_vertex(*p, nrm, DVec2::new(uv.x, -uv.y));
    }
    Ok(())
}

/// A closed prism over the counter-clockwise ring `ring` from elevation `z0` to `z1`:
/// walls, a top cap facing up and a bottom cap facing down.
///
/// Walls are written directly (one quad each, `u` along the ring as in
/// `Mesh::add_walls`); convex caps are fanned, others triangulated.
pub(crate) fn prism(ring: &[DVec2], z0: f64, z1: f64) -> Result<Mesh, GeomError> {
    let n = ring.len();
    if n < 3 || z1.partial_cmp(&z0) != Some(std::cmp::Ordering::Greater) {
        return Err(GeomError::DegenerateTriangle { triangle: 0 });
    }
    let mut m = Mesh::with_capacity(None, 6 * n, 4 * n);
    let mut along = 0.0;
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let len = a.distance(b);
        if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || a.as_vec2() == b.as_vec2()
        {
            return Err(GeomError::DegenerateTriangle {
                triangle: m.triangle_count(),
            });
        }
        let d = (b - a) / len;
        let normal = to_world(DVec2::new(d.y, -d.x), 0.0);
        let base = m.positions.len() as u32;
        for (p, h, u) in [
            (a, z0, along),
            (b, z0, along + len),
            (b, z1, along + len),
            (a, z1, along),
        ] {
            m.add_vertex(to_world(p, h), normal, DVec2::new(u, -h));
        }
        m.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
        along += len;
    }
    let convex = (0..n).all(|i| {
        orient2d(ring[i], ring[(i + 1) % n], ring[(i + 2) % n]) == Orientation::CounterClockwise
    });
    if convex {
        for (h, up) in [(z1, true), (z0, false)] {
            let (normal, sign) = if up {
                (DVec3::Y, -1.0)
            } else {
                (-DVec3::Y, 1.0)
            };
            let base = m.positions.len() as u32;
            for &p in ring {
                m.add_vertex(to_world(p, h), normal, DVec2::new(p.x, sign * p.y));
            }
            for k in 1..n as u32 - 1 {
                if up {
                    m.indices.extend_from_slice(&[base, base + k, base + k + 1]);
                } else {
                    m.indices.extend_from_slice(&[base, base + k + 1, base + k]);
                }
            }
        }
        // Fans of exactly convex rings can only collapse when rounded to f32.
        if m.triangles().any(|[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|i| m.positions[i as usize].as_dvec3());
            (b - a).cross(c - a) == DVec3::ZERO
        }) {
            return Err(GeomError::DegenerateTriangle { triangle: 0 });
        }
    } else {
        let top: Vec<DVec3> = ring.iter().map(|&p| to_world(p, z1)).collect();
        add_face(&mut m, &top)?;
        let rev: Vec<DVec3> = ring.iter().rev().map(|&p| to_world(p, z0)).collect();
        add_face(&mut m, &rev)?;
    }
    Ok(m)
}

/// A closed pyramid-like solid: the ring at `z0` (bottom cap facing down) joined to the
/// single `apex` by triangles. The ring must be star-shaped from the apex's plan point.
pub(crate) fn cone(ring: &[DVec2], z0: f64, apex: DVec2, z1: f64) -> Result<Mesh, GeomError> {
    let n = ring.len();
    if !(0..n).all(|i| orient2d(ring[i], ring[(i + 1) % n], apex) == Orientation::CounterClockwise)
    {
        return Err(GeomError::InvalidParameter {
            name: "apex",
            reason: "the footprint is not star-shaped from the apex".into(),
        });
    }
    let mut m = Mesh::with_capacity(None, 4 * n, 2 * n);
    let top = to_world(apex, z1);
    let bottom: Vec<DVec3> = ring.iter().map(|&p| to_world(p, z0)).collect();
    for i in 0..n {
        add_face(&mut m, &[bottom[i], bottom[(i + 1) % n], top])?;
    }
    let rev: Vec<DVec3> = bottom.iter().rev().copied().collect();
    add_face(&mut m, &rev)?;
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prism_uvs_are_metres_and_solid_is_closed() {
        let ring = Polygon::rect(DVec2::ZERO, DVec2::new(12.0, 5.0)).into_points();
        let m = prism(&ring, 2.0, 9.0).unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        assert!((m.signed_volume() - 12.0 * 5.0 * 7.0).abs() < 1e-3);
        // The first wall runs 12 m along the ring, from elevation 2 to 9.
        let us: Vec<f32> = m.uvs[..4].iter().map(|uv| uv.x).collect();
        let vs: Vec<f32> = m.uvs[..4].iter().map(|uv| uv.y).collect();
        assert_eq!(us, [0.0, 12.0, 12.0, 0.0]);
        assert_eq!(vs, [-2.0, -2.0, -9.0, -9.0]);
    }

    #[test]
    fn concave_prism_and_faces() {
        let l = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 4.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(4.0, 10.0),
            DVec2::new(0.0, 10.0),
        ];
        let m = prism(&l, 0.0, 3.0).unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        assert!((m.signed_volume() - 64.0 * 3.0).abs() < 1e-3);
        let mut f = Mesh::new(None);
        assert!(
            add_face(&mut f, &[DVec3::ZERO, DVec3::X, DVec3::X * 2.0]).is_err(),
            "collinear"
        );
        assert!(f.is_empty());
        assert!(prism(&l, 3.0, 3.0).is_err());
    }

    #[test]
    fn cone_needs_a_visible_apex() {
        let sq = Polygon::rect(DVec2::ZERO, DVec2::new(4.0, 4.0)).into_points();
        let c = cone(&sq, 0.0, DVec2::new(2.0, 2.0), 3.0).unwrap();
        c.check_closed().unwrap();
        assert!((c.signed_volume() - 16.0).abs() < 1e-4);
        assert!(cone(&sq, 0.0, DVec2::new(9.0, 2.0), 3.0).is_err());
    }
}
