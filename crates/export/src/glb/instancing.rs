//! Optional GPU instancing (`EXT_mesh_gpu_instancing`) of shared meshes in the per-node
//! layout ([`GlbOptions::gpu_instancing`](super::GlbOptions::gpu_instancing)).
//!
//! Rule: leaf nodes (no children) under the same parent that draw the same glTF mesh
//! with a TRS transform ([`Transform::Trs`]) are, when there are two or more of them,
//! replaced by one node under that parent drawing the mesh once per instance. The
//! instances' translations, rotations and scales are `f32` accessors (`TRANSLATION`,
//! `ROTATION`, `SCALE`, the extension's attributes) and `_FEATURE_ID_0` (`f32`, exact to
//! 2²⁴) numbers them; the node's `extras.instances` lists each instance's `name` and
//! metadata in that order, so picking an instance still finds its building. Leaves with
//! a general matrix stay nodes of their own.
//!
//! The extension goes to `extensionsUsed` only: a loader without it draws the mesh once
//! at the node, so keep the option off for such loaders (Godot, Unreal; the default).
//!
//! References: Khronos, *EXT_mesh_gpu_instancing* (instance transform applied before
//! the node's global transform).

use std::collections::BTreeMap;

use polis_geom::glam::{DQuat, DVec3, Vec3};
use polis_geom::scene::{NodeId, Scene, Transform};
use serde_json::{Map, Value, json};

use super::plan::{Plan, PlannedNode};
use crate::ExportError;

/// The extension's name.
pub(crate) const EXTENSION: &str = "EXT_mesh_gpu_instancing";

/// Bytes per instance: translation (12), rotation (16), scale (12), feature id (4).
const INSTANCE_BYTES: u64 = 44;

/// Replaces groups of sibling leaves drawing one mesh by instanced nodes (see the module
/// docs). Node indices, children and roots are renumbered; kept nodes keep their order
/// and the instanced nodes follow them.
pub(crate) fn instance(scene: &Scene, plan: &mut Plan<'_>) -> Result<(), ExportError> {
    let n = plan.nodes.len();
    let mut parent = vec![None; n];
    for (i, node) in plan.nodes.iter().enumerate() {
        for &c in &node.children {
            if let Some(p) = parent.get_mut(c as usize) {
                *p = Some(i);
            }
        }
    }
    let mut groups: BTreeMap<(usize, usize), Vec<usize>> = BTreeMap::new();
    for (i, node) in plan.nodes.iter().enumerate() {
        let trs = node
            .source
            .and_then(|s| scene.nodes.get(s.index()))
            .is_some_and(|s| matches!(s.transform, Transform::Trs { .. }));
        if let (Some(p), Some(m), true, true) =
            (parent[i], node.mesh, node.children.is_empty(), trs)
        {
            groups.entry((p, m)).or_default().push(i);
        }
    }
    groups.retain(|_, leaves| leaves.len() >= 2);
    if groups.is_empty() {
        return Ok(());
    }
    let mut removed = vec![false; n];
    for leaves in groups.values() {
        for &l in leaves {
            removed[l] = true;
        }
    }
    let mut new_index = vec![u32::MAX; n];
    let mut next = 0u32;
    for (i, &r) in removed.iter().enumerate() {
        if !r {
            new_index[i] = next;
            next += 1;
        }
    }
    let groups: Vec<((usize, usize), Vec<NodeId>)> = groups
        .into_iter()
        .map(|(key, leaves)| {
            let sources = leaves
                .iter()
                .filter_map(|&l| plan.nodes.get(l).and_then(|node| node.source))
                .collect();
            (key, sources)
        })
        .collect();
    let old = std::mem::take(&mut plan.nodes);
    let mut nodes: Vec<PlannedNode> = Vec::with_capacity(next as usize + groups.len());
    for (i, mut node) in old.into_iter().enumerate() {
        if removed[i] {
            continue;
        }
        node.children = node
            .children
            .iter()
            .filter(|&&c| !removed[c as usize])
            .map(|&c| new_index[c as usize])
            .collect();
        nodes.push(node);
    }
    for ((p, m), sources) in groups {
        let mut records = Vec::with_capacity(sources.len());
        for src in &sources {
            let node = &scene.nodes[src.index()];
            let mut record = Map::new();
            record.insert("name".into(), Value::from(node.name.as_str()));
            if let Value::Object(meta) =
                serde_json::to_value(&node.metadata).map_err(ExportError::json("instances"))?
            {
                for (k, v) in meta {
                    record.entry(k).or_insert(v);
                }
            }
            records.push(Value::Object(record));
        }
        let name = plan
            .meshes
            .get(m)
            .map_or_else(String::new, |mesh| mesh.name.clone());
        let mut node = PlannedNode::synthetic(
            format!("{name} ×{}", sources.len()),
            json!({ "instances": records }),
        );
        node.mesh = Some(m);
        node.instances = sources;
        let k = nodes.len() as u32;
        nodes.push(node);
        if let Some(parent) = nodes.get_mut(new_index[p] as usize) {
            parent.children.push(k);
        }
    }
    plan.roots = plan
        .roots
        .iter()
        .map(|&r| new_index.get(r as usize).copied().unwrap_or(r))
        .collect();
    plan.nodes = nodes;
    Ok(())
}

/// The instance arrays of every instanced node, in node order, laid out from `offset`
/// in the binary chunk.
pub(crate) struct Instances {
    /// Per instanced node: (plan node, instance count, byte offset of its arrays).
    pub nodes: Vec<(usize, usize, u64)>,
    /// The arrays: per node, translations, rotations, scales, feature ids.
    pub bytes: Vec<u8>,
}

/// Builds the instance arrays. `dequantize` (per glTF mesh, the web profile's
/// `(offset, scale)`) is composed into each instance's TRS: the extension applies the
/// instance transform to the vertices before the node's, so quantized positions are
/// first dequantized, then placed.
pub(crate) fn arrays(
    scene: &Scene,
    plan: &Plan<'_>,
    dequantize: &[Option<(Vec3, Vec3)>],
    offset: u64,
) -> Instances {
    let mut nodes = Vec::new();
    let mut bytes = Vec::new();
    for (i, node) in plan.nodes.iter().enumerate() {
        if node.instances.is_empty() {
            continue;
        }
        let at = offset + bytes.len() as u64;
        let count = node.instances.len();
        let q = node.mesh.and_then(|m| dequantize.get(m).copied().flatten());
        let trs: Vec<(DVec3, DQuat, DVec3)> = node
            .instances
            .iter()
            .map(|s| {
                let t = scene
                    .nodes
                    .get(s.index())
                    .map_or(Transform::IDENTITY, |n| n.transform);
                let t = match q {
                    Some((o, sc)) => super::compose_dequantize(&t, o, sc),
                    None => t,
                };
                match t {
                    Transform::Trs {
                        translation,
                        rotation,
                        scale,
                    } => (translation, rotation, scale),
                    Transform::Matrix(m) => {
                        let (s, r, t) = m.to_scale_rotation_translation();
                        (t, r, s)
                    }
                }
            })
            .collect();
        for (t, _, _) in &trs {
            for c in t.as_vec3().to_array() {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        for (_, r, _) in &trs {
            for c in r.as_quat().normalize().to_array() {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        for (_, _, s) in &trs {
            for c in s.as_vec3().to_array() {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        for k in 0..count {
            bytes.extend_from_slice(&(k as f32).to_le_bytes());
        }
        debug_assert_eq!(
            bytes.len() as u64,
            at - offset + INSTANCE_BYTES * count as u64
        );
        nodes.push((i, count, at));
    }
    Instances { nodes, bytes }
}

/// Adds `EXT_mesh_gpu_instancing` to each instanced node of the serialized document and
/// to `extensionsUsed` (not required: see the module docs).
pub(crate) fn add_extension(doc: &mut Value, instances: &Instances, accessors: &[[u32; 4]]) {
    if instances.nodes.is_empty() {
        return;
    }
    if let Some(nodes) = doc.get_mut("nodes").and_then(Value::as_array_mut) {
        for (&(i, _, _), ids) in instances.nodes.iter().zip(accessors) {
            if let Some(node) = nodes.get_mut(i).and_then(Value::as_object_mut) {
                node.insert(
                    "extensions".into(),
                    json!({ EXTENSION: { "attributes": {
                        "TRANSLATION": ids[0],
                        "ROTATION": ids[1],
                        "SCALE": ids[2],
                        "_FEATURE_ID_0": ids[3],
                    }}}),
                );
            }
        }
    }
    if let Some(root) = doc.as_object_mut() {
        let used = root
            .entry("extensionsUsed")
            .or_insert_with(|| Value::Array(Vec::new()));
        if let Some(list) = used.as_array_mut() {
            list.push(json!(EXTENSION));
        }
    }
}
