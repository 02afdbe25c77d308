//! The rewriting hot path of a compiled [`Grammar`]: binding a production's parameters
//! (the predecessor's own when it has no context, without a copy), matching contexts
//! (immediate neighbours on a string without brackets and ignored modules, the
//! bracket-aware walks of [`crate::context`] otherwise), conditions, the stochastic
//! choice and writing the successor.

use rand_pcg::Pcg64Mcg;

use super::{Arg, CProduction, Grammar, GrammarScratch, Pat, Table, TextView};
use crate::context::{BranchIndex, ContextItem, match_left, match_right};
use crate::grammar::expr;
use crate::random::pick_weighted;
use crate::string::ParamString;

impl Grammar {
    /// Evaluates an argument or condition with the bound parameters `vars`.
    #[inline(always)]
    fn eval_arg(&self, a: Arg, vars: &[f64], stack: &mut Vec<f64>, rng: &mut Pcg64Mcg) -> f64 {
        match a {
            Arg::Pair(op, k) => match self.pairs.get(k as usize) {
                Some(&(x, y)) => expr::binary(op, simple(x, vars), simple(y, vars)),
                None => f64::NAN,
            },
            Arg::Code(s, e) => self.eval_code((s, e), vars, stack, rng),
            other => simple(other, vars),
        }
    }

    /// Runs the bytecode of an [`Arg::Code`] (out of line: the common shapes never need it).
    #[inline(never)]
    fn eval_code(
        &self,
        range: (u32, u32),
        vars: &[f64],
        stack: &mut Vec<f64>,
        rng: &mut Pcg64Mcg,
    ) -> f64 {
        let code = self
            .code
            .get(range.0 as usize..range.1 as usize)
            .unwrap_or(&[]);
        expr::run(code, vars, stack, Some(rng))
    }

    /// Binds the parameters of `p` at module `i` if its context matches: the
    /// predecessor's own parameters when `p` has no context (no copy), otherwise left
    /// context, predecessor and right context copied into `vars`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn bind<'x>(
        &self,
        p: &CProduction,
        view: &TextView<'x>,
        branches: &BranchIndex,
        i: usize,
        left: &mut Vec<u32>,
        right: &mut Vec<u32>,
        vars: &'x mut Vec<f64>,
    ) -> Option<&'x [f64]> {
        if p.left.is_empty() && p.right.is_empty() {
            return Some(view.s.params(i));
        }
        self.bind_context(p, view, branches, i, (left, right, vars))
    }

    /// [`bind`](Self::bind) for a production with a context: the matched positions go
    /// to `left` and `right`, the bound parameters to `vars`.
    fn bind_context<'x>(
        &self,
        p: &CProduction,
        view: &TextView<'x>,
        branches: &BranchIndex,
        i: usize,
        (left, right, vars): (&mut Vec<u32>, &mut Vec<u32>, &'x mut Vec<f64>),
    ) -> Option<&'x [f64]> {
        let s = view.s;
        let eq = |&(sym, arity): &(u32, u32), pos: usize| {
            s.symbol(pos) == sym && s.params(pos).len() == arity as usize
        };
        let plain = self.plain_neighbours(branches);
        if p.left.is_empty() {
            left.clear();
        } else if !(if plain {
            match_neighbours_left(s, i, &p.left, left)
        } else {
            match_left(view, branches, i, &p.left, eq, left)
        }) {
            return None;
        }
        if p.right.is_empty() {
            right.clear();
        } else if !(if plain {
            match_neighbours_right(s, i, &p.right, right)
        } else {
            match_right(view, branches, i, &p.right, eq, right)
        }) {
            return None;
        }
        vars.clear();
        for &k in left.iter() {
            push_params(vars, s.params(k as usize));
        }
        push_params(vars, s.params(i));
        for &k in right.iter() {
            push_params(vars, s.params(k as usize));
        }
        Some(vars)
    }

    /// `true` when a context is made of the immediate neighbours: the string has no
    /// brackets (per the bracket index of this step) and the grammar ignores nothing.
    #[inline]
    fn plain_neighbours(&self, branches: &BranchIndex) -> bool {
        !self.ignores_any && branches.bracket_free()
    }

    /// [`bind`](Self::bind), then the condition.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn holds<'x>(
        &self,
        p: &CProduction,
        view: &TextView<'x>,
        branches: &BranchIndex,
        i: usize,
        (left, right, vars, stack): Lent<'_, 'x>,
        rng: &mut Pcg64Mcg,
    ) -> Option<&'x [f64]> {
        let bound = self.bind(p, view, branches, i, left, right, vars)?;
        match p.condition {
            None => Some(bound),
            Some(c) => expr::truth(self.eval_arg(c, bound, stack, rng)).then_some(bound),
        }
    }

    #[inline(always)]
    fn produce(
        &self,
        p: &CProduction,
        vars: &[f64],
        stack: &mut Vec<f64>,
        rng: &mut Pcg64Mcg,
        dst: &mut ParamString,
    ) {
        for m in &p.successor {
            dst.begin(m.symbol);
            for a in &m.args {
                let v = self.eval_arg(*a, vars, stack, rng);
                dst.push_param(v);
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    pub(super) fn apply(
        &self,
        table: &Table,
        s: &ParamString,
        i: usize,
        branches: &BranchIndex,
        rng: &mut Pcg64Mcg,
        scratch: &mut GrammarScratch,
        dst: &mut ParamString,
    ) -> bool {
        let Some(list) = table.by_symbol.get(s.symbol(i) as usize) else {
            return false;
        };
        let arity = s.params(i).len() as u32;
        let view = TextView { g: self, s };
        let GrammarScratch {
            vars,
            stack,
            left,
            right,
            candidates,
        } = scratch;
        for (k, &pi) in list.iter().enumerate() {
            let Some(p) = table.productions.get(pi as usize) else {
                continue;
            };
            if p.arity != arity {
                continue;
            }
            if p.probability.is_none() {
                let Some(bound) = self.holds(
                    p,
                    &view,
                    branches,
                    i,
                    (&mut *left, &mut *right, &mut *vars, &mut *stack),
                    rng,
                ) else {
                    continue;
                };
                self.produce(p, bound, stack, rng, dst);
                return true;
            }
            if self
                .holds(
                    p,
                    &view,
                    branches,
                    i,
                    (&mut *left, &mut *right, &mut *vars, &mut *stack),
                    rng,
                )
                .is_none()
            {
                continue;
            }
            let w = p.probability.unwrap_or(0.0);
            candidates.clear();
            candidates.push((pi, w));
            let mut total = w;
            for &qi in list.get(k + 1..).unwrap_or(&[]) {
                let Some(q) = table.productions.get(qi as usize) else {
                    continue;
                };
                if let Some(wq) = q.probability
                    && q.arity == arity
                    && self
                        .holds(
                            q,
                            &view,
                            branches,
                            i,
                            (&mut *left, &mut *right, &mut *vars, &mut *stack),
                            rng,
                        )
                        .is_some()
                {
                    candidates.push((qi, wq));
                    total += wq;
                }
            }
            if total <= 0.0 {
                return false;
            }
            let chosen = pick_weighted(candidates, total, pi, rng);
            let Some(c) = table.productions.get(chosen as usize) else {
                return false;
            };
            // Re-bind the chosen production's parameters (its condition held above).
            let Some(bound) = self.bind(c, &view, branches, i, left, right, vars) else {
                return false;
            };
            self.produce(c, bound, stack, rng, dst);
            return true;
        }
        false
    }
}

/// Scratch buffers lent to one production test: left and right context positions, bound
/// parameters, expression stack.
type Lent<'s, 'x> = (
    &'s mut Vec<u32>,
    &'s mut Vec<u32>,
    &'x mut Vec<f64>,
    &'s mut Vec<f64>,
);

/// Appends parameters; one parameter (the common case) without a `memcpy` call.
#[inline(always)]
fn push_params(vars: &mut Vec<f64>, p: &[f64]) {
    match p {
        &[v] => vars.push(v),
        _ => vars.extend_from_slice(p),
    }
}

/// Symbol and parameter count of module `pos` match the pattern module.
#[inline]
fn same_module(s: &ParamString, pos: usize, (sym, arity): (u32, u32)) -> bool {
    s.symbol(pos) == sym && s.params(pos).len() == arity as usize
}

/// Left context on a string without brackets or ignored modules: the modules just
/// before `i`, in pattern order (what [`match_left`] finds there, without the walk).
#[inline]
fn match_neighbours_left(s: &ParamString, i: usize, pattern: &[Pat], out: &mut Vec<u32>) -> bool {
    out.clear();
    let Some(first) = i.checked_sub(pattern.len()) else {
        return false;
    };
    for (k, item) in pattern.iter().enumerate() {
        match item {
            ContextItem::Module(want) if same_module(s, first + k, *want) => {
                out.push((first + k) as u32);
            }
            _ => return false,
        }
    }
    true
}

/// Right context on a string without brackets or ignored modules: the modules just
/// after `i` (what [`match_right`] finds there; a bracket in the pattern never matches).
#[inline]
fn match_neighbours_right(s: &ParamString, i: usize, pattern: &[Pat], out: &mut Vec<u32>) -> bool {
    out.clear();
    for (k, item) in pattern.iter().enumerate() {
        let pos = i + 1 + k;
        match item {
            ContextItem::Module(want) if pos < s.len() && same_module(s, pos, *want) => {
                out.push(pos as u32);
            }
            _ => return false,
        }
    }
    true
}

/// Evaluates an argument of the simple shapes (no bytecode, no pair).
#[inline(always)]
fn simple(a: Arg, vars: &[f64]) -> f64 {
    let var = |k: u32| vars.get(k as usize).copied().unwrap_or(f64::NAN);
    match a {
        Arg::Const(v) => v,
        Arg::Var(k) => var(k),
        Arg::VarConst(x, op, c) => expr::binary(op, var(x), c),
        Arg::ConstVar(c, op, y) => expr::binary(op, c, var(y)),
        Arg::VarVar(x, op, y) => expr::binary(op, var(x), var(y)),
        Arg::Pair(..) | Arg::Code(..) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::context::ContextView;
    use crate::{DeriveOptions, Grammar};

    /// A string over `A`, `B`, `C` (ids from a grammar that declares them), each with 0
    /// or 1 parameter.
    fn string(g: &Grammar, mods: &[(u8, bool)]) -> ParamString {
        let mut s = ParamString::new();
        for &(c, p) in mods {
            let name = ["A", "B", "C"][usize::from(c % 3)];
            let id = g.symbol_id(name).unwrap();
            s.push(id, if p { &[1.5] } else { &[] }).unwrap();
        }
        s
    }

    fn pattern(g: &Grammar, items: &[(u8, bool)]) -> Vec<Pat> {
        items
            .iter()
            .map(|&(c, p)| {
                let name = ["A", "B", "C"][usize::from(c % 3)];
                ContextItem::Module((g.symbol_id(name).unwrap(), u32::from(p)))
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]

        /// On a string without brackets and ignored modules, the neighbour matchers find
        /// exactly what the bracket-aware walks find, positions included.
        #[test]
        fn neighbours_equal_the_walk(
            mods in prop::collection::vec((0u8..3, any::<bool>()), 0..12),
            left in prop::collection::vec((0u8..3, any::<bool>()), 1..4),
            right in prop::collection::vec((0u8..3, any::<bool>()), 1..4),
            at in 0usize..12,
        ) {
            let g = Grammar::parse("ω: A B C\nA -> B").unwrap();
            let s = string(&g, &mods);
            prop_assume!(at < s.len());
            let view = TextView { g: &g, s: &s };
            let mut b = BranchIndex::default();
            b.rebuild(s.len(), |i| view.kind(i));
            prop_assert!(b.bracket_free() && g.plain_neighbours(&b));
            let eq = |&(sym, arity): &(u32, u32), pos: usize| {
                s.symbol(pos) == sym && s.params(pos).len() == arity as usize
            };
            let (lp, rp) = (pattern(&g, &left), pattern(&g, &right));
            let (mut fast, mut walk) = (Vec::new(), Vec::new());
            let f = match_neighbours_left(&s, at, &lp, &mut fast);
            let w = match_left(&view, &b, at, &lp, eq, &mut walk);
            prop_assert_eq!(f, w);
            if f {
                prop_assert_eq!(&fast, &walk);
            }
            let f = match_neighbours_right(&s, at, &rp, &mut fast);
            let w = match_right(&view, &b, at, &rp, eq, &mut walk);
            prop_assert_eq!(f, w);
            if f {
                prop_assert_eq!(&fast, &walk);
            }
        }

        /// `a op b` arguments evaluated as pairs of simple shapes give the same bits as
        /// the bytecode: `e ? e : e` is always `e` but is never a fast shape.
        #[test]
        fn pairs_equal_bytecode(
            x in prop_oneof![any::<f64>(), Just(f64::NAN), Just(0.0), Just(-0.0), -4.0f64..4.0],
            y in prop_oneof![any::<f64>(), Just(f64::INFINITY), -4.0f64..4.0],
            c in (0u8..12).prop_map(|k| f64::from(k) * 0.25),
            ops in prop::collection::vec(0usize..14, 3),
        ) {
            const OPS: [&str; 14] =
                ["+", "-", "*", "/", "%", "^", "<", "<=", ">", ">=", "==", "!=", "&&", "||"];
            let (o1, o2, o3) = (OPS[ops[0]], OPS[ops[1]], OPS[ops[2]]);
            let e = format!("(x {o1} {c:?}) {o2} ({c:?} {o3} y)");
            let run = |body: String| {
                let g = Grammar::parse(&format!("ω: S\nQ(x, y) -> P({body})")).unwrap();
                let mut axiom = ParamString::new();
                axiom.push(g.symbol_id("Q").unwrap(), &[x, y]).unwrap();
                let mut d = crate::Derivation::new(&g, axiom, DeriveOptions::default());
                d.derive(1).unwrap();
                d.string().params(0).first().map(|v| v.to_bits())
            };
            let direct = run(e.clone());
            let forced = run(format!("({e}) ? ({e}) : ({e})"));
            prop_assert_eq!(direct, forced);
        }
    }
}
