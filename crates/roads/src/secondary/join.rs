//! A secondary road that ends on a road (a road snap or a crossing): the road is split
//! and the new road joins the split node, without the general planar insertion.
//!
//! Growth used to add such a road with
//! [`insert_segment_with`](polis_geom::PlanarGraph::insert_segment_with), whose walk
//! costs a dozen spatial-index queries. By then the snap search has found the road and
//! the point, and the exact check has cleared the segment, so in nearly every case the
//! insertion does exactly this: anchor the end on the road at its closest point, split
//! the road there, add one edge. [`plan`] decides from the snap grid's roads whether the
//! insertion would do just that, by the insertion's own rules (same tolerances, same
//! arithmetic), and if so [`Join::Split`] gives the split point; the graph then gets the
//! same nodes, edges and ids, bit for bit, as the insertion would have given it. Where
//! any rule could act otherwise (a node within the insertion's snap distance of the end
//! or of the new road, a road passing within rounding of the split point, a node within
//! rounding of a piece of the split road, any meeting of the new road with another road
//! but at its root) the plan is [`Join::General`] and growth runs the insertion itself.
//!
//! The tests are supersets of the insertion's: a plan may send a case to the insertion
//! that the insertion would have handled plainly (it then does the same thing, only
//! slower), but never the other way round.

use polis_geom::graph::ROUNDING_TOLERANCE;
use polis_geom::predicates::{
    SegmentIntersection, closest_point_on_segment, distance_to_segment, segment_intersection,
};
use polis_geom::{Aabb2, DVec2, EdgeId, NodeId};

use super::grid::GridRoad;
use super::snap::Snapper;
use crate::network::RoadNetwork;

/// How a road snap or crossing joins the road it met.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Join {
    /// Split `edge` at `point` and join the new node: what the insertion would do.
    Split { edge: EdgeId, point: DVec2 },
    /// The insertion would refuse the segment as zero-length (its snapped ends within
    /// its snap distance).
    ZeroLength,
    /// Some rule of the insertion may act: run the insertion.
    General,
}

/// The rounding tolerance of planar insertion at `p` (its `rounding_eps`).
#[inline]
fn rounding_eps(p: DVec2) -> f64 {
    ROUNDING_TOLERANCE * p.abs().max_element().max(1.0)
}

/// How planar insertion of the road from node `source` at `a` to `q` on road `edge`
/// (snap distance `tolerance`) would join it: see the [module docs](self). `scratch` is
/// reused between calls.
pub(super) fn plan(
    g: &RoadNetwork,
    snapper: &mut Snapper,
    scratch: &mut Vec<GridRoad>,
    source: NodeId,
    (a, q): (DVec2, DVec2),
    edge: EdgeId,
    tolerance: f64,
) -> Join {
    // The insertion's snap distance for this segment.
    let scale = a.abs().max(q.abs()).max_element().max(1.0);
    let snap = tolerance.max(ROUNDING_TOLERANCE * scale);
    // Every road within 3 snap distances of the segment `a–q`: the split point lies
    // within `snap` of `q`, and the walk's snap distance is at most `2 snap`, so every
    // node and road the insertion looks at near the new road is among these.
    scratch.clear();
    snapper.roads_in(g, &Aabb2::new(a, q).expanded(3.0 * snap), scratch);
    let roads = &scratch[..];
    // Anchoring `q`: a node within the snap distance takes it.
    if roads
        .iter()
        .any(|r| r.pu.distance(q) <= snap || r.pv.distance(q) <= snap)
    {
        return Join::General;
    }
    // Else the road `q` lies on exactly (least id), else the nearest road within the
    // snap distance (ties by id), at its closest point.
    let on = roads
        .iter()
        .filter(|r| segment_intersection(q, q, r.pu, r.pv) != SegmentIntersection::Disjoint)
        .min_by_key(|r| r.edge);
    let (road, c) = match on {
        Some(r) => (*r, q),
        None => {
            let mut best: Option<(f64, GridRoad, DVec2)> = None;
            for r in roads {
                let (closest, _) = closest_point_on_segment(q, r.pu, r.pv);
                let d = closest.distance(q);
                if d <= snap && best.is_none_or(|(bd, br, _)| (d, r.edge) < (bd, br.edge)) {
                    best = Some((d, *r, closest));
                }
            }
            match best {
                Some((_, r, c)) => (r, c),
                None => return Join::General,
            }
        }
    };
    if road.edge != edge || c == road.pu || c == road.pv {
        return Join::General;
    }
    // The zero-length test of the snapped ends.
    if a == c || a.distance(c) <= snap || q.distance(a) <= snap {
        return Join::ZeroLength;
    }
    // The split: no node within rounding of the point, the point strictly inside.
    let eps_c = rounding_eps(c);
    if roads
        .iter()
        .any(|r| r.pu.distance(c) <= eps_c || r.pv.distance(c) <= eps_c)
    {
        return Join::General;
    }
    let d = road.pv - road.pu;
    let t = (c - road.pu).dot(d) / d.length_squared();
    if !(t > 0.0 && t < 1.0) {
        return Join::General;
    }
    // No other road within rounding of the split point (the insertion would bend it
    // through the new node).
    if roads
        .iter()
        .any(|r| r.edge != edge && distance_to_segment(c, r.pu, r.pv) <= eps_c)
    {
        return Join::General;
    }
    // The walk from `a` to the split point: no node other than the root within (twice)
    // its snap distance of the open segment, and no road meeting it but the root's roads
    // at `a`; the two pieces of the split road meet it only at the split point.
    let snap_w = 2.0 * snap.max(rounding_eps(a.abs().max(c.abs())));
    for r in roads {
        for (n, p) in [(r.u, r.pu), (r.v, r.pv)] {
            if n == source {
                continue;
            }
            let (closest, t) = closest_point_on_segment(p, a, c);
            if t > 0.0 && t < 1.0 && closest.distance(p) <= snap_w {
                return Join::General;
            }
        }
        if r.edge == edge {
            continue;
        }
        match segment_intersection(a, c, r.pu, r.pv) {
            SegmentIntersection::Disjoint => {}
            SegmentIntersection::Touching { point, .. }
                if point == a && (r.u == source || r.v == source) => {}
            _ => return Join::General,
        }
    }
    for (p0, p1) in [(road.pu, c), (c, road.pv)] {
        match segment_intersection(a, c, p0, p1) {
            SegmentIntersection::Touching { point, .. } if point == c => {}
            _ => return Join::General,
        }
    }
    // The pieces: no node but the road's ends within rounding of either (the insertion
    // would bend the piece through it; and only such a node's roads can meet a piece
    // where they did not meet the road).
    let eps_pieces =
        rounding_eps(road.pu.abs().max(c.abs())).max(rounding_eps(c.abs().max(road.pv.abs())));
    scratch.clear();
    snapper.roads_in(
        g,
        &Aabb2::new(road.pu, road.pv)
            .union(&Aabb2::new(c, c))
            .expanded(eps_pieces),
        scratch,
    );
    for r in scratch.iter() {
        for (n, p) in [(r.u, r.pu), (r.v, r.pv)] {
            if n == road.u || n == road.v {
                continue;
            }
            if distance_to_segment(p, road.pu, c) <= eps_pieces
                || distance_to_segment(p, c, road.pv) <= eps_pieces
            {
                return Join::General;
            }
        }
    }
    Join::Split { edge, point: c }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::network::{Junction, Road};
    use crate::secondary::snap::SnapEvent;
    use crate::secondary::{CellMaps, Neighbourhood, grow_cell};
    use polis_geom::graph::SnapOptions;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// A graph's nodes and edges to the bit: (id, position bits) and (id, ends, width).
    type Picture = (Vec<(NodeId, [u64; 2])>, Vec<(EdgeId, NodeId, NodeId, u64)>);

    fn nodes_and_edges(g: &RoadNetwork) -> Picture {
        (
            g.nodes()
                .map(|(n, p, _)| (n, [p.x.to_bits(), p.y.to_bits()]))
                .collect(),
            g.edges()
                .map(|(e, u, v, r)| (e, u, v, r.width.to_bits()))
                .collect(),
        )
    }

    /// On grown cells of every preset, every road snap and crossing of random proposals
    /// that the plan splits directly gives the graph planar insertion gives, to the bit
    /// (ids, positions, ends); a plan of zero length is one the insertion refuses.
    #[test]
    fn a_planned_join_is_what_planar_insertion_does() {
        let mut rng = Pcg64Mcg::seed_from_u64(18);
        let (mut split, mut zero, mut general) = (0, 0, 0);
        for n in Neighbourhood::ALL {
            let params = n.params().unwrap();
            let tolerance = (params.segment_size_m.value
                * crate::secondary::growth::INSERT_TOLERANCE)
                .max(1e-3);
            for cell in crate::secondary::tests::fixed_cells() {
                let mut p = params.clone();
                p.max_steps = Some(60);
                let g = grow_cell(&p, &cell, &CellMaps::none(), 3).unwrap().network;
                let ids: Vec<NodeId> = g.node_ids().collect();
                let mut snapper = Snapper::default();
                snapper.begin_cell(g.bbox(), params.segment_size_m.value);
                let mut scratch = Vec::new();
                for _ in 0..400 {
                    let source = ids[rng.random_range(0..ids.len())];
                    let a = g.position(source).unwrap();
                    let angle = rng.random::<f64>() * std::f64::consts::TAU;
                    let len = params.segment_size_m.value * (0.3 + rng.random::<f64>());
                    let b = a + DVec2::new(angle.cos(), angle.sin()) * len;
                    let radius = params.snap_size_m.value;
                    // Half the time a snap event; else any point near a random road
                    // (often near its ends, often beyond the insertion's snap distance
                    // of it), reached from any node: cases growth never asks about,
                    // where the insertion may anchor on a node, walk through nodes or
                    // split crossed roads, and the plan must leave it to the insertion.
                    let (e, q) = if rng.random::<bool>() {
                        match snapper.snap(&g, source, a, b, radius) {
                            SnapEvent::Cross(e, q) | SnapEvent::Road(e, q) => (e, q),
                            _ => continue,
                        }
                    } else {
                        let edges: Vec<EdgeId> = g.edge_ids().collect();
                        let e = edges[rng.random_range(0..edges.len())];
                        let (u, v) = g.segment(e).unwrap();
                        let t = match rng.random_range(0..3) {
                            0 => rng.random::<f64>(),
                            1 => rng.random::<f64>() * 2.0 * tolerance / u.distance(v),
                            _ => 1.0 - rng.random::<f64>() * 2.0 * tolerance / u.distance(v),
                        };
                        let off = (v - u).perp().normalize()
                            * tolerance
                            * (rng.random::<f64>() * 4.0 - 2.0);
                        (e, u.lerp(v, t) + off)
                    };
                    let road = Road {
                        width: 5.0,
                        step: 99,
                        ..crate::secondary::snap::tests::street()
                    };
                    let mut general_graph = g.clone();
                    let ins = general_graph.insert_segment_with(
                        a,
                        q,
                        road,
                        &SnapOptions {
                            snap_distance: tolerance,
                        },
                        |_| Junction { step: 99 },
                    );
                    match plan(&g, &mut snapper, &mut scratch, source, (a, q), e, tolerance) {
                        Join::Split { edge, point } => {
                            split += 1;
                            let ins = ins.unwrap();
                            let mut direct = g.clone();
                            let (m, piece) = direct
                                .split_edge(edge, point, Junction { step: 99 })
                                .unwrap();
                            let new = direct.add_edge(source, m, road).unwrap();
                            assert_eq!(ins.split, vec![(edge, piece)]);
                            assert_eq!(ins.created, vec![new]);
                            assert_eq!(nodes_and_edges(&direct), nodes_and_edges(&general_graph));
                            direct.check_invariants().unwrap();
                        }
                        Join::ZeroLength => {
                            zero += 1;
                            assert!(
                                matches!(ins, Err(polis_geom::GeomError::ZeroLengthEdge { .. })),
                                "{ins:?}"
                            );
                        }
                        Join::General => general += 1,
                    }
                }
            }
        }
        eprintln!("{split} direct splits, {zero} zero-length, {general} left to the insertion");
        // A source within the snap distance of `q` is a node there: the plan leaves
        // that to the insertion, so its own zero-length answer is rare.
        assert!(split > 300 && general > 100, "{split} {zero} {general}");
    }
}
