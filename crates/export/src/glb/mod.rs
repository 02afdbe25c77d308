//! glTF 2.0 binary (`.glb`) writer.
//!
//! [`write_glb`] turns a [`Scene`] into one self-contained `.glb`: a JSON chunk built with
//! [`gltf::json`] and one binary chunk holding every vertex, index and image byte.
//!
//! ## What is written
//!
//! * Per geometry (a scene [`Mesh`], or a merged batch): accessors `POSITION` (`VEC3` f32,
//!   with `min`/`max`), `NORMAL` (`VEC3` f32, renormalised to unit length), `TEXCOORD_0`
//!   (`VEC2` f32, metres, `v` down as glTF wants), indices (`u16` when the geometry has at
//!   most 65,535 vertices, else `u32`) and, when the material has a normal texture,
//!   `TANGENT` (`VEC4` f32, Lengyel's method, handedness in `w`), each in its own buffer
//!   view with the right `target`, offsets aligned to 4 bytes. `TEXCOORD_0` is written only
//!   when the material uses it: it has a texture, or asks to keep its coordinates
//!   ([`Material::keep_texture_coordinates`], e.g. roads in metres); the Khronos validator
//!   lists unused texture coordinates otherwise.
//! * Materials: glTF metallic-roughness PBR (base colour, metallic, roughness, base colour,
//!   normal and metallic-roughness textures, double-sidedness); `alphaMode` is `BLEND` when
//!   the base colour's alpha is below 1, else `OPAQUE`. Meshes without a material use
//!   glTF's default material.
//! * Textures with deduplicated samplers; images embedded as PNG (raw RGBA pixels are
//!   encoded, PNG bytes pass through unchanged) in buffer views with `mimeType`.
//! * Only what is used: materials no written primitive draws with, textures no written
//!   material refers to and images no written texture shows are left out (and indices
//!   renumbered in scene order), so validators find no unused object.
//! * The node tree with names, transforms (`translation`/`rotation`/`scale`; a general
//!   matrix is decomposed when it is a TRS, else written as `matrix`) and the node metadata
//!   as a JSON object in `extras`; one glTF scene holding the roots.
//!
//! ## Batching
//!
//! [`Batching::PerNode`] keeps one glTF node per scene node (picking, editing); a scene
//! mesh is stored once however many nodes draw it. [`Batching::PerParentAndMaterial`]
//! merges every leaf node that draws geometry into its parent, one primitive per
//! material (few draw calls, as Citygen batched per cell); the leaves' names, metadata
//! and triangle ranges are kept in the merged mesh's `extras.objects`
//! (`[{"name", "metadata", "ranges": [[primitive, first triangle, triangle count], …]}]`).
//!
//! ## Guarantees
//!
//! * The scene is validated ([`Scene::validate`]) before anything is written; an invalid
//!   scene is never written.
//! * Streaming: the binary chunk is written straight from the scene's meshes through a
//!   small buffer, never assembled in memory (batched geometry, PNG encodings and the
//!   tangents of one geometry at a time are the only copies).
//! * Byte-identical output for identical scenes and options.
//! * The container is exactly what [`gltf::binary::Glb::to_writer`] writes for the same
//!   chunks (tested byte for byte). It is written here rather than by `Glb::to_writer`
//!   because that needs the whole binary chunk as one slice in memory and does not check
//!   the format's 4 GiB limit, which this writer does before writing anything.
//!
//! ## Limitations
//!
//! * Scene meshes without triangles and meshes no node draws are left out (counted in
//!   [`GlbReport`]): glTF forbids empty accessors.
//! * A node matrix with shear cannot be a glTF TRS; it is written as `matrix`, which the
//!   Khronos validator reports as not decomposable. Scenes built with
//!   [`Transform::Trs`] never hit this.

mod plan;
mod tangents;

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Write;

use gltf::json;
use gltf::json::validation::{Checked, USize64};
use polis_geom::Mesh;
use polis_geom::glam::{DMat4, Vec3};
use polis_geom::scene::{Filter, Material, Scene, Transform, Wrap};
use serde::{Deserialize, Serialize};

use crate::ExportError;
use crate::images::png_bytes;
use plan::Plan;

/// How scene nodes become glTF nodes and meshes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Batching {
    /// One glTF node per scene node, each with its own metadata (picking, editing).
    PerNode,
    /// Leaf nodes merged into their parent, one primitive per material (few draw calls).
    /// The default, here and in `polis::SceneConfig`.
    #[default]
    PerParentAndMaterial,
}

/// Options of [`write_glb`].
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct GlbOptions {
    /// Node structure: one node per object, or batched per parent and material.
    /// Default: [`Batching::PerParentAndMaterial`].
    pub batching: Batching,
}

/// What [`write_glb`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GlbReport {
    /// glTF nodes.
    pub nodes: usize,
    /// glTF meshes.
    pub meshes: usize,
    /// glTF primitives over all meshes.
    pub primitives: usize,
    /// Triangles stored (each stored geometry once).
    pub triangles: usize,
    /// Materials written (unused ones are left out).
    pub materials: usize,
    /// Textures written (unused ones are left out).
    pub textures: usize,
    /// Images written (unused ones are left out).
    pub images: usize,
    /// Scene meshes left out because they have no triangles.
    pub skipped_empty_meshes: usize,
    /// Scene meshes left out because no node draws them.
    pub unused_meshes: usize,
    /// Bytes written.
    pub bytes: u64,
}

/// Writes `scene` as a glTF 2.0 binary file to `out`.
///
/// Validates the scene first ([`ExportError::InvalidScene`], nothing written) and checks
/// the 4 GiB limit of the format ([`ExportError::TooLarge`], nothing written). `out` gets
/// large writes only; wrapping a file in a `BufWriter` is not needed.
///
/// ```
/// use polis_export::{glb::{write_glb, GlbOptions}, geom::{DVec2, Polygon, Scene, mesh::prism}};
/// let mut scene = Scene::new();
/// let city = scene.add_root("city");
/// let mesh = scene.add_mesh(prism(&Polygon::rect(DVec2::ZERO, DVec2::splat(10.0)).into(), 0.0, 5.0, None)?);
/// scene.attach_mesh(city, mesh)?;
/// let mut bytes = Vec::new();
/// let report = write_glb(&scene, &GlbOptions::default(), &mut bytes)?;
/// assert_eq!(report.triangles, 12);
/// let gltf = gltf::Gltf::from_slice(&bytes)?;
/// assert_eq!(gltf.meshes().count(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_glb<W: Write>(
    scene: &Scene,
    options: &GlbOptions,
    mut out: W,
) -> Result<GlbReport, ExportError> {
    scene.validate()?;
    let plan = match options.batching {
        Batching::PerNode => plan::per_node(scene),
        Batching::PerParentAndMaterial => plan::batched(scene)?,
    };
    let used = Used::new(scene, &plan);
    let pngs = used
        .images
        .iter()
        .map(|&i| png_bytes(i, &scene.images[i]))
        .collect::<Result<Vec<_>, _>>()?;
    let layout = Layout::new(scene, &plan.geometries, &pngs);
    let root = document(scene, &plan, &layout, &used)?;
    let json_bytes = json::serialize::to_vec(&root).map_err(ExportError::json("glTF JSON"))?;

    let json_len = pad4(json_bytes.len() as u64);
    let mut total = 12 + 8 + json_len;
    if layout.bin_len > 0 {
        total += 8 + layout.bin_len;
    }
    if total > u64::from(u32::MAX) {
        return Err(ExportError::TooLarge {
            format: "glb",
            bytes: total,
            limit: u64::from(u32::MAX),
        });
    }
    let io = ExportError::io("glb");
    let result = (|| -> std::io::Result<()> {
        let mut w = Chunked::new(&mut out);
        w.put(b"glTF")?;
        w.put(&2u32.to_le_bytes())?;
        w.put(&(total as u32).to_le_bytes())?;
        w.put(&(json_len as u32).to_le_bytes())?;
        w.put(b"JSON")?;
        w.put(&json_bytes)?;
        for _ in json_bytes.len() as u64..json_len {
            w.put(b" ")?;
        }
        if layout.bin_len > 0 {
            w.put(&(layout.bin_len as u32).to_le_bytes())?;
            w.put(b"BIN\0")?;
            for (g, gl) in plan.geometries.iter().zip(&layout.geometries) {
                write_geometry(&mut w, g, gl)?;
            }
            for png in &pngs {
                w.put(png)?;
                w.pad4()?;
            }
        }
        w.finish()?;
        debug_assert_eq!(w.written, total);
        out.flush()
    })();
    result.map_err(io)?;
    Ok(GlbReport {
        nodes: plan.nodes.len(),
        meshes: plan.meshes.len(),
        primitives: plan.meshes.iter().map(|m| m.primitives.len()).sum(),
        triangles: plan.geometries.iter().map(|g| g.triangle_count()).sum(),
        materials: used.materials.len(),
        textures: used.textures.len(),
        images: used.images.len(),
        skipped_empty_meshes: plan.skipped_empty_meshes,
        unused_meshes: plan.unused_meshes,
        bytes: total,
    })
}

fn pad4(n: u64) -> u64 {
    n.div_ceil(4) * 4
}

/// The materials, textures and images the written primitives use (scene indices in
/// scene order), and their new glTF indices.
struct Used {
    materials: Vec<usize>,
    textures: Vec<usize>,
    images: Vec<usize>,
    /// glTF index of each scene material / texture / image (`u32::MAX`: left out).
    material_index: Vec<u32>,
    texture_index: Vec<u32>,
    image_index: Vec<u32>,
}

impl Used {
    fn new(scene: &Scene, plan: &Plan<'_>) -> Used {
        let mut material_used = vec![false; scene.materials.len()];
        for m in &plan.meshes {
            for &(_, material) in &m.primitives {
                if let Some(u) = material.and_then(|k| material_used.get_mut(k.index())) {
                    *u = true;
                }
            }
        }
        let mut texture_used = vec![false; scene.textures.len()];
        for (mat, _) in scene
            .materials
            .iter()
            .zip(&material_used)
            .filter(|(_, u)| **u)
        {
            for t in [
                mat.base_color_texture,
                mat.normal_texture,
                mat.metallic_roughness_texture,
            ]
            .into_iter()
            .flatten()
            {
                if let Some(u) = texture_used.get_mut(t.0 as usize) {
                    *u = true;
                }
            }
        }
        let mut image_used = vec![false; scene.images.len()];
        for (tex, _) in scene
            .textures
            .iter()
            .zip(&texture_used)
            .filter(|(_, u)| **u)
        {
            if let Some(u) = image_used.get_mut(tex.image.0 as usize) {
                *u = true;
            }
        }
        let renumber = |used: &[bool]| {
            let mut list = Vec::new();
            let index = used
                .iter()
                .enumerate()
                .map(|(i, &u)| {
                    if u {
                        list.push(i);
                        list.len() as u32 - 1
                    } else {
                        u32::MAX
                    }
                })
                .collect::<Vec<u32>>();
            (list, index)
        };
        let (materials, material_index) = renumber(&material_used);
        let (textures, texture_index) = renumber(&texture_used);
        let (images, image_index) = renumber(&image_used);
        Used {
            materials,
            textures,
            images,
            material_index,
            texture_index,
            image_index,
        }
    }
}

/// Whether a geometry drawn with `material` writes `TEXCOORD_0`.
fn writes_uvs(scene: &Scene, material: Option<polis_geom::scene::MaterialId>) -> bool {
    material
        .and_then(|m| scene.materials.get(m.index()))
        .is_some_and(Material::uses_texture_coordinates)
}

/// Where one geometry's four arrays lie in the binary chunk.
#[derive(Debug)]
struct GeometryLayout {
    vertices: usize,
    indices: usize,
    wide: bool,
    min: Vec3,
    max: Vec3,
    /// Whether tangents are written (the material has a normal texture).
    tangents: bool,
    /// Whether texture coordinates are written (the material uses them).
    uvs: bool,
    /// Byte offsets of positions, normals, uvs, indices, tangents.
    offsets: [u64; 5],
    /// Byte lengths of the same.
    lengths: [u64; 5],
}

#[derive(Debug)]
struct Layout {
    geometries: Vec<GeometryLayout>,
    /// (offset, length) of each image.
    images: Vec<(u64, u64)>,
    bin_len: u64,
}

/// The largest vertex count whose indices fit `u16` (65,535 is reserved for primitive
/// restart and must not appear).
const U16_VERTEX_LIMIT: usize = 65_535;

impl Layout {
    fn new(scene: &Scene, geometries: &[Cow<'_, Mesh>], pngs: &[Cow<'_, [u8]>]) -> Layout {
        let mut off = 0u64;
        let mut out = Vec::with_capacity(geometries.len());
        for g in geometries {
            let n = g.vertex_count();
            let wide = n > U16_VERTEX_LIMIT;
            let tangents = g
                .material
                .and_then(|m| scene.materials.get(m.index()))
                .is_some_and(|m| m.normal_texture.is_some());
            let uvs = writes_uvs(scene, g.material);
            let lengths = [
                12 * n as u64,
                12 * n as u64,
                if uvs { 8 * n as u64 } else { 0 },
                g.indices.len() as u64 * if wide { 4 } else { 2 },
                if tangents { 16 * n as u64 } else { 0 },
            ];
            let mut offsets = [0; 5];
            for (o, len) in offsets.iter_mut().zip(lengths) {
                *o = off;
                off = pad4(off + len);
            }
            let b = g.bbox();
            out.push(GeometryLayout {
                vertices: n,
                indices: g.indices.len(),
                wide,
                tangents,
                uvs,
                min: b.min,
                max: b.max,
                offsets,
                lengths,
            });
        }
        let mut images = Vec::with_capacity(pngs.len());
        for p in pngs {
            images.push((off, p.len() as u64));
            off = pad4(off + p.len() as u64);
        }
        Layout {
            geometries: out,
            images,
            bin_len: off,
        }
    }
}

/// The glTF JSON document for a plan and its layout.
fn document(
    scene: &Scene,
    plan: &Plan<'_>,
    layout: &Layout,
    used: &Used,
) -> Result<json::Root, ExportError> {
    let mut root = json::Root {
        asset: json::Asset {
            generator: Some(format!("polis-export {}", env!("CARGO_PKG_VERSION"))),
            ..json::Asset::default()
        },
        ..json::Root::default()
    };
    if layout.bin_len > 0 {
        root.buffers.push(json::Buffer {
            byte_length: USize64(layout.bin_len),
            name: None,
            uri: None,
            extensions: None,
            extras: None,
        });
    }
    let view =
        |root: &mut json::Root, offset: u64, length: u64, target: Option<json::buffer::Target>| {
            root.push(json::buffer::View {
                buffer: json::Index::new(0),
                byte_length: USize64(length),
                byte_offset: Some(USize64(offset)),
                byte_stride: None,
                name: None,
                target: target.map(Checked::Valid),
                extensions: None,
                extras: None,
            })
        };
    // Three to five accessors per geometry, in order: position, normal, uv (when the
    // material uses it), indices, tangents (for normal-mapped materials).
    let mut accessors = Vec::with_capacity(layout.geometries.len());
    for gl in &layout.geometries {
        let arrays = if gl.tangents { 5 } else { 4 };
        let mut ids = [json::Index::new(0); 5];
        for (k, id) in ids.iter_mut().enumerate().take(arrays) {
            if k == 2 && !gl.uvs {
                continue;
            }
            let target = if k == 3 {
                json::buffer::Target::ElementArrayBuffer
            } else {
                json::buffer::Target::ArrayBuffer
            };
            let v = view(&mut root, gl.offsets[k], gl.lengths[k], Some(target));
            let (count, ty, component) = match k {
                0 | 1 => (
                    gl.vertices,
                    json::accessor::Type::Vec3,
                    json::accessor::ComponentType::F32,
                ),
                2 => (
                    gl.vertices,
                    json::accessor::Type::Vec2,
                    json::accessor::ComponentType::F32,
                ),
                4 => (
                    gl.vertices,
                    json::accessor::Type::Vec4,
                    json::accessor::ComponentType::F32,
                ),
                _ if gl.wide => (
                    gl.indices,
                    json::accessor::Type::Scalar,
                    json::accessor::ComponentType::U32,
                ),
                _ => (
                    gl.indices,
                    json::accessor::Type::Scalar,
                    json::accessor::ComponentType::U16,
                ),
            };
            let (min, max) = if k == 0 {
                (
                    Some(json::Value::from(gl.min.to_array().to_vec())),
                    Some(json::Value::from(gl.max.to_array().to_vec())),
                )
            } else {
                (None, None)
            };
            *id = root.push(json::Accessor {
                buffer_view: Some(v),
                byte_offset: None,
                count: USize64(count as u64),
                component_type: Checked::Valid(json::accessor::GenericComponentType(component)),
                extensions: None,
                extras: None,
                type_: Checked::Valid(ty),
                min,
                max,
                name: None,
                normalized: false,
                sparse: None,
            });
        }
        accessors.push((ids, gl.tangents, gl.uvs));
    }
    for (i, (img, &(offset, length))) in used
        .images
        .iter()
        .map(|&k| &scene.images[k])
        .zip(&layout.images)
        .enumerate()
    {
        let v = view(&mut root, offset, length, None);
        root.push(json::Image {
            buffer_view: Some(v),
            mime_type: Some(json::image::MimeType("image/png".to_string())),
            name: named(&img.name).or_else(|| Some(format!("image {i}"))),
            uri: None,
            extensions: None,
            extras: None,
        });
    }
    let mut samplers: BTreeMap<(u8, u8, u8), json::Index<json::texture::Sampler>> = BTreeMap::new();
    for tex in used.textures.iter().map(|&k| &scene.textures[k]) {
        let key = (
            wrap_key(tex.wrap_u),
            wrap_key(tex.wrap_v),
            filter_key(tex.filter),
        );
        let sampler = match samplers.get(&key) {
            Some(&s) => s,
            None => {
                let (mag, min) = match tex.filter {
                    Filter::Nearest => (
                        json::texture::MagFilter::Nearest,
                        json::texture::MinFilter::Nearest,
                    ),
                    Filter::Linear => (
                        json::texture::MagFilter::Linear,
                        json::texture::MinFilter::LinearMipmapLinear,
                    ),
                };
                let s = root.push(json::texture::Sampler {
                    mag_filter: Some(Checked::Valid(mag)),
                    min_filter: Some(Checked::Valid(min)),
                    name: None,
                    wrap_s: Checked::Valid(wrap(tex.wrap_u)),
                    wrap_t: Checked::Valid(wrap(tex.wrap_v)),
                    extensions: None,
                    extras: None,
                });
                samplers.insert(key, s);
                s
            }
        };
        root.push(json::Texture {
            name: named(&tex.name),
            sampler: Some(sampler),
            source: json::Index::new(
                used.image_index
                    .get(tex.image.0 as usize)
                    .copied()
                    .unwrap_or(u32::MAX),
            ),
            extensions: None,
            extras: None,
        });
    }
    let texture = |t: polis_geom::scene::TextureId| {
        json::Index::new(
            used.texture_index
                .get(t.0 as usize)
                .copied()
                .unwrap_or(u32::MAX),
        )
    };
    for mat in used.materials.iter().map(|&k| &scene.materials[k]) {
        let info = |t: Option<polis_geom::scene::TextureId>| {
            t.map(|t| json::texture::Info {
                index: texture(t),
                tex_coord: 0,
                extensions: None,
                extras: None,
            })
        };
        root.push(json::Material {
            alpha_mode: Checked::Valid(if mat.base_color[3] < 1.0 {
                json::material::AlphaMode::Blend
            } else {
                json::material::AlphaMode::Opaque
            }),
            double_sided: mat.double_sided,
            name: named(&mat.name),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(mat.base_color),
                base_color_texture: info(mat.base_color_texture),
                metallic_factor: json::material::StrengthFactor(mat.metallic),
                roughness_factor: json::material::StrengthFactor(mat.roughness),
                metallic_roughness_texture: info(mat.metallic_roughness_texture),
                extensions: None,
                extras: None,
            },
            normal_texture: mat.normal_texture.map(|t| json::material::NormalTexture {
                index: texture(t),
                scale: 1.0,
                tex_coord: 0,
                extensions: None,
                extras: None,
            }),
            ..json::Material::default()
        });
    }
    for m in &plan.meshes {
        let primitives = m
            .primitives
            .iter()
            .map(|&(g, material)| {
                let ([pos, nrm, uv, idx, tan], has_tangents, has_uvs) = accessors[g];
                let mut attributes = BTreeMap::from([
                    (Checked::Valid(json::mesh::Semantic::Positions), pos),
                    (Checked::Valid(json::mesh::Semantic::Normals), nrm),
                ]);
                if has_uvs {
                    attributes.insert(Checked::Valid(json::mesh::Semantic::TexCoords(0)), uv);
                }
                if has_tangents {
                    attributes.insert(Checked::Valid(json::mesh::Semantic::Tangents), tan);
                }
                json::mesh::Primitive {
                    attributes,
                    extensions: None,
                    extras: None,
                    indices: Some(idx),
                    material: material.map(|m| {
                        json::Index::new(
                            used.material_index
                                .get(m.index())
                                .copied()
                                .unwrap_or(u32::MAX),
                        )
                    }),
                    mode: Checked::Valid(json::mesh::Mode::Triangles),
                    targets: None,
                }
            })
            .collect();
        let extras = if m.objects.is_empty() {
            None
        } else {
            Some(raw(&serde_json::json!({ "objects": m.objects }))?)
        };
        root.push(json::Mesh {
            extensions: None,
            extras,
            name: named(&m.name),
            primitives,
            weights: None,
        });
    }
    for pn in &plan.nodes {
        let node = &scene.nodes[pn.source.index()];
        let mut out = json::Node {
            children: (!pn.children.is_empty())
                .then(|| pn.children.iter().map(|&c| json::Index::new(c)).collect()),
            extras: if node.metadata.is_empty() {
                None
            } else {
                Some(raw(&node.metadata)?)
            },
            mesh: pn.mesh.map(|m| json::Index::new(m as u32)),
            name: named(&node.name),
            ..json::Node::default()
        };
        set_transform(&mut out, &node.transform);
        root.push(out);
    }
    // glTF forbids a scene without nodes: a scene without roots has no glTF scene.
    if !plan.roots.is_empty() {
        let scene_index = root.push(json::Scene {
            extensions: None,
            extras: None,
            name: Some("polis".to_string()),
            nodes: plan.roots.iter().map(|&r| json::Index::new(r)).collect(),
        });
        root.scene = Some(scene_index);
    }
    Ok(root)
}

fn named(name: &str) -> Option<String> {
    (!name.is_empty()).then(|| name.to_string())
}

fn raw<T: Serialize + ?Sized>(value: &T) -> Result<Box<serde_json::value::RawValue>, ExportError> {
    serde_json::value::to_raw_value(value).map_err(ExportError::json("extras"))
}

fn wrap(w: Wrap) -> json::texture::WrappingMode {
    match w {
        Wrap::Repeat => json::texture::WrappingMode::Repeat,
        Wrap::MirroredRepeat => json::texture::WrappingMode::MirroredRepeat,
        Wrap::ClampToEdge => json::texture::WrappingMode::ClampToEdge,
    }
}

fn wrap_key(w: Wrap) -> u8 {
    match w {
        Wrap::Repeat => 0,
        Wrap::MirroredRepeat => 1,
        Wrap::ClampToEdge => 2,
    }
}

fn filter_key(f: Filter) -> u8 {
    match f {
        Filter::Nearest => 0,
        Filter::Linear => 1,
    }
}

/// Relative tolerance under which a matrix counts as a TRS composition.
const TRS_TOLERANCE: f64 = 1e-9;

fn set_transform(node: &mut json::Node, t: &Transform) {
    let (translation, rotation, scale) = match *t {
        Transform::Trs {
            translation,
            rotation,
            scale,
        } => (translation, rotation, scale),
        Transform::Matrix(m) => {
            let (s, r, tr) = m.to_scale_rotation_translation();
            let back = DMat4::from_scale_rotation_translation(s, r, tr);
            let size = m.to_cols_array().iter().fold(1.0f64, |a, x| a.max(x.abs()));
            let err = (back - m)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |a, x| a.max(x.abs()));
            if err.is_nan() || err > TRS_TOLERANCE * size {
                node.matrix = Some(m.as_mat4().to_cols_array());
                return;
            }
            (tr, r, s)
        }
    };
    let translation = translation.as_vec3();
    if translation != Vec3::ZERO {
        node.translation = Some(translation.to_array());
    }
    let rotation = rotation.as_quat().normalize();
    if rotation != polis_geom::glam::Quat::IDENTITY && rotation.is_finite() {
        node.rotation = Some(json::scene::UnitQuaternion(rotation.to_array()));
    }
    let scale = scale.as_vec3();
    if scale != Vec3::ONE {
        node.scale = Some(scale.to_array());
    }
}

/// Buffered little-endian output that counts bytes.
struct Chunked<'w, W: Write> {
    out: &'w mut W,
    buf: Vec<u8>,
    written: u64,
}

const CHUNK: usize = 1 << 16;

impl<'w, W: Write> Chunked<'w, W> {
    fn new(out: &'w mut W) -> Self {
        Chunked {
            out,
            buf: Vec::with_capacity(CHUNK + 64),
            written: 0,
        }
    }

    #[inline]
    fn put(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        if self.buf.len() + bytes.len() > CHUNK {
            self.drain()?;
            if bytes.len() > CHUNK {
                self.written += bytes.len() as u64;
                return self.out.write_all(bytes);
            }
        }
        self.buf.extend_from_slice(bytes);
        self.written += bytes.len() as u64;
        Ok(())
    }

    fn pad4(&mut self) -> std::io::Result<()> {
        while !self.written.is_multiple_of(4) {
            self.put(&[0])?;
        }
        Ok(())
    }

    fn drain(&mut self) -> std::io::Result<()> {
        if !self.buf.is_empty() {
            self.out.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }

    fn finish(&mut self) -> std::io::Result<()> {
        self.drain()
    }
}

fn write_geometry<W: Write>(
    w: &mut Chunked<'_, W>,
    g: &Mesh,
    gl: &GeometryLayout,
) -> std::io::Result<()> {
    // 12 (header) + 8 + json + 8 (bin header) is a multiple of 4, so relative alignment
    // in the chunk equals absolute alignment in the file; pad after each array.
    for p in &g.positions {
        let mut b = [0u8; 12];
        b[0..4].copy_from_slice(&p.x.to_le_bytes());
        b[4..8].copy_from_slice(&p.y.to_le_bytes());
        b[8..12].copy_from_slice(&p.z.to_le_bytes());
        w.put(&b)?;
    }
    w.pad4()?;
    for n in &g.normals {
        let n = n.normalize_or_zero();
        let mut b = [0u8; 12];
        b[0..4].copy_from_slice(&n.x.to_le_bytes());
        b[4..8].copy_from_slice(&n.y.to_le_bytes());
        b[8..12].copy_from_slice(&n.z.to_le_bytes());
        w.put(&b)?;
    }
    w.pad4()?;
    if gl.uvs {
        for t in &g.uvs {
            let mut b = [0u8; 8];
            b[0..4].copy_from_slice(&t.x.to_le_bytes());
            b[4..8].copy_from_slice(&t.y.to_le_bytes());
            w.put(&b)?;
        }
        w.pad4()?;
    }
    if gl.wide {
        for &i in &g.indices {
            w.put(&i.to_le_bytes())?;
        }
    } else {
        for &i in &g.indices {
            w.put(&(i as u16).to_le_bytes())?;
        }
    }
    w.pad4()?;
    if gl.tangents {
        for t in tangents::tangents(g) {
            let mut b = [0u8; 16];
            for (k, c) in t.to_array().into_iter().enumerate() {
                b[4 * k..4 * k + 4].copy_from_slice(&c.to_le_bytes());
            }
            w.put(&b)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
