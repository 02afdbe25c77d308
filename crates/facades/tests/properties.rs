//! Property and integration tests of polis-facades (the test list).

use polis_facades::builtin::{brick_house, builtin_styles, classic_stone};
use polis_facades::{
    AxisStyle, CellRole, Col, Eval, Facade, FacadeSample, FacadeSpec, FacadeStyle, FaceRole,
    IntervalGroup, Layer, LayerStack, Part, PreparedStyle, Profile, RasterOptions, Segment,
};
use proptest::prelude::*;

/// Lengths biased to degenerate cases: exactly the minimum, just above, huge.
fn length_above(min: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(min),
        Just(min + 1e-9),
        (0.0..1.0f64).prop_map(move |x| min + x),
        (0.0..200.0f64).prop_map(move |x| min + x),
        (0.0..5000.0f64).prop_map(move |x| min + x),
    ]
}

fn segment() -> impl Strategy<Value = Segment> {
    (
        prop_oneof![Just(0.001), 0.001..0.05f64, 0.05..8.0f64],
        prop_oneof![Just(0.0), Just(1.0), 0.0..3.0f64],
        prop_oneof![Just(None), (0.1..1.0f64).prop_map(Some)],
        prop_oneof![
            Just(Profile::Off),
            Just(Profile::Full),
            (0.0..0.5f64, 0.5..1.0f64).prop_map(|(from, to)| Profile::Pulse { from, to }),
            (0.0..2.0f64).prop_map(|size_m| Profile::Centered { size_m }),
        ],
    )
        .prop_map(|(len, flex, min_frac, profile)| Segment {
            name: "seg".into(),
            length_m: len,
            flex,
            min_m: min_frac.map(|f: f64| (f * len).max(0.001)),
            profile,
            floor: false,
        })
}

fn axis_style() -> impl Strategy<Value = AxisStyle> {
    (
        prop::collection::vec(segment(), 0..3),
        prop::collection::vec(segment(), 0..4),
        prop::collection::vec(segment(), 0..3),
        0u32..3,
        prop::option::of(0u32..40),
    )
        .prop_filter_map(
            "an axis needs a segment",
            |(start, module, end, min_r, max_r)| {
                if start.is_empty() && module.is_empty() && end.is_empty() {
                    return None;
                }
                let min_repeats = if module.is_empty() { 0 } else { min_r };
                let max_repeats = max_r.map(|m| m.max(min_repeats.max(1)));
                Some(AxisStyle {
                    start,
                    module,
                    end,
                    min_repeats,
                    max_repeats,
                })
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Interval groups cover [0, L] without overlap for any L ≥ the style's minimum.
    #[test]
    fn interval_groups_cover_without_overlap(style in axis_style(), extra in 0.0..1.0f64, pick in 0usize..5) {
        let min = style.min_length();
        let len = [min, min + 1e-9, min + extra, min + 100.0 * extra, min * 3.0 + 1.0][pick];
        prop_assume!(len > 0.0);
        let g = match style.fit(len, None) {
            Ok(g) => g,
            // Very long lengths with tiny modules may exceed the interval cap: a clean error.
            Err(polis_facades::FacadeError::TooManyIntervals { .. }) => return Ok(()),
            Err(e) => return Err(TestCaseError::fail(format!("fit failed at L={len} ≥ min={min}: {e}"))),
        };
        g.check_invariants().map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert_eq!(g.length(), len);
        prop_assert_eq!(g.intervals()[0].start, 0.0);
        prop_assert_eq!(g.intervals().last().unwrap().end, len);
        for w in g.intervals().windows(2) {
            prop_assert_eq!(w[0].end, w[1].start);
            prop_assert!(w[0].len() > 0.0);
        }
        // Rigid segments keep their size (up to the ulps of the running sum), flexible
        // ones never go below their minimum.
        let segs: Vec<&Segment> = style.start.iter()
            .chain((0..g.repeat_count()).flat_map(|_| style.module.iter()))
            .chain(style.end.iter())
            .collect();
        prop_assert_eq!(segs.len(), g.len());
        let any_flex = segs.iter().any(|s| s.flex > 0.0);
        for (iv, s) in g.intervals().iter().zip(&segs) {
            prop_assert!(iv.len() >= s.min_len() - 1e-6 * len.max(1.0), "{} < min {}", iv.len(), s.min_len());
            if any_flex && s.flex == 0.0 {
                prop_assert!((iv.len() - s.length_m).abs() <= 1e-9 * len.max(1.0));
            }
        }
        // Every point of [0, L] is located in exactly the interval that contains it.
        for k in 0..=50 {
            let x = (len * k as f64 / 50.0).min(len);
            let hit = g.locate(x).unwrap();
            prop_assert!(hit.start <= x && x <= hit.end);
        }
    }

    /// Lengths below the minimum are a clean error, never a panic.
    #[test]
    fn too_short_is_an_error(style in axis_style(), frac in 0.0..0.999f64) {
        let min = style.min_length();
        prop_assume!(min > 1e-3);
        let r = style.fit(min * frac - 1e-5, None);
        prop_assert!(r.is_err());
    }

    /// Windows are never cut at facade edges and keep their nominal size.
    #[test]
    fn windows_never_cut(w in length_above(0.0), h in length_above(0.0), seed in any::<u64>(), which in 0usize..4) {
        let style = builtin_styles().swap_remove(which);
        let [mw, mh] = style.min_size();
        let (w, h) = ((w + mw).min(400.0), (h + mh).min(400.0));
        let p = PreparedStyle::new(style).unwrap();
        let f = p.facade(&FacadeSpec::new(w, h, seed)).unwrap();
        prop_assert!(!f.report().blank_columns && !f.report().blank_rows);
        let windows = f.cells_with_roles(&[CellRole::Window, CellRole::Door, CellRole::Shopfront, CellRole::Glass]);
        for c in windows.iter().filter(|c| c.level == 0) {
            prop_assert!(c.rect.min.x >= -1e-9 && c.rect.max.x <= w + 1e-9, "{:?} outside width {}", c.rect, w);
            prop_assert!(c.rect.min.y >= -1e-9 && c.rect.max.y <= h + 1e-9, "{:?} outside height {}", c.rect, h);
            // Every opening lies within one grid column: whole, not split by a boundary.
            let iv = f.columns().locate(c.rect.center().x).unwrap();
            if c.layer_name == "windows" {
                prop_assert!(c.rect.min.x >= iv.start - 1e-9 && c.rect.max.x <= iv.end + 1e-9);
            }
        }
        // Brick-house windows: exactly 1.1 m wide whatever the facade width.
        if p.style().name == "brick_house" {
            for c in windows.iter().filter(|c| c.layer_name == "windows") {
                prop_assert!((c.rect.width() - 1.1).abs() < 1e-9);
            }
        }
    }

    /// AND is the intersection and OR the union of the two profiles' active sets.
    #[test]
    fn and_or_semantics(
        a in prop::collection::vec((0.1..3.0f64, any::<bool>()), 1..6),
        b in prop::collection::vec((0.1..3.0f64, any::<bool>()), 1..6),
        pts in prop::collection::vec((0.0..1.0f64, 0.0..1.0f64), 30),
    ) {
        let prof = |on: bool| if on { Profile::Pulse { from: 0.2, to: 0.7 } } else { Profile::Off };
        let u = IntervalGroup::from_lengths(a.iter().map(|&(l, on)| (l, "x", prof(on)))).unwrap();
        let v = IntervalGroup::from_lengths(b.iter().map(|&(l, on)| (l, "y", prof(on)))).unwrap();
        let col = Col::Solid(FacadeSample::default());
        let and = Layer::new(u.clone(), v.clone(), Eval::And, col.clone());
        let or = Layer::new(u.clone(), v.clone(), Eval::Or, col);
        for (x, y) in pts {
            let (s, t) = (x * u.length(), y * v.length());
            let pu = u.value(u.locate(s).unwrap().index, s) >= 0.5;
            let pv = v.value(v.locate(t).unwrap().index, t) >= 0.5;
            prop_assert_eq!(and.is_active(s, t), pu && pv);
            prop_assert_eq!(or.is_active(s, t), pu || pv);
        }
    }

    /// A stack returns the topmost active layer's sample: fall-through.
    #[test]
    fn stack_falls_through(
        layers in prop::collection::vec((0.2..0.8f64, 0.2..0.8f64, 0.0..1.0f32), 1..5),
        pts in prop::collection::vec((0.0..10.0f64, 0.0..10.0f64), 40),
    ) {
        let built: Vec<Layer> = layers.iter().map(|&(fu, fv, c)| {
            let u = IntervalGroup::from_lengths([(5.0, "a", Profile::Pulse { from: 0.0, to: fu }), (5.0, "b", Profile::Off)]).unwrap();
            let v = IntervalGroup::from_lengths([(10.0, "a", Profile::Pulse { from: 0.0, to: fv })]).unwrap();
            Layer::new(u, v, Eval::And, Col::Solid(FacadeSample::rgb(c, 0.0, 0.0)))
        }).collect();
        let bg = FacadeSample::rgb(0.0, 1.0, 0.0);
        let stack = LayerStack::new(built.clone(), vec![], Some(bg)).unwrap();
        for (s, t) in pts {
            let expect = built.iter().rev().find_map(|l| l.sample(s, t)).unwrap_or(bg);
            prop_assert_eq!(stack.sample(s, t), expect);
        }
    }

    /// Malformed specs are errors, never panics.
    #[test]
    fn bad_specs_never_panic(
        w in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(-1.0), Just(0.0), Just(1e-300), Just(1e12), 0.0..100.0f64],
        h in prop_oneof![Just(f64::NAN), Just(-3.0), Just(0.0), Just(1e-9), 0.0..100.0f64],
        floors in prop::option::of(prop_oneof![Just(0u32), Just(u32::MAX), 0u32..50]),
        role in prop_oneof![Just(FaceRole::Street), Just(FaceRole::Side), Just(FaceRole::Blank), Just(FaceRole::GroundFloor), Just(FaceRole::UpperFloors)],
    ) {
        let p = PreparedStyle::new(brick_house()).unwrap();
        let spec = FacadeSpec { width_m: w, height_m: h, floors, role, seed: 1 };
        if let Ok(f) = p.facade(&spec) {
            let _ = f.sample(w * 0.5, h * 0.5);
            let _ = f.cells();
            let _ = f.rasterize(&RasterOptions { pixels_per_metre: 2.0, ..Default::default() });
        }
    }
}

#[test]
fn identical_seeds_give_identical_images() {
    let opts = RasterOptions {
        pixels_per_metre: 24.0,
        ..Default::default()
    };
    for style in builtin_styles() {
        let a = Facade::new(&style, &FacadeSpec::new(17.0, 13.0, 99)).unwrap();
        let b = Facade::new(&style, &FacadeSpec::new(17.0, 13.0, 99)).unwrap();
        let c = Facade::new(&style, &FacadeSpec::new(17.0, 13.0, 100)).unwrap();
        let (ta, tb, tc) = (
            a.rasterize(&opts).unwrap(),
            b.rasterize(&opts).unwrap(),
            c.rasterize(&opts).unwrap(),
        );
        assert_eq!(ta, tb, "{}", style.name);
        assert_eq!(a.cells(), b.cells());
        assert_ne!(
            ta.albedo, tc.albedo,
            "{}: another seed should vary the facade",
            style.name
        );
    }
}

#[test]
fn random_window_images_vary_per_cell() {
    let f = Facade::new(&brick_house(), &FacadeSpec::new(30.0, 20.0, 5)).unwrap();
    let variants: std::collections::BTreeSet<u32> = f
        .cells_with_roles(&[CellRole::Window])
        .iter()
        .filter_map(|c| c.variant)
        .collect();
    // Closed, half open, open and curtained windows all appear on a large facade.
    assert_eq!(variants.len(), 4, "{variants:?}");
}

#[test]
fn styles_round_trip_through_serde() {
    for style in builtin_styles() {
        let json = style.to_json().unwrap();
        let back = FacadeStyle::from_json(&json).unwrap();
        assert_eq!(back, style);
        // And the round-tripped style renders the same facade.
        let spec = FacadeSpec::new(12.0, 10.0, 3);
        let o = RasterOptions {
            pixels_per_metre: 8.0,
            ..Default::default()
        };
        assert_eq!(
            Facade::new(&style, &spec).unwrap().rasterize(&o).unwrap(),
            Facade::new(&back, &spec).unwrap().rasterize(&o).unwrap()
        );
    }
    assert!(FacadeStyle::from_json("{ \"name\": 3 }").is_err());
    let mut bad = brick_house();
    bad.stack
        .influences
        .push(polis_facades::InfluenceStyle::Border {
            source: "nope".into(),
            target: "wall".into(),
            margin_m: 0.1,
            col: Col::Solid(FacadeSample::default()),
        });
    assert!(FacadeStyle::from_json(&bad.to_json().unwrap()).is_err());
}

#[test]
fn door_influences_windows_in_the_brick_house() {
    let p = PreparedStyle::new(brick_house()).unwrap();
    let spec = FacadeSpec {
        floors: Some(3),
        ..FacadeSpec::new(11.0, 9.5, 8)
    };
    let f = p.facade(&spec).unwrap();
    let door = f.cells_with_roles(&[CellRole::Door]);
    assert_eq!(door.len(), 1);
    let d = door[0].rect;
    let windows = f.cells_with_roles(&[CellRole::Window]);
    // No window overlaps the door (scaled to nothing)…
    assert!(
        windows
            .iter()
            .all(|w| w.rect.intersection(&d).area() <= 0.0 || w.rect.intersection(&d).is_empty())
    );
    // …and the one right above it is 0.55 × the height of the others.
    let above: Vec<_> = windows
        .iter()
        .filter(|w| w.rect.min.x < d.max.x && w.rect.max.x > d.min.x && w.rect.min.y > d.max.y)
        .collect();
    let first = above
        .iter()
        .min_by(|a, b| a.rect.min.y.total_cmp(&b.rect.min.y))
        .unwrap();
    assert!(
        (first.rect.height() - 0.55 * 1.45).abs() < 1e-9,
        "{:?}",
        first.rect
    );
    let higher = above
        .iter()
        .max_by(|a, b| a.rect.min.y.total_cmp(&b.rect.min.y))
        .unwrap();
    assert!((higher.rect.height() - 1.45).abs() < 1e-9);
    // The side facade has no door, so no window is scaled.
    let side = p
        .facade(&FacadeSpec {
            role: FaceRole::Side,
            ..spec
        })
        .unwrap();
    assert!(
        side.cells_with_roles(&[CellRole::Window])
            .iter()
            .all(|w| (w.rect.height() - 1.45).abs() < 1e-9)
    );
}

#[test]
fn border_influence_paints_soldier_courses_around_windows() {
    let f = Facade::new(&brick_house(), &FacadeSpec::new(10.0, 9.0, 1)).unwrap();
    let w = f.cells_with_roles(&[CellRole::Window])[0].rect;
    // Just above the window's head: soldier-course bricks (darker than the wall bricks).
    let above = f.sample(w.center().x + 0.02, w.max.y + 0.05);
    let far = f.sample(w.min.x - 0.3, w.max.y + 0.5);
    assert!(
        above.albedo[0] < far.albedo[0] || above.height < 0.0,
        "{above:?} vs {far:?}"
    );
}

#[test]
fn classic_stone_has_a_distinct_ground_floor_and_nested_windows() {
    let p = PreparedStyle::new(classic_stone()).unwrap();
    let f = p.facade(&FacadeSpec::new(20.0, 16.0, 4)).unwrap();
    let ground: Vec<_> = f
        .rows()
        .intervals()
        .iter()
        .filter(|iv| iv.part == Part::Start)
        .collect();
    assert_eq!(ground.len(), 2);
    let cells = f.cells();
    assert!(cells.iter().any(|c| c.role == CellRole::Shopfront));
    assert!(
        cells
            .iter()
            .any(|c| c.role == CellRole::Glass && c.level == 1)
    );
    assert!(cells.iter().any(|c| c.role == CellRole::Cornice));
    // The string course is an OR layer: a band across the whole facade at each floor.
    let courses: Vec<_> = cells
        .iter()
        .filter(|c| c.layer_name == "string_course")
        .collect();
    assert!(!courses.is_empty());
}
