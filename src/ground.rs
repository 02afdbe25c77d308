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
/// generator), as closed solids in one mesh, one shell each: a bridge is a chain of
/// bridge roads through nodes where exactly two bridge roads and nothing else meet (a
/// bridge split into several roads), and its deck is **one** slab along the chain (mitred
/// at the inner nodes, so neighbouring roads' decks neither overlap nor share a face),
/// [`BRIDGE_DECK_M`] thick, its top just under the road surface, which runs straight by
/// length along the chain between the ground at its two ends, as the road surfaces do
/// (`polis_export::surfaces`); square piers every [`BRIDGE_PIER_SPACING_M`] along the
/// chain reach from [`PIER_FOOT_M`] below the ground (or water bed) up to the deck,
/// where the ground is below the deck. A chain whose mitred outline is not a simple
/// polygon (a sharp zigzag of short roads) and a closed loop of bridges get one deck per
/// road instead. `None` when there is no bridge.
pub(crate) fn bridge_mesh(
    network: &polis_roads::RoadNetwork,
    ground: &dyn Field,
) -> Result<Option<polis_geom::Mesh>> {
    use polis_geom::Mesh;
    let mut mesh = Mesh::new(None);
    let mut done = vec![false; network.edge_bound()];
    for (e, _, _, road) in network.edges() {
        if !road.bridge || done[e.index()] {
            continue;
        }
        let chain = bridge_chain(network, e)?;
        for c in &chain {
            done[c.0.index()] = true;
        }
        let Some(path) = BridgePath::new(network, &chain, ground)? else {
            continue;
        };
        match path.outline() {
            Some(deck) => add_bridge(&mut mesh, &path, &deck, ground)?,
            // One deck per road: each its own chain of one.
            None => {
                for c in &chain {
                    if let Some(one) = BridgePath::new(network, &[*c], ground)?
                        && let Some(deck) = one.outline()
                    {
                        add_bridge(&mut mesh, &one, &deck, ground)?;
                    }
                }
            }
        }
    }
    Ok((!mesh.is_empty()).then_some(mesh))
}

/// Under the road surface's lift (5 cm and the class lifts), metres.
const DECK_TOP_M: f64 = -0.04;

/// The chain of bridge roads through `first` (see [`bridge_mesh`]), in order along it,
/// each with whether it runs backwards (from its second node to its first).
fn bridge_chain(
    network: &polis_roads::RoadNetwork,
    first: polis_geom::graph::EdgeId,
) -> Result<Vec<(polis_geom::graph::EdgeId, bool)>> {
    use polis_geom::graph::{EdgeId, NodeId};
    // The other bridge road at `n` when the chain runs through it.
    let through = |n: NodeId, from: EdgeId| -> Result<Option<EdgeId>> {
        let at = network.edges_at(n)?;
        if at.len() != 2 {
            return Ok(None);
        }
        let other = if at[0] == from { at[1] } else { at[0] };
        Ok((other != from && network.edge_payload(other)?.bridge).then_some(other))
    };
    let (a, b) = network.endpoints(first)?;
    // Walk from `b` forwards, then from `a` backwards; a closed loop stops where it began.
    let mut forward = vec![(first, false)];
    let (mut at, mut via) = (b, first);
    while let Some(next) = through(at, via)? {
        if next == first {
            return Ok(vec![(first, false)]); // a closed loop: one road at a time
        }
        let (p, _) = network.endpoints(next)?;
        let backwards = p != at;
        forward.push((next, backwards));
        at = network.other_end(next, at)?;
        via = next;
    }
    let mut backward = Vec::new();
    let (mut at, mut via) = (a, first);
    while let Some(next) = through(at, via)? {
        let (_, q) = network.endpoints(next)?;
        // Listed in chain order later: this road leads into `at`.
        let backwards = q != at;
        backward.push((next, backwards));
        at = network.other_end(next, at)?;
        via = next;
    }
    backward.reverse();
    backward.extend(forward);
    Ok(backward)
}

/// A bridge's centre line: its points, each segment's half width, and the deck's height
/// at each point (straight by length between the ground at the two ends).
struct BridgePath {
    points: Vec<DVec2>,
    half_widths: Vec<f64>,
    /// Length along the path at each point.
    at: Vec<f64>,
    heights: [f64; 2],
}

impl BridgePath {
    /// The path of `chain` (roads in order, with their direction); `None` when a road
    /// has no width or length or the ground is not finite at an end.
    fn new(
        network: &polis_roads::RoadNetwork,
        chain: &[(polis_geom::graph::EdgeId, bool)],
        ground: &dyn Field,
    ) -> Result<Option<BridgePath>> {
        let mut points = Vec::with_capacity(chain.len() + 1);
        let mut half_widths = Vec::with_capacity(chain.len());
        for &(e, backwards) in chain {
            let road = network.edge_payload(e)?;
            let (mut a, mut b) = network.segment(e)?;
            if backwards {
                std::mem::swap(&mut a, &mut b);
            }
            if road.width <= 0.0 || a.distance(b) <= 0.0 {
                return Ok(None);
            }
            if points.is_empty() {
                points.push(a);
            }
            points.push(b);
            half_widths.push(0.5 * road.width);
        }
        let mut at = vec![0.0];
        for w in points.windows(2) {
            at.push(at[at.len() - 1] + w[0].distance(w[1]));
        }
        let (Some(&first), Some(&last)) = (points.first(), points.last()) else {
            return Ok(None);
        };
        let heights = [ground.sample(first), ground.sample(last)];
        if !heights.iter().all(|h| h.is_finite()) {
            return Ok(None);
        }
        Ok(Some(BridgePath {
            points,
            half_widths,
            at,
            heights,
        }))
    }

    fn length(&self) -> f64 {
        self.at.last().copied().unwrap_or(0.0)
    }

    /// The deck's height (the road surface's, before its lift) `s` metres along.
    fn height_at(&self, s: f64) -> f64 {
        let total = self.length();
        let f = if total > 0.0 {
            (s / total).clamp(0.0, 1.0)
        } else {
            0.0
        };
        self.heights[0] + (self.heights[1] - self.heights[0]) * f
    }

    /// The point `s` metres along.
    fn point_at(&self, s: f64) -> DVec2 {
        let k = self
            .at
            .partition_point(|&a| a <= s)
            .clamp(1, self.points.len() - 1);
        let (a, b) = (self.points[k - 1], self.points[k]);
        let span = self.at[k] - self.at[k - 1];
        a + (b - a) * ((s - self.at[k - 1]) / span).clamp(0.0, 1.0)
    }

    /// Length along the path of the point of it nearest `p`.
    fn along(&self, p: DVec2) -> f64 {
        let mut best = (f64::INFINITY, 0.0);
        for (k, w) in self.points.windows(2).enumerate() {
            let d = w[1] - w[0];
            let t = ((p - w[0]).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            let dist = p.distance(w[0] + d * t);
            if dist < best.0 {
                best = (dist, self.at[k] + t * d.length());
            }
        }
        best.1
    }

    /// The deck's outline: the path offset by each segment's half width on both sides,
    /// mitred at the inner points (a mitre reaches at most four half widths from its
    /// point); `None` when that is not a simple polygon.
    fn outline(&self) -> Option<PolygonWithHoles> {
        let n = self.points.len();
        let dirs: Vec<DVec2> = self
            .points
            .windows(2)
            .map(|w| (w[1] - w[0]).normalize())
            .collect();
        // The offset corner at point `k` on side `sign` (+1 left, −1 right).
        let corner = |k: usize, sign: f64| -> DVec2 {
            let p = self.points[k];
            let left = |j: usize| dirs[j].perp() * (sign * self.half_widths[j]);
            if k == 0 {
                return p + left(0);
            }
            if k == n - 1 {
                return p + left(k - 1);
            }
            let (d0, d1) = (dirs[k - 1], dirs[k]);
            let (q0, q1) = (p + left(k - 1), p + left(k));
            let cross = d0.perp_dot(d1);
            let reach = 4.0 * self.half_widths[k - 1].max(self.half_widths[k]);
            if cross.abs() < 1e-9 {
                return q1;
            }
            // q0 + t·d0 = q1 + u·d1.
            let t = (q1 - q0).perp_dot(d1) / cross;
            let m = q0 + d0 * t;
            if m.distance(p) <= reach {
                m
            } else {
                p + (m - p).normalize_or_zero() * reach
            }
        };
        let mut ring: Vec<DVec2> = (0..n).map(|k| corner(k, -1.0)).collect();
        ring.extend((0..n).rev().map(|k| corner(k, 1.0)));
        let mut deck = PolygonWithHoles::new(polis_geom::Polygon::new(ring), vec![]);
        deck.normalize();
        deck.validate().is_ok().then_some(deck)
    }
}

/// Appends a bridge's deck (outline `deck`) and piers to `mesh`.
fn add_bridge(
    mesh: &mut Mesh,
    path: &BridgePath,
    deck: &PolygonWithHoles,
    ground: &dyn Field,
) -> Result<()> {
    use polis_geom::Polygon;
    use polis_geom::mesh::RefineOptions;
    // No refinement: the deck is straight along each segment.
    let refine = RefineOptions {
        max_area: 1e9,
        ..RefineOptions::default()
    };
    let height = |p: DVec2| path.height_at(path.along(p));
    mesh.add_draped_slab(
        deck,
        &refine,
        height,
        DECK_TOP_M - BRIDGE_DECK_M,
        DECK_TOP_M,
    )?;
    let len = path.length();
    let piers = ((len / BRIDGE_PIER_SPACING_M).floor() as usize).max(1);
    for k in 1..=piers {
        let s = len * k as f64 / (piers + 1) as f64;
        let c = path.point_at(s);
        let h = PIER_SIDE_M * 0.5;
        let square = PolygonWithHoles::new(
            Polygon::rect(c - DVec2::splat(h), c + DVec2::splat(h)),
            vec![],
        );
        let deck_bottom = path.height_at(s) + DECK_TOP_M - BRIDGE_DECK_M;
        let floor = ground.sample(c) - PIER_FOOT_M;
        if floor.is_finite() && floor < deck_bottom {
            mesh.add_prism(&square, floor, deck_bottom)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // tests may panic on failure

    use super::*;
    use polis_geom::field::FnField;
    use polis_roads::{Junction, Road, RoadClass, RoadNetwork};

    fn bridge(width: f64) -> Road {
        Road {
            class: RoadClass::Highway,
            width,
            bridge: true,
            tunnel: false,
            step: 0,
        }
    }

    /// A river 300 m wide and 8 m deep between banks at 10 m and 4 m.
    fn river() -> FnField<impl Fn(DVec2) -> f64 + Send + Sync> {
        FnField::new(|p: DVec2| {
            let bank = if p.x < 0.0 { 10.0 } else { 4.0 };
            if p.x.abs() < 150.0 { -8.0 } else { bank }
        })
    }

    /// A straight bridge split into two roads, a bent one of three roads (one of them
    /// reversed), each between roads on land: one deck per bridge, each shell closed and
    /// outward, the deck's volume its outline's area times its thickness, piers from
    /// below the river bed to the deck, deck tops straight between the banks.
    #[test]
    fn bridges_split_into_several_roads_are_one_deck_on_piers() {
        let mut net = RoadNetwork::new();
        let street = Road {
            bridge: false,
            ..bridge(12.0)
        };
        let mut node =
            |x: f64, y: f64| net.add_node(DVec2::new(x, y), Junction::default()).unwrap();
        let straight = [
            (-260.0, 0.0),
            (-160.0, 0.0),
            (0.0, 0.0),
            (160.0, 0.0),
            (260.0, 0.0),
        ]
        .map(|(x, y)| node(x, y));
        let bent = [
            (-260.0, 400.0),
            (-160.0, 400.0),
            (-40.0, 430.0),
            (60.0, 400.0),
            (160.0, 380.0),
        ]
        .map(|(x, y)| node(x, y));
        for (k, w) in straight.windows(2).enumerate() {
            let inner = (1..3).contains(&k);
            net.add_edge(w[0], w[1], if inner { bridge(12.0) } else { street })
                .unwrap();
        }
        net.add_edge(bent[0], bent[1], street).unwrap();
        net.add_edge(bent[1], bent[2], bridge(14.0)).unwrap();
        net.add_edge(bent[3], bent[2], bridge(14.0)).unwrap(); // reversed
        net.add_edge(bent[3], bent[4], bridge(14.0)).unwrap();
        let ground = river();
        let mesh = bridge_mesh(&net, &ground).unwrap().unwrap();
        let r = mesh.edge_use();
        assert!(r.is_solid_shells(), "{r:?}");
        // Straight: 320 m, a deck and 8 piers; bent: about 330 m, a deck and 8 piers (all
        // over the river).
        assert_eq!(r.shell_volumes.len(), 18, "{:?}", r.shell_volumes);
        let deck = 320.0 * 12.0 * BRIDGE_DECK_M;
        assert!(
            (r.shell_volumes[0] - deck).abs() < 1e-3 * deck,
            "{:?}",
            r.shell_volumes
        );
        // The piers of the straight bridge: 2 m squares from 1 m under the bed (−9 m)
        // to the deck's bottom, straight from 10 m to 4 m.
        for k in 1..=8 {
            let s = 320.0 * k as f64 / 9.0;
            let deck_bottom = 10.0 - 6.0 * s / 320.0 + DECK_TOP_M - BRIDGE_DECK_M;
            let want = 4.0 * (deck_bottom + 9.0);
            assert!((r.shell_volumes[k] - want).abs() < 1e-3 * want, "pier {k}");
        }
        // Every vertex of the decks lies within a deck's thickness under the road surface
        // straight between the banks, and nothing of the bridges is under the piers' feet.
        for p in &mesh.positions {
            let (q, h) = polis_geom::to_layout(p.as_dvec3());
            assert!(h >= -9.0 - 1e-3, "{q} {h}");
            assert!(h <= 10.0 + DECK_TOP_M + 1e-3, "{q} {h}");
        }
    }
}
