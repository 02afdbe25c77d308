//! Street statistics of a cell's secondary network (the measures the presets are tested
//! against).

use serde::{Deserialize, Serialize};

use crate::network::{RoadClass, RoadNetwork};

/// Junction counts of the secondary roads of one or more cells.
///
/// A *junction* is a node with at least one secondary (street) road, except interior
/// nodes of degree 2, which only bend a street (street-network statistics simplify them
/// away, as OSMnx does); it is a *boundary* junction when it also has a primary road (the
/// cell boundary or a filament). The shares are over junctions.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct StreetStats {
    /// Junctions (interior degree-2 nodes not counted).
    pub junctions: usize,
    /// Junctions on the boundary or a filament.
    pub boundary: usize,
    /// Interior junctions of degree 1 (dead ends).
    pub dead_ends: usize,
    /// Interior nodes of degree 2 (bends, not junctions).
    pub two_way: usize,
    /// Interior junctions of degree 3.
    pub three_way: usize,
    /// Interior junctions of degree 4 or more.
    pub four_way: usize,
    /// Secondary road segments.
    pub streets: usize,
    /// Their total length, metres.
    pub street_length_m: f64,
}

impl StreetStats {
    /// The statistics of one cell graph (secondary roads are [`RoadClass::Street`]).
    pub fn of(network: &RoadNetwork) -> Self {
        let mut s = StreetStats::default();
        for (e, _, _, r) in network.edges() {
            if r.class == RoadClass::Street {
                s.streets += 1;
                s.street_length_m += network.edge_length(e).unwrap_or(0.0);
            }
        }
        for n in network.node_ids() {
            let Ok(edges) = network.edges_at(n) else {
                continue;
            };
            let class = |e| network.edge_payload(e).map(|r| r.class).ok();
            let streets = edges
                .iter()
                .filter(|&&e| class(e) == Some(RoadClass::Street))
                .count();
            if streets == 0 {
                continue;
            }
            if streets < edges.len() {
                s.junctions += 1;
                s.boundary += 1;
                continue;
            }
            if edges.len() != 2 {
                s.junctions += 1;
            }
            match edges.len() {
                1 => s.dead_ends += 1,
                2 => s.two_way += 1,
                3 => s.three_way += 1,
                _ => s.four_way += 1,
            }
        }
        s
    }

    /// Adds `other`'s counts.
    pub fn add(&mut self, other: &StreetStats) {
        self.junctions += other.junctions;
        self.boundary += other.boundary;
        self.dead_ends += other.dead_ends;
        self.two_way += other.two_way;
        self.three_way += other.three_way;
        self.four_way += other.four_way;
        self.streets += other.streets;
        self.street_length_m += other.street_length_m;
    }

    /// Share of junctions that are dead ends (0 with no junctions).
    pub fn dead_end_share(&self) -> f64 {
        self.share(self.dead_ends)
    }

    /// Share of junctions that are 4-way (or more) or on the boundary.
    pub fn four_way_or_boundary_share(&self) -> f64 {
        self.share(self.four_way + self.boundary)
    }

    fn share(&self, k: usize) -> f64 {
        if self.junctions == 0 {
            0.0
        } else {
            k as f64 / self.junctions as f64
        }
    }
}
