//! A scripted editing session on a Citygen city (issue 20): add a ring road, change a
//! cell to Suburbia, pin a tower, undo. After each step the city is written (SVG map
//! and GeoJSON, plus glb with `--glb`) to `OUT/step-N-name/`, the change events are
//! printed, and at the end the editing file is saved and replayed.
//!
//! ```text
//! cargo run --release --example edit_city -- [--size METRES] [--out DIR] [--glb]
//! ```
//!
//! Flags are parsed by clap (`--help` lists them).

use std::path::PathBuf;
use std::time::Instant;

use clap::Parser;
use polis::editor::{ChangeEvents, CityEditor, Edit, End};
use polis::geom::DVec2;
use polis::roads::secondary::Neighbourhood;
use polis::{CityConfig, Formats};

#[allow(dead_code)]
#[path = "common/cli.rs"]
mod cli;

/// A scripted editing session on a Citygen city, written after each step.
#[derive(Debug, Parser)]
#[command(name = "edit_city")]
struct Args {
    /// The city's size, metres.
    #[arg(long, value_name = "METRES", default_value = "2000", value_parser = cli::metres)]
    size: f64,
    /// The folder the steps are written to.
    #[arg(long, value_name = "DIR", default_value = "out/edit_city")]
    out: PathBuf,
    /// Also write each step's glb.
    #[arg(long)]
    glb: bool,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args { size, out, glb } = Args::parse();
    let formats = Formats {
        glb,
        svg: true,
        geojson: true,
        ..Formats::NONE
    };
    let mut config = CityConfig::preset("citygen")?;
    config.size_m = size;
    config.lod = Some(1);

    let t = Instant::now();
    let mut ed = CityEditor::new(config)?;
    println!(
        "start: {} cells, {} buildings ({:.2} s)",
        ed.cells().len(),
        ed.city().buildings.len(),
        t.elapsed().as_secs_f64()
    );
    write(&ed, &out, 0, "start", formats)?;

    // 1. A ring road: nodes on a circle, chained, closed back to the first node.
    let t = Instant::now();
    let r = size * 0.3;
    let at = |k: usize| {
        let a = std::f64::consts::TAU * k as f64 / 12.0 + 0.1;
        [r * a.cos(), r * a.sin()]
    };
    let mut ring_edits = 0;
    let mut first = None;
    let mut last: Option<u64> = None;
    for k in 0..12 {
        let edit = match last {
            None => Edit::AddNode {
                at: at(k),
                label: Some("ring".into()),
            },
            Some(from) => Edit::Chain {
                from,
                to: at(k),
                spec: Default::default(),
            },
        };
        let preview = ed.propose(&edit);
        if !preview.valid {
            // Water, a park or a too-sharp crossing: skip this ring node.
            println!("  ring node {k} refused: {:?}", preview.refusal);
            continue;
        }
        ed.apply(edit)?;
        ring_edits += 1;
        let node = match preview.end_node {
            Some(n) => n,
            None => nearest_node(&ed, at(k)),
        };
        first.get_or_insert(node);
        last = Some(node);
    }
    let mut ring_events = None;
    if let (Some(a), Some(b)) = (first, last)
        && a != b
    {
        let close = Edit::AddRoad {
            from: End::Node(b),
            to: End::Node(a),
            spec: Default::default(),
        };
        if ed.propose(&close).valid {
            ring_events = Some(ed.apply(close)?);
            ring_edits += 1;
        }
    }
    println!(
        "1. ring road: {ring_edits} edits in {:.2} s",
        t.elapsed().as_secs_f64()
    );
    if let Some(ev) = &ring_events {
        report(ev);
    }
    write(&ed, &out, 1, "ring", formats)?;

    // 2. The cell at the centre becomes Suburbia.
    let centre = ed
        .cell_at(DVec2::ZERO)
        .or_else(|| ed.cells().first().map(|c| c.id))
        .ok_or("no cell")?;
    let t = Instant::now();
    let ev = ed.apply(Edit::SetCellPattern {
        cell: centre,
        pattern: Neighbourhood::Suburbia.into(),
    })?;
    println!(
        "2. cell {centre} → Suburbia in {:.3} s",
        t.elapsed().as_secs_f64()
    );
    report(&ev);
    write(&ed, &out, 2, "suburbia", formats)?;

    // 3. A tower on the lot nearest a point east of the centre.
    let target = DVec2::new(size * 0.15, 0.0);
    let lot = ed
        .city()
        .lots
        .iter()
        .min_by(|a, b| {
            let d = |l: &polis::CityLot| (l.lot.polygon.centroid() - target).length();
            d(a).total_cmp(&d(b))
        })
        .map(|l| l.id)
        .ok_or("no lot")?;
    let t = Instant::now();
    ed.apply(Edit::PinKind {
        lot,
        kind: polis::buildings::BuildingKind::Skyscraper,
    })?;
    let ev = ed.apply(Edit::PinHeight {
        lot,
        height_m: 180.0,
    })?;
    println!(
        "3. tower on lot {lot} in {:.3} s (2 edits)",
        t.elapsed().as_secs_f64()
    );
    report(&ev);
    write(&ed, &out, 3, "tower", formats)?;

    // 4. Undo the height pin.
    let t = Instant::now();
    let ev = ed.undo()?;
    println!("4. undo in {:.3} s", t.elapsed().as_secs_f64());
    report(&ev);
    write(&ed, &out, 4, "undo", formats)?;

    // The session as a file, replayed to the same city.
    let file = ed.editing_file();
    file.save(out.join("session.json"))?;
    let t = Instant::now();
    let replayed = file.replay()?;
    let same = replayed.city().stats.buildings == ed.city().stats.buildings
        && replayed.config() == ed.config();
    println!(
        "replayed {} edits in {:.2} s: {}",
        file.edits.len(),
        t.elapsed().as_secs_f64(),
        if same { "same city" } else { "DIFFERENT" }
    );
    Ok(())
}

fn nearest_node(ed: &CityEditor, p: [f64; 2]) -> u64 {
    let p = DVec2::new(p[0], p[1]);
    ed.network()
        .nodes()
        .min_by(|a, b| (a.1.pos - p).length().total_cmp(&(b.1.pos - p).length()))
        .map_or(0, |(id, _)| id.0)
}

fn report(ev: &ChangeEvents) {
    println!(
        "   dirty: {} cells, {} road-graph cells; lots −{} +{} ~{}; buildings −{} +{} ~{}; \
         scene nodes −{} +{} ~{}",
        ev.dirty_cells.len(),
        ev.dirty_blocks.len(),
        ev.lots.removed.len(),
        ev.lots.added.len(),
        ev.lots.changed.len(),
        ev.buildings.removed.len(),
        ev.buildings.added.len(),
        ev.buildings.changed.len(),
        ev.scene_nodes.removed.len(),
        ev.scene_nodes.added.len(),
        ev.scene_nodes.changed.len(),
    );
}

fn write(
    ed: &CityEditor,
    out: &std::path::Path,
    step: usize,
    name: &str,
    formats: Formats,
) -> Result<(), Box<dyn std::error::Error>> {
    let dir = out.join(format!("step-{step}-{name}"));
    std::fs::create_dir_all(&dir)?;
    let written = ed.city().write_all(&dir, formats)?;
    println!(
        "   wrote {} files to {}",
        written.files.len(),
        dir.display()
    );
    Ok(())
}
