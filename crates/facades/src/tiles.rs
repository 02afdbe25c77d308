//! Shared tile sets: bounded texture memory at city scale.
//!
//! Parish & Müller texture with "a semi-procedural approach [...] to keep memory usage
//! small"; Kelly (§4.4.3.3, §5.6) applies *building tiles* with "a best fit algorithm
//! \[that\] aims to match the tiles dimensions without splitting or dividing a tile". Here a
//! style is rasterised once, on a prototype facade of `bays × floors` modules, and cut
//! along its interval groups into at most nine tiles — the 3 × 3 combinations of the
//! column parts (start margin, repeated bays, end margin) and the row parts (ground floor
//! and plinth, repeated storeys, cornice and attic) — plus an entrance tile (one bay of
//! the street-front ground floor). Every facade of the style is then covered by a handful
//! of quads whose UVs repeat those tiles a whole number of modules: a repeated region of
//! `n` bays shows the `bays`-wide tile `n / bays` times, which always ends on a module
//! boundary, so no window is ever cut. Modules stretched by the fit stretch their tile
//! accordingly.
//!
//! The street entrance gets the middle bay of a street-front prototype over the ground
//! rows and, when the entrance influences storeys above it (the window shrunk above the
//! brick house's door), a second entrance tile over those storeys.
//!
//! What a tile set cannot reproduce — modules stretched by the fit, layers on their own
//! axes or on particular storeys, patterns out of step with the modules, random detail —
//! is worked out per facade by [`PreparedStyle::tile_plan`](crate::PreparedStyle::tile_plan)
//! ([`crate::tile_plan`]), so callers know where to fall back to a facade's own texture.

use polis_geom::{Aabb2, DVec2};

use crate::error::{FacadeError, Result};
use crate::facade::{Facade, FacadeLayout, FacadeReport, FacadeSpec, FaceRole, PreparedStyle};
use crate::interval::{IntervalGroup, Part};
use crate::raster::{FacadeTextures, RasterOptions};
use crate::tile_plan::PROTOTYPE_SEED;

/// How a style's tile set is cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct TileOptions {
    /// Bays (column modules) per repeated tile. Default: 3.
    pub bays: u32,
    /// Storeys (row modules) per repeated tile. Default: 2.
    pub floors: u32,
}

impl Default for TileOptions {
    fn default() -> Self {
        TileOptions { bays: 3, floors: 2 }
    }
}

impl TileOptions {
    /// Checks the counts (1..=64).
    ///
    /// # Errors
    /// [`FacadeError::InvalidStyle`].
    pub fn validate(&self) -> Result<()> {
        if (1..=64).contains(&self.bays) && (1..=64).contains(&self.floors) {
            Ok(())
        } else {
            Err(FacadeError::InvalidStyle {
                style: "tiles".into(),
                reason: "tile bays and floors must be in 1..=64".into(),
            })
        }
    }
}

/// One tile of a [`TileSet`].
#[derive(Debug, Clone, PartialEq)]
pub struct Tile {
    /// Column part it covers.
    pub cols: Part,
    /// Row part it covers.
    pub rows: Part,
    /// Whether it is the entrance tile (one bay of the street-front ground floor).
    pub entrance: bool,
    /// Modules across (bays for repeated columns, else 1).
    pub modules_u: u32,
    /// Modules up (storeys for repeated rows, else 1).
    pub modules_v: u32,
    /// The textures.
    pub textures: FacadeTextures,
}

/// The shared tiles of one style.
#[derive(Debug, Clone, PartialEq)]
pub struct TileSet {
    /// Style name.
    pub style: String,
    /// The tiles.
    pub tiles: Vec<Tile>,
}

/// A quad of a facade textured with one tile.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TileQuad {
    /// The rectangle on the facade, metres.
    pub rect: Aabb2,
    /// Index of the tile in the [`TileSet`].
    pub tile: usize,
    /// Tile repetitions across and up (whole modules: `n / bays`), to be used with a
    /// repeating sampler.
    pub repeats: [f64; 2],
}

impl TileQuad {
    /// glTF texture coordinates at facade point `(s, t)` (u right, v down, image row 0 at
    /// v = 0; the tile's top edge at v = 0, the quad's bottom at v = `repeats[1]`).
    pub fn uv_at(&self, s: f64, t: f64) -> [f64; 2] {
        let u = (s - self.rect.min.x) / self.rect.width() * self.repeats[0];
        let v_up = (t - self.rect.min.y) / self.rect.height() * self.repeats[1];
        [u, self.repeats[1].ceil() - v_up]
    }
}

fn parts(g: &IntervalGroup) -> Vec<(Part, f64, f64)> {
    [Part::Start, Part::Repeat, Part::End]
        .into_iter()
        .filter_map(|p| g.part_range(p).map(|(a, b)| (p, a, b)))
        .collect()
}

impl TileSet {
    /// Rasterises the tiles of a style at the given resolution.
    ///
    /// # Errors
    /// Style errors, and rasterisation errors for bad options.
    pub fn build(style: &PreparedStyle, opts: &RasterOptions) -> Result<TileSet> {
        let st = style.style();
        let analysis = style.tiling();
        let spec = match analysis.proto {
            Some(spec) => spec,
            None => {
                let to = st.tiles;
                FacadeSpec {
                    width_m: st.columns.nominal_length(to.bays),
                    height_m: st.rows.nominal_length(to.floors),
                    floors: None,
                    role: FaceRole::Side,
                    seed: PROTOTYPE_SEED,
                }
            }
        };
        let proto = style.facade(&spec)?;
        let mut tiles = Vec::new();
        for &(rp, y0, y1) in &parts(proto.rows()) {
            for &(cp, x0, x1) in &parts(proto.columns()) {
                let region = Aabb2::new(DVec2::new(x0, y0), DVec2::new(x1, y1));
                tiles.push(Tile {
                    cols: cp,
                    rows: rp,
                    entrance: false,
                    modules_u: if cp == Part::Repeat {
                        proto.columns().repeat_count()
                    } else {
                        1
                    },
                    modules_v: if rp == Part::Repeat {
                        proto.rows().repeat_count()
                    } else {
                        1
                    },
                    textures: proto.rasterize_region(&region, opts)?,
                });
            }
        }
        // The entrance: the middle bay of a street-front prototype, over the ground rows
        // and over the storeys its influences reach (a window shrunk above the door).
        if let Some(e) = &analysis.entrance {
            let street = style.facade(&e.spec)?;
            let (cols, rows) = (street.columns(), street.rows());
            if let Some((x0, x1)) = cols.repeat_range(cols.repeat_count() / 2) {
                let mut cut = |y0: f64, y1: f64, rp: Part, floors: u32| -> Result<()> {
                    let region = Aabb2::new(DVec2::new(x0, y0), DVec2::new(x1, y1));
                    tiles.push(Tile {
                        cols: Part::Repeat,
                        rows: rp,
                        entrance: true,
                        modules_u: 1,
                        modules_v: floors,
                        textures: street.rasterize_region(&region, opts)?,
                    });
                    Ok(())
                };
                if let Some((y0, y1)) = rows.part_range(Part::Start) {
                    cut(y0, y1, Part::Start, 1)?;
                }
                if e.floors > 0
                    && let (Some((y0, _)), Some((_, y1))) =
                        (rows.repeat_range(0), rows.repeat_range(e.floors - 1))
                {
                    cut(y0, y1, Part::Repeat, e.floors)?;
                }
            }
        }
        Ok(TileSet {
            style: st.name.clone(),
            tiles,
        })
    }

    /// Bytes of texture memory the whole set holds.
    pub fn gpu_bytes(&self) -> usize {
        self.tiles.iter().map(|t| t.textures.gpu_bytes()).sum()
    }

    fn find(&self, cols: Part, rows: Part, entrance: bool) -> Option<usize> {
        self.tiles
            .iter()
            .position(|t| t.cols == cols && t.rows == rows && t.entrance == entrance)
    }
}

impl PreparedStyle {
    /// One quad covering the whole face with the style's repeated tile (the ground-floor
    /// tile on a [`FaceRole::GroundFloor`] face), its UVs repeating the tile once per
    /// `modules` bays and storeys, so no window is cut; margins, cornice and entrance are
    /// left out. It needs only the repetition counts, not the fitted intervals: the
    /// cheapest way to texture a city. `None` when the face is too small for one module
    /// or the set has no such tile.
    ///
    /// # Errors
    /// [`FacadeError::InvalidNumber`] for a bad spec.
    pub fn compact_tile_quad(&self, spec: &FacadeSpec, set: &TileSet) -> Result<Option<TileQuad>> {
        spec.validate()?;
        let (columns, rows) = self.sums(spec.role);
        let count = |axis: &crate::axis::AxisSums, len: f64, wanted: Option<u32>| match axis
            .repeat_count(len, wanted)
        {
            Ok(n) => Ok(Some(n)),
            Err(FacadeError::TooShort { .. }) => Ok(None),
            Err(e) => Err(e),
        };
        let Some(n_cols) = count(columns, spec.width_m, None)? else {
            return Ok(None);
        };
        let wanted = rows.wanted_rows(spec.floors);
        let Some(n_rows) = count(rows, spec.height_m, wanted)? else {
            return Ok(None);
        };
        let ground = spec.role == FaceRole::GroundFloor;
        let row_part = if ground { Part::Start } else { Part::Repeat };
        let Some((k, tile)) = set
            .find(Part::Repeat, row_part, false)
            .and_then(|k| set.tiles.get(k).map(|t| (k, t)))
        else {
            return Ok(None);
        };
        if n_cols == 0 || (!ground && n_rows == 0) {
            return Ok(None);
        }
        let rv = if ground {
            1.0
        } else {
            f64::from(n_rows) / f64::from(tile.modules_v.max(1))
        };
        Ok(Some(TileQuad {
            rect: Aabb2::new(DVec2::ZERO, DVec2::new(spec.width_m, spec.height_m)),
            tile: k,
            repeats: [f64::from(n_cols) / f64::from(tile.modules_u.max(1)), rv],
        }))
    }
}

impl Facade {
    /// Covers the facade with quads of a shared [`TileSet`] of its style: one per present
    /// (column part × row part), the ground strip of a street front split around the
    /// entrance bay. Regions whose tile is missing (a facade with margins the prototype
    /// lacked) are skipped; blank faces get no quads. A street front's entrance bay gets
    /// the entrance tiles over the ground rows and over the storeys the entrance changes.
    /// Where this is not exact, see [`PreparedStyle::tile_plan`].
    pub fn tile_quads(&self, set: &TileSet) -> Vec<TileQuad> {
        tile_quads(self.spec(), self.columns(), self.rows(), self.report(), set)
    }
}

impl FacadeLayout {
    /// The same quads as [`Facade::tile_quads`] of the facade with this layout.
    pub fn tile_quads(&self, set: &TileSet) -> Vec<TileQuad> {
        tile_quads(&self.spec, &self.columns, &self.rows, &self.report, set)
    }
}

/// A row band of a facade: (part, y0, y1, storeys in it, entrance tile and its v
/// repeats).
type Band = (Part, f64, f64, u32, Option<(usize, f64)>);

/// The quads of a facade with this spec, grid and report.
pub(crate) fn tile_quads(
    spec: &FacadeSpec,
    cols: &IntervalGroup,
    rows: &IntervalGroup,
    report: &FacadeReport,
    set: &TileSet,
) -> Vec<TileQuad> {
    let mut out = Vec::new();
    if report.blank_columns || report.blank_rows {
        return out;
    }
    let tile_mod = |k: usize| {
        set.tiles
            .get(k)
            .map_or([1, 1], |t| [t.modules_u, t.modules_v])
    };
    let n_cols = cols.repeat_count();
    let n_rows = rows.repeat_count();
    let street = spec.role == FaceRole::Street;
    let entrance = |rows: Part| {
        if street {
            set.find(Part::Repeat, rows, true)
        } else {
            None
        }
    };
    // Row bands: (part, y0, y1, storeys in the band, entrance tile and its v repeats).
    let mut bands: Vec<Band> = Vec::new();
    for &(rp, y0, y1) in &parts(rows) {
        match rp {
            Part::Repeat => {
                // The entrance's upper tile covers the first storeys of the entrance bay.
                let upper = entrance(Part::Repeat).map(|e| (e, tile_mod(e)[1].max(1)));
                match upper {
                    Some((e, k)) if n_rows > 0 => {
                        let ku = k.min(n_rows);
                        let yk = rows.repeat_range(ku - 1).map_or(y1, |r| r.1);
                        bands.push((rp, y0, yk, ku, Some((e, f64::from(ku) / f64::from(k)))));
                        if ku < n_rows {
                            bands.push((rp, yk, y1, n_rows - ku, None));
                        }
                    }
                    _ => bands.push((rp, y0, y1, n_rows, None)),
                }
            }
            _ => bands.push((rp, y0, y1, 1, entrance(rp).map(|e| (e, 1.0)))),
        }
    }
    for (rp, y0, y1, storeys, ent) in bands {
        for &(cp, x0, x1) in &parts(cols) {
            let Some(k) = set.find(cp, rp, false) else {
                continue;
            };
            let [mu, mv] = tile_mod(k);
            let rv = if rp == Part::Repeat {
                f64::from(storeys) / f64::from(mv)
            } else {
                1.0
            };
            let rect = |a: f64, b: f64| Aabb2::new(DVec2::new(a, y0), DVec2::new(b, y1));
            if cp == Part::Repeat
                && let Some((e, ev)) = ent
            {
                let mid = n_cols / 2;
                if let Some((ex0, ex1)) = cols.repeat_range(mid) {
                    if mid > 0 {
                        out.push(TileQuad {
                            rect: rect(x0, ex0),
                            tile: k,
                            repeats: [f64::from(mid) / f64::from(mu), rv],
                        });
                    }
                    out.push(TileQuad {
                        rect: rect(ex0, ex1),
                        tile: e,
                        repeats: [1.0, ev],
                    });
                    let right = n_cols - mid - 1;
                    if right > 0 {
                        out.push(TileQuad {
                            rect: rect(ex1, x1),
                            tile: k,
                            repeats: [f64::from(right) / f64::from(mu), rv],
                        });
                    }
                    continue;
                }
            }
            let ru = if cp == Part::Repeat {
                f64::from(n_cols) / f64::from(mu)
            } else {
                1.0
            };
            out.push(TileQuad {
                rect: rect(x0, x1),
                tile: k,
                repeats: [ru, rv],
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtin;

    /// Every built-in style, prepared, with its tile set at a coarse 8 texels per metre.
    fn coarse_sets() -> Vec<(PreparedStyle, TileSet)> {
        builtin::builtin_styles()
            .into_iter()
            .map(|style| {
                let p = PreparedStyle::new(style).unwrap();
                let opts = RasterOptions {
                    pixels_per_metre: 8.0,
                    ..Default::default()
                };
                let set = TileSet::build(&p, &opts).unwrap();
                (p, set)
            })
            .collect()
    }

    #[test]
    fn the_compact_quad_repeats_the_main_tile_as_often_as_the_fit() {
        for (p, set) in coarse_sets() {
            for role in [FaceRole::GroundFloor, FaceRole::UpperFloors, FaceRole::Side] {
                for (w, h, floors) in [(9.0, 4.5, Some(1)), (23.5, 14.2, Some(4)), (0.3, 0.2, None)]
                {
                    let spec = FacadeSpec {
                        floors,
                        role,
                        ..FacadeSpec::new(w, h, 3)
                    };
                    let layout = p.layout(&spec).unwrap();
                    let Some(q) = p.compact_tile_quad(&spec, &set).unwrap() else {
                        continue;
                    };
                    assert_eq!(q.rect.area(), w * h);
                    let tile = &set.tiles[q.tile];
                    assert!(!tile.entrance && tile.cols == Part::Repeat);
                    // Whole modules: the repeats times the tile's modules is the fitted
                    // repetition count of the columns.
                    let n = q.repeats[0] * f64::from(tile.modules_u);
                    assert!((n - f64::from(layout.columns().repeat_count())).abs() < 1e-9);
                    if tile.rows == Part::Repeat {
                        let m = q.repeats[1] * f64::from(tile.modules_v);
                        assert!((m - f64::from(layout.rows().repeat_count())).abs() < 1e-9);
                    }
                }
            }
        }
    }

    #[test]
    fn the_layout_alone_gives_the_facades_quads() {
        for (p, set) in coarse_sets() {
            for role in [
                FaceRole::Street,
                FaceRole::Side,
                FaceRole::GroundFloor,
                FaceRole::UpperFloors,
            ] {
                for (w, h, floors) in [(9.0, 8.0, None), (23.5, 14.2, Some(4)), (2.0, 1.0, None)] {
                    let spec = FacadeSpec {
                        floors,
                        role,
                        ..FacadeSpec::new(w, h, 11)
                    };
                    let full = p.facade(&spec).unwrap().tile_quads(&set);
                    let layout = p.layout(&spec).unwrap();
                    assert_eq!(
                        layout.tile_quads(&set),
                        full,
                        "{} {role:?} {w}x{h}",
                        set.style
                    );
                }
            }
        }
    }

    #[test]
    fn quads_cover_the_facade_once_with_whole_modules() {
        for style in builtin::builtin_styles() {
            let p = PreparedStyle::new(style).unwrap();
            let set = TileSet::build(
                &p,
                &RasterOptions {
                    pixels_per_metre: 16.0,
                    ..Default::default()
                },
            )
            .unwrap();
            assert!(set.tiles.len() <= 11, "{} tiles", set.tiles.len());
            for (w, h) in [(9.0, 8.0), (23.5, 14.2), (41.0, 60.0)] {
                let f = p.facade(&FacadeSpec::new(w, h, 4)).unwrap();
                if f.report().blank_columns || f.report().blank_rows {
                    continue;
                }
                let quads = f.tile_quads(&set);
                let area: f64 = quads.iter().map(|q| q.rect.area()).sum();
                assert!(
                    (area - w * h).abs() < 1e-6 * w * h,
                    "{}: {area} vs {}",
                    set.style,
                    w * h
                );
                for q in &quads {
                    let t = &set.tiles[q.tile];
                    // Repeats are whole modules: repeats × tile modules is an integer.
                    for (r, m) in [(q.repeats[0], t.modules_u), (q.repeats[1], t.modules_v)] {
                        let modules = r * f64::from(m);
                        assert!(
                            (modules - modules.round()).abs() < 1e-9,
                            "{} cut a module",
                            set.style
                        );
                    }
                }
            }
        }
    }
}
