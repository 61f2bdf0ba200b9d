//! The passes over a program's items: the declarations first (structs,
//! typedefs, enums, functions' signatures, modules, and in turtle mode the
//! modules declared by their use), then the globals, directives, axiom,
//! groups, productions, properties and control blocks that make the
//! [`Program`].

use std::collections::HashMap;

use crate::syntax::ast::{self, Init, Item, Section};
use crate::syntax::parse::MAX_NESTING;
use crate::syntax::span::Span;

use crate::lang::builtins::WORD_HOST;
use crate::lang::ir::{Ex, Filter, GlobalVar, Program, PropertyDef};
use crate::lang::modules::Alphabet;
use crate::lang::value::{StructDef, Ty, Value};

use super::{Compiler, Scope, MAX_BODY_VALUES, MAX_DECLARED};

/// The most values a struct may hold, counting those of the structs
/// inside it: every value of the type is built that large.
const MAX_STRUCT_VALUES: usize = 1 << 16;

impl Compiler {
    /// First pass: structs, typedefs and modules, so order does not matter.
    pub(super) fn declarations(&mut self, file: &ast::File) {
        for item in &file.items {
            match item {
                Item::Struct { name, body } => {
                    for (e, variants) in &body.enums {
                        self.enum_decl(e.as_ref(), variants, Some(&name.text));
                    }
                    let fields = &body.fields;
                    if self.struct_names.contains_key(&name.text) {
                        self.err(
                            name.span,
                            format!("struct `{}` is already declared", name.text),
                        );
                        continue;
                    }
                    if self.structs.len() >= MAX_DECLARED {
                        self.too_many(MAX_DECLARED, "structs", name.span);
                        continue;
                    }
                    let mut fs: Vec<(String, Ty)> = Vec::new();
                    let mut index: HashMap<String, u16> = HashMap::new();
                    // The struct itself, then its fields'.
                    let (mut values, mut depth) = (1usize, 1usize);
                    for (t, n, dims) in fields {
                        if index.contains_key(&n.text) {
                            self.err(
                                n.span,
                                format!("struct `{}` already has a field `{}`", name.text, n.text),
                            );
                            continue;
                        }
                        if fs.len() >= MAX_DECLARED {
                            self.err(
                                n.span,
                                format!(
                                    "more than {MAX_DECLARED} fields are declared in struct `{}`",
                                    name.text
                                ),
                            );
                            break;
                        }
                        if let Some(ty) = self
                            .resolve_type(t)
                            .and_then(|ty| self.with_dims(ty, t, dims, None, n.span))
                        {
                            let (v, d) = match ty {
                                Ty::Struct(i) => self.struct_shapes[i as usize],
                                _ => (1, 0),
                            };
                            values = values.saturating_add(v);
                            depth = depth.max(d + 1);
                            if let Some(c) = self.char_array(t, false, n, dims, &Init::None) {
                                self.field_chars
                                    .insert((self.structs.len() as u16, fs.len() as u16), c);
                            }
                            index.insert(n.text.clone(), fs.len() as u16);
                            fs.push((n.text.clone(), ty));
                        }
                    }
                    let problem = if depth > MAX_NESTING {
                        Some(format!(
                            "structs nest more than {MAX_NESTING} levels deep in `{}`",
                            name.text
                        ))
                    } else if values > MAX_STRUCT_VALUES {
                        Some(format!(
                            "struct `{}` holds more than {MAX_STRUCT_VALUES} values, counting those of the structs inside it",
                            name.text
                        ))
                    } else {
                        None
                    };
                    if let Some(m) = problem {
                        // Declared empty, so that its uses are not errors too.
                        self.err(name.span, m);
                        (fs, index, values, depth) = (Vec::new(), HashMap::new(), 1, 1);
                    }
                    self.struct_names
                        .insert(name.text.clone(), self.structs.len() as u16);
                    self.struct_fields.push(index);
                    self.struct_shapes.push((values, depth));
                    self.structs.push(StructDef {
                        name: name.text.clone(),
                        fields: fs,
                        elem: None,
                    });
                    for c in &body.ctors {
                        self.ctor_sig(name, c);
                    }
                    for m in &body.methods {
                        self.method_sig(name, m);
                    }
                }
                Item::Typedef { ty, name } => {
                    if let Some(t) = self.resolve_type(ty) {
                        self.typedefs.insert(name.text.clone(), t);
                    }
                }
                Item::Enum { name, variants } => self.enum_decl(name.as_ref(), variants, None),
                Item::Function(def) => self.function_sig(def),
                Item::Module { name, params } => {
                    if let Some(s) = self.alphabet.lookup(&name.text) {
                        let what = if self.alphabet.get(s).builtin {
                            "is a predefined module and cannot be redeclared"
                        } else {
                            "is already declared"
                        };
                        self.err(name.span, format!("module `{}` {what}", name.text));
                        continue;
                    }
                    let tys: Vec<Ty> = params.iter().filter_map(|p| self.resolve_type(p)).collect();
                    if self.alphabet.kinds.len() >= MAX_DECLARED {
                        let limit = MAX_DECLARED - crate::lang::modules::PREDEFINED.len();
                        self.too_many(limit, "modules", name.span);
                        continue;
                    }
                    if tys.len() == params.len() {
                        self.alphabet.declare(&name.text, tys);
                    }
                }
                _ => {}
            }
        }
    }

    /// Turtle mode (The Algorithmic Beauty of Plants): a module used but not
    /// declared is declared with as many float parameters as its first use.
    pub(super) fn declare_from_use(&mut self, file: &ast::File) {
        fn stmts(ss: &[ast::Stmt], out: &mut Vec<(String, usize)>) {
            for s in ss {
                match s {
                    ast::Stmt::Produce { modules, .. } => {
                        out.extend(modules.iter().map(|m| (m.name.text.clone(), m.args.len())))
                    }
                    ast::Stmt::Block(b) => stmts(&b.stmts, out),
                    ast::Stmt::If { then, els, .. } => {
                        stmts(std::slice::from_ref(then), out);
                        if let Some(e) = els {
                            stmts(std::slice::from_ref(e), out);
                        }
                    }
                    ast::Stmt::While { body, .. }
                    | ast::Stmt::DoWhile { body, .. }
                    | ast::Stmt::For { body, .. } => stmts(std::slice::from_ref(body), out),
                    ast::Stmt::Switch { body, .. } => stmts(body, out),
                    _ => {}
                }
            }
        }
        let mut used: Vec<(String, usize)> = Vec::new();
        for item in &file.items {
            match item {
                Item::Axiom { modules, .. } => {
                    used.extend(modules.iter().map(|m| (m.name.text.clone(), m.args.len())))
                }
                Item::Production(p) => {
                    for m in p
                        .new_left
                        .iter()
                        .chain(&p.left)
                        .chain(&p.strict)
                        .chain(&p.right)
                        .chain(&p.new_right)
                    {
                        used.push((m.name.text.clone(), m.params.len()));
                    }
                    match &p.body {
                        ast::Body::Arrow(succ, _) => {
                            used.extend(succ.iter().map(|m| (m.name.text.clone(), m.args.len())))
                        }
                        ast::Body::Block(b) => stmts(&b.stmts, &mut used),
                    }
                }
                _ => {}
            }
        }
        for (name, arity) in used {
            if self.alphabet.lookup(&name).is_none() {
                if self.alphabet.kinds.len() >= MAX_DECLARED {
                    let limit = MAX_DECLARED - crate::lang::modules::PREDEFINED.len();
                    self.too_many(limit, "modules", Span::default());
                    return;
                }
                let f = self.prec(Ty::Float);
                self.alphabet.declare(&name, vec![f; arity]);
            }
        }
    }

    pub(super) fn rules_and_directives(&mut self, file: &ast::File) -> Program {
        let mut program = Program {
            alphabet: Alphabet::new(),
            structs: Vec::new(),
            globals: Vec::new(),
            functions: Vec::new(),
            axiom: Vec::new(),
            derivation_length: None,
            ring: None,
            decomposition_depth: None,
            interpretation_depth: None,
            angle: None,
            rules: Vec::new(),
            control: Vec::new(),
            gillespie_groups: Vec::new(),
            warnings: Vec::new(),
            model: Default::default(),
            single: self.single,
            properties: Vec::new(),
        };
        self.property_decls(file);
        // Group numbers seen with `group` (false) and `ggroup` (true), and
        // where first.
        let mut group_kinds: Vec<(i64, bool, Span)> = Vec::new();
        let mut section = Section::Productions;
        let mut group = 0i64;
        let mut vgroup = 0i64;
        let mut filter = Filter::All;
        let mut axiom_seen = false;
        for item in &file.items {
            match item {
                Item::Global(decl) => self.global(decl),
                Item::Directive { kind, expr, span } => {
                    let mut scope = Scope::default();
                    let Some((ex, ty)) = self.expr(expr, &mut scope) else {
                        continue;
                    };
                    if !ty.is_numeric() {
                        self.err(
                            expr.span,
                            format!(
                                "expected a number, found a value of type {}",
                                self.type_name(ty)
                            ),
                        );
                        continue;
                    }
                    let slot = match kind {
                        ast::DirectiveKind::DerivationLength => &mut program.derivation_length,
                        ast::DirectiveKind::Angle => &mut program.angle,
                        ast::DirectiveKind::Ring => &mut program.ring,
                        ast::DirectiveKind::MaximumDepth => match section {
                            Section::Interpretation => &mut program.interpretation_depth,
                            _ => &mut program.decomposition_depth,
                        },
                    };
                    if slot.is_some() {
                        self.err(*span, "this directive is given twice");
                    }
                    *slot = Some((ex, *span));
                }
                Item::Axiom { modules, span } => {
                    if axiom_seen {
                        self.err(*span, "the axiom is given twice");
                    }
                    axiom_seen = true;
                    self.check_branches(modules, "the axiom");
                    let mut scope = Scope::default();
                    program.axiom = self.successors(modules, &mut scope);
                }
                Item::ContextFilter {
                    consider, names, ..
                } => {
                    let mut syms = Vec::new();
                    for n in names {
                        match self.alphabet.lookup(&n.text) {
                            Some(s) => syms.push(s),
                            None => self.err(n.span, format!("undeclared module `{}` in the module list; declare it with `module {}(...);`", n.text, n.text)),
                        }
                    }
                    syms.sort();
                    syms.dedup();
                    filter = if names.is_empty() {
                        Filter::All
                    } else if *consider {
                        Filter::Consider(syms.into())
                    } else {
                        Filter::Ignore(syms.into())
                    };
                }
                Item::Section { section: s, .. } => {
                    section = *s;
                    group = 0;
                    vgroup = 0;
                }
                Item::Group {
                    id,
                    gillespie,
                    span,
                } => {
                    group = *id;
                    if *gillespie && *id <= 0 {
                        self.err(
                            *span,
                            "a Gillespie group needs a number greater than 0: group 0 is the default group",
                        );
                    } else if *id != 0 {
                        self.group_kind(*id, *gillespie, *span, &mut group_kinds);
                    }
                }
                Item::VGroup { id, .. } => vgroup = *id,
                Item::Control { kind, body, .. } => {
                    let mut scope = Scope::default();
                    let stmts = self.block_stmts(&body.stmts, &mut scope);
                    program.control.push((*kind, stmts, scope.max as usize));
                }
                Item::Production(p) => {
                    let gillespie = group_kinds.iter().any(|(g, k, _)| *g == group && *k);
                    if gillespie && (!p.new_left.is_empty() || !p.new_right.is_empty()) {
                        self.err(
                            p.span,
                            format!(
                                "a production of a Gillespie group (`ggroup {group}:`) cannot \
                                 have a new context (`<<` or `>>`): a Gillespie step rewrites \
                                 one module in place (manual 7.2)"
                            ),
                        );
                    }
                    if let Some(mut rule) = self.rule(p, section, group, &filter) {
                        rule.vgroup = vgroup;
                        program.rules.push(rule);
                    }
                }
                Item::Property {
                    owner,
                    ty,
                    name,
                    init,
                } => {
                    // The same name may be a property of each owner.
                    let o = self
                        .host
                        .properties
                        .and_then(|ps| ps.owners.iter().position(|n| *n == owner.text));
                    let Some(p) = self
                        .props
                        .iter()
                        .find(|p| Some(p.owner as usize) == o && p.name == name.text)
                    else {
                        continue;
                    };
                    let (owner, pty, index) = (p.owner, p.ty, p.index);
                    let _ = ty;
                    let value = match init {
                        Some(e) => {
                            let mut scope = Scope::default();
                            let Some((x, t)) = self.expr(e, &mut scope) else {
                                continue;
                            };
                            let Some(x) = self.coerce(x, t, pty, e.span) else {
                                continue;
                            };
                            x
                        }
                        None => Ex::Const(Value::zero(pty, &self.structs)),
                    };
                    program.properties.push(PropertyDef {
                        owner,
                        name: name.text.clone(),
                        ty: pty,
                        index,
                        init: value,
                        span: name.span,
                    });
                }
                Item::Module { .. }
                | Item::Struct { .. }
                | Item::Typedef { .. }
                | Item::Enum { .. }
                | Item::Function(_) => {}
            }
        }
        program.gillespie_groups = group_kinds
            .iter()
            .filter(|(_, g, _)| *g)
            .map(|(id, _, span)| (*id, *span))
            .collect();
        program.functions = self.function_bodies(file);
        // A word needs an axiom; other topologies have their structure.
        if !axiom_seen && std::ptr::eq(self.host, &WORD_HOST) {
            let end = file
                .items
                .last()
                .map(|_| Span::default())
                .unwrap_or_default();
            self.err(
                end,
                "the program has no axiom: add a line such as `Axiom: A(1);`",
            );
        }
        program.alphabet = self.alphabet.clone();
        program.structs = self.structs.clone();
        program.globals = std::mem::take(&mut self.globals);
        program
    }

    fn global(&mut self, decl: &ast::VarDecl) {
        let Some(base) = self.resolve_type(&decl.ty) else {
            return;
        };
        for d in &decl.vars {
            let Some(ty) = self.declarator_type(base, &decl.ty, d) else {
                continue;
            };
            let chars = self.char_array(&decl.ty, d.pointer, &d.name, &d.dims, &d.init);
            let mut scope = Scope::default();
            let init = match (ty, &d.init) {
                (Ty::Elem(k), Init::None) => Some(Ex::Const((self.host.zero)(k))),
                _ => self.initializer(ty, &d.init, d.name.span, &mut scope),
            };
            let init = self.fit_init(init, chars.as_ref(), &d.init);
            if scope.max > 0 {
                self.err(d.name.span, "a global initializer cannot declare variables");
            }
            if self.global_names.contains_key(&d.name.text) {
                self.err(
                    d.name.span,
                    format!("`{}` is already declared", d.name.text),
                );
                continue;
            }
            // A variable may be named like a module (`V2f f(6, 0);`): in
            // L+C modules appear only in predecessors, successors and the
            // axiom, variables only in expressions.
            if self.globals.len() >= MAX_DECLARED {
                self.too_many(MAX_DECLARED, "global variables", d.name.span);
                continue;
            }
            self.count_global_values(ty, d.name.span);
            self.global_names
                .insert(d.name.text.clone(), self.globals.len() as u16);
            if let Some(c) = chars {
                self.global_chars.insert(self.globals.len() as u16, c);
            }
            self.globals.push(GlobalVar {
                name: d.name.text.clone(),
                ty,
                is_const: decl.is_const,
                init,
            });
        }
    }

    /// Records group `id` as a Gillespie group or a regular one; the two
    /// kinds share the numbers (manual 7.2), so one number cannot be both.
    fn group_kind(
        &mut self,
        id: i64,
        gillespie: bool,
        span: Span,
        seen: &mut Vec<(i64, bool, Span)>,
    ) {
        if let Some(&(_, was, _)) = seen.iter().find(|(g, _, _)| *g == id) {
            if was != gillespie {
                let (this, other) = if gillespie {
                    ("ggroup", "group")
                } else {
                    ("group", "ggroup")
                };
                self.err(
                    span,
                    format!(
                        "`{this} {id}:` reuses the number of an earlier `{other} {id}:`: a \
                         regular group and a Gillespie group cannot have the same number"
                    ),
                );
            }
            return;
        }
        seen.push((id, gillespie, span));
    }

    /// `enum Kind { A, B = 5, C };`: int constants, and `Kind` an int type.
    /// Declared in struct `S` (`scope`), they are also `S::A` and `S::Kind`,
    /// and `A` alone names them unless another struct declares an `A` too.
    fn enum_decl(
        &mut self,
        name: Option<&ast::Name>,
        variants: &[(ast::Name, Option<ast::Expr>)],
        scope: Option<&str>,
    ) {
        if let Some(n) = name {
            self.typedefs.insert(n.text.clone(), Ty::Int);
            if let Some(s) = scope {
                self.typedefs.insert(format!("{s}::{}", n.text), Ty::Int);
            }
        }
        let mut next = 0i64;
        for (v, value) in variants {
            if let Some(e) = value {
                match self.const_int(e, "an enumerator's value") {
                    Some(x) => next = x,
                    None => continue,
                }
            }
            if let Some(s) = scope {
                let scoped = format!("{s}::{}", v.text);
                if self.enum_consts.contains_key(&scoped) {
                    self.err(v.span, format!("`{scoped}` is already declared"));
                    continue;
                }
                self.enum_consts.insert(scoped, next);
                if self.struct_enums.remove(&v.text) {
                    self.enum_consts.remove(&v.text);
                    self.ambiguous_enums.insert(v.text.clone());
                } else if !self.enum_consts.contains_key(&v.text)
                    && !self.ambiguous_enums.contains(&v.text)
                {
                    self.enum_consts.insert(v.text.clone(), next);
                    self.struct_enums.insert(v.text.clone());
                }
                next = next.wrapping_add(1);
                continue;
            }
            // An enumerator outside structs hides those of structs.
            if self.struct_enums.remove(&v.text) {
                self.enum_consts.remove(&v.text);
            }
            self.ambiguous_enums.remove(&v.text);
            if self.enum_consts.contains_key(&v.text) || self.global_names.contains_key(&v.text) {
                self.err(v.span, format!("`{}` is already declared", v.text));
                continue;
            }
            self.enum_consts.insert(v.text.clone(), next);
            next = next.wrapping_add(1);
        }
    }

    /// Adds a global's (or a `static` local's) values to the program's
    /// total, which is limited as one body's locals are.
    pub(super) fn count_global_values(&mut self, ty: Ty, span: Span) {
        let width = match ty {
            Ty::Struct(i) => self.struct_shapes[i as usize].0,
            _ => 1,
        };
        let before = self.global_values;
        self.global_values = before.saturating_add(width);
        if before <= MAX_BODY_VALUES && self.global_values > MAX_BODY_VALUES {
            self.err(
                span,
                format!(
                    "the global (and static) variables hold more than {MAX_BODY_VALUES} \
                     values (an array counts its elements), the limit"
                ),
            );
        }
    }
}
