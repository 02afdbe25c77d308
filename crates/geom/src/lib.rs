//! # polis-geom
//!
//! The shared geometric vocabulary of [polis](https://example.invalid/polis): every stage
//! (roads, cells, lots, buildings, facades, export) speaks these types, so a stage can be
//! replaced by anyone who can build them by hand.
//!
//! | module | what |
//! |---|---|
//! | [`predicates`] | exact orientation and segment–segment classification |
//! | [`polygon`] | [`Polygon`], [`PolygonWithHoles`]: area, centroid, point location, validation |
//! | [`bbox`] | [`Aabb2`] |
//! | [`hash`] | [`hash::splitmix64`]: the stateless mix behind derived seeds |
//! | [`lines`] | offset lines and where they meet, angular order from any direction, splitting polygons and tagged regions by a line, which ring a hole belongs to |
//! | [`graph`] | [`PlanarGraph`]: a planar straight-line graph with stable ids, exact counter-clockwise adjacency, planar segment insertion |
//! | [`spatial`] | [`SegmentIndex`]: a hashed uniform grid over points and segments (box, nearest within a radius, segments crossing a segment in order); `spatial::RTreeIndex` (feature `rtree`) as the measured alternative |
//! | [`field`] | [`Field`]: input maps (population, water, elevation …) — constants, closures, PNG rasters, seeded simplex/fBm noise, the slides' `populationAt`, combinators, serde [`field::FieldSpec`] |
//! | [`measure`] | minimum enclosing circle (Welzl), segment–segment and segment–polygon distances |
//! | [`mesh`] | [`Mesh`]: f32 triangle meshes in glTF axes ([`to_world`]), constrained triangulation, prisms, closedness checks, cuts into ground-plane tiles |
//! | [`scene`] | [`Scene`]: node tree, materials, textures, images — the contract between generators and exporters |
//! | [`par`] | the one parallel-or-serial switch (rayon with feature `parallel`, plain iterators without) used by every crate that runs loops in parallel |
//! | [`metadata`] | [`Metadata`](metadata::Metadata): a node's small ordered map of [`MetaValue`]s (glTF `extras`, GeoJSON properties) |
//!
//! ## Numeric policy
//!
//! * Metres, `f64` ([`DVec2`], [`DVec3`]) everywhere inside; `f32` only in [`mesh`] data.
//! * Every left/right/on/crossing decision uses exact predicates ([`predicates`]); derived
//!   points are computed in floating point only after the topology is decided.
//! * Coordinates must be finite and within [`MAX_COORDINATE`] metres of the origin;
//!   validation reports anything else as a [`GeomError`].
//! * Polygons: simple rings, no repeated closing vertex, counter-clockwise outer rings,
//!   clockwise holes.
//!
//! ## Example
//!
//! ```
//! use polis_geom::{DVec2, Polygon, PointLocation};
//!
//! let lot = Polygon::rect(DVec2::new(0.0, 0.0), DVec2::new(20.0, 30.0));
//! lot.validate()?;
//! assert_eq!(lot.area(), 600.0);
//! assert_eq!(lot.locate(DVec2::new(5.0, 5.0)), PointLocation::Inside);
//! # Ok::<(), polis_geom::GeomError>(())
//! ```

pub use glam;
pub use glam::{DVec2, DVec3};

pub mod bbox;
pub mod error;
pub mod field;
pub mod graph;
pub mod hash;
mod inline_vec;
pub mod lines;
pub mod measure;
pub mod mesh;
pub mod metadata;
pub mod paint;
pub mod par;
pub mod polygon;
pub mod predicates;
pub mod scene;
mod simplicity;
pub mod simplify;
pub mod spatial;

pub use bbox::Aabb2;
pub use error::{GeomError, Ring};
pub use field::{Field, FieldExt};
pub use graph::{EdgeId, NodeId, PlanarGraph, SnapOptions};
pub use lines::{Line, ccw_cmp_from, meet, split_by_line, split_polygon_by_line};
pub use mesh::{Aabb3, Facing, Mesh, to_layout, to_world, triangulate};
pub use polygon::{PointLocation, Polygon, PolygonWithHoles};
pub use predicates::{
    AngleStart, Orientation, SegmentIntersection, ccw_cmp, orient2d, segment_intersection,
};
pub use scene::{Material, MaterialId, MeshId, MetaValue, Scene, Transform};
pub use spatial::{SegmentIndex, SpatialIndex};

/// The largest coordinate magnitude, in metres, that validation accepts (100,000 km).
///
/// Far beyond any city, and small enough that squared lengths and areas stay well inside
/// `f64`'s exact-integer and overflow ranges.
pub const MAX_COORDINATE: f64 = 1.0e8;
