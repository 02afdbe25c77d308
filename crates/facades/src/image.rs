//! Image maps: small rasters of [`FacadeSample`]s placed in cells, chosen at random per
//! cell (Parish & Müller §4.3: "pictures showing the window open, half-opened and closed.
//! By randomly applying the different window to each cell, a great visual complexity of
//! the facade is easily established").
//!
//! Images come from data ([`ImageStyle::Rgba`], e.g. decoded from a scan with
//! [`MaterialImage::from_png`]) or are drawn procedurally by the built-in generators
//! (sash windows in any opening state, office glazing with blinds).

use std::sync::Arc;

use crate::error::{FacadeError, Result};
use crate::sample::{FacadeSample, mix64, unit};

/// Resolution at which built-in images are drawn (width, height).
pub const BUILTIN_IMAGE_SIZE: [usize; 2] = [64, 96];

/// A raster of surface samples; row 0 is the bottom. Texels with alpha < 0.5 are
/// inactive: the layer falls through to the one below there.
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialImage {
    width: usize,
    height: usize,
    texels: Vec<FacadeSample>,
}

impl MaterialImage {
    /// An image from texels in rows bottom-up.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] if the size is zero or does not match the texels.
    pub fn new(width: usize, height: usize, texels: Vec<FacadeSample>) -> Result<Self> {
        if width == 0 || height == 0 || width.checked_mul(height) != Some(texels.len()) {
            return Err(FacadeError::InvalidStyle {
                style: "image".into(),
                reason: format!(
                    "{} texels do not make a {width}×{height} image",
                    texels.len()
                ),
            });
        }
        Ok(MaterialImage {
            width,
            height,
            texels,
        })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Nearest texel at normalised `(u, v) ∈ [0, 1]²` (v up).
    #[inline]
    pub fn sample(&self, u: f64, v: f64) -> FacadeSample {
        let x = ((u * self.width as f64) as usize).min(self.width - 1);
        let y = ((v * self.height as f64) as usize).min(self.height - 1);
        self.texels
            .get(y * self.width + x)
            .copied()
            .unwrap_or_default()
    }

    /// An image from sRGB RGBA8 bytes in rows top-down (as stored in image files), with a
    /// uniform height, roughness and metalness.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] if the byte count does not match the size.
    pub fn from_rgba8(
        width: usize,
        height: usize,
        rgba: &[u8],
        base: FacadeSample,
    ) -> Result<Self> {
        if width.checked_mul(height).and_then(|n| n.checked_mul(4)) != Some(rgba.len()) {
            return Err(FacadeError::InvalidStyle {
                style: "image".into(),
                reason: format!(
                    "{} bytes are not a {width}×{height} RGBA8 image",
                    rgba.len()
                ),
            });
        }
        let mut texels = Vec::with_capacity(width * height);
        for row in (0..height).rev() {
            for px in rgba[row * width * 4..(row + 1) * width * 4].chunks_exact(4) {
                let c = |k: usize| f32::from(px[k]) / 255.0;
                texels.push(FacadeSample {
                    albedo: [c(0), c(1), c(2), c(3)],
                    ..base
                });
            }
        }
        MaterialImage::new(width, height, texels)
    }

    /// Decodes a PNG (e.g. a scanned window) into an image, through
    /// [`decode_png_rgba8`](polis_geom::field::decode_png_rgba8).
    ///
    /// # Errors
    /// [`FacadeError::Png`] for undecodable data or images too large to decode.
    #[cfg(feature = "png")]
    pub fn from_png(bytes: &[u8], base: FacadeSample) -> Result<Self> {
        let (w, h, rgba) = polis_geom::field::decode_png_rgba8(bytes).map_err(|e| match e {
            polis_geom::GeomError::Image(message) => FacadeError::Png(message),
            other => FacadeError::Png(other.to_string()),
        })?;
        let (w, h) = (w as usize, h as usize);
        MaterialImage::from_rgba8(w, h, &rgba, base)
    }
}

/// Images chosen at random per cell, with weights.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageSet {
    images: Arc<Vec<MaterialImage>>,
    cumulative: Vec<f32>,
}

impl ImageSet {
    /// A set with the given weights (empty: equal weights).
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] for no images, a weight count mismatch, or negative,
    /// non-finite or all-zero weights.
    pub fn new(images: Vec<MaterialImage>, weights: &[f32]) -> Result<Self> {
        let bad = |reason: &str| FacadeError::InvalidStyle {
            style: "image set".into(),
            reason: reason.into(),
        };
        if images.is_empty() {
            return Err(bad("an image set needs at least one image"));
        }
        let w: Vec<f32> = if weights.is_empty() {
            vec![1.0; images.len()]
        } else if weights.len() == images.len() {
            weights.to_vec()
        } else {
            return Err(bad("give one weight per image, or none"));
        };
        if w.iter().any(|x| !x.is_finite() || *x < 0.0) || w.iter().sum::<f32>() <= 0.0 {
            return Err(bad("weights must be finite, ≥ 0 and not all 0"));
        }
        let total: f32 = w.iter().sum();
        let mut acc = 0.0;
        let cumulative = w
            .iter()
            .map(|x| {
                acc += x / total;
                acc
            })
            .collect();
        Ok(ImageSet {
            images: Arc::new(images),
            cumulative,
        })
    }

    /// The images.
    pub fn images(&self) -> &[MaterialImage] {
        &self.images
    }

    /// The variant index chosen for a cell with this seed.
    #[inline]
    pub fn choose(&self, cell_seed: u64) -> usize {
        let r = unit(mix64(cell_seed ^ 0x1A6E));
        self.cumulative
            .iter()
            .position(|&c| r < c)
            .unwrap_or(self.images.len().saturating_sub(1))
    }

    /// The image chosen for a cell.
    #[inline]
    pub fn get(&self, index: usize) -> Option<&MaterialImage> {
        self.images.get(index)
    }
}

/// A serialisable description of one image.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "kind", rename_all = "snake_case"))]
pub enum ImageStyle {
    /// A sash window drawn procedurally: frame, glazing bars, glass reflecting the sky and,
    /// when open, the dark room behind the raised lower sash.
    SashWindow {
        /// Panes per sash (columns, rows).
        panes: [u32; 2],
        /// 0 = closed, 0.5 = half open, 1 = fully open (lower sash raised).
        open: f32,
        /// Frame and glazing bars.
        frame: FacadeSample,
        /// Glass at the bottom of the window.
        glass_low: FacadeSample,
        /// Glass at the top (sky reflection).
        glass_high: FacadeSample,
        /// The room seen through the opening.
        interior: FacadeSample,
        /// Curtain colour drawn at both sides, if any.
        #[cfg_attr(feature = "serde", serde(default))]
        curtain: Option<[f32; 3]>,
    },
    /// Office glazing with a blind lowered over the top part.
    Blinds {
        /// The glass.
        glass: FacadeSample,
        /// The blind slats.
        blind: FacadeSample,
        /// Fraction of the height covered by the blind, from the top.
        lowered: f32,
    },
    /// Raw sRGB RGBA8 pixels (top-down rows), e.g. a scan; alpha < 128 is inactive.
    Rgba {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
        /// `width × height × 4` bytes.
        rgba: Vec<u8>,
        /// Height, roughness and metalness of every texel.
        base: FacadeSample,
    },
}

impl ImageStyle {
    /// Draws or decodes the image.
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`] for bad parameters.
    pub fn build(&self) -> Result<MaterialImage> {
        let [w, h] = BUILTIN_IMAGE_SIZE;
        match self {
            ImageStyle::SashWindow {
                panes,
                open,
                frame,
                glass_low,
                glass_high,
                interior,
                curtain,
            } => {
                if !open.is_finite()
                    || panes[0] == 0
                    || panes[1] == 0
                    || panes[0] > 16
                    || panes[1] > 16
                {
                    return Err(FacadeError::InvalidStyle {
                        style: "sash window".into(),
                        reason: "panes must be 1..=16 each and `open` finite".into(),
                    });
                }
                let open = open.clamp(0.0, 1.0);
                let mut tex = Vec::with_capacity(w * h);
                let frame_x = 0.07;
                let frame_y = 0.045;
                let meeting = 0.5; // meeting rail of the two sashes
                // The lower sash is raised by `open × half the height`.
                let raise = open * 0.5 * (1.0 - 2.0 * frame_y);
                for y in 0..h {
                    let v = (y as f32 + 0.5) / h as f32;
                    for x in 0..w {
                        let u = (x as f32 + 0.5) / w as f32;
                        let border =
                            u < frame_x || u > 1.0 - frame_x || v < frame_y || v > 1.0 - frame_y;
                        let inner_u = ((u - frame_x) / (1.0 - 2.0 * frame_x)).clamp(0.0, 1.0);
                        let sky = glass_low.lerp(glass_high, v);
                        let sash = |v0: f32, v1: f32| -> Option<FacadeSample> {
                            if v < v0 || v >= v1 {
                                return None;
                            }
                            let lv = (v - v0) / (v1 - v0);
                            let bar_u = (inner_u * panes[0] as f32).fract();
                            let bar_v = (lv * panes[1] as f32).fract();
                            let rail = !(0.04..=0.96).contains(&lv);
                            let bar =
                                !(0.04..=0.96).contains(&bar_u) || !(0.03..=0.97).contains(&bar_v);
                            Some(if rail || bar { *frame } else { sky })
                        };
                        let t = if border {
                            *frame
                        } else if let Some(s) =
                            sash(meeting + raise, 1.0 - frame_y).filter(|_| raise > 0.0)
                        {
                            // The raised lower sash now lies over the upper one.
                            s
                        } else if v < frame_y + raise {
                            // The opening below the raised lower sash.
                            *interior
                        } else if let Some(s) = sash(frame_y + raise, meeting + raise) {
                            s
                        } else {
                            sash(meeting, 1.0 - frame_y).unwrap_or(sky)
                        };
                        let t = match curtain {
                            Some(c) if !border && !(0.16..=0.84).contains(&inner_u) => {
                                FacadeSample::rgb(c[0], c[1], c[2]).with_height(t.height)
                            }
                            _ => t,
                        };
                        tex.push(t);
                    }
                }
                MaterialImage::new(w, h, tex)
            }
            ImageStyle::Blinds {
                glass,
                blind,
                lowered,
            } => {
                if !lowered.is_finite() {
                    return Err(FacadeError::InvalidStyle {
                        style: "blinds".into(),
                        reason: "`lowered` must be finite".into(),
                    });
                }
                let lowered = lowered.clamp(0.0, 1.0);
                let mut tex = Vec::with_capacity(w * h);
                for y in 0..h {
                    let v = (y as f32 + 0.5) / h as f32;
                    for _ in 0..w {
                        tex.push(if v > 1.0 - lowered {
                            if y % 4 == 0 { blind.shade(0.8) } else { *blind }
                        } else {
                            glass.shade(0.85 + 0.3 * v)
                        });
                    }
                }
                MaterialImage::new(w, h, tex)
            }
            ImageStyle::Rgba {
                width,
                height,
                rgba,
                base,
            } => MaterialImage::from_rgba8(*width, *height, rgba, *base),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sash(open: f32) -> ImageStyle {
        ImageStyle::SashWindow {
            panes: [2, 2],
            open,
            frame: FacadeSample::rgb(0.95, 0.95, 0.95),
            glass_low: FacadeSample::rgb(0.2, 0.25, 0.3).with_pbr(0.05, 0.0),
            glass_high: FacadeSample::rgb(0.5, 0.6, 0.7).with_pbr(0.05, 0.0),
            interior: FacadeSample::rgb(0.05, 0.04, 0.03),
            curtain: None,
        }
    }

    #[test]
    fn open_window_shows_interior_closed_does_not() {
        let closed = sash(0.0).build().unwrap();
        let open = sash(1.0).build().unwrap();
        let dark = |img: &MaterialImage| {
            let mut n = 0;
            for y in 0..img.height() {
                for x in 0..img.width() {
                    let s = img.sample(
                        (x as f64 + 0.5) / img.width() as f64,
                        (y as f64 + 0.5) / img.height() as f64,
                    );
                    if s.albedo[0] < 0.1 {
                        n += 1;
                    }
                }
            }
            n
        };
        assert_eq!(dark(&closed), 0);
        assert!(dark(&open) > 500);
        assert!(dark(&sash(0.5).build().unwrap()) < dark(&open));
    }

    #[test]
    fn weighted_choice_is_deterministic_and_covers_all() {
        let imgs = vec![
            sash(0.0).build().unwrap(),
            sash(0.5).build().unwrap(),
            sash(1.0).build().unwrap(),
        ];
        let set = ImageSet::new(imgs, &[2.0, 1.0, 1.0]).unwrap();
        let mut counts = [0; 3];
        for k in 0..4000u64 {
            let c = set.choose(mix64(k));
            assert_eq!(c, set.choose(mix64(k)));
            counts[c] += 1;
        }
        assert!(counts[0] > 1700 && counts[0] < 2300, "{counts:?}");
        assert!(counts[1] > 800 && counts[2] > 800);
        assert!(ImageSet::new(vec![], &[]).is_err());
    }

    #[test]
    fn rgba_rows_are_flipped_and_png_round_trips() {
        // 1×2 image: top red, bottom blue.
        let img = MaterialImage::from_rgba8(
            1,
            2,
            &[255, 0, 0, 255, 0, 0, 255, 255],
            FacadeSample::default(),
        )
        .unwrap();
        assert_eq!(img.sample(0.5, 0.9).albedo[0], 1.0);
        assert_eq!(img.sample(0.5, 0.1).albedo[2], 1.0);
        #[cfg(feature = "png")]
        {
            let png = crate::raster::encode_png(
                1,
                2,
                png::ColorType::Rgba,
                &[255, 0, 0, 255, 0, 0, 255, 255],
            )
            .unwrap();
            assert_eq!(
                MaterialImage::from_png(&png, FacadeSample::default()).unwrap(),
                img
            );
            assert!(MaterialImage::from_png(b"not a png", FacadeSample::default()).is_err());
        }
        assert!(MaterialImage::from_rgba8(2, 2, &[0; 4], FacadeSample::default()).is_err());
    }
}
