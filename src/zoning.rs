//! Mixed zones and lot-area height caps (Parish & Müller §2 and §4.1).
//!
//! * **Mixed zones.** P&M's zone maps mark residential, commercial *or mixed* zones. The
//!   zoning map ([`MapsConfig::zoning`](crate::MapsConfig::zoning)) indexes the building
//!   kinds by its rounded value (0 skyscraper … 5 industrial) and [`MIXED_ZONE`] (6)
//!   marks a mixed zone: there each lot draws its kind, commercial with probability
//!   [`MixedZone::commercial_share`], residential otherwise (a stable draw per lot id),
//!   so one block holds both.
//! * **Height by lot area.** "Regulations control the maximum height of a building
//!   through the ground area of the allotment and zoning plan" (§4.1): after the zoning
//!   bands and the maximum-height map set a lot's limit, [`AreaCap`]s lower it for small
//!   lots (the first cap whose `max_area_m2` the lot's area does not exceed applies).
//!
//! Bad input: a zoning map whose values reach beyond `[-0.5, 6.5)` (grey levels that
//! name no zone) is refused by [`CityConfig::validate`](crate::CityConfig::validate);
//! a non-finite value at a lot falls back to the bands. Caps are validated field by field.

use polis_buildings::BuildingKind;
use polis_geom::{DVec2, Field};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The zoning map value of a mixed (residential + commercial) zone.
pub const MIXED_ZONE: f64 = 6.0;

/// The highest zoning map value that names a zone (values round to 0 … 6).
pub const MAX_ZONE_VALUE: f64 = MIXED_ZONE + 0.5;

/// What a mixed zone builds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MixedZone {
    /// The residential kind. Default: apartment.
    pub residential: BuildingKind,
    /// The commercial kind. Default: office.
    pub commercial: BuildingKind,
    /// Share of the lots that are commercial, in [0, 1]. Default: 0.4.
    pub commercial_share: f64,
}

impl Default for MixedZone {
    fn default() -> Self {
        MixedZone {
            residential: BuildingKind::Apartment,
            commercial: BuildingKind::Office,
            commercial_share: 0.4,
        }
    }
}

/// A height cap by lot ground area (P&M §4.1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AreaCap {
    /// Lots up to this ground area, m² (finite, > 0)…
    pub max_area_m2: f64,
    /// …are built no taller than this, metres, in (0, [`MAX_BUILDING_HEIGHT_M`](crate::MAX_BUILDING_HEIGHT_M)].
    pub max_height_m: f64,
}

/// Checks the mixed zone and the caps.
///
/// # Errors
/// [`Error::Config`] naming the field.
pub(crate) fn validate(mixed: &MixedZone, caps: &[AreaCap]) -> Result<()> {
    if !(0.0..=1.0).contains(&mixed.commercial_share) {
        return Err(Error::config(
            "zoning.mixed.commercial_share",
            format!("{}; give a share in [0, 1]", mixed.commercial_share),
        ));
    }
    for (i, c) in caps.iter().enumerate() {
        let ok_area = c.max_area_m2.is_finite() && c.max_area_m2 > 0.0;
        let ok_h = c.max_height_m > 0.0 && c.max_height_m <= crate::MAX_BUILDING_HEIGHT_M;
        if !(ok_area && ok_h) {
            return Err(Error::config(
                format!("zoning.area_caps[{i}]"),
                format!(
                    "{} m², {} m; give an area > 0 and a height in (0, {}]",
                    c.max_area_m2,
                    c.max_height_m,
                    crate::MAX_BUILDING_HEIGHT_M
                ),
            ));
        }
    }
    Ok(())
}

/// Refuses a zoning map whose values `(lo, hi)` reach grey levels that name no zone.
///
/// # Errors
/// [`Error::Config`] on `maps.zoning`.
pub(crate) fn check_zone_map_range(lo: f64, hi: f64) -> Result<()> {
    if lo < -0.5 || hi >= MAX_ZONE_VALUE {
        return Err(Error::config(
            "maps.zoning",
            format!(
                "the map's values reach [{lo}, {hi}]; zone values round to 0 (skyscraper) … 5 \
                 (industrial) or 6 (mixed), so keep them in [-0.5, {MAX_ZONE_VALUE})"
            ),
        ));
    }
    Ok(())
}

/// The kind the zoning map gives at `p` for the lot seeded `lot_seed`: the indexed kind,
/// or in a mixed zone a stable draw between the mixed zone's two kinds.
pub(crate) fn zone_map_kind(
    zoning: &dyn Field,
    p: DVec2,
    mixed: &MixedZone,
    lot_seed: u64,
) -> BuildingKind {
    let v = zoning.sample(p);
    if v.is_finite() && v.round() >= MIXED_ZONE {
        let mut rng = Pcg64Mcg::seed_from_u64(lot_seed ^ 0x004D_4958_4544);
        return if rng.random::<f64>() < mixed.commercial_share {
            mixed.commercial
        } else {
            mixed.residential
        };
    }
    polis_buildings::kind_from_zoning(zoning, p)
}

/// `limit` lowered by the first cap whose area the lot's `area_m2` does not exceed
/// (caps taken from the smallest area up).
pub(crate) fn area_capped(caps: &[AreaCap], area_m2: f64, limit: f64) -> f64 {
    caps.iter()
        .filter(|c| area_m2 <= c.max_area_m2)
        .min_by(|a, b| a.max_area_m2.total_cmp(&b.max_area_m2))
        .map_or(limit, |c| limit.min(c.max_height_m))
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::field::Constant;

    #[test]
    fn caps_apply_from_the_smallest_area_up() {
        let caps = [
            AreaCap {
                max_area_m2: 1000.0,
                max_height_m: 40.0,
            },
            AreaCap {
                max_area_m2: 300.0,
                max_height_m: 12.0,
            },
        ];
        assert_eq!(area_capped(&caps, 200.0, 100.0), 12.0);
        assert_eq!(area_capped(&caps, 300.0, 100.0), 12.0);
        assert_eq!(area_capped(&caps, 301.0, 100.0), 40.0);
        assert_eq!(area_capped(&caps, 2000.0, 100.0), 100.0);
        assert_eq!(area_capped(&caps, 200.0, 8.0), 8.0);
        assert_eq!(area_capped(&[], 200.0, 8.0), 8.0);
        assert!(validate(&MixedZone::default(), &caps).is_ok());
        let bad = [AreaCap {
            max_area_m2: f64::NAN,
            max_height_m: 3.0,
        }];
        assert!(validate(&MixedZone::default(), &bad).is_err());
        let share = MixedZone {
            commercial_share: 1.5,
            ..MixedZone::default()
        };
        assert!(validate(&share, &[]).is_err());
    }

    #[test]
    fn mixed_zone_draws_both_kinds_and_indices_stay() {
        let mixed = MixedZone::default();
        let kinds: Vec<BuildingKind> = (0..200)
            .map(|i| zone_map_kind(&Constant(6.2), DVec2::ZERO, &mixed, i))
            .collect();
        let offices = kinds.iter().filter(|&&k| k == BuildingKind::Office).count();
        let flats = kinds
            .iter()
            .filter(|&&k| k == BuildingKind::Apartment)
            .count();
        assert_eq!(offices + flats, 200);
        assert!((50..110).contains(&offices), "{offices}");
        assert_eq!(
            zone_map_kind(&Constant(3.0), DVec2::ZERO, &mixed, 1),
            BuildingKind::House
        );
        assert!(check_zone_map_range(0.0, 6.0).is_ok());
        assert!(check_zone_map_range(0.0, 255.0).is_err());
        assert!(check_zone_map_range(-1.0, 5.0).is_err());
    }
}
