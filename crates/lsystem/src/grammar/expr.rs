//! Arithmetic expressions: the syntax tree, compilation to a small stack bytecode, and
//! the interpreter. Expressions are compiled once; derivation only runs bytecode.

use rand_pcg::Pcg64Mcg;

use crate::random::{normal_f64, unit_f64};

/// A unary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnaryOp {
    /// `-x`.
    Neg,
    /// `+x`.
    Plus,
    /// `!x` (1 if `x` is false, else 0).
    Not,
}

/// A binary operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinaryOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `%` (remainder with the sign of the dividend)
    Rem,
    /// `^` (power, right-associative)
    Pow,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `&&` (short-circuit)
    And,
    /// `||` (short-circuit)
    Or,
}

impl BinaryOp {
    /// The operator's text.
    pub fn text(self) -> &'static str {
        match self {
            BinaryOp::Add => "+",
            BinaryOp::Sub => "-",
            BinaryOp::Mul => "*",
            BinaryOp::Div => "/",
            BinaryOp::Rem => "%",
            BinaryOp::Pow => "^",
            BinaryOp::Lt => "<",
            BinaryOp::Le => "<=",
            BinaryOp::Gt => ">",
            BinaryOp::Ge => ">=",
            BinaryOp::Eq => "==",
            BinaryOp::Ne => "!=",
            BinaryOp::And => "&&",
            BinaryOp::Or => "||",
        }
    }

    /// Binding strength (higher binds tighter).
    pub fn precedence(self) -> u8 {
        match self {
            BinaryOp::Or => 1,
            BinaryOp::And => 2,
            BinaryOp::Lt
            | BinaryOp::Le
            | BinaryOp::Gt
            | BinaryOp::Ge
            | BinaryOp::Eq
            | BinaryOp::Ne => 3,
            BinaryOp::Add | BinaryOp::Sub => 4,
            BinaryOp::Mul | BinaryOp::Div | BinaryOp::Rem => 5,
            BinaryOp::Pow => 7,
        }
    }
}

/// A built-in function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// `sin(x)` (radians)
    Sin,
    /// `cos(x)`
    Cos,
    /// `tan(x)`
    Tan,
    /// `asin(x)`
    Asin,
    /// `acos(x)`
    Acos,
    /// `atan(x)`
    Atan,
    /// `atan2(y, x)`
    Atan2,
    /// `sqrt(x)`
    Sqrt,
    /// `exp(x)`
    Exp,
    /// `ln(x)` (also `log`)
    Ln,
    /// `log10(x)`
    Log10,
    /// `abs(x)`
    Abs,
    /// `floor(x)`
    Floor,
    /// `ceil(x)`
    Ceil,
    /// `round(x)`
    Round,
    /// `trunc(x)`
    Trunc,
    /// `sign(x)`: -1, 0 or 1
    Sign,
    /// `min(a, b)`
    Min,
    /// `max(a, b)`
    Max,
    /// `pow(a, b)`
    Pow,
    /// `clamp(x, lo, hi)`
    Clamp,
    /// `rand()`: uniform in `[0, 1)` from the seeded generator
    Rand,
    /// `ran(x)`: uniform in `[0, x)` (cpfg)
    Ran,
    /// `uniform(a, b)`: uniform in `[a, b)`
    Uniform,
    /// `nran(mean, sd)` (also `normal`): normal variate
    Normal,
}

impl Func {
    /// Every function with its name(s) and arity.
    pub const ALL: &'static [(&'static str, Func, usize)] = &[
        ("sin", Func::Sin, 1),
        ("cos", Func::Cos, 1),
        ("tan", Func::Tan, 1),
        ("asin", Func::Asin, 1),
        ("acos", Func::Acos, 1),
        ("atan", Func::Atan, 1),
        ("atan2", Func::Atan2, 2),
        ("sqrt", Func::Sqrt, 1),
        ("exp", Func::Exp, 1),
        ("ln", Func::Ln, 1),
        ("log", Func::Ln, 1),
        ("log10", Func::Log10, 1),
        ("abs", Func::Abs, 1),
        ("floor", Func::Floor, 1),
        ("ceil", Func::Ceil, 1),
        ("round", Func::Round, 1),
        ("trunc", Func::Trunc, 1),
        ("sign", Func::Sign, 1),
        ("min", Func::Min, 2),
        ("max", Func::Max, 2),
        ("pow", Func::Pow, 2),
        ("clamp", Func::Clamp, 3),
        ("rand", Func::Rand, 0),
        ("ran", Func::Ran, 1),
        ("uniform", Func::Uniform, 2),
        ("nran", Func::Normal, 2),
        ("normal", Func::Normal, 2),
    ];

    /// Looks a function up by name; returns it with its arity.
    pub fn lookup(name: &str) -> Option<(Func, usize)> {
        Self::ALL
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|&(_, f, a)| (f, a))
    }

    /// The canonical name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, f, _)| *f == self)
            .map_or("?", |(n, _, _)| n)
    }

    /// Number of arguments.
    pub fn arity(self) -> usize {
        Self::ALL
            .iter()
            .find(|(_, f, _)| *f == self)
            .map_or(0, |&(_, _, a)| a)
    }

    /// `true` for the functions that draw from the random generator.
    pub fn is_random(self) -> bool {
        matches!(self, Func::Rand | Func::Ran | Func::Uniform | Func::Normal)
    }
}

/// An expression of the text grammar.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A literal number (finite).
    Num(f64),
    /// A formal parameter or `#define` constant.
    Var(String),
    /// A unary operation.
    Unary(UnaryOp, Box<Expr>),
    /// A binary operation.
    Binary(BinaryOp, Box<Expr>, Box<Expr>),
    /// `c ? a : b`.
    Cond(Box<Expr>, Box<Expr>, Box<Expr>),
    /// A function call.
    Call(Func, Vec<Expr>),
}

impl Expr {
    /// `true` if the expression calls a random function.
    pub fn is_random(&self) -> bool {
        match self {
            Expr::Num(_) | Expr::Var(_) => false,
            Expr::Unary(_, a) => a.is_random(),
            Expr::Binary(_, a, b) => a.is_random() || b.is_random(),
            Expr::Cond(c, a, b) => c.is_random() || a.is_random() || b.is_random(),
            Expr::Call(f, args) => f.is_random() || args.iter().any(Expr::is_random),
        }
    }
}

/// One bytecode instruction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Op {
    Const(f64),
    Var(u32),
    Neg,
    Not,
    Bin(BinaryOp),
    /// Pop `v`; if `v` is false push 0 and jump.
    AndJump(u32),
    /// Pop `v`; if `v` is true push 1 and jump.
    OrJump(u32),
    /// Pop `v`; push 1 if true else 0.
    Truth,
    /// Pop `v`; jump if false.
    JumpIfFalse(u32),
    Jump(u32),
    Call(Func),
}

/// Truth value of a number: non-zero and not NaN.
#[inline]
pub(crate) fn truth(v: f64) -> bool {
    v != 0.0 && !v.is_nan()
}

#[inline]
fn b(v: bool) -> f64 {
    if v { 1.0 } else { 0.0 }
}

#[inline]
pub(crate) fn binary(op: BinaryOp, x: f64, y: f64) -> f64 {
    match op {
        BinaryOp::Add => x + y,
        BinaryOp::Sub => x - y,
        BinaryOp::Mul => x * y,
        BinaryOp::Div => x / y,
        BinaryOp::Rem => x % y,
        BinaryOp::Pow => x.powf(y),
        BinaryOp::Lt => b(x < y),
        BinaryOp::Le => b(x <= y),
        BinaryOp::Gt => b(x > y),
        BinaryOp::Ge => b(x >= y),
        BinaryOp::Eq => b(x == y),
        BinaryOp::Ne => b(x != y),
        BinaryOp::And => b(truth(x) && truth(y)),
        BinaryOp::Or => b(truth(x) || truth(y)),
    }
}

/// Applies a function to its arguments (`args.len() == f.arity()`).
pub(crate) fn call(f: Func, args: &[f64], rng: Option<&mut Pcg64Mcg>) -> f64 {
    let a = |k: usize| args.get(k).copied().unwrap_or(f64::NAN);
    match f {
        Func::Sin => a(0).sin(),
        Func::Cos => a(0).cos(),
        Func::Tan => a(0).tan(),
        Func::Asin => a(0).asin(),
        Func::Acos => a(0).acos(),
        Func::Atan => a(0).atan(),
        Func::Atan2 => a(0).atan2(a(1)),
        Func::Sqrt => a(0).sqrt(),
        Func::Exp => a(0).exp(),
        Func::Ln => a(0).ln(),
        Func::Log10 => a(0).log10(),
        Func::Abs => a(0).abs(),
        Func::Floor => a(0).floor(),
        Func::Ceil => a(0).ceil(),
        Func::Round => a(0).round(),
        Func::Trunc => a(0).trunc(),
        Func::Sign => {
            let x = a(0);
            if x > 0.0 {
                1.0
            } else if x < 0.0 {
                -1.0
            } else {
                x
            }
        }
        Func::Min => a(0).min(a(1)),
        Func::Max => a(0).max(a(1)),
        Func::Pow => a(0).powf(a(1)),
        Func::Clamp => a(0).max(a(1)).min(a(2)),
        Func::Rand => rng.map_or(f64::NAN, unit_f64),
        Func::Ran => rng.map_or(f64::NAN, |r| unit_f64(r) * a(0)),
        Func::Uniform => rng.map_or(f64::NAN, |r| a(0) + unit_f64(r) * (a(1) - a(0))),
        Func::Normal => rng.map_or(f64::NAN, |r| a(0) + normal_f64(r) * a(1)),
    }
}

/// Compiles `e`, resolving variables with `slot`, appending to `code`.
pub(crate) fn compile(
    e: &Expr,
    slot: &dyn Fn(&str) -> Option<u32>,
    code: &mut Vec<Op>,
) -> Result<(), String> {
    match e {
        Expr::Num(v) => code.push(Op::Const(*v)),
        Expr::Var(name) => match slot(name) {
            Some(k) => code.push(Op::Var(k)),
            None => return Err(format!("unknown name `{name}`")),
        },
        Expr::Unary(op, a) => {
            compile(a, slot, code)?;
            match op {
                UnaryOp::Neg => code.push(Op::Neg),
                UnaryOp::Not => code.push(Op::Not),
                UnaryOp::Plus => {}
            }
        }
        Expr::Binary(op @ (BinaryOp::And | BinaryOp::Or), a, bb) => {
            compile(a, slot, code)?;
            let at = code.len();
            code.push(Op::Jump(0));
            compile(bb, slot, code)?;
            code.push(Op::Truth);
            let end = code.len() as u32;
            if let Some(o) = code.get_mut(at) {
                *o = if *op == BinaryOp::And {
                    Op::AndJump(end)
                } else {
                    Op::OrJump(end)
                };
            }
        }
        Expr::Binary(op, a, bb) => {
            compile(a, slot, code)?;
            compile(bb, slot, code)?;
            code.push(Op::Bin(*op));
        }
        Expr::Cond(c, a, bb) => {
            compile(c, slot, code)?;
            let jf = code.len();
            code.push(Op::JumpIfFalse(0));
            compile(a, slot, code)?;
            let j = code.len();
            code.push(Op::Jump(0));
            let else_at = code.len() as u32;
            compile(bb, slot, code)?;
            let end = code.len() as u32;
            if let Some(o) = code.get_mut(jf) {
                *o = Op::JumpIfFalse(else_at);
            }
            if let Some(o) = code.get_mut(j) {
                *o = Op::Jump(end);
            }
        }
        Expr::Call(f, args) => {
            if args.len() != f.arity() {
                return Err(format!(
                    "`{}` takes {} argument(s), not {}",
                    f.name(),
                    f.arity(),
                    args.len()
                ));
            }
            for a in args {
                compile(a, slot, code)?;
            }
            code.push(Op::Call(*f));
        }
    }
    Ok(())
}

/// Runs bytecode. `stack` is scratch space; `rng` is `None` for constant folding.
#[inline]
pub(crate) fn run(
    code: &[Op],
    vars: &[f64],
    stack: &mut Vec<f64>,
    mut rng: Option<&mut Pcg64Mcg>,
) -> f64 {
    stack.clear();
    let mut pc = 0usize;
    while let Some(op) = code.get(pc) {
        pc += 1;
        match *op {
            Op::Const(v) => stack.push(v),
            Op::Var(k) => stack.push(vars.get(k as usize).copied().unwrap_or(f64::NAN)),
            Op::Neg => {
                if let Some(t) = stack.last_mut() {
                    *t = -*t;
                }
            }
            Op::Not => {
                if let Some(t) = stack.last_mut() {
                    *t = b(!truth(*t));
                }
            }
            Op::Truth => {
                if let Some(t) = stack.last_mut() {
                    *t = b(truth(*t));
                }
            }
            Op::Bin(op) => {
                let y = stack.pop().unwrap_or(f64::NAN);
                if let Some(t) = stack.last_mut() {
                    *t = binary(op, *t, y);
                }
            }
            Op::AndJump(t) => {
                let v = stack.pop().unwrap_or(f64::NAN);
                if !truth(v) {
                    stack.push(0.0);
                    pc = t as usize;
                }
            }
            Op::OrJump(t) => {
                let v = stack.pop().unwrap_or(f64::NAN);
                if truth(v) {
                    stack.push(1.0);
                    pc = t as usize;
                }
            }
            Op::JumpIfFalse(t) => {
                if !truth(stack.pop().unwrap_or(f64::NAN)) {
                    pc = t as usize;
                }
            }
            Op::Jump(t) => pc = t as usize,
            Op::Call(f) => {
                let n = f.arity();
                let at = stack.len().saturating_sub(n);
                let v = call(f, stack.get(at..).unwrap_or(&[]), rng.as_deref_mut());
                stack.truncate(at);
                stack.push(v);
            }
        }
    }
    stack.pop().unwrap_or(f64::NAN)
}

/// Evaluates a constant expression (no variables beyond `lookup`, no random functions).
pub(crate) fn eval_const(e: &Expr, lookup: &dyn Fn(&str) -> Option<f64>) -> Result<f64, String> {
    if e.is_random() {
        return Err("random functions are not allowed in a constant expression".into());
    }
    let mut code = Vec::new();
    let names = std::cell::RefCell::new(Vec::<f64>::new());
    compile(
        e,
        &|n| {
            let v = lookup(n)?;
            let mut names = names.borrow_mut();
            names.push(v);
            Some(names.len() as u32 - 1)
        },
        &mut code,
    )?;
    let vars = names.into_inner();
    Ok(run(&code, &vars, &mut Vec::new(), None))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn num(v: f64) -> Box<Expr> {
        Box::new(Expr::Num(v))
    }

    #[test]
    fn short_circuit_and_conditional() {
        // 0 && rand() must not draw; 1 || rand() must not draw.
        let e = Expr::Binary(
            BinaryOp::Or,
            Box::new(Expr::Binary(
                BinaryOp::And,
                num(0.0),
                Box::new(Expr::Call(Func::Rand, vec![])),
            )),
            Box::new(Expr::Cond(num(1.0), num(2.0), num(3.0))),
        );
        let mut code = Vec::new();
        compile(&e, &|_| None, &mut code).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        let mut rng2 = Pcg64Mcg::seed_from_u64(1);
        assert_eq!(run(&code, &[], &mut Vec::new(), Some(&mut rng)), 1.0);
        assert_eq!(unit_f64(&mut rng), unit_f64(&mut rng2));
        let c = Expr::Cond(
            num(0.0),
            num(2.0),
            Box::new(Expr::Binary(BinaryOp::Pow, num(2.0), num(10.0))),
        );
        assert_eq!(eval_const(&c, &|_| None).unwrap(), 1024.0);
        assert!(eval_const(&Expr::Call(Func::Rand, vec![]), &|_| None).is_err());
        assert!(eval_const(&Expr::Var("q".into()), &|_| None).is_err());
        assert!(eval_const(&Expr::Call(Func::Min, vec![Expr::Num(1.0)]), &|_| None).is_err());
    }
}
