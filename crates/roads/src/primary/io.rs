//! Sources and sinks of a primary network: a hand-written spec (JSON), GeoJSON, the
//! highways of a Parish & Müller growth, and the low-level planar [`RoadNetwork`] that
//! polis-cells reads.

use std::collections::BTreeMap;

use polis_geom::{DVec2, EdgeId, NodeId};
use serde::{Deserialize, Serialize};

use crate::network::{Junction, Road, RoadClass, RoadNetwork};
use crate::primary::edit::{Edit, Endpoint};
use crate::primary::error::PrimaryError;
use crate::primary::history::PrimaryEditor;
use crate::primary::network::{ControlId, ControlNode, Patch, PrimaryNetwork, PrimaryRoad, RoadId};
use crate::primary::params::{AdaptiveParams, EditOptions, RoadPreset, RoadSpec};
use crate::primary::plot::RoadPath;
use crate::primary::terrain::Terrain;

/// A node of a [`PrimarySpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NodeSpec {
    /// The spec's own key for the node (roads refer to it); the network assigns its own
    /// ids, in the order of the spec.
    pub id: u64,
    /// Position, metres.
    pub x: f64,
    /// Position, metres.
    pub y: f64,
    /// Optional label.
    #[serde(default)]
    pub label: Option<String>,
}

/// A road of a [`PrimarySpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RoadEntry {
    /// Key of its first node.
    pub a: u64,
    /// Key of its second node.
    pub b: u64,
    /// Its class. Default: [`RoadPreset::Primary`].
    #[serde(default = "default_class")]
    pub class: RoadPreset,
    /// Width in metres. Default: the class's width.
    #[serde(default)]
    pub width_m: Option<f64>,
    /// Adaptive parameters. Default: the class's preset.
    #[serde(default)]
    pub params: Option<AdaptiveParams>,
}

fn default_class() -> RoadPreset {
    RoadPreset::Primary
}

impl RoadEntry {
    /// The road's spec.
    pub fn spec(&self) -> RoadSpec {
        RoadSpec {
            class: self.class,
            width_m: self.width_m.unwrap_or(self.class.width_m()),
            params: self.params.unwrap_or(self.class.params()),
        }
    }
}

/// A primary network written by hand: nodes and roads, built through validity-checked
/// edits (so crossings become junctions). JSON:
/// `{"nodes": [{"id": 1, "x": 0, "y": 0}, …], "roads": [{"a": 1, "b": 2, "class": "InnerCity"}, …]}`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PrimarySpec {
    /// The nodes, added in this order.
    pub nodes: Vec<NodeSpec>,
    /// The roads, added in this order.
    #[serde(default)]
    pub roads: Vec<RoadEntry>,
}

impl PrimarySpec {
    /// Parses a spec from JSON.
    ///
    /// # Errors
    /// [`PrimaryError::BadData`] for malformed JSON.
    pub fn from_json(json: &str) -> Result<Self, PrimaryError> {
        serde_json::from_str(json).map_err(|e| PrimaryError::BadData(e.to_string()))
    }

    /// Builds the network by edits: every node, then every road (node snap, junctions at
    /// crossings). Returns the editor, whose log holds the edits.
    ///
    /// # Errors
    /// [`PrimaryError::BadData`] for a road naming an unknown key; otherwise the first
    /// refused edit.
    pub fn build(
        &self,
        terrain: Terrain,
        options: EditOptions,
    ) -> Result<PrimaryEditor, PrimaryError> {
        let mut ed = PrimaryEditor::new(terrain, options)?;
        let mut ids: BTreeMap<u64, ControlId> = BTreeMap::new();
        for n in &self.nodes {
            let id = ed.network().next_node_id();
            ed.apply(&Edit::AddNode {
                at: DVec2::new(n.x, n.y),
                label: n.label.clone(),
            })?;
            if ids.insert(n.id, id).is_some() {
                return Err(PrimaryError::BadData(format!(
                    "node key {} is used twice",
                    n.id
                )));
            }
        }
        for r in &self.roads {
            let key = |k: u64| {
                ids.get(&k).copied().ok_or_else(|| {
                    PrimaryError::BadData(format!("road names unknown node key {k}"))
                })
            };
            let (a, b) = (key(r.a)?, key(r.b)?);
            ed.apply(&Edit::AddRoad {
                from: Endpoint::Node(a),
                to: Endpoint::Node(b),
                spec: r.spec(),
            })?;
        }
        Ok(ed)
    }
}

fn coords(v: &serde_json::Value) -> Option<DVec2> {
    let a = v.as_array()?;
    Some(DVec2::new(a.first()?.as_f64()?, a.get(1)?.as_f64()?))
}

impl PrimaryNetwork {
    /// Builds a network from a GeoJSON `FeatureCollection` in layout metres: `Point`
    /// features are nodes (optional `label` property), `LineString` features are roads
    /// between their first and last coordinates (snapped to nodes or made new ones; the
    /// path between is plotted adaptively; optional `class` property: `Motorway`,
    /// `Primary`, `InnerCity`). Points are added first, then lines, in file order.
    ///
    /// # Errors
    /// [`PrimaryError::BadData`] for malformed GeoJSON; otherwise the first refused edit.
    pub fn from_geojson(
        json: &str,
        terrain: Terrain,
        options: EditOptions,
    ) -> Result<PrimaryEditor, PrimaryError> {
        let bad = |s: &str| PrimaryError::BadData(format!("GeoJSON: {s}"));
        let v: serde_json::Value = serde_json::from_str(json).map_err(|e| bad(&e.to_string()))?;
        let features = v
            .get("features")
            .and_then(|f| f.as_array())
            .ok_or_else(|| bad("expected a FeatureCollection with `features`"))?;
        let mut ed = PrimaryEditor::new(terrain, options)?;
        let geometry =
            |f: &serde_json::Value| -> Result<(String, serde_json::Value), PrimaryError> {
                let g = f
                    .get("geometry")
                    .ok_or_else(|| bad("a feature has no geometry"))?;
                let t = g
                    .get("type")
                    .and_then(|t| t.as_str())
                    .unwrap_or_default()
                    .to_string();
                Ok((t, g.get("coordinates").cloned().unwrap_or_default()))
            };
        for f in features {
            let (t, c) = geometry(f)?;
            if t == "Point" {
                let at = coords(&c).ok_or_else(|| bad("a Point needs [x, y]"))?;
                let label = f
                    .pointer("/properties/label")
                    .and_then(|l| l.as_str())
                    .map(str::to_string);
                ed.apply(&Edit::AddNode { at, label })?;
            }
        }
        for f in features {
            let (t, c) = geometry(f)?;
            if t == "LineString" {
                let line = c
                    .as_array()
                    .ok_or_else(|| bad("a LineString needs coordinates"))?;
                let (Some(a), Some(b)) =
                    (line.first().and_then(coords), line.last().and_then(coords))
                else {
                    return Err(bad("a LineString needs two [x, y] positions"));
                };
                let class = match f.pointer("/properties/class").and_then(|c| c.as_str()) {
                    None | Some("Primary") => RoadPreset::Primary,
                    Some("Motorway") => RoadPreset::Motorway,
                    Some("InnerCity") => RoadPreset::InnerCity,
                    Some(other) => return Err(bad(&format!("unknown road class {other:?}"))),
                };
                ed.apply(&Edit::AddRoad {
                    from: Endpoint::At(a),
                    to: Endpoint::At(b),
                    spec: class.spec(),
                })?;
            }
        }
        Ok(ed)
    }

    /// The primary network of the highways of a grown network (Parish & Müller), so the
    /// existing presets can start Kelly's pipeline. Highway junctions of degree ≠ 2 become
    /// control nodes; each chain of highway segments between them becomes one road of
    /// `spec` whose path is the chain as grown (every vertex a plot point, bridges kept),
    /// draped on `terrain`. A closed chain, or a second chain between the same two nodes,
    /// gets an extra control node at its middle vertex. Ids follow the graph's node and
    /// edge order.
    ///
    /// # Errors
    /// [`PrimaryError::OutsideMap`] where the terrain's elevation is undefined;
    /// [`PrimaryError::BadData`] if the highways are not planar.
    pub fn from_highways(
        network: &RoadNetwork,
        terrain: &Terrain,
        spec: RoadSpec,
    ) -> Result<PrimaryNetwork, PrimaryError> {
        spec.validate()?;
        let is_hw = |e: EdgeId| {
            network
                .edge_payload(e)
                .is_ok_and(|r| r.class == RoadClass::Highway)
        };
        let hw_edges = |n: NodeId| -> Vec<EdgeId> {
            network
                .edges_at(n)
                .map(|s| s.iter().copied().filter(|&e| is_hw(e)).collect())
                .unwrap_or_default()
        };
        let mut control: BTreeMap<NodeId, ControlId> = BTreeMap::new();
        let mut patch = Patch::default();
        let add_node = |n: NodeId,
                        patch: &mut Patch,
                        control: &mut BTreeMap<NodeId, ControlId>|
         -> Result<ControlId, PrimaryError> {
            if let Some(&c) = control.get(&n) {
                return Ok(c);
            }
            let pos = network.position(n)?;
            let elevation = terrain.elevation(pos);
            if !elevation.is_finite() {
                return Err(PrimaryError::OutsideMap { point: pos });
            }
            let id = ControlId(patch.next_node);
            patch.next_node += 1;
            patch.nodes.push((
                id,
                Some(ControlNode {
                    pos,
                    elevation,
                    label: None,
                }),
            ));
            control.insert(n, id);
            Ok(id)
        };
        for n in network.node_ids() {
            let d = hw_edges(n).len();
            if d != 0 && d != 2 {
                add_node(n, &mut patch, &mut control)?;
            }
        }
        let mut seen = vec![false; network.edge_bound()];
        let mut pairs: BTreeMap<(ControlId, ControlId), ()> = BTreeMap::new();
        let mut chains: Vec<(Vec<NodeId>, Vec<EdgeId>)> = Vec::new();
        // Chains from control nodes first, then the closed ones (all degree 2).
        let starts: Vec<NodeId> = control.keys().copied().chain(network.node_ids()).collect();
        for start in starts {
            for e0 in hw_edges(start) {
                if seen[e0.index()] {
                    continue;
                }
                let (mut nodes, mut edges) = (vec![start], Vec::new());
                let (mut at, mut e) = (start, e0);
                loop {
                    seen[e.index()] = true;
                    edges.push(e);
                    at = network.other_end(e, at)?;
                    nodes.push(at);
                    let next = hw_edges(at);
                    if control.contains_key(&at) || at == start || next.len() != 2 {
                        break;
                    }
                    match next.into_iter().find(|&x| x != e && !seen[x.index()]) {
                        Some(x) => e = x,
                        None => break,
                    }
                }
                chains.push((nodes, edges));
            }
        }
        for (nodes, edges) in chains {
            let first = add_node(nodes[0], &mut patch, &mut control)?;
            let last_n = nodes[nodes.len() - 1];
            let closed = last_n == nodes[0];
            let last = add_node(last_n, &mut patch, &mut control)?;
            let key = (first.min(last), first.max(last));
            let split = closed || pairs.contains_key(&key);
            let pieces: Vec<(usize, usize)> = if split && nodes.len() >= 3 {
                let mid = nodes.len() / 2;
                add_node(nodes[mid], &mut patch, &mut control)?;
                vec![(0, mid), (mid, nodes.len() - 1)]
            } else {
                vec![(0, nodes.len() - 1)]
            };
            for (i, j) in pieces {
                let (ca, cb) = (control[&nodes[i]], control[&nodes[j]]);
                pairs.insert((ca.min(cb), ca.max(cb)), ());
                let mut path = RoadPath::default();
                for &n in &nodes[i..=j] {
                    let p = network.position(n)?;
                    let h = terrain.elevation(p);
                    if !h.is_finite() {
                        return Err(PrimaryError::OutsideMap { point: p });
                    }
                    path.points.push(p);
                    path.elevation.push(h);
                }
                path.plot = (0..path.points.len() as u32).collect();
                path.bridge = edges[i..j]
                    .iter()
                    .map(|&e| network.edge_payload(e).is_ok_and(|r| r.bridge))
                    .collect();
                let id = RoadId(patch.next_road);
                patch.next_road += 1;
                patch.roads.push((
                    id,
                    Some(PrimaryRoad {
                        a: ca,
                        b: cb,
                        spec,
                        path,
                    }),
                ));
            }
        }
        let mut net = PrimaryNetwork::new();
        net.apply(&patch)?;
        net.check_invariants()?;
        Ok(net)
    }

    /// The low-level graph as the crate's planar [`RoadNetwork`] (every road a
    /// [`RoadClass::Highway`] with its width and bridge flags), with the map from each
    /// edge back to its primary road and from each control node to its graph node.
    /// Control nodes come first, in id order, then each road's interior vertices in road
    /// order, so the same network always gives the same graph ids.
    ///
    /// # Errors
    /// [`PrimaryError::Geometry`] only if the network's invariants were broken.
    pub fn to_road_network(&self) -> Result<LowLevelGraph, PrimaryError> {
        let mut g = RoadNetwork::new();
        let mut of_control = BTreeMap::new();
        let mut node_control = Vec::new();
        for (id, n) in self.nodes() {
            let v = g.add_node(n.pos, Junction::default())?;
            of_control.insert(id, v);
            node_control.push(Some(id));
        }
        let mut edge_road = Vec::new();
        for (id, r) in self.roads() {
            let pts = &r.path.points;
            let corrupt = || PrimaryError::BadData(format!("road {id} is inconsistent"));
            let mut prev = *of_control.get(&r.a).ok_or_else(corrupt)?;
            for (i, &p) in pts.iter().enumerate().skip(1) {
                let v = if i + 1 == pts.len() {
                    *of_control.get(&r.b).ok_or_else(corrupt)?
                } else {
                    node_control.push(None);
                    g.add_node(p, Junction::default())?
                };
                let road = Road {
                    class: RoadClass::Highway,
                    width: r.spec.width_m,
                    bridge: r.path.bridge.get(i - 1).copied().unwrap_or(false),
                    tunnel: false,
                    step: 0,
                };
                let e = g.add_edge(prev, v, road)?;
                if edge_road.len() <= e.index() {
                    edge_road.resize(e.index() + 1, None);
                }
                edge_road[e.index()] = Some(id);
                prev = v;
            }
        }
        Ok(LowLevelGraph {
            network: g,
            edge_road,
            node_control,
            of_control,
        })
    }
}

/// The low-level graph as a [`RoadNetwork`], with the ids that lead back to the primary
/// network ([`PrimaryNetwork::to_road_network`]).
#[derive(Debug, Clone)]
pub struct LowLevelGraph {
    /// The planar graph.
    pub network: RoadNetwork,
    /// For each edge index: the primary road it belongs to.
    pub edge_road: Vec<Option<RoadId>>,
    /// For each node index: the control node it is (`None` for path vertices).
    pub node_control: Vec<Option<ControlId>>,
    /// The graph node of each control node.
    pub of_control: BTreeMap<ControlId, NodeId>,
}

impl LowLevelGraph {
    /// The primary road an edge belongs to.
    pub fn road_of(&self, e: EdgeId) -> Option<RoadId> {
        self.edge_road.get(e.index()).copied().flatten()
    }

    /// The control node a graph node is, if any.
    pub fn control_of(&self, n: NodeId) -> Option<ControlId> {
        self.node_control.get(n.index()).copied().flatten()
    }
}
