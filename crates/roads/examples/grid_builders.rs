//! The course report's grid road builders: Downtown vs Residential in the same cell,
//! side by side, as SVG (the report's Images 4.1 and 4.2, seen from above).
//!
//! ```text
//! cargo run --release -p polis-roads --example grid_builders -- [OUT_SVG] [SEED] [GRID_M] [STARTS]
//! ```
//!
//! Arguments are parsed by clap (`--help` lists them); the rule sets check the grid
//! spacing and the number of builders.
//!
//! The cell is concave (a notch cut into its north side), has a hole (a block ringed by
//! primary roads), a lake (water) and a park; streets keep out of all three. For each
//! rule set the program prints the street statistics and the street map as the
//! report's console print (Images 2.1 and 2.2: `*` streets, `J` joined to the boundary).

use std::fmt::Write as _;
use std::sync::Arc;

use clap::Parser;
use polis_roads::RoadInputs;
use polis_roads::geom::field::{Constant, FnField};
use polis_roads::geom::{DVec2, Polygon, PolygonWithHoles};
use polis_roads::grid_builders::{
    GridBuilderGrowth, GridMaps, GridParams, GridRoads, street_stats,
};

const LAKE: (DVec2, f64) = (DVec2::new(170.0, 170.0), 70.0);
const PARK: (DVec2, DVec2) = (DVec2::new(420.0, 330.0), DVec2::new(540.0, 440.0));

/// A concave cell (a notch cut into its north side) with a hole: a block ringed by
/// primary roads.
fn cell() -> PolygonWithHoles {
    let outer = [
        (0.0, 20.0),
        (560.0, 0.0),
        (600.0, 480.0),
        (330.0, 500.0),
        (280.0, 360.0),
        (230.0, 500.0),
        (10.0, 470.0),
    ];
    let outer = Polygon::new(outer.iter().map(|&(x, y)| DVec2::new(x, y)).collect());
    let hole = Polygon::rect(DVec2::new(380.0, 150.0), DVec2::new(470.0, 230.0));
    PolygonWithHoles::new(outer, vec![hole])
}

fn maps() -> RoadInputs {
    let mut maps = RoadInputs::flat(Arc::new(Constant(1.0)));
    maps.water = Arc::new(FnField(|p: DVec2| {
        if p.distance(LAKE.0) < LAKE.1 {
            1.0
        } else {
            0.0
        }
    }));
    maps.parks = Arc::new(FnField(|p: DVec2| {
        let inside = p.cmpge(PARK.0).all() && p.cmple(PARK.1).all();
        if inside { 1.0 } else { 0.0 }
    }));
    maps
}

fn ring_path(out: &mut String, ring: &Polygon, dx: f64, h: f64) {
    for (i, p) in ring.points().iter().enumerate() {
        let c = if i == 0 { 'M' } else { 'L' };
        let _ = write!(out, "{c}{:.2},{:.2} ", p.x + dx, h - p.y);
    }
    out.push('Z');
}

fn panel(svg: &mut String, title: &str, roads: &GridRoads, cell: &PolygonWithHoles, dx: f64) {
    let h = 540.0;
    let mut d = String::new();
    for (_, ring) in cell.rings() {
        ring_path(&mut d, ring, dx, h);
    }
    let _ = writeln!(
        svg,
        r##"<path d="{d}" fill="#efe9dc" fill-rule="evenodd" stroke="#555" stroke-width="6"/>"##
    );
    let _ = writeln!(
        svg,
        r##"<circle cx="{:.1}" cy="{:.1}" r="{:.1}" fill="#9cc3e6"/>"##,
        LAKE.0.x + dx,
        h - LAKE.0.y,
        LAKE.1
    );
    let _ = writeln!(
        svg,
        r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#a8d5a0"/>"##,
        PARK.0.x + dx,
        h - PARK.1.y,
        PARK.1.x - PARK.0.x,
        PARK.1.y - PARK.0.y
    );
    for (_, a, b, road) in roads.network.edges() {
        let (Ok(p), Ok(q)) = (roads.network.position(a), roads.network.position(b)) else {
            continue;
        };
        let _ = writeln!(
            svg,
            r##"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="#333" stroke-width="{:.1}" stroke-linecap="square"/>"##,
            p.x + dx,
            h - p.y,
            q.x + dx,
            h - q.y,
            road.width * 0.6
        );
    }
    for n in roads.network.node_ids() {
        let Ok(p) = roads.network.position(n) else {
            continue;
        };
        let degree = roads.network.degree(n).unwrap_or(0);
        let colour = if roads.boundary_nodes.binary_search(&n).is_ok() {
            "#1f6fb2"
        } else if degree == 1 {
            "#d62728"
        } else {
            continue;
        };
        let _ = writeln!(
            svg,
            r##"<circle cx="{:.2}" cy="{:.2}" r="4" fill="{colour}"/>"##,
            p.x + dx,
            h - p.y
        );
    }
    let _ = writeln!(
        svg,
        r##"<text x="{:.1}" y="{:.1}" font-family="sans-serif" font-size="22" fill="#222">{title}</text>"##,
        dx + 10.0,
        h + 30.0
    );
}

/// The course report's Downtown and Residential grid road builders in one cell, as SVG.
#[derive(Debug, Parser)]
#[command(name = "grid_builders")]
struct Args {
    /// The SVG file to write.
    #[arg(value_name = "OUT_SVG", default_value = "grid_builders.svg")]
    path: std::path::PathBuf,
    /// The growth seed.
    #[arg(value_name = "SEED", default_value = "4")]
    seed: u64,
    /// The builders' grid spacing, metres (default: each rule set's own).
    #[arg(value_name = "GRID_M")]
    grid: Option<f64>,
    /// How many builders start (default: each rule set's own).
    #[arg(value_name = "STARTS")]
    starts: Option<u32>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args {
        path,
        seed,
        grid,
        starts,
    } = Args::parse();
    let cell = cell();
    let maps = maps();
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="1300" height="600" viewBox="-20 -20 1300 600"><rect x="-20" y="-20" width="1300" height="600" fill="white"/>"##
    );
    for (i, mut params) in [GridParams::downtown(), GridParams::residential()]
        .into_iter()
        .enumerate()
    {
        params.grid_size_m = grid.unwrap_or(params.grid_size_m);
        params.starts = starts.unwrap_or(params.starts);
        let params = &params;
        let mut worker = GridBuilderGrowth::new();
        let roads = worker.grow(&cell, &[], &GridMaps::from(&maps), params, seed)?;
        let s = street_stats(&roads.network, &roads.boundary_nodes, &cell)?;
        println!(
            "{:<12} streets {:>6.0} m  junctions {:>3}  4-way {:>4.2}  dead ends {:>4.2}  \
             blocks {:>3}  mean block {:>6.0} m²  ({} builders, {} steps)",
            params.rules.name,
            s.street_length_m,
            s.junctions,
            s.four_way_share,
            s.dead_end_share,
            s.blocks,
            s.mean_block_area_m2,
            roads.report.builders,
            roads.report.steps
        );
        print!("{}", worker.street_map());
        let title = format!(
            "{}: {} blocks, {:.0}% 4-way, {:.0}% dead ends",
            params.rules.name,
            s.blocks,
            100.0 * s.four_way_share,
            100.0 * s.dead_end_share
        );
        panel(&mut svg, &title, &roads, &cell, i as f64 * 640.0);
    }
    svg.push_str("</svg>\n");
    std::fs::write(&path, svg)?;
    println!("wrote {}", path.display());
    Ok(())
}
