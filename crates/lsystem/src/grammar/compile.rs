//! Compiling a grammar syntax tree into the runtime [`Grammar`]: interned symbols,
//! production tables by predecessor symbol, bytecode for conditions and arguments, and
//! the [`Rules`] implementation the derivation engine runs.

use rand_pcg::Pcg64Mcg;

use super::ast::{GrammarAst, ModuleCall, PatternItem, ProductionAst, Section};
use super::expr::{self, BinaryOp, Expr, Op};
use super::parse;
use crate::command::{Command, ModuleKind, QueryKind};
use crate::context::{BranchIndex, ContextItem, ContextView};
use crate::derivation::{Derivation, DeriveOptions, Rules};
use crate::error::{LsystemError, Result};
use crate::string::ParamString;
use crate::turtle::TurtleState;

mod rewrite;

/// Symbols with a fixed id and meaning in every grammar, in id order.
pub const BUILTIN_SYMBOLS: &[(&str, Command)] = &[
    ("[", Command::Push),
    ("]", Command::Pop),
    ("%", Command::Cut),
    ("F", Command::Forward(None)),
    ("f", Command::Move(None)),
    ("G", Command::Forward(None)),
    ("g", Command::Move(None)),
    ("+", Command::TurnLeft(None)),
    ("-", Command::TurnRight(None)),
    ("&", Command::PitchDown(None)),
    ("^", Command::PitchUp(None)),
    ("\\", Command::RollLeft(None)),
    ("/", Command::RollRight(None)),
    ("|", Command::TurnAround),
    ("$", Command::RollToVertical),
    ("!", Command::Width(None)),
    ("'", Command::Colour(None)),
    ("{", Command::PolygonStart),
    (".", Command::PolygonVertex),
    ("}", Command::PolygonEnd),
    ("@o", Command::Dot(None)),
    ("?P", Command::Query(QueryKind::Position)),
    ("?H", Command::Query(QueryKind::Heading)),
    ("?U", Command::Query(QueryKind::Up)),
    ("?L", Command::Query(QueryKind::Left)),
    ("?E", Command::Communicate),
];

#[inline]
fn with_arg(c: Command, a: Option<f64>) -> Command {
    match c {
        Command::Forward(_) => Command::Forward(a),
        Command::Move(_) => Command::Move(a),
        Command::TurnLeft(_) => Command::TurnLeft(a),
        Command::TurnRight(_) => Command::TurnRight(a),
        Command::PitchDown(_) => Command::PitchDown(a),
        Command::PitchUp(_) => Command::PitchUp(a),
        Command::RollLeft(_) => Command::RollLeft(a),
        Command::RollRight(_) => Command::RollRight(a),
        Command::Width(_) => Command::Width(a),
        Command::Colour(_) => Command::Colour(a),
        Command::Dot(_) => Command::Dot(a),
        other => other,
    }
}

/// A compiled expression. The common shapes `x`, `3`, `x op 3`, `3 op x` and `x op y`
/// are evaluated directly; everything else runs bytecode.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Arg {
    Const(f64),
    Var(u32),
    VarConst(u32, BinaryOp, f64),
    ConstVar(f64, BinaryOp, u32),
    VarVar(u32, BinaryOp, u32),
    /// `a op b` with `a` and `b` of the shapes above, stored in `Grammar::pairs`.
    Pair(BinaryOp, u32),
    Code(u32, u32),
}

#[derive(Debug, Clone)]
struct SuccModule {
    symbol: u32,
    args: Vec<Arg>,
}

/// A context pattern module: symbol id and parameter count.
type Pat = ContextItem<(u32, u32)>;

#[derive(Debug, Clone)]
struct CProduction {
    arity: u32,
    left: Vec<Pat>,
    right: Vec<Pat>,
    condition: Option<Arg>,
    successor: Vec<SuccModule>,
    probability: Option<f64>,
}

#[derive(Debug, Clone, Default)]
struct Table {
    productions: Vec<CProduction>,
    by_symbol: Vec<Vec<u32>>,
}

/// Reusable buffers of a [`Grammar`] derivation.
#[derive(Debug, Default)]
pub struct GrammarScratch {
    vars: Vec<f64>,
    stack: Vec<f64>,
    left: Vec<u32>,
    right: Vec<u32>,
    candidates: Vec<(u32, f64)>,
}

/// A compiled text grammar: the rules of a numeric-parameter L-system.
///
/// Build it with [`Grammar::parse`]; derive with [`Grammar::derivation`]. It implements
/// [`Rules`] with [`ParamString`] strings. See the [crate docs](crate) for the language.
#[derive(Debug, Clone)]
pub struct Grammar {
    ast: GrammarAst,
    names: Vec<String>,
    commands: Vec<Command>,
    kinds: Vec<ModuleKind>,
    ignore: Vec<bool>,
    productions: Table,
    decompositions: Table,
    interpretations: Table,
    code: Vec<Op>,
    pairs: Vec<(Arg, Arg)>,
    axiom: ParamString,
    defines: Vec<(String, f64)>,
    context_sensitive: bool,
    ignores_any: bool,
    introduces_pass: bool,
    needs_pass: bool,
    pass_symbols: Vec<bool>,
}

/// Where a statement of a parsed text starts, for compile errors.
#[derive(Debug, Clone, Default)]
pub(crate) struct Location {
    pub line: usize,
    pub column: usize,
    pub text: String,
}

fn compile_err(
    what: &str,
    label: Option<&str>,
    index: usize,
    loc: Option<&Location>,
    message: impl std::fmt::Display,
) -> LsystemError {
    match loc {
        Some(l) => LsystemError::Parse {
            line: l.line,
            column: l.column,
            message: format!("{message}"),
            snippet: l.text.clone(),
        },
        None => LsystemError::Parse {
            line: 0,
            column: 0,
            message: format!("{message}"),
            snippet: match label {
                Some(l) => format!("{what} {l}"),
                None => format!("{what} #{}", index + 1),
            },
        },
    }
}

fn substitute(e: &Expr, defines: &[(String, f64)], formals: &[String]) -> Expr {
    match e {
        Expr::Var(n) if !formals.contains(n) => match defines.iter().rev().find(|(d, _)| d == n) {
            Some((_, v)) => Expr::Num(*v),
            None => e.clone(),
        },
        Expr::Num(_) | Expr::Var(_) => e.clone(),
        Expr::Unary(o, a) => Expr::Unary(*o, Box::new(substitute(a, defines, formals))),
        Expr::Binary(o, a, b) => Expr::Binary(
            *o,
            Box::new(substitute(a, defines, formals)),
            Box::new(substitute(b, defines, formals)),
        ),
        Expr::Cond(c, a, b) => Expr::Cond(
            Box::new(substitute(c, defines, formals)),
            Box::new(substitute(a, defines, formals)),
            Box::new(substitute(b, defines, formals)),
        ),
        Expr::Call(f, args) => Expr::Call(
            *f,
            args.iter()
                .map(|a| substitute(a, defines, formals))
                .collect(),
        ),
    }
}

fn has_vars(e: &Expr) -> bool {
    match e {
        Expr::Num(_) => false,
        Expr::Var(_) => true,
        Expr::Unary(_, a) => has_vars(a),
        Expr::Binary(_, a, b) => has_vars(a) || has_vars(b),
        Expr::Cond(c, a, b) => has_vars(c) || has_vars(a) || has_vars(b),
        Expr::Call(_, args) => args.iter().any(has_vars),
    }
}

impl Grammar {
    /// Parses and compiles a grammar text.
    ///
    /// Errors carry the line, column and text of the problem; arbitrary input never panics.
    pub fn parse(text: &str) -> Result<Self> {
        let (ast, locations) = parse::parse(text)?;
        Self::compile(ast, &locations)
    }

    /// Compiles a syntax tree (e.g. one built or edited in code). Compile errors then
    /// name the production by label or number instead of a line.
    pub fn from_ast(ast: GrammarAst) -> Result<Self> {
        Self::compile(ast, &[])
    }

    fn compile(ast: GrammarAst, locations: &[Location]) -> Result<Self> {
        let mut g = Grammar {
            names: Vec::new(),
            commands: Vec::new(),
            kinds: Vec::new(),
            ignore: Vec::new(),
            productions: Table::default(),
            decompositions: Table::default(),
            interpretations: Table::default(),
            code: Vec::new(),
            pairs: Vec::new(),
            axiom: ParamString::new(),
            defines: Vec::new(),
            context_sensitive: false,
            ignores_any: false,
            introduces_pass: false,
            needs_pass: false,
            pass_symbols: Vec::new(),
            ast: GrammarAst::default(),
        };
        for (name, c) in BUILTIN_SYMBOLS {
            g.intern(name);
            if let Some(slot) = g.commands.last_mut() {
                *slot = *c;
            }
            if let Some(k) = g.kinds.last_mut() {
                *k = c.kind();
            }
        }
        for (k, d) in ast.defines.iter().enumerate() {
            let defines = g.defines.clone();
            let v = expr::eval_const(&d.value, &|n| {
                defines.iter().rev().find(|(m, _)| m == n).map(|(_, v)| *v)
            })
            .map_err(|m| compile_err("#define", Some(&d.name), k, None, m))?;
            g.defines.push((d.name.clone(), v));
        }
        for s in &ast.ignore {
            let id = g.intern(s) as usize;
            if let Some(f) = g.ignore.get_mut(id) {
                *f = true;
            }
        }
        g.ignores_any = g.ignore.iter().any(|&f| f);
        for s in &ast.communication {
            let id = g.intern(s) as usize;
            let kind = g.kinds.get(id).copied().unwrap_or(ModuleKind::Plain);
            if kind != ModuleKind::Plain {
                return Err(compile_err(
                    "#communication",
                    Some(s),
                    0,
                    None,
                    "brackets and `%` cannot be communication modules",
                ));
            }
            if let Some(c) = g.commands.get_mut(id) {
                *c = Command::Communicate;
            }
        }
        g.axiom = g.constant_string(&ast.axiom)?;
        for (k, p) in ast.productions.iter().enumerate() {
            g.add_production(p, k, locations.get(k))?;
        }
        let pass_symbols: Vec<bool> = g
            .commands
            .iter()
            .map(|c| matches!(c, Command::Query(_) | Command::Communicate))
            .collect();
        let uses_pass = |id: u32| pass_symbols.get(id as usize).copied().unwrap_or(false);
        g.introduces_pass = [&g.productions, &g.decompositions].iter().any(|t| {
            t.productions
                .iter()
                .any(|p| p.successor.iter().any(|m| uses_pass(m.symbol)))
        });
        g.needs_pass = g.axiom.iter().any(|(s, _)| uses_pass(s)) || g.introduces_pass;
        g.pass_symbols = pass_symbols;
        g.ast = ast;
        Ok(g)
    }

    fn intern(&mut self, name: &str) -> u32 {
        if let Some(i) = self.names.iter().position(|n| n == name) {
            return i as u32;
        }
        self.names.push(name.to_string());
        self.commands.push(Command::None);
        self.kinds.push(ModuleKind::Plain);
        self.ignore.push(false);
        (self.names.len() - 1) as u32
    }

    fn constant_string(&mut self, calls: &[ModuleCall]) -> Result<ParamString> {
        let mut s = ParamString::new();
        for (k, m) in calls.iter().enumerate() {
            let id = self.intern(&m.symbol);
            let mut params = Vec::with_capacity(m.args.len());
            for a in &m.args {
                let e = substitute(a, &self.defines, &[]);
                params.push(
                    expr::eval_const(&e, &|_| None)
                        .map_err(|msg| compile_err("axiom module", None, k, None, msg))?,
                );
            }
            s.push(id, &params)?;
        }
        Ok(s)
    }

    fn pattern(&mut self, items: &[PatternItem]) -> Vec<Pat> {
        items
            .iter()
            .map(|i| match i {
                PatternItem::Module(m) => {
                    ContextItem::Module((self.intern(&m.symbol), m.params.len() as u32))
                }
                PatternItem::Open => ContextItem::Open,
                PatternItem::Close => ContextItem::Close,
            })
            .collect()
    }

    fn add_production(
        &mut self,
        p: &ProductionAst,
        index: usize,
        loc: Option<&Location>,
    ) -> Result<()> {
        let err = |m: String| compile_err("production", p.label.as_deref(), index, loc, m);
        if p.left.iter().any(|i| !matches!(i, PatternItem::Module(_))) {
            return Err(err("brackets are not allowed in a left context".into()));
        }
        if p.section != Section::Productions && (!p.left.is_empty() || !p.right.is_empty()) {
            return Err(err(
                "decomposition and interpretation rules are context-free: remove the context"
                    .into(),
            ));
        }
        let mut formals: Vec<String> = Vec::new();
        let modules = p
            .left
            .iter()
            .filter_map(|i| match i {
                PatternItem::Module(m) => Some(m),
                _ => None,
            })
            .chain(std::iter::once(&p.predecessor))
            .chain(p.right.iter().filter_map(|i| match i {
                PatternItem::Module(m) => Some(m),
                _ => None,
            }));
        for m in modules {
            for n in &m.params {
                if formals.contains(n) {
                    return Err(err(format!("parameter `{n}` is bound twice")));
                }
                formals.push(n.clone());
            }
        }
        let pred = self.intern(&p.predecessor.symbol);
        if matches!(
            self.kinds.get(pred as usize),
            Some(ModuleKind::BranchOpen | ModuleKind::BranchClose | ModuleKind::Cut)
        ) {
            return Err(err(format!(
                "`{}` cannot be a predecessor",
                p.predecessor.symbol
            )));
        }
        let left = self.pattern(&p.left);
        let right = self.pattern(&p.right);
        let slot = |n: &str| formals.iter().position(|f| f == n).map(|k| k as u32);
        let condition = match &p.condition {
            None => None,
            Some(c) => Some(
                self.compile_arg(&substitute(c, &self.defines, &formals), &slot)
                    .map_err(err)?,
            ),
        };
        let mut successor = Vec::with_capacity(p.successor.len());
        for m in &p.successor {
            let symbol = self.intern(&m.symbol);
            let mut args = Vec::with_capacity(m.args.len());
            for a in &m.args {
                let e = substitute(a, &self.defines, &formals);
                let arg = match &e {
                    Expr::Var(n) => {
                        Arg::Var(slot(n).ok_or_else(|| err(format!("unknown name `{n}`")))?)
                    }
                    _ => self.compile_arg(&e, &slot).map_err(err)?,
                };
                args.push(arg);
            }
            successor.push(SuccModule { symbol, args });
        }
        let probability = match &p.probability {
            None => None,
            Some(w) => {
                let v =
                    expr::eval_const(&substitute(w, &self.defines, &[]), &|_| None).map_err(err)?;
                if !(v.is_finite() && v >= 0.0) {
                    return Err(err(format!(
                        "probability {v} is not a finite non-negative number"
                    )));
                }
                Some(v)
            }
        };
        if !left.is_empty() || !right.is_empty() {
            self.context_sensitive = true;
        }
        let table = match p.section {
            Section::Productions => &mut self.productions,
            Section::Decomposition => &mut self.decompositions,
            Section::Interpretation => &mut self.interpretations,
        };
        let id = table.productions.len() as u32;
        table.productions.push(CProduction {
            arity: p.predecessor.params.len() as u32,
            left,
            right,
            condition,
            successor,
            probability,
        });
        let sym = pred as usize;
        if table.by_symbol.len() <= sym {
            table.by_symbol.resize_with(sym + 1, Vec::new);
        }
        if let Some(l) = table.by_symbol.get_mut(sym) {
            l.push(id);
        }
        Ok(())
    }

    /// Compiles an expression (defines already substituted) into its fastest form.
    fn compile_arg(
        &mut self,
        e: &Expr,
        slot: &dyn Fn(&str) -> Option<u32>,
    ) -> core::result::Result<Arg, String> {
        if let Some(a) = simple_shape(e, slot)? {
            return Ok(a);
        }
        // `a op b` of two simple shapes (e.g. `0.25*x + 0.75*y`, `x + y + z`): evaluated
        // left then right like the bytecode, so the result is bit-identical.
        if let Expr::Binary(op, a, b) = e
            && let (Ok(Some(x)), Ok(Some(y))) = (simple_shape(a, slot), simple_shape(b, slot))
        {
            self.pairs.push((x, y));
            return Ok(Arg::Pair(*op, (self.pairs.len() - 1) as u32));
        }
        let start = self.code.len() as u32;
        expr::compile(e, slot, &mut self.code)?;
        Ok(Arg::Code(start, self.code.len() as u32))
    }

    /// The syntax tree this grammar was compiled from.
    pub fn ast(&self) -> &GrammarAst {
        &self.ast
    }

    /// The grammar as text (pretty-printed; parses back to the same syntax tree).
    pub fn to_text(&self) -> String {
        self.ast.to_string()
    }

    /// The axiom.
    pub fn axiom(&self) -> &ParamString {
        &self.axiom
    }

    /// The value of a `#define` constant.
    pub fn constant(&self, name: &str) -> Option<f64> {
        self.defines
            .iter()
            .rev()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }

    /// The id of a symbol used by the grammar (or built in).
    pub fn symbol_id(&self, name: &str) -> Option<u32> {
        self.names.iter().position(|n| n == name).map(|i| i as u32)
    }

    /// The name of a symbol id.
    pub fn symbol_name(&self, id: u32) -> Option<&str> {
        self.names.get(id as usize).map(String::as_str)
    }

    /// Parses a module string with constant arguments (names: `#define` constants) over
    /// this grammar's symbols, e.g. to start from another axiom.
    pub fn parse_string(&self, text: &str) -> Result<ParamString> {
        let names: Vec<String> = self.defines.iter().map(|(n, _)| n.clone()).collect();
        let calls = parse::parse_modules(text, &names, &self.ast.modules)?;
        let mut s = ParamString::new();
        for m in &calls {
            let Some(id) = self.symbol_id(&m.symbol) else {
                return Err(LsystemError::Parse {
                    line: 1,
                    column: 1,
                    message: format!("symbol `{}` does not occur in the grammar", m.symbol),
                    snippet: text.chars().take(40).collect(),
                });
            };
            let mut params = Vec::with_capacity(m.args.len());
            for a in &m.args {
                let e = substitute(a, &self.defines, &[]);
                params.push(expr::eval_const(&e, &|_| None).map_err(|msg| {
                    LsystemError::Parse {
                        line: 1,
                        column: 1,
                        message: msg,
                        snippet: text.chars().take(40).collect(),
                    }
                })?);
            }
            s.push(id, &params)?;
        }
        Ok(s)
    }

    /// Formats a string of this grammar, e.g. `F(1)+F(0.5)[A]`.
    pub fn format_string(&self, s: &ParamString) -> String {
        let mut out = String::new();
        for (sym, params) in s.iter() {
            out.push_str(self.symbol_name(sym).unwrap_or("�"));
            if !params.is_empty() {
                out.push('(');
                for (k, p) in params.iter().enumerate() {
                    if k > 0 {
                        out.push(',');
                    }
                    out.push_str(&p.to_string());
                }
                out.push(')');
            }
        }
        out
    }

    /// A derivation from the axiom that borrows this grammar.
    pub fn derivation(&self, options: DeriveOptions) -> Derivation<&Grammar> {
        Derivation::new(self, self.axiom.clone(), options)
    }

    /// A derivation from the axiom that owns this grammar.
    pub fn into_derivation(self, options: DeriveOptions) -> Derivation<Grammar> {
        let axiom = self.axiom.clone();
        Derivation::new(self, axiom, options)
    }

    #[inline]
    fn kind_of(&self, s: &ParamString, i: usize) -> ModuleKind {
        self.kinds
            .get(s.symbol(i) as usize)
            .copied()
            .unwrap_or(ModuleKind::Plain)
    }
}

/// `e` as one of the simple argument shapes (constant, parameter, `x op c`, `c op x`,
/// `x op y`), if it is one.
fn simple_shape(
    e: &Expr,
    slot: &dyn Fn(&str) -> Option<u32>,
) -> core::result::Result<Option<Arg>, String> {
    let var = |e: &Expr| match e {
        Expr::Var(n) => slot(n),
        _ => None,
    };
    let num = |e: &Expr| match e {
        Expr::Num(v) => Some(*v),
        _ => None,
    };
    if !has_vars(e) && !e.is_random() {
        return Ok(Some(Arg::Const(expr::eval_const(e, &|_| None)?)));
    }
    if let Some(k) = var(e) {
        return Ok(Some(Arg::Var(k)));
    }
    if let Expr::Binary(op, a, b) = e {
        match (var(a), num(a), var(b), num(b)) {
            (Some(x), _, _, Some(c)) => return Ok(Some(Arg::VarConst(x, *op, c))),
            (_, Some(c), Some(y), _) => return Ok(Some(Arg::ConstVar(c, *op, y))),
            (Some(x), _, Some(y), _) => return Ok(Some(Arg::VarVar(x, *op, y))),
            _ => {}
        }
    }
    Ok(None)
}

struct TextView<'a> {
    g: &'a Grammar,
    s: &'a ParamString,
}

impl ContextView for TextView<'_> {
    #[inline]
    fn len(&self) -> usize {
        self.s.len()
    }
    #[inline]
    fn kind(&self, i: usize) -> ModuleKind {
        self.g.kind_of(self.s, i)
    }
    #[inline]
    fn ignored(&self, i: usize) -> bool {
        self.g
            .ignore
            .get(self.s.symbol(i) as usize)
            .copied()
            .unwrap_or(false)
    }
}

static EMPTY_BRANCHES: std::sync::LazyLock<BranchIndex> =
    std::sync::LazyLock::new(BranchIndex::default);

impl Rules for Grammar {
    type String = ParamString;
    type Scratch = GrammarScratch;

    #[inline]
    fn kind(&self, s: &ParamString, i: usize) -> ModuleKind {
        self.kind_of(s, i)
    }
    #[inline]
    fn command(&self, s: &ParamString, i: usize) -> Command {
        let c = self
            .commands
            .get(s.symbol(i) as usize)
            .copied()
            .unwrap_or(Command::None);
        with_arg(c, s.params(i).first().copied())
    }
    #[inline]
    fn is_ignored(&self, s: &ParamString, i: usize) -> bool {
        self.ignore
            .get(s.symbol(i) as usize)
            .copied()
            .unwrap_or(false)
    }
    fn is_context_sensitive(&self) -> bool {
        self.context_sensitive
    }
    #[inline]
    fn rewrite(
        &self,
        src: &ParamString,
        i: usize,
        branches: &BranchIndex,
        rng: &mut Pcg64Mcg,
        scratch: &mut GrammarScratch,
        dst: &mut ParamString,
    ) -> Result<bool> {
        // Most modules of a string have no production (turtle symbols, brackets): that is
        // decided here, inline, without entering `apply`.
        match self.productions.by_symbol.get(src.symbol(i) as usize) {
            Some(list) if !list.is_empty() => {
                Ok(self.apply(&self.productions, src, i, branches, rng, scratch, dst))
            }
            _ => Ok(false),
        }
    }
    fn has_decomposition(&self) -> bool {
        !self.decompositions.productions.is_empty()
    }
    fn decompose(
        &self,
        src: &ParamString,
        i: usize,
        rng: &mut Pcg64Mcg,
        scratch: &mut GrammarScratch,
        dst: &mut ParamString,
    ) -> Result<bool> {
        Ok(self.apply(
            &self.decompositions,
            src,
            i,
            &EMPTY_BRANCHES,
            rng,
            scratch,
            dst,
        ))
    }
    fn has_interpretation(&self) -> bool {
        !self.interpretations.productions.is_empty()
    }
    fn interpret(
        &self,
        src: &ParamString,
        i: usize,
        rng: &mut Pcg64Mcg,
        scratch: &mut GrammarScratch,
        dst: &mut ParamString,
    ) -> Result<bool> {
        Ok(self.apply(
            &self.interpretations,
            src,
            i,
            &EMPTY_BRANCHES,
            rng,
            scratch,
            dst,
        ))
    }
    fn fill_query(&self, s: &mut ParamString, i: usize, kind: QueryKind, state: &TurtleState) {
        let v = match kind {
            QueryKind::Position => state.position,
            QueryKind::Heading => state.heading,
            QueryKind::Up => state.up,
            QueryKind::Left => state.left,
        };
        for (p, c) in s.params_mut(i).iter_mut().zip([v.x, v.y, v.z]) {
            *p = c;
        }
    }
    fn needs_pass(&self, s: &ParamString) -> bool {
        // The grammar's own rules may produce query/communication modules; a string set
        // from outside (restart, string_mut) may hold them too.
        self.needs_pass
            || (0..s.len()).any(|i| {
                self.pass_symbols
                    .get(s.symbol(i) as usize)
                    .copied()
                    .unwrap_or(false)
            })
    }
    fn may_introduce_pass(&self) -> bool {
        self.introduces_pass
    }
    fn check_storage(&self, s: &ParamString) -> Result<()> {
        if s.arena_overflowed() {
            return Err(LsystemError::TooManyParameters {
                max: crate::string::MAX_PARAMS,
            });
        }
        Ok(())
    }
}
