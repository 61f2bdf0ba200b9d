//! Calls by name: of a `define` function (inlined into the caller), a
//! user function, a constructor, a functional cast, a vector, an aggregate
//! over a set, or a function of the library or the topology.

use std::rc::Rc;

use crate::syntax::ast::{self, ExprKind};
use crate::syntax::span::Span;

use crate::lang::builtins::{self, SigError, LIBRARY};
use crate::lang::ir::{Ex, Func};
use crate::lang::value::Ty;

use super::constants::fold_unary;
use super::{Compiler, Scope, Typed};

/// Function calls are inlined; past this many in one rule, functions that
/// call each other twice over would take exponential time.
const MAX_INLINED_CALLS: usize = 10_000;

/// Functions calling functions nest no deeper than this (as in the
/// surface grammars' checker before the one language): each level adds a
/// body's nesting to the checked expression, which the checker, the
/// specialisations and the interpreter walk recursively.
const MAX_INLINE_DEPTH: usize = 32;

impl Compiler {
    pub(super) fn call(
        &mut self,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let n = name.text.as_str();
        if let Some(&f) = self.function_names.get(n) {
            return self.inline(f, args, span, scope);
        }
        if let Some(&id) = self.user_fn_names.get(n) {
            return self.user_call(id, name, args, span, scope);
        }
        if let Some(r) = self.ctor_or_stdio_call(name, args, span, scope) {
            return r;
        }
        // A functional cast: `float(x)`, `int(x)`.
        if let ("int" | "float" | "double" | "bool" | "long" | "short" | "unsigned" | "char", [a]) =
            (n, args)
        {
            return self.functional_cast(name, a, span, scope);
        }
        let mut typed = Vec::new();
        let mut ok = true;
        for a in args {
            match self.expr(a, scope) {
                Some(t) => typed.push(t),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        if matches!(n, "V2f" | "V2d" | "V3f" | "V3d") {
            let ty = match n {
                "V2f" => self.prec(Ty::V2),
                "V3f" => self.prec(Ty::V3),
                "V2d" => Ty::V2d,
                _ => Ty::V3d,
            };
            let ex = self.construct(ty, typed, args, span)?;
            return Some((ex, ty));
        }
        // `avg(ring(v))`: an aggregate over a whole set.
        if let ("sum" | "avg" | "count", [(_, Ty::Elem(k))]) = (n, typed.as_slice()) {
            if (self.host.members)(*k).is_some() {
                let (set, ty) = typed.pop()?;
                return self.fold(name, set, ty, args[0].span, None, None, scope);
            }
        }
        // With `float` computed in double (`--double`), C's float
        // functions are their double twins: `expf` is `exp`.
        let float_function = builtins::is_float_function(n);
        let n = match (float_function, self.single) {
            (true, false) => &n[..n.len() - 1],
            _ => n,
        };
        let Some(b) = builtins::lookup(n, self.host) else {
            let hint = if self.alphabet.lookup(n).is_some() {
                format!(": `{n}` is a module; modules go after `produce`, not in expressions")
            } else if self.hint_allowed() {
                let names = self.function_names();
                crate::lang::suggest::hint(n, names.iter().map(String::as_str))
            } else {
                String::new()
            };
            self.err(name.span, format!("unknown function `{n}`{hint}"));
            return None;
        };
        let library = LIBRARY.iter().any(|l| l.name == n);
        if library {
            // The library takes numbers and vectors: elements read as
            // their values.
            typed = typed
                .into_iter()
                .zip(args)
                .map(|((x, t), a)| self.arith(x, t, a.span))
                .collect();
        }
        let tys: Vec<Ty> = typed.iter().map(|(_, t)| *t).collect();
        match (b.resolve)(&tys) {
            Ok((f, ty)) => {
                if matches!(f, Func::Math1(_) | Func::Math2(_)) {
                    for (x, _) in &typed {
                        self.check_truncation(x);
                    }
                }
                // lpfg's programs call C's maths functions of <math.h>,
                // not C++'s overloads: `sqrt` of a `float` is a `double`
                // (lpfg 9bf820d: `sqrt(x) * sqrt(x) - 2` with a float
                // `x = 2` is 4.4e-16, not the float -1.2e-7). A vector's
                // length or dot product has its components' precision.
                // What the library declares `float` (lpfg's `ran`,
                // `func`) is a single-precision result.
                let ty = match f {
                    // `expf`, `sqrtf`, …: a float whatever the argument.
                    Func::Math1(_) | Func::Math2(_) if float_function => self.prec(Ty::Float),
                    Func::Math1(_) | Func::Math2(_) => Ty::Double,
                    Func::Length | Func::Dot => tys.first().map_or(ty, |t| t.scalar()),
                    Func::Normalized | Func::Cross => tys.first().map_or(ty, |t| *t),
                    _ => self.prec(ty),
                };
                let exs = typed.into_iter().map(|(e, _)| e).collect();
                Some((self.round(fold_unary(Ex::Call(f, exs, span)), ty), ty))
            }
            Err(SigError::Arity(want)) => {
                self.err(
                    span,
                    format!(
                        "`{n}` takes {want} argument(s), but {} were given",
                        typed.len()
                    ),
                );
                None
            }
            Err(SigError::NotNumber(i)) => {
                let found = self.type_name(tys[i]);
                self.err(
                    args[i].span,
                    format!("type error: `{n}` expects a number, found {found}"),
                );
                None
            }
            Err(SigError::Message(m)) => {
                self.err(span, m);
                None
            }
        }
    }

    /// `float(x)`: the cast `(float) x`.
    #[inline(never)]
    fn functional_cast(
        &mut self,
        name: &ast::Name,
        a: &ast::Expr,
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let t = ast::TypeRef {
            name: name.text.clone(),
            span: name.span,
            pointer: false,
            reference: false,
        };
        let cast = ast::Expr {
            kind: ExprKind::Cast(t, Box::new(a.clone())),
            span,
        };
        self.expr_inner(&cast, scope)
    }

    /// A struct's construction (`S(args)`) or one of C's standard I/O and
    /// string functions; `None` for another name. (One call in `call`, so
    /// that the frame of that recursive function stays small.)
    #[inline(never)]
    fn ctor_or_stdio_call(
        &mut self,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Option<Typed> {
        if let Some(ty) = self.struct_named(&name.text) {
            return Some(self.ctor_call(ty, name, args, span, scope));
        }
        self.stdio_call(name, args, span, scope)
    }

    /// A call of a `define` function: the arguments bind fresh locals,
    /// reserved before the arguments are compiled so that no argument's
    /// own locals overwrite a parameter already set; then the body sees
    /// only its parameters. The locals are free again after the call.
    fn inline(&mut self, f: usize, args: &[ast::Expr], span: Span, scope: &mut Scope) -> Typed {
        let functions = Rc::clone(&self.functions);
        let def = &functions[f];
        if def.params.len() != args.len() {
            self.err(
                span,
                format!(
                    "`{}` takes {} argument(s), but {} were given",
                    def.name,
                    def.params.len(),
                    args.len()
                ),
            );
            return None;
        }
        if self.inlining.contains(&f) {
            self.err(
                span,
                format!("`{}` calls itself; functions may not recurse", def.name),
            );
            return None;
        }
        if self.inlining.len() >= MAX_INLINE_DEPTH {
            self.err(
                span,
                format!(
                    "`{}` is called more than {MAX_INLINE_DEPTH} function calls deep; \
                     functions may not nest deeper",
                    def.name
                ),
            );
            return None;
        }
        self.inlined += 1;
        if self.inlined > MAX_INLINED_CALLS {
            self.err(
                span,
                format!(
                    "the functions called here expand to more than {MAX_INLINED_CALLS} calls; \
                     name a shared value with a parameter instead of calling a function twice"
                ),
            );
            return None;
        }
        // Each argument binds a local around the body: `Let`s nest.
        self.nested(args.len(), span, |c| {
            c.inline_body(f, def, args, span, scope)
        })
    }

    fn inline_body(
        &mut self,
        f: usize,
        def: &ast::Define,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let mark = (scope.vars.len(), scope.next);
        let Some(first) = scope.reserve(args.len()) else {
            self.too_many_locals(scope, span);
            return None;
        };
        let mut lets = Vec::with_capacity(args.len());
        let mut ok = true;
        for a in args {
            match self.expr(a, scope) {
                Some(t) => lets.push(t),
                None => ok = false,
            }
        }
        if !ok {
            scope.truncate(mark.0);
            scope.next = mark.1;
            return None;
        }
        let barrier = scope.barrier;
        scope.barrier = scope.vars.len();
        for (i, (p, (_, t))) in def.params.iter().zip(&lets).enumerate() {
            scope.bind(p, *t, first + i as u16);
        }
        let marked = self.truncating.len();
        for (i, (a, _)) in lets.iter().enumerate() {
            if let Some(d) = self.truncated_division(a) {
                self.truncating.push((first + i as u16, d));
            }
        }
        self.inlining.push(f);
        let errors = self.diags.len();
        let body = self.expr(&def.body, scope);
        self.inlining.pop();
        self.truncating.truncate(marked);
        // The caret points into the body; name the function once, at the
        // innermost call.
        for d in &mut self.diags[errors..] {
            if !d.message.contains(" (in `") {
                d.message = format!("{} (in `{}`)", d.message, def.name);
            }
        }
        scope.barrier = barrier;
        scope.truncate(mark.0);
        scope.next = mark.1;
        let (mut x, t) = body?;
        for (i, (a, _)) in lets.into_iter().enumerate().rev() {
            x = Ex::Let(first + i as u16, Box::new(a), Box::new(x));
        }
        Some((x, t))
    }
}
