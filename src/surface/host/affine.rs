//! [`Affine`]: an assignment recognised as a weighted sum of points the
//! host gives, its weights computed once per distinct set of integers.

use glam::DVec3;

use crate::lang::eval::RuntimeError;
use crate::lang::ir::{Ex, Func};
use crate::lang::value::Value;
use crate::syntax::ast::BinOp;

use super::{id, Evaluate, Weights, MAX_KEY, MAX_MEMO, MAX_TERMS};

/// An assignment that is a weighted sum of points the host gives for the
/// rule's elements (`pos(v)`, `avg(e)`, a sum or average over a one-ring),
/// whose weights depend only on integers the host gives for the element
/// (its valence, a count over its ring) and on constants. Recognised in
/// the checked IR: the integers are computed for every element, the
/// weights by the interpreter once per distinct set of integers, and the
/// points summed. The same meaning as the expression it came from, as a
/// curve stencil is for its body; only the order of the floating-point
/// products may differ (`s / n` is `(1 / n) * s`).
#[derive(Clone, Debug)]
pub struct Affine {
    /// The locals the expression binds, in order, with their values and
    /// whether they read the element (else they are functions of the
    /// earlier ones and constants).
    lets: Vec<(u16, Ex, bool)>,
    /// Per point: its weight's factors (each a scalar expression, divided
    /// by when `true`), a constant factor, and the host built-in with its
    /// local and constant arguments.
    terms: Vec<Term>,
}

#[derive(Clone, Debug)]
struct Term {
    factors: Vec<(Ex, bool)>,
    scale: f64,
    f: u16,
    slot: u16,
    args: [i64; 2],
}

/// The built-ins that give a point for an element.
fn point_call(e: &Ex) -> Option<(u16, u16, [i64; 2])> {
    match e {
        Ex::Call(Func::Host(f @ (id::POS | id::AVG_OF)), args, _) => match args.as_slice() {
            [Ex::Local(s)] => Some((*f, *s, [0, 0])),
            _ => None,
        },
        Ex::Call(Func::Host(id::RING_FOLD), args, _) => match args.as_slice() {
            [Ex::Local(s), Ex::Const(Value::Int(fold @ (0 | 1))), Ex::Const(Value::Int(filter))] => {
                Some((id::RING_FOLD, *s, [*fold, *filter]))
            }
            _ => None,
        },
        _ => None,
    }
}

/// True when `e` is a scalar that reads no element: constants, locals
/// (the integers bound by the lets) and arithmetic on them.
fn scalar(e: &Ex) -> bool {
    let mut ok = true;
    e.walk(&mut |x| match x {
        Ex::Call(Func::Host(f), ..) if !matches!(*f, id::CURRENT | id::STEP) => ok = false,
        Ex::Global(_)
        | Ex::Assign(..)
        | Ex::IncDec(..)
        | Ex::InContext(..)
        | Ex::Fold { .. }
        | Ex::MakeV2(..)
        | Ex::MakeV3(..)
        | Ex::MakeStruct(..)
        | Ex::Call(Func::Random(_) | Func::UseGroup | Func::Stop, ..) => ok = false,
        _ => {}
    });
    ok
}

impl Affine {
    /// The weighted sum `e` is, if it is one.
    pub fn of(e: &Ex) -> Option<Affine> {
        let mut a = Affine {
            lets: Vec::new(),
            terms: Vec::new(),
        };
        a.collect(e, &mut Vec::new(), 1.0, &mut Vec::new())?;
        let keys = a.lets.iter().filter(|l| l.2).count();
        (keys <= MAX_KEY && a.terms.len() <= MAX_TERMS && a.in_order()).then_some(a)
    }

    /// True when evaluating the lets that read the element first, then
    /// the others, then the factors, gives each local the value the
    /// interpreter's order gives it. Not so when a let that reads the
    /// element reads one that does not (`h(v, valence(v) * a)` inside a
    /// function of `a`), nor when a factor or a let's value binds a local
    /// of its own (an inlined call, a fold) in a slot that one of the lets
    /// holds: sibling calls reuse slots.
    fn in_order(&self) -> bool {
        let held: Vec<u16> = self.lets.iter().map(|l| l.0).collect();
        let later: Vec<u16> = self.lets.iter().filter(|l| !l.2).map(|l| l.0).collect();
        let mut ok = true;
        for (_, a, reads) in &self.lets {
            a.walk(&mut |x| match x {
                Ex::Local(s) if *reads && later.contains(s) => ok = false,
                Ex::Let(s, ..) | Ex::Fold { slot: s, .. } if held.contains(s) => ok = false,
                _ => {}
            });
        }
        for t in &self.terms {
            for (x, _) in &t.factors {
                x.walk(&mut |x| match x {
                    Ex::Let(s, ..) | Ex::Fold { slot: s, .. } if held.contains(s) => ok = false,
                    _ => {}
                });
            }
        }
        ok
    }

    /// Adds the terms of `scale * factors * e`. `alias` maps the locals
    /// of inlined parameters bound to another local to that local, so
    /// that nothing needs copying per element.
    fn collect(
        &mut self,
        e: &Ex,
        factors: &mut Vec<(Ex, bool)>,
        scale: f64,
        alias: &mut Vec<(u16, u16)>,
    ) -> Option<()> {
        if let Some((f, slot, args)) = point_call(e) {
            self.terms.push(Term {
                factors: factors.clone(),
                scale,
                f,
                slot: resolve(slot, alias),
                args,
            });
            return Some(());
        }
        match e {
            Ex::Let(s, a, body) => {
                // Two calls side by side may reuse a slot; the weights are
                // evaluated after all the lets, so a slot bound twice is
                // left to the interpreter.
                if alias.iter().any(|(a, _)| a == s) {
                    return None;
                }
                if let Ex::Local(x) = **a {
                    alias.push((*s, resolve(x, alias)));
                } else {
                    // A let that reads the element is computed for every
                    // element; one that does not is a function of the
                    // others and of constants.
                    let reads = !scalar(a);
                    if reads && !integer_host(a) {
                        return None;
                    }
                    self.lets.push((*s, subst(a, alias), reads));
                    // The let's own slot is no alias any more.
                    alias.push((*s, *s));
                }
                self.collect(body, factors, scale, alias)
            }
            Ex::Bin(BinOp::Add, a, b, _) => {
                self.collect(a, factors, scale, alias)?;
                self.collect(b, factors, scale, alias)
            }
            Ex::Bin(BinOp::Sub, a, b, _) => {
                self.collect(a, factors, scale, alias)?;
                self.collect(b, factors, -scale, alias)
            }
            Ex::Neg(a) => self.collect(a, factors, -scale, alias),
            Ex::Bin(BinOp::Mul, a, b, _) => {
                let (k, x) = if scalar(a) {
                    (a, b)
                } else if scalar(b) {
                    (b, a)
                } else {
                    return None;
                };
                factors.push((subst(k, alias), false));
                let r = self.collect(x, factors, scale, alias);
                factors.pop();
                r
            }
            Ex::Bin(BinOp::Div, a, b, _) if scalar(b) => {
                factors.push((subst(b, alias), true));
                let r = self.collect(a, factors, scale, alias);
                factors.pop();
                r
            }
            _ => None,
        }
    }

    /// The point, with the rule's elements bound in the evaluator's frame;
    /// None where the weights are not numbers (the general path then says
    /// what they are).
    pub fn eval(&self, ev: &mut dyn Evaluate<'_>) -> Result<Option<Value>, RuntimeError> {
        let mut key = [0i64; MAX_KEY];
        let mut k = 0;
        for (s, a, reads) in &self.lets {
            if *reads {
                let v = ev.eval(a)?;
                // The whole value is the key: a let that reads the element
                // may be a float (`valence(v) / 8.0`) or a bool
                // (`valence(v) > 6`), and its type is the same for every
                // element. Anything else is left to the interpreter.
                key[k] = match v {
                    Value::Int(i) => i,
                    Value::Bool(b) => b as i64,
                    Value::Float(f) => f.to_bits() as i64,
                    _ => return Ok(None),
                };
                k += 1;
                ev.frame()[*s as usize] = v;
            }
        }
        let form = self as *const Affine as usize;
        let found = ev
            .memo()
            .weights
            .iter()
            .find(|w| w.form == form && w.key == key)
            .map(|w| w.w);
        let weights = match found {
            Some(w) => w,
            None => {
                // Every let that reads the element is in the key: the
                // weights below depend on the key alone.
                for (s, a, reads) in &self.lets {
                    if !*reads {
                        let v = ev.eval(a)?;
                        ev.frame()[*s as usize] = v;
                    }
                }
                let mut w = [0.0; MAX_TERMS];
                for (t, wt) in self.terms.iter().zip(w.iter_mut()) {
                    *wt = t.scale;
                    for (x, inverse) in &t.factors {
                        let k = match ev.eval(x)? {
                            Value::Int(i) => i as f64,
                            Value::Float(f) => f,
                            Value::Bool(b) => b as i64 as f64,
                            _ => return Ok(None),
                        };
                        *wt = if *inverse { *wt / k } else { *wt * k };
                    }
                }
                let memo = ev.memo();
                if memo.weights.len() < MAX_MEMO {
                    memo.weights.push(Weights { form, key, w });
                }
                w
            }
        };
        let host = ev.host();
        let frame = ev.frame();
        let mut p = DVec3::ZERO;
        for (t, w) in self.terms.iter().zip(weights) {
            match host.point(t.f, &frame[t.slot as usize], t.args) {
                Some(q) => p += w * q,
                None => return Ok(None),
            }
        }
        Ok(Some(Value::V3(p)))
    }
}

/// The local an alias stands for.
fn resolve(slot: u16, alias: &[(u16, u16)]) -> u16 {
    alias
        .iter()
        .rev()
        .find(|(a, _)| *a == slot)
        .map_or(slot, |(_, b)| *b)
}

/// `e` with aliased locals replaced by what they stand for; a let or a
/// fold inside `e` that binds a slot hides the alias of that slot.
fn subst(e: &Ex, alias: &[(u16, u16)]) -> Ex {
    let mut e = e.clone();
    rewrite(&mut e, &mut alias.to_vec());
    e
}

fn rewrite(e: &mut Ex, alias: &mut Vec<(u16, u16)>) {
    match e {
        Ex::Local(s) => *s = resolve(*s, alias),
        Ex::Let(s, a, body) => {
            rewrite(a, alias);
            alias.push((*s, *s));
            rewrite(body, alias);
            alias.pop();
        }
        Ex::Fold {
            slot,
            set,
            cond,
            value,
            ..
        } => {
            rewrite(set, alias);
            alias.push((*slot, *slot));
            if let Some(c) = cond {
                rewrite(c, alias);
            }
            if let Some((v, _)) = value {
                rewrite(v, alias);
            }
            alias.pop();
        }
        Ex::Field(a, _) | Ex::Neg(a) | Ex::Not(a) | Ex::Convert(_, a) => rewrite(a, alias),
        Ex::Assign(_, _, a, _) => rewrite(a, alias),
        Ex::Bin(_, a, b, _) | Ex::Logic(_, a, b) | Ex::MakeV2(a, b) => {
            rewrite(a, alias);
            rewrite(b, alias);
        }
        Ex::Cond(a, b, c) | Ex::MakeV3(a, b, c) => {
            rewrite(a, alias);
            rewrite(b, alias);
            rewrite(c, alias);
        }
        Ex::Call(_, args, _) | Ex::MakeStruct(args) => {
            args.iter_mut().for_each(|a| rewrite(a, alias))
        }
        // Arrays and user functions are not part of surface grammars.
        Ex::Const(_)
        | Ex::Global(_)
        | Ex::IncDec(..)
        | Ex::InContext(..)
        | Ex::Load(_)
        | Ex::Index(..)
        | Ex::CallUser { .. } => {}
    }
}

/// A let that reads an integer of the element: `valence(v)`, a count over
/// its ring, arithmetic on those.
fn integer_host(e: &Ex) -> bool {
    let mut ok = true;
    e.walk(&mut |x| match x {
        Ex::Call(Func::Host(id::RING_FOLD), args, _) => {
            if !matches!(args.get(1), Some(Ex::Const(Value::Int(2)))) {
                ok = false
            }
        }
        Ex::Call(Func::Host(f), ..) => {
            if !matches!(
                *f,
                id::VALENCE | id::LEVEL | id::CURRENT | id::STEP | id::CREASES
            ) {
                ok = false
            }
        }
        Ex::Const(_) | Ex::Local(_) | Ex::Bin(..) | Ex::Neg(_) | Ex::Convert(..) => {}
        _ => ok = false,
    });
    ok
}
