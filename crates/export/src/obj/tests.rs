use super::*;
use crate::sink::MemorySink;
use crate::testing::{drawn_triangles, grid_scene, sample_scene};
use polis_geom::glam::Vec3;

/// Reads an OBJ and its MTL with `tobj`, the MTL from the sink.
pub(crate) fn load(obj: &[u8], files: &MemorySink) -> (Vec<tobj::Model>, Vec<tobj::Material>) {
    let opts = tobj::LoadOptions {
        single_index: true,
        triangulate: false,
        ..Default::default()
    };
    let (models, mats) = tobj::load_obj_buf(&mut std::io::Cursor::new(obj), &opts, |p| {
        let name = p.to_str().unwrap();
        let bytes = files
            .files
            .get(name)
            .ok_or(tobj::LoadError::OpenFileFailed)?;
        tobj::load_mtl_buf(&mut std::io::Cursor::new(bytes))
    })
    .expect("tobj reads the OBJ");
    (models, mats.expect("tobj reads the MTL"))
}

fn write(scene: &Scene) -> (Vec<u8>, MemorySink, ObjReport) {
    let mut obj = Vec::new();
    let mut files = MemorySink::new();
    let report = write_obj(scene, &ObjOptions::default(), &mut obj, &mut files).unwrap();
    assert_eq!(report.bytes as usize, obj.len());
    (obj, files, report)
}

#[test]
fn reads_back_with_tobj() {
    let scene = sample_scene();
    let (obj, files, report) = write(&scene);
    let (models, mats) = load(&obj, &files);
    // Groups: city, house 0..2, mirror.
    assert_eq!(report.groups, 5);
    // tobj splits per group and material: 1 + 2 + 1 + 2 + 1.
    assert_eq!(models.len(), 7);
    let names: Vec<&str> = models.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "city_0",
            "house_0_2",
            "house_0_2",
            "house_1_3",
            "house_2_4",
            "house_2_4",
            "mirror_5"
        ]
    );
    // Triangles per material match the scene as drawn.
    let tris: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    assert_eq!(tris, drawn_triangles(&scene).values().sum::<usize>());
    assert_eq!(tris, report.triangles);
    // Materials: three scene materials + the default.
    assert_eq!(mats.len(), 4);
    assert_eq!(report.materials, 4);
    assert_eq!(mats[0].name, "m0_brick_wall");
    assert_eq!(mats[0].diffuse, Some([0.7, 0.4, 0.3]));
    assert_eq!(
        mats[0].diffuse_texture.as_deref(),
        Some("scene_0_brick.png")
    );
    assert_eq!(
        mats[0].normal_texture.as_deref(),
        Some("scene_1_normal_map.png")
    );
    assert_eq!(mats[1].dissolve, Some(0.4));
    assert_eq!(
        mats[1].unknown_param.get("Pm").map(String::as_str),
        Some("0.8")
    );
    assert_eq!(mats[3].name, DEFAULT_MATERIAL);
    assert_eq!(models[0].mesh.material_id, Some(3));
    assert_eq!(models[1].mesh.material_id, Some(0));
    // Texture files are PNG.
    assert_eq!(report.textures, 2);
    for name in ["scene_0_brick.png", "scene_1_normal_map.png"] {
        let bytes = &files.files[name];
        png::Decoder::new(std::io::Cursor::new(bytes.clone()))
            .read_info()
            .unwrap();
    }
    assert!(files.files.contains_key("scene.mtl"));
}

#[test]
fn geometry_is_in_world_space_with_obj_texture_coordinates() {
    let scene = sample_scene();
    let (obj, files, _) = write(&scene);
    let (models, _) = load(&obj, &files);
    let worlds = scene.world_matrices();
    // house 2 (node 4), first model = the house prism.
    let house = &scene.meshes[0];
    let m = &models[4].mesh;
    // tobj renumbers vertices in order of first use: compare triangle corners.
    assert_eq!(m.indices.len(), house.indices.len());
    for (k, (&got, &want)) in m.indices.iter().zip(&house.indices).enumerate() {
        let (g, w) = (got as usize, want as usize);
        let p = worlds[4]
            .transform_point3(house.positions[w].as_dvec3())
            .as_vec3();
        let q = Vec3::new(
            m.positions[3 * g],
            m.positions[3 * g + 1],
            m.positions[3 * g + 2],
        );
        assert_eq!(q, p, "corner {k}");
        let uv = house.uvs[w];
        assert_eq!(m.texcoords[2 * g], uv.x);
        assert_eq!(m.texcoords[2 * g + 1], 1.0 - uv.y);
    }
    // Every model: indices in range, unit normals, front faces agree with normals (the
    // mirrored house included).
    for model in &models {
        let m = &model.mesh;
        let n = m.positions.len() / 3;
        assert!(m.indices.iter().all(|&i| (i as usize) < n));
        let v = |i: u32| {
            let i = i as usize;
            Vec3::new(
                m.positions[3 * i],
                m.positions[3 * i + 1],
                m.positions[3 * i + 2],
            )
        };
        for t in m.indices.chunks_exact(3) {
            let face = (v(t[1]) - v(t[0])).cross(v(t[2]) - v(t[0])).normalize();
            let i = t[0] as usize;
            let nrm = Vec3::new(m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]);
            assert!((nrm.length() - 1.0).abs() < 1e-5);
            assert!(face.dot(nrm) > 0.99, "{}: winding", model.name);
        }
    }
}

#[test]
fn byte_identical_and_validated() {
    let scene = sample_scene();
    let (a, fa, _) = write(&scene);
    let (b, fb, _) = write(&scene.clone());
    assert_eq!(a, b);
    assert_eq!(fa, fb);

    let mut bad = scene.clone();
    bad.meshes[2].normals[0] = Vec3::ZERO;
    let mut obj = Vec::new();
    let mut files = MemorySink::new();
    let e = write_obj(&bad, &ObjOptions::default(), &mut obj, &mut files).unwrap_err();
    assert!(matches!(e, ExportError::InvalidScene(_)));
    assert!(obj.is_empty() && files.files.is_empty());
    for stem in ["", "a b", "../x", ".hidden"] {
        let opts = ObjOptions {
            stem: stem.to_string(),
            ..ObjOptions::default()
        };
        assert!(matches!(
            write_obj(&scene, &opts, &mut obj, &mut files),
            Err(ExportError::InvalidOption { name: "stem", .. })
        ));
    }
    assert!(obj.is_empty());
}

#[test]
fn closure_sinks_receive_side_files() {
    let scene = sample_scene();
    let mut names = Vec::new();
    let mut sink = |name: &str, bytes: &[u8]| {
        names.push((name.to_string(), bytes.len()));
        Ok(())
    };
    let opts = ObjOptions {
        stem: "city.v2".to_string(),
        ..ObjOptions::default()
    };
    write_obj(&scene, &opts, std::io::sink(), &mut sink).unwrap();
    let got: Vec<&str> = names.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        got,
        [
            "city.v2.mtl",
            "city.v2_0_brick.png",
            "city.v2_1_normal_map.png"
        ]
    );
    assert!(names.iter().all(|(_, len)| *len > 0));
}

#[test]
fn default_material_only_when_drawn_and_dir_sink_writes_files() {
    let mut scene = sample_scene();
    // Give the plain slab a material, and draw an empty mesh without one: no triangle
    // needs the default material.
    scene.meshes[2].material = Some(polis_geom::scene::MaterialId(2));
    let empty = scene.add_mesh(Mesh::new(None));
    scene
        .attach_mesh(polis_geom::scene::NodeId(0), empty)
        .unwrap();
    let (obj, files, report) = write(&scene);
    assert_eq!(report.materials, 3, "no default material for an empty mesh");
    let (_, mats) = load(&obj, &files);
    assert!(mats.iter().all(|m| m.name != DEFAULT_MATERIAL));

    let dir = std::env::temp_dir().join(format!("polis-export-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut sink = crate::sink::DirSink::new(&dir);
    let opts = ObjOptions {
        stem: "disk".to_string(),
        ..ObjOptions::default()
    };
    let file = std::fs::File::create(dir.join("disk.obj")).unwrap();
    write_obj(&scene, &opts, file, &mut sink).unwrap();
    let obj = std::fs::read(dir.join("disk.obj")).unwrap();
    let mut from_disk = MemorySink::new();
    for name in ["disk.mtl", "disk_0_brick.png", "disk_1_normal_map.png"] {
        from_disk
            .files
            .insert(name.to_string(), std::fs::read(dir.join(name)).unwrap());
    }
    let (models, mats) = load(&obj, &from_disk);
    assert_eq!(models.len(), 7);
    assert_eq!(mats.len(), 3);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// With `texture_dir`, the textures go into the subfolder and the MTL names them by
/// their path relative to the OBJ, so a reader resolving `map_Kd` from the OBJ's folder
/// finds every texture file.
#[test]
fn textures_in_a_subfolder_are_found_from_the_mtl() {
    let scene = crate::testing::sample_scene();
    let dir = std::env::temp_dir().join(format!("polis-export-texdir-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let opts = ObjOptions {
        stem: "sub".to_string(),
        texture_dir: "textures".to_string(),
    };
    let file = std::fs::File::create(dir.join("sub.obj")).unwrap();
    let report = write_obj(&scene, &opts, file, &mut crate::sink::DirSink::new(&dir)).unwrap();
    assert!(report.textures > 0);
    let (_, mats) = tobj::load_obj(dir.join("sub.obj"), &tobj::GPU_LOAD_OPTIONS).unwrap();
    let mut named = 0;
    for m in mats.unwrap() {
        for t in [m.diffuse_texture, m.normal_texture].into_iter().flatten() {
            assert!(t.starts_with("textures/sub_"), "{t}");
            assert!(dir.join(&t).is_file(), "{t} missing");
            named += 1;
        }
    }
    assert!(named >= report.textures);
    let loose = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "png")
        })
        .count();
    assert_eq!(loose, 0, "no texture beside the OBJ");
    std::fs::remove_dir_all(&dir).unwrap();

    for bad in ["../up", "a/b", ".hidden"] {
        let opts = ObjOptions {
            texture_dir: bad.to_string(),
            ..ObjOptions::default()
        };
        assert!(matches!(
            write_obj(&scene, &opts, std::io::sink(), &mut MemorySink::new()),
            Err(ExportError::InvalidOption {
                name: "texture_dir",
                ..
            })
        ));
    }
}

/// The OBJ text of `scene` written the plain way, one `writeln!` at a time with `core`'s
/// number formatting and a linear search for each value already written in the node: the
/// reference the batched, parallel, hashed writer must match byte for byte.
pub(crate) fn reference_obj(scene: &Scene, stem: &str) -> Vec<u8> {
    use std::io::Write as _;
    /// The 1-based index of `v` among `vs` from `base` on, adding it if new.
    fn find<T: Copy>(vs: &mut Vec<T>, v: T, same: impl Fn(&T, &T) -> bool, base: u64) -> u64 {
        let k = vs.iter().position(|x| same(x, &v)).unwrap_or_else(|| {
            vs.push(v);
            vs.len() - 1
        });
        base + k as u64
    }
    let bits3 = |a: &[f32; 3], b: &[f32; 3]| a.map(f32::to_bits) == b.map(f32::to_bits);
    let bits2 = |a: &[f32; 2], b: &[f32; 2]| a.map(f32::to_bits) == b.map(f32::to_bits);
    let mut w = Vec::new();
    let _ = writeln!(w, "# polis-export {}", env!("CARGO_PKG_VERSION"));
    let _ = writeln!(
        w,
        "# metres; +Y up, right-handed (glTF axes); triangles counter-clockwise from the front"
    );
    let _ = writeln!(w, "mtllib {stem}.mtl");
    let worlds = scene.world_matrices();
    let (mut vb, mut tb, mut nb) = (1u64, 1u64, 1u64);
    for (i, node) in scene.nodes.iter().enumerate() {
        let meshes: Vec<&Mesh> = node
            .meshes
            .iter()
            .map(|m| &scene.meshes[m.index()])
            .filter(|m| !m.is_empty())
            .collect();
        if meshes.is_empty() {
            continue;
        }
        let world = worlds.get(i).copied().unwrap_or(DMat4::IDENTITY);
        let identity = world == DMat4::IDENTITY;
        let linear = DMat3::from_mat4(world);
        let mirror = linear.determinant() < 0.0;
        let normal_matrix = linear.inverse().transpose();
        let (mut ps, mut ts, mut ns) = (Vec::new(), Vec::new(), Vec::new());
        let mut faces: Vec<(String, Vec<[[u64; 3]; 3]>)> = Vec::new();
        for m in meshes {
            let mut ids = Vec::new();
            for k in 0..m.vertex_count() {
                let p = m.positions[k];
                let p = if identity {
                    p
                } else {
                    world.transform_point3(p.as_dvec3()).as_vec3()
                };
                let t = m.uvs[k];
                let n = m.normals[k];
                let n = if identity {
                    n.normalize_or_zero()
                } else {
                    (normal_matrix * n.as_dvec3()).normalize_or_zero().as_vec3()
                };
                ids.push([
                    find(&mut ps, p.to_array(), bits3, vb),
                    find(&mut ts, [t.x, 1.0 - t.y], bits2, tb),
                    find(&mut ns, n.to_array(), bits3, nb),
                ]);
            }
            let name = match m.material {
                Some(id) => material_name(id.index(), scene),
                None => DEFAULT_MATERIAL.to_string(),
            };
            let tris = m
                .triangles()
                .map(|[a, b, c]| {
                    let (b, c) = if mirror { (c, b) } else { (b, c) };
                    [a, b, c].map(|k| ids[k as usize])
                })
                .collect::<Vec<[[u64; 3]; 3]>>();
            faces.push((name, tris));
        }
        let _ = writeln!(w, "g {}_{i}", sanitize(&node.name, "node"));
        for [x, y, z] in &ps {
            let _ = writeln!(w, "v {x} {y} {z}");
        }
        for [u, v] in &ts {
            let _ = writeln!(w, "vt {u} {v}");
        }
        for [x, y, z] in &ns {
            let _ = writeln!(w, "vn {x} {y} {z}");
        }
        vb += ps.len() as u64;
        tb += ts.len() as u64;
        nb += ns.len() as u64;
        // Indices relative to the end of each stream: the absolute 1-based index less
        // the count of values written so far, less one (`-1` is the last value).
        let rel = |[p, t, n]: [u64; 3]| {
            [
                p as i64 - vb as i64,
                t as i64 - tb as i64,
                n as i64 - nb as i64,
            ]
        };
        for (name, tris) in faces {
            let _ = writeln!(w, "usemtl {name}");
            for [a, b, c] in tris {
                let [a, b, c] = [a, b, c].map(rel);
                let _ = writeln!(
                    w,
                    "f {}/{}/{} {}/{}/{} {}/{}/{}",
                    a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]
                );
            }
        }
    }
    w
}

#[test]
fn batches_and_threads_do_not_change_the_bytes() {
    let scene = grid_scene(6);
    let options = ObjOptions::default();
    let write = |batch: u64| {
        let (mut obj, mut files) = (Vec::new(), MemorySink::new());
        let report = write_obj_in_batches(
            &crate::SharedScene::new(&scene),
            &options,
            &mut obj,
            &mut files,
            batch,
        )
        .unwrap();
        assert_eq!(report.bytes, obj.len() as u64);
        obj
    };
    let reference = reference_obj(&scene, &options.stem);
    // Pieces of one node (1, 5, 64), of several nodes each (1,024: 32 vertices a piece),
    // the whole scene in one piece.
    for batch in [1, 5, 64, 1024, BATCH_VERTICES] {
        assert_eq!(write(batch), reference, "batch {batch}");
    }
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        assert_eq!(pool.install(|| write(7)), reference, "{threads} threads");
    }
}
