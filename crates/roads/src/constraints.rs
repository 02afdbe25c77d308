//! Local constraints (§3.3, §3.3.1): legality (prune, bridge, rotate, tunnel) and
//! self-sensitivity (crossings, snapping to junctions and roads, minimum angles).

use polis_geom::{DVec2, NodeId};
use serde::{Deserialize, Serialize};

use crate::inputs::RoadInputs;
use crate::legality::{Illegal, Legality};
use crate::modules::{QueryState, RoadAttr};
use crate::network::{RoadClass, RoadNetwork, angle_diff, angle_of, dir};
use crate::params::RoadParams;
use crate::snap::{SnapEvent, SnapQuery, snap};
use crate::tunnels::{tunnel_landing, tunnelable};

/// Why a snap event was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Refusal {
    /// Below the minimum angle.
    Angle,
    /// On a tunnel between its portals.
    Tunnel,
}

/// What a legal segment crosses: its own ground, water (a bridge) or land under a
/// tunnel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Span {
    Ground,
    Bridge,
    Tunnel,
}

/// The `localConstraints` function of p8: adjust a proposed segment to the environment
/// and the existing network, or reject it.
///
/// On [`QueryState::Succeed`] the generator inserts `road.start → road.end` into the
/// network (planar insertion: crossings become junctions), flagged with `road.bridge` or
/// `road.tunnel`.
pub trait LocalConstraints: Send {
    /// Adjusts `road` (its `end`, `angle`, `length`, `bridge`, `tunnel`, `snapped`) and returns
    /// `Succeed` or `Failed`.
    fn adjust(&mut self, road: &mut RoadAttr, network: &RoadNetwork) -> QueryState;

    /// Counters of what the constraints did (for reports). Default: none.
    fn stats(&self) -> ConstraintStats {
        ConstraintStats::default()
    }

    /// The junction at `road.start` found by the last [`adjust`](Self::adjust), if it
    /// looked for one: a hint for the planar insertion, which checks it and searches
    /// itself when it does not hold (so a wrong answer costs time, never a different
    /// network). Default: none.
    fn start_node(&self) -> Option<NodeId> {
        None
    }
}

/// What [`DefaultConstraints`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ConstraintStats {
    /// Proposals seen.
    pub proposals: usize,
    /// Segments shortened to stay legal.
    pub pruned: usize,
    /// Segments rotated to stay legal.
    pub rotated: usize,
    /// Highway segments turned into bridges.
    pub bridges: usize,
    /// Highway segments turned into tunnels ([`crate::tunnels`]).
    #[serde(default)]
    pub tunnels: usize,
    /// Segments ended at a crossing with an existing road.
    pub crossings: usize,
    /// Segments extended or shortened to an existing junction.
    pub junction_snaps: usize,
    /// Segments extended to meet an existing road.
    pub road_snaps: usize,
    /// Rejected: no legal variant found.
    pub failed_illegal: usize,
    /// Rejected: angle between roads below the minimum.
    pub failed_angle: usize,
    /// Rejected: too short after adjustment.
    pub failed_short: usize,
    /// Rejected: would join or cross a tunnel between its portals.
    #[serde(default)]
    pub failed_tunnel: usize,
}

/// The default local constraints of Parish & Müller with Kelly's snap algorithm.
#[derive(Debug, Clone)]
pub struct DefaultConstraints {
    params: RoadParams,
    legality: Legality,
    stats: ConstraintStats,
    /// The start junction found by the last `adjust`.
    start_node: Option<NodeId>,
}

/// Distance (metres) under which a point counts as the start junction.
const SAME_POINT_M: f64 = 1e-6;

impl DefaultConstraints {
    /// Constraints for `params` over `inputs`.
    pub fn new(params: &RoadParams, inputs: &RoadInputs) -> Self {
        DefaultConstraints {
            params: params.clone(),
            legality: Legality::new(inputs, params),
            stats: ConstraintStats::default(),
            start_node: None,
        }
    }

    /// The legality tests used.
    pub fn legality(&self) -> &Legality {
        &self.legality
    }

    /// Step 1 of §3.3: make the segment legal (prune, bridge, rotate, tunnel). Returns
    /// the new end and angle and what the segment crosses, or `None`.
    fn make_legal(
        &mut self,
        a: DVec2,
        angle: f64,
        len: f64,
        class: RoadClass,
    ) -> Option<(DVec2, f64, Span)> {
        let b = a + dir(angle) * len;
        let Some(v) = self.legality.segment(a, b) else {
            return Some((b, angle, Span::Ground));
        };
        let p = &self.params;
        // Prune to the last legal sample, refined by bisection toward the violation.
        // Only the stretch after the last legal sample needs testing (one sample step).
        let (mut lo, mut hi) = (v.t_legal, v.t);
        let from = a + (b - a) * v.t_legal;
        for _ in 0..10 {
            let mid = 0.5 * (lo + hi);
            if self.legality.segment_ok(from, a + (b - a) * mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let pruned = lo * len;
        if pruned >= (1.0 - p.max_prune_factor) * len && pruned >= p.min_segment_length_m.max(1e-3)
        {
            self.stats.pruned += 1;
            return Some((a + (b - a) * lo, angle, Span::Ground));
        }
        let under_water = p.tunnel_under_water;
        // Highways bridge water up to the maximum length (unless they tunnel under it).
        if class == RoadClass::Highway
            && v.what == Illegal::Water
            && p.max_bridge_length_m > 0.0
            && !under_water
            && let Some(landing) =
                self.legality
                    .bridge_landing(a, dir(angle), v.t * len, p.max_bridge_length_m)
        {
            self.stats.bridges += 1;
            return Some((landing, angle, Span::Bridge));
        }
        // Rotate within the maximal angle, nearest first, left before right (roads follow
        // coastlines and park edges, not the edge of the map).
        if v.what == Illegal::Outside {
            self.stats.failed_illegal += 1;
            return None;
        }
        let step = p.rotate_step_deg.to_radians();
        let max = p.max_rotate_deg.to_radians();
        let mut k = 1.0;
        while k * step <= max + 1e-12 {
            for s in [1.0, -1.0] {
                let ang = angle + s * k * step;
                let e = a + dir(ang) * len;
                if self.legality.segment_ok(a, e) {
                    self.stats.rotated += 1;
                    return Some((e, ang, Span::Ground));
                }
            }
            k += 1.0;
        }
        // Highways pass under land no rotation avoids (a park, a slope) in a tunnel, and
        // under water where the parameters say so.
        if class == RoadClass::Highway
            && (matches!(v.what, Illegal::Park | Illegal::Slope)
                || (v.what == Illegal::Water && under_water))
            && let Some(far) = tunnel_landing(
                &self.legality,
                a,
                dir(angle),
                v.t * len,
                p.max_tunnel_length_m,
                under_water,
            )
        {
            self.stats.tunnels += 1;
            return Some((far, angle, Span::Tunnel));
        }
        self.stats.failed_illegal += 1;
        None
    }

    /// Whether a road leaving junction `n` toward `toward` keeps the minimum angle to
    /// every road already there.
    fn angle_ok_at(&self, net: &RoadNetwork, n: NodeId, toward: DVec2) -> bool {
        let min = self.params.min_angle_deg.to_radians();
        let (Ok(p), Ok(edges)) = (net.position(n), net.edges_at(n)) else {
            return true;
        };
        if toward.distance(p) <= 0.0 {
            return false;
        }
        let a = angle_of(toward - p);
        edges.iter().all(|&e| {
            net.other_end(e, n)
                .and_then(|o| net.position(o))
                .is_ok_and(|q| angle_diff(angle_of(q - p), a) >= min)
        })
    }

    /// Whether the segment `a–b` meets edge `e` at no less than the minimum angle.
    fn angle_ok_edge(&self, net: &RoadNetwork, e: polis_geom::EdgeId, a: DVec2, b: DVec2) -> bool {
        let min = self.params.min_angle_deg.to_radians();
        let Ok((u, v)) = net.segment(e) else {
            return true;
        };
        let d = angle_diff(angle_of(v - u), angle_of(b - a));
        d.min(std::f64::consts::PI - d) >= min
    }
}

impl DefaultConstraints {
    /// Kelly's snap of `a → end` for a road of `class` leaving `start_node`: `Ok(None)`
    /// when nothing is near, `Ok(Some(event))` for an event meeting the minimum angle,
    /// `Err` for one below it or one on a tunnel edge.
    fn snap_event(
        &self,
        net: &RoadNetwork,
        start_node: Option<NodeId>,
        a: DVec2,
        end: DVec2,
        class: RoadClass,
    ) -> Result<Option<SnapEvent>, Refusal> {
        let q = SnapQuery {
            a,
            b: end,
            radius: self.params.snap_radius_m,
            start_node,
            only: match class {
                RoadClass::Highway => Some(RoadClass::Highway),
                RoadClass::Street => None,
            },
        };
        let Some(ev) = snap(net, &q) else {
            return Ok(None);
        };
        // Nothing joins or crosses a tunnel between its portals.
        if let SnapEvent::Cross { edge, .. } | SnapEvent::Road { edge, .. } = ev
            && net.edge_payload(edge).is_ok_and(|r| r.tunnel)
        {
            return Err(Refusal::Tunnel);
        }
        let ok = match ev {
            SnapEvent::Junction { node, .. } => self.angle_ok_at(net, node, a),
            SnapEvent::Cross { edge, .. } | SnapEvent::Road { edge, .. } => {
                self.angle_ok_edge(net, edge, a, ev.point())
            }
        };
        if ok {
            Ok(Some(ev))
        } else {
            Err(Refusal::Angle)
        }
    }

    /// The first crossing of `a → b` with any road of `net`, or junction on it, before
    /// `b` (the start junction excluded), or `None`.
    fn first_crossing(
        &self,
        net: &RoadNetwork,
        start_node: Option<NodeId>,
        a: DVec2,
        b: DVec2,
    ) -> Option<DVec2> {
        let q = SnapQuery {
            a,
            b,
            radius: 0.0,
            start_node,
            only: None,
        };
        match snap(net, &q) {
            Some(SnapEvent::Cross { point, .. } | SnapEvent::Junction { point, .. })
                if point.distance(b) > SAME_POINT_M =>
            {
                Some(point)
            }
            _ => None,
        }
    }

    fn count_snap(&mut self, ev: &SnapEvent) {
        match ev {
            SnapEvent::Junction { .. } => self.stats.junction_snaps += 1,
            SnapEvent::Cross { .. } => self.stats.crossings += 1,
            SnapEvent::Road { .. } => self.stats.road_snaps += 1,
        }
    }
}

impl LocalConstraints for DefaultConstraints {
    /// §3.3's two steps. Step 1 makes the proposal legal (prune, bridge, rotate), step 2
    /// applies the self-sensitive rules (snap to a crossing, junction or road, minimum
    /// angles), and a snapped road is checked for legality again.
    ///
    /// When the proposal as given, snapped, is already a legal road, the result of the two
    /// steps is that road, and it is taken straight away: one legality walk instead of
    /// two. (If the proposal itself was illegal, step 1 would have pruned or rotated it
    /// first; taking the legal snapped road instead connects to the network where the
    /// two-step order would stop short of it.)
    fn adjust(&mut self, road: &mut RoadAttr, net: &RoadNetwork) -> QueryState {
        self.stats.proposals += 1;
        self.start_node = None;
        let a = road.start;
        if !(a.is_finite()
            && road.angle.is_finite()
            && road.length.is_finite()
            && road.length > 0.0)
        {
            self.stats.failed_illegal += 1;
            return QueryState::Failed;
        }
        let min_len = self.params.min_segment_length_m.max(1e-3);
        let start_node = net.nearest_node(a, SAME_POINT_M).map(|(n, _)| n);
        self.start_node = start_node;
        let proposed = a + dir(road.angle) * road.length;
        // The proposal as given, snapped: taken when that road is legal.
        let first = self.snap_event(net, start_node, a, proposed, road.class);
        if let Ok(Some(ev)) = first {
            let end = ev.point();
            let len = a.distance(end);
            let start_ok = start_node.is_none_or(|s| self.angle_ok_at(net, s, proposed));
            if start_ok && len >= min_len && self.legality.segment_ok(a, end) {
                self.count_snap(&ev);
                road.end = end;
                road.angle = angle_of(end - a);
                road.length = len;
                road.bridge = false;
                road.tunnel = false;
                road.snapped = true;
                road.crossed = matches!(ev, SnapEvent::Cross { .. });
                return QueryState::Succeed;
            }
        }
        // Step 1: legality.
        let Some((mut end, angle, span)) = self.make_legal(a, road.angle, road.length, road.class)
        else {
            return QueryState::Failed;
        };
        let (bridge, tunnel) = (span == Span::Bridge, span == Span::Tunnel);
        if let Some(s) = start_node
            && !self.angle_ok_at(net, s, end)
        {
            self.stats.failed_angle += 1;
            return QueryState::Failed;
        }
        // Step 2: self-sensitivity (the snap of the unchanged proposal is known already).
        let event = if end == proposed {
            first
        } else {
            self.snap_event(net, start_node, a, end, road.class)
        };
        let mut snapped = false;
        let mut crossed = false;
        match event {
            Err(Refusal::Angle) => {
                self.stats.failed_angle += 1;
                return QueryState::Failed;
            }
            Err(Refusal::Tunnel) => {
                self.stats.failed_tunnel += 1;
                return QueryState::Failed;
            }
            Ok(Some(ev)) => {
                self.count_snap(&ev);
                end = ev.point();
                snapped = true;
                crossed = matches!(ev, SnapEvent::Cross { .. });
            }
            Ok(None) => {}
        }
        let len = a.distance(end);
        if len.is_nan() || len < min_len {
            self.stats.failed_short += 1;
            return QueryState::Failed;
        }
        let max_bridge = self.params.max_bridge_length_m;
        // A bridge cut short before the water, or a tunnel before the park or hill, is an
        // ordinary road.
        let on_ground = snapped && (bridge || tunnel) && self.legality.segment_ok(a, end);
        let (bridge, tunnel) = (bridge && !on_ground, tunnel && !on_ground);
        if snapped {
            let legal = if bridge {
                len <= max_bridge + 1e-9
                    && (self.legality.bridgeable(a, end)
                        || self.legality.point(end) == Some(Illegal::Water))
            } else if tunnel {
                // A tunnel ends at its far portal, on legal ground: never inside the hill.
                len <= self.params.max_tunnel_length_m + 1e-9
                    && tunnelable(&self.legality, a, end, self.params.tunnel_under_water)
            } else {
                self.legality.segment_ok(a, end)
            };
            if !legal {
                self.stats.failed_illegal += 1;
                return QueryState::Failed;
            }
        }
        // Highways snap to highways only, but a tunnel passes under no road at all: it
        // ends at the first road it would cross (a junction on legal ground there, its
        // far portal), or is refused.
        if tunnel && let Some(c) = self.first_crossing(net, start_node, a, end) {
            let under_water = self.params.tunnel_under_water;
            if !(a.distance(c) >= min_len && tunnelable(&self.legality, a, c, under_water)) {
                self.stats.failed_tunnel += 1;
                return QueryState::Failed;
            }
            (end, snapped, crossed) = (c, true, true);
        }
        let len = a.distance(end);
        road.end = end;
        road.angle = if snapped { angle_of(end - a) } else { angle };
        road.length = len;
        road.bridge = bridge;
        road.tunnel = tunnel;
        road.snapped = snapped;
        road.crossed = crossed;
        QueryState::Succeed
    }

    fn stats(&self) -> ConstraintStats {
        self.stats
    }

    fn start_node(&self) -> Option<NodeId> {
        self.start_node
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::sync::Arc;

    use polis_geom::field::{Constant, FnField};

    use super::*;

    /// Water in the strip 100 ≤ x ≤ 200; land elsewhere.
    fn strip() -> RoadInputs {
        let mut i = RoadInputs::flat(Arc::new(Constant(0.5)));
        i.water = Arc::new(FnField::new(|p: DVec2| {
            if (100.0..=200.0).contains(&p.x) {
                1.0
            } else {
                0.0
            }
        }));
        i
    }

    fn propose(
        c: &mut DefaultConstraints,
        start: (f64, f64),
        angle_deg: f64,
        len: f64,
        class: RoadClass,
    ) -> (QueryState, RoadAttr) {
        let mut r = RoadAttr::new(
            DVec2::new(start.0, start.1),
            angle_deg.to_radians(),
            len,
            class,
        );
        let s = c.adjust(&mut r, &RoadNetwork::new());
        (s, r)
    }

    #[test]
    fn prune_to_the_shore() {
        let p = RoadParams::default();
        let mut c = DefaultConstraints::new(&p, &strip());
        let (s, r) = propose(&mut c, (0.0, 0.0), 0.0, 150.0, RoadClass::Street);
        assert_eq!(s, QueryState::Succeed);
        assert!(r.end.x < 100.0 && r.end.x > 99.0, "{:?}", r.end);
        assert_eq!(c.stats().pruned, 1);
    }

    #[test]
    fn highway_bridges_streets_do_not() {
        let p = RoadParams::default();
        let mut c = DefaultConstraints::new(&p, &strip());
        let (s, r) = propose(&mut c, (95.0, 0.0), 0.0, 90.0, RoadClass::Highway);
        assert_eq!(s, QueryState::Succeed);
        assert!(r.bridge);
        assert!(r.end.x > 200.0 && r.length <= p.max_bridge_length_m);
        let (s, _) = propose(&mut c, (95.0, 0.0), 0.0, 90.0, RoadClass::Street);
        assert_eq!(s, QueryState::Failed);
        // Water wider than the limit: no bridge.
        let p = RoadParams {
            max_bridge_length_m: 80.0,
            ..RoadParams::default()
        };
        let mut c = DefaultConstraints::new(&p, &strip());
        let (s, _) = propose(&mut c, (95.0, 0.0), 0.0, 90.0, RoadClass::Highway);
        assert_eq!(s, QueryState::Failed);
    }

    #[test]
    fn rotate_around_a_pond() {
        let mut i = RoadInputs::flat(Arc::new(Constant(0.5)));
        i.water = Arc::new(FnField::new(|p: DVec2| {
            if p.distance(DVec2::new(60.0, -10.0)) < 25.0 {
                1.0
            } else {
                0.0
            }
        }));
        let p = RoadParams::default();
        let mut c = DefaultConstraints::new(&p, &i);
        let (s, r) = propose(&mut c, (0.0, 0.0), 0.0, 90.0, RoadClass::Street);
        assert_eq!(s, QueryState::Succeed);
        assert!(
            r.angle > 0.0 && r.angle <= p.max_rotate_deg.to_radians() + 1e-9,
            "{}",
            r.angle
        );
        assert_eq!(c.stats().rotated, 1);
        assert!(c.legality().segment_ok(r.start, r.end));
    }

    #[test]
    fn outside_the_map_fails() {
        let p = RoadParams::default();
        let mut c = DefaultConstraints::new(&p, &RoadInputs::flat(Arc::new(Constant(0.5))));
        let (s, _) = propose(&mut c, (1990.0, 0.0), 0.0, 200.0, RoadClass::Street);
        assert_eq!(s, QueryState::Failed);
    }

    #[test]
    fn minimum_angle_at_a_junction() {
        let p = RoadParams::default();
        let mut c = DefaultConstraints::new(&p, &RoadInputs::flat(Arc::new(Constant(0.5))));
        let mut n = RoadNetwork::new();
        let road = crate::network::Road {
            class: RoadClass::Street,
            width: 8.0,
            bridge: false,
            tunnel: false,
            step: 0,
        };
        n.insert_segment(
            DVec2::ZERO,
            DVec2::new(100.0, 0.0),
            road,
            &Default::default(),
        )
        .unwrap();
        // 10° off the existing road at its end junction: refused.
        let mut r = RoadAttr::new(DVec2::ZERO, 10f64.to_radians(), 90.0, RoadClass::Street);
        assert_eq!(c.adjust(&mut r, &n), QueryState::Failed);
        assert_eq!(c.stats().failed_angle, 1);
        let mut r = RoadAttr::new(DVec2::ZERO, 90f64.to_radians(), 90.0, RoadClass::Street);
        assert_eq!(c.adjust(&mut r, &n), QueryState::Succeed);
    }
}
