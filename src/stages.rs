//! The swappable stages of the pipeline and their default implementations.
//!
//! | stage | trait | default | granularity |
//! |---|---|---|---|
//! | roads | [`RoadStage`] | [`ParishMullerRoads`] | the whole map |
//! | cells | [`CellStage`] | [`EberlyCells`] | the whole road graph |
//! | blocks and lots | [`LotStage`] | [`KellyLots`] | one cell (run in parallel) |
//! | buildings | [`BuildingStage`] | [`GrammarBuildings`] | one lot (run in parallel) |
//! | facades | [`FacadeStage`] | [`TiledFacades`] | one building (run in parallel) |
//!
//! Per-item stages receive their item's own seed (derived from the city seed and the
//! item's stable id), so they need no shared random generator and the parallel run
//! equals the serial one.

use std::sync::Arc;

use polis_buildings::{Building, BuildingGenerator, BuildingKind, FacadeRole};
use polis_cells::{Cell, CellDecomposition};
use polis_facades::{FacadeSpec, FaceRole, PreparedStyle, RasterOptions, TileQuad, TileSet};
use polis_geom::{DVec2, DVec3, PolygonWithHoles};
use polis_lots::{Block, Lot};
use polis_roads::{GlobalGoals, GrowthReport, RoadGenerator, RoadNetwork};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::config::{CityConfig, FacadeDetail};
use crate::error::{Error, Result};
use crate::maps::CityMaps;

/// The stages, in pipeline order (also the keys of timings and skip counts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stage {
    /// Building the input maps.
    Maps,
    /// The road network.
    Roads,
    /// Cells: the minimal cycle basis of the road graph.
    Cells,
    /// Blocks, footpaths and lots.
    Lots,
    /// Buildings.
    Buildings,
    /// Facade textures and skins.
    Facades,
    /// Assembling the 3-D scene.
    Scene,
}

impl Stage {
    /// Every stage in order.
    pub const ALL: [Stage; 7] = [
        Stage::Maps,
        Stage::Roads,
        Stage::Cells,
        Stage::Lots,
        Stage::Buildings,
        Stage::Facades,
        Stage::Scene,
    ];

    /// A lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Maps => "maps",
            Stage::Roads => "roads",
            Stage::Cells => "cells",
            Stage::Lots => "lots",
            Stage::Buildings => "buildings",
            Stage::Facades => "facades",
            Stage::Scene => "scene",
        }
    }
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What every stage sees: the configuration and the built maps.
#[derive(Debug, Clone, Copy)]
pub struct StageContext<'a> {
    /// The city configuration.
    pub config: &'a CityConfig,
    /// The input maps.
    pub maps: &'a CityMaps,
}

impl StageContext<'_> {
    /// The seed of `stage` for the item with stable id `id`.
    pub fn seed(&self, stage: Stage, id: u64) -> u64 {
        crate::seed::sub_seed(self.config.seed, stage, id)
    }
}

/// A degenerate item that was skipped, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Skip {
    /// The stage that skipped it.
    pub stage: Stage,
    /// The item's id (cell id, lot id, building id).
    pub id: u64,
    /// Why.
    pub reason: String,
}

// ---------------------------------------------------------------------------------------
// Roads.

/// The road network and what the generator reports about it.
#[derive(Debug, Clone)]
pub struct RoadsOutput {
    /// A planar road graph.
    pub network: RoadNetwork,
    /// The growth report of an L-system generator, if there is one.
    pub growth: Option<GrowthReport>,
    /// Items the road stage skipped (the Citygen mode's cells too small for secondary
    /// roads), for the city's skip report.
    pub skipped: Vec<Skip>,
    /// The Citygen mode's city cells with their traits, which reach the lot and
    /// building stages ([`District`](crate::citygen::District)); empty otherwise.
    pub districts: Vec<crate::citygen::District>,
}

/// Makes the road network of the whole map.
pub trait RoadStage: Send + Sync {
    /// The road network; it must be planar (every crossing a node).
    ///
    /// # Errors
    /// Any failure; a user stage wraps its own error in [`Error::Stage`].
    fn roads(&self, cx: &StageContext<'_>) -> Result<RoadsOutput>;
}

/// Parish & Müller's extended L-system (polis-roads), with optional custom goals.
#[derive(Clone, Default)]
pub struct ParishMullerRoads {
    /// Global goals replacing the defaults (a custom road pattern). Default: none.
    pub goals: Option<Arc<dyn GlobalGoals>>,
}

impl std::fmt::Debug for ParishMullerRoads {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParishMullerRoads")
            .field("custom_goals", &self.goals.is_some())
            .finish()
    }
}

impl RoadStage for ParishMullerRoads {
    fn roads(&self, cx: &StageContext<'_>) -> Result<RoadsOutput> {
        let params = cx.config.effective_road_params();
        // Legality is tested every few metres along every candidate: the water, park and
        // elevation maps are read through lazily filled lattices (polis-roads'
        // `LazyLattice`, the spacing of its procedural maps), not evaluated each time.
        let mut inputs = cx.maps.inputs.clone();
        let spacing = polis_roads::procedural_lattice_m(&params);
        let window = params.bounds();
        let cache = |map: Arc<dyn polis_geom::Field>| -> Result<Arc<dyn polis_geom::Field>> {
            Ok(Arc::new(polis_roads::LazyLattice::new(
                map, spacing, window,
            )?))
        };
        if cx.maps.has_water {
            inputs.water = cache(inputs.water)?;
        }
        if cx.maps.has_parks {
            inputs.parks = cache(inputs.parks)?;
        }
        inputs.elevation = cache(inputs.elevation)?;
        let mut generator = RoadGenerator::new(&params, &inputs)?;
        if let Some(goals) = &self.goals {
            generator = generator.with_goals(Arc::clone(goals));
        }
        let generated = generator.run()?;
        Ok(RoadsOutput {
            network: generated.network,
            growth: Some(generated.report),
            skipped: Vec::new(),
            districts: Vec::new(),
        })
    }
}

// ---------------------------------------------------------------------------------------
// Cells.

/// Finds the cells (enclosed regions) of the road graph.
pub trait CellStage: Send + Sync {
    /// The cells of `network`.
    ///
    /// # Errors
    /// Any failure (a non-planar graph for the default stage).
    fn cells(&self, network: &RoadNetwork, cx: &StageContext<'_>) -> Result<CellDecomposition>;
}

/// Eberly's minimal cycle basis (polis-cells) with the configuration's `cells` options,
/// on the roads at ground level: a tunnel ([`polis_roads::Road::tunnel`]) bounds no cell,
/// since the land above it is one piece (P&M §3.3); its portals stay junctions.
#[derive(Debug, Clone, Copy, Default)]
pub struct EberlyCells;

impl CellStage for EberlyCells {
    fn cells(&self, network: &RoadNetwork, cx: &StageContext<'_>) -> Result<CellDecomposition> {
        Ok(polis_cells::extract_where(
            network,
            &cx.config.cells,
            |road| !road.tunnel,
        )?)
    }
}

// ---------------------------------------------------------------------------------------
// Blocks and lots.

/// One cell as the lot stage receives it.
#[derive(Debug, Clone)]
pub struct CellInput<'a> {
    /// The cell (boundary and island rings with their road-graph ids, filaments).
    pub cell: &'a Cell,
    /// The cell's region with the width of the road along every ring edge (boundary
    /// edges first, then each hole's), as polis-lots takes it.
    pub region: polis_lots::Cell,
    /// This cell's seed.
    pub seed: u64,
    /// The roads near the cell as `(a, b, width)` segments, metres: its rings, its
    /// filaments (dead ends and connectors inside it, which the blocks are not cut
    /// along) and other cells' roads passing close by. No lot may enter their corridors
    /// (centreline ± width / 2).
    pub nearby_roads: Vec<(DVec2, DVec2, f64)>,
    /// Lot options of this cell replacing the configuration's `lots` (a Citygen cell's
    /// lot size); none: the configuration's.
    pub lot_params: Option<polis_lots::LotParams>,
}

/// What the lot stage makes of one cell.
#[derive(Debug, Clone, Default)]
pub struct CellLots {
    /// Blocks (the cell inset by the roads' half widths, with footpaths). Each is
    /// behind an `Arc`, so a stage that keeps its results (the editor's memo) hands them
    /// out again without copying them.
    pub blocks: Vec<Arc<Block>>,
    /// Lots, each inside one of the blocks (behind an `Arc`, as the blocks).
    pub lots: Vec<Arc<Lot>>,
    /// Green spaces (parks inside blocks).
    pub green_spaces: Vec<PolygonWithHoles>,
    /// Degenerate pieces skipped (counted in the city's report).
    pub skipped: Vec<Skip>,
    /// The lot subdivision's split lines, in order, with the id of the block each cut
    /// (a debug record: [`City::debug_map`](crate::City::debug_map)). Default: empty.
    pub splits: Vec<(u64, Arc<polis_lots::SplitLine>)>,
}

/// Turns one cell into blocks and lots. Called for every cell, possibly in parallel.
pub trait LotStage: Send + Sync {
    /// The blocks and lots of one cell.
    ///
    /// # Errors
    /// Failures that should stop the city; a degenerate cell should rather be reported in
    /// [`CellLots::skipped`].
    fn lots(&self, cell: &CellInput<'_>, cx: &StageContext<'_>) -> Result<CellLots>;
}

/// Kelly's blocks (straight-skeleton inset, footpaths) and lot subdivision (polis-lots).
#[derive(Debug, Clone, Copy, Default)]
pub struct KellyLots;

impl LotStage for KellyLots {
    fn lots(&self, input: &CellInput<'_>, cx: &StageContext<'_>) -> Result<CellLots> {
        let mut out = CellLots::default();
        let id = input.region.id;
        // Filaments (culs-de-sac, connectors) are cut into the cell as slits so the
        // blocks leave their corridors and lots face them; a cell the cut cannot make
        // valid keeps its plain region (the lots then stay clear of the filament).
        let slit = polis_lots::with_filaments(&input.region, &filament_roads(input))
            .ok()
            .and_then(|c| polis_lots::blocks(&c, &cx.config.blocks).ok());
        let blocks =
            match slit.map_or_else(|| polis_lots::blocks(&input.region, &cx.config.blocks), Ok) {
                Ok(b) => b,
                Err(e) => {
                    out.skipped.push(Skip {
                        stage: Stage::Lots,
                        id,
                        reason: format!("cell {id}: no blocks: {e}"),
                    });
                    return Ok(out);
                }
            };
        let mut rng = Pcg64Mcg::seed_from_u64(input.seed);
        let params = input.lot_params.as_ref().unwrap_or(&cx.config.lots);
        let mut subdivider = polis_lots::Subdivider::new();
        subdivider.record_splits(true);
        for block in blocks {
            match subdivider.subdivide_block(&block, params, &mut rng) {
                Ok(sub) => {
                    let id = block.id();
                    out.splits
                        .extend(sub.splits.into_iter().map(|s| (id, Arc::new(s))));
                    out.lots.extend(
                        sub.lots
                            .into_iter()
                            .filter(|lot| clear_of_roads(&lot.polygon, &input.nearby_roads))
                            .map(Arc::new),
                    );
                    out.green_spaces.extend(sub.green_spaces);
                    out.blocks.push(Arc::new(block));
                }
                Err(e) => out.skipped.push(Skip {
                    stage: Stage::Lots,
                    id: block.id(),
                    reason: format!("block {} of cell {id}: {e}", block.piece),
                }),
            }
        }
        Ok(out)
    }
}

/// The cell's filaments with the width of each segment (read from the roads near the
/// cell, which hold every road of the cell; a segment not found there gets the narrowest
/// ring road's width).
fn filament_roads(input: &CellInput<'_>) -> Vec<polis_lots::FilamentRoad> {
    let fallback = input
        .region
        .road_widths
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let fallback = if fallback.is_finite() { fallback } else { 1.0 };
    input
        .cell
        .filaments
        .iter()
        .map(|f| polis_lots::FilamentRoad {
            points: f.points.clone(),
            widths: f
                .points
                .windows(2)
                .map(|w| {
                    input
                        .nearby_roads
                        .iter()
                        .find(|&&(a, b, _)| (a == w[0] && b == w[1]) || (a == w[1] && b == w[0]))
                        .map_or(fallback, |r| r.2)
                })
                .collect(),
        })
        .collect()
}

/// Whether `lot` stays out of every road corridor of `roads` (`(a, b, width)`): its
/// distance to each centreline is at least half the road's width.
///
/// Kelly's blocks are the cell inset by the roads along its rings; a filament (a dead end
/// or connector growing into the cell) is no ring edge, so subdivision lays lots across
/// it, and where a wide road's edge vanishes in the weighted skeleton, or another
/// cell's road passes close by, the inset can come nearer than half its width. Such a
/// lot would put a building on the carriageway; it is dropped, and its land stays open
/// along the road.
///
/// Limitations: the whole lot is dropped rather than cut back to the corridor's edge.
pub fn clear_of_roads(lot: &polis_geom::Polygon, roads: &[(DVec2, DVec2, f64)]) -> bool {
    let bb = lot.bbox();
    roads.iter().all(|&(a, b, width)| {
        let half = width * 0.5;
        !polis_geom::Aabb2::new(a, b).expanded(half).intersects(&bb)
            || polis_geom::measure::polygon_segment_distance(lot, a, b) >= half
    })
}

// ---------------------------------------------------------------------------------------
// Buildings.

/// One lot as the building stage receives it.
#[derive(Debug, Clone, Copy)]
pub struct LotInput<'a> {
    /// The lot's stable id (also the building's).
    pub id: u64,
    /// The lot.
    pub lot: &'a Lot,
    /// The kind the zoning chose.
    pub kind: BuildingKind,
    /// The height limit, metres.
    pub max_height_m: f64,
    /// The level of detail asked for.
    pub lod: usize,
}

/// Builds the building of one lot; made once per city by [`BuildingStage::prepare`].
pub trait BuildLot: Send + Sync {
    /// The building on `lot`, or `None` for an empty lot.
    ///
    /// # Errors
    /// Failures of this lot: the pipeline skips the lot and reports the error.
    fn build(&self, lot: &LotInput<'_>) -> Result<Option<Building>>;

    /// [`build`](Self::build), the building behind an [`Arc`](std::sync::Arc) as the
    /// city keeps it ([`City::buildings`](crate::City::buildings)). The default wraps
    /// `build`'s result; a builder that keeps its results (the editor's memo) hands out
    /// a pointer to one instead of a copy.
    ///
    /// # Errors
    /// As [`build`](Self::build).
    fn build_shared(&self, lot: &LotInput<'_>) -> Result<Option<std::sync::Arc<Building>>> {
        self.build(lot).map(|b| b.map(std::sync::Arc::new))
    }
}

/// The building stage: prepares (grammars, templates) once per city, then builds lots,
/// possibly in parallel.
pub trait BuildingStage: Send + Sync {
    /// The per-lot builder for this city.
    ///
    /// # Errors
    /// Bad parameters or grammars.
    fn prepare<'a>(&'a self, cx: &StageContext<'a>) -> Result<Box<dyn BuildLot + 'a>>;
}

/// The stochastic parametric building grammars of polis-buildings.
#[derive(Debug, Clone, Default)]
pub struct GrammarBuildings {
    /// Grammars replacing the defaults of some kinds (written in the text grammar).
    pub grammars: Vec<(BuildingKind, polis_buildings::BuildingGrammar)>,
}

impl BuildingStage for GrammarBuildings {
    fn prepare<'a>(&'a self, cx: &StageContext<'a>) -> Result<Box<dyn BuildLot + 'a>> {
        let mut generator = BuildingGenerator::new(cx.config.effective_building_params())?;
        for (kind, grammar) in &self.grammars {
            generator.set_grammar(*kind, grammar.clone());
        }
        Ok(Box::new(generator))
    }
}

impl BuildLot for BuildingGenerator {
    fn build(&self, lot: &LotInput<'_>) -> Result<Option<Building>> {
        Ok(BuildingGenerator::build(
            self,
            lot.lot,
            lot.id,
            lot.kind,
            lot.max_height_m,
            lot.lod,
        )?)
    }
}

// ---------------------------------------------------------------------------------------
// Facades.

/// A textured quad of a building's skin: a rectangle of one facade face, textured with
/// one tile repeated a whole number of modules. It is stored in the face's own frame
/// (48 bytes); [`corners`](Self::corners) and [`uvs`](Self::uvs) give the geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkinQuad {
    /// The rectangle on the face, metres from its bottom-left corner: `[s0, t0, s1, t1]`,
    /// `s` along the bottom edge, `t` up the left edge.
    pub rect: [f64; 4],
    /// Tile repetitions across and up (whole modules), for a repeating sampler.
    pub repeats: [f32; 2],
    /// The tile of the style's tile set.
    pub tile: u32,
    /// The facade face (index into [`Building::facades`]) it covers.
    pub face: u32,
}

impl SkinQuad {
    /// The corners on `face` (which must be the building's face [`SkinQuad::face`]):
    /// bottom-left, bottom-right, top-right, top-left seen from outside, relative to the
    /// building's origin (glTF axes).
    pub fn corners(&self, face: &polis_buildings::FacadeFace) -> [DVec3; 4] {
        let [s0, t0, s1, t1] = self.rect;
        [
            face.at(s0, t0),
            face.at(s1, t0),
            face.at(s1, t1),
            face.at(s0, t1),
        ]
    }

    /// Texture coordinates of the corners, in the order of [`corners`](Self::corners)
    /// (glTF convention: the tile's top edge at `v = 0`, the quad's bottom at
    /// `v = ⌈repeats up⌉`).
    pub fn uvs(&self) -> [DVec2; 4] {
        let [s0, t0, s1, t1] = self.rect;
        let tile = TileQuad {
            rect: polis_geom::Aabb2::new(DVec2::new(s0, t0), DVec2::new(s1, t1)),
            tile: self.tile as usize,
            repeats: self.repeats.map(f64::from),
        };
        [(s0, t0), (s1, t0), (s1, t1), (s0, t1)].map(|(s, t)| DVec2::from(tile.uv_at(s, t)))
    }
}

/// A building's facade skin: quads textured with one style's tiles. In the scene they are
/// surfaces of their own, just in front of the walls of the building's closed mass.
#[derive(Debug, Clone, PartialEq)]
pub struct Dress {
    /// Index of the style in [`City::tile_sets`](crate::City::tile_sets).
    pub style: usize,
    /// The quads.
    pub quads: Vec<SkinQuad>,
}

/// Dresses buildings; made once per city by [`FacadeStage::prepare`].
pub trait DressBuilding: Send + Sync {
    /// The shared tile sets (one per style), indexed by [`Dress::style`].
    fn tile_sets(&self) -> &[TileSet];
    /// The tile sets, for the city to keep once every building is dressed. The default
    /// copies [`tile_sets`](Self::tile_sets); implementations that own them move them.
    fn into_tile_sets(self: Box<Self>) -> Vec<TileSet> {
        self.tile_sets().to_vec()
    }
    /// The skin of one building, or `None` to leave it plain.
    ///
    /// # Errors
    /// Failures of this building: the pipeline skips its skin and reports the error.
    fn dress(&self, building: &Building, seed: u64) -> Result<Option<Dress>>;

    /// The skin of `building` in the style named `style` (a lot override) instead of its
    /// kind's; `None` is [`dress`](Self::dress). Default: ignores the style.
    ///
    /// # Errors
    /// As [`dress`](Self::dress).
    fn dress_styled(
        &self,
        building: &Building,
        seed: u64,
        style: Option<&str>,
    ) -> Result<Option<Dress>> {
        let _ = style;
        self.dress(building, seed)
    }

    /// [`dress_styled`](Self::dress_styled), the skin behind an
    /// [`Arc`](std::sync::Arc) as the city keeps it ([`City::dresses`](crate::City::dresses)).
    /// The default wraps `dress_styled`'s result; a dresser that keeps its results (the
    /// editor's memo) hands out a pointer to one instead of a copy.
    ///
    /// # Errors
    /// As [`dress`](Self::dress).
    fn dress_shared(
        &self,
        building: &Building,
        seed: u64,
        style: Option<&str>,
    ) -> Result<Option<std::sync::Arc<Dress>>> {
        self.dress_styled(building, seed, style)
            .map(|d| d.map(std::sync::Arc::new))
    }
}

/// The facade stage: textures (once per city), then skins per building.
pub trait FacadeStage: Send + Sync {
    /// The dresser for this city.
    ///
    /// # Errors
    /// Bad styles or rasterisation options.
    fn prepare<'a>(&'a self, cx: &StageContext<'a>) -> Result<Box<dyn DressBuilding + 'a>>;
}

/// Parish & Müller's layered-grid facades (polis-facades), applied as Kelly's shared
/// building tiles: each style is rasterised once into a tile set; every wall face is
/// covered by quads whose UVs repeat the tiles a whole number of modules.
#[derive(Debug, Clone, Copy, Default)]
pub struct TiledFacades;

/// Per-thread scratch of [`Tiler::dress`]: reused so dressing a building allocates only
/// its result.
#[derive(Default)]
struct DressScratch {
    /// Each wall face and the range of its quads in `tiles` (`None`: not covered).
    faces: Vec<(usize, Option<std::ops::Range<usize>>)>,
    /// The tile quads of every face.
    tiles: Vec<TileQuad>,
    /// The walls (part and bottom edge) with a face the tiles do not cover.
    failed: Vec<(u32, [u64; 4])>,
}

thread_local! {
    static DRESS_SCRATCH: std::cell::RefCell<DressScratch> = std::cell::RefCell::default();
}

struct Tiler {
    styles: Vec<PreparedStyle>,
    sets: Vec<TileSet>,
    style_of: [Option<usize>; 6],
    detail: FacadeDetail,
}

impl FacadeStage for TiledFacades {
    fn prepare<'a>(&'a self, cx: &StageContext<'a>) -> Result<Box<dyn DressBuilding + 'a>> {
        tiler(cx).map(|t| t as Box<dyn DressBuilding + 'a>)
    }
}

/// The default facade stage's dresser, owning everything it holds (the editor keeps it
/// between edits).
pub(crate) fn tiler(cx: &StageContext<'_>) -> Result<Box<dyn DressBuilding + 'static>> {
    {
        let fc = &cx.config.facades;
        let opts = RasterOptions {
            pixels_per_metre: fc.pixels_per_metre,
            // Power-of-two tiles suit the glb's repeating, mipmapped samplers.
            power_of_two: true,
            ..RasterOptions::default()
        };
        let mut styles: Vec<PreparedStyle> = Vec::new();
        let mut sets = Vec::new();
        let mut style_of = [None; 6];
        if fc.enabled {
            // The kinds' styles, then styles pinned on lots (Citygen lot overrides).
            let pinned = cx
                .config
                .citygen
                .lots
                .iter()
                .filter_map(|o| o.style.as_deref());
            let kinds = BuildingKind::ALL
                .iter()
                .map(|&k| (Some(k), fc.style_of.get(k)));
            for (kind, name) in kinds.chain(pinned.map(|s| (None, s))) {
                if let Some(i) = styles.iter().position(|s| s.style().name == name) {
                    if let Some(kind) = kind {
                        style_of[kind.index()] = Some(i);
                    }
                    continue;
                }
                let style = fc
                    .styles
                    .iter()
                    .find(|s| s.name == name)
                    .cloned()
                    .or_else(|| polis_facades::builtin::builtin_style(name))
                    .ok_or_else(|| {
                        Error::config(
                            kind.map_or("citygen.lots.style".to_string(), |k| {
                                format!("facades.style_of.{}", k.name())
                            }),
                            format!(
                                "no style named {name:?}: neither built in ({}) nor in \
                                 facades.styles",
                                polis_facades::builtin::builtin_styles()
                                    .iter()
                                    .map(|s| s.name.as_str())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        )
                    })?;
                let prepared = PreparedStyle::new(style)?;
                sets.push(TileSet::build(&prepared, &opts)?);
                if let Some(kind) = kind {
                    style_of[kind.index()] = Some(styles.len());
                }
                styles.push(prepared);
            }
        }
        Ok(Box::new(Tiler {
            styles,
            sets,
            style_of,
            detail: fc.detail,
        }))
    }
}

impl DressBuilding for Tiler {
    fn tile_sets(&self) -> &[TileSet] {
        &self.sets
    }

    fn into_tile_sets(self: Box<Self>) -> Vec<TileSet> {
        self.sets
    }

    fn dress(&self, b: &Building, seed: u64) -> Result<Option<Dress>> {
        self.dress_styled(b, seed, None)
    }

    fn dress_styled(&self, b: &Building, seed: u64, name: Option<&str>) -> Result<Option<Dress>> {
        let style = match name {
            Some(name) => self.styles.iter().position(|s| s.style().name == name),
            None => self.style_of.get(b.kind.index()).copied().flatten(),
        };
        let Some(style) = style else {
            return Ok(None);
        };
        let (Some(prepared), Some(set)) = (self.styles.get(style), self.sets.get(style)) else {
            return Ok(None);
        };
        DRESS_SCRATCH.with(|scratch| {
            let mut scratch = scratch.borrow_mut();
            let DressScratch {
                faces,
                tiles,
                failed,
            } = &mut *scratch;
            faces.clear();
            tiles.clear();
            // Each wall face's tile quads (a range of `tiles`), or `None` where the tiles
            // do not cover it.
            for (k, face) in b.facades.iter().enumerate() {
                let role = match face.role {
                    FacadeRole::Wall => FaceRole::UpperFloors,
                    FacadeRole::GroundFloor => FaceRole::GroundFloor,
                    FacadeRole::Roof => continue,
                };
                if !(face.width > 0.5 && face.height > 0.5) {
                    faces.push((k, None));
                    continue;
                }
                let spec = FacadeSpec {
                    width_m: face.width,
                    height_m: face.height,
                    floors: Some(face.floors),
                    role,
                    seed: crate::seed::mix(seed, k as u64),
                };
                let first = tiles.len();
                match self.detail {
                    FacadeDetail::Full => tiles.extend(prepared.layout(&spec)?.tile_quads(set)),
                    FacadeDetail::Compact => tiles.extend(prepared.compact_tile_quad(&spec, set)?),
                }
                let covered: f64 = tiles
                    .get(first..)
                    .map_or(0.0, |c| c.iter().map(|q| q.rect.area()).sum());
                let area = face.width * face.height;
                let ok = (covered - area).abs() <= 1e-6 * area;
                faces.push((k, ok.then_some(first..tiles.len())));
            }
            // A wall is dressed all or nothing: the ground-floor band and the storeys
            // above share one plane of the mass, whose triangles the skin replaces.
            let wall_key = |k: usize| {
                b.facades.get(k).map(|f| {
                    let (p, u) = (f.origin, f.u);
                    (f.part, [p.x, p.z, u.x, u.z].map(f64::to_bits))
                })
            };
            failed.clear();
            failed.extend(
                faces
                    .iter()
                    .filter(|(_, range)| range.is_none())
                    .filter_map(|(k, _)| wall_key(*k)),
            );
            let kept = |(k, range): &(usize, Option<std::ops::Range<usize>>)| {
                let wall_failed =
                    !failed.is_empty() && wall_key(*k).is_some_and(|key| failed.contains(&key));
                range.clone().filter(|_| !wall_failed).map(|r| (*k, r))
            };
            let count: usize = faces.iter().filter_map(kept).map(|(_, r)| r.len()).sum();
            if count == 0 {
                return Ok(None);
            }
            let mut quads = Vec::with_capacity(count);
            for (k, range) in faces.iter().filter_map(kept) {
                // Buildings have far fewer than 2^32 faces and tiles.
                let Ok(face) = u32::try_from(k) else { continue };
                for q in tiles.get(range).unwrap_or_default() {
                    let Ok(tile) = u32::try_from(q.tile) else {
                        continue;
                    };
                    quads.push(SkinQuad {
                        rect: [q.rect.min.x, q.rect.min.y, q.rect.max.x, q.rect.max.y],
                        repeats: q.repeats.map(|r| r as f32),
                        tile,
                        face,
                    });
                }
            }
            Ok(Some(Dress { style, quads }))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_buildings::FacadeFace;
    use polis_geom::Aabb2;

    /// A skin quad stored in its face's frame gives the corners on the face and the
    /// texture coordinates `TileQuad::uv_at` gives there.
    #[test]
    fn skin_quads_place_and_texture_like_their_tile_quads() {
        let bl = DVec3::new(2.0, 0.0, -1.0);
        let (u, v) = (DVec3::new(0.6, 0.0, 0.8), DVec3::Y);
        let (width, height) = (10.0, 7.5);
        let face = FacadeFace {
            origin: bl,
            u,
            v,
            width,
            height,
            floors: 2,
            part: 0,
            role: FacadeRole::Wall,
        };
        let tile = TileQuad {
            rect: Aabb2::new(DVec2::new(1.0, 0.5), DVec2::new(9.0, 7.5)),
            tile: 3,
            repeats: [4.0, 2.5],
        };
        let r = tile.rect;
        let skin = SkinQuad {
            rect: [r.min.x, r.min.y, r.max.x, r.max.y],
            repeats: tile.repeats.map(|x| x as f32),
            tile: 3,
            face: 0,
        };
        let st = [
            (r.min.x, r.min.y),
            (r.max.x, r.min.y),
            (r.max.x, r.max.y),
            (r.min.x, r.max.y),
        ];
        for ((corner, uv), (s, t)) in skin.corners(&face).iter().zip(skin.uvs()).zip(st) {
            let want = bl + u * s + v * t;
            assert!((*corner - want).length() < 1e-12, "{corner} vs {want}");
            let [wu, wv] = tile.uv_at(s, t);
            assert!(
                (uv - DVec2::new(wu, wv)).length() < 1e-6,
                "{uv} vs ({wu}, {wv})"
            );
        }
    }
}
