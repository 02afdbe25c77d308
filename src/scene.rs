//! Assembling the 3-D [`Scene`] of a city: block plinths, road surfaces, buildings with
//! their facade skins, and the shared facade textures as materials.
//!
//! The node tree is `city → roads | water`, `city → cell <id> → block <id> | building
//! <id>`; each cell's subtree is one run of nodes (the cell, its blocks, then each
//! building followed by its `lod 0` box) and one run of meshes, which an editor moves
//! whole when the cell is unchanged. The cells come first in the node array (they are
//! moved and made while the road layer, [`RoadLayer`], is made beside them) and the
//! layers (ground, roads, bridges, portals, water) after them, but first among the
//! root's children, so every walk of the tree meets the layers first; every node that draws carries its `layer` (`roads`, `water`, `blocks`,
//! `buildings`); building nodes carry `id` (text, exact) and `id_number`, `kind`,
//! `type`, `height`, `floors`, `lot`, `lot_id`, `cell` and `style` (when dressed), block
//! nodes `id` and `cell`. The glb writer's default
//! [`Batching::Tiled`](polis_export::glb::Batching) lays these out as `city → layer →
//! tile`, one primitive per material, with each building's and block's record in the
//! city node's feature table; [`Batching::PerParentAndMaterial`](polis_export::glb::Batching)
//! merges each cell's leaves instead.

use polis_buildings::{Building, BuildingKind, FacadeFace, PartRole};
use polis_export::map::{MapRoad, RoadClass as MapClass};
use polis_export::surfaces::{RoadSurfaceOptions, road_surface_parts};
use polis_facades::TileSet;

use polis_geom::par::{self, prelude::*};
use polis_geom::scene::{Image, ImageData, MeshId, MetaValue, Metadata, NodeId, Texture};
use polis_geom::{
    DVec2, DVec3, Facing, Field, Material, MaterialId, Mesh, PolygonWithHoles, Scene, Transform,
    to_world,
};
use polis_lots::Block;
use polis_roads::{RoadClass, RoadNetwork};

use crate::error::Result;
use crate::ground::{Ground, TerrainTiles, add_ground, build_ground};
use crate::stages::{Dress, SkinQuad};
use crate::{CityConfig, CityMaps, Foundation};

/// Plain materials of the scene, by role.
struct Palette {
    pavement: MaterialId,
    walls: [MaterialId; 6],
    roof: MaterialId,
    detail: MaterialId,
    /// Per style, per tile.
    tiles: Vec<Vec<MaterialId>>,
}

fn palette(scene: &mut Scene, sets: &[TileSet]) -> Result<Palette> {
    palette_with(scene, sets, true)
}

/// The palette's materials added to `scene`; with `pixels` off the tile images are left
/// empty (the material ids are the same: for making leaves outside a scene).
fn palette_with(scene: &mut Scene, sets: &[TileSet], keep_pixels: bool) -> Result<Palette> {
    let mut m = |name: &str, rgb: [f32; 3]| {
        scene.add_material(Material::new(name, [rgb[0], rgb[1], rgb[2], 1.0]))
    };
    let walls = [
        m("wall skyscraper", [0.55, 0.62, 0.70]),
        m("wall office", [0.62, 0.66, 0.70]),
        m("wall mid-rise", [0.80, 0.76, 0.68]),
        m("wall house", [0.82, 0.72, 0.60]),
        m("wall apartment", [0.76, 0.66, 0.58]),
        m("wall industrial", [0.60, 0.60, 0.58]),
    ];
    let roof = m("roof", [0.45, 0.25, 0.20]);
    let detail = m("detail", [0.30, 0.30, 0.32]);
    // Pavements and footpaths (the block plinths): paving slabs in metre coordinates.
    let pavement =
        crate::streets::add_street_material(scene, polis_facades::street::StreetSurface::Paving)?;
    let mut tiles = Vec::with_capacity(sets.len());
    for set in sets {
        let mut ids = Vec::with_capacity(set.tiles.len());
        for (k, tile) in set.tiles.iter().enumerate() {
            let t = &tile.textures;
            let name = format!("{} tile {k}", set.style);
            let mut texture = |suffix: &str, pixels: &[u8]| -> Result<_> {
                let image = scene.add_image(Image {
                    name: format!("{} {suffix}", name),
                    data: ImageData::Rgba8 {
                        width: t.width,
                        height: t.height,
                        pixels: if keep_pixels {
                            pixels.to_vec()
                        } else {
                            Vec::new()
                        },
                    },
                });
                Ok(scene.add_texture(Texture {
                    name: format!("{name} {suffix}"),
                    image,
                    ..Texture::default()
                })?)
            };
            let albedo = texture("albedo", &t.albedo)?;
            let normal = texture("normal", &t.normal)?;
            let mr = texture("metallic-roughness", &t.metallic_roughness)?;
            ids.push(scene.add_material(Material {
                name,
                base_color_texture: Some(albedo),
                normal_texture: Some(normal),
                metallic_roughness_texture: Some(mr),
                metallic: 1.0,
                roughness: 1.0,
                ..Material::default()
            }));
        }
        tiles.push(ids);
    }
    Ok(Palette {
        pavement,
        walls,
        roof,
        detail,
        tiles,
    })
}

/// The road network as map polylines (one per edge).
pub(crate) fn map_roads(network: &RoadNetwork) -> Result<Vec<MapRoad>> {
    let mut roads = Vec::with_capacity(network.edge_count());
    for (e, _, _, road) in network.edges() {
        let (a, b) = network.segment(e)?;
        roads.push(MapRoad {
            id: u64::from(e.raw()),
            points: vec![a, b],
            class: match road.class {
                RoadClass::Highway => MapClass::Highway,
                RoadClass::Street => MapClass::Street,
            },
            width_m: road.width,
            bridge: road.bridge,
            tunnel: road.tunnel,
            profile: None,
        });
    }
    Ok(roads)
}

/// Where a building stands: the level of its floor and, per footprint corner, how far
/// below that level its bottom goes.
struct Seat {
    /// Elevation of the building's local origin (its floor), metres.
    base: f64,
    /// Depth of the plinth below the floor, metres (0: none).
    plinth: f64,
    /// How far the bottom reaches below the ground under it besides, metres: the
    /// terrain's allowance (it lies up to this below the elevation map), so no building
    /// floats over the terrain mesh.
    foot: f64,
}

/// The seat of a footprint on the ground under its corners, by foundation mode (see
/// [`Foundation`]); non-finite ground samples are left out (0 m when none is finite).
fn seat(elevation: &dyn Field, pts: &[DVec2], mode: Foundation, foot: f64) -> Seat {
    let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
    for &p in pts {
        let g = elevation.sample(p);
        if g.is_finite() {
            lo = lo.min(g);
            hi = hi.max(g);
            sum += g;
            n += 1;
        }
    }
    if n == 0 {
        return Seat {
            base: 0.0,
            plinth: 0.0,
            foot,
        };
    }
    let base = match mode {
        Foundation::Lowest => lo,
        Foundation::Highest | Foundation::Follow => hi,
        Foundation::Average => (sum / n as f64).clamp(lo, hi),
    };
    Seat {
        base,
        plinth: base - lo,
        foot,
    }
}

/// Carries the bottom of a building's mass (every vertex at its floor, local height 0)
/// down by the plinth depth, or for [`Foundation::Follow`] down to the ground under each
/// vertex, so walls reach the ground. Texture `v` stays minus the height on walls.
fn lower_bottom(
    mesh: &mut Mesh,
    from: usize,
    seat: &Seat,
    mode: Foundation,
    elevation: &dyn Field,
    origin: DVec2,
) {
    if seat.plinth + seat.foot <= 0.0 {
        return;
    }
    let (positions, normals, uvs) = (
        mesh.positions.get_mut(from..).unwrap_or_default(),
        mesh.normals.get(from..).unwrap_or_default(),
        mesh.uvs.get_mut(from..).unwrap_or_default(),
    );
    for ((p, n), uv) in positions.iter_mut().zip(normals).zip(uvs) {
        if p.y != 0.0 {
            continue;
        }
        let depth = match mode {
            Foundation::Follow => {
                let (q, _) = polis_geom::to_layout(p.as_dvec3());
                let g = elevation.sample(q + origin);
                if g.is_finite() {
                    (seat.base - g).clamp(0.0, seat.plinth) + seat.foot
                } else {
                    seat.plinth + seat.foot
                }
            }
            _ => seat.plinth + seat.foot,
        };
        p.y = -(depth as f32);
        if n.y.abs() < 0.5 {
            uv.y = -p.y;
        }
    }
}

/// How buildings of `kind` are seated (the configuration's foundation mode).
fn foundation(config: &CityConfig, kind: BuildingKind) -> Foundation {
    config
        .scene
        .foundations
        .get(kind.index())
        .copied()
        .unwrap_or_default()
}

/// Lowest ground under a ring of layout points.
fn ground(elevation: &dyn Field, pts: &[DVec2]) -> f64 {
    let e = pts
        .iter()
        .map(|&p| elevation.sample(p))
        .filter(|e| e.is_finite())
        .fold(f64::INFINITY, f64::min);
    if e.is_finite() { e } else { 0.0 }
}

/// Meshes by material, reused from building to building: the first `used` are the
/// current building's.
#[derive(Default)]
struct Targets {
    meshes: Vec<Mesh>,
    used: usize,
}

impl Targets {
    /// The mesh of `material`, started (reusing an old one's memory) if new.
    fn get(&mut self, material: Option<MaterialId>) -> Option<&mut Mesh> {
        let used = self.used;
        let current = self.meshes.get(..used)?;
        let i = match current.iter().position(|m| m.material == material) {
            Some(i) => i,
            None => {
                match self.meshes.get_mut(used) {
                    Some(m) => {
                        m.positions.clear();
                        m.normals.clear();
                        m.uvs.clear();
                        m.indices.clear();
                        m.material = material;
                    }
                    None => self.meshes.push(Mesh::new(material)),
                }
                self.used += 1;
                used
            }
        };
        self.meshes.get_mut(i)
    }
}

/// How deep the terrain is cut in under graded road corridors (and 1 m beyond, tapering
/// over the next [`CORRIDOR_CUT_TAPER_M`]), metres: the terrain mesh's triangles span the
/// sharp foot of a cut's banks without vertices on the corridor's edge, and this keeps
/// them under the road surface. The cut is an upper bound on the terrain only: over the
/// cut and one more taper beyond it the terrain may also sag by this much under it
/// (`CutIn::slack`), and its vertices sit half that under the cut, so it is refined
/// where it would rise over the cut or sag under the slack's floor, not at every bend of
/// the graded ground.
pub const CORRIDOR_CUT_M: f64 = 0.5;

/// Over how many metres the corridors' cut tapers back to the ground, metres: gentle
/// (1:16 for the 0.5 m cut), so the taper's own bends need no small terrain leaves (a 1 m
/// taper refined both of its edges to the smallest leaf along every road).
pub const CORRIDOR_CUT_TAPER_M: f64 = 8.0;

/// How far a block plinth draped on an elevation map reaches below the ground, metres: a
/// foundation, so the ground between the plinth's vertices never shows under it.
pub const PLINTH_FOOT_M: f64 = 0.5;

/// Triangles of draped plinths: at most 400 m² (about 30 m sides), so a plinth bends
/// with ground whose features are a hundred metres or more long (the preset maps'
/// hills); between vertices it stays within `s²·κ/8` of the ground (side `s`, ground
/// curvature `κ`), which the foot below covers.
const PLINTH_REFINE: polis_geom::mesh::RefineOptions = polis_geom::mesh::RefineOptions {
    max_area: 400.0,
    min_angle_deg: 15.0,
    max_additional_vertices: 100_000,
};

/// How far facade skins stand out of the wall they dress, metres: enough that no
/// renderer's depth test mixes them with the closed mass behind, far below anything a
/// viewer can see.
pub const SKIN_OFFSET_M: f64 = 0.02;

thread_local! {
    static MESH_SCRATCH: std::cell::RefCell<Targets> = std::cell::RefCell::default();
}

/// The meshes of one building: its parts merged into one closed solid
/// ([`Building::merged_solid`], by role: walls, roofs, details) and, as their own
/// surfaces [`SKIN_OFFSET_M`] in front of the walls, one skin mesh per facade tile; one
/// mesh per material, in order of first use.
/// Where and how a building is seated: its seat, mode, and the ground.
type Seating<'a> = (&'a Seat, Foundation, &'a dyn Field);

fn building_meshes(
    b: &Building,
    dress: Option<&Dress>,
    pal: &Palette,
    seating: Option<Seating<'_>>,
) -> Result<Vec<Mesh>> {
    MESH_SCRATCH.with(|scratch| {
        let mut targets = scratch.borrow_mut();
        targets.used = 0;
        let wall = pal.walls[b.kind.index().min(5)];
        let material = |role: PartRole| {
            Some(match role {
                PartRole::Mass => wall,
                PartRole::Roof => pal.roof,
                PartRole::Detail | PartRole::Template => pal.detail,
            })
        };
        let mut add = |role: PartRole, part: &Mesh| {
            if let Some(mesh) = targets.get(material(role)) {
                let from = mesh.positions.len();
                mesh.append(part);
                if let Some((seat, mode, ground)) = seating {
                    lower_bottom(mesh, from, seat, mode, ground, b.origin);
                }
            }
        };
        if let [only] = b.parts.as_slice() {
            // Already one closed solid: copied once, not through a merged copy.
            add(only.role, &only.mesh);
        } else {
            for (role, part) in &b.merged_solid().meshes {
                add(*role, part);
            }
        }
        if let Some(d) = dress
            && let Some(materials) = pal.tiles.get(d.style)
        {
            for q in &d.quads {
                let (Some(&m), Some(face)) = (
                    materials.get(q.tile as usize),
                    b.facades.get(q.face as usize),
                ) else {
                    continue;
                };
                if let Some(mesh) = targets.get(Some(m)) {
                    push_skin_quad(mesh, q, face)?;
                }
            }
        }
        Ok(targets
            .meshes
            .get(..targets.used)
            .unwrap_or_default()
            .iter()
            .filter(|m| !m.is_empty())
            .cloned()
            .collect())
    })
}

/// Appends a skin quad: four vertices with the face's normal and the quad's texture
/// coordinates, two triangles. Quads too small to stay a rectangle in `f32` (and any
/// non-finite value) go through [`Mesh::add_quad`], which checks them.
fn push_skin_quad(mesh: &mut Mesh, q: &SkinQuad, face: &FacadeFace) -> Result<()> {
    let out = face.normal() * SKIN_OFFSET_M;
    let corners = q.corners(face).map(|c| c + out);
    let [s0, t0, s1, t1] = q.rect;
    let scale = corners
        .iter()
        .fold(1.0f64, |m, c| m.max(c.abs().max_element()));
    let normal = face.normal();
    let plain = (s1 - s0).min(t1 - t0) >= 1e-4 * scale
        && scale.is_finite()
        && (normal.length_squared() - 1.0).abs() < 1e-6;
    if !plain {
        mesh.add_quad(corners, q.uvs())?;
        return Ok(());
    }
    let base = mesh.positions.len() as u32;
    let n = normal.as_vec3();
    mesh.positions.extend(corners.map(|c| c.as_vec3()));
    mesh.normals.extend([n; 4]);
    mesh.uvs.extend(q.uvs().map(|t| t.as_vec2()));
    mesh.indices
        .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    Ok(())
}

/// Water bodies and the level of their surface, metres.
type WaterLevels = Vec<(PolygonWithHoles, f64)>;

/// Everything the scene is built from.
pub(crate) struct SceneInputs<'a> {
    /// The ground everything stands on: the elevation map, with the roads graded into it.
    pub ground: &'a dyn Field,
    /// The graded ground cut in under the road corridors, for the terrain mesh (the
    /// water bed not cut in: see `water`).
    pub cut_in: Option<polis_roads::grading::CutIn<'a>>,
    /// The water bodies, their levels and their bed (already in `ground`).
    pub water: Option<&'a crate::water::Water>,
    pub config: &'a CityConfig,
    pub maps: &'a CityMaps,
    pub network: &'a RoadNetwork,
    pub blocks: &'a [std::sync::Arc<Block>],
    pub buildings: &'a [std::sync::Arc<Building>],
    /// Cell id of each building.
    pub building_cells: &'a [u64],
    pub dresses: &'a [Option<std::sync::Arc<Dress>>],
    pub tile_sets: &'a [TileSet],
    /// Green spaces of the lot stage (parks on the ground).
    pub green_spaces: &'a [PolygonWithHoles],
    /// Cells of an earlier scene of the same city to reuse whole (the editor's splice).
    pub reuse: Option<&'a dyn SceneReuse>,
    /// Terrains of earlier runs to reuse (the editor's memo); only where `ground` does
    /// not depend on the road graph (no roads graded into it).
    pub terrains: Option<&'a dyn GroundReuse>,
}

/// Terrains (and the water bodies with their shores) an editor keeps between runs. A terrain is
/// a function of the ground it follows, the map and the terrain options: a memo keyed by
/// the configuration's digest (which fixes the map, the options and the elevation map)
/// and the water bed's ([`Water::bed_key`](crate::water::Water)) hands back the terrain
/// made before.
pub(crate) trait GroundReuse: Sync {
    /// The terrain made earlier on the ground with the water bed of digest `bed` (none:
    /// no water), if kept.
    fn terrain(&self, bed: Option<crate::editor::key::Key>) -> Option<TerrainTiles>;
    /// Keeps the terrain made on the ground with the water bed of digest `bed`.
    fn keep_terrain(
        &self,
        bed: Option<crate::editor::key::Key>,
        report: polis_geom::mesh::TerrainReport,
        tiles: &[Mesh],
    );
    /// The water bodies and their shores ([`WaterBase`](crate::water::WaterBase): the
    /// water map's outlines, [`smooth_mask`](crate::smooth_mask), on the elevation) an
    /// earlier run on the same maps made, if kept. They read only the configuration's
    /// maps, seed and size (no map paint reaches the water map or the elevation).
    fn water_base(&self) -> Option<std::sync::Arc<crate::water::WaterBase>>;
    /// Keeps the water bodies and shores made in this run.
    fn keep_water_base(&self, base: &std::sync::Arc<crate::water::WaterBase>);
}

/// Cells of an earlier scene an editor hands back to [`assemble`] whole instead of
/// making their leaves again. An implementation must only hand back a cell whose
/// inputs (its blocks, buildings, skins and their order; the ground, the palette, the
/// configuration) are those of the earlier scene, and only a subtree `assemble` made.
pub(crate) trait SceneReuse: Sync {
    /// Whether the subtree of cell `cell` in the earlier scene was made of exactly
    /// `items` (the same blocks, buildings and skins, in order), so that
    /// [`take_cell`](Self::take_cell) can hand it back: its numbers of nodes and meshes
    /// if so.
    fn whole_cell(&self, cell: u64, items: &CellItems<'_>) -> Option<(usize, usize)>;
    /// Appends the subtree of cell `cell` of the earlier scene (its nodes and meshes,
    /// renumbered) to `scene` as the last child of `parent`; `false` (nothing appended)
    /// if it cannot.
    ///
    /// # Errors
    /// `parent` is not a node of `scene`.
    fn take_cell(&self, cell: u64, scene: &mut Scene, parent: NodeId) -> Result<bool>;
}

/// The scene node name of building `id`; [`node_id`] reads it back.
pub(crate) fn building_node_name(id: u64) -> String {
    format!("building {id}")
}

/// The scene node name of block `id`; [`node_id`] reads it back.
pub(crate) fn block_node_name(id: u64) -> String {
    format!("block {id}")
}

/// The id in a node name made by [`building_node_name`] (`kind` "building") or
/// [`block_node_name`] (`kind` "block").
pub(crate) fn node_id(name: &str, kind: &str) -> Option<u64> {
    name.strip_prefix(kind)?.strip_prefix(' ')?.parse().ok()
}

/// A building leaf made outside a scene (the editor's in-place patch): its node's name,
/// translation and metadata, and its meshes.
pub(crate) type Reused = (String, DVec3, Metadata, Vec<Mesh>);

/// How far buildings and plinths reach below the ground: the terrain's one-sided
/// allowance (2 e) and, on graded ground (`graded`), the corridor cut, the terrain's slack
/// under it (as deep again) and the lowering of
/// smallest leaves that miss the bound at the foot of a bank (their diagonal's rise on
/// the bank). Metres; 0 without terrain.
fn foot_of(config: &CityConfig, graded: bool) -> f64 {
    let sc = &config.scene;
    if !sc.terrain {
        return 0.0;
    }
    let graded = if graded {
        2.0 * CORRIDOR_CUT_M + 2.0 * sc.terrain_mesh.min_cell_m * sc.road_grading.embankment_slope
    } else {
        0.0
    };
    2.0 * sc.terrain_mesh.max_error_m + graded
}

/// What a building's leaf reads besides the building: the configuration, the ground,
/// the palette, the tile sets and the foot ([`foot_of`]).
pub(crate) struct LeafContext<'a> {
    config: &'a CityConfig,
    ground: &'a dyn Field,
    palette: &'a Palette,
    tile_sets: &'a [TileSet],
    foot: f64,
}

/// The palette of a scene of `tile_sets`, as [`assemble`] makes it (same material ids),
/// without the tile images: for [`BuildingLeaves`].
pub(crate) struct LeafPalette(Palette);

impl LeafPalette {
    /// The palette of `tile_sets`.
    ///
    /// # Errors
    /// A failing street material.
    pub(crate) fn new(tile_sets: &[TileSet]) -> Result<Self> {
        Ok(LeafPalette(palette_with(
            &mut Scene::new(),
            tile_sets,
            false,
        )?))
    }
}

/// Building leaves of an existing scene, made one at a time as [`assemble`] makes them
/// (the editor's in-place update of a scene whose ground and palette are unchanged;
/// ungraded ground only).
pub(crate) struct BuildingLeaves<'a> {
    cx: LeafContext<'a>,
}

impl<'a> BuildingLeaves<'a> {
    /// Leaves on `maps`' elevation (no graded roads) with `palette`.
    pub(crate) fn new(
        config: &'a CityConfig,
        maps: &'a CityMaps,
        palette: &'a LeafPalette,
        tile_sets: &'a [TileSet],
    ) -> Self {
        BuildingLeaves {
            cx: LeafContext {
                config,
                ground: maps.inputs.elevation.as_ref(),
                palette: &palette.0,
                tile_sets,
                foot: foot_of(config, false),
            },
        }
    }

    /// The leaf of building `b` (with skin `dress`, in cell `cell`): its node's name,
    /// translation and metadata and its meshes, and its coarse box when the scene has
    /// coarse levels (`Some(None)`: it has none, the footprint cannot be extruded).
    ///
    /// # Errors
    /// A failing mesh.
    pub(crate) fn leaf(
        &self,
        b: &Building,
        dress: Option<&Dress>,
        cell: Option<u64>,
    ) -> Result<(Reused, Option<Option<Mesh>>)> {
        let (node, meshes) = building_leaf(&self.cx, b, dress, cell)?;
        let fine = self.cx.config.effective_lod();
        let coarse = (self.cx.config.scene.coarse_lod && fine > 0).then(|| {
            coarse_box(
                self.cx.config,
                self.cx.ground,
                self.cx.palette,
                b,
                self.cx.foot,
            )
        });
        Ok(((node.name, node.translation, node.metadata, meshes), coarse))
    }
}

/// Building `b`'s leaf: its node (name, placement, metadata) and meshes.
fn building_leaf(
    cx: &LeafContext<'_>,
    b: &Building,
    dress: Option<&Dress>,
    cell: Option<u64>,
) -> Result<(LeafNode, Vec<Mesh>)> {
    let elevation = cx.ground;
    let mode = foundation(cx.config, b.kind);
    let seat = seat(elevation, b.footprint.points(), mode, cx.foot);
    let meshes = building_meshes(b, dress, cx.palette, Some((&seat, mode, elevation)))?;
    let base = seat.base;
    let style = dress
        .and_then(|d| cx.tile_sets.get(d.style))
        .map_or("", |t| t.style.as_str());
    // Room for every entry (up to `style` and `cell`), the ids' text moved in: one
    // allocation for the entries and one per id. Written in key order, so each entry is
    // appended (no search, no shift).
    let mut metadata = Metadata::with_capacity(11);
    if let Some(cell) = cell {
        metadata.insert("cell", MetaValue::from(cell as f64));
    }
    metadata.extend([
        ("floors", MetaValue::from(f64::from(b.floors))),
        ("height", MetaValue::from(b.height)),
        // The id as text (exact in JavaScript above 2^53) and as a number.
        ("id", MetaValue::from(b.id.to_string())),
        ("id_number", MetaValue::from(b.id as f64)),
        ("kind", MetaValue::from_static(kind_class(b.kind))),
        ("layer", MetaValue::from_static("buildings")),
        ("lot", MetaValue::from(b.lot_id as f64)),
        ("lot_id", MetaValue::from(b.lot_id.to_string())),
    ]);
    if !style.is_empty() {
        metadata.insert("style", MetaValue::from(style));
    }
    metadata.insert("type", MetaValue::from_static(b.kind.name()));
    let node = LeafNode {
        name: building_node_name(b.id),
        translation: to_world(b.origin, base),
        metadata,
    };
    Ok((node, meshes))
}

/// Building `b`'s coarse level: its footprint extruded to its height (`None` if the
/// footprint cannot be extruded).
fn coarse_box(
    config: &CityConfig,
    elevation: &dyn Field,
    pal: &Palette,
    b: &Building,
    foot: f64,
) -> Option<Mesh> {
    let seat = seat(
        elevation,
        b.footprint.points(),
        foundation(config, b.kind),
        foot,
    );
    let local = b.footprint.translated(-b.origin);
    let wall = pal.walls[b.kind.index().min(5)];
    polis_geom::mesh::prism(&local.into(), -seat.plinth, b.height, Some(wall)).ok()
}

/// The road layer of the scene: the bridges (closed decks on piers), the road surfaces
/// (which follow the bridges' profiles) and the tunnels' portal frames. It reads only
/// the network, the ground (with the water bed) and the water, so [`assemble`] makes it
/// beside the cells' subtrees (their leaves made and the reused ones moved in) and adds
/// it to the scene after them.
pub(crate) struct RoadLayer {
    bridges: crate::ground::Bridges,
    surfaces: Option<polis_export::surfaces::RoadSurfaceParts>,
    portals: Option<Mesh>,
}

impl RoadLayer {
    /// The road layer of `network` on `ground` (the elevation, graded roads and water
    /// bed in it) with the water bodies `water`.
    ///
    /// # Errors
    /// A bridge, road surface or portal frame that cannot be made.
    pub(crate) fn new(
        config: &CityConfig,
        network: &RoadNetwork,
        ground: &dyn Field,
        water: Option<&crate::water::Water>,
    ) -> Result<Self> {
        // Bridges first: the road surfaces follow their profiles.
        let bridges = crate::ground::bridges(network, ground, water, &config.scene.road_grading)?;
        let surfaces = Self::surfaces(config, network, ground, &bridges)?;
        let portals = polis_roads::portal_mesh(network, ground)?;
        Ok(RoadLayer {
            bridges,
            surfaces,
            portals,
        })
    }

    /// The road surfaces (one serial pass over the network); `None` where there are
    /// none.
    fn surfaces(
        config: &CityConfig,
        network: &RoadNetwork,
        ground: &dyn Field,
        bridges: &crate::ground::Bridges,
    ) -> Result<Option<polis_export::surfaces::RoadSurfaceParts>> {
        if !(config.scene.road_surfaces && network.edge_count() > 0) {
            return Ok(None);
        }
        // No surface between a tunnel's portals (polis_roads::tunnels), but the open
        // cut from each portal's junction to its frame.
        let mut roads = map_roads(network)?;
        for r in roads.iter_mut().filter(|r| r.bridge) {
            if let Ok(k) = bridges.profiles.binary_search_by_key(&r.id, |p| p.0) {
                r.profile = Some(bridges.profiles[k].1.clone());
            }
        }
        let mut cuts = Vec::new();
        for p in polis_roads::portals(network)? {
            if p.setback > 0.0
                && let Some(tunnel) = roads.iter().find(|r| r.id == u64::from(p.edge.raw()))
            {
                cuts.push(MapRoad {
                    points: vec![p.position, p.face()],
                    tunnel: false,
                    ..tunnel.clone()
                });
            }
        }
        roads.retain(|r| !r.tunnel);
        roads.extend(cuts);
        if roads.is_empty() {
            return Ok(None);
        }
        Ok(Some(road_surface_parts(
            &roads,
            ground,
            &RoadSurfaceOptions::default(),
        )?))
    }
}

/// Builds the scene.
pub(crate) fn assemble(inp: &SceneInputs<'_>) -> Result<Scene> {
    let mut scene = Scene::new();
    let pal = palette(&mut scene, inp.tile_sets)?;
    let elevation = inp.ground;
    let root = scene.add_root(inp.config.name.clone());
    scene.set_metadata(root, "seed", inp.config.seed as f64)?;

    // Buildings and plinths reach below the ground as far as the terrain may lie below
    // it: its one-sided allowance (2 e) and, on graded ground, the corridor cut, the
    // slack under it and the lowering of smallest leaves that miss the bound at the foot of a bank (their
    // diagonal's rise on the bank).
    let foot = foot_of(inp.config, inp.cut_in.is_some());
    let plinth_foot = PLINTH_FOOT_M.max(foot);
    let fine = inp.config.effective_lod();
    let coarse = inp.config.scene.coarse_lod && fine > 0;
    // Building `i`'s node (name, placement, metadata) and meshes, and its coarse box
    // when the scene has coarse levels (`None` also where the footprint cannot be
    // extruded).
    let make_building = |i: usize| -> BuildingMade {
        let Some(b) = inp.buildings.get(i) else {
            return Ok(Default::default());
        };
        let leaf = LeafContext {
            config: inp.config,
            ground: elevation,
            palette: &pal,
            tile_sets: inp.tile_sets,
            foot,
        };
        let dress = inp.dresses.get(i).and_then(Option::as_deref);
        let (node, meshes) = building_leaf(&leaf, b, dress, inp.building_cells.get(i).copied())?;
        let boxed = if coarse {
            coarse_box(inp.config, elevation, &pal, b, foot)
        } else {
            None
        };
        Ok((node, meshes, boxed))
    };
    // Block `i`'s node and kerb-high plinth (none without a kerb).
    let kerb = inp.config.scene.kerb_height_m;
    let make_block = |i: usize| -> BlockMade {
        let Some(block) = inp.blocks.get(i).filter(|_| kerb > 0.0) else {
            return Ok(None);
        };
        let base = ground(elevation, block.polygon.outer.points());
        let plinth = if inp.config.maps.elevation.is_some() {
            // On an elevation map the plinth follows the ground: its top a kerb
            // above it, its bottom a foot below it, at every vertex.
            let mut m = Mesh::new(Some(pal.pavement));
            let height = |p: DVec2| {
                let g = elevation.sample(p);
                if g.is_finite() { g } else { base }
            };
            m.add_draped_slab(&block.polygon, &PLINTH_REFINE, height, -plinth_foot, kerb)?;
            m
        } else {
            polis_geom::mesh::prism(&block.polygon, base, base + kerb, Some(pal.pavement))?
        };
        let node = LeafNode {
            name: block_node_name(block.id()),
            translation: DVec3::ZERO,
            // In key order: each entry appended.
            metadata: Metadata::from([
                ("cell", MetaValue::from(block.cell_id as f64)),
                ("id", MetaValue::from(block.id().to_string().as_str())),
                ("layer", MetaValue::from_static("blocks")),
            ]),
        };
        Ok(Some((node, vec![plinth])))
    };
    // Water bodies (flat surfaces at their level, `crate::water`) and the ground
    // (terrain textured by land use, which paints the water bed).
    let water_and_ground = || -> Result<(WaterLevels, Option<Ground>)> {
        let scene = &inp.config.scene;
        let size = inp.config.size_m;
        let water: Vec<PolygonWithHoles> = inp
            .water
            .map(|w| w.bodies().iter().map(|b| b.polygon.clone()).collect())
            .unwrap_or_default();
        let terrain = if scene.terrain {
            let mut parks = if inp.maps.has_parks {
                crate::city::smooth_mask(inp.maps.inputs.parks.as_ref(), size)?
            } else {
                Vec::new()
            };
            parks.extend(inp.green_spaces.iter().cloned());
            let blocks = inp.blocks.iter().map(|b| &b.polygon);
            // The graded ground cut in under the corridors, with the bed: or the ground
            // (with its bed already).
            let cut_bed = match (&inp.cut_in, inp.water) {
                (Some(c), Some(w)) => Some(w.bed(c)),
                _ => None,
            };
            let terrain_field: &dyn Field = match (&cut_bed, &inp.cut_in) {
                (Some(b), _) => b,
                (None, Some(c)) => c,
                (None, None) => elevation,
            };
            // A terrain on the same ground (no graded roads in it) and water bed as an
            // earlier run's is that terrain.
            let bed = inp.water.map(crate::water::Water::bed_key);
            let memo = inp.terrains.filter(|_| inp.cut_in.is_none());
            let made = memo.and_then(|m| m.terrain(bed));
            let fresh = made.is_none();
            // The cut is an upper bound only: the terrain may sag under it by its depth
            // around the corridors (`CutIn::slack`).
            let slack = inp.cut_in.as_ref().map(|c| c.slack());
            let slack = slack.as_ref().map(|s| s as &dyn Field);
            let ground = build_ground(
                inp.config,
                terrain_field,
                slack,
                &water,
                &parks,
                blocks,
                made,
            )?;
            if let Some(m) = memo.filter(|_| fresh) {
                m.keep_terrain(bed, ground.report, &ground.tiles);
            }
            Some(ground)
        } else {
            None
        };
        let water = match inp.water {
            Some(w) if scene.water_surfaces => w
                .bodies()
                .iter()
                .map(|b| (b.polygon.clone(), b.level))
                .collect(),
            _ => Vec::new(),
        };
        Ok((water, terrain))
    };
    // The cells' subtrees (which cells an earlier scene hands back, the other cells'
    // leaves, the terrain) go into the scene while the road layer (bridges, road
    // surfaces, portal frames: one serial pass over the network, `RoadLayer`) is made
    // beside them; the layers then follow the cells in the node array but come first
    // among the root's children, so the tree (and every walk of it) is as if they had
    // been added first.
    let cells_job = |scene: &mut Scene| -> Result<(WaterLevels, Option<Ground>)> {
        // Cells in id order: the parent of their blocks and buildings. Each cell's subtree
        // (its node; its blocks; its buildings, each followed by its coarse box) is one run
        // of nodes and one run of meshes, so an editor can take it whole (`SceneReuse`).
        let cell_ids: Vec<u64> = {
            let mut ids: Vec<u64> = inp
                .blocks
                .iter()
                .map(|b| b.cell_id)
                .chain(inp.building_cells.iter().copied())
                .collect();
            ids.sort_unstable();
            ids.dedup();
            ids
        };
        let cell_index = |c: u64| cell_ids.binary_search(&c).ok();
        // Per cell (by index in `cell_ids`): its blocks and buildings, by index, in order.
        let mut cell_blocks: Vec<Vec<usize>> = vec![Vec::new(); cell_ids.len()];
        let mut cell_buildings: Vec<Vec<usize>> = vec![Vec::new(); cell_ids.len()];
        for (i, b) in inp.blocks.iter().enumerate() {
            if let Some(list) = cell_index(b.cell_id).and_then(|k| cell_blocks.get_mut(k)) {
                list.push(i);
            }
        }
        for (i, &c) in inp
            .building_cells
            .iter()
            .enumerate()
            .take(inp.buildings.len())
        {
            if let Some(list) = cell_index(c).and_then(|k| cell_buildings.get_mut(k)) {
                list.push(i);
            }
        }
        // The cells an earlier scene hands back whole (with their numbers of nodes and
        // meshes): their leaves are not made.
        let whole: Vec<Option<(usize, usize)>> = match inp.reuse {
            Some(r) => cell_ids
                .par_iter()
                .zip(cell_blocks.par_iter().zip(cell_buildings.par_iter()))
                .map(|(&c, (blocks, buildings))| {
                    r.whole_cell(
                        c,
                        &CellItems {
                            blocks: blocks.iter().filter_map(|&i| inp.blocks.get(i)).collect(),
                            buildings: buildings
                                .iter()
                                .filter_map(|&i| {
                                    let b = inp.buildings.get(i)?;
                                    Some((b, inp.dresses.get(i).and_then(Option::as_ref)))
                                })
                                .collect(),
                        },
                    )
                })
                .collect(),
            None => vec![None; cell_ids.len()],
        };
        // The leaves of the cells not handed back whole, made in parallel: by index, `None`
        // for the others.
        let made_where = |lists: &[Vec<usize>], len: usize| -> Vec<bool> {
            let mut made = vec![false; len];
            for (list, _) in lists.iter().zip(&whole).filter(|(_, w)| w.is_none()) {
                for &i in list {
                    if let Some(m) = made.get_mut(i) {
                        *m = true;
                    }
                }
            }
            made
        };
        let buildings_job = || {
            made_in_parallel(
                &made_where(&cell_buildings, inp.buildings.len()),
                make_building,
            )
        };
        let blocks_job =
            || made_in_parallel(&made_where(&cell_blocks, inp.blocks.len()), make_block);
        // Each cell's subtree: taken whole from the earlier scene, or its node and leaves
        // (blocks, then buildings with their coarse boxes under them).
        let (water_and_ground, (mut blocks, mut buildings)) =
            par::join(water_and_ground, || par::join(blocks_job, buildings_job));
        let water_and_ground = water_and_ground?;
        // Room for every cell's nodes and meshes, made once.
        let (mut more_nodes, mut more_meshes) = (0, 0);
        for (k, w) in whole.iter().enumerate() {
            if let Some((nodes, meshes)) = w {
                more_nodes += nodes;
                more_meshes += meshes;
                continue;
            }
            more_nodes += 1;
            for i in cell_blocks.get(k).into_iter().flatten() {
                if let Some(Some(Ok(Some((_, meshes))))) = blocks.get(*i) {
                    more_nodes += 1;
                    more_meshes += meshes.len();
                }
            }
            for i in cell_buildings.get(k).into_iter().flatten() {
                if let Some(Some(Ok((_, meshes, boxed)))) = buildings.get(*i) {
                    let boxed = usize::from(boxed.is_some());
                    more_nodes += 1 + boxed;
                    more_meshes += meshes.len() + boxed;
                }
            }
        }
        // With room for the layers added after the cells: the terrain's tiles, the roads,
        // bridges, portals and water (a few nodes and meshes each).
        let tiles = water_and_ground.1.as_ref().map_or(0, |g| g.tiles.len());
        scene.nodes.reserve(more_nodes + tiles + LAYER_ROOM);
        scene.meshes.reserve(more_meshes + tiles + LAYER_ROOM);
        for (k, &c) in cell_ids.iter().enumerate() {
            if whole.get(k).copied().flatten().is_some()
                && let Some(r) = inp.reuse
                && r.take_cell(c, scene, root)?
            {
                continue;
            }
            let node = scene.add_node(root, format!("cell {c}"))?;
            scene.set_metadata(node, "cell", c as f64)?;
            for &i in cell_blocks.get(k).map(Vec::as_slice).unwrap_or_default() {
                let made = match blocks.get_mut(i).and_then(Option::take) {
                    Some(made) => made,
                    None => make_block(i),
                }?;
                if let Some((leaf, meshes)) = made {
                    push_leaf(scene, node, leaf, meshes)?;
                }
            }
            for &i in cell_buildings.get(k).map(Vec::as_slice).unwrap_or_default() {
                let (leaf, meshes, boxed) = match buildings.get_mut(i).and_then(Option::take) {
                    Some(made) => made,
                    None => make_building(i),
                }?;
                let leaf = push_leaf(scene, node, leaf, meshes)?;
                // Coarse level of detail: the footprint extruded to the building's height,
                // a child `lod 0` of the building node, whose own meshes become the finest
                // level. A footprint that cannot be extruded keeps its one level, drawn at
                // every distance.
                if let Some(mesh) = boxed {
                    scene.set_metadata(leaf, "lod", fine as f64)?;
                    let child = scene.add_node(leaf, "lod 0")?;
                    scene.set_metadata(child, "lod", 0.0)?;
                    let mesh = scene.add_mesh(mesh);
                    scene.attach_mesh(child, mesh)?;
                }
            }
        }
        Ok(water_and_ground)
    };
    let (road_layer, made) = par::join(
        || RoadLayer::new(inp.config, inp.network, elevation, inp.water),
        || cells_job(&mut scene),
    );
    let RoadLayer {
        bridges,
        surfaces,
        portals,
    } = road_layer?;
    let (water, terrain) = made?;
    let cells = scene.node(root)?.children.len();
    if let Some(terrain) = terrain {
        add_ground(&mut scene, root, terrain)?;
    }
    if let Some(parts) = surfaces {
        // Ribbons by class with their markings, junction plates apart (Kelly §5.4).
        let node = scene.add_node(root, "roads")?;
        scene.set_metadata(node, "layer", MetaValue::from_static("roads"))?;
        for mesh in crate::streets::road_meshes(&mut scene, parts)? {
            let mesh = scene.add_mesh(mesh);
            scene.attach_mesh(node, mesh)?;
        }
    }
    // Bridges: closed decks on piers under the road surfaces; the decks' mesh, then the
    // piers' (materials `bridge` and `bridge pier`).
    if bridges.decks.is_some() || bridges.piers.is_some() {
        let node = scene.add_node(root, "bridges")?;
        let parts = [
            (bridges.decks, "bridge", [0.62, 0.60, 0.57, 1.0]),
            (bridges.piers, "bridge pier", [0.55, 0.54, 0.52, 1.0]),
        ];
        for (mesh, name, colour) in parts {
            if let Some(mut mesh) = mesh {
                mesh.material = Some(scene.add_material(Material::new(name, colour)));
                let mesh = scene.add_mesh(mesh);
                scene.attach_mesh(node, mesh)?;
            }
        }
    }
    // Tunnels: a concrete frame at each portal (the road surface stops there).
    if let Some(mut mesh) = portals {
        let concrete = Material::new("tunnel portal", [0.55, 0.54, 0.52, 1.0]);
        mesh.material = Some(scene.add_material(concrete));
        let node = scene.add_node(root, "tunnel portals")?;
        let mesh = scene.add_mesh(mesh);
        scene.attach_mesh(node, mesh)?;
    }
    if !water.is_empty() {
        let material = scene.add_material(Material {
            roughness: 0.1,
            ..Material::new("water", [0.12, 0.28, 0.42, 1.0])
        });
        let mut mesh = Mesh::new(Some(material));
        for (polygon, level) in &water {
            mesh.add_flat_polygon(polygon, *level, Facing::Up)?;
        }
        let node = scene.add_node(root, "water")?;
        scene.set_metadata(node, "layer", MetaValue::from_static("water"))?;
        let mesh = scene.add_mesh(mesh);
        scene.attach_mesh(node, mesh)?;
    }

    // The layers before the cells among the root's children.
    scene.node_mut(root)?.children.rotate_left(cells);
    Ok(scene)
}

/// Room for the nodes (and meshes) of the layers added after the cells besides the
/// terrain's tiles: the roads (a mesh per class and marking), bridges, portals, water.
const LAYER_ROOM: usize = 64;

/// `make(i)` for every `i` where `made[i]`, in parallel; `None` for the others.
fn made_in_parallel<T: Send>(made: &[bool], make: impl Fn(usize) -> T + Sync) -> Vec<Option<T>> {
    made.par_iter()
        .enumerate()
        .map(|(i, &m)| m.then(|| make(i)))
        .collect()
}

/// A building's leaf as made: its node's parts, its meshes and its coarse box.
type BuildingMade = Result<(LeafNode, Vec<Mesh>, Option<Mesh>)>;

/// A block's leaf as made (`None`: no plinth, no leaf).
type BlockMade = Result<Option<(LeafNode, Vec<Mesh>)>>;

/// The blocks and buildings (with skins) of one cell of a scene, in the order
/// [`assemble`] puts their leaves under the cell's node.
pub(crate) struct CellItems<'a> {
    /// The cell's blocks.
    pub blocks: Vec<&'a std::sync::Arc<Block>>,
    /// The cell's buildings, each with its skin.
    pub buildings: Vec<(
        &'a std::sync::Arc<Building>,
        Option<&'a std::sync::Arc<Dress>>,
    )>,
}

/// Adds `leaf` with `meshes` as the last child of `parent`; returns its node.
fn push_leaf(
    scene: &mut Scene,
    parent: NodeId,
    leaf: LeafNode,
    meshes: Vec<Mesh>,
) -> Result<NodeId> {
    let node = scene.add_node(parent, leaf.name)?;
    let first = scene.meshes.len();
    let ids = (first..first + meshes.len())
        .map(|i| MeshId(i as u32))
        .collect();
    scene.meshes.extend(meshes);
    let n = scene.node_mut(node)?;
    n.transform = Transform::from_translation(leaf.translation);
    n.metadata = leaf.metadata;
    n.meshes = ids;
    Ok(node)
}

/// What a leaf node of the scene (a block, a building) is made of before it joins the
/// scene: kept small, as there is one per building until the scene takes them.
#[derive(Default)]
struct LeafNode {
    name: String,
    /// Placement relative to the cell node.
    translation: DVec3,
    metadata: Metadata,
}

/// The name of a building kind's map class: the `kind` of a building in the glb, the
/// GeoJSON and the SVG alike (the grammar's kind is the glb's `type`).
pub(crate) fn kind_class(kind: BuildingKind) -> &'static str {
    match kind {
        BuildingKind::Skyscraper => "skyscraper",
        BuildingKind::Office | BuildingKind::MidRise => "commercial",
        BuildingKind::House | BuildingKind::Apartment => "residential",
        BuildingKind::Industrial => "industrial",
    }
}

/// The SVG/GeoJSON kind of a building kind.
pub(crate) fn map_kind(kind: BuildingKind) -> polis_export::map::BuildingKind {
    use polis_export::map::BuildingKind as K;
    match kind {
        BuildingKind::Skyscraper => K::Skyscraper,
        BuildingKind::Office | BuildingKind::MidRise => K::Commercial,
        BuildingKind::House | BuildingKind::Apartment => K::Residential,
        BuildingKind::Industrial => K::Industrial,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_name_for_building_kinds() {
        for k in BuildingKind::ALL {
            assert_eq!(kind_class(k), map_kind(k).as_str());
        }
    }

    /// Each building's untextured meshes are one closed, outward solid with its parts'
    /// volume; the skins stand [`SKIN_OFFSET_M`] in front of the walls they dress.
    #[test]
    fn buildings_are_closed_solids_dressed_by_skins() {
        let mut config = CityConfig::preset("default").unwrap();
        config.size_m = 1200.0;
        config.roads.max_segments = 200;
        config.facades.pixels_per_metre = 4.0;
        let city = crate::generate(&config).unwrap();
        let mut scene = Scene::new();
        let pal = palette(&mut scene, &city.tile_sets).unwrap();
        let tiles: Vec<MaterialId> = pal.tiles.iter().flatten().copied().collect();
        let mut dressed = 0;
        for (b, dress) in city.buildings.iter().zip(&city.dresses) {
            let meshes = building_meshes(b, dress.as_deref(), &pal, None).unwrap();
            let (skins, mass): (Vec<&Mesh>, Vec<&Mesh>) = meshes
                .iter()
                .partition(|m| m.material.is_some_and(|k| tiles.contains(&k)));
            let report = polis_geom::mesh::edge_use(mass);
            assert!(report.is_solid(), "building {}: {report:?}", b.id);
            let parts: f64 = b.parts.iter().map(|p| p.mesh.signed_volume()).sum();
            assert!((report.signed_volume - parts).abs() <= 1e-3 * parts);
            // Every skin vertex lies the offset in front of a dressed face's plane.
            if let Some(d) = dress {
                for m in skins {
                    for p in &m.positions {
                        let p = p.as_dvec3();
                        let on_a_face = d.quads.iter().any(|q| {
                            let f = &b.facades[q.face as usize];
                            ((p - f.origin).dot(f.normal()) - SKIN_OFFSET_M).abs() < 1e-3
                        });
                        assert!(on_a_face, "building {}: skin vertex off its wall", b.id);
                    }
                }
            }
            dressed += usize::from(dress.is_some());
        }
        assert!(dressed > 10, "{dressed} dressed buildings");
    }
}
