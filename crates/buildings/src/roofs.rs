//! Roof and detail templates (Parish & Müller §4.2's geometric templates): hip and gable
//! roofs from the straight skeleton's edge faces, mansard, pyramid, spire, antenna.
//!
//! Every template fills the current shape's volume: its footprint at the base elevation,
//! no higher than the shape's height, so a roof never leaves the bounding volume of the
//! module it refines (the LOD nesting of [`crate::lod`]).
//!
//! # Guarantees
//! Each returned mesh has been checked: valid, closed, consistently wound, outward
//! (positive volume). A template that cannot be built on a footprint (a pyramid on a
//! non-star-shaped polygon, a gable where the skeleton has no gable ends, a mansard whose
//! inset changes the topology) returns an error, and the interpreter falls back to the
//! hip roof, then the flat slab.
//!
//! # References
//! Kelly 2008 §4.4.1.1 (skeleton roofs); Aichholzer et al. 1995 (roofs as the lifted
//! straight skeleton); Parish & Müller 2001 §4.2.

use polis_geom::mesh::to_world;
use polis_geom::{DVec2, DVec3, GeomError, Mesh, Polygon, PolygonWithHoles};
use polis_lots::{StraightSkeleton, inset_shapes};

use crate::BuildingsError;
use crate::solid::{add_face, cone, prism};

/// Checks a finished solid: valid, closed, positive volume.
pub(crate) fn check_solid(m: &Mesh) -> Result<(), GeomError> {
    m.validate()?;
    m.check_closed()?;
    if m.signed_volume() > 0.0 {
        Ok(())
    } else {
        Err(GeomError::InvalidParameter {
            name: "mesh",
            reason: "the solid has no positive volume".into(),
        })
    }
}

/// The planar roof faces of a roof template (for facade faces with role `Roof`).
pub(crate) type RoofFaces = Vec<Vec<DVec3>>;

/// A hip roof (or, with `gable`, a gable roof) on the counter-clockwise `ring` at `z0`:
/// the straight skeleton's faces lifted at slope `slope` (rise per metre of inset), the
/// slope lowered so the ridge stays below `z0 + max_h`. For gables, every triangular face
/// whose apex joins exactly three faces has its apex moved onto its wall's plane, turning
/// it into a vertical gable wall.
pub(crate) fn skeleton_roof(
    ring: &[DVec2],
    z0: f64,
    max_h: f64,
    slope: f64,
    gable: bool,
) -> Result<(Mesh, RoofFaces), BuildingsError> {
    let poly = PolygonWithHoles::from(Polygon::new(ring.to_vec()));
    let sk = StraightSkeleton::new(&poly)?;
    let mut times: Vec<([u64; 2], f64)> = sk
        .nodes()
        .iter()
        .map(|n| ([n.position.x.to_bits(), n.position.y.to_bits()], n.time))
        .collect();
    times.sort_by_key(|t| t.0);
    let key = |p: DVec2| [p.x.to_bits(), p.y.to_bits()];
    let time_of = |p: DVec2, edge: usize| -> f64 {
        match times.binary_search_by(|t| t.0.cmp(&key(p))) {
            Ok(i) => times[i].1,
            Err(_) => {
                let (a, b) = (ring[edge], ring[(edge + 1) % ring.len()]);
                let d = (b - a).normalize_or_zero();
                (p - a).perp_dot(d).abs()
            }
        }
    };
    let max_t = sk.nodes().iter().map(|n| n.time).fold(0.0, f64::max);
    if !(max_t > 0.0 && max_t.is_finite()) {
        return Err(BuildingsError::Geom(GeomError::InvalidParameter {
            name: "footprint",
            reason: "the skeleton has no interior".into(),
        }));
    }
    let s = slope.min(max_h / max_t);
    // Gable ends: apex key → moved plan position.
    let mut moved: Vec<([u64; 2], DVec2)> = Vec::new();
    if gable {
        let mut uses: Vec<[u64; 2]> = sk
            .faces()
            .iter()
            .flat_map(|f| f.points().iter().map(|&p| key(p)))
            .collect();
        uses.sort_unstable();
        let count =
            |k: [u64; 2]| uses.partition_point(|u| *u <= k) - uses.partition_point(|u| *u < k);
        for f in sk.faces() {
            let pts = f.points();
            if pts.len() != 3 {
                continue;
            }
            let (a, b, c) = (pts[0], pts[1], pts[2]);
            let ab = b - a;
            let u = (c - a).dot(ab) / ab.length_squared();
            if count(key(c)) == 3 && u > 0.0 && u < 1.0 && !moved.iter().any(|m| m.0 == key(c)) {
                moved.push((key(c), a + ab * u));
            }
        }
        if moved.is_empty() {
            return Err(BuildingsError::Geom(GeomError::InvalidParameter {
                name: "footprint",
                reason: "no gable ends: the skeleton has no triangular end faces".into(),
            }));
        }
    }
    let place = |p: DVec2, edge: usize| -> DVec3 {
        let h = z0 + s * time_of(p, edge);
        let q = moved.iter().find(|m| m.0 == key(p)).map_or(p, |m| m.1);
        to_world(q, h)
    };
    let mut mesh = Mesh::with_capacity(None, 8 * ring.len(), 4 * ring.len());
    let mut faces = RoofFaces::new();
    for (e, f) in sk.faces().iter().enumerate() {
        let mut pts: Vec<DVec3> = Vec::with_capacity(f.len());
        for &p in f.points() {
            let w = place(p, e);
            if pts.last() != Some(&w) && !(pts.len() + 1 == f.len() && pts.first() == Some(&w)) {
                pts.push(w);
            }
        }
        if pts.len() < 3 {
            continue;
        }
        add_face(&mut mesh, &pts)?;
        faces.push(pts);
    }
    let bottom: Vec<DVec3> = ring.iter().rev().map(|&p| to_world(p, z0)).collect();
    add_face(&mut mesh, &bottom)?;
    check_solid(&mesh)?;
    Ok((mesh, faces))
}

/// A mansard roof: steep sides rising `h` while the footprint insets by `d`, and a flat
/// top. Built when the inset keeps every edge (one ring, sources `0..n` in order), so each
/// side is a planar trapezoid between an edge and its offset.
pub(crate) fn mansard(
    ring: &[DVec2],
    z0: f64,
    h: f64,
    d: f64,
) -> Result<(Mesh, RoofFaces), BuildingsError> {
    let poly = PolygonWithHoles::from(Polygon::new(ring.to_vec()));
    let shapes = inset_shapes(&poly, None, d)?;
    let n = ring.len();
    let not_kept = || {
        BuildingsError::Geom(GeomError::InvalidParameter {
            name: "Mansard",
            reason: "the inset does not keep every footprint edge".into(),
        })
    };
    let [shape] = shapes.as_slice() else {
        return Err(not_kept());
    };
    let inner = &shape.outer;
    if inner.points.len() != n || inner.sources.len() != n || !shape.holes.is_empty() {
        return Err(not_kept());
    }
    let k = inner
        .sources
        .iter()
        .position(|s| *s == Some(0))
        .ok_or_else(not_kept)?;
    let inner_at = |i: usize| inner.points[(k + i) % n];
    if (0..n).any(|i| inner.sources[(k + i) % n] != Some(i)) {
        return Err(not_kept());
    }
    let z1 = z0 + h;
    let mut mesh = Mesh::with_capacity(None, 6 * n, 4 * n);
    let mut faces = RoofFaces::new();
    for i in 0..n {
        let j = (i + 1) % n;
        let f = vec![
            to_world(ring[i], z0),
            to_world(ring[j], z0),
            to_world(inner_at(j), z1),
            to_world(inner_at(i), z1),
        ];
        add_face(&mut mesh, &f)?;
        faces.push(f);
    }
    let top: Vec<DVec3> = (0..n).map(|i| to_world(inner_at(i), z1)).collect();
    add_face(&mut mesh, &top)?;
    faces.push(top);
    let bottom: Vec<DVec3> = ring.iter().rev().map(|&p| to_world(p, z0)).collect();
    add_face(&mut mesh, &bottom)?;
    check_solid(&mesh)?;
    Ok((mesh, faces))
}

/// A pyramid roof: every edge joined to an apex above the footprint's centroid.
pub(crate) fn pyramid(
    ring: &[DVec2],
    z0: f64,
    h: f64,
) -> Result<(Mesh, RoofFaces), BuildingsError> {
    let c = Polygon::new(ring.to_vec()).centroid();
    let mesh = cone(ring, z0, c, z0 + h)?;
    check_solid(&mesh)?;
    let apex = to_world(c, z0 + h);
    let faces = (0..ring.len())
        .map(|i| {
            vec![
                to_world(ring[i], z0),
                to_world(ring[(i + 1) % ring.len()], z0),
                apex,
            ]
        })
        .collect();
    Ok((mesh, faces))
}

/// A flat roof slab (or parapet block) filling the shape: a prism from `z0` to `z0 + h`.
pub(crate) fn slab(ring: &[DVec2], z0: f64, h: f64) -> Result<(Mesh, RoofFaces), BuildingsError> {
    let mesh = prism(ring, z0, z0 + h)?;
    let top = ring.iter().map(|&p| to_world(p, z0 + h)).collect();
    Ok((mesh, vec![top]))
}

/// A regular `sides`-gon of radius `r` centred at `c`, counter-clockwise.
pub(crate) fn regular(c: DVec2, r: f64, sides: usize) -> Vec<DVec2> {
    (0..sides)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / sides as f64 + std::f64::consts::FRAC_PI_4;
            c + DVec2::new(libm_cos(a), libm_sin(a)) * r
        })
        .collect()
}

fn libm_cos(a: f64) -> f64 {
    polis_geom::glam::DVec2::from_angle(a).x
}

fn libm_sin(a: f64) -> f64 {
    polis_geom::glam::DVec2::from_angle(a).y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(w: f64, d: f64) -> Vec<DVec2> {
        Polygon::rect(DVec2::ZERO, DVec2::new(w, d)).into_points()
    }

    #[test]
    fn hip_roof_of_a_rectangle_has_the_known_volume() {
        // 20 × 10 at 45°: ridge 5 m high, volume = w·d²/4 − d³/12 (hip on a rectangle).
        let (m, faces) = skeleton_roof(&rect(20.0, 10.0), 0.0, 100.0, 1.0, false).unwrap();
        let expected = 20.0 * 100.0 / 4.0 - 1000.0 / 12.0;
        assert!(
            (m.signed_volume() - expected).abs() < 1e-3,
            "{}",
            m.signed_volume()
        );
        assert_eq!(faces.len(), 4);
        assert!((m.bbox().max.y - 5.0).abs() < 1e-5);
    }

    #[test]
    fn hip_roof_is_lowered_to_fit_the_height() {
        let (m, _) = skeleton_roof(&rect(20.0, 10.0), 3.0, 2.0, 1.0, false).unwrap();
        assert!((m.bbox().max.y - 5.0).abs() < 1e-5, "ridge at 3 + 2");
    }

    #[test]
    fn gable_roof_of_a_rectangle_is_a_prism() {
        // Gable on 20 × 10 at 45°: a triangular prism, volume = ½·10·5·20.
        let (m, faces) = skeleton_roof(&rect(20.0, 10.0), 0.0, 100.0, 1.0, true).unwrap();
        assert!(
            (m.signed_volume() - 500.0).abs() < 1e-3,
            "{}",
            m.signed_volume()
        );
        // Two gable walls are vertical.
        let vertical = faces
            .iter()
            .filter(|f| {
                f.iter().all(|p| (p.x - f[0].x).abs() < 1e-9)
                    || f.iter().all(|p| (p.z - f[0].z).abs() < 1e-9)
            })
            .count();
        assert_eq!(vertical, 2);
    }

    #[test]
    fn gable_on_a_square_has_no_gable_end() {
        assert!(skeleton_roof(&rect(10.0, 10.0), 0.0, 100.0, 1.0, true).is_err());
        assert!(skeleton_roof(&rect(10.0, 10.0), 0.0, 100.0, 1.0, false).is_ok());
    }

    #[test]
    fn hip_roof_on_an_l_shape_is_closed() {
        let l = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(30.0, 0.0),
            DVec2::new(30.0, 10.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(10.0, 25.0),
            DVec2::new(0.0, 25.0),
        ];
        for gable in [false, true] {
            if let Ok((m, _)) = skeleton_roof(&l, 2.0, 50.0, 0.7, gable) {
                check_solid(&m).unwrap();
            } else {
                assert!(gable, "the hip roof always exists");
            }
        }
    }

    #[test]
    fn pyramid_and_mansard_volumes() {
        let (p, _) = pyramid(&rect(10.0, 10.0), 0.0, 6.0).unwrap();
        assert!((p.signed_volume() - 200.0).abs() < 1e-3);
        // Mansard 20 × 10, inset 2 over 3 m: frustum volume h/3·(A1 + A2 + √(A1·A2)).
        let (m, faces) = mansard(&rect(20.0, 10.0), 0.0, 3.0, 2.0).unwrap();
        let (a1, a2): (f64, f64) = (200.0, 16.0 * 6.0);
        let v = 3.0 / 3.0 * (a1 + a2 + (a1 * a2).sqrt());
        // Not similar rectangles, so use the prismatoid formula instead.
        let am = 18.0 * 8.0;
        let prismatoid = 3.0 / 6.0 * (a1 + 4.0 * am + a2);
        assert!(
            (m.signed_volume() - prismatoid).abs() < 1e-3,
            "{} vs {prismatoid} (frustum {v})",
            m.signed_volume()
        );
        assert_eq!(faces.len(), 5);
        // An inset that swallows an edge is refused.
        assert!(mansard(&rect(20.0, 10.0), 0.0, 3.0, 5.0).is_err());
    }

    #[test]
    fn pyramid_needs_a_star_shaped_footprint() {
        let l = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(30.0, 0.0),
            DVec2::new(30.0, 2.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(2.0, 30.0),
            DVec2::new(0.0, 30.0),
        ];
        assert!(pyramid(&l, 0.0, 5.0).is_err());
    }
}
