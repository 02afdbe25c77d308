//! The geometric checks behind validity checking (Kelly §5.3.2): node placement, contacts
//! between new paths (sweep), angles at junctions.

use polis_geom::DVec2;
use polis_geom::predicates::{SegmentIntersection, segment_intersection};

use crate::primary::error::PrimaryError;
use crate::primary::network::RoadId;
use crate::primary::terrain::Terrain;

/// Checks that a node may stand at `p`: finite, inside the map, on legal ground.
pub(crate) fn check_site(
    p: DVec2,
    what: &'static str,
    terrain: &Terrain,
) -> Result<(), PrimaryError> {
    if !(p.is_finite() && p.abs().max_element() <= polis_geom::MAX_COORDINATE) {
        return Err(PrimaryError::BadCoordinate { what, point: p });
    }
    if !terrain.bounds().contains(p) {
        return Err(PrimaryError::OutsideMap { point: p });
    }
    match terrain.point(p) {
        None => {}
        Some(crate::legality::Illegal::Outside) => {
            return Err(PrimaryError::OutsideMap { point: p });
        }
        Some(what) => return Err(PrimaryError::IllegalNode { point: p, what }),
    }
    if !terrain.elevation(p).is_finite() {
        return Err(PrimaryError::OutsideMap { point: p });
    }
    Ok(())
}

/// The angle between the directions `o → p` and `o → q`, in degrees, `[0, 180]`.
pub(crate) fn angle_deg(o: DVec2, p: DVec2, q: DVec2) -> f64 {
    let (u, v) = (p - o, q - o);
    u.perp_dot(v).abs().atan2(u.dot(v)).to_degrees()
}

/// The acute angle between the lines of two segments, in degrees, `[0, 90]`.
pub(crate) fn crossing_angle_deg(a0: DVec2, a1: DVec2, b0: DVec2, b1: DVec2) -> f64 {
    let (u, v) = (a1 - a0, b1 - b0);
    let a = u.perp_dot(v).abs().atan2(u.dot(v)).to_degrees();
    a.min(180.0 - a)
}

/// A contact found by [`first_contact`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Contact {
    /// First path's road and segment.
    pub a: (RoadId, usize),
    /// Second path's road and segment.
    pub b: (RoadId, usize),
    /// How they meet.
    pub kind: SegmentIntersection,
}

impl Contact {
    /// A point of the contact.
    pub fn point(&self) -> DVec2 {
        match self.kind {
            SegmentIntersection::Crossing { point, .. }
            | SegmentIntersection::Touching { point, .. } => point,
            SegmentIntersection::Overlap { start, .. } => start,
            SegmentIntersection::Disjoint => DVec2::NAN,
        }
    }
}

/// The first contact (in sweep order) between segments of `paths` that `allowed` does not
/// excuse. Neighbouring segments of one path touching at their common vertex are always
/// excused. A sort-and-sweep along the x axis: `O(n log n + pairs whose x ranges meet)`.
pub(crate) fn first_contact(
    paths: &[(RoadId, &[DVec2])],
    mut allowed: impl FnMut(&Contact) -> bool,
) -> Option<Contact> {
    // (min x, max x, path, segment)
    let mut segs: Vec<(f64, f64, usize, usize)> = Vec::new();
    for (pi, (_, pts)) in paths.iter().enumerate() {
        for (k, w) in pts.windows(2).enumerate() {
            segs.push((w[0].x.min(w[1].x), w[0].x.max(w[1].x), pi, k));
        }
    }
    segs.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)).then(x.3.cmp(&y.3)));
    for i in 0..segs.len() {
        let (_, hi, pi, k) = segs[i];
        let (a0, a1) = (paths[pi].1[k], paths[pi].1[k + 1]);
        let (ylo, yhi) = (a0.y.min(a1.y), a0.y.max(a1.y));
        for &(lo2, _, pj, j) in &segs[i + 1..] {
            if lo2 > hi {
                break;
            }
            let (b0, b1) = (paths[pj].1[j], paths[pj].1[j + 1]);
            if b0.y.max(b1.y) < ylo || b0.y.min(b1.y) > yhi {
                continue;
            }
            let kind = segment_intersection(a0, a1, b0, b1);
            if !kind.intersects() {
                continue;
            }
            if pi == pj && k.abs_diff(j) == 1 {
                let common = if j == k + 1 { a1 } else { a0 };
                if matches!(kind, SegmentIntersection::Touching { point, .. } if point == common) {
                    continue;
                }
            }
            let c = Contact {
                a: (paths[pi].0, k),
                b: (paths[pj].0, j),
                kind,
            };
            if !allowed(&c) {
                return Some(c);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweep_finds_crossings_and_excuses_neighbours() {
        let zig = [
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(5.0, -5.0),
        ];
        let c = first_contact(&[(RoadId(1), &zig)], |_| false).unwrap();
        assert_eq!(c.a.0, RoadId(1));
        assert!((c.point() - DVec2::new(20.0 / 3.0, 0.0)).length() < 1e-9);
        let line = [
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(20.0, 0.0),
        ];
        assert!(first_contact(&[(RoadId(1), &line)], |_| false).is_none());
        let other = [DVec2::new(20.0, 0.0), DVec2::new(20.0, 10.0)];
        let touch = first_contact(&[(RoadId(1), &line), (RoadId(2), &other)], |_| false).unwrap();
        assert!(matches!(touch.kind, SegmentIntersection::Touching { .. }));
        assert!(
            first_contact(&[(RoadId(1), &line), (RoadId(2), &other)], |c| c.point()
                == DVec2::new(20.0, 0.0))
            .is_none()
        );
        assert!((angle_deg(DVec2::ZERO, DVec2::X, DVec2::Y) - 90.0).abs() < 1e-12);
        assert!(
            (crossing_angle_deg(DVec2::ZERO, DVec2::X, DVec2::ZERO, DVec2::new(-1.0, 0.1)) - 5.71)
                .abs()
                < 0.01
        );
    }
}
