//! [`PrimaryError`]: every refusal and failure of the primary network.

use polis_geom::{DVec2, GeomError};

use crate::legality::Illegal;
use crate::primary::network::{ControlId, RoadId};

/// Everything the primary network can refuse or fail at. A refused edit leaves the
/// network unchanged; the message says what was wrong and what to do instead.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PrimaryError {
    /// A parameter ([`AdaptiveParams`](crate::primary::AdaptiveParams),
    /// [`EditOptions`](crate::primary::EditOptions), a road width, …) is out of range.
    #[error("invalid primary-road parameter `{name}`: {reason}")]
    InvalidParameter {
        /// The field's name.
        name: &'static str,
        /// What was wrong and what to use instead.
        reason: String,
    },
    /// A coordinate is NaN, infinite or beyond [`polis_geom::MAX_COORDINATE`].
    #[error("bad coordinate {point} for {what}: use finite metres within ±1e8")]
    BadCoordinate {
        /// What the coordinate was for.
        what: &'static str,
        /// The coordinate.
        point: DVec2,
    },
    /// A node or a sample lies outside the map (or a map is NaN there).
    #[error("{point} is outside the map; place it inside the terrain's bounds")]
    OutsideMap {
        /// The point.
        point: DVec2,
    },
    /// A control node would stand in water or a park.
    #[error("a node cannot stand at {point}: the ground there is {what:?}")]
    IllegalNode {
        /// The point.
        point: DVec2,
        /// What is there.
        what: Illegal,
    },
    /// No control node with this id.
    #[error("there is no control node {0}")]
    UnknownNode(ControlId),
    /// No primary road with this id.
    #[error("there is no primary road {0}")]
    UnknownRoad(RoadId),
    /// A road from a node to itself.
    #[error("a road from node {0} to itself has no length; pick two different nodes")]
    SelfLoop(ControlId),
    /// The two nodes are already joined.
    #[error("nodes {a} and {b} are already joined by road {existing}")]
    DuplicateRoad {
        /// One end.
        a: ControlId,
        /// The other end.
        b: ControlId,
        /// The road joining them.
        existing: RoadId,
    },
    /// A new or moved node would be within the snap distance of another node.
    #[error("{point} is {distance:.2} m from node {node}, within the snap distance; use that node")]
    NodeTooClose {
        /// The proposed position.
        point: DVec2,
        /// The node in the way.
        node: ControlId,
        /// Their distance in metres.
        distance: f64,
    },
    /// A moved node would land on (within the snap distance of) a road not its own.
    #[error("{point} is on road {road} (within the snap distance); move the node elsewhere")]
    OnRoad {
        /// The proposed position.
        point: DVec2,
        /// The road.
        road: RoadId,
    },
    /// A road (or a piece of one between junctions) would be shorter than
    /// [`EditOptions::min_road_length_m`](crate::primary::EditOptions::min_road_length_m).
    #[error("a road piece at {at} would be {length:.3} m long, below the minimum {min} m")]
    ZeroLength {
        /// Where.
        at: DVec2,
        /// Its length in metres.
        length: f64,
        /// The minimum.
        min: f64,
    },
    /// The path would run along another road (collinear overlap).
    #[error("the path would run along road {road} near {at}; roads may cross but not overlap")]
    CollinearOverlap {
        /// The road overlapped.
        road: RoadId,
        /// A point of the overlap.
        at: DVec2,
    },
    /// Two roads would meet at an angle below
    /// [`EditOptions::min_angle_deg`](crate::primary::EditOptions::min_angle_deg).
    #[error("roads would meet at {angle_deg:.1}° at {at}, below the minimum {min_deg}°")]
    AngleTooSmall {
        /// The meeting point.
        at: DVec2,
        /// The angle in degrees.
        angle_deg: f64,
        /// The minimum.
        min_deg: f64,
    },
    /// A crossing would fall within the snap distance of a node (or of another crossing):
    /// the junction would be degenerate.
    #[error(
        "the path would cross road {road} at {at}, too close to a node or another crossing; connect to the node or move the road"
    )]
    CrossingNearNode {
        /// The crossing.
        at: DVec2,
        /// The road crossed.
        road: RoadId,
    },
    /// A re-plotted path (moved node, changed parameters) would cross another road.
    /// Moves and parameter changes never insert junctions (see the module docs).
    #[error(
        "the re-plotted road {road} would cross road {other} at {at}; move less far or delete one road"
    )]
    WouldCross {
        /// The re-plotted road.
        road: RoadId,
        /// The road in the way.
        other: RoadId,
        /// Where they would cross.
        at: DVec2,
    },
    /// A plotted path would cross itself.
    #[error(
        "the plotted path would cross itself at {at}; lower `deviation_deg` or raise `sample_size_m`"
    )]
    SelfCrossing {
        /// Where.
        at: DVec2,
    },
    /// No legal sample and no bridge possible: the way is blocked by a park or the map
    /// edge.
    #[error("the road is blocked at {at} by {what:?}: no sample of the fan is legal or bridgeable")]
    Blocked {
        /// The front's position.
        at: DVec2,
        /// What blocks it.
        what: Illegal,
    },
    /// Water would be crossed by a bridge longer than `max_bridge_m`.
    #[error(
        "the road would need a {length:.0} m bridge near {at}, longer than `max_bridge_m` = {max} m"
    )]
    BridgeTooLong {
        /// Where the bridge ends.
        at: DVec2,
        /// Its length in metres.
        length: f64,
        /// The limit.
        max: f64,
    },
    /// The plot would need more steps than the limit (a very long road with a tiny
    /// sample size).
    #[error("plotting would take {steps} steps, more than {max}; raise `sample_size_m`")]
    TooManySteps {
        /// Steps needed (bound).
        steps: f64,
        /// The limit.
        max: usize,
    },
    /// The preview was made for another state of the network.
    #[error("the preview is stale: the network changed since it was proposed; propose again")]
    StalePreview,
    /// Nothing to undo or redo.
    #[error("nothing to {0}")]
    NothingTo(&'static str),
    /// A loaded network, spec or GeoJSON is malformed or inconsistent.
    #[error("bad primary network data: {0}")]
    BadData(String),
    /// The geometry kernel refused an operation.
    #[error("geometry error in the primary network: {0}")]
    Geometry(#[from] GeomError),
}

impl From<PrimaryError> for crate::RoadError {
    fn from(e: PrimaryError) -> Self {
        match e {
            PrimaryError::Geometry(g) => crate::RoadError::Geometry(g),
            other => crate::RoadError::InvalidParameter {
                name: "primary network",
                reason: other.to_string(),
            },
        }
    }
}
