//! The kinetic wavefront: input edges as moving lines, active vertices as their
//! intersections, and the exact direction tests the event handler relies on.
//!
//! A wavefront edge never changes direction: it is the supporting line of input edge `e`
//! moved inwards by `w_e · t` at time `t`. A wavefront vertex is the meeting point of two
//! such lines and moves with constant velocity between events, so its position is
//! `p0 + v · (t − t0)` from the moment `t0` it was created.

use std::cmp::Ordering;

use polis_geom::predicates::{AngleStart, ccw_cmp, orient2d};
use polis_geom::{DVec2, Orientation};

/// Below this sine of the angle between two unit edge directions (the balance between the
/// velocity error `1e-16 / sine` of a true intersection and the error `sine` of treating
/// them as parallel), the edges are treated
/// as parallel: the vertex between them moves perpendicular to both (same direction) or
/// is a fold where the two wavefront edges lie on top of each other (opposite directions).
pub(crate) const PARALLEL_SINE: f64 = 1e-8;

/// One input edge as a moving line.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EdgeLine {
    /// Start point of the input edge.
    pub a: DVec2,
    /// `b - a` as computed (used for exact angular comparisons).
    pub raw: DVec2,
    /// Unit direction.
    pub dir: DVec2,
    /// Unit normal pointing into the polygon (left of `dir`).
    pub normal: DVec2,
    /// Speed of the wavefront edge (the weight).
    pub weight: f64,
}

impl EdgeLine {
    pub fn new(a: DVec2, b: DVec2, weight: f64) -> Self {
        let raw = b - a;
        let dir = raw.normalize();
        EdgeLine {
            a,
            raw,
            dir,
            normal: dir.perp(),
            weight,
        }
    }

    /// Signed distance of `x` in front of the wavefront line at time `t` (positive on the
    /// side the wavefront moves to).
    #[inline]
    pub fn ahead(&self, x: DVec2, t: f64) -> f64 {
        self.normal.dot(x - self.a) - self.weight * t
    }

    /// The supporting line of the input edge (at time 0).
    #[inline]
    pub fn line(&self) -> polis_geom::lines::Line {
        polis_geom::lines::Line {
            point: self.a,
            normal: self.normal,
        }
    }

    /// Position of `x` along the edge direction, measured from the start point.
    #[inline]
    pub fn along(&self, x: DVec2) -> f64 {
        self.dir.dot(x - self.a)
    }
}

/// How a wavefront vertex moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Motion {
    /// An ordinary vertex on both lines.
    Moving(DVec2),
    /// The two edges are parallel, point the same way, and have different weights: there
    /// is no vertex on both lines. The event loop replaces it at once by a step (a virtual
    /// edge of weight 0 along the common normal with a vertex on each line); the velocity
    /// given is the mean one.
    Step(DVec2),
    /// The two edges point in opposite directions and lie on top of each other: a zero-
    /// width fold that is zipped closed at once.
    Fold,
}

/// Whether the turn from edge `a` to edge `b` goes back on itself (antiparallel within
/// [`PARALLEL_SINE`]): the vertex between them is a fold.
pub(crate) fn turns_back(a: &EdgeLine, b: &EdgeLine) -> bool {
    a.dir.perp_dot(b.dir).abs() <= PARALLEL_SINE && a.dir.dot(b.dir) < 0.0
}

/// The velocity of the vertex between incoming edge `a` and outgoing edge `b`.
pub(crate) fn motion(a: &EdgeLine, b: &EdgeLine) -> Motion {
    let (na, nb) = (a.normal, b.normal);
    let (wa, wb) = (a.weight, b.weight);
    let sine = a.dir.perp_dot(b.dir);
    let cosine = a.dir.dot(b.dir);
    if sine.abs() <= PARALLEL_SINE {
        if turns_back(a, b) {
            return Motion::Fold;
        }
        let n = (na + nb).normalize();
        return if wa == wb {
            Motion::Moving(n * wa)
        } else {
            Motion::Step(n * (0.5 * (wa + wb)))
        };
    }
    if wa == wb && cosine >= 0.0 {
        // Stable for every angle up to a right angle and beyond.
        return Motion::Moving((na + nb) * (wa / (1.0 + na.dot(nb))));
    }
    let det = na.perp_dot(nb);
    Motion::Moving(DVec2::new(
        (wa * nb.y - wb * na.y) / det,
        (wb * na.x - wa * nb.x) / det,
    ))
}

/// Where the wavefront lines of `a` and `b` cross at time `t`, solved relative to the
/// nearby point `near` (for accuracy); `None` when they are parallel.
pub(crate) fn meet(a: &EdgeLine, b: &EdgeLine, t: f64, near: DVec2) -> Option<DVec2> {
    polis_geom::lines::meet(
        &a.line(),
        a.weight * t,
        &b.line(),
        b.weight * t,
        near,
        PARALLEL_SINE,
    )
}

/// Whether the turn from incoming edge direction `din` to outgoing `dout` is reflex
/// (a right turn in a counter-clockwise ring), decided exactly.
pub(crate) fn is_reflex(din: DVec2, dout: DVec2) -> bool {
    orient2d(DVec2::ZERO, din, dout) == Orientation::Clockwise
}

/// Exact counter-clockwise angular order of two non-zero directions from angle 0.
pub(crate) fn angle_cmp(a: DVec2, b: DVec2) -> Ordering {
    ccw_cmp(DVec2::ZERO, a, b, AngleStart::East)
}

/// An active vertex of the wavefront.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Vertex {
    /// Position at creation.
    pub p0: DVec2,
    /// Time of creation.
    pub t0: f64,
    /// How it moves.
    pub motion: Motion,
    /// The input edge whose wavefront arrives at this vertex.
    pub in_edge: u32,
    /// The input edge whose wavefront leaves this vertex.
    pub out_edge: u32,
    /// Previous vertex in its circular list.
    pub prev: u32,
    /// Next vertex in its circular list.
    pub next: u32,
    /// The skeleton node it started from.
    pub node: u32,
    /// Whether it is still part of the wavefront.
    pub alive: bool,
}

impl Vertex {
    /// Velocity (zero for a fold, which never moves).
    #[inline]
    pub fn velocity(&self) -> DVec2 {
        match self.motion {
            Motion::Moving(v) | Motion::Step(v) => v,
            Motion::Fold => DVec2::ZERO,
        }
    }

    /// Position at time `t`.
    #[inline]
    pub fn at(&self, t: f64) -> DVec2 {
        self.p0 + self.velocity() * (t - self.t0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    #[test]
    fn square_corner_moves_diagonally() {
        let a = EdgeLine::new(v(0., 1.), v(0., 0.), 1.0);
        let b = EdgeLine::new(v(0., 0.), v(1., 0.), 1.0);
        assert_eq!(motion(&a, &b), Motion::Moving(v(1., 1.)));
        assert!(!is_reflex(a.raw, b.raw));
        assert!(is_reflex(b.raw, a.raw));
    }

    #[test]
    fn weighted_corner_stays_on_both_lines() {
        let a = EdgeLine::new(v(0., 1.), v(0., 0.), 2.0);
        let b = EdgeLine::new(v(0., 0.), v(3., 1.), 0.5);
        let Motion::Moving(vel) = motion(&a, &b) else {
            panic!("expected a moving vertex")
        };
        assert!((a.normal.dot(vel) - 2.0).abs() < 1e-12);
        assert!((b.normal.dot(vel) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn parallel_cases() {
        let a = EdgeLine::new(v(0., 0.), v(1., 0.), 1.0);
        let b = EdgeLine::new(v(1., 0.), v(2., 0.), 1.0);
        assert_eq!(motion(&a, &b), Motion::Moving(v(0., 1.)));
        let c = EdgeLine::new(v(1., 0.), v(2., 0.), 3.0);
        assert_eq!(motion(&a, &c), Motion::Step(v(0., 2.)));
        let d = EdgeLine::new(v(1., 0.), v(0., 0.), 1.0);
        assert_eq!(motion(&a, &d), Motion::Fold);
    }

    #[test]
    fn angular_order() {
        let dirs = [v(1., 0.), v(1., 1.), v(-1., 0.), v(0., -1.), v(1., -1e-300)];
        for w in dirs.windows(2) {
            assert_eq!(angle_cmp(w[0], w[1]), Ordering::Less);
        }
        assert_eq!(angle_cmp(v(2., 2.), v(1., 1.)), Ordering::Equal);
    }
}
