//! What changed between two states of an edited city, by stable id: the
//! [`ChangeEvents`] a host applies to its meshes.

use std::collections::BTreeSet;
use std::sync::Arc;

use polis_geom::DVec2;
use polis_geom::par;

use super::edit::{ChangeEvents, Delta, Regenerated};
use super::memo::Redone;
use super::splice::OldScene;
use crate::City;
use crate::CityConfig;
use crate::citygen::{District, LotOverride};

/// Pairs sorted by key, of equal keys the last kept (as collecting them into a
/// `BTreeMap` would): the maps the deltas compare, as sorted vectors (one sort instead of
/// a tree insertion per item).
fn by_key<K: Ord, V>(mut v: Vec<(K, V)>) -> Vec<(K, V)> {
    // Stable: of equal keys the last stays last.
    v.sort_by(|a, b| a.0.cmp(&b.0));
    let mut out: Vec<(K, V)> = Vec::with_capacity(v.len());
    for (k, x) in v {
        match out.last_mut() {
            Some(last) if last.0 == k => *last = (k, x),
            _ => out.push((k, x)),
        }
    }
    out
}

/// Removed, added and changed keys between two maps sorted by key ([`by_key`]),
/// `changed` telling whether an old value and the new one differ; each list ascending.
fn delta_by<K: Ord + Clone, V, W>(
    old: &[(K, V)],
    new: &[(K, W)],
    changed: impl Fn(&V, &W) -> bool,
) -> Delta<K> {
    let mut d = Delta {
        removed: Vec::new(),
        added: Vec::new(),
        changed: Vec::new(),
    };
    let (mut i, mut j) = (0, 0);
    loop {
        match (old.get(i), new.get(j)) {
            (Some((k, v)), Some((l, w))) => match k.cmp(l) {
                std::cmp::Ordering::Less => {
                    d.removed.push(k.clone());
                    i += 1;
                }
                std::cmp::Ordering::Greater => {
                    d.added.push(l.clone());
                    j += 1;
                }
                std::cmp::Ordering::Equal => {
                    if changed(v, w) {
                        d.changed.push(k.clone());
                    }
                    i += 1;
                    j += 1;
                }
            },
            (Some((k, _)), None) => {
                d.removed.push(k.clone());
                i += 1;
            }
            (None, Some((l, _))) => {
                d.added.push(l.clone());
                j += 1;
            }
            (None, None) => break,
        }
    }
    d
}

/// The road-graph cells (those with blocks or lots) of a city.
fn cells_of(city: &City) -> BTreeSet<u64> {
    let mut cells: BTreeSet<u64> = city.blocks.iter().map(|b| b.cell_id).collect();
    let mut last = None;
    for l in &city.lots {
        // Lots come cell by cell.
        if last != Some(l.cell) {
            cells.insert(l.cell);
            last = Some(l.cell);
        }
    }
    cells
}

/// Road-graph cells removed, added and changed (a block or lot of theirs removed, added
/// or changed), from the lot and block deltas: a cell is its blocks and lots, by id.
fn cell_delta(old: &City, new: &City, lots: &Delta, block_nodes: &Delta) -> Delta {
    let (was, is) = (cells_of(old), cells_of(new));
    // A lot's id is its cell's id shifted left by 24 bits and its index in the cell.
    let mut touched: BTreeSet<u64> = lots
        .removed
        .iter()
        .chain(&lots.added)
        .chain(&lots.changed)
        .map(|id| id >> 24)
        .collect();
    let ids: BTreeSet<u64> = block_nodes
        .removed
        .iter()
        .chain(&block_nodes.added)
        .chain(&block_nodes.changed)
        .copied()
        .collect();
    for b in old.blocks.iter().chain(&new.blocks) {
        if ids.contains(&b.id()) {
            touched.insert(b.cell_id);
        }
    }
    Delta {
        removed: was.difference(&is).copied().collect(),
        added: is.difference(&was).copied().collect(),
        changed: touched
            .into_iter()
            .filter(|c| was.contains(c) && is.contains(c))
            .collect(),
    }
}

/// Whether the two road graphs have the same edges (positions and payloads) in order.
fn same_roads(a: &polis_roads::RoadNetwork, b: &polis_roads::RoadNetwork) -> bool {
    a.edge_count() == b.edge_count()
        && a.node_count() == b.node_count()
        && a.edges()
            .zip(b.edges())
            .all(|(x, y)| x.3 == y.3 && a.segment(x.0).ok() == b.segment(y.0).ok())
}

/// A building with its skin.
type Dressed<'a> = (
    &'a Arc<polis_buildings::Building>,
    Option<&'a Arc<crate::stages::Dress>>,
);

/// Whether two buildings with their skins differ: not where both are shared (the same
/// `Arc`s, as the memo hands out reused ones), else compared in full.
fn differ(a: &Dressed<'_>, b: &Dressed<'_>) -> bool {
    let same_skin = match (a.1, b.1) {
        (Some(x), Some(y)) => Arc::ptr_eq(x, y) || x == y,
        (None, None) => true,
        _ => false,
    };
    !(same_skin && (Arc::ptr_eq(a.0, b.0) || a.0 == b.0))
}

/// A city's buildings with their index and skin, by id ([`by_key`]).
fn buildings_of(c: &City) -> Vec<(u64, (usize, Dressed<'_>))> {
    by_key(
        c.buildings
            .iter()
            .enumerate()
            .map(|(i, b)| (b.id, (i, (b, c.dresses.get(i).and_then(Option::as_ref)))))
            .collect(),
    )
}

/// The change events from `old` to `new`. `spliced` is the scene splice of the edit, if
/// any: the buildings and blocks it found equal and reused are not compared again.
pub(super) fn changes(
    old: &City,
    new: &City,
    old_cells: &[District],
    new_cells: &[District],
    redone: &Redone,
    spliced: Option<&OldScene>,
) -> ChangeEvents {
    let ids = |d: &[District]| d.iter().map(|c| c.id).collect::<BTreeSet<u64>>();
    let (oc, nc) = (ids(old_cells), ids(new_cells));
    let cells = Delta {
        removed: oc.difference(&nc).copied().collect(),
        added: nc.difference(&oc).copied().collect(),
        changed: redone
            .cells
            .iter()
            .copied()
            .filter(|c| oc.contains(c) && nc.contains(c))
            .collect(),
    };
    // The old city is the one the splice indexed (or no building is known equal).
    let spliced = spliced.filter(|s| std::ptr::eq(s.city(), old));
    let same_building = |i: usize| spliced.is_some_and(|s| s.same_building_at(i));
    let same_block = |i: usize| spliced.is_some_and(|s| s.same_block_at(i));
    // The three comparisons are independent: two threads take them. The buildings by
    // id are kept to find their cells below.
    let ((lots, (buildings, old_of, new_of)), block_nodes) = par::join(
        || {
            par::join(
                || {
                    // A lot of a cell the edit left alone is the old city's, shared:
                    // found equal by its pointer.
                    delta_by(
                        &by_key(old.lots.iter().map(|l| (l.id, l)).collect()),
                        &by_key(new.lots.iter().map(|l| (l.id, l)).collect()),
                        |v, w| !v.same_as(w),
                    )
                },
                || {
                    let (old_of, new_of) = (buildings_of(old), buildings_of(new));
                    let d = delta_by(&old_of, &new_of, |(i, v), (_, w)| {
                        !same_building(*i) && differ(v, w)
                    });
                    (d, old_of, new_of)
                },
            )
        },
        || {
            delta_by(
                &by_key(
                    old.blocks
                        .iter()
                        .enumerate()
                        .map(|(i, b)| (b.id(), (i, b)))
                        .collect(),
                ),
                &by_key(new.blocks.iter().map(|b| (b.id(), b)).collect()),
                |(i, v), w| !same_block(*i) && !Arc::ptr_eq(v, w) && v != w,
            )
        },
    );
    let blocks = cell_delta(old, new, &lots, &block_nodes);
    // Scene nodes: `cell <c>` groups its blocks and buildings.
    let mut scene = Delta::<String>::default();
    let name = |kind: &str, id: &u64| format!("{kind} {id}");
    scene
        .removed
        .extend(blocks.removed.iter().map(|c| name("cell", c)));
    scene
        .added
        .extend(blocks.added.iter().map(|c| name("cell", c)));
    let mut touched: BTreeSet<u64> = blocks.changed.iter().copied().collect();
    // The cell of each building the events name, looked up by id.
    let find = |c: &City, of: &[(u64, (usize, Dressed<'_>))], id: u64| {
        of.binary_search_by_key(&id, |p| p.0)
            .ok()
            .and_then(|k| of.get(k))
            .and_then(|p| c.building_cells.get(p.1.0).copied())
    };
    for &id in buildings.changed.iter().chain(&buildings.added) {
        touched.extend(find(new, &new_of, id));
    }
    for &id in &buildings.removed {
        touched.extend(find(old, &old_of, id));
    }
    let gone: BTreeSet<u64> = blocks
        .removed
        .iter()
        .chain(&blocks.added)
        .copied()
        .collect();
    scene
        .changed
        .extend(touched.difference(&gone).map(|c| name("cell", c)));
    scene
        .removed
        .extend(block_nodes.removed.iter().map(|b| name("block", b)));
    scene
        .added
        .extend(block_nodes.added.iter().map(|b| name("block", b)));
    scene
        .changed
        .extend(block_nodes.changed.iter().map(|b| name("block", b)));
    scene
        .removed
        .extend(buildings.removed.iter().map(|b| name("building", b)));
    scene
        .added
        .extend(buildings.added.iter().map(|b| name("building", b)));
    scene
        .changed
        .extend(buildings.changed.iter().map(|b| name("building", b)));
    if !same_roads(&old.roads, &new.roads) {
        scene.changed.push("roads".to_string());
    }
    scene.removed.sort();
    scene.added.sort();
    scene.changed.sort();
    ChangeEvents {
        primary: None,
        cells,
        blocks,
        lots,
        buildings,
        scene_nodes: scene,
        orphaned: Vec::new(),
        regenerated: Regenerated {
            cells: redone.cells.len(),
            blocks: redone.blocks.len(),
            buildings: redone.buildings,
            dresses: redone.dresses,
        },
        dirty_cells: redone.cells.iter().copied().collect(),
        dirty_blocks: redone.blocks.iter().copied().collect(),
    }
}

/// The lot overrides of `config` that find no lot of `city`, by id or anchor.
pub(super) fn orphans(config: &CityConfig, city: &City) -> Vec<LotOverride> {
    if config.citygen.lots.is_empty() {
        return Vec::new();
    }
    let ids: BTreeSet<u64> = city.lots.iter().map(|l| l.id).collect();
    config
        .citygen
        .lots
        .iter()
        .filter(|o| {
            let at = DVec2::new(o.at[0], o.at[1]);
            !ids.contains(&o.lot)
                && !city
                    .lots
                    .iter()
                    .any(|l| l.lot.polygon.bbox().contains(at) && l.lot.polygon.contains(at))
        })
        .cloned()
        .collect()
}
