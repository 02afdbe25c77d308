//! The builders' street map converted to a planar road graph.
//!
//! Each maximal straight run of linked grid points becomes one segment (points where a
//! street only passes straight through are not nodes), and each join becomes a segment
//! from its grid point to its boundary point. All are added with
//! [`PlanarGraph::insert_segment_with`](polis_geom::PlanarGraph::insert_segment_with), which
//! decides every touch and crossing with exact predicates and splits there, so junctions
//! are nodes and the graph is planar by construction.

use polis_geom::graph::SnapOptions;
use polis_geom::{DVec2, NodeId};

use super::error::Result;
use super::lattice::{Dir, Frame, Site};
use crate::network::{Junction, Road, RoadClass, RoadNetwork};

/// Snap distance of the conversion as a fraction of the grid step (capped at 1 cm): far
/// below the smallest distance between distinct points the builders make (5 % of a step).
const SNAP_FRACTION: f64 = 1e-3;

fn street(width: f64, step: u32) -> Road {
    Road {
        class: RoadClass::Street,
        width,
        bridge: false,
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
        for (k, s) in sites.iter().enumerate() {
            if s.links & forward.bit() == 0 || s.links & back.bit() != 0 {
                continue;
            }
            // k starts a run towards `forward`: walk to its end.
            let (mut end, mut born) = (k, s.born);
            while sites[end].links & forward.bit() != 0 {
                match frame.neighbor(end, forward) {
                    Some(n) => end = n,
                    None => break,
                }
                born = born.max(sites[end].born);
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
