//! The stage's options: building types, footprint strategies, height distributions.

/// The building types of Parish & Müller §4.2 (commercial, residential, industrial), with
/// skyscrapers and the commercial and residential sub-types of the issue.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BuildingKind {
    /// Downtown tower with setbacks, crown and antenna or spire.
    Skyscraper,
    /// Office building: a tall slab with a podium.
    Office,
    /// Commercial mid-rise block with a flat or mansard roof.
    MidRise,
    /// Detached house with a gable, hip or pyramid roof.
    House,
    /// Residential apartment block.
    Apartment,
    /// Industrial shed or warehouse.
    Industrial,
}

impl BuildingKind {
    /// All kinds, in a fixed order.
    pub const ALL: [BuildingKind; 6] = [
        BuildingKind::Skyscraper,
        BuildingKind::Office,
        BuildingKind::MidRise,
        BuildingKind::House,
        BuildingKind::Apartment,
        BuildingKind::Industrial,
    ];

    /// A lower-case name (`"skyscraper"`, `"mid_rise"` …).
    pub fn name(self) -> &'static str {
        match self {
            BuildingKind::Skyscraper => "skyscraper",
            BuildingKind::Office => "office",
            BuildingKind::MidRise => "mid_rise",
            BuildingKind::House => "house",
            BuildingKind::Apartment => "apartment",
            BuildingKind::Industrial => "industrial",
        }
    }

    /// Index in [`ALL`](Self::ALL).
    pub fn index(self) -> usize {
        self as usize
    }

    /// Kelly's footprint strategy for this kind (§4.4.3.1): downtown kinds fill the lot,
    /// houses and apartments retreat from the street (houses fit a rectangle), industrial
    /// buildings retreat from every side.
    pub fn footprint_strategy(self) -> FootprintStrategy {
        match self {
            BuildingKind::Skyscraper | BuildingKind::Office | BuildingKind::MidRise => {
                FootprintStrategy::Downtown
            }
            BuildingKind::House => FootprintStrategy::SuburbanRectangle,
            BuildingKind::Apartment => FootprintStrategy::Suburban,
            BuildingKind::Industrial => FootprintStrategy::Industrial,
        }
    }
}

/// How a footprint is cut from its lot (Kelly 2008 §4.4.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum FootprintStrategy {
    /// Zero inset: the whole lot (down-town).
    Downtown,
    /// Weighted inset: street edges retreat by [`FootprintParams::street_setback`], the
    /// others by [`FootprintParams::side_setback`].
    Suburban,
    /// [`Suburban`](Self::Suburban) followed by the largest rectangle inscribed in the
    /// inset region with sides along and across the primary street edge (houses; see
    /// [`largest_rectangle`](crate::footprint::largest_rectangle)).
    SuburbanRectangle,
    /// Uniform inset by [`FootprintParams::industrial_setback`].
    Industrial,
}

/// Footprint options (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct FootprintParams {
    /// Setback from street edges for suburban kinds, m. Default: 5.
    pub street_setback: f64,
    /// Setback from the other (side and rear) edges for suburban kinds, m. Default: 2.
    pub side_setback: f64,
    /// Setback on every side for industrial kinds, m. Default: 3.
    pub industrial_setback: f64,
    /// Footprints smaller than this are not built, m². Default: 20.
    pub min_area: f64,
}

impl Default for FootprintParams {
    fn default() -> Self {
        Self {
            street_setback: 5.0,
            side_setback: 2.0,
            industrial_setback: 3.0,
            min_area: 20.0,
        }
    }
}

/// The distribution building heights are drawn from (Kelly §4.4.3.2 and §7.4).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum HeightDistribution {
    /// Kelly's building height ± deviance: uniform in `[m·(1 − d), m·(1 + d)]` with `m`
    /// the kind's median height.
    Uniform {
        /// Relative deviance, 0–1.
        deviance: f64,
    },
    /// Normal with mean `m` and standard deviation `sigma · m`.
    Normal {
        /// Relative standard deviation.
        sigma: f64,
    },
    /// Log-normal with a median that falls off from the city centre: the median is
    /// `m · (1 + centre_boost · exp(−(r / falloff)²))` at distance `r` from `centre`, and
    /// `ln h` has standard deviation `sigma` (a realistic skyline: a dense core of towers
    /// and a long tail).
    LogNormal {
        /// Standard deviation of `ln h`.
        sigma: f64,
        /// The city centre, layout metres.
        centre: [f64; 2],
        /// Extra median factor at the centre.
        centre_boost: f64,
        /// Distance over which the boost falls off, m.
        falloff: f64,
    },
}

impl Default for HeightDistribution {
    fn default() -> Self {
        HeightDistribution::Uniform { deviance: 0.25 }
    }
}

/// The building stage's options: one struct, serde, with units.
///
/// *What* (style) only: there is no performance knob that could change the city.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct BuildingParams {
    /// City seed; each building draws from a generator seeded by (seed, lot id).
    /// Default: 0.
    pub seed: u64,
    /// Median height of each kind, metres, in [`BuildingKind::ALL`] order.
    /// Default: skyscraper 120, office 45, mid-rise 20, house 8, apartment 15,
    /// industrial 9.
    pub median_height: [f64; 6],
    /// Storey height, metres (ground floor is `ground_floor_height`). Default: 3.2.
    pub floor_height: f64,
    /// Ground-floor storey height, metres. Default: 4.5.
    pub ground_floor_height: f64,
    /// Height distribution. Default: uniform ± 25 %.
    pub distribution: HeightDistribution,
    /// Footprint options. Default: [`FootprintParams::default`].
    pub footprint: FootprintParams,
    /// Derivation steps for the full-detail building (the highest LOD). Default: 6.
    pub max_lod: usize,
    /// Roof pitch for pitched roofs when the grammar does not give one, degrees.
    /// Default: 35.
    pub roof_pitch_deg: f64,
}

impl Default for BuildingParams {
    fn default() -> Self {
        Self {
            seed: 0,
            median_height: [120.0, 45.0, 20.0, 8.0, 15.0, 9.0],
            floor_height: 3.2,
            ground_floor_height: 4.5,
            distribution: HeightDistribution::default(),
            footprint: FootprintParams::default(),
            max_lod: 6,
            roof_pitch_deg: 35.0,
        }
    }
}

impl BuildingParams {
    /// Checks ranges; returns what is wrong.
    pub fn validate(&self) -> Result<(), crate::BuildingsError> {
        let bad = |name: &'static str, reason: String| {
            Err(crate::BuildingsError::InvalidParameter { name, reason })
        };
        if self
            .median_height
            .iter()
            .any(|h| !(h.is_finite() && *h > 0.0))
        {
            return bad(
                "median_height",
                "every median height must be finite and > 0 m".into(),
            );
        }
        if !(self.floor_height.is_finite() && self.floor_height > 0.5) {
            return bad(
                "floor_height",
                format!("{} m; give a storey height above 0.5 m", self.floor_height),
            );
        }
        if !(self.ground_floor_height.is_finite() && self.ground_floor_height > 0.5) {
            return bad(
                "ground_floor_height",
                format!(
                    "{} m; give a storey height above 0.5 m",
                    self.ground_floor_height
                ),
            );
        }
        let f = &self.footprint;
        for (name, v) in [
            ("footprint.street_setback", f.street_setback),
            ("footprint.side_setback", f.side_setback),
            ("footprint.industrial_setback", f.industrial_setback),
            ("footprint.min_area", f.min_area),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(
                    "footprint",
                    format!("{name} is {v}; it must be finite and ≥ 0"),
                );
            }
        }
        if f.street_setback == 0.0 && f.side_setback > 0.0
            || f.side_setback == 0.0 && f.street_setback > 0.0
        {
            return bad("footprint", "street_setback and side_setback must both be > 0 or both 0 (weighted skeleton weights must be positive)".into());
        }
        if self.max_lod > 64 {
            return bad(
                "max_lod",
                format!("{}; at most 64 derivation steps", self.max_lod),
            );
        }
        if !(self.roof_pitch_deg > 0.0 && self.roof_pitch_deg < 89.0) {
            return bad(
                "roof_pitch_deg",
                format!("{}°; give a pitch in (0, 89)", self.roof_pitch_deg),
            );
        }
        let ok = match self.distribution {
            HeightDistribution::Uniform { deviance } => (0.0..1.0).contains(&deviance),
            HeightDistribution::Normal { sigma } => sigma.is_finite() && sigma >= 0.0,
            HeightDistribution::LogNormal {
                sigma,
                centre,
                centre_boost,
                falloff,
            } => {
                sigma.is_finite()
                    && sigma >= 0.0
                    && centre.iter().all(|c| c.is_finite())
                    && centre_boost.is_finite()
                    && centre_boost >= 0.0
                    && falloff.is_finite()
                    && falloff > 0.0
            }
        };
        if !ok {
            return bad(
                "distribution",
                format!(
                    "{:?}: deviance in [0, 1), sigma ≥ 0, centre finite, boost ≥ 0, falloff > 0",
                    self.distribution
                ),
            );
        }
        Ok(())
    }
}
