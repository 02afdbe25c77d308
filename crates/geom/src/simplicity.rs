//! Finding forbidden contacts between the edges of rings: a Shamos–Hoey sweep decided by
//! exact predicates, O(n log n).
//!
//! The sweep line moves in lexicographic (x, then y) order, so vertical edges need no
//! special case. The status holds the edges crossing the sweep line, ordered bottom to
//! top by [`order`], which compares two edges using only exact orientation tests. The
//! order is consistent as long as no two active edges cross, and the sweep stops at the
//! first contact it finds, so it never relies on an inconsistent order. Every edge is
//! tested against its neighbours when it enters and its neighbours against each other when
//! it leaves (Shamos & Hoey 1976): if any two edges meet, some such pair meets.
//!
//! Contacts that are allowed (two consecutive edges of one ring sharing their vertex) are
//! the caller's business: `check` decides for each candidate pair. The caller must reject
//! repeated vertices (within and across rings) beforehand, so that a point is an endpoint
//! of at most two edges, and those two are consecutive.

use std::cmp::Ordering;
use std::collections::BTreeSet;
use std::ops::Bound;

use glam::DVec2;

use crate::predicates::orient2d_value;

/// An edge as the sweep sees it: `left` precedes `right` lexicographically.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SweepEdge {
    pub(crate) left: DVec2,
    pub(crate) right: DVec2,
    pub(crate) id: u32,
}

impl SweepEdge {
    /// The edge `a–b` with its ends put in sweep order.
    pub(crate) fn new(a: DVec2, b: DVec2, id: u32) -> Self {
        if lex(a, b) == Ordering::Greater {
            SweepEdge {
                left: b,
                right: a,
                id,
            }
        } else {
            SweepEdge {
                left: a,
                right: b,
                id,
            }
        }
    }
}

/// Lexicographic order of points (finite coordinates; `-0.0 == 0.0`).
pub(crate) fn lex(a: DVec2, b: DVec2) -> Ordering {
    let c = |u: f64, v: f64| u.partial_cmp(&v).unwrap_or(Ordering::Equal);
    c(a.x, b.x).then_with(|| c(a.y, b.y))
}

fn sign(v: f64) -> Ordering {
    v.partial_cmp(&0.0).unwrap_or(Ordering::Equal)
}

/// Bottom-to-top order of two edges that both cross the sweep line. `Equal` only for
/// collinear edges (which overlap when both are active).
fn order(s: &SweepEdge, t: &SweepEdge) -> Ordering {
    if lex(s.left, t.left) == Ordering::Less {
        return order(t, s).reverse();
    }
    // `s` starts at or after `t`'s start: locate its start against `t`'s line.
    match sign(orient2d_value(t.left, t.right, s.left)) {
        Ordering::Equal => sign(orient2d_value(t.left, t.right, s.right)),
        o => o,
    }
}

#[derive(Debug, Clone, Copy)]
struct Key(SweepEdge);

impl PartialEq for Key {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Key {}
impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Key {
    fn cmp(&self, other: &Self) -> Ordering {
        if self.0.id == other.0.id {
            Ordering::Equal
        } else {
            order(&self.0, &other.0)
        }
    }
}

/// Sweeps `edges` and returns the first non-`None` answer of `check(a, b)` (edge ids) for
/// a pair of edges that may meet. Returns `None` when no pair passed to `check` was
/// rejected, which (given the preconditions in the module docs) means no two edges meet
/// except where `check` allowed it.
pub(crate) fn find_contact<T>(
    edges: &[SweepEdge],
    mut check: impl FnMut(u32, u32) -> Option<T>,
) -> Option<T> {
    // (point, inserts after removals, edge position)
    let mut events: Vec<(DVec2, bool, usize)> = Vec::with_capacity(edges.len() * 2);
    for (i, e) in edges.iter().enumerate() {
        events.push((e.left, true, i));
        events.push((e.right, false, i));
    }
    events.sort_by(|a, b| {
        lex(a.0, b.0)
            .then(a.1.cmp(&b.1))
            .then(edges[a.2].id.cmp(&edges[b.2].id))
    });
    let mut status: BTreeSet<Key> = BTreeSet::new();
    let mut active = vec![false; edges.len()];
    for &(_, insert, i) in &events {
        let key = Key(edges[i]);
        let below = status.range(..key).next_back().copied();
        let above = status
            .range((Bound::Excluded(key), Bound::Unbounded))
            .next()
            .copied();
        if insert {
            if let Some(same) = status.get(&key) {
                // Collinear and both active: they overlap.
                if let Some(found) = check(same.0.id, key.0.id) {
                    return Some(found);
                }
                continue;
            }
            for n in [below, above].into_iter().flatten() {
                if let Some(found) = check(n.0.id, key.0.id) {
                    return Some(found);
                }
            }
            status.insert(key);
            active[i] = true;
        } else {
            if !active[i] {
                continue;
            }
            status.remove(&key);
            if let (Some(b), Some(a)) = (below, above)
                && let Some(found) = check(b.0.id, a.0.id)
            {
                return Some(found);
            }
        }
    }
    None
}
