//! The output types and the shape interpreter that turns a derived string into them.

use polis_geom::mesh::to_world;
use polis_geom::polygon::{locate_in_ring, ring_signed_area};
use polis_geom::{
    Aabb2, DVec2, DVec3, Mesh, PointLocation, Polygon, SegmentIntersection, segment_intersection,
};
use polis_lsystem::ParamString;

use crate::BuildingsError;
use crate::grammar::{BuildingGrammar, Op};
use crate::params::BuildingKind;
use crate::roofs::{self, RoofFaces};
use crate::solid::prism;
use crate::template::Template;

/// What a part of a building is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum PartRole {
    /// A mass (`Box`, or a non-terminal drawn as its volume).
    Mass,
    /// A roof template.
    Roof,
    /// A detail: antenna, spire.
    Detail,
    /// A user template.
    Template,
}

/// One closed solid of a building.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The mesh, in metres relative to [`Building::origin`] (glTF axes, Y up).
    pub mesh: Mesh,
    /// What it is.
    pub role: PartRole,
}

/// The role of a facade face, for the facades stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum FacadeRole {
    /// An upper-storey wall.
    Wall,
    /// The ground-floor storey of a wall (shop fronts, entrances).
    GroundFloor,
    /// A roof plane (its bounding rectangle).
    Roof,
}

/// A facade face: a planar rectangle of a building's surface that the facades stage
/// textures or fills with window geometry.
///
/// Stored as its bottom-left corner and two unit axes (104 bytes): [`corners`](Self::corners),
/// [`normal`](Self::normal) and [`at`](Self::at) give the geometry. A city keeps eight
/// faces per building, so the derived values are not stored.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FacadeFace {
    /// The bottom-left corner seen from outside, metres relative to [`Building::origin`]
    /// (glTF axes).
    pub origin: DVec3,
    /// Unit vector along the bottom edge, from bottom-left to bottom-right (horizontal).
    pub u: DVec3,
    /// Unit vector up the face, from bottom-left to top-left, perpendicular to `u`:
    /// straight up for walls, up the slope for roof planes.
    pub v: DVec3,
    /// Width along `u`, metres.
    pub width: f64,
    /// Height along `v`, metres. For roof planes, the face is the bounding rectangle of
    /// the plane's polygon.
    pub height: f64,
    /// Storeys in the face (0 for roofs).
    pub floors: u32,
    /// Index of the part in [`Building::parts`] it belongs to.
    pub part: u32,
    /// What it is.
    pub role: FacadeRole,
}

impl FacadeFace {
    /// The point `s` metres along and `t` metres up the face from its bottom-left corner.
    #[inline]
    pub fn at(&self, s: f64, t: f64) -> DVec3 {
        self.origin + self.u * s + self.v * t
    }

    /// Corners, counter-clockwise seen from outside: bottom-left, bottom-right, top-right,
    /// top-left.
    pub fn corners(&self) -> [DVec3; 4] {
        let (w, h) = (self.width, self.height);
        [
            self.at(0.0, 0.0),
            self.at(w, 0.0),
            self.at(w, h),
            self.at(0.0, h),
        ]
    }

    /// The outward unit normal, `u × v`.
    #[inline]
    pub fn normal(&self) -> DVec3 {
        self.u.cross(self.v)
    }

    /// The part index as a `usize`.
    #[inline]
    pub fn part_index(&self) -> usize {
        self.part as usize
    }
}

/// A building: closed solids and facade faces.
#[derive(Debug, Clone, PartialEq)]
pub struct Building {
    /// The building's id (its lot's id: one building per lot).
    pub id: u64,
    /// The lot it stands on.
    pub lot_id: u64,
    /// Its type.
    pub kind: BuildingKind,
    /// Total height above the ground, metres (the bounding volume's; parts never rise
    /// above it).
    pub height: f64,
    /// Storeys.
    pub floors: u32,
    /// Level of detail: derivation steps drawn.
    pub lod: usize,
    /// Layout position of the local origin (the footprint's centroid); every mesh and
    /// facade coordinate is relative to `to_world(origin, 0)`.
    pub origin: DVec2,
    /// The footprint in layout coordinates (absolute), counter-clockwise, starting with
    /// the primary street edge.
    pub footprint: Polygon,
    /// Closed solids.
    pub parts: Vec<Part>,
    /// Facade faces.
    pub facades: Vec<FacadeFace>,
    /// Templates that could not be built and fell back to a simpler one (a gable on a
    /// square, a pyramid on a non-star-shaped footprint …).
    pub fallbacks: u32,
}

impl Building {
    /// Triangles in all parts.
    pub fn triangle_count(&self) -> usize {
        self.parts.iter().map(|p| p.mesh.triangle_count()).sum()
    }

    /// The bounding box of all parts (local coordinates).
    pub fn bbox(&self) -> polis_geom::Aabb3 {
        self.parts
            .iter()
            .fold(polis_geom::Aabb3::default(), |b, p| b.union(&p.mesh.bbox()))
    }
}

/// Everything the interpreter needs about one building.
pub(crate) struct Context<'a> {
    pub grammar: &'a BuildingGrammar,
    pub templates: &'a [Template],
    /// The lot, layout coordinates.
    pub lot_world: &'a Polygon,
    /// The local origin in the layout.
    pub origin: DVec2,
    /// The lot in local coordinates with its edge index, made when first needed.
    pub lot_local: std::cell::OnceCell<LotShape>,
    /// Unit axis along the primary street edge.
    pub frame_x: DVec2,
    /// Height limit, metres.
    pub top: f64,
    pub floor_height: f64,
    pub ground_floor_height: f64,
    pub slope_default: f64,
}

impl Context<'_> {
    /// The lot in local coordinates.
    fn lot(&self) -> &LotShape {
        self.lot_local
            .get_or_init(|| LotShape::new(self.lot_world.translated(-self.origin)))
    }
}

/// A shape's footprint: a range of the ring arena (rings are never changed in place, so
/// saved shapes on the branch stack may share them).
#[derive(Clone, Copy)]
struct Shape {
    ring: Option<(usize, usize)>,
    /// The ring is known to lie inside the lot (the footprint, its setbacks, convex
    /// shrinks of those): no containment test needed.
    inside: bool,
    base: f64,
    height: f64,
}

/// Pitch of a mansard's upper roof when `Mansard(d)` gives none, degrees.
pub const MANSARD_UPPER_PITCH_DEG: f64 = 15.0;

/// Smallest part height drawn, metres.
const MIN_PART_HEIGHT: f64 = 0.05;

/// Reusable buffers of the shape interpreter (one set per thread): interpreting a
/// string allocates only what the returned building keeps.
#[derive(Default)]
pub(crate) struct Scratch {
    /// Every ring of the current string, appended as shapes change.
    rings: Vec<DVec2>,
    /// The branch stack.
    stack: Vec<Shape>,
    /// Parts and facade faces before they are copied into exactly sized vectors.
    parts: Vec<Part>,
    facades: Vec<FacadeFace>,
    /// A ring buffer lent to `Polygon` for its centroid and validation.
    poly: Vec<DVec2>,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Runs `f` with this thread's interpreter buffers (fresh ones if they are in use).
pub(crate) fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|s| match s.try_borrow_mut() {
        Ok(mut s) => f(&mut s),
        Err(_) => f(&mut Scratch::default()),
    })
}

/// A vector holding exactly the elements of `v` (no spare capacity), emptying `v` but
/// keeping its buffer.
fn exact<T>(v: &mut Vec<T>) -> Vec<T> {
    let mut out = Vec::with_capacity(v.len());
    out.append(v);
    out
}

/// `Polygon` operations on a borrowed ring, through a reusable buffer: `f` gets the ring
/// as a polygon (built exactly as `Polygon::new(ring.to_vec())`).
fn with_polygon<R>(buf: &mut Vec<DVec2>, ring: &[DVec2], f: impl FnOnce(&Polygon) -> R) -> R {
    let mut v = std::mem::take(buf);
    v.clear();
    v.extend_from_slice(ring);
    let poly = Polygon::new(v);
    let r = f(&poly);
    *buf = poly.into_points();
    r
}

/// Draws a derived string: returns parts, facade faces and the number of fallbacks. The
/// returned vectors are exactly sized.
pub(crate) fn interpret(
    cx: &Context<'_>,
    scratch: &mut Scratch,
    footprint: &[DVec2],
    height: f64,
    s: &ParamString,
) -> Result<(Vec<Part>, Vec<FacadeFace>, u32), BuildingsError> {
    let Scratch {
        rings,
        stack,
        parts,
        facades,
        poly,
    } = scratch;
    rings.clear();
    stack.clear();
    parts.clear();
    facades.clear();
    rings.extend_from_slice(footprint);
    let mut out = Output {
        parts,
        facades,
        poly,
        fallbacks: 0,
    };
    let mut cur = Shape {
        ring: Some((0, footprint.len())),
        inside: true,
        base: 0.0,
        height,
    };
    for i in 0..s.len() {
        let p = s.params(i);
        let arg = |k: usize, default: f64| {
            p.get(k)
                .copied()
                .filter(|v| v.is_finite())
                .unwrap_or(default)
        };
        match cx.grammar.op(s.symbol(i)) {
            Op::Ignore => {}
            Op::Push => stack.push(cur),
            Op::Pop => {
                if let Some(sh) = stack.pop() {
                    cur = sh;
                }
            }
            Op::Extrude => cur.height = arg(0, cur.height).max(0.0),
            Op::Up => cur.base += cur.height,
            Op::Scale => {
                let (sx, sy, sz) = (arg(0, 1.0), arg(1, 1.0), arg(2, 1.0));
                cur.height *= sz.max(0.0);
                cur.inside &= sx <= 1.0 && sx == sy && is_convex(ring_of(rings, cur.ring));
                cur.ring = cur
                    .ring
                    .and_then(|r| scaled(rings, out.poly, r, cx.frame_x, sx, sy));
            }
            Op::Taper => {
                let f = arg(0, 1.0);
                cur.inside &= f <= 1.0 && is_convex(ring_of(rings, cur.ring));
                cur.ring = cur
                    .ring
                    .and_then(|r| scaled(rings, out.poly, r, cx.frame_x, f, f));
            }
            Op::Move => {
                let d = cx.frame_x * arg(0, 0.0) + cx.frame_x.perp() * arg(1, 0.0);
                cur.base += arg(2, 0.0);
                cur.inside &= d == DVec2::ZERO;
                // A moved copy: saved shapes may share the ring.
                if let Some((start, len)) = cur.ring {
                    let at = rings.len();
                    rings.extend_from_within(start..start + len);
                    rings[at..].iter_mut().for_each(|q| *q += d);
                    cur.ring = Some((at, len));
                }
            }
            Op::Setback => {
                let d = arg(0, 0.0);
                cur.ring = cur.ring.and_then(|r| setback(rings, r, d));
            }
            op => {
                let Some((ring, z0, h)) = clip(cx, rings, &cur) else {
                    continue;
                };
                out.emit(cx, op, ring, z0, h, p)?;
            }
        }
    }
    let fallbacks = out.fallbacks;
    Ok((exact(parts), exact(facades), fallbacks))
}

/// The ring of a shape in the arena.
fn ring_of(rings: &[DVec2], r: Option<(usize, usize)>) -> Option<&[DVec2]> {
    r.and_then(|(start, len)| rings.get(start..start + len))
}

struct Output<'s> {
    parts: &'s mut Vec<Part>,
    facades: &'s mut Vec<FacadeFace>,
    poly: &'s mut Vec<DVec2>,
    fallbacks: u32,
}

impl Output<'_> {
    fn emit(
        &mut self,
        cx: &Context<'_>,
        op: Op,
        ring: &[DVec2],
        z0: f64,
        h: f64,
        p: &[f64],
    ) -> Result<(), BuildingsError> {
        let arg = |k: usize, default: f64| {
            p.get(k)
                .copied()
                .filter(|v| v.is_finite())
                .unwrap_or(default)
        };
        let pitch = |k: usize| {
            let deg = arg(k, cx.slope_default.atan().to_degrees()).clamp(1.0, 85.0);
            deg.to_radians().tan()
        };
        let roof: Result<(Mesh, RoofFaces), BuildingsError> = match op {
            Op::Box | Op::Volume => {
                let mesh = prism(ring, z0, z0 + h)?;
                self.walls(cx, ring, z0, h)?;
                self.parts.push(Part {
                    mesh,
                    role: PartRole::Mass,
                });
                return Ok(());
            }
            Op::Flat => roofs::slab(ring, z0, h),
            Op::Hip => roofs::skeleton_roof(ring, z0, h, pitch(0), false),
            Op::Gable => roofs::skeleton_roof(ring, z0, h, pitch(0), true),
            Op::Mansard => {
                let upper = arg(1, MANSARD_UPPER_PITCH_DEG).clamp(0.0, 60.0);
                roofs::mansard(ring, z0, h, arg(0, 1.5).max(0.01), upper.to_radians().tan())
            }
            Op::Pyramid => roofs::pyramid(ring, z0, h),
            Op::Spire | Op::Antenna => {
                let r = arg(0, 1.0).clamp(0.05, 50.0);
                let centre = with_polygon(self.poly, ring, Polygon::centroid);
                let sides = if op == Op::Spire { 8 } else { 4 };
                let small = roofs::regular(centre, r, sides);
                if !small
                    .iter()
                    .all(|&q| locate_in_ring(ring, q) != PointLocation::Outside)
                {
                    self.fallbacks += 1;
                    return Ok(());
                }
                let mesh = if op == Op::Spire {
                    crate::solid::cone(&small, z0, centre, z0 + h)?
                } else {
                    prism(&small, z0, z0 + h)?
                };
                self.parts.push(Part {
                    mesh,
                    role: PartRole::Detail,
                });
                return Ok(());
            }
            Op::Template => {
                let i = arg(0, 0.0);
                let t = (i >= 0.0).then(|| cx.templates.get(i as usize)).flatten();
                let Some(t) = t else {
                    self.fallbacks += 1;
                    return Ok(());
                };
                // The template fills the shape's box, which may overhang a non-rectangular
                // footprint: it must still lie inside the lot.
                let (x, y) = (cx.frame_x, cx.frame_x.perp());
                let b = Aabb2::in_frame(ring.iter().copied(), x, y);
                let (u0, u1, v0, v1) = (b.min.x, b.max.x, b.min.y, b.max.y);
                let corners = [
                    x * u0 + y * v0,
                    x * u1 + y * v0,
                    x * u1 + y * v1,
                    x * u0 + y * v1,
                ];
                if !cx.lot().contains_ring(&corners) {
                    self.fallbacks += 1;
                    return Ok(());
                }
                let mesh = exact_mesh(t.instance(ring, cx.frame_x, z0, h)?);
                if roofs::check_solid(&mesh).is_err() {
                    self.fallbacks += 1;
                    return Ok(());
                }
                self.parts.push(Part {
                    mesh,
                    role: PartRole::Template,
                });
                return Ok(());
            }
            _ => return Ok(()),
        };
        let (mesh, faces) = match roof {
            Ok(r) => r,
            Err(_) => {
                self.fallbacks += 1;
                match roofs::skeleton_roof(ring, z0, h, pitch(0), false) {
                    Ok(r) if matches!(op, Op::Gable | Op::Pyramid | Op::Mansard) => r,
                    _ => roofs::slab(ring, z0, h.min(0.5))?,
                }
            }
        };
        let part = self.next_part()?;
        for f in &faces {
            if let Some(q) = bounding_quad(f) {
                self.facades.push(FacadeFace {
                    role: FacadeRole::Roof,
                    floors: 0,
                    part,
                    ..q
                });
            }
        }
        self.parts.push(Part {
            mesh,
            role: PartRole::Roof,
        });
        Ok(())
    }

    /// Facade faces of a prism's walls: a ground-floor band on the ground, walls above.
    fn walls(
        &mut self,
        cx: &Context<'_>,
        ring: &[DVec2],
        z0: f64,
        h: f64,
    ) -> Result<(), BuildingsError> {
        let part = self.next_part()?;
        let g = cx.ground_floor_height;
        // The bands (and their storeys) are the same for every wall.
        let bands: [Option<(f64, f64, FacadeRole)>; 2] =
            if z0 <= 0.0 && h > g + 0.5 * cx.floor_height {
                [
                    Some((z0, z0 + g, FacadeRole::GroundFloor)),
                    Some((z0 + g, z0 + h, FacadeRole::Wall)),
                ]
            } else if z0 <= 0.0 {
                [Some((z0, z0 + h, FacadeRole::GroundFloor)), None]
            } else {
                [Some((z0, z0 + h, FacadeRole::Wall)), None]
            };
        let bands = bands.map(|band| {
            band.map(|(lo, hi, role)| {
                let fh = if role == FacadeRole::GroundFloor {
                    g
                } else {
                    cx.floor_height
                };
                (lo, hi, role, ((hi - lo) / fh).round().max(1.0) as u32)
            })
        });
        for (i, &a) in ring.iter().enumerate() {
            let b = ring.get(i + 1).or(ring.first()).copied().unwrap_or(a);
            let d = b - a;
            // `d.normalize_or_zero()` and `d.length()` with one square root.
            let width = d.length();
            let rcp = 1.0 / width;
            let u = if rcp.is_finite() && rcp > 0.0 {
                d * rcp
            } else {
                DVec2::ZERO
            };
            for &(lo, hi, role, floors) in bands.iter().flatten() {
                self.facades.push(FacadeFace {
                    origin: to_world(a, lo),
                    u: to_world(u, 0.0),
                    v: DVec3::Y,
                    width,
                    height: hi - lo,
                    floors,
                    part,
                    role,
                });
            }
        }
        Ok(())
    }

    /// The index the next part will have, as facade faces store it.
    fn next_part(&self) -> Result<u32, BuildingsError> {
        u32::try_from(self.parts.len()).map_err(|_| BuildingsError::InvalidParameter {
            name: "lod",
            reason: "a building would have more than 2^32 parts; lower the level of detail".into(),
        })
    }
}

/// The bounding rectangle of a planar polygon in its plane: `u` horizontal, `v` up.
fn bounding_quad(pts: &[DVec3]) -> Option<FacadeFace> {
    let n = pts.len();
    let mut nrm = DVec3::ZERO;
    for (i, p) in pts.iter().enumerate() {
        nrm += p.cross(pts[if i + 1 < n { i + 1 } else { 0 }]);
    }
    let nrm = nrm.normalize_or_zero();
    if nrm == DVec3::ZERO {
        return None;
    }
    let t = DVec3::Y.cross(nrm);
    let t = if t.length() < 1e-9 {
        DVec3::X
    } else {
        t.normalize()
    };
    let v = nrm.cross(t);
    let b = Aabb2::from_points(pts.iter().map(|p| DVec2::new(p.dot(t), p.dot(v))));
    let (u0, u1, v0, v1) = (b.min.x, b.max.x, b.min.y, b.max.y);
    let off = nrm * pts[0].dot(nrm);
    Some(FacadeFace {
        origin: off + t * u0 + v * v0,
        u: t,
        v,
        width: u1 - u0,
        height: v1 - v0,
        floors: 0,
        part: 0,
        role: FacadeRole::Roof,
    })
}

/// The part of the shape to draw: inside the lot, below the top; `None` if nothing is.
fn clip<'r>(cx: &Context<'_>, rings: &'r [DVec2], s: &Shape) -> Option<(&'r [DVec2], f64, f64)> {
    let ring = ring_of(rings, s.ring)?;
    let top = (s.base + s.height).min(cx.top);
    if !(s.base >= 0.0 && top - s.base >= MIN_PART_HEIGHT) {
        return None;
    }
    (s.inside || cx.lot().contains_ring(ring)).then_some((ring, s.base, top - s.base))
}

fn is_convex(r: Option<&[DVec2]>) -> bool {
    r.is_some_and(|r| {
        let n = r.len();
        let after = |i: usize| if i + 1 < n { i + 1 } else { 0 };
        (0..n).all(|i| {
            polis_geom::orient2d(r[i], r[after(i)], r[after(after(i))])
                != polis_geom::Orientation::Clockwise
        })
    })
}

/// Lots with more edges than this get a grid index of their edges for
/// [`LotShape::contains_ring`]; smaller ones are scanned.
const LOT_INDEX_MIN_EDGES: usize = 32;

/// A lot (local coordinates) prepared for containment tests: with many edges, a uniform
/// grid of about one edge per cell, so a ring of `m` edges is tested against an `n`-edge
/// lot in about `O(n + m)` instead of `O(n · m)`.
pub(crate) struct LotShape {
    polygon: Polygon,
    index: Option<polis_geom::spatial::GridIndex<u32>>,
}

impl LotShape {
    pub(crate) fn new(polygon: Polygon) -> Self {
        let n = polygon.len();
        let index = (n > LOT_INDEX_MIN_EDGES)
            .then(|| {
                let size = polygon.bbox().size().max_element();
                let cell =
                    (size / (n as f64).sqrt()).max(polis_geom::spatial::GridOptions::MIN_CELL_SIZE);
                let mut grid =
                    polis_geom::spatial::GridIndex::new(polis_geom::spatial::GridOptions {
                        cell_size: cell,
                    })
                    .ok()?;
                for (i, (a, b)) in polygon.edges().enumerate() {
                    use polis_geom::SpatialIndex;
                    grid.insert_segment(i as u32, a, b).ok()?;
                }
                Some(grid)
            })
            .flatten();
        LotShape { polygon, index }
    }

    /// Whether the ring lies inside the lot: every vertex inside or on it, and no edge
    /// properly crossing the lot's boundary. Where the ring does not meet the boundary at
    /// all it is wholly inside or wholly outside, and one vertex decides.
    pub(crate) fn contains_ring(&self, ring: &[DVec2]) -> bool {
        let lot = &self.polygon;
        let n = ring.len();
        let mut touches = false;
        for i in 0..n {
            let (a, b) = (ring[i], ring[if i + 1 < n { i + 1 } else { 0 }]);
            let mut verdict = |c: DVec2, d: DVec2| match segment_intersection(a, b, c, d) {
                SegmentIntersection::Crossing { .. } => false,
                SegmentIntersection::Disjoint => true,
                _ => {
                    touches = true;
                    true
                }
            };
            let clear = match &self.index {
                Some(grid) => {
                    use polis_geom::SpatialIndex;
                    let mut clear = true;
                    grid.for_each_candidate_along(a, b, |e, _| {
                        if clear {
                            let (c, d) = lot.edge(e as usize);
                            clear = verdict(c, d);
                        }
                    });
                    clear
                }
                None => lot.edges().all(|(c, d)| verdict(c, d)),
            };
            if !clear {
                return false;
            }
        }
        if touches {
            ring.iter().all(|&p| lot.contains(p))
        } else {
            ring.first().is_some_and(|&p| lot.contains(p))
        }
    }
}

/// The ring `r` of the arena scaled about its centroid by `sx` along `x` and `sy`
/// across, appended to the arena; `None` if the result is degenerate.
fn scaled(
    rings: &mut Vec<DVec2>,
    buf: &mut Vec<DVec2>,
    (start, len): (usize, usize),
    x: DVec2,
    sx: f64,
    sy: f64,
) -> Option<(usize, usize)> {
    if !(sx > 0.0 && sy > 0.0) {
        return None;
    }
    let c = with_polygon(buf, rings.get(start..start + len)?, Polygon::centroid);
    let y = x.perp();
    let at = rings.len();
    rings.extend_from_within(start..start + len);
    for p in &mut rings[at..] {
        let d = *p - c;
        *p = c + x * (d.dot(x) * sx) + y * (d.dot(y) * sy);
    }
    // Scaling keeps a simple ring simple only in exact arithmetic: rounding may merge
    // or cross vertices of tiny rings, so the result is checked.
    let ok = with_polygon(buf, &rings[at..], |poly| {
        poly.validate().is_ok() && poly.is_ccw() && poly.len() == len
    });
    if ok {
        Some((at, len))
    } else {
        rings.truncate(at);
        None
    }
}

/// The largest piece of the arena's ring `r` inset by `d`, starting as close as possible
/// to the original first vertex, appended to the arena; `None` when nothing is left.
fn setback(rings: &mut Vec<DVec2>, r: (usize, usize), d: f64) -> Option<(usize, usize)> {
    if !(d.is_finite() && d >= 0.0) {
        return None;
    }
    if d == 0.0 {
        // Rings are never changed in place: the shape may share it.
        return Some(r);
    }
    let (start, len) = r;
    let pieces = crate::footprint::inset_ring(rings.get(start..start + len)?, d).ok()?;
    let best = pieces.into_iter().max_by(|a, b| {
        ring_signed_area(&a.outer.points)
            .abs()
            .total_cmp(&ring_signed_area(&b.outer.points).abs())
    })?;
    // Keep the street edge first: rotate so the edge from input edge 0 (or the lowest) leads.
    let k = best
        .outer
        .sources
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.map(|s| (s, i)))
        .min()
        .map_or(0, |(_, i)| i);
    let mut pts = best.outer.points;
    pts.rotate_left(k);
    let poly = Polygon::new(pts);
    if !(poly.validate().is_ok() && poly.area() > 0.0) {
        return None;
    }
    let at = rings.len();
    rings.extend_from_slice(poly.points());
    Some((at, poly.len()))
}

/// `mesh` with exactly sized vectors (copied only when some has spare capacity).
pub(crate) fn exact_mesh(mesh: Mesh) -> Mesh {
    let tight = mesh.positions.capacity() == mesh.positions.len()
        && mesh.normals.capacity() == mesh.normals.len()
        && mesh.uvs.capacity() == mesh.uvs.len()
        && mesh.indices.capacity() == mesh.indices.len();
    if tight {
        return mesh;
    }
    Mesh {
        positions: mesh.positions.as_slice().to_vec(),
        normals: mesh.normals.as_slice().to_vec(),
        uvs: mesh.uvs.as_slice().to_vec(),
        indices: mesh.indices.as_slice().to_vec(),
        material: mesh.material,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn facade_faces_are_compact_and_derive_their_corners() {
        assert!(std::mem::size_of::<FacadeFace>() <= 104);
        // A roof plane rising to the north (−Z) at 30°.
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let face = FacadeFace {
            origin: DVec3::new(1.0, 3.0, 2.0),
            u: DVec3::X,
            v: DVec3::new(0.0, s, -c),
            width: 4.0,
            height: 2.0,
            floors: 0,
            part: 1,
            role: FacadeRole::Roof,
        };
        let [bl, br, tr, tl] = face.corners();
        assert_eq!(bl, face.origin);
        assert!((br - bl - DVec3::X * 4.0).length() < 1e-12);
        assert!((tr - br - (tl - bl)).length() < 1e-12);
        assert!((tl.y - bl.y - 2.0 * s).abs() < 1e-12);
        // Counter-clockwise seen from outside: the normal follows the right-hand rule;
        // a roof rising to the north faces up and south (+Z).
        let n = (br - bl).cross(tl - bl).normalize();
        assert!((face.normal() - n).length() < 1e-12);
        assert!(face.normal().y > 0.0 && face.normal().z > 0.0);
        assert_eq!(face.part_index(), 1);
    }
}
