//! The population-density map of the priority-queue slides: three layers of simplex noise.

use glam::DVec2;

use super::{Field, SimplexNoise};
use crate::GeomError;

/// Parameters of [`Population`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct PopulationParams {
    /// Seed of the simplex noise shared by the three layers. Default: 0.
    pub seed: u64,
    /// Metres per *slide unit*: the slides evaluate `populationAt(x, y)` in units where
    /// `x / 10` is a noise coordinate, so the finest layer's noise unit is `10 · unit_m`
    /// metres and the two coarse layers' is `20 · unit_m`. With the default, density
    /// features are roughly one to two kilometres across, a good size for a city of a few
    /// kilometres. (The slides' demo source divides by 10 000 and 20 000 instead of 10 and
    /// 20, with 300-unit street segments: `unit_m = 1000` reproduces its scale when a demo
    /// unit is read as one metre.) Must be finite and positive. Default: 100.
    pub unit_m: f64,
}

impl Default for PopulationParams {
    fn default() -> Self {
        PopulationParams {
            seed: 0,
            unit_m: 100.0,
        }
    }
}

/// The slides' layered-simplex population density, in `[0, 1]`, with exact gradient.
///
/// With `(x, y) = p / unit_m` (slide units) and `simplex2` = [`SimplexNoise`] of `seed`:
///
/// ```text
/// value1 = simplex2(x / 10      , y / 10      ) / 2 + 0.5
/// value2 = simplex2(x / 20 + 0.5, y / 20 + 0.5) / 2 + 0.5
/// value3 = simplex2(x / 20 + 1.0, y / 20 + 1.0) / 2 + 0.5
/// populationAt(x, y) = ((value1 · value2 + value3) / 2)²
/// ```
///
/// This is the slides' formula term for term; only the simplex noise is this crate's, so
/// the numbers differ from the JavaScript demo's while the statistics (the squared average
/// pushing most of the map to low density with a few dense peaks) are the same. Density is
/// what Parish & Müller's highways climb (§3.2.1) and what lets streets branch.
///
/// NaN or infinite points give NaN. Serialises as its [`PopulationParams`].
///
/// ```
/// use polis_geom::DVec2;
/// use polis_geom::field::{Field, Population, PopulationParams};
///
/// let pop = Population::new(PopulationParams { seed: 1, unit_m: 100.0 })?;
/// let d = pop.sample(DVec2::new(250.0, 800.0));
/// assert!((0.0..=1.0).contains(&d));
/// # Ok::<(), polis_geom::GeomError>(())
/// ```
#[derive(Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(try_from = "PopulationParams", into = "PopulationParams")
)]
pub struct Population {
    params: PopulationParams,
    noise: SimplexNoise,
}

impl std::fmt::Debug for Population {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Population")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl TryFrom<PopulationParams> for Population {
    type Error = GeomError;
    fn try_from(params: PopulationParams) -> Result<Self, GeomError> {
        Population::new(params)
    }
}

impl From<Population> for PopulationParams {
    fn from(p: Population) -> Self {
        p.params
    }
}

impl Population {
    /// The population map of `params`; `unit_m` must be finite and positive.
    pub fn new(params: PopulationParams) -> Result<Self, GeomError> {
        if !(params.unit_m.is_finite() && params.unit_m > 0.0) {
            return Err(GeomError::InvalidParameter {
                name: "unit_m",
                reason: format!(
                    "{} m per slide unit is not a positive finite length",
                    params.unit_m
                ),
            });
        }
        Ok(Population {
            params,
            noise: SimplexNoise::new(params.seed),
        })
    }

    /// The parameters this map was built from.
    pub fn params(&self) -> &PopulationParams {
        &self.params
    }

    /// The slides' `populationAt(x, y)` in slide units (no metre scaling).
    pub fn population_at(&self, x: f64, y: f64) -> f64 {
        self.eval(DVec2::new(x, y), 1.0).0
    }

    /// Value and gradient (per metre) at `p`, with `unit` metres per slide unit.
    fn eval(&self, p: DVec2, unit: f64) -> (f64, DVec2) {
        let s = p / unit;
        let (n1, g1) = self.noise.value_and_gradient(s / 10.0);
        let (n2, g2) = self.noise.value_and_gradient(s / 20.0 + DVec2::splat(0.5));
        let (n3, g3) = self.noise.value_and_gradient(s / 20.0 + DVec2::splat(1.0));
        let v1 = n1 / 2.0 + 0.5;
        let v2 = n2 / 2.0 + 0.5;
        let v3 = n3 / 2.0 + 0.5;
        let m = (v1 * v2 + v3) / 2.0;
        // Chain rule: d v1/dp = g1 / 2 / (10 unit), d v2,3/dp = g2,3 / 2 / (20 unit).
        let dv1 = g1 / (20.0 * unit);
        let dv2 = g2 / (40.0 * unit);
        let dv3 = g3 / (40.0 * unit);
        // d(m²) = 2m · dm, dm = (dv1 v2 + v1 dv2 + dv3) / 2.
        let grad = (dv1 * v2 + dv2 * v1 + dv3) * m;
        (m * m, grad)
    }
}

impl Population {
    /// The value of [`eval`](Self::eval), bit for bit, without the gradient's arithmetic.
    fn value(&self, p: DVec2, unit: f64) -> f64 {
        let s = p / unit;
        let v1 = self.noise.value(s / 10.0) / 2.0 + 0.5;
        let v2 = self.noise.value(s / 20.0 + DVec2::splat(0.5)) / 2.0 + 0.5;
        let v3 = self.noise.value(s / 20.0 + DVec2::splat(1.0)) / 2.0 + 0.5;
        let m = (v1 * v2 + v3) / 2.0;
        m * m
    }
}

impl Field for Population {
    fn sample(&self, p: DVec2) -> f64 {
        self.value(p, self.params.unit_m)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.eval(p, self.params.unit_m).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        self.eval(p, self.params.unit_m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::central_difference;

    fn grid(n: usize, step: f64) -> impl Iterator<Item = DVec2> {
        (0..n).flat_map(move |i| {
            (0..n).map(move |j| DVec2::new(i as f64 * step - 7.3e3, j as f64 * step - 4.1e3))
        })
    }

    #[test]
    fn matches_the_slides_formula_term_for_term() {
        let pop = Population::new(PopulationParams {
            seed: 3,
            unit_m: 50.0,
        })
        .unwrap();
        let simplex2 = SimplexNoise::new(3);
        for p in grid(20, 173.0) {
            let (x, y) = (p.x / 50.0, p.y / 50.0);
            let value1 = simplex2.value(DVec2::new(x / 10.0, y / 10.0)) / 2.0 + 0.5;
            let value2 = simplex2.value(DVec2::new(x / 20.0 + 0.5, y / 20.0 + 0.5)) / 2.0 + 0.5;
            let value3 = simplex2.value(DVec2::new(x / 20.0 + 1.0, y / 20.0 + 1.0)) / 2.0 + 0.5;
            let expected = ((value1 * value2 + value3) / 2.0).powi(2);
            assert!((pop.sample(p) - expected).abs() < 1e-15);
            assert!((pop.population_at(x, y) - expected).abs() < 1e-15);
        }
    }

    #[test]
    fn range_statistics_and_gradient() {
        let pop = Population::new(PopulationParams::default()).unwrap();
        let mut sum = 0.0;
        let mut count = 0.0;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in grid(120, 97.0) {
            let (v, g) = pop.sample_with_gradient(p);
            assert!((0.0..=1.0).contains(&v));
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v;
            count += 1.0;
            let numeric = central_difference(&pop, p, 1e-3);
            assert!(
                (g - numeric).length() < 1e-9 + 1e-5 * g.length(),
                "{g} vs {numeric} at {p}"
            );
        }
        // ((v1 v2 + v3) / 2)² with v ≈ ½ on average: mean near (3/8)² ≈ 0.14, with spread.
        let mean = sum / count;
        assert!((0.08..0.25).contains(&mean), "mean {mean}");
        assert!(hi - lo > 0.3, "[{lo}, {hi}]");
    }

    #[test]
    fn sample_is_the_value_of_sample_with_gradient_bit_for_bit() {
        let pop = Population::new(PopulationParams::default()).unwrap();
        for p in grid(150, 61.7) {
            assert_eq!(
                pop.sample(p).to_bits(),
                pop.sample_with_gradient(p).0.to_bits(),
                "at {p}"
            );
        }
        assert!(pop.sample(DVec2::new(0.0, f64::INFINITY)).is_nan());
    }

    #[test]
    fn unit_scales_the_map() {
        let a = Population::new(PopulationParams {
            seed: 8,
            unit_m: 100.0,
        })
        .unwrap();
        let b = Population::new(PopulationParams {
            seed: 8,
            unit_m: 400.0,
        })
        .unwrap();
        for p in grid(10, 311.0) {
            assert!((a.sample(p) - b.sample(p * 4.0)).abs() < 1e-12);
            assert!((a.gradient(p) - b.gradient(p * 4.0) * 4.0).length() < 1e-12);
        }
    }

    #[test]
    fn seeds_and_bad_params() {
        let p = DVec2::new(1234.0, 567.0);
        let a = Population::new(PopulationParams {
            seed: 1,
            unit_m: 100.0,
        })
        .unwrap();
        let b = Population::new(PopulationParams {
            seed: 2,
            unit_m: 100.0,
        })
        .unwrap();
        assert_ne!(a.sample(p), b.sample(p));
        assert_eq!(a.sample(p), a.clone().sample(p));
        for unit_m in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(Population::new(PopulationParams { seed: 0, unit_m }).is_err());
        }
        assert!(a.sample(DVec2::new(f64::NAN, 0.0)).is_nan());
        let json = serde_json::to_string(&a).unwrap();
        assert_eq!(json, r#"{"seed":1,"unit_m":100.0}"#);
        assert_eq!(serde_json::from_str::<Population>(&json).unwrap(), a);
        assert!(serde_json::from_str::<Population>(r#"{"unit_m":-3}"#).is_err());
    }
}
