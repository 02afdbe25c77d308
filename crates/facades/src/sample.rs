//! What a facade evaluates to at one point, and the stateless hashes used for per-cell
//! randomness.

/// The surface at one facade point: everything a PBR material (glTF metallic-roughness)
/// needs, plus a height for bump, normal and relief mapping.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct FacadeSample {
    /// Base colour, sRGB-encoded, each channel in `[0, 1]`; alpha last.
    pub albedo: [f32; 4],
    /// Height relative to the wall plane, metres (negative: recessed, e.g. a window).
    #[cfg_attr(feature = "serde", serde(default))]
    pub height: f32,
    /// Perceptual roughness in `[0, 1]` (glTF `roughnessFactor`).
    #[cfg_attr(feature = "serde", serde(default = "default_roughness"))]
    pub roughness: f32,
    /// Metalness in `[0, 1]` (glTF `metallicFactor`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub metallic: f32,
}

#[cfg_attr(not(feature = "serde"), allow(dead_code))]
fn default_roughness() -> f32 {
    0.8
}

impl Default for FacadeSample {
    /// Mid-grey plaster: albedo 0.5, height 0, roughness 0.8, metallic 0.
    fn default() -> Self {
        FacadeSample::rgb(0.5, 0.5, 0.5)
    }
}

impl FacadeSample {
    /// An opaque, rough, non-metallic surface of the given sRGB colour.
    pub const fn rgb(r: f32, g: f32, b: f32) -> Self {
        FacadeSample {
            albedo: [r, g, b, 1.0],
            height: 0.0,
            roughness: 0.8,
            metallic: 0.0,
        }
    }

    /// This sample with another height (metres).
    pub const fn with_height(mut self, height: f32) -> Self {
        self.height = height;
        self
    }

    /// This sample with other roughness and metalness.
    pub const fn with_pbr(mut self, roughness: f32, metallic: f32) -> Self {
        self.roughness = roughness;
        self.metallic = metallic;
        self
    }

    /// Multiplies the colour channels by `k` (alpha untouched), clamping to `[0, 1]`.
    #[inline]
    pub fn shade(mut self, k: f32) -> Self {
        for c in &mut self.albedo[..3] {
            *c = (*c * k).clamp(0.0, 1.0);
        }
        self
    }

    /// Linear interpolation towards `other` by `k ∈ [0, 1]`.
    #[inline]
    pub fn lerp(&self, other: &FacadeSample, k: f32) -> FacadeSample {
        let l = |a: f32, b: f32| a + (b - a) * k;
        FacadeSample {
            albedo: [
                l(self.albedo[0], other.albedo[0]),
                l(self.albedo[1], other.albedo[1]),
                l(self.albedo[2], other.albedo[2]),
                l(self.albedo[3], other.albedo[3]),
            ],
            height: l(self.height, other.height),
            roughness: l(self.roughness, other.roughness),
            metallic: l(self.metallic, other.metallic),
        }
    }

    /// Whether every field is finite and colour, roughness and metalness lie in `[0, 1]`.
    pub fn is_valid(&self) -> bool {
        let unit = |v: f32| (0.0..=1.0).contains(&v);
        self.albedo.iter().all(|&c| unit(c))
            && self.height.is_finite()
            && unit(self.roughness)
            && unit(self.metallic)
    }
}

/// SplitMix64: a stateless, well-mixed 64-bit hash ([`polis_geom::hash::splitmix64`]).
#[inline]
pub fn mix64(z: u64) -> u64 {
    polis_geom::hash::splitmix64(z)
}

/// Hash of a seed and two integer coordinates (a cell, a brick).
#[inline]
pub fn hash2(seed: u64, a: i64, b: i64) -> u64 {
    mix64(seed ^ mix64((a as u64).wrapping_mul(0x9E37_79B9) ^ (b as u64).rotate_left(32)))
}

/// A hash mapped to `[0, 1)`.
#[inline]
pub fn unit(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hashes_are_stable_and_spread() {
        // Pinned values: per-cell randomness must not change between versions.
        assert_eq!(mix64(0), 0xE220_A839_7B1D_CDAF);
        let mut sum = 0.0;
        for i in 0..1000 {
            let u = unit(hash2(7, i, -i));
            assert!((0.0..1.0).contains(&u));
            sum += u;
        }
        assert!((sum / 1000.0 - 0.5).abs() < 0.05);
        assert_ne!(hash2(1, 2, 3), hash2(1, 3, 2));
    }

    #[test]
    fn sample_helpers() {
        let a = FacadeSample::rgb(0.2, 0.4, 0.6);
        assert!(a.is_valid());
        assert_eq!(a.shade(10.0).albedo[0], 1.0);
        let b = a.lerp(&FacadeSample::rgb(1.0, 1.0, 1.0), 0.5);
        assert!((b.albedo[0] - 0.6).abs() < 1e-6);
        assert!(
            !FacadeSample {
                roughness: 2.0,
                ..a
            }
            .is_valid()
        );
    }
}
