//! The city on its ground: the terrain mesh of the scene against everything standing on
//! it (road surfaces, block plinths, buildings), sampled at their vertices, on the hilly
//! `san_francisco` preset.

#![allow(clippy::unwrap_used, clippy::expect_used)] // tests may panic on failure

use polis::geom::glam::{DMat4, DVec3};
use polis::geom::{DVec2, Mesh, Scene, to_layout};
use polis::{City, CityConfig};

/// Heights of a triangulated sheet at layout points: triangles bucketed on a grid.
struct Sheet {
    tris: Vec<[DVec3; 3]>,
    cell: f64,
    min: DVec2,
    n: usize,
    buckets: Vec<Vec<u32>>,
}

impl Sheet {
    fn new(meshes: &[(&Mesh, DMat4)], size: f64) -> Sheet {
        let tris: Vec<[DVec3; 3]> = meshes
            .iter()
            .flat_map(|(mesh, world)| {
                mesh.triangles().map(move |t| {
                    t.map(|i| world.transform_point3(mesh.positions[i as usize].as_dvec3()))
                })
            })
            .collect();
        let n = 128usize;
        let min = DVec2::splat(-size / 2.0);
        let cell = size / n as f64;
        let mut buckets = vec![Vec::new(); n * n];
        for (k, t) in tris.iter().enumerate() {
            let ps = t.map(|p| to_layout(p).0);
            let lo = ps[0].min(ps[1]).min(ps[2]);
            let hi = ps[0].max(ps[1]).max(ps[2]);
            let c = |v: f64, m: f64| (((v - m) / cell).floor().max(0.0) as usize).min(n - 1);
            for j in c(lo.y, min.y)..=c(hi.y, min.y) {
                for i in c(lo.x, min.x)..=c(hi.x, min.x) {
                    buckets[j * n + i].push(k as u32);
                }
            }
        }
        Sheet {
            tris,
            cell,
            min,
            n,
            buckets,
        }
    }

    fn height(&self, p: DVec2) -> Option<f64> {
        let c = |v: f64, m: f64| (((v - m) / self.cell).floor().max(0.0) as usize).min(self.n - 1);
        for &k in &self.buckets[c(p.y, self.min.y) * self.n + c(p.x, self.min.x)] {
            let t = self.tris[k as usize];
            let [(a, ha), (b, hb), (q, hq)] = t.map(to_layout);
            let d = (b - a).perp_dot(q - a);
            if d.abs() < 1e-12 {
                continue;
            }
            let l1 = (p - a).perp_dot(q - a) / d;
            let l2 = (b - a).perp_dot(p - a) / d;
            let l0 = 1.0 - l1 - l2;
            let eps = -1e-7;
            if l0 >= eps && l1 >= eps && l2 >= eps {
                return Some(l0 * ha + l1 * hb + l2 * hq);
            }
        }
        None
    }
}

fn node_meshes<'a>(
    scene: &'a Scene,
    worlds: &'a [DMat4],
    prefix: &'a str,
) -> impl Iterator<Item = (&'a Mesh, DMat4)> + 'a {
    scene
        .nodes
        .iter()
        .zip(worlds)
        .filter(move |(n, _)| n.name.starts_with(prefix))
        .flat_map(move |(n, w)| n.meshes.iter().map(move |m| (&scene.meshes[m.index()], *w)))
}

fn ground_meta(scene: &Scene) -> Option<String> {
    let n = scene.nodes.iter().find(|n| n.name == "ground")?;
    Some(format!("{:?}", n.metadata))
}

fn hilly_city() -> City {
    let mut c = CityConfig::preset("san_francisco").unwrap();
    c.size_m = 1400.0;
    c.roads.max_segments = 300;
    c.facades.pixels_per_metre = 4.0;
    polis::generate(&c).unwrap()
}

/// A default-preset city on its own hills (the preset's elevation map, seed 7).
fn hilly_default_city() -> City {
    let mut c = CityConfig::preset("default").unwrap();
    c.seed = 7;
    c.size_m = 1400.0;
    c.roads.max_segments = 300;
    c.facades.pixels_per_metre = 4.0;
    polis::generate(&c).unwrap()
}

/// Nothing floats above the terrain and nothing is buried by it, at every vertex.
#[test]
fn nothing_floats_and_nothing_is_buried_on_a_hilly_map() {
    stands_on_its_ground(&hilly_city());
}

/// The same on the default preset's hills.
#[test]
fn nothing_floats_and_nothing_is_buried_on_the_default_hills() {
    stands_on_its_ground(&hilly_default_city());
}

/// Samples every road, plinth and building vertex of `city` against its terrain mesh.
fn stands_on_its_ground(city: &City) {
    let scene = &city.scene;
    let worlds = scene.world_matrices();
    let e = city.config.scene.terrain_mesh.max_error_m;
    // The ground's tiles as one sheet.
    let tiles: Vec<(&Mesh, DMat4)> = node_meshes(scene, &worlds, "ground").collect();
    assert!(!tiles.is_empty(), "a ground node");
    let sheet = Sheet::new(&tiles, city.config.size_m);
    // f32 positions at up to a kilometre and 400 m of height: a millimetre of rounding.
    let tol = 2e-3;

    // Road surfaces: above the terrain, and at most the terrain's allowance plus their
    // lift above it.
    let (mut roads, mut worst_float, mut least_clearance) = (0, 0.0f64, f64::INFINITY);
    let (mut buried, mut worst_buried) = (0, 0.0f64);
    for (mesh, w) in node_meshes(scene, &worlds, "roads") {
        for p in &mesh.positions {
            let (q, h) = to_layout(w.transform_point3(p.as_dvec3()));
            let Some(g) = sheet.height(q) else { continue };
            if h < g - tol {
                buried += 1;
                if g - h > worst_buried {
                    eprintln!("buried {} at {q}", g - h);
                }
                worst_buried = worst_buried.max(g - h);
            }
            worst_float = worst_float.max(h - g);
            least_clearance = least_clearance.min(h - g);
            roads += 1;
        }
    }
    eprintln!(
        "{buried} of {roads} road vertices buried, worst {worst_buried} m, least clearance \
         {least_clearance} m; terrain {:?}",
        ground_meta(scene)
    );
    assert_eq!(buried, 0, "road vertices buried (worst {worst_buried} m)");
    assert!(roads > 1000, "{roads} road vertices");
    // Above it by at most the terrain's allowance (2 e), the corridor cut, the lifts
    // (5–13 cm) and, where a terrain leaf at the smallest size could not meet the bound
    // (the foot of a 1:2 bank) and was lowered, the bank's rise over one such leaf.
    // Bridges are left out: their surfaces stand above the ground on purpose.
    let grading = city.config.scene.road_grading;
    let leaf = city.config.scene.terrain_mesh.min_cell_m;
    let limit = 2.0 * e + polis::CORRIDOR_CUT_M + 0.15 + leaf * grading.embankment_slope;
    let bridges: Vec<(DVec2, DVec2, f64)> = city
        .roads
        .edges()
        .filter(|(_, _, _, r)| r.bridge)
        .map(|(e, _, _, r)| {
            let (a, b) = city.roads.segment(e).unwrap();
            (a, b, r.width)
        })
        .collect();
    let near_bridge = |q: DVec2| {
        bridges.iter().any(|&(a, b, w)| {
            let d = b - a;
            let t = ((q - a).dot(d) / d.length_squared().max(1e-12)).clamp(0.0, 1.0);
            q.distance(a + d * t) <= w
        })
    };
    let mut over = 0;
    for (mesh, w) in node_meshes(scene, &worlds, "roads") {
        for p in &mesh.positions {
            let (q, h) = to_layout(w.transform_point3(p.as_dvec3()));
            let Some(g) = sheet.height(q) else { continue };
            if h - g > limit + tol && !near_bridge(q) {
                over += 1;
            }
        }
    }
    eprintln!("worst float {worst_float} m (limit {limit} m off bridges)");
    // None beyond the limit: banks past their widest end in a continuous wall face (no
    // step under a road) and leaves that miss the bound are lowered only by their rise.
    assert_eq!(
        over, 0,
        "{over} of {roads} road vertices float more than {limit} m"
    );

    // Block plinths: the top above the terrain, the bottom below it (within `tol`, the
    // f32 rounding), at every vertex: they reach below the terrain by its allowance, the
    // corridor cut and the lowering of leaves at the foot of a bank (`foot_of`).
    let (mut plinths, mut plinth_gaps, mut plinth_bottoms) = (0, 0, 0);
    for (mesh, w) in node_meshes(scene, &worlds, "block ") {
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            let (q, h) = to_layout(w.transform_point3(p.as_dvec3()));
            let Some(g) = sheet.height(q) else { continue };
            if n.y > 0.5 {
                assert!(h >= g - tol, "plinth top buried at {q}: {h} < {g}");
                plinths += 1;
            } else if n.y < -0.5 {
                plinth_bottoms += 1;
                if h > g + tol {
                    plinth_gaps += 1;
                }
            }
        }
    }
    assert!(plinths > 100, "{plinths} plinth vertices");
    eprintln!("{plinth_gaps} of {plinth_bottoms} plinth bottom vertices above the terrain");
    assert_eq!(plinth_gaps, 0, "of {plinth_bottoms} plinth bottom vertices");

    // Buildings: the floor is not below the terrain at any footprint corner (not buried),
    // the bottom reaches the terrain under each corner (not floating), both within `tol`.
    let (mut checked, mut building_gaps) = (0, 0);
    for (b, node) in city.buildings.iter().zip(
        scene
            .nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| n.name.starts_with("building ")),
    ) {
        let (k, node) = node;
        let world = worlds[k];
        let floor = world.transform_point3(DVec3::ZERO).y;
        let bottom = node
            .meshes
            .iter()
            .flat_map(|m| scene.meshes[m.index()].positions.iter())
            .map(|p| world.transform_point3(p.as_dvec3()).y)
            .fold(f64::INFINITY, f64::min);
        for &c in b.footprint.points() {
            let Some(g) = sheet.height(c) else { continue };
            assert!(
                floor >= g - tol,
                "building {} buried: floor {floor} < {g}",
                b.id
            );
            building_gaps += usize::from(bottom > g + tol);
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} building corners");
    eprintln!("{building_gaps} of {checked} building corners above the terrain");
    assert_eq!(building_gaps, 0, "of {checked} building corners");
}

/// A small city of the default preset with `patch` merged into its configuration.
fn small_with(patch: serde_json::Value) -> polis::Result<City> {
    let mut base = serde_json::to_value(CityConfig::preset("default").unwrap()).unwrap();
    base["size_m"] = 700.0.into();
    base["roads"]["max_segments"] = 120.into();
    base["facades"]["pixels_per_metre"] = 4.0.into();
    fn merge(a: &mut serde_json::Value, b: serde_json::Value) {
        match (a, b) {
            (serde_json::Value::Object(a), serde_json::Value::Object(b)) => {
                for (k, v) in b {
                    merge(a.entry(k).or_insert(serde_json::Value::Null), v);
                }
            }
            (a, b) => *a = b,
        }
    }
    merge(&mut base, patch);
    let config = CityConfig::from_json(&base.to_string(), "test")?;
    polis::generate(&config)
}

/// Every scene vertex is finite and the scene validates.
fn sound(city: &City) {
    city.scene.validate().unwrap();
    for m in &city.scene.meshes {
        assert!(m.positions.iter().all(|p| p.is_finite()));
    }
    let ground = city.scene.nodes.iter().any(|n| n.name == "ground");
    assert!(ground, "the ground is there");
}

/// Extreme ground, a map of parks, a grade limit of 0: a city or a typed error, never a
/// panic or a NaN vertex.
#[test]
fn extreme_ground_degrades_without_panics_or_nan() {
    use serde_json::json;
    let fbm = |wavelength: f64| json!({"kind": "fbm", "seed": 5, "octaves": 2, "wavelength_m": wavelength});
    // 300 m cliffs.
    let cliffs = json!({"maps": {"elevation": {"kind": "scaled", "factor": 300.0,
        "field": {"kind": "threshold", "threshold": 0.0, "field": fbm(250.0)}}}});
    // 2 km spikes 20 m apart.
    let spikes =
        json!({"maps": {"elevation": {"kind": "scaled", "factor": 2000.0, "field": fbm(20.0)}}});
    // Everything under water, far below the sea.
    let drowned = json!({"maps": {"water": {"kind": "constant", "value": 1.0},
        "elevation": {"kind": "constant", "value": -500.0}}});
    // Parks everywhere.
    let parks = json!({"maps": {"parks": {"kind": "constant", "value": 1.0}}});
    // No grade allowed on a hill.
    let flat_roads = json!({"maps": {"elevation": {"kind": "scaled", "factor": 60.0, "field": fbm(400.0)}},
        "scene": {"road_grading": {"max_grade_highway": 0.0, "max_grade_street": 0.0}}});
    for (name, patch) in [
        ("cliffs", cliffs),
        ("spikes", spikes),
        ("drowned", drowned),
        ("parks", parks),
        ("flat roads", flat_roads),
    ] {
        match small_with(patch) {
            Ok(city) => sound(&city),
            Err(e) => assert!(!e.to_string().is_empty(), "{name}"),
        }
    }
    // A negative grade limit is a configuration error naming the field.
    let bad = small_with(json!({"scene": {"road_grading": {"max_grade_street": -1.0}}}));
    assert!(bad.unwrap_err().to_string().contains("max_grade_street"));
    let bad = small_with(json!({"scene": {"land_use_pixels": 1000}}));
    assert!(bad.unwrap_err().to_string().contains("land_use_pixels"));
}

/// Graded roads keep their class's limit on a hilly map, and the statistics report the
/// cut and fill; with `terrain` off the scene has no ground node.
#[test]
fn roads_are_graded_and_earthworks_reported() {
    let city = hilly_city();
    let w = city.stats.earthworks;
    assert!(w.cut_m3 > 0.0 && w.fill_m3 > 0.0, "{w:?}");
    let limit = city.config.scene.road_grading;
    assert!(w.steepest_grade <= limit.max_grade_street.max(limit.max_grade_highway) + 1e-9);
    let report = city.statistics().unwrap();
    assert_eq!(report.earthworks.cut_m3, w.cut_m3);
    assert!(report.to_string().contains("cut / fill"));
    // The ground is its own node in the glb (the tiled layout's layer `ground`) and its
    // own groups in the OBJ.
    let glb_has_ground = |city: &City| {
        let mut glb = Vec::new();
        city.write_glb(&mut glb).unwrap();
        let doc = polis::export::gltf::Gltf::from_slice(&glb).unwrap();
        doc.nodes().any(|n| n.name() == Some("ground"))
    };
    assert!(glb_has_ground(&city));
    let (mut obj, mut files) = (Vec::new(), polis::export::sink::MemorySink::new());
    polis::export::obj::write_obj(&city.scene, &Default::default(), &mut obj, &mut files).unwrap();
    let obj = String::from_utf8(obj).unwrap();
    assert!(obj.lines().any(|l| l.starts_with("g ground_")));
    let mut config = city.config.clone();
    config.scene.terrain = false;
    config.roads.max_segments = 80;
    let bare = polis::generate(&config).unwrap();
    assert!(!bare.scene.nodes.iter().any(|n| n.name == "ground"));
    assert!(!glb_has_ground(&bare));
}

/// The triangles of `mesh` (in world coordinates by `world`) that face down, as a mesh.
fn facing_down(mesh: &Mesh, world: DMat4) -> Mesh {
    let mut out = Mesh::new(None);
    for t in mesh.triangles() {
        let [a, b, c] = t.map(|i| world.transform_point3(mesh.positions[i as usize].as_dvec3()));
        if (b - a).cross(c - a).y < 0.0 {
            let base = out.positions.len() as u32;
            out.positions.extend([a, b, c].map(|p| p.as_vec3()));
            out.indices.extend([base, base + 1, base + 2]);
        }
    }
    out
}

/// `manhattan` at full size (seed 1: a highway bridge over the East River to the
/// mainland and a short one over a cove of the west shore):
/// every deck and pier in the `bridges` node is a closed, 2-manifold, outward shell by
/// the edge-use check; every deck's underside over the water is at least the clearance
/// above the water surface, or the height its span allows within the grade limit
/// (`min over its ends of h + g · (d − 3 · BRIDGE_CURVE_M)`, `d` the distance to the
/// end); every pier stands from a foot into the bed (the terrain) up to the deck; no
/// road, plinth top or building floor over a water outline lies below the water; the
/// water surface lies under the banks (the terrain at the shore above it); no NaN.
#[test]
fn bridge_decks_clear_the_water_on_piers_and_are_closed_solids() {
    let mut c = CityConfig::preset("manhattan").unwrap();
    c.facades.pixels_per_metre = 1.0;
    let city = polis::generate(&c).unwrap();
    sound(&city);
    // Roads, plinths and buildings on their ground, the bed cut in under the water.
    stands_on_its_ground(&city);
    let scene = &city.scene;
    let worlds = scene.world_matrices();
    let bridges = city.roads.edges().filter(|(_, _, _, r)| r.bridge).count();
    assert!(bridges > 0, "manhattan has bridges");
    let in_node =
        |name: &'static str| -> Vec<(&Mesh, DMat4)> { node_meshes(scene, &worlds, name).collect() };
    let parts = in_node("bridges");
    let material = |m: &Mesh| {
        m.material
            .map(|id| scene.materials[id.index()].name.clone())
            .unwrap_or_default()
    };
    let report = polis::geom::mesh::edge_use(parts.iter().map(|p| p.0));
    eprintln!("{bridges} bridge roads: {report:?}");
    assert!(report.is_solid_shells(), "{report:?}");
    assert!(report.components >= 1 && report.components <= bridges * 64);

    let water = Sheet::new(&in_node("water"), c.size_m);
    let terrain = Sheet::new(&in_node("ground"), c.size_m);
    let tol = 2e-3;
    // Bridge ends: nodes with a bridge road that are not inside a chain of two.
    let ends: Vec<DVec2> = city
        .roads
        .nodes()
        .filter(|&(n, _, _)| {
            let at = city.roads.edges_at(n).unwrap();
            let b = at
                .iter()
                .filter(|&&e| city.roads.edge_payload(e).unwrap().bridge)
                .count();
            b > 0 && !(b == 2 && at.len() == 2)
        })
        .map(|(_, p, _)| p)
        .collect();
    let g = c
        .scene
        .road_grading
        .max_grade_highway
        .min(c.scene.road_grading.max_grade_street);
    let (deck, worldd) = parts
        .iter()
        .copied()
        .find(|p| material(p.0) == "bridge")
        .expect("decks");
    let underside = facing_down(deck, worldd);
    let (mut over, mut lowest_mid, mut highest) = (0, f64::INFINITY, f64::NEG_INFINITY);
    for p in &underside.positions {
        let (q, h) = to_layout(p.as_dvec3());
        let Some(level) = water.height(q) else {
            continue;
        };
        over += 1;
        let (d, end) = ends
            .iter()
            .map(|&e| (e.distance(q), e))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap();
        let h_end = terrain.height(end).unwrap();
        let span =
            h_end + g * (d - 3.0 * polis::BRIDGE_CURVE_M) - (polis::BRIDGE_DECK_M + 0.04) - level;
        let want = polis::BRIDGE_CLEARANCE_M.min(span);
        assert!(
            h - level >= want - tol,
            "deck at {q}: {} above the water < {want}",
            h - level
        );
        if span > polis::BRIDGE_CLEARANCE_M {
            lowest_mid = lowest_mid.min(h - level);
        }
        highest = highest.max(h - level);
    }
    for (e, _, _, r) in city.roads.edges().filter(|(_, _, _, r)| r.bridge) {
        let (a, b) = city.roads.segment(e).unwrap();
        eprintln!(
            "bridge road {a} – {b}: {:.1} m, {:?}",
            a.distance(b),
            r.class
        );
    }
    eprintln!("highest underside above the water {highest} m");
    eprintln!(
        "{over} deck underside vertices over the water; lowest where the span allows the clearance: {lowest_mid} m"
    );
    assert!(over > 100, "{over}");
    // Manhattan's bridges are short (35 and 100 m): the span limits them (the full
    // clearance over a wide river: `ground::tests`); the longer one clears the water.
    assert!(lowest_mid >= polis::BRIDGE_CLEARANCE_M - tol);
    assert!(highest > 0.5, "{highest}");

    // Piers (24 vertices each): from a foot into the bed up to the deck's underside.
    let deck_bottom = Sheet::new(&[(&underside, DMat4::IDENTITY)], c.size_m);
    let (pier, worldp) = parts
        .iter()
        .copied()
        .find(|p| material(p.0) == "bridge pier")
        .expect("piers");
    let e = c.scene.terrain_mesh.max_error_m;
    let n_piers = pier.positions.len() / 24;
    assert!(n_piers >= 2, "{n_piers} piers");
    for k in 0..n_piers {
        let ps: Vec<DVec3> = pier.positions[24 * k..24 * (k + 1)]
            .iter()
            .map(|p| worldp.transform_point3(p.as_dvec3()))
            .collect();
        let lo = ps.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        let hi = ps.iter().map(|p| p.y).fold(f64::NEG_INFINITY, f64::max);
        let centre = ps.iter().map(|&p| to_layout(p).0).sum::<DVec2>() / 24.0;
        let bed = terrain.height(centre).unwrap();
        let top = deck_bottom.height(centre).unwrap();
        assert!(hi > lo, "pier {k}");
        // The terrain lies up to 2 e under the bed it follows.
        assert!(
            lo <= bed - polis::PIER_FOOT_M + 2.0 * e + tol && lo >= bed - polis::PIER_FOOT_M - tol,
            "pier {k} at {centre}: foot {lo}, bed {bed}"
        );
        assert!(
            hi <= top + tol && hi >= top - 0.2,
            "pier {k} at {centre}: top {hi}, deck {top}"
        );
        if let Some(level) = water.height(centre) {
            assert!(bed < level, "pier {k} at {centre} stands in the water");
        }
    }

    // Nothing on land under the water: road vertices (off bridges), plinth tops and
    // building floors over a water outline lie at or above its surface.
    let bridge_roads: Vec<(DVec2, DVec2, f64)> = city
        .roads
        .edges()
        .filter(|(_, _, _, r)| r.bridge)
        .map(|(e, _, _, r)| {
            let (a, b) = city.roads.segment(e).unwrap();
            (a, b, r.width)
        })
        .collect();
    let near_bridge = |q: DVec2| {
        bridge_roads.iter().any(|&(a, b, w)| {
            let d = b - a;
            let t = ((q - a).dot(d) / d.length_squared().max(1e-12)).clamp(0.0, 1.0);
            q.distance(a + d * t) <= w
        })
    };
    let mut wet = [0usize; 3];
    for (k, prefix) in ["roads", "block "].into_iter().enumerate() {
        for (mesh, w) in node_meshes(scene, &worlds, prefix) {
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                let (q, h) = to_layout(w.transform_point3(p.as_dvec3()));
                if (k == 1 && n.y < 0.5) || (k == 0 && near_bridge(q)) {
                    continue;
                }
                if let Some(level) = water.height(q) {
                    wet[k] += 1;
                    assert!(
                        h >= level - tol,
                        "{prefix} vertex at {q}: {h} under {level}"
                    );
                }
            }
        }
    }
    for (b, (k, _)) in city.buildings.iter().zip(
        scene
            .nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| n.name.starts_with("building ")),
    ) {
        let floor = worlds[k].transform_point3(DVec3::ZERO).y;
        for &corner in b.footprint.points() {
            if let Some(level) = water.height(corner) {
                wet[2] += 1;
                assert!(
                    floor >= level - tol,
                    "building {} at {corner}: {floor} < {level}",
                    b.id
                );
            }
        }
    }
    eprintln!(
        "over a water outline: {} road vertices, {} plinth tops, {} building corners",
        wet[0], wet[1], wet[2]
    );
    // The water runs under its banks: at the shore (the outline) the terrain stands
    // above the water surface.
    let water_mesh = in_node("water");
    let (mut shore, mut dry) = (0, 0);
    for (mesh, w) in &water_mesh {
        for p in &mesh.positions {
            let (q, level) = to_layout(w.transform_point3(p.as_dvec3()));
            let border = q.x.abs().max(q.y.abs()) > 0.5 * c.size_m - 1.0;
            if let (false, Some(ground)) = (border, terrain.height(q)) {
                shore += 1;
                dry += usize::from(ground > level);
                // The terrain's own bound: up to 2 e below the field it meshes (whose
                // shore is at or above the level).
                assert!(
                    ground > level - 2.0 * e,
                    "shore vertex {q}: terrain {ground} under the water at {level}"
                );
            }
        }
    }
    eprintln!("{dry} of {shore} shoreline vertices with the terrain above the water");
    // Where the terrain's triangles span the bank's top and the bed, a shore vertex can
    // lie within the terrain's error under the water (seed 1: 2 of 615, by 1.3 cm).
    assert!(shore > 100 && dry * 100 >= shore * 99, "{dry} of {shore}");
}
