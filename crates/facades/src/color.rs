//! Colour functions: `col(s, t)` of a layer, called for active points (Parish & Müller
//! §4.3: "returns the color (or bump or reflectivity) value of the point").

use std::fmt;
use std::sync::Arc;

use crate::error::{FacadeError, Result};
use crate::sample::{FacadeSample, hash2, unit};
use crate::sweep::RowSink;

/// Where a point lies, handed to colour and evaluation functions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointCtx {
    /// Facade (or nested-domain) coordinates of the point, metres: `s` along the facade,
    /// `t` up from its bottom.
    pub s: f64,
    /// See `s`.
    pub t: f64,
    /// Column index (interval of the layer's `u` group).
    pub i: usize,
    /// Row index (interval of the layer's `v` group).
    pub j: usize,
    /// Position inside the cell's box (its profiles' active ranges; after any inter-layer
    /// scaling), metres from the box's lower-left corner.
    pub local: [f64; 2],
    /// Size of that box, metres.
    pub size: [f64; 2],
    /// Profile value of the `u` interval at the point.
    pub pu: f32,
    /// Profile value of the `v` interval at the point.
    pub pv: f32,
    /// A per-cell random value derived from the facade seed, the layer and `(i, j)`.
    pub cell_seed: u64,
}

/// A user colour function (not serialisable).
pub type ColFnBox = Arc<dyn Fn(&PointCtx) -> FacadeSample + Send + Sync>;

/// A user closure wrapper with `Debug` and pointer equality.
#[derive(Clone)]
pub struct ColFn(pub ColFnBox);

impl fmt::Debug for ColFn {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("ColFn(<closure>)")
    }
}

impl PartialEq for ColFn {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A brick or ashlar pattern in facade metres (continuous across cells) or in cell-box
/// metres.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Bricks {
    /// The brick (or stone block) surface.
    pub brick: FacadeSample,
    /// The joint surface (its height is the joint depth, e.g. −0.01).
    pub mortar: FacadeSample,
    /// Brick pitch (width, height) including one joint, metres.
    pub size_m: [f64; 2],
    /// Joint width, metres.
    pub joint_m: f64,
    /// Horizontal offset of alternate courses as a fraction of the pitch (0.5 = running
    /// bond, 0 = stack bond).
    pub bond: f64,
    /// Per-brick brightness variation (0 = none, 0.2 = ±20 %).
    #[cfg_attr(feature = "serde", serde(default))]
    pub variation: f32,
    /// Lay the pattern in the cell box instead of the facade. Default: false.
    #[cfg_attr(feature = "serde", serde(default))]
    pub in_cell: bool,
    /// Seed salt for the per-brick variation. Default: 0.
    #[cfg_attr(feature = "serde", serde(default))]
    pub salt: u64,
}

impl Bricks {
    #[inline]
    fn eval(&self, x: f64, y: f64) -> FacadeSample {
        let [w, h] = self.size_m;
        let course = (y / h).floor();
        let xo = x + course * self.bond * w;
        let col = (xo / w).floor();
        let lx = xo - col * w;
        let ly = y - course * h;
        if lx < self.joint_m || ly < self.joint_m {
            return self.mortar;
        }
        if self.variation == 0.0 {
            return self.brick;
        }
        let r = unit(hash2(self.salt, col as i64, course as i64));
        self.brick.shade(1.0 + self.variation * (2.0 * r - 1.0))
    }

    /// The course of row `y` when the row is not inside a bed joint (then every texel of
    /// the row depends on its course and `x` alone), else `None`.
    pub(crate) fn course(&self, y: f64) -> Option<f64> {
        let h = self.size_m[1];
        let course = (y / h).floor();
        (y - course * h >= self.joint_m).then_some(course)
    }

    /// `eval(x, y)` for the texels `first..first + xs.len()` of a row, plus `depth` on
    /// the height, as runs into `sink`: the course is found once per row and each brick's
    /// shade once per brick (same results as `eval`). `x` is `xs[k] − x_origin` (0 for
    /// facade-aligned bricks, the box origin for bricks laid in the cell).
    pub(crate) fn eval_row<S: RowSink>(
        &self,
        xs: &[f64],
        first: usize,
        x_origin: Option<f64>,
        y: f64,
        depth: f32,
        sink: &mut S,
    ) {
        let [w, h] = self.size_m;
        let course = (y / h).floor();
        let ly = y - course * h;
        let mut mortar = self.mortar;
        mortar.height += depth;
        let end = first + xs.len();
        if ly < self.joint_m {
            sink.fill(first, end, mortar);
            return;
        }
        let off = course * self.bond * w;
        let shade = |col: f64| {
            let mut b = if self.variation == 0.0 {
                self.brick
            } else {
                let r = unit(hash2(self.salt, col as i64, course as i64));
                self.brick.shade(1.0 + self.variation * (2.0 * r - 1.0))
            };
            b.height += depth;
            b
        };
        // The brick column of texel k and whether it is mortar: the same arithmetic as
        // `eval`.
        let xo_at = |k: usize| {
            let s = xs.get(k).copied().unwrap_or(f64::NAN);
            let x = match x_origin {
                Some(o) => s - o,
                None => s,
            };
            x + off
        };
        let state = |k: usize| {
            let xo = xo_at(k);
            let col = floor_fast(xo / w);
            (col, xo - col * w < self.joint_m)
        };
        let n = xs.len();
        let spacing = match (xs.first(), xs.get(1)) {
            (Some(&a), Some(&b)) => b - a,
            _ => 0.0,
        };
        // Walk run by run: within a column the joint is a prefix, so "same column and
        // same kind" holds on a prefix of the texels that follow; guess its end from the
        // spacing and correct the guess against the exact per-texel test.
        let mut k = 0;
        while k < n {
            let (col, mortar_run) = state(k);
            let boundary = if mortar_run {
                col * w + self.joint_m
            } else {
                (col + 1.0) * w
            };
            let g = ((boundary - xo_at(k)) / spacing).ceil();
            let step = if g.is_finite() && g >= 1.0 {
                g.min(n as f64) as usize
            } else {
                1
            };
            let same = |q: usize| {
                let (c, m) = state(q);
                c == col && m == mortar_run
            };
            let mut e = (k + step).clamp(k + 1, n);
            while e > k + 1 && !same(e - 1) {
                e -= 1;
            }
            while e < n && same(e) {
                e += 1;
            }
            let m = if mortar_run { mortar } else { shade(col) };
            sink.fill(first + k, first + e, m);
            k = e;
        }
    }
}

/// `x.floor()` without a library call on targets without SSE4.1 (truncation, corrected
/// for negative non-integers); the result may differ from `floor` only in the sign of a
/// zero, which no caller can observe (it is multiplied and compared).
#[inline]
fn floor_fast(x: f64) -> f64 {
    if x.abs() < 4.0e15 {
        let t = x as i64 as f64;
        if t > x { t - 1.0 } else { t }
    } else {
        x.floor()
    }
}

/// A corrugated sheet at position `x` across its ridges.
#[inline]
fn corrugation(base: &FacadeSample, period_m: f64, depth_m: f32, x: f64) -> FacadeSample {
    let phase = (x / period_m).fract() as f32;
    // A triangle-rounded wave: cheaper than sin and smooth enough for normals.
    let tri = 4.0 * (phase - 0.5).abs() - 1.0;
    let wave = tri * (1.5 - 0.5 * tri * tri);
    let mut m = *base;
    m.height += 0.5 * depth_m * wave;
    m.shade(0.92 + 0.08 * wave)
}

/// A vertical corrugation at `s` with `depth` added to the height.
#[inline]
fn corrugated_at(
    base: &FacadeSample,
    period_m: f64,
    depth_m: f32,
    s: f64,
    depth: f32,
) -> FacadeSample {
    let mut m = corrugation(base, period_m, depth_m, s);
    m.height += depth;
    m
}

/// The colour function of a layer.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum Col {
    /// One surface everywhere.
    Solid(FacadeSample),
    /// A brick or stone-block pattern.
    Bricks(Bricks),
    /// A frame of width `width_m` around the cell box in `edge`, `inner` inside.
    Frame {
        /// Inside the frame.
        inner: FacadeSample,
        /// The frame.
        edge: FacadeSample,
        /// Frame width, metres.
        width_m: f64,
    },
    /// A vertical blend over the cell box, bottom to top (glass reflecting the sky).
    Gradient {
        /// At the bottom of the box.
        bottom: FacadeSample,
        /// At the top of the box.
        top: FacadeSample,
    },
    /// Corrugated sheet: a sinusoidal height profile of the given period.
    Corrugated {
        /// The sheet surface (its height is the mean height).
        base: FacadeSample,
        /// Wave period, metres.
        period_m: f64,
        /// Peak-to-peak depth, metres.
        depth_m: f32,
        /// Ridges run vertically (true) or horizontally.
        vertical: bool,
    },
    /// The sample produced by the evaluation function (an image map, a nested layer or
    /// stack), or `fallback` when the evaluation gives none (AND, OR, …).
    Inherit {
        /// Used when the evaluation gives no sample.
        fallback: FacadeSample,
    },
    /// A user closure (not serialisable).
    #[cfg_attr(feature = "serde", serde(skip))]
    Custom(ColFn),
}

impl Col {
    /// Wraps a closure as a colour function.
    pub fn custom(f: impl Fn(&PointCtx) -> FacadeSample + Send + Sync + 'static) -> Self {
        Col::Custom(ColFn(Arc::new(f)))
    }

    /// The colour at a point; `inner` is the evaluation function's sample, if any.
    #[inline]
    pub fn eval(&self, ctx: &PointCtx, inner: Option<&FacadeSample>) -> FacadeSample {
        match self {
            Col::Solid(m) => *m,
            Col::Bricks(b) => {
                if b.in_cell {
                    b.eval(ctx.local[0], ctx.local[1])
                } else {
                    b.eval(ctx.s, ctx.t)
                }
            }
            Col::Frame {
                inner,
                edge,
                width_m,
            } => {
                let [x, y] = ctx.local;
                let [w, h] = ctx.size;
                if x < *width_m || y < *width_m || w - x <= *width_m || h - y <= *width_m {
                    *edge
                } else {
                    *inner
                }
            }
            Col::Gradient { bottom, top } => {
                let k = if ctx.size[1] > 0.0 {
                    (ctx.local[1] / ctx.size[1]).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                bottom.lerp(top, k as f32)
            }
            Col::Corrugated {
                base,
                period_m,
                depth_m,
                vertical,
            } => corrugation(
                base,
                *period_m,
                *depth_m,
                if *vertical { ctx.s } else { ctx.t },
            ),
            Col::Inherit { fallback } => inner.copied().unwrap_or(*fallback),
            Col::Custom(f) => (f.0)(ctx),
        }
    }

    /// Evaluates the texels `first..first + xs.len()` of a row (texel centres `xs`, at
    /// height `t`) that share one cell and context except for `s` (the cell box starts at
    /// `box_x0`), adding `depth` to the heights, as runs into `sink`; `ctx_at(s)` builds the
    /// full context when needed. Equal to calling [`eval`](Self::eval) per point, faster
    /// for colours that are constant along runs (solid, frames, bricks).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn eval_row<S: RowSink>(
        &self,
        xs: &[f64],
        first: usize,
        t: f64,
        box_x0: f64,
        depth: f32,
        ctx_at: impl Fn(f64) -> PointCtx,
        sink: &mut S,
    ) {
        let end = first + xs.len();
        match self {
            Col::Solid(m) => {
                let mut m = *m;
                m.height += depth;
                sink.fill(first, end, m);
            }
            Col::Bricks(b) if !b.in_cell => b.eval_row(xs, first, None, t, depth, sink),
            Col::Bricks(b) => {
                if let Some(&s) = xs.first() {
                    // `eval` lays in-cell bricks at ctx.local = (s − box x0, t − box y0).
                    let y = ctx_at(s).local[1];
                    b.eval_row(xs, first, Some(box_x0), y, depth, sink);
                }
            }
            // Functions of t and the box alone are constant along the run.
            Col::Gradient { .. }
            | Col::Inherit { .. }
            | Col::Corrugated {
                vertical: false, ..
            } => {
                if let Some(&s) = xs.first() {
                    let mut m = self.eval(&ctx_at(s), None);
                    m.height += depth;
                    sink.fill(first, end, m);
                }
            }
            Col::Frame {
                inner,
                edge,
                width_m,
            } => {
                let Some(&s0) = xs.first() else { return };
                let c = ctx_at(s0);
                let [w, h] = c.size;
                let y = c.local[1];
                let (mut inner, mut edge) = (*inner, *edge);
                inner.height += depth;
                edge.height += depth;
                let band = y < *width_m || h - y <= *width_m;
                if band {
                    sink.fill(first, end, edge);
                    return;
                }
                let mut run_start = first;
                let mut run_edge = false;
                for (k, &s) in xs.iter().enumerate() {
                    // The same arithmetic as `eval`: local x = s − box origin.
                    let x = s - box_x0;
                    let is_edge = x < *width_m || w - x <= *width_m;
                    if k == 0 {
                        run_edge = is_edge;
                    } else if is_edge != run_edge {
                        sink.fill(run_start, first + k, if run_edge { edge } else { inner });
                        run_start = first + k;
                        run_edge = is_edge;
                    }
                }
                sink.fill(run_start, end, if run_edge { edge } else { inner });
            }
            Col::Corrugated {
                base,
                period_m,
                depth_m,
                vertical: true,
            } => {
                for (k, &s) in xs.iter().enumerate() {
                    sink.put(
                        first + k,
                        corrugated_at(base, *period_m, *depth_m, s, depth),
                    );
                }
            }
            _ => {
                for (k, &s) in xs.iter().enumerate() {
                    let mut m = self.eval(&ctx_at(s), None);
                    m.height += depth;
                    sink.put(first + k, m);
                }
            }
        }
    }

    /// For a vertically corrugated colour: the sample at every `s` of `xs` with `depth`
    /// added (a function of `s` alone, so a raster computes it once per column).
    pub(crate) fn vertical_strip(&self, xs: &[f64], depth: f32) -> Option<Vec<FacadeSample>> {
        match self {
            Col::Corrugated {
                base,
                period_m,
                depth_m,
                vertical: true,
            } => Some(
                xs.iter()
                    .map(|&s| corrugated_at(base, *period_m, *depth_m, s, depth))
                    .collect(),
            ),
            _ => None,
        }
    }

    /// Checks sizes and surfaces.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] describing the bad field.
    pub fn validate(&self) -> Result<()> {
        let bad = |reason: &str| {
            Err(FacadeError::InvalidStyle {
                style: "col".into(),
                reason: reason.into(),
            })
        };
        let samples: Vec<&FacadeSample> = match self {
            Col::Solid(m) | Col::Inherit { fallback: m } => vec![m],
            Col::Bricks(b) => {
                let [w, h] = b.size_m;
                if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0) {
                    return bad("brick size_m must be positive and finite");
                }
                if !(b.joint_m.is_finite()
                    && b.joint_m >= 0.0
                    && b.bond.is_finite()
                    && b.variation.is_finite())
                {
                    return bad("brick joint_m must be ≥ 0; bond and variation finite");
                }
                vec![&b.brick, &b.mortar]
            }
            Col::Frame {
                inner,
                edge,
                width_m,
            } => {
                if !(width_m.is_finite() && *width_m >= 0.0) {
                    return bad("frame width_m must be ≥ 0");
                }
                vec![inner, edge]
            }
            Col::Gradient { bottom, top } => vec![bottom, top],
            Col::Corrugated {
                base,
                period_m,
                depth_m,
                ..
            } => {
                if !(period_m.is_finite() && *period_m > 0.0 && depth_m.is_finite()) {
                    return bad("corrugation period_m must be > 0 and depth_m finite");
                }
                vec![base]
            }
            Col::Custom(_) => vec![],
        };
        if samples.iter().all(|m| m.is_valid()) {
            Ok(())
        } else {
            bad("surface channels must be finite, colour/roughness/metallic in [0, 1]")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx(s: f64, t: f64) -> PointCtx {
        PointCtx {
            s,
            t,
            i: 0,
            j: 0,
            local: [s, t],
            size: [1.0, 2.0],
            pu: 1.0,
            pv: 1.0,
            cell_seed: 0,
        }
    }

    #[test]
    fn bricks_have_joints_and_bond() {
        let b = Bricks {
            brick: FacadeSample::rgb(0.6, 0.2, 0.1),
            mortar: FacadeSample::rgb(0.8, 0.8, 0.8).with_height(-0.01),
            size_m: [0.25, 0.075],
            joint_m: 0.01,
            bond: 0.5,
            variation: 0.0,
            in_cell: false,
            salt: 0,
        };
        let col = Col::Bricks(b);
        assert_eq!(col.eval(&ctx(0.1, 0.03), None).albedo[0], 0.6);
        assert_eq!(col.eval(&ctx(0.255, 0.03), None).height, -0.01);
        // Next course is offset by half a brick: x = 0.255 + 0.125 is inside a brick.
        assert_eq!(col.eval(&ctx(0.255, 0.1), None).albedo[0], 0.6);
        assert_eq!(col.eval(&ctx(0.13, 0.1), None).height, -0.01);
    }

    #[test]
    fn frame_and_inherit() {
        let f = Col::Frame {
            inner: FacadeSample::rgb(0.0, 0.0, 0.0),
            edge: FacadeSample::rgb(1.0, 1.0, 1.0),
            width_m: 0.1,
        };
        assert_eq!(f.eval(&ctx(0.05, 1.0), None).albedo[0], 1.0);
        assert_eq!(f.eval(&ctx(0.5, 1.0), None).albedo[0], 0.0);
        assert_eq!(f.eval(&ctx(0.5, 1.95), None).albedo[0], 1.0);
        let inh = Col::Inherit {
            fallback: FacadeSample::rgb(0.3, 0.3, 0.3),
        };
        let img = FacadeSample::rgb(0.9, 0.1, 0.1);
        assert_eq!(inh.eval(&ctx(0.0, 0.0), Some(&img)), img);
        assert_eq!(inh.eval(&ctx(0.0, 0.0), None).albedo[0], 0.3);
    }

    #[test]
    fn validation() {
        assert!(
            Col::Solid(FacadeSample::rgb(2.0, 0.0, 0.0))
                .validate()
                .is_err()
        );
        assert!(
            Col::Corrugated {
                base: FacadeSample::default(),
                period_m: 0.0,
                depth_m: 0.02,
                vertical: true
            }
            .validate()
            .is_err()
        );
    }
}
