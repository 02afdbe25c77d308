//! Facade styles as data: the serialisable description of a layered grid that adapts to
//! any facade size ("style textures", Parish & Müller §4.3).
//!
//! A [`FacadeStyle`](crate::FacadeStyle) names the facade's primary grid (an [`AxisStyle`] for the columns and
//! one for the rows) and a [`StackStyle`]: layers (bottom first) over that grid or over
//! their own axes, each with a selection of rows and columns, an evaluation function and a
//! colour function, plus influences between layers. [`StackStyle::instantiate`] turns it
//! into a [`LayerStack`] for concrete lengths.

use std::collections::BTreeMap;

use rand::Rng;

use crate::axis::AxisStyle;
use crate::color::Col;
use crate::error::{FacadeError, Result};
use crate::image::{ImageSet, ImageStyle};
use crate::interval::IntervalGroup;
use crate::layer::{CellRole, Eval, Layer};
use crate::profile::Profile;
use crate::sample::FacadeSample;
use crate::stack::{Influence, LayerStack, Relation};

/// Deepest nesting of layers inside layers.
pub const MAX_NESTING: u32 = 4;

/// Which intervals of an axis a layer uses: those named in `names` (all when empty), then
/// a pick among them.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Select {
    /// Interval names to keep (empty: every interval). Default: empty.
    #[cfg_attr(feature = "serde", serde(default))]
    pub names: Vec<String>,
    /// Which of those. Default: all.
    #[cfg_attr(feature = "serde", serde(default))]
    pub pick: Pick,
}

/// A pick among the intervals a [`Select`] kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum Pick {
    /// All of them.
    #[default]
    All,
    /// The `index`-th (negative: from the end, −1 = last).
    Index {
        /// Position among the kept intervals.
        index: i64,
    },
    /// The middle one (the upper middle for an even count).
    Middle,
    /// Every `step`-th, starting at `offset`.
    Every {
        /// Step (≥ 1).
        step: u32,
        /// First position.
        offset: u32,
    },
}

impl Select {
    /// Every interval.
    pub fn all() -> Self {
        Select::default()
    }

    /// The intervals with one of these names.
    pub fn named(names: &[&str]) -> Self {
        Select {
            names: names.iter().map(|s| s.to_string()).collect(),
            pick: Pick::All,
        }
    }

    /// This selection with a pick.
    pub fn pick(mut self, pick: Pick) -> Self {
        self.pick = pick;
        self
    }

    /// The mask over `group` (`None` when everything is selected).
    pub fn mask(&self, group: &IntervalGroup) -> Option<Vec<bool>> {
        if self.names.is_empty() && self.pick == Pick::All {
            return None;
        }
        let kept: Vec<usize> = group
            .intervals()
            .iter()
            .enumerate()
            .filter(|(_, iv)| self.names.is_empty() || self.names.iter().any(|n| **n == *iv.name))
            .map(|(k, _)| k)
            .collect();
        let mut mask = vec![false; group.len()];
        let mut set = |k: Option<&usize>| {
            if let Some(m) = k.and_then(|&k| mask.get_mut(k)) {
                *m = true;
            }
        };
        match self.pick {
            Pick::All => kept.iter().for_each(|k| set(Some(k))),
            Pick::Index { index } => {
                let n = kept.len() as i64;
                let k = if index < 0 { n + index } else { index };
                if (0..n).contains(&k) {
                    set(kept.get(k as usize));
                }
            }
            Pick::Middle => set(kept.get(kept.len() / 2)),
            Pick::Every { step, offset } => {
                let step = step.max(1) as usize;
                kept.iter()
                    .enumerate()
                    .filter(|(p, _)| {
                        *p >= offset as usize && (*p - offset as usize).is_multiple_of(step)
                    })
                    .for_each(|(_, k)| set(Some(k)));
            }
        }
        Some(mask)
    }
}

/// The interval group a layer uses along one axis.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum AxisRef {
    /// The facade's primary grid (inside a nested stack: one interval over the whole box).
    #[default]
    Grid,
    /// One interval over the whole length with a [`Profile::Full`] profile.
    Whole,
    /// The layer's own axis style, fitted to the facade (or box) length.
    Own(AxisStyle),
}

/// The serialisable evaluation function of a layer (closures are available on
/// [`Layer`]s built in code).
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum EvalStyle {
    /// Every selected cell is active.
    Always,
    /// Logical AND of the two profiles.
    #[default]
    And,
    /// Logical OR of the two profiles.
    Or,
    /// A random image per cell.
    Image {
        /// The images.
        images: Vec<ImageStyle>,
        /// Their weights (empty: equal).
        #[cfg_attr(feature = "serde", serde(default))]
        weights: Vec<f32>,
    },
    /// A nested layer stack evaluated over each active box.
    Nested(Box<StackStyle>),
}

/// One layer of a style.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct LayerStyle {
    /// Name, referenced by influences.
    pub name: String,
    /// Role of its active cells. Default: wall.
    #[cfg_attr(feature = "serde", serde(default))]
    pub role: CellRole,
    /// Column axis. Default: the grid.
    #[cfg_attr(feature = "serde", serde(default))]
    pub u: AxisRef,
    /// Row axis. Default: the grid.
    #[cfg_attr(feature = "serde", serde(default))]
    pub v: AxisRef,
    /// Replaces the column profiles (e.g. a sill as wide as its window column). Default:
    /// keep the axis' profiles.
    #[cfg_attr(feature = "serde", serde(default))]
    pub u_profile: Option<Profile>,
    /// Replaces the row profiles. Default: keep.
    #[cfg_attr(feature = "serde", serde(default))]
    pub v_profile: Option<Profile>,
    /// Which columns. Default: all.
    #[cfg_attr(feature = "serde", serde(default))]
    pub cols: Select,
    /// Which rows. Default: all.
    #[cfg_attr(feature = "serde", serde(default))]
    pub rows: Select,
    /// Evaluation function. Default: AND.
    #[cfg_attr(feature = "serde", serde(default))]
    pub eval: EvalStyle,
    /// Colour function.
    pub col: Col,
    /// Offset from the wall plane, metres (negative: recessed). Default: 0.
    #[cfg_attr(feature = "serde", serde(default))]
    pub depth_m: f32,
    /// Only on street-facing facades (entrances). Default: false.
    #[cfg_attr(feature = "serde", serde(default))]
    pub street_only: bool,
}

impl LayerStyle {
    /// A layer on the primary grid with the given evaluation and colour.
    pub fn new(name: &str, role: CellRole, eval: EvalStyle, col: Col) -> Self {
        LayerStyle {
            name: name.into(),
            role,
            u: AxisRef::Grid,
            v: AxisRef::Grid,
            u_profile: None,
            v_profile: None,
            cols: Select::all(),
            rows: Select::all(),
            eval,
            col,
            depth_m: 0.0,
            street_only: false,
        }
    }

    /// Whether the role is an opening (removed from blank facades).
    pub fn is_opening(&self) -> bool {
        matches!(
            self.role,
            CellRole::Window
                | CellRole::Door
                | CellRole::Shopfront
                | CellRole::Glass
                | CellRole::Balcony
        )
    }
}

/// A serialisable influence between two layers, by name.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum InfluenceStyle {
    /// See [`Influence::ScaleCells`].
    ScaleCells {
        /// Influencing layer.
        source: String,
        /// Influenced layer.
        target: String,
        /// Which target cells.
        relation: Relation,
        /// Scale along `s` and `t`.
        scale: [f64; 2],
    },
    /// See [`Influence::Border`].
    Border {
        /// Influencing layer.
        source: String,
        /// Influenced layer.
        target: String,
        /// Border width, metres.
        margin_m: f64,
        /// Colour inside the border.
        col: Col,
    },
}

/// Layers (bottom first), influences and a background.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct StackStyle {
    /// The layers, bottom first.
    pub layers: Vec<LayerStyle>,
    /// Influences between them.
    #[cfg_attr(feature = "serde", serde(default))]
    pub influences: Vec<InfluenceStyle>,
    /// Surface where no layer is active (`None`: fall through to the enclosing layer).
    #[cfg_attr(feature = "serde", serde(default))]
    pub background: Option<FacadeSample>,
}

/// What the stack is being built for.
pub struct BuildContext<'a, R: Rng + ?Sized> {
    /// Primary columns (`None` inside nested stacks).
    pub grid_u: Option<&'a IntervalGroup>,
    /// Primary rows.
    pub grid_v: Option<&'a IntervalGroup>,
    /// Domain width, metres.
    pub width: f64,
    /// Domain height, metres.
    pub height: f64,
    /// Keep street-only layers.
    pub street: bool,
    /// Keep opening layers (false for blank facades).
    pub openings: bool,
    /// Source of the layer seeds.
    pub rng: &'a mut R,
    /// Nesting depth (0 = facade).
    pub depth: u32,
    /// Pre-built image sets by layer path (see [`StackStyle::build_images`]); missing ones
    /// are built on the fly.
    pub images: Option<&'a BTreeMap<String, ImageSet>>,
    /// Path of the enclosing layer (`""` at the facade level).
    pub path: String,
}

/// What instantiation had to leave out.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BuildReport {
    /// Layers skipped because their own axis did not fit the length (name, reason).
    pub skipped_layers: Vec<(String, String)>,
}

impl StackStyle {
    /// Checks names and every layer's data.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] or [`FacadeError::UnknownLayer`].
    pub fn validate(&self, depth: u32) -> Result<()> {
        if depth > MAX_NESTING {
            return Err(FacadeError::InvalidStyle {
                style: "nested stack".into(),
                reason: format!("layers nest deeper than {MAX_NESTING} levels"),
            });
        }
        if self.layers.is_empty() {
            return Err(FacadeError::InvalidStyle {
                style: "stack".into(),
                reason: "a stack needs at least one layer".into(),
            });
        }
        for (k, l) in self.layers.iter().enumerate() {
            if self.layers[..k].iter().any(|o| o.name == l.name) {
                return Err(FacadeError::InvalidStyle {
                    style: l.name.clone(),
                    reason: "layer names must be unique within a stack".into(),
                });
            }
            for (axis, a) in [("u", &l.u), ("v", &l.v)] {
                if let AxisRef::Own(s) = a {
                    s.validate(&format!("{}.{axis}", l.name))?;
                }
            }
            for p in [l.u_profile, l.v_profile].into_iter().flatten() {
                p.validate()?;
            }
            l.col.validate()?;
            match &l.eval {
                EvalStyle::Nested(inner) => inner.validate(depth + 1)?,
                EvalStyle::Image { images, weights } => {
                    let imgs = images
                        .iter()
                        .map(ImageStyle::build)
                        .collect::<Result<Vec<_>>>()?;
                    ImageSet::new(imgs, weights)?;
                }
                _ => {}
            }
        }
        for inf in &self.influences {
            let (InfluenceStyle::ScaleCells { source, target, .. }
            | InfluenceStyle::Border { source, target, .. }) = inf;
            for n in [source, target] {
                if !self.layers.iter().any(|l| &l.name == n) {
                    return Err(FacadeError::UnknownLayer { name: n.clone() });
                }
            }
        }
        Ok(())
    }

    /// Builds the layer stack for a domain. Layers whose own axis does not fit are left
    /// out (listed in the report) together with the influences naming them.
    ///
    /// # Errors
    /// Invalid data (see [`validate`](Self::validate)) and failures of the stack.
    pub fn instantiate<R: Rng + ?Sized>(
        &self,
        ctx: &mut BuildContext<'_, R>,
    ) -> Result<(LayerStack, BuildReport)> {
        let mut report = BuildReport::default();
        let mut layers = Vec::new();
        let mut names: Vec<&str> = Vec::new();
        for ls in &self.layers {
            // Every layer draws its seed, kept or not, so removing a layer for one facade
            // role does not reshuffle the others.
            let seed = ctx.rng.next_u64();
            if (ls.street_only && !ctx.street) || (!ctx.openings && ls.is_opening()) {
                continue;
            }
            match self.build_layer(ls, seed, ctx)? {
                Ok(layer) => {
                    layers.push(layer);
                    names.push(&ls.name);
                }
                Err(reason) => report.skipped_layers.push((ls.name.clone(), reason)),
            }
        }
        if layers.is_empty() {
            // Everything was skipped: keep the domain with an inactive layer.
            let u = IntervalGroup::single(ctx.width, "blank", Profile::Off)?;
            let v = IntervalGroup::single(ctx.height, "blank", Profile::Off)?;
            layers.push(
                Layer::new(u, v, Eval::And, Col::Solid(FacadeSample::default())).named("blank"),
            );
        }
        let index = |n: &str| names.iter().position(|m| *m == n);
        let mut influences = Vec::new();
        for inf in &self.influences {
            match inf {
                InfluenceStyle::ScaleCells {
                    source,
                    target,
                    relation,
                    scale,
                } => {
                    if let (Some(s), Some(t)) = (index(source), index(target)) {
                        influences.push(Influence::ScaleCells {
                            source: s,
                            target: t,
                            relation: *relation,
                            scale: *scale,
                        });
                    }
                }
                InfluenceStyle::Border {
                    source,
                    target,
                    margin_m,
                    col,
                } => {
                    if let (Some(s), Some(t)) = (index(source), index(target)) {
                        influences.push(Influence::Border {
                            source: s,
                            target: t,
                            margin_m: *margin_m,
                            col: col.clone(),
                        });
                    }
                }
            }
        }
        Ok((
            LayerStack::new(layers, influences, self.background)?,
            report,
        ))
    }

    /// Draws every image set of the stack (and of nested stacks) once, keyed by layer
    /// path, so that many facades of one style share them.
    ///
    /// # Errors
    /// Bad image parameters.
    pub fn build_images(&self, path: &str, out: &mut BTreeMap<String, ImageSet>) -> Result<()> {
        for ls in &self.layers {
            let p = layer_path(path, &ls.name);
            match &ls.eval {
                EvalStyle::Image { images, weights } => {
                    let imgs = images
                        .iter()
                        .map(ImageStyle::build)
                        .collect::<Result<Vec<_>>>()?;
                    out.insert(p, ImageSet::new(imgs, weights)?);
                }
                EvalStyle::Nested(inner) => inner.build_images(&p, out)?,
                _ => {}
            }
        }
        Ok(())
    }

    /// Builds one layer: outer `Err` for invalid data, inner `Err(reason)` for a layer that
    /// does not fit and is skipped.
    fn build_layer<R: Rng + ?Sized>(
        &self,
        ls: &LayerStyle,
        seed: u64,
        ctx: &mut BuildContext<'_, R>,
    ) -> Result<std::result::Result<Layer, String>> {
        let axis = |a: &AxisRef,
                    grid: Option<&IntervalGroup>,
                    len: f64|
         -> Result<std::result::Result<IntervalGroup, String>> {
            match (a, grid) {
                (AxisRef::Grid, Some(g)) => Ok(Ok(g.clone())),
                (AxisRef::Grid, None) | (AxisRef::Whole, _) => {
                    Ok(Ok(IntervalGroup::single(len, "whole", Profile::Full)?))
                }
                (AxisRef::Own(s), _) => match s.fit(len, None) {
                    Ok(g) => Ok(Ok(g)),
                    Err(e @ FacadeError::TooShort { .. }) => Ok(Err(e.to_string())),
                    Err(e) => Err(e),
                },
            }
        };
        let mut u = match axis(&ls.u, ctx.grid_u, ctx.width)? {
            Ok(g) => g,
            Err(r) => return Ok(Err(r)),
        };
        let mut v = match axis(&ls.v, ctx.grid_v, ctx.height)? {
            Ok(g) => g,
            Err(r) => return Ok(Err(r)),
        };
        if let Some(p) = ls.u_profile {
            u = u.with_profile(p);
        }
        if let Some(p) = ls.v_profile {
            v = v.with_profile(p);
        }
        let u_mask = ls.cols.mask(&u);
        let v_mask = ls.rows.mask(&v);
        let eval = match &ls.eval {
            EvalStyle::Always => Eval::Always,
            EvalStyle::And => Eval::And,
            EvalStyle::Or => Eval::Or,
            EvalStyle::Image { images, weights } => {
                match ctx
                    .images
                    .and_then(|m| m.get(&layer_path(&ctx.path, &ls.name)))
                {
                    Some(set) => Eval::Image(set.clone()),
                    None => {
                        let imgs = images
                            .iter()
                            .map(ImageStyle::build)
                            .collect::<Result<Vec<_>>>()?;
                        Eval::Image(ImageSet::new(imgs, weights)?)
                    }
                }
            }
            EvalStyle::Nested(inner) => {
                // The nested domain is the nominal box: the first selected cell's active
                // ranges (rigid windows make every box the same size).
                let first = |g: &IntervalGroup, m: &Option<Vec<bool>>| {
                    (0..g.len())
                        .filter(|&k| {
                            m.as_ref()
                                .is_none_or(|m| m.get(k).copied().unwrap_or(false))
                        })
                        .find_map(|k| g.active(k))
                        .map(|(a, b)| b - a)
                };
                let (Some(w), Some(h)) = (first(&u, &u_mask), first(&v, &v_mask)) else {
                    return Ok(Err(
                        "no selected cell has an active box for the nested stack".into(),
                    ));
                };
                let mut sub = BuildContext {
                    grid_u: None,
                    grid_v: None,
                    width: w,
                    height: h,
                    street: ctx.street,
                    openings: true,
                    rng: &mut *ctx.rng,
                    depth: ctx.depth + 1,
                    images: ctx.images,
                    path: layer_path(&ctx.path, &ls.name),
                };
                if sub.depth > MAX_NESTING {
                    return Err(FacadeError::InvalidStyle {
                        style: ls.name.clone(),
                        reason: format!("layers nest deeper than {MAX_NESTING} levels"),
                    });
                }
                let (stack, rep) = inner.instantiate(&mut sub)?;
                if !rep.skipped_layers.is_empty() {
                    return Ok(Err(format!(
                        "nested layers did not fit: {:?}",
                        rep.skipped_layers
                    )));
                }
                Eval::Stack(Box::new(stack))
            }
        };
        let layer = Layer::new(u, v, eval, ls.col.clone())
            .named(&ls.name)
            .with_role(ls.role)
            .with_depth(ls.depth_m)
            .with_seed(seed)
            .with_masks(u_mask, v_mask);
        layer.validate()?;
        Ok(Ok(layer))
    }
}

fn layer_path(parent: &str, name: &str) -> String {
    format!("{parent}/{name}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn group() -> IntervalGroup {
        IntervalGroup::from_lengths([
            (1.0, "margin", Profile::Off),
            (1.0, "bay", Profile::Full),
            (1.0, "bay", Profile::Full),
            (1.0, "bay", Profile::Full),
            (1.0, "bay", Profile::Full),
            (1.0, "margin", Profile::Off),
        ])
        .unwrap()
    }

    #[test]
    fn selections() {
        let g = group();
        assert_eq!(Select::all().mask(&g), None);
        assert_eq!(
            Select::named(&["bay"]).mask(&g).unwrap(),
            vec![false, true, true, true, true, false]
        );
        assert_eq!(
            Select::named(&["bay"]).pick(Pick::Middle).mask(&g).unwrap(),
            vec![false, false, false, true, false, false]
        );
        assert_eq!(
            Select::named(&["bay"])
                .pick(Pick::Index { index: -1 })
                .mask(&g)
                .unwrap(),
            vec![false, false, false, false, true, false]
        );
        assert_eq!(
            Select::all()
                .pick(Pick::Every { step: 2, offset: 1 })
                .mask(&g)
                .unwrap(),
            vec![false, true, false, true, false, true]
        );
        assert_eq!(
            Select::named(&["door"])
                .pick(Pick::Index { index: 3 })
                .mask(&g)
                .unwrap(),
            vec![false; 6]
        );
    }
}
