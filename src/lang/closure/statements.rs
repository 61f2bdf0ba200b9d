//! Statements compiled to closures: blocks, `if` (with comparisons of
//! leaves made in place), loops with the interpreter's limit and deadline
//! checks, and `produce` with its successors' parameters.

use crate::syntax::ast::BinOp;
use crate::syntax::span::Span;

use crate::lang::eval::Flow;
use crate::lang::ir::{Ex, St};
use crate::lang::modules::Sym;
use crate::lang::value::Value;

use super::kinds::{kind_of, Kind, Leaf, C};
use super::{rt, Compiler, Cx, DEADLINE_EVERY, R, SE};

impl Compiler<'_> {
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

    pub(super) fn block(&mut self, body: &[St]) -> Option<SE> {
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
