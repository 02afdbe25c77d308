//! [`Pipeline`]: the stages in order, per-cell and per-lot work in parallel, timings,
//! progress and the skip report.

use crate::clock::Instant;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use polis_geom::SpatialIndex;
use polis_geom::par::{self, prelude::*};

use polis_buildings::Building;
use polis_cells::Cell;
use polis_geom::{Aabb2, PolygonWithHoles};
use polis_lots::Block;
use polis_roads::RoadNetwork;

use crate::city::{City, CityLot, CityStats, SkipReport, StageTiming};
use crate::editor::key::Key;
use crate::error::{Error, Result};
use crate::scene::{SceneInputs, assemble};
use crate::stages::{
    BuildLot, BuildingStage, CellInput, CellLots, CellStage, Dress, DressBuilding, EberlyCells,
    FacadeStage, GrammarBuildings, KellyLots, LotInput, LotStage, RoadStage, Skip, Stage,
    StageContext, TiledFacades,
};
use crate::{CityConfig, CityMaps};

/// A progress callback: the stage and the fraction of it done, in [0, 1]. Called from
/// worker threads during parallel stages.
pub type Progress = dyn Fn(Stage, f64) + Send + Sync;

/// The city pipeline: one implementation per stage. `Pipeline::default()` runs the
/// stage crates; the `with_*` methods replace one stage.
///
/// ```no_run
/// use polis::{CityConfig, Pipeline};
///
/// let config = CityConfig::preset("paris")?;
/// let city = Pipeline::default()
///     .with_progress(|stage, done| eprintln!("{stage}: {:.0} %", done * 100.0))
///     .generate(&config)?;
/// println!("{} buildings", city.buildings.len());
/// # Ok::<(), polis::Error>(())
/// ```
pub struct Pipeline {
    roads: Box<dyn RoadStage>,
    cells: Box<dyn CellStage>,
    lots: Box<dyn LotStage>,
    buildings: Box<dyn BuildingStage>,
    facades: Box<dyn FacadeStage>,
    progress: Option<Arc<Progress>>,
    scene: bool,
    /// Scene parts of an earlier city to reuse (the editor's).
    reuse: Option<Arc<dyn crate::scene::SceneReuse + Send>>,
    /// Whole road-graph cells' buildings and skins of earlier runs (the editor's memo).
    cell_reuse: Option<Arc<dyn CellReuse>>,
    /// Terrains of earlier runs (the editor's memo).
    terrains: Option<Arc<dyn crate::scene::GroundReuse + Send>>,
}

impl Default for Pipeline {
    fn default() -> Self {
        Pipeline {
            roads: Box::new(crate::citygen::ConfiguredRoads::default()),
            cells: Box::new(EberlyCells),
            lots: Box::new(KellyLots),
            buildings: Box::new(GrammarBuildings::default()),
            facades: Box::new(TiledFacades),
            progress: None,
            scene: true,
            reuse: None,
            cell_reuse: None,
            terrains: None,
        }
    }
}

impl std::fmt::Debug for Pipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pipeline")
            .field("progress", &self.progress.is_some())
            .field("scene", &self.scene)
            .finish_non_exhaustive()
    }
}

/// Reports the fraction of a parallel loop done, at most about 100 times per chunk of
/// cells; the fraction is of the whole city's cells.
struct Ticker<'a> {
    stage: Stage,
    total: usize,
    done: AtomicUsize,
    span: Span,
    progress: Option<&'a Progress>,
}

impl Ticker<'_> {
    fn tick(&self) {
        let Some(p) = self.progress else { return };
        let d = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let step = (self.total / 100).max(1);
        if d.is_multiple_of(step) || d == self.total {
            let in_chunk = d as f64 / self.total.max(1) as f64;
            let cells = self.span.first as f64 + in_chunk * self.span.len as f64;
            let fraction = cells / self.span.total.max(1) as f64;
            // The stage reports its own end (1.0) once, after its last chunk.
            if fraction < 1.0 {
                p(self.stage, fraction);
            }
        }
    }
}

impl Pipeline {
    /// Replaces the road stage.
    pub fn with_roads(mut self, stage: impl RoadStage + 'static) -> Self {
        self.roads = Box::new(stage);
        self
    }

    /// Replaces the cell stage.
    pub fn with_cells(mut self, stage: impl CellStage + 'static) -> Self {
        self.cells = Box::new(stage);
        self
    }

    /// Replaces the block and lot stage.
    pub fn with_lots(mut self, stage: impl LotStage + 'static) -> Self {
        self.lots = Box::new(stage);
        self
    }

    /// Replaces the building stage.
    pub fn with_buildings(mut self, stage: impl BuildingStage + 'static) -> Self {
        self.buildings = Box::new(stage);
        self
    }

    /// Replaces the facade stage.
    pub fn with_facades(mut self, stage: impl FacadeStage + 'static) -> Self {
        self.facades = Box::new(stage);
        self
    }

    /// Sets the progress callback.
    pub fn with_progress(mut self, progress: impl Fn(Stage, f64) + Send + Sync + 'static) -> Self {
        self.progress = Some(Arc::new(progress));
        self
    }

    /// Reuses the leaves `reuse` hands back when assembling the scene (the editor's
    /// splice of an earlier scene).
    pub(crate) fn with_scene_reuse(
        mut self,
        reuse: Arc<dyn crate::scene::SceneReuse + Send>,
    ) -> Self {
        self.reuse = Some(reuse);
        self
    }

    /// Takes the buildings and skins of a road-graph cell from `reuse` where it holds
    /// them for the cell's inputs, and gives it those of the cells made (the editor's
    /// memo of whole cells).
    pub(crate) fn with_cell_reuse(mut self, reuse: Arc<dyn CellReuse>) -> Self {
        self.cell_reuse = Some(reuse);
        self
    }

    /// Takes the terrain from `terrains` where it holds one made on the same ground, and
    /// gives it the terrains made (the editor's memo).
    pub(crate) fn with_terrain_reuse(
        mut self,
        terrains: Arc<dyn crate::scene::GroundReuse + Send>,
    ) -> Self {
        self.terrains = Some(terrains);
        self
    }

    /// Whether to assemble the 3-D scene (default true). Without it the city keeps every
    /// layer and building mesh but `City::scene` is empty: for analyses and huge cities.
    pub fn with_scene(mut self, build: bool) -> Self {
        self.scene = build;
        self
    }

    /// Generates the city of `config`.
    ///
    /// # Errors
    /// [`Error::Config`] for a bad configuration, the failing stage's error otherwise.
    /// Degenerate cells and lots are skipped and listed in [`City::report`].
    pub fn generate(&self, config: &CityConfig) -> Result<City> {
        config.validate()?;
        // One chunk of every cell: the sink is not called, the city keeps it all.
        self.install(config, || {
            self.run(config, usize::MAX, &mut |_| Ok(()), true)
        })?
    }

    fn report(&self, stage: Stage, fraction: f64) {
        if let Some(p) = &self.progress {
            p(stage, fraction);
        }
    }

    fn ticker(&self, stage: Stage, total: usize, span: Span) -> Ticker<'_> {
        Ticker {
            stage,
            total,
            done: AtomicUsize::new(0),
            span,
            progress: self.progress.as_deref(),
        }
    }

    /// Generates a city without keeping its per-cell layers: the cells are processed in
    /// chunks of `cells_per_chunk`, and each chunk's blocks, lots, buildings and skins are
    /// handed to `sink` (in cell order) and then dropped. Memory stays at the road
    /// network, the cells and one chunk, so cities of millions of buildings fit.
    ///
    /// The chunks hold exactly what [`generate`](Self::generate) would have put in the
    /// city for those cells (sub-seeds come from stable ids, not from the chunking). The
    /// returned city has the maps, roads, cells, tile sets, statistics and report of the
    /// whole city; its per-cell layers and scene are empty.
    ///
    /// ```no_run
    /// use polis::{CityConfig, Pipeline};
    ///
    /// let config = CityConfig::preset("citygen")?;
    /// let mut triangles = 0;
    /// let city = Pipeline::default().stream(&config, 1024, |chunk| {
    ///     triangles += chunk.buildings.iter().map(|b| b.triangle_count()).sum::<usize>();
    ///     Ok(())
    /// })?;
    /// println!("{} buildings, {triangles} triangles", city.stats.buildings);
    /// # Ok::<(), polis::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`generate`](Self::generate), plus the first error `sink` returns (which stops
    /// the run); [`Error::Config`] if `cells_per_chunk` is 0.
    pub fn stream(
        &self,
        config: &CityConfig,
        cells_per_chunk: usize,
        mut sink: impl FnMut(CityChunk) -> Result<()> + Send,
    ) -> Result<City> {
        if cells_per_chunk == 0 {
            return Err(Error::config("cells_per_chunk", "must be at least 1"));
        }
        config.validate()?;
        self.install(config, || {
            self.run(config, cells_per_chunk, &mut sink, false)
        })?
    }

    /// Runs `job` on the configured thread pool.
    fn install<T: Send>(&self, config: &CityConfig, job: impl FnOnce() -> T + Send) -> Result<T> {
        match config.threads {
            Some(n) => par::install(n, job).map_err(|e| Error::Threads {
                threads: e.threads,
                message: e.message,
            }),
            None => Ok(job()),
        }
    }

    /// The pipeline: maps, roads and cells for the whole city, then blocks, lots,
    /// buildings and skins chunk by chunk, either into `sink` or (`keep`) into the
    /// returned city, whose scene is then assembled unless switched off.
    fn run(
        &self,
        config: &CityConfig,
        cells_per_chunk: usize,
        sink: &mut (dyn FnMut(CityChunk) -> Result<()> + Send),
        keep: bool,
    ) -> Result<City> {
        let started = Instant::now();
        let mut timings = Vec::new();
        let mut report = SkipReport {
            warnings: config.warnings(),
            ..SkipReport::default()
        };
        let mut clock = Instant::now();
        let lap = |stage: Stage, clock: &mut Instant| StageTiming {
            stage,
            time: restart(clock),
        };

        self.report(Stage::Maps, 0.0);
        let mut maps = CityMaps::build(
            &config.maps,
            crate::seed::sub_seed(config.seed, Stage::Maps, 0),
        )?;
        crate::citygen::paint_maps(&mut maps, &config.citygen.paint);
        let cx = StageContext {
            config,
            maps: &maps,
        };
        timings.push(lap(Stage::Maps, &mut clock));
        self.report(Stage::Maps, 1.0);

        // Road growth is serial; the facade tile sets are rasterised and the building
        // grammars prepared on the other thread meanwhile. Each stage's time is its own
        // elapsed time, so these overlap.
        self.report(Stage::Roads, 0.0);
        let (roads, prepared) = par::join(
            || timed(|| self.roads.roads(&cx)),
            || {
                let builder = timed(|| self.buildings.prepare(&cx))?;
                let dresser = timed(|| self.facades.prepare(&cx))?;
                Ok::<_, Error>((builder, dresser))
            },
        );
        let (roads, roads_time) = roads?;
        let ((builder, buildings_time), (dresser, facades_time)) = prepared?;
        let mut network = roads.network;
        report.skipped.extend(roads.skipped);
        timings.push(StageTiming {
            stage: Stage::Roads,
            time: roads_time,
        });
        timings.push(StageTiming {
            stage: Stage::Buildings,
            time: buildings_time,
        });
        timings.push(StageTiming {
            stage: Stage::Facades,
            time: facades_time,
        });
        self.report(Stage::Roads, 1.0);

        self.report(Stage::Cells, 0.0);
        clock = Instant::now();
        let cells = self.cells.cells(&network, &cx)?;
        let water = maps.has_water.then(|| maps.inputs.water.as_ref());
        crate::prune::prune_outer_stubs(&mut network, &cells, config.size_m, water)?;
        timings.push(lap(Stage::Cells, &mut clock));
        self.report(Stage::Cells, 1.0);
        self.report(Stage::Lots, 0.0);

        let mut counts = CityStats::default();
        let total = cells.cells.len();
        let mut kept = CityChunk::default();
        let ids = crate::citygen::block_ids(config, &cells);
        let districts = &roads.districts;
        // With a memo of whole cells: each city cell's box and digest, for the keys.
        let cell_memo = self.cell_reuse.as_deref().map(|reuse| CellMemoRun {
            reuse,
            districts: districts
                .iter()
                .map(|d| (d.region.outer.bbox(), reuse.district_key(d)))
                .collect(),
        });
        for (k, chunk) in cells.cells.chunks(cells_per_chunk).enumerate() {
            let span = Span {
                first: k * cells_per_chunk,
                len: chunk.len(),
                total,
            };
            let (out, chunk_timings, triangles) = self.chunk(
                chunk,
                ids.get(span.first..span.first + span.len)
                    .unwrap_or_default(),
                districts,
                span,
                &network,
                &cx,
                builder.as_ref(),
                dresser.as_ref(),
                cell_memo.as_ref(),
                &mut report,
            )?;
            timings.extend(chunk_timings);
            counts.blocks += out.blocks.len();
            counts.lots += out.lots.len();
            counts.buildings += out.buildings.len();
            counts.dressed_buildings += out.dresses.iter().filter(|d| d.is_some()).count();
            counts.building_triangles += triangles;
            if keep {
                kept.append(out);
            } else {
                sink(out)?;
            }
            clock = Instant::now();
        }
        drop(builder);
        let tile_sets = dresser.into_tile_sets();
        if total == 0 {
            // No chunk ran: the per-item stages are trivially done.
            for stage in [Stage::Lots, Stage::Buildings, Stage::Facades] {
                self.report(stage, 1.0);
            }
        }

        self.report(Stage::Scene, 0.0);
        // Roads graded into the land: the ground every later layer stands on.
        let graded = if config.scene.grade_roads && config.maps.elevation.is_some() {
            Some(polis_roads::grade_roads(
                &network,
                maps.inputs.elevation.as_ref(),
                &config.scene.road_grading,
            )?)
        } else {
            None
        };
        let earthworks = graded.as_ref().map(|g| g.earthworks).unwrap_or_default();
        let ground: &dyn polis_geom::Field = match &graded {
            Some(g) if g.moves_ground() => g,
            _ => maps.inputs.elevation.as_ref(),
        };
        let scene = if keep && self.scene {
            // Water bodies at their level over their bed, with the roads and blocks as
            // land: the bed is part of the ground everything stands on.
            // The water map's outlines read neither the roads nor the ground's grading.
            let outlines = self
                .terrains
                .as_deref()
                .map(|t| t as &dyn crate::scene::GroundReuse);
            let water =
                crate::water::Water::of_city(config, &maps, &network, &kept.blocks, outlines)?;
            let bed = water.as_ref().map(|w| w.bed(ground));
            let ground: &dyn polis_geom::Field = match &bed {
                Some(b) => b,
                None => ground,
            };
            assemble(&SceneInputs {
                ground,
                water: water.as_ref(),
                cut_in: graded.as_ref().filter(|g| g.moves_ground()).map(|g| {
                    g.cut_in(
                        crate::scene::CORRIDOR_CUT_M,
                        1.0,
                        crate::scene::CORRIDOR_CUT_TAPER_M,
                    )
                }),
                config,
                maps: &maps,
                network: &network,
                blocks: &kept.blocks,
                buildings: &kept.buildings,
                building_cells: &kept.building_cells,
                dresses: &kept.dresses,
                tile_sets: &tile_sets,
                green_spaces: &kept.green_spaces,
                reuse: self
                    .reuse
                    .as_deref()
                    .map(|r| r as &dyn crate::scene::SceneReuse),
                // The ground depends on the road graph where roads are graded into it.
                terrains: self
                    .terrains
                    .as_deref()
                    .filter(|_| !graded.as_ref().is_some_and(|g| g.moves_ground()))
                    .map(|t| t as &dyn crate::scene::GroundReuse),
            })?
        } else {
            polis_geom::Scene::new()
        };
        drop(graded);
        timings.push(lap(Stage::Scene, &mut clock));
        self.report(Stage::Scene, 1.0);

        let stats = CityStats {
            road_segments: network.edge_count(),
            junctions: network.node_count(),
            cells: cells.cells.len(),
            facade_tiles: tile_sets.iter().map(|s| s.tiles.len()).sum(),
            texture_bytes: tile_sets.iter().map(|s| s.gpu_bytes()).sum(),
            scene_triangles: scene.triangle_count(),
            timings: merge_timings(timings),
            wall_time: started.elapsed(),
            earthworks,
            ..counts
        };
        report.warnings.extend(empty_city_warnings(&stats));
        Ok(City {
            config: config.clone(),
            maps,
            roads: network,
            growth: roads.growth,
            cells,
            blocks: kept.blocks,
            lots: kept.lots,
            green_spaces: kept.green_spaces,
            lot_splits: kept.lot_splits,
            buildings: kept.buildings,
            building_cells: kept.building_cells,
            tile_sets,
            dresses: kept.dresses,
            scene,
            stats,
            report,
        })
    }

    /// Blocks, lots, buildings and skins of a run of cells; the wall time of each stage
    /// and the triangles of the buildings' meshes (a reused cell's counted when it was
    /// made: no pass over every building's meshes).
    #[allow(clippy::too_many_arguments)]
    fn chunk(
        &self,
        cells: &[Cell],
        ids: &[u64],
        districts: &[crate::citygen::District],
        span: Span,
        network: &RoadNetwork,
        cx: &StageContext<'_>,
        builder: &dyn BuildLot,
        dresser: &dyn DressBuilding,
        cell_memo: Option<&CellMemoRun<'_>>,
        report: &mut SkipReport,
    ) -> Result<(CityChunk, [StageTiming; 3], usize)> {
        let mut clock = Instant::now();
        let mut lap = |stage: Stage| StageTiming {
            stage,
            time: restart(&mut clock),
        };
        let mut out = CityChunk {
            cells: ids.to_vec(),
            ..CityChunk::default()
        };

        // Blocks and lots, cell by cell in parallel (the cell's input is made in its own
        // task); results in cell order.
        let ticker = self.ticker(Stage::Lots, cells.len(), span);
        let widest = network
            .edges()
            .map(|(_, _, _, r)| r.width)
            .fold(0.0, f64::max);
        type Made = (u64, CellLots, Option<(Key, Aabb2)>);
        let per_cell: Vec<Result<std::result::Result<Made, Skip>>> = cells
            .par_iter()
            .zip(ids)
            .map(|(cell, &id)| {
                let mut widths = Vec::new();
                for ring in std::iter::once(&cell.boundary).chain(cell.holes.iter()) {
                    for &e in &ring.edges {
                        widths.push(network.edge_payload(e)?.width);
                    }
                }
                // Every road near the cell (its rings, its filaments, roads of other
                // cells passing close by), for the lots to keep out of their corridors.
                let reach = cell.boundary.polygon.bbox().expanded(widest * 0.5);
                let mut nearby_roads = Vec::new();
                for e in network.edge_index().query_box(&reach) {
                    let (a, b) = network.endpoints(e)?;
                    let (pa, pb) = (network.position(a)?, network.position(b)?);
                    let road = network.edge_payload(e)?;
                    if road.tunnel {
                        // Underground: only its portals' mouths (a road width deep) are
                        // kept clear; lots may stand on the land above.
                        let mouth =
                            (pb - pa).normalize_or_zero() * road.width.min(0.5 * pa.distance(pb));
                        nearby_roads.push((pa, pa + mouth, road.width));
                        nearby_roads.push((pb - mouth, pb, road.width));
                    } else {
                        nearby_roads.push((pa, pb, road.width));
                    }
                }
                // Islands touching the boundary at a node are moved apart by a
                // micrometre so the region is a valid polygon with holes; a cell where
                // that fails is skipped and reported.
                let polygon = match cell.polygon_with_holes() {
                    Ok(p) => p,
                    Err(e) => {
                        return Ok(Err(Skip {
                            stage: Stage::Lots,
                            id,
                            reason: format!("cell {id}: {e}"),
                        }));
                    }
                };
                let input = CellInput {
                    cell,
                    region: polis_lots::Cell {
                        id,
                        polygon,
                        road_widths: widths,
                    },
                    seed: cx.seed(Stage::Lots, id),
                    nearby_roads,
                    lot_params: crate::citygen::lot_params_of(cx.config, districts, cell),
                };
                let lots = self.lots.lots(&input, cx)?;
                ticker.tick();
                let key = cell_memo.map(|m| m.key(&input, &lots));
                Ok(Ok((id, lots, key)))
            })
            .collect();
        // Exact room for what the cells made (growing by doubling would leave up to half
        // of each vector unused and copy it on the way).
        let made = per_cell
            .iter()
            .filter_map(|r| r.as_ref().ok()?.as_ref().ok());
        let (mut n_blocks, mut n_green, mut n_lots) = (0, 0, 0);
        for (_, lots, _) in made {
            n_blocks += lots.blocks.len();
            n_green += lots.green_spaces.len();
            n_lots += lots.lots.len();
        }
        out.blocks.reserve_exact(n_blocks);
        out.green_spaces.reserve_exact(n_green);
        out.lots.reserve_exact(n_lots);
        // Per cell with lots: its id, its lots' range in `out.lots`, and its key and box
        // for the memo of whole cells.
        type Run = (u64, std::ops::Range<usize>, Option<(Key, Aabb2)>);
        let mut runs: Vec<Run> = Vec::new();
        for result in per_cell {
            let (cell, lots, key) = match result? {
                Ok(done) => done,
                Err(skip) => {
                    report.skipped.push(skip);
                    continue;
                }
            };
            report.skipped.extend(lots.skipped);
            out.blocks.extend(lots.blocks);
            out.green_spaces.extend(lots.green_spaces);
            out.lot_splits.extend(lots.splits);
            let first = out.lots.len();
            for (i, lot) in lots.lots.into_iter().enumerate() {
                if i >= 1 << 24 || cell >= 1 << 40 {
                    report.skipped.push(Skip {
                        stage: Stage::Lots,
                        id: cell,
                        reason: format!("cell {cell}: more than 2^24 lots or 2^40 cells"),
                    });
                    break;
                }
                out.lots.push(CityLot {
                    id: cell << 24 | i as u64,
                    cell,
                    lot,
                });
            }
            runs.push((cell, first..out.lots.len(), key));
        }
        let lots_time = lap(Stage::Lots);
        self.report(Stage::Lots, span.done());

        // Buildings, lot by lot in parallel, but for the cells whose buildings and skins
        // the memo of whole cells holds for their inputs.
        let lod = cx.config.effective_lod();
        let overrides = &cx.config.citygen.lots;
        // The lots' ids are read only to match overrides (none: no set to build).
        let lot_ids: std::collections::BTreeSet<u64> = if overrides.is_empty() {
            std::collections::BTreeSet::new()
        } else {
            out.lots.iter().map(|l| l.id).collect()
        };
        let gone: Vec<bool> = match cell_memo {
            Some(_) => overrides
                .iter()
                .map(|o| !lot_ids.contains(&o.lot))
                .collect(),
            None => Vec::new(),
        };
        let keys: Vec<Option<Key>> = runs
            .iter()
            .map(|(cell, _, key)| {
                let (m, (key, bbox)) = (cell_memo?, (*key)?);
                Some(m.with_overrides(key, *cell, bbox, overrides, &gone))
            })
            .collect();
        let hits: Vec<Option<Arc<CellBuilt>>> = keys
            .iter()
            .map(|k| cell_memo.zip(*k).and_then(|(m, k)| m.reuse.get(k)))
            .collect();
        let todo: Vec<usize> = runs
            .iter()
            .zip(&hits)
            .filter(|(_, hit)| hit.is_none())
            .flat_map(|((_, range, _), _)| range.clone())
            .collect();
        let ticker = self.ticker(Stage::Buildings, todo.len(), span);
        // Per lot to build: the id its building was drawn under (none for a lot left
        // empty) and the building with its pinned style.
        type Built = (Option<u64>, Result<Option<(Arc<Building>, Option<String>)>>);
        // Each district's box once, not once per lot looked up in it.
        let district_boxes = crate::citygen::district_boxes(districts);
        let built: Vec<Built> = todo
            .par_iter()
            .map(|&i| {
                let Some(l) = out.lots.get(i) else {
                    return (None, Ok(None));
                };
                // Zoning, the cell's traits, the height map and the lot's overrides.
                let Some(plan) =
                    crate::citygen::lot_plan_in(cx, districts, &district_boxes, l, &lot_ids)
                else {
                    ticker.tick();
                    return (None, Ok(None));
                };
                let r = builder.build_shared(&LotInput {
                    id: plan.build_id,
                    lot: &l.lot,
                    kind: plan.kind,
                    max_height_m: plan.max_height_m,
                    lod,
                });
                ticker.tick();
                // A reseeded lot's building was drawn under another id: give it its own.
                let r = r.map(|b| {
                    b.map(|mut b| {
                        if b.id != l.id || b.lot_id != l.id {
                            let own = Arc::make_mut(&mut b);
                            own.id = l.id;
                            own.lot_id = l.id;
                        }
                        (b, plan.style)
                    })
                });
                (Some(plan.build_id), r)
            })
            .collect();
        let n_built = built.iter().filter(|b| matches!(b.1, Ok(Some(_)))).count()
            + hits
                .iter()
                .flatten()
                .map(|h| h.buildings.len())
                .sum::<usize>();
        out.buildings.reserve_exact(n_built);
        out.building_cells.reserve_exact(n_built);
        // Per cell made here: the ids its buildings were drawn under, its skips.
        let mut made: Vec<(Vec<u64>, Vec<Skip>)> = Vec::new();
        // Per building made here: its index in `out.buildings` and its pinned style.
        let mut fresh = Vec::new();
        let mut styles = Vec::new();
        // Per cell: its buildings' range in `out.buildings`.
        let mut spans = Vec::with_capacity(runs.len());
        let mut built = built.into_iter();
        for ((cell, range, _), hit) in runs.iter().zip(&hits) {
            let first = out.buildings.len();
            if let Some(h) = hit {
                out.buildings.extend(h.buildings.iter().cloned());
                out.building_cells
                    .extend(std::iter::repeat_n(*cell, h.buildings.len()));
                report.skipped.extend(h.building_skips.iter().cloned());
                spans.push(first..out.buildings.len());
                continue;
            }
            let (mut ids, mut skips) = (Vec::new(), Vec::new());
            for l in out.lots.get(range.clone()).unwrap_or_default() {
                let Some((build_id, b)) = built.next() else {
                    break;
                };
                ids.extend(build_id);
                match b {
                    Ok(Some((b, style))) => {
                        fresh.push(out.buildings.len());
                        out.buildings.push(b);
                        out.building_cells.push(l.cell);
                        styles.push(style);
                    }
                    Ok(None) => {}
                    Err(e) => skips.push(Skip {
                        stage: Stage::Buildings,
                        id: l.id,
                        reason: e.to_string(),
                    }),
                }
            }
            report.skipped.extend(skips.iter().cloned());
            made.push((ids, skips));
            spans.push(first..out.buildings.len());
        }
        let buildings_time = lap(Stage::Buildings);
        self.report(Stage::Buildings, span.done());

        // Facade skins, building by building (those of the cells made here).
        let ticker = self.ticker(Stage::Facades, fresh.len(), span);
        let dressed: Vec<Result<Option<_>>> = fresh
            .par_iter()
            .zip(&styles)
            .map(|(&i, style)| {
                let Some(b) = out.buildings.get(i) else {
                    return Ok(None);
                };
                let r = dresser.dress_shared(b, cx.seed(Stage::Facades, b.id), style.as_deref());
                ticker.tick();
                r
            })
            .collect();
        out.dresses.reserve_exact(out.buildings.len());
        let mut dressed = dressed.into_iter();
        let mut made = made.into_iter();
        let mut triangles = 0;
        for ((range, hit), key) in spans.into_iter().zip(&hits).zip(&keys) {
            if let Some(h) = hit {
                out.dresses.extend(h.dresses.iter().cloned());
                report.skipped.extend(h.facade_skips.iter().cloned());
                triangles += h.triangles;
                continue;
            }
            let cell_triangles = out
                .buildings
                .get(range.clone())
                .unwrap_or_default()
                .iter()
                .map(|b| b.triangle_count())
                .sum::<usize>();
            triangles += cell_triangles;
            let mut skips = Vec::new();
            for b in out.buildings.get(range.clone()).unwrap_or_default() {
                out.dresses.push(match dressed.next() {
                    Some(Ok(d)) => d,
                    Some(Err(e)) => {
                        skips.push(Skip {
                            stage: Stage::Facades,
                            id: b.id,
                            reason: e.to_string(),
                        });
                        None
                    }
                    None => None,
                });
            }
            report.skipped.extend(skips.iter().cloned());
            let (ids, building_skips) = made.next().unwrap_or_default();
            if let (Some(m), Some(key)) = (cell_memo, key) {
                let cell = CellBuilt {
                    buildings: out
                        .buildings
                        .get(range.clone())
                        .unwrap_or_default()
                        .to_vec(),
                    dresses: out.dresses.get(range).unwrap_or_default().to_vec(),
                    building_skips,
                    facade_skips: skips,
                    triangles: cell_triangles,
                };
                m.reuse.put(*key, cell, &ids);
            }
        }
        let facades_time = lap(Stage::Facades);
        self.report(Stage::Facades, span.done());
        Ok((out, [lots_time, buildings_time, facades_time], triangles))
    }
}

/// Runs `job` and measures its time.
fn timed<T>(job: impl FnOnce() -> Result<T>) -> Result<(T, std::time::Duration)> {
    let clock = Instant::now();
    job().map(|out| (out, clock.elapsed()))
}

/// The time since `clock`, restarting it.
fn restart(clock: &mut Instant) -> std::time::Duration {
    let t = clock.elapsed();
    *clock = Instant::now();
    t
}

/// Warnings for a city without roads or buildings, naming what to change.
fn empty_city_warnings(stats: &CityStats) -> Vec<String> {
    let mut out = Vec::new();
    if stats.road_segments == 0 {
        out.push(
            "no road was grown: check maps.population, maps.water, maps.elevation (slopes \
             above roads.max_slope are illegal) and roads.max_segments"
                .to_string(),
        );
    } else if stats.buildings == 0 {
        out.push(
            "no building was placed: check the lot sizes (lots), maps.parks, maps.max_height \
             and the skipped items"
                .to_string(),
        );
    }
    out
}

/// Sums the timings of each stage (chunks report theirs separately), in stage order.
fn merge_timings(timings: Vec<StageTiming>) -> Vec<StageTiming> {
    Stage::ALL
        .iter()
        .filter_map(|&stage| {
            let mut of = timings.iter().filter(|t| t.stage == stage).peekable();
            of.peek()?;
            Some(StageTiming {
                stage,
                time: of.map(|t| t.time).sum(),
            })
        })
        .collect()
}

/// Which cells a chunk covers, for progress reports.
#[derive(Debug, Clone, Copy)]
struct Span {
    first: usize,
    len: usize,
    total: usize,
}

impl Span {
    /// The fraction of the city's cells done once this chunk is (1 for the last chunk).
    fn done(self) -> f64 {
        if self.first + self.len >= self.total {
            1.0
        } else {
            (self.first + self.len) as f64 / self.total.max(1) as f64
        }
    }
}

/// The buildings and skins of one road-graph cell's lots, with what their stages
/// skipped: what the memo of whole cells ([`CellReuse`]) keeps.
#[derive(Debug, Default)]
pub(crate) struct CellBuilt {
    /// Its buildings, in lot order.
    pub buildings: Vec<Arc<Building>>,
    /// Their skins.
    pub dresses: Vec<Option<Arc<Dress>>>,
    /// Lots whose building failed, in lot order.
    pub building_skips: Vec<Skip>,
    /// Buildings whose skin failed, in building order.
    pub facade_skips: Vec<Skip>,
    /// Triangles of its buildings' meshes (counted once, when the cell is made).
    pub triangles: usize,
}

/// Whole road-graph cells of earlier runs (the editor's memo): a cell whose key is known
/// takes its buildings and skins from there instead of planning, building and dressing
/// each lot. The key must be a digest of everything they read, so a reused cell is bit
/// for bit what the stages would make again.
pub(crate) trait CellReuse: Send + Sync {
    /// The digest of city cell `d` as the lot plans read it (id, region, traits).
    fn district_key(&self, d: &crate::citygen::District) -> Key;
    /// The digest of what a cell's buildings and skins read of its input and of the
    /// configuration (the lot stage's input, the configuration but for the primary
    /// network, the per-cell settings and the lot overrides).
    fn cell_key(&self, input: &CellInput<'_>) -> Key;
    /// The cell made for `key` by an earlier run, if kept.
    fn get(&self, key: Key) -> Option<Arc<CellBuilt>>;
    /// Keeps `cell`, made for `key`; `build_ids` are the ids its lots' buildings were
    /// drawn under (lots left empty by their plan have none).
    fn put(&self, key: Key, cell: CellBuilt, build_ids: &[u64]);
}

/// A run's memo of whole cells with each city cell's box and digest.
struct CellMemoRun<'a> {
    reuse: &'a dyn CellReuse,
    districts: Vec<(Aabb2, Key)>,
}

impl CellMemoRun<'_> {
    /// The key of a cell's buildings and skins but for the lot overrides, and the box of
    /// its lots' corners and centroids: the cell's input with every city cell a lot plan
    /// could find one of its lots' centroids in (those whose box meets the box).
    fn key(&self, input: &CellInput<'_>, lots: &CellLots) -> (Key, Aabb2) {
        let mut bbox = Aabb2::EMPTY;
        for l in &lots.lots {
            for &p in l.polygon.points() {
                bbox.extend(p);
            }
            bbox.extend(l.polygon.centroid());
        }
        let mut key = self.reuse.cell_key(input);
        for (i, (b, k)) in self.districts.iter().enumerate() {
            if b.intersects(&bbox) {
                key = key.u64(i as u64).key(*k);
            }
        }
        (key, bbox)
    }

    /// `key` with the overrides a lot of cell `cell` (lots within `bbox`) can find: its
    /// lots' by id, and those whose lot is gone (`gone`, per override: no lot of the run
    /// has its id) anchored in the box; in configuration order, as the lot plans search
    /// them.
    fn with_overrides(
        &self,
        key: Key,
        cell: u64,
        bbox: Aabb2,
        overrides: &[crate::citygen::LotOverride],
        gone: &[bool],
    ) -> Key {
        let mut key = key.u64(overrides.len() as u64);
        for (i, (o, &gone)) in overrides.iter().zip(gone).enumerate() {
            let mine = if gone {
                bbox.contains(polis_geom::DVec2::new(o.at[0], o.at[1]))
            } else {
                o.lot >> 24 == cell
            };
            if mine {
                key = key.u64(i as u64).bytes(format!("{o:?}").as_bytes());
            }
        }
        key
    }
}

/// A run of cells with everything built on them, handed to the sink of
/// [`Pipeline::stream`]: the same data [`City`] keeps for those cells.
#[derive(Debug, Default)]
pub struct CityChunk {
    /// Ids of the cells, ascending.
    pub cells: Vec<u64>,
    /// Blocks, cell by cell (each behind an `Arc`, as in [`City::blocks`]).
    pub blocks: Vec<Arc<Block>>,
    /// Lots, cell by cell.
    pub lots: Vec<CityLot>,
    /// Green spaces inside blocks.
    pub green_spaces: Vec<PolygonWithHoles>,
    /// The lot subdivision's split lines with their block ids, cell by cell.
    pub lot_splits: Vec<(u64, Arc<polis_lots::SplitLine>)>,
    /// Buildings (one per built lot; `id` = the lot's id). Each is behind an `Arc`: a
    /// building an edit leaves alone is shared between the cities before and after it
    /// (and the editor's memo) rather than copied; `Arc::make_mut` gives a private copy
    /// to change.
    pub buildings: Vec<Arc<Building>>,
    /// Cell of each building (parallel to `buildings`).
    pub building_cells: Vec<u64>,
    /// Facade skin of each building (parallel to `buildings`), textured with the tile
    /// sets of the city [`Pipeline::stream`] returns.
    /// Each is behind an `Arc`, shared like [`buildings`](Self::buildings).
    pub dresses: Vec<Option<Arc<Dress>>>,
}

impl CityChunk {
    /// Moves `other`'s layers to the end of this chunk's.
    fn append(&mut self, mut other: CityChunk) {
        if self.cells.is_empty() && self.buildings.is_empty() && self.lots.is_empty() {
            *self = other;
            return;
        }
        self.cells.append(&mut other.cells);
        self.blocks.append(&mut other.blocks);
        self.lots.append(&mut other.lots);
        self.green_spaces.append(&mut other.green_spaces);
        self.lot_splits.append(&mut other.lot_splits);
        self.buildings.append(&mut other.buildings);
        self.building_cells.append(&mut other.building_cells);
        self.dresses.append(&mut other.dresses);
    }
}

/// Generates the city of `config` with the default pipeline.
///
/// # Errors
/// See [`Pipeline::generate`].
pub fn generate(config: &CityConfig) -> Result<City> {
    Pipeline::default().generate(config)
}
