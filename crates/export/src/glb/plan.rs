//! Which glTF nodes, meshes and primitives a scene becomes: one node per scene node, or
//! geometry batched per (parent node, material).

use std::borrow::Cow;
use std::collections::BTreeMap;

use polis_geom::Mesh;
use polis_geom::scene::{MaterialId, MeshId, Metadata, NodeId, Scene};
use serde::Serialize;

use crate::ExportError;

/// The glTF document's geometry and node structure, before bytes are laid out.
#[derive(Debug)]
pub(crate) struct Plan<'a> {
    /// Vertex and index data; each becomes four accessors (position, normal, uv, indices).
    pub geometries: Vec<Cow<'a, Mesh>>,
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
    /// The scene node it comes from (name, transform, metadata).
    pub source: NodeId,
    pub mesh: Option<usize>,
    pub children: Vec<u32>,
}

/// A leaf node whose geometry was merged into its parent's mesh (batched mode), recorded in
/// the mesh's `extras.objects` so that tools can still pick it.
#[derive(Debug, Serialize)]
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

/// One glTF node per scene node; a scene mesh is stored once however many nodes draw it,
/// and nodes drawing the same list of meshes share one glTF mesh (instancing).
pub(crate) fn per_node(scene: &Scene) -> Plan<'_> {
    let mut geometry_of: Vec<Option<usize>> = vec![None; scene.meshes.len()];
    let mut geometries: Vec<Cow<'_, Mesh>> = Vec::new();
    let mut mesh_of: BTreeMap<Vec<MeshId>, usize> = BTreeMap::new();
    let mut meshes: Vec<PlannedMesh<'_>> = Vec::new();
    let mut nodes = Vec::with_capacity(scene.nodes.len());
    for (i, node) in scene.nodes.iter().enumerate() {
        let ids = drawn(scene, &node.meshes);
        let mesh = if ids.is_empty() {
            None
        } else if let Some(&m) = mesh_of.get(&ids) {
            Some(m)
        } else {
            let mut primitives = Vec::with_capacity(ids.len());
            for &id in &ids {
                let g = match geometry_of[id.index()] {
                    Some(g) => g,
                    None => {
                        let g = geometries.len();
                        geometries.push(Cow::Borrowed(&scene.meshes[id.index()]));
                        geometry_of[id.index()] = Some(g);
                        g
                    }
                };
                primitives.push((g, scene.meshes[id.index()].material));
            }
            meshes.push(PlannedMesh {
                name: node.name.clone(),
                primitives,
                objects: Vec::new(),
            });
            mesh_of.insert(ids, meshes.len() - 1);
            Some(meshes.len() - 1)
        };
        nodes.push(PlannedNode {
            source: NodeId(i as u32),
            mesh,
            children: node.children.iter().map(|c| c.0).collect(),
        });
    }
    let used: Vec<bool> = geometry_of.iter().map(Option::is_some).collect();
    let (skipped_empty_meshes, unused_meshes) = counts(scene, &used);
    Plan {
        geometries,
        meshes,
        nodes,
        roots: scene.roots.iter().map(|r| r.0).collect(),
        skipped_empty_meshes,
        unused_meshes,
    }
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
    let mut geometries: Vec<Cow<'_, Mesh>> = Vec::new();
    let mut meshes = Vec::new();
    let mut nodes = Vec::new();
    for (i, node) in scene.nodes.iter().enumerate() {
        if absorbed[i] {
            continue;
        }
        // Material key → (merged mesh, [(object, first triangle, count)]).
        type Group = (Mesh, Vec<(usize, usize, usize)>);
        let mut groups: BTreeMap<Option<MaterialId>, Group> = BTreeMap::new();
        let mut objects: Vec<BatchedObject<'_>> = Vec::new();
        for id in drawn(scene, &node.meshes) {
            used[id.index()] = true;
            let m = &scene.meshes[id.index()];
            let g = groups
                .entry(m.material)
                .or_insert_with(|| (Mesh::new(m.material), Vec::new()));
            g.0.append(m);
        }
        for &c in &node.children {
            if !absorbed[c.index()] {
                continue;
            }
            let child = &scene.nodes[c.index()];
            let object = objects.len();
            objects.push(BatchedObject {
                name: &child.name,
                metadata: &child.metadata,
                ranges: Vec::new(),
            });
            let matrix = child.transform.matrix();
            for id in drawn(scene, &child.meshes) {
                used[id.index()] = true;
                let mut m = scene.meshes[id.index()].clone();
                m.transform(&matrix)?;
                let g = groups
                    .entry(m.material)
                    .or_insert_with(|| (Mesh::new(m.material), Vec::new()));
                g.1.push((object, g.0.triangle_count(), m.triangle_count()));
                g.0.append(&m);
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
                geometries.push(Cow::Owned(merged));
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
            source: NodeId(i as u32),
            mesh,
            children: node
                .children
                .iter()
                .filter(|c| !absorbed[c.index()])
                .map(|c| new_index[c.index()])
                .collect(),
        });
    }
    let (skipped_empty_meshes, unused_meshes) = counts(scene, &used);
    Ok(Plan {
        geometries,
        meshes,
        nodes,
        roots: scene.roots.iter().map(|r| new_index[r.index()]).collect(),
        skipped_empty_meshes,
        unused_meshes,
    })
}
