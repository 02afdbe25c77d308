//! Neighbourhood presets as serde data: Kelly's Manhattan, Suburbia and Industrial
//! (Fig. 76) and the Raster and Organic patterns of Fig. 44.
//!
//! # Units
//!
//! Citygen's values are in its own scene units. This crate reads one Citygen unit as
//! [`CITYGEN_UNIT_M`] = 20 m, chosen so that Kelly's building heights and lot sizes are
//! those of their namesakes: Manhattan buildings 1.7 ± 70 % → 34 m ± 70 % (10–58 m),
//! lots 0.7 → 14 m; Suburbia houses 0.3 → 6 m, lots 0.5 → 10 m; Industrial sheds
//! 0.6 → 12 m, lots 1.2 → 24 m. Manhattan's segment size 5 then gives 100 m streets (the
//! real short blocks are about 80 m), Suburbia's 2.4 gives 48 m. Road widths come out
//! narrower than real carriageways (0.45 → 9 m for Manhattan, whose streets are about
//! 18 m kerb to kerb): a city preset may scale them separately.
//!
//! Fig. 44 gives no numbers for Raster and Organic; the values shipped here are chosen to
//! reproduce the figure's look (a regular grid with no deviance; short, meandering,
//! partly connected roads) and say so in their `source` field.

use serde::{Deserialize, Serialize};

use super::error::SecondaryError;
use super::params::{BuildingHint, Deviated, SecondaryParams};

/// Metres per Citygen unit (see the [module docs](self)).
pub const CITYGEN_UNIT_M: f64 = 20.0;

/// A neighbourhood preset as stored: Kelly's control parameters in Citygen units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NeighbourhoodPreset {
    /// The preset's name.
    pub name: String,
    /// Where the values come from.
    #[serde(default)]
    pub source: String,
    /// *Segment Size*, Citygen units.
    pub segment_size: Deviated,
    /// Block aspect (§6.3), a ratio. Default: 1.
    #[serde(default = "one")]
    pub aspect: f64,
    /// *Degree*.
    pub degree: u32,
    /// *Degree* deviance (relative).
    #[serde(default)]
    pub degree_deviance: f64,
    /// *Snap Size*, Citygen units.
    pub snap_size: Deviated,
    /// *Road Width*, Citygen units.
    pub road_width: Deviated,
    /// *Connectivity*, a probability.
    pub connectivity: Deviated,
    /// *Lot Size* and *Lot Deviance*, Citygen units.
    pub lot_size: Deviated,
    /// *Building Height* and *Building Deviance*, Citygen units.
    pub building_height: Deviated,
    /// *Building Hint*.
    pub building_hint: BuildingHint,
}

fn one() -> f64 {
    1.0
}

impl NeighbourhoodPreset {
    /// Parses a preset from JSON.
    ///
    /// # Errors
    /// [`SecondaryError::Preset`] with the parser's message.
    pub fn from_json(name: &str, text: &str) -> Result<Self, SecondaryError> {
        serde_json::from_str(text).map_err(|e| SecondaryError::Preset {
            name: name.into(),
            message: e.to_string(),
        })
    }

    /// The preset in metres, `unit_m` metres per Citygen unit (normally
    /// [`CITYGEN_UNIT_M`]), with the other fields of [`SecondaryParams`] at their defaults.
    pub fn to_params(&self, unit_m: f64) -> SecondaryParams {
        SecondaryParams {
            segment_size_m: self.segment_size.scaled(unit_m),
            aspect: self.aspect,
            degree: self.degree,
            degree_deviance: self.degree_deviance,
            snap_size_m: self.snap_size.scaled(unit_m),
            road_width_m: self.road_width.scaled(unit_m),
            connectivity: self.connectivity,
            lot_size_m: self.lot_size.scaled(unit_m),
            building_height_m: self.building_height.scaled(unit_m),
            building_hint: self.building_hint,
            ..SecondaryParams::default()
        }
    }
}

/// The shipped neighbourhood presets.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, Default,
)]
#[serde(rename_all = "snake_case")]
pub enum Neighbourhood {
    /// Kelly's Manhattan (Fig. 76): a grid, degree 4, connectivity 1.
    #[default]
    Manhattan,
    /// Kelly's Suburbia (Fig. 76): degree 18 ± 60 %, connectivity 0.05: trees of
    /// culs-de-sac.
    Suburbia,
    /// Kelly's Industrial (Fig. 76): a coarse grid with connectivity 0.05.
    Industrial,
    /// The Raster pattern of Fig. 44: a grid without deviance.
    Raster,
    /// The Organic pattern of Fig. 44: short, meandering, partly connected roads.
    Organic,
}

impl Neighbourhood {
    /// Every preset.
    pub const ALL: [Neighbourhood; 5] = [
        Neighbourhood::Manhattan,
        Neighbourhood::Suburbia,
        Neighbourhood::Industrial,
        Neighbourhood::Raster,
        Neighbourhood::Organic,
    ];

    /// The preset's name (as in JSON).
    pub fn name(self) -> &'static str {
        match self {
            Neighbourhood::Manhattan => "manhattan",
            Neighbourhood::Suburbia => "suburbia",
            Neighbourhood::Industrial => "industrial",
            Neighbourhood::Raster => "raster",
            Neighbourhood::Organic => "organic",
        }
    }

    /// The preset's JSON text (Citygen units).
    pub fn json(self) -> &'static str {
        match self {
            Neighbourhood::Manhattan => include_str!("presets/manhattan.json"),
            Neighbourhood::Suburbia => include_str!("presets/suburbia.json"),
            Neighbourhood::Industrial => include_str!("presets/industrial.json"),
            Neighbourhood::Raster => include_str!("presets/raster.json"),
            Neighbourhood::Organic => include_str!("presets/organic.json"),
        }
    }

    /// The preset as stored (Citygen units).
    ///
    /// # Errors
    /// [`SecondaryError::Preset`] if the shipped JSON does not parse (tested not to).
    pub fn preset(self) -> Result<NeighbourhoodPreset, SecondaryError> {
        NeighbourhoodPreset::from_json(self.name(), self.json())
    }

    /// The preset in metres ([`CITYGEN_UNIT_M`] per unit).
    ///
    /// # Errors
    /// As [`preset`](Self::preset).
    pub fn params(self) -> Result<SecondaryParams, SecondaryError> {
        Ok(self.preset()?.to_params(CITYGEN_UNIT_M))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn every_preset_parses_validates_and_keeps_kellys_values() {
        for n in Neighbourhood::ALL {
            let p = n.preset().unwrap();
            assert_eq!(p.name, n.name());
            n.params().unwrap().validate().unwrap();
        }
        let m = Neighbourhood::Manhattan.params().unwrap();
        assert_eq!(m.segment_size_m, Deviated::new(100.0, 0.2));
        assert_eq!(m.degree, 4);
        assert_eq!(m.snap_size_m, Deviated::new(48.0, 0.1));
        assert_eq!(m.connectivity.value, 1.0);
        let s = Neighbourhood::Suburbia.params().unwrap();
        assert_eq!((s.degree, s.degree_deviance), (18, 0.6));
        assert_eq!(s.connectivity.value, 0.05);
        assert_eq!(s.building_hint, BuildingHint::House);
        let i = Neighbourhood::Industrial.params().unwrap();
        assert_eq!(i.lot_size_m, Deviated::new(24.0, 0.6));
    }

    #[test]
    fn a_bad_preset_file_is_a_typed_error() {
        let e = NeighbourhoodPreset::from_json("x", "{ \"name\": 3 }").unwrap_err();
        assert!(matches!(e, SecondaryError::Preset { .. }));
    }
}
