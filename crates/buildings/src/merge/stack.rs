//! The fast path of the merge: parts stacked on identical caps.
//!
//! Most buildings are a stack whose glued caps coincide exactly: a roof on its wall mass,
//! a slab on its storeys (same ring, same `f32` level). Then the merged solid is the
//! parts without those caps, and it is closed by construction: every edge of a removed
//! cap's boundary was used by the cap and one wall of its part, and is now used by the
//! two walls (or wall and roof face), which run it in opposite directions because the
//! two caps did; interior cap edges disappear with both their triangles. This holds when
//! the parts touch nowhere else, which the path checks from their heights: two parts
//! may share at most one level, and only a glued one. So this path copies the kept
//! triangles with their vertices, and needs no overlay and no edge-use check.

use polis_geom::Mesh;
use polis_geom::glam::Vec3;

use super::{MergedSolid, ROLES};
use crate::building::Part;

/// A horizontal triangle: its level (`f32` bits of y), facing, part and triangle index.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Cap {
    level: u32,
    up: bool,
    part: u32,
    triangle: u32,
}

/// A layout edge: the `f32` bits of its lower end's x and z, the other end's, and 1 if
/// it runs from the higher end to the lower.
type Edge = [u32; 5];

/// Reusable buffers (one set per thread).
#[derive(Default)]
struct Work {
    caps: Vec<Cap>,
    dropped: Vec<Vec<bool>>,
    up: Vec<Edge>,
    down: Vec<Edge>,
    remap: Vec<u32>,
    glued: Vec<u32>,
}

thread_local! {
    static WORK: std::cell::RefCell<Work> = std::cell::RefCell::default();
}

fn bits(v: f32) -> u32 {
    (v + 0.0).to_bits()
}

/// The merged solid when every level where caps meet has identical up and down caps at
/// the same `f32` level; `None` otherwise (the general merge decides).
pub(super) fn identical_stack(parts: &[Part]) -> Option<MergedSolid> {
    WORK.with(|w| match w.try_borrow_mut() {
        Ok(mut w) => run(parts, &mut w),
        Err(_) => run(parts, &mut Work::default()),
    })
}

fn run(parts: &[Part], w: &mut Work) -> Option<MergedSolid> {
    let Work {
        caps,
        dropped,
        up,
        down,
        remap,
        glued,
    } = w;
    glued.clear();
    caps.clear();
    for (pi, part) in parts.iter().enumerate() {
        let m = &part.mesh;
        for (ti, t) in m.triangles().enumerate() {
            let [a, b, c] = t.map(|i| m.positions.get(i as usize).copied());
            let (Some(a), Some(b), Some(c)) = (a, b, c) else {
                return None;
            };
            if a.y == b.y && b.y == c.y {
                let n = m.normals.get(t[0] as usize).copied().unwrap_or(Vec3::ZERO);
                caps.push(Cap {
                    level: bits(a.y),
                    up: n.y > 0.0,
                    part: pi as u32,
                    triangle: ti as u32,
                });
            }
        }
    }
    caps.sort_unstable();
    dropped.resize_with(parts.len(), Vec::new);
    for (d, p) in dropped.iter_mut().zip(parts) {
        d.clear();
        d.resize(p.mesh.triangle_count(), false);
    }
    // Levels in order; a level near another (a rounding step apart) is not for this path.
    let mut k = 0;
    let mut last_level: Option<f32> = None;
    while k < caps.len() {
        let level = caps[k].level;
        let mut end = k;
        while end < caps.len() && caps[end].level == level {
            end += 1;
        }
        let y = f32::from_bits(level);
        if last_level.is_some_and(|l| f64::from(y - l) <= super::LEVEL_TOLERANCE) {
            return None;
        }
        last_level = Some(y);
        let group = &caps[k..end];
        let split = group.partition_point(|c| !c.up);
        let (downs, ups) = group.split_at(split);
        if !downs.is_empty() && !ups.is_empty() {
            boundary(parts, ups, false, up);
            boundary(parts, downs, true, down);
            if up != down {
                return None;
            }
            for c in group {
                dropped[c.part as usize][c.triangle as usize] = true;
            }
            glued.push(level);
        }
        k = end;
    }
    // The parts may touch only where caps were glued: pairwise, their heights overlap
    // in at most one glued level (parts side by side, or two on one roof, go to the
    // general merge).
    for (i, a) in parts.iter().enumerate() {
        let (a0, a1) = (a.mesh.bbox().min.y, a.mesh.bbox().max.y);
        for b in &parts[i + 1..] {
            let (b0, b1) = (b.mesh.bbox().min.y, b.mesh.bbox().max.y);
            let (lo, hi) = (a0.max(b0), a1.min(b1));
            if lo < hi || (lo == hi && glued.binary_search(&bits(lo)).is_err()) {
                return None;
            }
        }
    }
    // Copy the kept triangles with their vertices, per role.
    let mut meshes: Vec<(crate::building::PartRole, Mesh)> = Vec::new();
    for role in ROLES {
        let mut out = Mesh::new(None);
        for (part, drop) in parts
            .iter()
            .zip(dropped.iter())
            .filter(|(p, _)| p.role == role)
        {
            let m = &part.mesh;
            remap.clear();
            remap.resize(m.vertex_count(), u32::MAX);
            for (t, &gone) in m.triangles().zip(drop.iter()) {
                if gone {
                    continue;
                }
                for i in t {
                    let i = i as usize;
                    if remap[i] == u32::MAX {
                        remap[i] = out.positions.len() as u32;
                        out.positions.push(m.positions[i]);
                        out.normals.push(m.normals[i]);
                        out.uvs.push(m.uvs[i]);
                    }
                    out.indices.push(remap[i]);
                }
            }
        }
        if !out.is_empty() {
            meshes.push((role, out));
        }
    }
    Some(MergedSolid {
        meshes,
        closed: true,
        unmerged_because: None,
    })
}

/// The boundary of a set of cap triangles as sorted edges, region on one fixed side
/// (down caps reversed): the edges no other triangle of the set runs the other way.
/// Edges are gathered undirected with their direction in the last word, so interior
/// edges (one use each way) cancel in one sorted pass.
fn boundary(parts: &[Part], caps: &[Cap], reverse: bool, out: &mut Vec<Edge>) {
    out.clear();
    for c in caps {
        let m = &parts[c.part as usize].mesh;
        let t = c.triangle as usize * 3;
        let p = [0, 1, 2].map(|k| {
            let v = m.positions[m.indices[t + k] as usize];
            [bits(v.x), bits(v.z)]
        });
        for k in 0..3 {
            let (a, b) = (p[k], p[(k + 1) % 3]);
            let (a, b) = if reverse { (b, a) } else { (a, b) };
            out.push(if a <= b {
                [a[0], a[1], b[0], b[1], 0]
            } else {
                [b[0], b[1], a[0], a[1], 1]
            });
        }
    }
    out.sort_unstable();
    let mut keep = 0;
    let mut k = 0;
    while k < out.len() {
        let interior = k + 1 < out.len()
            && out[k][..4] == out[k + 1][..4]
            && out[k][4] != out[k + 1][4]
            && (k + 2 >= out.len() || out[k + 2][..4] != out[k][..4]);
        if interior {
            k += 2;
        } else {
            out[keep] = out[k];
            keep += 1;
            k += 1;
        }
    }
    out.truncate(keep);
}
