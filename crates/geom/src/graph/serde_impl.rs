//! serde for [`PlanarGraph`]: nodes and edges by id (removed ids as `null`), the rotation
//! system and spatial indexes rebuilt on load.

use glam::DVec2;
#[cfg(feature = "serde")]
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{NodeId, PlanarGraph};
use crate::error::GeomError;

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
struct NodeOut<'a, N> {
    position: DVec2,
    payload: &'a N,
}

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
struct EdgeOut<'a, E> {
    ends: [NodeId; 2],
    payload: &'a E,
}

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename = "PlanarGraph"))]
struct GraphOut<'a, N, E> {
    nodes: Vec<Option<NodeOut<'a, N>>>,
    edges: Vec<Option<EdgeOut<'a, E>>>,
}

#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
struct NodeIn<N> {
    position: DVec2,
    payload: N,
}

#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
struct EdgeIn<E> {
    ends: [NodeId; 2],
    payload: E,
}

#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename = "PlanarGraph"))]
struct GraphIn<N, E> {
    nodes: Vec<Option<NodeIn<N>>>,
    edges: Vec<Option<EdgeIn<E>>>,
}

#[cfg(feature = "serde")]
/// Serialised as `{ "nodes": [{ "position": [x, y], "payload": … } or null, …],
/// "edges": [{ "ends": [a, b], "payload": … } or null, …] }`, where the index in each list
/// is the id and `null` marks a removed id.
impl<N: Serialize, E: Serialize> Serialize for PlanarGraph<N, E> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let out = GraphOut {
            nodes: self
                .nodes
                .iter()
                .map(|n| {
                    n.as_ref().map(|n| NodeOut {
                        position: n.pos,
                        payload: &n.payload,
                    })
                })
                .collect(),
            edges: self
                .edges
                .iter()
                .map(|e| {
                    e.as_ref().map(|e| EdgeOut {
                        ends: e.ends,
                        payload: &e.payload,
                    })
                })
                .collect(),
        };
        out.serialize(serializer)
    }
}

#[cfg(feature = "serde")]
/// Loads what [`Serialize`] wrote, keeping every id, and rebuilds the counter-clockwise
/// adjacency and the spatial indexes. Checks what [`PlanarGraph::add_node`] and
/// [`PlanarGraph::add_edge`] check (coordinates, live distinct ends, no duplicate edge);
/// call [`PlanarGraph::check_invariants`] to also verify planarity.
impl<'de, N: Deserialize<'de>, E: Deserialize<'de>> Deserialize<'de> for PlanarGraph<N, E> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let input = GraphIn::<N, E>::deserialize(deserializer)?;
        Self::from_parts(input).map_err(serde::de::Error::custom)
    }
}

impl<N, E> PlanarGraph<N, E> {
    fn from_parts(input: GraphIn<N, E>) -> Result<Self, GeomError> {
        let mut g = PlanarGraph::new();
        for n in input.nodes {
            match n {
                Some(n) => {
                    g.add_node(n.position, n.payload)?;
                }
                None => g.nodes.push(None),
            }
        }
        for e in input.edges {
            match e {
                Some(e) => {
                    g.add_edge(e.ends[0], e.ends[1], e.payload)?;
                }
                None => g.edges.push(None),
            }
        }
        Ok(g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_ids_and_order() {
        let mut g: PlanarGraph<String, u32> = PlanarGraph::new();
        let c = g.add_node(DVec2::new(0.0, 0.0), "c".into()).unwrap();
        // Short decimals: serde_json without its `float_roundtrip` feature may round
        // long ones by an ulp on reading.
        let pts = [
            (1.0, 0.0),
            (0.5, 2.25),
            (-1.0, 0.125),
            (-3.0, -1.5),
            (0.75, -1.0),
        ];
        let ids: Vec<NodeId> = pts
            .iter()
            .enumerate()
            .map(|(i, &(x, y))| g.add_node(DVec2::new(x, y), format!("n{i}")).unwrap())
            .collect();
        for (k, &n) in ids.iter().enumerate() {
            g.add_edge(c, n, k as u32).unwrap();
        }
        g.remove_node(ids[1]).unwrap();
        let e = g.find_edge(c, ids[3]).unwrap();
        g.remove_edge(e).unwrap();
        let json = serde_json::to_string(&g).unwrap();
        let back: PlanarGraph<String, u32> = serde_json::from_str(&json).unwrap();
        back.check_invariants().unwrap();
        assert_eq!(back.node_bound(), g.node_bound());
        assert_eq!(back.edge_bound(), g.edge_bound());
        assert_eq!(back.edges_at(c).unwrap(), g.edges_at(c).unwrap());
        let a: Vec<_> = g.edges().map(|(e, a, b, p)| (e, a, b, *p)).collect();
        let b: Vec<_> = back.edges().map(|(e, a, b, p)| (e, a, b, *p)).collect();
        assert_eq!(a, b);
        assert_eq!(back.node_payload(ids[4]).unwrap(), "n4");
        assert!(!back.contains_node(ids[1]));
        assert_eq!(serde_json::to_string(&back).unwrap(), json);
    }

    #[test]
    fn malformed_input_is_an_error() {
        let bad = [
            r#"{"nodes":[{"position":[0,0],"payload":null}],"edges":[{"ends":[0,0],"payload":null}]}"#,
            r#"{"nodes":[{"position":[0,0],"payload":null}],"edges":[{"ends":[0,7],"payload":null}]}"#,
            r#"{"nodes":[{"position":[0,0],"payload":null},null],"edges":[{"ends":[0,1],"payload":null}]}"#,
            r#"{"nodes":[{"position":[1e300,0],"payload":null}],"edges":[]}"#,
            r#"{"nodes":[{"position":[0,0],"payload":null},{"position":[1,0],"payload":null}],"edges":[{"ends":[0,1],"payload":null},{"ends":[1,0],"payload":null}]}"#,
            r#"{"nodes":[{"position":[0],"payload":null}],"edges":[]}"#,
        ];
        for s in bad {
            assert!(
                serde_json::from_str::<PlanarGraph<(), ()>>(s).is_err(),
                "{s}"
            );
        }
    }
}
