//! What changed between two states of an edited city, by stable id: the
//! [`ChangeEvents`] a host applies to its meshes.

use std::collections::{BTreeSet, HashSet};
use std::ops::Range;
use std::sync::Arc;

use polis_geom::DVec2;
use polis_geom::par;

use super::edit::{ChangeEvents, Delta, Regenerated};
use super::key::{IdBits, IdMap};
use super::memo::Redone;
use super::splice::OldScene;
use crate::City;
use crate::CityConfig;
use crate::citygen::{District, LotOverride};

/// A set of ids (parts).
type IdSet = HashSet<u64, IdBits>;

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
    let mut cells = BTreeSet::new();
    // Blocks and lots come cell by cell: one insertion per run.
    let mut last = None;
    for c in city
        .blocks
        .iter()
        .map(|b| b.cell_id)
        .chain(city.lots.iter().map(|l| l.cell))
    {
        if last != Some(c) {
            cells.insert(c);
            last = Some(c);
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

/// Building `i` of a city with its skin.
fn dressed(c: &City, i: usize) -> Dressed<'_> {
    (&c.buildings[i], c.dresses.get(i).and_then(Option::as_ref))
}

/// The buildings of a city at `indices`, with their index and skin, by id ([`by_key`]).
fn buildings_of<'a>(c: &'a City, indices: &[usize]) -> Vec<(u64, (usize, Dressed<'a>))> {
    by_key(
        indices
            .iter()
            .filter_map(|&i| {
                let b = c.buildings.get(i)?;
                Some((b.id, (i, (b, c.dresses.get(i).and_then(Option::as_ref)))))
            })
            .collect(),
    )
}

/// The part of an item with id `id`: its road-graph cell (a lot's id, and its
/// building's, is its cell's id shifted left by 24 bits and its index in the cell).
fn part(id: u64) -> u64 {
    id >> 24
}

/// The indices of the items a delta must compare, given the ids of the old and the new
/// items in order: all but those of the parts ([`part`] of their ids) whose items are
/// the same on both sides, pair by pair in order (`same(i, j)`: old item `i` and new
/// item `j`, of equal ids, would not be reported changed). Leaving such a part out is
/// exact: every occurrence of an id lies in its part, and a part that pairs off
/// unchanged adds nothing to a delta (of equal ids the same pair is kept on both
/// sides). Items come cell by cell, so a part is one run of consecutive items; where a
/// part is not (on either side) nothing is left out. The indices left are ascending.
/// The cost is one pass over the ids (and `same`, a pointer comparison where the edit
/// shared the items) and a sort of the items left, not of every item.
fn to_compare(
    old: &[u64],
    new: &[u64],
    same: impl Fn(usize, usize) -> bool,
) -> (Vec<usize>, Vec<usize>) {
    let everything = || ((0..old.len()).collect(), (0..new.len()).collect());
    let (Some(was), Some(is)) = (runs(old), runs(new)) else {
        return everything();
    };
    let is_by_part: IdMap<Range<usize>> = is.iter().map(|(p, r)| (*p, r.clone())).collect();
    let mut left_out = IdSet::with_capacity_and_hasher(was.len(), IdBits);
    for (p, r) in &was {
        if let Some(s) = is_by_part.get(p)
            && s.len() == r.len()
            && r.clone()
                .zip(s.clone())
                .all(|(i, j)| old.get(i) == new.get(j) && same(i, j))
        {
            left_out.insert(*p);
        }
    }
    // The runs are in item order.
    let keep = |runs: &[(u64, Range<usize>)]| -> Vec<usize> {
        runs.iter()
            .filter(|(p, _)| !left_out.contains(p))
            .flat_map(|(_, r)| r.clone())
            .collect()
    };
    (keep(&was), keep(&is))
}

/// The runs of consecutive ids of one part ([`part`]), in order, if each part's ids are
/// one run.
fn runs(ids: &[u64]) -> Option<Vec<(u64, Range<usize>)>> {
    let mut out: Vec<(u64, Range<usize>)> = Vec::new();
    let mut start = 0;
    for (i, w) in ids.windows(2).enumerate() {
        if part(w[0]) != part(w[1]) {
            out.push((part(w[0]), start..i + 1));
            start = i + 1;
        }
    }
    if let Some(&last) = ids.last() {
        out.push((part(last), start..ids.len()));
    }
    let mut seen = IdSet::with_capacity_and_hasher(out.len(), IdBits);
    out.iter().all(|(p, _)| seen.insert(*p)).then_some(out)
}

/// The change events from `old` to `new`. `spliced` is the scene splice of the edit, if
/// any: the buildings and blocks it found equal and reused are not compared again. The
/// lots and buildings of a cell whose items pair off unchanged are not sorted or
/// compared by id at all ([`to_compare`]); the events are those of comparing every
/// item.
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
    // The three comparisons are independent: two threads take them. The lots and
    // buildings of a cell the edit left alone pair off unchanged and are left out before
    // sorting ([`to_compare`]); the buildings by id are kept to find their cells below.
    let ((lots, (buildings, old_of, new_of)), block_nodes) = par::join(
        || {
            par::join(
                || {
                    // A lot of a cell the edit left alone is the old city's, shared:
                    // found equal by its pointer.
                    let ids = |c: &City| c.lots.iter().map(|l| l.id).collect::<Vec<u64>>();
                    let (o, n) = to_compare(&ids(old), &ids(new), |i, j| {
                        old.lots[i].same_as(&new.lots[j])
                    });
                    delta_by(
                        &by_key(o.iter().map(|&i| (old.lots[i].id, &old.lots[i])).collect()),
                        &by_key(n.iter().map(|&j| (new.lots[j].id, &new.lots[j])).collect()),
                        |v, w| !v.same_as(w),
                    )
                },
                || {
                    let ids = |c: &City| c.buildings.iter().map(|b| b.id).collect::<Vec<u64>>();
                    let (o, n) = to_compare(&ids(old), &ids(new), |i, j| {
                        same_building(i) || !differ(&dressed(old, i), &dressed(new, j))
                    });
                    let (old_of, new_of) = (buildings_of(old, &o), buildings_of(new, &n));
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
