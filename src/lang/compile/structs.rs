//! Structs' constructors and methods (C++): their signatures, bodies and
//! calls.

use crate::syntax::ast::{self, ExprKind, Init};
use crate::syntax::span::Span;

use crate::lang::ir::{Ex, Function, St};
use crate::lang::value::Ty;

use super::{pt_index, Compiler, Scope, Typed, UserSig, MAX_USER_FUNCTIONS};

impl Compiler {
    /// A constructor of struct `s`: a user function returning the struct.
    /// Constructors of one struct are told apart by their number of
    /// parameters.
    #[inline(never)]
    pub(super) fn ctor_sig(&mut self, s: &ast::Name, c: &ast::Ctor) {
        let Some(&si) = self.struct_names.get(&s.text) else {
            return;
        };
        let def = ast::FunctionDef {
            ret: ast::TypeRef {
                name: s.text.clone(),
                span: s.span,
                pointer: false,
                reference: false,
            },
            name: c.name.clone(),
            params: c.params.clone(),
            body: None,
        };
        let Some(params) = self.param_types(&def) else {
            return;
        };
        let ids = self.ctors.get(&s.text).cloned().unwrap_or_default();
        if ids
            .iter()
            .any(|&id| self.user_fns[id as usize].params.len() == params.len())
        {
            self.err(
                c.name.span,
                format!(
                    "`{}` already has a constructor with {} parameter(s); constructors are told apart only by their number of parameters",
                    s.text,
                    params.len()
                ),
            );
            return;
        }
        if self.user_fns.len() >= MAX_USER_FUNCTIONS {
            self.too_many(MAX_USER_FUNCTIONS, "functions", c.name.span);
            return;
        }
        self.ctors
            .entry(s.text.clone())
            .or_default()
            .push(self.user_fns.len() as u16);
        self.user_fns.push(UserSig {
            name: s.text.clone(),
            params,
            ret: Ty::Struct(si),
            span: c.name.span,
            defined: true,
        });
    }

    /// A constructor's body: the fields are locals, zero (or built by
    /// their own default constructor), that the parameters hide; the
    /// initialiser list sets them in the order they are declared, then the
    /// body runs, and the struct is made of them.
    #[inline(never)]
    pub(super) fn ctor_body(&mut self, s: &ast::Name, c: &ast::Ctor, id: u16) -> Option<Function> {
        let sig = self.user_fns[id as usize].clone();
        let Ty::Struct(si) = sig.ret else {
            return None;
        };
        let fields = self.structs[si as usize].fields.clone();
        let mut scope = Scope {
            ret: Some((Ty::Void, sig.name.clone())),
            ..Scope::default()
        };
        scope.reserve(sig.params.len());
        let mut stmts = Vec::new();
        let mut slots = Vec::with_capacity(fields.len());
        for (name, ty) in &fields {
            let slot = self.local(&mut scope, name, *ty, c.name.span);
            let zero = self.default_value(*ty, c.name.span);
            stmts.push(St::Init(slot, zero));
            slots.push(slot);
        }
        scope.push();
        self.bind_params(&mut scope, &c.params, &sig.params, 0, fields.len());
        let mut inits: Vec<(usize, &ast::Name, &Vec<ast::Expr>, Span)> = Vec::new();
        for (f, args, span) in &c.inits {
            let Some(k) = fields.iter().position(|(n, _)| *n == f.text) else {
                self.err(
                    f.span,
                    format!(
                        "struct `{}` has no field `{}` to initialise",
                        s.text, f.text
                    ),
                );
                continue;
            };
            if inits.iter().any(|i| i.0 == k) {
                self.err(
                    f.span,
                    format!("the field `{}` is initialised twice", f.text),
                );
                continue;
            }
            inits.push((k, f, args, *span));
        }
        // C++ initialises the fields in the order they are declared.
        inits.sort_by_key(|i| i.0);
        for (k, _, args, span) in inits {
            let ty = fields[k].1;
            let value = if args.is_empty() {
                Some(self.default_value(ty, span))
            } else {
                self.initializer(ty, &Init::Ctor(args.clone(), span), span, &mut scope)
            };
            if let Some(v) = value {
                stmts.push(St::Init(slots[k], v));
            }
        }
        stmts.extend(self.block_stmts(&c.body.stmts, &mut scope));
        let end = c.body.span.end as usize;
        Some(Function {
            name: sig.name.clone(),
            params: sig.params.iter().map(|p| p.0).collect(),
            ret: sig.ret,
            body: stmts,
            frame_size: (scope.max as usize).max(sig.params.len()),
            frame_values: scope.values,
            end: Span::new(c.body.span.file, end.saturating_sub(1), end),
            result: Some(Ex::MakeStruct(slots.into_iter().map(Ex::Local).collect())),
            this_back: None,
        })
    }

    /// A method of struct `s`: a user function `S::name` whose first
    /// parameter is the struct, by reference; no overloads.
    #[inline(never)]
    pub(super) fn method_sig(&mut self, s: &ast::Name, m: &ast::FunctionDef) {
        let Some(&si) = self.struct_names.get(&s.text) else {
            return;
        };
        let ret = match self.resolve_type(&m.ret) {
            Some(_) if m.ret.pointer && m.ret.name == "char" => Ty::Str,
            Some(_) if m.ret.pointer => {
                self.err(m.ret.span, "a method cannot return a pointer here");
                return;
            }
            Some(t) => t,
            None => return,
        };
        let this = ast::Param {
            ty: ast::TypeRef {
                name: s.text.clone(),
                span: s.span,
                pointer: false,
                reference: true,
            },
            name: None,
            dims: Vec::new(),
            is_const: false,
        };
        let def = ast::FunctionDef {
            params: std::iter::once(this)
                .chain(m.params.iter().cloned())
                .collect(),
            ..m.clone()
        };
        let Some(params) = self.param_types(&def) else {
            return;
        };
        let key = (si, m.name.text.clone());
        if self.methods.contains_key(&key)
            || self.struct_fields[si as usize].contains_key(&m.name.text)
        {
            self.err(
                m.name.span,
                format!(
                    "struct `{}` already has a member `{}`; methods cannot be overloaded",
                    s.text, m.name.text
                ),
            );
            return;
        }
        if self.user_fns.len() >= MAX_USER_FUNCTIONS {
            self.too_many(MAX_USER_FUNCTIONS, "functions", m.name.span);
            return;
        }
        self.methods.insert(key, self.user_fns.len() as u16);
        self.user_fns.push(UserSig {
            name: format!("{}::{}", s.text, m.name.text),
            params,
            ret,
            span: m.name.span,
            defined: true,
        });
    }

    /// A method's body: the struct is slot 0, the parameters follow; the
    /// fields are locals, read from it first and written back to it when
    /// the body ends, which the caller's variable then receives.
    #[inline(never)]
    pub(super) fn method_body(&mut self, m: &ast::FunctionDef, id: u16) -> Option<Function> {
        let sig = self.user_fns[id as usize].clone();
        let Ty::Struct(si) = sig.params.first()?.0 else {
            return None;
        };
        let body = m.body.as_ref()?;
        let fields = self.structs[si as usize].fields.clone();
        let mut scope = Scope {
            ret: Some((sig.ret, sig.name.clone())),
            ..Scope::default()
        };
        scope.reserve(sig.params.len());
        let mut stmts = Vec::new();
        let mut slots = Vec::with_capacity(fields.len());
        for (k, (name, ty)) in fields.iter().enumerate() {
            let slot = self.local(&mut scope, name, *ty, m.name.span);
            scope.set_chars(self.field_chars.get(&(si, k as u16)).cloned());
            stmts.push(St::Init(slot, Ex::Field(Box::new(Ex::Local(0)), k as u16)));
            slots.push(slot);
        }
        scope.push();
        self.bind_params(&mut scope, &m.params, &sig.params, 1, fields.len());
        stmts.extend(self.block_stmts(&body.stmts, &mut scope));
        let end = body.span.end as usize;
        Some(Function {
            name: sig.name.clone(),
            params: sig.params.iter().map(|p| p.0).collect(),
            ret: sig.ret,
            body: stmts,
            frame_size: (scope.max as usize).max(sig.params.len()),
            frame_values: scope.values,
            end: Span::new(body.span.file, end.saturating_sub(1), end),
            result: None,
            this_back: Some(Ex::MakeStruct(slots.into_iter().map(Ex::Local).collect())),
        })
    }

    /// `v.name(args)` on a struct `v`: its method `name`, `v` passed by
    /// reference.
    #[inline(never)]
    pub(super) fn struct_method(
        &mut self,
        si: u16,
        recv: &ast::Expr,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let sname = self.structs[si as usize].name.clone();
        let Some(&id) = self.methods.get(&(si, name.text.clone())) else {
            self.err(
                name.span,
                format!("struct `{sname}` has no method `{}`", name.text),
            );
            return None;
        };
        let want = self.user_fns[id as usize].params.len() - 1;
        if args.len() != want {
            self.err(
                span,
                format!(
                    "`{sname}::{}` takes {want} argument(s), but {} were given",
                    name.text,
                    args.len()
                ),
            );
            return None;
        }
        if !matches!(
            recv.kind,
            ExprKind::Ident(_) | ExprKind::Field(..) | ExprKind::Index(..)
        ) {
            self.err(
                recv.span,
                "methods are called on a variable here (`leaf.area()`), not on a value made by an expression",
            );
            return None;
        }
        let all: Vec<ast::Expr> = std::iter::once(recv.clone())
            .chain(args.iter().cloned())
            .collect();
        self.user_call(id, name, &all, span, scope)
    }

    /// The struct type that `name` names (not an array's typedef).
    pub(super) fn struct_named(&self, name: &str) -> Option<Ty> {
        match self.struct_names.get(name) {
            Some(&si) => Some(Ty::Struct(si)),
            None => match self.typedefs.get(name) {
                Some(t @ Ty::Struct(si)) if self.structs[*si as usize].elem.is_none() => Some(*t),
                _ => None,
            },
        }
    }

    /// `S(args)` in an expression, `S` naming struct type `ty`: the
    /// constructor of `S` that takes as many arguments; without
    /// constructors, `S()` is zero and `S(a, b)` sets the fields in order.
    #[inline(never)]
    pub(super) fn ctor_call(
        &mut self,
        ty: Ty,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let sname = self.structs[pt_index(ty)].name.clone();
        let Some(ids) = self.ctors.get(&sname).cloned() else {
            if args.is_empty() {
                return Some((self.default_value(ty, span), ty));
            }
            let mut exs = Vec::new();
            for a in args {
                exs.push(self.expr(a, scope)?);
            }
            return self.construct(ty, exs, args, span).map(|ex| (ex, ty));
        };
        match ids
            .iter()
            .copied()
            .find(|&id| self.user_fns[id as usize].params.len() == args.len())
        {
            Some(id) => self.user_call(id, name, args, span, scope),
            None => {
                let mut counts: Vec<usize> = ids
                    .iter()
                    .map(|&id| self.user_fns[id as usize].params.len())
                    .collect();
                counts.sort_unstable();
                let counts: Vec<String> = counts.iter().map(|c| c.to_string()).collect();
                self.err(
                    span,
                    format!(
                        "`{sname}` has no constructor that takes {} argument(s); its constructors take {}",
                        args.len(),
                        counts.join(" or ")
                    ),
                );
                None
            }
        }
    }

    /// Binds the named parameters of a constructor or a method, which
    /// follow its struct's `fields` field locals in `scope`: parameter `k`
    /// lives in slot `first + k` with the type `types[first + k]`; a name
    /// given twice is an error.
    fn bind_params(
        &mut self,
        scope: &mut Scope,
        params: &[ast::Param],
        types: &[(Ty, bool)],
        first: usize,
        fields: usize,
    ) {
        for (k, p) in params.iter().enumerate() {
            if let Some(n) = &p.name {
                if scope.vars[fields..].iter().any(|v| v.0 == n.text) {
                    self.err(
                        n.span,
                        format!("the parameter name `{}` is used twice", n.text),
                    );
                }
                scope.bind(&n.text, types[first + k].0, (first + k) as u16);
            }
        }
    }
}
