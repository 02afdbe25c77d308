//! Kelly's lot subdivision (Kelly 2008 §4.4.2, Figures 54 and 56).

use rand::{Rng, RngExt};

use super::Ctx;
use super::arena::Piece;

/// The upper bound on splits per region: far beyond any real block, it only stops runaway
/// loops on pathological input.
const MAX_SPLITS: usize = 100_000;

/// A street edge is preferred for the width split when the piece reaches between these
/// multiples of the lot depth behind it (see [`street_edge`]).
const PREFERRED_DEPTH: (f64, f64) = (0.75, 2.5);

/// The street edge whose lots are cut next (ours, refining Kelly's `getLongestRoad`): the
/// longest street edge among those the piece reaches between 0.75 and 2.5 lot depths
/// behind (its lots get a full depth, and a piece no deeper than that needs at most one
/// depth split); when no street edge qualifies, the longest street edge (Kelly).
///
/// Kelly's rule alone cuts the end of a long block wrongly: once the end piece is
/// narrower than the block is deep, the cross street at its end is its longest street
/// edge, and the piece is cut into lots along the cross street whose depth is whatever
/// is left of the piece (one or two lot widths). In a Manhattan block (61 × 230 m, lots
/// 25 × 100 ft) a quarter of the lots came out 6–16 m deep. With the preference the end
/// piece is cut across the side streets like the rest of the block while it is shallower
/// than 0.75 lot depths, and along the cross street into full-depth lots once it is deeper.
fn street_edge(arena: &super::arena::Arena, r: Piece, lot_depth: f64) -> Option<(usize, f64)> {
    let pts = arena.points(r);
    let street = arena.street(r);
    let n = pts.len();
    let (lo, hi) = (PREFERRED_DEPTH.0 * lot_depth, PREFERRED_DEPTH.1 * lot_depth);
    let mut best: Option<(usize, f64)> = None;
    for i in (0..n).filter(|&i| street[i]) {
        let (a, b) = arena.edge(r, i);
        let l2 = a.distance_squared(b);
        if l2 <= 0.0 || best.is_some_and(|(_, bl)| l2 <= bl) {
            continue;
        }
        let dir = (b - a) / l2.sqrt();
        let depth = pts
            .iter()
            .map(|p| dir.perp_dot(*p - a).abs())
            .fold(0.0, f64::max);
        if (lo..=hi).contains(&depth) {
            best = Some((i, l2));
        }
    }
    best.or_else(|| arena.longest_edge(r, |i| street[i]))
}

/// [`split_fraction`] for an edge of squared length `length2`; an edge clearly shorter than
/// one and a half pieces is turned down before any square root (the exact test decides
/// the rest, so the result is the same).
fn split_fraction_sq<R: Rng + ?Sized>(
    length2: f64,
    size: f64,
    deviance: f64,
    rng: &mut R,
) -> Option<f64> {
    if length2 < 2.2 * size * size {
        return None;
    }
    split_fraction(length2.sqrt(), size, deviance, rng)
}

/// The split position along an edge of length `length` for pieces of `size`: the
/// middle-most multiple of `1 / round(length / size)`, moved by the deviance (Figure 56).
/// `None` when the edge holds fewer than two pieces.
pub(crate) fn split_fraction<R: Rng + ?Sized>(
    length: f64,
    size: f64,
    deviance: f64,
    rng: &mut R,
) -> Option<f64> {
    // Both quotients are positive: rounding half up is rounding half away from zero, and
    // an integer conversion does it without a libm call.
    let factor = round_positive(length / size);
    if factor < 2.0 {
        return None;
    }
    let fraction = 1.0 / factor;
    let mid = round_positive(factor / 2.0) * fraction;
    let noise = if deviance > 0.0 {
        deviance * (rng.random::<f64>() - 0.5) * fraction
    } else {
        0.0
    };
    Some(mid + noise)
}

/// `x.round()` for finite `0 <= x < 2^52` (saturating beyond).
fn round_positive(x: f64) -> f64 {
    ((x + 0.5) as i64) as f64
}

pub(super) fn run<R: Rng + ?Sized>(ctx: &mut Ctx<'_>, region: Piece, rng: &mut R) {
    let params = ctx.params;
    // A FIFO queue: the pseudo-code of Figure 54.
    ctx.pieces.clear();
    ctx.pieces.push(region);
    let mut head = 0;
    let mut splits = 0;
    while head < ctx.pieces.len() {
        let r = ctx.pieces[head];
        head += 1;
        // The preferred street edge sets the lot width; failing that, the longest other
        // edge sets the depth.
        let road = street_edge(ctx.arena, r, params.lot_depth);
        if road.is_none() {
            ctx.finish(r);
            continue;
        }
        let mut plan = road.and_then(|(i, len)| {
            split_fraction_sq(len, params.lot_width, params.deviance, rng).map(|t| (i, t))
        });
        if plan.is_none() {
            let street = ctx.arena.street(r);
            let other = ctx.arena.longest_edge(r, |i| !street[i]);
            plan = other.and_then(|(i, len)| {
                split_fraction_sq(len, params.lot_depth, params.deviance, rng).map(|t| (i, t))
            });
        }
        let Some((edge, t)) = plan else {
            ctx.finish(r);
            continue;
        };
        if splits >= MAX_SPLITS {
            ctx.finish(r);
            continue;
        }
        splits += 1;
        let (a, b) = ctx.arena.edge(r, edge);
        let mut out = std::mem::take(ctx.scratch);
        let line = ctx.arena.split_across(r, a, b, t, &mut out);
        if out.len() < 2 {
            ctx.finish(r);
        } else {
            ctx.record_split(r, line);
            for &p in &out {
                if ctx.arena.has_street(p) {
                    ctx.pieces.push(p);
                } else {
                    ctx.finish(p);
                }
            }
        }
        *ctx.scratch = out;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn middle_most_fraction() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
        assert_eq!(split_fraction(60.0, 20.0, 0.0, &mut rng), Some(2.0 / 3.0));
        assert_eq!(split_fraction(40.0, 20.0, 0.0, &mut rng), Some(0.5));
        assert_eq!(split_fraction(20.0, 20.0, 0.0, &mut rng), None);
        assert!((split_fraction(100.0, 20.0, 0.0, &mut rng).unwrap() - 0.6).abs() < 1e-15);
        for _ in 0..100 {
            let t = split_fraction(60.0, 20.0, 1.0, &mut rng).unwrap();
            assert!((0.5..=5.0 / 6.0).contains(&t));
        }
    }
}
