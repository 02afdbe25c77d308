//! Lines: where two lines cross, the angular order of directions from any reference
//! direction, and a region cut by a line into all of its pieces.
//!
//! * [`Line`] and [`meet`]: a line in point–normal form, moved parallel to itself by a
//!   signed distance (an offset line, as in a straight-skeleton wavefront), and the
//!   crossing of two such lines, solved relative to a nearby point for accuracy.
//! * [`ccw_cmp_from`]: the exact counter-clockwise order of directions measured from an
//!   arbitrary reference direction (what [`ccw_cmp`](crate::ccw_cmp) does from the east or
//!   the south), for walks that turn "first clockwise from where they came from".
//! * [`split_by_line`]: a region (outer ring and holes, a value per edge) cut by an
//!   infinite line into *all* of its pieces, the method of Kelly 2008 §4.4.2.3 after
//!   Graphics Gems V II.3: the crossing edges get a vertex, the crossings are sorted along
//!   the line and paired by the Jordan curve rule (alternate stretches of the line are
//!   inside), each pair is bridged by two new edges, and the pieces are read off the rings.
//!   [`split_polygon_by_line`] is the same for an untagged [`PolygonWithHoles`].
//!
//! Side and order decisions are exact ([`orient2d`](crate::orient2d)); crossing points are
//! computed in floating point afterwards.

use std::cmp::Ordering;

use glam::DVec2;

use crate::polygon::{locate_in_ring, ring_signed_area};
use crate::predicates::{lerp_stable, orient2d_value};
use crate::{PointLocation, Polygon, PolygonWithHoles};

/// A line through `point` with unit `normal`; the signed distance of `x` from it is
/// `normal · (x − point)` (positive on the side the normal points to).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// A point on the line.
    pub point: DVec2,
    /// Unit normal.
    pub normal: DVec2,
}

impl Line {
    /// The line through `a` and `b` (`a != b`), its normal to the left of `a → b` (the
    /// inside of a counter-clockwise ring).
    pub fn through(a: DVec2, b: DVec2) -> Self {
        Line {
            point: a,
            normal: (b - a).normalize().perp(),
        }
    }

    /// Signed distance of `x` from the line (positive on the normal's side).
    #[inline]
    pub fn distance(&self, x: DVec2) -> f64 {
        self.normal.dot(x - self.point)
    }

    /// Unit direction along the line (the normal turned clockwise).
    #[inline]
    pub fn direction(&self) -> DVec2 {
        -self.normal.perp()
    }
}

/// Where the line `a` moved by `sa` along its normal crosses the line `b` moved by `sb`,
/// solved relative to the nearby point `near` (the result is then accurate near `near`,
/// wherever the lines are). `None` when the lines are parallel: the sine of the angle
/// between them at most `parallel_sine` (at least `0`), or the crossing not finite.
///
/// ```
/// use polis_geom::DVec2;
/// use polis_geom::lines::{Line, meet};
/// let x_axis = Line::through(DVec2::ZERO, DVec2::X); // normal +y
/// let y_axis = Line::through(DVec2::ZERO, DVec2::NEG_Y); // normal +x
/// // Both moved inwards by 1: they cross at (1, 1).
/// let p = meet(&x_axis, 1.0, &y_axis, 1.0, DVec2::ZERO, 0.0).unwrap();
/// assert!((p - DVec2::new(1.0, 1.0)).length() < 1e-15);
/// ```
pub fn meet(
    a: &Line,
    sa: f64,
    b: &Line,
    sb: f64,
    near: DVec2,
    parallel_sine: f64,
) -> Option<DVec2> {
    let (na, nb) = (a.normal, b.normal);
    let det = na.perp_dot(nb);
    if det.abs() <= parallel_sine || det == 0.0 {
        return None;
    }
    // How far each moved line is ahead of `near`; solve n · y = r for the step y.
    let ra = sa - na.dot(near - a.point);
    let rb = sb - nb.dot(near - b.point);
    let y = DVec2::new((ra * nb.y - rb * na.y) / det, (na.x * rb - nb.x * ra) / det);
    let p = near + y;
    p.is_finite().then_some(p)
}

/// Compares the directions `a` and `b` by their counter-clockwise angle from the
/// reference direction `r`, in `[0, 2π)`, exactly: `r` itself (and every direction along
/// it) comes first, the opposite of `r` exactly halfway. `Equal` only for the same
/// direction. All three must be non-zero.
///
/// With `r = (1, 0)` this is [`ccw_cmp`](crate::ccw_cmp) from the east; any other `r`
/// gives the order a walk needs that turns relative to the way it came.
///
/// ```
/// use std::cmp::Ordering;
/// use polis_geom::DVec2;
/// use polis_geom::lines::ccw_cmp_from;
/// let back = DVec2::new(0.0, -1.0);
/// // From "straight down", east comes a quarter turn before north.
/// assert_eq!(ccw_cmp_from(back, DVec2::X, DVec2::Y), Ordering::Less);
/// assert_eq!(ccw_cmp_from(back, DVec2::NEG_X, DVec2::X), Ordering::Greater);
/// ```
pub fn ccw_cmp_from(r: DVec2, a: DVec2, b: DVec2) -> Ordering {
    // 0 for angles in [0, π), 1 for [π, 2π).
    let half = |d: DVec2| {
        let o = orient2d_value(DVec2::ZERO, r, d);
        u8::from(!(o > 0.0 || (o == 0.0 && r.dot(d) > 0.0)))
    };
    half(a).cmp(&half(b)).then_with(|| {
        let o = orient2d_value(DVec2::ZERO, a, b);
        if o > 0.0 {
            Ordering::Less
        } else if o < 0.0 {
            Ordering::Greater
        } else {
            Ordering::Equal
        }
    })
}

/// A ring with a value per edge: `tags[i]` belongs to edge `points[i] → points[i + 1]`
/// (street access, a road id …).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TaggedRing<T> {
    /// The vertices, no repeated closing vertex.
    pub points: Vec<DVec2>,
    /// One value per edge.
    pub tags: Vec<T>,
}

impl<T> TaggedRing<T> {
    /// Signed area in m² (positive for counter-clockwise).
    pub fn signed_area(&self) -> f64 {
        ring_signed_area(&self.points)
    }
}

/// A region with a value per edge: a counter-clockwise outer ring and clockwise holes.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TaggedRegion<T> {
    /// The outer ring.
    pub outer: TaggedRing<T>,
    /// The holes.
    pub holes: Vec<TaggedRing<T>>,
}

impl<T> TaggedRegion<T> {
    /// Area in m² (the outer ring's minus the holes').
    pub fn area(&self) -> f64 {
        self.outer.signed_area() + self.holes.iter().map(TaggedRing::signed_area).sum::<f64>()
    }

    /// All rings, outer first.
    pub fn rings(&self) -> impl Iterator<Item = &TaggedRing<T>> {
        std::iter::once(&self.outer).chain(&self.holes)
    }
}

#[derive(Debug, Clone, Copy)]
struct Node<T> {
    p: DVec2,
    next: usize,
    tag: T,
}

/// Cuts `region` (valid, counter-clockwise outer ring, clockwise holes, one tag per edge)
/// by the infinite line through `a` and `b` into all of its pieces, each a region with its
/// own holes. Edges keep their tags, also where they are cut; the new edges along the line
/// get `bridge`.
///
/// A vertex exactly on the line counts as lying to its right (a symbolic shift of the
/// line), which keeps the number of crossings even; pieces of zero area that touching
/// produces are dropped. The region comes back whole (one piece) when the line misses it,
/// when `a == b`, or when the pieces would not add up to the region's area (numerically
/// degenerate input), so a cut never loses or invents area. A missing tag (fewer tags than
/// edges) reads as `bridge`.
pub fn split_by_line<T: Copy>(
    region: &TaggedRegion<T>,
    a: DVec2,
    b: DVec2,
    bridge: T,
) -> Vec<TaggedRegion<T>> {
    if a == b {
        return vec![region.clone()];
    }
    let mut nodes: Vec<Node<T>> = Vec::new();
    let mut crossings: Vec<(f64, usize)> = Vec::new();
    let dir = b - a;
    let mut side: Vec<f64> = Vec::new();
    for ring in region.rings() {
        let n = ring.points.len();
        let base = nodes.len();
        for (i, &p) in ring.points.iter().enumerate() {
            nodes.push(Node {
                p,
                next: base + (i + 1) % n,
                tag: ring.tags.get(i).copied().unwrap_or(bridge),
            });
        }
        side.clear();
        side.extend(ring.points.iter().map(|&p| orient2d_value(a, b, p)));
        for i in 0..n {
            let j = (i + 1) % n;
            let (li, lj) = (side[i] > 0.0, side[j] > 0.0);
            if li == lj {
                continue;
            }
            let at = if !lj && side[j] == 0.0 {
                base + j
            } else if !li && side[i] == 0.0 {
                base + i
            } else {
                // A proper crossing: interpolate by the exact-signed distances.
                let t = side[i] / (side[i] - side[j]);
                let p = lerp_stable(ring.points[i], ring.points[j], t);
                nodes.push(Node {
                    p,
                    next: nodes[base + i].next,
                    tag: nodes[base + i].tag,
                });
                let c = nodes.len() - 1;
                nodes[base + i].next = c;
                c
            };
            crossings.push((dir.dot(nodes[at].p - a), at));
        }
    }
    if crossings.len() < 2 || !crossings.len().is_multiple_of(2) {
        return vec![region.clone()];
    }
    crossings.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    // Jordan rule: the stretches between crossings 0–1, 2–3, … are inside. Bridge each.
    for pair in crossings.chunks_exact(2) {
        let (ca, cb) = (pair[0].1, pair[1].1);
        if ca == cb {
            continue;
        }
        let (na, nb) = (nodes[ca], nodes[cb]);
        nodes.push(na);
        let a2 = nodes.len() - 1;
        nodes.push(nb);
        let b2 = nodes.len() - 1;
        nodes[ca].next = b2;
        nodes[ca].tag = bridge;
        nodes[cb].next = a2;
        nodes[cb].tag = bridge;
    }
    // Read off every cycle.
    let mut seen = vec![false; nodes.len()];
    let mut outers: Vec<TaggedRing<T>> = Vec::new();
    let mut holes: Vec<TaggedRing<T>> = Vec::new();
    let scale = region
        .outer
        .points
        .iter()
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()))
        .max(1.0);
    let tiny = 1e-12 * scale * scale;
    for start in 0..nodes.len() {
        if seen[start] {
            continue;
        }
        let mut ring = TaggedRing {
            points: Vec::new(),
            tags: Vec::new(),
        };
        let mut k = start;
        let mut guard = 0;
        while !seen[k] && guard <= nodes.len() {
            seen[k] = true;
            ring.points.push(nodes[k].p);
            ring.tags.push(nodes[k].tag);
            k = nodes[k].next;
            guard += 1;
        }
        if k != start {
            return vec![region.clone()];
        }
        dedup_ring(&mut ring);
        if ring.points.len() < 3 {
            continue;
        }
        let area = ring.signed_area();
        if area > tiny {
            outers.push(ring);
        } else if area < -tiny {
            holes.push(ring);
        }
    }
    let mut pieces: Vec<TaggedRegion<T>> = outers
        .into_iter()
        .map(|outer| TaggedRegion {
            outer,
            holes: Vec::new(),
        })
        .collect();
    // Each hole goes to the smallest piece around it.
    for h in holes {
        let around =
            innermost_ring_containing(pieces.iter().map(|r| &r.outer.points[..]), h.points[0]);
        match around {
            Some(i) => pieces[i].holes.push(h),
            None => return vec![region.clone()],
        }
    }
    let total: f64 = pieces.iter().map(TaggedRegion::area).sum();
    let area = region.area();
    if pieces.is_empty() || (total - area).abs() > 1e-9 * area.abs().max(tiny) {
        return vec![region.clone()];
    }
    pieces
}

/// Of the counter-clockwise `rings`, the index of the one with the smallest area that has
/// `p` inside or on its boundary (the innermost of nested rings; the first of equals), or
/// `None`. This is where a hole found by walking a cut or offset boundary belongs.
pub fn innermost_ring_containing<'a>(
    rings: impl IntoIterator<Item = &'a [DVec2]>,
    p: DVec2,
) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for (i, r) in rings.into_iter().enumerate() {
        if locate_in_ring(r, p) != PointLocation::Outside {
            let area = ring_signed_area(r);
            if best.is_none_or(|(_, b)| area < b) {
                best = Some((i, area));
            }
        }
    }
    best.map(|(i, _)| i)
}

/// [`split_by_line`] for a polygon with holes without edge tags.
pub fn split_polygon_by_line(
    polygon: &PolygonWithHoles,
    a: DVec2,
    b: DVec2,
) -> Vec<PolygonWithHoles> {
    let ring = |p: &Polygon| TaggedRing {
        points: p.points().to_vec(),
        tags: vec![(); p.len()],
    };
    let region = TaggedRegion {
        outer: ring(&polygon.outer),
        holes: polygon.holes.iter().map(ring).collect(),
    };
    split_by_line(&region, a, b, ())
        .into_iter()
        .map(|r| {
            PolygonWithHoles::new(
                Polygon::new(r.outer.points),
                r.holes
                    .into_iter()
                    .map(|h| Polygon::new(h.points))
                    .collect(),
            )
        })
        .collect()
}

/// Removes repeated consecutive points; the surviving edge keeps the tag of the edge that
/// has length.
fn dedup_ring<T: Copy>(ring: &mut TaggedRing<T>) {
    let mut points: Vec<DVec2> = Vec::with_capacity(ring.points.len());
    let mut tags: Vec<T> = Vec::with_capacity(ring.points.len());
    for (&p, &s) in ring.points.iter().zip(&ring.tags) {
        if points.last() == Some(&p) {
            if let Some(l) = tags.last_mut() {
                *l = s;
            }
            continue;
        }
        points.push(p);
        tags.push(s);
    }
    while points.len() > 1 && points.first() == points.last() {
        points.pop();
        tags.pop();
    }
    ring.points = points;
    ring.tags = tags;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AngleStart, ccw_cmp};

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn ring(p: &[(f64, f64)]) -> TaggedRing<u32> {
        TaggedRing {
            points: p.iter().map(|&(x, y)| v(x, y)).collect(),
            tags: (1..=p.len() as u32).collect(),
        }
    }

    #[test]
    fn lines_meet_where_their_offsets_cross() {
        let bottom = Line::through(v(0., 0.), v(4., 0.));
        let slanted = Line::through(v(4., 0.), v(4., 4.) + v(-1., 0.));
        assert_eq!(bottom.normal, v(0., 1.));
        assert!((bottom.distance(v(3., 2.)) - 2.0).abs() < 1e-15);
        assert!((bottom.direction() - v(1., 0.)).length() < 1e-15);
        // Unmoved: they cross at (4, 0), from any nearby point.
        for near in [v(4., 0.), v(3., 1.), v(100., -50.)] {
            let p = meet(&bottom, 0.0, &slanted, 0.0, near, 1e-12).unwrap();
            assert!((p - v(4., 0.)).length() < 1e-12, "{p}");
        }
        // Moved inwards by 1 each: the crossing is at distance 1 from both.
        let p = meet(&bottom, 1.0, &slanted, 1.0, v(3., 1.), 1e-12).unwrap();
        assert!((bottom.distance(p) - 1.0).abs() < 1e-12);
        assert!((slanted.distance(p) - 1.0).abs() < 1e-12);
        // Parallel lines (same or opposite way) never meet.
        let top = Line::through(v(4., 3.), v(0., 3.));
        assert_eq!(meet(&bottom, 0.0, &top, 0.0, v(0., 0.), 0.0), None);
        let shifted = Line::through(v(0., 1.), v(1., 1.));
        assert_eq!(meet(&bottom, 0.0, &shifted, 0.0, v(0., 0.), 0.0), None);
        // Nearly parallel: refused below the given sine, solved above it.
        let almost = Line::through(v(0., 1.), v(1., 1. + 1e-9));
        assert_eq!(meet(&bottom, 0.0, &almost, 0.0, v(0., 0.), 1e-8), None);
        let p = meet(&bottom, 0.0, &almost, 0.0, v(0., 0.), 0.0).unwrap();
        assert!(p.y.abs() < 1e-6 && (p.x + 1e9).abs() < 1e3, "{p}");
    }

    #[test]
    fn angular_order_from_any_reference() {
        let dirs: Vec<DVec2> = (0..16)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 16.0;
                v(a.cos(), a.sin())
            })
            .collect();
        for (s, &r) in dirs.iter().enumerate() {
            for (i, &p) in dirs.iter().enumerate() {
                for (j, &q) in dirs.iter().enumerate() {
                    let (ki, kj) = ((i + 16 - s) % 16, (j + 16 - s) % 16);
                    assert_eq!(ccw_cmp_from(r, p, q), ki.cmp(&kj), "from {s}: {i} vs {j}");
                }
            }
        }
        // From the east it is ccw_cmp's order, also for nearly equal directions.
        let tricky = [
            v(1., 0.),
            v(1., 1e-300),
            v(-1., 1e-300),
            v(-1., 0.),
            v(1., -1e-300),
        ];
        for &p in &tricky {
            for &q in &tricky {
                assert_eq!(
                    ccw_cmp_from(v(1., 0.), p, q),
                    ccw_cmp(DVec2::ZERO, p, q, AngleStart::East)
                );
            }
        }
        // Directions along the reference: the same way first, the opposite way halfway.
        let r = v(3., 1.);
        assert_eq!(ccw_cmp_from(r, r * 2.0, v(0., 1.)), Ordering::Less);
        assert_eq!(ccw_cmp_from(r, -r, v(-1., 3.)), Ordering::Greater);
        assert_eq!(ccw_cmp_from(r, -r, v(1., -3.)), Ordering::Less);
        assert_eq!(ccw_cmp_from(r, r, r * 5.0), Ordering::Equal);
    }

    #[test]
    fn square_in_two_keeps_tags() {
        let r = TaggedRegion {
            outer: ring(&[(0., 0.), (4., 0.), (4., 4.), (0., 4.)]),
            holes: vec![],
        };
        let pieces = split_by_line(&r, v(1., -1.), v(1., 5.), 0);
        assert_eq!(pieces.len(), 2);
        let mut areas: Vec<f64> = pieces.iter().map(TaggedRegion::area).collect();
        areas.sort_by(f64::total_cmp);
        assert_eq!(areas, vec![4.0, 12.0]);
        for p in &pieces {
            // One bridge edge each; the cut edges 1 (bottom) and 3 (top) keep their tags.
            assert_eq!(p.outer.tags.iter().filter(|&&t| t == 0).count(), 1);
            assert!(p.outer.tags.contains(&1) && p.outer.tags.contains(&3));
            assert_eq!(p.outer.tags.len(), p.outer.points.len());
            assert!(p.outer.signed_area() > 0.0);
        }
    }

    #[test]
    fn u_shape_into_three() {
        let r = TaggedRegion {
            outer: ring(&[
                (0., 0.),
                (6., 0.),
                (6., 6.),
                (4., 6.),
                (4., 2.),
                (2., 2.),
                (2., 6.),
                (0., 6.),
            ]),
            holes: vec![],
        };
        let pieces = split_by_line(&r, v(-1., 4.), v(7., 4.), 0);
        assert_eq!(pieces.len(), 3);
        let total: f64 = pieces.iter().map(TaggedRegion::area).sum();
        assert!((total - r.area()).abs() < 1e-12);
        for p in &pieces {
            let poly = Polygon::new(p.outer.points.clone());
            assert!(poly.validate().is_ok() && poly.is_ccw());
        }
    }

    #[test]
    fn holes_are_cut_or_kept() {
        let mut h1 = ring(&[(2., 2.), (4., 2.), (4., 4.), (2., 4.)]);
        h1.points.reverse();
        let mut h2 = ring(&[(6., 6.), (8., 6.), (8., 8.), (6., 8.)]);
        h2.points.reverse();
        let r = TaggedRegion {
            outer: ring(&[(0., 0.), (10., 0.), (10., 10.), (0., 10.)]),
            holes: vec![h1, h2],
        };
        let pieces = split_by_line(&r, v(3., -1.), v(3., 11.), 0);
        assert_eq!(pieces.len(), 2);
        let total: f64 = pieces.iter().map(TaggedRegion::area).sum();
        assert!((total - r.area()).abs() < 1e-12);
        // The cut hole opened into the outer rings; the other stays a hole.
        assert_eq!(pieces.iter().map(|p| p.holes.len()).sum::<usize>(), 1);
    }

    #[test]
    fn degenerate_lines() {
        let r = TaggedRegion {
            outer: ring(&[(0., 0.), (4., 0.), (4., 4.), (0., 4.)]),
            holes: vec![],
        };
        // Through two vertices (a diagonal): two triangles.
        let pieces = split_by_line(&r, v(0., 0.), v(4., 4.), 0);
        assert_eq!(pieces.len(), 2);
        assert!(pieces.iter().all(|p| p.outer.points.len() == 3));
        // Along an edge, or missing: the square whole.
        for (a, b) in [
            (v(-1., 0.), v(5., 0.)),
            (v(-1., 9.), v(5., 9.)),
            (v(1., 1.), v(1., 1.)),
        ] {
            let pieces = split_by_line(&r, a, b, 0);
            assert_eq!(pieces.len(), 1);
            assert!((pieces[0].area() - 16.0).abs() < 1e-12);
        }
    }

    #[test]
    fn innermost_of_nested_rings() {
        let big = Polygon::rect(v(0., 0.), v(10., 10.));
        let small = Polygon::rect(v(1., 1.), v(4., 4.));
        let apart = Polygon::rect(v(6., 6.), v(9., 9.));
        let rings = [big.points(), small.points(), apart.points()];
        assert_eq!(innermost_ring_containing(rings, v(2., 2.)), Some(1));
        assert_eq!(innermost_ring_containing(rings, v(1., 2.)), Some(1));
        assert_eq!(innermost_ring_containing(rings, v(5., 5.)), Some(0));
        assert_eq!(innermost_ring_containing(rings, v(7., 7.)), Some(2));
        assert_eq!(innermost_ring_containing(rings, v(11., 5.)), None);
    }

    #[test]
    fn untagged_polygons() {
        let p = PolygonWithHoles::from(Polygon::rect(v(0., 0.), v(6., 2.)));
        let pieces = split_polygon_by_line(&p, v(2., 0.), v(2., 1.));
        assert_eq!(pieces.len(), 2);
        let areas: f64 = pieces.iter().map(PolygonWithHoles::area).sum();
        assert!((areas - 12.0).abs() < 1e-12);
        assert!(
            pieces
                .iter()
                .all(|q| q.validate().is_ok() && q.is_normalized())
        );
    }
}
