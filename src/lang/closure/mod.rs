//! Rule bodies compiled to closures: a specialisation of the checked IR
//! for the word rewriter, never a second language.
//!
//! A body whose values are all numbers (`int`, `float`, `double`, `bool`
//! parameters, locals and globals) is turned into a tree of closures over
//! a frame of 64-bit words, each expression's kind (integer, floating,
//! boolean) fixed when it is compiled: no [`Value`](super::value::Value)
//! is made, matched or dropped while it runs, parameters are read straight
//! from the word's slots and successor parameters written straight back as
//! slots.
//!
//! The kinds are the interpreter's: [`super::eval`] decides from the run-time
//! variants of its values, and every variant a body's expression can have
//! is fixed by the variants of the locals it reads, which the compiler
//! tracks per slot (a pattern parameter has its declared type's, an
//! initialisation or assignment the kind of what it stores; a slot that
//! would hold two kinds leaves the body to the interpreter). What runs is
//! what [`super::eval::Interp`] does with the same expression: C's integer
//! arithmetic (wrapping, the same division-by-zero and shift errors with
//! the same spans), single-precision rounding where the IR converts,
//! short-circuit `&&` and `||`, the same loop limit and deadline checks,
//! the same check for NaN and infinity in successors and the same
//! limit on the word, the random number generators drawn in the same
//! order. Anything else (vectors, structs, arrays, strings, user
//! functions, context queries, seeding the generators, I/O, `switch`)
//! makes [`compile`] give `None`, and the interpreter runs that body.
//!
//! - [`kinds`]: the kinds of values at run time and the compiled
//!   expressions of each kind: reads, conversions, binary operators
//! - [`expressions`]: expressions compiled to closures, the kinds of the
//!   locals tracked per slot
//! - [`statements`]: statements compiled to closures: blocks, `if`, loops,
//!   `produce`
//! - `tests`: the same results with and without compiled bodies
//!
//! This file holds what a compiled body runs on ([`Machine`]), the
//! compiled body ([`Body`]), and [`compile`], which compiles a body pass
//! by pass until the kinds of its locals are known.
//!
//! It uses `syntax`, `deadline` and the rest of `lang`; nothing above.

mod expressions;
mod kinds;
mod statements;
#[cfg(test)]
mod tests;

use std::cell::Cell;

use crate::deadline::Deadline;
use crate::syntax::span::Span;

use super::eval::{Emit, Env, Flow, RuntimeError, LOOP_LIMIT};
use super::ir::{Pattern, Rule};
use super::value::Ty;

use kinds::{kind_of, Kind};

type R<T> = Result<T, Box<RuntimeError>>;

fn rt(span: Option<Span>, m: impl Into<String>) -> Box<RuntimeError> {
    Box::new(RuntimeError::new(span, m))
}

thread_local! {
    /// Whether [`compile`] compiles on this thread (tests run every program
    /// with and without compiled bodies).
    static ENABLED: Cell<bool> = const { Cell::new(true) };
}

/// Turns compiled bodies on or off for the rewriters made on this thread
/// from now on (on by default). Results are the same either way.
#[cfg(test)]
pub(crate) fn set_enabled(on: bool) {
    ENABLED.with(|e| e.set(on));
}

/// Loop iterations, over all bodies, between two looks at the deadline
/// (as the interpreter's).
const DEADLINE_EVERY: u32 = 1 << 16;

/// What a compiled body runs on: its frame, the emitted slots, the loop
/// budget. Reused from body to body.
pub struct Machine {
    frame: Vec<u64>,
    slots: Vec<f64>,
    fuel: u64,
    ticks: u32,
    /// As [`super::eval::Interp::loop_limit`].
    pub loop_limit: u64,
    /// As [`super::eval::Interp::deadline`].
    pub deadline: Option<Deadline>,
}

impl Default for Machine {
    fn default() -> Machine {
        Machine {
            frame: Vec::new(),
            slots: Vec::new(),
            fuel: LOOP_LIMIT,
            ticks: 0,
            loop_limit: LOOP_LIMIT,
            deadline: None,
        }
    }
}

struct Cx<'a> {
    m: &'a mut Machine,
    env: &'a mut Env,
    sink: &'a mut dyn Emit,
}

type FE = Box<dyn Fn(&mut Cx) -> R<f64> + Send + Sync>;

type IE = Box<dyn Fn(&mut Cx) -> R<i64> + Send + Sync>;

type BE = Box<dyn Fn(&mut Cx) -> R<bool> + Send + Sync>;

type SE = Box<dyn Fn(&mut Cx) -> R<Flow> + Send + Sync>;

/// A value's 64 bits as the frame holds them.
type UE = Box<dyn Fn(&mut Cx) -> R<u64> + Send + Sync>;

/// A body compiled to closures, with the slots its pattern parameters go to.
pub struct Body {
    /// Per parameter of the patterns (left, strict, right context in
    /// order): the pattern's number, the parameter's, its slot, and
    /// whether it is a `bool`.
    binds: Vec<(usize, usize, usize, bool)>,
    frame_size: usize,
    /// The slots before this one are all bound to parameters: a run
    /// clears the frame from here on only.
    bound: usize,
    /// No statement stores into a parameter's slot: after a run, the
    /// frame still holds the parameters as bound.
    keeps_params: bool,
    /// Neither stores into a global nor draws a random number: what it
    /// produces depends on the matched modules and the globals alone.
    pure: bool,
    body: SE,
}

impl std::fmt::Debug for Body {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("closure::Body")
    }
}

/// Compiles a word rule's body, or `None` when it uses what only the
/// interpreter runs (or when compiled bodies are off on this thread).
pub fn compile(rule: &Rule, globals: &[super::ir::GlobalVar]) -> Option<Body> {
    if !ENABLED.with(|e| e.get()) || !rule.new_left.is_empty() || !rule.new_right.is_empty() {
        return None;
    }
    let pats: Vec<&Pattern> = rule
        .left
        .iter()
        .chain(&rule.strict)
        .chain(&rule.right)
        .collect();
    let mut seeds = vec![None; rule.frame_size];
    let mut binds = Vec::new();
    for (n, p) in pats.iter().enumerate() {
        for (j, (&slot, &ty)) in p.slots.iter().zip(&p.types).enumerate() {
            let k = kind_of(ty)?;
            let s = slot as usize;
            if s >= seeds.len() || seeds[s].is_some_and(|o| o != k) {
                return None;
            }
            seeds[s] = Some(k);
            binds.push((n, j, s, ty == Ty::Bool));
        }
    }
    // The kinds of the locals: what is known grows pass by pass until the
    // compiled body reads no slot of unknown kind.
    let mut kinds = seeds.clone();
    for _ in 0..8 {
        let mut c = Compiler {
            kinds: kinds.clone(),
            writes: seeds.clone(),
            globals,
            unknown: false,
            conflict: false,
            effects: false,
            stored: vec![false; rule.frame_size],
        };
        let body = c.block(&rule.body);
        if c.conflict {
            return None;
        }
        if c.writes == kinds {
            if c.unknown {
                return None;
            }
            let mut is_bound = vec![false; rule.frame_size];
            for &(_, _, slot, _) in &binds {
                is_bound[slot] = true;
            }
            let bound = is_bound.iter().take_while(|&&b| b).count();
            let keeps_params = binds.iter().all(|b| !c.stored[b.2]);
            return Some(Body {
                keeps_params,
                binds,
                frame_size: rule.frame_size,
                bound,
                pure: !c.effects,
                body: body?,
            });
        }
        kinds = c.writes;
    }
    None
}

impl Body {
    /// True when the body changes nothing outside its own frame and what
    /// it produces: no global is stored and no random number drawn. Such
    /// bodies may run on many modules at once, in any order.
    pub fn pure(&self) -> bool {
        self.pure
    }

    /// True when, right after `self` ran on some modules without
    /// producing, `next` may run on the same modules with
    /// [`Body::run_bound`]: both bind the same parameters to the same
    /// slots, and `self` stores into none of them.
    pub fn leaves_params_for(&self, next: &Body) -> bool {
        self.keeps_params && self.binds == next.binds
    }

    /// [`Body::run`] on parameters already in the machine's frame: those
    /// the last body run on it bound, when that body
    /// [left them](Body::leaves_params_for) for this one.
    #[inline]
    pub fn run_bound(
        &self,
        m: &mut Machine,
        env: &mut Env,
        sink: &mut dyn Emit,
    ) -> Result<Flow, RuntimeError> {
        self.clear_locals(m);
        self.go(m, env, sink)
    }

    /// Makes the frame the body's size, the slots past its bound
    /// parameters zero.
    #[inline]
    fn clear_locals(&self, m: &mut Machine) {
        if m.frame.len() < self.frame_size {
            m.frame.resize(self.frame_size, 0);
        }
        if self.bound < self.frame_size {
            m.frame[self.bound..self.frame_size].fill(0);
        }
    }

    /// Runs the body on the parameters of the matched modules (`params(k)`:
    /// the slots of the `k`-th matched module, left context first), as
    /// [`super::eval::Interp::run`] runs it on their decoded values.
    #[inline]
    pub fn run<'s>(
        &self,
        m: &mut Machine,
        params: impl Fn(usize) -> &'s [f64],
        env: &mut Env,
        sink: &mut dyn Emit,
    ) -> Result<Flow, RuntimeError> {
        // Cleared, though a body reads a local only after its declaration
        // stored into it or a pattern bound it: nothing of the last body
        // can show. The bound slots are written below.
        self.clear_locals(m);
        let mut data: &[f64] = &[];
        let mut at = usize::MAX;
        for &(k, j, slot, boolean) in &self.binds {
            if k != at {
                data = params(k);
                at = k;
            }
            // `value::decode` of one slot.
            let x = data.get(j).copied().unwrap_or(0.0);
            m.frame[slot] = if boolean {
                (x != 0.0) as u64
            } else {
                x.to_bits()
            };
        }
        self.go(m, env, sink)
    }

    /// Runs the body on its frame as bound.
    #[inline(always)]
    fn go(
        &self,
        m: &mut Machine,
        env: &mut Env,
        sink: &mut dyn Emit,
    ) -> Result<Flow, RuntimeError> {
        m.fuel = m.loop_limit;
        let mut cx = Cx { m, env, sink };
        match (self.body)(&mut cx) {
            Ok(Flow::Normal) => Ok(Flow::Return),
            Ok(f) => Ok(f),
            Err(e) => Err(*e),
        }
    }
}

struct Compiler<'g> {
    /// The kind each local holds, as far as known.
    kinds: Vec<Option<Kind>>,
    /// The kinds stored into each local by this pass.
    writes: Vec<Option<Kind>>,
    globals: &'g [super::ir::GlobalVar],
    /// A local of unknown kind was read.
    unknown: bool,
    /// A local would hold two kinds.
    conflict: bool,
    /// The body stores into a global or draws a random number.
    effects: bool,
    /// The locals the body stores into.
    stored: Vec<bool>,
}
