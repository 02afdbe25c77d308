//! The options of the glb writer: node layout, tile size, profile, LOD switch distances.

use crate::ExportError;

/// How scene nodes become glTF nodes and meshes. Which to use:
///
/// | layout | draw calls | use it for |
/// |---|---|---|
/// | [`Tiled`](Self::Tiled) (default) | ≈ materials × tiles | games and viewers: few draw calls, each layer (`roads`, `blocks`, `buildings`, `water`, `ground`, …) a node that can be hidden, streamed or given colliders tile by tile; buildings picked by their `_FEATURE_ID_0` |
/// | [`PerParentAndMaterial`](Self::PerParentAndMaterial) | materials × cells | tools that work cell by cell (the Citygen editor's regeneration unit) |
/// | [`PerNode`](Self::PerNode) | one per object and material | picking, editing, moving single buildings in a DCC tool (Blender); identical meshes stored once |
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Batching {
    /// One glTF node per scene node, each with its own metadata (picking, editing).
    /// Meshes with identical bytes are stored once and shared by every node drawing them.
    PerNode,
    /// Leaf nodes merged into their parent, one primitive per material (one mesh per
    /// cell in a polis city). Leaf metadata and triangle ranges in the mesh's
    /// `extras.objects`.
    PerParentAndMaterial,
    /// Geometry merged per layer, square tile of the ground plane, LOD level and
    /// material: `root → layer → layer tile → (LOD level)`. Every merged vertex carries
    /// the index of its object in the root's `extras.features` table (`_FEATURE_ID_0`).
    /// See the [module docs](super) for the layer, tile and feature rules. The default,
    /// here and in `polis::SceneConfig`.
    #[default]
    Tiled,
}

/// Which glTF extensions the writer may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum GlbProfile {
    /// Core glTF 2.0, no extension: every loader reads it (Godot, Unity, Unreal, Bevy,
    /// Blender, three.js). The default.
    #[default]
    Plain,
    /// For the web: `KHR_mesh_quantization` (positions as 16-bit integers on a grid of
    /// each mesh's bounds, normals and tangents as 8-bit) and `EXT_meshopt_compression`
    /// (meshoptimizer's vertex and index codecs, encoded by the pure-Rust
    /// `meshoptimizer-rs`). Both are listed in `extensionsRequired`, as their
    /// specifications demand for quantized attributes and for a fallback buffer without
    /// data: loaders without them (Bevy, Unreal, Godot's importer) refuse the file, so
    /// keep [`Plain`](Self::Plain) for those. three.js (with `MeshoptDecoder`) and Unity
    /// glTFast read it. Needs the crate feature `web` (on by default).
    Web,
}

impl std::str::FromStr for GlbProfile {
    type Err = ExportError;

    /// `plain` or `web` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "plain" | "default" => Ok(GlbProfile::Plain),
            "web" => Ok(GlbProfile::Web),
            other => Err(ExportError::InvalidOption {
                name: "profile",
                reason: format!("{other:?} is not a glb profile; give plain or web"),
            }),
        }
    }
}

impl std::fmt::Display for GlbProfile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            GlbProfile::Plain => "plain",
            GlbProfile::Web => "web",
        })
    }
}

/// Options of [`write_glb`](super::write_glb).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct GlbOptions {
    /// Node structure. Default: [`Batching::Tiled`].
    pub batching: Batching,
    /// Side of the square tiles of [`Batching::Tiled`] on the ground plane (glTF x and
    /// z), metres, finite and > 0. Larger tiles: fewer draw calls, coarser culling and
    /// streaming. Default: 250.
    pub tile_size_m: f64,
    /// Extensions the file may use. Default: [`GlbProfile::Plain`].
    pub profile: GlbProfile,
    /// Camera distance, metres, up to which the most detailed LOD level of a tile is
    /// drawn ([`Batching::Tiled`] with objects tagged `lod`); each coarser level takes
    /// over at twice the previous distance, the coarsest to infinity. Written in each
    /// LOD node's `extras.lod_range_m`; engines apply it themselves. Finite and > 0.
    /// Default: 300.
    pub lod_near_m: f64,
    /// [`GlbProfile::Web`] only: the largest width or height of an embedded texture,
    /// pixels, ≥ 1. Larger images are halved until they fit (normal maps averaged as
    /// vectors); images within it are re-encoded losslessly. The plain profile embeds
    /// every image at its size. Default: 256.
    pub web_texture_max_px: u32,
    /// [`Batching::PerNode`] only: sibling leaf nodes drawing the same mesh become one
    /// node drawing it per instance (`EXT_mesh_gpu_instancing`; their names and metadata
    /// in its `extras.instances`, numbered by the per-instance `_FEATURE_ID_0`). Read by
    /// three.js, Babylon.js and Unity glTFast; loaders without it (Godot, Unreal)
    /// draw one instance, so it is off by default. The other layouts merge shared
    /// meshes into their batches and ignore it. Default: false.
    pub gpu_instancing: bool,
}

impl Default for GlbOptions {
    fn default() -> Self {
        GlbOptions {
            batching: Batching::default(),
            tile_size_m: 250.0,
            profile: GlbProfile::default(),
            lod_near_m: 300.0,
            web_texture_max_px: 256,
            gpu_instancing: false,
        }
    }
}

impl GlbOptions {
    /// The default options with another layout.
    pub fn with_batching(batching: Batching) -> Self {
        GlbOptions {
            batching,
            ..GlbOptions::default()
        }
    }

    /// Checks the ranges documented on the fields.
    pub fn validate(&self) -> Result<(), ExportError> {
        for (name, v) in [
            ("tile_size_m", self.tile_size_m),
            ("lod_near_m", self.lod_near_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(ExportError::InvalidOption {
                    name,
                    reason: format!("{v} is not a finite length above 0 m"),
                });
            }
        }
        if self.web_texture_max_px == 0 {
            return Err(ExportError::InvalidOption {
                name: "web_texture_max_px",
                reason: "a texture needs at least 1 pixel".to_string(),
            });
        }
        if self.profile == GlbProfile::Web && !cfg!(feature = "web") {
            return Err(ExportError::InvalidOption {
                name: "profile",
                reason: "the web profile needs polis-export's cargo feature `web`".to_string(),
            });
        }
        Ok(())
    }
}
