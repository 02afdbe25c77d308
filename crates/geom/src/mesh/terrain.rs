//! Terrain: the ground of a whole map as one mesh, an adaptive quadtree over an elevation
//! field with a stated, checked error bound.
//!
//! [`Terrain::build`] covers a rectangle with square-ish root cells of at most
//! [`TerrainOptions::max_cell_m`] and splits a cell into four while its surface misses
//! the field by more than [`TerrainOptions::max_error_m`] at its *check points* (the
//! 5 × 5 lattice of quarter points of the cell), down to
//! [`TerrainOptions::min_cell_m`]. Each leaf is a fan of triangles around its centre
//! through every vertex on its border, its own corners and the corners of smaller
//! neighbours (*hanging* vertices), so the mesh has no cracks and no T-junctions. Leaves
//! whose border gained hanging vertices are checked again with their final fan, and split
//! if they now miss the bound (repeated until nothing changes).
//!
//! Every point the refinement checks is sampled once per leaf, in batches through
//! [`Field::sample_many`] (a split samples its leaf at twice the resolution, which gives
//! its four children their check points); each round of checks and of splits runs in
//! parallel through [`crate::par`], and a leaf is checked again only when its border
//! gained a corner. The decisions are taken in leaf order, so the mesh does not depend on
//! the thread count.
//!
//! The surface is **one-sided**: every vertex lies `max_error_m` *below* the field (and
//! half the slack lower where [`Terrain::build_with_slack`] gives one), so where the
//! interpolation is within the bound the surface lies between `2·max_error_m` (plus the
//! slack) below the field and the field itself. Things that stand on the field (road surfaces a
//! few centimetres above it, plinths reaching below it, buildings seated at their
//! corners) are then never buried by the terrain, and float above it by at most
//! `2·max_error_m` plus their own lift.
//!
//! [`Terrain::build_with_slack`] also takes a *slack* field: the surface may lie that much
//! further below the field (the check's lower side moves down by it; its upper side
//! stays with the field). The vertices then sit half the slack under the field, in the
//! middle of the band the check allows, so a fan may sag under them (a kink that bends
//! down: a ridge, a bank's top, the outer edge of a cut) or rise over them (a kink that
//! bends up: a valley, the foot of a bank) by half the slack more than `max_error_m`
//! before its leaf splits. A caller that must keep things under the field unburied (the
//! graded ground's road corridors) keeps the field's upper side.
//!
//! # Guarantees
//! * At every check point of every leaf, `field − slack − 2·max_error_m ≤ surface ≤
//!   field` (`slack` is 0 without a slack field),
//!   except in [`TerrainReport::unresolved_leaves`] (leaves at the minimum size or
//!   beyond the leaf budget that still miss the bound — cliffs, steps; their largest miss
//!   is [`TerrainReport::max_error_m`]). Those leaves' vertices are lowered by their fan's
//!   largest rise above the field at their check points (at most that miss), so
//!   `surface ≤ field` holds at every check point of every leaf (the one side that keeps
//!   things standing on the field unburied), while a fan that misses only on one side is
//!   lowered only as far as it rises, not to the bottom of the step. The vertices they
//!   share with neighbouring leaves go down with them, so a neighbour's surface may lie
//!   lower than `field − 2·max_error_m` near them, by at most that rise.
//! * The mesh is a 2-manifold with boundary (every interior edge used twice, in opposite
//!   directions), every triangle faces up, and it covers the rectangle exactly.
//! * Deterministic: a pure function of the field (and slack), the rectangle and the options.
//!
//! # Limitations
//! * Between check points (a quarter of a leaf apart) the miss can exceed the bound by
//!   the field's curvature: at most `κ·(s/4)²/8` for a leaf of side `s` (0.03 m for a
//!   64 m leaf on ground curving by 0.001 m⁻¹).
//! * A field that is not finite somewhere inside the rectangle is an error.
//!
//! # References
//! * Kelly 2008, §4.2 and §6.2 (roads and the city mapped onto the terrain);
//!   Parish & Müller 2001, §3 (elevation as an input map). The quadtree with crack-free
//!   fans is the usual restricted-quadtree terrain scheme (Lindstrom et al. 1996; Pajarola
//!   1998), written here from its description.

use glam::DVec2;

use super::{Mesh, to_world};
use crate::field::Field;
use crate::scene::MaterialId;
use crate::{Aabb2, GeomError, MAX_COORDINATE};

/// Options of [`Terrain::build`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct TerrainOptions {
    /// Largest vertical miss between the interpolated field and the field at the check
    /// points, metres (finite, > 0). The surface lies up to twice this below the field.
    /// Default: 0.2.
    pub max_error_m: f64,
    /// Largest leaf side, metres (finite, ≥ `min_cell_m`). Default: 64.
    pub max_cell_m: f64,
    /// Smallest leaf side, metres (finite, > 0). Default: 2.
    pub min_cell_m: f64,
    /// Most leaves (≥ 1): refinement stops there and the rest is reported unresolved.
    /// Default: 1,000,000.
    pub max_leaves: usize,
}

impl Default for TerrainOptions {
    fn default() -> Self {
        TerrainOptions {
            max_error_m: 0.2,
            max_cell_m: 64.0,
            min_cell_m: 2.0,
            max_leaves: 1_000_000,
        }
    }
}

impl TerrainOptions {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<(), GeomError> {
        let bad = |name: &'static str, reason: String| GeomError::InvalidParameter { name, reason };
        if !(self.max_error_m.is_finite() && self.max_error_m > 0.0) {
            return Err(bad(
                "max_error_m",
                format!("{} must be a finite number > 0", self.max_error_m),
            ));
        }
        if !(self.min_cell_m.is_finite() && self.min_cell_m > 0.0) {
            return Err(bad(
                "min_cell_m",
                format!("{} must be a finite number > 0", self.min_cell_m),
            ));
        }
        if !(self.max_cell_m.is_finite() && self.max_cell_m >= self.min_cell_m) {
            return Err(bad(
                "max_cell_m",
                format!(
                    "{} must be finite and at least min_cell_m ({})",
                    self.max_cell_m, self.min_cell_m
                ),
            ));
        }
        if self.max_leaves == 0 {
            return Err(bad("max_leaves", "must be at least 1".into()));
        }
        Ok(())
    }
}

/// What [`Terrain::build`] made.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct TerrainReport {
    /// Quadtree leaves.
    pub leaves: usize,
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Largest miss met at the check points, metres: `|interpolated − field|`, or with a
    /// slack field how far the interpolation lies above the field or below the field less
    /// the slack.
    pub max_error_m: f64,
    /// Leaves that still miss the bound (at the minimum size or beyond the leaf budget).
    pub unresolved_leaves: usize,
}

/// One quadtree leaf, in lattice units (the lattice step is the smallest leaf side).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Leaf {
    x: u64,
    y: u64,
    size: u64,
}

/// The terrain: its mesh and what it needs to answer heights at any point.
#[derive(Debug, Clone)]
pub struct Terrain {
    /// The ground surface: one up-facing, smooth-shaded sheet; texture coordinates map
    /// the rectangle onto the unit square (`u` east, `v` south: an image drawn north up).
    pub mesh: Mesh,
    /// Sizes and the error met.
    pub report: TerrainReport,
    grid: Lattice,
    leaves: Vec<Leaf>,
    /// Leaf corners sorted by `(y, x)` and by `(x, y)`, with the surface's height there
    /// (before the offset).
    rows: Vec<(Corner, f64)>,
    cols: Vec<(Corner, f64)>,
    centre_heights: Vec<f64>,
    /// Root cell → its leaves (indices into `leaves`).
    roots: Vec<Vec<u32>>,
    offset: f64,
}

/// The mapping between lattice units and metres.
#[derive(Debug, Clone, Copy)]
struct Lattice {
    min: DVec2,
    max: DVec2,
    unit: DVec2,
    /// Root cells along x and y.
    nx: u64,
    ny: u64,
    /// Lattice units per root cell side.
    root: u64,
}

impl Lattice {
    fn point(&self, x: f64, y: f64) -> DVec2 {
        DVec2::new(self.min.x + x * self.unit.x, self.min.y + y * self.unit.y)
    }
}

/// A leaf corner in lattice units, `(y, x)` or `(x, y)`.
type Corner = (u64, u64);

/// The heights along one edge of a leaf: `(parameter in [0, 1], field)`, sorted.
type EdgeProfile = Vec<(f64, f64)>;

impl Terrain {
    /// Builds the terrain of `field` over `bounds` (see the [module docs](self)).
    ///
    /// Fails on invalid options, an empty, non-finite or too large rectangle (beyond
    /// [`MAX_COORDINATE`]), or a field that is not finite at a sample point.
    pub fn build(
        field: &dyn Field,
        bounds: Aabb2,
        options: &TerrainOptions,
        material: Option<MaterialId>,
    ) -> Result<Terrain, GeomError> {
        Terrain::build_inner(field, None, bounds, options, material)
    }

    /// Builds the terrain of `field` over `bounds` where the surface may also lie up to
    /// `slack` metres further below the field (see the [module docs](self)): a check
    /// point misses when the fan lies more than `max_error_m` above the field or more
    /// than `max_error_m` below the field less the slack there. The vertices lie half
    /// the slack under the field (the middle of that band), so a kink that bends down
    /// (a ridge, the outer edge of a cut) or up (a valley, the foot of a bank) needs no
    /// refinement where half the slack covers the fan's sag under, or rise over, its
    /// vertices. Slack values below 0 or not a number count as 0; a slack of 0
    /// everywhere builds the terrain [`build`](Terrain::build) builds. The vertices
    /// follow the slack, so a slack that jumps makes the surface step where it does
    /// (leaves there may end unresolved): give it a taper.
    ///
    /// Fails as [`build`](Terrain::build) does.
    pub fn build_with_slack(
        field: &dyn Field,
        slack: &dyn Field,
        bounds: Aabb2,
        options: &TerrainOptions,
        material: Option<MaterialId>,
    ) -> Result<Terrain, GeomError> {
        Terrain::build_inner(field, Some(slack), bounds, options, material)
    }

    fn build_inner(
        field: &dyn Field,
        slack: Option<&dyn Field>,
        bounds: Aabb2,
        options: &TerrainOptions,
        material: Option<MaterialId>,
    ) -> Result<Terrain, GeomError> {
        options.validate()?;
        let ok = |v: f64| v.is_finite() && v.abs() <= MAX_COORDINATE;
        let size = bounds.max - bounds.min;
        if !(ok(bounds.min.x) && ok(bounds.min.y) && ok(bounds.max.x) && ok(bounds.max.y))
            || size.x <= 0.0
            || size.y <= 0.0
        {
            return Err(GeomError::InvalidParameter {
                name: "bounds",
                reason: format!(
                    "{:?}–{:?} must be a non-empty finite rectangle",
                    bounds.min, bounds.max
                ),
            });
        }
        let nx = ((size.x / options.max_cell_m).ceil() as u64).clamp(1, 4096);
        let ny = ((size.y / options.max_cell_m).ceil() as u64).clamp(1, 4096);
        let cell = DVec2::new(size.x / nx as f64, size.y / ny as f64);
        let mut levels = 0u32;
        while cell.max_element() / f64::from(1u32 << levels) > options.min_cell_m && levels < 16 {
            levels += 1;
        }
        // One lattice unit is half the smallest leaf, so every leaf's centre is a
        // lattice point.
        let root = 2u64 << levels;
        let grid = Lattice {
            min: bounds.min,
            max: bounds.max,
            unit: cell / root as f64,
            nx,
            ny,
            root,
        };
        let e = options.max_error_m;
        let refined = refine::refine(&grid, field, slack, e, options.max_leaves)?;
        let (leaves, checks): (Vec<Leaf>, Vec<refine::Checks>) = refined.leaves.into_iter().unzip();
        let (mut rows, mut cols) = (refined.rows, refined.cols);
        let mut centre_heights: Vec<f64> = checks.iter().map(|c| c.vertex(12)).collect();
        // Leaves that still miss the bound (cliffs, steps): every vertex of their fan is
        // lowered by the fan's largest rise above the field at their check points (the
        // fan is linear in its vertex heights, so it then lies below the field there);
        // lowering shared vertices only lowers neighbours. The rises are measured on the
        // unlowered fans, then applied together (order-independent).
        let mut flagged = refined.flagged;
        flagged.sort_unstable_by_key(|l| (l.y, l.x, l.size));
        flagged.dedup();
        let mut drops: Vec<(usize, f64)> = Vec::with_capacity(flagged.len());
        for f in &flagged {
            let Ok(k) = leaves.binary_search_by_key(&(f.y, f.x), |l| (l.y, l.x)) else {
                continue;
            };
            let leaf = leaves[k];
            if leaf.size != f.size {
                continue;
            }
            let profiles = edge_profiles(leaf, &rows, &cols);
            let rise = leaf_rise(&profiles, &checks[k]);
            if rise > 0.0 {
                drops.push((k, rise));
            }
        }
        let (row_orig, col_orig, centre_orig) = if drops.is_empty() {
            (Vec::new(), Vec::new(), Vec::new())
        } else {
            (rows.clone(), cols.clone(), centre_heights.clone())
        };
        for &(k, drop) in &drops {
            let leaf = leaves[k];
            let sz = leaf.size;
            for (line, from, along_rows) in [
                (leaf.y, leaf.x, true),
                (leaf.y + sz, leaf.x, true),
                (leaf.x, leaf.y, false),
                (leaf.x + sz, leaf.y, false),
            ] {
                let keys = if along_rows { &row_orig } else { &col_orig };
                let lo = keys.partition_point(|&(q, _)| q < (line, from));
                let hi = keys.partition_point(|&(q, _)| q <= (line, from + sz));
                for &((a, b), _) in keys.get(lo..hi).unwrap_or_default() {
                    let (row_key, col_key) = if along_rows {
                        ((a, b), (b, a))
                    } else {
                        ((b, a), (a, b))
                    };
                    if let Ok(r) = row_orig.binary_search_by_key(&row_key, |&(q, _)| q) {
                        rows[r].1 = rows[r].1.min(row_orig[r].1 - drop);
                    }
                    if let Ok(c) = col_orig.binary_search_by_key(&col_key, |&(q, _)| q) {
                        cols[c].1 = cols[c].1.min(col_orig[c].1 - drop);
                    }
                }
            }
            centre_heights[k] = centre_heights[k].min(centre_orig[k] - drop);
        }
        let mut roots = vec![Vec::new(); (nx * ny) as usize];
        for (k, l) in leaves.iter().enumerate() {
            let r = (l.y / root) * nx + l.x / root;
            if let Some(list) = roots.get_mut(r as usize) {
                list.push(k as u32);
            }
        }
        let mut terrain = Terrain {
            mesh: Mesh::new(material),
            report: TerrainReport {
                leaves: leaves.len(),
                triangles: 0,
                max_error_m: refined.worst,
                unresolved_leaves: refined.unresolved,
            },
            grid,
            leaves,
            rows,
            cols,
            centre_heights,
            roots,
            offset: e,
        };
        terrain.mesh = terrain.make_mesh(material)?;
        terrain.report.triangles = terrain.mesh.triangle_count();
        Ok(terrain)
    }

    /// The surface's height at `p` (metres, the mesh's own interpolation before rounding
    /// to `f32`), or `None` outside the rectangle.
    pub fn height_at(&self, p: DVec2) -> Option<f64> {
        let g = &self.grid;
        let lx = (p.x - g.min.x) / g.unit.x;
        let ly = (p.y - g.min.y) / g.unit.y;
        let (wx, wy) = ((g.nx * g.root) as f64, (g.ny * g.root) as f64);
        if !(lx >= 0.0 && ly >= 0.0 && lx <= wx && ly <= wy) {
            return None;
        }
        let rx = ((lx / g.root as f64) as u64).min(g.nx - 1);
        let ry = ((ly / g.root as f64) as u64).min(g.ny - 1);
        let list = self.roots.get((ry * g.nx + rx) as usize)?;
        for &k in list {
            let leaf = *self.leaves.get(k as usize)?;
            let s = leaf.size as f64;
            let (u, v) = ((lx - leaf.x as f64) / s, (ly - leaf.y as f64) / s);
            if (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v) {
                let profiles = edge_profiles(leaf, &self.rows, &self.cols);
                let centre = *self.centre_heights.get(k as usize)?;
                return Some(fan_height(&profiles, centre, u, v) - self.offset);
            }
        }
        None
    }

    /// The fans of every leaf as one up-facing mesh.
    fn make_mesh(&self, material: Option<MaterialId>) -> Result<Mesh, GeomError> {
        let g = &self.grid;
        let size = g.max - g.min;
        let mut mesh = Mesh::with_capacity(
            material,
            self.rows.len() + self.leaves.len(),
            6 * self.leaves.len(),
        );
        let uv = |p: DVec2| DVec2::new((p.x - g.min.x) / size.x, (g.max.y - p.y) / size.y);
        for &((y, x), h) in &self.rows {
            let p = g.point(x as f64, y as f64);
            mesh.add_vertex(to_world(p, h - self.offset), glam::DVec3::Y, uv(p));
        }
        // Vertex `k` is corner `rows[k]`; `col_ids[k]` is the vertex of corner `cols[k]`.
        let mut col_ids: Vec<((u64, u64), u32)> = self
            .rows
            .iter()
            .enumerate()
            .map(|(k, &((y, x), _))| ((x, y), k as u32))
            .collect();
        col_ids.sort_unstable_by_key(|&(key, _)| key);
        let col_ids: Vec<u32> = col_ids.into_iter().map(|(_, k)| k).collect();
        let row = |y: u64, a: u64, b: u64| {
            let lo = self.rows.partition_point(|&(k, _)| k < (y, a));
            let hi = self.rows.partition_point(|&(k, _)| k <= (y, b));
            lo as u32..hi.max(lo) as u32
        };
        let col = |x: u64, a: u64, b: u64| {
            let lo = self.cols.partition_point(|&(k, _)| k < (x, a));
            let hi = self.cols.partition_point(|&(k, _)| k <= (x, b));
            col_ids.get(lo..hi).unwrap_or_default()
        };
        let mut ring: Vec<u32> = Vec::new();
        for (leaf, &hc) in self.leaves.iter().zip(&self.centre_heights) {
            let s = leaf.size;
            let c = g.point(
                leaf.x as f64 + s as f64 / 2.0,
                leaf.y as f64 + s as f64 / 2.0,
            );
            let centre = mesh.add_vertex(to_world(c, hc - self.offset), glam::DVec3::Y, uv(c));
            // The border counter-clockwise: bottom (x up), right (y up), top (x down),
            // left (y down); each corner once.
            ring.clear();
            ring.extend(row(leaf.y, leaf.x, leaf.x + s - 1));
            ring.extend(col(leaf.x + s, leaf.y, leaf.y + s - 1));
            ring.extend(row(leaf.y + s, leaf.x + 1, leaf.x + s).rev());
            ring.extend(col(leaf.x, leaf.y + 1, leaf.y + s).iter().rev());
            for k in 0..ring.len() {
                let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                mesh.push_triangle(centre, a, b)?;
            }
        }
        mesh.compute_smooth_normals()?;
        Ok(mesh)
    }
}

/// Appends the four children of `leaf`.
fn split(leaf: Leaf, out: &mut Vec<Leaf>) {
    let h = leaf.size / 2;
    for (dx, dy) in [(0, 0), (h, 0), (0, h), (h, h)] {
        out.push(Leaf {
            x: leaf.x + dx,
            y: leaf.y + dy,
            size: h,
        });
    }
}

/// Where the corners on the leaf's four edges (bottom, right, top, left) lie in `rows`
/// (the bottom and top edges) and `cols` (the right and left edges): the corners with
/// their heights, sorted by `(y, x)` and by `(x, y)`.
fn edge_ranges(
    leaf: Leaf,
    rows: &[(Corner, f64)],
    cols: &[(Corner, f64)],
) -> [std::ops::Range<usize>; 4] {
    let s = leaf.size;
    let along = |keys: &[(Corner, f64)], line: u64, from: u64| {
        let lo = keys.partition_point(|&(k, _)| k < (line, from));
        let hi = keys.partition_point(|&(k, _)| k <= (line, from + s));
        lo..hi.max(lo)
    };
    [
        along(rows, leaf.y, leaf.x),
        along(cols, leaf.x + s, leaf.y),
        along(rows, leaf.y + s, leaf.x),
        along(cols, leaf.x, leaf.y),
    ]
}

/// The height profiles of the leaf's four edges (bottom, right, top, left), each
/// parametrised from its lower-left end, through every corner on it (see
/// [`edge_ranges`]).
fn edge_profiles(leaf: Leaf, rows: &[(Corner, f64)], cols: &[(Corner, f64)]) -> [EdgeProfile; 4] {
    profiles_in(leaf, rows, cols, &edge_ranges(leaf, rows, cols))
}

/// [`edge_profiles`] from the leaf's [`edge_ranges`], found already.
fn profiles_in(
    leaf: Leaf,
    rows: &[(Corner, f64)],
    cols: &[(Corner, f64)],
    ranges: &[std::ops::Range<usize>; 4],
) -> [EdgeProfile; 4] {
    let (s, from) = (leaf.size, [leaf.x, leaf.y, leaf.x, leaf.y]);
    let keys = [rows, cols, rows, cols];
    std::array::from_fn(|e| {
        keys[e]
            .get(ranges[e].clone())
            .unwrap_or_default()
            .iter()
            .map(|&((_, t), h)| ((t - from[e]) as f64 / s as f64, h))
            .collect()
    })
}

/// The height of a sorted edge profile at parameter `t`.
fn profile_at(p: &[(f64, f64)], t: f64) -> f64 {
    let i = p
        .partition_point(|&(q, _)| q <= t)
        .clamp(1, p.len().max(2) - 1);
    match (p.get(i - 1), p.get(i)) {
        (Some(&(t0, h0)), Some(&(t1, h1))) if t1 > t0 => h0 + (h1 - h0) * (t - t0) / (t1 - t0),
        (Some(&(_, h0)), _) => h0,
        _ => 0.0,
    }
}

/// The fan's height at local coordinates `(u, v)` in `[0, 1]²`: on the ray from the
/// centre through the point, linear between the centre and the border profile.
fn fan_height(profiles: &[EdgeProfile; 4], centre: f64, u: f64, v: f64) -> f64 {
    let (du, dv) = (u - 0.5, v - 0.5);
    let m = du.abs().max(dv.abs());
    if m <= 0.0 {
        return centre;
    }
    let lambda = m / 0.5;
    // Where the ray meets the border, and along which edge.
    let (eu, ev) = (0.5 + du / lambda, 0.5 + dv / lambda);
    let border = if dv.abs() >= du.abs() {
        if dv < 0.0 {
            profile_at(&profiles[0], eu)
        } else {
            profile_at(&profiles[2], eu)
        }
    } else if du > 0.0 {
        profile_at(&profiles[1], ev)
    } else {
        profile_at(&profiles[3], ev)
    };
    (1.0 - lambda) * centre + lambda * border
}

/// The fan's largest rise above the field at the leaf's check points (0 when it lies
/// below the field at all of them); check points where the field is not finite are
/// skipped.
fn leaf_rise(profiles: &[EdgeProfile; 4], checks: &refine::Checks) -> f64 {
    let mut worst = 0.0f64;
    for (k, &f) in checks.field.iter().enumerate() {
        let (u, v) = (
            f64::from((k % 5) as u32) / 4.0,
            f64::from((k / 5) as u32) / 4.0,
        );
        if f.is_finite() {
            worst = worst.max(fan_height(profiles, checks.vertex(12), u, v) - f);
        }
    }
    worst
}

mod refine;
#[cfg(test)]
mod tests;
