//! [`City`]: every layer of a generated city, its statistics and report, and the writers.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use polis_buildings::Building;
use polis_cells::CellDecomposition;
#[cfg(feature = "geojson")]
use polis_export::geojson;
#[cfg(feature = "gltf")]
use polis_export::glb;
use polis_export::map::{MapBlock, MapFootprint, MapLayers, MapLot};
#[cfg(feature = "obj")]
use polis_export::obj;
#[cfg(feature = "obj")]
use polis_export::sink::{DirSink, FileSink};
#[cfg(feature = "svg")]
use polis_export::svg;
use polis_facades::TileSet;
use polis_geom::{DVec2, Field, Polygon, PolygonWithHoles, Scene, par};
use polis_lots::{Block, Lot};
use polis_roads::{GrowthReport, RoadNetwork};
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::output::{Formats, WriteOptions};
use crate::stages::{Dress, Skip, Stage};
use crate::{CityConfig, CityMaps};

/// A lot with its stable id and the cell it lies in.
#[derive(Debug, Clone, PartialEq)]
pub struct CityLot {
    /// Stable id: `cell id << 24 | index of the lot in its cell`. The building on it has
    /// the same id.
    pub id: u64,
    /// The cell it lies in.
    pub cell: u64,
    /// The lot, behind an `Arc` like [`City::buildings`]: a lot an edit leaves alone is
    /// shared between the cities before and after it (and the editor's memo) rather than
    /// copied; `Arc::make_mut` gives a private copy to change.
    pub lot: Arc<Lot>,
}

impl CityLot {
    /// Whether `self` and `other` are equal, looking first whether they share their lot
    /// (as an edited city's unchanged cells do), then at the lots themselves.
    pub fn same_as(&self, other: &CityLot) -> bool {
        self.id == other.id
            && self.cell == other.cell
            && (Arc::ptr_eq(&self.lot, &other.lot) || self.lot == other.lot)
    }
}

/// Time spent in one stage.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StageTiming {
    /// The stage.
    pub stage: Stage,
    /// Wall-clock time.
    pub time: Duration,
}

/// Counts and per-stage timings of a city.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct CityStats {
    /// Road segments (graph edges).
    pub road_segments: usize,
    /// Junctions (graph nodes).
    pub junctions: usize,
    /// Cells.
    pub cells: usize,
    /// Blocks.
    pub blocks: usize,
    /// Lots.
    pub lots: usize,
    /// Buildings.
    pub buildings: usize,
    /// Buildings dressed with facade tiles.
    pub dressed_buildings: usize,
    /// Facade tile textures (each with albedo, normal and metallic-roughness images).
    pub facade_tiles: usize,
    /// Texture memory of the facade tiles, bytes.
    pub texture_bytes: usize,
    /// Triangles of the building meshes.
    pub building_triangles: usize,
    /// Triangles of the whole scene (0 when the scene was not built).
    pub scene_triangles: usize,
    /// Time per stage, in pipeline order. The building grammars and the facade tile
    /// sets are prepared while the roads grow, so the stage times can add up to more
    /// than [`wall_time`](Self::wall_time).
    pub timings: Vec<StageTiming>,
    /// Wall-clock time of the whole run (with [`Pipeline::stream`](crate::Pipeline::stream),
    /// including the sink's time).
    #[serde(default)]
    pub wall_time: Duration,
    /// Cut and fill of the roads graded into the land (zero without an elevation map or
    /// with [`SceneConfig::grade_roads`](crate::SceneConfig::grade_roads) off).
    #[serde(default)]
    pub earthworks: polis_roads::Earthworks,
}

impl CityStats {
    /// Wall-clock time of the whole run ([`wall_time`](Self::wall_time)).
    pub fn total_time(&self) -> Duration {
        self.wall_time
    }

    /// Time of one stage (zero if it did not run).
    pub fn time(&self, stage: Stage) -> Duration {
        self.timings
            .iter()
            .filter(|t| t.stage == stage)
            .map(|t| t.time)
            .sum()
    }
}

/// Degenerate items skipped on the way, with reasons.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SkipReport {
    /// Every skipped item, in pipeline order.
    pub skipped: Vec<Skip>,
    /// Settings that are valid but leave the city empty or nearly so
    /// ([`CityConfig::warnings`](crate::CityConfig::warnings)), and empty results (no
    /// road, no building), with the field to change. Default: none.
    #[serde(default)]
    pub warnings: Vec<String>,
}

impl SkipReport {
    /// How many items `stage` skipped.
    pub fn count(&self, stage: Stage) -> usize {
        self.skipped.iter().filter(|s| s.stage == stage).count()
    }

    /// Whether nothing was skipped.
    pub fn is_empty(&self) -> bool {
        self.skipped.is_empty()
    }
}

/// A generated city: every layer, the scene, statistics and the skip report.
#[derive(Debug)]
pub struct City {
    /// The configuration it was made from.
    pub config: CityConfig,
    /// The input maps.
    pub maps: CityMaps,
    /// The road network (planar).
    pub roads: RoadNetwork,
    /// The road generator's report, when the road stage gives one.
    pub growth: Option<GrowthReport>,
    /// Cells of the road graph.
    pub cells: CellDecomposition,
    /// Blocks, cell by cell. Each is behind an `Arc`, shared like
    /// [`buildings`](Self::buildings).
    pub blocks: Vec<Arc<Block>>,
    /// Lots, cell by cell (each lot behind an `Arc`: [`CityLot::lot`]).
    pub lots: Vec<CityLot>,
    /// Green spaces inside blocks.
    pub green_spaces: Vec<PolygonWithHoles>,
    /// The lot subdivision's split lines in the order they were cut, with the id of the
    /// block each belongs to (Kelly §5.5.1's debug view; [`City::debug_map`]). Each line
    /// is behind an `Arc`, shared like [`buildings`](Self::buildings).
    pub lot_splits: Vec<(u64, Arc<polis_lots::SplitLine>)>,
    /// Buildings (one per built lot; `id` = the lot's id). Each is behind an `Arc`: a
    /// building an edit leaves alone is shared between the cities before and after it
    /// (and the editor's memo) rather than copied; `Arc::make_mut` gives a private copy
    /// to change.
    pub buildings: Vec<Arc<Building>>,
    /// Cell of each building (parallel to `buildings`).
    pub building_cells: Vec<u64>,
    /// Shared facade tile sets, one per style in use.
    pub tile_sets: Vec<TileSet>,
    /// Facade skin of each building (parallel to `buildings`).
    /// Each is behind an `Arc`, shared like [`buildings`](Self::buildings).
    pub dresses: Vec<Option<Arc<Dress>>>,
    /// The 3-D scene (empty when `scene` was switched off).
    pub scene: Scene,
    /// Counts and timings.
    pub stats: CityStats,
    /// What was skipped.
    pub report: SkipReport,
}

/// Which files [`City::write_all`] wrote.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Written {
    /// Every file written, textures included (see [`City::write_all_with`] for the
    /// order).
    pub files: Vec<PathBuf>,
}

/// Creates `path`, lets `write` fill it through a buffer, flushes, and returns the path.
#[cfg_attr(
    not(any(
        feature = "gltf",
        feature = "obj",
        feature = "svg",
        feature = "geojson"
    )),
    allow(dead_code)
)]
fn write_file(
    path: PathBuf,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<()>,
) -> Result<PathBuf> {
    let io = |source| Error::Io {
        path: path.clone(),
        source,
    };
    // A buffer of 1 MiB: the text writers hand over many small pieces (an OBJ group,
    // a GeoJSON feature), and the default 8 KiB made one system call per few of them.
    let mut w = BufWriter::with_capacity(1 << 20, File::create(&path).map_err(io)?);
    write(&mut w)?;
    w.flush().map_err(io)?;
    Ok(path)
}

impl City {
    /// The 2-D map layers (water, parks, blocks, lots, roads, footprints) for the SVG and
    /// GeoJSON writers. Water and parks are the smooth outlines of their maps (≥ 0.5),
    /// traced on a 10 m grid and simplified to 1 m ([`smooth_mask`]).
    pub fn map_layers(&self) -> Result<MapLayers> {
        let mut map = MapLayers::default();
        if self.maps.has_water {
            map.water = smooth_mask(self.maps.inputs.water.as_ref(), self.config.size_m)?;
        }
        if self.maps.has_parks {
            map.parks = smooth_mask(self.maps.inputs.parks.as_ref(), self.config.size_m)?;
        }
        map.parks.extend(self.green_spaces.iter().cloned());
        map.roads = crate::scene::map_roads(&self.roads)?;
        map.blocks = self
            .blocks
            .iter()
            .map(|b| MapBlock {
                id: b.id(),
                polygon: b.polygon.clone(),
            })
            .collect();
        map.lots = self
            .lots
            .iter()
            .map(|l| MapLot {
                id: l.id,
                block: Some(l.lot.block_id),
                polygon: l.lot.polygon.clone().into(),
            })
            .collect();
        map.footprints = self
            .buildings
            .iter()
            .map(|b| MapFootprint {
                id: b.id,
                polygon: b.footprint.clone().into(),
                kind: crate::scene::map_kind(b.kind),
                height_m: b.height,
                floors: Some(b.floors),
                lot: Some(b.lot_id),
            })
            .collect();
        Ok(map)
    }

    /// Writes the scene as glb (layout and tile size from the configuration, the plain
    /// profile).
    ///
    /// # Errors
    /// Export and I/O errors.
    #[cfg(feature = "gltf")]
    pub fn write_glb<W: Write>(&self, out: W) -> Result<glb::GlbReport> {
        self.write_glb_with(out, glb::GlbProfile::Plain)
    }

    /// [`write_glb`](Self::write_glb) with a profile ([`glb::GlbProfile::Web`]:
    /// quantized and meshopt-compressed).
    ///
    /// # Errors
    /// Export and I/O errors.
    #[cfg(feature = "gltf")]
    pub fn write_glb_with<W: Write>(
        &self,
        out: W,
        profile: glb::GlbProfile,
    ) -> Result<glb::GlbReport> {
        Ok(glb::write_glb(
            &self.scene,
            &self.glb_options(profile),
            out,
        )?)
    }

    /// The glb options of [`write_glb_with`](Self::write_glb_with).
    #[cfg(feature = "gltf")]
    fn glb_options(&self, profile: glb::GlbProfile) -> glb::GlbOptions {
        glb::GlbOptions {
            batching: self.config.scene.batching,
            tile_size_m: self.config.scene.tile_size_m,
            profile,
            ..glb::GlbOptions::default()
        }
    }

    /// Writes the chosen `formats` into `dir` (created if missing): `city.glb`,
    /// `city.obj` (+ `city.mtl` and the texture PNGs in `textures/`), `city.svg` and
    /// `city.geojson` (local metres). `Formats::ALL` writes all four.
    ///
    /// # Errors
    /// Export and I/O errors, naming the file.
    pub fn write_all(&self, dir: impl AsRef<Path>, formats: Formats) -> Result<Written> {
        self.write_all_with(dir, &formats.into())
    }

    /// [`write_all`](Self::write_all) with every option: the formats and the GeoJSON's
    /// geographic anchor (WGS 84 longitude/latitude output). [`Written`] lists every file
    /// written, textures included, in a fixed order: svg, geojson, glb, obj, mtl, then
    /// the textures by name.
    ///
    /// # Errors
    /// Export and I/O errors, naming the file; [`Error::Export`] for an anchor outside
    /// WGS 84 bounds or a map that would cross the antimeridian or reach a pole there.
    pub fn write_all_with(&self, dir: impl AsRef<Path>, options: &WriteOptions) -> Result<Written> {
        let dir = dir.as_ref();
        let formats = options.formats;
        if let Some((format, feature)) = formats.not_compiled() {
            return Err(Error::config(
                "formats",
                format!("{format} needs the feature {feature} of polis-city"),
            ));
        }
        std::fs::create_dir_all(dir).map_err(|source| Error::Io {
            path: dir.into(),
            source,
        })?;
        // The files are written at the same time (the OBJ text is also formatted in
        // parallel); the first error in the order below is returned. The glb and OBJ
        // writers validate the scene and encode its textures once between them.
        #[cfg(any(feature = "gltf", feature = "obj"))]
        let shared = polis_export::SharedScene::new(&self.scene);
        #[cfg(any(feature = "svg", feature = "geojson"))]
        let maps = || -> Result<Vec<PathBuf>> {
            if !(formats.svg || formats.geojson) {
                return Ok(Vec::new());
            }
            #[allow(unused_mut)]
            let mut map = self.map_layers()?;
            let mut files = Vec::new();
            #[cfg(feature = "svg")]
            if formats.svg {
                if options.svg_debug.any() {
                    map.debug = self.debug_map()?;
                }
                let svg_options = svg::SvgOptions {
                    debug: options.svg_debug.clone(),
                    ..svg::SvgOptions::default()
                };
                files.push(write_file(dir.join("city.svg"), |w| {
                    svg::write_svg(&map, &svg_options, w)?;
                    Ok(())
                })?);
            }
            #[cfg(feature = "geojson")]
            if formats.geojson {
                let geo = geojson::GeoJsonOptions {
                    anchor_lon_lat: options.anchor_lon_lat,
                    coordinates: match options.anchor_lon_lat {
                        Some(_) => geojson::Coordinates::Wgs84,
                        None => geojson::Coordinates::Local,
                    },
                    ..geojson::GeoJsonOptions::default()
                };
                files.push(write_file(dir.join("city.geojson"), |w| {
                    geojson::write_geojson(&map, &geo, w)?;
                    Ok(())
                })?);
            }
            Ok(files)
        };
        #[cfg(not(any(feature = "svg", feature = "geojson")))]
        let maps = || -> Result<Vec<PathBuf>> { Ok(Vec::new()) };
        #[cfg(feature = "gltf")]
        let glb = || -> Result<Vec<PathBuf>> {
            if !formats.glb {
                return Ok(Vec::new());
            }
            let path = write_file(dir.join("city.glb"), |w| {
                let glb_options = self.glb_options(options.glb_profile);
                glb::write_glb_shared(&shared, &glb_options, w)?;
                Ok(())
            })?;
            Ok(vec![path])
        };
        #[cfg(not(feature = "gltf"))]
        let glb = || -> Result<Vec<PathBuf>> { Ok(Vec::new()) };
        #[cfg(feature = "obj")]
        let obj = || -> Result<Vec<PathBuf>> {
            if !formats.obj {
                return Ok(Vec::new());
            }
            let mut sink = RecordingSink {
                inner: DirSink::new(dir),
                names: Vec::new(),
            };
            let path = write_file(dir.join("city.obj"), |w| {
                let options = obj::ObjOptions {
                    stem: "city".into(),
                    texture_dir: crate::output::TEXTURE_DIR.into(),
                };
                obj::write_obj_shared(&shared, &options, w, &mut sink)?;
                Ok(())
            })?;
            // The MTL first, then the textures by name.
            sink.names
                .sort_by_key(|n| (!n.ends_with(".mtl"), n.clone()));
            let mut files = vec![path];
            files.extend(sink.names.iter().map(|n| dir.join(n)));
            Ok(files)
        };
        #[cfg(not(feature = "obj"))]
        let obj = || -> Result<Vec<PathBuf>> { Ok(Vec::new()) };
        let (maps, (glb, obj)) = par::join(maps, || par::join(glb, obj));
        let mut files = maps?;
        files.extend(glb?);
        files.extend(obj?);
        Ok(Written { files })
    }
}

/// A [`DirSink`] that remembers the names of the files it wrote.
#[cfg(feature = "obj")]
struct RecordingSink {
    inner: DirSink,
    names: Vec<String>,
}

#[cfg(feature = "obj")]
impl FileSink for RecordingSink {
    fn write_file(&mut self, name: &str, contents: &[u8]) -> std::io::Result<()> {
        self.inner.write_file(name, contents)?;
        self.names.push(name.to_string());
        Ok(())
    }

    fn create(&mut self, name: &str) -> std::io::Result<Box<dyn Write + '_>> {
        let w = self.inner.create(name)?;
        self.names.push(name.to_string());
        Ok(w)
    }
}

/// The area where `mask ≥ 0.5` inside the square map of side `size_m` (centred on the
/// origin), as smooth polygons: marching squares on a 10 m grid, simplified to 1 m
/// ([`polis_geom::field::contour_regions`]). The water and park layers of the maps and
/// the water surfaces of the scene.
///
/// # Errors
/// A size that is not a positive finite number of metres.
pub fn smooth_mask(mask: &dyn Field, size_m: f64) -> Result<Vec<PolygonWithHoles>> {
    let h = size_m * 0.5;
    let bounds = polis_geom::Aabb2::new(DVec2::splat(-h), DVec2::splat(h));
    Ok(polis_geom::field::contour_regions(
        mask,
        bounds,
        &polis_geom::field::ContourOptions::default(),
    )?)
}

/// The area where `mask ≥ 0.5` inside the square map of side `size_m`, as row runs of
/// `cell_m` squares merged into rectangles (exact on the sampling grid; for drawing).
pub fn trace_mask(mask: &dyn Field, size_m: f64, cell_m: f64) -> Vec<PolygonWithHoles> {
    let n = ((size_m / cell_m).ceil() as usize).clamp(1, 4096);
    let step = size_m / n as f64;
    let h = size_m * 0.5;
    let mut out = Vec::new();
    // Runs of the previous row still open: (start column, end column, start row).
    let mut open: Vec<(usize, usize, usize)> = Vec::new();
    let rect = |c0: usize, c1: usize, r0: usize, r1: usize| {
        let at = |c: usize, r: usize| DVec2::new(-h + c as f64 * step, -h + r as f64 * step);
        PolygonWithHoles::from(Polygon::rect(at(c0, r0), at(c1, r1)))
    };
    for r in 0..=n {
        let mut runs = Vec::new();
        if r < n {
            let y = -h + (r as f64 + 0.5) * step;
            let mut c = 0;
            while c < n {
                let inside =
                    |c: usize| mask.sample(DVec2::new(-h + (c as f64 + 0.5) * step, y)) >= 0.5;
                if inside(c) {
                    let c0 = c;
                    while c < n && inside(c) {
                        c += 1;
                    }
                    runs.push((c0, c));
                } else {
                    c += 1;
                }
            }
        }
        // A run continues an open rectangle with exactly the same columns.
        let mut next = Vec::with_capacity(runs.len());
        for &(c0, c1) in &runs {
            match open.iter().position(|&(a, b, _)| a == c0 && b == c1) {
                Some(i) => next.push(open.swap_remove(i)),
                None => next.push((c0, c1, r)),
            }
        }
        for (c0, c1, r0) in open.drain(..) {
            out.push(rect(c0, c1, r0, r));
        }
        open = next;
    }
    out.sort_by(|a: &PolygonWithHoles, b: &PolygonWithHoles| {
        let (pa, pb) = (a.outer.points()[0], b.outer.points()[0]);
        pa.y.total_cmp(&pb.y).then(pa.x.total_cmp(&pb.x))
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use polis_geom::field::FnField;

    #[test]
    fn city_lots_are_the_same_when_shared_or_equal() {
        let lot = |x: f64| Lot {
            polygon: Polygon::new(vec![
                DVec2::new(x, 0.0),
                DVec2::new(x + 10.0, 0.0),
                DVec2::new(x + 10.0, 20.0),
            ]),
            street_edges: vec![0],
            block_id: 7,
            area: 100.0,
        };
        let shared = Arc::new(lot(0.0));
        let a = CityLot {
            id: 1 << 24,
            cell: 1,
            lot: Arc::clone(&shared),
        };
        let b = CityLot {
            lot: shared,
            ..a.clone()
        };
        assert!(a.same_as(&b), "one lot, shared");
        let copy = CityLot {
            lot: Arc::new(lot(0.0)),
            ..a.clone()
        };
        assert!(a.same_as(&copy), "an equal copy");
        let moved = CityLot {
            lot: Arc::new(lot(1.0)),
            ..a.clone()
        };
        assert!(!a.same_as(&moved), "another polygon");
        let renumbered = CityLot {
            id: a.id + 1,
            ..a.clone()
        };
        assert!(!a.same_as(&renumbered), "one lot under another id");
    }

    #[test]
    fn traced_mask_area_matches_the_sampled_area() {
        // A disc of radius 300 m: traced area within one cell ring of π r².
        let disc = FnField::new(|p: DVec2| if p.length() < 300.0 { 1.0 } else { 0.0 });
        let polys = trace_mask(&disc, 1000.0, 10.0);
        let area: f64 = polys.iter().map(|p| p.area()).sum();
        let exact = std::f64::consts::PI * 300.0 * 300.0;
        assert!(
            (area - exact).abs() < 2.0 * std::f64::consts::PI * 300.0 * 10.0,
            "{area}"
        );
        for p in &polys {
            p.validate().unwrap();
        }
    }
}
