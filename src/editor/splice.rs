//! Splicing the scene: after an edit the 3-D scene is assembled again, but every cell
//! (a road-graph cell: the `cell <id>` node with its blocks and buildings) whose inputs
//! are those of the city before the edit takes its whole subtree from the earlier scene
//! instead of being meshed again (Kelly §6.7: each cell batches its own geometry, so an
//! edit touches only its cells' batches). [`assemble`](crate::scene::assemble) lays
//! each cell's subtree out as one run of nodes and one run of meshes, so a cell handed
//! back is a move of those two runs, renumbered, not a look-up per leaf.
//!
//! A cell is reused when the scene-wide inputs are unchanged ([`scene_key`]: the
//! configuration but for the Citygen edits, which reach the scene only through the
//! layers; the pinned facade styles, which decide the palette) and its own inputs are
//! equal: the same blocks, and the same buildings (every part and facade) with the same
//! skins, in the same order. Roads graded into an elevation map move the ground every
//! leaf stands on, so with grading on nothing is reused. The scene so made is the scene
//! `assemble` would make: reuse only skips recomputing identical parts. A cell with any
//! change has every leaf made again.

use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use polis_geom::Mesh;
use polis_geom::scene::{MeshId, Node, NodeId, Scene};

use super::key::{IdBits, IdMap, Key};
use super::memo::Memo;
use crate::City;
use crate::CityConfig;
use crate::error::Result;
use crate::scene::{CellItems, SceneReuse};

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

/// The scene of a city before an edit, indexed for reuse by cell. Its nodes and meshes
/// are moved out of the city into one store, and a cell handed back whole moves its run
/// of nodes and meshes from there into the new scene (renumbered) rather than copying
/// them: the city before the edit is dropped when the edit succeeds, and what it lent is
/// put back ([`OldScene::restore`], which first lets go of the scene's own reference to
/// the city) when it fails.
pub(super) struct OldScene {
    city: Arc<City>,
    /// The city's scene nodes and meshes, moved out of it; a taken cell's are left
    /// empty.
    tree: Mutex<Tree>,
    /// Per cell id: its subtree's runs and its items in the city.
    cells: IdMap<OldCell>,
    /// The editor's memo: which buildings and skins were made from the same keys as
    /// the old city's (equal without comparing them).
    memo: Arc<Memo>,
    /// Whether a cell was taken (what was lent can no longer be put back whole).
    taken: AtomicBool,
    /// Per old building (by index in the city's buildings): its cell was handed back
    /// whole, so it is equal to the new one; the change events need not compare it.
    same_buildings: Vec<AtomicBool>,
    /// Per old block (by index): the same, for blocks.
    same_blocks: Vec<AtomicBool>,
}

/// A scene's nodes and meshes.
#[derive(Default)]
struct Tree {
    nodes: Vec<Node>,
    meshes: Vec<Mesh>,
}

/// One cell of the old scene: the run of nodes (its node first) and the run of meshes
/// of its subtree, and its blocks and buildings by index in the city, in order.
struct OldCell {
    nodes: Range<usize>,
    meshes: Range<usize>,
    blocks: Vec<usize>,
    buildings: Vec<usize>,
}

/// What [`OldScene::lend`] moved out of a city: its scene's nodes and meshes, with the
/// cells' index.
pub(super) struct Lent {
    tree: Tree,
    cells: IdMap<OldCell>,
}

/// The runs of nodes and meshes of the subtree at `top`, if each is one run and the
/// subtree's nodes and meshes are used by it alone (as [`assemble`] lays a cell out);
/// `used` is scratch.
///
/// [`assemble`]: crate::scene::assemble
fn subtree(
    nodes: &[Node],
    top: usize,
    used: &mut Vec<bool>,
) -> Option<(Range<usize>, Range<usize>)> {
    let (mut n_count, mut n_max) = (0usize, top);
    let (mut m_count, mut m_min, mut m_max) = (0usize, usize::MAX, 0usize);
    let mut stack = vec![top];
    while let Some(n) = stack.pop() {
        let node = nodes.get(n)?;
        n_count += 1;
        // More visits than nodes: not a tree (a cycle); not indexed.
        if n_count > nodes.len() {
            return None;
        }
        n_max = n_max.max(n);
        for c in &node.children {
            if c.index() <= top {
                return None;
            }
            stack.push(c.index());
        }
        for m in &node.meshes {
            m_count += 1;
            m_min = m_min.min(m.index());
            m_max = m_max.max(m.index());
        }
    }
    if n_max + 1 - top != n_count {
        return None;
    }
    let meshes = if m_count == 0 {
        0..0
    } else {
        if m_max + 1 - m_min != m_count {
            return None;
        }
        // Each mesh of the run used once.
        used.clear();
        used.resize(m_count, false);
        for node in nodes.get(top..=n_max)? {
            for m in &node.meshes {
                let seen = used.get_mut(m.index() - m_min)?;
                if *seen {
                    return None;
                }
                *seen = true;
            }
        }
        m_min..m_max + 1
    };
    Some((top..n_max + 1, meshes))
}

/// `n` flags, all down.
fn flags(n: usize) -> Vec<AtomicBool> {
    (0..n).map(|_| AtomicBool::new(false)).collect()
}

impl OldScene {
    /// Indexes `city`'s scene by cell (each `cell <id>` child of the root whose subtree
    /// is one run of nodes and one of meshes) and moves its nodes and meshes out of it.
    pub(super) fn lend(city: &mut City) -> Lent {
        let scene = &city.scene;
        let mut by_cell: IdMap<(Vec<usize>, Vec<usize>)> =
            IdMap::with_capacity_and_hasher(city.cells.cells.len(), IdBits);
        for (i, b) in city.blocks.iter().enumerate() {
            by_cell.entry(b.cell_id).or_default().0.push(i);
        }
        for (i, &c) in city
            .building_cells
            .iter()
            .enumerate()
            .take(city.buildings.len())
        {
            by_cell.entry(c).or_default().1.push(i);
        }
        let mut cells = IdMap::with_capacity_and_hasher(by_cell.len(), IdBits);
        let mut used = Vec::new();
        for root in &scene.roots {
            let Some(root) = scene.nodes.get(root.index()) else {
                continue;
            };
            for top in &root.children {
                let Some(node) = scene.nodes.get(top.index()) else {
                    continue;
                };
                let Some(id) = crate::scene::node_id(&node.name, "cell") else {
                    continue;
                };
                let Some((nodes, meshes)) = subtree(&scene.nodes, top.index(), &mut used) else {
                    continue;
                };
                let (blocks, buildings) = by_cell.remove(&id).unwrap_or_default();
                cells.insert(
                    id,
                    OldCell {
                        nodes,
                        meshes,
                        blocks,
                        buildings,
                    },
                );
            }
        }
        Lent {
            tree: Tree {
                nodes: std::mem::take(&mut city.scene.nodes),
                meshes: std::mem::take(&mut city.scene.meshes),
            },
            cells,
        }
    }

    /// The scene of `city` from what [`lend`](Self::lend) moved out of it.
    pub(super) fn new(city: Arc<City>, lent: Lent, memo: Arc<Memo>) -> Self {
        OldScene {
            tree: Mutex::new(lent.tree),
            cells: lent.cells,
            memo,
            taken: AtomicBool::new(false),
            same_buildings: flags(city.buildings.len()),
            same_blocks: flags(city.blocks.len()),
            city,
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

    /// Puts what `city` lent back into it, if no cell took any of it (the edit failed
    /// before the scene was assembled); returns whether it did. This scene's own
    /// reference to the city is released first, so that `city` can be written to when
    /// the caller holds the only other one. On `false` the city may lack what was lent
    /// and must be made again.
    pub(super) fn restore(self, city: &mut Arc<City>) -> bool {
        let OldScene {
            city: lent_by,
            tree,
            taken,
            ..
        } = self;
        drop(lent_by);
        if taken.into_inner() {
            return false;
        }
        let tree = tree.into_inner().unwrap_or_else(PoisonError::into_inner);
        let Some(city) = Arc::get_mut(city) else {
            return false;
        };
        city.scene.nodes = tree.nodes;
        city.scene.meshes = tree.meshes;
        true
    }
}

impl SceneReuse for OldScene {
    fn whole_cell(&self, cell: u64, items: &CellItems<'_>) -> Option<(usize, usize)> {
        let old = self.cells.get(&cell)?;
        if old.blocks.len() != items.blocks.len() || old.buildings.len() != items.buildings.len() {
            return None;
        }
        let city = &self.city;
        let blocks = old.blocks.iter().zip(&items.blocks).all(|(&i, b)| {
            city.blocks
                .get(i)
                .is_some_and(|o| Arc::ptr_eq(o, b) || **o == ***b)
        });
        let same = blocks
            && old
                .buildings
                .iter()
                .zip(&items.buildings)
                .all(|(&i, (b, dress))| {
                    let Some(o) = city.buildings.get(i) else {
                        return false;
                    };
                    let old_dress = city.dresses.get(i).and_then(Option::as_ref);
                    // The same building and skin (shared with the old city, which is how
                    // the memo hands reused ones out), or made from the same keys: equal;
                    // otherwise compared in full.
                    let shared = Arc::ptr_eq(o, b)
                        && match (old_dress, dress) {
                            (Some(x), Some(y)) => Arc::ptr_eq(x, y),
                            (None, None) => true,
                            _ => false,
                        };
                    shared
                        || (o.id == b.id
                            && match self.memo.same_keys(b.id) {
                                Some(same) => same,
                                None => {
                                    **o == ***b && old_dress.map(|d| &**d) == dress.map(|d| &**d)
                                }
                            })
                });
        same.then(|| (old.nodes.len(), old.meshes.len()))
    }

    fn take_cell(&self, cell: u64, scene: &mut Scene, parent: NodeId) -> Result<bool> {
        let Some(old) = self.cells.get(&cell) else {
            return Ok(false);
        };
        scene.node(parent)?;
        let mut tree = self.tree.lock().unwrap_or_else(PoisonError::into_inner);
        let Tree { nodes, meshes } = &mut *tree;
        let (Some(taken_nodes), Some(taken_meshes)) = (
            nodes.get_mut(old.nodes.clone()),
            meshes.get_mut(old.meshes.clone()),
        ) else {
            return Ok(false);
        };
        // A cell is taken at most once (ids are unique): its nodes are all there.
        if taken_nodes.first().is_none_or(|n| n.name.is_empty()) {
            return Ok(false);
        }
        self.taken.store(true, Ordering::Relaxed);
        let top = scene.nodes.len();
        let node_shift = |n: NodeId| NodeId((n.index() - old.nodes.start + top) as u32);
        let first_mesh = scene.meshes.len();
        let mesh_shift = |m: MeshId| MeshId((m.index() - old.meshes.start + first_mesh) as u32);
        scene.nodes.extend(taken_nodes.iter_mut().map(|n| {
            let mut n = std::mem::take(n);
            for c in &mut n.children {
                *c = node_shift(*c);
            }
            for m in &mut n.meshes {
                *m = mesh_shift(*m);
            }
            n
        }));
        scene
            .meshes
            .extend(taken_meshes.iter_mut().map(std::mem::take));
        scene.node_mut(parent)?.children.push(NodeId(top as u32));
        for &i in &old.blocks {
            if let Some(f) = self.same_blocks.get(i) {
                f.store(true, Ordering::Relaxed);
            }
        }
        for &i in &old.buildings {
            if let Some(f) = self.same_buildings.get(i) {
                f.store(true, Ordering::Relaxed);
            }
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `lend` indexes every cell of a scene `assemble` made as one run of nodes (its
    /// node first) and one run of meshes, the runs of different cells apart.
    #[test]
    fn lend_indexes_every_cell_as_one_run() {
        let mut config = CityConfig::preset("milan").unwrap();
        config.size_m = 900.0;
        let mut city = crate::generate(&config).unwrap();
        let cells: std::collections::BTreeSet<u64> = city
            .blocks
            .iter()
            .map(|b| b.cell_id)
            .chain(city.building_cells.iter().copied())
            .collect();
        assert!(cells.len() > 3, "{} cells", cells.len());
        let (nodes, meshes) = (city.scene.nodes.len(), city.scene.meshes.len());
        let lent = OldScene::lend(&mut city);
        assert_eq!(lent.cells.len(), cells.len());
        assert_eq!(
            (lent.tree.nodes.len(), lent.tree.meshes.len()),
            (nodes, meshes)
        );
        let mut runs: Vec<(Range<usize>, Range<usize>)> = Vec::new();
        for (id, c) in &lent.cells {
            assert_eq!(lent.tree.nodes[c.nodes.start].name, format!("cell {id}"));
            assert_eq!(
                c.buildings.len() + c.blocks.len(),
                lent.tree.nodes[c.nodes.start].children.len()
            );
            runs.push((c.nodes.clone(), c.meshes.clone()));
        }
        runs.sort_by_key(|r| r.0.start);
        for w in runs.windows(2) {
            assert!(w[0].0.end <= w[1].0.start && w[0].1.end <= w[1].1.start);
        }
    }
}
