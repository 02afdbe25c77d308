//! The draft an edit builds on top of the network before it becomes a [`Preview`]:
//! resolving ends (node snap, T-junctions), plotting, finding crossings and splitting
//! roads at junctions, re-plotting for moves and parameter changes, and every refusal of
//! validity checking (see [`crate::primary::edit`]).

use std::collections::BTreeMap;

use polis_geom::DVec2;
use polis_geom::predicates::SegmentIntersection;

use crate::primary::edit::{Correction, Endpoint};
use crate::primary::error::PrimaryError;
use crate::primary::network::{
    ControlId, ControlNode, Cut, PrimaryNetwork, PrimaryRoad, RoadId, cut_path,
};
use crate::primary::params::{EditOptions, RoadSpec};
use crate::primary::plot::{RoadPath, plot_path};
use crate::primary::terrain::Terrain;
use crate::primary::validity::{angle_deg, check_site, crossing_angle_deg, first_contact};

/// A resolved road end.
#[derive(Debug, Clone, Copy)]
enum End {
    Node(ControlId, DVec2),
    OnRoad(RoadId, usize, DVec2),
    Free(DVec2),
}

impl End {
    fn pos(&self) -> DVec2 {
        match *self {
            End::Node(_, p) | End::OnRoad(_, _, p) | End::Free(p) => p,
        }
    }
}

/// A crossing of a new path with an existing one.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    seg: usize,
    t: f64,
    road: RoadId,
    road_seg: usize,
    at: DVec2,
}

/// The state an edit is building on top of the network.
pub(crate) struct Draft<'a> {
    net: &'a PrimaryNetwork,
    terrain: &'a Terrain,
    opts: &'a EditOptions,
    pub(crate) nodes: BTreeMap<ControlId, Option<ControlNode>>,
    pub(crate) roads: BTreeMap<RoadId, Option<PrimaryRoad>>,
    pub(crate) next_node: u64,
    pub(crate) next_road: u64,
    pub(crate) corrections: Vec<Correction>,
}

/// A path's vertex `k` is a cut at a vertex: re-express a point on segment `seg` that
/// equals its far vertex as a cut at that vertex.
fn normalize_cut(path: &RoadPath, seg: usize, at: DVec2) -> usize {
    if path.points.get(seg + 1) == Some(&at) {
        seg + 1
    } else {
        seg
    }
}

fn too_short(path: &RoadPath, min: f64) -> Result<(), PrimaryError> {
    let length = path.length();
    if length < min {
        return Err(PrimaryError::ZeroLength {
            at: path.points.first().copied().unwrap_or(DVec2::NAN),
            length,
            min,
        });
    }
    Ok(())
}

fn contact_point(kind: &SegmentIntersection) -> DVec2 {
    match *kind {
        SegmentIntersection::Crossing { point, .. }
        | SegmentIntersection::Touching { point, .. } => point,
        SegmentIntersection::Overlap { start, .. } => start,
        SegmentIntersection::Disjoint => DVec2::NAN,
    }
}

impl<'a> Draft<'a> {
    pub(crate) fn new(
        net: &'a PrimaryNetwork,
        terrain: &'a Terrain,
        opts: &'a EditOptions,
    ) -> Self {
        Draft {
            net,
            terrain,
            opts,
            nodes: BTreeMap::new(),
            roads: BTreeMap::new(),
            next_node: net.next_node_id().0,
            next_road: net.next_road_id().0,
            corrections: Vec::new(),
        }
    }

    fn node(&self, id: ControlId) -> Result<&ControlNode, PrimaryError> {
        match self.nodes.get(&id) {
            Some(Some(n)) => Ok(n),
            Some(None) => Err(PrimaryError::UnknownNode(id)),
            None => self.net.node(id),
        }
    }

    fn road(&self, id: RoadId) -> Result<&PrimaryRoad, PrimaryError> {
        match self.roads.get(&id) {
            Some(Some(r)) => Ok(r),
            Some(None) => Err(PrimaryError::UnknownRoad(id)),
            None => self.net.road(id),
        }
    }

    fn new_node(&mut self, pos: DVec2, label: Option<String>) -> Result<ControlId, PrimaryError> {
        let elevation = self.terrain.elevation(pos);
        if !elevation.is_finite() {
            return Err(PrimaryError::OutsideMap { point: pos });
        }
        let id = ControlId(self.next_node);
        self.next_node += 1;
        self.nodes.insert(
            id,
            Some(ControlNode {
                pos,
                elevation,
                label,
            }),
        );
        Ok(id)
    }

    fn new_road_id(&mut self) -> RoadId {
        let id = RoadId(self.next_road);
        self.next_road += 1;
        id
    }

    /// Refuses a new node at `p` within the snap distance of an existing node.
    fn clear_of_nodes(&self, p: DVec2) -> Result<(), PrimaryError> {
        let r = self.opts.snap_distance_m.max(self.opts.min_road_length_m);
        if let Some((node, distance)) = self.net.nearest_node(p, r) {
            return Err(PrimaryError::NodeTooClose {
                point: p,
                node,
                distance,
            });
        }
        Ok(())
    }

    /// Resolves a road end (node snap, road snap, free point).
    fn resolve(&mut self, e: &Endpoint) -> Result<End, PrimaryError> {
        let snap = self.opts.snap_distance_m;
        match *e {
            Endpoint::Node(id) => Ok(End::Node(id, self.node(id)?.pos)),
            Endpoint::At(p) => {
                if !(p.is_finite() && p.abs().max_element() <= polis_geom::MAX_COORDINATE) {
                    return Err(PrimaryError::BadCoordinate {
                        what: "road end",
                        point: p,
                    });
                }
                if let Some((node, _)) = self.net.nearest_node(p, snap) {
                    self.corrections
                        .push(Correction::SnappedToNode { point: p, node });
                    return Ok(End::Node(node, self.node(node)?.pos));
                }
                if let Some((road, seg, c, _)) = self.net.nearest_road(p, snap) {
                    check_site(c, "junction", self.terrain)?;
                    self.clear_of_nodes(c)?;
                    return Ok(End::OnRoad(road, seg as usize, c));
                }
                check_site(p, "road end", self.terrain)?;
                Ok(End::Free(p))
            }
        }
    }

    /// Refuses a path passing within the minimum road length of a node other than `ends`.
    fn clear_path(
        &self,
        road: RoadId,
        path: &RoadPath,
        ends: &[ControlId],
    ) -> Result<(), PrimaryError> {
        let r = self.opts.min_road_length_m;
        for w in path.points.windows(2) {
            for (node, distance) in self.net.nodes_near_segment(w[0], w[1], r) {
                if !ends.contains(&node) {
                    return Err(PrimaryError::PassesNode {
                        road,
                        node,
                        distance,
                    });
                }
            }
        }
        Ok(())
    }

    pub(crate) fn add_node(
        &mut self,
        at: DVec2,
        label: Option<String>,
    ) -> Result<(), PrimaryError> {
        check_site(at, "node", self.terrain)?;
        self.clear_of_nodes(at)?;
        match self.net.nearest_road(at, self.opts.snap_distance_m) {
            Some((road, seg, c, _)) => {
                check_site(c, "node", self.terrain)?;
                self.clear_of_nodes(c)?;
                let node = self.new_node(c, label)?;
                let seg = normalize_cut(&self.road(road)?.path, seg as usize, c);
                self.corrections
                    .push(Correction::OnRoad { at: c, road, node });
                self.split_road(road, vec![(seg, c, node)])
            }
            None => self.new_node(at, label).map(|_| ()),
        }
    }

    /// Splits an existing road at cuts `(segment, point, node)` (any order).
    fn split_road(
        &mut self,
        road: RoadId,
        mut cuts: Vec<(usize, DVec2, ControlId)>,
    ) -> Result<(), PrimaryError> {
        let r = self.road(road)?.clone();
        let pts = &r.path.points;
        cuts.sort_by(|x, y| {
            x.0.cmp(&y.0).then(
                pts[x.0]
                    .distance_squared(x.1)
                    .total_cmp(&pts[y.0].distance_squared(y.1)),
            )
        });
        let mut path_cuts = Vec::with_capacity(cuts.len());
        let mut ends = vec![r.a];
        for &(seg, at, node) in &cuts {
            if (seg == 0 && at == pts[0]) || seg + 1 >= pts.len() {
                return Err(PrimaryError::CrossingNearNode { at, road });
            }
            path_cuts.push(Cut {
                seg,
                point: at,
                elevation: self.node(node)?.elevation,
            });
            ends.push(node);
        }
        ends.push(r.b);
        let pieces = cut_path(&r.path, &path_cuts);
        for (i, path) in pieces.into_iter().enumerate() {
            too_short(&path, self.opts.min_road_length_m)?;
            let id = if i == 0 { road } else { self.new_road_id() };
            let piece = PrimaryRoad {
                a: ends[i],
                b: ends[i + 1],
                spec: r.spec,
                path,
            };
            self.roads.insert(id, Some(piece));
        }
        Ok(())
    }

    /// The smallest angle at node position `o` between `leave` and the roads `others`
    /// leave it by; refuses below the minimum.
    fn check_angle(
        &self,
        o: DVec2,
        leave: DVec2,
        others: impl IntoIterator<Item = DVec2>,
    ) -> Result<(), PrimaryError> {
        let min_deg = self.opts.min_angle_deg;
        for q in others {
            let angle_deg = angle_deg(o, leave, q);
            if angle_deg < min_deg {
                return Err(PrimaryError::AngleTooSmall {
                    at: o,
                    angle_deg,
                    min_deg,
                });
            }
        }
        Ok(())
    }

    pub(crate) fn add_road(
        &mut self,
        from: &Endpoint,
        to: &Endpoint,
        spec: &RoadSpec,
    ) -> Result<ControlId, PrimaryError> {
        spec.validate()?;
        let ea = self.resolve(from)?;
        let eb = self.resolve(to)?;
        if let (End::Node(a, _), End::Node(b, _)) = (ea, eb) {
            if a == b {
                return Err(PrimaryError::SelfLoop(a));
            }
            if let Some(existing) = self.net.road_between(a, b) {
                return Err(PrimaryError::DuplicateRoad { a, b, existing });
            }
        }
        let (pa, pb) = (ea.pos(), eb.pos());
        let min = self.opts.min_road_length_m;
        if pa.distance(pb) < min.max(self.opts.snap_distance_m) {
            return Err(PrimaryError::ZeroLength {
                at: pa,
                length: pa.distance(pb),
                min,
            });
        }
        let path = plot_path(pa, pb, &spec.params, self.terrain)?;
        too_short(&path, min)?;
        let new_id = RoadId(u64::MAX);
        if let Some(c) = first_contact(&[(new_id, &path.points)], |_| false) {
            return Err(PrimaryError::SelfCrossing { at: c.point() });
        }
        let crossings = self.crossings(&path, ea, eb)?;
        let own: Vec<ControlId> = [ea, eb]
            .iter()
            .filter_map(|e| match *e {
                End::Node(id, _) => Some(id),
                _ => None,
            })
            .collect();
        self.clear_path(new_id, &path, &own)?;
        // Angles where the road meets nodes and the roads it joins.
        let n = path.points.len();
        for (end, leave) in [(ea, path.points[1]), (eb, path.points[n - 2])] {
            match end {
                End::Node(id, o) => {
                    let others: Vec<DVec2> = self
                        .net
                        .roads_at(id)
                        .iter()
                        .filter_map(|&r| self.net.road(r).ok()?.leaving(id))
                        .collect();
                    self.check_angle(o, leave, others)?;
                }
                End::OnRoad(r, seg, c) => {
                    let rp = &self.road(r)?.path.points;
                    let seg = normalize_cut(&self.road(r)?.path, seg, c);
                    // The road's directions away from the junction: the vertices around it.
                    let before = if rp.get(seg) == Some(&c) {
                        seg.checked_sub(1).and_then(|k| rp.get(k))
                    } else {
                        rp.get(seg)
                    };
                    let (Some(&before), Some(&after)) = (before, rp.get(seg + 1)) else {
                        return Err(PrimaryError::CrossingNearNode { at: c, road: r });
                    };
                    self.check_angle(c, leave, [before, after])?;
                }
                End::Free(_) => {}
            }
        }
        // Nodes: the ends, then the crossings along the path.
        let node_of = |d: &mut Self, e: End| -> Result<ControlId, PrimaryError> {
            match e {
                End::Node(id, _) => Ok(id),
                End::OnRoad(_, _, p) | End::Free(p) => d.new_node(p, None),
            }
        };
        let a = node_of(self, ea)?;
        let b = node_of(self, eb)?;
        let mut splits: BTreeMap<RoadId, Vec<(usize, DVec2, ControlId)>> = BTreeMap::new();
        for (end, node) in [(ea, a), (eb, b)] {
            if let End::OnRoad(road, seg, c) = end {
                let seg = normalize_cut(&self.road(road)?.path, seg, c);
                splits.entry(road).or_default().push((seg, c, node));
                self.corrections
                    .push(Correction::OnRoad { at: c, road, node });
            }
        }
        let mut own_cuts = Vec::with_capacity(crossings.len());
        let mut ends = vec![a];
        for x in &crossings {
            let node = self.new_node(x.at, None)?;
            let rseg = normalize_cut(&self.road(x.road)?.path, x.road_seg, x.at);
            splits.entry(x.road).or_default().push((rseg, x.at, node));
            let seg = normalize_cut(&path, x.seg, x.at);
            own_cuts.push(Cut {
                seg,
                point: x.at,
                elevation: self.node(node)?.elevation,
            });
            ends.push(node);
            self.corrections.push(Correction::Junction {
                at: x.at,
                road: x.road,
                node,
            });
        }
        ends.push(b);
        for (i, piece) in cut_path(&path, &own_cuts).into_iter().enumerate() {
            too_short(&piece, min)?;
            let id = self.new_road_id();
            self.roads.insert(
                id,
                Some(PrimaryRoad {
                    a: ends[i],
                    b: ends[i + 1],
                    spec: *spec,
                    path: piece,
                }),
            );
        }
        for (road, cuts) in splits {
            self.split_road(road, cuts)?;
        }
        Ok(b)
    }

    /// The crossings of a new path with existing ones, along the path; refuses overlaps,
    /// shallow crossings and crossings near nodes.
    fn crossings(&self, path: &RoadPath, ea: End, eb: End) -> Result<Vec<Crossing>, PrimaryError> {
        let n = path.points.len();
        let excused = |end: End, road: RoadId| match end {
            End::Node(id, _) => self.net.roads_at(id).contains(&road),
            End::OnRoad(r, _, _) => r == road,
            End::Free(_) => false,
        };
        let mut out: Vec<Crossing> = Vec::new();
        for (k, w) in path.points.windows(2).enumerate() {
            for (road, j, t, kind) in self.net.path_hits(w[0], w[1]) {
                let at = contact_point(&kind);
                if let SegmentIntersection::Overlap { .. } = kind {
                    return Err(PrimaryError::CollinearOverlap { road, at });
                }
                if (at == path.points[0] && excused(ea, road))
                    || (at == path.points[n - 1] && excused(eb, road))
                {
                    continue;
                }
                if out.iter().any(|c| c.road == road && c.at == at) {
                    continue;
                }
                let (b0, b1) = self
                    .net
                    .road(road)?
                    .path
                    .points
                    .get(j as usize..j as usize + 2)
                    .map_or((at, at), |s| (s[0], s[1]));
                let angle_deg = crossing_angle_deg(w[0], w[1], b0, b1);
                if angle_deg < self.opts.min_angle_deg {
                    return Err(PrimaryError::AngleTooSmall {
                        at,
                        angle_deg,
                        min_deg: self.opts.min_angle_deg,
                    });
                }
                let snap = self.opts.snap_distance_m;
                if self.net.nearest_node(at, snap).is_some()
                    || at.distance(path.points[0]) <= snap
                    || at.distance(path.points[n - 1]) <= snap
                {
                    return Err(PrimaryError::CrossingNearNode { at, road });
                }
                match self.terrain.point(at) {
                    None => {}
                    Some(what) => return Err(PrimaryError::IllegalNode { point: at, what }),
                }
                out.push(Crossing {
                    seg: k,
                    t,
                    road,
                    road_seg: j as usize,
                    at,
                });
            }
        }
        out.sort_by(|x, y| {
            x.seg
                .cmp(&y.seg)
                .then(x.t.total_cmp(&y.t))
                .then(x.road.cmp(&y.road))
        });
        for w in out.windows(2) {
            if w[0].at.distance(w[1].at)
                < self.opts.min_road_length_m.max(self.opts.snap_distance_m)
            {
                return Err(PrimaryError::CrossingNearNode {
                    at: w[1].at,
                    road: w[1].road,
                });
            }
        }
        Ok(out)
    }

    pub(crate) fn move_node(&mut self, node: ControlId, to: DVec2) -> Result<(), PrimaryError> {
        let old = self.node(node)?.clone();
        check_site(to, "node", self.terrain)?;
        let snap = self.opts.snap_distance_m.max(self.opts.min_road_length_m);
        if let Some(p) = self.net.nearest_node_except(to, snap, node) {
            return Err(PrimaryError::NodeTooClose {
                point: to,
                node: p.0,
                distance: p.1,
            });
        }
        let own = self.net.roads_at(node).to_vec();
        if let Some(road) = self.net.nearest_road_except(to, snap, &own) {
            return Err(PrimaryError::OnRoad { point: to, road });
        }
        let elevation = self.terrain.elevation(to);
        self.nodes.insert(
            node,
            Some(ControlNode {
                pos: to,
                elevation,
                label: old.label,
            }),
        );
        self.replot(&own)
    }

    /// Re-plots `roads` between their (draft) end nodes; refuses any new contact.
    pub(crate) fn replot(&mut self, roads: &[RoadId]) -> Result<(), PrimaryError> {
        let min = self.opts.min_road_length_m;
        let mut fresh: Vec<(RoadId, PrimaryRoad)> = Vec::with_capacity(roads.len());
        for &id in roads {
            let mut r = self.road(id)?.clone();
            let (pa, pb) = (self.node(r.a)?.pos, self.node(r.b)?.pos);
            r.path = plot_path(pa, pb, &r.spec.params, self.terrain)?;
            too_short(&r.path, min)?;
            self.clear_path(id, &r.path, &[r.a, r.b])?;
            fresh.push((id, r));
        }
        // Contacts with the roads that stay.
        for (id, r) in &fresh {
            let pts = &r.path.points;
            for w in pts.windows(2) {
                for (other, _, _, kind) in self.net.path_hits(w[0], w[1]) {
                    if roads.contains(&other) {
                        continue;
                    }
                    let at = contact_point(&kind);
                    let o = self.road(other)?;
                    let shared = [r.a, r.b]
                        .into_iter()
                        .any(|n| (o.a == n || o.b == n) && self.node(n).is_ok_and(|x| x.pos == at));
                    if shared && matches!(kind, SegmentIntersection::Touching { .. }) {
                        continue;
                    }
                    return Err(PrimaryError::WouldCross {
                        road: *id,
                        other,
                        at,
                    });
                }
            }
        }
        // Among the re-plotted paths (and each with itself).
        let paths: Vec<(RoadId, &[DVec2])> = fresh
            .iter()
            .map(|(id, r)| (*id, r.path.points.as_slice()))
            .collect();
        let by_id: BTreeMap<RoadId, &PrimaryRoad> = fresh.iter().map(|(id, r)| (*id, r)).collect();
        if let Some(c) = first_contact(&paths, |c| {
            let (Some(x), Some(y)) = (by_id.get(&c.a.0), by_id.get(&c.b.0)) else {
                return false;
            };
            c.a.0 != c.b.0
                && matches!(c.kind, SegmentIntersection::Touching { .. })
                && [x.a, x.b].into_iter().any(|n| {
                    (y.a == n || y.b == n) && self.node(n).is_ok_and(|q| q.pos == c.point())
                })
        }) {
            return Err(if c.a.0 == c.b.0 {
                PrimaryError::SelfCrossing { at: c.point() }
            } else {
                PrimaryError::WouldCross {
                    road: c.a.0,
                    other: c.b.0,
                    at: c.point(),
                }
            });
        }
        for (id, r) in fresh {
            self.roads.insert(id, Some(r));
        }
        // Angles at every end of a re-plotted road, against all roads there.
        let mut ends: Vec<ControlId> = Vec::new();
        for &id in roads {
            let r = self.road(id)?;
            ends.extend([r.a, r.b]);
        }
        ends.sort_unstable();
        ends.dedup();
        for n in ends {
            let o = self.node(n)?.pos;
            let at: Vec<(RoadId, DVec2)> = self
                .net
                .roads_at(n)
                .iter()
                .filter_map(|&r| Some((r, self.road(r).ok()?.leaving(n)?)))
                .collect();
            for (i, &(ri, pi)) in at.iter().enumerate() {
                for &(rj, pj) in &at[i + 1..] {
                    if roads.contains(&ri) || roads.contains(&rj) {
                        self.check_angle(o, pi, [pj])?;
                    }
                }
            }
        }
        Ok(())
    }
}
