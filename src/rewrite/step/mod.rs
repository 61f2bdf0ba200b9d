//! One parallel rewriting step over a word: `step(rules, &src, &mut dst)`.
//!
//! Every module of `src` is rewritten from `src` (contexts included); the
//! first rule, in file order, that matches and produces wins; a module no
//! rule rewrites is copied. Strict predecessors of several modules
//! (pseudo-L-systems) partition the word without overlap, starting at the
//! phase. `src` is never mutated.
//!
//! The folder, one concept a file:
//! - [`general`]: [`Rewriter::step`], which picks the path a step takes,
//!   and the general loop, which scans the modules one at a time in the
//!   word's order (forward, backward, on a ring from a phase, past cut
//!   branches);
//! - [`try_rule`]: one rule tried at one module: its predecessor and
//!   contexts matched in the old and the new word, its body run (stencil,
//!   compiled or interpreted) and its successor appended;
//! - [`stencil`]: stencils evaluated into a word, and the fast path of a
//!   step whose rules are all stencils;
//! - [`uniform`]: the fast path of a ring of one kind of module, one
//!   stencil everywhere, with its kernels compiled for each shape;
//! - [`parallel`]: steps in parts on rayon's pool;
//! - [`lean`]: the loop over a range of modules with the rules by symbol,
//!   which the lean path runs over the whole word and a parallel step on
//!   each part.
//!
//! Here: the options and errors of a step, and the [`Rewriter`] with its
//! buffers.
//!
//! It uses `lang` and the other parts of `rewrite` (`context`, `word`,
//! `growth`); nothing above.

use crate::deadline::Deadline;
use crate::lang::closure;
use crate::lang::eval::{Interp, RuntimeError};
use crate::lang::ir::Program;
use crate::lang::{Sym, Value};

use super::context::Tables;
use super::word::Word;

mod general;
mod lean;
mod parallel;
mod stencil;
mod try_rule;
mod uniform;

#[cfg(test)]
mod tests;

use lean::Dispatch;

/// How one step runs.
#[derive(Clone, Copy, Debug)]
pub struct StepOptions {
    pub ring: bool,
    /// Left to right (`Forward()`, the default) or right to left.
    pub forward: bool,
    /// Where the partition into strict predecessors starts (pseudo-L-systems).
    pub phase: usize,
    /// The step fails once the new word holds more modules than this.
    pub max_modules: usize,
    /// The step fails once this passes.
    pub deadline: Option<Deadline>,
    /// Remove every `Cut` and the rest of its branch, as lpfg's forward
    /// production steps do (manual 5.4): a `Cut` and the modules after it
    /// up to the `EB` that closes its branch (kept), or to the end of the
    /// word, are neither rewritten nor copied. Contexts still see the
    /// whole old word. Decomposition, interpretation and backward steps
    /// leave `Cut` in place.
    pub cut: bool,
}

/// Why a step failed.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// A rule's body failed; `rule` indexes `Program::rules`.
    Runtime { rule: usize, error: RuntimeError },
    /// The new word outgrew `max_modules`; `rule` is the rule that
    /// produced last, if one did.
    TooLong { limit: usize, rule: Option<usize> },
    /// The deadline passed: what it says.
    Timeout(String),
}

impl std::fmt::Display for StepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepError::Runtime { error, .. } => f.write_str(&error.message),
            StepError::TooLong { limit, .. } => write!(f, "the word grew past {limit} modules"),
            StepError::Timeout(m) => f.write_str(m),
        }
    }
}

/// In an origin, a module copied from the old word (the low bits give its
/// index there), rather than produced by a rule.
pub const COPIED: u32 = 1 << 31;

/// Source modules between two looks at the deadline on the general path.
const DEADLINE_EVERY: usize = 4096;

impl std::error::Error for StepError {}

/// Rewrites words with a program's rules. Holds buffers reused across steps.
pub struct Rewriter<'p> {
    program: &'p Program,
    interp: Interp<'p>,
    /// Per rule, its body compiled to closures, where it can be.
    bodies: Vec<Option<closure::Body>>,
    machine: closure::Machine,
    sb: Sym,
    eb: Sym,
    cut: Sym,
    frame: Vec<Value>,
    /// The last step's growth (new length / old length), to size buffers.
    growth: f64,
    /// The fast path found every new slot finite while computing it.
    checked_finite: bool,
    matched: Vec<usize>,
    new_matched: Vec<usize>,
    tmp: Word,
    /// The context tables of the word a step rewrites.
    tables: Tables,
    /// The new words of a parallel step's parts after the first, kept
    /// from step to step so that their memory is reused.
    parts: Vec<Word>,
    /// For each module of the old word, the rule (its place in the step's
    /// list) that rewrites it in a step of stencils in parts, or
    /// `KEEP`.
    choice: Vec<u16>,
    /// The rules of the last step run in parts or on the lean path, by
    /// the symbol of their strict predecessor.
    dispatch: Dispatch,
    /// Where a step written in parts says which of its new word's parts
    /// are written, for a reader on another thread (the turtle walking
    /// the last step's word): set for one step by
    /// [`super::Derivation::next_step_read`].
    pub(crate) reader: Option<std::sync::Arc<super::growth::Growth>>,
}

/// `Rewriter::choice` of a module that no rule rewrites.
const KEEP: u16 = u16::MAX;

impl<'p> Rewriter<'p> {
    pub fn new(program: &'p Program) -> Rewriter<'p> {
        Rewriter {
            program,
            interp: Interp::for_program(program, None),
            bodies: program
                .rules
                .iter()
                .map(|r| closure::compile(r, &program.globals))
                .collect(),
            machine: closure::Machine::default(),
            sb: program.alphabet.builtin("SB"),
            eb: program.alphabet.builtin("EB"),
            cut: program.alphabet.builtin("Cut"),
            frame: Vec::new(),
            growth: 1.0,
            checked_finite: false,
            matched: Vec::new(),
            new_matched: Vec::new(),
            tmp: Word::new(),
            tables: Tables::default(),
            parts: Vec::new(),
            choice: Vec::new(),
            dispatch: Dispatch::default(),
            reader: None,
        }
    }

    /// Frees the words kept from step to step.
    pub fn release(&mut self) {
        self.parts = Vec::new();
        self.choice = Vec::new();
        self.tmp = Word::new();
        self.tables.clear();
    }
}

/// A uniform step's inner range runs on rayon's pool from this many modules
/// on; below it, one thread (the pool's start-up would cost more than it
/// saves).
pub(crate) const PARALLEL_MODULES: usize = 1 << 16;
