//! The road builders' rules and their probabilities, read from the report's JSON.
//!
//! A rule set has four groups, each a list of `{ "action", "probability" }` rules (the
//! report's Snippet 4, without its `//` comments, which JSON does not allow):
//!
//! | group | actions | asked when |
//! |---|---|---|
//! | `movementActionRules` | `CS` (continue straight), `TR` (turn right), `TL` (turn left), `STOP` | a builder is popped from the queue |
//! | `branchOutRules` | `doBranchOut`, `doNotBranchOut` | twice per pop: left, then right |
//! | `crossIntersectionRules` | `doCrossIntersection`, `doNotCrossIntersection` | a builder steps onto an existing street |
//! | `deadEndRules` | `doAllowDeadEnd`, `doNotAllowDeadEnd` | a builder's street would end in a dead end |
//!
//! Every action of a group appears exactly once, every probability is in `[0, 1]`, and
//! the probabilities of a group add up to 1 (within [`PROBABILITY_SUM_TOLERANCE`]). The
//! report's selection (Snippet 5) draws `r` uniform in `[0, 1)` and takes the first rule
//! whose running sum exceeds `r`; its "rules do not add up to at least 1" exception is a
//! [`GridError::ProbabilitySum`] here, found when the rules are read, not mid-growth.
//!
//! The report's Downtown and Residential sets ship with the crate
//! ([`GridRules::downtown`], [`GridRules::residential`], [`DOWNTOWN_JSON`],
//! [`RESIDENTIAL_JSON`]).

use rand_pcg::Pcg64Mcg;
use serde::{Deserialize, Serialize};

use super::error::{GridError, Result};
use crate::goals::unit_f64;

/// The report's Downtown rule set (Snippet 4), as shipped JSON.
pub const DOWNTOWN_JSON: &str = include_str!("downtown.json");

/// The report's Residential rule set (Snippet 4), as shipped JSON.
pub const RESIDENTIAL_JSON: &str = include_str!("residential.json");

/// How far from 1 the probabilities of a rule group may add up (rounding of decimal
/// fractions such as `0.95 + 0.01 + 0.01 + 0.03`).
pub const PROBABILITY_SUM_TOLERANCE: f64 = 1e-6;

/// An action of one rule group: its JSON name and the full list of the group's actions.
pub trait RuleAction: Copy + PartialEq + 'static {
    /// The group's JSON field name.
    const GROUP: &'static str;
    /// Every action of the group, in the report's order.
    const ALL: &'static [Self];
    /// The action's JSON name.
    fn name(self) -> &'static str;
}

/// A movement action (`movementActionRules`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Movement {
    /// `CS`: one grid step ahead.
    #[serde(rename = "CS")]
    ContinueStraight,
    /// `TR`: turn 90° right, then one grid step.
    #[serde(rename = "TR")]
    TurnRight,
    /// `TL`: turn 90° left, then one grid step.
    #[serde(rename = "TL")]
    TurnLeft,
    /// `STOP`: the builder stops where it is.
    #[serde(rename = "STOP")]
    Stop,
}

impl RuleAction for Movement {
    const GROUP: &'static str = "movementActionRules";
    const ALL: &'static [Self] = &[
        Movement::ContinueStraight,
        Movement::TurnRight,
        Movement::TurnLeft,
        Movement::Stop,
    ];
    fn name(self) -> &'static str {
        match self {
            Movement::ContinueStraight => "CS",
            Movement::TurnRight => "TR",
            Movement::TurnLeft => "TL",
            Movement::Stop => "STOP",
        }
    }
}

macro_rules! yes_no_action {
    ($(#[$doc:meta])* $t:ident, $group:literal, $yes:ident = $yes_name:literal, $no:ident = $no_name:literal) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
        pub enum $t {
            #[doc = concat!("`", $yes_name, "`.")]
            #[serde(rename = $yes_name)]
            $yes,
            #[doc = concat!("`", $no_name, "`.")]
            #[serde(rename = $no_name)]
            $no,
        }
        impl RuleAction for $t {
            const GROUP: &'static str = $group;
            const ALL: &'static [Self] = &[$t::$yes, $t::$no];
            fn name(self) -> &'static str {
                match self {
                    $t::$yes => $yes_name,
                    $t::$no => $no_name,
                }
            }
        }
    };
}

yes_no_action!(
    /// Whether a builder branches out to one side (`branchOutRules`).
    BranchOut, "branchOutRules", Do = "doBranchOut", DoNot = "doNotBranchOut"
);
yes_no_action!(
    /// Whether a builder that meets a street crosses it (`crossIntersectionRules`).
    CrossIntersection,
    "crossIntersectionRules",
    Do = "doCrossIntersection",
    DoNot = "doNotCrossIntersection"
);
yes_no_action!(
    /// Whether a builder may leave a dead end (`deadEndRules`).
    DeadEnd, "deadEndRules", Allow = "doAllowDeadEnd", DoNotAllow = "doNotAllowDeadEnd"
);

/// One rule: an action and its probability.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rule<A> {
    /// The action.
    pub action: A,
    /// Its probability, in `[0, 1]`.
    pub probability: f64,
}

/// A rule set in the report's JSON shape: a name and four rule groups.
///
/// Read with [`GridRules::from_json`] (which validates); a value built by hand is checked
/// by [`GridRules::validate`] before growth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct GridRules {
    /// The area type (`"Downtown"`, `"Residential"`, or any name of your own).
    #[serde(rename = "type")]
    pub name: String,
    /// Continue straight / turn right / turn left / stop.
    pub movement_action_rules: Vec<Rule<Movement>>,
    /// Branch out to a side or not (asked for the left, then the right side).
    pub branch_out_rules: Vec<Rule<BranchOut>>,
    /// Cross an intersection or end there in a T.
    pub cross_intersection_rules: Vec<Rule<CrossIntersection>>,
    /// Allow a dead end or try the other movements first.
    pub dead_end_rules: Vec<Rule<DeadEnd>>,
}

impl Default for GridRules {
    /// The report's Downtown rules.
    fn default() -> Self {
        GridRules::downtown()
    }
}

/// Checks one group: every action once, probabilities in `[0, 1]` adding up to 1.
fn validate_group<A: RuleAction>(rules: &[Rule<A>]) -> Result<()> {
    for r in rules {
        if !(0.0..=1.0).contains(&r.probability) {
            return Err(GridError::InvalidProbability {
                group: A::GROUP,
                action: r.action.name(),
                value: r.probability,
            });
        }
    }
    for &a in A::ALL {
        match rules.iter().filter(|r| r.action == a).count() {
            0 => {
                return Err(GridError::MissingAction {
                    group: A::GROUP,
                    action: a.name(),
                });
            }
            1 => {}
            _ => {
                return Err(GridError::DuplicateAction {
                    group: A::GROUP,
                    action: a.name(),
                });
            }
        }
    }
    let sum: f64 = rules.iter().map(|r| r.probability).sum();
    if (sum - 1.0).abs() > PROBABILITY_SUM_TOLERANCE {
        return Err(GridError::ProbabilitySum {
            group: A::GROUP,
            sum,
            tolerance: PROBABILITY_SUM_TOLERANCE,
        });
    }
    Ok(())
}

/// The report's `getActionFromRules` (Snippet 5): `r` uniform in `[0, 1)`, the first rule
/// whose running sum exceeds `r`. Rules of probability 0 are never chosen; should
/// rounding leave `r` past the last running sum, the last rule with a positive
/// probability is taken.
fn choose<A: RuleAction>(rules: &[Rule<A>], rng: &mut Pcg64Mcg) -> A {
    let r = unit_f64(rng);
    let mut acc = 0.0;
    let mut last = None;
    for rule in rules {
        if rule.probability > 0.0 {
            acc += rule.probability;
            last = Some(rule.action);
            if r < acc {
                return rule.action;
            }
        }
    }
    // Validated groups sum to 1, so some rule is positive; fall back to the first action
    // of the group for an unvalidated, all-zero group.
    last.unwrap_or(A::ALL[0])
}

/// The probability of `action` in `rules` (0 when absent).
fn probability_of<A: RuleAction>(rules: &[Rule<A>], action: A) -> f64 {
    rules
        .iter()
        .filter(|r| r.action == action)
        .map(|r| r.probability)
        .sum()
}

impl GridRules {
    /// Reads and validates one rule set (a JSON object of the report's shape).
    ///
    /// # Errors
    /// [`GridError::Json`] for text that is not such an object; the errors of
    /// [`validate`](Self::validate) for bad probabilities or actions.
    pub fn from_json(text: &str) -> Result<GridRules> {
        let rules: GridRules = serde_json::from_str(text)?;
        rules.validate()?;
        Ok(rules)
    }

    /// Reads and validates a list of rule sets (the report's file: a JSON array of
    /// objects), in file order.
    ///
    /// # Errors
    /// As [`from_json`](Self::from_json), for the first bad set.
    pub fn list_from_json(text: &str) -> Result<Vec<GridRules>> {
        let list: Vec<GridRules> = serde_json::from_str(text)?;
        for r in &list {
            r.validate()?;
        }
        Ok(list)
    }

    /// The set named `name` (ASCII case-insensitive) in `list`.
    ///
    /// # Errors
    /// [`GridError::UnknownRuleSet`] when none has that name.
    pub fn find<'a>(list: &'a [GridRules], name: &str) -> Result<&'a GridRules> {
        list.iter()
            .find(|r| r.name.eq_ignore_ascii_case(name))
            .ok_or_else(|| GridError::UnknownRuleSet {
                name: name.to_owned(),
                known: list
                    .iter()
                    .map(|r| r.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The report's Downtown rules (shipped as [`DOWNTOWN_JSON`]): mostly straight,
    /// branching often, crossing half the intersections, no dead ends.
    pub fn downtown() -> GridRules {
        shipped(DOWNTOWN_JSON)
    }

    /// The report's Residential rules (shipped as [`RESIDENTIAL_JSON`]): long straight
    /// streets that may stop, fewer branches, T junctions, dead ends allowed.
    pub fn residential() -> GridRules {
        shipped(RESIDENTIAL_JSON)
    }

    /// Checks every group: each action exactly once, probabilities in `[0, 1]`, adding up
    /// to 1 within [`PROBABILITY_SUM_TOLERANCE`].
    ///
    /// # Errors
    /// [`GridError::InvalidProbability`], [`GridError::MissingAction`],
    /// [`GridError::DuplicateAction`], [`GridError::ProbabilitySum`].
    pub fn validate(&self) -> Result<()> {
        validate_group(&self.movement_action_rules)?;
        validate_group(&self.branch_out_rules)?;
        validate_group(&self.cross_intersection_rules)?;
        validate_group(&self.dead_end_rules)
    }

    /// Draws the next movement (the report's `getMovementAction`).
    pub fn movement(&self, rng: &mut Pcg64Mcg) -> Movement {
        choose(&self.movement_action_rules, rng)
    }

    /// Draws whether to branch out to one side (`shouldBranchOut`).
    pub fn should_branch_out(&self, rng: &mut Pcg64Mcg) -> bool {
        choose(&self.branch_out_rules, rng) == BranchOut::Do
    }

    /// Draws whether to cross an intersection.
    pub fn should_cross(&self, rng: &mut Pcg64Mcg) -> bool {
        choose(&self.cross_intersection_rules, rng) == CrossIntersection::Do
    }

    /// Draws whether a dead end is allowed (`allowDeadEnd`).
    pub fn allow_dead_end(&self, rng: &mut Pcg64Mcg) -> bool {
        choose(&self.dead_end_rules, rng) == DeadEnd::Allow
    }

    /// The probability that a dead end is allowed (`doAllowDeadEnd`).
    pub fn dead_end_probability(&self) -> f64 {
        probability_of(&self.dead_end_rules, DeadEnd::Allow)
    }

    /// The movements a builder tries, in rule order, when the no-dead-end rule forbids
    /// it to stop (the report's `getAvailableMovementActions`): every movement with a
    /// positive probability except `STOP`.
    pub fn available_movements(&self) -> impl Iterator<Item = Movement> + '_ {
        self.movement_action_rules
            .iter()
            .filter(|r| r.probability > 0.0 && r.action != Movement::Stop)
            .map(|r| r.action)
    }
}

/// Parses a rule set shipped with the crate.
#[allow(clippy::expect_used)]
fn shipped(text: &str) -> GridRules {
    // A compile-time constant of this crate, parsed and validated by the unit tests below:
    // never user input.
    serde_json::from_str(text).expect("the shipped grid-builder rules are valid JSON")
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn shipped_sets_parse_validate_and_match_the_report() {
        let d = GridRules::from_json(DOWNTOWN_JSON).unwrap();
        let r = GridRules::from_json(RESIDENTIAL_JSON).unwrap();
        assert_eq!(d, GridRules::downtown());
        assert_eq!(r, GridRules::residential());
        assert_eq!(d.name, "Downtown");
        assert_eq!(r.name, "Residential");
        assert_eq!(
            probability_of(&d.movement_action_rules, Movement::ContinueStraight),
            0.8
        );
        assert_eq!(
            probability_of(&r.movement_action_rules, Movement::Stop),
            0.03
        );
        assert_eq!(probability_of(&d.branch_out_rules, BranchOut::Do), 0.2);
        assert_eq!(probability_of(&r.branch_out_rules, BranchOut::Do), 0.15);
        assert_eq!(
            probability_of(&d.cross_intersection_rules, CrossIntersection::Do),
            0.5
        );
        assert_eq!(
            probability_of(&r.cross_intersection_rules, CrossIntersection::Do),
            0.05
        );
        assert_eq!(d.dead_end_probability(), 0.0);
        assert_eq!(r.dead_end_probability(), 1.0);
    }

    #[test]
    fn choice_frequencies_follow_the_probabilities() {
        let r = GridRules::residential();
        let mut rng = Pcg64Mcg::seed_from_u64(5);
        let n = 200_000;
        let mut counts = [0usize; 4];
        for _ in 0..n {
            let drawn = r.movement(&mut rng);
            let i = Movement::ALL.iter().position(|&m| m == drawn).unwrap();
            counts[i] += 1;
        }
        for (i, &m) in Movement::ALL.iter().enumerate() {
            let p = probability_of(&r.movement_action_rules, m);
            let f = counts[i] as f64 / n as f64;
            // Five standard deviations of a binomial proportion.
            let sd = (p * (1.0 - p) / n as f64).sqrt();
            assert!((f - p).abs() <= 5.0 * sd + 1e-12, "{m:?}: {f} vs {p}");
        }
        // Zero-probability rules are never drawn.
        let d = GridRules::downtown();
        assert!((0..10_000).all(|_| d.movement(&mut rng) != Movement::Stop));
        assert!((0..10_000).all(|_| !d.allow_dead_end(&mut rng)));
    }

    #[test]
    fn available_movements_skip_stop_and_impossible_moves() {
        let mut r = GridRules::downtown();
        let all: Vec<_> = r.available_movements().collect();
        assert_eq!(
            all,
            [
                Movement::ContinueStraight,
                Movement::TurnRight,
                Movement::TurnLeft
            ]
        );
        r.movement_action_rules[1].probability = 0.0;
        r.movement_action_rules[0].probability = 0.9;
        assert_eq!(
            r.available_movements().collect::<Vec<_>>(),
            [Movement::ContinueStraight, Movement::TurnLeft]
        );
    }
}
