//! The text grammar: L-systems written in the notation of ABOP and Parish & Müller.
//!
//! ```text
//! /* ABOP §1.10.1 */
//! #define LIMIT 3
//! ω: B(2)A(4,4)
//! p1: A(x,y) : y <= LIMIT -> A(x*2, x+y)
//! p2: A(x,y) : y > LIMIT  -> B(x)A(x/y, 0)
//! p3: B(x)   : x < 1      -> C
//! p4: B(x)   : x >= 1     -> B(x-1)
//! ```
//!
//! # Syntax (EBNF)
//!
//! One statement per line (`;` also ends a statement). Spaces and tabs are free;
//! `/* … */` counts as a space anywhere; a line starting with `//`, or with `#` followed by
//! something other than a letter, is a comment.
//!
//! ```text
//! grammar     = { [ statement ] ( newline | ";" ) } ;
//! statement   = declare | define | ignore | communic | axiom | section | production ;
//! declare     = "#module" [ ":" ] { name } ;                (* multi-character module names *)
//! define      = "#define" name expr ;                       (* constant, may use earlier defines *)
//! ignore      = "#ignore" [ ":" ] { symbol } ;              (* skipped by context matching *)
//! communic    = ( "#communication" | "#comm" ) [ ":" ] { symbol } ;
//! axiom       = ( "#axiom" [ ":" ] | "ω:" | "axiom:" ) { module } ;
//! section     = ( "#productions" | "#decomposition" | "#interpretation" | "#homomorphism" ) [ ":" ] ;
//! production  = [ label ":" ] [ context "<" ] pattern [ ">" rcontext ]
//!               [ ":" ( expr | "*" ) ] ( "->" | "→" ) successor [ ":" expr ] ;
//! label       = name ;                                      (* two or more characters, e.g. p1 *)
//! context     = { pattern } ;
//! rcontext    = { pattern | "[" | "]" } ;
//! pattern     = symbol [ "(" name { "," name } ")" ] ;
//! successor   = "ε" | { module } ;
//! module      = symbol [ "(" expr { "," expr } ")" ] ;
//! symbol      = declared | letter | "?" letter | "@" letter
//!             | "+" | "-" | "&" | "^" | "\" | "/" | "|" | "$" | "[" | "]"
//!             | "!" | "'" | "%" | "{" | "}" | "." | "~" ;
//! expr        = or [ "?" expr ":" expr ] ;
//! or          = and { "||" and } ;
//! and         = cmp { "&&" cmp } ;
//! cmp         = sum [ ( "<" | "<=" | ">" | ">=" | "==" | "!=" ) sum ] ;
//! sum         = product { ( "+" | "-" ) product } ;
//! product     = unary { ( "*" | "/" | "%" ) unary } ;
//! unary       = ( "-" | "+" | "!" ) unary | power ;
//! power       = atom [ "^" unary ] ;                        (* right-associative *)
//! atom        = number | name | name "(" [ expr { "," expr } ] ")" | "(" expr ")" ;
//! name        = ( letter | "_" ) { letter | digit | "_" } ;
//! ```
//!
//! # Meaning
//!
//! * Module symbols are single characters, two characters for `?X` (query and
//!   communication modules) and `@X`, or names declared with `#module` (e.g.
//!   `#module Leaf Apex`), which are matched first, longest first, so `LeafA` reads as
//!   `Leaf` `A`. A declared name followed by `:` starts a production, not a label. A module matches a pattern when symbol **and number of
//!   parameters** agree (ABOP). Whitespace between modules is optional: `F[+F]F`.
//! * A predecessor binds its parameter names, and so do the context modules; names are
//!   bound left context first, then predecessor, then right context, and must be distinct.
//!   Other names are `#define` constants or `pi`.
//! * The condition is an expression that is true when non-zero (NaN is false); `*` or no
//!   condition means always. The probability after the successor is a constant
//!   expression (any non-negative weight): see [`TypedRules`](crate::TypedRules) for the
//!   stochastic choice, which both front ends share.
//! * Successor arguments are expressions over the bound names. `ε` or nothing is the
//!   empty successor.
//! * Sections: productions rewrite in parallel; decomposition rules are applied
//!   recursively to every new module right after a step; interpretation rules expand
//!   modules into turtle commands when the string is drawn, without changing it.
//!   Decomposition and interpretation rules are context-free.
//! * Functions: `sin cos tan asin acos atan atan2 sqrt exp ln log log10 abs floor ceil
//!   round trunc sign min max pow clamp` (angles in radians), and the random functions
//!   `rand()` (uniform in \[0,1)), `ran(x)` (\[0,x)), `uniform(a,b)`, `nran(m,s)`/`normal(m,s)`
//!   drawing from the derivation's seeded generator in a fixed order. `&&` and `||`
//!   short-circuit. Comparisons give 1 or 0.
//! * Expressions are compiled once into bytecode; arguments that are a plain parameter
//!   or a constant are copied without running code.
//! * Built-in symbols and their turtle commands: see [`BUILTIN_SYMBOLS`]; `?E` and the
//!   symbols of `#communication` are communication modules.
//!
//! # Errors
//!
//! Parse and compile errors are [`LsystemError::Parse`](crate::LsystemError::Parse) with
//! 1-based line and column and the text at that place. No input makes the parser panic
//! (property-tested, and fuzzed by `crates/lsystem/fuzz`); expressions nest at most
//! [`MAX_NESTING`] levels.

pub mod ast;
mod compile;
pub mod expr;
mod parse;
mod print;

pub use ast::{Define, GrammarAst, ModuleCall, ModulePattern, PatternItem, ProductionAst, Section};
pub use compile::{BUILTIN_SYMBOLS, Grammar, GrammarScratch};
pub use expr::{BinaryOp, Expr, Func, UnaryOp};
pub use parse::MAX_NESTING;
pub use print::{write_expr, write_grammar};

/// Parses a grammar text into its syntax tree without compiling it.
pub fn parse_ast(text: &str) -> crate::Result<GrammarAst> {
    parse::parse(text).map(|(ast, _)| ast)
}
