//! Shape grammars (paper 003, CGA shape) in `.lsys` files: the parser.
//!
//! ```text
//! attr floor_h = 3.5;                       // an attribute, inherited by children
//! define third(x) = x / 3;                  // an inline function
//! axiom: lot(30, 20) Lot                    // the initial shape(s)
//!
//! Lot --> extrude(13) Mass                  // CityEngine's notation
//! Mass --> comp(f) { top : Roof | side : Facade }
//! Facade --> split(y) { floor_h : Floor }*
//! 1 : facade(width) : width > 9; ⇝ wall(h/3) window(h/3) wall(h/3) : 0.8
//! ```
//!
//! A rule is `[id :] Symbol[(params)] [: cond [;]] ARROW successor [: prob]`
//! with ARROW one of `-->`, `~>` and `⇝`. It ends at a `;` or where a line
//! starts without indentation, so a long successor continues on indented
//! lines. A successor is a sequence of operations on the current shape and
//! of symbols, each of which makes a child shape from the current one.
//! Expressions are the language's, checked by its one checker; `scope.sx`,
//! `split.index` and their kin are identifiers of the shape host.

use crate::surface::grammar::{define, FunctionDef};
use crate::syntax::ast::{Expr, Name};
use crate::syntax::lex::{Tok, Token};
use crate::syntax::parse::Parser;
use crate::syntax::span::{Diagnostic, Span};

type R<T> = Result<T, Diagnostic>;

/// A scope axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    X,
    Y,
    Z,
}

impl Axis {
    pub fn index(self) -> usize {
        self as usize
    }

    fn parse(s: &str) -> Option<Axis> {
        match s {
            "x" | "X" => Some(Axis::X),
            "y" | "Y" => Some(Axis::Y),
            "z" | "Z" => Some(Axis::Z),
            _ => None,
        }
    }
}

/// How a part of a split is sized.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SizeKind {
    /// `3`: that many units.
    Absolute,
    /// `'0.3`: that fraction of the scope.
    Relative,
    /// `~3`: about that many units; floating parts share what the others
    /// leave, in proportion to their sizes.
    Floating,
}

#[derive(Clone, Debug)]
pub struct Part {
    pub kind: SizeKind,
    pub size: Expr,
    pub body: Vec<Op>,
    pub span: Span,
}

/// Which components `comp` takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompKind {
    Faces,
    Edges,
    Vertices,
}

#[derive(Clone, Debug)]
pub struct CompPart {
    /// `top`, `side`, `all`, ...
    pub selector: Name,
    pub body: Vec<Op>,
}

/// One item of a successor.
#[derive(Clone, Debug)]
pub enum Op {
    /// A child shape with this symbol and parameters, made from the
    /// current shape.
    Symbol { name: Name, args: Vec<Expr> },
    /// `NIL` or `epsilon`: the current shape is removed.
    Nil(Span),
    /// `[`: the current shape is saved ...
    Push(Span),
    /// `]`: ... and restored.
    Pop(Span),
    /// An operation on the current shape: `t`, `r`, `s`, `extrude`, `i`,
    /// `color`, `set`, `lot`, `polygon`, `primitiveCube`, ...
    Call {
        name: Name,
        args: Vec<Expr>,
        /// Which arguments were written relative, `'0.5` (a fraction of the
        /// scope's size, for `t` and `s`).
        relative: Vec<Option<Span>>,
        span: Span,
    },
    /// `split(x) { 1 : A | ~3 : B }`, `*` for a repeat; `psplit(x, 1, 0)`
    /// for a parallel split with its soft-connectivity flags between
    /// neighbouring pieces.
    Split {
        axis: Axis,
        parts: Vec<Part>,
        repeat: bool,
        /// `Some(flags)` for a parallel split: flag i says whether pieces i
        /// and i + 1 are soft-connected.
        parallel: Option<Vec<Expr>>,
        span: Span,
    },
    /// `comp(f) { top : Roof | side : Facade }`.
    Comp {
        kind: CompKind,
        parts: Vec<CompPart>,
        span: Span,
    },
    /// `Subdivide(n) { S }`, `Subdivide(n, "loop") { S }`.
    Subdivide {
        steps: Expr,
        scheme: Option<(String, Span)>,
        body: Vec<Op>,
        span: Span,
    },
}

#[derive(Clone, Debug)]
pub struct RuleDef {
    pub id: Option<(i64, Span)>,
    pub symbol: Name,
    pub params: Vec<Name>,
    pub cond: Option<Expr>,
    pub body: Vec<Op>,
    pub prob: Option<Expr>,
    pub span: Span,
    /// The rule as written, for messages.
    pub text: String,
}

#[derive(Clone, Debug)]
pub struct AttrDef {
    pub name: Name,
    pub init: Expr,
}

#[derive(Clone, Debug, Default)]
pub struct ShapeFile {
    pub attrs: Vec<AttrDef>,
    pub functions: Vec<FunctionDef>,
    pub axiom: Option<(Vec<Op>, Span)>,
    pub rules: Vec<RuleDef>,
}

/// The operations a successor may call by name. Any other name is a
/// symbol.
pub const OPERATIONS: &[&str] = &[
    "t",
    "translate",
    "r",
    "rotate",
    "s",
    "scale",
    "extrude",
    "i",
    "insert",
    "primitiveCube",
    "primitiveCylinder",
    "primitiveSphere",
    "color",
    "colour",
    "set",
    "lot",
    "polygon",
];

/// The names of `split`-like operations, paper 003's and CityEngine's.
fn is_split(s: &str) -> bool {
    matches!(s, "split" | "Split" | "psplit" | "Psplit")
}

/// True when the tokens are a shape grammar: a rule arrow `⇝`, or `-->` or
/// `~>` (adjacent punctuators) outside every bracket. C writes `k-->0`
/// (`k-- > 0`) only inside an expression, so within parentheses or a
/// block: such an arrow does not make an L+C file a shape grammar, where
/// a rule's arrow always stands at the top level.
pub fn is_shapes(toks: &[Token]) -> bool {
    if toks.iter().any(|t| t.tok.is_punct("\u{21DD}")) {
        return true;
    }
    let mut depth = 0i64;
    for (k, t) in toks.iter().enumerate() {
        if t.tok.is_punct("(") || t.tok.is_punct("{") {
            depth += 1;
        } else if t.tok.is_punct(")") || t.tok.is_punct("}") {
            depth -= 1;
        } else if depth <= 0 && arrow_at(&toks[k..]) {
            return true;
        }
    }
    false
}

/// `--` `>` or `~` `>` with nothing between them.
fn arrow_at(w: &[Token]) -> bool {
    w.len() >= 2
        && (w[0].tok.is_punct("--") || w[0].tok.is_punct("~"))
        && w[1].tok.is_punct(">")
        && !w[1].space_before
}

/// The tokens of a shape grammar: an arrow written `-->` or `~>` as one
/// punctuator (so that `x > 1 --> B` is not C's `1--`), and `scope . sx`
/// (`split.index`, `comp.total`, ...) as one identifier, which the shape
/// host names.
pub fn shape_tokens(toks: &[Token]) -> Vec<Token> {
    let mut out: Vec<Token> = Vec::with_capacity(toks.len());
    let mut k = 0;
    while k < toks.len() {
        if arrow_at(&toks[k..]) {
            let mut t = toks[k].clone();
            t.span = t.span.to(toks[k + 1].span);
            t.tok = Tok::Punct(if toks[k].tok.is_punct("~") {
                "~>"
            } else {
                "-->"
            });
            out.push(t);
            k += 2;
            continue;
        }
        if let (Tok::Ident(a), Some(Tok::Ident(b))) =
            (&toks[k].tok, toks.get(k + 2).map(|t| &t.tok))
        {
            if matches!(a.as_str(), "scope" | "split" | "comp" | "shape")
                && toks[k + 1].tok.is_punct(".")
            {
                let mut t = toks[k].clone();
                t.span = t.span.to(toks[k + 2].span);
                t.tok = Tok::Ident(format!("{a}.{b}"));
                out.push(t);
                k += 3;
                continue;
            }
        }
        out.push(toks[k].clone());
        k += 1;
    }
    out
}

struct Cx<'a, F: Fn(Span) -> usize> {
    /// The column of a token, from 1.
    col: &'a F,
}

impl<F: Fn(Span) -> usize> Cx<'_, F> {
    /// Where a rule ends: a token at the start of a line with no
    /// indentation.
    fn at_rule_end(&self, p: &Parser) -> bool {
        match p.peek() {
            None => true,
            Some(t) => t.tok.is_punct(";") || (t.line_start && (self.col)(t.span) == 1),
        }
    }
}

/// Parses a shape grammar from preprocessed tokens (after [`shape_tokens`]).
/// `col` gives a token's column; `text_of` a span's text.
pub fn parse(
    toks: &[Token],
    eof: Span,
    col: impl Fn(Span) -> usize,
    text_of: impl Fn(Span) -> String,
) -> R<ShapeFile> {
    let mut p = Parser::new(toks, eof);
    let cx = Cx { col: &col };
    let mut g = ShapeFile::default();
    while !p.at_end() {
        if p.eat_punct(";") {
            continue;
        }
        let start = p.span_here();
        if p.peek_ident("define") {
            g.functions.push(define(&mut p, &g.functions)?);
            continue;
        }
        if p.peek_ident("attr") {
            p.bump();
            let name = p.name("an attribute name after `attr`")?;
            if let Some(a) = g.attrs.iter().find(|a| a.name.text == name.text) {
                let _ = a;
                return Err(Diagnostic::new(
                    name.span,
                    format!("attribute `{}` is declared above", name.text),
                ));
            }
            p.expect_punct("=", "and the attribute's initial value")?;
            let init = p.expr()?;
            p.expect_punct(";", "after the attribute's initial value")?;
            g.attrs.push(AttrDef { name, init });
            continue;
        }
        if p.peek_ident("axiom") || p.peek_ident("Axiom") {
            p.bump();
            p.expect_punct(":", "after `axiom`")?;
            if g.axiom.is_some() {
                return Err(Diagnostic::new(start, "the grammar has one axiom"));
            }
            let body = successor(&mut p, &cx, true)?;
            if !cx.at_rule_end(&p) {
                return p.error("the end of the axiom: a `;` or a new line at the first column");
            }
            if body.is_empty() {
                return p.error("the initial shape, e.g. `axiom: lot(30, 20) Lot`");
            }
            g.axiom = Some((body, start.to(p.prev_span())));
            continue;
        }
        let mut r = rule(&mut p, &cx)?;
        r.text = text_of(r.span);
        g.rules.push(r);
    }
    if g.axiom.is_none() {
        return Err(Diagnostic::new(
            eof,
            "a shape grammar needs an axiom, e.g. `axiom: lot(30, 20) Lot`",
        ));
    }
    Ok(g)
}

/// The rule arrow: `-->`, `~>` or `⇝`.
fn peek_arrow(p: &Parser) -> bool {
    p.peek_punct("-->") || p.peek_punct("~>") || p.peek_punct("\u{21DD}")
}

fn eat_arrow(p: &mut Parser) -> bool {
    let at = peek_arrow(p);
    if at {
        p.bump();
    }
    at
}

/// rule := [INT ':'] Symbol ['(' params ')'] [':' cond [';']] ARROW successor [':' prob]
fn rule<F: Fn(Span) -> usize>(p: &mut Parser, cx: &Cx<F>) -> R<RuleDef> {
    let start = p.span_here();
    let mut id = None;
    if let (Some(Tok::Int(n)), Some(true)) = (
        p.peek().map(|t| &t.tok),
        p.peek_at(1).map(|t| t.tok.is_punct(":")),
    ) {
        id = Some((*n, p.span_here()));
        p.bump();
        p.bump();
    }
    let symbol = match p.peek().map(|t| &t.tok) {
        Some(Tok::Ident(_)) => p.name("a symbol")?,
        _ => {
            return p.error(
                "a rule such as `Lot --> extrude(10) Mass` or `1 : A : x > 1 ~> B : 0.5`, \
                 or `axiom:`, `attr` or `define`",
            )
        }
    };
    if OPERATIONS.contains(&symbol.text.as_str()) || is_reserved(&symbol.text) {
        return Err(Diagnostic::new(
            symbol.span,
            format!(
                "`{}` is an operation, not a symbol; name the shape otherwise",
                symbol.text
            ),
        ));
    }
    let mut params = Vec::new();
    if p.eat_punct("(") && !p.eat_punct(")") {
        loop {
            let n = p.name("a parameter name")?;
            if params.iter().any(|q: &Name| q.text == n.text) {
                return Err(Diagnostic::new(
                    n.span,
                    format!("`{}` already has a parameter `{}`", symbol.text, n.text),
                ));
            }
            params.push(n);
            if p.eat_punct(")") {
                break;
            }
            p.expect_punct(",", "or `)` between parameters")?;
        }
    }
    let mut cond = None;
    if p.eat_punct(":") {
        cond = Some(p.expr()?);
        p.eat_punct(";");
    }
    if !eat_arrow(p) {
        if cx.at_rule_end(p) {
            return Err(Diagnostic::new(
                symbol.span,
                format!(
                    "`{}` starts a rule, but no `-->`, `~>` or `⇝` follows it before the rule \
                     ends (a line that goes on with a successor is indented)",
                    symbol.text
                ),
            ));
        }
        return p.error("`-->`, `~>` or `⇝` before the successor");
    }
    let body = successor(p, cx, true)?;
    let mut prob = None;
    if p.eat_punct(":") {
        prob = Some(p.expr()?);
    }
    if !cx.at_rule_end(p) {
        return p.error(
            "the end of the rule: a `;`, or a new line that starts at the first column \
             (indent a successor that goes on)",
        );
    }
    p.eat_punct(";");
    Ok(RuleDef {
        id,
        symbol,
        params,
        cond,
        body,
        prob,
        span: start.to(p.prev_span()),
        text: String::new(),
    })
}

fn is_reserved(s: &str) -> bool {
    matches!(
        s,
        "NIL" | "epsilon" | "comp" | "Comp" | "Subdivide" | "subdivide" | "Repeat" | "repeat"
    ) || is_split(s)
}

/// A successor: operations and symbols up to the end of the rule, a `:`
/// (its probability), or, inside braces, a `|` or `}`.
fn successor<F: Fn(Span) -> usize>(p: &mut Parser, cx: &Cx<F>, top: bool) -> R<Vec<Op>> {
    let mut ops = Vec::new();
    loop {
        if top && (cx.at_rule_end(p) || p.peek_punct(":")) {
            break;
        }
        if !top && (p.peek_punct("|") || p.peek_punct("}") || p.at_end()) {
            break;
        }
        if peek_arrow(p) {
            return p.error("an operation or a symbol (a rule's arrow cannot come here)");
        }
        let at = p.span_here();
        if p.eat_punct("[") {
            ops.push(Op::Push(at));
            continue;
        }
        if p.eat_punct("]") {
            ops.push(Op::Pop(at));
            continue;
        }
        let name = match p.peek().map(|t| &t.tok) {
            Some(Tok::Ident(_)) => p.name("an operation or a symbol")?,
            _ => return p.error("an operation (`split`, `extrude`, `t`, ...) or a symbol"),
        };
        let n = name.text.as_str();
        if n == "NIL" || n == "epsilon" {
            ops.push(Op::Nil(name.span));
        } else if is_split(n) {
            ops.push(split(p, name)?);
        } else if n == "Repeat" || n == "repeat" {
            ops.push(repeat(p, name, cx)?);
        } else if n == "comp" || n == "Comp" {
            ops.push(comp(p, name, cx)?);
        } else if n == "Subdivide" || n == "subdivide" {
            // What may follow it is the checker's to say (`Checker::ops`).
            ops.push(subdivide(p, name, cx)?);
        } else if OPERATIONS.contains(&n) {
            p.expect_punct("(", &format!("after `{n}`"))?;
            let (args, relative) = call_args(p)?;
            let span = name.span.to(p.prev_span());
            ops.push(Op::Call {
                name,
                args,
                relative,
                span,
            });
        } else {
            let mut a = Vec::new();
            if p.eat_punct("(") {
                a = args(p)?;
            }
            ops.push(Op::Symbol { name, args: a });
        }
    }
    Ok(ops)
}

/// Arguments after `(`, through `)`.
fn args(p: &mut Parser) -> R<Vec<Expr>> {
    let mut out = Vec::new();
    if p.eat_punct(")") {
        return Ok(out);
    }
    loop {
        out.push(p.expr()?);
        if p.eat_punct(")") {
            return Ok(out);
        }
        p.expect_punct(",", "or `)` between arguments")?;
    }
}

/// An operation's arguments after `(`, through `)`; an argument may be
/// written relative, `'0.5`.
fn call_args(p: &mut Parser) -> R<(Vec<Expr>, Vec<Option<Span>>)> {
    let (mut out, mut rel) = (Vec::new(), Vec::new());
    if p.eat_punct(")") {
        return Ok((out, rel));
    }
    loop {
        let at = p.span_here();
        rel.push(p.eat_punct("'").then_some(at));
        out.push(p.expr()?);
        if p.eat_punct(")") {
            return Ok((out, rel));
        }
        p.expect_punct(",", "or `)` between arguments")?;
    }
}

fn axis(p: &mut Parser) -> R<Axis> {
    let at = p.span_here();
    let n = p.name("an axis, `x`, `y` or `z`")?;
    Axis::parse(&n.text).ok_or_else(|| {
        Diagnostic::new(
            at,
            format!("expected an axis, `x`, `y` or `z`, found `{}`", n.text),
        )
    })
}

/// `split(x) { parts }[*]`, `psplit(x, flags...) { parts }`, and paper
/// 003's `Split(X, 3, ~1) { A | B }` with the sizes in the call.
fn split(p: &mut Parser, name: Name) -> R<Op> {
    p.expect_punct("(", &format!("and an axis after `{}`", name.text))?;
    let ax = axis(p)?;
    let parallel_kw = name.text.eq_ignore_ascii_case("psplit");
    let mut in_call: Vec<(SizeKind, Expr, Span)> = Vec::new();
    let mut flags = Vec::new();
    while p.eat_punct(",") {
        if parallel_kw {
            flags.push(p.expr()?);
        } else {
            in_call.push(size(p)?);
        }
    }
    p.expect_punct(")", "after the split's axis and arguments")?;
    p.expect_punct("{", "and the split's parts, e.g. `{ 1 : A | ~3 : B }`")?;
    let mut parts = Vec::new();
    if in_call.is_empty() {
        loop {
            let (kind, size, at) = size(p)?;
            p.expect_punct(":", "between a part's size and its successor")?;
            let body = inner(p)?;
            parts.push(Part {
                kind,
                size,
                body,
                span: at,
            });
            if p.eat_punct("}") {
                break;
            }
            p.expect_punct("|", "or `}` after a part")?;
        }
    } else {
        let mut k = 0;
        loop {
            let at = p.span_here();
            let body = inner(p)?;
            let Some((kind, size, _)) = in_call.get(k).cloned() else {
                return Err(Diagnostic::new(
                    at,
                    format!(
                        "this split gives {} sizes, so it has {} parts",
                        in_call.len(),
                        in_call.len()
                    ),
                ));
            };
            parts.push(Part {
                kind,
                size,
                body,
                span: at,
            });
            k += 1;
            if p.eat_punct("}") {
                break;
            }
            p.expect_punct("|", "or `}` after a part")?;
        }
        if k != in_call.len() {
            return Err(Diagnostic::new(
                p.prev_span(),
                format!("this split gives {} sizes but {k} parts", in_call.len()),
            ));
        }
    }
    let repeat = p.eat_punct("*");
    let span = name.span.to(p.prev_span());
    Ok(Op::Split {
        axis: ax,
        parts,
        repeat,
        parallel: parallel_kw.then_some(flags),
        span,
    })
}

/// A part's size: `3`, `'0.3`, `~3`.
fn size(p: &mut Parser) -> R<(SizeKind, Expr, Span)> {
    let at = p.span_here();
    let kind = if p.eat_punct("~") {
        SizeKind::Floating
    } else if p.eat_punct("'") {
        SizeKind::Relative
    } else {
        SizeKind::Absolute
    };
    let e = p.expr()?;
    Ok((kind, e, at.to(p.prev_span())))
}

/// A part's successor inside braces, one level deeper: parts nest within
/// the parser's nesting limit, which bounds the recursion of the parse,
/// the checker and the derivation alike.
fn inner(p: &mut Parser) -> R<Vec<Op>> {
    let cx = Cx { col: &|_| 0usize };
    p.descend()?;
    let ops = successor(p, &cx, false);
    p.ascend();
    ops
}

/// paper 003's `Repeat(X, 2) { B }`: as many B of about 2 units as fit.
fn repeat<F: Fn(Span) -> usize>(p: &mut Parser, name: Name, _cx: &Cx<F>) -> R<Op> {
    p.expect_punct("(", "and an axis after `Repeat`")?;
    let ax = axis(p)?;
    p.expect_punct(",", "and a size after the axis")?;
    let at = p.span_here();
    let sz = p.expr()?;
    p.expect_punct(")", "after the repeat's size")?;
    p.expect_punct("{", "and the repeated successor, e.g. `{ B }`")?;
    let body = inner(p)?;
    p.expect_punct("}", "after the repeated successor")?;
    let span = name.span.to(p.prev_span());
    Ok(Op::Split {
        axis: ax,
        parts: vec![Part {
            kind: SizeKind::Floating,
            size: sz,
            body,
            span: at,
        }],
        repeat: true,
        parallel: None,
        span,
    })
}

/// `comp(f) { top : Roof | side : Facade }`.
fn comp<F: Fn(Span) -> usize>(p: &mut Parser, name: Name, _cx: &Cx<F>) -> R<Op> {
    p.expect_punct("(", "and `f`, `e` or `v` after `comp`")?;
    let at = p.span_here();
    let which = p.name("`f`, `e` or `v`")?;
    let kind = match which.text.as_str() {
        "f" | "F" => CompKind::Faces,
        "e" | "E" => CompKind::Edges,
        "v" | "V" => CompKind::Vertices,
        other => {
            return Err(Diagnostic::new(
                at,
                format!("expected `f`, `e` or `v` (faces, edges or vertices), found `{other}`"),
            ))
        }
    };
    p.expect_punct(")", "after the component kind")?;
    p.expect_punct(
        "{",
        "and the components, e.g. `{ top : Roof | side : Facade }`",
    )?;
    let mut parts = Vec::new();
    loop {
        let selector = p.name("a selector (`all`, `top`, `bottom`, `side`, `front`, ...)")?;
        p.expect_punct(":", "after the selector")?;
        let body = inner(p)?;
        parts.push(CompPart { selector, body });
        if p.eat_punct("}") {
            break;
        }
        p.expect_punct("|", "or `}` after a component's successor")?;
    }
    let span = name.span.to(p.prev_span());
    Ok(Op::Comp { kind, parts, span })
}

/// `Subdivide(n) { S }`, `Subdivide(n, "loop") { S }`.
fn subdivide<F: Fn(Span) -> usize>(p: &mut Parser, name: Name, _cx: &Cx<F>) -> R<Op> {
    p.expect_punct("(", "and a number of steps after `Subdivide`")?;
    let steps = p.expr()?;
    let mut scheme = None;
    if p.eat_punct(",") {
        let at = p.span_here();
        match p.peek().map(|t| &t.tok) {
            Some(Tok::Str(s)) => {
                scheme = Some((s.clone(), at));
                p.bump();
            }
            _ => return p.error(
                "a scheme as a string: \"sqrt3\", \"loop\", \"catmull-clark\" or a grammar file",
            ),
        }
    }
    p.expect_punct(")", "after the steps of `Subdivide`")?;
    p.expect_punct("{", "and the successor, e.g. `{ S }`")?;
    let body = inner(p)?;
    p.expect_punct("}", "after the successor")?;
    let span = name.span.to(p.prev_span());
    Ok(Op::Subdivide {
        steps,
        scheme,
        body,
        span,
    })
}
