//! The synthetic city of the benchmark and the allocation profile: 57,000 lots (the size
//! of Citygen's city, Kelly 2008 §6.5), shared through `#[path]` includes.

use polis_buildings::BuildingKind;
use polis_geom::{DVec2, Polygon};
use polis_lots::Lot;

/// Lots in the synthetic city.
pub const LOTS: usize = 57_000;

/// A city-like mix: rectangles of varied size and rotation, trapezoids and L-shapes.
pub fn lots() -> Vec<(Lot, BuildingKind)> {
    (0..LOTS)
        .map(|i| {
            let (gx, gy) = ((i % 240) as f64, (i / 240) as f64);
            let o = DVec2::new(gx * 50.0, gy * 50.0);
            let w = 14.0 + (i * 7 % 13) as f64;
            let d = 22.0 + (i * 5 % 17) as f64;
            let pts: Vec<DVec2> = match i % 4 {
                0 | 1 => {
                    let a = (i % 9) as f64 * 0.1;
                    let (x, y) = (DVec2::from_angle(a), DVec2::from_angle(a).perp());
                    vec![o, o + x * w, o + x * w + y * d, o + y * d]
                }
                2 => vec![
                    o,
                    o + DVec2::new(w, 0.0),
                    o + DVec2::new(w * 0.8, d),
                    o + DVec2::new(w * 0.1, d * 0.9),
                ],
                _ => vec![
                    o,
                    o + DVec2::new(w, 0.0),
                    o + DVec2::new(w, d * 0.4),
                    o + DVec2::new(w * 0.5, d * 0.4),
                    o + DVec2::new(w * 0.5, d),
                    o + DVec2::new(0.0, d),
                ],
            };
            let polygon = Polygon::new(pts);
            let kind = BuildingKind::ALL[(i * 31 + i / 240) % 6];
            (
                Lot {
                    area: polygon.area(),
                    polygon,
                    street_edges: vec![0],
                    block_id: 0,
                },
                kind,
            )
        })
        .collect()
}
