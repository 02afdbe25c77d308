//! Where every array lies in the binary chunk, what its accessor says, and how it is
//! written: streamed from the meshes (plain profile) or from pre-encoded bytes (web).

use std::io::Write;

use gltf::json;
use polis_geom::Mesh;
use polis_geom::glam::{DVec3, Vec3};
use polis_geom::scene::{Material, MaterialId, Scene};

use super::plan::{FeatureIds, Geometry, Plan, Shape, moved};
use super::tangents;
use crate::ExportError;

/// The largest vertex count whose indices fit `u16` (65,535 is reserved for primitive
/// restart and must not appear).
pub(crate) const U16_VERTEX_LIMIT: usize = 65_535;

/// The largest feature index written as `u16` (beyond: `f32`, exact up to 2²⁴).
const U16_FEATURE_LIMIT: u32 = 65_535;

/// Feature indices of `f32` are exact below this.
const F32_EXACT: u32 = 1 << 24;

/// What an array holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Slot {
    Position,
    Normal,
    Uv,
    Index,
    Tangent,
    Feature,
}

/// One array: its accessor and its place in its buffer view.
#[derive(Debug)]
pub(crate) struct ArrayLayout {
    pub slot: Slot,
    pub count: usize,
    pub ty: json::accessor::Type,
    pub component: json::accessor::ComponentType,
    pub normalized: bool,
    /// `min` and `max` of the accessor (positions).
    pub bounds: Option<([f64; 3], [f64; 3])>,
    /// Bytes per vertex (the `byteStride` of the view; `None` for indices).
    pub stride: Option<usize>,
    /// The buffer view holding it ([`Layout::views`]) and its offset in that view (the
    /// accessor's `byteOffset`).
    pub view: usize,
    pub offset: u64,
    /// Bytes in the (uncompressed) view: `count` × stride or index size.
    pub length: u64,
    /// Web profile: the `EXT_meshopt_compression` filter the stream was encoded with
    /// (`OCTAHEDRAL` for normals and tangents, `EXPONENTIAL` for wide texture
    /// coordinates), applied by the decoder.
    #[cfg_attr(not(feature = "web"), allow(dead_code))]
    pub filter: Option<&'static str>,
}

impl ArrayLayout {
    /// An array of `count` elements of `size` bytes each, not yet placed in a view.
    pub fn new(
        slot: Slot,
        count: usize,
        ty: json::accessor::Type,
        component: json::accessor::ComponentType,
        size: usize,
    ) -> Self {
        ArrayLayout {
            slot,
            count,
            ty,
            component,
            normalized: false,
            bounds: None,
            stride: (slot != Slot::Index).then_some(size),
            view: 0,
            offset: 0,
            length: (count * size) as u64,
            filter: None,
        }
    }

    pub fn target(&self) -> json::buffer::Target {
        if self.slot == Slot::Index {
            json::buffer::Target::ElementArrayBuffer
        } else {
            json::buffer::Target::ArrayBuffer
        }
    }

    /// The element size the view (and the codec) sees: the stride, or the index size.
    pub fn element_size(&self) -> usize {
        self.stride.unwrap_or(match self.component {
            json::accessor::ComponentType::U32 | json::accessor::ComponentType::F32 => 4,
            json::accessor::ComponentType::U16 | json::accessor::ComponentType::I16 => 2,
            _ => 1,
        })
    }

    /// Arrays with equal keys share a buffer view: indices of one size, or vertex
    /// attributes of one stride and one meshopt filter.
    fn view_key(&self) -> (bool, usize, Option<&'static str>) {
        (self.slot == Slot::Index, self.element_size(), self.filter)
    }
}

/// One buffer view: a run of arrays of one kind ([`ArrayLayout::view_key`]) from one
/// batch of geometries, back to back.
#[derive(Debug)]
pub(crate) struct ViewLayout {
    /// Offset and length in buffer 0 (plain) or in the fallback buffer (web).
    pub offset: u64,
    pub length: u64,
    /// `byteStride` (vertex attributes) or `None` (indices).
    pub stride: Option<usize>,
    pub target: json::buffer::Target,
    /// Elements in the view and the size of one (the meshopt stream's `count` and
    /// `byteStride`).
    #[cfg_attr(not(feature = "web"), allow(dead_code))]
    pub count: usize,
    #[cfg_attr(not(feature = "web"), allow(dead_code))]
    pub element_size: usize,
    #[cfg_attr(not(feature = "web"), allow(dead_code))]
    pub filter: Option<&'static str>,
    /// Web profile: `(offset, length)` of the meshopt stream in the binary chunk.
    #[cfg_attr(not(feature = "web"), allow(dead_code))]
    pub compressed: Option<(u64, u64)>,
    /// The arrays it holds in order: (geometry of the layout, array of that geometry).
    pub members: Vec<(usize, usize)>,
}

impl ViewLayout {
    /// The `EXT_meshopt_compression` mode of the view.
    #[cfg(feature = "web")]
    pub fn meshopt_mode(&self) -> &'static str {
        if self.stride.is_none() {
            "TRIANGLES"
        } else {
            "ATTRIBUTES"
        }
    }
}

/// The arrays of one written geometry, in slot order.
#[derive(Debug)]
pub(crate) struct GeometryLayout {
    pub arrays: Vec<ArrayLayout>,
}

/// Where everything lies.
#[derive(Debug)]
pub(crate) struct Layout {
    /// Per written geometry (a plan geometry, or in the web profile a geometry on one
    /// quantisation grid), its arrays.
    pub geometries: Vec<GeometryLayout>,
    /// The geometry buffer views, in file order.
    pub views: Vec<ViewLayout>,
    /// Per glTF mesh, per primitive: the written geometry.
    pub primitive_geometry: Vec<Vec<usize>>,
    /// Per glTF mesh: the dequantisation `(offset, scale)` its nodes apply (web).
    pub dequantize: Vec<Option<(Vec3, Vec3)>>,
    /// (offset, length) of each image in the binary chunk.
    pub images: Vec<(u64, u64)>,
    /// Length of the binary chunk (buffer 0).
    pub bin_len: u64,
    /// Web profile: length of the fallback buffer (buffer 1, no data) and the
    /// compressed streams in chunk order (one per view).
    pub fallback_len: Option<u64>,
    pub streams: Vec<Vec<u8>>,
}

impl Layout {
    /// Nodes the document adds to hold a dequantized mesh under a node with children.
    pub fn extra_nodes(&self, plan: &Plan<'_>) -> usize {
        plan.nodes
            .iter()
            .filter(|n| {
                !n.children.is_empty()
                    && n.mesh
                        .and_then(|m| self.dequantize.get(m).copied().flatten())
                        .is_some()
            })
            .count()
    }
}

/// Consecutive glTF meshes share buffer views until their geometry holds this many
/// vertices: a tile of the tiled layout usually has views of its own, while small
/// meshes (sparse tiles, the per-node layout's buildings) do not each pay for a set of
/// view objects in the JSON (about 200 bytes each with the meshopt extension).
const BATCH_VERTICES: usize = 8_192;

/// The written geometries in batches that share buffer views: each geometry in the batch
/// of the first mesh drawing it, in mesh and primitive order; a batch closes after a
/// mesh once it holds [`BATCH_VERTICES`] vertices. `vertices(g)` is geometry `g`'s
/// vertex count; geometries no mesh draws come last.
pub(crate) fn batches(
    primitive_geometry: &[Vec<usize>],
    geometries: usize,
    vertices: impl Fn(usize) -> usize,
) -> Vec<Vec<usize>> {
    let mut placed = vec![false; geometries];
    let mut out = Vec::new();
    let (mut batch, mut size) = (Vec::new(), 0usize);
    for prims in primitive_geometry {
        for &g in prims {
            if let Some(p) = placed.get_mut(g)
                && !*p
            {
                *p = true;
                batch.push(g);
                size += vertices(g);
            }
        }
        if size >= BATCH_VERTICES {
            out.push(std::mem::take(&mut batch));
            size = 0;
        }
    }
    batch.extend((0..geometries).filter(|&g| !placed[g]));
    if !batch.is_empty() {
        out.push(batch);
    }
    out
}

/// The views of one batch: its geometries' arrays grouped by kind (in the order the
/// kinds first appear), each array's `view` (counted from `first_view`) and `offset`
/// set; the views' own `offset` is left at 0 for the caller to place.
pub(crate) fn batch_views(
    batch: &[usize],
    geometries: &mut [GeometryLayout],
    first_view: usize,
) -> Vec<ViewLayout> {
    let mut views: Vec<ViewLayout> = Vec::new();
    let mut keys = Vec::new();
    for &g in batch {
        for (k, a) in geometries[g].arrays.iter_mut().enumerate() {
            let key = a.view_key();
            let v = match keys.iter().position(|&x| x == key) {
                Some(v) => v,
                None => {
                    keys.push(key);
                    views.push(ViewLayout {
                        offset: 0,
                        length: 0,
                        stride: a.stride,
                        target: a.target(),
                        count: 0,
                        element_size: a.element_size(),
                        filter: a.filter,
                        compressed: None,
                        members: Vec::new(),
                    });
                    views.len() - 1
                }
            };
            let view = &mut views[v];
            // Vertex arrays of one stride, or indices of one size: every array starts
            // at a multiple of its element size (4-byte aligned vertex attributes).
            a.view = first_view + v;
            a.offset = view.length;
            view.length += a.length;
            view.count += a.count;
            view.members.push((g, k));
        }
    }
    views
}

pub(crate) fn pad4(n: u64) -> u64 {
    n.div_ceil(4) * 4
}

/// Whether a geometry drawn with `material` writes `TEXCOORD_0`.
pub(crate) fn writes_uvs(scene: &Scene, material: Option<MaterialId>) -> bool {
    material
        .and_then(|m| scene.materials.get(m.index()))
        .is_some_and(Material::uses_texture_coordinates)
}

/// Whether a geometry drawn with `material` writes `TANGENT` (a normal texture).
pub(crate) fn writes_tangents(scene: &Scene, material: Option<MaterialId>) -> bool {
    material
        .and_then(|m| scene.materials.get(m.index()))
        .is_some_and(|m| m.normal_texture.is_some())
}

/// The component type of a geometry's feature ids, checking the `f32` limit.
pub(crate) fn feature_component(
    ids: &FeatureIds,
) -> Result<json::accessor::ComponentType, ExportError> {
    let max = ids.max();
    if max <= U16_FEATURE_LIMIT {
        Ok(json::accessor::ComponentType::U16)
    } else if max < F32_EXACT {
        Ok(json::accessor::ComponentType::F32)
    } else {
        Err(ExportError::InvalidOption {
            name: "batching",
            reason: format!(
                "{max} features do not fit a float feature id (at most 2^24); split the scene \
                 or write it per node"
            ),
        })
    }
}

/// The plain layout: every array as its core glTF type, in one buffer; the arrays of a
/// batch of meshes ([`batches`]) in one view per kind.
pub(crate) fn plain(
    scene: &Scene,
    plan: &Plan<'_>,
    pngs: &[std::borrow::Cow<'_, [u8]>],
) -> Result<Layout, ExportError> {
    use json::accessor::{ComponentType as C, Type as T};
    let mut geometries = Vec::with_capacity(plan.geometries.len());
    for g in &plan.geometries {
        let m = &g.mesh;
        let n = m.vertex_count();
        let b = g.bbox();
        let mut arrays = Vec::with_capacity(6);
        arrays.push(ArrayLayout {
            bounds: Some((b.min.as_dvec3().to_array(), b.max.as_dvec3().to_array())),
            ..ArrayLayout::new(Slot::Position, n, T::Vec3, C::F32, 12)
        });
        arrays.push(ArrayLayout::new(Slot::Normal, n, T::Vec3, C::F32, 12));
        if writes_uvs(scene, m.material()) {
            arrays.push(ArrayLayout::new(Slot::Uv, n, T::Vec2, C::F32, 8));
        }
        let wide = n > U16_VERTEX_LIMIT;
        let (ic, isize) = if wide { (C::U32, 4) } else { (C::U16, 2) };
        arrays.push(ArrayLayout::new(
            Slot::Index,
            m.index_count(),
            T::Scalar,
            ic,
            isize,
        ));
        if writes_tangents(scene, m.material()) {
            arrays.push(ArrayLayout::new(Slot::Tangent, n, T::Vec4, C::F32, 16));
        }
        if let Some(ids) = &g.features {
            // Four bytes per vertex either way: u16 with a stride of 4 (vertex attribute
            // elements are 4-byte aligned), or f32.
            let c = feature_component(ids)?;
            arrays.push(ArrayLayout::new(Slot::Feature, n, T::Scalar, c, 4));
        }
        geometries.push(GeometryLayout { arrays });
    }
    let primitive_geometry: Vec<Vec<usize>> = plan
        .meshes
        .iter()
        .map(|m| m.primitives.iter().map(|&(g, _)| g).collect())
        .collect();
    let mut views = Vec::new();
    let mut off = 0u64;
    for batch in batches(&primitive_geometry, geometries.len(), |g| {
        plan.geometries[g].mesh.vertex_count()
    }) {
        for mut v in batch_views(&batch, &mut geometries, views.len()) {
            v.offset = off;
            off = pad4(off + v.length);
            views.push(v);
        }
    }
    let mut images = Vec::with_capacity(pngs.len());
    for p in pngs {
        images.push((off, p.len() as u64));
        off = pad4(off + p.len() as u64);
    }
    Ok(Layout {
        geometries,
        views,
        primitive_geometry,
        dequantize: vec![None; plan.meshes.len()],
        images,
        bin_len: off,
        fallback_len: None,
        streams: Vec::new(),
    })
}

/// Buffered little-endian output that counts bytes.
pub(crate) struct Chunked<'w, W: Write> {
    out: &'w mut W,
    buf: Vec<u8>,
    pub written: u64,
}

const CHUNK: usize = 1 << 16;

impl<'w, W: Write> Chunked<'w, W> {
    pub fn new(out: &'w mut W) -> Self {
        Chunked {
            out,
            buf: Vec::with_capacity(CHUNK + 64),
            written: 0,
        }
    }

    #[inline]
    pub fn put(&mut self, bytes: &[u8]) -> std::io::Result<()> {
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

    /// Writes `items` as `bytes` gives each: converted 4 kB at a time straight into the
    /// buffer (one length check per block, no second copy).
    pub fn put_all<T, const N: usize>(
        &mut self,
        items: &[T],
        bytes: impl Fn(&T) -> [u8; N],
    ) -> std::io::Result<()> {
        const BLOCK: usize = 4096;
        for chunk in items.chunks((BLOCK / N).max(1)) {
            let len = chunk.len() * N;
            if self.buf.len() + len > CHUNK {
                self.drain()?;
            }
            let start = self.buf.len();
            self.buf.resize(start + len, 0);
            for (out, item) in self.buf[start..].chunks_exact_mut(N).zip(chunk) {
                out.copy_from_slice(&bytes(item));
            }
            self.written += len as u64;
        }
        Ok(())
    }

    pub fn pad4(&mut self) -> std::io::Result<()> {
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

    pub fn finish(&mut self) -> std::io::Result<()> {
        self.drain()
    }
}

/// Streams one view's arrays (plain profile), padded to 4 bytes.
pub(crate) fn write_view<W: Write>(
    w: &mut Chunked<'_, W>,
    geometries: &[Geometry<'_>],
    layout: &[GeometryLayout],
    view: &ViewLayout,
) -> std::io::Result<()> {
    // 12 (header) + 8 + json + 8 (bin header) is a multiple of 4, so relative alignment
    // in the chunk equals absolute alignment in the file; views start 4-byte aligned.
    for &(g, k) in &view.members {
        if let (Some(g), Some(a)) = (
            geometries.get(g),
            layout.get(g).and_then(|l| l.arrays.get(k)),
        ) {
            write_array(w, g, a)?;
        }
    }
    w.pad4()
}

/// The little-endian bytes of `p`.
fn vec3_bytes(p: Vec3) -> [u8; 12] {
    let mut b = [0u8; 12];
    b[0..4].copy_from_slice(&p.x.to_le_bytes());
    b[4..8].copy_from_slice(&p.y.to_le_bytes());
    b[8..12].copy_from_slice(&p.z.to_le_bytes());
    b
}

/// Streams one array of a geometry: a whole mesh's, or a gathered geometry's piece by
/// piece (the bytes of its merged mesh).
fn write_array<W: Write>(
    w: &mut Chunked<'_, W>,
    g: &Geometry<'_>,
    a: &ArrayLayout,
) -> std::io::Result<()> {
    match (&g.mesh, a.slot) {
        (_, Slot::Feature) => write_features(w, g, a),
        (Shape::Whole(m), _) => write_piece(w, m, DVec3::ZERO, 0, a),
        // A piece's tangents depend on its own triangles only, when every piece has
        // its normals and texture coordinates (else the merged arrays are made).
        (Shape::Gathered(gathered), Slot::Tangent) if !gathered.aligned() => {
            write_piece(w, &gathered.to_mesh(), DVec3::ZERO, 0, a)
        }
        (Shape::Gathered(gathered), _) => {
            let mut base = 0u32;
            for (m, t) in &gathered.pieces {
                write_piece(w, m, *t, base, a)?;
                base += m.positions.len() as u32;
            }
            Ok(())
        }
    }
}

/// Streams array `a` (not the feature ids) of mesh `m` as a piece of a merged geometry:
/// its positions moved by `t` ([`moved`]), its indices counted from `base`.
fn write_piece<W: Write>(
    w: &mut Chunked<'_, W>,
    m: &Mesh,
    t: DVec3,
    base: u32,
    a: &ArrayLayout,
) -> std::io::Result<()> {
    match a.slot {
        Slot::Position if t == DVec3::ZERO => w.put_all(&m.positions, |p| vec3_bytes(*p))?,
        Slot::Position => w.put_all(&m.positions, |&p| vec3_bytes(moved(p, t)))?,
        Slot::Normal => w.put_all(&m.normals, |n| vec3_bytes(n.normalize_or_zero()))?,
        Slot::Uv => w.put_all(&m.uvs, |t| {
            let mut b = [0u8; 8];
            b[0..4].copy_from_slice(&t.x.to_le_bytes());
            b[4..8].copy_from_slice(&t.y.to_le_bytes());
            b
        })?,
        Slot::Index => {
            if a.component == json::accessor::ComponentType::U32 {
                w.put_all(&m.indices, |&i| (base + i).to_le_bytes())?;
            } else {
                w.put_all(&m.indices, |&i| ((base + i) as u16).to_le_bytes())?;
            }
        }
        Slot::Tangent => {
            let moved_positions: Vec<Vec3>;
            let positions = if t == DVec3::ZERO {
                &m.positions
            } else {
                moved_positions = m.positions.iter().map(|&p| moved(p, t)).collect();
                &moved_positions
            };
            let all = tangents::tangents_of(positions, &m.normals, &m.uvs, &m.indices);
            w.put_all(&all, |t| {
                let mut b = [0u8; 16];
                for (k, c) in t.to_array().into_iter().enumerate() {
                    b[4 * k..4 * k + 4].copy_from_slice(&c.to_le_bytes());
                }
                b
            })?
        }
        Slot::Feature => {}
    }
    Ok(())
}

/// Streams a geometry's feature ids (array `a`), run by run.
fn write_features<W: Write>(
    w: &mut Chunked<'_, W>,
    g: &Geometry<'_>,
    a: &ArrayLayout,
) -> std::io::Result<()> {
    let Some(ids) = &g.features else {
        return Ok(());
    };
    // Each run is one id repeated: its four bytes laid out once in a block,
    // and the block written as often as the run needs.
    const BLOCK: usize = 1024;
    let mut block = [0u8; 4 * BLOCK];
    for &(n, f) in ids.runs() {
        let bytes = if a.component == json::accessor::ComponentType::F32 {
            (f as f32).to_le_bytes()
        } else {
            let [lo, hi] = (f as u16).to_le_bytes();
            [lo, hi, 0, 0]
        };
        let mut left = n as usize;
        for c in block.chunks_exact_mut(4).take(left.min(BLOCK)) {
            c.copy_from_slice(&bytes);
        }
        while left > 0 {
            let k = left.min(BLOCK);
            w.put(&block[..4 * k])?;
            left -= k;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glb::plan::Gathered;
    use polis_geom::glam::Vec2;
    use proptest::prelude::*;
    use std::borrow::Cow;

    /// A mesh of `n` vertices (values from `seed`, −0 among them) and `t` triangles;
    /// without texture coordinates when `uvs` is false.
    fn piece(seed: u32, n: usize, t: usize, uvs: bool) -> Mesh {
        let value = |k: usize| {
            let v = (seed as usize * 31 + k * 17) % 23;
            if v == 0 { -0.0 } else { v as f32 * 0.37 - 3.0 }
        };
        let mut m = Mesh::new(None);
        for k in 0..n {
            m.positions
                .push(Vec3::new(value(3 * k), value(3 * k + 1), value(3 * k + 2)));
            m.normals
                .push(Vec3::new(value(k), 1.0, value(k + 5)).normalize_or(Vec3::Y));
            if uvs {
                m.uvs.push(Vec2::new(value(k + 7), value(k + 11)));
            }
        }
        for k in 0..t {
            m.indices
                .extend([k % n, (k * 7 + 1) % n, (k * 5 + 2) % n].map(|i| i as u32));
        }
        m
    }

    fn bytes(g: &Geometry<'_>, a: &ArrayLayout) -> Vec<u8> {
        let mut out = Vec::new();
        let mut w = Chunked::new(&mut out);
        write_array(&mut w, g, a).unwrap();
        w.finish().unwrap();
        out
    }

    proptest! {
        /// A gathered geometry streams the bytes of its merged mesh, array by array
        /// (tangents from the merged mesh too when a piece lacks texture coordinates).
        #[test]
        fn gathered_pieces_stream_their_merged_arrays(
            spec in proptest::collection::vec(
                (0u32..1000, 1usize..20, 0usize..12, 0usize..3, -1e4f64..1e4),
                1..6,
            ),
            missing_uvs in any::<bool>(),
        ) {
            let pieces: Vec<(Cow<'_, Mesh>, DVec3)> = spec
                .iter()
                .enumerate()
                .map(|(i, &(seed, n, t, moved, x))| {
                    let m = piece(seed, n, t, !(missing_uvs && i == 0));
                    let t = if moved == 0 { DVec3::ZERO } else { DVec3::new(x, -0.5, x * 0.3) };
                    (Cow::Owned(m), t)
                })
                .collect();
            let gathered = Gathered {
                material: None,
                vertices: pieces.iter().map(|(m, _)| m.positions.len()).sum(),
                indices: pieces.iter().map(|(m, _)| m.indices.len()).sum(),
                pieces,
            };
            let merged = gathered.to_mesh();
            let n = merged.vertex_count();
            let g = Geometry { mesh: Shape::Gathered(gathered), features: None, bounds: None };
            let whole = Geometry { mesh: Shape::Whole(Cow::Borrowed(&merged)), features: None, bounds: None };
            use json::accessor::{ComponentType as C, Type as T};
            let arrays = [
                ArrayLayout::new(Slot::Position, n, T::Vec3, C::F32, 12),
                ArrayLayout::new(Slot::Normal, n, T::Vec3, C::F32, 12),
                ArrayLayout::new(Slot::Uv, n, T::Vec2, C::F32, 8),
                ArrayLayout::new(Slot::Index, merged.indices.len(), T::Scalar, C::U16, 2),
                ArrayLayout::new(Slot::Index, merged.indices.len(), T::Scalar, C::U32, 4),
                ArrayLayout::new(Slot::Tangent, n, T::Vec4, C::F32, 16),
            ];
            for a in &arrays {
                prop_assert_eq!(bytes(&g, a), bytes(&whole, a), "{:?}", a.slot);
            }
        }
    }
}
