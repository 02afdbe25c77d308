//! The error type of `polis-cells`.

use polis_geom::{DVec2, EdgeId, GeomError, NodeId};

/// One way in which the input graph fails to be planar.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Conflict {
    /// Two edges cross at a point interior to both.
    Crossing {
        /// The edge with the smaller id.
        first: EdgeId,
        /// The other edge.
        second: EdgeId,
        /// Where they cross (computed after the exact decision).
        point: DVec2,
    },
    /// Two collinear edges share a piece of positive length.
    Overlap {
        /// The edge with the smaller id.
        first: EdgeId,
        /// The other edge.
        second: EdgeId,
    },
    /// A node lies inside an edge it is not an end of (a T-junction without a node).
    NodeOnEdge {
        /// The node.
        node: NodeId,
        /// The edge whose interior it lies on.
        edge: EdgeId,
        /// The node's position.
        point: DVec2,
    },
}

impl std::fmt::Display for Conflict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Conflict::Crossing {
                first,
                second,
                point,
            } => write!(f, "edges {first} and {second} cross at {point}"),
            Conflict::Overlap { first, second } => {
                write!(f, "edges {first} and {second} overlap")
            }
            Conflict::NodeOnEdge { node, edge, point } => {
                write!(f, "node {node} at {point} lies inside edge {edge}")
            }
        }
    }
}

/// Formats the first few conflicts for an error message.
fn list(conflicts: &[Conflict], total: usize) -> String {
    let mut s = conflicts
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("; ");
    if total > conflicts.len() {
        s.push_str(&format!(" (and {} more)", total - conflicts.len()));
    }
    s
}

/// What went wrong while extracting cells.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CellsError {
    /// The graph is not planar: edges cross, overlap, or pass through nodes.
    #[error(
        "the road graph is not planar: {}; insert roads with `PlanarGraph::insert_segment` (which splits at crossings) or fix the listed edges",
        list(.conflicts, *.total)
    )]
    NotPlanar {
        /// The first conflicts found, in increasing order of edge ids (at most
        /// [`MAX_REPORTED_CONFLICTS`](crate::MAX_REPORTED_CONFLICTS)).
        conflicts: Vec<Conflict>,
        /// How many conflicts there are in all.
        total: usize,
    },
    /// Two nodes share a position and the parameters say to reject that.
    #[error(
        "nodes {first} and {second} are both at {point}; merge them, or set `coincident_nodes` to `Merge`"
    )]
    CoincidentNodes {
        /// The node with the smaller id.
        first: NodeId,
        /// The other node.
        second: NodeId,
        /// The shared position.
        point: DVec2,
    },
    /// The graph has more edges than this crate's compact half-edge indices can hold.
    #[error(
        "the graph has {edges} edge slots; at most {limit} are supported, split the graph into regions"
    )]
    TooLarge {
        /// Edge slots in the graph ([`polis_geom::PlanarGraph::edge_bound`]).
        edges: usize,
        /// The limit.
        limit: usize,
    },
    /// An error from the geometry kernel (a bad id or coordinate in the graph).
    #[error(transparent)]
    Geom(#[from] GeomError),
    /// An internal consistency check failed: a bug in this crate.
    #[error("internal error in cell extraction: {0}; please report the input graph")]
    Internal(String),
}

/// The former name of [`CellsError`], kept so existing code compiles: every polis crate
/// names its error `<Crate>Error`.
pub type Error = CellsError;
