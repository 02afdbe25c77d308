//! Bidirectional sampling (Kelly §4.2.2) with the selection strategies of §4.2.3, and
//! the low-level path: spline, draped on the elevation.
//!
//! # Algorithm
//!
//! Two fronts start at the road's ends. In turn, a front takes a step: it lays a fan of
//! `n_sample` samples at distance `d_sample`, evenly over `±θ_dev` around the direction
//! to the other front's head, classifies each step (legal / water / blocked, see
//! [`Terrain::step`]), keeps the legal samples (or, when none is legal, the water ones:
//! a bridge), and moves to the one its [`Strategy`] prefers (ties: the first sample of
//! the fan, counter-clockwise order). Plotting ends when the heads are within `d_snap`;
//! they are joined, and the plot points are the first front's points followed by the
//! second's, reversed. A head whose last step points away from the other head (the
//! fronts met side by side) is dropped before the join, so the road never turns back on
//! itself there.
//!
//! *Termination.* While the heads are `D > d_snap > d·cos θ` apart, a step toward a
//! fixed target at most `θ < 45°` off brings the front closer by at least
//! `d·(2cos²θ − 1) / (2cos θ) > 0` (law of cosines), so the number of steps is bounded
//! by `D₀` over that amount; the bound is computed first and a plot that would exceed
//! [`MAX_PLOT_STEPS`] is refused.
//!
//! *Commutativity.* The front that steps first is the one at the end that is smaller in
//! `(x, y)` order, whichever end the caller names first, and every computation is done in
//! that orientation; `plot(b → a)` is then exactly `plot(a → b)` reversed, bit for bit.
//!
//! *Bridges.* A step that crosses water is allowed only when no legal sample exists; the
//! water steps of a run (and the join) add up to the bridge length, which may not exceed
//! `max_bridge_m`. A fan with neither legal nor water samples blocks the road.
//!
//! # References
//! G. Kelly, *An Interactive System for Procedural City Generation*, 2008, §4.2.2–4.2.3.

use polis_geom::DVec2;
use serde::{Deserialize, Serialize};

use crate::legality::Illegal;
use crate::primary::error::PrimaryError;
use crate::primary::params::{AdaptiveParams, MAX_PLOT_STEPS, Strategy};
use crate::primary::spline::catmull_rom;
use crate::primary::terrain::{Ground, Terrain};

/// The plot points of a road, from its first end to its second.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plot {
    /// Plot points, both ends included.
    pub points: Vec<DVec2>,
    /// For each step between consecutive points: whether it crosses water (a bridge).
    pub bridge: Vec<bool>,
}

/// One fan of samples, recorded by [`plot_traced`] (Kelly's "plot debug info", Fig. 72).
#[derive(Debug, Clone, PartialEq)]
pub struct Fan {
    /// `0` for the front that started at the first end given, `1` for the other.
    pub front: u8,
    /// The head the fan was laid from.
    pub from: DVec2,
    /// The other front's head it aimed at.
    pub toward: DVec2,
    /// The samples, counter-clockwise (with [`Strategy::Straight`] and an even
    /// `n_sample`, the straight-ahead step is added last).
    pub samples: Vec<DVec2>,
    /// What each sample's step crosses.
    pub ground: Vec<Ground>,
    /// Index of the chosen sample.
    pub chosen: usize,
}

/// The low-level path of a primary road: the spline through its plot points sampled every
/// `segment_draw_size_m`, draped on the elevation (Kelly §4.2.2).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RoadPath {
    /// Polyline vertices in metres, from the road's first node to its second.
    pub points: Vec<DVec2>,
    /// Ground elevation at each vertex, metres.
    pub elevation: Vec<f64>,
    /// Indices into `points` of the plot points (the first and last vertex included).
    pub plot: Vec<u32>,
    /// For each segment `points[i]–points[i+1]`: whether it is part of a bridge.
    pub bridge: Vec<bool>,
}

impl RoadPath {
    /// Length in metres (2-D).
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| w[0].distance(w[1])).sum()
    }

    /// The plot points.
    pub fn plot_points(&self) -> impl Iterator<Item = DVec2> + '_ {
        self.plot
            .iter()
            .filter_map(|&i| self.points.get(i as usize).copied())
    }

    /// The largest grade `|Δh| / length` over the path's segments (0 for a single point).
    pub fn max_grade(&self) -> f64 {
        let mut g: f64 = 0.0;
        for i in 1..self.points.len() {
            let len = self.points[i - 1].distance(self.points[i]);
            if len > 0.0 {
                g = g.max((self.elevation[i] - self.elevation[i - 1]).abs() / len);
            }
        }
        g
    }

    /// The same path run backwards.
    pub fn reversed(&self) -> RoadPath {
        let last = self.points.len().saturating_sub(1) as u32;
        RoadPath {
            points: self.points.iter().rev().copied().collect(),
            elevation: self.elevation.iter().rev().copied().collect(),
            plot: self.plot.iter().rev().map(|&i| last - i).collect(),
            bridge: self.bridge.iter().rev().copied().collect(),
        }
    }
}

/// Plots the road `a → b` (see the [module docs](self)).
///
/// # Errors
/// [`PrimaryError::InvalidParameter`] for bad parameters, [`PrimaryError::BadCoordinate`]
/// for non-finite ends, [`PrimaryError::TooManySteps`], [`PrimaryError::Blocked`],
/// [`PrimaryError::BridgeTooLong`].
pub fn plot(
    a: DVec2,
    b: DVec2,
    params: &AdaptiveParams,
    terrain: &Terrain,
) -> Result<Plot, PrimaryError> {
    plot_inner(a, b, params, terrain, None)
}

/// [`plot`], recording every fan into `trace` (cleared first).
///
/// # Errors
/// As [`plot`].
pub fn plot_traced(
    a: DVec2,
    b: DVec2,
    params: &AdaptiveParams,
    terrain: &Terrain,
    trace: &mut Vec<Fan>,
) -> Result<Plot, PrimaryError> {
    trace.clear();
    plot_inner(a, b, params, terrain, Some(trace))
}

/// Plots `a → b` and samples the spline into the draped low-level path.
///
/// # Errors
/// As [`plot`]; [`PrimaryError::OutsideMap`] where the elevation is undefined on the path.
pub fn plot_path(
    a: DVec2,
    b: DVec2,
    params: &AdaptiveParams,
    terrain: &Terrain,
) -> Result<RoadPath, PrimaryError> {
    // Spline in the canonical orientation too, so the path is exactly reversible.
    let flip = flipped(a, b);
    let (p, q) = if flip { (b, a) } else { (a, b) };
    let plot = plot(p, q, params, terrain)?;
    let path = path_from_plot(&plot, params.segment_draw_size_m, terrain)?;
    Ok(if flip { path.reversed() } else { path })
}

/// The low-level path of given plot points (spline, drape, bridge flags per segment).
///
/// # Errors
/// [`PrimaryError::OutsideMap`] where the elevation is undefined on the path.
pub fn path_from_plot(
    plot: &Plot,
    draw_size_m: f64,
    terrain: &Terrain,
) -> Result<RoadPath, PrimaryError> {
    let mut path = RoadPath::default();
    catmull_rom(&plot.points, draw_size_m, &mut path.points, &mut path.plot);
    path.elevation.reserve(path.points.len());
    for &p in &path.points {
        let h = terrain.elevation(p);
        if !h.is_finite() {
            return Err(PrimaryError::OutsideMap { point: p });
        }
        path.elevation.push(h);
    }
    // Bridge flags: each low-level segment inherits its plot step's flag. Duplicate plot
    // points were dropped by the spline, so map kept plot points back to steps.
    let mut step_flags = Vec::with_capacity(path.plot.len().saturating_sub(1));
    let mut k = 0;
    for w in plot.points.windows(2).zip(&plot.bridge) {
        if w.0[0] != w.0[1] {
            step_flags.push(*w.1);
        } else if let Some(last) = step_flags.last_mut() {
            *last |= *w.1;
        }
    }
    for w in path.plot.windows(2) {
        let flag = step_flags.get(k).copied().unwrap_or(false);
        for _ in w[0]..w[1] {
            path.bridge.push(flag);
        }
        k += 1;
    }
    Ok(path)
}

/// Whether `a` comes after `b` in `(x, y)` order: then plotting runs from `b`.
fn flipped(a: DVec2, b: DVec2) -> bool {
    a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)).is_gt()
}

/// One front of the bidirectional search.
struct Front {
    points: Vec<DVec2>,
    bridge: Vec<bool>,
    head_h: f64,
    /// Length of the current run of water steps, metres.
    run: f64,
}

fn plot_inner(
    a: DVec2,
    b: DVec2,
    params: &AdaptiveParams,
    terrain: &Terrain,
    mut trace: Option<&mut Vec<Fan>>,
) -> Result<Plot, PrimaryError> {
    params.validate()?;
    for p in [a, b] {
        if !(p.is_finite() && p.abs().max_element() <= polis_geom::MAX_COORDINATE) {
            return Err(PrimaryError::BadCoordinate {
                what: "road end",
                point: p,
            });
        }
    }
    let flip = flipped(a, b);
    let (p, q) = if flip { (b, a) } else { (a, b) };
    let d = params.sample_size_m;
    let theta = params.deviation_rad();
    let cos_t = theta.cos();
    // Steps needed at most (module docs).
    let gain = d * (2.0 * cos_t * cos_t - 1.0) / (2.0 * cos_t);
    let bound = p.distance(q) / gain + 2.0;
    if bound.is_nan() || bound > MAX_PLOT_STEPS as f64 {
        return Err(PrimaryError::TooManySteps {
            steps: bound,
            max: MAX_PLOT_STEPS,
        });
    }
    // Fan offsets as rotations (cos, sin), counter-clockwise; cost of Straight = |offset|.
    let n = params.samples as usize;
    let mut offsets: Vec<f64> = (0..n)
        .map(|i| {
            if n == 1 {
                0.0
            } else {
                // Symmetric about 0 bit for bit: the middle sample is exactly straight.
                theta * (2.0 * i as f64 - (n - 1) as f64) / (n - 1) as f64
            }
        })
        .collect();
    if params.strategy == Strategy::Straight && n.is_multiple_of(2) {
        offsets.push(0.0);
    }
    let rot: Vec<(f64, f64)> = offsets.iter().map(|o| (o.cos(), o.sin())).collect();
    let start_h = |x: DVec2| {
        let h = terrain.elevation(x);
        if h.is_finite() {
            Ok(h)
        } else {
            Err(PrimaryError::OutsideMap { point: x })
        }
    };
    let mut fronts = [
        Front {
            points: vec![p],
            bridge: Vec::new(),
            head_h: start_h(p)?,
            run: 0.0,
        },
        Front {
            points: vec![q],
            bridge: Vec::new(),
            head_h: start_h(q)?,
            run: 0.0,
        },
    ];
    let head = |f: &Front| f.points.last().copied().unwrap_or(DVec2::ZERO);
    let mut samples = Vec::with_capacity(rot.len());
    let mut grounds = Vec::with_capacity(rot.len());
    let mut heights = Vec::with_capacity(rot.len());
    let mut side = 0usize;
    let mut steps = 0usize;
    loop {
        let (h0, h1) = (head(&fronts[0]), head(&fronts[1]));
        let dist = h0.distance(h1);
        if dist <= params.snap_m {
            break;
        }
        steps += 1;
        if steps as f64 > bound {
            // Unreachable by the termination argument; a guard, not a result.
            return Err(PrimaryError::TooManySteps {
                steps: steps as f64,
                max: MAX_PLOT_STEPS,
            });
        }
        let (from, toward) = if side == 0 { (h0, h1) } else { (h1, h0) };
        let toward_h = fronts[1 - side].head_h;
        let from_h = fronts[side].head_h;
        let u = (toward - from) / dist;
        samples.clear();
        grounds.clear();
        heights.clear();
        for &(c, s) in &rot {
            let dir = DVec2::new(u.x * c - u.y * s, u.x * s + u.y * c);
            let x = from + dir * d;
            let mut g = terrain.step(from, x);
            let h = terrain.elevation(x);
            if !h.is_finite() {
                g = Ground::Blocked(Illegal::Outside);
            }
            samples.push(x);
            grounds.push(g);
            heights.push(h);
        }
        let want = if grounds.contains(&Ground::Legal) {
            Ground::Legal
        } else if grounds.contains(&Ground::Water) {
            Ground::Water
        } else {
            // Name the obstacle straight ahead (the smallest offset).
            let k = (0..offsets.len())
                .min_by(|&i, &j| {
                    offsets[i]
                        .abs()
                        .total_cmp(&offsets[j].abs())
                        .then(i.cmp(&j))
                })
                .unwrap_or(0);
            let what = match grounds.get(k) {
                Some(Ground::Blocked(w)) => *w,
                _ => Illegal::Outside,
            };
            return Err(PrimaryError::Blocked { at: from, what });
        };
        let cost = |i: usize| -> f64 {
            match params.strategy {
                Strategy::Straight => offsets[i].abs(),
                Strategy::MinimumElevation => heights[i],
                Strategy::MinimumElevationDifference => (heights[i] - from_h).abs(),
                Strategy::EvenElevationDifference => {
                    let progress = dist - samples[i].distance(toward);
                    if progress > 0.0 {
                        ((heights[i] - from_h) / progress - (toward_h - from_h) / dist).abs()
                    } else {
                        f64::INFINITY
                    }
                }
            }
        };
        let mut best = usize::MAX;
        let mut best_cost = f64::INFINITY;
        for (i, g) in grounds.iter().enumerate() {
            if *g != want {
                continue;
            }
            let c = cost(i);
            if best == usize::MAX || c < best_cost {
                best = i;
                best_cost = c;
            }
        }
        let x = samples[best];
        let front = &mut fronts[side];
        let bridge = want == Ground::Water;
        if bridge {
            front.run += d;
            if front.run > params.max_bridge_m {
                return Err(PrimaryError::BridgeTooLong {
                    at: x,
                    length: front.run,
                    max: params.max_bridge_m,
                });
            }
            if terrain.point(x).is_none() {
                front.run = 0.0;
            }
        } else {
            front.run = 0.0;
        }
        front.points.push(x);
        front.bridge.push(bridge);
        front.head_h = heights[best];
        if let Some(t) = trace.as_deref_mut() {
            t.push(Fan {
                front: (side as u8) ^ u8::from(flip),
                from,
                toward,
                samples: samples.clone(),
                ground: grounds.clone(),
                chosen: best,
            });
        }
        side = 1 - side;
    }
    // Join the heads. Side by side, the last step of a front can point away from the
    // other head, so the join would turn back on it (a hairpin): drop such heads first.
    let [mut f0, mut f1] = fronts;
    loop {
        let (h0, h1) = (head(&f0), head(&f1));
        let back = |f: &Front, from: DVec2, to: DVec2| {
            f.points.len() > 1 && (from - f.points[f.points.len() - 2]).dot(to - from) < 0.0
        };
        if back(&f0, h0, h1) {
            f0.points.pop();
            f0.bridge.pop();
        } else if back(&f1, h1, h0) {
            f1.points.pop();
            f1.bridge.pop();
        } else {
            break;
        }
    }
    let (h0, h1) = (head(&f0), head(&f1));
    let join_bridge = match terrain.step(h0, h1) {
        Ground::Legal => false,
        Ground::Water => {
            let length = f0.run + h0.distance(h1) + f1.run;
            if length > params.max_bridge_m {
                return Err(PrimaryError::BridgeTooLong {
                    at: h1,
                    length,
                    max: params.max_bridge_m,
                });
            }
            true
        }
        Ground::Blocked(what) => return Err(PrimaryError::Blocked { at: h0, what }),
    };
    let mut points = f0.points;
    let mut bridge = f0.bridge;
    if h0 == h1 {
        // Coincident heads: one point, the join vanishes.
        f1.points.pop();
        let last = f1.bridge.pop().unwrap_or(false);
        if let Some(b) = bridge.last_mut() {
            *b |= last;
        }
    } else {
        bridge.push(join_bridge);
    }
    points.extend(f1.points.iter().rev());
    bridge.extend(f1.bridge.iter().rev());
    if flip {
        points.reverse();
        bridge.reverse();
    }
    Ok(Plot { points, bridge })
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use polis_geom::field::FnField;
    use polis_geom::{Aabb2, field::Constant};

    use super::*;
    use crate::RoadInputs;

    fn hill() -> Terrain {
        let f =
            FnField::new(|p: DVec2| 80.0 * (-(p.length_squared()) / (2.0 * 300.0 * 300.0)).exp());
        Terrain::with_elevation(
            Arc::new(f),
            Aabb2::new(DVec2::splat(-2000.0), DVec2::splat(2000.0)),
        )
        .unwrap()
    }

    fn params(strategy: Strategy) -> AdaptiveParams {
        AdaptiveParams {
            strategy,
            sample_size_m: 50.0,
            snap_m: 50.0,
            deviation_deg: 30.0,
            samples: 7,
            ..AdaptiveParams::default()
        }
    }

    #[test]
    fn straight_on_flat_land_is_a_line() {
        let t = Terrain::flat(Aabb2::new(DVec2::splat(-2000.0), DVec2::splat(2000.0))).unwrap();
        let (a, b) = (DVec2::new(-500.0, 0.0), DVec2::new(500.0, 0.0));
        let p = plot(a, b, &params(Strategy::Straight), &t).unwrap();
        assert_eq!(p.points.first(), Some(&a));
        assert_eq!(p.points.last(), Some(&b));
        assert!(p.points.iter().all(|x| x.y == 0.0));
        assert_eq!(p.bridge.len(), p.points.len() - 1);
        let mut trace = Vec::new();
        let q = plot_traced(b, a, &params(Strategy::Straight), &t, &mut trace).unwrap();
        assert_eq!(q.points.iter().rev().copied().collect::<Vec<_>>(), p.points);
        assert_eq!(trace.len(), p.points.len() - 2);
        assert!(trace.iter().any(|f| f.front == 0) && trace.iter().any(|f| f.front == 1));
    }

    #[test]
    fn strategies_avoid_the_hill() {
        let t = hill();
        let (a, b) = (DVec2::new(-700.0, 40.0), DVec2::new(700.0, -40.0));
        let straight = plot_path(a, b, &params(Strategy::Straight), &t).unwrap();
        let low = plot_path(a, b, &params(Strategy::MinimumElevation), &t).unwrap();
        let top = |p: &RoadPath| p.elevation.iter().copied().fold(f64::MIN, f64::max);
        assert!(
            top(&low) < top(&straight) - 10.0,
            "{} {}",
            top(&low),
            top(&straight)
        );
        assert_eq!(low.points.first(), Some(&a));
        assert_eq!(low.points.last(), Some(&b));
    }

    #[test]
    fn water_is_bridged_up_to_the_limit_and_parks_block() {
        let mut inputs = RoadInputs::flat(Arc::new(Constant(1.0)));
        inputs.water = Arc::new(FnField::new(|p: DVec2| f64::from(p.x.abs() < 100.0)));
        let t = Terrain::new(
            &inputs,
            Aabb2::new(DVec2::splat(-2000.0), DVec2::splat(2000.0)),
        )
        .unwrap();
        let (a, b) = (DVec2::new(-400.0, 0.0), DVec2::new(400.0, 0.0));
        let p = plot(a, b, &params(Strategy::Straight), &t).unwrap();
        assert!(p.bridge.iter().any(|&x| x));
        let short = AdaptiveParams {
            max_bridge_m: 60.0,
            ..params(Strategy::Straight)
        };
        assert!(matches!(
            plot(a, b, &short, &t),
            Err(PrimaryError::BridgeTooLong { .. })
        ));
        let mut inputs = RoadInputs::flat(Arc::new(Constant(1.0)));
        inputs.parks = Arc::new(FnField::new(|p: DVec2| f64::from(p.x.abs() < 100.0)));
        let t = Terrain::new(
            &inputs,
            Aabb2::new(DVec2::splat(-2000.0), DVec2::splat(2000.0)),
        )
        .unwrap();
        assert!(matches!(
            plot(a, b, &params(Strategy::Straight), &t),
            Err(PrimaryError::Blocked {
                what: Illegal::Park,
                ..
            })
        ));
    }
}
