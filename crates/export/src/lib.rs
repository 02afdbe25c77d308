//! # polis-export
//!
//! Writers that take a polis city out of memory: engine-ready 3-D models and 2-D maps.
//!
//! | writer | input | output |
//! |---|---|---|
//! | [`glb::write_glb`] | [`Scene`](geom::Scene) | glTF 2.0 binary: one buffer, PBR materials, embedded PNG textures; merged per layer, tile and material with per-vertex feature ids (default), per (parent, material), or one node per object; optional web profile (quantized, meshopt-compressed) |
//! | [`obj::write_obj`] | [`Scene`](geom::Scene) | Wavefront OBJ (one group per object, world space, triangles) + MTL + texture PNGs through a [`FileSink`](sink::FileSink) |
//! | [`svg::write_svg`] | [`MapLayers`](map::MapLayers) | SVG plan: water, parks, blocks, lots, roads by class and width, footprints by kind; north up |
//! | [`geojson::write_geojson`] | [`MapLayers`](map::MapLayers) | RFC 7946 FeatureCollection in a documented local metric coordinate system |
//! | [`surfaces::road_surfaces`] | [`MapRoad`](map::MapRoad)s + an elevation [`Field`](geom::Field) | a [`Mesh`](geom::Mesh) of road ribbons joined by junction polygons, dead-end caps (draped, bridges spanning) to put in a scene |
//! | [`footpaths::footpath_mesh`] | a block's footpath strip ([`PolygonWithHoles`](geom::PolygonWithHoles)) + an elevation [`Field`](geom::Field) | a kerb-high, draped, closed [`Mesh`](geom::Mesh) of the footpath |
//!
//! The 3-D input is `polis-geom`'s [`Scene`](geom::Scene) (what the building and facade
//! stages produce); the 2-D input is this crate's plain [`map`] model, which anyone can
//! fill by hand, so the exporters depend on no other stage crate.
//!
//! ## Example
//!
//! ```
//! use polis_export::geom::{DVec2, Polygon, Scene, mesh::prism, scene::Material};
//! use polis_export::{glb, obj, sink::MemorySink};
//!
//! let mut scene = Scene::new();
//! let brick = scene.add_material(Material::new("brick", [0.6, 0.3, 0.2, 1.0]));
//! let body = prism(&Polygon::rect(DVec2::ZERO, DVec2::new(8.0, 12.0)).into(), 0.0, 9.0, Some(brick))?;
//! let body = scene.add_mesh(body);
//! let city = scene.add_root("city");
//! let house = scene.add_node(city, "house 1")?;
//! scene.attach_mesh(house, body)?;
//! scene.set_metadata(house, "floors", 3.0)?;
//!
//! let mut glb_bytes = Vec::new();
//! glb::write_glb(&scene, &glb::GlbOptions::default(), &mut glb_bytes)?;
//! let doc = gltf::Gltf::from_slice(&glb_bytes)?;
//! // Tiled by default: city → layer `house 1` → one tile, one primitive per material;
//! // the house's record is in the city node's feature table.
//! assert_eq!(doc.nodes().count(), 3);
//!
//! let (mut obj_bytes, mut side_files) = (Vec::new(), MemorySink::new());
//! obj::write_obj(&scene, &obj::ObjOptions::default(), &mut obj_bytes, &mut side_files)?;
//! assert!(side_files.files.contains_key("scene.mtl"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## Features
//!
//! All on by default: `gltf` ([`glb`]), `obj` ([`obj`]), `svg` ([`svg`]), `geojson`
//! ([`geojson`]) — one per writer —, `png` (PNG encoding of raw scene images, needed by
//! the glb and OBJ writers) and `parallel` (the OBJ text formatted on rayon through
//! [`geom::par`]; the same bytes without), and `serde` (`Serialize`/`Deserialize` for
//! the option and surface types; `gltf` and `geojson` turn it on). [`map`],
//! [`surfaces`], [`footpaths`] and [`sink`] are always there.
//!
//! ## Guarantees
//!
//! * **Nothing invalid is written.** Scenes pass [`Scene::validate`](geom::Scene::validate)
//!   and maps [`MapLayers::validate`](map::MapLayers::validate) (NaN, infinities,
//!   out-of-range indices, broken trees, short rings) before the first byte; options are
//!   checked too. The error is a typed [`ExportError`].
//! * **Streaming.** Every writer writes through `impl Write` as it goes; no writer builds
//!   the whole file as a string or buffer (the glTF JSON chunk, PNG encodings, batched
//!   meshes and the OBJ text of about 256 Ki vertices at a time, formatted in parallel,
//!   are the only things assembled first).
//! * **Deterministic.** Identical input and options give identical bytes: array order
//!   everywhere, ordered maps only, fixed or shortest-round-trip number formatting.
//! * **Checked by real readers** in the tests: `gltf` (with validation) and a hand decoder
//!   of the binary chunk, `tobj`, `serde_json`, and an XML well-formedness checker; property
//!   tests export random scenes and maps and read them back.
//!
//! ## Limitations
//!
//! * Road surfaces ([`surfaces`]) join roads only where they share a point (a planar
//!   graph); roads that cross without one overlap (larger classes lifted on top).
//! * glTF: no KTX2/JPEG textures, no animations or cameras; a sheared node matrix is
//!   written as `matrix` (not a TRS). OBJ: no metallic-roughness texture map.
//! * GeoJSON positions are local metres, not WGS 84 (stated in the file; see [`geojson`]).
//!
//! ## References
//!
//! * Khronos, *glTF 2.0 Specification* (2021), §3.6 binary data, §3.7 geometry, §5.
//! * H. Butler et al., *RFC 7946: The GeoJSON Format* (2016), §3, §4.
//! * W3C, *Scalable Vector Graphics 1.1* (2011), paths and fill rules.
//! * G. Kelly, *An Interactive System for Procedural City Generation* (2008): batching
//!   geometry per cell and material for few draw calls.

#[cfg(feature = "gltf")]
pub use gltf;
pub use polis_geom as geom;

mod error;
pub mod footpaths;
#[cfg(feature = "geojson")]
pub mod geojson;
#[cfg(feature = "gltf")]
pub mod glb;
#[cfg(feature = "png")]
#[cfg_attr(not(all(feature = "gltf", feature = "obj")), allow(dead_code))]
mod images;
pub mod map;
#[cfg(feature = "obj")]
pub mod obj;
#[cfg(any(feature = "gltf", feature = "obj"))]
pub mod shared;
pub mod sink;
pub mod surfaces;
#[cfg(feature = "svg")]
pub mod svg;
#[cfg(feature = "obj")]
mod text;

pub use error::ExportError;
#[cfg(any(feature = "gltf", feature = "obj"))]
pub use shared::SharedScene;

#[cfg(test)]
mod testing;

// Random scenes and maps through every writer.
#[cfg(test)]
#[cfg(all(
    feature = "gltf",
    feature = "obj",
    feature = "svg",
    feature = "geojson"
))]
mod proptests;
