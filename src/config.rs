//! [`CityConfig`]: everything that decides a city, as data (serde), and the built-in
//! presets.

use std::path::Path;

use polis_buildings::{BuildingKind, BuildingParams};
use polis_cells::CellParams;
#[cfg(feature = "gltf")]
use polis_export::glb::Batching;
use polis_facades::FacadeStyle;
use polis_geom::mesh::TerrainOptions;
use polis_lots::{BlockParams, LotParams};
use polis_roads::{GradeParams, RoadParams};
use serde::{Deserialize, Serialize};

use crate::citygen::{CitygenConfig, RoadMode};
use crate::error::{Error, Result};
use crate::maps::{MapSpec, MapsConfig};

/// The most worker threads [`CityConfig::threads`] may ask for. Per-cell work gains
/// nothing from more workers than cores, and every worker costs a stack and scratch
/// buffers; 256 covers the largest machines while a typo (4,000 or 100,000 threads) is
/// refused with an error instead of exhausting the machine.
pub const MAX_THREADS: usize = 256;

/// The largest value of `maps.max_image_pixels`: 2³⁰ pixels (a 4 GiB map raster).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 30;

/// The largest ground elevation, in metres above or below 0, an elevation map may give
/// (deeper than the deepest ocean trench, higher than the highest mountain).
pub const MAX_ELEVATION_M: f64 = 12_000.0;

/// The tallest building height limit, metres, a zoning band or maximum-height map may
/// give (the tallest buildings are about 830 m).
pub const MAX_BUILDING_HEIGHT_M: f64 = 1_000.0;

/// The whole description of a city. Every field has a default, so a configuration file
/// names only what differs (`{ "seed": 7, "size_m": 2000 }` is a complete file); unknown
/// fields are errors, so a typo does not pass silently.
///
/// The pipeline owns three things inside the stage parameters: `roads.seed`,
/// `buildings.seed` (both derived from [`seed`](Self::seed)) and `roads.bounds_*` (the
/// square of side [`size_m`](Self::size_m) centred on the origin). Values written there
/// are replaced.
///
/// # Sanity policy
/// [`validate`](Self::validate) checks every numeric field against a documented range
/// and names the field it refuses: `size_m` in [10, 10⁶] m; `threads` 1 to
/// [`MAX_THREADS`]; every map's value range (computed from its description,
/// [`MapSpec::value_range`]) finite, elevation within ±[`MAX_ELEVATION_M`], maximum height
/// in [0, [`MAX_BUILDING_HEIGHT_M`]]; zoning heights in (0, [`MAX_BUILDING_HEIGHT_M`]];
/// the stage parameters through their own `validate` (e.g. `roads.max_segments` ≥ 1).
/// Valid settings that leave the city empty are listed by [`warnings`](Self::warnings)
/// and in the city's report. The full table is in ARCHITECTURE.md.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CityConfig {
    /// A name for reports and output metadata. Default: "polis".
    pub name: String,
    /// The city seed; every stage and item derives its own seed from it. Default: 1.
    pub seed: u64,
    /// Side of the square city map, metres, centred on the origin. Default: 4000
    /// (16 km², Citygen's test city).
    pub size_m: f64,
    /// Level of detail of the buildings (derivation steps); `None` = the grammars' full
    /// detail (`buildings.max_lod`); a level above `buildings.max_lod` is a configuration
    /// error. Default: None.
    pub lod: Option<usize>,
    /// Worker threads for per-cell and per-lot work; `None` = one per core, `Some(1)` =
    /// serial, at most [`MAX_THREADS`]. The output is byte-identical for any value.
    /// Default: None.
    pub threads: Option<usize>,
    /// Input maps.
    pub maps: MapsConfig,
    /// How the roads are made: one Parish & Müller growth, or Kelly's Citygen (primary
    /// network, cells, secondary growth per cell). Default: parish_muller.
    #[serde(skip_serializing_if = "RoadMode::is_default")]
    pub road_mode: RoadMode,
    /// The Citygen mode's options (read when `road_mode` is `citygen`).
    #[serde(skip_serializing_if = "CitygenConfig::is_default")]
    pub citygen: CitygenConfig,
    /// Road generator (Parish & Müller §3).
    pub roads: RoadParams,
    /// Cell extraction (Eberly's minimal cycle basis).
    pub cells: CellParams,
    /// Blocks and footpaths (Kelly §4.4.1).
    pub blocks: BlockParams,
    /// Lot subdivision (Kelly §4.4.2, Parish & Müller §4.1).
    pub lots: LotParams,
    /// Which building stands where.
    pub zoning: ZoningConfig,
    /// Building grammars, footprints and heights (Parish & Müller §4.2, Kelly §4.4.3).
    pub buildings: BuildingParams,
    /// Facade textures (Parish & Müller §4.3).
    pub facades: FacadeConfig,
    /// How the 3-D scene is assembled.
    pub scene: SceneConfig,
    /// The real city the statistics report compares this city with (a city of
    /// `polis::stats::reference`, e.g. "Manhattan", or a regional mean such as
    /// "US/Canada mean"). Default: None.
    #[serde(default)]
    pub imitates: Option<String>,
}

impl Default for CityConfig {
    fn default() -> Self {
        CityConfig {
            name: "polis".into(),
            seed: 1,
            size_m: 4000.0,
            lod: None,
            threads: None,
            maps: MapsConfig::default(),
            road_mode: RoadMode::default(),
            citygen: CitygenConfig::default(),
            roads: RoadParams::default(),
            cells: CellParams::default(),
            blocks: BlockParams::default(),
            lots: LotParams::default(),
            zoning: ZoningConfig::default(),
            buildings: BuildingParams::default(),
            facades: FacadeConfig::default(),
            scene: SceneConfig::default(),
            imitates: None,
        }
    }
}

/// One zoning band: where the population density is at least `min_density`, build
/// `kind` no taller than `max_height_m`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ZoneBand {
    /// Lowest density of the band.
    pub min_density: f64,
    /// The building kind.
    pub kind: BuildingKind,
    /// Height limit, metres, in (0, [`MAX_BUILDING_HEIGHT_M`]].
    pub max_height_m: f64,
}

/// How lots get their building kind and height limit: by population density bands
/// (Parish & Müller §4.2 take the type from zoning maps; without a zoning map the
/// density is the zoning). A zoning map or a maximum-height map in
/// [`MapsConfig`] replaces the bands' kind or limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ZoningConfig {
    /// Bands, tried from the highest `min_density` down; the first that the density
    /// reaches applies. Default: skyscrapers above 0.55, offices above 0.45, mid-rises
    /// above 0.35, apartments above 0.25, houses above 0.08, industry below.
    pub bands: Vec<ZoneBand>,
    /// Kind where no band applies. Default: industrial.
    pub fallback_kind: BuildingKind,
    /// Height limit where no band applies, metres. Default: 15.
    pub fallback_max_height_m: f64,
    /// What mixed zones of the zoning map build (P&M §2). Default: [`MixedZone::default`](crate::MixedZone).
    pub mixed: crate::MixedZone,
    /// Height caps by lot ground area, applied after the bands and the maximum-height
    /// map (P&M §4.1). Default: none.
    pub area_caps: Vec<crate::AreaCap>,
}

impl Default for ZoningConfig {
    fn default() -> Self {
        let band = |min_density, kind, max_height_m| ZoneBand {
            min_density,
            kind,
            max_height_m,
        };
        ZoningConfig {
            bands: vec![
                band(0.55, BuildingKind::Skyscraper, 180.0),
                band(0.45, BuildingKind::Office, 90.0),
                band(0.35, BuildingKind::MidRise, 40.0),
                band(0.25, BuildingKind::Apartment, 25.0),
                band(0.08, BuildingKind::House, 12.0),
            ],
            fallback_kind: BuildingKind::Industrial,
            fallback_max_height_m: 15.0,
            mixed: crate::MixedZone::default(),
            area_caps: Vec::new(),
        }
    }
}

impl ZoningConfig {
    /// The kind and height limit at `density`.
    pub fn zone(&self, density: f64) -> (BuildingKind, f64) {
        self.bands
            .iter()
            .filter(|b| density >= b.min_density)
            .max_by(|a, b| a.min_density.total_cmp(&b.min_density))
            .map_or((self.fallback_kind, self.fallback_max_height_m), |b| {
                (b.kind, b.max_height_m)
            })
    }
}

/// How much of a style's tile set a facade shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FacadeDetail {
    /// One textured quad per facade face: the repeated bay × storey tile (the
    /// ground-floor tile on ground-floor faces), stretched to whole modules so no window
    /// is cut. Margins and cornices are left out. City scale: as many triangles as the
    /// untextured walls.
    #[default]
    Compact,
    /// Every tile of the set: margins, cornice, ground floor and the entrance bay, a few
    /// quads per face (Kelly's best fit). Close-ups and hero buildings.
    Full,
}

/// Which facade style dresses each building kind (names of built-in styles or of
/// [`FacadeConfig::styles`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KindStyles {
    /// Default: office_curtain_wall.
    pub skyscraper: String,
    /// Default: office_curtain_wall.
    pub office: String,
    /// Default: classic_stone.
    pub mid_rise: String,
    /// Default: brick_house.
    pub house: String,
    /// Default: brick_house.
    pub apartment: String,
    /// Default: industrial.
    pub industrial: String,
}

impl Default for KindStyles {
    fn default() -> Self {
        KindStyles {
            skyscraper: "office_curtain_wall".into(),
            office: "office_curtain_wall".into(),
            mid_rise: "classic_stone".into(),
            house: "brick_house".into(),
            apartment: "brick_house".into(),
            industrial: "industrial".into(),
        }
    }
}

impl KindStyles {
    /// The style name for `kind`.
    pub fn get(&self, kind: BuildingKind) -> &str {
        match kind {
            BuildingKind::Skyscraper => &self.skyscraper,
            BuildingKind::Office => &self.office,
            BuildingKind::MidRise => &self.mid_rise,
            BuildingKind::House => &self.house,
            BuildingKind::Apartment => &self.apartment,
            BuildingKind::Industrial => &self.industrial,
        }
    }
}

/// Facade textures: shared tile sets per style, applied through UVs in metres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FacadeConfig {
    /// Dress buildings with facade textures. Default: true.
    pub enabled: bool,
    /// Styles in addition to the built-in ones (a user style may replace a built-in one
    /// of the same name). Default: none.
    pub styles: Vec<FacadeStyle>,
    /// Style per building kind.
    pub style_of: KindStyles,
    /// Texels per metre of the tile textures. Default: 32.
    pub pixels_per_metre: f64,
    /// Compact (one quad per face) or full tile sets. Default: compact.
    pub detail: FacadeDetail,
}

impl Default for FacadeConfig {
    fn default() -> Self {
        FacadeConfig {
            enabled: true,
            styles: Vec::new(),
            style_of: KindStyles::default(),
            pixels_per_metre: 32.0,
            detail: FacadeDetail::Compact,
        }
    }
}

/// How the glTF/OBJ scene is assembled from the layers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SceneConfig {
    /// Height of the block plinths (kerbs), metres. Default: 0.15.
    pub kerb_height_m: f64,
    /// Road surfaces as meshes draped on the elevation. Default: true.
    pub road_surfaces: bool,
    /// Node structure of the glb: tiles of merged geometry per layer and material, per
    /// cell, or per building. Default: tiled (few draw calls; see
    /// [`Batching`] for when to use which). Only with the feature `gltf`.
    #[cfg(feature = "gltf")]
    pub batching: Batching,
    /// Side of the glb's square tiles with [`Batching::Tiled`], metres (see
    /// `polis_export::glb::GlbOptions::tile_size_m`). Default: 250.
    pub tile_size_m: f64,
    /// Adds a coarse level of detail to every building: its footprint extruded to its
    /// height (one mesh in its wall colour), a child node `lod 0` of the building node,
    /// whose own meshes are then tagged as level `lod` (the generator's level). The glb's
    /// tiled layout writes the levels as separate nodes per tile with their switch
    /// distances; the per-cell and per-building layouts, the OBJ and the scene itself
    /// hold both levels, overlapping. Ignored at `lod` 0. Default: false.
    pub coarse_lod: bool,
    /// Water bodies of the water map as flat surfaces at their level (their lowest shore
    /// point less [`WATER_FREEBOARD_M`](crate::WATER_FREEBOARD_M); the bed under them is
    /// part of the ground either way), in a node `water` of their own (false leaves
    /// them out). Default: true.
    pub water_surfaces: bool,
    /// How each building kind is seated on sloping ground, in
    /// [`BuildingKind::ALL`] order. Default: [`Foundation::Highest`] for every kind.
    pub foundations: [Foundation; 6],
    /// A ground mesh of the whole map (the elevation map as a terrain, textured by land
    /// use) in a node `ground` of its own (false leaves it out). Default: true.
    pub terrain: bool,
    /// How finely the terrain follows the elevation map: its error bound (the surface
    /// lies up to twice `max_error_m` below the map, never above) and leaf sizes.
    /// Default: [`TerrainOptions::default`] (0.2 m, leaves of 2–64 m).
    pub terrain_mesh: TerrainOptions,
    /// Side of the land-use texture of the ground, pixels (a power of two, 16 to 4096).
    /// Default: 1024 (about 4 m per pixel on a 4 km map).
    pub land_use_pixels: u32,
    /// Roads graded into the land on an elevation map: a height profile within a
    /// maximum grade per class, cut and fill with embankments, the terrain, plinths and
    /// buildings conformed to it (false: roads are draped on the raw map).
    /// Default: true.
    pub grade_roads: bool,
    /// The grading's limits and embankments. Default: [`GradeParams::default`]
    /// (highways 6 %, streets 15 %, 1:2 banks).
    pub road_grading: GradeParams,
}

/// How a building is seated on the ground under its footprint (CityEngine's four
/// alignments). The ground is the elevation map sampled at the footprint's corners.
///
/// Guarantees, at the footprint's corners: with [`Highest`](Self::Highest) and
/// [`Follow`](Self::Follow) no building floats and none is buried (the building's floor
/// is at or above the ground, its plinth or walls reach down to the ground); with
/// [`Lowest`](Self::Lowest) the uphill side is buried by the footprint's ground relief
/// (highest minus lowest corner), with [`Average`](Self::Average) by the relief above
/// the mean. Nothing is checked between corners: a footprint over a ridge can still cut
/// into it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Foundation {
    /// Level at the lowest ground, no plinth: the building stands into the slope.
    Lowest,
    /// Level at the highest ground, on a plinth (the walls carried down) to the lowest.
    #[default]
    Highest,
    /// Level at the mean ground, on a plinth to the lowest.
    Average,
    /// Level at the highest ground; every corner's walls reach down to the ground under
    /// it, so the bottom follows the slope.
    Follow,
}

impl Default for SceneConfig {
    fn default() -> Self {
        SceneConfig {
            kerb_height_m: 0.15,
            road_surfaces: true,
            #[cfg(feature = "gltf")]
            batching: Batching::default(),
            tile_size_m: 250.0,
            coarse_lod: false,
            water_surfaces: true,
            foundations: [Foundation::Highest; 6],
            terrain: true,
            terrain_mesh: TerrainOptions::default(),
            land_use_pixels: 1024,
            grade_roads: true,
            road_grading: GradeParams::default(),
        }
    }
}

/// The built-in presets: name and file text (`presets/<name>.json`).
const PRESETS: &[(&str, &str)] = &[
    ("default", include_str!("../presets/default.json")),
    ("manhattan", include_str!("../presets/manhattan.json")),
    ("paris", include_str!("../presets/paris.json")),
    (
        "san_francisco",
        include_str!("../presets/san_francisco.json"),
    ),
    ("old_town", include_str!("../presets/old_town.json")),
    ("suburbia", include_str!("../presets/suburbia.json")),
    ("citygen", include_str!("../presets/citygen.json")),
    ("citygen_us", include_str!("../presets/citygen_us.json")),
    ("milan", include_str!("../presets/milan.json")),
];

impl CityConfig {
    /// Names of the built-in presets.
    pub fn preset_names() -> impl Iterator<Item = &'static str> {
        PRESETS.iter().map(|(n, _)| *n)
    }

    /// A built-in preset by name (see [`preset_names`](Self::preset_names)).
    ///
    /// # Errors
    /// [`Error::UnknownPreset`] listing the names that exist.
    pub fn preset(name: &str) -> Result<CityConfig> {
        let text = PRESETS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, t)| *t)
            .ok_or_else(|| Error::UnknownPreset {
                name: name.into(),
                known: Self::preset_names().collect::<Vec<_>>().join(", "),
            })?;
        Self::from_json(text, &format!("preset {name}"))
    }

    /// Parses a configuration from JSON text; `source_name` names it in errors.
    ///
    /// # Errors
    /// [`Error::Parse`] with the line and column, or [`Error::Config`] from
    /// [`validate`](Self::validate).
    pub fn from_json(text: &str, source_name: &str) -> Result<CityConfig> {
        // Editors on some systems start UTF-8 files with a byte-order mark; JSON forbids
        // it, so it is dropped here rather than reported as a syntax error.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let config: CityConfig = serde_json::from_str(text).map_err(|e| Error::Parse {
            source_name: source_name.into(),
            message: e.to_string(),
        })?;
        config.validate()?;
        Ok(config)
    }

    /// Reads a JSON configuration file.
    ///
    /// # Errors
    /// [`Error::Io`], [`Error::Parse`] or [`Error::Config`].
    pub fn from_path(path: impl AsRef<Path>) -> Result<CityConfig> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.into(),
            source,
        })?;
        Self::from_json(&text, &path.display().to_string())
    }

    /// The configuration as pretty JSON (every field, defaults included).
    pub fn to_json(&self) -> String {
        // Serialising plain data with string keys cannot fail; fall back to an empty
        // object rather than panic.
        serde_json::to_string_pretty(self).unwrap_or_else(|_| "{}".into())
    }

    /// The road parameters the pipeline runs: `roads` with the city's seed and bounds.
    pub fn effective_road_params(&self) -> RoadParams {
        let h = self.size_m * 0.5;
        RoadParams {
            seed: crate::seed::sub_seed(self.seed, crate::Stage::Roads, 0),
            bounds_min: [-h, -h],
            bounds_max: [h, h],
            ..self.roads.clone()
        }
    }

    /// The building parameters the pipeline runs: `buildings` with the city's seed.
    pub fn effective_building_params(&self) -> BuildingParams {
        BuildingParams {
            seed: crate::seed::sub_seed(self.seed, crate::Stage::Buildings, 0),
            ..self.buildings.clone()
        }
    }

    /// The level of detail the buildings are drawn at.
    pub fn effective_lod(&self) -> usize {
        self.lod
            .unwrap_or(self.buildings.max_lod)
            .min(self.buildings.max_lod)
    }

    /// Checks what the stage crates do not: the city's own fields, the zoning bands and
    /// the facade options; then the road and building parameters as the pipeline will
    /// run them.
    ///
    /// # Errors
    /// [`Error::Config`] naming the field, or the stage crate's parameter error.
    pub fn validate(&self) -> Result<()> {
        if !(self.size_m.is_finite() && (10.0..=1.0e6).contains(&self.size_m)) {
            return Err(Error::config(
                "size_m",
                format!("{} m; give a map side in [10, 1000000] m", self.size_m),
            ));
        }
        if let Some(t) = self.threads
            && !(1..=MAX_THREADS).contains(&t)
        {
            return Err(Error::config(
                "threads",
                format!("{t} threads; give 1 to {MAX_THREADS}, or leave it out for one per core"),
            ));
        }
        if let Some(lod) = self.lod
            && lod > self.buildings.max_lod
        {
            return Err(Error::config(
                "lod",
                format!(
                    "{lod} is above the most detailed level, buildings.max_lod = {}; give 0 to \
                     {0}, raise buildings.max_lod, or leave lod out",
                    self.buildings.max_lod
                ),
            ));
        }
        let height_ok = |h: f64| h.is_finite() && h > 0.0 && h <= MAX_BUILDING_HEIGHT_M;
        for (i, b) in self.zoning.bands.iter().enumerate() {
            if !(b.min_density.is_finite() && height_ok(b.max_height_m)) {
                return Err(Error::config(
                    format!("zoning.bands[{i}]"),
                    format!(
                        "min_density {} must be finite and max_height_m {} in (0, {MAX_BUILDING_HEIGHT_M}] m",
                        b.min_density, b.max_height_m
                    ),
                ));
            }
        }
        crate::zoning::validate(&self.zoning.mixed, &self.zoning.area_caps)?;
        if let Some(z) = &self.maps.zoning {
            let (lo, hi) = z.value_range();
            crate::zoning::check_zone_map_range(lo, hi)?;
        }
        if !height_ok(self.zoning.fallback_max_height_m) {
            return Err(Error::config(
                "zoning.fallback_max_height_m",
                format!(
                    "{} m; give a height in (0, {MAX_BUILDING_HEIGHT_M}] m",
                    self.zoning.fallback_max_height_m
                ),
            ));
        }
        self.check_maps()?;
        let ppm = self.facades.pixels_per_metre;
        if !(ppm.is_finite() && (1.0..=512.0).contains(&ppm)) {
            return Err(Error::config(
                "facades.pixels_per_metre",
                format!("{ppm}; give 1 to 512 texels per metre"),
            ));
        }
        if !(self.scene.kerb_height_m.is_finite()
            && (0.0..=5.0).contains(&self.scene.kerb_height_m))
        {
            return Err(Error::config(
                "scene.kerb_height_m",
                "give a kerb height in [0, 5] m",
            ));
        }
        if !(self.scene.tile_size_m.is_finite() && self.scene.tile_size_m > 0.0) {
            return Err(Error::config(
                "scene.tile_size_m",
                "give the glb's tile side as a finite length above 0 m",
            ));
        }
        crate::ground::validate(&self.scene).map_err(|(field, why)| Error::config(field, why))?;
        self.scene.road_grading.validate()?;
        self.effective_road_params().validate()?;
        self.citygen.validate()?;
        self.effective_building_params().validate()?;
        self.lots.validate()?;
        self.blocks.validate()?;
        Ok(())
    }

    /// The maps' value ranges against their physical ranges (the sanity policy in the
    /// crate docs and ARCHITECTURE.md), from the descriptions alone.
    fn check_maps(&self) -> Result<()> {
        let m = &self.maps;
        if !(1..=MAX_IMAGE_PIXELS).contains(&m.max_image_pixels) {
            return Err(Error::config(
                "maps.max_image_pixels",
                format!(
                    "{} pixels; give 1 to {MAX_IMAGE_PIXELS} (2^30)",
                    m.max_image_pixels
                ),
            ));
        }
        let mut all: Vec<(String, &MapSpec)> = vec![("maps.population".into(), &m.population)];
        let named = [
            ("maps.water", &m.water),
            ("maps.parks", &m.parks),
            ("maps.elevation", &m.elevation),
            ("maps.zoning", &m.zoning),
            ("maps.max_height", &m.max_height),
            ("maps.grid_angle", &m.grid_angle),
        ];
        all.extend(
            named
                .iter()
                .filter_map(|(n, s)| s.as_ref().map(|s| (n.to_string(), s))),
        );
        for (i, pm) in m.pattern_weights.iter().enumerate() {
            all.push((format!("maps.pattern_weights[{i}].map"), &pm.map));
        }
        for (name, spec) in all {
            let (lo, hi) = spec.value_range();
            if !(lo.is_finite() && hi.is_finite()) {
                return Err(Error::config(
                    name,
                    format!(
                        "the map's values can reach [{lo}, {hi}]; every map must stay finite \
                         (check its scale factors and constants)"
                    ),
                ));
            }
        }
        if let Some(e) = &m.elevation {
            let (lo, hi) = e.value_range();
            if lo < -MAX_ELEVATION_M || hi > MAX_ELEVATION_M {
                return Err(Error::config(
                    "maps.elevation",
                    format!(
                        "the map's values can reach [{lo}, {hi}] m; ground elevation must stay \
                         within ±{MAX_ELEVATION_M} m (check the elevation scale)"
                    ),
                ));
            }
        }
        if let Some(h) = &m.max_height {
            let (lo, hi) = h.value_range();
            if lo < 0.0 || hi > MAX_BUILDING_HEIGHT_M {
                return Err(Error::config(
                    "maps.max_height",
                    format!(
                        "the map's values can reach [{lo}, {hi}] m; a height limit must be in \
                         [0, {MAX_BUILDING_HEIGHT_M}] m (check the maximum-height scale)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Settings that are valid but leave the city (nearly) empty, as messages for the
    /// report ([`SkipReport::warnings`](crate::SkipReport::warnings)): a maximum-height map
    /// that is 0 everywhere, parks or water everywhere, a population map that never
    /// reaches the street threshold.
    pub fn warnings(&self) -> Vec<String> {
        let m = &self.maps;
        let mut out = Vec::new();
        if let Some((_, hi)) = m.max_height.as_ref().map(MapSpec::value_range)
            && hi <= 0.0
        {
            out.push(format!(
                "maps.max_height is at most {hi} m everywhere: no building can stand"
            ));
        }
        if let Some((lo, _)) = m.parks.as_ref().map(MapSpec::value_range)
            && lo >= 0.5
        {
            out.push("maps.parks is a park (≥ 0.5) everywhere: no lot can be built".into());
        }
        if let Some((lo, _)) = m.water.as_ref().map(MapSpec::value_range)
            && lo >= 0.5
        {
            out.push("maps.water is water (≥ 0.5) everywhere: no road can start".into());
        }
        let (_, pop) = m.population.value_range();
        if pop < self.roads.population_threshold {
            out.push(format!(
                "maps.population is at most {pop} everywhere, below roads.population_threshold \
                 {}: no street can branch",
                self.roads.population_threshold
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_parses_and_validates() {
        for name in CityConfig::preset_names() {
            let c = CityConfig::preset(name).unwrap();
            c.validate().unwrap();
            // A preset survives a round trip through its full JSON form.
            let back = CityConfig::from_json(&c.to_json(), name).unwrap();
            assert_eq!(back, c, "{name}");
        }
    }

    #[test]
    fn unknown_preset_and_unknown_fields_are_errors() {
        let err = CityConfig::preset("atlantis").unwrap_err();
        assert!(err.to_string().contains("manhattan"), "{err}");
        let err = CityConfig::from_json(r#"{ "sede": 3 }"#, "test").unwrap_err();
        assert!(err.to_string().contains("sede"), "{err}");
        let err = CityConfig::from_json(r#"{ "size_m": -4 }"#, "test").unwrap_err();
        assert!(err.to_string().contains("size_m"), "{err}");
        let err = CityConfig::from_json("{ not json", "test").unwrap_err();
        assert!(matches!(err, Error::Parse { .. }), "{err}");
    }

    #[test]
    fn zoning_bands_pick_the_highest_band_reached() {
        let z = ZoningConfig::default();
        assert_eq!(z.zone(0.9).0, BuildingKind::Skyscraper);
        assert_eq!(z.zone(0.3).0, BuildingKind::Apartment);
        assert_eq!(z.zone(0.0).0, BuildingKind::Industrial);
        assert_eq!(z.zone(f64::NAN).0, BuildingKind::Industrial);
    }

    /// A map scaled by `scale`. With PNG maps built, the scaled field is a PNG file that
    /// does not exist, so a test passes only if validation judges the scale before it
    /// reads any file; without them a constant field stands in.
    fn scaled_map(scale: f64) -> MapSpec {
        #[cfg(feature = "png")]
        let field = polis_geom::field::FieldSpec::Png {
            path: "/nonexistent/map.png".into(),
            extent: polis_geom::Aabb2::new(
                polis_geom::DVec2::splat(-100.0),
                polis_geom::DVec2::splat(100.0),
            ),
        };
        #[cfg(not(feature = "png"))]
        let field = polis_geom::field::FieldSpec::Constant { value: 1.0 };
        MapSpec::Field(polis_geom::field::FieldSpec::Scaled {
            field: Box::new(field),
            factor: scale,
        })
    }

    fn field_of(err: Error) -> String {
        match err {
            Error::Config { field, .. } => field,
            other => panic!("not a configuration error: {other}"),
        }
    }

    /// The adversarial run's bad values: each is refused naming the field, before any
    /// file is read.
    #[test]
    fn out_of_range_values_name_their_field() {
        let base = CityConfig::default();
        for threads in [0, MAX_THREADS + 1, 4_000, 100_000] {
            let c = CityConfig {
                threads: Some(threads),
                ..base.clone()
            };
            assert_eq!(field_of(c.validate().unwrap_err()), "threads");
        }
        for threads in [1, MAX_THREADS] {
            let c = CityConfig {
                threads: Some(threads),
                ..base.clone()
            };
            c.validate().unwrap();
        }
        for scale in [f64::NAN, 1e300, f64::INFINITY, -13_000.0] {
            let mut c = base.clone();
            c.maps.elevation = Some(scaled_map(scale));
            assert_eq!(
                field_of(c.validate().unwrap_err()),
                "maps.elevation",
                "{scale}"
            );
        }
        let mut c = base.clone();
        c.maps.elevation = Some(scaled_map(300.0));
        c.validate().unwrap();
        for scale in [-50.0, f64::NAN, 1e6] {
            let mut c = base.clone();
            c.maps.max_height = Some(scaled_map(scale));
            assert_eq!(
                field_of(c.validate().unwrap_err()),
                "maps.max_height",
                "{scale}"
            );
        }
        let mut c = base.clone();
        c.maps.population = scaled_map(f64::NAN);
        assert_eq!(field_of(c.validate().unwrap_err()), "maps.population");
        let mut c = base.clone();
        c.zoning.bands[0].max_height_m = 5_000.0;
        assert_eq!(field_of(c.validate().unwrap_err()), "zoning.bands[0]");
        let mut c = base.clone();
        c.roads.max_segments = 0;
        let err = c.validate().unwrap_err();
        assert!(
            matches!(
                &err,
                Error::Roads(polis_roads::RoadError::InvalidParameter {
                    name: "max_segments",
                    ..
                })
            ),
            "{err}"
        );
        for px in [0, MAX_IMAGE_PIXELS + 1] {
            let mut c = base.clone();
            c.maps.max_image_pixels = px;
            assert_eq!(field_of(c.validate().unwrap_err()), "maps.max_image_pixels");
        }
        let mut c = base.clone();
        c.lots.lot_width = f64::NAN;
        assert!(c.validate().unwrap_err().to_string().contains("lot_width"));
        let mut c = base;
        c.blocks.footpath_width = -1.0;
        assert!(
            c.validate()
                .unwrap_err()
                .to_string()
                .contains("footpath_width")
        );
    }

    #[test]
    fn a_byte_order_mark_is_accepted() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/config_with_bom.json"
        );
        let bytes = std::fs::read(path).unwrap();
        assert_eq!(
            &bytes[..3],
            b"\xef\xbb\xbf",
            "the fixture starts with a BOM"
        );
        let c = CityConfig::from_path(path).unwrap();
        assert_eq!((c.seed, c.size_m), (7, 600.0));
    }

    #[test]
    fn empty_but_valid_settings_are_warned_about() {
        let mut c = CityConfig::default();
        assert!(c.warnings().is_empty(), "{:?}", c.warnings());
        c.maps.max_height = Some(scaled_map(0.0));
        c.validate().unwrap();
        let w = c.warnings();
        assert!(w.len() == 1 && w[0].contains("maps.max_height"), "{w:?}");
        c.maps.population = MapSpec::constant(0.01);
        assert!(c.warnings().iter().any(|w| w.contains("maps.population")));
    }
}
