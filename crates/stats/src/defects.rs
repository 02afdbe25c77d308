//! Plan defects an urban designer sees at once, counted: roads inside blocks with no
//! lots along them, street stubs ending in land with no lots along them, and buildings
//! standing in a road corridor.
//!
//! # Definitions
//! * A point of a road **has a lot along it** when some lot comes within
//!   `width / 2 + `[`lot_reach_m`](crate::StatsOptions::lot_reach_m) of it (or covers it).
//!   Roads are sampled every [`sample_step_m`](crate::StatsOptions::sample_step_m) (at
//!   least once per segment, at the middle of equal pieces).
//! * A road segment is **inside a block** when its midpoint lies strictly inside a block
//!   polygon: a filament (dead end, connector) that the blocks were not cut along.
//! * A **stub** is a dead end of the simplified graph with its street. It is **at the
//!   map edge** within [`edge_margin_m`](crate::StatsOptions::edge_margin_m) of the
//!   bounds (or outside them), **in water** where the water map is ≥ 0.5, and **in land**
//!   otherwise; a stub in land with no lot along any of its samples is a defect.
//! * A building is **in a road corridor** when its footprint comes closer than
//!   `width / 2 − `[`corridor_tolerance_m`](crate::StatsOptions::corridor_tolerance_m)
//!   to a road's centreline.

use polis_geom::measure::polygon_segment_distance;
use polis_geom::spatial::{RTreeIndex, Shape, SpatialIndex};
use polis_geom::{Aabb2, DVec2, PointLocation, SegmentIndex};
use serde::{Deserialize, Serialize};

use crate::error::StatsError;
use crate::input::CityInput;
use crate::simplify::SimpleGraph;
use crate::{StatsOptions, summary::ratio};

/// The plan-defect counters.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PlanDefects {
    /// Road segments inside a block.
    pub segments_inside_blocks: usize,
    /// Their length, metres.
    pub length_inside_blocks_m: f64,
    /// Segments inside a block with no lot along any sample.
    pub segments_inside_blocks_without_lots: usize,
    /// Length inside blocks with no lot along it (sampled), metres.
    pub length_inside_blocks_without_lots_m: f64,
    /// Dead ends of the simplified graph.
    pub stubs: usize,
    /// Dead ends at the map edge.
    pub stubs_at_map_edge: usize,
    /// Dead ends in water.
    pub stubs_in_water: usize,
    /// Dead ends in land.
    pub stubs_in_land: usize,
    /// Dead ends in land whose street has no lot along it.
    pub stubs_in_land_without_lots: usize,
    /// Buildings whose footprint enters a road corridor.
    pub buildings_in_road_corridor: usize,
    /// Share of buildings in a road corridor.
    pub buildings_in_road_corridor_share: f64,
}

/// Spatial lookups shared by the counters.
struct Indexes {
    /// Input street segments of positive length, by edge index.
    roads: SegmentIndex<usize>,
    /// Lots by bounding box.
    lots: RTreeIndex<usize>,
    /// Blocks by bounding box.
    blocks: RTreeIndex<usize>,
    /// Widest road's half width.
    max_half_width: f64,
}

fn index_err(what: String) -> impl FnOnce(polis_geom::GeomError) -> StatsError {
    move |_| StatsError::BadValue {
        what: format!("{what} (beyond ±{:e} m)", polis_geom::MAX_COORDINATE),
        value: f64::INFINITY,
    }
}

fn build_indexes(city: &CityInput<'_>) -> Result<Indexes, StatsError> {
    let g = city.streets;
    let mut roads = SegmentIndex::default();
    let mut max_half_width: f64 = 0.0;
    for (i, e) in g.edges.iter().enumerate() {
        let (a, b) = (g.nodes[e.a], g.nodes[e.b]);
        if a != b {
            roads
                .insert_segment(i, a, b)
                .map_err(index_err(format!("street edge {i}")))?;
            max_half_width = max_half_width.max(e.width_m * 0.5);
        }
    }
    // Lots and blocks are found by bounding box: stored as their box's diagonal in an
    // R-tree, whose candidates are exactly the entries whose box meets the query box.
    let boxes = |items: Vec<(usize, Aabb2)>, what: &str| {
        RTreeIndex::bulk_load(
            items
                .into_iter()
                .map(|(i, b)| (i, Shape::Segment(b.min, b.max))),
        )
        .map_err(index_err(format!("a {what}")))
    };
    let lots = boxes(
        city.lots
            .iter()
            .enumerate()
            .filter(|(_, l)| !l.polygon.is_empty())
            .map(|(i, l)| (i, l.polygon.bbox()))
            .collect(),
        "lot",
    )?;
    let blocks = boxes(
        city.blocks
            .iter()
            .enumerate()
            .filter(|(_, b)| !b.outer.is_empty())
            .map(|(i, b)| (i, b.bbox()))
            .collect(),
        "block",
    )?;
    Ok(Indexes {
        roads,
        lots,
        blocks,
        max_half_width,
    })
}

/// Whether some lot lies within `reach` of `p`.
fn lot_near(city: &CityInput<'_>, ix: &Indexes, p: DVec2, reach: f64) -> bool {
    let mut found = false;
    ix.lots
        .for_each_candidate(&Aabb2::new(p, p).expanded(reach), |i, _| {
            if !found && polygon_segment_distance(city.lots[i].polygon, p, p) <= reach {
                found = true;
            }
        });
    found
}

/// Sample points of the segment `a–b`: the middles of `⌈len / step⌉` equal pieces
/// (at least one), with the length each stands for.
fn samples(a: DVec2, b: DVec2, step: f64) -> impl Iterator<Item = (DVec2, f64)> {
    let len = a.distance(b);
    let k = if step > 0.0 {
        (len / step).ceil().clamp(1.0, 1.0e6) as usize
    } else {
        1
    };
    (0..k).map(move |i| (a.lerp(b, (i as f64 + 0.5) / k as f64), len / k as f64))
}

/// Length of segment `edge` with a lot along it, and its whole length.
fn served_length(
    city: &CityInput<'_>,
    ix: &Indexes,
    opt: &StatsOptions,
    edge: usize,
) -> (f64, f64) {
    let e = city.streets.edges[edge];
    let (a, b) = (city.streets.nodes[e.a], city.streets.nodes[e.b]);
    let reach = e.width_m * 0.5 + opt.lot_reach_m;
    let mut served = 0.0;
    for (p, w) in samples(a, b, opt.sample_step_m) {
        if lot_near(city, ix, p, reach) {
            served += w;
        }
    }
    (served, a.distance(b))
}

fn inside_a_block(city: &CityInput<'_>, ix: &Indexes, p: DVec2) -> bool {
    let mut inside = false;
    ix.blocks.for_each_candidate(&Aabb2::new(p, p), |i, _| {
        if !inside && city.blocks[i].locate(p) == PointLocation::Inside {
            inside = true;
        }
    });
    inside
}

/// Where a dead end lies.
enum DeadEnd {
    MapEdge,
    Water,
    Land,
}

fn classify(city: &CityInput<'_>, opt: &StatsOptions, p: DVec2) -> DeadEnd {
    if let Some(b) = city.bounds {
        let inner = (p.x - b.min.x)
            .min(b.max.x - p.x)
            .min(p.y - b.min.y)
            .min(b.max.y - p.y);
        if inner <= opt.edge_margin_m {
            return DeadEnd::MapEdge;
        }
    }
    if city.water.is_some_and(|w| w.sample(p) >= 0.5) {
        return DeadEnd::Water;
    }
    DeadEnd::Land
}

fn in_corridor(city: &CityInput<'_>, ix: &Indexes, opt: &StatsOptions, building: usize) -> bool {
    let fp = city.buildings[building].footprint;
    if fp.is_empty() {
        return false;
    }
    let bb = fp.bbox();
    let mut hit = false;
    ix.roads
        .for_each_candidate(&bb.expanded(ix.max_half_width), |i, _| {
            if hit {
                return;
            }
            let e = city.streets.edges[i];
            let limit = e.width_m * 0.5 - opt.corridor_tolerance_m;
            if limit <= 0.0 {
                return;
            }
            let (a, b) = (city.streets.nodes[e.a], city.streets.nodes[e.b]);
            if !Aabb2::new(a, b).expanded(limit).intersects(&bb) {
                return;
            }
            hit = polygon_segment_distance(fp, a, b) < limit;
        });
    hit
}

/// Counts the plan defects of a (validated) city whose simplified street graph is `s`.
///
/// # Errors
/// [`StatsError::BadValue`] for coordinates beyond `MAX_COORDINATE`.
pub fn plan_defects(
    city: &CityInput<'_>,
    s: &SimpleGraph,
    opt: &StatsOptions,
) -> Result<PlanDefects, StatsError> {
    let ix = build_indexes(city)?;
    let g = city.streets;
    let mut d = PlanDefects::default();
    for (i, e) in g.edges.iter().enumerate() {
        let (a, b) = (g.nodes[e.a], g.nodes[e.b]);
        if a == b || !inside_a_block(city, &ix, a.lerp(b, 0.5)) {
            continue;
        }
        let (served, len) = served_length(city, &ix, opt, i);
        d.segments_inside_blocks += 1;
        d.length_inside_blocks_m += len;
        d.length_inside_blocks_without_lots_m += (len - served).max(0.0);
        if served == 0.0 {
            d.segments_inside_blocks_without_lots += 1;
        }
    }
    for street in &s.edges {
        for (end, is_a) in [(street.a, true), (street.b, false)] {
            if s.degree[end] != 1 || (!is_a && street.a == street.b) {
                continue;
            }
            d.stubs += 1;
            match classify(city, opt, g.nodes[end]) {
                DeadEnd::MapEdge => d.stubs_at_map_edge += 1,
                DeadEnd::Water => d.stubs_in_water += 1,
                DeadEnd::Land => {
                    d.stubs_in_land += 1;
                    let served = street
                        .edges
                        .iter()
                        .any(|&k| served_length(city, &ix, opt, k).0 > 0.0);
                    if !served {
                        d.stubs_in_land_without_lots += 1;
                    }
                }
            }
        }
    }
    d.buildings_in_road_corridor = (0..city.buildings.len())
        .filter(|&i| in_corridor(city, &ix, opt, i))
        .count();
    d.buildings_in_road_corridor_share = ratio(
        d.buildings_in_road_corridor as f64,
        city.buildings.len() as f64,
    );
    Ok(d)
}
