//! Parish & Müller's lot subdivision (2001 §4.1): split across the longest roughly
//! parallel edges until every lot is under an area threshold.

use rand::{Rng, RngExt};

use super::Ctx;
use super::arena::Piece;

const MAX_SPLITS: usize = 100_000;

pub(super) fn run<R: Rng + ?Sized>(ctx: &mut Ctx<'_>, region: Piece, rng: &mut R) {
    let params = ctx.params;
    let cos_tol = params.parallel_tolerance_deg.to_radians().cos();
    ctx.pieces.clear();
    ctx.pieces.push(region);
    let mut splits = 0;
    while let Some(r) = ctx.pieces.pop() {
        if ctx.arena.area(r) <= params.max_area || splits >= MAX_SPLITS {
            ctx.finish(r);
            continue;
        }
        let pts = ctx.arena.points(r);
        let n = pts.len();
        let edge = |i: usize| (pts[i], pts[(i + 1) % n]);
        // The longest edge that has a roughly antiparallel partner; else the longest edge.
        let mut best: Option<(f64, usize)> = None;
        let mut longest: Option<(f64, usize)> = None;
        for i in 0..n {
            let (a, b) = edge(i);
            let len = a.distance(b);
            if longest.is_none_or(|(l, _)| len > l) {
                longest = Some((len, i));
            }
            if best.is_some_and(|(l, _)| len <= l) {
                continue;
            }
            let d = (b - a) / len;
            let has_partner = (0..n).any(|j| {
                let (c, e) = edge(j);
                j != i && -d.dot((e - c).normalize()) >= cos_tol
            });
            if has_partner {
                best = Some((len, i));
            }
        }
        let Some((_, i)) = best.or(longest) else {
            ctx.finish(r);
            continue;
        };
        let (a, b) = edge(i);
        let t = 0.5 + params.deviance * (rng.random::<f64>() - 0.5) * 0.5;
        splits += 1;
        let mut out = std::mem::take(ctx.scratch);
        let line = ctx.arena.split_across(r, a, b, t, &mut out);
        if out.len() < 2 {
            ctx.finish(r);
        } else {
            ctx.record_split(r, line);
            ctx.pieces.extend(out.iter().rev());
        }
        *ctx.scratch = out;
    }
}
