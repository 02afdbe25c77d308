//! Property tests for `polis_geom::field`: no field panics on any point (NaN, infinite,
//! huge, tiny), noise stays in range, exact gradients agree with central differences, and
//! bad parameters are errors, never panics.

#![allow(clippy::unwrap_used)]

use polis_geom::field::{
    Constant, Fbm, FbmParams, Field, FieldExt, Population, PopulationParams, Raster, SimplexNoise,
    central_difference,
};
use polis_geom::{Aabb2, DVec2};
use proptest::prelude::*;

/// Coordinates biased to the degenerate: NaN, ±∞, zero, lattice-like integers, huge and tiny
/// magnitudes, and ordinary city-scale values.
fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(0.0),
        1 => Just(-0.0),
        1 => Just(f64::MAX),
        1 => Just(f64::MIN_POSITIVE),
        2 => (-1000i64..1000).prop_map(|i| i as f64),
        2 => -1e300f64..1e300,
        2 => -1e12f64..1e12,
        6 => -1e5f64..1e5,
    ]
}

fn point() -> impl Strategy<Value = DVec2> {
    (coord(), coord()).prop_map(|(x, y)| DVec2::new(x, y))
}

fn finite_point() -> impl Strategy<Value = DVec2> {
    (-2e4f64..2e4, -2e4f64..2e4).prop_map(|(x, y)| DVec2::new(x, y))
}

fn raster() -> Raster {
    let extent = Aabb2::new(DVec2::new(-500.0, -300.0), DVec2::new(700.0, 900.0));
    Raster::from_fn(13, 7, extent, |c, r| ((c * 7 + r * 3) % 11) as f32 / 10.0).unwrap()
}

fn all_fields(seed: u64) -> Vec<Box<dyn Field>> {
    let fbm = Fbm::new(FbmParams {
        seed,
        ..FbmParams::default()
    })
    .unwrap();
    let pop = Population::new(PopulationParams {
        seed,
        unit_m: 100.0,
    })
    .unwrap();
    vec![
        Constant(0.5).boxed(),
        SimplexNoise::new(seed).boxed(),
        fbm.clone().boxed(),
        pop.clone().boxed(),
        raster().boxed(),
        fbm.clone()
            .scaled(3.0)
            .offset(-1.0)
            .clamped(0.0, 1.0)
            .boxed(),
        pop.clone()
            .threshold(0.2)
            .select(raster(), fbm.clone())
            .boxed(),
        fbm.clone().blend(pop.clone(), raster()).boxed(),
        pop.clone().min(fbm.clone()).max(Constant(-0.5)).boxed(),
        fbm.plus(pop.times(raster()))
            .magnified(3.0)
            .translated(DVec2::ONE)
            .boxed(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn nothing_panics_on_any_point(seed in any::<u64>(), p in point()) {
        for f in all_fields(seed) {
            let v = f.sample(p);
            let g = f.gradient(p);
            let (v2, g2) = f.sample_with_gradient(p);
            // Same answer through both entry points (NaN-aware).
            prop_assert!(v == v2 || (v.is_nan() && v2.is_nan()));
            prop_assert!(g == g2 || (g.is_nan() && g2.is_nan()), "{g} vs {g2}");
            if !p.is_nan() && p.is_finite() {
                // Finite points far from lattice precision limits give finite samples.
                if p.abs().max_element() < 1e9 {
                    prop_assert!(v.is_finite(), "{v} at {p}");
                }
            }
            if p.x.is_nan() || p.y.is_nan() {
                // Constant ignores the point; every other field says NaN.
                prop_assert!(v.is_nan() || v == 0.5);
            }
        }
    }

    #[test]
    fn noise_values_stay_in_range(seed in any::<u64>(), p in point()) {
        let n = SimplexNoise::new(seed).sample(p);
        prop_assert!(n.is_nan() || (-1.0..=1.0).contains(&n));
        let fbm = Fbm::new(FbmParams { seed, octaves: 4, ..FbmParams::default() }).unwrap();
        let v = fbm.sample(p);
        prop_assert!(v.is_nan() || (-1.0..=1.0).contains(&v));
        let pop = Population::new(PopulationParams { seed, unit_m: 37.0 }).unwrap();
        let d = pop.sample(p);
        prop_assert!(d.is_nan() || (0.0..=1.0).contains(&d));
        let r = raster().sample(p);
        prop_assert!(r.is_nan() || (0.0..=1.0).contains(&r));
    }

    #[test]
    fn exact_gradients_agree_with_central_differences(seed in any::<u64>(), p in finite_point()) {
        let simplex = SimplexNoise::new(seed).magnified(150.0);
        let fbm = Fbm::new(FbmParams { seed, octaves: 3, wavelength_m: 800.0, ..FbmParams::default() }).unwrap();
        let pop = Population::new(PopulationParams { seed, unit_m: 60.0 }).unwrap();
        let fields: [&dyn Field; 3] = [&simplex, &fbm, &pop];
        for f in fields {
            let exact = f.gradient(p);
            let numeric = central_difference(f, p, 1e-3);
            prop_assert!((exact - numeric).length() <= 1e-7 + 1e-4 * exact.length(),
                "{exact} vs {numeric} at {p}");
        }
    }

    #[test]
    fn same_seed_same_bits(seed in any::<u64>(), p in finite_point()) {
        let a = Fbm::new(FbmParams { seed, ..FbmParams::default() }).unwrap();
        let b = Fbm::new(FbmParams { seed, ..FbmParams::default() }).unwrap();
        prop_assert_eq!(a.sample(p).to_bits(), b.sample(p).to_bits());
        let pa = Population::new(PopulationParams { seed, unit_m: 100.0 }).unwrap();
        let pb = Population::new(PopulationParams { seed, unit_m: 100.0 }).unwrap();
        prop_assert_eq!(pa.sample(p).to_bits(), pb.sample(p).to_bits());
    }

    #[test]
    fn bad_parameters_are_errors(
        octaves in prop_oneof![Just(0u32), 0u32..40, Just(u32::MAX)],
        wavelength in coord(),
        lacunarity in coord(),
        gain in coord(),
        unit in coord(),
    ) {
        let r = Fbm::new(FbmParams { seed: 1, octaves, wavelength_m: wavelength, lacunarity, gain });
        if let Ok(f) = r {
            let v = f.sample(DVec2::new(12.0, 34.0));
            prop_assert!((-1.0..=1.0).contains(&v));
        }
        let r = Population::new(PopulationParams { seed: 1, unit_m: unit });
        prop_assert_eq!(r.is_ok(), unit.is_finite() && unit > 0.0);
    }

    #[test]
    fn raster_construction_never_panics(
        w in 0usize..6, h in 0usize..6, len in 0usize..40,
        a in point(), b in point(), v in coord(),
    ) {
        let r = Raster::new(w, h, Aabb2::new(a, b), vec![v as f32; len]);
        let texel = (b - a).abs() / DVec2::new(w.max(1) as f64, h.max(1) as f64);
        let valid = w > 0 && h > 0 && len == w * h && a.is_finite() && b.is_finite()
            && (v as f32).is_finite() && texel.is_finite() && texel.min_element() > 0.0;
        prop_assert_eq!(r.is_ok(), valid, "{:?}", r);
        if let Ok(r) = r {
            let s = r.sample((a + b) * 0.5);
            prop_assert!(s.is_finite());
        }
    }

}

#[cfg(feature = "png")]
mod png_props {
    use super::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn png_decoder_never_panics_on_garbage(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        let extent = Aabb2::new(DVec2::ZERO, DVec2::ONE);
        let _ = Raster::from_png_bytes(&bytes, extent);
        // A valid signature and header with garbage after it.
        let mut framed = b"\x89PNG\r\n\x1a\n".to_vec();
        framed.extend_from_slice(&bytes);
        let _ = Raster::from_png_bytes(&framed, extent);
    }
    }
}

#[test]
fn value_stability() {
    // Pinned outputs: change only with a note in the changelog (seeded maps must not drift).
    let n = SimplexNoise::new(42);
    let fbm = Fbm::new(FbmParams {
        seed: 42,
        ..FbmParams::default()
    })
    .unwrap();
    let pop = Population::new(PopulationParams {
        seed: 42,
        unit_m: 100.0,
    })
    .unwrap();
    let p = DVec2::new(0.37, -1.21);
    let q = DVec2::new(1234.5, -678.9);
    let got = [n.sample(p), fbm.sample(q), pop.sample(q)].map(f64::to_bits);
    assert_eq!(got, PINNED);
}

/// Simplex(42) at (0.37, -1.21), default fBm(42) and population(42) at (1234.5, -678.9).
const PINNED: [u64; 3] = [
    0x3fbf_f4fc_8abc_d99a,
    0x3fd6_6463_f094_1bc3,
    0x3fd3_7d35_5541_3fd9,
];
