//! Roof and detail templates (Parish & Müller §4.2's geometric templates): hip and gable
//! roofs from the straight skeleton's edge faces, mansard, pyramid, spire, antenna.
//!
//! Every template fills the current shape's volume: its footprint at the base elevation,
//! no higher than the shape's height, so a roof never leaves the bounding volume of the
//! module it refines (the LOD nesting described in [`crate::grammar`]).
//!
//! # Guarantees
//! Each returned mesh has been checked: valid, closed, consistently wound, outward
//! (positive volume). A template that cannot be built on a footprint (a pyramid on a
//! non-star-shaped polygon, a gable where the skeleton has no gable ends) returns an
//! error, and the interpreter falls back to the hip roof, then the flat slab. Mansards are
//! built on any footprint the skeleton handles: the steep part is the skeleton roof cut
//! at the inset, so lost edges and split insets need no special case.
//!
//! # References
//! Kelly 2008 §4.4.1.1 (skeleton roofs); Aichholzer et al. 1995 (roofs as the lifted
//! straight skeleton); Parish & Müller 2001 §4.2.

use polis_geom::mesh::to_world;
use polis_geom::{DVec2, DVec3, GeomError, Mesh, Polygon, PolygonWithHoles};
use polis_lots::StraightSkeleton;

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
    let times = NodeTimes::new(&sk);
    let key = polis_geom::hash::point_key;
    let time_of = |p: DVec2, edge: usize| times.time(p, ring, edge);
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
    let mut faces = RoofFaces::with_capacity(sk.faces().len());
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
        faces.push(pts);
    }
    let mesh = solid_of(&faces, ring, z0)?;
    check_solid(&mesh)?;
    Ok((mesh, faces))
}

/// The solid of the planar `faces` (in order) closed by the bottom face, `ring` at `z0`
/// facing down, in a mesh sized exactly (a face of `n` corners has `n` vertices and
/// `n − 2` triangles).
fn solid_of(faces: &[Vec<DVec3>], ring: &[DVec2], z0: f64) -> Result<Mesh, GeomError> {
    let bottom: Vec<DVec3> = ring.iter().rev().map(|&p| to_world(p, z0)).collect();
    let all = || faces.iter().map(Vec::as_slice).chain([bottom.as_slice()]);
    let vertices = all().map(<[DVec3]>::len).sum();
    let triangles = all().map(|f| f.len().saturating_sub(2)).sum();
    let mut mesh = Mesh::with_capacity(None, vertices, triangles);
    for f in all() {
        add_face(&mut mesh, f)?;
    }
    Ok(mesh)
}

/// Distance, metres, that a mansard's break line keeps from every skeleton event: when a
/// node's time lies closer to the inset distance than this, the inset moves twice this
/// far beyond it, so the break line never passes exactly through an event (no pinched or
/// collapsed top rings, no zero-length edges).
pub(crate) const MANSARD_EVENT_CLEARANCE: f64 = 1e-3;

/// A mansard roof: the lower steep slope is the straight-skeleton roof of `ring` cut at
/// the break line, the wavefront at time `d` (the inset by `d`, however many pieces it
/// has and whichever edges it lost); over every remaining piece stands a shallow hip roof
/// of pitch `upper_slope` (rise per metre; 0 for flat tops), lowered so it takes at most
/// half of `h`. The steep part rises the rest of `h`. If the inset is empty (`d` at or
/// beyond the skeleton's last event) the whole roof is the steep slope: a hip roof.
///
/// Faces of the steep part are the skeleton faces clipped to `t ≤ d` (each face is
/// monotone along its edge, so the clip is one polygon); break-line points are computed
/// once per skeleton arc, from its lower node, so neighbouring faces share them bit for
/// bit and the top rings chain into closed loops.
pub(crate) fn mansard(
    ring: &[DVec2],
    z0: f64,
    h: f64,
    d: f64,
    upper_slope: f64,
) -> Result<(Mesh, RoofFaces), BuildingsError> {
    let bad = |reason: &str| {
        BuildingsError::Geom(GeomError::InvalidParameter {
            name: "Mansard",
            reason: reason.into(),
        })
    };
    if !(d > 0.0 && d.is_finite() && h > 0.0 && h.is_finite() && upper_slope >= 0.0) {
        return Err(bad("give an inset > 0 m, a height > 0 m and a pitch ≥ 0"));
    }
    let poly = PolygonWithHoles::from(Polygon::new(ring.to_vec()));
    let sk = StraightSkeleton::new(&poly)?;
    let times = NodeTimes::new(&sk);
    let max_t = sk.nodes().iter().map(|n| n.time).fold(0.0, f64::max);
    // Keep the break line clear of every event (just past it: a wavefront part that
    // collapses there is gone, not left as a sliver).
    let mut d = d;
    for _ in 0..8 {
        if d >= max_t - MANSARD_EVENT_CLEARANCE {
            break;
        }
        match sk
            .nodes()
            .iter()
            .find(|n| n.time > 0.0 && (n.time - d).abs() < MANSARD_EVENT_CLEARANCE)
        {
            Some(n) => d = n.time + 2.0 * MANSARD_EVENT_CLEARANCE,
            None => break,
        }
    }
    if d >= max_t - MANSARD_EVENT_CLEARANCE {
        // Nothing is left above the break line: the steep slope closes as a hip roof.
        return skeleton_roof(ring, z0, h, h / d.max(max_t), false);
    }
    if d <= 0.0
        || sk
            .nodes()
            .iter()
            .any(|n| n.time > 0.0 && (n.time - d).abs() < MANSARD_EVENT_CLEARANCE)
    {
        return Err(bad("the inset lies on a cluster of skeleton events"));
    }
    // Clip every face to t ≤ d, in the plan.
    let mut bands: Vec<Vec<(DVec2, f64)>> = Vec::with_capacity(sk.faces().len());
    let mut cap_edges: Vec<(DVec2, DVec2)> = Vec::new();
    for (e, f) in sk.faces().iter().enumerate() {
        let pts: Vec<(DVec2, f64)> = f
            .points()
            .iter()
            .map(|&p| (p, times.time(p, ring, e)))
            .collect();
        let m = pts.len();
        let mut out: Vec<(DVec2, f64)> = Vec::with_capacity(m + 2);
        for i in 0..m {
            let (p, tp) = pts[i];
            let (q, tq) = pts[(i + 1) % m];
            if tp <= d {
                out.push((p, tp));
            }
            if (tp <= d) != (tq <= d) {
                // The arc's lower end decides the point, whichever face asks.
                let ((lo, tlo), (hi, thi)) = if tp < tq {
                    ((p, tp), (q, tq))
                } else {
                    ((q, tq), (p, tp))
                };
                out.push((lo + (hi - lo) * ((d - tlo) / (thi - tlo)), d));
            }
        }
        out.dedup_by(|a, b| a.0 == b.0);
        if out.len() > 1 && out.first().map(|a| a.0) == out.last().map(|a| a.0) {
            out.pop();
        }
        let k = out.len();
        for i in 0..k {
            let (a, b) = (out[i], out[(i + 1) % k]);
            if a.1 == d && b.1 == d {
                // The face runs right to left along the break line; the cap runs the
                // other way (counter-clockwise seen from above).
                cap_edges.push((b.0, a.0));
            }
        }
        bands.push(out);
    }
    let loops = chain_loops(&cap_edges).ok_or_else(|| bad("the break line does not close"))?;
    // The upper roofs' skeletons decide how much height they take.
    let mut uppers: Vec<(Vec<DVec2>, Option<StraightSkeleton>)> = Vec::with_capacity(loops.len());
    let mut t_up: f64 = 0.0;
    for l in loops {
        let piece = Polygon::new(l.clone());
        let area = piece.signed_area();
        if area.is_nan() || area <= 0.0 {
            return Err(bad("a piece above the break line is not counter-clockwise"));
        }
        let sk_up = if upper_slope > 0.0 {
            StraightSkeleton::new(&PolygonWithHoles::from(piece)).ok()
        } else {
            None
        };
        if let Some(s) = &sk_up {
            t_up = t_up.max(s.nodes().iter().map(|n| n.time).fold(0.0, f64::max));
        }
        uppers.push((l, sk_up));
    }
    let h_up = if t_up > 0.0 {
        (upper_slope * t_up).min(0.5 * h)
    } else {
        0.0
    };
    let s_up = if t_up > 0.0 { h_up / t_up } else { 0.0 };
    let s_low = (h - h_up) / d;
    let z_break = z0 + s_low * d;
    let mut faces = RoofFaces::with_capacity(bands.len() + uppers.len());
    for band in &bands {
        if band.len() < 3 {
            continue;
        }
        let f: Vec<DVec3> = band
            .iter()
            .map(|&(p, t)| to_world(p, if t == d { z_break } else { z0 + s_low * t }))
            .collect();
        faces.push(f);
    }
    for (piece, sk_up) in &uppers {
        match sk_up {
            Some(s) => {
                let t = NodeTimes::new(s);
                for (e, f) in s.faces().iter().enumerate() {
                    let mut pts: Vec<DVec3> = Vec::with_capacity(f.len());
                    for &p in f.points() {
                        let tp = t.time(p, piece, e);
                        let w = to_world(
                            p,
                            if tp == 0.0 {
                                z_break
                            } else {
                                z_break + s_up * tp
                            },
                        );
                        if pts.last() != Some(&w)
                            && !(pts.len() + 1 == f.len() && pts.first() == Some(&w))
                        {
                            pts.push(w);
                        }
                    }
                    if pts.len() < 3 {
                        continue;
                    }
                    faces.push(pts);
                }
            }
            None => {
                let top: Vec<DVec3> = piece.iter().map(|&p| to_world(p, z_break)).collect();
                faces.push(top);
            }
        }
    }
    let mesh = solid_of(&faces, ring, z0)?;
    check_solid(&mesh)?;
    Ok((mesh, faces))
}

/// Chains directed edges into closed loops (each start point used once); `None` if an
/// edge has no unique successor.
fn chain_loops(edges: &[(DVec2, DVec2)]) -> Option<Vec<Vec<DVec2>>> {
    let key = polis_geom::hash::point_key;
    let mut by_start: Vec<([u64; 2], usize)> = edges
        .iter()
        .enumerate()
        .map(|(i, e)| (key(e.0), i))
        .collect();
    by_start.sort_unstable();
    if by_start.windows(2).any(|w| w[0].0 == w[1].0) {
        return None;
    }
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for first in 0..edges.len() {
        if used[first] {
            continue;
        }
        let mut l = Vec::new();
        let mut cur = first;
        loop {
            if used[cur] {
                if cur != first {
                    return None;
                }
                break;
            }
            used[cur] = true;
            let (a, b) = edges[cur];
            l.push(a);
            let i = by_start.binary_search_by(|s| s.0.cmp(&key(b))).ok()?;
            cur = by_start[i].1;
        }
        if l.len() < 3 {
            return None;
        }
        loops.push(l);
    }
    Some(loops)
}

/// Skeleton node times by exact position, for lifting faces into roofs.
struct NodeTimes {
    times: Vec<([u64; 2], f64)>,
}

impl NodeTimes {
    fn new(sk: &StraightSkeleton) -> Self {
        let mut times: Vec<([u64; 2], f64)> = sk
            .nodes()
            .iter()
            .map(|n| (polis_geom::hash::point_key(n.position), n.time))
            .collect();
        times.sort_by_key(|t| t.0);
        NodeTimes { times }
    }

    /// The time of face point `p` of input edge `edge` of `ring`: the node's, or the
    /// distance to the edge's line when no node sits there.
    fn time(&self, p: DVec2, ring: &[DVec2], edge: usize) -> f64 {
        let k = polis_geom::hash::point_key(p);
        match self.times.binary_search_by(|t| t.0.cmp(&k)) {
            Ok(i) => self.times[i].1,
            Err(_) => {
                let (a, b) = (ring[edge % ring.len()], ring[(edge + 1) % ring.len()]);
                let d = (b - a).normalize_or_zero();
                (p - a).perp_dot(d).abs()
            }
        }
    }
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
        // Flat-topped mansard 20 × 10, inset 2 over 3 m: a prismatoid,
        // V = h/6·(A_bottom + 4·A_middle + A_top).
        let (m, faces) = mansard(&rect(20.0, 10.0), 0.0, 3.0, 2.0, 0.0).unwrap();
        let (a1, a2, am) = (200.0, 16.0 * 6.0, 18.0 * 8.0);
        let prismatoid = 3.0 / 6.0 * (a1 + 4.0 * am + a2);
        assert!(
            (m.signed_volume() - prismatoid).abs() < 1e-3,
            "{} vs {prismatoid}",
            m.signed_volume()
        );
        assert_eq!(faces.len(), 5);
        // An inset that swallows the whole footprint leaves only the steep slope: a hip
        // roof at slope 3/5 (ridge at 5 · 3/5 = 3 m).
        let (m, faces) = mansard(&rect(20.0, 10.0), 0.0, 3.0, 5.0, 0.3).unwrap();
        check_solid(&m).unwrap();
        assert_eq!(faces.len(), 4);
        assert!((m.bbox().max.y - 3.0).abs() < 1e-5);
    }

    #[test]
    fn mansard_with_a_shallow_upper_roof() {
        // 20 × 10, inset 2, upper pitch 0.25: the upper hip over the 16 × 6 inset rises
        // 3 · 0.25 = 0.75 m, the steep part the other 3.25 m (slope 3.25/2 ≫ 0.25).
        let (m, faces) = mansard(&rect(20.0, 10.0), 1.0, 4.0, 2.0, 0.25).unwrap();
        check_solid(&m).unwrap();
        assert_eq!(faces.len(), 8, "4 steep trapezoids and 4 upper hip faces");
        assert!((m.bbox().max.y - 5.0).abs() < 1e-5, "{}", m.bbox().max.y);
        // The break line is at 1 + 3.25 m: the inset's corners are there.
        let break_z = 4.25f32;
        let on_break = m
            .positions
            .iter()
            .filter(|p| (p.y - break_z).abs() < 1e-5)
            .count();
        assert!(on_break >= 4);
        // Volume: the flat-topped prismatoid plus the hip on 16 × 6 at slope 0.25.
        let lower = 3.25 / 6.0 * (200.0 + 4.0 * 18.0 * 8.0 + 96.0);
        let hip = 0.25 * (16.0 * 36.0 / 4.0 - 216.0 / 12.0);
        assert!(
            (m.signed_volume() - (lower + hip)).abs() < 1e-2,
            "{} vs {}",
            m.signed_volume(),
            lower + hip
        );
    }

    /// Two 12 × 12 squares joined by a 4 m wide corridor.
    fn dumbbell() -> Vec<DVec2> {
        [
            (0.0, 0.0),
            (12.0, 0.0),
            (12.0, 4.0),
            (22.0, 4.0),
            (22.0, 0.0),
            (34.0, 0.0),
            (34.0, 12.0),
            (22.0, 12.0),
            (22.0, 8.0),
            (12.0, 8.0),
            (12.0, 12.0),
            (0.0, 12.0),
        ]
        .map(|(x, y)| DVec2::new(x, y))
        .to_vec()
    }

    #[test]
    fn mansard_splits_over_a_concave_footprint() {
        // Inset 3 loses the corridor and its four edges: two 6 × 6 pieces remain, each
        // under its own shallow pyramid-like hip.
        for (d, pieces) in [(3.0, 2), (1.5, 1), (2.0, 2)] {
            for pitch in [0.0, 0.3] {
                let (m, faces) = mansard(&dumbbell(), 0.0, 3.0, d, pitch)
                    .unwrap_or_else(|e| panic!("d {d} pitch {pitch}: {e}"));
                check_solid(&m).unwrap();
                assert!(m.bbox().max.y <= 3.0 + 1e-5);
                // Flat tops: one face per piece at the break line (y = 3).
                if pitch == 0.0 {
                    let tops = faces
                        .iter()
                        .filter(|f| f.iter().all(|p| (p.y - 3.0).abs() < 1e-9))
                        .count();
                    assert_eq!(tops, pieces, "d {d}");
                }
            }
        }
        // d = 2 is exactly the corridor's collapse: the break line moves 2 mm past the
        // event (two pieces, no sliver), and the roof stays closed.
    }

    #[test]
    fn mansard_on_an_l_shape_losing_edges() {
        // A chamfered L: the 1 m chamfer edges vanish in the inset by 2.5.
        let l = [
            (0.0, 0.0),
            (29.0, 0.0),
            (30.0, 1.0),
            (30.0, 10.0),
            (10.0, 10.0),
            (10.0, 25.0),
            (1.0, 25.0),
            (0.0, 24.0),
        ]
        .map(|(x, y)| DVec2::new(x, y));
        for pitch in [0.0, 0.27] {
            let (m, _) = mansard(&l, 2.0, 2.5, 2.5, pitch).unwrap();
            check_solid(&m).unwrap();
            assert!(m.bbox().max.y <= 4.5 + 1e-5);
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 160, ..Default::default() })]
        /// Random star footprints (concave for most), insets from shallow to beyond the
        /// last event, flat and pitched tops: the mansard is always built and closed.
        #[test]
        fn mansard_is_closed_on_random_concave_footprints(
            n in 3usize..14,
            radii in proptest::collection::vec(0.25f64..1.0, 14),
            size in 6.0f64..40.0,
            d in 0.2f64..12.0,
            pitch in proptest::prop_oneof![proptest::strategy::Just(0.0), 0.05f64..0.6],
            integer in proptest::bool::ANY,
        ) {
            let ring: Vec<DVec2> = (0..n)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / n as f64;
                    let p = DVec2::from_angle(a) * size * radii[i];
                    if integer { p.round() } else { p }
                })
                .collect();
            let poly = Polygon::new(ring.clone());
            if poly.validate().is_err() || !poly.is_ccw() {
                return Ok(());
            }
            if StraightSkeleton::new(&PolygonWithHoles::from(poly)).is_err() {
                return Ok(());
            }
            match mansard(&ring, 1.0, 4.0, d, pitch) {
                Ok((m, faces)) => {
                    check_solid(&m).map_err(|e| proptest::test_runner::TestCaseError::fail(e.to_string()))?;
                    proptest::prop_assert!(m.bbox().max.y <= 5.0 + 1e-4);
                    proptest::prop_assert!(m.bbox().min.y >= 1.0 - 1e-4);
                    proptest::prop_assert!(!faces.is_empty());
                }
                Err(e) => proptest::prop_assert!(false, "{e}"),
            }
        }
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
