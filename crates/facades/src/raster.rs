//! Texture mode: rasterise a facade (or part of one) into glTF-ready textures.
//!
//! * **albedo**: RGBA8, sRGB (glTF `baseColorTexture`);
//! * **normal**: RGBA8 tangent-space normal map derived from the height field by central
//!   differences (glTF `normalTexture`, +X right, +Y up, +Z out of the wall); the alpha
//!   channel carries the height itself, mapped from ±[`HEIGHT_RANGE_M`] to 0–255, for
//!   relief/parallax mapping as in Kelly §4.4.3.3 (glTF readers ignore it);
//! * **metallic-roughness**: RGBA8 as glTF expects: G = roughness, B = metalness (R = 255,
//!   no occlusion; A = 255).
//!
//! Rows are rasterised by runs ([`crate::sweep`]): each layer's active runs on a row are
//! found analytically and painted bottom-up, then coloured; only image maps, nested
//! layers and closures are probed texel by texel.

use polis_geom::{Aabb2, DVec2};
use serde::{Deserialize, Serialize};

use crate::MAX_TEXTURE_TEXELS;
use crate::error::{FacadeError, Result, check_range};
use crate::facade::Facade;
use crate::sample::FacadeSample;
use crate::stack::LayerStack;
use crate::sweep::RowSweep;

/// Heights in `[−HEIGHT_RANGE_M, +HEIGHT_RANGE_M]` metres map to the normal map's alpha.
pub const HEIGHT_RANGE_M: f32 = 0.5;

/// How to rasterise.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RasterOptions {
    /// Texels per metre. Default: 64 (a 1.1 m window is 70 texels wide).
    pub pixels_per_metre: f64,
    /// Multiplies the height slopes in the normal map (1 = physical). Default: 1.
    pub normal_strength: f32,
}

impl Default for RasterOptions {
    fn default() -> Self {
        RasterOptions {
            pixels_per_metre: 64.0,
            normal_strength: 1.0,
        }
    }
}

/// Rasterised textures of a facade or of one tile.
#[derive(Debug, Clone, PartialEq)]
pub struct FacadeTextures {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Size covered, metres.
    pub size_m: [f64; 2],
    /// RGBA8 sRGB base colour, rows top-down.
    pub albedo: Vec<u8>,
    /// RGBA8 normal map (height in alpha), rows top-down.
    pub normal: Vec<u8>,
    /// RGBA8 metallic-roughness (G roughness, B metalness), rows top-down.
    pub metallic_roughness: Vec<u8>,
    /// The height field, metres, rows top-down.
    pub height_m: Vec<f32>,
}

impl FacadeTextures {
    /// Bytes held by the three RGBA8 textures (what a GPU would hold).
    pub fn gpu_bytes(&self) -> usize {
        self.albedo.len() + self.normal.len() + self.metallic_roughness.len()
    }

    /// The albedo as a PNG file.
    ///
    /// # Errors
    /// [`FacadeError::Png`].
    pub fn albedo_png(&self) -> Result<Vec<u8>> {
        encode_png(self.width, self.height, png::ColorType::Rgba, &self.albedo)
    }

    /// The normal map (height in alpha) as a PNG file.
    ///
    /// # Errors
    /// [`FacadeError::Png`].
    pub fn normal_png(&self) -> Result<Vec<u8>> {
        encode_png(self.width, self.height, png::ColorType::Rgba, &self.normal)
    }

    /// The metallic-roughness texture as a PNG file.
    ///
    /// # Errors
    /// [`FacadeError::Png`].
    pub fn metallic_roughness_png(&self) -> Result<Vec<u8>> {
        encode_png(
            self.width,
            self.height,
            png::ColorType::Rgba,
            &self.metallic_roughness,
        )
    }
}

/// Encodes 8-bit pixels (rows top-down) as a PNG file.
///
/// # Errors
/// [`FacadeError::Png`] if the data does not match the size or encoding fails.
pub fn encode_png(width: u32, height: u32, color: png::ColorType, data: &[u8]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, width, height);
        enc.set_color(color);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc
            .write_header()
            .map_err(|e| FacadeError::Png(e.to_string()))?;
        w.write_image_data(data)
            .map_err(|e| FacadeError::Png(e.to_string()))?;
        w.finish().map_err(|e| FacadeError::Png(e.to_string()))?;
    }
    Ok(out)
}

/// `[0, 1] → 0..=255`, rounding; clamps out-of-range values and maps NaN to 0.
#[inline]
fn to_u8(v: f32) -> u8 {
    let x = v * 255.0 + 0.5;
    if x >= 255.0 {
        255
    } else if x > 0.0 {
        // In (0, 255): the truncating cast is exact and cheap.
        x as i32 as u8
    } else {
        0
    }
}

/// Rasterises `region` (metres, in the stack's domain) of a stack into `width × height`
/// texels, multiplying albedo by `tint`.
///
/// # Errors
/// [`FacadeError::InvalidNumber`] for an empty or non-finite region,
/// [`FacadeError::TextureTooLarge`] above [`MAX_TEXTURE_TEXELS`].
pub fn rasterize_stack(
    stack: &LayerStack,
    region: &Aabb2,
    width: u32,
    height: u32,
    tint: f32,
    normal_strength: f32,
) -> Result<FacadeTextures> {
    let n = u64::from(width) * u64::from(height);
    if width == 0 || height == 0 || n > MAX_TEXTURE_TEXELS {
        return Err(FacadeError::TextureTooLarge {
            width: u64::from(width),
            height: u64::from(height),
            limit: MAX_TEXTURE_TEXELS,
        });
    }
    for v in [region.min.x, region.min.y, region.max.x, region.max.y] {
        check_range(
            "region coordinate",
            v,
            -crate::MAX_LENGTH_M,
            crate::MAX_LENGTH_M,
            "[-1e5, 1e5] m",
        )?;
    }
    if !(region.width() > 0.0 && region.height() > 0.0) {
        return Err(FacadeError::InvalidNumber {
            what: "region size",
            value: region.width().min(region.height()),
            range: "> 0 m",
        });
    }
    check_range(
        "normal_strength",
        f64::from(normal_strength),
        0.0,
        1e6,
        "[0, 1e6]",
    )?;
    let n = n as usize;
    let (w, h) = (width as usize, height as usize);
    let mut albedo = vec![0u8; n * 4];
    let mut mr = vec![0u8; n * 4];
    let mut heights = vec![0f32; n];
    let ds = region.width() / w as f64;
    let dt = region.height() / h as f64;
    let mut sweep = RowSweep::new(region.min.x, ds, w);
    let mut row = vec![FacadeSample::default(); w];
    // NaN albedo never equals anything: the first row is always converted.
    let mut prev_row = vec![
        FacadeSample {
            albedo: [f32::NAN; 4],
            ..FacadeSample::default()
        };
        w
    ];
    let (mut prev_a, mut prev_m) = (vec![0u8; w * 4], vec![0u8; w * 4]);
    let rows = albedo
        .chunks_exact_mut(w * 4)
        .zip(mr.chunks_exact_mut(w * 4))
        .zip(heights.chunks_exact_mut(w));
    for (y, ((arow, mrow), hrow)) in rows.enumerate() {
        let t = region.max.y - (y as f64 + 0.5) * dt;
        sweep.row(stack, t, &mut row);
        // Rows often repeat (inside a course of bricks, a band of cladding): copy them.
        if prev_row == row {
            arow.copy_from_slice(&prev_a);
            mrow.copy_from_slice(&prev_m);
            for (hh, smp) in hrow.iter_mut().zip(&row) {
                *hh = smp.height;
            }
            continue;
        }
        // Runs of equal samples are common (walls, mortar, glass): convert once per run.
        let mut prev: Option<(FacadeSample, [u8; 4], [u8; 4])> = None;
        for (((a, m), hh), smp) in arow
            .chunks_exact_mut(4)
            .zip(mrow.chunks_exact_mut(4))
            .zip(hrow.iter_mut())
            .zip(&row)
        {
            let (pa, pm) = match prev {
                Some((p, pa, pm)) if p == *smp => (pa, pm),
                _ => {
                    let pa = [
                        to_u8(smp.albedo[0] * tint),
                        to_u8(smp.albedo[1] * tint),
                        to_u8(smp.albedo[2] * tint),
                        to_u8(smp.albedo[3]),
                    ];
                    let pm = [255, to_u8(smp.roughness), to_u8(smp.metallic), 255];
                    prev = Some((*smp, pa, pm));
                    (pa, pm)
                }
            };
            a.copy_from_slice(&pa);
            m.copy_from_slice(&pm);
            *hh = smp.height;
        }
        prev_row.copy_from_slice(&row);
        prev_a.copy_from_slice(arow);
        prev_m.copy_from_slice(mrow);
    }
    let normal = normals_from_heights(&heights, w, h, ds, dt, normal_strength);
    Ok(FacadeTextures {
        width,
        height,
        size_m: [region.width(), region.height()],
        albedo,
        normal,
        metallic_roughness: mr,
        height_m: heights,
    })
}

/// A tangent-space normal map (RGBA8, height in alpha) from a height field (rows
/// top-down) with texel sizes `ds` × `dt` metres, by central differences (one-sided at the
/// borders).
pub fn normals_from_heights(
    heights: &[f32],
    w: usize,
    h: usize,
    ds: f64,
    dt: f64,
    strength: f32,
) -> Vec<u8> {
    let mut out = vec![0u8; w * h * 4];
    if w == 0 || h == 0 || heights.len() < w * h {
        return out;
    }
    // One-sided differences at the borders span one texel, central ones two.
    let kx = |span: usize| strength / (span.max(1) as f64 * ds) as f32;
    // The last computed row: its (up, centre, down) rows, slope factor and output.
    let mut last: Option<(usize, usize, usize, f32)> = None;
    let mut last_out = vec![0u8; w * 4];
    let row_of = |r: usize| heights.get(r * w..r * w + w);
    for (y, orow) in out.chunks_exact_mut(w * 4).enumerate() {
        let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let ky = strength / ((y1 - y0).max(1) as f64 * dt) as f32;
        let (Some(up), Some(cur), Some(dn)) = (row_of(y0), row_of(y), row_of(y1)) else {
            continue;
        };
        // Identical neighbourhoods give identical normals (rows inside a brick course, a
        // band of corrugated sheet): copy instead of recomputing.
        if let Some((a, b, c, k)) = last
            && k == ky
            && row_of(a) == Some(up)
            && row_of(b) == Some(cur)
            && row_of(c) == Some(dn)
        {
            orow.copy_from_slice(&last_out);
            continue;
        }
        let mut last_c = f32::NAN;
        let mut last_alpha = 0u8;
        let mut texel = |l: f32, r: f32, u: f32, d: f32, c: f32, k: f32, px: &mut [u8]| {
            if c != last_c {
                last_c = c;
                last_alpha = to_u8(c * (0.5 / HEIGHT_RANGE_M) + 0.5);
            }
            if l == r && u == d {
                px.copy_from_slice(&[128, 128, 255, last_alpha]);
                return;
            }
            // Row y0 is higher up the wall than y1: dh/dt = (h(y0) − h(y1)) / Δt.
            let (nx, ny) = (-(r - l) * k, -(u - d) * ky);
            let inv = 1.0 / (nx * nx + ny * ny + 1.0).sqrt();
            px.copy_from_slice(&[
                to_u8(nx * inv * 0.5 + 0.5),
                to_u8(ny * inv * 0.5 + 0.5),
                to_u8(inv * 0.5 + 0.5),
                last_alpha,
            ]);
        };
        let (k_in, k_edge) = (kx(2), kx(1));
        let mut px = orow.chunks_exact_mut(4);
        // Left border (one-sided), interior (central), right border (one-sided).
        if let (Some(p), Some(&c), Some(&u), Some(&d)) =
            (px.next(), cur.first(), up.first(), dn.first())
        {
            let r = cur.get(1).copied().unwrap_or(c);
            texel(c, r, u, d, c, k_edge, p);
        }
        if w >= 3 {
            let inner = cur
                .windows(3)
                .zip(up.iter().skip(1))
                .zip(dn.iter().skip(1))
                .zip(px.by_ref().take(w - 2));
            for (((win, &u), &d), p) in inner {
                texel(win[0], win[2], u, d, win[1], k_in, p);
            }
        }
        if w >= 2
            && let (Some(p), Some(&c), Some(&l), Some(&u), Some(&d)) =
                (px.next(), cur.last(), cur.get(w - 2), up.last(), dn.last())
        {
            texel(l, c, u, d, c, k_edge, p);
        }
        last = Some((y0, y, y1, ky));
        last_out.copy_from_slice(orow);
    }
    out
}

impl Facade {
    /// Rasterises the whole facade ("hero" mode: one texture per facade).
    ///
    /// The size is `round(width · ppm) × round(height · ppm)` texels (at least 1).
    ///
    /// # Errors
    /// [`FacadeError::InvalidNumber`] for a bad resolution;
    /// [`FacadeError::TextureTooLarge`].
    pub fn rasterize(&self, opts: &RasterOptions) -> Result<FacadeTextures> {
        let region = Aabb2::new(
            DVec2::ZERO,
            DVec2::new(self.spec().width_m, self.spec().height_m),
        );
        self.rasterize_region(&region, opts)
    }

    /// Rasterises a region of the facade (metres) at the options' resolution.
    ///
    /// # Errors
    /// As [`rasterize`](Self::rasterize).
    pub fn rasterize_region(&self, region: &Aabb2, opts: &RasterOptions) -> Result<FacadeTextures> {
        let ppm = check_range(
            "pixels_per_metre",
            opts.pixels_per_metre,
            1e-3,
            1e4,
            "[0.001, 10000]",
        )?;
        let px = |m: f64| -> Result<u32> {
            let v = (m * ppm).round().max(1.0);
            if v > f64::from(u32::MAX) {
                return Err(FacadeError::TextureTooLarge {
                    width: v as u64,
                    height: 1,
                    limit: MAX_TEXTURE_TEXELS,
                });
            }
            Ok(v as u32)
        };
        rasterize_stack(
            self.stack(),
            region,
            px(region.width())?,
            px(region.height())?,
            self.tint(),
            opts.normal_strength,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;
    use crate::facade::{FacadeSpec, PreparedStyle};

    #[test]
    fn raster_matches_point_evaluation() {
        let p = PreparedStyle::new(builtin::brick_house()).unwrap();
        let f = p.facade(&FacadeSpec::new(9.0, 7.0, 11)).unwrap();
        let tex = f.rasterize(&RasterOptions::default()).unwrap();
        assert_eq!((tex.width, tex.height), (576, 448));
        let ds = 9.0 / 576.0;
        let dt = 7.0 / 448.0;
        for (x, y) in [(0, 0), (100, 200), (575, 447), (300, 30), (288, 400)] {
            let s = (x as f64 + 0.5) * ds;
            let t = 7.0 - (y as f64 + 0.5) * dt;
            let m = f.sample(s, t);
            let k = (y * 576 + x) * 4;
            assert_eq!(tex.albedo[k], to_u8(m.albedo[0]), "({x},{y})");
            assert_eq!(tex.metallic_roughness[k + 1], to_u8(m.roughness));
            assert_eq!(tex.height_m[y * 576 + x], m.height);
        }
    }

    #[test]
    fn to_u8_rounds_and_clamps() {
        assert_eq!(to_u8(0.0), 0);
        assert_eq!(to_u8(1.0), 255);
        assert_eq!(to_u8(0.5), 128);
        assert_eq!(to_u8(-3.0), 0);
        assert_eq!(to_u8(7.0), 255);
        assert_eq!(to_u8(f32::NAN), 0);
        for k in 0..=255u8 {
            assert_eq!(to_u8(f32::from(k) / 255.0), k);
        }
    }

    #[test]
    fn flat_heights_give_straight_normals_and_steps_tilt_them() {
        let flat = normals_from_heights(&[0.0; 9], 3, 3, 0.1, 0.1, 1.0);
        assert!(
            flat.chunks(4)
                .all(|p| p[0] == 128 && p[1] == 128 && p[2] == 255)
        );
        // Height rising to the right: the normal leans left (x < 0.5).
        let ramp = normals_from_heights(&[0.0, 0.1, 0.2, 0.0, 0.1, 0.2], 3, 2, 0.1, 0.1, 1.0);
        assert!(ramp[4] < 128);
        // Height rising upwards (row 0 is the top): normal leans down (y < 0.5).
        let up = normals_from_heights(&[0.2, 0.2, 0.0, 0.0], 2, 2, 0.1, 0.1, 1.0);
        assert!(up[1] < 128);
    }

    #[test]
    fn limits_and_bad_options() {
        let p = PreparedStyle::new(builtin::industrial()).unwrap();
        let f = p.facade(&FacadeSpec::new(30.0, 8.0, 1)).unwrap();
        let bad = RasterOptions {
            pixels_per_metre: f64::NAN,
            ..RasterOptions::default()
        };
        assert!(f.rasterize(&bad).is_err());
        let huge = RasterOptions {
            pixels_per_metre: 9000.0,
            ..RasterOptions::default()
        };
        assert!(matches!(
            f.rasterize(&huge),
            Err(FacadeError::TextureTooLarge { .. })
        ));
    }
}
