//! Expressions: the common ones, the rare ones, arrays and calls, folds
//! over a set's members, and the fields and characters they read.

use glam::{DVec2, DVec3};

use crate::syntax::ast::BinOp;
use crate::syntax::span::Span;

use super::super::ir::*;
use super::super::value::{Ty, Value};
use super::operators::{binary, float_binary};
use super::{rt, Cx, Interp, RuntimeError, R};

impl<'p> Interp<'p> {
    pub(super) fn expr(&mut self, e: &Ex, cx: &mut Cx) -> R<Value> {
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
}

pub(super) fn field(v: &Value, i: u16) -> Value {
    match v {
        Value::V2(p) => Value::Float(p[i as usize]),
        Value::V3(p) => Value::Float(p[i as usize]),
        Value::Struct(fs) => fs[i as usize].clone(),
        _ => Value::Void,
    }
}

/// An index out of an array's range, as a run-time error.
pub(super) fn out_of_range(i: i64, len: usize, span: Span) -> Box<RuntimeError> {
    rt(
        Some(span),
        format!(
            "index {i} is out of range: the array has {len} element(s), indices 0 to {}",
            len as i64 - 1
        ),
    )
}

/// Character `i` of a string, as C reads a `char` array (0 at the end).
pub(super) fn char_at(s: &str, i: i64, span: Span) -> R<Value> {
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
