//! Wavefront OBJ + MTL writer.
//!
//! [`write_obj`] streams the scene's geometry as one OBJ file and hands the MTL library and
//! the texture PNGs to a [`FileSink`] (files beside the OBJ: [`DirSink`](crate::sink::DirSink)
//! for a folder, [`MemorySink`](crate::sink::MemorySink) in tests).
//!
//! ## What is written
//!
//! * One group (`g`) per scene node that draws geometry, named `<node name>_<node index>`
//!   (whitespace and other unsafe characters become `_`), with the node's meshes in
//!   **world coordinates** (OBJ has no hierarchy): positions by the node's world matrix,
//!   normals by its inverse transpose, triangles reversed under a mirroring transform so
//!   front faces stay counter-clockwise. A mesh drawn by several nodes is written once per
//!   node.
//! * Per mesh a `usemtl` line and `v`/`vt`/`vn` lines, then `f a/a/a b/b/b c/c/c`
//!   triangles (one shared index for position, uv and normal). Texture coordinates are
//!   converted from glTF's `v`-down convention to OBJ's `v`-up: `vt u (1 − v)`, so an image
//!   maps the same way in both files.
//! * `<stem>.mtl`: per scene material `newmtl m<index>_<name>` with `Kd` (base colour, linear
//!   RGB), `d` (alpha), `Ks`/`Ns` derived from roughness, the PBR extension lines `Pr`
//!   (roughness) and `Pm` (metallic), `map_Kd` and `map_Bump`/`norm` for the base colour
//!   and normal textures. Meshes without a material use `polis_default` (white).
//! * `<stem>_<image index>_<name>.png` per image a material uses.
//!
//! Numbers use Rust's shortest round-trip formatting, so output is byte-identical for
//! identical scenes, and `f32` values read back exactly.
//!
//! ## Limitations
//!
//! * The metallic-roughness texture is not written (MTL has no packed-channel map).
//! * Empty meshes are skipped. OBJ readers differ on group semantics; `tobj` makes one model
//!   per group and material.

use std::io::Write;

use polis_geom::Mesh;
use polis_geom::glam::{DMat3, DMat4, Vec2, Vec3};
use polis_geom::scene::{Material, Scene};
use serde::{Deserialize, Serialize};

use crate::ExportError;
use crate::images::{png_bytes, sanitize};
use crate::sink::FileSink;

/// Options of [`write_obj`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct ObjOptions {
    /// The stem of the side files: the MTL library is `<stem>.mtl` (named in the OBJ's
    /// `mtllib`), textures `<stem>_<image>_<name>.png`. ASCII letters, digits, `-`, `_`
    /// and `.` only. Default: `"scene"`.
    pub stem: String,
}

impl Default for ObjOptions {
    fn default() -> Self {
        ObjOptions {
            stem: "scene".to_string(),
        }
    }
}

/// What [`write_obj`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ObjReport {
    /// Groups (`g`), one per node that draws geometry.
    pub groups: usize,
    /// Vertices (`v`; as many `vt` and `vn`).
    pub vertices: usize,
    /// Triangles (`f`).
    pub triangles: usize,
    /// Materials in the MTL library (the default one included when used).
    pub materials: usize,
    /// Texture files written.
    pub textures: usize,
    /// Bytes of the OBJ file.
    pub bytes: u64,
}

/// The name of the material used for meshes without one.
pub const DEFAULT_MATERIAL: &str = "polis_default";

/// Writes `scene` as OBJ to `obj`, and its MTL library and textures to `sink`.
///
/// Validates the scene first ([`ExportError::InvalidScene`]: nothing written).
///
/// ```
/// use polis_export::{obj::{write_obj, ObjOptions}, sink::MemorySink};
/// use polis_export::geom::{DVec2, Polygon, Scene, mesh::prism};
/// let mut scene = Scene::new();
/// let city = scene.add_root("city");
/// let mesh = scene.add_mesh(prism(&Polygon::rect(DVec2::ZERO, DVec2::splat(10.0)).into(), 0.0, 5.0, None)?);
/// scene.attach_mesh(city, mesh)?;
/// let (mut obj, mut files) = (Vec::new(), MemorySink::new());
/// let report = write_obj(&scene, &ObjOptions::default(), &mut obj, &mut files)?;
/// assert_eq!(report.triangles, 12);
/// assert!(files.files.contains_key("scene.mtl"));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_obj<W: Write, S: FileSink>(
    scene: &Scene,
    options: &ObjOptions,
    mut obj: W,
    sink: &mut S,
) -> Result<ObjReport, ExportError> {
    scene.validate()?;
    let stem = &options.stem;
    if stem.is_empty()
        || !stem
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
        || stem.starts_with('.')
    {
        return Err(ExportError::InvalidOption {
            name: "stem",
            reason: format!("{stem:?} must be non-empty ASCII letters, digits, '-', '_', '.'"),
        });
    }
    let mtl_name = format!("{stem}.mtl");
    let mut report = ObjReport::default();

    // --- OBJ ---
    let worlds = scene.world_matrices();
    let uses_default = scene
        .nodes
        .iter()
        .flat_map(|n| &n.meshes)
        .map(|m| &scene.meshes[m.index()])
        .any(|m| m.material.is_none() && !m.is_empty());
    let mut w = Counted::new(&mut obj);
    let io = ExportError::io("obj");
    (|| -> std::io::Result<()> {
        writeln!(w, "# polis-export {}", env!("CARGO_PKG_VERSION"))?;
        writeln!(
            w,
            "# metres; +Y up, right-handed (glTF axes); triangles counter-clockwise from the front"
        )?;
        writeln!(w, "mtllib {mtl_name}")?;
        let mut base: u64 = 1;
        for (i, node) in scene.nodes.iter().enumerate() {
            let meshes: Vec<&Mesh> = node
                .meshes
                .iter()
                .map(|m| &scene.meshes[m.index()])
                .filter(|m| !m.is_empty())
                .collect();
            if meshes.is_empty() {
                continue;
            }
            report.groups += 1;
            writeln!(w, "g {}_{i}", sanitize(&node.name, "node"))?;
            let world = worlds.get(i).copied().unwrap_or(DMat4::IDENTITY);
            for m in meshes {
                match m.material {
                    Some(id) => writeln!(w, "usemtl {}", material_name(id.index(), scene))?,
                    None => writeln!(w, "usemtl {DEFAULT_MATERIAL}")?,
                }
                write_mesh(&mut w, m, &world, base)?;
                base += m.vertex_count() as u64;
                report.vertices += m.vertex_count();
                report.triangles += m.triangle_count();
            }
        }
        w.flush()
    })()
    .map_err(io)?;
    report.bytes = w.written;

    // --- MTL and textures ---
    let mut texture_files: Vec<Option<String>> = vec![None; scene.images.len()];
    let mut file_of = |t: polis_geom::scene::TextureId| -> Option<String> {
        let image = scene.textures.get(t.index())?.image.index();
        let img = scene.images.get(image)?;
        let name = format!("{stem}_{image}_{}.png", sanitize(&img.name, "image"));
        texture_files[image] = Some(name.clone());
        Some(name)
    };
    {
        let mut mtl = sink
            .create(&mtl_name)
            .map_err(ExportError::io(mtl_name.clone()))?;
        (|| -> std::io::Result<()> {
            writeln!(mtl, "# polis-export {}", env!("CARGO_PKG_VERSION"))?;
            for (i, mat) in scene.materials.iter().enumerate() {
                let base = mat.base_color_texture.and_then(&mut file_of);
                let normal = mat.normal_texture.and_then(&mut file_of);
                write_material(
                    &mut mtl,
                    &material_name(i, scene),
                    mat,
                    base.as_deref(),
                    normal.as_deref(),
                )?;
            }
            if uses_default {
                write_material(&mut mtl, DEFAULT_MATERIAL, &Material::default(), None, None)?;
            }
            mtl.flush()
        })()
        .map_err(ExportError::io(mtl_name.clone()))?;
    }
    report.materials = scene.materials.len() + usize::from(uses_default);
    for (i, name) in texture_files.iter().enumerate() {
        let (Some(name), Some(img)) = (name, scene.images.get(i)) else {
            continue;
        };
        let png = png_bytes(i, img)?;
        sink.write_file(name, &png)
            .map_err(ExportError::io(name.clone()))?;
        report.textures += 1;
    }
    Ok(report)
}

/// The MTL name of scene material `i`: unique, without whitespace.
fn material_name(i: usize, scene: &Scene) -> String {
    let name = scene.materials.get(i).map_or("", |m| m.name.as_str());
    format!("m{i}_{}", sanitize(name, "material"))
}

fn write_material(
    w: &mut dyn Write,
    name: &str,
    mat: &Material,
    base: Option<&str>,
    normal: Option<&str>,
) -> std::io::Result<()> {
    let [r, g, b, a] = mat.base_color;
    writeln!(w, "\nnewmtl {name}")?;
    writeln!(w, "Ka 0 0 0")?;
    writeln!(w, "Kd {r} {g} {b}")?;
    // A rough dielectric has a faint specular; shininess falls with roughness.
    let smooth = 1.0 - mat.roughness;
    let ks = 0.04 + 0.96 * mat.metallic;
    writeln!(w, "Ks {ks} {ks} {ks}")?;
    writeln!(w, "Ns {}", (smooth * smooth * 1000.0).max(1.0))?;
    writeln!(w, "d {a}")?;
    writeln!(w, "illum 2")?;
    writeln!(w, "Pr {}", mat.roughness)?;
    writeln!(w, "Pm {}", mat.metallic)?;
    if let Some(f) = base {
        writeln!(w, "map_Kd {f}")?;
    }
    if let Some(f) = normal {
        writeln!(w, "map_Bump {f}")?;
        writeln!(w, "norm {f}")?;
    }
    Ok(())
}

/// Writes one mesh's vertices and faces in world coordinates; `base` is the OBJ index of
/// its first vertex.
fn write_mesh<W: Write>(w: &mut W, m: &Mesh, world: &DMat4, base: u64) -> std::io::Result<()> {
    let identity = *world == DMat4::IDENTITY;
    let linear = DMat3::from_mat4(*world);
    let mirror = linear.determinant() < 0.0;
    let normal_matrix = linear.inverse().transpose();
    for p in &m.positions {
        let p = if identity {
            *p
        } else {
            world.transform_point3(p.as_dvec3()).as_vec3()
        };
        write_v3(w, "v ", p)?;
    }
    for t in &m.uvs {
        write_v2(w, "vt ", Vec2::new(t.x, 1.0 - t.y))?;
    }
    for n in &m.normals {
        let n = if identity {
            n.normalize_or_zero()
        } else {
            (normal_matrix * n.as_dvec3()).normalize_or_zero().as_vec3()
        };
        write_v3(w, "vn ", n)?;
    }
    for [a, b, c] in m.triangles() {
        let (a, b, c) = (
            base + u64::from(a),
            base + u64::from(b),
            base + u64::from(c),
        );
        let (b, c) = if mirror { (c, b) } else { (b, c) };
        writeln!(w, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")?;
    }
    Ok(())
}

fn write_v3<W: Write>(w: &mut W, tag: &str, v: Vec3) -> std::io::Result<()> {
    writeln!(w, "{tag}{} {} {}", v.x, v.y, v.z)
}

fn write_v2<W: Write>(w: &mut W, tag: &str, v: Vec2) -> std::io::Result<()> {
    writeln!(w, "{tag}{} {}", v.x, v.y)
}

/// A buffered writer that counts bytes (so the report knows the size without seeking).
struct Counted<'w, W: Write> {
    inner: std::io::BufWriter<&'w mut W>,
    written: u64,
}

impl<'w, W: Write> Counted<'w, W> {
    fn new(out: &'w mut W) -> Self {
        Counted {
            inner: std::io::BufWriter::with_capacity(1 << 16, out),
            written: 0,
        }
    }
}

impl<W: Write> Write for Counted<'_, W> {
    #[inline]
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.written += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

#[cfg(test)]
pub(crate) mod tests;
