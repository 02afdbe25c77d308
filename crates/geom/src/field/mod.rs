//! Scalar fields over the plane: the input maps of a city.
//!
//! Parish & Müller (2001, §2) drive their whole pipeline from 2-D image maps: *geographical*
//! maps (elevation, land/water/vegetation) and *socio-statistical* maps (population density,
//! zoning, maximal building height), plus grey-scale control maps that blend street patterns
//! (§3.2.2). A [`Field`] is such a map as a function `DVec2 (metres) → f64`, with an
//! optional gradient (the San Francisco rule follows the least or steepest elevation;
//! highways climb the population map).
//!
//! | type | what |
//! |---|---|
//! | [`Constant`] | the same value everywhere |
//! | [`FnField`] | any closure |
//! | [`Raster`] | an `f32` grid over a world-space box, bilinear; from/to grey-scale PNG (feature `png`) |
//! | [`SimplexNoise`] | seeded 2-D simplex noise in `[-1, 1]`, analytic gradient |
//! | [`Fbm`] | fractal (fBm) sum of simplex octaves, in metres |
//! | [`Population`] | the layered-simplex `populationAt` of the priority-queue slides |
//! | [`combinators`] | scale, offset, sum, product, threshold, min, max, clamp, mask, blend, domain transform |
//! | [`FieldSpec`] | any of the above described as data (serde), built into a `Box<dyn Field>` |
//!
//! The PNG loader behind [`Raster::from_png_bytes`] also decodes colour images for
//! textures: `decode_png_rgba8` (feature `png`) turns any PNG into 8-bit RGBA pixels.
//!
//! [`FieldExt`] chains the combinators: `noise.scaled(0.5).offset(0.5).clamped(0.0, 1.0)`.
//! Fields are used as trait objects (`Box<dyn Field>`, `Arc<dyn Field>`), and `&F`,
//! `Box<F>`, `Arc<F>` are fields themselves.
//!
//! ## Example
//!
//! ```
//! use polis_geom::DVec2;
//! use polis_geom::field::{Field, FieldExt, Fbm, FbmParams, Population, PopulationParams};
//!
//! // The slides' population map, one slide unit = 250 m.
//! let population = Population::new(PopulationParams { seed: 7, unit_m: 250.0 })?;
//! // Water where a 2 km fBm dips below -0.3; parks are a constant "no park" here.
//! let terrain = Fbm::new(FbmParams { seed: 7, wavelength_m: 2000.0, ..FbmParams::default() })?;
//! let water = terrain.threshold(-0.3).scaled(-1.0).offset(1.0); // 1 = water, 0 = land
//! let maps: Vec<Box<dyn Field>> = vec![population.boxed(), water.boxed()];
//!
//! let p = DVec2::new(1200.0, -350.0);
//! let density = maps[0].sample(p);
//! assert!((0.0..=1.0).contains(&density));
//! let uphill = maps[0].gradient(p); // per metre
//! assert!(uphill.is_finite());
//! assert!(maps[1].sample(p) == 0.0 || maps[1].sample(p) == 1.0);
//! # Ok::<(), polis_geom::GeomError>(())
//! ```
//!
//! ## Guarantees
//!
//! * **Deterministic**: every field is a pure function of its parameters and the point. Noise
//!   permutation tables come from a `rand_pcg` generator seeded by the user's seed and the
//!   evaluation uses only `+ − × ÷` and `floor`, so the same seed gives the same bits on
//!   every platform.
//! * **Never panics on the point**: NaN and infinite points are fine. Unless a type documents
//!   otherwise, a point with a NaN coordinate samples to NaN; noise sampled at an infinite
//!   point is NaN; [`Raster`] clamps infinite points to its edge; [`Constant`] ignores the
//!   point.
//! * Bad *parameters* (zero-sized rasters, non-finite extents, zero octaves …) are rejected
//!   at construction with a [`GeomError`](crate::GeomError).
//!
//! ## Limitations
//!
//! * The default [`Field::gradient`] is a central difference with step
//!   [`GRADIENT_STEP_M`] (1 cm); types with an exact gradient override it. Where a field is
//!   not differentiable (raster texel borders, threshold steps, min/max switch lines) the
//!   gradient is the one of the piece chosen at the point (see each type).
//! * Noise loses precision far from the origin (beyond ~1e9 noise units) but still returns
//!   values in `[-1, 1]`, or NaN where scaling a finite point into noise units overflows
//!   (coordinates near `f64::MAX`).
//!
//! ## References
//!
//! * Y. I. H. Parish, P. Müller: *Procedural Modeling of Cities*, SIGGRAPH 2001, §2 (input
//!   maps), §3.2 (global goals), §3.3 (local constraints).
//! * The priority-queue slides (`populationAt`), after S. Barrett, *L-Systems Considered
//!   Harmful* (2008).
//! * K. Perlin: *Improving Noise*, SIGGRAPH 2002; S. Gustavson: *Simplex noise demystified*
//!   (2005) — the simplex lattice used here.

use std::sync::Arc;

use glam::DVec2;

pub mod combinators;
pub mod contour;
#[cfg(feature = "png")]
mod image;
pub mod noise;
pub mod population;
pub mod raster;
pub mod spec;

pub use combinators::{
    Blend, Clamp, DomainTransform, Mask, Max, Min, Offset, Product, Scaled, Sum, Threshold,
};
pub use contour::{ContourOptions, MAX_CONTOUR_CELLS, contour_regions};
#[cfg(feature = "png")]
pub use image::{MAX_PNG_DECODED_BYTES, decode_png_rgba8, decode_png_rgba8_limited};
pub use noise::{Fbm, FbmParams, MAX_OCTAVES, SimplexNoise};
pub use population::{Population, PopulationParams};
pub use raster::Raster;
pub use spec::FieldSpec;

/// The default largest image, in pixels (width × height), the PNG loaders decode:
/// 2²⁶ ≈ 67 million (8192 × 8192). A map raster keeps one `f32` per pixel (256 MiB at
/// this size) and a texture four bytes, so the limit bounds memory by what the image
/// decodes to, not by the file's size: a PNG of a few hundred kilobytes can claim
/// 20,000 × 20,000 pixels. Checked from the header, before anything is allocated. Use the
/// `*_limited` loaders (`Raster::from_png_bytes_limited`, `decode_png_rgba8_limited`)
/// or `maps.max_image_pixels` of a city configuration for another limit.
pub const DEFAULT_MAX_PNG_PIXELS: u64 = 1 << 26;

/// Step, in metres, of the central differences used by the default [`Field::gradient`].
///
/// 1 cm: far below any feature of a city map, far above `f64` rounding for coordinates up
/// to [`MAX_COORDINATE`](crate::MAX_COORDINATE).
pub const GRADIENT_STEP_M: f64 = 0.01;

/// A scalar map over the plane (metres → value): population density, water, parks,
/// elevation, pattern weights, maximal height.
///
/// Implementors must be deterministic and must not panic for any point (NaN, infinite,
/// huge): return NaN or a documented value instead.
pub trait Field: Send + Sync {
    /// The value at `p` (metres).
    fn sample(&self, p: DVec2) -> f64;

    /// The gradient at `p`, in value units per metre.
    ///
    /// Default: central differences with step [`GRADIENT_STEP_M`] (four samples).
    /// Implementations with an exact gradient override it.
    fn gradient(&self, p: DVec2) -> DVec2 {
        central_difference(self, p, GRADIENT_STEP_M)
    }

    /// Value and gradient at `p` together (cheaper for fields that compute both at once).
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        (self.sample(p), self.gradient(p))
    }

    /// `Some(v)` when the field is known to be `v` everywhere (so callers may skip
    /// sampling it), `None` when unknown. Default: `None`; [`Constant`] says its value.
    fn constant_value(&self) -> Option<f64> {
        None
    }

    /// The values at many points at once: `out[k]` becomes the value at `points[k]`, for
    /// every `k` below the shorter length (entries of `out` beyond `points` are left
    /// alone).
    ///
    /// Default: one [`sample`](Field::sample) per point. Fields that look up their
    /// neighbourhood for every sample (a spatial index around the point) override it to
    /// look up once around the points' bounding box, which pays when the points lie close
    /// together (a terrain leaf's check points). An override must give the values of
    /// `sample` bit for bit.
    fn sample_many(&self, points: &[DVec2], out: &mut [f64]) {
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = self.sample(*p);
        }
    }
}

/// The gradient of `field` at `p` by central differences with step `h` metres:
/// `((f(p+h·x̂) − f(p−h·x̂)) / 2h, (f(p+h·ŷ) − f(p−h·ŷ)) / 2h)`.
///
/// A zero or non-finite `h` gives a NaN gradient; the function never panics.
pub fn central_difference<F: Field + ?Sized>(field: &F, p: DVec2, h: f64) -> DVec2 {
    let dx = DVec2::new(h, 0.0);
    let dy = DVec2::new(0.0, h);
    let inv = 0.5 / h;
    DVec2::new(
        (field.sample(p + dx) - field.sample(p - dx)) * inv,
        (field.sample(p + dy) - field.sample(p - dy)) * inv,
    )
}

/// `Field` for pointers to a field: every method forwards to the pointee, so a
/// pointer's overrides (a constant's value, batched sampling) are the field's own.
macro_rules! forward_field {
    ($($pointer:ty),*) => {$(
        impl<F: Field + ?Sized> Field for $pointer {
            fn sample(&self, p: DVec2) -> f64 {
                (**self).sample(p)
            }
            fn gradient(&self, p: DVec2) -> DVec2 {
                (**self).gradient(p)
            }
            fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
                (**self).sample_with_gradient(p)
            }
            fn constant_value(&self) -> Option<f64> {
                (**self).constant_value()
            }
            fn sample_many(&self, points: &[DVec2], out: &mut [f64]) {
                (**self).sample_many(points, out)
            }
        }
    )*};
}

forward_field!(&F, Box<F>, Arc<F>);

/// The same value everywhere; the gradient is zero. The point is ignored, even when NaN.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(transparent))]
pub struct Constant(pub f64);

impl Field for Constant {
    fn sample(&self, _p: DVec2) -> f64 {
        self.0
    }
    fn gradient(&self, _p: DVec2) -> DVec2 {
        DVec2::ZERO
    }
    fn sample_with_gradient(&self, _p: DVec2) -> (f64, DVec2) {
        (self.0, DVec2::ZERO)
    }
    fn constant_value(&self) -> Option<f64> {
        Some(self.0)
    }
}

/// A field from a closure `Fn(DVec2) -> f64`; the gradient is by central differences.
///
/// The closure is responsible for the [`Field`] contract (no panics, deterministic).
///
/// ```
/// use polis_geom::DVec2;
/// use polis_geom::field::{Field, FnField};
///
/// // A radial density falling off from the centre over 3 km.
/// let radial = FnField::new(|p: DVec2| (1.0 - p.length() / 3000.0).max(0.0));
/// assert_eq!(radial.sample(DVec2::ZERO), 1.0);
/// assert!(radial.gradient(DVec2::new(1000.0, 0.0)).x < 0.0);
/// ```
#[derive(Clone, Copy)]
pub struct FnField<F>(pub F);

impl<F: Fn(DVec2) -> f64 + Send + Sync> FnField<F> {
    /// Wraps `f`.
    pub fn new(f: F) -> Self {
        FnField(f)
    }
}

impl<F> std::fmt::Debug for FnField<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("FnField(<closure>)")
    }
}

impl<F: Fn(DVec2) -> f64 + Send + Sync> Field for FnField<F> {
    fn sample(&self, p: DVec2) -> f64 {
        (self.0)(p)
    }
}

/// Combinator methods for every [`Field`] (also for `Box<dyn Field>` and `Arc<dyn Field>`).
///
/// Each method wraps `self` in the [`combinators`] type of the same meaning.
pub trait FieldExt: Field + Sized {
    /// `k · self` ([`Scaled`]).
    fn scaled(self, k: f64) -> Scaled<Self> {
        Scaled::new(self, k)
    }
    /// `self + c` ([`Offset`]).
    fn offset(self, c: f64) -> Offset<Self> {
        Offset::new(self, c)
    }
    /// `self + other` ([`Sum`]).
    fn plus<B: Field>(self, other: B) -> Sum<Self, B> {
        Sum::new(self, other)
    }
    /// `self · other` ([`Product`]).
    fn times<B: Field>(self, other: B) -> Product<Self, B> {
        Product::new(self, other)
    }
    /// 1 where `self >= t`, else 0 ([`Threshold`]).
    fn threshold(self, t: f64) -> Threshold<Self> {
        Threshold::new(self, t)
    }
    /// The smaller of `self` and `other` ([`Min`]).
    fn min<B: Field>(self, other: B) -> Min<Self, B> {
        Min::new(self, other)
    }
    /// The larger of `self` and `other` ([`Max`]).
    fn max<B: Field>(self, other: B) -> Max<Self, B> {
        Max::new(self, other)
    }
    /// `self` clamped to `[lo, hi]` ([`Clamp`]).
    fn clamped(self, lo: f64, hi: f64) -> Clamp<Self> {
        Clamp::new(self, lo, hi)
    }
    /// Uses `self` as a mask: `if_true` where `self >= 0.5`, else `if_false` ([`Mask`]).
    fn select<T: Field, E: Field>(self, if_true: T, if_false: E) -> Mask<Self, T, E> {
        Mask::new(self, if_true, if_false)
    }
    /// Uses `self` as a weight `w` clamped to `[0, 1]`: `(1 − w)·zero + w·one` ([`Blend`]).
    fn blend<A: Field, B: Field>(self, zero: A, one: B) -> Blend<Self, A, B> {
        Blend::new(self, zero, one)
    }
    /// The map moved by `d` metres: `sample(p) = self(p − d)` ([`DomainTransform`]).
    fn translated(self, d: DVec2) -> DomainTransform<Self> {
        DomainTransform::new(self, DVec2::ONE, -d)
    }
    /// The map enlarged `k` times about the origin: `sample(p) = self(p / k)`
    /// ([`DomainTransform`]). `k = 0` or non-finite gives a NaN-valued field, no panic.
    fn magnified(self, k: f64) -> DomainTransform<Self> {
        DomainTransform::new(self, DVec2::splat(1.0 / k), DVec2::ZERO)
    }
    /// `sample(p) = self(p ⊙ scale + offset)` ([`DomainTransform`]).
    fn transformed(self, scale: DVec2, offset: DVec2) -> DomainTransform<Self> {
        DomainTransform::new(self, scale, offset)
    }
    /// `self` as a boxed trait object.
    fn boxed(self) -> Box<dyn Field>
    where
        Self: 'static,
    {
        Box::new(self)
    }
    /// `self` as a shared trait object.
    fn shared(self) -> Arc<dyn Field>
    where
        Self: 'static,
    {
        Arc::new(self)
    }
}

impl<F: Field> FieldExt for F {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_and_closure() {
        let c = Constant(0.25);
        assert_eq!(c.sample(DVec2::new(f64::NAN, 1.0)), 0.25);
        assert_eq!(c.gradient(DVec2::ZERO), DVec2::ZERO);
        let f = FnField::new(|p: DVec2| 3.0 * p.x - 2.0 * p.y + 1.0);
        assert_eq!(f.sample(DVec2::new(1.0, 1.0)), 2.0);
        let g = f.gradient(DVec2::new(10.0, -4.0));
        assert!((g - DVec2::new(3.0, -2.0)).length() < 1e-9);
        let (v, g2) = f.sample_with_gradient(DVec2::new(10.0, -4.0));
        assert_eq!(v, 39.0);
        assert_eq!(g, g2);
        assert!(format!("{f:?}").contains("FnField"));
    }

    #[test]
    fn central_difference_of_quadratic_is_exact_enough() {
        let f = FnField::new(|p: DVec2| p.x * p.x + p.x * p.y);
        let p = DVec2::new(2.0, 5.0);
        let g = central_difference(&f, p, 0.5);
        // Central differences are exact for quadratics up to rounding.
        assert!((g - DVec2::new(2.0 * 2.0 + 5.0, 2.0)).length() < 1e-12);
        assert!(central_difference(&f, p, 0.0).is_nan());
    }

    #[test]
    #[allow(clippy::needless_borrows_for_generic_args)] // `&F` is what is tested
    fn pointer_types_are_fields() {
        fn takes<F: Field>(f: F) -> f64 {
            f.sample(DVec2::ZERO)
        }
        let c = Constant(2.0);
        assert_eq!(takes(&c), 2.0);
        assert_eq!(takes(Box::new(c)), 2.0);
        assert_eq!(takes(Arc::new(c)), 2.0);
        let dynamic: Box<dyn Field> = c.boxed();
        assert_eq!(takes(&dynamic), 2.0);
        let shared: Arc<dyn Field> = c.shared();
        assert_eq!(shared.gradient(DVec2::ONE), DVec2::ZERO);
        // Combinators work on trait objects too.
        let doubled = dynamic.scaled(2.0);
        assert_eq!(doubled.sample(DVec2::ZERO), 4.0);
        let maps: Vec<Box<dyn Field>> = vec![Constant(1.0).boxed(), doubled.boxed()];
        assert_eq!(maps[1].sample(DVec2::ONE), 4.0);
    }

    #[test]
    fn fields_are_send_and_sync() {
        fn check<T: Send + Sync>() {}
        check::<Box<dyn Field>>();
        check::<Arc<dyn Field>>();
        check::<Raster>();
        check::<Fbm>();
    }
}
