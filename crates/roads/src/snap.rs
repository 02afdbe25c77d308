//! Kelly's snap algorithm (Citygen §4.3.3): the proximity and intersection status of a
//! proposed segment `a–b` against the existing network.
//!
//! * **Extended bounding box exclusion** (§4.3.3.1): only junctions in the segment's
//!   bounding box grown by the snap size, and only roads met by the segment (found by the
//!   spatial index's segment query, which walks the cells along `a–b`), are tested.
//! * **Ordered tests with an `r`-value benchmark** (§4.3.3.2–5): events are prioritised
//!   by their position `r` along `a–b` (0 at the root `a`). Test 1 (junction proximity)
//!   keeps the smallest `r` of a junction within the snap size of the segment body (or,
//!   for `1 < r ≤ 1 + snap/|ab|`, within the snap size of `b`); test 2 (road intersection)
//!   only looks at crossings before that `r`; test 3 (road proximity of `b`), whose events
//!   have the lowest priority, runs only when the first two found nothing.

use polis_geom::predicates::closest_point_on_segment;
use polis_geom::spatial::{Shape, SpatialIndex};
use polis_geom::{Aabb2, DVec2, EdgeId, NodeId};

use crate::network::{RoadClass, RoadNetwork};

/// What the snap algorithm found first along a proposed segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SnapEvent {
    /// The segment crosses a road at `point` (`r` along the segment): make a crossing.
    Cross {
        /// The road crossed.
        edge: EdgeId,
        /// The crossing point.
        point: DVec2,
        /// Its parameter along the segment.
        r: f64,
    },
    /// A junction lies within the snap size of the segment: extend or shorten to it.
    Junction {
        /// The junction.
        node: NodeId,
        /// Its position.
        point: DVec2,
        /// Its (projected) parameter along the segment.
        r: f64,
    },
    /// The segment's end is within the snap size of a road: extend it to meet the road.
    Road {
        /// The road.
        edge: EdgeId,
        /// The closest point of the road to the segment's end.
        point: DVec2,
    },
}

impl SnapEvent {
    /// Where the segment should end.
    pub fn point(&self) -> DVec2 {
        match *self {
            SnapEvent::Cross { point, .. }
            | SnapEvent::Junction { point, .. }
            | SnapEvent::Road { point, .. } => point,
        }
    }
}

/// A snap query.
#[derive(Debug, Clone, Copy)]
pub struct SnapQuery {
    /// Root of the proposed segment.
    pub a: DVec2,
    /// Target of the proposed segment.
    pub b: DVec2,
    /// Snap size (metres).
    pub radius: f64,
    /// The junction the segment grows from (its roads are ignored).
    pub start_node: Option<NodeId>,
    /// Only roads of this class are snapped to (`None`: all). Highways use
    /// `Some(Highway)`: they cut through streets without stopping.
    pub only: Option<RoadClass>,
}

fn edge_ok(net: &RoadNetwork, e: EdgeId, q: &SnapQuery) -> bool {
    let Ok((u, v)) = net.endpoints(e) else {
        return false;
    };
    if q.start_node.is_some_and(|s| s == u || s == v) {
        return false;
    }
    match (q.only, net.edge_payload(e)) {
        (None, Ok(_)) => true,
        (Some(c), Ok(r)) => r.class == c,
        (_, Err(_)) => false,
    }
}

fn node_ok(net: &RoadNetwork, n: NodeId, q: &SnapQuery) -> bool {
    if q.start_node == Some(n) {
        return false;
    }
    let Ok(edges) = net.edges_at(n) else {
        return false;
    };
    // A junction adjacent to the start is reached by an existing road already.
    if let Some(s) = q.start_node
        && edges
            .iter()
            .any(|&e| net.other_end(e, n).is_ok_and(|o| o == s))
    {
        return false;
    }
    match q.only {
        None => true,
        Some(c) => edges
            .iter()
            .any(|&e| net.edge_payload(e).is_ok_and(|r| r.class == c)),
    }
}

/// Runs the three ordered tests and returns the highest-priority event, if any.
pub fn snap(net: &RoadNetwork, q: &SnapQuery) -> Option<SnapEvent> {
    let (a, b) = (q.a, q.b);
    let d = b - a;
    let len2 = d.length_squared();
    if !(len2 > 0.0 && len2.is_finite()) {
        return None;
    }
    let len = len2.sqrt();
    let radius = q.radius.max(0.0);
    let mut best: Option<SnapEvent> = None;
    // Above this r nothing can win any more (Kelly's benchmark).
    let mut best_r = 1.0 + radius / len;
    // Test 1: junction proximity inside the extended bounding box. The index's
    // candidates come in no particular order: ties in r go to the smaller node id.
    let ext = Aabb2::new(a, b).expanded(radius);
    net.node_index().for_each_candidate(&ext, |n, shape| {
        let Shape::Point(p) = *shape else { return };
        if !ext.contains(p) {
            return;
        }
        let r = (p - a).dot(d) / len2;
        let better = r < best_r
            || (r == best_r && matches!(best, Some(SnapEvent::Junction { node, .. }) if n < node));
        if !(r > 0.0 && better) {
            return;
        }
        let hit = if r <= 1.0 {
            // Perpendicular distance from the line (Kelly's s-value, in metres).
            (d.perp_dot(p - a) / len).abs() <= radius
        } else {
            p.distance(b) <= radius
        };
        if hit && node_ok(net, n, q) {
            best_r = r;
            best = Some(SnapEvent::Junction {
                node: n,
                point: p,
                r,
            });
        }
    });
    // Test 2: the first road intersection along a–b before the best junction event.
    let limit = best_r.min(1.0 + f64::EPSILON);
    let first = net.edge_index().first_crossing(a, b, |hit| {
        hit.t < limit && hit.t * len > 1e-9 * len.max(1.0) && edge_ok(net, hit.key, q)
    });
    if let Some(hit) = first {
        let point = a + d * hit.t;
        best = Some(SnapEvent::Cross {
            edge: hit.key,
            point,
            r: hit.t,
        });
    }
    if best.is_some() {
        return best;
    }
    // Test 3: proximity of the end b to a road (every road within the radius meets the
    // box around b; ties in distance go to the smaller edge id).
    let around = Aabb2::new(b, b).expanded(radius);
    let mut near: Option<(f64, EdgeId, DVec2)> = None;
    net.edge_index().for_each_candidate(&around, |e, shape| {
        let Shape::Segment(u, v) = *shape else { return };
        let (c, _) = closest_point_on_segment(b, u, v);
        let dist = c.distance(b);
        if dist <= radius
            && near.is_none_or(|(bd, be, _)| (dist, e) < (bd, be))
            && edge_ok(net, e, q)
        {
            near = Some((dist, e, c));
        }
    });
    near.map(|(_, edge, point)| SnapEvent::Road { edge, point })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use crate::network::{Junction, Road};
    use polis_geom::graph::SnapOptions;

    fn road() -> Road {
        Road {
            class: RoadClass::Street,
            width: 8.0,
            bridge: false,
            tunnel: false,
            step: 0,
        }
    }

    type Seg = ((f64, f64), (f64, f64));

    fn net(segs: &[Seg]) -> RoadNetwork {
        let mut n = RoadNetwork::new();
        for &((ax, ay), (bx, by)) in segs {
            n.insert_segment_with(
                DVec2::new(ax, ay),
                DVec2::new(bx, by),
                road(),
                &SnapOptions::default(),
                |_| Junction::default(),
            )
            .unwrap();
        }
        n
    }

    fn q(a: (f64, f64), b: (f64, f64), radius: f64) -> SnapQuery {
        SnapQuery {
            a: DVec2::new(a.0, a.1),
            b: DVec2::new(b.0, b.1),
            radius,
            start_node: None,
            only: None,
        }
    }

    #[test]
    fn crossing_becomes_a_junction_point() {
        let n = net(&[((0.0, 0.0), (100.0, 0.0))]);
        let ev = snap(&n, &q((40.0, -50.0), (40.0, 50.0), 5.0)).unwrap();
        assert!(matches!(ev, SnapEvent::Cross { r, .. } if (r - 0.5).abs() < 1e-12));
        assert_eq!(ev.point(), DVec2::new(40.0, 0.0));
    }

    #[test]
    fn end_near_a_road_extends_to_meet_it() {
        let n = net(&[((0.0, 0.0), (100.0, 0.0))]);
        let ev = snap(&n, &q((40.0, -50.0), (42.0, -8.0), 10.0)).unwrap();
        assert!(matches!(ev, SnapEvent::Road { .. }));
        assert_eq!(ev.point(), DVec2::new(42.0, 0.0));
        // Out of reach: nothing.
        assert!(snap(&n, &q((40.0, -50.0), (42.0, -12.0), 10.0)).is_none());
    }

    #[test]
    fn end_near_a_junction_extends_to_it_before_a_later_crossing() {
        // Junction (100, 0) near the end; a road crossing further along is ignored.
        let n = net(&[((0.0, 0.0), (100.0, 0.0)), ((100.0, 0.0), (100.0, 80.0))]);
        let ev = snap(&n, &q((96.0, -60.0), (97.0, -6.0), 10.0)).unwrap();
        assert!(matches!(ev, SnapEvent::Junction { .. }), "{ev:?}");
        assert_eq!(ev.point(), DVec2::new(100.0, 0.0));
        // A junction close to the body of the segment wins over a crossing behind it.
        let n = net(&[((0.0, 20.0), (100.0, 20.0)), ((50.0, 50.0), (50.0, 60.0))]);
        let ev = snap(&n, &q((48.0, -50.0), (48.0, 30.0), 5.0)).unwrap();
        assert!(matches!(ev, SnapEvent::Cross { .. }), "{ev:?}");
        let n = net(&[((0.0, 20.0), (100.0, 20.0)), ((51.0, 0.0), (60.0, -5.0))]);
        let ev = snap(&n, &q((48.0, -50.0), (48.0, 30.0), 5.0)).unwrap();
        assert_eq!(ev.point(), DVec2::new(51.0, 0.0), "{ev:?}");
    }

    #[test]
    fn roads_at_the_start_junction_are_ignored() {
        let n = net(&[((0.0, 0.0), (100.0, 0.0))]);
        let start = n.nearest_node(DVec2::new(100.0, 0.0), 1e-9).map(|x| x.0);
        let mut query = q((100.0, 0.0), (100.0, 60.0), 10.0);
        query.start_node = start;
        assert!(snap(&n, &query).is_none());
        // Highways ignore streets.
        let mut query = q((40.0, -50.0), (40.0, 50.0), 5.0);
        query.only = Some(RoadClass::Highway);
        assert!(snap(&n, &query).is_none());
    }
}
