//! What travels to the page, as JSON: primary nodes and roads; city cells (ring, pattern,
//! their secondary streets); blocks grouped by the road-graph cell they came from (block
//! plates, lots, building footprints with height and kind). Coordinates are layout
//! metres rounded to centimetres and flattened (`[x0, y0, x1, y1, …]`).
//!
//! A scene sends everything; an edit's delta sends only the nodes, roads, cells and
//! block groups its change events name (see [`crate::session`]).
//!
//! Ids of city cells, block groups and buildings are 64-bit hashes, beyond the 2⁵³ a
//! JavaScript number holds exactly, so they travel as decimal strings ([`id`]); the
//! API turns them back into numbers ([`crate::api::parse_edit`]). Node and road ids are
//! small counters and stay numbers.

use std::collections::{BTreeMap, BTreeSet};

use polis::City;
use polis::geom::{Aabb2, DVec2, PolygonWithHoles};
use polis::roads::RoadClass;
use polis::roads::primary::{ControlId, ControlNode, PrimaryRoad, RoadId, RoadSpec};
use serde::Serialize;

/// A 64-bit id as the page keeps it: a decimal string.
pub fn id(v: u64) -> String {
    v.to_string()
}

/// Centimetres: the page draws at most a few pixels per metre.
pub fn round(v: f64) -> f64 {
    (v * 100.0).round() / 100.0
}

/// Points flattened and rounded.
pub fn flat<'a>(points: impl IntoIterator<Item = &'a DVec2>) -> Vec<f64> {
    points
        .into_iter()
        .flat_map(|p| [round(p.x), round(p.y)])
        .collect()
}

/// A control node.
#[derive(Debug, Serialize)]
pub struct NodeWire {
    /// Its id.
    pub id: u64,
    /// Position, metres.
    pub x: f64,
    /// Position, metres.
    pub y: f64,
    /// Its label.
    pub label: Option<String>,
}

impl NodeWire {
    /// From the primary network's node.
    pub fn new(id: ControlId, n: &ControlNode) -> NodeWire {
        NodeWire {
            id: id.0,
            x: round(n.pos.x),
            y: round(n.pos.y),
            label: n.label.clone(),
        }
    }
}

/// A primary road: its ends, width, spec (for the road inspector) and plotted path.
#[derive(Debug, Serialize)]
pub struct RoadWire {
    /// Its id.
    pub id: u64,
    /// First node.
    pub a: u64,
    /// Second node.
    pub b: u64,
    /// Carriageway width, metres.
    pub w: f64,
    /// The low-level path.
    pub pts: Vec<f64>,
    /// Class, width and adaptive parameters.
    pub spec: RoadSpec,
}

impl RoadWire {
    /// From the primary network's road.
    pub fn new(id: RoadId, r: &PrimaryRoad) -> RoadWire {
        RoadWire {
            id: id.0,
            a: r.a.0,
            b: r.b.0,
            w: round(r.spec.width_m),
            pts: flat(&r.path.points),
            spec: r.spec,
        }
    }
}

/// One street segment of a city cell.
#[derive(Debug, Serialize)]
pub struct StreetWire {
    /// Carriageway width, metres.
    pub w: f64,
    /// Its two ends.
    pub pts: Vec<f64>,
}

/// A city cell (a region of the primary network).
#[derive(Debug, Serialize)]
pub struct CellWire {
    /// Its stable id (a decimal string).
    pub id: String,
    /// Outer ring.
    pub ring: Vec<f64>,
    /// Its neighbourhood preset or grid pattern (`suburbia`, `downtown`, …).
    pub pattern: String,
    /// The secondary streets inside it.
    pub streets: Vec<StreetWire>,
    /// Why it has no secondary streets, if its growth was skipped (too small or invalid
    /// for its pattern).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped: Option<String>,
}

/// A building footprint for the plan and 3-D views.
#[derive(Debug, Serialize)]
pub struct BuildingWire {
    /// Its id (its lot's; a decimal string).
    pub id: String,
    /// Footprint ring.
    pub ring: Vec<f64>,
    /// Height, metres.
    pub h: f64,
    /// Kind, lower case (`house`, `midrise`, …).
    pub kind: String,
}

/// The blocks, lots and buildings of one road-graph cell (id = `lot id >> 24`).
#[derive(Debug, Default, Serialize)]
pub struct BlockWire {
    /// The road-graph cell's stable id (a decimal string).
    pub id: String,
    /// Block rings: outer rings and holes (filled even-odd).
    pub rings: Vec<Vec<f64>>,
    /// Lot outer rings.
    pub lots: Vec<Vec<f64>>,
    /// Buildings.
    pub buildings: Vec<BuildingWire>,
}

fn rings(p: &PolygonWithHoles) -> impl Iterator<Item = Vec<f64>> + '_ {
    std::iter::once(flat(p.outer.points())).chain(p.holes.iter().map(|h| flat(h.points())))
}

/// The block groups of `city` whose ids `want` selects (all when `None`), by id.
pub fn block_groups(city: &City, want: Option<&BTreeSet<u64>>) -> BTreeMap<u64, BlockWire> {
    let pick = |id: u64| want.is_none_or(|w| w.contains(&id));
    let mut out: BTreeMap<u64, BlockWire> = BTreeMap::new();
    fn group(out: &mut BTreeMap<u64, BlockWire>, id: u64) -> &mut BlockWire {
        out.entry(id).or_insert_with(|| BlockWire {
            id: self::id(id),
            ..BlockWire::default()
        })
    }
    for b in city.blocks.iter().filter(|b| pick(b.cell_id)) {
        group(&mut out, b.cell_id).rings.extend(rings(&b.polygon));
    }
    for l in city.lots.iter().filter(|l| pick(l.cell)) {
        group(&mut out, l.cell)
            .lots
            .push(flat(l.lot.polygon.points()));
    }
    for (b, &cell) in city.buildings.iter().zip(&city.building_cells) {
        if !pick(cell) {
            continue;
        }
        group(&mut out, cell).buildings.push(BuildingWire {
            id: id(b.id),
            ring: flat(b.footprint.points()),
            h: round(b.height),
            kind: format!("{:?}", b.kind).to_lowercase(),
        });
    }
    out
}

/// The secondary streets of `city` inside each of the `rings` (by a segment's midpoint),
/// by ring index. Where city cells nest, the smallest ring of `all` containing the
/// midpoint owns the street, so a street is sent with exactly one cell.
pub fn streets_in(city: &City, rings: &[Vec<DVec2>], all: &[Vec<DVec2>]) -> Vec<Vec<StreetWire>> {
    let boxes = |rs: &[Vec<DVec2>]| -> Vec<Option<Aabb2>> {
        rs.iter()
            .map(|r| Some(Aabb2::from_points(r.iter().copied())).filter(|b| !b.is_empty()))
            .collect()
    };
    let (own, others) = (boxes(rings), boxes(all));
    let area = |r: &[DVec2]| polis::geom::Polygon::new(r.to_vec()).area().abs();
    let all_areas: Vec<f64> = all.iter().map(|r| area(r)).collect();
    let mut out: Vec<Vec<StreetWire>> = rings.iter().map(|_| Vec::new()).collect();
    for (i, b) in own.iter().enumerate() {
        let Some(b) = b else { continue };
        let my_area = area(&rings[i]);
        for e in city.roads.edges_in_box(b) {
            let Ok(road) = city.roads.edge_payload(e) else {
                continue;
            };
            if road.class != RoadClass::Street {
                continue;
            }
            let Ok((p, q)) = city.roads.segment(e) else {
                continue;
            };
            let mid = (p + q) * 0.5;
            if !ring_contains(&rings[i], mid) {
                continue;
            }
            // A nested, smaller cell containing the midpoint owns the street.
            let inner = all.iter().enumerate().any(|(j, r)| {
                all_areas[j] < my_area
                    && others[j].is_some_and(|bj| bj.contains(mid))
                    && ring_contains(r, mid)
            });
            if !inner {
                out[i].push(StreetWire {
                    w: round(road.width),
                    pts: flat(&[p, q]),
                });
            }
        }
    }
    out
}

/// Whether `p` lies inside the ring (even-odd rule; for drawing and counting only).
pub fn ring_contains(ring: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    let n = ring.len();
    for i in 0..n {
        let a = ring[i];
        let b = ring[(i + n - 1) % n];
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
    }
    inside
}
