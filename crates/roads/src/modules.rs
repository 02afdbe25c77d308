//! The extended L-system of Parish & Müller (§3.1): modules `R`, `B`, `?I` and the
//! productions p1–p9, on [`polis_lsystem`]'s typed front end.
//!
//! ```text
//! ω : R(0, initialRuleAttr) ?I(initRoadAttr, UNASSIGNED)          (two, back to back)
//! p1: R(del, ruleAttr) : del < 0                                   → ε
//! p2: R(del, ruleAttr) > ?I(roadAttr, state) : state == SUCCEED
//!       {globalGoals(ruleAttr, roadAttr) → pDel[0-2], pRuleAttr[0-2], pRoadAttr[0-2]}
//!                                                                  → B(pDel[1], …) B(pDel[2], …) R(pDel[0], …) ?I(pRoadAttr[0], UNASSIGNED)
//! p3: R(del, ruleAttr) > ?I(roadAttr, state) : state == FAILED     → ε
//! p4: B(del, ruleAttr, roadAttr) : del > 0                         → B(del − 1, ruleAttr, roadAttr)
//! p5: B(del, ruleAttr, roadAttr) : del == 0                        → R(del, ruleAttr) ?I(roadAttr, UNASSIGNED)
//! p6: B(del, ruleAttr, roadAttr) : del < 0                         → ε
//! p7: R(del, ruleAttr) < ?I(roadAttr, state) : del < 0             → ε
//! p8: ?I(roadAttr, state) : state == UNASSIGNED
//!       {localConstraints(roadAttr) adjusts state, roadAttr}       → ?I(roadAttr, state)
//! p9: ?I(roadAttr, state) : state != UNASSIGNED                    → ε
//! ```
//!
//! p8 is the open-L-system communication: `?I` is a communication module, and the
//! environment ([`crate::generator`]) answers every unassigned `?I` after each step by
//! calling [`LocalConstraints`](crate::LocalConstraints) and, on success, inserting the
//! segment into the planar graph. Two departures from the paper's text, both without
//! effect on the network: the turtle modules `+(angle) F(length)` of p2 are not kept in
//! the string (segments carry absolute positions, and the accepted road lives in the graph,
//! so a string of `F`s would only make every step O(all roads) instead of O(growing tips));
//! and p5's brackets `[ ]` are dropped for the same reason (with absolute positions the
//! turtle's push/pop carries no information; `R` and its `?I` stay adjacent, which is all
//! the contexts of p2, p3 and p7 need).

use std::sync::Arc;

use polis_geom::DVec2;
use polis_lsystem::{Command, Module, Production, TypedRules};
use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::goals::GlobalGoals;
use crate::network::RoadClass;

/// The state of an insertion query `?I`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum QueryState {
    /// Not yet answered by the local constraints.
    Unassigned,
    /// Accepted: the segment is in the graph.
    Succeed,
    /// Rejected: the road stops here.
    Failed,
}

/// Rule attributes (`ruleAttr`): what the productions and global goals carry along a road.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RuleAttr {
    /// The class of the road this module grows.
    pub class: RoadClass,
    /// Number of branchings from the axiom to this road.
    pub depth: u32,
    /// Segments grown by this road since it branched.
    pub age: u32,
    /// The direction the road started in, radians (highways keep within
    /// [`RoadParams::highway_max_total_turn_deg`](crate::RoadParams::highway_max_total_turn_deg)
    /// of it).
    pub heading: f64,
    /// The bend of the current street link: heading change per segment, radians
    /// ([`StreetRules`](crate::StreetRules)).
    pub turn: f64,
    /// The length factor of the current street link (1 = the pattern's street length).
    pub scale: f64,
}

impl RuleAttr {
    /// A new road of `class` at branching depth `depth`, starting in direction `heading`
    /// (radians): age 0, a straight link of factor 1.
    pub fn new(class: RoadClass, depth: u32, heading: f64) -> Self {
        RuleAttr {
            class,
            depth,
            age: 0,
            heading,
            turn: 0.0,
            scale: 1.0,
        }
    }
}

/// Road attributes (`roadAttr`): one proposed or accepted segment.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RoadAttr {
    /// Start of the segment (metres).
    pub start: DVec2,
    /// Direction, radians counter-clockwise from +x.
    pub angle: f64,
    /// Length in metres.
    pub length: f64,
    /// Road class.
    pub class: RoadClass,
    /// End of the segment: `start + length · (cos angle, sin angle)` as proposed, the
    /// adjusted end once the local constraints have run.
    pub end: DVec2,
    /// Set by the local constraints: the segment crosses water (a bridge).
    pub bridge: bool,
    /// Set by the local constraints: the segment passes under illegal land (a park, a
    /// slope over the limit) between two portals (a tunnel, [`crate::tunnels`]).
    pub tunnel: bool,
    /// Set by the local constraints: the segment was connected to an existing road or
    /// junction (a crossing); the road stops growing (§3.3.1).
    pub snapped: bool,
    /// Set by the local constraints with `snapped`: the connection is a crossing of an
    /// existing road (not a junction or a road reached by extension), so a street may go
    /// on through it ([`StreetRules::cross_through_probability`](crate::StreetRules::cross_through_probability)).
    pub crossed: bool,
}

impl RoadAttr {
    /// A proposal from `start` in direction `angle` (radians) of `length` metres.
    pub fn new(start: DVec2, angle: f64, length: f64, class: RoadClass) -> Self {
        RoadAttr {
            start,
            angle,
            length,
            class,
            end: start + crate::network::dir(angle) * length,
            bridge: false,
            tunnel: false,
            snapped: false,
            crossed: false,
        }
    }
}

/// One of the three successors `globalGoals` fills in p2: `pDel[i]`, `pRuleAttr[i]`,
/// `pRoadAttr[i]`. Index 0 continues the road, 1 and 2 are branches.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Proposal {
    /// Delay in steps; negative deletes the module (no successor).
    pub delay: i32,
    /// Rule attributes of the successor.
    pub rule: RuleAttr,
    /// The proposed segment (start = end of the current segment).
    pub road: RoadAttr,
}

/// The modules of the road L-system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RoadModule {
    /// `R(del, ruleAttr)`: a growing road end.
    R {
        /// Delay / deletion flag.
        del: i32,
        /// Rule attributes.
        rule: RuleAttr,
    },
    /// `B(del, ruleAttr, roadAttr)`: a branch waiting `del` steps.
    B {
        /// Delay / deletion flag.
        del: i32,
        /// Rule attributes of the branch road.
        rule: RuleAttr,
        /// The branch's first segment.
        road: RoadAttr,
    },
    /// `?I(roadAttr, state)`: the insertion query, answered by the environment.
    I {
        /// The segment.
        road: RoadAttr,
        /// Query state.
        state: QueryState,
    },
}

/// Symbol id of `R`.
pub const SYM_R: u32 = 0;
/// Symbol id of `B`.
pub const SYM_B: u32 = 1;
/// Symbol id of `?I`.
pub const SYM_I: u32 = 2;

impl Module for RoadModule {
    #[inline]
    fn symbol(&self) -> u32 {
        match self {
            RoadModule::R { .. } => SYM_R,
            RoadModule::B { .. } => SYM_B,
            RoadModule::I { .. } => SYM_I,
        }
    }
    #[inline]
    fn command(&self) -> Command {
        match self {
            RoadModule::I { .. } => Command::Communicate,
            _ => Command::None,
        }
    }
}

fn del_of(m: &RoadModule) -> i32 {
    match *m {
        RoadModule::R { del, .. } | RoadModule::B { del, .. } => del,
        RoadModule::I { .. } => 0,
    }
}

fn state_of(m: Option<&RoadModule>) -> Option<QueryState> {
    match m {
        Some(RoadModule::I { state, .. }) => Some(*state),
        _ => None,
    }
}

/// The productions p1–p9 with `goals` called in p2.
///
/// # Errors
/// Only if the engine refused a production (it does not for these).
pub fn road_rules(goals: Arc<dyn GlobalGoals>) -> Result<TypedRules<'static, RoadModule>> {
    let mut rules = TypedRules::new();
    // p1
    rules.add(Production::new(SYM_R, |_, _| {}).when(|m| del_of(m.module()) < 0))?;
    // p2
    rules.add(
        Production::new(SYM_R, move |m, out| {
            let (RoadModule::R { rule, .. }, Some(RoadModule::I { road, .. })) =
                (m.module(), m.right(0))
            else {
                return;
            };
            let [cont, b1, b2] = goals.successors(rule, road, out.rng());
            for b in [b1, b2] {
                out.push(RoadModule::B {
                    del: b.delay,
                    rule: b.rule,
                    road: b.road,
                });
            }
            out.push(RoadModule::R {
                del: cont.delay,
                rule: cont.rule,
            });
            out.push(RoadModule::I {
                road: cont.road,
                state: QueryState::Unassigned,
            });
        })
        .right([SYM_I])
        .when(|m| state_of(m.right(0)) == Some(QueryState::Succeed)),
    )?;
    // p3
    rules.add(
        Production::new(SYM_R, |_, _| {})
            .right([SYM_I])
            .when(|m| state_of(m.right(0)) == Some(QueryState::Failed)),
    )?;
    // p4
    rules.add(
        Production::new(SYM_B, |m, out| {
            if let RoadModule::B { del, rule, road } = *m.module() {
                out.push(RoadModule::B {
                    del: del - 1,
                    rule,
                    road,
                });
            }
        })
        .when(|m| del_of(m.module()) > 0),
    )?;
    // p5
    rules.add(
        Production::new(SYM_B, |m, out| {
            if let RoadModule::B { del, rule, road } = *m.module() {
                out.push(RoadModule::R { del, rule });
                out.push(RoadModule::I {
                    road,
                    state: QueryState::Unassigned,
                });
            }
        })
        .when(|m| del_of(m.module()) == 0),
    )?;
    // p6
    rules.add(Production::new(SYM_B, |_, _| {}).when(|m| del_of(m.module()) < 0))?;
    // p7
    rules.add(
        Production::new(SYM_I, |_, _| {})
            .left([SYM_R])
            .when(|m| m.left(0).is_some_and(|r| del_of(r) < 0)),
    )?;
    // p8 is the environment's answer (communication module); p9:
    rules.add(
        Production::new(SYM_I, |_, _| {})
            .when(|m| state_of(Some(m.module())).is_some_and(|s| s != QueryState::Unassigned)),
    )?;
    Ok(rules)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use polis_lsystem::rand_pcg::Pcg64Mcg;
    use polis_lsystem::{Derivation, DeriveOptions, Environment, TurtleState};

    use super::*;

    /// Goals: the continuation goes on with delay 0 while `age < 2`, then stops; branch 1
    /// waits 2 steps, branch 2 never grows.
    struct Stub;
    impl GlobalGoals for Stub {
        fn axiom(&self) -> Vec<(RuleAttr, RoadAttr)> {
            Vec::new()
        }
        fn successors(&self, rule: &RuleAttr, road: &RoadAttr, _: &mut Pcg64Mcg) -> [Proposal; 3] {
            let next = RoadAttr::new(road.end, road.angle, 10.0, rule.class);
            let r = RuleAttr {
                age: rule.age + 1,
                ..*rule
            };
            [
                Proposal {
                    delay: if rule.age < 2 { 0 } else { -1 },
                    rule: r,
                    road: next,
                },
                Proposal {
                    delay: 2,
                    rule: RuleAttr { age: 10, ..*rule },
                    road: next,
                },
                Proposal {
                    delay: -1,
                    rule: r,
                    road: next,
                },
            ]
        }
    }

    /// Accepts every query.
    struct Accept(usize);
    impl Environment<Vec<RoadModule>> for Accept {
        fn communicate(&mut self, s: &mut Vec<RoadModule>, i: usize, _: &TurtleState) {
            if let Some(RoadModule::I { state, .. }) = s.get_mut(i)
                && *state == QueryState::Unassigned
            {
                *state = QueryState::Succeed;
                self.0 += 1;
            }
        }
    }

    fn syms(s: &[RoadModule]) -> String {
        s.iter()
            .map(|m| match m {
                RoadModule::R { del, .. } => format!("R{del}"),
                RoadModule::B { del, .. } => format!("B{del}"),
                RoadModule::I {
                    state: QueryState::Unassigned,
                    ..
                } => "?".into(),
                RoadModule::I {
                    state: QueryState::Succeed,
                    ..
                } => "S".into(),
                RoadModule::I {
                    state: QueryState::Failed,
                    ..
                } => "F".into(),
            })
            .collect::<Vec<_>>()
            .join(" ")
    }

    #[test]
    fn productions_p1_to_p9() {
        let rules = road_rules(Arc::new(Stub)).unwrap();
        let rule = RuleAttr::new(crate::RoadClass::Street, 0, 0.0);
        let road = RoadAttr::new(DVec2::ZERO, 0.0, 10.0, crate::RoadClass::Street);
        let axiom = vec![
            RoadModule::R { del: 0, rule },
            RoadModule::I {
                road,
                state: QueryState::Unassigned,
            },
        ];
        let mut d = Derivation::new(rules, axiom, DeriveOptions::default());
        let mut env = Accept(0);
        // p8 (environment) answers the axiom, p2 creates B B R ?I, p9 erases the old ?I.
        d.step_with(&mut env).unwrap();
        assert_eq!(syms(d.string()), "B2 B-1 R0 S");
        // p4 decrements, p6 erases the negative branch, p2 again.
        d.step_with(&mut env).unwrap();
        assert_eq!(syms(d.string()), "B1 B2 B-1 R0 S");
        // age 2: the continuation gets del −1 (this stub environment answers its ?I
        // anyway; the generator's does not).
        d.step_with(&mut env).unwrap();
        assert_eq!(syms(d.string()), "B0 B1 B2 B-1 R-1 S");
        // p5 turns B0 into R ?I; p1 and p7 erase the stopped road.
        d.step_with(&mut env).unwrap();
        assert_eq!(syms(d.string()), "R0 S B0 B1");
        assert_eq!(env.0, 5);
    }

    #[test]
    fn failed_query_deletes_the_road() {
        struct Reject;
        impl Environment<Vec<RoadModule>> for Reject {
            fn communicate(&mut self, s: &mut Vec<RoadModule>, i: usize, _: &TurtleState) {
                if let Some(RoadModule::I { state, .. }) = s.get_mut(i) {
                    *state = QueryState::Failed;
                }
            }
        }
        let rules = road_rules(Arc::new(Stub)).unwrap();
        let rule = RuleAttr::new(crate::RoadClass::Street, 0, 0.0);
        let road = RoadAttr::new(DVec2::ZERO, 0.0, 10.0, crate::RoadClass::Street);
        let axiom = vec![
            RoadModule::R { del: 0, rule },
            RoadModule::I {
                road,
                state: QueryState::Unassigned,
            },
        ];
        let mut d = Derivation::new(rules, axiom, DeriveOptions::default());
        d.step_with(&mut Reject).unwrap();
        assert!(d.string().is_empty(), "{}", syms(d.string()));
    }
}
