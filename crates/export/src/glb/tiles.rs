//! The tiled layout ([`Batching::Tiled`](super::Batching::Tiled)): geometry merged per
//! (root, layer, tile, LOD level, material), with a feature id per vertex.
//!
//! Rules, applied per scene root (each root keeps its own glTF node, transform and
//! metadata; everything below is expressed in the root's frame):
//!
//! * An **object** is a node that draws a non-empty mesh (the root itself included).
//! * Its **layer** is the nearest `layer` text entry in the metadata of the object or an
//!   ancestor below the root; without one, the name of its ancestor directly under the
//!   root (so a node `roads`, `water` or `ground` under the city is a layer by its name).
//! * Its **LOD level** is the nearest `lod` number (a whole number ≥ 0, higher = more
//!   detail) on the same path; without one it is drawn at every distance.
//! * Its **feature** is the nearest node on the path (the object or an ancestor below the
//!   root) whose metadata has an entry other than `layer` and `lod`: each such node is one
//!   record of the root's `extras.features` table (its `name`, `layer` and metadata), and
//!   the record's index is the `_FEATURE_ID_0` of every vertex it contributed. Geometry of
//!   no feature gets the table's length (`extras.null_feature_id`); a primitive with no
//!   feature at all has no `_FEATURE_ID_0`. The web profile writes the table by column
//!   ([`by_column`]).
//! * Its **tile** is the square of side `tile_size_m` on the root's x–z plane holding the
//!   centre of its bounding box, `(⌊x / s⌋, ⌊z / s⌋)`; an object wider or deeper than a
//!   tile (a layer-wide surface: the road network, water, ground) is cut instead, each
//!   of its meshes by [`Mesh::cut_into_tiles`] (each triangle going to the tile of its
//!   centroid). A mesh that is already one tile's cut ([`Mesh::whole_tile`]: a polis
//!   ground, cut into the scene's tiles where it is built) is appended whole, which
//!   gives the same bytes as cutting it again without the vertex map.
//! * A scene mesh's box and whether it is one tile's cut are read from its
//!   [`MeshSurvey`], taken by the pass that validates the scene ([`Scene::survey`]), so
//!   the plan reads a mesh's vertices once, when it copies them.

use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};

use polis_geom::glam::{DMat4, DVec3, Vec3};
use polis_geom::mesh::{MeshSurvey, TileIndex, tile_of};
use polis_geom::scene::{MaterialId, Node, NodeId, Scene};
use polis_geom::{Aabb3, Mesh};
use serde::ser::{Serialize, SerializeMap, Serializer};
use serde_json::value::RawValue;
use serde_json::{Map, Value, json};

use super::options::{GlbOptions, GlbProfile};
use super::plan::{FeatureIds, Gathered, Geometry, Plan, PlannedMesh, PlannedNode, Shape};
use crate::ExportError;

/// No feature yet (replaced by the table's length once it is known).
const NO_FEATURE: u32 = u32::MAX;

/// A tile index on the x–z plane.
type Tile = TileIndex;

/// Where a merge group sits: (layer, tile, LOD level).
type GroupKey = (usize, Tile, Option<u32>);

/// One piece of a merged geometry, recorded by the walk and copied by [`Merge::fill`].
struct Piece<'a> {
    /// The index of its merged geometry in [`Merge::targets`].
    target: usize,
    source: Source<'a>,
    /// Its feature record ([`NO_FEATURE`]: none).
    feature: u32,
}

/// Where a piece's vertices come from.
enum Source<'a> {
    /// A scene mesh, its positions moved by a translation (zero: copied as they are, a
    /// −0 kept; else each `p + t` in `f64`, as [`Mesh::transform`] moves them) and its
    /// normals copied (a translation turns none).
    Scene(&'a Mesh, DVec3),
    /// A mesh made by the walk (a transformed copy, a cut part): an index into
    /// [`Merge::owned`], copied as it is, or moved in when it is its geometry's only
    /// piece.
    Owned(usize),
}

/// The counted size and the bounds of one merged geometry.
struct Target {
    material: Option<MaterialId>,
    vertices: usize,
    indices: usize,
    pieces: usize,
    /// Whether any piece has a feature (else the primitive has no `_FEATURE_ID_0`).
    featured: bool,
    /// The union of the pieces' bounds, in walk order.
    bounds: Aabb3,
}

/// The merged geometries of one root, built in two passes: the walk records every
/// piece in order and counts each (layer, tile, LOD level, material) geometry's vertices
/// and indices; [`fill`](Self::fill) then hands each geometry its pieces (a
/// [`Gathered`] geometry: the scene's meshes borrowed, the walk's moved in), which the
/// writer streams piece by piece. No merged array is made (the web profile makes one per
/// geometry as it encodes it); the bytes are those of appending the pieces one by one.
#[derive(Default)]
struct Merge<'a> {
    groups: BTreeMap<GroupKey, BTreeMap<Option<MaterialId>, usize>>,
    targets: Vec<Target>,
    pieces: Vec<Piece<'a>>,
    owned: Vec<Option<Mesh>>,
}

/// The box `b` moved by `t`: the moved corners' box, exactly (rounding `x + t` to `f32`
/// is monotone in `x`; with `t = 0` the box itself, a −0 bound made +0).
fn moved_box(b: Aabb3, t: DVec3) -> Aabb3 {
    Aabb3 {
        min: (b.min.as_dvec3() + t).as_vec3(),
        max: (b.max.as_dvec3() + t).as_vec3(),
    }
}

/// A merged geometry: the mesh (the scene's own when it is the geometry's only piece,
/// unmoved), else its pieces; and, when any piece has a feature, the feature id of every
/// vertex.
type Merged<'a> = (Shape<'a>, Option<FeatureIds>);

/// The merged geometries of one group: (material, geometry, bounds) per material.
type GroupGeometries<'a> = Vec<(Option<MaterialId>, Merged<'a>, Aabb3)>;

impl<'a> Merge<'a> {
    /// Records `source`, a mesh `m` (bounds `bounds`, feature `feature`), as the next
    /// piece of the geometry of `key` and `material`.
    fn add(&mut self, key: GroupKey, m: &Mesh, source: Source<'a>, bounds: Aabb3, feature: u32) {
        let targets = &mut self.targets;
        let material = m.material;
        let target = *self
            .groups
            .entry(key)
            .or_default()
            .entry(material)
            .or_insert_with(|| {
                targets.push(Target {
                    material,
                    vertices: 0,
                    indices: 0,
                    pieces: 0,
                    featured: false,
                    bounds: Aabb3::EMPTY,
                });
                targets.len() - 1
            });
        let t = &mut targets[target];
        t.vertices += m.positions.len();
        t.indices += m.indices.len();
        t.pieces += 1;
        t.featured |= feature != NO_FEATURE;
        t.bounds = t.bounds.union(&bounds);
        self.pieces.push(Piece {
            target,
            source,
            feature,
        });
    }

    /// A scene mesh `m` with bounds `b`, moved by `t`.
    fn add_moved(&mut self, key: GroupKey, m: &'a Mesh, b: Aabb3, t: DVec3, feature: u32) {
        self.add(key, m, Source::Scene(m, t), moved_box(b, t), feature);
    }

    /// A mesh the walk made, with bounds `b`.
    fn add_owned(&mut self, key: GroupKey, m: Mesh, b: Aabb3, feature: u32) {
        let k = self.owned.len();
        self.add(key, &m, Source::Owned(k), b, feature);
        self.owned.push(Some(m));
    }

    /// The merged geometries, per group in key order and per material in order, with
    /// their bounds; a piece without a feature gets `null_id`. A geometry of several
    /// pieces (or one moved piece) is [gathered](Shape::Gathered): the pieces are kept,
    /// not copied, and the writer streams their arrays.
    fn fill(self, null_id: u32) -> Vec<(GroupKey, GroupGeometries<'a>)> {
        let Merge {
            groups,
            targets,
            pieces,
            mut owned,
        } = self;
        let mut merged: Vec<Option<Merged<'a>>> = targets.iter().map(|_| None).collect();
        for piece in pieces {
            let spec = &targets[piece.target];
            let feature = if piece.feature == NO_FEATURE {
                null_id
            } else {
                piece.feature
            };
            let (mesh, t) = match piece.source {
                Source::Scene(m, t) => (Cow::Borrowed(m), t),
                Source::Owned(k) => match owned[k].take() {
                    Some(m) => (Cow::Owned(m), DVec3::ZERO),
                    None => continue,
                },
            };
            let slot = &mut merged[piece.target];
            // A geometry of one unmoved piece is that piece (a mesh the walk made moved
            // in, a scene mesh borrowed): its material is the geometry's, its indices
            // start at 0.
            if spec.pieces == 1 && t == DVec3::ZERO {
                let ids = spec.featured.then(|| {
                    let mut ids = FeatureIds::with_capacity(1);
                    ids.push(feature, mesh.positions.len());
                    ids
                });
                *slot = Some((Shape::Whole(mesh), ids));
                continue;
            }
            let (shape, ids) = slot.get_or_insert_with(|| {
                (
                    Shape::Gathered(Gathered {
                        material: spec.material,
                        vertices: spec.vertices,
                        indices: spec.indices,
                        pieces: Vec::with_capacity(spec.pieces),
                    }),
                    spec.featured
                        .then(|| FeatureIds::with_capacity(spec.pieces)),
                )
            });
            if let Some(ids) = ids {
                ids.push(feature, mesh.positions.len());
            }
            if let Shape::Gathered(g) = shape {
                g.pieces.push((mesh, t));
            }
        }
        groups
            .into_iter()
            .map(|(key, by_material)| {
                let geometries = by_material
                    .into_iter()
                    .filter_map(|(material, t)| {
                        let m = merged[t].take()?;
                        Some((material, m, targets[t].bounds))
                    })
                    .collect();
                (key, geometries)
            })
            .collect()
    }
}

/// The layers of one root in first-seen order, with an index by name (a city root has
/// a layer name per cell, so a linear search per node would cost quadratic time).
#[derive(Default)]
struct Layers<'a> {
    names: Vec<String>,
    index: HashMap<&'a str, usize>,
}

impl<'a> Layers<'a> {
    /// The index of layer `name`, added when new.
    fn index(&mut self, name: &'a str) -> usize {
        *self.index.entry(name).or_insert_with(|| {
            self.names.push(name.to_string());
            self.names.len() - 1
        })
    }
}

/// What the walk down one root knows about the path to a node.
#[derive(Clone, Copy)]
struct PathInfo {
    layer: usize,
    lod: Option<u32>,
    /// The node whose record the path's geometry belongs to, and that node's layer.
    feature: Option<(NodeId, usize)>,
}

/// One record of a root's feature table: its node's name, its layer and the node's
/// metadata less any `name` and `layer` entry, keys in sorted order (the order of a
/// `serde_json::Map`), serialized from the scene without building JSON values.
struct Record<'s> {
    node: &'s Node,
    layer: &'s str,
}

impl Serialize for Record<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        // The metadata iterates in key order: `layer` and `name` go in where they sort.
        let fixed = [("layer", self.layer), ("name", self.node.name.as_str())];
        let mut next = 0;
        let mut map = s.serialize_map(None)?;
        for (k, v) in self.node.metadata.iter() {
            while let Some(&(f, text)) = fixed.get(next)
                && f < k
            {
                map.serialize_entry(f, text)?;
                next += 1;
            }
            if k != "layer" && k != "name" {
                map.serialize_entry(k, v)?;
            }
        }
        for &(f, text) in fixed.get(next..).unwrap_or_default() {
            map.serialize_entry(f, text)?;
        }
        map.end()
    }
}

/// A root's feature table, each record written when its node is met (its metadata
/// then at hand): in the plain profile as JSON text (no JSON values built and dropped),
/// in the web profile as values for [`by_column`].
enum Table {
    Rows(Vec<Box<RawValue>>),
    Values(Vec<Value>),
}

impl Table {
    fn new(profile: GlbProfile) -> Self {
        match profile {
            GlbProfile::Plain => Table::Rows(Vec::new()),
            GlbProfile::Web => Table::Values(Vec::new()),
        }
    }

    /// Adds `record`; returns its index.
    fn push(&mut self, record: Record<'_>) -> Result<u32, ExportError> {
        let error = ExportError::json("extras");
        let len = match self {
            Table::Rows(rows) => {
                rows.push(serde_json::value::to_raw_value(&record).map_err(error)?);
                rows.len()
            }
            Table::Values(values) => {
                values.push(serde_json::to_value(record).map_err(error)?);
                values.len()
            }
        };
        Ok(len as u32 - 1)
    }

    fn len(&self) -> usize {
        match self {
            Table::Rows(rows) => rows.len(),
            Table::Values(values) => values.len(),
        }
    }
}

/// The translation of `frame` when it only moves (its linear part is the identity).
fn translation_only(frame: &DMat4) -> Option<DVec3> {
    let linear = polis_geom::glam::DMat3::from_mat4(*frame);
    (linear == polis_geom::glam::DMat3::IDENTITY
        && frame.row(3) == polis_geom::glam::DVec4::W
        && frame.w_axis.is_finite())
    .then(|| frame.w_axis.truncate())
}

/// The layout described in the [module docs](self).
///
/// `surveys` are the scene's mesh surveys ([`Scene::survey`], one per mesh in order):
/// a scene mesh's box and its tile facts are read from there, not from its positions.
pub(crate) fn tiled<'a>(
    scene: &'a Scene,
    surveys: &[MeshSurvey],
    options: &GlbOptions,
) -> Result<Plan<'a>, ExportError> {
    let size = options.tile_size_m;
    let mut plan = Plan::empty();
    let mut used = vec![false; scene.meshes.len()];
    for &root in &scene.roots {
        let root_index = plan.nodes.len() as u32;
        plan.roots.push(root_index);
        plan.nodes.push(PlannedNode::from_scene(root));

        // Walk the subtree in pre-order: objects, their frame, path info.
        let mut layer_set = Layers::default();
        let mut features = Table::new(options.profile);
        let mut record_of: BTreeMap<NodeId, u32> = BTreeMap::new();
        let mut merge = Merge::default();
        let mut levels: Vec<u32> = Vec::new();
        let mut stack: Vec<(NodeId, DMat4, Option<PathInfo>)> = vec![(root, DMat4::IDENTITY, None)];
        while let Some((id, frame, path)) = stack.pop() {
            let node = &scene.nodes[id.index()];
            let is_root = id == root;
            // One pass over the metadata (a building has a dozen entries): its layer,
            // its LOD level and whether it has any other entry (then it is a feature).
            let (mut layer_name, mut lod_value, mut own_feature) = (None, None, false);
            for (k, v) in node.metadata.iter() {
                match k {
                    "layer" => layer_name = v.as_str(),
                    "lod" => lod_value = v.as_f64(),
                    _ => own_feature = true,
                }
            }
            let info = if is_root {
                None
            } else {
                let inherited = path;
                let layer = match (layer_name, inherited) {
                    (Some(name), _) => layer_set.index(name),
                    (None, Some(p)) => p.layer,
                    (None, None) => layer_set.index(&node.name),
                };
                let lod = match lod_value {
                    Some(l) if l >= 0.0 && l.fract() == 0.0 && l <= f64::from(u16::MAX) => {
                        Some(l as u32)
                    }
                    Some(l) => {
                        return Err(ExportError::InvalidOption {
                            name: "lod",
                            reason: format!(
                                "node {} ({:?}) has lod {l}; give a whole number from 0",
                                id.0, node.name
                            ),
                        });
                    }
                    None => inherited.and_then(|p| p.lod),
                };
                let feature = if own_feature {
                    Some((id, layer))
                } else {
                    inherited.and_then(|p| p.feature)
                };
                if let Some(l) = lod
                    && !levels.contains(&l)
                {
                    levels.push(l);
                }
                Some(PathInfo {
                    layer,
                    lod,
                    feature,
                })
            };
            for &c in node.children.iter().rev() {
                let m = frame * scene.nodes[c.index()].transform.matrix();
                stack.push((c, m, info));
            }
            let drawn: Vec<(&Mesh, &MeshSurvey)> = node
                .meshes
                .iter()
                .filter_map(|m| {
                    let mesh = scene.meshes.get(m.index())?;
                    let survey = surveys.get(m.index())?;
                    used[m.index()] = true;
                    (!mesh.is_empty()).then_some((mesh, survey))
                })
                .collect();
            if drawn.is_empty() {
                continue;
            }
            let info = match info {
                Some(i) => i,
                None => {
                    // Geometry on the root itself: a layer named after the root.
                    PathInfo {
                        layer: layer_set.index(&node.name),
                        lod: None,
                        feature: None,
                    }
                }
            };
            // The record of the feature, made when its first geometry is met.
            let feature = match info.feature {
                None => NO_FEATURE,
                Some((owner, layer)) => match record_of.get(&owner) {
                    Some(&k) => k,
                    None => {
                        let k = features.push(Record {
                            node: &scene.nodes[owner.index()],
                            layer: &layer_set.names[layer],
                        })?;
                        record_of.insert(owner, k);
                        k
                    }
                },
            };
            // A frame that only moves (the usual building or block under its cell):
            // vertices are moved while they are copied, without a transformed copy.
            let shift = translation_only(&frame);
            if let Some(t) = shift {
                let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
                for (_, s) in &drawn {
                    lo = lo.min(s.bounds.min.as_dvec3() + t);
                    hi = hi.max(s.bounds.max.as_dvec3() + t);
                }
                if hi.x - lo.x <= size && hi.z - lo.z <= size {
                    let c = ((lo + hi) * 0.5).as_vec3();
                    let key = (info.layer, tile_of(c.x, c.z, size), info.lod);
                    for (m, s) in drawn {
                        merge.add_moved(key, m, s.bounds, t, feature);
                    }
                    continue;
                }
            }
            // Each mesh in the root's frame with its box and, when it is the scene's
            // own, its survey (a transformed copy has none).
            type Placed<'m, 's> = (Cow<'m, Mesh>, Aabb3, Option<&'s MeshSurvey>);
            let placed: Vec<Placed<'a, '_>> = if frame == DMat4::IDENTITY {
                drawn
                    .into_iter()
                    .map(|(m, s)| (Cow::Borrowed(m), s.bounds, Some(s)))
                    .collect()
            } else {
                let mut out = Vec::with_capacity(drawn.len());
                for (m, _) in drawn {
                    let mut m = m.clone();
                    m.transform(&frame)?;
                    let b = m.bbox();
                    out.push((Cow::Owned(m), b, None));
                }
                out
            };
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for (_, b, _) in &placed {
                lo = lo.min(b.min);
                hi = hi.max(b.max);
            }
            let whole = f64::from(hi.x - lo.x) <= size && f64::from(hi.z - lo.z) <= size;
            for (m, b, survey) in placed {
                // Whole (its box moved by zero: a −0 bound made +0), already one
                // tile's cut (the ground, cut where it is built: the bytes its cut would
                // give, its box too, −0 kept), or cut into tiles by triangle centroids.
                let one_tile = || match survey {
                    Some(s) => s.whole_tile(size),
                    None => m.whole_tile(size),
                };
                let (key, b) = if whole {
                    let c = (lo + hi) * 0.5;
                    let key = (info.layer, tile_of(c.x, c.z, size), info.lod);
                    (key, moved_box(b, DVec3::ZERO))
                } else if let Some(tile) = one_tile() {
                    ((info.layer, tile, info.lod), b)
                } else {
                    for (tile, part, b) in m.cut_into_tiles(size) {
                        merge.add_owned((info.layer, tile, info.lod), part, b, feature);
                    }
                    continue;
                };
                match m {
                    Cow::Borrowed(m) => {
                        merge.add(key, m, Source::Scene(m, DVec3::ZERO), b, feature)
                    }
                    Cow::Owned(m) => merge.add_owned(key, m, b, feature),
                }
            }
        }

        // Nodes: root → layers (first-seen order) → tiles (sorted) → LOD levels.
        let layers = layer_set.names;
        levels.sort_unstable_by(|a, b| b.cmp(a));
        let null_id = features.len() as u32;
        let mut layer_nodes: Vec<Option<u32>> = vec![None; layers.len()];
        let mut tile_nodes: BTreeMap<(usize, Tile), u32> = BTreeMap::new();
        for ((layer, tile, lod), group) in merge.fill(null_id) {
            let layer_node = match layer_nodes[layer] {
                Some(n) => n,
                None => {
                    let n = plan.nodes.len() as u32;
                    plan.nodes.push(PlannedNode::synthetic(
                        layers[layer].clone(),
                        json!({ "layer": layers[layer] }),
                    ));
                    plan.nodes[root_index as usize].children.push(n);
                    layer_nodes[layer] = Some(n);
                    n
                }
            };
            let tile_node = match tile_nodes.get(&(layer, tile)) {
                Some(&n) => n,
                None => {
                    let n = plan.nodes.len() as u32;
                    let (x, z) = (tile.0 as f64 * size, tile.1 as f64 * size);
                    plan.nodes.push(PlannedNode::synthetic(
                        format!("{} {},{}", layers[layer], tile.0, tile.1),
                        json!({
                            "layer": layers[layer],
                            "tile": [tile.0, tile.1],
                            "tile_bounds_m": [x, z, x + size, z + size],
                        }),
                    ));
                    plan.nodes[layer_node as usize].children.push(n);
                    tile_nodes.insert((layer, tile), n);
                    n
                }
            };
            let mut primitives = Vec::with_capacity(group.len());
            for (material, (mesh, features), bounds) in group {
                primitives.push((plan.geometries.len(), material));
                plan.geometries.push(Geometry {
                    mesh,
                    features,
                    bounds: Some(bounds),
                });
            }
            let tile_name = format!("{} {},{}", layers[layer], tile.0, tile.1);
            let mesh = plan.meshes.len();
            match lod {
                None => {
                    plan.meshes.push(PlannedMesh {
                        name: tile_name,
                        primitives,
                        objects: Vec::new(),
                    });
                    plan.nodes[tile_node as usize].mesh = Some(mesh);
                }
                Some(level) => {
                    let rank = levels.iter().position(|&l| l == level).unwrap_or(0);
                    let near = options.lod_near_m;
                    let from = if rank == 0 {
                        0.0
                    } else {
                        near * f64::from(1u32 << (rank - 1).min(30))
                    };
                    let to =
                        (rank + 1 < levels.len()).then(|| near * f64::from(1u32 << rank.min(30)));
                    let name = format!("{tile_name} lod {level}");
                    plan.meshes.push(PlannedMesh {
                        name: name.clone(),
                        primitives,
                        objects: Vec::new(),
                    });
                    let n = plan.nodes.len() as u32;
                    let mut node = PlannedNode::synthetic(
                        name,
                        json!({ "lod": level, "lod_range_m": [from, to] }),
                    );
                    node.mesh = Some(mesh);
                    plan.nodes.push(node);
                    plan.nodes[tile_node as usize].children.push(n);
                }
            }
        }
        plan.tiles += tile_nodes.len();
        let mut extras = Map::new();
        extras.insert("feature_id_attribute".into(), json!("_FEATURE_ID_0"));
        extras.insert("null_feature_id".into(), json!(null_id));
        extras.insert("tile_size_m".into(), json!(size));
        if !levels.is_empty() {
            extras.insert("lod_levels".into(), json!(levels));
        }
        // The layers that have a node: a node directly under the root that has no
        // `layer` entry names a layer only if geometry falls in it (a city's cells,
        // whose buildings and blocks name their own layers, are none).
        let named: Vec<&str> = layers
            .iter()
            .zip(&layer_nodes)
            .filter(|(_, node)| node.is_some())
            .map(|(name, _)| name.as_str())
            .collect();
        extras.insert("layers".into(), json!(named));
        plan.features += features.len();
        match features {
            Table::Rows(rows) => {
                let root_node = &mut plan.nodes[root_index as usize];
                root_node.extras = Some(extras);
                root_node.raw_extras.push(("features", rows));
            }
            Table::Values(values) => {
                extras.insert("features".into(), by_column(values));
                plan.nodes[root_index as usize].extras = Some(extras);
            }
        }
    }
    plan.count_meshes(scene, &used);
    Ok(plan)
}

/// The feature records as one column per key (the web profile's table): an object of
/// arrays as long as the table, keys in sorted order, `null` where a record lacks the
/// key; a whole number below 2^53 is written without its fraction (`416`, not `416.0`).
/// Record `i` is `{k: columns[k][i]}` less its nulls. The key names, written once
/// instead of once per record, are most of what this saves (a third of a city's table).
fn by_column(records: Vec<Value>) -> Value {
    let n = records.len();
    let mut columns: BTreeMap<String, Vec<Value>> = BTreeMap::new();
    for (i, record) in records.into_iter().enumerate() {
        let Value::Object(fields) = record else {
            continue;
        };
        for (k, v) in fields {
            let column = columns.entry(k).or_insert_with(|| vec![Value::Null; n]);
            column[i] = compact_number(v);
        }
    }
    Value::Object(
        columns
            .into_iter()
            .map(|(k, v)| (k, Value::Array(v)))
            .collect(),
    )
}

/// A whole `f64` below 2^53 as an integer; anything else unchanged.
fn compact_number(v: Value) -> Value {
    const EXACT: f64 = 9_007_199_254_740_992.0; // 2^53
    match v.as_f64() {
        Some(x) if v.is_f64() && x.fract() == 0.0 && x.abs() < EXACT => Value::from(x as i64),
        _ => v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::glam::Vec2;
    use polis_geom::scene::MetaValue;
    use proptest::prelude::*;

    /// A strip of `n` triangles with coordinates from `seed` (a −0 among them), with or
    /// without texture coordinates.
    fn strip(seed: u64, n: usize, material: Option<MaterialId>, uvs: bool) -> Mesh {
        let mut m = Mesh::new(material);
        for k in 0..n + 2 {
            let h = polis_geom::hash::splitmix64(seed ^ k as u64);
            let x = (h % 1000) as f32 * 0.37 - 180.0;
            let z = if k == 0 {
                -0.0
            } else {
                ((h >> 20) % 1000) as f32 * 0.41
            };
            m.positions.push(Vec3::new(x, (k % 3) as f32, z));
            m.normals.push(Vec3::Y);
            if uvs {
                m.uvs.push(Vec2::new(x, z));
            }
        }
        for k in 0..n as u32 {
            m.indices.extend([k, k + 1, k + 2]);
        }
        m
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// A record written as text is the JSON object of its name, its layer and the
        /// node's other metadata (a `name` or `layer` entry of the node replaced), keys
        /// sorted, byte for byte; the web profile's value is that object.
        #[test]
        fn a_record_is_the_sorted_object_of_name_layer_and_metadata(
            entries in proptest::collection::vec(
                (
                    prop_oneof![
                        Just("name".to_string()),
                        Just("layer".to_string()),
                        Just("lod".to_string()),
                        "[a-z_]{0,6}",
                    ],
                    prop_oneof![
                        "[ -~é\n]{0,8}".prop_map(MetaValue::from),
                        any::<f64>().prop_map(MetaValue::from),
                        any::<bool>().prop_map(MetaValue::from),
                    ],
                ),
                0..12,
            ),
            name in "[ -~é]{0,8}",
            layer in "[a-z]{1,8}",
        ) {
            let mut node = Node::new(name.clone());
            for (k, v) in entries {
                node.metadata.insert(k, v);
            }
            let mut expect = Map::new();
            expect.insert("name".into(), Value::from(name.as_str()));
            expect.insert("layer".into(), Value::from(layer.as_str()));
            for (k, v) in node.metadata.iter() {
                if k != "name" && k != "layer" {
                    expect.insert(k.to_string(), serde_json::to_value(v).unwrap());
                }
            }
            let record = Record { node: &node, layer: &layer };
            let text = serde_json::value::to_raw_value(&record).unwrap();
            prop_assert_eq!(text.get(), serde_json::to_string(&expect).unwrap());
            let mut table = Table::new(GlbProfile::Web);
            prop_assert_eq!(table.push(record).unwrap(), 0);
            let Table::Values(values) = table else {
                unreachable!("the web profile's table holds values");
            };
            prop_assert_eq!(&values[0], &Value::Object(expect));
        }

        /// The merge gives, per geometry, what appending its pieces one by one in walk
        /// order gives (positions moved in `f64`, feature ids with the null id where a
        /// piece has none, the union of the pieces' bounds), and every array it copies
        /// into is allocated once at its final size.
        #[test]
        fn fill_appends_the_pieces_in_order_into_arrays_sized_once(
            pieces in proptest::collection::vec(
                (0usize..3, 0u32..2, 0u8..3, (-500.0f64..500.0, -500.0f64..500.0), 1usize..6, any::<bool>()),
                1..40,
            ),
        ) {
            let scene: Vec<Mesh> = pieces
                .iter()
                .enumerate()
                .map(|(i, &(_, material, _, _, n, _))| {
                    strip(i as u64, n, Some(MaterialId(material)), material == 0)
                })
                .collect();
            let null_id = 99;
            let mut merge = Merge::default();
            // Per geometry: the mesh, feature ids and bounds of appending one by one,
            // and the number of pieces.
            type Expected = (Mesh, Vec<u32>, Aabb3, usize);
            let mut expect: BTreeMap<(GroupKey, Option<MaterialId>), Expected> = BTreeMap::new();
            for (i, &(k, _, kind, (x, z), _, featured)) in pieces.iter().enumerate() {
                let key = (k, (k as i64, 0), None);
                let m = &scene[i];
                let feature = if featured { i as u32 } else { NO_FEATURE };
                let (t, bounds) = match kind {
                    // Moved (a translation), as it is, or a mesh the walk made.
                    0 => (DVec3::new(x, 1.5, z), moved_box(m.bbox(), DVec3::new(x, 1.5, z))),
                    _ => (DVec3::ZERO, m.bbox()),
                };
                match kind {
                    0 => merge.add_moved(key, m, m.bbox(), t, feature),
                    1 => merge.add(key, m, Source::Scene(m, DVec3::ZERO), bounds, feature),
                    _ => merge.add_owned(key, m.clone(), bounds, feature),
                }
                let mut moved = m.clone();
                for p in &mut moved.positions {
                    if t != DVec3::ZERO {
                        *p = (p.as_dvec3() + t).as_vec3();
                    }
                }
                let e = expect
                    .entry((key, m.material))
                    .or_insert_with(|| (Mesh::new(m.material), Vec::new(), Aabb3::EMPTY, 0));
                e.0.append(&moved);
                let id = if featured { i as u32 } else { null_id };
                e.1.extend(std::iter::repeat_n(id, m.positions.len()));
                e.2 = e.2.union(&bounds);
                e.3 += 1;
            }
            let mut got = BTreeMap::new();
            for (key, geometries) in merge.fill(null_id) {
                for (material, (mesh, ids), bounds) in geometries {
                    prop_assert_eq!(mesh.material(), material);
                    got.insert((key, material), (mesh, ids, bounds));
                }
            }
            prop_assert_eq!(got.len(), expect.len());
            for (k, (mesh, ids, bounds, count)) in expect {
                let (g_mesh, g_ids, g_bounds) = &got[&k];
                prop_assert_eq!(&*g_mesh.to_mesh(), &mesh);
                prop_assert_eq!(g_bounds, &bounds);
                match g_ids {
                    Some(g) => {
                        prop_assert_eq!(g.to_vec(), ids.clone());
                        prop_assert_eq!(g.max(), ids.iter().copied().max().unwrap_or(0));
                    }
                    None => prop_assert!(ids.iter().all(|&f| f == null_id)),
                }
                // A lone unmoved piece is the geometry's mesh; several pieces are
                // gathered, not copied.
                if count > 1 {
                    let gathered = matches!(g_mesh, Shape::Gathered(g) if g.pieces.len() == count);
                    prop_assert!(gathered);
                }
            }
        }
    }
}
