//! The derivation engine: parallel rewriting with double buffering, cut, decomposition,
//! the query/communication pass and growth guards, generic over [`Rules`].
//!
//! # One derivation step
//!
//! 1. Before the first step the axiom goes through the interpretation pass (4.), so that
//!    query and communication modules in the axiom carry values.
//! 2. **Rewriting.** Every module of the current string is rewritten in parallel into a
//!    second buffer: [`Rules::rewrite`] tries the productions in order (context, condition,
//!    stochastic choice are the rules' business) and the module is copied unchanged when
//!    none applies. A cut module `%` is not copied, and neither is anything after it up to
//!    the end of its branch (the closing `]` is kept, so brackets stay balanced).
//! 3. **Decomposition.** If the rules have decomposition rules, each new module is
//!    decomposed recursively (depth ≤ [`DeriveOptions::max_depth`]) into a third buffer.
//! 4. **Interpretation pass** (only when [`Rules::needs_pass`] says the string has query or
//!    communication modules): a turtle walks the string from the start, applying the
//!    interpretation (homomorphism) rules to what it draws. Each query module receives the
//!    turtle state at its position; each communication module is handed, in string order
//!    (left to right, branches in the order they are written), to the
//!    [`Environment`], which may rewrite its parameters. Modules produced by homomorphism
//!    rules are only drawn: they never receive query values.
//!
//! The step is atomic: if a guard fires ([`LsystemError::StringTooLong`],
//! [`LsystemError::DepthExceeded`], …) the current string is left as it was before the
//! step.

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

use crate::command::{Command, ModuleKind, QueryKind};
use crate::context::{BranchIndex, ContextView, end_of_branch};
use crate::error::{LsystemError, Result};
use crate::string::ModuleString;
use crate::turtle::{Turtle, TurtleOptions, TurtleSink, TurtleState};

/// Hard cap of [`DeriveOptions::max_depth`].
const MAX_DEPTH_CAP: usize = 4096;

/// Options of a derivation: seed, growth guards and the turtle used between steps.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct DeriveOptions {
    /// Seed of the `Pcg64Mcg` generator behind stochastic productions and random
    /// expressions. Default: 0.
    pub seed: u64,
    /// Largest string (modules) a step may produce; beyond it the step fails with
    /// [`LsystemError::StringTooLong`]. Default: 50 000 000.
    pub max_len: usize,
    /// Largest number of derivation steps. Default: 10 000.
    pub max_steps: usize,
    /// Deepest recursion of decomposition and interpretation rules (capped at 4096 so the
    /// recursion always fits the stack). Default: 64.
    pub max_depth: usize,
    /// Turtle used to fill query modules and to place communication modules. Default:
    /// [`TurtleOptions::default`].
    pub turtle: TurtleOptions,
}

impl Default for DeriveOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            max_len: 50_000_000,
            max_steps: 10_000,
            max_depth: 64,
            turtle: TurtleOptions::default(),
        }
    }
}

/// The environment of an open L-system (Měch & Prusinkiewicz 1996): it receives the
/// communication modules after every step.
///
/// Calls come in string order. Environments that need to see every request before
/// answering (e.g. light competition) can record indices in
/// [`communicate`](Self::communicate) and write answers in [`end_pass`](Self::end_pass).
///
/// # Example: a road that grows until the coast (Parish & Müller's `R` / `?I`)
///
/// ```
/// use polis_lsystem::{
///     Command, Derivation, DeriveOptions, Environment, Module, Production, TurtleState,
///     TypedRules,
/// };
///
/// #[derive(Clone, Copy, Debug, PartialEq)]
/// enum State { Unassigned, Succeed, Failed }
///
/// #[derive(Clone, Debug, PartialEq)]
/// enum Road {
///     R,               // a growing road end
///     I(f64, State),   // ?I(length, state): answered by the local constraints
///     F(f64),          // a built segment
/// }
///
/// impl Module for Road {
///     fn symbol(&self) -> u32 {
///         match self { Road::R => 0, Road::I(..) => 1, Road::F(_) => 2 }
///     }
///     fn command(&self) -> Command {
///         match self {
///             Road::I(..) => Command::Communicate,
///             Road::F(l) => Command::Forward(Some(*l)),
///             Road::R => Command::None,
///         }
///     }
/// }
///
/// /// Local constraints: nothing may be built beyond y = 25; shorten what would cross it.
/// struct Coast;
/// impl Environment<Vec<Road>> for Coast {
///     fn communicate(&mut self, s: &mut Vec<Road>, i: usize, t: &TurtleState) {
///         if let Some(Road::I(len, state @ State::Unassigned)) = s.get_mut(i) {
///             let room = 25.0 - t.position.y;
///             if room >= 1.0 {
///                 *len = len.min(room);
///                 *state = State::Succeed;
///             } else {
///                 *state = State::Failed;
///             }
///         }
///     }
/// }
///
/// let mut rules = TypedRules::new();
/// // R > ?I(l, SUCCEED) -> F(l) R ?I(10, UNASSIGNED)
/// rules.add(
///     Production::new(0, |m, o| {
///         if let Some(Road::I(l, _)) = m.right(0) {
///             o.extend([Road::F(*l), Road::R, Road::I(10.0, State::Unassigned)]);
///         }
///     })
///     .right([1])
///     .when(|m| matches!(m.right(0), Some(Road::I(_, State::Succeed)))),
/// )?;
/// // R > ?I(l, FAILED) -> ε
/// rules.add(
///     Production::new(0, |_, _| {})
///         .right([1])
///         .when(|m| matches!(m.right(0), Some(Road::I(_, State::Failed)))),
/// )?;
/// // ?I(l, state) : state != UNASSIGNED -> ε
/// rules.add(
///     Production::new(1, |_, _| {})
///         .when(|m| !matches!(m.module(), Road::I(_, State::Unassigned))),
/// )?;
///
/// let axiom = vec![Road::R, Road::I(10.0, State::Unassigned)];
/// let mut d = Derivation::new(rules, axiom, DeriveOptions::default());
/// d.derive_with(5, &mut Coast)?;
/// assert_eq!(d.string(), &vec![Road::F(10.0), Road::F(10.0), Road::F(5.0)]);
/// # Ok::<(), polis_lsystem::LsystemError>(())
/// ```
pub trait Environment<S> {
    /// Called before the first communication module of a pass. `step` is the number of
    /// derivation steps done so far.
    fn begin_pass(&mut self, _step: usize) {}
    /// One communication module at `index` of `string`, with the turtle state there. The
    /// environment may change the module's parameters (not the string's length).
    fn communicate(&mut self, string: &mut S, index: usize, turtle: &TurtleState);
    /// Called after the last communication module of a pass.
    fn end_pass(&mut self, _string: &mut S) {}
}

/// What a derivation step did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepReport {
    /// Number of steps done, including this one.
    pub step: usize,
    /// Length of the new string.
    pub len: usize,
    /// Modules rewritten by a production (the rest were copied).
    pub rewritten: usize,
    /// Modules removed by cuts `%` (including the `%` themselves).
    pub cut: usize,
    /// Communication modules handed to the environment after the step.
    pub communicated: usize,
}

/// A rule set the engine can derive with: productions plus the meaning of modules.
///
/// Implemented by [`TypedRules`](crate::TypedRules) (typed modules, closures) and
/// [`Grammar`](crate::Grammar) (text grammars). Implement it yourself to plug another
/// production language into the same engine.
pub trait Rules {
    /// The module string.
    type String: ModuleString;
    /// Reusable scratch space for rewriting (kept by the [`Derivation`]).
    type Scratch: Default;

    /// Structural kind of module `i`.
    fn kind(&self, s: &Self::String, i: usize) -> ModuleKind;
    /// Turtle command of module `i`.
    fn command(&self, s: &Self::String, i: usize) -> Command;
    /// `true` if module `i` is skipped by context matching.
    fn is_ignored(&self, _s: &Self::String, _i: usize) -> bool {
        false
    }
    /// `true` if any production has a context (the engine then indexes brackets).
    fn is_context_sensitive(&self) -> bool;
    /// Rewrites module `i` of `src`, appending the successor to `dst`. Returns `false`
    /// (and appends nothing) when no production applies.
    fn rewrite(
        &self,
        src: &Self::String,
        i: usize,
        branches: &BranchIndex,
        rng: &mut Pcg64Mcg,
        scratch: &mut Self::Scratch,
        dst: &mut Self::String,
    ) -> Result<bool>;
    /// `true` if there are decomposition rules.
    fn has_decomposition(&self) -> bool {
        false
    }
    /// Applies a decomposition rule to module `i` (context-free), appending to `dst`.
    fn decompose(
        &self,
        _src: &Self::String,
        _i: usize,
        _rng: &mut Pcg64Mcg,
        _scratch: &mut Self::Scratch,
        _dst: &mut Self::String,
    ) -> Result<bool> {
        Ok(false)
    }
    /// `true` if there are interpretation (homomorphism) rules.
    fn has_interpretation(&self) -> bool {
        false
    }
    /// Applies an interpretation rule to module `i`, appending the turtle modules to `dst`.
    fn interpret(
        &self,
        _src: &Self::String,
        _i: usize,
        _rng: &mut Pcg64Mcg,
        _scratch: &mut Self::Scratch,
        _dst: &mut Self::String,
    ) -> Result<bool> {
        Ok(false)
    }
    /// Writes the turtle state into query module `i`.
    fn fill_query(&self, s: &mut Self::String, i: usize, kind: QueryKind, state: &TurtleState);
    /// `true` if the string may hold query or communication modules, so the
    /// interpretation pass must run after a step.
    fn needs_pass(&self, s: &Self::String) -> bool;
    /// `false` if no production or decomposition rule ever writes a query or
    /// communication module: a string without them then stays without them, and the
    /// engine skips [`needs_pass`](Self::needs_pass) once it has said `false` (until the
    /// string is replaced or edited). Default: `true` (always ask).
    fn may_introduce_pass(&self) -> bool {
        true
    }
    /// Checks storage limits after a rewrite (e.g. the parameter arena). Default: none.
    fn check_storage(&self, _s: &Self::String) -> Result<()> {
        Ok(())
    }
}

/// Rules behind a reference or a shared pointer are rules: a derivation can borrow its
/// rules or share them (`Arc`) with derivations kept on other threads.
macro_rules! forward_rules {
    ($($ptr:ty),*) => {$(
        impl<R: Rules + ?Sized> Rules for $ptr {
            type String = R::String;
            type Scratch = R::Scratch;
            #[inline]
            fn kind(&self, s: &Self::String, i: usize) -> ModuleKind {
                (**self).kind(s, i)
            }
            #[inline]
            fn command(&self, s: &Self::String, i: usize) -> Command {
                (**self).command(s, i)
            }
            #[inline]
            fn is_ignored(&self, s: &Self::String, i: usize) -> bool {
                (**self).is_ignored(s, i)
            }
            fn is_context_sensitive(&self) -> bool {
                (**self).is_context_sensitive()
            }
            #[inline]
            fn rewrite(
                &self,
                src: &Self::String,
                i: usize,
                branches: &BranchIndex,
                rng: &mut Pcg64Mcg,
                scratch: &mut Self::Scratch,
                dst: &mut Self::String,
            ) -> Result<bool> {
                (**self).rewrite(src, i, branches, rng, scratch, dst)
            }
            fn has_decomposition(&self) -> bool {
                (**self).has_decomposition()
            }
            fn decompose(
                &self,
                src: &Self::String,
                i: usize,
                rng: &mut Pcg64Mcg,
                scratch: &mut Self::Scratch,
                dst: &mut Self::String,
            ) -> Result<bool> {
                (**self).decompose(src, i, rng, scratch, dst)
            }
            fn has_interpretation(&self) -> bool {
                (**self).has_interpretation()
            }
            fn interpret(
                &self,
                src: &Self::String,
                i: usize,
                rng: &mut Pcg64Mcg,
                scratch: &mut Self::Scratch,
                dst: &mut Self::String,
            ) -> Result<bool> {
                (**self).interpret(src, i, rng, scratch, dst)
            }
            fn fill_query(&self, s: &mut Self::String, i: usize, kind: QueryKind, state: &TurtleState) {
                (**self).fill_query(s, i, kind, state);
            }
            fn needs_pass(&self, s: &Self::String) -> bool {
                (**self).needs_pass(s)
            }
            fn check_storage(&self, s: &Self::String) -> Result<()> {
                (**self).check_storage(s)
            }
            fn may_introduce_pass(&self) -> bool {
                (**self).may_introduce_pass()
            }
        }
    )*};
}

forward_rules!(&R, std::sync::Arc<R>);

/// A string seen through its rules, for the context matchers.
pub struct View<'a, R: Rules + ?Sized> {
    /// The rules.
    pub rules: &'a R,
    /// The string.
    pub string: &'a R::String,
}

impl<R: Rules + ?Sized> ContextView for View<'_, R> {
    #[inline]
    fn len(&self) -> usize {
        self.string.len()
    }
    #[inline]
    fn kind(&self, i: usize) -> ModuleKind {
        self.rules.kind(self.string, i)
    }
    #[inline]
    fn ignored(&self, i: usize) -> bool {
        self.rules.is_ignored(self.string, i)
    }
}

/// A running derivation: the current string, the rules, the generator and the buffers.
///
/// Step with [`step`](Self::step) / [`step_with`](Self::step_with), or run several steps
/// with [`derive`](Self::derive) / [`derive_with`](Self::derive_with); read the string with
/// [`string`](Self::string) and the turtle with [`interpret`](Self::interpret) or
/// [`turtle_states`](Self::turtle_states) between steps.
pub struct Derivation<R: Rules> {
    rules: R,
    options: DeriveOptions,
    current: R::String,
    next: R::String,
    decomposed: R::String,
    levels: Vec<R::String>,
    branches: BranchIndex,
    scratch: R::Scratch,
    rng: Pcg64Mcg,
    step: usize,
    passed: bool,
    /// The current string is known to hold no query or communication module.
    pass_free: bool,
    /// Length of the last step's rewritten string over its input's (sizes the next
    /// step's buffer); `None` before the first step.
    growth: Option<f64>,
}

impl<R: Rules> Derivation<R> {
    /// Starts a derivation from `axiom`.
    pub fn new(rules: R, axiom: R::String, options: DeriveOptions) -> Self {
        Self {
            rules,
            rng: Pcg64Mcg::seed_from_u64(options.seed),
            options,
            current: axiom,
            next: R::String::default(),
            decomposed: R::String::default(),
            levels: Vec::new(),
            branches: BranchIndex::default(),
            scratch: R::Scratch::default(),
            step: 0,
            passed: false,
            pass_free: false,
            growth: None,
        }
    }

    /// Starts over from `axiom` (step 0, generator reseeded), keeping every buffer: the
    /// reusable-worker entry point when many strings are derived with the same rules.
    pub fn restart(&mut self, axiom: &R::String) {
        self.restart_seeded(axiom, self.options.seed);
    }

    /// [`restart`](Self::restart) with a new [`DeriveOptions::seed`]: the derivation then
    /// derives exactly what `Derivation::new` with that seed would, interpretation passes
    /// included, while keeping its buffers.
    pub fn restart_seeded(&mut self, axiom: &R::String, seed: u64) {
        self.options.seed = seed;
        self.current.clone_from(axiom);
        self.rng = Pcg64Mcg::seed_from_u64(seed);
        self.step = 0;
        self.passed = false;
        self.pass_free = false;
        self.growth = None;
    }

    /// The current string.
    pub fn string(&self) -> &R::String {
        &self.current
    }

    /// Mutable access to the current string (e.g. to edit parameters between steps).
    pub fn string_mut(&mut self) -> &mut R::String {
        self.pass_free = false;
        &mut self.current
    }

    /// Takes the current string out, ending the derivation.
    pub fn into_string(self) -> R::String {
        self.current
    }

    /// The rules.
    pub fn rules(&self) -> &R {
        &self.rules
    }

    /// The options.
    pub fn options(&self) -> &DeriveOptions {
        &self.options
    }

    /// Number of steps done.
    pub fn steps_done(&self) -> usize {
        self.step
    }

    /// Heap bytes held by the string buffers and indexes (the engine's working memory).
    pub fn heap_bytes(&self) -> usize {
        self.current.heap_bytes()
            + self.next.heap_bytes()
            + self.decomposed.heap_bytes()
            + self
                .levels
                .iter()
                .map(ModuleString::heap_bytes)
                .sum::<usize>()
            + self.branches.heap_bytes()
    }

    /// One step without an environment (communication modules are left as they are).
    pub fn step(&mut self) -> Result<StepReport> {
        self.step_impl::<dyn Environment<R::String>>(None)
    }

    /// One step; communication modules are handed to `env` afterwards.
    pub fn step_with<E: Environment<R::String> + ?Sized>(
        &mut self,
        env: &mut E,
    ) -> Result<StepReport> {
        self.step_impl(Some(env))
    }

    /// `n` steps without an environment; returns the last report.
    pub fn derive(&mut self, n: usize) -> Result<StepReport> {
        let mut last = StepReport {
            step: self.step,
            len: self.current.len(),
            ..StepReport::default()
        };
        for _ in 0..n {
            last = self.step()?;
        }
        Ok(last)
    }

    /// `n` steps with an environment; returns the last report.
    pub fn derive_with<E: Environment<R::String> + ?Sized>(
        &mut self,
        n: usize,
        env: &mut E,
    ) -> Result<StepReport> {
        let mut last = StepReport {
            step: self.step,
            len: self.current.len(),
            ..StepReport::default()
        };
        for _ in 0..n {
            last = self.step_with(env)?;
        }
        Ok(last)
    }

    fn ensure_levels(&mut self) {
        let want = self.options.max_depth.saturating_add(1).min(MAX_DEPTH_CAP);
        if self.levels.len() < want {
            self.levels.resize_with(want, R::String::default);
        }
    }

    fn step_impl<E: Environment<R::String> + ?Sized>(
        &mut self,
        mut env: Option<&mut E>,
    ) -> Result<StepReport> {
        if self.step >= self.options.max_steps {
            return Err(LsystemError::TooManySteps {
                requested: self.step + 1,
                max: self.options.max_steps,
            });
        }
        if !self.passed {
            self.pass(env.as_deref_mut())?;
        }
        let mut report = StepReport {
            step: self.step + 1,
            ..StepReport::default()
        };
        let Self {
            rules,
            options,
            current,
            next,
            branches,
            scratch,
            rng,
            growth,
            ..
        } = self;
        let max_len = options.max_len;
        let n = current.len();
        if rules.is_context_sensitive() {
            branches.rebuild(n, |i| rules.kind(current, i));
        }
        next.clear();
        // Size the buffer from the last step's growth (the same length before the first
        // step), with 1/16 slack, so it is not grown by doubling and copying.
        let ratio = growth.unwrap_or(1.0);
        let estimate = (n as f64 * ratio * (17.0 / 16.0)).ceil() + 16.0;
        next.reserve_like(current, estimate.min(max_len as f64 + 1.0) as usize);
        let mut i = 0;
        while i < n {
            if rules.kind(current, i) == ModuleKind::Cut {
                let end = end_of_branch(
                    &View {
                        rules: &*rules,
                        string: &*current,
                    },
                    i + 1,
                );
                report.cut += end - i;
                i = end;
                continue;
            }
            if rules.rewrite(current, i, branches, rng, scratch, next)? {
                report.rewritten += 1;
            } else {
                next.push_copy(current, i);
            }
            if next.len() > max_len {
                let len = next.len();
                next.clear();
                return Err(LsystemError::StringTooLong {
                    step: report.step,
                    len,
                    max: max_len,
                });
            }
            i += 1;
        }
        rules.check_storage(next)?;
        if n > 0 {
            self.growth = Some(self.next.len() as f64 / n as f64);
        }
        if self.rules.has_decomposition() {
            self.decompose_next(report.step)?;
        }
        std::mem::swap(&mut self.current, &mut self.next);
        self.step += 1;
        self.passed = false;
        report.communicated = self.pass(env)?;
        report.len = self.current.len();
        Ok(report)
    }

    fn decompose_next(&mut self, step: usize) -> Result<()> {
        self.ensure_levels();
        let Self {
            rules,
            options,
            next,
            decomposed,
            levels,
            scratch,
            rng,
            ..
        } = self;
        decomposed.clear();
        for i in 0..next.len() {
            decompose_rec(
                rules,
                next,
                i,
                levels,
                scratch,
                rng,
                decomposed,
                options.max_depth,
            )?;
            if decomposed.len() > options.max_len {
                let len = decomposed.len();
                decomposed.clear();
                return Err(LsystemError::StringTooLong {
                    step,
                    len,
                    max: options.max_len,
                });
            }
        }
        rules.check_storage(decomposed)?;
        std::mem::swap(next, decomposed);
        Ok(())
    }

    /// The query/communication pass over the current string. Returns how many
    /// communication modules were handed to the environment.
    fn pass<E: Environment<R::String> + ?Sized>(
        &mut self,
        mut env: Option<&mut E>,
    ) -> Result<usize> {
        self.passed = true;
        if self.pass_free && !self.rules.may_introduce_pass() {
            return Ok(0);
        }
        if !self.rules.needs_pass(&self.current) {
            self.pass_free = true;
            return Ok(0);
        }
        self.ensure_levels();
        let Self {
            rules,
            options,
            current,
            levels,
            scratch,
            step,
            ..
        } = self;
        let mut rng = interpretation_rng(options.seed, *step);
        let mut turtle = Turtle::new(options.turtle);
        if let Some(e) = env.as_deref_mut() {
            e.begin_pass(*step);
        }
        let mut calls = 0;
        for i in 0..current.len() {
            match rules.command(current, i) {
                Command::Query(kind) => rules.fill_query(current, i, kind, turtle.state()),
                Command::Communicate => {
                    if let Some(e) = env.as_deref_mut() {
                        e.communicate(current, i, turtle.state());
                        calls += 1;
                    }
                }
                _ => walk(
                    rules,
                    current,
                    i,
                    levels,
                    scratch,
                    &mut rng,
                    &mut turtle,
                    &mut (),
                    options.max_depth,
                )?,
            }
        }
        if let Some(e) = env {
            e.end_pass(current);
        }
        Ok(calls)
    }

    /// Interprets the current string with the turtle of [`DeriveOptions::turtle`], applying
    /// interpretation rules, and reports the geometry to `sink`. Returns the final state.
    pub fn interpret<K: TurtleSink + ?Sized>(&self, sink: &mut K) -> Result<TurtleState> {
        self.interpret_with(&self.options.turtle, sink)
    }

    /// Like [`interpret`](Self::interpret) with other turtle options.
    pub fn interpret_with<K: TurtleSink + ?Sized>(
        &self,
        turtle: &TurtleOptions,
        sink: &mut K,
    ) -> Result<TurtleState> {
        let mut t = Turtle::new(*turtle);
        self.walk_all(&mut t, sink, |_, _| {})?;
        Ok(*t.state())
    }

    /// The turtle state at every module of the current string (before the module acts).
    pub fn turtle_states(&self) -> Result<Vec<TurtleState>> {
        let mut t = Turtle::new(self.options.turtle);
        let mut out = Vec::with_capacity(self.current.len());
        self.walk_all(&mut t, &mut (), |_, s| out.push(*s))?;
        Ok(out)
    }

    fn walk_all<K: TurtleSink + ?Sized>(
        &self,
        turtle: &mut Turtle,
        sink: &mut K,
        mut before: impl FnMut(usize, &TurtleState),
    ) -> Result<()> {
        let mut levels: Vec<R::String> = Vec::new();
        if self.rules.has_interpretation() {
            levels.resize_with(
                self.options.max_depth.saturating_add(1).min(MAX_DEPTH_CAP),
                Default::default,
            );
        } else {
            levels.push(R::String::default());
        }
        let mut scratch = R::Scratch::default();
        let mut rng = interpretation_rng(self.options.seed, self.step);
        for i in 0..self.current.len() {
            before(i, turtle.state());
            walk(
                &self.rules,
                &self.current,
                i,
                &mut levels,
                &mut scratch,
                &mut rng,
                turtle,
                sink,
                self.options.max_depth,
            )?;
        }
        Ok(())
    }
}

/// The generator used by interpretation rules in the pass after step `step`: derived from
/// the seed and the step, so drawing never disturbs the derivation's own stream.
fn interpretation_rng(seed: u64, step: usize) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(
        seed ^ (step as u64)
            .wrapping_add(1)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15),
    )
}

#[allow(clippy::too_many_arguments)]
fn decompose_rec<R: Rules>(
    rules: &R,
    src: &R::String,
    i: usize,
    levels: &mut [R::String],
    scratch: &mut R::Scratch,
    rng: &mut Pcg64Mcg,
    out: &mut R::String,
    max_depth: usize,
) -> Result<()> {
    let Some((buf, rest)) = levels.split_first_mut() else {
        return Err(LsystemError::DepthExceeded {
            what: "decomposition",
            max: max_depth,
        });
    };
    buf.clear();
    if rules.decompose(src, i, rng, scratch, buf)? {
        for j in 0..buf.len() {
            decompose_rec(rules, buf, j, rest, scratch, rng, out, max_depth)?;
        }
    } else {
        out.push_copy(src, i);
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn walk<R: Rules, K: TurtleSink + ?Sized>(
    rules: &R,
    src: &R::String,
    i: usize,
    levels: &mut [R::String],
    scratch: &mut R::Scratch,
    rng: &mut Pcg64Mcg,
    turtle: &mut Turtle,
    sink: &mut K,
    max_depth: usize,
) -> Result<()> {
    if rules.has_interpretation() {
        let Some((buf, rest)) = levels.split_first_mut() else {
            return Err(LsystemError::DepthExceeded {
                what: "interpretation",
                max: max_depth,
            });
        };
        buf.clear();
        if rules.interpret(src, i, rng, scratch, buf)? {
            for j in 0..buf.len() {
                walk(rules, buf, j, rest, scratch, rng, turtle, sink, max_depth)?;
            }
            return Ok(());
        }
    }
    turtle.apply(rules.command(src, i), sink);
    Ok(())
}
