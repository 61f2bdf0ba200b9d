//! Expressions: literals, names, operators, assignments, `?:`, casts,
//! context tests, fields and elements, vectors' methods; the nesting
//! limit, which inlined functions count too.

use crate::syntax::ast::{self, BinOp, ExprKind, UnOp};
use crate::syntax::parse::MAX_NESTING;
use crate::syntax::span::Span;

use crate::lang::ir::{Ex, Func, Pattern};
use crate::lang::value::{Ty, Value};

use super::constants::{fold_constants, fold_unary};
use super::types::binary_type;
use super::{Compiler, Scope, Typed};

impl Compiler {
    /// Compiles an expression. The parser bounds the nesting of what is
    /// written; inlined functions nest their bodies inside their calls, so
    /// the same bound is kept here (and so on the interpreter's recursion).
    pub(super) fn expr(&mut self, e: &ast::Expr, scope: &mut Scope) -> Typed {
        self.nested(1, e.span, |c| c.expr_inner(e, scope))
    }

    /// Runs `f` `levels` deeper, or refuses with the nesting limit's
    /// message at `span`.
    pub(super) fn nested(
        &mut self,
        levels: usize,
        span: Span,
        f: impl FnOnce(&mut Self) -> Typed,
    ) -> Typed {
        if self.depth + levels > MAX_NESTING {
            self.err(
                span,
                format!(
                    "this is nested more than {MAX_NESTING} levels deep once the functions it \
                     calls are inlined; split it into simpler parts"
                ),
            );
            return None;
        }
        self.depth += levels;
        let r = f(self);
        self.depth -= levels;
        r
    }

    pub(super) fn expr_inner(&mut self, e: &ast::Expr, scope: &mut Scope) -> Typed {
        let span = e.span;
        match &e.kind {
            ExprKind::Int(i) => Some((Ex::Const(Value::Int(*i)), Ty::Int)),
            // A literal without a suffix is a `double`, as in C.
            // A literal with an `f` suffix is a `float` (its value is
            // already the nearest single-precision one).
            ExprKind::Float(f, true) => Some((Ex::Const(Value::Float(*f)), self.prec(Ty::Float))),
            ExprKind::Float(f, false) => Some((Ex::Const(Value::Float(*f)), Ty::Double)),
            ExprKind::Str(s) => Some((
                Ex::Const(Value::Str(crate::lang::stdio::unescape(s).into())),
                Ty::Str,
            )),
            ExprKind::Ident(n) => {
                if let Some((ty, slot, global)) = scope.lookup_var(n) {
                    return Some((
                        if global {
                            Ex::Global(slot)
                        } else {
                            Ex::Local(slot)
                        },
                        ty,
                    ));
                }
                if let Some(&g) = self.global_names.get(n) {
                    return Some((Ex::Global(g), self.globals[g as usize].ty));
                }
                if let Some(&v) = self.enum_consts.get(n) {
                    return Some((Ex::Const(Value::Int(v)), Ty::Int));
                }
                if self.ambiguous_enums.contains(n) {
                    return self.ambiguous_enumerator(n, span);
                }
                let handle = match n.as_str() {
                    "NULL" => Some(0),
                    "stdout" => Some(crate::lang::stdio::STDOUT),
                    "stderr" => Some(crate::lang::stdio::STDERR),
                    _ => None,
                };
                if let Some(h) = handle {
                    return Some((Ex::Const(Value::Int(h)), Ty::Int));
                }
                if let Some((f, ty)) = self.host.value(n) {
                    return Some((Ex::Call(f, Vec::new(), span), self.prec(ty)));
                }
                let c = match n.as_str() {
                    "true" => Value::Bool(true),
                    "false" => Value::Bool(false),
                    "M_PI" | "PI" => Value::Float(std::f64::consts::PI),
                    "M_PI_2" => Value::Float(std::f64::consts::FRAC_PI_2),
                    "M_E" => Value::Float(std::f64::consts::E),
                    "M_SQRT2" => Value::Float(std::f64::consts::SQRT_2),
                    "RAND_MAX" => Value::Int(crate::lang::random::RAND_MAX),
                    _ => {
                        let hint = if self.alphabet.lookup(n).is_some() {
                            format!(": `{n}` is a module, not a value")
                        } else {
                            self.value_hint(n, scope)
                        };
                        self.err(span, format!("unknown identifier `{n}`{hint}"));
                        return None;
                    }
                };
                let ty = match c {
                    Value::Bool(_) => Ty::Bool,
                    Value::Int(_) => Ty::Int,
                    _ => Ty::Double,
                };
                Some((Ex::Const(c), ty))
            }
            ExprKind::Unary(op, a) => {
                let (x, t) = self.expr(a, scope)?;
                let (x, t) = self.arith(x, t, a.span);
                match op {
                    UnOp::Plus if t.is_numeric() || t.is_vector() => Some((x, t)),
                    UnOp::Neg if t.is_numeric() || t.is_vector() => {
                        let t = if t == Ty::Bool { Ty::Int } else { t };
                        Some((fold_unary(Ex::Neg(Box::new(x))), t))
                    }
                    UnOp::Not if t.is_numeric() => Some((Ex::Not(Box::new(x)), Ty::Bool)),
                    _ => {
                        let sym = match op {
                            UnOp::Neg => "-",
                            UnOp::Plus => "+",
                            UnOp::Not => "!",
                        };
                        self.err(
                            span,
                            format!(
                                "type error: cannot apply unary `{sym}` to {}",
                                self.type_name(t)
                            ),
                        );
                        None
                    }
                }
            }
            ExprKind::Binary(op, a, b) => {
                let l = self.expr(a, scope);
                let r = self.expr(b, scope);
                let ((lx, lt), (rx, rt)) = (l?, r?);
                let (lx, lt) = self.arith(lx, lt, a.span);
                let (rx, rt) = self.arith(rx, rt, b.span);
                let Some(ty) = binary_type(*op, lt, rt) else {
                    self.err(
                        span,
                        format!(
                            "type error: cannot apply `{}` to {} and {}",
                            op.symbol(),
                            self.type_name(lt),
                            self.type_name(rt)
                        ),
                    );
                    return None;
                };
                if *op == BinOp::Div && !lt.is_floating() && !rt.is_floating() && ty == Ty::Int {
                    self.int_divisions.push(span);
                }
                // A float result, or a float on either side (a comparison):
                // the integers are read as floats.
                if !matches!(ty, Ty::Int | Ty::Bool) || lt.is_floating() || rt.is_floating() {
                    self.check_truncation(&lx);
                    self.check_truncation(&rx);
                }
                // Single-precision arithmetic: C converts a scalar operand
                // to `float` first (lpfg's `V2f * s` takes a float), then
                // rounds the result.
                let arithmetic = matches!(
                    op,
                    BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem
                );
                let (lx, rx) = if arithmetic && ty.is_single() {
                    let to_float = |x: Ex, t: Ty| {
                        if t.is_numeric() && t != Ty::Float {
                            fold_unary(Ex::Convert(Ty::Float, Box::new(x)))
                        } else {
                            x
                        }
                    };
                    (to_float(lx, lt), to_float(rx, rt))
                } else {
                    (lx, rx)
                };
                if let Some(c) = fold_constants(*op, &lx, &rx) {
                    return Some((Ex::Convert(ty, Box::new(c)), ty))
                        .map(|(x, t)| (fold_unary(x), t));
                }
                let ex = match op {
                    BinOp::And => Ex::Logic(true, Box::new(lx), Box::new(rx)),
                    BinOp::Or => Ex::Logic(false, Box::new(lx), Box::new(rx)),
                    _ => Ex::Bin(*op, Box::new(lx), Box::new(rx), span),
                };
                let ex = if arithmetic { self.round(ex, ty) } else { ex };
                Some((ex, ty))
            }
            ExprKind::Assign(op, lhs, rhs) if matches!(lhs.kind, ExprKind::Prop(..)) => {
                self.assign_property(*op, lhs, rhs, span, scope)
            }
            ExprKind::IncDec {
                target,
                delta,
                prefix,
            } if matches!(target.kind, ExprKind::Prop(..)) => {
                let one = ast::Expr {
                    kind: ExprKind::Int(1),
                    span,
                };
                let op = if *delta > 0 { BinOp::Add } else { BinOp::Sub };
                let (x, ty) = self.assign_property(Some(op), target, &one, span, scope)?;
                if *prefix {
                    return Some((x, ty));
                }
                if ty != Ty::Int {
                    self.err(
                        span,
                        "a property's `++`/`--` after it gives its old value only for an int; write `v$x += 1`",
                    );
                    return None;
                }
                let back = if *delta > 0 { BinOp::Sub } else { BinOp::Add };
                Some((
                    Ex::Bin(back, Box::new(x), Box::new(Ex::Const(Value::Int(1))), span),
                    ty,
                ))
            }
            ExprKind::Assign(op, lhs, rhs) => {
                let place = self.place(lhs, scope);
                let (rx, rhs_ty) = self.expr(rhs, scope)?;
                let place = place?;
                let rt = match op {
                    None => rhs_ty,
                    Some(o) => match binary_type(*o, place.ty, rhs_ty) {
                        Some(t) => t,
                        None => {
                            self.err(
                                span,
                                format!(
                                    "type error: cannot apply `{}=` to {} and {}",
                                    o.symbol(),
                                    self.type_name(place.ty),
                                    self.type_name(rhs_ty)
                                ),
                            );
                            return None;
                        }
                    },
                };
                let vectors = rt.is_vector() && rt.dim() == place.ty.dim();
                if !(rt == place.ty || (rt.is_numeric() && place.ty.is_numeric()) || vectors) {
                    self.err(
                        span,
                        format!(
                            "type mismatch in assignment: expected {}, found {}",
                            self.type_name(place.ty),
                            self.type_name(rt)
                        ),
                    );
                    return None;
                }
                let ty = place.ty;
                // `v *= s` on a `V2f` takes a float `s`, as lpfg's operator
                // does; the store rounds the result (`Value::convert`).
                let rx = if op.is_some() && ty.is_vector() && ty.is_single() && rhs_ty.is_numeric()
                {
                    fold_unary(Ex::Convert(Ty::Float, Box::new(rx)))
                } else {
                    rx
                };
                // A string assigned to a declared `char` array must fit.
                let rx = match &place.chars {
                    Some(c) => self.fit(rx, c, "the assignment", span)?,
                    None => rx,
                };
                Some((Ex::Assign(place, *op, Box::new(rx), ty), ty))
            }
            ExprKind::IncDec {
                target,
                delta,
                prefix,
            } => {
                let place = self.place(target, scope)?;
                if !place.ty.is_numeric() {
                    self.err(
                        span,
                        format!(
                            "type error: `++`/`--` need a number, found {}",
                            self.type_name(place.ty)
                        ),
                    );
                    return None;
                }
                let ty = place.ty;
                Some((Ex::IncDec(place, *delta, *prefix), ty))
            }
            ExprKind::Cond(c, a, b) => {
                let c = self.condition(c, scope);
                let l = self.expr(a, scope);
                let r = self.expr(b, scope);
                let (c, (lx, lt), (rx, rt)) = (c?, l?, r?);
                let ((lx, lt), (rx, rt)) = if lt == rt {
                    ((lx, lt), (rx, rt))
                } else {
                    (self.arith(lx, lt, a.span), self.arith(rx, rt, b.span))
                };
                let ty = if lt == rt {
                    lt
                } else if lt.is_numeric() && rt.is_numeric() {
                    lt.wider(rt).wider(Ty::Int)
                } else if lt.is_vector() && lt.dim() == rt.dim() {
                    lt.wider(rt)
                } else {
                    self.err(
                        span,
                        format!(
                            "type error: the branches of `?:` have different types, {} and {}",
                            self.type_name(lt),
                            self.type_name(rt)
                        ),
                    );
                    return None;
                };
                if ty.is_floating() {
                    self.check_truncation(&lx);
                    self.check_truncation(&rx);
                }
                let lx = if lt == ty {
                    lx
                } else {
                    fold_unary(Ex::Convert(ty, Box::new(lx)))
                };
                let rx = if rt == ty {
                    rx
                } else {
                    fold_unary(Ex::Convert(ty, Box::new(rx)))
                };
                Some((Ex::Cond(Box::new(c), Box::new(lx), Box::new(rx)), ty))
            }
            ExprKind::Cast(t, a) => {
                let ty = self.resolve_type(t);
                let (x, xt) = self.expr(a, scope)?;
                let ty = ty?;
                if xt == ty {
                    return Some((x, ty));
                }
                let vectors = xt.is_vector() && xt.dim() == ty.dim();
                if !(xt.is_numeric() && ty.is_numeric() || vectors) {
                    self.err(
                        span,
                        format!(
                            "cannot cast {} to {}",
                            self.type_name(xt),
                            self.type_name(ty)
                        ),
                    );
                    return None;
                }
                Some((fold_unary(Ex::Convert(ty, Box::new(x))), ty))
            }
            ExprKind::Field(..) | ExprKind::Index(..) | ExprKind::List(_) => self.access(e, scope),
            ExprKind::Method(recv, name, args) => self.method(recv, name, args, span, scope),
            ExprKind::Gather { op, var, set, cond } => {
                self.gather(op, Some(var), set, cond.as_deref(), scope)
            }
            ExprKind::Call(name, args) => self.call(name, args, span, scope),
            ExprKind::Prop(target, name) => {
                let (tx, tt) = self.expr(target, scope)?;
                let (_, index, ty) = self.property(tt, name, span)?;
                let get = self.host.properties?.get;
                Some((
                    Ex::Call(
                        Func::Host(get),
                        vec![tx, Ex::Const(Value::Int(index as i64))],
                        span,
                    ),
                    ty,
                ))
            }
            ExprKind::InContext(kind, pats) => {
                if !scope.in_rule {
                    self.err(
                        span,
                        "context tests are only allowed in the body of a production",
                    );
                    return None;
                }
                let mut out = Vec::new();
                let mut all_places = Vec::new();
                for p in pats {
                    let (sym, tys, width) = self.module_params(&p.name, p.params.len())?;
                    for (n, t) in p.params.iter().zip(tys.iter().copied()) {
                        let ident = ast::Expr {
                            kind: ExprKind::Ident(n.text.clone()),
                            span: n.span,
                        };
                        let place = self.place(&ident, scope)?;
                        let vectors = t.is_vector() && place.ty.dim() == t.dim();
                        if !(place.ty == t || (place.ty.is_numeric() && t.is_numeric()) || vectors)
                        {
                            self.err(
                                n.span,
                                format!(
                                    "`{}` has type {} but this parameter of `{}` is {}",
                                    n.text,
                                    self.type_name(place.ty),
                                    p.name.text,
                                    self.type_name(t)
                                ),
                            );
                            return None;
                        }
                        all_places.push(place);
                    }
                    out.push(Pattern {
                        sym,
                        slots: Vec::new(),
                        types: tys,
                        width,
                    });
                }
                Some((Ex::InContext(*kind, out, all_places), Ty::Bool))
            }
        }
    }

    /// A field, an element of an array, or a misplaced `{...}`; out of
    /// `expr_inner`, so that its frame stays small for deep nesting.
    #[inline(never)]
    fn access(&mut self, e: &ast::Expr, scope: &mut Scope) -> Typed {
        let span = e.span;
        match &e.kind {
            ExprKind::Field(base, f) => {
                if self.indexes_a_variable(e, scope) {
                    let p = self.place_of(e, scope, false)?;
                    let ty = p.ty;
                    return Some((Ex::Load(p), ty));
                }
                let (x, t) = self.expr(base, scope)?;
                let (idx, ft) = self.field_of(t, f)?;
                Some((Ex::Field(Box::new(x), idx), ft))
            }
            ExprKind::Index(base, index) => {
                if self.indexes_a_variable(e, scope) {
                    let p = self.place_of(e, scope, false)?;
                    let ty = p.ty;
                    return Some((Ex::Load(p), ty));
                }
                let b = self.expr(base, scope);
                let i = self.index(index, scope);
                let ((bx, bt), i) = (b?, i?);
                let elem = self.elem_of(bt, span)?;
                Some((Ex::Index(Box::new(bx), Box::new(i), span), elem))
            }
            _ => {
                self.err(
                    span,
                    "a `{...}` list is an initializer: it may only follow `=` in a declaration",
                );
                None
            }
        }
    }

    fn method(
        &mut self,
        recv: &ast::Expr,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let (x, t) = self.expr(recv, scope)?;
        if let (Ty::Struct(si), false) = (t, self.methods.is_empty()) {
            return self.struct_method(si, recv, name, args, span, scope);
        }
        if !t.is_vector() || !args.is_empty() {
            self.err(
                name.span,
                format!(
                    "{} has no method `{}` taking {} argument(s)",
                    self.type_name(t),
                    name.text,
                    args.len()
                ),
            );
            return None;
        }
        match name.text.as_str() {
            "Length" => Some((
                self.round(Ex::Call(Func::Length, vec![x], span), t.scalar()),
                t.scalar(),
            )),
            "Normalized" => Some((self.round(Ex::Call(Func::Normalized, vec![x], span), t), t)),
            "Normalize" => {
                let place = self.place(recv, scope)?;
                Some((
                    Ex::Assign(
                        place,
                        None,
                        Box::new(Ex::Call(Func::Normalized, vec![x], span)),
                        t,
                    ),
                    t,
                ))
            }
            _ => {
                self.err(
                    name.span,
                    format!(
                        "unknown method `{}`: vectors have Length(), Normalize() and Normalized()",
                        name.text
                    ),
                );
                None
            }
        }
    }

    /// `A` that several structs declare: only `S::A` names it. (Out of
    /// `expr_inner`, so that the frame of that recursive function stays
    /// small.)
    #[cold]
    #[inline(never)]
    fn ambiguous_enumerator(&mut self, n: &str, span: Span) -> Typed {
        self.err(
            span,
            format!("more than one struct declares an enumerator `{n}`: write `Struct::{n}`"),
        );
        None
    }
}
