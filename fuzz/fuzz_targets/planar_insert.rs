//! Segments from bytes — on a small integer grid, along collinear chains of short edges,
//! nudged by tiny amounts, with any snap distance — inserted into one planar graph: no
//! panic, the graph stays planar (`check_invariants`), and every node of an insertion's
//! route lies within the snap distance of the segment as given.
//!
//! Kept fast (libFuzzer wants millions of executions): each insertion is checked by its
//! own local test (an insertion that breaks planarity returns `GraphCorrupt`, which fails
//! here), and the whole graph by `check_invariants` once, after the last insertion,
//! instead of after every one (that whole-graph check was most of an execution).
#![no_main]

use libfuzzer_sys::fuzz_target;
use polis_geom::graph::SnapOptions;
use polis_geom::predicates::distance_to_segment;
use polis_geom::{DVec2, GeomError, PlanarGraph};

fuzz_target!(|data: &[u8]| {
    let Some((&head, rest)) = data.split_first() else {
        return;
    };
    let snap = [0.0, 1e-6, 0.01, 0.05, 0.3][usize::from(head % 5)];
    let options = SnapOptions {
        snap_distance: snap,
    };
    let mut g: PlanarGraph<(), u32> = PlanarGraph::new();
    // A collinear chain of unit edges along a direction chosen by the first byte.
    let dir = DVec2::from_angle(f64::from(head / 5) * 0.123);
    let links = usize::from(head % 23);
    for i in 0..links {
        let _ = g.insert_segment(dir * i as f64, dir * (i + 1) as f64, 0, &options);
    }
    for (k, c) in rest.chunks_exact(5).enumerate().take(40) {
        let grid = |v: u8| f64::from(v % 16) - 4.0;
        let nudge = f64::from(c[4]) * 1e-9;
        let (p, q) = if c[4] % 3 == 0 {
            // Along the chain, slightly off it.
            (
                dir * grid(c[0]) + dir.perp() * (f64::from(c[1]) * 1e-3 - 0.128),
                dir * grid(c[2]) + dir.perp() * (f64::from(c[3]) * 1e-3 - 0.128),
            )
        } else {
            (
                DVec2::new(grid(c[0]), grid(c[1]) + nudge),
                DVec2::new(grid(c[2]) + nudge, grid(c[3])),
            )
        };
        let inserted = g.insert_segment(p, q, k as u32 + 1, &options);
        if let Err(GeomError::GraphCorrupt(e)) = &inserted {
            panic!("inserting {p}–{q} broke planarity: {e}");
        }
        if let Ok(ins) = inserted {
            let tol = snap + 1e-9 * (1.0 + p.abs().max(q.abs()).max_element());
            for &n in &ins.nodes {
                let pn = g.position(n).expect("route node exists");
                let d = distance_to_segment(pn, p, q);
                assert!(
                    d <= tol,
                    "route node {pn} is {d} from {p}–{q} (snap {snap})"
                );
            }
        }
    }
    if let Err(e) = g.check_invariants() {
        panic!("not planar after the last insertion: {e}");
    }
});
