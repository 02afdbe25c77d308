//! The input maps of a city: [`MapSpec`] (data) and [`CityMaps`] (the built fields).
//!
//! Every map is a [`Field`] over the layout plane (metres). A configuration names each one
//! with a [`MapSpec`]: either a [`FieldSpec`] of polis-geom (noise, the slides'
//! population, a grey-scale PNG, constants and combinators) or one of the city-scale
//! [`Shape`]s written here (a coastline, an island, a radial centre, the smallest of
//! several maps). The seeds written in a map are *salts*: they are mixed with the city
//! seed, so a new city seed gives new maps while one preset file serves every seed. PNG
//! maps take no seed and replace a procedural map exactly.

use std::sync::Arc;

use polis_geom::field::{Constant, Fbm, FbmParams, FieldSpec, FnField, PopulationParams};
use polis_geom::{DVec2, Field};
use polis_roads::{Pattern, RoadInputs};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::seed::mix;

/// A city-scale procedural shape: coasts, islands and centres, seeded.
///
/// Serialised with a `kind` tag like [`FieldSpec`], e.g.
/// `{ "kind": "island", "centre": [0, 0], "radii_m": [900, 2600] }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
#[non_exhaustive]
pub enum Shape {
    /// Water (1) beyond a noisy straight coastline, land (0) before it.
    Coast {
        /// Direction from the origin toward the sea, degrees counter-clockwise from +x.
        /// Default: 0 (sea to the east).
        #[serde(default)]
        toward_deg: f64,
        /// Distance of the mean coastline from the origin, metres. Default: 1440.
        #[serde(default = "coast_distance")]
        distance_m: f64,
        /// Amplitude of the coastline's wiggle, metres. Default: 900.
        #[serde(default = "coast_roughness")]
        roughness_m: f64,
        /// Wavelength of the wiggle, metres. Default: 1800.
        #[serde(default = "coast_wavelength")]
        wavelength_m: f64,
        /// Seed salt. Default: 0.
        #[serde(default)]
        seed: u64,
    },
    /// Land (0) inside a noisy ellipse, water (1) outside: an island city.
    Island {
        /// Centre, metres. Default: the origin.
        #[serde(default)]
        centre: [f64; 2],
        /// Semi-axes (along, across the ellipse's angle), metres.
        radii_m: [f64; 2],
        /// Direction of the first semi-axis, degrees counter-clockwise from +x. Default: 0.
        #[serde(default)]
        angle_deg: f64,
        /// Amplitude of the shore's wiggle as a fraction of the radius. Default: 0.12.
        #[serde(default = "island_roughness")]
        roughness: f64,
        /// Wavelength of the wiggle, metres. Default: 900.
        #[serde(default = "island_wavelength")]
        wavelength_m: f64,
        /// Seed salt. Default: 0.
        #[serde(default)]
        seed: u64,
    },
    /// A density peak: `peak` at the centre falling smoothly to 0 at `radius_m`,
    /// modulated by noise of relative amplitude `noise`.
    Radial {
        /// Centre, metres. Default: the origin.
        #[serde(default)]
        centre: [f64; 2],
        /// Radius at which the value reaches 0, metres.
        radius_m: f64,
        /// Value at the centre. Default: 1.
        #[serde(default = "one")]
        peak: f64,
        /// Relative noise amplitude in [0, 1]. Default: 0.3.
        #[serde(default = "radial_noise")]
        noise: f64,
        /// Noise wavelength, metres. Default: 600.
        #[serde(default = "radial_wavelength")]
        wavelength_m: f64,
        /// Seed salt. Default: 0.
        #[serde(default)]
        seed: u64,
    },
    /// The smallest of several maps at each point. For water maps (1 is water) the
    /// intersection of their water: an island's sea that ends at a coast, e.g. a river
    /// between an island and the mainland (the `manhattan` preset). Each map is built
    /// with its own salt (its index mixed into the city's), so maps of the same kind
    /// and seed still get different noise. NaN where any map is NaN.
    MinOf {
        /// The maps, at least one.
        of: Vec<MapSpec>,
    },
}

fn coast_distance() -> f64 {
    1440.0
}
fn coast_roughness() -> f64 {
    900.0
}
fn coast_wavelength() -> f64 {
    1800.0
}
fn island_roughness() -> f64 {
    0.12
}
fn island_wavelength() -> f64 {
    900.0
}
fn one() -> f64 {
    1.0
}
fn radial_noise() -> f64 {
    0.3
}
fn radial_wavelength() -> f64 {
    600.0
}

/// One input map as data: a city [`Shape`] or any polis-geom [`FieldSpec`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MapSpec {
    /// A coast, island or centre.
    Shape(Shape),
    /// Noise, population, PNG, constants and combinators.
    Field(FieldSpec),
}

impl From<FieldSpec> for MapSpec {
    fn from(f: FieldSpec) -> Self {
        MapSpec::Field(f)
    }
}

impl From<Shape> for MapSpec {
    fn from(s: Shape) -> Self {
        MapSpec::Shape(s)
    }
}

impl MapSpec {
    /// A grey-scale PNG covering `extent` (metres): the image's top row is the extent's
    /// north edge. Values are in [0, 1].
    #[cfg(feature = "png")]
    pub fn png(path: impl Into<std::path::PathBuf>, extent: polis_geom::Aabb2) -> Self {
        MapSpec::Field(FieldSpec::Png {
            path: path.into(),
            extent,
        })
    }

    /// A constant map.
    pub fn constant(value: f64) -> Self {
        MapSpec::Field(FieldSpec::Constant { value })
    }

    /// Builds the field, mixing `salt` (derived from the city seed) into every seed.
    ///
    /// # Errors
    /// [`Error::Config`] naming `name` for out-of-range shape parameters; geometry errors
    /// for bad field parameters or unreadable PNG files.
    pub fn build(&self, name: &str, salt: u64) -> Result<Arc<dyn Field>> {
        self.build_limited(name, salt, polis_geom::field::DEFAULT_MAX_PNG_PIXELS)
    }

    /// [`build`](Self::build) with PNG images limited to `max_pixels` pixels each,
    /// checked from the header before decoding.
    ///
    /// # Errors
    /// As [`build`](Self::build).
    pub fn build_limited(&self, name: &str, salt: u64, max_pixels: u64) -> Result<Arc<dyn Field>> {
        match self {
            MapSpec::Field(spec) => Ok(Arc::from(salted(spec, salt).build_limited(max_pixels)?)),
            MapSpec::Shape(shape) => build_shape(shape, name, salt, max_pixels),
        }
    }
}

impl MapSpec {
    /// A conservative interval holding every value the built map can take, from the
    /// description alone (see [`FieldSpec::value_range`]); NaN or infinite bounds flag a
    /// NaN or overflowing parameter. [`CityConfig::validate`](crate::CityConfig::validate)
    /// checks it against each map's physical range.
    pub fn value_range(&self) -> (f64, f64) {
        match self {
            MapSpec::Field(spec) => spec.value_range(),
            MapSpec::Shape(Shape::Coast { .. } | Shape::Island { .. }) => (0.0, 1.0),
            // An empty list is refused when built; its range is empty (NaN flags it).
            MapSpec::Shape(Shape::MinOf { of }) => of
                .iter()
                .map(MapSpec::value_range)
                .reduce(|(lo, hi), (l, h)| (nan_min(lo, l), nan_min(hi, h)))
                .unwrap_or((f64::NAN, f64::NAN)),
            MapSpec::Shape(Shape::Radial { peak, noise, .. }) => {
                // max(peak · base · (1 + noise · n), 0) with base in [0, 1], n in [-1, 1].
                let top = peak * (1.0 + noise.abs());
                if top.is_nan() {
                    (f64::NAN, f64::NAN)
                } else {
                    (0.0, top.max(0.0))
                }
            }
        }
    }
}

fn finite_pos(name: &str, field: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::config(
            format!("{name}.{field}"),
            format!("{v} must be finite and > 0"),
        ))
    }
}

fn finite(name: &str, field: &str, v: &[f64]) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::config(
            format!("{name}.{field}"),
            format!("{v:?} must be finite"),
        ))
    }
}

fn noise(seed: u64, wavelength_m: f64) -> Result<Fbm> {
    Ok(Fbm::new(FbmParams {
        seed,
        octaves: 4,
        wavelength_m,
        ..FbmParams::default()
    })?)
}

/// The smaller of `a` and `b`, NaN if either is.
fn nan_min(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

fn build_shape(shape: &Shape, name: &str, salt: u64, max_pixels: u64) -> Result<Arc<dyn Field>> {
    Ok(match *shape {
        Shape::MinOf { ref of } => {
            if of.is_empty() {
                return Err(Error::config(
                    format!("{name}.of"),
                    "min_of needs at least one map".to_string(),
                ));
            }
            let maps = of
                .iter()
                .enumerate()
                .map(|(i, m)| {
                    m.build_limited(
                        &format!("{name}.of[{i}]"),
                        mix(salt, i as u64 + 1),
                        max_pixels,
                    )
                })
                .collect::<Result<Vec<_>>>()?;
            Arc::new(FnField::new(move |p: DVec2| {
                maps.iter()
                    .map(|m| m.sample(p))
                    .reduce(nan_min)
                    .unwrap_or(f64::NAN)
            }))
        }
        Shape::Coast {
            toward_deg,
            distance_m,
            roughness_m,
            wavelength_m,
            seed,
        } => {
            finite(name, "coast", &[toward_deg, distance_m, roughness_m])?;
            finite_pos(name, "wavelength_m", wavelength_m)?;
            let dir = DVec2::from_angle(toward_deg.to_radians());
            let n = noise(mix(salt, seed), wavelength_m)?;
            Arc::new(FnField::new(move |p: DVec2| {
                let v = p.dot(dir) + roughness_m * n.sample(p);
                if v.is_nan() {
                    f64::NAN
                } else if v > distance_m {
                    1.0
                } else {
                    0.0
                }
            }))
        }
        Shape::Island {
            centre,
            radii_m,
            angle_deg,
            roughness,
            wavelength_m,
            seed,
        } => {
            finite(
                name,
                "island",
                &[centre[0], centre[1], angle_deg, roughness],
            )?;
            finite_pos(name, "radii_m[0]", radii_m[0])?;
            finite_pos(name, "radii_m[1]", radii_m[1])?;
            finite_pos(name, "wavelength_m", wavelength_m)?;
            let c = DVec2::from(centre);
            let x = DVec2::from_angle(angle_deg.to_radians());
            let n = noise(mix(salt, seed), wavelength_m)?;
            Arc::new(FnField::new(move |p: DVec2| {
                let d = p - c;
                let (u, v) = (d.dot(x) / radii_m[0], d.perp_dot(x) / radii_m[1]);
                let r = (u * u + v * v).sqrt() + roughness * n.sample(p);
                if r.is_nan() {
                    f64::NAN
                } else if r > 1.0 {
                    1.0
                } else {
                    0.0
                }
            }))
        }
        Shape::Radial {
            centre,
            radius_m,
            peak,
            noise: amp,
            wavelength_m,
            seed,
        } => {
            finite(name, "radial", &[centre[0], centre[1], peak])?;
            finite_pos(name, "radius_m", radius_m)?;
            finite_pos(name, "wavelength_m", wavelength_m)?;
            if !(0.0..=1.0).contains(&amp) {
                return Err(Error::config(
                    format!("{name}.noise"),
                    format!("{amp} must be in [0, 1]"),
                ));
            }
            let c = DVec2::from(centre);
            let n = noise(mix(salt, seed), wavelength_m)?;
            Arc::new(FnField::new(move |p: DVec2| {
                let t = (1.0 - (p - c).length() / radius_m).max(0.0);
                // Smooth fall-off (smoothstep of the distance) times the noise factor.
                let base = t * t * (3.0 - 2.0 * t);
                (peak * base * (1.0 + amp * n.sample(p))).max(0.0)
            }))
        }
    })
}

/// `spec` with `salt` mixed into every seed it holds.
fn salted(spec: &FieldSpec, salt: u64) -> FieldSpec {
    let s = |f: &FieldSpec| Box::new(salted(f, salt));
    match spec {
        FieldSpec::Simplex { seed, wavelength_m } => FieldSpec::Simplex {
            seed: mix(salt, *seed),
            wavelength_m: *wavelength_m,
        },
        FieldSpec::Fbm(p) => FieldSpec::Fbm(FbmParams {
            seed: mix(salt, p.seed),
            ..*p
        }),
        FieldSpec::Population(p) => FieldSpec::Population(PopulationParams {
            seed: mix(salt, p.seed),
            ..*p
        }),
        FieldSpec::Scaled { field, factor } => FieldSpec::Scaled {
            field: s(field),
            factor: *factor,
        },
        FieldSpec::Offset { field, offset } => FieldSpec::Offset {
            field: s(field),
            offset: *offset,
        },
        FieldSpec::Sum { a, b } => FieldSpec::Sum { a: s(a), b: s(b) },
        FieldSpec::Product { a, b } => FieldSpec::Product { a: s(a), b: s(b) },
        FieldSpec::Threshold { field, threshold } => FieldSpec::Threshold {
            field: s(field),
            threshold: *threshold,
        },
        FieldSpec::Min { a, b } => FieldSpec::Min { a: s(a), b: s(b) },
        FieldSpec::Max { a, b } => FieldSpec::Max { a: s(a), b: s(b) },
        FieldSpec::Clamp { field, lo, hi } => FieldSpec::Clamp {
            field: s(field),
            lo: *lo,
            hi: *hi,
        },
        FieldSpec::Mask {
            mask,
            if_true,
            if_false,
            threshold,
        } => FieldSpec::Mask {
            mask: s(mask),
            if_true: s(if_true),
            if_false: s(if_false),
            threshold: *threshold,
        },
        FieldSpec::Blend { weight, zero, one } => FieldSpec::Blend {
            weight: s(weight),
            zero: s(zero),
            one: s(one),
        },
        FieldSpec::Transform {
            field,
            scale,
            offset,
        } => FieldSpec::Transform {
            field: s(field),
            scale: *scale,
            offset: *offset,
        },
        // Constants, rasters and PNG files hold no seed.
        other => other.clone(),
    }
}

/// A pattern-weight map (Parish & Müller Fig. 7): where this map is high, roads follow
/// `pattern`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatternMap {
    /// The road pattern.
    pub pattern: Pattern,
    /// Its grey-scale weight map.
    pub map: MapSpec,
}

/// The input maps of a city, as data. `None` means the map's neutral value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapsConfig {
    /// Population density, about [0, 1] (highways climb it, streets branch above the
    /// road threshold, the zoning bands read it). Default: the slides' layered-simplex
    /// population with 100 m units.
    pub population: MapSpec,
    /// Water: ≥ 0.5 is water (only highways cross it, as bridges). Default: none.
    pub water: Option<MapSpec>,
    /// Parks and other no-build land: ≥ 0.5 is a park. Default: none.
    pub parks: Option<MapSpec>,
    /// Ground elevation, metres, within ±[`MAX_ELEVATION_M`](crate::MAX_ELEVATION_M).
    /// Default: flat (0 m).
    pub elevation: Option<MapSpec>,
    /// Zoning: the value, rounded, indexes the building kinds (0 skyscraper, 1 office,
    /// 2 mid-rise, 3 house, 4 apartment, 5 industrial); replaces the zoning bands.
    /// Default: none (the bands of [`ZoningConfig`](crate::ZoningConfig) apply).
    pub zoning: Option<MapSpec>,
    /// Maximum building height, metres, in [0, [`MAX_BUILDING_HEIGHT_M`](crate::MAX_BUILDING_HEIGHT_M)];
    /// replaces the bands' limits, and where it is 0 no building stands. Default: none.
    pub max_height: Option<MapSpec>,
    /// Pattern-weight maps; empty = `roads.pattern` everywhere. Default: empty.
    pub pattern_weights: Vec<PatternMap>,
    /// Local New York grid angle, degrees. Default: none (`roads.grid_angle_deg`).
    pub grid_angle: Option<MapSpec>,
    /// The largest PNG map, in pixels (width × height), read from each image's header
    /// before decoding; 1 to 2³⁰. Default:
    /// [`DEFAULT_MAX_PNG_PIXELS`](polis_geom::field::DEFAULT_MAX_PNG_PIXELS) (8192²).
    pub max_image_pixels: u64,
}

impl Default for MapsConfig {
    fn default() -> Self {
        MapsConfig {
            population: MapSpec::Field(FieldSpec::Population(PopulationParams {
                seed: 0,
                unit_m: 100.0,
            })),
            water: None,
            parks: None,
            elevation: None,
            zoning: None,
            max_height: None,
            pattern_weights: Vec::new(),
            grid_angle: None,
            max_image_pixels: polis_geom::field::DEFAULT_MAX_PNG_PIXELS,
        }
    }
}

/// The built input maps, shared by every stage.
#[derive(Clone)]
pub struct CityMaps {
    /// The maps the road generator reads — population, water (≥ 0.5 is water), parks
    /// (≥ 0.5 is a park), elevation (metres), pattern weights, local grid angle — which
    /// the later stages read too (zoning by population, the scene's ground).
    pub inputs: RoadInputs,
    /// Zoning map (kind index), if given.
    pub zoning: Option<Arc<dyn Field>>,
    /// Maximum height map, metres, if given.
    pub max_height: Option<Arc<dyn Field>>,
    /// Whether a water map was given (a constant dry map otherwise).
    pub has_water: bool,
    /// Whether a park map was given.
    pub has_parks: bool,
}

impl std::fmt::Debug for CityMaps {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CityMaps")
            .field("inputs", &self.inputs)
            .field("has_water", &self.has_water)
            .field("has_parks", &self.has_parks)
            .field("zoning", &self.zoning.is_some())
            .field("max_height", &self.max_height.is_some())
            .finish()
    }
}

impl CityMaps {
    /// Builds every map of `config`, salting seeds with `seed`.
    ///
    /// # Errors
    /// The first map that cannot be built, named (`maps.water.radius_m`).
    pub fn build(config: &MapsConfig, seed: u64) -> Result<CityMaps> {
        let px = config.max_image_pixels;
        let opt = |m: &Option<MapSpec>, name: &str, k: u64| -> Result<Option<Arc<dyn Field>>> {
            m.as_ref()
                .map(|m| m.build_limited(name, mix(seed, k), px))
                .transpose()
        };
        let zero = || -> Arc<dyn Field> { Arc::new(Constant(0.0)) };
        let water = opt(&config.water, "maps.water", 2)?;
        let parks = opt(&config.parks, "maps.parks", 3)?;
        let mut pattern_weights = Vec::with_capacity(config.pattern_weights.len());
        for (i, pm) in config.pattern_weights.iter().enumerate() {
            let name = format!("maps.pattern_weights[{i}]");
            pattern_weights.push((
                pm.pattern,
                pm.map.build_limited(&name, mix(seed, 100 + i as u64), px)?,
            ));
        }
        Ok(CityMaps {
            has_water: water.is_some(),
            has_parks: parks.is_some(),
            inputs: RoadInputs {
                population: config
                    .population
                    .build_limited("maps.population", mix(seed, 1), px)?,
                water: water.unwrap_or_else(zero),
                parks: parks.unwrap_or_else(zero),
                elevation: opt(&config.elevation, "maps.elevation", 4)?.unwrap_or_else(zero),
                pattern_weights,
                grid_angle: opt(&config.grid_angle, "maps.grid_angle", 7)?,
            },
            zoning: opt(&config.zoning, "maps.zoning", 5)?,
            max_height: opt(&config.max_height, "maps.max_height", 6)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shapes_and_fields_parse_from_one_enum() {
        let island: MapSpec =
            serde_json::from_str(r#"{ "kind": "island", "radii_m": [800, 2000] }"#).unwrap();
        assert!(matches!(island, MapSpec::Shape(Shape::Island { .. })));
        let fbm: MapSpec =
            serde_json::from_str(r#"{ "kind": "fbm", "seed": 3, "wavelength_m": 900 }"#).unwrap();
        assert!(matches!(fbm, MapSpec::Field(FieldSpec::Fbm(_))));
        let island = island.build("water", 1).unwrap();
        assert_eq!(island.sample(DVec2::ZERO), 0.0, "the centre is land");
        assert_eq!(
            island.sample(DVec2::new(5000.0, 0.0)),
            1.0,
            "far away is water"
        );
    }

    #[test]
    fn the_salt_changes_noise_but_not_constants() {
        let spec = MapSpec::Field(FieldSpec::Fbm(FbmParams::default()));
        let p = DVec2::new(123.0, -456.0);
        let a = spec.build("m", 1).unwrap().sample(p);
        let b = spec.build("m", 2).unwrap().sample(p);
        assert_ne!(a, b);
        assert_eq!(spec.build("m", 1).unwrap().sample(p), a, "deterministic");
        let c = MapSpec::constant(0.25);
        assert_eq!(c.build("m", 1).unwrap().sample(p), 0.25);
    }

    #[test]
    fn bad_shape_parameters_are_named() {
        let bad = MapSpec::Shape(Shape::Radial {
            centre: [0.0, 0.0],
            radius_m: -3.0,
            peak: 1.0,
            noise: 0.2,
            wavelength_m: 100.0,
            seed: 0,
        });
        let err = bad.build("maps.population", 0).err().unwrap();
        assert!(
            err.to_string().contains("maps.population.radius_m"),
            "{err}"
        );
    }

    #[test]
    fn radial_peaks_at_the_centre_and_vanishes_outside() {
        let r = MapSpec::Shape(Shape::Radial {
            centre: [100.0, 0.0],
            radius_m: 1000.0,
            peak: 1.0,
            noise: 0.0,
            wavelength_m: 100.0,
            seed: 0,
        })
        .build("p", 0)
        .unwrap();
        assert!((r.sample(DVec2::new(100.0, 0.0)) - 1.0).abs() < 1e-12);
        assert_eq!(r.sample(DVec2::new(1200.0, 0.0)), 0.0);
    }

    /// An island and a coast combined: water only where both have water (a river between
    /// the island and the mainland beyond the coast), ranges and errors of the parts.
    #[test]
    fn min_of_intersects_water_maps() {
        let spec: MapSpec = serde_json::from_str(
            r#"{ "kind": "min_of", "of": [
                { "kind": "island", "radii_m": [1000, 1000], "roughness": 0 },
                { "kind": "coast", "toward_deg": 180, "distance_m": -1500, "roughness_m": 0 }
            ] }"#,
        )
        .unwrap();
        assert_eq!(spec.value_range(), (0.0, 1.0));
        let w = spec.build("water", 3).unwrap();
        assert_eq!(w.sample(DVec2::ZERO), 0.0, "the island");
        assert_eq!(w.sample(DVec2::new(1200.0, 0.0)), 1.0, "the river");
        assert_eq!(w.sample(DVec2::new(-1200.0, 0.0)), 1.0, "the sea");
        assert_eq!(w.sample(DVec2::new(1800.0, 0.0)), 0.0, "the mainland");
        assert_eq!(
            spec.build("water", 3)
                .unwrap()
                .sample(DVec2::new(1499.0, 7.0)),
            w.sample(DVec2::new(1499.0, 7.0)),
            "deterministic"
        );
        // A NaN part makes the point NaN, not the other part's value.
        let nan = MapSpec::Shape(Shape::MinOf {
            of: vec![MapSpec::constant(0.0), MapSpec::constant(f64::NAN)],
        });
        assert!(nan.build("m", 0).unwrap().sample(DVec2::ZERO).is_nan());
        assert!(nan.value_range().0.is_nan());
        let empty = MapSpec::Shape(Shape::MinOf { of: Vec::new() });
        let err = empty.build("maps.water", 0).err().unwrap();
        assert!(err.to_string().contains("maps.water.of"), "{err}");
        let bad = MapSpec::Shape(Shape::MinOf {
            of: vec![MapSpec::Shape(Shape::Island {
                centre: [0.0, 0.0],
                radii_m: [-1.0, 1.0],
                angle_deg: 0.0,
                roughness: 0.0,
                wavelength_m: 900.0,
                seed: 0,
            })],
        });
        let err = bad.build("maps.water", 0).err().unwrap();
        assert!(
            err.to_string().contains("maps.water.of[0].radii_m[0]"),
            "{err}"
        );
    }
}
