//! [`GridMaps`]: the maps the builders must respect.

use polis_geom::{DVec2, Field};

use crate::inputs::RoadInputs;

/// The maps grid streets must keep out of: no street sample where water or parks are
/// ≥ 0.5 (or NaN), the convention of [`RoadInputs`]. `None` means no such area.
#[derive(Clone, Copy, Default)]
pub struct GridMaps<'a> {
    /// Water. Default: none.
    pub water: Option<&'a dyn Field>,
    /// Parks and other no-build areas. Default: none.
    pub parks: Option<&'a dyn Field>,
}

impl std::fmt::Debug for GridMaps<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GridMaps")
            .field("water", &self.water.is_some())
            .field("parks", &self.parks.is_some())
            .finish()
    }
}

impl<'a> From<&'a RoadInputs> for GridMaps<'a> {
    /// The water and park maps of the road generator's inputs.
    fn from(inputs: &'a RoadInputs) -> Self {
        GridMaps {
            water: Some(&*inputs.water),
            parks: Some(&*inputs.parks),
        }
    }
}

impl GridMaps<'_> {
    /// No water, no parks: everything is buildable.
    pub fn none() -> Self {
        GridMaps::default()
    }

    /// Whether `p` is in water or a park (a map value ≥ 0.5 or NaN).
    pub fn blocked_at(&self, p: DVec2) -> bool {
        let bad = |m: Option<&dyn Field>| {
            m.is_some_and(|f| {
                let v = f.sample(p);
                v.is_nan() || v >= 0.5
            })
        };
        bad(self.water) || bad(self.parks)
    }
}
