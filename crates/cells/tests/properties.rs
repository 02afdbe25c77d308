//! Property tests on random planar graphs, checked against an independent half-edge face
//! walk written here (it shares nothing with the crate but the graph's rotation system).
//!
//! Inputs: perturbed grids with random edges removed, Delaunay triangulations of random
//! points (many of them on a small integer lattice: collinear and cocircular points) with
//! random edges removed, and concentric rings joined by random connectors with dead ends
//! (nesting, bridges, separate components).

#![allow(clippy::unwrap_used)]

use std::collections::BTreeMap;

use polis_cells::geom::polygon::{locate_in_ring, ring_signed_area};
use polis_cells::geom::{DVec2, EdgeId, NodeId, PlanarGraph, PointLocation};
use polis_cells::{CellDecomposition, extract};
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use spade::{DelaunayTriangulation, Point2, Triangulation};

type G = PlanarGraph<(), ()>;

// ----- generators ------------------------------------------------------------------

fn perturbed_grid(seed: u64, nx: usize, ny: usize, keep: f64, jitter: f64) -> G {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut g = G::new();
    let mut id = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let p = DVec2::new(
                i as f64 + rng.random_range(-jitter..=jitter),
                j as f64 + rng.random_range(-jitter..=jitter),
            );
            id.push(g.add_node(p, ()).unwrap());
        }
    }
    for j in 0..ny {
        for i in 0..nx {
            if i + 1 < nx && rng.random_range(0.0..1.0) < keep {
                g.add_edge(id[j * nx + i], id[j * nx + i + 1], ()).unwrap();
            }
            if j + 1 < ny && rng.random_range(0.0..1.0) < keep {
                g.add_edge(id[j * nx + i], id[(j + 1) * nx + i], ())
                    .unwrap();
            }
        }
    }
    g
}

fn triangulation(seed: u64, points: usize, lattice: bool, keep: f64) -> G {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut pts: Vec<Point2<f64>> = Vec::new();
    for _ in 0..points {
        let p = if lattice {
            Point2::new(
                f64::from(rng.random_range(0..8i32)),
                f64::from(rng.random_range(0..8i32)),
            )
        } else {
            Point2::new(rng.random_range(0.0..100.0), rng.random_range(0.0..100.0))
        };
        if !pts.contains(&p) {
            pts.push(p);
        }
    }
    let tri = DelaunayTriangulation::<Point2<f64>>::bulk_load(pts).unwrap();
    let mut g = G::new();
    let mut id = Vec::new();
    for v in tri.vertices() {
        let p = v.position();
        id.push(g.add_node(DVec2::new(p.x, p.y), ()).unwrap());
    }
    for e in tri.undirected_edges() {
        if rng.random_range(0.0..1.0) < keep {
            let [a, b] = e.vertices();
            g.add_edge(id[a.fix().index()], id[b.fix().index()], ())
                .unwrap();
        }
    }
    g
}

/// Concentric rings (radii 100, 80, 60 …) with 0–3 radial connectors between neighbours,
/// chords, dead ends pointing inwards, and a few isolated nodes.
fn rings(seed: u64, count: usize) -> G {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut g = G::new();
    let mut all: Vec<Vec<NodeId>> = Vec::new();
    let sides = 12;
    for k in 0..count {
        let r = 100.0 - 20.0 * k as f64;
        // Sometimes the ring touches the previous one at its node 0 (a cut vertex).
        let pinch = k > 0 && rng.random_range(0.0..1.0) < 0.3;
        let ids: Vec<NodeId> = (0..sides)
            .map(|i| {
                if pinch && i == 0 {
                    return all[k - 1][0];
                }
                let a = std::f64::consts::TAU * i as f64 / sides as f64;
                g.add_node(DVec2::new(r * a.cos(), r * a.sin()), ())
                    .unwrap()
            })
            .collect();
        // Keep the ring closed most of the time; otherwise an open arc.
        let closed = rng.random_range(0.0..1.0) < 0.8;
        for i in 0..sides {
            if i + 1 < sides || closed {
                g.add_edge(ids[i], ids[(i + 1) % sides], ()).unwrap();
            }
        }
        if rng.random_range(0.0..1.0) < 0.3 && k + 1 == count {
            // A chord across the innermost ring.
            g.add_edge(ids[0], ids[sides / 2], ()).unwrap();
        }
        all.push(ids);
    }
    for k in 0..count.saturating_sub(1) {
        let links = rng.random_range(0..4usize);
        for l in 0..links {
            let i = (l * 5 + rng.random_range(0..2usize)) % sides;
            if all[k][i] != all[k + 1][i] && g.find_edge(all[k][i], all[k + 1][i]).is_none() {
                g.add_edge(all[k][i], all[k + 1][i], ()).unwrap();
            }
        }
        // A dead end halfway to the next ring, away from the connectors.
        if rng.random_range(0.0..1.0) < 0.5 {
            let i = 3;
            let p = g.position(all[k][i]).unwrap();
            let q = g.position(all[k + 1][i]).unwrap();
            let m = g.add_node(p.lerp(q, 0.5), ()).unwrap();
            if g.find_edge(all[k][i], all[k + 1][i]).is_none() {
                g.add_edge(all[k][i], m, ()).unwrap();
            }
        }
    }
    if rng.random_range(0.0..1.0) < 0.5 {
        g.add_node(DVec2::new(0.5, 0.25), ()).unwrap();
    }
    g
}

// ----- the independent reference: a half-edge face walk ------------------------------

/// Half-edge `(edge, forward)`; forward runs from the edge's first end to its second.
type Half = (EdgeId, bool);

struct Faces {
    /// Every face walk as a list of (from-node, edge) steps.
    walks: Vec<Vec<(NodeId, EdgeId)>>,
    /// Component index by node raw id.
    comp_of: BTreeMap<NodeId, usize>,
}

fn faces(g: &G) -> Faces {
    let mut comp_of = BTreeMap::new();
    for (k, c) in g.connected_components().iter().enumerate() {
        for &n in c {
            comp_of.insert(n, k);
        }
    }
    let mut seen: BTreeMap<Half, bool> = BTreeMap::new();
    let mut walks = Vec::new();
    for (e, _, _, _) in g.edges() {
        for fwd in [true, false] {
            if seen.contains_key(&(e, fwd)) {
                continue;
            }
            let mut walk = Vec::new();
            let (mut he, mut f) = (e, fwd);
            loop {
                seen.insert((he, f), true);
                let (a, b) = g.endpoints(he).unwrap();
                let (from, to) = if f { (a, b) } else { (b, a) };
                walk.push((from, he));
                // Face on the left: at `to`, take the edge just clockwise of the way back.
                let next = g.next_cw(to, he).unwrap();
                let (na, _) = g.endpoints(next).unwrap();
                he = next;
                f = na == to;
                if he == e && f == fwd {
                    break;
                }
            }
            walks.push(walk);
        }
    }
    Faces { walks, comp_of }
}

fn walk_points(g: &G, w: &[(NodeId, EdgeId)]) -> Vec<DVec2> {
    w.iter().map(|&(n, _)| g.position(n).unwrap()).collect()
}

/// Reduces a bounded face walk to its outer simple cycle: split at a repeated node and
/// keep the closed piece with the larger signed area, until no node repeats.
fn outer_cycle(g: &G, walk: &[(NodeId, EdgeId)]) -> Vec<EdgeId> {
    let mut w = walk.to_vec();
    'again: loop {
        for i in 0..w.len() {
            for j in i + 1..w.len() {
                if w[i].0 == w[j].0 {
                    let inner: Vec<_> = w[i..j].to_vec();
                    let mut outer: Vec<_> = w[..i].to_vec();
                    outer.extend_from_slice(&w[j..]);
                    let ai = ring_signed_area(&walk_points(g, &inner));
                    let ao = ring_signed_area(&walk_points(g, &outer));
                    w = if ai > ao { inner } else { outer };
                    continue 'again;
                }
            }
        }
        break;
    }
    let mut e: Vec<EdgeId> = w.iter().map(|s| s.1).collect();
    e.sort();
    e
}

fn check(g: &G, d: &CellDecomposition) -> Result<(), TestCaseError> {
    let f = faces(g);
    let ncomp = g.connected_components().len();

    // Bounded faces: walks with positive area.
    let mut bounded: Vec<(usize, f64, Vec<DVec2>, Vec<EdgeId>)> = Vec::new();
    for w in &f.walks {
        let pts = walk_points(g, w);
        let a = ring_signed_area(&pts);
        if a > 0.0 {
            // The outside of a tree has zero area, which rounding may make positive:
            // such a walk reduces to an edge walked there and back, not a cycle.
            let cyc = outer_cycle(g, w);
            let mut distinct = cyc.clone();
            distinct.dedup();
            if distinct.len() >= 3 && distinct.len() == cyc.len() {
                bounded.push((f.comp_of[&w[0].0], a, pts, cyc));
            }
        }
    }

    // Euler per component: bounded faces = E − V + 1.
    let mut v_per = vec![0i64; ncomp];
    let mut e_per = vec![0i64; ncomp];
    let mut cyc_per = vec![0i64; ncomp];
    for (n, _, _) in g.nodes() {
        v_per[f.comp_of[&n]] += 1;
    }
    for (_, a, _, _) in g.edges() {
        e_per[f.comp_of[&a]] += 1;
    }
    for c in d.cycles() {
        cyc_per[f.comp_of[&c.nodes[0]]] += 1;
    }
    for k in 0..ncomp {
        prop_assert_eq!(
            cyc_per[k],
            e_per[k] - v_per[k] + 1,
            "Euler, component {}",
            k
        );
    }
    prop_assert_eq!(d.report.components, ncomp);

    // Same cycles as the reference.
    let mut expect: Vec<Vec<EdgeId>> = bounded.iter().map(|b| b.3.clone()).collect();
    let mut got: Vec<Vec<EdgeId>> = d
        .cycles()
        .map(|r| {
            let mut e = r.edges.clone();
            e.sort();
            e
        })
        .collect();
    expect.sort();
    got.sort();
    prop_assert_eq!(&got, &expect);

    // Rings are simple, counter-clockwise, and consistent with the graph.
    for r in d.cycles() {
        prop_assert!(r.polygon.signed_area() > 0.0);
        let mut ns = r.nodes.clone();
        ns.sort();
        ns.dedup();
        prop_assert_eq!(ns.len(), r.len());
        for (i, &e) in r.edges.iter().enumerate() {
            let (a, b) = g.endpoints(e).unwrap();
            let (x, y) = (r.nodes[i], r.nodes[(i + 1) % r.len()]);
            prop_assert!((a, b) == (x, y) || (a, b) == (y, x));
            prop_assert_eq!(r.polygon.points()[i], g.position(x).unwrap());
        }
    }

    // Edge usage: 0, 1 or 2 cycles; exactly the filament edges on none.
    let mut uses = vec![0u32; g.edge_bound()];
    for r in d.cycles() {
        for e in &r.edges {
            uses[e.index()] += 1;
        }
    }
    let mut fil = vec![0u32; g.edge_bound()];
    for fl in d.filaments() {
        prop_assert_eq!(fl.edges.len() + 1, fl.nodes.len());
        for e in &fl.edges {
            fil[e.index()] += 1;
        }
    }
    for (e, _, _, _) in g.edges() {
        prop_assert!(uses[e.index()] <= 2);
        prop_assert_eq!(
            fil[e.index()],
            u32::from(uses[e.index()] == 0),
            "edge {}",
            e
        );
    }

    // Nesting: B inside A (geometrically) exactly when A is an ancestor of B; interiors
    // of cycles never overlap otherwise.
    let cells = &d.cells;
    for b in cells {
        let mut anc = Vec::new();
        let mut p = b.parent;
        while let Some(c) = p {
            anc.push(c);
            p = cells[c.index()].parent;
        }
        for a in cells {
            if a.id == b.id {
                continue;
            }
            let probe = b
                .boundary
                .nodes
                .iter()
                .zip(b.boundary.polygon.points())
                .find(|(n, _)| !a.boundary.nodes.contains(n));
            let inside =
                probe.is_some_and(|(_, &p)| a.boundary.polygon.locate(p) == PointLocation::Inside);
            prop_assert_eq!(
                inside,
                anc.contains(&a.id),
                "cell {} in cell {}",
                b.id,
                a.id
            );
            if !inside {
                // No vertex of b strictly inside a at all.
                for &p in b.boundary.polygon.points() {
                    prop_assert!(a.boundary.polygon.locate(p) != PointLocation::Inside);
                }
            }
        }
        // Holes outline the union of the children.
        let kids: f64 = b
            .children
            .iter()
            .map(|c| cells[c.index()].boundary.area())
            .sum();
        let holes: f64 = b.holes.iter().map(|h| h.area()).sum();
        prop_assert!((kids - holes).abs() <= 1e-9 * (1.0 + kids));
        for h in &b.holes {
            prop_assert!(h.polygon.signed_area() < 0.0);
        }
    }

    // Area: the cells tile the union of the bounded faces. A component lies in the union of
    // another's faces when one of its nodes is inside one of that component's face walks.
    let mut nested = vec![false; ncomp];
    for (n, p, _) in g.nodes() {
        let k = f.comp_of[&n];
        if bounded
            .iter()
            .any(|b| b.0 != k && locate_in_ring(&b.2, p) == PointLocation::Inside)
        {
            nested[k] = true;
        }
    }
    let union: f64 = bounded.iter().filter(|b| !nested[b.0]).map(|b| b.1).sum();
    let total = d.total_area();
    prop_assert!(
        (total - union).abs() <= 1e-9 * (1.0 + union),
        "{} vs {}",
        total,
        union
    );

    // Filaments lie in their cell: the midpoint of an edge is inside the boundary and
    // outside every hole; outer filaments are inside no cycle.
    for fl in d.filaments() {
        let mid = fl.points[0].lerp(fl.points[1], 0.5);
        match fl.cell {
            Some(c) => {
                let cell = &cells[c.index()];
                prop_assert_eq!(cell.boundary.polygon.locate(mid), PointLocation::Inside);
                for h in &cell.holes {
                    prop_assert_eq!(h.polygon.locate(mid), PointLocation::Outside);
                }
            }
            None => {
                for cell in cells {
                    prop_assert!(cell.boundary.polygon.locate(mid) != PointLocation::Inside);
                }
            }
        }
    }

    // Every cell's region validates once touching holes are separated, and loses at most
    // a sliver of area.
    for c in cells {
        let poly = c.polygon_with_holes();
        prop_assert!(poly.is_ok(), "cell {}: {:?}", c.id, poly.err());
        let Ok(poly) = poly else { continue };
        prop_assert!(poly.validate().is_ok());
        prop_assert_eq!(&poly.outer, &c.boundary.polygon);
        let perimeter: f64 = c.holes.iter().map(|h| h.polygon.perimeter()).sum();
        prop_assert!(
            (poly.area() - c.area()).abs()
                <= polis_cells::TOUCH_SEPARATION * perimeter + 1e-9 * (1.0 + c.area())
        );
    }

    // Deterministic; and without the planarity check (containment then comes from a
    // sweep run after the face walks) the output is the same.
    prop_assert_eq!(&extract(g).unwrap(), d);
    let unchecked = polis_cells::CellParams {
        check_planarity: false,
        ..Default::default()
    };
    prop_assert_eq!(&polis_cells::extract_with(g, &unchecked).unwrap(), d);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn perturbed_grids(seed in any::<u64>(), nx in 2usize..9, ny in 2usize..9,
                       keep in prop_oneof![Just(1.0), 0.5f64..1.0], jitter in prop_oneof![Just(0.0), 0.0f64..0.25]) {
        let g = perturbed_grid(seed, nx, ny, keep, jitter);
        g.check_invariants().unwrap();
        let d = extract(&g).unwrap();
        check(&g, &d)?;
    }

    #[test]
    fn triangulations_with_edges_removed(seed in any::<u64>(), points in 3usize..60,
                                         lattice in any::<bool>(), keep in prop_oneof![Just(1.0), 0.3f64..1.0]) {
        let g = triangulation(seed, points, lattice, keep);
        g.check_invariants().unwrap();
        let d = extract(&g).unwrap();
        check(&g, &d)?;
    }

    #[test]
    fn concentric_rings(seed in any::<u64>(), count in 1usize..5) {
        let g = rings(seed, count);
        g.check_invariants().unwrap();
        let d = extract(&g).unwrap();
        check(&g, &d)?;
    }
}

/// Random edges between distinct points of a small lattice (plus some off-lattice points
/// and isolated nodes): often non-planar, with collinear overlaps, T-junctions and nodes
/// on edges.
fn soup(seed: u64, nodes: usize, edges: usize) -> G {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut g = G::new();
    let mut pts: Vec<DVec2> = Vec::new();
    for _ in 0..nodes {
        let p = if rng.random_range(0.0..1.0) < 0.8 {
            DVec2::new(
                f64::from(rng.random_range(0..6i32)) * 1e3,
                f64::from(rng.random_range(0..6i32)) * 1e3,
            )
        } else {
            DVec2::new(rng.random_range(0.0..5e3), rng.random_range(0.0..5e3))
        };
        if !pts.contains(&p) {
            pts.push(p);
        }
    }
    let ids: Vec<NodeId> = pts.iter().map(|&p| g.add_node(p, ()).unwrap()).collect();
    for _ in 0..edges {
        let a = ids[rng.random_range(0..ids.len())];
        let b = ids[rng.random_range(0..ids.len())];
        if a != b && g.find_edge(a, b).is_none() {
            g.add_edge(a, b, ()).unwrap();
        }
    }
    g
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The grid-bucketed planarity check agrees with polis-geom's exhaustive sweep, and
    /// every reported conflict is real.
    #[test]
    fn planarity_check_agrees_with_the_graph(seed in any::<u64>(), nodes in 2usize..14, edges in 0usize..10) {
        let g = soup(seed, nodes, edges);
        let reference = g.check_invariants();
        // Without the check, non-planar input gives unspecified cells but never a panic.
        let unchecked = polis_cells::CellParams { check_planarity: false, ..Default::default() };
        let _ = polis_cells::extract_with(&g, &unchecked);
        match extract(&g) {
            Ok(d) => {
                prop_assert!(reference.is_ok(), "missed: {:?}", reference);
                check(&g, &d)?;
            }
            Err(polis_cells::Error::NotPlanar { conflicts, total }) => {
                prop_assert!(reference.is_err());
                prop_assert!(total >= conflicts.len() && !conflicts.is_empty());
                for c in conflicts {
                    match c {
                        polis_cells::Conflict::Crossing { first, second, .. }
                        | polis_cells::Conflict::Overlap { first, second } => {
                            let (a0, a1) = g.segment(first).unwrap();
                            let (b0, b1) = g.segment(second).unwrap();
                            prop_assert!(polis_cells::geom::predicates::segments_intersect(a0, a1, b0, b1));
                        }
                        polis_cells::Conflict::NodeOnEdge { node, edge, .. } => {
                            let (a, b) = g.segment(edge).unwrap();
                            let p = g.position(node).unwrap();
                            prop_assert!(polis_cells::geom::predicates::point_on_segment(p, a, b));
                        }
                    }
                }
            }
            Err(other) => prop_assert!(false, "{}", other),
        }
    }
}

/// Random segments (on a lattice or not) added raw, so they cross, overlap and touch.
fn segments(seed: u64, count: usize, lattice: bool) -> G {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut g = G::new();
    let pt = |rng: &mut Pcg64Mcg| {
        if lattice {
            DVec2::new(
                f64::from(rng.random_range(0..7i32)) * 10.0,
                f64::from(rng.random_range(0..7i32)) * 10.0,
            )
        } else {
            DVec2::new(rng.random_range(0.0..100.0), rng.random_range(0.0..100.0))
        }
    };
    for _ in 0..count {
        let (p, q) = (pt(&mut rng), pt(&mut rng));
        if p != q {
            let a = g.add_node(p, ()).unwrap();
            let b = g.add_node(q, ()).unwrap();
            g.add_edge(a, b, ()).unwrap();
        }
    }
    g
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random segments planarised by polis-geom's planar insertion.
    #[test]
    fn random_segments_planarised(seed in any::<u64>(), count in 1usize..25, lattice in any::<bool>()) {
        let raw = segments(seed, count, lattice);
        let p = polis_cells::extract_planarized(
            &raw,
            &polis_cells::CellParams::default(),
            &polis_cells::geom::SnapOptions::default(),
            |_| (),
        )
        .unwrap();
        p.graph.check_invariants().unwrap();
        check(&p.graph, &p.cells)?;
        for (e, _, _, _) in raw.edges() {
            prop_assert!(!p.edge_map[e.index()].is_empty());
        }
    }
}
