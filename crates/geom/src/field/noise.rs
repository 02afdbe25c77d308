//! Seeded 2-D simplex noise and its fractal (fBm) sum, with exact gradients.
//!
//! The simplex lattice is Perlin's (2001) as explained by Gustavson (2005): the plane is
//! skewed so that equilateral triangles become half unit squares, each of the three corners
//! of the containing triangle contributes `(½ − |d|²)⁴ (g · d)` with a pseudo-random unit
//! gradient `g`, and the sum is scaled into `[-1, 1]`. Written here from the description,
//! with three choices of our own:
//!
//! * the permutation table is a Fisher–Yates shuffle driven by a `rand_pcg::Pcg64Mcg`
//!   seeded with the user's seed (only the generator's raw 64-bit output is used, so the
//!   table does not depend on `rand`'s sampling algorithms);
//! * the gradients are 16 unit vectors at multiples of 22.5° (isotropic enough for city
//!   maps, and no `sin`/`cos` at run time: they are literals);
//! * the scale factor is the exact bound `1 / max Σ (½ − |dᵢ|²)⁴ |dᵢ|` (the maximum sits at
//!   the midpoint of a triangle's long edge, where two corners contribute `(⅓)⁴ √⅙` each),
//!   so the value can never leave `[-1, 1]`.
//!
//! Evaluation uses `+ − × ÷` and `floor` only: results are bit-identical on every platform.

use std::f64::consts::FRAC_1_SQRT_2;

use glam::DVec2;
use rand_pcg::Pcg64Mcg;
use rand_pcg::rand_core::{Rng, SeedableRng};

use super::Field;
use crate::GeomError;

/// Skew factor `(√3 − 1) / 2`.
const F2: f64 = 0.366_025_403_784_438_6;
/// Unskew factor `(3 − √3) / 6`.
const G2: f64 = 0.211_324_865_405_187_13;
/// `1 / max_p Σᵢ (½ − |dᵢ|²)⁴ |dᵢ|` = 1 / 0.010080204702811…, rounded down a little so
/// rounding can never push a value past ±1.
const NORMALISE: f64 = 99.2;

/// 16 unit gradients, `(cos 22.5°·k, sin 22.5°·k)`.
const GRADIENTS: [[f64; 2]; 16] = [
    [1.0, 0.0],
    [0.923_879_532_511_286_7, 0.382_683_432_365_089_8],
    [FRAC_1_SQRT_2, FRAC_1_SQRT_2],
    [0.382_683_432_365_089_8, 0.923_879_532_511_286_7],
    [0.0, 1.0],
    [-0.382_683_432_365_089_8, 0.923_879_532_511_286_7],
    [-FRAC_1_SQRT_2, FRAC_1_SQRT_2],
    [-0.923_879_532_511_286_7, 0.382_683_432_365_089_8],
    [-1.0, 0.0],
    [-0.923_879_532_511_286_7, -0.382_683_432_365_089_8],
    [-FRAC_1_SQRT_2, -FRAC_1_SQRT_2],
    [-0.382_683_432_365_089_8, -0.923_879_532_511_286_7],
    [0.0, -1.0],
    [0.382_683_432_365_089_8, -0.923_879_532_511_286_7],
    [FRAC_1_SQRT_2, -FRAC_1_SQRT_2],
    [0.923_879_532_511_286_7, -0.382_683_432_365_089_8],
];

/// Seeded 2-D simplex noise in noise units: values in `[-1, 1]`, features about one unit
/// across, exact gradient.
///
/// As a [`Field`] it reads the point's coordinates directly as noise coordinates (one unit
/// per metre); use [`Fbm`] (which has a wavelength in metres) or
/// [`FieldExt::magnified`](super::FieldExt::magnified) for city-sized features.
///
/// The value is 0 at every lattice point, in particular at the origin, for every seed.
/// NaN or infinite points give NaN. Serialises as its seed.
///
/// ```
/// use polis_geom::DVec2;
/// use polis_geom::field::{Field, SimplexNoise};
///
/// let n = SimplexNoise::new(42);
/// let v = n.sample(DVec2::new(0.3, 1.7));
/// assert!((-1.0..=1.0).contains(&v));
/// assert_eq!(v, SimplexNoise::new(42).sample(DVec2::new(0.3, 1.7)));
/// ```
#[derive(Clone, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(from = "SimplexSeed", into = "SimplexSeed"))]
pub struct SimplexNoise {
    seed: u64,
    perm: [u8; 256],
}

/// The serialised form of [`SimplexNoise`].
#[derive(Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct SimplexSeed {
    seed: u64,
}

impl From<SimplexSeed> for SimplexNoise {
    fn from(s: SimplexSeed) -> Self {
        SimplexNoise::new(s.seed)
    }
}

impl From<SimplexNoise> for SimplexSeed {
    fn from(n: SimplexNoise) -> Self {
        SimplexSeed { seed: n.seed }
    }
}

impl std::fmt::Debug for SimplexNoise {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SimplexNoise")
            .field("seed", &self.seed)
            .finish_non_exhaustive()
    }
}

impl Default for SimplexNoise {
    fn default() -> Self {
        SimplexNoise::new(0)
    }
}

/// `⌊x⌋`, bit-identical to [`f64::floor`] (signed zeros and NaN included).
///
/// `f64::floor` is a libm call on the baseline x86-64 target (no SSE4.1 `roundsd`), and
/// it is a good part of a simplex sample; below 2⁵² truncation through `i64` is exact.
#[inline]
fn floor(x: f64) -> f64 {
    if x.abs() < 4_503_599_627_370_496.0 {
        let t = (x as i64) as f64;
        let f = if t > x { t - 1.0 } else { t };
        // ⌊-0.0⌋ = -0.0 and ⌊0.3⌋ = +0.0, as libm gives them.
        if f == 0.0 { f.copysign(x) } else { f }
    } else {
        x.floor()
    }
}

/// The value of one corner with gradient `g` at offset `d` from it: the same operations,
/// in the same order, as the value part of [`corner`].
#[inline]
fn corner_value(g: [f64; 2], dx: f64, dy: f64) -> f64 {
    let t = 0.5 - dx * dx - dy * dy;
    if t > 0.0 {
        let gd = g[0] * dx + g[1] * dy;
        let t2 = t * t;
        let t4 = t2 * t2;
        t4 * gd
    } else {
        0.0
    }
}

/// The containing simplex of `q`: the offsets from its three corners and their gradients.
#[derive(Clone, Copy)]
struct Simplex {
    d: [[f64; 2]; 3],
    g: [[f64; 2]; 3],
}

/// `(value, d value / d d)` of one corner with gradient `g` at offset `d` from the corner.
#[inline]
fn corner(g: [f64; 2], dx: f64, dy: f64) -> (f64, f64, f64) {
    let t = 0.5 - dx * dx - dy * dy;
    if t > 0.0 {
        let gd = g[0] * dx + g[1] * dy;
        let t2 = t * t;
        let t3 = t2 * t;
        let t4 = t2 * t2;
        // d/dd [t⁴ (g·d)] = t⁴ g − 8 t³ (g·d) d
        let k = 8.0 * t3 * gd;
        (t4 * gd, t4 * g[0] - k * dx, t4 * g[1] - k * dy)
    } else {
        (0.0, 0.0, 0.0)
    }
}

impl SimplexNoise {
    /// The noise of `seed`: its permutation table is shuffled by `Pcg64Mcg::seed_from_u64(seed)`.
    pub fn new(seed: u64) -> Self {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let mut perm = [0u8; 256];
        for (i, v) in (0u8..=255).zip(perm.iter_mut()) {
            *v = i;
        }
        // Fisher–Yates with a multiply-shift index: j = ⌊r · (i + 1) / 2³²⌋ ≤ i.
        for i in (1..perm.len()).rev() {
            let r = rng.next_u64() >> 32;
            let j = ((r * (i as u64 + 1)) >> 32) as usize;
            perm.swap(i, j);
        }
        SimplexNoise { seed, perm }
    }

    /// The seed this noise was built from.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Gradient index of lattice point `(i, j)` (both already reduced mod 256).
    #[inline]
    fn hash(&self, i: usize, j: usize) -> usize {
        let a = usize::from(self.perm[j & 255]);
        usize::from(self.perm[(i + a) & 255]) & 15
    }

    /// The noise value at `q` (noise units), in `[-1, 1]`: the value of
    /// [`value_and_gradient`](Self::value_and_gradient), bit for bit, without the
    /// gradient's arithmetic.
    pub fn value(&self, q: DVec2) -> f64 {
        if !q.is_finite() {
            return f64::NAN;
        }
        let Simplex { d, g } = self.simplex(q);
        let n0 = corner_value(g[0], d[0][0], d[0][1]);
        let n1 = corner_value(g[1], d[1][0], d[1][1]);
        let n2 = corner_value(g[2], d[2][0], d[2][1]);
        (NORMALISE * (n0 + n1 + n2)).clamp(-1.0, 1.0)
    }

    /// The noise value at `q` (noise units) and its exact gradient (per noise unit).
    pub fn value_and_gradient(&self, q: DVec2) -> (f64, DVec2) {
        if !q.is_finite() {
            return (f64::NAN, DVec2::NAN);
        }
        let Simplex { d, g } = self.simplex(q);
        let (n0, a0, b0) = corner(g[0], d[0][0], d[0][1]);
        let (n1, a1, b1) = corner(g[1], d[1][0], d[1][1]);
        let (n2, a2, b2) = corner(g[2], d[2][0], d[2][1]);
        let value = (NORMALISE * (n0 + n1 + n2)).clamp(-1.0, 1.0);
        let gradient = DVec2::new(a0 + a1 + a2, b0 + b1 + b2) * NORMALISE;
        (value, gradient)
    }

    /// The simplex containing the finite point `q`.
    #[inline(always)]
    fn simplex(&self, q: DVec2) -> Simplex {
        let (x, y) = (q.x, q.y);
        // Skew to find the containing half-square of the simplex grid.
        let s = (x + y) * F2;
        let i = floor(x + s);
        let j = floor(y + s);
        let t = (i + j) * G2;
        // Offset from the first corner, unskewed.
        let x0 = x - (i - t);
        let y0 = y - (j - t);
        let (i1, j1) = if x0 > y0 { (1usize, 0usize) } else { (0, 1) };
        let x1 = x0 - i1 as f64 + G2;
        let y1 = y0 - j1 as f64 + G2;
        let x2 = x0 - 1.0 + 2.0 * G2;
        let y2 = y0 - 1.0 + 2.0 * G2;
        // Lattice coordinates mod 256 (saturating casts: huge or NaN inputs cannot panic).
        let ii = ((i as i64) & 255) as usize;
        let jj = ((j as i64) & 255) as usize;
        Simplex {
            d: [[x0, y0], [x1, y1], [x2, y2]],
            g: [
                GRADIENTS[self.hash(ii, jj)],
                GRADIENTS[self.hash(ii + i1, jj + j1)],
                GRADIENTS[self.hash(ii + 1, jj + 1)],
            ],
        }
    }
}

impl Field for SimplexNoise {
    fn sample(&self, p: DVec2) -> f64 {
        self.value(p)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.value_and_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        self.value_and_gradient(p)
    }
}

/// The most octaves an [`Fbm`] accepts.
pub const MAX_OCTAVES: u32 = 24;

/// Parameters of fractal Brownian motion noise ([`Fbm`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct FbmParams {
    /// Seed of the octaves' permutation tables and offsets. Default: 0.
    pub seed: u64,
    /// Number of simplex octaves summed, 1 to [`MAX_OCTAVES`]. Default: 5.
    pub octaves: u32,
    /// Wavelength of the first (coarsest) octave in metres: one noise unit. Default: 1000.
    pub wavelength_m: f64,
    /// Frequency ratio between successive octaves (> 0). Default: 2.
    pub lacunarity: f64,
    /// Amplitude ratio between successive octaves (≥ 0). Default: 0.5.
    pub gain: f64,
}

impl Default for FbmParams {
    fn default() -> Self {
        FbmParams {
            seed: 0,
            octaves: 5,
            wavelength_m: 1000.0,
            lacunarity: 2.0,
            gain: 0.5,
        }
    }
}

#[derive(Clone, PartialEq)]
struct Octave {
    noise: SimplexNoise,
    /// Noise units per metre.
    frequency: f64,
    /// Weight, already divided by the sum of all weights.
    weight: f64,
    /// Offset in noise units, so octaves do not share their zero at the origin.
    offset: DVec2,
}

/// Fractal Brownian motion: `Σₖ gainᵏ · simplexₖ(p · lacunarityᵏ / wavelength + oₖ)`
/// divided by `Σₖ gainᵏ`, so values stay in `[-1, 1]`; exact gradient (per metre).
///
/// Octave `k` has its own permutation table and a random offset `oₖ ∈ [0, 256)²` noise
/// units, both drawn from `Pcg64Mcg::seed_from_u64(seed)`. NaN or infinite points give
/// NaN. Serialises as its [`FbmParams`].
#[derive(Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "FbmParams", into = "FbmParams"))]
pub struct Fbm {
    params: FbmParams,
    octaves: Vec<Octave>,
}

impl std::fmt::Debug for Fbm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Fbm")
            .field("params", &self.params)
            .finish_non_exhaustive()
    }
}

impl TryFrom<FbmParams> for Fbm {
    type Error = GeomError;
    fn try_from(params: FbmParams) -> Result<Self, GeomError> {
        Fbm::new(params)
    }
}

impl From<Fbm> for FbmParams {
    fn from(f: Fbm) -> Self {
        f.params
    }
}

fn invalid(name: &'static str, reason: String) -> GeomError {
    GeomError::InvalidParameter { name, reason }
}

impl Fbm {
    /// Builds the octaves; rejects out-of-range parameters with
    /// [`GeomError::InvalidParameter`].
    pub fn new(params: FbmParams) -> Result<Self, GeomError> {
        if params.octaves == 0 || params.octaves > MAX_OCTAVES {
            return Err(invalid(
                "octaves",
                format!(
                    "{} octaves requested; use 1 to {MAX_OCTAVES}",
                    params.octaves
                ),
            ));
        }
        if !(params.wavelength_m.is_finite() && params.wavelength_m > 0.0) {
            return Err(invalid(
                "wavelength_m",
                format!("{} m is not a positive finite length", params.wavelength_m),
            ));
        }
        if !(params.lacunarity.is_finite() && params.lacunarity > 0.0) {
            return Err(invalid(
                "lacunarity",
                format!("{} must be a positive finite ratio", params.lacunarity),
            ));
        }
        if !(params.gain.is_finite() && params.gain >= 0.0) {
            return Err(invalid(
                "gain",
                format!("{} must be a finite ratio >= 0", params.gain),
            ));
        }
        let mut rng = Pcg64Mcg::seed_from_u64(params.seed);
        let mut octaves = Vec::with_capacity(params.octaves as usize);
        let mut frequency = 1.0 / params.wavelength_m;
        let mut amplitude = 1.0;
        let mut total = 0.0;
        for _ in 0..params.octaves {
            let noise = SimplexNoise::new(rng.next_u64());
            // 53 random bits → [0, 256).
            let mut unit = || (rng.next_u64() >> 11) as f64 * (256.0 / (1u64 << 53) as f64);
            let offset = DVec2::new(unit(), unit());
            octaves.push(Octave {
                noise,
                frequency,
                weight: amplitude,
                offset,
            });
            total += amplitude;
            frequency *= params.lacunarity;
            amplitude *= params.gain;
        }
        let finest = octaves.last().map_or(0.0, |o| o.frequency);
        if !(finest.is_finite() && finest > 0.0 && finest < 1e15) {
            return Err(invalid(
                "lacunarity",
                format!(
                    "the finest octave's frequency {finest} per metre is out of range; use fewer octaves or a lacunarity nearer 1"
                ),
            ));
        }
        if !(total.is_finite() && total > 0.0) {
            return Err(invalid(
                "gain",
                format!("the octave weights sum to {total}; use a smaller gain or fewer octaves"),
            ));
        }
        for o in &mut octaves {
            o.weight /= total;
        }
        Ok(Fbm { params, octaves })
    }

    /// The parameters this noise was built from.
    pub fn params(&self) -> &FbmParams {
        &self.params
    }
}

impl Field for Fbm {
    fn sample(&self, p: DVec2) -> f64 {
        let mut v = 0.0;
        for o in &self.octaves {
            v += o.weight * o.noise.value(p * o.frequency + o.offset);
        }
        v.clamp(-1.0, 1.0)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.sample_with_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let mut v = 0.0;
        let mut g = DVec2::ZERO;
        for o in &self.octaves {
            let (n, dn) = o.noise.value_and_gradient(p * o.frequency + o.offset);
            v += o.weight * n;
            g += dn * (o.weight * o.frequency);
        }
        (v.clamp(-1.0, 1.0), g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::central_difference;
    use rand_pcg::Pcg64;

    fn random_points(seed: u64, n: usize, spread: f64) -> Vec<DVec2> {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut unit = move || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        (0..n)
            .map(|_| DVec2::new(unit() * 2.0 - 1.0, unit() * 2.0 - 1.0) * spread)
            .collect()
    }

    #[test]
    fn gradient_table_is_unit_length() {
        for g in GRADIENTS {
            assert!((g[0] * g[0] + g[1] * g[1] - 1.0).abs() < 1e-15);
        }
        assert!((F2 - (3f64.sqrt() - 1.0) / 2.0).abs() < 1e-16);
        assert!((G2 - (3.0 - 3f64.sqrt()) / 6.0).abs() < 1e-16);
    }

    #[test]
    fn normalisation_bound_holds_at_the_worst_point() {
        // The worst case: the midpoint of the edge shared by the two triangles of a skewed
        // unit square, gradients aligned with the offsets. The edge has length √(2/3), so
        // both end corners are at d² = 1/6 and the third corners of both triangles at the
        // triangle height √(1/2), where they vanish.
        let side2: f64 = 2.0 / 3.0;
        let d2 = side2 / 4.0;
        let worst = 2.0 * (0.5 - d2).powi(4) * d2.sqrt();
        assert!(NORMALISE * worst <= 1.0);
        assert!(NORMALISE * worst > 0.9999);
        // Scan one simplex for the bound (only its three corners reach into it).
        let corners = [
            DVec2::ZERO,
            DVec2::new(1.0 - G2, -G2),
            DVec2::new(1.0 - 2.0 * G2, 1.0 - 2.0 * G2),
        ];
        let m = 300;
        let mut best: f64 = 0.0;
        for a in 0..=m {
            for b in 0..=(m - a) {
                let (u, v) = (a as f64 / m as f64, b as f64 / m as f64);
                let p = corners[0] * u + corners[1] * v + corners[2] * (1.0 - u - v);
                let s: f64 = corners
                    .iter()
                    .map(|&c| {
                        let d = p - c;
                        let t = (0.5 - d.length_squared()).max(0.0);
                        t.powi(4) * d.length()
                    })
                    .sum();
                best = best.max(s);
            }
        }
        assert!(best <= worst + 1e-15, "{best} > {worst}");
    }

    #[test]
    fn fast_floor_is_bit_identical_to_libm() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.3,
            -0.3,
            1.0,
            -1.0,
            0.999_999_999_999_999_9,
            -0.999_999_999_999_999_9,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            4_503_599_627_370_496.0,
            -4_503_599_627_370_497.0,
            9.3e18,
            -9.3e18,
            1e300,
            -1e300,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        xs.extend(
            random_points(31, 50_000, 1e3)
                .iter()
                .flat_map(|p| [p.x, p.y]),
        );
        xs.extend(
            random_points(32, 5_000, 1e16)
                .iter()
                .flat_map(|p| [p.x, p.y]),
        );
        for i in -300..300 {
            let k = f64::from(i);
            xs.extend([k, k.next_up(), k.next_down(), k + 0.5]);
        }
        for x in xs {
            assert_eq!(floor(x).to_bits(), x.floor().to_bits(), "floor({x:e})");
        }
    }

    #[test]
    fn value_is_the_value_of_value_and_gradient_bit_for_bit() {
        let n = SimplexNoise::new(17);
        let mut pts = random_points(12, 50_000, 300.0);
        pts.extend(random_points(13, 2_000, 1e12));
        pts.extend([
            DVec2::ZERO,
            DVec2::new(-0.0, 0.0),
            DVec2::new(1.0 - G2, -G2),
        ]);
        for p in pts {
            assert_eq!(
                n.value(p).to_bits(),
                n.value_and_gradient(p).0.to_bits(),
                "at {p}"
            );
        }
        assert!(n.value(DVec2::new(f64::INFINITY, 0.0)).is_nan());
    }

    #[test]
    fn simplex_range_and_spread() {
        let n = SimplexNoise::new(1);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in random_points(9, 200_000, 300.0) {
            let v = n.value(p);
            assert!((-1.0..=1.0).contains(&v), "{v} at {p}");
            lo = lo.min(v);
            hi = hi.max(v);
        }
        // The noise uses most of its range.
        assert!(lo < -0.85 && hi > 0.85, "range [{lo}, {hi}]");
    }

    #[test]
    fn simplex_is_zero_on_lattice_points_and_continuous() {
        let n = SimplexNoise::new(5);
        assert_eq!(n.value(DVec2::ZERO), 0.0);
        // Lattice point (1, 0) of the skewed grid, unskewed.
        let t = G2;
        assert!(n.value(DVec2::new(1.0 - t, -t)).abs() < 1e-12);
        // Continuity: tiny steps give tiny changes (no jumps at simplex borders).
        for p in random_points(3, 5_000, 20.0) {
            let d = (n.value(p + DVec2::splat(1e-7)) - n.value(p)).abs();
            assert!(d < 1e-4, "jump {d} at {p}");
        }
    }

    #[test]
    fn simplex_gradient_matches_central_differences() {
        let n = SimplexNoise::new(77);
        for p in random_points(4, 2_000, 50.0) {
            let exact = n.gradient(p);
            let numeric = central_difference(&n, p, 1e-5);
            assert!(
                (exact - numeric).length() < 1e-5 * (1.0 + exact.length()),
                "{exact} vs {numeric} at {p}"
            );
        }
    }

    #[test]
    fn seeds_are_deterministic_and_distinct() {
        let pts = random_points(11, 64, 40.0);
        let a: Vec<f64> = pts.iter().map(|&p| SimplexNoise::new(3).value(p)).collect();
        let b: Vec<f64> = pts.iter().map(|&p| SimplexNoise::new(3).value(p)).collect();
        let c: Vec<f64> = pts.iter().map(|&p| SimplexNoise::new(4).value(p)).collect();
        assert_eq!(a, b);
        assert!(a.iter().zip(&c).filter(|(x, y)| x != y).count() > 60);
        assert_ne!(SimplexNoise::new(3), SimplexNoise::new(4));
    }

    #[test]
    fn permutation_is_a_permutation() {
        let n = SimplexNoise::new(123);
        let mut seen = [false; 256];
        for &v in &n.perm {
            seen[usize::from(v)] = true;
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn non_finite_and_huge_points() {
        let n = SimplexNoise::new(0);
        assert!(n.value(DVec2::new(f64::NAN, 0.0)).is_nan());
        assert!(n.gradient(DVec2::new(0.0, f64::NAN)).is_nan());
        assert!(n.value(DVec2::new(f64::INFINITY, 0.0)).is_nan());
        for &x in &[1e9, -1e12, 1e18, 1e300, f64::MAX] {
            let v = n.value(DVec2::new(x, -x * 0.5));
            assert!(v.is_nan() || (-1.0..=1.0).contains(&v));
        }
    }

    #[test]
    fn fbm_range_gradient_and_determinism() {
        let f = Fbm::new(FbmParams {
            seed: 9,
            octaves: 6,
            wavelength_m: 500.0,
            ..FbmParams::default()
        })
        .unwrap();
        for p in random_points(21, 20_000, 20_000.0) {
            let v = f.sample(p);
            assert!((-1.0..=1.0).contains(&v));
        }
        for p in random_points(22, 500, 5_000.0) {
            let (v, g) = f.sample_with_gradient(p);
            assert_eq!(v, f.sample(p));
            let numeric = central_difference(&f, p, 1e-3);
            assert!(
                (g - numeric).length() < 1e-6 + 1e-4 * g.length(),
                "{g} vs {numeric}"
            );
        }
        let again = Fbm::new(*f.params()).unwrap();
        let other = Fbm::new(FbmParams {
            seed: 10,
            ..*f.params()
        })
        .unwrap();
        let p = DVec2::new(123.0, 456.0);
        assert_eq!(f.sample(p), again.sample(p));
        assert_ne!(f.sample(p), other.sample(p));
        // The octave offsets move the zero away from the origin.
        assert_ne!(f.sample(DVec2::ZERO), 0.0);
    }

    #[test]
    fn fbm_single_octave_is_scaled_simplex() {
        let f = Fbm::new(FbmParams {
            octaves: 1,
            wavelength_m: 100.0,
            ..FbmParams::default()
        })
        .unwrap();
        let o = &f.octaves[0];
        let p = DVec2::new(37.0, -12.5);
        assert_eq!(f.sample(p), o.noise.value(p / 100.0 + o.offset));
        assert_eq!(o.weight, 1.0);
    }

    #[test]
    fn fbm_rejects_bad_params() {
        let bad = [
            FbmParams {
                octaves: 0,
                ..FbmParams::default()
            },
            FbmParams {
                octaves: MAX_OCTAVES + 1,
                ..FbmParams::default()
            },
            FbmParams {
                wavelength_m: 0.0,
                ..FbmParams::default()
            },
            FbmParams {
                wavelength_m: f64::NAN,
                ..FbmParams::default()
            },
            FbmParams {
                lacunarity: -2.0,
                ..FbmParams::default()
            },
            FbmParams {
                lacunarity: 1e300,
                octaves: 3,
                ..FbmParams::default()
            },
            FbmParams {
                gain: f64::INFINITY,
                ..FbmParams::default()
            },
            FbmParams {
                gain: 1e300,
                octaves: 3,
                ..FbmParams::default()
            },
        ];
        for p in bad {
            assert!(
                matches!(Fbm::new(p), Err(GeomError::InvalidParameter { .. })),
                "{p:?}"
            );
        }
    }

    #[test]
    fn serde_round_trips() {
        let n = SimplexNoise::new(99);
        let json = serde_json::to_string(&n).unwrap();
        assert_eq!(json, r#"{"seed":99}"#);
        let back: SimplexNoise = serde_json::from_str(&json).unwrap();
        assert_eq!(back, n);
        let f = Fbm::new(FbmParams {
            seed: 5,
            ..FbmParams::default()
        })
        .unwrap();
        let json = serde_json::to_string(&f).unwrap();
        let back: Fbm = serde_json::from_str(&json).unwrap();
        assert_eq!(back, f);
        let defaults: FbmParams = serde_json::from_str("{}").unwrap();
        assert_eq!(defaults, FbmParams::default());
        assert!(serde_json::from_str::<Fbm>(r#"{"octaves":0}"#).is_err());
    }
}
