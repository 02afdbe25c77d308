//! The syntax tree of a grammar text (what the parser returns and the printer prints).

use super::expr::Expr;

/// Which rule section a production belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Section {
    /// Ordinary productions (`#productions`, the default).
    #[default]
    Productions,
    /// Decomposition rules (`#decomposition`).
    Decomposition,
    /// Interpretation rules (`#interpretation` or `#homomorphism`).
    Interpretation,
}

/// A module in an axiom or successor: a symbol and argument expressions.
#[derive(Debug, Clone, PartialEq)]
pub struct ModuleCall {
    /// The symbol, e.g. `F`, `?P`, `@o`, `[`.
    pub symbol: String,
    /// The arguments.
    pub args: Vec<Expr>,
}

/// A module in a predecessor or context: a symbol and formal parameter names.
#[derive(Debug, Clone, PartialEq)]
pub struct ModulePattern {
    /// The symbol.
    pub symbol: String,
    /// Formal parameter names.
    pub params: Vec<String>,
}

/// An item of a context.
#[derive(Debug, Clone, PartialEq)]
pub enum PatternItem {
    /// A module.
    Module(ModulePattern),
    /// `[` (right context only).
    Open,
    /// `]` (right context only).
    Close,
}

/// A production `label: left < pred > right : condition -> successor : probability`.
#[derive(Debug, Clone, PartialEq)]
pub struct ProductionAst {
    /// Optional label (`p1`).
    pub label: Option<String>,
    /// Section.
    pub section: Section,
    /// Left context (empty if none).
    pub left: Vec<PatternItem>,
    /// The strict predecessor.
    pub predecessor: ModulePattern,
    /// Right context (empty if none).
    pub right: Vec<PatternItem>,
    /// Condition (`None` for `*` or no condition).
    pub condition: Option<Expr>,
    /// Successor (empty = ε).
    pub successor: Vec<ModuleCall>,
    /// Stochastic weight, a constant expression.
    pub probability: Option<Expr>,
}

/// A `#define NAME expr`.
#[derive(Debug, Clone, PartialEq)]
pub struct Define {
    /// The name.
    pub name: String,
    /// Its value, a constant expression over earlier defines.
    pub value: Expr,
}

/// A whole grammar text.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GrammarAst {
    /// Declared multi-character module names (`#module`).
    pub modules: Vec<String>,
    /// Constants, in order.
    pub defines: Vec<Define>,
    /// Symbols ignored by context matching.
    pub ignore: Vec<String>,
    /// Symbols registered as communication modules (besides `?E`).
    pub communication: Vec<String>,
    /// The axiom (empty if none was given).
    pub axiom: Vec<ModuleCall>,
    /// Productions of all sections, in order.
    pub productions: Vec<ProductionAst>,
}
