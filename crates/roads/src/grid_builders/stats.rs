//! [`StreetStats`]: how gridded and how dense a cell's streets are.

use polis_geom::{NodeId, PolygonWithHoles};
use serde::{Deserialize, Serialize};

use super::error::Result;
use super::graph::with_boundary;
use crate::network::RoadNetwork;

/// Street statistics of one cell's road graph (streets only, with the nodes where they
/// meet the cell boundary).
///
/// A boundary node is a junction with the boundary road, so it is counted apart from the
/// interior nodes; nodes of degree 2 (bends) are not junctions.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct StreetStats {
    /// Interior nodes of degree ≥ 3.
    pub junctions: usize,
    /// Interior nodes of degree ≥ 4.
    pub four_way: usize,
    /// Interior nodes of degree 1.
    pub dead_ends: usize,
    /// Nodes on the cell boundary (streets joining the boundary road).
    pub boundary_joins: usize,
    /// `four_way / junctions` (0 without junctions).
    pub four_way_share: f64,
    /// Dead ends among all street ends and junctions:
    /// `dead_ends / (junctions + dead_ends + boundary_joins)` (0 without any).
    pub dead_end_share: f64,
    /// `(four_way + boundary_joins) / (junctions + dead_ends + boundary_joins)`: the share
    /// of the "4-way-or-boundary" junctions.
    pub four_way_or_boundary_share: f64,
    /// Blocks: the faces the streets cut the cell into.
    pub blocks: usize,
    /// Cell area divided by `blocks`, m².
    pub mean_block_area_m2: f64,
    /// Total street length, metres.
    pub street_length_m: f64,
    /// Street length per cell area, km per km².
    pub density_km_per_km2: f64,
}

fn share(n: usize, d: usize) -> f64 {
    if d == 0 { 0.0 } else { n as f64 / d as f64 }
}

/// Measures `network` (the streets of `cell`, meeting its boundary at `boundary_nodes`).
///
/// Blocks are counted with Euler's formula on the streets plus the cell's rings
/// (inserted with exact predicates): bounded faces `E − V + C`, less one per hole.
///
/// # Errors
/// [`GridError::InvalidCell`](super::GridError::InvalidCell) when the cell's rings cannot be added to the graph (bad
/// coordinates).
pub fn street_stats(
    network: &RoadNetwork,
    boundary_nodes: &[NodeId],
    cell: &PolygonWithHoles,
) -> Result<StreetStats> {
    let mut s = StreetStats::default();
    for n in network.node_ids() {
        let degree = network.degree(n)?;
        if boundary_nodes.binary_search(&n).is_ok() {
            s.boundary_joins += 1;
        } else if degree == 1 {
            s.dead_ends += 1;
        } else if degree >= 3 {
            s.junctions += 1;
            if degree >= 4 {
                s.four_way += 1;
            }
        }
    }
    for (e, ..) in network.edges() {
        s.street_length_m += network.edge_length(e)?;
    }
    let ends = s.junctions + s.dead_ends + s.boundary_joins;
    s.four_way_share = share(s.four_way, s.junctions);
    s.dead_end_share = share(s.dead_ends, ends);
    s.four_way_or_boundary_share = share(s.four_way + s.boundary_joins, ends);

    let whole = with_boundary(network, cell, &[])?;
    let components = whole.connected_components().len();
    let bounded = (whole.edge_count() + components).saturating_sub(whole.node_count());
    s.blocks = bounded.saturating_sub(cell.holes.len());
    let area = cell.area();
    s.mean_block_area_m2 = if s.blocks == 0 {
        area
    } else {
        area / s.blocks as f64
    };
    s.density_km_per_km2 = if area > 0.0 {
        (s.street_length_m / 1000.0) / (area / 1.0e6)
    } else {
        0.0
    };
    Ok(s)
}
