//! [`Pipeline`]: the stages in order, per-cell and per-lot work in parallel, timings,
//! progress and the skip report.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use polis_geom::Field;
use rayon::prelude::*;

use crate::city::{City, CityLot, CityStats, SkipReport, StageTiming};
use crate::error::{Error, Result};
use crate::scene::{SceneInputs, assemble};
use crate::stages::{
    BuildingStage, CellInput, CellStage, EberlyCells, FacadeStage, GrammarBuildings, KellyLots,
    LotInput, LotStage, ParishMullerRoads, RoadStage, Skip, Stage, StageContext, TiledFacades,
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
}

impl Default for Pipeline {
    fn default() -> Self {
        Pipeline {
            roads: Box::new(ParishMullerRoads::default()),
            cells: Box::new(EberlyCells),
            lots: Box::new(KellyLots),
            buildings: Box::new(GrammarBuildings::default()),
            facades: Box::new(TiledFacades),
            progress: None,
            scene: true,
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

/// Reports the fraction of a parallel loop done, at most about 100 times.
struct Ticker<'a> {
    stage: Stage,
    total: usize,
    done: AtomicUsize,
    progress: Option<&'a Progress>,
}

impl Ticker<'_> {
    fn tick(&self) {
        let Some(p) = self.progress else { return };
        let d = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let step = (self.total / 100).max(1);
        if d.is_multiple_of(step) || d == self.total {
            p(self.stage, d as f64 / self.total.max(1) as f64);
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
        match config.threads {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| Error::Threads {
                    threads: n,
                    message: e.to_string(),
                })?
                .install(|| self.run(config)),
            None => self.run(config),
        }
    }

    fn report(&self, stage: Stage, fraction: f64) {
        if let Some(p) = &self.progress {
            p(stage, fraction);
        }
    }

    fn ticker(&self, stage: Stage, total: usize) -> Ticker<'_> {
        Ticker {
            stage,
            total,
            done: AtomicUsize::new(0),
            progress: self.progress.as_deref(),
        }
    }

    fn run(&self, config: &CityConfig) -> Result<City> {
        let mut timings = Vec::new();
        let mut report = SkipReport::default();
        let mut clock = Instant::now();
        let mut lap = |stage: Stage, timings: &mut Vec<StageTiming>| {
            timings.push(StageTiming {
                stage,
                time: clock.elapsed(),
            });
            clock = Instant::now();
            self.report(stage, 1.0);
        };

        self.report(Stage::Maps, 0.0);
        let maps = CityMaps::build(
            &config.maps,
            crate::seed::sub_seed(config.seed, Stage::Maps, 0),
        )?;
        let cx = StageContext {
            config,
            maps: &maps,
        };
        lap(Stage::Maps, &mut timings);

        self.report(Stage::Roads, 0.0);
        let roads = self.roads.roads(&cx)?;
        let network = roads.network;
        lap(Stage::Roads, &mut timings);

        self.report(Stage::Cells, 0.0);
        let cells = self.cells.cells(&network, &cx)?;
        lap(Stage::Cells, &mut timings);

        // Blocks and lots, cell by cell in parallel; results in cell order.
        self.report(Stage::Lots, 0.0);
        let mut inputs = Vec::with_capacity(cells.cells.len());
        for cell in &cells.cells {
            let id = cell.id.index() as u64;
            let mut widths = Vec::new();
            for ring in std::iter::once(&cell.boundary).chain(cell.holes.iter()) {
                for &e in &ring.edges {
                    widths.push(network.edge_payload(e)?.width);
                }
            }
            // Islands touching the boundary at a node are moved apart by a micrometre
            // so the region is a valid polygon with holes; a cell where that fails is
            // skipped and reported.
            let polygon = match cell.polygon_with_holes() {
                Ok(p) => p,
                Err(e) => {
                    report.skipped.push(Skip {
                        stage: Stage::Lots,
                        id,
                        reason: format!("cell {id}: {e}"),
                    });
                    continue;
                }
            };
            inputs.push(CellInput {
                cell,
                region: polis_lots::Cell {
                    id,
                    polygon,
                    road_widths: widths,
                },
                seed: cx.seed(Stage::Lots, id),
            });
        }
        let ticker = self.ticker(Stage::Lots, inputs.len());
        let per_cell: Vec<Result<_>> = inputs
            .par_iter()
            .map(|input| {
                let r = self.lots.lots(input, &cx);
                ticker.tick();
                r
            })
            .collect();
        let mut blocks = Vec::new();
        let mut lots = Vec::new();
        let mut green_spaces = Vec::new();
        for (input, result) in inputs.iter().zip(per_cell) {
            let out = result?;
            let cell = input.region.id;
            report.skipped.extend(out.skipped);
            blocks.extend(out.blocks);
            green_spaces.extend(out.green_spaces);
            for (i, lot) in out.lots.into_iter().enumerate() {
                if i >= 1 << 24 || cell >= 1 << 40 {
                    report.skipped.push(Skip {
                        stage: Stage::Lots,
                        id: cell,
                        reason: format!("cell {cell}: more than 2^24 lots or 2^40 cells"),
                    });
                    break;
                }
                lots.push(CityLot {
                    id: cell << 24 | i as u64,
                    cell,
                    lot,
                });
            }
        }
        drop(inputs);
        lap(Stage::Lots, &mut timings);

        // Buildings, lot by lot in parallel.
        self.report(Stage::Buildings, 0.0);
        let builder = self.buildings.prepare(&cx)?;
        let lod = config.effective_lod();
        let ticker = self.ticker(Stage::Buildings, lots.len());
        let built: Vec<Result<Option<_>>> = lots
            .par_iter()
            .map(|l| {
                let c = l.lot.polygon.centroid();
                let (mut kind, mut max_height_m) =
                    config.zoning.zone(maps.inputs.population.sample(c));
                if let Some(z) = &maps.zoning {
                    kind = polis_buildings::kind_from_zoning(z.as_ref(), c);
                }
                if let Some(h) = &maps.max_height {
                    let v = h.sample(c);
                    if v.is_finite() && v > 0.0 {
                        max_height_m = v;
                    }
                }
                let r = builder.build(&LotInput {
                    id: l.id,
                    lot: &l.lot,
                    kind,
                    max_height_m,
                    lod,
                });
                ticker.tick();
                r
            })
            .collect();
        let mut buildings = Vec::new();
        let mut building_cells = Vec::new();
        for (l, b) in lots.iter().zip(built) {
            match b {
                Ok(Some(b)) => {
                    buildings.push(b);
                    building_cells.push(l.cell);
                }
                Ok(None) => {}
                Err(e) => report.skipped.push(Skip {
                    stage: Stage::Buildings,
                    id: l.id,
                    reason: e.to_string(),
                }),
            }
        }
        drop(builder);
        lap(Stage::Buildings, &mut timings);

        // Facades: tile sets once, skins building by building.
        self.report(Stage::Facades, 0.0);
        let dresser = self.facades.prepare(&cx)?;
        let ticker = self.ticker(Stage::Facades, buildings.len());
        let dressed: Vec<Result<Option<_>>> = buildings
            .par_iter()
            .map(|b| {
                let r = dresser.dress(b, cx.seed(Stage::Facades, b.id));
                ticker.tick();
                r
            })
            .collect();
        let mut dresses = Vec::with_capacity(buildings.len());
        for (b, d) in buildings.iter().zip(dressed) {
            dresses.push(match d {
                Ok(d) => d,
                Err(e) => {
                    report.skipped.push(Skip {
                        stage: Stage::Facades,
                        id: b.id,
                        reason: e.to_string(),
                    });
                    None
                }
            });
        }
        let tile_sets = dresser.tile_sets().to_vec();
        drop(dresser);
        lap(Stage::Facades, &mut timings);

        self.report(Stage::Scene, 0.0);
        let scene = if self.scene {
            assemble(&SceneInputs {
                config,
                maps: &maps,
                network: &network,
                blocks: &blocks,
                buildings: &buildings,
                building_cells: &building_cells,
                dresses: &dresses,
                tile_sets: &tile_sets,
            })?
        } else {
            polis_geom::Scene::new()
        };
        lap(Stage::Scene, &mut timings);

        let stats = CityStats {
            road_segments: network.edge_count(),
            junctions: network.node_count(),
            cells: cells.cells.len(),
            blocks: blocks.len(),
            lots: lots.len(),
            buildings: buildings.len(),
            dressed_buildings: dresses.iter().filter(|d| d.is_some()).count(),
            facade_tiles: tile_sets.iter().map(|s| s.tiles.len()).sum(),
            texture_bytes: tile_sets.iter().map(|s| s.gpu_bytes()).sum(),
            building_triangles: buildings.iter().map(|b| b.triangle_count()).sum(),
            scene_triangles: scene.triangle_count(),
            timings,
        };
        Ok(City {
            config: config.clone(),
            maps,
            roads: network,
            growth: roads.growth,
            cells,
            blocks,
            lots,
            green_spaces,
            buildings,
            building_cells,
            tile_sets,
            dresses,
            scene,
            stats,
            report,
        })
    }
}

/// Generates the city of `config` with the default pipeline.
///
/// # Errors
/// See [`Pipeline::generate`].
pub fn generate(config: &CityConfig) -> Result<City> {
    Pipeline::default().generate(config)
}
