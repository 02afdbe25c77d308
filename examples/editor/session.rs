//! The editable city behind the API: a [`CityEditor`] (polis' editable city), the output
//! log, and the translation of its [`ChangeEvents`] into what the page needs: only the
//! primary nodes and roads, city cells and block groups that an edit touched.

use std::collections::BTreeSet;
use std::time::Instant;

use polis::editor::{ChangeEvents, CityEditor, Edit, Preview};
use polis::geom::DVec2;
use polis::roads::primary::{ControlId, Correction, RoadId};
use polis::roads::secondary::Neighbourhood;
use polis::{City, CityConfig};
use serde::Serialize;
use serde_json::json;

use crate::api::ApiError;
use crate::wire::{self, CellWire, NodeWire, RoadWire};

/// The most lines the output log keeps.
const LOG_LINES: usize = 1000;

/// An export: bytes, type and file name.
pub struct Export {
    /// The file.
    pub body: Vec<u8>,
    /// Its MIME type.
    pub content_type: &'static str,
    /// The name offered for download.
    pub file_name: &'static str,
}

/// The server's time for one committed edit, milliseconds.
#[derive(Debug, Clone, Copy)]
pub struct Timing {
    /// The editor's share: applying the edit and regenerating what it touched.
    pub edit_ms: f64,
    /// Everything: the edit plus building the delta's JSON.
    pub total_ms: f64,
}

/// The editor session: the city, its revision and the output log.
pub struct Session {
    editor: CityEditor,
    revision: u64,
    log: Vec<String>,
}

/// An error of the library as the page sees it: unknown ids are 404, nothing to undo
/// 409, a refused or invalid edit 422, anything else 500.
fn api_error(e: polis::Error) -> ApiError {
    match e {
        polis::Error::UnknownId { .. } => ApiError::not_found(e.to_string()),
        polis::Error::NothingTo(_) => ApiError::conflict(e.to_string()),
        polis::Error::InvalidEdit { .. } | polis::Error::Roads(_) | polis::Error::Config { .. } => {
            ApiError::refused(e.to_string())
        }
        e => ApiError::internal(e.to_string()),
    }
}

fn to_json<T: Serialize>(v: &T) -> Result<Vec<u8>, ApiError> {
    serde_json::to_vec(v).map_err(|e| ApiError::internal(format!("cannot write JSON: {e}")))
}

/// A pattern's name as the page shows it (`suburbia`, `downtown`, …).
fn pattern_name<T: Serialize>(pattern: &T) -> String {
    serde_json::to_value(pattern)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_else(|| "unknown".to_string())
}

impl Session {
    /// Generates the city of `config` (Citygen road mode); with `empty`, its primary
    /// network is emptied first (the user draws the city from scratch).
    ///
    /// # Errors
    /// A configuration the editor cannot edit, a failing stage.
    pub fn new(config: CityConfig, empty: bool) -> polis::Result<Session> {
        let mut config = config;
        if empty {
            config.citygen.primary = polis::citygen::PrimarySource::Kelly {
                network: polis::citygen::InlinePrimary(Box::default()),
            };
        }
        let started = Instant::now();
        let editor = CityEditor::new(config)?;
        let mut s = Session {
            editor,
            revision: 1,
            log: Vec::new(),
        };
        let ms = started.elapsed().as_secs_f64() * 1e3;
        let line = format!("generated {} in {ms:.0} ms", s.summary());
        s.say(line);
        Ok(s)
    }

    /// Counts for the log.
    pub fn summary(&self) -> String {
        let c = self.editor.city();
        format!(
            "{} primary nodes, {} primary roads, {} city cells, {} road segments, {} lots, {} buildings ({} triangles)",
            self.editor.network().node_count(),
            self.editor.network().road_count(),
            self.editor.cells().len(),
            c.stats.road_segments,
            c.stats.lots,
            c.stats.buildings,
            c.stats.scene_triangles,
        )
    }

    fn say(&mut self, line: String) {
        self.log.push(line);
        if self.log.len() > LOG_LINES {
            self.log.remove(0);
        }
    }

    fn city(&self) -> &City {
        self.editor.city()
    }

    /// The city cells whose ids `want` selects (all for `None`), with their streets.
    fn cells(&self, want: Option<&BTreeSet<u64>>) -> Vec<CellWire> {
        let cells: Vec<_> = self
            .editor
            .cells()
            .into_iter()
            .filter(|c| want.is_none_or(|w| w.contains(&c.id)))
            .collect();
        let outlines: Vec<Vec<DVec2>> = cells
            .iter()
            .map(|c| c.outline.iter().map(|p| DVec2::new(p[0], p[1])).collect())
            .collect();
        // Streets are found among all cells' outlines, so nesting is decided the same
        // way for a delta as for the whole scene.
        let all: Vec<Vec<DVec2>> = match want {
            None => outlines.clone(),
            Some(_) => self
                .editor
                .cells()
                .iter()
                .map(|c| c.outline.iter().map(|p| DVec2::new(p[0], p[1])).collect())
                .collect(),
        };
        let mut streets = wire::streets_in(self.city(), &outlines, &all);
        cells
            .iter()
            .zip(&outlines)
            .zip(streets.iter_mut())
            .map(|((c, o), s)| CellWire {
                id: wire::id(c.id),
                ring: wire::flat(o),
                pattern: pattern_name(&c.pattern),
                streets: std::mem::take(s),
                skipped: c.skipped.clone(),
            })
            .collect()
    }

    /// The whole scene.
    pub fn scene(&mut self) -> Result<Vec<u8>, ApiError> {
        let net = self.editor.network();
        let nodes: Vec<NodeWire> = net.nodes().map(|(id, n)| NodeWire::new(id, n)).collect();
        let roads: Vec<RoadWire> = net.roads().map(|(id, r)| RoadWire::new(id, r)).collect();
        let h = self.editor.config().size_m * 0.5;
        let blocks: Vec<_> = wire::block_groups(self.city(), None)
            .into_values()
            .collect();
        let presets: Vec<String> = Neighbourhood::ALL
            .iter()
            .map(pattern_name)
            .chain(["downtown".to_string(), "residential".to_string()])
            .collect();
        to_json(&json!({
            "revision": self.revision,
            "bounds": [-h, -h, h, h],
            "presets": presets,
            "road_defaults": polis::roads::primary::RoadSpec::default(),
            "nodes": nodes,
            "roads": roads,
            "cells": self.cells(None),
            "blocks": blocks,
            "log": self.log,
        }))
    }

    /// What `edit` would do: the red proposed geometry, the green corrected roads and
    /// the nodes validity checking made or snapped to (Kelly Fig. 69).
    pub fn preview(&mut self, edit: &Edit) -> Result<Vec<u8>, ApiError> {
        let p: Preview = self.editor.propose(edit);
        let net = self.editor.network();
        let pos = |n: u64| net.node(ControlId(n)).ok().map(|n| n.pos);
        let at = |p: &[f64; 2]| DVec2::new(p[0], p[1]);
        let mut proposed: Vec<Vec<DVec2>> = Vec::new();
        let mut nodes: Vec<DVec2> = Vec::new();
        let mut width = None;
        match edit {
            Edit::Chain { from, to, spec } => {
                proposed.extend(pos(*from).map(|a| vec![a, at(to)]));
                width = Some(spec.width_m);
            }
            Edit::MoveNode { node, to } => {
                for r in net.roads_at(ControlId(*node)) {
                    let other = net
                        .road(*r)
                        .ok()
                        .and_then(|r| r.other_end(ControlId(*node)));
                    if let Some(o) = other.and_then(|o| pos(o.0)) {
                        proposed.push(vec![at(to), o]);
                    }
                }
                nodes.push(at(to));
            }
            Edit::AddRoad { from, to, spec } => {
                let end = |e: &polis::editor::End| match e {
                    polis::editor::End::Node(n) => pos(*n),
                    polis::editor::End::At(p) => Some(at(p)),
                };
                if let (Some(a), Some(b)) = (end(from), end(to)) {
                    proposed.push(vec![a, b]);
                }
                width = Some(spec.width_m);
            }
            Edit::AddNode { at: p, .. } => nodes.push(at(p)),
            _ => {}
        }
        for c in &p.corrections {
            nodes.push(match c {
                Correction::SnappedToNode { node, point } => pos(node.0).unwrap_or(*point),
                Correction::OnRoad { at, .. } | Correction::Junction { at, .. } => *at,
            });
        }
        let roads: Vec<_> = p
            .roads
            .iter()
            .filter_map(|r| {
                let path = r.path.as_ref()?;
                let w = width
                    .or_else(|| net.road(RoadId(r.road)).ok().map(|x| x.spec.width_m))
                    .unwrap_or(10.0);
                let pts: Vec<DVec2> = path.iter().map(at).collect();
                Some(json!({ "w": wire::round(w), "pts": wire::flat(&pts) }))
            })
            .collect();
        let proposed: Vec<Vec<f64>> = proposed.iter().map(wire::flat).collect();
        let nodes: Vec<_> = nodes
            .iter()
            .map(|n| json!({ "x": wire::round(n.x), "y": wire::round(n.y) }))
            .collect();
        to_json(&json!({
            "ok": p.valid,
            "message": p.refusal,
            "proposed": proposed,
            "roads": roads,
            "nodes": nodes,
            "cells": p.cells.iter().map(|c| wire::id(*c)).collect::<Vec<_>>(),
            "end_node": p.end_node,
        }))
    }

    /// Commits `edit`; returns the delta and the server's time.
    pub fn apply(&mut self, edit: &Edit) -> Result<(Vec<u8>, Timing), ApiError> {
        let started = Instant::now();
        let end_node = match edit {
            Edit::Chain { .. } | Edit::AddRoad { .. } => self.editor.propose(edit).end_node,
            _ => None,
        };
        let events = self.editor.apply(edit.clone()).map_err(|e| {
            let e = api_error(e);
            self.say(format!("refused: {}", e.message));
            e
        })?;
        let added_node = match edit {
            Edit::AddNode { .. } => events
                .primary
                .as_ref()
                .and_then(|p| p.nodes_added.last().map(|n| n.0)),
            _ => end_node,
        };
        let what = serde_json::to_value(edit)
            .ok()
            .and_then(|v| v.get("op").and_then(|o| o.as_str().map(str::to_string)))
            .unwrap_or_default();
        self.delta(&events, &what, added_node, started)
    }

    /// Undoes the last edit.
    pub fn undo(&mut self) -> Result<(Vec<u8>, Timing), ApiError> {
        let started = Instant::now();
        let events = self.editor.undo().map_err(api_error)?;
        self.delta(&events, "undo", None, started)
    }

    /// Redoes the last undone edit.
    pub fn redo(&mut self) -> Result<(Vec<u8>, Timing), ApiError> {
        let started = Instant::now();
        let events = self.editor.redo().map_err(api_error)?;
        self.delta(&events, "redo", None, started)
    }

    /// The page's delta for `events`: the changed and removed nodes, roads, city cells
    /// and block groups, nothing else.
    fn delta(
        &mut self,
        events: &ChangeEvents,
        what: &str,
        end_node: Option<u64>,
        started: Instant,
    ) -> Result<(Vec<u8>, Timing), ApiError> {
        self.revision += 1;
        let edit_ms = started.elapsed().as_secs_f64() * 1e3;
        let net = self.editor.network();
        let (mut nodes, mut nodes_removed, mut roads, mut roads_removed) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        if let Some(p) = &events.primary {
            for id in p.nodes_added.iter().chain(&p.nodes_moved) {
                match net.node(*id) {
                    Ok(n) => nodes.push(NodeWire::new(*id, n)),
                    Err(_) => nodes_removed.push(id.0),
                }
            }
            nodes_removed.extend(p.nodes_removed.iter().map(|n| n.0));
            for id in p.roads_added.iter().chain(&p.roads_replotted) {
                match net.road(*id) {
                    Ok(r) => roads.push(RoadWire::new(*id, r)),
                    Err(_) => roads_removed.push(id.0),
                }
            }
            roads_removed.extend(p.roads_removed.iter().map(|r| r.0));
        }
        let cell_ids: BTreeSet<u64> = events
            .cells
            .added
            .iter()
            .chain(&events.cells.changed)
            .copied()
            .collect();
        let cells = self.cells(Some(&cell_ids));
        // A block group is re-sent when its blocks, or any of its lots or buildings,
        // changed (a lot's and a building's id carry their road-graph cell: id >> 24).
        let mut block_ids: BTreeSet<u64> = events
            .blocks
            .added
            .iter()
            .chain(&events.blocks.changed)
            .copied()
            .collect();
        for d in [&events.lots, &events.buildings] {
            for id in d.added.iter().chain(&d.changed).chain(&d.removed) {
                block_ids.insert(id >> 24);
            }
        }
        for id in &events.blocks.removed {
            block_ids.remove(id);
        }
        let groups = wire::block_groups(self.city(), Some(&block_ids));
        // A group that lost everything (its lots and buildings removed) is removed.
        let mut blocks_removed: Vec<String> =
            events.blocks.removed.iter().map(|b| wire::id(*b)).collect();
        blocks_removed.extend(
            block_ids
                .iter()
                .filter(|id| !groups.contains_key(id))
                .map(|b| wire::id(*b)),
        );
        let blocks: Vec<_> = groups.into_values().collect();
        let r = &events.regenerated;
        let line = format!(
            "{what}: {edit_ms:.1} ms; regrown {} cells, {} blocks, {} buildings, {} dressed; sent {} nodes, {} roads, {} cells, {} block groups",
            r.cells,
            r.blocks,
            r.buildings,
            r.dresses,
            nodes.len() + nodes_removed.len(),
            roads.len() + roads_removed.len(),
            cells.len() + events.cells.removed.len(),
            blocks.len() + blocks_removed.len(),
        );
        self.say(line.clone());
        let mut log = vec![line];
        for o in &events.orphaned {
            let l = format!("override of lot {} is orphaned (its lot is gone)", o.lot);
            self.say(l.clone());
            log.push(l);
        }
        let body = to_json(&json!({
            "revision": self.revision,
            "end_node": end_node,
            "nodes": nodes,
            "nodes_removed": nodes_removed,
            "roads": roads,
            "roads_removed": roads_removed,
            "cells": cells,
            "cells_removed": events.cells.removed.iter().map(|c| wire::id(*c)).collect::<Vec<_>>(),
            "blocks": blocks,
            "blocks_removed": blocks_removed,
            "log": log,
        }))?;
        let timing = Timing {
            edit_ms,
            total_ms: started.elapsed().as_secs_f64() * 1e3,
        };
        Ok((body, timing))
    }

    /// The cell inspector: the cell's pattern and its generation parameters with their
    /// deviances (Kelly §5.5.1), as the editor would grow it now.
    pub fn cell_info(&self, id: u64) -> Result<Vec<u8>, ApiError> {
        let cell = self
            .editor
            .cells()
            .into_iter()
            .find(|c| c.id == id)
            .ok_or_else(|| ApiError::not_found(format!("no city cell with id {id}")))?;
        let inspected = self
            .editor
            .cell_params(id)
            .map_err(|e| ApiError::not_found(e.to_string()))?;
        let params = &inspected.params;
        let d = |name: &str, label: &str, v: polis::roads::secondary::Deviated| json!({ "name": name, "label": label, "value": v.value, "deviance": v.deviance });
        let plain = |name: &str, label: &str, v: f64, integer: bool| json!({ "name": name, "label": label, "value": v, "deviance": null, "integer": integer });
        let list = vec![
            d("segment_size", "Segment size (m)", params.segment_size_m),
            plain("degree", "Degree", f64::from(params.degree), true),
            plain(
                "degree_deviance",
                "Degree deviance",
                params.degree_deviance,
                false,
            ),
            d("snap_size", "Snap size (m)", params.snap_size_m),
            d("road_width", "Road width (m)", params.road_width_m),
            d("connectivity", "Connectivity", params.connectivity),
            d("lot_size", "Lot size (m)", params.lot_size_m),
            d(
                "building_height",
                "Building height (m)",
                params.building_height_m,
            ),
        ];
        let city = self.city();
        let outline: Vec<DVec2> = cell
            .outline
            .iter()
            .map(|p| DVec2::new(p[0], p[1]))
            .collect();
        let one = std::slice::from_ref(&outline);
        let streets = wire::streets_in(city, one, one);
        let bbox = polis::geom::Aabb2::from_points(outline.iter().copied());
        let inside = |p: Option<&DVec2>| {
            p.is_some_and(|p| bbox.contains(*p) && wire::ring_contains(&outline, *p))
        };
        let lots = city
            .lots
            .iter()
            .filter(|l| inside(l.lot.polygon.points().first()))
            .count();
        let buildings = city
            .buildings
            .iter()
            .filter(|b| inside(b.footprint.points().first()))
            .count();
        to_json(&json!({
            "id": wire::id(id),
            "pattern": pattern_name(&inspected.pattern),
            "params": list,
            "seed": wire::id(inspected.seed),
            "own_seed": inspected.settings.and_then(|s| s.seed).map(wire::id),
            "traits_apply": inspected.traits_apply,
            "lots": lots,
            "buildings": buildings,
            "streets": streets.first().map_or(0, Vec::len),
        }))
    }

    /// The output log.
    pub fn log_json(&self) -> Result<Vec<u8>, ApiError> {
        to_json(&self.log)
    }

    /// The city in one of the library's formats.
    pub fn export(&mut self, format: &str) -> Result<Export, ApiError> {
        use polis::export::{geojson, obj, svg};
        let started = Instant::now();
        let city = self.editor.city();
        let fail = |e: &dyn std::fmt::Display| ApiError::internal(format!("export failed: {e}"));
        let mut body = Vec::new();
        let (content_type, file_name) = match format {
            "glb" => {
                city.write_glb(&mut body).map_err(|e| fail(&e))?;
                ("model/gltf-binary", "city.glb")
            }
            "obj" | "mtl" => {
                let mut mtl = Vec::new();
                let mut sink = |name: &str, data: &[u8]| -> std::io::Result<()> {
                    if name.ends_with(".mtl") {
                        mtl = data.to_vec();
                    }
                    Ok(())
                };
                let options = obj::ObjOptions {
                    stem: "city".into(),
                    texture_dir: polis::TEXTURE_DIR.into(),
                };
                obj::write_obj(&city.scene, &options, &mut body, &mut sink)
                    .map_err(|e| fail(&e))?;
                if format == "mtl" {
                    body = mtl;
                    ("text/plain; charset=utf-8", "city.mtl")
                } else {
                    ("text/plain; charset=utf-8", "city.obj")
                }
            }
            "geojson" | "svg" => {
                let map = city.map_layers().map_err(|e| fail(&e))?;
                if format == "svg" {
                    svg::write_svg(&map, &svg::SvgOptions::default(), &mut body)
                        .map_err(|e| fail(&e))?;
                    ("image/svg+xml", "city.svg")
                } else {
                    geojson::write_geojson(&map, &geojson::GeoJsonOptions::default(), &mut body)
                        .map_err(|e| fail(&e))?;
                    ("application/geo+json", "city.geojson")
                }
            }
            "stats" => {
                let report = city.statistics().map_err(|e| fail(&e))?;
                body = serde_json::to_vec_pretty(&report).map_err(|e| fail(&e))?;
                ("application/json", "report.json")
            }
            other => {
                return Err(ApiError::not_found(format!(
                    "no export format {other:?}: use glb, obj, mtl, geojson, svg or stats"
                )));
            }
        };
        let line = format!(
            "export {file_name}: {} bytes in {:.0} ms",
            body.len(),
            started.elapsed().as_secs_f64() * 1e3
        );
        self.say(line);
        Ok(Export {
            body,
            content_type,
            file_name,
        })
    }
}
