//! The plain data a [`CityEditor`](super::CityEditor) speaks: [`Edit`] in, [`Preview`]
//! and [`ChangeEvents`] out. All serde, as tagged JSON (`{"op": "move_node", "node": 3,
//! "to": [120.0, -40.5]}`), so a browser or an engine can send and read them.

use polis_buildings::BuildingKind;
use polis_geom::DVec2;
use polis_roads::primary::{self, ChangeSet, ControlId, Correction, RoadId, RoadSpec};
use serde::{Deserialize, Serialize};

use crate::citygen::{CellParam, CellPatternChoice, LotOverride, PaintLayer};
use crate::error::{Error, Result};

/// One end of a road to add: an existing control node or a point (snapped to a node or
/// a road within the snap distance, else a new node). JSON: `{"node": 4}` or
/// `{"at": [x, y]}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum End {
    /// A control node by id.
    Node(u64),
    /// A point, metres.
    At([f64; 2]),
}

/// One edit of a Citygen city (Kelly §5: node, road and cell edit modes, the property
/// inspector, presets), plus overrides, map paint and global settings.
///
/// Primary-network edits go through the validity checks of
/// [`polis_roads::primary`] (node snap, T-junctions, crossings become junctions; moves
/// that would cross are refused). Cell edits name a city cell by its stable id
/// ([`CityEditor::cells`](super::CityEditor::cells)); lot and building edits name a lot
/// by its stable id (a building has its lot's id).
///
/// Incremental or not: every edit regenerates only the work whose inputs changed (see
/// [`CityEditor`](super::CityEditor)); [`SetFacadeStyle`](Edit::SetFacadeStyle) and
/// [`SetLod`](Edit::SetLod) change an input of every building, so they rebuild every
/// building and skin (a full rebuild of those stages; roads and lots are kept).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
#[non_exhaustive]
pub enum Edit {
    /// Add a control node (on a road within the snap distance, it splits the road).
    AddNode {
        /// Where, metres.
        at: [f64; 2],
        /// Optional label. Default: none.
        #[serde(default)]
        label: Option<String>,
    },
    /// Move a control node; its roads are re-plotted (refused if one would cross).
    MoveNode {
        /// The node.
        node: u64,
        /// Its new position, metres.
        to: [f64; 2],
    },
    /// Set or clear a node's label (no effect on the city).
    SetNodeLabel {
        /// The node.
        node: u64,
        /// The label.
        #[serde(default)]
        label: Option<String>,
    },
    /// Delete a node and its roads.
    DeleteNode {
        /// The node.
        node: u64,
    },
    /// Add a primary road (with node snap, T-junctions and crossings as junctions).
    AddRoad {
        /// First end.
        from: End,
        /// Second end.
        to: End,
        /// What road. Default: [`RoadSpec::default`] (a primary road).
        #[serde(default)]
        spec: RoadSpec,
    },
    /// Kelly's chain tool: a road from `from` to a new or snapped node at `to`.
    Chain {
        /// The node to continue from.
        from: u64,
        /// The clicked point, metres.
        to: [f64; 2],
        /// What road. Default: a primary road.
        #[serde(default)]
        spec: RoadSpec,
    },
    /// Delete a primary road (its nodes stay).
    DeleteRoad {
        /// The road.
        road: u64,
    },
    /// Change a road's class, width or plotting parameters (re-plotted).
    SetRoad {
        /// The road.
        road: u64,
        /// The new spec.
        spec: RoadSpec,
    },
    /// Give a cell a neighbourhood preset or grid pattern (Kelly §5.5.2's presets).
    SetCellPattern {
        /// The cell's stable id.
        cell: u64,
        /// The pattern.
        pattern: CellPatternChoice,
    },
    /// Set one growth or trait parameter of a cell, with its deviance (Kelly §5.5.1's
    /// property inspector): segment size, degree, snap size, road width, connectivity,
    /// lot size, building height, …
    SetCellParam {
        /// The cell's stable id.
        cell: u64,
        /// The parameter and its value.
        param: CellParam,
    },
    /// Give a cell its own growth seed.
    SetCellSeed {
        /// The cell's stable id.
        cell: u64,
        /// The seed.
        seed: u64,
    },
    /// Drop every setting of a cell (pattern, parameters, seed).
    ResetCell {
        /// The cell's stable id.
        cell: u64,
    },
    /// Pin the kind of the building on a lot.
    PinKind {
        /// The lot's (and building's) id.
        lot: u64,
        /// The kind.
        kind: BuildingKind,
    },
    /// Pin the height limit of the building on a lot, metres in (0, 1000] (the kind's
    /// drawn height is clamped to it: a tower stands at it).
    PinHeight {
        /// The lot.
        lot: u64,
        /// The height, metres.
        height_m: f64,
    },
    /// Pin the facade style of the building on a lot (a built-in style or one of
    /// `facades.styles`).
    PinStyle {
        /// The lot.
        lot: u64,
        /// The style's name.
        style: String,
    },
    /// Remove the building of a lot (the lot stays empty).
    RemoveBuilding {
        /// The lot.
        lot: u64,
    },
    /// Give the building of a lot a new seed.
    ReseedLot {
        /// The lot.
        lot: u64,
        /// The seed.
        seed: u64,
    },
    /// Drop every override of a lot.
    ClearLot {
        /// The lot.
        lot: u64,
    },
    /// Paint a rectangle of a map (population, zoning or park).
    Paint {
        /// The map.
        layer: PaintLayer,
        /// Minimum corner, metres.
        min: [f64; 2],
        /// Maximum corner, metres.
        max: [f64; 2],
        /// The value inside.
        value: f64,
    },
    /// Global: the facade style of a building kind (every building of the kind is
    /// re-dressed).
    SetFacadeStyle {
        /// The kind.
        kind: BuildingKind,
        /// The style's name.
        style: String,
    },
    /// Global: the level of detail (every building is rebuilt).
    SetLod {
        /// The level, or none for the building parameters' maximum.
        lod: Option<usize>,
    },
}

impl Edit {
    /// Whether this edits the primary network.
    pub fn is_primary(&self) -> bool {
        matches!(
            self,
            Edit::AddNode { .. }
                | Edit::MoveNode { .. }
                | Edit::SetNodeLabel { .. }
                | Edit::DeleteNode { .. }
                | Edit::AddRoad { .. }
                | Edit::Chain { .. }
                | Edit::DeleteRoad { .. }
                | Edit::SetRoad { .. }
        )
    }

    /// The primary-network edit this is, with every coordinate checked finite.
    ///
    /// # Errors
    /// [`Error::InvalidEdit`] for a non-finite coordinate.
    pub(crate) fn to_primary(&self) -> Result<Option<primary::Edit>> {
        let pt = |field: &str, p: [f64; 2]| -> Result<DVec2> {
            if p[0].is_finite() && p[1].is_finite() {
                Ok(DVec2::new(p[0], p[1]))
            } else {
                Err(Error::InvalidEdit {
                    field: field.into(),
                    reason: format!("[{}, {}]: give finite metres", p[0], p[1]),
                })
            }
        };
        let end = |field: &str, e: End| -> Result<primary::Endpoint> {
            Ok(match e {
                End::Node(n) => primary::Endpoint::Node(ControlId(n)),
                End::At(p) => primary::Endpoint::At(pt(field, p)?),
            })
        };
        Ok(Some(match self {
            Edit::AddNode { at, label } => primary::Edit::AddNode {
                at: pt("at", *at)?,
                label: label.clone(),
            },
            Edit::MoveNode { node, to } => primary::Edit::MoveNode {
                node: ControlId(*node),
                to: pt("to", *to)?,
            },
            Edit::SetNodeLabel { node, label } => primary::Edit::SetLabel {
                node: ControlId(*node),
                label: label.clone(),
            },
            Edit::DeleteNode { node } => primary::Edit::DeleteNode {
                node: ControlId(*node),
            },
            Edit::AddRoad { from, to, spec } => primary::Edit::AddRoad {
                from: end("from", *from)?,
                to: end("to", *to)?,
                spec: *spec,
            },
            Edit::Chain { from, to, spec } => primary::Edit::Chain {
                from: ControlId(*from),
                to: pt("to", *to)?,
                spec: *spec,
            },
            Edit::DeleteRoad { road } => primary::Edit::DeleteRoad {
                road: RoadId(*road),
            },
            Edit::SetRoad { road, spec } => primary::Edit::SetRoad {
                road: RoadId(*road),
                spec: *spec,
            },
            _ => return Ok(None),
        }))
    }
}

/// A primary road as a preview draws it: its id and its path after the edit (`None`:
/// deleted).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PreviewRoad {
    /// The road's id.
    pub road: u64,
    /// Its low-level path, metres, or none when the edit deletes it.
    pub path: Option<Vec<[f64; 2]>>,
}

/// What an edit would do, for the editor's red/green cursor (Kelly §5.3.2): whether it
/// is valid, why not, the corrections validity checking applied (snaps, T-junctions,
/// crossings), the roads as they would be, and the cells it would touch. Nothing is
/// changed by proposing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Preview {
    /// Whether [`CityEditor::apply`](super::CityEditor::apply) would accept the edit.
    pub valid: bool,
    /// Why not, when not valid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refusal: Option<String>,
    /// Corrections of a primary edit.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub corrections: Vec<Correction>,
    /// Primary roads as the edit leaves them (touched roads only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub roads: Vec<PreviewRoad>,
    /// For road edits, the node at the road's second end (the chain tool continues from
    /// it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_node: Option<u64>,
    /// City cells the edit names or whose bounding roads it touches (stable ids,
    /// increasing); a topology change may also create cells.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cells: Vec<u64>,
}

/// Removed, added and changed items of one kind, by stable id (each increasing).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Delta<T = u64> {
    /// Items that are gone.
    pub removed: Vec<T>,
    /// New items.
    pub added: Vec<T>,
    /// Items that are still there but differ.
    pub changed: Vec<T>,
}

impl<T> Delta<T> {
    /// Whether nothing changed.
    pub fn is_empty(&self) -> bool {
        self.removed.is_empty() && self.added.is_empty() && self.changed.is_empty()
    }

    /// How many items were removed, added or changed.
    pub fn len(&self) -> usize {
        self.removed.len() + self.added.len() + self.changed.len()
    }
}

/// What one committed edit (or undo, redo) changed, so a host updates only those
/// meshes: cells, blocks, lots, buildings and scene nodes by stable id.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ChangeEvents {
    /// The primary network's changes (nodes and roads by id), for primary edits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub primary: Option<ChangeSet>,
    /// City cells (the primary network's cells, by stable id) whose secondary roads were
    /// regenerated: the dirty set of the road stage.
    pub cells: Delta,
    /// The road graph's cells whose blocks and lots were regenerated, by the stable id
    /// the lots carry (`lot id >> 24`).
    pub blocks: Delta,
    /// Lots by id.
    pub lots: Delta,
    /// Buildings by id (the lot's id); a building whose skin changed is changed.
    pub buildings: Delta,
    /// Scene nodes by name (`cell <id>`, `block <id>`, `building <id>`, `roads`,
    /// `water`, …).
    pub scene_nodes: Delta<String>,
    /// Lot overrides that no longer find their lot (after this edit).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub orphaned: Vec<LotOverride>,
    /// Counts of the work redone: cells grown, road-graph cells subdivided, buildings
    /// built, buildings dressed.
    pub regenerated: Regenerated,
    /// The dirty set of the road stage: city cells whose secondary roads were grown
    /// again (new inputs), increasing. Every other city cell was reused bit for bit.
    pub dirty_cells: Vec<u64>,
    /// The dirty set of the lot stage: road-graph cells whose blocks and lots were made
    /// again, increasing. Every other road-graph cell kept its blocks and lots bit for
    /// bit (and its buildings and skins, unless an override or global edit changed
    /// their inputs).
    pub dirty_blocks: Vec<u64>,
}

/// How much work an edit redid (the rest was reused bit for bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Regenerated {
    /// City cells whose secondary roads were grown.
    pub cells: usize,
    /// Road-graph cells whose blocks and lots were made.
    pub blocks: usize,
    /// Buildings built.
    pub buildings: usize,
    /// Buildings dressed.
    pub dresses: usize,
}
