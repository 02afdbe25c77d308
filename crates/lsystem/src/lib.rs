//! # polis-lsystem
//!
//! A parametric, context-sensitive, stochastic, open L-system engine with a text grammar in
//! the notation of the literature and a 3-D turtle. It drives the road network (Parish &
//! Müller's extended L-system, whose `?I` modules talk to the environment) and the building
//! grammar of [polis](https://example.invalid/polis), and stands alone for plant modelling:
//! it depends on nothing of polis.
//!
//! ## Key types
//!
//! | type | what |
//! |---|---|
//! | [`Derivation`] | the engine: parallel rewriting, cut, decomposition, query/communication pass, guards, step by step |
//! | [`Rules`] | what the engine needs from a rule set; implemented by both front ends |
//! | [`TypedRules`], [`Module`], [`Production`] | typed front end: your module type, productions as closures |
//! | [`Grammar`] | text front end: parse, compile, pretty-print ([`grammar`] documents the language in EBNF) |
//! | [`ParamString`] | numeric-parameter module string (symbol ids + flat `f64` arena) |
//! | [`Environment`] | the environment of an open L-system |
//! | [`Turtle`], [`TurtleOptions`], [`TurtleSink`], [`Geometry`] | the 3-D turtle and its output |
//! | [`DeriveOptions`] | seed, growth guards, turtle used between steps |
//! | [`LsystemError`] | everything that can fail |
//!
//! ## Example
//!
//! ```
//! use polis_lsystem::{DeriveOptions, Geometry, Grammar, TurtleOptions};
//!
//! // ABOP figure 1.24 (d): a bracketed plant, δ = 20°.
//! let g = Grammar::parse("
//!     ω: X
//!     p1: X -> F[+X]F[-X]+X
//!     p2: F -> FF
//! ")?;
//! let mut d = g.derivation(DeriveOptions {
//!     turtle: TurtleOptions { angle_degrees: 20.0, ..TurtleOptions::default() },
//!     ..DeriveOptions::default()
//! });
//! d.derive(5)?;
//! let mut plant = Geometry::default();
//! d.interpret(&mut plant)?;
//! // Every F draws: #F(n+1) = 2·#F(n) + 2·#X(n), #X(n) = 3ⁿ.
//! assert_eq!(plant.segments.len(), 422);
//! # Ok::<(), polis_lsystem::LsystemError>(())
//! ```
//!
//! ## Semantics (ABOP ch. 1, cpfg, Měch & Prusinkiewicz 1996)
//!
//! * **Parallel rewriting** of every module of the previous string; productions of a
//!   symbol are tried in order and the first whose predecessor (symbol and parameter
//!   count), context and condition match applies; identity when none matches; an empty
//!   successor erases (ε).
//! * **Stochastic** productions choose among the matching ones with one draw from a seeded
//!   `Pcg64Mcg` ([`TypedRules`] documents the rule); same seed, same string, on every platform.
//! * **Context** is bracket-aware ([`context`]): the left context follows the path to the
//!   root, the right context skips whole branches, an ignore set is skipped by both.
//! * **Branches** `[ ]`; **cut** `%` removes itself and the rest of its branch in the next step.
//! * **Query modules** `?P ?H ?U ?L` receive the turtle position/heading/up/left (as many
//!   components as they have parameters) after every step; **communication modules**
//!   (`?E` and registered symbols) are handed to the [`Environment`] in string order with
//!   the turtle state at their position (open L-systems).
//! * **Decomposition** rules expand new modules recursively right after a step;
//!   **interpretation** (homomorphism) rules expand modules into turtle commands when
//!   drawing, without growing the string.
//! * **Guards**: [`DeriveOptions::max_len`], [`DeriveOptions::max_steps`] and
//!   [`DeriveOptions::max_depth`] return typed errors instead of running out of memory;
//!   a failed step leaves the string as it was.
//!
//! ## Guarantees
//!
//! * Deterministic: the string after `n` steps depends only on the rules, the axiom, the
//!   seed and the environment's answers.
//! * No panics on user input: arbitrary grammar text, NaN parameters, unbalanced brackets
//!   (they never match a context; `]` on an empty turtle stack is ignored and counted).
//! * No per-module heap allocation while deriving: strings are double-buffered and
//!   [`ParamString`] keeps parameters in one arena; text expressions run precompiled
//!   bytecode (plain parameters, constants and `x op c` forms skip the interpreter).
//!
//! ## Limitations
//!
//! * Text-grammar module names are one character (`?X`/`@X`: two) unless declared with
//!   `#module`.
//! * Decomposition and interpretation rules are context-free; modules produced by
//!   interpretation rules are drawn only (they receive no query values).
//! * Stochastic weights are constants. The turtle's rotations use glam's `libm` sine and
//!   cosine (identical on every platform), but the math functions of text expressions
//!   (`sin`, `exp`, `^` …) use `f64` from `std`, whose last bit may differ across platforms.
//! * One thread per derivation (derive independent strings in parallel).
//!
//! ## References
//!
//! * P. Prusinkiewicz, A. Lindenmayer, *The Algorithmic Beauty of Plants*, 1990, ch. 1.
//! * P. Prusinkiewicz, M. James, R. Měch, *Synthetic Topiary*, SIGGRAPH 94.
//! * R. Měch, P. Prusinkiewicz, *Visual Models of Plants Interacting with Their
//!   Environment*, SIGGRAPH 96.
//! * Y. Parish, P. Müller, *Procedural Modeling of Cities*, SIGGRAPH 2001, §3.1.

pub use glam;
pub use rand;
pub use rand_pcg;

pub mod command;
pub mod context;
pub mod derivation;
pub mod error;
pub mod grammar;
mod random;
pub mod string;
pub mod turtle;
pub mod typed;

pub use command::{Command, ModuleKind, QueryKind};
pub use context::{BranchIndex, ContextItem};
pub use derivation::{Derivation, DeriveOptions, Environment, Rules, StepReport};
pub use error::{LsystemError, Result};
pub use grammar::Grammar;
pub use string::{ModuleString, ParamString};
pub use turtle::{Geometry, Segment, Turtle, TurtleOptions, TurtleSink, TurtleState};
pub use typed::{Match, Module, Production, Successor, TypedRules};
