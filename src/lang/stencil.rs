//! Affine stencils: rules whose body is one `produce` of affine combinations
//! of the predecessor's parameters, such as every subdivision rule of paper
//! 002. The engine evaluates them as fixed weights, with no interpreter.

use crate::syntax::ast::BinOp;

use super::ir::{Ex, Rule, St};
use super::modules::Sym;
use super::value::{Ty, Value};

/// One term of a sum: `w * x`, `x / w`, or the constant `w`, negated when
/// `negate` (a unary minus), added or subtracted (`sub`) to what precedes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Term {
    /// `(k, off)`: the parameter at slot offset `off` of matched module `k`,
    /// modules counted over left context, strict predecessor, right context.
    /// `None` for a constant.
    pub source: Option<(u16, u16)>,
    pub w: f64,
    pub div: bool,
    pub negate: bool,
    pub sub: bool,
}

impl Term {
    /// The term's value for one component `x` of its source.
    #[inline(always)]
    pub fn apply(&self, x: f64) -> f64 {
        let v = match (self.source, self.div) {
            (None, _) => self.w,
            (Some(_), true) => x / self.w,
            (Some(_), false) => self.w * x,
        };
        if self.negate {
            -v
        } else {
            v
        }
    }
}

/// One output parameter: a sum of terms, evaluated left to right with
/// exactly the operations the interpreter would perform, so that the fast
/// path and the interpreter agree to the last bit.
#[derive(Clone, Debug, PartialEq)]
pub struct Combination {
    pub terms: Vec<Term>,
    pub ty: Ty,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Stencil {
    pub outputs: Vec<(Sym, Vec<Combination>)>,
}

/// A combination whose terms are all `±c * x`: `Σ w_k · x_k` added left to
/// right, with the signs folded into the weights. Folding is exact:
/// `a - c*x` equals `a + (-c)*x` and `-(c*x)` equals `(-c)*x` in IEEE
/// arithmetic.
#[derive(Clone, Debug, PartialEq)]
pub struct PlainCombination {
    pub ty: Ty,
    /// `(k, off, w)` as in [`Term`].
    pub terms: Vec<(u16, u16, f64)>,
}

impl Combination {
    /// The plain form, when every term is a weighted parameter.
    pub fn plain(&self) -> Option<PlainCombination> {
        let mut terms = Vec::with_capacity(self.terms.len());
        for (n, t) in self.terms.iter().enumerate() {
            let (k, off) = t.source?;
            if t.div {
                return None;
            }
            let sign = if t.negate != (t.sub && n > 0) {
                -1.0
            } else {
                1.0
            };
            terms.push((k, off, sign * t.w));
        }
        Some(PlainCombination { ty: self.ty, terms })
    }
}

/// The value of a constant expression, computed with the interpreter's own
/// operations.
fn constant(e: &Ex) -> Option<Value> {
    match e {
        Ex::Const(v @ (Value::Int(_) | Value::Float(_))) => Some(v.clone()),
        Ex::Neg(a) => match constant(a)? {
            Value::Int(i) => Some(Value::Int(i.wrapping_neg())),
            Value::Float(f) => Some(Value::Float(-f)),
            _ => None,
        },
        Ex::Convert(t @ (Ty::Int | Ty::Float | Ty::Double), a) => Some(constant(a)?.convert(*t)),
        Ex::Bin(op @ (BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div), a, b, _) => {
            super::eval::binary(*op, constant(a)?, constant(b)?).ok()
        }
        _ => None,
    }
}

/// A local slot of a float or vector pattern parameter.
fn slot(e: &Ex, slot_ty: &[Ty]) -> Option<u16> {
    match e {
        Ex::Local(s)
            if slot_ty
                .get(*s as usize)
                .is_some_and(|t| t.is_floating() || t.is_vector()) =>
        {
            Some(*s)
        }
        _ => None,
    }
}

/// The operation under a single-precision rounding: the checker wraps every
/// `float`, `V2f` and `V3f` product, quotient and sum in a conversion to its
/// own type, and the stencil rounds each of them in the same places
/// (`Combination::ty` says whether it is single precision).
fn unrounded(e: &Ex) -> &Ex {
    match e {
        Ex::Convert(t, a) if t.is_single() && matches!(**a, Ex::Bin(..)) => a,
        _ => e,
    }
}

/// A slot under any number of unary minuses: `x`, `-x`, `--x`. Negation
/// commutes exactly with multiplication and division by a constant.
fn signed_slot(e: &Ex, slot_ty: &[Ty]) -> Option<(u16, bool)> {
    match e {
        Ex::Neg(a) => signed_slot(a, slot_ty).map(|(s, n)| (s, !n)),
        _ => slot(e, slot_ty).map(|s| (s, false)),
    }
}

/// A term: `x`, `c*x`, `x*c`, `x/c`, `c`, `-term`. Slots are local slots
/// here; `compile` maps them to matched modules.
fn term(e: &Ex, slot_ty: &[Ty]) -> Option<(Option<u16>, f64, bool, bool)> {
    let e = unrounded(e);
    if let Some(c) = constant(e) {
        return Some((None, c.as_f64(), false, false));
    }
    if let Some(s) = slot(e, slot_ty) {
        return Some((Some(s), 1.0, false, false));
    }
    match e {
        Ex::Neg(a) => {
            let (s, w, div, neg) = term(a, slot_ty)?;
            Some((s, w, div, !neg))
        }
        Ex::Bin(BinOp::Mul, a, b, _) => match (
            constant(a),
            signed_slot(b, slot_ty),
            signed_slot(a, slot_ty),
            constant(b),
        ) {
            (Some(c), Some((s, n)), _, _) | (_, _, Some((s, n)), Some(c)) => {
                Some((Some(s), c.as_f64(), false, n))
            }
            _ => None,
        },
        Ex::Bin(BinOp::Div, a, b, _) => {
            let c = constant(b)?.as_f64();
            let (s, n) = signed_slot(a, slot_ty)?;
            Some((Some(s), c, true, n))
        }
        _ => None,
    }
}

/// A sum `term (+|- term)*`, left-associated as the parser builds it.
fn sum(e: &Ex, slot_ty: &[Ty], out: &mut Vec<(Option<u16>, f64, bool, bool, bool)>) -> Option<()> {
    let e = unrounded(e);
    if constant(e).is_none() {
        if let Ex::Bin(op @ (BinOp::Add | BinOp::Sub), a, b, _) = e {
            sum(a, slot_ty, out)?;
            let (s, w, div, neg) = term(b, slot_ty)?;
            out.push((s, w, div, neg, *op == BinOp::Sub));
            return Some(());
        }
    }
    let (s, w, div, neg) = term(e, slot_ty)?;
    out.push((s, w, div, neg, false));
    Some(())
}

/// The slots an output of type `ty` fills: its components.
fn slots_of(ty: Ty) -> usize {
    ty.dim().max(1)
}

impl Combination {
    /// The slots this output fills.
    pub fn slots(&self) -> usize {
        slots_of(self.ty)
    }
}

impl PlainCombination {
    /// The slots this output fills.
    pub fn slots(&self) -> usize {
        slots_of(self.ty)
    }
}

impl Stencil {
    /// The slots of the whole successor: every output's components.
    pub fn slot_count(&self) -> usize {
        self.outputs
            .iter()
            .flat_map(|(_, cs)| cs.iter().map(Combination::slots))
            .sum()
    }

    /// Compiles `rule` to a stencil when its body allows it.
    pub fn compile(rule: &Rule) -> Option<Stencil> {
        if !rule.new_left.is_empty() || !rule.new_right.is_empty() {
            return None;
        }
        let modules = match rule.body.as_slice() {
            [St::Produce {
                modules,
                last: true,
            }] => modules,
            _ => return None,
        };
        // Locals are the pattern parameters, allocated in order.
        let mut sources = Vec::new();
        let pats = rule.left.iter().chain(&rule.strict).chain(&rule.right);
        for (k, p) in pats.enumerate() {
            let mut off = 0u16;
            for (slot, ty) in p.slots.iter().zip(&p.types) {
                if *slot as usize != sources.len() {
                    return None;
                }
                sources.push((k as u16, off));
                off += match ty {
                    t if t.is_vector() => t.dim() as u16,
                    Ty::Int | Ty::Float | Ty::Double | Ty::Bool => 1,
                    // Struct widths need the struct table; keep it simple.
                    _ => return None,
                };
            }
        }
        if sources.len() != rule.frame_size {
            return None;
        }
        // Slot types: recovered from the successor expressions is not
        // possible, so only plain float/vector slots used consistently pass.
        let slot_ty = slot_types(rule);
        let mut outputs = Vec::new();
        for m in modules {
            let mut combos = Vec::new();
            for (a, want) in m.args.iter().zip(&m.types) {
                let mut raw = Vec::new();
                sum(a, &slot_ty, &mut raw)?;
                // The result type: the type of the slots in the sum, all
                // equal; a vector sum may not add scalar constants.
                let mut ty = None;
                for (s, ..) in &raw {
                    let t = match s {
                        Some(s) => slot_ty[*s as usize],
                        None => Ty::Float,
                    };
                    if ty.is_some_and(|u| u != t) {
                        return None;
                    }
                    ty = Some(t);
                }
                let ty = ty?;
                if ty != *want {
                    return None;
                }
                let terms = raw
                    .iter()
                    .map(|&(s, w, div, negate, sub)| Term {
                        source: s.map(|s| sources[s as usize]),
                        w,
                        div,
                        negate,
                        sub,
                    })
                    .collect();
                combos.push(Combination { terms, ty });
            }
            outputs.push((m.sym, combos));
        }
        Some(Stencil { outputs })
    }
}

/// The declared type of each pattern slot, from the patterns' symbols.
fn slot_types(rule: &Rule) -> Vec<Ty> {
    let mut tys = vec![Ty::Void; rule.frame_size];
    for p in rule.left.iter().chain(&rule.strict).chain(&rule.right) {
        for (j, s) in p.slots.iter().enumerate() {
            if let Some(t) = p.types.get(j) {
                tys[*s as usize] = *t;
            }
        }
    }
    tys
}
