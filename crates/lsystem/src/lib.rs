//! polis-lsystem: a parametric L-system engine (modules, productions, context, stochastic choice, query and communication modules, text grammar, 3-D turtle).
//!
//! **Status: not yet implemented.** This crate is a placeholder in the workspace; the
//! issue tracker names what it will own. Nothing here pretends to work yet.
