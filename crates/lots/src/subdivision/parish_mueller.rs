//! Parish & Müller's lot subdivision (2001 §4.1): split across the longest roughly
//! parallel edges until every lot is under an area threshold.

use rand::{Rng, RngExt};

use super::{LotParams, Subdivision, finish, split_across};
use crate::polygon_split::Region;

const MAX_SPLITS: usize = 100_000;

pub(super) fn run<R: Rng + ?Sized>(
    region: Region,
    block_id: u64,
    params: &LotParams,
    rng: &mut R,
    out: &mut Subdivision,
) {
    let cos_tol = params.parallel_tolerance_deg.to_radians().cos();
    let mut stack = vec![region];
    let mut splits = 0;
    while let Some(r) = stack.pop() {
        if r.area() <= params.max_area || splits >= MAX_SPLITS {
            finish(r, block_id, params, out);
            continue;
        }
        let ring = &r.outer;
        let n = ring.points.len();
        // The longest edge that has a roughly antiparallel partner; else the longest edge.
        let mut order: Vec<(f64, usize)> = (0..n)
            .map(|i| {
                let (a, b) = ring.edge(i);
                (a.distance(b), i)
            })
            .collect();
        order.sort_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        let mut choice = None;
        for &(len, i) in &order {
            let (a, b) = ring.edge(i);
            let d = (b - a) / len;
            let partner = (0..n)
                .filter(|&j| j != i)
                .filter_map(|j| {
                    let (c, e) = ring.edge(j);
                    let l = c.distance(e);
                    let dj = (e - c) / l;
                    (-d.dot(dj) >= cos_tol).then_some((l, j))
                })
                .max_by(|x, y| x.0.total_cmp(&y.0).then(y.1.cmp(&x.1)));
            if partner.is_some() {
                choice = Some(i);
                break;
            }
        }
        let i = choice.unwrap_or(order[0].1);
        let (a, b) = ring.edge(i);
        let t = 0.5 + params.deviance * (rng.random::<f64>() - 0.5) * 0.5;
        splits += 1;
        let pieces = split_across(&r, a, b, t);
        if pieces.len() < 2 {
            finish(r, block_id, params, out);
            continue;
        }
        stack.extend(pieces.into_iter().rev());
    }
}
