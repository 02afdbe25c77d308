//! [`GridIndex`]: a hashed uniform grid.

use std::collections::HashMap;

use glam::DVec2;

use super::{GridOptions, IndexKey, Shape, SpatialIndex};
use crate::bbox::Aabb2;
use crate::error::GeomError;
use crate::inline_vec::InlineVec;

pub(crate) use crate::hash::FxBuild;

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
/// query reads each cell's list contiguously instead of chasing pointers). 64 bytes for
/// `u32` keys, one cache line: the box is recomputed from the shape when needed rather
/// than stored, since queries are bound by the memory they scan.
#[derive(Debug, Clone, Copy)]
struct Entry<K> {
    key: K,
    /// Whether the shape is rasterised (entered in a subset of its box's cells).
    raster: bool,
    /// Lowest cell of the bounding box.
    first: Cell,
    shape: Shape,
}

impl<K> Entry<K> {
    /// Bounding box of the shape.
    #[inline]
    fn bbox(&self) -> Aabb2 {
        self.shape.bbox()
    }
}

/// Cells per chunk side (a power of two).
const CHUNK_BITS: u32 = 3;
const CHUNK: i64 = 1 << CHUNK_BITS;

#[derive(Debug, Clone)]
struct Chunk<K> {
    cells: Vec<Vec<Entry<K>>>,
    used: usize,
}

/// `⌊v⌋` as a cell coordinate, equal to `v.floor() as i64`: below 2⁵² by truncation
/// (`f64::floor` is a libm call on the baseline x86-64 target, and cell coordinates are
/// computed several times per query); beyond, by `floor` (the `as` cast saturates).
#[inline]
fn cell_floor(v: f64) -> i64 {
    if v.abs() < 4_503_599_627_370_496.0 {
        let t = v as i64;
        if (t as f64) > v { t - 1 } else { t }
    } else {
        v.floor() as i64
    }
}

/// The grid's cell geometry, copied out of the index so that cell walks need no borrow
/// of it.
#[derive(Debug, Clone, Copy)]
struct Geo {
    size: f64,
    inv: f64,
}

impl Geo {
    #[inline]
    fn cell_coord(self, x: f64) -> i64 {
        // Finite and bounded by MAX_COORDINATE / MIN_CELL_SIZE: fits i64.
        cell_floor(x * self.inv)
    }

    /// Calls `f` with the column runs `(i, j0, j1)` (cells `(i, j0..=j1)`) of every cell
    /// the shape is entered in, columns in increasing order.
    fn runs_of(self, shape: &Shape, raster: bool, mut f: impl FnMut(i64, i64, i64)) {
        match *shape {
            Shape::Segment(a, b) if raster => self.segment_runs(a, b, None, &mut f),
            _ => {
                let b = shape.bbox();
                let (i0, j0) = (self.cell_coord(b.min.x), self.cell_coord(b.min.y));
                let (i1, j1) = (self.cell_coord(b.max.x), self.cell_coord(b.max.y));
                for i in i0..=i1 {
                    f(i, j0, j1);
                }
            }
        }
    }

    /// Conservative rasterisation of the segment `a–b`: every cell the segment meets is
    /// reported (and possibly a few neighbours), as one run `(i, j0, j1)` per column in
    /// increasing column order (a run may be empty, `j0 > j1`). With `clip`, only cells
    /// inside that range.
    fn segment_runs(
        self,
        a: DVec2,
        b: DVec2,
        clip: Option<(Cell, Cell)>,
        f: &mut impl FnMut(i64, i64, i64),
    ) {
        let (lo, hi) = (a.min(b), a.max(b));
        let (mut i0, mut i1) = (self.cell_coord(lo.x), self.cell_coord(hi.x));
        let (j_lo, j_hi) = (self.cell_coord(lo.y), self.cell_coord(hi.y));
        if let Some(((ci0, _), (ci1, _))) = clip {
            i0 = i0.max(ci0);
            i1 = i1.min(ci1);
        }
        let s = self.size;
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
            f(i, j0, j1);
        }
    }
}

/// Column runs of a query walk, kept on the stack for the usual short walks.
type Runs = InlineVec<(i64, i64, i64), 16>;

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
    fn geo(&self) -> Geo {
        Geo {
            size: self.options.cell_size,
            inv: self.inv,
        }
    }

    #[inline]
    fn cell_coord(&self, x: f64) -> i64 {
        self.geo().cell_coord(x)
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
    fn walk_range<'s>(
        &'s self,
        (i0, j0): Cell,
        (i1, j1): Cell,
        mut visit: impl FnMut(Cell, &'s [Entry<K>]),
    ) {
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

    /// Reports the raster entries gathered by a walk, each once, in key order.
    fn report_raster<F: FnMut(K, &Shape)>(found: &mut RasterBuf<'_, K>, f: &mut F) {
        found.report(f);
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
            if e.bbox().intersects(b) {
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
            first,
            raster,
        };
        self.lookup.insert(key, shape);
        if self.is_big(&shape) {
            self.big.push(entry);
            return Ok(old);
        }
        let geo = self.geo();
        let (chunks, occupied, extent) = (&mut self.chunks, &mut self.occupied, &mut self.extent);
        geo.runs_of(&shape, raster, |i, j0, j1| {
            if j0 > j1 {
                return;
            }
            for j in j0..=j1 {
                let (key, idx) = chunk_of((i, j));
                let ch = chunks.entry(key).or_insert_with(|| Chunk {
                    cells: vec![Vec::new(); (CHUNK * CHUNK) as usize],
                    used: 0,
                });
                if let Some(list) = ch.cells.get_mut(idx) {
                    if list.is_empty() {
                        ch.used += 1;
                        *occupied += 1;
                    }
                    list.push(entry);
                }
            }
            *extent = Some(match *extent {
                None => ((i, j0), (i, j1)),
                Some((lo, hi)) => ((lo.0.min(i), lo.1.min(j0)), (hi.0.max(i), hi.1.max(j1))),
            });
        });
        Ok(old)
    }

    fn remove(&mut self, key: K) -> Option<Shape> {
        let shape = self.lookup.remove(&key)?;
        if self.is_big(&shape) {
            self.big.retain(|e| e.key != key);
            return Some(shape);
        }
        let (_, raster) = self.placement(&shape);
        let geo = self.geo();
        let (chunks, occupied) = (&mut self.chunks, &mut self.occupied);
        geo.runs_of(&shape, raster, |i, j0, j1| {
            for j in j0..=j1 {
                let (ck, idx) = chunk_of((i, j));
                let Some(ch) = chunks.get_mut(&ck) else {
                    continue;
                };
                if let Some(list) = ch.cells.get_mut(idx)
                    && let Some(i) = list.iter().position(|e| e.key == key)
                {
                    list.swap_remove(i);
                    if list.is_empty() {
                        ch.used -= 1;
                        *occupied -= 1;
                    }
                }
                if ch.used == 0 {
                    chunks.remove(&ck);
                }
            }
        });
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
        // A box-stored entry is reported at its lowest cell clipped to the range; raster
        // entries are gathered and de-duplicated.
        let mut raster = RasterBuf::new();
        self.walk_range((i0, j0), (i1, j1), |c, list| {
            for e in list {
                if !e.bbox().intersects(b) {
                    continue;
                }
                if e.raster {
                    raster.push(e);
                } else if (e.first.0.max(i0), e.first.1.max(j0)) == c {
                    f(e.key, &e.shape);
                }
            }
        });
        Self::report_raster(&mut raster, &mut f);
    }

    fn for_each_candidate_along<F: FnMut(K, &Shape)>(&self, a: DVec2, b: DVec2, mut f: F) {
        let bb = Aabb2::new(a, b);
        if bb.is_empty() {
            return;
        }
        let Some(range) = self.clipped_range(&bb) else {
            self.visit_big(&bb, &mut f);
            return;
        };
        let geo = self.geo();
        let mut runs = Runs::new((0, 0, 0));
        let mut cells = 0u64;
        geo.segment_runs(a, b, Some(range), &mut |i, j0, j1| {
            if j0 <= j1 {
                runs.push((i, j0, j1));
                cells += (j1 - j0 + 1) as u64;
            }
        });
        if cells > self.lookup.len() as u64 {
            return self.scan_all(&bb, f);
        }
        self.visit_big(&bb, &mut f);
        let runs = runs.as_slice();
        // A box-stored entry is in every cell of its box: report it at the first cell of
        // the walk (columns in increasing order, rows increasing within a column) inside
        // its box. Raster entries are gathered and de-duplicated.
        let mut raster = RasterBuf::new();
        for (r, &(i, j0, j1)) in runs.iter().enumerate() {
            for j in j0..=j1 {
                let Some(list) = self.cell((i, j)) else {
                    continue;
                };
                for e in list {
                    let ebox = e.bbox();
                    if !ebox.intersects(&bb) {
                        continue;
                    }
                    if e.raster {
                        raster.push(e);
                        continue;
                    }
                    let (ei0, ej0) = e.first;
                    let ej1 = geo.cell_coord(ebox.max.y);
                    if j != j0.max(ej0) {
                        continue;
                    }
                    let seen_before = runs
                        .get(..r)
                        .unwrap_or(&[])
                        .iter()
                        .rev()
                        .take_while(|run| run.0 >= ei0)
                        .any(|&(_, rj0, rj1)| rj0 <= ej1 && rj1 >= ej0);
                    if !seen_before {
                        f(e.key, &e.shape);
                    }
                }
            }
        }
        Self::report_raster(&mut raster, &mut f);
    }
}

/// Raster entries met by one query walk (with repeats), kept by reference on the stack
/// for the usual few dozen: no allocation and no copies of the 64-byte entries.
struct RasterBuf<'a, K> {
    inline: [Option<&'a Entry<K>>; 32],
    len: usize,
    more: Vec<&'a Entry<K>>,
}

impl<'a, K> RasterBuf<'a, K> {
    fn new() -> Self {
        RasterBuf {
            inline: [None; 32],
            len: 0,
            more: Vec::new(),
        }
    }

    #[inline]
    fn push(&mut self, e: &'a Entry<K>) {
        if self.more.is_empty()
            && let Some(slot) = self.inline.get_mut(self.len)
        {
            *slot = Some(e);
            self.len += 1;
        } else {
            if self.more.is_empty() {
                self.more.extend(self.inline.iter().flatten().copied());
            }
            self.more.push(e);
        }
    }

    /// Reports every gathered entry once, in key order.
    fn report<F: FnMut(K, &Shape)>(&mut self, f: &mut F)
    where
        K: IndexKey,
    {
        let mut last: Option<K> = None;
        let mut emit = |e: &Entry<K>| {
            if last != Some(e.key) {
                last = Some(e.key);
                f(e.key, &e.shape);
            }
        };
        if self.more.is_empty() {
            let list = self.inline.get_mut(..self.len).unwrap_or(&mut []);
            list.sort_unstable_by_key(|e| e.map(|e| e.key));
            list.iter().flatten().for_each(|e| emit(e));
        } else {
            self.more.sort_unstable_by_key(|e| e.key);
            self.more.iter().for_each(|e| emit(e));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// More raster entries than the inline buffer holds, each met in many cells: every
    /// one is reported once, in key order, by both walks.
    #[test]
    fn many_long_segments_spill_and_are_reported_once() {
        let mut g = GridIndex::<u32>::new(GridOptions { cell_size: 1.0 }).unwrap_or_default();
        for k in 0..100u32 {
            let x = f64::from(k) * 0.25;
            let _ = g.insert(
                k,
                Shape::Segment(DVec2::new(x, -20.0), DVec2::new(x + 3.0, 20.0)),
            );
        }
        let (a, b) = (DVec2::new(-5.0, 0.5), DVec2::new(40.0, 1.5));
        let mut along = Vec::new();
        g.for_each_candidate_along(a, b, |k, _| along.push(k));
        let mut boxed = Vec::new();
        g.for_each_candidate(&Aabb2::new(a, b), |k, _| boxed.push(k));
        let all: Vec<u32> = (0..100).collect();
        assert_eq!(along, all);
        assert_eq!(boxed, all);
    }

    #[test]
    fn an_entry_fits_a_cache_line() {
        assert!(std::mem::size_of::<Entry<u32>>() <= 64);
    }
}
