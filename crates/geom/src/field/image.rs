//! Loading [`Raster`] fields from PNG images (cargo feature `png`).

use std::io::Cursor;
use std::path::Path;

use super::Raster;
use crate::{Aabb2, GeomError};

/// The largest decoded image, in bytes, that [`Raster::from_png_bytes`] accepts (512 MiB:
/// e.g. 16 384² grey 16-bit). Protects against headers that claim enormous sizes.
pub const MAX_PNG_DECODED_BYTES: usize = 512 << 20;

use super::DEFAULT_MAX_PNG_PIXELS;

/// Rec. 709 luma weights applied to RGB channel values.
const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

fn png_error(e: png::DecodingError) -> GeomError {
    GeomError::Image(format!(
        "PNG decoding failed ({e}); the input must be a complete, valid PNG file"
    ))
}

/// Decodes the first frame of a PNG with `transformations`, refusing images of more than
/// `max_pixels` pixels (read from the header, before decoding) or that would decode to
/// more than [`MAX_PNG_DECODED_BYTES`].
fn read_png(
    bytes: &[u8],
    transformations: png::Transformations,
    max_pixels: u64,
) -> Result<(Vec<u8>, png::OutputInfo), GeomError> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(transformations);
    let mut reader = decoder.read_info().map_err(png_error)?;
    let (width, height) = (reader.info().width, reader.info().height);
    let pixels = u64::from(width) * u64::from(height);
    if pixels > max_pixels {
        return Err(GeomError::Image(format!(
            "the PNG is {width} × {height} = {pixels} pixels, more than the limit of \
             {max_pixels}; downscale it or raise the pixel limit"
        )));
    }
    let size = reader
        .output_buffer_size()
        .filter(|&s| s <= MAX_PNG_DECODED_BYTES)
        .ok_or_else(|| {
            let info = reader.info();
            GeomError::Image(format!(
                "the PNG is {} × {} pixels, more than the {} MiB this loader accepts; downscale it",
                info.width,
                info.height,
                MAX_PNG_DECODED_BYTES >> 20
            ))
        })?;
    let mut buf = vec![0u8; size];
    let out = reader.next_frame(&mut buf).map_err(png_error)?;
    buf.truncate(out.buffer_size());
    Ok((buf, out))
}

/// Decodes a PNG (any colour type and bit depth) to 8-bit RGBA pixels, row by row from
/// the top: `(width, height, 4 · width · height bytes)`. Grey is spread to R, G and B,
/// palettes are expanded, 16-bit samples keep their high byte, and a missing alpha
/// channel is opaque.
///
/// Errors: [`GeomError::Image`] when the bytes are not a decodable PNG, have more than
/// [`DEFAULT_MAX_PNG_PIXELS`] pixels or decode to more than [`MAX_PNG_DECODED_BYTES`].
///
/// ```
/// # use polis_geom::field::decode_png_rgba8;
/// assert!(decode_png_rgba8(b"not a png").is_err());
/// ```
pub fn decode_png_rgba8(bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), GeomError> {
    decode_png_rgba8_limited(bytes, DEFAULT_MAX_PNG_PIXELS)
}

/// [`decode_png_rgba8`] with another pixel limit: images of more than `max_pixels`
/// pixels (width × height, read from the header) are refused before decoding.
///
/// Errors: as [`decode_png_rgba8`], and [`GeomError::Image`] naming the size for an
/// image over the limit.
pub fn decode_png_rgba8_limited(
    bytes: &[u8],
    max_pixels: u64,
) -> Result<(u32, u32, Vec<u8>), GeomError> {
    let (buf, out) = read_png(
        bytes,
        png::Transformations::EXPAND | png::Transformations::STRIP_16,
        max_pixels,
    )?;
    let rgba: Vec<u8> = match out.color_type {
        png::ColorType::Rgba => buf,
        png::ColorType::Rgb => buf
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect(),
        png::ColorType::Grayscale => buf.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        png::ColorType::GrayscaleAlpha => buf
            .chunks_exact(2)
            .flat_map(|p| [p[0], p[0], p[0], p[1]])
            .collect(),
        png::ColorType::Indexed => {
            return Err(GeomError::Image(
                "the PNG palette could not be expanded".into(),
            ));
        }
    };
    let expected = (out.width as usize)
        .saturating_mul(out.height as usize)
        .saturating_mul(4);
    if rgba.len() != expected {
        return Err(GeomError::Image(format!(
            "the PNG decoded to {} of {} bytes; the file is truncated",
            rgba.len(),
            expected
        )));
    }
    Ok((out.width, out.height, rgba))
}

impl Raster {
    /// Decodes a PNG image into a raster over `extent` (metres), values in `[0, 1]`.
    ///
    /// * Grey 1/2/4/8-bit → `v / (2⁸ − 1)` after expansion to 8 bits; grey 16-bit →
    ///   `v / 65535`.
    /// * Grey + alpha: the alpha channel is ignored.
    /// * RGB, RGBA and palette images: converted to luma `0.2126 R + 0.7152 G + 0.0722 B`
    ///   on the stored (gamma-encoded) channel values; alpha is ignored.
    /// * The image's top row is the raster's top row (largest `y`), as the image is shown.
    ///
    /// Errors: [`GeomError::Image`] when the bytes are not a decodable PNG, have more
    /// than [`DEFAULT_MAX_PNG_PIXELS`] pixels or decode to more than
    /// [`MAX_PNG_DECODED_BYTES`]; the errors of [`Raster::new`] for a bad `extent`.
    pub fn from_png_bytes(bytes: &[u8], extent: Aabb2) -> Result<Raster, GeomError> {
        Raster::from_png_bytes_limited(bytes, extent, DEFAULT_MAX_PNG_PIXELS)
    }

    /// [`from_png_bytes`](Self::from_png_bytes) with another pixel limit: an image of
    /// more than `max_pixels` pixels (width × height, read from the header) is refused
    /// before decoding.
    ///
    /// Errors: as [`from_png_bytes`](Self::from_png_bytes).
    pub fn from_png_bytes_limited(
        bytes: &[u8],
        extent: Aabb2,
        max_pixels: u64,
    ) -> Result<Raster, GeomError> {
        let (buf, out) = read_png(bytes, png::Transformations::EXPAND, max_pixels)?;
        let channels = match out.color_type {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => {
                return Err(GeomError::Image(
                    "the PNG palette could not be expanded; save the map as grey-scale".into(),
                ));
            }
        };
        let sample_bytes = match out.bit_depth {
            png::BitDepth::Eight => 1,
            png::BitDepth::Sixteen => 2,
            other => {
                return Err(GeomError::Image(format!(
                    "unexpected bit depth {other:?} after expansion; save the map as 8- or 16-bit grey-scale"
                )));
            }
        };
        let width = out.width as usize;
        let height = out.height as usize;
        let pixel_bytes = channels * sample_bytes;
        let read = |s: &[u8]| -> f32 {
            match s {
                [hi, lo] => f32::from(u16::from_be_bytes([*hi, *lo])) / 65535.0,
                [v] => f32::from(*v) / 255.0,
                _ => 0.0,
            }
        };
        let mut data = Vec::with_capacity(width.saturating_mul(height));
        for line in buf.chunks(out.line_size.max(1)).take(height) {
            for px in line.chunks_exact(pixel_bytes).take(width) {
                let mut ch = px.chunks_exact(sample_bytes).map(read);
                let value = if channels <= 2 {
                    ch.next().unwrap_or(0.0)
                } else {
                    let r = ch.next().unwrap_or(0.0);
                    let g = ch.next().unwrap_or(0.0);
                    let b = ch.next().unwrap_or(0.0);
                    LUMA[0] * r + LUMA[1] * g + LUMA[2] * b
                };
                data.push(value.clamp(0.0, 1.0));
            }
        }
        if data.len() != width.saturating_mul(height) {
            return Err(GeomError::Image(format!(
                "the PNG decoded to {} of {width} × {height} pixels; the file is truncated",
                data.len()
            )));
        }
        Raster::new(width, height, extent, data)
    }

    /// Reads a PNG file and decodes it as [`from_png_bytes`](Self::from_png_bytes) does.
    ///
    /// Errors: [`GeomError::Image`] naming the path when the file cannot be read, and the
    /// errors of [`from_png_bytes`](Self::from_png_bytes).
    pub fn from_png_path(path: impl AsRef<Path>, extent: Aabb2) -> Result<Raster, GeomError> {
        Raster::from_png_path_limited(path, extent, DEFAULT_MAX_PNG_PIXELS)
    }

    /// [`from_png_path`](Self::from_png_path) with another pixel limit (see
    /// [`from_png_bytes_limited`](Self::from_png_bytes_limited)).
    ///
    /// Errors: as [`from_png_path`](Self::from_png_path).
    pub fn from_png_path_limited(
        path: impl AsRef<Path>,
        extent: Aabb2,
        max_pixels: u64,
    ) -> Result<Raster, GeomError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| {
            GeomError::Image(format!(
                "cannot read {}: {e}; check the path of the map image",
                path.display()
            ))
        })?;
        Raster::from_png_bytes_limited(&bytes, extent, max_pixels)
    }
}

impl Raster {
    /// Encodes the raster as a 16-bit grey-scale PNG, mapping `lo` to black and `hi` to
    /// white (values outside `[lo, hi]` are clamped); the top row is the top of the image.
    /// Decoding the result with [`from_png_bytes`](Self::from_png_bytes) gives the values
    /// mapped to `[0, 1]`, to within 1/65535.
    ///
    /// Useful to look at generated maps. Errors: [`GeomError::InvalidParameter`] unless
    /// `lo < hi` are finite; [`GeomError::Image`] if the raster is wider or taller than a
    /// PNG can be (2³¹ − 1 pixels).
    pub fn to_png_bytes(&self, lo: f64, hi: f64) -> Result<Vec<u8>, GeomError> {
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(GeomError::InvalidParameter {
                name: "lo/hi",
                reason: format!("the grey range [{lo}, {hi}] must be finite with lo < hi"),
            });
        }
        let too_big = || {
            GeomError::Image(format!(
                "a {} × {} raster is too large for a PNG",
                self.width(),
                self.height()
            ))
        };
        let w = u32::try_from(self.width()).map_err(|_| too_big())?;
        let h = u32::try_from(self.height()).map_err(|_| too_big())?;
        let scale = 65535.0 / (hi - lo);
        let pixels: Vec<u8> = self
            .data()
            .iter()
            .flat_map(|&v| {
                let level = ((f64::from(v) - lo) * scale).round().clamp(0.0, 65535.0) as u16;
                level.to_be_bytes()
            })
            .collect();
        let encode_error =
            |e: png::EncodingError| GeomError::Image(format!("PNG encoding failed: {e}"));
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, w, h);
            encoder.set_color(png::ColorType::Grayscale);
            encoder.set_depth(png::BitDepth::Sixteen);
            let mut writer = encoder.write_header().map_err(encode_error)?;
            writer.write_image_data(&pixels).map_err(encode_error)?;
            writer.finish().map_err(encode_error)?;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::Field;
    use glam::DVec2;

    fn encode(w: u32, h: u32, color: png::ColorType, depth: png::BitDepth, data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, w, h);
            enc.set_color(color);
            enc.set_depth(depth);
            let mut writer = enc.write_header().unwrap();
            writer.write_image_data(data).unwrap();
        }
        out
    }

    fn extent() -> Aabb2 {
        Aabb2::new(DVec2::new(0.0, 0.0), DVec2::new(300.0, 200.0))
    }

    #[test]
    fn grey8_round_trip() {
        // 3 × 2: top row 0, 51, 255; bottom row 102, 153, 204.
        let pixels = [0u8, 51, 255, 102, 153, 204];
        let bytes = encode(
            3,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Eight,
            &pixels,
        );
        let r = Raster::from_png_bytes(&bytes, extent()).unwrap();
        assert_eq!((r.width(), r.height()), (3, 2));
        for (i, &p) in pixels.iter().enumerate() {
            let (col, row) = (i % 3, i / 3);
            assert_eq!(r.get(col, row).unwrap(), f32::from(p) / 255.0);
            let c = r.texel_center(col, row);
            assert_eq!(r.sample(c), f64::from(f32::from(p) / 255.0));
        }
        // The image's top row is at the top of the extent.
        assert_eq!(r.sample(DVec2::new(250.0, 199.0)), 1.0);
        assert_eq!(r.sample(DVec2::new(50.0, 199.0)), 0.0);
    }

    #[test]
    fn grey16_and_low_bit_depths() {
        let values: [u16; 4] = [0, 1000, 40000, 65535];
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
        let png16 = encode(
            2,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Sixteen,
            &bytes,
        );
        let r = Raster::from_png_bytes(&png16, extent()).unwrap();
        for (i, &v) in values.iter().enumerate() {
            assert_eq!(r.get(i % 2, i / 2).unwrap(), f32::from(v) / 65535.0);
        }
        // 1-bit grey: 4 pixels in one byte, 1 0 1 1.
        let png1 = encode(
            4,
            1,
            png::ColorType::Grayscale,
            png::BitDepth::One,
            &[0b1011_0000],
        );
        let r = Raster::from_png_bytes(&png1, extent()).unwrap();
        assert_eq!(r.data(), &[1.0, 0.0, 1.0, 1.0]);
    }

    #[test]
    fn grey_alpha_and_colour_are_converted() {
        let ga = encode(
            2,
            1,
            png::ColorType::GrayscaleAlpha,
            png::BitDepth::Eight,
            &[255, 0, 51, 255],
        );
        let r = Raster::from_png_bytes(&ga, extent()).unwrap();
        assert_eq!(r.data(), &[1.0, 0.2]);
        let rgb = encode(
            3,
            1,
            png::ColorType::Rgb,
            png::BitDepth::Eight,
            &[255, 0, 0, 0, 255, 0, 255, 255, 255],
        );
        let r = Raster::from_png_bytes(&rgb, extent()).unwrap();
        assert!((r.data()[0] - 0.2126).abs() < 1e-6);
        assert!((r.data()[1] - 0.7152).abs() < 1e-6);
        assert!((r.data()[2] - 1.0).abs() < 1e-6);
        let rgba = encode(
            1,
            1,
            png::ColorType::Rgba,
            png::BitDepth::Eight,
            &[0, 0, 255, 7],
        );
        let r = Raster::from_png_bytes(&rgba, extent()).unwrap();
        assert!((r.data()[0] - 0.0722).abs() < 1e-6);
    }

    /// Every colour type and bit depth decodes to the same RGBA pixels.
    #[test]
    fn rgba8_from_every_colour_type() {
        use png::{BitDepth, ColorType};
        let cases: [(ColorType, BitDepth, Vec<u8>, [u8; 8]); 5] = [
            (
                ColorType::Rgba,
                BitDepth::Eight,
                vec![1, 2, 3, 4, 5, 6, 7, 8],
                [1, 2, 3, 4, 5, 6, 7, 8],
            ),
            (
                ColorType::Rgb,
                BitDepth::Eight,
                vec![1, 2, 3, 5, 6, 7],
                [1, 2, 3, 255, 5, 6, 7, 255],
            ),
            (
                ColorType::Grayscale,
                BitDepth::Eight,
                vec![9, 200],
                [9, 9, 9, 255, 200, 200, 200, 255],
            ),
            (
                ColorType::GrayscaleAlpha,
                BitDepth::Eight,
                vec![9, 10, 200, 20],
                [9, 9, 9, 10, 200, 200, 200, 20],
            ),
            // 16-bit samples keep their high byte.
            (
                ColorType::Grayscale,
                BitDepth::Sixteen,
                vec![9, 99, 200, 1],
                [9, 9, 9, 255, 200, 200, 200, 255],
            ),
        ];
        for (color, depth, data, want) in cases {
            let (w, h, rgba) = decode_png_rgba8(&encode(2, 1, color, depth, &data)).unwrap();
            assert_eq!(
                (w, h, rgba.as_slice()),
                (2, 1, &want[..]),
                "{color:?} {depth:?}"
            );
        }
        let good = encode(2, 1, ColorType::Rgb, BitDepth::Eight, &[1, 2, 3, 5, 6, 7]);
        for cut in [0, 1, 8, 20, 33, good.len() - 13] {
            assert!(
                matches!(decode_png_rgba8(&good[..cut]), Err(GeomError::Image(_))),
                "cut at {cut}"
            );
        }
    }

    #[test]
    fn errors_are_typed() {
        assert!(matches!(
            Raster::from_png_bytes(b"not a png", extent()),
            Err(GeomError::Image(_))
        ));
        assert!(matches!(
            Raster::from_png_bytes(&[], extent()),
            Err(GeomError::Image(_))
        ));
        let good = encode(
            2,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Eight,
            &[1, 2, 3, 4],
        );
        // Cuts inside the signature, the header and the image data.
        for cut in [1, 8, 20, 33, 45] {
            assert!(
                matches!(
                    Raster::from_png_bytes(&good[..cut], extent()),
                    Err(GeomError::Image(_))
                ),
                "cut at {cut}"
            );
        }
        assert!(matches!(
            Raster::from_png_bytes(&good, Aabb2::EMPTY),
            Err(GeomError::InvalidParameter { name: "extent", .. })
        ));
        let missing = Raster::from_png_path("/nonexistent/polis/map.png", extent()).unwrap_err();
        assert!(missing.to_string().contains("/nonexistent/polis/map.png"));
    }

    #[test]
    fn write_and_read_back() {
        let r =
            Raster::from_fn(5, 3, extent(), |c, row| c as f32 * 10.0 - row as f32 * 5.0).unwrap();
        let bytes = r.to_png_bytes(-10.0, 40.0).unwrap();
        let back = Raster::from_png_bytes(&bytes, extent()).unwrap();
        assert_eq!((back.width(), back.height()), (5, 3));
        for (a, b) in r.data().iter().zip(back.data()) {
            let expected = (f64::from(*a) + 10.0) / 50.0;
            assert!(
                (f64::from(*b) - expected).abs() <= 1.0 / 65535.0,
                "{a} → {b}"
            );
        }
        // Clamping outside the range, and bad ranges.
        let clamped =
            Raster::from_png_bytes(&r.to_png_bytes(0.0, 10.0).unwrap(), extent()).unwrap();
        assert_eq!(clamped.get(4, 0), Some(1.0));
        assert_eq!(clamped.get(0, 2), Some(0.0));
        assert!(r.to_png_bytes(1.0, 1.0).is_err());
        assert!(r.to_png_bytes(f64::NAN, 1.0).is_err());
    }

    #[test]
    fn path_round_trip() {
        let bytes = encode(
            2,
            1,
            png::ColorType::Grayscale,
            png::BitDepth::Eight,
            &[0, 255],
        );
        let dir = std::env::temp_dir().join(format!("polis-geom-field-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("map.png");
        std::fs::write(&path, &bytes).unwrap();
        let r = Raster::from_png_path(&path, extent()).unwrap();
        assert_eq!(r.data(), &[0.0, 1.0]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A PNG of 20,000 × 20,000 grey pixels, made as a small file (every row the same
    /// zero bytes, deflated), is refused from its header under the default limit and
    /// under a lowered one, without decoding.
    #[test]
    fn pixel_limit_refuses_decompression_bombs_from_the_header() {
        let side = 20_000u32;
        let mut bytes = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut bytes, side, side);
            enc.set_color(png::ColorType::Grayscale);
            enc.set_depth(png::BitDepth::One);
            enc.set_compression(png::Compression::Fast);
            let mut writer = enc.write_header().unwrap();
            let row = vec![0u8; (side as usize).div_ceil(8)];
            let mut stream = writer.stream_writer().unwrap();
            for _ in 0..side {
                std::io::Write::write_all(&mut stream, &row).unwrap();
            }
            stream.finish().unwrap();
        }
        assert!(bytes.len() < 2 << 20, "{} bytes", bytes.len());
        for err in [
            Raster::from_png_bytes(&bytes, extent()).unwrap_err(),
            decode_png_rgba8(&bytes).unwrap_err(),
        ] {
            let text = err.to_string();
            assert!(text.contains("20000 × 20000"), "{text}");
        }
        // A configurable limit: a 3 × 2 image passes 6 pixels and is refused at 5.
        let small = encode(
            3,
            2,
            png::ColorType::Grayscale,
            png::BitDepth::Eight,
            &[0; 6],
        );
        assert!(Raster::from_png_bytes_limited(&small, extent(), 6).is_ok());
        assert!(Raster::from_png_bytes_limited(&small, extent(), 5).is_err());
        assert!(decode_png_rgba8_limited(&small, 6).is_ok());
        assert!(decode_png_rgba8_limited(&small, 5).is_err());
    }
}
