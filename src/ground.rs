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
//! The ground the terrain follows has the water bodies' bed cut in ([`crate::water`]);
//! the bridges ([`bridges`]) climb over the water on piers standing in that bed.
//!
//! References: Kelly 2008 §4.2, §6.2 (the city on its terrain); Parish & Müller 2001 §3
//! (elevation, water and parks as input maps).

use polis_geom::mesh::{Terrain, TerrainReport};
use polis_geom::paint::ClassGrid;
use polis_geom::scene::{Image, ImageData, Texture, Wrap};
use polis_geom::{Aabb2, DVec2, Field, Material, MaterialId, Mesh, PolygonWithHoles, Scene};

use crate::error::Result;
use crate::water::Water;
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
    /// The terrain's sizes and error.
    pub report: TerrainReport,
    /// The terrain's mesh cut into the scene's tiles ([`SceneConfig::tile_size_m`],
    /// [`Mesh::cut_into_tiles`]), in tile order.
    pub tiles: Vec<Mesh>,
    pub land_use: ClassGrid,
}

/// A terrain made earlier for the same ground, options and map: its report and tiles.
pub(crate) type TerrainTiles = (TerrainReport, Vec<Mesh>);

/// The map's square.
pub(crate) fn map_bounds(config: &CityConfig) -> Aabb2 {
    let h = config.size_m * 0.5;
    Aabb2::new(DVec2::splat(-h), DVec2::splat(h))
}

/// Builds the terrain of `elevation` (allowed `slack` metres further below it, where
/// given: [`Terrain::build_with_slack`]) and paints the land-use classes.
pub(crate) fn build_ground<'a>(
    config: &CityConfig,
    elevation: &dyn Field,
    slack: Option<&dyn Field>,
    water: &[PolygonWithHoles],
    parks: &[PolygonWithHoles],
    blocks: impl Iterator<Item = &'a PolygonWithHoles> + Send,
    made: Option<TerrainTiles>,
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
    let terrain = || -> Result<TerrainTiles> {
        if let Some(made) = made {
            return Ok(made);
        }
        let terrain = match slack {
            Some(slack) => {
                Terrain::build_with_slack(elevation, slack, bounds, &scene.terrain_mesh, None)?
            }
            None => Terrain::build(elevation, bounds, &scene.terrain_mesh, None)?,
        };
        // Cut here, once, rather than by every tiled glb written: the writer appends a
        // mesh that is already one tile's cut whole.
        let tiles = terrain
            .mesh
            .cut_into_tiles(scene.tile_size_m)
            .into_iter()
            .map(|(_, mesh, _)| mesh)
            .collect();
        Ok((terrain.report, tiles))
    };
    let (terrain, land_use) = polis_geom::par::join(terrain, paint);
    let (report, tiles) = terrain?;
    Ok(Ground {
        report,
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
        report,
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
    scene.set_metadata(node, "max_error_m", report.max_error_m)?;
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
/// Height of a bridge deck's underside above the water surface it crosses, metres,
/// where the span allows the deck to climb that high within its grade limit.
pub const BRIDGE_CLEARANCE_M: f64 = 8.0;
/// Half the length of a bridge deck's vertical curves (parabolas), metres.
pub const BRIDGE_CURVE_M: f64 = 25.0;
/// Side of a square pier, metres.
const PIER_SIDE_M: f64 = 2.0;
/// How far a pier reaches into the ground below it, metres.
pub const PIER_FOOT_M: f64 = 1.0;
/// Longest piece of a deck (and of a bridge's road profile) between two heights,
/// metres.
const DECK_STATION_M: f64 = 5.0;
/// How far beyond a bridge's end the grade of the road that leads on is read, metres.
const APPROACH_M: f64 = 10.0;

/// A network's bridges: their decks and piers, and the height profile of each bridge
/// road for its road surface.
pub(crate) struct Bridges {
    /// Every deck, one closed shell each; `None` without a deck.
    pub decks: Option<Mesh>,
    /// Every pier, one closed shell each; `None` without a pier.
    pub piers: Option<Mesh>,
    /// Per bridge road with a deck (by edge id): `(metres along the road from its first
    /// point, height of the road surface before its lift)` pairs, increasing.
    pub profiles: Vec<(u64, Vec<(f64, f64)>)>,
}

/// The decks and piers of the network's bridges (roads flagged `bridge` by the road
/// generator), as closed solids in one mesh, one shell each, and the profiles their road
/// surfaces follow.
///
/// A bridge is a chain of bridge roads through nodes where exactly two bridge roads and
/// nothing else meet (a bridge split into several roads), and its deck is **one** slab
/// along the chain (mitred at the inner nodes, so neighbouring roads' decks neither
/// overlap nor share a face), [`BRIDGE_DECK_M`] thick, its top just under the road
/// surface. The road surface follows the deck's profile ([`Profile`]): from the ground
/// at each end it climbs, within the chain's grade limit (the lowest of its roads'
/// classes in `grading`), to [`BRIDGE_CLEARANCE_M`] above the highest water surface
/// under it, bending over parabolic vertical curves of up to 2 · [`BRIDGE_CURVE_M`]
/// that start tangent to the road leading on at each end; a span too short to climb
/// that high rises as high as its grade allows; a chain with no water under it, or
/// whose ends lie further apart in height than its grade allows, runs straight. Square
/// piers every [`BRIDGE_PIER_SPACING_M`] along the chain reach from [`PIER_FOOT_M`]
/// below the ground (the water bed, `ground` being the ground with the bed cut in) up
/// to the deck's underside, where the ground is below it. A chain whose mitred outline
/// is not a simple polygon (a sharp zigzag of short roads) and a closed loop of bridges
/// get one deck per road instead.
pub(crate) fn bridges(
    network: &polis_roads::RoadNetwork,
    ground: &dyn Field,
    water: Option<&Water>,
    grading: &polis_roads::grading::GradeParams,
) -> Result<Bridges> {
    let mut mesh = [Mesh::new(None), Mesh::new(None)];
    let mut profiles = Vec::new();
    let mut done = vec![false; network.edge_bound()];
    let mut add = |path: &BridgePath, chain: &[Link], mesh: &mut [Mesh; 2]| -> Result<bool> {
        let Some(deck) = path.outline() else {
            return Ok(false);
        };
        add_bridge(mesh, path, &deck, ground)?;
        profiles.extend(path.road_profiles(chain));
        Ok(true)
    };
    for (e, _, _, road) in network.edges() {
        if !road.bridge || done[e.index()] {
            continue;
        }
        let chain = bridge_chain(network, e)?;
        for c in &chain {
            done[c.0.index()] = true;
        }
        let Some(path) = BridgePath::new(network, &chain, ground, water, grading)? else {
            continue;
        };
        if !add(&path, &chain, &mut mesh)? {
            // One deck per road: each its own chain of one.
            for c in &chain {
                if let Some(one) = BridgePath::new(network, &[*c], ground, water, grading)? {
                    add(&one, &[*c], &mut mesh)?;
                }
            }
        }
    }
    profiles.sort_by_key(|p| p.0);
    let [decks, piers] = mesh.map(|m| (!m.is_empty()).then_some(m));
    Ok(Bridges {
        decks,
        piers,
        profiles,
    })
}

/// Under the road surface's lift (5 cm and the class lifts), metres.
const DECK_TOP_M: f64 = -0.04;

/// A road of a bridge chain, and whether it runs backwards along the chain.
type Link = (polis_geom::graph::EdgeId, bool);

/// The chain of bridge roads through `first` (see [`bridges`]), in order along it,
/// each with whether it runs backwards (from its second node to its first).
fn bridge_chain(
    network: &polis_roads::RoadNetwork,
    first: polis_geom::graph::EdgeId,
) -> Result<Vec<Link>> {
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

/// A deck's height profile along its chain: a polyline of points of intersection
/// `(s, h)` whose inner corners are rounded by parabolas (vertical curves).
#[derive(Debug, Clone)]
struct Profile {
    pvi: Vec<(f64, f64)>,
    /// Half length of each corner's curve (0 at the two ends).
    half: Vec<f64>,
}

impl Profile {
    /// Straight from `h0` to `h1` over `len` metres.
    fn straight(len: f64, h0: f64, h1: f64) -> Profile {
        Profile {
            pvi: vec![(0.0, h0), (len, h1)],
            half: vec![0.0, 0.0],
        }
    }

    /// The highest smooth profile from `h0` to `h1` over `len` metres that keeps
    /// `grade` and climbs no higher than `top` (plus what the crest curves take back),
    /// leaving the start at grade `m0` and reaching the end at grade `m1` (the roads
    /// leading on, clamped to the grade), and never below the straight line between the
    /// ends. Straight when the ends lie further apart in height than `grade` allows.
    fn climbing(len: f64, [h0, h1]: [f64; 2], [m0, m1]: [f64; 2], grade: f64, top: f64) -> Profile {
        let (m0, m1) = (m0.clamp(-grade, grade), m1.clamp(-grade, grade));
        if !(len > 0.0 && grade > 0.0 && top.is_finite() && m0.is_finite() && m1.is_finite()) {
            return Profile::straight(len, h0, h1);
        }
        // The curves at the ends start tangent to the roads leading on: their corners
        // lie `a` metres in, on those roads' grades (an eighth of a short span: it
        // climbs sooner).
        let a = BRIDGE_CURVE_M.min(0.125 * len);
        let (s1, y1) = (a, h0 + m0 * a);
        let (s2, y2) = (len - a, h1 - m1 * a);
        let span = s2 - s1;
        if span.is_nan() || span <= 0.0 || (y2 - y1).abs() > grade * span {
            return Profile::straight(len, h0, h1);
        }
        // Between the corners: the straight line, or higher the grade-limited climb to
        // the top (raised by the most a crest curve takes back).
        let level = top + grade * BRIDGE_CURVE_M / 4.0;
        let sigma = (y2 - y1) / span;
        let f = |s: f64| {
            let up = y1 + grade * (s - s1);
            let down = y2 + grade * (s2 - s);
            let straight = y1 + sigma * (s - s1);
            straight.max(level.min(up).min(down))
        };
        let mut breaks = vec![s1, s2];
        breaks.push(s1 + (level - y1) / grade);
        breaks.push(s2 - (level - y2) / grade);
        breaks.push(0.5 * (y2 - y1 + grade * (s1 + s2)) / grade);
        if sigma != 0.0 {
            breaks.push(s1 + (level - y1) / sigma);
        }
        breaks.push((y2 - y1 + grade * s2 + sigma * s1) / (sigma + grade));
        let mut inner: Vec<f64> = breaks
            .into_iter()
            .filter(|s| s.is_finite() && *s >= s1 && *s <= s2)
            .collect();
        inner.sort_by(f64::total_cmp);
        inner.dedup_by(|x, y| (*x - *y).abs() < 1e-6);
        let mut pvi = vec![(0.0, h0)];
        pvi.extend(inner.into_iter().map(|s| (s, f(s))));
        pvi.push((len, h1));
        // Drop corners where the grade does not change.
        let mut kept: Vec<(f64, f64)> = Vec::with_capacity(pvi.len());
        for p in pvi {
            if kept.last().is_some_and(|q| p.0 - q.0 < 1e-6) {
                continue;
            }
            while kept.len() >= 2 {
                let (q, r) = (kept[kept.len() - 2], kept[kept.len() - 1]);
                let (m_qr, m_rp) = ((r.1 - q.1) / (r.0 - q.0), (p.1 - r.1) / (p.0 - r.0));
                if (m_qr - m_rp).abs() < 1e-9 {
                    kept.pop();
                } else {
                    break;
                }
            }
            kept.push(p);
        }
        // Each inner corner's curve: at most the nominal half length, and no more than
        // half its neighbouring legs (all of a leg to an end, which has no curve).
        let n = kept.len();
        let leg = |j: usize, k: usize| {
            let l = kept[k].0 - kept[j].0;
            if j == 0 || k == n - 1 { l } else { 0.5 * l }
        };
        let half = (0..n)
            .map(|i| {
                if i == 0 || i + 1 >= n {
                    0.0
                } else {
                    BRIDGE_CURVE_M.min(leg(i - 1, i)).min(leg(i, i + 1))
                }
            })
            .collect();
        Profile { pvi: kept, half }
    }

    fn length(&self) -> f64 {
        self.pvi.last().map_or(0.0, |p| p.0)
    }

    /// The height `s` metres along.
    fn height(&self, s: f64) -> f64 {
        let n = self.pvi.len();
        let s = s.clamp(0.0, self.length());
        let slope = |k: usize| {
            let (a, b) = (self.pvi[k], self.pvi[k + 1]);
            if b.0 > a.0 {
                (b.1 - a.1) / (b.0 - a.0)
            } else {
                0.0
            }
        };
        let k = self.pvi.partition_point(|p| p.0 <= s).clamp(1, n - 1) - 1;
        // A curve around the corner at either end of leg `k`.
        for i in [k, k + 1] {
            let a = self.half[i];
            let (si, hi) = self.pvi[i];
            if i > 0 && i + 1 < n && a > 0.0 && (s - si).abs() < a {
                let (m_in, m_out) = (slope(i - 1), slope(i));
                let x = s - si + a;
                return hi + m_in * (s - si) + (m_out - m_in) * x * x / (4.0 * a);
            }
        }
        let (a, b) = (self.pvi[k], self.pvi[k + 1]);
        if b.0 > a.0 {
            a.1 + (b.1 - a.1) * (s - a.0) / (b.0 - a.0)
        } else {
            a.1
        }
    }
}

/// A bridge's centre line: its points, each segment's half width, and the deck's
/// profile along it.
struct BridgePath {
    points: Vec<DVec2>,
    half_widths: Vec<f64>,
    /// Length along the path at each point.
    at: Vec<f64>,
    profile: Profile,
}

impl BridgePath {
    /// The path of `chain` (roads in order, with their direction) on `ground`, its
    /// profile climbing over the highest water surface under it; `None` when a road has
    /// no width or length or the ground is not finite at an end.
    fn new(
        network: &polis_roads::RoadNetwork,
        chain: &[Link],
        ground: &dyn Field,
        water: Option<&Water>,
        grading: &polis_roads::grading::GradeParams,
    ) -> Result<Option<BridgePath>> {
        let mut points = Vec::with_capacity(chain.len() + 1);
        let mut half_widths = Vec::with_capacity(chain.len());
        let mut grade = f64::INFINITY;
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
            grade = grade.min(grading.max_grade(road.class));
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
        let len = at.last().copied().unwrap_or(0.0);
        let mut path = BridgePath {
            points,
            half_widths,
            at,
            profile: Profile::straight(len, heights[0], heights[1]),
        };
        // The highest water surface under the path (inner points every station).
        let stations = (len / DECK_STATION_M).ceil().max(1.0) as usize;
        let surface = water.and_then(|w| {
            (1..stations)
                .filter_map(|k| w.body_at(path.point_at(len * k as f64 / stations as f64)))
                .map(|b| b.level)
                .reduce(f64::max)
        });
        if let Some(surface) = surface {
            // The grades of the roads leading on, read on the ground beyond each end.
            let n = path.points.len();
            let out0 = (path.points[0] - path.points[1]).normalize_or_zero();
            let out1 = (path.points[n - 1] - path.points[n - 2]).normalize_or_zero();
            let lead = |end: DVec2, out: DVec2, h: f64| {
                let g = ground.sample(end + out * APPROACH_M);
                if g.is_finite() {
                    (h - g) / APPROACH_M
                } else {
                    0.0
                }
            };
            let m0 = lead(first, out0, heights[0]);
            let m1 = -lead(last, out1, heights[1]);
            let top = surface + BRIDGE_CLEARANCE_M + BRIDGE_DECK_M - DECK_TOP_M;
            path.profile = Profile::climbing(len, heights, [m0, m1], grade, top);
        }
        Ok(Some(path))
    }

    fn length(&self) -> f64 {
        self.at.last().copied().unwrap_or(0.0)
    }

    /// The road surface's height (before its lift) `s` metres along.
    fn height_at(&self, s: f64) -> f64 {
        self.profile.height(s)
    }

    /// The deck's height (before its lift) `s` metres along as the deck is built: the
    /// profile at the outline's stations ([`outline`](Self::outline)), straight between
    /// them. On a crest curve the chord runs below the profile (by up to the curve's
    /// sag over one station), and a pier sized to the profile would poke into the deck.
    fn deck_height_at(&self, s: f64) -> f64 {
        let n = self.points.len();
        if n < 2 {
            return self.height_at(s);
        }
        let k = self.at.partition_point(|&a| a <= s).clamp(1, n - 1);
        let (a0, a1) = (self.at[k - 1], self.at[k]);
        let span = a1 - a0;
        if span.is_nan() || span <= 0.0 {
            return self.height_at(s);
        }
        let pieces = (span / DECK_STATION_M).ceil().max(1.0);
        let step = span / pieces;
        let j = ((s - a0) / step).floor().clamp(0.0, pieces - 1.0);
        let s0 = a0 + j * step;
        let s1 = if j + 1.0 >= pieces { a1 } else { s0 + step };
        let t = ((s - s0) / (s1 - s0)).clamp(0.0, 1.0);
        let (h0, h1) = (self.height_at(s0), self.height_at(s1));
        h0 + (h1 - h0) * t
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

    /// Each road's profile (see [`Bridges::profiles`]), sampled every
    /// [`DECK_STATION_M`] or less along it, from its own first point.
    fn road_profiles(&self, chain: &[Link]) -> Vec<(u64, Vec<(f64, f64)>)> {
        chain
            .iter()
            .zip(self.at.windows(2))
            .map(|(&(e, backwards), w)| {
                let len = w[1] - w[0];
                let n = (len / DECK_STATION_M).ceil().max(1.0) as usize;
                let samples = (0..=n)
                    .map(|j| {
                        let s = len * j as f64 / n as f64;
                        let along = if backwards { w[1] - s } else { w[0] + s };
                        (s, self.height_at(along))
                    })
                    .collect();
                (u64::from(e.raw()), samples)
            })
            .collect()
    }

    /// The deck's outline: the path offset by each segment's half width on both sides,
    /// mitred at the inner points (a mitre reaches at most four half widths from its
    /// point), with points every [`DECK_STATION_M`] or less along each side so the deck
    /// follows its profile; `None` when that is not a simple polygon.
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
        // One side's corners with the stations between them, from the first point on.
        let side = |sign: f64| -> Vec<DVec2> {
            let mut out = vec![corner(0, sign)];
            for k in 1..n {
                let (a, b) = (corner(k - 1, sign), corner(k, sign));
                let pieces = ((self.at[k] - self.at[k - 1]) / DECK_STATION_M)
                    .ceil()
                    .max(1.0) as usize;
                out.extend((1..pieces).map(|j| a.lerp(b, j as f64 / pieces as f64)));
                out.push(b);
            }
            out
        };
        let mut ring = side(-1.0);
        ring.extend(side(1.0).into_iter().rev());
        let mut deck = PolygonWithHoles::new(polis_geom::Polygon::new(ring), vec![]);
        deck.normalize();
        deck.validate().is_ok().then_some(deck)
    }
}

/// Appends a bridge's deck (outline `deck`) and piers to `mesh` (decks, piers).
fn add_bridge(
    [decks, piers]: &mut [Mesh; 2],
    path: &BridgePath,
    deck: &PolygonWithHoles,
    ground: &dyn Field,
) -> Result<()> {
    use polis_geom::Polygon;
    use polis_geom::mesh::RefineOptions;
    // No refinement: the outline has its stations along the profile.
    let refine = RefineOptions {
        max_area: 1e9,
        ..RefineOptions::default()
    };
    let height = |p: DVec2| path.height_at(path.along(p));
    decks.add_draped_slab(
        deck,
        &refine,
        height,
        DECK_TOP_M - BRIDGE_DECK_M,
        DECK_TOP_M,
    )?;
    let len = path.length();
    let count = ((len / BRIDGE_PIER_SPACING_M).floor() as usize).max(1);
    for k in 1..=count {
        let s = len * k as f64 / (count + 1) as f64;
        let c = path.point_at(s);
        let h = PIER_SIDE_M * 0.5;
        let square = PolygonWithHoles::new(
            Polygon::rect(c - DVec2::splat(h), c + DVec2::splat(h)),
            vec![],
        );
        // Up to the deck's underside at the pier's lowest corner (the deck tilts), as
        // built (straight between stations) or as profiled, whichever is lower.
        let under = |a: f64| path.height_at(a).min(path.deck_height_at(a));
        let deck_bottom = square
            .outer
            .points()
            .iter()
            .map(|&q| under(path.along(q)))
            .fold(under(s), f64::min)
            + DECK_TOP_M
            - BRIDGE_DECK_M;
        let floor = ground.sample(c) - PIER_FOOT_M;
        if floor.is_finite() && floor < deck_bottom {
            piers.add_prism(&square, floor, deck_bottom)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // tests may panic on failure

    use super::*;
    use polis_geom::field::FnField;
    use polis_roads::grading::GradeParams;
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
        let made = bridges(&net, &ground, None, &GradeParams::default()).unwrap();
        let mut mesh = made.decks.unwrap();
        mesh.append(&made.piers.unwrap());
        let r = mesh.edge_use();
        assert!(r.is_solid_shells(), "{r:?}");
        // Straight: 320 m, a deck and 8 piers; bent: about 330 m, a deck and 8 piers (all
        // over the river). Decks first, then piers.
        assert_eq!(r.shell_volumes.len(), 18, "{:?}", r.shell_volumes);
        let deck = 320.0 * 12.0 * BRIDGE_DECK_M;
        assert!(
            (r.shell_volumes[0] - deck).abs() < 1e-3 * deck,
            "{:?}",
            r.shell_volumes
        );
        // The piers of the straight bridge: 2 m squares from 1 m under the bed (−9 m)
        // to the deck's bottom at the pier's lower side, straight from 10 m to 4 m.
        for k in 1..=8 {
            let s = 320.0 * k as f64 / 9.0 + 1.0;
            let deck_bottom = 10.0 - 6.0 * s / 320.0 + DECK_TOP_M - BRIDGE_DECK_M;
            let want = 4.0 * (deck_bottom + 9.0);
            let got = r.shell_volumes[1 + k];
            assert!((got - want).abs() < 1e-3 * want, "pier {k}: {got} {want}");
        }
        // Every vertex of the decks lies within a deck's thickness under the road surface
        // straight between the banks, and nothing of the bridges is under the piers' feet.
        for p in &mesh.positions {
            let (q, h) = polis_geom::to_layout(p.as_dvec3());
            assert!(h >= -9.0 - 1e-3, "{q} {h}");
            assert!(h <= 10.0 + DECK_TOP_M + 1e-3, "{q} {h}");
        }
    }

    /// A straight highway bridge of one road across a river `width` metres wide (banks
    /// at 5 m, the water bed of `crate::water`), and the bridges of that map.
    fn river_crossing(width: f64) -> (RoadNetwork, Water, Bridges, f64) {
        let half = 0.5 * width;
        let mut net = RoadNetwork::new();
        let street = Road {
            bridge: false,
            ..bridge(12.0)
        };
        let xs = [-half - 100.0, -half - 5.0, half + 5.0, half + 100.0];
        let nodes = xs.map(|x| {
            net.add_node(DVec2::new(x, 0.0), Junction::default())
                .unwrap()
        });
        net.add_edge(nodes[0], nodes[1], street).unwrap();
        net.add_edge(nodes[1], nodes[2], bridge(12.0)).unwrap();
        net.add_edge(nodes[2], nodes[3], street).unwrap();
        let river = PolygonWithHoles::from(polis_geom::Polygon::rect(
            DVec2::new(-half, -1000.0),
            DVec2::new(half, 1000.0),
        ));
        let banks = polis_geom::field::Constant(5.0);
        let bounds = Aabb2::new(DVec2::splat(-1000.0), DVec2::splat(1000.0));
        let water = Water::new(vec![river], &banks, bounds, &net, std::iter::empty())
            .unwrap()
            .unwrap();
        let made = bridges(
            &net,
            &water.bed(&banks),
            Some(&water),
            &GradeParams::default(),
        )
        .unwrap();
        (net, water, made, width + 10.0)
    }

    /// Over a wide river the deck climbs to the clearance; over a narrow one as high as
    /// the grade allows: checked at every deck vertex over the water against the bound
    /// the documentation states; the road profile keeps the grade limit; piers stand
    /// on the bed (a foot into it) up to the deck's underside; every shell is closed.
    #[test]
    fn decks_clear_the_water_and_piers_stand_on_its_bed() {
        let g = GradeParams::default().max_grade_highway;
        let level = 5.0 - crate::water::WATER_FREEBOARD_M;
        for width in [600.0, 150.0] {
            let (_, water, made, len) = river_crossing(width);
            let decks = made.decks.clone().unwrap();
            let piers = made.piers.clone().unwrap();
            for m in [&decks, &piers] {
                let r = m.edge_use();
                assert!(r.is_solid_shells(), "{r:?}");
            }
            // The profile: within the grade, from the ground at both ends.
            let (_, profile) = &made.profiles[0];
            assert!((profile[0].1 - 5.0).abs() < 1e-9);
            assert!((profile[profile.len() - 1].1 - 5.0).abs() < 1e-9);
            let steepest = profile
                .windows(2)
                .map(|w| ((w[1].1 - w[0].1) / (w[1].0 - w[0].0)).abs())
                .fold(0.0, f64::max);
            assert!(steepest <= g + 1e-9, "{steepest}");
            // Deck bottoms over the water: at least the clearance, or the bound the span
            // allows (`min over ends of h + g · (d − 3 A)`).
            let x0 = -0.5 * len;
            let mut lowest = f64::INFINITY;
            let mut over = 0;
            for (p, n) in decks.positions.iter().zip(&decks.normals) {
                let (q, h) = polis_geom::to_layout(p.as_dvec3());
                if n.y > -0.5 || water.body_at(q).is_none() {
                    continue;
                }
                over += 1;
                let d = (q.x - x0).min(len - (q.x - x0));
                let span =
                    5.0 + g * (d - 3.0 * BRIDGE_CURVE_M) - (BRIDGE_DECK_M - DECK_TOP_M) - level;
                let want = BRIDGE_CLEARANCE_M.min(span);
                assert!(
                    h - level >= want - 1e-3,
                    "{width}: {q} {} < {want}",
                    h - level
                );
                if d > 0.5 * len - 1.0 {
                    lowest = lowest.min(h - level);
                }
            }
            assert!(over > 10, "{over}");
            if width > 500.0 {
                assert!(lowest >= BRIDGE_CLEARANCE_M - 1e-3, "{lowest}");
            } else {
                // 160 m at 6 % after 20 m curves at the ends: 3.6 m up at mid-span, less
                // the crest curve's 0.75 m and the deck: its underside 2.1 m above the
                // water.
                assert!(lowest > 2.0 && lowest < BRIDGE_CLEARANCE_M, "{lowest}");
            }
            // Piers: from a foot below the bed up to the deck, positive heights.
            let bed = water.bed(&polis_geom::field::Constant(5.0));
            let r = piers.edge_use();
            assert!(r.shell_volumes.len() >= 3);
            for k in 0..piers.positions.len() / 24 {
                let ps = &piers.positions[24 * k..24 * (k + 1)];
                let lo = ps.iter().map(|p| p.y as f64).fold(f64::INFINITY, f64::min);
                let hi = ps
                    .iter()
                    .map(|p| p.y as f64)
                    .fold(f64::NEG_INFINITY, f64::max);
                let c = ps
                    .iter()
                    .map(|p| polis_geom::to_layout(p.as_dvec3()).0)
                    .sum::<DVec2>()
                    / ps.len() as f64;
                assert!(hi > lo, "pier {k}");
                assert!(
                    (lo - (bed.sample(c) - PIER_FOOT_M)).abs() < 1e-3,
                    "pier {k} at {c}"
                );
            }
        }
    }

    #[test]
    fn profiles_keep_the_grade_and_meet_their_ends() {
        let g = 0.06;
        let cases = [
            (800.0, [5.0, 5.0], [0.0, 0.0]),
            (120.0, [5.0, 9.0], [0.05, -0.02]),
            (300.0, [20.0, 5.0], [-0.06, 0.06]),
            (50.0, [0.0, 30.0], [0.0, 0.0]), // too steep: straight
        ];
        for (len, h, m) in cases {
            let p = Profile::climbing(len, h, m, g, 14.0);
            assert!((p.height(0.0) - h[0]).abs() < 1e-9);
            assert!((p.height(len) - h[1]).abs() < 1e-9);
            let straight = (h[1] - h[0]).abs() / len;
            let mut prev = p.height(0.0);
            for i in 1..=1000 {
                let s = len * i as f64 / 1000.0;
                let y = p.height(s);
                let grade = (y - prev).abs() / (len / 1000.0);
                assert!(grade <= g.max(straight) + 1e-6, "{len} {s} {grade}");
                // Smooth: no jump.
                assert!((y - prev).abs() <= g.max(straight) * len / 1000.0 + 1e-6);
                prev = y;
            }
        }
    }
}
