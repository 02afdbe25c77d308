//! What the report measures, as plain data a user can build by hand: a
//! [`StreetGraph`], block polygons, [`LotInput`]s and [`BuildingInput`]s, gathered in a
//! [`CityInput`].

use polis_geom::{Aabb2, DVec2, Field, PlanarGraph, Polygon, PolygonWithHoles};

use crate::error::StatsError;

/// The class of a street edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum StreetClass {
    /// A highway or arterial.
    Highway,
    /// A local street.
    Street,
}

/// One straight street segment between two nodes of a [`StreetGraph`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StreetEdge {
    /// First node (index into [`StreetGraph::nodes`]).
    pub a: usize,
    /// Second node.
    pub b: usize,
    /// Carriageway width, metres (the road corridor is the centreline ± width / 2).
    pub width_m: f64,
    /// Highway or street.
    pub class: StreetClass,
    /// Whether the segment is a bridge (it crosses water). Default: `false`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub bridge: bool,
}

/// A street network: straight segments between nodes. Curved streets are chains of
/// segments through degree-2 nodes; the report merges them ([`crate::simplify`]).
///
/// Parallel edges, zero-length edges and isolated nodes are allowed: zero-length edges
/// are contracted and isolated nodes counted, never measured.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StreetGraph {
    /// Node positions, metres (layout: x east, y north).
    pub nodes: Vec<DVec2>,
    /// Ground elevation at each node, metres; `None` when unknown (no grade metrics).
    pub elevations: Option<Vec<f64>>,
    /// The segments.
    pub edges: Vec<StreetEdge>,
}

impl StreetGraph {
    /// The live nodes and edges of a planar graph; `edge` gives each edge's class and
    /// width from its payload. Nodes are numbered in the graph's id order.
    pub fn from_planar<N, E>(
        graph: &PlanarGraph<N, E>,
        mut edge: impl FnMut(&E) -> (StreetClass, f64),
    ) -> StreetGraph {
        let mut index = vec![usize::MAX; graph.node_bound()];
        let mut nodes = Vec::with_capacity(graph.node_count());
        for (id, p, _) in graph.nodes() {
            index[id.index()] = nodes.len();
            nodes.push(p);
        }
        let edges = graph
            .edges()
            .map(|(_, a, b, e)| {
                let (class, width_m) = edge(e);
                StreetEdge {
                    a: index[a.index()],
                    b: index[b.index()],
                    width_m,
                    class,
                    bridge: false,
                }
            })
            .collect();
        StreetGraph {
            nodes,
            elevations: None,
            edges,
        }
    }

    /// Samples `elevation` (metres) at every node.
    pub fn with_elevation(mut self, elevation: &dyn Field) -> StreetGraph {
        self.elevations = Some(self.nodes.iter().map(|p| elevation.sample(*p)).collect());
        self
    }

    /// Checks node indices, coordinates, widths and elevations.
    ///
    /// # Errors
    /// [`StatsError::NodeOutOfRange`], [`StatsError::BadValue`] or
    /// [`StatsError::ElevationCount`].
    pub fn validate(&self) -> Result<(), StatsError> {
        for (i, p) in self.nodes.iter().enumerate() {
            finite_point(*p, || format!("street node {i}"))?;
        }
        for (i, e) in self.edges.iter().enumerate() {
            for node in [e.a, e.b] {
                if node >= self.nodes.len() {
                    return Err(StatsError::NodeOutOfRange {
                        edge: i,
                        node,
                        nodes: self.nodes.len(),
                    });
                }
            }
            non_negative(e.width_m, || format!("street edge {i} width"))?;
        }
        if let Some(z) = &self.elevations {
            if z.len() != self.nodes.len() {
                return Err(StatsError::ElevationCount {
                    elevations: z.len(),
                    nodes: self.nodes.len(),
                });
            }
            for (i, v) in z.iter().enumerate() {
                if !v.is_finite() {
                    return Err(StatsError::BadValue {
                        what: format!("elevation of street node {i}"),
                        value: *v,
                    });
                }
            }
        }
        Ok(())
    }
}

/// A lot: its polygon and which of its edges face a street.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LotInput<'a> {
    /// The lot (counter-clockwise).
    pub polygon: &'a Polygon,
    /// Indices of the polygon edges that face a street (edge `i` runs from vertex `i` to
    /// vertex `i + 1`).
    pub street_edges: &'a [usize],
}

/// A building: footprint, height, storeys and a kind label (`"House"`, `"Office"` …).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuildingInput<'a> {
    /// The footprint (counter-clockwise).
    pub footprint: &'a Polygon,
    /// Height above the ground, metres.
    pub height_m: f64,
    /// Storeys (for the floor-area ratio).
    pub floors: u32,
    /// The kind, as a label; the kind mix counts labels.
    pub kind: &'a str,
}

/// Everything the report reads.
#[derive(Clone, Copy)]
pub struct CityInput<'a> {
    /// The street network.
    pub streets: &'a StreetGraph,
    /// Blocks (land between streets).
    pub blocks: &'a [&'a PolygonWithHoles],
    /// Lots.
    pub lots: &'a [LotInput<'a>],
    /// Buildings.
    pub buildings: &'a [BuildingInput<'a>],
    /// The map square; dead ends within [`StatsOptions::edge_margin_m`](crate::StatsOptions::edge_margin_m)
    /// of its border are "at the map edge". `None`: no dead end is at the edge.
    pub bounds: Option<Aabb2>,
    /// Land area, m², for the intersection density. `None`: the area of `bounds`, or of
    /// the street nodes' bounding box without bounds.
    pub land_area_m2: Option<f64>,
    /// Water map (water where ≥ 0.5): dead ends in water are not stubs in land.
    pub water: Option<&'a dyn Field>,
}

impl std::fmt::Debug for CityInput<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CityInput")
            .field("nodes", &self.streets.nodes.len())
            .field("edges", &self.streets.edges.len())
            .field("blocks", &self.blocks.len())
            .field("lots", &self.lots.len())
            .field("buildings", &self.buildings.len())
            .field("bounds", &self.bounds)
            .field("land_area_m2", &self.land_area_m2)
            .field("water", &self.water.is_some())
            .finish()
    }
}

impl<'a> CityInput<'a> {
    /// A city of streets only: no blocks, lots or buildings, no bounds, no water.
    pub fn streets_only(streets: &'a StreetGraph) -> CityInput<'a> {
        CityInput {
            streets,
            blocks: &[],
            lots: &[],
            buildings: &[],
            bounds: None,
            land_area_m2: None,
            water: None,
        }
    }

    /// Checks every value the report reads.
    ///
    /// # Errors
    /// The first bad value, named.
    pub fn validate(&self) -> Result<(), StatsError> {
        self.streets.validate()?;
        for (i, b) in self.blocks.iter().enumerate() {
            for (_, ring) in b.rings() {
                for p in ring.points() {
                    finite_point(*p, || format!("block {i} vertex"))?;
                }
            }
        }
        for (i, l) in self.lots.iter().enumerate() {
            for p in l.polygon.points() {
                finite_point(*p, || format!("lot {i} vertex"))?;
            }
            for &e in l.street_edges {
                if e >= l.polygon.len() {
                    return Err(StatsError::LotEdgeOutOfRange {
                        lot: i,
                        edge: e,
                        edges: l.polygon.len(),
                    });
                }
            }
        }
        for (i, b) in self.buildings.iter().enumerate() {
            for p in b.footprint.points() {
                finite_point(*p, || format!("building {i} vertex"))?;
            }
            non_negative(b.height_m, || format!("building {i} height"))?;
        }
        if let Some(a) = self.land_area_m2 {
            non_negative(a, || "land area".into())?;
        }
        if let Some(b) = self.bounds {
            finite_point(b.min, || "bounds".into())?;
            finite_point(b.max, || "bounds".into())?;
        }
        Ok(())
    }
}

/// Finite and within [`polis_geom::MAX_COORDINATE`] of the origin (the workspace's
/// coordinate contract).
fn finite_point(p: DVec2, what: impl FnOnce() -> String) -> Result<(), StatsError> {
    let limit = polis_geom::MAX_COORDINATE;
    if p.is_finite() && p.x.abs() <= limit && p.y.abs() <= limit {
        return Ok(());
    }
    Err(StatsError::BadValue {
        what: what(),
        value: if p.x.is_finite() && p.x.abs() <= limit {
            p.y
        } else {
            p.x
        },
    })
}

fn non_negative(v: f64, what: impl FnOnce() -> String) -> Result<(), StatsError> {
    if v.is_finite() && v >= 0.0 {
        return Ok(());
    }
    Err(StatsError::BadValue {
        what: what(),
        value: v,
    })
}
