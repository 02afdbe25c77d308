//! GeoJSON writer (RFC 7946 `FeatureCollection`).
//!
//! [`write_geojson`] writes the features of a [`MapLayers`]:
//!
//! | layer | geometry | properties |
//! |---|---|---|
//! | water | `Polygon` | `layer: "water"` |
//! | parks | `Polygon` | `layer: "park"` |
//! | blocks | `Polygon` | `layer: "block"`, `id` |
//! | lots | `Polygon` | `layer: "lot"`, `id`, `block` (or `null`) |
//! | roads | `LineString` | `layer: "road"`, `id`, `class`, `width_m`, `bridge`, `tunnel` |
//! | footprints | `Polygon` | `layer: "building"`, `id`, `kind`, `height_m`, `floors`, `lot` |
//!
//! Every feature also has a top-level `id` `"<layer>-<id>"` (`"<layer>-<index>"` for water
//! and parks). Polygon rings are closed (the first position repeated last) and follow the
//! right-hand rule (outer rings counter-clockwise, holes clockwise) whatever the input
//! orientation.
//!
//! ## Coordinate system
//!
//! With [`Coordinates::Wgs84`] and an anchor, positions are WGS 84 `[longitude,
//! latitude]` in degrees as RFC 7946 requires, projected from the layout plane by a local
//! tangent-plane projection around the anchor ([`projection`]; its error is documented
//! there: about 2 m at the corners of a 4 km city), and the foreign member says
//! `"type": "wgs84"`. GIS tools (QGIS, geopandas, kepler.gl) read such a file as it is.
//!
//! By default ([`Coordinates::Local`]) positions are **not** WGS 84 longitude/latitude:
//! they are `[x, y]` in metres in the
//! city's local layout plane, `x` east and `y` north, as every 2-D stage of polis uses
//! them. RFC 7946 §4 allows other coordinate systems "where all involved parties have a
//! prior arrangement" and has no `crs` member; the arrangement is stated in a top-level
//! foreign member [`CRS_MEMBER`]:
//!
//! ```json
//! "polis:coordinates": {"type": "local-metric", "units": "m", "x": "east", "y": "north",
//!                       "anchor_lon_lat": null}
//! ```
//!
//! `anchor_lon_lat` is [`GeoJsonOptions::anchor_lon_lat`]: where the layout origin lies on
//! Earth, if the user knows, so that a GIS user can georeference the layer (e.g. with a
//! local transverse Mercator projection centred there). Numbers are written with the
//! shortest representation that reads back to the same `f64` (deterministic).

use std::io::Write;

use polis_geom::{DVec2, PolygonWithHoles, Ring};
#[cfg(feature = "serde")]
use serde::ser::{SerializeMap, SerializeSeq};
#[cfg(feature = "serde")]
use serde::{Serialize, Serializer};

use crate::ExportError;
use crate::map::{LayerSet, MapLayers};

pub mod projection;

use projection::TangentPlane;

/// The name of the top-level foreign member that states the coordinate system.
pub const CRS_MEMBER: &str = "polis:coordinates";

/// Options of [`write_geojson`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct GeoJsonOptions {
    /// Which layers to write. Default: all.
    pub layers: LayerSet,
    /// Longitude and latitude in degrees (WGS 84) of the layout origin, recorded in
    /// [`CRS_MEMBER`] for georeferencing; coordinates stay metric. Default: none.
    pub anchor_lon_lat: Option<[f64; 2]>,
    /// Indent the output (larger, for reading). Default: false.
    pub pretty: bool,
    /// Local metres or WGS 84 longitude/latitude (which needs
    /// [`anchor_lon_lat`](Self::anchor_lon_lat)). Default: [`Coordinates::Local`].
    pub coordinates: Coordinates,
}

/// The coordinate system of the positions [`write_geojson`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Coordinates {
    /// `[x, y]` metres in the layout plane (`x` east, `y` north), as polis computes them.
    #[default]
    Local,
    /// RFC 7946's WGS 84 `[longitude, latitude]` in degrees, projected around
    /// [`GeoJsonOptions::anchor_lon_lat`] ([`projection`]).
    Wgs84,
}

impl Default for GeoJsonOptions {
    fn default() -> Self {
        GeoJsonOptions {
            layers: LayerSet::ALL,
            anchor_lon_lat: None,
            pretty: false,
            coordinates: Coordinates::Local,
        }
    }
}

/// What [`write_geojson`] wrote.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GeoJsonReport {
    /// Features written.
    pub features: usize,
}

/// Writes the selected layers of `map` as a GeoJSON `FeatureCollection` to `out`.
///
/// ```
/// use polis_export::map::{MapLayers, MapRoad, RoadClass};
/// use polis_export::geojson::{write_geojson, GeoJsonOptions};
/// use polis_export::geom::DVec2;
/// let mut map = MapLayers::default();
/// map.roads.push(MapRoad::new(vec![DVec2::ZERO, DVec2::new(50.0, 20.0)], RoadClass::Highway, 12.0));
/// let mut out = Vec::new();
/// write_geojson(&map, &GeoJsonOptions::default(), &mut out)?;
/// let v: serde_json::Value = serde_json::from_slice(&out)?;
/// assert_eq!(v["features"][0]["properties"]["class"], "highway");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_geojson<W: Write>(
    map: &MapLayers,
    options: &GeoJsonOptions,
    out: W,
) -> Result<GeoJsonReport, ExportError> {
    if let Some([lon, lat]) = options.anchor_lon_lat
        && !((-180.0..=180.0).contains(&lon) && (-90.0..=90.0).contains(&lat))
    {
        return Err(ExportError::InvalidOption {
            name: "anchor_lon_lat",
            reason: format!(
                "[{lon}, {lat}] is not a longitude in [-180, 180] and a latitude in [-90, 90]"
            ),
        });
    }
    map.validate()?;
    let proj = match (options.coordinates, options.anchor_lon_lat) {
        (Coordinates::Local, _) => None,
        (Coordinates::Wgs84, None) => {
            return Err(ExportError::InvalidOption {
                name: "coordinates",
                reason: "WGS 84 coordinates need anchor_lon_lat (where the layout origin is)"
                    .into(),
            });
        }
        (Coordinates::Wgs84, Some(anchor)) => {
            let plane = TangentPlane::new(anchor)?;
            if let Some((min, max)) = map.bounds(options.layers) {
                plane.check_extent(min, max)?;
            }
            Some(plane)
        }
    };
    let mut w = std::io::BufWriter::with_capacity(1 << 16, out);
    let mut report = GeoJsonReport::default();
    let l = options.layers;
    let nl = if options.pretty { "\n" } else { "" };
    let io = ExportError::io("geojson");
    let crs = match proj {
        None => serde_json::json!({
            "type": "local-metric",
            "units": "m",
            "x": "east",
            "y": "north",
            "anchor_lon_lat": options.anchor_lon_lat,
        }),
        Some(_) => serde_json::json!({
            "type": "wgs84",
            "projection": "local tangent plane (equirectangular) around the anchor",
            "anchor_lon_lat": options.anchor_lon_lat,
        }),
    };
    write!(
        w,
        r#"{{"type":"FeatureCollection",{nl}"{CRS_MEMBER}":{crs},{nl}"features":["#
    )
    .map_err(io)?;
    let mut emit = |feature: &dyn erased::Feature| -> Result<(), ExportError> {
        let sep = if report.features == 0 { nl } else { "," };
        write!(w, "{sep}{nl}").map_err(ExportError::io("geojson"))?;
        feature.write(&mut w, options.pretty)?;
        report.features += 1;
        Ok(())
    };
    let area = |layer: &'static str, i: usize, p| Feature {
        id: format!("{layer}-{i}"),
        proj,
        geometry: Geometry::Polygon(p),
        properties: Layer { layer },
    };
    if l.water {
        for (i, p) in map.water.iter().enumerate() {
            emit(&area("water", i, p))?;
        }
    }
    if l.parks {
        for (i, p) in map.parks.iter().enumerate() {
            emit(&area("park", i, p))?;
        }
    }
    if l.blocks {
        for b in &map.blocks {
            emit(&Feature {
                proj,
                id: format!("block-{}", b.id),
                geometry: Geometry::Polygon(&b.polygon),
                properties: BlockProps {
                    layer: "block",
                    id: b.id,
                },
            })?;
        }
    }
    if l.lots {
        for lot in &map.lots {
            emit(&Feature {
                proj,
                id: format!("lot-{}", lot.id),
                geometry: Geometry::Polygon(&lot.polygon),
                properties: LotProps {
                    layer: "lot",
                    id: lot.id,
                    block: lot.block,
                },
            })?;
        }
    }
    if l.roads {
        for r in &map.roads {
            emit(&Feature {
                proj,
                id: format!("road-{}", r.id),
                geometry: Geometry::LineString(&r.points),
                properties: RoadProps {
                    layer: "road",
                    id: r.id,
                    class: r.class.as_str(),
                    width_m: r.width_m,
                    bridge: r.bridge,
                    tunnel: r.tunnel,
                },
            })?;
        }
    }
    if l.footprints {
        for f in &map.footprints {
            emit(&Feature {
                proj,
                id: format!("building-{}", f.id),
                geometry: Geometry::Polygon(&f.polygon),
                properties: BuildingProps {
                    layer: "building",
                    id: f.id,
                    kind: f.kind.as_str(),
                    height_m: f.height_m,
                    floors: f.floors,
                    lot: f.lot,
                },
            })?;
        }
    }
    let tail = if report.features == 0 { "" } else { nl };
    writeln!(w, "{tail}]}}").map_err(ExportError::io("geojson"))?;
    w.flush().map_err(ExportError::io("geojson"))?;
    Ok(report)
}

/// Lets features with different property types go through one closure.
mod erased {
    use super::*;

    pub trait Feature {
        fn write(&self, w: &mut dyn Write, pretty: bool) -> Result<(), ExportError>;
    }

    impl<P: Serialize> Feature for super::Feature<'_, P> {
        fn write(&self, w: &mut dyn Write, pretty: bool) -> Result<(), ExportError> {
            let r = if pretty {
                serde_json::to_writer_pretty(w, self)
            } else {
                serde_json::to_writer(w, self)
            };
            r.map_err(ExportError::json(format!("feature {}", self.id)))
        }
    }
}

struct Feature<'a, P> {
    id: String,
    /// `Some` for WGS 84 output.
    proj: Option<TangentPlane>,
    geometry: Geometry<'a>,
    properties: P,
}

#[cfg(feature = "serde")]
impl<P: Serialize> Serialize for Feature<'_, P> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(4))?;
        m.serialize_entry("type", "Feature")?;
        m.serialize_entry("id", &self.id)?;
        m.serialize_entry(
            "geometry",
            &Projected {
                geometry: &self.geometry,
                proj: self.proj,
            },
        )?;
        m.serialize_entry("properties", &self.properties)?;
        m.end()
    }
}

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
struct Layer {
    layer: &'static str,
}

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
struct BlockProps {
    layer: &'static str,
    id: u64,
}

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
struct LotProps {
    layer: &'static str,
    id: u64,
    block: Option<u64>,
}

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
struct RoadProps<'a> {
    layer: &'static str,
    id: u64,
    class: &'a str,
    width_m: f64,
    bridge: bool,
    tunnel: bool,
}

#[cfg_attr(feature = "serde", derive(serde::Serialize))]
struct BuildingProps<'a> {
    layer: &'static str,
    id: u64,
    kind: &'a str,
    height_m: f64,
    floors: Option<u32>,
    lot: Option<u64>,
}

enum Geometry<'a> {
    LineString(&'a [DVec2]),
    Polygon(&'a PolygonWithHoles),
}

/// A geometry with the projection its positions go through.
struct Projected<'a> {
    geometry: &'a Geometry<'a>,
    proj: Option<TangentPlane>,
}

#[cfg(feature = "serde")]
impl Serialize for Projected<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(2))?;
        let proj = self.proj;
        match self.geometry {
            Geometry::LineString(points) => {
                m.serialize_entry("type", "LineString")?;
                m.serialize_entry(
                    "coordinates",
                    &Positions {
                        points,
                        reverse: false,
                        close: false,
                        proj,
                    },
                )?;
            }
            Geometry::Polygon(p) => {
                m.serialize_entry("type", "Polygon")?;
                m.serialize_entry("coordinates", &Rings(p, proj))?;
            }
        }
        m.end()
    }
}

/// A polygon's rings: outer counter-clockwise, holes clockwise, each closed.
struct Rings<'a>(&'a PolygonWithHoles, Option<TangentPlane>);

#[cfg(feature = "serde")]
impl Serialize for Rings<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(1 + self.0.holes.len()))?;
        for (ring, poly) in self.0.rings() {
            let ccw = ring == Ring::Outer;
            seq.serialize_element(&Positions {
                points: poly.points(),
                reverse: (poly.signed_area() > 0.0) != ccw,
                close: true,
                proj: self.1,
            })?;
        }
        seq.end()
    }
}

/// A list of `[x, y]` positions, optionally reversed and closed by repeating the first.
struct Positions<'a> {
    points: &'a [DVec2],
    reverse: bool,
    close: bool,
    proj: Option<TangentPlane>,
}

#[cfg(feature = "serde")]
impl Serialize for Positions<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let n = self.points.len() + usize::from(self.close && !self.points.is_empty());
        let mut seq = s.serialize_seq(Some(n))?;
        let at = |k: usize| {
            let k = k % self.points.len();
            let p = if self.reverse {
                self.points[self.points.len() - 1 - k]
            } else {
                self.points[k]
            };
            match &self.proj {
                Some(plane) => plane.lon_lat(p),
                None => [p.x, p.y],
            }
        };
        for k in 0..n {
            seq.serialize_element(&at(k))?;
        }
        seq.end()
    }
}

#[cfg(test)]
mod tests;
