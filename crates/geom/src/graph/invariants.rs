//! [`PlanarGraph::check_invariants`]: a full consistency and planarity check.

use std::cmp::Ordering;

use glam::DVec2;

use super::{EdgeId, NodeId, PlanarGraph};
use crate::error::GeomError;
use crate::predicates::{AngleStart, ccw_cmp};
use crate::predicates::{SegmentIntersection, point_on_segment, segment_intersection};
use crate::spatial::{Shape, SpatialIndex};

fn corrupt(msg: String) -> GeomError {
    GeomError::GraphCorrupt(msg)
}

/// An item of the planarity sweep: a node (as a point) or an edge (as a segment).
#[derive(Clone, Copy)]
enum Item {
    Node(NodeId, DVec2),
    Edge(EdgeId, [NodeId; 2], DVec2, DVec2),
}

impl<N, E> PlanarGraph<N, E> {
    /// Checks every invariant of the graph and returns the first violation found.
    ///
    /// * bookkeeping: counts, live ends of every edge, adjacency lists that hold exactly
    ///   the incident edges, the spatial indexes holding exactly the live nodes and edges;
    /// * no zero-length edges and no two edges joining the same pair of nodes;
    /// * every adjacency list sorted counter-clockwise (exact comparator, ties by id);
    /// * planarity: no two edges share a point other than a common end node, no node lies
    ///   on another node or inside an edge it does not end.
    ///
    /// Cost: one spatial-index query per node and per edge, so about linear for road-like
    /// graphs (about 1 s for 150,000 edges on the benchmark machine, see the repository's `BENCHMARKS.md`).
    /// Run it in tests and after bulk edits.
    pub fn check_invariants(&self) -> Result<(), GeomError> {
        self.check_bookkeeping()?;
        self.check_rotation()?;
        self.check_planarity()
    }

    fn check_bookkeeping(&self) -> Result<(), GeomError> {
        let live_nodes = self.nodes.iter().filter(|n| n.is_some()).count();
        let live_edges = self.edges.iter().filter(|e| e.is_some()).count();
        if live_nodes != self.node_count() || live_edges != self.edge_count() {
            return Err(corrupt(format!(
                "counts say {} nodes / {} edges but {live_nodes} / {live_edges} are live",
                self.node_count(),
                self.edge_count()
            )));
        }
        for (e, a, b, _) in self.edges() {
            for n in [a, b] {
                let adj = self
                    .edges_at(n)
                    .map_err(|_| corrupt(format!("edge {e} ends at dead node {n}")))?;
                let uses = adj.iter().filter(|&&x| x == e).count();
                if uses != 1 {
                    return Err(corrupt(format!(
                        "edge {e} appears {uses} times around its end {n}"
                    )));
                }
            }
            let (pa, pb) = (self.position(a)?, self.position(b)?);
            if a == b || pa == pb {
                return Err(GeomError::ZeroLengthEdge { a: pa, b: pb });
            }
        }
        for n in self.node_ids() {
            let mut others = Vec::new();
            for (e, m) in self.neighbors(n)? {
                let (a, b) = self
                    .endpoints(e)
                    .map_err(|_| corrupt(format!("node {n} lists dead edge {e}")))?;
                if a != n && b != n {
                    return Err(corrupt(format!(
                        "node {n} lists edge {e}, which joins {a} and {b}"
                    )));
                }
                others.push((m, e));
            }
            others.sort_unstable();
            for w in others.windows(2) {
                if w[0].0 == w[1].0 {
                    return Err(GeomError::DuplicateEdge {
                        a: n.raw(),
                        b: w[0].0.raw(),
                        existing: w[0].1.raw(),
                    });
                }
            }
        }
        self.check_index()
    }

    /// The spatial indexes hold exactly the live nodes and edges, with their geometry.
    fn check_index(&self) -> Result<(), GeomError> {
        if self.node_index().len() != self.node_count()
            || self.edge_index().len() != self.edge_count()
        {
            return Err(corrupt(format!(
                "the spatial indexes hold {} nodes / {} edges, the graph {} / {}",
                self.node_index().len(),
                self.edge_index().len(),
                self.node_count(),
                self.edge_count()
            )));
        }
        for (n, p, _) in self.nodes() {
            if self.node_index().get(n) != Some(Shape::Point(p)) {
                return Err(corrupt(format!(
                    "node {n} is missing or misplaced in the index"
                )));
            }
        }
        for (e, a, b, _) in self.edges() {
            let s = Shape::Segment(self.position(a)?, self.position(b)?);
            if self.edge_index().get(e) != Some(s) {
                return Err(corrupt(format!(
                    "edge {e} is missing or misplaced in the index"
                )));
            }
        }
        Ok(())
    }

    fn check_rotation(&self) -> Result<(), GeomError> {
        for n in self.node_ids() {
            let o = self.position(n)?;
            let adj = self.edges_at(n)?;
            for w in adj.windows(2) {
                let p = self.far_position(w[0], n);
                let q = self.far_position(w[1], n);
                let (Some(p), Some(q)) = (p, q) else {
                    return Err(corrupt(format!("node {n} lists a dead edge")));
                };
                match ccw_cmp(o, p, q, AngleStart::East) {
                    Ordering::Less => {}
                    Ordering::Equal => {
                        let (first, second) = (w[0].min(w[1]), w[0].max(w[1]));
                        return Err(GeomError::EdgesIntersect {
                            first: first.raw(),
                            second: second.raw(),
                            point: if p.distance_squared(o) <= q.distance_squared(o) {
                                p
                            } else {
                                q
                            },
                        });
                    }
                    Ordering::Greater => {
                        return Err(corrupt(format!(
                            "edges {} and {} around node {n} are not in counter-clockwise order",
                            w[0], w[1]
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    fn check_planarity(&self) -> Result<(), GeomError> {
        let edge_item = |e: EdgeId| -> Result<Item, GeomError> {
            let (a, b) = self.endpoints(e)?;
            Ok(Item::Edge(e, [a, b], self.position(a)?, self.position(b)?))
        };
        // Candidates come from the spatial indexes (whose contents `check_index` has just
        // verified); every decision is made by `check_pair` with exact predicates.
        for (n, p, _) in self.nodes() {
            let item = Item::Node(n, p);
            for near in self.node_index().points_within(p, 0.0) {
                if near.key > n {
                    check_pair(&item, &Item::Node(near.key, near.point))?;
                }
            }
            for hit in self.edge_index().segments_crossing(p, p) {
                check_pair(&item, &edge_item(hit.key)?)?;
            }
        }
        for (e, _, _, _) in self.edges() {
            let item = edge_item(e)?;
            let Item::Edge(_, _, a, b) = item else {
                continue;
            };
            for hit in self.edge_index().segments_crossing(a, b) {
                if hit.key > e {
                    check_pair(&item, &edge_item(hit.key)?)?;
                }
            }
        }
        Ok(())
    }
}

fn check_pair(i: &Item, j: &Item) -> Result<(), GeomError> {
    match (*i, *j) {
        (Item::Node(n, p), Item::Node(m, q)) => {
            if p == q {
                return Err(GeomError::NodeOnGeometry {
                    node: n.raw().max(m.raw()),
                    point: p,
                    what: "node",
                    other: n.raw().min(m.raw()),
                });
            }
        }
        (Item::Node(n, p), Item::Edge(e, ends, a, b))
        | (Item::Edge(e, ends, a, b), Item::Node(n, p)) => {
            if !ends.contains(&n) && point_on_segment(p, a, b) {
                return Err(GeomError::NodeOnGeometry {
                    node: n.raw(),
                    point: p,
                    what: "edge",
                    other: e.raw(),
                });
            }
        }
        (Item::Edge(e, ee, a0, a1), Item::Edge(f, fe, b0, b1)) => {
            let shared = ee.iter().any(|x| fe.contains(x));
            let bad = match segment_intersection(a0, a1, b0, b1) {
                SegmentIntersection::Disjoint => None,
                SegmentIntersection::Touching { point, .. } => {
                    // Allowed only at a common end node.
                    let at_common_end = shared
                        && ((ee.contains(&fe[0]) && point == b0)
                            || (ee.contains(&fe[1]) && point == b1));
                    (!at_common_end).then_some(point)
                }
                SegmentIntersection::Crossing { point, .. } => Some(point),
                SegmentIntersection::Overlap { start, .. } => Some(start),
            };
            if let Some(point) = bad {
                return Err(GeomError::EdgesIntersect {
                    first: e.raw().min(f.raw()),
                    second: e.raw().max(f.raw()),
                    point,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn detects_crossing_overlap_and_node_on_edge() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let a = g.add_node(v(0.0, 0.0), ()).unwrap();
        let b = g.add_node(v(2.0, 2.0), ()).unwrap();
        let c = g.add_node(v(0.0, 2.0), ()).unwrap();
        let d = g.add_node(v(2.0, 0.0), ()).unwrap();
        g.add_edge(a, b, ()).unwrap();
        g.check_invariants().unwrap();
        let x = g.add_edge(c, d, ()).unwrap();
        assert!(matches!(
            g.check_invariants(),
            Err(GeomError::EdgesIntersect { point, .. }) if point == v(1.0, 1.0)
        ));
        g.remove_edge(x).unwrap();
        // Collinear overlap sharing an end: caught by the rotation check.
        let m = g.add_node(v(3.0, 3.0), ()).unwrap();
        let y = g.add_edge(a, m, ()).unwrap();
        assert!(matches!(
            g.check_invariants(),
            Err(GeomError::EdgesIntersect { .. })
        ));
        g.remove_edge(y).unwrap();
        g.remove_node(m).unwrap();
        // A node inside an edge.
        let on = g.add_node(v(1.0, 1.0), ()).unwrap();
        assert!(matches!(
            g.check_invariants(),
            Err(GeomError::NodeOnGeometry { node, what: "edge", .. }) if node == on.raw()
        ));
        g.remove_node(on).unwrap();
        // Two nodes at one place.
        g.add_node(v(0.0, 2.0), ()).unwrap();
        assert!(matches!(
            g.check_invariants(),
            Err(GeomError::NodeOnGeometry { what: "node", .. })
        ));
    }

    #[test]
    fn shared_end_is_fine_but_t_junction_is_not() {
        let mut g: PlanarGraph<(), ()> = PlanarGraph::new();
        let a = g.add_node(v(0.0, 0.0), ()).unwrap();
        let b = g.add_node(v(4.0, 0.0), ()).unwrap();
        let c = g.add_node(v(4.0, 3.0), ()).unwrap();
        g.add_edge(a, b, ()).unwrap();
        g.add_edge(b, c, ()).unwrap();
        g.add_edge(c, a, ()).unwrap();
        g.check_invariants().unwrap();
        // An edge from c ending exactly on a–b's interior (T-junction without a node).
        let t = g.add_node(v(2.0, -3.0), ()).unwrap();
        let u = g.add_node(v(2.0, 0.0), ()).unwrap();
        g.remove_node(u).unwrap();
        let far = g.add_node(v(2.0, 5.0), ()).unwrap();
        g.add_edge(t, far, ()).unwrap();
        assert!(g.check_invariants().is_err());
    }
}
