//! Colour quantisation of the rendered image to an indexed PNG: a README picture a third
//! the size of its RGB encoding.
//!
//! 1. **Median cut** (Heckbert 1982) over the image's distinct colours, weighted by
//!    how many pixels have them: the box whose widest channel range × pixel count is the
//!    largest is split at the weighted median of that channel, until there are as many
//!    boxes as palette entries or no box holds two colours.
//! 2. **Lloyd refinement** (k-means): each distinct colour goes to its nearest palette
//!    entry, each entry moves to the weighted mean of its colours; a few rounds.
//! 3. Each pixel takes its colour's nearest entry; no dithering (dither noise is what
//!    DEFLATE compresses worst, and a 3-D view has few smooth gradients but the sky).
//!
//! Deterministic: colours are sorted before every step, ties broken by colour value.

/// Rounds of Lloyd refinement after the median cut.
const LLOYD_ROUNDS: usize = 3;

/// A distinct colour and how many pixels have it.
#[derive(Clone, Copy)]
struct Count {
    rgb: [u8; 3],
    n: u64,
}

/// The palette (at most `size` entries, `size` in 1..=256) and one index per pixel of
/// `rgb` (3 bytes a pixel).
pub fn quantize(rgb: &[u8], size: usize) -> (Vec<[u8; 3]>, Vec<u8>) {
    let size = size.clamp(1, 256);
    let mut keys: Vec<u32> = rgb
        .chunks_exact(3)
        .map(|p| u32::from_be_bytes([0, p[0], p[1], p[2]]))
        .collect();
    keys.sort_unstable();
    let mut colours: Vec<Count> = Vec::new();
    for k in keys {
        let [_, r, g, b] = k.to_be_bytes();
        match colours.last_mut() {
            Some(c) if c.rgb == [r, g, b] => c.n += 1,
            _ => colours.push(Count {
                rgb: [r, g, b],
                n: 1,
            }),
        }
    }
    let mut palette = median_cut(&mut colours, size);
    for _ in 0..LLOYD_ROUNDS {
        palette = lloyd(&colours, &palette);
    }
    // The median cut reordered the colours: sorted again for the look-up below.
    colours.sort_unstable_by_key(|c| c.rgb);
    let nearest: Vec<u8> = colours
        .iter()
        .map(|c| nearest(&palette, c.rgb) as u8)
        .collect();
    let indices = rgb
        .chunks_exact(3)
        .map(|p| {
            let i = colours
                .binary_search_by_key(&[p[0], p[1], p[2]], |c| c.rgb)
                .unwrap_or(0);
            nearest[i]
        })
        .collect();
    (palette, indices)
}

/// Heckbert's median cut of `colours` into at most `size` boxes; the boxes' weighted means.
fn median_cut(colours: &mut [Count], size: usize) -> Vec<[u8; 3]> {
    let mut boxes: Vec<(usize, usize)> = vec![(0, colours.len())];
    while boxes.len() < size {
        // The box to split: widest channel range × pixels, among boxes of two colours or more.
        let best = boxes
            .iter()
            .enumerate()
            .filter(|(_, (a, b))| b - a >= 2)
            .map(|(i, &(a, b))| {
                let (channel, range) = widest(&colours[a..b]);
                let pixels: u64 = colours[a..b].iter().map(|c| c.n).sum();
                (u64::from(range) * pixels, i, channel)
            })
            .max_by_key(|&(score, i, _)| (score, std::cmp::Reverse(i)));
        let Some((score, i, channel)) = best else {
            break;
        };
        if score == 0 {
            break;
        }
        let (a, b) = boxes[i];
        let part = &mut colours[a..b];
        part.sort_unstable_by_key(|c| (c.rgb[channel], c.rgb));
        let total: u64 = part.iter().map(|c| c.n).sum();
        let mut acc = 0;
        let mut cut = 1;
        for (k, c) in part.iter().enumerate() {
            acc += c.n;
            if 2 * acc >= total {
                cut = (k + 1).clamp(1, part.len() - 1);
                break;
            }
        }
        boxes[i] = (a, a + cut);
        boxes.push((a + cut, b));
    }
    boxes
        .iter()
        .map(|&(a, b)| mean(colours[a..b].iter()))
        .collect()
}

/// The channel with the widest range over `colours`, and that range.
fn widest(colours: &[Count]) -> (usize, u8) {
    let (mut lo, mut hi) = ([255u8; 3], [0u8; 3]);
    for c in colours {
        for k in 0..3 {
            lo[k] = lo[k].min(c.rgb[k]);
            hi[k] = hi[k].max(c.rgb[k]);
        }
    }
    (0..3)
        .map(|k| (k, hi[k] - lo[k]))
        .max_by_key(|&(k, r)| (r, std::cmp::Reverse(k)))
        .unwrap_or((0, 0))
}

/// The pixel-weighted mean colour.
fn mean<'a>(colours: impl Iterator<Item = &'a Count>) -> [u8; 3] {
    let (mut sum, mut n) = ([0u64; 3], 0u64);
    for c in colours {
        for (s, &v) in sum.iter_mut().zip(&c.rgb) {
            *s += u64::from(v) * c.n;
        }
        n += c.n;
    }
    sum.map(|s| (s + n / 2).checked_div(n).unwrap_or(0) as u8)
}

/// One Lloyd round: every colour to its nearest entry, every entry to its colours' mean
/// (an entry that keeps no colour stays where it is).
fn lloyd(colours: &[Count], palette: &[[u8; 3]]) -> Vec<[u8; 3]> {
    let mut sums = vec![([0u64; 3], 0u64); palette.len()];
    for c in colours {
        let (sum, n) = &mut sums[nearest(palette, c.rgb)];
        for (s, &v) in sum.iter_mut().zip(&c.rgb) {
            *s += u64::from(v) * c.n;
        }
        *n += c.n;
    }
    sums.iter()
        .zip(palette)
        .map(|((sum, n), &old)| {
            if *n == 0 {
                old
            } else {
                sum.map(|s| ((s + n / 2) / n) as u8)
            }
        })
        .collect()
}

/// Index of the entry nearest to `rgb` (squared distance, red and blue weighted 2 and 3,
/// green 4, roughly the eye's sensitivity); the first of equals.
fn nearest(palette: &[[u8; 3]], rgb: [u8; 3]) -> usize {
    let mut best = (u32::MAX, 0);
    for (i, p) in palette.iter().enumerate() {
        let d = |k: usize| {
            let v = i32::from(p[k]) - i32::from(rgb[k]);
            (v * v) as u32
        };
        let dist = 2 * d(0) + 4 * d(1) + 3 * d(2);
        if dist < best.0 {
            best = (dist, i);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An image with no more colours than the palette keeps every pixel exactly.
    #[test]
    fn few_colours_are_kept_exactly() {
        let colours = [[10u8, 20, 30], [200, 100, 0], [0, 0, 0], [255, 255, 255]];
        let rgb: Vec<u8> = (0..400).flat_map(|i| colours[(i * 7) % 4]).collect();
        let (palette, indices) = quantize(&rgb, 16);
        assert_eq!(palette.len(), 4);
        for (p, &i) in rgb.chunks_exact(3).zip(&indices) {
            assert_eq!(palette[usize::from(i)], [p[0], p[1], p[2]]);
        }
    }

    /// A smooth gradient of many colours lands within a few levels of each pixel.
    #[test]
    fn a_gradient_is_close_after_quantisation() {
        let rgb: Vec<u8> = (0..256 * 64)
            .flat_map(|i| {
                let (x, y) = ((i % 256) as u8, (i / 256) as u8);
                [x, y.wrapping_mul(4), x / 2 + y]
            })
            .collect();
        let (palette, indices) = quantize(&rgb, 256);
        assert!(palette.len() <= 256);
        let worst = rgb
            .chunks_exact(3)
            .zip(&indices)
            .map(|(p, &i)| {
                let q = palette[usize::from(i)];
                (0..3)
                    .map(|k| (i32::from(p[k]) - i32::from(q[k])).abs())
                    .max()
                    .unwrap_or(0)
            })
            .max()
            .unwrap_or(0);
        assert!(worst <= 24, "worst channel error {worst}");
    }
}
