//! Input keys of the editor's memo: a 128-bit digest of the exact bits of everything a
//! piece of work reads (two independent SplitMix64 lanes), so equal keys mean equal
//! inputs up to a collision chance of about n² / 2¹²⁹ for n items.

use polis_geom::hash::splitmix64;

/// The editor's memo keys are [`Digest`](polis_geom::hash::Digest)s.
pub(crate) use polis_geom::hash::Digest as Key;

/// A hash map on stable ids (lot, building and block ids): hashed by one SplitMix64
/// step of the id instead of SipHash. Looked up only, never iterated into an output.
pub(crate) type IdMap<V> = std::collections::HashMap<u64, V, IdBits>;

/// Hashes a `u64` id by one SplitMix64 step (see [`IdMap`]).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct IdBits;

impl std::hash::BuildHasher for IdBits {
    type Hasher = IdHasher;
    fn build_hasher(&self) -> IdHasher {
        IdHasher(0)
    }
}

/// The hasher of [`IdBits`].
pub(crate) struct IdHasher(u64);

impl std::hash::Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = splitmix64(self.0 ^ u64::from(b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = splitmix64(self.0 ^ v);
    }
}
