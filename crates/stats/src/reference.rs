//! Street-network statistics of 100 real cities, shipped with the crate.
//!
//! The table is G. Boeing, *Urban spatial order: street network orientation,
//! configuration, and entropy*, Applied Network Science 4:67 (2019), Table 1, as
//! reconstructed for this project (`data/street-network-reference.csv`, compiled in):
//! per city φ, `H_o`, `H_w`, median segment length, circuity, `k̄`, dead-end and
//! four-way shares. Some cities have only φ and the four-way share (`H_o` derived from
//! φ); their other values are `None`. Regional means ([`regional_mean`]) average the
//! cities of a region value by value; they agree with the paper's Table 2 (US/Canada
//! φ ≈ 0.427, P₄ ≈ 0.334).

use crate::error::StatsError;

/// The reference table as CSV text (header line first).
pub const REFERENCE_CSV: &str = include_str!("../data/street-network-reference.csv");

/// One real city's street-network values (`None` where the table has none).
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ReferenceCity {
    /// World region (`US/Canada`, `Europe`, `Asia/Oceania`, `Latin America`,
    /// `Middle East/Africa`).
    pub region: String,
    /// City name (`Manhattan`, `San Francisco` …), or `<region> mean`.
    pub city: String,
    /// Orientation order φ.
    pub phi: Option<f64>,
    /// Orientation entropy `H_o`, nats.
    pub orientation_entropy: Option<f64>,
    /// Length-weighted orientation entropy `H_w`, nats.
    pub weighted_orientation_entropy: Option<f64>,
    /// Median street segment length, metres.
    pub median_segment_m: Option<f64>,
    /// Circuity.
    pub circuity: Option<f64>,
    /// Average node degree `k̄`.
    pub average_degree: Option<f64>,
    /// Share of dead ends.
    pub share_dead_end: Option<f64>,
    /// Share of four-way intersections.
    pub share_4way: Option<f64>,
    /// Where the row's values come from (the CSV's provenance column).
    pub provenance: String,
}

/// Splits one CSV line at commas outside double quotes (`""` inside quotes is a quote).
fn split_csv(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                if let Some(f) = out.last_mut() {
                    f.push('"');
                }
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(String::new()),
            _ => {
                if let Some(f) = out.last_mut() {
                    f.push(c);
                }
            }
        }
    }
    out
}

/// Parses a reference table in the shipped CSV's format.
///
/// # Errors
/// [`StatsError::Reference`] naming the line for a missing column or a bad number.
pub fn parse_reference(csv: &str) -> Result<Vec<ReferenceCity>, StatsError> {
    let mut lines = csv.lines().enumerate();
    let header = lines.next().map(|(_, h)| split_csv(h)).unwrap_or_default();
    let col = |name: &str| -> Result<usize, StatsError> {
        header
            .iter()
            .position(|h| h.trim() == name)
            .ok_or_else(|| StatsError::Reference {
                line: 1,
                reason: format!("no column {name:?}"),
            })
    };
    let (region, city, prov) = (col("region")?, col("city")?, col("provenance")?);
    let nums = [
        col("phi")?,
        col("H_o")?,
        col("H_w")?,
        col("median_seg_len_m")?,
        col("circuity")?,
        col("k_avg")?,
        col("P_deadend")?,
        col("P_4way")?,
    ];
    let mut out = Vec::new();
    for (i, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        let f = split_csv(line);
        let get = |c: usize| -> Result<&str, StatsError> {
            f.get(c).map(|s| s.trim()).ok_or(StatsError::Reference {
                line: i + 1,
                reason: format!("{} columns, expected {}", f.len(), header.len()),
            })
        };
        let mut v = [None; 8];
        for (slot, &c) in v.iter_mut().zip(&nums) {
            let text = get(c)?;
            if !text.is_empty() {
                let x: f64 = text.parse().map_err(|_| StatsError::Reference {
                    line: i + 1,
                    reason: format!("{text:?} is not a number"),
                })?;
                if !x.is_finite() {
                    return Err(StatsError::Reference {
                        line: i + 1,
                        reason: format!("{text:?} is not finite"),
                    });
                }
                *slot = Some(x);
            }
        }
        out.push(ReferenceCity {
            region: get(region)?.to_string(),
            city: get(city)?.to_string(),
            phi: v[0],
            orientation_entropy: v[1],
            weighted_orientation_entropy: v[2],
            median_segment_m: v[3],
            circuity: v[4],
            average_degree: v[5],
            share_dead_end: v[6],
            share_4way: v[7],
            provenance: get(prov)?.to_string(),
        });
    }
    Ok(out)
}

/// The 100 cities of the shipped table, in its order.
///
/// # Errors
/// Never for the shipped table (tested); the type allows a corrupt build.
pub fn reference_cities() -> Result<Vec<ReferenceCity>, StatsError> {
    parse_reference(REFERENCE_CSV)
}

/// Mean of the present values.
fn mean(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let (sum, n) = values
        .flatten()
        .fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// The mean of a region's cities, value by value (each over the cities that have it),
/// named `<region> mean`; `None` for a region without cities.
pub fn regional_mean(cities: &[ReferenceCity], region: &str) -> Option<ReferenceCity> {
    let rows: Vec<&ReferenceCity> = cities
        .iter()
        .filter(|c| c.region.eq_ignore_ascii_case(region))
        .collect();
    let first = rows.first()?;
    let m = |f: fn(&ReferenceCity) -> Option<f64>| mean(rows.iter().map(|c| f(c)));
    Some(ReferenceCity {
        region: first.region.clone(),
        city: format!("{} mean", first.region),
        phi: m(|c| c.phi),
        orientation_entropy: m(|c| c.orientation_entropy),
        weighted_orientation_entropy: m(|c| c.weighted_orientation_entropy),
        median_segment_m: m(|c| c.median_segment_m),
        circuity: m(|c| c.circuity),
        average_degree: m(|c| c.average_degree),
        share_dead_end: m(|c| c.share_dead_end),
        share_4way: m(|c| c.share_4way),
        provenance: format!("mean of {} cities", rows.len()),
    })
}

/// A reference city by name, case-insensitively: a city of the table (`"Manhattan"`) or
/// a regional mean (`"US/Canada mean"`).
///
/// # Errors
/// [`StatsError::UnknownCity`] listing the regions and a few cities.
pub fn reference_city(name: &str) -> Result<ReferenceCity, StatsError> {
    let cities = reference_cities()?;
    let wanted = name.trim();
    if let Some(c) = cities.iter().find(|c| c.city.eq_ignore_ascii_case(wanted)) {
        return Ok(c.clone());
    }
    let lower = wanted.to_ascii_lowercase();
    if let Some(region) = lower.strip_suffix(" mean")
        && let Some(m) = regional_mean(&cities, region.trim())
    {
        return Ok(m);
    }
    let mut regions: Vec<&str> = cities.iter().map(|c| c.region.as_str()).collect();
    regions.dedup();
    Err(StatsError::UnknownCity {
        name: name.into(),
        known: format!(
            "{} cities of the table (Manhattan, Paris, Rome …) and the regional means {}",
            cities.len(),
            regions
                .iter()
                .map(|r| format!("\"{r} mean\""))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    })
}
