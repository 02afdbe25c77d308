//! [`RTreeIndex`]: an R*-tree backend (the `rstar` crate), kept for comparison.

use std::collections::HashMap;

use rstar::{AABB, RTree, RTreeObject};

use super::grid::FxBuild;
use super::{IndexKey, Shape, SpatialIndex};
use crate::bbox::Aabb2;
use crate::error::GeomError;

#[derive(Debug, Clone)]
struct Entry<K> {
    key: K,
    shape: Shape,
}

impl<K> PartialEq for Entry<K>
where
    K: PartialEq,
{
    fn eq(&self, other: &Self) -> bool {
        self.key == other.key
    }
}

fn envelope(b: &Aabb2) -> AABB<[f64; 2]> {
    AABB::from_corners([b.min.x, b.min.y], [b.max.x, b.max.y])
}

impl<K> RTreeObject for Entry<K> {
    type Envelope = AABB<[f64; 2]>;
    fn envelope(&self) -> Self::Envelope {
        envelope(&self.shape.bbox())
    }
}

/// A spatial index on an R*-tree (`rstar`), with the same exact answers as
/// [`GridIndex`](super::GridIndex). Adapts to any distribution of sizes and densities, but
/// was slower on road-like data (see the [module docs](super)).
#[derive(Debug, Clone)]
pub struct RTreeIndex<K> {
    tree: RTree<Entry<K>>,
    lookup: HashMap<K, Shape, FxBuild>,
}

impl<K: IndexKey> Default for RTreeIndex<K> {
    fn default() -> Self {
        RTreeIndex {
            tree: RTree::new(),
            lookup: HashMap::default(),
        }
    }
}

impl<K: IndexKey> RTreeIndex<K> {
    /// An empty index.
    pub fn new() -> Self {
        Self::default()
    }

    /// Builds an index from many shapes at once (bulk loading gives a better tree than
    /// repeated insertion). Later entries replace earlier ones with the same key.
    ///
    /// # Errors
    /// As [`SpatialIndex::insert`]: the first bad coordinate.
    pub fn bulk_load(items: impl IntoIterator<Item = (K, Shape)>) -> Result<Self, GeomError> {
        let mut lookup: HashMap<K, Shape, FxBuild> = HashMap::default();
        let mut keys = Vec::new();
        for (k, s) in items {
            s.validate()?;
            if lookup.insert(k, s).is_none() {
                keys.push(k);
            }
        }
        let entries = keys
            .into_iter()
            .filter_map(|key| lookup.get(&key).map(|&shape| Entry { key, shape }))
            .collect();
        Ok(RTreeIndex {
            tree: RTree::bulk_load(entries),
            lookup,
        })
    }
}

impl<K: IndexKey> SpatialIndex<K> for RTreeIndex<K> {
    fn insert(&mut self, key: K, shape: Shape) -> Result<Option<Shape>, GeomError> {
        shape.validate()?;
        let old = self.remove(key);
        self.tree.insert(Entry { key, shape });
        self.lookup.insert(key, shape);
        Ok(old)
    }

    fn remove(&mut self, key: K) -> Option<Shape> {
        let shape = self.lookup.remove(&key)?;
        self.tree.remove(&Entry { key, shape });
        Some(shape)
    }

    fn get(&self, key: K) -> Option<Shape> {
        self.lookup.get(&key).copied()
    }

    fn len(&self) -> usize {
        self.lookup.len()
    }

    fn clear(&mut self) {
        *self = Self::default();
    }

    fn for_each_candidate<F: FnMut(K, &Shape)>(&self, b: &Aabb2, mut f: F) {
        if b.is_empty() {
            return;
        }
        for e in self.tree.locate_in_envelope_intersecting(envelope(b)) {
            f(e.key, &e.shape);
        }
    }
}
