//! Lot subdivision: a block's land split recursively into lots that face a street.
//!
//! Two strategies ([`LotStrategy`]):
//!
//! * **Kelly** (2008 §4.4.2): split across the longest street-facing edge first (so lots
//!   stand perpendicular to their street), with lot width and depth targets and a deviance;
//!   the split point is the accurate "middle-most fraction" (a 60 × 20 block with 20 × 20
//!   targets gives exactly three lots); concave regions are cut by a line into *all* their
//!   pieces ([`split_by_line`](crate::polygon_split::split_by_line)); pieces that lose
//!   street access are dropped at once (or kept as green space).
//! * **Parish & Müller** (2001 §4.1): split across the longest pair of roughly parallel
//!   edges until each lot is under an area threshold; lots that are too small, have no
//!   street access or (optionally) are concave are discarded.
//!
//! # Guarantees
//!
//! * The kept lots and the discarded pieces partition the input: they do not overlap and
//!   their areas add up to the input's (up to rounding).
//! * Every piece is a simple polygon; every kept lot has at least one street edge.
//! * Deterministic: the same input, parameters and generator state give the same lots.

mod kelly;
mod parish_mueller;

use polis_geom::{Polygon, PolygonWithHoles};
use rand::Rng;
use serde::{Deserialize, Serialize};

use crate::LotsError;
use crate::block::Block;
use crate::polygon_split::{Region, TaggedRing};

/// Which subdivision algorithm to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum LotStrategy {
    /// Kelly 2008: street-facing edges first, width/depth targets, concave splits.
    #[default]
    Kelly,
    /// Parish & Müller 2001: longest roughly parallel edges until under an area.
    ParishMueller,
}

/// Parameters of lot subdivision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LotParams {
    /// The algorithm. Default: [`LotStrategy::Kelly`].
    pub strategy: LotStrategy,
    /// Target lot width along the street, metres (Kelly). Default: 15.
    pub lot_width: f64,
    /// Target lot depth away from the street, metres (Kelly). Default: 30.
    pub lot_depth: f64,
    /// Randomness of the split position, 0 (regular) to 1 (a whole lot width either way
    /// … half of one), as a fraction of one lot. Default: 0.2.
    pub deviance: f64,
    /// Lots smaller than this are discarded, m². Default: 30.
    pub min_area: f64,
    /// Parish & Müller: split until each lot is under this area, m². Default: 600.
    pub max_area: f64,
    /// Parish & Müller: edges within this angle of antiparallel count as "roughly
    /// parallel", degrees. Default: 20.
    pub parallel_tolerance_deg: f64,
    /// Parish & Müller: discard concave lots, as the paper does. Default: true.
    pub discard_concave: bool,
    /// Keep pieces without street access as green space instead of discarding them.
    /// Default: false.
    pub green_space: bool,
}

impl Default for LotParams {
    fn default() -> Self {
        LotParams {
            strategy: LotStrategy::Kelly,
            lot_width: 15.0,
            lot_depth: 30.0,
            deviance: 0.2,
            min_area: 30.0,
            max_area: 600.0,
            parallel_tolerance_deg: 20.0,
            discard_concave: true,
            green_space: false,
        }
    }
}

impl LotParams {
    fn validate(&self) -> Result<(), LotsError> {
        let positive = |name: &'static str, x: f64| {
            if x.is_finite() && x > 0.0 {
                Ok(())
            } else {
                Err(LotsError::InvalidParameter {
                    name,
                    reason: format!("{x}; it must be finite and greater than zero"),
                })
            }
        };
        positive("lot_width", self.lot_width)?;
        positive("lot_depth", self.lot_depth)?;
        positive("max_area", self.max_area)?;
        if !(self.min_area.is_finite() && self.min_area >= 0.0) {
            return Err(LotsError::InvalidParameter {
                name: "min_area",
                reason: format!("{}; it must be finite and not negative", self.min_area),
            });
        }
        if !(0.0..=1.0).contains(&self.deviance) {
            return Err(LotsError::InvalidParameter {
                name: "deviance",
                reason: format!("{}; it must be between 0 and 1", self.deviance),
            });
        }
        if !(0.0..90.0).contains(&self.parallel_tolerance_deg) {
            return Err(LotsError::InvalidParameter {
                name: "parallel_tolerance_deg",
                reason: format!("{}; it must be in [0, 90)", self.parallel_tolerance_deg),
            });
        }
        Ok(())
    }
}

/// A building lot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Lot {
    /// The lot, counter-clockwise.
    pub polygon: Polygon,
    /// Indices of the polygon's edges that face a street.
    pub street_edges: Vec<usize>,
    /// The block it belongs to.
    pub block_id: u64,
    /// Area in m².
    pub area: f64,
}

/// Why a piece was not kept as a lot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum DiscardReason {
    /// No edge faces a street.
    NoStreetAccess,
    /// Smaller than [`LotParams::min_area`].
    TooSmall,
    /// Concave, with [`LotParams::discard_concave`] set (Parish & Müller).
    Concave,
}

/// A piece of the block that is not a lot.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Discarded {
    /// The piece.
    pub polygon: PolygonWithHoles,
    /// Why it is not a lot.
    pub reason: DiscardReason,
    /// Area in m².
    pub area: f64,
}

/// The result of subdividing one region.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Subdivision {
    /// The lots.
    pub lots: Vec<Lot>,
    /// Pieces without street access kept as green space (with [`LotParams::green_space`]).
    pub green_spaces: Vec<PolygonWithHoles>,
    /// Everything else that is not a lot.
    pub discarded: Vec<Discarded>,
}

impl Subdivision {
    fn append(&mut self, other: Subdivision) {
        self.lots.extend(other.lots);
        self.green_spaces.extend(other.green_spaces);
        self.discarded.extend(other.discarded);
    }
}

/// Subdivides every parcel of a block into lots. `rng` should be seeded by the caller for
/// this block (for instance from the city seed and [`Block::id`]).
pub fn subdivide_block<R: Rng + ?Sized>(
    block: &Block,
    params: &LotParams,
    rng: &mut R,
) -> Result<Subdivision, LotsError> {
    let mut out = Subdivision::default();
    for parcel in &block.parcels {
        out.append(subdivide(parcel, block.id(), params, rng)?);
    }
    Ok(out)
}

/// Subdivides one region (a polygon with street flags per edge) into lots.
///
/// # Errors
/// Invalid geometry (not simple, NaN, wrong orientation), a street flag count that does
/// not match the edge count, or invalid parameters.
pub fn subdivide<R: Rng + ?Sized>(
    region: &Region,
    block_id: u64,
    params: &LotParams,
    rng: &mut R,
) -> Result<Subdivision, LotsError> {
    params.validate()?;
    validate_region(region)?;
    let mut out = Subdivision::default();
    let mut simple = Vec::new();
    cut_holes(region.clone(), &mut simple);
    for r in simple {
        match params.strategy {
            LotStrategy::Kelly => kelly::run(r, block_id, params, rng, &mut out),
            LotStrategy::ParishMueller => parish_mueller::run(r, block_id, params, rng, &mut out),
        }
    }
    Ok(out)
}

fn validate_region(region: &Region) -> Result<(), LotsError> {
    let pw = to_polygon(region);
    pw.validate()?;
    if pw.outer.signed_area() <= 0.0 {
        return Err(LotsError::WrongOrientation {
            ring: polis_geom::Ring::Outer,
        });
    }
    for (i, h) in pw.holes.iter().enumerate() {
        if h.signed_area() >= 0.0 {
            return Err(LotsError::WrongOrientation {
                ring: polis_geom::Ring::Hole(i),
            });
        }
    }
    let total: usize = region.rings().map(|r| r.points.len()).sum();
    let flags: usize = region.rings().map(|r| r.street.len()).sum();
    if region.rings().any(|r| r.street.len() != r.points.len()) {
        return Err(LotsError::EdgeCountMismatch {
            what: "street flags",
            expected: total,
            got: flags,
        });
    }
    Ok(())
}

/// The region as a plain polygon with holes.
pub(crate) fn to_polygon(region: &Region) -> PolygonWithHoles {
    PolygonWithHoles::new(
        Polygon::new(region.outer.points.clone()),
        region
            .holes
            .iter()
            .map(|h| Polygon::new(h.points.clone()))
            .collect(),
    )
}

/// Cuts a region with holes into simple regions: across the middle of each hole's longest
/// edge, perpendicular to it.
fn cut_holes(region: Region, out: &mut Vec<Region>) {
    let mut stack = vec![region];
    let mut guard = 0;
    while let Some(r) = stack.pop() {
        guard += 1;
        let Some(hole) = r.holes.first() else {
            out.push(r);
            continue;
        };
        if guard > 1000 {
            out.push(r);
            continue;
        }
        let Some((i, _)) = longest_edge(hole, |_| true) else {
            out.push(r);
            continue;
        };
        let (a, b) = hole.edge(i);
        let pieces = split_across(&r, a, b, 0.5);
        if pieces.len() == 1 && pieces[0].holes.len() == r.holes.len() {
            out.push(r);
            continue;
        }
        stack.extend(pieces);
    }
}

/// The longest edge of a ring among those `filter` accepts: (index, length).
pub(crate) fn longest_edge(
    ring: &TaggedRing,
    filter: impl Fn(usize) -> bool,
) -> Option<(usize, f64)> {
    let mut best: Option<(usize, f64)> = None;
    for i in 0..ring.points.len() {
        if !filter(i) {
            continue;
        }
        let (a, b) = ring.edge(i);
        let l = a.distance(b);
        if best.is_none_or(|(_, bl)| l > bl) {
            best = Some((i, l));
        }
    }
    best
}

/// Splits `region` by the line perpendicular to `a → b` through the point at fraction `t`
/// of the way from `a` to `b`. If a vertex lies (almost) on that line the point is moved a
/// little along the edge, so the split never runs along an edge or through a vertex.
pub(crate) fn split_across(region: &Region, a: DVec2, b: DVec2, t: f64) -> Vec<Region> {
    let d = b - a;
    let len = d.length();
    let n = d.perp();
    let tol = 1e-7 * len;
    let mut t = t;
    for attempt in 0..8 {
        let p = polis_geom::predicates::lerp_stable(a, b, t);
        let near = region
            .rings()
            .flat_map(|r| r.points.iter())
            .any(|&q| (q - p).dot(d).abs() <= tol * len);
        if !near || attempt == 7 {
            return crate::polygon_split::split_by_line(region, p, p + n);
        }
        t += 1e-5 * (attempt as f64 + 1.0) * if attempt % 2 == 0 { 1.0 } else { -1.0 };
    }
    vec![region.clone()]
}

use polis_geom::DVec2;

/// Sorts a finished piece into lots, green space or discarded.
pub(crate) fn finish(region: Region, block_id: u64, params: &LotParams, out: &mut Subdivision) {
    let area = region.area();
    let polygon = to_polygon(&region);
    if !region.has_street() {
        if params.green_space {
            out.green_spaces.push(polygon);
        } else {
            out.discarded.push(Discarded {
                polygon,
                reason: DiscardReason::NoStreetAccess,
                area,
            });
        }
        return;
    }
    if area < params.min_area {
        out.discarded.push(Discarded {
            polygon,
            reason: DiscardReason::TooSmall,
            area,
        });
        return;
    }
    if params.strategy == LotStrategy::ParishMueller
        && params.discard_concave
        && !polygon.outer.is_convex()
    {
        out.discarded.push(Discarded {
            polygon,
            reason: DiscardReason::Concave,
            area,
        });
        return;
    }
    let street_edges = region
        .outer
        .street
        .iter()
        .enumerate()
        .filter_map(|(i, &s)| s.then_some(i))
        .collect();
    out.lots.push(Lot {
        polygon: polygon.outer,
        street_edges,
        block_id,
        area,
    });
}
