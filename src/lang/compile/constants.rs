//! Constants: operations on constants folded when compiled, integer
//! constants (array sizes, enumerators, `case` labels), and the values
//! known before the program runs.

use crate::syntax::ast::{self, BinOp};
use crate::syntax::parse::MAX_NESTING;

use crate::lang::ir::{Ex, Func};
use crate::lang::value::Value;

use super::{Compiler, Scope};

impl Compiler {
    /// An integer constant: a literal, an enumerator, a `const` global
    /// with a constant initializer, or arithmetic of those.
    #[inline(never)]
    pub(super) fn const_int(&mut self, e: &ast::Expr, what: &str) -> Option<i64> {
        let mut scope = Scope::default();
        let (ex, _) = self.expr(e, &mut scope)?;
        match self.const_value(&ex, 0) {
            Some(Value::Int(i)) => Some(i),
            Some(Value::Bool(b)) => Some(b as i64),
            _ => {
                self.err(e.span, format!("{what} must be an integer constant"));
                None
            }
        }
    }

    /// `e`'s value when it is an integer constant; `None`, and nothing
    /// reported, otherwise.
    pub(super) fn quiet_const_int(&mut self, e: &ast::Expr) -> Option<i64> {
        let (diags, warnings) = (self.diags.len(), self.warnings.len());
        let mut scope = Scope::default();
        let v = self
            .expr(e, &mut scope)
            .and_then(|(ex, _)| self.const_value(&ex, 0));
        self.diags.truncate(diags);
        self.warnings.truncate(warnings);
        match v {
            Some(Value::Int(i)) => Some(i),
            Some(Value::Bool(b)) => Some(b as i64),
            _ => None,
        }
    }

    /// The value `ex` makes when it is known before the program runs: a
    /// constant, a string function (`sprintf`'s formatting) of constants,
    /// or an array or struct of those.
    pub(super) fn const_written(&self, ex: &Ex) -> Option<Value> {
        use crate::lang::stdio::IoFunc;
        Some(match ex {
            Ex::Call(
                Func::Io(
                    f @ (IoFunc::Format | IoFunc::Concat | IoFunc::Strncat | IoFunc::Snprintf),
                ),
                args,
                _,
            ) => {
                let vals = args
                    .iter()
                    .map(|a| self.const_value(a, 0))
                    .collect::<Option<Vec<_>>>()?;
                crate::lang::stdio::call(*f, &vals, &crate::lang::stdio::ProgramOutput::default())
                    .ok()?
            }
            Ex::MakeStruct(parts) => Value::Struct(
                parts
                    .iter()
                    .map(|p| self.const_written(p))
                    .collect::<Option<Vec<_>>>()?
                    .into(),
            ),
            _ => self.const_value(ex, 0)?,
        })
    }

    pub(super) fn const_value(&self, ex: &Ex, depth: usize) -> Option<Value> {
        if depth > MAX_NESTING {
            return None;
        }
        match ex {
            Ex::Const(v) => Some(v.clone()),
            Ex::Global(g) => {
                let gv = self.globals.get(*g as usize)?;
                if gv.is_const {
                    Some(
                        self.const_value(gv.init.as_ref()?, depth + 1)?
                            .convert(gv.ty),
                    )
                } else {
                    None
                }
            }
            Ex::Neg(a) => crate::lang::eval::binary(
                BinOp::Sub,
                Value::Int(0),
                self.const_value(a, depth + 1)?,
            )
            .ok(),
            Ex::Convert(t, a) => Some(self.const_value(a, depth + 1)?.convert(*t)),
            Ex::Bin(op, a, b, _) => crate::lang::eval::binary(
                *op,
                self.const_value(a, depth + 1)?,
                self.const_value(b, depth + 1)?,
            )
            .ok(),
            _ => None,
        }
    }
}

/// `a op b` of two constants, computed once at compile time. Divisions of
/// integers are left alone: `check` warns about those that truncate, and
/// division by zero is an error where the program runs.
pub(super) fn fold_constants(op: BinOp, a: &Ex, b: &Ex) -> Option<Ex> {
    let (Ex::Const(x), Ex::Const(y)) = (a, b) else {
        return None;
    };
    let int = |v: &Value| matches!(v, Value::Int(_) | Value::Bool(_));
    if matches!(op, BinOp::Div | BinOp::Rem) && int(x) && int(y) {
        return None;
    }
    if matches!(op, BinOp::And | BinOp::Or) {
        return None;
    }
    crate::lang::eval::binary(op, x.clone(), y.clone())
        .ok()
        .map(Ex::Const)
}

/// A negation, conversion or maths function of constants, computed once.
pub(super) fn fold_unary(e: Ex) -> Ex {
    match e {
        Ex::Neg(a) => match *a {
            Ex::Const(Value::Int(i)) => Ex::Const(Value::Int(i.wrapping_neg())),
            Ex::Const(Value::Float(f)) => Ex::Const(Value::Float(-f)),
            a => Ex::Neg(Box::new(a)),
        },
        Ex::Convert(t, a) => match *a {
            Ex::Const(v) => Ex::Const(v.convert(t)),
            a => Ex::Convert(t, Box::new(a)),
        },
        Ex::Call(Func::Math1(f), args, span) => match args.as_slice() {
            [Ex::Const(a)] => Ex::Const(Value::Float(f(a.as_f64()))),
            _ => Ex::Call(Func::Math1(f), args, span),
        },
        Ex::Call(Func::Math2(f), args, span) => match args.as_slice() {
            [Ex::Const(a), Ex::Const(b)] => Ex::Const(Value::Float(f(a.as_f64(), b.as_f64()))),
            _ => Ex::Call(Func::Math2(f), args, span),
        },
        e => e,
    }
}
