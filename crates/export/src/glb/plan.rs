//! Which glTF nodes, meshes and primitives a scene becomes: one node per scene node, or
//! geometry batched per (parent node, material); the tiled layout is in `tiles`.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::hash::{Hash, Hasher};

use polis_geom::glam::{DVec3, Vec3};
use polis_geom::scene::{MaterialId, MeshId, Metadata, Node, NodeId, Scene};
use polis_geom::{Aabb3, Mesh};

use crate::ExportError;

/// The glTF document's geometry and node structure, before bytes are laid out.
#[derive(Debug)]
pub(crate) struct Plan<'a> {
    /// Vertex and index data; each becomes one accessor per array.
    pub geometries: Vec<Geometry<'a>>,
    /// glTF meshes.
    pub meshes: Vec<PlannedMesh<'a>>,
    /// glTF nodes.
    pub nodes: Vec<PlannedNode>,
    /// glTF indices of the scene's root nodes.
    pub roots: Vec<u32>,
    /// Scene meshes without triangles (left out: glTF forbids empty accessors).
    pub skipped_empty_meshes: usize,
    /// Scene meshes that no node draws (left out).
    pub unused_meshes: usize,
    /// Records in the roots' feature tables (tiled layout).
    pub features: usize,
    /// Tile nodes (tiled layout).
    pub tiles: usize,
}

impl Plan<'_> {
    pub fn empty() -> Self {
        Plan {
            geometries: Vec::new(),
            meshes: Vec::new(),
            nodes: Vec::new(),
            roots: Vec::new(),
            skipped_empty_meshes: 0,
            unused_meshes: 0,
            features: 0,
            tiles: 0,
        }
    }

    /// Fills the skipped and unused mesh counts from which scene meshes were `used`.
    pub fn count_meshes(&mut self, scene: &Scene, used: &[bool]) {
        (self.skipped_empty_meshes, self.unused_meshes) = counts(scene, used);
    }
}

/// One geometry: a mesh and, in the tiled layout, the feature index of every vertex.
#[derive(Debug)]
pub(crate) struct Geometry<'a> {
    pub mesh: Shape<'a>,
    /// `_FEATURE_ID_0` per vertex, as runs.
    pub features: Option<FeatureIds>,
    /// The bounds of `mesh`'s positions when the plan already knows them (the tiled
    /// layout tracks them while merging); `None`: computed from the mesh.
    pub bounds: Option<Aabb3>,
}

impl<'a> Geometry<'a> {
    fn plain(mesh: Cow<'a, Mesh>) -> Self {
        Geometry {
            mesh: Shape::Whole(mesh),
            features: None,
            bounds: None,
        }
    }

    /// The bounding box of the positions.
    pub fn bbox(&self) -> Aabb3 {
        self.bounds.unwrap_or_else(|| self.mesh.to_mesh().bbox())
    }
}

/// A geometry's vertices and triangles: one mesh, or the pieces of a merged geometry (the
/// tiled layout) laid end to end. The plain writer streams a merged geometry's arrays
/// straight from its pieces, so no merged copy of the city is made.
#[derive(Debug)]
pub(crate) enum Shape<'a> {
    /// One mesh, as it is.
    Whole(Cow<'a, Mesh>),
    /// Pieces laid end to end.
    Gathered(Gathered<'a>),
}

/// The pieces of a merged geometry: what appending them one by one to an empty mesh of
/// `material` gives ([`to_mesh`](Self::to_mesh)), without the copy.
#[derive(Debug)]
pub(crate) struct Gathered<'a> {
    pub material: Option<MaterialId>,
    /// Positions over all pieces.
    pub vertices: usize,
    /// Indices over all pieces.
    pub indices: usize,
    /// Each piece's mesh and the translation of its positions: zero, the positions as
    /// they are (a −0 kept); else each `p + t` in `f64`, rounded to `f32`. Normals,
    /// texture coordinates are the piece's; its indices count from the vertices of the
    /// pieces before it.
    pub pieces: Vec<(Cow<'a, Mesh>, DVec3)>,
}

impl Gathered<'_> {
    /// The merged mesh: the pieces appended in order, moved.
    pub fn to_mesh(&self) -> Mesh {
        let mut out = Mesh::new(self.material);
        out.positions.reserve_exact(self.vertices);
        out.normals.reserve_exact(self.vertices);
        out.uvs.reserve_exact(self.vertices);
        out.indices.reserve_exact(self.indices);
        for (m, t) in &self.pieces {
            let base = out.positions.len() as u32;
            out.positions
                .extend(m.positions.iter().map(|&p| moved(p, *t)));
            out.normals.extend_from_slice(&m.normals);
            out.uvs.extend_from_slice(&m.uvs);
            out.indices.extend(m.indices.iter().map(|&i| base + i));
        }
        out
    }

    /// Whether each piece has a normal and a texture coordinate per position, so arrays
    /// computed per vertex from its own triangles (tangents) can be computed piece by
    /// piece.
    pub fn aligned(&self) -> bool {
        self.pieces
            .iter()
            .all(|(m, _)| m.normals.len() == m.positions.len() && m.uvs.len() == m.positions.len())
    }
}

/// `p` moved by `t` as a merged geometry moves it: unchanged for a zero `t` (a −0 kept),
/// else `p + t` in `f64`, rounded to `f32`.
pub(crate) fn moved(p: Vec3, t: DVec3) -> Vec3 {
    if t == DVec3::ZERO {
        p
    } else {
        (p.as_dvec3() + t).as_vec3()
    }
}

impl Shape<'_> {
    /// The mesh's material.
    pub fn material(&self) -> Option<MaterialId> {
        match self {
            Shape::Whole(m) => m.material,
            Shape::Gathered(g) => g.material,
        }
    }

    /// Vertices.
    pub fn vertex_count(&self) -> usize {
        match self {
            Shape::Whole(m) => m.vertex_count(),
            Shape::Gathered(g) => g.vertices,
        }
    }

    /// Indices (three per triangle).
    pub fn index_count(&self) -> usize {
        match self {
            Shape::Whole(m) => m.indices.len(),
            Shape::Gathered(g) => g.indices,
        }
    }

    /// Triangles.
    pub fn triangle_count(&self) -> usize {
        self.index_count() / 3
    }

    /// The mesh: borrowed when whole, merged from the pieces when gathered.
    pub fn to_mesh(&self) -> Cow<'_, Mesh> {
        match self {
            Shape::Whole(m) => Cow::Borrowed(m),
            Shape::Gathered(g) => Cow::Owned(g.to_mesh()),
        }
    }
}

/// A geometry's feature id per vertex, stored as runs of equal ids (a merged geometry's
/// pieces each give all their vertices one id): no array as long as the vertices is
/// allocated, filled and scanned for its largest id; the writer expands the runs as it
/// streams them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct FeatureIds {
    /// (vertices, id) in vertex order; no run is empty and no two neighbours share an id.
    runs: Vec<(u32, u32)>,
    max: u32,
}

impl FeatureIds {
    /// Room for `runs` runs.
    pub fn with_capacity(runs: usize) -> Self {
        FeatureIds {
            runs: Vec::with_capacity(runs),
            max: 0,
        }
    }

    /// Gives the next `count` vertices the id `id`.
    pub fn push(&mut self, id: u32, mut count: usize) {
        self.max = self.max.max(id);
        if let Some(last) = self.runs.last_mut()
            && last.1 == id
        {
            let room = (u32::MAX - last.0) as usize;
            let add = room.min(count);
            last.0 += add as u32;
            count -= add;
        }
        while count > 0 {
            let n = count.min(u32::MAX as usize);
            self.runs.push((n as u32, id));
            count -= n;
        }
    }

    /// The largest id (0 without vertices).
    pub fn max(&self) -> u32 {
        self.max
    }

    /// The (vertices, id) runs in vertex order.
    pub fn runs(&self) -> &[(u32, u32)] {
        &self.runs
    }

    /// The id of every vertex, in order (the web profile's per-vertex attribute).
    #[cfg(any(test, feature = "web"))]
    pub fn to_vec(&self) -> Vec<u32> {
        let len = self.runs.iter().map(|&(n, _)| n as usize).sum();
        let mut out = Vec::with_capacity(len);
        for &(n, id) in &self.runs {
            out.resize(out.len() + n as usize, id);
        }
        out
    }
}

/// One glTF mesh.
#[derive(Debug)]
pub(crate) struct PlannedMesh<'a> {
    pub name: String,
    /// (geometry index, material) per primitive.
    pub primitives: Vec<(usize, Option<MaterialId>)>,
    /// The objects merged into this mesh, when batching.
    pub objects: Vec<BatchedObject<'a>>,
}

/// One glTF node.
#[derive(Debug)]
pub(crate) struct PlannedNode {
    /// The scene node it comes from (name, transform, metadata); `None` for a node the
    /// layout adds (a layer, a tile, a LOD level).
    pub source: Option<NodeId>,
    /// The name of an added node.
    pub name: String,
    /// Entries added to the extras (after the scene node's metadata).
    pub extras: Option<serde_json::Map<String, serde_json::Value>>,
    /// Entries added to the extras whose value is an array of elements already written
    /// as JSON text (the tiled layout's feature table in the plain profile); where
    /// `extras` has the same key, this one is written.
    pub raw_extras: Vec<(&'static str, Vec<Box<serde_json::value::RawValue>>)>,
    pub mesh: Option<usize>,
    pub children: Vec<u32>,
    /// `EXT_mesh_gpu_instancing`: the scene nodes whose transforms are the instances
    /// (empty: a plain node).
    pub instances: Vec<NodeId>,
}

impl PlannedNode {
    pub fn from_scene(source: NodeId) -> Self {
        PlannedNode {
            source: Some(source),
            name: String::new(),
            extras: None,
            raw_extras: Vec::new(),
            mesh: None,
            children: Vec::new(),
            instances: Vec::new(),
        }
    }

    /// An added node with a name and extras (a JSON object).
    pub fn synthetic(name: String, extras: serde_json::Value) -> Self {
        PlannedNode {
            source: None,
            name,
            extras: match extras {
                serde_json::Value::Object(m) => Some(m),
                _ => None,
            },
            raw_extras: Vec::new(),
            mesh: None,
            children: Vec::new(),
            instances: Vec::new(),
        }
    }
}

/// A leaf node whose geometry was merged into its parent's mesh (batched mode), recorded in
/// the mesh's `extras.objects` so that tools can still pick it.
#[derive(Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub(crate) struct BatchedObject<'a> {
    /// The leaf node's name.
    pub name: &'a str,
    /// The leaf node's metadata.
    pub metadata: &'a Metadata,
    /// `[primitive, first triangle, triangle count]` per piece of geometry it contributed.
    pub ranges: Vec<[usize; 3]>,
}

fn drawn(scene: &Scene, ids: &[MeshId]) -> Vec<MeshId> {
    ids.iter()
        .copied()
        .filter(|m| scene.meshes.get(m.index()).is_some_and(|m| !m.is_empty()))
        .collect()
}

fn counts(scene: &Scene, used: &[bool]) -> (usize, usize) {
    let empty = scene.meshes.iter().filter(|m| m.is_empty()).count();
    let unused = scene
        .meshes
        .iter()
        .zip(used)
        .filter(|(m, u)| !m.is_empty() && !**u)
        .count();
    (empty, unused)
}

/// A hash of everything a mesh writes (geometry bytes and material), to find identical
/// meshes; equal hashes are confirmed by comparing the meshes.
fn content_hash(m: &Mesh) -> u64 {
    let mut h = std::hash::DefaultHasher::new();
    m.material.hash(&mut h);
    m.positions.len().hash(&mut h);
    for p in &m.positions {
        p.to_array().map(f32::to_bits).hash(&mut h);
    }
    for n in &m.normals {
        n.to_array().map(f32::to_bits).hash(&mut h);
    }
    for t in &m.uvs {
        t.to_array().map(f32::to_bits).hash(&mut h);
    }
    m.indices.hash(&mut h);
    h.finish()
}

/// One glTF node per scene node. Scene meshes with identical content (the same
/// vertices, indices and material, e.g. a template placed many times) are stored once
/// however many nodes draw them, and nodes drawing the same list of meshes share one
/// glTF mesh.
pub(crate) fn per_node(scene: &Scene) -> Plan<'_> {
    let mut geometry_of: Vec<Option<usize>> = vec![None; scene.meshes.len()];
    let mut by_content: BTreeMap<u64, Vec<usize>> = BTreeMap::new();
    let mut geometries: Vec<Geometry<'_>> = Vec::new();
    let mut mesh_of: BTreeMap<Vec<usize>, usize> = BTreeMap::new();
    let mut meshes: Vec<PlannedMesh<'_>> = Vec::new();
    let mut nodes = Vec::with_capacity(scene.nodes.len());
    for (i, node) in scene.nodes.iter().enumerate() {
        let ids = drawn(scene, &node.meshes);
        let mut gs = Vec::with_capacity(ids.len());
        for &id in &ids {
            let g = match geometry_of[id.index()] {
                Some(g) => g,
                None => {
                    let mesh = &scene.meshes[id.index()];
                    let same = by_content.entry(content_hash(mesh)).or_default();
                    let g = match same
                        .iter()
                        .find(|&&g| matches!(&geometries[g].mesh, Shape::Whole(w) if **w == *mesh))
                    {
                        Some(&g) => g,
                        None => {
                            geometries.push(Geometry::plain(Cow::Borrowed(mesh)));
                            same.push(geometries.len() - 1);
                            geometries.len() - 1
                        }
                    };
                    geometry_of[id.index()] = Some(g);
                    g
                }
            };
            gs.push(g);
        }
        let mesh = if gs.is_empty() {
            None
        } else if let Some(&m) = mesh_of.get(&gs) {
            Some(m)
        } else {
            let primitives = gs
                .iter()
                .map(|&g| (g, geometries[g].mesh.material()))
                .collect();
            meshes.push(PlannedMesh {
                name: node.name.clone(),
                primitives,
                objects: Vec::new(),
            });
            mesh_of.insert(gs, meshes.len() - 1);
            Some(meshes.len() - 1)
        };
        nodes.push(PlannedNode {
            mesh,
            children: node.children.iter().map(|c| c.0).collect(),
            ..PlannedNode::from_scene(NodeId(i as u32))
        });
    }
    let used: Vec<bool> = geometry_of.iter().map(Option::is_some).collect();
    let mut plan = Plan::empty();
    plan.geometries = geometries;
    plan.meshes = meshes;
    plan.nodes = nodes;
    plan.roots = scene.roots.iter().map(|r| r.0).collect();
    plan.count_meshes(scene, &used);
    plan
}

/// Geometry batched per (parent node, material): every leaf node that draws something and
/// has a parent is merged into its parent's mesh (transformed by its local transform), one
/// primitive per material; its name and metadata go to the mesh's `extras.objects` with the
/// triangle ranges it occupies. Other nodes are kept.
pub(crate) fn batched(scene: &Scene) -> Result<Plan<'_>, ExportError> {
    let n = scene.nodes.len();
    let mut has_parent = vec![false; n];
    for node in &scene.nodes {
        for &c in &node.children {
            has_parent[c.index()] = true;
        }
    }
    let absorbed: Vec<bool> = scene
        .nodes
        .iter()
        .enumerate()
        .map(|(i, node)| {
            has_parent[i] && node.children.is_empty() && !drawn(scene, &node.meshes).is_empty()
        })
        .collect();
    // glTF index of every kept node, in array order.
    let mut new_index = vec![u32::MAX; n];
    let mut next = 0u32;
    for (i, &a) in absorbed.iter().enumerate() {
        if !a {
            new_index[i] = next;
            next += 1;
        }
    }
    let mut used = vec![false; scene.meshes.len()];
    let mut geometries: Vec<Geometry<'_>> = Vec::new();
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    for (i, node) in scene.nodes.iter().enumerate() {
        if absorbed[i] {
            continue;
        }
        // Material key → (merged mesh, [(object, first triangle, count)]), each mesh
        // allocated once at its final size (counted first: no doubling re-copies).
        type Group = (Mesh, Vec<(usize, usize, usize)>);
        let own = drawn(scene, &node.meshes);
        let children: Vec<(&Node, Vec<MeshId>)> = node
            .children
            .iter()
            .filter(|c| absorbed[c.index()])
            .map(|c| {
                let child = &scene.nodes[c.index()];
                (child, drawn(scene, &child.meshes))
            })
            .collect();
        let mut sizes: BTreeMap<Option<MaterialId>, (usize, usize)> = BTreeMap::new();
        for &id in own.iter().chain(children.iter().flat_map(|c| &c.1)) {
            let m = &scene.meshes[id.index()];
            let size = sizes.entry(m.material).or_default();
            size.0 += m.positions.len();
            size.1 += m.indices.len();
        }
        let mut groups: BTreeMap<Option<MaterialId>, Group> = sizes
            .into_iter()
            .map(|(material, (vertices, indices))| {
                let mut m = Mesh::new(material);
                m.positions.reserve_exact(vertices);
                m.normals.reserve_exact(vertices);
                m.uvs.reserve_exact(vertices);
                m.indices.reserve_exact(indices);
                (material, (m, Vec::new()))
            })
            .collect();
        let mut objects: Vec<BatchedObject<'_>> = Vec::new();
        for id in own {
            used[id.index()] = true;
            let m = &scene.meshes[id.index()];
            if let Some(g) = groups.get_mut(&m.material) {
                g.0.append(m);
            }
        }
        for (child, meshes) in children {
            let object = objects.len();
            objects.push(BatchedObject {
                name: &child.name,
                metadata: &child.metadata,
                ranges: Vec::new(),
            });
            let matrix = child.transform.matrix();
            for id in meshes {
                used[id.index()] = true;
                let m = &scene.meshes[id.index()];
                if let Some(g) = groups.get_mut(&m.material) {
                    g.1.push((object, g.0.triangle_count(), m.triangle_count()));
                    g.0.append_transformed(m, &matrix)?;
                }
            }
        }
        let mesh = if groups.is_empty() {
            None
        } else {
            let mut primitives = Vec::with_capacity(groups.len());
            for (p, (material, (merged, ranges))) in groups.into_iter().enumerate() {
                for (object, first, count) in ranges {
                    if let Some(o) = objects.get_mut(object) {
                        o.ranges.push([p, first, count]);
                    }
                }
                primitives.push((geometries.len(), material));
                geometries.push(Geometry::plain(Cow::Owned(merged)));
            }
            for o in &mut objects {
                o.ranges.sort_unstable();
            }
            meshes.push(PlannedMesh {
                name: node.name.clone(),
                primitives,
                objects,
            });
            Some(meshes.len() - 1)
        };
        nodes.push(PlannedNode {
            mesh,
            children: node
                .children
                .iter()
                .filter(|c| !absorbed[c.index()])
                .map(|c| new_index[c.index()])
                .collect(),
            ..PlannedNode::from_scene(NodeId(i as u32))
        });
    }
    let mut plan = Plan::empty();
    plan.geometries = geometries;
    plan.meshes = meshes;
    plan.nodes = nodes;
    plan.roots = scene.roots.iter().map(|r| new_index[r.index()]).collect();
    plan.count_meshes(scene, &used);
    Ok(plan)
}

#[cfg(test)]
mod tests {
    use super::FeatureIds;

    /// Runs expand to the ids pushed, neighbours with one id merged, empty pushes
    /// dropped; the length and the largest id follow.
    #[test]
    fn feature_runs_expand_to_the_ids_pushed() {
        let mut ids = FeatureIds::with_capacity(0);
        assert_eq!((ids.max(), ids.to_vec()), (0, vec![]));
        let pushes = [(7, 2), (7, 1), (3, 0), (9, 3), (2, 1), (7, 2)];
        let mut expect = Vec::new();
        for (id, n) in pushes {
            ids.push(id, n);
            expect.extend(std::iter::repeat_n(id, n));
        }
        assert_eq!(ids.to_vec(), expect);
        assert_eq!(ids.max(), 9);
        assert_eq!(ids.runs(), &[(3, 7), (3, 9), (1, 2), (2, 7)]);
    }
}
