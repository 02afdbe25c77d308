//! How the streets of one road pattern grow: branching, crossroads against T-junctions,
//! culs-de-sac, curved streets made of several short segments, and the spread of street
//! lengths (Parish & Müller §3.2.2: the rules of a pattern set the parameters of the
//! ideal successor; the local constraints then adjust them).
//!
//! A street between two branch points is a *link* of
//! [`segments_per_link`](StreetRules::segments_per_link) segments. When a link starts, the
//! global goals draw its length (log-normal around the pattern's street length, spread
//! [`length_sigma`](StreetRules::length_sigma)) and its bend (a heading change per
//! segment, uniform in ± [`curve_deg`](StreetRules::curve_deg)), and carry both in the
//! road's [`RuleAttr`](crate::RuleAttr). Its segments then follow an arc, so the street
//! between junctions is curved (circuity above 1, as in organic and radial towns), and
//! only the link's last segment end is a branch point. There the street branches with
//! [`branch_probability`](StreetRules::branch_probability): to both sides (a crossroads)
//! with [`crossroads_probability`](StreetRules::crossroads_probability), else to one
//! side drawn at random (a T); or it ends, with
//! [`dead_end_probability`](StreetRules::dead_end_probability) (a cul-de-sac): at any of
//! its branch points, or, with [`DeadEndLinks::First`], only at the end of its first link,
//! so that culs-de-sac are short side streets and never end a growth front. A street
//! that crosses an existing road goes on through the crossing with
//! [`cross_through_probability`](StreetRules::cross_through_probability), else it ends
//! there as §3.3.1 has it.
//!
//! ## Guarantees
//! * Every draw comes from the derivation's seeded generator, in a fixed order.
//! * [`StreetRules::validate`] refuses a NaN, a probability outside [0, 1], a negative
//!   spread or bend, a bend of 60° or more and 0 or more than 64 segments per link.
//!
//! ## Limitations
//! * The bend is constant along a link (an arc); streets whose curvature changes
//!   within one link (an S) come only from the pattern's own per-segment deviation
//!   ([`RoadParams::street_deviation_deg`](crate::RoadParams::street_deviation_deg) for
//!   Basic).
//!
//! ## References
//! * Y. I. H. Parish, P. Müller, *Procedural Modeling of Cities*, SIGGRAPH 2001, §3.2.2
//!   (patterns; "the rule set … may contain … probability of branching"), Fig. 7.
//! * G. Boeing, *Urban spatial order*, Applied Network Science 4:67 (2019): the measures
//!   these knobs are tuned against (shares of dead ends and four-way junctions, circuity,
//!   median segment length).

use polis_lsystem::rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use crate::error::{Result, RoadError};
use crate::goals::unit_f64;

/// The street rules of one pattern (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StreetRules {
    /// Probability that a street's branch point grows branches, in [0, 1]. Default: 0.99.
    pub branch_probability: f64,
    /// Of the branch points that branch, the share that branch to both sides (a
    /// crossroads); the others branch to one side (a T), in [0, 1]. Default: 0.82.
    pub crossroads_probability: f64,
    /// Probability that a street ends at a branch point with nothing after it (a
    /// cul-de-sac), in [0, 1]. Default: 0.
    pub dead_end_probability: f64,
    /// Which branch points of a street may end it
    /// ([`dead_end_probability`](Self::dead_end_probability)): any of them, or only the
    /// end of its first link. Default: [`DeadEndLinks::Any`].
    pub dead_end_links: DeadEndLinks,
    /// Probability that a street whose segment crossed an existing road goes on through
    /// the crossing (a four-way junction, as grid streets cross avenues) instead of
    /// ending there (a T, §3.3.1's default), in [0, 1]. Default: 0.
    pub cross_through_probability: f64,
    /// Segments per link (street between two branch points), 1 to 64. Default: 1.
    pub segments_per_link: u32,
    /// Largest heading change per segment of a link, degrees in [0, 60): each link draws
    /// its bend uniformly in ± this. Default: 0 (straight links).
    pub curve_deg: f64,
    /// Spread of link lengths: the length is the pattern's street length times
    /// `exp(σ · z)`, z standard normal (the median stays the street length); ≥ 0, at most
    /// 2. Default: 0.
    pub length_sigma: f64,
    /// New York only: street segments end on a city-wide lattice of the pattern's block
    /// length and width (lines through the axiom's start, along and across the grid
    /// angle), so the grids that growth fronts from different highway points lay down
    /// line up into whole blocks instead of cutting each other's blocks short. Each
    /// segment runs to the next lattice line at least half a block ahead (its length is
    /// 0.5–1.5 blocks). Needs one segment per link and no length spread to stay on the
    /// lattice; a local grid-angle map bends the lattice with it. Default: false.
    pub lattice: bool,
}

impl Default for StreetRules {
    fn default() -> Self {
        StreetRules {
            branch_probability: 0.99,
            crossroads_probability: 0.82,
            dead_end_probability: 0.0,
            dead_end_links: DeadEndLinks::Any,
            cross_through_probability: 0.0,
            segments_per_link: 1,
            curve_deg: 0.0,
            length_sigma: 0.0,
            lattice: false,
        }
    }
}

/// Which links of a street may end in a cul-de-sac
/// ([`StreetRules::dead_end_links`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DeadEndLinks {
    /// Any link: a street may end at any of its branch points. With a high dead-end
    /// probability this is a branching process near extinction: whether a growth front
    /// lives on is left to a few early draws, so the network's size (and with it its
    /// statistics) swings widely from seed to seed, and land is left without streets.
    #[default]
    Any,
    /// Only the first link: a street that ends is a side street one link long (a
    /// cul-de-sac off the street it branched from); a street past its first link always
    /// goes on until a road, the population or the map stops it, so culs-de-sac never
    /// cut off a growth front and the streets fill their land on every seed.
    First,
}

/// What happens at a street's branch point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchChoice {
    /// The street ends here, with no branch (a cul-de-sac).
    DeadEnd,
    /// The street goes on; branches to the left and to the right as flagged.
    Go {
        /// A branch to the left (counter-clockwise side).
        left: bool,
        /// A branch to the right.
        right: bool,
    },
}

impl StreetRules {
    /// The rules equivalent to independent branching on each side with probability `p`
    /// (the generator's behaviour where a pattern has no rules): branch with
    /// `1 − (1 − p)²`, both sides with `p² / (1 − (1 − p)²)` of those.
    pub fn per_side(p: f64) -> Self {
        let any = 1.0 - (1.0 - p) * (1.0 - p);
        StreetRules {
            branch_probability: any,
            crossroads_probability: if any > 0.0 {
                (p * p / any).min(1.0)
            } else {
                0.0
            },
            ..StreetRules::default()
        }
    }

    /// Checks every field against its documented range.
    ///
    /// # Errors
    /// [`RoadError::InvalidParameter`] naming the field (`streets.<field>`).
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, v: f64, want: &str| RoadError::InvalidParameter {
            name,
            reason: format!("{v} is out of range; use {want}"),
        };
        for (name, v) in [
            ("streets.branch_probability", self.branch_probability),
            (
                "streets.crossroads_probability",
                self.crossroads_probability,
            ),
            ("streets.dead_end_probability", self.dead_end_probability),
            (
                "streets.cross_through_probability",
                self.cross_through_probability,
            ),
        ] {
            if !(0.0..=1.0).contains(&v) {
                return Err(bad(name, v, "a probability in [0, 1]"));
            }
        }
        if !(1..=64).contains(&self.segments_per_link) {
            return Err(bad(
                "streets.segments_per_link",
                f64::from(self.segments_per_link),
                "1 to 64 segments",
            ));
        }
        if !(self.curve_deg.is_finite() && (0.0..60.0).contains(&self.curve_deg)) {
            return Err(bad(
                "streets.curve_deg",
                self.curve_deg,
                "degrees in [0, 60)",
            ));
        }
        if !(self.length_sigma.is_finite() && (0.0..=2.0).contains(&self.length_sigma)) {
            return Err(bad(
                "streets.length_sigma",
                self.length_sigma,
                "a spread in [0, 2]",
            ));
        }
        Ok(())
    }

    /// Draws a new link: its bend per segment (radians) and its length factor.
    pub fn draw_link(&self, rng: &mut Pcg64Mcg) -> (f64, f64) {
        let turn = (2.0 * unit_f64(rng) - 1.0) * self.curve_deg.to_radians();
        let scale = if self.length_sigma > 0.0 {
            (self.length_sigma * standard_normal(rng)).exp()
        } else {
            1.0
        };
        (turn, scale)
    }

    /// Decides what happens at the branch point ending a street's first link (three
    /// draws, always, so the generator's sequence does not depend on the outcome); the
    /// same as [`branch_at`](Self::branch_at) with `first_link` true.
    pub fn branch(&self, rng: &mut Pcg64Mcg) -> BranchChoice {
        self.branch_at(true, rng)
    }

    /// Decides what happens at a branch point, `first_link` telling whether it ends the
    /// street's first link (three draws, always, so the generator's sequence does not
    /// depend on the outcome). Past the first link, a street ends only when
    /// [`dead_end_links`](Self::dead_end_links) is [`DeadEndLinks::Any`].
    pub fn branch_at(&self, first_link: bool, rng: &mut Pcg64Mcg) -> BranchChoice {
        let (r_end, r_branch, r_kind) = (unit_f64(rng), unit_f64(rng), unit_f64(rng));
        let may_end = first_link || self.dead_end_links == DeadEndLinks::Any;
        if may_end && r_end < self.dead_end_probability {
            return BranchChoice::DeadEnd;
        }
        if r_branch >= self.branch_probability {
            return BranchChoice::Go {
                left: false,
                right: false,
            };
        }
        if r_kind < self.crossroads_probability {
            return BranchChoice::Go {
                left: true,
                right: true,
            };
        }
        // One side: the remaining part of the draw picks which, evenly.
        let left =
            (r_kind - self.crossroads_probability) < 0.5 * (1.0 - self.crossroads_probability);
        BranchChoice::Go { left, right: !left }
    }
}

/// A standard normal number (Box–Muller; two uniform draws).
pub fn standard_normal(rng: &mut Pcg64Mcg) -> f64 {
    let u1 = unit_f64(rng).max(1e-300);
    let u2 = unit_f64(rng);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn branch_shares_follow_the_probabilities() {
        let r = StreetRules {
            branch_probability: 0.8,
            crossroads_probability: 0.25,
            dead_end_probability: 0.1,
            ..StreetRules::default()
        };
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        let n = 20_000;
        let (mut dead, mut none, mut cross, mut left, mut right) = (0, 0, 0, 0, 0);
        for _ in 0..n {
            match r.branch(&mut rng) {
                BranchChoice::DeadEnd => dead += 1,
                BranchChoice::Go {
                    left: false,
                    right: false,
                } => none += 1,
                BranchChoice::Go {
                    left: true,
                    right: true,
                } => cross += 1,
                BranchChoice::Go { left: true, .. } => left += 1,
                BranchChoice::Go { .. } => right += 1,
            }
        }
        let f = |k: i32| f64::from(k) / f64::from(n);
        assert!((f(dead) - 0.1).abs() < 0.01);
        assert!((f(none) - 0.9 * 0.2).abs() < 0.015);
        assert!((f(cross) - 0.9 * 0.8 * 0.25).abs() < 0.015);
        assert!((f(left) - 0.9 * 0.8 * 0.375).abs() < 0.015);
        assert!((f(right) - f(left)).abs() < 0.02);
    }

    /// With `First`, a street past its first link never ends, and the draws (so the
    /// generator's sequence) are the same as with `Any`; on the first link both agree.
    #[test]
    fn dead_ends_only_on_first_links() {
        let any = StreetRules {
            dead_end_probability: 0.4,
            ..StreetRules::default()
        };
        let first = StreetRules {
            dead_end_links: DeadEndLinks::First,
            ..any
        };
        let (mut ra, mut rf) = (Pcg64Mcg::seed_from_u64(3), Pcg64Mcg::seed_from_u64(3));
        let mut ended_any = 0;
        for i in 0..2_000 {
            let on_first = i % 2 == 0;
            let a = any.branch_at(on_first, &mut ra);
            let f = first.branch_at(on_first, &mut rf);
            if on_first {
                assert_eq!(a, f);
            } else {
                assert_ne!(f, BranchChoice::DeadEnd);
                if a == BranchChoice::DeadEnd {
                    ended_any += 1;
                } else {
                    assert_eq!(a, f);
                }
            }
        }
        assert!(ended_any > 300, "{ended_any}");
        assert_eq!(ra, rf);
        assert_eq!(any.branch(&mut ra), any.branch_at(true, &mut rf));
    }

    #[test]
    fn per_side_matches_independent_sides() {
        let r = StreetRules::per_side(0.9);
        assert!((r.branch_probability - 0.99).abs() < 1e-12);
        // Both sides: 0.81 of all branch points.
        assert!((r.branch_probability * r.crossroads_probability - 0.81).abs() < 1e-12);
        let none = StreetRules::per_side(0.0);
        assert_eq!(none.branch_probability, 0.0);
        assert_eq!(none.crossroads_probability, 0.0);
    }

    #[test]
    fn link_lengths_have_the_median_and_bends_the_bound() {
        let r = StreetRules {
            curve_deg: 20.0,
            length_sigma: 0.4,
            ..StreetRules::default()
        };
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let mut scales = Vec::new();
        for _ in 0..4001 {
            let (turn, scale) = r.draw_link(&mut rng);
            assert!(turn.abs() <= 20f64.to_radians());
            assert!(scale > 0.0 && scale.is_finite());
            scales.push(scale);
        }
        scales.sort_by(f64::total_cmp);
        assert!((scales[2000] - 1.0).abs() < 0.05, "{}", scales[2000]);
        // σ of the logarithm.
        let logs: Vec<f64> = scales.iter().map(|s| s.ln()).collect();
        let var = logs.iter().map(|x| x * x).sum::<f64>() / logs.len() as f64;
        assert!((var.sqrt() - 0.4).abs() < 0.03, "{}", var.sqrt());
    }

    #[test]
    fn bad_rules_are_refused_by_name() {
        for (r, name) in [
            (
                StreetRules {
                    branch_probability: 1.5,
                    ..StreetRules::default()
                },
                "streets.branch_probability",
            ),
            (
                StreetRules {
                    segments_per_link: 0,
                    ..StreetRules::default()
                },
                "streets.segments_per_link",
            ),
            (
                StreetRules {
                    curve_deg: f64::NAN,
                    ..StreetRules::default()
                },
                "streets.curve_deg",
            ),
            (
                StreetRules {
                    length_sigma: -1.0,
                    ..StreetRules::default()
                },
                "streets.length_sigma",
            ),
        ] {
            match r.validate() {
                Err(RoadError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
                other => panic!("{other:?}"),
            }
        }
        assert!(StreetRules::default().validate().is_ok());
    }
}
