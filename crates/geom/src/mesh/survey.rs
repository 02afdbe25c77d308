//! A mesh's checks ([`Mesh::validate`]) and, from the same pass over its vertices and
//! triangles, what a writer wants to know before it copies the mesh ([`Mesh::survey`]):
//! its bounding box and whether it is already one tile's cut. A scene surveys all its
//! meshes at once ([`Scene::survey`](crate::scene::Scene::survey)).
//!
//! Why a pass and not a box stored with the mesh: [`Mesh`]'s arrays and
//! [`Scene::meshes`](crate::scene::Scene::meshes) are public, so a stored box could be
//! made stale by any caller; a survey is taken from the arrays it describes while they
//! are borrowed, and a writer that validates the scene anyway gets it for the cost of a
//! few comparisons per vertex and triangle already in registers.

use glam::Vec3A;

use super::{
    Aabb3, Mesh, NORMAL_LENGTH_TOLERANCE, TileIndex, invalid_vertex, tile_of, triangle_in_range,
};
use crate::GeomError;

/// What one validating pass learned about a valid mesh ([`Mesh::survey`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshSurvey {
    /// The box of the positions, to the bit what [`Mesh::bbox`] gives.
    pub bounds: Aabb3,
    /// The smallest and largest corner sums `a + b + c` of the triangles (three times
    /// their centroids), per coordinate, added as [`Mesh::whole_tile`] adds them.
    corner_sums: (Vec3A, Vec3A),
    /// Every corner sum finite (a sum of finite corners can overflow).
    sums_finite: bool,
    /// Every vertex used, numbered in first-use order.
    first_use_order: bool,
    /// The mesh has a triangle.
    triangles: bool,
}

impl MeshSurvey {
    /// What [`Mesh::whole_tile`] gives for the surveyed mesh and side `size`, without
    /// reading the mesh again.
    pub fn whole_tile(&self, size: f64) -> Option<TileIndex> {
        if size.is_nan() || size <= 0.0 || !self.triangles {
            return None;
        }
        if !self.first_use_order || !self.sums_finite {
            return None;
        }
        let (lo, hi) = self.corner_sums;
        let tile = tile_of(lo.x / 3.0, lo.z / 3.0, size);
        (tile_of(hi.x / 3.0, hi.z / 3.0, size) == tile).then_some(tile)
    }
}

impl Mesh {
    /// Checks the mesh as [`validate`](Self::validate) does (the same first problem
    /// reported) and returns its [`MeshSurvey`]: its box and its tile facts, gathered
    /// in the same pass.
    pub fn survey(&self) -> Result<MeshSurvey, GeomError> {
        self.check::<true>()
    }

    /// The checks of [`validate`](Self::validate); with `SURVEY`, also the survey
    /// (else a survey of nothing, never read).
    pub(super) fn check<const SURVEY: bool>(&self) -> Result<MeshSurvey, GeomError> {
        let n = self.positions.len();
        if self.normals.len() != n {
            return Err(GeomError::MeshAttributeLength {
                attribute: "normals",
                len: self.normals.len(),
                expected: n,
            });
        }
        if self.uvs.len() != n {
            return Err(GeomError::MeshAttributeLength {
                attribute: "uvs",
                len: self.uvs.len(),
                expected: n,
            });
        }
        if !self.indices.len().is_multiple_of(3) {
            return Err(GeomError::MeshIndexCount {
                len: self.indices.len(),
            });
        }
        // The box as `bbox` takes it: four lanes, positions in order.
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for (i, ((p, nrm), uv)) in self
            .positions
            .iter()
            .zip(&self.normals)
            .zip(&self.uvs)
            .enumerate()
        {
            if !p.is_finite() {
                return Err(invalid_vertex("position", i, "not finite"));
            }
            if !nrm.is_finite() {
                return Err(invalid_vertex("normal", i, "not finite"));
            }
            if (nrm.length() - 1.0).abs() > NORMAL_LENGTH_TOLERANCE {
                return Err(invalid_vertex("normal", i, "not of unit length"));
            }
            if !uv.is_finite() {
                return Err(invalid_vertex("uv", i, "not finite"));
            }
            if SURVEY {
                let p = Vec3A::from(*p);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        // The tile facts as `whole_tile` gathers them: first-use order as "every index
        // at most the next new number", the corner sums' extremes on four lanes and
        // their finiteness as a running total of `sum × 0`.
        let mut next = 0usize;
        let mut ordered = true;
        let (mut sum_lo, mut sum_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let mut nonfinite = Vec3A::ZERO;
        for (t, tri) in self.triangles().enumerate() {
            triangle_in_range(t, tri, n)?;
            let [a, b, c] = tri.map(|i| self.positions[i as usize]);
            if super::triangle_is_degenerate(a, b, c) {
                return Err(GeomError::DegenerateTriangle { triangle: t });
            }
            if SURVEY {
                for i in tri {
                    let i = i as usize;
                    ordered &= i <= next;
                    next = next.max(i + 1);
                }
                let sum = Vec3A::from(a) + Vec3A::from(b) + Vec3A::from(c);
                nonfinite += sum * 0.0;
                sum_lo = sum_lo.min(sum);
                sum_hi = sum_hi.max(sum);
            }
        }
        Ok(MeshSurvey {
            bounds: Aabb3 {
                min: lo.into(),
                max: hi.into(),
            },
            corner_sums: (sum_lo, sum_hi),
            sums_finite: nonfinite.is_finite(),
            first_use_order: ordered && next == n,
            triangles: !self.indices.is_empty(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DVec2, DVec3, Vec3};
    use proptest::prelude::*;

    /// A grid of `w × h` quads over `[x0, x0 + w·step] × [z0, z0 + h·step]`, its heights
    /// and its vertex order from `seed` (shuffled when `shuffle`), −0 among the
    /// coordinates.
    fn grid(seed: u64, w: usize, h: usize, (x0, z0): (f64, f64), step: f64, shuffle: bool) -> Mesh {
        let mut m = Mesh::new(None);
        let mut ids = Vec::new();
        for j in 0..=h {
            for i in 0..=w {
                let k = (j * (w + 1) + i) as u64;
                let y = (crate::hash::splitmix64(seed ^ k) % 7) as f64 * 0.25;
                let x = x0 + i as f64 * step;
                let x = if x == 0.0 { -0.0 } else { x };
                ids.push(m.add_vertex(
                    DVec3::new(x, y, z0 + j as f64 * step),
                    DVec3::Y,
                    DVec2::ZERO,
                ));
            }
        }
        for j in 0..h {
            for i in 0..w {
                let v = |di: usize, dj: usize| ids[(j + dj) * (w + 1) + i + di];
                let _ = m.push_triangle(v(0, 0), v(0, 1), v(1, 0));
                let _ = m.push_triangle(v(1, 0), v(0, 1), v(1, 1));
            }
        }
        if shuffle && m.indices.len() >= 6 {
            // Swap the first two triangles: first-use order broken.
            let (a, b) = m.indices.split_at_mut(3);
            a.swap_with_slice(&mut b[..3]);
        }
        m
    }

    #[test]
    fn a_survey_reports_what_validate_reports() {
        let mut m = grid(1, 2, 2, (0.0, 0.0), 1.0, false);
        m.normals[3] = Vec3::X * 2.0;
        assert_eq!(m.survey().err(), m.validate().err());
        let mut m = grid(1, 2, 2, (0.0, 0.0), 1.0, false);
        m.indices[4] = 99;
        assert_eq!(m.survey().err(), m.validate().err());
        let empty = Mesh::new(None).survey().unwrap();
        assert_eq!(empty.bounds, Mesh::new(None).bbox());
        assert_eq!(empty.whole_tile(10.0), None);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]
        /// The survey's box is `bbox` to the bit and its tile is `whole_tile`'s, for
        /// grids in one tile and across tile lines, cut into tiles or not, in first-use
        /// order or not, for several sides (one not positive).
        #[test]
        fn a_survey_gives_bbox_and_whole_tile(
            seed in any::<u64>(),
            w in 1usize..6,
            h in 1usize..6,
            x0 in -40.0f64..40.0,
            z0 in -40.0f64..40.0,
            step in prop_oneof![Just(0.5), Just(1.0), Just(3.25), Just(7.0)],
            shuffle in any::<bool>(),
            cut in any::<bool>(),
        ) {
            let m = grid(seed, w, h, (x0.round(), z0), step, shuffle);
            let meshes: Vec<Mesh> = if cut {
                m.cut_into_tiles(10.0).into_iter().map(|(_, part, _)| part).collect()
            } else {
                vec![m]
            };
            for m in meshes {
                let s = m.survey();
                prop_assert_eq!(s.is_ok(), m.validate().is_ok());
                let Ok(s) = s else { continue };
                let (b, e) = (s.bounds, m.bbox());
                prop_assert_eq!(
                    (b.min.to_array().map(f32::to_bits), b.max.to_array().map(f32::to_bits)),
                    (e.min.to_array().map(f32::to_bits), e.max.to_array().map(f32::to_bits))
                );
                for size in [10.0, 4.0, 100.0, 0.0] {
                    prop_assert_eq!(s.whole_tile(size), m.whole_tile(size));
                }
            }
        }
    }
}
