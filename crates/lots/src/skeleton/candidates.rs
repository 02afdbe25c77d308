//! Split-event candidates: the times at which a wavefront vertex reaches the moving
//! supporting lines of the edges, earliest first.
//!
//! A candidate is only a possibility: the event loop confirms it against the wavefront as
//! it is at that time (`Engine::validate_split`). What this module must get exactly right
//! is the *set*: every line the vertex reaches before the horizon, in the total order
//! (time, edge), handed out a batch of [`CANDIDATE_BATCH`] at a time.
//!
//! Two ways to find a batch, with identical results:
//!
//! * **Scan**: the hit time on every line (branch-free, vectorised), then the earliest
//!   few. O(m) per vertex for m lines; used for small polygons.
//! * **Index**: the lines grouped by weight and bucketed by the direction of their normal
//!   (about `PER_BUCKET` lines per bucket). A vertex at `q` moving with velocity `v` from
//!   time `t0` reaches the line `n · x = c + w t` at time `t0 + a / (w − n · v)`, where
//!   `a = n · q − c − w t0` is how far the line is ahead of it. Within a bucket the normals
//!   differ from the bucket's middle by at most its half-width, which bounds both `n · q`
//!   and the closing speed `w − n · v`; so for each bucket, sorted by offset `c`, the lines
//!   ahead of the vertex form a contiguous run, and walking it from the nearest line
//!   outwards gives lower bounds on the hit times that only grow. The runs of all buckets
//!   are merged by that bound until the batch is full; after that each run is walked on
//!   its own down to what can still come before the batch's last time (or the horizon, or
//!   the time the vertex leaves the polygon's box). Offsets are measured from the centre
//!   of a grid cell near the vertex (one sorted copy per cell, up to 4 × 4), which keeps
//!   the bounds tight. Every line that can enter the batch is visited, and its time is
//!   computed by the very same expression as in the scan, so both give the same batch
//!   (a unit test runs both on random polygons and compares the skeletons bit for bit).
//!   A vertex typically visits a few dozen lines instead of all of them; one that flies
//!   across a dense region (a sharp reflex spike) or asks for a second batch still visits
//!   many.

use std::cmp::Ordering;

use polis_geom::DVec2;

use super::wavefront::EdgeLine;

/// A potential split: the time a vertex reaches the supporting line of an edge.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Candidate {
    pub t: f64,
    pub edge: u32,
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        self.t.total_cmp(&other.t).then(self.edge.cmp(&other.edge))
    }
}

/// How many split candidates of one vertex are kept at a time; the next batch is computed
/// only if all of these turn out not to be real hits.
pub(crate) const CANDIDATE_BATCH: usize = 12;

/// The next few split candidates of one vertex, sorted.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CandidateBatch {
    pub items: [Candidate; CANDIDATE_BATCH],
    pub len: u8,
    pub next: u8,
    /// Whether these are all the candidates there are.
    pub complete: bool,
}

/// The vertex a batch is computed for.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Query {
    pub p0: DVec2,
    pub t0: f64,
    pub vel: DVec2,
    /// `vel.length()`, computed once per query.
    pub speed: f64,
    pub in_edge: u32,
    pub out_edge: u32,
    /// Only candidates after this one (the last of the previous batch).
    pub after: Option<Candidate>,
}

/// Fixed facts of one simulation the filters need.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Bounds {
    pub horizon: f64,
    pub eps: f64,
    pub bbox_min: DVec2,
    pub bbox_max: DVec2,
}

/// Polygons with fewer edges than this are scanned (the index does not pay off).
const INDEX_MIN_LINES: usize = 256;

/// More distinct weights than this: scan (each weight is its own group of buckets).
const INDEX_MAX_WEIGHTS: usize = 8;

/// The supporting lines of all edges (input edges, then virtual step edges), as arrays
/// for the scan, and the index over the input edges.
#[derive(Debug, Default)]
pub(crate) struct SplitLines {
    nx: Vec<f64>,
    ny: Vec<f64>,
    c: Vec<f64>,
    w: Vec<f64>,
    /// Scratch: hit time on every line.
    times: Vec<f64>,
    index: LineIndex,
    /// Tests: `Some(true)` always uses the index (when it can), `Some(false)` never.
    pub force_index: Option<bool>,
}

impl SplitLines {
    /// Forgets all lines.
    pub fn clear(&mut self) {
        self.nx.clear();
        self.ny.clear();
        self.c.clear();
        self.w.clear();
        self.index.enabled = false;
    }

    /// Adds the line of an edge (input edges first, then steps).
    pub fn push(&mut self, e: &EdgeLine) {
        self.nx.push(e.normal.x);
        self.ny.push(e.normal.y);
        self.c.push(e.normal.dot(e.a));
        self.w.push(e.weight);
    }

    /// Builds the index over the lines added so far (the input edges), if it pays off.
    pub fn build_index(&mut self, edges: &[EdgeLine], bounds: &Bounds) {
        let m = self.nx.len();
        let wanted = self.force_index.unwrap_or(m >= INDEX_MIN_LINES);
        self.index.enabled = wanted && self.index.build(edges, bounds);
    }

    /// The `CANDIDATE_BATCH` earliest hits of the vertex on edge lines after `q.after`
    /// (in the order time, then edge).
    pub fn batch(&mut self, q: &Query, b: &Bounds) -> CandidateBatch {
        if self.index.enabled {
            self.batch_indexed(q, b)
        } else {
            self.batch_scanned(q, b)
        }
    }

    /// The hit time of the vertex on line `i`, or infinity if it never reaches it (or is
    /// already behind it). The one expression both ways of searching use.
    #[inline(always)]
    fn hit_time(&self, i: usize, q: &Query, eps: f64) -> f64 {
        let (px, py) = (q.p0.x, q.p0.y);
        let slope = self.nx[i] * q.vel.x + self.ny[i] * q.vel.y - self.w[i];
        let ahead = self.nx[i] * px + self.ny[i] * py - self.c[i] - self.w[i] * q.t0;
        line_hit(
            slope,
            ahead,
            q.t0,
            eps,
            TOUCH_SLOPE_REL * (q.speed + self.w[i]),
        )
    }

    fn batch_scanned(&mut self, q: &Query, b: &Bounds) -> CandidateBatch {
        let mut batch = CandidateBatch::default();
        let m = self.nx.len();
        let mut times = std::mem::take(&mut self.times);
        times.clear();
        times.resize(m, f64::INFINITY);
        // First pass, branch-free so that it vectorises (the same expression as
        // `hit_time`, written out over the arrays).
        let (nxs, nys, cs, ws) = (&self.nx[..m], &self.ny[..m], &self.c[..m], &self.w[..m]);
        let (px, py, vx, vy, t0, eps) = (q.p0.x, q.p0.y, q.vel.x, q.vel.y, q.t0, b.eps);
        let speed = q.speed;
        for (i, slot) in times.iter_mut().enumerate() {
            let slope = nxs[i] * vx + nys[i] * vy - ws[i];
            let ahead = nxs[i] * px + nys[i] * py - cs[i] - ws[i] * t0;
            *slot = line_hit(slope, ahead, t0, eps, TOUCH_SLOPE_REL * (speed + ws[i]));
        }
        // Second pass: the few that can enter the batch.
        for (i, &t) in times.iter().enumerate() {
            offer(&mut batch, i as u32, t, q, b);
        }
        batch.complete = (batch.len as usize) < CANDIDATE_BATCH;
        self.times = times;
        batch
    }

    fn batch_indexed(&mut self, q: &Query, b: &Bounds) -> CandidateBatch {
        let mut batch = CandidateBatch::default();
        // Step edges made during the run are not in the index: scan them.
        for i in self.index.lines..self.nx.len() {
            let t = self.hit_time(i, q, b.eps);
            offer(&mut batch, i as u32, t, q, b);
        }
        let mut index = std::mem::take(&mut self.index);
        // No hit counts once the vertex has left the polygon's box.
        let end = b.horizon.min(exit_time(q, b));
        index.search(q, b, end, |i| {
            let t = self.hit_time(i as usize, q, b.eps);
            offer(&mut batch, i, t, q, b);
            (batch.len as usize == CANDIDATE_BATCH).then(|| batch.items[CANDIDATE_BATCH - 1].t)
        });
        self.index = index;
        batch.complete = (batch.len as usize) < CANDIDATE_BATCH;
        batch
    }
}

/// A closing speed below this times the vertex's and the line's speeds counts as none:
/// the vertex moves along with the line (far above the rounding of the slope, about
/// `1e-16` of the speeds, and far below any real closing speed: closing the coincidence
/// tolerance at it would take `1e3` times the polygon's size over the speed).
pub(crate) const TOUCH_SLOPE_REL: f64 = 1e-12;

/// When a vertex, `ahead` in front of a wavefront line at time `t0` (negative: behind
/// it) and closing on it at `-slope` per unit of time, reaches it: `t0` if it is on
/// the line (within `eps`) and moving along with it (closing speed within `tol` of 0),
/// else the time it crosses the line if it closes on it from in front (or from within
/// `eps` behind), else never (infinity).
///
/// The touching case matters when neither moves towards the other: a vertex that stands
/// still between two weighted steps and a step edge (weight 0) that an event laid over
/// it, or a vertex gliding along an edge of its own speed. The wavefront touches itself
/// there, which is an event (the piece it touches splits), and no crossing time exists.
#[inline(always)]
pub(crate) fn line_hit(slope: f64, ahead: f64, t0: f64, eps: f64, tol: f64) -> f64 {
    // Both answers computed, then selected: branch-free, so the scan over all lines
    // vectorises.
    let crossing = t0 - ahead.max(0.0) / slope;
    let t = if slope < 0.0 && ahead >= -eps {
        crossing
    } else {
        f64::INFINITY
    };
    if ahead.abs() <= eps && slope.abs() <= tol {
        t0
    } else {
        t
    }
}

/// A time after which the vertex is outside the polygon's box for sure (its hits there
/// are all refused by `offer`), with a margin far above rounding.
fn exit_time(q: &Query, b: &Bounds) -> f64 {
    let mut tau = f64::INFINITY;
    for (p, v, lo, hi) in [
        (q.p0.x, q.vel.x, b.bbox_min.x, b.bbox_max.x),
        (q.p0.y, q.vel.y, b.bbox_min.y, b.bbox_max.y),
    ] {
        if v > 0.0 {
            tau = tau.min((hi - p) / v);
        } else if v < 0.0 {
            tau = tau.min((lo - p) / v);
        }
    }
    let size = b.bbox_min.abs().max(b.bbox_max.abs()).max_element();
    let slack = 4.0 * (b.eps + 1e-15 * size) / q.speed;
    q.t0 + tau.max(0.0) + slack
}

/// Offers line `i`, reached at time `t`, to the batch (kept sorted, the largest dropped
/// when full).
#[inline]
fn offer(batch: &mut CandidateBatch, i: u32, t: f64, q: &Query, b: &Bounds) {
    if t.is_nan() || t > b.horizon || i == q.in_edge || i == q.out_edge {
        return;
    }
    let cand = Candidate { t, edge: i };
    if q.after.is_some_and(|a| cand <= a) {
        return;
    }
    let full = batch.len as usize == CANDIDATE_BATCH;
    if full && cand >= batch.items[CANDIDATE_BATCH - 1] {
        return;
    }
    // The hit point must be where the polygon is.
    let p = q.p0 + q.vel * (t - q.t0);
    if p.x < b.bbox_min.x || p.y < b.bbox_min.y || p.x > b.bbox_max.x || p.y > b.bbox_max.y {
        return;
    }
    let mut k = if full {
        CANDIDATE_BATCH - 1
    } else {
        batch.len as usize
    };
    while k > 0 && batch.items[k - 1] > cand {
        batch.items[k] = batch.items[k - 1];
        k -= 1;
    }
    batch.items[k] = cand;
    if !full {
        batch.len += 1;
    }
}

/// A bucket of lines of one weight whose normals lie within a small angle range, sorted
/// by offset.
#[derive(Debug, Clone, Copy)]
struct Bucket {
    /// Unit normal at the middle of the bucket's actual angle range.
    mid: DVec2,
    /// Half the actual angle range (radians), with a margin for rounding.
    half: f64,
    weight: f64,
    /// Its entries `start..end`, ascending by offset.
    start: u32,
    end: u32,
}

/// A bucket's window during a query: entries `lo..` have been visited; it grows downwards
/// (to smaller offsets, lines further ahead) in the order the vertex can reach them.
#[derive(Debug, Clone, Copy)]
struct Window {
    /// The earliest time (after the vertex's start) the next entry can be reached.
    next: f64,
    bucket: u32,
    lo: u32,
    /// Entry `lo - 1` can be reached after `(base − offset) / rate`.
    base: f64,
    /// The bound on the closing speed `w − n · v` in the bucket.
    rate: f64,
}
impl PartialEq for Window {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Window {}
impl PartialOrd for Window {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Window {
    fn cmp(&self, other: &Self) -> Ordering {
        // Earliest first out of a max-heap.
        other
            .next
            .total_cmp(&self.next)
            .then(other.bucket.cmp(&self.bucket))
    }
}

/// Lines per bucket, on average.
const PER_BUCKET: usize = 24;

/// The input edges' lines, grouped by weight and bucketed by normal angle.
#[derive(Debug, Default)]
struct LineIndex {
    enabled: bool,
    /// How many lines (the input edges) are indexed.
    lines: usize,
    /// The polygon's box is cut into `grid × grid` cells; offsets are measured from the
    /// centre of the cell the vertex is in (the bound's slack grows with that distance).
    grid: usize,
    lo: DVec2,
    cell: DVec2,
    /// Safety margin on offsets (far above rounding).
    margin: f64,
    buckets: Vec<Bucket>,
    /// Entries for each cell centre `o` (cell by cell, `lines` each): offsets
    /// `n · (a − o)` and lines, bucket by bucket, ascending within a bucket.
    offset: Vec<f64>,
    line: Vec<u32>,
    windows: std::collections::BinaryHeap<Window>,
    /// Build scratch: (weight, angle, offset, line).
    scratch: Vec<(f64, f64, f64, u32)>,
}

impl LineIndex {
    /// Indexes the input edges; `false` if there are too many distinct weights.
    fn build(&mut self, edges: &[EdgeLine], b: &Bounds) -> bool {
        let m = edges.len();
        let mut weights: Vec<f64> = edges.iter().map(|e| e.weight).collect();
        weights.sort_by(f64::total_cmp);
        weights.dedup();
        if weights.len() > INDEX_MAX_WEIGHTS || m == 0 {
            return false;
        }
        self.lines = m;
        self.grid = ((m as f64).sqrt() / 24.0).clamp(1.0, 4.0) as usize;
        self.lo = b.bbox_min;
        self.cell = (b.bbox_max - b.bbox_min) / self.grid as f64;
        self.margin = 1e3 * b.eps;
        let slots = (m / PER_BUCKET).clamp(1, 4096);
        let width = std::f64::consts::TAU / slots as f64;
        let slot_of = |a: f64| (((a + std::f64::consts::PI) / width) as usize).min(slots - 1);
        let mut entries = std::mem::take(&mut self.scratch);
        entries.clear();
        entries.extend(edges.iter().enumerate().map(|(i, e)| {
            let n = e.normal;
            (e.weight, n.y.atan2(n.x), n.dot(e.a), i as u32)
        }));
        entries.sort_by(|x, y| {
            x.0.total_cmp(&y.0)
                .then(slot_of(x.1).cmp(&slot_of(y.1)))
                .then(x.3.cmp(&y.3))
        });
        self.buckets.clear();
        self.offset.clear();
        self.line.clear();
        let mut k = 0;
        while k < entries.len() {
            let (w, a, _, _) = entries[k];
            let slot = slot_of(a);
            let mut end = k;
            let (mut a0, mut a1) = (a, a);
            while end < entries.len() && entries[end].0 == w && slot_of(entries[end].1) == slot {
                a0 = a0.min(entries[end].1);
                a1 = a1.max(entries[end].1);
                end += 1;
            }
            let am = 0.5 * (a0 + a1);
            self.buckets.push(Bucket {
                mid: DVec2::new(am.cos(), am.sin()),
                half: 0.5 * (a1 - a0) + 1e-9,
                weight: w,
                start: k as u32,
                end: end as u32,
            });
            k = end;
        }
        // Per cell centre, each bucket sorted by offset from it.
        self.offset.resize(self.grid * self.grid * m, 0.0);
        self.line.resize(self.grid * self.grid * m, 0);
        let mut sorted: Vec<(f64, u32)> = Vec::new();
        for cell in 0..self.grid * self.grid {
            let o = self.centre(cell);
            for bk in &self.buckets {
                sorted.clear();
                sorted.extend(entries[bk.start as usize..bk.end as usize].iter().map(|x| {
                    let e = &edges[x.3 as usize];
                    (e.normal.dot(e.a - o), x.3)
                }));
                sorted.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                let base = cell * m + bk.start as usize;
                for (j, &(c, line)) in sorted.iter().enumerate() {
                    self.offset[base + j] = c;
                    self.line[base + j] = line;
                }
            }
        }
        self.scratch = entries;
        true
    }

    /// The centre of cell `k` (row by row).
    fn centre(&self, k: usize) -> DVec2 {
        let (i, j) = (k % self.grid, k / self.grid);
        self.lo + self.cell * DVec2::new(i as f64 + 0.5, j as f64 + 0.5)
    }

    /// The cell a point is in (clamped to the grid).
    fn cell_of(&self, p: DVec2) -> usize {
        let g = self.grid;
        let f = |x: f64, lo: f64, size: f64| {
            if size > 0.0 {
                (((x - lo) / size).max(0.0) as usize).min(g - 1)
            } else {
                0
            }
        };
        f(p.x, self.lo.x, self.cell.x) + g * f(p.y, self.lo.y, self.cell.y)
    }

    /// Visits the indexed lines in the order of a lower bound on the time the vertex
    /// reaches them, until that bound passes `end` or the time `visit` returns (the
    /// batch's last, once it is full).
    fn search(
        &mut self,
        q: &Query,
        b: &Bounds,
        end: f64,
        mut visit: impl FnMut(u32) -> Option<f64>,
    ) {
        let cell = self.cell_of(q.p0);
        let rel = q.p0 - self.centre(cell);
        let shift = (cell * self.lines) as u32;
        let (qn, speed) = (rel.length(), q.speed);
        let mut heap = std::mem::take(&mut self.windows);
        heap.clear();
        for (k, bk) in self.buckets.iter().enumerate() {
            // |n − mid| <= half for every normal n of the bucket, so n · u is within
            // |u| · half of mid · u.
            let h = bk.half;
            let rate = bk.weight - bk.mid.dot(q.vel) + speed * h;
            if rate <= 0.0 {
                continue;
            }
            let nq = bk.mid.dot(rel) - bk.weight * q.t0;
            // ahead = n · q − c − w t0 >= −eps  ⇒  c <= top.
            let top = nq + qn * h + b.eps + self.margin;
            let (start, stop) = (bk.start + shift, bk.end + shift);
            let slice = &self.offset[start as usize..stop as usize];
            let hi = start + slice.partition_point(|&c| c <= top) as u32;
            if hi > start {
                // ahead <= τ · (w − n · v) needs c >= base − τ · rate.
                let base = nq - qn * h - self.margin;
                let c = self.offset[hi as usize - 1];
                heap.push(Window {
                    next: ((base - c) / rate).max(0.0),
                    bucket: k as u32,
                    lo: hi,
                    base,
                    rate,
                });
            }
        }
        // Until the batch is full, take lines in the order of their bounds, so that its
        // last time becomes small soon; after that the order does not matter, and each
        // window is run down on its own to what can still come before the batch's last.
        let mut last = f64::INFINITY;
        while let Some(mut w) = heap.peek_mut() {
            let t = q.t0 + w.next;
            if t > end || last.is_finite() {
                break;
            }
            w.lo -= 1;
            if let Some(l) = visit(self.line[w.lo as usize]) {
                last = l;
            }
            if w.lo == self.buckets[w.bucket as usize].start + shift {
                std::collections::binary_heap::PeekMut::pop(w);
            } else {
                let c = self.offset[w.lo as usize - 1];
                w.next = ((w.base - c) / w.rate).max(0.0);
            }
        }
        for w in heap.drain() {
            let start = self.buckets[w.bucket as usize].start + shift;
            // Entry c can come by time `limit` only if c >= base − (limit − t0) · rate.
            let floor = |limit: f64| w.base - (limit - q.t0) * w.rate;
            let mut lowest = floor(last.min(end));
            let mut lo = w.lo;
            while lo > start && self.offset[lo as usize - 1] >= lowest {
                lo -= 1;
                if let Some(l) = visit(self.line[lo as usize])
                    && l < last
                {
                    last = l;
                    lowest = floor(last.min(end));
                }
            }
        }
        self.windows = heap;
    }
}

#[cfg(test)]
mod tests {
    use polis_geom::{DVec2, Polygon, PolygonWithHoles};
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    use crate::skeleton::events::Engine;
    use crate::skeleton::prepare;

    /// Runs the whole simulation with the index forced on or off.
    fn run(p: &PolygonWithHoles, w: Option<&[f64]>, index: bool) -> Engine {
        let mut e = Engine::default();
        e.lines.force_index = Some(index);
        prepare(&mut e, p, w).unwrap();
        e.run(f64::INFINITY).unwrap();
        e
    }

    fn same(p: &PolygonWithHoles, w: Option<&[f64]>) {
        let (a, b) = (run(p, w, false), run(p, w, true));
        assert!(
            b.lines.index.enabled || w.is_some(),
            "the index was not used"
        );
        assert_eq!(a.nodes.len(), b.nodes.len());
        for (x, y) in a.nodes.iter().zip(&b.nodes) {
            assert_eq!(x.position, y.position);
            assert_eq!(x.time.to_bits(), y.time.to_bits());
        }
        assert_eq!(a.arcs, b.arcs);
    }

    fn star(rng: &mut Pcg64Mcg, n: usize, grid: bool) -> Polygon {
        let mut pts: Vec<DVec2> = (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * (i as f64 + rng.random_range(0.0..0.5)) / n as f64;
                let p = DVec2::new(a.cos(), a.sin()) * rng.random_range(20.0..100.0);
                if grid { p.round() } else { p }
            })
            .collect();
        pts.dedup();
        Polygon::new(pts)
    }

    fn comb(rng: &mut Pcg64Mcg, teeth: usize) -> Polygon {
        let mut pts = vec![
            DVec2::new(0.0, -10.0),
            DVec2::new(teeth as f64 * 2.0, -10.0),
        ];
        for i in (0..teeth).rev() {
            let x = i as f64 * 2.0;
            let depth = f64::from(rng.random_range(1u8..9));
            pts.push(DVec2::new(x + 2.0, 10.0));
            pts.push(DVec2::new(x + 1.5, 10.0 - depth));
            pts.push(DVec2::new(x + 0.5, 10.0 - depth));
        }
        pts.push(DVec2::new(0.0, 10.0));
        Polygon::new(pts)
    }

    #[test]
    fn index_and_scan_give_identical_skeletons() {
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let mut tried = 0;
        for k in 0..24 {
            let n = rng.random_range(40..400);
            let outer = match k % 3 {
                0 => star(&mut rng, n, false),
                1 => star(&mut rng, n, true),
                _ => comb(&mut rng, n / 3),
            };
            let p = PolygonWithHoles::from(outer);
            if p.validate().is_err() || p.outer.signed_area() <= 0.0 {
                continue;
            }
            tried += 1;
            same(&p, None);
            // Weighted: a few distinct weights (indexed per weight).
            let w: Vec<f64> = (0..p.outer.len())
                .map(|_| [1.0, 2.0, 0.5][rng.random_range(0..3)])
                .collect();
            same(&p, Some(&w));
        }
        assert!(tried >= 16);
        // A polygon with holes (indexed together with the outer ring).
        let mut holes = Vec::new();
        for i in 0..6 {
            let c = DVec2::new(-15.0 + 6.0 * i as f64, 0.0);
            let mut h = Polygon::regular(5, c, 2.0);
            h.reverse();
            holes.push(h);
        }
        let p = PolygonWithHoles::new(Polygon::regular(60, DVec2::ZERO, 40.0), holes);
        same(&p, None);
    }
}
