//! Splicing the scene: after an edit the 3-D scene is assembled again, but every block
//! and building whose inputs are those of the city before the edit takes its node and
//! meshes from the earlier scene instead of being meshed again (Kelly §6.7: each cell
//! batches its own geometry, so an edit touches only its cells' batches).
//!
//! A leaf is reused when the scene-wide inputs are unchanged ([`scene_key`]: the
//! configuration but for the Citygen edits, which reach the scene only through the
//! layers; the pinned facade styles, which decide the palette) and its own inputs are
//! equal: the same building (every part and facade), skin and cell; the same block.
//! Roads graded into an elevation map move the ground every leaf stands on, so with
//! grading on nothing is reused. The scene so made is the scene `assemble` would make:
//! reuse only skips recomputing identical parts.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use polis_buildings::Building;
use polis_geom::metadata::Metadata;
use polis_geom::scene::NodeId;
use polis_geom::{Mesh, Transform};
use polis_lots::Block;

use super::key::{IdBits, IdMap, Key};
use super::memo::Memo;
use crate::City;
use crate::CityConfig;
use crate::scene::{Reused, SceneReuse};
use crate::stages::Dress;

/// The digest of what every leaf of the scene reads besides its own item, or `None`
/// when the ground depends on the road graph (graded roads) and nothing may be reused.
pub(super) fn scene_key(config: &CityConfig) -> Option<Key> {
    if config.scene.grade_roads && config.maps.elevation.is_some() {
        return None;
    }
    let mut c = config.clone();
    let pinned: Vec<String> = c
        .citygen
        .lots
        .iter()
        .filter_map(|o| o.style.clone())
        .collect();
    c.citygen = Default::default();
    let text = serde_json::to_string(&(&c, &pinned)).ok()?;
    Some(Key::new(0x7363_656E).bytes(text.as_bytes()))
}

/// The scene of a city before an edit, indexed for reuse. Its meshes, and the names and
/// metadata of its block and building leaves, are moved out of the city (which keeps its
/// node tree) into slots, and a reused leaf takes them from their slots rather than
/// copying them: the city before the edit is dropped when the edit succeeds, and what it
/// lent is put back ([`OldScene::restore`], which first lets go of the scene's own
/// reference to the city) when it fails.
pub(super) struct OldScene {
    city: Arc<City>,
    /// The city's scene meshes, by mesh id; `None` once taken by a reused leaf.
    meshes: Vec<Mutex<Option<Mesh>>>,
    /// The name and metadata of each indexed leaf, by its index in `buildings` then
    /// `blocks` order of [`Lent::leaves`]; `None` once taken.
    names: Vec<Mutex<Option<(String, Metadata)>>>,
    /// The node each slot of `names` came from.
    named: Vec<NodeId>,
    /// The editor's memo: which buildings and skins were made from the same keys as
    /// the old city's (equal without comparing them).
    memo: Arc<Memo>,
    /// Per old building (by index in the city's buildings): its node and slot in
    /// `names`, if it has one.
    buildings: Vec<Option<(NodeId, usize)>>,
    /// Building id → index in the city's buildings.
    building_at: IdMap<usize>,
    /// Per new building (by index, see [`SceneReuse::prepare`]): the index of the old
    /// building with its id, if any.
    matched: OnceLock<Vec<Option<usize>>>,
    /// Block id → (index in the city's blocks, node, slot in `names`).
    blocks: IdMap<(usize, NodeId, usize)>,
    /// Per old building (by index): found equal to the new one (building, skin and cell)
    /// and reused; the change events then need not compare it again.
    same_buildings: Vec<AtomicBool>,
    /// Per old block (by index): found equal to the new one and reused.
    same_blocks: Vec<AtomicBool>,
}

/// What [`OldScene::lend`] moved out of a city: its scene's meshes and the names and
/// metadata of its leaves, with their index.
pub(super) struct Lent {
    meshes: Vec<Mesh>,
    names: Vec<(String, Metadata)>,
    named: Vec<NodeId>,
    buildings: Vec<Option<(NodeId, usize)>>,
    building_at: IdMap<usize>,
    blocks: IdMap<(usize, NodeId, usize)>,
}

/// Values in slots of their own, to be taken once each.
fn slots<T>(v: Vec<T>) -> Vec<Mutex<Option<T>>> {
    v.into_iter().map(|m| Mutex::new(Some(m))).collect()
}

/// The values of `slots`, if none was taken.
fn unslot_all<T>(slots: Vec<Mutex<Option<T>>>) -> Option<Vec<T>> {
    slots
        .into_iter()
        .map(|slot| slot.into_inner().unwrap_or_else(PoisonError::into_inner))
        .collect()
}

impl OldScene {
    /// Indexes `city`'s scene leaves by the ids in their names and moves out of it its
    /// scene's meshes and its leaves' names and metadata.
    ///
    /// The scene [`assemble`](crate::scene::assemble) makes (and the in-place patch
    /// keeps) has the buildings' nodes in the order of the city's buildings, so the
    /// `k`-th building node is building `k`'s: that is checked by id, and a node out of
    /// that order is found through the ids instead.
    pub(super) fn lend(city: &mut City) -> Lent {
        let building_at: IdMap<usize> = city
            .buildings
            .iter()
            .enumerate()
            .map(|(i, b)| (b.id, i))
            .collect();
        let block_at: IdMap<usize> = city
            .blocks
            .iter()
            .enumerate()
            .map(|(i, b)| (b.id(), i))
            .collect();
        let mut buildings = vec![None; city.buildings.len()];
        let mut blocks = IdMap::with_capacity_and_hasher(block_at.len(), IdBits);
        let mut names = Vec::with_capacity(building_at.len() + block_at.len());
        let mut named = Vec::with_capacity(names.capacity());
        // The index the next building node has in the assembled order.
        let mut next_building = 0;
        for (n, node) in city.scene.nodes.iter_mut().enumerate() {
            let id = |kind: &str| crate::scene::node_id(&node.name, kind);
            let node_id = NodeId(n as u32);
            let slot = names.len();
            let indexed = if let Some(id) = id("building") {
                let at = match city.buildings.get(next_building) {
                    Some(b) if b.id == id => Some(next_building),
                    _ => building_at.get(&id).copied(),
                };
                next_building += 1;
                at.and_then(|i| buildings.get_mut(i))
                    .map(|entry| *entry = Some((node_id, slot)))
                    .is_some()
            } else if let Some(id) = id("block") {
                block_at
                    .get(&id)
                    .map(|&i| blocks.insert(id, (i, node_id, slot)))
                    .is_some()
            } else {
                false
            };
            if indexed {
                names.push((
                    std::mem::take(&mut node.name),
                    std::mem::take(&mut node.metadata),
                ));
                named.push(node_id);
            }
        }
        Lent {
            meshes: std::mem::take(&mut city.scene.meshes),
            names,
            named,
            buildings,
            building_at,
            blocks,
        }
    }

    /// The scene of `city` from what [`lend`](Self::lend) moved out of it.
    pub(super) fn new(city: Arc<City>, lent: Lent, memo: Arc<Memo>) -> Self {
        let flags = |n: usize| (0..n).map(|_| AtomicBool::new(false)).collect();
        OldScene {
            meshes: slots(lent.meshes),
            names: slots(lent.names),
            named: lent.named,
            memo,
            same_buildings: flags(city.buildings.len()),
            same_blocks: flags(city.blocks.len()),
            city,
            buildings: lent.buildings,
            building_at: lent.building_at,
            matched: OnceLock::new(),
            blocks: lent.blocks,
        }
    }

    /// The city before the edit.
    pub(super) fn city(&self) -> &City {
        &self.city
    }

    /// Whether the old building at `index` was found equal to the new one with its id
    /// (same building, skin and cell) while the scene was assembled.
    pub(super) fn same_building_at(&self, index: usize) -> bool {
        self.same_buildings
            .get(index)
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// Whether the old block at `index` was found equal to the new one with its id.
    pub(super) fn same_block_at(&self, index: usize) -> bool {
        self.same_blocks
            .get(index)
            .is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// Puts what `city` lent back into it, if no leaf took any of it (the edit failed
    /// before the scene was assembled); returns whether it did. This scene's own
    /// reference to the city is released first, so that `city` can be written to when
    /// the caller holds the only other one. On `false` the city may lack what was lent
    /// and must be made again.
    pub(super) fn restore(self, city: &mut Arc<City>) -> bool {
        let OldScene {
            city: lent_by,
            meshes,
            names,
            named,
            ..
        } = self;
        drop(lent_by);
        let (Some(meshes), Some(names)) = (unslot_all(meshes), unslot_all(names)) else {
            return false;
        };
        let Some(city) = Arc::get_mut(city) else {
            return false;
        };
        for (n, (name, metadata)) in named.iter().zip(names) {
            if let Some(node) = city.scene.nodes.get_mut(n.0 as usize) {
                node.name = name;
                node.metadata = metadata;
            }
        }
        city.scene.meshes = meshes;
        true
    }

    /// Takes mesh `m` out of its slot.
    fn take(&self, m: usize) -> Option<Mesh> {
        self.meshes
            .get(m)?
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
    }

    /// The node `n` (its name and metadata in slot `slot`) as a reusable leaf (name,
    /// translation, metadata, meshes).
    fn leaf(&self, n: NodeId, slot: usize) -> Option<Reused> {
        let scene = &self.city.scene;
        let node = scene.nodes.get(n.0 as usize)?;
        let Transform::Trs { translation, .. } = node.transform else {
            return None;
        };
        // A leaf is reused at most once (ids are unique), so its parts are there.
        let meshes = node
            .meshes
            .iter()
            .map(|m| self.take(m.0 as usize))
            .collect::<Option<Vec<Mesh>>>()?;
        let (name, metadata) = self
            .names
            .get(slot)?
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()?;
        Some((name, translation, metadata, meshes))
    }

    /// The index of the old building with the id of new building `index` (see
    /// [`SceneReuse::prepare`]).
    fn old_index(&self, index: usize) -> Option<usize> {
        self.matched.get()?.get(index).copied().flatten()
    }
}

impl SceneReuse for OldScene {
    fn prepare(&self, buildings: &[Arc<Building>]) {
        // The new city lists the buildings of the cells it reused in the old city's
        // order, shared with it: a cursor through the old buildings meets them by
        // pointer, without reading a building; the others are looked up by id.
        let old = &self.city.buildings;
        let mut next = 0;
        let matched = buildings
            .iter()
            .map(|b| {
                let at = match old.get(next) {
                    Some(o) if Arc::ptr_eq(o, b) => Some(next),
                    _ => self.building_at.get(&b.id).copied(),
                };
                if let Some(i) = at {
                    next = i + 1;
                }
                at
            })
            .collect();
        // A second call (none is made) keeps the first's matching, made of the same
        // buildings.
        let _ = self.matched.set(matched);
    }

    fn building(
        &self,
        index: usize,
        b: &Arc<Building>,
        dress: Option<&Arc<Dress>>,
        cell: Option<u64>,
    ) -> Option<Reused> {
        let i = self.old_index(index)?;
        let (n, slot) = self.buildings.get(i).copied().flatten()?;
        let old_cell = self.city.building_cells.get(i).copied();
        if old_cell != cell {
            return None;
        }
        // The same building and skin (shared with the old city, which is how the memo
        // hands reused ones out), or made from the same keys: equal; otherwise compared
        // in full.
        let old = self.city.buildings.get(i)?;
        let old_dress = self.city.dresses.get(i).and_then(Option::as_ref);
        let shared = Arc::ptr_eq(old, b)
            && match (old_dress, dress) {
                (Some(x), Some(y)) => Arc::ptr_eq(x, y),
                (None, None) => true,
                _ => false,
            };
        let same = shared
            || match self.memo.same_keys(b.id) {
                Some(same) => same,
                None => **old == **b && old_dress.map(|d| &**d) == dress.map(|d| &**d),
            };
        if !same {
            return None;
        }
        let leaf = self.leaf(n, slot)?;
        if let Some(f) = self.same_buildings.get(i) {
            f.store(true, Ordering::Relaxed);
        }
        Some(leaf)
    }

    fn coarse(&self, index: usize, b: &Arc<Building>) -> Option<Option<Mesh>> {
        let i = self.old_index(index)?;
        let (n, _) = self.buildings.get(i).copied().flatten()?;
        // A building reused whole was compared already.
        if !self.same_building_at(i) {
            let old = self.city.buildings.get(i)?;
            if !(Arc::ptr_eq(old, b) || **old == **b) {
                return None;
            }
        }
        let scene = &self.city.scene;
        let node = scene.nodes.get(n.0 as usize)?;
        let lod = node.children.iter().find_map(|c| {
            let child = scene.nodes.get(c.0 as usize)?;
            (child.name == "lod 0").then_some(child)
        });
        match lod {
            None => Some(None),
            Some(child) => {
                let m = child.meshes.first()?;
                Some(Some(self.take(m.0 as usize)?))
            }
        }
    }

    fn block(&self, b: &Arc<Block>) -> Option<Reused> {
        let &(i, n, slot) = self.blocks.get(&b.id())?;
        let old = self.city.blocks.get(i)?;
        if !Arc::ptr_eq(old, b) && old != b {
            return None;
        }
        let leaf = self.leaf(n, slot)?;
        if let Some(f) = self.same_blocks.get(i) {
            f.store(true, Ordering::Relaxed);
        }
        Some(leaf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `lend` takes the `k`-th building node for building `k` only when its id says so:
    /// with the buildings listed in the opposite order to their nodes, each building
    /// still gets the node named after it.
    #[test]
    fn lend_finds_building_nodes_out_of_order() {
        let mut config = CityConfig::preset("milan").unwrap();
        config.size_m = 900.0;
        let mut city = crate::generate(&config).unwrap();
        assert!(
            city.buildings.len() > 20,
            "{} buildings",
            city.buildings.len()
        );
        city.buildings.reverse();
        city.building_cells.reverse();
        city.dresses.reverse();
        let before: Vec<String> = city.scene.nodes.iter().map(|n| n.name.clone()).collect();
        let lent = OldScene::lend(&mut city);
        for (k, b) in city.buildings.iter().enumerate() {
            let (node, slot) = lent.buildings[k].expect("every building has a node");
            assert_eq!(
                before[node.0 as usize],
                crate::scene::building_node_name(b.id)
            );
            assert_eq!(lent.names[slot].0, before[node.0 as usize]);
            assert_eq!(lent.named[slot], node);
        }
    }
}
