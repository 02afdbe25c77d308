//! Textured road and footpath surfaces in the scene (Kelly §4.4.1, §5.4; the course
//! report's street textures): PBR materials whose textures
//! ([`polis_facades::street`]) are generated like the facades', one per ribbon kind
//! (lane markings laid along the road), plain asphalt for the junction plates, paving
//! for the pavements and footpaths (block plinths).
//!
//! Texture coordinates: junction plates, dead-end caps and pavements keep their metre
//! coordinates (their textures repeat every metre: [`polis_facades::street::ASPHALT_TILE_M`],
//! [`PAVING_TILE_M`](polis_facades::street::PAVING_TILE_M)). Ribbons keep `u` along
//! the road in units of the marking period (metres / [`MARKING_PERIOD_M`]) and `v` across
//! the road as a fraction of its width (0 on the right edge, 1 on the left), since lane
//! markings sit at fractions of the width and core glTF has no texture transform to
//! scale metre coordinates per road.

use polis_export::map::RoadClass as MapClass;
use polis_export::surfaces::RoadSurfaceParts;
use polis_facades::FacadeTextures;
use polis_facades::street::{MARKING_PERIOD_M, StreetSurface, street_textures};
use polis_geom::scene::{Image, ImageData, Texture};
use polis_geom::{Material, MaterialId, Mesh, Scene};

use crate::error::Result;

/// The seed of the street textures (the same in every city: they are materials, not
/// layout).
const STREET_TEXTURE_SEED: u64 = 0x57EE7;

/// The ribbon texture of a road class.
pub(crate) fn surface_of(class: &MapClass) -> StreetSurface {
    match class {
        MapClass::Highway => StreetSurface::Highway,
        MapClass::Major => StreetSurface::Major,
        MapClass::Street => StreetSurface::Street,
        _ => StreetSurface::Lane,
    }
}

/// Adds the textured PBR material of `surface` (albedo, normal, metallic-roughness).
pub(crate) fn add_street_material(scene: &mut Scene, surface: StreetSurface) -> Result<MaterialId> {
    let t: FacadeTextures = street_textures(surface, STREET_TEXTURE_SEED);
    let name = format!("street {}", surface.name());
    let mut texture = |suffix: &str, pixels: Vec<u8>| -> Result<_> {
        let image = scene.add_image(Image {
            name: format!("{name} {suffix}"),
            data: ImageData::Rgba8 {
                width: t.width,
                height: t.height,
                pixels,
            },
        });
        Ok(scene.add_texture(Texture {
            name: format!("{name} {suffix}"),
            image,
            ..Texture::default()
        })?)
    };
    let albedo = texture("albedo", t.albedo.clone())?;
    let normal = texture("normal", t.normal.clone())?;
    let mr = texture("metallic-roughness", t.metallic_roughness.clone())?;
    Ok(scene.add_material(Material {
        name,
        base_color_texture: Some(albedo),
        normal_texture: Some(normal),
        metallic_roughness_texture: Some(mr),
        metallic: 1.0,
        roughness: 1.0,
        ..Material::default()
    }))
}

/// The road surfaces as textured meshes: one per ribbon group (its class's marking
/// texture; coordinates as in the [module docs](self)), then the junction plates (plain
/// asphalt, metre coordinates). Materials are added for the kinds present only, one per
/// kind.
pub(crate) fn road_meshes(scene: &mut Scene, parts: RoadSurfaceParts) -> Result<Vec<Mesh>> {
    let mut materials: Vec<(StreetSurface, MaterialId)> = Vec::new();
    let mut material = |scene: &mut Scene, s: StreetSurface| -> Result<MaterialId> {
        if let Some(&(_, id)) = materials.iter().find(|(k, _)| *k == s) {
            return Ok(id);
        }
        let id = add_street_material(scene, s)?;
        materials.push((s, id));
        Ok(id)
    };
    let mut out = Vec::with_capacity(parts.ribbons.len() + 1);
    for mut g in parts.ribbons {
        let s = surface_of(&g.class);
        g.mesh.material = Some(material(scene, s)?);
        let (ku, kv) = (
            (1.0 / MARKING_PERIOD_M) as f32,
            (-1.0 / g.width_m.max(f64::MIN_POSITIVE)) as f32,
        );
        for uv in &mut g.mesh.uvs {
            uv.x *= ku;
            uv.y *= kv;
        }
        out.push(g.mesh);
    }
    let mut junctions = parts.junctions;
    if junctions.triangle_count() > 0 {
        junctions.material = Some(material(scene, StreetSurface::Asphalt)?);
        out.push(junctions);
    }
    Ok(out)
}
