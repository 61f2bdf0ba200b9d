//! User-defined C functions: their parameter types, signatures (a first
//! pass, so that calls may come before definitions), bodies (the last
//! pass) and calls.

use crate::syntax::ast::{self, ExprKind, Item};
use crate::syntax::span::Span;

use crate::lang::ir::{Ex, Function};
use crate::lang::value::Ty;

use super::{pt_index, Compiler, Scope, Typed, UserSig, MAX_USER_FUNCTIONS};

impl Compiler {
    /// A function's parameter types as its callers see them.
    pub(super) fn param_types(&mut self, def: &ast::FunctionDef) -> Option<Vec<(Ty, bool)>> {
        let mut out = Vec::with_capacity(def.params.len());
        let mut ok = true;
        for p in &def.params {
            let at = p.name.as_ref().map_or(p.ty.span, |n| n.span);
            let Some(mut ty) = self.resolve_type(&p.ty) else {
                ok = false;
                continue;
            };
            let mut by_ref = p.ty.reference;
            if p.ty.pointer {
                match p.ty.name.as_str() {
                    "char" => ty = Ty::Str,
                    "FILE" => ty = Ty::Int,
                    // `float *a`: an array of any length.
                    _ => {
                        ty = match self.array_type(ty, None, at) {
                            Some(t) => t,
                            None => {
                                ok = false;
                                continue;
                            }
                        };
                    }
                }
            }
            if ty == Ty::Void {
                self.err(at, "a parameter cannot have type void");
                ok = false;
                continue;
            }
            match self.with_dims(ty, &p.ty, &p.dims, None, at) {
                Some(t) => ty = t,
                None => {
                    ok = false;
                    continue;
                }
            }
            // C passes arrays as pointers: the callee's writes are the
            // caller's. So are a `char *s` or `char s[]` parameter's
            // (`sprintf(s, ...)` fills the caller's buffer) when the
            // argument is a variable; a `const` one is not written.
            by_ref |= self.is_array(ty) || (ty == Ty::Str && !p.is_const);
            out.push((ty, by_ref));
        }
        ok.then_some(out)
    }

    /// First pass: a function's signature, so that calls may come before
    /// its definition.
    pub(super) fn function_sig(&mut self, def: &ast::FunctionDef) {
        let ret = match self.resolve_type(&def.ret) {
            Some(_) if def.ret.pointer && def.ret.name == "char" => Ty::Str,
            Some(_) if def.ret.pointer && def.ret.name != "FILE" => {
                self.err(def.ret.span, "a function cannot return a pointer here");
                return;
            }
            Some(t) => t,
            None => return,
        };
        let Some(params) = self.param_types(def) else {
            return;
        };
        let name = &def.name;
        if let Some(&id) = self.user_fn_names.get(&name.text) {
            let sig = &self.user_fns[id as usize];
            if sig.params != params || sig.ret != ret {
                self.err(
                    name.span,
                    format!(
                        "`{}` is declared again with other types; functions cannot be overloaded",
                        name.text
                    ),
                );
                return;
            }
            if sig.defined && def.body.is_some() {
                self.err(
                    name.span,
                    format!("function `{}` is defined twice", name.text),
                );
                return;
            }
            if def.body.is_some() {
                let sig = &mut self.user_fns[id as usize];
                sig.defined = true;
                sig.span = name.span;
            }
            return;
        }
        if self.user_fns.len() >= MAX_USER_FUNCTIONS {
            self.too_many(MAX_USER_FUNCTIONS, "functions", name.span);
            return;
        }
        self.user_fn_names
            .insert(name.text.clone(), self.user_fns.len() as u16);
        self.user_fns.push(UserSig {
            name: name.text.clone(),
            params,
            ret,
            span: name.span,
            defined: def.body.is_some(),
        });
    }

    /// Last pass: the functions' bodies, checked with every signature,
    /// global and struct known.
    pub(super) fn function_bodies(&mut self, file: &ast::File) -> Vec<Function> {
        let mut out: Vec<Function> = self
            .user_fns
            .iter()
            .map(|s| Function {
                name: s.name.clone(),
                params: s.params.iter().map(|p| p.0).collect(),
                ret: s.ret,
                body: Vec::new(),
                frame_size: s.params.len(),
                frame_values: 0,
                end: s.span,
                result: None,
                this_back: None,
            })
            .collect();
        for item in &file.items {
            if let Item::Struct { name, body } = item {
                for c in &body.ctors {
                    let id = self.ctors.get(&name.text).and_then(|ids| {
                        ids.iter()
                            .copied()
                            .find(|&id| self.user_fns[id as usize].span == c.name.span)
                    });
                    if let Some(f) = id.and_then(|id| self.ctor_body(name, c, id).map(|f| (id, f)))
                    {
                        out[f.0 as usize] = f.1;
                    }
                }
                for m in &body.methods {
                    let id = self.struct_names.get(&name.text).and_then(|&si| {
                        self.methods
                            .get(&(si, m.name.text.clone()))
                            .copied()
                            .filter(|&id| self.user_fns[id as usize].span == m.name.span)
                    });
                    if let Some(f) = id.and_then(|id| self.method_body(m, id).map(|f| (id, f))) {
                        out[f.0 as usize] = f.1;
                    }
                }
            }
            let Item::Function(def) = item else { continue };
            let Some(body) = &def.body else { continue };
            let Some(&id) = self.user_fn_names.get(&def.name.text) else {
                continue;
            };
            let sig = self.user_fns[id as usize].clone();
            if sig.span != def.name.span {
                continue; // refused as a second definition
            }
            let mut scope = Scope {
                ret: Some((sig.ret, sig.name.clone())),
                ..Scope::default()
            };
            for (p, (t, _)) in def.params.iter().zip(&sig.params) {
                match &p.name {
                    Some(n) => {
                        if scope.lookup(&n.text).is_some() {
                            self.err(
                                n.span,
                                format!("the parameter name `{}` is used twice", n.text),
                            );
                        }
                        self.local(&mut scope, &n.text, *t, n.span);
                    }
                    None => {
                        scope.reserve(1);
                    }
                }
            }
            let stmts = self.block_stmts(&body.stmts, &mut scope);
            let end = body.span.end as usize;
            out[id as usize] = Function {
                name: sig.name.clone(),
                params: sig.params.iter().map(|p| p.0).collect(),
                ret: sig.ret,
                body: stmts,
                frame_size: (scope.max as usize).max(sig.params.len()),
                frame_values: scope.values,
                end: Span::new(body.span.file, end.saturating_sub(1), end),
                result: None,
                this_back: None,
            };
        }
        out
    }

    /// A call of a user-defined function: arguments checked against the
    /// parameters, arrays and references passed as places.
    #[inline(never)]
    pub(super) fn user_call(
        &mut self,
        id: u16,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let sig = self.user_fns[id as usize].clone();
        if args.len() != sig.params.len() {
            let types: Vec<String> = sig.params.iter().map(|p| self.type_name(p.0)).collect();
            self.err(
                span,
                format!(
                    "`{}` takes {} argument(s) ({}), but {} were given",
                    sig.name,
                    sig.params.len(),
                    types.join(", "),
                    args.len()
                ),
            );
            return None;
        }
        if !sig.defined {
            self.err(
                name.span,
                format!(
                    "`{}` is declared but never defined: its body is missing",
                    sig.name
                ),
            );
            return None;
        }
        let mut exs = Vec::with_capacity(args.len());
        let mut back = Vec::new();
        let mut ok = true;
        for (k, (a, &(pt, by_ref))) in args.iter().zip(&sig.params).enumerate() {
            let mismatch = |c: &mut Compiler, found: Ty| {
                let (w, f) = (c.type_name(pt), c.type_name(found));
                c.err(
                    a.span,
                    format!(
                        "type mismatch in argument {} of `{}`: expected {w}, found {f}",
                        k + 1,
                        sig.name
                    ),
                );
            };
            let is_place = matches!(
                a.kind,
                ExprKind::Ident(_) | ExprKind::Field(..) | ExprKind::Index(..)
            );
            // A string argument that is not a variable (a literal, a
            // call) is passed as a value.
            if by_ref && (pt != Ty::Str || is_place) {
                if !is_place {
                    self.err(
                        a.span,
                        format!(
                            "argument {} of `{}` is passed by reference: it must be a variable",
                            k + 1,
                            sig.name
                        ),
                    );
                    ok = false;
                    continue;
                }
                let Some(p) = self.place_of(a, scope, false) else {
                    ok = false;
                    continue;
                };
                let open_array = matches!(pt, Ty::Struct(i) if self.structs[i as usize].elem.is_some()
                    && self.structs[i as usize].fields.is_empty());
                let fits = p.ty == pt
                    || (open_array
                        && matches!(p.ty, Ty::Struct(j)
                            if self.structs[j as usize].elem == self.structs[pt_index(pt)].elem));
                if !fits {
                    mismatch(self, p.ty);
                    ok = false;
                    continue;
                }
                if !self.is_const_place(&p, scope) {
                    back.push((k as u16, p.clone()));
                }
                exs.push(Ex::Load(p));
            } else {
                let Some((x, t)) = self.expr(a, scope) else {
                    ok = false;
                    continue;
                };
                let (x, t) = self.arith(x, t, a.span);
                if !(t == pt || (t.is_numeric() && pt.is_numeric())) {
                    mismatch(self, t);
                    ok = false;
                    continue;
                }
                match self.coerce(x, t, pt, a.span) {
                    Some(x) => exs.push(x),
                    None => ok = false,
                }
            }
        }
        if !ok {
            return None;
        }
        Some((
            Ex::CallUser {
                id,
                args: exs,
                back,
                span,
            },
            sig.ret,
        ))
    }
}
