//! Reporting: errors, limits reported once, warnings about divisions of
//! integers that truncate, and the "did you mean" hints.

use crate::syntax::ast::BinOp;
use crate::syntax::span::{Diagnostic, Span};

use crate::lang::builtins;
use crate::lang::ir::Ex;
use crate::lang::value::Value;

use super::{Compiler, Scope, MAX_HINTS};

impl Compiler {
    pub(super) fn err(&mut self, span: Span, msg: impl Into<String>) {
        self.diags.push(Diagnostic::new(span, msg));
    }

    /// Reports that more than `limit` `what` are declared, at the first
    /// one too many only.
    pub(super) fn too_many(&mut self, limit: usize, what: &'static str, span: Span) {
        if self.counts_reported.insert(what) {
            self.err(span, format!("more than {limit} {what} are declared"));
        }
    }

    /// Warns when `ex` is a division of integer constants that truncates
    /// and its value is about to be used as a floating-point number.
    /// Also where the division is of integer variables (`(n - 2)/n`), which
    /// C truncates as well, and which a surface grammar written before the
    /// one language meant as a fraction.
    pub(super) fn check_truncation(&mut self, ex: &Ex) {
        // An inlined function's value is its body's.
        if let Ex::Let(_, _, body) = ex {
            return self.check_truncation(body);
        }
        // A division of integer variables.
        if let Ex::Bin(BinOp::Div, a, b, span) = ex {
            let constants = matches!(
                (&**a, &**b),
                (Ex::Const(Value::Int(_)), Ex::Const(Value::Int(_)))
            );
            if !constants && self.int_divisions.contains(span) {
                let at = Diagnostic::new(
                    *span,
                    "this divides integers, which truncates (C's arithmetic), and its value is \
                     then used as a floating-point number; write one operand as a float (`2.0`, \
                     or `(float) n`) if a fraction is meant",
                );
                if !self.warnings.contains(&at) {
                    self.warnings.push(at);
                }
                return;
            }
        }
        let Some(ex) = self.truncated_division(ex) else {
            return;
        };
        if let Ex::Bin(BinOp::Div, a, b, span) = &ex {
            if let (Ex::Const(Value::Int(x)), Ex::Const(Value::Int(y))) = (&**a, &**b) {
                // Wrapping, as the interpreter divides: `i64::MIN / -1`
                // overflows, and it does not truncate.
                if *y != 0 && x.wrapping_rem(*y) != 0 {
                    let at = Diagnostic::new(
                        *span,
                        format!(
                            "`{x}/{y}` is {} in integer arithmetic; write {x}.0/{y}",
                            x.wrapping_div(*y)
                        ),
                    );
                    if !self.warnings.contains(&at) {
                        self.warnings.push(at);
                    }
                }
            }
        }
    }

    /// The division of integer constants `ex` is, negated or not, or
    /// the one an inlined parameter `ex` was bound to.
    pub(super) fn truncated_division(&self, ex: &Ex) -> Option<Ex> {
        match ex {
            Ex::Neg(a) => self.truncated_division(a),
            Ex::Local(s) => self
                .truncating
                .iter()
                .rev()
                .find(|(t, _)| t == s)
                .map(|(_, d)| d.clone()),
            Ex::Bin(BinOp::Div, a, b, _)
                if matches!(
                    (&**a, &**b),
                    (Ex::Const(Value::Int(_)), Ex::Const(Value::Int(_)))
                ) =>
            {
                Some(ex.clone())
            }
            _ => None,
        }
    }

    /// The names a value may have here, sorted: the visible locals, the
    /// globals, enumerators, the host's values and the language's
    /// constants (for "did you mean").
    fn value_names(&self, scope: &Scope) -> Vec<String> {
        let mut names: Vec<String> = scope.vars[scope.barrier.min(scope.vars.len())..]
            .iter()
            .map(|(n, _, _)| n.clone())
            .chain(self.global_names.keys().cloned())
            .chain(self.enum_consts.keys().cloned())
            .chain(self.host.values.iter().map(|(n, _, _)| n.to_string()))
            .chain(
                [
                    "true", "false", "M_PI", "PI", "M_PI_2", "M_E", "M_SQRT2", "RAND_MAX", "NULL",
                    "stdout", "stderr",
                ]
                .map(String::from),
            )
            .collect();
        names.sort();
        names.dedup();
        names
    }

    /// The functions a call may name, sorted: the library's, the host's,
    /// the program's own and C's input and output (for "did you mean").
    pub(super) fn function_names(&self) -> Vec<String> {
        let mut names: Vec<String> = builtins::LIBRARY
            .iter()
            .map(|b| b.name.to_string())
            .chain(self.host.functions.iter().map(|b| b.name.to_string()))
            .chain(self.user_fn_names.keys().cloned())
            .chain(
                [
                    "printf", "fprintf", "sprintf", "snprintf", "puts", "fputs", "fopen", "fclose",
                    "fflush", "strlen", "strcmp", "strcpy", "strcat", "strncpy", "strncat",
                ]
                .map(String::from),
            )
            .collect();
        names.sort();
        names.dedup();
        names
    }

    /// True while fewer than [`MAX_HINTS`] hints were looked for; counts
    /// this one.
    pub(super) fn hint_allowed(&mut self) -> bool {
        self.hints += 1;
        self.hints <= MAX_HINTS
    }

    /// "; did you mean `x`?" for a value's name that is not known.
    pub(super) fn value_hint(&mut self, name: &str, scope: &Scope) -> String {
        if !self.hint_allowed() {
            return String::new();
        }
        let names = self.value_names(scope);
        crate::lang::suggest::hint(name, names.iter().map(String::as_str))
    }

    /// "; did you mean `Apex`?" for a module name that is not declared,
    /// from the modules the program declares and the predefined ones.
    pub(super) fn module_hint(&mut self, name: &str) -> String {
        if !self.hint_allowed() {
            return String::new();
        }
        let mut names: Vec<&str> = self
            .alphabet
            .kinds
            .iter()
            .map(|k| k.name.as_str())
            .collect();
        names.sort_unstable();
        names.dedup();
        crate::lang::suggest::hint(name, names)
    }
}
