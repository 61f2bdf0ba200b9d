//! Statements: blocks, declarations of locals (and `static` locals),
//! loops, `switch`, `break` and `continue`, `return`, and conditions.

use crate::syntax::ast;
use crate::syntax::span::Span;

use crate::lang::ir::{Ex, GlobalVar, St};
use crate::lang::value::{Ty, Value};

use super::{Compiler, Scope, MAX_BODY_VALUES, MAX_DECLARED, MAX_LOCALS};

impl Compiler {
    pub(super) fn block_stmts(&mut self, stmts: &[ast::Stmt], scope: &mut Scope) -> Vec<St> {
        scope.push();
        let mut out = Vec::new();
        for s in stmts {
            self.stmt(s, scope, &mut out);
        }
        scope.pop();
        out
    }

    fn stmt(&mut self, s: &ast::Stmt, scope: &mut Scope, out: &mut Vec<St>) {
        match s {
            ast::Stmt::Expr(e) => {
                if let Some((ex, _)) = self.expr(e, scope) {
                    out.push(St::Expr(ex));
                }
            }
            ast::Stmt::Decl(d) => {
                let Some(base) = self.resolve_type(&d.ty) else {
                    return;
                };
                for v in &d.vars {
                    let Some(ty) = self.declarator_type(base, &d.ty, v) else {
                        continue;
                    };
                    if d.is_static {
                        self.static_local(d, v, ty, scope);
                        continue;
                    }
                    let chars = self.char_array(&d.ty, v.pointer, &v.name, &v.dims, &v.init);
                    let init = self.initializer(ty, &v.init, v.name.span, scope);
                    let init = self.fit_init(init, chars.as_ref(), &v.init);
                    let slot = self.local(scope, &v.name.text, ty, v.name.span);
                    scope.set_chars(chars);
                    if d.is_const {
                        scope.consts.insert(slot);
                    }
                    let value = init.unwrap_or_else(|| match ty {
                        Ty::Elem(k) => match (self.host.fresh)(k) {
                            Some(f) => Ex::Call(f, Vec::new(), v.name.span),
                            None => Ex::Const((self.host.zero)(k)),
                        },
                        _ => Ex::Const(self.zero(ty)),
                    });
                    out.push(St::Init(slot, value));
                }
            }
            ast::Stmt::Forall {
                var,
                set,
                body,
                span,
            } => {
                if let Some(st) = self.forall(var, set, body, *span, scope) {
                    out.push(st);
                }
            }
            ast::Stmt::SetEdit {
                op,
                elem,
                set,
                span,
            } => {
                if let Some(st) = self.set_edit(*op, elem, set, *span, scope) {
                    out.push(st);
                }
            }
            ast::Stmt::If { cond, then, els } => {
                let c = self.condition(cond, scope);
                let t = self.sub_stmt(then, scope);
                let e = els.as_ref().map(|e| Box::new(self.sub_stmt(e, scope)));
                if let Some(c) = c {
                    out.push(St::If(c, Box::new(t), e));
                }
            }
            ast::Stmt::While { cond, body, span } => {
                let c = self.condition(cond, scope);
                scope.loops += 1;
                let b = self.sub_stmt(body, scope);
                scope.loops -= 1;
                if let Some(c) = c {
                    out.push(St::Loop {
                        cond: Some(c),
                        body: Box::new(b),
                        step: None,
                        test_after: false,
                        span: *span,
                    });
                }
            }
            ast::Stmt::DoWhile { body, cond, span } => {
                scope.loops += 1;
                let b = self.sub_stmt(body, scope);
                scope.loops -= 1;
                if let Some(c) = self.condition(cond, scope) {
                    out.push(St::Loop {
                        cond: Some(c),
                        body: Box::new(b),
                        step: None,
                        test_after: true,
                        span: *span,
                    });
                }
            }
            ast::Stmt::For {
                init,
                cond,
                step,
                body,
                span,
            } => {
                scope.push();
                let mut stmts = Vec::new();
                if let Some(i) = init {
                    self.stmt(i, scope, &mut stmts);
                }
                let c = cond.as_ref().and_then(|c| self.condition(c, scope));
                let st = step
                    .as_ref()
                    .and_then(|e| self.expr(e, scope))
                    .map(|(e, _)| e);
                scope.loops += 1;
                let b = self.sub_stmt(body, scope);
                scope.loops -= 1;
                scope.pop();
                stmts.push(St::Loop {
                    cond: c,
                    body: Box::new(b),
                    step: st,
                    test_after: false,
                    span: *span,
                });
                out.push(St::Block(stmts));
            }
            ast::Stmt::Block(b) => out.push(St::Block(self.block_stmts(&b.stmts, scope))),
            ast::Stmt::Produce {
                modules,
                last,
                span,
            } => {
                if !scope.in_rule {
                    let kw = if *last { "produce" } else { "nproduce" };
                    self.err(
                        *span,
                        format!("`{kw}` is only allowed in the body of a production or rule"),
                    );
                    return;
                }
                let modules = self.successors(modules, scope);
                out.push(St::Produce {
                    modules,
                    last: *last,
                });
            }
            ast::Stmt::Return(value, span) => self.return_stmt(value.as_ref(), *span, scope, out),
            ast::Stmt::Switch { value, body, span } => self.switch(value, body, *span, scope, out),
            ast::Stmt::Break(_)
            | ast::Stmt::Continue(_)
            | ast::Stmt::Case(..)
            | ast::Stmt::Default(_) => self.jump(s, scope, out),
            ast::Stmt::Empty => {}
        }
    }

    /// `break`, `continue`, and a `case` or `default` label found outside
    /// a `switch`'s body. (Out of `stmt`, so that the frame of that
    /// recursive function stays small.)
    #[inline(never)]
    fn jump(&mut self, s: &ast::Stmt, scope: &Scope, out: &mut Vec<St>) {
        match s {
            ast::Stmt::Break(span) if scope.loops == 0 && scope.switches == 0 => {
                self.err(*span, "`break` is only allowed inside a loop or a `switch`")
            }
            ast::Stmt::Break(_) => out.push(St::Break),
            ast::Stmt::Continue(span) if scope.loops == 0 => {
                self.err(*span, "`continue` is only allowed inside a loop")
            }
            ast::Stmt::Continue(_) => out.push(St::Continue),
            ast::Stmt::Case(_, span) => self.err(
                *span,
                "a `case` label belongs directly in the body of a `switch`",
            ),
            ast::Stmt::Default(span) => self.err(
                *span,
                "a `default` label belongs directly in the body of a `switch`",
            ),
            _ => {}
        }
    }

    /// `switch (value) { case 1: ... default: ... }`: C's semantics. The
    /// labels are integer constants, each value once; control enters at
    /// the matching label and falls through the labels after it until a
    /// `break`. A label may not jump past a declaration of the body.
    #[inline(never)]
    fn switch(
        &mut self,
        value: &ast::Expr,
        body: &[ast::Stmt],
        span: Span,
        scope: &mut Scope,
        out: &mut Vec<St>,
    ) {
        let checked = self.expr(value, scope).and_then(|(ex, ty)| {
            if matches!(ty, Ty::Int | Ty::Bool) {
                Some(ex)
            } else {
                let found = self.type_name(ty);
                self.err(
                    value.span,
                    format!(
                        "the value of `switch` must be an integer (an int, a char, a bool or an enumerator), found {found}"
                    ),
                );
                None
            }
        });
        scope.push();
        scope.switches += 1;
        let mut stmts: Vec<St> = Vec::new();
        let mut cases: Vec<(i64, u32, Span)> = Vec::new();
        let mut default: Option<(u32, Span)> = None;
        let mut declared: Option<&ast::Name> = None;
        for s in body {
            let at = stmts.len() as u32;
            match s {
                ast::Stmt::Case(e, label) => {
                    let value = self
                        .expr(e, scope)
                        .map(|(ex, _)| match self.const_value(&ex, 0) {
                            Some(Value::Bool(b)) => Some(Value::Int(b as i64)),
                            v => v,
                        });
                    match value {
                        None => {}
                        Some(Some(Value::Int(v))) if cases.iter().any(|c| c.0 == v) => {
                            self.err(
                                e.span,
                                format!("this `case` is {v}, which is already a label of this `switch`"),
                            );
                        }
                        Some(Some(Value::Int(v))) => cases.push((v, at, *label)),
                        Some(_) => self.err(
                            e.span,
                            "a `case` label must be an integer constant: a number, a character, an enumerator or a `const int` global",
                        ),
                    }
                }
                ast::Stmt::Default(label) => {
                    if default.is_some() {
                        self.err(*label, "this `switch` already has a `default` label");
                    } else {
                        default = Some((at, *label));
                    }
                }
                _ => {
                    if let ast::Stmt::Decl(d) = s {
                        declared = declared.or(d.vars.first().map(|v| &v.name));
                    }
                    self.stmt(s, scope, &mut stmts);
                    continue;
                }
            }
            if let Some(name) = declared {
                let label = match s {
                    ast::Stmt::Case(_, l) | ast::Stmt::Default(l) => *l,
                    _ => span,
                };
                self.err(
                    label,
                    format!(
                        "this label jumps past the declaration of `{}`; put the statements of the case in braces `{{ }}`",
                        name.text
                    ),
                );
            }
        }
        scope.switches -= 1;
        scope.pop();
        if let Some(value) = checked {
            let mut cases: Vec<(i64, u32)> = cases.into_iter().map(|c| (c.0, c.1)).collect();
            cases.sort_unstable();
            out.push(St::Switch {
                value,
                cases,
                default: default.map(|d| d.0),
                body: stmts,
            });
        }
    }

    pub(super) fn sub_stmt(&mut self, s: &ast::Stmt, scope: &mut Scope) -> St {
        scope.push();
        let mut v = Vec::new();
        self.stmt(s, scope, &mut v);
        scope.pop();
        if v.len() == 1 {
            v.pop().expect("one")
        } else {
            St::Block(v)
        }
    }

    /// A new local variable, or the error that there are too many, at
    /// `span`.
    pub(super) fn local(&mut self, scope: &mut Scope, name: &str, ty: Ty, span: Span) -> u16 {
        let slot = scope.declare(name, ty);
        if scope.full {
            self.too_many_locals(scope, span);
        }
        let width = match ty {
            Ty::Struct(i) => self.struct_shapes[i as usize].0,
            _ => 1,
        };
        let before = scope.values;
        scope.values = scope.values.saturating_add(width);
        if before <= MAX_BODY_VALUES && scope.values > MAX_BODY_VALUES {
            self.err(
                span,
                format!(
                    "the local variables of this body hold more than {MAX_BODY_VALUES} \
                     values (an array counts its elements), the limit"
                ),
            );
        }
        slot
    }

    pub(super) fn too_many_locals(&mut self, scope: &mut Scope, span: Span) {
        if scope.full && !std::mem::replace(&mut scope.full_reported, true) {
            self.err(
                span,
                format!(
                    "more than {MAX_LOCALS} local variables in one body (parameters, \
                     declarations and inlined functions' arguments); split it into several rules"
                ),
            );
        }
    }

    pub(super) fn condition(&mut self, e: &ast::Expr, scope: &mut Scope) -> Option<Ex> {
        let (ex, ty) = self.expr(e, scope)?;
        self.condition_of(ex, ty, e.span)
    }

    /// `static int n = 0;` in a body: a global that only this body names,
    /// initialised once before the run.
    #[inline(never)]
    fn static_local(&mut self, d: &ast::VarDecl, v: &ast::Declarator, ty: Ty, scope: &mut Scope) {
        let chars = self.char_array(&d.ty, v.pointer, &v.name, &v.dims, &v.init);
        let mut init_scope = Scope::default();
        let init = self.initializer(ty, &v.init, v.name.span, &mut init_scope);
        let init = self.fit_init(init, chars.as_ref(), &v.init);
        if init_scope.max > 0 {
            self.err(
                v.name.span,
                "a static variable's initializer cannot declare variables",
            );
        }
        if self.globals.len() >= MAX_DECLARED {
            self.too_many(MAX_DECLARED, "global variables", v.name.span);
            return;
        }
        self.count_global_values(ty, v.name.span);
        let owner = scope.ret.as_ref().map_or("a body", |(_, n)| n.as_str());
        let slot = self.globals.len() as u16;
        if let Some(c) = chars {
            self.global_chars.insert(slot, c);
        }
        self.globals.push(GlobalVar {
            name: format!("{}::{}", owner, v.name.text),
            ty,
            is_const: d.is_const,
            init,
        });
        scope.bind_static(&v.name.text, ty, slot);
    }

    #[inline(never)]
    fn return_stmt(
        &mut self,
        value: Option<&ast::Expr>,
        span: Span,
        scope: &mut Scope,
        out: &mut Vec<St>,
    ) {
        match (scope.ret.clone(), value) {
            (None, None) | (Some((Ty::Void, _)), None) => out.push(St::Return),
            (None, Some(v)) => self.err(
                v.span,
                "only a function returns a value; a production or a control block ends with a plain `return;`",
            ),
            (Some((Ty::Void, name)), Some(v)) => self.err(
                v.span,
                format!("`{name}` returns void: its `return` takes no value"),
            ),
            (Some((t, name)), None) => {
                let t = self.type_name(t);
                self.err(span, format!("`{name}` returns {t}: `return` needs a value"));
            }
            (Some((t, _)), Some(v)) => {
                if let Some((x, xt)) = self.expr(v, scope) {
                    if let Some(x) = self.coerce(x, xt, t, v.span) {
                        out.push(St::ReturnValue(x));
                    }
                }
            }
        }
    }
}
