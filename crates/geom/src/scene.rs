//! Scenes: what generators produce and exporters write.
//!
//! A [`Scene`] holds flat arrays of [`Node`]s, [`Mesh`]es, [`Material`]s, [`Texture`]s and
//! [`Image`]s, referring to each other by typed indices ([`NodeId`], [`MeshId`],
//! [`MaterialId`], [`TextureId`], [`ImageId`]), the shape of a glTF document. The nodes form
//! a tree (a forest under [`Scene::roots`]): city → districts/cells → blocks → buildings,
//! each with a name, a local [`Transform`], its meshes and ordered metadata (glTF `extras`).
//!
//! Build with [`Scene::add_node`], [`Scene::add_mesh`], [`Scene::add_material`], … which
//! check their references and return typed ids; or fill the public fields by hand and call
//! [`Scene::validate`], which every exporter calls before writing.
//!
//! ```
//! use polis_geom::{DVec2, Polygon, mesh::prism};
//! use polis_geom::scene::{Material, MetaValue, Scene, Transform};
//!
//! let mut scene = Scene::new();
//! let brick = scene.add_material(Material::new("brick", [0.6, 0.3, 0.2, 1.0]));
//! let footprint = Polygon::rect(DVec2::ZERO, DVec2::new(8.0, 12.0));
//! let body = scene.add_mesh(prism(&footprint.into(), 0.0, 9.0, Some(brick))?);
//! let city = scene.add_root("city");
//! let house = scene.add_node(city, "house 17")?;
//! scene.attach_mesh(house, body)?;
//! scene.set_metadata(house, "floors", MetaValue::Number(3.0))?;
//! scene.node_mut(house)?.transform = Transform::from_translation([100.0, 0.0, -40.0].into());
//! scene.validate()?;
//! # Ok::<(), polis_geom::GeomError>(())
//! ```
//!
//! Mapping to glTF: a node's meshes become the primitives of one glTF mesh (each
//! [`Mesh`] is a primitive with one material); [`ImageData::Png`] bytes are embedded as
//! they are and [`ImageData::Rgba8`] pixels are encoded to PNG by the exporter.

use std::borrow::Cow;

use glam::{DMat4, DQuat, DVec3};

use crate::GeomError;
use crate::mesh::{Mesh, MeshSurvey};
pub use crate::metadata::{MetaValue, Metadata};

macro_rules! typed_id {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
        #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
        #[cfg_attr(feature = "serde", serde(transparent))]
        pub struct $name(pub u32);

        impl $name {
            /// The index into the scene's array.
            #[inline]
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }
    };
}

typed_id!(
    /// Index of a node in [`Scene::nodes`].
    NodeId
);
typed_id!(
    /// Index of a mesh in [`Scene::meshes`].
    MeshId
);
typed_id!(
    /// Index of a material in [`Scene::materials`].
    MaterialId
);
typed_id!(
    /// Index of a texture in [`Scene::textures`].
    TextureId
);
typed_id!(
    /// Index of an image in [`Scene::images`].
    ImageId
);

/// How far from 1 the length of a [`Transform::Trs`] rotation quaternion may be.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// A node's placement relative to its parent (world axes, metres).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Transform {
    /// Translation, rotation (unit quaternion) and scale, applied as `T · R · S`.
    Trs {
        /// Translation in metres.
        translation: DVec3,
        /// Rotation, a unit quaternion.
        rotation: DQuat,
        /// Scale factors per axis (non-zero).
        scale: DVec3,
    },
    /// A general affine matrix (column-major; last row `(0, 0, 0, 1)`).
    Matrix(DMat4),
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    /// No movement.
    pub const IDENTITY: Transform = Transform::Trs {
        translation: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
        scale: DVec3::ONE,
    };

    /// A pure translation.
    pub fn from_translation(translation: DVec3) -> Self {
        Transform::Trs {
            translation,
            rotation: DQuat::IDENTITY,
            scale: DVec3::ONE,
        }
    }

    /// The transform as a matrix.
    pub fn matrix(&self) -> DMat4 {
        match *self {
            Transform::Trs {
                translation,
                rotation,
                scale,
            } => DMat4::from_scale_rotation_translation(scale, rotation, translation),
            Transform::Matrix(m) => m,
        }
    }

    /// Why the transform cannot be exported, if it cannot: non-finite values, a rotation
    /// that is not a unit quaternion (within [`ROTATION_TOLERANCE`]), a zero scale, a projective or singular
    /// matrix.
    fn problem(&self) -> Option<&'static str> {
        match *self {
            Transform::Trs {
                translation,
                rotation,
                scale,
            } => {
                if !translation.is_finite() || !rotation.is_finite() || !scale.is_finite() {
                    Some("a value is not finite")
                } else if (rotation.length() - 1.0).abs() > ROTATION_TOLERANCE {
                    Some("the rotation is not a unit quaternion; normalise it")
                } else if scale.x == 0.0 || scale.y == 0.0 || scale.z == 0.0 {
                    Some("a scale factor is zero")
                } else {
                    None
                }
            }
            Transform::Matrix(m) => {
                if !m.is_finite() {
                    Some("a value is not finite")
                } else if m.row(3) != glam::DVec4::new(0.0, 0.0, 0.0, 1.0) {
                    Some("the matrix is projective; its last row must be (0, 0, 0, 1)")
                } else if m.determinant() == 0.0 {
                    Some("the matrix is singular")
                } else {
                    None
                }
            }
        }
    }
}

/// One node of the scene tree.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Node {
    /// A name for people and tools (need not be unique).
    pub name: String,
    /// Placement relative to the parent.
    pub transform: Transform,
    /// The meshes drawn at this node, in order.
    pub meshes: Vec<MeshId>,
    /// Child nodes, in order.
    pub children: Vec<NodeId>,
    /// Metadata in key order (deterministic output).
    pub metadata: Metadata,
}

impl Node {
    /// A node with a name, the identity transform and nothing else.
    pub fn new(name: impl Into<String>) -> Self {
        Node {
            name: name.into(),
            ..Node::default()
        }
    }
}

/// A metallic-roughness PBR material (glTF 2.0 core).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Material {
    /// A name for people and tools.
    pub name: String,
    /// Base colour factor, linear RGBA, each in `[0, 1]`. Default: opaque white.
    pub base_color: [f32; 4],
    /// Metalness in `[0, 1]`. Default: 0 (a dielectric: brick, concrete, asphalt).
    pub metallic: f32,
    /// Perceptual roughness in `[0, 1]`. Default: 0.9 (matte).
    pub roughness: f32,
    /// Base colour texture (sRGB), multiplied by `base_color`. Default: none.
    pub base_color_texture: Option<TextureId>,
    /// Tangent-space normal map. Default: none.
    pub normal_texture: Option<TextureId>,
    /// Metallic (blue) and roughness (green) texture, multiplied by the factors.
    /// Default: none.
    pub metallic_roughness_texture: Option<TextureId>,
    /// Whether back faces are drawn too (for open surfaces such as sheets). Default: false.
    pub double_sided: bool,
    /// Whether exporters keep the texture coordinates of meshes drawn with this material
    /// although it has no texture (surfaces whose metre coordinates an engine may texture
    /// later: road ribbons, junction plates, footpaths). A textured material always keeps
    /// them; an untextured one without this flag drops them (glTF validators list unused
    /// `TEXCOORD_0` attributes). Default: false.
    #[cfg_attr(feature = "serde", serde(default))]
    pub keep_texture_coordinates: bool,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: String::new(),
            base_color: [1.0; 4],
            metallic: 0.0,
            roughness: 0.9,
            base_color_texture: None,
            normal_texture: None,
            metallic_roughness_texture: None,
            double_sided: false,
            keep_texture_coordinates: false,
        }
    }
}

impl Material {
    /// A plain material with a name and base colour (linear RGBA).
    pub fn new(name: impl Into<String>, base_color: [f32; 4]) -> Self {
        Material {
            name: name.into(),
            base_color,
            ..Material::default()
        }
    }

    /// Whether meshes drawn with this material need texture coordinates in an export: it
    /// has a texture, or [`keep_texture_coordinates`](Self::keep_texture_coordinates).
    pub fn uses_texture_coordinates(&self) -> bool {
        self.keep_texture_coordinates
            || self.base_color_texture.is_some()
            || self.normal_texture.is_some()
            || self.metallic_roughness_texture.is_some()
    }

    fn textures(&self) -> impl Iterator<Item = (&'static str, TextureId)> {
        [
            ("base colour texture", self.base_color_texture),
            ("normal texture", self.normal_texture),
            (
                "metallic-roughness texture",
                self.metallic_roughness_texture,
            ),
        ]
        .into_iter()
        .filter_map(|(k, t)| t.map(|t| (k, t)))
    }
}

/// How texture coordinates outside `[0, 1]` are treated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Wrap {
    /// Tile the image (the default: UVs are in metres).
    #[default]
    Repeat,
    /// Tile, mirroring every other copy.
    MirroredRepeat,
    /// Repeat the edge texels.
    ClampToEdge,
}

/// How texels are filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Filter {
    /// Nearest texel (pixel-art look).
    Nearest,
    /// Linear (with mipmaps when minifying).
    #[default]
    Linear,
}

/// A texture: an image and how to sample it.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Texture {
    /// A name for people and tools.
    pub name: String,
    /// The image.
    pub image: ImageId,
    /// Wrapping along `u`. Default: repeat.
    pub wrap_u: Wrap,
    /// Wrapping along `v`. Default: repeat.
    pub wrap_v: Wrap,
    /// Filtering. Default: linear.
    pub filter: Filter,
}

/// The pixels of an image.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ImageData {
    /// A complete PNG file, embedded by the glTF writer as it is.
    Png(Vec<u8>),
    /// Raw 8-bit RGBA pixels, row by row from the top, `4 · width · height` bytes; the
    /// glTF writer encodes them as PNG.
    Rgba8 {
        /// Width in pixels (> 0).
        width: u32,
        /// Height in pixels (> 0).
        height: u32,
        /// The pixels.
        pixels: Vec<u8>,
    },
}

/// An image for textures.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Image {
    /// A name (and the file stem used by writers that store images beside the model).
    pub name: String,
    /// The pixels.
    pub data: ImageData,
}

/// The eight bytes every PNG file starts with.
pub const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];

impl Image {
    fn problem(&self) -> Option<String> {
        match &self.data {
            ImageData::Png(bytes) => (!bytes.starts_with(&PNG_SIGNATURE))
                .then(|| "the bytes do not start with the PNG signature".to_string()),
            ImageData::Rgba8 {
                width,
                height,
                pixels,
            } => {
                let expected = 4 * u64::from(*width) * u64::from(*height);
                if *width == 0 || *height == 0 {
                    Some(format!("the size {width}×{height} is empty"))
                } else if pixels.len() as u64 != expected {
                    Some(format!(
                        "{} bytes for {width}×{height} RGBA pixels; expected {expected}",
                        pixels.len()
                    ))
                } else {
                    None
                }
            }
        }
    }
}

/// A scene: a forest of nodes with meshes, materials, textures and images.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Scene {
    /// Every node; the tree structure is in [`Node::children`] and [`roots`](Self::roots).
    pub nodes: Vec<Node>,
    /// The top-level nodes, in order.
    pub roots: Vec<NodeId>,
    /// The meshes (glTF primitives).
    pub meshes: Vec<Mesh>,
    /// The materials.
    pub materials: Vec<Material>,
    /// The textures.
    pub textures: Vec<Texture>,
    /// The images.
    pub images: Vec<Image>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Self {
        Scene::default()
    }

    /// Adds a top-level node and returns its id.
    pub fn add_root(&mut self, name: impl Into<String>) -> NodeId {
        let id = NodeId(self.nodes.len() as u32);
        self.nodes.push(Node::new(name));
        self.roots.push(id);
        id
    }

    /// Adds a node as the last child of `parent` and returns its id.
    pub fn add_node(
        &mut self,
        parent: NodeId,
        name: impl Into<String>,
    ) -> Result<NodeId, GeomError> {
        self.check(parent)?;
        let id = NodeId(self.nodes.len() as u32);
        self.nodes.push(Node::new(name));
        self.nodes[parent.index()].children.push(id);
        Ok(id)
    }

    /// The node `id`.
    pub fn node(&self, id: NodeId) -> Result<&Node, GeomError> {
        self.check(id)?;
        Ok(&self.nodes[id.index()])
    }

    /// The node `id`, to change.
    pub fn node_mut(&mut self, id: NodeId) -> Result<&mut Node, GeomError> {
        self.check(id)?;
        Ok(&mut self.nodes[id.index()])
    }

    /// Adds a mesh and returns its id. Its material is checked by [`validate`](Self::validate).
    pub fn add_mesh(&mut self, mesh: Mesh) -> MeshId {
        self.meshes.push(mesh);
        MeshId(self.meshes.len() as u32 - 1)
    }

    /// Draws mesh `mesh` at node `node`.
    pub fn attach_mesh(&mut self, node: NodeId, mesh: MeshId) -> Result<(), GeomError> {
        if mesh.index() >= self.meshes.len() {
            return Err(out_of_range(
                format!("node {}", node.0),
                "mesh",
                mesh.index(),
                self.meshes.len(),
            ));
        }
        self.node_mut(node)?.meshes.push(mesh);
        Ok(())
    }

    /// Sets one metadata entry of a node (replacing an earlier value of the key).
    pub fn set_metadata(
        &mut self,
        node: NodeId,
        key: impl Into<Cow<'static, str>>,
        value: impl Into<MetaValue>,
    ) -> Result<(), GeomError> {
        self.node_mut(node)?.metadata.insert(key, value);
        Ok(())
    }

    /// Adds a material and returns its id.
    pub fn add_material(&mut self, material: Material) -> MaterialId {
        self.materials.push(material);
        MaterialId(self.materials.len() as u32 - 1)
    }

    /// Adds an image and returns its id.
    pub fn add_image(&mut self, image: Image) -> ImageId {
        self.images.push(image);
        ImageId(self.images.len() as u32 - 1)
    }

    /// Adds a texture and returns its id; fails if its image does not exist.
    pub fn add_texture(&mut self, texture: Texture) -> Result<TextureId, GeomError> {
        if texture.image.index() >= self.images.len() {
            return Err(out_of_range(
                format!("texture {}", self.textures.len()),
                "image",
                texture.image.index(),
                self.images.len(),
            ));
        }
        self.textures.push(texture);
        Ok(TextureId(self.textures.len() as u32 - 1))
    }

    /// Total number of triangles over all meshes (each counted once, however many nodes
    /// draw it).
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(Mesh::triangle_count).sum()
    }

    /// The world matrix of every node (parent · local, down from the roots), indexed like
    /// [`nodes`](Self::nodes); identity for nodes not reachable from a root. Call after
    /// [`validate`](Self::validate): on a cyclic graph each node is visited once at most.
    pub fn world_matrices(&self) -> Vec<DMat4> {
        let mut out = vec![DMat4::IDENTITY; self.nodes.len()];
        let mut seen = vec![false; self.nodes.len()];
        let mut stack: Vec<(NodeId, DMat4)> = self
            .roots
            .iter()
            .rev()
            .map(|&r| (r, DMat4::IDENTITY))
            .collect();
        while let Some((id, parent)) = stack.pop() {
            let Some(node) = self.nodes.get(id.index()) else {
                continue;
            };
            if std::mem::replace(&mut seen[id.index()], true) {
                continue;
            }
            let world = parent * node.transform.matrix();
            out[id.index()] = world;
            for &c in node.children.iter().rev() {
                stack.push((c, world));
            }
        }
        out
    }

    /// Checks the scene: every id in range; the nodes form a forest under
    /// [`roots`](Self::roots) (no cycle, no node with two parents or listed twice, a root
    /// has no parent, every node reachable); transforms finite and invertible; material
    /// factors in `[0, 1]`; images consistent; metadata numbers finite; every mesh valid
    /// ([`Mesh::validate`]). Reports the first problem in array order.
    pub fn validate(&self) -> Result<(), GeomError> {
        self.checked::<false>().map(|_| ())
    }

    /// Checks the scene as [`validate`](Self::validate) does (the same first problem
    /// reported) and returns the survey of every mesh ([`Mesh::survey`]: its box and
    /// tile facts, gathered in the validating pass), in [`meshes`](Self::meshes) order.
    /// The surveys describe the meshes as they are while borrowed: a writer that
    /// validates the scene anyway reads each mesh's box from here instead of reading
    /// the positions again.
    pub fn survey(&self) -> Result<Vec<MeshSurvey>, GeomError> {
        self.checked::<true>()
    }

    /// The checks of [`validate`](Self::validate); with `SURVEY`, the mesh surveys too
    /// (else none).
    fn checked<const SURVEY: bool>(&self) -> Result<Vec<MeshSurvey>, GeomError> {
        let nodes = self.nodes.len();
        for (k, &r) in self.roots.iter().enumerate() {
            if r.index() >= nodes {
                return Err(out_of_range(format!("root {k}"), "node", r.index(), nodes));
            }
        }
        for (i, node) in self.nodes.iter().enumerate() {
            let who = || format!("node {i} ({:?})", node.name);
            for &c in &node.children {
                if c.index() >= nodes {
                    return Err(out_of_range(who(), "node", c.index(), nodes));
                }
            }
            for &m in &node.meshes {
                if m.index() >= self.meshes.len() {
                    return Err(out_of_range(who(), "mesh", m.index(), self.meshes.len()));
                }
            }
            if let Some(reason) = node.transform.problem() {
                return Err(invalid(format!("the transform of {}", who()), reason));
            }
            for (key, value) in &node.metadata {
                if let MetaValue::Number(x) = value
                    && !x.is_finite()
                {
                    return Err(invalid(
                        format!("metadata {key:?} of {}", who()),
                        "numbers must be finite",
                    ));
                }
            }
        }
        self.validate_tree()?;
        let mut surveys = Vec::with_capacity(if SURVEY { self.meshes.len() } else { 0 });
        for (i, mesh) in self.meshes.iter().enumerate() {
            if let Some(m) = mesh.material
                && m.index() >= self.materials.len()
            {
                return Err(out_of_range(
                    format!("mesh {i}"),
                    "material",
                    m.index(),
                    self.materials.len(),
                ));
            }
            let in_mesh = |e| GeomError::InMesh {
                mesh: i,
                source: Box::new(e),
            };
            if SURVEY {
                surveys.push(mesh.survey().map_err(in_mesh)?);
            } else {
                mesh.validate().map_err(in_mesh)?;
            }
        }
        for (i, mat) in self.materials.iter().enumerate() {
            let who = || format!("material {i} ({:?})", mat.name);
            let factors = mat.base_color.iter().chain([&mat.metallic, &mat.roughness]);
            for &f in factors {
                if !(0.0..=1.0).contains(&f) {
                    return Err(invalid(
                        who(),
                        "colour, metallic and roughness factors must lie in [0, 1]",
                    ));
                }
            }
            for (what, t) in mat.textures() {
                if t.index() >= self.textures.len() {
                    return Err(out_of_range(
                        format!("the {what} of {}", who()),
                        "texture",
                        t.index(),
                        self.textures.len(),
                    ));
                }
            }
        }
        for (i, tex) in self.textures.iter().enumerate() {
            if tex.image.index() >= self.images.len() {
                return Err(out_of_range(
                    format!("texture {i}"),
                    "image",
                    tex.image.index(),
                    self.images.len(),
                ));
            }
        }
        for (i, img) in self.images.iter().enumerate() {
            if let Some(reason) = img.problem() {
                return Err(invalid(format!("image {i} ({:?})", img.name), &reason));
            }
        }
        Ok(surveys)
    }

    /// The node graph is a forest under the roots. Assumes ids are in range.
    fn validate_tree(&self) -> Result<(), GeomError> {
        let n = self.nodes.len();
        let not_tree = |node: usize, problem: String| GeomError::SceneNotATree { node, problem };
        // parent[c] = Some(p); roots get a sentinel so a root listed as a child is caught.
        const ROOT: usize = usize::MAX;
        let mut parent: Vec<Option<usize>> = vec![None; n];
        for &r in &self.roots {
            if parent[r.index()].replace(ROOT).is_some() {
                return Err(not_tree(r.index(), "is listed as a root twice".to_string()));
            }
        }
        for (p, node) in self.nodes.iter().enumerate() {
            for &c in &node.children {
                match parent[c.index()].replace(p) {
                    None => {}
                    Some(ROOT) => {
                        return Err(not_tree(
                            c.index(),
                            format!("is a root and also a child of node {p}"),
                        ));
                    }
                    Some(q) if q == p => {
                        return Err(not_tree(
                            c.index(),
                            format!("is listed twice as a child of node {p}"),
                        ));
                    }
                    Some(q) => {
                        return Err(not_tree(
                            c.index(),
                            format!("has two parents, nodes {q} and {p}"),
                        ));
                    }
                }
            }
        }
        // Every node has at most one parent: following parents either reaches a root, or
        // a parentless non-root (unreachable), or loops (a cycle).
        // state: 0 = unknown, 1 = on the current path, 2 = reaches a root.
        let mut state = vec![0u8; n];
        for start in 0..n {
            let mut path = Vec::new();
            let mut v = start;
            loop {
                match state[v] {
                    2 => break,
                    1 => return Err(not_tree(v, "lies on a cycle of children".to_string())),
                    _ => {}
                }
                state[v] = 1;
                path.push(v);
                match parent[v] {
                    Some(ROOT) => break,
                    Some(p) => v = p,
                    None => {
                        return Err(not_tree(
                            v,
                            "is neither a root nor anyone's child (unreachable)".to_string(),
                        ));
                    }
                }
            }
            for v in path {
                state[v] = 2;
            }
        }
        Ok(())
    }

    fn check(&self, id: NodeId) -> Result<(), GeomError> {
        if id.index() < self.nodes.len() {
            Ok(())
        } else {
            Err(out_of_range(
                "the caller".to_string(),
                "node",
                id.index(),
                self.nodes.len(),
            ))
        }
    }
}

fn out_of_range(referrer: String, what: &'static str, index: usize, len: usize) -> GeomError {
    GeomError::SceneIndexOutOfRange {
        referrer,
        what,
        index,
        len,
    }
}

fn invalid(what: String, reason: &str) -> GeomError {
    GeomError::SceneInvalidValue {
        what,
        reason: reason.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::prism;
    use crate::{DVec2, Polygon};

    fn sample() -> Scene {
        let mut s = Scene::new();
        let img = s.add_image(Image {
            name: "brick".into(),
            data: ImageData::Rgba8 {
                width: 2,
                height: 1,
                pixels: vec![255; 8],
            },
        });
        let tex = s
            .add_texture(Texture {
                name: "brick".into(),
                image: img,
                ..Texture::default()
            })
            .unwrap();
        let mat = s.add_material(Material {
            base_color_texture: Some(tex),
            ..Material::new("brick", [0.7, 0.4, 0.3, 1.0])
        });
        let fp = Polygon::rect(DVec2::ZERO, DVec2::new(8.0, 12.0));
        let mesh = s.add_mesh(prism(&fp.into(), 0.0, 9.0, Some(mat)).unwrap());
        let city = s.add_root("city");
        let block = s.add_node(city, "block").unwrap();
        for k in 0..3 {
            let b = s.add_node(block, format!("house {k}")).unwrap();
            s.attach_mesh(b, mesh).unwrap();
            s.set_metadata(b, "kind", "residential").unwrap();
            s.set_metadata(b, "height", 9.0).unwrap();
            s.set_metadata(b, "bridge", false).unwrap();
            s.node_mut(b).unwrap().transform =
                Transform::from_translation(DVec3::new(10.0 * k as f64, 0.0, 0.0));
        }
        s.node_mut(block).unwrap().transform = Transform::Trs {
            translation: DVec3::new(0.0, 1.0, 0.0),
            rotation: DQuat::IDENTITY,
            scale: DVec3::splat(2.0),
        };
        s
    }

    #[test]
    fn sample_scene_is_valid() {
        let s = sample();
        s.validate().unwrap();
        assert_eq!(s.nodes.len(), 5);
        assert_eq!(s.triangle_count(), 12);
        let w = s.world_matrices();
        // house 2: translate 20 then block's scale 2 and lift 1.
        let p = w[4].transform_point3(DVec3::ZERO);
        assert_eq!(p, DVec3::new(40.0, 1.0, 0.0));
        // Metadata iterates in key order.
        let keys: Vec<&str> = s.nodes[2].metadata.keys().collect();
        assert_eq!(keys, ["bridge", "height", "kind"]);
        // Round trip through serde.
        let json = serde_json::to_string(&s).unwrap();
        let back: Scene = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn builders_check_ids() {
        let mut s = sample();
        assert!(s.add_node(NodeId(99), "x").is_err());
        assert!(s.attach_mesh(NodeId(0), MeshId(5)).is_err());
        assert!(s.attach_mesh(NodeId(50), MeshId(0)).is_err());
        assert!(s.set_metadata(NodeId(50), "k", 1.0).is_err());
        assert!(
            s.add_texture(Texture {
                image: ImageId(3),
                ..Texture::default()
            })
            .is_err()
        );
        s.validate().unwrap();
    }

    #[test]
    fn validation_catches_bad_indices() {
        let mut s = sample();
        s.nodes[2].meshes.push(MeshId(7));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneIndexOutOfRange {
                what: "mesh",
                index: 7,
                ..
            })
        ));
        let mut s = sample();
        s.nodes[1].children.push(NodeId(70));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneIndexOutOfRange { what: "node", .. })
        ));
        let mut s = sample();
        s.roots.push(NodeId(9));
        assert!(s.validate().is_err());
        let mut s = sample();
        s.meshes[0].material = Some(MaterialId(4));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneIndexOutOfRange {
                what: "material",
                ..
            })
        ));
        let mut s = sample();
        s.materials[0].normal_texture = Some(TextureId(2));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneIndexOutOfRange {
                what: "texture",
                ..
            })
        ));
        let mut s = sample();
        s.textures[0].image = ImageId(1);
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneIndexOutOfRange { what: "image", .. })
        ));
        let mut s = sample();
        s.meshes[0].indices[0] = 1000;
        assert!(matches!(
            s.validate(),
            Err(GeomError::InMesh { mesh: 0, .. })
        ));
    }

    #[test]
    fn validation_catches_bad_trees() {
        // A cycle below the root.
        let mut s = sample();
        s.nodes[3].children.push(NodeId(1));
        assert!(matches!(s.validate(), Err(GeomError::SceneNotATree { .. })));
        // A cycle detached from the roots: each node has exactly one parent.
        let mut s = sample();
        let a = NodeId(s.nodes.len() as u32);
        let b = NodeId(a.0 + 1);
        s.nodes.push(Node {
            children: vec![b],
            ..Node::new("a")
        });
        s.nodes.push(Node {
            children: vec![a],
            ..Node::new("b")
        });
        match s.validate() {
            Err(GeomError::SceneNotATree { problem, .. }) => assert!(problem.contains("cycle")),
            other => panic!("{other:?}"),
        }
        // A self-loop.
        let mut s = sample();
        s.nodes[4].children.push(NodeId(4));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneNotATree { node: 4, .. })
        ));
        // Two parents.
        let mut s = sample();
        s.nodes[0].children.push(NodeId(3));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneNotATree { node: 3, .. })
        ));
        // A root that is also a child.
        let mut s = sample();
        s.roots.push(NodeId(2));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneNotATree { node: 2, .. })
        ));
        // Unreachable.
        let mut s = sample();
        s.nodes.push(Node::new("orphan"));
        match s.validate() {
            Err(GeomError::SceneNotATree { node: 5, problem }) => {
                assert!(problem.contains("unreachable"))
            }
            other => panic!("{other:?}"),
        }
        // world_matrices terminates on cycles.
        let mut s = sample();
        s.nodes[4].children.push(NodeId(0));
        assert_eq!(s.world_matrices().len(), 5);
    }

    proptest::proptest! {
        /// Random forests validate; one more child link always breaks the tree.
        #[test]
        fn random_forests_and_one_extra_link(
            parents in proptest::collection::vec(proptest::prelude::any::<Option<proptest::sample::Index>>(), 1..40),
            from in proptest::prelude::any::<proptest::sample::Index>(),
            to in proptest::prelude::any::<proptest::sample::Index>(),
        ) {
            let mut s = Scene::new();
            for (i, p) in parents.iter().enumerate() {
                match p {
                    Some(p) if i > 0 => {
                        s.add_node(NodeId(p.index(i) as u32), format!("n{i}")).unwrap();
                    }
                    _ => {
                        s.add_root(format!("n{i}"));
                    }
                }
            }
            s.validate().unwrap();
            let n = s.nodes.len();
            let (a, b) = (from.index(n), to.index(n));
            s.nodes[a].children.push(NodeId(b as u32));
            let is_not_a_tree = matches!(s.validate(), Err(GeomError::SceneNotATree { .. }));
            proptest::prop_assert!(is_not_a_tree);
            // World matrices still terminate.
            proptest::prop_assert_eq!(s.world_matrices().len(), n);
        }
    }

    #[test]
    fn validation_catches_bad_values() {
        let mut s = sample();
        s.node_mut(NodeId(1)).unwrap().transform =
            Transform::Matrix(DMat4::from_scale(DVec3::ZERO));
        assert!(matches!(
            s.validate(),
            Err(GeomError::SceneInvalidValue { .. })
        ));
        let mut s = sample();
        s.nodes[2].transform = Transform::from_translation(DVec3::new(f64::NAN, 0.0, 0.0));
        assert!(s.validate().is_err());
        let mut s = sample();
        s.nodes[2].transform = Transform::Trs {
            translation: DVec3::ZERO,
            rotation: DQuat::from_xyzw(0.0, 0.0, 0.0, 2.0),
            scale: DVec3::ONE,
        };
        assert!(s.validate().is_err());
        let mut s = sample();
        s.set_metadata(NodeId(2), "height", f64::INFINITY).unwrap();
        assert!(s.validate().is_err());
        let mut s = sample();
        s.materials[0].roughness = 1.5;
        assert!(s.validate().is_err());
        let mut s = sample();
        s.materials[0].base_color[3] = f32::NAN;
        assert!(s.validate().is_err());
        let mut s = sample();
        s.images[0].data = ImageData::Rgba8 {
            width: 2,
            height: 2,
            pixels: vec![0; 8],
        };
        assert!(s.validate().is_err());
        let mut s = sample();
        s.images[0].data = ImageData::Png(b"GIF89a".to_vec());
        assert!(s.validate().is_err());
        s.images[0].data = ImageData::Png(PNG_SIGNATURE.to_vec());
        s.validate().unwrap();
    }
}
