//! The quadtree refinement of [`Terrain::build`](super::Terrain::build): which leaves
//! the terrain ends with, and the field at their check points and corners.
//!
//! Every leaf carries the field at its 25 check points ([`Checks`]), sampled once: a
//! root samples its own, and a split samples its leaf at twice the resolution (9 × 9
//! points, of which the 25 even ones are the leaf's), which gives the four children
//! theirs. The batches go to [`Field::sample_many`], so a field that looks up its
//! neighbourhood per sample (the graded ground's road cones) looks up once per leaf.
//!
//! Both rounds decide exactly as a plain pass-by-pass refinement would:
//! 1. **Own fans**, level by level: every leaf of a level is checked on its own corners
//!    and centre; those that miss the bound split (in level order, while the leaf budget
//!    allows).
//! 2. **Final fans**, pass by pass: every leaf is checked with every corner on its
//!    border (its own and those of smaller neighbours, *hanging* vertices), against the
//!    corners at the start of the pass; those that miss split, and passes repeat until
//!    none does. A leaf of the first round without hanging vertices has passed already;
//!    a child of a split of this round is checked like any other leaf, also when no
//!    vertex hangs on its border. A leaf's check depends only on the corners on its
//!    border, so a pass checks only the leaves that are new or gained a corner since
//!    their last check and keeps the others' results.
//!
//! The checks of a level or a pass and the samples of its splits run in parallel
//! ([`crate::par`]); the decisions run in leaf order, so the leaves do not depend on the
//! thread count.

use glam::DVec2;

use super::{Corner, EdgeProfile, Lattice, Leaf, edge_ranges, fan_height, profiles_in, split};
use crate::field::Field;
use crate::par::prelude::*;
use crate::{GeomError, MAX_COORDINATE};

/// The field and the slack at a leaf's 5 × 5 check points, row by row: entry `5·j + i`
/// is the point `(i/4, j/4)` of the leaf (its corners are entries 0, 4, 20 and 24, its
/// centre 12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Checks {
    /// The field.
    pub field: [f64; 25],
    /// How far below the field the fan may lie there (≥ 0, rounded down to `f32`; all 0
    /// without a slack field).
    pub slack: [f32; 25],
}

impl Checks {
    /// The height a vertex of the fan takes at check entry `k` (before the terrain's
    /// offset): the field less [`MIDLINE_SHARE`] of the slack there, the middle of the
    /// band the check allows (the field itself without slack).
    pub fn vertex(&self, k: usize) -> f64 {
        self.field[k] - MIDLINE_SHARE * f64::from(self.slack[k])
    }
}

/// Which share of the slack the fans' vertices sit under the field: a half, the middle
/// of the band `[field − slack − 2e, field]` the check allows, so a fan may rise over its
/// vertices (a kink that bends up: a valley, the foot of a bank) by half the slack and
/// sag under them (a ridge, a bank's top) by half the slack, besides `max_error_m`
/// either way, before the leaf splits. Without slack the vertices take the field's
/// values.
pub(super) const MIDLINE_SHARE: f64 = 0.5;

/// Entries of [`Checks`] that are vertices of the leaf's own fan: the corners in the
/// order bottom left, bottom right, top right, top left, then the centre.
const VERTICES: [usize; 5] = [0, 4, 24, 20, 12];

/// Corners with the field there, sorted by their key (`(y, x)` or `(x, y)`).
type CornerList = Vec<(Corner, f64)>;

/// What the refinement settled on.
pub(super) struct Refined {
    /// The leaves, sorted by `(y, x)`, with the field at their check points.
    pub leaves: Vec<(Leaf, Checks)>,
    /// Leaf corners with the field there, sorted by `(y, x)` and by `(x, y)`.
    pub rows: Vec<(Corner, f64)>,
    pub cols: Vec<(Corner, f64)>,
    /// Leaves that miss the bound for good (possibly repeated, possibly split later).
    pub flagged: Vec<Leaf>,
    /// Largest miss met.
    pub worst: f64,
    /// Leaves counted as unresolved.
    pub unresolved: usize,
}

/// A leaf of the final-fan passes: its check points are `store[slot]`; `miss` is its
/// last check's.
#[derive(Clone, Copy)]
struct Node {
    leaf: Leaf,
    slot: usize,
    miss: f64,
}

/// Refines the root cells of `grid` over `field` to `max_error` (see the module docs).
pub(super) fn refine(
    grid: &Lattice,
    field: &dyn Field,
    slack: Option<&dyn Field>,
    max_error: f64,
    max_leaves: usize,
) -> Result<Refined, GeomError> {
    let e = max_error;
    let mut roots = Vec::with_capacity((grid.nx * grid.ny) as usize);
    for j in 0..grid.ny {
        for i in 0..grid.nx {
            roots.push(Leaf {
                x: i * grid.root,
                y: j * grid.root,
                size: grid.root,
            });
        }
    }
    let mut work: Vec<(Leaf, Checks)> = roots
        .par_iter()
        .map(|&leaf| (leaf, root_checks(grid, field, slack, leaf)))
        .collect();

    // 1. Own fans, level by level.
    // The settled leaves; their check points are `store[slot]`.
    let mut nodes: Vec<Node> = Vec::with_capacity(work.len());
    let mut store: Vec<Checks> = Vec::with_capacity(work.len());
    let mut worst = 0.0f64;
    let mut unresolved = 0usize;
    let mut flagged: Vec<Leaf> = Vec::new();
    while !work.is_empty() {
        let misses: Vec<Result<f64, GeomError>> = work
            .par_iter()
            .map(|(leaf, checks)| own_miss(grid, *leaf, checks))
            .collect();
        let pending = work.len();
        let mut splitting = Vec::new();
        for (done, ((leaf, checks), miss)) in work.iter().zip(misses).enumerate() {
            let miss = miss?;
            // Leaves if this one splits: the settled, the next level's, the rest of this
            // level's, and its four children.
            let room = nodes.len() + 4 * splitting.len() + (pending - done - 1) + 4 <= max_leaves;
            if miss > e && leaf.size > 2 && room {
                splitting.push(done);
            } else {
                if miss > e {
                    unresolved += 1;
                    flagged.push(*leaf);
                }
                worst = worst.max(miss);
                nodes.push(Node {
                    leaf: *leaf,
                    slot: store.len(),
                    miss: 0.0,
                });
                store.push(*checks);
            }
        }
        let children: Vec<[(Leaf, Checks); 4]> = splitting
            .par_iter()
            .map(|&k| {
                let (leaf, checks) = &work[k];
                children_of(grid, field, slack, *leaf, checks)
            })
            .collect();
        work = children.into_iter().flatten().collect();
    }

    // 2. Final fans, pass by pass.
    let (mut rows, mut cols) = corners_of(nodes.iter().map(|n| (n.leaf, &store[n.slot])));
    // Slots at or beyond `fresh` hold leaves not checked yet; `new_rows` and `new_cols`
    // the corners added since the last pass.
    let mut fresh = 0usize;
    let mut new_rows: Vec<(Corner, f64)> = Vec::new();
    let mut new_cols: Vec<(Corner, f64)> = Vec::new();
    // Root cells whose closed square holds a corner of `new_rows`.
    let mut touched = vec![false; (grid.nx * grid.ny) as usize];
    // Slots from here on hold leaves split off in this round, whose own fans were never
    // checked.
    let round_two = store.len();
    loop {
        let due: Vec<usize> = (0..nodes.len())
            .into_par_iter()
            .filter(|&k| {
                let n = nodes[k];
                let root = (n.leaf.y / grid.root) * grid.nx + n.leaf.x / grid.root;
                n.slot >= fresh
                    || (touched.get(root as usize) == Some(&true)
                        && gained_corner(n.leaf, &new_rows, &new_cols))
            })
            .collect();
        let checked: Vec<Result<f64, GeomError>> = due
            .par_iter()
            .map(|&k| {
                let n = nodes[k];
                let own_checked = n.slot < round_two;
                final_miss(grid, n.leaf, &store[n.slot], own_checked, &rows, &cols)
            })
            .collect();
        for (&k, miss) in due.iter().zip(checked) {
            nodes[k].miss = miss?;
        }
        fresh = store.len();
        let mut kept: Vec<Node> = Vec::with_capacity(nodes.len());
        let mut splitting: Vec<Node> = Vec::new();
        for (done, n) in nodes.iter().enumerate() {
            let room = kept.len() + (nodes.len() - done - 1) + 4 <= max_leaves;
            if n.miss > e && n.leaf.size > 2 && room {
                let mut children = Vec::with_capacity(4);
                split(n.leaf, &mut children);
                let first = store.len() + 4 * splitting.len();
                for (c, leaf) in children.into_iter().enumerate() {
                    kept.push(Node {
                        leaf,
                        slot: first + c,
                        miss: 0.0,
                    });
                }
                splitting.push(*n);
            } else {
                kept.push(*n);
            }
        }
        if splitting.is_empty() {
            for n in &nodes {
                if n.miss > e {
                    unresolved += 1;
                    flagged.push(n.leaf);
                }
                worst = worst.max(n.miss);
            }
            break;
        }
        let children: Vec<[(Leaf, Checks); 4]> = splitting
            .par_iter()
            .map(|n| children_of(grid, field, slack, n.leaf, &store[n.slot]))
            .collect();
        for (_, checks) in children.iter().flatten() {
            store.push(*checks);
        }
        (new_rows, new_cols) = split_corners(&splitting, &store, &rows);
        touched.fill(false);
        for &((y, x), _) in &new_rows {
            for ry in roots_at(y, grid.root, grid.ny) {
                for rx in roots_at(x, grid.root, grid.nx) {
                    if let Some(t) = touched.get_mut((ry * grid.nx + rx) as usize) {
                        *t = true;
                    }
                }
            }
        }
        rows = merge(rows, &new_rows);
        cols = merge(cols, &new_cols);
        nodes = kept;
    }
    nodes.sort_unstable_by_key(|n| (n.leaf.y, n.leaf.x));
    Ok(Refined {
        leaves: nodes.iter().map(|n| (n.leaf, store[n.slot])).collect(),
        rows,
        cols,
        flagged,
        worst,
        unresolved,
    })
}

/// The point of check entry `k` of `leaf`.
pub(super) fn check_point(grid: &Lattice, leaf: Leaf, k: usize) -> DVec2 {
    let s = leaf.size as f64;
    let (i, j) = ((k % 5) as u32, (k / 5) as u32);
    grid.point(
        leaf.x as f64 + f64::from(i) / 4.0 * s,
        leaf.y as f64 + f64::from(j) / 4.0 * s,
    )
}

/// The field and the slack at a root's check points.
fn root_checks(grid: &Lattice, field: &dyn Field, slack: Option<&dyn Field>, leaf: Leaf) -> Checks {
    let points: [DVec2; 25] = std::array::from_fn(|k| check_point(grid, leaf, k));
    let mut checks = Checks {
        field: [0.0; 25],
        slack: [0.0; 25],
    };
    field.sample_many(&points, &mut checks.field);
    if let Some(slack) = slack {
        let mut values = [0.0; 25];
        slack.sample_many(&points, &mut values);
        for (s, v) in checks.slack.iter_mut().zip(values) {
            *s = slack_of(v);
        }
    }
    checks
}

/// A slack as stored: `v` rounded down to `f32`, 0 where it is negative or not a number
/// (an infinite slack stays infinite).
fn slack_of(v: f64) -> f32 {
    if v.is_nan() || v <= 0.0 {
        return 0.0;
    }
    let r = v as f32;
    if f64::from(r) > v { r.next_down() } else { r }
}

/// The four children of `leaf` (in [`split`] order) with their check points: the leaf's
/// own are the children's even ones, the other 56 are sampled in one batch.
fn children_of(
    grid: &Lattice,
    field: &dyn Field,
    slack: Option<&dyn Field>,
    leaf: Leaf,
    checks: &Checks,
) -> [(Leaf, Checks); 4] {
    // The leaf at twice the resolution: 9 × 9 points an eighth of its side apart.
    let s = leaf.size as f64;
    let mut fine = [0.0f64; 81];
    let mut fine_slack = [0.0f32; 81];
    let mut points = Vec::with_capacity(56);
    let mut slots = Vec::with_capacity(56);
    for j in 0..9u32 {
        for i in 0..9u32 {
            let k = (9 * j + i) as usize;
            if i % 2 == 0 && j % 2 == 0 {
                let own = (5 * (j / 2) + i / 2) as usize;
                fine[k] = checks.field[own];
                fine_slack[k] = checks.slack[own];
            } else {
                // Exact: eighths of a power-of-two side in lattice units, as the child's
                // own quarter points would be computed.
                points.push(grid.point(
                    leaf.x as f64 + f64::from(i) / 8.0 * s,
                    leaf.y as f64 + f64::from(j) / 8.0 * s,
                ));
                slots.push(k);
            }
        }
    }
    let mut values = vec![0.0; points.len()];
    field.sample_many(&points, &mut values);
    for (&k, &v) in slots.iter().zip(&values) {
        fine[k] = v;
    }
    if let Some(slack) = slack {
        slack.sample_many(&points, &mut values);
        for (&k, &v) in slots.iter().zip(&values) {
            fine_slack[k] = slack_of(v);
        }
    }
    let mut children = Vec::with_capacity(4);
    split(leaf, &mut children);
    std::array::from_fn(|c| {
        let (ox, oy) = ((c % 2) * 4, (c / 2) * 4);
        let child = children.get(c).copied().unwrap_or(leaf);
        let at = |k: usize| 9 * (oy + k / 5) + ox + k % 5;
        (
            child,
            Checks {
                field: std::array::from_fn(|k| fine[at(k)]),
                slack: std::array::from_fn(|k| fine_slack[at(k)]),
            },
        )
    })
}

/// An error for the field's value `v` at `p`.
fn not_finite(v: f64, p: DVec2) -> GeomError {
    GeomError::InvalidParameter {
        name: "field",
        reason: format!("the ground is {v} at {p}; it must be finite"),
    }
}

/// The leaf's fan vertices must be finite and within [`MAX_COORDINATE`].
fn check_vertices(grid: &Lattice, leaf: Leaf, checks: &Checks) -> Result<(), GeomError> {
    for k in VERTICES {
        let v = checks.field[k];
        if !(v.is_finite() && v.abs() <= MAX_COORDINATE) {
            return Err(not_finite(v, check_point(grid, leaf, k)));
        }
    }
    Ok(())
}

/// The largest miss of the fan with border `profiles` at the leaf's check points (the
/// corners and the centre are vertices): how far it lies above the field, or below the
/// field less the slack there (`|fan − field|` without slack).
fn fan_miss(
    grid: &Lattice,
    leaf: Leaf,
    profiles: &[EdgeProfile; 4],
    checks: &Checks,
) -> Result<f64, GeomError> {
    let mut worst = 0.0f64;
    for (k, (&f, &slack)) in checks.field.iter().zip(&checks.slack).enumerate() {
        if VERTICES.contains(&k) {
            continue;
        }
        if !f.is_finite() {
            return Err(not_finite(f, check_point(grid, leaf, k)));
        }
        let (u, v) = (
            f64::from((k % 5) as u32) / 4.0,
            f64::from((k / 5) as u32) / 4.0,
        );
        // Above the field by `d`, or below the field less the slack by `−d − slack`;
        // with no slack the larger of the two is `|d|` exactly.
        let d = fan_height(profiles, checks.vertex(12), u, v) - f;
        worst = worst.max(d.max(-d - f64::from(slack)));
    }
    Ok(worst)
}

/// The miss of the leaf's own fan (its corners and centre).
fn own_miss(grid: &Lattice, leaf: Leaf, checks: &Checks) -> Result<f64, GeomError> {
    check_vertices(grid, leaf, checks)?;
    let v = |k: usize| checks.vertex(k);
    let [bl, br, tr, tl] = [v(0), v(4), v(24), v(20)];
    let profiles = [
        vec![(0.0, bl), (1.0, br)],
        vec![(0.0, br), (1.0, tr)],
        vec![(0.0, tl), (1.0, tr)],
        vec![(0.0, bl), (1.0, tl)],
    ];
    fan_miss(grid, leaf, &profiles, checks)
}

/// The miss of the leaf's final fan (through every corner on its border); 0 for a leaf
/// whose own fan was checked (`own_checked`) and whose border holds no other corner.
fn final_miss(
    grid: &Lattice,
    leaf: Leaf,
    checks: &Checks,
    own_checked: bool,
    rows: &[(Corner, f64)],
    cols: &[(Corner, f64)],
) -> Result<f64, GeomError> {
    check_vertices(grid, leaf, checks)?;
    let ranges = edge_ranges(leaf, rows, cols);
    if ranges.iter().all(|r| r.len() <= 2) {
        return if own_checked {
            Ok(0.0)
        } else {
            own_miss(grid, leaf, checks)
        };
    }
    let profiles = profiles_in(leaf, rows, cols, &ranges);
    fan_miss(grid, leaf, &profiles, checks)
}

/// The root cells (along one axis, `count` of them, `root` lattice units each) whose
/// closed side holds lattice coordinate `v`: one, or two on a boundary between them.
fn roots_at(v: u64, root: u64, count: u64) -> impl Iterator<Item = u64> {
    let own = v / root;
    let before = v.is_multiple_of(root).then(|| own.checked_sub(1)).flatten();
    [before, Some(own)]
        .into_iter()
        .flatten()
        .filter(move |&r| r < count)
}

/// Whether a corner of `new_rows` / `new_cols` (sorted) lies on the leaf's border.
fn gained_corner(leaf: Leaf, new_rows: &[(Corner, f64)], new_cols: &[(Corner, f64)]) -> bool {
    let s = leaf.size;
    let on = |keys: &[(Corner, f64)], line: u64, from: u64| {
        let lo = keys.partition_point(|&(k, _)| k < (line, from));
        keys.get(lo).is_some_and(|&(k, _)| k <= (line, from + s))
    };
    on(new_rows, leaf.y, leaf.x)
        || on(new_rows, leaf.y + s, leaf.x)
        || on(new_cols, leaf.x, leaf.y)
        || on(new_cols, leaf.x + s, leaf.y)
}

/// Sorted, deduplicated corners of `leaves` by `(y, x)` and by `(x, y)`, with the field.
fn corners_of<'a>(leaves: impl Iterator<Item = (Leaf, &'a Checks)>) -> (CornerList, CornerList) {
    let mut rows = Vec::new();
    for (l, c) in leaves {
        let s = l.size;
        rows.extend([
            ((l.y, l.x), c.vertex(0)),
            ((l.y, l.x + s), c.vertex(4)),
            ((l.y + s, l.x), c.vertex(20)),
            ((l.y + s, l.x + s), c.vertex(24)),
        ]);
    }
    sort_corners(rows)
}

/// `rows` sorted and deduplicated (equal corners hold equal values), and the same
/// corners sorted by `(x, y)`.
fn sort_corners(mut rows: Vec<(Corner, f64)>) -> (CornerList, CornerList) {
    rows.sort_unstable_by_key(|&(k, _)| k);
    rows.dedup_by_key(|&mut (k, _)| k);
    let mut cols: Vec<(Corner, f64)> = rows.iter().map(|&((y, x), h)| ((x, y), h)).collect();
    cols.sort_unstable_by_key(|&(k, _)| k);
    (rows, cols)
}

/// The corners the splits of `splitting` add that `rows` lacks (the midpoints of their
/// sides and their centres), by `(y, x)` and by `(x, y)`; the field there is read from
/// the split leaves' check points (entries 2, 14, 22, 10 and 12).
fn split_corners(
    splitting: &[Node],
    store: &[Checks],
    rows: &[(Corner, f64)],
) -> (CornerList, CornerList) {
    let mut added = Vec::with_capacity(5 * splitting.len());
    for n in splitting {
        let (l, c) = (n.leaf, &store[n.slot]);
        let h = l.size / 2;
        for (key, k) in [
            ((l.y, l.x + h), 2),
            ((l.y + h, l.x + l.size), 14),
            ((l.y + l.size, l.x + h), 22),
            ((l.y + h, l.x), 10),
            ((l.y + h, l.x + h), 12),
        ] {
            if rows.binary_search_by_key(&key, |&(q, _)| q).is_err() {
                added.push((key, c.vertex(k)));
            }
        }
    }
    sort_corners(added)
}

/// The union of two sorted corner lists without common corners, sorted.
fn merge(old: Vec<(Corner, f64)>, new: &[(Corner, f64)]) -> Vec<(Corner, f64)> {
    if new.is_empty() {
        return old;
    }
    let mut out = Vec::with_capacity(old.len() + new.len());
    let mut rest = new.iter().peekable();
    for item in old {
        while let Some(&&n) = rest.peek() {
            if n.0 < item.0 {
                out.push(n);
                rest.next();
            } else {
                break;
            }
        }
        out.push(item);
    }
    out.extend(rest);
    out
}
