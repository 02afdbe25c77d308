//! Layer stacks and functions between layers.
//!
//! "Layers can be stacked which means that if a point (s, t) on layer l is evaluated as not
//! active the same point is evaluated on layer l − 1. [...] To establish the influence of
//! different layers on each other, functions between layers can be established"
//! (Parish & Müller §4.3, fig. 13 right: one layer scales the active cells of another;
//! fig. 14 right: differently sized and coloured bricks around windows and doors).

use polis_geom::{Aabb2, DVec2};

use crate::color::Col;
use crate::error::{FacadeError, Result};
use crate::interval::Hit;
use crate::layer::{Layer, Probe};
use crate::sample::FacadeSample;

/// How a target cell must lie relative to a source layer's active cells for a
/// [`Influence::ScaleCells`] to apply.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum Relation {
    /// The target's active box overlaps a source box (positive area).
    Overlap,
    /// The target box lies above a source box, overlapping it horizontally, at most
    /// `max_gap_m` higher (windows above a door).
    Above {
        /// Largest vertical gap, metres.
        max_gap_m: f64,
    },
    /// The target box lies below a source box, overlapping it horizontally.
    Below {
        /// Largest vertical gap, metres.
        max_gap_m: f64,
    },
    /// The boxes are within `distance_m` of each other (L∞ distance).
    Near {
        /// Largest distance, metres.
        distance_m: f64,
    },
}

impl Relation {
    fn query(&self, r: &Aabb2) -> Aabb2 {
        match *self {
            Relation::Overlap => *r,
            Relation::Above { max_gap_m } => Aabb2::new(
                DVec2::new(r.min.x, r.min.y - max_gap_m),
                DVec2::new(r.max.x, r.min.y),
            ),
            Relation::Below { max_gap_m } => Aabb2::new(
                DVec2::new(r.min.x, r.max.y),
                DVec2::new(r.max.x, r.max.y + max_gap_m),
            ),
            Relation::Near { distance_m } => r.expanded(distance_m),
        }
    }

    fn holds(&self, target: &Aabb2, source: &Aabb2) -> bool {
        const EPS: f64 = 1e-9;
        let x_overlap = target.min.x.max(source.min.x) < target.max.x.min(source.max.x) - EPS;
        match *self {
            Relation::Overlap => {
                let i = target.intersection(source);
                i.width() > EPS && i.height() > EPS
            }
            Relation::Above { max_gap_m } => {
                let gap = target.min.y - source.max.y;
                x_overlap && gap >= -EPS && gap <= max_gap_m + EPS
            }
            Relation::Below { max_gap_m } => {
                let gap = source.min.y - target.max.y;
                x_overlap && gap >= -EPS && gap <= max_gap_m + EPS
            }
            Relation::Near { distance_m } => target.expanded(distance_m + EPS).intersects(source),
        }
    }
}

/// A function between two layers of a stack (indices, bottom = 0).
#[derive(Debug, Clone, PartialEq)]
pub enum Influence {
    /// Scales the active cells of `target` that stand in `relation` to an active cell of
    /// `source`, about their box centre (`[0, 0]` removes them). Applied once, when the
    /// stack is built.
    ScaleCells {
        /// The influencing layer.
        source: usize,
        /// The influenced layer.
        target: usize,
        /// Which target cells.
        relation: Relation,
        /// Scale along `s` and `t`.
        scale: [f64; 2],
    },
    /// Points of `target` within `margin_m` of an active cell of `source` take colour `col`
    /// (a soldier course of bricks around windows and doors). Evaluated per point.
    Border {
        /// The influencing layer.
        source: usize,
        /// The influenced layer.
        target: usize,
        /// Width of the border, metres.
        margin_m: f64,
        /// The colour function used inside the border.
        col: Col,
    },
}

/// Layers evaluated top-down with fall-through, plus the influences between them.
#[derive(Debug, Clone)]
pub struct LayerStack {
    layers: Vec<Layer>,
    /// Per layer: the border influences targeting it, as (source, margin, col).
    borders: Vec<Vec<(usize, f64, Col)>>,
    background: Option<FacadeSample>,
}

/// The merged `s` spans of one border influence on the current row, and a cursor.
type BorderSpans = (Vec<(f64, f64)>, usize);

/// Per-layer state while sweeping one raster row.
#[derive(Debug, Clone, Default)]
pub(crate) struct RowState {
    hv: Vec<Option<Hit>>,
    cursor: Vec<usize>,
    /// Per layer, per border: the merged `s` spans (expanded by the margin) and a cursor.
    spans: Vec<Vec<BorderSpans>>,
    /// Per layer, per border: every active rectangle of the source layer, in the order
    /// [`Layer::any_rect_in`] visits them, for the stack at this address.
    rects: Vec<Vec<Vec<Aabb2>>>,
    rects_of: usize,
    /// Scratch for the unmerged spans.
    scratch: Vec<(f64, f64)>,
}

impl LayerStack {
    /// Builds a stack (bottom layer first), validates it and applies the cell-scaling
    /// influences in order.
    ///
    /// `background` is returned where no layer is active (`None`: the stack is itself
    /// inactive there, so an enclosing layer falls through).
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] for no layers, layers of different domains, bad masks
    /// or influence indices out of range or pointing from a layer to itself.
    pub fn new(
        mut layers: Vec<Layer>,
        influences: Vec<Influence>,
        background: Option<FacadeSample>,
    ) -> Result<Self> {
        let bad = |reason: String| FacadeError::InvalidStyle {
            style: "layer stack".into(),
            reason,
        };
        let Some(first) = layers.first() else {
            return Err(bad("a stack needs at least one layer".into()));
        };
        let (w, h) = (first.width(), first.height());
        for l in &layers {
            l.validate()?;
            if (l.width() - w).abs() > 1e-6 * w.max(1.0)
                || (l.height() - h).abs() > 1e-6 * h.max(1.0)
            {
                return Err(bad(format!(
                    "layer `{}` covers {}×{} m but the stack covers {w}×{h} m",
                    l.name,
                    l.width(),
                    l.height()
                )));
            }
        }
        if let Some(bg) = background
            && !bg.is_valid()
        {
            return Err(bad("background surface is out of range".into()));
        }
        let n = layers.len();
        let mut borders = vec![Vec::new(); n];
        for inf in influences {
            match inf {
                Influence::ScaleCells {
                    source,
                    target,
                    relation,
                    scale,
                } => {
                    if source >= n || target >= n || source == target {
                        return Err(bad(format!(
                            "influence {source} → {target} is not between two layers"
                        )));
                    }
                    if !(scale.iter().all(|k| k.is_finite() && *k >= 0.0)) {
                        return Err(bad("scale factors must be finite and ≥ 0".into()));
                    }
                    apply_scale(&mut layers, source, target, relation, scale);
                }
                Influence::Border {
                    source,
                    target,
                    margin_m,
                    col,
                } => {
                    if source >= n || target >= n || source == target {
                        return Err(bad(format!(
                            "influence {source} → {target} is not between two layers"
                        )));
                    }
                    if !(margin_m.is_finite() && margin_m >= 0.0) {
                        return Err(bad("border margin_m must be finite and ≥ 0".into()));
                    }
                    col.validate()?;
                    if let Some(b) = borders.get_mut(target) {
                        b.push((source, margin_m, col));
                    }
                }
            }
        }
        Ok(LayerStack {
            layers,
            borders,
            background,
        })
    }

    /// The layers, bottom first.
    pub fn layers(&self) -> &[Layer] {
        &self.layers
    }

    /// The background surface.
    pub fn background(&self) -> Option<FacadeSample> {
        self.background
    }

    /// Domain width, metres.
    pub fn width(&self) -> f64 {
        self.layers.first().map_or(0.0, Layer::width)
    }

    /// Domain height, metres.
    pub fn height(&self) -> f64 {
        self.layers.first().map_or(0.0, Layer::height)
    }

    /// The topmost active layer at `(s, t)` and its probe.
    pub fn probe_top(&self, s: f64, t: f64) -> Option<(usize, Probe)> {
        self.layers
            .iter()
            .enumerate()
            .rev()
            .find_map(|(k, l)| l.probe(s, t).map(|p| (k, p)))
    }

    #[inline]
    fn col_for(&self, k: usize, s: f64, t: f64) -> Option<&Col> {
        let borders = self.borders.get(k)?;
        for (source, margin, col) in borders {
            let src = self.layers.get(*source)?;
            let q = Aabb2::new(
                DVec2::new(s - margin, t - margin),
                DVec2::new(s + margin, t + margin),
            );
            if src.any_rect_in(&q, |_| true) {
                return Some(col);
            }
        }
        None
    }

    /// The sample at `(s, t)`: the topmost active layer's colour, falling through inactive
    /// layers; the background (or `None`) where no layer is active.
    pub fn sample_opt(&self, s: f64, t: f64) -> Option<FacadeSample> {
        match self.probe_top(s, t) {
            Some((k, p)) => {
                let layer = self.layers.get(k)?;
                let col = self.col_for(k, s, t).unwrap_or(&layer.col);
                Some(layer.shade(&p, col))
            }
            None => self.background,
        }
    }

    /// [`sample_opt`](Self::sample_opt), with the default surface where nothing is active.
    pub fn sample(&self, s: f64, t: f64) -> FacadeSample {
        self.sample_opt(s, t).unwrap_or_default()
    }

    /// Prepares a row sweep at height `t`: locates `t` once per layer and collects the
    /// border spans.
    pub(crate) fn begin_row(&self, t: f64, state: &mut RowState) {
        state.hv.clear();
        state.hv.extend(self.layers.iter().map(|l| l.v.locate(t)));
        state.cursor.clear();
        state.cursor.resize(self.layers.len(), 0);
        state.spans.resize_with(self.layers.len(), Vec::new);
        // The source rectangles are collected once per stack and row sweep.
        let me = self as *const LayerStack as usize;
        if state.rects_of != me || state.rects.len() != self.borders.len() {
            state.rects_of = me;
            state.rects = self
                .borders
                .iter()
                .map(|borders| {
                    borders
                        .iter()
                        .map(|(source, _, _)| {
                            let mut v = Vec::new();
                            if let Some(src) = self.layers.get(*source) {
                                for j in 0..src.v.len() {
                                    for i in 0..src.u.len() {
                                        src.cell_rects(i, j, |r| v.push(r));
                                    }
                                }
                            }
                            v
                        })
                        .collect()
                })
                .collect();
        }
        for (k, borders) in self.borders.iter().enumerate() {
            let (Some(slot), Some(rects)) = (state.spans.get_mut(k), state.rects.get(k)) else {
                continue;
            };
            slot.resize_with(borders.len(), || (Vec::new(), 0));
            for (((_, margin, _), (spans, cur)), rects) in
                borders.iter().zip(slot.iter_mut()).zip(rects)
            {
                spans.clear();
                *cur = 0;
                // The source's rectangles meeting the band |t' − t| ≤ margin (what
                // `Layer::any_rect_in` finds for that band), widened by the margin.
                let q = Aabb2::new(DVec2::new(-1e9, t - margin), DVec2::new(1e9, t + margin));
                let scratch = &mut state.scratch;
                scratch.clear();
                scratch.extend(
                    rects
                        .iter()
                        .filter(|r| r.intersects(&q))
                        .map(|r| (r.min.x - margin, r.max.x + margin)),
                );
                scratch.sort_by(|a, b| a.0.total_cmp(&b.0));
                // Merge overlapping spans so a forward cursor suffices.
                for &(a, b) in scratch.iter() {
                    match spans.last_mut() {
                        Some(last) if a <= last.1 => last.1 = last.1.max(b),
                        _ => spans.push((a, b)),
                    }
                }
            }
        }
    }

    /// The border colour (if any) that replaces layer `k`'s colour at `s` on the row
    /// prepared by [`begin_row`](Self::begin_row): O(log spans).
    #[inline]
    pub(crate) fn border_col_in_row(&self, k: usize, s: f64, state: &RowState) -> Option<&Col> {
        let (borders, slot) = (self.borders.get(k)?, state.spans.get(k)?);
        for ((_, _, col), (spans, _)) in borders.iter().zip(slot) {
            let p = spans.partition_point(|sp| sp.1 < s);
            if spans.get(p).is_some_and(|sp| sp.0 <= s) {
                return Some(col);
            }
        }
        None
    }

    /// As [`border_col_in_row`](Self::border_col_in_row) for non-decreasing `s` along the
    /// row: amortised O(1) with the row state's cursors.
    #[cfg(test)]
    pub(crate) fn border_col_advance(
        &self,
        k: usize,
        s: f64,
        state: &mut RowState,
    ) -> Option<&Col> {
        let (borders, slot) = (self.borders.get(k)?, state.spans.get_mut(k)?);
        for ((_, _, col), (spans, cur)) in borders.iter().zip(slot.iter_mut()) {
            while spans.get(*cur).is_some_and(|sp| sp.1 < s) {
                *cur += 1;
            }
            if spans.get(*cur).is_some_and(|sp| sp.0 <= s) {
                return Some(col);
            }
        }
        None
    }

    /// For non-decreasing `s` along the row: the border colour at `s` (if any) and, per
    /// border, where the answer may change next — `(s', inclusive)`: at the first texel
    /// `≥ s'` (`inclusive`) or `> s'`. Calls `f` with each such boundary.
    #[inline]
    pub(crate) fn border_run(
        &self,
        k: usize,
        s: f64,
        state: &mut RowState,
        mut f: impl FnMut(f64, bool),
    ) -> Option<&Col> {
        let (borders, slot) = (self.borders.get(k)?, state.spans.get_mut(k)?);
        let mut found = None;
        for ((_, _, col), (spans, cur)) in borders.iter().zip(slot.iter_mut()) {
            while spans.get(*cur).is_some_and(|sp| sp.1 < s) {
                *cur += 1;
            }
            match spans.get(*cur) {
                Some(sp) if sp.0 <= s => {
                    // Inside: the status changes after the span's end.
                    f(sp.1, false);
                    if found.is_none() {
                        found = Some(col);
                    }
                }
                // Before the next span: the status changes at its start.
                Some(sp) => f(sp.0, true),
                None => {}
            }
        }
        found
    }

    /// Whether layer `k` is the target of any border influence.
    #[inline]
    pub(crate) fn has_borders(&self, k: usize) -> bool {
        self.borders.get(k).is_some_and(|b| !b.is_empty())
    }

    /// The sample at `(s, t)` during a row sweep begun with [`begin_row`](Self::begin_row)
    /// at this `t`; `s` must not decrease between calls (amortised O(1) per layer).
    #[cfg(test)]
    pub(crate) fn sample_in_row(&self, s: f64, t: f64, state: &mut RowState) -> FacadeSample {
        for k in (0..self.layers.len()).rev() {
            let (Some(layer), Some(Some(hv)), Some(cursor)) =
                (self.layers.get(k), state.hv.get(k), state.cursor.get_mut(k))
            else {
                continue;
            };
            let Some(hu) = layer.u.locate_from(s, cursor) else {
                continue;
            };
            let Some(p) = layer.probe_hits(s, t, &hu, hv) else {
                continue;
            };
            let col = self.border_col_advance(k, s, state).unwrap_or(&layer.col);
            return layer.shade(&p, col);
        }
        self.background.unwrap_or_default()
    }
}

fn apply_scale(
    layers: &mut [Layer],
    source: usize,
    target: usize,
    relation: Relation,
    scale: [f64; 2],
) {
    let (Some(src), Some(tgt)) = (layers.get(source), layers.get(target)) else {
        return;
    };
    let (nu, nv) = (tgt.u.len(), tgt.v.len());
    let mut factors = tgt
        .cell_scale
        .clone()
        .unwrap_or_else(|| vec![[1.0, 1.0]; nu * nv]);
    let mut changed = false;
    for j in 0..nv {
        for i in 0..nu {
            let mut hit = false;
            tgt.cell_rects(i, j, |r| {
                if hit {
                    return;
                }
                let q = relation.query(&r);
                hit = src.any_rect_in(&q.expanded(1e-9), |sr| relation.holds(&r, sr));
            });
            if hit && let Some(f) = factors.get_mut(j * nu + i) {
                f[0] *= scale[0];
                f[1] *= scale[1];
                changed = true;
            }
        }
    }
    if changed && let Some(t) = layers.get_mut(target) {
        t.cell_scale = Some(factors);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interval::IntervalGroup;
    use crate::layer::Eval;
    use crate::profile::Profile;

    fn solid(r: f32, g: f32, b: f32) -> Col {
        Col::Solid(FacadeSample::rgb(r, g, b))
    }

    /// 3 bays × 2 floors of 2 × 3 m; windows 1 × 1.5 m centred at 1 m sill height.
    fn windows() -> Layer {
        let u = IntervalGroup::from_lengths([
            (2.0, "bay", Profile::Centered { size_m: 1.0 }),
            (2.0, "bay", Profile::Centered { size_m: 1.0 }),
            (2.0, "bay", Profile::Centered { size_m: 1.0 }),
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
            (
                3.0,
                "floor",
                Profile::At {
                    offset_m: 1.0,
                    size_m: 1.5,
                },
            ),
        ])
        .unwrap();
        Layer::new(u, v, Eval::And, solid(0.0, 0.0, 1.0)).named("windows")
    }

    fn wall() -> Layer {
        let u = IntervalGroup::single(6.0, "wall", Profile::Full).unwrap();
        let v = IntervalGroup::single(6.0, "wall", Profile::Full).unwrap();
        Layer::new(u, v, Eval::Always, solid(1.0, 0.0, 0.0)).named("wall")
    }

    /// A door in the middle bay, ground floor, 0–2.2 m.
    fn door() -> Layer {
        let u = IntervalGroup::from_lengths([
            (2.5, "x", Profile::Off),
            (1.0, "door", Profile::Full),
            (2.5, "x", Profile::Off),
        ])
        .unwrap();
        let v =
            IntervalGroup::from_lengths([(2.2, "door", Profile::Full), (3.8, "x", Profile::Off)])
                .unwrap();
        Layer::new(u, v, Eval::And, solid(0.0, 1.0, 0.0)).named("door")
    }

    #[test]
    fn stack_falls_through_to_lower_layers() {
        let st = LayerStack::new(vec![wall(), windows()], vec![], None).unwrap();
        assert_eq!(
            st.sample(1.0, 1.5).albedo,
            [0.0, 0.0, 1.0, 1.0],
            "window on top"
        );
        assert_eq!(
            st.sample(0.2, 1.5).albedo,
            [1.0, 0.0, 0.0, 1.0],
            "falls through to wall"
        );
        // Without the wall layer, nothing is active there: background or None.
        let bare = LayerStack::new(
            vec![windows()],
            vec![],
            Some(FacadeSample::rgb(0.5, 0.5, 0.5)),
        )
        .unwrap();
        assert_eq!(bare.sample(0.2, 1.5).albedo[0], 0.5);
        let none = LayerStack::new(vec![windows()], vec![], None).unwrap();
        assert_eq!(none.sample_opt(0.2, 1.5), None);
        assert_eq!(none.probe_top(1.0, 1.5).map(|p| p.0), Some(0));
    }

    #[test]
    fn door_removes_overlapping_window_and_shrinks_the_one_above() {
        let inf = vec![
            Influence::ScaleCells {
                source: 2,
                target: 1,
                relation: Relation::Overlap,
                scale: [0.0, 0.0],
            },
            Influence::ScaleCells {
                source: 2,
                target: 1,
                relation: Relation::Above { max_gap_m: 3.0 },
                scale: [0.5, 0.5],
            },
        ];
        let st = LayerStack::new(vec![wall(), windows(), door()], inf, None).unwrap();
        let w = &st.layers()[1];
        // Middle ground-floor window (overlapping the door 0..2.2 vs 1..2.5) is gone.
        let mut r = vec![];
        w.cell_rects(1, 0, |x| r.push(x));
        assert!(r.is_empty());
        assert_eq!(
            st.sample(3.0, 2.4).albedo,
            [1.0, 0.0, 0.0, 1.0],
            "wall where the window was"
        );
        // The window above the door is half size about its centre (3.0, 4.75).
        r.clear();
        w.cell_rects(1, 1, |x| r.push(x));
        assert_eq!(r.len(), 1);
        assert!((r[0].width() - 0.5).abs() < 1e-9 && (r[0].height() - 0.75).abs() < 1e-9);
        assert_eq!(st.sample(3.0, 4.75).albedo[2], 1.0);
        assert_eq!(
            st.sample(2.6, 4.75).albedo[0],
            1.0,
            "outside the shrunken window"
        );
        // Side windows are untouched.
        r.clear();
        w.cell_rects(0, 1, |x| r.push(x));
        assert!((r[0].width() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn border_recolours_around_source_cells() {
        let inf = vec![Influence::Border {
            source: 1,
            target: 0,
            margin_m: 0.2,
            col: solid(1.0, 1.0, 0.0),
        }];
        let st = LayerStack::new(vec![wall(), windows()], inf, None).unwrap();
        // Window of bay 0 floor 0: [0.5, 1.5] × [1.0, 2.5].
        assert_eq!(st.sample(0.4, 1.5).albedo, [1.0, 1.0, 0.0, 1.0]);
        assert_eq!(st.sample(0.2, 1.5).albedo, [1.0, 0.0, 0.0, 1.0]);
        assert_eq!(st.sample(1.0, 2.6).albedo, [1.0, 1.0, 0.0, 1.0]);
        // The row sweep agrees with point evaluation.
        let mut state = RowState::default();
        for t in [0.5, 0.9, 1.5, 2.6, 2.8, 4.0] {
            st.begin_row(t, &mut state);
            for k in 0..600 {
                let s = k as f64 * 0.01;
                assert_eq!(
                    st.sample_in_row(s, t, &mut state),
                    st.sample(s, t),
                    "s={s} t={t}"
                );
            }
        }
    }

    #[test]
    fn bad_stacks_are_rejected() {
        assert!(LayerStack::new(vec![], vec![], None).is_err());
        let small = Layer::new(
            IntervalGroup::single(1.0, "a", Profile::Full).unwrap(),
            IntervalGroup::single(1.0, "a", Profile::Full).unwrap(),
            Eval::Always,
            solid(0.0, 0.0, 0.0),
        );
        assert!(LayerStack::new(vec![wall(), small], vec![], None).is_err());
        let inf = vec![Influence::ScaleCells {
            source: 0,
            target: 5,
            relation: Relation::Overlap,
            scale: [1.0, 1.0],
        }];
        assert!(LayerStack::new(vec![wall()], inf, None).is_err());
    }
}
