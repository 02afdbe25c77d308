//! # polis-stats
//!
//! Measures a city the way urban researchers measure real ones, and says how far it is
//! from a real city: the street-network metrics of Boeing 2019 on the simplified graph,
//! block, lot and building metrics, the plan defects an urban designer sees at once,
//! and a realism comparison against 100 real cities shipped with the crate.
//!
//! Inputs are plain data ([`CityInput`]: a [`StreetGraph`], block polygons, lots,
//! buildings), so any road graph can be measured, not only polis's.
//!
//! | module | what |
//! |---|---|
//! | [`input`] | [`StreetGraph`] (from any [`PlanarGraph`](polis_geom::PlanarGraph)), [`LotInput`], [`BuildingInput`], [`CityInput`] |
//! | [`simplify`] | the simplified graph: degree-2 chains merged, curved streets keep their polyline length |
//! | [`streets`] | `H_o`, `H_w`, φ, `k̄`, node-degree shares, segment lengths, circuity, intersection density, grade |
//! | [`parcels`] | block areas and shape factor Φ = A / (π r_c²), lot area / frontage / depth, coverage, floor-area ratio, heights, kind mix |
//! | [`defects`] | roads inside blocks without lots, stubs in land without lots, buildings in road corridors |
//! | [`reference`](mod@reference) | Boeing 2019's Table 1 (100 cities) and regional means |
//! | [`realism`] | metric by metric against a reference city, in or out of band |
//! | [`summary`] | [`Distribution`](summary::Distribution) and [`Histogram`](summary::Histogram) |
//!
//! [`report`] computes a [`CityReport`]; it serialises to JSON (serde) and prints as a
//! table (`Display`). [`CityReport::compare_with`] adds the realism comparison.
//!
//! ## Guarantees
//! * Every number is finite: an empty city, isolated nodes, zero-length edges, no
//!   blocks give zeros and counts, never NaN.
//! * Bad input (NaN coordinates, an edge naming a missing node, a lot edge index out of
//!   range) is a [`StatsError`], never a panic.
//! * Deterministic: no hash-map order reaches the output (kinds are a sorted map).
//!
//! ## Example
//!
//! ```
//! use polis_geom::DVec2;
//! use polis_stats::{CityInput, StatsOptions, StreetClass, StreetEdge, StreetGraph};
//!
//! // A plus sign: one four-way node and four dead ends.
//! let mut g = StreetGraph::default();
//! g.nodes = vec![DVec2::ZERO, DVec2::X * 100.0, DVec2::Y * 100.0, -DVec2::X * 100.0, -DVec2::Y * 100.0];
//! for k in 1..5 {
//!     g.edges.push(StreetEdge { a: 0, b: k, width_m: 10.0, class: StreetClass::Street, bridge: false });
//! }
//! let report = polis_stats::report(&CityInput::streets_only(&g), &StatsOptions::default())?
//!     .compare_with("Manhattan")?;
//! assert_eq!(report.streets.share_dead_end, 0.8);
//! assert!((report.streets.orientation_order - 1.0).abs() < 1e-12);
//! println!("{report}");
//! # Ok::<(), polis_stats::StatsError>(())
//! ```
//!
//! ## References
//! * G. Boeing, *Urban spatial order: street network orientation, configuration, and
//!   entropy*, Applied Network Science 4:67 (2019): the street metrics and the
//!   reference table.
//! * G. Boeing, *OSMnx*, CEUS 65 (2017): graph simplification, circuity, intersection
//!   density.

pub use polis_geom as geom;

mod boxgrid;
pub mod defects;
mod error;
pub mod input;
pub mod parcels;
pub mod realism;
pub mod reference;
pub mod simplify;
pub mod streets;
pub mod summary;
mod table;

pub use defects::PlanDefects;
pub use error::StatsError;
pub use input::{BuildingInput, CityInput, LotInput, StreetClass, StreetEdge, StreetGraph};
pub use parcels::{BlockMetrics, BuildingMetrics, LotMetrics};
pub use realism::{Band, Realism, RealismRow, compare};
pub use reference::{ReferenceCity, reference_cities, reference_city};
pub use streets::StreetMetrics;

/// What the plan-defect counters call "along", "at the edge" and "in the corridor".
/// Definitions, not performance knobs: changing them changes the counts.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct StatsOptions {
    /// A lot is along a road when it comes within half the road's width plus this,
    /// metres (footpath and front garden). Default: 8.
    pub lot_reach_m: f64,
    /// Roads are sampled for lots along them every this many metres. Default: 5.
    pub sample_step_m: f64,
    /// Dead ends this close to the map bounds are at the map edge, metres. Default: 10.
    pub edge_margin_m: f64,
    /// A footprint may come this much closer to a road than half its width before it
    /// counts as in the corridor, metres (rounding of insets). Default: 0.05.
    pub corridor_tolerance_m: f64,
}

impl Default for StatsOptions {
    fn default() -> Self {
        StatsOptions {
            lot_reach_m: 8.0,
            sample_step_m: 5.0,
            edge_margin_m: 10.0,
            corridor_tolerance_m: 0.05,
        }
    }
}

impl StatsOptions {
    /// Checks that every field is finite and not negative (the sample step > 0).
    ///
    /// # Errors
    /// [`StatsError::BadValue`] naming the field.
    pub fn validate(&self) -> Result<(), StatsError> {
        for (name, v, min_exclusive) in [
            ("lot_reach_m", self.lot_reach_m, false),
            ("sample_step_m", self.sample_step_m, true),
            ("edge_margin_m", self.edge_margin_m, false),
            ("corridor_tolerance_m", self.corridor_tolerance_m, false),
        ] {
            let ok = v.is_finite() && if min_exclusive { v > 0.0 } else { v >= 0.0 };
            if !ok {
                return Err(StatsError::BadValue {
                    what: format!("StatsOptions::{name}"),
                    value: v,
                });
            }
        }
        Ok(())
    }
}

/// The whole report.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CityReport {
    /// Street-network metrics.
    pub streets: StreetMetrics,
    /// Block metrics.
    pub blocks: BlockMetrics,
    /// Lot metrics.
    pub lots: LotMetrics,
    /// Building metrics.
    pub buildings: BuildingMetrics,
    /// Plan defects.
    pub defects: PlanDefects,
    /// The comparison with a reference city, once [`compare_with`](Self::compare_with)
    /// added it.
    pub realism: Option<Realism>,
    /// Earthworks of the roads graded into the land, filled in by whoever graded them
    /// (zero otherwise).
    #[cfg_attr(feature = "serde", serde(default))]
    pub earthworks: EarthworkMetrics,
}

/// Cut and fill of roads graded into the land (Kelly 2008 §4.2).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EarthworkMetrics {
    /// Ground removed where roads run below it, m³.
    pub cut_m3: f64,
    /// Ground added where roads run above it, m³.
    pub fill_m3: f64,
    /// Road length whose profile leaves the ground by more than 5 cm, metres.
    pub moved_length_m: f64,
    /// Steepest graded road piece (rise per metre).
    pub steepest_grade: f64,
}

impl CityReport {
    /// Adds the realism comparison with the reference city `name` (a city of the table
    /// or `"<region> mean"`; see [`reference_city`]).
    ///
    /// # Errors
    /// [`StatsError::UnknownCity`].
    pub fn compare_with(mut self, name: &str) -> Result<CityReport, StatsError> {
        let city = reference_city(name)?;
        self.realism = Some(compare(&self.streets, &city));
        Ok(self)
    }
}

/// Land area for densities: the given one, else the bounds', else the street nodes'
/// bounding box's (0 without nodes).
fn land_area(city: &CityInput<'_>) -> f64 {
    if let Some(a) = city.land_area_m2 {
        return a;
    }
    if let Some(b) = city.bounds {
        return b.area().max(0.0);
    }
    if city.streets.nodes.is_empty() {
        return 0.0;
    }
    polis_geom::Aabb2::from_points(city.streets.nodes.iter().copied())
        .area()
        .max(0.0)
}

/// Computes the report of `city`.
///
/// # Errors
/// [`StatsError`] for bad input ([`CityInput::validate`]) or options.
pub fn report(city: &CityInput<'_>, options: &StatsOptions) -> Result<CityReport, StatsError> {
    options.validate()?;
    city.validate()?;
    let simple = simplify::simplify(city.streets);
    let land = land_area(city);
    let lot_area: f64 = city.lots.iter().map(|l| l.polygon.area()).sum();
    Ok(CityReport {
        streets: streets::street_metrics(city.streets, &simple, land),
        blocks: parcels::block_metrics(city.blocks),
        lots: parcels::lot_metrics(city.lots),
        buildings: parcels::building_metrics(city.buildings, lot_area, land),
        defects: defects::plan_defects(city, &simple, options),
        realism: None,
        earthworks: EarthworkMetrics::default(),
    })
}
