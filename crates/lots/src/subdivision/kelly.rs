//! Kelly's lot subdivision (Kelly 2008 §4.4.2, Figures 54 and 56).

use rand::{Rng, RngExt};

use super::Ctx;
use super::arena::Piece;

/// The upper bound on splits per region: far beyond any real block, it only stops runaway
/// loops on pathological input.
const MAX_SPLITS: usize = 100_000;

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
        // The longest street edge sets the lot width; failing that, the longest other edge
        // sets the depth.
        let street = ctx.arena.street(r);
        let road = ctx.arena.longest_edge(r, |i| street[i]);
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
