//! Open L-systems: the exchange with an environment before a step.
//!
//! Before every derivation step (none after the last, none once
//! `NoEnvironment()` was called), lpfg interprets the word with the
//! turtle, sends every communication module it meets (`E1(x)`,
//! `E2(x, y)`, `EA20(a)`) with the turtle's frame to the environmental
//! program, and writes the answers into those modules' parameters in
//! place; a module the environment does not answer keeps its values. The
//! derivation knows only the traits here: [`EnvironmentStarter`] starts
//! one environment for one run (a built-in program, or an external
//! process speaking lpfg's protocol; `crate::enviro`), and
//! [`Environment`] answers one step's queries.

use crate::deadline::Deadline;

/// The turtle's frame where it met a communication module: position and
/// the heading, left and up vectors.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Frame {
    pub position: [f64; 3],
    pub heading: [f64; 3],
    pub left: [f64; 3],
    pub up: [f64; 3],
}

/// The module after a communication module in the interpreted word, sent
/// when the `.e` file says `following module: on`: its name and its
/// parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Following {
    pub name: String,
    pub params: Vec<f64>,
}

/// One communication module met by the turtle before a step.
#[derive(Clone, Debug, PartialEq)]
pub struct Query {
    /// Which module: an opaque number that the answer repeats (the
    /// module's index in the word).
    pub id: u64,
    /// Its parameters: one for `E1`, two for `E2`, twenty for `EA20`.
    pub values: Vec<f64>,
    /// The module after it, where there is one and the environment asks.
    pub following: Option<Following>,
    /// The turtle's frame at the module.
    pub frame: Frame,
}

/// An answer: the module's id and its new parameters (one for `E1`, two
/// for `E2`, up to twenty for `EA20`).
#[derive(Clone, Debug, PartialEq)]
pub struct Answer {
    pub id: u64,
    pub values: Vec<f64>,
}

/// One running environment: answers the queries of one step at a time,
/// for one derivation. Dropping it ends it and removes everything it made
/// (processes, files, semaphores), whatever state it is in.
pub trait Environment: Send + std::fmt::Debug {
    /// The answers to one step's queries (sent in the word's order). An
    /// error is a message that names the program and what went wrong.
    fn exchange(&mut self, queries: &[Query]) -> Result<Vec<Answer>, String>;
}

/// What a model's `.e` file sets up: starts a fresh [`Environment`] for
/// each run (so that `serve` and `watch` restart it), and says what the
/// queries carry.
pub trait EnvironmentStarter: Send + Sync + std::fmt::Debug {
    /// Starts the environment; `deadline` bounds the wait for it.
    fn start(&self, deadline: Option<Deadline>) -> Result<Box<dyn Environment>, String>;
    /// Whether each query carries the module after it (`following
    /// module: on`).
    fn following_module(&self) -> bool {
        false
    }
    /// lpfg's `-cleanEA20` for this environment's runs (see
    /// `DeriveOptions::clean_ea20`, which also turns it on).
    fn clean_ea20(&self) -> bool {
        false
    }
}
