//! The input of secondary growth: one city cell and the maps.

use polis_geom::{DVec2, Field, PolygonWithHoles};

/// One city cell (Kelly §4.3.1): its region and the roads of its private graph.
#[derive(Debug, Clone, PartialEq)]
pub struct SecondaryCell {
    /// A stable id (from the caller: e.g. a hash of the cell's boundary nodes), which
    /// sub-seeds the growth so that editing one cell never reshuffles another.
    pub id: u64,
    /// The cell's region: outer ring and holes (islands). Any orientation; it is
    /// normalised and validated at the start of growth.
    pub region: PolygonWithHoles,
    /// Filament roads of the cell's own graph (dead ends and connectors inside the cell),
    /// as segments in metres. Secondary roads may join them.
    pub filaments: Vec<[DVec2; 2]>,
}

impl SecondaryCell {
    /// A cell without filaments.
    pub fn new(id: u64, region: impl Into<PolygonWithHoles>) -> Self {
        SecondaryCell {
            id,
            region: region.into(),
            filaments: Vec::new(),
        }
    }
}

/// The maps secondary roads must respect: no road is built where water or parks are
/// ≥ 0.5 (the convention of [`RoadInputs`](crate::RoadInputs)).
#[derive(Clone, Copy, Default)]
pub struct CellMaps<'a> {
    /// Water; `None` = no water.
    pub water: Option<&'a dyn Field>,
    /// Parks and other no-build areas; `None` = none.
    pub parks: Option<&'a dyn Field>,
    /// Spacing of the legality samples along each proposed road, metres. `0` means the
    /// default, 5 m (as [`RoadParams::legality_step_m`](crate::RoadParams)).
    pub step_m: f64,
}

impl std::fmt::Debug for CellMaps<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CellMaps")
            .field("water", &self.water.is_some())
            .field("parks", &self.parks.is_some())
            .field("step_m", &self.step_m)
            .finish()
    }
}

impl CellMaps<'_> {
    /// No maps: everything is legal.
    pub fn none() -> Self {
        CellMaps::default()
    }

    fn illegal_at(&self, p: DVec2) -> bool {
        let bad = |m: Option<&dyn Field>| {
            m.is_some_and(|f| {
                let v = f.sample(p);
                v >= 0.5 || v.is_nan()
            })
        };
        bad(self.water) || bad(self.parks)
    }

    /// Whether the segment `a–b` stays out of water and parks (sampled at both ends and
    /// every `step_m` between).
    pub fn segment_legal(&self, a: DVec2, b: DVec2) -> bool {
        if self.water.is_none() && self.parks.is_none() {
            return true;
        }
        let step = if self.step_m > 0.0 && self.step_m.is_finite() {
            self.step_m
        } else {
            5.0
        };
        let n = ((a.distance(b) / step).ceil() as usize).clamp(1, 100_000);
        (0..=n).all(|i| !self.illegal_at(a.lerp(b, i as f64 / n as f64)))
    }
}
