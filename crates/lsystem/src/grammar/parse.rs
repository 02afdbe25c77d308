//! The grammar parser: a hand-written recursive-descent parser over characters that
//! reports errors with line, column and the offending text, and never panics.

use super::ast::{
    Define, GrammarAst, ModuleCall, ModulePattern, PatternItem, ProductionAst, Section,
};
use super::compile::Location;
use super::expr::{BinaryOp, Expr, Func, UnaryOp};
use crate::error::{LsystemError, Result};

/// Deepest nesting of expressions the parser accepts.
pub const MAX_NESTING: usize = 200;

/// Characters that are module symbols on their own.
pub(crate) const PUNCT_SYMBOLS: &str = "+-&^\\/|$[]!'%{}.~";

pub(crate) fn parse(text: &str) -> Result<(GrammarAst, Vec<Location>)> {
    let mut p = Parser {
        chars: text.chars().collect(),
        pos: 0,
        line_starts: Vec::new(),
        depth: 0,
        defines: Vec::new(),
        formals: Vec::new(),
        section: Section::Productions,
        ast: GrammarAst::default(),
        axiom_seen: false,
        locations: Vec::new(),
        modules: Vec::new(),
    };
    p.line_starts.push(0);
    for (i, c) in p.chars.iter().enumerate() {
        if *c == '\n' {
            p.line_starts.push(i + 1);
        }
    }
    p.grammar()?;
    Ok((p.ast, p.locations))
}

/// Parses a module string with constant arguments (e.g. an axiom), resolving names
/// with `defines`.
pub(crate) fn parse_modules(
    text: &str,
    defines: &[String],
    modules: &[String],
) -> Result<Vec<ModuleCall>> {
    let mut p = Parser {
        chars: text.chars().collect(),
        pos: 0,
        line_starts: vec![0],
        depth: 0,
        defines: defines.to_vec(),
        formals: Vec::new(),
        section: Section::Productions,
        ast: GrammarAst::default(),
        axiom_seen: false,
        locations: Vec::new(),
        modules: Vec::new(),
    };
    for m in modules {
        p.declare(m);
    }
    for (i, c) in p.chars.iter().enumerate() {
        if *c == '\n' {
            p.line_starts.push(i + 1);
        }
    }
    let calls = p.calls()?;
    p.skip_ws()?;
    if p.peek().is_some() {
        return Err(p.err(p.pos, "expected a module symbol"));
    }
    Ok(calls)
}

struct Parser {
    chars: Vec<char>,
    pos: usize,
    line_starts: Vec<usize>,
    depth: usize,
    defines: Vec<String>,
    formals: Vec<String>,
    section: Section,
    ast: GrammarAst,
    axiom_seen: bool,
    locations: Vec<Location>,
    /// Declared multi-character module names, longest first.
    modules: Vec<Vec<char>>,
}

fn is_ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_ident_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

impl Parser {
    fn declare(&mut self, name: &str) {
        let chars: Vec<char> = name.chars().collect();
        if !self.modules.contains(&chars) {
            self.modules.push(chars);
            self.modules
                .sort_by(|a, b| b.len().cmp(&a.len()).then(a.cmp(b)));
        }
    }

    fn is_module_name(&self, word: &str) -> bool {
        let chars: Vec<char> = word.chars().collect();
        self.modules.contains(&chars)
    }

    fn peek(&self) -> Option<char> {
        self.chars.get(self.pos).copied()
    }

    fn peek_at(&self, k: usize) -> Option<char> {
        self.chars.get(self.pos + k).copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek();
        if c.is_some() {
            self.pos += 1;
        }
        c
    }

    fn location(&self, pos: usize) -> Location {
        match self.err(pos, "") {
            LsystemError::Parse {
                line,
                column,
                snippet,
                ..
            } => Location {
                line,
                column,
                text: snippet,
            },
            _ => Location::default(),
        }
    }

    fn err(&self, pos: usize, message: impl Into<String>) -> LsystemError {
        let line = match self.line_starts.binary_search(&pos) {
            Ok(l) => l,
            Err(l) => l.saturating_sub(1),
        };
        let start = self.line_starts.get(line).copied().unwrap_or(0);
        let column = pos.saturating_sub(start) + 1;
        let rest: String = self
            .chars
            .get(pos..)
            .unwrap_or(&[])
            .iter()
            .take_while(|c| **c != '\n')
            .take(40)
            .collect();
        let snippet = if rest.trim().is_empty() {
            if pos >= self.chars.len() {
                "end of input".to_string()
            } else {
                "end of line".to_string()
            }
        } else {
            rest.trim_end().to_string()
        };
        LsystemError::Parse {
            line: line + 1,
            column,
            message: message.into(),
            snippet,
        }
    }

    /// Skips spaces, tabs, carriage returns and block comments (not newlines).
    fn skip_ws(&mut self) -> Result<()> {
        loop {
            match self.peek() {
                Some(' ' | '\t' | '\r') => self.pos += 1,
                Some('/') if self.peek_at(1) == Some('*') => {
                    let start = self.pos;
                    self.pos += 2;
                    loop {
                        match self.bump() {
                            None => {
                                return Err(self.err(start, "unterminated block comment: add `*/`"));
                            }
                            Some('*') if self.peek() == Some('/') => {
                                self.pos += 1;
                                break;
                            }
                            _ => {}
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn skip_line(&mut self) {
        while let Some(c) = self.peek() {
            if c == '\n' {
                break;
            }
            self.pos += 1;
        }
    }

    fn at_end_of_statement(&self) -> bool {
        matches!(self.peek(), None | Some('\n' | ';'))
    }

    fn ident(&mut self) -> Option<String> {
        if !self.peek().is_some_and(is_ident_start) {
            return None;
        }
        let start = self.pos;
        while self.peek().is_some_and(is_ident_char) {
            self.pos += 1;
        }
        Some(
            self.chars
                .get(start..self.pos)
                .unwrap_or(&[])
                .iter()
                .collect(),
        )
    }

    fn expect(&mut self, c: char, what: &str) -> Result<()> {
        self.skip_ws()?;
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.err(self.pos, format!("expected {what}")))
        }
    }

    fn grammar(&mut self) -> Result<()> {
        loop {
            self.skip_ws()?;
            match self.peek() {
                None => return Ok(()),
                Some('\n' | ';') => {
                    self.pos += 1;
                    continue;
                }
                Some('/') if self.peek_at(1) == Some('/') => {
                    self.skip_line();
                    continue;
                }
                Some('#') => {
                    if self.peek_at(1).is_some_and(|c| c.is_ascii_alphabetic()) {
                        self.directive()?;
                    } else {
                        self.skip_line();
                        continue;
                    }
                }
                Some(_) => self.statement()?,
            }
            self.skip_ws()?;
            if !self.at_end_of_statement() {
                return Err(self.err(self.pos, "unexpected text after the statement"));
            }
        }
    }

    fn optional_colon(&mut self) -> Result<()> {
        self.skip_ws()?;
        if self.peek() == Some(':') {
            self.pos += 1;
        }
        Ok(())
    }

    fn directive(&mut self) -> Result<()> {
        let at = self.pos;
        self.pos += 1;
        let word = self.ident().unwrap_or_default();
        match word.as_str() {
            "define" => {
                self.skip_ws()?;
                let name_at = self.pos;
                let Some(name) = self.ident() else {
                    return Err(self.err(name_at, "expected a constant name after #define"));
                };
                if Func::lookup(&name).is_some() || name == "pi" {
                    return Err(self.err(name_at, format!("`{name}` is a built-in name")));
                }
                self.formals.clear();
                let value = self.expr()?;
                if value.is_random() {
                    return Err(self.err(
                        name_at,
                        "a #define must be constant: random functions are not allowed",
                    ));
                }
                self.defines.push(name.clone());
                self.ast.defines.push(Define { name, value });
            }
            "module" | "modules" => {
                self.optional_colon()?;
                loop {
                    self.skip_ws()?;
                    if self.at_end_of_statement() {
                        break;
                    }
                    let n_at = self.pos;
                    match self.ident() {
                        Some(n) if n.chars().count() >= 2 => {
                            if Func::lookup(&n).is_some() || n == "pi" || n == "axiom" {
                                return Err(self.err(
                                    n_at,
                                    format!("`{n}` is reserved and cannot be a module name"),
                                ));
                            }
                            if !self.ast.modules.contains(&n) {
                                self.ast.modules.push(n.clone());
                            }
                            self.declare(&n);
                        }
                        _ => {
                            return Err(self.err(
                                n_at,
                                "#module declares names of two or more letters, digits or `_`, starting with a letter",
                            ));
                        }
                    }
                }
            }
            "ignore" | "communication" | "comm" => {
                self.optional_colon()?;
                let mut syms = Vec::new();
                loop {
                    self.skip_ws()?;
                    if self.at_end_of_statement() {
                        break;
                    }
                    let s_at = self.pos;
                    match self.symbol() {
                        Some(s) => syms.push(s),
                        None => return Err(self.err(s_at, "expected a module symbol")),
                    }
                }
                if word == "ignore" {
                    self.ast.ignore.extend(syms);
                } else {
                    self.ast.communication.extend(syms);
                }
            }
            "axiom" => {
                self.optional_colon()?;
                self.axiom(at)?;
            }
            "productions" | "production" => {
                self.optional_colon()?;
                self.section = Section::Productions;
            }
            "decomposition" => {
                self.optional_colon()?;
                self.section = Section::Decomposition;
            }
            "interpretation" | "homomorphism" => {
                self.optional_colon()?;
                self.section = Section::Interpretation;
            }
            _ => {
                return Err(self.err(
                    at,
                    format!(
                        "unknown directive `#{word}` (known: #define, #ignore, #communication, #axiom, \
                         #productions, #decomposition, #interpretation)"
                    ),
                ));
            }
        }
        Ok(())
    }

    fn axiom(&mut self, at: usize) -> Result<()> {
        if self.axiom_seen {
            return Err(self.err(at, "a second axiom; a grammar has one"));
        }
        self.axiom_seen = true;
        self.formals.clear();
        let calls = self.calls()?;
        for c in &calls {
            if c.args.iter().any(Expr::is_random) {
                return Err(self.err(
                    at,
                    "the axiom must be constant: random functions are not allowed",
                ));
            }
        }
        self.ast.axiom = calls;
        Ok(())
    }

    fn statement(&mut self) -> Result<()> {
        let start = self.pos;
        if self.peek() == Some('ω') {
            self.pos += 1;
            self.expect(':', "`:` after ω")?;
            return self.axiom(start);
        }
        // A label (identifier of two or more characters followed by `:`), or `axiom:`.
        let mut label = None;
        if let Some(word) = self.ident() {
            self.skip_ws()?;
            if word.chars().count() >= 2 && self.peek() == Some(':') && !self.is_module_name(&word)
            {
                self.pos += 1;
                if word == "axiom" {
                    return self.axiom(start);
                }
                label = Some(word);
            } else {
                self.pos = start;
            }
        }
        self.production(label)
    }

    fn arrow_ahead(&self) -> bool {
        (self.peek() == Some('-') && self.peek_at(1) == Some('>')) || self.peek() == Some('→')
    }

    fn symbol(&mut self) -> Option<String> {
        let c = self.peek()?;
        for m in &self.modules {
            if self.chars.get(self.pos..self.pos + m.len()) == Some(m.as_slice()) {
                self.pos += m.len();
                return Some(m.iter().collect());
            }
        }
        if c.is_ascii_alphabetic() {
            self.pos += 1;
            return Some(c.to_string());
        }
        if c == '?' || c == '@' {
            let d = self.peek_at(1)?;
            if d.is_ascii_alphabetic() {
                self.pos += 2;
                return Some(format!("{c}{d}"));
            }
            return None;
        }
        if PUNCT_SYMBOLS.contains(c) {
            self.pos += 1;
            return Some(c.to_string());
        }
        None
    }

    fn pattern_items(&mut self) -> Result<Vec<(usize, PatternItem)>> {
        let mut items = Vec::new();
        loop {
            self.skip_ws()?;
            if self.arrow_ahead() {
                break;
            }
            let at = self.pos;
            match self.peek() {
                Some('[') => {
                    self.pos += 1;
                    items.push((at, PatternItem::Open));
                }
                Some(']') => {
                    self.pos += 1;
                    items.push((at, PatternItem::Close));
                }
                _ => {
                    let Some(symbol) = self.symbol() else { break };
                    let mut params = Vec::new();
                    self.skip_ws()?;
                    if self.peek() == Some('(') {
                        self.pos += 1;
                        loop {
                            self.skip_ws()?;
                            let p_at = self.pos;
                            let Some(name) = self.ident() else {
                                return Err(self.err(p_at, "expected a parameter name"));
                            };
                            params.push(name);
                            self.skip_ws()?;
                            match self.bump() {
                                Some(',') => continue,
                                Some(')') => break,
                                _ => {
                                    return Err(
                                        self.err(self.pos.saturating_sub(1), "expected `,` or `)`")
                                    );
                                }
                            }
                        }
                    }
                    items.push((at, PatternItem::Module(ModulePattern { symbol, params })));
                }
            }
        }
        Ok(items)
    }

    fn single(&self, items: Vec<(usize, PatternItem)>, at: usize) -> Result<ModulePattern> {
        let mut it = items.into_iter();
        match (it.next(), it.next()) {
            (Some((_, PatternItem::Module(m))), None) => Ok(m),
            (None, _) => Err(self.err(at, "expected a predecessor module")),
            (Some((p, PatternItem::Open | PatternItem::Close)), _) => {
                Err(self.err(p, "a bracket cannot be a predecessor"))
            }
            (Some(_), Some((p, _))) => Err(self.err(
                p,
                "the predecessor is a single module; use `<` and `>` to give a context",
            )),
        }
    }

    fn production(&mut self, label: Option<String>) -> Result<()> {
        self.skip_ws()?;
        let start = self.pos;
        let first = self.pattern_items()?;
        self.skip_ws()?;
        let mut left = Vec::new();
        let predecessor;
        if self.peek() == Some('<') {
            self.pos += 1;
            if let Some((p, _)) = first
                .iter()
                .find(|(_, i)| !matches!(i, PatternItem::Module(_)))
            {
                return Err(self.err(*p, "brackets are not allowed in a left context"));
            }
            left = first.into_iter().map(|(_, i)| i).collect();
            self.skip_ws()?;
            let at = self.pos;
            let pred = self.pattern_items()?;
            predecessor = self.single(pred, at)?;
        } else {
            predecessor = self.single(first, start)?;
        }
        self.skip_ws()?;
        let mut right = Vec::new();
        if self.peek() == Some('>') {
            self.pos += 1;
            right = self.pattern_items()?.into_iter().map(|(_, i)| i).collect();
        }
        // Formal parameters, in text order: left context, predecessor, right context.
        self.formals.clear();
        let mut lists: Vec<&[String]> = Vec::new();
        for i in &left {
            if let PatternItem::Module(m) = i {
                lists.push(&m.params);
            }
        }
        lists.push(&predecessor.params);
        for i in &right {
            if let PatternItem::Module(m) = i {
                lists.push(&m.params);
            }
        }
        let mut formals: Vec<String> = Vec::new();
        for name in lists.into_iter().flatten() {
            if formals.contains(name) {
                return Err(self.err(start, format!("parameter `{name}` is bound twice")));
            }
            formals.push(name.clone());
        }
        self.formals = formals;
        self.skip_ws()?;
        let mut condition = None;
        if self.peek() == Some(':') {
            self.pos += 1;
            self.skip_ws()?;
            if self.peek() == Some('*') {
                self.pos += 1;
            } else {
                condition = Some(self.expr()?);
            }
        }
        self.skip_ws()?;
        if self.peek() == Some('→') {
            self.pos += 1;
        } else if self.arrow_ahead() {
            self.pos += 2;
        } else {
            return Err(self.err(self.pos, "expected `->` (or `→`)"));
        }
        self.skip_ws()?;
        let successor = if self.peek() == Some('ε') {
            self.pos += 1;
            Vec::new()
        } else {
            self.calls()?
        };
        self.skip_ws()?;
        let mut probability = None;
        if self.peek() == Some(':') {
            self.pos += 1;
            let at = self.pos;
            self.formals.clear();
            let e = self.expr()?;
            if e.is_random() {
                return Err(self.err(at, "a probability must be constant"));
            }
            probability = Some(e);
        }
        self.formals.clear();
        self.locations.push(self.location(start));
        self.ast.productions.push(ProductionAst {
            label,
            section: self.section,
            left,
            predecessor,
            right,
            condition,
            successor,
            probability,
        });
        Ok(())
    }

    fn calls(&mut self) -> Result<Vec<ModuleCall>> {
        let mut out = Vec::new();
        loop {
            self.skip_ws()?;
            if self.at_end_of_statement() || self.peek() == Some(':') {
                break;
            }
            let at = self.pos;
            let Some(symbol) = self.symbol() else {
                return Err(self.err(at, "expected a module symbol"));
            };
            let mut args = Vec::new();
            self.skip_ws()?;
            if self.peek() == Some('(') {
                self.pos += 1;
                loop {
                    args.push(self.expr()?);
                    self.skip_ws()?;
                    match self.bump() {
                        Some(',') => continue,
                        Some(')') => break,
                        _ => {
                            return Err(self.err(self.pos.saturating_sub(1), "expected `,` or `)`"));
                        }
                    }
                }
            }
            out.push(ModuleCall { symbol, args });
        }
        Ok(out)
    }

    // ---- expressions -------------------------------------------------------------

    fn enter(&mut self) -> Result<()> {
        self.depth += 1;
        if self.depth > MAX_NESTING {
            return Err(self.err(
                self.pos,
                format!("expression nested deeper than {MAX_NESTING} levels"),
            ));
        }
        Ok(())
    }

    fn expr(&mut self) -> Result<Expr> {
        self.enter()?;
        let r = self.ternary();
        self.depth -= 1;
        r
    }

    fn ternary(&mut self) -> Result<Expr> {
        let c = self.binary_level(1)?;
        self.skip_ws()?;
        if self.peek() == Some('?') {
            self.pos += 1;
            let a = self.expr()?;
            self.expect(':', "`:` of the conditional expression `c ? a : b`")?;
            let b = self.expr()?;
            return Ok(Expr::Cond(Box::new(c), Box::new(a), Box::new(b)));
        }
        Ok(c)
    }

    fn peek_binary(&mut self, level: u8) -> Result<Option<(BinaryOp, usize)>> {
        self.skip_ws()?;
        let (c, d) = (self.peek(), self.peek_at(1));
        let op = match (c, d) {
            (Some('|'), Some('|')) => Some((BinaryOp::Or, 2)),
            (Some('&'), Some('&')) => Some((BinaryOp::And, 2)),
            (Some('<'), Some('=')) => Some((BinaryOp::Le, 2)),
            (Some('>'), Some('=')) => Some((BinaryOp::Ge, 2)),
            (Some('='), Some('=')) => Some((BinaryOp::Eq, 2)),
            (Some('!'), Some('=')) => Some((BinaryOp::Ne, 2)),
            (Some('<'), _) => Some((BinaryOp::Lt, 1)),
            (Some('>'), _) => Some((BinaryOp::Gt, 1)),
            (Some('+'), _) => Some((BinaryOp::Add, 1)),
            (Some('-'), Some('>')) => None,
            (Some('-'), _) => Some((BinaryOp::Sub, 1)),
            (Some('*'), _) => Some((BinaryOp::Mul, 1)),
            (Some('/'), Some('*')) => None,
            (Some('/'), _) => Some((BinaryOp::Div, 1)),
            (Some('%'), _) => Some((BinaryOp::Rem, 1)),
            _ => None,
        };
        Ok(op.filter(|(o, _)| o.precedence() == level))
    }

    /// Left-associative binary levels 1 (||) to 5 (* / %); level 3 (comparisons) is
    /// non-associative.
    fn binary_level(&mut self, level: u8) -> Result<Expr> {
        if level > 5 {
            return self.unary();
        }
        self.enter()?;
        let mut lhs = self.binary_level(level + 1)?;
        while let Some((op, len)) = self.peek_binary(level)? {
            self.pos += len;
            let rhs = self.binary_level(level + 1)?;
            lhs = Expr::Binary(op, Box::new(lhs), Box::new(rhs));
            if level == 3 {
                break;
            }
        }
        self.depth -= 1;
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Expr> {
        self.enter()?;
        self.skip_ws()?;
        let r = match (self.peek(), self.peek_at(1)) {
            (Some('-'), Some(c)) if c != '>' => {
                self.pos += 1;
                Ok(Expr::Unary(UnaryOp::Neg, Box::new(self.unary()?)))
            }
            (Some('+'), _) => {
                self.pos += 1;
                Ok(Expr::Unary(UnaryOp::Plus, Box::new(self.unary()?)))
            }
            (Some('!'), d) if d != Some('=') => {
                self.pos += 1;
                Ok(Expr::Unary(UnaryOp::Not, Box::new(self.unary()?)))
            }
            _ => self.power(),
        };
        self.depth -= 1;
        r
    }

    fn power(&mut self) -> Result<Expr> {
        let base = self.atom()?;
        self.skip_ws()?;
        if self.peek() == Some('^') {
            self.pos += 1;
            let exp = self.unary()?;
            return Ok(Expr::Binary(BinaryOp::Pow, Box::new(base), Box::new(exp)));
        }
        Ok(base)
    }

    fn number(&mut self) -> Result<Expr> {
        let start = self.pos;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.pos += 1;
        }
        if self.peek() == Some('.') {
            self.pos += 1;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.pos += 1;
            }
        }
        if matches!(self.peek(), Some('e' | 'E')) {
            let save = self.pos;
            self.pos += 1;
            if matches!(self.peek(), Some('+' | '-')) {
                self.pos += 1;
            }
            if self.peek().is_some_and(|c| c.is_ascii_digit()) {
                while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                    self.pos += 1;
                }
            } else {
                self.pos = save;
            }
        }
        let text: String = self
            .chars
            .get(start..self.pos)
            .unwrap_or(&[])
            .iter()
            .collect();
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Expr::Num(v)),
            _ => Err(self.err(start, format!("`{text}` is not a finite number"))),
        }
    }

    fn atom(&mut self) -> Result<Expr> {
        self.skip_ws()?;
        let at = self.pos;
        match self.peek() {
            Some(c)
                if c.is_ascii_digit()
                    || (c == '.' && self.peek_at(1).is_some_and(|d| d.is_ascii_digit())) =>
            {
                self.number()
            }
            Some('(') => {
                self.pos += 1;
                let e = self.expr()?;
                self.expect(')', "`)`")?;
                Ok(e)
            }
            Some(c) if is_ident_start(c) => {
                let name = self.ident().unwrap_or_default();
                let after_name = self.pos;
                self.skip_ws()?;
                if self.peek() == Some('(')
                    && !self.formals.contains(&name)
                    && !self.defines.contains(&name)
                {
                    let Some((f, arity)) = Func::lookup(&name) else {
                        return Err(self.err(at, format!("unknown function `{name}`")));
                    };
                    self.pos += 1;
                    let mut args = Vec::new();
                    self.skip_ws()?;
                    if self.peek() == Some(')') {
                        self.pos += 1;
                    } else {
                        loop {
                            args.push(self.expr()?);
                            self.skip_ws()?;
                            match self.bump() {
                                Some(',') => continue,
                                Some(')') => break,
                                _ => {
                                    return Err(
                                        self.err(self.pos.saturating_sub(1), "expected `,` or `)`")
                                    );
                                }
                            }
                        }
                    }
                    if args.len() != arity {
                        return Err(self.err(
                            at,
                            format!("`{name}` takes {arity} argument(s), not {}", args.len()),
                        ));
                    }
                    return Ok(Expr::Call(f, args));
                }
                self.pos = after_name;
                if self.formals.contains(&name) || self.defines.contains(&name) {
                    Ok(Expr::Var(name))
                } else if name == "pi" {
                    Ok(Expr::Num(std::f64::consts::PI))
                } else {
                    Err(self.err(
                        at,
                        format!("unknown name `{name}`: not a parameter of this production nor a #define"),
                    ))
                }
            }
            _ => Err(self.err(at, "expected a number, a name or `(`")),
        }
    }
}
