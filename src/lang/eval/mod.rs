//! The interpreter for rule bodies, control blocks and initialisers.
//!
//! It knows nothing about words: successors go to an [`Emit`] sink and
//! context tests are answered by a [`Host`], which the rewriting engine (or
//! a later mesh engine) provides.
//!
//! This file holds the interpreter, [`Interp`] (its state, its limits and
//! its entry points), what it talks to ([`Emit`], [`Host`]), how a
//! statement ends ([`Flow`]) and [`RuntimeError`]. The rest is `Interp`'s
//! methods and their helpers, one part a file:
//!
//! - [`env`](mod@env): [`Env`], the global state shared by all bodies of one
//!   derivation
//! - [`statements`]: statements: loops, blocks, `produce`, `switch`,
//!   `forall` and set edits
//! - [`expressions`]: expressions, folds over a set's members, fields and
//!   array elements
//! - [`places`]: the variables, fields and elements read and written in
//!   place
//! - [`user_calls`]: calls of user-defined functions, their frames and
//!   stack segments
//! - [`builtin_calls`]: calls of built-in functions: the library's, the
//!   topology's, the run's
//! - [`operators`]: the binary operators ([`binary`])
//!
//! It uses `deadline`, `syntax` and the rest of `lang`; nothing above.

mod builtin_calls;
mod env;
mod expressions;
mod operators;
mod places;
mod statements;
mod user_calls;

pub use env::{Env, MAX_VIEWS};
pub use operators::binary;

use crate::deadline::Deadline;
use crate::syntax::ast::ContextKind;
use crate::syntax::span::Span;

use super::ir::*;
use super::modules::Sym;
use super::value::{StructDef, Value};

/// An error raised while running a body: what and, when known, where.
#[derive(Clone, Debug, PartialEq)]
pub struct RuntimeError {
    pub span: Option<Span>,
    pub message: String,
}

impl RuntimeError {
    pub fn new(span: Option<Span>, message: impl Into<String>) -> RuntimeError {
        RuntimeError {
            span,
            message: message.into(),
        }
    }
}

impl std::fmt::Display for RuntimeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for RuntimeError {}

/// Inside the interpreter an error is boxed: a result stays the size of a
/// value, which every expression node returns.
type R<T> = Result<T, Box<RuntimeError>>;

fn rt(span: Option<Span>, m: impl Into<String>) -> Box<RuntimeError> {
    Box::new(RuntimeError::new(span, m))
}

/// Receives successor modules.
pub trait Emit {
    fn emit(&mut self, sym: Sym, args: &[Value]);

    /// A module whose parameters are given as a word stores them
    /// (`value::encode`): what compiled bodies ([`super::closure`]) emit.
    /// By default, each slot as a `float` (which encodes as itself).
    fn emit_slots(&mut self, sym: Sym, slots: &[f64]) {
        let args: Vec<Value> = slots.iter().map(|&x| Value::Float(x)).collect();
        self.emit(sym, &args);
    }

    /// Modules one after another whose parameters are given as one run of
    /// slots: module `k` has symbol `syms[k]` and the next `widths[k]`
    /// slots. The same as [`Emit::emit_slots`] on each in turn (the
    /// default), at once.
    fn emit_run(&mut self, syms: &[Sym], widths: &[usize], slots: &[f64]) {
        let mut at = 0;
        for (&sym, &w) in syms.iter().zip(widths) {
            self.emit_slots(sym, &slots[at..at + w]);
            at += w;
        }
    }

    /// True when the sink holds more than it may: the interpreter stops
    /// the body after the `produce` that filled it.
    fn full(&self) -> bool {
        false
    }
}

/// The topology a body runs on, as the body sees it: it answers context
/// tests, evaluates the topology's built-ins ([`Func::Host`]) and lists the
/// members of its sets.
pub trait Host {
    /// A context test made inside a body (`InLeftContext(...)` ...). On
    /// success it appends the matched modules' parameters to `out`, in
    /// order.
    fn in_context(&mut self, kind: ContextKind, pats: &[Pattern], out: &mut Vec<Value>) -> bool {
        let _ = (kind, pats, out);
        false
    }

    /// Built-in number `id` of the topology's table, on checked
    /// arguments; an error says why the arguments have no value (`bnext`
    /// of a vertex off the boundary).
    fn call(&mut self, id: u16, args: &[Value]) -> Result<Value, String> {
        let _ = (id, args);
        Ok(Value::Void)
    }

    /// Appends the members of `set` to `out`.
    fn members(&mut self, set: &Value, out: &mut Vec<Value>) {
        let _ = (set, out);
    }
}

/// A host for bodies that have no context (control blocks, initialisers).
pub struct NoHost;

impl Host for NoHost {}

/// A sink for expressions, which produce nothing.
struct NoSink;

impl Emit for NoSink {
    fn emit(&mut self, _: Sym, _: &[Value]) {}
}

impl Emit for Vec<(Sym, Vec<Value>)> {
    fn emit(&mut self, sym: Sym, args: &[Value]) {
        self.push((sym, args.to_vec()));
    }
}

/// How a statement ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    Normal,
    /// A `produce` ran: the successor is complete.
    Produced,
    /// `return` (or the end of the body): the rule does not apply.
    Return,
    Break,
    Continue,
}

/// Loop iterations one body may run before it is stopped.
pub const LOOP_LIMIT: u64 = 10_000_000;

/// Loop iterations and function calls, over all bodies, between two looks
/// at the deadline.
const DEADLINE_EVERY: u32 = 1 << 16;

/// Calls of user-defined functions may nest this deep (a recursion); a
/// deeper call is an error at the call.
pub const MAX_CALL_DEPTH: u32 = 10_000;

/// The frames of the user function calls in progress may hold this many
/// values in all (their arguments, arrays passed included, and their
/// local arrays): a recursion that copies a large array at every level
/// stops with a message before it runs out of memory.
pub const MAX_FRAME_VALUES: usize = 1 << 22;

/// The interpreter recurses on the Rust stack. Once a chain of user
/// function calls has used this much of the caller's stack (whose size is
/// not known: a test thread has 2 MiB), the next call runs on a new thread
/// with a stack of [`SEGMENT_STACK`] bytes (reserved, and used as it is
/// needed), which it may use up to [`SEGMENT_MARGIN`] from its end before
/// it moves on to another. [`MAX_CALL_DEPTH`] calls fit in one or two.
const STACK_SEGMENT: usize = 256 << 10;
const SEGMENT_STACK: usize = 512 << 20;
const SEGMENT_MARGIN: usize = 4 << 20;

/// Runs bodies. Holds scratch space reused across calls.
pub struct Interp<'p> {
    pub structs: &'p [StructDef],
    /// The program's user-defined functions.
    funcs: &'p [Function],
    /// User function calls in progress.
    calls: u32,
    /// The values their frames hold (see [`MAX_FRAME_VALUES`]).
    frame_values: usize,
    /// The value of the `return` that ended the running function.
    ret: Option<Value>,
    /// The stack address where the current stack segment started (0: not
    /// yet known), and how much of it calls may use.
    stack_base: usize,
    stack_room: usize,
    scratch: Vec<Value>,
    fuel: u64,
    /// The loop iterations one body may run ([`LOOP_LIMIT`] unless the
    /// topology sets more: a vv step walks the whole mesh).
    pub loop_limit: u64,
    /// The run stops once this passes; looked at every
    /// [`DEADLINE_EVERY`] loop iterations.
    pub deadline: Option<Deadline>,
    /// Loop iterations since the interpreter was made, wrapping.
    ticks: u32,
    /// Lists of members for `forall` loops, reused.
    member_lists: Vec<Vec<Value>>,
    /// Frames of user function calls, reused.
    frames: Vec<Vec<Value>>,
}

impl<'p> Interp<'p> {
    pub fn new(structs: &'p [StructDef]) -> Interp<'p> {
        Interp {
            structs,
            funcs: &[],
            calls: 0,
            frame_values: 0,
            ret: None,
            stack_base: 0,
            stack_room: STACK_SEGMENT,
            scratch: Vec::new(),
            fuel: LOOP_LIMIT,
            loop_limit: LOOP_LIMIT,
            deadline: None,
            ticks: 0,
            member_lists: Vec::new(),
            frames: Vec::new(),
        }
    }

    /// An interpreter of `program`'s bodies (its structs and its
    /// functions) that stops once `deadline` passes.
    pub fn for_program(program: &'p Program, deadline: Option<Deadline>) -> Interp<'p> {
        Interp {
            funcs: &program.functions,
            ..Interp::with_deadline(&program.structs, deadline)
        }
    }

    /// An interpreter that stops once `deadline` passes.
    pub fn with_deadline(structs: &'p [StructDef], deadline: Option<Deadline>) -> Interp<'p> {
        Interp {
            deadline,
            ..Interp::new(structs)
        }
    }

    /// Runs a body. Returns `Flow::Produced` if a `produce` ended it.
    pub fn run(
        &mut self,
        body: &[St],
        frame: &mut [Value],
        env: &mut Env,
        host: &mut (dyn Host + Send),
        sink: &mut dyn Emit,
    ) -> Result<Flow, RuntimeError> {
        self.fuel = self.loop_limit;
        self.stack_base = 0;
        let mut cx = Cx {
            frame,
            env,
            host,
            sink,
        };
        for s in body {
            match self.stmt(s, &mut cx).map_err(|e| *e)? {
                Flow::Normal => {}
                f => return Ok(f),
            }
        }
        Ok(Flow::Return)
    }

    /// Evaluates an expression over `frame`'s locals against `host`: a
    /// guard or an assignment of a rule on another topology.
    pub fn eval(
        &mut self,
        e: &Ex,
        frame: &mut [Value],
        env: &mut Env,
        host: &mut (dyn Host + Send),
    ) -> Result<Value, RuntimeError> {
        let mut sink = NoSink;
        self.stack_base = 0;
        let mut cx = Cx {
            frame,
            env,
            host,
            sink: &mut sink,
        };
        self.expr(e, &mut cx).map_err(|e| *e)
    }

    /// Evaluates an expression with no locals (initialisers, directives).
    pub fn eval_global(&mut self, e: &Ex, env: &mut Env) -> Result<Value, RuntimeError> {
        self.stack_base = 0;
        let mut frame: Vec<Value> = Vec::new();
        let mut sink: Vec<(Sym, Vec<Value>)> = Vec::new();
        let mut cx = Cx {
            frame: &mut frame,
            env,
            host: &mut NoHost,
            sink: &mut sink,
        };
        self.expr(e, &mut cx).map_err(|e| *e)
    }

    /// Evaluates successor modules with no locals (the axiom).
    pub fn eval_modules(
        &mut self,
        succ: &[Succ],
        env: &mut Env,
        sink: &mut dyn Emit,
    ) -> Result<(), RuntimeError> {
        let mut frame: Vec<Value> = Vec::new();
        self.stack_base = 0;
        let mut cx = Cx {
            frame: &mut frame,
            env,
            host: &mut NoHost,
            sink,
        };
        self.produce(succ, &mut cx).map_err(|e| *e)
    }
}

struct Cx<'a> {
    frame: &'a mut [Value],
    env: &'a mut Env,
    host: &'a mut (dyn Host + Send),
    sink: &'a mut dyn Emit,
}
