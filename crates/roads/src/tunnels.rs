//! Tunnels (Parish & Müller §3.3): a flagged highway that crosses illegal *land* — a
//! park, or ground steeper than [`RoadParams::max_slope`](crate::RoadParams::max_slope) —
//! becomes "two tunnel entrances on both sides" at the geometry stage, as a highway over
//! water becomes a bridge.
//!
//! ## Algorithm
//!
//! The local constraints ([`DefaultConstraints`](crate::DefaultConstraints)) try, for a
//! highway segment whose first illegal sample is in a park or on a slope, in the paper's
//! order: prune, rotate (the highway goes round the park or along the slope where it
//! can), and only then a tunnel. [`tunnel_landing`] walks on along the segment's
//! direction from the first illegal sample, one legality step at a time, and takes the
//! first far portal `b` (one step past a legal sample, as bridges land) that opens onto
//! climbable ground (the next `slope_step_m` beyond it within the slope limit) and for
//! which [`tunnelable`]`(a, b)` holds:
//!
//! 1. `b` is legal ground (inside the map, no water, no park);
//! 2. every sample between lies on land — legal or park, not outside the map, and not
//!    water (a bridge's) unless [`RoadParams::tunnel_under_water`](crate::RoadParams::tunnel_under_water)
//!    lets highways cross water in tunnels instead of on bridges;
//! 3. the tunnel's own grade, a straight bore between the portals at the ground's height
//!    there, is within the slope limit;
//! 4. the ground above the bore is nowhere more than [`COVER_TOLERANCE_M`] below it: a
//!    tunnel runs *under* its hill or park. A valley (ground falling away under the
//!    chord) is no tunnel; the highway is refused there. (Not tested under water.)
//!
//! The walk stops at [`RoadParams::max_tunnel_length_m`](crate::RoadParams::max_tunnel_length_m)
//! (the whole segment, portal to portal) or at water or the map edge: such a highway is
//! refused (no road), as one over water wider than the bridge limit is.
//!
//! The segment is inserted as one edge flagged [`Road::tunnel`](crate::Road::tunnel).
//! No road may join or cross it between its portals: the self-sensitive snap refuses
//! a crossing or extension onto a tunnel edge (a road above it on the hill is not
//! connected to it), while its portals are ordinary junctions.
//!
//! [`portals`] lists both ends of every tunnel; [`portal_mesh`] builds a concrete frame
//! at each for a scene. A frame stands set back from its junction, just far enough that
//! it keeps clear of the junction's other roads and of other tunnels' frames there
//! ([`Portal::setback`]); the scene draws the road surface from the junction to the frame
//! (an open cut) and none between the frames.
//!
//! ## Guarantees
//!
//! * A tunnel is at most `max_tunnel_length_m` long, both its ends are legal ground, no
//!   sample along it is outside the map (nor water, unless `tunnel_under_water`), its
//!   grade is within `max_slope`.
//! * A tunnel is never a bridge (`bridge` and `tunnel` are never both set).
//! * With `max_tunnel_length_m = 0`, or on maps without parks and slopes over the
//!   limit, the network is the same as without tunnels (tunnels are tried only where
//!   the highway would otherwise have been refused).
//!
//! ## Limitations
//!
//! * The bore is a straight chord between the portals at ground height; its depth under
//!   a flat park is not modelled (cut and cover), nor is the inside of the tunnel drawn.
//! * Only highways tunnel (as only highways bridge). Water is bridged unless
//!   `tunnel_under_water` is set, and then always tunnelled (no choice per crossing).
//! * The facade's cell stage leaves tunnels out (`polis_cells::extract_where`): the land
//!   above a tunnel is one block, whose lots keep out of the portals' mouths only. In the
//!   Citygen mode, though, the primary network's city cells are still bounded by its
//!   tunnels, so that Kelly's secondary growth (`secondary`), which knows nothing of
//!   grade separation, never crosses one.
//!
//! ## References
//!
//! * Y. I. H. Parish, P. Müller, *Procedural Modeling of Cities*, SIGGRAPH 2001, §3.3.

use polis_geom::measure::segment_distance;
use polis_geom::mesh::Mesh;
use polis_geom::{DVec2, EdgeId, Field, NodeId, Polygon, PolygonWithHoles};

use crate::error::Result;
use crate::legality::{Illegal, Legality};
use crate::network::RoadNetwork;

/// How far the ground above a tunnel may lie below its bore (a straight line between the
/// portals at the ground's height there), metres. Deeper dips make the crossing a valley,
/// not a hill: no tunnel.
pub const COVER_TOLERANCE_M: f64 = 1.0;

/// Clear height of a portal above the road, metres.
pub const PORTAL_CLEARANCE_M: f64 = 5.5;
/// Height of a portal's lintel above its clearance, metres.
pub const PORTAL_LINTEL_M: f64 = 1.5;
/// Thickness of a portal's frame (along the road) and width of its side walls, metres.
pub const PORTAL_WALL_M: f64 = 1.0;
/// How far a portal's walls reach into the ground below the road, metres.
const PORTAL_FOOT_M: f64 = 1.0;
/// Step of the search for a portal's setback ([`Portal::setback`]), metres.
const SETBACK_STEP_M: f64 = 0.25;

/// Whether the straight piece `a–b` may be a tunnel: `b` on legal ground, every sample
/// (every `legality_step_m`) on land (legal or park, not outside the map; water only
/// when `under_water`), the grade between the ends within the slope limit and the ground
/// nowhere more than [`COVER_TOLERANCE_M`] below the straight bore (not tested under
/// water, whose bed the elevation map need not hold).
pub fn tunnelable(legality: &Legality, a: DVec2, b: DVec2, under_water: bool) -> bool {
    let len = a.distance(b);
    if !(len.is_finite() && len > 0.0) || legality.point(b).is_some() {
        return false;
    }
    let (ha, hb) = (legality.elevation(a), legality.elevation(b));
    if !(ha.is_finite() && hb.is_finite()) || (hb - ha).abs() > legality.max_slope() * len {
        return false;
    }
    let n = ((len / legality.step()).ceil() as usize).clamp(1, 1_000_000);
    (1..n).all(|i| {
        let t = i as f64 / n as f64;
        let p = a + (b - a) * t;
        match legality.point(p) {
            None | Some(Illegal::Park) => {
                let ground = legality.elevation(p);
                ground.is_finite() && ground >= ha + (hb - ha) * t - COVER_TOLERANCE_M
            }
            Some(Illegal::Water) => under_water,
            Some(Illegal::Outside | Illegal::Slope) => false,
        }
    })
}

/// The far portal of a tunnel for a highway leaving `a` in the unit direction `d`, whose
/// first illegal sample (a park or a slope) lies `s0` metres along: the nearest `b` one
/// legality step past a legal sample with [`tunnelable`]`(a, b)` and climbable ground
/// for [`RoadParams::slope_step_m`](crate::RoadParams::slope_step_m) beyond, at most `max_len`
/// metres from `a`. `None` when there is none (the crossing is too long, reaches water
/// or the map edge, or is a valley). Water ends the search unless `under_water`.
pub fn tunnel_landing(
    legality: &Legality,
    a: DVec2,
    d: DVec2,
    s0: f64,
    max_len: f64,
    under_water: bool,
) -> Option<DVec2> {
    let step = legality.step();
    if !(max_len > 0.0 && step > 0.0 && s0.is_finite()) {
        return None;
    }
    let mut s = s0;
    while s + step <= max_len {
        s += step;
        match legality.point(a + d * s) {
            Some(Illegal::Outside) => return None,
            Some(Illegal::Water) if !under_water => return None,
            Some(Illegal::Water | Illegal::Park | Illegal::Slope) => {}
            None => {
                let b = a + d * (s + step).min(max_len);
                // The portal opens onto ground a road can climb, not onto the hill's flank.
                let ahead = legality.segment(b, b + d * legality.slope_step());
                let flank = ahead.is_some_and(|v| v.what == Illegal::Slope);
                if !flank && tunnelable(legality, a, b, under_water) {
                    return Some(b);
                }
            }
        }
    }
    None
}

/// One end of a tunnel: where the road enters the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Portal {
    /// The junction at the portal.
    pub node: NodeId,
    /// The tunnel edge.
    pub edge: EdgeId,
    /// The portal's position (the junction's), metres.
    pub position: DVec2,
    /// Unit direction from the portal into the tunnel.
    pub into: DVec2,
    /// Carriageway width of the tunnel, metres.
    pub width: f64,
    /// How far along the tunnel from the junction its frame stands, metres: the least
    /// (in steps of a quarter metre) at which the frame's footprint keeps clear of every
    /// other road's corridor at the junction (its centre line ± half its width; for
    /// another tunnel, ± half its width and a wall, so two frames never overlap), at most
    /// half the tunnel's length less a wall. 0 at a junction with no other road. The road
    /// surface runs on from the junction to the frame (an open cut).
    pub setback: f64,
}

impl Portal {
    /// Where the frame's face stands: `position + into · setback`.
    pub fn face(&self) -> DVec2 {
        self.position + self.into * self.setback
    }

    /// The frame's footprint (walls and lintel): a rectangle across the road, one wall
    /// thick, from the face into the tunnel, as its four corners.
    pub fn footprint(&self) -> [DVec2; 4] {
        let reach = self.into.perp() * (0.5 * self.width + PORTAL_WALL_M);
        let (near, far) = (self.face(), self.face() + self.into * PORTAL_WALL_M);
        [near - reach, near + reach, far + reach, far - reach]
    }
}

/// Both portals of every tunnel edge of `network`, in edge order (the start end first).
/// An end where only tunnel edges meet, two of them, is inside one tunnel (an edge split
/// by a later insertion) and has no portal.
///
/// # Errors
/// A corrupt graph (an edge whose end is missing).
pub fn portals(network: &RoadNetwork) -> Result<Vec<Portal>> {
    let mut out = Vec::new();
    for (e, u, v, road) in network.edges() {
        if !road.tunnel {
            continue;
        }
        let (pu, pv) = network.segment(e)?;
        for (n, p, q) in [(u, pu, pv), (v, pv, pu)] {
            let edges = network.edges_at(n)?;
            let inside = edges.len() == 2
                && edges
                    .iter()
                    .all(|&f| network.edge_payload(f).is_ok_and(|r| r.tunnel));
            let len = p.distance(q);
            if inside || len <= 0.0 {
                continue;
            }
            let mut portal = Portal {
                node: n,
                edge: e,
                position: p,
                into: (q - p) / len,
                width: road.width,
                setback: 0.0,
            };
            portal.setback = setback(network, &portal, len)?;
            out.push(portal);
        }
    }
    Ok(out)
}

/// The least setback (a multiple of [`SETBACK_STEP_M`]) at which `portal`'s footprint
/// is farther than each other road at its junction from that road's centre line than half
/// its width (another tunnel: half its width and a wall), capped at half the tunnel's
/// length `len` less a wall.
fn setback(network: &RoadNetwork, portal: &Portal, len: f64) -> Result<f64> {
    let mut others = Vec::new();
    for &f in network.edges_at(portal.node)? {
        if f == portal.edge {
            continue;
        }
        let (a, b) = network.segment(f)?;
        let road = network.edge_payload(f)?;
        let reach = 0.5 * road.width + if road.tunnel { PORTAL_WALL_M } else { 0.0 };
        others.push((a, b, reach));
    }
    let cap = (0.5 * len - PORTAL_WALL_M).max(0.0);
    let clear = |setback: f64| {
        let q = Portal { setback, ..*portal }.footprint();
        others.iter().all(|&(a, b, reach)| {
            (0..4).all(|i| segment_distance(q[i], q[(i + 1) % 4], a, b) > reach)
        })
    };
    let steps = (cap / SETBACK_STEP_M).floor() as usize;
    Ok((0..=steps)
        .map(|i| i as f64 * SETBACK_STEP_M)
        .find(|&s| clear(s))
        .unwrap_or(cap))
}

/// A concrete frame at every portal of `network` as closed solids: two side walls
/// ([`PORTAL_WALL_M`] wide) beside the carriageway and a lintel over it at
/// [`PORTAL_CLEARANCE_M`], [`PORTAL_WALL_M`] thick along the road, standing on `ground`
/// at the portal's face ([`Portal::face`], set back from the junction clear of its other
/// roads; reaching a metre into the ground). `None` when there is no tunnel.
///
/// # Errors
/// A corrupt graph; the mesh builder's errors.
pub fn portal_mesh(network: &RoadNetwork, ground: &dyn Field) -> Result<Option<Mesh>> {
    let mut mesh = Mesh::new(None);
    for p in portals(network)? {
        let face = p.face();
        let h = ground.sample(face);
        if !(h.is_finite() && p.width > 0.0) {
            continue;
        }
        let side = p.into.perp();
        let half = 0.5 * p.width;
        // A quad from `lo` to `hi` across the road (signed offsets), one wall thick.
        let quad = |lo: f64, hi: f64| {
            let (a, b) = (face + side * lo, face + side * hi);
            let mut poly = PolygonWithHoles::new(
                Polygon::new(vec![
                    a,
                    b,
                    b + p.into * PORTAL_WALL_M,
                    a + p.into * PORTAL_WALL_M,
                ]),
                vec![],
            );
            poly.normalize();
            poly
        };
        let top = h + PORTAL_CLEARANCE_M;
        mesh.add_prism(&quad(-half - PORTAL_WALL_M, -half), h - PORTAL_FOOT_M, top)?;
        mesh.add_prism(&quad(half, half + PORTAL_WALL_M), h - PORTAL_FOOT_M, top)?;
        mesh.add_prism(
            &quad(-half - PORTAL_WALL_M, half + PORTAL_WALL_M),
            top,
            top + PORTAL_LINTEL_M,
        )?;
    }
    Ok((!mesh.is_empty()).then_some(mesh))
}
