//! The builders' street map converted to a planar road graph.
//!
//! Each straight run of linked grid points between two nodes (junctions, bends, ends,
//! joins; points a street only passes straight through are not nodes) becomes one
//! segment, and each join becomes a segment from its grid point to its boundary point.
//! All are added with
//! [`PlanarGraph::insert_segment_with`](polis_geom::PlanarGraph::insert_segment_with), which
//! decides every touch and crossing with exact predicates and splits there, so junctions
//! are nodes and the graph is planar by construction.

use polis_geom::graph::SnapOptions;
use polis_geom::{DVec2, NodeId};

use polis_geom::PolygonWithHoles;

use super::GridRoads;
use super::error::{GridError, Result};
use super::lattice::{Dir, Frame, Site};
use crate::network::{Junction, Road, RoadClass, RoadNetwork};

/// The payload of boundary and filament edges in [`GridRoads::cell_graph`]: the roads
/// around the cell, which are not the builders' to size.
pub const BOUNDARY_ROAD: Road = Road {
    class: RoadClass::Highway,
    width: 0.0,
    bridge: false,
    tunnel: false,
    step: 0,
};

impl GridRoads {
    /// The cell's whole road graph: the streets plus the cell's rings and `filaments` as
    /// [`BOUNDARY_ROAD`] edges ([`RoadClass::Highway`], width 0), inserted with exact
    /// predicates, so boundary edges are split where streets join them (and a street is
    /// split where a boundary vertex lies within the 1 cm snap distance of it). This is
    /// the shape of a cell's private graph in Kelly's secondary growth (boundary and
    /// filaments as highways, new roads as streets). Planar.
    ///
    /// # Errors
    /// [`GridError::InvalidCell`] when a ring or filament has bad coordinates.
    pub fn cell_graph(
        &self,
        cell: &PolygonWithHoles,
        filaments: &[[DVec2; 2]],
    ) -> Result<RoadNetwork> {
        with_boundary(&self.network, cell, filaments)
    }
}

/// `network` plus the rings of `cell` and `filaments` as [`BOUNDARY_ROAD`] edges.
pub(crate) fn with_boundary(
    network: &RoadNetwork,
    cell: &PolygonWithHoles,
    filaments: &[[DVec2; 2]],
) -> Result<RoadNetwork> {
    let mut whole = network.clone();
    let opts = SnapOptions::default();
    let rings = cell.rings().flat_map(|(_, ring)| ring.edges());
    for (a, b) in rings.chain(filaments.iter().map(|&[a, b]| (a, b))) {
        whole
            .insert_segment(a, b, BOUNDARY_ROAD, &opts)
            .map_err(GridError::InvalidCell)?;
    }
    Ok(whole)
}

/// Snap distance of the conversion as a fraction of the grid step (capped at 1 cm): far
/// below the smallest distance between distinct points the builders make (5 % of a step).
const SNAP_FRACTION: f64 = 1e-3;

fn street(width: f64, step: u32) -> Road {
    Road {
        class: RoadClass::Street,
        width,
        bridge: false,
        tunnel: false,
        step,
    }
}

/// The planar graph of `sites` and `joins`; also returns the nodes on the boundary
/// (sorted, without repeats).
pub(crate) fn to_network(
    frame: &Frame,
    sites: &[Site],
    joins: &[(usize, DVec2)],
    width: f64,
) -> Result<(RoadNetwork, Vec<NodeId>)> {
    let mut g = RoadNetwork::new();
    let opts = SnapOptions {
        snap_distance: (frame.step * SNAP_FRACTION).min(0.01),
    };
    for (forward, back) in [(Dir::East, Dir::West), (Dir::North, Dir::South)] {
        // A point the street only passes straight through is not a node.
        let straight = forward.bit() | back.bit();
        let through = |s: &Site| s.links == straight && !s.joined;
        for (k, s) in sites.iter().enumerate() {
            if s.links & forward.bit() == 0 || through(s) {
                continue;
            }
            // k is a node with a street towards `forward`: walk to the next node.
            let (mut end, mut born) = (k, s.born);
            while let Some(n) = frame.neighbor(end, forward) {
                end = n;
                born = born.max(sites[end].born);
                if !through(&sites[end]) {
                    break;
                }
            }
            let (a, b) = (frame.position(k), frame.position(end));
            g.insert_segment_with(a, b, street(width, born), &opts, |_| Junction {
                step: born,
            })?;
        }
    }
    let mut boundary = Vec::with_capacity(joins.len());
    for &(k, hit) in joins {
        if !sites[k].joined {
            continue; // pruned
        }
        let born = sites[k].born;
        let r =
            g.insert_segment_with(frame.position(k), hit, street(width, born), &opts, |_| {
                Junction { step: born }
            })?;
        boundary.extend(r.nodes.last().copied());
    }
    boundary.sort_unstable();
    boundary.dedup();
    Ok((g, boundary))
}
