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
use polis_geom::predicates::distance_to_segment;
use polis_geom::{Aabb2, DVec2, PointLocation};

use crate::boxgrid::BoxGrid;
use crate::input::CityInput;
use crate::simplify::SimpleGraph;
use crate::{StatsOptions, summary::ratio};
use polis_geom::par::{self, prelude::*};

/// The plan-defect counters.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
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
    roads: BoxGrid,
    /// Lots by bounding box.
    lots: BoxGrid,
    /// Blocks by bounding box.
    blocks: BoxGrid,
    /// Widest road's half width.
    max_half_width: f64,
}

/// Cell size of the lookup grids, metres (a few lots across).
const GRID_CELL_M: f64 = 32.0;

fn build_indexes(city: &CityInput<'_>) -> Indexes {
    let g = city.streets;
    let roads = g
        .edges
        .iter()
        .map(|e| {
            let (a, b) = (g.nodes[e.a], g.nodes[e.b]);
            if a == b {
                Aabb2::EMPTY
            } else {
                Aabb2::new(a, b)
            }
        })
        .collect();
    let max_half_width = g.edges.iter().map(|e| e.width_m * 0.5).fold(0.0, f64::max);
    let lots = city.lots.iter().map(|l| l.polygon.bbox()).collect();
    let blocks = city.blocks.iter().map(|b| b.outer.bbox()).collect();
    let (lots, (roads, blocks)) = par::join(
        || BoxGrid::new(lots, GRID_CELL_M),
        || {
            (
                BoxGrid::new(roads, GRID_CELL_M),
                BoxGrid::new(blocks, GRID_CELL_M),
            )
        },
    );
    Indexes {
        roads,
        lots,
        blocks,
        max_half_width,
    }
}

/// Whether some lot lies within `reach` of `p`.
fn lot_near(city: &CityInput<'_>, ix: &Indexes, p: DVec2, reach: f64) -> bool {
    let mut found = false;
    ix.lots.for_each(&Aabb2::new(p, p).expanded(reach), |i| {
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
    ix.blocks.for_each(&Aabb2::new(p, p), |i| {
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
    // A bounding circle of the footprint: roads farther than its radius plus their
    // half width from its centre cannot reach the footprint.
    let centre = (bb.min + bb.max) * 0.5;
    let radius = fp
        .points()
        .iter()
        .map(|p| p.distance(centre))
        .fold(0.0, f64::max);
    let mut hit = false;
    ix.roads.for_each(&bb.expanded(ix.max_half_width), |i| {
        if hit {
            return;
        }
        let e = city.streets.edges[i];
        let limit = e.width_m * 0.5 - opt.corridor_tolerance_m;
        if limit <= 0.0 {
            return;
        }
        let (a, b) = (city.streets.nodes[e.a], city.streets.nodes[e.b]);
        if !Aabb2::new(a, b).expanded(limit).intersects(&bb)
            || distance_to_segment(centre, a, b) >= radius + limit
        {
            return;
        }
        hit = polygon_segment_distance(fp, a, b) < limit;
    });
    hit
}

/// Counts the plan defects of a (validated) city whose simplified street graph is `s`.
/// Segments and buildings are examined in parallel (rayon); the counts and sums are
/// gathered in input order, so any thread count gives the same numbers.
pub fn plan_defects(city: &CityInput<'_>, s: &SimpleGraph, opt: &StatsOptions) -> PlanDefects {
    let ix = build_indexes(city);
    let g = city.streets;
    let mut d = PlanDefects::default();
    let inside: Vec<Option<(f64, f64)>> = (0..g.edges.len())
        .into_par_iter()
        .map(|i| {
            let e = g.edges[i];
            let (a, b) = (g.nodes[e.a], g.nodes[e.b]);
            (a != b && inside_a_block(city, &ix, a.lerp(b, 0.5)))
                .then(|| served_length(city, &ix, opt, i))
        })
        .collect();
    for (served, len) in inside.into_iter().flatten() {
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
        .into_par_iter()
        .filter(|&i| in_corridor(city, &ix, opt, i))
        .count();
    d.buildings_in_road_corridor_share = ratio(
        d.buildings_in_road_corridor as f64,
        city.buildings.len() as f64,
    );
    d
}
