//! [`Cell::road_graph`]: the private road graph of one cell (Kelly §4.3.1: "each cell is
//! self-contained and consists of a private road graph with the boundary cycle, filament
//! roads" …), for growing secondary roads inside it independently of the other cells.

use std::collections::BTreeMap;

use polis_geom::{EdgeId, NodeId, PlanarGraph};

use crate::error::Error;
use crate::output::Cell;

/// A cell's own road graph and the way back to the input graph.
#[derive(Debug, Clone)]
pub struct CellGraph<N, E> {
    /// The boundary cycle, the islands' outlines and the filaments inside the cell, with
    /// clones of the input payloads.
    pub graph: PlanarGraph<N, E>,
    /// By node index of `graph`: the input node it copies.
    pub nodes: Vec<NodeId>,
    /// By edge index of `graph`: the input edge it copies.
    pub edges: Vec<EdgeId>,
}

impl Cell {
    /// Copies this cell's roads out of `graph` (the graph the cell was extracted from):
    /// the boundary, the hole outlines and the filaments, in that order, each edge once.
    ///
    /// # Errors
    /// [`Error::Geom`] when an id of the cell does not name a live node or edge of `graph`
    /// (a different graph, or one edited since the extraction).
    pub fn road_graph<N: Clone, E: Clone>(
        &self,
        graph: &PlanarGraph<N, E>,
    ) -> Result<CellGraph<N, E>, Error> {
        let mut out = CellGraph {
            graph: PlanarGraph::new(),
            nodes: Vec::new(),
            edges: Vec::new(),
        };
        let mut node_of: BTreeMap<NodeId, NodeId> = BTreeMap::new();
        let mut seen: BTreeMap<EdgeId, EdgeId> = BTreeMap::new();
        let edges = self
            .boundary
            .edges
            .iter()
            .chain(self.holes.iter().flat_map(|h| h.edges.iter()))
            .chain(self.filaments.iter().flat_map(|f| f.edges.iter()));
        for &e in edges {
            if seen.contains_key(&e) {
                continue;
            }
            let (a, b) = graph.endpoints(e)?;
            let mut local = [a, b];
            for (slot, n) in local.iter_mut().zip([a, b]) {
                *slot = match node_of.get(&n) {
                    Some(&m) => m,
                    None => {
                        let m = out
                            .graph
                            .add_node(graph.position(n)?, graph.node_payload(n)?.clone())?;
                        out.nodes.push(n);
                        node_of.insert(n, m);
                        m
                    }
                };
            }
            let ne = out
                .graph
                .add_edge(local[0], local[1], graph.edge_payload(e)?.clone())?;
            out.edges.push(e);
            seen.insert(e, ne);
        }
        for iso in &self.isolated_nodes {
            if let std::collections::btree_map::Entry::Vacant(slot) = node_of.entry(iso.node) {
                let m = out.graph.add_node(
                    graph.position(iso.node)?,
                    graph.node_payload(iso.node)?.clone(),
                )?;
                out.nodes.push(iso.node);
                slot.insert(m);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use polis_geom::DVec2;

    use super::*;

    #[test]
    fn cell_with_island_and_dead_end() {
        let mut g: PlanarGraph<u8, &str> = PlanarGraph::new();
        let sq = |g: &mut PlanarGraph<u8, &str>, x0: f64, s: f64, tag: &'static str| {
            let ids: Vec<NodeId> = [(x0, x0), (x0 + s, x0), (x0 + s, x0 + s), (x0, x0 + s)]
                .iter()
                .map(|&(x, y)| g.add_node(DVec2::new(x, y), 1).unwrap())
                .collect();
            for i in 0..4 {
                g.add_edge(ids[i], ids[(i + 1) % 4], tag).unwrap();
            }
            ids
        };
        let outer = sq(&mut g, 0.0, 30.0, "ring");
        sq(&mut g, 10.0, 10.0, "island");
        let end = g.add_node(DVec2::new(5.0, 3.0), 9).unwrap();
        g.add_edge(outer[0], end, "lane").unwrap();
        let d = crate::extract(&g).unwrap();
        let cg = d.cells[0].road_graph(&g).unwrap();
        assert_eq!(cg.graph.edge_count(), 4 + 4 + 1);
        assert_eq!(cg.graph.node_count(), 9);
        cg.graph.check_invariants().unwrap();
        let lanes = cg.graph.edges().filter(|e| *e.3 == "lane").count();
        assert_eq!(lanes, 1);
        // Extracting the private graph again gives the same cell (and the island).
        let again = crate::extract(&cg.graph).unwrap();
        assert_eq!(again.cells.len(), 2);
        assert_eq!(again.cells[0].area(), d.cells[0].area());
        for (i, &orig) in cg.nodes.iter().enumerate() {
            let local = NodeId::from_raw(i as u32);
            assert_eq!(cg.graph.position(local).unwrap(), g.position(orig).unwrap());
        }
    }
}
