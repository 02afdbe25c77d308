//! [`RoadParams`]: every knob of the generator, with units and defaults.

use std::collections::BTreeMap;

use polis_geom::{Aabb2, DVec2};
use serde::{Deserialize, Serialize};

use crate::error::{Result, RoadError};
use crate::street_rules::StreetRules;

/// The road patterns of Parish & Müller (§3.2.2, Table 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Pattern {
    /// No superimposed pattern: highways follow population, streets run straight on with
    /// a small random deviation and branch at about 90°.
    Basic,
    /// Rectangular raster at [`RoadParams::grid_angle_deg`] (or a local angle map), with
    /// blocks of [`RoadParams::block_length_m`] × [`RoadParams::block_width_m`].
    NewYork,
    /// Radial and concentric roads around [`RoadParams::paris_centre`] (or the population
    /// peak).
    Paris,
    /// Roads follow the least elevation change; short connectors climb the gradient.
    SanFrancisco,
}

/// All parameters of the Parish & Müller road generator. Lengths in metres, angles in
/// degrees, densities in the population map's units (the default map is in `[0, 1]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RoadParams {
    /// Seed of the L-system's stochastic choices (branching). Default: 1.
    pub seed: u64,
    /// Lower-left corner of the map (metres); roads never leave the map. Default: (-2000, -2000).
    pub bounds_min: [f64; 2],
    /// Upper-right corner of the map (metres). Default: (2000, 2000).
    pub bounds_max: [f64; 2],
    /// Where the two initial highway segments start; `None` = the most populated legal
    /// point of a 64 × 64 sample of the map. Default: None.
    pub start: Option<[f64; 2]>,
    /// Direction of the first highway segment (the second goes the opposite way), degrees
    /// counter-clockwise from +x; `None` = the best ray of the population search. Default: None.
    pub start_angle_deg: Option<f64>,
    /// The pattern used where no pattern-weight map is given (see
    /// [`RoadInputs::pattern_weights`](crate::RoadInputs::pattern_weights)). Default: Basic.
    pub pattern: Pattern,
    /// Length of a highway segment. Default: 240 m.
    pub highway_length_m: f64,
    /// Length of a street segment (Basic, Paris, San Francisco). Default: 90 m.
    pub street_length_m: f64,
    /// Highway width. Default: 16 m.
    pub highway_width_m: f64,
    /// Street width. Default: 8 m.
    pub street_width_m: f64,
    /// Highway rays are shot within ± this angle of the current direction (§3.2.1, Fig. 4). Default: 30°.
    pub highway_max_turn_deg: f64,
    /// Number of highway rays (odd: one straight ahead). Default: 9.
    pub highway_rays: u32,
    /// Length of a highway ray. Default: 900 m.
    pub highway_ray_length_m: f64,
    /// Population samples per ray (weighted by inverse distance). Default: 6.
    pub highway_ray_samples: u32,
    /// Probability that a highway branches into another highway at a segment end (each
    /// side), where the population is above [`Self::population_threshold`]. Default: 0.06.
    pub highway_branch_probability: f64,
    /// Probability that a street branch is created on each side of a segment end where
    /// the population exceeds the threshold. Default: 0.9.
    pub street_branch_probability: f64,
    /// Random deviation of Basic streets from straight, ± degrees. Default: 5°.
    pub street_deviation_deg: f64,
    /// The street rules of each pattern (branching, crossroads or T, culs-de-sac, curved
    /// links, length spread; see [`StreetRules`]); in JSON an object keyed by pattern
    /// name. A pattern without an entry branches on each side independently with
    /// [`Self::street_branch_probability`] ([`StreetRules::per_side`]), one segment per
    /// link. Default: empty.
    pub streets: BTreeMap<Pattern, StreetRules>,
    /// A highway turns at most this far, in total, from the direction it started in
    /// (degrees), so highways run from population centre to population centre and on to
    /// the map edge instead of coiling around a peak; 180° sets no bound (the highways of
    /// Kelly's Citygen mode may loop to close primary cells). Default: 180°.
    pub highway_max_total_turn_deg: f64,
    /// Delay, in derivation steps, before a branch grows. Default: 1.
    pub branch_delay: i32,
    /// Extra delay of streets branching from highways (the slides' blue segments), so
    /// highways are not cut off by streets. Default: 5.
    pub highway_street_delay: i32,
    /// Streets branch only where the population is above this. Default: 0.1.
    pub population_threshold: f64,
    /// Streets stop growing where the population is below this. Default: 0.04.
    pub street_min_population: f64,
    /// New York: global grid angle (degrees) where no local angle map is given. Default: 0°.
    pub grid_angle_deg: f64,
    /// New York: block length (along the grid angle). Default: 160 m.
    pub block_length_m: f64,
    /// New York: block width (across the grid angle). Default: 80 m.
    pub block_width_m: f64,
    /// Paris: centre of the radial pattern; `None` = the population peak. Default: None.
    pub paris_centre: Option<[f64; 2]>,
    /// San Francisco: length of the steep connectors along the gradient. Default: 50 m.
    pub sf_connector_length_m: f64,
    /// Largest slope (rise over run) a road may climb. Default: 0.35.
    pub max_slope: f64,
    /// A segment ending in an illegal area may be shortened by up to this fraction of its
    /// length (0–1). Default: 0.5.
    pub max_prune_factor: f64,
    /// A segment may be rotated by up to this angle to stay legal. Default: 30°.
    pub max_rotate_deg: f64,
    /// Angular step of the rotation search. Default: 5°.
    pub rotate_step_deg: f64,
    /// Highways may cross water with segments (flagged `bridge`) up to this long. Default: 400 m.
    pub max_bridge_length_m: f64,
    /// Highways may pass under illegal land (a park, a slope over [`max_slope`](Self::max_slope))
    /// with segments (flagged `tunnel`) up to this long, where no rotation keeps them on
    /// legal ground (§3.3: "two tunnel entrances"); longer crossings are refused. 0 turns
    /// tunnels off. Default: 300 m.
    pub max_tunnel_length_m: f64,
    /// Highways cross water in tunnels (within [`max_tunnel_length_m`](Self::max_tunnel_length_m))
    /// instead of bridges: for a preset whose city tunnels under its river (§3.3 leaves
    /// the choice to the geometry stage). Default: false (bridges).
    pub tunnel_under_water: bool,
    /// Snap radius of the self-sensitive constraints (Kelly's snap size): a segment end
    /// this close to a junction or road is extended to it. Default: 30 m.
    pub snap_radius_m: f64,
    /// Smallest angle between two roads at a junction. Default: 30°.
    pub min_angle_deg: f64,
    /// Shortest segment accepted after pruning or snapping. Default: 12 m.
    pub min_segment_length_m: f64,
    /// Spacing of legality samples (water, parks, map edge) along a segment. Default: 5 m.
    pub legality_step_m: f64,
    /// Baseline over which the slope (grade) is measured along a segment. Default: 20 m.
    pub slope_step_m: f64,
    /// Stop after this many accepted segments; at least 1. Default: 4000.
    pub max_segments: usize,
    /// Stop after this many derivation steps; at least 1. Default: 1000.
    pub max_steps: usize,
    /// Smooth highway corners by corner cutting after growth (end of §3.3.1). Default: false.
    pub smooth_highways: bool,
    /// Rounds of highway corner cutting. Default: 2.
    pub smoothing_rounds: u32,
    /// Population feedback (§3.2.1, [`crate::feedback`]): the density each accepted
    /// street end uses up at its own point, falling off to zero at
    /// [`Self::feedback_radius_m`]; 0 turns the feedback off. Finite, ≥ 0. Default: 0.
    pub population_feedback: f64,
    /// Radius of the area a street end uses population from, metres (about a block).
    /// Finite, > 0. Default: 120.
    pub feedback_radius_m: f64,
}

impl Default for RoadParams {
    fn default() -> Self {
        RoadParams {
            seed: 1,
            bounds_min: [-2000.0, -2000.0],
            bounds_max: [2000.0, 2000.0],
            start: None,
            start_angle_deg: None,
            pattern: Pattern::Basic,
            highway_length_m: 240.0,
            street_length_m: 90.0,
            highway_width_m: 16.0,
            street_width_m: 8.0,
            highway_max_turn_deg: 30.0,
            highway_rays: 9,
            highway_ray_length_m: 900.0,
            highway_ray_samples: 6,
            highway_branch_probability: 0.06,
            street_branch_probability: 0.9,
            street_deviation_deg: 5.0,
            streets: BTreeMap::new(),
            highway_max_total_turn_deg: 180.0,
            branch_delay: 1,
            highway_street_delay: 5,
            population_threshold: 0.1,
            street_min_population: 0.04,
            grid_angle_deg: 0.0,
            block_length_m: 160.0,
            block_width_m: 80.0,
            paris_centre: None,
            sf_connector_length_m: 50.0,
            max_slope: 0.35,
            max_prune_factor: 0.5,
            max_rotate_deg: 30.0,
            rotate_step_deg: 5.0,
            max_bridge_length_m: 400.0,
            max_tunnel_length_m: 300.0,
            tunnel_under_water: false,
            snap_radius_m: 30.0,
            min_angle_deg: 30.0,
            min_segment_length_m: 12.0,
            legality_step_m: 5.0,
            slope_step_m: 20.0,
            max_segments: 4000,
            max_steps: 1000,
            smooth_highways: false,
            smoothing_rounds: 2,
            population_feedback: 0.0,
            feedback_radius_m: 120.0,
        }
    }
}

fn check(name: &'static str, ok: bool, value: f64, want: &str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(RoadError::InvalidParameter {
            name,
            reason: format!("{value} is out of range; use {want}"),
        })
    }
}

impl RoadParams {
    /// The street rules of `pattern`: its entry in [`Self::streets`], else independent
    /// branching on each side with [`Self::street_branch_probability`].
    pub fn street_rules(&self, pattern: Pattern) -> StreetRules {
        self.streets
            .get(&pattern)
            .copied()
            .unwrap_or_else(|| StreetRules::per_side(self.street_branch_probability))
    }

    /// The map as a box.
    pub fn bounds(&self) -> Aabb2 {
        Aabb2::new(
            DVec2::from_array(self.bounds_min),
            DVec2::from_array(self.bounds_max),
        )
    }

    /// Checks every field against its documented range.
    ///
    /// # Errors
    /// [`RoadError::InvalidParameter`] naming the first bad field.
    pub fn validate(&self) -> Result<()> {
        let lim = polis_geom::MAX_COORDINATE / 4.0;
        for (name, v) in [
            ("bounds_min", self.bounds_min),
            ("bounds_max", self.bounds_max),
        ] {
            for c in v {
                check(
                    name,
                    c.is_finite() && c.abs() <= lim,
                    c,
                    "finite metres within 2.5e7",
                )?;
            }
        }
        for i in 0..2 {
            let w = self.bounds_max[i] - self.bounds_min[i];
            check(
                "bounds_max",
                w > 1.0,
                w,
                "a map at least 1 m wide above bounds_min",
            )?;
        }
        if let Some(s) = self.start {
            for c in s {
                check("start", c.is_finite(), c, "finite metres")?;
            }
        }
        if let Some(c) = self.paris_centre {
            for c in c {
                check("paris_centre", c.is_finite(), c, "finite metres")?;
            }
        }
        if let Some(a) = self.start_angle_deg {
            check("start_angle_deg", a.is_finite(), a, "finite degrees")?;
        }
        let pos = |name, v: f64| check(name, v.is_finite() && v > 0.0, v, "a positive length");
        pos("highway_length_m", self.highway_length_m)?;
        pos("street_length_m", self.street_length_m)?;
        pos("block_length_m", self.block_length_m)?;
        pos("block_width_m", self.block_width_m)?;
        pos("sf_connector_length_m", self.sf_connector_length_m)?;
        pos("highway_ray_length_m", self.highway_ray_length_m)?;
        pos("legality_step_m", self.legality_step_m)?;
        pos("slope_step_m", self.slope_step_m)?;
        pos("rotate_step_deg", self.rotate_step_deg)?;
        let nonneg = |name, v: f64| check(name, v.is_finite() && v >= 0.0, v, "a finite value ≥ 0");
        nonneg("highway_width_m", self.highway_width_m)?;
        nonneg("street_width_m", self.street_width_m)?;
        nonneg("max_slope", self.max_slope)?;
        nonneg("max_bridge_length_m", self.max_bridge_length_m)?;
        nonneg("max_tunnel_length_m", self.max_tunnel_length_m)?;
        nonneg("snap_radius_m", self.snap_radius_m)?;
        nonneg("min_segment_length_m", self.min_segment_length_m)?;
        nonneg("street_deviation_deg", self.street_deviation_deg)?;
        let deg = |name, v: f64, hi: f64| {
            check(
                name,
                v.is_finite() && (0.0..=hi).contains(&v),
                v,
                "degrees in range",
            )
        };
        deg("highway_max_turn_deg", self.highway_max_turn_deg, 180.0)?;
        deg(
            "highway_max_total_turn_deg",
            self.highway_max_total_turn_deg,
            180.0,
        )?;
        for rules in self.streets.values() {
            rules.validate()?;
        }
        deg("max_rotate_deg", self.max_rotate_deg, 180.0)?;
        deg("min_angle_deg", self.min_angle_deg, 89.0)?;
        check(
            "grid_angle_deg",
            self.grid_angle_deg.is_finite(),
            self.grid_angle_deg,
            "finite degrees",
        )?;
        let unit = |name, v: f64| check(name, (0.0..=1.0).contains(&v), v, "a value in [0, 1]");
        unit(
            "highway_branch_probability",
            self.highway_branch_probability,
        )?;
        unit("street_branch_probability", self.street_branch_probability)?;
        check(
            "population_feedback",
            self.population_feedback.is_finite() && self.population_feedback >= 0.0,
            self.population_feedback,
            "a finite density ≥ 0",
        )?;
        check(
            "feedback_radius_m",
            self.feedback_radius_m.is_finite() && self.feedback_radius_m > 0.0,
            self.feedback_radius_m,
            "finite metres > 0",
        )?;
        unit("max_prune_factor", self.max_prune_factor)?;
        check(
            "population_threshold",
            self.population_threshold.is_finite(),
            self.population_threshold,
            "a finite density",
        )?;
        check(
            "street_min_population",
            self.street_min_population.is_finite(),
            self.street_min_population,
            "a finite density",
        )?;
        check(
            "highway_rays",
            (1..=360).contains(&self.highway_rays),
            f64::from(self.highway_rays),
            "1 to 360 rays",
        )?;
        check(
            "highway_ray_samples",
            (1..=256).contains(&self.highway_ray_samples),
            f64::from(self.highway_ray_samples),
            "1 to 256 samples",
        )?;
        check(
            "branch_delay",
            self.branch_delay >= 0,
            f64::from(self.branch_delay),
            "a delay ≥ 0",
        )?;
        check(
            "highway_street_delay",
            self.highway_street_delay >= 0,
            f64::from(self.highway_street_delay),
            "a delay ≥ 0",
        )?;
        check(
            "smoothing_rounds",
            self.smoothing_rounds <= 8,
            f64::from(self.smoothing_rounds),
            "0 to 8 rounds",
        )?;
        check(
            "max_segments",
            self.max_segments >= 1,
            self.max_segments as f64,
            "at least 1 segment (0 can only give an empty city)",
        )?;
        check(
            "max_steps",
            self.max_steps >= 1,
            self.max_steps as f64,
            "at least 1 derivation step (0 can only give an empty city)",
        )?;
        // Keep legality sampling bounded: at most ~10^5 samples per segment.
        let longest = self
            .highway_length_m
            .max(self.street_length_m)
            .max(self.block_length_m)
            .max(self.max_bridge_length_m)
            .max(self.max_tunnel_length_m)
            + self.snap_radius_m;
        check(
            "legality_step_m",
            longest / self.legality_step_m <= 1.0e5,
            self.legality_step_m,
            "a step no smaller than 1e-5 of the longest segment",
        )?;
        Ok(())
    }
}
