//! Footpath meshes: the strip between a block's boundary (the kerb, along the road) and
//! its inset (the edge of the lots), raised by a kerb's height and draped on the terrain.
//!
//! [`footpath_mesh`] takes one strip as a plain [`PolygonWithHoles`]: its outer ring is
//! the kerb line, its holes the inner edges. This is exactly one of the
//! `Block::footpath.strips` that `polis-lots` builds (a block with a courtyard gives a
//! strip whose outer ring is the courtyard's inner edge: every ring of a strip gets the
//! same treatment, so that works too). Taking the polygon rather than the block keeps
//! `polis-export` free of the stage crates (see ARCHITECTURE.md).
//!
//! The mesh has:
//!
//! * a **top** at `terrain + lift_m + kerb_height_m`, the strip triangulated with
//!   [`triangulate`] after its edges were split every
//!   [`FootpathOptions::max_segment_m`] (so it follows the terrain), smooth normals;
//! * **side faces** along every ring (the kerb towards the road, the step down to the
//!   lots), from `terrain + lift_m − skirt_m` (just under the road surface, so no gap
//!   shows) up to the top, facing away from the strip;
//! * with [`FootpathOptions::closed`], a **bottom**, so the strip is a closed,
//!   outward-facing solid ([`Mesh::check_closed`] holds) for collision or booleans.
//!
//! Texture coordinates are metres: the top and bottom use the layout position (`(x, −y)`
//! from above, `(x, y)` from below), the sides `u` along the ring and `v` up the face.

use polis_geom::field::Field;
use polis_geom::glam::DVec3;
use polis_geom::mesh::{to_world, triangulate};
use polis_geom::scene::MaterialId;
use polis_geom::{DVec2, MAX_COORDINATE, Mesh, Polygon, PolygonWithHoles};

use crate::ExportError;

/// Options of [`footpath_mesh`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct FootpathOptions {
    /// Height of the kerb above the road surface, metres (finite, > 0). Default: 0.15.
    pub kerb_height_m: f64,
    /// Height of the road surface above the terrain, metres (finite); use the same value
    /// as [`RoadSurfaceOptions::lift_m`](crate::surfaces::RoadSurfaceOptions::lift_m).
    /// Default: 0.05.
    pub lift_m: f64,
    /// How far the side faces reach below the road surface, metres (finite, ≥ 0), so no
    /// gap opens where the terrain bends between samples. Default: 0.05.
    pub skirt_m: f64,
    /// Longest ring edge between two terrain samples, metres (finite, > 0). Default: 10.0.
    pub max_segment_m: f64,
    /// Whether to add the bottom face, making each strip a closed solid. Default: true.
    pub closed: bool,
}

impl Default for FootpathOptions {
    fn default() -> Self {
        FootpathOptions {
            kerb_height_m: 0.15,
            lift_m: 0.05,
            skirt_m: 0.05,
            max_segment_m: 10.0,
            closed: true,
        }
    }
}

impl FootpathOptions {
    fn validate(&self) -> Result<(), ExportError> {
        let bad = |name: &'static str, v: f64, want: &str| ExportError::InvalidOption {
            name,
            reason: format!("{v} m; it must be {want}"),
        };
        if !(self.kerb_height_m.is_finite() && self.kerb_height_m > 0.0) {
            return Err(bad("kerb_height_m", self.kerb_height_m, "finite and > 0"));
        }
        if !self.lift_m.is_finite() {
            return Err(bad("lift_m", self.lift_m, "finite"));
        }
        if !(self.skirt_m.is_finite() && self.skirt_m >= 0.0) {
            return Err(bad("skirt_m", self.skirt_m, "finite and ≥ 0"));
        }
        if !(self.max_segment_m.is_finite() && self.max_segment_m > 0.0) {
            return Err(bad("max_segment_m", self.max_segment_m, "finite and > 0"));
        }
        Ok(())
    }
}

/// Builds the kerb-high mesh of one footpath strip (outer ring = the kerb line at the
/// road, holes = the inner edges), draped on `elevation`, with `material`.
///
/// Either orientation is accepted. Fails with [`ExportError::InvalidMap`] if the strip is
/// not a valid polygon with holes or the elevation field is not finite on it,
/// [`ExportError::InvalidOption`] on options out of range; nothing is built then.
///
/// ```
/// use polis_export::footpaths::{footpath_mesh, FootpathOptions};
/// use polis_export::geom::{DVec2, Polygon, PolygonWithHoles, field::Constant};
/// // A 2.5 m footpath around a 40 m × 30 m block.
/// let kerb = Polygon::rect(DVec2::ZERO, DVec2::new(40.0, 30.0));
/// let inner = Polygon::rect(DVec2::new(2.5, 2.5), DVec2::new(37.5, 27.5));
/// let strip = PolygonWithHoles::new(kerb, vec![inner]);
/// let mesh = footpath_mesh(&strip, &Constant(0.0), &FootpathOptions::default(), None)?;
/// mesh.validate()?;
/// mesh.check_closed()?;
/// let volume = strip.area() * (0.15 + 0.05);
/// assert!((mesh.signed_volume() - volume).abs() < 1e-3);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn footpath_mesh(
    strip: &PolygonWithHoles,
    elevation: &dyn Field,
    options: &FootpathOptions,
    material: Option<MaterialId>,
) -> Result<Mesh, ExportError> {
    let mut mesh = Mesh::new(material);
    add_footpath(&mut mesh, strip, elevation, options)?;
    Ok(mesh)
}

/// [`footpath_mesh`] for many strips (all blocks of a city), into one mesh with
/// `material`. Fails on the first invalid strip, naming its index.
pub fn footpath_meshes(
    strips: &[PolygonWithHoles],
    elevation: &dyn Field,
    options: &FootpathOptions,
    material: Option<MaterialId>,
) -> Result<Mesh, ExportError> {
    let mut mesh = Mesh::new(material);
    for (i, strip) in strips.iter().enumerate() {
        add_footpath(&mut mesh, strip, elevation, options).map_err(|e| match e {
            ExportError::InvalidMap { what, reason } => ExportError::InvalidMap {
                what: format!("{what} (strip {i})"),
                reason,
            },
            other => other,
        })?;
    }
    Ok(mesh)
}

/// Appends one strip to `mesh`; on error the mesh is unchanged.
fn add_footpath(
    mesh: &mut Mesh,
    strip: &PolygonWithHoles,
    elevation: &dyn Field,
    o: &FootpathOptions,
) -> Result<(), ExportError> {
    o.validate()?;
    let invalid = |e: polis_geom::GeomError| {
        ExportError::map(
            "footpath strip",
            format!("{e}; give a simple outer ring (the kerb) with simple holes inside"),
        )
    };
    // Coordinates first (they bound the subdivision); `triangulate` validates the rest.
    for (_, ring) in strip.rings() {
        if let Some(p) = ring
            .points()
            .iter()
            .find(|p| !(p.is_finite() && p.abs().max_element() <= MAX_COORDINATE))
        {
            return Err(ExportError::map(
                "footpath strip",
                format!("the point {p} is not finite or beyond ±{MAX_COORDINATE} m"),
            ));
        }
    }
    let mut strip = strip.clone();
    strip.normalize();
    let split = PolygonWithHoles::new(
        subdivide(&strip.outer, o.max_segment_m),
        strip
            .holes
            .iter()
            .map(|h| subdivide(h, o.max_segment_m))
            .collect(),
    );
    let triangles = triangulate(&split).map_err(invalid)?;
    // One layout point per vertex, ring by ring, and its ground height.
    let points: Vec<DVec2> = split
        .rings()
        .flat_map(|(_, r)| r.points().iter().copied())
        .collect();
    let mut ground = Vec::with_capacity(points.len());
    for &p in &points {
        let h = elevation.sample(p);
        if !h.is_finite() {
            return Err(ExportError::map(
                "footpath strip",
                format!("the elevation field is {h} at {p}; it must be finite"),
            ));
        }
        ground.push(h);
    }
    let top: Vec<DVec3> = points
        .iter()
        .zip(&ground)
        .map(|(&p, &h)| to_world(p, h + o.lift_m + o.kerb_height_m))
        .collect();
    let base: Vec<DVec3> = points
        .iter()
        .zip(&ground)
        .map(|(&p, &h)| to_world(p, h + o.lift_m - o.skirt_m))
        .collect();
    let mut out = Mesh::new(mesh.material);
    add_cap(&mut out, &top, &points, &triangles, false)?;
    if o.closed {
        add_cap(&mut out, &base, &points, &triangles, true)?;
    }
    let mut start = 0;
    for (_, ring) in split.rings() {
        let n = ring.len();
        let mut along = 0.0;
        for k in 0..n {
            let (a, b) = (start + k, start + (k + 1) % n);
            let len = (points[b] - points[a]).length();
            let rise_a = top[a].y - base[a].y;
            let rise_b = top[b].y - base[b].y;
            // The strip lies left of every ring edge: the face looks right, outwards.
            out.add_quad(
                [base[a], base[b], top[b], top[a]],
                [
                    DVec2::new(along, 0.0),
                    DVec2::new(along + len, 0.0),
                    DVec2::new(along + len, rise_b),
                    DVec2::new(along, rise_a),
                ],
            )?;
            along += len;
        }
        start += n;
    }
    out.validate()?;
    mesh.append(&out);
    Ok(())
}

/// The ring with every edge longer than `max` split into equal pieces.
fn subdivide(ring: &Polygon, max: f64) -> Polygon {
    let mut out = Vec::with_capacity(ring.len());
    for (a, b) in ring.edges() {
        out.push(a);
        let pieces = ((b - a).length() / max).ceil();
        if pieces > 1.0 && pieces.is_finite() {
            let n = pieces as usize;
            for k in 1..n {
                out.push(a.lerp(b, k as f64 / n as f64));
            }
        }
    }
    Polygon::new(out)
}

/// A horizontal-ish face over `triangles` at the given world positions, smooth normals,
/// facing up (or down with `flip`).
fn add_cap(
    mesh: &mut Mesh,
    world: &[DVec3],
    layout: &[DVec2],
    triangles: &[[u32; 3]],
    flip: bool,
) -> Result<(), ExportError> {
    let mut normals = vec![DVec3::ZERO; world.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| world[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    let base = mesh.vertex_count() as u32;
    for ((&w, &p), n) in world.iter().zip(layout).zip(&normals) {
        let n = n.normalize_or(DVec3::Y);
        let (n, uv) = if flip {
            (-n, DVec2::new(p.x, p.y))
        } else {
            (n, DVec2::new(p.x, -p.y))
        };
        mesh.add_vertex(w, n, uv);
    }
    for &[a, b, c] in triangles {
        let (b, c) = if flip { (c, b) } else { (b, c) };
        mesh.push_triangle(base + a, base + b, base + c)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::field::{Constant, FnField};
    use proptest::prelude::*;

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Polygon {
        Polygon::rect(DVec2::new(x0, y0), DVec2::new(x1, y1))
    }

    fn block_strip() -> PolygonWithHoles {
        PolygonWithHoles::new(rect(0.0, 0.0, 40.0, 30.0), vec![rect(2.5, 2.5, 37.5, 27.5)])
    }

    #[test]
    fn closed_outward_solid_with_kerb_and_metre_uvs() {
        let o = FootpathOptions::default();
        let strip = block_strip();
        let m = footpath_mesh(&strip, &Constant(3.0), &o, None).unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        let h = o.kerb_height_m + o.skirt_m;
        assert!((m.signed_volume() - strip.area() * h).abs() < 1e-3);
        // The top is at terrain + lift + kerb, the base just under the road surface.
        let ys: Vec<f32> = m.positions.iter().map(|p| p.y).collect();
        let top = (3.0 + o.lift_m + o.kerb_height_m) as f32;
        let base = (3.0 + o.lift_m - o.skirt_m) as f32;
        assert!(
            ys.iter()
                .all(|&y| (y - top).abs() < 1e-6 || (y - base).abs() < 1e-6)
        );
        // Top faces up, side faces horizontal, bottom faces down.
        assert!(m.normals.iter().any(|n| n.y > 0.99));
        assert!(m.normals.iter().any(|n| n.y < -0.99));
        assert!(m.normals.iter().any(|n| n.y.abs() < 1e-6));
        // Side faces: u along the ring up to its perimeter, v up to the kerb + skirt.
        let max_u = m.uvs.iter().map(|uv| uv.x).fold(0.0f32, f32::max);
        assert!((max_u - 140.0).abs() < 1e-3, "{max_u}");
        assert!(m.uvs.iter().any(|uv| (uv.y - h as f32).abs() < 1e-5));
        // Split every 10 m: the 40 m kerb edges have 4 pieces.
        let open = FootpathOptions {
            closed: false,
            ..o.clone()
        };
        let m = footpath_mesh(&strip, &Constant(0.0), &open, None).unwrap();
        m.validate().unwrap();
        assert!(!m.is_closed());
        let kerb_quads = 2 * (4 + 3) + 2 * (4 + 3);
        assert_eq!(
            m.triangle_count() - triangulate(&split(&strip)).unwrap().len(),
            2 * kerb_quads
        );
    }

    fn split(s: &PolygonWithHoles) -> PolygonWithHoles {
        PolygonWithHoles::new(
            subdivide(&s.outer, 10.0),
            s.holes.iter().map(|h| subdivide(h, 10.0)).collect(),
        )
    }

    #[test]
    fn drapes_and_rejects_bad_input() {
        let o = FootpathOptions::default();
        let slope = FnField::new(|p: DVec2| 0.2 * p.x - 0.1 * p.y);
        // Clockwise input is normalised.
        let mut strip = block_strip();
        strip.outer.reverse();
        let m = footpath_mesh(&strip, &slope, &o, None).unwrap();
        m.validate().unwrap();
        m.check_closed().unwrap();
        assert!(m.signed_volume() > 0.0);
        for (p, n) in m.positions.iter().zip(&m.normals) {
            let ground = 0.2 * p.x + 0.1 * p.z;
            let up = f64::from(p.y) - f64::from(ground);
            assert!(
                (up - 0.2).abs() < 1e-4 || up.abs() < 1e-4,
                "{p}: {up} above ground"
            );
            assert!(n.is_finite());
        }
        let nan = FnField::new(|_p: DVec2| f64::NAN);
        assert!(matches!(
            footpath_mesh(&block_strip(), &nan, &o, None),
            Err(ExportError::InvalidMap { .. })
        ));
        let bow = PolygonWithHoles::new(
            Polygon::new(vec![
                DVec2::ZERO,
                DVec2::new(1.0, 1.0),
                DVec2::new(1.0, 0.0),
                DVec2::new(0.0, 1.0),
            ]),
            Vec::new(),
        );
        assert!(footpath_mesh(&bow, &Constant(0.0), &o, None).is_err());
        let bad = FootpathOptions {
            kerb_height_m: 0.0,
            ..o.clone()
        };
        assert!(footpath_mesh(&block_strip(), &Constant(0.0), &bad, None).is_err());
        // Many strips in one mesh; the failing one is named.
        let strips = [block_strip(), bow];
        let err = footpath_meshes(&strips, &Constant(0.0), &o, None).unwrap_err();
        assert!(err.to_string().contains("strip 1"), "{err}");
        let m = footpath_meshes(&strips[..1], &Constant(0.0), &o, None).unwrap();
        m.check_closed().unwrap();
    }

    #[cfg(all(feature = "gltf", feature = "obj"))]
    #[test]
    fn roads_and_footpaths_export_to_glb_and_obj() {
        use crate::map::{MapRoad, RoadClass};
        use crate::surfaces::{RoadSurfaceOptions, road_surfaces};
        use polis_geom::scene::{Material, Scene};
        // A block between four streets, its footpath, on a slope.
        let slope = FnField::new(|p: DVec2| 0.05 * p.x);
        let c = [(0.0, 0.0), (50.0, 0.0), (50.0, 40.0), (0.0, 40.0)].map(|(x, y)| DVec2::new(x, y));
        let roads: Vec<MapRoad> = (0..4)
            .map(|k| MapRoad::new(vec![c[k], c[(k + 1) % 4]], RoadClass::Street, 8.0))
            .collect();
        let strip =
            PolygonWithHoles::new(rect(4.0, 4.0, 46.0, 36.0), vec![rect(6.5, 6.5, 43.5, 33.5)]);
        let mut scene = Scene::new();
        // Road and footpath surfaces keep their metre texture coordinates.
        let asphalt = scene.add_material(Material {
            keep_texture_coordinates: true,
            ..Material::new("asphalt", [0.2, 0.2, 0.2, 1.0])
        });
        let paving = scene.add_material(Material {
            keep_texture_coordinates: true,
            ..Material::new("paving", [0.7, 0.7, 0.65, 1.0])
        });
        let road = road_surfaces(
            &roads,
            &slope,
            &RoadSurfaceOptions::default(),
            Some(asphalt),
        )
        .unwrap();
        let path =
            footpath_mesh(&strip, &slope, &FootpathOptions::default(), Some(paving)).unwrap();
        let (rt, pt) = (road.triangle_count(), path.triangle_count());
        let root = scene.add_root("city");
        for (name, mesh) in [("roads", road), ("footpaths", path)] {
            let node = scene.add_node(root, name).unwrap();
            let id = scene.add_mesh(mesh);
            scene.attach_mesh(node, id).unwrap();
        }
        let mut glb = Vec::new();
        let per_node = crate::glb::GlbOptions::with_batching(crate::glb::Batching::PerNode);
        crate::glb::write_glb(&scene, &per_node, &mut glb).unwrap();
        let doc = crate::testing::decode_glb(&glb);
        assert_eq!((doc.meshes, doc.materials), (2, 2));
        let tris: Vec<usize> = doc
            .prims
            .iter()
            .flatten()
            .map(|p| p.indices.len() / 3)
            .collect();
        assert_eq!(tris, vec![rt, pt]);
        assert!(
            doc.prims
                .iter()
                .flatten()
                .all(|p| p.uvs.len() == p.positions.len())
        );
        let (mut obj, mut files) = (Vec::new(), crate::sink::MemorySink::new());
        crate::obj::write_obj(&scene, &Default::default(), &mut obj, &mut files).unwrap();
        let (models, _) = crate::obj::tests::load(&obj, &files);
        let faces: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
        assert_eq!(faces, rt + pt);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

        /// Star-shaped blocks (convex and concave, tiny to huge, far from the origin) with a
        /// footpath ring: always a valid closed outward solid of the strip's area × height.
        #[test]
        fn strips_give_closed_solids(
            radii in prop::collection::vec(20.0..60.0f64, 3..12),
            width in prop_oneof![Just(0.5), 1.0..5.0f64],
            offset in prop_oneof![Just(0.0), Just(1e4)],
            tilt in -0.3..0.3f64,
        ) {
            let n = radii.len();
            let ring = |inset: f64| -> Polygon {
                Polygon::new((0..n).map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    DVec2::new(a.cos(), a.sin()) * (radii[k] - inset) + DVec2::splat(offset)
                }).collect())
            };
            let mut hole = ring(width * 2.0);
            hole.make_cw();
            let strip = PolygonWithHoles::new(ring(0.0), vec![hole]);
            prop_assume!(strip.validate().is_ok());
            let terrain = FnField::new(move |p: DVec2| tilt * (p.x - offset));
            let o = FootpathOptions::default();
            let m = footpath_mesh(&strip, &terrain, &o, None).unwrap();
            prop_assert!(m.validate().is_ok());
            prop_assert!(m.check_closed().is_ok());
            if offset == 0.0 {
                let want = strip.area() * (o.kerb_height_m + o.skirt_m);
                prop_assert!((m.signed_volume() - want).abs() < 1e-3 * want.max(1.0));
            }
        }
    }
}
