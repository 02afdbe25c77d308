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
//!   `TANGENT` (`VEC4` f32, Lengyel's method, handedness in `w`). `TEXCOORD_0` is written
//!   only when the material uses it: it has a texture, or asks to keep its coordinates
//!   ([`Material::keep_texture_coordinates`], e.g. roads in metres); the Khronos validator
//!   lists unused texture coordinates otherwise.
//! * Buffer views shared by many accessors: consecutive glTF meshes form a batch (closed
//!   after the mesh that brings it to 8,192 vertices, so a large tile has its own) and
//!   each batch stores its arrays in one view per kind, back to back, each accessor at
//!   its `byteOffset`: vertex attributes of one `byteStride` (and, in the web profile,
//!   one meshopt filter) share a view, indices of one size another. Views start on
//!   4 bytes, vertex attributes are 4-byte aligned and indices aligned to their size.
//!   A few hundred view objects instead of one per array keep the JSON small (the
//!   default city: 669 views for 8,672 accessors).
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
//! ## Layouts ([`Batching`])
//!
//! [`Batching::Tiled`] (the default) merges geometry per scene root, layer, square tile
//! ([`GlbOptions::tile_size_m`]) and LOD level, one primitive per material: the node tree
//! is `root → layer (roads, blocks, buildings, water, ground, …) → "<layer> i,j" tile →
//! ("… lod k" level)`, so draw calls are about materials × tiles and a game can hide,
//! stream or collide each layer tile by tile. Layers, LOD levels and feature records
//! come from node metadata (`layer`, `lod`, anything else): see `tiles` for the rules.
//! Every merged vertex of an object carries `_FEATURE_ID_0` (an application attribute in
//! the style of `EXT_mesh_features`: `u16` with a stride of 4, or `f32` past 65,535
//! records), the index of its record in the root node's `extras.features` table
//! (`name`, `layer` and the node's metadata: a polis building's `id` as text and number,
//! `kind`, `height`, `floors`, `lot`, `style`, …). Vertex attributes survive optimisers
//! that reorder, merge or re-index triangles, where triangle ranges do not. LOD nodes
//! carry `extras.lod` and `extras.lod_range_m = [near, far]` (`far` null: to infinity),
//! the camera distances between which an engine should draw them. The root's extras
//! also hold `layers` (the names of its layer nodes, in their order), `tile_size_m`,
//! `null_feature_id` (the id of geometry that belongs to no record) and, with LOD
//! nodes, `lod_levels` (finest first).
//!
//! [`Batching::PerNode`] keeps one glTF node per scene node (picking, editing); meshes
//! with identical bytes are stored once however many nodes draw them.
//! [`Batching::PerParentAndMaterial`] merges every leaf node that draws geometry into its
//! parent, one primitive per material (one mesh per cell, as Citygen batched); the
//! leaves' names, metadata and triangle ranges are kept in the merged mesh's
//! `extras.objects` (`[{"name", "metadata", "ranges": [[primitive, first triangle,
//! triangle count], …]}]`).
//!
//! ## Profiles ([`GlbProfile`])
//!
//! [`GlbProfile::Plain`] (the default) is core glTF 2.0 without extensions.
//! [`GlbProfile::Web`] quantizes (`KHR_mesh_quantization`) and compresses
//! (`EXT_meshopt_compression`, normals and tangents through its octahedral filter) the
//! vertex and index arrays, and re-encodes the textures as smaller PNG files (a
//! resolution cap, [`GlbOptions::web_texture_max_px`], then the smallest lossless colour
//! type: palette, RGB or RGBA); see `web` for the grids and why both extensions are then
//! required, and `web_images` for the textures. Its tiled feature table is written by
//! column, a third smaller for a city: `extras.features` is an object of equally long
//! arrays, one per key of any record (`{"id": ["0", …], "height": [51.77, …], …}`, keys
//! sorted, `null` where a record lacks the key, whole numbers without a fraction), so
//! record `i` is `{k: features[k][i]}`.
//!
//! ## Instancing
//!
//! [`GlbOptions::gpu_instancing`] (off by default) turns sibling leaves of the per-node
//! layout that draw one mesh into one node with `EXT_mesh_gpu_instancing` (listed as used,
//! not required); see `instancing`.
//!
//! ## Guarantees
//!
//! * The scene is validated ([`Scene::validate`]) before anything is written; an invalid
//!   scene is never written.
//! * Streaming: the binary chunk is written straight from the scene's meshes through a
//!   small buffer, never assembled in memory (the per-parent batches, PNG encodings and
//!   the tangents of one geometry at a time are the only copies: the tiled layout's
//!   merged geometries are streamed piece by piece from the scene's meshes; the web
//!   profile holds its compressed streams).
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

mod instancing;
mod layout;
mod options;
mod plan;
mod tangents;
mod tiles;
#[cfg(feature = "web")]
mod web;
#[cfg(feature = "web")]
mod web_images;

pub use options::{Batching, GlbOptions, GlbProfile};

use std::collections::BTreeMap;
use std::io::Write;

use gltf::json;
use gltf::json::validation::{Checked, USize64};
use polis_geom::glam::{DMat4, Vec3};
use polis_geom::scene::{Filter, Scene, Transform, Wrap};
#[cfg(feature = "serde")]
use serde::Serialize;

use crate::ExportError;
use crate::SharedScene;
use layout::{Chunked, Layout, Slot, pad4, write_view};
use plan::Plan;
use std::borrow::Cow;

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
    /// Draw calls of the whole file: the primitives of every node's mesh, summed over
    /// nodes (every LOD level counted; an engine draws one level per tile at a time).
    pub draw_calls: usize,
    /// Records in the feature tables ([`Batching::Tiled`]).
    pub features: usize,
    /// Tile nodes ([`Batching::Tiled`]).
    pub tiles: usize,
    /// Stored geometries drawn by two or more nodes (shared, not copied).
    pub shared_geometries: usize,
    /// Instances drawn through `EXT_mesh_gpu_instancing` ([`GlbOptions::gpu_instancing`]).
    pub instances: usize,
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
    out: W,
) -> Result<GlbReport, ExportError> {
    write_glb_shared(&SharedScene::new(scene), options, out)
}

/// [`write_glb`] of `shared`'s scene, with the scene's validation and its images' PNG
/// files taken from `shared` (computed there once for every writer that shares it: see
/// [`SharedScene`]). Same bytes as [`write_glb`].
///
/// # Errors
/// As [`write_glb`].
pub fn write_glb_shared<W: Write>(
    shared: &SharedScene<'_>,
    options: &GlbOptions,
    mut out: W,
) -> Result<GlbReport, ExportError> {
    options.validate()?;
    let scene = shared.scene();
    let mut plan = match options.batching {
        Batching::PerNode => {
            shared.survey()?;
            plan::per_node(scene)
        }
        Batching::PerParentAndMaterial => {
            shared.survey()?;
            plan::batched(scene)?
        }
        // The validating pass also surveys each mesh (its box, whether it is one
        // tile's cut): the tiled plan reads those instead of the meshes.
        Batching::Tiled => tiles::tiled(scene, shared.survey()?, options)?,
    };
    if options.gpu_instancing && options.batching == Batching::PerNode {
        instancing::instance(scene, &mut plan)?;
    }
    let used = Used::new(scene, &plan);
    let pngs = match options.profile {
        #[cfg(feature = "web")]
        GlbProfile::Web => web::images(scene, &used, options.web_texture_max_px)?,
        _ => shared
            .pngs(&used.images)?
            .into_iter()
            .map(Cow::Borrowed)
            .collect::<Vec<_>>(),
    };
    let mut layout = match options.profile {
        GlbProfile::Plain => layout::plain(scene, &plan, &pngs)?,
        #[cfg(feature = "web")]
        GlbProfile::Web => web::layout(scene, &plan, &pngs)?,
        #[cfg(not(feature = "web"))]
        GlbProfile::Web => layout::plain(scene, &plan, &pngs)?,
    };
    // Instance arrays (EXT_mesh_gpu_instancing) after the images.
    let instances = instancing::arrays(scene, &plan, &layout.dequantize, layout.bin_len);
    layout.bin_len += pad4(instances.bytes.len() as u64);
    let (root, instance_accessors) = document(scene, &plan, &layout, &used, &instances)?;
    let json_bytes = if layout.fallback_len.is_some() || !instances.nodes.is_empty() {
        let mut doc = serde_json::to_value(&root).map_err(ExportError::json("glTF JSON"))?;
        #[cfg(feature = "web")]
        {
            if layout.fallback_len.is_some() {
                web::add_extensions(&mut doc, &layout);
            }
        }
        instancing::add_extension(&mut doc, &instances, &instance_accessors);
        serde_json::to_vec(&doc).map_err(ExportError::json("glTF JSON"))?
    } else {
        json::serialize::to_vec(&root).map_err(ExportError::json("glTF JSON"))?
    };

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
            if layout.fallback_len.is_some() {
                for s in &layout.streams {
                    w.put(s)?;
                    w.pad4()?;
                }
            } else {
                for v in &layout.views {
                    write_view(&mut w, &plan.geometries, &layout.geometries, v)?;
                }
            }
            for png in &pngs {
                w.put(png)?;
                w.pad4()?;
            }
            w.put(&instances.bytes)?;
            w.pad4()?;
        }
        w.finish()?;
        debug_assert_eq!(w.written, total);
        out.flush()
    })();
    result.map_err(io)?;
    let mut drawers = vec![0usize; plan.geometries.len()];
    let mut draw_calls = 0;
    for n in &plan.nodes {
        if let Some(m) = n.mesh.and_then(|m| plan.meshes.get(m)) {
            draw_calls += m.primitives.len();
            for &(g, _) in &m.primitives {
                drawers[g] += 1;
            }
        }
    }
    Ok(GlbReport {
        nodes: plan.nodes.len() + layout.extra_nodes(&plan),
        meshes: plan.meshes.len(),
        primitives: plan.meshes.iter().map(|m| m.primitives.len()).sum(),
        triangles: plan
            .geometries
            .iter()
            .map(|g| g.mesh.triangle_count())
            .sum(),
        draw_calls,
        features: plan.features,
        tiles: plan.tiles,
        shared_geometries: drawers.iter().filter(|&&d| d >= 2).count(),
        instances: instances.nodes.iter().map(|&(_, count, _)| count).sum(),
        materials: used.materials.len(),
        textures: used.textures.len(),
        images: used.images.len(),
        skipped_empty_meshes: plan.skipped_empty_meshes,
        unused_meshes: plan.unused_meshes,
        bytes: total,
    })
}

/// The materials, textures and images the written primitives use (scene indices in
/// scene order), and their new glTF indices.
pub(crate) struct Used {
    materials: Vec<usize>,
    textures: Vec<usize>,
    pub(crate) images: Vec<usize>,
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

    /// Per written image (in `images` order): whether a written material uses it as its
    /// normal texture.
    #[cfg(feature = "web")]
    pub(crate) fn normal_maps(&self, scene: &Scene) -> Vec<bool> {
        let mut normal = vec![false; self.images.len()];
        for mat in self
            .materials
            .iter()
            .filter_map(|&k| scene.materials.get(k))
        {
            let image = mat
                .normal_texture
                .and_then(|t| scene.textures.get(t.0 as usize))
                .and_then(|t| self.image_index.get(t.image.0 as usize))
                .and_then(|&i| normal.get_mut(i as usize));
            if let Some(n) = image {
                *n = true;
            }
        }
        normal
    }
}

/// The glTF JSON document for a plan and its layout, and per instanced node the
/// accessors of its instance arrays (translation, rotation, scale, feature id).
fn document(
    scene: &Scene,
    plan: &Plan<'_>,
    layout: &Layout,
    used: &Used,
    instances: &instancing::Instances,
) -> Result<(json::Root, Vec<[u32; 4]>), ExportError> {
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
    // Web profile: the vertex and index views lie in a second buffer without data (the
    // fallback of EXT_meshopt_compression); their compressed streams are in buffer 0.
    let geometry_buffer = match layout.fallback_len {
        Some(len) => {
            root.buffers.push(json::Buffer {
                byte_length: USize64(len.max(4)),
                name: Some("meshopt fallback".to_string()),
                uri: None,
                extensions: None,
                extras: None,
            });
            json::Index::new(root.buffers.len() as u32 - 1)
        }
        None => json::Index::new(0),
    };
    let view = |root: &mut json::Root,
                buffer: json::Index<json::Buffer>,
                offset: u64,
                length: u64,
                stride: Option<usize>,
                target: Option<json::buffer::Target>| {
        root.push(json::buffer::View {
            buffer,
            byte_length: USize64(length),
            byte_offset: Some(USize64(offset)),
            byte_stride: stride.map(json::buffer::Stride),
            name: None,
            target: target.map(Checked::Valid),
            extensions: None,
            extras: None,
        })
    };
    // The geometry views first (the web profile's extensions follow them by index),
    // then one accessor per array, in layout order: position, normal, uv (when the
    // material uses it), indices, tangents (normal-mapped materials), feature ids
    // (tiled), each at its offset in its view.
    let first_view = root.buffer_views.len() as u32;
    for v in &layout.views {
        view(
            &mut root,
            geometry_buffer,
            v.offset,
            v.length,
            v.stride,
            Some(v.target),
        );
    }
    let mut accessors: Vec<Vec<(Slot, json::Index<json::Accessor>)>> =
        Vec::with_capacity(layout.geometries.len());
    for gl in &layout.geometries {
        let mut ids = Vec::with_capacity(gl.arrays.len());
        for a in &gl.arrays {
            let v = json::Index::new(first_view + a.view as u32);
            let (min, max) = match a.bounds {
                Some((lo, hi)) => (
                    Some(json::Value::from(lo.to_vec())),
                    Some(json::Value::from(hi.to_vec())),
                ),
                None => (None, None),
            };
            let id = root.push(json::Accessor {
                buffer_view: Some(v),
                byte_offset: (a.offset > 0).then_some(USize64(a.offset)),
                count: USize64(a.count as u64),
                component_type: Checked::Valid(json::accessor::GenericComponentType(a.component)),
                extensions: None,
                extras: None,
                type_: Checked::Valid(a.ty),
                min,
                max,
                name: None,
                normalized: a.normalized,
                sparse: None,
            });
            ids.push((a.slot, id));
        }
        accessors.push(ids);
    }
    for (i, (img, &(offset, length))) in used
        .images
        .iter()
        .map(|&k| &scene.images[k])
        .zip(&layout.images)
        .enumerate()
    {
        let v = view(&mut root, json::Index::new(0), offset, length, None, None);
        root.push(json::Image {
            buffer_view: Some(v),
            mime_type: Some(json::image::MimeType("image/png".to_string())),
            name: named(&img.name).or_else(|| Some(format!("image {i}"))),
            uri: None,
            extensions: None,
            extras: None,
        });
    }
    let mut instance_accessors = Vec::with_capacity(instances.nodes.len());
    for &(_, count, at) in &instances.nodes {
        let mut ids = [0u32; 4];
        let mut offset = at;
        for (k, (ty, size)) in [
            (json::accessor::Type::Vec3, 12u64),
            (json::accessor::Type::Vec4, 16),
            (json::accessor::Type::Vec3, 12),
            (json::accessor::Type::Scalar, 4),
        ]
        .into_iter()
        .enumerate()
        {
            let length = size * count as u64;
            let v = view(&mut root, json::Index::new(0), offset, length, None, None);
            offset += length;
            let id = root.push(json::Accessor {
                buffer_view: Some(v),
                byte_offset: None,
                count: USize64(count as u64),
                component_type: Checked::Valid(json::accessor::GenericComponentType(
                    json::accessor::ComponentType::F32,
                )),
                extensions: None,
                extras: None,
                type_: Checked::Valid(ty),
                min: None,
                max: None,
                name: None,
                normalized: false,
                sparse: None,
            });
            ids[k] = id.value() as u32;
        }
        instance_accessors.push(ids);
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
    for (mi, m) in plan.meshes.iter().enumerate() {
        let primitives = m
            .primitives
            .iter()
            .enumerate()
            .map(|(k, &(g, material))| {
                let g = layout
                    .primitive_geometry
                    .get(mi)
                    .and_then(|p| p.get(k))
                    .copied()
                    .unwrap_or(g);
                let mut attributes = BTreeMap::new();
                let mut indices = None;
                for &(slot, id) in accessors.get(g).map(Vec::as_slice).unwrap_or_default() {
                    let semantic = match slot {
                        Slot::Position => json::mesh::Semantic::Positions,
                        Slot::Normal => json::mesh::Semantic::Normals,
                        Slot::Uv => json::mesh::Semantic::TexCoords(0),
                        Slot::Tangent => json::mesh::Semantic::Tangents,
                        Slot::Feature => json::mesh::Semantic::Extras("FEATURE_ID_0".to_string()),
                        Slot::Index => {
                            indices = Some(id);
                            continue;
                        }
                    };
                    attributes.insert(Checked::Valid(semantic), id);
                }
                json::mesh::Primitive {
                    attributes,
                    extensions: None,
                    extras: None,
                    indices,
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
    // Nodes whose quantized mesh needs a dequantising transform they cannot take (they
    // have children) get a child node holding the mesh, appended after the plan's nodes.
    let mut holders: Vec<json::Node> = Vec::new();
    let first_holder = plan.nodes.len() as u32;
    for pn in &plan.nodes {
        let source = pn.source.and_then(|s| scene.nodes.get(s.index()));
        let metadata = match source {
            Some(node) if !node.metadata.is_empty() => {
                match serde_json::to_value(&node.metadata).map_err(ExportError::json("extras"))? {
                    serde_json::Value::Object(m) => m,
                    _ => serde_json::Map::new(),
                }
            }
            _ => serde_json::Map::new(),
        };
        let none = serde_json::Map::new();
        let extras = Merged(
            &metadata,
            pn.extras.as_ref().unwrap_or(&none),
            &pn.raw_extras,
        );
        let name = match source {
            Some(node) => named(&node.name),
            None => named(&pn.name),
        };
        let mut children: Vec<json::Index<json::Node>> =
            pn.children.iter().map(|&c| json::Index::new(c)).collect();
        let mut mesh = pn.mesh.map(|m| json::Index::new(m as u32));
        let dequantize = pn
            .mesh
            .and_then(|m| layout.dequantize.get(m).copied().flatten());
        let mut out = json::Node {
            extras: if extras.is_empty() {
                None
            } else {
                // The root's feature table is serialized from the plan, never copied.
                Some(raw(&extras)?)
            },
            name,
            ..json::Node::default()
        };
        let transform = source.map_or(Transform::IDENTITY, |n| n.transform);
        // Instanced nodes: the instances' transforms carry the dequantisation.
        let dequantize = dequantize.filter(|_| pn.instances.is_empty());
        match dequantize {
            Some((offset, scale)) if children.is_empty() => {
                set_transform(&mut out, &compose_dequantize(&transform, offset, scale));
            }
            Some((offset, scale)) => {
                set_transform(&mut out, &transform);
                let mut holder = json::Node {
                    mesh: mesh.take(),
                    name: Some("mesh".to_string()),
                    ..json::Node::default()
                };
                set_transform(
                    &mut holder,
                    &compose_dequantize(&Transform::IDENTITY, offset, scale),
                );
                children.push(json::Index::new(first_holder + holders.len() as u32));
                holders.push(holder);
            }
            None => set_transform(&mut out, &transform),
        }
        out.mesh = mesh;
        out.children = (!children.is_empty()).then_some(children);
        root.push(out);
    }
    for h in holders {
        root.push(h);
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
    Ok((root, instance_accessors))
}

/// A node's metadata, the layout's extras and its arrays of elements already written as
/// text, serialized as one JSON object without copying any: keys in sorted order (as
/// `serde_json::Map` orders them); where several have a key, the array, else the second
/// object's value.
struct Merged<'a>(
    &'a serde_json::Map<String, serde_json::Value>,
    &'a serde_json::Map<String, serde_json::Value>,
    &'a [(&'static str, Vec<Box<serde_json::value::RawValue>>)],
);

impl Merged<'_> {
    fn is_empty(&self) -> bool {
        self.0.is_empty() && self.1.is_empty() && self.2.is_empty()
    }
}

impl Serialize for Merged<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut keys: Vec<&str> = self
            .0
            .keys()
            .chain(self.1.keys())
            .map(String::as_str)
            .chain(self.2.iter().map(|(k, _)| *k))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        let mut map = s.serialize_map(Some(keys.len()))?;
        for k in keys {
            if let Some((_, v)) = self.2.iter().find(|(name, _)| *name == k) {
                map.serialize_entry(k, v)?;
            } else if let Some(v) = self.1.get(k).or_else(|| self.0.get(k)) {
                map.serialize_entry(k, v)?;
            }
        }
        map.end()
    }
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

/// `t` followed (inside) by the dequantisation `q ↦ offset + scale ⊙ q` of quantized
/// positions: a TRS stays a TRS (the scale multiplies, the offset moves the translation).
pub(crate) fn compose_dequantize(t: &Transform, offset: Vec3, scale: Vec3) -> Transform {
    let (o, s) = (offset.as_dvec3(), scale.as_dvec3());
    match *t {
        Transform::Trs {
            translation,
            rotation,
            scale: sc,
        } => Transform::Trs {
            translation: translation + rotation * (sc * o),
            rotation,
            scale: sc * s,
        },
        Transform::Matrix(m) => Transform::Matrix(
            m * DMat4::from_scale_rotation_translation(s, polis_geom::glam::DQuat::IDENTITY, o),
        ),
    }
}

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

#[cfg(test)]
mod tests;
#[cfg(test)]
mod tiled_tests;
