//! Kelly's lot subdivision (Kelly 2008 §4.4.2, Figures 54 and 56).

use std::collections::VecDeque;

use rand::{Rng, RngExt};

use super::{LotParams, Subdivision, finish, longest_edge, split_across};
use crate::polygon_split::Region;

/// The upper bound on splits per region: far beyond any real block, it only stops runaway
/// loops on pathological input.
const MAX_SPLITS: usize = 100_000;

/// The split position along an edge of length `length` for pieces of `size`: the
/// middle-most multiple of `1 / round(length / size)`, moved by the deviance (Figure 56).
/// `None` when the edge holds fewer than two pieces.
pub(crate) fn split_fraction<R: Rng + ?Sized>(
    length: f64,
    size: f64,
    deviance: f64,
    rng: &mut R,
) -> Option<f64> {
    let factor = (length / size).round();
    if factor < 2.0 {
        return None;
    }
    let fraction = 1.0 / factor;
    let mid = (factor / 2.0).round() * fraction;
    let noise = if deviance > 0.0 {
        deviance * (rng.random::<f64>() - 0.5) * fraction
    } else {
        0.0
    };
    Some(mid + noise)
}

pub(super) fn run<R: Rng + ?Sized>(
    region: Region,
    block_id: u64,
    params: &LotParams,
    rng: &mut R,
    out: &mut Subdivision,
) {
    let mut queue = VecDeque::from([region]);
    let mut splits = 0;
    while let Some(r) = queue.pop_front() {
        if !r.has_street() {
            finish(r, block_id, params, out);
            continue;
        }
        // The longest street edge sets the lot width; failing that, the longest other edge
        // sets the depth.
        let street = longest_edge(&r.outer, |i| r.outer.street[i]);
        let mut plan = street.and_then(|(i, len)| {
            split_fraction(len, params.lot_width, params.deviance, rng).map(|t| (i, t))
        });
        if plan.is_none() {
            let other = longest_edge(&r.outer, |i| !r.outer.street[i]);
            plan = other.and_then(|(i, len)| {
                split_fraction(len, params.lot_depth, params.deviance, rng).map(|t| (i, t))
            });
        }
        let Some((edge, t)) = plan else {
            finish(r, block_id, params, out);
            continue;
        };
        if splits >= MAX_SPLITS {
            finish(r, block_id, params, out);
            continue;
        }
        splits += 1;
        let (a, b) = r.outer.edge(edge);
        let pieces = split_across(&r, a, b, t);
        if pieces.len() < 2 {
            finish(r, block_id, params, out);
            continue;
        }
        for p in pieces {
            if p.has_street() {
                queue.push_back(p);
            } else {
                finish(p, block_id, params, out);
            }
        }
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
