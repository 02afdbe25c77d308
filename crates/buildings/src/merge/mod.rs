//! One closed 2-manifold per building: the stacked parts merged into one solid.
//!
//! A building's [`Part`]s are closed solids glued face to face: a wall mass's top cap
//! lies under a roof's bottom cap, a setback tower stands on the podium's roof. Each part
//! is closed, but their union drawn as is is not a 2-manifold (the glued caps are
//! duplicate faces, and the rings where they meet are used by four triangles).
//! [`merge_parts`] removes the glued faces and stitches the rings:
//!
//! 1. **Levels.** Every horizontal triangle lies at a level; levels closer than
//!    [`LEVEL_TOLERANCE`] are one level, and vertices that near a level are moved onto
//!    it (the interpreter's `base + height` and the next part's base can differ by a
//!    rounding step).
//! 2. **Overlay per level.** At a level with both up-facing triangles (tops of parts
//!    below, region `U`) and down-facing ones (bottoms of parts above, region `D`), the
//!    merged surface keeps `U \ D` facing up and `D \ U` facing down. When both regions
//!    have the same boundary (a roof on its mass) both simply go. Otherwise the boundary
//!    edges of `U` and `D` are split where they cross, touch or overlap (exact
//!    [`segment_intersection`]), every piece is kept or dropped by which side of the
//!    other region it lies on, the kept pieces are chained into rings, and the rings
//!    (outer rings with their holes) are triangulated again.
//! 3. **T-junctions.** Every other triangle with an edge on a split boundary edge is
//!    fanned from its opposite corner through the split points, so walls, roofs and
//!    caps share every edge exactly.
//! 4. **Check.** The result must pass the edge-use check ([`polis_geom::mesh::edge_use()`]):
//!    every edge used exactly twice in opposite directions, positive volume.
//!
//! # Guarantees
//! A returned [`MergedSolid`] with `closed == true` passed the edge-use check and
//! [`Mesh::validate`]: closed, 2-manifold, consistently wound, outward, with the parts'
//! total volume minus nothing (glued faces enclose no volume). Triangles keep their
//! part's role (walls, roofs, details) so the scene can give each its material; new
//! horizontal triangles take the role of the part whose cap they come from.
//! Deterministic.
//!
//! # Limitations
//! Parts may meet only at horizontal planes (stacking, setbacks, overhangs, roofs,
//! spires, antennas: everything the shipped grammars make). Parts that overlap in volume
//! or touch along walls (two boxes side by side in a user grammar) are not unioned; the
//! parts are then returned unmerged with `closed == false`, and so is any building whose
//! merge fails the check (counted by the scene, never a panic). Two parts touching along
//! a single edge make a non-manifold edge by nature and are returned unmerged too.
//!
//! # References
//! Parish & Müller 2001 §4.2 (buildings as stacked grammar volumes); the overlay is the
//! usual boolean of polygon boundaries (keep the pieces of each boundary that lie
//! outside the other region).

use polis_geom::glam::{Vec2, Vec3};
use std::collections::HashMap;

use polis_geom::hash::{FxBuild, point_key};
use polis_geom::lines::{ccw_cmp_from, innermost_ring_containing};
use polis_geom::mesh::{edge_use, to_world};
use polis_geom::polygon::ring_signed_area;
use polis_geom::{
    DVec2, DVec3, Mesh, Orientation, Polygon, PolygonWithHoles, SegmentIntersection, orient2d,
    segment_intersection, triangulate,
};

use crate::building::{Building, Part, PartRole};

mod stack;

/// Horizontal levels (and vertices near them) closer than this, in metres, are one level.
///
/// Far below any storey or roof dimension, far above the rounding steps (`f32` at a few
/// hundred metres: about 3e-5 m) by which glued caps can differ.
pub const LEVEL_TOLERANCE: f64 = 1e-3;

/// A building's mass as one surface, split by role (one mesh per role that has
/// triangles, in [`PartRole`] order: mass, roof, detail, template).
#[derive(Debug, Clone, PartialEq)]
pub struct MergedSolid {
    /// The meshes (local coordinates, as the parts).
    pub meshes: Vec<(PartRole, Mesh)>,
    /// Whether the meshes together passed the edge-use check (one closed, 2-manifold,
    /// outward solid). When `false`, `meshes` are the parts unmerged.
    pub closed: bool,
    /// Why the parts were not merged (`None` when `closed`).
    pub unmerged_because: Option<&'static str>,
}

impl Building {
    /// The building's parts merged into one closed 2-manifold (see [`merge_parts`]).
    pub fn merged_solid(&self) -> MergedSolid {
        merge_parts(&self.parts)
    }
}

/// A triangle of the merge: corners (f64 of the stored f32 values), its flat normal and
/// texture coordinates, and its role.
#[derive(Clone, Copy)]
struct Tri {
    p: [DVec3; 3],
    uv: [DVec2; 3],
    normal: Vec3,
    role: PartRole,
}

/// The roles in output order.
const ROLES: [PartRole; 4] = [
    PartRole::Mass,
    PartRole::Roof,
    PartRole::Detail,
    PartRole::Template,
];

/// The parts as meshes by role, unmerged.
fn unmerged(parts: &[Part], why: &'static str) -> MergedSolid {
    let mut meshes: Vec<(PartRole, Mesh)> = Vec::new();
    for role in ROLES {
        let m = Mesh::merged(
            None,
            parts.iter().filter(|p| p.role == role).map(|p| &p.mesh),
        );
        if !m.is_empty() {
            meshes.push((role, m));
        }
    }
    MergedSolid {
        meshes,
        closed: false,
        unmerged_because: Some(why),
    }
}

/// Merges a building's parts into one closed 2-manifold (see the [module docs](self)).
///
/// Never fails: parts that cannot be merged come back unmerged with `closed == false`.
/// A single part is returned as it is, unchecked (the buildings stage makes every part
/// closed); merged parts are checked.
pub fn merge_parts(parts: &[Part]) -> MergedSolid {
    match try_merge(parts) {
        Ok(solid) => solid,
        Err(why) => unmerged(parts, why),
    }
}

/// Why a merge gave up.
type Why = &'static str;

fn try_merge(parts: &[Part]) -> Result<MergedSolid, Why> {
    if parts.is_empty() {
        return Err("the building has no parts");
    }
    // One part is already one closed solid: the interpreter builds every part closed
    // (see the crate's guarantees), so there is nothing to merge or check.
    if let [only] = parts {
        return Ok(MergedSolid {
            meshes: vec![(only.role, only.mesh.clone())],
            closed: true,
            unmerged_because: None,
        });
    }
    // Stacks glued on identical caps (most buildings) need no overlay.
    if let Some(solid) = stack::identical_stack(parts) {
        return Ok(solid);
    }
    // Triangles with their attributes.
    let mut tris: Vec<Tri> = Vec::new();
    for part in parts {
        let m = &part.mesh;
        for t in m.triangles() {
            let get = |i: u32| {
                let i = i as usize;
                Some((
                    m.positions.get(i)?.as_dvec3(),
                    m.uvs.get(i)?.as_dvec2(),
                    *m.normals.get(i)?,
                ))
            };
            let bad = "a part's triangle names a vertex it does not have";
            let [a, b, c] = [
                get(t[0]).ok_or(bad)?,
                get(t[1]).ok_or(bad)?,
                get(t[2]).ok_or(bad)?,
            ];
            tris.push(Tri {
                p: [a.0, b.0, c.0],
                uv: [a.1, b.1, c.1],
                normal: a.2,
                role: part.role,
            });
        }
    }
    snap_levels(&mut tris);
    // Horizontal triangles by level and facing; everything else stays.
    let mut levels: Vec<f64> = tris
        .iter()
        .filter(|t| is_horizontal(t))
        .map(|t| t.p[0].y)
        .collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let mut out: Vec<Tri> = Vec::with_capacity(tris.len());
    let mut splits: Vec<Split> = Vec::new();
    let mut at_level: Vec<Vec<Tri>> = vec![Vec::new(); levels.len()];
    for t in tris {
        if is_horizontal(&t) {
            let k = levels
                .binary_search_by(|l| l.total_cmp(&t.p[0].y))
                .map_err(|_| "a level was lost")?;
            at_level[k].push(t);
        } else {
            out.push(t);
        }
    }
    for (&y, level) in levels.iter().zip(&at_level) {
        let (up, down): (Vec<Tri>, Vec<Tri>) = level.iter().partition(|t| faces_up(t));
        if up.is_empty() || down.is_empty() {
            out.extend_from_slice(level);
            continue;
        }
        overlay(y, &up, &down, &mut out, &mut splits)?;
    }
    // T-junctions: fan every triangle with an edge that was split.
    splits.sort_by_key(|s| s.key);
    // An edge on both boundaries was cut on each side: one list with every point.
    let mut merged: Vec<Split> = Vec::with_capacity(splits.len());
    for s in splits {
        match merged.last_mut() {
            Some(last) if last.key == s.key => {
                let lo = DVec3::from_array(s.key.0.map(f32::from_bits).map(f64::from));
                last.points.extend(s.points);
                last.points
                    .sort_by(|p, q| lo.distance_squared(*p).total_cmp(&lo.distance_squared(*q)));
                last.points.dedup();
            }
            _ => merged.push(s),
        }
    }
    let splits = merged;
    let mut fixed: Vec<Tri> = Vec::with_capacity(out.len());
    for t in out {
        fan_split(&t, &splits, &mut fixed);
    }
    // Meshes by role.
    let mut meshes: Vec<(PartRole, Mesh)> = Vec::new();
    for role in ROLES {
        let mut m = Mesh::new(None);
        for t in fixed.iter().filter(|t| t.role == role) {
            let base = m.positions.len() as u32;
            for k in 0..3 {
                m.positions.push(t.p[k].as_vec3());
                m.normals.push(t.normal);
                m.uvs.push(t.uv[k].as_vec2());
            }
            m.indices.extend([base, base + 1, base + 2]);
        }
        if !m.is_empty() {
            weld(&mut m);
            meshes.push((role, m));
        }
    }
    let report = edge_use(meshes.iter().map(|(_, m)| m));
    if !report.is_solid() {
        return Err("the merged surface fails the edge-use check");
    }
    if meshes.iter().any(|(_, m)| m.validate().is_err()) {
        return Err("the merged surface has a degenerate triangle");
    }
    Ok(MergedSolid {
        meshes,
        closed: true,
        unmerged_because: None,
    })
}

/// Merges vertices with identical position, normal and texture coordinates (a flat face
/// then shares its corners, as the parts' meshes did). Each class of identical vertices
/// keeps its lowest-numbered member's values (`-0.0` and `+0.0` are one value), and the
/// kept vertices are numbered in first-use order of the indices.
fn weld(m: &mut Mesh) {
    let n = m.positions.len();
    let key = |i: usize| {
        let (p, nr, uv) = (m.positions[i], m.normals[i], m.uvs[i]);
        [p.x, p.y, p.z, nr.x, nr.y, nr.z, uv.x, uv.y].map(|v| (v + 0.0).to_bits())
    };
    // Each vertex's representative: the first vertex with its key.
    let mut first_of: HashMap<[u32; 8], u32, FxBuild> =
        HashMap::with_capacity_and_hasher(n, FxBuild::default());
    let rep: Vec<u32> = (0..n)
        .map(|i| *first_of.entry(key(i)).or_insert(i as u32))
        .collect();
    let classes = first_of.len();
    drop(first_of);
    // Renumber in first-use order for a stable, cache-friendly layout.
    let mut first = vec![u32::MAX; n];
    let mut positions: Vec<Vec3> = Vec::with_capacity(classes);
    let mut normals: Vec<Vec3> = Vec::with_capacity(classes);
    let mut uvs: Vec<Vec2> = Vec::with_capacity(classes);
    for idx in &mut m.indices {
        let Some(&src) = rep.get(*idx as usize) else {
            continue;
        };
        let src = src as usize;
        if first[src] == u32::MAX {
            first[src] = positions.len() as u32;
            positions.push(m.positions[src]);
            normals.push(m.normals[src]);
            uvs.push(m.uvs[src]);
        }
        *idx = first[src];
    }
    m.positions = positions;
    m.normals = normals;
    m.uvs = uvs;
}

fn is_horizontal(t: &Tri) -> bool {
    t.p[0].y == t.p[1].y && t.p[1].y == t.p[2].y
}

/// The layout point of a world point.
#[inline]
fn flat(p: DVec3) -> DVec2 {
    DVec2::new(p.x, -p.z)
}

/// Whether a horizontal triangle faces up, by its face's normal: a sliver of a cap
/// (a corner that was collinear before rounding to `f32`) may wind either way, but its
/// edges still pair with its neighbours', so it belongs to its face's side.
fn faces_up(t: &Tri) -> bool {
    t.normal.y > 0.0
}

/// Moves every vertex within [`LEVEL_TOLERANCE`] of a horizontal triangle's level onto
/// that level (levels themselves are clustered from the lowest up).
fn snap_levels(tris: &mut [Tri]) {
    let mut raw: Vec<f64> = tris
        .iter()
        .filter(|t| {
            (t.p[0].y - t.p[1].y).abs() <= LEVEL_TOLERANCE
                && (t.p[1].y - t.p[2].y).abs() <= LEVEL_TOLERANCE
                && (t.p[0].y - t.p[2].y).abs() <= LEVEL_TOLERANCE
        })
        .map(|t| t.p[0].y)
        .collect();
    raw.sort_by(f64::total_cmp);
    let mut reps: Vec<f64> = Vec::new();
    for y in raw {
        if reps.last().is_none_or(|&r| y - r > LEVEL_TOLERANCE) {
            reps.push(y);
        }
    }
    if reps.is_empty() {
        return;
    }
    for t in tris {
        for p in &mut t.p {
            let k = reps.partition_point(|&r| r < p.y);
            let near = [k.checked_sub(1), Some(k)]
                .into_iter()
                .flatten()
                .filter_map(|i| reps.get(i))
                .copied()
                .filter(|r| (r - p.y).abs() <= LEVEL_TOLERANCE)
                .min_by(|a, b| (a - p.y).abs().total_cmp(&(b - p.y).abs()));
            if let Some(r) = near {
                p.y = r;
            }
        }
    }
}

/// An edge key: the two ends' `f32` bits in a fixed order, at a level.
type Key = ([u32; 3], [u32; 3]);

fn pkey(p: DVec3) -> [u32; 3] {
    (p.as_vec3() + Vec3::ZERO).to_array().map(f32::to_bits)
}

/// A boundary edge that was split: its key (lower end first) and the interior points
/// from the lower end to the other.
struct Split {
    key: Key,
    points: Vec<DVec3>,
}

/// A directed boundary segment in the layout, region on its left.
#[derive(Clone, Copy)]
struct Seg {
    a: DVec2,
    b: DVec2,
}

/// The boundary of the union of triangles (counter-clockwise seen from `ccw_from`):
/// their directed edges that no other triangle runs the other way.
fn boundary(tris: &[Tri], reverse: bool) -> Vec<Seg> {
    let mut edges: Vec<(DVec2, DVec2)> = Vec::with_capacity(3 * tris.len());
    for t in tris {
        let q = t.p.map(flat);
        for k in 0..3 {
            let (a, b) = (q[k], q[(k + 1) % 3]);
            edges.push(if reverse { (b, a) } else { (a, b) });
        }
    }
    let bits = point_key;
    let mut sorted: Vec<([u64; 2], [u64; 2])> =
        edges.iter().map(|&(a, b)| (bits(a), bits(b))).collect();
    sorted.sort_unstable();
    edges
        .into_iter()
        .filter(|&(a, b)| sorted.binary_search(&(bits(b), bits(a))).is_err())
        .map(|(a, b)| Seg { a, b })
        .collect()
}

/// Whether `p` lies in the closed union of the horizontal triangles `tris`.
fn in_region(tris: &[Tri], p: DVec2) -> Option<PartRole> {
    tris.iter()
        .find(|t| {
            let [a, b, c] = t.p.map(flat);
            let (a, b) = if orient2d(a, b, c) == Orientation::CounterClockwise {
                (a, b)
            } else {
                (b, a)
            };
            // The corners in counter-clockwise order: a, b, c.
            orient2d(a, b, p) != Orientation::Clockwise
                && orient2d(b, c, p) != Orientation::Clockwise
                && orient2d(c, a, p) != Orientation::Clockwise
        })
        .map(|t| t.role)
}

/// Round a computed point to what the mesh will store, so every later decision sees it.
fn stored(p: DVec2) -> DVec2 {
    p.as_vec2().as_dvec2()
}

/// The pieces of each segment of `own` cut at every point where a segment of `other`
/// crosses, touches or overlaps it.
fn cut(own: &[Seg], other: &[Seg]) -> Vec<Vec<DVec2>> {
    own.iter()
        .map(|s| {
            let mut pts = vec![s.a, s.b];
            for o in other {
                match segment_intersection(s.a, s.b, o.a, o.b) {
                    SegmentIntersection::Disjoint => {}
                    SegmentIntersection::Crossing { point, .. } => pts.push(stored(point)),
                    SegmentIntersection::Touching { point, .. } => pts.push(point),
                    SegmentIntersection::Overlap { start, end, .. } => pts.extend([start, end]),
                }
            }
            let d = s.b - s.a;
            let len2 = d.length_squared();
            pts.sort_by(|p, q| ((*p - s.a).dot(d) / len2).total_cmp(&((*q - s.a).dot(d) / len2)));
            pts.dedup();
            pts
        })
        .collect()
}

/// Replaces the up-facing triangles `up` and down-facing `down` of level `y` by `U \ D`
/// (up) and `D \ U` (down) in `out`, recording split boundary edges in `splits`.
fn overlay(
    y: f64,
    up: &[Tri],
    down: &[Tri],
    out: &mut Vec<Tri>,
    splits: &mut Vec<Split>,
) -> Result<(), Why> {
    let bu = boundary(up, false);
    let bd = boundary(down, true);
    // Same region: both caps go.
    let bits = |s: &Seg| {
        let (a, b) = (point_key(s.a), point_key(s.b));
        [a[0], a[1], b[0], b[1]]
    };
    let mut ku: Vec<[u64; 4]> = bu.iter().map(bits).collect();
    let mut kd: Vec<[u64; 4]> = bd.iter().map(bits).collect();
    ku.sort_unstable();
    kd.sort_unstable();
    if ku == kd {
        return Ok(());
    }
    let cu = cut(&bu, &bd);
    let cd = cut(&bd, &bu);
    // Undirected pieces of each side, to find pieces on both boundaries.
    let pkey2 = |a: DVec2, b: DVec2| {
        let (a, b) = (point_key(a), point_key(b));
        if a <= b { (a, b, true) } else { (b, a, false) }
    };
    let pieces = |c: &[Vec<DVec2>]| {
        let mut v: Vec<_> = c
            .iter()
            .flat_map(|pts| pts.windows(2).map(|w| pkey2(w[0], w[1])))
            .collect();
        v.sort_unstable();
        v
    };
    let (pu, pd) = (pieces(&cu), pieces(&cd));
    let shared = |list: &[([u64; 2], [u64; 2], bool)], a: DVec2, b: DVec2| {
        let (lo, hi, dir) = pkey2(a, b);
        let i = list.partition_point(|e| (e.0, e.1) < (lo, hi));
        list.get(i)
            .filter(|e| e.0 == lo && e.1 == hi)
            .map(|e| e.2 == dir)
    };
    let mut keep_up: Vec<Seg> = Vec::new();
    let mut keep_down: Vec<Seg> = Vec::new();
    for (own, other_tris, other_pieces, keep, rev) in
        [(&cu, down, &pd, 0usize, 1usize), (&cd, up, &pu, 1, 0)]
    {
        for pts in own.iter() {
            for w in pts.windows(2) {
                let (a, b) = (w[0], w[1]);
                if a == b {
                    continue;
                }
                match shared(other_pieces, a, b) {
                    // On both boundaries, same direction: both regions on one side,
                    // neither on the other — no boundary of either difference.
                    Some(true) => {}
                    // Opposite directions: this region on the left, the other on the
                    // right; the piece bounds this region's difference.
                    Some(false) => push(&mut keep_up, &mut keep_down, keep, Seg { a, b }),
                    None => {
                        let mid = (a + b) * 0.5;
                        if in_region(other_tris, mid).is_some() {
                            push(&mut keep_up, &mut keep_down, rev, Seg { a: b, b: a });
                        } else {
                            push(&mut keep_up, &mut keep_down, keep, Seg { a, b });
                        }
                    }
                }
            }
        }
    }
    // Record splits of the original boundary edges.
    for (segs, c) in [(&bu, &cu), (&bd, &cd)] {
        for (s, pts) in segs.iter().zip(c) {
            if pts.len() > 2 {
                let (a, b) = (to_world(s.a, y), to_world(s.b, y));
                let inner: Vec<DVec3> = pts[1..pts.len() - 1]
                    .iter()
                    .map(|&p| to_world(p, y))
                    .collect();
                let (ka, kb) = (pkey(a), pkey(b));
                let (key, points) = if ka <= kb {
                    ((ka, kb), inner)
                } else {
                    ((kb, ka), inner.into_iter().rev().collect())
                };
                splits.push(Split { key, points });
            }
        }
    }
    for (segs, facing_up, src) in [(keep_up, true, up), (keep_down, false, down)] {
        for poly in chain(&segs)? {
            emit(y, &poly, facing_up, src, out)?;
        }
    }
    Ok(())
}

fn push(up: &mut Vec<Seg>, down: &mut Vec<Seg>, which: usize, s: Seg) {
    if which == 0 {
        up.push(s);
    } else {
        down.push(s);
    }
}

/// Chains directed segments (region on the left) into rings and groups them into
/// polygons with holes. `None` if the segments do not close into rings.
fn chain(segs: &[Seg]) -> Result<Vec<PolygonWithHoles>, Why> {
    let bits = point_key;
    let mut order: Vec<usize> = (0..segs.len()).collect();
    order.sort_by_key(|&i| bits(segs[i].a));
    let mut used = vec![false; segs.len()];
    let mut rings: Vec<Vec<DVec2>> = Vec::new();
    for start in 0..segs.len() {
        if used[start] {
            continue;
        }
        let mut ring = Vec::new();
        let mut cur = start;
        loop {
            used[cur] = true;
            let s = segs[cur];
            ring.push(s.a);
            if s.b == segs[start].a {
                break;
            }
            // Outgoing segments at s.b not used yet; at a pinch, the first clockwise
            // from the way back keeps the region on the left.
            let lo = order.partition_point(|&i| bits(segs[i].a) < bits(s.b));
            let back = s.a - s.b;
            let next = order[lo..]
                .iter()
                .take_while(|&&i| segs[i].a == s.b)
                .copied()
                .filter(|&i| !used[i])
                .max_by(|&i, &j| ccw_cmp_from(back, segs[i].b - s.b, segs[j].b - s.b))
                .ok_or("a cap's boundary does not close")?;
            cur = next;
            if ring.len() > segs.len() {
                return Err("a cap's boundary does not close");
            }
        }
        rings.push(ring);
    }
    let (outers, holes): (Vec<Vec<DVec2>>, Vec<Vec<DVec2>>) =
        rings.into_iter().partition(|r| ring_signed_area(r) > 0.0);
    let mut polys: Vec<PolygonWithHoles> = outers
        .into_iter()
        .map(|r| PolygonWithHoles::new(Polygon::new(r), Vec::new()))
        .collect();
    for h in holes {
        let probe = h
            .iter()
            .copied()
            .find(|&p| !polys.iter().any(|o| o.outer.points().contains(&p)))
            .ok_or("a hole touches its ring")?;
        let i = innermost_ring_containing(polys.iter().map(|o| o.outer.points()), probe)
            .ok_or("a hole lies in no ring")?;
        if let Some(o) = polys.get_mut(i) {
            o.holes.push(Polygon::new(h));
        }
    }
    Ok(polys)
}

/// Triangulates `poly` at level `y` into `out`, facing up or down; each triangle takes
/// the role of the source triangle under its centroid.
fn emit(
    y: f64,
    poly: &PolygonWithHoles,
    up: bool,
    src: &[Tri],
    out: &mut Vec<Tri>,
) -> Result<(), Why> {
    let tris = triangulate(poly).map_err(|_| "a merged cap cannot be triangulated")?;
    let pts: Vec<DVec2> = poly
        .rings()
        .flat_map(|(_, r)| r.points().iter().copied())
        .collect();
    let fallback = src.first().ok_or("a cap without triangles")?.role;
    let (normal, sign) = if up { (Vec3::Y, -1.0) } else { (-Vec3::Y, 1.0) };
    for [a, b, c] in tris {
        let q = [a, b, c].map(|i| pts.get(i as usize).copied());
        let [Some(a), Some(b), Some(c)] = q else {
            return Err("a merged cap cannot be triangulated");
        };
        let role = in_region(src, (a + b + c) / 3.0).unwrap_or(fallback);
        let corners = if up { [a, b, c] } else { [a, c, b] };
        out.push(Tri {
            p: corners.map(|p| to_world(p, y)),
            uv: corners.map(|p| DVec2::new(p.x, sign * p.y)),
            normal,
            role,
        });
    }
    Ok(())
}

/// Appends `t`, fanned from its opposite corner through the split points of an edge.
fn fan_split(t: &Tri, splits: &[Split], out: &mut Vec<Tri>) {
    for k in 0..3 {
        let (i, j, o) = (k, (k + 1) % 3, (k + 2) % 3);
        let (a, b) = (t.p[i], t.p[j]);
        if a.y != b.y {
            continue;
        }
        let (ka, kb) = (pkey(a), pkey(b));
        let key = if ka <= kb { (ka, kb) } else { (kb, ka) };
        let Ok(s) = splits.binary_search_by(|s| s.key.cmp(&key)) else {
            continue;
        };
        let pts: Vec<DVec3> = if ka <= kb {
            splits[s].points.clone()
        } else {
            splits[s].points.iter().rev().copied().collect()
        };
        let len = a.distance(b);
        let uv_at = |p: DVec3| {
            let f = if len > 0.0 { a.distance(p) / len } else { 0.0 };
            t.uv[i].lerp(t.uv[j], f)
        };
        let mut prev = (a, t.uv[i]);
        for p in pts.into_iter().chain(std::iter::once(b)) {
            let cur = if p == b { (b, t.uv[j]) } else { (p, uv_at(p)) };
            out.push(Tri {
                p: [prev.0, cur.0, t.p[o]],
                uv: [prev.1, cur.1, t.uv[o]],
                normal: t.normal,
                role: t.role,
            });
            prev = cur;
        }
        return;
    }
    out.push(*t);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solid::prism;
    use polis_geom::Polygon;

    fn part(ring: &[DVec2], z0: f64, z1: f64, role: PartRole) -> Part {
        Part {
            mesh: prism(ring, z0, z1).unwrap(),
            role,
        }
    }

    fn volume(parts: &[Part]) -> f64 {
        parts.iter().map(|p| p.mesh.signed_volume()).sum()
    }

    fn check(parts: &[Part]) -> MergedSolid {
        let m = merge_parts(parts);
        assert!(m.closed, "not merged");
        let r = edge_use(m.meshes.iter().map(|(_, m)| m));
        assert!(r.is_solid(), "{r:?}");
        assert_eq!(r.components, 1);
        assert!(
            (r.signed_volume - volume(parts)).abs() < 1e-3 * volume(parts),
            "{} vs {}",
            r.signed_volume,
            volume(parts)
        );
        m
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<DVec2> {
        Polygon::rect(DVec2::new(x0, y0), DVec2::new(x1, y1)).into_points()
    }

    #[test]
    fn identical_rings_stack_into_one_box() {
        let r = rect(-5.0, -4.0, 5.0, 4.0);
        let m = check(&[
            part(&r, 0.0, 6.0, PartRole::Mass),
            part(&r, 6.0, 7.0, PartRole::Roof),
        ]);
        // Two caps gone: 12 walls triangles... the merged box has 8 wall + 4 cap triangles
        // (two bands of walls, top and bottom).
        let tris: usize = m.meshes.iter().map(|(_, m)| m.triangle_count()).sum();
        assert_eq!(tris, 8 + 8 + 2 + 2);
        assert_eq!(m.meshes.len(), 2);
    }

    #[test]
    fn setback_and_overhang_and_crossing() {
        let base = rect(-10.0, -10.0, 10.0, 10.0);
        // Strictly inside: a ring with a hole.
        check(&[
            part(&base, 0.0, 5.0, PartRole::Mass),
            part(&rect(-4.0, -4.0, 4.0, 6.0), 5.0, 20.0, PartRole::Mass),
        ]);
        // Overhanging on one side, crossing two walls: T-junctions on the walls.
        check(&[
            part(&base, 0.0, 5.0, PartRole::Mass),
            part(&rect(-4.0, -4.0, 14.0, 6.0), 5.0, 20.0, PartRole::Mass),
        ]);
        // Sharing part of a wall line (collinear overlap) and a corner.
        check(&[
            part(&base, 0.0, 5.0, PartRole::Mass),
            part(&rect(-10.0, -10.0, 2.0, 3.0), 5.0, 8.0, PartRole::Mass),
        ]);
        // Larger on top (a cantilevered floor).
        check(&[
            part(&rect(-4.0, -4.0, 4.0, 4.0), 0.0, 5.0, PartRole::Mass),
            part(&base, 5.0, 8.0, PartRole::Mass),
        ]);
        // Three storeys, the roof and an antenna on the top.
        let top = rect(-6.0, -6.0, 6.0, 6.0);
        check(&[
            part(&base, 0.0, 5.0, PartRole::Mass),
            part(&top, 5.0, 30.0, PartRole::Mass),
            part(&top, 30.0, 30.5, PartRole::Roof),
            part(&rect(-0.5, -0.5, 0.5, 0.5), 30.5, 40.0, PartRole::Detail),
        ]);
    }

    #[test]
    fn levels_a_rounding_step_apart_are_glued() {
        let r = rect(0.0, 0.0, 7.0, 3.0);
        let z = 0.1 + 0.2;
        check(&[
            part(&r, 0.0, z, PartRole::Mass),
            part(&r, 0.3 + 1e-6, 2.0, PartRole::Roof),
        ]);
    }

    #[test]
    fn parts_side_by_side_stay_unmerged() {
        let a = part(&rect(0.0, 0.0, 5.0, 5.0), 0.0, 5.0, PartRole::Mass);
        let b = part(&rect(5.0, 0.0, 10.0, 5.0), 0.0, 5.0, PartRole::Mass);
        let m = merge_parts(&[a, b]);
        assert!(!m.closed);
        assert!(merge_parts(&[]).meshes.is_empty());
    }

    /// The weld as it was first written: vertices sorted by (key, index), each class's
    /// lowest index kept, renumbered in first-use order. [`weld`] must give the same
    /// mesh bit for bit.
    fn weld_by_sorting(m: &mut Mesh) {
        let n = m.positions.len();
        let key = |i: usize| {
            let (p, nr, uv) = (m.positions[i], m.normals[i], m.uvs[i]);
            [p.x, p.y, p.z, nr.x, nr.y, nr.z, uv.x, uv.y].map(|v| (v + 0.0).to_bits())
        };
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by_key(|&i| (key(i), i));
        let mut remap = vec![0u32; n];
        let mut keep: Vec<usize> = Vec::with_capacity(n);
        for (k, &i) in order.iter().enumerate() {
            if k == 0 || key(order[k - 1]) != key(i) {
                keep.push(i);
            }
            remap[i] = keep.len() as u32 - 1;
        }
        let mut first = vec![u32::MAX; keep.len()];
        let (mut positions, mut normals, mut uvs) = (Vec::new(), Vec::new(), Vec::new());
        for idx in &mut m.indices {
            let c = remap[*idx as usize] as usize;
            if first[c] == u32::MAX {
                first[c] = positions.len() as u32;
                positions.push(m.positions[keep[c]]);
                normals.push(m.normals[keep[c]]);
                uvs.push(m.uvs[keep[c]]);
            }
            *idx = first[c];
        }
        m.positions = positions;
        m.normals = normals;
        m.uvs = uvs;
    }

    fn same_bits(a: &Mesh, b: &Mesh) -> bool {
        let v3 = |v: &[Vec3]| {
            v.iter()
                .flat_map(|p| p.to_array())
                .map(f32::to_bits)
                .collect::<Vec<_>>()
        };
        let v2 = |v: &[Vec2]| {
            v.iter()
                .flat_map(|p| p.to_array())
                .map(f32::to_bits)
                .collect::<Vec<_>>()
        };
        a.indices == b.indices
            && v3(&a.positions) == v3(&b.positions)
            && v3(&a.normals) == v3(&b.normals)
            && v2(&a.uvs) == v2(&b.uvs)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        /// Welding by hashing equals welding by sorting, bit for bit: same kept values
        /// (a class's lowest vertex, `-0.0` against `+0.0` included), same numbering, on
        /// meshes with many repeated vertices in any order and unused ones.
        #[test]
        fn weld_by_hashing_equals_weld_by_sorting(
            vertices in proptest::collection::vec((0u8..4, 0u8..3, 0u8..3, proptest::bool::ANY), 1..60),
            triangles in proptest::collection::vec((0usize..1000, 0usize..1000, 0usize..1000), 0..40),
        ) {
            let value = |k: u8, negative: bool| match (k, negative) {
                (0, true) => -0.0,
                (0, false) => 0.0,
                (k, _) => f32::from(k) * 0.25,
            };
            let mut m = Mesh::new(None);
            for &(p, nr, uv, neg) in &vertices {
                m.positions.push(Vec3::new(value(p, neg), value(p % 2, !neg), 1.0));
                m.normals.push(Vec3::new(0.0, value(nr, neg), 1.0));
                m.uvs.push(Vec2::new(value(uv, !neg), 0.5));
            }
            let n = vertices.len();
            for &(a, b, c) in &triangles {
                m.indices.extend([a % n, b % n, c % n].map(|i| i as u32));
            }
            let mut hashed = m.clone();
            weld(&mut hashed);
            let mut sorted = m;
            weld_by_sorting(&mut sorted);
            proptest::prop_assert!(same_bits(&hashed, &sorted));
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(128))]

        /// Two stacked boxes in any relative position that overlaps merge into one
        /// outward solid with the sum of their volumes.
        #[test]
        fn stacked_boxes_merge(
            a in (-20i32..0, -20i32..0, 1i32..20, 1i32..20),
            b in (-20i32..0, -20i32..0, 1i32..20, 1i32..20),
            scale in proptest::sample::select(vec![1.0, 0.5, 0.37]),
            h in (1.0f64..10.0, 1.0f64..10.0),
        ) {
            let r = |(x0, y0, x1, y1): (i32, i32, i32, i32)| {
                rect(f64::from(x0) * scale, f64::from(y0) * scale, f64::from(x1) * scale, f64::from(y1) * scale)
            };
            let parts = [
                part(&r(a), 0.0, h.0, PartRole::Mass),
                part(&r(b), h.0, h.0 + h.1, PartRole::Roof),
            ];
            let m = merge_parts(&parts);
            proptest::prop_assert!(m.closed);
            let rep = edge_use(m.meshes.iter().map(|(_, m)| m));
            proptest::prop_assert!(rep.is_solid());
            let v = volume(&parts);
            proptest::prop_assert!((rep.signed_volume - v).abs() < 1e-3 * v);
        }
    }
}
