//! Kelly's secondary road growth drawn as SVG:
//!
//! * `secondary_presets.svg`: Manhattan, Suburbia and Industrial side by side in the same
//!   cell (Citygen Fig. 76), plus Raster and Organic (Fig. 44);
//! * `secondary_steps.svg`: one cell after 10, 100, 300 and 1000 growth steps (Fig. 43).
//!
//! Run: `cargo run --release -p polis-roads --example secondary_growth [OUT_DIR]`
//! (`--help` lists the arguments).

use std::fmt::Write as _;

use clap::Parser;
use polis_roads::RoadClass;
use polis_roads::geom::{DVec2, Polygon};
use polis_roads::secondary::{
    CellMaps, Neighbourhood, SecondaryCell, SecondaryGrowth, SecondaryRoads, StreetStats,
};

/// The cell every panel grows in: an irregular, slightly concave hexagon, about 1 km².
fn cell() -> SecondaryCell {
    let pts = [
        (0.0, 0.0),
        (1050.0, -60.0),
        (1180.0, 520.0),
        (980.0, 1020.0),
        (520.0, 900.0),
        (60.0, 1080.0),
    ];
    SecondaryCell::new(
        42,
        Polygon::new(pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect()),
    )
}

const PANEL: f64 = 1300.0;

fn panel(svg: &mut String, roads: &SecondaryRoads, col: usize, title: &str) {
    let ox = col as f64 * PANEL + 60.0;
    let oy = 120.0;
    let _ = writeln!(svg, r#"<g transform="translate({ox} {oy})">"#);
    let _ = writeln!(
        svg,
        r#"<text x="0" y="-40" font-size="56" font-family="sans-serif">{title}</text>"#
    );
    for (e, _, _, r) in roads.network.edges() {
        let Ok((a, b)) = roads.network.segment(e) else {
            continue;
        };
        // Layout y up, SVG y down.
        let (stroke, w) = match r.class {
            RoadClass::Highway => ("#222", 14.0),
            RoadClass::Street => ("#c0392b", r.width.max(3.0)),
        };
        let _ = writeln!(
            svg,
            r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{stroke}" stroke-width="{w:.1}" stroke-linecap="round"/>"#,
            a.x,
            1100.0 - a.y,
            b.x,
            1100.0 - b.y
        );
    }
    let s = StreetStats::of(&roads.network);
    let _ = writeln!(
        svg,
        r#"<text x="0" y="1180" font-size="40" font-family="sans-serif">{} streets, dead ends {:.0} %, 4-way or boundary {:.0} %</text>"#,
        s.streets,
        100.0 * s.dead_end_share(),
        100.0 * s.four_way_or_boundary_share()
    );
    let _ = writeln!(svg, "</g>");
}

fn write(path: &std::path::Path, panels: usize, body: &str) -> std::io::Result<()> {
    let w = panels as f64 * PANEL + 60.0;
    let svg = format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{:.0}" viewBox="0 0 {w} 1360"><rect width="100%" height="100%" fill="white"/>{body}</svg>"#,
        w / 4.0,
        1360.0 / 4.0
    );
    std::fs::write(path, svg)
}

/// Kelly's neighbourhood presets side by side, and one cell's growth step by step, as SVG.
#[derive(Debug, Parser)]
#[command(name = "secondary_growth")]
struct Args {
    /// The folder the two SVG files are written to.
    #[arg(value_name = "OUT_DIR", default_value = ".")]
    out: std::path::PathBuf,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args { out } = Args::parse();
    std::fs::create_dir_all(&out)?;
    let cell = cell();
    let maps = CellMaps::none();
    // Fig. 76 (and Fig. 44): every preset in the same cell, same seed.
    let mut body = String::new();
    for (i, n) in Neighbourhood::ALL.into_iter().enumerate() {
        let t = std::time::Instant::now();
        let roads = SecondaryGrowth::new(n.params()?)?.grow(&cell, &maps, 7)?;
        eprintln!("{:>10}: {:?} {:?}", n.name(), t.elapsed(), roads.report);
        panel(&mut body, &roads, i, n.name());
    }
    let path = out.join("secondary_presets.svg");
    write(&path, Neighbourhood::ALL.len(), &body)?;
    println!("wrote {}", path.display());
    // Fig. 43: growth after 10, 100, 300 and 1000 steps.
    let mut body = String::new();
    for (i, steps) in [10u32, 100, 300, 1000].into_iter().enumerate() {
        let mut params = Neighbourhood::Organic.params()?;
        params.max_steps = Some(steps);
        let roads = SecondaryGrowth::new(params)?.grow(&cell, &maps, 7)?;
        panel(&mut body, &roads, i, &format!("{steps} steps"));
    }
    let path = out.join("secondary_steps.svg");
    write(&path, 4, &body)?;
    println!("wrote {}", path.display());
    Ok(())
}
