//! The statistics report of a [`City`] ([`polis_stats`]) and the real city each preset
//! imitates.

use polis_geom::{Aabb2, DVec2, Field};
use polis_roads::RoadClass;
use polis_stats::{
    BuildingInput, CityInput, CityReport, LotInput, StatsOptions, StreetClass, StreetGraph,
};

use crate::error::Result;
use crate::{City, CityConfig};

/// The reference city a configuration is compared with: [`CityConfig::imitates`], or
/// `None` when it names none. The presets name theirs (manhattan → Manhattan,
/// san_francisco → San Francisco, old_town → Rome, suburbia → Charlotte, paris → Paris,
/// default and citygen → the US/Canada regional mean).
pub fn reference_city_name(config: &CityConfig) -> Option<&str> {
    config.imitates.as_deref().filter(|s| !s.trim().is_empty())
}

/// Land (not water) area of the city square, m²: the square's area less the water map's
/// share, sampled at the centres of a grid of at most 200 × 200 cells (at least 5 m).
fn land_area(water: &dyn Field, size_m: f64) -> f64 {
    let cells = (size_m / 5.0).clamp(1.0, 200.0) as usize;
    let step = size_m / cells as f64;
    let h = size_m * 0.5;
    let mut wet = 0usize;
    for j in 0..cells {
        for i in 0..cells {
            let p = DVec2::new(-h + (i as f64 + 0.5) * step, -h + (j as f64 + 0.5) * step);
            if water.sample(p) >= 0.5 {
                wet += 1;
            }
        }
    }
    size_m * size_m * (1.0 - wet as f64 / (cells * cells) as f64)
}

/// The road network as polis-stats' [`StreetGraph`] (class, carriageway width and bridge
/// flag per edge), without elevation.
pub fn street_graph(roads: &polis_roads::RoadNetwork) -> StreetGraph {
    let mut g = StreetGraph::from_planar(roads, |r| {
        let class = match r.class {
            RoadClass::Highway => StreetClass::Highway,
            RoadClass::Street => StreetClass::Street,
        };
        (class, r.width)
    });
    // `from_planar` lists the edges in the graph's order: carry the bridge flags over.
    for (edge, (_, _, _, road)) in g.edges.iter_mut().zip(roads.edges()) {
        edge.bridge = road.bridge;
    }
    g
}

/// The street-network part of the report, fast: only the maps and the road stage of
/// `config` run (no blocks, lots or buildings; the street metrics depend on the roads
/// alone), measured over the city square and compared with the city the configuration
/// imitates. Its street metrics and realism rows are those of
/// [`City::statistics`] for the same configuration, except the intersection density,
/// which is per km² of the whole square here (not of land). The road stage is the one
/// the configuration's [`road_mode`](CityConfig::road_mode) names (Parish & Müller, or
/// Citygen's primary network and secondary growth per cell), as the pipeline runs it.
///
/// # Errors
/// [`Error::Config`](crate::Error::Config) for a bad configuration; the road stage's
/// error; [`Error::Stats`](crate::Error::Stats) for an unknown reference city.
pub fn road_statistics(config: &CityConfig) -> Result<CityReport> {
    use crate::stages::{CellStage, RoadStage, StageContext};
    config.validate()?;
    // The maps exactly as the pipeline builds them (salted with the maps stage's seed).
    let maps = crate::CityMaps::build(
        &config.maps,
        crate::seed::sub_seed(config.seed, crate::Stage::Maps, 0),
    )?;
    let cx = StageContext {
        config,
        maps: &maps,
    };
    let mut network = crate::citygen::ConfiguredRoads::default()
        .roads(&cx)?
        .network;
    // The fringe stubs the pipeline prunes after its cell stage (`crate::prune`).
    let cells = crate::stages::EberlyCells.cells(&network, &cx)?;
    let water = maps.has_water.then(|| maps.inputs.water.as_ref());
    crate::prune::prune_outer_stubs(&mut network, &cells, config.size_m, water)?;
    let streets = street_graph(&network);
    let h = config.size_m * 0.5;
    let mut input = CityInput::streets_only(&streets);
    input.bounds = Some(Aabb2::new(DVec2::splat(-h), DVec2::splat(h)));
    let report = polis_stats::report(&input, &StatsOptions::default())?;
    Ok(match reference_city_name(config) {
        Some(name) => report.compare_with(name)?,
        None => report,
    })
}

impl City {
    /// The statistics report ([`polis_stats::report`]) with the default options, compared
    /// with the city the configuration imitates ([`reference_city_name`]) when it names
    /// one.
    ///
    /// # Errors
    /// [`Error::Stats`](crate::Error::Stats): a reference city the table does not know,
    /// or layers the report cannot measure.
    pub fn statistics(&self) -> Result<CityReport> {
        self.statistics_with(&StatsOptions::default())
    }

    /// [`statistics`](Self::statistics) with explicit options.
    ///
    /// # Errors
    /// As [`statistics`](Self::statistics).
    pub fn statistics_with(&self, options: &StatsOptions) -> Result<CityReport> {
        let streets = street_graph(&self.roads).with_elevation(self.maps.inputs.elevation.as_ref());
        let blocks: Vec<_> = self.blocks.iter().map(|b| &b.polygon).collect();
        let lots: Vec<LotInput<'_>> = self
            .lots
            .iter()
            .map(|l| LotInput {
                polygon: &l.lot.polygon,
                street_edges: &l.lot.street_edges,
            })
            .collect();
        let buildings: Vec<BuildingInput<'_>> = self
            .buildings
            .iter()
            .map(|b| BuildingInput {
                footprint: &b.footprint,
                height_m: b.height,
                floors: b.floors,
                kind: b.kind.name(),
            })
            .collect();
        let size = self.config.size_m;
        let water = self.maps.inputs.water.as_ref();
        let input = CityInput {
            streets: &streets,
            blocks: &blocks,
            lots: &lots,
            buildings: &buildings,
            bounds: Some(Aabb2::new(
                DVec2::splat(-size * 0.5),
                DVec2::splat(size * 0.5),
            )),
            land_area_m2: Some(if self.maps.has_water {
                land_area(water, size)
            } else {
                size * size
            }),
            water: self.maps.has_water.then_some(water),
        };
        let mut report = polis_stats::report(&input, options)?;
        let w = self.stats.earthworks;
        report.earthworks = polis_stats::EarthworkMetrics {
            cut_m3: w.cut_m3,
            fill_m3: w.fill_m3,
            moved_length_m: w.moved_length_m,
            steepest_grade: w.steepest_grade,
        };
        Ok(match reference_city_name(&self.config) {
            Some(name) => report.compare_with(name)?,
            None => report,
        })
    }
}
