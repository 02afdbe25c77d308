//! Smooth region outlines from a field: marching squares and Douglas–Peucker.
//!
//! [`contour_regions`] traces the region `{p : field(p) ≥ threshold}` inside a box as
//! polygons with holes:
//!
//! 1. **Sampling.** The field is sampled on a regular grid of `cell_m` squares over the
//!    box (at most [`MAX_CONTOUR_CELLS`] per side), row by row on the thread pool with
//!    the feature `parallel` (each value is its own point's sample, so the grid does not
//!    depend on the thread count). Outside the box counts as below the threshold, so a
//!    region that reaches the border is closed along it.
//! 2. **Marching squares.** In each cell the outline crosses every edge whose ends lie on
//!    both sides of the threshold, at the linearly interpolated point (computed once per
//!    edge, so neighbouring cells share it bit for bit). Segments are directed with the
//!    region on their left. The two saddle cases are decided by the cell centre's
//!    sample: above the threshold joins the two inside corners, below separates them.
//! 3. **Rings.** Segments are chained through the edges they cross into closed rings:
//!    outer boundaries run counter-clockwise, holes clockwise.
//! 4. **Simplification.** Each ring is simplified by Douglas–Peucker with tolerance
//!    `simplify_m`; a simplified ring that is no longer simple, or a polygon whose
//!    simplified holes touch its outline, keeps the unsimplified rings.
//!
//! # Guarantees
//! Every returned polygon validates ([`PolygonWithHoles::validate`]): simple rings,
//! counter-clockwise outer, clockwise holes strictly inside. Deterministic (rings in grid
//! order). Every grid sample at or above the threshold lies inside or on a polygon of the
//! unsimplified outline; with simplification, within `simplify_m` of it.
//!
//! # Limitations
//! Features smaller than a cell can be missed; the outline is the piecewise-linear
//! interpolation of the samples, so its error against the true level set is
//! `O(cell²·curvature)` for a smooth field. Non-finite samples count as below the
//! threshold.
//!
//! # References
//! W. E. Lorensen, H. E. Cline, *Marching cubes*, SIGGRAPH 1987 (the 2-D case);
//! D. Douglas, T. Peucker, *Algorithms for the reduction of the number of points required
//! to represent a digitized line*, 1973.

use glam::DVec2;

use super::Field;
use crate::lines::innermost_ring_containing;
use crate::par::prelude::*;
use crate::polygon::ring_signed_area;
use crate::{Aabb2, GeomError, Polygon, PolygonWithHoles};

/// The most grid cells per side [`contour_regions`] samples (larger grids are coarsened).
pub const MAX_CONTOUR_CELLS: usize = 4096;

/// Options of [`contour_regions`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct ContourOptions {
    /// Side of the sampling cells, metres. Default: 10.
    pub cell_m: f64,
    /// The region is where the field is at or above this value. Default: 0.5.
    pub threshold: f64,
    /// Douglas–Peucker tolerance, metres (0 keeps every crossing point). Default: 1.
    pub simplify_m: f64,
}

impl Default for ContourOptions {
    fn default() -> Self {
        ContourOptions {
            cell_m: 10.0,
            threshold: 0.5,
            simplify_m: 1.0,
        }
    }
}

/// Traces `{p : field(p) ≥ threshold}` inside `bounds` as polygons with holes (see the
/// [module docs](self)).
///
/// Errors: an empty or non-finite box, a cell size or tolerance that is not a positive
/// (non-negative for the tolerance) finite number, a non-finite threshold.
pub fn contour_regions(
    field: &dyn Field,
    bounds: Aabb2,
    options: &ContourOptions,
) -> Result<Vec<PolygonWithHoles>, GeomError> {
    let bad = |name: &'static str, reason: &str| GeomError::InvalidParameter {
        name,
        reason: reason.to_string(),
    };
    let size = bounds.max - bounds.min;
    if !(bounds.min.is_finite() && bounds.max.is_finite() && size.x > 0.0 && size.y > 0.0) {
        return Err(bad("bounds", "the box must be finite and non-empty"));
    }
    if !(options.cell_m.is_finite() && options.cell_m > 0.0) {
        return Err(bad("cell_m", "must be a positive number of metres"));
    }
    if !(options.simplify_m.is_finite() && options.simplify_m >= 0.0) {
        return Err(bad(
            "simplify_m",
            "must be zero or a positive number of metres",
        ));
    }
    if !options.threshold.is_finite() {
        return Err(bad("threshold", "must be finite"));
    }
    let cells = |len: f64| ((len / options.cell_m).ceil() as usize).clamp(1, MAX_CONTOUR_CELLS);
    let grid = Grid::sample(
        field,
        bounds,
        cells(size.x),
        cells(size.y),
        options.threshold,
    );
    let rings = grid.rings(field);
    Ok(assemble(rings, options.simplify_m))
}

/// The sampled grid, padded by one vertex on every side (outside the box: below the
/// threshold, placed on the border so the outline runs along it).
struct Grid {
    /// Vertices per row (cells + 1 + 2 padding).
    w: usize,
    /// Vertex rows.
    h: usize,
    values: Vec<f64>,
    xs: Vec<f64>,
    ys: Vec<f64>,
    threshold: f64,
}

impl Grid {
    fn sample(field: &dyn Field, b: Aabb2, nx: usize, ny: usize, threshold: f64) -> Grid {
        let coords = |lo: f64, hi: f64, n: usize| -> Vec<f64> {
            let step = (hi - lo) / n as f64;
            let mut v = Vec::with_capacity(n + 3);
            v.push(lo);
            v.extend((0..=n).map(|i| if i == n { hi } else { lo + i as f64 * step }));
            v.push(hi);
            v
        };
        let xs = coords(b.min.x, b.max.x, nx);
        let ys = coords(b.min.y, b.max.y, ny);
        let (w, h) = (xs.len(), ys.len());
        let below = threshold - 1.0;
        let mut values = vec![below; w * h];
        // The inner rows on the thread pool, one row a job (a few hundred samples of a
        // noise field each): every value is its point's sample, whatever the order.
        let mut rows: Vec<(usize, &mut [f64])> = values
            .chunks_mut(w)
            .enumerate()
            .skip(1)
            .take(h.saturating_sub(2))
            .collect();
        rows.par_iter_mut().for_each(|(j, row)| {
            let y = ys[*j];
            for (i, out) in row.iter_mut().enumerate().take(w - 1).skip(1) {
                let v = field.sample(DVec2::new(xs[i], y));
                *out = if v.is_finite() { v } else { below };
            }
        });
        Grid {
            w,
            h,
            values,
            xs,
            ys,
            threshold,
        }
    }

    fn inside(&self, i: usize, j: usize) -> bool {
        self.values[j * self.w + i] >= self.threshold
    }

    /// The crossing point on the edge from vertex `(i0, j0)` to the next vertex along
    /// `horizontal` (always computed from the lower-index end: shared bit for bit).
    fn crossing(&self, i0: usize, j0: usize, horizontal: bool) -> DVec2 {
        let (i1, j1) = if horizontal {
            (i0 + 1, j0)
        } else {
            (i0, j0 + 1)
        };
        let (a, b) = (
            DVec2::new(self.xs[i0], self.ys[j0]),
            DVec2::new(self.xs[i1], self.ys[j1]),
        );
        let (va, vb) = (self.values[j0 * self.w + i0], self.values[j1 * self.w + i1]);
        let t = ((self.threshold - va) / (vb - va)).clamp(0.0, 1.0);
        let t = if t.is_finite() { t } else { 0.5 };
        a + (b - a) * t
    }

    /// Edge id: horizontal edges first, then vertical.
    fn edge(&self, i: usize, j: usize, horizontal: bool) -> usize {
        if horizontal {
            j * self.w + i
        } else {
            self.w * self.h + j * self.w + i
        }
    }

    fn edge_point(&self, id: usize) -> DVec2 {
        let n = self.w * self.h;
        if id < n {
            self.crossing(id % self.w, id / self.w, true)
        } else {
            let id = id - n;
            self.crossing(id % self.w, id / self.w, false)
        }
    }

    /// The closed rings of the outline, region on the left, as chains of edge ids.
    fn rings(&self, field: &dyn Field) -> Vec<Vec<DVec2>> {
        let mut next = vec![usize::MAX; 2 * self.w * self.h];
        for j in 0..self.h - 1 {
            for i in 0..self.w - 1 {
                // Corners counter-clockwise and the edges between them (a → b).
                let corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let edges = [
                    self.edge(i, j, true),
                    self.edge(i + 1, j, false),
                    self.edge(i, j + 1, true),
                    self.edge(i, j, false),
                ];
                let ins = corners.map(|(a, b)| self.inside(a, b));
                let mut exits = [usize::MAX; 2];
                let mut entries = [usize::MAX; 2];
                let (mut ne, mut nn) = (0, 0);
                // Walking counter-clockwise: crossings in walk order.
                let mut order = [(false, 0usize); 4];
                let mut count = 0;
                for k in 0..4 {
                    let (a, b) = (ins[k], ins[(k + 1) % 4]);
                    if a && !b {
                        exits[ne] = edges[k];
                        ne += 1;
                        order[count] = (true, edges[k]);
                        count += 1;
                    } else if !a && b {
                        entries[nn] = edges[k];
                        nn += 1;
                        order[count] = (false, edges[k]);
                        count += 1;
                    }
                }
                match count {
                    0 => {}
                    2 => next[exits[0]] = entries[0],
                    _ => {
                        // Saddle: the centre decides whether the inside corners join.
                        let c = DVec2::new(
                            0.5 * (self.xs[i] + self.xs[i + 1]),
                            0.5 * (self.ys[j] + self.ys[j + 1]),
                        );
                        let padded = i == 0 || j == 0 || i + 2 == self.w || j + 2 == self.h;
                        let v = if padded {
                            f64::NEG_INFINITY
                        } else {
                            field.sample(c)
                        };
                        let joined = v.is_finite() && v >= self.threshold;
                        for k in 0..4 {
                            let (is_exit, e) = order[k];
                            if !is_exit {
                                continue;
                            }
                            // Joined: the entry after the exit; separate: the one before.
                            let partner = if joined {
                                order[(k + 1) % 4]
                            } else {
                                order[(k + 3) % 4]
                            };
                            next[e] = partner.1;
                        }
                    }
                }
            }
        }
        let mut seen = vec![false; next.len()];
        let mut rings = Vec::new();
        for start in 0..next.len() {
            if next[start] == usize::MAX || seen[start] {
                continue;
            }
            let mut ring: Vec<DVec2> = Vec::new();
            let mut e = start;
            while e != usize::MAX && !seen[e] {
                seen[e] = true;
                let p = self.edge_point(e);
                if ring.last() != Some(&p) {
                    ring.push(p);
                }
                e = next[e];
            }
            while ring.len() > 1 && ring.first() == ring.last() {
                ring.pop();
            }
            drop_straight(&mut ring);
            if ring.len() >= 3 && ring_signed_area(&ring) != 0.0 {
                rings.push(ring);
            }
        }
        rings
    }
}

/// Removes vertices exactly on the straight line through their neighbours (runs along
/// the border, straight contour lines), in one pass with a stack.
fn drop_straight(ring: &mut Vec<DVec2>) {
    let straight = |a: DVec2, b: DVec2, c: DVec2| {
        crate::orient2d(a, b, c) == crate::Orientation::Collinear && (b - a).dot(c - b) >= 0.0
    };
    let mut out: Vec<DVec2> = Vec::with_capacity(ring.len());
    for &p in ring.iter() {
        while out.len() >= 2 && straight(out[out.len() - 2], out[out.len() - 1], p) {
            out.pop();
        }
        out.push(p);
    }
    // Across the seam: the last and first vertices.
    loop {
        let n = out.len();
        if n < 3 {
            break;
        }
        if straight(out[n - 2], out[n - 1], out[0]) {
            out.pop();
        } else if straight(out[n - 1], out[0], out[1]) {
            out.remove(0);
        } else {
            break;
        }
    }
    *ring = out;
}

/// Douglas–Peucker on a closed ring: split at the vertex farthest from the first, keep
/// the points farther than `tol` from the chords.
fn simplify(ring: &[DVec2], tol: f64) -> Vec<DVec2> {
    let n = ring.len();
    if tol <= 0.0 || n <= 4 {
        return ring.to_vec();
    }
    let far = (1..n)
        .max_by(|&a, &b| {
            ring[0]
                .distance_squared(ring[a])
                .total_cmp(&ring[0].distance_squared(ring[b]))
        })
        .unwrap_or(n / 2);
    let mut keep = vec![false; n];
    keep[0] = true;
    keep[far] = true;
    let mut stack = vec![(0usize, far), (far, n)];
    while let Some((a, b)) = stack.pop() {
        if b - a < 2 {
            continue;
        }
        let (p, q) = (ring[a], ring[b % n]);
        let d = q - p;
        let len = d.length();
        let dist = |x: DVec2| {
            if len > 0.0 {
                d.perp_dot(x - p).abs() / len
            } else {
                x.distance(p)
            }
        };
        let (k, dk) = (a + 1..b).fold((a, -1.0), |(bk, bd), k| {
            let dk = dist(ring[k]);
            if dk > bd { (k, dk) } else { (bk, bd) }
        });
        if dk > tol {
            keep[k] = true;
            stack.push((a, k));
            stack.push((k, b));
        }
    }
    ring.iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(p, _)| *p)
        .collect()
}

/// Groups rings into polygons with holes, simplified where that keeps them valid.
fn assemble(rings: Vec<Vec<DVec2>>, tol: f64) -> Vec<PolygonWithHoles> {
    let (outers, holes): (Vec<Vec<DVec2>>, Vec<Vec<DVec2>>) =
        rings.into_iter().partition(|r| ring_signed_area(r) > 0.0);
    let mut polys: Vec<(Vec<DVec2>, Vec<Vec<DVec2>>)> =
        outers.into_iter().map(|r| (r, Vec::new())).collect();
    for h in holes {
        // A hole's vertices lie on cell edges strictly inside its outer ring's cells, so
        // any of them locates it.
        if let Some(i) = innermost_ring_containing(polys.iter().map(|p| p.0.as_slice()), h[0]) {
            polys[i].1.push(h);
        }
    }
    polys
        .into_iter()
        .map(|(outer, holes)| {
            let simple = |r: &[DVec2]| {
                let s = simplify(r, tol);
                let p = Polygon::new(s);
                if p.len() >= 3 && p.validate().is_ok() && p.is_ccw() == (ring_signed_area(r) > 0.0)
                {
                    p
                } else {
                    Polygon::new(r.to_vec())
                }
            };
            let simplified =
                PolygonWithHoles::new(simple(&outer), holes.iter().map(|h| simple(h)).collect());
            if simplified.validate().is_ok() {
                simplified
            } else {
                PolygonWithHoles::new(
                    Polygon::new(outer),
                    holes.into_iter().map(Polygon::new).collect(),
                )
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PointLocation;
    use crate::field::FnField;

    fn square(half: f64) -> Aabb2 {
        Aabb2::new(DVec2::splat(-half), DVec2::splat(half))
    }

    #[test]
    fn a_disc_is_one_smooth_ring_of_the_right_area() {
        let disc = FnField::new(|p: DVec2| 1.0 - p.length() / 300.0 + 0.5);
        // field ≥ 0.5 ⇔ |p| ≤ 300.
        let polys = contour_regions(&disc, square(500.0), &ContourOptions::default()).unwrap();
        assert_eq!(polys.len(), 1);
        let p = &polys[0];
        p.validate().unwrap();
        assert!(p.holes.is_empty() && p.outer.is_ccw());
        let exact = std::f64::consts::PI * 300.0 * 300.0;
        assert!((p.area() - exact).abs() < 0.002 * exact, "{}", p.area());
        // Every vertex lies on the circle within the simplification tolerance.
        for q in p.outer.points() {
            assert!((q.length() - 300.0).abs() < 1.0 + 1e-6, "{q}");
        }
        // Simplified: far fewer vertices than crossings (about 190).
        assert!(p.outer.len() < 120, "{}", p.outer.len());
    }

    #[test]
    fn rings_with_holes_and_regions_on_the_border() {
        // An annulus, and a half-plane that leaves the box.
        let annulus = FnField::new(|p: DVec2| {
            let r = p.length();
            if (100.0..=250.0).contains(&r) {
                1.0
            } else {
                0.0
            }
        });
        let polys = contour_regions(&annulus, square(400.0), &ContourOptions::default()).unwrap();
        assert_eq!(polys.len(), 1);
        assert_eq!(polys[0].holes.len(), 1);
        polys[0].validate().unwrap();
        assert!(!polys[0].holes[0].is_ccw());
        let east = FnField::new(|p: DVec2| if p.x > 120.0 { 1.0 } else { 0.0 });
        let b = square(400.0);
        let polys = contour_regions(&east, b, &ContourOptions::default()).unwrap();
        assert_eq!(polys.len(), 1);
        polys[0].validate().unwrap();
        // A rectangle from the threshold line (between samples at 120 and 130) to the border.
        assert_eq!(polys[0].outer.len(), 4);
        let area = polys[0].area();
        assert!((area - 275.0 * 800.0).abs() <= 5.0 * 800.0 + 1e-6, "{area}");
        // The whole box, and nothing.
        let all = contour_regions(&FnField::new(|_| 1.0), b, &ContourOptions::default()).unwrap();
        assert_eq!(all.len(), 1);
        assert!((all[0].area() - 800.0 * 800.0).abs() < 1e-6);
        let none = contour_regions(&FnField::new(|_| 0.0), b, &ContourOptions::default()).unwrap();
        assert!(none.is_empty());
    }

    #[test]
    fn saddles_follow_the_centre_sample() {
        // A checkerboard of 10 m squares sampled at their corners: every cell is a saddle.
        let board = FnField::new(|p: DVec2| {
            let (i, j) = ((p.x / 10.0).round() as i64, (p.y / 10.0).round() as i64);
            if (i + j).rem_euclid(2) == 0 { 1.0 } else { 0.0 }
        });
        let options = ContourOptions {
            simplify_m: 0.0,
            ..ContourOptions::default()
        };
        let polys = contour_regions(&board, square(50.0), &options).unwrap();
        for p in &polys {
            p.validate().unwrap();
        }
        assert!(!polys.is_empty());
    }

    #[test]
    fn bad_options_are_errors() {
        let f = FnField::new(|_| 1.0);
        let b = square(10.0);
        for o in [
            ContourOptions {
                cell_m: 0.0,
                ..ContourOptions::default()
            },
            ContourOptions {
                cell_m: f64::NAN,
                ..ContourOptions::default()
            },
            ContourOptions {
                simplify_m: -1.0,
                ..ContourOptions::default()
            },
            ContourOptions {
                threshold: f64::INFINITY,
                ..ContourOptions::default()
            },
        ] {
            assert!(contour_regions(&f, b, &o).is_err());
        }
        let empty = Aabb2::new(DVec2::ZERO, DVec2::ZERO);
        assert!(contour_regions(&f, empty, &ContourOptions::default()).is_err());
        let nan = FnField::new(|_| f64::NAN);
        assert!(
            contour_regions(&nan, b, &ContourOptions::default())
                .unwrap()
                .is_empty()
        );
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]

        /// Any noise field: valid polygons, and every grid sample above the threshold is
        /// inside the unsimplified outline, every one below outside.
        #[test]
        fn noise_regions_are_valid_and_hold_their_samples(
            seed in 0u64..1000,
            threshold in -0.4f64..0.4,
            simplify_m in proptest::sample::select(vec![0.0, 0.5, 3.0]),
        ) {
            let noise = crate::field::Fbm::new(crate::field::FbmParams {
                seed,
                wavelength_m: 60.0,
                ..crate::field::FbmParams::default()
            })
            .unwrap();
            let b = square(100.0);
            let options = ContourOptions { cell_m: 5.0, threshold, simplify_m };
            let polys = contour_regions(&noise, b, &options).unwrap();
            for p in &polys {
                proptest::prop_assert!(p.validate().is_ok());
                proptest::prop_assert!(p.outer.is_ccw());
                proptest::prop_assert!(p.holes.iter().all(|h| !h.is_ccw()));
            }
            if simplify_m == 0.0 {
                for j in 0..=40 {
                    for i in 0..=40 {
                        let q = DVec2::new(-100.0 + 5.0 * f64::from(i), -100.0 + 5.0 * f64::from(j));
                        let v = noise.sample(q);
                        let located = polys.iter().map(|p| p.locate(q)).find(|l| *l != PointLocation::Outside);
                        if v > threshold {
                            proptest::prop_assert!(located.is_some(), "{q} above, outside");
                        } else if v < threshold {
                            proptest::prop_assert!(located != Some(PointLocation::Inside), "{q} below, inside");
                        }
                    }
                }
            }
        }
    }
}
