//! Input keys of the editor's memo: a 128-bit digest of the exact bits of everything a
//! piece of work reads (two independent SplitMix64 lanes), so equal keys mean equal
//! inputs up to a collision chance of about n² / 2¹²⁹ for n items.

use polis_geom::hash::splitmix64;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};

/// A running 128-bit digest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) struct Key(u64, u64);

impl Key {
    /// A digest started with a salt naming what is hashed.
    pub(crate) fn new(salt: u64) -> Self {
        Key(splitmix64(salt ^ 0x6B65_795F_6C61_6E31), splitmix64(!salt))
    }

    /// Mixes one word in.
    pub(crate) fn u64(mut self, v: u64) -> Self {
        self.0 = splitmix64(self.0 ^ v);
        self.1 = splitmix64(self.1.rotate_left(23) ^ v ^ 0x9E37_79B9_7F4A_7C15);
        self
    }

    /// Mixes the bits of a float in.
    pub(crate) fn f64(self, v: f64) -> Self {
        self.u64(v.to_bits())
    }

    /// Mixes a point in.
    pub(crate) fn point(self, p: DVec2) -> Self {
        self.f64(p.x).f64(p.y)
    }

    /// Mixes bytes in (length first).
    pub(crate) fn bytes(mut self, b: &[u8]) -> Self {
        self = self.u64(b.len() as u64);
        for chunk in b.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self = self.u64(u64::from_le_bytes(w));
        }
        self
    }

    /// Mixes a ring in (length first).
    pub(crate) fn ring(mut self, ring: &Polygon) -> Self {
        self = self.u64(ring.points().len() as u64);
        for &p in ring.points() {
            self = self.point(p);
        }
        self
    }

    /// Mixes a region in (outer ring, then each hole).
    pub(crate) fn region(mut self, r: &PolygonWithHoles) -> Self {
        self = self.ring(&r.outer).u64(r.holes.len() as u64);
        for h in &r.holes {
            self = self.ring(h);
        }
        self
    }

    /// Mixes another key in.
    pub(crate) fn key(self, k: Key) -> Self {
        self.u64(k.0).u64(k.1)
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_separate_order_values_and_salts() {
        let a = Key::new(1).u64(2).u64(3);
        assert_eq!(a, Key::new(1).u64(2).u64(3));
        assert_ne!(a, Key::new(1).u64(3).u64(2));
        assert_ne!(a, Key::new(2).u64(2).u64(3));
        assert_ne!(Key::new(0).f64(0.0), Key::new(0).f64(-0.0));
        assert_ne!(Key::new(0).bytes(b"ab"), Key::new(0).bytes(b"ab\0"));
    }
}
