//! Calls of built-in functions: the library's (mathematics, vectors), the
//! topology's, and those of the run (groups, views, direction, random
//! numbers, the model, stdio, batch defaults).

use glam::DVec3;

use crate::syntax::span::Span;

use super::super::ir::*;
use super::super::value::Value;
use super::{rt, Cx, Interp, MAX_VIEWS, R};

impl<'p> Interp<'p> {
    #[inline(never)]
    pub(super) fn call(&mut self, f: Func, args: &[Ex], span: Span, cx: &mut Cx) -> R<Value> {
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
            Func::Io(f) => return super::super::stdio::call(f, vals, &cx.env.output),
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
