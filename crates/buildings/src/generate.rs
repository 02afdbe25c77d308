//! The building generator: footprint → height → grammar derivation → shapes, per LOD.

use polis_geom::{Aabb2, DVec2, Field, Polygon};
use polis_lots::Lot;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

use crate::BuildingsError;
use crate::building::{Building, Context, interpret, with_scratch};
use crate::footprint::footprint;
use crate::grammar::BuildingGrammar;
use crate::params::{BuildingKind, BuildingParams, HeightDistribution};
use crate::template::Template;

/// Lowest building drawn, metres: under this the maximum-height map forbids building.
pub const MIN_BUILDING_HEIGHT: f64 = 2.5;

/// The geometric resolution of buildings, metres: before a footprint is cut, lot vertices
/// within this distance of the chord between their neighbours (near-duplicate vertices,
/// nearly straight runs of a finely sampled curve) are dropped, except where a street
/// edge meets a side edge. Building meshes are `f32` (about 1 mm at 10 km from the
/// origin), and finer detail only gives triangles of zero area after rounding.
pub const LOT_RESOLUTION_M: f64 = 1e-3;

/// Longest string a building derivation may produce (modules).
pub const MAX_BUILDING_MODULES: usize = 100_000;

/// A building's footprint and height before any grammar runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Footprint (layout, absolute), counter-clockwise, primary street edge first.
    pub footprint: Polygon,
    /// Height of the bounding volume, metres.
    pub height: f64,
    /// Storeys.
    pub floors: u32,
    /// Seed of the building's derivation.
    pub seed: u64,
}

/// The reusable generator: parameters, one grammar per kind, user templates.
#[derive(Debug, Clone)]
pub struct BuildingGenerator {
    params: BuildingParams,
    grammars: Vec<BuildingGrammar>,
    templates: Vec<Template>,
}

/// A stable 64-bit mix of the city seed and an id (SplitMix64 finaliser).
pub fn mix_seed(seed: u64, id: u64) -> u64 {
    let mut z = seed ^ id.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl BuildingGenerator {
    /// A generator with the default grammars of every kind.
    pub fn new(params: BuildingParams) -> Result<Self, BuildingsError> {
        params.validate()?;
        let grammars = BuildingKind::ALL
            .iter()
            .map(|&k| BuildingGrammar::default_for(k))
            .collect::<Result<_, _>>()?;
        Ok(BuildingGenerator {
            params,
            grammars,
            templates: Vec::new(),
        })
    }

    /// Replaces the grammar of `kind` (e.g. one parsed from a user's building file).
    pub fn set_grammar(&mut self, kind: BuildingKind, grammar: BuildingGrammar) {
        if let Some(g) = self.grammars.get_mut(kind.index()) {
            *g = grammar;
        }
    }

    /// Adds a user template; `Template(i)` in a grammar names the `i`-th added.
    pub fn add_template(&mut self, template: Template) -> usize {
        self.templates.push(template);
        self.templates.len() - 1
    }

    /// The parameters.
    pub fn params(&self) -> &BuildingParams {
        &self.params
    }

    /// Footprint and height of the building of `kind` on `lot` under the maximum height
    /// `max_height` (metres, e.g. sampled from the maximum-height map at the lot's
    /// centroid). `Ok(None)` when the lot cannot carry one (too small after the setbacks,
    /// or a height limit under [`MIN_BUILDING_HEIGHT`]).
    pub fn plan(
        &self,
        lot: &Lot,
        lot_id: u64,
        kind: BuildingKind,
        max_height: f64,
    ) -> Result<Option<Plan>, BuildingsError> {
        let lot = &*resolved_lot(lot, lot_id)?;
        Ok(self
            .plan_centred(lot, lot_id, kind, max_height)?
            .map(|(plan, _)| plan))
    }

    /// [`plan`](Self::plan) of a lot already at [`LOT_RESOLUTION_M`] ([`resolved_lot`]),
    /// with the footprint's centroid (the building's origin).
    fn plan_centred(
        &self,
        lot: &Lot,
        lot_id: u64,
        kind: BuildingKind,
        max_height: f64,
    ) -> Result<Option<(Plan, DVec2)>, BuildingsError> {
        if !(max_height.is_finite()) {
            return Err(BuildingsError::Lot {
                lot_id,
                reason: format!("the maximum height {max_height} is not finite"),
            });
        }
        if max_height < MIN_BUILDING_HEIGHT {
            return Ok(None);
        }
        let Some(mut fp) = footprint(
            lot,
            lot_id,
            kind.footprint_strategy(),
            &self.params.footprint,
        )?
        else {
            return Ok(None);
        };
        // Primary street edge first: the longest edge when the lot names none.
        // (Each edge's length once; on equal lengths the first edge leads.)
        let lead =
            if kind.footprint_strategy() == crate::params::FootprintStrategy::SuburbanRectangle {
                0
            } else {
                fp.edges()
                    .enumerate()
                    .map(|(i, (a, b))| (a.distance(b), i))
                    .max_by(|p, q| p.0.total_cmp(&q.0).then(q.1.cmp(&p.1)))
                    .map_or(0, |(_, i)| i)
            };
        let mut pts = fp.into_points();
        pts.rotate_left(lead);
        if pts.capacity() != pts.len() {
            // The footprint is kept by the building: no spare capacity.
            pts = pts.as_slice().to_vec();
        }
        fp = Polygon::new(pts);
        let seed = mix_seed(self.params.seed, lot_id);
        let mut rng = Pcg64Mcg::seed_from_u64(seed ^ 0x6865_6967_6874);
        let centroid = fp.centroid();
        let height = self
            .draw_height(kind, centroid, &mut rng)
            .clamp(MIN_BUILDING_HEIGHT, max_height);
        let p = &self.params;
        let floors = if height <= p.ground_floor_height {
            1
        } else {
            1 + ((height - p.ground_floor_height) / p.floor_height).floor() as u32
        };
        Ok(Some((
            Plan {
                footprint: fp,
                height,
                floors,
                seed,
            },
            centroid,
        )))
    }

    /// A height drawn from the configured distribution for `kind` at layout point `at`.
    pub fn draw_height(&self, kind: BuildingKind, at: DVec2, rng: &mut Pcg64Mcg) -> f64 {
        let m = self
            .params
            .median_height
            .get(kind.index())
            .copied()
            .unwrap_or(10.0);
        let normal = |rng: &mut Pcg64Mcg| {
            // Box–Muller with libm-backed trigonometry (platform-independent).
            let u1: f64 = 1.0 - rng.random::<f64>();
            let u2: f64 = rng.random::<f64>();
            (-2.0 * u1.ln()).sqrt() * DVec2::from_angle(std::f64::consts::TAU * u2).x
        };
        let h = match self.params.distribution {
            HeightDistribution::Uniform { deviance } => {
                m * (1.0 + deviance * (2.0 * rng.random::<f64>() - 1.0))
            }
            HeightDistribution::Normal { sigma } => m * (1.0 + sigma * normal(rng)),
            HeightDistribution::LogNormal {
                sigma,
                centre,
                centre_boost,
                falloff,
            } => {
                let r = at.distance(DVec2::from(centre)) / falloff;
                let median = m * (1.0 + centre_boost * (-r * r).exp());
                median * (sigma * normal(rng)).exp()
            }
        };
        if h.is_finite() { h } else { m }
    }

    /// The building of `kind` on `lot` at level of detail `lod` (derivation steps; capped
    /// at [`BuildingParams::max_lod`]). `Ok(None)` when the lot carries no building.
    pub fn build(
        &self,
        lot: &Lot,
        lot_id: u64,
        kind: BuildingKind,
        max_height: f64,
        lod: usize,
    ) -> Result<Option<Building>, BuildingsError> {
        let mut last = None;
        self.build_lods(
            lot,
            lot_id,
            kind,
            max_height,
            lod.min(self.params.max_lod),
            true,
            &mut |b| last = Some(b),
        )?;
        Ok(last)
    }

    /// Every level of detail `0..=max_lod` of one building (LOD `k + 1` refines LOD `k`).
    pub fn lods(
        &self,
        lot: &Lot,
        lot_id: u64,
        kind: BuildingKind,
        max_height: f64,
    ) -> Result<Vec<Building>, BuildingsError> {
        let mut out = Vec::with_capacity(self.params.max_lod + 1);
        self.build_lods(
            lot,
            lot_id,
            kind,
            max_height,
            self.params.max_lod,
            false,
            &mut |b| out.push(b),
        )?;
        Ok(out)
    }

    /// Builds LOD `lod` (and, unless `last_only`, every LOD below it) and hands each
    /// building to `sink`. Allocates only what the buildings keep: the derivation, the
    /// local footprint and the interpreter run in per-thread buffers.
    #[allow(clippy::too_many_arguments)]
    fn build_lods(
        &self,
        lot: &Lot,
        lot_id: u64,
        kind: BuildingKind,
        max_height: f64,
        lod: usize,
        last_only: bool,
        sink: &mut dyn FnMut(Building),
    ) -> Result<(), BuildingsError> {
        let lot = &*resolved_lot(lot, lot_id)?;
        let Some((plan, origin)) = self.plan_centred(lot, lot_id, kind, max_height)? else {
            return Ok(());
        };
        let Some(grammar) = self.grammars.get(kind.index()) else {
            return Err(BuildingsError::InvalidParameter {
                name: "kind",
                reason: "no grammar for this kind".into(),
            });
        };
        let derivation_error = |source| BuildingsError::Derivation {
            kind: kind.name().into(),
            source,
        };
        let mut local = LOCAL.with(std::cell::Cell::take);
        local.clear();
        local.extend(plan.footprint.points().iter().map(|&p| p - origin));
        let (w, d, frame_x) = extents(&local);
        let p = &self.params;
        let cx = Context {
            grammar,
            templates: &self.templates,
            lot_world: &lot.polygon,
            origin,
            lot_local: std::cell::OnceCell::new(),
            frame_x,
            top: plan.height,
            floor_height: p.floor_height,
            ground_floor_height: p.ground_floor_height,
            slope_default: p.roof_pitch_deg.to_radians().tan(),
        };
        let axiom = [plan.height, w, d, f64::from(plan.floors)];
        let mut footprint = Some(plan.footprint);
        grammar.derive(plan.seed, &axiom, derivation_error, |derivation| {
            for k in 0..=lod {
                if k > 0 {
                    derivation.step().map_err(derivation_error)?;
                }
                if last_only && k < lod {
                    continue;
                }
                let (parts, facades, fallbacks) = with_scratch(|scratch| {
                    interpret(&cx, scratch, &local, plan.height, derivation.string())
                })?;
                let footprint = if k == lod {
                    footprint.take()
                } else {
                    footprint.clone()
                };
                sink(Building {
                    id: lot_id,
                    lot_id,
                    kind,
                    height: plan.height,
                    floors: plan.floors,
                    lod: k,
                    origin,
                    footprint: footprint.unwrap_or_else(|| Polygon::new(Vec::new())),
                    parts,
                    facades,
                    fallbacks,
                });
            }
            Ok(())
        })?;
        LOCAL.with(|l| l.set(local));
        Ok(())
    }
}

/// `lot` at [`LOT_RESOLUTION_M`]: its vertices within the resolution of the chord between
/// their kept neighbours dropped (never where the street flag changes), the street edges
/// renumbered. The lot itself when nothing is dropped or when the simplified ring would
/// not be a valid polygon.
///
/// # Errors
/// [`BuildingsError::Lot`] when fewer than three vertices remain (no extent above the
/// resolution).
pub fn resolved_lot(lot: &Lot, lot_id: u64) -> Result<std::borrow::Cow<'_, Lot>, BuildingsError> {
    use std::borrow::Cow;
    let pts = lot.polygon.points();
    let n = pts.len();
    if n <= 3 {
        return Ok(Cow::Borrowed(lot));
    }
    let mut street = vec![false; n];
    for &e in lot.street_edges.iter().filter(|&&e| e < n) {
        street[e] = true;
    }
    // Vertex i joins edge i − 1 and edge i; it stays where a street edge meets a side
    // edge, unless one of them is shorter than the resolution (a near-duplicate vertex
    // carries no street of its own).
    let long = |e: usize| pts[e].distance(pts[(e + 1) % n]) >= LOT_RESOLUTION_M;
    let fixed = |i: usize| {
        let before = (i + n - 1) % n;
        street[before] != street[i] && long(before) && long(i)
    };
    let kept = polis_geom::simplify::simplify_ring(pts, LOT_RESOLUTION_M, fixed);
    if kept.len() == n {
        return Ok(Cow::Borrowed(lot));
    }
    if kept.len() < 3 {
        return Err(BuildingsError::Lot {
            lot_id,
            reason: format!(
                "the lot has no extent above the {LOT_RESOLUTION_M} m resolution of buildings"
            ),
        });
    }
    let polygon = Polygon::new(kept.iter().map(|&i| pts[i]).collect());
    if polygon.validate().is_err() {
        return Ok(Cow::Borrowed(lot));
    }
    // Original edge e lies in the kept edge that starts at the last kept vertex ≤ e
    // (or at the last kept vertex, for edges before the first); a kept edge faces a
    // street when the longest original edge it covers does.
    let edge_of = |e: usize| match kept.binary_search(&e) {
        Ok(t) => t,
        Err(0) => kept.len() - 1,
        Err(t) => t - 1,
    };
    let k = kept.len();
    let kept_street: Vec<bool> = (0..k)
        .map(|t| {
            let (from, to) = (kept[t], kept[(t + 1) % k]);
            let span = (to + n - from) % n;
            (0..span)
                .map(|j| (from + j) % n)
                .max_by(|&a, &b| {
                    let len = |e: usize| pts[e].distance(pts[(e + 1) % n]);
                    len(a).total_cmp(&len(b)).then(b.cmp(&a))
                })
                .is_some_and(|e| street[e])
        })
        .collect();
    let mut street_edges: Vec<usize> = Vec::with_capacity(lot.street_edges.len());
    for &e in lot.street_edges.iter().filter(|&&e| e < n) {
        let t = edge_of(e);
        if kept_street[t] && !street_edges.contains(&t) {
            street_edges.push(t);
        }
    }
    Ok(Cow::Owned(Lot {
        area: polygon.area(),
        polygon,
        street_edges,
        block_id: lot.block_id,
    }))
}

thread_local! {
    /// Per-thread buffer of [`BuildingGenerator::build_lods`]: the footprint relative to
    /// the origin (taken while in use, so a nested call gets a fresh one).
    static LOCAL: std::cell::Cell<Vec<DVec2>> = const { std::cell::Cell::new(Vec::new()) };
}

/// Width along and depth across the first edge, and the first edge's unit direction.
fn extents(ring: &[DVec2]) -> (f64, f64, DVec2) {
    let x = match ring {
        [a, b, ..] => (*b - *a).normalize_or(DVec2::X),
        _ => DVec2::X,
    };
    let b = Aabb2::in_frame(ring.iter().copied(), x, x.perp());
    (b.max.x - b.min.x, b.max.y - b.min.y, x)
}

/// How zones choose building types.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ZoneRule {
    /// The zoning map's value, rounded, indexes [`BuildingKind::ALL`] (0 skyscraper … 5
    /// industrial; out of range clamps).
    #[default]
    Index,
}

/// The building kind a zoning map assigns to layout point `p` ([`ZoneRule::Index`]).
pub fn kind_from_zoning(zoning: &dyn Field, p: DVec2) -> BuildingKind {
    let v = zoning.sample(p);
    let i = if v.is_finite() {
        v.round().clamp(0.0, 5.0) as usize
    } else {
        3
    };
    BuildingKind::ALL
        .get(i)
        .copied()
        .unwrap_or(BuildingKind::House)
}

/// One-call form: a building (full detail) on every lot, the kind from the zoning map,
/// the height limit from the maximum-height map, both sampled at the lot's centroid;
/// lot ids are the slice indices. Lots that carry none are skipped; errors of single lots
/// are returned, not skipped.
pub fn generate(
    lots: &[Lot],
    params: &BuildingParams,
    zoning: &dyn Field,
    max_height: &dyn Field,
) -> Result<Vec<Building>, BuildingsError> {
    let g = BuildingGenerator::new(params.clone())?;
    let mut out = Vec::with_capacity(lots.len());
    for (i, lot) in lots.iter().enumerate() {
        let c = lot.polygon.centroid();
        let kind = kind_from_zoning(zoning, c);
        if let Some(b) = g.build(lot, i as u64, kind, max_height.sample(c), params.max_lod)? {
            out.push(b);
        }
    }
    Ok(out)
}
