//! The interpreter for rule bodies, control blocks and initialisers.
//!
//! It knows nothing about words: successors go to an [`Emit`] sink and
//! context tests are answered by a [`Host`], which the rewriting engine (or
//! a later mesh engine) provides.

use glam::{DVec2, DVec3};

use crate::deadline::Deadline;
use crate::syntax::ast::{BinOp, ContextKind, SetEditOp};
use crate::syntax::span::Span;

use super::ir::*;
use super::modules::Sym;
use super::random::Random;
use super::stdio::ProgramOutput;
use super::value::{StructDef, Ty, Value};

/// Global state shared by all bodies of one derivation.
#[derive(Clone, Debug)]
pub struct Env {
    pub globals: Vec<Value>,
    pub step: i64,
    pub current_group: i64,
    pub next_group: i64,
    /// Direction requested for the next step (`Forward()` / `Backward()`).
    pub forward: bool,
    pub stop: bool,
    /// The run's random number generators (`ran`, `rand`, `drand48`,
    /// Gillespie steps).
    pub random: Random,
    /// The model folder's functions and contours, for `func` and its kin.
    pub model: super::model::ModelRef,
    /// What the program prints and the files it writes.
    pub output: ProgramOutput,
    /// The views `UseView` activated, in the order of their first call,
    /// each once (at most [`MAX_VIEWS`]).
    pub views: Vec<i64>,
    /// False after `NoEnvironment()`: query modules are not answered.
    pub environment: bool,
}

impl Env {
    /// The environment of a run of `program`: every global exists, zero,
    /// before the initialisers run (one may call a function that reads a
    /// global declared after it); then each initialiser, in order.
    pub fn for_program(
        program: &Program,
        interp: &mut Interp,
        output: ProgramOutput,
        seed: Option<u32>,
    ) -> Result<Env, RuntimeError> {
        let zeros = program
            .globals
            .iter()
            .map(|g| Value::zero(g.ty, &program.structs))
            .collect();
        let mut env = Env::new(zeros);
        env.output = output;
        env.random = Random::new(seed);
        env.model = program.model.clone();
        for (k, g) in program.globals.iter().enumerate() {
            if let Some(e) = &g.init {
                env.globals[k] = interp.eval_global(e, &mut env)?.convert(g.ty);
            }
        }
        Ok(env)
    }
}

/// More views than this are not recorded.
pub const MAX_VIEWS: usize = 64;

impl Env {
    /// An environment with `globals` whose model accessors ask `model`.
    pub fn with_model(globals: Vec<Value>, model: super::model::ModelRef) -> Env {
        Env {
            model,
            ..Env::new(globals)
        }
    }

    /// An environment with `globals` and no model ([`super::model::NoModel`]).
    pub fn new(globals: Vec<Value>) -> Env {
        Env {
            globals,
            step: 0,
            current_group: 0,
            next_group: 0,
            forward: true,
            stop: false,
            random: Random::default(),
            model: Default::default(),
            output: ProgramOutput::default(),
            views: Vec::new(),
            environment: true,
        }
    }
}

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

    fn stmt(&mut self, s: &St, cx: &mut Cx) -> R<Flow> {
        match s {
            St::Expr(e) => {
                self.expr(e, cx)?;
                Ok(Flow::Normal)
            }
            St::Init(slot, e) => {
                let v = self.expr(e, cx)?;
                cx.frame[*slot as usize] = v;
                Ok(Flow::Normal)
            }
            St::If(c, t, e) => {
                if self.expr(c, cx)?.truthy() {
                    self.stmt(t, cx)
                } else if let Some(e) = e {
                    self.stmt(e, cx)
                } else {
                    Ok(Flow::Normal)
                }
            }
            St::Loop {
                cond,
                body,
                step,
                test_after,
                span,
            } => {
                let mut first = true;
                loop {
                    if !(first && *test_after) {
                        if let Some(c) = cond {
                            if !self.expr(c, cx)?.truthy() {
                                break;
                            }
                        }
                    }
                    first = false;
                    if self.fuel == 0 {
                        return Err(rt(
                            Some(*span),
                            format!("a loop ran more than {} iterations in one body; is its condition ever false?", self.loop_limit),
                        ));
                    }
                    self.fuel -= 1;
                    self.ticks = self.ticks.wrapping_add(1);
                    if self.ticks.is_multiple_of(DEADLINE_EVERY) {
                        if let Err(m) = crate::deadline::check(self.deadline) {
                            return Err(rt(Some(*span), m));
                        }
                    }
                    match self.stmt(body, cx)? {
                        Flow::Break => break,
                        Flow::Normal | Flow::Continue => {}
                        f => return Ok(f),
                    }
                    if let Some(st) = step {
                        self.expr(st, cx)?;
                    }
                }
                Ok(Flow::Normal)
            }
            St::Block(b) => {
                for s in b {
                    match self.stmt(s, cx)? {
                        Flow::Normal => {}
                        f => return Ok(f),
                    }
                }
                Ok(Flow::Normal)
            }
            St::Produce { modules, last } => {
                self.produce(modules, cx)?;
                Ok(if *last { Flow::Produced } else { Flow::Normal })
            }
            St::Return => Ok(Flow::Return),
            St::ReturnValue(e) => {
                let v = self.expr(e, cx)?;
                self.ret = Some(v);
                Ok(Flow::Return)
            }
            St::Break => Ok(Flow::Break),
            St::Continue => Ok(Flow::Continue),
            St::Switch {
                value,
                cases,
                default,
                body,
            } => self.switch(value, cases, *default, body, cx),
            St::ForAll {
                slot,
                set,
                body,
                span,
            } => self.for_all(*slot, set, body, *span, cx),
            St::SetEdit { place, op, elem } => {
                let e = self.expr(elem, cx)?;
                self.set_edit(place, *op, e, cx)?;
                Ok(Flow::Normal)
            }
        }
    }

    /// `forall x in S`: the members the host lists when the loop starts,
    /// one at a time in local `slot`. Out of `stmt`, so that its frame
    /// stays small.
    #[inline(never)]
    fn for_all(&mut self, slot: u16, set: &Ex, body: &St, span: Span, cx: &mut Cx) -> R<Flow> {
        let s = self.expr(set, cx)?;
        let mut members = self.member_lists.pop().unwrap_or_default();
        members.clear();
        cx.host.members(&s, &mut members);
        let mut flow = Flow::Normal;
        for m in members.drain(..) {
            if self.fuel == 0 {
                return Err(rt(
                    Some(span),
                    format!(
                        "loops ran more than {} iterations in one body",
                        self.loop_limit
                    ),
                ));
            }
            self.fuel -= 1;
            self.ticks = self.ticks.wrapping_add(1);
            if self.ticks.is_multiple_of(DEADLINE_EVERY) {
                if let Err(m) = crate::deadline::check(self.deadline) {
                    return Err(rt(Some(span), m));
                }
            }
            cx.frame[slot as usize] = m;
            match self.stmt(body, cx)? {
                Flow::Break => break,
                Flow::Normal | Flow::Continue => {}
                f => {
                    flow = f;
                    break;
                }
            }
        }
        members.clear();
        self.member_lists.push(members);
        Ok(flow)
    }

    /// `add`, `remove`, `merge` on the set at `place`: in place when the
    /// place is a variable, so that a set held once is never copied.
    #[inline(never)]
    fn set_edit(&mut self, place: &Place, op: SetEditOp, elem: Value, cx: &mut Cx) -> R<()> {
        fn edit(set: &mut Value, op: SetEditOp, elem: &Value) {
            let Value::Set(s) = set else { return };
            let s = std::sync::Arc::make_mut(s);
            match (op, elem) {
                (SetEditOp::Add, Value::Elem(e)) => {
                    s.insert(e.ids[0]);
                }
                (SetEditOp::Remove, Value::Elem(e)) => {
                    s.remove(e.ids[0]);
                }
                (SetEditOp::Merge, Value::Set(t)) => s.merge(t),
                _ => {}
            }
        }
        if place.path.is_empty() {
            let root = if place.global {
                &mut cx.env.globals[place.slot as usize]
            } else {
                &mut cx.frame[place.slot as usize]
            };
            edit(root, op, &elem);
            return Ok(());
        }
        let mut v = self.load(place, cx)?;
        edit(&mut v, op, &elem);
        self.store(place, v, cx)
    }

    /// Runs a `switch`'s body from the label of its value's; a `break`
    /// ends it. Out of `stmt`, so that its frame stays small.
    #[inline(never)]
    fn switch(
        &mut self,
        value: &Ex,
        cases: &[(i64, u32)],
        default: Option<u32>,
        body: &[St],
        cx: &mut Cx,
    ) -> R<Flow> {
        let v = self.expr(value, cx)?.as_i64();
        let start = match cases.binary_search_by_key(&v, |c| c.0) {
            Ok(k) => Some(cases[k].1),
            Err(_) => default,
        };
        if let Some(start) = start {
            for s in &body[start as usize..] {
                match self.stmt(s, cx)? {
                    Flow::Normal => {}
                    Flow::Break => break,
                    f => return Ok(f),
                }
            }
        }
        Ok(Flow::Normal)
    }

    fn produce(&mut self, modules: &[Succ], cx: &mut Cx) -> R<()> {
        for m in modules {
            let base = self.scratch.len();
            for (k, a) in m.args.iter().enumerate() {
                let v = self.expr(a, cx)?;
                if v.is_non_finite() {
                    self.scratch.truncate(base);
                    return Err(rt(
                        Some(m.span),
                        format!(
                            "parameter {} of this successor module is {v}; NaN and infinity are not allowed in a word",
                            k + 1
                        ),
                    ));
                }
                self.scratch.push(v);
            }
            cx.sink.emit(m.sym, &self.scratch[base..]);
            self.scratch.truncate(base);
        }
        if cx.sink.full() {
            return Err(rt(
                modules.first().map(|m| m.span),
                "this successor takes the word past its limit",
            ));
        }
        Ok(())
    }

    /// The array indices of a place's path, evaluated in order.
    #[inline(never)]
    fn indices(&mut self, place: &Place, cx: &mut Cx) -> R<Vec<i64>> {
        let mut out = Vec::new();
        for step in &place.path {
            if let Step::Index(e, _) = step {
                out.push(self.expr(e, cx)?.as_i64());
            }
        }
        Ok(out)
    }

    #[inline(never)]
    fn load(&mut self, place: &Place, cx: &mut Cx) -> R<Value> {
        let idx = if place.path.is_empty() {
            Vec::new()
        } else {
            self.indices(place, cx)?
        };
        load_at(place, &idx, cx)
    }

    #[inline(never)]
    fn store(&mut self, place: &Place, value: Value, cx: &mut Cx) -> R<()> {
        if place.path.iter().all(|s| matches!(s, Step::Field(_))) {
            let root = if place.global {
                &mut cx.env.globals[place.slot as usize]
            } else {
                &mut cx.frame[place.slot as usize]
            };
            set_path(root, &place.path, value);
            return Ok(());
        }
        let idx = self.indices(place, cx)?;
        store_at(place, &idx, value, cx)
    }

    /// Reads a place and writes `f` of its value back, the indices
    /// evaluated once (C's `a[i++] += x` and `a[i++]++` step `i` once).
    /// Returns the old and the new value.
    #[inline(never)]
    fn update(
        &mut self,
        place: &Place,
        cx: &mut Cx,
        f: impl FnOnce(Value) -> R<Value>,
    ) -> R<(Value, Value)> {
        if place.path.is_empty() {
            // A plain variable (`s += x`, `i++`): read and written in place.
            let slot = if place.global {
                &mut cx.env.globals[place.slot as usize]
            } else {
                &mut cx.frame[place.slot as usize]
            };
            let new = f(slot.clone())?;
            let cur = std::mem::replace(slot, new.clone());
            return Ok((cur, new));
        }
        let idx = self.indices(place, cx)?;
        let cur = load_at(place, &idx, cx)?;
        let new = f(cur.clone())?;
        store_at(place, &idx, new.clone(), cx)?;
        Ok((cur, new))
    }

    /// A call of a user-defined function: the arguments go into a new
    /// frame, the body runs, parameters passed by reference are written
    /// back.
    #[inline(never)]
    fn call_user(
        &mut self,
        id: u16,
        args: &[Ex],
        back: &[(u16, Place)],
        span: Span,
        cx: &mut Cx,
    ) -> R<Value> {
        let funcs = self.funcs;
        let f = &funcs[id as usize];
        // Frames are reused: a call allocates only when it goes deeper
        // than any before it.
        let mut frame = self.frames.pop().unwrap_or_default();
        frame.clear();
        frame.resize(f.frame_size.max(args.len()), Value::Void);
        let r = self.call_in(f, args, back, span, cx, &mut frame);
        frame.clear();
        self.frames.push(frame);
        r
    }

    /// [`Interp::call_user`] on the frame it got.
    fn call_in(
        &mut self,
        f: &'p Function,
        args: &[Ex],
        back: &[(u16, Place)],
        span: Span,
        cx: &mut Cx,
        frame: &mut [Value],
    ) -> R<Value> {
        for (slot, a) in frame.iter_mut().zip(args) {
            *slot = self.expr(a, cx)?;
        }
        if self.calls >= MAX_CALL_DEPTH {
            return Err(rt(
                Some(span),
                format!(
                    "calls of functions nest more than {MAX_CALL_DEPTH} deep here (a recursion that does not end?), calling `{}`",
                    f.name
                ),
            ));
        }
        // A recursion without loops looks at the deadline too.
        self.ticks = self.ticks.wrapping_add(1);
        if self.ticks.is_multiple_of(DEADLINE_EVERY) {
            if let Err(m) = crate::deadline::check(self.deadline) {
                return Err(rt(Some(span), m));
            }
        }
        let values = frame[..args.len()]
            .iter()
            .fold(f.frame_values, |n, v| n.saturating_add(value_count(v)));
        if self.frame_values.saturating_add(values) > MAX_FRAME_VALUES {
            return Err(rt(
                Some(span),
                format!(
                    "the calls of functions in progress would hold more than {MAX_FRAME_VALUES} \
                     values (arguments and local arrays; an array passed is copied), calling `{}`",
                    f.name
                ),
            ));
        }
        self.calls += 1;
        self.frame_values += values;
        let r = self.invoke(f, frame, cx.env, &mut *cx.host, span);
        self.frame_values -= values;
        self.calls -= 1;
        let v = r?;
        for (k, place) in back {
            let value = std::mem::replace(&mut frame[*k as usize], Value::Void);
            // What the function wrote into a declared `char` array of the
            // caller's (through a `char *` parameter) must fit there.
            if let Some(m) = place
                .chars
                .as_ref()
                .and_then(|c| c.overflow(&format!("`{}`", f.name), &value))
            {
                return Err(rt(Some(span), m));
            }
            self.store(place, value, cx)?;
        }
        Ok(v)
    }

    /// Runs function `f`'s body on `frame`, on a new stack segment when
    /// this one is used up.
    #[inline(never)]
    fn invoke(
        &mut self,
        f: &'p Function,
        frame: &mut [Value],
        env: &mut Env,
        host: &mut (dyn Host + Send),
        span: Span,
    ) -> R<Value> {
        let here = stack_address();
        if self.stack_base == 0 {
            self.stack_base = here;
        }
        if self.stack_base.abs_diff(here) > self.stack_room {
            let saved = (self.stack_base, self.stack_room);
            let spawned = std::thread::scope(|s| {
                std::thread::Builder::new()
                    .name("subgram-calls".into())
                    .stack_size(SEGMENT_STACK)
                    .spawn_scoped(s, || {
                        self.stack_base = 0;
                        self.stack_room = SEGMENT_STACK - SEGMENT_MARGIN;
                        self.run_function(f, frame, env, host)
                    })
                    .map(|h| h.join())
            });
            (self.stack_base, self.stack_room) = saved;
            return match spawned {
                Ok(Ok(r)) => r,
                Ok(Err(panic)) => std::panic::resume_unwind(panic),
                Err(e) => Err(rt(
                    Some(span),
                    format!("no stack for deeper function calls: {e}"),
                )),
            };
        }
        self.run_function(f, frame, env, host)
    }

    #[inline(never)]
    fn run_function(
        &mut self,
        f: &'p Function,
        frame: &mut [Value],
        env: &mut Env,
        host: &mut (dyn Host + Send),
    ) -> R<Value> {
        let mut sink = NoSink;
        let mut cx = Cx {
            frame,
            env,
            host,
            sink: &mut sink,
        };
        self.ret = None;
        for s in &f.body {
            match self.stmt(s, &mut cx)? {
                Flow::Normal => {}
                _ => break,
            }
        }
        if let Some(this) = &f.this_back {
            cx.frame[0] = self.expr(this, &mut cx)?;
        }
        if let Some(r) = &f.result {
            return self.expr(r, &mut cx);
        }
        match self.ret.take() {
            Some(v) => Ok(v),
            None if f.ret == Ty::Void => Ok(Value::Void),
            None => Err(rt(
                Some(f.end),
                format!(
                    "`{}` reached its end without a `return`; it must return a value",
                    f.name
                ),
            )),
        }
    }

    fn expr(&mut self, e: &Ex, cx: &mut Cx) -> R<Value> {
        Ok(match e {
            Ex::Const(v) => v.clone(),
            Ex::Local(s) => cx.frame[*s as usize].clone(),
            Ex::Global(s) => cx.env.globals[*s as usize].clone(),
            Ex::Field(b, i) => field(&self.expr(b, cx)?, *i),
            Ex::Neg(a) => match self.expr(a, cx)? {
                Value::Int(i) => Value::Int(i.wrapping_neg()),
                Value::Float(f) => Value::Float(-f),
                Value::Bool(b) => Value::Int(-(b as i64)),
                Value::V2(v) => Value::V2(-v),
                Value::V3(v) => Value::V3(-v),
                other => other,
            },
            Ex::Not(a) => Value::Bool(!self.expr(a, cx)?.truthy()),
            Ex::Bin(op, a, b, span) => {
                let x = self.expr(a, cx)?;
                let y = self.expr(b, cx)?;
                match float_binary(*op, &x, &y) {
                    Some(v) => v,
                    None => binary(*op, x, y).map_err(|m| rt(Some(*span), m))?,
                }
            }
            Ex::Logic(and, a, b) => {
                let x = self.expr(a, cx)?.truthy();
                if *and {
                    Value::Bool(x && self.expr(b, cx)?.truthy())
                } else {
                    Value::Bool(x || self.expr(b, cx)?.truthy())
                }
            }
            Ex::Cond(c, a, b) => {
                if self.expr(c, cx)?.truthy() {
                    self.expr(a, cx)?
                } else {
                    self.expr(b, cx)?
                }
            }
            Ex::Convert(t, a) => self.expr(a, cx)?.convert(*t),
            Ex::Call(f, args, span) => self.call(*f, args, *span, cx)?,
            Ex::Let(slot, a, body) => {
                let v = self.expr(a, cx)?;
                cx.frame[*slot as usize] = v;
                self.expr(body, cx)?
            }
            _ => self.expr_rare(e, cx)?,
        })
    }

    /// The expressions that bodies use less often, kept out of `expr`
    /// so that its frame stays small.
    #[inline(never)]
    fn expr_rare(&mut self, e: &Ex, cx: &mut Cx) -> R<Value> {
        Ok(match e {
            Ex::Assign(place, op, rhs, ty) => {
                let r = self.expr(rhs, cx)?;
                match op {
                    None => {
                        let v = r.convert(*ty);
                        self.store(place, v.clone(), cx)?;
                        v
                    }
                    Some(op) => {
                        let update =
                            |cur| Ok(binary(*op, cur, r).map_err(|m| rt(None, m))?.convert(*ty));
                        self.update(place, cx, update)?.1
                    }
                }
            }
            Ex::Load(..) | Ex::Index(..) | Ex::CallUser { .. } => self.expr_c(e, cx)?,
            Ex::IncDec(place, d, prefix) if place.path.is_empty() && place.ty == Ty::Int => {
                // `i++` on a plain int, the loop counter: in place.
                let slot = if place.global {
                    &mut cx.env.globals[place.slot as usize]
                } else {
                    &mut cx.frame[place.slot as usize]
                };
                let cur = slot.as_i64();
                let new = cur.wrapping_add(*d as i64);
                *slot = Value::Int(new);
                Value::Int(if *prefix { new } else { cur })
            }
            Ex::IncDec(place, d, prefix) => {
                let step = |cur| {
                    Ok(binary(BinOp::Add, cur, Value::Int(*d as i64))
                        .map_err(|m| rt(None, m))?
                        .convert(place.ty))
                };
                let (cur, new) = self.update(place, cx, step)?;
                if *prefix {
                    new
                } else {
                    cur
                }
            }
            Ex::MakeV2(x, y) => Value::V2(DVec2::new(
                self.expr(x, cx)?.as_f64(),
                self.expr(y, cx)?.as_f64(),
            )),
            Ex::MakeV3(x, y, z) => Value::V3(DVec3::new(
                self.expr(x, cx)?.as_f64(),
                self.expr(y, cx)?.as_f64(),
                self.expr(z, cx)?.as_f64(),
            )),
            Ex::MakeStruct(parts) => {
                let mut vs = Vec::with_capacity(parts.len());
                for p in parts {
                    vs.push(self.expr(p, cx)?);
                }
                Value::Struct(vs.into_boxed_slice())
            }
            Ex::Fold {
                op,
                slot,
                set,
                cond,
                value,
            } => self.fold(*op, *slot, set, cond.as_deref(), value.as_ref(), cx)?,
            Ex::InContext(kind, pats, places) => {
                let mut vals = Vec::new();
                if cx.host.in_context(*kind, pats, &mut vals) {
                    for (place, v) in places.iter().zip(vals) {
                        self.store(place, v.convert(place.ty), cx)?;
                    }
                    Value::Bool(true)
                } else {
                    Value::Bool(false)
                }
            }
            // `expr` handles every other expression.
            _ => Value::Void,
        })
    }

    /// Arrays and user function calls, kept out of `expr_rare` so that
    /// its frame stays small too.
    #[inline(never)]
    fn expr_c(&mut self, e: &Ex, cx: &mut Cx) -> R<Value> {
        Ok(match e {
            Ex::Load(place) => self.load(place, cx)?,
            Ex::Index(base, index, span) => {
                let b = self.expr(base, cx)?;
                let i = self.expr(index, cx)?.as_i64();
                match b {
                    Value::Struct(fs) => match usize::try_from(i).ok().and_then(|k| fs.get(k)) {
                        Some(v) => v.clone(),
                        None => return Err(out_of_range(i, fs.len(), *span)),
                    },
                    Value::Str(s) => char_at(&s, i, *span)?,
                    _ => Value::Void,
                }
            }
            Ex::CallUser {
                id,
                args,
                back,
                span,
            } => self.call_user(*id, args, back, *span, cx)?,
            _ => Value::Void,
        })
    }

    /// A sum, average or count over the members of a set, which go into
    /// local `slot` one at a time. Members are listed on the scratch stack,
    /// so folds nest without allocating.
    #[inline(never)]
    fn fold(
        &mut self,
        op: FoldOp,
        slot: u16,
        set: &Ex,
        cond: Option<&Ex>,
        value: Option<&(Box<Ex>, Ty)>,
        cx: &mut Cx,
    ) -> R<Value> {
        let set = self.expr(set, cx)?;
        let base = self.scratch.len();
        cx.host.members(&set, &mut self.scratch);
        let end = self.scratch.len();
        let mut count = 0i64;
        let mut sum = value.map(|(_, t)| Value::zero(*t, self.structs));
        let mut result = Ok(());
        for k in base..end {
            let m = self.scratch[k].clone();
            cx.frame[slot as usize] = m;
            let keep = match cond {
                None => Ok(true),
                Some(c) => self.expr(c, cx).map(|v| v.truthy()),
            };
            match keep {
                Ok(true) => {}
                Ok(false) => continue,
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
            count += 1;
            if let (Some((v, _)), Some(acc)) = (value, sum.as_mut()) {
                match self
                    .expr(v, cx)
                    .and_then(|x| binary(BinOp::Add, acc.clone(), x).map_err(|m| rt(None, m)))
                {
                    Ok(s) => *acc = s,
                    Err(e) => {
                        result = Err(e);
                        break;
                    }
                }
            }
        }
        self.scratch.truncate(base);
        result?;
        Ok(match (op, sum) {
            (FoldOp::Count, _) | (_, None) => Value::Int(count),
            (FoldOp::Sum, Some(s)) => s,
            (FoldOp::Avg, Some(s)) => {
                binary(BinOp::Div, s, Value::Float(count as f64)).map_err(|m| rt(None, m))?
            }
        })
    }

    #[inline(never)]
    fn call(&mut self, f: Func, args: &[Ex], span: Span, cx: &mut Cx) -> R<Value> {
        // One argument, the common case, stays on the stack.
        if let [a] = args {
            match f {
                Func::Host(id) => {
                    let v = self.expr(a, cx)?;
                    return cx
                        .host
                        .call(id, std::slice::from_ref(&v))
                        .map_err(|m| rt(Some(span), m));
                }
                Func::Math1(g) => return Ok(Value::Float(g(self.expr(a, cx)?.as_f64()))),
                _ => {}
            }
        }
        // A host built-in of two or three arguments (a topology's queries
        // and edits) takes them on the stack too.
        if let (Func::Host(id), 2..=3) = (f, args.len()) {
            let mut vs = [Value::Void, Value::Void, Value::Void];
            for (v, a) in vs.iter_mut().zip(args) {
                *v = self.expr(a, cx)?;
            }
            return cx
                .host
                .call(id, &vs[..args.len()])
                .map_err(|m| rt(Some(span), m));
        }
        // Other arguments go on the scratch stack: no allocation per call.
        let base = self.scratch.len();
        for a in args {
            match self.expr(a, cx) {
                Ok(v) => self.scratch.push(v),
                Err(e) => {
                    self.scratch.truncate(base);
                    return Err(e);
                }
            }
        }
        let v = self.apply(f, base, span, cx);
        self.scratch.truncate(base);
        v.map_err(|m| rt(Some(span), m))
    }

    #[inline(never)]
    fn apply(&mut self, f: Func, base: usize, span: Span, cx: &mut Cx) -> Result<Value, String> {
        let vals = &self.scratch[base..];
        let num = |i: usize| vals[i].as_f64();
        Ok(match f {
            Func::Host(id) => return cx.host.call(id, vals),
            Func::Math1(g) => Value::Float(g(num(0))),
            Func::Math2(g) => Value::Float(g(num(0), num(1))),
            Func::AbsInt => Value::Int(vals[0].as_i64().wrapping_abs()),
            Func::MinInt => Value::Int(vals[0].as_i64().min(vals[1].as_i64())),
            Func::MaxInt => Value::Int(vals[0].as_i64().max(vals[1].as_i64())),
            Func::Length => match &vals[0] {
                Value::V2(v) => Value::Float(v.length()),
                Value::V3(v) => Value::Float(v.length()),
                _ => Value::Float(f64::NAN),
            },
            Func::Normalized => match &vals[0] {
                Value::V2(v) => Value::V2(v.normalize_or_zero()),
                Value::V3(v) => Value::V3(v.normalize_or_zero()),
                other => other.clone(),
            },
            Func::Dot => match (&vals[0], &vals[1]) {
                (Value::V2(a), Value::V2(b)) => Value::Float(a.dot(*b)),
                (Value::V3(a), Value::V3(b)) => Value::Float(a.dot(*b)),
                _ => Value::Float(f64::NAN),
            },
            Func::Cross => match (&vals[0], &vals[1]) {
                (Value::V3(a), Value::V3(b)) => Value::V3(a.cross(*b)),
                _ => Value::Void,
            },
            Func::StepNo => Value::Int(cx.env.step),
            Func::UseGroup => {
                cx.env.next_group = vals[0].as_i64();
                Value::Void
            }
            Func::UseView => {
                let v = vals[0].as_i64();
                if !cx.env.views.contains(&v) && cx.env.views.len() < MAX_VIEWS {
                    cx.env.views.push(v);
                }
                Value::Void
            }
            Func::Environment(on) => {
                cx.env.environment = on;
                Value::Void
            }
            Func::CurrentGroup => Value::Int(cx.env.current_group),
            Func::Forward => {
                cx.env.forward = true;
                Value::Void
            }
            Func::Backward => {
                cx.env.forward = false;
                Value::Void
            }
            Func::IsForward => Value::Bool(cx.env.forward),
            Func::Stop => {
                cx.env.stop = true;
                Value::Void
            }
            Func::Random(op) => cx.env.random.call(op, vals),
            Func::Model(a) if a.changes_the_model() => {
                // The run's own copy, made on the first change.
                return cx.env.model.make_mut().call_mut(a, vals);
            }
            Func::Model(a) => return cx.env.model.call(a, vals),
            Func::NoOp => {
                let _ = span;
                Value::Void
            }
            Func::Io(f) => return super::stdio::call(f, vals, &cx.env.output),
            Func::Batch(b) => batch(b),
        })
    }
}

/// What [`Func::Batch`] gives: see [`Batch`].
fn batch(b: Batch) -> Value {
    match b {
        Batch::MouseStatus => Value::Struct(Box::new([
            Value::Int(-1),
            Value::Int(0),
            Value::Int(0),
            Value::V3(DVec3::ZERO),
            Value::V3(DVec3::ZERO),
            Value::V3(DVec3::ZERO),
            Value::Bool(false),
            Value::Bool(false),
            Value::Bool(false),
        ])),
        Batch::MenuChoice => Value::Int(-1),
        Batch::CameraPosition => Value::Struct(Box::new([
            Value::V3(DVec3::Z),
            Value::V3(DVec3::ZERO),
            Value::V3(DVec3::NEG_Z),
            Value::V3(DVec3::NEG_X),
            Value::V3(DVec3::Y),
            Value::Float(1.0),
        ])),
        Batch::ViewMin(_) => Value::Float(-1.0),
        Batch::ViewMax(_) => Value::Float(1.0),
        Batch::ViewScale => Value::Float(1.0),
    }
}

struct Cx<'a> {
    frame: &'a mut [Value],
    env: &'a mut Env,
    host: &'a mut (dyn Host + Send),
    sink: &'a mut dyn Emit,
}

fn field(v: &Value, i: u16) -> Value {
    match v {
        Value::V2(p) => Value::Float(p[i as usize]),
        Value::V3(p) => Value::Float(p[i as usize]),
        Value::Struct(fs) => fs[i as usize].clone(),
        _ => Value::Void,
    }
}

/// An index out of an array's range, as a run-time error.
fn out_of_range(i: i64, len: usize, span: Span) -> Box<RuntimeError> {
    rt(
        Some(span),
        format!(
            "index {i} is out of range: the array has {len} element(s), indices 0 to {}",
            len as i64 - 1
        ),
    )
}

/// Character `i` of a string, as C reads a `char` array (0 at the end).
fn char_at(s: &str, i: i64, span: Span) -> R<Value> {
    let b = s.as_bytes();
    match usize::try_from(i).ok() {
        Some(k) if k < b.len() => Ok(Value::Int(b[k] as i64)),
        Some(k) if k == b.len() => Ok(Value::Int(0)),
        _ => Err(rt(
            Some(span),
            format!(
                "index {i} is out of range: the string has {} character(s)",
                b.len()
            ),
        )),
    }
}

/// The address of a local variable: how deep the stack is here.
#[inline(never)]
fn stack_address() -> usize {
    let marker = 0u8;
    std::hint::black_box(&marker) as *const u8 as usize
}

fn set_path(root: &mut Value, path: &[Step], value: Value) {
    let Some((first, rest)) = path.split_first() else {
        *root = value;
        return;
    };
    let Step::Field(first) = *first else {
        return;
    };
    match root {
        Value::V2(p) => p[first as usize] = value.as_f64(),
        Value::V3(p) => p[first as usize] = value.as_f64(),
        Value::Struct(fs) => set_path(&mut fs[first as usize], rest, value),
        _ => {}
    }
}

/// The common cases of [`binary`], numbers and points, without moving the
/// values: the same results, fewer steps.
#[inline]
fn float_binary(op: BinOp, x: &Value, y: &Value) -> Option<Value> {
    use BinOp::*;
    let float = |a: f64, b: f64| -> Option<Value> {
        Some(match op {
            Add => Value::Float(a + b),
            Sub => Value::Float(a - b),
            Mul => Value::Float(a * b),
            Div => Value::Float(a / b),
            Lt => Value::Bool(a < b),
            Le => Value::Bool(a <= b),
            Gt => Value::Bool(a > b),
            Ge => Value::Bool(a >= b),
            Eq => Value::Bool(a == b),
            Ne => Value::Bool(a != b),
            _ => return None,
        })
    };
    Some(match (x, y) {
        (Value::Int(a), Value::Int(b)) => match op {
            Add => Value::Int(a.wrapping_add(*b)),
            Sub => Value::Int(a.wrapping_sub(*b)),
            Mul => Value::Int(a.wrapping_mul(*b)),
            Div if *b != 0 => Value::Int(a.wrapping_div(*b)),
            Rem if *b != 0 => Value::Int(a.wrapping_rem(*b)),
            Lt => Value::Bool(a < b),
            Le => Value::Bool(a <= b),
            Gt => Value::Bool(a > b),
            Ge => Value::Bool(a >= b),
            Eq => Value::Bool(a == b),
            Ne => Value::Bool(a != b),
            _ => return None,
        },
        (Value::Int(a), Value::Float(b)) => return float(*a as f64, *b),
        (Value::Float(a), Value::Int(b)) => return float(*a, *b as f64),
        (Value::Float(a), Value::Float(b)) => return float(*a, *b),
        (Value::V3(a), Value::V3(b)) => match op {
            Add => Value::V3(*a + *b),
            Sub => Value::V3(*a - *b),
            _ => return None,
        },
        (Value::Float(s), Value::V3(p)) | (Value::V3(p), Value::Float(s)) if op == Mul => {
            Value::V3(*p * *s)
        }
        (Value::V3(p), Value::Float(s)) if op == Div => Value::V3(*p / *s),
        _ => return None,
    })
}

/// Applies a binary operator to two values whose types were checked.
pub fn binary(op: BinOp, x: Value, y: Value) -> Result<Value, String> {
    use BinOp::*;
    use Value::*;
    let x = if let Bool(b) = x { Int(b as i64) } else { x };
    let y = if let Bool(b) = y { Int(b as i64) } else { y };
    Ok(match (op, x, y) {
        // Elements: by identity (not by the flags of how they were read),
        // ordered by id.
        (Eq, Elem(a), Elem(b)) => Bool(a.kind == b.kind && a.ids == b.ids),
        (Ne, Elem(a), Elem(b)) => Bool(!(a.kind == b.kind && a.ids == b.ids)),
        (Lt, Elem(a), Elem(b)) => Bool(a.ids[0] < b.ids[0]),
        (Le, Elem(a), Elem(b)) => Bool(a.ids[0] <= b.ids[0]),
        (Gt, Elem(a), Elem(b)) => Bool(a.ids[0] > b.ids[0]),
        (Ge, Elem(a), Elem(b)) => Bool(a.ids[0] >= b.ids[0]),
        (Add, Int(a), Int(b)) => Int(a.wrapping_add(b)),
        (Sub, Int(a), Int(b)) => Int(a.wrapping_sub(b)),
        (Mul, Int(a), Int(b)) => Int(a.wrapping_mul(b)),
        (Div, Int(_), Int(0)) | (Rem, Int(_), Int(0)) => {
            return Err("integer division by zero".into())
        }
        (Div, Int(a), Int(b)) => Int(a.wrapping_div(b)),
        (Rem, Int(a), Int(b)) => Int(a.wrapping_rem(b)),
        (BitAnd, Int(a), Int(b)) => Int(a & b),
        (BitOr, Int(a), Int(b)) => Int(a | b),
        (BitXor, Int(a), Int(b)) => Int(a ^ b),
        // C leaves a shift by a negative count or by the width or more
        // undefined; here it is an error rather than a guess.
        (Shl | Shr, Int(_), Int(b)) if !(0..64).contains(&b) => {
            return Err(format!("a shift by {b} bits (C allows 0 to 63 here)"))
        }
        (Shl, Int(a), Int(b)) => Int(a.wrapping_shl(b as u32)),
        (Shr, Int(a), Int(b)) => Int(a >> b),
        (Lt, Int(a), Int(b)) => Bool(a < b),
        (Le, Int(a), Int(b)) => Bool(a <= b),
        (Gt, Int(a), Int(b)) => Bool(a > b),
        (Ge, Int(a), Int(b)) => Bool(a >= b),
        (Eq, Int(a), Int(b)) => Bool(a == b),
        (Ne, Int(a), Int(b)) => Bool(a != b),
        (Add, V2(a), V2(b)) => V2(a + b),
        (Sub, V2(a), V2(b)) => V2(a - b),
        (Add, V3(a), V3(b)) => V3(a + b),
        (Sub, V3(a), V3(b)) => V3(a - b),
        (Mul, V2(a), V2(b)) => Float(a.dot(b)),
        (Mul, V3(a), V3(b)) => Float(a.dot(b)),
        (Rem, V3(a), V3(b)) => V3(a.cross(b)),
        (Eq, V2(a), V2(b)) => Bool(a == b),
        (Ne, V2(a), V2(b)) => Bool(a != b),
        (Eq, V3(a), V3(b)) => Bool(a == b),
        (Ne, V3(a), V3(b)) => Bool(a != b),
        (Mul, V2(a), s) | (Mul, s, V2(a)) => V2(a * s.as_f64()),
        (Mul, V3(a), s) | (Mul, s, V3(a)) => V3(a * s.as_f64()),
        (Div, V2(a), s) => V2(a / s.as_f64()),
        (Div, V3(a), s) => V3(a / s.as_f64()),
        (op, a, b) => {
            let (a, b) = (a.as_f64(), b.as_f64());
            match op {
                Add => Float(a + b),
                Sub => Float(a - b),
                Mul => Float(a * b),
                Div => Float(a / b),
                Rem => Float(a % b),
                Lt => Bool(a < b),
                Le => Bool(a <= b),
                Gt => Bool(a > b),
                Ge => Bool(a >= b),
                Eq => Bool(a == b),
                Ne => Bool(a != b),
                _ => {
                    return Err(format!(
                        "operator `{}` does not apply to these values",
                        op.symbol()
                    ))
                }
            }
        }
    })
}

impl std::fmt::Display for RuntimeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for RuntimeError {}

/// How many numbers a value holds: an array or struct counts its
/// elements, all the way down.
fn value_count(v: &Value) -> usize {
    match v {
        Value::Struct(fs) => fs.iter().fold(1, |n, f| n.saturating_add(value_count(f))),
        _ => 1,
    }
}

/// The value at a place whose array indices `idx` are evaluated.
fn load_at(place: &Place, idx: &[i64], cx: &Cx) -> R<Value> {
    let mut v = if place.global {
        &cx.env.globals[place.slot as usize]
    } else {
        &cx.frame[place.slot as usize]
    };
    let mut k = 0;
    for step in &place.path {
        match step {
            Step::Field(i) => match v {
                Value::Struct(fs) => v = &fs[*i as usize],
                other => return Ok(field(other, *i)),
            },
            Step::Index(_, span) => {
                let i = idx[k];
                k += 1;
                match v {
                    Value::Struct(fs) => match usize::try_from(i).ok().and_then(|i| fs.get(i)) {
                        Some(e) => v = e,
                        None => return Err(out_of_range(i, fs.len(), *span)),
                    },
                    Value::Str(s) => return char_at(s, i, *span),
                    _ => return Ok(Value::Void),
                }
            }
        }
    }
    Ok(v.clone())
}

/// Writes `value` at a place whose array indices `idx` are evaluated.
fn store_at(place: &Place, idx: &[i64], value: Value, cx: &mut Cx) -> R<()> {
    let root = if place.global {
        &mut cx.env.globals[place.slot as usize]
    } else {
        &mut cx.frame[place.slot as usize]
    };
    let mut v = root;
    let mut k = 0;
    for step in &place.path {
        match step {
            Step::Field(i) => match v {
                Value::Struct(fs) => v = &mut fs[*i as usize],
                other => {
                    // The last step: a vector's component.
                    set_path(other, std::slice::from_ref(step), value);
                    return Ok(());
                }
            },
            Step::Index(_, span) => {
                let i = idx[k];
                k += 1;
                match v {
                    Value::Struct(fs) => {
                        let n = fs.len();
                        match usize::try_from(i).ok().and_then(|i| fs.get_mut(i)) {
                            Some(e) => v = e,
                            None => return Err(out_of_range(i, n, *span)),
                        }
                    }
                    Value::Str(_) => {
                        return Err(rt(
                            Some(*span),
                            "a character of a string cannot be assigned; build the string with sprintf, strcpy or strcat",
                        ))
                    }
                    _ => return Ok(()),
                }
            }
        }
    }
    *v = value;
    Ok(())
}
