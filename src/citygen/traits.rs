//! How the Citygen mode's per-cell traits and per-lot overrides reach the later stages:
//! stable ids of the road graph's cells, a cell's lot options (Kelly's *Lot Size* and
//! *Lot Deviance*), and each lot's kind, height limit, seed and style (*Building Height*,
//! *Building Deviance*, *Building Hint*; pins).

use std::collections::BTreeSet;

use polis_buildings::BuildingKind;
use polis_cells::{Cell, CellDecomposition};
use polis_geom::hash::splitmix64;
use polis_geom::{Aabb2, DVec2, Field};
use polis_roads::secondary::BuildingHint;
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

use super::{District, RoadMode, lot_override, stable_cell_id};
use crate::CityConfig;
use crate::city::CityLot;
use crate::stages::{Stage, StageContext};

/// Bits of a road-graph cell id in the Citygen mode (a lot id is `cell << 24 | index`).
const CELL_ID_BITS: u32 = 40;

/// The id of each road-graph cell (the cells blocks and lots are made from), in cell
/// order. Parish & Müller mode: the cell's index. Citygen mode: a 40-bit hash of the
/// cell's boundary positions ([`stable_cell_id`]), so a cell that an edit elsewhere does
/// not touch keeps its id, its seeds and the ids of its lots and buildings; a repeated
/// hash (about one city in 10⁴ of 17,000 cells) is rehashed in cell order.
pub fn block_ids(config: &CityConfig, cells: &CellDecomposition) -> Vec<u64> {
    if config.road_mode != RoadMode::Citygen {
        return cells.cells.iter().map(|c| c.id.index() as u64).collect();
    }
    let mask = (1u64 << CELL_ID_BITS) - 1;
    let mut seen = BTreeSet::new();
    cells
        .cells
        .iter()
        .map(|c| {
            let mut id = stable_cell_id(c) & mask;
            while !seen.insert(id) {
                id = splitmix64(id) & mask;
            }
            id
        })
        .collect()
}

/// The district (city cell) containing `p`, if any.
pub fn district_at(districts: &[District], p: DVec2) -> Option<&District> {
    districts
        .iter()
        .find(|d| d.region.outer.bbox().contains(p) && d.region.contains(p))
}

/// The bounding box of each district's outer ring, in order: for
/// [`district_in_boxes`], when many points are looked up in the same districts.
pub(crate) fn district_boxes(districts: &[District]) -> Vec<Aabb2> {
    districts.iter().map(|d| d.region.outer.bbox()).collect()
}

/// [`district_at`] with the districts' boxes made once ([`district_boxes`]): the same
/// district (the first in order whose box and region hold `p`). Without a box for every
/// district (`boxes` not made from `districts`), [`district_at`].
pub(crate) fn district_in_boxes<'d>(
    districts: &'d [District],
    boxes: &[Aabb2],
    p: DVec2,
) -> Option<&'d District> {
    if boxes.len() != districts.len() {
        return district_at(districts, p);
    }
    districts
        .iter()
        .zip(boxes)
        .find(|(d, b)| b.contains(p) && d.region.contains(p))
        .map(|(d, _)| d)
}

/// A point inside the road-graph cell: its ring's centroid if inside, else the centroid
/// of the first ear (a vertex and its neighbours) that is.
fn inside_point(cell: &Cell) -> Option<DVec2> {
    let ring = &cell.boundary.polygon;
    let c = ring.centroid();
    if ring.contains(c) {
        return Some(c);
    }
    let pts = ring.points();
    let n = pts.len();
    (0..n)
        .map(|i| (pts[(i + n - 1) % n] + pts[i] + pts[(i + 1) % n]) / 3.0)
        .find(|&q| ring.contains(q))
}

/// The lot options of a road-graph cell whose city cell's traits apply: the
/// configuration's `lots` with the cell's lot size as width and its deviance (clamped to
/// [0, 1]); the depth keeps the configuration's depth-to-width ratio.
pub fn lot_params_of(
    config: &CityConfig,
    districts: &[District],
    cell: &Cell,
) -> Option<polis_lots::LotParams> {
    if districts.is_empty() {
        return None;
    }
    let d = district_at(districts, inside_point(cell)?)?;
    if !d.traits_apply {
        return None;
    }
    let mut p = config.lots;
    let size = d.traits.lot_size_m;
    if !(size.value.is_finite() && size.value > 0.0) {
        return None;
    }
    let ratio = p.lot_depth / p.lot_width;
    p.lot_width = size.value;
    p.lot_depth = size.value * ratio;
    p.deviance = size.deviance.clamp(0.0, 1.0);
    Some(p)
}

/// The building kind of Kelly's building hint.
pub fn hint_kind(hint: BuildingHint) -> BuildingKind {
    match hint {
        BuildingHint::Skyscraper => BuildingKind::Skyscraper,
        BuildingHint::Office => BuildingKind::Office,
        BuildingHint::MidRise => BuildingKind::MidRise,
        BuildingHint::Apartment => BuildingKind::Apartment,
        BuildingHint::House => BuildingKind::House,
        BuildingHint::Industrial => BuildingKind::Industrial,
    }
}

/// What to build on one lot.
#[derive(Debug, Clone, PartialEq)]
pub struct LotPlan {
    /// The kind.
    pub kind: BuildingKind,
    /// The height limit, metres (> 0).
    pub max_height_m: f64,
    /// The id the building grammar is seeded with (the lot's, or a reseeded one).
    pub build_id: u64,
    /// A pinned facade style.
    pub style: Option<String>,
}

/// The plan of lot `l`, or `None` for a lot left empty. In order, each replacing what
/// came before: the zoning bands by population; the cell's hint and a draw of its
/// building height (when its traits apply); a zoning map or painted zoning; a maximum
/// height map (0 or less leaves the lot empty); the lot's override (removed, kind,
/// height, seed, style), found by id or anchor among `lot_ids`.
pub fn lot_plan(
    cx: &StageContext<'_>,
    districts: &[District],
    l: &CityLot,
    lot_ids: &BTreeSet<u64>,
) -> Option<LotPlan> {
    lot_plan_in(cx, districts, &[], l, lot_ids)
}

/// [`lot_plan`] with the districts' boxes made once ([`district_boxes`]; none: made as
/// needed), for the lots of a whole city. The same plan.
pub(crate) fn lot_plan_in(
    cx: &StageContext<'_>,
    districts: &[District],
    boxes: &[Aabb2],
    l: &CityLot,
    lot_ids: &BTreeSet<u64>,
) -> Option<LotPlan> {
    let config = cx.config;
    let maps = cx.maps;
    let c = l.lot.polygon.centroid();
    let (mut kind, mut max_height_m) = config.zoning.zone(maps.inputs.population.sample(c));
    if let Some(d) = district_in_boxes(districts, boxes, c).filter(|d| d.traits_apply) {
        kind = hint_kind(d.traits.building_hint);
        let mut rng = Pcg64Mcg::seed_from_u64(cx.seed(Stage::Buildings, l.id) ^ 0x4845_4947);
        let h = d.traits.building_height_m.sample(&mut rng);
        max_height_m = h.clamp(1.0, crate::MAX_BUILDING_HEIGHT_M);
    }
    if let Some(z) = &maps.zoning
        && z.sample(c).is_finite()
    {
        let seed = cx.seed(Stage::Buildings, l.id);
        kind = crate::zoning::zone_map_kind(z.as_ref(), c, &config.zoning.mixed, seed);
    }
    if let Some(h) = &maps.max_height {
        // The map replaces the limit; 0 m (or less, or NaN) leaves the lot empty.
        max_height_m = h.sample(c);
    }
    // Small lots build lower (P&M §4.1).
    max_height_m = crate::zoning::area_capped(&config.zoning.area_caps, l.lot.area, max_height_m);
    let mut plan = LotPlan {
        kind,
        max_height_m,
        build_id: l.id,
        style: None,
    };
    if let Some(o) = lot_override(&config.citygen.lots, l.id, &l.lot.polygon, lot_ids) {
        if o.removed {
            return None;
        }
        if let Some(k) = o.kind {
            plan.kind = k;
        }
        if let Some(h) = o.height_m {
            plan.max_height_m = h;
        }
        if let Some(s) = o.seed {
            plan.build_id = splitmix64(s ^ splitmix64(l.id));
        }
        plan.style.clone_from(&o.style);
    }
    if plan.max_height_m.is_nan() || plan.max_height_m <= 0.0 {
        return None;
    }
    Some(plan)
}
