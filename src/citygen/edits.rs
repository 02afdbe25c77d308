//! What an editor changes in a Citygen city, as configuration data: per-cell settings
//! (Kelly §5.5's cell property inspector), per-lot and per-building overrides anchored to
//! stable ids (Lipp et al. 2011's "anchored assignments"), and painted map rectangles.
//!
//! They live in [`CitygenConfig`](super::CitygenConfig) (`cells`, `lots`, `paint`), so
//! [`generate`](crate::generate) of a configuration holding them gives exactly the city
//! a [`CityEditor`](crate::editor::CityEditor) made by editing.

use std::sync::Arc;

use polis_buildings::BuildingKind;
use polis_geom::{DVec2, Field};
use polis_roads::secondary::{BuildingHint, Deviated, SecondaryParams};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::maps::CityMaps;

use super::CellPatternChoice;

/// One growth or trait parameter of a city cell, with its deviance where Kelly gives one
/// (§4.3.2: "a deviance parameter partners each control parameter"). In JSON an object
/// with one member named after the parameter: `{"segment_size": {"value": 60,
/// "deviance": 0.2}}`, `{"degree": 3}`. Units are metres (the neighbourhood presets'
/// Citygen units are converted before these apply).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum CellParam {
    /// [`SecondaryParams::segment_size_m`]: metres, > 0 and ≤ 100 km.
    SegmentSize(Deviated),
    /// [`SecondaryParams::aspect`]: in [0.1, 10].
    Aspect(f64),
    /// [`SecondaryParams::degree`]: 1 to 64.
    Degree(u32),
    /// [`SecondaryParams::degree_deviance`]: in [0, 1].
    DegreeDeviance(f64),
    /// [`SecondaryParams::snap_size_m`]: metres, ≥ 0.
    SnapSize(Deviated),
    /// [`SecondaryParams::road_width_m`]: metres, > 0.
    RoadWidth(Deviated),
    /// [`SecondaryParams::connectivity`]: a probability in [0, 1].
    Connectivity(Deviated),
    /// [`SecondaryParams::lot_size_m`]: lot width, metres, > 0 (used by the lot stage).
    LotSize(Deviated),
    /// [`SecondaryParams::building_height_m`]: metres, > 0 (used by the building stage).
    BuildingHeight(Deviated),
    /// [`SecondaryParams::building_hint`].
    BuildingHint(BuildingHint),
    /// [`SecondaryParams::start_sides`]: ≥ 1.
    StartSides(u32),
    /// [`SecondaryParams::min_angle_deg`]: degrees in [0, 90].
    MinAngle(f64),
    /// [`SecondaryParams::bow`]: a fraction of the street in [0, 0.5] (streets bowed
    /// between their ends; 0 keeps them straight).
    Bow(Deviated),
}

impl CellParam {
    /// Writes this parameter into `p`.
    pub fn apply(&self, p: &mut SecondaryParams) {
        match *self {
            CellParam::SegmentSize(d) => p.segment_size_m = d,
            CellParam::Aspect(a) => p.aspect = a,
            CellParam::Degree(d) => p.degree = d,
            CellParam::DegreeDeviance(d) => p.degree_deviance = d,
            CellParam::SnapSize(d) => p.snap_size_m = d,
            CellParam::RoadWidth(d) => p.road_width_m = d,
            CellParam::Connectivity(d) => p.connectivity = d,
            CellParam::LotSize(d) => p.lot_size_m = d,
            CellParam::BuildingHeight(d) => p.building_height_m = d,
            CellParam::BuildingHint(h) => p.building_hint = h,
            CellParam::StartSides(s) => p.start_sides = s,
            CellParam::MinAngle(a) => p.min_angle_deg = a,
            CellParam::Bow(b) => p.bow = b,
        }
    }

    /// Whether `self` and `other` set the same parameter.
    pub fn same_parameter(&self, other: &CellParam) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
    }

    /// Checks the range documented on the variant (by applying it to the default
    /// parameters and validating them).
    ///
    /// # Errors
    /// [`Error::InvalidEdit`] naming the parameter.
    pub fn validate(&self) -> Result<()> {
        let mut p = SecondaryParams::default();
        self.apply(&mut p);
        p.validate().map_err(|e| Error::InvalidEdit {
            field: "param".into(),
            reason: e.to_string(),
        })
    }
}

/// Parameter overrides of one neighbourhood preset, city-wide: wherever the preset
/// grows a cell (chosen by default, a population band, an override, a zone or a cell's
/// settings; grid patterns take their traits from it too), its parameters are these over
/// Kelly's, before a zone level's and the cell's own parameters apply. A city preset
/// tunes a neighbourhood to the real city it imitates this way, leaving Kelly's shipped
/// values (Fig. 76) as they are.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PresetParams {
    /// The neighbourhood preset tuned.
    pub neighbourhood: polis_roads::secondary::Neighbourhood,
    /// Parameters over the preset's (metres), applied in order.
    pub params: Vec<CellParam>,
}

/// The settings of one city cell, keyed by its stable id
/// ([`stable_cell_id`](super::stable_cell_id) / the bounding primary roads).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellSettings {
    /// The cell's stable id.
    pub cell: u64,
    /// Its neighbourhood preset or grid pattern, replacing the one the configuration
    /// would choose. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pattern: Option<CellPatternChoice>,
    /// Parameters over the pattern's, applied in order; at most one per parameter.
    /// Default: none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<CellParam>,
    /// The cell's own growth seed, replacing the city's. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

impl CellSettings {
    /// Settings of `cell` that change nothing.
    pub fn new(cell: u64) -> Self {
        CellSettings {
            cell,
            pattern: None,
            params: Vec::new(),
            seed: None,
        }
    }

    /// Sets `param`, replacing an earlier value of the same parameter.
    pub fn set(&mut self, param: CellParam) {
        match self.params.iter_mut().find(|q| q.same_parameter(&param)) {
            Some(q) => *q = param,
            None => self.params.push(param),
        }
    }

    /// Whether the settings change nothing.
    pub fn is_empty(&self) -> bool {
        self.pattern.is_none() && self.params.is_empty() && self.seed.is_none()
    }
}

/// Overrides of one lot and the building on it (the building's id is the lot's id).
///
/// Anchoring: the override applies to the lot with id `lot`; if no lot has that id
/// (its block was regenerated and renumbered), to the lot whose polygon contains `at`
/// (the lot's centroid when the override was made); if none does, the override is
/// *orphaned*: kept, reported ([`CityEditor::orphans`](crate::editor::CityEditor::orphans)),
/// and applied nowhere.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LotOverride {
    /// The lot's stable id.
    pub lot: u64,
    /// The anchor point, metres: inside the lot when the override was made.
    pub at: [f64; 2],
    /// The building kind, replacing the zoning's. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kind: Option<BuildingKind>,
    /// The building's height limit, metres, in (0, 1000], replacing the zoning's and the
    /// cell's; the grammar draws the kind's height and clamps it to this, so a tall kind
    /// stands at this height. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_m: Option<f64>,
    /// The facade style (a built-in style or one of `facades.styles`), replacing the
    /// kind's. Default: none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub style: Option<String>,
    /// No building on the lot. Default: false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub removed: bool,
    /// A seed for the building, replacing the one derived from the lot's id. Default:
    /// none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

impl LotOverride {
    /// An override of `lot` anchored at `at` that changes nothing yet.
    pub fn new(lot: u64, at: DVec2) -> Self {
        LotOverride {
            lot,
            at: [at.x, at.y],
            kind: None,
            height_m: None,
            style: None,
            removed: false,
            seed: None,
        }
    }

    /// Whether the override changes nothing.
    pub fn is_empty(&self) -> bool {
        self.kind.is_none()
            && self.height_m.is_none()
            && self.style.is_none()
            && !self.removed
            && self.seed.is_none()
    }
}

/// Which map a [`MapPaint`] paints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum PaintLayer {
    /// Population density (value in [0, 1]): neighbourhood bands, zoning bands.
    Population,
    /// Zoning (value: a building kind index 0–5, see [`MapsConfig::zoning`](crate::MapsConfig)).
    Zoning,
    /// Parks (value ≥ 0.5 is a park; in [0, 1]).
    Park,
}

/// A rectangle painted onto an input map: inside it, the map reads `value`. Later paints
/// lie over earlier ones.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapPaint {
    /// The map.
    pub layer: PaintLayer,
    /// The rectangle's minimum corner, metres.
    pub min: [f64; 2],
    /// The rectangle's maximum corner, metres (each coordinate > the minimum's).
    pub max: [f64; 2],
    /// The value inside.
    pub value: f64,
}

impl MapPaint {
    /// The rectangle.
    pub fn rect(&self) -> polis_geom::Aabb2 {
        polis_geom::Aabb2::new(
            DVec2::new(self.min[0], self.min[1]),
            DVec2::new(self.max[0], self.max[1]),
        )
    }

    /// Checks the rectangle (finite, non-empty, inside the map's square of side `size_m`
    /// centred on the origin) and the value's range for its layer.
    ///
    /// # Errors
    /// [`Error::InvalidEdit`] naming what is wrong.
    pub fn validate(&self, size_m: f64) -> Result<()> {
        let bad = |field: &str, reason: String| Error::InvalidEdit {
            field: field.into(),
            reason,
        };
        let h = size_m * 0.5;
        for k in 0..2 {
            let (a, b) = (self.min[k], self.max[k]);
            if !(a.is_finite() && b.is_finite() && a < b) {
                return Err(bad(
                    "min/max",
                    format!("[{a}, {b}]: give finite corners, min below max"),
                ));
            }
            if a < -h || b > h {
                return Err(bad(
                    "min/max",
                    format!("[{a}, {b}] leaves the map (± {h} m)"),
                ));
            }
        }
        let range = match self.layer {
            PaintLayer::Population | PaintLayer::Park => (0.0, 1.0),
            PaintLayer::Zoning => (0.0, 5.0),
        };
        if !(self.value.is_finite() && self.value >= range.0 && self.value <= range.1) {
            return Err(bad(
                "value",
                format!(
                    "{}: give a value in [{}, {}] for this map",
                    self.value, range.0, range.1
                ),
            ));
        }
        Ok(())
    }
}

/// A map with rectangles painted over it (the last containing rectangle wins).
struct Painted {
    inner: Option<Arc<dyn Field>>,
    rects: Vec<(polis_geom::Aabb2, f64)>,
    /// Value outside every rectangle when there is no inner map.
    background: f64,
}

impl Field for Painted {
    fn sample(&self, p: DVec2) -> f64 {
        for (r, v) in self.rects.iter().rev() {
            if r.contains(p) {
                return *v;
            }
        }
        self.inner.as_ref().map_or(self.background, |f| f.sample(p))
    }
}

/// `maps` with the rectangles of `paint` painted on.
pub fn paint_maps(maps: &mut CityMaps, paint: &[MapPaint]) {
    if paint.is_empty() {
        return;
    }
    let rects = |layer: PaintLayer| -> Vec<(polis_geom::Aabb2, f64)> {
        paint
            .iter()
            .filter(|p| p.layer == layer)
            .map(|p| (p.rect(), p.value))
            .collect()
    };
    let population = rects(PaintLayer::Population);
    if !population.is_empty() {
        maps.inputs.population = Arc::new(Painted {
            inner: Some(Arc::clone(&maps.inputs.population)),
            rects: population,
            background: 0.0,
        });
    }
    let parks = rects(PaintLayer::Park);
    if !parks.is_empty() {
        maps.inputs.parks = Arc::new(Painted {
            inner: maps.has_parks.then(|| Arc::clone(&maps.inputs.parks)),
            rects: parks,
            background: 0.0,
        });
        maps.has_parks = true;
    }
    let zoning = rects(PaintLayer::Zoning);
    if !zoning.is_empty() {
        maps.zoning = Some(Arc::new(Painted {
            inner: maps.zoning.clone(),
            rects: zoning,
            // Outside the painted rectangles of a city without a zoning map, the bands
            // decide: see `zone_of`.
            background: f64::NAN,
        }));
    }
}

/// The override that applies to the lot `id` with polygon `polygon`, by id first, else
/// by anchor point (see [`LotOverride`]).
pub fn lot_override<'a>(
    overrides: &'a [LotOverride],
    id: u64,
    polygon: &polis_geom::Polygon,
    ids: &std::collections::BTreeSet<u64>,
) -> Option<&'a LotOverride> {
    overrides.iter().find(|o| o.lot == id).or_else(|| {
        overrides
            .iter()
            .find(|o| !ids.contains(&o.lot) && polygon.contains(DVec2::new(o.at[0], o.at[1])))
    })
}
