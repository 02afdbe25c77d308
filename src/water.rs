//! Water bodies with depth: each body's surface at its level a little below its shores,
//! over a bed that falls from the shoreline to a stated depth.
//!
//! * **Bodies**: the smooth outlines of the water map ([`crate::smooth_mask`]). A body's
//!   **level** is its lowest shore point (a ring vertex not on the map's border) on the
//!   elevation map, less [`WATER_FREEBOARD_M`]; a body whose every vertex lies on the
//!   border takes the lowest of them.
//! * **Bed**: inside a body the ground lies `depth` below the ground around it (the
//!   elevation map, with the roads graded into it), where
//!   `depth = min(excess, bank(d))`: `excess` is how far the ground stands above the
//!   deepest bed, `level −` [`WATER_MAX_DEPTH_M`] (0 where the map is deeper already),
//!   and `bank(d)` grows with `d`, the distance to the nearest shore or *land*, at
//!   [`WATER_BANK_SLOPE`] (a 1:3 bank) up to [`WATER_BANK_M`], then steepens into a wall
//!   over the next [`WATER_BANK_WALL_M`] (ground far above the water needs a bed that
//!   deep within a bounded distance). The bed is continuous (`d` is 0 on the shoreline,
//!   where `depth` is 0), so the terrain meets the banks without a step; it crosses the
//!   water level at `d ≥ freeboard / slope` (1.5 m) inside the outline, so the water
//!   surface runs under the banks and no sliver of it lies above the ground.
//! * **Land inside the outline**: road corridors (off bridges and tunnels) and the city
//!   blocks that reach into a body keep their ground within [`WATER_LAND_MARGIN_M`] of
//!   their edges; the bed falls away from them like from a shore (a road along the coast
//!   whose edge the outline crosses stays on dry ground; a block in a bay is reclaimed).
//!
//! # Limitations
//! A body has one level. Where its shores stand at very different heights (a river
//! across a slope) the water lies far below the higher shores; where the elevation map
//! inside a body stands above its shores (hills in the sea) the bed falls from them too,
//! through the bank's wall if need be.
//!
//! References: Parish & Müller 2001 §3 (water as an input map); Kelly 2008 §6.2 (the
//! city on its terrain).

use polis_geom::predicates::distance_to_segment;
use polis_geom::spatial::{GridOptions, Shape, SpatialIndex};
use polis_geom::{Aabb2, DVec2, Field, PolygonWithHoles, SegmentIndex};

use crate::error::Result;

/// How far a water body's surface lies below its lowest shore point, metres.
pub const WATER_FREEBOARD_M: f64 = 0.5;
/// Deepest bed below a water body's surface, metres (the elevation map may be deeper).
pub const WATER_MAX_DEPTH_M: f64 = 6.0;
/// How fast the bed falls from the shore: depth per metre of distance (1:3).
pub const WATER_BANK_SLOPE: f64 = 1.0 / 3.0;
/// Widest bank at [`WATER_BANK_SLOPE`] from the shore, metres.
pub const WATER_BANK_M: f64 = 40.0;
/// Width over which a bank steeper than [`WATER_BANK_SLOPE`] becomes a wall where the
/// bed must be deeper than the bank reaches, metres.
pub const WATER_BANK_WALL_M: f64 = 10.0;
/// Margin around road corridors and blocks inside a water outline that keeps its
/// ground, metres.
pub const WATER_LAND_MARGIN_M: f64 = 2.0;

/// Height of the horizontal strips of the containment index, metres.
const STRIP_M: f64 = 8.0;
/// Cell of the distance indices, metres.
const CELL_M: f64 = 16.0;

/// How far below its ground the bed may lie at `d` metres from the shore or land (see
/// the [module docs](self)); infinite past the wall.
fn bank(d: f64) -> f64 {
    if d <= WATER_BANK_M {
        return WATER_BANK_SLOPE * d;
    }
    let x = (d - WATER_BANK_M) / WATER_BANK_WALL_M;
    if x < 1.0 {
        WATER_BANK_SLOPE * d + WATER_BANK_SLOPE * WATER_BANK_WALL_M * x / (1.0 - x)
    } else {
        f64::INFINITY
    }
}

/// Closed rings, each edge with its owner: even-odd containment by horizontal strips,
/// distances by a segment grid.
struct Rings {
    edges: Vec<(DVec2, DVec2, u32)>,
    index: SegmentIndex<u32>,
    strips: Vec<Vec<u32>>,
    y0: f64,
}

impl Rings {
    fn new<'a>(rings: impl Iterator<Item = (&'a [DVec2], u32)>) -> Result<Rings> {
        let mut edges = Vec::new();
        for (points, owner) in rings {
            for (k, &a) in points.iter().enumerate() {
                let b = points[(k + 1) % points.len()];
                if a != b {
                    edges.push((a, b, owner));
                }
            }
        }
        let mut index = SegmentIndex::new(GridOptions { cell_size: CELL_M })?;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (k, &(a, b, _)) in edges.iter().enumerate() {
            index.insert(k as u32, Shape::Segment(a, b))?;
            lo = lo.min(a.y.min(b.y));
            hi = hi.max(a.y.max(b.y));
        }
        let mut strips = Vec::new();
        if lo <= hi {
            let n = (((hi - lo) / STRIP_M).floor() as usize + 1).min(1 << 20);
            strips = vec![Vec::new(); n];
            for (k, &(a, b, _)) in edges.iter().enumerate() {
                let s0 = (((a.y.min(b.y) - lo) / STRIP_M).floor() as usize).min(n - 1);
                let s1 = (((a.y.max(b.y) - lo) / STRIP_M).floor() as usize).min(n - 1);
                for strip in &mut strips[s0..=s1] {
                    strip.push(k as u32);
                }
            }
        }
        Ok(Rings {
            edges,
            index,
            strips,
            y0: lo,
        })
    }

    /// The owner of the rings around `p`: the owner of the first edge a ray from `p`
    /// towards +x crosses, when it crosses an odd number of edges (the rings of the
    /// owners do not cross one another, holes belong to their polygon's owner).
    fn owner_at(&self, p: DVec2) -> Option<u32> {
        if !p.y.is_finite() || p.y < self.y0 {
            return None;
        }
        let strip = self
            .strips
            .get(((p.y - self.y0) / STRIP_M).floor() as usize)?;
        let (mut crossings, mut first) = (0u32, (f64::INFINITY, None));
        for &k in strip {
            let (a, b, owner) = self.edges[k as usize];
            if (a.y > p.y) != (b.y > p.y) {
                let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
                if x > p.x {
                    crossings += 1;
                    if x < first.0 {
                        first = (x, Some(owner));
                    }
                }
            }
        }
        if crossings % 2 == 1 { first.1 } else { None }
    }

    /// The distance from `p` to the nearest edge, or `reach` when none is nearer.
    fn distance_within(&self, p: DVec2, reach: f64) -> f64 {
        let mut d = reach;
        self.index
            .for_each_candidate(&Aabb2::new(p, p).expanded(reach), |k, _| {
                let (a, b, _) = self.edges[k as usize];
                d = d.min(distance_to_segment(p, a, b));
            });
        d
    }
}

/// A water body: its outline and the level of its surface, metres.
#[derive(Debug, Clone)]
pub(crate) struct WaterBody {
    pub polygon: PolygonWithHoles,
    pub level: f64,
}

/// The water bodies of a map and their shores: what the water map's outlines, the
/// elevation and the map's bounds fix, so an editor keeps them between runs on the same
/// maps ([`GroundReuse::water_base`](crate::scene::GroundReuse::water_base)).
pub(crate) struct WaterBase {
    bodies: Vec<WaterBody>,
    shore: Rings,
}

impl WaterBase {
    /// The bodies of `outlines` on `elevation` (levels) inside the map `bounds`.
    fn new(
        outlines: Vec<PolygonWithHoles>,
        elevation: &dyn Field,
        bounds: Aabb2,
    ) -> Result<WaterBase> {
        if outlines.is_empty() {
            return Ok(WaterBase {
                bodies: Vec::new(),
                shore: Rings::new(std::iter::empty())?,
            });
        }
        let border = 1e-6 * (bounds.max - bounds.min).max_element().max(1.0);
        let on_border = |p: DVec2| {
            (p.x - bounds.min.x).abs() <= border
                || (p.x - bounds.max.x).abs() <= border
                || (p.y - bounds.min.y).abs() <= border
                || (p.y - bounds.max.y).abs() <= border
        };
        let bodies: Vec<WaterBody> = outlines
            .into_iter()
            .map(|polygon| {
                let lowest = |shore_only: bool| {
                    polygon
                        .rings()
                        .flat_map(|(_, r)| r.points().iter().copied())
                        .filter(|&p| !shore_only || !on_border(p))
                        .map(|p| elevation.sample(p))
                        .filter(|e| e.is_finite())
                        .fold(f64::INFINITY, f64::min)
                };
                let shore = lowest(true);
                let low = if shore.is_finite() {
                    shore
                } else {
                    lowest(false)
                };
                let level = if low.is_finite() { low } else { 0.0 } - WATER_FREEBOARD_M;
                WaterBody { polygon, level }
            })
            .collect();
        let shore = Rings::new(
            bodies
                .iter()
                .enumerate()
                .flat_map(|(k, b)| b.polygon.rings().map(move |(_, r)| (r.points(), k as u32))),
        )?;
        Ok(WaterBase { bodies, shore })
    }
}

/// The water bodies of a city and what the bed under them needs: see the
/// [module docs](self).
pub(crate) struct Water {
    /// The bodies and their shores (what the water map and the elevation fix).
    base: std::sync::Arc<WaterBase>,
    /// Blocks that reach into a body (land inside an outline).
    blocks: Rings,
    /// Road corridors off bridges and tunnels within reach of a body (see
    /// [`Water::on`]): segments and half widths.
    roads: Vec<(DVec2, DVec2, f64)>,
    road_index: SegmentIndex<u32>,
    widest_road: f64,
    /// A digest of everything the bed reads besides the ground under it
    /// ([`bed_key`](Self::bed_key)).
    bed_key: crate::editor::key::Key,
}

impl Water {
    /// The bodies of `outlines` on `elevation` (levels) inside the map `bounds`, with the
    /// roads of `network` and the `blocks` as land. `None` without a body.
    #[cfg(test)]
    pub(crate) fn new<'a>(
        outlines: Vec<PolygonWithHoles>,
        elevation: &dyn Field,
        bounds: Aabb2,
        network: &polis_roads::RoadNetwork,
        blocks: impl Iterator<Item = &'a PolygonWithHoles>,
    ) -> Result<Option<Water>> {
        let base = WaterBase::new(outlines, elevation, bounds)?;
        Water::on(std::sync::Arc::new(base), network, blocks)
    }

    /// The bodies of `base` with the roads of `network` and the `blocks` as land. `None`
    /// without a body.
    fn on<'a>(
        base: std::sync::Arc<WaterBase>,
        network: &polis_roads::RoadNetwork,
        blocks: impl Iterator<Item = &'a PolygonWithHoles>,
    ) -> Result<Option<Water>> {
        if base.bodies.is_empty() {
            return Ok(None);
        }
        let (bodies, shore) = (&base.bodies, &base.shore);
        // Blocks with a corner in a body or an edge near a shore.
        let reaches_in = |b: &PolygonWithHoles| {
            let bbox = b.bbox().expanded(WATER_LAND_MARGIN_M);
            let mut near = false;
            shore.index.for_each_candidate(&bbox, |_, s| {
                near |= s.intersects_box(&bbox);
            });
            near || b
                .outer
                .points()
                .iter()
                .any(|&p| shore.owner_at(p).is_some())
        };
        let wet: Vec<&PolygonWithHoles> = blocks.filter(|b| reaches_in(b)).collect();
        let blocks = Rings::new(
            wet.iter()
                .enumerate()
                .flat_map(|(k, b)| b.rings().map(move |(_, r)| (r.points(), k as u32))),
        )?;
        let mut roads = Vec::new();
        for (e, _, _, road) in network.edges() {
            if road.bridge || road.tunnel {
                continue;
            }
            let (a, b) = network.segment(e)?;
            roads.push((a, b, 0.5 * road.width.max(0.0)));
        }
        let widest_road = roads.iter().map(|r| r.2).fold(0.0, f64::max);
        // A depth is read inside a body, within a bank's reach (`WATER_BANK_M +
        // WATER_BANK_WALL_M`) of its shore, from roads whose corridor with its margin
        // comes closer than that: no road farther from a body's box can change it. Only
        // the roads within that reach are kept (the rest of the city's roads would fill
        // the index on every edit for nothing).
        let reach = WATER_BANK_M + WATER_BANK_WALL_M + widest_road + WATER_LAND_MARGIN_M;
        let boxes: Vec<Aabb2> = bodies
            .iter()
            .map(|b| b.polygon.bbox().expanded(reach))
            .collect();
        roads.retain(|&(a, b, _)| {
            let seg = Aabb2::new(a.min(b), a.max(b));
            boxes.iter().any(|x| x.intersects(&seg))
        });
        let mut road_index = SegmentIndex::new(GridOptions { cell_size: CELL_M })?;
        for (k, &(a, b, _)) in roads.iter().enumerate() {
            road_index.insert(k as u32, Shape::Segment(a, b))?;
        }
        // The bed's digest: the bodies, the blocks that reach into them, and the roads
        // within reach of one (those kept). The blocks and roads in any order (the bed
        // reads them as sets: whether a point lies in a block, the nearest distances),
        // so an edit elsewhere that renumbers them keeps the digest.
        use crate::editor::key::Key;
        let mut bed_key = Key::new(0x7761_7465).u64(bodies.len() as u64);
        for b in bodies {
            bed_key = bed_key.region(&b.polygon).f64(b.level);
        }
        let mut land: Vec<Key> = wet.iter().map(|b| Key::new(1).region(b)).collect();
        land.extend(
            roads
                .iter()
                .map(|&(a, b, half)| Key::new(2).point(a).point(b).f64(half)),
        );
        land.sort_unstable();
        bed_key = bed_key.u64(land.len() as u64);
        for k in land {
            bed_key = bed_key.key(k);
        }
        Ok(Some(Water {
            base,
            blocks,
            roads,
            road_index,
            widest_road,
            bed_key,
        }))
    }

    /// The water bodies of a city's water map (none without one), with its roads and
    /// blocks as land. The bodies and their shores (the map's outlines, their levels and
    /// their grid) are taken from `kept` where it holds those of the same configuration
    /// (the editor's memo), and handed to it when made.
    pub(crate) fn of_city(
        config: &crate::CityConfig,
        maps: &crate::CityMaps,
        network: &polis_roads::RoadNetwork,
        blocks: &[std::sync::Arc<polis_lots::Block>],
        kept: Option<&dyn crate::scene::GroundReuse>,
    ) -> Result<Option<Water>> {
        if !maps.has_water {
            return Ok(None);
        }
        let base = match kept.and_then(|k| k.water_base()) {
            Some(base) => base,
            None => {
                let outlines = crate::city::smooth_mask(maps.inputs.water.as_ref(), config.size_m)?;
                let made = std::sync::Arc::new(WaterBase::new(
                    outlines,
                    maps.inputs.elevation.as_ref(),
                    crate::ground::map_bounds(config),
                )?);
                if let Some(k) = kept {
                    k.keep_water_base(&made);
                }
                made
            }
        };
        Water::on(base, network, blocks.iter().map(|b| &b.polygon))
    }

    /// The water bodies.
    pub(crate) fn bodies(&self) -> &[WaterBody] {
        &self.base.bodies
    }

    /// The body whose outline holds `p`.
    pub(crate) fn body_at(&self, p: DVec2) -> Option<&WaterBody> {
        self.base
            .shore
            .owner_at(p)
            .and_then(|k| self.base.bodies.get(k as usize))
    }

    /// How far below the ground `e` at `p` the bed lies there (0 outside the bodies).
    fn depth(&self, p: DVec2, e: f64) -> f64 {
        let Some(body) = self.body_at(p) else {
            return 0.0;
        };
        let excess = e - (body.level - WATER_MAX_DEPTH_M);
        if excess.is_nan() || excess <= 0.0 {
            return 0.0; // deep enough already (or not finite: left alone)
        }
        // `bank(d) ≥ excess` from this distance on.
        let reach = (excess / WATER_BANK_SLOPE).min(WATER_BANK_M + WATER_BANK_WALL_M);
        let mut d = self.base.shore.distance_within(p, reach);
        if d > 0.0 && !self.blocks.edges.is_empty() {
            if self.blocks.owner_at(p).is_some() {
                d = 0.0;
            } else {
                let m = WATER_LAND_MARGIN_M;
                let block = self.blocks.distance_within(p, d + m);
                if block < d + m {
                    d = d.min((block - m).max(0.0));
                }
            }
        }
        if d > 0.0 {
            let m = WATER_LAND_MARGIN_M;
            let b = Aabb2::new(p, p).expanded(d + self.widest_road + m);
            self.road_index.for_each_candidate(&b, |k, _| {
                let (a, q, half) = self.roads[k as usize];
                d = d.min((distance_to_segment(p, a, q) - half - m).max(0.0));
            });
        }
        if d >= reach {
            return excess; // past the bank (exactly: what a batch far from shores gives)
        }
        excess.min(bank(d))
    }

    /// A digest of everything the bed reads besides the ground it is cut into: the
    /// bodies, the blocks reaching into them and the roads near enough to one to bound
    /// a bank. Two waters with the same digest cut the same bed into the same ground.
    pub(crate) fn bed_key(&self) -> crate::editor::key::Key {
        self.bed_key
    }

    /// The bed under the bodies, on top of `base` (the ground elsewhere).
    pub(crate) fn bed<'a>(&'a self, base: &'a dyn Field) -> WaterBed<'a> {
        WaterBed { water: self, base }
    }
}

/// How far every shore stays from a batch of bed samples that [`WaterBed::sample_many`]
/// reads as lying on one side of all shores, metres: far beyond the rounding of the
/// shore crossings [`Water::body_at`] counts.
const SHORE_CLEAR_M: f64 = 1.0;

/// A ground field with the water bodies' bed cut into it: see [`Water::bed`].
pub(crate) struct WaterBed<'a> {
    water: &'a Water,
    base: &'a dyn Field,
}

impl Field for WaterBed<'_> {
    fn sample(&self, p: DVec2) -> f64 {
        let e = self.base.sample(p);
        e - self.water.depth(p, e)
    }

    /// The base's values at all the points, then the depths: one containment test for
    /// all of them where no shore, block or road comes within the widest bank of
    /// their bounding box (every point then lies in the same body, or none, and as far
    /// from shore and land as any bank reaches), else one per point. The same values as
    /// [`sample`](Field::sample).
    fn sample_many(&self, points: &[DVec2], out: &mut [f64]) {
        self.base.sample_many(points, out);
        let w = self.water;
        let far = Aabb2::of_finite_points(points).filter(|b| {
            let m = WATER_LAND_MARGIN_M;
            let bank = WATER_BANK_M + WATER_BANK_WALL_M;
            let near = |index: &SegmentIndex<u32>, by: f64| {
                let b = b.expanded(bank + by);
                let mut hit = false;
                index.for_each_candidate(&b, |_, s| hit |= s.intersects_box(&b));
                hit
            };
            !near(&w.base.shore.index, 0.0)
                && !near(&w.blocks.index, m)
                && !near(&w.road_index, w.widest_road + m)
        });
        match far {
            Some(_) => {
                let Some(body) = points.first().and_then(|&p| w.body_at(p)) else {
                    return; // on land (or no point): the base
                };
                if w.blocks.owner_at(points[0]).is_some() {
                    return; // all inside one block
                }
                for o in out.iter_mut().take(points.len()) {
                    let excess = *o - (body.level - WATER_MAX_DEPTH_M);
                    if excess > 0.0 {
                        *o -= excess; // past every bank
                    }
                }
            }
            None => {
                // No shore within a metre of the points' box: every point lies in the
                // body of the first, or on land with it (depth 0 at every point).
                let dry = Aabb2::of_finite_points(points).is_some_and(|b| {
                    let b = b.expanded(SHORE_CLEAR_M);
                    let mut hit = false;
                    w.base
                        .shore
                        .index
                        .for_each_candidate(&b, |_, s| hit |= s.intersects_box(&b));
                    !hit && points.iter().all(|p| p.is_finite())
                        && points.first().is_some_and(|&p| w.body_at(p).is_none())
                });
                if dry {
                    return;
                }
                for (&p, o) in points.iter().zip(out.iter_mut()) {
                    *o -= w.depth(p, *o);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // tests may panic on failure

    use super::*;
    use polis_geom::Polygon;
    use polis_geom::field::Constant;
    use polis_roads::{Junction, Road, RoadClass, RoadNetwork};

    fn square(h: f64) -> Aabb2 {
        Aabb2::new(DVec2::splat(-h), DVec2::splat(h))
    }

    /// A river 200 m wide across a 1 km map at 10 m, with an island, a street along its
    /// north bank whose edge the outline crosses, and a block reaching into it.
    #[test]
    fn the_bed_falls_from_shores_and_land_to_its_depth_continuously() {
        let river = PolygonWithHoles::new(
            Polygon::rect(DVec2::new(-500.0, -100.0), DVec2::new(500.0, 100.0)),
            vec![Polygon::new(vec![
                DVec2::new(-20.0, -20.0),
                DVec2::new(-20.0, 20.0),
                DVec2::new(20.0, 20.0),
                DVec2::new(20.0, -20.0),
            ])],
        );
        let mut net = RoadNetwork::new();
        let a = net
            .add_node(DVec2::new(-300.0, 103.0), Junction::default())
            .unwrap();
        let b = net
            .add_node(DVec2::new(300.0, 103.0), Junction::default())
            .unwrap();
        let street = Road {
            class: RoadClass::Street,
            width: 10.0,
            bridge: false,
            tunnel: false,
            step: 0,
        };
        net.add_edge(a, b, street).unwrap();
        let block = PolygonWithHoles::from(Polygon::rect(
            DVec2::new(200.0, -120.0),
            DVec2::new(260.0, -60.0),
        ));
        let ground = Constant(10.0);
        let water = Water::new(
            vec![river],
            &ground,
            square(500.0),
            &net,
            [&block].into_iter(),
        )
        .unwrap()
        .unwrap();
        let level = 10.0 - WATER_FREEBOARD_M;
        assert_eq!(water.bodies()[0].level, level);
        let bed = water.bed(&ground);
        // Mid-river: the deepest bed; on land and on the island: the ground.
        assert_eq!(bed.sample(DVec2::new(0.0, 0.0)), 10.0);
        let deepest = level - WATER_MAX_DEPTH_M;
        assert!((bed.sample(DVec2::new(-100.0, 0.0)) - deepest).abs() < 1e-9);
        assert!((bed.sample(DVec2::new(-100.0, -50.0)) - deepest).abs() < 1e-9);
        assert_eq!(bed.sample(DVec2::new(-100.0, 150.0)), 10.0);
        // The street's corridor and margin (5 + 2 m) keep their ground, then a 1:3 bank.
        for y in [96.0, 101.0] {
            assert_eq!(bed.sample(DVec2::new(0.0, y)), 10.0, "{y}");
        }
        let off = bed.sample(DVec2::new(0.0, 90.0));
        assert!((off - (10.0 - (103.0 - 90.0 - 7.0) * WATER_BANK_SLOPE)).abs() < 1e-9);
        // The block and its margin keep their ground.
        assert_eq!(bed.sample(DVec2::new(230.0, -80.0)), 10.0);
        assert_eq!(bed.sample(DVec2::new(230.0, -59.0)), 10.0);
        // Continuous: no step between points 1 cm apart across the map.
        let mut worst = 0.0f64;
        for i in 0..20_000 {
            let p = DVec2::new(-450.0 + 0.05 * i as f64, -130.0 + 0.0131 * i as f64);
            let q = p + DVec2::new(0.01, 0.0);
            worst = worst.max((bed.sample(p) - bed.sample(q)).abs());
        }
        assert!(worst <= 0.01 * WATER_BANK_SLOPE * 1.01 + 1e-9, "{worst}");
        // Under the surface from 1.5 m inside the outline (freeboard / slope), nowhere
        // deeper than the deepest bed.
        // (West of the block, away from the street and the island.)
        for i in 0..200 {
            let p = DVec2::new(-300.0 + 2.0 * i as f64, -100.0 + 1.6);
            let h = bed.sample(p);
            assert!(
                h < level && h >= level - WATER_MAX_DEPTH_M - 1e-9,
                "{p} {h}"
            );
        }
    }

    /// Many samples at once give the values of one at a time, bit for bit, in batches
    /// of a terrain leaf's 5 × 5 check points at every scale, near and far from shores,
    /// roads and blocks.
    #[test]
    fn many_samples_equal_single_ones() {
        let lake = PolygonWithHoles::new(
            Polygon::rect(DVec2::new(-400.0, -400.0), DVec2::new(400.0, 400.0)),
            vec![Polygon::new(vec![
                DVec2::new(-50.0, -50.0),
                DVec2::new(-50.0, 50.0),
                DVec2::new(50.0, 50.0),
                DVec2::new(50.0, -50.0),
            ])],
        );
        let mut net = RoadNetwork::new();
        let a = net
            .add_node(DVec2::new(-500.0, 390.0), Junction::default())
            .unwrap();
        let b = net
            .add_node(DVec2::new(500.0, 390.0), Junction::default())
            .unwrap();
        let street = Road {
            class: RoadClass::Street,
            width: 10.0,
            bridge: false,
            tunnel: false,
            step: 0,
        };
        net.add_edge(a, b, street).unwrap();
        let block = PolygonWithHoles::from(Polygon::rect(
            DVec2::new(-300.0, -420.0),
            DVec2::new(-100.0, -200.0),
        ));
        let hills = polis_geom::field::FnField::new(|p: DVec2| 8.0 + 0.01 * p.x + 0.002 * p.y);
        let water = Water::new(
            vec![lake],
            &hills,
            square(600.0),
            &net,
            [&block].into_iter(),
        )
        .unwrap()
        .unwrap();
        let bed = water.bed(&hills);
        let mut batches = 0;
        for size in [2.0, 8.0, 64.0, 256.0] {
            let n = (1200.0 / size) as i32;
            for i in 0..n {
                for j in 0..n {
                    let lo = DVec2::new(-600.0 + size * i as f64, -600.0 + size * j as f64);
                    let pts: Vec<DVec2> = (0..25)
                        .map(|k| lo + DVec2::new((k % 5) as f64, (k / 5) as f64) * (size / 4.0))
                        .collect();
                    let mut many = vec![0.0; 25];
                    bed.sample_many(&pts, &mut many);
                    for (p, m) in pts.iter().zip(&many) {
                        assert_eq!(m.to_bits(), bed.sample(*p).to_bits(), "{p} at {size}");
                    }
                    batches += 1;
                }
            }
        }
        assert!(batches > 1000);
    }

    /// Ground far above the water inside the outline: the bank steepens into a wall
    /// within the bank and wall widths; the bed is never above the ground.
    #[test]
    fn high_ground_inside_the_outline_falls_through_the_wall() {
        let lake = PolygonWithHoles::from(Polygon::rect(
            DVec2::new(-200.0, -200.0),
            DVec2::new(200.0, 200.0),
        ));
        // Shores at 0 m, a 500 m hill in the middle.
        let hill = polis_geom::field::FnField::new(
            |p: DVec2| {
                if p.length() < 100.0 { 500.0 } else { 0.0 }
            },
        );
        let water = Water::new(
            vec![lake],
            &hill,
            square(500.0),
            &RoadNetwork::new(),
            std::iter::empty(),
        )
        .unwrap()
        .unwrap();
        let bed = water.bed(&hill);
        let deepest = water.bodies()[0].level - WATER_MAX_DEPTH_M;
        let far = WATER_BANK_M + WATER_BANK_WALL_M;
        assert_eq!(bed.sample(DVec2::new(0.0, 0.0)), deepest);
        assert_eq!(bed.sample(DVec2::new(200.0 - far - 1.0, 0.0)), deepest);
        for i in 0..400 {
            let p = DVec2::new(-200.0 + i as f64, 37.0);
            assert!(bed.sample(p) <= hill.sample(p));
        }
    }
}
