//! [`FieldSpec`]: a map described as data (serde), built into a `Box<dyn Field>`.
//!
//! Configuration files cannot hold closures, so a city configuration names its input maps
//! with this enum: noise, the slides' population, PNG images, constants, and the
//! combinators over them, nested as deeply as needed.

use glam::DVec2;

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
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
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
        #[cfg_attr(feature = "serde", serde(default = "half"))]
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
        #[cfg_attr(feature = "serde", serde(default = "one"))]
        scale: DVec2,
        /// Added after scaling. Default: (0, 0).
        #[cfg_attr(feature = "serde", serde(default))]
        offset: DVec2,
    },
}

#[cfg_attr(not(feature = "serde"), allow(dead_code))]
fn half() -> f64 {
    0.5
}

#[cfg_attr(not(feature = "serde"), allow(dead_code))]
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
        self.build_limited(super::DEFAULT_MAX_PNG_PIXELS)
    }

    /// [`build`](Self::build) with PNG images limited to `max_pixels` pixels each
    /// (width × height, checked from the header before decoding; see
    /// [`Raster::from_png_bytes_limited`]).
    ///
    /// Errors: as [`build`](Self::build).
    // Without the feature `png` no variant reads an image, so the limit only recurses.
    #[cfg_attr(not(feature = "png"), allow(clippy::only_used_in_recursion))]
    pub fn build_limited(&self, max_pixels: u64) -> Result<Box<dyn Field>, GeomError> {
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
            FieldSpec::Png { path, extent } => {
                Box::new(Raster::from_png_path_limited(path, *extent, max_pixels)?)
            }
            FieldSpec::Scaled { field, factor } => {
                Box::new(Scaled::new(field.build_limited(max_pixels)?, *factor))
            }
            FieldSpec::Offset { field, offset } => {
                Box::new(Offset::new(field.build_limited(max_pixels)?, *offset))
            }
            FieldSpec::Sum { a, b } => Box::new(Sum::new(
                a.build_limited(max_pixels)?,
                b.build_limited(max_pixels)?,
            )),
            FieldSpec::Product { a, b } => Box::new(Product::new(
                a.build_limited(max_pixels)?,
                b.build_limited(max_pixels)?,
            )),
            FieldSpec::Threshold { field, threshold } => {
                Box::new(Threshold::new(field.build_limited(max_pixels)?, *threshold))
            }
            FieldSpec::Min { a, b } => Box::new(Min::new(
                a.build_limited(max_pixels)?,
                b.build_limited(max_pixels)?,
            )),
            FieldSpec::Max { a, b } => Box::new(Max::new(
                a.build_limited(max_pixels)?,
                b.build_limited(max_pixels)?,
            )),
            FieldSpec::Clamp { field, lo, hi } => {
                Box::new(Clamp::new(field.build_limited(max_pixels)?, *lo, *hi))
            }
            FieldSpec::Mask {
                mask,
                if_true,
                if_false,
                threshold,
            } => Box::new(
                Mask::new(
                    mask.build_limited(max_pixels)?,
                    if_true.build_limited(max_pixels)?,
                    if_false.build_limited(max_pixels)?,
                )
                .with_threshold(*threshold),
            ),
            FieldSpec::Blend { weight, zero, one } => Box::new(Blend::new(
                weight.build_limited(max_pixels)?,
                zero.build_limited(max_pixels)?,
                one.build_limited(max_pixels)?,
            )),
            FieldSpec::Transform {
                field,
                scale,
                offset,
            } => Box::new(DomainTransform::new(
                field.build_limited(max_pixels)?,
                *scale,
                *offset,
            )),
        })
    }
}

/// A closed interval `[lo, hi]` of field values, for [`FieldSpec::value_range`].
pub type ValueRange = (f64, f64);

/// `min` and `max` that keep a NaN (`f64::min` drops it).
fn nan_min(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.min(b)
    }
}

fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

fn range_union(a: ValueRange, b: ValueRange) -> ValueRange {
    (nan_min(a.0, b.0), nan_max(a.1, b.1))
}

fn range_product(a: ValueRange, b: ValueRange) -> ValueRange {
    let p = [a.0 * b.0, a.0 * b.1, a.1 * b.0, a.1 * b.1];
    if p.iter().any(|v| v.is_nan()) {
        return (f64::NAN, f64::NAN);
    }
    (
        p.iter().copied().fold(f64::INFINITY, f64::min),
        p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    )
}

fn nan_if(bad: bool, r: ValueRange) -> ValueRange {
    if bad { (f64::NAN, f64::NAN) } else { r }
}

impl FieldSpec {
    /// A conservative interval holding every value the built field can take at a point
    /// whose sample is defined, computed from the description alone (no file is read):
    /// interval arithmetic over the combinators, `[-1, 1]` for noise, `[0, 1]` for the
    /// population and PNG images, the data's extremes for an inline raster.
    ///
    /// A NaN bound means a parameter is NaN (e.g. a `scaled` factor); an infinite bound
    /// means a parameter is infinite or the arithmetic overflows. Configuration checks use
    /// this to refuse maps that can only produce non-finite or unphysical values.
    ///
    /// Guarantees: for every point `p` where `build()?.sample(p)` is finite, the value
    /// lies in the returned interval (property-tested). Limitations: the interval may be
    /// wider than the values actually taken (e.g. `a − a` gives `[-2, 2]` for noise).
    pub fn value_range(&self) -> ValueRange {
        match self {
            FieldSpec::Constant { value } => (*value, *value),
            FieldSpec::Simplex { .. } | FieldSpec::Fbm(_) => (-1.0, 1.0),
            FieldSpec::Population(_) => (0.0, 1.0),
            FieldSpec::Raster(r) => r
                .data()
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(f64::from(v)), hi.max(f64::from(v)))
                }),
            #[cfg(feature = "png")]
            FieldSpec::Png { .. } => (0.0, 1.0),
            FieldSpec::Scaled { field, factor } => {
                range_product(field.value_range(), (*factor, *factor))
            }
            FieldSpec::Offset { field, offset } => {
                let (lo, hi) = field.value_range();
                (lo + offset, hi + offset)
            }
            FieldSpec::Sum { a, b } => {
                let (a, b) = (a.value_range(), b.value_range());
                (a.0 + b.0, a.1 + b.1)
            }
            FieldSpec::Product { a, b } => range_product(a.value_range(), b.value_range()),
            FieldSpec::Threshold { field, threshold } => {
                let (lo, hi) = field.value_range();
                nan_if(lo.is_nan() || hi.is_nan() || threshold.is_nan(), (0.0, 1.0))
            }
            FieldSpec::Min { a, b } => {
                let (a, b) = (a.value_range(), b.value_range());
                (nan_min(a.0, b.0), nan_min(a.1, b.1))
            }
            FieldSpec::Max { a, b } => {
                let (a, b) = (a.value_range(), b.value_range());
                (nan_max(a.0, b.0), nan_max(a.1, b.1))
            }
            FieldSpec::Clamp { field, lo, hi } => {
                let (a, b) = field.value_range();
                // Bounds in either order, as `Clamp::new` takes them.
                let (lo, hi) = if lo > hi { (hi, lo) } else { (lo, hi) };
                let clamp = |v: f64| v.max(*lo).min(*hi);
                nan_if(
                    a.is_nan() || b.is_nan() || lo.is_nan() || hi.is_nan(),
                    (clamp(a).min(clamp(b)), clamp(a).max(clamp(b))),
                )
            }
            FieldSpec::Mask {
                mask,
                if_true,
                if_false,
                threshold,
            } => {
                let (m0, m1) = mask.value_range();
                nan_if(
                    m0.is_nan() || m1.is_nan() || threshold.is_nan(),
                    range_union(if_true.value_range(), if_false.value_range()),
                )
            }
            FieldSpec::Blend { weight, zero, one } => {
                let (w0, w1) = weight.value_range();
                nan_if(
                    w0.is_nan() || w1.is_nan(),
                    range_union(zero.value_range(), one.value_range()),
                )
            }
            FieldSpec::Transform {
                field,
                scale,
                offset,
            } => nan_if(
                !(scale.is_finite() && offset.is_finite()),
                field.value_range(),
            ),
        }
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

    /// Random trees of combinators over noise, population and constants.
    fn arb_spec() -> impl proptest::strategy::Strategy<Value = FieldSpec> {
        use proptest::prelude::*;
        let leaf = prop_oneof![
            (-50.0f64..50.0).prop_map(|value| FieldSpec::Constant { value }),
            (0u64..4, 50.0f64..500.0)
                .prop_map(|(seed, wavelength_m)| FieldSpec::Simplex { seed, wavelength_m }),
            (0u64..4)
                .prop_map(|seed| FieldSpec::Population(PopulationParams { seed, unit_m: 50.0 })),
        ];
        leaf.prop_recursive(4, 24, 3, |inner| {
            prop_oneof![
                (inner.clone(), -10.0f64..10.0).prop_map(|(f, factor)| FieldSpec::Scaled {
                    field: b(f),
                    factor
                }),
                (inner.clone(), -10.0f64..10.0).prop_map(|(f, offset)| FieldSpec::Offset {
                    field: b(f),
                    offset
                }),
                (inner.clone(), inner.clone())
                    .prop_map(|(a, c)| FieldSpec::Sum { a: b(a), b: b(c) }),
                (inner.clone(), inner.clone())
                    .prop_map(|(a, c)| FieldSpec::Product { a: b(a), b: b(c) }),
                (inner.clone(), inner.clone())
                    .prop_map(|(a, c)| FieldSpec::Min { a: b(a), b: b(c) }),
                (inner.clone(), inner.clone())
                    .prop_map(|(a, c)| FieldSpec::Max { a: b(a), b: b(c) }),
                (inner.clone(), -2.0f64..2.0, -3.0f64..3.0).prop_map(|(f, lo, w)| {
                    FieldSpec::Clamp {
                        field: b(f),
                        lo,
                        hi: lo + w,
                    }
                }),
                (inner.clone(), inner.clone(), inner.clone()).prop_map(|(m, t, f)| {
                    FieldSpec::Mask {
                        mask: b(m),
                        if_true: b(t),
                        if_false: b(f),
                        threshold: 0.2,
                    }
                }),
                (inner.clone(), inner.clone(), inner).prop_map(|(w, z, o)| FieldSpec::Blend {
                    weight: b(w),
                    zero: b(z),
                    one: b(o)
                }),
            ]
        })
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(96))]

        /// Every sample of the built field lies in the range computed from the data.
        #[test]
        fn value_range_holds_every_sample(spec in arb_spec(), x in -3000.0f64..3000.0, y in -3000.0f64..3000.0) {
            let (lo, hi) = spec.value_range();
            let f = spec.build().unwrap();
            for k in 0..8 {
                let p = DVec2::new(x + 97.0 * f64::from(k), y - 61.0 * f64::from(k));
                let v = f.sample(p);
                let slack = 1e-9 * (1.0 + lo.abs().max(hi.abs()));
                proptest::prop_assert!(v >= lo - slack && v <= hi + slack, "{v} outside [{lo}, {hi}]");
            }
        }
    }

    /// Fuzzing finding (issue 22, config_maps): a clamp written with `lo > hi` (which
    /// `Clamp::new` takes in either order) got the range `[hi, hi]`.
    #[test]
    fn value_range_of_a_clamp_with_bounds_swapped() {
        let spec = FieldSpec::Clamp {
            field: b(FieldSpec::Population(PopulationParams::default())),
            lo: 5.0,
            hi: 0.0,
        };
        assert_eq!(spec.value_range(), (0.0, 1.0));
        let f = spec.build().unwrap();
        for k in 0..50 {
            let v = f.sample(DVec2::new(37.0 * f64::from(k), -53.0 * f64::from(k)));
            assert!((0.0..=1.0).contains(&v), "{v}");
        }
    }

    #[test]
    fn value_range_flags_nan_and_overflow() {
        let png = FieldSpec::Constant { value: 0.5 };
        let nan = FieldSpec::Scaled {
            field: b(png.clone()),
            factor: f64::NAN,
        };
        let (lo, hi) = nan.value_range();
        assert!(lo.is_nan() && hi.is_nan());
        // NaN survives min/max/blend, which `f64::min` would drop.
        let hidden = FieldSpec::Max {
            a: b(nan.clone()),
            b: b(png.clone()),
        };
        assert!(hidden.value_range().0.is_nan());
        let huge = FieldSpec::Scaled {
            field: b(FieldSpec::Fbm(FbmParams::default())),
            factor: 1e300,
        };
        assert_eq!(huge.value_range(), (-1e300, 1e300));
        let over = FieldSpec::Scaled {
            field: b(huge),
            factor: 1e300,
        };
        assert_eq!(over.value_range(), (f64::NEG_INFINITY, f64::INFINITY));
    }
}
