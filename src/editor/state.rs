//! [`CityEditor`]: the state (configuration + primary network), applying edits, undo and
//! redo.

use std::sync::Arc;

use polis_geom::{Aabb2, DVec2};
use polis_roads::primary::{EditOptions, PrimaryEditor, PrimaryNetwork, Terrain};
use serde::{Deserialize, Serialize};

use super::diff::{changes, orphans};
use super::edit::{ChangeEvents, Edit, Preview, PreviewRoad};
use super::memo::Memo;
use super::splice::{OldScene, scene_key};
use crate::citygen::{
    CellPatternChoice, CellSettings, District, InlinePrimary, LotOverride, PrimarySource, RoadMode,
};
use crate::error::{Error, Result};
use crate::{City, CityConfig, CityMaps, KindStyles};

/// A city cell as an editor shows it: its stable id, outline and pattern.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellInfo {
    /// The stable id ([`Edit`]s name cells by it).
    pub id: u64,
    /// The outer ring, metres, counter-clockwise.
    pub outline: Vec<[f64; 2]>,
    /// Its pattern.
    pub pattern: CellPatternChoice,
    /// Why the cell has no secondary roads, if its growth was skipped (the cell is too
    /// small or invalid for its pattern); `None` for a grown cell.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skipped: Option<String>,
}

/// Everything a cell inspector shows of a city cell (Kelly §5.5.1's property inspector):
/// its pattern, the growth parameters it was grown with (each with its deviance, lot
/// size and building height included) and its seed. From
/// [`CityEditor::cell_params`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CellParams {
    /// The stable id.
    pub id: u64,
    /// Its pattern (preset or grid pattern).
    pub pattern: CellPatternChoice,
    /// The growth parameters in metres: the pattern's preset, the road width factor and
    /// the cell's own parameters applied (`{"value": …, "deviance": …}` for each
    /// deviated one; `lot_size_m` and `building_height_m` among them).
    pub params: polis_roads::secondary::SecondaryParams,
    /// The growth seed in effect (the city's, or the cell's own).
    pub seed: u64,
    /// Whether the lot size, building height and hint reach the lot and building stages.
    pub traits_apply: bool,
    /// The cell's settings as edits wrote them (none when unedited).
    pub settings: Option<CellSettings>,
}

/// The settings an edit other than a primary one changes (what undo restores).
#[derive(Debug, Clone, PartialEq)]
struct Settings {
    cells: Vec<CellSettings>,
    lots: Vec<LotOverride>,
    paint: Vec<crate::citygen::MapPaint>,
    style_of: KindStyles,
    lod: Option<usize>,
}

impl Settings {
    fn of(c: &CityConfig) -> Self {
        Settings {
            cells: c.citygen.cells.clone(),
            lots: c.citygen.lots.clone(),
            paint: c.citygen.paint.clone(),
            style_of: c.facades.style_of.clone(),
            lod: c.lod,
        }
    }

    fn write(self, c: &mut CityConfig) {
        c.citygen.cells = self.cells;
        c.citygen.lots = self.lots;
        c.citygen.paint = self.paint;
        c.facades.style_of = self.style_of;
        c.lod = self.lod;
    }
}

/// One step of the history: the edit, and for non-primary edits the settings on the
/// other side of it (before it on the undo stack, after it on the redo stack).
#[derive(Debug, Clone)]
struct Step {
    edit: Edit,
    settings: Option<Settings>,
}

/// An editable Citygen city: see the [module docs](super).
pub struct CityEditor {
    base: CityConfig,
    config: CityConfig,
    primary: PrimaryEditor,
    city: Arc<City>,
    districts: Vec<District>,
    memo: Arc<Memo>,
    undo: Vec<Step>,
    redo: Vec<Step>,
    orphans: Vec<LotOverride>,
    /// Look-ups into `city` for lot edits in place (see `patch.rs`); made on the first
    /// such edit after a pipeline run.
    index: Option<super::patch::Index>,
    /// Failed runs after which the lent scene was put back into the city (no rebuild).
    #[cfg(test)]
    scenes_restored: usize,
}

impl std::fmt::Debug for CityEditor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CityEditor")
            .field("cells", &self.districts.len())
            .field("undo", &self.undo.len())
            .field("redo", &self.redo.len())
            .finish_non_exhaustive()
    }
}

/// The map's square.
fn bounds(config: &CityConfig) -> Aabb2 {
    let h = config.size_m * 0.5;
    Aabb2::new(DVec2::splat(-h), DVec2::splat(h))
}

/// The maps of `config` as the pipeline builds them (paint included).
fn maps_of(config: &CityConfig) -> Result<CityMaps> {
    let mut maps = CityMaps::build(
        &config.maps,
        crate::seed::sub_seed(config.seed, crate::Stage::Maps, 0),
    )?;
    crate::citygen::paint_maps(&mut maps, &config.citygen.paint);
    Ok(maps)
}

fn terrain_of(config: &CityConfig, maps: &CityMaps) -> Result<Terrain> {
    Terrain::new(&maps.inputs, bounds(config))
        .map_err(|e| Error::Roads(polis_roads::RoadError::from(e)))
}

fn road_error(e: polis_roads::PrimaryError) -> Error {
    match e {
        polis_roads::PrimaryError::UnknownNode(n) => Error::UnknownId {
            kind: "node",
            id: n.0,
        },
        polis_roads::PrimaryError::UnknownRoad(r) => Error::UnknownId {
            kind: "road",
            id: r.0,
        },
        e => Error::Roads(polis_roads::RoadError::from(e)),
    }
}

impl CityEditor {
    /// An editor of the city of `config`, which must be in the Citygen road mode. A
    /// primary network that is not a Kelly network (P&M highways, rings, a road graph)
    /// becomes one first ([`PrimaryNetwork::from_highways`]: every chain of highway
    /// segments between junctions a primary road), so the editor's city is the city of
    /// that network, [`config`](Self::config).
    ///
    /// # Errors
    /// [`Error::Config`] for a bad configuration or another road mode; a failing stage.
    pub fn new(mut config: CityConfig) -> Result<Self> {
        config.validate()?;
        if config.road_mode != RoadMode::Citygen {
            return Err(Error::config(
                "road_mode",
                "the editor edits Citygen cities: set road_mode to \"citygen\"",
            ));
        }
        let maps = maps_of(&config)?;
        let terrain = terrain_of(&config, &maps)?;
        let network = match &config.citygen.primary {
            PrimarySource::Kelly { network } => (*network.0).clone(),
            _ => {
                let cx = crate::stages::StageContext {
                    config: &config,
                    maps: &maps,
                };
                crate::citygen::kelly_network_of(&cx, &terrain)?
            }
        };
        config.citygen.primary = PrimarySource::Kelly {
            network: InlinePrimary(Box::new(network.clone())),
        };
        let primary = PrimaryEditor::with_network(network, terrain, EditOptions::default())
            .map_err(road_error)?;
        let memo = Arc::new(Memo::default());
        let (city, districts, _) = build(&memo, &config, None)?;
        let orphans = orphans(&config, &city);
        Ok(CityEditor {
            base: config.clone(),
            config,
            primary,
            city: Arc::new(city),
            districts,
            memo,
            undo: Vec::new(),
            redo: Vec::new(),
            orphans,
            index: None,
            #[cfg(test)]
            scenes_restored: 0,
        })
    }

    /// The city as it stands.
    pub fn city(&self) -> &City {
        &self.city
    }

    /// The configuration of the city as it stands (primary network inline, cell
    /// settings, overrides, paint): [`generate`](crate::generate) of it gives
    /// [`city`](Self::city).
    pub fn config(&self) -> &CityConfig {
        &self.config
    }

    /// The configuration the editor started from (its primary network converted to a
    /// Kelly network).
    pub fn base(&self) -> &CityConfig {
        &self.base
    }

    /// The primary network.
    pub fn network(&self) -> &PrimaryNetwork {
        self.primary.network()
    }

    /// The city cells: the grown ones in the order the road stage made them, then those
    /// whose growth was skipped (with the reason; they stay selectable and editable, so a
    /// pattern too big for a cell can be changed back).
    pub fn cells(&self) -> Vec<CellInfo> {
        self.districts
            .iter()
            .map(|d| CellInfo {
                id: d.id,
                outline: d.region.outer.points().iter().map(|p| [p.x, p.y]).collect(),
                pattern: d.pattern,
                skipped: self
                    .city
                    .report
                    .skipped
                    .iter()
                    .find(|s| s.stage == crate::Stage::Roads && s.id == d.id)
                    .map(|s| s.reason.clone()),
            })
            .collect()
    }

    /// The inspector's view of cell `id`: pattern, parameters with deviances, lot size,
    /// building height, seed.
    ///
    /// # Errors
    /// [`Error::UnknownId`] if no city cell has that id.
    pub fn cell_params(&self, id: u64) -> Result<CellParams> {
        let d = self
            .districts
            .iter()
            .find(|d| d.id == id)
            .ok_or(Error::UnknownId { kind: "cell", id })?;
        Ok(CellParams {
            id,
            pattern: d.pattern,
            params: d.params.clone(),
            seed: d.seed,
            traits_apply: d.traits_apply,
            settings: self
                .config
                .citygen
                .cells
                .iter()
                .find(|c| c.cell == id)
                .cloned(),
        })
    }

    /// The city cell containing `p`, if any.
    pub fn cell_at(&self, p: DVec2) -> Option<u64> {
        crate::citygen::district_at(&self.districts, p).map(|d| d.id)
    }

    /// The lot containing `p`, if any.
    pub fn lot_at(&self, p: DVec2) -> Option<u64> {
        self.city
            .lots
            .iter()
            .find(|l| l.lot.polygon.bbox().contains(p) && l.lot.polygon.contains(p))
            .map(|l| l.id)
    }

    /// Lot overrides that find no lot (neither by id nor by anchor point).
    pub fn orphans(&self) -> &[LotOverride] {
        &self.orphans
    }

    /// Whether there is an edit to undo.
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// Whether there is an edit to redo.
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// The edits in effect, in order.
    pub fn edits(&self) -> Vec<Edit> {
        self.undo.iter().map(|s| s.edit.clone()).collect()
    }

    /// The undone edits that [`redo`](Self::redo) would apply, next first.
    pub fn undone(&self) -> Vec<Edit> {
        self.redo.iter().rev().map(|s| s.edit.clone()).collect()
    }

    /// The editing file of this session: base configuration and edit log.
    pub fn editing_file(&self) -> super::EditingFile {
        super::EditingFile {
            base: self.base.clone(),
            edits: self.edits(),
            undone: self.undone(),
        }
    }

    /// What `edit` would do, without doing it (for a red/green cursor): validity,
    /// corrections, the roads as they would be, the cells touched.
    pub fn propose(&self, edit: &Edit) -> Preview {
        let refused = |e: Error| Preview {
            valid: false,
            refusal: Some(e.to_string()),
            ..Preview::default()
        };
        match edit.to_primary() {
            Err(e) => refused(e),
            Ok(Some(pe)) => match self.primary.propose(&pe) {
                Err(e) => refused(road_error(e)),
                Ok(p) => {
                    let mut touched = Vec::new();
                    let roads = p
                        .roads()
                        .iter()
                        .map(|(id, r)| {
                            if let Some(r) = r {
                                touched.extend(r.path.points.iter().copied());
                            }
                            if let Ok(old) = self.primary.network().road(*id) {
                                touched.extend(old.path.points.iter().copied());
                            }
                            PreviewRoad {
                                road: id.0,
                                path: r
                                    .as_ref()
                                    .map(|r| r.path.points.iter().map(|q| [q.x, q.y]).collect()),
                            }
                        })
                        .collect();
                    for (_, n) in p.nodes() {
                        if let Some(n) = n {
                            touched.push(n.pos);
                        }
                    }
                    Preview {
                        valid: true,
                        refusal: None,
                        corrections: p.corrections().to_vec(),
                        roads,
                        end_node: p.end_node().map(|n| n.0),
                        cells: self.cells_near(&touched),
                    }
                }
            },
            Ok(None) => match self.settings_after(edit) {
                Err(e) => refused(e),
                Ok(_) => Preview {
                    valid: true,
                    cells: self.cells_named(edit),
                    ..Preview::default()
                },
            },
        }
    }

    /// Applies `edit`: the city is regenerated where the edit touches it.
    ///
    /// # Errors
    /// [`Error::UnknownId`], [`Error::InvalidEdit`], a primary-network refusal
    /// ([`Error::Roads`]), or a failing stage; the editor is then unchanged.
    pub fn apply(&mut self, edit: Edit) -> Result<ChangeEvents> {
        let mut config = self.config.clone();
        let (preview, before) = match edit.to_primary()? {
            Some(pe) => {
                let preview = self.primary.propose(&pe).map_err(road_error)?;
                let mut net = self.primary.network().clone();
                net.commit(&preview).map_err(road_error)?;
                config.citygen.primary = PrimarySource::Kelly {
                    network: InlinePrimary(Box::new(net)),
                };
                (Some(preview), None)
            }
            None => {
                let after = self.settings_after(&edit)?;
                let before = Settings::of(&config);
                after.write(&mut config);
                (None, Some(before))
            }
        };
        let mut events = self.rebuild(config)?;
        if let Some(p) = &preview {
            events.primary = Some(self.primary.commit(p).map_err(road_error)?);
        }
        self.undo.push(Step {
            edit,
            settings: before,
        });
        self.redo.clear();
        Ok(events)
    }

    /// Undoes the last edit in effect.
    ///
    /// # Errors
    /// [`Error::NothingTo`] when no edit is in effect; a failing stage (the editor is
    /// then unchanged).
    pub fn undo(&mut self) -> Result<ChangeEvents> {
        let step = self.undo.pop().ok_or(Error::NothingTo("undo"))?;
        match self.step(step, true) {
            Ok((events, step)) => {
                self.redo.push(step);
                Ok(events)
            }
            Err(b) => {
                let (e, step) = *b;
                self.undo.push(step);
                Err(e)
            }
        }
    }

    /// Redoes the last undone edit.
    ///
    /// # Errors
    /// [`Error::NothingTo`] when nothing is undone; a failing stage (the editor is then
    /// unchanged).
    pub fn redo(&mut self) -> Result<ChangeEvents> {
        let step = self.redo.pop().ok_or(Error::NothingTo("redo"))?;
        match self.step(step, false) {
            Ok((events, step)) => {
                self.undo.push(step);
                Ok(events)
            }
            Err(b) => {
                let (e, step) = *b;
                self.redo.push(step);
                Err(e)
            }
        }
    }

    /// Undoes (`back`) or redoes one step; returns the step for the other stack, or the
    /// error and the step unchanged.
    fn step(
        &mut self,
        step: Step,
        back: bool,
    ) -> std::result::Result<(ChangeEvents, Step), Box<(Error, Step)>> {
        let mut config = self.config.clone();
        match &step.settings {
            Some(other) => {
                let here = Settings::of(&config);
                other.clone().write(&mut config);
                match self.rebuild(config) {
                    Ok(events) => Ok((
                        events,
                        Step {
                            edit: step.edit,
                            settings: Some(here),
                        },
                    )),
                    Err(e) => Err(Box::new((e, step))),
                }
            }
            None => {
                let moved = if back {
                    self.primary.undo()
                } else {
                    self.primary.redo()
                };
                let changes = match moved {
                    Ok(c) => c,
                    Err(e) => return Err(Box::new((road_error(e), step))),
                };
                config.citygen.primary = PrimarySource::Kelly {
                    network: InlinePrimary(Box::new(self.primary.network().clone())),
                };
                match self.rebuild(config) {
                    Ok(mut events) => {
                        events.primary = Some(changes);
                        Ok((events, step))
                    }
                    Err(e) => {
                        // Put the network back where the city is.
                        let _ = if back {
                            self.primary.redo()
                        } else {
                            self.primary.undo()
                        };
                        Err(Box::new((e, step)))
                    }
                }
            }
        }
    }

    /// Builds the city of `config` through the memo and, on success, makes it the
    /// editor's; returns what changed.
    fn rebuild(&mut self, config: CityConfig) -> Result<ChangeEvents> {
        if let Some(events) = self.patch(&config) {
            return Ok(events);
        }
        self.index = None;
        let maps_changed = self.maps_changed(&config);
        // Leaves of the scene whose inputs the edit left alone are spliced in from the
        // scene as it stands.
        let reuse = match (scene_key(&self.config), scene_key(&config)) {
            (Some(a), Some(b)) if a == b && !self.city.scene.nodes.is_empty() => {
                // The meshes and the leaves' names move into the splice (the city keeps
                // its node tree).
                Arc::get_mut(&mut self.city)
                    .map(OldScene::lend)
                    .map(|lent| {
                        Arc::new(OldScene::new(
                            Arc::clone(&self.city),
                            lent,
                            Arc::clone(&self.memo),
                        ))
                    })
            }
            _ => None,
        };
        let (city, districts, redone) = match build(&self.memo, &config, reuse.clone()) {
            Ok(built) => built,
            Err(e) => {
                self.restore(reuse)?;
                return Err(e);
            }
        };
        let mut events = changes(
            &self.city,
            &city,
            &self.districts,
            &districts,
            &redone,
            reuse.as_deref(),
        );
        let orphans = orphans(&config, &city);
        events.orphaned.clone_from(&orphans);
        if maps_changed {
            // New legality for later road edits (the maps were painted).
            let maps = maps_of(&config)?;
            self.primary.set_terrain(terrain_of(&config, &maps)?);
        }
        let old = std::mem::replace(&mut self.city, Arc::new(city));
        drop_later((old, reuse));
        self.districts = districts;
        self.config = config;
        self.orphans = orphans;
        Ok(events)
    }

    /// After a failed run: the meshes and leaf names the splice took put back into the
    /// city, or, where a leaf had taken some (the run failed while the scene was
    /// assembled), the city made again of the configuration as it stands (the memo holds
    /// every result of it, so only the scene is made anew).
    fn restore(&mut self, reuse: Option<Arc<OldScene>>) -> Result<()> {
        let Some(reuse) = reuse else { return Ok(()) };
        // The pipeline has let go of the splice, so this is its only reference; the
        // splice lets go of its reference to the city before writing to it.
        if let Ok(reuse) = Arc::try_unwrap(reuse)
            && reuse.restore(&mut self.city)
        {
            #[cfg(test)]
            {
                self.scenes_restored += 1;
            }
            return Ok(());
        }
        self.index = None;
        let (city, _, _) = build(&self.memo, &self.config, None)?;
        self.city = Arc::new(city);
        Ok(())
    }

    /// An edit of lot overrides only, made in place in the city (see `patch.rs`);
    /// `None` where the patch declines and the pipeline must run.
    fn patch(&mut self, config: &CityConfig) -> Option<ChangeEvents> {
        if !super::patch::lots_only(&self.config, config) {
            return None;
        }
        let city = Arc::get_mut(&mut self.city)?;
        let index = self
            .index
            .get_or_insert_with(|| super::patch::Index::of(city));
        let (events, orphans) = super::patch::patch_lots(
            city,
            index,
            config,
            &self.districts,
            &self.memo,
            &self.orphans,
        )?;
        self.config = config.clone();
        self.orphans = orphans;
        Some(events)
    }

    fn maps_changed(&self, config: &CityConfig) -> bool {
        config.citygen.paint != self.config.citygen.paint
    }

    /// The settings after a non-primary edit, validated against the city as it stands.
    fn settings_after(&self, edit: &Edit) -> Result<Settings> {
        let mut s = Settings::of(&self.config);
        match edit {
            Edit::SetCellPattern { cell, pattern } => {
                self.check_cell(*cell)?;
                cell_settings(&mut s.cells, *cell).pattern = Some(*pattern);
            }
            Edit::SetCellParam { cell, param } => {
                self.check_cell(*cell)?;
                param.validate()?;
                cell_settings(&mut s.cells, *cell).set(*param);
            }
            Edit::SetCellSeed { cell, seed } => {
                self.check_cell(*cell)?;
                cell_settings(&mut s.cells, *cell).seed = Some(*seed);
            }
            Edit::ResetCell { cell } => {
                self.check_cell(*cell)?;
                s.cells.retain(|c| c.cell != *cell);
            }
            Edit::PinKind { lot, kind } => {
                self.lot_override(&mut s.lots, *lot)?.kind = Some(*kind);
            }
            Edit::PinHeight { lot, height_m } => {
                let h = *height_m;
                if !(h.is_finite() && h > 0.0 && h <= crate::MAX_BUILDING_HEIGHT_M) {
                    return Err(Error::InvalidEdit {
                        field: "height_m".into(),
                        reason: format!("{h}: give a height in (0, 1000] m"),
                    });
                }
                self.lot_override(&mut s.lots, *lot)?.height_m = Some(h);
            }
            Edit::PinStyle { lot, style } => {
                self.check_style(style)?;
                self.lot_override(&mut s.lots, *lot)?.style = Some(style.clone());
            }
            Edit::RemoveBuilding { lot } => {
                self.lot_override(&mut s.lots, *lot)?.removed = true;
            }
            Edit::ReseedLot { lot, seed } => {
                self.lot_override(&mut s.lots, *lot)?.seed = Some(*seed);
            }
            Edit::ClearLot { lot } => {
                self.check_lot(*lot)?;
                s.lots.retain(|o| o.lot != *lot);
            }
            Edit::Paint {
                layer,
                min,
                max,
                value,
            } => {
                let p = crate::citygen::MapPaint {
                    layer: *layer,
                    min: *min,
                    max: *max,
                    value: *value,
                };
                p.validate(self.config.size_m)?;
                s.paint.push(p);
            }
            Edit::SetFacadeStyle { kind, style } => {
                self.check_style(style)?;
                set_style(&mut s.style_of, *kind, style.clone());
            }
            Edit::SetLod { lod } => {
                let max = self.config.buildings.max_lod;
                if lod.is_some_and(|l| l > max) {
                    return Err(Error::InvalidEdit {
                        field: "lod".into(),
                        reason: format!("give a level of detail up to buildings.max_lod ({max})"),
                    });
                }
                s.lod = *lod;
            }
            _ => {
                return Err(Error::InvalidEdit {
                    field: "op".into(),
                    reason: "not a settings edit".into(),
                });
            }
        }
        Ok(s)
    }

    fn check_cell(&self, id: u64) -> Result<()> {
        if self.districts.iter().any(|d| d.id == id) {
            Ok(())
        } else {
            Err(Error::UnknownId { kind: "cell", id })
        }
    }

    fn check_lot(&self, id: u64) -> Result<&crate::CityLot> {
        self.city
            .lots
            .iter()
            .find(|l| l.id == id)
            .ok_or(Error::UnknownId { kind: "lot", id })
    }

    fn check_style(&self, style: &str) -> Result<()> {
        let known = self.config.facades.styles.iter().any(|s| s.name == style)
            || polis_facades::builtin::builtin_style(style).is_some();
        if known {
            Ok(())
        } else {
            Err(Error::InvalidEdit {
                field: "style".into(),
                reason: format!("no style named {style:?} (built in or in facades.styles)"),
            })
        }
    }

    /// The override of lot `id` in `lots`, made (anchored at the lot) if new.
    fn lot_override<'a>(
        &self,
        lots: &'a mut Vec<LotOverride>,
        id: u64,
    ) -> Result<&'a mut LotOverride> {
        let lot = self.check_lot(id)?;
        let i = match lots.iter().position(|o| o.lot == id) {
            Some(i) => i,
            None => {
                lots.push(LotOverride::new(id, anchor(&lot.lot.polygon)));
                lots.len() - 1
            }
        };
        lots.get_mut(i).ok_or(Error::UnknownId { kind: "lot", id })
    }

    /// Cells within reach of `points` (their outer box holds one), ids increasing.
    fn cells_near(&self, points: &[DVec2]) -> Vec<u64> {
        let mut out: Vec<u64> = self
            .districts
            .iter()
            .filter(|d| {
                let bb = d.region.outer.bbox();
                points.iter().any(|&p| bb.contains(p))
            })
            .map(|d| d.id)
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Cells a non-primary edit names.
    fn cells_named(&self, edit: &Edit) -> Vec<u64> {
        let lot_cell = |lot: u64| {
            self.city
                .lots
                .iter()
                .find(|l| l.id == lot)
                .and_then(|l| self.cell_at(anchor(&l.lot.polygon)))
        };
        match edit {
            Edit::SetCellPattern { cell, .. }
            | Edit::SetCellParam { cell, .. }
            | Edit::SetCellSeed { cell, .. }
            | Edit::ResetCell { cell } => vec![*cell],
            Edit::PinKind { lot, .. }
            | Edit::PinHeight { lot, .. }
            | Edit::PinStyle { lot, .. }
            | Edit::RemoveBuilding { lot }
            | Edit::ReseedLot { lot, .. }
            | Edit::ClearLot { lot } => lot_cell(*lot).into_iter().collect(),
            Edit::Paint { min, max, .. } => {
                let r = Aabb2::new(DVec2::new(min[0], min[1]), DVec2::new(max[0], max[1]));
                let mut v: Vec<u64> = self
                    .districts
                    .iter()
                    .filter(|d| d.region.outer.bbox().intersects(&r))
                    .map(|d| d.id)
                    .collect();
                v.sort_unstable();
                v
            }
            _ => self.districts.iter().map(|d| d.id).collect(),
        }
    }
}

/// A point inside a lot to anchor its override at: the centroid if inside, else the
/// centroid of the first ear that is.
pub(crate) fn anchor(polygon: &polis_geom::Polygon) -> DVec2 {
    let c = polygon.centroid();
    if polygon.contains(c) {
        return c;
    }
    let pts = polygon.points();
    let n = pts.len();
    (0..n)
        .map(|i| (pts[(i + n - 1) % n] + pts[i] + pts[(i + 1) % n]) / 3.0)
        .find(|&q| polygon.contains(q))
        .unwrap_or(c)
}

/// The settings of `cell` in `cells`, made if new.
fn cell_settings(cells: &mut Vec<CellSettings>, cell: u64) -> &mut CellSettings {
    let i = match cells.iter().position(|c| c.cell == cell) {
        Some(i) => i,
        None => {
            cells.push(CellSettings::new(cell));
            cells.len() - 1
        }
    };
    &mut cells[i]
}

fn set_style(styles: &mut KindStyles, kind: polis_buildings::BuildingKind, style: String) {
    use polis_buildings::BuildingKind as K;
    match kind {
        K::Skyscraper => styles.skyscraper = style,
        K::Office => styles.office = style,
        K::MidRise => styles.mid_rise = style,
        K::House => styles.house = style,
        K::Apartment => styles.apartment = style,
        K::Industrial => styles.industrial = style,
    }
}

/// Runs the memoised pipeline on `config`.
/// Drops `v` on a thread of its own: freeing the city before an edit (every layer and
/// mesh of it) is taken off the edit's path. Where no thread can be started it is
/// dropped here.
fn drop_later<T: Send + 'static>(v: T) {
    // On failure the closure, and `v` with it, is dropped by `spawn` itself.
    let _ = std::thread::Builder::new()
        .name("polis-editor-drop".into())
        .spawn(move || drop(v));
}

fn build(
    memo: &Arc<Memo>,
    config: &CityConfig,
    reuse: Option<Arc<OldScene>>,
) -> Result<(City, Vec<District>, super::memo::Redone)> {
    memo.begin(config);
    let mut pipeline = memo.pipeline();
    if let Some(r) = reuse {
        pipeline = pipeline.with_scene_reuse(r);
    }
    let result = pipeline.generate(config);
    let (redone, districts) = memo.finish(result.is_ok());
    Ok((result?, districts, redone))
}

// The city is compared through its glb and GeoJSON bytes.
#[cfg(all(test, feature = "gltf", feature = "geojson"))]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]

    use super::*;

    /// A small Citygen city at one level of detail.
    fn small() -> CityConfig {
        let mut c = crate::citygen::tests::small_rings();
        c.lod = Some(1);
        c
    }

    /// The city's glb and GeoJSON bytes.
    fn bytes(city: &City) -> (Vec<u8>, Vec<u8>) {
        let mut glb = Vec::new();
        city.write_glb(&mut glb).unwrap();
        let mut geojson = Vec::new();
        polis_export::geojson::write_geojson(
            &city.map_layers().unwrap(),
            &polis_export::geojson::GeoJsonOptions::default(),
            &mut geojson,
        )
        .unwrap();
        (glb, geojson)
    }

    fn fail_growth(ed: &CityEditor, cell: Option<u64>) {
        *ed.memo
            .fail_growth
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = cell;
    }

    /// A run that fails in growth, after the scene was lent to the splice, gives the
    /// scene back to the city as it was: the same city (no rebuild, no second run),
    /// byte for byte, and a typed error; for an edit and for an undo.
    #[test]
    fn a_failed_run_puts_the_lent_scene_back_without_a_rebuild() {
        let mut ed = CityEditor::new(small()).unwrap();
        let cell = ed
            .cells()
            .into_iter()
            .find(|c| c.skipped.is_none())
            .expect("a grown cell")
            .id;
        let config = ed.config().clone();
        let before = bytes(ed.city());
        assert!(!ed.city.scene.meshes.is_empty());

        // An edit that regrows `cell`: the splice takes the scene, growth fails.
        let edit = Edit::SetCellSeed { cell, seed: 7 };
        let city = Arc::as_ptr(&ed.city);
        fail_growth(&ed, Some(cell));
        let err = ed.apply(edit.clone()).unwrap_err();
        assert!(
            matches!(
                err,
                Error::Roads(polis_roads::RoadError::InvalidParameter { .. })
            ),
            "{err}"
        );
        assert_eq!(ed.scenes_restored, 1, "the lent scene was put back");
        assert!(std::ptr::eq(Arc::as_ptr(&ed.city), city), "not rebuilt");
        assert_eq!(ed.config(), &config);
        assert!(ed.edits().is_empty());
        assert!(bytes(ed.city()) == before, "the city is unchanged");

        // The editor goes on from there: the edit made without the failure is the city
        // `generate` makes.
        fail_growth(&ed, None);
        ed.apply(edit).unwrap();
        let edited = bytes(ed.city());
        assert!(edited != before, "the seed regrew the cell");
        assert!(edited == bytes(&crate::generate(ed.config()).unwrap()));

        // An undo that fails in growth leaves the edit in effect and the city as it was.
        let city = Arc::as_ptr(&ed.city);
        fail_growth(&ed, Some(cell));
        let err = ed.undo().unwrap_err();
        assert!(matches!(err, Error::Roads(_)), "{err}");
        assert_eq!(ed.scenes_restored, 2);
        assert!(std::ptr::eq(Arc::as_ptr(&ed.city), city), "not rebuilt");
        assert_eq!(ed.edits().len(), 1);
        assert!(bytes(ed.city()) == edited, "the city is unchanged");
        fail_growth(&ed, None);
        ed.undo().unwrap();
        assert!(bytes(ed.city()) == before, "undo gives the first city back");
    }

    /// The wall time of an edit that fails in growth on the `citygen` preset, one per
    /// grown cell of the first 9 (see BENCHMARKS.md, issue 20 session 17):
    /// `cargo test --release --lib -- --ignored --nocapture failed_edit_wall_time`.
    #[test]
    #[ignore = "a timing, run by hand"]
    fn failed_edit_wall_time() {
        let mut ed = CityEditor::new(CityConfig::preset("citygen").unwrap()).unwrap();
        let cells: Vec<u64> = ed
            .cells()
            .into_iter()
            .filter(|c| c.skipped.is_none())
            .map(|c| c.id)
            .take(9)
            .collect();
        let mut ms = Vec::new();
        for &cell in &cells {
            fail_growth(&ed, Some(cell));
            let t = crate::clock::Instant::now();
            let failed = ed.apply(Edit::SetCellSeed { cell, seed: 7 });
            ms.push(t.elapsed().as_secs_f64() * 1e3);
            assert!(failed.is_err());
        }
        assert_eq!(ed.scenes_restored, cells.len(), "every scene put back");
        ms.sort_by(f64::total_cmp);
        eprintln!(
            "failed edit, {} cells: min {:.1} ms, median {:.1} ms, max {:.1} ms",
            ms.len(),
            ms[0],
            ms[ms.len() / 2],
            ms[ms.len() - 1]
        );
    }
}
