//! Highway curvature smoothing by corner cutting (end of §3.3.1), keeping the graph planar.

use polis_geom::predicates::{Orientation, orient2d};
use polis_geom::{Aabb2, DVec2, NodeId};

use crate::error::Result;
use crate::inputs::RoadInputs;
use crate::legality::Legality;
use crate::network::{Junction, RoadClass, RoadNetwork, angle_diff, angle_of};
use crate::params::RoadParams;

/// Corners sharper than this (turn angle, radians) are cut.
const MIN_TURN: f64 = 0.05;
/// Fraction of each edge cut away at a corner (Chaikin's 1/4).
const CUT: f64 = 0.25;

fn strictly_inside(p: DVec2, t: [DVec2; 3]) -> bool {
    let o = orient2d(t[0], t[1], t[2]);
    if o == Orientation::Collinear {
        return false;
    }
    (0..3).all(|i| orient2d(t[i], t[(i + 1) % 3], p) == o)
}

/// Cuts the corners of highway chains: every junction of degree 2 between two non-bridge
/// highway edges whose direction turns is replaced by two points a quarter along each
/// edge joined by a new edge (one Chaikin round per `params.smoothing_rounds`).
/// A corner is cut only if the new edge crosses nothing, no junction lies inside the cut
/// triangle, and the new edge is legal; so the graph stays planar. Returns the number
/// of corners cut.
///
/// # Errors
/// [`crate::RoadError::Geometry`] if the graph is corrupt.
pub fn smooth_highways(
    net: &mut RoadNetwork,
    params: &RoadParams,
    inputs: &RoadInputs,
) -> Result<usize> {
    let legality = Legality::new(inputs, params);
    let mut cut = 0;
    for _ in 0..params.smoothing_rounds {
        let candidates: Vec<NodeId> = net.node_ids().collect();
        for v in candidates {
            if !net.contains_node(v) || net.degree(v)? != 2 {
                continue;
            }
            let edges = net.edges_at(v)?.to_vec();
            let [e1, e2] = [edges[0], edges[1]];
            let (r1, r2) = (*net.edge_payload(e1)?, *net.edge_payload(e2)?);
            if r1.class != RoadClass::Highway
                || r2.class != RoadClass::Highway
                || r1.bridge
                || r2.bridge
            {
                continue;
            }
            let (u, w) = (net.other_end(e1, v)?, net.other_end(e2, v)?);
            let (pu, pv, pw) = (net.position(u)?, net.position(v)?, net.position(w)?);
            let turn = std::f64::consts::PI - angle_diff(angle_of(pu - pv), angle_of(pw - pv));
            if turn < MIN_TURN {
                continue;
            }
            let p1 = pv + (pu - pv) * CUT;
            let p2 = pv + (pw - pv) * CUT;
            if p1.distance(p2) < 1e-3 || !legality.segment_ok(p1, p2) {
                continue;
            }
            // Nothing may cross the new edge or sit inside the cut triangle.
            let tri = [p1, pv, p2];
            let blocked_edge = net
                .edges_crossing(p1, p2)
                .iter()
                .any(|h| h.key != e1 && h.key != e2);
            let blocked_node = net
                .nodes_in_box(&Aabb2::from_points(tri))
                .into_iter()
                .any(|n| {
                    n != v
                        && net
                            .position(n)
                            .is_ok_and(|p| strictly_inside(p, tri) || p == p1 || p == p2)
                });
            if blocked_edge || blocked_node {
                continue;
            }
            let step = net.node_payload(v)?.step;
            let (n1, _) = net.split_edge(e1, p1, Junction { step })?;
            // e2 is still the edge v–w (splitting e1 did not touch it).
            let (n2, _) = net.split_edge(e2, p2, Junction { step })?;
            net.remove_node(v)?;
            net.add_edge(n1, n2, r1)?;
            cut += 1;
        }
    }
    Ok(cut)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::sync::Arc;

    use polis_geom::field::Constant;
    use polis_geom::graph::SnapOptions;

    use super::*;
    use crate::network::Road;

    fn hw() -> Road {
        Road {
            class: RoadClass::Highway,
            width: 16.0,
            bridge: false,
            tunnel: false,
            step: 0,
        }
    }

    #[test]
    fn corner_is_cut_and_graph_stays_planar() {
        let mut n = RoadNetwork::new();
        let o = SnapOptions::default();
        n.insert_segment(DVec2::ZERO, DVec2::new(100.0, 0.0), hw(), &o)
            .unwrap();
        n.insert_segment(DVec2::new(100.0, 0.0), DVec2::new(100.0, 100.0), hw(), &o)
            .unwrap();
        let params = RoadParams {
            smoothing_rounds: 2,
            ..RoadParams::default()
        };
        let inputs = RoadInputs::flat(Arc::new(Constant(0.5)));
        let cut = smooth_highways(&mut n, &params, &inputs).unwrap();
        assert!(cut >= 2, "{cut}");
        n.check_invariants().unwrap();
        assert!(n.nearest_node(DVec2::new(100.0, 0.0), 1.0).is_none());
        let ends = n.node_ids().filter(|&v| n.degree(v).unwrap() == 1).count();
        assert_eq!(ends, 2);
    }

    #[test]
    fn corner_with_a_junction_inside_is_kept() {
        let mut n = RoadNetwork::new();
        let o = SnapOptions::default();
        n.insert_segment(DVec2::ZERO, DVec2::new(100.0, 0.0), hw(), &o)
            .unwrap();
        n.insert_segment(DVec2::new(100.0, 0.0), DVec2::new(100.0, 100.0), hw(), &o)
            .unwrap();
        // A dead-end street inside the corner's cut triangle.
        let street = Road {
            class: RoadClass::Street,
            ..hw()
        };
        n.insert_segment(DVec2::new(90.0, 3.0), DVec2::new(97.0, 6.0), street, &o)
            .unwrap();
        let params = RoadParams {
            smoothing_rounds: 1,
            ..RoadParams::default()
        };
        let inputs = RoadInputs::flat(Arc::new(Constant(0.5)));
        smooth_highways(&mut n, &params, &inputs).unwrap();
        n.check_invariants().unwrap();
        assert!(n.nearest_node(DVec2::new(100.0, 0.0), 1e-9).is_some());
    }
}
