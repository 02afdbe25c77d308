//! Street surface textures: asphalt with lane markings laid along the road, kerb-side
//! gutters, plain asphalt for junction plates and paving slabs for footpaths (Kelly
//! §4.4.1 and §5.4: roads and footpaths as textured geometry; the course report's street
//! textures, oriented along the road).
//!
//! Each texture is a [`FacadeTextures`] (albedo, normal map, metallic-roughness, height)
//! that tiles seamlessly in both directions, drawn like the facades' from a height field
//! and colours per texel, deterministic for a seed.
//!
//! * **Ribbons** ([`StreetSurface::Street`], [`Major`](StreetSurface::Major),
//!   [`Highway`](StreetSurface::Highway), [`Lane`](StreetSurface::Lane)): the texture's
//!   `x` runs along the road over [`MARKING_PERIOD_M`] metres, its `y` across the whole
//!   width of the road (row 0 on the right edge, the last row on the left), so a mesh
//!   whose `v` runs across the road from 0 to 1 gets its markings in place at any width.
//!   Markings: a dashed centre line (streets), edge lines and a dashed centre line (major
//!   roads), edge lines, dashed lane lines and a solid double centre line (highways);
//!   every ribbon has a concrete gutter along both kerbs.
//! * **Junction plates** ([`StreetSurface::Asphalt`]): plain asphalt, [`ASPHALT_TILE_M`]
//!   square, for metre coordinates divided by the tile size.
//! * **Footpaths** ([`StreetSurface::Paving`]): square slabs of [`SLAB_M`] with sunk
//!   joints, [`PAVING_TILE_M`] square.
//!
//! # Limitations
//! Markings are placed by fractions of the width: their line widths grow with the road.
//! The lane count of a highway is fixed (two each way).

use polis_geom::hash::splitmix64;

use crate::raster::FacadeTextures;

/// Length of road one ribbon texture covers, metres (one dash and one gap). 12 m.
pub const MARKING_PERIOD_M: f64 = 12.0;
/// Side of the plain asphalt texture, metres. 4 m.
pub const ASPHALT_TILE_M: f64 = 4.0;
/// Side of the paving texture, metres. 2 m.
pub const PAVING_TILE_M: f64 = 2.0;
/// Side of one paving slab, metres. 0.5 m.
pub const SLAB_M: f64 = 0.5;

/// What a street surface texture shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum StreetSurface {
    /// Plain asphalt (junction plates, dead-end caps), [`ASPHALT_TILE_M`] square.
    Asphalt,
    /// A street ribbon: dashed centre line.
    Street,
    /// A major road ribbon: solid edge lines, dashed centre line.
    Major,
    /// A highway ribbon: solid edge lines, dashed lane lines, solid double centre line.
    Highway,
    /// A ribbon without markings (footpath and other roads drawn as ribbons).
    Lane,
    /// Paving slabs (footpaths, pavements), [`PAVING_TILE_M`] square.
    Paving,
}

impl StreetSurface {
    /// A short name (`"asphalt"`, `"street"`, …) for materials and files.
    pub fn name(self) -> &'static str {
        match self {
            StreetSurface::Asphalt => "asphalt",
            StreetSurface::Street => "street",
            StreetSurface::Major => "major",
            StreetSurface::Highway => "highway",
            StreetSurface::Lane => "lane",
            StreetSurface::Paving => "paving",
        }
    }

    /// Whether the texture spans a ribbon's width (`y` across the road) rather than a
    /// square of metres.
    pub fn is_ribbon(self) -> bool {
        matches!(
            self,
            StreetSurface::Street
                | StreetSurface::Major
                | StreetSurface::Highway
                | StreetSurface::Lane
        )
    }

    /// Texels (width, height): ribbons 256 along × 64 across, squares 128 × 128. Powers of
    /// two, so mipmapped repeating samplers suit every engine.
    pub fn texels(self) -> (u32, u32) {
        if self.is_ribbon() {
            (256, 64)
        } else {
            (128, 128)
        }
    }

    /// Metres one texture repeat covers along `x` (and along `y` for the square ones; a
    /// ribbon's `y` covers its road's width).
    pub fn period_m(self) -> f64 {
        match self {
            StreetSurface::Asphalt => ASPHALT_TILE_M,
            StreetSurface::Paving => PAVING_TILE_M,
            _ => MARKING_PERIOD_M,
        }
    }
}

/// What a texel is made of.
#[derive(Clone, Copy, PartialEq)]
enum Stuff {
    Asphalt,
    Paint([u8; 3]),
    Concrete,
    Slab(u8),
    Joint,
}

const WHITE: [u8; 3] = [232, 230, 220];
const YELLOW: [u8; 3] = [226, 184, 58];

/// The textures of `surface`, deterministic for `seed` (the same seed and surface give
/// the same bytes).
pub fn street_textures(surface: StreetSurface, seed: u64) -> FacadeTextures {
    let (w, h) = surface.texels();
    let (wu, hu) = (w as usize, h as usize);
    let period = surface.period_m();
    let mut stuff = Vec::with_capacity(wu * hu);
    for y in 0..hu {
        // Across the texture: a fraction of the width for ribbons, metres for squares.
        let t = (y as f64 + 0.5) / h as f64;
        for x in 0..wu {
            let s = (x as f64 + 0.5) / w as f64 * period;
            stuff.push(classify(surface, s, t, seed));
        }
    }
    let seed = splitmix64(seed ^ 0x5EED_57EE7);
    // Height: coarse periodic value noise (ruts, patches) plus fine grain, paint a little
    // proud, joints and gutters lower.
    let coarse = |x: usize, y: usize| periodic_noise(seed, x, y, wu, hu, 16);
    let mut height = Vec::with_capacity(wu * hu);
    let mut albedo = Vec::with_capacity(wu * hu * 4);
    let mut mr = Vec::with_capacity(wu * hu * 4);
    for y in 0..hu {
        for x in 0..wu {
            let grain = unit(splitmix64(seed ^ ((x as u64) << 20) ^ ((y as u64) << 40))) - 0.5;
            let blotch = coarse(x, y) - 0.5;
            let k = stuff[y * wu + x];
            let (rgb, rough, dh) = match k {
                Stuff::Asphalt => {
                    let g = 60.0 + 14.0 * blotch + 16.0 * grain;
                    ([g, g, g + 2.0], 0.92, 0.0)
                }
                Stuff::Paint(c) => {
                    let f = 1.0 + 0.06 * grain - 0.08 * blotch.abs();
                    (c.map(|v| f64::from(v) * f), 0.6, 0.0015)
                }
                Stuff::Concrete => {
                    let g = 150.0 + 10.0 * blotch + 8.0 * grain;
                    ([g, g - 2.0, g - 8.0], 0.8, -0.004)
                }
                Stuff::Slab(tone) => {
                    let g = 140.0 + f64::from(tone) * 0.15 + 8.0 * grain + 6.0 * blotch;
                    ([g + 6.0, g, g - 8.0], 0.78, 0.0)
                }
                Stuff::Joint => {
                    let g = 92.0 + 6.0 * grain;
                    ([g, g, g - 4.0], 0.95, -0.005)
                }
            };
            height.push((0.003 * blotch + 0.0008 * grain + dh) as f32);
            albedo.extend(rgb.map(|v| v.clamp(0.0, 255.0) as u8));
            albedo.push(255);
            mr.extend([0, (rough * 255.0) as u8, 0, 255]);
        }
    }
    let texel_m = [
        period / w as f64,
        if surface.is_ribbon() {
            0.1
        } else {
            period / h as f64
        },
    ];
    let normal = periodic_normals(&height, wu, hu, texel_m);
    FacadeTextures {
        width: w,
        height: h,
        size_m: [period, if surface.is_ribbon() { 1.0 } else { period }],
        albedo,
        normal,
        metallic_roughness: mr,
        height_m: height,
    }
}

/// The material at `s` metres along (or across `x`) and `t` (fraction across a ribbon,
/// or a fraction of the square).
fn classify(surface: StreetSurface, s: f64, t: f64, seed: u64) -> Stuff {
    let band = |centre: f64, half: f64| (t - centre).abs() <= half;
    // Dashes: 3 m painted of each 12 m period (6 m for highway lanes: 3 of 6).
    let dash = |len: f64, of: f64| s.rem_euclid(of) < len;
    let gutter = 0.035;
    let line = 0.012;
    match surface {
        StreetSurface::Asphalt => Stuff::Asphalt,
        StreetSurface::Paving => {
            let (x, y) = (s, t * PAVING_TILE_M);
            let joint = 0.02;
            let (fx, fy) = (x.rem_euclid(SLAB_M), y.rem_euclid(SLAB_M));
            if fx < joint || fy < joint {
                return Stuff::Joint;
            }
            let (i, j) = ((x / SLAB_M) as u64, (y / SLAB_M) as u64);
            Stuff::Slab((splitmix64(seed ^ (i << 8) ^ (j << 24)) & 0x7F) as u8)
        }
        _ if t < gutter || t > 1.0 - gutter => Stuff::Concrete,
        StreetSurface::Lane => Stuff::Asphalt,
        StreetSurface::Street => {
            if band(0.5, line) && dash(3.0, MARKING_PERIOD_M) {
                Stuff::Paint(WHITE)
            } else {
                Stuff::Asphalt
            }
        }
        StreetSurface::Major => {
            let edge = band(gutter + 0.03, line) || band(1.0 - gutter - 0.03, line);
            if edge || (band(0.5, line) && dash(4.0, MARKING_PERIOD_M)) {
                Stuff::Paint(WHITE)
            } else {
                Stuff::Asphalt
            }
        }
        StreetSurface::Highway => {
            if band(gutter + 0.025, line) || band(1.0 - gutter - 0.025, line) {
                Stuff::Paint(WHITE)
            } else if band(0.5 - 0.012, 0.006) || band(0.5 + 0.012, 0.006) {
                Stuff::Paint(YELLOW)
            } else if (band(0.25, line * 0.8) || band(0.75, line * 0.8))
                && dash(3.0, MARKING_PERIOD_M / 2.0)
            {
                Stuff::Paint(WHITE)
            } else {
                Stuff::Asphalt
            }
        }
    }
}

/// A number in `[0, 1)` from a hash.
fn unit(h: u64) -> f64 {
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Value noise on a lattice of `cells` per side, wrapping at the texture's edges
/// (seamless), smoothly interpolated: in `[0, 1]`.
fn periodic_noise(seed: u64, x: usize, y: usize, w: usize, h: usize, cells: usize) -> f64 {
    let c = cells.max(1);
    let fx = x as f64 / w as f64 * c as f64;
    let fy = y as f64 / h as f64 * c as f64;
    let (i, j) = (fx as usize, fy as usize);
    let (tx, ty) = (fx - i as f64, fy - j as f64);
    let v = |a: usize, b: usize| {
        unit(splitmix64(
            seed ^ (((a % c) as u64) << 16) ^ (((b % c) as u64) << 36),
        ))
    };
    let smooth = |t: f64| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (smooth(tx), smooth(ty));
    let top = v(i, j) + (v(i + 1, j) - v(i, j)) * sx;
    let bottom = v(i, j + 1) + (v(i + 1, j + 1) - v(i, j + 1)) * sx;
    top + (bottom - top) * sy
}

/// A tangent-space normal map (RGBA8, height in alpha) of a height field that wraps at
/// its edges: central differences across the seams too.
fn periodic_normals(height: &[f32], w: usize, h: usize, texel_m: [f64; 2]) -> Vec<u8> {
    let mut out = Vec::with_capacity(w * h * 4);
    let (lo, hi) = height
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = (hi - lo).max(1e-6);
    let at = |x: usize, y: usize| f64::from(height[y * w + x]);
    for y in 0..h {
        for x in 0..w {
            let dx = (at((x + 1) % w, y) - at((x + w - 1) % w, y)) / (2.0 * texel_m[0]);
            let dy = (at(x, (y + 1) % h) - at(x, (y + h - 1) % h)) / (2.0 * texel_m[1]);
            // Rows run top-down, texture v downwards: the normal's y follows +v.
            let n = polis_geom::glam::DVec3::new(-dx, dy, 1.0).normalize();
            let enc = |c: f64| ((c * 0.5 + 0.5) * 255.0).round().clamp(0.0, 255.0) as u8;
            let a = ((at(x, y) as f32 - lo) / span * 255.0).round() as u8;
            out.extend([enc(n.x), enc(n.y), enc(n.z), a]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [StreetSurface; 6] = [
        StreetSurface::Asphalt,
        StreetSurface::Street,
        StreetSurface::Major,
        StreetSurface::Highway,
        StreetSurface::Lane,
        StreetSurface::Paving,
    ];

    /// Sizes, determinism, and the markings where they belong: along the road (a dash
    /// runs along `x`), at the centre of the width, gutters on both edges.
    #[test]
    fn textures_are_sized_deterministic_and_marked_along_the_road() {
        for s in ALL {
            let t = street_textures(s, 9);
            let (w, h) = s.texels();
            let n = (w * h * 4) as usize;
            assert_eq!((t.width, t.height), (w, h));
            assert!(w.is_power_of_two() && h.is_power_of_two());
            assert_eq!(
                (t.albedo.len(), t.normal.len(), t.metallic_roughness.len()),
                (n, n, n)
            );
            assert_eq!(t, street_textures(s, 9), "{}", s.name());
            assert_ne!(t.albedo, street_textures(s, 10).albedo, "{}", s.name());
        }
        let street = street_textures(StreetSurface::Street, 1);
        let px = |x: usize, y: usize| street.albedo[(y * 256 + x) * 4];
        // Centre row: painted for the first 3 m of 12 (64 texels), asphalt after.
        assert!(px(10, 32) > 200 && px(50, 31) > 200);
        assert!(px(100, 32) < 120 && px(200, 32) < 120);
        // Off the centre: asphalt along the whole length; the gutters are concrete.
        assert!((0..256).all(|x| px(x, 16) < 120));
        assert!((0..256).all(|x| px(x, 0) > 120 && px(x, 63) > 120));
        // Highways: a yellow double centre line (red ≫ blue).
        let hw = street_textures(StreetSurface::Highway, 1);
        let i = (31 * 256 + 7) * 4;
        assert!(hw.albedo[i] > 180 && hw.albedo[i + 2] < 120);
    }

    /// The normal maps are unit-ish vectors pointing out of the surface, and the noise
    /// tiles: the height field is continuous across the texture's seams.
    #[test]
    fn normals_point_up_and_textures_tile() {
        for s in ALL {
            let t = street_textures(s, 4);
            for px in t.normal.chunks_exact(4) {
                assert!(px[2] >= 128 + 64, "{}: {px:?}", s.name());
            }
            let (w, h) = (t.width as usize, t.height as usize);
            let n = |x: usize, y: usize| periodic_noise(7, x, y, w, h, 16);
            for y in 0..h {
                assert!((n(0, y) - n(w - 1, y)).abs() < 0.35);
            }
        }
    }
}
