//! The knobs of adaptive roads (Kelly §4.2.2–4.2.3, §5.4.1), the road presets of §6.2
//! and the tolerances of validity checking (§5.3.2).

use serde::{Deserialize, Serialize};

use crate::primary::error::PrimaryError;

/// How a front picks its next plot point from the fan of samples (Kelly §4.2.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Strategy {
    /// Straight toward the other front; a legal sample nearest to that direction when the
    /// straight step is illegal.
    Straight,
    /// The lowest sample (§4.2.3.1): roads run like streams.
    MinimumElevation,
    /// The sample with the smallest elevation change from the current plot point
    /// (§4.2.3.2): flat roads, but a steep step where the fronts meet on a slope.
    MinimumElevationDifference,
    /// The sample whose elevation change per metre of progress is nearest to the grade
    /// still needed to reach the other front (§4.2.3.3):
    /// `min |Δh_step / d_progress − Δh_dest / d_dest|`.
    EvenElevationDifference,
}

/// Parameters of one adaptive road (Kelly §4.2.2, the road property inspector of §5.4.1).
///
/// Termination (§4.2.2) needs `deviation_deg < 45` and
/// `snap_m > sample_size_m · cos(deviation_deg)`: then every step brings a front closer
/// to the other by a fixed positive amount. [`AdaptiveParams::validate`] checks both.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AdaptiveParams {
    /// Sample selection strategy. Default: [`Strategy::EvenElevationDifference`].
    pub strategy: Strategy,
    /// `d_sample`: distance of each step, in metres (> 0). Default: 260 (primary road).
    pub sample_size_m: f64,
    /// `n_sample`: samples in each fan, 1 to 64. Default: 7.
    pub samples: u32,
    /// `θ_dev`: half-angle of the fan in degrees, in `[0, 45)`. Default: 25.
    pub deviation_deg: f64,
    /// `d_snap`: the fronts join when this close, in metres; must exceed
    /// `sample_size_m · cos(deviation_deg)`. Default: 260.
    pub snap_m: f64,
    /// Length of the low-level segments interpolated from the spline, in metres (> 0).
    /// Default: 10.
    pub segment_draw_size_m: f64,
    /// The longest bridge over water, in metres (≥ 0); longer crossings fail.
    /// Default: 400.
    pub max_bridge_m: f64,
}

impl Default for AdaptiveParams {
    fn default() -> Self {
        RoadPreset::Primary.params()
    }
}

/// The most steps a plot may take (a bound computed before plotting).
pub const MAX_PLOT_STEPS: usize = 100_000;

/// The most samples in a fan.
pub const MAX_SAMPLES: u32 = 64;

fn bad(name: &'static str, reason: String) -> PrimaryError {
    PrimaryError::InvalidParameter { name, reason }
}

impl AdaptiveParams {
    /// `θ_dev` in radians.
    pub fn deviation_rad(&self) -> f64 {
        self.deviation_deg.to_radians()
    }

    /// Checks every field, including Kelly's termination condition.
    ///
    /// # Errors
    /// [`PrimaryError::InvalidParameter`] naming the first bad field.
    pub fn validate(&self) -> Result<(), PrimaryError> {
        let d = self.sample_size_m;
        if !(d.is_finite() && d > 0.0 && d <= 1e6) {
            return Err(bad(
                "sample_size_m",
                format!("{d} m; use a length in (0, 1e6]"),
            ));
        }
        if !(1..=MAX_SAMPLES).contains(&self.samples) {
            return Err(bad(
                "samples",
                format!("{}; use 1 to {MAX_SAMPLES} samples per fan", self.samples),
            ));
        }
        let t = self.deviation_deg;
        if !(t.is_finite() && (0.0..45.0).contains(&t)) {
            return Err(bad(
                "deviation_deg",
                format!("{t}°; plotting terminates only for 0 ≤ θ_dev < 45°"),
            ));
        }
        let need = d * self.deviation_rad().cos();
        let s = self.snap_m;
        if !(s.is_finite() && s > need) {
            return Err(bad(
                "snap_m",
                format!(
                    "{s} m; plotting terminates only for d_snap > d_sample·cos θ_dev = {need:.3} m"
                ),
            ));
        }
        let g = self.segment_draw_size_m;
        if !(g.is_finite() && g >= 0.01) {
            return Err(bad(
                "segment_draw_size_m",
                format!("{g} m; use a length of at least 0.01 m"),
            ));
        }
        let b = self.max_bridge_m;
        if !(b.is_finite() && b >= 0.0) {
            return Err(bad("max_bridge_m", format!("{b} m; use a length ≥ 0")));
        }
        Ok(())
    }
}

/// The road kinds of Kelly §6.2, each with its sample size and deviation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum RoadPreset {
    /// Motorway: 640 m samples, 15° deviation (Fig. 83): long, gentle curves.
    Motorway,
    /// Primary road: 260 m samples, 25° deviation (Fig. 84): follows the terrain.
    Primary,
    /// Inner-city road: 90 m samples, 22° deviation (Fig. 85): meanders moderately.
    InnerCity,
}

impl RoadPreset {
    /// All presets, in declaration order.
    pub const ALL: [RoadPreset; 3] = [
        RoadPreset::Motorway,
        RoadPreset::Primary,
        RoadPreset::InnerCity,
    ];

    /// The preset's adaptive parameters: §6.2's sample size and deviation, 7 samples,
    /// `snap_m = sample_size_m` (which satisfies the termination condition for any
    /// deviation above 0), the even-elevation-difference strategy.
    pub fn params(self) -> AdaptiveParams {
        let (d, dev, draw, bridge) = match self {
            RoadPreset::Motorway => (640.0, 15.0, 20.0, 800.0),
            RoadPreset::Primary => (260.0, 25.0, 10.0, 400.0),
            RoadPreset::InnerCity => (90.0, 22.0, 5.0, 200.0),
        };
        AdaptiveParams {
            strategy: Strategy::EvenElevationDifference,
            sample_size_m: d,
            samples: 7,
            deviation_deg: dev,
            snap_m: d,
            segment_draw_size_m: draw,
            max_bridge_m: bridge,
        }
    }

    /// The preset's carriageway width in metres: 24 (motorway), 16, 10 (inner city).
    pub fn width_m(self) -> f64 {
        match self {
            RoadPreset::Motorway => 24.0,
            RoadPreset::Primary => 16.0,
            RoadPreset::InnerCity => 10.0,
        }
    }

    /// A [`RoadSpec`] of this class, width and parameters.
    pub fn spec(self) -> RoadSpec {
        RoadSpec {
            class: self,
            width_m: self.width_m(),
            params: self.params(),
        }
    }
}

/// What a primary road is: its class, width and adaptive parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RoadSpec {
    /// The road's class (one of §6.2's kinds).
    pub class: RoadPreset,
    /// Carriageway width in metres (> 0, ≤ 200).
    pub width_m: f64,
    /// How the road is plotted.
    pub params: AdaptiveParams,
}

impl Default for RoadSpec {
    fn default() -> Self {
        RoadPreset::Primary.spec()
    }
}

impl RoadSpec {
    /// Checks the width and the parameters.
    ///
    /// # Errors
    /// [`PrimaryError::InvalidParameter`] naming the bad field.
    pub fn validate(&self) -> Result<(), PrimaryError> {
        let w = self.width_m;
        if !(w.is_finite() && w > 0.0 && w <= 200.0) {
            return Err(bad("width_m", format!("{w} m; use a width in (0, 200]")));
        }
        self.params.validate()
    }
}

/// Tolerances of validity checking (Kelly §5.3.2). Keeps *how edits are corrected* apart
/// from *how roads are plotted* ([`AdaptiveParams`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EditOptions {
    /// A proposed point this close to a node snaps to it; this close to a road it becomes
    /// a junction on it (T-junction). Crossings this close to a node are refused.
    /// Metres, ≥ 0. Default: 12.
    pub snap_distance_m: f64,
    /// Smallest angle between two roads meeting at a node or crossing, in degrees,
    /// in `[0, 90]`. Default: 15.
    pub min_angle_deg: f64,
    /// Shortest road or road piece between junctions, in metres (> 0). Default: 1.
    pub min_road_length_m: f64,
}

impl Default for EditOptions {
    fn default() -> Self {
        EditOptions {
            snap_distance_m: 12.0,
            min_angle_deg: 15.0,
            min_road_length_m: 1.0,
        }
    }
}

impl EditOptions {
    /// Checks every field.
    ///
    /// # Errors
    /// [`PrimaryError::InvalidParameter`] naming the first bad field.
    pub fn validate(&self) -> Result<(), PrimaryError> {
        let s = self.snap_distance_m;
        if !(s.is_finite() && (0.0..=1e5).contains(&s)) {
            return Err(bad("snap_distance_m", format!("{s} m; use 0 to 1e5 m")));
        }
        let a = self.min_angle_deg;
        if !(a.is_finite() && (0.0..=90.0).contains(&a)) {
            return Err(bad("min_angle_deg", format!("{a}°; use 0 to 90°")));
        }
        let l = self.min_road_length_m;
        if !(l.is_finite() && l > 0.0 && l <= 1e5) {
            return Err(bad(
                "min_road_length_m",
                format!("{l} m; use a length in (0, 1e5]"),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_match_the_paper() {
        for p in RoadPreset::ALL {
            p.spec().validate().unwrap();
        }
        let m = RoadPreset::Motorway.params();
        assert_eq!((m.sample_size_m, m.deviation_deg), (640.0, 15.0));
        let p = RoadPreset::Primary.params();
        assert_eq!((p.sample_size_m, p.deviation_deg), (260.0, 25.0));
        let i = RoadPreset::InnerCity.params();
        assert_eq!((i.sample_size_m, i.deviation_deg), (90.0, 22.0));
        // Presets are serde data.
        let json = serde_json::to_string(&RoadPreset::Motorway.spec()).unwrap();
        let back: RoadSpec = serde_json::from_str(&json).unwrap();
        assert_eq!(back, RoadPreset::Motorway.spec());
    }

    #[test]
    fn termination_condition_is_enforced_by_name() {
        let mut p = AdaptiveParams {
            deviation_deg: 45.0,
            ..AdaptiveParams::default()
        };
        let name = |p: &AdaptiveParams| match p.validate() {
            Err(PrimaryError::InvalidParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(name(&p), "deviation_deg");
        p.deviation_deg = 20.0;
        p.snap_m = p.sample_size_m * 20f64.to_radians().cos();
        assert_eq!(name(&p), "snap_m");
        p.snap_m = f64::NAN;
        assert_eq!(name(&p), "snap_m");
        p.snap_m = p.sample_size_m;
        p.samples = 0;
        assert_eq!(name(&p), "samples");
        p.samples = 3;
        p.sample_size_m = -1.0;
        assert_eq!(name(&p), "sample_size_m");
        p.sample_size_m = 10.0;
        p.snap_m = 10.0;
        p.segment_draw_size_m = 0.0;
        assert_eq!(name(&p), "segment_draw_size_m");
        p.segment_draw_size_m = 1.0;
        p.max_bridge_m = f64::INFINITY;
        assert_eq!(name(&p), "max_bridge_m");
        p.max_bridge_m = 0.0;
        p.validate().unwrap();
        let e = EditOptions {
            min_angle_deg: 91.0,
            ..EditOptions::default()
        };
        assert!(matches!(
            e.validate(),
            Err(PrimaryError::InvalidParameter {
                name: "min_angle_deg",
                ..
            })
        ));
    }
}
