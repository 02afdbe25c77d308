//! [`FieldSpec`]: a map described as data (serde), built into a `Box<dyn Field>`.
//!
//! Configuration files cannot hold closures, so a city configuration names its input maps
//! with this enum: noise, the slides' population, PNG images, constants, and the
//! combinators over them, nested as deeply as needed.

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::{
    Blend, Clamp, Constant, DomainTransform, Fbm, FbmParams, Field, Mask, Max, Min, Offset,
    Population, PopulationParams, Product, Raster, Scaled, SimplexNoise, Sum, Threshold,
};
use crate::GeomError;

/// An input map described as data; [`build`](FieldSpec::build) turns it into a field.
///
/// Serialised with a `kind` tag, e.g. (JSON):
///
/// ```json
/// { "kind": "clamp", "lo": 0.0, "hi": 1.0,
///   "field": { "kind": "offset", "offset": 0.2,
///              "field": { "kind": "fbm", "seed": 7, "wavelength_m": 1500.0 } } }
/// ```
///
/// Every variant mirrors a type of [`field`](super) and has its semantics; missing
/// parameters of `fbm` and `population` take their defaults.
///
/// ```
/// use polis_geom::DVec2;
/// use polis_geom::field::{Field, FieldSpec};
///
/// let spec: FieldSpec = serde_json::from_str(r#"
///     { "kind": "threshold", "threshold": 0.2,
///       "field": { "kind": "population", "seed": 3 } }"#).unwrap();
/// let can_branch = spec.build()?;
/// let v = can_branch.sample(DVec2::new(100.0, 200.0));
/// assert!(v == 0.0 || v == 1.0);
/// # Ok::<(), polis_geom::GeomError>(())
/// ```
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum FieldSpec {
    /// [`Constant`]: the same value everywhere.
    Constant {
        /// The value.
        value: f64,
    },
    /// [`SimplexNoise`] of `seed` with features `wavelength_m` metres across
    /// (`sample(p) = simplex(p / wavelength_m)`).
    Simplex {
        /// Permutation seed.
        seed: u64,
        /// Metres per noise unit; finite and positive.
        wavelength_m: f64,
    },
    /// [`Fbm`] noise.
    Fbm(FbmParams),
    /// The slides' layered-simplex [`Population`].
    Population(PopulationParams),
    /// An inline [`Raster`] (validated on deserialisation).
    Raster(Raster),
    /// A PNG image over `extent`, read by [`Raster::from_png_path`] when built
    /// (feature `png`).
    #[cfg(feature = "png")]
    Png {
        /// Path of the image file.
        path: std::path::PathBuf,
        /// The world-space box it covers, metres.
        extent: crate::Aabb2,
    },
    /// [`Scaled`]: `factor · field`.
    Scaled {
        /// Inner map.
        field: Box<FieldSpec>,
        /// The factor.
        factor: f64,
    },
    /// [`Offset`]: `field + offset`.
    Offset {
        /// Inner map.
        field: Box<FieldSpec>,
        /// The constant added.
        offset: f64,
    },
    /// [`Sum`]: `a + b`.
    Sum {
        /// First term.
        a: Box<FieldSpec>,
        /// Second term.
        b: Box<FieldSpec>,
    },
    /// [`Product`]: `a · b`.
    Product {
        /// First factor.
        a: Box<FieldSpec>,
        /// Second factor.
        b: Box<FieldSpec>,
    },
    /// [`Threshold`]: 1 where `field >= threshold`, else 0.
    Threshold {
        /// Inner map.
        field: Box<FieldSpec>,
        /// The level at and above which the result is 1.
        threshold: f64,
    },
    /// [`Min`]: the smaller of `a` and `b`.
    Min {
        /// First map.
        a: Box<FieldSpec>,
        /// Second map.
        b: Box<FieldSpec>,
    },
    /// [`Max`]: the larger of `a` and `b`.
    Max {
        /// First map.
        a: Box<FieldSpec>,
        /// Second map.
        b: Box<FieldSpec>,
    },
    /// [`Clamp`]: `field` limited to `[lo, hi]`.
    Clamp {
        /// Inner map.
        field: Box<FieldSpec>,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// [`Mask`]: `if_true` where `mask >= threshold`, else `if_false`.
    Mask {
        /// The selecting map.
        mask: Box<FieldSpec>,
        /// Used where `mask >= threshold`.
        if_true: Box<FieldSpec>,
        /// Used elsewhere.
        if_false: Box<FieldSpec>,
        /// Selection level. Default: 0.5.
        #[serde(default = "half")]
        threshold: f64,
    },
    /// [`Blend`]: `(1 − w)·zero + w·one`, `w = weight` clamped to `[0, 1]`.
    Blend {
        /// The weight map.
        weight: Box<FieldSpec>,
        /// The map at weight 0.
        zero: Box<FieldSpec>,
        /// The map at weight 1.
        one: Box<FieldSpec>,
    },
    /// [`DomainTransform`]: `field(p ⊙ scale + offset)`.
    Transform {
        /// Inner map.
        field: Box<FieldSpec>,
        /// Component-wise factor on the point. Default: (1, 1).
        #[serde(default = "one")]
        scale: DVec2,
        /// Added after scaling. Default: (0, 0).
        #[serde(default)]
        offset: DVec2,
    },
}

fn half() -> f64 {
    0.5
}

fn one() -> DVec2 {
    DVec2::ONE
}

impl Default for FieldSpec {
    /// A constant 0.
    fn default() -> Self {
        FieldSpec::Constant { value: 0.0 }
    }
}

impl FieldSpec {
    /// Builds the field; errors are those of the leaf constructors ([`Fbm::new`],
    /// [`Population::new`], [`Raster::from_png_path`]) and
    /// [`GeomError::InvalidParameter`] for a bad simplex `wavelength_m`.
    pub fn build(&self) -> Result<Box<dyn Field>, GeomError> {
        Ok(match self {
            FieldSpec::Constant { value } => Box::new(Constant(*value)),
            FieldSpec::Simplex { seed, wavelength_m } => {
                if !(wavelength_m.is_finite() && *wavelength_m > 0.0) {
                    return Err(GeomError::InvalidParameter {
                        name: "wavelength_m",
                        reason: format!("{wavelength_m} m is not a positive finite length"),
                    });
                }
                Box::new(DomainTransform::new(
                    SimplexNoise::new(*seed),
                    DVec2::splat(1.0 / wavelength_m),
                    DVec2::ZERO,
                ))
            }
            FieldSpec::Fbm(params) => Box::new(Fbm::new(*params)?),
            FieldSpec::Population(params) => Box::new(Population::new(*params)?),
            FieldSpec::Raster(raster) => Box::new(raster.clone()),
            #[cfg(feature = "png")]
            FieldSpec::Png { path, extent } => Box::new(Raster::from_png_path(path, *extent)?),
            FieldSpec::Scaled { field, factor } => Box::new(Scaled::new(field.build()?, *factor)),
            FieldSpec::Offset { field, offset } => Box::new(Offset::new(field.build()?, *offset)),
            FieldSpec::Sum { a, b } => Box::new(Sum::new(a.build()?, b.build()?)),
            FieldSpec::Product { a, b } => Box::new(Product::new(a.build()?, b.build()?)),
            FieldSpec::Threshold { field, threshold } => {
                Box::new(Threshold::new(field.build()?, *threshold))
            }
            FieldSpec::Min { a, b } => Box::new(Min::new(a.build()?, b.build()?)),
            FieldSpec::Max { a, b } => Box::new(Max::new(a.build()?, b.build()?)),
            FieldSpec::Clamp { field, lo, hi } => Box::new(Clamp::new(field.build()?, *lo, *hi)),
            FieldSpec::Mask {
                mask,
                if_true,
                if_false,
                threshold,
            } => Box::new(
                Mask::new(mask.build()?, if_true.build()?, if_false.build()?)
                    .with_threshold(*threshold),
            ),
            FieldSpec::Blend { weight, zero, one } => {
                Box::new(Blend::new(weight.build()?, zero.build()?, one.build()?))
            }
            FieldSpec::Transform {
                field,
                scale,
                offset,
            } => Box::new(DomainTransform::new(field.build()?, *scale, *offset)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Aabb2;
    use crate::field::FieldExt;

    fn b(s: FieldSpec) -> Box<FieldSpec> {
        Box::new(s)
    }

    #[test]
    fn builds_the_same_field_as_the_types() {
        let fbm = FbmParams {
            seed: 4,
            ..FbmParams::default()
        };
        let pop = PopulationParams {
            seed: 4,
            unit_m: 80.0,
        };
        let spec = FieldSpec::Mask {
            mask: b(FieldSpec::Threshold {
                field: b(FieldSpec::Fbm(fbm)),
                threshold: 0.0,
            }),
            if_true: b(FieldSpec::Clamp {
                field: b(FieldSpec::Offset {
                    field: b(FieldSpec::Scaled {
                        field: b(FieldSpec::Population(pop)),
                        factor: 2.0,
                    }),
                    offset: -0.1,
                }),
                lo: 0.0,
                hi: 1.0,
            }),
            if_false: b(FieldSpec::Constant { value: 0.0 }),
            threshold: 0.5,
        };
        let built = spec.build().unwrap();
        let by_hand = Fbm::new(fbm).unwrap().threshold(0.0).select(
            Population::new(pop)
                .unwrap()
                .scaled(2.0)
                .offset(-0.1)
                .clamped(0.0, 1.0),
            Constant(0.0),
        );
        for i in 0..200 {
            let p = DVec2::new(i as f64 * 37.3 - 3000.0, i as f64 * -11.9 + 800.0);
            assert_eq!(built.sample(p).to_bits(), by_hand.sample(p).to_bits());
            assert_eq!(built.gradient(p), by_hand.gradient(p));
        }
        let json = serde_json::to_string(&spec).unwrap();
        let back: FieldSpec = serde_json::from_str(&json).unwrap();
        assert_eq!(back, spec);
    }

    #[test]
    fn every_variant_round_trips_and_builds() {
        let extent = Aabb2::new(DVec2::ZERO, DVec2::new(10.0, 10.0));
        let raster = Raster::new(2, 1, extent, vec![0.0, 1.0]).unwrap();
        let c = |v| b(FieldSpec::Constant { value: v });
        let specs = vec![
            FieldSpec::default(),
            FieldSpec::Simplex {
                seed: 1,
                wavelength_m: 300.0,
            },
            FieldSpec::Fbm(FbmParams::default()),
            FieldSpec::Population(PopulationParams::default()),
            FieldSpec::Raster(raster),
            FieldSpec::Sum {
                a: c(1.0),
                b: c(2.0),
            },
            FieldSpec::Product {
                a: c(3.0),
                b: c(2.0),
            },
            FieldSpec::Min {
                a: c(1.0),
                b: c(2.0),
            },
            FieldSpec::Max {
                a: c(1.0),
                b: c(2.0),
            },
            FieldSpec::Blend {
                weight: c(0.25),
                zero: c(0.0),
                one: c(4.0),
            },
            FieldSpec::Transform {
                field: c(5.0),
                scale: DVec2::ONE,
                offset: DVec2::ZERO,
            },
        ];
        let expected = [
            0.0,
            f64::NAN,
            f64::NAN,
            f64::NAN,
            0.5,
            3.0,
            6.0,
            1.0,
            2.0,
            1.0,
            5.0,
        ];
        for (spec, want) in specs.iter().zip(expected) {
            let json = serde_json::to_string(spec).unwrap();
            let back: FieldSpec = serde_json::from_str(&json).unwrap();
            assert_eq!(&back, spec, "{json}");
            let v = back.build().unwrap().sample(DVec2::new(5.0, 5.0));
            if want.is_nan() {
                assert!(v.is_finite());
            } else {
                assert_eq!(v, want, "{json}");
            }
        }
    }

    #[test]
    fn defaults_and_errors() {
        let spec: FieldSpec =
            serde_json::from_str(r#"{"kind":"transform","field":{"kind":"constant","value":2}}"#)
                .unwrap();
        assert_eq!(
            spec,
            FieldSpec::Transform {
                field: b(FieldSpec::Constant { value: 2.0 }),
                scale: DVec2::ONE,
                offset: DVec2::ZERO
            }
        );
        let fbm: FieldSpec = serde_json::from_str(r#"{"kind":"fbm","seed":9}"#).unwrap();
        assert_eq!(
            fbm,
            FieldSpec::Fbm(FbmParams {
                seed: 9,
                ..FbmParams::default()
            })
        );
        let bad = FieldSpec::Scaled {
            field: b(FieldSpec::Fbm(FbmParams {
                octaves: 0,
                ..FbmParams::default()
            })),
            factor: 1.0,
        };
        assert!(matches!(
            bad.build(),
            Err(GeomError::InvalidParameter {
                name: "octaves",
                ..
            })
        ));
        let bad = FieldSpec::Simplex {
            seed: 0,
            wavelength_m: 0.0,
        };
        assert!(bad.build().is_err());
        assert!(serde_json::from_str::<FieldSpec>(r#"{"kind":"nonsense"}"#).is_err());
        assert!(
            serde_json::from_str::<FieldSpec>(
                r#"{"kind":"raster","width":2,"height":2,"extent":{"min":[0,0],"max":[1,1]},"data":[1]}"#
            )
            .is_err()
        );
    }

    #[cfg(feature = "png")]
    #[test]
    fn png_spec_reads_the_file() {
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, 2, 1);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::Eight);
            let mut w = enc.write_header().unwrap();
            w.write_image_data(&[0, 255]).unwrap();
        }
        let dir = std::env::temp_dir().join(format!("polis-geom-spec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("water.png");
        std::fs::write(&path, &bytes).unwrap();
        let extent = Aabb2::new(DVec2::ZERO, DVec2::new(200.0, 100.0));
        let spec = FieldSpec::Png {
            path: path.clone(),
            extent,
        };
        let f = spec.build().unwrap();
        assert_eq!(f.sample(DVec2::new(150.0, 50.0)), 1.0);
        std::fs::remove_dir_all(&dir).unwrap();
        let missing = FieldSpec::Png { path, extent };
        assert!(matches!(missing.build(), Err(GeomError::Image(_))));
    }
}
