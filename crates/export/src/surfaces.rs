//! Road surface meshes: ribbons of each road's width joined by junction polygons, draped
//! on an elevation field, for the glTF and OBJ writers.
//!
//! [`road_surfaces`] turns the [`MapRoad`]s of a map into one [`Mesh`] (one material):
//!
//! * **The network.** Every centre-line point is a node; roads that share a point (exactly)
//!   meet there. Each segment between two nodes becomes a ribbon of its road's width.
//!   Duplicate segments (the same two nodes twice) keep the wider road.
//! * **Junctions.** At every node of degree ≥ 2 the incident segments are sorted
//!   counter-clockwise ([`ccw_cmp`](polis_geom::predicates::ccw_cmp)). Where two
//!   consecutive roads enclose less than a half-turn, the left border of one meets the
//!   right border of the next; each ribbon is cut square at the farthest such corner along
//!   it, and the junction polygon runs cut, corner, cut, … around the node. A gap of more
//!   than a half-turn (the outside of a bend) gets a miter up to [`MITER_LIMIT`]
//!   half-widths, else a bevel; a gap of exactly a half-turn a step between the borders.
//!   A node where one road continues straight (two segments, exactly opposite) needs no
//!   polygon. The polygon is star-shaped around the node (checked exactly) and
//!   triangulated with [`triangulate`](polis_geom::mesh::triangulate).
//! * **Dead ends** (degree 1) get an [`EndCap`]: round by default.
//! * **Short segments.** When the two junctions of a segment want more than its length
//!   (a crossing split into two T's a few metres apart, a fork on a short stem), they
//!   **merge** into one polygon: the outside roads of the group are walked
//!   counter-clockwise around it (around each node in its order, across each short
//!   segment), consecutive roads of one node meet as above, roads of different nodes where
//!   their borders cross (or by a bevel), and the polygon must be simple and
//!   counter-clockwise. Short segments forming a cycle, or ending in a dead end, are not
//!   merged: both cuts are shortened in proportion (the ribbon vanishes) and a corner that
//!   then lies beyond a cut is joined by a chord. A polygon that is not star-shaped around
//!   its node (resp. not simple, when merged) after that (near-parallel roads on short
//!   segments, overlapping segments) becomes the convex hull of its corners.
//!   [`RoadSurfaceReport`] counts every case; on the default `polis-roads` networks
//!   (seeds 1, 3, 7; about 3,400 segments and 2,000 junctions each) 68–91 junctions merge
//!   and 9–18 (under 1 %) are hulls.
//! * **Draping.** Every vertex is lifted to the elevation field at its own layout point
//!   plus [`RoadSurfaceOptions::lift_m`]; segments longer than
//!   [`RoadSurfaceOptions::max_segment_m`] are subdivided. Bridges instead run straight
//!   between their cut ends (or follow their [`MapRoad::profile`] where they have one),
//!   and a node all of whose roads are bridges is a flat deck:
//!   inside a chain of bridge segments (one bridge road with several points, or a bridge
//!   split into several roads) at the height interpolated by length between the chain's
//!   ends on land; at a dead end or a branching of bridges, at the terrain height under
//!   the bridge roads' end points, interpolated along each road.
//! * **Classes.** Each class is lifted by [`RoadSurfaceOptions::class_lift_m`] per rank
//!   (footpath < other < street < major < highway); a junction takes the highest rank of
//!   its roads, and a ribbon's cut ends take their junction's height, so ribbon and
//!   junction share their edge exactly. Roads that cross without a shared point (a bridge
//!   over a street, or input that is not planar) overlap, the larger class on top.
//! * **Texture coordinates** are metres: on ribbons `u` along the road (from its start)
//!   and `v` across it (`0` on the right edge to `−width` on the left), so a lane-marking
//!   texture runs along the road; on junctions and caps the layout position `(x, −y)`.
//!   Ribbons are flat shaded per quad; each junction has one normal (the area-weighted
//!   mean of its triangles').
//!
//! ## Guarantees
//!
//! On a planar network (roads meet only at shared points, as a
//! [`PlanarGraph`](polis_geom::PlanarGraph) gives them) whose segments are long enough for
//! their junctions (no segment clamped) and whose roads keep their width apart elsewhere,
//! ribbons and junction polygons do not overlap: the property tests check pairwise-disjoint
//! interiors on random planar graphs. The mesh always passes
//! [`Mesh::validate`](polis_geom::Mesh::validate) (no NaN, no zero-area triangle).
//!
//! ## Limitations
//!
//! * Roads crossing without a shared point are not split: their ribbons overlap.
//! * The terrain is sampled at the vertices only; a wide junction may float above or dip
//!   below terrain that bends inside it.
//! * Clamped junctions (near-parallel roads on very short segments) may overlap their
//!   neighbours; the report counts them.
//!
//! ## Footpaths
//!
//! The footpath strips around blocks are meshed by [`crate::footpaths`].

use std::collections::BTreeMap;

use polis_geom::field::Field;
use polis_geom::glam::DVec3;
use polis_geom::mesh::to_world;
use polis_geom::scene::MaterialId;
use polis_geom::{DVec2, Mesh};

use crate::ExportError;
use crate::map::{MapRoad, check_roads};

mod junctions;

pub use junctions::MIN_TRIM_HALF_WIDTHS;

/// The longest miter, in half-widths (2 = turns up to 120° are exact).
pub const MITER_LIMIT: f64 = 2.0;

/// How a road ends at a dead end (a node with one road).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum EndCap {
    /// The ribbon stops square at the node.
    Flat,
    /// The ribbon goes on half its width past the node.
    Square,
    /// A half-disc of the road's width past the node, as a polygon of `segments` edges
    /// (at least 2).
    Round {
        /// Edges of the half-disc's arc.
        segments: u32,
    },
}

impl Default for EndCap {
    fn default() -> Self {
        EndCap::Round { segments: 8 }
    }
}

/// Options of [`road_surfaces`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct RoadSurfaceOptions {
    /// Longest piece of ribbon between two terrain samples, metres (finite, > 0).
    /// Default: 10.0.
    pub max_segment_m: f64,
    /// Height of the surface above the terrain, metres (finite). Default: 0.05.
    pub lift_m: f64,
    /// Extra height per class rank, metres (finite, ≥ 0). Default: 0.02.
    pub class_lift_m: f64,
    /// The cap at dead ends. Default: `EndCap::Round { segments: 8 }`.
    pub end_cap: EndCap,
}

impl Default for RoadSurfaceOptions {
    fn default() -> Self {
        RoadSurfaceOptions {
            max_segment_m: 10.0,
            lift_m: 0.05,
            class_lift_m: 0.02,
            end_cap: EndCap::default(),
        }
    }
}

/// What [`road_surfaces_with_report`] built and which hard cases it met.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub struct RoadSurfaceReport {
    /// Junction polygons and dead-end caps in the mesh.
    pub junctions: usize,
    /// Segments dropped because another segment joins the same two points (the wider
    /// one is kept).
    pub duplicate_segments: usize,
    /// Segments too short for the cuts both junctions wanted (cuts shortened).
    pub clamped_segments: usize,
    /// Junctions merged with a neighbour into one polygon because the segment between
    /// them is shorter than the cuts both wanted (counted once per merged polygon).
    pub merged_junctions: usize,
    /// Corners between two roads joined by a chord because a cut was shortened.
    pub clamped_corners: usize,
    /// Junctions replaced by the convex hull of their corners (near-parallel roads on
    /// short segments, overlapping segments).
    pub approximated_junctions: usize,
    /// Junctions left out because their polygon was degenerate.
    pub skipped_junctions: usize,
}

/// Builds the road surfaces of `roads` (ribbons, junctions, dead-end caps) as one mesh
/// with `material`, draped on `elevation` (metres above the layout plane at each layout
/// point). See the [module docs](self) for the construction.
///
/// Roads are checked as [`MapLayers::validate`](crate::map::MapLayers::validate) checks
/// them; zero-width roads and
/// zero-length segments are skipped. Fails with [`ExportError::InvalidMap`] when the
/// elevation field returns a non-finite value, [`ExportError::InvalidOption`] on options
/// out of range.
///
/// ```
/// use polis_export::map::{MapRoad, RoadClass};
/// use polis_export::surfaces::{road_surfaces, EndCap, RoadSurfaceOptions};
/// use polis_export::geom::{DVec2, field::Constant};
/// // A crossing of two 100 m streets, 8 m wide: 2 × 800 m² less the shared 64 m².
/// let a = MapRoad::new(vec![DVec2::new(-50.0, 0.0), DVec2::ZERO, DVec2::new(50.0, 0.0)], RoadClass::Street, 8.0);
/// let b = MapRoad::new(vec![DVec2::new(0.0, -50.0), DVec2::ZERO, DVec2::new(0.0, 50.0)], RoadClass::Street, 8.0);
/// let options = RoadSurfaceOptions { end_cap: EndCap::Flat, ..Default::default() };
/// let mesh = road_surfaces(&[a, b], &Constant(0.0), &options, None)?;
/// mesh.validate()?;
/// assert!((mesh.surface_area() - (1600.0 - 64.0)).abs() < 1e-2);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn road_surfaces(
    roads: &[MapRoad],
    elevation: &dyn Field,
    options: &RoadSurfaceOptions,
    material: Option<MaterialId>,
) -> Result<Mesh, ExportError> {
    road_surfaces_with_report(roads, elevation, options, material).map(|(mesh, _)| mesh)
}

/// [`road_surfaces`] with the [`RoadSurfaceReport`] of the hard cases met.
pub fn road_surfaces_with_report(
    roads: &[MapRoad],
    elevation: &dyn Field,
    options: &RoadSurfaceOptions,
    material: Option<MaterialId>,
) -> Result<(Mesh, RoadSurfaceReport), ExportError> {
    check_options(options)?;
    check_roads(roads)?;
    let plan = junctions::plan(roads, options);
    let drape = Drape::new(roads, &plan, elevation, options)?;
    // Room for everything below (an upper bound: degenerate pieces are skipped), so the
    // one large mesh never grows by doubling.
    let ribbons = || plan.edges.iter().filter(|e| !e.dropped && !e.internal);
    let pieces: usize = ribbons().map(|e| ribbon_pieces(e, options)).sum();
    let mut mesh = Mesh::with_capacity(
        material,
        4 * pieces + ring_vertices(&plan),
        2 * pieces + ring_triangles(&plan),
    );
    for e in ribbons() {
        add_ribbon(&mut mesh, roads, e, &drape, options)?;
    }
    let mut report = plan.report.clone();
    for j in &plan.junctions {
        if !add_junction(&mut mesh, j, &drape)? {
            report.skipped_junctions += 1;
            report.junctions -= 1;
        }
    }
    Ok((mesh, report))
}

/// Vertices of every junction ring of `plan`.
fn ring_vertices(plan: &junctions::Plan) -> usize {
    plan.junctions.iter().map(|j| j.ring.len()).sum()
}

/// Triangles of every junction of `plan`.
fn ring_triangles(plan: &junctions::Plan) -> usize {
    plan.junctions.iter().map(|j| j.triangles.len()).sum()
}

/// The ribbons of one road class and width (see [`RoadSurfaceParts`]).
#[derive(Debug, Clone)]
pub struct RibbonGroup {
    /// The class of the roads.
    pub class: crate::map::RoadClass,
    /// Their width, metres.
    pub width_m: f64,
    /// The ribbons, texture coordinates in metres as in [`road_surfaces`] (`u` along the
    /// road, `v` from `0` on the right edge to `−width_m` on the left), no material.
    pub mesh: Mesh,
}

/// [`road_surfaces`] in separate surfaces (Kelly §5.4: roads as textured geometry,
/// junction plates as their own surfaces): the ribbons grouped by class and width, so
/// each group can take a texture laid out across its width, and the junction plates and
/// dead-end caps apart.
#[derive(Debug, Clone)]
pub struct RoadSurfaceParts {
    /// Ribbons by (class rank, class, width), in that order.
    pub ribbons: Vec<RibbonGroup>,
    /// Junction plates and dead-end caps, texture coordinates the layout position
    /// `(x, −y)` in metres, no material.
    pub junctions: Mesh,
    /// The hard cases met, as [`road_surfaces_with_report`] counts them.
    pub report: RoadSurfaceReport,
}

/// The surfaces of [`road_surfaces_with_report`], the same triangles split into ribbon
/// groups and junction plates ([`RoadSurfaceParts`]).
///
/// # Errors
/// As [`road_surfaces`].
pub fn road_surface_parts(
    roads: &[MapRoad],
    elevation: &dyn Field,
    options: &RoadSurfaceOptions,
) -> Result<RoadSurfaceParts, ExportError> {
    check_options(options)?;
    check_roads(roads)?;
    let plan = junctions::plan(roads, options);
    let drape = Drape::new(roads, &plan, elevation, options)?;
    // The ribbon groups by (class rank, class, width), each sized before it is filled.
    let mut index: BTreeMap<(u8, &str, u64), usize> = BTreeMap::new();
    let mut groups: Vec<RibbonGroup> = Vec::new();
    let mut sizes: Vec<usize> = Vec::new();
    let mut last: Option<(usize, usize)> = None;
    let ribbons: Vec<(&junctions::PlanEdge, usize)> = plan
        .edges
        .iter()
        .filter(|e| !e.dropped && !e.internal)
        .map(|e| {
            // A road's segments are consecutive: its group is looked up once.
            let g = match last {
                Some((r, g)) if r == e.road => g,
                _ => {
                    let road = &roads[e.road];
                    let key = (
                        road.class.rank(),
                        road.class.as_str(),
                        road.width_m.to_bits(),
                    );
                    let g = *index.entry(key).or_insert_with(|| {
                        groups.push(RibbonGroup {
                            class: road.class.clone(),
                            width_m: road.width_m,
                            mesh: Mesh::new(None),
                        });
                        sizes.push(0);
                        groups.len() - 1
                    });
                    last = Some((e.road, g));
                    g
                }
            };
            sizes[g] += ribbon_pieces(e, options);
            (e, g)
        })
        .collect();
    for (group, &quads) in groups.iter_mut().zip(&sizes) {
        group.mesh.reserve(4 * quads, 2 * quads);
    }
    for (e, g) in ribbons {
        add_ribbon(&mut groups[g].mesh, roads, e, &drape, options)?;
    }
    let mut junctions = Mesh::with_capacity(None, ring_vertices(&plan), ring_triangles(&plan));
    let mut report = plan.report.clone();
    for j in &plan.junctions {
        let added = add_junction(&mut junctions, j, &drape)?;
        if !added {
            report.skipped_junctions += 1;
            report.junctions -= 1;
        }
    }
    let mut ribbons: Vec<RibbonGroup> = Vec::with_capacity(groups.len());
    let mut groups: Vec<Option<RibbonGroup>> = groups.into_iter().map(Some).collect();
    for &g in index.values() {
        if let Some(group) = groups[g].take().filter(|g| g.mesh.triangle_count() > 0) {
            ribbons.push(group);
        }
    }
    Ok(RoadSurfaceParts {
        ribbons,
        junctions,
        report,
    })
}

fn check_options(o: &RoadSurfaceOptions) -> Result<(), ExportError> {
    if !(o.max_segment_m.is_finite() && o.max_segment_m > 0.0) {
        return Err(ExportError::InvalidOption {
            name: "max_segment_m",
            reason: format!("{} must be finite and > 0", o.max_segment_m),
        });
    }
    if !(o.lift_m.is_finite() && o.class_lift_m.is_finite() && o.class_lift_m >= 0.0) {
        return Err(ExportError::InvalidOption {
            name: "lift_m",
            reason: "lift_m must be finite and class_lift_m finite and ≥ 0".to_string(),
        });
    }
    Ok(())
}

/// Heights of the plan's vertices.
struct Drape<'a> {
    elevation: &'a dyn Field,
    /// Lift of each node (its highest class).
    node_lift: Vec<f64>,
    /// Deck height of each node all of whose roads are bridges.
    deck: Vec<Option<f64>>,
}

impl<'a> Drape<'a> {
    fn new(
        roads: &[MapRoad],
        plan: &junctions::Plan,
        elevation: &'a dyn Field,
        o: &RoadSurfaceOptions,
    ) -> Result<Self, ExportError> {
        let lift = |r: usize| o.lift_m + o.class_lift_m * f64::from(roads[r].class.rank());
        // Per junction (a merged junction is one): the highest class, and a deck if every
        // road there is a bridge.
        let n = plan.nodes.len();
        let mut node_lift = vec![f64::NEG_INFINITY; n];
        let mut all_bridges = vec![true; n];
        let mut profiled = vec![true; n];
        let mut sum = vec![0.0; n];
        let mut count = vec![0usize; n];
        for (v, node) in plan.nodes.iter().enumerate() {
            let r = plan.rep.get(v).copied().unwrap_or(v);
            for &(e, starts) in &node.ends {
                let edge = &plan.edges[e];
                node_lift[r] = node_lift[r].max(lift(edge.road));
                let road = &roads[edge.road];
                if !road.bridge {
                    all_bridges[r] = false;
                } else if all_bridges[r] {
                    profiled[r] &= road.profile.is_some();
                    let s = edge.s_a + if starts { 0.0 } else { edge.len };
                    sum[r] += bridge_height(road, edge.road, s, elevation)?;
                    count[r] += 1;
                }
            }
        }
        for l in &mut node_lift {
            if !l.is_finite() {
                *l = o.lift_m;
            }
        }
        let deck: Vec<Option<f64>> = (0..n)
            .map(|v| {
                let r = plan.rep.get(v).copied().unwrap_or(v);
                (all_bridges[r] && count[r] > 0).then(|| sum[r] / count[r] as f64)
            })
            .collect();
        let node_lift: Vec<f64> = (0..n)
            .map(|v| node_lift[plan.rep.get(v).copied().unwrap_or(v)])
            .collect();
        // A deck node inside a chain of bridge segments (a bridge split into several
        // roads): straight between the chain's ends on land, by length along the chain.
        // Each chain is walked once, from its first unvisited node both ways.
        let mut chained = deck.clone();
        let mut done = vec![false; plan.nodes.len()];
        for (v, n) in plan.nodes.iter().enumerate() {
            let r = plan.rep.get(v).copied().unwrap_or(v);
            if done[v] || deck[v].is_none() || n.ends.len() != 2 || profiled[r] {
                continue; // (a deck node of profiled bridges has its profiles' height)
            }
            done[v] = true;
            let walks = [
                walk_chain(plan, &deck, v, n.ends[0].0),
                walk_chain(plan, &deck, v, n.ends[1].0),
            ];
            for (u, _) in walks.iter().flat_map(|w| &w.inner) {
                done[*u] = true;
            }
            let [Some(a), Some(b)] = [walks[0].end, walks[1].end] else {
                continue; // a closed loop of bridges: keep each road's own profile
            };
            let height = |u: usize| match deck[u] {
                Some(h) => Ok(h),
                None => sample(elevation, plan.nodes[u].pos),
            };
            let (h0, h1) = (height(a.0)?, height(b.0)?);
            let total = a.1 + b.1;
            if total > 0.0 {
                let at = |d: f64| h0 + (h1 - h0) * d / total;
                chained[v] = Some(at(a.1));
                for &(u, d) in &walks[0].inner {
                    chained[u] = Some(at(a.1 - d));
                }
                for &(u, d) in &walks[1].inner {
                    chained[u] = Some(at(a.1 + d));
                }
            }
        }
        let deck = chained;
        Ok(Drape {
            elevation,
            node_lift,
            deck,
        })
    }

    /// The terrain under `p`, checked.
    fn ground(&self, p: DVec2) -> Result<f64, ExportError> {
        sample(self.elevation, p)
    }

    /// The surface height at `p`, a vertex of node `v`'s junction or ribbon cuts.
    fn at_node(&self, v: usize, p: DVec2) -> Result<f64, ExportError> {
        let base = match self.deck[v] {
            Some(h) => h,
            None => self.ground(p)?,
        };
        Ok(base + self.node_lift[v])
    }
}

fn sample(elevation: &dyn Field, p: DVec2) -> Result<f64, ExportError> {
    let h = elevation.sample(p);
    if h.is_finite() {
        Ok(h)
    } else {
        Err(ExportError::map(
            format!("road surface at {p}"),
            format!("the elevation field is {h} there; it must be finite"),
        ))
    }
}

/// A walk along a chain of bridge segments.
struct Chain {
    /// The node where the chain stops (on land, at a branching or a dead end) and the
    /// length walked; `None` for a closed loop of bridges.
    end: Option<(usize, f64)>,
    /// The deck nodes passed on the way, with their distance from the start.
    inner: Vec<(usize, f64)>,
}

/// From node `v` along edge `e`, through deck nodes with two roads, to the first node
/// that is on land or where the chain branches or ends.
fn walk_chain(plan: &junctions::Plan, deck: &[Option<f64>], v: usize, e: usize) -> Chain {
    let (mut at, mut via, mut dist) = (v, e, 0.0);
    let mut inner = Vec::new();
    for _ in 0..=plan.nodes.len() {
        let edge = &plan.edges[via];
        let next = if edge.a == at { edge.b } else { edge.a };
        dist += edge.len;
        let n = &plan.nodes[next];
        if next == v {
            break;
        }
        if deck[next].is_none() || n.ends.len() != 2 || plan.merged.get(next) == Some(&true) {
            return Chain {
                end: Some((next, dist)),
                inner,
            };
        }
        inner.push((next, dist));
        via = if n.ends[0].0 == via {
            n.ends[1].0
        } else {
            n.ends[0].0
        };
        at = next;
    }
    Chain { end: None, inner }
}

/// The deck height of bridge `road` at `s` metres along its centre line: its profile's
/// ([`MapRoad::profile`]), or straight between the terrain at its two end points.
fn bridge_height(
    road: &MapRoad,
    index: usize,
    s: f64,
    elevation: &dyn Field,
) -> Result<f64, ExportError> {
    let (Some(&first), Some(&last)) = (road.points.first(), road.points.last()) else {
        return Err(ExportError::map(
            format!("road {index} (id {})", road.id),
            "a bridge needs at least two points",
        ));
    };
    if let Some(h) = road.profile_height(s) {
        return Ok(h);
    }
    let total: f64 = road.points.windows(2).map(|w| (w[1] - w[0]).length()).sum();
    let (h0, h1) = (sample(elevation, first)?, sample(elevation, last)?);
    let f = if total > 0.0 {
        (s / total).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Ok(h0 + (h1 - h0) * f)
}

/// The quads of an edge's ribbon: its length between the junction cuts in pieces of at
/// most `max_segment_m` (none when the cuts leave nothing).
fn ribbon_pieces(e: &junctions::PlanEdge, o: &RoadSurfaceOptions) -> usize {
    let inner = e.len - e.trim[0] - e.trim[1];
    if inner <= e.len * 1e-12 {
        0
    } else {
        (inner / o.max_segment_m).ceil().max(1.0) as usize
    }
}

fn add_ribbon(
    mesh: &mut Mesh,
    roads: &[MapRoad],
    e: &junctions::PlanEdge,
    drape: &Drape<'_>,
    o: &RoadSurfaceOptions,
) -> Result<(), ExportError> {
    let road = &roads[e.road];
    let inner = e.len - e.trim[0] - e.trim[1];
    let pieces = ribbon_pieces(e, o);
    if pieces == 0 {
        return Ok(());
    }
    let lift = o.lift_m + o.class_lift_m * f64::from(road.class.rank());
    let [ra, la] = e.cut_a;
    let [rb, lb] = e.cut_b;
    let ends = [
        [drape.at_node(e.a, ra)?, drape.at_node(e.a, la)?],
        [drape.at_node(e.b, rb)?, drape.at_node(e.b, lb)?],
    ];
    let station = |j: usize| -> Result<(DVec3, DVec3, f64), ExportError> {
        let t = j as f64 / pieces as f64;
        let (r, l) = (ra.lerp(rb, t), la.lerp(lb, t));
        let s = e.s_a + e.trim[0] + inner * t;
        let profiled = road.bridge.then(|| road.profile_height(s)).flatten();
        let (hr, hl) = if j == 0 {
            (ends[0][0], ends[0][1])
        } else if j == pieces {
            (ends[1][0], ends[1][1])
        } else if let Some(h) = profiled {
            (h + lift, h + lift)
        } else if road.bridge {
            (
                ends[0][0] + (ends[1][0] - ends[0][0]) * t,
                ends[0][1] + (ends[1][1] - ends[0][1]) * t,
            )
        } else {
            (drape.ground(r)? + lift, drape.ground(l)? + lift)
        };
        Ok((to_world(l, hl), to_world(r, hr), s))
    };
    let mut prev = station(0)?;
    for j in 1..=pieces {
        let next = station(j)?;
        let (l0, r0, s0) = prev;
        let (l1, r1, s1) = next;
        let uv = [
            DVec2::new(s0, 0.0),
            DVec2::new(s1, 0.0),
            DVec2::new(s1, -road.width_m),
            DVec2::new(s0, -road.width_m),
        ];
        // Counter-clockwise from above: right edge forwards, left edge backwards.
        // A quad collapsed to nothing by rounding is skipped (the mesh stays valid).
        let _ = mesh.add_quad([r0, r1, l1, l0], uv);
        prev = next;
    }
    Ok(())
}

/// Adds a junction polygon; `false` if it has no usable triangle after rounding to `f32`.
fn add_junction(
    mesh: &mut Mesh,
    j: &junctions::Junction,
    drape: &Drape<'_>,
) -> Result<bool, ExportError> {
    let mut world = Vec::with_capacity(j.ring.len());
    for &p in &j.ring {
        world.push(to_world(p, drape.at_node(j.node, p)?));
    }
    let rounded: Vec<DVec3> = world.iter().map(|w| w.as_vec3().as_dvec3()).collect();
    let mut normal = DVec3::ZERO;
    let mut keep = Vec::with_capacity(j.triangles.len());
    for t in &j.triangles {
        let [a, b, c] = t.map(|i| rounded[i as usize]);
        let n = (b - a).cross(c - a);
        if n != DVec3::ZERO {
            normal += n;
            keep.push(*t);
        }
    }
    let normal = normal.normalize_or_zero();
    if keep.is_empty() || !normal.is_finite() || normal.y <= 0.0 {
        return Ok(false);
    }
    let base = mesh.vertex_count() as u32;
    for (&p, &w) in j.ring.iter().zip(&world) {
        mesh.add_vertex(w, normal, DVec2::new(p.x, -p.y));
    }
    for [a, b, c] in keep {
        mesh.push_triangle(base + a, base + b, base + c)?;
    }
    Ok(true)
}

#[cfg(test)]
mod tests;
