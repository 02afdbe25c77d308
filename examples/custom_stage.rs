//! A custom road stage plugged into the pipeline: the researcher's way in.
//!
//! ```text
//! cargo run --release --example custom_stage -- [SPACING_M] [OUT_DIR]
//! ```
//!
//! Arguments are parsed by clap (`--help` lists them).
//!
//! `GridRoads` replaces Parish & Müller's L-system with a jittered grid: streets every
//! `spacing_m` metres, every `highway_every`-th line a highway, each junction moved by a
//! seeded random offset of at most `jitter` × spacing (so the city is not a perfect
//! chessboard), and no road where the water map is wet. Everything after the roads —
//! cells, blocks, lots, buildings, facades, the scene — is the default pipeline, so the
//! output is a full city on a grid.
//!
//! What a stage must guarantee: the network is planar (every crossing a node). A grid
//! whose junctions move by less than a third of the spacing stays planar, since every
//! road joins neighbours only and neighbouring quadrilaterals stay simple; the example
//! checks `check_invariants()` before returning, as a stage in a study should.

use std::path::PathBuf;

use clap::Parser;
use polis::geom::DVec2;
use polis::lots::rand::{RngExt, SeedableRng};
use polis::lots::rand_pcg::Pcg64Mcg;
use polis::prelude::*;
use polis::roads::{Junction, Road, RoadClass, RoadNetwork};
use polis::stages::{RoadStage, RoadsOutput, StageContext};

#[allow(dead_code)]
#[path = "common/cli.rs"]
mod cli;

/// A jittered grid of streets and highways.
#[derive(Debug, Clone, Copy)]
struct GridRoads {
    /// Distance between parallel streets, metres.
    spacing_m: f64,
    /// Every this many lines is a highway (0: none).
    highway_every: usize,
    /// Largest junction offset as a fraction of the spacing, below 1/3.
    jitter: f64,
}

impl RoadStage for GridRoads {
    fn roads(&self, cx: &StageContext<'_>) -> polis::Result<RoadsOutput> {
        let stage_error = |msg: String| polis::Error::Stage {
            stage: Stage::Roads,
            source: msg.into(),
        };
        if !(self.spacing_m.is_finite() && self.spacing_m >= 20.0) {
            return Err(stage_error(format!(
                "spacing {} m; give at least 20 m",
                self.spacing_m
            )));
        }
        if !(0.0..1.0 / 3.0).contains(&self.jitter) {
            return Err(stage_error(format!(
                "jitter {}; give [0, 1/3)",
                self.jitter
            )));
        }
        let half = cx.config.size_m * 0.5;
        let n = (cx.config.size_m / self.spacing_m).floor() as usize;
        if n < 1 {
            return Err(stage_error("the map is smaller than one block".into()));
        }
        // One seeded generator for the whole stage: the grid is the same for the same
        // city seed, whatever the thread count.
        let mut rng = Pcg64Mcg::seed_from_u64(cx.seed(Stage::Roads, 0));
        let origin = -half + 0.5 * (cx.config.size_m - n as f64 * self.spacing_m);
        let water = &cx.maps.inputs.water;
        let wet = |p: DVec2| cx.maps.has_water && water.sample(p) >= 0.5;

        let mut network = RoadNetwork::new();
        let mut ids = vec![vec![None; n + 1]; n + 1];
        for (i, row) in ids.iter_mut().enumerate() {
            for (j, id) in row.iter_mut().enumerate() {
                let jitter = DVec2::new(rng.random_range(-1.0..=1.0), rng.random_range(-1.0..=1.0))
                    * (self.jitter * self.spacing_m);
                let p = DVec2::new(
                    origin + i as f64 * self.spacing_m,
                    origin + j as f64 * self.spacing_m,
                ) + jitter;
                if !wet(p) {
                    *id = Some(network.add_node(p, Junction { step: 0 })?);
                }
            }
        }
        let class = |line: usize| {
            if self.highway_every > 0 && line.is_multiple_of(self.highway_every) {
                RoadClass::Highway
            } else {
                RoadClass::Street
            }
        };
        let params = cx.config.effective_road_params();
        for i in 0..=n {
            for j in 0..=n {
                // The road east (along line j) and the road north (along line i).
                let steps = [((i + 1, j), class(j)), ((i, j + 1), class(i))];
                for ((a, b), class) in steps {
                    let (Some(Some(from)), Some(Some(to))) = (
                        ids.get(i).and_then(|r| r.get(j)).copied(),
                        ids.get(a).and_then(|r| r.get(b)).copied(),
                    ) else {
                        continue;
                    };
                    let mid = (network.position(from)? + network.position(to)?) * 0.5;
                    if wet(mid) {
                        continue;
                    }
                    let width = match class {
                        RoadClass::Highway => params.highway_width_m,
                        RoadClass::Street => params.street_width_m,
                    };
                    network.add_edge(
                        from,
                        to,
                        Road {
                            class,
                            width,
                            bridge: false,
                            tunnel: false,
                            step: 0,
                        },
                    )?;
                }
            }
        }
        network
            .check_invariants()
            .map_err(|e| stage_error(format!("the grid is not planar: {e}")))?;
        Ok(RoadsOutput {
            network,
            growth: None,
            skipped: Vec::new(),
            districts: Vec::new(),
        })
    }
}

/// A full city on a jittered grid of streets: a custom road stage in the pipeline.
#[derive(Debug, Parser)]
#[command(name = "custom_stage")]
struct Args {
    /// The grid's street spacing, metres (the stage refuses less than 20).
    #[arg(value_name = "SPACING_M", default_value = "110", value_parser = cli::metres)]
    spacing_m: f64,
    /// The folder the SVG and glb are written to.
    #[arg(value_name = "OUT_DIR", default_value = "out/custom_stage")]
    out: PathBuf,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let Args { spacing_m, out } = Args::parse();
    let mut config = CityConfig::preset("default")?;
    config.size_m = 1500.0;
    let stage = GridRoads {
        spacing_m,
        highway_every: 5,
        jitter: 0.12,
    };
    let city = Pipeline::default().with_roads(stage).generate(&config)?;
    let s = &city.stats;
    println!(
        "grid roads every {spacing_m} m: {} segments, {} cells, {} lots, {} buildings",
        s.road_segments, s.cells, s.lots, s.buildings
    );
    let formats: Formats = "svg,glb".parse()?;
    for f in city.write_all(&out, formats)?.files {
        println!("wrote {}", f.display());
    }
    Ok(())
}
