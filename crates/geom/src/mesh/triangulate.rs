//! Constrained Delaunay triangulation of a polygon with holes.

use std::collections::VecDeque;

use glam::DVec2;
use spade::handles::{FixedFaceHandle, InnerTag};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

use super::small_cdt;
use crate::{GeomError, PolygonWithHoles};

/// Triangulates a polygon with holes without adding vertices.
///
/// Returns triangles as index triples into the polygon's vertices listed ring by ring: the
/// outer ring's vertices first, then each hole's, in their given order (the order of
/// [`PolygonWithHoles::rings`]). Every triangle runs counter-clockwise in the layout
/// plane, whatever the rings' orientations.
///
/// The polygon is validated first ([`PolygonWithHoles::validate`]); its error is returned
/// unchanged. A polygon without holes of at most 64 vertices (junctions, footprints, lot
/// caps) is triangulated directly: ear clipping with exact orientation tests, then Lawson
/// flips with the exact in-circle test until every interior edge is locally Delaunay, in
/// fixed buffers. Any other polygon goes through spade's constrained Delaunay
/// triangulation with every ring edge as a constraint; the triangles inside are those
/// reached from the outside by crossing an odd number of constraint edges (a
/// breadth-first walk over the triangles, in spade's deterministic face order). Both give
/// a constrained Delaunay triangulation; where several exist (four or more co-circular
/// vertices) the two paths may choose differently, and the triangles' order differs.
///
/// # Guarantees
/// * Exactly `n + 2h − 2` triangles for `n` vertices and `h` holes, none of zero area,
///   together covering the polygon: the sum of their areas is the polygon's area (up to
///   floating-point rounding).
/// * Among all triangulations of the polygon that use only its vertices, the constrained
///   Delaunay one maximises the smallest angle (few slivers).
/// * Deterministic: the same polygon gives the same triangles in the same order.
/// * Allocation: the direct path allocates only the returned vector (validation allocates
///   its own scratch).
///
/// # Errors
/// The polygon's validation error; [`GeomError::Triangulation`] if spade rejects a
/// coordinate (non-zero values below about 1.8e−43) or, which validation should make
/// impossible, finds crossing constraints.
///
/// # Example
/// ```
/// use polis_geom::{DVec2, Polygon, PolygonWithHoles, mesh::triangulate};
/// let square = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 10.0));
/// let hole = Polygon::rect(DVec2::new(4.0, 4.0), DVec2::new(6.0, 6.0));
/// let triangles = triangulate(&PolygonWithHoles::new(square, vec![hole]))?;
/// assert_eq!(triangles.len(), 8 + 2 - 2);
/// # Ok::<(), polis_geom::GeomError>(())
/// ```
///
/// # References
/// L. P. Chew, *Constrained Delaunay triangulations*, Algorithmica 4 (1989);
/// C. L. Lawson, *Software for C¹ surface interpolation* (1977) for the flips;
/// spade's `ConstrainedDelaunayTriangulation` (Stoeoef/spade), which decides every
/// orientation and in-circle test exactly.
pub fn triangulate(polygon: &PolygonWithHoles) -> Result<Vec<[u32; 3]>, GeomError> {
    polygon.validate()?;
    let ring = polygon.outer.points();
    // Coordinates spade rejects (non-zero below about 1.8e-43) go to spade for its error.
    if polygon.holes.is_empty()
        && ring.len() <= small_cdt::MAX_VERTICES
        && ring.iter().all(|p| {
            spade::validate_coordinate(p.x).is_ok() && spade::validate_coordinate(p.y).is_ok()
        })
        && let Some(triangles) = small_cdt::triangulate_ring(ring)
    {
        return Ok(triangles);
    }
    spade_triangles(polygon)
}

/// The spade path of [`triangulate`] for a validated polygon.
pub(super) fn spade_triangles(polygon: &PolygonWithHoles) -> Result<Vec<[u32; 3]>, GeomError> {
    let cdt = build_constrained(polygon)?;
    let total = cdt.num_vertices();
    let depth = constraint_depth(&cdt);
    let mut triangles = Vec::with_capacity(total + 2 * polygon.holes.len());
    for face in cdt.inner_faces() {
        if depth.get(face.index()).is_some_and(|d| d % 2 == 1) {
            // spade lists a face's vertices counter-clockwise; vertex indices are input
            // indices because the bulk loader keeps the order of distinct vertices.
            triangles.push(face.vertices().map(|v| v.fix().index() as u32));
        }
    }
    Ok(triangles)
}

/// Options of [`triangulate_refined`]: how fine the triangles must be.
///
/// These are *how* knobs of a mesh, not of the city's layout: they change the number of
/// vertices of a surface, never its outline.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct RefineOptions {
    /// The largest triangle area, in m². Default: 25 (about 7 m sides), fine enough to
    /// follow a terrain sampled every 10 m.
    pub max_area: f64,
    /// The smallest angle, in degrees, that refinement tries to keep (values above about
    /// 30 may not terminate and hit `max_additional_vertices`). Default: 25.
    pub min_angle_deg: f64,
    /// The most vertices refinement may add, a guard against run-away refinement.
    /// Default: 1,000,000.
    pub max_additional_vertices: usize,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            max_area: 25.0,
            min_angle_deg: 25.0,
            max_additional_vertices: 1_000_000,
        }
    }
}

/// A triangulation with added (Steiner) vertices, from [`triangulate_refined`].
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RefinedTriangulation {
    /// The vertices: the polygon's, ring by ring as in [`triangulate`], then the added ones.
    pub points: Vec<DVec2>,
    /// Counter-clockwise triangles, indices into `points`.
    pub triangles: Vec<[u32; 3]>,
    /// Whether refinement met the options before running out of additional vertices.
    pub complete: bool,
}

/// Triangulates a polygon with holes and refines the triangles until none is larger than
/// `options.max_area` and (as far as possible) none has an angle below
/// `options.min_angle_deg`, adding vertices inside and on the boundary (boundary edges are
/// split, never moved). For surfaces draped on an elevation field
/// ([`Mesh::add_draped_polygon`](super::Mesh::add_draped_polygon)) and any mesh that needs
/// well-shaped triangles.
///
/// # Guarantees
/// The triangles cover exactly the polygon (the sum of their areas is its area), run
/// counter-clockwise and have no zero area; the polygon's vertices come first, in ring
/// order. Deterministic for a given spade version (pinned exactly in the workspace:
/// spade may change its refinement order in patch releases).
///
/// # Errors
/// As [`triangulate`]; [`GeomError::InvalidParameter`] for a `max_area` that is not
/// positive and finite or a `min_angle_deg` outside `[0, 60)`.
///
/// # References
/// J. Ruppert, *A Delaunay refinement algorithm for quality 2-dimensional mesh
/// generation*, J. Algorithms 18 (1995); spade's `refine`.
pub fn triangulate_refined(
    polygon: &PolygonWithHoles,
    options: &RefineOptions,
) -> Result<RefinedTriangulation, GeomError> {
    if !(options.max_area > 0.0 && options.max_area.is_finite()) {
        return Err(GeomError::InvalidParameter {
            name: "max_area",
            reason: format!("{} m² is not a positive finite area", options.max_area),
        });
    }
    if !(0.0..60.0).contains(&options.min_angle_deg) {
        return Err(GeomError::InvalidParameter {
            name: "min_angle_deg",
            reason: format!("{}° is outside [0, 60)", options.min_angle_deg),
        });
    }
    let mut cdt = constrained(polygon)?;
    let params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .with_max_allowed_area(options.max_area)
        .with_angle_limit(AngleLimit::from_deg(options.min_angle_deg))
        .with_max_additional_vertices(options.max_additional_vertices);
    let result = cdt.refine(params);
    if u32::try_from(cdt.num_vertices()).is_err() {
        return Err(GeomError::InvalidParameter {
            name: "max_area",
            reason: "refinement exceeded the u32 index range; use a larger area".to_string(),
        });
    }
    // Split constraint edges stay constraint edges, so the parity walk still finds the
    // inside (the excluded-face set spade returns is not needed).
    let depth = constraint_depth(&cdt);
    let points = cdt
        .vertices()
        .map(|v| {
            let p = v.position();
            DVec2::new(p.x, p.y)
        })
        .collect();
    let triangles = cdt
        .inner_faces()
        .filter(|f| depth.get(f.index()).is_some_and(|d| d % 2 == 1))
        .map(|f| f.vertices().map(|v| v.fix().index() as u32))
        .collect();
    Ok(RefinedTriangulation {
        points,
        triangles,
        complete: result.refinement_complete,
    })
}

/// Validates the polygon and builds the constrained Delaunay triangulation of its rings,
/// vertex `i` of spade being vertex `i` of the rings listed in order.
fn constrained(
    polygon: &PolygonWithHoles,
) -> Result<ConstrainedDelaunayTriangulation<Point2<f64>>, GeomError> {
    polygon.validate()?;
    build_constrained(polygon)
}

/// [`constrained`] for a polygon already validated.
fn build_constrained(
    polygon: &PolygonWithHoles,
) -> Result<ConstrainedDelaunayTriangulation<Point2<f64>>, GeomError> {
    let total: usize = polygon.rings().map(|(_, r)| r.len()).sum();
    if u32::try_from(total).is_err() {
        return Err(GeomError::InvalidParameter {
            name: "polygon",
            reason: format!("{total} vertices exceed the u32 index range; split the polygon"),
        });
    }
    let mut vertices = Vec::with_capacity(total);
    let mut edges = Vec::with_capacity(total);
    for (_, ring) in polygon.rings() {
        let start = vertices.len();
        let n = ring.len();
        for (i, p) in ring.points().iter().enumerate() {
            vertices.push(Point2::new(p.x, p.y));
            edges.push([start + i, start + (i + 1) % n]);
        }
    }
    let mut conflicts = 0usize;
    let cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::try_bulk_load_cdt(vertices, edges, |_| conflicts += 1)
            .map_err(|e| {
                GeomError::Triangulation(format!(
                    "a coordinate was rejected ({e:?}); coordinates must be 0 or at least 1.8e-43 in magnitude"
                ))
            })?;
    if conflicts > 0 {
        return Err(GeomError::Triangulation(format!(
            "{conflicts} ring edges cross others"
        )));
    }
    if cdt.num_vertices() != total {
        return Err(GeomError::Triangulation(format!(
            "{} of {total} vertices coincide",
            total - cdt.num_vertices()
        )));
    }
    Ok(cdt)
}

/// For every face (indexed by face index), the least number of constraint edges crossed
/// on a walk from the outer face, by a 0–1 breadth-first search.
fn constraint_depth(cdt: &ConstrainedDelaunayTriangulation<Point2<f64>>) -> Vec<u32> {
    let mut depth = vec![u32::MAX; cdt.num_all_faces()];
    let mut queue: VecDeque<(FixedFaceHandle<InnerTag>, u32)> = VecDeque::new();
    // Seed with the faces on the convex hull: their depth across the hull edge.
    for face in cdt.inner_faces() {
        for e in face.adjacent_edges() {
            if e.rev().face().is_outer() {
                let d = u32::from(e.is_constraint_edge());
                if d < depth[face.index()] {
                    depth[face.index()] = d;
                    if d == 0 {
                        queue.push_front((face.fix(), d));
                    } else {
                        queue.push_back((face.fix(), d));
                    }
                }
            }
        }
    }
    while let Some((fixed, d)) = queue.pop_front() {
        if d > depth[fixed.index()] {
            continue;
        }
        let face = cdt.face(fixed);
        for e in face.adjacent_edges() {
            let Some(next) = e.rev().face().as_inner() else {
                continue;
            };
            let w = u32::from(e.is_constraint_edge());
            let nd = d + w;
            if nd < depth[next.index()] {
                depth[next.index()] = nd;
                if w == 0 {
                    queue.push_front((next.fix(), nd));
                } else {
                    queue.push_back((next.fix(), nd));
                }
            }
        }
    }
    depth
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::predicates::orient2d_value;
    use crate::{DVec2, PointLocation, Polygon};
    use proptest::prelude::*;

    pub(crate) fn vertices(p: &PolygonWithHoles) -> Vec<DVec2> {
        p.rings().flat_map(|(_, r)| r.points().to_vec()).collect()
    }

    /// Checks the guarantees of [`triangulate`] on a valid polygon.
    pub(crate) fn check_triangulation(p: &PolygonWithHoles) {
        let tris = triangulate(p).unwrap();
        let pts = vertices(p);
        assert_eq!(tris.len(), pts.len() + 2 * p.holes.len() - 2);
        let mut sum = 0.0;
        for t in &tris {
            let [a, b, c] = t.map(|i| pts[i as usize]);
            let twice = orient2d_value(a, b, c);
            assert!(twice > 0.0, "triangle {t:?} is not counter-clockwise");
            sum += 0.5 * twice;
            let centre = (a + b + c) / 3.0;
            assert_ne!(p.locate(centre), PointLocation::Outside);
        }
        let area = p.area();
        assert!(
            (sum - area).abs() <= 1e-9 * area.max(1.0),
            "triangles cover {sum}, polygon has {area}"
        );
    }

    /// A star-shaped polygon around the origin: one vertex per angular sector, radius in
    /// `[5, 5 + spread]`, optionally snapped to a grid of `snap` metres.
    pub(crate) fn star(radii: &[f64], jitter: &[f64], snap: Option<f64>) -> Polygon {
        let n = radii.len();
        Polygon::new(
            radii
                .iter()
                .zip(jitter)
                .enumerate()
                .map(|(i, (&r, &j))| {
                    let a = std::f64::consts::TAU * (i as f64 + 0.8 * j) / n as f64;
                    let p = DVec2::new(r * a.cos(), r * a.sin());
                    match snap {
                        Some(s) => (p / s).round() * s,
                        None => p,
                    }
                })
                .collect(),
        )
    }

    /// A vertically convex orthogonal polygon: column `i` spans `[i, i + 1] ×
    /// [bottom[i], top[i]]` (bottoms < 0 < tops), scaled by `scale` and moved by `offset`.
    pub(crate) fn orthogonal(bottom: &[i32], top: &[i32], scale: f64, offset: DVec2) -> Polygon {
        let mut pts = Vec::new();
        let k = bottom.len();
        for (i, &b) in bottom.iter().enumerate() {
            pts.push(DVec2::new(i as f64, b.into()));
            pts.push(DVec2::new((i + 1) as f64, b.into()));
        }
        for i in (0..k).rev() {
            pts.push(DVec2::new((i + 1) as f64, top[i].into()));
            pts.push(DVec2::new(i as f64, top[i].into()));
        }
        // Drop the repeated corners where neighbouring columns share a height.
        pts.dedup();
        if pts.first() == pts.last() {
            pts.pop();
        }
        Polygon::new(pts.into_iter().map(|p| p * scale + offset).collect())
    }

    fn square_hole(centre: DVec2, half: f64) -> Polygon {
        let mut h = Polygon::rect(centre - DVec2::splat(half), centre + DVec2::splat(half));
        h.reverse();
        h
    }

    #[test]
    fn square_and_hole() {
        let sq = Polygon::rect(DVec2::ZERO, DVec2::new(10.0, 10.0));
        check_triangulation(&sq.clone().into());
        let p = PolygonWithHoles::new(sq, vec![square_hole(DVec2::splat(5.0), 1.0)]);
        check_triangulation(&p);
        // Clockwise outer ring and counter-clockwise hole: still counter-clockwise output.
        let mut q = p.clone();
        q.outer.reverse();
        q.holes[0].reverse();
        check_triangulation(&q);
    }

    #[test]
    fn collinear_vertices_and_two_holes() {
        // A long side with collinear vertices, two holes.
        let outer = Polygon::new(
            [(0., 0.), (2., 0.), (4., 0.), (6., 0.), (6., 3.), (0., 3.)]
                .iter()
                .map(|&(x, y)| DVec2::new(x, y))
                .collect(),
        );
        let p = PolygonWithHoles::new(
            outer,
            vec![
                square_hole(DVec2::new(1.5, 1.5), 0.5),
                square_hole(DVec2::new(4.5, 1.5), 0.5),
            ],
        );
        check_triangulation(&p);
    }

    #[test]
    fn comb_with_10000_vertices() {
        // Teeth 1 m wide, 50 m deep: many long, thin reflex pockets.
        let teeth = 2500;
        let mut pts = Vec::new();
        for i in 0..teeth {
            let x = 2.0 * i as f64;
            pts.push(DVec2::new(x, 0.0));
            pts.push(DVec2::new(x + 1.0, 0.0));
            pts.push(DVec2::new(x + 1.0, 50.0));
            pts.push(DVec2::new(x + 2.0, 50.0));
        }
        pts.push(DVec2::new(2.0 * teeth as f64, -10.0));
        pts.push(DVec2::new(0.0, -10.0));
        let comb = Polygon::new(pts);
        assert_eq!(comb.len(), 10_002);
        check_triangulation(&comb.into());
    }

    #[test]
    fn bad_polygons_give_errors() {
        let v = |x, y| DVec2::new(x, y);
        let bad = [
            vec![v(0., 0.), v(f64::NAN, 0.), v(0., 1.)],
            vec![v(0., 0.), v(1., 1.), v(1., 0.), v(0., 1.)], // bow-tie
            vec![v(0., 0.), v(1., 0.), v(1., 0.), v(0., 1.)], // duplicate
            vec![v(0., 0.), v(1e12, 0.), v(0., 1.)],
            vec![v(0., 0.), v(1., 0.)],
            vec![],
        ];
        for pts in bad {
            assert!(triangulate(&Polygon::new(pts).into()).is_err());
        }
        // Too small for spade's exact arithmetic: an error, not a panic.
        let tiny = Polygon::new(vec![v(0., 0.), v(1e-44, 0.), v(0., 1e-44)]);
        assert!(triangulate(&tiny.into()).is_err());
    }

    #[test]
    fn value_stability() {
        // An L-shape with a collinear vertex: the exact triangles are pinned, so a change
        // of spade or of the inside filter shows up here.
        let l = Polygon::new(
            [
                (0., 0.),
                (2., 0.),
                (4., 0.),
                (4., 1.),
                (1., 1.),
                (1., 3.),
                (0., 3.),
            ]
            .iter()
            .map(|&(x, y)| DVec2::new(x, y))
            .collect(),
        );
        let l: PolygonWithHoles = l.into();
        // spade's path (taken by polygons with holes or of more than 64 vertices).
        assert_eq!(
            spade_triangles(&l).unwrap(),
            vec![[0, 4, 6], [4, 0, 1], [1, 3, 4], [5, 6, 4], [2, 3, 1]]
        );
        // The direct path (ear clipping + Lawson flips) that this polygon takes: the same
        // triangles (no four vertices are co-circular), in its own order.
        assert_eq!(
            triangulate(&l).unwrap(),
            vec![[1, 2, 3], [4, 5, 6], [1, 3, 4], [4, 6, 0], [1, 4, 0]]
        );
        check_triangulation(&l);
    }

    #[test]
    fn refined_triangles_cover_the_polygon() {
        let mut hole = Polygon::rect(DVec2::new(20.0, 20.0), DVec2::new(30.0, 25.0));
        hole.reverse();
        let p = PolygonWithHoles::new(
            Polygon::rect(DVec2::ZERO, DVec2::new(60.0, 40.0)),
            vec![hole],
        );
        let options = RefineOptions {
            max_area: 10.0,
            ..RefineOptions::default()
        };
        let r = triangulate_refined(&p, &options).unwrap();
        assert!(r.complete);
        assert_eq!(&r.points[..8], &vertices(&p)[..]);
        assert!(r.points.len() > 100);
        let mut sum = 0.0;
        for t in &r.triangles {
            let [a, b, c] = t.map(|i| r.points[i as usize]);
            let area = 0.5 * orient2d_value(a, b, c);
            assert!(area > 0.0 && area <= options.max_area * (1.0 + 1e-9));
            assert_ne!(p.locate((a + b + c) / 3.0), PointLocation::Outside);
            sum += area;
        }
        assert!((sum - p.area()).abs() < 1e-9 * p.area());
        // Every added vertex lies in the closed polygon.
        for &q in &r.points[8..] {
            assert_ne!(p.locate(q), PointLocation::Outside);
        }
        // Same input, same output.
        assert_eq!(triangulate_refined(&p, &options).unwrap(), r);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            let o = RefineOptions {
                max_area: bad,
                ..options
            };
            assert!(triangulate_refined(&p, &o).is_err());
        }
        let o = RefineOptions {
            min_angle_deg: 61.0,
            ..options
        };
        assert!(triangulate_refined(&p, &o).is_err());
        // A cap on added vertices ends refinement early but still covers the polygon.
        let o = RefineOptions {
            max_additional_vertices: 5,
            ..options
        };
        let capped = triangulate_refined(&p, &o).unwrap();
        assert!(!capped.complete);
        let sum: f64 = capped
            .triangles
            .iter()
            .map(|t| {
                0.5 * orient2d_value(
                    capped.points[t[0] as usize],
                    capped.points[t[1] as usize],
                    capped.points[t[2] as usize],
                )
            })
            .sum();
        assert!((sum - p.area()).abs() < 1e-9 * p.area());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        #[test]
        fn star_area_is_preserved(
            spec in prop::collection::vec((prop_oneof![Just(5.0), Just(9.0), 5.0f64..9.0], 0.0f64..1.0), 3..60),
            snap in prop_oneof![Just(None), Just(Some(0.5)), Just(Some(0.25))],
            with_hole in any::<bool>(),
        ) {
            let (radii, jitter): (Vec<f64>, Vec<f64>) = spec.into_iter().unzip();
            let outer = star(&radii, &jitter, snap);
            let holes = if with_hole && radii.len() >= 8 {
                vec![square_hole(DVec2::ZERO, 2.0)]
            } else {
                vec![]
            };
            let p = PolygonWithHoles::new(outer, holes);
            match p.validate() {
                Ok(()) => check_triangulation(&p),
                Err(e) => prop_assert_eq!(triangulate(&p), Err(e)),
            }
        }

        #[test]
        fn orthogonal_area_is_preserved(
            cols in prop::collection::vec((-4i32..=-1, 1i32..=4), 1..40),
            scale in prop_oneof![Just(1.0), 0.01f64..100.0],
            offset in (-1e4f64..1e4, -1e4f64..1e4),
            hole_at in any::<prop::sample::Index>(),
            with_hole in any::<bool>(),
        ) {
            let (bottom, top): (Vec<i32>, Vec<i32>) = cols.into_iter().unzip();
            let offset = DVec2::new(offset.0, offset.1);
            let outer = orthogonal(&bottom, &top, scale, offset);
            let holes = if with_hole {
                let j = hole_at.index(bottom.len()) as f64;
                let h = Polygon::rect(DVec2::new(j + 0.25, -0.5), DVec2::new(j + 0.75, 0.5));
                vec![h.map_points(|q| q * scale + offset)]
            } else {
                vec![]
            };
            let p = PolygonWithHoles::new(outer, holes);
            p.validate().unwrap();
            check_triangulation(&p);
        }

        #[test]
        fn garbage_never_panics(pts in prop::collection::vec((prop_oneof![
            Just(f64::NAN), Just(f64::INFINITY), Just(1e12), Just(0.0), Just(1e-300),
            -5.0f64..5.0, (-3i32..3).prop_map(f64::from)
        ], (-3i32..3).prop_map(f64::from)), 0..30)) {
            let p: PolygonWithHoles =
                Polygon::new(pts.iter().map(|&(x, y)| DVec2::new(x, y)).collect()).into();
            if triangulate(&p).is_ok() {
                check_triangulation(&p);
            }
        }
    }
}
