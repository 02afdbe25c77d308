//! The realism comparison: a city's street metrics beside a [reference
//! city](crate::reference)'s, each marked in or out of its band.
//!
//! Bands (issue 19): φ ± 0.10, `k̄` ± 0.20, dead-end share ± 0.05, four-way share
//! ± 0.08, median segment length ± 25 %, circuity ± 0.02. The entropies are shown
//! without a band (φ carries the same information). A metric the reference lacks has
//! no verdict.

use crate::reference::ReferenceCity;
use crate::streets::StreetMetrics;

/// How far from the reference value a metric may be.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Band {
    /// Within ± this much of the reference value.
    Absolute(f64),
    /// Within ± this fraction of the reference value.
    Relative(f64),
}

impl Band {
    /// Whether `value` is within the band around `reference` (inclusive).
    pub fn contains(&self, value: f64, reference: f64) -> bool {
        let half = match *self {
            Band::Absolute(d) => d,
            Band::Relative(f) => f * reference.abs(),
        };
        // A hair of slack so that a value printed as the band's edge passes.
        (value - reference).abs() <= half + 1e-9
    }
}

impl std::fmt::Display for Band {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Band::Absolute(d) => write!(f, "±{d}"),
            Band::Relative(r) => write!(f, "±{}%", r * 100.0),
        }
    }
}

/// One compared metric.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RealismRow {
    /// Metric name (`phi`, `k_avg` …, as in the reference table).
    pub metric: String,
    /// The generated city's value.
    pub polis: f64,
    /// The reference city's value, if known.
    pub real: Option<f64>,
    /// The band, if the metric has one.
    pub band: Option<Band>,
    /// In band (`None` without a band or a reference value).
    pub in_band: Option<bool>,
}

/// A city's street metrics against a reference city.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Realism {
    /// The reference city.
    pub city: String,
    /// Its region.
    pub region: String,
    /// Metric by metric.
    pub rows: Vec<RealismRow>,
    /// Metrics in their band.
    pub in_band: usize,
    /// Metrics out of their band.
    pub out_of_band: usize,
}

impl Realism {
    /// The row of a metric.
    pub fn row(&self, metric: &str) -> Option<&RealismRow> {
        self.rows.iter().find(|r| r.metric == metric)
    }
}

/// Compares `streets` with `reference`.
pub fn compare(streets: &StreetMetrics, reference: &ReferenceCity) -> Realism {
    let r = reference;
    let items: [(&str, f64, Option<f64>, Option<Band>); 8] = [
        (
            "phi",
            streets.orientation_order,
            r.phi,
            Some(Band::Absolute(0.10)),
        ),
        (
            "H_o",
            streets.orientation_entropy,
            r.orientation_entropy,
            None,
        ),
        (
            "H_w",
            streets.weighted_orientation_entropy,
            r.weighted_orientation_entropy,
            None,
        ),
        (
            "k_avg",
            streets.average_degree,
            r.average_degree,
            Some(Band::Absolute(0.20)),
        ),
        (
            "P_deadend",
            streets.share_dead_end,
            r.share_dead_end,
            Some(Band::Absolute(0.05)),
        ),
        (
            "P_4way",
            streets.share_4way,
            r.share_4way,
            Some(Band::Absolute(0.08)),
        ),
        (
            "median_seg_len_m",
            streets.segment_length_m.median,
            r.median_segment_m,
            Some(Band::Relative(0.25)),
        ),
        (
            "circuity",
            streets.circuity,
            r.circuity,
            Some(Band::Absolute(0.02)),
        ),
    ];
    let rows: Vec<RealismRow> = items
        .into_iter()
        .map(|(metric, polis, real, band)| RealismRow {
            metric: metric.into(),
            polis,
            real,
            band,
            in_band: match (real, band) {
                (Some(x), Some(b)) => Some(b.contains(polis, x)),
                _ => None,
            },
        })
        .collect();
    Realism {
        city: r.city.clone(),
        region: r.region.clone(),
        in_band: rows.iter().filter(|x| x.in_band == Some(true)).count(),
        out_of_band: rows.iter().filter(|x| x.in_band == Some(false)).count(),
        rows,
    }
}
