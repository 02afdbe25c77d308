//! The pretty-printer: grammar syntax tree → text that parses back to the same tree.

use std::fmt::{self, Write};

use super::ast::{GrammarAst, ModuleCall, ModulePattern, PatternItem, Section};
use super::expr::{BinaryOp, Expr, UnaryOp};

fn needs_parens_left(op: BinaryOp, child: &Expr) -> bool {
    match child {
        Expr::Cond(..) => true,
        Expr::Unary(..) => op == BinaryOp::Pow,
        Expr::Binary(c, ..) => {
            let (p, cp) = (op.precedence(), c.precedence());
            cp < p || (cp == p && (op == BinaryOp::Pow || p == 3))
        }
        _ => false,
    }
}

fn needs_parens_right(op: BinaryOp, child: &Expr) -> bool {
    match child {
        Expr::Cond(..) => true,
        Expr::Binary(c, ..) => {
            let (p, cp) = (op.precedence(), c.precedence());
            cp < p || (cp == p && op != BinaryOp::Pow)
        }
        _ => false,
    }
}

fn write_wrapped(out: &mut String, e: &Expr, parens: bool) -> fmt::Result {
    if parens {
        out.push('(');
        write_expr(out, e)?;
        out.push(')');
        Ok(())
    } else {
        write_expr(out, e)
    }
}

/// Writes an expression with the fewest parentheses that keep its tree.
pub fn write_expr(out: &mut String, e: &Expr) -> fmt::Result {
    match e {
        Expr::Num(v) => write!(out, "{v}"),
        Expr::Var(n) => write!(out, "{n}"),
        Expr::Unary(op, a) => {
            out.push(match op {
                UnaryOp::Neg => '-',
                UnaryOp::Plus => '+',
                UnaryOp::Not => '!',
            });
            let parens = match &**a {
                Expr::Cond(..) => true,
                Expr::Binary(b, ..) => *b != BinaryOp::Pow,
                _ => false,
            };
            write_wrapped(out, a, parens)
        }
        Expr::Binary(op, a, b) => {
            write_wrapped(out, a, needs_parens_left(*op, a))?;
            write!(out, " {} ", op.text())?;
            write_wrapped(out, b, needs_parens_right(*op, b))
        }
        Expr::Cond(c, a, b) => {
            write_wrapped(out, c, matches!(**c, Expr::Cond(..)))?;
            out.push_str(" ? ");
            write_expr(out, a)?;
            out.push_str(" : ");
            write_expr(out, b)
        }
        Expr::Call(f, args) => {
            write!(out, "{}(", f.name())?;
            for (k, a) in args.iter().enumerate() {
                if k > 0 {
                    out.push_str(", ");
                }
                write_expr(out, a)?;
            }
            out.push(')');
            Ok(())
        }
    }
}

fn write_call(out: &mut String, m: &ModuleCall) -> fmt::Result {
    out.push_str(&m.symbol);
    if !m.args.is_empty() {
        out.push('(');
        for (k, a) in m.args.iter().enumerate() {
            if k > 0 {
                out.push_str(", ");
            }
            write_expr(out, a)?;
        }
        out.push(')');
    }
    Ok(())
}

fn write_pattern(out: &mut String, m: &ModulePattern) {
    out.push_str(&m.symbol);
    if !m.params.is_empty() {
        out.push('(');
        out.push_str(&m.params.join(", "));
        out.push(')');
    }
}

fn write_items(out: &mut String, items: &[PatternItem]) {
    for (k, i) in items.iter().enumerate() {
        if k > 0 {
            out.push(' ');
        }
        match i {
            PatternItem::Module(m) => write_pattern(out, m),
            PatternItem::Open => out.push('['),
            PatternItem::Close => out.push(']'),
        }
    }
}

/// Writes a whole grammar: defines, ignore and communication sets, axiom, then the
/// productions in order with a section directive wherever the section changes.
pub fn write_grammar(out: &mut String, g: &GrammarAst) -> fmt::Result {
    if !g.modules.is_empty() {
        writeln!(out, "#module {}", g.modules.join(" "))?;
    }
    // With multi-character names, modules are separated by spaces so that `A B` never
    // reads back as a module `AB`.
    let sep = if g.modules.is_empty() { "" } else { " " };
    for d in &g.defines {
        write!(out, "#define {} ", d.name)?;
        write_expr(out, &d.value)?;
        out.push('\n');
    }
    if !g.ignore.is_empty() {
        writeln!(out, "#ignore {}", g.ignore.join(" "))?;
    }
    if !g.communication.is_empty() {
        writeln!(out, "#communication {}", g.communication.join(" "))?;
    }
    if !g.axiom.is_empty() {
        out.push_str("#axiom ");
        for (k, m) in g.axiom.iter().enumerate() {
            if k > 0 {
                out.push_str(sep);
            }
            write_call(out, m)?;
        }
        out.push('\n');
    }
    let mut section = Section::Productions;
    for p in &g.productions {
        if p.section != section {
            section = p.section;
            out.push_str(match section {
                Section::Productions => "#productions\n",
                Section::Decomposition => "#decomposition\n",
                Section::Interpretation => "#interpretation\n",
            });
        }
        if let Some(l) = &p.label {
            write!(out, "{l}: ")?;
        }
        if !p.left.is_empty() {
            write_items(out, &p.left);
            out.push_str(" < ");
        }
        write_pattern(out, &p.predecessor);
        if !p.right.is_empty() {
            out.push_str(" > ");
            write_items(out, &p.right);
        }
        if let Some(c) = &p.condition {
            out.push_str(" : ");
            write_expr(out, c)?;
        }
        out.push_str(" -> ");
        if p.successor.is_empty() {
            out.push('ε');
        } else {
            for (k, m) in p.successor.iter().enumerate() {
                if k > 0 {
                    out.push_str(sep);
                }
                write_call(out, m)?;
            }
        }
        if let Some(w) = &p.probability {
            out.push_str(" : ");
            write_expr(out, w)?;
        }
        out.push('\n');
    }
    Ok(())
}

impl fmt::Display for GrammarAst {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut s = String::new();
        write_grammar(&mut s, self)?;
        f.write_str(&s)
    }
}

impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut s = String::new();
        write_expr(&mut s, self)?;
        f.write_str(&s)
    }
}
