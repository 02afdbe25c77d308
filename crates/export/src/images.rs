//! Images as PNG files: [`ImageData::Png`] bytes pass through, raw RGBA pixels are encoded.

use std::borrow::Cow;

use polis_geom::scene::{Image, ImageData};

use crate::ExportError;

/// The PNG file of scene image `index`: the stored bytes of [`ImageData::Png`], or the
/// [`ImageData::Rgba8`] pixels encoded losslessly (8-bit RGBA, default compression,
/// deterministic).
pub fn png_bytes(index: usize, image: &Image) -> Result<Cow<'_, [u8]>, ExportError> {
    match &image.data {
        ImageData::Png(bytes) => Ok(Cow::Borrowed(bytes)),
        ImageData::Rgba8 {
            width,
            height,
            pixels,
        } => {
            let err = |e: png::EncodingError| ExportError::Png {
                image: index,
                reason: e.to_string(),
            };
            let mut out = Vec::with_capacity(pixels.len() / 2 + 64);
            let mut encoder = png::Encoder::new(&mut out, *width, *height);
            encoder.set_color(png::ColorType::Rgba);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header().map_err(err)?;
            writer.write_image_data(pixels).map_err(err)?;
            writer.finish().map_err(err)?;
            Ok(Cow::Owned(out))
        }
    }
}

/// A file name made of ASCII letters, digits, `-` and `_` only (other characters become
/// `_`), never empty: safe in OBJ/MTL statements, SVG ids and on every file system.
pub fn sanitize(name: &str, fallback: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        fallback.to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgba_is_encoded_and_png_passes_through() {
        let img = Image {
            name: "x".into(),
            data: ImageData::Rgba8 {
                width: 3,
                height: 2,
                pixels: (0..24).collect(),
            },
        };
        let png = png_bytes(0, &img).unwrap();
        assert!(png.starts_with(&polis_geom::scene::PNG_SIGNATURE));
        // Decode it again.
        let decoder = png::Decoder::new(std::io::Cursor::new(png.to_vec()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(
            &buf[..info.buffer_size()],
            &(0..24).collect::<Vec<u8>>()[..]
        );
        let again = png_bytes(0, &img).unwrap();
        assert_eq!(png, again, "encoding is deterministic");

        let raw = Image {
            name: "y".into(),
            data: ImageData::Png(png.to_vec()),
        };
        assert!(matches!(png_bytes(1, &raw).unwrap(), Cow::Borrowed(_)));
    }

    #[test]
    fn sanitize_names() {
        assert_eq!(sanitize("house 17/ä", "n"), "house_17__");
        assert_eq!(sanitize("", "n"), "n");
        assert_eq!(sanitize("a-b_C9", "n"), "a-b_C9");
    }
}
