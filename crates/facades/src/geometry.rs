//! Geometry mode: the active cells of every layer as rectangles with roles.
//!
//! For close-up levels of detail a mesher recesses windows and doors and extrudes ledges
//! and cornices as real geometry; it needs the active cells, not texels. Cells of nested
//! stacks (glazing bars, panes) are mapped into the facade and reported with their nesting
//! level.

use std::fmt;
use std::ops::Deref;
use std::sync::Arc;

use polis_geom::{Aabb2, DVec2};
#[cfg(feature = "serde")]
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::facade::Facade;
use crate::layer::{CellRole, Eval, Layer};
use crate::stack::LayerStack;

/// One active cell rectangle.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FacadeCell {
    /// The rectangle in facade metres (`s` right, `t` up).
    pub rect: Aabb2,
    /// What it is.
    pub role: CellRole,
    /// Index of its layer in its stack (bottom = 0); higher layers cover lower ones.
    pub layer: usize,
    /// Name of its layer (shared by every cell of the layer: cloning it is a reference
    /// count, not an allocation).
    pub layer_name: LayerName,
    /// Offset from the wall plane, metres (negative: recessed), summed over nesting.
    pub depth_m: f32,
    /// The image variant shown (e.g. 0 closed, 1 half open, 2 open), for image layers.
    pub variant: Option<u32>,
    /// Column index in its layer.
    pub col: usize,
    /// Row index in its layer.
    pub row: usize,
    /// 0 for facade layers, 1 for cells of a nested stack inside a level-0 cell, …
    pub level: u32,
}

/// The name of a layer as carried by every [`FacadeCell`]: a shared, immutable string.
///
/// It dereferences to `str` and compares equal to `str`, `&str` and `String`, so code
/// written against the former `String` field (`cell.layer_name == "windows"`,
/// `cell.layer_name.starts_with(..)`, `format!("{}", cell.layer_name)`) keeps working;
/// it serialises as a plain string.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct LayerName(Arc<str>);

impl LayerName {
    /// The name as a string slice.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl Deref for LayerName {
    type Target = str;
    fn deref(&self) -> &str {
        &self.0
    }
}

impl AsRef<str> for LayerName {
    fn as_ref(&self) -> &str {
        &self.0
    }
}

impl fmt::Display for LayerName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl From<&str> for LayerName {
    fn from(s: &str) -> Self {
        LayerName(Arc::from(s))
    }
}

impl From<String> for LayerName {
    fn from(s: String) -> Self {
        LayerName(Arc::from(s))
    }
}

impl From<LayerName> for String {
    fn from(n: LayerName) -> Self {
        n.0.to_string()
    }
}

impl PartialEq<str> for LayerName {
    fn eq(&self, other: &str) -> bool {
        &*self.0 == other
    }
}

impl PartialEq<&str> for LayerName {
    fn eq(&self, other: &&str) -> bool {
        &*self.0 == *other
    }
}

impl PartialEq<String> for LayerName {
    fn eq(&self, other: &String) -> bool {
        *self.0 == **other
    }
}

#[cfg(feature = "serde")]
impl Serialize for LayerName {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.0)
    }
}

#[cfg(feature = "serde")]
impl<'de> Deserialize<'de> for LayerName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        String::deserialize(d).map(LayerName::from)
    }
}

/// An affine map from a nested domain into the facade: `p ↦ offset + p · scale`.
#[derive(Debug, Clone, Copy)]
struct Map {
    offset: DVec2,
    scale: DVec2,
}

impl Map {
    fn rect(&self, r: &Aabb2) -> Aabb2 {
        Aabb2::new(
            self.offset + r.min * self.scale,
            self.offset + r.max * self.scale,
        )
    }
}

fn collect_stack(stack: &LayerStack, map: Map, level: u32, depth: f32, out: &mut Vec<FacadeCell>) {
    for (k, layer) in stack.layers().iter().enumerate() {
        collect_layer(layer, k, map, level, depth, out);
    }
}

fn collect_layer(
    layer: &Layer,
    index: usize,
    map: Map,
    level: u32,
    depth: f32,
    out: &mut Vec<FacadeCell>,
) {
    let depth_m = depth + layer.depth_m;
    // One shared name per layer and call: every cell holds a reference to it.
    let name = LayerName::from(layer.name.as_str());
    let picked = |m: &Option<Vec<bool>>, k: usize| {
        m.as_ref()
            .is_none_or(|m| m.get(k).copied().unwrap_or(false))
    };
    for j in 0..layer.v.len() {
        // Unselected rows and columns have no cells: skip them without a look.
        if !picked(&layer.v_mask, j) {
            continue;
        }
        for i in 0..layer.u.len() {
            if !picked(&layer.u_mask, i) {
                continue;
            }
            layer.cell_rects(i, j, |r| {
                out.push(FacadeCell {
                    rect: map.rect(&r),
                    role: layer.role,
                    layer: index,
                    layer_name: name.clone(),
                    depth_m,
                    variant: layer.variant(i, j),
                    col: i,
                    row: j,
                    level,
                });
                let inner = match &layer.eval {
                    Eval::Nested(l) => Some((l.width(), l.height(), None, Some(l.as_ref()))),
                    Eval::Stack(s) => Some((s.width(), s.height(), Some(s.as_ref()), None)),
                    _ => None,
                };
                if let Some((w, h, stack, single)) = inner
                    && w > 0.0
                    && h > 0.0
                {
                    let sub = Map {
                        offset: map.offset + r.min * map.scale,
                        scale: map.scale * DVec2::new(r.width() / w, r.height() / h),
                    };
                    if let Some(s) = stack {
                        collect_stack(s, sub, level + 1, depth_m, out);
                    }
                    if let Some(l) = single {
                        collect_layer(l, 0, sub, level + 1, depth_m, out);
                    }
                }
            });
        }
    }
}

impl Facade {
    /// Every active cell of every layer (bottom layer first, then row by row), with nested
    /// cells after their parent. Deterministic order.
    pub fn cells(&self) -> Vec<FacadeCell> {
        let mut out = Vec::new();
        self.cells_into(&mut out);
        out
    }

    /// [`cells`](Self::cells) into a reused buffer (cleared first).
    pub fn cells_into(&self, out: &mut Vec<FacadeCell>) {
        out.clear();
        let id = Map {
            offset: DVec2::ZERO,
            scale: DVec2::ONE,
        };
        collect_stack(self.stack(), id, 0, 0.0, out);
    }

    /// The cells with one of the given roles (e.g. windows and doors for recessing).
    pub fn cells_with_roles(&self, roles: &[CellRole]) -> Vec<FacadeCell> {
        let mut v = self.cells();
        v.retain(|c| roles.contains(&c.role));
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;
    use crate::facade::{FacadeSpec, PreparedStyle};

    #[test]
    fn window_cells_are_inside_and_whole() {
        let p = PreparedStyle::new(builtin::brick_house()).unwrap();
        let f = p.facade(&FacadeSpec::new(11.3, 9.1, 2)).unwrap();
        let windows = f.cells_with_roles(&[CellRole::Window]);
        assert!(windows.len() >= 6);
        let doors = f.cells_with_roles(&[CellRole::Door]);
        assert_eq!(doors.len(), 1);
        for w in &windows {
            assert!(w.rect.min.x >= 0.0 && w.rect.max.x <= 11.3);
            assert!(w.rect.min.y >= 0.0 && w.rect.max.y <= 9.1);
            // Windows keep their nominal width; the one above the door is shrunk in
            // height only.
            assert!((w.rect.width() - 1.1).abs() < 1e-9, "{:?}", w.rect);
            assert!(w.variant.is_some());
            assert!(
                w.rect.intersection(&doors[0].rect).area() <= 0.0
                    || w.rect.intersection(&doors[0].rect).is_empty()
            );
        }
    }

    #[test]
    fn nested_cells_are_mapped_into_their_parent() {
        let p = PreparedStyle::new(builtin::classic_stone()).unwrap();
        let f = p.facade(&FacadeSpec::new(14.0, 15.0, 9)).unwrap();
        let cells = f.cells();
        let windows: Vec<_> = cells
            .iter()
            .filter(|c| c.role == CellRole::Window && c.level == 0)
            .collect();
        let panes: Vec<_> = cells
            .iter()
            .filter(|c| c.role == CellRole::Glass && c.level == 1)
            .collect();
        assert!(!windows.is_empty());
        assert!(
            panes.len() >= windows.len() * 4,
            "{} panes for {} windows",
            panes.len(),
            windows.len()
        );
        for p in &panes {
            assert!(
                windows.iter().any(|w| {
                    let i = w.rect.intersection(&p.rect);
                    (i.area() - p.rect.area()).abs() < 1e-9
                }),
                "pane {:?} outside every window",
                p.rect
            );
            assert!(p.depth_m < -0.15);
        }
    }
}
