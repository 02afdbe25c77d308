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

mod arena;
mod kelly;
mod parish_mueller;

use polis_geom::{Polygon, PolygonWithHoles};
use rand::Rng;

use crate::LotsError;
use crate::block::Block;
use crate::polygon_split::{Region, TaggedRing};
use arena::{Arena, Piece};

/// Which subdivision algorithm to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum LotStrategy {
    /// Kelly 2008: street-facing edges first, width/depth targets, concave splits.
    #[default]
    Kelly,
    /// Parish & Müller 2001: longest roughly parallel edges until under an area.
    ParishMueller,
}

/// Parameters of lot subdivision.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
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
    /// Checks every field against its documented range.
    ///
    /// # Errors
    /// [`LotsError::InvalidParameter`] naming the first bad field.
    pub fn validate(&self) -> Result<(), LotsError> {
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
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
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
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum DiscardReason {
    /// No edge faces a street.
    NoStreetAccess,
    /// Smaller than [`LotParams::min_area`].
    TooSmall,
    /// Concave, with [`LotParams::discard_concave`] set (Parish & Müller).
    Concave,
    /// A region whose hole could not be cut away (numerically degenerate input).
    HoleNotCut,
}

/// A piece of the block that is not a lot.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Discarded {
    /// The piece.
    pub polygon: PolygonWithHoles,
    /// Why it is not a lot.
    pub reason: DiscardReason,
    /// Area in m².
    pub area: f64,
}

/// One subdivision step's cut, recorded when [`Subdivider::record_splits`] is on (Kelly
/// §5.5.1: the lot subdivision debug view draws the split lines in order).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SplitLine {
    /// The cut line's parts inside the piece it split, metres: one chord for a convex
    /// piece, several where the line crosses a concave piece more than once.
    pub chords: Vec<[polis_geom::DVec2; 2]>,
}

/// The result of subdividing one region.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Subdivision {
    /// The lots.
    pub lots: Vec<Lot>,
    /// Pieces without street access kept as green space (with [`LotParams::green_space`]).
    pub green_spaces: Vec<PolygonWithHoles>,
    /// Everything else that is not a lot.
    pub discarded: Vec<Discarded>,
    /// The split lines, one per subdivision step, in the order they were cut; empty unless
    /// [`Subdivider::record_splits`] is on. Default: empty.
    #[cfg_attr(
        feature = "serde",
        serde(default, skip_serializing_if = "Vec::is_empty")
    )]
    pub splits: Vec<SplitLine>,
}

impl Subdivision {
    fn append(&mut self, other: Subdivision) {
        self.lots.extend(other.lots);
        self.green_spaces.extend(other.green_spaces);
        self.discarded.extend(other.discarded);
        self.splits.extend(other.splits);
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
    Subdivider::new().subdivide(region, block_id, params, rng)
}

/// A reusable subdivision worker: keeps its buffers between calls.
#[derive(Debug, Default)]
pub struct Subdivider {
    arena: Arena,
    pieces: Vec<Piece>,
    scratch: Vec<Piece>,
    record_splits: bool,
}

impl Subdivider {
    /// A worker with empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether [`Subdivision::splits`] records every step's split line (a debug record; it
    /// never changes the lots). Default: off.
    pub fn record_splits(&mut self, on: bool) -> &mut Self {
        self.record_splits = on;
        self
    }

    /// Same as [`subdivide_block`], reusing this worker's buffers (and its
    /// [`record_splits`](Self::record_splits) choice).
    ///
    /// # Errors
    /// As [`subdivide`].
    pub fn subdivide_block<R: Rng + ?Sized>(
        &mut self,
        block: &Block,
        params: &LotParams,
        rng: &mut R,
    ) -> Result<Subdivision, LotsError> {
        let mut out = Subdivision::default();
        for parcel in &block.parcels {
            out.append(self.subdivide(parcel, block.id(), params, rng)?);
        }
        Ok(out)
    }

    /// Same as [`subdivide`], reusing this worker's buffers.
    pub fn subdivide<R: Rng + ?Sized>(
        &mut self,
        region: &Region,
        block_id: u64,
        params: &LotParams,
        rng: &mut R,
    ) -> Result<Subdivision, LotsError> {
        params.validate()?;
        validate_region(region)?;
        let mut out = Subdivision::default();
        self.arena.clear();
        if region.holes.is_empty() {
            let piece = self.arena.push(&region.outer, None);
            self.run(piece, block_id, params, &mut out, rng);
            return Ok(out);
        }
        let mut simple = Vec::new();
        cut_holes(region.clone(), &mut simple);
        for r in simple {
            if !r.holes.is_empty() {
                let area = r.area();
                out.discarded.push(Discarded {
                    polygon: to_polygon(&r),
                    reason: DiscardReason::HoleNotCut,
                    area,
                });
                continue;
            }
            let piece = self.arena.push(&r.outer, None);
            self.run(piece, block_id, params, &mut out, rng);
        }
        Ok(out)
    }

    /// Runs the strategy on one simple piece.
    fn run<R: Rng + ?Sized>(
        &mut self,
        piece: Piece,
        block_id: u64,
        params: &LotParams,
        out: &mut Subdivision,
        rng: &mut R,
    ) {
        let mut ctx = Ctx {
            arena: &mut self.arena,
            pieces: &mut self.pieces,
            scratch: &mut self.scratch,
            block_id,
            params,
            out,
            record_splits: self.record_splits,
        };
        match params.strategy {
            LotStrategy::Kelly => kelly::run(&mut ctx, piece, rng),
            LotStrategy::ParishMueller => parish_mueller::run(&mut ctx, piece, rng),
        }
    }
}

/// What the strategies work with.
pub(crate) struct Ctx<'a> {
    pub arena: &'a mut Arena,
    pub pieces: &'a mut Vec<Piece>,
    pub scratch: &'a mut Vec<Piece>,
    pub block_id: u64,
    pub params: &'a LotParams,
    pub out: &'a mut Subdivision,
    pub record_splits: bool,
}

impl Ctx<'_> {
    /// Records the line `(q, r)` that split piece `p` (when recording is on).
    pub fn record_split(&mut self, p: Piece, (q, r): (polis_geom::DVec2, polis_geom::DVec2)) {
        if self.record_splits {
            let chords = self.arena.chords(p, q, r);
            self.out.splits.push(SplitLine { chords });
        }
    }

    /// Sorts a finished piece into lots, green space or discarded.
    pub fn finish(&mut self, p: Piece) {
        let params = self.params;
        let area = self.arena.area(p);
        let polygon = || PolygonWithHoles::from(Polygon::new(self.arena.points(p).to_vec()));
        if !self.arena.has_street(p) {
            if params.green_space {
                self.out.green_spaces.push(polygon());
            } else {
                self.out.discarded.push(Discarded {
                    polygon: polygon(),
                    reason: DiscardReason::NoStreetAccess,
                    area,
                });
            }
            return;
        }
        if area < params.min_area {
            self.out.discarded.push(Discarded {
                polygon: polygon(),
                reason: DiscardReason::TooSmall,
                area,
            });
            return;
        }
        if params.strategy == LotStrategy::ParishMueller && params.discard_concave && !p.convex {
            self.out.discarded.push(Discarded {
                polygon: polygon(),
                reason: DiscardReason::Concave,
                area,
            });
            return;
        }
        let street_edges = self
            .arena
            .street(p)
            .iter()
            .enumerate()
            .filter_map(|(i, &s)| s.then_some(i))
            .collect();
        self.out.lots.push(Lot {
            polygon: Polygon::new(self.arena.points(p).to_vec()),
            street_edges,
            block_id: self.block_id,
            area,
        });
    }
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
        let Some(i) = longest_edge(hole) else {
            out.push(r);
            continue;
        };
        let Some((a, b)) = hole.edge(i) else {
            out.push(r);
            continue;
        };
        let mid = (a + b) * 0.5;
        let pieces = crate::polygon_split::split_by_line(&r, mid, mid + (b - a).perp());
        if pieces.len() == 1 && pieces[0].holes.len() == r.holes.len() {
            out.push(r);
            continue;
        }
        stack.extend(pieces);
    }
}

/// The longest edge of a ring: its index.
fn longest_edge(ring: &TaggedRing) -> Option<usize> {
    let n = ring.points.len();
    (0..n)
        .filter_map(|i| ring.edge(i).map(|e| (e, i)))
        .max_by(|((a0, a1), i), ((b0, b1), j)| {
            a0.distance(*a1).total_cmp(&b0.distance(*b1)).then(j.cmp(i))
        })
        .map(|(_, i)| i)
}
