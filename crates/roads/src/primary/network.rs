//! [`PrimaryNetwork`]: the high-level graph of control nodes and primary roads, each road
//! holding its low-level path (Kelly §4.2, Fig. 38).
//!
//! Ids are monotonic `u64`s handed out by the network and never reused by later edits;
//! a road split at a new junction keeps its id for the piece at its first end. Undo
//! restores the whole state, id counters included (see [`crate::primary::EditLog`]).
//!
//! Invariants ([`PrimaryNetwork::check_invariants`]): every road joins two distinct live
//! nodes (two nodes may be joined by several roads with different paths, e.g. where a
//! new road crosses an old one twice); each path starts and ends exactly at its nodes, has
//! no repeated consecutive vertices and lists its plot points; no two nodes coincide; and
//! the low-level paths form a planar embedding of the high-level graph: two paths meet
//! only at a node they share, at their ends, and no path touches itself or passes through
//! a node. Both graphs are therefore planar.

use std::collections::BTreeMap;

use polis_geom::predicates::SegmentIntersection;
use polis_geom::spatial::SpatialIndex;
use polis_geom::{DVec2, SegmentIndex};
use serde::{Deserialize, Serialize};

use crate::primary::error::PrimaryError;
use crate::primary::params::RoadSpec;
use crate::primary::plot::RoadPath;

macro_rules! id_type {
    ($(#[$m:meta])* $t:ident, $prefix:literal) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
        #[serde(transparent)]
        pub struct $t(pub u64);

        impl std::fmt::Display for $t {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, concat!($prefix, "{}"), self.0)
            }
        }
    };
}

id_type!(
    /// The stable id of a control node (a node of the high-level graph).
    ControlId,
    "n"
);
id_type!(
    /// The stable id of a primary road (an edge of the high-level graph).
    RoadId,
    "r"
);

/// A control node: a primary road intersection or end (Kelly §4.2, §5.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControlNode {
    /// Position in metres.
    pub pos: DVec2,
    /// Ground elevation there, metres (the node is draped like the roads).
    pub elevation: f64,
    /// Optional label (Kelly's nodes show their instance count by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

/// A primary road: two control nodes, what the road is, and its low-level path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrimaryRoad {
    /// The node the path starts at.
    pub a: ControlId,
    /// The node the path ends at.
    pub b: ControlId,
    /// Class, width and adaptive parameters.
    pub spec: RoadSpec,
    /// The plotted, interpolated and draped path from `a` to `b`.
    pub path: RoadPath,
}

impl PrimaryRoad {
    /// The end that is not `n` (or `None` when `n` is not an end).
    pub fn other_end(&self, n: ControlId) -> Option<ControlId> {
        if self.a == n {
            Some(self.b)
        } else if self.b == n {
            Some(self.a)
        } else {
            None
        }
    }

    /// The first path segment's far point seen from end `n` (the direction the road
    /// leaves the node in).
    pub fn leaving(&self, n: ControlId) -> Option<DVec2> {
        let p = &self.path.points;
        if p.len() < 2 {
            return None;
        }
        if self.a == n {
            Some(p[1])
        } else if self.b == n {
            Some(p[p.len() - 2])
        } else {
            None
        }
    }
}

/// A set of node and road states plus id counters: what a commit writes, or, for undo,
/// what it overwrote. `None` = absent.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Patch {
    /// Node states, in increasing id order.
    pub nodes: Vec<(ControlId, Option<ControlNode>)>,
    /// Road states, in increasing id order.
    pub roads: Vec<(RoadId, Option<PrimaryRoad>)>,
    /// The next node id.
    pub next_node: u64,
    /// The next road id.
    pub next_road: u64,
}

/// The primary road network: high-level graph (control nodes, roads) and low-level graph
/// (each road's path). Serde data; derived indexes are rebuilt on load, and loading
/// checks every invariant. See the [module docs](self).
#[derive(Debug, Clone, Default)]
pub struct PrimaryNetwork {
    nodes: BTreeMap<ControlId, ControlNode>,
    roads: BTreeMap<RoadId, PrimaryRoad>,
    next_node: u64,
    next_road: u64,
    /// Roads at each node, increasing ids (derived).
    incident: BTreeMap<ControlId, Vec<RoadId>>,
    node_index: SegmentIndex<ControlId>,
    path_index: SegmentIndex<(RoadId, u32)>,
    /// Bumped by every change; previews remember it (not serialised).
    revision: u64,
}

impl PrimaryNetwork {
    /// An empty network.
    pub fn new() -> Self {
        Self::default()
    }

    /// The control nodes, by increasing id.
    pub fn nodes(&self) -> impl Iterator<Item = (ControlId, &ControlNode)> + '_ {
        self.nodes.iter().map(|(&k, v)| (k, v))
    }

    /// The roads, by increasing id.
    pub fn roads(&self) -> impl Iterator<Item = (RoadId, &PrimaryRoad)> + '_ {
        self.roads.iter().map(|(&k, v)| (k, v))
    }

    /// A node.
    ///
    /// # Errors
    /// [`PrimaryError::UnknownNode`].
    pub fn node(&self, id: ControlId) -> Result<&ControlNode, PrimaryError> {
        self.nodes.get(&id).ok_or(PrimaryError::UnknownNode(id))
    }

    /// A road.
    ///
    /// # Errors
    /// [`PrimaryError::UnknownRoad`].
    pub fn road(&self, id: RoadId) -> Result<&PrimaryRoad, PrimaryError> {
        self.roads.get(&id).ok_or(PrimaryError::UnknownRoad(id))
    }

    /// The roads at node `n`, increasing ids (empty for an unknown node).
    pub fn roads_at(&self, n: ControlId) -> &[RoadId] {
        self.incident.get(&n).map_or(&[], Vec::as_slice)
    }

    /// The road joining `a` and `b`, if any.
    pub fn road_between(&self, a: ControlId, b: ControlId) -> Option<RoadId> {
        self.roads_at(a)
            .iter()
            .copied()
            .find(|r| self.roads.get(r).is_some_and(|x| x.other_end(a) == Some(b)))
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of roads.
    pub fn road_count(&self) -> usize {
        self.roads.len()
    }

    /// The id the next new node will get.
    pub fn next_node_id(&self) -> ControlId {
        ControlId(self.next_node)
    }

    /// The id the next new road will get.
    pub fn next_road_id(&self) -> RoadId {
        RoadId(self.next_road)
    }

    /// A counter bumped by every change of this value (not serialised): previews made
    /// at another revision are refused.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The node nearest to `p` within `radius` metres (ties: smaller id).
    pub fn nearest_node(&self, p: DVec2, radius: f64) -> Option<(ControlId, f64)> {
        self.node_index
            .nearest_point(p, radius)
            .map(|n| (n.key, n.distance))
    }

    /// The road path nearest to `p` within `radius`: `(road, segment, closest point,
    /// distance)` (ties: smaller road id, then segment).
    pub fn nearest_road(&self, p: DVec2, radius: f64) -> Option<(RoadId, u32, DVec2, f64)> {
        self.path_index
            .nearest_segment(p, radius)
            .map(|n| (n.key.0, n.key.1, n.closest, n.distance))
    }

    /// The node nearest to `p` within `radius`, other than `except`.
    pub fn nearest_node_except(
        &self,
        p: DVec2,
        radius: f64,
        except: ControlId,
    ) -> Option<(ControlId, f64)> {
        self.node_index
            .points_within(p, radius)
            .into_iter()
            .find(|n| n.key != except)
            .map(|n| (n.key, n.distance))
    }

    /// The road nearest to `p` within `radius`, other than the roads in `except`.
    pub fn nearest_road_except(&self, p: DVec2, radius: f64, except: &[RoadId]) -> Option<RoadId> {
        self.path_index
            .segments_within(p, radius)
            .into_iter()
            .find(|s| !except.contains(&s.key.0))
            .map(|s| s.key.0)
    }

    /// The path segments that share a point with the segment `a–b`, ordered along it:
    /// `(road, segment index, how they meet)`.
    pub fn path_hits(&self, a: DVec2, b: DVec2) -> Vec<(RoadId, u32, f64, SegmentIntersection)> {
        self.path_index
            .segments_crossing(a, b)
            .into_iter()
            .map(|h| (h.key.0, h.key.1, h.t, h.kind))
            .collect()
    }

    /// The current state of the items a patch names (for undo).
    pub(crate) fn snapshot(&self, like: &Patch) -> Patch {
        Patch {
            nodes: like
                .nodes
                .iter()
                .map(|(id, _)| (*id, self.nodes.get(id).cloned()))
                .collect(),
            roads: like
                .roads
                .iter()
                .map(|(id, _)| (*id, self.roads.get(id).cloned()))
                .collect(),
            next_node: self.next_node,
            next_road: self.next_road,
        }
    }

    /// Writes a patch's states (index and adjacency kept up to date).
    pub(crate) fn apply(&mut self, patch: &Patch) -> Result<(), PrimaryError> {
        for (id, road) in &patch.roads {
            self.set_road(*id, road.clone())?;
        }
        for (id, node) in &patch.nodes {
            self.set_node(*id, node.clone())?;
        }
        self.next_node = patch.next_node;
        self.next_road = patch.next_road;
        self.revision += 1;
        Ok(())
    }

    fn set_node(&mut self, id: ControlId, node: Option<ControlNode>) -> Result<(), PrimaryError> {
        self.node_index.remove(id);
        match node {
            Some(n) => {
                self.node_index.insert_point(id, n.pos)?;
                self.nodes.insert(id, n);
            }
            None => {
                self.nodes.remove(&id);
            }
        }
        Ok(())
    }

    fn set_road(&mut self, id: RoadId, road: Option<PrimaryRoad>) -> Result<(), PrimaryError> {
        if let Some(old) = self.roads.remove(&id) {
            for k in 0..old.path.points.len().saturating_sub(1) {
                self.path_index.remove((id, k as u32));
            }
            for end in [old.a, old.b] {
                if let Some(list) = self.incident.get_mut(&end) {
                    list.retain(|&r| r != id);
                    if list.is_empty() {
                        self.incident.remove(&end);
                    }
                }
            }
        }
        if let Some(road) = road {
            for (k, w) in road.path.points.windows(2).enumerate() {
                self.path_index.insert_segment((id, k as u32), w[0], w[1])?;
            }
            for end in [road.a, road.b] {
                let list = self.incident.entry(end).or_default();
                if let Err(pos) = list.binary_search(&id) {
                    list.insert(pos, id);
                }
            }
            self.roads.insert(id, road);
        }
        Ok(())
    }

    /// Checks every invariant of the [module docs](self).
    ///
    /// # Errors
    /// [`PrimaryError::BadData`] describing the first violation.
    pub fn check_invariants(&self) -> Result<(), PrimaryError> {
        let bad = |s: String| Err(PrimaryError::BadData(s));
        for (&id, n) in &self.nodes {
            if id.0 >= self.next_node {
                return bad(format!(
                    "node {id} is not below the next id {}",
                    self.next_node
                ));
            }
            if !n.pos.is_finite() || !n.elevation.is_finite() {
                return bad(format!("node {id} has a non-finite position or elevation"));
            }
            if let Some(other) = self
                .node_index
                .points_within(n.pos, 0.0)
                .iter()
                .find(|x| x.key != id)
            {
                return bad(format!("nodes {id} and {} coincide", other.key));
            }
        }
        for (&id, r) in &self.roads {
            if id.0 >= self.next_road {
                return bad(format!(
                    "road {id} is not below the next id {}",
                    self.next_road
                ));
            }
            let (Some(na), Some(nb)) = (self.nodes.get(&r.a), self.nodes.get(&r.b)) else {
                return bad(format!("road {id} joins a missing node"));
            };
            if r.a == r.b {
                return bad(format!("road {id} is a loop"));
            }
            let p = &r.path;
            let n = p.points.len();
            if n < 2 || p.points[0] != na.pos || p.points[n - 1] != nb.pos {
                return bad(format!(
                    "road {id}'s path does not run from its first node to its second"
                ));
            }
            if p.elevation.len() != n || p.bridge.len() != n - 1 {
                return bad(format!("road {id}'s path has inconsistent lengths"));
            }
            if p.points.iter().any(|q| !q.is_finite()) || p.points.windows(2).any(|w| w[0] == w[1])
            {
                return bad(format!("road {id}'s path has a bad or repeated vertex"));
            }
            let plot_ok = p.plot.first() == Some(&0)
                && p.plot.last() == Some(&((n - 1) as u32))
                && p.plot.windows(2).all(|w| w[0] < w[1]);
            if !plot_ok {
                return bad(format!(
                    "road {id}'s plot indices are not increasing from 0 to the end"
                ));
            }
            if self.roads_at(r.a).binary_search(&id).is_err()
                || self.roads_at(r.b).binary_search(&id).is_err()
            {
                return bad(format!("road {id} is missing from its nodes' adjacency"));
            }
        }
        self.check_planar()
    }

    /// The planarity part of [`check_invariants`](Self::check_invariants).
    fn check_planar(&self) -> Result<(), PrimaryError> {
        for (&id, r) in &self.roads {
            let pts = &r.path.points;
            for (k, w) in pts.windows(2).enumerate() {
                for h in self.path_index.segments_crossing(w[0], w[1]) {
                    let (other, j) = h.key;
                    if other == id && (j as usize).abs_diff(k) <= 1 {
                        // Neighbouring segments share their common vertex.
                        let common = if j as usize == k + 1 { w[1] } else { w[0] };
                        if j as usize == k
                            || matches!(h.kind, SegmentIntersection::Touching { point, .. } if point == common)
                        {
                            continue;
                        }
                    }
                    if other != id
                        && let SegmentIntersection::Touching { point, .. } = h.kind
                        && self.shared_end(id, other, point)
                    {
                        continue;
                    }
                    return Err(PrimaryError::BadData(format!(
                        "paths of roads {id} and {other} meet away from a shared node: {:?}",
                        h.kind
                    )));
                }
            }
        }
        for (&id, n) in &self.nodes {
            for s in self.path_index.segments_within(n.pos, 0.0) {
                let Some(r) = self.roads.get(&s.key.0) else {
                    return Err(PrimaryError::BadData(format!(
                        "index names dead road {}",
                        s.key.0
                    )));
                };
                let last = r.path.points.len().saturating_sub(2) as u32;
                let at_end = (r.a == id && s.key.1 == 0) || (r.b == id && s.key.1 == last);
                if !at_end {
                    return Err(PrimaryError::BadData(format!(
                        "node {id} lies on road {}",
                        s.key.0
                    )));
                }
            }
        }
        Ok(())
    }

    /// Whether `point` is the position of a node that ends both roads.
    fn shared_end(&self, r1: RoadId, r2: RoadId, point: DVec2) -> bool {
        let (Some(x), Some(y)) = (self.roads.get(&r1), self.roads.get(&r2)) else {
            return false;
        };
        [x.a, x.b]
            .into_iter()
            .any(|n| (y.a == n || y.b == n) && self.nodes.get(&n).is_some_and(|nd| nd.pos == point))
    }

    /// The network as JSON (byte-stable: maps in id order, shortest round-trip floats).
    ///
    /// # Errors
    /// [`PrimaryError::BadData`] if serialisation fails.
    pub fn to_json(&self) -> Result<String, PrimaryError> {
        serde_json::to_string(self).map_err(|e| PrimaryError::BadData(e.to_string()))
    }

    /// A network from [`to_json`](Self::to_json) output; every invariant is checked.
    ///
    /// # Errors
    /// [`PrimaryError::BadData`] for malformed or inconsistent data.
    pub fn from_json(json: &str) -> Result<Self, PrimaryError> {
        serde_json::from_str(json).map_err(|e| PrimaryError::BadData(e.to_string()))
    }
}

#[derive(Serialize)]
struct NetworkRef<'a> {
    next_node: u64,
    next_road: u64,
    nodes: &'a BTreeMap<ControlId, ControlNode>,
    roads: &'a BTreeMap<RoadId, PrimaryRoad>,
}

#[derive(Deserialize)]
struct NetworkData {
    next_node: u64,
    next_road: u64,
    nodes: BTreeMap<ControlId, ControlNode>,
    roads: BTreeMap<RoadId, PrimaryRoad>,
}

impl Serialize for PrimaryNetwork {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        NetworkRef {
            next_node: self.next_node,
            next_road: self.next_road,
            nodes: &self.nodes,
            roads: &self.roads,
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for PrimaryNetwork {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let data = NetworkData::deserialize(d)?;
        let mut net = PrimaryNetwork::new();
        let patch = Patch {
            nodes: data.nodes.into_iter().map(|(k, v)| (k, Some(v))).collect(),
            roads: data.roads.into_iter().map(|(k, v)| (k, Some(v))).collect(),
            next_node: data.next_node,
            next_road: data.next_road,
        };
        net.apply(&patch).map_err(serde::de::Error::custom)?;
        net.check_invariants().map_err(serde::de::Error::custom)?;
        net.revision = 0;
        Ok(net)
    }
}

/// A cut of a path: at a vertex, or at a point inside a segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Cut {
    /// The segment index.
    pub seg: usize,
    /// The point, on segment `seg` (possibly equal to its first vertex).
    pub point: DVec2,
    /// The elevation there.
    pub elevation: f64,
}

/// Cuts `path` at `cuts` (sorted along the path, strictly inside it) into pieces; each cut
/// point ends one piece and starts the next, as a plot point of both.
pub(crate) fn cut_path(path: &RoadPath, cuts: &[Cut]) -> Vec<RoadPath> {
    let pts = &path.points;
    let mut pieces = Vec::with_capacity(cuts.len() + 1);
    let mut cur = RoadPath {
        points: vec![pts[0]],
        elevation: vec![path.elevation[0]],
        plot: vec![0],
        bridge: Vec::new(),
    };
    let mut plot = path.plot.iter().peekable();
    plot.next();
    let finish = |cur: &mut RoadPath, pieces: &mut Vec<RoadPath>, start: DVec2, h: f64| {
        let last = (cur.points.len() - 1) as u32;
        if cur.plot.last() != Some(&last) {
            cur.plot.push(last);
        }
        pieces.push(std::mem::replace(
            cur,
            RoadPath {
                points: vec![start],
                elevation: vec![h],
                plot: vec![0],
                bridge: Vec::new(),
            },
        ));
    };
    let mut ci = 0;
    for i in 0..pts.len() - 1 {
        while let Some(c) = cuts.get(ci).filter(|c| c.seg == i) {
            if c.point != pts[i] {
                cur.points.push(c.point);
                cur.elevation.push(c.elevation);
                cur.bridge.push(path.bridge[i]);
            }
            finish(&mut cur, &mut pieces, c.point, c.elevation);
            ci += 1;
        }
        cur.points.push(pts[i + 1]);
        cur.elevation.push(path.elevation[i + 1]);
        cur.bridge.push(path.bridge[i]);
        if plot.peek().is_some_and(|&&k| k as usize == i + 1) {
            plot.next();
            cur.plot.push((cur.points.len() - 1) as u32);
        }
    }
    pieces.push(cur);
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cutting_keeps_every_vertex_and_plot_point() {
        let path = RoadPath {
            points: (0..5)
                .map(|i| DVec2::new(f64::from(i) * 10.0, 0.0))
                .collect(),
            elevation: vec![0.0; 5],
            plot: vec![0, 2, 4],
            bridge: vec![false, true, false, false],
        };
        let cuts = [
            Cut {
                seg: 1,
                point: DVec2::new(15.0, 0.0),
                elevation: 1.0,
            },
            Cut {
                seg: 3,
                point: DVec2::new(30.0, 0.0),
                elevation: 0.0,
            },
        ];
        let pieces = cut_path(&path, &cuts);
        assert_eq!(pieces.len(), 3);
        assert_eq!(
            pieces[0].points,
            vec![DVec2::ZERO, DVec2::new(10.0, 0.0), DVec2::new(15.0, 0.0)]
        );
        assert_eq!(pieces[0].bridge, vec![false, true]);
        assert_eq!(pieces[0].plot, vec![0, 2]);
        assert_eq!(
            pieces[1].points,
            vec![
                DVec2::new(15.0, 0.0),
                DVec2::new(20.0, 0.0),
                DVec2::new(30.0, 0.0)
            ]
        );
        assert_eq!(pieces[1].plot, vec![0, 1, 2]);
        assert_eq!(pieces[1].bridge, vec![true, false]);
        assert_eq!(
            pieces[2].points,
            vec![DVec2::new(30.0, 0.0), DVec2::new(40.0, 0.0)]
        );
        assert_eq!(pieces[2].plot, vec![0, 1]);
    }
}
