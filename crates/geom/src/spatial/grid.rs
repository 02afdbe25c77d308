//! [`GridIndex`]: a hashed uniform grid.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use glam::DVec2;

use super::{GridOptions, IndexKey, Shape, SpatialIndex};
use crate::bbox::Aabb2;
use crate::error::GeomError;

/// A small, fast, deterministic hasher (the multiply-rotate scheme of Firefox's "FxHash",
/// with a final bit mix).
/// Only used for lookups; no output ever depends on hash-map iteration order.
#[derive(Default, Clone, Copy)]
pub(crate) struct FxHasher(u64);

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut buf = [0u8; 8];
            buf[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(buf));
        }
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(SEED);
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_i64(&mut self, i: i64) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        // A final avalanche (MurmurHash3's fmix64): the multiply above leaves the low bits,
        // which pick the bucket, depending on the low input bits only.
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h
    }
}

pub(crate) type FxBuild = BuildHasherDefault<FxHasher>;

type Cell = (i64, i64);

/// Segments whose bounding box covers at most this many cells are entered in every cell
/// of the box (so a box query can report each once, from its first cell, without
/// de-duplication); longer ones are rasterised along their line.
const BOX_CELLS_MAX: i64 = 4;

/// Segments spanning more than this many cells (columns plus rows) are not entered in
/// cells at all but kept in a short list that every query scans: a few very long
/// segments (a 100 km highway on 1 m cells) then cost neither memory nor insert time.
const BIG_SPAN: i64 = 4096;

/// What a cell lists: the shape itself (copied into every cell it is entered in, so a
/// query reads each cell's list contiguously instead of chasing pointers).
#[derive(Debug, Clone, Copy)]
struct Entry<K> {
    key: K,
    shape: Shape,
    /// Bounding box of the shape.
    bbox: Aabb2,
    /// Lowest cell of the bounding box.
    first: Cell,
    /// Whether the shape is rasterised (entered in a subset of its box's cells).
    raster: bool,
}

/// Cells per chunk side (a power of two).
const CHUNK_BITS: u32 = 3;
const CHUNK: i64 = 1 << CHUNK_BITS;

#[derive(Debug, Clone)]
struct Chunk<K> {
    cells: Vec<Vec<Entry<K>>>,
    used: usize,
}

#[inline]
fn chunk_of(c: Cell) -> (Cell, usize) {
    let key = (c.0 >> CHUNK_BITS, c.1 >> CHUNK_BITS);
    let idx = ((c.0 & (CHUNK - 1)) * CHUNK + (c.1 & (CHUNK - 1))) as usize;
    (key, idx)
}

/// A spatial index that buckets shapes into the square cells of a uniform grid (hashed, so
/// only occupied cells cost memory). A short segment is entered in every cell of its
/// bounding box, a longer one in every cell it passes through (conservatively), a point
/// in its one cell.
///
/// Insert and remove are `O(cells covered)`; a query visits the cells under its box (or,
/// for [`segments_crossing`](SpatialIndex::segments_crossing), along its segment) and
/// refines the candidates exactly. Fast when segments are about the size of a cell and
/// spread evenly — a road network. See [`GridOptions`].
#[derive(Debug, Clone)]
pub struct GridIndex<K> {
    options: GridOptions,
    inv: f64,
    /// Chunks of `CHUNK × CHUNK` cells, keyed by chunk coordinates: one hash lookup
    /// serves many neighbouring cells, and their lists sit side by side.
    chunks: HashMap<Cell, Chunk<K>, FxBuild>,
    occupied: usize,
    /// Segments too long for the cells (see `BIG_SPAN`).
    big: Vec<Entry<K>>,
    lookup: HashMap<K, Shape, FxBuild>,
    /// Range of cells ever occupied (never shrinks): queries are clipped to it.
    extent: Option<(Cell, Cell)>,
}

impl<K: IndexKey> Default for GridIndex<K> {
    fn default() -> Self {
        GridIndex::build(GridOptions::default())
    }
}

impl<K: IndexKey> GridIndex<K> {
    /// An empty grid with the given options.
    ///
    /// # Errors
    /// [`GeomError::InvalidParameter`] if the cell size is not finite or below
    /// [`GridOptions::MIN_CELL_SIZE`].
    pub fn new(options: GridOptions) -> Result<Self, GeomError> {
        let s = options.cell_size;
        if !(s.is_finite() && s >= GridOptions::MIN_CELL_SIZE) {
            return Err(GeomError::InvalidParameter {
                name: "cell_size",
                reason: format!(
                    "{s} m; use a finite size of at least {} m",
                    GridOptions::MIN_CELL_SIZE
                ),
            });
        }
        Ok(Self::build(options))
    }

    fn build(options: GridOptions) -> Self {
        GridIndex {
            options,
            inv: 1.0 / options.cell_size,
            chunks: HashMap::default(),
            occupied: 0,
            big: Vec::new(),
            lookup: HashMap::default(),
            extent: None,
        }
    }

    /// The options the grid was built with.
    pub fn options(&self) -> GridOptions {
        self.options
    }

    /// Number of occupied cells (for statistics).
    pub fn occupied_cells(&self) -> usize {
        self.occupied
    }

    #[inline]
    fn cell_coord(&self, x: f64) -> i64 {
        // Finite and bounded by MAX_COORDINATE / MIN_CELL_SIZE: fits i64; `as` saturates.
        (x * self.inv).floor() as i64
    }

    /// The lowest cell of the shape's box, and whether it is rasterised.
    fn placement(&self, shape: &Shape) -> (Cell, bool) {
        let b = shape.bbox();
        let (i0, j0) = (self.cell_coord(b.min.x), self.cell_coord(b.min.y));
        let (i1, j1) = (self.cell_coord(b.max.x), self.cell_coord(b.max.y));
        let count = (i1 - i0 + 1).saturating_mul(j1 - j0 + 1);
        ((i0, j0), count > BOX_CELLS_MAX)
    }

    /// Whether a shape goes to the list of big segments instead of the cells.
    fn is_big(&self, shape: &Shape) -> bool {
        let b = shape.bbox();
        let span = (self.cell_coord(b.max.x) - self.cell_coord(b.min.x))
            .saturating_add(self.cell_coord(b.max.y) - self.cell_coord(b.min.y));
        span > BIG_SPAN
    }

    /// Calls `f` for every cell the shape is entered in.
    fn cells_of(&self, shape: &Shape, raster: bool, mut f: impl FnMut(Cell)) {
        match *shape {
            Shape::Segment(a, b) if raster => self.segment_cells(a, b, None, &mut f),
            _ => {
                let b = shape.bbox();
                let (i0, j0) = (self.cell_coord(b.min.x), self.cell_coord(b.min.y));
                let (i1, j1) = (self.cell_coord(b.max.x), self.cell_coord(b.max.y));
                for i in i0..=i1 {
                    for j in j0..=j1 {
                        f((i, j));
                    }
                }
            }
        }
    }

    /// Conservative rasterisation of the segment `a–b`: every cell the segment meets is
    /// reported (and possibly a few neighbours), column by column. With `clip`, only
    /// cells inside that range.
    fn segment_cells(
        &self,
        a: DVec2,
        b: DVec2,
        clip: Option<(Cell, Cell)>,
        f: &mut impl FnMut(Cell),
    ) {
        let (lo, hi) = (a.min(b), a.max(b));
        let (mut i0, mut i1) = (self.cell_coord(lo.x), self.cell_coord(hi.x));
        let (j_lo, j_hi) = (self.cell_coord(lo.y), self.cell_coord(hi.y));
        if let Some(((ci0, _), (ci1, _))) = clip {
            i0 = i0.max(ci0);
            i1 = i1.min(ci1);
        }
        let s = self.options.cell_size;
        // Slack for rounding in the column bounds and the line evaluation.
        let margin = s * 1e-6 + hi.abs().max(lo.abs()).max_element() * 1e-12;
        let dx = b.x - a.x;
        for i in i0..=i1 {
            let (mut j0, mut j1) = if dx == 0.0 || i0 == i1 {
                (j_lo, j_hi)
            } else {
                let x0 = (i as f64 * s - margin).max(lo.x);
                let x1 = ((i + 1) as f64 * s + margin).min(hi.x);
                let slope = (b.y - a.y) / dx;
                let y0 = a.y + (x0 - a.x) * slope;
                let y1 = a.y + (x1 - a.x) * slope;
                let ylo = (y0.min(y1) - margin).max(lo.y);
                let yhi = (y0.max(y1) + margin).min(hi.y);
                (
                    self.cell_coord(ylo).max(j_lo),
                    self.cell_coord(yhi).min(j_hi),
                )
            };
            if let Some(((_, cj0), (_, cj1))) = clip {
                j0 = j0.max(cj0);
                j1 = j1.min(cj1);
            }
            for j in j0..=j1 {
                f((i, j));
            }
        }
    }

    /// The list of one cell, if occupied.
    #[inline]
    fn cell(&self, c: Cell) -> Option<&[Entry<K>]> {
        let (key, idx) = chunk_of(c);
        self.chunks
            .get(&key)
            .and_then(|ch| ch.cells.get(idx))
            .map(Vec::as_slice)
    }

    /// Calls `visit` with every occupied cell of the inclusive range, chunk by chunk.
    fn walk_range(&self, (i0, j0): Cell, (i1, j1): Cell, visit: &mut dyn FnMut(Cell, &[Entry<K>])) {
        for ci in (i0 >> CHUNK_BITS)..=(i1 >> CHUNK_BITS) {
            for cj in (j0 >> CHUNK_BITS)..=(j1 >> CHUNK_BITS) {
                let Some(ch) = self.chunks.get(&(ci, cj)) else {
                    continue;
                };
                let (bi, bj) = (ci * CHUNK, cj * CHUNK);
                for i in i0.max(bi)..=i1.min(bi + CHUNK - 1) {
                    for j in j0.max(bj)..=j1.min(bj + CHUNK - 1) {
                        let idx = ((i - bi) * CHUNK + (j - bj)) as usize;
                        if let Some(list) = ch.cells.get(idx)
                            && !list.is_empty()
                        {
                            visit((i, j), list);
                        }
                    }
                }
            }
        }
    }

    /// Visits the entries of the cells `walk` presents whose box meets `b`, each once.
    /// `first_of` gives, for a box-stored entry, the one cell of the walk at which it is
    /// reported; the others (and all entries when `first_of` is `None`) are
    /// de-duplicated by sorting on the key.
    fn visit_cells<F: FnMut(K, &Shape)>(
        &self,
        walk: impl FnOnce(&mut dyn FnMut(Cell, &[Entry<K>])),
        first_of: Option<&dyn Fn(Cell) -> Cell>,
        b: &Aabb2,
        mut f: F,
    ) {
        let mut found: Vec<Entry<K>> = Vec::new();
        walk(&mut |c, list| {
            for e in list {
                if !e.bbox.intersects(b) {
                    continue;
                }
                match first_of {
                    Some(first) if !e.raster => {
                        if first(e.first) == c {
                            f(e.key, &e.shape);
                        }
                    }
                    _ => found.push(*e),
                }
            }
        });
        found.sort_unstable_by_key(|e| e.key);
        found.dedup_by_key(|e| e.key);
        for e in found {
            f(e.key, &e.shape);
        }
    }

    /// The cell range of `b` clipped to the occupied extent, or `None` if they miss.
    fn clipped_range(&self, b: &Aabb2) -> Option<(Cell, Cell)> {
        let ((ei0, ej0), (ei1, ej1)) = self.extent?;
        if b.is_empty() {
            return None;
        }
        let i0 = self.cell_coord(b.min.x).max(ei0);
        let j0 = self.cell_coord(b.min.y).max(ej0);
        let i1 = self.cell_coord(b.max.x).min(ei1);
        let j1 = self.cell_coord(b.max.y).min(ej1);
        (i0 <= i1 && j0 <= j1).then_some(((i0, j0), (i1, j1)))
    }

    fn visit_big<F: FnMut(K, &Shape)>(&self, b: &Aabb2, f: &mut F) {
        for e in &self.big {
            if e.bbox.intersects(b) {
                f(e.key, &e.shape);
            }
        }
    }

    fn scan_all<F: FnMut(K, &Shape)>(&self, b: &Aabb2, mut f: F) {
        for (&k, s) in &self.lookup {
            if s.bbox().intersects(b) {
                f(k, s);
            }
        }
    }
}

impl<K: IndexKey> SpatialIndex<K> for GridIndex<K> {
    fn insert(&mut self, key: K, shape: Shape) -> Result<Option<Shape>, GeomError> {
        shape.validate()?;
        let old = self.remove(key);
        let (first, raster) = self.placement(&shape);
        let entry = Entry {
            key,
            shape,
            bbox: shape.bbox(),
            first,
            raster,
        };
        self.lookup.insert(key, shape);
        if self.is_big(&shape) {
            self.big.push(entry);
            return Ok(old);
        }
        let mut touched: Vec<Cell> = Vec::new();
        self.cells_of(&shape, raster, |c| touched.push(c));
        for c in touched {
            let (key, idx) = chunk_of(c);
            let ch = self.chunks.entry(key).or_insert_with(|| Chunk {
                cells: vec![Vec::new(); (CHUNK * CHUNK) as usize],
                used: 0,
            });
            if let Some(list) = ch.cells.get_mut(idx) {
                if list.is_empty() {
                    ch.used += 1;
                    self.occupied += 1;
                }
                list.push(entry);
            }
            self.extent = Some(match self.extent {
                None => (c, c),
                Some((lo, hi)) => (
                    (lo.0.min(c.0), lo.1.min(c.1)),
                    (hi.0.max(c.0), hi.1.max(c.1)),
                ),
            });
        }
        Ok(old)
    }

    fn remove(&mut self, key: K) -> Option<Shape> {
        let shape = self.lookup.remove(&key)?;
        if self.is_big(&shape) {
            self.big.retain(|e| e.key != key);
            return Some(shape);
        }
        let (_, raster) = self.placement(&shape);
        let mut touched: Vec<Cell> = Vec::new();
        self.cells_of(&shape, raster, |c| touched.push(c));
        for c in touched {
            let (ck, idx) = chunk_of(c);
            let Some(ch) = self.chunks.get_mut(&ck) else {
                continue;
            };
            if let Some(list) = ch.cells.get_mut(idx)
                && let Some(i) = list.iter().position(|e| e.key == key)
            {
                list.swap_remove(i);
                if list.is_empty() {
                    ch.used -= 1;
                    self.occupied -= 1;
                }
            }
            if ch.used == 0 {
                self.chunks.remove(&ck);
            }
        }
        Some(shape)
    }

    fn get(&self, key: K) -> Option<Shape> {
        self.lookup.get(&key).copied()
    }

    fn len(&self) -> usize {
        self.lookup.len()
    }

    fn clear(&mut self) {
        *self = Self::build(self.options);
    }

    fn for_each_candidate<F: FnMut(K, &Shape)>(&self, b: &Aabb2, mut f: F) {
        if b.is_empty() {
            return;
        }
        let range = self.clipped_range(b);
        if let Some(((i0, j0), (i1, j1))) = range {
            let count = (i1 - i0 + 1).saturating_mul(j1 - j0 + 1);
            if count as u64 > self.lookup.len() as u64 {
                return self.scan_all(b, f);
            }
        }
        self.visit_big(b, &mut f);
        let Some(((i0, j0), (i1, j1))) = range else {
            return;
        };
        // A box-stored entry is reported at its lowest cell clipped to the range.
        let first = move |c: Cell| (c.0.max(i0), c.1.max(j0));
        self.visit_cells(
            |visit| self.walk_range((i0, j0), (i1, j1), visit),
            Some(&first),
            b,
            f,
        );
    }

    fn for_each_candidate_along<F: FnMut(K, &Shape)>(&self, a: DVec2, b: DVec2, mut f: F) {
        let bb = Aabb2::new(a, b);
        if bb.is_empty() {
            return;
        }
        let mut cells = Vec::new();
        if let Some(range) = self.clipped_range(&bb) {
            self.segment_cells(a, b, Some(range), &mut |c| cells.push(c));
            if cells.len() > self.lookup.len() {
                return self.scan_all(&bb, f);
            }
        }
        self.visit_big(&bb, &mut f);
        match cells[..] {
            // One cell: every entry in it is listed once there.
            [only] => self.visit_cells(
                |visit| {
                    if let Some(list) = self.cell(only) {
                        visit(only, list);
                    }
                },
                Some(&move |_| only),
                &bb,
                f,
            ),
            _ => self.visit_cells(
                |visit| {
                    for &c in &cells {
                        if let Some(list) = self.cell(c) {
                            visit(c, list);
                        }
                    }
                },
                None,
                &bb,
                f,
            ),
        }
    }
}
