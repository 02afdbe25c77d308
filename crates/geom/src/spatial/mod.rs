//! Spatial indexes over points and segments, updatable while roads grow.
//!
//! An index maps keys `K` (any `Copy + Ord + Hash` id, e.g. [`EdgeId`](crate::EdgeId)) to a
//! [`Shape`]: a point or a segment. It answers
//!
//! * [`query_box`](SpatialIndex::query_box): keys whose shape meets a closed box;
//! * [`nearest_point`](SpatialIndex::nearest_point) / [`nearest_segment`](SpatialIndex::nearest_segment)
//!   within a radius, and all [`points_within`](SpatialIndex::points_within) /
//!   [`segments_within`](SpatialIndex::segments_within) a radius;
//! * [`segments_crossing`](SpatialIndex::segments_crossing): every segment that crosses,
//!   touches or overlaps a query segment, ordered by position along it.
//!
//! Two backends implement the [`SpatialIndex`] trait with identical answers:
//! [`GridIndex`] (a hashed uniform grid, the default, [`SegmentIndex`]) and
//! `RTreeIndex` (an R*-tree from the `rstar` crate, behind the `rtree` feature). The backends only gather
//! *candidates* by bounding box; every decision is then made by the trait's shared code with
//! exact predicates ([`crate::predicates`]), and results are sorted by distance/parameter
//! and then by key, so the answer never depends on the backend, the cell size, insertion
//! order or hash order.
//!
//! # Why a grid
//!
//! Measured on 100,000 random segments of 5–50 m in a 10 km square (the polis repository's `BENCHMARKS.md`,
//! `cargo bench -p polis-geom --bench spatial`): with 64 m cells the grid inserts about
//! 3× and removes about 4× faster than the R*-tree, and answers small-radius nearest and
//! segment-crossing queries 2–3× faster; the bulk-loaded R*-tree is about 1.3× faster on
//! 100 m box queries. Planar insertion and road growth repeat exactly the operations the
//! grid is fast at, on short, evenly spread segments, so the grid is the default.
//! `obvhs` was not used: it stores `f32` boxes (millimetres at 10 km, so every box would
//! need padding) and has no nearest-neighbour query.
//!
//! # Example
//!
//! ```
//! use polis_geom::{DVec2, spatial::{SegmentIndex, SpatialIndex}};
//!
//! let mut index = SegmentIndex::<u32>::default();
//! index.insert_segment(1, DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0))?;
//! index.insert_segment(2, DVec2::new(5.0, -5.0), DVec2::new(5.0, 5.0))?;
//! index.insert_point(3, DVec2::new(2.0, 1.0))?;
//! let hits = index.segments_crossing(DVec2::new(7.0, 1.0), DVec2::new(3.0, 5.0));
//! assert_eq!(hits.iter().map(|h| h.key).collect::<Vec<_>>(), vec![2]);
//! let near = index.nearest_segment(DVec2::new(3.0, 0.5), 1.0).map(|n| n.key);
//! assert_eq!(near, Some(1));
//! # Ok::<(), polis_geom::GeomError>(())
//! ```

mod grid;
#[cfg(feature = "rtree")]
mod rtree;
mod shape;

use std::fmt::Debug;
use std::hash::Hash;

use glam::DVec2;

use crate::bbox::Aabb2;
use crate::error::GeomError;
use crate::predicates::{SegmentIntersection, segment_intersection};

pub use grid::GridIndex;
#[cfg(feature = "rtree")]
pub use rtree::RTreeIndex;
pub use shape::Shape;

/// The spatial index polis uses (the faster backend on the benchmark): [`GridIndex`].
pub type SegmentIndex<K> = GridIndex<K>;

/// What a key of a spatial index must be: a small copyable, totally ordered id.
pub trait IndexKey: Copy + Ord + Hash + Debug {}
impl<T: Copy + Ord + Hash + Debug> IndexKey for T {}

/// Tuning of a [`GridIndex`]. A performance knob only: answers never depend on it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct GridOptions {
    /// Side of a grid cell, in metres. Best near the typical segment length and query
    /// radius. Must be finite and at least [`GridOptions::MIN_CELL_SIZE`].
    /// Default: 64 m (fastest on the benchmark for 5–50 m segments and 25–100 m queries).
    pub cell_size: f64,
}

impl GridOptions {
    /// The smallest allowed cell size, in metres (keeps cell coordinates within `i64`
    /// and cell counts bounded for any coordinate within [`MAX_COORDINATE`](crate::MAX_COORDINATE)).
    pub const MIN_CELL_SIZE: f64 = 1e-3;
}

impl Default for GridOptions {
    fn default() -> Self {
        GridOptions { cell_size: 64.0 }
    }
}

/// A segment found near a point: see [`SpatialIndex::nearest_segment`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentNear<K> {
    /// The segment's key.
    pub key: K,
    /// Distance from the query point, in metres.
    pub distance: f64,
    /// The closest point of the segment.
    pub closest: DVec2,
    /// Parameter of `closest` along the segment as stored (`0` at its first end).
    pub t: f64,
}

/// A point found near a point: see [`SpatialIndex::nearest_point`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointNear<K> {
    /// The point's key.
    pub key: K,
    /// Its position.
    pub point: DVec2,
    /// Distance from the query point, in metres.
    pub distance: f64,
}

/// A segment meeting a query segment: see [`SpatialIndex::segments_crossing`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentHit<K> {
    /// The stored segment's key.
    pub key: K,
    /// Parameter along the query segment of the first common point (`0` at its start).
    pub t: f64,
    /// How the query segment (first) and the stored segment (second) meet, exactly
    /// classified by [`segment_intersection`].
    pub kind: SegmentIntersection,
}

/// The queries every spatial index answers; backends supply storage and candidates.
///
/// All answers are exact with respect to the stored `f64` geometry (distances are the
/// `f64` distances of [`crate::predicates::distance_to_segment`]), and deterministic:
/// sorted as each method says, ties broken by key.
pub trait SpatialIndex<K: IndexKey> {
    /// Stores `shape` under `key`, replacing (and returning) any shape stored under it.
    ///
    /// # Errors
    /// [`GeomError::NonFinite`] / [`GeomError::OutOfRange`] for a bad coordinate; the
    /// index is unchanged then.
    fn insert(&mut self, key: K, shape: Shape) -> Result<Option<Shape>, GeomError>;

    /// Removes and returns the shape stored under `key`.
    fn remove(&mut self, key: K) -> Option<Shape>;

    /// The shape stored under `key`.
    fn get(&self, key: K) -> Option<Shape>;

    /// Number of stored shapes.
    fn len(&self) -> usize;

    /// Removes everything.
    fn clear(&mut self);

    /// Calls `f` once for every stored shape whose bounding box meets the closed box
    /// `b`, and possibly for some others (a superset), in unspecified order.
    fn for_each_candidate<F: FnMut(K, &Shape)>(&self, b: &Aabb2, f: F);

    /// Like [`for_each_candidate`](Self::for_each_candidate) for the shapes that may
    /// meet the closed segment `a–b`. The default uses the segment's bounding box.
    fn for_each_candidate_along<F: FnMut(K, &Shape)>(&self, a: DVec2, b: DVec2, f: F) {
        self.for_each_candidate(&Aabb2::new(a, b), f);
    }

    /// Whether nothing is stored.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Stores the point `p` under `key` (see [`insert`](Self::insert)).
    fn insert_point(&mut self, key: K, p: DVec2) -> Result<Option<Shape>, GeomError> {
        self.insert(key, Shape::Point(p))
    }

    /// Stores the segment `a–b` under `key` (see [`insert`](Self::insert)).
    fn insert_segment(&mut self, key: K, a: DVec2, b: DVec2) -> Result<Option<Shape>, GeomError> {
        self.insert(key, Shape::Segment(a, b))
    }

    /// Keys of all shapes that share a point with the closed box `b`, in increasing order.
    fn query_box(&self, b: &Aabb2) -> Vec<K> {
        let mut out = Vec::new();
        // Every stored coordinate is within MAX_COORDINATE: clip (infinite) boxes to a
        // finite one so the exact predicates see finite corners.
        let limit = 2.0 * crate::MAX_COORDINATE;
        let b = b.intersection(&Aabb2::new(DVec2::splat(-limit), DVec2::splat(limit)));
        if b.is_empty() {
            return out;
        }
        self.for_each_candidate(&b, |k, s| {
            if s.intersects_box(&b) {
                out.push(k);
            }
        });
        out.sort_unstable();
        out
    }

    /// All stored points within `radius` of `p` (inclusive), nearest first, ties by key.
    fn points_within(&self, p: DVec2, radius: f64) -> Vec<PointNear<K>> {
        let mut out = Vec::new();
        if radius.is_nan() || radius < 0.0 || !p.is_finite() {
            return out;
        }
        self.for_each_candidate(&Aabb2::new(p, p).expanded(radius), |key, s| {
            if let Shape::Point(q) = *s {
                let distance = q.distance(p);
                if distance <= radius {
                    out.push(PointNear {
                        key,
                        point: q,
                        distance,
                    });
                }
            }
        });
        out.sort_unstable_by(|x, y| x.distance.total_cmp(&y.distance).then(x.key.cmp(&y.key)));
        out
    }

    /// All stored segments within `radius` of `p` (inclusive), nearest first, ties by key.
    fn segments_within(&self, p: DVec2, radius: f64) -> Vec<SegmentNear<K>> {
        let mut out = Vec::new();
        if radius.is_nan() || radius < 0.0 || !p.is_finite() {
            return out;
        }
        self.for_each_candidate(&Aabb2::new(p, p).expanded(radius), |key, s| {
            if let Some(n) = s.segment_near(key, p)
                && n.distance <= radius
            {
                out.push(n);
            }
        });
        out.sort_unstable_by(|x, y| x.distance.total_cmp(&y.distance).then(x.key.cmp(&y.key)));
        out
    }

    /// The stored point nearest to `p` within `radius` (inclusive); ties by smaller key.
    fn nearest_point(&self, p: DVec2, radius: f64) -> Option<PointNear<K>> {
        let mut best: Option<PointNear<K>> = None;
        if radius.is_nan() || radius < 0.0 || !p.is_finite() {
            return None;
        }
        self.for_each_candidate(&Aabb2::new(p, p).expanded(radius), |key, s| {
            if let Shape::Point(q) = *s {
                let distance = q.distance(p);
                let better = best.is_none_or(|b| (distance, key) < (b.distance, b.key));
                if distance <= radius && better {
                    best = Some(PointNear {
                        key,
                        point: q,
                        distance,
                    });
                }
            }
        });
        best
    }

    /// The stored segment nearest to `p` within `radius` (inclusive); ties by smaller key.
    fn nearest_segment(&self, p: DVec2, radius: f64) -> Option<SegmentNear<K>> {
        let mut best: Option<SegmentNear<K>> = None;
        if radius.is_nan() || radius < 0.0 || !p.is_finite() {
            return None;
        }
        self.for_each_candidate(&Aabb2::new(p, p).expanded(radius), |key, s| {
            if let Some(n) = s.segment_near(key, p) {
                let better = best.is_none_or(|b| (n.distance, key) < (b.distance, b.key));
                if n.distance <= radius && better {
                    best = Some(n);
                }
            }
        });
        best
    }

    /// Every stored segment that shares a point with the closed query segment `a–b`
    /// (crossing, touching, or collinear overlap), ordered by the parameter `t` along
    /// `a → b` of the first common point, ties by key. Stored points are ignored.
    fn segments_crossing(&self, a: DVec2, b: DVec2) -> Vec<SegmentHit<K>> {
        let mut out = Vec::new();
        if !a.is_finite() || !b.is_finite() {
            return out;
        }
        self.for_each_candidate_along(a, b, |key, s| {
            if let Shape::Segment(s0, s1) = *s
                && let Some(hit) = classify_hit(key, a, b, s0, s1)
            {
                out.push(hit);
            }
        });
        out.sort_unstable_by(|x, y| x.t.total_cmp(&y.t).then(x.key.cmp(&y.key)));
        out
    }

    /// The first hit of [`segments_crossing`](Self::segments_crossing)`(a, b)` that
    /// `accept` approves — smallest `t`, ties by key — found without allocating or
    /// sorting. `accept` is asked only about hits that would come before the best one
    /// found so far, in unspecified order, so it should be a pure test.
    fn first_crossing<P: FnMut(&SegmentHit<K>) -> bool>(
        &self,
        a: DVec2,
        b: DVec2,
        mut accept: P,
    ) -> Option<SegmentHit<K>> {
        if !a.is_finite() || !b.is_finite() {
            return None;
        }
        let mut best: Option<SegmentHit<K>> = None;
        self.for_each_candidate_along(a, b, |key, s| {
            if let Shape::Segment(s0, s1) = *s
                && let Some(hit) = classify_hit(key, a, b, s0, s1)
                && best.is_none_or(|h| hit.t.total_cmp(&h.t).then(hit.key.cmp(&h.key)).is_lt())
                && accept(&hit)
            {
                best = Some(hit);
            }
        });
        best
    }
}

/// The hit of stored segment `s0–s1` on query `a–b`, if they meet.
pub(crate) fn classify_hit<K>(
    key: K,
    a: DVec2,
    b: DVec2,
    s0: DVec2,
    s1: DVec2,
) -> Option<SegmentHit<K>> {
    let kind = segment_intersection(a, b, s0, s1);
    let t = match kind {
        SegmentIntersection::Disjoint => return None,
        SegmentIntersection::Crossing { t, .. } | SegmentIntersection::Touching { t, .. } => t,
        SegmentIntersection::Overlap { t, .. } => t.0.min(t.1),
    };
    Some(SegmentHit { key, t, kind })
}

#[cfg(test)]
mod tests;
