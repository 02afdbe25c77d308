//! The editable city's benchmark (issue 20): random edits of three kinds on a Citygen
//! city — move a primary node, change a cell's preset, pin a building — with the wall
//! time of each committed edit (regeneration, change events and the scene included),
//! printed as p50 / p95 / max per edit and per dirty cell.
//!
//! ```text
//! cargo bench --bench editor                       # citygen preset, 20 edits per kind
//! cargo bench --bench editor -- --edits 1000 --size 1500
//! cargo bench --bench editor -- --edits 5 --stages  # p50 per pipeline stage too
//! cargo bench --bench editor -- --kind "cell preset" # one kind of edit only
//! ```
//!
//! With `--stages` each kind also prints the median of each pipeline stage's time
//! (`City::stats.timings`; roads, buildings and facades preparation overlap) and the
//! editor's own share (the edit's wall time minus the pipeline's: change events,
//! orphans, dropping the old city), over the edits that ran the pipeline; lot edits the
//! editor patches in place run none and are counted apart.
//!
//! Per dirty cell = the edit's wall time divided by the number of city cells it regrew
//! (at least 1; a pin regrows none). Refused edits (a move whose re-plotted roads would
//! cross) are counted, not timed.

use std::time::Instant;

use polis::CityConfig;
use polis::editor::{CityEditor, Edit};
use polis::geom::hash::splitmix64;
use polis::roads::secondary::Neighbourhood;

// As the browser editor (examples/editor) runs: mimalloc as the global allocator. The
// edit clones and frees hundreds of thousands of small layers; glibc's allocator spends
// about half of an edit's CPU time in malloc and free (perf, session 10).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "common/process.rs"]
mod process;
use process::cpu_seconds;

fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

struct Stats {
    per_edit_ms: Vec<f64>,
    /// Per stage (in `Stage::ALL` order, then the editor's own share): ms per edit.
    stages_ms: Vec<Vec<f64>>,
    per_cell_ms: Vec<f64>,
    dirty_cells: usize,
    refused: usize,
    /// Edits made in place (lot edits, see the editor's `patch.rs`): no pipeline run.
    in_place: usize,
    cpu_s: f64,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut edits = 20usize;
    let mut size = None;
    let mut preset = "citygen".to_string();
    let mut stages = false;
    let mut kinds: Vec<String> = ["move node", "cell preset", "pin building"]
        .map(String::from)
        .to_vec();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--edits" => edits = args.next().ok_or("--edits N")?.parse()?,
            "--size" => size = Some(args.next().ok_or("--size METRES")?.parse()?),
            "--preset" => preset = args.next().ok_or("--preset NAME")?,
            "--stages" => stages = true,
            "--kind" => kinds = vec![args.next().ok_or("--kind NAME")?],
            "--bench" => {}
            other => return Err(format!("unknown argument {other:?}").into()),
        }
    }
    let mut config = CityConfig::preset(&preset)?;
    if let Some(s) = size {
        config.size_m = s;
    }
    let t = Instant::now();
    let mut ed = CityEditor::new(config)?;
    println!(
        "{preset} ({} m): {} cells, {} lots, {} buildings; editor made in {:.2} s",
        ed.config().size_m,
        ed.cells().len(),
        ed.city().lots.len(),
        ed.city().buildings.len(),
        t.elapsed().as_secs_f64()
    );
    let mut h = 0x0BE0_C4ED_u64;
    let mut next = move || {
        h = splitmix64(h);
        h
    };
    println!(
        "{:<14} {:>6} {:>8} {:>9} {:>9} {:>9} {:>11} {:>11} {:>11} {:>8}",
        "edit",
        "done",
        "refused",
        "p50 ms",
        "p95 ms",
        "max ms",
        "p50 ms/cell",
        "p95 ms/cell",
        "dirty cells",
        "CPU s"
    );
    for kind in kinds.iter().map(String::as_str) {
        let mut s = Stats {
            per_edit_ms: Vec::new(),
            stages_ms: vec![Vec::new(); polis::Stage::ALL.len() + 1],
            per_cell_ms: Vec::new(),
            dirty_cells: 0,
            refused: 0,
            in_place: 0,
            cpu_s: 0.0,
        };
        while s.per_edit_ms.len() < edits && s.refused < edits * 20 {
            let r = next();
            let edit = match kind {
                "move node" => {
                    let nodes: Vec<_> = ed.network().nodes().map(|(id, n)| (id.0, n.pos)).collect();
                    let (node, p) = nodes[(r % nodes.len() as u64) as usize];
                    let dx = (next() % 41) as f64 - 20.0;
                    let dy = (next() % 41) as f64 - 20.0;
                    Edit::MoveNode {
                        node,
                        to: [p.x + dx, p.y + dy],
                    }
                }
                "cell preset" => {
                    let cells = ed.cells();
                    let n = Neighbourhood::ALL[(next() % Neighbourhood::ALL.len() as u64) as usize];
                    Edit::SetCellPattern {
                        cell: cells[(r % cells.len() as u64) as usize].id,
                        pattern: n.into(),
                    }
                }
                _ => {
                    let lots = &ed.city().lots;
                    Edit::PinHeight {
                        lot: lots[(r % lots.len() as u64) as usize].id,
                        height_m: 40.0 + (next() % 160) as f64,
                    }
                }
            };
            let at = ed.city() as *const polis::City;
            let cpu = cpu_seconds();
            let t = Instant::now();
            match ed.apply(edit) {
                Ok(ev) => {
                    let ms = t.elapsed().as_secs_f64() * 1e3;
                    s.cpu_s += cpu_seconds().zip(cpu).map_or(0.0, |(b, a)| b - a);
                    s.per_edit_ms.push(ms);
                    s.per_cell_ms.push(ms / ev.dirty_cells.len().max(1) as f64);
                    s.dirty_cells += ev.dirty_cells.len();
                    // A lot edit patched in place ran no pipeline: no stage times.
                    if std::ptr::eq(at, ed.city()) {
                        s.in_place += 1;
                        continue;
                    }
                    let st = &ed.city().stats;
                    for (i, stage) in polis::Stage::ALL.iter().enumerate() {
                        let t = st.timings.iter().find(|t| t.stage == *stage);
                        s.stages_ms[i].push(t.map_or(0.0, |t| t.time.as_secs_f64() * 1e3));
                    }
                    s.stages_ms[polis::Stage::ALL.len()]
                        .push(ms - st.wall_time.as_secs_f64() * 1e3);
                }
                Err(_) => s.refused += 1,
            }
        }
        s.per_edit_ms.sort_by(f64::total_cmp);
        s.per_cell_ms.sort_by(f64::total_cmp);
        println!(
            "{:<14} {:>6} {:>8} {:>9.1} {:>9.1} {:>9.1} {:>11.1} {:>11.1} {:>11.2} {:>8.1}",
            kind,
            s.per_edit_ms.len(),
            s.refused,
            quantile(&s.per_edit_ms, 0.5),
            quantile(&s.per_edit_ms, 0.95),
            quantile(&s.per_edit_ms, 1.0),
            quantile(&s.per_cell_ms, 0.5),
            quantile(&s.per_cell_ms, 0.95),
            s.dirty_cells as f64 / s.per_edit_ms.len().max(1) as f64,
            s.cpu_s,
        );
        if stages && s.in_place > 0 {
            println!(
                "  {} of {} made in place (no pipeline run)",
                s.in_place,
                s.per_edit_ms.len()
            );
        }
        if stages && s.in_place < s.per_edit_ms.len() {
            let mut line = String::from("  p50 by stage (ms):");
            for (i, v) in s.stages_ms.iter_mut().enumerate() {
                v.sort_by(f64::total_cmp);
                let name = polis::Stage::ALL
                    .get(i)
                    .map_or("editor".to_string(), |st| format!("{st:?}").to_lowercase());
                line.push_str(&format!(" {name} {:.1}", quantile(v, 0.5)));
            }
            println!("{line}");
        }
    }
    Ok(())
}
