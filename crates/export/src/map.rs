//! The 2-D map model that the SVG and GeoJSON writers draw: plain data, filled by hand or by
//! the pipeline.
//!
//! Coordinates are layout coordinates in metres: `x` east, `y` north (the XY plane of every
//! 2-D stage of polis). Polygons follow the polis contract (simple rings, no repeated
//! closing vertex); the writers accept either orientation and write what each format
//! wants. Nothing here depends on the stage crates, so a user can build a map from any
//! source:
//!
//! ```
//! use polis_export::map::{BuildingKind, MapFootprint, MapLayers, MapRoad, RoadClass};
//! use polis_export::geom::{DVec2, Polygon};
//!
//! let mut map = MapLayers::default();
//! map.roads.push(MapRoad::new(
//!     vec![DVec2::new(0.0, 0.0), DVec2::new(100.0, 0.0)],
//!     RoadClass::Street,
//!     8.0,
//! ));
//! map.footprints.push(MapFootprint::new(
//!     Polygon::rect(DVec2::new(10.0, 6.0), DVec2::new(20.0, 16.0)).into(),
//!     BuildingKind::Residential,
//!     9.0,
//! ));
//! map.validate()?;
//! # Ok::<(), polis_export::ExportError>(())
//! ```

use polis_geom::{DVec2, MAX_COORDINATE, PolygonWithHoles};

use crate::ExportError;

/// The class of a road, for styling and attributes.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum RoadClass {
    /// A highway: the fast network between population centres (Parish & Müller §3).
    Highway,
    /// A major road (avenue, arterial).
    Major,
    /// A street: the local grid that fills the areas between highways.
    Street,
    /// A footpath or pedestrian way.
    Footpath,
    /// Anything else, named.
    Other(String),
}

impl RoadClass {
    /// The class as a lower-case word (`"highway"`, `"major"`, `"street"`, `"footpath"`,
    /// or the name of [`Other`](Self::Other)).
    pub fn as_str(&self) -> &str {
        match self {
            RoadClass::Highway => "highway",
            RoadClass::Major => "major",
            RoadClass::Street => "street",
            RoadClass::Footpath => "footpath",
            RoadClass::Other(s) => s,
        }
    }

    /// Drawing order: smaller classes first so that larger roads are drawn over them.
    pub(crate) fn rank(&self) -> u8 {
        match self {
            RoadClass::Footpath => 0,
            RoadClass::Other(_) => 1,
            RoadClass::Street => 2,
            RoadClass::Major => 3,
            RoadClass::Highway => 4,
        }
    }
}

/// The kind of a building, for styling and attributes.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[non_exhaustive]
pub enum BuildingKind {
    /// Houses and apartment blocks.
    Residential,
    /// Shops and offices.
    Commercial,
    /// Factories and warehouses.
    Industrial,
    /// Tall office towers.
    Skyscraper,
    /// Anything else, named.
    Other(String),
}

impl BuildingKind {
    /// The kind as a lower-case word.
    pub fn as_str(&self) -> &str {
        match self {
            BuildingKind::Residential => "residential",
            BuildingKind::Commercial => "commercial",
            BuildingKind::Industrial => "industrial",
            BuildingKind::Skyscraper => "skyscraper",
            BuildingKind::Other(s) => s,
        }
    }
}

/// A road as a centre line.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MapRoad {
    /// A stable id chosen by the producer (e.g. the road-graph edge id). Default: 0.
    pub id: u64,
    /// The centre line, at least two points, metres.
    pub points: Vec<DVec2>,
    /// The class.
    pub class: RoadClass,
    /// Total width in metres (≥ 0).
    pub width_m: f64,
    /// Whether the road is a bridge (over water).
    pub bridge: bool,
    /// Whether the road is a tunnel (under a park or a hill, between two portals): no
    /// road surface is drawn for it; maps draw it dashed. Default: `false`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub tunnel: bool,
    /// A bridge's height profile: `(metres along the centre line from its first point,
    /// height of the road surface before its lift)` pairs, increasing along the road.
    /// The road surface over the bridge follows it (linearly between the pairs, held
    /// at the first and last height beyond them) instead of running straight between
    /// the ground at the bridge's ends. Ignored on other roads. Default: `None`.
    #[cfg_attr(feature = "serde", serde(default))]
    pub profile: Option<Vec<(f64, f64)>>,
}

impl MapRoad {
    /// A road that is neither a bridge nor a tunnel, with id 0.
    pub fn new(points: Vec<DVec2>, class: RoadClass, width_m: f64) -> Self {
        MapRoad {
            id: 0,
            points,
            class,
            width_m,
            bridge: false,
            tunnel: false,
            profile: None,
        }
    }

    /// The height of [`profile`](Self::profile) `s` metres along the road: linear
    /// between its pairs, held beyond them; `None` without a profile (or an empty one).
    pub fn profile_height(&self, s: f64) -> Option<f64> {
        let p = self.profile.as_deref()?;
        let (first, last) = (p.first()?, p.last()?);
        if s <= first.0 {
            return Some(first.1);
        }
        if s >= last.0 {
            return Some(last.1);
        }
        let k = p.partition_point(|q| q.0 <= s).clamp(1, p.len() - 1);
        let (a, b) = (p[k - 1], p[k]);
        Some(if b.0 > a.0 {
            a.1 + (b.1 - a.1) * (s - a.0) / (b.0 - a.0)
        } else {
            b.1
        })
    }
}

/// A city block: the area enclosed by roads, inset by half their width.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MapBlock {
    /// A stable id chosen by the producer.
    pub id: u64,
    /// The block's outline.
    pub polygon: PolygonWithHoles,
}

/// A lot: a parcel of a block.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MapLot {
    /// A stable id chosen by the producer.
    pub id: u64,
    /// The block it belongs to, if known.
    pub block: Option<u64>,
    /// The lot's outline.
    pub polygon: PolygonWithHoles,
}

/// A building footprint.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MapFootprint {
    /// A stable id chosen by the producer. Default: 0.
    pub id: u64,
    /// The footprint.
    pub polygon: PolygonWithHoles,
    /// The building kind.
    pub kind: BuildingKind,
    /// Height above ground in metres (≥ 0).
    pub height_m: f64,
    /// Number of floors, if known.
    pub floors: Option<u32>,
    /// The lot it stands on, if known.
    pub lot: Option<u64>,
}

impl MapFootprint {
    /// A footprint with id 0, no floor count and no lot.
    pub fn new(polygon: PolygonWithHoles, kind: BuildingKind, height_m: f64) -> Self {
        MapFootprint {
            id: 0,
            polygon,
            kind,
            height_m,
            floors: None,
            lot: None,
        }
    }
}

/// One fan of a primary road's plot (Kelly §4.2.2, the plot debug view of Fig. 72): the
/// samples laid from a front's head, and the one taken.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MapFan {
    /// The head the fan was laid from, metres.
    pub from: DVec2,
    /// The samples, counter-clockwise, metres.
    pub samples: Vec<DVec2>,
    /// Index into `samples` of the sample the front moved to.
    pub chosen: usize,
}

/// One lot subdivision step's split line (Kelly §5.5.1).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MapSplit {
    /// The block whose subdivision cut it.
    pub block: u64,
    /// The cut's parts inside the piece it split (one for a convex piece), metres.
    pub chords: Vec<[DVec2; 2]>,
}

/// What Kelly's debug views draw over the map (§5.4.1, §5.5.1): the primary roads' plot
/// points and sample fans, and the lot subdivision's split lines in the order they were
/// cut. Block and lot boundaries come from [`MapLayers::blocks`] and [`MapLayers::lots`].
/// The SVG writer draws them only when asked (`SvgOptions::debug`); other writers ignore
/// them. Default: empty.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct MapDebug {
    /// Plot points of the primary roads (Kelly's plot samples), metres.
    pub plot_points: Vec<DVec2>,
    /// The sample fans of the primary roads' plots, in plotting order.
    pub fans: Vec<MapFan>,
    /// The lot subdivision's split lines, in order (block by block, step by step).
    pub splits: Vec<MapSplit>,
}

impl MapDebug {
    /// Checks every point as [`MapLayers::validate`] does, and every fan's chosen index.
    pub fn validate(&self) -> Result<(), ExportError> {
        for (k, &p) in self.plot_points.iter().enumerate() {
            check_point(p, k, || "debug plot points".to_string())?;
        }
        for (i, f) in self.fans.iter().enumerate() {
            let who = || format!("debug fan {i}");
            check_point(f.from, 0, who)?;
            for (k, &p) in f.samples.iter().enumerate() {
                check_point(p, k, who)?;
            }
            if f.chosen >= f.samples.len() {
                return Err(ExportError::map(
                    who(),
                    format!("chosen sample {} of {} samples", f.chosen, f.samples.len()),
                ));
            }
        }
        for (i, s) in self.splits.iter().enumerate() {
            for (k, c) in s.chords.iter().enumerate() {
                for &p in c {
                    check_point(p, k, || format!("debug split line {i}"))?;
                }
            }
        }
        Ok(())
    }
}

/// Everything a map shows, by layer (drawn bottom to top in this order: water, parks,
/// blocks, lots, roads, footprints).
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct MapLayers {
    /// Lakes, rivers, sea.
    pub water: Vec<PolygonWithHoles>,
    /// Parks and other green areas.
    pub parks: Vec<PolygonWithHoles>,
    /// City blocks.
    pub blocks: Vec<MapBlock>,
    /// Lots.
    pub lots: Vec<MapLot>,
    /// Roads.
    pub roads: Vec<MapRoad>,
    /// Building footprints.
    pub footprints: Vec<MapFootprint>,
    /// Debug overlays (drawn only when a writer is asked to). Default: empty.
    pub debug: MapDebug,
}

/// Which layers a writer includes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct LayerSet {
    /// Water areas. Default: true.
    pub water: bool,
    /// Parks. Default: true.
    pub parks: bool,
    /// Blocks. Default: true.
    pub blocks: bool,
    /// Lots. Default: true.
    pub lots: bool,
    /// Roads. Default: true.
    pub roads: bool,
    /// Building footprints. Default: true.
    pub footprints: bool,
}

impl Default for LayerSet {
    fn default() -> Self {
        LayerSet::ALL
    }
}

impl LayerSet {
    /// Every layer.
    pub const ALL: LayerSet = LayerSet {
        water: true,
        parks: true,
        blocks: true,
        lots: true,
        roads: true,
        footprints: true,
    };
    /// No layer.
    pub const NONE: LayerSet = LayerSet {
        water: false,
        parks: false,
        blocks: false,
        lots: false,
        roads: false,
        footprints: false,
    };
}

/// Checks roads as [`MapLayers::validate`] does.
pub(crate) fn check_roads(roads: &[MapRoad]) -> Result<(), ExportError> {
    for (i, r) in roads.iter().enumerate() {
        let who = || format!("road {i} (id {})", r.id);
        if r.points.len() < 2 {
            return Err(ExportError::map(
                who(),
                format!("{} points; a road needs at least 2", r.points.len()),
            ));
        }
        for (k, &p) in r.points.iter().enumerate() {
            check_point(p, k, who)?;
        }
        if !(r.width_m.is_finite() && r.width_m >= 0.0) {
            return Err(ExportError::map(
                who(),
                format!("width {} m must be finite and ≥ 0", r.width_m),
            ));
        }
    }
    Ok(())
}

impl MapLayers {
    /// Checks every feature: coordinates finite and within ±[`MAX_COORDINATE`] m, rings of
    /// at least three points, roads of at least two points, widths and heights finite and
    /// non-negative. The writers call this before writing anything.
    ///
    /// Simplicity of rings is not checked (the writers do not need it); see
    /// [`PolygonWithHoles::validate`].
    pub fn validate(&self) -> Result<(), ExportError> {
        for (i, p) in self.water.iter().enumerate() {
            check_polygon(p, || format!("water area {i}"))?;
        }
        for (i, p) in self.parks.iter().enumerate() {
            check_polygon(p, || format!("park {i}"))?;
        }
        for (i, b) in self.blocks.iter().enumerate() {
            check_polygon(&b.polygon, || format!("block {i} (id {})", b.id))?;
        }
        for (i, l) in self.lots.iter().enumerate() {
            check_polygon(&l.polygon, || format!("lot {i} (id {})", l.id))?;
        }
        check_roads(&self.roads)?;
        for (i, f) in self.footprints.iter().enumerate() {
            let who = || format!("footprint {i} (id {})", f.id);
            check_polygon(&f.polygon, who)?;
            if !(f.height_m.is_finite() && f.height_m >= 0.0) {
                return Err(ExportError::map(
                    who(),
                    format!("height {} m must be finite and ≥ 0", f.height_m),
                ));
            }
        }
        self.debug.validate()
    }

    /// The bounding box of the selected layers as `(min, max)`, `None` if they are empty.
    /// Roads are padded by half their width.
    pub fn bounds(&self, layers: LayerSet) -> Option<(DVec2, DVec2)> {
        let mut min = DVec2::splat(f64::INFINITY);
        let mut max = DVec2::splat(f64::NEG_INFINITY);
        let mut add = |p: DVec2, pad: f64| {
            min = min.min(p - pad);
            max = max.max(p + pad);
        };
        let mut add_poly = |p: &PolygonWithHoles| {
            for &q in p.outer.points() {
                add(q, 0.0);
            }
        };
        if layers.water {
            self.water.iter().for_each(&mut add_poly);
        }
        if layers.parks {
            self.parks.iter().for_each(&mut add_poly);
        }
        if layers.blocks {
            self.blocks.iter().for_each(|b| add_poly(&b.polygon));
        }
        if layers.lots {
            self.lots.iter().for_each(|l| add_poly(&l.polygon));
        }
        if layers.footprints {
            self.footprints.iter().for_each(|f| add_poly(&f.polygon));
        }
        if layers.roads {
            for r in &self.roads {
                for &p in &r.points {
                    add(p, r.width_m / 2.0);
                }
            }
        }
        (min.x <= max.x && min.y <= max.y).then_some((min, max))
    }
}

fn check_point(p: DVec2, k: usize, who: impl Fn() -> String) -> Result<(), ExportError> {
    if !p.is_finite() {
        return Err(ExportError::map(
            who(),
            format!("point {k} ({p}) is not finite"),
        ));
    }
    if p.x.abs() > MAX_COORDINATE || p.y.abs() > MAX_COORDINATE {
        return Err(ExportError::map(
            who(),
            format!("point {k} ({p}) lies beyond ±{MAX_COORDINATE} m"),
        ));
    }
    Ok(())
}

fn check_polygon(p: &PolygonWithHoles, who: impl Fn() -> String) -> Result<(), ExportError> {
    for (ring, poly) in p.rings() {
        if poly.len() < 3 {
            return Err(ExportError::map(
                who(),
                format!(
                    "the {ring} has {} points; a ring needs at least 3",
                    poly.len()
                ),
            ));
        }
        for (k, &q) in poly.points().iter().enumerate() {
            check_point(q, k, || format!("{}, {ring}", who()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::Polygon;

    #[test]
    fn validation_rejects_bad_features() {
        let sq: PolygonWithHoles = Polygon::rect(DVec2::ZERO, DVec2::ONE).into();
        let mut m = MapLayers::default();
        m.water.push(sq.clone());
        m.validate().unwrap();
        m.roads
            .push(MapRoad::new(vec![DVec2::ZERO], RoadClass::Street, 5.0));
        assert!(matches!(m.validate(), Err(ExportError::InvalidMap { .. })));
        m.roads[0].points.push(DVec2::new(f64::NAN, 0.0));
        assert!(m.validate().is_err());
        m.roads[0].points[1] = DVec2::ONE;
        m.validate().unwrap();
        m.roads[0].width_m = -1.0;
        assert!(m.validate().is_err());
        m.roads[0].width_m = 1.0;
        m.footprints.push(MapFootprint::new(
            sq.clone(),
            BuildingKind::Industrial,
            f64::INFINITY,
        ));
        assert!(m.validate().is_err());
        m.footprints[0].height_m = 3.0;
        m.validate().unwrap();
        m.lots.push(MapLot {
            id: 1,
            block: None,
            polygon: Polygon::new(vec![DVec2::ZERO, DVec2::ONE]).into(),
        });
        let e = m.validate().unwrap_err().to_string();
        assert!(e.contains("lot 0") && e.contains("at least 3"), "{e}");
        m.lots[0].polygon = Polygon::rect(DVec2::ZERO, DVec2::splat(2e8)).into();
        assert!(m.validate().is_err());
    }

    #[test]
    fn bounds_follow_layers_and_pad_roads() {
        let mut m = MapLayers::default();
        assert_eq!(m.bounds(LayerSet::ALL), None);
        m.parks
            .push(Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 5.0)).into());
        m.roads.push(MapRoad::new(
            vec![DVec2::new(0.0, 20.0), DVec2::new(4.0, 20.0)],
            RoadClass::Highway,
            4.0,
        ));
        assert_eq!(
            m.bounds(LayerSet::ALL),
            Some((DVec2::new(-2.0, 0.0), DVec2::new(10.0, 22.0)))
        );
        let only_roads = LayerSet {
            roads: true,
            ..LayerSet::NONE
        };
        assert_eq!(
            m.bounds(only_roads),
            Some((DVec2::new(-2.0, 18.0), DVec2::new(6.0, 22.0)))
        );
    }
}
