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
//! a crossing), a crossing within the snap distance of a node, a path passing within the
//! minimum road length of a node that is not its end, a path crossing itself, a
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

use polis_geom::DVec2;
use serde::{Deserialize, Serialize};

use crate::primary::draft::Draft;
use crate::primary::error::PrimaryError;
use crate::primary::network::{ControlId, ControlNode, Patch, PrimaryNetwork, PrimaryRoad, RoadId};
use crate::primary::params::{EditOptions, RoadSpec};
use crate::primary::terrain::Terrain;

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
    /// Set or clear a node's label (Kelly's node property inspector).
    SetLabel {
        /// The node.
        node: ControlId,
        /// The new label.
        label: Option<String>,
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
            Edit::SetLabel { node, label } => {
                let mut n = self.node(*node)?.clone();
                n.label.clone_from(label);
                d.nodes.insert(*node, Some(n));
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
