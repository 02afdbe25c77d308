//! The output: a planar road graph with typed junctions and roads.

use polis_geom::{DVec2, PlanarGraph};
use serde::{Deserialize, Serialize};

/// The two road classes of Parish & Müller (§3.2.1): highways connect population
/// centres; streets fill the areas between them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum RoadClass {
    /// A highway: long segments, follows population peaks, branches rarely, may bridge water.
    Highway,
    /// A street: short segments, follows the dominant pattern, branches where populated.
    Street,
}

/// A junction (node payload) of the network.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Junction {
    /// Derivation step at which the junction was created.
    pub step: u32,
}

/// A road (edge payload) of the network.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Road {
    /// Highway or street.
    pub class: RoadClass,
    /// Carriageway width in metres.
    pub width: f64,
    /// `true` when the road crosses an illegal area (water): a bridge (or tunnel) at the
    /// geometry stage. Such a road is never longer than
    /// [`RoadParams::max_bridge_length_m`](crate::RoadParams::max_bridge_length_m).
    pub bridge: bool,
    /// `true` when the road passes under illegal land (a park, a slope over the limit)
    /// between two portals: a tunnel ([`crate::tunnels`]), never longer than
    /// [`RoadParams::max_tunnel_length_m`](crate::RoadParams::max_tunnel_length_m); no
    /// other road meets it between its ends. Never set together with `bridge`.
    /// Default (serde): `false`.
    #[serde(default)]
    pub tunnel: bool,
    /// Derivation step of the L-system at which the segment was created.
    pub step: u32,
}

/// The road network: a planar straight-line graph (every crossing is a node) of
/// [`Junction`]s and [`Road`]s. `check_invariants()` holds after every generator call.
pub type RoadNetwork = PlanarGraph<Junction, Road>;

/// Summary numbers of a network.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct NetworkStats {
    /// Live junctions.
    pub junctions: usize,
    /// Live edges.
    pub edges: usize,
    /// Total highway length, metres.
    pub highway_length_m: f64,
    /// Total street length, metres.
    pub street_length_m: f64,
    /// Total bridge length, metres.
    pub bridge_length_m: f64,
    /// Total tunnel length, metres.
    pub tunnel_length_m: f64,
    /// Junctions of degree 1 (dead ends).
    pub dead_ends: usize,
}

/// Counts and lengths of `network`.
pub fn network_stats(network: &RoadNetwork) -> NetworkStats {
    let mut s = NetworkStats {
        junctions: network.node_count(),
        edges: network.edge_count(),
        ..NetworkStats::default()
    };
    for (e, _, _, road) in network.edges() {
        let len = network.edge_length(e).unwrap_or(0.0);
        match road.class {
            RoadClass::Highway => s.highway_length_m += len,
            RoadClass::Street => s.street_length_m += len,
        }
        if road.bridge {
            s.bridge_length_m += len;
        }
        if road.tunnel {
            s.tunnel_length_m += len;
        }
    }
    s.dead_ends = network
        .node_ids()
        .filter(|&n| network.degree(n).unwrap_or(0) == 1)
        .count();
    s
}

/// Unit direction of the angle `a` (radians, counter-clockwise from +x).
#[inline]
pub(crate) fn dir(a: f64) -> DVec2 {
    DVec2::new(a.cos(), a.sin())
}

/// The angle of the vector `v` (radians).
#[inline]
pub(crate) fn angle_of(v: DVec2) -> f64 {
    v.y.atan2(v.x)
}

/// The smallest absolute difference between two angles, in `[0, π]`.
#[inline]
pub(crate) fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(std::f64::consts::TAU);
    d.min(std::f64::consts::TAU - d)
}
