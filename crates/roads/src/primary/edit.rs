//! Edits with validity checking (Kelly §5.3–5.4): every change is first *proposed*,
//! giving a [`Preview`] of the corrected change or a typed refusal, and then committed
//! exactly as previewed.
//!
//! # Corrections (Kelly §5.3.2, Fig. 69)
//!
//! * **Node snap.** A proposed road end within [`EditOptions::snap_distance_m`] of a node
//!   is that node.
//! * **Road snap (T-junction).** Otherwise, an end within the snap distance of a road's
//!   path becomes a new node on that path (the road is split there).
//! * **Road intersection.** Wherever a new road's path crosses an existing path, a
//!   junction node is inserted on both; the crossed road is split, each piece keeping
//!   its path exactly (nothing else moves).
//!
//! # Refusals
//!
//! Zero length (a road or piece shorter than [`EditOptions::min_road_length_m`]), a road
//! from a node to itself or between already joined nodes, collinear overlap with another
//! path, a meeting angle below [`EditOptions::min_angle_deg`] (at a node, a T-junction or
//! a crossing), a crossing within the snap distance of a node, a path crossing itself, a
//! node outside the map or on water or park, unknown ids, non-finite coordinates, bad
//! parameters, a plot that is blocked or needs too long a bridge.
//!
//! # Moves and parameter changes re-plot, and never insert junctions
//!
//! Moving a node re-plots all its roads; changing a road's parameters re-plots that road.
//! If a re-plotted path would cross or touch another road (or another re-plotted one),
//! the edit is **refused** with [`PrimaryError::WouldCross`]. A drag passes through many
//! positions, and inserting junctions would make the network depend on the path of the
//! drag rather than on where the node ends up; refusing keeps ids and topology stable
//! while dragging (the node stays at the last position that was valid), and the user
//! adds a crossing road explicitly when a junction is wanted.

use std::collections::BTreeMap;

use polis_geom::DVec2;
use polis_geom::predicates::SegmentIntersection;
use serde::{Deserialize, Serialize};

use crate::primary::error::PrimaryError;
use crate::primary::network::{
    ControlId, ControlNode, Cut, Patch, PrimaryNetwork, PrimaryRoad, RoadId, cut_path,
};
use crate::primary::params::{EditOptions, RoadSpec};
use crate::primary::plot::{RoadPath, plot_path};
use crate::primary::terrain::Terrain;
use crate::primary::validity::{angle_deg, check_site, crossing_angle_deg, first_contact};

/// One end of a proposed road.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Endpoint {
    /// An existing control node.
    Node(ControlId),
    /// A point: snapped to a node or a road within the snap distance, else a new node.
    At(DVec2),
}

/// An edit of the primary network (Kelly's node tools §5.3 and road tools §5.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Edit {
    /// Add a node at a point; on a road (within the snap distance) it splits the road.
    AddNode {
        /// Where, metres.
        at: DVec2,
        /// Optional label.
        label: Option<String>,
    },
    /// Move a node and re-plot its roads.
    MoveNode {
        /// The node.
        node: ControlId,
        /// Its new position.
        to: DVec2,
    },
    /// Delete a node and its roads.
    DeleteNode {
        /// The node.
        node: ControlId,
    },
    /// Add a road between two ends (with node snap, T-junctions and crossings).
    AddRoad {
        /// Its first end.
        from: Endpoint,
        /// Its second end.
        to: Endpoint,
        /// What road.
        spec: RoadSpec,
    },
    /// The chain tool (§5.3.1): a road from `from` to a new (or snapped) node at `to`;
    /// the preview's [`Preview::end_node`] is the node to chain from next.
    Chain {
        /// The selected node.
        from: ControlId,
        /// The clicked point.
        to: DVec2,
        /// What road.
        spec: RoadSpec,
    },
    /// Delete a road (its nodes stay).
    DeleteRoad {
        /// The road.
        road: RoadId,
    },
    /// Change a road's class, width or adaptive parameters; the road is re-plotted.
    SetRoad {
        /// The road.
        road: RoadId,
        /// The new spec.
        spec: RoadSpec,
    },
}

/// A correction validity checking applied to a proposed edit (Fig. 69).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Correction {
    /// A proposed end snapped to an existing node.
    SnappedToNode {
        /// The proposed point.
        point: DVec2,
        /// The node used.
        node: ControlId,
    },
    /// A proposed end (or node) put onto a road as a new junction node.
    OnRoad {
        /// The junction.
        at: DVec2,
        /// The road split there.
        road: RoadId,
        /// The new node.
        node: ControlId,
    },
    /// A crossing with an existing road became a junction node on both.
    Junction {
        /// The crossing.
        at: DVec2,
        /// The road crossed (and split).
        road: RoadId,
        /// The new node.
        node: ControlId,
    },
}

/// What a commit changed: which nodes and roads were added, removed, moved or
/// re-plotted (a later stage re-derives the city cells these touch). Ids increasing.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct ChangeSet {
    /// New nodes.
    pub nodes_added: Vec<ControlId>,
    /// Deleted nodes.
    pub nodes_removed: Vec<ControlId>,
    /// Nodes whose position (or label) changed.
    pub nodes_moved: Vec<ControlId>,
    /// New roads (including the new pieces of split roads).
    pub roads_added: Vec<RoadId>,
    /// Deleted roads.
    pub roads_removed: Vec<RoadId>,
    /// Roads whose path or spec changed (re-plotted, or cut short by a split).
    pub roads_replotted: Vec<RoadId>,
}

impl ChangeSet {
    /// The changes from `before` to `after` (two states of the same items).
    pub fn between(before: &Patch, after: &Patch) -> ChangeSet {
        let mut c = ChangeSet::default();
        for ((id, b), (_, a)) in before.nodes.iter().zip(&after.nodes) {
            match (b, a) {
                (None, Some(_)) => c.nodes_added.push(*id),
                (Some(_), None) => c.nodes_removed.push(*id),
                (Some(x), Some(y)) if x != y => c.nodes_moved.push(*id),
                _ => {}
            }
        }
        for ((id, b), (_, a)) in before.roads.iter().zip(&after.roads) {
            match (b, a) {
                (None, Some(_)) => c.roads_added.push(*id),
                (Some(_), None) => c.roads_removed.push(*id),
                (Some(x), Some(y)) if x != y => c.roads_replotted.push(*id),
                _ => {}
            }
        }
        c
    }

    /// Whether nothing changed.
    pub fn is_empty(&self) -> bool {
        self == &ChangeSet::default()
    }
}

/// A proposed edit after validity checking: exactly what [`PrimaryNetwork::commit`] will
/// write.
#[derive(Debug, Clone, PartialEq)]
pub struct Preview {
    pub(crate) edit: Edit,
    pub(crate) before: Patch,
    pub(crate) after: Patch,
    pub(crate) revision: u64,
    pub(crate) changes: ChangeSet,
    pub(crate) corrections: Vec<Correction>,
    pub(crate) end: Option<ControlId>,
}

impl Preview {
    /// The edit as proposed.
    pub fn edit(&self) -> &Edit {
        &self.edit
    }

    /// What the commit will change.
    pub fn changes(&self) -> &ChangeSet {
        &self.changes
    }

    /// The corrections applied (snaps, T-junctions, crossing junctions).
    pub fn corrections(&self) -> &[Correction] {
        &self.corrections
    }

    /// For road edits: the node at the road's second end (the chain tool continues from
    /// it).
    pub fn end_node(&self) -> Option<ControlId> {
        self.end
    }

    /// The nodes as they will be (`None` = deleted).
    pub fn nodes(&self) -> &[(ControlId, Option<ControlNode>)] {
        &self.after.nodes
    }

    /// The roads as they will be (`None` = deleted): new paths to draw while previewing.
    pub fn roads(&self) -> &[(RoadId, Option<PrimaryRoad>)] {
        &self.after.roads
    }

    /// The state the commit writes, and the state it overwrites (for undo).
    pub fn patches(&self) -> (&Patch, &Patch) {
        (&self.before, &self.after)
    }
}

impl PrimaryNetwork {
    /// Validity-checks `edit` against this network on `terrain` (see the
    /// [module docs](self)). The network is not changed.
    ///
    /// # Errors
    /// A typed refusal naming the reason.
    pub fn propose(
        &self,
        edit: &Edit,
        terrain: &Terrain,
        options: &EditOptions,
    ) -> Result<Preview, PrimaryError> {
        options.validate()?;
        let mut d = Draft::new(self, terrain, options);
        let end = match edit {
            Edit::AddNode { at, label } => {
                d.add_node(*at, label.clone())?;
                None
            }
            Edit::MoveNode { node, to } => {
                d.move_node(*node, *to)?;
                None
            }
            Edit::DeleteNode { node } => {
                self.node(*node)?;
                for &r in self.roads_at(*node) {
                    d.roads.insert(r, None);
                }
                d.nodes.insert(*node, None);
                None
            }
            Edit::AddRoad { from, to, spec } => Some(d.add_road(from, to, spec)?),
            Edit::Chain { from, to, spec } => {
                Some(d.add_road(&Endpoint::Node(*from), &Endpoint::At(*to), spec)?)
            }
            Edit::DeleteRoad { road } => {
                self.road(*road)?;
                d.roads.insert(*road, None);
                None
            }
            Edit::SetRoad { road, spec } => {
                spec.validate()?;
                let mut r = self.road(*road)?.clone();
                r.spec = *spec;
                d.roads.insert(*road, Some(r));
                d.replot(&[*road])?;
                None
            }
        };
        let after = Patch {
            nodes: d.nodes.into_iter().collect(),
            roads: d.roads.into_iter().collect(),
            next_node: d.next_node,
            next_road: d.next_road,
        };
        let before = self.snapshot(&after);
        Ok(Preview {
            edit: edit.clone(),
            changes: ChangeSet::between(&before, &after),
            before,
            after,
            revision: self.revision(),
            corrections: d.corrections,
            end,
        })
    }

    /// Applies a preview of this network exactly as proposed.
    ///
    /// # Errors
    /// [`PrimaryError::StalePreview`] if the network changed since the proposal.
    pub fn commit(&mut self, preview: &Preview) -> Result<ChangeSet, PrimaryError> {
        if preview.revision != self.revision() || self.snapshot(&preview.after) != preview.before {
            return Err(PrimaryError::StalePreview);
        }
        self.apply(&preview.after)?;
        Ok(preview.changes.clone())
    }

    /// Applies a patch whose prior state is `expect` (undo / redo of a logged commit).
    pub(crate) fn swap_patch(
        &mut self,
        expect: &Patch,
        to: &Patch,
    ) -> Result<ChangeSet, PrimaryError> {
        if &self.snapshot(to) != expect {
            return Err(PrimaryError::StalePreview);
        }
        self.apply(to)?;
        Ok(ChangeSet::between(expect, to))
    }
}

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
struct Draft<'a> {
    net: &'a PrimaryNetwork,
    terrain: &'a Terrain,
    opts: &'a EditOptions,
    nodes: BTreeMap<ControlId, Option<ControlNode>>,
    roads: BTreeMap<RoadId, Option<PrimaryRoad>>,
    next_node: u64,
    next_road: u64,
    corrections: Vec<Correction>,
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
    fn new(net: &'a PrimaryNetwork, terrain: &'a Terrain, opts: &'a EditOptions) -> Self {
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
        if let Some((node, distance)) = self.net.nearest_node(p, self.opts.snap_distance_m) {
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

    fn add_node(&mut self, at: DVec2, label: Option<String>) -> Result<(), PrimaryError> {
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

    fn add_road(
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

    fn move_node(&mut self, node: ControlId, to: DVec2) -> Result<(), PrimaryError> {
        let old = self.node(node)?.clone();
        check_site(to, "node", self.terrain)?;
        let snap = self.opts.snap_distance_m;
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
    fn replot(&mut self, roads: &[RoadId]) -> Result<(), PrimaryError> {
        let min = self.opts.min_road_length_m;
        let mut fresh: Vec<(RoadId, PrimaryRoad)> = Vec::with_capacity(roads.len());
        for &id in roads {
            let mut r = self.road(id)?.clone();
            let (pa, pb) = (self.node(r.a)?.pos, self.node(r.b)?.pos);
            r.path = plot_path(pa, pb, &r.spec.params, self.terrain)?;
            too_short(&r.path, min)?;
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
