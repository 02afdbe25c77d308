//! [`StatsError`]: what the statistics report rejects.

/// An error of the statistics report: input it cannot measure, or a reference city it
/// does not know.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StatsError {
    /// A street edge names a node that does not exist.
    #[error("street edge {edge} joins node {node}, but the graph has only {nodes} nodes")]
    NodeOutOfRange {
        /// The edge's index.
        edge: usize,
        /// The node index it names.
        node: usize,
        /// How many nodes there are.
        nodes: usize,
    },
    /// A coordinate, width, height, elevation or area is NaN or infinite, a coordinate
    /// lies beyond `polis_geom::MAX_COORDINATE`, or a width, height or area is negative.
    #[error(
        "{what} is {value}; give a finite value (coordinates within ±1e8 m, widths, heights and areas ≥ 0)"
    )]
    BadValue {
        /// Which value (`street node 4`, `lot 7 street edge`, `building 3 height`).
        what: String,
        /// The value given.
        value: f64,
    },
    /// The elevation list does not have one value per node.
    #[error("{elevations} elevations for {nodes} nodes; give one per node")]
    ElevationCount {
        /// Elevations given.
        elevations: usize,
        /// Nodes in the graph.
        nodes: usize,
    },
    /// A lot names a street edge its polygon does not have.
    #[error("lot {lot} names street edge {edge}, but its polygon has {edges} edges")]
    LotEdgeOutOfRange {
        /// The lot's index.
        lot: usize,
        /// The edge index it names.
        edge: usize,
        /// Edges of its polygon.
        edges: usize,
    },
    /// No reference city of that name.
    #[error("no reference city named {name:?}; known: {known}")]
    UnknownCity {
        /// The name asked for.
        name: String,
        /// Some names that exist (regions and cities), comma-separated.
        known: String,
    },
    /// A reference table row could not be read.
    #[error("reference table line {line}: {reason}")]
    Reference {
        /// 1-based line of the CSV text.
        line: usize,
        /// What is wrong.
        reason: String,
    },
}
