//! The one production model: a rule is a predecessor with contexts, a
//! guard and a successor, written in one language, checked by one checker
//! (`lang::compile`) and run by one interpreter (`lang::eval`). What
//! changes from one kind of system to the next is the topology the rules
//! walk, and only that.
//!
//! A topology supplies
//!
//! | | what | words (`rewrite`) | stellar mesh (`surface`) |
//! |---|---|---|---|
//! | element values | what a pattern binds | a module's parameters | [`Value::Elem`]: vertex, edge, face, set of vertices |
//! | host built-ins | a [`HostTable`] beside the maths | none (contexts are syntax) | `l`, `valence`, `ring`, `block`, `new`, … |
//! | matching | how a predecessor and its contexts match | `rewrite::context` | element kind, boundary or interior, guard |
//! | successor | what a production does | emits modules ([`Emit`]) | a stellar operator and its assignment |
//! | schedule | what one step is | one parallel step | rules in file order, each on what matched when it started |
//!
//! and answers a body's questions through [`Host`]. The [`Topology`]
//! trait is the schedule's face: a run that steps, and says where it is.
//!
//! [`Value::Elem`]: crate::lang::value::Value::Elem
//! [`Emit`]: crate::lang::eval::Emit
//! [`Host`]: crate::lang::eval::Host

use std::path::Path;

use crate::lang::builtins::{HostTable, WORD_HOST};
use crate::rewrite::{Derivation, DeriveError, Word};
use crate::syntax::lex::Token;
use crate::syntax::source::Front;
use crate::syntax::SourceError;

/// A topology's entry in the loader's table: how a program written for it
/// is told from its tokens, and checked. Each topology that programs are
/// written for (`surface`, `vv`, `shape`) defines its `ENTRY`; the loader
/// lists them and asks each in turn, and a program none claims is a curve
/// L-system. No topology knows the loader.
pub struct Entry {
    /// True when a program's preprocessed tokens are written for this
    /// topology (a surface grammar's `mesh:` directive, a vv program's
    /// `mesh S;`, …).
    pub claims: fn(&[Token]) -> bool,
    /// Parses and checks the program; `dir` is the folder its relative
    /// file names are read from (`None`: the current folder). The checked
    /// program is the topology's own type ([`Checked`]).
    pub check: fn(Front, Option<&Path>) -> Result<Checked, SourceError>,
}

/// A program checked by a topology's [`Entry`], as the topology's own type
/// (`surface::Grammar`, `vv::VvProgram`, `shape::ShapeGrammar`): the
/// loader, which knows every topology, takes it back by that type.
pub type Checked = Box<dyn std::any::Any + Send>;

/// A system running on its topology: its structure, its schedule, and the
/// table of elements and built-ins its rules were checked with.
pub trait Topology {
    /// What the productions rewrite: a word of modules, a mesh.
    type Structure;
    /// Why a step failed.
    type Error;

    /// The element kinds and host built-ins the checker adds to the
    /// language for this topology.
    fn host_table() -> &'static HostTable
    where
        Self: Sized;

    /// The structure as it stands.
    fn structure(&self) -> &Self::Structure;

    /// Steps done so far.
    fn steps_done(&self) -> u64;

    /// True while steps remain: the derivation length is not reached and
    /// nothing (lpfg's `Stop()`) ended the run.
    fn has_next(&self) -> bool;

    /// One step of the schedule: every rule matches on the structure as
    /// the step (or, for file-order schedules, the rule) starts, then what
    /// matched is applied.
    fn step(&mut self) -> Result<(), Self::Error>;
}

/// Runs the steps that remain of any topology, telling `progress` after
/// each.
pub fn run<T: Topology>(system: &mut T, mut progress: impl FnMut(&T)) -> Result<(), T::Error> {
    while system.has_next() {
        system.step()?;
        progress(system);
    }
    Ok(())
}

/// Words of modules: one parallel step of the productions, with lpfg's
/// control blocks, groups and decomposition around it.
impl Topology for Derivation<'_> {
    type Structure = Word;
    type Error = DeriveError;

    fn host_table() -> &'static HostTable {
        &WORD_HOST
    }

    fn structure(&self) -> &Word {
        &self.word
    }

    fn steps_done(&self) -> u64 {
        self.step
    }

    fn has_next(&self) -> bool {
        Derivation::has_next(self)
    }

    fn step(&mut self) -> Result<(), DeriveError> {
        self.next_step()
    }
}
