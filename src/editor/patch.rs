//! Lot edits in place: an edit that changes only lot overrides (pin a kind or a height,
//! remove a building's pin, reseed a lot, clear an override) leaves the road graph,
//! blocks, lots, tile sets and ground as they are, so the editor rebuilds only the
//! buildings of the lots whose override changed, dresses them, and replaces their
//! scene leaves in the city it holds, instead of running the pipeline over every item.
//! The cost is that of the lots touched (plus a scan of the scene's mesh ids when a
//! building's mesh count changes), not of the city.
//!
//! The city so patched is the city the pipeline makes of the new configuration: each
//! building, skin and leaf is made by the same functions from the same inputs
//! ([`lot_plan`], the building grammar, the dresser of the last run, the scene's leaf
//! and coarse-box code), and everything else is unchanged by such an edit. Where that
//! cannot be shown cheaply the patch declines and the editor runs the pipeline: a
//! pinned style added or dropped (the tile sets and palette change), roads graded into
//! the ground, a building appearing or disappearing (the scene's node tree would
//! change), a lot whose building or skin failed before or fails now (the skip report
//! would change).

use std::collections::BTreeSet;

use polis_buildings::Building;
use polis_geom::scene::NodeId;

use super::edit::{ChangeEvents, Delta, Regenerated};
use super::memo::Memo;
use crate::City;
use crate::CityConfig;
use crate::citygen::{District, LotOverride, lot_plan};
use polis_geom::scene::MeshId;
use polis_geom::{Mesh, Scene, Transform};

use crate::scene::{BuildingLeaves, LeafPalette, Reused};
use crate::stages::{BuildLot, Dress, LotInput, Stage, StageContext};

/// Look-ups by id into a city whose lots, buildings and scene nodes an in-place patch
/// keeps (built after each pipeline run, on the first patch).
pub(super) struct Index {
    /// Lot id → index in `City::lots`, by id.
    lots: Vec<(u64, usize)>,
    /// Building id → index in `City::buildings`, by id.
    buildings: Vec<(u64, usize)>,
    /// Building id → its scene node, by id.
    nodes: Vec<(u64, NodeId)>,
}

fn find<T: Copy>(v: &[(u64, T)], id: u64) -> Option<T> {
    v.binary_search_by_key(&id, |e| e.0)
        .ok()
        .and_then(|i| v.get(i))
        .map(|e| e.1)
}

/// `pairs` sorted by id, for [`find`].
fn by_id<T>(pairs: impl Iterator<Item = (u64, T)>) -> Vec<(u64, T)> {
    let mut v: Vec<(u64, T)> = pairs.collect();
    v.sort_by_key(|e| e.0);
    v
}

impl Index {
    /// The index of `city`.
    pub(super) fn of(city: &City) -> Self {
        let lots = by_id(city.lots.iter().enumerate().map(|(i, l)| (l.id, i)));
        let buildings = by_id(city.buildings.iter().enumerate().map(|(i, b)| (b.id, i)));
        let nodes = by_id(city.scene.nodes.iter().enumerate().filter_map(|(n, node)| {
            let id = crate::scene::node_id(&node.name, "building")?;
            Some((id, NodeId(n as u32)))
        }));
        Index {
            lots,
            buildings,
            nodes,
        }
    }
}

/// The pinned facade styles of `config`, in order.
fn pinned(config: &CityConfig) -> impl Iterator<Item = &str> {
    config
        .citygen
        .lots
        .iter()
        .filter_map(|o| o.style.as_deref())
}

/// Whether `new` differs from `old` in the lot overrides only, with the same pinned
/// styles, on ungraded ground: an edit the patch may take.
pub(super) fn lots_only(old: &CityConfig, new: &CityConfig) -> bool {
    if old.citygen.lots == new.citygen.lots
        || !pinned(old).eq(pinned(new))
        || (new.scene.grade_roads && new.maps.elevation.is_some())
    {
        return false;
    }
    let mut c = old.clone();
    c.citygen.lots.clone_from(&new.citygen.lots);
    c == *new
}

/// A building made for a lot, with its skin.
type Made = Option<(Building, Option<Dress>)>;

/// The overrides in one list and not the other (either way).
fn changed_overrides<'a>(old: &'a [LotOverride], new: &'a [LotOverride]) -> Vec<&'a LotOverride> {
    old.iter()
        .filter(|o| !new.contains(o))
        .chain(new.iter().filter(|o| !old.contains(o)))
        .collect()
}

/// Patches `city` (made of `old`) into the city of `config`, which differs from `old` in
/// the lot overrides only ([`lots_only`]). Returns the change events and the new orphans
/// (`orphans` are `old`'s), or `None`, with `city` untouched, where the patch declines
/// (see the [module docs](self)) and the pipeline must run.
pub(super) fn patch_lots(
    city: &mut City,
    index: &Index,
    config: &CityConfig,
    districts: &[District],
    memo: &Memo,
    orphans: &[LotOverride],
) -> Option<(ChangeEvents, Vec<LotOverride>)> {
    let old = &city.config;
    if city.scene.nodes.is_empty() {
        return None;
    }
    let changed = changed_overrides(&old.citygen.lots, &config.citygen.lots);
    // The lots whose override may differ: by id, or by anchor for an override whose lot
    // is gone.
    let mut affected = BTreeSet::new();
    for o in &changed {
        match find(&index.lots, o.lot) {
            Some(i) => {
                affected.insert(i);
            }
            None => {
                let at = polis_geom::DVec2::new(o.at[0], o.at[1]);
                affected.extend(city.lots.iter().enumerate().filter_map(|(i, l)| {
                    let p = &l.lot.polygon;
                    (p.bbox().contains(at) && p.contains(at)).then_some(i)
                }));
            }
        }
    }
    // A lot whose building or skin was skipped: the report would change.
    let skipped = city.report.skipped.iter().any(|s| {
        matches!(s.stage, Stage::Buildings | Stage::Facades)
            && find(&index.lots, s.id).is_some_and(|i| affected.contains(&i))
    });
    if skipped {
        return None;
    }
    // The lot ids overrides name that are lots (all `lot_plan` asks of the set).
    let ids: BTreeSet<u64> = config
        .citygen
        .lots
        .iter()
        .map(|o| o.lot)
        .filter(|&id| find(&index.lots, id).is_some())
        .collect();
    let cx = StageContext {
        config,
        maps: &city.maps,
    };
    let builder =
        polis_buildings::BuildingGenerator::new(config.effective_building_params()).ok()?;
    let dresser = memo.dresser_for(config)?;
    let lod = config.effective_lod();
    let palette = LeafPalette::new(&city.tile_sets).ok()?;
    let leaves = BuildingLeaves::new(config, &city.maps, &palette, &city.tile_sets);
    let mut regenerated = Regenerated::default();
    // (building index, node, building, skin, leaf, coarse box) per changed building.
    let mut updates = Vec::new();
    for &i in &affected {
        let l = city.lots.get(i)?;
        let made: Made = match lot_plan(&cx, districts, l, &ids) {
            None => None,
            Some(plan) => {
                let b = BuildLot::build(
                    &builder,
                    &LotInput {
                        id: plan.build_id,
                        lot: &l.lot,
                        kind: plan.kind,
                        max_height_m: plan.max_height_m,
                        lod,
                    },
                )
                .ok()?;
                regenerated.buildings += 1;
                match b {
                    None => None,
                    Some(mut b) => {
                        b.id = l.id;
                        b.lot_id = l.id;
                        let d = dresser
                            .dress_styled(&b, cx.seed(Stage::Facades, b.id), plan.style.as_deref())
                            .ok()?;
                        regenerated.dresses += 1;
                        Some((b, d))
                    }
                }
            }
        };
        let at = find(&index.buildings, l.id);
        let (k, b, d) = match (at, made) {
            (None, None) => continue,
            (Some(k), Some((b, d))) => (k, b, d),
            // A building appears or disappears.
            _ => return None,
        };
        let same = **city.buildings.get(k)? == b
            && city.dresses.get(k)?.as_deref() == d.as_ref()
            && *city.building_cells.get(k)? == l.cell;
        if same {
            continue;
        }
        let node = find(&index.nodes, l.id)?;
        let (leaf, coarse) = leaves.leaf(&b, d.as_ref(), Some(l.cell)).ok()?;
        let boxed = coarse.as_ref().is_some_and(Option::is_some);
        if !building_replaceable(&city.scene, node, leaf.3.len(), boxed) {
            return None;
        }
        updates.push((k, l.cell, node, b, d, leaf, coarse));
    }
    // Orphans: the unchanged overrides keep their state, the changed ones are looked up.
    let new_orphans: Vec<LotOverride> = config
        .citygen
        .lots
        .iter()
        .filter(|o| {
            if old.citygen.lots.contains(o) {
                return orphans.contains(o);
            }
            let at = polis_geom::DVec2::new(o.at[0], o.at[1]);
            find(&index.lots, o.lot).is_none()
                && !city
                    .lots
                    .iter()
                    .any(|l| l.lot.polygon.bbox().contains(at) && l.lot.polygon.contains(at))
        })
        .cloned()
        .collect();

    // Every check passed: patch.
    let mut buildings = Delta::default();
    let mut scene_nodes = Delta::<String>::default();
    let mut cells = BTreeSet::new();
    for (k, cell, node, b, d, leaf, coarse) in updates {
        replace_building(&mut city.scene, node, leaf, coarse);
        let stats = &mut city.stats;
        if let Some(slot) = city.buildings.get_mut(k) {
            stats.building_triangles = (stats.building_triangles + b.triangle_count())
                .saturating_sub(slot.triangle_count());
            buildings.changed.push(b.id);
            scene_nodes
                .changed
                .push(crate::scene::building_node_name(b.id));
            *slot = std::sync::Arc::new(b);
        }
        if let Some(slot) = city.dresses.get_mut(k) {
            stats.dressed_buildings = (stats.dressed_buildings + usize::from(d.is_some()))
                .saturating_sub(usize::from(slot.is_some()));
            *slot = d.map(std::sync::Arc::new);
        }
        cells.insert(cell);
    }
    // The memo's keys of the old buildings no longer describe the city's.
    memo.forget(buildings.changed.iter().copied());
    city.stats.scene_triangles = city.scene.triangle_count();
    city.config = config.clone();
    buildings.changed.sort_unstable();
    scene_nodes
        .changed
        .extend(cells.iter().map(|c| format!("cell {c}")));
    scene_nodes.changed.sort();
    let events = ChangeEvents {
        primary: None,
        cells: Delta::default(),
        blocks: Delta::default(),
        lots: Delta::default(),
        buildings,
        scene_nodes,
        orphaned: new_orphans.clone(),
        regenerated,
        dirty_cells: Vec::new(),
        dirty_blocks: Vec::new(),
    };
    Some((events, new_orphans))
}

/// The building node `node` of `scene` as `assemble` makes it: its run of mesh ids
/// (first, count) and its coarse child (node and mesh), or `None` if it is not such a
/// node (meshes not one run, children other than one `lod 0` box).
fn building_node(scene: &Scene, node: NodeId) -> Option<(usize, usize, Option<usize>)> {
    let old = scene.nodes.get(node.0 as usize)?;
    let child = match old.children.as_slice() {
        [] => None,
        [c] => {
            let n = scene.nodes.get(c.0 as usize)?;
            let m = match n.meshes.as_slice() {
                [m] if n.name == "lod 0" && n.children.is_empty() => m.0 as usize,
                _ => return None,
            };
            // The coarse level's node carries the finest level's number.
            old.metadata.get("lod")?;
            Some(m)
        }
        _ => return None,
    };
    let first = old.meshes.first().map_or(0, |m| m.0 as usize);
    let len = old.meshes.len();
    let run = old
        .meshes
        .iter()
        .enumerate()
        .all(|(k, m)| m.0 as usize == first + k);
    (run && first + len <= scene.meshes.len() && child.is_none_or(|m| m < scene.meshes.len()))
        .then_some((first, len, child))
}

/// Whether [`replace_building`] can replace the building node `node` with a leaf of
/// `meshes` meshes and (`boxed`) a coarse box: it is a building node of
/// `assemble`'s and the coarse level neither appears nor disappears (the node tree
/// would change).
pub(crate) fn building_replaceable(
    scene: &Scene,
    node: NodeId,
    meshes: usize,
    boxed: bool,
) -> bool {
    building_node(scene, node)
        .is_some_and(|(_, len, child)| child.is_some() == boxed && (len > 0 || meshes == 0))
}

/// Replaces the building node `node` of `scene` (made by `assemble`) with `leaf` and
/// its coarse box `coarse` (from `BuildingLeaves::leaf`): name, placement, metadata,
/// meshes (the scene's later mesh ids shift when their number changes) and the `lod 0`
/// child's box. Returns `false`, leaving the scene unchanged, unless
/// [`building_replaceable`].
pub(crate) fn replace_building(
    scene: &mut Scene,
    node: NodeId,
    leaf: Reused,
    coarse: Option<Option<Mesh>>,
) -> bool {
    let (name, translation, mut metadata, meshes) = leaf;
    let new_box = coarse.flatten();
    if !building_replaceable(scene, node, meshes.len(), new_box.is_some()) {
        return false;
    }
    let Some((first, len, mut child)) = building_node(scene, node) else {
        return false;
    };
    if child.is_some()
        && let Some(f) = scene
            .nodes
            .get(node.0 as usize)
            .and_then(|n| n.metadata.get("lod"))
            .cloned()
    {
        metadata.insert("lod", f);
    }
    let k = meshes.len();
    if k == len {
        for (slot, m) in scene.meshes[first..first + len].iter_mut().zip(meshes) {
            *slot = m;
        }
    } else {
        scene.meshes.splice(first..first + len, meshes);
        let end = first + len;
        let shift = |id: usize| if id >= end { id + k - len } else { id };
        for n in &mut scene.nodes {
            for m in &mut n.meshes {
                *m = MeshId(shift(m.0 as usize) as u32);
            }
        }
        child = child.map(shift);
    }
    if let (Some(m), Some(b)) = (child, new_box)
        && let Some(slot) = scene.meshes.get_mut(m)
    {
        *slot = b;
    }
    if let Some(n) = scene.nodes.get_mut(node.0 as usize) {
        n.name = name;
        n.transform = Transform::from_translation(translation);
        n.metadata = metadata;
        n.meshes = (first..first + k).map(|i| MeshId(i as u32)).collect();
    }
    true
}
