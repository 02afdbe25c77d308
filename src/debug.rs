//! Kelly's debug views as map data (Citygen §5.4.1, §5.5.1): the primary roads' plot
//! points and sample fans, and the lot subdivision's split lines in order. The SVG writer
//! draws them as optional layers (`polis_export::svg::SvgDebug`; the `city` example's
//! `--debug-layers`).

use polis_export::map::{MapDebug, MapFan, MapSplit};
use polis_geom::{Aabb2, DVec2};
use polis_roads::primary::{Terrain, plot_traced};

use crate::citygen::RoadMode;
use crate::stages::StageContext;
use crate::{City, Error, Result};

impl City {
    /// The debug overlays of this city: the lot subdivision's split lines (every city),
    /// and, in the Citygen mode, the primary roads' plot points and the sample fans of
    /// re-plotting each primary road between its control nodes over the city's terrain
    /// (Kelly Fig. 72). Block and lot boundaries are the map's own blocks and lots.
    ///
    /// Limitations: a primary road that was moved by hand (its plot points edited) shows
    /// the fans of a fresh plot between its ends, not of the edits; a road that cannot be
    /// re-plotted (blocked) shows its plot points only.
    ///
    /// # Errors
    /// The primary network's errors (a file that cannot be read, a terrain the network
    /// does not fit).
    pub fn debug_map(&self) -> Result<MapDebug> {
        let mut debug = MapDebug {
            splits: self
                .lot_splits
                .iter()
                .map(|(block, line)| MapSplit {
                    block: *block,
                    chords: line.chords.clone(),
                })
                .collect(),
            ..MapDebug::default()
        };
        if self.config.road_mode != RoadMode::Citygen {
            return Ok(debug);
        }
        let h = self.config.size_m * 0.5;
        let terrain = Terrain::new(
            &self.maps.inputs,
            Aabb2::new(DVec2::splat(-h), DVec2::splat(h)),
        )
        .map_err(|e| Error::Roads(e.into()))?;
        let cx = StageContext {
            config: &self.config,
            maps: &self.maps,
        };
        let net = crate::citygen::kelly_network_of(&cx, &terrain)?;
        let mut trace = Vec::new();
        for (_, road) in net.roads() {
            debug.plot_points.extend(road.path.plot_points());
            let (Ok(a), Ok(b)) = (net.node(road.a), net.node(road.b)) else {
                continue;
            };
            if plot_traced(a.pos, b.pos, &road.spec.params, &terrain, &mut trace).is_err() {
                continue;
            }
            debug.fans.extend(trace.drain(..).map(|f| MapFan {
                from: f.from,
                samples: f.samples,
                chosen: f.chosen,
            }));
        }
        Ok(debug)
    }
}
