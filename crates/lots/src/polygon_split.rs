//! Splitting a region (outer ring plus holes) by an infinite line into *all* its pieces.
//!
//! This is a general polygon operation that belongs in `polis-geom` (it is here until the
//! geometry kernel is free to take it). The method is Kelly 2008 §4.4.2.3, after Graphics
//! Gems V II.3: the ring edges crossing the line get an intersection vertex, the
//! intersections are sorted along the line and paired by the Jordan curve rule (each
//! alternate stretch of the line is inside the region), each pair is *bridged* with two
//! new edges, and the pieces are read off by walking the rings.
//!
//! Every edge carries a tag (street access, for lots) that is kept through the split; the
//! bridge edges get `false`.
//!
//! Side tests are exact ([`orient2d`]). A vertex exactly on the line counts as being on
//! its right (a symbolic shift of the line), which keeps the crossing count even; pieces
//! of zero area that such touching produces are dropped. If the pieces' areas do not add
//! up to the region's, the region is returned whole, so a split never loses land.

use polis_geom::polygon::{locate_in_ring, ring_signed_area};
use polis_geom::predicates::orient2d_value;
use polis_geom::{DVec2, PointLocation};
use serde::{Deserialize, Serialize};

/// A ring with a tag per edge: `street[i]` belongs to edge `points[i] → points[i + 1]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaggedRing {
    /// The vertices.
    pub points: Vec<DVec2>,
    /// One flag per edge: whether the edge faces a street.
    pub street: Vec<bool>,
}

impl TaggedRing {
    /// Signed area (positive for counter-clockwise).
    pub fn signed_area(&self) -> f64 {
        ring_signed_area(&self.points)
    }

    /// Edge `i` (cyclically) as (start, end); `None` for an empty ring.
    pub fn edge(&self, i: usize) -> Option<(DVec2, DVec2)> {
        let n = self.points.len();
        if n == 0 {
            return None;
        }
        Some((self.points[i % n], self.points[(i + 1) % n]))
    }
}

/// A region to split: a counter-clockwise outer ring and clockwise holes, with edge tags.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Region {
    /// The outer ring (counter-clockwise).
    pub outer: TaggedRing,
    /// Holes (clockwise).
    pub holes: Vec<TaggedRing>,
}

impl Region {
    /// Area in m² (outer minus holes).
    pub fn area(&self) -> f64 {
        self.outer.signed_area() + self.holes.iter().map(TaggedRing::signed_area).sum::<f64>()
    }

    /// All rings, outer first.
    pub fn rings(&self) -> impl Iterator<Item = &TaggedRing> {
        std::iter::once(&self.outer).chain(&self.holes)
    }

    /// Whether any edge faces a street.
    pub fn has_street(&self) -> bool {
        self.rings().any(|r| r.street.iter().any(|&s| s))
    }
}

#[derive(Debug, Clone, Copy)]
struct Node {
    p: DVec2,
    next: usize,
    street: bool,
}

/// Splits `region` by the infinite line through `a` and `b` (`a != b`) into all of its
/// pieces, each a region with its own holes. Returns the region unchanged (one piece) if
/// the line misses it or the split would be inconsistent.
pub fn split_by_line(region: &Region, a: DVec2, b: DVec2) -> Vec<Region> {
    if a == b {
        return vec![region.clone()];
    }
    let mut nodes: Vec<Node> = Vec::new();
    let mut crossings: Vec<(f64, usize)> = Vec::new();
    let dir = b - a;
    for ring in region.rings() {
        let n = ring.points.len();
        let base = nodes.len();
        for (i, &p) in ring.points.iter().enumerate() {
            nodes.push(Node {
                p,
                next: base + (i + 1) % n,
                street: ring.street.get(i).copied().unwrap_or(false),
            });
        }
        let side: Vec<f64> = ring
            .points
            .iter()
            .map(|&p| orient2d_value(a, b, p))
            .collect();
        for i in 0..n {
            let j = (i + 1) % n;
            let (li, lj) = (side[i] > 0.0, side[j] > 0.0);
            if li == lj {
                continue;
            }
            let (pi, pj) = (ring.points[i], ring.points[j]);
            let at = if !lj && side[j] == 0.0 {
                base + j
            } else if !li && side[i] == 0.0 {
                base + i
            } else {
                // Proper crossing: the weights are the exact-signed distances.
                let t = side[i] / (side[i] - side[j]);
                let p = polis_geom::predicates::lerp_stable(pi, pj, t);
                nodes.push(Node {
                    p,
                    next: nodes[base + i].next,
                    street: nodes[base + i].street,
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
    for pair in crossings.chunks_exact(2) {
        let (ca, cb) = (pair[0].1, pair[1].1);
        if ca == cb {
            continue;
        }
        let na = Node {
            p: nodes[ca].p,
            next: nodes[ca].next,
            street: nodes[ca].street,
        };
        let nb = Node {
            p: nodes[cb].p,
            next: nodes[cb].next,
            street: nodes[cb].street,
        };
        nodes.push(na);
        let a2 = nodes.len() - 1;
        nodes.push(nb);
        let b2 = nodes.len() - 1;
        nodes[ca].next = b2;
        nodes[ca].street = false;
        nodes[cb].next = a2;
        nodes[cb].street = false;
    }
    // Read off every cycle.
    let mut seen = vec![false; nodes.len()];
    let mut outers: Vec<TaggedRing> = Vec::new();
    let mut holes: Vec<TaggedRing> = Vec::new();
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
            street: Vec::new(),
        };
        let mut k = start;
        let mut guard = 0;
        while !seen[k] && guard <= nodes.len() {
            seen[k] = true;
            ring.points.push(nodes[k].p);
            ring.street.push(nodes[k].street);
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
    let mut pieces: Vec<Region> = outers
        .into_iter()
        .map(|outer| Region {
            outer,
            holes: Vec::new(),
        })
        .collect();
    for h in holes {
        let probe = h.points[0];
        let mut best: Option<(usize, f64)> = None;
        for (i, r) in pieces.iter().enumerate() {
            if locate_in_ring(&r.outer.points, probe) != PointLocation::Outside {
                let ar = r.outer.signed_area();
                if best.is_none_or(|(_, b)| ar < b) {
                    best = Some((i, ar));
                }
            }
        }
        match best {
            Some((i, _)) => pieces[i].holes.push(h),
            None => return vec![region.clone()],
        }
    }
    let total: f64 = pieces.iter().map(Region::area).sum();
    let area = region.area();
    if pieces.is_empty() || (total - area).abs() > 1e-9 * area.abs().max(tiny) {
        return vec![region.clone()];
    }
    pieces
}

/// Removes repeated consecutive points; the surviving edge keeps the tag of the edge that
/// has length.
fn dedup_ring(ring: &mut TaggedRing) {
    let mut points: Vec<DVec2> = Vec::with_capacity(ring.points.len());
    let mut street: Vec<bool> = Vec::with_capacity(ring.points.len());
    for (&p, &s) in ring.points.iter().zip(&ring.street) {
        if points.last() == Some(&p) {
            if let Some(l) = street.last_mut() {
                *l = s;
            }
            continue;
        }
        points.push(p);
        street.push(s);
    }
    while points.len() > 1 && points.first() == points.last() {
        points.pop();
        street.pop();
    }
    ring.points = points;
    ring.street = street;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn ring(p: &[(f64, f64)]) -> TaggedRing {
        TaggedRing {
            points: p.iter().map(|&(x, y)| v(x, y)).collect(),
            street: vec![true; p.len()],
        }
    }

    #[test]
    fn square_in_two() {
        let r = Region {
            outer: ring(&[(0., 0.), (4., 0.), (4., 4.), (0., 4.)]),
            holes: vec![],
        };
        let pieces = split_by_line(&r, v(1., -1.), v(1., 5.));
        assert_eq!(pieces.len(), 2);
        let mut areas: Vec<f64> = pieces.iter().map(Region::area).collect();
        areas.sort_by(f64::total_cmp);
        assert_eq!(areas, vec![4.0, 12.0]);
        for p in &pieces {
            assert_eq!(p.outer.street.iter().filter(|s| !**s).count(), 1);
        }
    }

    #[test]
    fn comb_into_many() {
        // A U shape cut across both prongs: three pieces.
        let r = Region {
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
        let pieces = split_by_line(&r, v(-1., 4.), v(7., 4.));
        assert_eq!(pieces.len(), 3);
        let total: f64 = pieces.iter().map(Region::area).sum();
        assert!((total - r.area()).abs() < 1e-12);
    }

    #[test]
    fn through_a_hole_and_past_one() {
        let mut h1 = ring(&[(2., 2.), (4., 2.), (4., 4.), (2., 4.)]);
        h1.points.reverse();
        let mut h2 = ring(&[(6., 6.), (8., 6.), (8., 8.), (6., 8.)]);
        h2.points.reverse();
        let r = Region {
            outer: ring(&[(0., 0.), (10., 0.), (10., 10.), (0., 10.)]),
            holes: vec![h1, h2],
        };
        let pieces = split_by_line(&r, v(3., -1.), v(3., 11.));
        assert_eq!(pieces.len(), 2);
        let total: f64 = pieces.iter().map(Region::area).sum();
        assert!((total - r.area()).abs() < 1e-12);
        assert_eq!(pieces.iter().map(|p| p.holes.len()).sum::<usize>(), 1);
    }

    #[test]
    fn line_through_vertices_and_along_edge() {
        let r = Region {
            outer: ring(&[(0., 0.), (4., 0.), (4., 4.), (0., 4.)]),
            holes: vec![],
        };
        let pieces = split_by_line(&r, v(0., 0.), v(4., 4.));
        assert_eq!(pieces.len(), 2);
        let pieces = split_by_line(&r, v(-1., 0.), v(5., 0.));
        let total: f64 = pieces.iter().map(Region::area).sum();
        assert!((total - 16.0).abs() < 1e-12);
        let pieces = split_by_line(&r, v(-1., 9.), v(5., 9.));
        assert_eq!(pieces.len(), 1);
    }
}
