//! Road surface meshes: ribbons of each road's width along its centre line, draped on an
//! elevation field, for the glTF and OBJ writers.
//!
//! [`road_surfaces`] turns the [`MapRoad`]s of a map into one [`Mesh`] (one material):
//!
//! * Each road is a ribbon of its width. At interior vertices the two sides are joined with
//!   a **miter** (the offset point on the bisector), so a polyline's ribbon has exactly the
//!   area `length × width` and no gaps; the miter length is limited to
//!   [`MITER_LIMIT`] half-widths (sharper turns are clamped and slightly narrowed).
//! * Segments longer than [`RoadSurfaceOptions::max_segment_m`] are subdivided and every
//!   station is lifted to the elevation field sampled at its centre point, plus
//!   [`RoadSurfaceOptions::lift_m`]; bridges instead run straight between the elevations at
//!   their two ends (a deck over water or a valley).
//! * Crossings: ribbons of different roads overlap where they cross; each class is lifted
//!   by [`RoadSurfaceOptions::class_lift_m`] per rank (footpath < other < street < major <
//!   highway) so the larger road is drawn on top without depth fighting.
//! * Quads are flat shaded (Newell normals), counter-clockwise from above; texture
//!   coordinates are metres with `u` along the road (from its start) and `v` across it
//!   (`0` on the right edge to `−width` on the left), so a lane-marking texture runs along
//!   the road.
//!
//! ## Limitations
//!
//! * No junction polygons: overlapping ribbons stand in for intersections, and turns
//!   sharper than the miter limit are clamped rather than bevelled.
//! * The terrain is sampled at the ribbon's stations only; a ribbon may float above or dip
//!   below terrain that bends across its width.

use polis_geom::field::Field;
use polis_geom::glam::DVec3;
use polis_geom::mesh::to_world;
use polis_geom::scene::MaterialId;
use polis_geom::{DVec2, Mesh};
use serde::{Deserialize, Serialize};

use crate::ExportError;
use crate::map::{MapLayers, MapRoad};

/// The longest miter, in half-widths (2 = turns up to 120° are exact).
pub const MITER_LIMIT: f64 = 2.0;

/// Options of [`road_surfaces`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RoadSurfaceOptions {
    /// Longest piece of ribbon between two terrain samples, metres (finite, > 0).
    /// Default: 10.0.
    pub max_segment_m: f64,
    /// Height of the surface above the terrain, metres (finite). Default: 0.05.
    pub lift_m: f64,
    /// Extra height per class rank at crossings, metres (finite, ≥ 0). Default: 0.02.
    pub class_lift_m: f64,
}

impl Default for RoadSurfaceOptions {
    fn default() -> Self {
        RoadSurfaceOptions {
            max_segment_m: 10.0,
            lift_m: 0.05,
            class_lift_m: 0.02,
        }
    }
}

/// Builds the surface ribbons of `roads` as one mesh with `material`, draped on
/// `elevation` (metres above the layout plane at each layout point).
///
/// Roads are checked as [`MapLayers::validate`] checks them; zero-width roads and
/// zero-length segments are skipped. Fails with [`ExportError::InvalidMap`] when the
/// elevation field returns a non-finite value.
///
/// ```
/// use polis_export::map::{MapRoad, RoadClass};
/// use polis_export::surfaces::{road_surfaces, RoadSurfaceOptions};
/// use polis_export::geom::{DVec2, field::Constant};
/// let road = MapRoad::new(vec![DVec2::ZERO, DVec2::new(100.0, 0.0)], RoadClass::Street, 8.0);
/// let mesh = road_surfaces(&[road], &Constant(0.0), &RoadSurfaceOptions::default(), None)?;
/// mesh.validate()?;
/// assert!((mesh.surface_area() - 800.0).abs() < 1e-3);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn road_surfaces(
    roads: &[MapRoad],
    elevation: &dyn Field,
    options: &RoadSurfaceOptions,
    material: Option<MaterialId>,
) -> Result<Mesh, ExportError> {
    let o = options;
    if !(o.max_segment_m.is_finite() && o.max_segment_m > 0.0) {
        return Err(ExportError::InvalidOption {
            name: "max_segment_m",
            reason: format!("{} must be finite and > 0", o.max_segment_m),
        });
    }
    if !(o.lift_m.is_finite() && o.class_lift_m.is_finite() && o.class_lift_m >= 0.0) {
        return Err(ExportError::InvalidOption {
            name: "lift_m",
            reason: "lift_m must be finite and class_lift_m finite and ≥ 0".to_string(),
        });
    }
    MapLayers {
        roads: roads.to_vec(),
        ..MapLayers::default()
    }
    .validate()?;
    let mut mesh = Mesh::new(material);
    for (i, road) in roads.iter().enumerate() {
        add_ribbon(&mut mesh, i, road, elevation, o)?;
    }
    Ok(mesh)
}

/// The left unit normal of the direction `d`.
fn left(d: DVec2) -> DVec2 {
    DVec2::new(-d.y, d.x)
}

fn add_ribbon(
    mesh: &mut Mesh,
    index: usize,
    road: &MapRoad,
    elevation: &dyn Field,
    o: &RoadSurfaceOptions,
) -> Result<(), ExportError> {
    let half = road.width_m / 2.0;
    if half <= 0.0 {
        return Ok(());
    }
    // Drop repeated points: they have no direction.
    let mut pts: Vec<DVec2> = Vec::with_capacity(road.points.len());
    for &p in &road.points {
        if pts.last() != Some(&p) {
            pts.push(p);
        }
    }
    if pts.len() < 2 {
        return Ok(());
    }
    let dirs: Vec<DVec2> = pts.windows(2).map(|w| (w[1] - w[0]).normalize()).collect();
    // Offset (from centre to the left edge) at every vertex: miter at interior vertices.
    let offsets: Vec<DVec2> = (0..pts.len())
        .map(|k| {
            let before = dirs.get(k.wrapping_sub(1)).copied();
            let after = dirs.get(k).copied();
            match (before, after) {
                (Some(a), Some(b)) => {
                    let (na, nb) = (left(a), left(b));
                    let bis = (na + nb).normalize_or_zero();
                    let cos = bis.dot(na);
                    if bis == DVec2::ZERO || cos <= 0.0 {
                        na * half
                    } else {
                        bis * (half / cos.max(1.0 / MITER_LIMIT))
                    }
                }
                (Some(a), None) | (None, Some(a)) => left(a) * half,
                (None, None) => DVec2::ZERO,
            }
        })
        .collect();
    let lift = o.lift_m + o.class_lift_m * f64::from(road.class.rank());
    let height = |p: DVec2| -> Result<f64, ExportError> {
        let h = elevation.sample(p);
        if h.is_finite() {
            Ok(h)
        } else {
            Err(ExportError::map(
                format!("road {index} (id {})", road.id),
                format!("the elevation field is {h} at {p}; it must be finite"),
            ))
        }
    };
    let (h_start, h_end) = if road.bridge {
        (height(pts[0])?, height(pts[pts.len() - 1])?)
    } else {
        (0.0, 0.0)
    };
    let total: f64 = pts.windows(2).map(|w| (w[1] - w[0]).length()).sum();
    let mut along = 0.0;
    for (k, w) in pts.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        let len = (b - a).length();
        let pieces = (len / o.max_segment_m).ceil().max(1.0) as usize;
        let station = |j: usize| -> Result<(DVec3, DVec3, f64), ExportError> {
            let t = j as f64 / pieces as f64;
            let c = a.lerp(b, t);
            let off = offsets[k].lerp(offsets[k + 1], t);
            let s = along + len * t;
            let h = if road.bridge {
                let f = if total > 0.0 { s / total } else { 0.0 };
                h_start + (h_end - h_start) * f
            } else {
                height(c)?
            } + lift;
            Ok((to_world(c + off, h), to_world(c - off, h), s))
        };
        let mut prev = station(0)?;
        for j in 1..=pieces {
            let next = station(j)?;
            let (l0, r0, s0) = prev;
            let (l1, r1, s1) = next;
            let uv = [
                DVec2::new(s0, 0.0),
                DVec2::new(s1, 0.0),
                DVec2::new(s1, -road.width_m),
                DVec2::new(s0, -road.width_m),
            ];
            // Counter-clockwise from above: right edge forwards, left edge backwards.
            // A quad collapsed by a clamped miter is skipped (the mesh stays valid).
            let _ = mesh.add_quad([r0, r1, l1, l0], uv);
            prev = next;
        }
        along += len;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::RoadClass;
    use polis_geom::field::{Constant, FnField};
    use polis_geom::glam::Vec3;

    fn road(points: &[(f64, f64)], class: RoadClass, w: f64) -> MapRoad {
        MapRoad::new(
            points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
            class,
            w,
        )
    }

    #[test]
    fn straight_and_mitred_ribbons_have_exact_area() {
        let o = RoadSurfaceOptions::default();
        let straight = road(&[(0.0, 0.0), (100.0, 0.0)], RoadClass::Street, 8.0);
        let m = road_surfaces(&[straight], &Constant(0.0), &o, None).unwrap();
        m.validate().unwrap();
        assert_eq!(m.triangle_count(), 2 * 10, "subdivided every 10 m");
        assert!((m.surface_area() - 800.0).abs() < 1e-3);
        assert!(
            m.normals.iter().all(|n| (*n - Vec3::Y).length() < 1e-6),
            "faces up"
        );
        // An L turn (90°) and a 120° turn: miters keep area = length × width.
        for (pts, len) in [
            (vec![(0.0, 0.0), (50.0, 0.0), (50.0, 40.0)], 90.0),
            (
                vec![(0.0, 0.0), (30.0, 0.0), (15.0, 25.980762113533157)],
                60.0,
            ),
        ] {
            let r = road(&pts, RoadClass::Major, 6.0);
            let m = road_surfaces(&[r], &Constant(2.0), &o, None).unwrap();
            m.validate().unwrap();
            assert!(
                (m.surface_area() - len * 6.0).abs() < 1e-2,
                "{} vs {}",
                m.surface_area(),
                len * 6.0
            );
            let lift = 2.0 + o.lift_m + o.class_lift_m * 3.0;
            assert!(
                m.positions
                    .iter()
                    .all(|p| (f64::from(p.y) - lift).abs() < 1e-5)
            );
        }
    }

    #[test]
    fn drapes_on_terrain_and_bridges_span() {
        let o = RoadSurfaceOptions {
            max_segment_m: 5.0,
            lift_m: 0.0,
            class_lift_m: 0.0,
        };
        let slope = FnField::new(|p: DVec2| 0.1 * p.x);
        let r = road(&[(0.0, 0.0), (40.0, 0.0)], RoadClass::Street, 4.0);
        let m = road_surfaces(std::slice::from_ref(&r), &slope, &o, None).unwrap();
        m.validate().unwrap();
        for p in &m.positions {
            assert!((p.y - 0.1 * p.x).abs() < 1e-5, "{p}");
        }
        // A valley 10 m deep between x = 10 and 30: the road dips, the bridge does not.
        let valley = FnField::new(|p: DVec2| {
            if (10.0..=30.0).contains(&p.x) {
                -10.0
            } else {
                0.0
            }
        });
        let m = road_surfaces(std::slice::from_ref(&r), &valley, &o, None).unwrap();
        assert!(m.positions.iter().any(|p| p.y == -10.0));
        let bridge = MapRoad { bridge: true, ..r };
        let m = road_surfaces(&[bridge], &valley, &o, None).unwrap();
        assert!(m.positions.iter().all(|p| p.y == 0.0));
    }

    #[test]
    fn larger_classes_lie_on_top_at_crossings() {
        let o = RoadSurfaceOptions::default();
        let a = road(&[(-20.0, 0.0), (20.0, 0.0)], RoadClass::Highway, 10.0);
        let b = road(&[(0.0, -20.0), (0.0, 20.0)], RoadClass::Footpath, 2.0);
        let ha = road_surfaces(&[a], &Constant(0.0), &o, None)
            .unwrap()
            .positions[0]
            .y;
        let hb = road_surfaces(&[b], &Constant(0.0), &o, None)
            .unwrap()
            .positions[0]
            .y;
        assert!(ha > hb);
    }

    #[test]
    fn degenerate_and_bad_input() {
        let o = RoadSurfaceOptions::default();
        // Zero width, repeated points, a U-turn: no panic, valid mesh.
        let roads = [
            road(&[(0.0, 0.0), (10.0, 0.0)], RoadClass::Street, 0.0),
            road(
                &[(0.0, 0.0), (0.0, 0.0), (10.0, 0.0), (10.0, 0.0)],
                RoadClass::Street,
                3.0,
            ),
            road(
                &[(0.0, 0.0), (10.0, 0.0), (0.0, 0.0)],
                RoadClass::Street,
                3.0,
            ),
            road(
                &[(0.0, 0.0), (10.0, 0.0), (0.0, 0.5)],
                RoadClass::Street,
                3.0,
            ),
        ];
        let m = road_surfaces(&roads, &Constant(0.0), &o, None).unwrap();
        m.validate().unwrap();
        assert!(m.triangle_count() > 0);
        let nan = FnField::new(|_p: DVec2| f64::NAN);
        assert!(matches!(
            road_surfaces(&roads[1..2], &nan, &o, None),
            Err(ExportError::InvalidMap { .. })
        ));
        let bad = RoadSurfaceOptions {
            max_segment_m: 0.0,
            ..o.clone()
        };
        assert!(road_surfaces(&roads, &Constant(0.0), &bad, None).is_err());
        let nan_road = road(&[(0.0, f64::NAN), (1.0, 0.0)], RoadClass::Street, 3.0);
        assert!(road_surfaces(&[nan_road], &Constant(0.0), &o, None).is_err());
    }
}
