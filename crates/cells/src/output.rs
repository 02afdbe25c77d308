//! The result of cell extraction: [`CellDecomposition`], [`Cell`], [`Ring`], [`Filament`]
//! and the [`ExtractionReport`].

use polis_geom::{DVec2, EdgeId, NodeId, Polygon, PolygonWithHoles};

/// The index of a [`Cell`] in [`CellDecomposition::cells`] (and of its minimal cycle).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct CellId(pub u32);

impl CellId {
    /// The index as `usize`.
    #[inline]
    pub const fn index(self) -> usize {
        self.0 as usize
    }
}

impl std::fmt::Display for CellId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// A closed ring of graph edges: a minimal cycle (counter-clockwise) or a hole outline
/// (clockwise).
///
/// `edges[i]` joins `nodes[i]` and `nodes[(i + 1) % len]`; `polygon` holds the nodes'
/// positions in the same order (no repeated closing vertex). The ids name the input
/// graph's nodes and edges, so their payloads (road class, width …) stay reachable.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Ring {
    /// The nodes in ring order.
    pub nodes: Vec<NodeId>,
    /// The edges in ring order.
    pub edges: Vec<EdgeId>,
    /// The positions of `nodes`, metres.
    pub polygon: Polygon,
}

impl Ring {
    /// Number of nodes (and edges).
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the ring is empty (never the case for extracted rings).
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Unsigned enclosed area, m².
    pub fn area(&self) -> f64 {
        self.polygon.area()
    }
}

/// How a filament is attached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum FilamentKind {
    /// Starts at a branch point (degree ≥ 3) and ends at a dead end (degree 1): a cul-de-sac.
    DeadEnd,
    /// Both ends are branch points: a connector (bridge) between parts of the network.
    Connector,
    /// Both ends are dead ends: a free-floating road.
    Free,
}

/// A filament: a chain of edges on no cycle, whose inner nodes have degree 2 and whose end
/// nodes are dead ends (degree 1) or branch points (degree ≥ 3).
///
/// `edges[i]` joins `nodes[i]` and `nodes[i + 1]`; `points` are the nodes' positions.
/// Dead-end filaments run from the branch point to the dead end.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Filament {
    /// The nodes along the chain.
    pub nodes: Vec<NodeId>,
    /// The edges along the chain (one fewer than `nodes`).
    pub edges: Vec<EdgeId>,
    /// Positions of `nodes`, metres.
    pub points: Vec<DVec2>,
    /// How the chain is attached.
    pub kind: FilamentKind,
    /// The innermost cell containing it, `None` outside every cycle.
    pub cell: Option<CellId>,
}

/// A node without edges.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct IsolatedNode {
    /// The node.
    pub node: NodeId,
    /// Its position, metres.
    pub point: DVec2,
    /// The innermost cell containing it, `None` outside every cycle.
    pub cell: Option<CellId>,
}

/// A city cell: one bounded face of the road graph.
///
/// Self-contained (owns all its geometry and ids; `Clone + Send + Sync`), so cells can be
/// handed to parallel workers together with a shared `&PlanarGraph` for the payloads.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Cell {
    /// This cell's id (its index in [`CellDecomposition::cells`]).
    pub id: CellId,
    /// The minimal cycle bounding the cell, counter-clockwise, starting at its leftmost
    /// node (lowest on ties).
    pub boundary: Ring,
    /// The innermost cell whose boundary strictly contains this one (`None` at top level).
    pub parent: Option<CellId>,
    /// Cells whose boundaries lie directly inside this one (islands), in id order.
    pub children: Vec<CellId>,
    /// Nesting depth: 0 for top-level cells.
    pub depth: u32,
    /// Outlines of the islands (the union of the children's regions), clockwise. A hole
    /// may touch the boundary or another hole at a single node (a cut vertex).
    pub holes: Vec<Ring>,
    /// Filaments inside the cell and not inside any child: dead ends, connectors to the
    /// islands, free-floating roads.
    pub filaments: Vec<Filament>,
    /// Nodes without edges inside the cell and not inside any child.
    pub isolated_nodes: Vec<IsolatedNode>,
}

impl Cell {
    /// Area of the boundary polygon, m² (islands included).
    pub fn boundary_area(&self) -> f64 {
        self.boundary.area()
    }

    /// Area of the cell itself: the boundary's minus the holes', m².
    pub fn area(&self) -> f64 {
        self.boundary.area() - self.holes.iter().map(Ring::area).sum::<f64>()
    }

    /// The cell's region as a polygon with holes (outer ring counter-clockwise, holes
    /// clockwise), exactly as extracted. Holes touching the boundary or each other at a
    /// node make it fail [`PolygonWithHoles::validate`] although the region is well
    /// defined: use [`Cell::polygon_with_holes`] for a polygon that always validates.
    pub fn region(&self) -> PolygonWithHoles {
        PolygonWithHoles::new(
            self.boundary.polygon.clone(),
            self.holes.iter().map(|h| h.polygon.clone()).collect(),
        )
    }
}

/// Why an edge of the input was left out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum DropReason {
    /// After merging coincident nodes it joins the same pair of nodes as `kept`.
    Duplicate {
        /// The edge that represents the pair (smallest id).
        kept: EdgeId,
    },
    /// After merging coincident nodes both its ends are one node.
    ZeroLength,
    /// During planarisation ([`extract_planarized`](crate::extract_planarized)) its ends
    /// snapped together.
    Collapsed,
}

/// An edge left out of the extraction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DroppedEdge {
    /// The edge.
    pub edge: EdgeId,
    /// Why.
    pub reason: DropReason,
}

/// A node merged into another at the same position.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct NodeMerge {
    /// The merged node: it appears in no output.
    pub node: NodeId,
    /// The node that represents it (smallest id at that position).
    pub into: NodeId,
    /// The shared position.
    pub point: DVec2,
}

/// What the extraction repaired or counted.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ExtractionReport {
    /// Coincident nodes merged (see [`CoincidentNodes`](crate::CoincidentNodes)).
    pub merged_nodes: Vec<NodeMerge>,
    /// Edges left out (duplicates or zero length after merging).
    pub dropped_edges: Vec<DroppedEdge>,
    /// Connected components of the graph (isolated nodes count as components).
    pub components: usize,
    /// Minimal cycles found (= cells).
    pub cycles: usize,
    /// Edges on at least one cycle.
    pub cycle_edges: usize,
    /// Edges on no cycle (all in filaments).
    pub filament_edges: usize,
}

/// The cells of a planar road graph: Eberly's minimal cycle basis grouped by containment.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CellDecomposition {
    /// One cell per minimal cycle (bounded face), in extraction order: left to right by
    /// the leftmost node of each cycle. A parent always precedes its children.
    pub cells: Vec<Cell>,
    /// Cells at the top of the containment forest, in id order.
    pub roots: Vec<CellId>,
    /// Filaments outside every cycle.
    pub outer_filaments: Vec<Filament>,
    /// Isolated nodes outside every cycle.
    pub outer_isolated_nodes: Vec<IsolatedNode>,
    /// Outer outlines (clockwise) of the network's pieces that lie outside every cycle:
    /// the boundary of the union of the top-level cells.
    pub outlines: Vec<Ring>,
    /// What was repaired and counted.
    pub report: ExtractionReport,
}

impl CellDecomposition {
    /// The cell with id `id`, if any.
    pub fn cell(&self, id: CellId) -> Option<&Cell> {
        self.cells.get(id.index())
    }

    /// The minimal cycles (cell boundaries), counter-clockwise, in cell order.
    pub fn cycles(&self) -> impl ExactSizeIterator<Item = &Ring> + '_ {
        self.cells.iter().map(|c| &c.boundary)
    }

    /// Every filament: first those inside cells (in cell order), then the outer ones.
    pub fn filaments(&self) -> impl Iterator<Item = &Filament> + '_ {
        self.cells
            .iter()
            .flat_map(|c| c.filaments.iter())
            .chain(self.outer_filaments.iter())
    }

    /// Every isolated node, inside cells or outside.
    pub fn isolated_nodes(&self) -> impl Iterator<Item = &IsolatedNode> + '_ {
        self.cells
            .iter()
            .flat_map(|c| c.isolated_nodes.iter())
            .chain(self.outer_isolated_nodes.iter())
    }

    /// Total area of the cells (bounded faces, islands not counted twice), m².
    pub fn total_area(&self) -> f64 {
        self.cells.iter().map(Cell::area).sum()
    }
}
