//! Productions: the predecessor's patterns, the successors (module calls
//! checked against the modules' parameters), the balance of the branches'
//! brackets, and the label a rule is known by.

use crate::syntax::ast::{self, Section};
use crate::syntax::span::{Diagnostic, Span};

use crate::lang::ir::{Ex, Filter, Pattern, Rule, St, Succ};
use crate::lang::modules::{Signature, Sym};
use crate::lang::value::Ty;

use super::constants::fold_unary;
use super::{Compiler, Scope};

impl Compiler {
    pub(super) fn rule(
        &mut self,
        p: &ast::Production,
        section: Section,
        group: i64,
        filter: &Filter,
    ) -> Option<Rule> {
        let mut scope = Scope::rule();
        let mut ok = true;
        let mut pats =
            |c: &mut Compiler, list: &[ast::PatModule], scope: &mut Scope| -> Vec<Pattern> {
                let mut out = Vec::with_capacity(list.len());
                for m in list {
                    match c.pattern(m, scope) {
                        Some(pat) => out.push(pat),
                        None => ok = false,
                    }
                }
                out
            };
        let new_left = pats(self, &p.new_left, &mut scope);
        let left = pats(self, &p.left, &mut scope);
        let strict = pats(self, &p.strict, &mut scope);
        let right = pats(self, &p.right, &mut scope);
        let new_right = pats(self, &p.new_right, &mut scope);
        if !ok {
            // The body's names depend on the predecessor: checking it now
            // would only repeat the predecessor's error.
            return None;
        }
        let body = match &p.body {
            ast::Body::Block(b) => self.block_stmts(&b.stmts, &mut scope),
            ast::Body::Arrow(succ, _) => {
                self.check_branches(succ, "the successor");
                let modules = self.successors(succ, &mut scope);
                vec![St::Produce {
                    modules,
                    last: true,
                }]
            }
        };
        let label = pattern_label(p);
        let mut rule = Rule {
            new_left,
            left,
            strict,
            right,
            new_right,
            filter: filter.clone(),
            body,
            frame_size: scope.max as usize,
            section,
            group,
            vgroup: 0,
            span: p.span,
            label,
            stencil: None,
        };
        rule.stencil = crate::lang::stencil::Stencil::compile(&rule);
        Some(rule)
    }

    /// A predecessor module: each parameter becomes a local of the module's type.
    fn pattern(&mut self, m: &ast::PatModule, scope: &mut Scope) -> Option<Pattern> {
        let (sym, tys, width) = self.module_params(&m.name, m.params.len())?;
        let mut slots = Vec::new();
        for (n, t) in m.params.iter().zip(tys.iter().copied()) {
            if scope.has(&n.text) {
                self.err(
                    n.span,
                    format!(
                        "the parameter name `{}` is used twice in this predecessor",
                        n.text
                    ),
                );
                return None;
            }
            slots.push(self.local(scope, &n.text, t, n.span));
        }
        Some(Pattern {
            sym,
            slots,
            types: tys,
            width,
        })
    }

    /// A warning at a `]` that closes no branch of `modules`, or at the
    /// first `[` that is never closed (`X -> F-[[X]+X]+F[+FX-X`): the
    /// derivation runs, but the turtle's branches are not what was meant.
    pub(super) fn check_branches(&mut self, modules: &[ast::ModuleCall], what: &str) {
        let mut open: Vec<Span> = Vec::new();
        for m in modules {
            match m.name.text.as_str() {
                "SB" | "[" => open.push(m.name.span),
                "EB" | "]" if open.pop().is_none() => {
                    let at = Diagnostic::new(
                        m.name.span,
                        format!("this `]` closes no branch: the brackets of {what} do not balance"),
                    );
                    self.warnings.push(at);
                    return;
                }
                _ => {}
            }
        }
        if let Some(&first) = open.first() {
            let n = open.len();
            let more = if n > 1 {
                format!(" ({n} branches are left open)")
            } else {
                String::new()
            };
            let at = Diagnostic::new(
                first,
                format!("this `[` is never closed: the brackets of {what} do not balance{more}"),
            );
            self.warnings.push(at);
        }
    }

    /// The module `name` and its parameter types for `count` parameters.
    pub(super) fn module_params(
        &mut self,
        name: &ast::Name,
        count: usize,
    ) -> Option<(Sym, Vec<Ty>, Option<usize>)> {
        let Some(sym) = self.alphabet.lookup(&name.text) else {
            let hint = self.module_hint(&name.text);
            let mut m = crate::lang::modules::undeclared(
                &name.text,
                &vec!["float"; count].join(", "),
                &hint,
            );
            if name.text == "Step" && count == 0 {
                // `Step:` is a block only in a vv program.
                m.push_str(
                    "; a `Step:` block belongs to a vertex-vertex program, which declares \
                     its mesh first: `mesh S = \"base.obj\";`",
                );
            }
            self.err(name.span, m);
            return None;
        };
        match &self.alphabet.get(sym).sig {
            Signature::Fixed(tys) => {
                if tys.len() != count {
                    let decl = tys
                        .iter()
                        .map(|t| self.type_name(*t))
                        .collect::<Vec<_>>()
                        .join(", ");
                    self.err(
                        name.span,
                        format!(
                            "module `{}` is declared with {} parameter(s) ({}) but {} are given here",
                            name.text,
                            tys.len(),
                            decl,
                            count
                        ),
                    );
                    return None;
                }
                Some((sym, tys.iter().map(|t| self.prec(*t)).collect(), None))
            }
            Signature::Overloads(ovs) => match ovs.iter().find(|o| o.len() == count) {
                Some(o) => {
                    let w = o
                        .iter()
                        .map(|t| crate::lang::value::width(*t, &self.structs))
                        .sum();
                    Some((sym, o.iter().map(|t| self.prec(*t)).collect(), Some(w)))
                }
                None => {
                    let counts: Vec<String> = ovs.iter().map(|o| o.len().to_string()).collect();
                    self.err(
                        name.span,
                        format!(
                            "predefined module `{}` takes {} parameter(s), but {} are given here",
                            name.text,
                            counts.join(" or "),
                            count
                        ),
                    );
                    None
                }
            },
        }
    }

    pub(super) fn successors(
        &mut self,
        modules: &[ast::ModuleCall],
        scope: &mut Scope,
    ) -> Vec<Succ> {
        // Sized exactly: a program may hold hundreds of thousands of rules.
        let mut out = Vec::with_capacity(modules.len());
        for m in modules {
            let mut args = Vec::with_capacity(m.args.len());
            let mut ok = true;
            for a in &m.args {
                match self.expr(a, scope) {
                    Some(t) => args.push(t),
                    None => ok = false,
                }
            }
            if !ok {
                continue;
            }
            let Some(sym) = self.alphabet.lookup(&m.name.text) else {
                let types: Vec<String> = args.iter().map(|(_, t)| self.type_name(*t)).collect();
                let hint = self.module_hint(&m.name.text);
                self.err(
                    m.name.span,
                    crate::lang::modules::undeclared(&m.name.text, &types.join(", "), &hint),
                );
                continue;
            };
            let candidates: Vec<Vec<Ty>> = match &self.alphabet.get(sym).sig {
                Signature::Fixed(t) => vec![t.clone()],
                Signature::Overloads(o) => o
                    .iter()
                    .map(|v| v.iter().map(|t| self.prec(*t)).collect())
                    .collect(),
            };
            let converts = |w: &Ty, t: &Ty| {
                w == t
                    || (w.is_numeric() && t.is_numeric())
                    || (w.is_vector() && w.dim() == t.dim())
            };
            let fits = |want: &[Ty]| {
                want.len() == args.len() && want.iter().zip(&args).all(|(w, (_, t))| converts(w, t))
            };
            let Some(want) = candidates.iter().find(|w| fits(w)).cloned() else {
                let same_arity = candidates.iter().find(|w| w.len() == args.len());
                match same_arity {
                    Some(want) => {
                        for ((_, t), (w, a)) in args.iter().zip(want.iter().zip(&m.args)) {
                            if !converts(w, t) {
                                self.err(
                                    a.span,
                                    format!(
                                        "type mismatch in argument of `{}`: expected {}, found {}",
                                        m.name.text,
                                        self.type_name(*w),
                                        self.type_name(*t)
                                    ),
                                );
                                break;
                            }
                        }
                    }
                    None => {
                        let counts: Vec<String> =
                            candidates.iter().map(|c| c.len().to_string()).collect();
                        self.err(
                            m.name.span,
                            format!(
                                "module `{}` takes {} parameter(s), but {} are given here",
                                m.name.text,
                                counts.join(" or "),
                                args.len()
                            ),
                        );
                    }
                }
                continue;
            };
            let args = args
                .into_iter()
                .zip(&want)
                .map(|((ex, t), w)| {
                    if t == *w {
                        ex
                    } else {
                        // To a `float` parameter: rounded, as lpfg stores it.
                        fold_unary(Ex::Convert(*w, Box::new(ex)))
                    }
                })
                .collect();
            out.push(Succ {
                sym,
                args,
                types: want,
                span: m.name.span,
            });
        }
        out
    }
}

fn pattern_label(p: &ast::Production) -> String {
    let list = |ms: &[ast::PatModule]| -> String {
        ms.iter()
            .map(|m| {
                if m.name.text == "#" {
                    "#".to_string()
                } else {
                    let ps: Vec<&str> = m.params.iter().map(|n| n.text.as_str()).collect();
                    format!("{}({})", m.name.text, ps.join(","))
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut s = String::new();
    if !p.new_left.is_empty() {
        s += &format!("{} << ", list(&p.new_left));
    }
    if !p.left.is_empty() {
        s += &format!("{} < ", list(&p.left));
    }
    s += &list(&p.strict);
    if !p.right.is_empty() {
        s += &format!(" > {}", list(&p.right));
    }
    if !p.new_right.is_empty() {
        s += &format!(" >> {}", list(&p.new_right));
    }
    s
}
