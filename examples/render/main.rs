//! Renders a generated city's 3-D scene to a PNG with a small software rasteriser, so a
//! picture of the city needs nothing but this workspace:
//!
//! ```text
//! cargo run --release --example render -- [--preset NAME] [--seed N] [--size METRES]
//!     [--lod N] [--target X,Y] [--view AZIMUTH,ELEVATION,DISTANCE] [--fov DEGREES]
//!     [--width PX] [--height PX] [--samples N] [--out FILE.png]
//! cargo run --release --example render -- --help
//! ```
//!
//! The camera looks at `--target` (layout metres: x east, y north; default the centre of
//! the tallest buildings; at the height of the ground there) from `DISTANCE` metres away, `AZIMUTH` degrees clockwise from north and
//! `ELEVATION` degrees above the horizon. The default writes `out/city-3d.png`, the
//! README's rendered view.
//!
//! How it draws:
//! - **Visibility:** every triangle is clipped to the near plane, projected, and
//!   rasterised into a depth buffer that keeps the nearest triangle's index per sample
//!   (`--samples` × `--samples` samples per pixel, averaged at the end).
//! - **Shading**, once per sample: the camera ray is intersected with its triangle for the
//!   exact point, texture coordinates and their screen-space footprint (which picks the
//!   mip level); the sun's light is masked by a shadow map (orthographic depth from the
//!   sun, filtered over 3 × 3 texels); sky and ground light fill the shadows; distant
//!   points fade into haze. Pixels with no triangle show the ground plane or the sky.
//! - **Colour:** material colours are linear and textures sRGB, as in glTF; the result is
//!   encoded as sRGB, then quantised to a 256-colour palette (median cut and k-means,
//!   no dithering) and written as an indexed PNG, a third of the RGB file's size.

#[allow(dead_code)]
#[path = "../common/cli.rs"]
mod cli;
mod palette;

use std::path::PathBuf;
use std::time::Instant;

use clap::error::ErrorKind;
use clap::{CommandFactory, Parser};
use polis::geom::field::{Field, decode_png_rgba8};
use polis::geom::glam::{DVec3, Vec2, Vec3};
use polis::geom::scene::{ImageData, Scene};
use polis::{CityConfig, Pipeline};
use rayon::prelude::*;

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

type BoxResult<T> = Result<T, Box<dyn std::error::Error>>;

/// Render a generated city's 3-D scene to a PNG with a software rasteriser.
#[derive(Debug, Parser)]
#[command(name = "render", version)]
struct Cli {
    /// The built-in preset to generate.
    #[arg(long, value_name = "NAME", default_value = "default", value_parser = cli::preset_names())]
    preset: String,
    /// The city seed.
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    /// Side of the square map in metres (10 to 1,000,000).
    #[arg(long, value_name = "METRES", value_parser = positive)]
    size: Option<f64>,
    /// Level of detail of the buildings, 0 to the preset's `buildings.max_lod`.
    #[arg(long, value_name = "N")]
    lod: Option<usize>,
    /// Layout point looked at (metres: x east, y north). Default: the tallest buildings.
    #[arg(long, value_name = "X,Y", allow_hyphen_values = true, value_parser = numbers::<2>)]
    target: Option<[f64; 2]>,
    /// Camera: azimuth (degrees clockwise from north), elevation (degrees, within ±89),
    /// distance (metres, positive). Default: from the city centre's side, 24°, 900 m.
    #[arg(long, value_name = "AZIMUTH,ELEVATION,DISTANCE", allow_hyphen_values = true,
          value_parser = view)]
    view: Option<[f64; 3]>,
    /// Vertical field of view in degrees (1 to 170).
    #[arg(long, value_name = "DEGREES", default_value_t = 40.0, value_parser = fov)]
    fov: f64,
    /// Image width in pixels.
    #[arg(long, value_name = "PX", default_value_t = 1280,
          value_parser = clap::value_parser!(u16).range(1..=16384))]
    width: u16,
    /// Image height in pixels.
    #[arg(long, value_name = "PX", default_value_t = 720,
          value_parser = clap::value_parser!(u16).range(1..=16384))]
    height: u16,
    /// Samples per pixel along each axis (1 to 8).
    #[arg(long, value_name = "N", default_value_t = 3,
          value_parser = clap::value_parser!(u8).range(1..=8))]
    samples: u8,
    /// The PNG to write (its folder is created if missing).
    #[arg(long, value_name = "FILE.png", default_value = "out/city-3d.png")]
    out: PathBuf,
}

/// What to render and how.
struct Args {
    config: CityConfig,
    /// Layout point looked at; `None`: the city's tallest buildings.
    target: Option<[f64; 2]>,
    /// Azimuth (degrees clockwise from north; `None`: from the city centre's side),
    /// elevation (degrees), distance (metres).
    view: [Option<f64>; 3],
    fov_deg: f64,
    width: usize,
    height: usize,
    samples: usize,
    out: PathBuf,
}

/// `N` comma-separated finite numbers.
fn numbers<const N: usize>(text: &str) -> Result<[f64; N], String> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| e.to_string())?;
    let out: [f64; N] = parts
        .try_into()
        .map_err(|_| format!("expected {N} comma-separated numbers"))?;
    if out.iter().any(|v| !v.is_finite()) {
        return Err("numbers must be finite".into());
    }
    Ok(out)
}

fn positive(text: &str) -> Result<f64, String> {
    match numbers::<1>(text)? {
        [v] if v > 0.0 => Ok(v),
        _ => Err("expected a positive number".into()),
    }
}

fn fov(text: &str) -> Result<f64, String> {
    match numbers::<1>(text)? {
        [v] if (1.0..=170.0).contains(&v) => Ok(v),
        _ => Err("expected degrees in 1..=170".into()),
    }
}

fn view(text: &str) -> Result<[f64; 3], String> {
    let v = numbers::<3>(text)?;
    if v[2] <= 0.0 || !(-89.0..=89.0).contains(&v[1]) {
        return Err("the elevation must be within ±89° and the distance positive".into());
    }
    Ok(v)
}

fn configure(cli: Cli) -> Result<Args, clap::Error> {
    let mut cmd = Cli::command();
    let mut config = CityConfig::preset(&cli.preset)
        .map_err(|e| cmd.error(ErrorKind::InvalidValue, format!("--preset: {e}")))?;
    if let Some(seed) = cli.seed {
        config.seed = seed;
    }
    if let Some(size) = cli.size {
        config.size_m = size;
    }
    if let Some(lod) = cli.lod {
        let max = config.buildings.max_lod;
        if lod > max {
            return Err(cmd.error(
                ErrorKind::ValueValidation,
                format!(
                    "--lod {lod} is above the preset's most detailed level ({max}); give 0..={max}"
                ),
            ));
        }
        config.lod = Some(lod);
    }
    config
        .validate()
        .map_err(|e| cmd.error(ErrorKind::ValueValidation, e.to_string()))?;
    let (width, height, samples) = (
        usize::from(cli.width),
        usize::from(cli.height),
        usize::from(cli.samples),
    );
    if (width * samples) as u64 * (height * samples) as u64 > 1 << 27 {
        return Err(cmd.error(
            ErrorKind::ValueValidation,
            format!(
                "{width} × {height} px with {samples}² samples each is more than 2^27 \
                 samples; lower one of them"
            ),
        ));
    }
    Ok(Args {
        config,
        target: cli.target,
        view: cli
            .view
            .map_or([None, Some(24.0), Some(900.0)], |v| v.map(Some)),
        fov_deg: cli.fov,
        width,
        height,
        samples,
        out: cli.out,
    })
}

fn main() {
    let args = match configure(Cli::parse()) {
        Ok(args) => args,
        Err(e) => e.exit(),
    };
    if let Err(e) = run(args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: Args) -> BoxResult<()> {
    let t = Instant::now();
    let city = Pipeline::default().generate(&args.config)?;
    println!(
        "generated the {} city (seed {}): {} buildings, {} triangles in {:.2} s",
        args.config.name,
        args.config.seed,
        city.buildings.len(),
        city.scene.triangle_count(),
        t.elapsed().as_secs_f64()
    );
    let t = Instant::now();
    let world = World::new(&city.scene)?;
    let target = args.target.unwrap_or_else(|| downtown(&city.buildings));
    // Look at the ground there, not at sea level: on hilly maps the eye would be inside
    // a hill.
    let ground = city
        .maps
        .inputs
        .elevation
        .sample(polis::geom::glam::DVec2::from(target));
    let camera = Camera::new(&args, target, if ground.is_finite() { ground } else { 0.0 });
    let sun = Sun::new(&world, &camera);
    let image = render(&world, &camera, &sun, args.samples);
    let png = encode(&image, args.width, args.height)?;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&args.out, png)?;
    println!(
        "rendered {} × {} px ({}² samples each) to {} in {:.2} s",
        args.width,
        args.height,
        args.samples,
        args.out.display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Downtown: among the tallest hundredth of the buildings, the one with the most height
/// of the others within 400 m (layout metres); the origin for a city without buildings.
fn downtown(buildings: &[std::sync::Arc<polis::buildings::Building>]) -> [f64; 2] {
    let mut by_height: Vec<_> = buildings
        .iter()
        .filter(|b| b.height.is_finite() && b.origin.is_finite())
        .collect();
    by_height.sort_by(|a, b| b.height.total_cmp(&a.height));
    by_height.truncate((by_height.len() / 100).max(1));
    let weight = |a: &polis::buildings::Building| -> f64 {
        by_height
            .iter()
            .filter(|b| b.origin.distance(a.origin) < 400.0)
            .map(|b| b.height)
            .sum()
    };
    by_height
        .iter()
        .max_by(|a, b| weight(a).total_cmp(&weight(b)))
        .map_or([0.0, 0.0], |b| [b.origin.x, b.origin.y])
}

// ---------------------------------------------------------------------------------------
// The scene as flat triangles.

/// A triangle in world space with its material.
struct Tri {
    p: [Vec3; 3],
    uv: [Vec2; 3],
    material: u32,
}

/// A material as the renderer uses it: a linear colour and an optional texture.
struct Surface {
    color: Vec3,
    texture: Option<usize>,
}

/// Mip levels of a texture, linear RGB, largest first.
struct Mips {
    levels: Vec<Level>,
}

struct Level {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

struct World {
    tris: Vec<Tri>,
    surfaces: Vec<Surface>,
    textures: Vec<Mips>,
    /// Scene bounds (world); the ground plane is at `min.y`.
    min: Vec3,
    max: Vec3,
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

impl Mips {
    fn new(width: usize, height: usize, rgba: &[u8]) -> Option<Mips> {
        if width == 0 || height == 0 || rgba.len() < width * height * 4 {
            return None;
        }
        let texels = rgba
            .chunks_exact(4)
            .take(width * height)
            .map(|p| {
                Vec3::new(
                    srgb_to_linear(f32::from(p[0]) / 255.0),
                    srgb_to_linear(f32::from(p[1]) / 255.0),
                    srgb_to_linear(f32::from(p[2]) / 255.0),
                )
            })
            .collect();
        let mut levels = vec![Level {
            width,
            height,
            texels,
        }];
        while let Some(last) = levels.last().filter(|l| l.width > 1 || l.height > 1) {
            let (w, h) = (last.width.div_ceil(2), last.height.div_ceil(2));
            let at = |x: usize, y: usize| {
                last.texels[y.min(last.height - 1) * last.width + x.min(last.width - 1)]
            };
            let texels = (0..w * h)
                .map(|i| {
                    let (x, y) = (2 * (i % w), 2 * (i / w));
                    (at(x, y) + at(x + 1, y) + at(x, y + 1) + at(x + 1, y + 1)) * 0.25
                })
                .collect();
            levels.push(Level {
                width: w,
                height: h,
                texels,
            });
        }
        Some(Mips { levels })
    }

    /// Bilinear sample of a repeating texture at `lod` (level, fractional parts blended).
    fn sample(&self, uv: Vec2, lod: f32) -> Vec3 {
        let top = (self.levels.len() - 1) as f32;
        let lod = lod.clamp(0.0, top);
        let l0 = lod.floor() as usize;
        let f = lod - l0 as f32;
        let a = self.bilinear(l0, uv);
        if f > 0.0 && l0 + 1 < self.levels.len() {
            a.lerp(self.bilinear(l0 + 1, uv), f)
        } else {
            a
        }
    }

    fn bilinear(&self, level: usize, uv: Vec2) -> Vec3 {
        let l = &self.levels[level];
        let x = uv.x.rem_euclid(1.0) * l.width as f32 - 0.5;
        let y = uv.y.rem_euclid(1.0) * l.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |v: f32, n: usize| (v as i64).rem_euclid(n as i64) as usize;
        let (xa, xb) = (wrap(x0, l.width), wrap(x0 + 1.0, l.width));
        let (ya, yb) = (wrap(y0, l.height), wrap(y0 + 1.0, l.height));
        let t = |x: usize, y: usize| l.texels[y * l.width + x];
        let top = t(xa, ya).lerp(t(xb, ya), fx);
        let bottom = t(xa, yb).lerp(t(xb, yb), fx);
        top.lerp(bottom, fy)
    }
}

impl World {
    fn new(scene: &Scene) -> BoxResult<World> {
        let mut textures = Vec::new();
        let mut texture_of_image = vec![None; scene.images.len()];
        for (i, image) in scene.images.iter().enumerate() {
            let mips = match &image.data {
                ImageData::Rgba8 {
                    width,
                    height,
                    pixels,
                } => Mips::new(*width as usize, *height as usize, pixels),
                ImageData::Png(bytes) => decode_png_rgba8(bytes)
                    .ok()
                    .and_then(|(w, h, rgba)| Mips::new(w as usize, h as usize, &rgba)),
            };
            if let Some(m) = mips {
                texture_of_image[i] = Some(textures.len());
                textures.push(m);
            }
        }
        let surfaces = scene
            .materials
            .iter()
            .map(|m| Surface {
                color: Vec3::new(m.base_color[0], m.base_color[1], m.base_color[2]),
                texture: m
                    .base_color_texture
                    .and_then(|t| scene.textures.get(t.index()))
                    .and_then(|t| texture_of_image.get(t.image.index()).copied().flatten()),
            })
            .chain([Surface {
                color: Vec3::splat(0.6),
                texture: None,
            }])
            .collect::<Vec<_>>();
        let default_material = (surfaces.len() - 1) as u32;

        let matrices = scene.world_matrices();
        let mut tris = Vec::with_capacity(scene.triangle_count());
        for (node, m) in scene.nodes.iter().zip(&matrices) {
            for mesh in node
                .meshes
                .iter()
                .filter_map(|&id| scene.meshes.get(id.index()))
            {
                let material = mesh.material.map_or(default_material, |id| id.0);
                let material = material.min(default_material);
                for t in mesh.triangles() {
                    let k = t.map(|k| k as usize);
                    let ([Some(p0), Some(p1), Some(p2)], [Some(t0), Some(t1), Some(t2)]) = (
                        k.map(|k| mesh.positions.get(k).copied()),
                        k.map(|k| mesh.uvs.get(k).copied()),
                    ) else {
                        continue;
                    };
                    let p = [p0, p1, p2].map(|v| m.transform_point3(v.as_dvec3()).as_vec3());
                    let uv = [t0, t1, t2];
                    if p.iter().any(|v| !v.is_finite()) {
                        continue;
                    }
                    tris.push(Tri { p, uv, material });
                }
            }
        }
        if tris.is_empty() {
            return Err("the scene has no triangles to render".into());
        }
        let (min, max) = tris.iter().flat_map(|t| t.p).fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
        Ok(World {
            tris,
            surfaces,
            textures,
            min,
            max,
        })
    }
}

// ---------------------------------------------------------------------------------------
// Camera, sun and the shared rasteriser.

struct Camera {
    eye: Vec3,
    /// The view frame: `right`, `up`, `forward` unit vectors, and the half extents of the
    /// image plane at distance 1.
    frame: [DVec3; 3],
    half: [f64; 2],
    /// Ray directions: `dir(x, y) = corner + x · right + y · down` for pixel-space `x, y`
    /// (samples), not normalised.
    corner: Vec3,
    right: Vec3,
    down: Vec3,
    /// Sample resolution.
    width: usize,
    height: usize,
}

/// The near plane, metres in front of the eye.
const NEAR: f64 = 0.5;

impl Camera {
    /// The camera looking at layout point `target` at height `ground` (metres).
    fn new(args: &Args, target: [f64; 2], ground: f64) -> Camera {
        // By default the eye is on the side of the city centre, so the city fills the
        // foreground.
        let from_centre = f64::atan2(-target[0], -target[1]).to_degrees();
        let azimuth = args.view[0].unwrap_or(from_centre);
        let elevation = args.view[1].unwrap_or(24.0);
        let distance = args.view[2].unwrap_or(900.0);
        let (az, el) = (azimuth.to_radians(), elevation.to_radians());
        // Layout: x east, y north; world: x east, y up, z south.
        let target = DVec3::new(target[0], ground, -target[1]);
        let towards_eye = DVec3::new(az.sin() * el.cos(), el.sin(), -az.cos() * el.cos());
        let eye = target + towards_eye * distance;
        let (width, height) = (args.width * args.samples, args.height * args.samples);
        let aspect = width as f64 / height as f64;
        let fov = args.fov_deg.to_radians();
        let forward = (target - eye).normalize();
        let right = forward.cross(DVec3::Y).normalize();
        let up = right.cross(forward);
        let half_h = (fov * 0.5).tan();
        let half_w = half_h * aspect;
        let px = 2.0 * half_w / width as f64;
        let corner = forward - right * half_w + up * half_h;
        Camera {
            eye: eye.as_vec3(),
            frame: [right, up, forward],
            half: [half_w, half_h],
            corner: corner.as_vec3(),
            right: (right * px).as_vec3(),
            down: (-up * px).as_vec3(),
            width,
            height,
        }
    }

    /// A world point in the view frame: across, up, and depth in front of the eye.
    fn view(&self, p: Vec3) -> DVec3 {
        let r = p.as_dvec3() - self.eye.as_dvec3();
        let [right, up, forward] = self.frame;
        DVec3::new(r.dot(right), r.dot(up), r.dot(forward))
    }

    /// Sample coordinates and inverse depth of a view-frame point in front of the eye.
    fn screen(&self, v: DVec3) -> Vec3 {
        let iz = 1.0 / v.z;
        Vec3::new(
            ((v.x * iz / self.half[0] + 1.0) * 0.5 * self.width as f64) as f32,
            ((1.0 - v.y * iz / self.half[1]) * 0.5 * self.height as f64) as f32,
            iz as f32,
        )
    }

    fn ray(&self, x: f32, y: f32) -> Vec3 {
        self.corner + self.right * x + self.down * y
    }
}

/// Calls `plot(x, y, depth)` for the pixel centres inside the screen triangle `v`
/// (`x`, `y` in pixels, `z` a depth interpolated linearly), within `width × height`.
fn raster(v: [Vec3; 3], width: usize, height: usize, mut plot: impl FnMut(usize, usize, f32)) {
    let area = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    let x0 = (lo.x - 0.5).ceil().max(0.0) as usize;
    let y0 = (lo.y - 0.5).ceil().max(0.0) as usize;
    let x1 = ((hi.x - 0.5).floor().min(width as f32 - 1.0)).max(-1.0);
    let y1 = ((hi.y - 0.5).floor().min(height as f32 - 1.0)).max(-1.0);
    if x1 < 0.0 || y1 < 0.0 {
        return;
    }
    let (x1, y1) = (x1 as usize, y1 as usize);
    let inv = 1.0 / area;
    let edge =
        |a: Vec3, b: Vec3, px: f32, py: f32| (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
    for y in y0..=y1 {
        let py = y as f32 + 0.5;
        for x in x0..=x1 {
            let px = x as f32 + 0.5;
            let w0 = edge(v[1], v[2], px, py) * inv;
            let w1 = edge(v[2], v[0], px, py) * inv;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            plot(x, y, w0 * v[0].z + w1 * v[1].z + w2 * v[2].z);
        }
    }
}

/// Directional sunlight with an orthographic shadow map fitted around the view.
struct Sun {
    /// Unit vector towards the sun.
    dir: Vec3,
    /// Light-space axes (`right`, `up` across the map, `dir` its depth).
    right: Vec3,
    up: Vec3,
    /// Light-space coordinates of texel (0, 0) and texels per metre.
    origin: Vec2,
    scale: f32,
    size: usize,
    depth: Vec<f32>,
}

impl Sun {
    fn new(world: &World, camera: &Camera) -> Sun {
        let dir = Vec3::new(0.55, 0.6, 0.5).normalize();
        let right = Vec3::Y.cross(dir).normalize();
        let up = dir.cross(right);
        // The map covers the scene near the camera's view: the ground within reach of the
        // eye (a few distances around it), clipped to the scene.
        let reach = (camera.eye.y.abs() * 4.0 + 1500.0).max(500.0);
        let lo = world.min.max(camera.eye - Vec3::splat(reach));
        let hi = world.max.min(camera.eye + Vec3::splat(reach));
        let corners = (0..8).map(|i| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { world.min.y } else { world.max.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        });
        let (mut a, mut b) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for c in corners {
            let q = Vec2::new(c.dot(right), c.dot(up));
            a = a.min(q);
            b = b.max(q);
        }
        let size = 4096;
        let scale = (size as f32 - 2.0) / (b - a).max_element().max(1.0);
        let mut sun = Sun {
            dir,
            right,
            up,
            origin: a,
            scale,
            size,
            depth: vec![f32::NEG_INFINITY; size * size],
        };
        for t in &world.tris {
            let v = t.p.map(|p| sun.light_space(p));
            let (size, depth) = (sun.size, &mut sun.depth);
            raster(v, size, size, |x, y, d| {
                let slot = &mut depth[y * size + x];
                if d > *slot {
                    *slot = d;
                }
            });
        }
        sun
    }

    /// Texel coordinates and height towards the sun.
    fn light_space(&self, p: Vec3) -> Vec3 {
        let q = (Vec2::new(p.dot(self.right), p.dot(self.up)) - self.origin) * self.scale;
        Vec3::new(q.x, q.y, p.dot(self.dir))
    }

    /// The fraction of sunlight reaching `p` (surface normal `n`), 3 × 3 texels filtered.
    fn light(&self, p: Vec3, n: Vec3) -> f32 {
        let cos = n.dot(self.dir).max(0.0);
        if cos <= 0.0 {
            return 0.0;
        }
        let q = self.light_space(p);
        let bias = 0.2 + 2.5 * (1.0 - cos * cos).sqrt() / cos.max(0.2) / self.scale;
        let (cx, cy) = (q.x.floor() as i64, q.y.floor() as i64);
        let mut lit = 0.0;
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (x, y) = (cx + dx, cy + dy);
                let inside =
                    x >= 0 && y >= 0 && (x as usize) < self.size && (y as usize) < self.size;
                if !inside || self.depth[y as usize * self.size + x as usize] <= q.z + bias {
                    lit += 1.0;
                }
            }
        }
        cos * lit / 9.0
    }
}

// ---------------------------------------------------------------------------------------
// Rendering.

const NONE: u32 = u32::MAX;

/// Clips a triangle in the view frame to depth `≥ NEAR`: up to four vertices.
fn clip_near(v: [DVec3; 3]) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(4);
    for i in 0..3 {
        let (a, b) = (v[i], v[(i + 1) % 3]);
        let (ia, ib) = (a.z >= NEAR, b.z >= NEAR);
        if ia {
            out.push(a);
        }
        if ia != ib {
            let t = (NEAR - a.z) / (b.z - a.z);
            out.push(a + (b - a) * t);
        }
    }
    out
}

/// Linear RGB, one per sample, row by row.
fn render(world: &World, camera: &Camera, sun: &Sun, samples: usize) -> Vec<Vec3> {
    let (w, h) = (camera.width, camera.height);
    // Visibility: the nearest triangle of every sample (depth as 1/w, larger is nearer).
    let mut depth = vec![0.0f32; w * h];
    let mut ids = vec![NONE; w * h];
    for (i, t) in world.tris.iter().enumerate() {
        let view = t.p.map(|p| camera.view(p));
        if view.iter().all(|v| v.z < NEAR) {
            continue;
        }
        let screen: Vec<Vec3> = clip_near(view)
            .into_iter()
            .map(|v| camera.screen(v))
            .collect();
        // Back faces (clockwise on screen, y down) are hidden by the closed meshes.
        let Some(&s0) = screen.first() else { continue };
        for k in 1..screen.len().saturating_sub(1) {
            let v = [s0, screen[k], screen[k + 1]];
            let area =
                (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
            if area >= 0.0 {
                continue;
            }
            raster(v, w, h, |x, y, d| {
                let j = y * w + x;
                if d > depth[j] {
                    depth[j] = d;
                    ids[j] = i as u32;
                }
            });
        }
    }

    // Shading, one row at a time in parallel.
    let mut color = vec![Vec3::ZERO; w * h];
    let texel_scale = 1.0 / samples as f32;
    color.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let (fx, fy) = (x as f32 + 0.5, y as f32 + 0.5);
            let dir = camera.ray(fx, fy);
            *out = match world.tris.get(ids[y * w + x] as usize) {
                Some(t) => shade(world, camera, sun, t, dir, [fx, fy], texel_scale),
                None => background(world, camera, sun, dir),
            };
        }
    });
    color
}

/// Where the ray `eye + s · dir` meets the triangle's plane: `(s, barycentrics)`.
fn hit(t: &Tri, eye: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
    let e1 = t.p[1] - t.p[0];
    let e2 = t.p[2] - t.p[0];
    let pv = dir.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = eye - t.p[0];
    let u = tv.dot(pv) * inv;
    let qv = tv.cross(e1);
    let v = dir.dot(qv) * inv;
    let s = e2.dot(qv) * inv;
    Some((s, Vec3::new(1.0 - u - v, u, v)))
}

fn uv_at(t: &Tri, b: Vec3) -> Vec2 {
    t.uv[0] * b.x + t.uv[1] * b.y + t.uv[2] * b.z
}

const SKY_ZENITH: Vec3 = Vec3::new(0.20, 0.36, 0.70);
const SKY_HORIZON: Vec3 = Vec3::new(0.62, 0.72, 0.85);
const SUN_COLOR: Vec3 = Vec3::new(1.0, 0.93, 0.82);
const GROUND_COLOR: Vec3 = Vec3::new(0.23, 0.27, 0.18);
/// Metres of air that halve the contrast.
const HAZE: f32 = 4000.0;

fn sky(dir: Vec3) -> Vec3 {
    let up = (dir.normalize().y).max(0.0);
    SKY_HORIZON.lerp(SKY_ZENITH, up.powf(0.6))
}

/// Lit colour of a surface point: albedo under sun, sky and ground light, then haze.
fn lit(sun: &Sun, albedo: Vec3, p: Vec3, n: Vec3, distance: f32, dir: Vec3) -> Vec3 {
    let sunlight = sun.light(p, n) * 1.25;
    let skylight = SKY_HORIZON.lerp(SKY_ZENITH, 0.5 + 0.5 * n.y) * (0.3 + 0.15 * n.y);
    let bounce = GROUND_COLOR * (0.25 * (1.0 - n.y).max(0.0));
    let c = albedo * (SUN_COLOR * sunlight + skylight + bounce);
    let fade = 1.0 - (-distance / HAZE).exp();
    c.lerp(sky(dir) * 1.05, fade)
}

fn shade(
    world: &World,
    camera: &Camera,
    sun: &Sun,
    t: &Tri,
    dir: Vec3,
    pixel: [f32; 2],
    texel_scale: f32,
) -> Vec3 {
    let Some((s, b)) = hit(t, camera.eye, dir) else {
        return sky(dir);
    };
    let p = camera.eye + dir * s;
    let mut n = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]).normalize_or_zero();
    if n.dot(dir) > 0.0 {
        n = -n;
    }
    let Some(surface) = world.surfaces.get(t.material as usize) else {
        return sky(dir);
    };
    let mut albedo = surface.color;
    if let Some(mips) = surface.texture.and_then(|i| world.textures.get(i)) {
        let uv = uv_at(t, b);
        // The texture footprint of one output pixel picks the mip level.
        let [px, py] = pixel;
        let step = |d: Vec3| hit(t, camera.eye, d).map_or(Vec2::ZERO, |(_, b2)| uv_at(t, b2) - uv);
        let du = step(camera.ray(px + 1.0, py));
        let dv = step(camera.ray(px, py + 1.0));
        let level0 = &mips.levels[0];
        let texels = Vec2::new(level0.width as f32, level0.height as f32);
        let footprint = (du * texels).length().max((dv * texels).length()) / texel_scale;
        albedo *= mips.sample(uv, footprint.max(1e-6).log2());
    }
    lit(sun, albedo, p, n, s * dir.length(), dir)
}

fn background(world: &World, camera: &Camera, sun: &Sun, dir: Vec3) -> Vec3 {
    if dir.y < 0.0 {
        let s = (world.min.y - camera.eye.y) / dir.y;
        let p = camera.eye + dir * s;
        return lit(sun, GROUND_COLOR, p, Vec3::Y, s * dir.length(), dir);
    }
    sky(dir)
}

/// Colours of the written PNG's palette.
const PALETTE_SIZE: usize = 256;

/// Averages `samples × samples` blocks and encodes sRGB PNG bytes, indexed on a
/// [`PALETTE_SIZE`]-colour palette (see [`palette`]).
fn encode(image: &[Vec3], width: usize, height: usize) -> BoxResult<Vec<u8>> {
    let samples = (image.len() / (width * height)).isqrt();
    let stride = width * samples;
    let mut rgb = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            let mut sum = Vec3::ZERO;
            for sy in 0..samples {
                for sx in 0..samples {
                    sum += image[(y * samples + sy) * stride + x * samples + sx];
                }
            }
            let c = sum / (samples * samples) as f32;
            rgb.extend([c.x, c.y, c.z].map(|v| (linear_to_srgb(v) * 255.0).round() as u8));
        }
    }
    let (palette, indices) = palette::quantize(&rgb, PALETTE_SIZE);
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width as u32, height as u32);
    encoder.set_color(png::ColorType::Indexed);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_palette(palette.concat());
    encoder.set_compression(png::Compression::High);
    encoder.write_header()?.write_image_data(&indices)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(args: &[&str]) -> Result<Args, clap::Error> {
        let cli = Cli::try_parse_from(std::iter::once("render").chain(args.iter().copied()))?;
        configure(cli)
    }

    /// `--help` is help (exit 0), `--x=y` parses, typos get suggestions, and every
    /// out-of-range value is an error rather than clamped.
    #[test]
    fn command_line_validates_instead_of_clamping() {
        let help = parse(&["--help"]).err().unwrap();
        assert_eq!(help.kind(), ErrorKind::DisplayHelp);
        assert_eq!(help.exit_code(), 0);
        let a = parse(&["--seed=9", "--view=-30,20,500", "--samples", "2"]).unwrap();
        assert_eq!(a.config.seed, 9);
        assert_eq!(a.view, [Some(-30.0), Some(20.0), Some(500.0)]);
        assert_eq!(a.samples, 2);
        let typo = parse(&["--sampels", "2"]).err().unwrap();
        assert!(typo.to_string().contains("'--samples'"), "{typo}");
        for bad in [
            &["--samples", "9"][..],
            &["--lod", "7"],
            &["--fov", "180"],
            &["--view=0,95,900"],
            &["--width", "0"],
            &["--width", "16384", "--height", "16384"],
            &["--preset", "pari"],
        ] {
            let e = parse(bad).err().unwrap();
            assert_ne!(e.exit_code(), 0, "{bad:?}");
        }
    }

    /// Two triangles sharing a diagonal cover every pixel centre of their square, and
    /// none outside it.
    #[test]
    fn raster_covers_a_square_without_gaps() {
        let (a, b, c, d) = (
            Vec3::new(2.0, 3.0, 1.0),
            Vec3::new(12.0, 3.0, 1.0),
            Vec3::new(12.0, 9.0, 1.0),
            Vec3::new(2.0, 9.0, 1.0),
        );
        let mut hits = vec![0u32; 16 * 16];
        for tri in [[a, b, c], [a, c, d]] {
            raster(tri, 16, 16, |x, y, z| {
                assert!((z - 1.0).abs() < 1e-5);
                hits[y * 16 + x] += 1;
            });
        }
        for y in 0..16 {
            for x in 0..16 {
                let inside = (2..12).contains(&x) && (3..9).contains(&y);
                assert_eq!(hits[y * 16 + x] > 0, inside, "pixel ({x}, {y})");
            }
        }
    }

    /// Clipping keeps the part in front of the near plane: a triangle crossing it becomes
    /// a quadrilateral with two vertices on the plane.
    #[test]
    fn near_clipping_keeps_the_front() {
        let v = [
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
        ];
        let poly = clip_near(v);
        assert_eq!(poly.len(), 4);
        assert!(poly.iter().all(|p| p.z >= NEAR - 1e-12));
        assert_eq!(
            poly.iter().filter(|p| (p.z - NEAR).abs() < 1e-12).count(),
            2
        );
        assert!(clip_near(v.map(|p| p - DVec3::Z * 5.0)).is_empty());
    }

    /// Each mip level averages the one above it, down to one texel.
    #[test]
    fn mips_keep_the_mean_colour() {
        let rgba: Vec<u8> = (0..8 * 4)
            .flat_map(|i| [(i * 8) as u8, 255 - (i * 8) as u8, 128, 255])
            .collect();
        let mips = Mips::new(8, 4, &rgba).unwrap();
        assert_eq!(mips.levels.len(), 4);
        let mean = |l: &Level| l.texels.iter().sum::<Vec3>() / l.texels.len() as f32;
        let first = mean(&mips.levels[0]);
        for l in &mips.levels {
            assert!((mean(l) - first).abs().max_element() < 1e-5);
        }
        assert!(Mips::new(8, 4, &rgba[..10]).is_none());
    }

    /// The ray through a pixel meets its triangle at the barycentrics of the hit point.
    #[test]
    fn hit_finds_the_point_on_the_triangle() {
        let t = Tri {
            p: [
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(4.0, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -4.0),
            ],
            uv: [Vec2::ZERO, Vec2::X, Vec2::Y],
            material: 0,
        };
        let eye = Vec3::new(1.0, 10.0, -1.0);
        let (s, b) = hit(&t, eye, Vec3::new(0.0, -2.0, 0.0)).unwrap();
        assert!((s - 5.0).abs() < 1e-6);
        assert!((b - Vec3::new(0.5, 0.25, 0.25)).abs().max_element() < 1e-6);
        assert!((uv_at(&t, b) - Vec2::new(0.25, 0.25)).abs().max_element() < 1e-6);
        assert!(hit(&t, eye, Vec3::X).is_none());
    }
}
