//! [`extract_planarized`]: cells of a graph that may not be planar, after rebuilding it with
//! the graph's planar insertion (snapping, splitting at crossings, merging overlaps).

use polis_geom::graph::SnapOptions;
use polis_geom::{DVec2, EdgeId, GeomError, NodeId, PlanarGraph};

use crate::error::Error;
use crate::output::{CellDecomposition, DropReason, DroppedEdge};
use crate::params::CellParams;

/// The planar graph built by [`extract_planarized`], its cells, and where every input
/// node and edge went.
#[derive(Debug, Clone)]
pub struct Planarized<N, E> {
    /// The planar rebuild of the input; the cells' ids refer to this graph.
    pub graph: PlanarGraph<N, E>,
    /// The cells of `graph`.
    pub cells: CellDecomposition,
    /// By input node index ([`NodeId::index`]): the node it became (`None` for dead slots).
    pub node_map: Vec<Option<NodeId>>,
    /// By input edge index ([`EdgeId::index`]): the edges it became, in order from its
    /// first end (empty for dead slots and collapsed edges). Where input edges overlap,
    /// the shared pieces are listed under each of them.
    pub edge_map: Vec<Vec<EdgeId>>,
}

/// Rebuilds `graph` with planar insertion (nodes first, then edges, both in id order) and
/// extracts the cells of the result.
///
/// Crossing edges are split at a new node (payload from `make_node(position)`), overlaps
/// are merged into one edge (the first inserted keeps its payload), and nodes and edge ends
/// within `snap.snap_distance` of existing geometry are snapped to it. An edge whose ends
/// snap together is left out and listed with [`DropReason::Collapsed`] in the report.
///
/// # Errors
/// [`Error::Geom`] when planar insertion fails; otherwise as
/// [`extract_with`](crate::extract_with) (the planarity check then always passes).
pub fn extract_planarized<N: Clone, E: Clone>(
    graph: &PlanarGraph<N, E>,
    params: &CellParams,
    snap: &SnapOptions,
    mut make_node: impl FnMut(DVec2) -> N,
) -> Result<Planarized<N, E>, Error> {
    let mut out: PlanarGraph<N, E> = PlanarGraph::new();
    let mut node_map = vec![None; graph.node_bound()];
    for (id, p, payload) in graph.nodes() {
        let (n, _) = out.insert_point_with(p, snap, |_| payload.clone())?;
        node_map[id.index()] = Some(n);
    }
    // The input edges every new edge belongs to (several where input edges overlap);
    // pieces split off later inherit them.
    let mut users: Vec<Vec<u32>> = Vec::new();
    let mut edge_map: Vec<Vec<EdgeId>> = vec![Vec::new(); graph.edge_bound()];
    let mut collapsed = Vec::new();
    for (e, a, b, payload) in graph.edges() {
        let (Some(na), Some(nb)) = (node_map[a.index()], node_map[b.index()]) else {
            return Err(Error::Internal(format!("edge {e} ends at a dead node")));
        };
        let (pa, pb) = (out.position(na)?, out.position(nb)?);
        match out.insert_segment_with(pa, pb, payload.clone(), snap, &mut make_node) {
            Ok(ins) => {
                let grow = |users: &mut Vec<Vec<u32>>, x: EdgeId| {
                    if users.len() <= x.index() {
                        users.resize(x.index() + 1, Vec::new());
                    }
                };
                for &(x, piece) in &ins.split {
                    grow(&mut users, x);
                    grow(&mut users, piece);
                    let inherited = users[x.index()].clone();
                    for &i in &inherited {
                        edge_map[i as usize].push(piece);
                    }
                    users[piece.index()] = inherited;
                }
                for &x in &ins.path {
                    grow(&mut users, x);
                    users[x.index()].push(e.raw());
                    edge_map[e.index()].push(x);
                }
            }
            Err(GeomError::ZeroLengthEdge { .. }) => collapsed.push(e),
            Err(err) => return Err(err.into()),
        }
    }
    // Order every path from the input edge's first end.
    for (e, a, b, _) in graph.edges() {
        let (pa, pb) = (graph.position(a)?, graph.position(b)?);
        let d = pb - pa;
        let along = |x: &EdgeId| {
            out.segment(*x)
                .map(|(p, q)| ((p + q) * 0.5 - pa).dot(d))
                .unwrap_or(0.0)
        };
        let list = &mut edge_map[e.index()];
        list.retain(|x| out.contains_edge(*x));
        list.sort_by(|x, y| along(x).total_cmp(&along(y)).then(x.cmp(y)));
        list.dedup();
    }
    let mut cells = crate::extract_with(&out, params)?;
    cells
        .report
        .dropped_edges
        .extend(collapsed.into_iter().map(|edge| DroppedEdge {
            edge,
            reason: DropReason::Collapsed,
        }));
    Ok(Planarized {
        graph: out,
        cells,
        node_map,
        edge_map,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_diagonals_become_four_triangles() {
        let mut g: PlanarGraph<&str, u8> = PlanarGraph::new();
        let c: Vec<NodeId> = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
            .iter()
            .map(|&(x, y)| g.add_node(DVec2::new(x, y), "corner").unwrap())
            .collect();
        for i in 0..4 {
            g.add_edge(c[i], c[(i + 1) % 4], 1).unwrap();
        }
        let d1 = g.add_edge(c[0], c[2], 2).unwrap();
        g.add_edge(c[1], c[3], 2).unwrap();
        assert!(matches!(crate::extract(&g), Err(Error::NotPlanar { .. })));
        let p = extract_planarized(
            &g,
            &CellParams::default(),
            &SnapOptions::default(),
            |_| "crossing",
        )
        .unwrap();
        assert_eq!(p.cells.cells.len(), 4);
        assert_eq!(p.graph.node_count(), 5);
        assert_eq!(p.edge_map[d1.index()].len(), 2);
        for e in &p.edge_map[d1.index()] {
            assert_eq!(*p.graph.edge_payload(*e).unwrap(), 2);
        }
        let centre = p
            .graph
            .nodes()
            .find(|(_, _, n)| **n == "crossing")
            .map(|(_, q, _)| q)
            .unwrap();
        assert_eq!(centre, DVec2::new(5.0, 5.0));
        for cell in &p.cells.cells {
            assert!((cell.area() - 25.0).abs() < 1e-9);
        }
    }
}
