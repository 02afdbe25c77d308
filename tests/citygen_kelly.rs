//! The Citygen road mode fed by a Kelly primary network (issue 17's `PrimaryNetwork`),
//! and the course report's grid road builders as a per-cell pattern.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis::CityConfig;
use polis::citygen::{
    CellOverride, CellPatternChoice, CitygenNetwork, GridPattern, InlinePrimary, PrimarySource,
    citygen_network,
};
use polis::geom::{Aabb2, DVec2};
use polis::roads::RoadClass;
use polis::roads::primary::{
    Edit, EditOptions, Endpoint, PrimaryEditor, PrimaryNetwork, RoadPreset, Strategy, Terrain,
};
use polis::roads::secondary::Neighbourhood;
use polis::stages::StageContext;

/// A 1000 m square of straight inner-city roads by the chain tool, then its diagonal from corner to corner: two cells.
fn square_with_diagonal() -> PrimaryNetwork {
    let terrain = Terrain::flat(Aabb2::new(DVec2::splat(-700.0), DVec2::splat(700.0))).unwrap();
    let mut ed = PrimaryEditor::new(terrain, EditOptions::default()).unwrap();
    // Straight roads: on flat terrain the elevation strategies have no preference.
    let mut spec = RoadPreset::InnerCity.spec();
    spec.params.strategy = Strategy::Straight;
    let first = ed.network().next_node_id();
    ed.apply(&Edit::AddNode {
        at: DVec2::new(-500.0, -500.0),
        label: None,
    })
    .unwrap();
    let mut at = first;
    for (x, y) in [
        (500.0, -500.0),
        (500.0, 500.0),
        (-500.0, 500.0),
        (-500.0, -500.0),
    ] {
        let p = ed
            .propose(&Edit::Chain {
                from: at,
                to: DVec2::new(x, y),
                spec,
            })
            .unwrap();
        at = p.end_node().unwrap();
        ed.commit(&p).unwrap();
    }
    assert_eq!(at, first);
    ed.apply(&Edit::AddRoad {
        from: Endpoint::At(DVec2::new(-500.0, -500.0)),
        to: Endpoint::At(DVec2::new(500.0, 500.0)),
        spec,
    })
    .unwrap();
    ed.network().check_invariants().unwrap();
    assert_eq!(ed.network().node_count(), 4);
    assert_eq!(ed.network().road_count(), 5);
    ed.into_network()
}

fn config(primary: PrimarySource) -> CityConfig {
    let mut c = CityConfig::preset("milan").unwrap();
    c.size_m = 1400.0;
    c.citygen.primary = primary;
    c.citygen.by_population.clear();
    c.citygen.overrides.clear();
    c.citygen.neighbourhood = Neighbourhood::Manhattan.into();
    c
}

fn network(config: &CityConfig, threads: usize) -> CitygenNetwork {
    let maps = polis::CityMaps::build(&config.maps, 7).unwrap();
    let cx = StageContext {
        config,
        maps: &maps,
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| citygen_network(&cx))
        .unwrap()
        .0
}

fn json(n: &CitygenNetwork) -> String {
    serde_json::to_string(&n.network).unwrap()
}

#[test]
fn an_inline_kelly_network_makes_its_two_cells_the_same_on_any_thread_count() {
    let net = square_with_diagonal();
    let c = config(PrimarySource::Kelly {
        network: InlinePrimary(Box::new(net.clone())),
    });
    // The configuration carries the network in its serde form and reads back equal.
    let back = CityConfig::from_json(&c.to_json(), "kelly").unwrap();
    assert_eq!(back, c);
    let a = network(&c, 1);
    let b = network(&c, 3);
    assert_eq!(a.cells.len(), 2, "skipped: {:?}", a.skipped);
    assert!(a.skipped.is_empty());
    assert_eq!(json(&a), json(&b));
    // The primary graph is the low-level graph of the network, straight runs merged:
    // the same length, the four corners and nothing else on this flat square.
    let low = net.to_road_network().unwrap();
    let length = |g: &polis::roads::RoadNetwork| -> f64 {
        g.edges()
            .map(|(e, ..)| {
                let (p, q) = g.segment(e).unwrap();
                p.distance(q)
            })
            .sum()
    };
    let (simple, plotted) = (length(&a.primary), length(&low.network));
    assert!(
        simple <= plotted + 1e-6 && simple > plotted * 0.995,
        "{simple} vs {plotted}"
    );
    assert!(a.primary.edges().count() < low.network.edges().count());
    a.network.check_invariants().unwrap();
    let streets = a
        .network
        .edges()
        .filter(|e| e.3.class == RoadClass::Street)
        .count();
    assert!(streets > 20, "{streets} streets");
    // The whole pipeline runs on it.
    let city = polis::generate(&c).unwrap();
    assert!(!city.buildings.is_empty());
}

#[test]
fn a_kelly_spec_file_and_a_saved_network_file_give_the_same_cells() {
    let dir = std::env::temp_dir().join(format!("polis-citygen-kelly-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // The saved network: exactly the inline network's graph.
    let net = square_with_diagonal();
    let saved = dir.join("network.json");
    std::fs::write(&saved, net.to_json().unwrap()).unwrap();
    let from_file = network(&config(PrimarySource::KellyFile { path: saved }), 1);
    let inline = network(
        &config(PrimarySource::Kelly {
            network: InlinePrimary(Box::new(net)),
        }),
        1,
    );
    assert_eq!(json(&from_file), json(&inline));
    // A hand-written spec: a square and its diagonal, plotted over the city's terrain.
    let spec = dir.join("spec.json");
    std::fs::write(
        &spec,
        r#"{"nodes": [{"id": 1, "x": -500, "y": -500}, {"id": 2, "x": 500, "y": -500},
                      {"id": 3, "x": 500, "y": 500}, {"id": 4, "x": -500, "y": 500}],
            "roads": [{"a": 1, "b": 2, "class": "InnerCity"}, {"a": 2, "b": 3, "class": "InnerCity"},
                      {"a": 3, "b": 4, "class": "InnerCity"}, {"a": 4, "b": 1, "class": "InnerCity"},
                      {"a": 1, "b": 3, "class": "InnerCity"}]}"#,
    )
    .unwrap();
    let c = config(PrimarySource::KellyFile { path: spec });
    let a = network(&c, 1);
    assert_eq!(a.cells.len() + a.skipped.len(), 2, "{:?}", a.skipped);
    assert_eq!(json(&a), json(&network(&c, 3)));
    // The same square as GeoJSON: corner points, then lines between them.
    let geojson = dir.join("square.geojson");
    let line = |a: (i32, i32), b: (i32, i32)| {
        format!(
            r#"{{"type": "Feature", "properties": {{"class": "InnerCity"}}, "geometry": {{"type": "LineString", "coordinates": [[{}, {}], [{}, {}]]}}}}"#,
            a.0, a.1, b.0, b.1
        )
    };
    let (p1, p2, p3, p4) = ((-500, -500), (500, -500), (500, 500), (-500, 500));
    let lines = [
        line(p1, p2),
        line(p2, p3),
        line(p3, p4),
        line(p4, p1),
        line(p1, p3),
    ];
    std::fs::write(
        &geojson,
        format!(
            r#"{{"type": "FeatureCollection", "features": [{}]}}"#,
            lines.join(",")
        ),
    )
    .unwrap();
    let g = network(&config(PrimarySource::KellyFile { path: geojson }), 1);
    assert_eq!(g.cells.len() + g.skipped.len(), 2, "{:?}", g.skipped);
    // Bad files are typed errors.
    let bad = dir.join("bad.json");
    std::fs::write(&bad, r#"{"nodes": [{"id": 1, "x": "west"}]}"#).unwrap();
    let maps = polis::CityMaps::build(&c.maps, 7).unwrap();
    let c = config(PrimarySource::KellyFile { path: bad });
    let cx = StageContext {
        config: &c,
        maps: &maps,
    };
    assert!(matches!(
        citygen_network(&cx),
        Err(polis::Error::Parse { .. })
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Street edges of cell `k` and how many run along one of the two directions of its
/// first street (grid streets turn by 90° only; the runs on to the boundary may not).
fn axis_aligned(n: &CitygenNetwork, k: usize) -> (usize, usize) {
    let segs: Vec<(DVec2, DVec2)> = n.cells[k].segments().map(|(a, b, _)| (a, b)).collect();
    let Some(&(a0, b0)) = segs.first() else {
        return (0, 0);
    };
    let axis = (b0 - a0).normalize();
    let aligned = segs
        .iter()
        .filter(|(a, b)| {
            let d = (*b - *a).normalize();
            d.dot(axis).abs() > 1.0 - 1e-9 || d.perp_dot(axis).abs() > 1.0 - 1e-9
        })
        .count();
    (segs.len(), aligned)
}

#[test]
fn a_cell_overridden_to_downtown_gets_grid_builder_streets() {
    let mut c = config(PrimarySource::Kelly {
        network: InlinePrimary(Box::new(square_with_diagonal())),
    });
    c.citygen.overrides = vec![CellOverride {
        at: [250.0, -250.0],
        neighbourhood: GridPattern::Downtown.into(),
    }];
    // The names read from JSON as before, the grid patterns beside Kelly's.
    let back = CityConfig::from_json(&c.to_json(), "downtown").unwrap();
    assert_eq!(
        back.citygen.overrides[0].neighbourhood,
        CellPatternChoice::Grid(GridPattern::Downtown)
    );
    let a = network(&c, 1);
    assert_eq!(json(&a), json(&network(&c, 3)));
    a.network.check_invariants().unwrap();
    assert_eq!(a.cells.len(), 2, "{:?}", a.skipped);
    // The override's cell is the one below the diagonal (paths wiggle by metres).
    let inside = |k: usize| {
        a.cells[k].segments().all(|(x, y, _)| {
            let m = (x + y) * 0.5;
            m.y < m.x + 20.0
        })
    };
    let (grid, kelly) = if inside(0) { (0, 1) } else { (1, 0) };
    assert!(inside(grid));
    // Grid streets: axis-parallel runs (all but the boundary joins), no Kelly growth
    // steps, and Downtown's no-dead-end rule: no street ends inside the cell.
    let (total, aligned) = axis_aligned(&a, grid);
    assert!(
        total > 10 && aligned * 10 >= total * 8,
        "{aligned} of {total}"
    );
    assert_eq!(a.cells[grid].report.steps, 0);
    let g = &a.cells[grid].network;
    for n in g.node_ids() {
        let edges = g.edges_at(n).unwrap();
        let street = edges
            .iter()
            .any(|&e| g.edge_payload(e).unwrap().class == RoadClass::Street);
        assert!(
            !street || edges.len() >= 2,
            "a dead end in the Downtown cell"
        );
    }
    // The other cell stays Kelly's Manhattan, whose deviated directions are not a grid.
    let (total, aligned) = axis_aligned(&a, kelly);
    assert!(
        total > 10 && aligned * 10 < total * 8,
        "{aligned} of {total}"
    );
    // Residential also grows, and differs.
    c.citygen.overrides[0].neighbourhood = GridPattern::Residential.into();
    let r = network(&c, 1);
    r.network.check_invariants().unwrap();
    assert_ne!(json(&r), json(&a));
}
