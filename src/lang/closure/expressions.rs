//! Expressions compiled to closures of their kind, with the kinds that
//! locals hold tracked per slot; leaves and fused binary operators that
//! save a call per operand.

use crate::syntax::ast::BinOp;
use crate::syntax::span::Span;

use crate::lang::ir::{Ex, Func};
use crate::lang::value::{round32, Ty, Value};

use super::kinds::{bin, convert, kind_of, read, read_global, value_of, Kind, Leaf, C};
use super::{Compiler, Cx, R};

impl Compiler<'_> {
    pub(super) fn write(&mut self, slot: u16, k: Kind) -> Option<usize> {
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
    pub(super) fn leaf(&self, e: &Ex) -> Option<Leaf> {
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

    pub(super) fn expr(&mut self, e: &Ex) -> Option<C> {
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
                        use crate::lang::random::Op;
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
