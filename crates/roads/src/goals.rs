//! Global goals (§3.2): population density and road patterns fill the parameters of the
//! ideal successor in p2.

use std::f64::consts::{FRAC_PI_2, PI};

use polis_geom::DVec2;
use polis_lsystem::rand_pcg::Pcg64Mcg;
use rand::Rng;

use crate::error::{Result, RoadError};
use crate::inputs::RoadInputs;
use crate::legality::{Illegal, Legality};
use crate::modules::{Proposal, RoadAttr, RuleAttr};
use crate::network::{RoadClass, angle_diff, angle_of, dir};
use crate::params::{Pattern, RoadParams};
use crate::street_rules::BranchChoice;

/// The `globalGoals` function of p2: given an accepted segment, propose the continuation
/// and two branches.
///
/// Implement it to add a goal without touching a production; wrap [`DefaultGoals`] to
/// change only part of its answer (see the `road_custom_goal` example).
pub trait GlobalGoals: Send + Sync {
    /// The axiom: the initial road segments (Parish & Müller's single `R ?I`; the slides
    /// start with two opposite segments).
    fn axiom(&self) -> Vec<(RuleAttr, RoadAttr)>;

    /// `[continuation, branch 1, branch 2]` after the accepted segment `road` grown by a
    /// road with `rule`. A negative delay means "no successor". `rng` is the derivation's
    /// seeded generator.
    fn successors(&self, rule: &RuleAttr, road: &RoadAttr, rng: &mut Pcg64Mcg) -> [Proposal; 3];
}

/// A uniform number in `[0, 1)` (top 53 bits of one draw).
pub fn unit_f64(rng: &mut Pcg64Mcg) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

const PATTERNS: [Pattern; 4] = [
    Pattern::Basic,
    Pattern::NewYork,
    Pattern::Paris,
    Pattern::SanFrancisco,
];

/// The default global goals: population-seeking highways (ray sampling with inverse
/// distance weights), the four patterns of Table 1 blended by weight maps (Fig. 7),
/// population-thresholded street branching and the highway-to-street delay.
#[derive(Debug, Clone)]
pub struct DefaultGoals {
    params: RoadParams,
    inputs: RoadInputs,
    legality: Legality,
    start: DVec2,
    centre: DVec2,
}

/// Per-pattern proposal: direction (radians) and length (metres).
#[derive(Debug, Clone, Copy)]
struct Aim {
    angle: f64,
    length: f64,
}

impl DefaultGoals {
    /// Goals for `params` over `inputs`. Finds the start (population peak on legal
    /// ground) and the Paris centre (population peak) unless given.
    ///
    /// # Errors
    /// [`RoadError::InvalidParameter`] for bad parameters; [`RoadError::NoLegalStart`]
    /// when no legal start point exists.
    pub fn new(params: &RoadParams, inputs: &RoadInputs) -> Result<Self> {
        params.validate()?;
        let legality = Legality::new(inputs, params);
        let b = params.bounds();
        let mut best_legal: Option<(f64, DVec2)> = None;
        let mut best_any: Option<(f64, DVec2)> = None;
        const N: usize = 64;
        for j in 0..N {
            for i in 0..N {
                let p = DVec2::new(
                    b.min.x + b.width() * (i as f64 + 0.5) / N as f64,
                    b.min.y + b.height() * (j as f64 + 0.5) / N as f64,
                );
                let v = inputs.population.sample(p);
                if !v.is_finite() {
                    continue;
                }
                if best_any.is_none_or(|(bv, _)| v > bv) {
                    best_any = Some((v, p));
                }
                // Legality only for a new best (the maps may be slow to sample).
                if best_legal.is_none_or(|(bv, _)| v > bv) && legality.point(p).is_none() {
                    best_legal = Some((v, p));
                }
            }
        }
        let start = match params.start {
            Some(s) => {
                let s = DVec2::from_array(s);
                if legality.point(s).is_some() {
                    return Err(RoadError::InvalidParameter {
                        name: "start",
                        reason: format!(
                            "({}, {}) is outside the map or in an illegal area; move it onto legal land",
                            s.x, s.y
                        ),
                    });
                }
                s
            }
            None => best_legal.ok_or(RoadError::NoLegalStart)?.1,
        };
        let centre = match params.paris_centre {
            Some(c) => DVec2::from_array(c),
            None => best_any.map_or(b.center(), |(_, p)| p),
        };
        Ok(DefaultGoals {
            params: params.clone(),
            inputs: inputs.clone(),
            legality,
            start,
            centre,
        })
    }

    /// The start point of the axiom.
    pub fn start(&self) -> DVec2 {
        self.start
    }

    /// The centre of the Paris pattern.
    pub fn centre(&self) -> DVec2 {
        self.centre
    }

    /// The parameters.
    pub fn params(&self) -> &RoadParams {
        &self.params
    }

    /// Normalised pattern weights at `p` (Basic, New York, Paris, San Francisco).
    pub fn pattern_weights(&self, p: DVec2) -> [f64; 4] {
        let mut w = [0.0; 4];
        if self.inputs.pattern_weights.is_empty() {
            w[pattern_slot(self.params.pattern)] = 1.0;
            return w;
        }
        for (pat, f) in &self.inputs.pattern_weights {
            let v = f.sample(p);
            if v.is_finite() && v > 0.0 {
                w[pattern_slot(*pat)] += v;
            }
        }
        let s: f64 = w.iter().sum();
        if s > 0.0 {
            for x in &mut w {
                *x /= s;
            }
        } else {
            w = [1.0, 0.0, 0.0, 0.0];
        }
        w
    }

    /// Inverse-distance-weighted population along the ray from `p` in direction `a`
    /// (§3.2.1, Fig. 4). Samples in water or in a park count nothing, whatever the
    /// population map says there (a procedural map goes on under the sea): a highway
    /// starting on a shore otherwise aimed at the population it saw across the water,
    /// met water no bridge spans and stopped, and the city stayed a pocket of a few
    /// hundred streets around its start. Beyond the map's edge the samples count (the
    /// country goes on there, and highways run on to the edge).
    pub fn ray_score(&self, p: DVec2, a: f64) -> f64 {
        let n = self.params.highway_ray_samples;
        let d = dir(a);
        let mut sum = 0.0;
        for i in 1..=n {
            let dist = self.params.highway_ray_length_m * f64::from(i) / f64::from(n);
            let q = p + d * dist;
            if matches!(self.legality.point(q), Some(Illegal::Water | Illegal::Park)) {
                continue;
            }
            let v = self.inputs.population.sample(q);
            if v.is_finite() {
                sum += v / dist;
            }
        }
        sum
    }

    /// The best of `highway_rays` rays within `±half_fan` of `a` (ties: closest to `a`).
    /// Rays the highway cannot take ([`ray_open`](Self::ray_open); the map's edge closes
    /// a ray only if `edge_closes`) lose to every open one; when none is open, the best
    /// of all (the local constraints then end the highway there).
    pub fn best_ray(&self, p: DVec2, a: f64, half_fan: f64, edge_closes: bool) -> f64 {
        let n = self.params.highway_rays.max(1);
        let mut best: Option<(bool, f64, f64)> = None;
        for i in 0..n {
            let off = if n == 1 {
                0.0
            } else {
                -half_fan + 2.0 * half_fan * f64::from(i) / f64::from(n - 1)
            };
            let cand = a + off;
            let s = self.ray_score(p, cand);
            let open = self.ray_open(p, cand, edge_closes);
            let better = best.is_none_or(|(bo, bs, ba)| {
                (open && !bo)
                    || (open == bo
                        && (s > bs + 1e-12 || (s >= bs - 1e-12 && off.abs() < angle_diff(ba, a))))
            });
            if better {
                best = Some((open, s, cand));
            }
        }
        best.map_or(a, |(_, _, ang)| ang)
    }

    /// Whether a highway can leave `p` in direction `a`: its first segment stays on legal
    /// ground, or crosses water that a bridge (or, where the parameters say so, a tunnel)
    /// within the local constraints' length limit spans, as [`DefaultConstraints`]
    /// would build it: from `p` where the water begins early in the segment, from the
    /// shore (the last legal sample) where it begins late enough for the constraints to
    /// prune the segment there, so that the next segment is the bridge. A park or a slope
    /// does not close a ray (the constraints rotate round it or tunnel under it); the
    /// map's edge does if `edge_closes`.
    ///
    /// [`DefaultConstraints`]: crate::DefaultConstraints
    pub fn ray_open(&self, p: DVec2, a: f64, edge_closes: bool) -> bool {
        let d = dir(a);
        let len = self.params.highway_length_m;
        let Some(v) = self.legality.segment(p, p + d * len) else {
            return true;
        };
        match v.what {
            Illegal::Outside => !edge_closes,
            Illegal::Park | Illegal::Slope => true,
            Illegal::Water => {
                let reach = if self.params.tunnel_under_water {
                    self.params.max_tunnel_length_m
                } else {
                    self.params.max_bridge_length_m
                };
                // Where the water begins far enough along, the constraints prune the
                // segment to the shore and the next one bridges from there, its length
                // limit counted from the shore: a river as wide as the limit is open
                // wherever the highway meets it.
                let shore = v.t_legal * len;
                let from = if shore >= (1.0 - self.params.max_prune_factor) * len
                    && shore >= self.params.min_segment_length_m
                {
                    shore
                } else {
                    0.0
                };
                self.legality
                    .bridge_landing(p + d * from, d, v.t * len - from, reach)
                    .is_some()
            }
        }
    }

    fn class_length(&self, class: RoadClass) -> f64 {
        match class {
            RoadClass::Highway => self.params.highway_length_m,
            RoadClass::Street => self.params.street_length_m,
        }
    }

    fn grid_angle(&self, p: DVec2) -> f64 {
        let deg = match &self.inputs.grid_angle {
            Some(f) => {
                let v = f.sample(p);
                if v.is_finite() {
                    v
                } else {
                    self.params.grid_angle_deg
                }
            }
            None => self.params.grid_angle_deg,
        };
        deg.to_radians()
    }

    /// Basic rule: highways follow population, streets go on with a small deviation.
    fn basic(&self, p: DVec2, a: f64, class: RoadClass, branch: bool, rng: &mut Pcg64Mcg) -> Aim {
        let angle = match class {
            RoadClass::Highway if !branch => {
                self.best_ray(p, a, self.params.highway_max_turn_deg.to_radians(), false)
            }
            _ => {
                let dev = self.params.street_deviation_deg.to_radians();
                a + (2.0 * unit_f64(rng) - 1.0) * dev
            }
        };
        Aim {
            angle,
            length: self.class_length(class),
        }
    }

    /// New York rule: the nearest grid axis; block length along the grid angle, block
    /// width across it (streets).
    fn new_york(&self, p: DVec2, a: f64, class: RoadClass) -> Aim {
        let g = self.grid_angle(p);
        let k = ((a - g) / FRAC_PI_2).round();
        let angle = g + k * FRAC_PI_2;
        let along = (k as i64).rem_euclid(2) == 0;
        let mut length = match class {
            RoadClass::Highway => self.params.highway_length_m,
            RoadClass::Street if along => self.params.block_length_m,
            RoadClass::Street => self.params.block_width_m,
        };
        if class == RoadClass::Street && self.params.street_rules(Pattern::NewYork).lattice {
            // To the next lattice line (through the start) at least half a block ahead.
            let t = (p - self.start).dot(dir(angle));
            let mut next = ((t / length).floor() + 1.0) * length;
            if next - t < 0.5 * length {
                next += length;
            }
            length = next - t;
        }
        Aim { angle, length }
    }

    /// Paris rule: radial or concentric (a chord of the circle through `p`) around the
    /// centre, whichever is closer to `a`.
    fn paris(&self, p: DVec2, a: f64, class: RoadClass) -> Aim {
        let len = self.class_length(class);
        let v = p - self.centre;
        let r = v.length();
        if r < 1e-6 {
            return Aim {
                angle: a,
                length: len,
            };
        }
        let radial = angle_of(v);
        let d = angle_diff(a, radial);
        if d <= PI / 4.0 || r < len {
            return Aim {
                angle: radial,
                length: len,
            };
        }
        if d >= 3.0 * PI / 4.0 {
            // Inward: stop at the centre rather than overshoot it.
            return Aim {
                angle: radial + PI,
                length: len.min(r),
            };
        }
        let side = if v.perp_dot(dir(a)) >= 0.0 { 1.0 } else { -1.0 };
        let phi = side * len / r;
        let q = self.centre
            + DVec2::new(
                v.x * phi.cos() - v.y * phi.sin(),
                v.x * phi.sin() + v.y * phi.cos(),
            );
        Aim {
            angle: angle_of(q - p),
            length: q.distance(p),
        }
    }

    /// San Francisco rule: the direction within the highway fan of least elevation change.
    fn san_francisco(&self, p: DVec2, a: f64, class: RoadClass) -> Aim {
        let len = self.class_length(class);
        let h0 = self.inputs.elevation.sample(p);
        let n = self.params.highway_rays.max(3);
        let half = self.params.highway_max_turn_deg.to_radians().max(0.35);
        let mut best = (f64::INFINITY, a);
        for i in 0..n {
            let off = -half + 2.0 * half * f64::from(i) / f64::from(n - 1);
            let c = a + off;
            let dh = (self.inputs.elevation.sample(p + dir(c) * len) - h0).abs();
            let dh = if dh.is_finite() { dh } else { f64::INFINITY };
            if dh < best.0 - 1e-9 || (dh <= best.0 + 1e-9 && off.abs() < angle_diff(best.1, a)) {
                best = (dh, c);
            }
        }
        Aim {
            angle: best.1,
            length: len,
        }
    }

    /// A San Francisco connector: along the elevation gradient on the side of `a`.
    fn sf_connector(&self, p: DVec2, a: f64) -> Aim {
        let g = self.inputs.elevation.gradient(p);
        let angle = if g.is_finite() && g.length() > 1e-6 {
            let up = angle_of(g);
            if angle_diff(up, a) <= FRAC_PI_2 {
                up
            } else {
                up + PI
            }
        } else {
            a
        };
        Aim {
            angle,
            length: self.params.sf_connector_length_m,
        }
    }

    /// The pattern-blended proposal (§3.2.2: "summed up and weighted").
    fn blend(&self, p: DVec2, a: f64, class: RoadClass, branch: bool, rng: &mut Pcg64Mcg) -> Aim {
        let w = self.pattern_weights(p);
        let mut v = DVec2::ZERO;
        let mut len = 0.0;
        let mut best = (
            0.0,
            Aim {
                angle: a,
                length: self.class_length(class),
            },
        );
        for (k, pat) in PATTERNS.iter().enumerate() {
            let wk = w[k];
            if wk <= 0.0 {
                continue;
            }
            let aim = match pat {
                Pattern::Basic => self.basic(p, a, class, branch, rng),
                Pattern::NewYork => self.new_york(p, a, class),
                Pattern::Paris => self.paris(p, a, class),
                Pattern::SanFrancisco if branch && class == RoadClass::Street => {
                    self.sf_connector(p, a)
                }
                Pattern::SanFrancisco => self.san_francisco(p, a, class),
            };
            v += dir(aim.angle) * wk;
            len += aim.length * wk;
            if wk > best.0 {
                best = (wk, aim);
            }
        }
        if v.length() < 1e-9 || !len.is_finite() || len <= 0.0 {
            return best.1;
        }
        Aim {
            angle: angle_of(v),
            length: len,
        }
    }

    fn proposal(
        &self,
        delay: i32,
        rule: RuleAttr,
        start: DVec2,
        aim: Aim,
        class: RoadClass,
    ) -> Proposal {
        Proposal {
            delay,
            rule,
            road: RoadAttr::new(start, aim.angle, aim.length, class),
        }
    }
}

fn pattern_slot(p: Pattern) -> usize {
    match p {
        Pattern::Basic => 0,
        Pattern::NewYork => 1,
        Pattern::Paris => 2,
        Pattern::SanFrancisco => 3,
    }
}

impl GlobalGoals for DefaultGoals {
    fn axiom(&self) -> Vec<(RuleAttr, RoadAttr)> {
        let p = self.start;
        let a = match self.params.start_angle_deg {
            Some(d) => d.to_radians(),
            None => self.best_ray(p, 0.0, PI, true),
        };
        let w = self.pattern_weights(p);
        // Align the axiom with the dominant pattern where it has a direction.
        let a = if w[1] >= 0.5 {
            // The grid axis nearest the population's direction on which the axiom can be
            // laid (either way legal): on hills the nearest axis may be too steep.
            let g = self.new_york(p, a, RoadClass::Highway).angle;
            let len = self.params.highway_length_m;
            let legal = |ang: f64| {
                self.legality.segment_ok(p, p + dir(ang) * len)
                    || self.legality.segment_ok(p, p - dir(ang) * len)
            };
            [0.0, FRAC_PI_2, -FRAC_PI_2]
                .into_iter()
                .map(|k| g + k)
                .find(|&ang| legal(ang))
                .unwrap_or(g)
        } else if w[2] >= 0.5 && p.distance(self.centre) > 1e-6 {
            angle_of(p - self.centre)
        } else {
            a
        };
        // The second highway leaves the other way; where that way is closed (the start
        // lies on a shore or near the map's edge), along the best open ray within a
        // right angle of it (a grid axis under New York), so the city does not grow
        // from one road.
        let b = if self.ray_open(p, a + PI, true) {
            a + PI
        } else if w[1] >= 0.5 {
            let side = [a + FRAC_PI_2, a - FRAC_PI_2]
                .into_iter()
                .filter(|&c| self.ray_open(p, c, true))
                .max_by(|&x, &y| self.ray_score(p, x).total_cmp(&self.ray_score(p, y)));
            side.unwrap_or(a + PI)
        } else {
            self.best_ray(p, a + PI, FRAC_PI_2, true)
        };
        let len = self.params.highway_length_m;
        vec![
            (
                RuleAttr::new(RoadClass::Highway, 0, a),
                RoadAttr::new(p, a, len, RoadClass::Highway),
            ),
            (
                RuleAttr::new(RoadClass::Highway, 0, b),
                RoadAttr::new(p, b, len, RoadClass::Highway),
            ),
        ]
    }

    fn successors(&self, rule: &RuleAttr, road: &RoadAttr, rng: &mut Pcg64Mcg) -> [Proposal; 3] {
        match rule.class {
            RoadClass::Highway => self.highway_successors(rule, road, rng),
            RoadClass::Street => self.street_successors(rule, road, rng),
        }
    }
}

impl DefaultGoals {
    /// The direction of the accepted segment and the population at its end.
    fn segment_end(&self, road: &RoadAttr) -> (DVec2, f64, f64) {
        let p = road.end;
        let a = if road.end.distance(road.start) > 0.0 {
            angle_of(road.end - road.start)
        } else {
            road.angle
        };
        let pop = self.inputs.population.sample(p);
        (p, a, if pop.is_finite() { pop } else { 0.0 })
    }

    /// The pattern of largest weight at `p` (the first of equals, in Table 1's order).
    pub fn dominant_pattern(&self, p: DVec2) -> Pattern {
        let w = self.pattern_weights(p);
        let mut best = 0;
        for k in 1..4 {
            if w[k] > w[best] {
                best = k;
            }
        }
        PATTERNS[best]
    }

    /// A highway goes on toward population (its turn from its first direction bounded by
    /// `highway_max_total_turn_deg`) and branches into highways (rarely, where populated)
    /// and streets (after the extra delay).
    fn highway_successors(
        &self,
        rule: &RuleAttr,
        road: &RoadAttr,
        rng: &mut Pcg64Mcg,
    ) -> [Proposal; 3] {
        let (p, a, pop) = self.segment_end(road);
        let prm = &self.params;
        let stop = road.snapped;
        let cont_rule = RuleAttr {
            age: rule.age.saturating_add(1),
            ..*rule
        };
        let mut cont_aim = self.blend(p, a, RoadClass::Highway, false, rng);
        // No coiling: keep within the total turn of the highway's first direction.
        let max_total = prm.highway_max_total_turn_deg.to_radians();
        let off = wrap_pi(cont_aim.angle - rule.heading);
        if off.abs() > max_total {
            cont_aim.angle = rule.heading + max_total.copysign(off);
        }
        let cont = self.proposal(
            if stop { -1 } else { 0 },
            cont_rule,
            p,
            cont_aim,
            RoadClass::Highway,
        );
        let mut branches = [cont; 2];
        for (i, side) in [1.0f64, -1.0].into_iter().enumerate() {
            let r = unit_f64(rng);
            let (bclass, delay) =
                if r < prm.highway_branch_probability && pop > prm.population_threshold {
                    (RoadClass::Highway, prm.branch_delay)
                } else {
                    let r2 = unit_f64(rng);
                    if pop > prm.population_threshold && r2 < prm.street_branch_probability {
                        (
                            RoadClass::Street,
                            prm.branch_delay.saturating_add(prm.highway_street_delay),
                        )
                    } else {
                        (RoadClass::Street, -1)
                    }
                };
            let delay = if stop { -1 } else { delay };
            let mut aim = self.blend(p, a + side * FRAC_PI_2, bclass, true, rng);
            let mut brule = RuleAttr::new(bclass, rule.depth.saturating_add(1), aim.angle);
            if bclass == RoadClass::Street {
                self.start_link(&mut brule, &mut aim, p, rng);
            }
            if let Some(slot) = branches.get_mut(i) {
                *slot = self.proposal(delay, brule, p, aim, bclass);
            }
        }
        let [b1, b2] = branches;
        [cont, b1, b2]
    }

    /// Draws a new street link at `p` into `rule` and sets the first segment of `aim`
    /// to the link's segment length.
    fn start_link(&self, rule: &mut RuleAttr, aim: &mut Aim, p: DVec2, rng: &mut Pcg64Mcg) {
        let rules = self.params.street_rules(self.dominant_pattern(p));
        let (turn, scale) = rules.draw_link(rng);
        rule.turn = turn;
        rule.scale = scale;
        let n = rules.segments_per_link.max(1);
        aim.angle += self.bend(p, turn, 0, n);
        aim.length *= scale / f64::from(n);
    }

    /// How far segment `index` of a link of `n` segments with bend `turn` turns from the
    /// pattern's direction. Basic follows the previous segment, so each segment turns by
    /// `turn` and the turns add up; the other patterns snap back to their own direction
    /// (grid axis, radial or concentric, contour), so the offset grows along the link,
    /// `turn · (index − (n − 1) / 2)`: an arc about the pattern's direction.
    fn bend(&self, p: DVec2, turn: f64, index: u32, n: u32) -> f64 {
        if self.dominant_pattern(p) == Pattern::Basic {
            if index == 0 { 0.0 } else { turn }
        } else {
            turn * (f64::from(index) - 0.5 * f64::from(n.saturating_sub(1)))
        }
    }

    /// A street goes on along its link (bending by the link's turn per segment); at the
    /// link's end (a branch point) it ends, branches to one side, to both or to neither,
    /// per the [`StreetRules`](crate::StreetRules) of the dominant pattern, and draws its
    /// next link.
    fn street_successors(
        &self,
        rule: &RuleAttr,
        road: &RoadAttr,
        rng: &mut Pcg64Mcg,
    ) -> [Proposal; 3] {
        let (p, a, pop) = self.segment_end(road);
        let prm = &self.params;
        let rules = prm.street_rules(self.dominant_pattern(p));
        // A crossing ends the street unless it goes on through (one draw, always).
        let through = unit_f64(rng) < rules.cross_through_probability && road.crossed;
        let stop = (road.snapped && !through) || pop < prm.street_min_population;
        let n = rules.segments_per_link.max(1);
        let at_branch_point = rule.age.saturating_add(1).is_multiple_of(n);
        let mut cont_rule = RuleAttr {
            age: rule.age.saturating_add(1),
            ..*rule
        };
        let (mut left, mut right, mut dead_end) = (false, false, false);
        if at_branch_point {
            let first_link = rule.age.saturating_add(1) == n;
            match rules.branch_at(first_link, rng) {
                BranchChoice::DeadEnd => dead_end = true,
                BranchChoice::Go { left: l, right: r } => {
                    let populated = pop > prm.population_threshold;
                    left = l && populated;
                    right = r && populated;
                }
            }
        }
        let mut cont_aim;
        if at_branch_point {
            cont_aim = self.blend(p, a, RoadClass::Street, false, rng);
            self.start_link(&mut cont_rule, &mut cont_aim, p, rng);
        } else {
            // The pattern proposes, then the link bends (so a grid street, a radial or
            // concentric Paris street, or a contour, curves too).
            cont_aim = self.blend(p, a, RoadClass::Street, false, rng);
            let index = rule.age.saturating_add(1) % n;
            cont_aim.angle += self.bend(p, rule.turn, index, n);
            cont_aim.length *= rule.scale / f64::from(n);
        }
        let cont_delay = if stop || dead_end { -1 } else { 0 };
        let cont = self.proposal(cont_delay, cont_rule, p, cont_aim, RoadClass::Street);
        let mut branches = [cont; 2];
        for (i, (side, grow)) in [(1.0f64, left), (-1.0, right)].into_iter().enumerate() {
            let mut aim = self.blend(p, a + side * FRAC_PI_2, RoadClass::Street, true, rng);
            let mut brule =
                RuleAttr::new(RoadClass::Street, rule.depth.saturating_add(1), aim.angle);
            self.start_link(&mut brule, &mut aim, p, rng);
            let delay = if grow && !stop { prm.branch_delay } else { -1 };
            if let Some(slot) = branches.get_mut(i) {
                *slot = self.proposal(delay, brule, p, aim, RoadClass::Street);
            }
        }
        let [b1, b2] = branches;
        [cont, b1, b2]
    }
}

/// `a` wrapped into (−π, π].
fn wrap_pi(a: f64) -> f64 {
    let w = a.rem_euclid(std::f64::consts::TAU);
    if w > PI { w - std::f64::consts::TAU } else { w }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use std::sync::Arc;

    use polis_geom::Field;
    use polis_geom::field::{Constant, FnField};
    use rand::SeedableRng;

    use super::*;

    fn flat() -> RoadInputs {
        RoadInputs::flat(Arc::new(FnField::new(|p: DVec2| {
            (-(p.length() / 800.0).powi(2)).exp()
        })))
    }

    #[test]
    fn highway_rays_climb_toward_population() {
        let params = RoadParams::default();
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        // The peak is at the origin; from (1000, 0) heading north, the best ray turns west.
        let a = g.best_ray(
            DVec2::new(1000.0, 0.0),
            FRAC_PI_2,
            30f64.to_radians(),
            false,
        );
        assert!(a > FRAC_PI_2 + 0.1, "{a}");
        assert!(g.start().length() < 100.0);
        assert!(g.centre().length() < 100.0);
    }

    #[test]
    fn pattern_weights_are_normalised_and_blend() {
        let params = RoadParams::default();
        let w: Arc<dyn Field> = Arc::new(Constant(3.0));
        let inputs =
            flat().with_pattern_weights(vec![(Pattern::NewYork, w.clone()), (Pattern::Paris, w)]);
        let g = DefaultGoals::new(&params, &inputs).unwrap();
        assert_eq!(
            g.pattern_weights(DVec2::new(5.0, 5.0)),
            [0.0, 0.5, 0.5, 0.0]
        );
        // No weight anywhere: Basic.
        let inputs = flat().with_pattern_weights(vec![(
            Pattern::Paris,
            Arc::new(Constant(0.0)) as Arc<dyn Field>,
        )]);
        let g = DefaultGoals::new(&params, &inputs).unwrap();
        assert_eq!(g.pattern_weights(DVec2::ZERO), [1.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn new_york_snaps_to_the_grid_with_block_sizes() {
        let params = RoadParams {
            pattern: Pattern::NewYork,
            grid_angle_deg: 10.0,
            ..RoadParams::default()
        };
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        let rule = RuleAttr::new(RoadClass::Street, 1, 0.0);
        let road = RoadAttr::new(DVec2::ZERO, 0.0, 50.0, RoadClass::Street);
        let [c, b1, b2] = g.successors(&rule, &road, &mut rng);
        assert!((c.road.angle - 10f64.to_radians()).abs() < 1e-9);
        assert_eq!(c.road.length, params.block_length_m);
        assert!((b1.road.angle - 100f64.to_radians()).abs() < 1e-9);
        assert_eq!(b1.road.length, params.block_width_m);
        assert!((b2.road.angle + 80f64.to_radians()).abs() < 1e-9);
        // Branches start where the segment ended.
        assert_eq!(b1.road.start, road.end);
    }

    /// With the lattice on, a New York street segment from anywhere ends on a lattice
    /// line through the start, 0.5 to 1.5 blocks ahead; off, it is one block long.
    #[test]
    fn new_york_lattice_puts_segment_ends_on_lattice_lines() {
        let mut params = RoadParams {
            pattern: Pattern::NewYork,
            grid_angle_deg: 30.0,
            block_length_m: 80.0,
            block_width_m: 240.0,
            ..RoadParams::default()
        };
        params.streets.insert(
            Pattern::NewYork,
            crate::StreetRules {
                lattice: true,
                ..crate::StreetRules::default()
            },
        );
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let origin = g.start();
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        for _ in 0..200 {
            let p = origin
                + DVec2::new(
                    unit_f64(&mut rng) * 1800.0 - 900.0,
                    unit_f64(&mut rng) * 1800.0 - 900.0,
                );
            let a = unit_f64(&mut rng) * std::f64::consts::TAU;
            let aim = g.new_york(p, a, RoadClass::Street);
            let u = dir(aim.angle);
            // Along the grid angle (or against it): block length; across: width.
            let along = (u.dot(dir(30f64.to_radians()))).abs() > 0.5;
            let s = if along { 80.0 } else { 240.0 };
            assert!(
                (0.5 * s - 1e-9..1.5 * s + 1e-9).contains(&aim.length),
                "{}",
                aim.length
            );
            let t = (p + u * aim.length - origin).dot(u) / s;
            assert!((t - t.round()).abs() < 1e-9, "{t}");
        }
        params.streets.clear();
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let aim = g.new_york(origin + DVec2::new(13.0, 7.0), 0.5, RoadClass::Street);
        assert_eq!(aim.length, 80.0);
    }

    #[test]
    fn paris_concentric_step_stays_on_the_circle() {
        let params = RoadParams {
            pattern: Pattern::Paris,
            paris_centre: Some([0.0, 0.0]),
            ..RoadParams::default()
        };
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let p = DVec2::new(500.0, 0.0);
        let aim = g.paris(p, FRAC_PI_2, RoadClass::Street);
        let q = p + dir(aim.angle) * aim.length;
        assert!((q.length() - 500.0).abs() < 1e-6);
        let radial = g.paris(p, 0.1, RoadClass::Street);
        assert!(radial.angle.abs() < 1e-12);
    }

    #[test]
    fn streets_branch_only_above_the_threshold() {
        let params = RoadParams {
            street_branch_probability: 1.0,
            ..RoadParams::default()
        };
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        let rule = RuleAttr::new(RoadClass::Street, 1, 0.0);
        let dense = RoadAttr::new(DVec2::ZERO, 0.0, 10.0, RoadClass::Street);
        let [_, b1, b2] = g.successors(&rule, &dense, &mut rng);
        assert!(b1.delay >= 0 && b2.delay >= 0);
        let empty = RoadAttr::new(DVec2::new(1900.0, 1900.0), 0.0, 10.0, RoadClass::Street);
        let [c, b1, b2] = g.successors(&rule, &empty, &mut rng);
        assert!(c.delay < 0 && b1.delay < 0 && b2.delay < 0);
        // From a highway, street branches wait the extra delay.
        let hw = RuleAttr::new(RoadClass::Highway, 0, 0.0);
        let params = RoadParams {
            highway_branch_probability: 0.0,
            ..params
        };
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let road = RoadAttr::new(DVec2::ZERO, 0.0, 10.0, RoadClass::Highway);
        let [_, b1, _] = g.successors(&hw, &road, &mut rng);
        assert_eq!(b1.delay, params.branch_delay + params.highway_street_delay);
        assert_eq!(b1.rule.class, RoadClass::Street);
    }

    #[test]
    fn a_highway_turns_at_most_its_total_bound() {
        let params = RoadParams {
            highway_max_total_turn_deg: 10.0,
            highway_branch_probability: 0.0,
            ..RoadParams::default()
        };
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        // Heading north at (1000, 0): the population (at the origin) pulls west.
        let rule = RuleAttr::new(RoadClass::Highway, 0, FRAC_PI_2);
        let road = RoadAttr::new(
            DVec2::new(1000.0, -10.0),
            FRAC_PI_2,
            10.0,
            RoadClass::Highway,
        );
        let [c, _, _] = g.successors(&rule, &road, &mut rng);
        let off = c.road.angle - FRAC_PI_2;
        assert!(off > 0.0 && off <= 10f64.to_radians() + 1e-12, "{off}");
        // Without the bound it turns further.
        let free = DefaultGoals::new(
            &RoadParams {
                highway_max_total_turn_deg: 180.0,
                ..params
            },
            &flat(),
        )
        .unwrap();
        let [c, _, _] = free.successors(&rule, &road, &mut rng);
        assert!(
            c.road.angle - FRAC_PI_2 > 10f64.to_radians(),
            "{}",
            c.road.angle
        );
    }

    #[test]
    fn a_street_link_bends_and_branches_only_at_its_end() {
        let mut streets = std::collections::BTreeMap::new();
        streets.insert(
            Pattern::Basic,
            crate::StreetRules {
                branch_probability: 1.0,
                crossroads_probability: 1.0,
                segments_per_link: 3,
                curve_deg: 20.0,
                ..crate::StreetRules::default()
            },
        );
        let params = RoadParams {
            street_deviation_deg: 0.0,
            streets,
            ..RoadParams::default()
        };
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(2);
        let rule = RuleAttr {
            turn: 0.2,
            scale: 1.5,
            ..RuleAttr::new(RoadClass::Street, 1, 0.0)
        };
        let road = RoadAttr::new(DVec2::ZERO, 0.0, 30.0, RoadClass::Street);
        // Segments 1 and 2 of the link: bend by the turn, a third of the link, no branch.
        for age in [0, 1] {
            let [c, b1, b2] = g.successors(&RuleAttr { age, ..rule }, &road, &mut rng);
            assert!((c.road.angle - 0.2).abs() < 1e-12, "{}", c.road.angle);
            assert!((c.road.length - 1.5 * params.street_length_m / 3.0).abs() < 1e-9);
            assert!(c.delay >= 0 && b1.delay < 0 && b2.delay < 0);
        }
        // Segment 3 ends the link: both branches, a new link drawn for the continuation.
        let [c, b1, b2] = g.successors(&RuleAttr { age: 2, ..rule }, &road, &mut rng);
        assert!(c.delay >= 0 && b1.delay >= 0 && b2.delay >= 0);
        assert!(c.rule.turn.abs() <= 20f64.to_radians());
        assert!(c.road.angle.abs() < 1e-12, "a new link starts straight on");
    }

    #[test]
    fn a_street_goes_through_a_crossing_only_by_its_rule() {
        let mut streets = std::collections::BTreeMap::new();
        let rules = crate::StreetRules {
            cross_through_probability: 1.0,
            ..crate::StreetRules::default()
        };
        streets.insert(Pattern::Basic, rules);
        let params = RoadParams {
            streets,
            ..RoadParams::default()
        };
        let g = DefaultGoals::new(&params, &flat()).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let rule = RuleAttr::new(RoadClass::Street, 1, 0.0);
        let mut road = RoadAttr::new(DVec2::ZERO, 0.0, 30.0, RoadClass::Street);
        road.snapped = true;
        road.crossed = true;
        let [c, _, _] = g.successors(&rule, &road, &mut rng);
        assert!(c.delay >= 0, "goes on through the crossing");
        // A snap to a junction or a road still ends it.
        road.crossed = false;
        let [c, b1, b2] = g.successors(&rule, &road, &mut rng);
        assert!(c.delay < 0 && b1.delay < 0 && b2.delay < 0);
    }
}
