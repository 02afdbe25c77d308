//! The Citygen road mode (Kelly 2008, §4.1–4.3): a primary network, its city cells, and
//! secondary roads grown inside each cell, joined into one road graph for the later
//! stages (blocks, lots, buildings, facades).
//!
//! ```text
//!  primary network ──polis-cells──▶ city cells ──SecondaryGrowth per cell (rayon)──▶
//!  union graph (primary + every cell's secondary roads) ──▶ cells = blocks ──▶ lots …
//! ```
//!
//! The primary network comes from a [`PrimarySource`]: the highways of a Parish & Müller
//! growth with the configuration's road parameters, a ring-and-spoke network (Kelly
//! §6.1's Milan), a road graph in a JSON file, or a Kelly [`PrimaryNetwork`](polis_roads::primary::PrimaryNetwork)
//! (inline or from a file; its paths simplified within [`PATH_TOLERANCE_M`]). Each
//! cell's pattern ([`CellPatternChoice`]: a Kelly neighbourhood preset, or the course
//! report's grid road builders with Downtown or Residential rules) is chosen by an
//! explicit override (a point inside the cell), else by the population at the cell's
//! centre ([`CitygenConfig::by_population`]), else the default.
//!
//! Cell ids are stable: a hash of the cell's sorted boundary positions, so editing one
//! part of the primary network does not reseed the cells elsewhere. Cells are grown in
//! parallel and joined in cell order, so any thread count gives the same graph.

use std::path::PathBuf;
use std::sync::Arc;

use polis_cells::Cell;
use polis_geom::graph::SnapOptions;
use polis_geom::hash::splitmix64;
use polis_geom::par::map_costliest_first;
use polis_geom::par::prelude::*;
use polis_geom::{DVec2, Field};
use polis_roads::grid_builders::{GridBuilderGrowth, GridError, GridMaps, GridParams};
use polis_roads::secondary::{
    CellMaps, Neighbourhood, SecondaryCell, SecondaryError, SecondaryGrowth, SecondaryRoads,
    estimated_work,
};
use polis_roads::{Junction, Road, RoadClass, RoadNetwork};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

mod edits;
mod kelly;
mod traits;
mod zones;
use crate::stages::{ParishMullerRoads, RoadStage, RoadsOutput, Skip, Stage, StageContext};
pub use edits::{
    CellParam, CellSettings, LotOverride, MapPaint, PaintLayer, PresetParams, lot_override,
    paint_maps,
};
pub use kelly::{InlinePrimary, PATH_TOLERANCE_M};
pub use traits::{LotPlan, block_ids, district_at, hint_kind, lot_params_of, lot_plan};
pub(crate) use traits::{district_boxes, lot_plan_in};
pub use zones::{MIN_ZONE_SAMPLES, ZoneLevel, ZoneMap, ZoneRule, Zoning};

/// How the city's roads are made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RoadMode {
    /// One Parish & Müller growth over the whole map (§3). Default.
    #[default]
    ParishMuller,
    /// Kelly's Citygen: primary network, cells, secondary growth per cell
    /// ([`CitygenConfig`]).
    Citygen,
}

impl RoadMode {
    /// Whether this is the default mode (for serde's `skip_serializing_if`).
    pub fn is_default(&self) -> bool {
        *self == RoadMode::ParishMuller
    }
}

/// Where the Citygen mode's primary network comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
#[non_exhaustive]
pub enum PrimarySource {
    /// The highways of a Parish & Müller growth with the configuration's `roads`
    /// parameters (streets switched off): its highway edges and their junctions. Default.
    #[default]
    Highways,
    /// Concentric rings joined by radial spokes, inside the map's square (Kelly §6.1,
    /// Milan's ring roads).
    Rings {
        /// Centre, metres. Default: the origin.
        #[serde(default)]
        centre: [f64; 2],
        /// Number of rings. Must be 1 to 64.
        rings: u32,
        /// Distance between rings, metres (the first ring has this radius). Must be > 0.
        spacing_m: f64,
        /// Radial spokes from the first ring to the map's edge. Must be 3 to 256.
        spokes: u32,
        /// Length of the pieces the rings are drawn with, metres. Default: 150.
        #[serde(default = "ring_piece")]
        piece_m: f64,
    },
    /// A road graph read from a JSON file (the serde form of
    /// [`RoadNetwork`], e.g. an exported `roads.json`).
    Graph {
        /// The file.
        path: PathBuf,
    },
    /// A Kelly primary network ([`PrimaryNetwork`](polis_roads::primary::PrimaryNetwork), issue 17), inline in its serde form;
    /// its low-level graph ([`PrimaryNetwork::to_road_network`](polis_roads::primary::PrimaryNetwork::to_road_network)) is the primary network.
    Kelly {
        /// The network (checked when the configuration is read).
        network: InlinePrimary,
    },
    /// A Kelly primary network read from a file: its serde form
    /// ([`PrimaryNetwork::to_json`](polis_roads::primary::PrimaryNetwork::to_json)), a hand-written [`PrimarySpec`](polis_roads::primary::PrimarySpec) (`nodes` + `roads`)
    /// or a GeoJSON `FeatureCollection` ([`PrimaryNetwork::from_geojson`](polis_roads::primary::PrimaryNetwork::from_geojson)). Specs and
    /// GeoJSON are built by validity-checked edits and plotted over the city's terrain
    /// (elevation, water, parks) inside the map's square.
    KellyFile {
        /// The file.
        path: PathBuf,
    },
}

fn ring_piece() -> f64 {
    150.0
}

/// The course report's grid road builders' shipped rule sets, as a cell pattern
/// ([`polis_roads::grid_builders`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum GridPattern {
    /// The report's Downtown rules ([`GridParams::downtown`]): no dead ends, many
    /// crossings.
    Downtown,
    /// The report's Residential rules ([`GridParams::residential`]): builders may stop.
    Residential,
}

impl GridPattern {
    /// The pattern's parameters.
    pub fn params(self) -> GridParams {
        match self {
            GridPattern::Downtown => GridParams::downtown(),
            GridPattern::Residential => GridParams::residential(),
        }
    }

    /// The Kelly preset whose lot and building traits the pattern's cells take (grid
    /// builders make roads only): Manhattan for Downtown, Suburbia for Residential.
    pub fn traits_from(self) -> Neighbourhood {
        match self {
            GridPattern::Downtown => Neighbourhood::Manhattan,
            GridPattern::Residential => Neighbourhood::Suburbia,
        }
    }
}

/// What fills a cell: one of Kelly's neighbourhood presets or the grid road builders. In
/// JSON just the name (`"manhattan"`, …, `"downtown"`, `"residential"`), so
/// configurations written before grid patterns existed read unchanged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
#[non_exhaustive]
pub enum CellPatternChoice {
    /// Kelly's secondary growth with a neighbourhood preset.
    Kelly(Neighbourhood),
    /// The grid road builders with a shipped rule set.
    Grid(GridPattern),
}

impl Default for CellPatternChoice {
    fn default() -> Self {
        CellPatternChoice::Kelly(Neighbourhood::Manhattan)
    }
}

impl From<Neighbourhood> for CellPatternChoice {
    fn from(n: Neighbourhood) -> Self {
        CellPatternChoice::Kelly(n)
    }
}

impl From<GridPattern> for CellPatternChoice {
    fn from(g: GridPattern) -> Self {
        CellPatternChoice::Grid(g)
    }
}

/// One population band of [`CitygenConfig::by_population`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PopulationBand {
    /// The band applies where the population at the cell's centre is at least this.
    pub min_density: f64,
    /// The neighbourhood of such cells.
    pub neighbourhood: CellPatternChoice,
}

/// An explicit neighbourhood for the cell containing a point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CellOverride {
    /// A point inside the cell, metres.
    pub at: [f64; 2],
    /// Its neighbourhood.
    pub neighbourhood: CellPatternChoice,
}

/// The Citygen mode's options (used when [`CityConfig::road_mode`](crate::CityConfig) is
/// [`RoadMode::Citygen`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CitygenConfig {
    /// The primary network. Default: the P&M highways.
    pub primary: PrimarySource,
    /// Metres per Citygen unit for the neighbourhood presets (see
    /// [`polis_roads::secondary::presets`]). Must be in (0, 1000]. Default: 20.
    pub unit_m: f64,
    /// The neighbourhood of cells no band or override picks. Default: Manhattan.
    pub neighbourhood: CellPatternChoice,
    /// Neighbourhood by population at the cell's centre: the band with the highest
    /// `min_density` reached applies. Default: none.
    pub by_population: Vec<PopulationBand>,
    /// Explicit neighbourhoods; the first override whose point lies in a cell applies.
    /// Default: none.
    pub overrides: Vec<CellOverride>,
    /// A zoning map whose levels choose each cell's neighbourhood (and optionally some
    /// of its parameters) by the cell's area majority or centroid ([`ZoneMap`]); it
    /// comes after per-cell settings and overrides, before the population bands.
    /// Default: none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub zones: Option<ZoneMap>,
    /// Carriageway widths of secondary roads are multiplied by this (Kelly's widths in
    /// Citygen units come out narrow in metres). Must be in (0, 10]. Default: 1.
    pub road_width_factor: f64,
    /// City-wide parameter overrides of neighbourhood presets ([`PresetParams`]), after
    /// the unit and width factor. Default: none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub preset_params: Vec<PresetParams>,
    /// Whether every cell's lot size, building height (with deviances) and building hint
    /// reach the lot and building stages (Kelly §5.5.1); when false only cells whose
    /// settings set one of them do, and the `lots` options and zoning bands decide
    /// elsewhere. Default: false.
    pub cell_traits: bool,
    /// Per-cell settings (pattern, parameters, seed) by stable cell id, as the editor
    /// writes them. Default: none.
    pub cells: Vec<CellSettings>,
    /// Per-lot and per-building overrides, anchored to lot ids. Default: none.
    pub lots: Vec<LotOverride>,
    /// Rectangles painted onto the population, zoning and park maps. Default: none.
    pub paint: Vec<MapPaint>,
}

impl Default for CitygenConfig {
    fn default() -> Self {
        CitygenConfig {
            primary: PrimarySource::Highways,
            unit_m: polis_roads::secondary::CITYGEN_UNIT_M,
            neighbourhood: CellPatternChoice::Kelly(Neighbourhood::Manhattan),
            by_population: Vec::new(),
            overrides: Vec::new(),
            zones: None,
            road_width_factor: 1.0,
            preset_params: Vec::new(),
            cell_traits: false,
            cells: Vec::new(),
            lots: Vec::new(),
            paint: Vec::new(),
        }
    }
}

impl CitygenConfig {
    /// Whether every field is at its default (for serde's `skip_serializing_if`).
    pub fn is_default(&self) -> bool {
        *self == CitygenConfig::default()
    }

    /// Checks the ranges documented on each field.
    ///
    /// # Errors
    /// [`Error::Config`] naming the field.
    pub fn validate(&self) -> Result<()> {
        if !(self.unit_m.is_finite() && self.unit_m > 0.0 && self.unit_m <= 1000.0) {
            return Err(Error::config(
                "citygen.unit_m",
                "give metres per unit in (0, 1000]",
            ));
        }
        let f = self.road_width_factor;
        if !(f.is_finite() && f > 0.0 && f <= 10.0) {
            return Err(Error::config(
                "citygen.road_width_factor",
                "give a factor in (0, 10]",
            ));
        }
        for (i, b) in self.by_population.iter().enumerate() {
            if !b.min_density.is_finite() {
                return Err(Error::config(
                    format!("citygen.by_population[{i}].min_density"),
                    "must be finite",
                ));
            }
        }
        for (i, t) in self.preset_params.iter().enumerate() {
            for q in &t.params {
                q.validate().map_err(|e| {
                    Error::config(format!("citygen.preset_params[{i}].params"), e.to_string())
                })?;
            }
        }
        for (i, c) in self.cells.iter().enumerate() {
            for q in &c.params {
                q.validate().map_err(|e| {
                    Error::config(format!("citygen.cells[{i}].params"), e.to_string())
                })?;
            }
        }
        for (i, o) in self.lots.iter().enumerate() {
            let ok = o.at.iter().all(|c| c.is_finite())
                && o.height_m
                    .is_none_or(|h| h.is_finite() && h > 0.0 && h <= crate::MAX_BUILDING_HEIGHT_M);
            if !ok {
                return Err(Error::config(
                    format!("citygen.lots[{i}]"),
                    "a finite anchor and a height in (0, 1000] m",
                ));
            }
        }
        for (i, p) in self.paint.iter().enumerate() {
            p.validate(f64::INFINITY)
                .map_err(|e| Error::config(format!("citygen.paint[{i}]"), e.to_string()))?;
        }
        if let Some(z) = &self.zones {
            z.validate()?;
        }
        for (i, o) in self.overrides.iter().enumerate() {
            if !(o.at[0].is_finite() && o.at[1].is_finite()) {
                return Err(Error::config(
                    format!("citygen.overrides[{i}].at"),
                    "must be finite",
                ));
            }
        }
        if let PrimarySource::Rings {
            rings,
            spacing_m,
            spokes,
            piece_m,
            centre,
        } = &self.primary
        {
            let ok = (1..=64).contains(rings)
                && spacing_m.is_finite()
                && *spacing_m > 0.0
                && (3..=256).contains(spokes)
                && piece_m.is_finite()
                && *piece_m >= 1.0
                && centre.iter().all(|c| c.is_finite());
            if !ok {
                return Err(Error::config(
                    "citygen.primary",
                    "rings: 1 to 64 rings, spacing_m > 0, 3 to 256 spokes, piece_m ≥ 1, a finite centre",
                ));
            }
        }
        for n in Neighbourhood::ALL {
            n.params().map_err(polis_roads::RoadError::from)?;
        }
        Ok(())
    }
}

/// What the Citygen mode made, stage by stage (for reports and benchmarks).
#[derive(Debug, Clone)]
pub struct CitygenNetwork {
    /// The primary network.
    pub primary: RoadNetwork,
    /// Every grown cell's secondary roads, in cell order. Each is behind an `Arc`: the
    /// editor's memo hands a cell an edit left alone back without copying its graph.
    pub cells: Vec<Arc<SecondaryRoads>>,
    /// Every grown cell's id, region, pattern and traits (parallel to `cells`).
    pub districts: Vec<District>,
    /// The cells whose growth was skipped (too small or invalid for their pattern; the
    /// reasons are in `skipped`), in cell order: still city cells an editor shows and
    /// edits, with no secondary roads. Their traits do not reach the lot stage.
    pub ungrown: Vec<District>,
    /// The union: primary and secondary roads in one planar graph.
    pub network: RoadNetwork,
    /// Cells that could not be grown (too small, invalid boundary), with why.
    pub skipped: Vec<Skip>,
    /// Wall time of the secondary growth of all cells (parallel), seconds.
    pub secondary_s: f64,
}

/// The Citygen road stage: see the [module docs](self).
#[derive(Debug, Clone, Default)]
pub struct CitygenRoads;

impl RoadStage for CitygenRoads {
    fn roads(&self, cx: &StageContext<'_>) -> Result<RoadsOutput> {
        let (net, growth) = citygen_network(cx)?;
        Ok(RoadsOutput {
            network: net.network,
            growth,
            skipped: net.skipped,
            districts: net.districts,
        })
    }
}

/// The default road stage: Parish & Müller or Citygen, as
/// [`CityConfig::road_mode`](crate::CityConfig) says.
#[derive(Debug, Clone, Default)]
pub struct ConfiguredRoads {
    /// The P&M stage (with its optional custom goals).
    pub parish_muller: ParishMullerRoads,
}

impl RoadStage for ConfiguredRoads {
    fn roads(&self, cx: &StageContext<'_>) -> Result<RoadsOutput> {
        match cx.config.road_mode {
            RoadMode::ParishMuller => self.parish_muller.roads(cx),
            RoadMode::Citygen => CitygenRoads.roads(cx),
        }
    }
}

/// A stable id of a cell: a hash of its sorted boundary positions.
pub fn stable_cell_id(cell: &Cell) -> u64 {
    let mut keys: Vec<(u64, u64)> = cell
        .boundary
        .polygon
        .points()
        .iter()
        .map(|p| (p.x.to_bits(), p.y.to_bits()))
        .collect();
    keys.sort_unstable();
    keys.iter().fold(0x00C1_7C3E_u64, |h, &(x, y)| {
        splitmix64(splitmix64(h ^ x) ^ y)
    })
}

/// Runs the Citygen mode's road part: primary network, cells, secondary growth, union.
/// Returns the P&M growth report too when the primary network came from it.
///
/// # Errors
/// Configuration errors, a primary graph file that cannot be read, a failed stage.
pub fn citygen_network(
    cx: &StageContext<'_>,
) -> Result<(CitygenNetwork, Option<polis_roads::GrowthReport>)> {
    citygen_network_with(cx, None)
}

/// [`citygen_network`] with the editor's memo of grown cells.
pub(crate) fn citygen_network_with(
    cx: &StageContext<'_>,
    memo: Option<&dyn GrowthMemo>,
) -> Result<(CitygenNetwork, Option<polis_roads::GrowthReport>)> {
    let cg = &cx.config.citygen;
    cg.validate()?;
    let (mut primary, growth, kelly_roads) = primary_network(cx)?;
    let mut decomposition = polis_cells::extract_with(&primary, &cx.config.cells)?;
    // P&M highways on a small map may enclose nothing: the map's edge then closes them
    // (as it bounds the rings source), so the city has cells.
    if decomposition.cells.is_empty() && cg.primary == PrimarySource::Highways {
        close_with_map_edge(&mut primary, cx.config.size_m)?;
        decomposition = polis_cells::extract_with(&primary, &cx.config.cells)?;
    }
    // Maps: water and parks through lazily cached lattices, as the P&M stage reads them.
    let params = cx.config.effective_road_params();
    let spacing = polis_roads::procedural_lattice_m(&params);
    let window = params.bounds();
    let cache = |map: &Arc<dyn Field>| -> Result<Arc<dyn Field>> {
        Ok(Arc::new(polis_roads::LazyLattice::new(
            Arc::clone(map),
            spacing,
            window,
        )?))
    };
    let water = cx
        .maps
        .has_water
        .then(|| cache(&cx.maps.inputs.water))
        .transpose()?;
    let parks = cx
        .maps
        .has_parks
        .then(|| cache(&cx.maps.inputs.parks))
        .transpose()?;
    let maps = CellMaps {
        water: water.as_deref(),
        parks: parks.as_deref(),
        step_m: params.legality_step_m,
    };
    let mut presets = Vec::new();
    for n in Neighbourhood::ALL {
        let mut p = n
            .preset()
            .map_err(polis_roads::RoadError::from)?
            .to_params(cg.unit_m);
        p.road_width_m.value *= cg.road_width_factor;
        for t in cg.preset_params.iter().filter(|t| t.neighbourhood == n) {
            for q in &t.params {
                q.apply(&mut p);
            }
        }
        presets.push((n, p));
    }
    let preset = |n: Neighbourhood| {
        presets
            .iter()
            .find(|(m, _)| *m == n)
            .map(|(_, p)| p.clone())
            .unwrap_or_default()
    };
    let city_seed = cx.seed(Stage::Roads, 1);
    // What every cell's growth reads besides its own inputs (for the editor's memo).
    let shared = memo.map(|_| {
        let parks: Vec<_> = cg
            .paint
            .iter()
            .filter(|p| p.layer == PaintLayer::Park)
            .collect();
        let text = format!(
            "{:?}|{:?}|{:?}|{}",
            cx.config.maps, parks, params, cx.config.size_m
        );
        crate::editor::key::Key::new(0x6772_6F77).bytes(text.as_bytes())
    });
    let ids = cell_ids(&decomposition, &primary, kelly_roads.as_deref());
    let zoning = zoning_of(cx)?;
    let started = crate::clock::Instant::now();
    /// A cell ready to grow.
    struct Ready {
        input: SecondaryCell,
        district: District,
        pattern: CellPatternChoice,
        params: polis_roads::secondary::SecondaryParams,
        seed: u64,
    }
    // Each cell's inputs, pattern and parameters, or the reason it is skipped.
    let prepared: Vec<std::result::Result<Ready, Skip>> = decomposition
        .cells
        .par_iter()
        .zip(ids.par_iter())
        .map(|(cell, &id)| {
            let skip = |reason: String| Skip {
                stage: Stage::Roads,
                id,
                reason,
            };
            let region = match cell.polygon_with_holes() {
                Ok(r) => r,
                Err(e) => return Err(skip(format!("cell {id}: {e}"))),
            };
            let settings = cg.cells.iter().find(|s| s.cell == id);
            let chosen = choose_pattern(cx, zoning.as_ref(), &region);
            let pattern = settings.and_then(|s| s.pattern).unwrap_or(chosen.pattern);
            // A zone level's parameters apply to its pattern only, not to a pattern the
            // cell's settings chose instead.
            let zone_params = if pattern == chosen.pattern {
                chosen.params.as_slice()
            } else {
                &[]
            };
            let mut p = match pattern {
                CellPatternChoice::Kelly(n) => preset(n),
                CellPatternChoice::Grid(g) => preset(g.traits_from()),
            };
            let cell_params = settings.map(|s| s.params.as_slice()).unwrap_or_default();
            let explicit = zone_params.iter().chain(cell_params).any(|q| {
                matches!(
                    q,
                    CellParam::LotSize(_)
                        | CellParam::BuildingHeight(_)
                        | CellParam::BuildingHint(_)
                )
            });
            for q in zone_params.iter().chain(cell_params) {
                q.apply(&mut p);
            }
            let seed = settings
                .and_then(|s| s.seed)
                .map_or(city_seed, |s| splitmix64(s ^ 0x0CE1_15EE_D000_0001));
            let input = SecondaryCell {
                id,
                region,
                filaments: filament_segments(cell),
            };
            let district = District {
                id,
                region: input.region.clone(),
                pattern,
                traits: polis_roads::secondary::CellTraits {
                    lot_size_m: p.lot_size_m,
                    building_height_m: p.building_height_m,
                    building_hint: p.building_hint,
                },
                traits_apply: cg.cell_traits || explicit,
                params: p.clone(),
                seed,
            };
            Ok(Ready {
                input,
                district,
                pattern,
                params: p,
                seed,
            })
        })
        .collect();
    // The growth, largest cells first (by an estimate from their area and parameters),
    // so that the pool's threads finish together; the results stay in cell order.
    type Grown = std::result::Result<Arc<SecondaryRoads>, Skip>;
    let grown: Vec<Result<Grown>> = map_costliest_first(
        &prepared,
        |prep| match prep {
            Ok(r) => estimated_work(&r.params, r.input.region.area()),
            Err(_) => 0.0,
        },
        |prep| {
            let ready = match prep {
                Ok(r) => r,
                // Not grown: `prepared` keeps the reason.
                Err(s) => return Ok(Err(s.clone())),
            };
            let Ready {
                input,
                pattern,
                params: p,
                seed,
                ..
            } = ready;
            let (id, pattern, seed) = (input.id, *pattern, *seed);
            let skip = |reason: String| Skip {
                stage: Stage::Roads,
                id,
                reason,
            };
            let grow = || -> Result<std::result::Result<SecondaryRoads, Skip>> {
                grow_cell(input, &maps, pattern, p, seed, &skip)
            };
            let roads = match (memo, shared) {
                (Some(m), Some(shared)) => {
                    let key = crate::editor::key::Key::new(0x6365_6C6C)
                        .key(shared)
                        .u64(id)
                        .u64(seed)
                        .region(&input.region)
                        .bytes(format!("{pattern:?}|{p:?}").as_bytes());
                    let mut key = key.u64(input.filaments.len() as u64);
                    for [a, b] in &input.filaments {
                        key = key.point(*a).point(*b);
                    }
                    m.grow(id, key, &grow)?
                }
                _ => grow()?.map(Arc::new),
            };
            Ok(roads)
        },
    );
    let secondary_s = started.elapsed().as_secs_f64();
    let mut cells = Vec::with_capacity(grown.len());
    let mut districts = Vec::with_capacity(grown.len());
    let mut skipped = Vec::new();
    let mut ungrown = Vec::new();
    for (prep, g) in prepared.into_iter().zip(grown) {
        match (prep, g?) {
            (Err(s), _) => skipped.push(s),
            (Ok(ready), Ok(r)) => {
                cells.push(r);
                districts.push(ready.district);
            }
            (Ok(ready), Err(s)) => {
                skipped.push(s);
                ungrown.push(ready.district);
            }
        }
    }
    let network = union(&primary, &cells)?;
    Ok((
        CitygenNetwork {
            primary,
            cells,
            districts,
            ungrown,
            network,
            skipped,
            secondary_s,
        },
        growth,
    ))
}

/// Grows one cell with its pattern and parameters; a cell too small or invalid for its
/// pattern is skipped with the reason.
fn grow_cell(
    input: &SecondaryCell,
    maps: &CellMaps<'_>,
    pattern: CellPatternChoice,
    p: &polis_roads::secondary::SecondaryParams,
    seed: u64,
    skip: &dyn Fn(String) -> Skip,
) -> Result<std::result::Result<SecondaryRoads, Skip>> {
    let id = input.id;
    match pattern {
        CellPatternChoice::Kelly(_) => {
            let result = with_kelly_worker(p, |g| g.grow(input, maps, seed));
            match result {
                Ok(r) => Ok(Ok(r)),
                Err(e) if e.is_skip() => Ok(Err(skip(e.to_string()))),
                Err(e) => Err(secondary_error(e)),
            }
        }
        CellPatternChoice::Grid(g) => match grow_grid(input, maps, g, p, seed) {
            Ok(r) => Ok(Ok(r)),
            Err(
                e @ (GridError::NoStart { .. }
                | GridError::InvalidCell(_)
                | GridError::TooManyLatticePoints { .. }),
            ) => Ok(Err(skip(format!("cell {id}: {e}")))),
            Err(e) => Err(Error::config("citygen.neighbourhood", e.to_string())),
        },
    }
}

std::thread_local! {
    /// This thread's Kelly growth worker: its snap grid, queues and scratch are kept from
    /// cell to cell (a pool thread grows many cells), so they are allocated once per
    /// thread rather than once per cell. A worker's output depends only on its parameters
    /// and inputs, never on the cells it grew before.
    static KELLY_WORKER: std::cell::RefCell<Option<SecondaryGrowth>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `f` on this thread's Kelly growth worker set to `params` (a fresh worker if the
/// thread's is in use).
fn with_kelly_worker<T>(
    params: &polis_roads::secondary::SecondaryParams,
    f: impl FnOnce(&mut SecondaryGrowth) -> std::result::Result<T, SecondaryError>,
) -> std::result::Result<T, SecondaryError> {
    KELLY_WORKER.with(|cell| match cell.try_borrow_mut() {
        Ok(mut slot) => {
            let worker = match slot.as_mut() {
                Some(w) => {
                    w.set_params(params.clone())?;
                    w
                }
                None => slot.insert(SecondaryGrowth::new(params.clone())?),
            };
            f(worker)
        }
        Err(_) => f(&mut SecondaryGrowth::new(params.clone())?),
    })
}

/// The Citygen road stage's memo of grown cells (the editor's): returns the cell's
/// secondary roads for input key `key`, growing them with `grow` only when the key is
/// new.
pub(crate) trait GrowthMemo: Send + Sync {
    /// The cell `id`'s roads for inputs `key`.
    ///
    /// # Errors
    /// `grow`'s.
    fn grow(
        &self,
        id: u64,
        key: crate::editor::key::Key,
        grow: &(dyn Fn() -> Result<std::result::Result<SecondaryRoads, Skip>> + Sync),
    ) -> Result<std::result::Result<Arc<SecondaryRoads>, Skip>>;
}

/// A city cell as the later stages see it: its stable id, region, pattern and the lot
/// and building traits of its parameters (Kelly §5.5.1).
#[derive(Debug, Clone, PartialEq)]
pub struct District {
    /// The cell's stable id.
    pub id: u64,
    /// Its region.
    pub region: polis_geom::PolygonWithHoles,
    /// Its pattern.
    pub pattern: CellPatternChoice,
    /// Lot size, building height and hint of its parameters.
    pub traits: polis_roads::secondary::CellTraits,
    /// Whether the traits reach the lot and building stages
    /// ([`CitygenConfig::cell_traits`], or set on this cell by a cell edit).
    pub traits_apply: bool,
    /// The growth parameters the cell was grown with (its pattern's preset in metres,
    /// the road width factor, then its [`CellSettings`] parameters).
    pub params: polis_roads::secondary::SecondaryParams,
    /// The growth seed (the city's, or the cell's own from [`CellSettings::seed`]).
    pub seed: u64,
}

/// The stable id of every cell of the primary decomposition: for a Kelly primary
/// network, a hash of the sorted ids of the primary roads along its outer boundary
/// (unchanged by any edit that does not touch those roads, even one that moves the
/// cell's corners); otherwise [`stable_cell_id`] (its boundary positions). Two cells
/// with the same key (degenerate) get the position hash mixed in, in cell order.
fn cell_ids(
    decomposition: &polis_cells::CellDecomposition,
    primary: &RoadNetwork,
    kelly_roads: Option<&[Option<u64>]>,
) -> Vec<u64> {
    let mut ids: Vec<u64> = decomposition
        .cells
        .iter()
        .map(|cell| {
            let Some(roads) = kelly_roads else {
                return stable_cell_id(cell);
            };
            let mut r: Vec<u64> = cell
                .boundary
                .edges
                .iter()
                .filter(|e| primary.contains_edge(**e))
                .filter_map(|e| roads.get(e.index()).copied().flatten())
                .collect();
            r.sort_unstable();
            r.dedup();
            if r.is_empty() {
                return stable_cell_id(cell);
            }
            r.iter().fold(0x0052_0AD5_u64, |h, &x| splitmix64(h ^ x))
        })
        .collect();
    let mut seen = std::collections::BTreeSet::new();
    for (id, cell) in ids.iter_mut().zip(&decomposition.cells) {
        if !seen.insert(*id) {
            *id = splitmix64(*id ^ stable_cell_id(cell));
            seen.insert(*id);
        }
    }
    ids
}

/// One cell grown by the grid road builders, in the shape of Kelly's cell graph
/// (boundary and filaments as highways, streets as streets), with the lot and building
/// traits of `traits` (the builders make roads only). Seeded by `seed` and the cell id.
fn grow_grid(
    cell: &SecondaryCell,
    maps: &CellMaps<'_>,
    pattern: GridPattern,
    traits: &polis_roads::secondary::SecondaryParams,
    seed: u64,
) -> std::result::Result<SecondaryRoads, GridError> {
    let grid_maps = GridMaps {
        water: maps.water,
        parks: maps.parks,
    };
    let mut params = pattern.params();
    if maps.step_m > 0.0 {
        params.legality_step_m = maps.step_m;
    }
    let grown = GridBuilderGrowth::new().grow(
        &cell.region,
        &cell.filaments,
        &grid_maps,
        &params,
        splitmix64(seed ^ splitmix64(cell.id)),
    )?;
    Ok(SecondaryRoads {
        cell: cell.id,
        network: grown.cell_graph(&cell.region, &cell.filaments)?,
        report: polis_roads::secondary::CellGrowthReport::default(),
        traits: polis_roads::secondary::CellTraits {
            lot_size_m: traits.lot_size_m,
            building_height_m: traits.building_height_m,
            building_hint: traits.building_hint,
        },
    })
}

fn secondary_error(e: SecondaryError) -> Error {
    Error::Roads(e.into())
}

/// The filament roads inside a cell, as segments.
fn filament_segments(cell: &Cell) -> Vec<[DVec2; 2]> {
    cell.filaments
        .iter()
        .flat_map(|f| f.points.windows(2).map(|w| [w[0], w[1]]))
        .collect()
}

/// A cell's pattern as the configuration chooses it (before per-cell settings).
#[derive(Debug, Clone, PartialEq)]
pub struct ChosenPattern {
    /// The pattern.
    pub pattern: CellPatternChoice,
    /// Parameter overrides of the zoning level that chose it (empty otherwise), applied
    /// on top of the pattern's preset.
    pub params: Vec<CellParam>,
    /// The zoning level (index into `citygen.zones.levels`) that chose it, if any.
    pub zone: Option<usize>,
}

/// Builds the configuration's zoning map, if any, checking that an image covers the
/// city.
///
/// # Errors
/// [`Error::Config`] for a map not covering the city; errors building the map.
pub fn zoning_of(cx: &StageContext<'_>) -> Result<Option<Zoning>> {
    let Some(z) = &cx.config.citygen.zones else {
        return Ok(None);
    };
    z.validate()?;
    z.check_extent(cx.config.size_m)?;
    let salt = cx.seed(Stage::Maps, 0x0204_50E5);
    Ok(Some(z.build(salt, cx.config.maps.max_image_pixels)?))
}

/// The pattern the configuration gives the cell with region `region`: the first
/// override inside it, else the level of the zoning map `zoning` (built by
/// [`zoning_of`]) by the map's rule, else the highest population band reached at the
/// mean of its outer ring's vertices, else [`CitygenConfig::neighbourhood`].
pub fn choose_pattern(
    cx: &StageContext<'_>,
    zoning: Option<&Zoning>,
    region: &polis_geom::PolygonWithHoles,
) -> ChosenPattern {
    let cg = &cx.config.citygen;
    let plain = |pattern| ChosenPattern {
        pattern,
        params: Vec::new(),
        zone: None,
    };
    for o in &cg.overrides {
        if region.contains(DVec2::new(o.at[0], o.at[1])) {
            return plain(o.neighbourhood);
        }
    }
    if let (Some(zones), Some(zoning)) = (&cg.zones, zoning)
        && let Some(i) = zoning.level_of(zones, region)
        && let Some(level) = zones.levels.get(i)
    {
        return ChosenPattern {
            pattern: level.neighbourhood,
            params: level.params.clone(),
            zone: Some(i),
        };
    }
    let pts = region.outer.points();
    let centre = pts.iter().copied().sum::<DVec2>() / pts.len().max(1) as f64;
    let density = cx.maps.inputs.population.sample(centre);
    plain(
        cg.by_population
            .iter()
            .filter(|b| density >= b.min_density)
            .max_by(|a, b| a.min_density.total_cmp(&b.min_density))
            .map_or(cg.neighbourhood, |b| b.neighbourhood),
    )
}

/// The pattern the configuration gives the cell with region `region` ([`choose_pattern`]
/// with the configuration's zoning map, built for this one call).
///
/// # Errors
/// As [`zoning_of`].
pub fn neighbourhood_of(
    cx: &StageContext<'_>,
    region: &polis_geom::PolygonWithHoles,
) -> Result<CellPatternChoice> {
    let zoning = zoning_of(cx)?;
    Ok(choose_pattern(cx, zoning.as_ref(), region).pattern)
}

/// Primary and secondary roads in one planar graph, cells joined in order.
fn union(primary: &RoadNetwork, cells: &[Arc<SecondaryRoads>]) -> Result<RoadNetwork> {
    let mut net = primary.clone();
    let snap = SnapOptions {
        snap_distance: 0.01,
    };
    for cell in cells {
        for (a, b, road) in cell.segments() {
            match net.insert_segment_with(a, b, *road, &snap, |_| Junction::default()) {
                Ok(_) | Err(polis_geom::GeomError::ZeroLengthEdge { .. }) => {}
                Err(e) => return Err(e.into()),
            }
        }
    }
    Ok(net)
}

/// The primary network of the configured source.
type KellyRoads = Option<Vec<Option<u64>>>;

/// The primary network of the configured source; for Kelly sources, the primary road id
/// of each edge too.
fn primary_network(
    cx: &StageContext<'_>,
) -> Result<(RoadNetwork, Option<polis_roads::GrowthReport>, KellyRoads)> {
    let (net, growth) = match &cx.config.citygen.primary {
        PrimarySource::Highways => {
            let mut config = cx.config.clone();
            config.roads.street_branch_probability = 0.0;
            let scx = StageContext {
                config: &config,
                maps: cx.maps,
            };
            let out = ParishMullerRoads::default().roads(&scx)?;
            (highways_of(&out.network)?, out.growth)
        }
        PrimarySource::Rings {
            centre,
            rings,
            spacing_m,
            spokes,
            piece_m,
        } => (
            rings_network(
                cx.config.size_m,
                DVec2::new(centre[0], centre[1]),
                *rings,
                *spacing_m,
                *spokes,
                *piece_m,
            )?,
            None,
        ),
        PrimarySource::Graph { path } => {
            let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
                path: path.clone(),
                source,
            })?;
            let net: RoadNetwork = serde_json::from_str(&text).map_err(|e| Error::Parse {
                source_name: path.display().to_string(),
                message: e.to_string(),
            })?;
            net.check_invariants()?;
            (net, None)
        }
        PrimarySource::Kelly { network } => {
            let (net, roads) = kelly::low_level(&network.0)?;
            return Ok((net, None, Some(roads)));
        }
        PrimarySource::KellyFile { path } => {
            let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
                path: path.clone(),
                source,
            })?;
            let (net, roads) = kelly::low_level(&kelly::kelly_from_text(cx, &text, path)?)?;
            return Ok((net, None, Some(roads)));
        }
    };
    Ok((net, growth, None))
}

/// The configured primary network as a Kelly network on `terrain`
/// ([`PrimaryNetwork::from_highways`](polis_roads::primary::PrimaryNetwork::from_highways)
/// of its highway edges, primary road spec), for the editor. P&M highways that enclose
/// no cell are closed by the map's edge first, as the road stage closes them.
///
/// # Errors
/// As [`citygen_network`]; a network the Kelly network cannot hold (outside the terrain).
pub fn kelly_network_of(
    cx: &StageContext<'_>,
    terrain: &polis_roads::primary::Terrain,
) -> Result<polis_roads::primary::PrimaryNetwork> {
    if let PrimarySource::Kelly { network } = &cx.config.citygen.primary {
        return Ok((*network.0).clone());
    }
    if let PrimarySource::KellyFile { path } = &cx.config.citygen.primary {
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            path: path.clone(),
            source,
        })?;
        return kelly::kelly_from_text(cx, &text, path);
    }
    let (mut net, _, _) = primary_network(cx)?;
    // The map's edge closes P&M highways that enclose nothing, as in the road stage, so
    // the editor's city has the cells `generate` gives the original configuration.
    if matches!(cx.config.citygen.primary, PrimarySource::Highways)
        && polis_cells::extract_with(&net, &cx.config.cells)?
            .cells
            .is_empty()
    {
        close_with_map_edge(&mut net, cx.config.size_m)?;
    }
    polis_roads::primary::PrimaryNetwork::from_highways(
        &net,
        terrain,
        polis_roads::primary::RoadSpec::default(),
    )
    .map_err(|e| Error::Roads(e.into()))
}

/// Adds the edge of the map's square (side `size_m`, centred on the origin) to `net` as
/// highways, split where roads meet it.
fn close_with_map_edge(net: &mut RoadNetwork, size_m: f64) -> Result<()> {
    let h = size_m * 0.5;
    let c = [(-h, -h), (h, -h), (h, h), (-h, h)].map(|(x, y)| DVec2::new(x, y));
    let road = Road {
        class: RoadClass::Highway,
        width: 16.0,
        bridge: false,
        tunnel: false,
        step: 0,
    };
    for i in 0..4 {
        let (a, b) = (c[i], c[(i + 1) % 4]);
        match net.insert_segment_with(a, b, road, &SnapOptions::default(), |_| Junction::default())
        {
            Ok(_) | Err(polis_geom::GeomError::ZeroLengthEdge { .. }) => {}
            Err(e) => return Err(e.into()),
        }
    }
    Ok(())
}

/// The highway edges of `net` and their junctions (same positions, new ids).
fn highways_of(net: &RoadNetwork) -> Result<RoadNetwork> {
    let mut out = RoadNetwork::new();
    let mut map = vec![None; net.node_bound()];
    for (_, u, v, road) in net.edges() {
        if road.class != RoadClass::Highway {
            continue;
        }
        let mut id = |n: polis_geom::NodeId, out: &mut RoadNetwork| -> Result<polis_geom::NodeId> {
            if let Some(Some(m)) = map.get(n.index()) {
                return Ok(*m);
            }
            let m = out.add_node(net.position(n)?, *net.node_payload(n)?)?;
            if let Some(slot) = map.get_mut(n.index()) {
                *slot = Some(m);
            }
            Ok(m)
        };
        let (a, b) = (id(u, &mut out)?, id(v, &mut out)?);
        out.add_edge(a, b, *road)?;
    }
    Ok(out)
}

/// Rings and spokes inside the square of side `size_m` centred on the origin, with the
/// square's edge as the outermost road.
fn rings_network(
    size_m: f64,
    centre: DVec2,
    rings: u32,
    spacing: f64,
    spokes: u32,
    piece: f64,
) -> Result<RoadNetwork> {
    let h = size_m * 0.5;
    let inside = |p: DVec2| p.x.abs() < h && p.y.abs() < h;
    let mut net = RoadNetwork::new();
    let snap = SnapOptions::default();
    let road = |width: f64| Road {
        class: RoadClass::Highway,
        width,
        bridge: false,
        tunnel: false,
        step: 0,
    };
    let add = |net: &mut RoadNetwork, a: DVec2, b: DVec2, w: f64| -> Result<()> {
        match net.insert_segment_with(a, b, road(w), &snap, |_| Junction::default()) {
            Ok(_) | Err(polis_geom::GeomError::ZeroLengthEdge { .. }) => Ok(()),
            Err(e) => Err(e.into()),
        }
    };
    let corners = [
        DVec2::new(-h, -h),
        DVec2::new(h, -h),
        DVec2::new(h, h),
        DVec2::new(-h, h),
    ];
    for i in 0..4 {
        add(&mut net, corners[i], corners[(i + 1) % 4], 16.0)?;
    }
    for k in 1..=rings {
        let r = spacing * k as f64;
        let n = ((std::f64::consts::TAU * r / piece).ceil() as usize).max(12);
        let at = |i: usize| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            centre + r * DVec2::new(a.cos(), a.sin())
        };
        for i in 0..n {
            let (a, b) = (at(i), at(i + 1));
            if inside(a) && inside(b) {
                add(&mut net, a, b, 20.0)?;
            }
        }
    }
    for s in 0..spokes {
        let a = std::f64::consts::TAU * (s as f64 + 0.5) / spokes as f64;
        let d = DVec2::new(a.cos(), a.sin());
        let start = centre + spacing * d;
        // To the square's edge.
        let tx = if d.x.abs() > 1e-12 {
            ((h.copysign(d.x)) - start.x) / d.x
        } else {
            f64::INFINITY
        };
        let ty = if d.y.abs() > 1e-12 {
            ((h.copysign(d.y)) - start.y) / d.y
        } else {
            f64::INFINITY
        };
        let t = tx.min(ty);
        if t.is_finite() && t > 0.0 && inside(start) {
            add(&mut net, start, start + d * t, 16.0)?;
        }
    }
    Ok(net)
}

#[cfg(test)]
pub(crate) mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::CityConfig;

    /// A small Citygen city: two rings and six spokes in 1.4 km (the editor's unit
    /// tests edit it too).
    pub(crate) fn small_rings() -> CityConfig {
        let mut c = CityConfig::preset("milan").unwrap();
        c.size_m = 1400.0;
        c.citygen.primary = PrimarySource::Rings {
            centre: [0.0, 0.0],
            rings: 2,
            spacing_m: 300.0,
            spokes: 6,
            piece_m: 150.0,
        };
        c
    }

    fn network(config: &CityConfig, threads: usize) -> CitygenNetwork {
        let maps = crate::CityMaps::build(&config.maps, 7).unwrap();
        let cx = StageContext {
            config,
            maps: &maps,
        };
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| citygen_network(&cx))
            .unwrap()
            .0
    }

    #[test]
    fn the_road_part_is_planar_joined_and_the_same_on_any_thread_count() {
        let config = small_rings();
        let a = network(&config, 1);
        let b = network(&config, 3);
        a.network.check_invariants().unwrap();
        assert!(
            a.cells.len() >= 8,
            "{} cells, {:?}",
            a.cells.len(),
            a.skipped
        );
        let json = |n: &CitygenNetwork| serde_json::to_string(&n.network).unwrap();
        assert_eq!(json(&a), json(&b));
        // Every cell's secondary roads are in the union, joined to the primary network:
        // every street component of the union reaches a highway.
        let streets: usize = a.cells.iter().map(|c| c.segments().count()).sum();
        let union_streets = a
            .network
            .edges()
            .filter(|e| e.3.class == RoadClass::Street)
            .count();
        assert!(union_streets >= streets && streets > 100);
        for comp in a.network.connected_components() {
            let highway = comp.iter().any(|&n| {
                a.network
                    .edges_at(n)
                    .unwrap()
                    .iter()
                    .any(|&e| a.network.edge_payload(e).unwrap().class == RoadClass::Highway)
            });
            assert!(highway, "a street component away from the primary network");
        }
    }

    #[test]
    fn cell_ids_are_stable_under_edits_elsewhere() {
        let config = small_rings();
        let a = network(&config, 1);
        // A different centre moves every cell; the same network gives the same ids.
        let b = network(&config, 2);
        let ids = |n: &CitygenNetwork| n.cells.iter().map(|c| c.cell).collect::<Vec<_>>();
        assert_eq!(ids(&a), ids(&b));
        let mut set = ids(&a);
        set.sort_unstable();
        set.dedup();
        assert_eq!(set.len(), a.cells.len(), "ids are unique");
    }

    #[test]
    fn overrides_and_population_bands_pick_neighbourhoods() {
        let mut config = small_rings();
        config.citygen.by_population.clear();
        config.citygen.neighbourhood = Neighbourhood::Industrial.into();
        config.citygen.overrides = vec![CellOverride {
            at: [0.0, 0.0],
            neighbourhood: Neighbourhood::Manhattan.into(),
        }];
        let maps = crate::CityMaps::build(&config.maps, 7).unwrap();
        let cx = StageContext {
            config: &config,
            maps: &maps,
        };
        let square = |c: f64, h: f64| {
            polis_geom::PolygonWithHoles::from(polis_geom::Polygon::new(vec![
                DVec2::new(c - h, -h),
                DVec2::new(c + h, -h),
                DVec2::new(c + h, h),
                DVec2::new(c - h, h),
            ]))
        };
        assert_eq!(
            neighbourhood_of(&cx, &square(0.0, 50.0)).unwrap(),
            Neighbourhood::Manhattan.into()
        );
        assert_eq!(
            neighbourhood_of(&cx, &square(500.0, 50.0)).unwrap(),
            Neighbourhood::Industrial.into()
        );
        config.citygen.by_population = vec![PopulationBand {
            min_density: -1.0,
            neighbourhood: Neighbourhood::Organic.into(),
        }];
        let cx = StageContext {
            config: &config,
            maps: &maps,
        };
        assert_eq!(
            neighbourhood_of(&cx, &square(500.0, 50.0)).unwrap(),
            Neighbourhood::Organic.into()
        );
    }

    #[test]
    fn the_default_mode_leaves_configurations_as_they_were() {
        let c = CityConfig::preset("default").unwrap();
        assert_eq!(c.road_mode, RoadMode::ParishMuller);
        let json = c.to_json();
        assert!(
            !json.contains("road_mode") && !json.contains("citygen"),
            "{json}"
        );
        for name in ["suburbia", "citygen", "milan"] {
            let c = CityConfig::preset(name).unwrap();
            assert_eq!(c.road_mode, RoadMode::Citygen, "{name}");
            let back = CityConfig::from_json(&c.to_json(), name).unwrap();
            assert_eq!(back, c);
        }
    }

    #[test]
    fn bad_citygen_options_are_config_errors() {
        let mut c = CityConfig::preset("milan").unwrap();
        c.citygen.unit_m = f64::NAN;
        assert!(matches!(c.validate(), Err(Error::Config { .. })));
        let mut c = small_rings();
        if let PrimarySource::Rings { rings, .. } = &mut c.citygen.primary {
            *rings = 0;
        }
        assert!(matches!(c.validate(), Err(Error::Config { .. })));
        let mut c = CityConfig::preset("milan").unwrap();
        c.citygen.primary = PrimarySource::Graph {
            path: "/no/such/graph.json".into(),
        };
        assert!(crate::generate(&c).is_err());
    }
}
