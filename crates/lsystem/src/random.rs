//! Random numbers from the seeded generator, defined here so that results do not depend
//! on the sampling code of a `rand` release.

use rand::Rng;

/// A uniform `f64` in `[0, 1)`: the top 53 bits of one `u64` draw.
#[inline]
pub fn unit_f64<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Chooses one of `candidates` (id, weight) with probability proportional to its weight,
/// from one uniform draw; `total` is the sum of the weights (> 0). Returns `fallback`
/// only for an empty list.
pub fn pick_weighted<R: Rng + ?Sized>(
    candidates: &[(u32, f64)],
    total: f64,
    fallback: u32,
    rng: &mut R,
) -> u32 {
    let target = unit_f64(rng) * total;
    let mut acc = 0.0;
    let mut chosen = fallback;
    for &(id, weight) in candidates {
        chosen = id;
        acc += weight;
        if target < acc {
            break;
        }
    }
    chosen
}

/// A standard normal variate (Box–Muller, two uniform draws).
pub fn normal_f64<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    let u1 = 1.0 - unit_f64(rng); // (0, 1]
    let u2 = unit_f64(rng);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}
