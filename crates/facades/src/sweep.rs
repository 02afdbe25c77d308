//! The span rasteriser: one row of texels at a time, by runs instead of points.
//!
//! Point evaluation walks the stack top-down for every texel. Along one row, though, each
//! layer's activity only changes at interval and profile boundaries: for AND, OR and
//! `Always` layers with box profiles the active set of cell `(i, j)` on the row is one
//! interval of `s` found analytically. The sweep therefore
//!
//! 1. paints, bottom layer first, each layer's active runs into an *owner* array (a higher
//!    layer overwrites a lower one: exactly the stack's fall-through); layers whose
//!    activity is not a run (image maps, nested layers and stacks, closures, smooth
//!    profiles, cells scaled by an influence) are probed texel by texel inside their
//!    candidate range only, and their samples kept;
//! 2. colours every texel from its owner's colour function, with constant colours costing
//!    a copy.
//!
//! The result equals point evaluation at the texel centres (tested).

use crate::color::{Col, PointCtx};
use crate::interval::Hit;
use crate::layer::{Eval, Layer};
use crate::sample::{FacadeSample, hash2};
use crate::stack::{LayerStack, RowState};

/// Owner flag: the texel's sample was computed while probing.
const DONE: u32 = u32::MAX;

/// Where a row sweep writes its samples: texels `0..w` are written once each, in
/// increasing order, as runs.
pub(crate) trait RowSink {
    /// Texels `a..b` take `m`.
    fn fill(&mut self, a: usize, b: usize, m: FacadeSample);
    /// Texel `x` takes `m`.
    #[inline]
    fn put(&mut self, x: usize, m: FacadeSample) {
        self.fill(x, x + 1, m);
    }
    /// Whether the sink keeps column strips by reference ([`RowSink::strip`]).
    fn wants_strips(&self) -> bool {
        false
    }
    /// Texels `a..b` take `samples` (one each), which are `a..b` of the sweep's strip `id`.
    fn strip(&mut self, a: usize, b: usize, id: u32, samples: &[FacadeSample]) {
        let _ = id;
        for (k, m) in samples.iter().enumerate().take(b.saturating_sub(a)) {
            self.put(a + k, *m);
        }
    }
}

/// A sink that stores one sample per texel.
pub(crate) struct Texels<'a>(pub(crate) &'a mut [FacadeSample]);

impl RowSink for Texels<'_> {
    #[inline]
    fn fill(&mut self, a: usize, b: usize, m: FacadeSample) {
        if let Some(run) = self.0.get_mut(a..b) {
            run.fill(m);
        }
    }

    #[inline]
    fn put(&mut self, x: usize, m: FacadeSample) {
        if let Some(o) = self.0.get_mut(x) {
            *o = m;
        }
    }
}

/// What a run of a row holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum RunKind {
    /// One sample over the whole run.
    Const(FacadeSample),
    /// The same texels of a column strip of the sweep (a colour that depends on `s` only).
    Strip(u32),
}

/// A run of texels ending (exclusive) at `end`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Run {
    /// One past the last texel.
    pub(crate) end: u32,
    /// Its content.
    pub(crate) kind: RunKind,
}

/// A row as maximal runs (adjacent equal constant runs are merged).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct RowRuns {
    pub(crate) runs: Vec<Run>,
}

impl RowSink for RowRuns {
    #[inline]
    fn fill(&mut self, a: usize, b: usize, m: FacadeSample) {
        if b <= a {
            return;
        }
        let end = b as u32;
        if let Some(last) = self.runs.last_mut()
            && last.kind == RunKind::Const(m)
        {
            last.end = end;
            return;
        }
        self.runs.push(Run {
            end,
            kind: RunKind::Const(m),
        });
    }

    fn wants_strips(&self) -> bool {
        true
    }

    #[inline]
    fn strip(&mut self, a: usize, b: usize, id: u32, _samples: &[FacadeSample]) {
        if b <= a {
            return;
        }
        let end = b as u32;
        if let Some(last) = self.runs.last_mut()
            && last.kind == RunKind::Strip(id)
        {
            last.end = end;
            return;
        }
        self.runs.push(Run {
            end,
            kind: RunKind::Strip(id),
        });
    }
}

#[derive(Debug, Clone, Copy)]
struct Span {
    layer: usize,
    hu: Hit,
    hv: Hit,
    box_x0: f64,
    box_y0: f64,
    box_w: f64,
    box_h: f64,
    /// For an image cell: the chosen image and the cell seed.
    image: Option<(usize, u64)>,
}

/// The first of the sorted texel centres `xs` that is `≥ s` (`> s` when `strict` is
/// false): O(1) from the spacing, corrected against the exact centres so the answer
/// equals a binary search.
#[inline]
fn first_at_or_after(xs: &[f64], s: f64, strict: bool) -> usize {
    let n = xs.len();
    let below = |x: f64| if strict { x < s } else { x <= s };
    let (Some(&first), Some(&second)) = (xs.first(), xs.get(1)) else {
        return xs.partition_point(|&x| below(x));
    };
    let ds = second - first;
    let guess = ((s - first) / ds).ceil();
    let mut k = if guess.is_nan() {
        0
    } else {
        guess.clamp(0.0, n as f64) as usize
    };
    while k > 0 && xs.get(k - 1).is_some_and(|&x| !below(x)) {
        k -= 1;
    }
    while xs.get(k).is_some_and(|&x| below(x)) {
        k += 1;
    }
    k
}

/// Reusable buffers of the row sweep for one raster width.
#[derive(Debug, Clone, Default)]
pub(crate) struct RowSweep {
    xs: Vec<f64>,
    owner: Vec<u32>,
    samples: Vec<FacadeSample>,
    spans: Vec<Span>,
    state: RowState,
    /// Sweeps for nested stacks (reused) and their output row.
    pool: Vec<RowSweep>,
    nested_out: Vec<FacadeSample>,
    /// Column strips of colours that depend on `s` alone, keyed by the colour's address
    /// (valid for the stack being swept): one sample per texel.
    strips: Vec<(usize, Vec<FacadeSample>)>,
    /// Whole rows of facade-aligned brick patterns, keyed by (colour address, course,
    /// depth): every row of a course between its joints is the same.
    brick_rows: Vec<((usize, u64, u32), RowRuns, usize)>,
    /// Next entry of `brick_rows` to replace when full.
    brick_next: usize,
}

/// Most cached brick rows (several brick colours may alternate along a row).
const BRICK_ROWS: usize = 16;

impl RowSweep {
    /// A sweep over `w` texels whose centres are `s0 + (x + ½)·ds`.
    pub(crate) fn new(s0: f64, ds: f64, w: usize) -> Self {
        RowSweep {
            xs: (0..w).map(|x| s0 + (x as f64 + 0.5) * ds).collect(),
            owner: vec![0; w],
            samples: vec![FacadeSample::default(); w],
            spans: Vec::new(),
            state: RowState::default(),
            pool: Vec::new(),
            nested_out: Vec::new(),
            strips: Vec::new(),
            brick_rows: Vec::new(),
            brick_next: 0,
        }
    }

    /// Emits texels `a..b` of a facade-aligned brick colour from the row cache of its
    /// course (computed over the whole row on first use). `None` if the colour is not such
    /// a pattern.
    fn cached_bricks<S: RowSink>(
        &mut self,
        col: &Col,
        t: f64,
        depth: f32,
        a: usize,
        b: usize,
        sink: &mut S,
    ) -> Option<()> {
        let Col::Bricks(bricks) = col else {
            return None;
        };
        if bricks.in_cell {
            return None;
        }
        let course = bricks.course(t)?;
        let key = (
            col as *const Col as usize,
            course.to_bits(),
            depth.to_bits(),
        );
        let slot = match self.brick_rows.iter().position(|(k, _, _)| *k == key) {
            Some(p) => p,
            None => {
                let mut runs = RowRuns::default();
                bricks.eval_row(&self.xs, 0, None, t, depth, &mut runs);
                if self.brick_rows.len() < BRICK_ROWS {
                    self.brick_rows.push((key, runs, 0));
                    self.brick_rows.len() - 1
                } else {
                    let p = self.brick_next % BRICK_ROWS;
                    self.brick_next = p + 1;
                    if let Some(e) = self.brick_rows.get_mut(p) {
                        *e = (key, runs, 0);
                    }
                    p
                }
            }
        };
        let (_, cached, cursor) = self.brick_rows.get_mut(slot)?;
        let runs = &cached.runs;
        // Runs are asked for left to right along a row: continue from the last one.
        let mut start = *cursor;
        if start > 0 && runs.get(start - 1).is_none_or(|r| r.end as usize > a) {
            start = runs.partition_point(|r| (r.end as usize) <= a);
        }
        while runs.get(start).is_some_and(|r| (r.end as usize) <= a) {
            start += 1;
        }
        let mut from = a;
        while from < b {
            let Some(r) = runs.get(start) else { break };
            let to = (r.end as usize).min(b);
            if let RunKind::Const(m) = r.kind {
                sink.fill(from, to, m);
            }
            from = to;
            if r.end as usize <= b {
                start += 1;
            }
        }
        *cursor = start;
        Some(())
    }

    /// The samples of column strip `id` (one per texel), as referenced by
    /// [`RunKind::Strip`].
    pub(crate) fn strip_samples(&self, id: u32) -> &[FacadeSample] {
        self.strips.get(id as usize).map_or(&[], |s| s.1.as_slice())
    }

    /// The strip id of `col` (with `depth`) if it depends on `s` alone, computing it on
    /// first use.
    fn strip_id(&mut self, col: &Col, depth: f32) -> Option<u32> {
        let key = col as *const Col as usize;
        if let Some(k) = self.strips.iter().position(|(c, _)| *c == key) {
            return Some(k as u32);
        }
        let samples = col.vertical_strip(&self.xs, depth)?;
        self.strips.push((key, samples));
        Some(self.strips.len() as u32 - 1)
    }

    /// Re-targets the sweep at arbitrary sorted texel positions.
    fn set_xs(&mut self, xs: impl Iterator<Item = f64>) {
        self.xs.clear();
        self.xs.extend(xs);
        let n = self.xs.len();
        self.owner.resize(n, 0);
        self.samples.resize(n, FacadeSample::default());
    }

    /// Evaluates the row at height `t` into `out` (one sample per texel).
    pub(crate) fn row(&mut self, stack: &LayerStack, t: f64, out: &mut [FacadeSample]) {
        let w = out.len().min(self.xs.len());
        let out = out.get_mut(..w).unwrap_or_default();
        self.row_into(stack, t, &mut Texels(out));
    }

    /// Evaluates the row at height `t` as runs (cleared first).
    pub(crate) fn row_runs(&mut self, stack: &LayerStack, t: f64, out: &mut RowRuns) {
        out.runs.clear();
        self.row_into(stack, t, out);
    }

    /// Evaluates the row at height `t` into a sink, texels `0..w` in order.
    fn row_into<S: RowSink>(&mut self, stack: &LayerStack, t: f64, sink: &mut S) {
        stack.begin_row(t, &mut self.state);
        self.owner.fill(0);
        self.spans.clear();
        let xs = &self.xs;
        for (k, layer) in stack.layers().iter().enumerate() {
            let Some(hv) = layer.v.locate(t) else {
                continue;
            };
            let j = hv.index;
            let scaled = layer.cell_scale.is_some();
            let v_box = layer.v.get(j).is_some_and(|iv| iv.profile.is_box());
            // Whole-row rejections (unscaled cells only: scaling moves boxes in t).
            if layer
                .v_mask
                .as_ref()
                .is_some_and(|m| !m.get(j).copied().unwrap_or(false))
            {
                continue;
            }
            if !scaled && v_box {
                let v_on = layer.v.value(j, t) >= 0.5;
                let in_v_box = layer.v.active(j).is_some_and(|(a, b)| t >= a && t < b);
                match layer.eval {
                    Eval::And if !v_on => continue,
                    Eval::Image(_) | Eval::Nested(_) | Eval::Stack(_) if !in_v_box => continue,
                    _ => {}
                }
            }
            for (i, iv) in layer.u.intervals().iter().enumerate() {
                if !layer.selected(i, j) {
                    continue;
                }
                let hu = Hit {
                    index: i,
                    start: iv.start,
                    end: iv.end,
                };
                let Some(bx) = layer.unscaled_box(&hu, &hv) else {
                    continue;
                };
                // Cells untouched by influences (scale 1) take the fast paths.
                let scaled = scaled && layer.scale_of(i, j) != [1.0, 1.0];
                let definite = !scaled
                    && v_box
                    && iv.profile.is_box()
                    && matches!(layer.eval, Eval::Always | Eval::And | Eval::Or);
                // The candidate range of `s` on this row, before clipping to the cell.
                let (sa, sb) = if definite {
                    match layer.eval {
                        Eval::And => {
                            if layer.v.value(j, t) < 0.5 {
                                continue;
                            }
                            let Some(r) = layer.u.active(i) else { continue };
                            r
                        }
                        Eval::Or if layer.v.value(j, t) < 0.5 => {
                            let Some(r) = layer.u.active(i) else { continue };
                            r
                        }
                        _ => (hu.start, hu.end),
                    }
                } else if scaled {
                    let [su, sv] = layer.scale_of(i, j);
                    if su <= 0.0 || sv <= 0.0 {
                        continue;
                    }
                    let (cx, cy) = (0.5 * (bx[0] + bx[1]), 0.5 * (bx[2] + bx[3]));
                    let y = cy + (t - cy) / sv;
                    if !(y >= hv.start && y <= hv.end) {
                        continue;
                    }
                    // Scaled cells are probed over the whole scaled cell (pad a texel for
                    // rounding; the probe decides).
                    let pad = xs.get(1).zip(xs.first()).map_or(0.0, |(b, a)| b - a);
                    (
                        cx + (hu.start - cx) * su - pad,
                        cx + (hu.end - cx) * su + pad,
                    )
                } else {
                    match layer.eval {
                        Eval::Image(_) | Eval::Nested(_) | Eval::Stack(_) => {
                            if !(t >= bx[2] && t < bx[3]) {
                                continue;
                            }
                            (bx[0], bx[1])
                        }
                        _ => (hu.start, hu.end),
                    }
                };
                let (sa, sb) = (sa.max(hu.start), sb.min(hu.end));
                let x0 = first_at_or_after(xs, sa, true);
                // The last interval is closed at L.
                let x1 = first_at_or_after(xs, sb, i + 1 != layer.u.len());
                if x0 >= x1 {
                    continue;
                }
                let id = self.spans.len() as u32 + 1;
                self.spans.push(Span {
                    layer: k,
                    hu,
                    hv,
                    box_x0: bx[0],
                    box_y0: bx[2],
                    box_w: bx[1] - bx[0],
                    box_h: bx[3] - bx[2],
                    image: None,
                });
                if definite {
                    if let Some(o) = self.owner.get_mut(x0..x1) {
                        o.fill(id);
                    }
                } else if let (Eval::Image(set), false) = (&layer.eval, scaled) {
                    // One image per cell: choose it once, then sample texels directly
                    // (the same arithmetic as `Layer::probe_hits`).
                    // The texels where the image is opaque become the span's; they
                    // are coloured with the runs.
                    let seed = hash2(layer.seed, i as i64, j as i64);
                    let chosen = set.choose(seed);
                    let Some(img) = set.get(chosen) else {
                        continue;
                    };
                    if let Some(sp) = self.spans.last_mut() {
                        sp.image = Some((chosen, seed));
                    }
                    let (bw, bh) = (bx[1] - bx[0], bx[3] - bx[2]);
                    let v = (t - bx[2]) / bh;
                    let (Some(xr), Some(or)) = (xs.get(x0..x1), self.owner.get_mut(x0..x1)) else {
                        continue;
                    };
                    for (&s, o) in xr.iter().zip(or) {
                        if img.sample((s - bx[0]) / bw, v).albedo[3] >= 0.5 {
                            *o = id;
                        }
                    }
                } else if let (Eval::Stack(inner), false) = (&layer.eval, scaled) {
                    // A nested stack: sweep its row over the texels mapped into its
                    // domain (the same arithmetic as `Layer::probe_hits`).
                    let (bw, bh) = (bx[1] - bx[0], bx[3] - bx[2]);
                    let (iw, ih) = (inner.width(), inner.height());
                    let nt = (t - bx[2]) / bh * ih;
                    let mut sub = self.pool.pop().unwrap_or_default();
                    sub.set_xs(xs[x0..x1].iter().map(|&s| (s - bx[0]) / bw * iw));
                    let mut buf = std::mem::take(&mut self.nested_out);
                    buf.resize(x1 - x0, FacadeSample::default());
                    sub.row(inner, nt, &mut buf);
                    let has_bg = inner.background().is_some();
                    for (q, x) in (x0..x1).enumerate() {
                        if !has_bg && sub.owner.get(q).is_none_or(|&o| o == 0) {
                            continue;
                        }
                        let (Some(&s), Some(&inner_m)) = (xs.get(x), buf.get(q)) else {
                            break;
                        };
                        let col = stack
                            .border_col_in_row(k, s, &self.state)
                            .unwrap_or(&layer.col);
                        let m = match col {
                            Col::Inherit { .. } => inner_m,
                            _ => {
                                let ctx = PointCtx {
                                    s,
                                    t,
                                    i,
                                    j,
                                    local: [s - bx[0], t - bx[2]],
                                    size: [bw, bh],
                                    pu: layer.u.value(i, s),
                                    pv: layer.v.value(j, t),
                                    cell_seed: if matches!(layer.col, Col::Custom(_)) {
                                        hash2(layer.seed, i as i64, j as i64)
                                    } else {
                                        0
                                    },
                                };
                                col.eval(&ctx, Some(&inner_m))
                            }
                        };
                        if let (Some(smp), Some(o)) =
                            (self.samples.get_mut(x), self.owner.get_mut(x))
                        {
                            *smp = m;
                            smp.height += layer.depth_m;
                            *o = DONE;
                        }
                    }
                    self.nested_out = buf;
                    self.pool.push(sub);
                } else {
                    for x in x0..x1 {
                        let Some(&s) = xs.get(x) else { break };
                        if let Some(p) = layer.probe_hits(s, t, &hu, &hv) {
                            let col = stack
                                .border_col_in_row(k, s, &self.state)
                                .unwrap_or(&layer.col);
                            if let (Some(smp), Some(o)) =
                                (self.samples.get_mut(x), self.owner.get_mut(x))
                            {
                                *smp = layer.shade(&p, col);
                                *o = DONE;
                            }
                        }
                    }
                }
            }
        }
        let background = stack.background().unwrap_or_default();
        let layers = stack.layers();
        let w = self.owner.len();
        let mut x = 0;
        while x < w {
            let o = self.owner[x];
            let mut e = x + 1;
            while e < w && self.owner[e] == o {
                e += 1;
            }
            match o {
                0 => sink.fill(x, e, background),
                DONE => {
                    for (q, m) in self.samples[x..e].iter().enumerate() {
                        sink.put(x + q, *m);
                    }
                }
                id => {
                    let sp = self.spans.get(id as usize - 1).copied();
                    let layer = sp.and_then(|sp| layers.get(sp.layer));
                    let (Some(sp), Some(layer)) = (sp, layer) else {
                        sink.fill(x, e, background);
                        x = e;
                        continue;
                    };
                    if stack.has_borders(sp.layer) {
                        // Split the run where a border colour starts or stops.
                        let mut a = x;
                        while a < e {
                            let mut b = e;
                            let xs = &self.xs;
                            let col = stack
                                .border_run(sp.layer, xs[a], &mut self.state, |s, inclusive| {
                                    b = b.min(first_at_or_after(xs, s, inclusive).max(a + 1));
                                })
                                .unwrap_or(&layer.col);
                            self.shade_run(layer, &sp, col, t, background, a, b, sink);
                            a = b;
                        }
                    } else {
                        self.shade_run(layer, &sp, &layer.col, t, background, x, e, sink);
                    }
                }
            }
            x = e;
        }
    }

    /// Colours texels `a..b` of a definite span with `col`.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn shade_run<S: RowSink>(
        &mut self,
        layer: &Layer,
        sp: &Span,
        col: &Col,
        t: f64,
        background: FacadeSample,
        a: usize,
        b: usize,
        sink: &mut S,
    ) {
        if sink.wants_strips()
            && let Some(id) = self.strip_id(col, layer.depth_m)
        {
            let samples = self.strip_samples(id);
            sink.strip(a, b, id, samples.get(a..b).unwrap_or_default());
            return;
        }
        if sink.wants_strips()
            && self
                .cached_bricks(col, t, layer.depth_m, a, b, sink)
                .is_some()
        {
            return;
        }
        let xs = &self.xs[a..b];
        if let (Some((chosen, seed)), Eval::Image(set)) = (sp.image, &layer.eval) {
            let Some(img) = set.get(chosen) else {
                sink.fill(a, b, background);
                return;
            };
            // The same arithmetic as `Layer::probe_hits`; one colour per image texel.
            let ly = t - sp.box_y0;
            let v = ly / sp.box_h;
            let mut run: Option<(usize, FacadeSample, FacadeSample)> = None;
            for (k, &s) in xs.iter().enumerate() {
                let local = [s - sp.box_x0, ly];
                let texel = img.sample(local[0] / sp.box_w, v);
                if let Some((start, last, m)) = run {
                    if last == texel && matches!(col, Col::Inherit { .. }) {
                        continue;
                    }
                    sink.fill(start, a + k, m);
                }
                let mut m = match col {
                    Col::Inherit { .. } => texel,
                    _ => {
                        let ctx = PointCtx {
                            s,
                            t,
                            i: sp.hu.index,
                            j: sp.hv.index,
                            local,
                            size: [sp.box_w, sp.box_h],
                            pu: layer.u.value(sp.hu.index, s),
                            pv: layer.v.value(sp.hv.index, t),
                            cell_seed: seed,
                        };
                        col.eval(&ctx, Some(&texel))
                    }
                };
                m.height += layer.depth_m;
                run = Some((a + k, texel, m));
            }
            if let Some((start, _, m)) = run {
                sink.fill(start, b, m);
            }
            return;
        }
        if let Col::Custom(_) = col {
            for (k, &s) in xs.iter().enumerate() {
                let m = match layer.probe_hits(s, t, &sp.hu, &sp.hv) {
                    Some(p) => layer.shade(&p, col),
                    None => background,
                };
                sink.put(a + k, m);
            }
            return;
        }
        let ctx_at = |s: f64| PointCtx {
            s,
            t,
            i: sp.hu.index,
            j: sp.hv.index,
            local: [s - sp.box_x0, t - sp.box_y0],
            size: [sp.box_w, sp.box_h],
            pu: layer.u.value(sp.hu.index, s),
            pv: layer.v.value(sp.hv.index, t),
            cell_seed: 0,
        };
        col.eval_row(xs, a, t, sp.box_x0, layer.depth_m, ctx_at, sink);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin::builtin_styles;
    use crate::facade::{FacadeSpec, FaceRole, PreparedStyle};
    use crate::interval::IntervalGroup;
    use crate::layer::Layer;
    use crate::profile::Profile;
    use crate::stack::{Influence, Relation};

    fn check(stack: &LayerStack, w: f64, h: f64, ppm: f64) {
        let (nx, ny) = (
            (w * ppm).round().max(1.0) as usize,
            (h * ppm).round().max(1.0) as usize,
        );
        let (ds, dt) = (w / nx as f64, h / ny as f64);
        let mut sweep = RowSweep::new(0.0, ds, nx);
        let mut row = vec![FacadeSample::default(); nx];
        // The run sweep (column strips, brick-row cache) expanded back to texels.
        let mut run_sweep = RowSweep::new(0.0, ds, nx);
        let mut runs = RowRuns::default();
        let mut expanded = vec![FacadeSample::default(); nx];
        for y in 0..ny {
            let t = h - (y as f64 + 0.5) * dt;
            sweep.row(stack, t, &mut row);
            run_sweep.row_runs(stack, t, &mut runs);
            let mut a = 0;
            for r in &runs.runs {
                let b = r.end as usize;
                assert!(b > a, "empty or unordered run");
                match r.kind {
                    RunKind::Const(m) => expanded[a..b].fill(m),
                    RunKind::Strip(id) => {
                        expanded[a..b].copy_from_slice(&run_sweep.strip_samples(id)[a..b]);
                    }
                }
                a = b;
            }
            assert_eq!(a, nx, "runs cover the row");
            // Runs are maximal: no two adjacent constant runs are equal.
            for pair in runs.runs.windows(2) {
                assert_ne!(pair[0].kind, pair[1].kind, "unmerged runs");
            }
            for (x, (got, from_runs)) in row.iter().zip(&expanded).enumerate() {
                let s = (x as f64 + 0.5) * ds;
                let want = stack.sample(s, t);
                assert_eq!(*got, want, "texel ({x}, {y}) at ({s}, {t})");
                assert_eq!(*from_runs, want, "run texel ({x}, {y}) at ({s}, {t})");
            }
        }
    }

    #[test]
    fn sweep_equals_point_evaluation_on_every_builtin() {
        for style in builtin_styles() {
            let p = PreparedStyle::new(style).unwrap();
            for (w, h, role) in [
                (7.3, 9.1, FaceRole::Street),
                (21.0, 14.5, FaceRole::Street),
                (13.0, 30.0, FaceRole::Side),
            ] {
                let f = p
                    .facade(&FacadeSpec {
                        role,
                        ..FacadeSpec::new(w, h, 17)
                    })
                    .unwrap();
                check(f.stack(), w, h, 9.0);
            }
        }
    }

    #[test]
    fn sweep_handles_closures_scaled_cells_and_smooth_profiles() {
        let u = IntervalGroup::from_lengths([
            (1.0, "pier", Profile::Off),
            (
                2.0,
                "bay",
                Profile::Smooth {
                    from: 0.2,
                    to: 0.8,
                    soft_m: 0.3,
                },
            ),
            (1.0, "pier", Profile::Off),
            (2.0, "bay", Profile::Centered { size_m: 1.2 }),
        ])
        .unwrap();
        let v = IntervalGroup::from_lengths([
            (
                3.0,
                "floor",
                Profile::At {
                    offset_m: 1.0,
                    size_m: 1.5,
                },
            ),
            (3.0, "floor", Profile::Full),
        ])
        .unwrap();
        let wall = Layer::new(
            IntervalGroup::single(6.0, "w", Profile::Full).unwrap(),
            IntervalGroup::single(6.0, "w", Profile::Full).unwrap(),
            Eval::Always,
            Col::custom(|c| FacadeSample::rgb((c.s / 6.0) as f32, (c.t / 6.0) as f32, 0.0)),
        );
        let round = Layer::new(
            u.clone(),
            v.clone(),
            Eval::custom(|c| {
                let x = c.local[0] / c.size[0] - 0.5;
                let y = c.local[1] / c.size[1] - 0.5;
                x * x + y * y < 0.2
            }),
            Col::Gradient {
                bottom: FacadeSample::rgb(0.0, 0.0, 0.5),
                top: FacadeSample::rgb(0.0, 0.0, 1.0),
            },
        );
        let and = Layer::new(
            u,
            v,
            Eval::And,
            Col::Frame {
                inner: FacadeSample::rgb(1.0, 1.0, 1.0),
                edge: FacadeSample::rgb(0.2, 0.2, 0.2),
                width_m: 0.1,
            },
        );
        let door = Layer::new(
            IntervalGroup::from_lengths([
                (4.2, "x", Profile::Off),
                (1.0, "d", Profile::Full),
                (0.8, "x", Profile::Off),
            ])
            .unwrap(),
            IntervalGroup::from_lengths([(2.0, "d", Profile::Full), (4.0, "x", Profile::Off)])
                .unwrap(),
            Eval::And,
            Col::Solid(FacadeSample::rgb(0.0, 1.0, 0.0)),
        );
        let stack = LayerStack::new(
            vec![wall, and, round, door],
            vec![
                Influence::ScaleCells {
                    source: 3,
                    target: 1,
                    relation: Relation::Above { max_gap_m: 5.0 },
                    scale: [0.7, 1.3],
                },
                Influence::Border {
                    source: 1,
                    target: 0,
                    margin_m: 0.15,
                    col: Col::Solid(FacadeSample::rgb(1.0, 0.0, 1.0)),
                },
            ],
            None,
        )
        .unwrap();
        check(&stack, 6.0, 6.0, 23.0);
    }
}
