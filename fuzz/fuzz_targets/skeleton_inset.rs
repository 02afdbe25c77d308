//! Polygons from bytes — random rings, stars, wheels with spokes, integer grids nudged
//! by 1e-9 to 1e-13 (near-degenerate), slivers — with optional weights: the straight
//! skeleton and the insets never panic; they refuse the same inputs (the input checks
//! are shared); whatever the skeleton accepts, every inset accepts; an accepted inset
//! is valid, inside the polygon and no larger than it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use polis_geom::{DVec2, Polygon, PolygonWithHoles};
use polis_lots::{LotsError, StraightSkeleton, inset_weighted};

/// Reads bytes as small numbers, zeros when they run out.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        let (b, rest) = self.0.split_first().map_or((0, &[][..]), |(b, r)| (*b, r));
        self.0 = rest;
        b
    }
    fn unit(&mut self) -> f64 {
        f64::from(u16::from_le_bytes([self.byte(), self.byte()])) / 65535.0
    }
}

fn polygon(b: &mut Bytes<'_>) -> Polygon {
    let family = b.byte() % 5;
    // Up to 26 vertices: the near-degenerate cases need few, and the skeleton's cost
    // grows faster than linearly with the count (wheels still reach 76).
    let n = 3 + usize::from(b.byte() % 24);
    let tiny = 10f64.powi(-9 - i32::from(b.byte() % 5));
    let at = |r: f64, a: f64| DVec2::from_angle(a) * r;
    let pts: Vec<DVec2> = match family {
        // A random ring (often not simple: the checks must refuse it).
        0 => (0..n)
            .map(|_| DVec2::new(b.unit() * 100.0 - 50.0, b.unit() * 100.0 - 50.0))
            .collect(),
        // A star with random radii.
        1 => (0..n)
            .map(|i| {
                at(
                    1.0 + b.unit() * 30.0,
                    std::f64::consts::TAU * i as f64 / n as f64,
                )
            })
            .collect(),
        // A wheel: rim vertices and notches, some running in to a spoke tip.
        2 => {
            let sectors = 3 + n % 17;
            let tip = 1.0 + b.unit() * 8.0;
            let half = (0.2 + b.unit() * 3.0)
                .min(80.0 / sectors as f64)
                .to_radians();
            let step = std::f64::consts::TAU / sectors as f64;
            let rim = 10.0 * (step / 2.0).cos() - 0.01;
            let mut v = Vec::new();
            for k in 0..sectors {
                let a = step * k as f64;
                let c = a + step / 2.0;
                v.push(at(10.0, a));
                v.push(at(rim, c - half));
                if b.byte() % 4 != 0 {
                    v.push(at(tip, c));
                }
                v.push(at(rim, c + half));
            }
            v
        }
        // An integer star nudged by a tiny amount per vertex (near-degenerate).
        3 => (0..n)
            .map(|i| {
                let p = at(
                    2.0 + f64::from(b.byte() % 12),
                    std::f64::consts::TAU * i as f64 / n as f64,
                )
                .round();
                p + DVec2::new(b.unit() - 0.5, b.unit() - 0.5) * tiny
            })
            .collect(),
        // A sliver triangle or quad.
        _ => {
            let h = 10f64.powf(-14.0 + b.unit() * 15.0);
            let mut v = vec![
                DVec2::ZERO,
                DVec2::new(100.0, 0.0),
                DVec2::new(b.unit() * 100.0, h),
            ];
            if n % 2 == 0 {
                v.push(DVec2::new(b.unit() * 50.0, h * b.unit()));
            }
            v
        }
    };
    let mut p = Polygon::new(pts);
    p.make_ccw();
    p
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let poly: PolygonWithHoles = polygon(&mut b).into();
    let n = poly.outer.len();
    let weighted = b.byte() % 2 == 1;
    let weights: Vec<f64> = (0..n)
        .map(|_| match b.byte() % 4 {
            0 => 1.0,
            1 => 2.0,
            2 => 0.5,
            _ => 0.1 + b.unit() * 3.0,
        })
        .collect();
    let w = weighted.then_some(&weights[..]);
    let unit = vec![1.0; n];
    let skeleton = StraightSkeleton::weighted(&poly, w.unwrap_or(&unit));
    let d = b.unit() * 20.0;
    let inset = inset_weighted(&poly, w.unwrap_or(&unit), d);
    let input_error = |e: &LotsError| {
        matches!(
            e,
            LotsError::InvalidPolygon(_)
                | LotsError::WrongOrientation { .. }
                | LotsError::NeedleVertex { .. }
                | LotsError::InvalidEdgeValue { .. }
        )
    };
    match (&skeleton, &inset) {
        (Ok(_), Err(e)) => panic!("the skeleton accepts what the inset refuses: {e}"),
        (Err(a), Err(b)) if input_error(a) || input_error(b) => assert_eq!(a, b),
        (Err(a), Ok(_)) => assert!(!input_error(a), "inset accepted: {a}"),
        _ => {}
    }
    if let Ok(shapes) = inset {
        // The engine merges points within 1e-9 of the polygon's size, and a pinch is
        // separated by twice that: the inset may lie that far out along the perimeter.
        let area: f64 = shapes.iter().map(PolygonWithHoles::area).sum();
        let size = poly.outer.bbox().size().max_element();
        let perimeter: f64 = poly.outer.edges().map(|(a, b)| a.distance(b)).sum();
        let slack = 4e-9 * size * perimeter;
        assert!(
            area <= poly.area() + slack,
            "{area} > {} + {slack}",
            poly.area()
        );
        for s in &shapes {
            assert!(s.validate().is_ok(), "invalid inset {:?}", s.validate());
        }
    }
});
