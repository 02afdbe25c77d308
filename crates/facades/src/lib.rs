//! # polis-facades
//!
//! Layered-grid procedural facades after Parish & Müller, *Procedural Modeling of Cities*
//! (SIGGRAPH 2001) §4.3, rendered to glTF-ready textures or to window/door geometry, with
//! shared tile sets fitted without cutting tiles after Kelly, *Citygen* (2008) §4.4.3.3
//! and §5.6.
//!
//! ## The model
//!
//! | paper | here |
//! |---|---|
//! | interval group: ordered, non-overlapping intervals | [`IntervalGroup`] (built by hand or by [`AxisStyle::fit`] for any length) |
//! | PULSE functions on the intervals | [`Profile`] |
//! | layer = two interval groups + *eval* + *col* | [`Layer`] `{ u, v, eval, col, .. }` |
//! | AND / OR, procedural, image map, nested layer, layer stack as *eval* | [`Eval`] |
//! | colour (or bump, reflectivity) function | [`Col`] → [`FacadeSample`] |
//! | layer stacks falling through to the layer below | [`LayerStack`] |
//! | functions between layers (scaling cells, bricks around windows) | [`Influence`] |
//! | style texture that fits any facade size | [`FacadeStyle`] (serde data) → [`Facade`] |
//! | building tiles fitted without splitting (Kelly) | [`TileSet`], [`Facade::tile_quads`], [`TilePlan`] |
//!
//! A [`FacadeStyle`] is data: a primary grid (columns and rows as [`AxisStyle`]s with
//! fixed margins, a repeated module and named irregular rows such as the ground floor and
//! the cornice) and a [`StackStyle`] of layers. [`PreparedStyle::facade`] fits it to a
//! [`FacadeSpec`] (width, height, floors, role, seed) and gives a [`Facade`], which can be
//!
//! 1. evaluated at any point ([`Facade::sample`], O(log n): binary search per axis),
//! 2. rasterised ([`Facade::rasterize`]) into albedo, normal (from the height field) and
//!    metallic-roughness textures at a chosen resolution,
//! 3. reduced to its active cells with roles ([`Facade::cells`]) for geometry mode, or
//! 4. covered with quads of the style's shared [`TileSet`] ([`Facade::tile_quads`]), so a
//!    city of tens of thousands of buildings embeds one small tile set per style.
//!
//! Built-in styles: [`builtin::brick_house`], [`builtin::office_curtain_wall`],
//! [`builtin::classic_stone`], [`builtin::industrial`].
//!
//! ## Example
//!
//! ```
//! use polis_facades::{builtin, CellRole, FacadeSpec, PreparedStyle, RasterOptions};
//!
//! let style = PreparedStyle::new(builtin::brick_house())?;
//! let facade = style.facade(&FacadeSpec::new(10.0, 8.5, 42))?;
//! // Point evaluation, in metres from the bottom-left corner.
//! let here = facade.sample(2.0, 1.5);
//! assert!(here.is_valid());
//! // Geometry mode: the window openings, never cut by the facade's edges.
//! let windows = facade.cells_with_roles(&[CellRole::Window]);
//! assert!(windows.iter().all(|w| w.rect.min.x >= 0.0 && w.rect.max.x <= 10.0));
//! // Texture mode at 16 texels per metre.
//! let tex = facade.rasterize(&RasterOptions { pixels_per_metre: 16.0, ..Default::default() })?;
//! assert_eq!((tex.width, tex.height), (160, 136));
//! # Ok::<(), polis_facades::FacadeError>(())
//! ```
//!
//! ## Guarantees
//!
//! * Interval groups cover `[0, L]` exactly, in order, without overlap, for every `L` at
//!   least the style's minimum; rigid segments (windows) keep their size, so windows are
//!   never cut at facade edges nor stretched.
//! * Deterministic: the same style and spec (seed included) give bit-identical samples,
//!   textures, cells and quads. The facade seed drives a `rand_pcg` generator that seeds
//!   the layers; per-cell choices hash the layer seed with the cell index, so a point can
//!   be evaluated alone.
//! * Rasterised textures equal point evaluation at the texel centres: the span rasteriser
//!   ([`sweep`]) finds each layer's active runs per row analytically, emits each row as
//!   runs of equal samples (converted once per run, normals derived per run of equal
//!   heights), and is tested texel-for-texel against [`Facade::sample`] and byte-for-byte
//!   against a texel-by-texel rasteriser on every built-in style.
//! * No panics on user input: bad numbers, malformed styles and oversized textures are
//!   [`FacadeError`]s; faces smaller than the style get a blank grid (recorded in
//!   [`FacadeReport`]).
//!
//! ## Limitations
//!
//! * Image maps are sampled nearest-texel; built-in images are drawn procedurally (scans
//!   can be loaded with [`MaterialImage::from_png`] into layers built in code, or given as
//!   [`ImageStyle::Rgba`] data).
//! * Closures ([`Eval::Custom`], [`Col::Custom`]) are available for layers built in code,
//!   not in serialised styles.
//! * Tile sets repeat a prototype: they are exact only where everything repeats with the
//!   modules. [`PreparedStyle::tile_plan`] reports, per facade and without building its
//!   stack, the regions where they are not (stretched modules, layers on their own axes or
//!   on particular storeys, patterns out of step with the bays, entrance influences
//!   leaving the entrance bay) and the random detail they repeat (see [`tile_plan`]).
//!
//! ## References
//!
//! * Y. I. H. Parish, P. Müller, *Procedural Modeling of Cities*, SIGGRAPH 2001, §4.3.
//! * G. Kelly, *An Interactive System for Procedural City Generation*, 2008, §4.4.3.3, §5.6.
//! * D. Ebert et al., *Texturing and Modeling: A Procedural Approach* (PULSE).

pub use polis_geom as geom;
/// The random-number crates of this crate's public signatures (`Rng` bounds, `Pcg64Mcg`),
/// re-exported so callers never match their versions by hand.
pub use rand;
#[doc(no_inline)]
pub use rand_pcg;

pub mod axis;
pub mod builtin;
pub mod color;
pub mod error;
pub mod facade;
pub mod geometry;
pub mod image;
pub mod interval;
pub mod layer;
pub mod profile;
pub mod raster;
pub mod sample;
pub mod stack;
pub mod street;
pub mod style;
pub mod sweep;
pub mod tile_plan;
pub mod tiles;

pub use axis::{AxisStyle, Segment};
pub use color::{Bricks, Col, ColFn, PointCtx};
pub use error::{FacadeError, FacadesError, Result};
pub use facade::{
    Facade, FacadeLayout, FacadeReport, FacadeSpec, FacadeStyle, FaceRole, PreparedStyle,
};
pub use geometry::{FacadeCell, LayerName};
pub use image::{ImageSet, ImageStyle, MaterialImage};
pub use interval::{Hit, Interval, IntervalGroup, Part};
pub use layer::{CellRole, Eval, EvalFn, Layer, Probe};
pub use profile::Profile;
#[cfg(feature = "png")]
pub use raster::encode_png;
pub use raster::{FacadeTextures, RasterOptions};
pub use sample::FacadeSample;
pub use stack::{Influence, LayerStack, Relation};
pub use style::{AxisRef, EvalStyle, InfluenceStyle, LayerStyle, Pick, Select, StackStyle};
pub use tile_plan::{TileIssue, TileIssueKind, TilePlan};
pub use tiles::{Tile, TileOptions, TileQuad, TileSet};

/// Largest length of a facade, axis or segment, metres (100 km).
pub const MAX_LENGTH_M: f64 = 1.0e5;

/// Smallest length of a style segment, metres (1 mm).
pub const MIN_SEGMENT_M: f64 = 1.0e-3;

/// Most intervals in one interval group.
pub const MAX_INTERVALS: usize = 1 << 20;

/// Most storeys a facade spec may ask for.
pub const MAX_FLOORS: u32 = 10_000;

/// Most texels in one rasterised texture (2²⁷ ≈ 134 million, e.g. 16384 × 8192).
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 27;
