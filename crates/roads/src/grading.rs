//! Roads graded into the land: a height profile for every road that keeps a maximum grade
//! per class and follows the smoothed ground, the terrain conformed to it with cut and
//! fill embankments, and the earthwork volumes.
//!
//! [`grade_roads`] works on the road network's *profile graph*: every junction, plus
//! points along each road at most [`GradeParams::sample_m`] apart. Each profile edge may
//! rise at most `max_grade(class) · length`.
//!
//! 1. **Target**: the ground under each point, smoothed along the roads (a few passes of
//!    averaging with the neighbours), so a road does not copy every bump.
//! 2. **Grade limit**: the largest profile below the target that keeps the limit,
//!    `U(n) = min_m target(m) + dist(n, m)`, and the smallest above it,
//!    `L(n) = max_m target(m) − dist(n, m)` (multi-source Dijkstra with edge weights
//!    `max_grade · length`), and the profile `(U + L) / 2`. Both envelopes keep the limit
//!    on every edge, so their mean does too; where the target already keeps it,
//!    `U = L = target` and the road follows the (smoothed) ground exactly. Points inside
//!    bridges are no sources: a bridge deck runs at the grade its land ends allow.
//! 3. **Conformed ground** ([`GradedGround`], a [`Field`]): the ground clamped into every
//!    nearby road's cone — the road's height inside its corridor (half its width from
//!    the centre line), and beyond it heights within
//!    [`GradeParams::embankment_slope`] (rise per metre) times the distance: where the
//!    road runs above the ground (fill) the ground rises to it, where below (cut) it falls
//!    to it, until the banks meet the natural ground. A bank that would be wider than
//!    [`GradeParams::max_embankment_m`] steepens into a retaining wall's face over the
//!    next [`RETAINING_WALL_M`] (the cone lets go of the ground continuously, so the
//!    conformed ground has no step a terrain mesh or a road surface could not follow).
//!    Where two roads' cones leave no common height, their meeting height. Bridges leave
//!    the ground alone (decks on piers).
//! 4. **Volumes**: per profile edge the cross-section `2·w/2·Δ + Δ²/s` (corridor plus two
//!    embankment wedges, `Δ` the road's height above the ground on the centre line, `s` the
//!    embankment slope) integrated along the road (trapezoids); positive parts are fill,
//!    negative cut.
//!
//! # Guarantees
//! * Every profile edge keeps its class's grade limit (up to rounding), whatever the
//!   ground; a limit of 0 gives each connected network one level (the midpoint of its
//!   lowest and highest smoothed ground): documented degradation, no error.
//! * Roads on ground that already keeps the limit are not moved, and produce no volume.
//! * Deterministic: a pure function of the network, the ground and the parameters.
//!
//! # Limitations
//! * Where corridors of roads at different heights overlap (junction corners) the ground
//!   takes the cones' meeting height, a little off both roads; the volumes count each
//!   road's cross-section on its own, so overlaps at junctions are counted twice. A bank
//!   wider than [`GradeParams::max_embankment_m`] ends in a steep wall face (up to
//!   [`RETAINING_WALL_M`] wide) whose volume the cross-sections do not count.
//! * The ground is sampled at the profile points; bumps shorter than `sample_m` between
//!   them are neither smoothed nor cut.
//!
//! # References
//! Kelly 2008, §4.2 (roads plotted over the terrain, with a maximum gradient) and §4.4.1
//! (the road surface and footpaths on the terrain); Parish & Müller 2001, §3.3 (elevation
//! as a constraint on roads).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use polis_geom::field::Field;
use polis_geom::spatial::{GridOptions, Shape, SpatialIndex};
use polis_geom::{Aabb2, DVec2, SegmentIndex};
use serde::{Deserialize, Serialize};

use crate::error::{Result, RoadsError};
use crate::network::{RoadClass, RoadNetwork};

/// Parameters of [`grade_roads`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GradeParams {
    /// Steepest grade of a highway (rise per metre, finite, ≥ 0). Default: 0.06.
    pub max_grade_highway: f64,
    /// Steepest grade of a street (rise per metre, finite, ≥ 0). Default: 0.15.
    pub max_grade_street: f64,
    /// Longest piece of road between two profile points, metres (finite, ≥ 1).
    /// Default: 10.
    pub sample_m: f64,
    /// Passes of neighbour averaging of the ground along the roads (≤ 100). Default: 2.
    pub smoothing_passes: u32,
    /// Embankment slope, rise per metre of run (finite, > 0): 0.5 is a 1:2 bank.
    /// Default: 0.5.
    pub embankment_slope: f64,
    /// Widest embankment on either side of a corridor, metres (finite, ≥ 0): beyond it
    /// the bank steepens into a retaining wall's face over [`RETAINING_WALL_M`] and the
    /// ground beyond is left alone. Default: 30.
    pub max_embankment_m: f64,
}

impl Default for GradeParams {
    fn default() -> Self {
        GradeParams {
            max_grade_highway: 0.06,
            max_grade_street: 0.15,
            sample_m: 10.0,
            smoothing_passes: 2,
            embankment_slope: 0.5,
            max_embankment_m: 30.0,
        }
    }
}

impl GradeParams {
    /// Checks every field's range.
    pub fn validate(&self) -> Result<()> {
        let bad =
            |name: &'static str, reason: String| RoadsError::InvalidParameter { name, reason };
        for (name, v) in [
            ("max_grade_highway", self.max_grade_highway),
            ("max_grade_street", self.max_grade_street),
            ("max_embankment_m", self.max_embankment_m),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, format!("{v} must be a finite number ≥ 0")));
            }
        }
        if !(self.sample_m.is_finite() && self.sample_m >= 1.0) {
            return Err(bad(
                "sample_m",
                format!("{} must be a finite number ≥ 1 m", self.sample_m),
            ));
        }
        if !(self.embankment_slope.is_finite() && self.embankment_slope > 0.0) {
            return Err(bad(
                "embankment_slope",
                format!("{} must be a finite number > 0", self.embankment_slope),
            ));
        }
        if self.smoothing_passes > 100 {
            return Err(bad(
                "smoothing_passes",
                format!("{} must be at most 100", self.smoothing_passes),
            ));
        }
        Ok(())
    }

    /// The grade limit of a road class.
    pub fn max_grade(&self, class: RoadClass) -> f64 {
        match class {
            RoadClass::Highway => self.max_grade_highway,
            RoadClass::Street => self.max_grade_street,
        }
    }
}

/// Earthwork volumes of a grading, cubic metres.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Earthworks {
    /// Ground removed where roads run below it, m³.
    pub cut_m3: f64,
    /// Ground added where roads run above it, m³.
    pub fill_m3: f64,
    /// Road length whose profile leaves the ground by more than 5 cm, metres.
    pub moved_length_m: f64,
    /// Steepest profile edge after grading (rise per metre).
    pub steepest_grade: f64,
}

/// One piece of graded road between two profile points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GradedPiece {
    /// Start and end on the layout, metres.
    pub a: DVec2,
    /// End.
    pub b: DVec2,
    /// Road height at `a` and `b`, metres.
    pub ha: f64,
    /// Height at `b`.
    pub hb: f64,
    /// Half the road's width, metres.
    pub half_width: f64,
    /// A bridge or tunnel piece (leaves the ground alone).
    pub bridge: bool,
    /// The road's class.
    pub class: RoadClass,
}

impl GradedPiece {
    /// The road height at parameter `t ∈ [0, 1]`.
    pub fn height_at(&self, t: f64) -> f64 {
        self.ha + (self.hb - self.ha) * t
    }

    /// The parameter `t ∈ [0, 1]` of the centre-line point nearest `p`, and the distance
    /// to it, metres.
    pub fn project(&self, p: DVec2) -> (f64, f64) {
        let ab = self.b - self.a;
        let l2 = ab.length_squared();
        let t = if l2 > 0.0 {
            ((p - self.a).dot(ab) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (t, p.distance(self.a + ab * t))
    }
}

/// The graded roads and the ground conformed to them (see the [module docs](self)).
pub struct GradedGround<'a> {
    ground: &'a dyn Field,
    pieces: Vec<GradedPiece>,
    /// Pieces that change the ground, by index into `pieces`.
    index: SegmentIndex<u32>,
    /// Every piece off bridges (the corridors a terrain is cut in under).
    corridors: SegmentIndex<u32>,
    /// Farthest reach of any corridor plus embankment from its centre line, metres.
    reach: f64,
    slope: f64,
    max_bank: f64,
    /// Widest half width of a corridor, metres.
    corridor_reach: f64,
    /// The volumes.
    pub earthworks: Earthworks,
}

impl std::fmt::Debug for GradedGround<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GradedGround")
            .field("pieces", &self.pieces.len())
            .field("earthworks", &self.earthworks)
            .finish()
    }
}

/// A node of the heap: cost first, then node index (determinism).
#[derive(PartialEq)]
struct Item(f64, u32);
impl Eq for Item {}
impl PartialOrd for Item {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Item {
    fn cmp(&self, other: &Self) -> Ordering {
        // Min-heap on cost, then index.
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

/// The profile graph: points, their ground, and weighted adjacency.
struct Profile {
    points: Vec<DVec2>,
    ground: Vec<f64>,
    /// Whether a point may be a source (not inside a bridge).
    source: Vec<bool>,
    /// `(from, to, weight = max grade · length, piece template)`.
    edges: Vec<(u32, u32, f64, usize)>,
    adjacency: Vec<Vec<(u32, f64)>>,
    /// Per network edge: class, half width, bridge.
    roads: Vec<(RoadClass, f64, bool)>,
}

fn profile(network: &RoadNetwork, ground: &dyn Field, params: &GradeParams) -> Result<Profile> {
    let mut points = Vec::with_capacity(network.node_count());
    let mut ids = vec![u32::MAX; network.node_bound()];
    let mut source = Vec::new();
    for (n, p, _) in network.nodes() {
        if let Some(slot) = ids.get_mut(n.index()) {
            *slot = points.len() as u32;
        }
        points.push(p);
        // A junction is a source unless every road at it is a bridge (or a tunnel).
        let all_bridges = network
            .edges_at(n)?
            .iter()
            .all(|&e| network.edge_payload(e).is_ok_and(|r| r.bridge || r.tunnel));
        source.push(!all_bridges || network.degree(n)? == 0);
    }
    let mut edges = Vec::new();
    let mut roads = Vec::new();
    for (e, a, b, road) in network.edges() {
        let (pa, pb) = network.segment(e)?;
        let (ia, ib) = (
            ids.get(a.index()).copied().unwrap_or(u32::MAX),
            ids.get(b.index()).copied().unwrap_or(u32::MAX),
        );
        if ia == u32::MAX || ib == u32::MAX {
            continue;
        }
        let len = pa.distance(pb);
        let pieces = ((len / params.sample_m).ceil() as usize).clamp(1, 1 << 20);
        let grade = params.max_grade(road.class);
        let r = roads.len();
        // A tunnel leaves the ground above it alone, as a bridge the ground below.
        let off_ground = road.bridge || road.tunnel;
        roads.push((road.class, 0.5 * road.width.max(0.0), off_ground));
        let mut prev = ia;
        for k in 1..=pieces {
            let next = if k == pieces {
                ib
            } else {
                let p = pa.lerp(pb, k as f64 / pieces as f64);
                points.push(p);
                source.push(!off_ground);
                (points.len() - 1) as u32
            };
            edges.push((prev, next, grade * len / pieces as f64, r));
            prev = next;
        }
    }
    let mut g = Vec::with_capacity(points.len());
    for &p in &points {
        let v = ground.sample(p);
        if !v.is_finite() {
            return Err(RoadsError::InvalidParameter {
                name: "ground",
                reason: format!("the elevation is {v} at {p}; it must be finite"),
            });
        }
        g.push(v);
    }
    let mut adjacency = vec![Vec::new(); points.len()];
    for &(a, b, w, _) in &edges {
        adjacency[a as usize].push((b, w));
        adjacency[b as usize].push((a, w));
    }
    Ok(Profile {
        points,
        ground: g,
        source,
        edges,
        adjacency,
        roads,
    })
}

/// Width of the band beyond the widest bank over which a cone lets go of the ground
/// (the face of a retaining wall), metres.
pub const RETAINING_WALL_M: f64 = 10.0;

/// How far a road's cone lets the ground rise or fall at `beyond` metres past its
/// corridor: `slope · beyond` on the bank (up to `max_bank`), then, over the next
/// [`RETAINING_WALL_M`], growing without bound (`slope · beyond + slope · W · x / (1 − x)`
/// with `x` the share of the wall band `W` crossed), so the cone lets go of the ground
/// continuously instead of in a step; `None` past the band (the cone binds nowhere).
fn cone_rise(beyond: f64, slope: f64, max_bank: f64) -> Option<f64> {
    if beyond <= max_bank {
        return Some(slope * beyond);
    }
    let x = (beyond - max_bank) / RETAINING_WALL_M;
    if x < 1.0 {
        Some(slope * beyond + slope * RETAINING_WALL_M * x / (1.0 - x))
    } else {
        None
    }
}

/// Grid cell of the index of pieces that move the ground (queried `half width +
/// max_embankment_m` around every ground sample), metres.
const CONE_CELL_M: f64 = 16.0;
/// Grid cell of the index of corridors (queried a few metres around a sample), metres.
const CORRIDOR_CELL_M: f64 = 8.0;

/// Multi-source Dijkstra: `min over sources m of (value(m) + sign·dist)`, with `sign = 1`
/// for the upper envelope; for the lower one the values are negated.
fn envelope(p: &Profile, values: &[f64]) -> Vec<f64> {
    let mut best = vec![f64::INFINITY; p.points.len()];
    let mut heap = BinaryHeap::new();
    for (i, (&v, &s)) in values.iter().zip(&p.source).enumerate() {
        if s {
            best[i] = v;
            heap.push(Item(v, i as u32));
        }
    }
    while let Some(Item(c, n)) = heap.pop() {
        if c > best[n as usize] {
            continue;
        }
        for &(m, w) in &p.adjacency[n as usize] {
            let nc = c + w;
            if nc < best[m as usize] {
                best[m as usize] = nc;
                heap.push(Item(nc, m));
            }
        }
    }
    best
}

/// Grades the roads of `network` on `ground` (see the [module docs](self)).
///
/// Fails on invalid parameters or a ground that is not finite under a road.
pub fn grade_roads<'a>(
    network: &RoadNetwork,
    ground: &'a dyn Field,
    params: &GradeParams,
) -> Result<GradedGround<'a>> {
    params.validate()?;
    let p = profile(network, ground, params)?;
    // 1. The smoothed target (bridge interiors take no part).
    let mut target = p.ground.clone();
    for _ in 0..params.smoothing_passes {
        let prev = target.clone();
        for (i, t) in target.iter_mut().enumerate() {
            if !p.source[i] {
                continue;
            }
            let (mut sum, mut n) = (prev[i], 1.0);
            for &(m, _) in &p.adjacency[i] {
                if p.source[m as usize] {
                    sum += prev[m as usize];
                    n += 1.0;
                }
            }
            *t = sum / n;
        }
    }
    // 2. The envelopes and their mean.
    let upper = envelope(&p, &target);
    let neg: Vec<f64> = target.iter().map(|t| -t).collect();
    let lower: Vec<f64> = envelope(&p, &neg).into_iter().map(|v| -v).collect();
    let heights: Vec<f64> = upper
        .iter()
        .zip(&lower)
        .zip(&p.ground)
        .map(|((&u, &l), &g)| {
            if u.is_finite() && l.is_finite() {
                0.5 * (u + l)
            } else {
                g // a component without sources (all bridge): left on the ground
            }
        })
        .collect();
    // 3. Pieces, the index of those that move the ground, and 4. the volumes.
    let mut pieces = Vec::with_capacity(p.edges.len());
    // Cells near the pieces' length (at most `sample_m`, 10 m by default) and a fraction
    // of the cones' reach: every ground sample visits only the pieces near it.
    let mut index = SegmentIndex::new(GridOptions {
        cell_size: CONE_CELL_M,
    })?;
    let mut corridors = SegmentIndex::new(GridOptions {
        cell_size: CORRIDOR_CELL_M,
    })?;
    let mut works = Earthworks::default();
    let mut reach = 0.0f64;
    let s = params.embankment_slope;
    for &(a, b, _, r) in &p.edges {
        let (class, half_width, bridge) = p.roads[r];
        let (ia, ib) = (a as usize, b as usize);
        let piece = GradedPiece {
            a: p.points[ia],
            b: p.points[ib],
            ha: heights[ia],
            hb: heights[ib],
            half_width,
            bridge,
            class,
        };
        let len = piece.a.distance(piece.b);
        if len > 0.0 {
            works.steepest_grade = works.steepest_grade.max((piece.hb - piece.ha).abs() / len);
        }
        let (da, db) = (heights[ia] - p.ground[ia], heights[ib] - p.ground[ib]);
        if !bridge && len > 0.0 {
            corridors.insert(pieces.len() as u32, Shape::Segment(piece.a, piece.b))?;
        }
        if !bridge {
            let section = |d: f64| {
                let bank = (d.abs() / s).min(params.max_embankment_m);
                // Corridor plus two wedges (cut off at the widest bank).
                2.0 * half_width * d.abs() + bank * (2.0 * d.abs() - bank * s)
            };
            for (d, w) in [(da, 0.5 * len), (db, 0.5 * len)] {
                let v = section(d) * w;
                if d > 0.0 {
                    works.fill_m3 += v;
                } else {
                    works.cut_m3 += v;
                }
            }
            if da.abs().max(db.abs()) > 0.05 {
                works.moved_length_m += len;
            }
            if da.abs().max(db.abs()) > 1e-9 && len > 0.0 {
                // A cone binds wherever the ground leaves it, up to the widest bank.
                reach = reach.max(half_width + params.max_embankment_m + RETAINING_WALL_M);
                index.insert(pieces.len() as u32, Shape::Segment(piece.a, piece.b))?;
            }
        }
        pieces.push(piece);
    }
    Ok(GradedGround {
        ground,
        pieces,
        index,
        corridors,
        reach,
        slope: s,
        max_bank: params.max_embankment_m,
        corridor_reach: p.roads.iter().map(|r| r.1).fold(0.0, f64::max),
        earthworks: works,
    })
}

impl GradedGround<'_> {
    /// The graded pieces of road (every profile edge), in network edge order.
    pub fn pieces(&self) -> &[GradedPiece] {
        &self.pieces
    }

    /// Whether grading moved any road off the ground (otherwise the field is the
    /// ground's).
    pub fn moves_ground(&self) -> bool {
        !self.index.is_empty()
    }

    /// This ground cut in under the road corridors, for a terrain mesh: `depth` metres
    /// lower within `margin` metres beyond each corridor (off bridges), tapering back to
    /// the ground over the next `taper` metres. A mesh that interpolates this field
    /// stays below the road surfaces where the graded ground bends sharply (the foot of
    /// a cut's banks) although its vertices do not lie on the corridors' edges.
    pub fn cut_in(&self, depth: f64, margin: f64, taper: f64) -> CutIn<'_> {
        CutIn {
            graded: self,
            depth: depth.max(0.0),
            margin: margin.max(0.0),
            taper: taper.max(0.0),
        }
    }
}

/// A [`GradedGround`] cut in under its road corridors: see [`GradedGround::cut_in`].
#[derive(Clone, Copy)]
pub struct CutIn<'a> {
    graded: &'a GradedGround<'a>,
    depth: f64,
    margin: f64,
    taper: f64,
}

impl<'a> CutIn<'a> {
    /// The share of the cut depth piece `k` asks for at `p` (1 within the corridor and
    /// its margin, tapering to 0 over the taper beyond).
    fn share(&self, k: u32, p: DVec2) -> f64 {
        self.share_beyond(k, p, self.margin)
    }

    /// 1 within `flat` metres beyond the corridor of piece `k`, tapering to 0 over the
    /// next `taper` metres.
    fn share_beyond(&self, k: u32, p: DVec2, flat: f64) -> f64 {
        let Some(piece) = self.graded.pieces.get(k as usize) else {
            return 0.0;
        };
        let (_, d) = piece.project(p);
        let beyond = d - piece.half_width - flat;
        if beyond <= 0.0 {
            1.0
        } else if self.taper > 0.0 {
            (1.0 - beyond / self.taper).max(0.0)
        } else {
            0.0
        }
    }

    /// The largest share of the cut depth any corridor asks for at `p`, flat `flat`
    /// metres beyond the corridors.
    fn sink(&self, p: DVec2, flat: f64) -> f64 {
        let mut sink = 0.0f64;
        let b = Aabb2::new(p, p).expanded(self.graded.corridor_reach + flat + self.taper);
        self.graded.corridors.for_each_candidate(&b, |k, _| {
            sink = sink.max(self.share_beyond(k, p, flat));
        });
        sink
    }

    /// The corridors near the box of `points` whose share, flat `flat` metres beyond the
    /// corridor, may be above 0 somewhere in it (`None` for no finite point).
    fn near(&self, points: &[DVec2], flat: f64) -> Option<Vec<u32>> {
        let b = Aabb2::of_finite_points(points)?;
        let mut near = Vec::new();
        // Corridors that cut nowhere in the box (at least `flat` and the taper beyond it
        // at its centre's distance less its half diagonal) share 0 at every point: left
        // out.
        let (centre, half_diagonal) = (b.center(), 0.5 * b.size().length());
        let reach = self.graded.corridor_reach + flat + self.taper;
        self.graded
            .corridors
            .for_each_candidate(&b.expanded(reach), |k, _| {
                if let Some(piece) = self.graded.pieces.get(k as usize) {
                    let beyond = piece.project(centre).1 - half_diagonal - piece.half_width;
                    if beyond < flat + self.taper + BOX_SLACK_M {
                        near.push(k);
                    }
                }
            });
        Some(near)
    }

    /// How far a terrain of this field may lie below it (for
    /// [`Terrain::build_with_slack`](polis_geom::mesh::Terrain::build_with_slack)): the
    /// cut's depth over the whole cut (its flat part and its taper), tapering to 0 over
    /// one more taper. The terrain then keeps the cut as an upper bound there, with its
    /// vertices half the slack under the cut: it refines where its fans would rise over
    /// the cut or sag under the slack's floor, not at every bend of the graded ground
    /// (the foot or the top of a bank at a corridor's edge, a crest along a road). The
    /// slack is continuous (it tapers), so the terrain's vertices do not step with it.
    pub fn slack(&self) -> CutSlack<'a> {
        CutSlack { cut: *self }
    }
}

/// How far a terrain may lie under a [`CutIn`]: see [`CutIn::slack`].
pub struct CutSlack<'a> {
    cut: CutIn<'a>,
}

impl CutSlack<'_> {
    /// The flat part of the slack beyond a corridor: the cut's flat part and its taper.
    fn flat(&self) -> f64 {
        self.cut.margin + self.cut.taper
    }
}

impl Field for CutSlack<'_> {
    fn sample(&self, p: DVec2) -> f64 {
        self.cut.depth * self.cut.sink(p, self.flat())
    }

    /// One look-up of the corridors around all the points, then the values of
    /// [`sample`](Field::sample) (combined by `max`, as the cut's shares).
    fn sample_many(&self, points: &[DVec2], out: &mut [f64]) {
        let flat = self.flat();
        let Some(near) = self.cut.near(points, flat) else {
            for (p, o) in points.iter().zip(out.iter_mut()) {
                *o = self.sample(*p);
            }
            return;
        };
        for (&p, o) in points.iter().zip(out.iter_mut()) {
            let sink = near.iter().fold(0.0f64, |sink, &k| {
                sink.max(self.cut.share_beyond(k, p, flat))
            });
            *o = self.cut.depth * sink;
        }
    }
}

impl Field for CutIn<'_> {
    fn sample(&self, p: DVec2) -> f64 {
        let g = self.graded.sample(p);
        g - self.depth * self.sink(p, self.margin)
    }

    /// One look-up of the corridors around all the points, then the values of
    /// [`sample`](Field::sample) (the shares are combined by `max`, so the order and a
    /// superset of the corridors near each point change nothing).
    fn sample_many(&self, points: &[DVec2], out: &mut [f64]) {
        self.graded.sample_many(points, out);
        let Some(near) = self.near(points, self.margin) else {
            for (p, o) in points.iter().zip(out.iter_mut()) {
                *o = self.sample(*p);
            }
            return;
        };
        for (&p, o) in points.iter().zip(out.iter_mut()) {
            let sink = near
                .iter()
                .fold(0.0f64, |sink, &k| sink.max(self.share(k, p)));
            *o -= self.depth * sink;
        }
    }
}

/// Slack beyond rounding when a whole box of points is found out of a piece's reach by
/// its centre's distance, metres: a piece left out would give nothing at any point of
/// the box even with distances off by far more than rounding.
const BOX_SLACK_M: f64 = 1e-6;

impl GradedGround<'_> {
    /// Narrows `(lo, hi)` to the cone of piece `k` at `p`.
    fn narrow(&self, k: u32, p: DVec2, lo: &mut f64, hi: &mut f64) {
        let Some(piece) = self.pieces.get(k as usize) else {
            return;
        };
        let (t, d) = piece.project(p);
        let beyond = (d - piece.half_width).max(0.0);
        if let Some(rise) = cone_rise(beyond, self.slope, self.max_bank) {
            let r = piece.height_at(t);
            *lo = lo.max(r - rise);
            *hi = hi.min(r + rise);
        }
    }
}

/// Whether cones that each hold the ground `g` and whose bounds lie within
/// `[wide_lo, wide_hi]` (a lower bound at most `wide_lo`, an upper at least `wide_hi`)
/// leave [`clamp_into`]`(g, lo, hi)` as it is. With them the range is
/// `[max(lo, l), min(hi, h)]`, `l ≤ min(g, wide_lo)`, `h ≥ max(g, wide_hi)`:
/// * `lo ≤ g ≤ hi`: still holds `g`, the value `g`;
/// * `g < lo ≤ hi`: the value stays `lo` while `h ≥ lo`, sure when `wide_hi ≥ lo`;
/// * `lo ≤ hi < g`: likewise `hi` while `wide_lo ≤ hi`;
/// * `lo > hi` (the meeting height): `l ≤ lo` and `h ≥ hi` keep both bounds.
fn wide_cones_agree(g: f64, lo: f64, hi: f64, wide_lo: f64, wide_hi: f64) -> bool {
    if lo <= hi {
        if g < lo {
            wide_hi >= lo
        } else if g > hi {
            wide_lo <= hi
        } else {
            true
        }
    } else {
        wide_lo <= lo && wide_hi >= hi
    }
}

/// The ground `g` clamped into the cones' common range `[lo, hi]`, or their meeting
/// height where they leave none.
fn clamp_into(g: f64, lo: f64, hi: f64) -> f64 {
    if lo <= hi {
        g.clamp(lo, hi)
    } else {
        0.5 * (lo + hi)
    }
}

impl Field for GradedGround<'_> {
    /// The ground clamped into every nearby road's *cone*: a road piece at height `r`
    /// allows heights within `r ± slope · b` at `b` metres beyond its corridor (so `r`
    /// itself inside it), up to [`GradeParams::max_embankment_m`] beyond, then ever wider
    /// over the [`RETAINING_WALL_M`] after it. Where two cones leave no common height
    /// (roads at different heights side by side), their meeting height is taken.
    /// Continuous wherever the ground is.
    fn sample(&self, p: DVec2) -> f64 {
        let g = self.ground.sample(p);
        if self.index.is_empty() || !g.is_finite() {
            return g;
        }
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        let b = Aabb2::new(p, p).expanded(self.reach);
        self.index.for_each_candidate(&b, |k, _| {
            self.narrow(k, p, &mut lo, &mut hi);
        });
        clamp_into(g, lo, hi)
    }

    /// One look-up of the pieces around all the points, then the values of
    /// [`sample`](Field::sample): the cones are combined by `max` and `min`, so the order
    /// and a superset of the pieces near each point change nothing (a piece beyond a
    /// point's reach binds nowhere there).
    fn sample_many(&self, points: &[DVec2], out: &mut [f64]) {
        self.ground.sample_many(points, out);
        if self.index.is_empty() {
            return;
        }
        let Some(b) = Aabb2::of_finite_points(points) else {
            for (p, o) in points.iter().zip(out.iter_mut()) {
                *o = self.sample(*p);
            }
            return;
        };
        // The natural ground's range over the batch.
        let (mut g_lo, mut g_hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &g in out.iter().filter(|g| g.is_finite()) {
            g_lo = g_lo.min(g);
            g_hi = g_hi.max(g);
        }
        let mut near = Vec::new();
        let mut wide = Vec::new();
        // Pieces whose cone binds nowhere in the box (past the bank and the wall face at
        // its centre's distance less its half diagonal) are left out. Pieces whose cone
        // holds the batch's whole ground range at every point of the box (`wide`: their
        // narrowest rise there, at the box's nearest distance, reaches from every height
        // of the piece past that range) are read only at points where the others'
        // range might not stand with them (`wide_cones_agree`).
        let (centre, half_diagonal) = (b.center(), 0.5 * b.size().length());
        let wall_end = self.max_bank + RETAINING_WALL_M + BOX_SLACK_M;
        let (mut wide_lo, mut wide_hi) = (f64::NEG_INFINITY, f64::INFINITY);
        self.index
            .for_each_candidate(&b.expanded(self.reach), |k, _| {
                if let Some(piece) = self.pieces.get(k as usize) {
                    let beyond = piece.project(centre).1 - half_diagonal - piece.half_width;
                    if beyond < wall_end {
                        // The cone's narrowest at the box, less rounding.
                        let rise = cone_rise(beyond.max(0.0), self.slope, self.max_bank)
                            .map(|r| r * (1.0 - 1e-9) - BOX_SLACK_M);
                        let (r_lo, r_hi) = (piece.ha.min(piece.hb), piece.ha.max(piece.hb));
                        match rise {
                            Some(rise) if r_hi - rise <= g_lo && r_lo + rise >= g_hi => {
                                wide_lo = wide_lo.max(r_hi - rise);
                                wide_hi = wide_hi.min(r_lo + rise);
                                wide.push(k);
                            }
                            _ => near.push(k),
                        }
                    }
                }
            });
        for (&p, o) in points.iter().zip(out.iter_mut()) {
            if !o.is_finite() {
                continue;
            }
            let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
            for &k in &near {
                self.narrow(k, p, &mut lo, &mut hi);
            }
            if !wide_cones_agree(*o, lo, hi, wide_lo, wide_hi) {
                for &k in &wide {
                    self.narrow(k, p, &mut lo, &mut hi);
                }
            }
            *o = clamp_into(*o, lo, hi);
        }
    }
}

#[cfg(test)]
mod tests;
