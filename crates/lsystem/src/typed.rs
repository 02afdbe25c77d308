//! The typed front end: your own module type and productions written as Rust closures.
//!
//! ```
//! use polis_lsystem::{Derivation, DeriveOptions, Module, Production, TypedRules};
//!
//! #[derive(Clone, Debug, PartialEq)]
//! enum Algae { A, B }
//! impl Module for Algae {
//!     fn symbol(&self) -> u32 { match self { Algae::A => 0, Algae::B => 1 } }
//! }
//!
//! let mut rules = TypedRules::new();
//! rules.add(Production::new(0, |_, out| { out.push(Algae::A); out.push(Algae::B); }))?;
//! rules.add(Production::new(1, |_, out| out.push(Algae::A)))?;
//! let mut d = Derivation::new(rules, vec![Algae::B], DeriveOptions::default());
//! d.derive(5)?;
//! assert_eq!(d.string().len(), 8); // Fibonacci
//! # Ok::<(), polis_lsystem::LsystemError>(())
//! ```

use rand_pcg::Pcg64Mcg;

use crate::command::{Command, ModuleKind, QueryKind};
use crate::context::{BranchIndex, ContextItem, ContextView, match_left, match_right};
use crate::derivation::Rules;
use crate::error::{LsystemError, Result};
use crate::random::{pick_weighted, unit_f64};
use crate::turtle::TurtleState;

/// A typed module: anything cloneable with a small symbol id.
///
/// `symbol` selects the productions (ids index a table, so keep them small and dense);
/// `command` gives the module's meaning to the turtle and the engine (`[`, `]`, `%`,
/// queries and communication modules are recognised through it).
pub trait Module: Clone {
    /// Small dense id of the module's symbol (productions are looked up by it).
    fn symbol(&self) -> u32;
    /// The turtle command of this module. Default: [`Command::None`].
    #[inline]
    fn command(&self) -> Command {
        Command::None
    }
    /// Stores the turtle state in a query module. Default: does nothing.
    fn fill_query(&mut self, _kind: QueryKind, _state: &TurtleState) {}
}

/// The matched predecessor and its context, handed to conditions and successors.
pub struct Match<'a, M> {
    string: &'a [M],
    module: &'a M,
    index: usize,
    left: &'a [u32],
    right: &'a [u32],
}

impl<'a, M> Match<'a, M> {
    /// The predecessor module.
    #[inline]
    pub fn module(&self) -> &'a M {
        self.module
    }
    /// Its index in the string.
    #[inline]
    pub fn index(&self) -> usize {
        self.index
    }
    /// The module matched by the `k`-th module of the left-context pattern.
    #[inline]
    pub fn left(&self, k: usize) -> Option<&'a M> {
        self.left.get(k).and_then(|&p| self.string.get(p as usize))
    }
    /// The module matched by the `k`-th module of the right-context pattern (brackets
    /// in the pattern are not counted).
    #[inline]
    pub fn right(&self, k: usize) -> Option<&'a M> {
        self.right.get(k).and_then(|&p| self.string.get(p as usize))
    }
    /// The whole (previous) string.
    pub fn string(&self) -> &'a [M] {
        self.string
    }
}

/// Where a successor writes its modules.
pub struct Successor<'a, M> {
    out: &'a mut Vec<M>,
    rng: &'a mut Pcg64Mcg,
}

impl<M> Successor<'_, M> {
    /// Appends a module.
    #[inline]
    pub fn push(&mut self, m: M) {
        self.out.push(m);
    }
    /// Appends several modules.
    #[inline]
    pub fn extend(&mut self, ms: impl IntoIterator<Item = M>) {
        self.out.extend(ms);
    }
    /// The derivation's seeded generator.
    pub fn rng(&mut self) -> &mut Pcg64Mcg {
        self.rng
    }
    /// A uniform number in `[0, 1)` from the derivation's generator.
    pub fn random(&mut self) -> f64 {
        unit_f64(self.rng)
    }
}

type Condition<'a, M> = Box<dyn Fn(&Match<'_, M>) -> bool + Send + Sync + 'a>;
type SuccessorFn<'a, M> = Box<dyn Fn(&Match<'_, M>, &mut Successor<'_, M>) + Send + Sync + 'a>;

/// A production `left < predecessor > right : condition -> successor : probability`.
pub struct Production<'a, M> {
    predecessor: u32,
    left: Vec<ContextItem<u32>>,
    right: Vec<ContextItem<u32>>,
    condition: Option<Condition<'a, M>>,
    successor: SuccessorFn<'a, M>,
    probability: Option<f64>,
}

impl<M> std::fmt::Debug for Production<'_, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Production")
            .field("predecessor", &self.predecessor)
            .field("left", &self.left)
            .field("right", &self.right)
            .field("condition", &self.condition.is_some())
            .field("probability", &self.probability)
            .finish()
    }
}

impl<'a, M: Module> Production<'a, M> {
    /// A context-free, unconditional production for modules whose symbol is `predecessor`.
    pub fn new(
        predecessor: u32,
        successor: impl Fn(&Match<'_, M>, &mut Successor<'_, M>) + Send + Sync + 'a,
    ) -> Self {
        Self {
            predecessor,
            left: Vec::new(),
            right: Vec::new(),
            condition: None,
            successor: Box::new(successor),
            probability: None,
        }
    }

    /// Left context: symbols on the path toward the root, in string order.
    pub fn left(mut self, symbols: impl IntoIterator<Item = u32>) -> Self {
        self.left = symbols.into_iter().map(ContextItem::Module).collect();
        self
    }

    /// Right context: symbols following in the same branch, in string order.
    pub fn right(mut self, symbols: impl IntoIterator<Item = u32>) -> Self {
        self.right = symbols.into_iter().map(ContextItem::Module).collect();
        self
    }

    /// Right context with brackets (e.g. `G [ H ] M`).
    pub fn right_pattern(mut self, items: impl IntoIterator<Item = ContextItem<u32>>) -> Self {
        self.right = items.into_iter().collect();
        self
    }

    /// A condition on the matched modules.
    pub fn when(mut self, condition: impl Fn(&Match<'_, M>) -> bool + Send + Sync + 'a) -> Self {
        self.condition = Some(Box::new(condition));
        self
    }

    /// Makes the production stochastic with this weight (see [`TypedRules`] for the choice).
    pub fn probability(mut self, weight: f64) -> Self {
        self.probability = Some(weight);
        self
    }

    fn validate(&self) -> Result<()> {
        if let Some(w) = self.probability
            && !(w.is_finite() && w >= 0.0)
        {
            return Err(LsystemError::Invalid {
                what: "probability",
                reason: format!("{w} is not a finite non-negative weight"),
            });
        }
        if self
            .left
            .iter()
            .any(|c| !matches!(c, ContextItem::Module(_)))
        {
            return Err(LsystemError::Invalid {
                what: "left context",
                reason: "brackets are only allowed in the right context".into(),
            });
        }
        if self.predecessor as usize > MAX_SYMBOL {
            return Err(LsystemError::Invalid {
                what: "symbol",
                reason: format!(
                    "symbol id {} is above {MAX_SYMBOL}; use small dense ids",
                    self.predecessor
                ),
            });
        }
        Ok(())
    }

    #[inline]
    fn context_ok(
        &self,
        view: &TypedView<'_, M>,
        branches: &BranchIndex,
        i: usize,
        scratch: &mut TypedScratch,
    ) -> bool {
        let s = view.s;
        if self.left.is_empty() {
            scratch.left.clear();
        } else if !match_left(
            view,
            branches,
            i,
            &self.left,
            |&sym, p| s.get(p).is_some_and(|m| m.symbol() == sym),
            &mut scratch.left,
        ) {
            return false;
        }
        if self.right.is_empty() {
            scratch.right.clear();
            true
        } else {
            match_right(
                view,
                branches,
                i,
                &self.right,
                |&sym, p| s.get(p).is_some_and(|m| m.symbol() == sym),
                &mut scratch.right,
            )
        }
    }
}

/// Most symbol ids a [`TypedRules`] table indexes.
pub const MAX_SYMBOL: usize = 1 << 20;

/// Reusable buffers of [`TypedRules`].
#[derive(Debug, Default)]
pub struct TypedScratch {
    left: Vec<u32>,
    right: Vec<u32>,
    candidates: Vec<(u32, f64)>,
}

struct TypedView<'a, M> {
    s: &'a [M],
    ignore: &'a [bool],
}

impl<M: Module> ContextView for TypedView<'_, M> {
    #[inline]
    fn len(&self) -> usize {
        self.s.len()
    }
    #[inline]
    fn kind(&self, i: usize) -> ModuleKind {
        self.s
            .get(i)
            .map_or(ModuleKind::Plain, |m| m.command().kind())
    }
    #[inline]
    fn ignored(&self, i: usize) -> bool {
        self.s
            .get(i)
            .and_then(|m| self.ignore.get(m.symbol() as usize))
            .copied()
            .unwrap_or(false)
    }
}

struct Table<'a, M> {
    productions: Vec<Production<'a, M>>,
    by_symbol: Vec<Vec<u32>>,
}

impl<'a, M: Module> Table<'a, M> {
    fn add(&mut self, p: Production<'a, M>) -> Result<()> {
        p.validate()?;
        let sym = p.predecessor as usize;
        if self.by_symbol.len() <= sym {
            self.by_symbol.resize_with(sym + 1, Vec::new);
        }
        if let Some(list) = self.by_symbol.get_mut(sym) {
            list.push(self.productions.len() as u32);
        }
        self.productions.push(p);
        Ok(())
    }

    /// Tries the productions of module `i`; appends the successor and returns `true` if one applied.
    #[inline]
    fn apply(
        &self,
        view: &TypedView<'_, M>,
        branches: &BranchIndex,
        i: usize,
        rng: &mut Pcg64Mcg,
        scratch: &mut TypedScratch,
        dst: &mut Vec<M>,
    ) -> bool {
        let Some(m) = view.s.get(i) else {
            return false;
        };
        let Some(list) = self.by_symbol.get(m.symbol() as usize) else {
            return false;
        };
        for (k, &pi) in list.iter().enumerate() {
            let Some(p) = self.productions.get(pi as usize) else {
                continue;
            };
            if !p.context_ok(view, branches, i, scratch)
                || !self.condition_ok(p, view, m, i, scratch)
            {
                continue;
            }
            let Some(w) = p.probability else {
                self.produce(p, view, m, i, rng, scratch, dst);
                return true;
            };
            // Stochastic: choose among all matching stochastic productions of this symbol.
            scratch.candidates.clear();
            scratch.candidates.push((pi, w));
            let mut total = w;
            for &qi in list.get(k + 1..).unwrap_or(&[]) {
                let Some(q) = self.productions.get(qi as usize) else {
                    continue;
                };
                if let Some(wq) = q.probability
                    && q.context_ok(view, branches, i, scratch)
                    && self.condition_ok(q, view, m, i, scratch)
                {
                    scratch.candidates.push((qi, wq));
                    total += wq;
                }
            }
            if total <= 0.0 {
                return false;
            }
            let chosen = pick_weighted(&scratch.candidates, total, pi, rng);
            let Some(c) = self.productions.get(chosen as usize) else {
                return false;
            };
            c.context_ok(view, branches, i, scratch);
            self.produce(c, view, m, i, rng, scratch, dst);
            return true;
        }
        false
    }

    #[inline]
    fn condition_ok(
        &self,
        p: &Production<'a, M>,
        view: &TypedView<'_, M>,
        m: &M,
        i: usize,
        scratch: &TypedScratch,
    ) -> bool {
        match &p.condition {
            None => true,
            Some(c) => c(&Match {
                string: view.s,
                module: m,
                index: i,
                left: &scratch.left,
                right: &scratch.right,
            }),
        }
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn produce(
        &self,
        p: &Production<'a, M>,
        view: &TypedView<'_, M>,
        m: &M,
        i: usize,
        rng: &mut Pcg64Mcg,
        scratch: &TypedScratch,
        dst: &mut Vec<M>,
    ) {
        let mt = Match {
            string: view.s,
            module: m,
            index: i,
            left: &scratch.left,
            right: &scratch.right,
        };
        (p.successor)(&mt, &mut Successor { out: dst, rng });
    }
}

/// Productions, decomposition and interpretation rules for typed modules.
///
/// # Semantics (ABOP ch. 1)
///
/// * Productions of a symbol are tried in the order they were added; the first whose
///   context and condition match applies. Modules without a matching production are
///   copied (identity); a successor that pushes nothing erases the module (ε).
/// * **Stochastic choice.** If the first matching production has a probability, the
///   successor is chosen among it and every *later* matching production of the same
///   symbol that also has a probability, with chances proportional to the weights
///   (one uniform draw from the seeded generator, in string order). Weights need not sum
///   to 1.
/// * Context matching is bracket-aware ([`crate::context`]); symbols marked with
///   [`ignore`](Self::ignore) are skipped by it.
/// * Decomposition and interpretation rules are context-free: their context patterns are
///   ignored. Conditions should be pure functions of the match.
/// * Closures may borrow data for the lifetime `'a` (e.g. the maps a road generator reads
///   in its global goals); use `TypedRules<'static, M>` for self-contained rules.
pub struct TypedRules<'a, M> {
    productions: Table<'a, M>,
    decompositions: Table<'a, M>,
    interpretations: Table<'a, M>,
    ignore: Vec<bool>,
    context_sensitive: bool,
}

impl<M: Module> Default for TypedRules<'_, M> {
    fn default() -> Self {
        Self::new()
    }
}

impl<M: Module> std::fmt::Debug for TypedRules<'_, M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TypedRules")
            .field("productions", &self.productions.productions)
            .field("decompositions", &self.decompositions.productions.len())
            .field("interpretations", &self.interpretations.productions.len())
            .finish()
    }
}

impl<'a, M: Module> TypedRules<'a, M> {
    /// No rules: every module maps to itself.
    pub fn new() -> Self {
        Self {
            productions: Table {
                productions: Vec::new(),
                by_symbol: Vec::new(),
            },
            decompositions: Table {
                productions: Vec::new(),
                by_symbol: Vec::new(),
            },
            interpretations: Table {
                productions: Vec::new(),
                by_symbol: Vec::new(),
            },
            ignore: Vec::new(),
            context_sensitive: false,
        }
    }

    /// Adds a production (after the existing ones of its symbol).
    pub fn add(&mut self, p: Production<'a, M>) -> Result<&mut Self> {
        self.context_sensitive |= !p.left.is_empty() || !p.right.is_empty();
        self.productions.add(p)?;
        Ok(self)
    }

    /// Adds a decomposition rule, applied recursively after every step.
    pub fn add_decomposition(&mut self, p: Production<'a, M>) -> Result<&mut Self> {
        self.decompositions.add(p)?;
        Ok(self)
    }

    /// Adds an interpretation (homomorphism) rule, applied recursively when the turtle
    /// reads the string; the string itself is not changed.
    pub fn add_interpretation(&mut self, p: Production<'a, M>) -> Result<&mut Self> {
        self.interpretations.add(p)?;
        Ok(self)
    }

    /// Adds symbols to the ignore set of context matching. Ids above [`MAX_SYMBOL`] are
    /// skipped (they cannot be ignored).
    pub fn ignore(&mut self, symbols: impl IntoIterator<Item = u32>) -> &mut Self {
        for s in symbols {
            let s = s as usize;
            if s > MAX_SYMBOL {
                continue;
            }
            if self.ignore.len() <= s {
                self.ignore.resize(s + 1, false);
            }
            if let Some(f) = self.ignore.get_mut(s) {
                *f = true;
            }
        }
        self
    }

    fn view<'s>(&'s self, s: &'s [M]) -> TypedView<'s, M> {
        TypedView {
            s,
            ignore: &self.ignore,
        }
    }
}

static EMPTY_BRANCHES: std::sync::LazyLock<BranchIndex> =
    std::sync::LazyLock::new(BranchIndex::default);

impl<M: Module> Rules for TypedRules<'_, M> {
    type String = Vec<M>;
    type Scratch = TypedScratch;

    #[inline]
    fn kind(&self, s: &Vec<M>, i: usize) -> ModuleKind {
        s.get(i).map_or(ModuleKind::Plain, |m| m.command().kind())
    }
    #[inline]
    fn command(&self, s: &Vec<M>, i: usize) -> Command {
        s.get(i).map_or(Command::None, Module::command)
    }
    #[inline]
    fn is_ignored(&self, s: &Vec<M>, i: usize) -> bool {
        self.view(s).ignored(i)
    }
    fn is_context_sensitive(&self) -> bool {
        self.context_sensitive
    }
    #[inline]
    fn rewrite(
        &self,
        src: &Vec<M>,
        i: usize,
        branches: &BranchIndex,
        rng: &mut Pcg64Mcg,
        scratch: &mut TypedScratch,
        dst: &mut Vec<M>,
    ) -> Result<bool> {
        Ok(self
            .productions
            .apply(&self.view(src), branches, i, rng, scratch, dst))
    }
    fn has_decomposition(&self) -> bool {
        !self.decompositions.productions.is_empty()
    }
    fn decompose(
        &self,
        src: &Vec<M>,
        i: usize,
        rng: &mut Pcg64Mcg,
        scratch: &mut TypedScratch,
        dst: &mut Vec<M>,
    ) -> Result<bool> {
        Ok(self
            .decompositions
            .apply(&self.view(src), &EMPTY_BRANCHES, i, rng, scratch, dst))
    }
    fn has_interpretation(&self) -> bool {
        !self.interpretations.productions.is_empty()
    }
    fn interpret(
        &self,
        src: &Vec<M>,
        i: usize,
        rng: &mut Pcg64Mcg,
        scratch: &mut TypedScratch,
        dst: &mut Vec<M>,
    ) -> Result<bool> {
        Ok(self
            .interpretations
            .apply(&self.view(src), &EMPTY_BRANCHES, i, rng, scratch, dst))
    }
    fn fill_query(&self, s: &mut Vec<M>, i: usize, kind: QueryKind, state: &TurtleState) {
        if let Some(m) = s.get_mut(i) {
            m.fill_query(kind, state);
        }
    }
    fn needs_pass(&self, s: &Vec<M>) -> bool {
        s.iter()
            .any(|m| matches!(m.command(), Command::Query(_) | Command::Communicate))
    }
}
