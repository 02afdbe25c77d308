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
//! * Per group its `v`, `vt` and `vn` lines, each distinct value once (OBJ indexes the
//!   three separately: the corners of a flat face share one `vn` line, and a corner shared
//!   by faces of different normals or texture coordinates one `v` line), then per mesh a
//!   `usemtl` line and its `f p/t/n p/t/n p/t/n` triangles. Values are distinct when
//!   their text differs (they are compared by their bits). Face indices are relative
//!   (negative, OBJ's "relative reference numbers": `-1` is the last value of its stream
//!   written so far), which within a group are short numbers where absolute indices grow
//!   to seven digits. `citygen`'s OBJ has 41 % fewer bytes than with one line of each
//!   per mesh vertex (395 against 674 MB), and relative indices take a further third off
//!   (see BENCHMARKS.md, "Issue 25, session 17"). Texture
//!   coordinates are converted from glTF's `v`-down convention to OBJ's `v`-up:
//!   `vt u (1 − v)`, so an image maps the same way in both files.
//! * `<stem>.mtl`: per scene material `newmtl m<index>_<name>` with `Kd` (base colour, linear
//!   RGB), `d` (alpha), `Ks`/`Ns` derived from roughness, the PBR extension lines `Pr`
//!   (roughness) and `Pm` (metallic), `map_Kd` and `map_Bump`/`norm` for the base colour
//!   and normal textures. Meshes without a material use `polis_default` (white).
//! * `<stem>_<image index>_<name>.png` per image a material uses, beside the OBJ or in
//!   the subfolder [`ObjOptions::texture_dir`] (the MTL names the relative path).
//!
//! Numbers are written exactly as Rust's `Display` writes them (shortest round-trip digits,
//! plain notation), so output is byte-identical for identical scenes, and `f32` values
//! read back exactly (a value written recently is copied from a small per-thread table of
//! texts instead of being formatted again). The text is formatted on rayon's thread pool,
//! a batch of about 256 Ki vertices at a time while the previous batch is written, each
//! batch in pieces of consecutive nodes cut by vertex count (each piece into one buffer,
//! the buffers reused batch after batch), and written in node order: the bytes do not
//! depend on the number of threads.
//!
//! [`write_obj_shared`] takes the scene's validation and texture files from a
//! [`SharedScene`] that a glb writer of the same scene shares.
//!
//! ## Limitations
//!
//! * The metallic-roughness texture is not written (MTL has no packed-channel map).
//! * Empty meshes are skipped. OBJ readers differ on group semantics; `tobj` makes one model
//!   per group and material.

use std::io::Write;

use std::collections::HashMap;

use polis_geom::Mesh;
use polis_geom::glam::{DMat3, DMat4, Vec2, Vec3};
use polis_geom::hash::FxBuild;
use polis_geom::par::{self, prelude::*};
use polis_geom::scene::{Material, Scene};

use crate::ExportError;
use crate::SharedScene;
use crate::images::sanitize;
use crate::sink::FileSink;
use crate::text::{F32Texts, push_u64};

/// Options of [`write_obj`].
#[derive(Debug, Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct ObjOptions {
    /// The stem of the side files: the MTL library is `<stem>.mtl` (named in the OBJ's
    /// `mtllib`), textures `<stem>_<image>_<name>.png`. ASCII letters, digits, `-`, `_`
    /// and `.` only. Default: `"scene"`.
    pub stem: String,
    /// A subfolder for the texture PNGs, relative to the OBJ (the MTL's `map_Kd` lines
    /// name `<texture_dir>/<file>`, and the sink receives that relative name); empty for
    /// textures beside the OBJ. Same characters as `stem`. Default: `""`.
    pub texture_dir: String,
}

impl Default for ObjOptions {
    fn default() -> Self {
        ObjOptions {
            stem: "scene".to_string(),
            texture_dir: String::new(),
        }
    }
}

/// What [`write_obj`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ObjReport {
    /// Groups (`g`), one per node that draws geometry.
    pub groups: usize,
    /// Distinct vertex positions (`v` lines).
    pub vertices: usize,
    /// Distinct texture coordinates (`vt` lines).
    pub texcoords: usize,
    /// Distinct normals (`vn` lines).
    pub normals: usize,
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
    obj: W,
    sink: &mut S,
) -> Result<ObjReport, ExportError> {
    write_obj_in_batches(&SharedScene::new(scene), options, obj, sink, BATCH_VERTICES)
}

/// [`write_obj`] of `shared`'s scene, with the scene's validation and its images' PNG
/// files taken from `shared` (computed there once for every writer that shares it: see
/// [`SharedScene`]). Same bytes as [`write_obj`].
///
/// # Errors
/// As [`write_obj`].
pub fn write_obj_shared<W: Write, S: FileSink>(
    shared: &SharedScene<'_>,
    options: &ObjOptions,
    obj: W,
    sink: &mut S,
) -> Result<ObjReport, ExportError> {
    write_obj_in_batches(shared, options, obj, sink, BATCH_VERTICES)
}

/// About how many vertices' text [`write_obj`] formats at a time.
const BATCH_VERTICES: u64 = 1 << 18;

/// [`write_obj`] with batches of about `batch_vertices` vertices (the tests vary it: the
/// bytes must not depend on it).
pub(crate) fn write_obj_in_batches<W: Write, S: FileSink>(
    shared: &SharedScene<'_>,
    options: &ObjOptions,
    mut obj: W,
    sink: &mut S,
    batch_vertices: u64,
) -> Result<ObjReport, ExportError> {
    shared.survey()?;
    let scene = shared.scene();
    let stem = &options.stem;
    let plain = |name: &str| {
        !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
            && !name.starts_with('.')
    };
    if !plain(stem) {
        return Err(ExportError::InvalidOption {
            name: "stem",
            reason: format!("{stem:?} must be non-empty ASCII letters, digits, '-', '_', '.'"),
        });
    }
    let texture_dir = &options.texture_dir;
    if !texture_dir.is_empty() && !plain(texture_dir) {
        return Err(ExportError::InvalidOption {
            name: "texture_dir",
            reason: format!(
                "{texture_dir:?} must be empty or ASCII letters, digits, '-', '_', '.'"
            ),
        });
    }
    let mtl_name = format!("{stem}.mtl");
    let mut report = ObjReport::default();

    // --- OBJ ---
    // Each node's text is formatted on its own (in parallel, in batches of bounded size)
    // and the batches are written in node order, so the bytes are those of a serial pass.
    let worlds = scene.world_matrices();
    let material_names: Vec<String> = (0..scene.materials.len())
        .map(|i| material_name(i, scene))
        .collect();
    let drawn_meshes = |i: usize| {
        scene.nodes[i]
            .meshes
            .iter()
            .map(|m| &scene.meshes[m.index()])
            .filter(|m| !m.is_empty())
    };
    // The nodes that draw geometry, with the running count of their meshes' vertices
    // (which cuts the batches); whether a drawn mesh has no material (the MTL then needs
    // the default one).
    let mut drawn: Vec<(usize, u64)> = Vec::new();
    let mut base: u64 = 1;
    let mut uses_default = false;
    for i in 0..scene.nodes.len() {
        let first = base;
        for m in drawn_meshes(i) {
            uses_default |= m.material.is_none();
            report.triangles += m.triangle_count();
            base += m.vertex_count() as u64;
        }
        if drawn_meshes(i).next().is_some() {
            drawn.push((i, first));
        }
    }
    report.groups = drawn.len();
    let mut header = Vec::new();
    (|| -> std::io::Result<()> {
        writeln!(header, "# polis-export {}", env!("CARGO_PKG_VERSION"))?;
        writeln!(
            header,
            "# metres; +Y up, right-handed (glTF axes); triangles counter-clockwise from the front"
        )?;
        writeln!(header, "mtllib {mtl_name}")
    })()
    .map_err(ExportError::io("obj"))?;
    obj.write_all(&header).map_err(ExportError::io("obj"))?;
    let mut bytes = header.len() as u64;
    // One node's text appended to `out`, welded in `g` (its arrays reused), with the
    // thread's weld maps and recent number texts.
    let node_text =
        |&(i, _): &(usize, u64), g: &mut NodeGeometry, scratch: &mut Scratch, out: &mut Vec<u8>| {
            let world = worlds.get(i).copied().unwrap_or(DMat4::IDENTITY);
            g.weld(drawn_meshes(i), &world, &mut scratch.weld);
            let mirror = DMat3::from_mat4(world).determinant() < 0.0;
            out.reserve(g.text_estimate());
            out.extend_from_slice(b"g ");
            out.extend_from_slice(sanitize(&scene.nodes[i].name, "node").as_bytes());
            out.push(b'_');
            push_u64(out, i as u64);
            out.push(b'\n');
            g.push_vertices(out, &mut scratch.texts);
            let mut corner = 0;
            for m in drawn_meshes(i) {
                out.extend_from_slice(b"usemtl ");
                match m.material.and_then(|id| material_names.get(id.index())) {
                    Some(name) => out.extend_from_slice(name.as_bytes()),
                    None => out.extend_from_slice(DEFAULT_MATERIAL.as_bytes()),
                }
                out.push(b'\n');
                g.push_faces(out, m, corner, mirror);
                corner += m.vertex_count();
            }
        };
    // Batches of about 256 Ki vertices (some tens of MiB of text): the next batch is
    // formatted on the thread pool while this thread writes the last one. A batch is cut
    // into pieces of consecutive nodes (1/32 of its vertices), formatted in parallel,
    // each into one buffer (a node's text does not depend on the nodes before it: its
    // faces index relative to its own values). The buffers of the batch written last are
    // the next batch's, so the text does not take fresh memory batch after batch. The
    // pieces are cut by vertex counts, not by threads; the streams' running counts are
    // only for the report.
    let batches = batch_bounds(&drawn, batch_vertices);
    let piece_vertices = (batch_vertices / 32).max(1);
    let format = |range: &std::ops::Range<usize>,
                  start: Counts,
                  mut buffers: Vec<Vec<u8>>|
     -> (Vec<Vec<u8>>, Counts) {
        let nodes = drawn.get(range.clone()).unwrap_or_default();
        let pieces = batch_bounds(nodes, piece_vertices);
        buffers.resize_with(pieces.len(), Vec::new);
        let counts: Vec<Counts> = pieces
            .par_iter()
            .zip(buffers.par_iter_mut())
            .map(|(piece, out)| {
                out.clear();
                SCRATCH.with_borrow_mut(|scratch| {
                    let mut g = std::mem::take(&mut scratch.geometry);
                    let mut counts = Counts::ZERO;
                    for node in nodes.get(piece.clone()).unwrap_or_default() {
                        node_text(node, &mut g, scratch, out);
                        counts = counts.plus(Counts::of(&g));
                    }
                    scratch.geometry = g;
                    counts
                })
            })
            .collect();
        let next = counts.into_iter().fold(start, Counts::plus);
        (buffers, next)
    };
    let one = Counts {
        positions: 1,
        uvs: 1,
        normals: 1,
    };
    let (mut ready, mut counts) = batches
        .first()
        .map(|r| format(r, one, Vec::new()))
        .unwrap_or((Vec::new(), one));
    let mut spare = Vec::new();
    for k in 0..batches.len() {
        let (written, next) = par::run_beside(
            || batches.get(k + 1).map(|r| format(r, counts, spare)),
            || {
                ready.iter().try_for_each(|text| {
                    bytes += text.len() as u64;
                    obj.write_all(text)
                })
            },
        );
        written.map_err(ExportError::io("obj"))?;
        if let Some((texts, after)) = next {
            spare = std::mem::replace(&mut ready, texts);
            counts = after;
        } else {
            spare = Vec::new();
            ready = Vec::new();
        }
    }
    report.vertices = (counts.positions - 1) as usize;
    report.texcoords = (counts.uvs - 1) as usize;
    report.normals = (counts.normals - 1) as usize;
    obj.flush().map_err(ExportError::io("obj"))?;
    report.bytes = bytes;

    // --- MTL and textures ---
    let mut texture_files: Vec<Option<String>> = vec![None; scene.images.len()];
    let mut file_of = |t: polis_geom::scene::TextureId| -> Option<String> {
        let image = scene.textures.get(t.index())?.image.index();
        let img = scene.images.get(image)?;
        let file = format!("{stem}_{image}_{}.png", sanitize(&img.name, "image"));
        let name = if texture_dir.is_empty() {
            file
        } else {
            format!("{texture_dir}/{file}")
        };
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
    // The used images' files, encoded in parallel (or by a writer sharing `shared`).
    let (used, names): (Vec<usize>, Vec<&String>) = texture_files
        .iter()
        .enumerate()
        .filter_map(|(i, name)| Some((i, name.as_ref()?)))
        .unzip();
    let pngs = shared.pngs(&used)?;
    for (name, png) in names.into_iter().zip(pngs) {
        sink.write_file(name, png)
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

/// Splits the drawn nodes (node, first vertex) into runs of consecutive nodes of about
/// `vertices` vertices each (a node is never split).
fn batch_bounds(drawn: &[(usize, u64)], vertices: u64) -> Vec<std::ops::Range<usize>> {
    let mut bounds = Vec::new();
    let mut start = 0;
    while let Some(&(_, first)) = drawn.get(start) {
        let end = drawn
            .iter()
            .skip(start + 1)
            .position(|&(_, f)| f - first >= vertices)
            .map_or(drawn.len(), |k| start + 1 + k);
        bounds.push(start..end);
        start = end;
    }
    bounds
}

/// The next OBJ index (1-based) of each of the three vertex streams.
#[derive(Debug, Clone, Copy)]
struct Counts {
    positions: u64,
    uvs: u64,
    normals: u64,
}

impl Counts {
    /// No values.
    const ZERO: Counts = Counts {
        positions: 0,
        uvs: 0,
        normals: 0,
    };

    /// The sum of two counts.
    fn plus(self, other: Counts) -> Counts {
        Counts {
            positions: self.positions + other.positions,
            uvs: self.uvs + other.uvs,
            normals: self.normals + other.normals,
        }
    }

    /// How many values of each stream a node writes.
    fn of(g: &NodeGeometry) -> Counts {
        Counts {
            positions: g.positions.len() as u64,
            uvs: g.uvs.len() as u64,
            normals: g.normals.len() as u64,
        }
    }
}

/// No value in a stream (a mesh without texture coordinates or normals).
const ABSENT: u32 = u32::MAX;

/// The values seen in a node so far, by the bits of their text, per stream: one set of
/// maps per thread, cleared for each node (their memory is kept).
#[derive(Default)]
struct WeldMaps {
    positions: HashMap<[u32; 3], u32, FxBuild>,
    uvs: HashMap<[u32; 2], u32, FxBuild>,
    normals: HashMap<[u32; 3], u32, FxBuild>,
}

impl WeldMaps {
    /// Empties the maps for the next node. Clearing costs the capacity, so maps a large
    /// node grew are dropped instead of being cleared for every small node after it.
    fn clear(&mut self) {
        const KEEP: usize = 1 << 12;
        if self.positions.capacity() > KEEP
            || self.uvs.capacity() > KEEP
            || self.normals.capacity() > KEEP
        {
            *self = WeldMaps::default();
        } else {
            self.positions.clear();
            self.uvs.clear();
            self.normals.clear();
        }
    }
}

/// What a thread keeps between the nodes it formats: the weld maps, the texts of the
/// numbers it wrote last, and one node's welded arrays (their memory reused).
#[derive(Default)]
struct Scratch {
    weld: WeldMaps,
    texts: F32Texts,
    geometry: NodeGeometry,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::default();
}

/// One node's geometry in world coordinates, welded: each distinct position, texture
/// coordinate and normal once (by the bits of the value written, so identical text),
/// in first-use order over the node's meshes, and for every mesh vertex its three
/// indices into them. OBJ indexes the three streams separately: a flat face's corners
/// share one normal line, and a vertex shared by faces with different normals or texture
/// coordinates still has one position line.
#[derive(Default)]
struct NodeGeometry {
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    normals: Vec<Vec3>,
    /// Per vertex of the node's meshes in order: (position, uv, normal) indices.
    corners: Vec<[u32; 3]>,
}

impl NodeGeometry {
    /// Welds the meshes of one node whose world matrix is `world`, in place of what
    /// `self` held, with the maps `seen`.
    fn weld<'a>(
        &mut self,
        meshes: impl Iterator<Item = &'a Mesh>,
        world: &DMat4,
        seen: &mut WeldMaps,
    ) {
        let identity = *world == DMat4::IDENTITY;
        let normal_matrix = DMat3::from_mat4(*world).inverse().transpose();
        self.positions.clear();
        self.uvs.clear();
        self.normals.clear();
        self.corners.clear();
        seen.clear();
        for m in meshes {
            let n = m.vertex_count();
            self.corners.reserve(n);
            let with_uvs = m.uvs.len() == n;
            let with_normals = m.normals.len() == n;
            for k in 0..n {
                let p = if identity {
                    m.positions[k]
                } else {
                    world.transform_point3(m.positions[k].as_dvec3()).as_vec3()
                };
                let ip = index_of(&mut seen.positions, &mut self.positions, p, p.to_array());
                let it = if with_uvs {
                    let t = Vec2::new(m.uvs[k].x, 1.0 - m.uvs[k].y);
                    index_of(&mut seen.uvs, &mut self.uvs, t, t.to_array())
                } else {
                    ABSENT
                };
                let inn = if with_normals {
                    let v = m.normals[k];
                    let v = if identity {
                        v.normalize_or_zero()
                    } else {
                        (normal_matrix * v.as_dvec3()).normalize_or_zero().as_vec3()
                    };
                    index_of(&mut seen.normals, &mut self.normals, v, v.to_array())
                } else {
                    ABSENT
                };
                self.corners.push([ip, it, inn]);
            }
        }
    }

    /// About how many bytes of text the node takes (vertex lines about 30 bytes a value,
    /// face lines about 50 a triangle).
    fn text_estimate(&self) -> usize {
        64 + (self.positions.len() + self.uvs.len() + self.normals.len()) * 30
            + self.corners.len() / 3 * 50
    }

    /// Appends the `v`, `vt` and `vn` lines (numbers through `texts`).
    fn push_vertices(&self, out: &mut Vec<u8>, texts: &mut F32Texts) {
        for p in &self.positions {
            push_vector(out, b"v ", &p.to_array(), texts);
        }
        for t in &self.uvs {
            push_vector(out, b"vt ", &t.to_array(), texts);
        }
        for n in &self.normals {
            push_vector(out, b"vn ", &n.to_array(), texts);
        }
    }

    /// Appends mesh `m`'s triangles, whose vertices are this node's corners from
    /// `corner` on, with indices relative to the end of each stream (`-1` is the node's
    /// last value): the node's values are the last ones written before its faces.
    fn push_faces(&self, out: &mut Vec<u8>, m: &Mesh, corner: usize, mirror: bool) {
        let own = Counts::of(self);
        let lens = [own.positions, own.uvs, own.normals];
        let relative = |out: &mut Vec<u8>, stream: usize, id: u32| {
            out.push(b'-');
            push_u64(out, lens[stream] - u64::from(id));
        };
        for [a, b, c] in m.triangles() {
            let (b, c) = if mirror { (c, b) } else { (b, c) };
            out.push(b'f');
            for k in [a, b, c] {
                let ids = self.corners[corner + k as usize];
                out.push(b' ');
                relative(out, 0, ids[0]);
                if ids[1] != ABSENT || ids[2] != ABSENT {
                    out.push(b'/');
                    if ids[1] != ABSENT {
                        relative(out, 1, ids[1]);
                    }
                    if ids[2] != ABSENT {
                        out.push(b'/');
                        relative(out, 2, ids[2]);
                    }
                }
            }
            out.push(b'\n');
        }
    }
}

/// The index of `value` (keyed by the bits of `parts`) in `values`, adding it if new.
fn index_of<T: Copy, const N: usize>(
    seen: &mut HashMap<[u32; N], u32, FxBuild>,
    values: &mut Vec<T>,
    value: T,
    parts: [f32; N],
) -> u32 {
    let next = values.len() as u32;
    let id = *seen.entry(parts.map(f32::to_bits)).or_insert(next);
    if id == next {
        values.push(value);
    }
    id
}

/// Appends `tag`, the components separated by spaces, and a newline.
fn push_vector(out: &mut Vec<u8>, tag: &[u8], v: &[f32], texts: &mut F32Texts) {
    out.extend_from_slice(tag);
    for (k, &x) in v.iter().enumerate() {
        if k > 0 {
            out.push(b' ');
        }
        texts.push(out, x);
    }
    out.push(b'\n');
}

#[cfg(test)]
pub(crate) mod tests;
