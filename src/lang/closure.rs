//! Rule bodies compiled to closures: a specialisation of the checked IR
//! for the word rewriter, never a second language.
//!
//! A body whose values are all numbers (`int`, `float`, `double`, `bool`
//! parameters, locals and globals) is turned into a tree of closures over
//! a frame of 64-bit words, each expression's kind (integer, floating,
//! boolean) fixed when it is compiled: no [`Value`] is made, matched or
//! dropped while it runs, parameters are read straight from the word's
//! slots and successor parameters written straight back as slots.
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

use std::cell::Cell;

use crate::deadline::Deadline;
use crate::syntax::ast::BinOp;
use crate::syntax::span::Span;

use super::eval::{Emit, Env, Flow, RuntimeError, LOOP_LIMIT};
use super::ir::{Ex, Func, Pattern, Rule, St};
use super::modules::Sym;
use super::value::{round32, Ty, Value};

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

/// The kind of a value at run time: `Value::Int`, `Value::Float`,
/// `Value::Bool`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    I,
    F,
    B,
}

fn kind_of(ty: Ty) -> Option<Kind> {
    match ty {
        Ty::Int => Some(Kind::I),
        Ty::Float | Ty::Double => Some(Kind::F),
        Ty::Bool => Some(Kind::B),
        _ => None,
    }
}

/// An operand read without a call: a local or a number, as `f64`.
#[derive(Clone, Copy)]
enum Leaf {
    Float(usize),
    Int(usize),
    Const(f64),
}

impl Leaf {
    #[inline(always)]
    fn get(self, frame: &[u64]) -> f64 {
        match self {
            Leaf::Float(s) => f64::from_bits(frame[s]),
            Leaf::Int(s) => frame[s] as i64 as f64,
            Leaf::Const(x) => x,
        }
    }
}

/// A compiled expression of its kind.
enum C {
    I(IE),
    F(FE),
    B(BE),
}

impl C {
    fn kind(&self) -> Kind {
        match self {
            C::I(_) => Kind::I,
            C::F(_) => Kind::F,
            C::B(_) => Kind::B,
        }
    }

    /// `Value::as_f64`.
    fn f(self) -> FE {
        match self {
            C::F(f) => f,
            C::I(f) => Box::new(move |cx| Ok(f(cx)? as f64)),
            C::B(f) => Box::new(move |cx| Ok(f(cx)? as i64 as f64)),
        }
    }

    /// `Value::as_i64`.
    fn i(self) -> IE {
        match self {
            C::I(f) => f,
            C::F(f) => Box::new(move |cx| Ok(f(cx)? as i64)),
            C::B(f) => Box::new(move |cx| Ok(f(cx)? as i64)),
        }
    }

    /// `Value::truthy`.
    fn b(self) -> BE {
        match self {
            C::B(f) => f,
            C::I(f) => Box::new(move |cx| Ok(f(cx)? != 0)),
            C::F(f) => Box::new(move |cx| Ok(f(cx)? != 0.0)),
        }
    }

    /// The value's 64 bits as the frame holds them: an `f64`'s bits, an
    /// `i64`'s, 0 or 1.
    fn bits(self) -> UE {
        match self {
            C::F(f) => Box::new(move |cx| Ok(f(cx)?.to_bits())),
            C::I(f) => Box::new(move |cx| Ok(f(cx)? as u64)),
            C::B(f) => Box::new(move |cx| Ok(f(cx)? as u64)),
        }
    }
}

/// Reads a frame slot of kind `k`.
fn read(k: Kind, s: usize) -> C {
    match k {
        Kind::F => C::F(Box::new(move |cx| Ok(f64::from_bits(cx.m.frame[s])))),
        Kind::I => C::I(Box::new(move |cx| Ok(cx.m.frame[s] as i64))),
        Kind::B => C::B(Box::new(move |cx| Ok(cx.m.frame[s] != 0))),
    }
}

/// Reads a global of kind `k` (a global's value always has its type's
/// variant: initialisers and assignments convert to it).
fn read_global(k: Kind, s: usize) -> C {
    match k {
        Kind::F => C::F(Box::new(move |cx| Ok(cx.env.globals[s].as_f64()))),
        Kind::I => C::I(Box::new(move |cx| Ok(cx.env.globals[s].as_i64()))),
        Kind::B => C::B(Box::new(move |cx| Ok(cx.env.globals[s].truthy()))),
    }
}

fn value_of(k: Kind, bits: u64) -> Value {
    match k {
        Kind::F => Value::Float(f64::from_bits(bits)),
        Kind::I => Value::Int(bits as i64),
        Kind::B => Value::Bool(bits != 0),
    }
}

/// `Value::convert` to `ty` of a value of kind `c.kind()`: the kind of
/// the result is `ty`'s.
fn convert(ty: Ty, c: C) -> Option<C> {
    Some(match (ty, c) {
        (Ty::Int, c) => C::I(c.i()),
        (Ty::Float, c) => {
            let f = c.f();
            C::F(Box::new(move |cx| Ok(round32(f(cx)?))))
        }
        (Ty::Double, c) => C::F(c.f()),
        (Ty::Bool, c) => C::B(c.b()),
        _ => return None,
    })
}

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

impl Compiler<'_> {
    fn write(&mut self, slot: u16, k: Kind) -> Option<usize> {
        let s = slot as usize;
        if let Some(st) = self.stored.get_mut(s) {
            *st = true;
        }
        let w = self.writes.get_mut(s)?;
        match w {
            Some(o) if *o != k => self.conflict = true,
            _ => *w = Some(k),
        }
        Some(s)
    }

    fn local(&mut self, slot: u16) -> Option<C> {
        let s = slot as usize;
        match *self.kinds.get(s)? {
            Some(k) => Some(read(k, s)),
            None => {
                self.unknown = true;
                Some(read(Kind::F, s))
            }
        }
    }

    /// A leaf read as a floating-point operand (`Value::as_f64`): a local
    /// of known kind `F` or `I`, or a number.
    fn leaf(&self, e: &Ex) -> Option<Leaf> {
        match e {
            Ex::Local(s) => match self.kinds.get(*s as usize)? {
                Some(Kind::F) => Some(Leaf::Float(*s as usize)),
                Some(Kind::I) => Some(Leaf::Int(*s as usize)),
                _ => None,
            },
            Ex::Const(Value::Float(x)) => Some(Leaf::Const(*x)),
            Ex::Const(Value::Int(i)) => Some(Leaf::Const(*i as f64)),
            _ => None,
        }
    }

    /// `a op b` on two leaves of which one at least is floating, in one
    /// closure (rounded to single precision with `round`): the floating
    /// branch of [`bin`] without a call per operand.
    fn fused(&self, op: BinOp, a: &Ex, b: &Ex, round: bool) -> Option<C> {
        use BinOp::*;
        let (x, y) = (self.leaf(a)?, self.leaf(b)?);
        let floating = |l: Leaf, e: &Ex| {
            matches!(l, Leaf::Float(_)) || matches!(e, Ex::Const(Value::Float(_)))
        };
        if !floating(x, a) && !floating(y, b) {
            return None;
        }
        macro_rules! f {
            ($f:expr) => {
                C::F(Box::new(move |cx| {
                    let v = $f(x.get(&cx.m.frame), y.get(&cx.m.frame));
                    Ok(if round { round32(v) } else { v })
                }))
            };
        }
        macro_rules! b {
            ($f:expr) => {
                C::B(Box::new(move |cx| {
                    Ok($f(x.get(&cx.m.frame), y.get(&cx.m.frame)))
                }))
            };
        }
        Some(match op {
            Add => f!(|p: f64, q: f64| p + q),
            Sub => f!(|p: f64, q: f64| p - q),
            Mul => f!(|p: f64, q: f64| p * q),
            Div => f!(|p: f64, q: f64| p / q),
            Lt if !round => b!(|p: f64, q: f64| p < q),
            Le if !round => b!(|p: f64, q: f64| p <= q),
            Gt if !round => b!(|p: f64, q: f64| p > q),
            Ge if !round => b!(|p: f64, q: f64| p >= q),
            Eq if !round => b!(|p: f64, q: f64| p == q),
            Ne if !round => b!(|p: f64, q: f64| p != q),
            _ => return None,
        })
    }

    /// `a op b` where one operand is a leaf and the other compiles to a
    /// floating expression, in one closure that calls that expression and
    /// reads the leaf itself (rounded to single precision with `round`):
    /// the floating branch of [`bin`] with one call fewer. The left operand
    /// is evaluated first, as in `bin`.
    fn half_fused(&mut self, op: BinOp, a: &Ex, b: &Ex, round: bool) -> Option<Result<C, C>> {
        use BinOp::*;
        if !matches!(op, Add | Sub | Mul | Div) {
            return None;
        }
        let (la, lb) = (self.leaf(a), self.leaf(b));
        macro_rules! f {
            ($op:tt, $e:expr, $l:expr, $left:expr) => {{
                let (e, l) = ($e, $l);
                if $left {
                    C::F(Box::new(move |cx| {
                        let v = e(cx)? $op l.get(&cx.m.frame);
                        Ok(if round { round32(v) } else { v })
                    }))
                } else {
                    C::F(Box::new(move |cx| {
                        let x = l.get(&cx.m.frame);
                        let v = x $op e(cx)?;
                        Ok(if round { round32(v) } else { v })
                    }))
                }
            }};
        }
        let (e, l, left) = match (la, lb) {
            (None, Some(l)) => (self.expr(a)?, l, true),
            (Some(l), None) => (self.expr(b)?, l, false),
            _ => return None,
        };
        let C::F(e) = e else {
            return Some(Err(e));
        };
        Some(Ok(match op {
            Add => f!(+, e, l, left),
            Sub => f!(-, e, l, left),
            Mul => f!(*, e, l, left),
            _ => f!(/, e, l, left),
        }))
    }

    /// A binary operator on two expressions: [`Compiler::fused`] or
    /// [`Compiler::half_fused`] where they apply, otherwise [`bin`] (after
    /// a conversion to `ty`, when given).
    fn binary(&mut self, op: BinOp, a: &Ex, b: &Ex, span: Span, ty: Option<Ty>) -> Option<C> {
        let round = ty == Some(Ty::Float);
        if ty.is_none() || round {
            if let Some(c) = self.fused(op, a, b, round) {
                return Some(c);
            }
            match self.half_fused(op, a, b, round) {
                Some(Ok(c)) => return Some(c),
                // The expression side was compiled but is not floating.
                Some(Err(e)) => {
                    let (ca, cb) = if self.leaf(a).is_some() {
                        (self.expr(a)?, e)
                    } else {
                        (e, self.expr(b)?)
                    };
                    let c = bin(op, ca, cb, Some(span))?;
                    return match ty {
                        Some(ty) => convert(ty, c),
                        None => Some(c),
                    };
                }
                None => {}
            }
        }
        let (ca, cb) = (self.expr(a)?, self.expr(b)?);
        let c = bin(op, ca, cb, Some(span))?;
        match ty {
            Some(ty) => convert(ty, c),
            None => Some(c),
        }
    }

    /// `if (a OP b) t else e` where `a OP b` compares two leaves of which
    /// one at least is floating ([`Compiler::fused`]'s comparisons): the
    /// test made in the statement's closure, with no call for it.
    fn if_compare(&mut self, c: &Ex, t: &St, e: Option<&St>) -> Option<SE> {
        use BinOp::*;
        let Ex::Bin(op, a, b, _) = c else {
            return None;
        };
        let (x, y) = (self.leaf(a)?, self.leaf(b)?);
        let floating = |l: Leaf, e: &Ex| {
            matches!(l, Leaf::Float(_)) || matches!(e, Ex::Const(Value::Float(_)))
        };
        if !matches!(op, Lt | Le | Gt | Ge | Eq | Ne) || (!floating(x, a) && !floating(y, b)) {
            return None;
        }
        let t = self.stmt(t)?;
        let e = match e {
            Some(e) => Some(self.stmt(e)?),
            None => None,
        };
        macro_rules! iff {
            ($f:expr) => {
                match e {
                    Some(e) => Box::new(move |cx: &mut Cx| {
                        if $f(x.get(&cx.m.frame), y.get(&cx.m.frame)) {
                            t(cx)
                        } else {
                            e(cx)
                        }
                    }) as SE,
                    None => Box::new(move |cx: &mut Cx| {
                        if $f(x.get(&cx.m.frame), y.get(&cx.m.frame)) {
                            t(cx)
                        } else {
                            Ok(Flow::Normal)
                        }
                    }),
                }
            };
        }
        Some(match op {
            Lt => iff!(|p: f64, q: f64| p < q),
            Le => iff!(|p: f64, q: f64| p <= q),
            Gt => iff!(|p: f64, q: f64| p > q),
            Ge => iff!(|p: f64, q: f64| p >= q),
            Eq => iff!(|p: f64, q: f64| p == q),
            _ => iff!(|p: f64, q: f64| p != q),
        })
    }

    fn block(&mut self, body: &[St]) -> Option<SE> {
        let mut sts = body
            .iter()
            .map(|s| self.stmt(s))
            .collect::<Option<Vec<_>>>()?;
        if sts.len() == 1 {
            return sts.pop();
        }
        Some(Box::new(move |cx| {
            for s in &sts {
                match s(cx)? {
                    Flow::Normal => {}
                    f => return Ok(f),
                }
            }
            Ok(Flow::Normal)
        }))
    }

    fn stmt(&mut self, s: &St) -> Option<SE> {
        Some(match s {
            St::Expr(e) => {
                let e = self.expr(e)?.bits();
                Box::new(move |cx| {
                    e(cx)?;
                    Ok(Flow::Normal)
                })
            }
            St::Init(slot, e) => {
                let c = self.expr(e)?;
                let s = self.write(*slot, c.kind())?;
                let e = c.bits();
                Box::new(move |cx| {
                    cx.m.frame[s] = e(cx)?;
                    Ok(Flow::Normal)
                })
            }
            St::If(c, t, e) => {
                if let Some(s) = self.if_compare(c, t, e.as_deref()) {
                    return Some(s);
                }
                let c = self.expr(c)?.b();
                let t = self.stmt(t)?;
                match e {
                    Some(e) => {
                        let e = self.stmt(e)?;
                        Box::new(move |cx| if c(cx)? { t(cx) } else { e(cx) })
                    }
                    None => Box::new(move |cx| if c(cx)? { t(cx) } else { Ok(Flow::Normal) }),
                }
            }
            St::Loop {
                cond,
                body,
                step,
                test_after,
                span,
            } => {
                let cond = match cond {
                    Some(c) => Some(self.expr(c)?.b()),
                    None => None,
                };
                let body = self.stmt(body)?;
                let step = match step {
                    Some(s) => Some(self.expr(s)?.bits()),
                    None => None,
                };
                let (test_after, span) = (*test_after, *span);
                Box::new(move |cx| {
                    let mut first = true;
                    loop {
                        if !(first && test_after) {
                            if let Some(c) = &cond {
                                if !c(cx)? {
                                    break;
                                }
                            }
                        }
                        first = false;
                        if cx.m.fuel == 0 {
                            return Err(rt(
                                Some(span),
                                format!("a loop ran more than {} iterations in one body; is its condition ever false?", cx.m.loop_limit),
                            ));
                        }
                        cx.m.fuel -= 1;
                        cx.m.ticks = cx.m.ticks.wrapping_add(1);
                        if cx.m.ticks.is_multiple_of(DEADLINE_EVERY) {
                            if let Err(m) = crate::deadline::check(cx.m.deadline) {
                                return Err(rt(Some(span), m));
                            }
                        }
                        match body(cx)? {
                            Flow::Break => break,
                            Flow::Normal | Flow::Continue => {}
                            f => return Ok(f),
                        }
                        if let Some(st) = &step {
                            st(cx)?;
                        }
                    }
                    Ok(Flow::Normal)
                })
            }
            St::Block(b) => self.block(b)?,
            St::Produce { modules, last } => {
                // Every parameter of every module in one list, in order,
                // each with its module and its place in it.
                let mut args = Vec::new();
                for (k, m) in modules.iter().enumerate() {
                    for (j, a) in m.args.iter().enumerate() {
                        args.push((self.arg(a)?, k, j));
                    }
                }
                let first = modules.first().map(|m| m.span);
                let flow = if *last { Flow::Produced } else { Flow::Normal };
                let syms: Vec<Sym> = modules.iter().map(|m| m.sym).collect();
                let widths: Vec<usize> = modules.iter().map(|m| m.args.len()).collect();
                let spans: Vec<Span> = modules.iter().map(|m| m.span).collect();
                // Where each module's slots start among the statement's.
                let starts: Vec<usize> = widths
                    .iter()
                    .scan(0, |at, &w| {
                        let s = *at;
                        *at += w;
                        Some(s)
                    })
                    .collect();
                Box::new(move |cx| {
                    // Every module's slots first, then all modules at once;
                    // when one fails, the sink gets those before it, as
                    // module by module.
                    let base = cx.m.slots.len();
                    cx.m.slots.reserve(args.len());
                    for (a, k, j) in &args {
                        if let Err(e) = parameter(cx, a, *j, spans[*k]) {
                            cx.m.slots.truncate(base + starts[*k]);
                            cx.sink
                                .emit_run(&syms[..*k], &widths[..*k], &cx.m.slots[base..]);
                            cx.m.slots.truncate(base);
                            return Err(e);
                        }
                    }
                    cx.sink.emit_run(&syms, &widths, &cx.m.slots[base..]);
                    cx.m.slots.truncate(base);
                    if cx.sink.full() {
                        return Err(rt(first, "this successor takes the word past its limit"));
                    }
                    Ok(flow)
                })
            }
            St::Return => Box::new(|_| Ok(Flow::Return)),
            St::Break => Box::new(|_| Ok(Flow::Break)),
            St::Continue => Box::new(|_| Ok(Flow::Continue)),
            _ => return None,
        })
    }

    /// A successor parameter: a constant's slot (a finite `float`, an
    /// `int`, a `bool`, possibly converted) or a local of known kind read
    /// where it is written, otherwise the compiled expression.
    fn arg(&mut self, e: &Ex) -> Option<Arg> {
        let constant = match e {
            Ex::Const(v) => Some(v.clone()),
            Ex::Convert(ty, c) => match &**c {
                Ex::Const(v) if kind_of(*ty).is_some() => Some(v.clone().convert(*ty)),
                _ => None,
            },
            _ => None,
        };
        match constant {
            Some(Value::Float(f)) if f.is_finite() => return Some(Arg::Slot(f)),
            Some(Value::Int(i)) => return Some(Arg::Slot(f64::from_bits(i as u64))),
            Some(Value::Bool(b)) => return Some(Arg::Slot(b as u8 as f64)),
            _ => {}
        }
        if let Ex::Local(s) = e {
            if let Some(Some(k)) = self.kinds.get(*s as usize) {
                return Some(Arg::Local(*k, *s as usize));
            }
        }
        Some(Arg::C(self.expr(e)?))
    }

    fn expr(&mut self, e: &Ex) -> Option<C> {
        Some(match e {
            Ex::Const(Value::Int(i)) => {
                let i = *i;
                C::I(Box::new(move |_| Ok(i)))
            }
            Ex::Const(Value::Float(x)) => {
                let x = *x;
                C::F(Box::new(move |_| Ok(x)))
            }
            Ex::Const(Value::Bool(b)) => {
                let b = *b;
                C::B(Box::new(move |_| Ok(b)))
            }
            Ex::Local(s) => self.local(*s)?,
            Ex::Global(s) => read_global(kind_of(self.globals.get(*s as usize)?.ty)?, *s as usize),
            Ex::Neg(a) => match self.expr(a)? {
                C::I(f) => C::I(Box::new(move |cx| Ok(f(cx)?.wrapping_neg()))),
                C::F(f) => C::F(Box::new(move |cx| Ok(-f(cx)?))),
                C::B(f) => C::I(Box::new(move |cx| Ok(-(f(cx)? as i64)))),
            },
            Ex::Not(a) => {
                let a = self.expr(a)?.b();
                C::B(Box::new(move |cx| Ok(!a(cx)?)))
            }
            Ex::Bin(op, a, b, span) => self.binary(*op, a, b, *span, None)?,
            Ex::Logic(and, a, b) => {
                let (a, b) = (self.expr(a)?.b(), self.expr(b)?.b());
                if *and {
                    C::B(Box::new(move |cx| Ok(a(cx)? && b(cx)?)))
                } else {
                    C::B(Box::new(move |cx| Ok(a(cx)? || b(cx)?)))
                }
            }
            Ex::Cond(c, a, b) => {
                let c = self.expr(c)?.b();
                match (self.expr(a)?, self.expr(b)?) {
                    (C::I(a), C::I(b)) => {
                        C::I(Box::new(move |cx| if c(cx)? { a(cx) } else { b(cx) }))
                    }
                    (C::F(a), C::F(b)) => {
                        C::F(Box::new(move |cx| if c(cx)? { a(cx) } else { b(cx) }))
                    }
                    (C::B(a), C::B(b)) => {
                        C::B(Box::new(move |cx| if c(cx)? { a(cx) } else { b(cx) }))
                    }
                    _ => return None,
                }
            }
            Ex::Convert(ty, a) => {
                if let (Ty::Float, Ex::Bin(op, x, y, span)) = (ty, &**a) {
                    return self.binary(*op, x, y, *span, Some(Ty::Float));
                }
                let a = self.expr(a)?;
                convert(*ty, a)?
            }
            Ex::Call(f, args, _) => {
                let mut args = args
                    .iter()
                    .map(|a| self.expr(a))
                    .collect::<Option<Vec<_>>>()?
                    .into_iter();
                let mut next = || args.next();
                match f {
                    Func::Math1(g) => {
                        let (g, a) = (*g, next()?.f());
                        C::F(Box::new(move |cx| Ok(g(a(cx)?))))
                    }
                    Func::Math2(g) => {
                        let (g, a, b) = (*g, next()?.f(), next()?.f());
                        C::F(Box::new(move |cx| {
                            let x = a(cx)?;
                            Ok(g(x, b(cx)?))
                        }))
                    }
                    Func::AbsInt => {
                        let a = next()?.i();
                        C::I(Box::new(move |cx| Ok(a(cx)?.wrapping_abs())))
                    }
                    Func::MinInt | Func::MaxInt => {
                        let (a, b) = (next()?.i(), next()?.i());
                        if matches!(f, Func::MinInt) {
                            C::I(Box::new(move |cx| {
                                let x = a(cx)?;
                                Ok(x.min(b(cx)?))
                            }))
                        } else {
                            C::I(Box::new(move |cx| {
                                let x = a(cx)?;
                                Ok(x.max(b(cx)?))
                            }))
                        }
                    }
                    Func::Random(op) => {
                        use super::random::Op;
                        self.effects = true;
                        let op = *op;
                        let float = match op {
                            Op::Ran | Op::Drand48 | Op::GillespieTime => true,
                            Op::Rand | Op::Lrand48 | Op::Mrand48 => false,
                            // The seeding calls give no value.
                            _ => return None,
                        };
                        let arg = next().map(|c| (c.kind(), c.bits()));
                        if next().is_some() {
                            return None;
                        }
                        // `Random::call` on the argument as the interpreter
                        // holds it.
                        let call = move |cx: &mut Cx| -> R<Value> {
                            Ok(match &arg {
                                Some((k, a)) => {
                                    let v = value_of(*k, a(cx)?);
                                    cx.env.random.call(op, std::slice::from_ref(&v))
                                }
                                None => cx.env.random.call(op, &[]),
                            })
                        };
                        if float {
                            C::F(Box::new(move |cx| Ok(call(cx)?.as_f64())))
                        } else {
                            C::I(Box::new(move |cx| Ok(call(cx)?.as_i64())))
                        }
                    }
                    _ => return None,
                }
            }
            Ex::Let(slot, a, body) => {
                let a = self.expr(a)?;
                let s = self.write(*slot, a.kind())?;
                let a = a.bits();
                match self.expr(body)? {
                    C::I(b) => C::I(Box::new(move |cx| {
                        cx.m.frame[s] = a(cx)?;
                        b(cx)
                    })),
                    C::F(b) => C::F(Box::new(move |cx| {
                        cx.m.frame[s] = a(cx)?;
                        b(cx)
                    })),
                    C::B(b) => C::B(Box::new(move |cx| {
                        cx.m.frame[s] = a(cx)?;
                        b(cx)
                    })),
                }
            }
            Ex::Assign(place, op, rhs, ty) if place.path.is_empty() => {
                // The interpreter evaluates the right-hand side before it
                // reads the variable of `x += e`: compiled, `e` must not
                // write anything.
                if op.is_some() && !pure(rhs) {
                    return None;
                }
                let k = kind_of(*ty)?;
                let r = self.expr(rhs)?;
                let new = match op {
                    None => convert(*ty, r)?,
                    Some(op) => {
                        let cur = if place.global {
                            let g = place.slot as usize;
                            read_global(kind_of(self.globals.get(g)?.ty)?, g)
                        } else {
                            self.local(place.slot)?
                        };
                        // `binary`'s errors here have no span.
                        convert(*ty, bin(*op, cur, r, None)?)?
                    }
                };
                self.store(place.global, place.slot, k, new)?
            }
            Ex::IncDec(place, d, prefix) if place.path.is_empty() => {
                let k = kind_of(place.ty)?;
                let d = *d as i64;
                let cur = if place.global {
                    let g = place.slot as usize;
                    let gk = kind_of(self.globals.get(g)?.ty)?;
                    if gk != k {
                        return None;
                    }
                    read_global(gk, g)
                } else {
                    let c = self.local(place.slot)?;
                    if c.kind() != k {
                        return None;
                    }
                    c
                };
                let step = match (k, cur) {
                    (Kind::I, C::I(c)) => C::I(Box::new(move |cx| Ok(c(cx)?.wrapping_add(d)))),
                    (Kind::F, C::F(c)) => {
                        let single = place.ty == Ty::Float;
                        C::F(Box::new(move |cx| {
                            let v = c(cx)? + d as f64;
                            Ok(if single { round32(v) } else { v })
                        }))
                    }
                    _ => return None,
                };
                let stored = self.store(place.global, place.slot, k, step)?;
                // The old value is the new one less the step, read before
                // the store; the closure below reads the slot itself.
                if *prefix {
                    stored
                } else {
                    let (global, slot) = (place.global, place.slot as usize);
                    let st = stored.bits();
                    let get = move |cx: &mut Cx| -> u64 {
                        if global {
                            match &cx.env.globals[slot] {
                                Value::Int(i) => *i as u64,
                                v => v.as_f64().to_bits(),
                            }
                        } else {
                            cx.m.frame[slot]
                        }
                    };
                    match k {
                        Kind::I => C::I(Box::new(move |cx| {
                            let old = get(cx);
                            st(cx)?;
                            Ok(old as i64)
                        })),
                        _ => C::F(Box::new(move |cx| {
                            let old = get(cx);
                            st(cx)?;
                            Ok(f64::from_bits(old))
                        })),
                    }
                }
            }
            _ => return None,
        })
    }

    /// Stores `new` (of kind `k`) into a local or a global and gives it.
    fn store(&mut self, global: bool, slot: u16, k: Kind, new: C) -> Option<C> {
        if new.kind() != k {
            return None;
        }
        let s = if global {
            if kind_of(self.globals.get(slot as usize)?.ty)? != k {
                return None;
            }
            self.effects = true;
            slot as usize
        } else {
            self.write(slot, k)?
        };
        let v = new.bits();
        let set = move |cx: &mut Cx| -> R<u64> {
            let x = v(cx)?;
            if global {
                cx.env.globals[s] = value_of(k, x);
            } else {
                cx.m.frame[s] = x;
            }
            Ok(x)
        };
        Some(match k {
            Kind::I => C::I(Box::new(move |cx| Ok(set(cx)? as i64))),
            Kind::F => C::F(Box::new(move |cx| Ok(f64::from_bits(set(cx)?)))),
            Kind::B => C::B(Box::new(move |cx| Ok(set(cx)? != 0))),
        })
    }
}

/// True when evaluating `e` writes nothing.
fn pure(e: &Ex) -> bool {
    let mut ok = true;
    e.walk(&mut |x| {
        if matches!(
            x,
            Ex::Assign(..) | Ex::IncDec(..) | Ex::Let(..) | Ex::CallUser { .. }
        ) {
            ok = false;
        }
    });
    ok
}

/// A successor module's parameter as [`Compiler::arg`] compiles it.
enum Arg {
    /// The slot of a constant.
    Slot(f64),
    /// A local of this kind.
    Local(Kind, usize),
    C(C),
}

/// Parameter `j` (from 0) of a successor module at `span`, checked
/// finite, appended to the machine's slots.
#[inline(always)]
fn parameter(cx: &mut Cx, a: &Arg, j: usize, span: Span) -> R<()> {
    // `value::encode`: an int's bits, a float, a bool as 0 or 1.
    let (x, float) = match a {
        Arg::Slot(x) => (*x, false),
        Arg::Local(Kind::F, s) => (f64::from_bits(cx.m.frame[*s]), true),
        Arg::Local(Kind::I, s) => (f64::from_bits(cx.m.frame[*s]), false),
        Arg::Local(Kind::B, s) => ((cx.m.frame[*s] != 0) as u8 as f64, false),
        Arg::C(C::F(a)) => (a(cx)?, true),
        Arg::C(C::I(a)) => (f64::from_bits(a(cx)? as u64), false),
        Arg::C(C::B(a)) => (a(cx)? as u8 as f64, false),
    };
    if float && !x.is_finite() {
        return Err(rt(
            Some(span),
            format!(
                "parameter {} of this successor module is {}; NaN and infinity are not allowed in a word",
                j + 1,
                Value::Float(x)
            ),
        ));
    }
    cx.m.slots.push(x);
    Ok(())
}

/// A binary operator on compiled operands, as `eval::binary` (and its fast
/// path `float_binary`) computes it on values of these kinds; `span`
/// locates its errors.
fn bin(op: BinOp, a: C, b: C, span: Option<Span>) -> Option<C> {
    use BinOp::*;
    let integral = a.kind() != Kind::F && b.kind() != Kind::F;
    if integral {
        // Booleans count as integers (`binary` turns them into ints).
        let (a, b) = (a.i(), b.i());
        macro_rules! int {
            ($f:expr) => {
                C::I(Box::new(move |cx| {
                    let x = a(cx)?;
                    let y = b(cx)?;
                    $f(x, y)
                }))
            };
        }
        macro_rules! cmp {
            ($f:expr) => {
                C::B(Box::new(move |cx| {
                    let x = a(cx)?;
                    let y = b(cx)?;
                    Ok($f(x, y))
                }))
            };
        }
        let zero = move || rt(span, "integer division by zero");
        let shift = move |y: i64| rt(span, format!("a shift by {y} bits (C allows 0 to 63 here)"));
        return Some(match op {
            Add => int!(|x: i64, y| Ok(x.wrapping_add(y))),
            Sub => int!(|x: i64, y| Ok(x.wrapping_sub(y))),
            Mul => int!(|x: i64, y| Ok(x.wrapping_mul(y))),
            Div => int!(|x: i64, y| if y == 0 {
                Err(zero())
            } else {
                Ok(x.wrapping_div(y))
            }),
            Rem => int!(|x: i64, y| if y == 0 {
                Err(zero())
            } else {
                Ok(x.wrapping_rem(y))
            }),
            BitAnd => int!(|x: i64, y| Ok(x & y)),
            BitOr => int!(|x: i64, y| Ok(x | y)),
            BitXor => int!(|x: i64, y| Ok(x ^ y)),
            Shl => int!(|x: i64, y: i64| if (0..64).contains(&y) {
                Ok(x.wrapping_shl(y as u32))
            } else {
                Err(shift(y))
            }),
            Shr => int!(|x: i64, y: i64| if (0..64).contains(&y) {
                Ok(x >> y)
            } else {
                Err(shift(y))
            }),
            Lt => cmp!(|x, y| x < y),
            Le => cmp!(|x, y| x <= y),
            Gt => cmp!(|x, y| x > y),
            Ge => cmp!(|x, y| x >= y),
            Eq => cmp!(|x, y| x == y),
            Ne => cmp!(|x, y| x != y),
            And | Or => return None,
        });
    }
    let (a, b) = (a.f(), b.f());
    macro_rules! flt {
        ($f:expr) => {
            C::F(Box::new(move |cx| {
                let x = a(cx)?;
                let y = b(cx)?;
                Ok($f(x, y))
            }))
        };
    }
    macro_rules! cmp {
        ($f:expr) => {
            C::B(Box::new(move |cx| {
                let x = a(cx)?;
                let y = b(cx)?;
                Ok($f(x, y))
            }))
        };
    }
    Some(match op {
        Add => flt!(|x: f64, y: f64| x + y),
        Sub => flt!(|x: f64, y: f64| x - y),
        Mul => flt!(|x: f64, y: f64| x * y),
        Div => flt!(|x: f64, y: f64| x / y),
        Rem => flt!(|x: f64, y: f64| x % y),
        Lt => cmp!(|x: f64, y: f64| x < y),
        Le => cmp!(|x: f64, y: f64| x <= y),
        Gt => cmp!(|x: f64, y: f64| x > y),
        Ge => cmp!(|x: f64, y: f64| x >= y),
        Eq => cmp!(|x: f64, y: f64| x == y),
        Ne => cmp!(|x: f64, y: f64| x != y),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DeriveOptions, Word};

    /// A derivation's result as text that is equal only when the words
    /// are equal to the bit: symbols, every slot's bits, the globals after
    /// `End`, or the error's message.
    fn fingerprint(text: &str, compiled: bool) -> String {
        fingerprint_limited(text, compiled, DeriveOptions::default().max_modules)
    }

    /// [`fingerprint`] with a limit on the word.
    fn fingerprint_limited(text: &str, compiled: bool, max_modules: usize) -> String {
        set_enabled(compiled);
        let out = (|| {
            let curve = crate::load_str("t.lsys", text, &[]).map_err(|e| e.to_string())?;
            let opts = DeriveOptions {
                max_modules,
                ..DeriveOptions::default()
            };
            let d = curve.derive(opts).map_err(|e| e.to_string())?;
            Ok::<_, String>(format!("{}\n{:?}", word_bits(&d.word), d.env.globals))
        })();
        set_enabled(true);
        out.unwrap_or_else(|e| format!("error: {e}"))
    }

    fn word_bits(w: &Word) -> String {
        let mut s = String::new();
        for i in 0..w.len() {
            s.push_str(&format!("{}(", w.sym(i).0));
            for x in w.data(i) {
                s.push_str(&format!("{:x},", x.to_bits()));
            }
            s.push(')');
        }
        s
    }

    /// The same result with and without compiled bodies; returns it.
    fn both(text: &str) -> String {
        let on = fingerprint(text, true);
        let off = fingerprint(text, false);
        assert_eq!(on, off, "compiled and interpreted differ on\n{text}");
        on
    }

    /// The parameters of the final word's modules, read as `f64`s (ints
    /// are stored by their bits; these tests read floats only).
    fn params(text: &str) -> Vec<f64> {
        both(text);
        let curve = crate::load_str("t.lsys", text, &[]).expect("loads");
        let d = curve.derive(DeriveOptions::default()).expect("derives");
        d.word.all_slots().to_vec()
    }

    fn compiles(text: &str) -> Vec<bool> {
        let curve = crate::load_str("t.lsys", text, &[]).expect("loads");
        let p = &curve.program;
        p.rules
            .iter()
            .map(|r| compile(r, &p.globals).is_some())
            .collect()
    }

    #[test]
    fn common_bodies_compile() {
        // Guards on parameters, arithmetic, locals, if/else, loops with
        // break and continue, maths built-ins, `?:`, `define`d functions,
        // globals read and written, int and bool parameters.
        let text = "#define HALF(x) ((x) * 0.5)\n\
            module A(float, float); module B(int, bool);\n\
            int count = 0;\n\
            derivation length: 2;\nAxiom: A(1, 1) B(3, true);\n\
            A(l, w) : { if (l > 0.01) produce F(l) SB() Left(30) A(l * 0.7, w) EB() A(HALF(l), w); }\n\
            B(n, b) : { float s = 0; int i; for (i = 0; i < 10; i++) { if (i == 2) continue; if (i > 6) break; s += sqrt(i); }\n\
                count += 1; if (b && n > 2) produce B(n / 2, !b) A(s > 3 ? s : 0, pow(2, n)); else produce B(n - 1, b); }\n";
        assert_eq!(compiles(text), vec![true, true]);
        both(text);
        // Off, nothing compiles: the comparisons of these tests are not
        // of the compiled path with itself.
        set_enabled(false);
        let off = compiles(text);
        set_enabled(true);
        assert_eq!(off, vec![false, false]);
        // Not compiled: vectors, user functions; these run interpreted.
        let text = "module P(V2f); module A(float);\nfloat f(float x) { return x * 2; }\n\
            derivation length: 1;\nAxiom: P(V2f(1, 2)) A(1);\n\
            P(v) : { produce P(v * 2); }\nA(x) : { produce A(f(x)); }\n";
        assert_eq!(compiles(text), vec![false, false]);
        both(text);
    }

    #[test]
    fn single_precision_rounding() {
        // float: each product rounded to single precision, as C does:
        // 0.1 is a double constant, l * 0.1 in double, then stored into
        // the float parameter.
        let text = "module A(float);\nderivation length: 1;\nAxiom: A(3);\n\
            A(l) : { float t = l * 0.1; produce A(t + 1e-9); }\n";
        assert_eq!(compiles(text), vec![true]);
        let t = (3.0f64 * 0.1) as f32 as f64;
        let want = (t + 1e-9) as f32 as f64;
        assert_eq!(params(text), vec![want]);
    }

    #[test]
    fn float_to_int_and_int_arithmetic() {
        // C truncates toward zero; 7 / 2 is 3, -7 / 2 is -3, -7 % 2 is -1.
        let text = "module A(int, int, int, int);\nderivation length: 1;\nAxiom: A(0, 0, 0, 0);\n\
            A(a, b, c, d) : { int k = 2.7; int m = -2.7; produce A(k, m, 7 / 2 + -7 / 2, -7 % 2); }\n";
        assert_eq!(compiles(text), vec![true]);
        let got: Vec<i64> = params(text).iter().map(|x| x.to_bits() as i64).collect();
        assert_eq!(got, vec![2, -2, 0, -1]);
    }

    #[test]
    fn mixed_int_and_float_operands() {
        // C's usual conversions: 7 / 2 is 3 (both int), 7 / 2.0 is 3.5,
        // 7 * 0.5 is 3.5, 0.5 < 7 is true (1 in a float parameter);
        // 0.1 + 0.2 in double is 0.30000000000000004, then rounded to
        // single precision by the float parameter.
        let text = "module A(float, float, float, float, float); module B(int, float);\n\
            derivation length: 1;\nAxiom: B(7, 0.5);\n\
            B(n, x) : { double d = 0.1; produce A(n / 2, n / 2.0, n * x, x < n, d + 0.2); }\n";
        assert_eq!(compiles(text), vec![true]);
        let sum = (0.1f64 + 0.2) as f32 as f64;
        assert_eq!(params(text), vec![3.0, 3.5, 3.5, 1.0, sum]);
    }

    #[test]
    fn random_numbers_in_bodies() {
        // The generators advance in the same order, compiled or not: the
        // words are equal to the bit (their values are checked against
        // lpfg's in tests/it/random.rs), and two modules drew different
        // numbers.
        let text = "module A(float, int);\nderivation length: 3;\nAxiom: A(0, 0) A(0, 0);\n\
            A(x, n) : { if (ran(1) < 2) produce A(x + ran(2), rand() % 1000 + n) A(drand48(), lrand48() % 7); }\n";
        assert_eq!(compiles(text), vec![true]);
        let p = params(text);
        assert_eq!(p.len(), 32);
        assert_ne!(p[0], p[2]);
    }

    #[test]
    fn integer_division_by_zero_is_the_same_error() {
        let text = "module A(int);\nderivation length: 1;\nAxiom: A(0);\n\
            A(n) : { produce A(1 / n); }\n";
        assert_eq!(compiles(text), vec![true]);
        let out = both(text);
        assert!(out.contains("integer division by zero"), "{out}");
        // `x /= 0` reports the same message (and no span, as interpreted).
        let text = "module A(int);\nderivation length: 1;\nAxiom: A(0);\n\
            A(n) : { int k = 5; k /= n; produce A(k); }\n";
        assert_eq!(compiles(text), vec![true]);
        assert!(both(text).contains("integer division by zero"));
    }

    #[test]
    fn short_circuit_and_conditional() {
        // The right operand of `||` (`&&`) is not evaluated when the left
        // one decides: no division by zero here.
        let text = "module A(int, int);\nderivation length: 1;\nAxiom: A(1, 0);\n\
            A(x, z) : { int a = x > 0 || 1 / z > 0; int b = x < 0 && 1 / z > 0; \
            produce A(a ? 10 : 1 / z, b ? 1 / z : 20); }\n";
        assert_eq!(compiles(text), vec![true]);
        let got: Vec<i64> = params(text).iter().map(|x| x.to_bits() as i64).collect();
        assert_eq!(got, vec![10, 20]);
    }

    #[test]
    fn loops_with_break_and_continue() {
        // Sum of the odd i below 10 until i reaches 7: 1 + 3 + 5 = 9; the
        // do-while runs its body once even though its condition is false.
        let text = "module A(int, int);\nderivation length: 1;\nAxiom: A(0, 0);\n\
            A(a, b) : { int s = 0; int i; for (i = 0; i < 10; i++) { if (i % 2 == 0) continue; \
            if (i >= 7) break; s += i; } int n = 0; do { n++; } while (n > 5); \
            int w = 0; while (w < 4) w = w + 1; produce A(s, n * 100 + w); }\n";
        assert_eq!(compiles(text), vec![true]);
        let got: Vec<i64> = params(text).iter().map(|x| x.to_bits() as i64).collect();
        assert_eq!(got, vec![9, 104]);
    }

    #[test]
    fn loop_limit_and_non_finite_successors() {
        // A loop that never ends stops at the limit with the same message
        // and place as interpreted.
        let text = "module A(int);\nderivation length: 1;\nAxiom: A(0);\n\
            A(n) : { int i = 0; while (n == 0) { i++; } produce A(i); }\n";
        assert_eq!(compiles(text), vec![true]);
        let out = both(text);
        assert!(
            out.contains("a loop ran more than 10000000 iterations"),
            "{out}"
        );
        // NaN in a successor: the same message naming the parameter.
        let text = "module A(float, float);\nderivation length: 1;\nAxiom: A(0, 1);\n\
            A(x, y) : { produce A(y, x / x); }\n";
        assert_eq!(compiles(text), vec![true]);
        let out = both(text);
        assert!(
            out.contains("parameter 2 of this successor module is NaN"),
            "{out}"
        );
    }

    #[test]
    fn deadline_stops_a_compiled_loop() {
        let text = "module A(int);\nderivation length: 1;\nAxiom: A(0);\n\
            A(n) : { int i = 0; while (n == 0) { i++; } produce A(i); }\n";
        let curve = crate::load_str("t.lsys", text, &[]).expect("loads");
        assert!(compile(&curve.program.rules[0], &curve.program.globals).is_some());
        let opts = DeriveOptions {
            deadline: Some(crate::Deadline::after(std::time::Duration::from_millis(1))),
            ..DeriveOptions::default()
        };
        let e = curve.derive(opts).expect_err("times out").to_string();
        assert!(e.contains("time limit"), "{e}");
    }

    /// Every program of `lsystems/` and of the test data that loads as a
    /// curve derives to the same word, to the bit, with and without
    /// compiled bodies (or fails with the same message).
    #[test]
    fn corpus_same_with_and_without() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = Vec::new();
        fn walk(d: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
            let Ok(rd) = std::fs::read_dir(d) else { return };
            for e in rd.flatten() {
                let p = e.path();
                if p.is_dir() {
                    walk(&p, out);
                } else if p.extension().is_some_and(|x| x == "lsys" || x == "l") {
                    out.push(p);
                }
            }
        }
        walk(&root.join("lsystems"), &mut files);
        walk(&root.join("tests/data"), &mut files);
        files.sort();
        let (mut programs, mut compiled, mut rules) = (0, 0, 0);
        for f in &files {
            let mut run = |on: bool| -> Option<String> {
                set_enabled(on);
                let curve = crate::load_file(f, &[]);
                let out = curve.ok().map(|c| {
                    if on {
                        rules += c.program.rules.len();
                        compiled += c
                            .program
                            .rules
                            .iter()
                            .filter(|r| compile(r, &c.program.globals).is_some())
                            .count();
                    }
                    let opts = DeriveOptions {
                        max_modules: 200_000,
                        deadline: Some(crate::Deadline::after(std::time::Duration::from_secs(5))),
                        ..DeriveOptions::default()
                    };
                    match c.run(opts) {
                        Ok(mut r) => {
                            let i = r.interpreted().map(|w| word_bits(&w));
                            format!(
                                "{}\n{:?}",
                                word_bits(r.word()),
                                i.map_err(|e| e.to_string())
                            )
                        }
                        Err(e) => format!("error: {e}"),
                    }
                });
                set_enabled(true);
                out
            };
            let on = run(true);
            let off = run(false);
            let timed_out =
                |s: &Option<String>| s.as_ref().is_some_and(|s| s.contains("time limit"));
            if on.is_some() && !timed_out(&on) && !timed_out(&off) {
                programs += 1;
                assert_eq!(on, off, "{}", f.display());
            }
        }
        // The corpus has curves and plants whose bodies compile.
        eprintln!("{programs} programs compared, {compiled} of {rules} bodies compiled");
        assert!(programs > 60, "{programs} programs compared");
        assert!(compiled > 20, "{compiled} bodies compiled");
    }

    /// A small deterministic generator (splitmix64) for the random programs.
    struct Gen(u64);

    impl Gen {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
        fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
            xs[self.below(xs.len())]
        }
    }

    /// Names a body may read (with their types) and write.
    struct Scope {
        read: Vec<(String, &'static str)>,
        write: Vec<(String, &'static str)>,
        counters: Vec<String>,
        depth: usize,
        in_loop: bool,
        /// Only what compiles: no writes to `bool`s, `?:` of one kind, no
        /// side effects in the right-hand side of `x op= e`.
        friendly: bool,
        /// No side effects at all (the right-hand side of `x op= e`).
        pure: bool,
    }

    const NUMBERS: &[&str] = &[
        "0",
        "1",
        "2",
        "3",
        "-1",
        "-7",
        "7",
        "0.5",
        "0.1",
        "2.5",
        "-2.5",
        "1e30",
        "1e-30",
        "3.0",
        "16777217",
        "9007199254740993",
        "0.3333333",
        "1e300",
        "2147483647",
    ];

    fn gen_expr(g: &mut Gen, sc: &mut Scope, depth: usize) -> String {
        if depth == 0 || g.below(4) == 0 {
            return if g.below(2) == 0 && !sc.read.is_empty() {
                let i = g.below(sc.read.len());
                sc.read[i].0.clone()
            } else {
                g.pick(NUMBERS).to_string()
            };
        }
        let d = depth - 1;
        match g.below(16) {
            0..=3 => {
                let op = g.pick(&["+", "-", "*", "/", "%", "<", "<=", ">", ">=", "==", "!="]);
                let (a, b) = (gen_expr(g, sc, d), gen_expr(g, sc, d));
                format!("({a} {op} {b})")
            }
            4 => {
                let op = g.pick(&["&&", "||"]);
                let (a, b) = (gen_expr(g, sc, d), gen_side(g, sc, d));
                format!("({a} {op} {b})")
            }
            5 => {
                let (c, a, b) = (gen_expr(g, sc, d), gen_expr(g, sc, d), gen_expr(g, sc, d));
                if sc.friendly {
                    let t = g.pick(&["int", "double"]);
                    format!("({c} ? (({t}) {a}) : (({t}) {b}))")
                } else {
                    format!("({c} ? {a} : {b})")
                }
            }
            6 => format!("(-{})", gen_expr(g, sc, d)),
            7 => format!("(!{})", gen_expr(g, sc, d)),
            8 => {
                let f = g.pick(&[
                    "sin", "cos", "floor", "ceil", "fabs", "sqrt", "exp", "log", "atan", "tan",
                ]);
                format!("{f}({})", gen_expr(g, sc, d))
            }
            9 => {
                let f = g.pick(&["pow", "atan2", "fmod", "min", "max"]);
                format!("{f}({}, {})", gen_expr(g, sc, d), gen_expr(g, sc, d))
            }
            10 => format!("abs({})", gen_expr(g, sc, d)),
            11 => {
                let t = g.pick(&["int", "float", "double"]);
                format!("(({t}) {})", gen_expr(g, sc, d))
            }
            12 => g
                .pick(&["ran(1)", "ran(3)", "(rand() % 5)", "drand48()"])
                .to_string(),
            _ => gen_side(g, sc, d),
        }
    }

    /// An expression that writes a variable.
    fn gen_side(g: &mut Gen, sc: &mut Scope, depth: usize) -> String {
        let writable: Vec<String> = sc
            .write
            .iter()
            .filter(|(_, t)| !(sc.friendly && *t == "bool"))
            .map(|(n, _)| n.clone())
            .collect();
        if writable.is_empty() || sc.pure {
            return gen_expr(g, sc, depth.saturating_sub(1));
        }
        let v = writable[g.below(writable.len())].clone();
        match g.below(6) {
            0 => format!("({v}++)"),
            1 => format!("(--{v})"),
            2 => format!("({v}--)"),
            3 => format!("(++{v})"),
            _ => {
                let op = g.pick(&["=", "+=", "-=", "*=", "/=", "%="]);
                let was = sc.pure;
                sc.pure = sc.friendly && op != "=";
                let e = gen_expr(g, sc, depth.saturating_sub(1));
                sc.pure = was;
                format!("({v} {op} {e})")
            }
        }
    }

    fn gen_stmt(g: &mut Gen, sc: &mut Scope, out: &mut String, succ: &[(&str, usize)]) {
        let d = 3;
        let deep = sc.depth < 3;
        match g.below(14) {
            0..=3 => {
                let s = gen_side(g, sc, d);
                out.push_str(&format!("{s}; "));
            }
            4 | 5 if deep => {
                let c = gen_expr(g, sc, d);
                out.push_str(&format!("if ({c}) {{ "));
                sc.depth += 1;
                gen_stmt(g, sc, out, succ);
                if g.below(2) == 0 {
                    out.push_str("} else { ");
                    gen_stmt(g, sc, out, succ);
                }
                sc.depth -= 1;
                out.push_str("} ");
            }
            6 | 7 if deep && sc.counters.len() > sc.depth => {
                let k = sc.counters[sc.depth].clone();
                let n = g.below(5);
                let was = sc.in_loop;
                sc.in_loop = true;
                sc.depth += 1;
                match g.below(3) {
                    0 => out.push_str(&format!("for ({k} = 0; {k} < {n}; {k}++) {{ ")),
                    1 => out.push_str(&format!("{k} = 0; while ({k} < {n}) {{ {k}++; ")),
                    _ => out.push_str(&format!("{k} = 0; do {{ {k} += 1; ")),
                }
                let close = if out.ends_with("+= 1; ") {
                    format!("}} while ({k} < {n}); ")
                } else {
                    "} ".to_string()
                };
                for _ in 0..1 + g.below(3) {
                    gen_stmt(g, sc, out, succ);
                }
                out.push_str(&close);
                sc.depth -= 1;
                sc.in_loop = was;
            }
            8 if sc.in_loop => {
                let c = gen_expr(g, sc, 2);
                let what = g.pick(&["break", "continue"]);
                out.push_str(&format!("if ({c}) {what}; "));
            }
            9 | 10 => {
                let c = gen_expr(g, sc, 2);
                let verb = g.pick(&["produce", "produce", "nproduce"]);
                out.push_str(&format!("if ({c}) {verb}"));
                for _ in 0..1 + g.below(3) {
                    let (name, n) = succ[g.below(succ.len())];
                    let args: Vec<String> = (0..n).map(|_| gen_expr(g, sc, 2)).collect();
                    out.push_str(&format!(" {name}({})", args.join(", ")));
                }
                out.push_str("; ");
            }
            11 if g.below(3) == 0 => out.push_str("return; "),
            _ => {
                let s = gen_side(g, sc, d);
                out.push_str(&format!("{s}; "));
            }
        }
    }

    /// A random program over int, float, double and bool: globals, modules
    /// with parameters of each type, several productions per module (with
    /// and without context) whose bodies may not produce, loops, side
    /// effects in `&&`, `||` and `?:`.
    fn gen_program(seed: u64) -> String {
        let mut g = Gen(seed);
        let friendly = seed.is_multiple_of(2);
        let mut p = String::from(
            "module A(float, int); module B(int, double, bool);\n\
             int gi = 3; float gf = 0.5; double gd = 1.25; bool gb = true;\n\
             derivation length: 3;\n\
             Axiom: A(1.5, 3) B(-7, 2.25, true) A(-0.5, -2) B(0, 0.1, false);\n",
        );
        // Control statements (interpreted) that seed the generators and
        // change the globals the bodies read.
        if g.below(2) == 0 {
            let backward = if g.below(2) == 0 { "Backward(); " } else { "" };
            p.push_str(&format!(
                "Start: {{ {backward}srand({}); gi = {}; }}\n",
                g.below(9),
                g.below(5)
            ));
        }
        if g.below(2) == 0 {
            p.push_str(
                "StartEach: { gd = gd * 0.5 + gi; gf += 0.25; }\nEndEach: { gi = gi % 7; }\n",
            );
        }
        let globals = [
            ("gi", "int"),
            ("gf", "float"),
            ("gd", "double"),
            ("gb", "bool"),
        ];
        let succ = [("A", 2), ("B", 3)];
        for _ in 0..2 + g.below(3) {
            let (head, params): (&str, Vec<(&str, &str)>) = match g.below(4) {
                0 => ("A(x, n)", vec![("x", "float"), ("n", "int")]),
                1 => (
                    "B(m, d, b)",
                    vec![("m", "int"), ("d", "double"), ("b", "bool")],
                ),
                2 => (
                    "A(x, n) > B(m, d, b)",
                    vec![
                        ("x", "float"),
                        ("n", "int"),
                        ("m", "int"),
                        ("d", "double"),
                        ("b", "bool"),
                    ],
                ),
                _ => (
                    "B(m, d, b) < A(x, n)",
                    vec![
                        ("m", "int"),
                        ("d", "double"),
                        ("b", "bool"),
                        ("x", "float"),
                        ("n", "int"),
                    ],
                ),
            };
            let mut sc = Scope {
                read: Vec::new(),
                write: Vec::new(),
                counters: vec!["k0".into(), "k1".into(), "k2".into()],
                depth: 0,
                in_loop: false,
                friendly,
                pure: false,
            };
            let mut body = String::from("int k0 = 0; int k1 = 0; int k2 = 0; ");
            for (n, t) in params.iter().chain(&globals) {
                sc.read.push((n.to_string(), t));
                sc.write.push((n.to_string(), t));
            }
            for (i, t) in ["int", "float", "double"].iter().enumerate() {
                if g.below(2) == 0 {
                    let e = gen_expr(&mut g, &mut sc, 2);
                    body.push_str(&format!("{t} l{i} = {e}; "));
                    sc.read.push((format!("l{i}"), t));
                    sc.write.push((format!("l{i}"), t));
                }
            }
            sc.read
                .extend(sc.counters.iter().map(|c| (c.clone(), "int")));
            for _ in 0..2 + g.below(5) {
                gen_stmt(&mut g, &mut sc, &mut body, &succ);
            }
            p.push_str(&format!("{head} : {{ {body}}}\n"));
        }
        p
    }

    /// Many random programs derive to the same word, to the bit, or fail
    /// with the same message, with and without compiled bodies.
    #[test]
    fn random_programs_same_with_and_without() {
        let (mut ok, mut errors, mut compiled_rules) = (0, 0, 0);
        for seed in 0..400u64 {
            let text = gen_program(seed);
            // With a small limit on the word: the same module is the one
            // that takes the word past it.
            let limit = 6 + seed as usize % 20;
            let (a, b) = (
                fingerprint_limited(&text, true, limit),
                fingerprint_limited(&text, false, limit),
            );
            assert_eq!(a, b, "seed {seed}, limit {limit}: differ on\n{text}");
            let on = fingerprint(&text, true);
            let off = fingerprint(&text, false);
            assert_eq!(
                on, off,
                "seed {seed}: compiled and interpreted differ on\n{text}"
            );
            if on.starts_with("error") {
                errors += 1;
            } else {
                ok += 1;
            }
            if let Ok(c) = crate::load_str("t.lsys", &text, &[]) {
                compiled_rules += c
                    .program
                    .rules
                    .iter()
                    .filter(|r| compile(r, &c.program.globals).is_some())
                    .count();
            }
        }
        eprintln!("{ok} derived, {errors} failed the same way, {compiled_rules} bodies compiled");
        // The comparison is not vacuous: most programs derive, and most
        // of the bodies of the programs that compile-friendly seeds make
        // run compiled (a run of these 400 seeds: 235 derived, 650 compiled).
        assert!(ok > 150, "{ok} programs derived");
        assert!(compiled_rules > 400, "{compiled_rules} bodies compiled");
    }
}
