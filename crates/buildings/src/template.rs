//! User templates: closed meshes read from OBJ (with `tobj`) and fitted into a shape's
//! volume by the `Template(i)` module.

use polis_geom::mesh::to_world;
use polis_geom::{Aabb2, DVec2, DVec3, Mesh};

use crate::BuildingsError;
use crate::solid::add_face;

/// A template mesh: triangles in its own frame (glTF axes: Y up), fitted into the
/// current shape's box when instanced (x along the shape's frame, −z across it, y up).
#[derive(Debug, Clone, PartialEq)]
pub struct Template {
    name: String,
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    min: DVec3,
    max: DVec3,
}

impl Template {
    /// A template from positions and counter-clockwise triangles.
    ///
    /// Fails if it is empty, has an index out of range, a non-finite position, or a flat
    /// bounding box.
    pub fn from_triangles(
        name: &str,
        positions: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self, BuildingsError> {
        let err = |reason: String| BuildingsError::Template {
            name: name.to_string(),
            reason,
        };
        if triangles.is_empty() {
            return Err(err("no triangles".into()));
        }
        if triangles
            .iter()
            .flatten()
            .any(|&i| i as usize >= positions.len())
        {
            return Err(err("a triangle index is out of range".into()));
        }
        if positions.iter().any(|p| !p.is_finite()) {
            return Err(err("a position is not finite".into()));
        }
        let min = positions.iter().fold(DVec3::INFINITY, |a, &p| a.min(p));
        let max = positions.iter().fold(DVec3::NEG_INFINITY, |a, &p| a.max(p));
        if (max - min).min_element() <= 0.0 {
            return Err(err(
                "the bounding box is flat; a template must have volume".into()
            ));
        }
        Ok(Template {
            name: name.to_string(),
            positions,
            triangles,
            min,
            max,
        })
    }

    /// A template from OBJ text (all objects merged; materials ignored; polygons
    /// triangulated by `tobj`).
    #[cfg(feature = "obj")]
    pub fn from_obj_str(name: &str, obj: &str) -> Result<Self, BuildingsError> {
        let options = tobj::LoadOptions {
            triangulate: true,
            single_index: true,
            ..Default::default()
        };
        let (models, _) = tobj::load_obj_buf(&mut obj.as_bytes(), &options, |_| {
            Err(tobj::LoadError::GenericFailure)
        })
        .map_err(|e| BuildingsError::Template {
            name: name.to_string(),
            reason: format!("OBJ parse error: {e}"),
        })?;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for m in &models {
            let base = positions.len() as u32;
            positions.extend(
                m.mesh
                    .positions
                    .chunks_exact(3)
                    .map(|c| DVec3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]))),
            );
            triangles.extend(
                m.mesh
                    .indices
                    .chunks_exact(3)
                    .map(|c| [base + c[0], base + c[1], base + c[2]]),
            );
        }
        Self::from_triangles(name, positions, triangles)
    }

    /// The template's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The mesh fitted into the box spanned by `ring` in the frame with unit axis `x`
    /// (layout), from elevation `z0` to `z0 + h`.
    pub(crate) fn instance(
        &self,
        ring: &[DVec2],
        x: DVec2,
        z0: f64,
        h: f64,
    ) -> Result<Mesh, BuildingsError> {
        let y = x.perp();
        let b = Aabb2::in_frame(ring.iter().copied(), x, y);
        let (u0, u1, v0, v1) = (b.min.x, b.max.x, b.min.y, b.max.y);
        let size = self.max - self.min;
        let map = |p: DVec3| {
            let su = (p.x - self.min.x) / size.x;
            let sv = (self.max.z - p.z) / size.z;
            let sh = (p.y - self.min.y) / size.y;
            let q = x * (u0 + su * (u1 - u0)) + y * (v0 + sv * (v1 - v0));
            to_world(q, z0 + sh * h)
        };
        let world: Vec<DVec3> = self.positions.iter().map(|&p| map(p)).collect();
        let mut mesh = Mesh::with_capacity(None, 3 * self.triangles.len(), self.triangles.len());
        for t in &self.triangles {
            let pts = t.map(|i| world[i as usize]);
            // Triangles that collapse at this scale are left out (their edge partners too
            // would be degenerate); the closure check below reports any damage.
            let _ = add_face(&mut mesh, &pts);
        }
        Ok(mesh)
    }
}
