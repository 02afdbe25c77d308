//! Street-network metrics of Boeing 2019 on the [simplified graph](crate::simplify):
//! orientation entropy and order, node degrees, segment lengths, circuity, intersection
//! density and grade.
//!
//! # Definitions
//! * **Bearing** of a street: the compass bearing (0° north, clockwise) of the straight
//!   line from one end to the other; a street counts with both its bearing and the
//!   reverse one. Self-loops and streets whose ends coincide have none.
//! * **Orientation entropy** `H_o = −Σ Pᵢ ln Pᵢ` over 36 bins of 10° centred on 0°, 10° …
//!   350° (bin `i` holds `[10i − 5°, 10i + 5°)`); `H_w` weights each bearing by the
//!   street's length.
//! * **Orientation order** `φ = 1 − ((H_o − H_g) / (H_max − H_g))²` with `H_max = ln 36`
//!   (uniform) and `H_g = ln 4` (a perfect grid): 1 for a grid, 0 for no order.
//! * **Average degree** `k̄ = 2m / n`; shares of nodes with degree 1 (dead ends), 3, 4
//!   and ≥ 5, over the `n` nodes of the simplified graph (isolated nodes excluded).
//! * **Segment length**: the polyline length of a simplified edge.
//! * **Circuity**: Σ length / Σ straight-line distance between the ends (self-loops add
//!   length and no distance, as in OSMnx).
//! * **Intersection density**: nodes of degree ≥ 2 per km² of land (OSMnx counts every
//!   node with more than one street as an intersection).
//! * **Grade** (with elevations): |Δ elevation| / length of each street.
//!
//! With no street (empty city, only isolated nodes) every value is 0.
//!
//! # References
//! G. Boeing, *Urban spatial order: street network orientation, configuration, and
//! entropy*, Applied Network Science 4:67 (2019), §"Methods".

use crate::input::{StreetClass, StreetGraph};
use crate::simplify::SimpleGraph;
use crate::summary::{Distribution, ratio};

/// Number of orientation bins (10° each).
pub const ORIENTATION_BINS: usize = 36;

/// Entropy of a perfect four-way grid, `ln 4`.
pub fn grid_entropy() -> f64 {
    4f64.ln()
}

/// Entropy of uniformly spread bearings, `ln 36`.
pub fn max_entropy() -> f64 {
    (ORIENTATION_BINS as f64).ln()
}

/// Orientation order φ of an entropy `h` (see the module docs); clamped to [0, 1].
pub fn orientation_order(h: f64) -> f64 {
    let x = (h - grid_entropy()) / (max_entropy() - grid_entropy());
    (1.0 - x * x).clamp(0.0, 1.0)
}

/// Grade statistics of the streets.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GradeMetrics {
    /// Median absolute grade (rise / run).
    pub median: f64,
    /// Length-weighted mean absolute grade.
    pub mean_weighted: f64,
    /// Steepest street's grade.
    pub max: f64,
    /// Share of street length steeper than 10 %.
    pub share_steeper_10pct: f64,
}

/// The street-network metrics.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StreetMetrics {
    /// Nodes of the simplified graph (isolated nodes excluded).
    pub nodes: usize,
    /// Streets (edges of the simplified graph).
    pub streets: usize,
    /// Input segments.
    pub segments: usize,
    /// Input nodes without a street.
    pub isolated_nodes: usize,
    /// Input segments of zero length (contracted).
    pub zero_length_edges: usize,
    /// Self-loops (rings with a single intersection or none).
    pub self_loops: usize,
    /// Orientation entropy `H_o`, nats.
    pub orientation_entropy: f64,
    /// Length-weighted orientation entropy `H_w`, nats.
    pub weighted_orientation_entropy: f64,
    /// Orientation order φ (from `H_o`).
    pub orientation_order: f64,
    /// Bearing shares of the 36 bins (bin `i` centred on `10 i` degrees), unweighted.
    pub orientation_histogram: Vec<f64>,
    /// Average node degree `k̄`.
    pub average_degree: f64,
    /// Share of nodes that are dead ends (degree 1).
    pub share_dead_end: f64,
    /// Share of three-way nodes.
    pub share_3way: f64,
    /// Share of four-way nodes.
    pub share_4way: f64,
    /// Share of nodes with five or more streets.
    pub share_5plus: f64,
    /// Street lengths, metres.
    pub segment_length_m: Distribution,
    /// Circuity (≥ 1 for open streets).
    pub circuity: f64,
    /// Total street length, km.
    pub total_length_km: f64,
    /// Share of the length that is highway.
    pub highway_share: f64,
    /// Intersections (nodes of degree ≥ 2).
    pub intersections: usize,
    /// Intersections per km² of land.
    pub intersection_density_per_km2: f64,
    /// Land area used for the density, km².
    pub land_area_km2: f64,
    /// Grades, when elevations were given.
    pub grade: Option<GradeMetrics>,
    /// Input segments flagged as bridges ([`StreetEdge::bridge`](crate::StreetEdge)).
    #[cfg_attr(feature = "serde", serde(default))]
    pub bridges: usize,
    /// Their total length, metres.
    #[cfg_attr(feature = "serde", serde(default))]
    pub bridge_length_m: f64,
}

/// Bin of a bearing in degrees (any value; taken mod 360).
fn bin_of(bearing_deg: f64) -> usize {
    let b = (bearing_deg + 5.0).rem_euclid(360.0);
    ((b / 10.0).floor() as usize).min(ORIENTATION_BINS - 1)
}

/// Shannon entropy (nats) of bin weights; 0 when they sum to 0.
fn entropy(bins: &[f64]) -> f64 {
    let total: f64 = bins.iter().sum();
    if total <= 0.0 {
        return 0.0;
    }
    bins.iter()
        .filter(|w| **w > 0.0)
        .map(|w| {
            let p = w / total;
            -p * p.ln()
        })
        .sum()
}

/// Measures the simplified graph `s` of `g`; `land_area_m2` is the denominator of the
/// intersection density (0 gives density 0).
pub fn street_metrics(g: &StreetGraph, s: &SimpleGraph, land_area_m2: f64) -> StreetMetrics {
    let mut counts = [0f64; ORIENTATION_BINS];
    let mut weights = [0f64; ORIENTATION_BINS];
    let (mut length, mut chord, mut highway) = (0.0, 0.0, 0.0);
    for e in &s.edges {
        length += e.length_m;
        chord += e.chord_m;
        if e.class == StreetClass::Highway {
            highway += e.length_m;
        }
        if e.is_loop() || e.chord_m <= 0.0 {
            continue;
        }
        let d = g.nodes[e.b] - g.nodes[e.a];
        let bearing = d.x.atan2(d.y).to_degrees();
        for b in [bearing, bearing + 180.0] {
            counts[bin_of(b)] += 1.0;
            weights[bin_of(b)] += e.length_m;
        }
    }
    let h_o = entropy(&counts);
    let h_w = entropy(&weights);
    let bearings: f64 = counts.iter().sum();
    let n = s.nodes.len();
    let share = |pred: &dyn Fn(usize) -> bool| {
        ratio(
            s.nodes.iter().filter(|&&v| pred(s.degree[v])).count() as f64,
            n as f64,
        )
    };
    let intersections = s.nodes.iter().filter(|&&v| s.degree[v] >= 2).count();
    let land_km2 = land_area_m2 / 1.0e6;
    StreetMetrics {
        nodes: n,
        streets: s.edges.len(),
        segments: g.edges.len(),
        isolated_nodes: s.isolated_nodes,
        zero_length_edges: s.zero_length_edges,
        self_loops: s.edges.iter().filter(|e| e.is_loop()).count(),
        orientation_entropy: h_o,
        weighted_orientation_entropy: h_w,
        orientation_order: if bearings > 0.0 {
            orientation_order(h_o)
        } else {
            0.0
        },
        orientation_histogram: counts.iter().map(|c| ratio(*c, bearings)).collect(),
        average_degree: ratio(2.0 * s.edges.len() as f64, n as f64),
        share_dead_end: share(&|d| d == 1),
        share_3way: share(&|d| d == 3),
        share_4way: share(&|d| d == 4),
        share_5plus: share(&|d| d >= 5),
        segment_length_m: Distribution::of(s.edges.iter().map(|e| e.length_m)),
        circuity: ratio(length, chord),
        total_length_km: length / 1000.0,
        highway_share: ratio(highway, length),
        intersections,
        intersection_density_per_km2: ratio(intersections as f64, land_km2),
        land_area_km2: land_km2,
        grade: g.elevations.as_ref().map(|z| grades(s, z)),
        bridges: g.edges.iter().filter(|e| e.bridge).count(),
        bridge_length_m: g
            .edges
            .iter()
            .filter(|e| e.bridge)
            .map(|e| g.nodes[e.a].distance(g.nodes[e.b]))
            .filter(|l| l.is_finite())
            .sum(),
    }
}

fn grades(s: &SimpleGraph, z: &[f64]) -> GradeMetrics {
    let mut per: Vec<(f64, f64)> = s
        .edges
        .iter()
        .filter(|e| e.length_m > 0.0 && !e.is_loop())
        .map(|e| ((z[e.b] - z[e.a]).abs() / e.length_m, e.length_m))
        .filter(|(g, _)| g.is_finite())
        .collect();
    per.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let total: f64 = per.iter().map(|p| p.1).sum();
    let grades: Vec<f64> = per.iter().map(|p| p.0).collect();
    GradeMetrics {
        median: crate::summary::percentile_sorted(&grades, 0.5),
        mean_weighted: ratio(per.iter().map(|(g, l)| g * l).sum(), total),
        max: grades.last().copied().unwrap_or(0.0),
        share_steeper_10pct: ratio(per.iter().filter(|p| p.0 > 0.1).map(|p| p.1).sum(), total),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_are_centred_on_multiples_of_ten() {
        assert_eq!(bin_of(0.0), 0);
        assert_eq!(bin_of(4.9), 0);
        assert_eq!(bin_of(5.0), 1);
        assert_eq!(bin_of(-4.9), 0);
        assert_eq!(bin_of(-5.1), 35);
        assert_eq!(bin_of(355.0), 0);
        assert_eq!(bin_of(90.0), 9);
        assert_eq!(bin_of(540.0), 18);
    }

    #[test]
    fn order_of_grid_and_uniform() {
        assert!((orientation_order(grid_entropy()) - 1.0).abs() < 1e-12);
        assert!(orientation_order(max_entropy()).abs() < 1e-12);
        assert_eq!(entropy(&[0.0; 3]), 0.0);
        assert!((entropy(&[1.0; 36]) - max_entropy()).abs() < 1e-12);
    }
}
