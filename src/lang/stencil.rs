//! Affine stencils: rules whose body is one `produce` of affine combinations
//! of the predecessor's parameters, such as every subdivision rule of paper
//! 002. The engine evaluates them as fixed weights, with no interpreter.

use crate::syntax::ast::BinOp;

use super::ir::{Ex, Rule, St};
use super::modules::Sym;
use super::value::{Ty, Value};

/// One output parameter: `constant + Σ weight · (the parameter at slot
/// offset `off` of matched module `k`)`, componentwise for vectors.
#[derive(Clone, Debug, PartialEq)]
pub struct Combination {
    /// `(k, off, weight)`, with modules counted over left context, strict
    /// predecessor, right context.
    pub terms: Vec<(u16, u16, f64)>,
    pub constant: f64,
    pub ty: Ty,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Stencil {
    pub outputs: Vec<(Sym, Vec<Combination>)>,
}

/// An affine form over local slots, with a scalar constant.
#[derive(Clone, Debug, Default)]
struct Affine {
    terms: Vec<(u16, f64)>,
    constant: f64,
}

impl Affine {
    fn scale(mut self, s: f64) -> Affine {
        for t in &mut self.terms {
            t.1 *= s;
        }
        self.constant *= s;
        self
    }

    fn add(mut self, other: Affine, sign: f64) -> Affine {
        for (slot, w) in other.terms {
            match self.terms.iter_mut().find(|t| t.0 == slot) {
                Some(t) => t.1 += sign * w,
                None => self.terms.push((slot, sign * w)),
            }
        }
        self.constant += sign * other.constant;
        self
    }

    fn constant(&self) -> Option<f64> {
        self.terms.is_empty().then_some(self.constant)
    }
}

fn affine(e: &Ex, slot_ty: &[Ty]) -> Option<Affine> {
    match e {
        Ex::Const(Value::Int(i)) => Some(Affine {
            terms: vec![],
            constant: *i as f64,
        }),
        Ex::Const(Value::Float(f)) => Some(Affine {
            terms: vec![],
            constant: *f,
        }),
        Ex::Local(s) => {
            let ty = *slot_ty.get(*s as usize)?;
            matches!(ty, Ty::Float | Ty::V2 | Ty::V3).then(|| Affine {
                terms: vec![(*s, 1.0)],
                constant: 0.0,
            })
        }
        Ex::Convert(Ty::Float, a) => {
            let a = affine(a, slot_ty)?;
            a.constant().map(|c| Affine {
                terms: vec![],
                constant: c,
            })
        }
        Ex::Neg(a) => Some(affine(a, slot_ty)?.scale(-1.0)),
        Ex::Bin(op, a, b) => {
            let (x, y) = (affine(a, slot_ty)?, affine(b, slot_ty)?);
            match op {
                BinOp::Add => Some(x.add(y, 1.0)),
                BinOp::Sub => Some(x.add(y, -1.0)),
                BinOp::Mul => match (x.constant(), y.constant()) {
                    (Some(c), _) => Some(y.scale(c)),
                    (_, Some(c)) => Some(x.scale(c)),
                    _ => None,
                },
                BinOp::Div => y.constant().filter(|c| *c != 0.0).map(|c| x.scale(1.0 / c)),
                _ => None,
            }
        }
        _ => None,
    }
}

impl Stencil {
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
                    Ty::V2 => 2,
                    Ty::V3 => 3,
                    Ty::Int | Ty::Float | Ty::Bool => 1,
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
            for a in &m.args {
                let (ex, ty) = match a {
                    Ex::Convert(t, inner) => (inner.as_ref(), *t),
                    other => (other, Ty::Void),
                };
                let aff = affine(ex, &slot_ty)?;
                // The result type is the type of its slot terms (all equal).
                let term_ty = aff.terms.iter().map(|(s, _)| slot_ty[*s as usize]).fold(
                    None,
                    |acc: Option<Ty>, t| match acc {
                        None => Some(t),
                        Some(a) if a == t => Some(a),
                        Some(_) => Some(Ty::Void),
                    },
                );
                let ty = match (term_ty, ty) {
                    (Some(Ty::Void), _) => return None,
                    (Some(t @ (Ty::V2 | Ty::V3)), _) => {
                        if aff.constant != 0.0 {
                            return None;
                        }
                        t
                    }
                    (Some(Ty::Float), Ty::Void | Ty::Float) | (None, Ty::Float) => Ty::Float,
                    _ => return None,
                };
                let terms = aff
                    .terms
                    .iter()
                    .map(|&(slot, w)| {
                        let (k, j) = sources[slot as usize];
                        (k, j, w)
                    })
                    .collect();
                combos.push(Combination {
                    terms,
                    constant: aff.constant,
                    ty,
                });
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
