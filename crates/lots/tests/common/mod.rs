//! Independent checks shared by the integration tests. They use only the public API and
//! polis-geom, never the crate's internals.
#![allow(dead_code, missing_docs)]

use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use polis_lots::StraightSkeleton;

pub fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

pub fn poly(p: &[(f64, f64)]) -> Polygon {
    Polygon::new(p.iter().map(|&(x, y)| v(x, y)).collect())
}

/// Input edges ring by ring as (start, end).
pub fn input_edges(p: &PolygonWithHoles) -> Vec<(DVec2, DVec2)> {
    p.rings()
        .flat_map(|(_, r)| r.edges().collect::<Vec<_>>())
        .collect()
}

/// Perpendicular distance from `x` to the line through `a`, `b` (signed, positive left).
pub fn line_distance(x: DVec2, a: DVec2, b: DVec2) -> f64 {
    let d = (b - a).normalize();
    d.perp_dot(x - a)
}

/// Checks the skeleton against the polygon and returns a description of the first problem.
///
/// * each arc endpoint at time `t` lies at distance `t · w` (left of the edge) from both
///   input edges whose faces the arc separates;
/// * every node lies inside or on the polygon;
/// * the faces tile the polygon: each face starts with its input edge, has non-negative
///   area, and the areas add up to the polygon's area.
pub fn check_skeleton(p: &PolygonWithHoles, sk: &StraightSkeleton, tol: f64) -> Result<(), String> {
    let edges = input_edges(p);
    let w = sk.weights();
    let scale = p.bbox().width().max(p.bbox().height());
    let tol_d = tol * scale.max(1.0);
    for (k, arc) in sk.arcs().iter().enumerate() {
        // An arc along a weighted step (parallel neighbours of different weights) lies on
        // one of its two lines only.
        let step = arc.step;
        for n in [arc.from, arc.to] {
            let node = sk.nodes()[n];
            let off = |e: usize| {
                let (a, b) = edges[e];
                line_distance(node.position, a, b) - node.time * w[e]
            };
            let (el, er) = (off(arc.left_edge), off(arc.right_edge));
            let ok = if step {
                el.abs().min(er.abs()) <= tol_d
            } else {
                el.abs() <= tol_d && er.abs() <= tol_d
            };
            if !ok {
                return Err(format!(
                    "arc {k} node {n} at {:?} time {}: off its lines by {el} (edge {}) and {er} (edge {})",
                    node.position, node.time, arc.left_edge, arc.right_edge
                ));
            }
        }
    }
    for (i, n) in sk.nodes().iter().enumerate() {
        if !p.contains(n.position) {
            // Allow rounding right at the boundary.
            let near = edges.iter().any(|&(a, b)| {
                polis_geom::predicates::distance_to_segment(n.position, a, b) <= tol_d
            });
            if !near {
                return Err(format!(
                    "node {i} at {:?} is outside the polygon",
                    n.position
                ));
            }
        }
    }
    if sk.faces().len() != edges.len() {
        return Err(format!(
            "{} faces for {} edges",
            sk.faces().len(),
            edges.len()
        ));
    }
    let mut total = 0.0;
    for (e, f) in sk.faces().iter().enumerate() {
        let pts = f.points();
        if pts.len() < 3 {
            return Err(format!("face {e} has {} points", pts.len()));
        }
        if pts[0] != edges[e].0 || pts[1] != edges[e].1 {
            return Err(format!("face {e} does not start with its edge"));
        }
        let a = f.signed_area();
        if a < -tol_d * scale {
            return Err(format!("face {e} has negative area {a}"));
        }
        total += a;
    }
    let area = p.area();
    if (total - area).abs() > tol * area.max(1.0) * 10.0 {
        return Err(format!("faces add up to {total}, polygon area is {area}"));
    }
    // And the structure's own check agrees.
    sk.check_invariants(area, 1e-6)
}
