//! The editor's memo: the pipeline's own stages wrapped so that each piece of per-item
//! work (a city cell's secondary growth, a road-graph cell's blocks and lots, a lot's
//! building, a building's skin) is looked up by the exact digest of everything it reads
//! ([`Key`]) and done only when that digest is new. A road-graph cell's buildings and
//! skins are kept whole as well ([`CellReuse`]): a cell whose key is known takes them in
//! one look-up, without planning, keying or looking up each lot.
//!
//! Because every stage is a deterministic function of those inputs, a reused result is
//! bit for bit what the stage would make again: the edited city is the city
//! [`generate`](crate::generate) makes of the same configuration, and the dirty set of an
//! edit is exactly the work whose inputs it changed. After each run the memo keeps what
//! that run used (the current city), so memory stays one city's worth of results.

use std::collections::{BTreeSet, HashMap};
use std::hash::{Hash, Hasher};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use polis_buildings::Building;
use polis_roads::secondary::SecondaryRoads;

use super::key::{IdMap, Key};
use crate::citygen::{ConfiguredRoads, GrowthMemo, RoadMode, citygen_network_with};
use crate::error::Result;
use crate::ground::TerrainTiles;
use crate::pipeline::{CellBuilt, CellReuse};
use crate::scene::GroundReuse;
use crate::stages::{
    BuildLot, BuildingStage, CellInput, CellLots, CellStage, Dress, DressBuilding, EberlyCells,
    FacadeStage, KellyLots, LotInput, LotStage, RoadStage, RoadsOutput, Skip, StageContext,
};

/// Results of one kind, each behind an `Arc` with the number of the last run that used
/// it: a look-up holds the lock for a pointer copy only and the caller copies the result
/// out of it with the lock released (the per-item stages look up from both threads).
/// After a successful run the store keeps what that run used (looked up, made, or
/// touched through a road-graph cell's whole result: [`Memo::touch_cell`]), so memory
/// stays one city's worth of results.
///
/// The map is a hash map on the keys' own bits (keys are digests already); it is
/// looked up and pruned, never iterated into an output.
struct Store<T> {
    map: HashMap<Key, Arc<Entry<T>>, KeyBits>,
    /// The number of the current run.
    run: u64,
    /// Whether this run looked anything up or made anything.
    used: bool,
}

/// A result in a [`Store`] and the number of the last run that used it.
pub(crate) struct Entry<T> {
    value: T,
    used: AtomicU64,
}

impl<T> Entry<T> {
    /// Marks the entry used by run `run`.
    fn touch(&self, run: u64) {
        self.used.store(run, Ordering::Relaxed);
    }
}

impl<T> Default for Store<T> {
    fn default() -> Self {
        Store {
            map: HashMap::default(),
            run: 0,
            used: false,
        }
    }
}

/// Hashes a [`Key`] by its own bits (it is a digest).
#[derive(Debug, Clone, Copy, Default)]
struct KeyBits;

impl std::hash::BuildHasher for KeyBits {
    type Hasher = KeyBitsHasher;
    fn build_hasher(&self) -> KeyBitsHasher {
        KeyBitsHasher(0)
    }
}

/// The hasher of [`KeyBits`]: the words written, folded.
struct KeyBitsHasher(u64);

impl Hasher for KeyBitsHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = self.0.rotate_left(29) ^ v;
    }
}

impl<T> Store<T> {
    /// Starts run `run`.
    fn begin(&mut self, run: u64) {
        self.run = run;
        self.used = false;
    }

    /// The result for `key`, if a run kept it (marked used by this one).
    fn get(&mut self, key: Key) -> Option<Arc<Entry<T>>> {
        let e = self.map.get(&key)?;
        e.touch(self.run);
        self.used = true;
        Some(Arc::clone(e))
    }

    /// Keeps `value` for `key` (used by this run).
    fn put(&mut self, key: Key, value: T) -> Arc<Entry<T>> {
        let e = Arc::new(Entry {
            value,
            used: AtomicU64::new(self.run),
        });
        self.map.insert(key, Arc::clone(&e));
        self.used = true;
        e
    }

    /// The entries of `keys` that the store holds, in order (none marked used).
    fn entries(&self, keys: &[Key]) -> Vec<Arc<Entry<T>>> {
        keys.iter()
            .filter_map(|k| self.map.get(k).cloned())
            .collect()
    }

    /// Ends a run: keep what it used (`touched`: some entries were marked used through
    /// a cell's whole result), or, after a failed run or one that skipped this kind of
    /// work (such as growth when the road stage was reused whole), everything.
    fn finish(&mut self, ok: bool, touched: bool) {
        if ok && (self.used || touched) {
            let run = self.run;
            self.map
                .retain(|_, e| e.used.load(Ordering::Relaxed) == run);
        }
    }
}

/// What one run redid: the ids of the items whose work was done again.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Redone {
    /// City cells grown.
    pub cells: BTreeSet<u64>,
    /// Road-graph cells subdivided.
    pub blocks: BTreeSet<u64>,
    /// Buildings built (by the id the grammar was seeded with).
    pub buildings: usize,
    /// Buildings dressed.
    pub dresses: usize,
}

/// Per building id: the key its building was built from (recorded under the id the
/// grammar was seeded with, which is the building's own id unless its lot was reseeded)
/// and the key its skin was made from; for the last run and this one. Equal keys of an
/// id in both runs mean an equal building and skin (each is a function of its key), which
/// lets the scene splice skip comparing them. A reseeded lot's building finds no key
/// under its own id (unless another reseeded lot's seed id collides with it, a chance of
/// about n / 2⁶⁴), and is compared in full.
#[derive(Default)]
struct IdKeys {
    last_built: IdMap<Key>,
    this_built: IdMap<Key>,
    last_dressed: IdMap<Key>,
    this_dressed: IdMap<Key>,
}

/// Fingerprints of the configuration parts each stage reads besides its item.
#[derive(Debug, Clone, Copy)]
struct Fingerprints {
    /// Everything the road and cell stages read: the configuration but for the lot
    /// overrides, the facade settings and the level of detail (the edits of lots,
    /// buildings and styles), which only later stages read.
    roads: Key,
    lots: Key,
    buildings: Key,
    facades: Key,
    /// Everything a road-graph cell's buildings and skins read of the configuration
    /// besides the cell's input, its city cells and its lot overrides: the
    /// configuration but for the primary network, the per-cell settings and the lot
    /// overrides (which reach them only through those), with the pinned styles.
    plan: Key,
    /// What the terrain reads of the configuration: all of it but the Citygen settings
    /// (none of which reaches the elevation or water maps).
    ground: Key,
}

/// The memo shared by the wrapped stages of one editor.
#[derive(Default)]
pub(crate) struct Memo {
    growth: Mutex<Store<std::result::Result<Arc<SecondaryRoads>, Skip>>>,
    lots: Mutex<Store<CellLots>>,
    buildings: Mutex<Store<Option<Arc<Building>>>>,
    dresses: Mutex<Store<Option<Arc<Dress>>>>,
    /// The last terrain made, by [`Fingerprints::ground`] and the water bed's digest.
    terrain: Mutex<Option<(Key, TerrainTiles)>>,
    /// The water bodies and shores of the last run, by [`Fingerprints::ground`].
    water: Mutex<Option<(Key, Arc<crate::water::WaterBase>)>>,
    /// Road-graph cells' buildings and skins, whole (see [`WholeCell`]).
    whole: Mutex<Store<WholeCell>>,
    /// The number of the current run.
    run: AtomicU64,
    /// Whether this run took a cell whole (and so marked its buildings and skins used).
    touched: AtomicBool,
    dresser: Mutex<Option<(Key, Arc<dyn DressBuilding>)>>,
    /// The building generator of the last run (its grammars parsed), by
    /// [`Fingerprints::buildings`].
    builder: Mutex<Option<(Key, Arc<dyn BuildLot>)>>,
    redone: Mutex<Redone>,
    /// The input keys of each building and skin, by the building's id (see [`IdKeys`]).
    ids: Mutex<IdKeys>,
    districts: Mutex<Vec<crate::citygen::District>>,
    fingerprints: Mutex<Option<Fingerprints>>,
    /// The last run's road stage output and cells, by [`Fingerprints::roads`]: an edit of
    /// lots, buildings or styles reuses the union graph and its cells whole.
    /// With the output, every city cell (grown, then ungrown) for the editor.
    roads: Mutex<Option<(Key, RoadsOutput, Vec<crate::citygen::District>)>>,
    cells: Mutex<Option<(Key, polis_cells::CellDecomposition)>>,
    /// A test's injected failure: the city cell whose growth fails when it is grown
    /// (not when its roads are taken from the memo), as a stage error would.
    #[cfg(test)]
    pub(super) fail_growth: Mutex<Option<u64>>,
}

/// A road-graph cell's buildings and skins, with the memo's entries of each (so a run
/// that takes the cell whole marks them used, and the stores keep them for a later run
/// that makes the cell again from some of the same lots).
struct WholeCell {
    built: Arc<CellBuilt>,
    buildings: Vec<Arc<Entry<Option<Arc<Building>>>>>,
    dresses: Vec<Arc<Entry<Option<Arc<Dress>>>>>,
}

/// Writes serialised bytes into a [`Key`].
struct KeyWriter(Key);

impl std::io::Write for KeyWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0 = self.0.bytes(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The digest of what the road and cell stages read of `config` (see
/// [`Fingerprints::roads`]); `None` if it cannot be serialised (the stages then run).
fn roads_key(config: &crate::CityConfig) -> Option<Key> {
    let mut c = config.clone();
    c.citygen.lots.clear();
    c.facades = Default::default();
    c.lod = None;
    let mut w = KeyWriter(Key::new(0x726F_6164));
    serde_json::to_writer(&mut w, &c).ok()?;
    Some(w.0)
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panic while holding a lock cannot leave a store half-written (each operation is
    // one insert or remove), so a poisoned lock is still usable.
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Feeds std `Hash` values into a [`Key`].
struct KeyHasher(Key);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        0
    }
    fn write(&mut self, bytes: &[u8]) {
        self.0 = self.0.bytes(bytes);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = self.0.u64(v);
    }
}

fn hashed(k: Key, v: &impl Hash) -> Key {
    let mut h = KeyHasher(k);
    v.hash(&mut h);
    h.0
}

/// The digest of what the facade stage reads of `config`: the facade settings, the
/// pinned styles and the seed.
fn facades_key(config: &crate::CityConfig) -> Key {
    let pinned: Vec<&str> = config
        .citygen
        .lots
        .iter()
        .filter_map(|o| o.style.as_deref())
        .collect();
    Key::new(3).bytes(format!("{:?}|{:?}|{}", config.facades, pinned, config.seed).as_bytes())
}

impl Memo {
    /// Whether building `id` and its skin were made from the same keys in the last run
    /// and in this one (so they are equal): `None` where either run has no key for it.
    pub(crate) fn same_keys(&self, id: u64) -> Option<bool> {
        let ids = lock(&self.ids);
        let built = (ids.last_built.get(&id)?, ids.this_built.get(&id)?);
        let dressed = (ids.last_dressed.get(&id)?, ids.this_dressed.get(&id)?);
        Some(built.0 == built.1 && dressed.0 == dressed.1)
    }

    /// Forgets the last run's keys of buildings `ids` (changed outside a run, by a lot
    /// edit made in place).
    pub(crate) fn forget(&self, ids: impl IntoIterator<Item = u64>) {
        let mut keys = lock(&self.ids);
        for id in ids {
            keys.last_built.remove(&id);
            keys.last_dressed.remove(&id);
        }
    }

    /// The facade stage's dresser of the last run, if `config`'s facade inputs are that
    /// run's (for dressing a building outside a run).
    pub(crate) fn dresser_for(&self, config: &crate::CityConfig) -> Option<Arc<dyn DressBuilding>> {
        let key = facades_key(config);
        match &*lock(&self.dresser) {
            Some((k, d)) if *k == key => Some(Arc::clone(d)),
            _ => None,
        }
    }

    /// Starts a run on `config`: fingerprints of what the stages read globally.
    pub(crate) fn begin(&self, config: &crate::CityConfig) {
        let run = self.run.fetch_add(1, Ordering::Relaxed) + 1;
        let text = |salt: u64, s: String| Key::new(salt).bytes(s.as_bytes());
        *lock(&self.fingerprints) = Some(Fingerprints {
            roads: roads_key(config).unwrap_or(Key::new(config.seed)),
            lots: text(
                1,
                format!("{:?}|{:?}|{}", config.blocks, config.lots, config.seed),
            ),
            buildings: text(
                2,
                format!("{:?}|{}", config.effective_building_params(), config.seed),
            ),
            facades: facades_key(config),
            // Not serialisable: a key of this run alone (no cell is taken whole).
            plan: plan_key(config).unwrap_or(Key::new(0x706C_616E).u64(run)),
            ground: ground_key(config).unwrap_or(Key::new(0x6772_6F75).u64(run)),
        });
        *lock(&self.redone) = Redone::default();
        self.touched.store(false, Ordering::Relaxed);
        lock(&self.growth).begin(run);
        lock(&self.lots).begin(run);
        lock(&self.buildings).begin(run);
        lock(&self.dresses).begin(run);
        lock(&self.whole).begin(run);
    }

    /// Ends a run (see [`Store::finish`]) and returns what it redid and the city cells
    /// its road stage made.
    pub(crate) fn finish(&self, ok: bool) -> (Redone, Vec<crate::citygen::District>) {
        {
            let mut ids = lock(&self.ids);
            let this_built = std::mem::take(&mut ids.this_built);
            let this_dressed = std::mem::take(&mut ids.this_dressed);
            if ok {
                ids.last_built = this_built;
                ids.last_dressed = this_dressed;
            }
        }
        let touched = self.touched.load(Ordering::Relaxed);
        lock(&self.growth).finish(ok, false);
        lock(&self.lots).finish(ok, false);
        lock(&self.buildings).finish(ok, touched);
        lock(&self.dresses).finish(ok, touched);
        lock(&self.whole).finish(ok, false);
        (
            std::mem::take(&mut *lock(&self.redone)),
            std::mem::take(&mut *lock(&self.districts)),
        )
    }

    fn fingerprints(&self) -> Fingerprints {
        lock(&self.fingerprints).unwrap_or(Fingerprints {
            roads: Key::new(0),
            lots: Key::new(1),
            buildings: Key::new(2),
            facades: Key::new(3),
            plan: Key::new(4),
            ground: Key::new(5),
        })
    }

    /// The pipeline with every stage wrapped.
    pub(crate) fn pipeline(self: &Arc<Self>) -> crate::Pipeline {
        crate::Pipeline::default()
            .with_roads(MemoRoads(Arc::clone(self)))
            .with_cells(MemoCells(Arc::clone(self)))
            .with_lots(MemoLots(Arc::clone(self)))
            .with_buildings(MemoBuildings(Arc::clone(self)))
            .with_facades(MemoFacades(Arc::clone(self)))
            .with_cell_reuse(Arc::clone(self) as Arc<dyn CellReuse>)
            .with_terrain_reuse(Arc::clone(self) as Arc<dyn GroundReuse + Send>)
    }
}

impl GrowthMemo for Memo {
    fn grow(
        &self,
        id: u64,
        key: Key,
        grow: &(dyn Fn() -> Result<std::result::Result<SecondaryRoads, Skip>> + Sync),
    ) -> Result<std::result::Result<Arc<SecondaryRoads>, Skip>> {
        let hit = lock(&self.growth).get(key);
        if let Some(v) = hit {
            return Ok(v.value.clone());
        }
        #[cfg(test)]
        if *lock(&self.fail_growth) == Some(id) {
            return Err(crate::Error::Roads(
                polis_roads::RoadError::InvalidParameter {
                    name: "secondary",
                    reason: format!("cell {id}: a growth failure injected by a test"),
                },
            ));
        }
        let v = grow()?.map(Arc::new);
        lock(&self.growth).put(key, v.clone());
        lock(&self.redone).cells.insert(id);
        Ok(v)
    }
}

impl CellReuse for Memo {
    fn district_key(&self, d: &crate::citygen::District) -> Key {
        Key::new(0x6469_7374)
            .u64(d.id)
            .u64(u64::from(d.traits_apply))
            .bytes(format!("{:?}", d.traits).as_bytes())
            .region(&d.region)
    }

    fn cell_key(&self, input: &CellInput<'_>) -> Key {
        let fp = self.fingerprints();
        Key::new(0x6365_6C6C)
            .key(lots_key(fp.lots, input))
            .key(fp.plan)
    }

    fn get(&self, key: Key) -> Option<Arc<CellBuilt>> {
        let cell = lock(&self.whole).get(key)?;
        let run = self.run.load(Ordering::Relaxed);
        for e in &cell.value.buildings {
            e.touch(run);
        }
        for e in &cell.value.dresses {
            e.touch(run);
        }
        self.touched.store(true, Ordering::Relaxed);
        Some(Arc::clone(&cell.value.built))
    }

    fn put(&self, key: Key, cell: CellBuilt, build_ids: &[u64]) {
        let (built, dressed): (Vec<Key>, Vec<Key>) = {
            let ids = lock(&self.ids);
            (
                build_ids
                    .iter()
                    .filter_map(|id| ids.this_built.get(id).copied())
                    .collect(),
                cell.buildings
                    .iter()
                    .filter_map(|b| ids.this_dressed.get(&b.id).copied())
                    .collect(),
            )
        };
        let buildings = lock(&self.buildings).entries(&built);
        let dresses = lock(&self.dresses).entries(&dressed);
        lock(&self.whole).put(
            key,
            WholeCell {
                built: Arc::new(cell),
                buildings,
                dresses,
            },
        );
    }
}

struct MemoRoads(Arc<Memo>);

impl RoadStage for MemoRoads {
    fn roads(&self, cx: &StageContext<'_>) -> Result<RoadsOutput> {
        if cx.config.road_mode != RoadMode::Citygen {
            return ConfiguredRoads::default().roads(cx);
        }
        let key = self.0.fingerprints().roads;
        if let Some((k, out, all)) = &*lock(&self.0.roads)
            && *k == key
        {
            lock(&self.0.districts).clone_from(all);
            return Ok(out.clone());
        }
        let (net, growth) = citygen_network_with(cx, Some(&*self.0))?;
        // The editor's cells: a cell whose growth an edit made impossible (a pattern too
        // big for it) stays a cell the user can select and edit back.
        let all: Vec<_> = net.districts.iter().chain(&net.ungrown).cloned().collect();
        lock(&self.0.districts).clone_from(&all);
        let out = RoadsOutput {
            network: net.network,
            growth,
            skipped: net.skipped,
            districts: net.districts,
        };
        *lock(&self.0.roads) = Some((key, out.clone(), all));
        Ok(out)
    }
}

/// The cell stage, reused whole when the road stage's inputs are (the union graph is
/// then the same graph).
struct MemoCells(Arc<Memo>);

impl CellStage for MemoCells {
    fn cells(
        &self,
        network: &polis_roads::RoadNetwork,
        cx: &StageContext<'_>,
    ) -> Result<polis_cells::CellDecomposition> {
        let key = self.0.fingerprints().roads;
        if let Some((k, cells)) = &*lock(&self.0.cells)
            && *k == key
        {
            return Ok(cells.clone());
        }
        let cells = EberlyCells.cells(network, cx)?;
        *lock(&self.0.cells) = Some((key, cells.clone()));
        Ok(cells)
    }
}

/// The input key of a cell's blocks and lots (`lots`: the lot stage's fingerprint).
fn lots_key(lots: Key, input: &CellInput<'_>) -> Key {
    let r = &input.region;
    let mut key = Key::new(0x6C6F_7473)
        .key(lots)
        .u64(r.id)
        .u64(input.seed)
        .region(&r.polygon)
        .u64(r.road_widths.len() as u64);
    for &w in &r.road_widths {
        key = key.f64(w);
    }
    key = key.u64(input.nearby_roads.len() as u64);
    for &(a, b, w) in &input.nearby_roads {
        key = key.point(a).point(b).f64(w);
    }
    if let Some(p) = &input.lot_params {
        key = key.bytes(format!("{p:?}").as_bytes());
    }
    key
}

/// The digest of what a road-graph cell's buildings and skins read of `config` besides
/// the cell ([`Fingerprints::plan`]).
/// `None` if it cannot be serialised.
fn plan_key(config: &crate::CityConfig) -> Option<Key> {
    let mut c = config.clone();
    c.citygen.primary = Default::default();
    c.citygen.cells.clear();
    c.citygen.lots.clear();
    let mut w = KeyWriter(Key::new(0x706C_616E).key(facades_key(config)));
    serde_json::to_writer(&mut w, &c).ok()?;
    Some(w.0)
}

/// The digest of what the terrain reads of `config` ([`Fingerprints::ground`]); `None`
/// if it cannot be serialised.
fn ground_key(config: &crate::CityConfig) -> Option<Key> {
    let mut c = config.clone();
    c.citygen = Default::default();
    let mut w = KeyWriter(Key::new(0x6772_6F75));
    serde_json::to_writer(&mut w, &c).ok()?;
    Some(w.0)
}

impl GroundReuse for Memo {
    fn terrain(&self, bed: Option<Key>) -> Option<TerrainTiles> {
        let key = terrain_key(self.fingerprints().ground, bed);
        match &*lock(&self.terrain) {
            Some((k, (report, tiles))) if *k == key => Some((*report, tiles.clone())),
            _ => None,
        }
    }

    fn keep_terrain(
        &self,
        bed: Option<Key>,
        report: polis_geom::mesh::TerrainReport,
        tiles: &[polis_geom::Mesh],
    ) {
        let key = terrain_key(self.fingerprints().ground, bed);
        *lock(&self.terrain) = Some((key, (report, tiles.to_vec())));
    }

    fn water_base(&self) -> Option<Arc<crate::water::WaterBase>> {
        let key = self.fingerprints().ground;
        match &*lock(&self.water) {
            Some((k, base)) if *k == key => Some(base.clone()),
            _ => None,
        }
    }

    fn keep_water_base(&self, base: &Arc<crate::water::WaterBase>) {
        *lock(&self.water) = Some((self.fingerprints().ground, base.clone()));
    }
}

/// The key of a terrain on the ground of configuration digest `ground` with the water
/// bed of digest `bed`.
fn terrain_key(ground: Key, bed: Option<Key>) -> Key {
    let k = Key::new(0x7465_7272).key(ground);
    match bed {
        Some(b) => k.u64(1).key(b),
        None => k.u64(0),
    }
}

struct MemoLots(Arc<Memo>);

impl LotStage for MemoLots {
    fn lots(&self, input: &CellInput<'_>, cx: &StageContext<'_>) -> Result<CellLots> {
        let r = &input.region;
        let key = lots_key(self.0.fingerprints().lots, input);
        let hit = lock(&self.0.lots).get(key);
        if let Some(v) = hit {
            return Ok(v.value.clone());
        }
        let v = KellyLots.lots(input, cx)?;
        lock(&self.0.lots).put(key, v.clone());
        lock(&self.0.redone).blocks.insert(r.id);
        Ok(v)
    }
}

struct MemoBuildings(Arc<Memo>);

impl BuildingStage for MemoBuildings {
    fn prepare<'a>(&'a self, cx: &StageContext<'a>) -> Result<Box<dyn BuildLot + 'a>> {
        let fingerprint = self.0.fingerprints().buildings;
        let mut cached = lock(&self.0.builder);
        let inner = match &*cached {
            Some((k, b)) if *k == fingerprint => Arc::clone(b),
            _ => {
                let b: Arc<dyn BuildLot> = Arc::new(polis_buildings::BuildingGenerator::new(
                    cx.config.effective_building_params(),
                )?);
                *cached = Some((fingerprint, Arc::clone(&b)));
                b
            }
        };
        Ok(Box::new(MemoBuild {
            memo: &self.0,
            inner,
            fingerprint,
        }))
    }
}

struct MemoBuild<'a> {
    memo: &'a Memo,
    inner: Arc<dyn BuildLot>,
    fingerprint: Key,
}

impl BuildLot for MemoBuild<'_> {
    fn build(&self, lot: &LotInput<'_>) -> Result<Option<Building>> {
        Ok(self.build_shared(lot)?.map(|b| (*b).clone()))
    }

    /// The building of `lot`: a pointer to the memo's where its key was seen before.
    fn build_shared(&self, lot: &LotInput<'_>) -> Result<Option<Arc<Building>>> {
        let l = lot.lot;
        let mut key = Key::new(0x626C_6467)
            .key(self.fingerprint)
            .u64(lot.id)
            .f64(lot.max_height_m)
            .u64(lot.lod as u64)
            .ring(&l.polygon)
            .u64(l.block_id)
            .f64(l.area)
            .u64(l.street_edges.len() as u64);
        for &e in &l.street_edges {
            key = key.u64(e as u64);
        }
        let key = hashed(key, &lot.kind);
        lock(&self.memo.ids).this_built.insert(lot.id, key);
        let hit = lock(&self.memo.buildings).get(key);
        if let Some(v) = hit {
            return Ok(v.value.clone());
        }
        let v = self.inner.build(lot)?.map(Arc::new);
        lock(&self.memo.buildings).put(key, v.clone());
        lock(&self.memo.redone).buildings += 1;
        Ok(v)
    }
}

struct MemoFacades(Arc<Memo>);

impl FacadeStage for MemoFacades {
    fn prepare<'a>(&'a self, cx: &StageContext<'a>) -> Result<Box<dyn DressBuilding + 'a>> {
        let fingerprint = self.0.fingerprints().facades;
        let mut cached = lock(&self.0.dresser);
        let inner = match &*cached {
            Some((k, d)) if *k == fingerprint => Arc::clone(d),
            _ => {
                let d: Arc<dyn DressBuilding> = Arc::from(crate::stages::tiler(cx)?);
                *cached = Some((fingerprint, Arc::clone(&d)));
                d
            }
        };
        Ok(Box::new(MemoDress {
            memo: &self.0,
            inner,
            fingerprint,
        }))
    }
}

struct MemoDress<'a> {
    memo: &'a Memo,
    inner: Arc<dyn DressBuilding>,
    fingerprint: Key,
}

impl DressBuilding for MemoDress<'_> {
    fn tile_sets(&self) -> &[polis_facades::TileSet] {
        self.inner.tile_sets()
    }

    fn into_tile_sets(self: Box<Self>) -> Vec<polis_facades::TileSet> {
        self.inner.tile_sets().to_vec()
    }

    fn dress(&self, b: &Building, seed: u64) -> Result<Option<Dress>> {
        self.dress_styled(b, seed, None)
    }

    fn dress_styled(&self, b: &Building, seed: u64, style: Option<&str>) -> Result<Option<Dress>> {
        Ok(self.dress_shared(b, seed, style)?.map(|d| (*d).clone()))
    }

    /// The skin of `b`: a pointer to the memo's where its key was seen before.
    fn dress_shared(
        &self,
        b: &Building,
        seed: u64,
        style: Option<&str>,
    ) -> Result<Option<Arc<Dress>>> {
        let key = self.key(b, seed, style);
        lock(&self.memo.ids).this_dressed.insert(b.id, key);
        let hit = lock(&self.memo.dresses).get(key);
        if let Some(v) = hit {
            return Ok(v.value.clone());
        }
        let v = self.inner.dress_styled(b, seed, style)?.map(Arc::new);
        lock(&self.memo.dresses).put(key, v.clone());
        lock(&self.memo.redone).dresses += 1;
        Ok(v)
    }
}

impl MemoDress<'_> {
    /// The input key of `b`'s skin: its building's key where this run built it under
    /// its own id (see [`IdKeys`]), else a digest of its facades.
    fn key(&self, b: &Building, seed: u64, style: Option<&str>) -> Key {
        let built = lock(&self.memo.ids).this_built.get(&b.id).copied();
        if let Some(k) = built {
            return Key::new(0x6472_6B79)
                .key(self.fingerprint)
                .u64(seed)
                .bytes(style.unwrap_or("\0").as_bytes())
                .key(k)
                .u64(b.id);
        }
        let mut key = Key::new(0x6472_6573)
            .key(self.fingerprint)
            .u64(seed)
            .bytes(style.unwrap_or("\0").as_bytes())
            .u64(b.facades.len() as u64);
        key = hashed(key, &b.kind);
        for f in &b.facades {
            key = key
                .f64(f.origin.x)
                .f64(f.origin.y)
                .f64(f.origin.z)
                .f64(f.u.x)
                .f64(f.u.y)
                .f64(f.u.z)
                .f64(f.v.x)
                .f64(f.v.y)
                .f64(f.v.z)
                .f64(f.width)
                .f64(f.height)
                .u64(u64::from(f.floors))
                .u64(u64::from(f.part));
            key = hashed(key, &f.role);
        }
        key
    }
}
