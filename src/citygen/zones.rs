//! Neighbourhoods chosen by a zoning map (Kelly §5.5: the user paints which cells are
//! Manhattan, Suburbia, Industrial …; issue 18).
//!
//! A [`ZoneMap`] is any input map (a grey-scale PNG, an inline raster, a procedural field
//! or a city shape, as in `maps`) whose values are *levels*: each [`ZoneLevel`] names the
//! pattern of the cells its value labels, and optionally overrides some of the pattern's
//! parameters ([`CellParam`]s, as the editor writes them per cell).
//!
//! # The rule
//!
//! * A sample `v` of the map belongs to the level whose `value` is nearest, if
//!   `|v − value| ≤ tolerance`; otherwise it is *unknown* (e.g. the blend between two
//!   grey levels along a zone border, or a grey no level names) and does not vote.
//!   Equally near levels: the first listed wins.
//! * [`ZoneRule::Majority`] (default): the cell's region is sampled on a square lattice
//!   of [`ZoneMap::sample_m`] (the lattice is refined until at least 16 lattice points
//!   fall inside, down to 1/64 of the step); each sample inside the region votes for its
//!   level, and the level with most votes wins (ties: the first listed). A cell with no
//!   known sample falls back to its centroid.
//! * [`ZoneRule::Centroid`]: the level at the area centroid of the cell's outer ring.
//! * A cell whose samples are all unknown is not zoned: it falls through to the
//!   population bands and the default neighbourhood (documented default, no error).
//!
//! Precedence for each cell: its per-cell settings (editor) → an explicit override →
//! the zoning map → the population bands → the default neighbourhood.

use std::sync::Arc;

use polis_geom::{Aabb2, DVec2, Field, PointLocation, PolygonWithHoles};
use serde::{Deserialize, Serialize};

use super::{CellParam, CellPatternChoice};
use crate::error::{Error, Result};
use crate::maps::MapSpec;

/// How a cell's samples of the zoning map choose its level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ZoneRule {
    /// The level covering most of the cell's area (samples on a lattice). Default.
    #[default]
    Majority,
    /// The level at the cell's centroid.
    Centroid,
}

/// One level of a zoning map: the cells it labels and how they grow.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ZoneLevel {
    /// The map value of this level (e.g. a grey level in [0, 1] of a PNG, or an integer
    /// label of a procedural map). Must be finite and differ from every other level's.
    pub value: f64,
    /// The pattern of the cells at this level.
    pub neighbourhood: CellPatternChoice,
    /// Parameter overrides applied on top of the pattern's preset (as per-cell settings
    /// are). Default: none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<CellParam>,
}

/// A zoning map selecting each city cell's neighbourhood: see the [module docs](self).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ZoneMap {
    /// The map (any input map form; PNG grey levels are in [0, 1]).
    pub map: MapSpec,
    /// The levels; at least one.
    pub levels: Vec<ZoneLevel>,
    /// How a cell's samples decide. Default: majority.
    #[serde(default)]
    pub rule: ZoneRule,
    /// The largest distance of a sample from its level's value; farther samples are
    /// unknown. `None`: half the smallest gap between two levels' values (every value
    /// for a single level). Must be finite and ≥ 0. Default: None.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Lattice step of the majority rule's samples, metres. Must be finite and in
    /// [1, 1000]. Default: 25.
    #[serde(default = "default_sample_m")]
    pub sample_m: f64,
}

fn default_sample_m() -> f64 {
    25.0
}

/// The fewest samples the majority rule takes inside a cell (it refines its lattice to
/// reach them).
pub const MIN_ZONE_SAMPLES: usize = 16;

impl ZoneMap {
    /// Checks the levels, tolerance and sample step.
    ///
    /// # Errors
    /// [`Error::Config`] naming the field.
    pub fn validate(&self) -> Result<()> {
        if self.levels.is_empty() {
            return Err(Error::config(
                "citygen.zones.levels",
                "give at least one level (a map value and its neighbourhood)",
            ));
        }
        for (i, l) in self.levels.iter().enumerate() {
            if !l.value.is_finite() {
                return Err(Error::config(
                    format!("citygen.zones.levels[{i}].value"),
                    "must be finite",
                ));
            }
            if self.levels[..i].iter().any(|m| m.value == l.value) {
                return Err(Error::config(
                    format!("citygen.zones.levels[{i}].value"),
                    format!("{} is given to two levels", l.value),
                ));
            }
            for q in &l.params {
                q.validate().map_err(|e| {
                    Error::config(format!("citygen.zones.levels[{i}].params"), e.to_string())
                })?;
            }
        }
        if let Some(t) = self.tolerance
            && !(t.is_finite() && t >= 0.0)
        {
            return Err(Error::config(
                "citygen.zones.tolerance",
                format!("{t}; give a finite distance ≥ 0"),
            ));
        }
        if !(self.sample_m.is_finite() && (1.0..=1000.0).contains(&self.sample_m)) {
            return Err(Error::config(
                "citygen.zones.sample_m",
                format!("{} m; give a step in [1, 1000] m", self.sample_m),
            ));
        }
        Ok(())
    }

    /// Checks that a PNG or inline raster map covers the city's square of side `size_m`
    /// (centred on the origin): a smaller image would hold its edge values over the rest
    /// of the city.
    ///
    /// # Errors
    /// [`Error::Config`] naming `citygen.zones.map`.
    pub fn check_extent(&self, size_m: f64) -> Result<()> {
        let extent = match &self.map {
            #[cfg(feature = "png")]
            MapSpec::Field(polis_geom::field::FieldSpec::Png { extent, .. }) => Some(*extent),
            MapSpec::Field(polis_geom::field::FieldSpec::Raster(r)) => Some(r.extent()),
            _ => None,
        };
        if let Some(e) = extent {
            let h = size_m * 0.5;
            let covers = e.min.x <= -h && e.min.y <= -h && e.max.x >= h && e.max.y >= h;
            if !covers {
                return Err(Error::config(
                    "citygen.zones.map",
                    format!(
                        "the image covers [{}, {}] × [{}, {}] m, not the city's square ±{h} m",
                        e.min.x, e.max.x, e.min.y, e.max.y
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The tolerance in use (see [`tolerance`](Self::tolerance)).
    pub fn effective_tolerance(&self) -> f64 {
        if let Some(t) = self.tolerance {
            return t;
        }
        let mut values: Vec<f64> = self.levels.iter().map(|l| l.value).collect();
        values.sort_by(f64::total_cmp);
        values
            .windows(2)
            .map(|w| (w[1] - w[0]) * 0.5)
            .fold(f64::INFINITY, f64::min)
    }

    /// Builds the map.
    ///
    /// # Errors
    /// As [`MapSpec::build_limited`].
    pub fn build(&self, salt: u64, max_pixels: u64) -> Result<Zoning> {
        Ok(Zoning {
            field: self
                .map
                .build_limited("citygen.zones.map", salt, max_pixels)?,
            tolerance: self.effective_tolerance(),
        })
    }
}

/// A built zoning map: the field and the tolerance, ready to classify cells with the
/// levels of its [`ZoneMap`].
#[derive(Clone)]
pub struct Zoning {
    field: Arc<dyn Field>,
    tolerance: f64,
}

impl std::fmt::Debug for Zoning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Zoning")
            .field("tolerance", &self.tolerance)
            .finish_non_exhaustive()
    }
}

impl Zoning {
    /// The level (index into `zones.levels`) of one sample, if any.
    fn level_at(&self, zones: &ZoneMap, p: DVec2) -> Option<usize> {
        let v = self.field.sample(p);
        if !v.is_finite() {
            return None;
        }
        let mut best: Option<(f64, usize)> = None;
        for (i, l) in zones.levels.iter().enumerate() {
            let d = (v - l.value).abs();
            if d <= self.tolerance && best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, i));
            }
        }
        best.map(|(_, i)| i)
    }

    /// The level of the cell `region` by the map's rule, or `None` when no sample is
    /// known (the cell is not zoned).
    pub fn level_of(&self, zones: &ZoneMap, region: &PolygonWithHoles) -> Option<usize> {
        let centroid = || {
            let c = region.outer.centroid();
            self.level_at(zones, c)
        };
        if zones.rule == ZoneRule::Centroid {
            return centroid();
        }
        let mut votes = vec![0usize; zones.levels.len()];
        let bbox = Aabb2::from_points(region.outer.points().iter().copied());
        let mut step = zones.sample_m;
        for _ in 0..7 {
            votes.iter_mut().for_each(|v| *v = 0);
            let mut inside = 0usize;
            let nx = ((bbox.max.x - bbox.min.x) / step).floor() as usize + 1;
            let ny = ((bbox.max.y - bbox.min.y) / step).floor() as usize + 1;
            if nx.saturating_mul(ny) > 1 << 20 {
                break;
            }
            // The lattice is centred on the box so that a cell's samples do not depend
            // on where the city's origin is.
            let x0 = bbox.min.x + 0.5 * ((bbox.max.x - bbox.min.x) - (nx - 1) as f64 * step);
            let y0 = bbox.min.y + 0.5 * ((bbox.max.y - bbox.min.y) - (ny - 1) as f64 * step);
            for j in 0..ny {
                for i in 0..nx {
                    let p = DVec2::new(x0 + i as f64 * step, y0 + j as f64 * step);
                    if region.locate(p) != PointLocation::Inside {
                        continue;
                    }
                    inside += 1;
                    if let Some(l) = self.level_at(zones, p)
                        && let Some(v) = votes.get_mut(l)
                    {
                        *v += 1;
                    }
                }
            }
            if inside >= MIN_ZONE_SAMPLES {
                break;
            }
            step *= 0.5;
        }
        let best = votes
            .iter()
            .enumerate()
            .filter(|(_, v)| **v > 0)
            .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(&a.0)))
            .map(|(i, _)| i);
        best.or_else(centroid)
    }
}
