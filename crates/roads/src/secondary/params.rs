//! The control parameters of one cell (Kelly §4.3.2, §5.5.1, Fig. 76) and their
//! deviances.

use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

use super::error::SecondaryError;

/// A control parameter and its deviance (Kelly §4.3.2: "a deviance parameter partners
/// each control parameter"): each use draws `value · (1 + u)`, `u` uniform in
/// `[−deviance, +deviance]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Deviated {
    /// The mean value (unit of the field that holds it).
    pub value: f64,
    /// Relative deviance: `0.2` is Kelly's "± 20 %". Must lie in `[0, 1]`.
    #[serde(default)]
    pub deviance: f64,
}

impl Deviated {
    /// `value` with no deviance.
    pub const fn exact(value: f64) -> Self {
        Deviated {
            value,
            deviance: 0.0,
        }
    }

    /// `value ± deviance` (relative).
    pub const fn new(value: f64, deviance: f64) -> Self {
        Deviated { value, deviance }
    }

    /// One draw: `value · (1 + u)`, `u` uniform in `[−deviance, deviance]`. Draws exactly
    /// one number from `rng` (also when the deviance is 0, so that changing a deviance
    /// does not shift the other parameters' draws).
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> f64 {
        let u: f64 = rng.random::<f64>();
        self.value * (1.0 + self.deviance * (2.0 * u - 1.0))
    }

    /// The value scaled by `k` (deviance unchanged): converts Citygen units to metres.
    pub fn scaled(&self, k: f64) -> Deviated {
        Deviated {
            value: self.value * k,
            deviance: self.deviance,
        }
    }

    fn check(
        &self,
        name: &'static str,
        min: f64,
        min_inclusive: bool,
    ) -> Result<(), SecondaryError> {
        let v = self.value;
        let ok = v.is_finite() && if min_inclusive { v >= min } else { v > min };
        if !ok {
            let bound = if min_inclusive { "≥" } else { ">" };
            return Err(SecondaryError::InvalidParameter {
                name,
                reason: format!("value {v}; give a finite value {bound} {min}"),
            });
        }
        check_deviance(name, self.deviance)
    }
}

fn check_deviance(name: &'static str, d: f64) -> Result<(), SecondaryError> {
    if d.is_finite() && (0.0..=1.0).contains(&d) {
        Ok(())
    } else {
        Err(SecondaryError::InvalidParameter {
            name,
            reason: format!("deviance {d}; give a relative deviance in [0, 1] (1 = ± 100 %)"),
        })
    }
}

/// What kind of building a cell asks for (Kelly's *Building Hint*, §5.5.1). The
/// building stage maps it to its own building kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum BuildingHint {
    /// Towers on small, deep lots.
    Skyscraper,
    /// Office blocks.
    Office,
    /// Mid-rise city blocks (the Manhattan cell).
    MidRise,
    /// Apartment buildings.
    Apartment,
    /// Detached houses (the Suburbia cell).
    House,
    /// Sheds and warehouses (the Industrial cell).
    Industrial,
}

/// The control parameters of one city cell, in metres (Kelly §4.3.2, §5.5.1, §6.3).
///
/// The road-growth parameters are Kelly's five with their deviances (segment size,
/// degree, snap size, road width, connectivity) plus the aspect of §6.3; lot size and
/// building height/deviance/hint are kept per cell as Citygen does and handed on to the
/// lot and building stages. Kelly's presets are in [`Neighbourhood`](super::Neighbourhood),
/// given in Citygen units and converted with [`CITYGEN_UNIT_M`](super::CITYGEN_UNIT_M).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SecondaryParams {
    /// Length of each proposed segment, metres (*Segment Size*): small values give tightly
    /// packed streets. Default: 100 ± 20 % (Manhattan).
    pub segment_size_m: Deviated,
    /// Block aspect (Kelly §6.3): segments along the cell's main axis (its longest
    /// boundary side) are `aspect` times as long as segments across it; in between, the
    /// length follows the ellipse with these two half-axes. Must be finite and in
    /// `[0.1, 10]`. Default: 1.
    pub aspect: f64,
    /// Branches tried at each node (*Degree*): direction `i` is the incoming direction
    /// turned by `i · 360° / degree`. Must be 1 to 64. Default: 4.
    pub degree: u32,
    /// Deviance of the degree: the number of branches of each node is
    /// `round(degree · (1 ± deviance))` (at least 1), and each branch direction turns by
    /// up to `± deviance` of half the angle between branches (Kelly §6.3: a high degree
    /// deviance "enables the road growth to meander"). In `[0, 1]`. Default: 0.01.
    pub degree_deviance: f64,
    /// Snap distance, metres (*Snap Size*): proposals ending or passing this close to a
    /// road or junction join it. Must be ≥ 0. Default: 48 ± 10 %.
    pub snap_size_m: Deviated,
    /// Carriageway width of the secondary roads, metres (*Road Width*). Must be > 0.
    /// Default: 9 (Manhattan).
    pub road_width_m: Deviated,
    /// Probability that the growth from a node joins an existing road or junction it
    /// meets (*Connectivity*); otherwise the proposal is dropped and the road stops short
    /// of it (a node left with no other branch is a cul-de-sac). Drawn once per expanded
    /// node and road or junction met, not once per direction: with degree 18 a node
    /// aims several directions at the same neighbour, and separate draws would multiply
    /// its chance to connect. Drawn values are clamped to `[0, 1]`. Value in `[0, 1]`.
    /// Default: 1.
    pub connectivity: Deviated,
    /// The smallest angle a new road may make with another road at either of its ends,
    /// degrees (ours, not Kelly's: his snap joins whatever node or road is in the snap
    /// area). Kelly's node snap gathers the ends of neighbouring proposals onto one node,
    /// so with a snap size near half the segment size many junctions get five or more
    /// arms meeting at acute angles (16 % of the junctions of an `organic` city; real
    /// networks have a few per cent, Boeing 2019). A proposal that would meet a road at
    /// a sharper angle, at its root or where it joins, is dropped. Above 72° no junction
    /// can get a fifth arm. Must be in `[0, 90]`. Default: 0 (no test, Kelly).
    pub min_angle_deg: f64,
    /// How far each street bows from the straight line between its ends, as a fraction
    /// of that distance (the sagitta of a half-sine bend; ours, not Kelly's: his growth
    /// places straight segments), drawn per street with its deviance, to a random side.
    /// Bows street edges after the growth, where they stay clear of the other roads and
    /// the maps (see [`bend`](super::bend)); lengthens a street by about `2 bow²` to
    /// `π² bow² / 4` (0.1: 2–2.5 %). Value in `[0, 0.5]`. Default: 0 (straight streets,
    /// Kelly).
    pub bow: Deviated,
    /// Lot width, metres (*Lot Size* and *Lot Deviance*), for the lot stage. Must be > 0.
    /// Default: 14 ± 40 %.
    pub lot_size_m: Deviated,
    /// Building height, metres (*Building Height* and *Building Deviance*), for the
    /// building stage. Must be > 0. Default: 34 ± 70 %.
    pub building_height_m: Deviated,
    /// What kind of building the cell asks for (*Building Hint*). Default: MidRise.
    pub building_hint: BuildingHint,
    /// How many of the longest boundary sides start a road (Kelly: "a selection of the
    /// longest cell boundary sides"). Must be ≥ 1. Default: 2.
    pub start_sides: u32,
    /// Growth steps (nodes taken from the queue); `None` grows until the queue is empty.
    /// Kelly's Fig. 43 shows 10, 100, 300 and 1000 steps. Default: None.
    pub max_steps: Option<u32>,
}

impl Default for SecondaryParams {
    fn default() -> Self {
        SecondaryParams {
            segment_size_m: Deviated::new(100.0, 0.2),
            aspect: 1.0,
            degree: 4,
            degree_deviance: 0.01,
            snap_size_m: Deviated::new(48.0, 0.1),
            road_width_m: Deviated::exact(9.0),
            connectivity: Deviated::exact(1.0),
            min_angle_deg: 0.0,
            bow: Deviated::exact(0.0),
            lot_size_m: Deviated::new(14.0, 0.4),
            building_height_m: Deviated::new(34.0, 0.7),
            building_hint: BuildingHint::MidRise,
            start_sides: 2,
            max_steps: None,
        }
    }
}

/// The largest `degree` accepted.
pub const MAX_DEGREE: u32 = 64;

impl SecondaryParams {
    /// Checks every field against its documented range.
    ///
    /// # Errors
    /// [`SecondaryError::InvalidParameter`] naming the field.
    pub fn validate(&self) -> Result<(), SecondaryError> {
        self.segment_size_m.check("segment_size_m", 0.0, false)?;
        if self.segment_size_m.value > 1.0e5 {
            return Err(SecondaryError::InvalidParameter {
                name: "segment_size_m",
                reason: format!("{} m; give at most 100 km", self.segment_size_m.value),
            });
        }
        if !(self.aspect.is_finite() && (0.1..=10.0).contains(&self.aspect)) {
            return Err(SecondaryError::InvalidParameter {
                name: "aspect",
                reason: format!("{}; give a block aspect in [0.1, 10]", self.aspect),
            });
        }
        if !(1..=MAX_DEGREE).contains(&self.degree) {
            return Err(SecondaryError::InvalidParameter {
                name: "degree",
                reason: format!("{}; give 1 to {MAX_DEGREE} branches per node", self.degree),
            });
        }
        check_deviance("degree_deviance", self.degree_deviance)?;
        self.snap_size_m.check("snap_size_m", 0.0, true)?;
        self.road_width_m.check("road_width_m", 0.0, false)?;
        self.connectivity.check("connectivity", 0.0, true)?;
        if self.connectivity.value > 1.0 {
            return Err(SecondaryError::InvalidParameter {
                name: "connectivity",
                reason: format!("{}; give a probability in [0, 1]", self.connectivity.value),
            });
        }
        if !(self.min_angle_deg.is_finite() && (0.0..=90.0).contains(&self.min_angle_deg)) {
            return Err(SecondaryError::InvalidParameter {
                name: "min_angle_deg",
                reason: format!("{}; give an angle in [0, 90] degrees", self.min_angle_deg),
            });
        }
        self.bow.check("bow", 0.0, true)?;
        if self.bow.value > 0.5 {
            return Err(SecondaryError::InvalidParameter {
                name: "bow",
                reason: format!(
                    "{}; give a fraction of the street in [0, 0.5]",
                    self.bow.value
                ),
            });
        }
        self.lot_size_m.check("lot_size_m", 0.0, false)?;
        self.building_height_m
            .check("building_height_m", 0.0, false)?;
        if self.start_sides == 0 {
            return Err(SecondaryError::InvalidParameter {
                name: "start_sides",
                reason: "0; give at least 1 starting side".into(),
            });
        }
        Ok(())
    }

    /// The longest a proposed segment can be, metres (segment size, deviance and aspect
    /// at their largest).
    pub fn max_segment_m(&self) -> f64 {
        self.segment_size_m.value * (1.0 + self.segment_size_m.deviance) * self.aspect.max(1.0)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn bad(f: impl FnOnce(&mut SecondaryParams)) -> &'static str {
        let mut p = SecondaryParams::default();
        f(&mut p);
        match p.validate() {
            Err(SecondaryError::InvalidParameter { name, .. }) => name,
            other => panic!("expected an error, got {other:?}"),
        }
    }

    #[test]
    fn bad_values_name_their_field() {
        SecondaryParams::default().validate().unwrap();
        assert_eq!(bad(|p| p.degree = 0), "degree");
        assert_eq!(bad(|p| p.segment_size_m.value = -1.0), "segment_size_m");
        assert_eq!(bad(|p| p.segment_size_m.value = f64::NAN), "segment_size_m");
        assert_eq!(bad(|p| p.snap_size_m.value = -0.5), "snap_size_m");
        assert_eq!(
            bad(|p| p.road_width_m.value = f64::INFINITY),
            "road_width_m"
        );
        assert_eq!(bad(|p| p.connectivity.value = 1.5), "connectivity");
        assert_eq!(bad(|p| p.connectivity.value = -0.1), "connectivity");
        assert_eq!(bad(|p| p.segment_size_m.deviance = 1.01), "segment_size_m");
        assert_eq!(bad(|p| p.degree_deviance = 2.0), "degree_deviance");
        assert_eq!(bad(|p| p.lot_size_m.deviance = f64::NAN), "lot_size_m");
        assert_eq!(bad(|p| p.aspect = 0.0), "aspect");
        assert_eq!(bad(|p| p.start_sides = 0), "start_sides");
        assert_eq!(bad(|p| p.min_angle_deg = 91.0), "min_angle_deg");
        assert_eq!(bad(|p| p.min_angle_deg = -1.0), "min_angle_deg");
        assert_eq!(bad(|p| p.bow.value = 0.6), "bow");
        assert_eq!(bad(|p| p.bow.value = -0.1), "bow");
        assert_eq!(bad(|p| p.bow.deviance = 1.5), "bow");
    }

    #[test]
    fn samples_stay_within_the_deviance() {
        use rand::SeedableRng;
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        let d = Deviated::new(10.0, 0.3);
        for _ in 0..1000 {
            let v = d.sample(&mut rng);
            assert!((7.0..=13.0).contains(&v), "{v}");
        }
        assert_eq!(Deviated::exact(4.0).sample(&mut rng), 4.0);
    }
}
