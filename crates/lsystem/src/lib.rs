//! # polis-lsystem
//!
//! A parametric, context-sensitive, stochastic, open L-system engine with a text grammar
//! and a 3-D turtle (Prusinkiewicz & Lindenmayer, *The Algorithmic Beauty of Plants*,
//! 1990, ch. 1; Parish & Müller 2001 §3.1).

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
