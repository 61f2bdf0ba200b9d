//! Shape grammars (paper 003): CGA shape's tree of shapes as the fourth
//! topology of the one production model, with paper 003's `Subdivide`.
//!
//! A rule rewrites a shape: a symbol with numeric parameters, attributes,
//! a scope (an oriented box) and a polygon mesh (`geom`). Its guard,
//! probability and every expression of its successor are checked by the
//! language's one checker against [`host::SHAPE_HOST`]; the successor's
//! operations (scope rules, split, repeat, comp, extrude, insert,
//! Subdivide) are the topology's. The schedule is [`run::derive`].
//!
//! **Layer.** It uses `colour`, `deadline`, `lang`, `mesh`, `model`,
//! `production`, `surface`, `syntax`; it is used by `command`, `load`,
//! `system`. Nothing here names a layer above (see ARCHITECTURE.md, "Layers").

pub(crate) mod geom;
pub(crate) mod grammar;
pub(crate) mod host;
pub(crate) mod output;
pub(crate) mod run;
pub(crate) mod smooth;

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::lang::compile::RuleCompiler;
use crate::lang::eval::{Env, Interp};
use crate::lang::ir::Ex;
use crate::lang::value::{Ty, Value};
use crate::mesh::PolygonSoup;
use crate::production::Entry;
use crate::syntax::ast::{Expr, ExprKind};
use crate::syntax::source::Front;
use crate::syntax::span::{Diagnostic, SourceMap, Span};
use crate::syntax::SourceError;

use geom::Selector;
use grammar::{Axis, CompKind, Op, ShapeFile, SizeKind};
use run::smooth_scheme::Scheme;

pub use run::{ShapeError, ShapeOptions, ShapeTree};

/// A checked shape grammar.
#[derive(Debug)]
pub struct ShapeGrammar {
    pub(crate) symbols: Vec<String>,
    pub(crate) rules: Vec<Rule>,
    /// The rules of each symbol, in file order.
    pub(crate) by_symbol: Vec<Vec<usize>>,
    pub(crate) axiom: Vec<COp>,
    pub(crate) axiom_frame: usize,
    pub(crate) attr_base_axiom: usize,
    pub(crate) attr_names: Vec<String>,
    pub(crate) attr_init: Vec<Value>,
    pub(crate) sources: SourceMap,
    pub(crate) warnings: Vec<Diagnostic>,
    /// The schemes `Subdivide` names, loaded once.
    pub(crate) schemes: Vec<Scheme>,
    /// The files the grammar reads: inserted meshes and scheme files, as
    /// found (a command never writes over them).
    pub(crate) inputs: Vec<PathBuf>,
}

#[derive(Debug)]
pub(crate) struct Rule {
    pub params: usize,
    pub cond: Option<X>,
    pub prob: Option<X>,
    pub body: Vec<COp>,
    pub frame: usize,
    pub span: Span,
}

/// A checked expression with the place it was written, for run-time
/// messages.
#[derive(Debug)]
pub(crate) struct X {
    pub ex: Ex,
    pub span: Span,
}

/// An inserted primitive.
#[derive(Debug)]
pub(crate) enum Insert {
    Box,
    Cylinder(X),
    Sphere(X, X),
    /// A mesh file's soup, read once however often the grammar inserts it.
    Mesh(std::sync::Arc<PolygonSoup>),
}

/// A checked successor operation.
#[derive(Debug)]
pub(crate) enum COp {
    Symbol {
        symbol: u32,
        args: Vec<X>,
        span: Span,
    },
    Nil,
    Push,
    Pop(Span),
    /// `t(x, y, z)`; each coordinate absolute, or relative to the scope's
    /// size (`'0.5`).
    Translate([X; 3], [bool; 3], Span),
    Rotate([X; 3], Span),
    Scale([X; 3], [bool; 3], Span),
    Extrude(X, Span),
    Insert(Insert, Span),
    Colour([u8; 3]),
    ColourRgb([X; 3]),
    /// An attribute's slot (from the attributes' base), its new value and
    /// the attribute's type, which the value is converted to (C's
    /// assignment: `true` for 2.5 in a truth value).
    Set(u16, X, Ty),
    SetGroup(Option<std::sync::Arc<str>>),
    Lot(X, X, Span),
    Polygon(Vec<X>, Span),
    Split {
        axis: Axis,
        parts: Vec<CPart>,
        repeat: bool,
        parallel: Option<Vec<X>>,
        span: Span,
    },
    Comp {
        kind: CompKind,
        parts: Vec<(Selector, Span, Vec<COp>)>,
        span: Span,
    },
    Subdivide {
        steps: X,
        /// Its index in [`ShapeGrammar::schemes`].
        scheme: usize,
        body: Vec<COp>,
        span: Span,
    },
}

#[derive(Debug)]
pub(crate) struct CPart {
    pub kind: SizeKind,
    pub size: X,
    pub body: Vec<COp>,
    pub span: Span,
}

/// This topology's entry in the loader's table.
pub(crate) const ENTRY: Entry = Entry {
    claims: is_shapes,
    check: |front, dir| from_front(front, dir).map(|g| Box::new(g) as crate::production::Checked),
};

/// True when preprocessed tokens are a shape grammar.
pub(crate) fn is_shapes(toks: &[crate::syntax::lex::Token]) -> bool {
    grammar::is_shapes(toks)
}

/// Parses and checks a shape grammar; `dir` is the folder inserted mesh
/// files are found in.
pub(crate) fn from_front(front: Front, dir: Option<&Path>) -> Result<ShapeGrammar, SourceError> {
    let eof = front.eof();
    let Front {
        sources, tokens, ..
    } = front;
    let tokens = grammar::shape_tokens(&tokens);
    let col = |s: Span| sources.get(s.file).line_col(s.start as usize).1;
    let text_of = |s: Span| {
        let text = &sources.get(s.file).text;
        let end = (s.end as usize).min(text.len());
        let t = text.get(s.start as usize..end).unwrap_or_default();
        t.split_whitespace().collect::<Vec<_>>().join(" ")
    };
    let file = match grammar::parse(&tokens, eof, col, text_of) {
        Ok(f) => f,
        Err(e) => return Err(SourceError::at(&sources, e)),
    };
    let mut c = Checker {
        rc: RuleCompiler::new(&host::SHAPE_HOST, &file.functions),
        symbols: Vec::new(),
        sym_index: HashMap::new(),
        attrs: Vec::new(),
        diags: Vec::new(),
        warnings: Vec::new(),
        schemes: Vec::new(),
        dir: dir.map(Path::to_path_buf),
        in_part: false,
        inputs: Vec::new(),
        meshes: HashMap::new(),
    };
    let g = c.file(&file);
    let (errs, warns) = c.rc.take_diagnostics();
    c.diags.extend(errs);
    c.warnings.extend(warns);
    if !c.diags.is_empty() {
        c.diags.sort_by_key(|d| (d.span.file.0, d.span.start));
        return Err(SourceError::Program {
            sources,
            diagnostics: c.diags,
        });
    }
    let (rules, axiom, axiom_frame, attr_init) = g.expect("no diagnostics");
    let mut by_symbol = vec![Vec::new(); c.symbols.len()];
    for (i, (sym, _)) in rules.iter().enumerate() {
        by_symbol[*sym as usize].push(i);
    }
    c.warnings.sort_by_key(|d| (d.span.file.0, d.span.start));
    Ok(ShapeGrammar {
        symbols: c.symbols,
        rules: rules.into_iter().map(|(_, r)| r).collect(),
        by_symbol,
        axiom,
        axiom_frame,
        attr_base_axiom: 0,
        attr_names: c.attrs.iter().map(|a| a.0.clone()).collect(),
        attr_init,
        sources,
        warnings: c.warnings,
        schemes: c.schemes,
        inputs: c.inputs,
    })
}

type Checked = (Vec<(u32, Rule)>, Vec<COp>, usize, Vec<Value>);

struct Checker {
    rc: RuleCompiler,
    symbols: Vec<String>,
    sym_index: HashMap<String, u32>,
    /// Name and type of each attribute.
    attrs: Vec<(String, Ty)>,
    diags: Vec<Diagnostic>,
    warnings: Vec<Diagnostic>,
    schemes: Vec<Scheme>,
    dir: Option<PathBuf>,
    in_part: bool,
    inputs: Vec<PathBuf>,
    /// The meshes read so far, by path.
    meshes: HashMap<PathBuf, std::sync::Arc<PolygonSoup>>,
}

/// A constant expression's value, if it is a literal number.
fn literal(e: &Expr) -> Option<f64> {
    match &e.kind {
        ExprKind::Int(i) => Some(*i as f64),
        ExprKind::Float(x, _) => Some(*x),
        _ => None,
    }
}

impl Checker {
    fn symbol(&mut self, name: &str) -> u32 {
        if let Some(&s) = self.sym_index.get(name) {
            return s;
        }
        let s = self.symbols.len() as u32;
        self.symbols.push(name.to_string());
        self.sym_index.insert(name.to_string(), s);
        s
    }

    fn err(&mut self, span: Span, m: impl Into<String>) {
        self.diags.push(Diagnostic::new(span, m));
    }

    fn file(&mut self, f: &ShapeFile) -> Option<Checked> {
        // Attributes: typed by their initial values, evaluated once.
        let mut attr_init = Vec::new();
        self.rc.start_rule();
        for a in &f.attrs {
            let Some((ex, ty)) = self.rc.expr(&a.init) else {
                continue;
            };
            if !matches!(ty, Ty::Int | Ty::Float | Ty::Double | Ty::Bool) {
                self.err(a.init.span, "an attribute holds a number or a truth value");
                continue;
            }
            let frame_len = self.rc.frame_size().max(1) + attr_init.len();
            let mut frame = attr_init.clone();
            frame.resize(frame_len, Value::Void);
            let mut host = host::ShapeHost::default();
            match Interp::new(&[]).eval(
                &ex,
                &mut frame,
                &mut Env::with_model(Vec::new(), crate::model::default_ref()),
                &mut host,
            ) {
                Ok(v) => attr_init.push(v),
                Err(e) => {
                    self.err(e.span.unwrap_or(a.init.span), e.message);
                    continue;
                }
            }
            self.rc.bind(&a.name.text, ty);
            self.attrs.push((a.name.text.clone(), ty));
        }
        // Rule ids are unique (paper 003: "a unique identifier").
        let mut ids: HashMap<i64, Span> = HashMap::new();
        for r in &f.rules {
            if let Some((id, at)) = r.id {
                if ids.insert(id, at).is_some() {
                    self.err(
                        at,
                        format!("rule {id} is numbered above; a rule's id is unique"),
                    );
                }
            }
        }
        // Symbols with rules and their arities.
        let mut arity: HashMap<String, (usize, Span)> = HashMap::new();
        for r in &f.rules {
            match arity.get(&r.symbol.text) {
                Some(&(n, at)) if n != r.params.len() => {
                    let (l, _) = (at, 0);
                    let _ = l;
                    self.err(
                        r.symbol.span,
                        format!(
                            "`{}` has {} parameters in an earlier rule and {} here",
                            r.symbol.text,
                            n,
                            r.params.len()
                        ),
                    );
                }
                Some(_) => {}
                None => {
                    arity.insert(r.symbol.text.clone(), (r.params.len(), r.symbol.span));
                }
            }
            self.symbol(&r.symbol.text);
        }
        // The axiom.
        self.rc.start_rule();
        for (n, t) in self.attrs.clone() {
            self.rc.bind(&n, t);
        }
        let (ops, _) = f.axiom.as_ref()?;
        let axiom = self.ops(ops, &arity);
        let axiom_frame = self.rc.frame_size().max(1);
        // The rules.
        let mut rules = Vec::new();
        for r in &f.rules {
            self.rc.start_rule();
            for p in &r.params {
                self.rc.bind(&p.text, Ty::Double);
            }
            for (n, t) in self.attrs.clone() {
                self.rc.bind(&n, t);
            }
            let cond = r.cond.as_ref().and_then(|e| self.typed(e, Ty::Bool));
            let prob = r.prob.as_ref().and_then(|e| self.typed(e, Ty::Double));
            self.in_part = false;
            let body = self.ops(&r.body, &arity);
            let sym = self.symbol(&r.symbol.text);
            rules.push((
                sym,
                Rule {
                    params: r.params.len(),
                    cond,
                    prob,
                    body,
                    frame: self.rc.frame_size().max(1),
                    span: r.span,
                },
            ));
        }
        // The probabilities of a symbol whose rules all apply always (no
        // condition) and all have literal probabilities must sum to 1:
        // caught before any run. Where a rule has a condition or a
        // computed probability, the sum of the rules that apply is checked
        // when they apply.
        let mut sums: HashMap<&str, (f64, usize, Span)> = HashMap::new();
        let mut unknown: HashSet<&str> = HashSet::new();
        for r in &f.rules {
            match (r.prob.as_ref().map(literal), &r.cond) {
                (Some(Some(p)), None) => {
                    let e = sums.entry(&r.symbol.text).or_insert((0.0, 0, r.span));
                    e.0 += p;
                    e.1 += 1;
                }
                // No probability: the run says that all or none have one.
                (None, None) => {}
                _ => {
                    unknown.insert(&r.symbol.text);
                }
            }
        }
        let mut bad: Vec<_> = sums
            .into_iter()
            .filter(|(sym, (s, _, _))| !unknown.contains(sym) && (s - 1.0).abs() > 1e-9)
            .collect();
        bad.sort_by_key(|(_, (_, _, at))| at.start);
        for (sym, (s, k, at)) in bad {
            self.err(
                at,
                format!(
                    "the probabilities of the {k} rule{} for `{sym}` sum to {s}, not 1",
                    if k == 1 { "" } else { "s" }
                ),
            );
        }
        if !self.diags.is_empty() {
            return None;
        }
        Some((rules, axiom, axiom_frame, attr_init))
    }

    fn ops(&mut self, ops: &[Op], arity: &HashMap<String, (usize, Span)>) -> Vec<COp> {
        let mut out = Vec::with_capacity(ops.len());
        // `NIL` and `Subdivide` end a successor: what follows them would
        // never run, and inside `[ ]` they would end it too.
        let mut depth = 0usize;
        let mut ended: Option<&str> = None;
        for op in ops {
            let (ends, at) = match op {
                Op::Nil(at) => (Some("`NIL`"), *at),
                Op::Subdivide { span, .. } => (Some("`Subdivide`"), *span),
                Op::Push(_) => {
                    depth += 1;
                    (None, Span::default())
                }
                Op::Pop(_) => {
                    depth = depth.saturating_sub(1);
                    (None, Span::default())
                }
                _ => (None, Span::default()),
            };
            if let Some(what) = ended {
                let at = match op {
                    Op::Symbol { name, .. } => name.span,
                    Op::Call { span, .. }
                    | Op::Split { span, .. }
                    | Op::Comp { span, .. }
                    | Op::Subdivide { span, .. }
                    | Op::Pop(span)
                    | Op::Push(span)
                    | Op::Nil(span) => *span,
                };
                self.err(
                    at,
                    format!(
                        "nothing follows {what} in a successor: it ends the shape's rule \
                         (what the shape becomes after `Subdivide` goes in its braces)"
                    ),
                );
                break;
            }
            if let Some(what) = ends {
                if depth > 0 {
                    self.err(
                        at,
                        format!("{what} ends the rule's shape, so it cannot be inside `[ ]`"),
                    );
                }
                ended = Some(what);
            }
            if let Some(c) = self.op(op, arity) {
                out.push(c);
            }
        }
        out
    }

    fn num(&mut self, e: &Expr) -> X {
        let ex = self
            .rc
            .expr_as(e, Ty::Double)
            .unwrap_or(Ex::Const(Value::Float(0.0)));
        X { ex, span: e.span }
    }

    fn typed(&mut self, e: &Expr, ty: Ty) -> Option<X> {
        let ex = self.rc.expr_as(e, ty)?;
        Some(X { ex, span: e.span })
    }

    /// A constant the checker made up (a default argument).
    fn konst(x: f64, span: Span) -> X {
        X {
            ex: Ex::Const(Value::Float(x)),
            span,
        }
    }

    fn three(&mut self, name: &str, args: &[Expr], span: Span) -> Option<[X; 3]> {
        if args.len() != 3 {
            self.err(
                span,
                format!(
                    "`{name}` takes three numbers, x, y and z; this has {}",
                    args.len()
                ),
            );
            return None;
        }
        Some([self.num(&args[0]), self.num(&args[1]), self.num(&args[2])])
    }

    fn op(&mut self, op: &Op, arity: &HashMap<String, (usize, Span)>) -> Option<COp> {
        Some(match op {
            Op::Symbol { name, args } => {
                if let Some(&(n, _)) = arity.get(&name.text) {
                    if n != args.len() {
                        self.err(
                            name.span,
                            format!(
                                "`{}` takes {n} parameters (as its rules say); this gives {}",
                                name.text,
                                args.len()
                            ),
                        );
                    }
                }
                let args = args.iter().map(|a| self.num(a)).collect();
                COp::Symbol {
                    symbol: self.symbol(&name.text),
                    args,
                    span: name.span,
                }
            }
            Op::Nil(_) => COp::Nil,
            Op::Push(_) => COp::Push,
            Op::Pop(s) => COp::Pop(*s),
            Op::Call {
                name,
                args,
                relative,
                span,
            } => {
                let rel: Vec<bool> = relative.iter().map(Option::is_some).collect();
                if !matches!(name.text.as_str(), "t" | "translate" | "s" | "scale") {
                    if let Some(at) = relative.iter().flatten().next() {
                        self.err(
                            *at,
                            format!(
                                "a relative value (`'x`, a fraction of the scope's size) is for \
                                 `t` and `s`, not `{}`",
                                name.text
                            ),
                        );
                        return None;
                    }
                }
                let mut op = self.call(&name.text, args, *span)?;
                if let COp::Translate(_, r, _) | COp::Scale(_, r, _) = &mut op {
                    for (k, slot) in r.iter_mut().enumerate() {
                        *slot = rel.get(k).copied().unwrap_or(false);
                    }
                }
                op
            }
            Op::Split {
                axis,
                parts,
                repeat,
                parallel,
                span,
            } => {
                let was = std::mem::replace(&mut self.in_part, true);
                let parts = parts
                    .iter()
                    .map(|p| CPart {
                        kind: p.kind,
                        size: self.num(&p.size),
                        body: self.ops(&p.body, arity),
                        span: p.span,
                    })
                    .collect();
                self.in_part = was;
                let parallel = parallel.as_ref().map(|fl| {
                    fl.iter()
                        .map(|f| X {
                            ex: self
                                .rc
                                .expr_as(f, Ty::Bool)
                                .unwrap_or(Ex::Const(Value::Bool(true))),
                            span: f.span,
                        })
                        .collect()
                });
                COp::Split {
                    axis: *axis,
                    parts,
                    repeat: *repeat,
                    parallel,
                    span: *span,
                }
            }
            Op::Comp { kind, parts, span } => {
                let was = std::mem::replace(&mut self.in_part, true);
                let mut out = Vec::new();
                for p in parts {
                    let sel = Selector::parse(&p.selector.text);
                    let body = self.ops(&p.body, arity);
                    match sel {
                        Some(s) if *kind == CompKind::Faces || s == Selector::All => {
                            out.push((s, p.selector.span, body))
                        }
                        Some(_) => self.err(
                            p.selector.span,
                            "edges and vertices are selected with `all`",
                        ),
                        None => self.err(
                            p.selector.span,
                            format!(
                                "expected a selector: `all`, `top`, `bottom`, `front`, `back`, \
                                 `left`, `right`, `side`, `vertical` or `horizontal`, found `{}`",
                                p.selector.text
                            ),
                        ),
                    }
                }
                self.in_part = was;
                COp::Comp {
                    kind: *kind,
                    parts: out,
                    span: *span,
                }
            }
            Op::Subdivide {
                steps,
                scheme,
                body,
                span,
            } => {
                if self.in_part {
                    self.err(
                        *span,
                        "`Subdivide` smooths the rule's own shape; inside a split or a \
                         component, give the part a symbol and subdivide in its rule",
                    );
                }
                let steps = self.num(steps);
                let sch = self.scheme(scheme.as_ref())?;
                let body = self.ops(body, arity);
                COp::Subdivide {
                    steps,
                    scheme: sch,
                    body,
                    span: *span,
                }
            }
        })
    }

    /// The scheme a `Subdivide` names, loaded once per grammar: its index
    /// in the grammar's schemes.
    fn scheme(&mut self, s: Option<&(String, Span)>) -> Option<usize> {
        let (name, at) = match s {
            Some((n, at)) => (n.as_str(), *at),
            None => ("sqrt3", Span::default()),
        };
        if let Some(k) = self.schemes.iter().position(|x| x.name == name) {
            return Some(k);
        }
        if !smooth::SCHEME_NAMES.contains(&name) {
            self.inputs.push(scheme_path(name, self.dir.as_deref()));
        }
        let grammar = match load_scheme(name, self.dir.as_deref()) {
            Ok(mut g) => {
                // A smoothing group's faces go back to its shapes, which
                // keep them: a tighter bound than a surface run's.
                g.max_faces = g.max_faces.min(run::MAX_SMOOTH_FACES);
                g
            }
            Err(m) => {
                self.err(at, m);
                return None;
            }
        };
        self.schemes.push(Scheme {
            name: name.to_string(),
            grammar,
        });
        Some(self.schemes.len() - 1)
    }

    fn call(&mut self, name: &str, args: &[Expr], span: Span) -> Option<COp> {
        let n = args.len();
        let want = |c: &mut Checker, k: &str| {
            c.err(span, format!("`{name}` takes {k}; this has {n} arguments"));
            None
        };
        Some(match name {
            "t" | "translate" => COp::Translate(self.three(name, args, span)?, [false; 3], span),
            "r" | "rotate" => COp::Rotate(self.three(name, args, span)?, span),
            "s" | "scale" => COp::Scale(self.three(name, args, span)?, [false; 3], span),
            "extrude" => {
                if n != 1 {
                    return want(self, "one number, the height");
                }
                COp::Extrude(self.num(&args[0]), span)
            }
            "primitiveCube" => {
                if n != 0 {
                    return want(self, "no arguments");
                }
                COp::Insert(Insert::Box, span)
            }
            "primitiveCylinder" => {
                let k = match n {
                    0 => Self::konst(16.0, span),
                    1 => self.num(&args[0]),
                    _ => return want(self, "at most one number, its sides"),
                };
                COp::Insert(Insert::Cylinder(k), span)
            }
            "primitiveSphere" => {
                let (a, b) = match n {
                    0 => (Self::konst(24.0, span), Self::konst(12.0, span)),
                    2 => (self.num(&args[0]), self.num(&args[1])),
                    _ => return want(self, "no arguments, or slices and stacks"),
                };
                COp::Insert(Insert::Sphere(a, b), span)
            }
            "i" | "insert" => {
                let Some(ExprKind::Str(what)) = args.first().map(|a| &a.kind) else {
                    return want(
                        self,
                        "a string: \"box\", \"cylinder\", \"sphere\" or a mesh file",
                    );
                };
                if n != 1 {
                    return want(self, "one string");
                }
                let at = args[0].span;
                match what.as_str() {
                    "box" | "cube" => COp::Insert(Insert::Box, span),
                    "cylinder" => COp::Insert(Insert::Cylinder(Self::konst(16.0, at)), span),
                    "sphere" => COp::Insert(
                        Insert::Sphere(Self::konst(24.0, at), Self::konst(12.0, at)),
                        span,
                    ),
                    file => {
                        let path = match &self.dir {
                            Some(d) => d.join(file),
                            None => PathBuf::from(file),
                        };
                        if path.exists() && !path.is_file() {
                            // A directory, a pipe (which would wait for a
                            // writer forever) or a device.
                            self.err(
                                at,
                                format!(
                                    "cannot insert `{file}`: {} is not a regular file",
                                    path.display()
                                ),
                            );
                            return None;
                        }
                        if let Some(soup) = self.meshes.get(&path) {
                            return Some(COp::Insert(Insert::Mesh(soup.clone()), span));
                        }
                        self.inputs.push(path.clone());
                        match crate::mesh::io::read(&path) {
                            Ok(soup) => {
                                let soup = std::sync::Arc::new(soup);
                                self.meshes.insert(path, soup.clone());
                                COp::Insert(Insert::Mesh(soup), span)
                            }
                            Err(e) => {
                                self.err(at, format!("cannot insert `{file}`: {e}"));
                                return None;
                            }
                        }
                    }
                }
            }
            "color" | "colour" => match args {
                [a] => match &a.kind {
                    ExprKind::Str(s) => match crate::colour::Rgba::parse(s) {
                        Some(c) => COp::Colour([c.0, c.1, c.2]),
                        None => {
                            self.err(
                                a.span,
                                format!("expected a colour such as \"#c04020\", found \"{s}\""),
                            );
                            return None;
                        }
                    },
                    _ => return want(self, "a string \"#rrggbb\" or three numbers from 0 to 1"),
                },
                [_, _, _] => COp::ColourRgb(self.three(name, args, span)?),
                _ => return want(self, "a string \"#rrggbb\" or three numbers from 0 to 1"),
            },
            "set" => {
                let [target, value] = args else {
                    return want(self, "an attribute and its value");
                };
                let ExprKind::Ident(attr) = &target.kind else {
                    self.err(target.span, "expected an attribute's name");
                    return None;
                };
                if attr == "smoothingGroup" {
                    return Some(COp::SetGroup(match &value.kind {
                        ExprKind::Str(s) if s.is_empty() => None,
                        ExprKind::Str(s) => Some(s.as_str().into()),
                        ExprKind::Int(i) => Some(i.to_string().into()),
                        _ => {
                            self.err(
                                value.span,
                                "a smoothing group is named by a string or a whole number",
                            );
                            return None;
                        }
                    }));
                }
                let Some(k) = self.attrs.iter().position(|(a, _)| a == attr) else {
                    self.err(
                        target.span,
                        format!(
                            "`{attr}` is not an attribute; declare it with `attr {attr} = ...;`"
                        ),
                    );
                    return None;
                };
                let ty = self.attrs[k].1;
                let v = self.typed(value, ty)?;
                COp::Set(k as u16, v, ty)
            }
            "lot" => {
                if n != 2 {
                    return want(self, "two numbers, its width (x) and depth (z)");
                }
                COp::Lot(self.num(&args[0]), self.num(&args[1]), span)
            }
            "polygon" => {
                if n < 6 || !n.is_multiple_of(2) {
                    return want(self, "x and z of at least three corners");
                }
                COp::Polygon(args.iter().map(|a| self.num(a)).collect(), span)
            }
            _ => {
                self.err(span, format!("`{name}` is not an operation"));
                return None;
            }
        })
    }
}

/// A subdivision scheme by name: one of the project's own surface grammars
/// (`sqrt3`, `loop`, `catmull-clark`), or a surface grammar file relative
/// to the shape grammar's folder.
fn load_scheme(name: &str, dir: Option<&Path>) -> Result<crate::surface::Grammar, String> {
    if smooth::SCHEME_NAMES.contains(&name) {
        return smooth::scheme(name);
    }
    let path = scheme_path(name, dir);
    if !path.is_file() {
        return Err(format!(
            "`{name}` is not a scheme: use \"sqrt3\", \"loop\", \"catmull-clark\" or a \
             surface grammar file (none is at {})",
            path.display()
        ));
    }
    crate::surface::load_file(&path, &[])
        .map_err(|e| format!("the scheme `{name}` does not load:\n{e}"))
}

/// Where a scheme file named `name` is: relative to the grammar's folder.
fn scheme_path(name: &str, dir: Option<&Path>) -> PathBuf {
    match dir {
        Some(d) => d.join(name),
        None => PathBuf::from(name),
    }
}

/// A unit vector along a scope axis, for tests.
#[allow(dead_code)]
pub(crate) fn axis_vec(a: Axis) -> DVec3 {
    match a {
        Axis::X => DVec3::X,
        Axis::Y => DVec3::Y,
        Axis::Z => DVec3::Z,
    }
}
