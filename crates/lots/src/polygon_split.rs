//! Splitting a region (outer ring plus holes) by an infinite line into *all* its pieces,
//! with street access tracked on every edge.
//!
//! The geometry is [`polis_geom::lines::split_by_line`] (Kelly 2008 §4.4.2.3: crossings
//! sorted along the line, paired by the Jordan curve rule, bridged); this module keeps the
//! lots' own [`Region`] / [`TaggedRing`] types, whose per-edge tag is street access. Every
//! edge keeps its flag through the split; the bridge edges get `false`. If the pieces'
//! areas do not add up to the region's, the region is returned whole, so a split never
//! loses land.

use polis_geom::DVec2;
use polis_geom::lines::{TaggedRegion, TaggedRing as GeomRing};
use polis_geom::polygon::ring_signed_area;

/// A ring with a tag per edge: `street[i]` belongs to edge `points[i] → points[i + 1]`.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
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
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
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

/// Splits `region` by the infinite line through `a` and `b` (`a != b`) into all of its
/// pieces, each a region with its own holes. Returns the region unchanged (one piece) if
/// the line misses it or the split would be inconsistent.
pub fn split_by_line(region: &Region, a: DVec2, b: DVec2) -> Vec<Region> {
    let to_geom = |r: &TaggedRing| GeomRing {
        points: r.points.clone(),
        tags: r.street.clone(),
    };
    let from_geom = |r: GeomRing<bool>| TaggedRing {
        points: r.points,
        street: r.tags,
    };
    let geom = TaggedRegion {
        outer: to_geom(&region.outer),
        holes: region.holes.iter().map(to_geom).collect(),
    };
    polis_geom::lines::split_by_line(&geom, a, b, false)
        .into_iter()
        .map(|piece| Region {
            outer: from_geom(piece.outer),
            holes: piece.holes.into_iter().map(from_geom).collect(),
        })
        .collect()
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

    // The geometry is tested in `polis_geom::lines`; these check that street flags and
    // holes go through the conversion.
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
    fn holes_and_flags_survive() {
        let mut hole = ring(&[(2., 2.), (4., 2.), (4., 4.), (2., 4.)]);
        hole.points.reverse();
        hole.street = vec![false, true, false, false];
        let r = Region {
            outer: ring(&[(0., 0.), (10., 0.), (10., 10.), (0., 10.)]),
            holes: vec![hole],
        };
        let pieces = split_by_line(&r, v(7., -1.), v(7., 11.));
        assert_eq!(pieces.len(), 2);
        let with_hole: Vec<&Region> = pieces.iter().filter(|p| !p.holes.is_empty()).collect();
        assert_eq!(with_hole.len(), 1);
        assert_eq!(
            with_hole[0].holes[0].street,
            vec![false, true, false, false]
        );
        assert!((pieces.iter().map(Region::area).sum::<f64>() - r.area()).abs() < 1e-12);
    }
}
