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

use crate::MAX_TEXTURE_TEXELS;
use crate::error::{FacadeError, Result, check_range};
use crate::facade::Facade;
use crate::sample::FacadeSample;
use crate::stack::LayerStack;
use crate::sweep::{RowRuns, RowSweep, RunKind};

/// Heights in `[−HEIGHT_RANGE_M, +HEIGHT_RANGE_M]` metres map to the normal map's alpha.
pub const HEIGHT_RANGE_M: f32 = 0.5;

/// How to rasterise.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct RasterOptions {
    /// Texels per metre. Default: 64 (a 1.1 m window is 70 texels wide).
    pub pixels_per_metre: f64,
    /// Multiplies the height slopes in the normal map (1 = physical). Default: 1.
    pub normal_strength: f32,
    /// Round each texture's width and height to the nearest power of two (the texels
    /// then stretch to cover the same metres): images that suit repeating, mipmapped samplers
    /// (the Khronos glTF validator warns on non-power-of-two images used so, as WebGL 1
    /// cannot sample them). Default: false.
    #[cfg_attr(feature = "serde", serde(default))]
    pub power_of_two: bool,
}

impl Default for RasterOptions {
    fn default() -> Self {
        RasterOptions {
            pixels_per_metre: 64.0,
            normal_strength: 1.0,
            power_of_two: false,
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
    #[cfg(feature = "png")]
    pub fn albedo_png(&self) -> Result<Vec<u8>> {
        encode_png(self.width, self.height, png::ColorType::Rgba, &self.albedo)
    }

    /// The normal map (height in alpha) as a PNG file.
    ///
    /// # Errors
    /// [`FacadeError::Png`].
    #[cfg(feature = "png")]
    pub fn normal_png(&self) -> Result<Vec<u8>> {
        encode_png(self.width, self.height, png::ColorType::Rgba, &self.normal)
    }

    /// The metallic-roughness texture as a PNG file.
    ///
    /// # Errors
    /// [`FacadeError::Png`].
    #[cfg(feature = "png")]
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
#[cfg(feature = "png")]
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
pub(crate) fn to_u8(v: f32) -> u8 {
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
    // The outputs grow row by row (each row is zeroed just before it is written, while it
    // is in cache, instead of zeroing whole textures up front).
    let mut albedo = Vec::with_capacity(n * 4);
    let mut mr = Vec::with_capacity(n * 4);
    let mut heights = Vec::with_capacity(n);
    let mut normal = Vec::with_capacity(n * 4);
    let ds = region.width() / w as f64;
    let dt = region.height() / h as f64;
    let mut sweep = RowSweep::new(region.min.x, ds, w);
    // The last three rows as runs and as height segments (row y lives in slot y % 3).
    let mut runs: [RowRuns; 3] = Default::default();
    let mut hsegs: [Vec<HSeg>; 3] = Default::default();
    let mut conv = Converter::new(tint);
    let mut normals = NormalRows::new(w, h, ds, dt, normal_strength);
    for y in 0..h {
        let t = region.max.y - (y as f64 + 0.5) * dt;
        let slot = y % 3;
        let prev = (y + 2) % 3;
        sweep.row_runs(stack, t, &mut runs[slot]);
        let (row4, row1) = (y * w * 4..(y + 1) * w * 4, y * w..(y + 1) * w);
        if y > 0 && runs[slot] == runs[prev] {
            // Rows often repeat (inside a course of bricks, a band of cladding): copy.
            let (p4, p1) = (row4.start - w * 4, row1.start - w);
            albedo.extend_from_within(p4..row4.start);
            mr.extend_from_within(p4..row4.start);
            heights.extend_from_within(p1..row1.start);
            let [a, b, c] = &mut hsegs;
            let (dst, src) = match slot {
                0 => (a, &*c),
                1 => (b, &*a),
                _ => (c, &*b),
            };
            dst.clone_from(src);
        } else {
            conv.row(&runs[slot], &sweep, w, &mut albedo, &mut mr, &mut heights);
            height_segments(&runs[slot], &mut hsegs[slot]);
        }
        // Row y − 1 now has both neighbours: derive its normals.
        if y > 0 {
            normal.resize(y * w * 4, 0);
            normals.row(y - 1, &hsegs, &heights, &mut normal);
        }
    }
    normal.resize(n * 4, 0);
    normals.row(h - 1, &hsegs, &heights, &mut normal);
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

/// Converts runs of samples into RGBA8 texels, once per run.
struct Converter {
    tint: f32,
    /// The last converted constant sample and its albedo and metallic-roughness texels.
    last: Option<(FacadeSample, [u8; 4], [u8; 4])>,
    /// Converted column strips, by strip id: (albedo, metallic-roughness) of every texel.
    strips: Vec<Option<(Vec<u8>, Vec<u8>)>>,
}

impl Converter {
    fn new(tint: f32) -> Self {
        Converter {
            tint,
            last: None,
            strips: Vec::new(),
        }
    }

    #[inline]
    fn texels(&self, m: &FacadeSample) -> ([u8; 4], [u8; 4]) {
        let tint = self.tint;
        (
            [
                to_u8(m.albedo[0] * tint),
                to_u8(m.albedo[1] * tint),
                to_u8(m.albedo[2] * tint),
                to_u8(m.albedo[3]),
            ],
            [255, to_u8(m.roughness), to_u8(m.metallic), 255],
        )
    }

    /// Appends one row (`w` texels) of albedo, metallic-roughness and height from its
    /// runs.
    fn row(
        &mut self,
        runs: &RowRuns,
        sweep: &RowSweep,
        w: usize,
        albedo: &mut Vec<u8>,
        mr: &mut Vec<u8>,
        heights: &mut Vec<f32>,
    ) {
        let (a0, m0, h0) = (albedo.len(), mr.len(), heights.len());
        let mut a = 0usize;
        for run in &runs.runs {
            let b = (run.end as usize).min(w);
            if b <= a {
                continue;
            }
            match run.kind {
                RunKind::Const(m) => {
                    let (pa, pm) = match self.last {
                        Some((p, pa, pm)) if p == m => (pa, pm),
                        _ => {
                            let (pa, pm) = self.texels(&m);
                            self.last = Some((m, pa, pm));
                            (pa, pm)
                        }
                    };
                    push4(albedo, pa, b - a);
                    push4(mr, pm, b - a);
                    heights.extend(std::iter::repeat_n(m.height, b - a));
                }
                RunKind::Strip(id) => {
                    let samples = sweep.strip_samples(id);
                    let k = id as usize;
                    if self.strips.len() <= k {
                        self.strips.resize(k + 1, None);
                    }
                    if self.strips.get(k).is_some_and(Option::is_none) {
                        let mut sa = Vec::with_capacity(samples.len() * 4);
                        let mut sm = Vec::with_capacity(samples.len() * 4);
                        for m in samples {
                            let (pa, pm) = self.texels(m);
                            sa.extend_from_slice(&pa);
                            sm.extend_from_slice(&pm);
                        }
                        if let Some(slot) = self.strips.get_mut(k) {
                            *slot = Some((sa, sm));
                        }
                    }
                    if let Some(Some((sa, sm))) = self.strips.get(k)
                        && let (Some(src_a), Some(src_m), Some(src_h)) = (
                            sa.get(a * 4..b * 4),
                            sm.get(a * 4..b * 4),
                            samples.get(a..b),
                        )
                    {
                        albedo.extend_from_slice(src_a);
                        mr.extend_from_slice(src_m);
                        heights.extend(src_h.iter().map(|m| m.height));
                    }
                }
            }
            a = b;
            // Keep the three outputs in step even if a strip were missing.
            albedo.resize(a0 + a * 4, 0);
            mr.resize(m0 + a * 4, 0);
            heights.resize(h0 + a, 0.0);
        }
        albedo.resize(a0 + w * 4, 0);
        mr.resize(m0 + w * 4, 0);
        heights.resize(h0 + w, 0.0);
    }
}

/// Appends `n` copies of the texel `p` to `dst` (in 64-byte blocks, without zeroing).
#[inline]
fn push4(dst: &mut Vec<u8>, p: [u8; 4], n: usize) {
    let block = [p; 16];
    let block = block.as_flattened();
    let mut left = n * 4;
    while left >= block.len() {
        dst.extend_from_slice(block);
        left -= block.len();
    }
    dst.extend_from_slice(block.get(..left).unwrap_or_default());
}

/// Writes the texel `p` into every 4-byte texel of `dst`.
#[inline]
fn fill4(dst: &mut [u8], p: [u8; 4]) {
    for px in dst.chunks_exact_mut(4) {
        px.copy_from_slice(&p);
    }
}

/// A run of a row's height field: constant (bit pattern) or a column strip's heights.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum HKind {
    Const(u32),
    Strip(u32),
}

/// A segment of a row's height field ending (exclusive) at `end`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct HSeg {
    end: u32,
    kind: HKind,
}

/// The maximal segments of equal height (or of one strip) of a row.
fn height_segments(runs: &RowRuns, out: &mut Vec<HSeg>) {
    out.clear();
    for run in &runs.runs {
        let kind = match run.kind {
            RunKind::Const(m) => HKind::Const(m.height.to_bits()),
            RunKind::Strip(id) => HKind::Strip(id),
        };
        match out.last_mut() {
            Some(last) if last.kind == kind => last.end = run.end,
            _ => out.push(HSeg { end: run.end, kind }),
        }
    }
}

/// The normal-map texel for heights left, right, up, down and centre with slope factors
/// `k` (along the row) and `ky` (across rows); the height itself goes to alpha.
#[inline]
fn normal_texel(l: f32, r: f32, u: f32, d: f32, c: f32, k: f32, ky: f32) -> [u8; 4] {
    let alpha = to_u8(c * (0.5 / HEIGHT_RANGE_M) + 0.5);
    if l == r && u == d {
        return [128, 128, 255, alpha];
    }
    // Row y0 is higher up the wall than y1: dh/dt = (h(y0) − h(y1)) / Δt.
    let (nx, ny) = (-(r - l) * k, -(u - d) * ky);
    let inv = 1.0 / (nx * nx + ny * ny + 1.0).sqrt();
    [
        to_u8(nx * inv * 0.5 + 0.5),
        to_u8(ny * inv * 0.5 + 0.5),
        to_u8(inv * 0.5 + 0.5),
        alpha,
    ]
}

/// The normal-map derivation fused into the row loop: row `y` is derived as soon as row
/// `y + 1` exists, segment by segment of constant heights (only texels next to a height
/// change are computed one by one), and copied when its neighbourhood repeats the last
/// one. Equal, texel for texel, to [`normals_from_heights`].
struct NormalRows {
    w: usize,
    h: usize,
    dt: f64,
    strength: f32,
    k_in: f32,
    k_edge: f32,
    /// The last derived row, its slope factor across rows and its neighbourhood.
    last: Option<(usize, u32)>,
    last_segs: [Vec<HSeg>; 3],
}

impl NormalRows {
    fn new(w: usize, h: usize, ds: f64, dt: f64, strength: f32) -> Self {
        // One-sided differences at the borders span one texel, central ones two.
        let kx = |span: usize| strength / (span.max(1) as f64 * ds) as f32;
        NormalRows {
            w,
            h,
            dt,
            strength,
            k_in: kx(2),
            k_edge: kx(1),
            last: None,
            last_segs: Default::default(),
        }
    }

    /// Derives row `y` (its rows `y − 1`, `y`, `y + 1`, clamped, are in `heights` and in
    /// `segs[row % 3]`).
    fn row(&mut self, y: usize, segs: &[Vec<HSeg>; 3], heights: &[f32], out: &mut [u8]) {
        let (w, h) = (self.w, self.h);
        if y >= h || w == 0 {
            return;
        }
        let (y0, y1) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let ky = self.strength / ((y1 - y0).max(1) as f64 * self.dt) as f32;
        let (Some(su), Some(sc), Some(sd)) = (segs.get(y0 % 3), segs.get(y % 3), segs.get(y1 % 3))
        else {
            return;
        };
        let row4 = y * w * 4..(y + 1) * w * 4;
        if let Some((ly, lk)) = self.last
            && lk == ky.to_bits()
            && self.last_segs[0] == *su
            && self.last_segs[1] == *sc
            && self.last_segs[2] == *sd
        {
            out.copy_within(ly * w * 4..(ly + 1) * w * 4, row4.start);
            return;
        }
        let row_of = |r: usize| heights.get(r * w..r * w + w).unwrap_or_default();
        let (up, cur, dn) = (row_of(y0), row_of(y), row_of(y1));
        let Some(orow) = out.get_mut(row4) else {
            return;
        };
        let (k_in, k_edge) = (self.k_in, self.k_edge);
        let at = |x: usize| -> [u8; 4] {
            let (Some(&c), Some(&u), Some(&d)) = (cur.get(x), up.get(x), dn.get(x)) else {
                return [0; 4];
            };
            if x == 0 {
                let r = cur.get(1).copied().unwrap_or(c);
                normal_texel(c, r, u, d, c, k_edge, ky)
            } else if x + 1 == w {
                let l = cur.get(x - 1).copied().unwrap_or(c);
                normal_texel(l, c, u, d, c, k_edge, ky)
            } else {
                let l = cur.get(x - 1).copied().unwrap_or(c);
                let r = cur.get(x + 1).copied().unwrap_or(c);
                normal_texel(l, r, u, d, c, k_in, ky)
            }
        };
        let put = |orow: &mut [u8], x: usize, p: [u8; 4]| {
            if let Some(px) = orow.get_mut(x * 4..x * 4 + 4) {
                px.copy_from_slice(&p);
            }
        };
        let (mut iu, mut ic, mut id) = (0usize, 0usize, 0usize);
        let mut a = 0usize;
        while a < w {
            let (Some(gu), Some(gc), Some(gd)) = (su.get(iu), sc.get(ic), sd.get(id)) else {
                // Malformed segments (never produced): derive the rest texel by texel.
                for x in a..w {
                    put(orow, x, at(x));
                }
                break;
            };
            let b = (gu.end.min(gc.end).min(gd.end) as usize).min(w);
            if b <= a {
                for x in a..w {
                    put(orow, x, at(x));
                }
                break;
            }
            match (gu.kind, gc.kind, gd.kind) {
                (HKind::Const(hu), HKind::Const(hc), HKind::Const(hd)) if b - a >= 3 => {
                    put(orow, a, at(a));
                    let (hu, hc, hd) = (f32::from_bits(hu), f32::from_bits(hc), f32::from_bits(hd));
                    // Inside the segment every texel sees the same neighbourhood.
                    let p = normal_texel(hc, hc, hu, hd, hc, k_in, ky);
                    fill4(
                        orow.get_mut((a + 1) * 4..(b - 1) * 4).unwrap_or_default(),
                        p,
                    );
                    put(orow, b - 1, at(b - 1));
                }
                _ => {
                    for x in a..b {
                        put(orow, x, at(x));
                    }
                }
            }
            for (seg, i) in [(su, &mut iu), (sc, &mut ic), (sd, &mut id)] {
                if seg.get(*i).is_some_and(|g| g.end as usize <= b) {
                    *i += 1;
                }
            }
            a = b;
        }
        self.last = Some((y, ky.to_bits()));
        self.last_segs[0].clone_from(su);
        self.last_segs[1].clone_from(sc);
        self.last_segs[2].clone_from(sd);
    }
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
        let texel = |l: f32, r: f32, u: f32, d: f32, c: f32, k: f32, px: &mut [u8]| {
            px.copy_from_slice(&normal_texel(l, r, u, d, c, k, ky));
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
            let mut v = (m * ppm).round().max(1.0);
            if opts.power_of_two && v <= f64::from(1u32 << 31) {
                // The nearest power of two (texture memory stays about the same).
                let up = (v as u32).next_power_of_two();
                let down = (up / 2).max(1);
                v = f64::from(if v - f64::from(down) < f64::from(up) - v {
                    down
                } else {
                    up
                });
            }
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
    use crate::color::Col;
    use crate::facade::{FacadeSpec, FaceRole, PreparedStyle};
    use crate::interval::IntervalGroup;
    use crate::layer::{Eval, Layer};
    use crate::profile::Profile;

    /// The rasteriser as it was before runs, column strips and fused normals: every texel
    /// sampled by the row sweep and converted on its own, normals derived afterwards from
    /// the whole height field. The run rasteriser must give the same bytes.
    fn reference(
        stack: &LayerStack,
        region: &Aabb2,
        w: usize,
        h: usize,
        tint: f32,
        strength: f32,
    ) -> FacadeTextures {
        let ds = region.width() / w as f64;
        let dt = region.height() / h as f64;
        let mut sweep = RowSweep::new(region.min.x, ds, w);
        let mut row = vec![FacadeSample::default(); w];
        let (mut albedo, mut mr, mut heights) = (vec![], vec![], vec![]);
        for y in 0..h {
            let t = region.max.y - (y as f64 + 0.5) * dt;
            sweep.row(stack, t, &mut row);
            for m in &row {
                albedo.extend([
                    to_u8(m.albedo[0] * tint),
                    to_u8(m.albedo[1] * tint),
                    to_u8(m.albedo[2] * tint),
                    to_u8(m.albedo[3]),
                ]);
                mr.extend([255, to_u8(m.roughness), to_u8(m.metallic), 255]);
                heights.push(m.height);
            }
        }
        FacadeTextures {
            width: w as u32,
            height: h as u32,
            size_m: [region.width(), region.height()],
            normal: normals_from_heights(&heights, w, h, ds, dt, strength),
            albedo,
            metallic_roughness: mr,
            height_m: heights,
        }
    }

    fn same_as_reference(stack: &LayerStack, region: &Aabb2, w: u32, h: u32, tint: f32) {
        for strength in [1.0, 3.5] {
            let got = rasterize_stack(stack, region, w, h, tint, strength).unwrap();
            let want = reference(stack, region, w as usize, h as usize, tint, strength);
            assert!(got.albedo == want.albedo, "albedo differs");
            assert!(
                got.metallic_roughness == want.metallic_roughness,
                "mr differs"
            );
            assert!(got.height_m == want.height_m, "heights differ");
            if let Some(k) = (0..got.normal.len()).find(|&k| got.normal[k] != want.normal[k]) {
                panic!("normal byte {k} (texel {}) differs", k / 4);
            }
            assert_eq!(got, want);
        }
    }

    #[test]
    fn runs_give_the_bytes_of_texel_by_texel_rasterisation() {
        for style in builtin::builtin_styles() {
            let p = PreparedStyle::new(style).unwrap();
            for (w, h, role, ppm) in [
                (20.0, 15.0, FaceRole::Street, 24.0),
                (7.3, 9.1, FaceRole::Street, 37.0),
                (13.0, 30.0, FaceRole::Side, 9.5),
                (2.0, 2.0, FaceRole::Blank, 16.0),
            ] {
                let f = p
                    .facade(&FacadeSpec {
                        role,
                        ..FacadeSpec::new(w, h, 23)
                    })
                    .unwrap();
                let (tw, th) = ((w * ppm).round() as u32, (h * ppm).round() as u32);
                let full = Aabb2::new(DVec2::ZERO, DVec2::new(w, h));
                same_as_reference(f.stack(), &full, tw, th, f.tint());
                // An off-origin region, and degenerate 1-texel-wide and -high rasters.
                let part = Aabb2::new(DVec2::new(0.37 * w, 0.21 * h), DVec2::new(w, 0.9 * h));
                same_as_reference(f.stack(), &part, tw / 2 + 1, th / 3 + 1, 1.0);
                same_as_reference(f.stack(), &full, 1, th, 1.0);
                same_as_reference(f.stack(), &full, tw, 1, 1.0);
                same_as_reference(f.stack(), &full, 2, 2, 1.0);
            }
        }
    }

    #[test]
    fn runs_match_the_reference_on_strips_and_closures() {
        // Corrugation (a column strip) under a closure colour and bricks in the cell.
        let u = IntervalGroup::from_lengths([
            (1.0, "a", Profile::Off),
            (2.0, "b", Profile::Centered { size_m: 1.3 }),
            (1.5, "a", Profile::Off),
        ])
        .unwrap();
        let v = IntervalGroup::from_lengths([
            (1.2, "a", Profile::Off),
            (
                2.5,
                "b",
                Profile::Inset {
                    start_m: 0.3,
                    end_m: 0.2,
                },
            ),
        ])
        .unwrap();
        let whole = |l: f64| IntervalGroup::single(l, "w", Profile::Full).unwrap();
        let sheet = Layer::new(
            whole(4.5),
            whole(3.7),
            Eval::Always,
            Col::Corrugated {
                base: FacadeSample::rgb(0.4, 0.5, 0.6),
                period_m: 0.17,
                depth_m: 0.03,
                vertical: true,
            },
        )
        .with_depth(0.01);
        let blocks = Layer::new(
            u.clone(),
            v.clone(),
            Eval::And,
            Col::Bricks(crate::color::Bricks {
                brick: FacadeSample::rgb(0.7, 0.6, 0.5),
                mortar: FacadeSample::rgb(0.3, 0.3, 0.3).with_height(-0.02),
                size_m: [0.31, 0.13],
                joint_m: 0.02,
                bond: 0.5,
                variation: 0.2,
                in_cell: true,
                salt: 4,
            }),
        );
        let dots = Layer::new(
            u,
            v,
            Eval::Or,
            Col::custom(|c| {
                FacadeSample::rgb((c.s / 5.0) as f32, 0.2, 0.3).with_height((c.t * 0.01) as f32)
            }),
        )
        .with_masks(Some(vec![false, false, true]), None);
        let stack = LayerStack::new(
            vec![sheet, blocks, dots],
            vec![crate::stack::Influence::Border {
                source: 1,
                target: 0,
                margin_m: 0.12,
                col: Col::Corrugated {
                    base: FacadeSample::rgb(0.9, 0.8, 0.1),
                    period_m: 0.05,
                    depth_m: 0.01,
                    vertical: true,
                },
            }],
            None,
        )
        .unwrap();
        let full = Aabb2::new(DVec2::ZERO, DVec2::new(4.5, 3.7));
        same_as_reference(&stack, &full, 171, 133, 0.93);
        same_as_reference(&stack, &full, 45, 37, 1.0);
    }

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
