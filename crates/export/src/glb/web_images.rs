//! The web profile's textures: PNG files re-encoded smaller, still plain PNG (every glTF
//! loader reads it; no extension).
//!
//! Per image:
//!
//! 1. **Resolution cap**: an image wider or taller than
//!    [`GlbOptions::web_texture_max_px`](super::GlbOptions::web_texture_max_px) is halved
//!    (2 × 2 box filter) until it fits, so power-of-two sizes stay powers of two. Texels of
//!    a normal map are averaged as vectors and renormalised (tangent-space directions,
//!    not colours).
//! 2. **Colour type** chosen from the pixels, losslessly: an image with at most 256
//!    distinct colours becomes indexed (a palette, `tRNS` for its alpha values when any
//!    is below 255, 1, 2, 4 or 8 bits per index as the palette needs); an opaque image
//!    drops its alpha channel (RGB); otherwise RGBA.
//! 3. DEFLATE at the `png` crate's `High` level with adaptive row filters.
//!
//! Step 1 is the only lossy one: an image within the cap decodes to exactly its pixels.
//!
//! References: W3C, *Portable Network Graphics (PNG) Specification* (3rd ed.), §4.5
//! (colour types, palette and `tRNS`), §7.3 (filters).

use std::borrow::Cow;
use std::collections::BTreeMap;

use polis_geom::scene::{Image, ImageData};

use crate::ExportError;

/// An image as 8-bit RGBA pixels.
pub(crate) struct Rgba<'a> {
    pub width: u32,
    pub height: u32,
    pub pixels: Cow<'a, [u8]>,
}

fn png_error(image: usize) -> impl Fn(String) -> ExportError {
    move |reason| ExportError::Png { image, reason }
}

/// The pixels of scene image `index` as 8-bit RGBA (PNG bytes decoded).
pub(crate) fn rgba(index: usize, image: &Image) -> Result<Rgba<'_>, ExportError> {
    let err = png_error(index);
    match &image.data {
        ImageData::Rgba8 {
            width,
            height,
            pixels,
        } => Ok(Rgba {
            width: *width,
            height: *height,
            pixels: Cow::Borrowed(pixels),
        }),
        ImageData::Png(bytes) => {
            let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes.as_slice()));
            decoder
                .set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
            let mut reader = decoder.read_info().map_err(|e| err(e.to_string()))?;
            let size = reader
                .output_buffer_size()
                .ok_or_else(|| err("the image is too large to decode".into()))?;
            let mut buf = vec![0; size];
            let info = reader
                .next_frame(&mut buf)
                .map_err(|e| err(e.to_string()))?;
            buf.truncate(info.buffer_size());
            let pixels: Vec<u8> = match info.color_type {
                png::ColorType::Rgba => buf,
                png::ColorType::Rgb => buf
                    .chunks_exact(3)
                    .flat_map(|p| [p[0], p[1], p[2], 255])
                    .collect(),
                png::ColorType::GrayscaleAlpha => buf
                    .chunks_exact(2)
                    .flat_map(|p| [p[0], p[0], p[0], p[1]])
                    .collect(),
                png::ColorType::Grayscale => buf.iter().flat_map(|&g| [g, g, g, 255]).collect(),
                png::ColorType::Indexed => {
                    return Err(err("an indexed PNG was not expanded".into()));
                }
            };
            Ok(Rgba {
                width: info.width,
                height: info.height,
                pixels: Cow::Owned(pixels),
            })
        }
    }
}

/// Halves `img` (2 × 2 box filter; an odd last row or column is averaged with itself)
/// until both sides are at most `max_px`. `normal_map`: texels are unit vectors
/// (`c / 255 · 2 − 1`), averaged and renormalised.
pub(crate) fn cap(mut img: Rgba<'_>, max_px: u32, normal_map: bool) -> Rgba<'_> {
    while (img.width > max_px || img.height > max_px) && (img.width > 1 || img.height > 1) {
        let (w, h) = (img.width as usize, img.height as usize);
        let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
        let src = &img.pixels;
        let mut out = Vec::with_capacity(4 * nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let texels = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| {
                    let (sx, sy) = ((2 * x + dx).min(w - 1), (2 * y + dy).min(h - 1));
                    4 * (sy * w + sx)
                });
                let mean = |c: usize| -> f32 {
                    texels.iter().map(|&o| f32::from(src[o + c])).sum::<f32>() / 4.0
                };
                let alpha = mean(3).round() as u8;
                if normal_map {
                    let v = [0, 1, 2].map(|c| {
                        texels
                            .iter()
                            .map(|&o| f32::from(src[o + c]) / 255.0 * 2.0 - 1.0)
                            .sum::<f32>()
                    });
                    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    let unit = if len > 1e-6 {
                        v.map(|c| c / len)
                    } else {
                        [0.0, 0.0, 1.0]
                    };
                    let [r, g, b] = unit.map(|c| ((c + 1.0) * 0.5 * 255.0).round() as u8);
                    out.extend([r, g, b, alpha]);
                } else {
                    out.extend([
                        mean(0).round() as u8,
                        mean(1).round() as u8,
                        mean(2).round() as u8,
                        alpha,
                    ]);
                }
            }
        }
        img = Rgba {
            width: nw as u32,
            height: nh as u32,
            pixels: Cow::Owned(out),
        };
    }
    img
}

/// Bits per palette index for a palette of `n` colours.
fn index_bits(n: usize) -> u8 {
    match n {
        0..=2 => 1,
        3..=4 => 2,
        5..=16 => 4,
        _ => 8,
    }
}

/// The smallest lossless PNG colour type for the pixels (see the module docs), encoded
/// at the `High` DEFLATE level.
pub(crate) fn encode(index: usize, img: &Rgba<'_>) -> Result<Vec<u8>, ExportError> {
    let err = png_error(index);
    let px = &img.pixels;
    let opaque = px.chunks_exact(4).all(|p| p[3] == 255);
    // Distinct colours, up to one past the palette's limit.
    let mut colours: BTreeMap<[u8; 4], u8> = BTreeMap::new();
    for p in px.chunks_exact(4) {
        let c = [p[0], p[1], p[2], p[3]];
        if !colours.contains_key(&c) {
            if colours.len() == 256 {
                colours.insert(c, 0);
                break;
            }
            colours.insert(c, 0);
        }
    }
    let (w, h) = (img.width as usize, img.height as usize);
    let mut out = Vec::with_capacity(px.len() / 4 + 1024);
    let mut encoder = png::Encoder::new(&mut out, img.width, img.height);
    encoder.set_compression(png::Compression::High);
    encoder.set_filter(png::Filter::Adaptive);
    let data: Vec<u8> = if colours.len() <= 256 {
        let mut palette = Vec::with_capacity(3 * colours.len());
        let mut trns = Vec::with_capacity(colours.len());
        for (k, (c, slot)) in colours.iter_mut().enumerate() {
            *slot = k as u8;
            palette.extend_from_slice(&c[..3]);
            trns.push(c[3]);
        }
        let bits = index_bits(colours.len());
        encoder.set_color(png::ColorType::Indexed);
        encoder.set_depth(match bits {
            1 => png::BitDepth::One,
            2 => png::BitDepth::Two,
            4 => png::BitDepth::Four,
            _ => png::BitDepth::Eight,
        });
        encoder.set_palette(palette);
        if !opaque {
            // tRNS may stop before the opaque tail; the palette order is the colours'.
            encoder.set_trns(trns);
        }
        // Rows of indices packed `bits` per index, most significant first, each row
        // starting on a byte.
        let per_byte = 8 / bits as usize;
        let row_bytes = w.div_ceil(per_byte);
        let mut data = vec![0u8; row_bytes * h];
        for y in 0..h {
            for x in 0..w {
                let o = 4 * (y * w + x);
                let c = [px[o], px[o + 1], px[o + 2], px[o + 3]];
                let i = colours.get(&c).copied().unwrap_or(0);
                let shift = 8 - bits as usize * (x % per_byte + 1);
                data[y * row_bytes + x / per_byte] |= i << shift;
            }
        }
        data
    } else if opaque {
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        px.chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect()
    } else {
        encoder.set_color(png::ColorType::Rgba);
        encoder.set_depth(png::BitDepth::Eight);
        px.to_vec()
    };
    let mut writer = encoder.write_header().map_err(|e| err(e.to_string()))?;
    writer
        .write_image_data(&data)
        .map_err(|e| err(e.to_string()))?;
    writer.finish().map_err(|e| err(e.to_string()))?;
    Ok(out)
}

/// The web profile's PNG file of scene image `index` (see the module docs).
pub(crate) fn web_png(
    index: usize,
    image: &Image,
    max_px: u32,
    normal_map: bool,
) -> Result<Vec<u8>, ExportError> {
    let img = cap(rgba(index, image)?, max_px, normal_map);
    encode(index, &img)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn decode(bytes: &[u8]) -> (u32, u32, Vec<u8>) {
        let img = Image {
            name: String::new(),
            data: ImageData::Png(bytes.to_vec()),
        };
        let d = rgba(0, &img).unwrap();
        (d.width, d.height, d.pixels.into_owned())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Within the cap, the re-encoded PNG decodes to exactly the pixels, whatever
        /// colour type it chose (palettes of 1 to 300 colours, with and without alpha).
        #[test]
        fn within_the_cap_the_pixels_survive(
            w in 1u32..40,
            h in 1u32..40,
            colours in 1usize..300,
            translucent in any::<bool>(),
            seed in any::<u64>(),
        ) {
            let mut pixels = Vec::with_capacity((4 * w * h) as usize);
            for i in 0..(w * h) as u64 {
                let k = polis_geom::hash::splitmix64(seed ^ i) % colours as u64;
                let a = if translucent { (k * 37 % 256) as u8 } else { 255 };
                pixels.extend([(k * 7) as u8, (k * 13 % 256) as u8, (k / 256) as u8, a]);
            }
            let img = Image {
                name: "t".into(),
                data: ImageData::Rgba8 { width: w, height: h, pixels: pixels.clone() },
            };
            let png = web_png(0, &img, 64, false).unwrap();
            prop_assert_eq!(decode(&png), (w, h, pixels));
        }
    }

    #[test]
    fn large_images_are_halved_to_the_cap_and_normal_maps_stay_unit() {
        // 64 × 32, capped at 16: halved twice to 16 × 8.
        let (w, h) = (64u32, 32u32);
        let mut pixels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                // A tilted normal per texel, alternating between two directions.
                let tilt = if (x + y) % 2 == 0 { 0.6f32 } else { -0.6 };
                let z = (1.0 - tilt * tilt).sqrt();
                let enc = |c: f32| ((c + 1.0) * 0.5 * 255.0).round() as u8;
                pixels.extend([enc(tilt), enc(0.0), enc(z), 255]);
            }
        }
        let img = Image {
            name: "n".into(),
            data: ImageData::Rgba8 {
                width: w,
                height: h,
                pixels,
            },
        };
        let (cw, ch, px) = decode(&web_png(0, &img, 16, true).unwrap());
        assert_eq!((cw, ch), (16, 8));
        for p in px.chunks_exact(4) {
            let v = [0, 1, 2].map(|c| f32::from(p[c]) / 255.0 * 2.0 - 1.0);
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            // The two tilts cancel: straight up, unit length (not the 0.8 of a colour
            // average).
            assert!((len - 1.0).abs() < 0.02, "{len}");
            assert!(v[2] > 0.99, "{v:?}");
        }
        // A colour image: box-filtered means.
        let img = Image {
            name: "c".into(),
            data: ImageData::Rgba8 {
                width: 2,
                height: 2,
                pixels: vec![0, 0, 0, 255, 100, 0, 0, 255, 0, 200, 0, 255, 0, 0, 40, 255],
            },
        };
        let (cw, ch, px) = decode(&web_png(0, &img, 1, false).unwrap());
        assert_eq!((cw, ch, px), (1, 1, vec![25, 50, 10, 255]));
    }
}
