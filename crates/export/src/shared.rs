//! What the writers of one scene share when they write it at the same time.
//!
//! The glb and OBJ writers both validate the scene and both need the PNG file of every
//! image a material uses (a raw [`ImageData::Rgba8`](polis_geom::scene::ImageData) image
//! is encoded: tens of milliseconds for a city's facade textures). A caller writing both
//! files of one scene, one beside the other (the facade's `City::write_all`), hands both
//! writers one [`SharedScene`]: the scene is validated once and each image encoded once,
//! by whichever writer asks first (the other waits for the result). Bytes are those of
//! the writers on their own.

use std::borrow::Cow;
use std::sync::OnceLock;

use polis_geom::GeomError;
use polis_geom::mesh::MeshSurvey;
use polis_geom::par::prelude::*;
use polis_geom::scene::Scene;

use crate::ExportError;
use crate::images::png_bytes;

/// A scene with its validating survey and its images' PNG files, each computed once on
/// first use and shared by the writers that borrow it ([`glb::write_glb_shared`],
/// [`obj::write_obj_shared`]).
///
/// [`glb::write_glb_shared`]: crate::glb::write_glb_shared
/// [`obj::write_obj_shared`]: crate::obj::write_obj_shared
///
/// ```
/// use polis_export::{SharedScene, glb, obj, sink::MemorySink};
/// use polis_export::geom::{DVec2, Polygon, Scene, mesh::prism};
/// let mut scene = Scene::new();
/// let city = scene.add_root("city");
/// let mesh = scene.add_mesh(prism(&Polygon::rect(DVec2::ZERO, DVec2::splat(10.0)).into(), 0.0, 5.0, None)?);
/// scene.attach_mesh(city, mesh)?;
/// let shared = SharedScene::new(&scene);
/// let (mut glb_bytes, mut obj_bytes, mut files) = (Vec::new(), Vec::new(), MemorySink::new());
/// let glb_options = glb::GlbOptions::default();
/// let obj_options = obj::ObjOptions::default();
/// let (g, o) = std::thread::scope(|s| {
///     let g = s.spawn(|| glb::write_glb_shared(&shared, &glb_options, &mut glb_bytes));
///     let o = obj::write_obj_shared(&shared, &obj_options, &mut obj_bytes, &mut files);
///     (g.join(), o)
/// });
/// assert_eq!(o?.triangles, 12);
/// assert!(g.is_ok());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct SharedScene<'a> {
    scene: &'a Scene,
    survey: OnceLock<Result<Vec<MeshSurvey>, GeomError>>,
    /// Per scene image: its PNG file, or the encoder's message.
    pngs: Vec<OnceLock<Result<Cow<'a, [u8]>, String>>>,
}

impl<'a> SharedScene<'a> {
    /// `scene`, nothing computed yet.
    pub fn new(scene: &'a Scene) -> Self {
        SharedScene {
            scene,
            survey: OnceLock::new(),
            pngs: scene.images.iter().map(|_| OnceLock::new()).collect(),
        }
    }

    /// The scene.
    pub fn scene(&self) -> &'a Scene {
        self.scene
    }

    /// [`Scene::survey`]: the scene validated, with each mesh's survey; computed on the
    /// first call.
    ///
    /// # Errors
    /// [`ExportError::InvalidScene`] with the first problem, as [`Scene::validate`].
    pub fn survey(&self) -> Result<&[MeshSurvey], ExportError> {
        match self.survey.get_or_init(|| self.scene.survey()) {
            Ok(surveys) => Ok(surveys),
            Err(e) => Err(ExportError::InvalidScene(e.clone())),
        }
    }

    /// The PNG file of scene image `index` (`images::png_bytes`), encoded on the first
    /// call.
    ///
    /// # Errors
    /// [`ExportError::Png`] if it cannot be encoded; [`ExportError::InvalidOption`] for an
    /// index past the scene's images.
    pub fn png(&self, index: usize) -> Result<&[u8], ExportError> {
        let (Some(slot), Some(image)) = (self.pngs.get(index), self.scene.images.get(index)) else {
            return Err(ExportError::InvalidOption {
                name: "image",
                reason: format!("no image {index}: the scene has {}", self.pngs.len()),
            });
        };
        let png = slot.get_or_init(|| {
            png_bytes(index, image).map_err(|e| match e {
                ExportError::Png { reason, .. } => reason,
                other => other.to_string(),
            })
        });
        match png {
            Ok(bytes) => Ok(bytes),
            Err(reason) => Err(ExportError::Png {
                image: index,
                reason: reason.clone(),
            }),
        }
    }

    /// The PNG files of scene images `indices`, in that order, encoded in parallel where
    /// not encoded yet.
    ///
    /// # Errors
    /// The first of [`png`](Self::png)'s errors in `indices` order.
    pub fn pngs(&self, indices: &[usize]) -> Result<Vec<&[u8]>, ExportError> {
        let encoded: Vec<Result<&[u8], ExportError>> =
            indices.par_iter().map(|&i| self.png(i)).collect();
        encoded.into_iter().collect()
    }
}
