//! [`GridParams`]: the rules plus the grid they are walked on.

use serde::{Deserialize, Serialize};

use super::error::{GridError, Result};
use super::rules::GridRules;

/// Everything the grid road builders of one cell need besides the cell, the maps and the
/// seed: the report's rules, and how its abstract grid is laid over the cell in metres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GridParams {
    /// The builders' rules and probabilities (the report's JSON shape). Default: the
    /// report's Downtown rules.
    pub rules: GridRules,
    /// Distance between neighbouring grid points, metres: one builder step. Parallel
    /// streets are at least two steps apart (the report's side constraint), so the
    /// smallest block is `2 · grid_size_m` from street centre to street centre. Must be
    /// finite and positive. Default: 25 m (a 500 m cell is a 20 × 20 grid, the size of
    /// the report's smaller maps).
    pub grid_size_m: f64,
    /// Direction of the grid's first axis, degrees counter-clockwise from +x; `None`
    /// follows the cell: the direction of its longest boundary edge. Default: `None`.
    pub orientation_deg: Option<f64>,
    /// How many builders start: one at the midpoint of each of the `starts` longest
    /// boundary edges (longest first), walking inwards. The report starts one; a second
    /// reaches the far side of concave cells; in a cell only a few grid steps across the
    /// boundary ends many builders early, so more starts keep the cell covered. Must be
    /// at least 1. Default: 4.
    pub starts: u32,
    /// Clearance from the cell boundary (and filaments), as a fraction of `grid_size_m`:
    /// grid points closer than this to the boundary are never streets, and a builder
    /// whose next step would come this close runs on to the boundary and joins it. The
    /// boundary thus acts as one more street for the report's side constraint. Must be in
    /// `[0.05, 0.95]`. Default: 0.5.
    pub boundary_clearance: f64,
    /// Carriageway width written on every street, metres. Must be finite and positive.
    /// Default: 10 m.
    pub street_width_m: f64,
    /// Legality sampling step along each street, metres: a street is refused where a
    /// sample falls in water or a park (map value ≥ 0.5, as in [`crate::RoadInputs`]).
    /// Must be finite and positive. Default: 5 m.
    pub legality_step_m: f64,
    /// The largest grid (points over the cell's bounding box) a cell may need: a guard
    /// against a tiny `grid_size_m` on a huge cell exhausting memory. A performance knob
    /// only: within the limit the roads do not depend on it. Default: 4,000,000.
    pub max_lattice_points: u64,
}

impl Default for GridParams {
    fn default() -> Self {
        GridParams::downtown()
    }
}

impl GridParams {
    /// The report's Downtown area: Downtown rules, 25 m grid, 12 m streets.
    pub fn downtown() -> GridParams {
        GridParams {
            rules: GridRules::downtown(),
            grid_size_m: 25.0,
            orientation_deg: None,
            starts: 4,
            boundary_clearance: 0.5,
            street_width_m: 12.0,
            legality_step_m: 5.0,
            max_lattice_points: 4_000_000,
        }
    }

    /// The report's Residential area: Residential rules on the same 25 m grid, 8 m
    /// streets.
    pub fn residential() -> GridParams {
        GridParams {
            rules: GridRules::residential(),
            street_width_m: 8.0,
            ..GridParams::downtown()
        }
    }

    /// Checks every field and the rules.
    ///
    /// # Errors
    /// [`GridError::InvalidParameter`] naming the field, or the rules' errors
    /// ([`GridRules::validate`]).
    pub fn validate(&self) -> Result<()> {
        fn positive(name: &'static str, v: f64) -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(GridError::InvalidParameter {
                    name,
                    reason: format!("{v}; use a finite number greater than 0"),
                })
            }
        }
        positive("grid_size_m", self.grid_size_m)?;
        positive("street_width_m", self.street_width_m)?;
        positive("legality_step_m", self.legality_step_m)?;
        if let Some(a) = self.orientation_deg
            && !a.is_finite()
        {
            return Err(GridError::InvalidParameter {
                name: "orientation_deg",
                reason: format!("{a}; use a finite angle in degrees, or null to follow the cell"),
            });
        }
        if self.starts == 0 {
            return Err(GridError::InvalidParameter {
                name: "starts",
                reason: "0; at least one builder must start".into(),
            });
        }
        if !(0.05..=0.95).contains(&self.boundary_clearance) {
            return Err(GridError::InvalidParameter {
                name: "boundary_clearance",
                reason: format!(
                    "{}; use a fraction of the grid size between 0.05 and 0.95",
                    self.boundary_clearance
                ),
            });
        }
        if self.max_lattice_points == 0 {
            return Err(GridError::InvalidParameter {
                name: "max_lattice_points",
                reason: "0; use a positive limit".into(),
            });
        }
        self.rules.validate()
    }
}
