//! Streets that bow between their ends: the optional last pass of a cell's growth
//! ([`SecondaryParams::bow`]).
//!
//! Kelly's growth places straight segments, so a street between two junctions is a
//! straight line, and a grid neighbourhood's streets have a circuity (length over the
//! straight distance between their ends) of 1.003 where real US grids have 1.012–1.041
//! (Boeing 2019). Kelly curves his primary roads along the terrain (§4.2) and lets the
//! secondary growth meander through the degree deviance (§6.3), which bends a network at
//! its nodes but never a street between two of them. This pass bends each street
//! (secondary edge) of a grown cell into a half-sine bow through its two ends: the
//! offset from the chord at a fraction `t` of the way is `s · sin(π t)`, `s` the sagitta,
//! drawn per street as `bow · chord` (with the bow's deviance) and a random side. A bow
//! of `r = s / chord` lengthens the street by about `π² r² / 4` drawn finely (r = 0.1:
//! 2.5 %) and `2 r²` as two pieces bent at the middle (2 %), and turns its ends by
//! `atan(π r)` (17°) or `atan(2 r)` (11°). The bow is drawn as a chain of straight pieces joined
//! at new junctions of degree 2, so every later stage reads it as it reads any road; the
//! street statistics merge the chain back into one street between the same junctions
//! (its bearing unchanged). The pieces are as few as keep the chain within
//! [`TOLERANCE_M`] of the curve (`π² s / 8 n²` for `n` pieces), but none shorter than
//! [`MIN_PIECE_M`] where the street is long enough for two, and at least two: a street
//! shorter than three times that bends once, at its middle. Kelly's lot subdivision
//! cuts a block's lots along one street edge at a time (the longest), so a frontage of
//! short pieces gives fewer and wider lots: `citygen_us` seed 2 has 9,630 lots with
//! straight streets, 6,114 with pieces of 10 m or more, 8,197 with 30 m, 9,067 with
//! 50 m.
//!
//! A bow is kept only when the graph stays planar and clear: each piece stays at least
//! the street's width from every road it did not touch before (or no nearer than the
//! straight street was), every piece is legal on the maps (water, parks), and at each
//! end the street turns by less than half the angle to its neighbours on that side, so
//! the order of roads around a junction is kept and two bowed neighbours cannot meet.
//! Otherwise half the sagitta is tried, then the street stays straight. The draws (two
//! per street, in edge-id order) come from their own generator, so the growth itself is
//! drawn exactly as without the pass; a bow of 0 skips the pass and leaves the cell
//! bit for bit as Kelly's growth made it.

use polis_geom::measure::segment_distance;
use polis_geom::{Aabb2, DVec2, EdgeId, NodeId};
use rand::{Rng, RngExt};

use super::cell::CellMaps;
use super::error::SecondaryError;
use super::params::SecondaryParams;
use crate::network::{Junction, RoadClass, RoadNetwork};

/// How far the chain of pieces that draws a bowed street may stray from the curve,
/// metres.
pub const TOLERANCE_M: f64 = 0.25;

/// The shortest piece of a bowed street, metres, where the street is at least twice
/// as long (a shorter street is drawn with two pieces, bent at its middle).
pub const MIN_PIECE_M: f64 = 50.0;

/// Most pieces of a bowed street.
pub const MAX_PIECES: usize = 24;

/// Sagittas below this many metres leave the street straight.
const MIN_SAGITTA_M: f64 = 0.05;

/// Bows the street edges of `g` (see the [module docs](self)); returns how many were
/// bowed. Does nothing when `p.bow.value` is 0.
///
/// # Errors
/// [`SecondaryError::Geometry`] on an internal graph failure.
pub(super) fn bow_streets<R: Rng + ?Sized>(
    g: &mut RoadNetwork,
    p: &SecondaryParams,
    maps: &CellMaps<'_>,
    rng: &mut R,
) -> Result<u32, SecondaryError> {
    if p.bow.value <= 0.0 {
        return Ok(0);
    }
    let streets: Vec<EdgeId> = g
        .edges()
        .filter(|(_, _, _, r)| r.class == RoadClass::Street)
        .map(|(e, _, _, _)| e)
        .collect();
    let mut bowed = 0;
    let mut points: Vec<DVec2> = Vec::new();
    for e in streets {
        // Two draws per street whatever happens to it.
        let r = p.bow.sample(rng).max(0.0);
        let side = if rng.random::<f64>() < 0.5 { -1.0 } else { 1.0 };
        let (u, v) = g.endpoints(e)?;
        let (a, b) = (g.position(u)?, g.position(v)?);
        let chord = a.distance(b);
        for sagitta in [r * chord * side, 0.5 * r * chord * side] {
            if sagitta.abs() < MIN_SAGITTA_M {
                break;
            }
            bow_points(a, b, sagitta, &mut points);
            if fits(g, e, (u, v), (a, b), &points, maps)? {
                replace(g, e, &points)?;
                bowed += 1;
                break;
            }
        }
    }
    Ok(bowed)
}

/// The chain from `a` to `b` bowed by `sagitta` (positive: to the left of `a → b`).
fn bow_points(a: DVec2, b: DVec2, sagitta: f64, out: &mut Vec<DVec2>) {
    out.clear();
    let d = b - a;
    let chord = d.length();
    // A piece of length c / n across curvature π² s / c² strays (c / n)² · π² s / 8c².
    let n = (std::f64::consts::PI * (sagitta.abs() / (8.0 * TOLERANCE_M)).sqrt()).ceil();
    let longest = ((chord / MIN_PIECE_M).floor() as usize).clamp(2, MAX_PIECES);
    let n = (n as usize).clamp(2, longest);
    let left = d.perp() / chord;
    out.push(a);
    for i in 1..n {
        let t = i as f64 / n as f64;
        out.push(a + d * t + left * (sagitta * (std::f64::consts::PI * t).sin()));
    }
    out.push(b);
}

/// Whether the chain `pts` can replace street `e` between `ends` (at `at`; see the
/// module docs).
fn fits(
    g: &RoadNetwork,
    e: EdgeId,
    (u, v): (NodeId, NodeId),
    (a, b): (DVec2, DVec2),
    pts: &[DVec2],
    maps: &CellMaps<'_>,
) -> Result<bool, SecondaryError> {
    let clearance = g.edge_payload(e)?.width.max(0.0);
    let (Some(&first), Some(&last)) = (pts.get(1), pts.get(pts.len().saturating_sub(2))) else {
        return Ok(false);
    };
    if !keeps_order(g, e, u, b - a, first - a)? || !keeps_order(g, e, v, a - b, last - b)? {
        return Ok(false);
    }
    let pieces = pts.len() - 1;
    for (i, w) in pts.windows(2).enumerate() {
        let (p0, p1) = (w[0], w[1]);
        if !maps.segment_legal(p0, p1) {
            return Ok(false);
        }
        let near = Aabb2::new(p0, p1).expanded(clearance + 1e-6);
        for f in g.edges_in_box(&near) {
            if f == e {
                continue;
            }
            let (fu, fv) = g.endpoints(f)?;
            let at_u = fu == u || fv == u;
            let at_v = fu == v || fv == v;
            // The end pieces meet their neighbours at the junction: the order test
            // above keeps them apart.
            if (i == 0 && at_u) || (i + 1 == pieces && at_v) {
                continue;
            }
            let (fa, fb) = g.segment(f)?;
            let bent = segment_distance(p0, p1, fa, fb);
            let straight = segment_distance(a, b, fa, fb);
            if bent <= 0.0 || bent < clearance.min(straight) {
                return Ok(false);
            }
        }
    }
    Ok(true)
}

/// Whether turning street `e`'s direction at node `n` from `old` to `new` keeps it
/// within half the angle to each neighbour on the side it turns to.
fn keeps_order(
    g: &RoadNetwork,
    e: EdgeId,
    n: NodeId,
    old: DVec2,
    new: DVec2,
) -> Result<bool, SecondaryError> {
    let turn = signed_angle(old, new);
    let here = g.position(n)?;
    for &f in g.edges_at(n)? {
        if f == e {
            continue;
        }
        let far = g.position(g.other_end(f, n)?)?;
        let to = signed_angle(old, far - here);
        if to * turn > 0.0 && turn.abs() >= 0.5 * to.abs() {
            return Ok(false);
        }
    }
    Ok(true)
}

/// The angle from `a` to `b`, radians in `(−π, π]`.
fn signed_angle(a: DVec2, b: DVec2) -> f64 {
    a.perp_dot(b).atan2(a.dot(b))
}

/// Replaces street `e` by the chain `pts` (its ends are `e`'s), each piece with `e`'s
/// road.
fn replace(g: &mut RoadNetwork, e: EdgeId, pts: &[DVec2]) -> Result<(), SecondaryError> {
    let (u, v) = g.endpoints(e)?;
    let road = g.remove_edge(e)?;
    let mut prev = u;
    for &q in pts.iter().skip(1).take(pts.len().saturating_sub(2)) {
        let n = g.add_node(q, Junction::default())?;
        g.add_edge(prev, n, road)?;
        prev = n;
    }
    g.add_edge(prev, v, road)?;
    Ok(())
}
