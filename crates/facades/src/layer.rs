//! Layers: two interval groups, an evaluation function and a colour function.
//!
//! "A layer is defined by two interval groups, an evaluation function *eval* between the
//! interval groups and a color evaluation function *col*. For each point (s, t) where the
//! function eval(s, t) is evaluated to 1 the point is considered as an *active* point in
//! the layer. [...] If this set is partitioned, the partitions are called *active grid
//! cells*" (Parish & Müller §4.3). Here the partition is the grid of the two interval
//! groups: cell `(i, j)` is the product of interval `i` of `u` and interval `j` of `v`.

use std::fmt;
use std::sync::Arc;

use polis_geom::{Aabb2, DVec2};

use crate::color::{Col, PointCtx};
use crate::error::{FacadeError, Result};
use crate::image::ImageSet;
use crate::interval::{Hit, IntervalGroup};
use crate::sample::{FacadeSample, hash2};
use crate::stack::LayerStack;

/// What an active cell is, for geometry mode and for consumers' materials.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum CellRole {
    /// Plain wall (base layers).
    #[default]
    Wall,
    /// A window opening.
    Window,
    /// A door or gate.
    Door,
    /// A sill, string course or other ledge.
    Ledge,
    /// A cornice or parapet band.
    Cornice,
    /// A plinth or base course.
    Plinth,
    /// A pier, pilaster, quoin or mullion.
    Pier,
    /// A shop window.
    Shopfront,
    /// A balcony slab.
    Balcony,
    /// A frame or glazing bar inside an opening.
    Frame,
    /// Glass inside an opening.
    Glass,
    /// A cladding or spandrel panel.
    Panel,
    /// Anything else decorative.
    Ornament,
}

/// A user evaluation closure (not serialisable): returns whether the point is active.
pub type EvalFnBox = Arc<dyn Fn(&PointCtx) -> bool + Send + Sync>;

/// Wrapper for [`EvalFnBox`] with `Debug`.
#[derive(Clone)]
pub struct EvalFn(pub EvalFnBox);

impl fmt::Debug for EvalFn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("EvalFn(<closure>)")
    }
}

/// The evaluation function of a layer.
///
/// *Box* below means the cell's active box: the product of the active ranges of the two
/// intervals' profiles (e.g. the window opening inside a bay × storey cell).
#[derive(Debug, Clone)]
pub enum Eval {
    /// Every point of every (selected) cell is active.
    Always,
    /// `min(pu, pv) ≥ ½`: active where both profiles are (logical AND).
    And,
    /// `max(pu, pv) ≥ ½`: active where either profile is (logical OR: crossing bands).
    Or,
    /// A closure decides; it sees the [`PointCtx`] (box = active ranges, or the whole
    /// interval where a profile is nowhere active).
    Custom(EvalFn),
    /// A random image map per cell: an image of the set is chosen per cell and stretched
    /// over its box; texels with alpha ≥ ½ are active and give the sample.
    Image(ImageSet),
    /// A nested layer evaluated over the box (its domain is scaled to the box).
    Nested(Box<Layer>),
    /// A nested layer stack evaluated over the box.
    Stack(Box<LayerStack>),
}

impl Eval {
    /// Wraps a closure as an evaluation function.
    pub fn custom(f: impl Fn(&PointCtx) -> bool + Send + Sync + 'static) -> Self {
        Eval::Custom(EvalFn(Arc::new(f)))
    }

    pub(crate) fn uses_box(&self) -> bool {
        matches!(
            self,
            Eval::And | Eval::Image(_) | Eval::Nested(_) | Eval::Stack(_) | Eval::Custom(_)
        )
    }
}

/// A probed active point: its context, the evaluation's own sample (image texel, nested
/// result) and the image variant chosen for the cell.
#[derive(Debug, Clone, Copy)]
pub struct Probe {
    /// The point's context.
    pub ctx: PointCtx,
    /// The evaluation's sample, for [`Col::Inherit`].
    pub inner: Option<FacadeSample>,
}

/// One layer of a layered grid.
#[derive(Debug, Clone)]
pub struct Layer {
    /// Name, used by influences and reports.
    pub name: String,
    /// What its active cells are.
    pub role: CellRole,
    /// Columns (along `s`).
    pub u: IntervalGroup,
    /// Rows (along `t`, upwards).
    pub v: IntervalGroup,
    /// The evaluation function.
    pub eval: Eval,
    /// The colour function.
    pub col: Col,
    /// Offset of the active area from the wall plane, metres (negative: recessed). Added to
    /// every sample's height and reported with geometry cells.
    pub depth_m: f32,
    /// Which columns take part (`None`: all). One flag per interval of `u`.
    pub u_mask: Option<Vec<bool>>,
    /// Which rows take part (`None`: all). One flag per interval of `v`.
    pub v_mask: Option<Vec<bool>>,
    /// Seed of the per-cell randomness.
    pub seed: u64,
    /// Per-cell scale set by inter-layer influences (row-major, `j · nu + i`).
    pub(crate) cell_scale: Option<Vec<[f64; 2]>>,
}

impl Layer {
    /// A layer over two interval groups with an evaluation and a colour function.
    pub fn new(u: IntervalGroup, v: IntervalGroup, eval: Eval, col: Col) -> Self {
        Layer {
            name: String::new(),
            role: CellRole::Wall,
            u,
            v,
            eval,
            col,
            depth_m: 0.0,
            u_mask: None,
            v_mask: None,
            seed: 0,
            cell_scale: None,
        }
    }

    /// Sets the name.
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }

    /// Sets the role.
    pub fn with_role(mut self, role: CellRole) -> Self {
        self.role = role;
        self
    }

    /// Sets the depth (metres).
    pub fn with_depth(mut self, depth_m: f32) -> Self {
        self.depth_m = depth_m;
        self
    }

    /// Sets the seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Restricts the layer to some columns and rows.
    pub fn with_masks(mut self, u_mask: Option<Vec<bool>>, v_mask: Option<Vec<bool>>) -> Self {
        self.u_mask = u_mask;
        self.v_mask = v_mask;
        self
    }

    /// Checks masks against the groups, the colour function and nested layers.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] naming the layer.
    pub fn validate(&self) -> Result<()> {
        let bad = |reason: String| FacadeError::InvalidStyle {
            style: format!("layer `{}`", self.name),
            reason,
        };
        if let Some(m) = &self.u_mask
            && m.len() != self.u.len()
        {
            return Err(bad(format!(
                "u_mask has {} flags for {} columns",
                m.len(),
                self.u.len()
            )));
        }
        if let Some(m) = &self.v_mask
            && m.len() != self.v.len()
        {
            return Err(bad(format!(
                "v_mask has {} flags for {} rows",
                m.len(),
                self.v.len()
            )));
        }
        if !self.depth_m.is_finite() {
            return Err(bad("depth_m must be finite".into()));
        }
        self.col.validate()?;
        match &self.eval {
            Eval::Nested(l) => l.validate(),
            Eval::Stack(s) => s.layers().iter().try_for_each(Layer::validate),
            _ => Ok(()),
        }
    }

    /// Width of the layer's domain (`u` length), metres.
    pub fn width(&self) -> f64 {
        self.u.length()
    }

    /// Height of the layer's domain (`v` length), metres.
    pub fn height(&self) -> f64 {
        self.v.length()
    }

    #[inline]
    pub(crate) fn selected(&self, i: usize, j: usize) -> bool {
        let ok = |m: &Option<Vec<bool>>, k: usize| {
            m.as_ref()
                .is_none_or(|m| m.get(k).copied().unwrap_or(false))
        };
        ok(&self.u_mask, i) && ok(&self.v_mask, j)
    }

    #[inline]
    pub(crate) fn scale_of(&self, i: usize, j: usize) -> [f64; 2] {
        match &self.cell_scale {
            Some(sc) => sc.get(j * self.u.len() + i).copied().unwrap_or([1.0, 1.0]),
            None => [1.0, 1.0],
        }
    }

    /// The unscaled box of cell `(i, j)` as `[x0, x1, y0, y1]`, or `None` if the evaluation
    /// needs a box and a profile is nowhere active.
    #[inline]
    pub(crate) fn unscaled_box(&self, hu: &Hit, hv: &Hit) -> Option<[f64; 4]> {
        let cell = [hu.start, hu.end, hv.start, hv.end];
        if !self.eval.uses_box() {
            return Some(cell);
        }
        let (ru, rv) = (self.u.active(hu.index), self.v.active(hv.index));
        match (&self.eval, ru, rv) {
            (_, Some((a, b)), Some((c, d))) => Some([a, b, c, d]),
            (Eval::Custom(_), ru, rv) => {
                let (a, b) = ru.unwrap_or((hu.start, hu.end));
                let (c, d) = rv.unwrap_or((hv.start, hv.end));
                Some([a, b, c, d])
            }
            _ => None,
        }
    }

    /// Evaluates the layer at `(s, t)` given both interval hits: `None` if inactive.
    #[inline]
    pub(crate) fn probe_hits(&self, s: f64, t: f64, hu: &Hit, hv: &Hit) -> Option<Probe> {
        let (i, j) = (hu.index, hv.index);
        if !self.selected(i, j) {
            return None;
        }
        let mut bx = self.unscaled_box(hu, hv)?;
        let (mut x, mut y) = (s, t);
        let [su, sv] = self.scale_of(i, j);
        if su != 1.0 || sv != 1.0 {
            if su <= 0.0 || sv <= 0.0 {
                return None;
            }
            // Inverse-map the point into the unscaled cell around the box centre.
            let cx = 0.5 * (bx[0] + bx[1]);
            let cy = 0.5 * (bx[2] + bx[3]);
            x = cx + (s - cx) / su;
            y = cy + (t - cy) / sv;
            if !(x >= hu.start && x <= hu.end && y >= hv.start && y <= hv.end) {
                return None;
            }
            if !self.eval.uses_box() {
                bx = [hu.start, hu.end, hv.start, hv.end];
            }
        }
        let pu = self.u.value(i, x);
        let pv = self.v.value(j, y);
        let mut ctx = PointCtx {
            s,
            t,
            i,
            j,
            local: [x - bx[0], y - bx[2]],
            size: [bx[1] - bx[0], bx[3] - bx[2]],
            pu,
            pv,
            cell_seed: 0,
        };
        let in_box = || x >= bx[0] && x < bx[1] && y >= bx[2] && y < bx[3];
        let mut inner = None;
        let active = match &self.eval {
            Eval::Always => true,
            Eval::And => pu.min(pv) >= 0.5,
            Eval::Or => pu.max(pv) >= 0.5,
            Eval::Custom(f) => {
                ctx.cell_seed = hash2(self.seed, i as i64, j as i64);
                (f.0)(&ctx)
            }
            Eval::Image(set) => {
                if !in_box() {
                    return None;
                }
                ctx.cell_seed = hash2(self.seed, i as i64, j as i64);
                let img = set.get(set.choose(ctx.cell_seed))?;
                let texel = img.sample(ctx.local[0] / ctx.size[0], ctx.local[1] / ctx.size[1]);
                inner = Some(texel);
                texel.albedo[3] >= 0.5
            }
            Eval::Nested(layer) => {
                if !in_box() {
                    return None;
                }
                let ns = ctx.local[0] / ctx.size[0] * layer.width();
                let nt = ctx.local[1] / ctx.size[1] * layer.height();
                inner = layer.sample(ns, nt);
                inner.is_some()
            }
            Eval::Stack(stack) => {
                if !in_box() {
                    return None;
                }
                let ns = ctx.local[0] / ctx.size[0] * stack.width();
                let nt = ctx.local[1] / ctx.size[1] * stack.height();
                inner = stack.sample_opt(ns, nt);
                inner.is_some()
            }
        };
        if !active {
            return None;
        }
        if ctx.cell_seed == 0 && matches!(self.col, Col::Custom(_)) {
            ctx.cell_seed = hash2(self.seed, i as i64, j as i64);
        }
        Some(Probe { ctx, inner })
    }

    /// Evaluates the layer at `(s, t)`: `None` where it is inactive. O(log n): one binary
    /// search per interval group (plus the nested layer's, if any).
    #[inline]
    pub fn probe(&self, s: f64, t: f64) -> Option<Probe> {
        let hu = self.u.locate(s)?;
        let hv = self.v.locate(t)?;
        self.probe_hits(s, t, &hu, &hv)
    }

    /// The colour of an active probe, with the layer's depth added to the height.
    #[inline]
    pub fn shade(&self, probe: &Probe, col: &Col) -> FacadeSample {
        let mut m = col.eval(&probe.ctx, probe.inner.as_ref());
        m.height += self.depth_m;
        m
    }

    /// The sample at `(s, t)`, or `None` where the layer is inactive.
    #[inline]
    pub fn sample(&self, s: f64, t: f64) -> Option<FacadeSample> {
        self.probe(s, t).map(|p| self.shade(&p, &self.col))
    }

    /// Whether point `(s, t)` is active.
    pub fn is_active(&self, s: f64, t: f64) -> bool {
        self.probe(s, t).is_some()
    }

    /// The active rectangles of cell `(i, j)` (facade metres, after inter-layer scaling),
    /// passed to `f`: one for AND/image/nested/custom cells (their box), up to two for OR
    /// cells (the crossing bands), the cell for `Always`. Custom evaluations are tested at
    /// the box centre. Nothing for unselected or inactive cells.
    pub fn cell_rects(&self, i: usize, j: usize, mut f: impl FnMut(Aabb2)) {
        let (Some(iu), Some(iv)) = (self.u.get(i), self.v.get(j)) else {
            return;
        };
        if !self.selected(i, j) {
            return;
        }
        let hu = Hit {
            index: i,
            start: iu.start,
            end: iu.end,
        };
        let hv = Hit {
            index: j,
            start: iv.start,
            end: iv.end,
        };
        let cell = Aabb2::new(DVec2::new(iu.start, iv.start), DVec2::new(iu.end, iv.end));
        let Some(bx) = self.unscaled_box(&hu, &hv) else {
            return;
        };
        let b = Aabb2::new(DVec2::new(bx[0], bx[2]), DVec2::new(bx[1], bx[3]));
        let [su, sv] = self.scale_of(i, j);
        if su <= 0.0 || sv <= 0.0 {
            return;
        }
        let c = b.center();
        let scale = |r: Aabb2| {
            let k = DVec2::new(su, sv);
            let r = Aabb2::new(c + (r.min - c) * k, c + (r.max - c) * k).intersection(&cell);
            (r.width() > 0.0 && r.height() > 0.0).then_some(r)
        };
        let mut emit = |r: Aabb2| {
            if let Some(r) = scale(r) {
                f(r);
            }
        };
        match &self.eval {
            Eval::Always => emit(cell),
            Eval::Or => {
                if let Some((a, b2)) = self.u.active(i) {
                    emit(Aabb2::new(DVec2::new(a, iv.start), DVec2::new(b2, iv.end)));
                }
                if let Some((a, b2)) = self.v.active(j) {
                    emit(Aabb2::new(DVec2::new(iu.start, a), DVec2::new(iu.end, b2)));
                }
            }
            Eval::Custom(_) => {
                let p = scale(b).map(|r| r.center());
                if p.is_some_and(|p| self.probe_hits(p.x, p.y, &hu, &hv).is_some()) {
                    emit(b);
                }
            }
            _ => emit(b),
        }
    }

    /// Calls `f` for every active rectangle of the cells overlapping `region` (facade
    /// metres) until it returns `true`; returns whether it did. O(log n + k) for k cells.
    pub fn any_rect_in(&self, region: &Aabb2, mut f: impl FnMut(&Aabb2) -> bool) -> bool {
        let ru = self.u.overlapping(region.min.x, region.max.x);
        let rv = self.v.overlapping(region.min.y, region.max.y);
        for j in rv {
            for i in ru.clone() {
                let mut hit = false;
                self.cell_rects(i, j, |r| {
                    if !hit && r.intersects(region) && f(&r) {
                        hit = true;
                    }
                });
                if hit {
                    return true;
                }
            }
        }
        false
    }

    /// The image variant an image-evaluated cell shows, if any.
    pub fn variant(&self, i: usize, j: usize) -> Option<u32> {
        match &self.eval {
            Eval::Image(set) => Some(set.choose(hash2(self.seed, i as i64, j as i64)) as u32),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::Profile;

    fn grid() -> (IntervalGroup, IntervalGroup) {
        let u = IntervalGroup::from_lengths([
            (1.0, "pier", Profile::Off),
            (
                2.0,
                "bay",
                Profile::Pulse {
                    from: 0.25,
                    to: 0.75,
                },
            ),
            (1.0, "pier", Profile::Off),
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
            (1.0, "cornice", Profile::Full),
        ])
        .unwrap();
        (u, v)
    }

    fn red() -> Col {
        Col::Solid(FacadeSample::rgb(1.0, 0.0, 0.0))
    }

    #[test]
    fn and_is_intersection_or_is_union() {
        let (u, v) = grid();
        let and = Layer::new(u.clone(), v.clone(), Eval::And, red());
        let or = Layer::new(u, v, Eval::Or, red());
        // Inside the window box: both.
        assert!(and.is_active(2.0, 2.0) && or.is_active(2.0, 2.0));
        // Bay column but below the window: only OR.
        assert!(!and.is_active(2.0, 0.5) && or.is_active(2.0, 0.5));
        // Pier column, cornice row: only OR.
        assert!(!and.is_active(0.5, 3.5) && or.is_active(0.5, 3.5));
        // Pier column, floor row, below the window band: neither.
        assert!(!and.is_active(0.5, 0.5) && !or.is_active(0.5, 0.5));
        // Pier column in the window band: the horizontal OR band only.
        assert!(!and.is_active(0.5, 2.0) && or.is_active(0.5, 2.0));
        // Window bay and cornice row: both (cornice profile is Full).
        assert!(and.is_active(2.0, 3.5));
        // Outside the domain: inactive.
        assert!(!or.is_active(-1.0, 1.0) && !or.is_active(1.0, 4.5));
        let mut rects = vec![];
        and.cell_rects(1, 0, |r| rects.push(r));
        assert_eq!(
            rects,
            vec![Aabb2::new(DVec2::new(1.5, 1.0), DVec2::new(2.5, 2.5))]
        );
        rects.clear();
        or.cell_rects(1, 0, |r| rects.push(r));
        assert_eq!(rects.len(), 2);
    }

    #[test]
    fn masks_select_cells() {
        let (u, v) = grid();
        let l = Layer::new(u, v, Eval::Always, red()).with_masks(None, Some(vec![false, true]));
        assert!(!l.is_active(0.5, 1.0));
        assert!(l.is_active(0.5, 3.5));
        assert!(l.validate().is_ok());
        let bad = l.clone().with_masks(Some(vec![true]), None);
        assert!(bad.validate().is_err());
    }

    #[test]
    fn custom_eval_sees_cell_context() {
        let (u, v) = grid();
        // A round window: active inside the ellipse inscribed in the box.
        let l = Layer::new(
            u,
            v,
            Eval::custom(|c| {
                let x = c.local[0] / c.size[0] - 0.5;
                let y = c.local[1] / c.size[1] - 0.5;
                c.pu >= 0.5 && c.pv >= 0.5 && x * x + y * y <= 0.25
            }),
            red(),
        );
        assert!(l.is_active(2.0, 1.75));
        assert!(
            !l.is_active(1.55, 1.05),
            "box corner is outside the ellipse"
        );
        let mut n = 0;
        l.cell_rects(1, 0, |_| n += 1);
        assert_eq!(n, 1);
    }

    #[test]
    fn nested_layer_maps_into_box() {
        let (u, v) = grid();
        // Nested: a 1 × 1.5 domain with a vertical glazing bar in the middle third.
        let nu = IntervalGroup::from_lengths([
            (0.45, "pane", Profile::Off),
            (0.1, "bar", Profile::Full),
            (0.45, "pane", Profile::Off),
        ])
        .unwrap();
        let nv = IntervalGroup::single(1.5, "all", Profile::Full).unwrap();
        let bar = Layer::new(
            nu,
            nv,
            Eval::And,
            Col::Solid(FacadeSample::rgb(0.0, 0.0, 1.0)),
        );
        let l = Layer::new(
            u,
            v,
            Eval::Nested(Box::new(bar)),
            Col::Inherit {
                fallback: FacadeSample::default(),
            },
        );
        // Box is x ∈ [1.5, 2.5): bar at [1.95, 2.05).
        assert_eq!(l.sample(2.0, 2.0).unwrap().albedo[2], 1.0);
        assert!(l.sample(1.7, 2.0).is_none());
        assert!(l.sample(0.5, 2.0).is_none());
    }
}
