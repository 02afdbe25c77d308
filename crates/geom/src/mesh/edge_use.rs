//! The edge-use check: is a set of triangles one closed, 2-manifold, consistently wound,
//! outward solid — and if not, what fails.
//!
//! Vertices are welded by exact position (`f32` bits, `-0.0` = `+0.0`), so a surface
//! split into several meshes (one per material) or built from faces with their own
//! vertices (flat shading) is checked as the one surface it draws. Every undirected edge
//! is then counted:
//!
//! * used **once**: an *open* edge (a hole or a crack; its length is summed);
//! * used **three or more** times: a *non-manifold* edge (fins, solids glued edge to
//!   edge, duplicated faces);
//! * used **twice in the same direction**: the two triangles disagree about the winding
//!   (a *flipped* edge).
//!
//! A surface passes when no edge is open, non-manifold or flipped, no triangle is
//! degenerate, and the enclosed volume is positive (outward orientation). A mesh of
//! several solids (a bridge's deck and piers) is checked shell by shell:
//! [`EdgeUseReport::shell_volumes`] holds each edge-connected component's volume.
//! [`EdgeUseReport::flipped_triangles`] counts the triangles to reverse so every
//! component agrees (the smaller side of each component's orientation classes).
//!
//! # Guarantees
//! Deterministic: edges are reported in position order. Runs in `O(t log t)` for `t`
//! triangles. Indices out of range are counted as [`EdgeUseReport::bad_indices`], never
//! a panic.
//!
//! # Limitations
//! Edges, not vertices: two solids touching at one vertex pass. Self-intersections
//! (triangles crossing without sharing an edge) are not detected. Welding is exact: two
//! vertices a rounding step apart are different vertices, so a crack of `1e-7` m shows
//! as open edges (which is what a watertightness check in other tools reports too).

use glam::Vec3;

use super::Mesh;

/// One reported edge: its ends (welded positions, the lower first) and how many
/// triangles use it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReportedEdge {
    /// One end.
    pub a: Vec3,
    /// The other end.
    pub b: Vec3,
    /// Triangles that use it.
    pub uses: usize,
}

impl ReportedEdge {
    /// Its length in metres.
    pub fn length(&self) -> f64 {
        self.a.as_dvec3().distance(self.b.as_dvec3())
    }
}

/// What the edge-use check found (see the [module docs](self)).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EdgeUseReport {
    /// Triangles checked.
    pub triangles: usize,
    /// Distinct welded vertices.
    pub vertices: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Edges used by one triangle.
    pub open: Vec<ReportedEdge>,
    /// Total length of the open edges, metres.
    pub open_length: f64,
    /// Edges used by three or more triangles.
    pub non_manifold: Vec<ReportedEdge>,
    /// Edges used by two triangles in the same direction.
    pub flipped: Vec<ReportedEdge>,
    /// Triangles to reverse for a consistent winding: in each edge-connected component,
    /// the smaller of the two orientation classes.
    pub flipped_triangles: usize,
    /// Triangles whose welded corners repeat a vertex (zero area after welding).
    pub degenerate_triangles: usize,
    /// Triangles with an index that names no vertex (left out of everything else).
    pub bad_indices: usize,
    /// Edge-connected components of triangles (shells).
    pub components: usize,
    /// Signed volume, m³ (divergence theorem, `f64`): positive for an outward closed
    /// surface.
    pub signed_volume: f64,
    /// Signed volume of each component (shell), m³, in the order of each shell's first
    /// triangle: a mesh holding several solids (a bridge's deck and piers) is a set of
    /// outward solids when it is closed and every one of these is positive.
    pub shell_volumes: Vec<f64>,
}

impl EdgeUseReport {
    /// Whether every edge is used exactly twice in opposite directions and no triangle
    /// is degenerate or broken: a closed, 2-manifold, consistently wound surface.
    pub fn is_closed_manifold(&self) -> bool {
        self.open.is_empty()
            && self.non_manifold.is_empty()
            && self.flipped.is_empty()
            && self.degenerate_triangles == 0
            && self.bad_indices == 0
            && self.triangles > 0
    }

    /// [`is_closed_manifold`](Self::is_closed_manifold) with a positive volume: an
    /// outward solid.
    pub fn is_solid(&self) -> bool {
        self.is_closed_manifold() && self.signed_volume > 0.0
    }

    /// [`is_closed_manifold`](Self::is_closed_manifold) with a positive volume in every
    /// shell: each component an outward solid (an inside-out shell inside a larger one
    /// passes [`is_solid`](Self::is_solid), not this).
    pub fn is_solid_shells(&self) -> bool {
        self.is_closed_manifold() && self.shell_volumes.iter().all(|&v| v > 0.0)
    }
}

/// The welding key of a position: its bits, with `-0.0` made `+0.0`.
#[inline]
fn key(p: Vec3) -> [u32; 3] {
    (p + Vec3::ZERO).to_array().map(f32::to_bits)
}

/// Checks the triangles of all `meshes` together as one surface (see the
/// [module docs](self)).
pub fn edge_use<'a>(meshes: impl IntoIterator<Item = &'a Mesh>) -> EdgeUseReport {
    let meshes: Vec<&Mesh> = meshes.into_iter().collect();
    let mut report = EdgeUseReport::default();
    // Weld: every vertex of every mesh gets the rank of its position.
    let total: usize = meshes.iter().map(|m| m.positions.len()).sum();
    let mut all: Vec<([u32; 3], u32)> = Vec::with_capacity(total);
    for m in &meshes {
        for &p in &m.positions {
            all.push((key(p), all.len() as u32));
        }
    }
    all.sort_unstable();
    let mut canon = vec![0u32; total];
    let mut reps: Vec<Vec3> = Vec::new();
    for (k, &(kk, v)) in all.iter().enumerate() {
        if k == 0 || all[k - 1].0 != kk {
            reps.push(Vec3::from_array(kk.map(f32::from_bits)));
        }
        canon[v as usize] = reps.len() as u32 - 1;
    }
    report.vertices = reps.len();
    // Triangles as welded corners.
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut base = 0usize;
    for m in &meshes {
        let n = m.positions.len();
        for t in m.triangles() {
            report.triangles += 1;
            if t.iter().any(|&i| i as usize >= n) {
                report.bad_indices += 1;
                continue;
            }
            let c = t.map(|i| canon[base + i as usize]);
            if c[0] == c[1] || c[1] == c[2] || c[2] == c[0] {
                report.degenerate_triangles += 1;
                continue;
            }
            tris.push(c);
        }
        base += n;
    }
    // Volume in f64 about the first welded vertex.
    let origin = reps.first().map_or(glam::DVec3::ZERO, |p| p.as_dvec3());
    let sixes: Vec<f64> = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| reps[i as usize].as_dvec3() - origin);
            a.dot(b.cross(c))
        })
        .collect();
    report.signed_volume = sixes.iter().sum::<f64>() / 6.0;
    // Directed uses: (low, high, runs low → high, triangle).
    let mut uses: Vec<(u32, u32, bool, u32)> = Vec::with_capacity(3 * tris.len());
    for (ti, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            uses.push((a.min(b), a.max(b), a < b, ti as u32));
        }
    }
    uses.sort_unstable();
    // Orientation classes: union-find with parity (parity 1 = the two triangles must be
    // reversed relative to each other to agree).
    let mut parent: Vec<u32> = (0..tris.len() as u32).collect();
    let mut parity = vec![0u8; tris.len()];
    let edge = |a: u32, b: u32, n: usize| ReportedEdge {
        a: reps[a as usize],
        b: reps[b as usize],
        uses: n,
    };
    let mut k = 0;
    while k < uses.len() {
        let (a, b, _, _) = uses[k];
        let mut end = k + 1;
        while end < uses.len() && uses[end].0 == a && uses[end].1 == b {
            end += 1;
        }
        report.edges += 1;
        let n = end - k;
        match n {
            1 => {
                let e = edge(a, b, 1);
                report.open_length += e.length();
                report.open.push(e);
            }
            2 => {
                let same = uses[k].2 == uses[k + 1].2;
                if same {
                    report.flipped.push(edge(a, b, 2));
                }
                union(&mut parent, &mut parity, uses[k].3, uses[k + 1].3, same);
            }
            _ => {
                report.non_manifold.push(edge(a, b, n));
                // Non-manifold edges still connect their triangles into one shell.
                for j in k + 1..end {
                    union(&mut parent, &mut parity, uses[k].3, uses[j].3, false);
                }
            }
        }
        k = end;
    }
    // Per component, count triangles in each orientation class and sum the volume.
    let mut counts: Vec<[usize; 2]> = vec![[0, 0]; tris.len()];
    let mut shell_of_root = vec![u32::MAX; tris.len()];
    for (t, &six) in sixes.iter().enumerate() {
        let (root, p) = find(&mut parent, &mut parity, t as u32);
        counts[root as usize][p as usize] += 1;
        let shell = &mut shell_of_root[root as usize];
        if *shell == u32::MAX {
            *shell = report.shell_volumes.len() as u32;
            report.shell_volumes.push(0.0);
        }
        report.shell_volumes[*shell as usize] += six / 6.0;
    }
    for c in &counts {
        if c[0] + c[1] > 0 {
            report.components += 1;
            report.flipped_triangles += c[0].min(c[1]);
        }
    }
    report
}

/// The root of `x` and the parity of `x` relative to it (with path compression, in two
/// passes without allocating).
fn find(parent: &mut [u32], parity: &mut [u8], x: u32) -> (u32, u8) {
    // First pass: the root and x's parity to it.
    let (mut r, mut acc) = (x, 0u8);
    while parent[r as usize] != r {
        acc ^= parity[r as usize];
        r = parent[r as usize];
    }
    // Second pass: point every node of the path at the root with its own parity.
    let (mut v, mut p) = (x, acc);
    while parent[v as usize] != r && v != r {
        let (next, own) = (parent[v as usize], parity[v as usize]);
        parent[v as usize] = r;
        parity[v as usize] = p;
        p ^= own;
        v = next;
    }
    (r, acc)
}

/// Joins the classes of triangles `a` and `b`; `differ` says they have opposite
/// orientations (they run their shared edge the same way). A contradiction (a
/// non-orientable component) keeps the first relation.
fn union(parent: &mut [u32], parity: &mut [u8], a: u32, b: u32, differ: bool) {
    let (ra, pa) = find(parent, parity, a);
    let (rb, pb) = find(parent, parity, b);
    if ra != rb {
        parent[rb as usize] = ra;
        parity[rb as usize] = pa ^ pb ^ u8::from(differ);
    }
}

impl Mesh {
    /// The [edge-use check](self::edge_use) of this mesh alone.
    pub fn edge_use(&self) -> EdgeUseReport {
        edge_use([self])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{flat_polygon, prism};
    use crate::{DVec2, Polygon, PolygonWithHoles};
    use glam::{DMat4, DVec3};

    fn cube() -> Mesh {
        prism(
            &PolygonWithHoles::from(Polygon::rect(DVec2::ZERO, DVec2::ONE)),
            0.0,
            1.0,
            None,
        )
        .unwrap()
    }

    #[test]
    fn a_prism_is_an_outward_solid() {
        let r = cube().edge_use();
        assert!(r.is_solid(), "{r:?}");
        assert_eq!((r.vertices, r.edges, r.components), (8, 18, 1));
        assert!((r.signed_volume - 1.0).abs() < 1e-9);
        assert_eq!(r.flipped_triangles, 0);
    }

    #[test]
    fn a_removed_triangle_leaves_three_open_edges() {
        let mut m = cube();
        let tri: Vec<u32> = m.indices.drain(0..3).collect();
        let r = m.edge_use();
        assert!(!r.is_closed_manifold());
        assert_eq!(r.open.len(), 3);
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| m.positions[i as usize].as_dvec3());
        let perimeter = a.distance(b) + b.distance(c) + c.distance(a);
        assert!((r.open_length - perimeter).abs() < 1e-6);
        assert!(r.non_manifold.is_empty() && r.flipped.is_empty());
    }

    #[test]
    fn a_flipped_triangle_is_found_and_counted() {
        let mut m = cube();
        m.indices.swap(4, 5);
        let r = m.edge_use();
        assert!(!r.is_closed_manifold());
        assert_eq!(r.flipped.len(), 3);
        assert_eq!(r.flipped_triangles, 1);
        assert!(r.open.is_empty());
    }

    #[test]
    fn an_inside_out_solid_is_closed_but_not_outward() {
        let mut m = cube();
        m.flip();
        let r = m.edge_use();
        assert!(r.is_closed_manifold() && !r.is_solid());
        assert!(r.signed_volume < 0.0);
    }

    #[test]
    fn glued_and_stacked_solids() {
        // Two cubes glued face to face: the shared square is used by four triangles on
        // its diagonal and its edges.
        let a = cube();
        let mut b = cube();
        b.transform(&DMat4::from_translation(DVec3::Y)).unwrap();
        let r = edge_use([&a, &b]);
        assert!(!r.non_manifold.is_empty());
        assert!(!r.is_closed_manifold());
        // Two disjoint cubes are two closed shells.
        let mut c = cube();
        c.transform(&DMat4::from_translation(DVec3::X * 3.0))
            .unwrap();
        let r = edge_use([&a, &c]);
        assert!(r.is_solid() && r.is_solid_shells());
        assert_eq!(r.components, 2);
        assert_eq!(r.shell_volumes.len(), 2);
        assert!(r.shell_volumes.iter().all(|v| (v - 1.0).abs() < 1e-9));
        // A large cube with a small inside-out one inside: positive in total, one shell
        // negative.
        let mut big = cube();
        big.transform(&DMat4::from_scale(DVec3::splat(4.0)))
            .unwrap();
        let mut small = cube();
        small
            .transform(&DMat4::from_translation(DVec3::ONE))
            .unwrap();
        small.flip();
        let r = edge_use([&big, &small]);
        assert!(r.is_solid() && !r.is_solid_shells());
        assert_eq!(r.shell_volumes.len(), 2);
        assert!(
            (r.shell_volumes[0] - 64.0).abs() < 1e-9 && (r.shell_volumes[1] + 1.0).abs() < 1e-9
        );
        // An open square sheet.
        let sheet = flat_polygon(
            &PolygonWithHoles::from(Polygon::rect(DVec2::ZERO, DVec2::ONE)),
            0.0,
            crate::Facing::Up,
            None,
        )
        .unwrap();
        let r = sheet.edge_use();
        assert_eq!(r.open.len(), 4);
        assert!((r.open_length - 4.0).abs() < 1e-9);
    }

    #[test]
    fn bad_indices_and_degenerate_triangles_are_counted() {
        let mut m = cube();
        m.indices.extend([0, 1, 999]);
        m.indices.extend([0, 0, 1]);
        let r = m.edge_use();
        assert_eq!((r.bad_indices, r.degenerate_triangles), (1, 1));
        assert!(!r.is_closed_manifold());
        assert_eq!(Mesh::default().edge_use(), EdgeUseReport::default());
        assert!(!Mesh::default().edge_use().is_solid());
    }

    /// A random simple ring: a star-shaped polygon with `n` vertices at random radii.
    fn star(radii: &[f64], phase: f64) -> Polygon {
        let n = radii.len();
        let pts = radii
            .iter()
            .enumerate()
            .map(|(i, &r)| {
                let a = phase + std::f64::consts::TAU * i as f64 / n as f64;
                DVec2::new(r * a.cos(), r * a.sin())
            })
            .collect();
        Polygon::new(pts)
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(96))]

        #[test]
        fn extruded_random_polygons_pass_and_damage_is_found(
            radii in proptest::collection::vec(1.0f64..30.0, 3..24),
            phase in 0.0f64..6.3,
            z0 in -50.0f64..50.0,
            h in 0.5f64..80.0,
            victim in 0usize..10_000,
        ) {
            let poly = star(&radii, phase);
            proptest::prop_assume!(poly.validate().is_ok());
            let m = prism(&PolygonWithHoles::from(poly.clone()), z0, z0 + h, None).unwrap();
            let r = m.edge_use();
            proptest::prop_assert!(r.is_solid() && r.is_solid_shells(), "{:?}", r);
            let volume = poly.area() * h;
            proptest::prop_assert_eq!(r.shell_volumes.len(), 1);
            proptest::prop_assert!((r.shell_volumes[0] - r.signed_volume).abs() < 1e-9 * volume);
            proptest::prop_assert!((r.signed_volume - volume).abs() < 1e-4 * volume.max(1.0));
            // Euler: V − E + F = 2 for one closed genus-0 shell.
            proptest::prop_assert_eq!(
                r.vertices as i64 - r.edges as i64 + r.triangles as i64, 2);
            // Removing any one triangle opens exactly its three edges.
            let t = victim % m.triangle_count();
            let mut cut = m.clone();
            cut.indices.drain(3 * t..3 * t + 3);
            let r = cut.edge_use();
            proptest::prop_assert_eq!(r.open.len(), 3);
            proptest::prop_assert!(!r.is_closed_manifold());
            // Reversing one triangle flips its three edges and counts one triangle.
            let mut flipped = m.clone();
            flipped.indices.swap(3 * t + 1, 3 * t + 2);
            let r = flipped.edge_use();
            proptest::prop_assert_eq!(r.flipped.len(), 3);
            proptest::prop_assert_eq!(r.flipped_triangles, 1);
            // Splitting the solid across two meshes changes nothing.
            let mut first = m.clone();
            let mut second = m.clone();
            first.indices.truncate(3 * t);
            second.indices.drain(..3 * t);
            let r = edge_use([&first, &second]);
            proptest::prop_assert!(r.is_solid());
        }
    }
}
