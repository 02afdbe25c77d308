//! From the layout plane (metres, `x` east, `y` north) to WGS 84 longitude/latitude around
//! a geographic anchor: a local tangent-plane (equirectangular) projection.
//!
//! The layout origin goes to the anchor `(λ₀, φ₀)`; a point `(x, y)` goes to
//!
//! ```text
//! φ = φ₀ + y / M(φ₀)             M = a (1 − e²) / (1 − e² sin² φ₀)^{3/2}  (meridian radius)
//! λ = λ₀ + x / (N(φ₀) cos φ₀)    N = a / (1 − e² sin² φ₀)^{1/2}          (prime vertical)
//! ```
//!
//! on the WGS 84 ellipsoid (`a` = 6 378 137 m, `f` = 1 / 298.257 223 563), in radians.
//! Distances along the two axes through the anchor are exact to first order.
//!
//! ## Limitations
//!
//! The parallels are treated as straight and equally long: at north offset `y` the true
//! length of a degree of longitude differs by the factor `1 − y tan φ₀ / N`, so a point
//! at `(x, y)` lands about `|x · y| · tan φ₀ / N` metres east or west of where it belongs;
//! a straight east–west layout line follows the parallel, which departs from the
//! tangent plane's straight line by `x² tan φ₀ / (2N)`; and the tangent plane itself
//! departs from the ellipsoid by second-order terms below `(x² + y²) / (2N)`. Together
//! that is under 2 m for a 4 km city (|x|, |y| ≤ 2 km) at 45°, under 2.3 m at 60°, and
//! 25 times as much for a 20 km city:
//! [`TangentPlane::max_error_m`] gives the bound for a map's extent. Maps that would reach
//! a pole or cross the antimeridian are refused (RFC 7946 §3.1.9 would require cutting
//! them).
//!
//! ## References
//! NIMA TR8350.2, *Department of Defense World Geodetic System 1984* (3rd ed.), §3
//! (the defining parameters); RFC 7946 §4 (coordinate reference system).

use polis_geom::DVec2;

use crate::ExportError;

/// WGS 84 semi-major axis, metres.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS 84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// The tangent-plane projection around one anchor (see the [module](self) docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TangentPlane {
    /// Anchor longitude, degrees.
    pub lon0: f64,
    /// Anchor latitude, degrees.
    pub lat0: f64,
    /// Metres per radian of latitude at the anchor (`M`).
    meridian_m: f64,
    /// Metres per radian of longitude at the anchor (`N cos φ₀`).
    parallel_m: f64,
    /// `N`, metres.
    normal_m: f64,
}

impl TangentPlane {
    /// The projection around `[longitude, latitude]` in degrees.
    ///
    /// # Errors
    /// [`ExportError::InvalidOption`] (`anchor_lon_lat`) for a longitude outside
    /// [-180, 180], a latitude outside (-90, 90) (a pole has no east), or non-finite input.
    pub fn new([lon0, lat0]: [f64; 2]) -> Result<Self, ExportError> {
        if !((-180.0..=180.0).contains(&lon0) && lat0 > -90.0 && lat0 < 90.0) {
            return Err(ExportError::InvalidOption {
                name: "anchor_lon_lat",
                reason: format!(
                    "[{lon0}, {lat0}] is not a longitude in [-180, 180] and a latitude \
                     strictly between -90 and 90"
                ),
            });
        }
        let e2 = WGS84_F * (2.0 - WGS84_F);
        let phi = lat0.to_radians();
        let w = 1.0 - e2 * phi.sin().powi(2);
        let normal_m = WGS84_A / w.sqrt();
        Ok(TangentPlane {
            lon0,
            lat0,
            meridian_m: WGS84_A * (1.0 - e2) / (w * w.sqrt()),
            parallel_m: normal_m * phi.cos(),
            normal_m,
        })
    }

    /// `[longitude, latitude]` in degrees of the layout point `p` (metres).
    pub fn lon_lat(&self, p: DVec2) -> [f64; 2] {
        [
            self.lon0 + (p.x / self.parallel_m).to_degrees(),
            self.lat0 + (p.y / self.meridian_m).to_degrees(),
        ]
    }

    /// An upper bound, in metres, on the position error of the projection over the
    /// layout box `min..max` (see the module's Limitations).
    pub fn max_error_m(&self, min: DVec2, max: DVec2) -> f64 {
        let far = min.abs().max(max.abs());
        let tan = self.lat0.to_radians().tan().abs();
        ((far.x * far.y + 0.5 * far.x * far.x) * tan + 0.5 * far.length_squared()) / self.normal_m
    }

    /// Checks that the layout box `min..max` maps inside WGS 84 bounds without reaching a
    /// pole or crossing the antimeridian.
    ///
    /// # Errors
    /// [`ExportError::InvalidOption`] (`anchor_lon_lat`) naming the offending corner.
    pub fn check_extent(&self, min: DVec2, max: DVec2) -> Result<(), ExportError> {
        let [w, s] = self.lon_lat(min);
        let [e, n] = self.lon_lat(max);
        let ok = [w, s, e, n].iter().all(|v| v.is_finite())
            && (-180.0..=180.0).contains(&w)
            && (-180.0..=180.0).contains(&e)
            && s > -90.0
            && n < 90.0;
        if ok {
            Ok(())
        } else {
            Err(ExportError::InvalidOption {
                name: "anchor_lon_lat",
                reason: format!(
                    "the map spans longitudes {w}..{e} and latitudes {s}..{n} around the \
                     anchor: it would cross the antimeridian or reach a pole; move the anchor"
                ),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_degree_of_latitude_and_longitude_has_its_known_length() {
        // At the equator a degree of longitude is a·π/180 = 111 319.49 m and a degree of
        // latitude 110 574.27 m; at 60° N, 55 799.98 m and 111 412.24 m (WGS 84 tables).
        let eq = TangentPlane::new([0.0, 0.0]).unwrap();
        let [lon, _] = eq.lon_lat(DVec2::new(111_319.49, 0.0));
        assert!((lon - 1.0).abs() < 1e-7, "{lon}");
        let [_, lat] = eq.lon_lat(DVec2::new(0.0, 110_574.27));
        assert!((lat - 1.0).abs() < 1e-4, "{lat}");
        let north = TangentPlane::new([10.0, 60.0]).unwrap();
        let [lon, lat] = north.lon_lat(DVec2::new(55_799.98, 111_412.24));
        assert!((lon - 11.0).abs() < 1e-4, "{lon}");
        assert!((lat - 61.0).abs() < 2e-2, "{lat}"); // M varies over the degree
    }

    #[test]
    fn bad_anchors_and_extents_are_refused() {
        for a in [[181.0, 0.0], [0.0, 90.0], [0.0, -90.0], [f64::NAN, 0.0]] {
            assert!(TangentPlane::new(a).is_err(), "{a:?}");
        }
        let near_date_line = TangentPlane::new([179.99, 0.0]).unwrap();
        let h = DVec2::splat(2000.0);
        assert!(near_date_line.check_extent(-h, h).is_err());
        let near_pole = TangentPlane::new([0.0, 89.99]).unwrap();
        assert!(near_pole.check_extent(-h, h).is_err());
        let berlin = TangentPlane::new([13.4, 52.5]).unwrap();
        assert!(berlin.check_extent(-h, h).is_ok());
        // The documented bounds for a 4 km city.
        assert!(berlin.max_error_m(-h, h) < 2.0);
        let at45 = TangentPlane::new([0.0, 45.0]).unwrap();
        let at60 = TangentPlane::new([0.0, 60.0]).unwrap();
        assert!(at45.max_error_m(-h, h) < 2.0 && at60.max_error_m(-h, h) < 2.3);
    }
}
