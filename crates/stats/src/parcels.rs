//! Block, lot and building metrics.
//!
//! # Definitions
//! * **Block shape factor** `Φ = A / (π r_c²)`: the block's area over the area of its
//!   minimum enclosing circle (radius `r_c`, Welzl's algorithm on the outer ring): 1 for
//!   a disc, 0.64 for a square, small for long thin blocks. Blocks of zero area or
//!   radius are counted in [`BlockMetrics::degenerate`] and left out of Φ.
//! * **Lot frontage**: the total length of the lot's street-facing edges. **Depth**: the
//!   largest distance of a lot vertex from the line of its longest street edge. Both
//!   only for lots with street access.
//! * **Block long axis**: the major principal axis of the outer ring's second moment of
//!   area (the direction the block is longest in). The blocks' common direction is the
//!   axial mean of these axes (angles doubled, so 10° and 190° agree), each weighted by
//!   the block's area times its elongation `(λ₁ − λ₂) / (λ₁ + λ₂)` of the moment's
//!   eigenvalues, so square blocks do not vote; its strength is the length of that mean,
//!   0 (no common direction) to 1 (every block long the same way).
//! * **Coverage**: building footprint area over lot area; **floor-area ratio**:
//!   Σ footprint × storeys over lot area.
//!
//! # References
//! Φ after L. Bobkova, M. Berghauser Pont, L. Marcus, *Towards analytical typologies of
//! plot systems*, Urban Morphology 25 (2021), and Louf & Barthelemy, *A typology of
//! street patterns*, J. R. Soc. Interface 11 (2014), who use `Φ = A / (π r_c²)`.

use std::collections::BTreeMap;

use polis_geom::measure::min_enclosing_circle;

use crate::input::{BuildingInput, LotInput};
use crate::summary::{Distribution, Histogram, ratio};

/// Edges of the shape-factor histogram: ten bins of 0.1.
pub const SHAPE_FACTOR_BINS: [f64; 11] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0];

/// Edges of the building-height histogram, metres; the last bin is open (≥ 160 m).
pub const HEIGHT_BINS_M: [f64; 6] = [0.0, 10.0, 20.0, 40.0, 80.0, 160.0];

/// Block metrics.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BlockMetrics {
    /// Blocks.
    pub count: usize,
    /// Areas, m².
    pub area_m2: Distribution,
    /// Shape factors Φ.
    pub shape_factor: Distribution,
    /// Shape factors in bins of 0.1.
    pub shape_factor_histogram: Histogram,
    /// Blocks with zero area or no enclosing circle.
    pub degenerate: usize,
    /// The blocks' common long-axis direction (see the module definitions), degrees in
    /// [0, 180) counter-clockwise from +x; 0 without elongated blocks.
    #[cfg_attr(feature = "serde", serde(default))]
    pub long_axis_deg: f64,
    /// How strongly the blocks share that direction, 0 to 1.
    #[cfg_attr(feature = "serde", serde(default))]
    pub long_axis_order: f64,
}

/// The major principal axis of `ring`'s second moment of area about its centroid:
/// (angle in radians, elongation in [0, 1], area). `None` for a ring without area.
pub fn long_axis(ring: &[polis_geom::DVec2]) -> Option<(f64, f64, f64)> {
    let n = ring.len();
    let first = *ring.first()?;
    // Moments about the first vertex (for precision), then moved to the centroid.
    let (mut a2, mut cx, mut cy, mut ixx, mut iyy, mut ixy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for i in 0..n {
        let (Some(&p), Some(&q)) = (ring.get(i), ring.get((i + 1) % n)) else {
            continue;
        };
        let (p, q) = (p - first, q - first);
        let c = p.x * q.y - q.x * p.y;
        a2 += c;
        cx += (p.x + q.x) * c;
        cy += (p.y + q.y) * c;
        ixx += (p.x * p.x + p.x * q.x + q.x * q.x) * c;
        iyy += (p.y * p.y + p.y * q.y + q.y * q.y) * c;
        ixy += (p.x * q.y + 2.0 * p.x * p.y + 2.0 * q.x * q.y + q.x * p.y) * c;
    }
    let area = a2 * 0.5;
    if area == 0.0 || !area.is_finite() {
        return None;
    }
    let (cx, cy) = (cx / (3.0 * a2), cy / (3.0 * a2));
    // ∫x² dA, ∫y² dA, ∫xy dA (signed like the area), central.
    let sxx = ixx / 12.0 - area * cx * cx;
    let syy = iyy / 12.0 - area * cy * cy;
    let sxy = ixy / 24.0 - area * cx * cy;
    let (sxx, syy, sxy) = if area < 0.0 {
        (-sxx, -syy, -sxy)
    } else {
        (sxx, syy, sxy)
    };
    let trace = sxx + syy;
    let diff = ((sxx - syy).powi(2) + 4.0 * sxy * sxy).sqrt();
    let elongation = if trace > 0.0 {
        (diff / trace).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    angle.is_finite().then_some((angle, elongation, area.abs()))
}

/// Lot metrics.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LotMetrics {
    /// Lots.
    pub count: usize,
    /// Areas, m².
    pub area_m2: Distribution,
    /// Frontages of lots with street access, metres.
    pub frontage_m: Distribution,
    /// Depths of lots with street access, metres.
    pub depth_m: Distribution,
    /// Lots with at least one street edge.
    pub with_street_access: usize,
    /// Share of lots with street access.
    pub street_access_share: f64,
}

/// Building metrics.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BuildingMetrics {
    /// Buildings.
    pub count: usize,
    /// Footprint areas, m².
    pub footprint_m2: Distribution,
    /// Footprint area over lot area.
    pub coverage: f64,
    /// Footprint area over land area.
    pub ground_coverage: f64,
    /// Floor-area ratio: Σ footprint × storeys over lot area.
    pub floor_area_ratio: f64,
    /// Heights, metres.
    pub height_m: Distribution,
    /// Heights in the bins of [`HEIGHT_BINS_M`].
    pub height_histogram: Histogram,
    /// Storeys.
    pub floors: Distribution,
    /// Buildings per kind label (sorted by label).
    pub kinds: BTreeMap<String, usize>,
}

/// Measures blocks given as polygons with holes.
pub fn block_metrics(blocks: &[&polis_geom::PolygonWithHoles]) -> BlockMetrics {
    let mut areas = Vec::with_capacity(blocks.len());
    let mut phis = Vec::with_capacity(blocks.len());
    let mut degenerate = 0;
    let (mut ax, mut ay, mut weights) = (0.0, 0.0, 0.0);
    for b in blocks {
        let area = b.area();
        areas.push(area);
        if let Some((angle, elongation, a)) = long_axis(b.outer.points()) {
            let w = a * elongation;
            ax += w * (2.0 * angle).cos();
            ay += w * (2.0 * angle).sin();
            weights += w;
        }
        let circle = min_enclosing_circle(b.outer.points());
        match circle {
            Some(c) if c.radius > 0.0 && area > 0.0 => phis.push((area / c.area()).min(1.0)),
            _ => degenerate += 1,
        }
    }
    BlockMetrics {
        count: blocks.len(),
        area_m2: Distribution::of(areas),
        shape_factor: Distribution::of(phis.iter().copied()),
        shape_factor_histogram: Histogram::of(&SHAPE_FACTOR_BINS, false, phis),
        degenerate,
        long_axis_deg: if weights > 0.0 {
            (0.5 * ay.atan2(ax)).to_degrees().rem_euclid(180.0) % 180.0
        } else {
            0.0
        },
        long_axis_order: ratio(ax.hypot(ay), weights).clamp(0.0, 1.0),
    }
}

/// Frontage and depth of a lot with street access.
pub fn frontage_and_depth(lot: &LotInput<'_>) -> Option<(f64, f64)> {
    let n = lot.polygon.len();
    let mut frontage = 0.0;
    let mut primary: Option<(f64, usize)> = None;
    for &i in lot.street_edges.iter().filter(|&&i| i < n) {
        let (a, b) = lot.polygon.edge(i);
        let len = a.distance(b);
        frontage += len;
        if primary.is_none_or(|(l, _)| len > l) {
            primary = Some((len, i));
        }
    }
    let (len, i) = primary?;
    let (a, b) = lot.polygon.edge(i);
    let depth = if len > 0.0 {
        let dir = (b - a) / len;
        lot.polygon
            .points()
            .iter()
            .map(|p| dir.perp_dot(*p - a).abs())
            .fold(0.0, f64::max)
    } else {
        0.0
    };
    Some((frontage, depth))
}

/// Measures lots.
pub fn lot_metrics(lots: &[LotInput<'_>]) -> LotMetrics {
    let fd: Vec<(f64, f64)> = lots.iter().filter_map(frontage_and_depth).collect();
    LotMetrics {
        count: lots.len(),
        area_m2: Distribution::of(lots.iter().map(|l| l.polygon.area())),
        frontage_m: Distribution::of(fd.iter().map(|x| x.0)),
        depth_m: Distribution::of(fd.iter().map(|x| x.1)),
        with_street_access: fd.len(),
        street_access_share: ratio(fd.len() as f64, lots.len() as f64),
    }
}

/// Measures buildings against the lots' total area and the land area (m²).
pub fn building_metrics(
    buildings: &[BuildingInput<'_>],
    lot_area_m2: f64,
    land_area_m2: f64,
) -> BuildingMetrics {
    let footprints: Vec<f64> = buildings.iter().map(|b| b.footprint.area()).collect();
    let built: f64 = footprints.iter().sum();
    let floor_area: f64 = buildings
        .iter()
        .zip(&footprints)
        .map(|(b, a)| a * f64::from(b.floors))
        .sum();
    let mut kinds = BTreeMap::new();
    for b in buildings {
        *kinds.entry(b.kind.to_string()).or_insert(0) += 1;
    }
    BuildingMetrics {
        count: buildings.len(),
        footprint_m2: Distribution::of(footprints.iter().copied()),
        coverage: ratio(built, lot_area_m2),
        ground_coverage: ratio(built, land_area_m2),
        floor_area_ratio: ratio(floor_area, lot_area_m2),
        height_m: Distribution::of(buildings.iter().map(|b| b.height_m)),
        height_histogram: Histogram::of(&HEIGHT_BINS_M, true, buildings.iter().map(|b| b.height_m)),
        floors: Distribution::of(buildings.iter().map(|b| f64::from(b.floors))),
        kinds,
    }
}
