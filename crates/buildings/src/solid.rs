//! Closed solids from planar faces: the mesh-building primitives every shape module uses.
//!
//! Every face is a planar polygon given by its exact world corners; faces of one solid
//! share corners bit for bit, so [`Mesh::check_closed`] welds them. Texture coordinates
//! follow `polis_geom::mesh`'s convention (metres, `u` along the horizontal tangent,
//! `v = −` distance upwards).

use polis_geom::glam::Vec3;
use polis_geom::mesh::to_world;
use polis_geom::{
    DVec2, DVec3, GeomError, Mesh, Orientation, Polygon, PolygonWithHoles, orient2d, triangulate,
};

/// `Mesh::add_vertex` without its index, inlined into the hot loops (f32 at the end).
#[inline]
fn push_vertex(mesh: &mut Mesh, position: DVec3, normal: DVec3, uv: DVec2) {
    mesh.positions.push(position.as_vec3());
    mesh.normals.push(normal.as_vec3());
    mesh.uvs.push(uv.as_vec2());
}

/// Appends the planar polygon `pts` (counter-clockwise seen from its front) as one
/// flat-shaded face. Convex faces are fanned; others are ear-clipped (or, when that gets
/// stuck, go through the constrained Delaunay triangulation). Leaves the mesh unchanged
/// on failure.
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
    // Triangulation decides on an exact projection (dropping the normal's dominant axis,
    // no arithmetic), so points collinear in space stay collinear: a rotated basis would
    // round them apart and let a zero-area ear through. It projects the points as the
    // mesh stores them (rounded to `f32`), so a vertex that rounding makes straight is
    // seen straight and never becomes the tip of a zero-area triangle.
    let k = if nrm.x.abs() >= nrm.y.abs() && nrm.x.abs() >= nrm.z.abs() {
        0
    } else if nrm.y.abs() >= nrm.z.abs() {
        1
    } else {
        2
    };
    let flip = nrm[k] < 0.0;
    with_work(|w| {
        let TriWork {
            exact,
            tris,
            left,
            poly,
        } = w;
        exact.clear();
        exact.extend(pts.iter().map(|p| {
            let p = p.as_vec3().as_dvec3();
            let (a, b) = (p[(k + 1) % 3], p[(k + 2) % 3]);
            if flip {
                DVec2::new(b, a)
            } else {
                DVec2::new(a, b)
            }
        }));
        let convex = (0..n).all(|i| {
            orient2d(exact[i], exact[(i + 1) % n], exact[(i + 2) % n])
                == Orientation::CounterClockwise
        });
        let base = mesh.positions.len() as u32;
        let first = mesh.indices.len();
        tris.clear();
        if convex {
            tris.extend((1..n as u32 - 1).map(|i| [0, i, i + 1]));
        } else {
            triangulate_into(exact, false, left, poly, tris).ok_or(
                GeomError::DegenerateTriangle {
                    triangle: mesh.triangle_count(),
                },
            )??;
        }
        for tri in tris.iter() {
            let [p, q, r] = tri.map(|i| pts[i as usize].as_vec3().as_dvec3());
            if (q - p).cross(r - p) == DVec3::ZERO {
                mesh.indices.truncate(first);
                return Err(GeomError::DegenerateTriangle {
                    triangle: first / 3,
                });
            }
            mesh.indices.extend(tri.iter().map(|&i| base + i));
        }
        for p in pts {
            let uv = DVec2::new(p.dot(t), p.dot(b));
            push_vertex(mesh, *p, nrm, DVec2::new(uv.x, -uv.y));
        }
        Ok(())
    })
}

/// Reusable buffers of the triangulations (one set per thread).
#[derive(Default)]
struct TriWork {
    /// A face's exact projection.
    exact: Vec<DVec2>,
    /// Triangles found.
    tris: Vec<[u32; 3]>,
    /// Ear clipping's remaining vertices.
    left: Vec<u32>,
    /// A ring lent to `Polygon` for validation.
    poly: Vec<DVec2>,
}

thread_local! {
    static TRI_WORK: std::cell::RefCell<TriWork> = std::cell::RefCell::new(TriWork::default());
}

/// Runs `f` with this thread's triangulation buffers (fresh ones if they are in use).
fn with_work<R>(f: impl FnOnce(&mut TriWork) -> R) -> R {
    TRI_WORK.with(|w| match w.try_borrow_mut() {
        Ok(mut w) => f(&mut w),
        Err(_) => f(&mut TriWork::default()),
    })
}

/// The vertices of a horizontal cap over `ring` at elevation `h` (what `push_vertex` per
/// corner writes, one attribute at a time).
#[inline]
fn push_cap(m: &mut Mesh, ring: &[DVec2], h: f64, normal: DVec3, sign: f64) {
    m.positions
        .extend(ring.iter().map(|&p| to_world(p, h).as_vec3()));
    m.normals
        .extend(std::iter::repeat_n(normal.as_vec3(), ring.len()));
    m.uvs
        .extend(ring.iter().map(|&p| DVec2::new(p.x, sign * p.y).as_vec2()));
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
    // 4 vertices and 2 triangles per wall, n vertices and n − 2 triangles per cap (every
    // triangulation of a simple ring has n − 2): the mesh is sized exactly.
    let mut m = Mesh::with_capacity(None, 6 * n, 4 * n - 4);
    let after = |i: usize| if i + 1 < n { i + 1 } else { 0 };
    with_work(|w| {
        let TriWork {
            exact,
            tris,
            left,
            poly,
        } = w;
        // Convexity and the caps' triangles are decided on the ring as the mesh stores it
        // (rounded to `f32`, which `to_world` keeps exact): a corner that rounding makes
        // straight is then not fanned from, and ear clipping never takes it as the tip
        // of a zero-area triangle.
        exact.clear();
        exact.extend(ring.iter().map(|p| p.as_vec2().as_dvec2()));
        let convex = (0..n).all(|i| {
            let (j, k) = (after(i), after(after(i)));
            orient2d(exact[i], exact[j], exact[k]) == Orientation::CounterClockwise
        });
        // Triangles can still collapse when rounded to f32: a convex prism is checked
        // whole (walls and fans), a triangulated one on its caps; each triangle is checked
        // from the f32 corners it is written with, as they are stored.
        let mut collapsed = false;
        let mut along = 0.0;
        for i in 0..n {
            let (a, b) = (ring[i], ring[after(i)]);
            let len = a.distance(b);
            if len.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
                || a.as_vec2() == b.as_vec2()
            {
                return Err(GeomError::DegenerateTriangle {
                    triangle: m.triangle_count(),
                });
            }
            let d = (b - a) / len;
            let normal = to_world(DVec2::new(d.y, -d.x), 0.0).as_vec3();
            let base = m.positions.len() as u32;
            // One slice per attribute (a capacity check each, not one per vertex).
            let corners = [
                (a, z0, along),
                (b, z0, along + len),
                (b, z1, along + len),
                (a, z1, along),
            ];
            let p = corners.map(|(p, h, _)| to_world(p, h).as_vec3());
            if convex {
                collapsed |= flat(p[0], p[1], p[2]) || flat(p[0], p[2], p[3]);
            }
            m.positions.extend_from_slice(&p);
            m.normals.extend_from_slice(&[normal; 4]);
            m.uvs
                .extend_from_slice(&corners.map(|(_, h, u)| DVec2::new(u, -h).as_vec2()));
            m.indices
                .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
            along += len;
        }
        // One triangulation serves both caps (reversed for the bottom): a fan for a
        // convex ring, as in `add_face`, else ear clipping or CDT. The ring is simple: a
        // validated lot, an inset of one, or a checked shrink.
        if convex {
            tris.clear();
            tris.extend((1..n as u32 - 1).map(|k| [0, k, k + 1]));
        } else {
            triangulate_into(exact, true, left, poly, tris)
                .ok_or(GeomError::DegenerateTriangle { triangle: 0 })??;
        }
        for (h, up) in [(z1, true), (z0, false)] {
            let (normal, sign) = if up {
                (DVec3::Y, -1.0)
            } else {
                (-DVec3::Y, 1.0)
            };
            let start = m.positions.len();
            let base = start as u32;
            push_cap(&mut m, ring, h, normal, sign);
            let cap = m.positions.get(start..).unwrap_or_default();
            let at = |i: u32| cap.get(i as usize).copied().unwrap_or_default();
            for &[a, b, c] in tris.iter() {
                let [a, b, c] = if up { [a, b, c] } else { [a, c, b] };
                m.indices.extend_from_slice(&[base + a, base + b, base + c]);
                collapsed = collapsed || flat(at(a), at(b), at(c));
            }
        }
        if collapsed {
            return Err(GeomError::DegenerateTriangle { triangle: 0 });
        }
        Ok(())
    })?;
    Ok(m)
}

/// Whether the triangle of the stored (f32) corners `a`, `b`, `c` has collapsed: a zero
/// cross product in f64.
#[inline]
fn flat(a: Vec3, b: Vec3, c: Vec3) -> bool {
    let [a, b, c] = [a, b, c].map(Vec3::as_dvec3);
    (b - a).cross(c - a) == DVec3::ZERO
}

/// Largest ring ear clipping handles; longer rings go to the constrained Delaunay
/// triangulation.
const EAR_CLIPPING_MAX: usize = 64;

/// Triangles (index triples, counter-clockwise) of the counter-clockwise simple ring
/// `ring`. Small rings are ear-clipped with exact orientation tests: an ear is a strictly
/// convex corner whose closed triangle holds no other remaining vertex, so no triangle is
/// degenerate; when no such ear exists (collinear runs), or for long rings, the
/// constrained Delaunay triangulation of polis-geom decides. `None` when the ring is not
/// counter-clockwise. Unless `simple` promises it, the ring is validated first.
#[cfg(test)]
pub(crate) fn triangulate_ring(
    ring: &[DVec2],
    simple: bool,
) -> Option<Result<Vec<[u32; 3]>, GeomError>> {
    let mut out = Vec::new();
    let r = triangulate_into(ring, simple, &mut Vec::new(), &mut Vec::new(), &mut out)?;
    Some(r.map(|()| out))
}

/// [`triangulate_ring`] into `out` (cleared first), with the buffers `left` (ear
/// clipping) and `poly` (validation).
fn triangulate_into(
    ring: &[DVec2],
    simple: bool,
    left: &mut Vec<u32>,
    poly: &mut Vec<DVec2>,
    out: &mut Vec<[u32; 3]>,
) -> Option<Result<(), GeomError>> {
    out.clear();
    let n = ring.len();
    if n < 3
        || polis_geom::polygon::ring_signed_area(ring).partial_cmp(&0.0)
            != Some(std::cmp::Ordering::Greater)
    {
        return None;
    }
    if ring.first() == ring.last() {
        return None;
    }
    if n <= EAR_CLIPPING_MAX {
        if !simple {
            let mut v = std::mem::take(poly);
            v.clear();
            v.extend_from_slice(ring);
            let p = Polygon::new(v);
            let valid = p.validate();
            *poly = p.into_points();
            if let Err(e) = valid {
                return Some(Err(e));
            }
        }
        if ear_clip(ring, left, out) {
            return Some(Ok(()));
        }
        out.clear();
    }
    Some(
        triangulate(&PolygonWithHoles::from(Polygon::new(ring.to_vec()))).map(|t| {
            out.extend(t);
        }),
    )
}

/// Ear clipping of a counter-clockwise simple ring into `out`; `false` when it gets
/// stuck.
fn ear_clip(ring: &[DVec2], left: &mut Vec<u32>, out: &mut Vec<[u32; 3]>) -> bool {
    let n = ring.len();
    left.clear();
    left.extend(0..n as u32);
    let at = |i: u32| ring[i as usize];
    let mut i = 0usize;
    let mut misses = 0usize;
    while left.len() > 3 {
        let m = left.len();
        let (a, b, c) = (left[(i + m - 1) % m], left[i % m], left[(i + 1) % m]);
        let (pa, pb, pc) = (at(a), at(b), at(c));
        let ear = orient2d(pa, pb, pc) == Orientation::CounterClockwise
            && left.iter().all(|&k| {
                if k == a || k == b || k == c {
                    return true;
                }
                let q = at(k);
                // Outside the closed triangle: strictly right of one of its edges.
                orient2d(pa, pb, q) == Orientation::Clockwise
                    || orient2d(pb, pc, q) == Orientation::Clockwise
                    || orient2d(pc, pa, q) == Orientation::Clockwise
            });
        if ear {
            out.push([a, b, c]);
            left.remove(i % m);
            misses = 0;
            i %= left.len();
        } else {
            misses += 1;
            if misses > m {
                return false;
            }
            i = (i + 1) % m;
        }
    }
    let [a, b, c] = [left[0], left[1], left[2]];
    if orient2d(at(a), at(b), at(c)) != Orientation::CounterClockwise {
        return false;
    }
    out.push([a, b, c]);
    true
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
    // n side triangles of 3 vertices, a bottom of n vertices and n − 2 triangles.
    let mut m = Mesh::with_capacity(None, 4 * n, (2 * n).saturating_sub(2));
    let top = to_world(apex, z1);
    for i in 0..n {
        add_face(
            &mut m,
            &[to_world(ring[i], z0), to_world(ring[(i + 1) % n], z0), top],
        )?;
    }
    let rev: Vec<DVec3> = ring.iter().rev().map(|&p| to_world(p, z0)).collect();
    add_face(&mut m, &rev)?;
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_straight_only_in_f32_is_not_fanned_from() {
        // Convex in f64 (corner 3 lies 1.6e-15 rad off the line from corner 2 to 0),
        // straight once rounded to f32: a fan from corner 0 would hold a flat triangle.
        let ring = [
            DVec2::new(39.02965313072855, 0.0),
            DVec2::new(-19.514826565364274, 33.80067111210565),
            DVec2::new(-19.514826565364274, -33.80067111210565),
            DVec2::new(9.757413282682137, -16.90033555605305),
        ];
        let m = prism(&ring, 0.0, 80.0).unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        let area = Polygon::new(ring.to_vec()).area();
        assert!((m.signed_volume() / (80.0 * area) - 1.0).abs() < 1e-6);
    }

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
    fn ear_clipping_covers_concave_rings_without_slivers() {
        // A comb with collinear runs along its base, and an L with a collinear vertex.
        let mut comb = vec![DVec2::new(0.0, 0.0)];
        for k in 0..6 {
            let x = f64::from(k) * 2.0;
            comb.push(DVec2::new(x + 1.0, 0.0));
        }
        comb.push(DVec2::new(12.0, 0.0));
        for k in (0..6).rev() {
            let x = f64::from(k) * 2.0;
            comb.extend([
                DVec2::new(x + 2.0, 5.0),
                DVec2::new(x + 1.5, 5.0),
                DVec2::new(x + 1.5, 1.0),
                DVec2::new(x + 0.5, 1.0),
                DVec2::new(x + 0.5, 5.0),
            ]);
        }
        comb.push(DVec2::new(0.0, 5.0));
        let comb = Polygon::new(comb);
        comb.validate().unwrap();
        let l = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(5.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 4.0),
            DVec2::new(4.0, 4.0),
            DVec2::new(4.0, 10.0),
            DVec2::new(0.0, 10.0),
        ];
        for ring in [comb.points().to_vec(), l] {
            let t = triangulate_ring(&ring, false).unwrap().unwrap();
            assert_eq!(t.len(), ring.len() - 2);
            let mut area = 0.0;
            for [a, b, c] in t {
                let [a, b, c] = [a, b, c].map(|i| ring[i as usize]);
                assert_eq!(orient2d(a, b, c), Orientation::CounterClockwise);
                area += 0.5 * (b - a).perp_dot(c - a);
            }
            let expected = Polygon::new(ring.clone()).area();
            assert!((area - expected).abs() < 1e-9, "{area} vs {expected}");
            assert!(prism(&ring, 0.0, 2.0).unwrap().check_closed().is_ok());
        }
        // Clockwise and self-intersecting rings are refused.
        let mut cw = Polygon::rect(DVec2::ZERO, DVec2::ONE).into_points();
        cw.reverse();
        assert!(triangulate_ring(&cw, false).is_none());
        let bow = [
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(0.0, 3.0),
            DVec2::new(5.0, 3.0),
            DVec2::new(6.0, -1.0),
        ];
        assert!(matches!(triangulate_ring(&bow, false), Some(Err(_)) | None));
    }

    #[test]
    fn faces_with_collinear_corners_in_space_get_no_slivers() {
        // (−2, 5), (1, 2), (2, 1) lie on x + y = 3: a rotated plane basis used to round
        // them apart and the ear clipper took the zero-area ear (found by the mansard
        // property test, pinned in proptest-regressions/roofs.txt).
        let ring = [
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 2.0),
            (0.0, 4.0),
            (-2.0, 5.0),
            (-4.0, 4.0),
            (-4.0, 1.0),
            (-5.0, -1.0),
            (-4.0, -4.0),
            (-2.0, -4.0),
            (0.0, -3.0),
            (3.0, -4.0),
            (4.0, -2.0),
        ]
        .map(|(x, y)| DVec2::new(x, y));
        for z in [0.0, 1.0, 7.3] {
            let down: Vec<DVec3> = ring.iter().rev().map(|&p| to_world(p, z)).collect();
            let up: Vec<DVec3> = ring.iter().map(|&p| to_world(p, z)).collect();
            let mut m = Mesh::new(None);
            add_face(&mut m, &down).unwrap();
            add_face(&mut m, &up).unwrap();
            m.validate().unwrap();
            assert_eq!(m.triangle_count(), 2 * (ring.len() - 2));
        }
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
