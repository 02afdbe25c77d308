//! Street stubs that dangle into empty land outside every cell are pruned after the cell
//! stage (issue 19's plan defects).
//!
//! A street that grew out of the city's fringe and never closed a block lies outside
//! every cell: no block, so no lot, is ever made along it. Such a stub reads as a defect
//! on a plan (a road to nowhere), so it is removed: the street edges of the outer
//! filaments are stripped leaf by leaf, from each dead end lying in land and away from
//! the map's edge, until a junction, the map edge or water is reached. Dead ends at the
//! map edge (streets that continue beyond the map) and in water (a quay, a bridge head)
//! stay; so do highways (they connect population centres, not lots) and the filaments
//! inside cells (the lot stage cuts them into the blocks, so lots face them).
//!
//! The cells do not change: an outer filament is on no cycle and inside none.

use polis_cells::CellDecomposition;
use polis_geom::{DVec2, Field, NodeId};
use polis_roads::{RoadClass, RoadNetwork};

use crate::error::Result;

/// Dead ends this close to the map's edge are streets that continue beyond the map,
/// metres (the statistics report's `edge_margin_m`).
pub const MAP_EDGE_MARGIN_M: f64 = 10.0;

/// Removes the outer street stubs ending in land (see the module documentation) from
/// `network`, whose cells are `cells`. Returns how many edges were removed.
///
/// # Errors
/// A graph inconsistent with its cells (an id the network does not hold).
pub(crate) fn prune_outer_stubs(
    network: &mut RoadNetwork,
    cells: &CellDecomposition,
    size_m: f64,
    water: Option<&dyn Field>,
) -> Result<usize> {
    let half = size_m * 0.5;
    let in_land_inside = |p: DVec2| {
        let inner = (half - p.x.abs()).min(half - p.y.abs());
        inner > MAP_EDGE_MARGIN_M && !water.is_some_and(|w| w.sample(p) >= 0.5)
    };
    let mut outer = vec![false; network.edge_bound()];
    for f in &cells.outer_filaments {
        for &e in &f.edges {
            if let Some(slot) = outer.get_mut(e.index()) {
                *slot = true;
            }
        }
    }
    // Dead ends of outer filaments, in filament order (deterministic).
    let mut stack: Vec<NodeId> = cells
        .outer_filaments
        .iter()
        .flat_map(|f| [f.nodes.first(), f.nodes.last()])
        .flatten()
        .copied()
        .collect();
    let mut removed = 0;
    while let Some(n) = stack.pop() {
        if !network.contains_node(n) || network.degree(n)? != 1 {
            continue;
        }
        let e = network.edges_at(n)?[0];
        if !outer.get(e.index()).copied().unwrap_or(false)
            || network.edge_payload(e)?.class != RoadClass::Street
            || !in_land_inside(network.position(n)?)
        {
            continue;
        }
        let other = network.other_end(e, n)?;
        network.remove_edge(e)?;
        network.remove_node(n)?;
        removed += 1;
        if network.degree(other)? == 0 {
            network.remove_node(other)?;
        } else {
            stack.push(other);
        }
    }
    Ok(removed)
}
