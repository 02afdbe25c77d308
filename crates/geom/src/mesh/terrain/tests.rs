use super::*;
use crate::field::{Fbm, FbmParams, FieldExt, FnField};
use proptest::prelude::*;

fn rect(w: f64, h: f64) -> Aabb2 {
    Aabb2::new(
        DVec2::new(-w / 2.0, -h / 3.0),
        DVec2::new(w / 2.0, 2.0 * h / 3.0),
    )
}

/// The sheet's edges: each interior edge twice in opposite directions, the border once,
/// every triangle facing up.
fn check_sheet(t: &Terrain, bounds: Aabb2) {
    t.mesh.validate().unwrap();
    let r = t.mesh.edge_use();
    assert!(r.non_manifold.is_empty() && r.flipped.is_empty(), "{r:?}");
    assert_eq!(r.components, 1);
    let size = bounds.max - bounds.min;
    let perimeter = 2.0 * (size.x + size.y);
    // The border is the rectangle's perimeter (3-D length ≥ its plan length).
    assert!(
        r.open_length >= perimeter * (1.0 - 1e-6),
        "{} < {perimeter}",
        r.open_length
    );
    for tri in t.mesh.triangles() {
        let [a, b, c] = tri.map(|i| t.mesh.positions[i as usize].as_dvec3());
        assert!((b - a).cross(c - a).y > 0.0, "a triangle faces down");
    }
    // Plan area is the rectangle's.
    let plan: f64 = t
        .mesh
        .triangles()
        .map(|tri| {
            let [a, b, c] = tri.map(|i| t.mesh.positions[i as usize].as_dvec3());
            0.5 * (b - a).cross(c - a).y
        })
        .sum();
    assert!((plan - size.x * size.y).abs() < 1e-3 * size.x * size.y);
}

/// Every leaf's 5 × 5 check points.
fn check_points(t: &Terrain) -> impl Iterator<Item = DVec2> + '_ {
    t.leaves.iter().flat_map(move |leaf| {
        let s = leaf.size as f64;
        (0..25u32).map(move |k| {
            t.grid.point(
                leaf.x as f64 + s * f64::from(k % 5) / 4.0,
                leaf.y as f64 + s * f64::from(k / 5) / 4.0,
            )
        })
    })
}

/// The one-sided bound at every check point of every leaf.
fn check_bound(t: &Terrain, field: &dyn Field, e: f64) {
    assert_eq!(t.report.unresolved_leaves, 0, "{:?}", t.report);
    assert!(t.report.max_error_m <= e);
    for p in check_points(t) {
        let f = field.sample(p);
        let h = t.height_at(p).unwrap();
        assert!(
            h <= f + 1e-9 && h >= f - 2.0 * e - 1e-9,
            "{h} vs {f} at {p}"
        );
    }
}

#[test]
fn a_plane_needs_only_root_cells_and_lies_the_bound_below() {
    let field = FnField(|p: DVec2| 3.0 + 0.1 * p.x - 0.05 * p.y);
    let bounds = rect(300.0, 200.0);
    let options = TerrainOptions::default();
    let t = Terrain::build(&field, bounds, &options, None).unwrap();
    assert_eq!(t.report.leaves, 5 * 4);
    assert_eq!(t.report.triangles, 4 * 20);
    check_sheet(&t, bounds);
    for k in 0..50 {
        let p = bounds.min + DVec2::new(k as f64 * 5.9, k as f64 * 3.7);
        let h = t.height_at(p).unwrap();
        assert!((h - (field.sample(p) - 0.2)).abs() < 1e-9);
    }
    assert_eq!(t.height_at(DVec2::new(1e4, 0.0)), None);
    // Vertices: positions are the field less the bound (f32).
    for p in &t.mesh.positions {
        let (q, h) = crate::to_layout(p.as_dvec3());
        assert!((h - (field.sample(q) - 0.2)).abs() < 1e-3);
    }
}

#[test]
fn a_hill_refines_and_keeps_the_bound() {
    let field = FnField(|p: DVec2| 40.0 * (-(p.length_squared()) / (2.0 * 60.0f64.powi(2))).exp());
    let bounds = rect(400.0, 300.0);
    let options = TerrainOptions {
        max_error_m: 0.1,
        ..TerrainOptions::default()
    };
    let t = Terrain::build(&field, bounds, &options, None).unwrap();
    assert!(t.report.leaves > 50, "{:?}", t.report);
    check_sheet(&t, bounds);
    check_bound(&t, &field, 0.1);
}

#[test]
fn a_cliff_is_reported_not_a_panic() {
    // A 30 m step: no leaf can resolve it, the unresolved leaves are counted.
    let field = FnField(|p: DVec2| if p.x > 10.3 { 30.0 } else { 0.0 });
    let bounds = rect(200.0, 200.0);
    let t = Terrain::build(&field, bounds, &TerrainOptions::default(), None).unwrap();
    assert!(t.report.unresolved_leaves > 0);
    assert!(t.report.max_error_m > 1.0);
    check_sheet(&t, bounds);
    // Still below the field at every check point, even at the cliff.
    for p in check_points(&t) {
        assert!(
            t.height_at(p).unwrap() <= field.sample(p) + 1e-9,
            "above at {p}"
        );
    }
    // A leaf budget stops refinement without breaking the mesh.
    let small = TerrainOptions {
        max_leaves: 40,
        ..TerrainOptions::default()
    };
    let t = Terrain::build(&field, bounds, &small, None).unwrap();
    assert!(t.report.leaves <= 40, "{:?}", t.report);
    check_sheet(&t, bounds);
}

/// Every vertex lies at most `max_error_m` plus the worst miss below the field: a leaf
/// that cannot meet the bound is lowered by its fan's rise above the field, not to the
/// bottom of the step or the valley in it.
fn check_vertices_not_sunk(t: &Terrain, field: &dyn Field, e: f64) {
    let allowance = e + t.report.max_error_m;
    for p in &t.mesh.positions {
        let (q, h) = crate::mesh::to_layout(p.as_dvec3());
        let f = field.sample(q);
        // f32 positions: a millimetre per hundred metres of height and extent.
        let tol = 1e-3 * (1.0 + f.abs() / 100.0 + q.abs().max_element() / 100.0);
        assert!(
            h >= f - allowance - tol,
            "sunk at {q}: {h} < {f} − {allowance}"
        );
        assert!(h <= f + tol, "above at {q}: {h} > {f}");
    }
}

#[test]
fn unresolved_leaves_sink_by_their_rise_only() {
    let bounds = rect(200.0, 200.0);
    let o = TerrainOptions::default();
    // A cliff, and a valley too sharp for the smallest leaves, off the lattice lines.
    let cliff = FnField(|p: DVec2| if p.x > 10.3 { 30.0 } else { 0.0 });
    let valley = FnField(|p: DVec2| 8.0 * (p.x - 10.8).abs() + 0.3 * p.y);
    for field in [&cliff as &dyn Field, &valley] {
        let t = Terrain::build(field, bounds, &o, None).unwrap();
        assert!(t.report.unresolved_leaves > 0, "{:?}", t.report);
        check_sheet(&t, bounds);
        check_vertices_not_sunk(&t, field, o.max_error_m);
        for p in check_points(&t) {
            assert!(t.height_at(p).unwrap() <= field.sample(p) + 1e-9);
        }
    }
}

#[test]
fn bad_input_is_an_error() {
    let bounds = rect(100.0, 100.0);
    let nan = FnField(|p: DVec2| if p.x > 20.0 { f64::NAN } else { 1.0 });
    assert!(Terrain::build(&nan, bounds, &TerrainOptions::default(), None).is_err());
    let flat = FnField(|_| 0.0);
    for bad in [
        TerrainOptions {
            max_error_m: 0.0,
            ..TerrainOptions::default()
        },
        TerrainOptions {
            max_error_m: f64::NAN,
            ..TerrainOptions::default()
        },
        TerrainOptions {
            min_cell_m: 0.0,
            ..TerrainOptions::default()
        },
        TerrainOptions {
            max_cell_m: 1.0,
            ..TerrainOptions::default()
        },
        TerrainOptions {
            max_leaves: 0,
            ..TerrainOptions::default()
        },
    ] {
        assert!(
            Terrain::build(&flat, bounds, &bad, None).is_err(),
            "{bad:?}"
        );
    }
    let empty = Aabb2::new(DVec2::ZERO, DVec2::new(0.0, 5.0));
    assert!(Terrain::build(&flat, empty, &TerrainOptions::default(), None).is_err());
    let huge = Aabb2::new(DVec2::ZERO, DVec2::splat(1e9));
    assert!(Terrain::build(&flat, huge, &TerrainOptions::default(), None).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(12))]

    /// On random fBm ground, the bound holds at every check point, the sheet is sound,
    /// and between check points the miss stays within the curvature allowance.
    #[test]
    fn random_ground_keeps_the_bound(
        seed in 0u64..1000,
        wavelength in 40.0f64..400.0,
        amplitude in 0.5f64..40.0,
        e in 0.05f64..0.5,
        w in 50.0f64..200.0,
        h in 50.0f64..200.0,
    ) {
        let fbm = fbm(seed, wavelength, 3);
        let field = fbm.scaled(amplitude);
        let bounds = rect(w, h);
        let options = TerrainOptions { max_error_m: e, max_cell_m: 32.0, min_cell_m: 1.0, ..TerrainOptions::default() };
        let t = Terrain::build(&field, bounds, &options, None).unwrap();
        check_sheet(&t, bounds);
        if t.report.unresolved_leaves == 0 {
            check_bound(&t, &field, e);
        } else {
            // Steep random ground (up to 40 m over a 10 m top octave) can be beyond a
            // 1 m leaf at a 5 cm bound: such leaves are counted and lowered, so the
            // surface still never rises above the field at a check point.
            for p in check_points(&t) {
                prop_assert!(t.height_at(p).unwrap() <= field.sample(p) + 1e-9);
            }
        }
        // Random points: within the bound plus a generous curvature allowance (below
        // the field without limit where leaves were lowered).
        let slack = e;
        let floor = if t.report.unresolved_leaves == 0 { 2.0 * e + slack } else { f64::INFINITY };
        for k in 0..200u32 {
            let f = |n: u32| f64::from(n.wrapping_mul(2_654_435_761) % 10_007) / 10_007.0;
            let p = bounds.min + (bounds.max - bounds.min) * DVec2::new(f(k), f(k + 5000));
            let v = field.sample(p);
            let s = t.height_at(p).unwrap();
            prop_assert!(s <= v + slack && s >= v - floor, "{s} vs {v}");
        }
    }
}

/// fBm hills of the given seed, wavelength (metres) and octave count.
fn fbm(seed: u64, wavelength_m: f64, octaves: u32) -> Fbm {
    Fbm::new(FbmParams {
        seed,
        wavelength_m,
        octaves,
        ..FbmParams::default()
    })
    .unwrap()
}

#[test]
fn the_mesh_does_not_depend_on_the_thread_count() {
    let fbm = fbm(7, 60.0, 4);
    let field = fbm.scaled(12.0);
    let bounds = rect(300.0, 250.0);
    let options = TerrainOptions {
        max_error_m: 0.05,
        ..TerrainOptions::default()
    };
    let build = |threads: usize| {
        crate::par::install(threads, || {
            Terrain::build(&field, bounds, &options, None).unwrap()
        })
        .unwrap()
    };
    let (one, three) = (build(1), build(3));
    assert!(one.report.leaves > 200, "{:?}", one.report);
    assert_eq!(one.report, three.report);
    assert_eq!(one.mesh.positions, three.mesh.positions);
    assert_eq!(one.mesh.indices, three.mesh.indices);
    assert_eq!(one.mesh.normals, three.mesh.normals);
    // With a slack (a band along a line, as beside a road corridor) too.
    let slack = FnField(|p: DVec2| {
        if (p.x - 0.3 * p.y).abs() < 20.0 {
            0.4
        } else {
            0.0
        }
    });
    let build = |threads: usize| {
        crate::par::install(threads, || {
            Terrain::build_with_slack(&field, &slack, bounds, &options, None).unwrap()
        })
        .unwrap()
    };
    let (one_slack, three_slack) = (build(1), build(3));
    assert!(
        one_slack.report.leaves < one.report.leaves,
        "{:?}",
        one_slack.report
    );
    assert_eq!(one_slack.report, three_slack.report);
    assert_eq!(one_slack.mesh.positions, three_slack.mesh.positions);
    assert_eq!(one_slack.mesh.indices, three_slack.mesh.indices);
}

/// A leaf split for its final fan (hanging vertices of smaller neighbours) has children
/// whose own fans were never checked in the first round: they are checked too, also
/// when no vertex hangs on their border. On this ground (a cut 0.3 m deep along a line
/// across fBm hills, as under a road corridor) an unchecked child missed the bound by
/// 4 cm.
#[test]
fn children_of_a_final_fan_split_keep_the_bound() {
    let fbm = fbm(57, 80.0, 3);
    let angle = 57.0f64 * 0.7;
    let dir = DVec2::new(angle.cos(), angle.sin());
    let field = FnField(move |p: DVec2| {
        let beyond = (p.dot(dir) - 6.2).abs() - 5.0;
        let share = if beyond <= 0.0 {
            1.0
        } else {
            (1.0 - beyond).max(0.0)
        };
        fbm.sample(p) * 5.0 - 0.3 * share
    });
    let bounds = rect(120.0, 100.0);
    let options = TerrainOptions {
        max_error_m: 0.2,
        min_cell_m: 0.5,
        max_cell_m: 32.0,
        ..TerrainOptions::default()
    };
    let t = Terrain::build(&field, bounds, &options, None).unwrap();
    check_sheet(&t, bounds);
    check_bound(&t, &field, 0.2);
}

/// The terrain cut into tiles (as the scene's ground is) has no seam: welded by their
/// exact bits, the tiles' triangles are one sheet whose only open edges are the
/// rectangle's border, with the whole mesh's edges, so every vertex on a tile border
/// is the same to the bit in each tile using it. Every triangle is in exactly one tile,
/// and each tile is what a writer appends whole ([`Mesh::whole_tile`]).
#[test]
fn terrain_tiles_meet_without_seams() {
    let fbm = fbm(11, 90.0, 4);
    let field = fbm.scaled(25.0);
    let bounds = rect(700.0, 560.0);
    let options = TerrainOptions {
        max_error_m: 0.1,
        ..TerrainOptions::default()
    };
    let t = Terrain::build(&field, bounds, &options, None).unwrap();
    let size = 130.0;
    let tiles = t.mesh.cut_into_tiles(size);
    assert!(tiles.len() >= 20, "{} tiles", tiles.len());
    let whole = t.mesh.edge_use();
    let joined = crate::mesh::edge_use(tiles.iter().map(|(_, m, _)| m));
    assert!(joined.non_manifold.is_empty() && joined.flipped.is_empty());
    assert_eq!(joined.components, 1);
    assert_eq!(
        (joined.triangles, joined.vertices, joined.edges),
        (whole.triangles, whole.vertices, whole.edges)
    );
    assert_eq!(joined.open, whole.open, "the tiles' seams are closed");
    let mut seen = 0;
    for (tile, m, b) in &tiles {
        assert_eq!(m.whole_tile(size), Some(*tile));
        assert_eq!(*b, m.bbox());
        m.validate().unwrap();
        seen += m.triangle_count();
    }
    assert_eq!(seen, t.mesh.triangle_count());
    // The whole mesh is not one tile's cut.
    assert_eq!(t.mesh.whole_tile(size), None);
}

/// The band with a slack at every check point of every leaf:
/// `field − slack − 2e ≤ surface ≤ field`.
fn check_band(t: &Terrain, field: &dyn Field, slack: &dyn Field, e: f64) {
    assert_eq!(t.report.unresolved_leaves, 0, "{:?}", t.report);
    assert!(t.report.max_error_m <= e);
    for p in check_points(t) {
        let (f, s) = (field.sample(p), slack.sample(p).max(0.0));
        let h = t.height_at(p).unwrap();
        assert!(
            h <= f + 1e-9 && h >= f - s - 2.0 * e - 1e-9,
            "{h} vs {f} (slack {s}) at {p}"
        );
    }
}

/// The rectangle and options of the slack tests: 160 m × 120 m, `max_error_m` 0.1,
/// leaves 0.25–32 m.
fn kink_case() -> (Aabb2, TerrainOptions) {
    let options = TerrainOptions {
        max_error_m: 0.1,
        min_cell_m: 0.25,
        max_cell_m: 32.0,
        ..TerrainOptions::default()
    };
    (rect(160.0, 120.0), options)
}

/// The terrains of `field` over [`kink_case`]'s rectangle without and with `slack`, each
/// checked (a sheet, the bound, the band), the one with slack on fewer than `tenths`
/// tenths of the other's leaves; the one without.
fn plain_and_slacked(field: &dyn Field, slack: &dyn Field, tenths: usize) -> Terrain {
    let (bounds, options) = kink_case();
    let plain = Terrain::build(field, bounds, &options, None).unwrap();
    let slacked = Terrain::build_with_slack(field, slack, bounds, &options, None).unwrap();
    check_sheet(&slacked, bounds);
    check_bound(&plain, field, 0.1);
    check_band(&slacked, field, slack, 0.1);
    assert!(
        slacked.report.leaves * 10 < plain.report.leaves * tenths,
        "{:?} against {:?}",
        slacked.report,
        plain.report
    );
    plain
}

/// A slack lets a kink that bends down (the outer edge of a cut along a line across
/// fBm hills, as beside a road corridor) go unrefined while the surface stays under
/// the field at every check point; a kink that bends up (the cut's inner edge) still
/// refines. With a slack of 0 everywhere (or below 0, or not a number) the terrain is
/// `build`'s, bit for bit.
#[test]
fn a_slack_spares_the_kinks_that_bend_down() {
    let fbm = fbm(23, 80.0, 3);
    let angle = 0.9f64;
    let dir = DVec2::new(angle.cos(), angle.sin());
    let share = move |p: DVec2, flat: f64| {
        let beyond = (p.dot(dir) - 6.2).abs() - 5.0 - flat;
        if beyond <= 0.0 {
            1.0
        } else {
            (1.0 - beyond).max(0.0)
        }
    };
    let field = FnField(move |p: DVec2| fbm.sample(p) * 5.0 - 0.5 * share(p, 1.0));
    let slack = FnField(move |p: DVec2| 0.5 * share(p, 2.0));
    let plain = plain_and_slacked(&field, &slack, 9);
    let (bounds, options) = kink_case();
    for v in [0.0, -3.0, f64::NAN] {
        let zero = FnField(move |_: DVec2| v);
        let same = Terrain::build_with_slack(&field, &zero, bounds, &options, None).unwrap();
        assert_eq!(same.report, plain.report);
        assert_eq!(same.mesh.positions, plain.mesh.positions);
        assert_eq!(same.mesh.indices, plain.mesh.indices);
    }
}

/// Kinks that bend *up* (the feet of a trench's 1:2 banks along a line across fBm
/// hills, as at a road cut's corridor edges) are spared too where a slack covers them:
/// the fans' vertices sit in the middle of the band the check allows
/// ([`refine::MIDLINE_SHARE`] of the slack under the field), so a fan may rise over the vertices'
/// level by half the slack and still lie under the field. The band holds at every check
/// point.
#[test]
fn a_slack_spares_the_kinks_that_bend_up() {
    let fbm = fbm(31, 80.0, 3);
    let angle = 0.4f64;
    let dir = DVec2::new(angle.cos(), angle.sin());
    let across = move |p: DVec2| (p.dot(dir) - 70.3).abs();
    // A trench 10 m wide with banks rising at 0.5 until they meet the hills 1.5 m up.
    let field =
        FnField(move |p: DVec2| fbm.sample(p) * 5.0 + (0.5 * (across(p) - 5.0).max(0.0)).min(1.5));
    // Over the trench and its banks, tapering to 0 over the next 8 m (a slack that
    // jumps would make the vertices step with it).
    let slack = FnField(move |p: DVec2| 0.5 * (1.0 - (across(p) - 10.0).max(0.0) / 8.0).max(0.0));
    plain_and_slacked(&field, &slack, 7);
}
