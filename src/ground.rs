//! The ground of the 3-D scene: a terrain mesh of the whole map
//! ([`Terrain`](polis_geom::mesh::Terrain), an adaptive quadtree of the elevation map
//! with a stated error bound) textured by land use.
//!
//! The land-use texture is a [`ClassGrid`] of [`SceneConfig::land_use_pixels`]² pixels
//! (a power of two, sampled clamped to the edge) painted in order: bare land everywhere,
//! the bed of water bodies, built land (the blocks), parks (the park map's smooth
//! outlines and the lot stage's green spaces) on top. The terrain lies up to
//! `2 · max_error_m` below the elevation map and never above it (at its check points), so
//! road surfaces (a few centimetres above the map), block plinths (reaching
//! [`PLINTH_FOOT_M`](crate::scene::PLINTH_FOOT_M) below it) and buildings (carried
//! `2 · max_error_m` below their lowest corner) are never buried by it and reach down
//! into it.
//!
//! The node `ground` holds the terrain cut into the scene's tiles
//! ([`SceneConfig::tile_size_m`]; each triangle in the tile of its centroid, vertices on
//! a tile border copied bit for bit into each tile using them, so the tiles meet without
//! a seam), one mesh per tile in tile order: the tiled glb layout appends them as they
//! are instead of cutting a map-wide mesh each time it writes.
//!
//! References: Kelly 2008 §4.2, §6.2 (the city on its terrain); Parish & Müller 2001 §3
//! (elevation, water and parks as input maps).

use polis_geom::mesh::Terrain;
use polis_geom::paint::ClassGrid;
use polis_geom::scene::{Image, ImageData, Texture, Wrap};
use polis_geom::{Aabb2, DVec2, Field, Material, MaterialId, Mesh, PolygonWithHoles, Scene};

use crate::error::Result;
use crate::{CityConfig, SceneConfig};

/// Land-use classes of the ground texture, and their colours (linear RGB).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum LandUse {
    /// Land that is neither built nor a park: meadow.
    Bare = 0,
    /// The blocks of the city (under their plinths, and between them).
    Built = 1,
    /// Parks and green spaces.
    Park = 2,
    /// The bed of water bodies (under the water surface).
    WaterBed = 3,
}

impl LandUse {
    /// Every class, in code order.
    pub const ALL: [LandUse; 4] = [
        LandUse::Bare,
        LandUse::Built,
        LandUse::Park,
        LandUse::WaterBed,
    ];

    /// The class's colour, 8-bit sRGB.
    pub fn rgb(self) -> [u8; 3] {
        match self {
            LandUse::Bare => [150, 158, 104],
            LandUse::Built => [150, 146, 138],
            LandUse::Park => [84, 138, 66],
            LandUse::WaterBed => [120, 112, 92],
        }
    }
}

/// What the ground layer is made of, before it joins the scene.
pub(crate) struct Ground {
    /// The terrain, its mesh taken into `tiles`.
    pub terrain: Terrain,
    /// The terrain's mesh cut into the scene's tiles ([`SceneConfig::tile_size_m`],
    /// [`Mesh::cut_into_tiles`]), in tile order.
    pub tiles: Vec<Mesh>,
    pub land_use: ClassGrid,
}

/// The map's square.
pub(crate) fn map_bounds(config: &CityConfig) -> Aabb2 {
    let h = config.size_m * 0.5;
    Aabb2::new(DVec2::splat(-h), DVec2::splat(h))
}

/// Builds the terrain of `elevation` and paints the land-use classes.
pub(crate) fn build_ground<'a>(
    config: &CityConfig,
    elevation: &dyn Field,
    water: &[PolygonWithHoles],
    parks: &[PolygonWithHoles],
    blocks: impl Iterator<Item = &'a PolygonWithHoles> + Send,
) -> Result<Ground> {
    let bounds = map_bounds(config);
    let scene = &config.scene;
    let paint = || {
        let n = scene.land_use_pixels;
        let mut grid = ClassGrid::new(n, n, bounds, LandUse::Bare as u8);
        for w in water {
            grid.fill(w, LandUse::WaterBed as u8);
        }
        for b in blocks {
            grid.fill(b, LandUse::Built as u8);
        }
        for p in parks {
            grid.fill(p, LandUse::Park as u8);
        }
        grid
    };
    let (terrain, land_use) = polis_geom::par::join(
        || Terrain::build(elevation, bounds, &scene.terrain_mesh, None),
        paint,
    );
    let mut terrain = terrain?;
    // Cut here, once, rather than by every tiled glb written: the writer appends a
    // mesh that is already one tile's cut whole.
    let tiles = std::mem::take(&mut terrain.mesh)
        .cut_into_tiles(scene.tile_size_m)
        .into_iter()
        .map(|(_, mesh, _)| mesh)
        .collect();
    Ok(Ground {
        terrain,
        tiles,
        land_use,
    })
}

/// Adds the ground's texture, material and meshes (one per tile) to the scene under a
/// node `ground`.
pub(crate) fn add_ground(
    scene: &mut Scene,
    root: polis_geom::scene::NodeId,
    ground: Ground,
) -> Result<()> {
    let Ground {
        terrain,
        tiles,
        land_use,
    } = ground;
    let mut pixels = Vec::with_capacity(4 * land_use.cells.len());
    let colours = LandUse::ALL.map(LandUse::rgb);
    for &c in &land_use.cells {
        let [r, g, b] = colours.get(c as usize).copied().unwrap_or(colours[0]);
        pixels.extend([r, g, b, 255]);
    }
    let image = scene.add_image(Image {
        name: "ground land use".into(),
        data: ImageData::Rgba8 {
            width: land_use.width,
            height: land_use.height,
            pixels,
        },
    });
    let texture = scene.add_texture(Texture {
        name: "ground land use".into(),
        image,
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        ..Texture::default()
    })?;
    let material: MaterialId = scene.add_material(Material {
        base_color_texture: Some(texture),
        metallic: 0.0,
        roughness: 1.0,
        ..Material::new("ground", [1.0, 1.0, 1.0, 1.0])
    });
    let node = scene.add_node(root, "ground")?;
    scene.set_metadata(node, "max_error_m", terrain.report.max_error_m)?;
    for mut tile in tiles {
        tile.material = Some(material);
        let mesh = scene.add_mesh(tile);
        scene.attach_mesh(node, mesh)?;
    }
    Ok(())
}

/// Checks the ground options of the scene configuration.
pub(crate) fn validate(scene: &SceneConfig) -> std::result::Result<(), (&'static str, String)> {
    scene
        .terrain_mesh
        .validate()
        .map_err(|e| ("scene.terrain_mesh", e.to_string()))?;
    let n = scene.land_use_pixels;
    if !(n.is_power_of_two() && (16..=4096).contains(&n)) {
        return Err((
            "scene.land_use_pixels",
            format!("{n} must be a power of two from 16 to 4096"),
        ));
    }
    Ok(())
}

/// Thickness of a bridge deck under its road surface, metres.
pub const BRIDGE_DECK_M: f64 = 1.2;
/// Spacing of a bridge's piers along it, metres (at least one pier per bridge).
pub const BRIDGE_PIER_SPACING_M: f64 = 40.0;
/// Side of a square pier, metres.
const PIER_SIDE_M: f64 = 2.0;
/// How far a pier reaches into the ground below it, metres.
const PIER_FOOT_M: f64 = 1.0;

/// The decks and piers of the network's bridges (roads flagged `bridge` by the road
/// generator), as closed solids in one mesh: each deck a slab of the road's width,
/// [`BRIDGE_DECK_M`] thick, its top just under the road surface (which runs straight
/// between the bridge's ends at the ground's height there, as the road surfaces do),
/// and square piers every [`BRIDGE_PIER_SPACING_M`] from below the ground (or water bed)
/// up to the deck. `None` when there is no bridge.
pub(crate) fn bridge_mesh(
    network: &polis_roads::RoadNetwork,
    ground: &dyn Field,
) -> Result<Option<polis_geom::Mesh>> {
    use polis_geom::mesh::RefineOptions;
    use polis_geom::{Mesh, Polygon};
    let mut mesh = Mesh::new(None);
    // Under the road surface's lift (5 cm and the class lifts).
    let top = -0.04;
    let refine = RefineOptions {
        max_area: 1e9,
        ..RefineOptions::default()
    };
    for (e, _, _, road) in network.edges() {
        if !road.bridge || road.width <= 0.0 {
            continue;
        }
        let (a, b) = network.segment(e)?;
        let len = a.distance(b);
        if len <= 0.0 {
            continue;
        }
        let (ha, hb) = (ground.sample(a), ground.sample(b));
        if !(ha.is_finite() && hb.is_finite()) {
            continue;
        }
        let dir = (b - a) / len;
        let side = dir.perp() * (0.5 * road.width);
        let deck = PolygonWithHoles::new(
            Polygon::new(vec![a - side, a + side, b + side, b - side]),
            vec![],
        );
        let mut deck = deck;
        deck.normalize();
        let along = |p: DVec2| ha + (hb - ha) * ((p - a).dot(dir) / len).clamp(0.0, 1.0);
        mesh.add_draped_slab(&deck, &refine, along, top - BRIDGE_DECK_M, top)?;
        let piers = ((len / BRIDGE_PIER_SPACING_M).floor() as usize).max(1);
        for k in 1..=piers {
            let c = a + dir * (len * k as f64 / (piers + 1) as f64);
            let h = PIER_SIDE_M * 0.5;
            let square = PolygonWithHoles::new(
                Polygon::rect(c - DVec2::splat(h), c + DVec2::splat(h)),
                vec![],
            );
            let deck_bottom = along(c) + top - BRIDGE_DECK_M;
            let floor = ground.sample(c) - PIER_FOOT_M;
            if floor.is_finite() && floor < deck_bottom {
                mesh.add_prism(&square, floor, deck_bottom)?;
            }
        }
    }
    Ok((!mesh.is_empty()).then_some(mesh))
}
