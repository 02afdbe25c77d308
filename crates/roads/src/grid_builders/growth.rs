//! The report's road creation algorithm (Snippet 3): road builders in a FIFO queue, each
//! pop one stochastic movement, validity constraints, the no-dead-end rule, and
//! branching out to both sides of the builder's previous position.
//!
//! A move from grid point `P` towards `d` ends in one of these outcomes (the report's
//! constraint list, with the cell boundary acting as a street):
//!
//! * **boundary join** — the boundary (or a filament) lies within one step plus the
//!   clearance ahead: the street runs on to it and the builder is done;
//! * **intersection** — the next point `Q` is a street: with the cross-intersection
//!   probability the builder is placed across it (if the point beyond `Q` is valid),
//!   forming a cross junction, otherwise the street ends at `Q` in a T and the builder
//!   is deleted;
//! * **advance** — `Q` is free, clear of the boundary, with no street to its left or
//!   right (exception: a street *ending* there and pointing at `Q`, which is joined),
//!   and the way to it is out of water and parks;
//! * **blocked** — anything else.

use std::collections::VecDeque;

use polis_geom::DVec2;
use rand_pcg::Pcg64Mcg;

use super::lattice::{Dir, Frame, Ground, Site};
use super::rules::{GridRules, Movement};

/// What the builders did (see [`GridReport`](super::GridReport) for the public form).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct Counts {
    pub(crate) pops: u32,
    pub(crate) builders: u32,
    pub(crate) branches: u32,
    pub(crate) crossings: u32,
    pub(crate) t_junctions: u32,
    pub(crate) boundary_joins: u32,
    pub(crate) side_joins: u32,
    pub(crate) blocked: u32,
    pub(crate) rescued: u32,
    pub(crate) dead_ends_allowed: u32,
    pub(crate) dead_ends_pruned: u32,
    pub(crate) pruned_points: u32,
    pub(crate) truncated: bool,
}

/// A road builder: a grid point and the direction it last moved in (the report's
/// `RoadBuilder`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Builder {
    pub(crate) site: usize,
    pub(crate) dir: Dir,
}

/// The outcome of one move (see the module docs).
#[derive(Debug, Clone, Copy)]
enum Step {
    Advance {
        to: usize,
        tips: [Option<Dir>; 2],
    },
    Cross {
        via: usize,
        to: usize,
        tips: [Option<Dir>; 2],
    },
    CrossToBoundary {
        via: usize,
        join: Join,
    },
    JoinStreet {
        at: usize,
    },
    JoinBoundary {
        join: Join,
    },
    Blocked,
}

/// A street from a grid point on to the boundary: where it meets the boundary, and the
/// grid point it passes on the way, if any.
#[derive(Debug, Clone, Copy)]
struct Join {
    hit: DVec2,
    passes: Option<usize>,
}

/// What became of a builder after a move.
enum Fate {
    Continues(Builder),
    Joined,
    Blocked,
}

/// The growth state of one cell.
pub(crate) struct Growth<'g, 'a> {
    pub(crate) frame: Frame,
    pub(crate) sites: &'g mut Vec<Site>,
    pub(crate) joins: &'g mut Vec<(usize, DVec2)>,
    pub(crate) ground: &'g Ground<'a>,
    pub(crate) rules: &'g GridRules,
    pub(crate) rng: Pcg64Mcg,
    pub(crate) clearance: f64,
    pub(crate) queue: &'g mut VecDeque<Builder>,
    /// Queue pops after which the remaining builders are ended (a guard: see `run`).
    pub(crate) max_pops: u32,
    pub(crate) counts: Counts,
}

impl Growth<'_, '_> {
    fn site(&self, k: usize) -> Site {
        self.sites.get(k).copied().unwrap_or_default()
    }

    fn link(&mut self, a: usize, d: Dir, b: usize) {
        self.sites[a].links |= d.bit();
        self.sites[b].links |= d.opposite().bit();
    }

    fn mark(&mut self, k: usize) {
        let born = self.counts.pops;
        let s = &mut self.sites[k];
        s.street = true;
        s.born = born;
    }

    /// Whether the street at `n` ends there, coming from the opposite of `towards`, so
    /// that it points at the grid point beyond it.
    fn tip_towards(&self, n: usize, towards: Dir) -> bool {
        let s = self.site(n);
        s.street && !s.joined && s.links == towards.opposite().bit()
    }

    /// Whether free point `q`, reached from `from` moving towards `d`, is a valid street
    /// position; if so, the sides at which a street ends pointing at it.
    pub(crate) fn fresh(&self, q: usize, d: Dir, from: DVec2) -> Option<[Option<Dir>; 2]> {
        let s = self.site(q);
        if s.street || s.passed {
            return None;
        }
        let qw = self.frame.position(q);
        if !self.ground.clear(qw, self.clearance) || !self.ground.inside(qw) {
            return None;
        }
        let mut tips = [None; 2];
        for (slot, side) in tips.iter_mut().zip([d.left(), d.right()]) {
            if let Some(n) = self.frame.neighbor(q, side)
                && self.site(n).street
            {
                let nw = self.frame.position(n);
                if self.tip_towards(n, side.opposite())
                    && self.ground.first_hit(qw, nw).is_none()
                    && self.ground.legal(qw, nw)
                {
                    *slot = Some(side);
                } else {
                    return None;
                }
            }
        }
        self.ground.legal(from, qw).then_some(tips)
    }

    /// Whether the boundary lies within one step plus the clearance of `p` towards `d`:
    /// `None` if not, else the join if it is legal (out of water and parks, steep enough,
    /// passing no point another join passes) or `Some(None)` if it is not.
    fn boundary_ahead(&self, p: usize, d: Dir) -> Option<Option<Join>> {
        let pw = self.frame.position(p);
        let reach = self.frame.step + self.clearance;
        let (hit, steep) = self
            .ground
            .first_hit(pw, pw + self.frame.vector(d) * reach)?;
        if !steep || !self.ground.legal(pw, hit) {
            return Some(None);
        }
        if pw.distance(hit) < self.frame.step {
            return Some(Some(Join { hit, passes: None }));
        }
        // The join runs past the next grid point.
        Some(match self.frame.neighbor(p, d) {
            Some(q) if !self.site(q).passed && !self.site(q).street => Some(Join {
                hit,
                passes: Some(q),
            }),
            _ => None,
        })
    }

    /// Records a join from site `k`.
    fn add_join(&mut self, k: usize, join: Join) {
        self.sites[k].joined = true;
        if let Some(q) = join.passes {
            self.sites[q].passed = true;
        }
        self.joins.push((k, join.hit));
        self.counts.boundary_joins += 1;
    }

    /// Where a move from `p` towards `d` leads (draws the cross-intersection rule when it
    /// meets a street).
    fn probe(&mut self, p: usize, d: Dir) -> Step {
        let pw = self.frame.position(p);
        if let Some(join) = self.boundary_ahead(p, d) {
            return match join {
                Some(join) => Step::JoinBoundary { join },
                None => Step::Blocked,
            };
        }
        let Some(q) = self.frame.neighbor(p, d) else {
            return Step::Blocked;
        };
        let qw = self.frame.position(q);
        if !self.site(q).street {
            return match self.fresh(q, d, pw) {
                Some(tips) => Step::Advance { to: q, tips },
                None => Step::Blocked,
            };
        }
        if !self.ground.legal(pw, qw) {
            return Step::Blocked;
        }
        // An intersection: cross it or end in a T.
        let through = self.site(q).links & d.bit() != 0;
        if self.rules.should_cross(&mut self.rng) && !through {
            if let Some(join) = self.boundary_ahead(q, d) {
                if let Some(join) = join {
                    return Step::CrossToBoundary { via: q, join };
                }
            } else if let Some(to) = self.frame.neighbor(q, d)
                && let Some(tips) = self.fresh(to, d, qw)
            {
                return Step::Cross { via: q, to, tips };
            }
        }
        Step::JoinStreet { at: q }
    }

    fn join_tips(&mut self, q: usize, tips: [Option<Dir>; 2]) {
        for side in tips.into_iter().flatten() {
            if let Some(n) = self.frame.neighbor(q, side) {
                self.link(q, side, n);
                self.counts.side_joins += 1;
            }
        }
    }

    /// Turns `b` by `m` and moves it; applies the outcome to the map.
    fn apply(&mut self, b: Builder, m: Movement) -> Fate {
        let d = match m {
            Movement::ContinueStraight | Movement::Stop => b.dir,
            Movement::TurnRight => b.dir.right(),
            Movement::TurnLeft => b.dir.left(),
        };
        match self.probe(b.site, d) {
            Step::Advance { to, tips } => {
                self.mark(to);
                self.link(b.site, d, to);
                self.join_tips(to, tips);
                Fate::Continues(Builder { site: to, dir: d })
            }
            Step::Cross { via, to, tips } => {
                self.link(b.site, d, via);
                self.mark(to);
                self.link(via, d, to);
                self.join_tips(to, tips);
                self.counts.crossings += 1;
                Fate::Continues(Builder { site: to, dir: d })
            }
            Step::CrossToBoundary { via, join } => {
                self.link(b.site, d, via);
                self.add_join(via, join);
                self.counts.crossings += 1;
                Fate::Joined
            }
            Step::JoinStreet { at } => {
                self.link(b.site, d, at);
                self.counts.t_junctions += 1;
                Fate::Joined
            }
            Step::JoinBoundary { join } => {
                self.add_join(b.site, join);
                Fate::Joined
            }
            Step::Blocked => Fate::Blocked,
        }
    }

    /// Queues a builder that starts at `site`, joined to the boundary at `hit` by a
    /// street passing the grid points `passes`.
    pub(crate) fn start(
        &mut self,
        site: usize,
        dir: Dir,
        hit: DVec2,
        passes: &[usize],
        tips: [Option<Dir>; 2],
    ) {
        self.mark(site);
        self.join_tips(site, tips);
        self.sites[site].joined = true;
        for &q in passes {
            self.sites[q].passed = true;
        }
        self.joins.push((site, hit));
        self.queue.push_back(Builder { site, dir });
        self.counts.builders += 1;
        self.counts.boundary_joins += 1;
    }

    /// The build loop: pops builders until the queue is empty.
    ///
    /// Every pop either makes a new street point or ends a builder, but pruning frees
    /// points again, so termination is only almost sure; after `max_pops` pops the
    /// builders still queued end where they are, under the dead-end rule.
    pub(crate) fn run(&mut self) {
        while let Some(b) = self.queue.pop_front() {
            if !self.site(b.site).street {
                continue; // its street was pruned away
            }
            if self.counts.pops >= self.max_pops {
                self.counts.truncated = true;
                self.end_stopped(b);
                continue;
            }
            self.counts.pops += 1;
            let m = self.rules.movement(&mut self.rng);
            let fate = if m == Movement::Stop {
                Fate::Blocked
            } else {
                self.apply(b, m)
            };
            match fate {
                Fate::Continues(next) => self.queue.push_back(next),
                Fate::Joined => {}
                Fate::Blocked => self.end(b, m),
            }
            // Branch out of the previous position: first left, then right.
            for side in [b.dir.left(), b.dir.right()] {
                if self.rules.should_branch_out(&mut self.rng) {
                    self.branch(b.site, side);
                }
            }
        }
    }

    /// A builder that stopped or was blocked at `b`: leaves a dead end if the rules
    /// allow one, else tries the other movements, else its street is pruned back to the
    /// last junction.
    fn end(&mut self, b: Builder, tried: Movement) {
        if tried != Movement::Stop {
            self.counts.blocked += 1;
        }
        if self.site(b.site).degree() >= 2 {
            return; // ends at a junction or a join: no dead end
        }
        if self.rules.allow_dead_end(&mut self.rng) {
            self.counts.dead_ends_allowed += 1;
            return;
        }
        let others: Vec<Movement> = self
            .rules
            .available_movements()
            .filter(|&m| m != tried)
            .collect();
        for m in others {
            match self.apply(b, m) {
                Fate::Continues(next) => {
                    self.counts.rescued += 1;
                    self.queue.push_back(next);
                    return;
                }
                Fate::Joined => {
                    self.counts.rescued += 1;
                    return;
                }
                Fate::Blocked => {}
            }
        }
        self.prune(b.site);
    }

    /// Ends a builder without moving it (after the guard): a dead end stays only if the
    /// rules allow it.
    fn end_stopped(&mut self, b: Builder) {
        if self.site(b.site).degree() >= 2 {
            return;
        }
        if self.rules.allow_dead_end(&mut self.rng) {
            self.counts.dead_ends_allowed += 1;
        } else {
            self.prune(b.site);
        }
    }

    /// Removes the dead-end street ending at `k`, back to the nearest junction.
    fn prune(&mut self, mut k: usize) {
        self.counts.dead_ends_pruned += 1;
        loop {
            let s = self.site(k);
            if s.street && s.joined && s.links == 0 {
                // A start that never moved: its join would end in a dead end. (The
                // points its join passed stay reserved: cheap, and never wrong.)
                self.sites[k].street = false;
                self.sites[k].joined = false;
                self.counts.pruned_points += 1;
                return;
            }
            if !s.street || s.joined || s.links.count_ones() != 1 {
                return;
            }
            let Some(d) = Dir::ALL.into_iter().find(|d| s.links & d.bit() != 0) else {
                return;
            };
            let Some(n) = self.frame.neighbor(k, d) else {
                return;
            };
            self.sites[k] = Site::default();
            self.sites[n].links &= !d.opposite().bit();
            self.counts.pruned_points += 1;
            k = n;
        }
    }

    /// The report's `branchOutToSide`: a new builder at `site` facing `side` takes one
    /// step; it is queued if that step reached a free, valid point (a branch that would
    /// run straight into a street is dropped). A branch within reach of the boundary
    /// joins it.
    fn branch(&mut self, site: usize, side: Dir) {
        if !self.site(site).street {
            return;
        }
        match self.probe_branch(site, side) {
            Step::Advance { to, tips } => {
                self.mark(to);
                self.link(site, side, to);
                self.join_tips(to, tips);
                self.queue.push_back(Builder {
                    site: to,
                    dir: side,
                });
                self.counts.builders += 1;
                self.counts.branches += 1;
            }
            Step::JoinBoundary { join } if !self.site(site).joined => {
                self.add_join(site, join);
                self.counts.branches += 1;
            }
            _ => {}
        }
    }

    /// [`probe`](Self::probe) for a branch: no intersections (no rule is drawn).
    fn probe_branch(&self, p: usize, d: Dir) -> Step {
        let pw = self.frame.position(p);
        if let Some(join) = self.boundary_ahead(p, d) {
            return match join {
                Some(join) => Step::JoinBoundary { join },
                None => Step::Blocked,
            };
        }
        match self.frame.neighbor(p, d) {
            Some(q) => match self.fresh(q, d, pw) {
                Some(tips) => Step::Advance { to: q, tips },
                None => Step::Blocked,
            },
            None => Step::Blocked,
        }
    }
}
