//! Types: type names, `float`'s precision, C's conversions, and the
//! result types of operators.

use crate::syntax::ast::{self, BinOp};
use crate::syntax::span::Span;

use crate::lang::ir::Ex;
use crate::lang::value::Ty;

use super::constants::fold_unary;
use super::Compiler;

impl Compiler {
    /// A type as this program computes it: without single precision,
    /// `float`, `V2f` and `V3f` are `double`, `V2d` and `V3d`.
    pub(super) fn prec(&self, ty: Ty) -> Ty {
        if self.single {
            ty
        } else {
            ty.widened()
        }
    }

    /// A value of single-precision type `ty` rounded as C rounds the
    /// result of `float` arithmetic or a conversion to `float`; values of
    /// other types are left as they are.
    pub(super) fn round(&self, ex: Ex, ty: Ty) -> Ex {
        if ty.is_single() {
            fold_unary(Ex::Convert(ty, Box::new(ex)))
        } else {
            ex
        }
    }

    /// An element in arithmetic reads as its value (a mesh vertex as its
    /// position); anything else is left as it is.
    pub(super) fn arith(&self, ex: Ex, ty: Ty, span: Span) -> (Ex, Ty) {
        if let Ty::Elem(k) = ty {
            if let Some((f, t)) = (self.host.arith)(k) {
                return (Ex::Call(f, vec![ex], span), self.prec(t));
            }
        }
        (ex, ty)
    }

    /// A checked expression used as a condition.
    pub(super) fn condition_of(&mut self, ex: Ex, ty: Ty, span: Span) -> Option<Ex> {
        if !ty.is_numeric() {
            self.err(
                span,
                format!(
                    "expected a condition (a number or bool), found {}",
                    self.type_name(ty)
                ),
            );
            return None;
        }
        Some(ex)
    }

    pub(super) fn type_name(&self, ty: Ty) -> String {
        match ty {
            Ty::Int => "int".into(),
            Ty::Float => "float".into(),
            Ty::Double => "double".into(),
            Ty::Bool => "bool".into(),
            Ty::V2 => "V2f".into(),
            Ty::V3 => "V3f".into(),
            Ty::V2d => "V2d".into(),
            Ty::V3d => "V3d".into(),
            Ty::Struct(i) => self.structs[i as usize].name.clone(),
            Ty::Str => "string".into(),
            Ty::Void => "void".into(),
            Ty::Elem(k) => self.host.element_name(k).into(),
        }
    }

    pub(super) fn resolve_type(&mut self, t: &ast::TypeRef) -> Option<Ty> {
        let ty = match t.name.as_str() {
            // `char *s` is a string; a `FILE *` is a handle, an int.
            "char" if t.pointer => Ty::Str,
            "int" | "long" | "unsigned" | "short" | "signed" | "char" | "size_t" | "FILE" => {
                Ty::Int
            }
            "float" => self.prec(Ty::Float),
            "double" => Ty::Double,
            "bool" => Ty::Bool,
            "V2f" => self.prec(Ty::V2),
            "V3f" => self.prec(Ty::V3),
            "V2d" => Ty::V2d,
            "V3d" => Ty::V3d,
            "void" => Ty::Void,
            other => {
                if let Some(&(_, k)) = self.host.types.iter().find(|(n, _)| *n == other) {
                    Ty::Elem(k)
                } else if let Some(t) = self.typedefs.get(other) {
                    *t
                } else if let Some(&i) = self.struct_names.get(other) {
                    Ty::Struct(i)
                } else {
                    self.err(
                        t.span,
                        format!("unknown type `{other}`: expected int, float, double, bool, V2f, V3f, a declared struct or enum"),
                    );
                    return None;
                }
            }
        };
        Some(ty)
    }

    /// The types of the values that build a `ty`: a vector's components,
    /// a struct's fields, or `ty` itself.
    pub(super) fn parts_of(&self, ty: Ty) -> Vec<Ty> {
        match ty {
            t if t.is_vector() => vec![t.scalar(); t.dim()],
            Ty::Struct(i) => self.structs[i as usize]
                .fields
                .iter()
                .map(|f| f.1)
                .collect(),
            t => vec![t],
        }
    }

    /// Converts `ex` of type `from` to `to`, or reports a type error.
    pub(super) fn coerce(&mut self, ex: Ex, from: Ty, to: Ty, span: Span) -> Option<Ex> {
        if from == to {
            return Some(ex);
        }
        let (ex, from) = if matches!(to, Ty::Elem(_)) {
            (ex, from)
        } else {
            self.arith(ex, from, span)
        };
        if from == to {
            return Some(ex);
        }
        if from.is_numeric() && to.is_numeric() {
            if from == Ty::Int && to.is_floating() {
                self.check_truncation(&ex);
            }
            // To `float`, the conversion rounds to single precision.
            return Some(fold_unary(Ex::Convert(to, Box::new(ex))));
        }
        if from.is_vector() && from.dim() == to.dim() {
            // `V2d` to `V2f` rounds each component; the other way is exact.
            return Some(fold_unary(Ex::Convert(to, Box::new(ex))));
        }
        self.err(
            span,
            format!(
                "type mismatch: expected {}, found {}",
                self.type_name(to),
                self.type_name(from)
            ),
        );
        None
    }
}

/// The result type of `a op b`, or `None` for a type error. Numbers
/// follow C's usual arithmetic conversions (`double` over `float` over
/// `int`); vectors of one size but two precisions give the double one.
pub fn binary_type(op: BinOp, a: Ty, b: Ty) -> Option<Ty> {
    if let (Ty::Elem(x), Ty::Elem(y)) = (a, b) {
        // Elements compare by identity, and in the order of their ids
        // (vv's universe order, `p < q`).
        use BinOp::*;
        return (x == y && matches!(op, Eq | Ne | Lt | Le | Gt | Ge)).then_some(Ty::Bool);
    }
    let num = a.is_numeric() && b.is_numeric();
    let promote = || a.wider(b).wider(Ty::Int);
    let vectors = a.is_vector() && a.dim() == b.dim();
    use BinOp::*;
    match op {
        Add | Sub => {
            if num {
                Some(promote())
            } else if vectors {
                Some(a.wider(b))
            } else {
                None
            }
        }
        Mul => {
            if num {
                Some(promote())
            } else if a.is_numeric() && b.is_vector() {
                Some(b)
            } else if a.is_vector() && b.is_numeric() {
                Some(a)
            } else if vectors {
                // The dot product.
                Some(a.wider(b).scalar())
            } else {
                None
            }
        }
        Div => {
            if num {
                Some(promote())
            } else if a.is_vector() && b.is_numeric() {
                Some(a)
            } else {
                None
            }
        }
        Rem => {
            if num {
                Some(promote())
            } else if vectors && a.dim() == 3 {
                // The cross product.
                Some(a.wider(b))
            } else {
                None
            }
        }
        Lt | Le | Gt | Ge => num.then_some(Ty::Bool),
        Eq | Ne => (num || vectors).then_some(Ty::Bool),
        And | Or => num.then_some(Ty::Bool),
        BitAnd | BitOr | BitXor | Shl | Shr => {
            (num && !a.is_floating() && !b.is_floating()).then_some(Ty::Int)
        }
    }
}
