//! Fields built from fields: arithmetic, thresholds, selection, domain transforms.
//!
//! Each combinator is a plain struct with public fields (serde-friendly when its inner
//! fields are), also reachable through [`FieldExt`](super::FieldExt) methods. Gradients
//! are exact wherever the inner gradients are.
//!
//! **NaN policy.** A NaN value of any inner field that the result depends on gives NaN (so
//! a NaN point gives NaN through any chain of combinators over point-dependent fields).
//! [`Min`] and [`Max`] propagate NaN instead of ignoring it as `f64::min` does.
//! Combinators never panic, whatever their parameters.

use glam::DVec2;

use super::Field;

/// `factor · field`. Built by [`FieldExt::scaled`](super::FieldExt::scaled).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Scaled<F> {
    /// The field scaled.
    pub field: F,
    /// The factor.
    pub factor: f64,
}

impl<F: Field> Scaled<F> {
    /// `factor · field`.
    pub fn new(field: F, factor: f64) -> Self {
        Scaled { field, factor }
    }
}

impl<F: Field> Field for Scaled<F> {
    fn sample(&self, p: DVec2) -> f64 {
        self.factor * self.field.sample(p)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.field.gradient(p) * self.factor
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (v, g) = self.field.sample_with_gradient(p);
        (self.factor * v, g * self.factor)
    }
}

/// `field + offset`. Built by [`FieldExt::offset`](super::FieldExt::offset).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Offset<F> {
    /// The field shifted.
    pub field: F,
    /// The constant added.
    pub offset: f64,
}

impl<F: Field> Offset<F> {
    /// `field + offset`.
    pub fn new(field: F, offset: f64) -> Self {
        Offset { field, offset }
    }
}

impl<F: Field> Field for Offset<F> {
    fn sample(&self, p: DVec2) -> f64 {
        self.field.sample(p) + self.offset
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.field.gradient(p)
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (v, g) = self.field.sample_with_gradient(p);
        (v + self.offset, g)
    }
}

/// `a + b`. Built by [`FieldExt::plus`](super::FieldExt::plus).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Sum<A, B> {
    /// First term.
    pub a: A,
    /// Second term.
    pub b: B,
}

impl<A: Field, B: Field> Sum<A, B> {
    /// `a + b`.
    pub fn new(a: A, b: B) -> Self {
        Sum { a, b }
    }
}

impl<A: Field, B: Field> Field for Sum<A, B> {
    fn sample(&self, p: DVec2) -> f64 {
        self.a.sample(p) + self.b.sample(p)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.a.gradient(p) + self.b.gradient(p)
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (va, ga) = self.a.sample_with_gradient(p);
        let (vb, gb) = self.b.sample_with_gradient(p);
        (va + vb, ga + gb)
    }
}

/// `a · b`. Built by [`FieldExt::times`](super::FieldExt::times).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Product<A, B> {
    /// First factor.
    pub a: A,
    /// Second factor.
    pub b: B,
}

impl<A: Field, B: Field> Product<A, B> {
    /// `a · b`.
    pub fn new(a: A, b: B) -> Self {
        Product { a, b }
    }
}

impl<A: Field, B: Field> Field for Product<A, B> {
    fn sample(&self, p: DVec2) -> f64 {
        self.a.sample(p) * self.b.sample(p)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.sample_with_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (va, ga) = self.a.sample_with_gradient(p);
        let (vb, gb) = self.b.sample_with_gradient(p);
        (va * vb, ga * vb + gb * va)
    }
}

/// A step: `1` where `field >= threshold` (the threshold itself counts as above), else `0`;
/// NaN where the field is NaN. The gradient is zero (NaN where the value is NaN): the step
/// itself has no finite derivative. Built by
/// [`FieldExt::threshold`](super::FieldExt::threshold).
///
/// Typical use: a water map `water.threshold(0.5)` as the legality test of Parish & Müller's
/// local constraints (§3.3).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Threshold<F> {
    /// The field tested.
    pub field: F,
    /// The level at and above which the result is 1.
    pub threshold: f64,
}

impl<F: Field> Threshold<F> {
    /// `1` where `field >= threshold`, else `0`.
    pub fn new(field: F, threshold: f64) -> Self {
        Threshold { field, threshold }
    }

    fn step(&self, v: f64) -> f64 {
        if v.is_nan() {
            f64::NAN
        } else if v >= self.threshold {
            1.0
        } else {
            0.0
        }
    }
}

impl<F: Field> Field for Threshold<F> {
    fn sample(&self, p: DVec2) -> f64 {
        self.step(self.field.sample(p))
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.sample_with_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let v = self.sample(p);
        (v, if v.is_nan() { DVec2::NAN } else { DVec2::ZERO })
    }
}

/// Picks the value and gradient of `a` or `b`; NaN if either is NaN.
fn pick(va: f64, vb: f64, take_a: bool) -> Option<bool> {
    if va.is_nan() || vb.is_nan() {
        None
    } else {
        Some(take_a)
    }
}

/// The smaller of `a` and `b` (`a` on ties, NaN if either is NaN); the gradient is the
/// chosen one's. Built by [`FieldExt::min`](super::FieldExt::min).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Min<A, B> {
    /// First field.
    pub a: A,
    /// Second field.
    pub b: B,
}

impl<A: Field, B: Field> Min<A, B> {
    /// `min(a, b)`.
    pub fn new(a: A, b: B) -> Self {
        Min { a, b }
    }
}

impl<A: Field, B: Field> Field for Min<A, B> {
    fn sample(&self, p: DVec2) -> f64 {
        let (va, vb) = (self.a.sample(p), self.b.sample(p));
        match pick(va, vb, va <= vb) {
            Some(true) => va,
            Some(false) => vb,
            None => f64::NAN,
        }
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.sample_with_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (va, vb) = (self.a.sample(p), self.b.sample(p));
        match pick(va, vb, va <= vb) {
            Some(true) => (va, self.a.gradient(p)),
            Some(false) => (vb, self.b.gradient(p)),
            None => (f64::NAN, DVec2::NAN),
        }
    }
}

/// The larger of `a` and `b` (`a` on ties, NaN if either is NaN); the gradient is the
/// chosen one's. Built by [`FieldExt::max`](super::FieldExt::max).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Max<A, B> {
    /// First field.
    pub a: A,
    /// Second field.
    pub b: B,
}

impl<A: Field, B: Field> Max<A, B> {
    /// `max(a, b)`.
    pub fn new(a: A, b: B) -> Self {
        Max { a, b }
    }
}

impl<A: Field, B: Field> Field for Max<A, B> {
    fn sample(&self, p: DVec2) -> f64 {
        let (va, vb) = (self.a.sample(p), self.b.sample(p));
        match pick(va, vb, va >= vb) {
            Some(true) => va,
            Some(false) => vb,
            None => f64::NAN,
        }
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.sample_with_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (va, vb) = (self.a.sample(p), self.b.sample(p));
        match pick(va, vb, va >= vb) {
            Some(true) => (va, self.a.gradient(p)),
            Some(false) => (vb, self.b.gradient(p)),
            None => (f64::NAN, DVec2::NAN),
        }
    }
}

/// `field` limited to `[lo, hi]`; the gradient is zero where the value is clamped (strictly
/// outside the interval) and the field's inside it. Built by
/// [`FieldExt::clamped`](super::FieldExt::clamped).
///
/// Bounds given in the wrong order are swapped; a NaN bound is ignored (no limit on that
/// side). A NaN value stays NaN.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Clamp<F> {
    /// The field limited.
    pub field: F,
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
}

impl<F: Field> Clamp<F> {
    /// `field` limited to `[lo, hi]` (bounds in either order).
    pub fn new(field: F, lo: f64, hi: f64) -> Self {
        let (lo, hi) = if lo > hi { (hi, lo) } else { (lo, hi) };
        Clamp { field, lo, hi }
    }

    /// The clamped value, and whether it was clamped.
    fn limit(&self, v: f64) -> (f64, bool) {
        if v < self.lo {
            (self.lo, true)
        } else if v > self.hi {
            (self.hi, true)
        } else {
            (v, false)
        }
    }
}

impl<F: Field> Field for Clamp<F> {
    fn sample(&self, p: DVec2) -> f64 {
        self.limit(self.field.sample(p)).0
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.sample_with_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let v = self.field.sample(p);
        match self.limit(v) {
            (c, true) => (c, DVec2::ZERO),
            (c, false) => (c, self.field.gradient(p)),
        }
    }
}

/// Selection by a mask: `if_true` where `mask >= threshold`, else `if_false`; NaN where
/// the mask is NaN. Value and gradient are the selected field's. Built by
/// [`FieldExt::select`](super::FieldExt::select) (threshold 0.5).
///
/// Typical use: a zoning map choosing between two height maps.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Mask<M, T, E> {
    /// The selecting field.
    pub mask: M,
    /// Used where `mask >= threshold`.
    pub if_true: T,
    /// Used where `mask < threshold`.
    pub if_false: E,
    /// The mask level at and above which `if_true` is used. [`Mask::new`] sets 0.5.
    pub threshold: f64,
}

impl<M: Field, T: Field, E: Field> Mask<M, T, E> {
    /// `if_true` where `mask >= 0.5`, else `if_false`.
    pub fn new(mask: M, if_true: T, if_false: E) -> Self {
        Mask {
            mask,
            if_true,
            if_false,
            threshold: 0.5,
        }
    }

    /// The same selection with another threshold.
    pub fn with_threshold(self, threshold: f64) -> Self {
        Mask { threshold, ..self }
    }

    fn choose(&self, p: DVec2) -> Option<bool> {
        let m = self.mask.sample(p);
        if m.is_nan() {
            None
        } else {
            Some(m >= self.threshold)
        }
    }
}

impl<M: Field, T: Field, E: Field> Field for Mask<M, T, E> {
    fn sample(&self, p: DVec2) -> f64 {
        match self.choose(p) {
            Some(true) => self.if_true.sample(p),
            Some(false) => self.if_false.sample(p),
            None => f64::NAN,
        }
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        match self.choose(p) {
            Some(true) => self.if_true.gradient(p),
            Some(false) => self.if_false.gradient(p),
            None => DVec2::NAN,
        }
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        match self.choose(p) {
            Some(true) => self.if_true.sample_with_gradient(p),
            Some(false) => self.if_false.sample_with_gradient(p),
            None => (f64::NAN, DVec2::NAN),
        }
    }
}

/// Linear blend by a weight map: `(1 − w)·zero + w·one` with `w = weight` clamped to
/// `[0, 1]`; exact gradient (the weight's gradient counts only where `0 < weight < 1`).
/// Built by [`FieldExt::blend`](super::FieldExt::blend).
///
/// Typical use: Parish & Müller §3.2.2 blend street-pattern rules by grey-scale control
/// maps; the same idea blends any two maps.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Blend<W, A, B> {
    /// The weight (0 → `zero`, 1 → `one`).
    pub weight: W,
    /// The field at weight 0.
    pub zero: A,
    /// The field at weight 1.
    pub one: B,
}

impl<W: Field, A: Field, B: Field> Blend<W, A, B> {
    /// `(1 − w)·zero + w·one`.
    pub fn new(weight: W, zero: A, one: B) -> Self {
        Blend { weight, zero, one }
    }
}

impl<W: Field, A: Field, B: Field> Field for Blend<W, A, B> {
    fn sample(&self, p: DVec2) -> f64 {
        let w = self.weight.sample(p);
        if w.is_nan() {
            return f64::NAN;
        }
        let w = w.clamp(0.0, 1.0);
        let a = self.zero.sample(p);
        let b = self.one.sample(p);
        a + (b - a) * w
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.sample_with_gradient(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (w, gw) = self.weight.sample_with_gradient(p);
        if w.is_nan() {
            return (f64::NAN, DVec2::NAN);
        }
        let inside = w > 0.0 && w < 1.0;
        let w = w.clamp(0.0, 1.0);
        let (a, ga) = self.zero.sample_with_gradient(p);
        let (b, gb) = self.one.sample_with_gradient(p);
        let mut g = ga + (gb - ga) * w;
        if inside {
            g += gw * (b - a);
        }
        (a + (b - a) * w, g)
    }
}

/// The field read at a transformed point: `sample(p) = field(p ⊙ scale + offset)`
/// (component-wise product); gradient `scale ⊙ ∇field`. Built by
/// [`FieldExt::translated`](super::FieldExt::translated),
/// [`FieldExt::magnified`](super::FieldExt::magnified) and
/// [`FieldExt::transformed`](super::FieldExt::transformed).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DomainTransform<F> {
    /// The field read.
    pub field: F,
    /// Component-wise factor on the point (inner units per metre).
    pub scale: DVec2,
    /// Added after scaling, in the inner field's units.
    pub offset: DVec2,
}

impl<F: Field> DomainTransform<F> {
    /// `sample(p) = field(p ⊙ scale + offset)`.
    pub fn new(field: F, scale: DVec2, offset: DVec2) -> Self {
        DomainTransform {
            field,
            scale,
            offset,
        }
    }
}

impl<F: Field> Field for DomainTransform<F> {
    fn sample(&self, p: DVec2) -> f64 {
        self.field.sample(p * self.scale + self.offset)
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.field.gradient(p * self.scale + self.offset) * self.scale
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        let (v, g) = self
            .field
            .sample_with_gradient(p * self.scale + self.offset);
        (v, g * self.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::{Constant, FieldExt, FnField, central_difference};

    /// `x` and `y` as fields, with exact gradients (1, 0) and (0, 1) by central differences.
    fn x() -> FnField<fn(DVec2) -> f64> {
        FnField(|p| p.x)
    }
    fn y() -> FnField<fn(DVec2) -> f64> {
        FnField(|p| p.y)
    }

    const P: DVec2 = DVec2::new(3.0, -2.0);

    fn close(a: DVec2, b: DVec2) -> bool {
        (a - b).length() < 1e-9
    }

    #[test]
    fn arithmetic() {
        let f = x().scaled(2.0).offset(1.0);
        assert_eq!(f.sample(P), 7.0);
        assert!(close(f.gradient(P), DVec2::new(2.0, 0.0)));
        let s = x().plus(y());
        assert_eq!(s.sample(P), 1.0);
        assert!(close(s.gradient(P), DVec2::ONE));
        let m = x().times(y());
        assert_eq!(m.sample(P), -6.0);
        // ∇(xy) = (y, x)
        assert!(close(m.gradient(P), DVec2::new(-2.0, 3.0)));
        let (v, g) = m.sample_with_gradient(P);
        assert_eq!(v, -6.0);
        assert!(close(g, m.gradient(P)));
    }

    #[test]
    fn threshold_is_greater_or_equal() {
        let t = x().threshold(3.0);
        assert_eq!(t.sample(DVec2::new(3.0, 0.0)), 1.0);
        assert_eq!(t.sample(DVec2::new(2.999, 0.0)), 0.0);
        assert_eq!(t.sample(DVec2::new(1e9, 0.0)), 1.0);
        assert_eq!(t.gradient(P), DVec2::ZERO);
        assert!(t.sample(DVec2::new(f64::NAN, 0.0)).is_nan());
        assert!(t.gradient(DVec2::new(f64::NAN, 0.0)).is_nan());
    }

    #[test]
    fn min_max_pick_and_propagate_nan() {
        let lo = x().min(y());
        let hi = x().max(y());
        assert_eq!(lo.sample(P), -2.0);
        assert_eq!(hi.sample(P), 3.0);
        assert!(close(lo.gradient(P), DVec2::new(0.0, 1.0)));
        assert!(close(hi.gradient(P), DVec2::new(1.0, 0.0)));
        // Ties pick `a`.
        let tie = DVec2::new(1.0, 1.0);
        assert!(close(lo.gradient(tie), DVec2::new(1.0, 0.0)));
        assert!(close(hi.gradient(tie), DVec2::new(1.0, 0.0)));
        let nan = Constant(f64::NAN);
        assert!(x().min(nan).sample(P).is_nan());
        assert!(nan.max(x()).sample(P).is_nan());
        assert!(nan.max(x()).gradient(P).is_nan());
    }

    #[test]
    fn clamp_semantics() {
        let c = x().clamped(5.0, -1.0); // swapped
        assert_eq!((c.lo, c.hi), (-1.0, 5.0));
        assert_eq!(c.sample(DVec2::new(7.0, 0.0)), 5.0);
        assert_eq!(c.sample(DVec2::new(-7.0, 0.0)), -1.0);
        assert_eq!(c.sample(P), 3.0);
        assert_eq!(c.gradient(DVec2::new(7.0, 0.0)), DVec2::ZERO);
        assert!(close(c.gradient(P), DVec2::new(1.0, 0.0)));
        let open = x().clamped(f64::NAN, 1.0);
        assert_eq!(open.sample(DVec2::new(-1e9, 0.0)), -1e9);
        assert_eq!(open.sample(DVec2::new(1e9, 0.0)), 1.0);
        assert!(c.sample(DVec2::new(f64::NAN, 0.0)).is_nan());
    }

    #[test]
    fn mask_selects() {
        let m = x().threshold(0.0).select(Constant(10.0), y());
        assert_eq!(m.sample(P), 10.0);
        assert_eq!(m.gradient(P), DVec2::ZERO);
        let q = DVec2::new(-1.0, 4.0);
        assert_eq!(m.sample(q), 4.0);
        assert!(close(m.gradient(q), DVec2::new(0.0, 1.0)));
        // The raw mask with a custom threshold: x >= 3 is "true".
        let raw = Mask::new(x(), Constant(1.0), Constant(2.0)).with_threshold(3.0);
        assert_eq!(raw.sample(P), 1.0);
        assert_eq!(raw.sample(DVec2::new(2.5, 0.0)), 2.0);
        assert!(raw.sample(DVec2::new(f64::NAN, 0.0)).is_nan());
        assert!(
            raw.sample_with_gradient(DVec2::new(f64::NAN, 0.0))
                .1
                .is_nan()
        );
    }

    #[test]
    fn blend_weights_and_gradient() {
        let w = x().scaled(0.1); // 0.3 at P
        let b = w.blend(Constant(0.0), y()); // 0.1·x·y inside
        assert!((b.sample(P) - 0.3 * -2.0).abs() < 1e-12);
        let numeric = central_difference(&b, P, 1e-4);
        assert!((b.gradient(P) - numeric).length() < 1e-6);
        // Outside [0, 1] the weight is clamped and its gradient ignored.
        let far = DVec2::new(50.0, 2.0);
        assert_eq!(b.sample(far), 2.0);
        assert!(close(b.gradient(far), DVec2::new(0.0, 1.0)));
        assert!(
            Constant(f64::NAN)
                .blend(Constant(0.0), Constant(1.0))
                .sample(P)
                .is_nan()
        );
    }

    #[test]
    fn domain_transform() {
        let f = x().plus(y().scaled(10.0));
        let moved = f.translated(DVec2::new(1.0, 1.0));
        assert_eq!(moved.sample(P), f.sample(P - DVec2::ONE));
        let big = f.magnified(4.0);
        assert_eq!(big.sample(P * 4.0), f.sample(P));
        assert!(close(big.gradient(P), DVec2::new(0.25, 2.5)));
        let t = f.transformed(DVec2::new(2.0, -1.0), DVec2::new(0.5, 0.0));
        assert_eq!(t.sample(P), f.sample(DVec2::new(6.5, 2.0)));
        assert!(close(t.gradient(P), DVec2::new(2.0, -10.0)));
        // Degenerate magnification: NaN/inf values, no panic.
        let zero = f.magnified(0.0);
        let _ = zero.sample(P);
        assert!(zero.sample(DVec2::ZERO).is_nan());
    }

    #[test]
    fn serde_of_data_combinators() {
        let f = Constant(0.25).scaled(2.0).offset(1.0).clamped(0.0, 1.2);
        let json = serde_json::to_string(&f).unwrap();
        let back: Clamp<Offset<Scaled<Constant>>> = serde_json::from_str(&json).unwrap();
        assert_eq!(back, f);
        assert_eq!(back.sample(P), 1.2);
    }
}
