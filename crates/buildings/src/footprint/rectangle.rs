//! The strip sweep of [`largest_rectangle`](super::largest_rectangle): the region in the
//! street frame, candidate side pairs pruned by upper bounds, the exact tallest rectangle
//! of a pair, refinement around the best pair.
//!
//! Every candidate pair the sweep skips is one that provably cannot replace the best
//! rectangle (only a strictly larger area replaces it), so the result is the one of the
//! plain sweep over every pair in the same order, bit for bit; the tests keep that plain
//! sweep as the reference.

use polis_geom::{DVec2, Polygon};

use super::{
    RECTANGLE_GRID_STEPS, RECTANGLE_MAX_VERTEX_CANDIDATES, RECTANGLE_REFINE_ROUNDS, rect_inside,
};

thread_local! {
    /// Reusable buffers of [`largest`], one set per thread.
    static RECTANGLE: std::cell::RefCell<RectangleWork> =
        std::cell::RefCell::new(RectangleWork::default());
}

/// [`largest_rectangle`](super::largest_rectangle) through this thread's buffers.
pub(super) fn largest(region: &Polygon, dir: DVec2) -> Option<Polygon> {
    RECTANGLE.with(|w| match w.try_borrow_mut() {
        Ok(mut work) => rectangle_in(&mut work, region, dir),
        Err(_) => rectangle_in(&mut RectangleWork::default(), region, dir),
    })
}

/// The buffers of [`largest`]: the region in the street frame and its edges, the vertex
/// coordinates, the candidate side coordinates with their spreads (computed when first
/// needed), the blocked intervals of a strip, and the refinement candidates.
#[derive(Default)]
struct RectangleWork {
    frame: Vec<DVec2>,
    edges: Vec<Edge>,
    xs: Vec<f64>,
    us: Vec<f64>,
    spread: Vec<Option<f64>>,
    blocked: Vec<(f64, f64)>,
    c1: Vec<(f64, Option<f64>)>,
}

/// An edge of the region in the frame, its endpoints ordered by `u` (`x0 <= x1`), with
/// the differences every interpolation uses (`dx == 0` for an edge across the street).
#[derive(Clone, Copy)]
struct Edge {
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    dx: f64,
    dy: f64,
    /// The lower and upper end of the edge's `v` range.
    ylo: f64,
    yhi: f64,
}

impl Edge {
    /// The edge from `a` to `b`.
    fn new(a: DVec2, b: DVec2) -> Self {
        let (p, q) = if a.x <= b.x { (a, b) } else { (b, a) };
        Edge {
            x0: p.x,
            x1: q.x,
            y0: p.y,
            y1: q.y,
            dx: q.x - p.x,
            dy: q.y - p.y,
            ylo: p.y.min(q.y),
            yhi: p.y.max(q.y),
        }
    }

    /// The edge's `v` at `u` (`x0 < u <= x1` or `x0 <= u < x1`, not across the street).
    #[inline]
    fn at(&self, u: f64) -> f64 {
        self.y0 + self.dy * ((u - self.x0) / self.dx)
    }
}

/// Largest coordinate magnitude of a frame whose spreads are finite and within
/// [`spread_bound`] of its `v` extent (no difference or interpolation overflows).
const BOUNDED_FRAME: f64 = 1e100;

/// An upper bound of every spread of a frame with `v` range `[vmin, vmax]`: the extent plus
/// a margin far above the interpolation's rounding error (a few units in the last place
/// of the largest coordinate).
fn spread_bound(vmin: f64, vmax: f64) -> f64 {
    (vmax - vmin) + 1e-12 * vmin.abs().max(vmax.abs())
}

/// [`largest`] with the buffers of `work`.
fn rectangle_in(work: &mut RectangleWork, region: &Polygon, dir: DVec2) -> Option<Polygon> {
    let RectangleWork {
        frame,
        edges,
        xs,
        us,
        spread,
        blocked,
        c1,
    } = work;
    let len = dir.length();
    if !(len > 0.0 && len.is_finite()) || region.len() < 3 {
        return None;
    }
    let x = dir / len;
    let y = x.perp();
    frame.clear();
    frame.extend(
        region
            .points()
            .iter()
            .map(|p| DVec2::new(p.dot(x), p.dot(y))),
    );
    if frame.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
    for p in frame.iter() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let (w, h) = (hi.x - lo.x, hi.y - lo.y);
    if !(w > 0.0 && h > 0.0) {
        return None;
    }
    edges.clear();
    edges.extend(
        frame
            .iter()
            .zip(frame.iter().cycle().skip(1))
            .map(|(&a, &b)| Edge::new(a, b)),
    );
    // Pairs are skipped by `width × bound <= best` before any spread is computed: the
    // bound holds for every spread when nothing can overflow (else it is infinite and
    // skips nothing).
    let bounded = lo.abs().max_element().max(hi.abs().max_element()) < BOUNDED_FRAME;
    let bound = if bounded {
        spread_bound(lo.y, hi.y)
    } else {
        f64::INFINITY
    };
    blocked.clear();
    let mut strip = Strip {
        ring: frame,
        edges,
        vmin: lo.y,
        vmax: hi.y,
        blocked,
    };
    // First pass: vertex coordinates and a uniform grid, sorted (the grid already is:
    // the vertex coordinates are sorted and merged into it).
    let step = w / RECTANGLE_GRID_STEPS as f64;
    xs.clear();
    xs.extend(strip.ring.iter().map(|p| p.x));
    xs.sort_unstable_by(f64::total_cmp);
    xs.dedup();
    if xs.len() > RECTANGLE_MAX_VERTEX_CANDIDATES {
        thin_candidates(xs, strip.edges);
    }
    us.clear();
    let mut grid = (1..RECTANGLE_GRID_STEPS)
        .map(|k| lo.x + step * k as f64)
        .peekable();
    for &v in xs.iter() {
        while let Some(g) = grid.next_if(|g| g.total_cmp(&v).is_lt()) {
            us.push(g);
        }
        us.push(v);
    }
    us.extend(grid);
    us.dedup();
    // Upper bounds: a rectangle's side at `u` is a vertical segment inside the region,
    // no longer than the region's spread on that line (computed when first needed).
    spread.clear();
    spread.resize(us.len(), None);
    let mut best = Best::default();
    for (i, &u0) in us.iter().enumerate() {
        // The candidates ascend: no later one leaves a wider strip to its right.
        if (hi.x - u0) * bound <= best.area {
            break;
        }
        let Some(s0) = spread_at(&strip, us, spread, i) else {
            continue;
        };
        if (hi.x - u0) * s0 <= best.area {
            continue;
        }
        for j in (i + 1..us.len()).rev() {
            let Some(&u1) = us.get(j) else {
                continue;
            };
            let width = u1 - u0;
            if width * s0 <= best.area {
                break;
            }
            let Some(s1) = spread_at(&strip, us, spread, j) else {
                continue;
            };
            if width * s1 <= best.area {
                continue;
            }
            strip.consider(u0, u1, &mut best);
        }
    }
    if best.area <= 0.0 {
        return None;
    }
    // Refinement: finer grids around the best sides.
    let mut r = step;
    for _ in 0..RECTANGLE_REFINE_ROUNDS {
        let (b0, b1) = (best.u0, best.u1);
        let cand = |c: f64| (-4..=4).map(move |k| c + r * 0.25 * f64::from(k));
        c1.clear();
        c1.extend(cand(b1).filter(|u| *u <= hi.x).map(|u| (u, None)));
        // Both candidate lists ascend: once the widest pair left cannot win, no later
        // `u0` can. Spreads are computed when a pair first needs them.
        let last = c1.last().map_or(f64::NEG_INFINITY, |c| c.0);
        for u0 in cand(b0).filter(|u| *u >= lo.x) {
            if last <= u0 || (last - u0) * bound <= best.area {
                break;
            }
            if bounded {
                // Finite spreads: a pair needs `width × s0 > best` (and the same with
                // `s1`), which holds on a suffix of the ascending right candidates only.
                let s0 = strip.spread(u0);
                let mut from = c1.len();
                while let Some(&(u1, _)) = from.checked_sub(1).and_then(|j| c1.get(j)) {
                    if !(u1 > u0 && (u1 - u0) * s0 > best.area) {
                        break;
                    }
                    from -= 1;
                }
                for (u1, s1) in c1.iter_mut().skip(from) {
                    let u1 = *u1;
                    if (u1 - u0) * s0 > best.area {
                        let s1 = *s1.get_or_insert_with(|| strip.spread(u1));
                        if (u1 - u0) * s0.min(s1) > best.area {
                            strip.consider(u0, u1, &mut best);
                        }
                    }
                }
                continue;
            }
            let mut s0 = None;
            for (u1, s1) in c1.iter_mut() {
                let u1 = *u1;
                if u1 > u0 && (u1 - u0) * bound > best.area {
                    let s1 = *s1.get_or_insert_with(|| strip.spread(u1));
                    // (Finite spreads: the minimum below cannot exceed `s1`.)
                    if !bounded || (u1 - u0) * s1 > best.area {
                        let s0 = *s0.get_or_insert_with(|| strip.spread(u0));
                        if (u1 - u0) * s0.min(s1) > best.area {
                            strip.consider(u0, u1, &mut best);
                        }
                    }
                }
            }
        }
        r *= 0.25;
    }
    placed(
        region,
        (x, y),
        [best.u0, best.u1, best.v0, best.v1],
        (lo, hi),
    )
}

/// The rectangle `[u0, u1] × [v0, v1]` of the frame with axes `x`, `y` (whose points span
/// `lo`–`hi`) back in the layout, shrunk by a tiny margin and checked exactly to lie
/// inside `region`; the margin grows a few times before giving up.
fn placed(
    region: &Polygon,
    (x, y): (DVec2, DVec2),
    [bu0, bu1, bv0, bv1]: [f64; 4],
    (lo, hi): (DVec2, DVec2),
) -> Option<Polygon> {
    let (w, h) = (hi.x - lo.x, hi.y - lo.y);
    let scale = w
        .max(h)
        .max(lo.abs().max_element())
        .max(hi.abs().max_element());
    let mut margin = 1e-9 * scale;
    for _ in 0..6 {
        let (u0, u1) = (bu0 + margin, bu1 - margin);
        let (v0, v1) = (bv0 + margin, bv1 - margin);
        if !(u1 > u0 && v1 > v0) {
            return None;
        }
        let corners = [
            x * u0 + y * v0,
            x * u1 + y * v0,
            x * u1 + y * v1,
            x * u0 + y * v1,
        ];
        if rect_inside(region, &corners) {
            let r = Polygon::new(corners.to_vec());
            return (r.area() > 0.0 && r.is_ccw()).then_some(r);
        }
        margin *= 16.0;
    }
    None
}

/// Thins the sorted, distinct vertex coordinates `xs` of a many-vertex region to at most
/// about [`RECTANGLE_MAX_VERTEX_CANDIDATES`]: the coordinates of edges across the street
/// (where the sides of an orthogonal region's optimum lie) first, then evenly spaced
/// vertex coordinates to fill up. Each pair costs a pass over the edges, so keeping
/// every coordinate of an `n`-vertex region made the sweep `O(n³)`; with a bounded set it
/// is `O(n)` per pair, and the error bound (from the uniform grid) is unchanged.
fn thin_candidates(xs: &mut Vec<f64>, edges: &[Edge]) {
    let cap = RECTANGLE_MAX_VERTEX_CANDIDATES;
    let mut across: Vec<f64> = edges.iter().filter(|e| e.dx == 0.0).map(|e| e.x0).collect();
    across.sort_unstable_by(f64::total_cmp);
    across.dedup();
    let every = |v: &[f64], k: usize| -> Vec<f64> {
        let stride = v.len().div_ceil(k.max(1)).max(1);
        v.iter().step_by(stride).copied().collect()
    };
    let mut keep = every(&across, cap / 2);
    let room = cap.saturating_sub(keep.len());
    keep.extend(every(xs, room));
    if let (Some(&first), Some(&last)) = (xs.first(), xs.last()) {
        keep.extend([first, last]);
    }
    keep.sort_unstable_by(f64::total_cmp);
    keep.dedup();
    *xs = keep;
}

/// The spread at candidate `i`, computed on first use.
fn spread_at(strip: &Strip<'_>, us: &[f64], spread: &mut [Option<f64>], i: usize) -> Option<f64> {
    let (u, s) = (us.get(i)?, spread.get_mut(i)?);
    Some(*s.get_or_insert_with(|| strip.spread(*u)))
}

/// The best rectangle so far, in frame coordinates.
#[derive(Default)]
struct Best {
    area: f64,
    u0: f64,
    u1: f64,
    v0: f64,
    v1: f64,
}

/// The region in the street frame (ring and edges), with a reusable buffer of blocked
/// intervals.
struct Strip<'a> {
    ring: &'a [DVec2],
    edges: &'a [Edge],
    vmin: f64,
    vmax: f64,
    blocked: &'a mut Vec<(f64, f64)>,
}

impl Strip<'_> {
    /// The region's extent along the line `u = const`: from its lowest to its highest
    /// point there (0 if the line misses it).
    fn spread(&self, u: f64) -> f64 {
        let (mut v0, mut v1) = (f64::INFINITY, f64::NEG_INFINITY);
        for e in self.edges {
            if u < e.x0 || u > e.x1 {
                continue;
            }
            // (The interpolated point is both ends of its interval: one `min`, one `max`.)
            let (va, vb) = if e.dx == 0.0 {
                (e.ylo, e.yhi)
            } else {
                let v = e.at(u);
                (v, v)
            };
            v0 = v0.min(va);
            v1 = v1.max(vb);
        }
        (v1 - v0).max(0.0)
    }

    /// The tallest rectangle over `[u0, u1]` inside the region; replaces `best` when larger.
    fn consider(&mut self, u0: f64, u1: f64, best: &mut Best) {
        self.blocked.clear();
        for e in self.edges {
            if e.x1 <= u0 || e.x0 >= u1 {
                continue;
            }
            self.blocked.push(if e.dx == 0.0 {
                (e.ylo, e.yhi)
            } else {
                let va = if e.x0 < u0 { e.at(u0) } else { e.y0 };
                let vb = if e.x1 > u1 { e.at(u1) } else { e.y1 };
                (va.min(vb), va.max(vb))
            });
        }
        sort_by_start(self.blocked);
        tallest_gap(
            self.ring,
            (self.vmin, self.vmax),
            self.blocked,
            (u0, u1),
            best,
        );
    }
}

/// Walks the gaps between the sorted blocked intervals of the strip `[u0, u1]` (from
/// `vmin` to `vmax`): a gap holds no boundary point, so one exact point-in-ring test at its
/// middle decides whether it lies inside; an inside gap taller than `best` replaces it.
fn tallest_gap(
    ring: &[DVec2],
    (vmin, vmax): (f64, f64),
    blocked: &[(f64, f64)],
    (u0, u1): (f64, f64),
    best: &mut Best,
) {
    let width = u1 - u0;
    let mid = 0.5 * (u0 + u1);
    let mut cur = vmin;
    let gaps = blocked.iter().copied().chain(std::iter::once((vmax, vmax)));
    for (s, e) in gaps {
        if s > cur && (s - cur) * width > best.area {
            let m = DVec2::new(mid, 0.5 * (cur + s));
            if polis_geom::polygon::locate_in_ring(ring, m) == polis_geom::PointLocation::Inside {
                *best = Best {
                    area: (s - cur) * width,
                    u0,
                    u1,
                    v0: cur,
                    v1: s,
                };
            }
        }
        cur = cur.max(e);
    }
}

/// A stable sort of intervals by start (`total_cmp`). The standard library's stable sort
/// is an insertion sort on the handful of intervals of a small region's strip and
/// `O(k log k)` on the thousands of a many-vertex region's (where an insertion sort made
/// each strip quadratic).
fn sort_by_start(v: &mut [(f64, f64)]) {
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain sweep this module replaced (every pair's spreads computed up front, the
    /// per-edge modulo and ordering, a full sort of the candidates), kept as the
    /// reference the pruned sweep must equal bit for bit.
    mod reference {
        use super::super::{Best, RECTANGLE_GRID_STEPS, RECTANGLE_REFINE_ROUNDS};
        use polis_geom::{DVec2, Polygon};

        pub fn largest(region: &Polygon, dir: DVec2) -> Option<Polygon> {
            let (mut frame, mut us, mut spread, mut blocked, mut c1) =
                (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
            let len = dir.length();
            if !(len > 0.0 && len.is_finite()) || region.len() < 3 {
                return None;
            }
            let x = dir / len;
            let y = x.perp();
            frame.extend(
                region
                    .points()
                    .iter()
                    .map(|p| DVec2::new(p.dot(x), p.dot(y))),
            );
            if frame.iter().any(|p: &DVec2| !p.is_finite()) {
                return None;
            }
            let (mut lo, mut hi) = (DVec2::INFINITY, DVec2::NEG_INFINITY);
            for p in frame.iter() {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            let (w, h) = (hi.x - lo.x, hi.y - lo.y);
            if !(w > 0.0 && h > 0.0) {
                return None;
            }
            let mut strip = Strip {
                ring: &frame,
                vmin: lo.y,
                vmax: hi.y,
                blocked: &mut blocked,
            };
            us.extend(strip.ring.iter().map(|p| p.x));
            let step = w / RECTANGLE_GRID_STEPS as f64;
            us.extend((1..RECTANGLE_GRID_STEPS).map(|k| lo.x + step * k as f64));
            us.sort_by(f64::total_cmp);
            us.dedup();
            spread.extend(us.iter().map(|&u| strip.spread(u)));
            let mut best = Best::default();
            for (i, &u0) in us.iter().enumerate() {
                let s0 = spread[i];
                if (hi.x - u0) * s0 <= best.area {
                    continue;
                }
                for (j, &u1) in us.iter().enumerate().skip(i + 1).rev() {
                    let width = u1 - u0;
                    if width * s0 <= best.area {
                        break;
                    }
                    if width * spread[j] <= best.area {
                        continue;
                    }
                    strip.consider(u0, u1, &mut best);
                }
            }
            if best.area <= 0.0 {
                return None;
            }
            let mut r = step;
            for _ in 0..RECTANGLE_REFINE_ROUNDS {
                let (b0, b1) = (best.u0, best.u1);
                let cand = |c: f64| (-4..=4).map(move |k| c + r * 0.25 * f64::from(k));
                c1.clear();
                c1.extend(
                    cand(b1)
                        .filter(|u| *u <= hi.x)
                        .map(|u| (u, strip.spread(u))),
                );
                for u0 in cand(b0).filter(|u| *u >= lo.x) {
                    let s0 = strip.spread(u0);
                    for &(u1, s1) in c1.iter() {
                        if u1 > u0 && (u1 - u0) * s0.min(s1) > best.area {
                            strip.consider(u0, u1, &mut best);
                        }
                    }
                }
                r *= 0.25;
            }
            super::placed(
                region,
                (x, y),
                [best.u0, best.u1, best.v0, best.v1],
                (lo, hi),
            )
        }

        struct Strip<'a> {
            ring: &'a [DVec2],
            vmin: f64,
            vmax: f64,
            blocked: &'a mut Vec<(f64, f64)>,
        }

        impl Strip<'_> {
            fn spread(&self, u: f64) -> f64 {
                let (mut v0, mut v1) = (f64::INFINITY, f64::NEG_INFINITY);
                let n = self.ring.len();
                for i in 0..n {
                    let (a, b) = (self.ring[i], self.ring[(i + 1) % n]);
                    let (p, q) = if a.x <= b.x { (a, b) } else { (b, a) };
                    if u < p.x || u > q.x {
                        continue;
                    }
                    let (va, vb) = if p.x == q.x {
                        (p.y, q.y)
                    } else {
                        let v = p.y + (q.y - p.y) * ((u - p.x) / (q.x - p.x));
                        (v, v)
                    };
                    v0 = v0.min(va.min(vb));
                    v1 = v1.max(va.max(vb));
                }
                (v1 - v0).max(0.0)
            }

            fn consider(&mut self, u0: f64, u1: f64, best: &mut Best) {
                self.blocked.clear();
                let n = self.ring.len();
                for i in 0..n {
                    let (a, b) = (self.ring[i], self.ring[(i + 1) % n]);
                    let (p, q) = if a.x <= b.x { (a, b) } else { (b, a) };
                    if q.x <= u0 || p.x >= u1 {
                        continue;
                    }
                    let (va, vb) = if p.x == q.x {
                        (p.y, q.y)
                    } else {
                        let at = |u: f64| p.y + (q.y - p.y) * ((u - p.x) / (q.x - p.x));
                        (
                            if p.x < u0 { at(u0) } else { p.y },
                            if q.x > u1 { at(u1) } else { q.y },
                        )
                    };
                    self.blocked.push((va.min(vb), va.max(vb)));
                }
                self.blocked.sort_by(|a, b| a.0.total_cmp(&b.0));
                super::super::tallest_gap(
                    self.ring,
                    (self.vmin, self.vmax),
                    self.blocked,
                    (u0, u1),
                    best,
                );
            }
        }
    }

    /// Bit patterns of a result (`None` stays `None`).
    fn bits(r: Option<Polygon>) -> Option<Vec<[u64; 2]>> {
        r.map(|p| {
            p.points()
                .iter()
                .map(|q| [q.x.to_bits(), q.y.to_bits()])
                .collect()
        })
    }

    /// Regions biased to what breaks sweeps: integer (collinear, axis-parallel,
    /// repeated-coordinate) stars and staircases, concave combs, slivers, rotated and
    /// far-from-the-origin copies, and general random rings (some invalid or clockwise:
    /// both versions must still agree).
    fn region() -> impl proptest::strategy::Strategy<Value = (Vec<DVec2>, DVec2)> {
        use proptest::prelude::*;
        (
            0usize..6,
            3usize..14,
            prop::collection::vec(0.05f64..1.0, 14),
            prop::collection::vec(-6i32..7, 28),
            (0.5f64..80.0, -3.2f64..3.2, 0usize..4),
        )
            .prop_map(|(family, n, radii, ints, (size, angle, far))| {
                let offset = [0.0, 1e3, 1e5, -3.7e6][far];
                let mut pts: Vec<DVec2> = match family {
                    // Star with random radii (concave, near-collinear runs).
                    0 => (0..n)
                        .map(|i| {
                            let a = std::f64::consts::TAU * i as f64 / n as f64;
                            DVec2::from_angle(a) * size * radii[i]
                        })
                        .collect(),
                    // Integer staircase star: exact collinear and axis-parallel edges.
                    1 => (0..n)
                        .map(|i| {
                            let a = std::f64::consts::TAU * i as f64 / n as f64;
                            (DVec2::from_angle(a) * f64::from(ints[i].abs() + 1)).round()
                        })
                        .collect(),
                    // A comb: teeth of random integer depths along the street.
                    2 => {
                        let teeth = n.min(7);
                        let mut p = vec![DVec2::new(0.0, 0.0), DVec2::new(2.0 * teeth as f64, 0.0)];
                        for t in (0..teeth).rev() {
                            let x = 2.0 * t as f64;
                            let d = f64::from(ints[t].abs() + 1);
                            p.push(DVec2::new(x + 2.0, d));
                            p.push(DVec2::new(x + 1.0, d));
                            p.push(DVec2::new(x + 1.0, 1.0));
                            p.push(DVec2::new(x, 1.0));
                        }
                        p.pop();
                        p.push(DVec2::new(0.0, f64::from(ints[0].abs() + 1)));
                        p.iter().map(|q| *q * size * 0.1).collect()
                    }
                    // A sliver: a long thin quad or triangle.
                    3 => {
                        let t = radii[0] * 1e-3;
                        let mut p = vec![
                            DVec2::ZERO,
                            DVec2::new(size, 0.0),
                            DVec2::new(size * radii[1], size * t),
                        ];
                        if n % 2 == 0 {
                            p.push(DVec2::new(size * radii[2] * 0.5, size * t * radii[3]));
                        }
                        p
                    }
                    // Random integer ring (often self-intersecting or with repeats).
                    4 => (0..n)
                        .map(|i| DVec2::new(f64::from(ints[2 * i]), f64::from(ints[2 * i + 1])))
                        .collect(),
                    // A rotated rectangle with collinear extra vertices on its sides.
                    _ => {
                        let (w, d) = (size, size * radii[0]);
                        let x = DVec2::from_angle(angle);
                        let y = x.perp();
                        vec![
                            DVec2::ZERO,
                            x * w * 0.5,
                            x * w,
                            x * w + y * d,
                            x * w * radii[1] + y * d,
                            y * d,
                        ]
                    }
                };
                for p in &mut pts {
                    *p += DVec2::splat(offset);
                }
                let dir = match family {
                    5 => DVec2::from_angle(angle) * radii[2],
                    1 | 2 | 4 if angle > 0.0 => DVec2::X,
                    _ => DVec2::from_angle(angle),
                };
                (pts, dir)
            })
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 256, ..Default::default() })]
        #[test]
        fn pruned_sweep_equals_the_plain_sweep((pts, dir) in region()) {
            let mut poly = Polygon::new(pts);
            proptest::prop_assert_eq!(
                bits(largest(&poly, dir)),
                bits(reference::largest(&poly, dir))
            );
            // The footprint's case: a valid counter-clockwise region.
            if poly.validate().is_ok() {
                poly.make_ccw();
                proptest::prop_assert_eq!(
                    bits(largest(&poly, dir)),
                    bits(reference::largest(&poly, dir))
                );
            }
        }
    }

    #[test]
    fn pruned_sweep_equals_the_plain_sweep_on_known_shapes() {
        let shapes = [
            super::super::tests::l_shape().points().to_vec(),
            vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(16.0, 0.0),
                DVec2::new(0.0, 10.0),
            ],
            vec![
                DVec2::new(-0.0, -0.0),
                DVec2::new(8.0, 0.0),
                DVec2::new(8.0, 8.0),
                DVec2::new(0.0, 8.0),
            ],
        ];
        for s in shapes {
            let p = Polygon::new(s);
            for dir in [
                DVec2::X,
                DVec2::Y,
                DVec2::new(1.0, 1.0),
                DVec2::new(-3.0, 0.1),
            ] {
                let r = largest(&p, dir);
                assert_eq!(bits(r.clone()), bits(reference::largest(&p, dir)));
                if dir == DVec2::X {
                    assert!(r.is_some());
                }
            }
        }
    }

    #[test]
    fn intervals_sort_stably_by_start() {
        let mut v = [(3.0, 4.0), (1.0, 9.0), (3.0, 3.5), (-0.0, 1.0), (0.0, 0.5)];
        let mut w = v;
        sort_by_start(&mut v);
        w.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert_eq!(
            v.map(|(a, b)| (a.to_bits(), b.to_bits())),
            w.map(|(a, b)| (a.to_bits(), b.to_bits()))
        );
    }
}
