//! Where every array lies in the binary chunk, what its accessor says, and how it is
//! written: streamed from the meshes (plain profile) or from pre-encoded bytes (web).

use std::io::Write;

use gltf::json;
use polis_geom::glam::Vec3;
use polis_geom::scene::{Material, MaterialId, Scene};

use super::plan::{Geometry, Plan};
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

/// One array: its place in the buffer and its accessor.
#[derive(Debug)]
pub(crate) struct ArrayLayout {
    pub slot: Slot,
    pub count: usize,
    pub ty: json::accessor::Type,
    pub component: json::accessor::ComponentType,
    pub normalized: bool,
    /// `min` and `max` of the accessor (positions).
    pub bounds: Option<([f64; 3], [f64; 3])>,
    /// `byteStride` of the buffer view (vertex attributes whose elements are not
    /// 4-byte multiples, and every vertex view of the web profile).
    pub stride: Option<usize>,
    /// Offset and length in buffer 0 (plain) or in the fallback buffer (web).
    pub offset: u64,
    pub length: u64,
    /// Web profile: `(offset, length)` of the meshopt stream in the binary chunk.
    #[cfg_attr(not(feature = "web"), allow(dead_code))]
    pub compressed: Option<(u64, u64)>,
    /// Web profile: the `EXT_meshopt_compression` filter the stream was encoded with
    /// (`OCTAHEDRAL` for normals and tangents), applied by the decoder.
    #[cfg_attr(not(feature = "web"), allow(dead_code))]
    pub filter: Option<&'static str>,
}

impl ArrayLayout {
    pub fn target(&self) -> json::buffer::Target {
        if self.slot == Slot::Index {
            json::buffer::Target::ElementArrayBuffer
        } else {
            json::buffer::Target::ArrayBuffer
        }
    }

    /// The `EXT_meshopt_compression` mode of the view.
    #[cfg(feature = "web")]
    pub fn meshopt_mode(&self) -> &'static str {
        if self.slot == Slot::Index {
            "TRIANGLES"
        } else {
            "ATTRIBUTES"
        }
    }

    /// The element size the codec sees (the stride, or the index size).
    #[cfg(feature = "web")]
    pub fn element_size(&self) -> usize {
        self.stride.unwrap_or(match self.component {
            json::accessor::ComponentType::U32 | json::accessor::ComponentType::F32 => 4,
            json::accessor::ComponentType::U16 | json::accessor::ComponentType::I16 => 2,
            _ => 1,
        })
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
    pub geometries: Vec<GeometryLayout>,
    /// Per glTF mesh, per primitive: the written geometry.
    pub primitive_geometry: Vec<Vec<usize>>,
    /// Per glTF mesh: the dequantisation `(offset, scale)` its nodes apply (web).
    pub dequantize: Vec<Option<(Vec3, Vec3)>>,
    /// (offset, length) of each image in the binary chunk.
    pub images: Vec<(u64, u64)>,
    /// Length of the binary chunk (buffer 0).
    pub bin_len: u64,
    /// Web profile: length of the fallback buffer (buffer 1, no data) and the
    /// compressed streams in chunk order.
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
pub(crate) fn feature_component(ids: &[u32]) -> Result<json::accessor::ComponentType, ExportError> {
    let max = ids.iter().copied().max().unwrap_or(0);
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

/// The plain layout: every array as its core glTF type, in one buffer.
pub(crate) fn plain(
    scene: &Scene,
    plan: &Plan<'_>,
    pngs: &[std::borrow::Cow<'_, [u8]>],
) -> Result<Layout, ExportError> {
    use json::accessor::{ComponentType as C, Type as T};
    let mut off = 0u64;
    let mut geometries = Vec::with_capacity(plan.geometries.len());
    for g in &plan.geometries {
        let m = &g.mesh;
        let n = m.vertex_count();
        let b = m.bbox();
        let mut arrays = Vec::with_capacity(6);
        let mut push = |slot, count: usize, ty, component, size: u64, stride| {
            let length = count as u64 * size;
            arrays.push(ArrayLayout {
                slot,
                count,
                ty,
                component,
                normalized: false,
                bounds: (slot == Slot::Position)
                    .then(|| (b.min.as_dvec3().to_array(), b.max.as_dvec3().to_array())),
                stride,
                offset: off,
                length,
                compressed: None,
                filter: None,
            });
            off = pad4(off + length);
        };
        push(Slot::Position, n, T::Vec3, C::F32, 12, None);
        push(Slot::Normal, n, T::Vec3, C::F32, 12, None);
        if writes_uvs(scene, m.material) {
            push(Slot::Uv, n, T::Vec2, C::F32, 8, None);
        }
        let wide = n > U16_VERTEX_LIMIT;
        let (ic, isize) = if wide { (C::U32, 4) } else { (C::U16, 2) };
        push(Slot::Index, m.indices.len(), T::Scalar, ic, isize, None);
        if writes_tangents(scene, m.material) {
            push(Slot::Tangent, n, T::Vec4, C::F32, 16, None);
        }
        if let Some(ids) = &g.features {
            // Four bytes per vertex either way: u16 with a stride of 4 (vertex attribute
            // elements are 4-byte aligned), or f32.
            let c = feature_component(ids)?;
            let stride = (c == C::U16).then_some(4);
            push(Slot::Feature, n, T::Scalar, c, 4, stride);
        }
        geometries.push(GeometryLayout { arrays });
    }
    let mut images = Vec::with_capacity(pngs.len());
    for p in pngs {
        images.push((off, p.len() as u64));
        off = pad4(off + p.len() as u64);
    }
    Ok(Layout {
        geometries,
        primitive_geometry: plan
            .meshes
            .iter()
            .map(|m| m.primitives.iter().map(|&(g, _)| g).collect())
            .collect(),
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

/// Streams one geometry's arrays (plain profile) in layout order.
pub(crate) fn write_geometry<W: Write>(
    w: &mut Chunked<'_, W>,
    g: &Geometry<'_>,
    gl: &GeometryLayout,
) -> std::io::Result<()> {
    // 12 (header) + 8 + json + 8 (bin header) is a multiple of 4, so relative alignment
    // in the chunk equals absolute alignment in the file; pad after each array.
    let m = &g.mesh;
    for a in &gl.arrays {
        match a.slot {
            Slot::Position | Slot::Normal => {
                let normals = a.slot == Slot::Normal;
                let src = if normals { &m.normals } else { &m.positions };
                for p in src {
                    let p = if normals { p.normalize_or_zero() } else { *p };
                    let mut b = [0u8; 12];
                    b[0..4].copy_from_slice(&p.x.to_le_bytes());
                    b[4..8].copy_from_slice(&p.y.to_le_bytes());
                    b[8..12].copy_from_slice(&p.z.to_le_bytes());
                    w.put(&b)?;
                }
            }
            Slot::Uv => {
                for t in &m.uvs {
                    let mut b = [0u8; 8];
                    b[0..4].copy_from_slice(&t.x.to_le_bytes());
                    b[4..8].copy_from_slice(&t.y.to_le_bytes());
                    w.put(&b)?;
                }
            }
            Slot::Index => {
                if a.component == json::accessor::ComponentType::U32 {
                    for &i in &m.indices {
                        w.put(&i.to_le_bytes())?;
                    }
                } else {
                    for &i in &m.indices {
                        w.put(&(i as u16).to_le_bytes())?;
                    }
                }
            }
            Slot::Tangent => {
                for t in tangents::tangents(m) {
                    let mut b = [0u8; 16];
                    for (k, c) in t.to_array().into_iter().enumerate() {
                        b[4 * k..4 * k + 4].copy_from_slice(&c.to_le_bytes());
                    }
                    w.put(&b)?;
                }
            }
            Slot::Feature => {
                let ids = g.features.as_deref().unwrap_or_default();
                if a.component == json::accessor::ComponentType::F32 {
                    for &f in ids {
                        w.put(&(f as f32).to_le_bytes())?;
                    }
                } else {
                    for &f in ids {
                        let [lo, hi] = (f as u16).to_le_bytes();
                        w.put(&[lo, hi, 0, 0])?;
                    }
                }
            }
        }
        w.pad4()?;
    }
    Ok(())
}
