//! [`splitmix64`]: the stateless 64-bit mix that derives seeds from seeds and ids;
//! [`point_key`]: an exact key of a point for sorting, hashing and matching;
//! [`FxHasher`]: a fast deterministic hasher for such keys.

use std::hash::{BuildHasherDefault, Hasher};

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

/// A small, fast, deterministic hasher for keys polis builds itself (bits of numbers,
/// ids) (the multiply-rotate scheme of Firefox's "FxHash",
/// with a final bit mix).
/// For lookups only: nothing polis writes depends on a hash map's iteration order.
#[derive(Default, Clone, Copy)]
pub struct FxHasher(u64);

const SEED: u64 = 0x51_7c_c1_b7_27_22_0a_95;

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut buf = [0u8; 8];
            buf[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(buf));
        }
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(SEED);
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_i64(&mut self, i: i64) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        // A final avalanche (MurmurHash3's fmix64): the multiply above leaves the low bits,
        // which pick the bucket, depending on the low input bits only.
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h
    }
}

/// [`FxHasher`] as a hash map's `BuildHasher` (`HashMap<K, V, FxBuild>`).
pub type FxBuild = BuildHasherDefault<FxHasher>;

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
