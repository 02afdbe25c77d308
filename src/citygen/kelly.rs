//! Kelly primary networks (issue 17) as a [`PrimarySource`](super::PrimarySource): the
//! inline serde form, files (saved network, hand-written spec, GeoJSON), and the
//! conversion of the low-level graph into the Citygen mode's primary road graph.

use polis_geom::DVec2;
use polis_roads::RoadNetwork;
use polis_roads::primary::{EditOptions, PrimaryNetwork, PrimarySpec, Terrain};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::stages::StageContext;

/// A [`PrimaryNetwork`] inside a configuration: serde as the network itself; equal when
/// the serialised networks are equal (the network has no `PartialEq` of its own).
#[derive(Debug, Clone, Default, Serialize)]
#[serde(transparent)]
pub struct InlinePrimary(pub Box<PrimaryNetwork>);

impl<'de> Deserialize<'de> for InlinePrimary {
    /// Through JSON text: inside the internally tagged [`PrimarySource`](super::PrimarySource), serde buffers
    /// the network, and the buffer cannot read the network's integer map keys (JSON
    /// strings) back; its own JSON reader can. Every invariant is checked.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let value = serde_json::Value::deserialize(d)?;
        PrimaryNetwork::from_json(&value.to_string())
            .map(|n| InlinePrimary(Box::new(n)))
            .map_err(serde::de::Error::custom)
    }
}

impl PartialEq for InlinePrimary {
    fn eq(&self, other: &Self) -> bool {
        match (self.0.to_json(), other.0.to_json()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        }
    }
}

/// The low-level graph of a Kelly primary network ([`PrimaryNetwork::to_road_network`]),
/// as the primary road graph, each chain of path vertices between control nodes (and
/// bridge changes) simplified by Douglas–Peucker within [`PATH_TOLERANCE_M`]: a path
/// sampled every few metres would otherwise give its cells sides of a few metres, too
/// short for Kelly's growth to start on (it starts at the longest sides).
///
/// Returns the graph and, per edge index, the id of the primary road it lies on.
///
/// Limitations: the simplified path may move up to the tolerance off the plotted one; a
/// simplification that would break planarity is a geometry error.
pub(super) fn low_level(net: &PrimaryNetwork) -> Result<(RoadNetwork, Vec<Option<u64>>)> {
    let g = net
        .to_road_network()
        .map_err(polis_roads::RoadError::from)?;
    let gn = &g.network;
    let mut out = RoadNetwork::new();
    let mut road_of: Vec<Option<u64>> = Vec::new();
    let mut ids = vec![None; gn.node_bound()];
    let keep = |n: polis_geom::NodeId| -> Result<bool> {
        if g.control_of(n).is_some() {
            return Ok(true);
        }
        let edges = gn.edges_at(n)?;
        let [e, f] = edges[..] else {
            return Ok(true);
        };
        Ok(gn.edge_payload(e)?.bridge != gn.edge_payload(f)?.bridge)
    };
    let mut done = vec![false; gn.edge_bound()];
    for (e0, a0, b0, road) in gn.edges() {
        if done.get(e0.index()).copied().unwrap_or(true) {
            continue;
        }
        if let Some(d) = done.get_mut(e0.index()) {
            *d = true;
        }
        // The chain through e0, from kept node to kept node.
        let mut halves = [vec![a0], vec![b0]];
        for (side, from) in [(0, b0), (1, a0)] {
            let mut prev = from;
            let mut at = halves[side][0];
            while !keep(at)? {
                let edges = gn.edges_at(at)?;
                let Some(&next) = edges
                    .iter()
                    .find(|&&x| gn.endpoints(x).is_ok_and(|(p, q)| p != prev && q != prev))
                else {
                    break;
                };
                if let Some(d) = done.get_mut(next.index()) {
                    *d = true;
                }
                let (p, q) = gn.endpoints(next)?;
                prev = at;
                at = if p == at { q } else { p };
                halves[side].push(at);
            }
        }
        let [mut chain, tail] = halves;
        chain.reverse();
        chain.extend(tail);
        let pts = chain
            .iter()
            .map(|&n| gn.position(n))
            .collect::<std::result::Result<Vec<_>, _>>()?;
        let mut kept = vec![false; pts.len()];
        douglas_peucker(&pts, 0, pts.len() - 1, &mut kept);
        let mut prev: Option<polis_geom::NodeId> = None;
        for (k, &n) in chain.iter().enumerate() {
            if !kept[k] {
                continue;
            }
            let m = match ids.get(n.index()) {
                Some(Some(m)) => *m,
                _ => {
                    let m = out.add_node(pts[k], *gn.node_payload(n)?)?;
                    if let Some(slot) = ids.get_mut(n.index()) {
                        *slot = Some(m);
                    }
                    m
                }
            };
            if let Some(p) = prev {
                let e = out.add_edge(p, m, *road)?;
                if road_of.len() <= e.index() {
                    road_of.resize(e.index() + 1, None);
                }
                road_of[e.index()] = g.road_of(e0).map(|r| r.0);
            }
            prev = Some(m);
        }
    }
    out.check_invariants()?;
    road_of.resize(out.edge_bound(), None);
    Ok((out, road_of))
}

/// How far a simplified Kelly path may leave its plotted path, metres.
pub const PATH_TOLERANCE_M: f64 = 0.5;

/// Marks the points of `pts[i..=j]` Douglas–Peucker keeps (the ends always).
fn douglas_peucker(pts: &[DVec2], i: usize, j: usize, kept: &mut [bool]) {
    kept[i] = true;
    kept[j] = true;
    if j <= i + 1 {
        return;
    }
    let (a, b) = (pts[i], pts[j]);
    let far = (i + 1..j)
        .map(|k| (k, polis_geom::predicates::distance_to_segment(pts[k], a, b)))
        .max_by(|x, y| x.1.total_cmp(&y.1));
    if let Some((k, d)) = far
        && d > PATH_TOLERANCE_M
    {
        douglas_peucker(pts, i, k, kept);
        douglas_peucker(pts, k, j, kept);
    }
}

/// A Kelly primary network from a file's text: GeoJSON (a `features` member), its serde
/// form (`next_node`), or a [`PrimarySpec`].
pub(super) fn kelly_from_text(
    cx: &StageContext<'_>,
    text: &str,
    path: &std::path::Path,
) -> Result<PrimaryNetwork> {
    let parse = |e: polis_roads::primary::PrimaryError| Error::Parse {
        source_name: path.display().to_string(),
        message: e.to_string(),
    };
    let value: serde_json::Value = serde_json::from_str(text).map_err(|e| Error::Parse {
        source_name: path.display().to_string(),
        message: e.to_string(),
    })?;
    if value.get("next_node").is_some() {
        return PrimaryNetwork::from_json(text).map_err(parse);
    }
    let h = cx.config.size_m * 0.5;
    let bounds = polis_geom::Aabb2::new(DVec2::splat(-h), DVec2::splat(h));
    let terrain = Terrain::new(&cx.maps.inputs, bounds).map_err(parse)?;
    let editor = if value.get("features").is_some() {
        PrimaryNetwork::from_geojson(text, terrain, EditOptions::default())
    } else {
        PrimarySpec::from_json(text).and_then(|s| s.build(terrain, EditOptions::default()))
    }
    .map_err(parse)?;
    Ok(editor.into_network())
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::hash::splitmix64;

    /// Douglas–Peucker keeps both ends, and every dropped point lies within the tolerance
    /// of the kept segment spanning it: 300 random wiggly polylines (splitmix64 stream).
    #[test]
    fn simplification_keeps_ends_and_stays_within_the_tolerance() {
        let mut h = 0x5EED_u64;
        let mut next = || {
            h = splitmix64(h);
            (h >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..300 {
            let n = 2 + (next() * 38.0) as usize;
            let amp = 4.0 * next();
            let pts: Vec<DVec2> = (0..n)
                .map(|i| DVec2::new(i as f64 * 7.0, amp * (next() - 0.5)))
                .collect();
            let mut kept = vec![false; n];
            douglas_peucker(&pts, 0, n - 1, &mut kept);
            assert!(kept[0] && kept[n - 1]);
            let idx: Vec<usize> = (0..n).filter(|&k| kept[k]).collect();
            for w in idx.windows(2) {
                for k in w[0] + 1..w[1] {
                    let d =
                        polis_geom::predicates::distance_to_segment(pts[k], pts[w[0]], pts[w[1]]);
                    assert!(d <= PATH_TOLERANCE_M + 1e-9, "{d}");
                }
            }
        }
    }
}
