//! The Citygen road mode step by step: primary network, cells, secondary growth per cell,
//! the union graph, then (with `--city`) the whole city on it. Writes an SVG of the roads
//! (primary black, secondary red) and prints counts and timings.
//!
//! ```text
//! cargo run --release --example citygen -- [PRESET] [--city | --city-only] [--lod N]
//!     [--threads N] [--out DIR] [--bench-growth RUNS]
//! ```
//!
//! `--bench-growth RUNS` grows every Kelly cell serially on one thread `RUNS` times (one growth worker, its
//! buffers kept from cell to cell as each pool thread of the pipeline keeps one) and
//! prints CPU time and a digest of the grown graphs; then each cell's least time over
//! those runs, with what the cells would take on the pool's number of idle cores (handed
//! out in their order, largest first, or largest first by the pipeline's estimate); then
//! grows them `RUNS` times on the thread pool (`--threads`, default all cores), largest
//! first by that estimate as the pipeline does, and prints wall time and the digest (the
//! serial one); each such run is followed by one in rayon's own splitting of the cells
//! in halves, for a paired comparison of the two schedules.
//!
//! `--city` also generates the whole city (without the 3-D scene) after the road part;
//! `--city-only` only generates the whole city, scene included (for timing any preset).
//!
//! `PRESET` is a built-in preset in the Citygen mode (`citygen`, `suburbia`, `milan`) or a
//! configuration file (`….json`); default `citygen`. Flags are parsed by clap (`--help`
//! lists them; `--bench-growth` alone runs 5 times).

use std::fmt::Write as _;
use std::time::Instant;

use clap::Parser;
use polis::citygen::citygen_network;
use polis::roads::RoadClass;
use polis::roads::secondary::StreetStats;
use polis::stages::{Stage, StageContext};
use polis::{CityConfig, CityMaps, Pipeline};

#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The Citygen road mode step by step, and the secondary growth's benchmark.
#[derive(Debug, Parser)]
#[command(name = "citygen")]
struct Args {
    /// A built-in preset in the Citygen mode, or a configuration file (`….json`).
    #[arg(value_name = "PRESET", default_value = "citygen")]
    preset: String,
    /// Also generate the whole city (without the 3-D scene) after the road part.
    #[arg(long)]
    city: bool,
    /// Only generate the whole city, scene included (for timing any preset).
    #[arg(long, conflicts_with = "city")]
    city_only: bool,
    /// The buildings' level of detail (default: the configuration's).
    #[arg(long, value_name = "N")]
    lod: Option<usize>,
    /// Threads of the pool (default: every core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
    /// The folder the SVG is written to.
    #[arg(long, value_name = "DIR", default_value = "out")]
    out: std::path::PathBuf,
    /// Time the secondary growth RUNS times serially and on the pool (see above).
    #[arg(long, value_name = "RUNS", num_args = 0..=1, default_missing_value = "5",
          value_parser = clap::value_parser!(u32).range(1..))]
    bench_growth: Option<u32>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args {
        preset,
        city,
        city_only,
        lod,
        threads,
        out,
        bench_growth,
    } = Args::parse();
    let threads = threads.map(usize::from);
    let bench_growth = bench_growth.map_or(0, |r| r as usize);
    let mut config = if preset.ends_with(".json") {
        CityConfig::from_path(&preset)?
    } else {
        CityConfig::preset(&preset)?
    };
    let preset = config.name.clone();
    config.threads = threads;
    config.lod = lod.or(config.lod);
    if city_only {
        let t = Instant::now();
        let c = Pipeline::default().generate(&config)?;
        println!(
            "city: {} road segments, {} buildings, {} scene triangles; {:.3} s",
            c.stats.road_segments,
            c.stats.buildings,
            c.stats.scene_triangles,
            t.elapsed().as_secs_f64()
        );
        return Ok(());
    }
    let maps = CityMaps::build(
        &config.maps,
        polis::seed::sub_seed(config.seed, Stage::Maps, 0),
    )?;
    let cx = StageContext {
        config: &config,
        maps: &maps,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()?;
    let t = Instant::now();
    let (net, _) = pool.install(|| citygen_network(&cx))?;
    let total = t.elapsed();
    if bench_growth > 0 {
        return growth_bench(&cx, &net.primary, bench_growth, &pool);
    }
    let mut stats = StreetStats::default();
    let mut per_cell = Vec::new();
    for c in &net.cells {
        stats.add(&StreetStats::of(&c.network));
        per_cell.push(c.segments().count());
    }
    println!(
        "{preset}: primary {} roads; {} cells grown, {} skipped; {} secondary roads; union {} roads, {} junctions",
        net.primary.edge_count(),
        net.cells.len(),
        net.skipped.len(),
        stats.streets,
        net.network.edge_count(),
        net.network.node_count()
    );
    println!(
        "secondary growth {:.2} ms ({:.3} ms per cell); road part total {:.1} ms",
        net.secondary_s * 1e3,
        net.secondary_s * 1e3 / net.cells.len().max(1) as f64,
        total.as_secs_f64() * 1e3
    );
    println!(
        "cell junctions: dead ends {:.3}, 4-way or boundary {:.3}",
        stats.dead_end_share(),
        stats.four_way_or_boundary_share()
    );
    let whole = polis::roads::network_stats(&net.network);
    println!(
        "union: dead ends {:.3} of junctions, mean degree {:.2}",
        whole.dead_ends as f64 / whole.junctions.max(1) as f64,
        2.0 * whole.edges as f64 / whole.junctions.max(1) as f64
    );
    std::fs::create_dir_all(&out)?;
    let h = config.size_m * 0.5;
    let mut svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="1600" height="1600" viewBox="{} {} {} {}"><rect x="{}" y="{}" width="100%" height="100%" fill="white"/>"#,
        -h, -h, config.size_m, config.size_m, -h, -h
    );
    for (e, _, _, r) in net.network.edges() {
        let Ok((a, b)) = net.network.segment(e) else {
            continue;
        };
        let (c, w) = match r.class {
            RoadClass::Highway => ("#111", 14.0),
            RoadClass::Street => ("#c0392b", 4.0),
        };
        let _ = writeln!(
            svg,
            r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{c}" stroke-width="{w}"/>"#,
            a.x, -a.y, b.x, -b.y
        );
    }
    svg.push_str("</svg>");
    let path = out.join(format!("citygen_{preset}.svg"));
    std::fs::write(&path, svg)?;
    println!("wrote {}", path.display());
    if city {
        let t = Instant::now();
        let c = Pipeline::default().with_scene(false).generate(&config)?;
        println!(
            "city: {} road segments, {} cells, {} blocks, {} lots, {} buildings, {} skipped; {:.2} s",
            c.stats.road_segments,
            c.stats.cells,
            c.stats.blocks,
            c.stats.lots,
            c.stats.buildings,
            c.report.skipped.len(),
            t.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

/// CPU time of the calling thread, nanoseconds (Linux: `/proc/thread-self/schedstat`).
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

std::thread_local! {
    /// The growth worker of each thread of the benchmark's pool.
    static WORKER: std::cell::RefCell<Option<polis::roads::secondary::SecondaryGrowth>> =
        const { std::cell::RefCell::new(None) };
}

/// Grows every cell of the primary network serially on this thread, `runs` times, and
/// prints wall and CPU time per run (the inputs are prepared before the clock starts);
/// then `runs` times on `pool`'s threads, printing wall time.
fn growth_bench(
    cx: &StageContext<'_>,
    primary: &polis::roads::RoadNetwork,
    runs: usize,
    pool: &rayon::ThreadPool,
) -> Result<(), Box<dyn std::error::Error>> {
    use polis::roads::secondary::{CellMaps, SecondaryCell, SecondaryGrowth, estimated_work};
    let cg = &cx.config.citygen;
    let cells = polis::cells::extract_with(primary, &cx.config.cells)?;
    let zoning = polis::citygen::zoning_of(cx)?;
    let mut inputs = Vec::new();
    for cell in &cells.cells {
        let Ok(region) = cell.polygon_with_holes() else {
            continue;
        };
        // Kelly's growth only: cells given a grid pattern are not in this benchmark.
        let chosen = polis::citygen::choose_pattern(cx, zoning.as_ref(), &region);
        let polis::citygen::CellPatternChoice::Kelly(n) = chosen.pattern else {
            continue;
        };
        let mut p = n.preset()?.to_params(cg.unit_m);
        p.road_width_m.value *= cg.road_width_factor;
        for q in &chosen.params {
            q.apply(&mut p);
        }
        let filaments = cell
            .filaments
            .iter()
            .flat_map(|f| f.points.windows(2).map(|w| [w[0], w[1]]))
            .collect();
        let id = polis::citygen::stable_cell_id(cell);
        inputs.push((
            SecondaryCell {
                id,
                region,
                filaments,
            },
            p,
        ));
    }
    let seed = cx.seed(Stage::Roads, 1);
    let maps = CellMaps::none();
    // Each cell's least wall time over the serial runs (its growth alone, read with the
    // monotonic clock, which costs far less than the CPU clock's file read).
    let mut cell_ns = vec![u64::MAX; inputs.len()];
    for run in 0..runs {
        let (t, c) = (Instant::now(), thread_cpu_ns());
        let mut roads = 0;
        let mut digest = 0u64;
        // One worker for all cells, as each thread of the pipeline's pool keeps one.
        let mut growth: Option<SecondaryGrowth> = None;
        for ((cell, p), best) in inputs.iter().zip(&mut cell_ns) {
            let started = Instant::now();
            let worker = match growth.as_mut() {
                Some(w) => {
                    w.set_params(p.clone())?;
                    w
                }
                None => growth.insert(SecondaryGrowth::new(p.clone())?),
            };
            let grown = worker.grow(cell, &maps, seed);
            *best = (*best).min(started.elapsed().as_nanos() as u64);
            if let Ok(r) = grown {
                roads += r.segments().count();
                digest = polis::geom::hash::splitmix64(digest ^ graph_digest(&r.network));
            }
        }
        let joins = growth.as_ref().map_or((0, 0), |w| w.join_counters());
        let (wall, cpu) = (
            t.elapsed().as_secs_f64() * 1e3,
            (thread_cpu_ns() - c) as f64 / 1e6,
        );
        println!(
            "run {run}: {} cells, {roads} secondary roads (digest {digest:016x}), serial wall {wall:.2} ms, CPU {cpu:.2} ms, {:.3} ms CPU per cell; joins onto a road {} direct, {} by planar insertion",
            inputs.len(),
            cpu / inputs.len().max(1) as f64,
            joins.0,
            joins.1
        );
    }
    let estimates: Vec<f64> = inputs
        .iter()
        .map(|(cell, p)| estimated_work(p, cell.region.area()))
        .collect();
    schedules(&cell_ns, &estimates, pool.current_num_threads());
    // The same growth with the cells spread over the pool's threads (as the pipeline
    // grows them): wall time, and the digest, which must be the serial one. Each run is
    // followed by one with rayon's own splitting of the cells in halves (the pipeline's
    // schedule before session 19), for a paired comparison of the two schedules.
    let grow_one = |(cell, p): &(SecondaryCell, polis::roads::secondary::SecondaryParams)| {
        // One worker per pool thread, as the pipeline keeps.
        WORKER.with(|w| {
            let mut slot = w.try_borrow_mut().ok()?;
            let worker = match slot.as_mut() {
                Some(w) => {
                    w.set_params(p.clone()).ok()?;
                    w
                }
                None => slot.insert(SecondaryGrowth::new(p.clone()).ok()?),
            };
            worker.grow(cell, &maps, seed).ok().map(|r| r.network)
        })
    };
    // The digest is taken after the clock stops, as the serial runs' cell times leave it
    // out (the pipeline collects the networks and hashes nothing).
    let digest_of = |grown: &[Option<polis::roads::RoadNetwork>]| {
        grown.iter().flatten().fold(0u64, |d, g| {
            polis::geom::hash::splitmix64(d ^ graph_digest(g))
        })
    };
    for run in 0..runs {
        let t = Instant::now();
        // Largest first by the pipeline's estimate, as the pipeline schedules them.
        let grown: Vec<Option<polis::roads::RoadNetwork>> = pool.install(|| {
            polis::geom::par::map_costliest_first(
                &inputs,
                |(cell, p)| estimated_work(p, cell.region.area()),
                grow_one,
            )
        });
        let wall = t.elapsed().as_secs_f64() * 1e3;
        println!(
            "parallel run {run}: {} threads, digest {:016x}, wall {wall:.2} ms",
            pool.current_num_threads(),
            digest_of(&grown)
        );
        let t = Instant::now();
        let grown: Vec<Option<polis::roads::RoadNetwork>> = pool.install(|| {
            use rayon::prelude::*;
            inputs.par_iter().map(grow_one).collect()
        });
        let wall = t.elapsed().as_secs_f64() * 1e3;
        println!(
            "  the same in rayon's halves: digest {:016x}, wall {wall:.2} ms",
            digest_of(&grown)
        );
    }
    Ok(())
}

/// Prints the cells' growth times (each cell's least over the serial runs) and what they
/// would take on `threads` idle cores: the lower bound (the largest cell, or the sum
/// shared evenly), cells handed out to whichever core is free first in their order,
/// largest first, and largest first by the pipeline's `estimates` (as it runs them).
fn schedules(cell_ns: &[u64], estimates: &[f64], threads: usize) {
    let threads = threads.max(1);
    let ms = |ns: u64| ns as f64 / 1e6;
    let sum: u64 = cell_ns.iter().sum();
    let mut sorted = cell_ns.to_vec();
    sorted.sort_unstable_by(|a, b| b.cmp(a));
    let makespan = |order: &[u64]| {
        let mut free = vec![0u64; threads];
        for &t in order {
            if let Some(f) = free.iter_mut().min() {
                *f += t;
            }
        }
        free.into_iter().max().unwrap_or(0)
    };
    let mut by_estimate: Vec<(f64, usize, u64)> = estimates
        .iter()
        .zip(cell_ns)
        .enumerate()
        .map(|(i, (&e, &t))| (e, i, t))
        .collect();
    by_estimate.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let by_estimate: Vec<u64> = by_estimate.into_iter().map(|(_, _, t)| t).collect();
    let largest = sorted.first().copied().unwrap_or(0);
    println!(
        "cells: sum of least times {:.2} ms, largest {:.2} ms, next {:.2} / {:.2} / {:.2} ms; on {threads} idle cores: bound {:.2} ms, in order {:.2} ms, largest first {:.2} ms, by estimate {:.2} ms",
        ms(sum),
        ms(largest),
        ms(sorted.get(1).copied().unwrap_or(0)),
        ms(sorted.get(2).copied().unwrap_or(0)),
        ms(sorted.get(3).copied().unwrap_or(0)),
        ms(largest.max(sum.div_ceil(threads as u64))),
        ms(makespan(cell_ns)),
        ms(makespan(&sorted)),
        ms(makespan(&by_estimate)),
    );
}

/// FNV-1a over a graph's nodes and edges in id order (positions to the bit).
fn graph_digest(net: &polis::roads::RoadNetwork) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |v: u64| {
        for b in v.to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for (n, p, _) in net.nodes() {
        eat(n.index() as u64);
        eat(p.x.to_bits());
        eat(p.y.to_bits());
    }
    for (e, u, v, r) in net.edges() {
        eat(e.index() as u64);
        eat(u.index() as u64);
        eat(v.index() as u64);
        eat(r.width.to_bits());
    }
    h
}
