//! [`splitmix64`]: the stateless 64-bit mix that derives seeds from seeds and ids;
//! [`point_key`]: an exact key of a point for sorting, hashing and matching.

use glam::DVec2;

/// An exact key for a point: the bit patterns of its coordinates, with −0 and +0 the same
/// coordinate (adding +0.0 turns −0.0 into +0.0; every other value keeps its bits). Two
/// points have the same key exactly when they compare equal (`==`), which raw
/// `to_bits` keys do not give: a point computed as (−0, 5) and a copy written as (0, 5)
/// would be two points. The key's order groups equal points; it is not the coordinates'
/// numeric order.
#[inline]
pub fn point_key(p: DVec2) -> [u64; 2] {
    [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits()]
}

/// SplitMix64 (Steele, Lea & Flood 2014) as a function: the golden-ratio increment then
/// its finaliser. A bijection on `u64` with full avalanche, so seeds derived from nearby
/// ids (`seed ^ id`, `seed + k`) are uncorrelated. Used wherever a stage derives a
/// per-item seed or a per-cell random value without a generator.
#[inline]
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_keys_match_exactly_when_points_are_equal() {
        let a = DVec2::new(-0.0, 5.0);
        let b = DVec2::new(0.0, 5.0);
        assert_eq!(a, b);
        assert_eq!(point_key(a), point_key(b));
        assert_eq!(point_key(DVec2::new(0.0, -0.0)), point_key(DVec2::ZERO));
        assert_ne!(point_key(DVec2::new(1.0, 5.0)), point_key(b));
        assert_ne!(
            point_key(DVec2::new(f64::MIN_POSITIVE, 0.0)),
            point_key(DVec2::ZERO)
        );
    }

    #[test]
    fn matches_the_reference_sequence() {
        // The first outputs of the reference SplitMix64 generator seeded with 0: its
        // state advances by the increment, and each output is the mix of the old state.
        assert_eq!(splitmix64(0), 0xE220_A839_7B1D_CDAF);
        assert_eq!(splitmix64(0x9E37_79B9_7F4A_7C15), 0x6E78_9E6A_A1B9_65F4);
    }
}
