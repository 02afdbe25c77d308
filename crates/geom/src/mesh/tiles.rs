//! A mesh cut into square tiles of the ground plane (world x–z), each triangle going to
//! the tile of its centroid: the ground's tiles (cut once where the ground is built) and
//! the glb writer's tiled layout (layer-wide surfaces cut while writing) share this one
//! definition, so a mesh cut in advance is exactly what the writer would have cut.
//!
//! * The **tile** of a point is `(⌊x / s⌋, ⌊z / s⌋)` for side `s`, the coordinates as
//!   `f64` ([`tile_of`]); of a triangle, the tile of its centroid, computed in `f32` as
//!   `(a + b + c) / 3`.
//! * A **cut** ([`Mesh::cut_into_tiles`]) lists the tiles in order, each as a mesh of its
//!   own: its triangles in index order, its vertices in first-use order (the numbering
//!   that appending its triangles one by one to an empty mesh gives), only the vertices
//!   it uses. A vertex on a tile border is copied into every tile that uses it, bit for
//!   bit, so the tiles meet without a seam.

use glam::Vec3A;

use super::{Aabb3, Mesh};
use crate::par::prelude::*;

/// A tile of the x–z plane: `(⌊x / s⌋, ⌊z / s⌋)`.
pub type TileIndex = (i64, i64);

/// The tile of the point `(x, z)` for tiles of side `size`.
pub fn tile_of(x: f32, z: f32, size: f64) -> TileIndex {
    (
        (f64::from(x) / size).floor() as i64,
        (f64::from(z) / size).floor() as i64,
    )
}

/// The tile of triangle `tri` (three vertex indices of `m`): that of its centroid.
fn triangle_tile(m: &Mesh, tri: &[u32], size: f64) -> TileIndex {
    let c = (m.positions[tri[0] as usize]
        + m.positions[tri[1] as usize]
        + m.positions[tri[2] as usize])
        / 3.0;
    tile_of(c.x, c.z, size)
}

/// The triangles of `m` grouped by their tile: tiles in order, each with its triangles
/// in index order (what sorting (tile, triangle) pairs gives). A counting sort over the
/// tiles' bounding grid when it is no larger than a few cells per triangle (a
/// layer-wide surface: a ground of 1.6 million triangles over a few hundred tiles),
/// else a sorted map.
pub fn triangles_by_tile(m: &Mesh, size: f64) -> Vec<(TileIndex, Vec<u32>)> {
    let tiles: Vec<TileIndex> = m
        .indices
        .chunks_exact(3)
        .map(|tri| triangle_tile(m, tri, size))
        .collect();
    let Some(&first) = tiles.first() else {
        return Vec::new();
    };
    let (lo, hi) = tiles.iter().fold((first, first), |(lo, hi), t| {
        (
            (lo.0.min(t.0), lo.1.min(t.1)),
            (hi.0.max(t.0), hi.1.max(t.1)),
        )
    });
    let span = |a: i64, b: i64| i128::from(b) - i128::from(a) + 1;
    let cells = span(lo.0, hi.0) * span(lo.1, hi.1);
    if cells > 4 * tiles.len() as i128 + 64 {
        let mut runs: std::collections::BTreeMap<TileIndex, Vec<u32>> = Default::default();
        for (t, &tile) in tiles.iter().enumerate() {
            runs.entry(tile).or_default().push(t as u32);
        }
        return runs.into_iter().collect();
    }
    // Row-major over (i, j): the cells' order is the tiles' order.
    let columns = span(lo.1, hi.1) as usize;
    let cell = |t: TileIndex| (t.0 - lo.0) as usize * columns + (t.1 - lo.1) as usize;
    let mut count = vec![0u32; cells as usize];
    for &t in &tiles {
        count[cell(t)] += 1;
    }
    let mut slot = vec![usize::MAX; count.len()];
    let mut runs: Vec<(TileIndex, Vec<u32>)> = Vec::new();
    for (c, &n) in count.iter().enumerate() {
        if n > 0 {
            slot[c] = runs.len();
            let tile = (lo.0 + (c / columns) as i64, lo.1 + (c % columns) as i64);
            runs.push((tile, Vec::with_capacity(n as usize)));
        }
    }
    for (t, &tile) in tiles.iter().enumerate() {
        runs[slot[cell(tile)]].1.push(t as u32);
    }
    runs
}

/// The triangles `tris` of `m` as a mesh of their own (vertices in first-use order) and
/// its bounds; `remap` (all `u32::MAX`, one per vertex of `m`) maps old to new vertices
/// and is reset.
fn extract(m: &Mesh, tris: &[u32], remap: &mut [u32]) -> (Mesh, Aabb3) {
    let mut out = Mesh::new(m.material);
    let mut bounds = Aabb3::EMPTY;
    // A connected sheet has about half as many vertices as triangles; reserving one per
    // triangle spares the doubling copies without a counting pass.
    out.indices.reserve(3 * tris.len());
    for v in [&mut out.positions, &mut out.normals] {
        v.reserve(tris.len());
    }
    if !m.uvs.is_empty() {
        out.uvs.reserve(tris.len());
    }
    let mut touched = Vec::new();
    for &t in tris {
        for k in 0..3 {
            let v = m.indices[3 * t as usize + k] as usize;
            if remap[v] == u32::MAX {
                remap[v] = out.positions.len() as u32;
                touched.push(v);
                out.positions.push(m.positions[v]);
                bounds.extend(m.positions[v]);
                out.normals.push(m.normals[v]);
                if let Some(&uv) = m.uvs.get(v) {
                    out.uvs.push(uv);
                }
            }
            out.indices.push(remap[v]);
        }
    }
    for v in touched {
        remap[v] = u32::MAX;
    }
    (out, bounds)
}

/// Chunks a cut is split into (each allocates a vertex map as long as the mesh).
const CUT_CHUNKS: usize = 8;

impl Mesh {
    /// The mesh cut into tiles of side `size` (see the [module docs](self)): per tile
    /// of [`triangles_by_tile`], in its order, the tile's triangles as a mesh of their
    /// own (the same material) and its bounds. Tiles are cut in parallel, in a few
    /// chunks with one vertex map each; the result does not depend on the number of
    /// threads.
    pub fn cut_into_tiles(&self, size: f64) -> Vec<(TileIndex, Mesh, Aabb3)> {
        let runs = triangles_by_tile(self, size);
        let chunk = runs.len().div_ceil(CUT_CHUNKS).max(1);
        let chunks: Vec<&[(TileIndex, Vec<u32>)]> = runs.chunks(chunk).collect();
        let parts: Vec<Vec<(TileIndex, Mesh, Aabb3)>> = chunks
            .into_par_iter()
            .map(|runs| {
                let mut remap = vec![u32::MAX; self.vertex_count()];
                runs.iter()
                    .map(|(tile, tris)| {
                        let (part, bounds) = extract(self, tris, &mut remap);
                        (*tile, part, bounds)
                    })
                    .collect()
            })
            .collect();
        parts.into_iter().flatten().collect()
    }

    /// The one tile of side `size` this mesh is already the cut of: every triangle's
    /// centroid in that tile, every vertex used, and the vertices numbered in first-use
    /// order — so [`cut_into_tiles`](Self::cut_into_tiles) would give back the mesh
    /// itself. `None` otherwise, without triangles, with a centroid that is not finite
    /// or a side that is not positive.
    ///
    /// One pass over the triangles, without allocating or dividing per triangle (a
    /// writer checks a ground tile cut in advance this way instead of cutting it
    /// again): the tile of a point is monotone in each coordinate (a correctly rounded
    /// division by a positive side, then the floor), so when the centroids' smallest and
    /// largest coordinates share a tile, every centroid does.
    pub fn whole_tile(&self, size: f64) -> Option<TileIndex> {
        if size.is_nan() || size <= 0.0 {
            return None;
        }
        let n = self.positions.len();
        if self.indices.len() < 3
            || !self.indices.len().is_multiple_of(3)
            || self.normals.len() != n
            || !(self.uvs.is_empty() || self.uvs.len() == n)
        {
            return None;
        }
        // One pass over the triangles: the first-use numbering, and the extremes of
        // the corner sums `a + b + c` in x and z. Dividing by 3 (correctly rounded, by a
        // positive number) is monotone, so the extreme centroids are the extreme sums
        // divided once; a sum is finite exactly when its centroid is. Without branches
        // on the data: an index is in first-use order when it is at most the next new
        // number (then the next is past it), and `sum × 0` is 0 for a finite sum, NaN
        // otherwise, so their total says whether every sum was finite. The extremes
        // of finite sums are the same in the four lanes of `Vec3A` (up to the sign of
        // a zero, which gives the same tile).
        let mut next = 0usize;
        let mut ordered = true;
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let mut nonfinite = Vec3A::ZERO;
        let (triangles, _) = self.indices.as_chunks::<3>();
        for tri in triangles {
            let mut corners = [Vec3A::ZERO; 3];
            for (corner, &i) in corners.iter_mut().zip(tri) {
                let i = i as usize;
                ordered &= i <= next;
                next = next.max(i + 1);
                *corner = Vec3A::from(*self.positions.get(i)?);
            }
            // `a + b + c` as `triangle_tile` adds them (the first corner not added to
            // zero: a −0 stays −0).
            let [a, b, c] = corners;
            let sum = a + b + c;
            nonfinite += sum * 0.0;
            lo = lo.min(sum);
            hi = hi.max(sum);
        }
        let finite = nonfinite.is_finite();
        if !ordered || next != n || !finite {
            return None;
        }
        let tile = tile_of(lo.x / 3.0, lo.z / 3.0, size);
        (tile_of(hi.x / 3.0, hi.z / 3.0, size) == tile).then_some(tile)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec2, DVec3};

    /// Two unit triangles at `(x, z)` and `(x + 1, z)` sharing an edge.
    fn pair(x: f64, z: f64) -> Mesh {
        let mut m = Mesh::new(None);
        let v = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (2.0, 1.0)]
            .map(|(dx, dz)| m.add_vertex(DVec3::new(x + dx, 0.0, z + dz), DVec3::Y, DVec2::ZERO));
        m.push_triangle(v[0], v[1], v[2]).unwrap();
        m.push_triangle(v[1], v[3], v[2]).unwrap();
        m
    }

    #[test]
    fn whole_tile_holds_only_for_a_mesh_that_is_its_own_cut() {
        let m = pair(10.0, 20.0);
        assert_eq!(m.whole_tile(100.0), Some((0, 0)));
        assert_eq!(pair(-10.0, 20.0).whole_tile(100.0), Some((-1, 0)));
        // Across a tile line: two tiles.
        assert_eq!(pair(99.0, 20.0).whole_tile(100.0), None);
        // Vertices not in first-use order.
        let mut r = m.clone();
        r.indices.swap(1, 2);
        assert_eq!(r.whole_tile(100.0), None);
        // A vertex no triangle uses.
        let mut u = m.clone();
        u.add_vertex(DVec3::ZERO, DVec3::Y, DVec2::ZERO);
        assert_eq!(u.whole_tile(100.0), None);
        assert_eq!(Mesh::new(None).whole_tile(100.0), None);
        // A corner that is not finite (in any coordinate), an index past the vertices.
        for (axis, value) in [(0, f32::NAN), (1, f32::INFINITY), (2, f32::NEG_INFINITY)] {
            let mut f = m.clone();
            f.positions[3][axis] = value;
            assert_eq!(f.whole_tile(100.0), None);
        }
        let mut past = m.clone();
        past.indices[5] = 4;
        assert_eq!(past.whole_tile(100.0), None);
        // Each of those is cut into meshes that are.
        for mesh in [r, u, pair(99.0, 20.0)] {
            for (tile, part, _) in mesh.cut_into_tiles(100.0) {
                assert_eq!(part.whole_tile(100.0), Some(tile));
            }
        }
        // A mesh that is its own cut is cut into itself.
        let cut = m.cut_into_tiles(100.0);
        assert_eq!(cut.len(), 1);
        assert_eq!(cut[0].1, m);
        assert_eq!(cut[0].2, m.bbox());
    }

    proptest::proptest! {
        /// `whole_tile` answers `Some(t)` exactly when cutting the mesh gives back the
        /// mesh itself as tile `t`: meshes on a grid that straddles tile lines (−0 and
        /// +0 among the coordinates), triangles in any vertex order.
        #[test]
        fn whole_tile_is_a_cut_that_gives_the_mesh_back(
            corners in proptest::collection::vec((-6i32..6, -6i32..6, proptest::bool::ANY), 3..12),
            triangles in proptest::collection::vec((0usize..12, 0usize..12, 0usize..12), 1..8),
            size in proptest::sample::select(vec![1.0, 2.5, 3.0, 100.0]),
        ) {
            let mut m = Mesh::new(None);
            for &(x, z, negative_zero) in &corners {
                let z = if z == 0 && negative_zero { -0.0 } else { f64::from(z) * 0.75 };
                m.add_vertex(DVec3::new(f64::from(x) * 0.5, 0.0, z), DVec3::Y, DVec2::ZERO);
            }
            let n = corners.len();
            for &(a, b, c) in &triangles {
                m.indices.extend([a % n, b % n, c % n].map(|i| i as u32));
            }
            let cut = m.cut_into_tiles(size);
            let is_own_cut = cut.len() == 1 && cut[0].1 == m;
            let expected = is_own_cut.then(|| cut[0].0);
            proptest::prop_assert_eq!(m.whole_tile(size), expected);
        }
    }
}
