//! Kelly's primary network feeds polis-cells: the low-level graph of an edited primary
//! network is a planar road graph whose bounded faces are the city cells, and every cell
//! edge leads back to its primary road.

#![allow(clippy::unwrap_used)]

use polis::geom::{Aabb2, DVec2};
use polis::roads::primary::{Edit, EditOptions, Endpoint, PrimaryEditor, RoadPreset, Terrain};

#[test]
fn cells_of_an_edited_primary_network() {
    let terrain = Terrain::flat(Aabb2::new(DVec2::splat(-1000.0), DVec2::splat(1000.0))).unwrap();
    let mut ed = PrimaryEditor::new(terrain, EditOptions::default()).unwrap();
    let spec = RoadPreset::InnerCity.spec();
    // A square ring by the chain tool, then two roads across it: the crossings become
    // junctions, and the square falls into four cells.
    let corners = [
        (-400.0, -400.0),
        (400.0, -400.0),
        (400.0, 400.0),
        (-400.0, 400.0),
    ];
    let first = ed.network().next_node_id();
    ed.apply(&Edit::AddNode {
        at: DVec2::new(-400.0, -400.0),
        label: None,
    })
    .unwrap();
    let mut at = first;
    for &(x, y) in corners.iter().skip(1).chain(std::iter::once(&corners[0])) {
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
    assert_eq!(at, first); // the chain closed onto its first node (node snap)
    let across = |a: (f64, f64), b: (f64, f64)| Edit::AddRoad {
        from: Endpoint::At(DVec2::new(a.0, a.1)),
        to: Endpoint::At(DVec2::new(b.0, b.1)),
        spec,
    };
    ed.apply(&across((-600.0, 10.0), (600.0, -10.0))).unwrap();
    ed.apply(&across((-10.0, -600.0), (10.0, 600.0))).unwrap();
    let net = ed.network();
    net.check_invariants().unwrap();
    let low = net.to_road_network().unwrap();
    let cells = polis::cells::extract(&low.network).unwrap();
    assert_eq!(cells.cells.len(), 4);
    for cell in &cells.cells {
        assert!(cell.boundary.area() > 100_000.0);
    }
    // Every graph edge maps back to a live primary road.
    for (e, _, _, _) in low.network.edges() {
        net.road(low.road_of(e).unwrap()).unwrap();
    }
}
