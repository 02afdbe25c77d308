//! [`LazyLattice`]: a map sampled on a square lattice, lazily and once per lattice point,
//! and interpolated bilinearly between lattice points.
//!
//! The procedural maps of [`RoadInputs::procedural`](crate::RoadInputs::procedural) are
//! fractal noise, and the local constraints sample water every
//! [`legality_step_m`](crate::RoadParams::legality_step_m) (and elevation every
//! [`slope_step_m`](crate::RoadParams::slope_step_m)) along every proposed segment: about
//! 600,000 samples of four-octave noise for 15,000 segments. Many samples share a lattice
//! cell (40 m by default), so evaluated once per lattice point the noise costs a seventh
//! of the evaluations (measured for the benchmark's 15,000 segments: ~90,000 lattice
//! points for both maps), and each sample becomes four memory reads and a bilinear blend.
//!
//! The lattice is a *definition*, not an approximation of one: a `LazyLattice` is the
//! function "bilinear interpolation of the source's values at the points `(i·s, j·s)`",
//! the same everywhere, whichever points were cached and in whatever order they were
//! asked for. So a network tested against the lattice map is tested against exactly the
//! map it was grown on.

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering};

use polis_geom::{Aabb2, DVec2, Field};

use crate::error::{Result, RoadError};

/// The most lattice points a [`LazyLattice`] caches (4 bytes each): 16 MiB.
pub const MAX_CACHED_POINTS: usize = 1 << 22;

/// A cache slot not computed yet: a NaN bit pattern that is never stored (NaN source
/// values are stored as the canonical `f32::NAN`).
const EMPTY: u32 = u32::MAX;

/// `2⁵²`: below it, `f64 → i64 → f64` truncation is exact.
const EXACT_INT: f64 = 4_503_599_627_370_496.0;

/// `⌊x⌋` for `|x| < 2⁵²` without the libm call of [`f64::floor`] (which the baseline
/// x86-64 target does not inline); the caller checks the range.
#[inline]
fn floor_small(x: f64) -> f64 {
    let t = (x as i64) as f64;
    if t > x { t - 1.0 } else { t }
}

/// A [`Field`] that is the bilinear interpolation of `source` on the square lattice
/// `{(i·s, j·s)}` (`s` = spacing, `i`, `j` integers), with the lattice values computed on
/// first use and kept (as `f32`) for the lattice points inside a window.
///
/// * **Value.** At `p`, with `(i, j) = ⌊p / s⌋` and `(fx, fy)` the fractions inside that
///   cell, `(1−fy)·((1−fx)·v(i,j) + fx·v(i+1,j)) + fy·((1−fx)·v(i,j+1) + fx·v(i+1,j+1))`,
///   where `v` is the source's value at the lattice point rounded to `f32` (a NaN value
///   stays NaN). It is continuous, exact at lattice points, and within each cell lies
///   between the cell's smallest and largest corner value.
/// * **Deterministic and thread-safe.** A lattice value depends only on the source and the
///   lattice point, never on which points were asked for before; concurrent first uses
///   store the same bits. Cached or not, a point samples to the same bits.
/// * **Cost.** A cached sample is four loads and a blend; the source is evaluated at most
///   once per lattice point of the window. Outside the window (and for the lattice points
///   beyond [`MAX_CACHED_POINTS`]) the corners are evaluated on every sample: correct,
///   four times slower than the source.
/// * **Edge cases.** A point with a NaN or infinite coordinate, or one more than `2⁵²`
///   spacings from the origin, is passed to the source unchanged.
/// * **Gradient:** central differences (the default of [`Field`]); it jumps across cell
///   borders, as the bilinear surface's slope does.
pub struct LazyLattice {
    source: Arc<dyn Field>,
    spacing: f64,
    inv: f64,
    /// Lowest cached lattice point and the window's size in lattice points.
    i0: i64,
    j0: i64,
    nx: i64,
    ny: i64,
    /// `f32` bits of lattice point `(i0 + a, j0 + b)` at `b · nx + a`, or [`EMPTY`].
    cache: Box<[AtomicU32]>,
    evaluated: AtomicUsize,
}

impl std::fmt::Debug for LazyLattice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LazyLattice")
            .field("spacing", &self.spacing)
            .field("window", &(self.i0, self.j0, self.nx, self.ny))
            .field("evaluated", &self.evaluated())
            .finish_non_exhaustive()
    }
}

impl LazyLattice {
    /// The lattice of `source` with spacing `spacing_m` metres, caching the lattice points
    /// of `window` (grown by one spacing), unless the window has more than
    /// [`MAX_CACHED_POINTS`] of them or is not finite: then nothing is cached.
    ///
    /// # Errors
    /// [`RoadError::InvalidParameter`] if `spacing_m` is not finite and positive.
    pub fn new(source: Arc<dyn Field>, spacing_m: f64, window: Aabb2) -> Result<Self> {
        if !(spacing_m.is_finite() && spacing_m > 0.0) {
            return Err(RoadError::InvalidParameter {
                name: "spacing_m",
                reason: format!("{spacing_m} m is not a lattice spacing; use a finite length > 0"),
            });
        }
        let inv = 1.0 / spacing_m;
        let lo = (window.min * inv).floor() - DVec2::ONE;
        let hi = (window.max * inv).floor() + DVec2::splat(2.0);
        let size = hi - lo + DVec2::ONE;
        let fits = lo.is_finite()
            && hi.is_finite()
            && lo.abs().max_element() < EXACT_INT
            && hi.abs().max_element() < EXACT_INT
            && size.min_element() >= 1.0
            && size.x * size.y <= MAX_CACHED_POINTS as f64;
        let (i0, j0, nx, ny) = if fits {
            (lo.x as i64, lo.y as i64, size.x as i64, size.y as i64)
        } else {
            (0, 0, 0, 0)
        };
        let n = usize::try_from(nx.saturating_mul(ny)).unwrap_or(0);
        let cache = (0..n).map(|_| AtomicU32::new(EMPTY)).collect();
        Ok(LazyLattice {
            source,
            spacing: spacing_m,
            inv,
            i0,
            j0,
            nx,
            ny,
            cache,
            evaluated: AtomicUsize::new(0),
        })
    }

    /// The lattice spacing in metres.
    pub fn spacing(&self) -> f64 {
        self.spacing
    }

    /// How many times the source was evaluated at a lattice point so far (cached points
    /// count once; points outside the window count at every use).
    pub fn evaluated(&self) -> usize {
        self.evaluated.load(Ordering::Relaxed)
    }

    /// The number of lattice points the cache can hold.
    pub fn cached_capacity(&self) -> usize {
        self.cache.len()
    }

    /// The source at lattice point `(i, j)`, rounded to `f32`.
    fn evaluate(&self, i: i64, j: i64) -> f32 {
        self.evaluated.fetch_add(1, Ordering::Relaxed);
        let p = DVec2::new(i as f64 * self.spacing, j as f64 * self.spacing);
        let v = self.source.sample(p) as f32;
        if v.is_nan() { f32::NAN } else { v }
    }

    /// The four corner values of cell `(i, j)`, computing the missing ones (the slow
    /// path, kept out of line so that the cached path stays small).
    #[cold]
    #[inline(never)]
    fn corners(&self, i: i64, j: i64) -> [f64; 4] {
        [
            self.value(i, j),
            self.value(i + 1, j),
            self.value(i, j + 1),
            self.value(i + 1, j + 1),
        ]
    }

    /// The lattice value at `(i, j)`, from the cache when the point is in the window.
    #[inline]
    fn value(&self, i: i64, j: i64) -> f64 {
        let (a, b) = (i.wrapping_sub(self.i0), j.wrapping_sub(self.j0));
        if (0..self.nx).contains(&a) && (0..self.ny).contains(&b) {
            let slot = usize::try_from(b * self.nx + a)
                .ok()
                .and_then(|k| self.cache.get(k));
            if let Some(slot) = slot {
                let bits = slot.load(Ordering::Relaxed);
                if bits != EMPTY {
                    return f64::from(f32::from_bits(bits));
                }
                let v = self.evaluate(i, j);
                slot.store(v.to_bits(), Ordering::Relaxed);
                return f64::from(v);
            }
        }
        f64::from(self.evaluate(i, j))
    }
}

impl LazyLattice {
    /// The four corner values of cell `(i, j)` when all four are cached already: two
    /// pairs of neighbouring slots.
    #[inline]
    fn cached_corners(&self, i: i64, j: i64) -> Option<[f64; 4]> {
        let (a, b) = (i.wrapping_sub(self.i0), j.wrapping_sub(self.j0));
        if !((0..self.nx - 1).contains(&a) && (0..self.ny - 1).contains(&b)) {
            return None;
        }
        // In range: 0 ≤ k and k + nx + 1 < nx · ny = cache.len().
        let (k, nx) = ((b * self.nx + a) as usize, self.nx as usize);
        let (Some(s00), Some(s10), Some(s01), Some(s11)) = (
            self.cache.get(k),
            self.cache.get(k + 1),
            self.cache.get(k + nx),
            self.cache.get(k + nx + 1),
        ) else {
            return None;
        };
        let bits = [
            s00.load(Ordering::Relaxed),
            s10.load(Ordering::Relaxed),
            s01.load(Ordering::Relaxed),
            s11.load(Ordering::Relaxed),
        ];
        if bits.contains(&EMPTY) {
            return None;
        }
        Some(bits.map(|b| f64::from(f32::from_bits(b))))
    }
}

impl Field for LazyLattice {
    fn sample(&self, p: DVec2) -> f64 {
        let u = p * self.inv;
        if !(u.x.abs() < EXACT_INT && u.y.abs() < EXACT_INT) {
            return self.source.sample(p);
        }
        let (x0, y0) = (floor_small(u.x), floor_small(u.y));
        let (fx, fy) = (u.x - x0, u.y - y0);
        let (i, j) = (x0 as i64, y0 as i64);
        let [v00, v10, v01, v11] = match self.cached_corners(i, j) {
            Some(c) => c,
            None => self.corners(i, j),
        };
        let bottom = v00 + (v10 - v00) * fx;
        let top = v01 + (v11 - v01) * fx;
        bottom + (top - bottom) * fy
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use polis_geom::field::{Fbm, FbmParams, FnField};

    use super::*;

    fn window() -> Aabb2 {
        Aabb2::new(DVec2::splat(-500.0), DVec2::splat(500.0))
    }

    #[test]
    fn exact_at_lattice_points_and_bilinear_between() {
        // A bilinear source is reproduced exactly (up to f32 rounding of the corners).
        let f = LazyLattice::new(
            Arc::new(FnField::new(|p: DVec2| 0.5 * p.x - 0.25 * p.y + 3.0)),
            10.0,
            window(),
        )
        .unwrap();
        for &(x, y) in &[
            (0.0, 0.0),
            (10.0, -20.0),
            (3.3, 7.7),
            (-123.4, 56.7),
            (499.0, -499.0),
        ] {
            let want = 0.5 * x - 0.25 * y + 3.0;
            assert!(
                (f.sample(DVec2::new(x, y)) - want).abs() < 1e-4,
                "at ({x}, {y})"
            );
        }
        // Within a cell the value lies between the corner values.
        let g = LazyLattice::new(
            Arc::new(FnField::new(|p: DVec2| (p.x * p.y).sin())),
            7.0,
            window(),
        )
        .unwrap();
        for k in 0..500 {
            let p = DVec2::new(-300.0 + 1.37 * k as f64, 200.0 - 0.91 * k as f64);
            let (i, j) = ((p.x / 7.0).floor(), (p.y / 7.0).floor());
            let c: Vec<f64> = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .iter()
                .map(|&(a, b)| f64::from(((i + a) * 7.0 * (j + b) * 7.0).sin() as f32))
                .collect();
            let (lo, hi) = c
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                    (l.min(v), h.max(v))
                });
            let v = g.sample(p);
            assert!(
                v >= lo - 1e-12 && v <= hi + 1e-12,
                "{v} outside [{lo}, {hi}] at {p}"
            );
        }
    }

    #[test]
    fn cached_and_uncached_agree_bit_for_bit_and_evaluate_once() {
        let fbm: Arc<dyn Field> = Arc::new(
            Fbm::new(FbmParams {
                seed: 4,
                wavelength_m: 300.0,
                ..FbmParams::default()
            })
            .unwrap(),
        );
        let cached = LazyLattice::new(fbm.clone(), 20.0, window()).unwrap();
        // A window too large to cache: every sample evaluates its corners.
        let huge = Aabb2::new(DVec2::splat(-1e7), DVec2::splat(1e7));
        let uncached = LazyLattice::new(fbm, 20.0, huge).unwrap();
        assert_eq!(uncached.cached_capacity(), 0);
        let pts: Vec<DVec2> = (0..2000)
            .map(|k| DVec2::new(-480.0 + 0.479 * k as f64, 470.0 - 0.473 * k as f64))
            .collect();
        // Forward, then backward: order does not matter.
        for p in pts.iter().chain(pts.iter().rev()) {
            assert_eq!(
                cached.sample(*p).to_bits(),
                uncached.sample(*p).to_bits(),
                "at {p}"
            );
        }
        // The diagonal crosses ~50 cells per axis: far fewer evaluations than samples.
        assert!(cached.evaluated() < 250, "{}", cached.evaluated());
        assert_eq!(uncached.evaluated(), 4 * 4000);
        // Outside the window: still the same function.
        let far = DVec2::new(3000.0, -2000.5);
        assert_eq!(cached.sample(far).to_bits(), uncached.sample(far).to_bits());
    }

    #[test]
    fn odd_points_and_parameters() {
        let f = LazyLattice::new(Arc::new(FnField::new(|p: DVec2| p.x)), 5.0, window()).unwrap();
        assert!(f.sample(DVec2::new(f64::NAN, 0.0)).is_nan());
        assert_eq!(f.sample(DVec2::new(1e300, 0.0)), 1e300);
        assert_eq!(f.sample(DVec2::new(-0.0, 0.0)), 0.0);
        let nan = LazyLattice::new(
            Arc::new(FnField::new(
                |p: DVec2| if p.x > 0.0 { f64::NAN } else { 1.0 },
            )),
            5.0,
            window(),
        )
        .unwrap();
        assert!(nan.sample(DVec2::new(2.0, 1.0)).is_nan());
        assert_eq!(nan.sample(DVec2::new(-6.0, 1.0)), 1.0);
        assert!(
            nan.sample(DVec2::new(2.0, 1.0)).is_nan(),
            "NaN is cached as NaN"
        );
        for s in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(LazyLattice::new(Arc::new(FnField::new(|p: DVec2| p.x)), s, window()).is_err());
        }
        let bad_window = Aabb2::new(DVec2::splat(f64::NEG_INFINITY), DVec2::splat(f64::INFINITY));
        let g = LazyLattice::new(Arc::new(FnField::new(|p: DVec2| p.y)), 5.0, bad_window).unwrap();
        assert_eq!(g.cached_capacity(), 0);
        assert!((g.sample(DVec2::new(1.0, 2.5)) - 2.5).abs() < 1e-6);
    }
}
