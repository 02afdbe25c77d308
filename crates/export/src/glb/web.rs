//! The web profile: `KHR_mesh_quantization` + `EXT_meshopt_compression`.
//!
//! Per glTF mesh, positions are quantized to unsigned 16-bit integers on a grid spanning
//! the mesh's bounds (one step for all axes, a power of two of metres at or above the
//! largest extent / 65,535, 3.9 mm over a 250 m tile, so the dequantising scale is
//! uniform and normals keep their directions) and the nodes drawing it dequantize with
//! their transform (scale and offset composed into their TRS, or a child node `mesh` when
//! they have children of their own). Normals and tangents go through meshopt's
//! `OCTAHEDRAL` filter (signed normalized bytes); texture coordinates within [0, 1]
//! become unsigned normalized 16-bit, others stay `f32` through the `EXPONENTIAL` filter
//! at steps of at most 1/4096 of a repeat (a sixteenth of a texel of a 256 px texture);
//! feature ids stay exact. The arrays of a batch of meshes are grouped into views by
//! kind (stride and filter, or index size; the glb module's docs), and each view is
//! encoded whole with meshoptimizer's codecs (vertex codec version 0, index codec
//! version 1, as the extension specifies: one stream per view, its `count` the sum of
//! its accessors') and stored in the binary chunk; the views point into a fallback
//! buffer without data, so both extensions are required. The tiled layout's feature
//! table is written column by column (the glb module's docs, "Profiles").
//!
//! References: Khronos, *KHR_mesh_quantization*; *EXT_meshopt_compression* (2021);
//! A. Kapoulkine, meshoptimizer (vertex and index codecs).

use std::borrow::Cow;
use std::collections::BTreeMap;

use gltf::json::accessor::{ComponentType as C, Type as T};
use meshoptimizer_rs::codec::{
    ExpMode, IndexEncoding, VertexEncoding, encode_filter_exp, encode_filter_oct,
    encode_index_buffer, encode_vertex_buffer,
};
use meshoptimizer_rs::{Limits, Workspace, optimize_vertex_cache};
use polis_geom::glam::Vec3;
use polis_geom::par::prelude::*;
use polis_geom::scene::Scene;
use serde_json::{Value, json};

use super::layout::{
    ArrayLayout, GeometryLayout, Layout, Slot, U16_VERTEX_LIMIT, ViewLayout, batch_views, batches,
    feature_component, pad4, writes_tangents, writes_uvs,
};
use super::plan::{Geometry, Plan};
use super::tangents;
use crate::ExportError;

/// The extensions a web-profile file uses and requires.
pub(crate) const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_mesh_quantization"];

/// Largest value of the 16-bit position grid.
const GRID_MAX: f32 = 65_535.0;

/// A quantisation grid: position = offset + scale ⊙ q.
#[derive(Debug, Clone, Copy)]
struct Grid {
    offset: Vec3,
    scale: Vec3,
}

impl Grid {
    /// One step on all three axes: a uniform scale in the node transform leaves the
    /// normals' directions alone, where a per-axis scale would bend them through the
    /// normal matrix. The step is the power of two of metres at or above the largest
    /// extent / 65,535 (3.9 mm for a 250 m tile) and the offset a multiple of it, so
    /// points on a map-aligned binary lattice (the terrain's quadtree corners, every
    /// 2 m) land on the grid exactly and their coordinates' low bytes repeat, which the
    /// vertex codec's byte deltas compress to nothing.
    fn spanning(lo: Vec3, hi: Vec3) -> Grid {
        let extent = (hi - lo).max_element();
        if !(extent > 0.0 && extent.is_finite()) {
            return Grid {
                offset: lo,
                scale: Vec3::ONE,
            };
        }
        let mut step = 2f32.powi((extent / GRID_MAX).log2().ceil() as i32);
        let mut offset = (lo / step).floor() * step;
        // Aligning the offset down can add one step to the span: then a step twice as
        // large (at most two rounds).
        for _ in 0..2 {
            if ((hi - offset) / step).max_element() <= GRID_MAX {
                break;
            }
            step *= 2.0;
            offset = (lo / step).floor() * step;
        }
        Grid {
            offset,
            scale: Vec3::splat(step),
        }
    }

    fn key(&self) -> [u32; 6] {
        let (o, s) = (self.offset, self.scale);
        [o.x, o.y, o.z, s.x, s.y, s.z].map(f32::to_bits)
    }

    fn quantize(&self, p: Vec3) -> [u16; 3] {
        let q = ((p - self.offset) / self.scale).round();
        [q.x, q.y, q.z].map(|c| c.clamp(0.0, GRID_MAX) as u16)
    }
}

/// The `EXT_meshopt_compression` filter of unit vectors.
const OCTAHEDRAL: &str = "OCTAHEDRAL";

/// Bits per octahedral component: 8, the signed bytes of the accessor (about 1° steps).
const OCTAHEDRAL_BITS: u32 = 8;

/// The `EXT_meshopt_compression` filter of floats on a shared exponent.
const EXPONENTIAL: &str = "EXPONENTIAL";

/// Texture coordinates keep steps of at most 2^-UV_STEP_BITS texture repeats (1/4096:
/// a sixteenth of a texel of the 256 px web textures).
const UV_STEP_BITS: i32 = 12;

/// How a mesh's texture coordinates are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum UvCoding {
    /// All within [0, 1] (the ground's map-wide texture): unsigned normalized 16-bit
    /// (`KHR_mesh_quantization`), steps of 1/65,535.
    Unorm16,
    /// Floats through meshopt's `EXPONENTIAL` filter with one exponent per component
    /// over the mesh and this many mantissa bits: a fixed step of at most
    /// 2^-[`UV_STEP_BITS`] repeats at the largest coordinate (repeating metre or
    /// marking-period coordinates), exact lower bits dropped so the codec compresses
    /// them.
    Exponential(u32),
}

/// The coding of texture coordinates `uvs` (finite; a non-finite one fails the encoder).
fn uv_coding(uvs: &[[f32; 2]]) -> UvCoding {
    let mut largest = 0.0f32;
    let mut unit = true;
    for c in uvs.iter().flatten() {
        unit &= (0.0..=1.0).contains(c);
        largest = largest.max(c.abs());
    }
    if unit {
        return UvCoding::Unorm16;
    }
    // The filter stores m · 2^e with a signed mantissa of `bits` bits and e shared by
    // the component: e = ⌊log2 |largest|⌋ + 1 − (bits − 1).
    let magnitude = if largest > 0.0 && largest.is_finite() {
        largest.log2().floor() as i32 + 1
    } else {
        0
    };
    UvCoding::Exponential((magnitude + UV_STEP_BITS + 1).clamp(2, 24) as u32)
}

/// Unit vectors (four floats each: direction and `w`, the tangent handedness or 0) as
/// meshopt's octahedral filter stores them: two octahedral coordinates, a constant
/// and `w`, in signed bytes the decoder turns back into a normalized vector. The
/// constant third byte and the smooth coordinates compress better than `x, y, z`.
fn octahedral(unit: &[f32], n: usize, ws: &mut Workspace) -> Result<Vec<u8>, ExportError> {
    encode_filter_oct(n, 4, OCTAHEDRAL_BITS, unit, ws).map_err(codec)
}

/// One array's data before the codec (quantized and filtered, in the order the
/// codec sees it).
enum Data {
    /// Vertex attribute bytes, `stride` per vertex.
    Vertex(Vec<u8>),
    /// Triangle indices.
    Index(Vec<u32>),
}

fn codec(e: meshoptimizer_rs::Error) -> ExportError {
    ExportError::InvalidOption {
        name: "profile",
        reason: format!("meshopt encoding failed: {e:?}"),
    }
}

/// Quantizes and filters one geometry on `grid`: its arrays and their data.
fn encode(
    scene: &Scene,
    g: &Geometry<'_>,
    grid: Grid,
    ws: &mut Workspace,
) -> Result<(GeometryLayout, Vec<Data>), ExportError> {
    // A gathered geometry's merged arrays are made here: the codecs reorder them.
    let m = &*g.mesh.to_mesh();
    // Triangles in vertex-cache order (Forsyth's method, meshoptimizer's), then vertices
    // in first-use order: what the codecs compress best.
    let cached = optimize_vertex_cache(&m.indices, m.vertex_count(), ws).map_err(codec)?;
    let mut remap = vec![u32::MAX; m.vertex_count()];
    let mut order: Vec<usize> = Vec::with_capacity(m.vertex_count());
    let indices: Vec<u32> = cached
        .iter()
        .map(|&v| {
            let r = &mut remap[v as usize];
            if *r == u32::MAX {
                *r = order.len() as u32;
                order.push(v as usize);
            }
            *r
        })
        .collect();
    let n = order.len();
    let array = |slot, ty, component, normalized, stride: usize| ArrayLayout {
        normalized,
        ..ArrayLayout::new(slot, n, ty, component, stride)
    };
    let mut arrays = Vec::with_capacity(6);
    let mut data = Vec::with_capacity(6);

    let mut bytes = Vec::with_capacity(8 * n);
    let (mut lo, mut hi) = ([u16::MAX; 3], [0u16; 3]);
    for &p in order.iter().map(|&v| &m.positions[v]) {
        let q = grid.quantize(p);
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
            bytes.extend_from_slice(&q[k].to_le_bytes());
        }
        bytes.extend_from_slice(&[0, 0]);
    }
    arrays.push(ArrayLayout {
        bounds: Some((lo.map(f64::from), hi.map(f64::from))),
        ..array(Slot::Position, T::Vec3, C::U16, false, 8)
    });
    data.push(Data::Vertex(bytes));

    let mut unit = Vec::with_capacity(4 * n);
    for nrm in order.iter().map(|&v| &m.normals[v]) {
        unit.extend_from_slice(&nrm.normalize_or_zero().extend(0.0).to_array());
    }
    arrays.push(ArrayLayout {
        filter: Some(OCTAHEDRAL),
        ..array(Slot::Normal, T::Vec3, C::I8, true, 4)
    });
    data.push(Data::Vertex(octahedral(&unit, n, ws)?));

    if writes_uvs(scene, m.material) {
        let uvs: Vec<[f32; 2]> = order
            .iter()
            .filter_map(|&v| m.uvs.get(v))
            .map(|t| [t.x, t.y])
            .collect();
        match uv_coding(&uvs) {
            UvCoding::Unorm16 => {
                let mut bytes = Vec::with_capacity(4 * n);
                for c in uvs.iter().flatten() {
                    let q = (c * 65_535.0).round().clamp(0.0, 65_535.0) as u16;
                    bytes.extend_from_slice(&q.to_le_bytes());
                }
                arrays.push(array(Slot::Uv, T::Vec2, C::U16, true, 4));
                data.push(Data::Vertex(bytes));
            }
            UvCoding::Exponential(bits) => {
                let flat: Vec<f32> = uvs.iter().flatten().copied().collect();
                let filtered = encode_filter_exp(n, 8, bits, &flat, ExpMode::SharedComponent, ws)
                    .map_err(codec)?;
                arrays.push(ArrayLayout {
                    filter: Some(EXPONENTIAL),
                    ..array(Slot::Uv, T::Vec2, C::F32, false, 8)
                });
                data.push(Data::Vertex(filtered));
            }
        }
    }

    let wide = n > U16_VERTEX_LIMIT;
    let (ic, isize) = if wide { (C::U32, 4) } else { (C::U16, 2) };
    arrays.push(ArrayLayout::new(
        Slot::Index,
        indices.len(),
        T::Scalar,
        ic,
        isize,
    ));
    data.push(Data::Index(indices));

    if writes_tangents(scene, m.material) {
        let all = tangents::tangents(m);
        let mut unit = Vec::with_capacity(4 * n);
        for t in order.iter().filter_map(|&v| all.get(v)) {
            let d = t.truncate().normalize_or_zero();
            unit.extend_from_slice(&d.extend(if t.w < 0.0 { -1.0 } else { 1.0 }).to_array());
        }
        arrays.push(ArrayLayout {
            filter: Some(OCTAHEDRAL),
            ..array(Slot::Tangent, T::Vec4, C::I8, true, 4)
        });
        data.push(Data::Vertex(octahedral(&unit, n, ws)?));
    }

    if let Some(runs) = &g.features {
        let c = feature_component(runs)?;
        let ids = runs.to_vec();
        let mut bytes = Vec::with_capacity(4 * n);
        for &f in order.iter().filter_map(|&v| ids.get(v)) {
            if c == C::F32 {
                bytes.extend_from_slice(&(f as f32).to_le_bytes());
            } else {
                let [a, b] = (f as u16).to_le_bytes();
                bytes.extend_from_slice(&[a, b, 0, 0]);
            }
        }
        arrays.push(array(Slot::Feature, T::Scalar, c, false, 4));
        data.push(Data::Vertex(bytes));
    }
    Ok((GeometryLayout { arrays }, data))
}

/// One batch of written geometries ([`batches`]), encoded: each geometry's arrays (views
/// counted from the batch's first) and the batch's views with their meshopt streams.
struct EncodedBatch {
    geometries: Vec<GeometryLayout>,
    views: Vec<(ViewLayout, Vec<u8>)>,
}

/// Encodes the geometries `batch` (indices into `jobs`): their arrays, one view per kind
/// holding the arrays back to back, each view's data through the codec as one stream.
fn encode_batch(
    scene: &Scene,
    plan: &Plan<'_>,
    jobs: &[(usize, Grid)],
    batch: &[usize],
) -> Result<EncodedBatch, ExportError> {
    let mut ws = Workspace::new(Limits::default());
    let mut geometries = Vec::with_capacity(batch.len());
    let mut data = Vec::with_capacity(batch.len());
    for &j in batch {
        let (g, grid) = jobs[j];
        let (layout, d) = encode(scene, &plan.geometries[g], grid, &mut ws)?;
        geometries.push(layout);
        data.push(d);
    }
    let local: Vec<usize> = (0..batch.len()).collect();
    let mut views = Vec::new();
    for mut v in batch_views(&local, &mut geometries, 0) {
        let stream = if v.stride.is_none() {
            let mut indices = Vec::with_capacity(v.count);
            for &(g, k) in &v.members {
                if let Some(Data::Index(i)) = data[g].get(k) {
                    indices.extend_from_slice(i);
                }
            }
            encode_index_buffer(&indices, IndexEncoding::new(1).map_err(codec)?, &mut ws)
                .map_err(codec)?
        } else {
            let mut bytes = Vec::with_capacity(v.length as usize);
            for &(g, k) in &v.members {
                if let Some(Data::Vertex(b)) = data[g].get(k) {
                    bytes.extend_from_slice(b);
                }
            }
            encode_vertex_buffer(
                &bytes,
                v.count,
                v.element_size,
                VertexEncoding::new(0, 0).map_err(codec)?,
                &mut ws,
            )
            .map_err(codec)?
        };
        for m in &mut v.members {
            m.0 = batch[m.0];
        }
        views.push((v, stream));
    }
    Ok(EncodedBatch { geometries, views })
}

/// The web layout: one grid per glTF mesh, each (geometry, grid) encoded once; the
/// geometries in batches sharing views ([`batches`]), encoded in parallel; streams in
/// the binary chunk, then the images.
pub(crate) fn layout(
    scene: &Scene,
    plan: &Plan<'_>,
    pngs: &[Cow<'_, [u8]>],
) -> Result<Layout, ExportError> {
    let mut jobs: Vec<(usize, Grid)> = Vec::new();
    let mut job_of: BTreeMap<(usize, [u32; 6]), usize> = BTreeMap::new();
    let mut primitive_geometry = Vec::with_capacity(plan.meshes.len());
    let mut dequantize = Vec::with_capacity(plan.meshes.len());
    for m in &plan.meshes {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for &(g, _) in &m.primitives {
            let b = plan.geometries[g].bbox();
            lo = lo.min(b.min);
            hi = hi.max(b.max);
        }
        let grid = Grid::spanning(lo, hi);
        let mut prims = Vec::with_capacity(m.primitives.len());
        for &(g, _) in &m.primitives {
            let job = *job_of.entry((g, grid.key())).or_insert_with(|| {
                jobs.push((g, grid));
                jobs.len() - 1
            });
            prims.push(job);
        }
        primitive_geometry.push(prims);
        dequantize.push(Some((grid.offset, grid.scale)));
    }
    let batches = batches(&primitive_geometry, jobs.len(), |j| {
        plan.geometries[jobs[j].0].mesh.vertex_count()
    });
    let encoded: Vec<EncodedBatch> = batches
        .par_iter()
        .map(|batch| encode_batch(scene, plan, &jobs, batch))
        .collect::<Result<_, _>>()?;
    let (mut fallback, mut bin) = (0u64, 0u64);
    let mut streams = Vec::new();
    let mut views = Vec::new();
    let mut geometries: Vec<Option<GeometryLayout>> = (0..jobs.len()).map(|_| None).collect();
    for (batch, e) in batches.iter().zip(encoded) {
        let first = views.len();
        for (&j, mut g) in batch.iter().zip(e.geometries) {
            for a in &mut g.arrays {
                a.view += first;
            }
            geometries[j] = Some(g);
        }
        for (mut v, stream) in e.views {
            v.offset = fallback;
            fallback = pad4(fallback + v.length);
            v.compressed = Some((bin, stream.len() as u64));
            bin = pad4(bin + stream.len() as u64);
            streams.push(stream);
            views.push(v);
        }
    }
    let geometries = geometries
        .into_iter()
        .map(|g| g.unwrap_or(GeometryLayout { arrays: Vec::new() }))
        .collect();
    let mut images = Vec::with_capacity(pngs.len());
    for p in pngs {
        images.push((bin, p.len() as u64));
        bin = pad4(bin + p.len() as u64);
    }
    Ok(Layout {
        geometries,
        views,
        primitive_geometry,
        dequantize,
        images,
        bin_len: bin,
        fallback_len: Some(fallback),
        streams,
    })
}

/// The web profile's images (in the written order): re-encoded by `web_images`, in
/// parallel.
pub(crate) fn images(
    scene: &Scene,
    used: &super::Used,
    max_px: u32,
) -> Result<Vec<Cow<'static, [u8]>>, ExportError> {
    let normal = used.normal_maps(scene);
    used.images
        .par_iter()
        .zip(normal.par_iter())
        .map(|(&i, &n)| super::web_images::web_png(i, &scene.images[i], max_px, n).map(Cow::Owned))
        .collect()
}

/// Adds the extension objects the typed JSON cannot hold: `EXT_meshopt_compression` on
/// the geometry views (created first, in the layout's order) and on the
/// fallback buffer (index 1), and both extensions as used and required.
pub(crate) fn add_extensions(doc: &mut Value, layout: &Layout) {
    if let Some(views) = doc.get_mut("bufferViews").and_then(Value::as_array_mut) {
        for (view, lv) in views.iter_mut().zip(&layout.views) {
            if let (Some((offset, length)), Some(v)) = (lv.compressed, view.as_object_mut()) {
                let mut e = json!({
                    "buffer": 0,
                    "byteOffset": offset,
                    "byteLength": length,
                    "byteStride": lv.element_size,
                    "count": lv.count,
                    "mode": lv.meshopt_mode(),
                });
                if let (Some(f), Some(e)) = (lv.filter, e.as_object_mut()) {
                    e.insert("filter".into(), json!(f));
                }
                v.insert("extensions".into(), json!({ "EXT_meshopt_compression": e }));
            }
        }
    }
    if let Some(b) = doc
        .get_mut("buffers")
        .and_then(|b| b.get_mut(1))
        .and_then(Value::as_object_mut)
    {
        b.insert(
            "extensions".into(),
            json!({ "EXT_meshopt_compression": { "fallback": true } }),
        );
    }
    if let Some(root) = doc.as_object_mut() {
        root.insert("extensionsUsed".into(), json!(EXTENSIONS));
        root.insert("extensionsRequired".into(), json!(EXTENSIONS));
    }
}
