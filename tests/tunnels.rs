//! Tunnels through the whole pipeline (P&M §3.3): a highway across a park strip passes
//! under it; the scene draws no road surface between the portals and a frame at each,
//! the map layers keep the road with its `tunnel` flag; a park over the whole map is a
//! typed error.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use polis::geom::field::{FieldSpec, Raster};
use polis::geom::{Aabb2, DVec2};
use polis::{CityConfig, MapSpec};

/// Park between x = `lo` and `hi` (metres), the whole height of a 1.2 km map.
fn strip(lo: f64, hi: f64) -> MapSpec {
    let texels = 240; // 5 m texels over −600..600
    let data = (0..texels)
        .map(|i| {
            let x = -600.0 + 5.0 * (f64::from(i) + 0.5);
            if (lo..=hi).contains(&x) { 1.0 } else { 0.0 }
        })
        .collect();
    let extent = Aabb2::new(DVec2::new(-600.0, -600.0), DVec2::new(600.0, 600.0));
    MapSpec::Field(FieldSpec::Raster(
        Raster::new(texels as usize, 1, extent, data).unwrap(),
    ))
}

fn config() -> CityConfig {
    let mut c = CityConfig::preset("default").unwrap();
    c.size_m = 1200.0;
    c.maps.parks = Some(strip(150.0, 300.0));
    c.maps.water = None;
    c.maps.elevation = None;
    c.roads.start = Some([0.0, 0.0]);
    c.roads.start_angle_deg = Some(0.0);
    c.roads.max_segments = 260;
    c
}

#[test]
fn a_highway_under_a_park_is_a_tunnel_without_surface() {
    let city = polis::generate(&config()).unwrap();
    let tunnels: Vec<(DVec2, DVec2)> = city
        .roads
        .edges()
        .filter(|(_, _, _, r)| r.tunnel)
        .map(|(e, _, _, _)| city.roads.segment(e).unwrap())
        .collect();
    assert!(
        !tunnels.is_empty(),
        "the highway east passes under the park"
    );
    // No road surface vertex inside the park (the tunnel's stretch), a road east of it.
    let scene = &city.scene;
    let roads = scene.nodes.iter().find(|n| n.name == "roads").unwrap();
    let mut east = false;
    for &id in &roads.meshes {
        for p in &scene.meshes[id.index()].positions {
            assert!(!(165.0..285.0).contains(&p.x), "road surface at {p:?}");
            east |= p.x > 300.0;
        }
    }
    assert!(east, "the city goes on beyond the park");
    // A portal frame at each end.
    let portals = scene
        .nodes
        .iter()
        .find(|n| n.name == "tunnel portals")
        .unwrap();
    let frames = &scene.meshes[portals.meshes[0].index()];
    frames.validate().unwrap();
    assert!(frames.positions.iter().any(|p| p.x < 150.0));
    assert!(frames.positions.iter().any(|p| p.x > 300.0));
    // The map layers (GeoJSON, SVG) keep the road and its flag.
    let map = city.map_layers().unwrap();
    assert_eq!(map.roads.iter().filter(|r| r.tunnel).count(), tunnels.len());
}

#[test]
fn without_tunnels_the_park_stops_the_highway() {
    let mut c = config();
    c.roads.max_tunnel_length_m = 0.0;
    let city = polis::generate(&c).unwrap();
    assert!(city.roads.edges().all(|(_, _, _, r)| !r.tunnel));
    assert!(city.roads.nodes().all(|(_, p, _)| p.x < 300.0));
    assert!(!city.scene.nodes.iter().any(|n| n.name == "tunnel portals"));
}

#[test]
fn a_park_over_the_whole_map_is_a_typed_error() {
    let mut c = config();
    c.roads.start = None;
    c.maps.parks = Some(MapSpec::Field(FieldSpec::Constant { value: 1.0 }));
    let err = polis::generate(&c).unwrap_err();
    assert!(
        matches!(
            err,
            polis::Error::Roads(polis::roads::RoadError::NoLegalStart)
        ),
        "{err}"
    );
}

/// A 3 × 3 grid of 120 m blocks whose middle column's middle street (between the two
/// centre blocks) is a tunnel.
struct GridWithTunnel;

impl polis::stages::RoadStage for GridWithTunnel {
    fn roads(
        &self,
        _cx: &polis::stages::StageContext<'_>,
    ) -> polis::Result<polis::stages::RoadsOutput> {
        use polis::roads::{Junction, Road, RoadClass, RoadNetwork};
        let mut net = RoadNetwork::new();
        let mut node = Vec::new();
        for j in 0..4 {
            for i in 0..4 {
                let p = DVec2::new(f64::from(i) * 120.0 - 180.0, f64::from(j) * 120.0 - 180.0);
                node.push(net.add_node(p, Junction::default())?);
            }
        }
        let road = |tunnel| Road {
            class: RoadClass::Street,
            width: 8.0,
            bridge: false,
            tunnel,
            step: 0,
        };
        for j in 0..4 {
            for i in 0..4 {
                let k = j * 4 + i;
                if i < 3 {
                    net.add_edge(node[k], node[k + 1], road(false))?;
                }
                if j < 3 {
                    // The street from (−60, −60) to (−60, 60) runs underground.
                    net.add_edge(node[k], node[k + 4], road(i == 1 && j == 1))?;
                }
            }
        }
        Ok(polis::stages::RoadsOutput {
            network: net,
            growth: None,
            skipped: Vec::new(),
            districts: Vec::new(),
        })
    }
}

/// The land above a tunnel is one piece: no cell (block) is bounded by a tunnel, the
/// two blocks either side of it are one, and lots stand above it (P&M §3.3).
#[test]
fn no_cell_is_bounded_by_a_tunnel() {
    let mut c = CityConfig::preset("default").unwrap();
    c.size_m = 500.0;
    c.maps.parks = None;
    c.maps.water = None;
    c.maps.elevation = None;
    let city = polis::Pipeline::default()
        .with_roads(GridWithTunnel)
        .generate(&c)
        .unwrap();
    let tunnel = |e| city.roads.edge_payload(e).is_ok_and(|r| r.tunnel);
    assert_eq!(city.roads.edges().filter(|(e, ..)| tunnel(*e)).count(), 1);
    let rings = city
        .cells
        .cells
        .iter()
        .flat_map(|c| std::iter::once(&c.boundary).chain(&c.holes));
    assert!(
        rings.flat_map(|r| r.edges.iter()).all(|&e| !tunnel(e)),
        "a cell ring runs along the tunnel"
    );
    // Nine blocks of the grid, the two either side of the tunnel joined.
    assert_eq!(city.cells.cells.len(), 8);
    // One block covers the land above the tunnel, ...
    let above = DVec2::new(-60.0, 0.0);
    assert!(
        city.blocks.iter().any(|b| b.polygon.contains(above)),
        "no block on the land above the tunnel"
    );
    // ... with lots either side of its line, none in its portals' mouths (a road width
    // deep from each portal, ± half the road's width).
    let west = city
        .lots
        .iter()
        .filter(|l| l.lot.polygon.bbox().max.x < -60.0);
    let east = city
        .lots
        .iter()
        .filter(|l| l.lot.polygon.bbox().min.x > -60.0);
    let merged = |l: &&polis::CityLot| {
        let b = l.lot.polygon.bbox();
        b.min.x > -176.0 && b.max.x < 56.0 && b.min.y > -56.0 && b.max.y < 56.0
    };
    assert!(west.filter(merged).count() > 0 && east.filter(merged).count() > 0);
    for l in &city.lots {
        for mouth in [DVec2::new(-60.0, -56.0), DVec2::new(-60.0, 56.0)] {
            assert!(
                !l.lot.polygon.contains(mouth),
                "lot {} stands in a portal's mouth",
                l.id
            );
        }
    }
}
