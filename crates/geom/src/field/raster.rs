//! Grid fields: an `f32` image laid over a world-space box, sampled bilinearly.

use glam::DVec2;

use super::Field;
use crate::{Aabb2, GeomError};

/// An `f32` grid over a world-space rectangle, sampled bilinearly: the image maps of
/// Parish & Müller §2 (population, water, parks, elevation, zoning, pattern weights).
///
/// **Layout.** `data[row * width + col]`, rows from the top (largest `y`) down, like an
/// image: texel `(col, row)` covers `[min.x + col·tx, min.x + (col+1)·tx] ×
/// [max.y − (row+1)·ty, max.y − row·ty]` with `tx = extent width / width` and
/// `ty = extent height / height`, and its value sits at the texel's centre
/// ([`texel_center`](Self::texel_center)).
///
/// **Sampling.** Bilinear between the four nearest texel centres; exact at texel centres.
/// Outside the centres' hull the edge value is held (*clamp to edge*), also for points far
/// outside the extent and infinite points. A point with a NaN coordinate samples to NaN.
///
/// **Gradient** (per metre): exact derivative of the bilinear patch containing the point;
/// along an axis where the point is clamped it is zero. On a texel-centre line (where the
/// bilinear surface has a kink) it is the derivative of the patch to the right / below.
///
/// Serialises as `{ width, height, extent, data }` and is validated on deserialisation.
///
/// ```
/// use polis_geom::{Aabb2, DVec2};
/// use polis_geom::field::{Field, Raster};
///
/// // 2 × 1 texels over a 20 m × 10 m box: 0 on the left, 1 on the right.
/// let extent = Aabb2::new(DVec2::new(0.0, 0.0), DVec2::new(20.0, 10.0));
/// let r = Raster::new(2, 1, extent, vec![0.0, 1.0])?;
/// assert_eq!(r.sample(DVec2::new(5.0, 5.0)), 0.0); // centre of the left texel
/// assert_eq!(r.sample(DVec2::new(10.0, 5.0)), 0.5); // halfway between the centres
/// assert_eq!(r.sample(DVec2::new(-100.0, 5.0)), 0.0); // clamped to the edge
/// assert_eq!(r.gradient(DVec2::new(10.0, 5.0)), DVec2::new(0.1, 0.0)); // 1 per 10 m
/// # Ok::<(), polis_geom::GeomError>(())
/// ```
#[derive(Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "RasterData", into = "RasterData"))]
pub struct Raster {
    width: usize,
    height: usize,
    extent: Aabb2,
    data: Vec<f32>,
    /// Texel size in metres.
    texel: DVec2,
}

/// The serialised form of [`Raster`].
#[derive(Clone)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct RasterData {
    width: usize,
    height: usize,
    extent: Aabb2,
    data: Vec<f32>,
}

impl TryFrom<RasterData> for Raster {
    type Error = GeomError;
    fn try_from(d: RasterData) -> Result<Self, GeomError> {
        Raster::new(d.width, d.height, d.extent, d.data)
    }
}

impl From<Raster> for RasterData {
    fn from(r: Raster) -> Self {
        RasterData {
            width: r.width,
            height: r.height,
            extent: r.extent,
            data: r.data,
        }
    }
}

impl std::fmt::Debug for Raster {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Raster")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("extent", &self.extent)
            .finish_non_exhaustive()
    }
}

/// Checks that `extent` is finite and has positive width and height.
fn validate_extent(extent: &Aabb2) -> Result<(), GeomError> {
    let ok = extent.min.is_finite()
        && extent.max.is_finite()
        && extent.max.x > extent.min.x
        && extent.max.y > extent.min.y;
    if ok {
        Ok(())
    } else {
        Err(GeomError::InvalidParameter {
            name: "extent",
            reason: format!(
                "the raster extent {:?}–{:?} must be finite with positive width and height",
                extent.min, extent.max
            ),
        })
    }
}

/// Where a coordinate falls along one axis of `n` texel centres: first texel index of the
/// patch, fraction inside the patch, and whether the coordinate is inside (not clamped).
#[inline]
fn axis(t: f64, n: usize) -> (usize, f64, bool) {
    if n < 2 {
        return (0, 0.0, false);
    }
    let last = (n - 1) as f64;
    let tc = t.clamp(0.0, last);
    let i0 = (tc.floor() as usize).min(n - 2);
    (i0, tc - i0 as f64, (0.0..=last).contains(&t))
}

impl Raster {
    /// A raster of `width × height` texels over `extent` with `data` in row-major order
    /// (row 0 at the top).
    ///
    /// Errors: [`GeomError::InvalidParameter`] for a zero width or height, an extent that is
    /// not finite or has no area, or a non-finite value; [`GeomError::RasterSize`] when
    /// `data.len() != width * height`.
    pub fn new(
        width: usize,
        height: usize,
        extent: Aabb2,
        data: Vec<f32>,
    ) -> Result<Self, GeomError> {
        if width == 0 || height == 0 {
            return Err(GeomError::InvalidParameter {
                name: if width == 0 { "width" } else { "height" },
                reason: format!(
                    "a raster of {width} × {height} texels is empty; both must be at least 1"
                ),
            });
        }
        if width.checked_mul(height) != Some(data.len()) {
            return Err(GeomError::RasterSize {
                width,
                height,
                len: data.len(),
            });
        }
        validate_extent(&extent)?;
        let texel = DVec2::new(
            (extent.max.x - extent.min.x) / width as f64,
            (extent.max.y - extent.min.y) / height as f64,
        );
        if !(texel.is_finite() && texel.x > 0.0 && texel.y > 0.0) {
            return Err(GeomError::InvalidParameter {
                name: "extent",
                reason: format!(
                    "texels of {texel} m are degenerate; use a larger extent or fewer texels"
                ),
            });
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return Err(GeomError::InvalidParameter {
                name: "data",
                reason: format!(
                    "texel {} (column {}, row {}) is {}; raster values must be finite",
                    i,
                    i % width,
                    i / width,
                    data.get(i).copied().unwrap_or(f32::NAN)
                ),
            });
        }
        Ok(Raster {
            width,
            height,
            extent,
            data,
            texel,
        })
    }

    /// A raster whose texel `(col, row)` has the value `f(col, row)`.
    pub fn from_fn(
        width: usize,
        height: usize,
        extent: Aabb2,
        mut f: impl FnMut(usize, usize) -> f32,
    ) -> Result<Self, GeomError> {
        let len = width.checked_mul(height).ok_or(GeomError::RasterSize {
            width,
            height,
            len: 0,
        })?;
        let mut data = Vec::with_capacity(len);
        for row in 0..height {
            for col in 0..width {
                data.push(f(col, row));
            }
        }
        Raster::new(width, height, extent, data)
    }

    /// Bakes `field` into a raster by sampling it at every texel centre (values rounded to
    /// `f32`). Errors as [`new`](Self::new), including for non-finite samples.
    pub fn from_field<F: Field + ?Sized>(
        field: &F,
        width: usize,
        height: usize,
        extent: Aabb2,
    ) -> Result<Self, GeomError> {
        validate_extent(&extent)?;
        let tx = (extent.max.x - extent.min.x) / width.max(1) as f64;
        let ty = (extent.max.y - extent.min.y) / height.max(1) as f64;
        Raster::from_fn(width, height, extent, |col, row| {
            let p = DVec2::new(
                extent.min.x + (col as f64 + 0.5) * tx,
                extent.max.y - (row as f64 + 0.5) * ty,
            );
            field.sample(p) as f32
        })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The world-space rectangle the raster covers, in metres.
    pub fn extent(&self) -> Aabb2 {
        self.extent
    }

    /// The size of one texel in metres.
    pub fn texel_size(&self) -> DVec2 {
        self.texel
    }

    /// The values, row-major, row 0 at the top.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The value of texel `(col, row)`, or `None` outside the grid.
    pub fn get(&self, col: usize, row: usize) -> Option<f32> {
        if col < self.width && row < self.height {
            self.data.get(row * self.width + col).copied()
        } else {
            None
        }
    }

    /// The world position of texel `(col, row)`'s centre (also for indices outside the grid).
    pub fn texel_center(&self, col: usize, row: usize) -> DVec2 {
        DVec2::new(
            self.extent.min.x + (col as f64 + 0.5) * self.texel.x,
            self.extent.max.y - (row as f64 + 0.5) * self.texel.y,
        )
    }

    #[inline]
    fn at(&self, col: usize, row: usize) -> f64 {
        f64::from(
            self.data
                .get(row * self.width + col)
                .copied()
                .unwrap_or(f32::NAN),
        )
    }

    /// Bilinear value and exact gradient at `p`.
    fn bilinear(&self, p: DVec2) -> (f64, DVec2) {
        // Continuous texel coordinates: integer values at texel centres.
        let u = (p.x - self.extent.min.x) / self.texel.x - 0.5;
        let v = (self.extent.max.y - p.y) / self.texel.y - 0.5;
        if u.is_nan() || v.is_nan() {
            return (f64::NAN, DVec2::NAN);
        }
        let (c0, fu, inside_u) = axis(u, self.width);
        let (r0, fv, inside_v) = axis(v, self.height);
        let c1 = (c0 + 1).min(self.width - 1);
        let r1 = (r0 + 1).min(self.height - 1);
        let a = self.at(c0, r0);
        let b = self.at(c1, r0);
        let c = self.at(c0, r1);
        let d = self.at(c1, r1);
        let top = a + (b - a) * fu;
        let bottom = c + (d - c) * fu;
        let value = top + (bottom - top) * fv;
        let dvalue_du = if inside_u {
            (b - a) + ((d - c) - (b - a)) * fv
        } else {
            0.0
        };
        let dvalue_dv = if inside_v { bottom - top } else { 0.0 };
        let gradient = DVec2::new(dvalue_du / self.texel.x, -dvalue_dv / self.texel.y);
        (value, gradient)
    }
}

impl Field for Raster {
    fn sample(&self, p: DVec2) -> f64 {
        self.bilinear(p).0
    }
    fn gradient(&self, p: DVec2) -> DVec2 {
        self.bilinear(p).1
    }
    fn sample_with_gradient(&self, p: DVec2) -> (f64, DVec2) {
        self.bilinear(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::central_difference;

    fn extent() -> Aabb2 {
        Aabb2::new(DVec2::new(-64.0, 0.0), DVec2::new(64.0, 32.0))
    }

    fn sample_raster() -> Raster {
        // 8 × 4 texels of 16 m × 8 m.
        Raster::from_fn(8, 4, extent(), |c, r| {
            (c * c) as f32 * 0.25 - r as f32 * 1.5
        })
        .unwrap()
    }

    #[test]
    fn exact_at_texel_centres() {
        let r = sample_raster();
        assert_eq!(r.texel_size(), DVec2::new(16.0, 8.0));
        for row in 0..4 {
            for col in 0..8 {
                let p = r.texel_center(col, row);
                assert_eq!(
                    r.sample(p),
                    f64::from(r.get(col, row).unwrap()),
                    "{col},{row}"
                );
            }
        }
        // Row 0 is at the top.
        assert_eq!(r.texel_center(0, 0), DVec2::new(-56.0, 28.0));
        assert_eq!(r.get(8, 0), None);
        assert_eq!(r.get(0, 4), None);
    }

    #[test]
    fn bilinear_between_centres() {
        let r = sample_raster();
        let a = r.texel_center(2, 1);
        let d = r.texel_center(3, 2);
        let (va, vb, vc, vd) = (
            f64::from(r.get(2, 1).unwrap()),
            f64::from(r.get(3, 1).unwrap()),
            f64::from(r.get(2, 2).unwrap()),
            f64::from(r.get(3, 2).unwrap()),
        );
        let p = a + (d - a) * DVec2::new(0.25, 0.5);
        let expected = (va * 0.75 + vb * 0.25) * 0.5 + (vc * 0.75 + vd * 0.25) * 0.5;
        assert!((r.sample(p) - expected).abs() < 1e-12);
        // Midpoint of an edge between two centres is their average.
        let m = (r.texel_center(4, 0) + r.texel_center(5, 0)) * 0.5;
        let avg = (f64::from(r.get(4, 0).unwrap()) + f64::from(r.get(5, 0).unwrap())) / 2.0;
        assert_eq!(r.sample(m), avg);
    }

    #[test]
    fn clamp_to_edge_and_non_finite_points() {
        let r = sample_raster();
        let corner = f64::from(r.get(7, 3).unwrap());
        assert_eq!(r.sample(DVec2::new(1e9, -1e9)), corner);
        assert_eq!(
            r.sample(DVec2::new(f64::INFINITY, f64::NEG_INFINITY)),
            corner
        );
        assert_eq!(r.gradient(DVec2::new(1e9, -1e9)), DVec2::ZERO);
        let top_left = f64::from(r.get(0, 0).unwrap());
        assert_eq!(r.sample(DVec2::new(-1e300, 1e300)), top_left);
        // Clamped along x only: the gradient keeps its y part.
        let g = r.gradient(DVec2::new(-1000.0, 10.0));
        assert_eq!(g.x, 0.0);
        assert!((g.y - 1.5 / 8.0).abs() < 1e-12);
        assert!(r.sample(DVec2::new(f64::NAN, 0.0)).is_nan());
        assert!(r.gradient(DVec2::new(0.0, f64::NAN)).is_nan());
    }

    #[test]
    fn gradient_matches_central_differences_inside_patches() {
        let r = sample_raster();
        for i in 0..40 {
            for j in 0..20 {
                // Avoid texel-centre lines, where the surface has a kink.
                let p = DVec2::new(-55.0 + i as f64 * 2.77, 4.5 + j as f64 * 1.13);
                let exact = r.gradient(p);
                let numeric = central_difference(&r, p, 1e-4);
                assert!(
                    (exact - numeric).length() < 1e-7,
                    "{exact} vs {numeric} at {p}"
                );
            }
        }
    }

    #[test]
    fn single_texel_and_single_row() {
        let one = Raster::new(1, 1, extent(), vec![3.5]).unwrap();
        assert_eq!(one.sample(DVec2::new(5.0, 5.0)), 3.5);
        assert_eq!(one.gradient(DVec2::new(5.0, 5.0)), DVec2::ZERO);
        let row = Raster::new(3, 1, extent(), vec![0.0, 3.0, 6.0]).unwrap();
        let mid = row.texel_center(1, 0);
        assert_eq!(row.sample(mid), 3.0);
        let g = row.gradient(mid + DVec2::new(1.0, 0.3));
        assert!((g.x - 3.0 / row.texel_size().x).abs() < 1e-12);
        assert_eq!(g.y, 0.0);
    }

    #[test]
    fn validation() {
        let e = extent();
        assert!(matches!(
            Raster::new(0, 2, e, vec![]),
            Err(GeomError::InvalidParameter { name: "width", .. })
        ));
        assert!(matches!(
            Raster::new(2, 0, e, vec![]),
            Err(GeomError::InvalidParameter { name: "height", .. })
        ));
        assert!(matches!(
            Raster::new(2, 2, e, vec![0.0; 3]),
            Err(GeomError::RasterSize {
                width: 2,
                height: 2,
                len: 3
            })
        ));
        assert!(matches!(
            Raster::new(usize::MAX, 2, e, vec![0.0; 3]),
            Err(GeomError::RasterSize { .. })
        ));
        for bad in [
            Aabb2::EMPTY,
            Aabb2::new(DVec2::ZERO, DVec2::new(0.0, 5.0)),
            Aabb2::new(DVec2::ZERO, DVec2::new(f64::INFINITY, 5.0)),
            Aabb2 {
                min: DVec2::new(f64::NAN, 0.0),
                max: DVec2::ONE,
            },
        ] {
            assert!(matches!(
                Raster::new(1, 1, bad, vec![0.0]),
                Err(GeomError::InvalidParameter { name: "extent", .. })
            ));
        }
        let err = Raster::new(2, 1, e, vec![0.0, f32::NAN]).unwrap_err();
        assert!(err.to_string().contains("column 1, row 0"), "{err}");
        assert!(Raster::from_fn(usize::MAX, 3, e, |_, _| 0.0).is_err());
    }

    #[test]
    fn bake_a_field_and_serde() {
        let plane = crate::field::FnField::new(|p: DVec2| 0.5 * p.x + 0.25 * p.y);
        let r = Raster::from_field(&plane, 16, 8, extent()).unwrap();
        // Bilinear interpolation reproduces a plane exactly (up to f32 storage).
        for p in [
            DVec2::new(-30.0, 11.0),
            DVec2::new(50.1, 20.7),
            DVec2::new(0.0, 16.0),
        ] {
            assert!((r.sample(p) - plane.sample(p)).abs() < 1e-4);
            assert!((r.gradient(p) - DVec2::new(0.5, 0.25)).length() < 1e-5);
        }
        let json = serde_json::to_string(&r).unwrap();
        let back: Raster = serde_json::from_str(&json).unwrap();
        assert_eq!(back, r);
        let broken = json.replace("\"width\":16", "\"width\":15");
        assert!(serde_json::from_str::<Raster>(&broken).is_err());
        assert!(format!("{r:?}").contains("width: 16"));
    }
}
