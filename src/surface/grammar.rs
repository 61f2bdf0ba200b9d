//! Surface grammars: the rule notation of paper 000, §7, in `.lsys` files.
//!
//! ```text
//! mesh: "lsystems/meshes/octahedron.obj";   // the axiom: a base mesh
//! derivation length: 2;
//! define loop1(v) = 0.5*v + 0.125*sum(w in ring(v) where l(w) == c);
//!
//! F(f) -> V(v = avg(f)) || E^3 F^3                  face split
//! E(e; l(e) == c) | F^2 -> V(v = avg(e)) || E^4 F^4  interior edge split
//! E(e) | F -> V(v = avg(e)) || E^3 F^2              boundary edge split
//! E(e; l(e) < c) | F^2 -> E || F^2                  edge flip
//! V(v; l(v) < c) | interior -> V(v = loop1(v))      vertex rule
//! ```
//!
//! Expressions are the curve language's, with mesh elements as values and
//! neighbourhood sums `sum(w in ring(v) where cond)`.
//!
//! Quad schemes add `blocks: bisection;` (4-8 meshes: a split block's
//! external edges become the next internal edges; the default,
//! `quadrisection`, makes the spokes of the new vertex the next internal
//! edges) and `init:` before a rule that runs once, before the first step:
//!
//! ```text
//! init: E(e; block(e)) | F^2 -> V(v = avg(ring(v))) || E^4 F^4
//! ```
//!
//! `init: match_blocks;`, before the rules, is the one named operation: it
//! pairs the triangles that are in no block into blocks, by a maximum
//! matching of the dual graph (`Mesh::match_blocks`, paper 004's
//! preprocess); the triangles it leaves on the boundary are `lone(e)` for
//! an `init:` boundary split, whose two halves make a block.
//!
//! A 4-8 grammar may add `adaptive;`: its split rules' conditions then
//! select which blocks to split, and the run splits the coarser
//! neighbours a selected block needs first, so that the mesh stays a 4-8
//! mesh (`surface::run`, "Adaptive 4-8 refinement").
//! `adaptive: incremental;` tests, from the second step on, only the
//! diamonds at the vertices made since the step before, so that a step's
//! work follows what the last one made rather than the mesh's size.

use crate::mesh::BlockSplit;
use crate::syntax::ast::Expr;
use crate::syntax::lex::{Tok, Token};
use crate::syntax::parse::Parser;
use crate::syntax::span::{Diagnostic, Span};

/// The element type a rule rewrites.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Face,
    Edge,
    Vertex,
}

/// The stellar operator (or vertex rule) a rule performs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `F -> V || E^3 F^3`
    FaceSplit,
    /// `E | F^2 -> V || E^4 F^4`
    EdgeSplit,
    /// `E | F -> V || E^3 F^2`
    BoundarySplit,
    /// `E | F^2 -> E || F^2`
    Flip,
    /// `V -> V`
    Vertex,
}

/// Which vertices a vertex rule may match.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexContext {
    Any,
    Boundary,
    Interior,
}

#[derive(Clone, Debug)]
pub struct RuleDef {
    pub op: Op,
    /// The predecessor's name (`f`, `e`, `v`).
    pub name: String,
    pub cond: Option<Expr>,
    pub vertex_context: VertexContext,
    /// The successor vertex's name and assignment, if any.
    pub assign: Option<(String, Expr)>,
    pub span: Span,
    /// The rule as written, for messages.
    pub text: String,
    /// Written `init: ...`: runs once, before the first step.
    pub init: bool,
}

pub use crate::syntax::ast::Define as FunctionDef;

#[derive(Clone, Debug, Default)]
pub struct GrammarFile {
    pub mesh: Option<(String, Span)>,
    pub length: Option<Expr>,
    pub functions: Vec<FunctionDef>,
    pub rules: Vec<RuleDef>,
    /// `blocks: bisection;` (4-8 meshes), `blocks: dual;` (Doo-Sabin,
    /// Peters) or `blocks: quadrisection;`.
    pub block_split: Option<(BlockSplit, Span)>,
    /// `init: match_blocks;`: pair the triangles that are in no basic
    /// block by a maximum matching before the `init:` rules run.
    pub match_blocks: Option<Span>,
    /// `adaptive;`: a 4-8 grammar (`blocks: bisection;`) whose split rules
    /// may select some blocks only; the run keeps the mesh a 4-8 mesh by
    /// splitting the coarser neighbours first (see `surface::run`).
    pub adaptive: Option<Span>,
    /// `adaptive: incremental;`: from the second step on, split rules test
    /// only the diamonds at vertices made since the step before.
    pub incremental: bool,
    /// `creasing: chaikin;` or `creasing: uniform;`: how semi-sharp
    /// creases soften from step to step (OpenSubdiv's creasing methods).
    pub creasing: Option<(crate::mesh::Creasing, Span)>,
}

type R<T> = Result<T, Diagnostic>;

/// `^ k` after an element letter; 1 when absent.
fn power(p: &mut Parser) -> R<i64> {
    if p.eat_punct("^") {
        match p.peek().map(|t| &t.tok) {
            Some(Tok::Int(k)) => {
                p.bump();
                Ok(*k)
            }
            _ => p.error("a count after `^`, as in `F^2`"),
        }
    } else {
        Ok(1)
    }
}

/// A successor context such as `E^4 F^4`: the counts of E and F.
fn counts(p: &mut Parser) -> R<(i64, i64)> {
    let (mut e, mut f) = (0, 0);
    while p.peek_ident("E") || p.peek_ident("F") {
        let which = p.name("E or F")?.text;
        let k = power(p)?;
        if which == "E" {
            e += k;
        } else {
            f += k;
        }
    }
    Ok((e, f))
}

/// `name` followed by `:`, as in `mesh:`.
fn at_key(p: &Parser, name: &str) -> bool {
    p.peek_ident(name) && p.peek_at(1).is_some_and(|t| t.tok.is_punct(":"))
}

/// True when a token list is a surface grammar: it has `mesh:` at the start
/// of a line, or a rule whose predecessor is `F(`, `E(` or `V(` with `;` or
/// `)` followed by `->` and a successor context `||`.
pub fn is_surface(toks: &[Token]) -> bool {
    toks.windows(2)
        .any(|w| w[0].line_start && w[0].tok.is_ident("mesh") && w[1].tok.is_punct(":"))
}

/// Parses a surface grammar from preprocessed tokens.
pub fn parse(toks: &[Token], eof: Span, text_of: impl Fn(Span) -> String) -> R<GrammarFile> {
    let mut p = Parser::new(toks, eof);
    let mut g = GrammarFile::default();
    while !p.at_end() {
        if p.eat_punct(";") {
            continue;
        }
        let start = p.span_here();
        if at_key(&p, "mesh") {
            p.bump();
            p.bump();
            let path = match p.peek().map(|t| &t.tok) {
                Some(Tok::Str(s)) => s.clone(),
                _ => {
                    return p
                        .error("the base mesh as a quoted file name, e.g. `mesh: \"cube.obj\";`")
                }
            };
            let span = p.span_here();
            p.bump();
            p.eat_punct(";");
            g.mesh = Some((path, span));
            continue;
        }
        if p.peek_ident("derivation") && p.peek_at(1).is_some_and(|t| t.tok.is_ident("length")) {
            p.bump();
            p.bump();
            p.expect_punct(":", "after `derivation length`")?;
            g.length = Some(p.expr()?);
            p.expect_punct(";", "after the derivation length")?;
            continue;
        }
        if at_key(&p, "blocks") {
            p.bump();
            p.bump();
            let at = p.span_here();
            let how = match p.peek().map(|t| &t.tok) {
                Some(Tok::Ident(w)) if w == "quadrisection" => BlockSplit::Quadrisection,
                Some(Tok::Ident(w)) if w == "bisection" => BlockSplit::Bisection,
                Some(Tok::Ident(w)) if w == "dual" => BlockSplit::Dual,
                _ => return p.error("`quadrisection`, `bisection` or `dual` after `blocks:`"),
            };
            p.bump();
            p.expect_punct(";", "after the block refinement")?;
            g.block_split = Some((how, at));
            continue;
        }
        if at_key(&p, "creasing") {
            p.bump();
            p.bump();
            let at = p.span_here();
            let how = match p.peek().map(|t| &t.tok) {
                Some(Tok::Ident(w)) if w == "uniform" => crate::mesh::Creasing::Uniform,
                Some(Tok::Ident(w)) if w == "chaikin" => crate::mesh::Creasing::Chaikin,
                _ => return p.error("`uniform` or `chaikin` after `creasing:`"),
            };
            p.bump();
            p.expect_punct(";", "after the creasing method")?;
            g.creasing = Some((how, at));
            continue;
        }
        if p.peek_ident("adaptive") && p.peek_at(1).is_some_and(|t| t.tok.is_punct(";")) {
            g.adaptive = Some(p.span_here());
            p.bump();
            p.bump();
            continue;
        }
        if at_key(&p, "adaptive") {
            g.adaptive = Some(p.span_here());
            p.bump();
            p.bump();
            if !p.peek_ident("incremental") {
                return p.error("`incremental` after `adaptive:` (or `adaptive;` alone)");
            }
            p.bump();
            p.expect_punct(";", "after `adaptive: incremental`")?;
            g.incremental = true;
            continue;
        }
        if at_key(&p, "init") {
            p.bump();
            p.bump();
            if p.peek_ident("match_blocks") {
                let at = p.span_here();
                p.bump();
                p.expect_punct(";", "after `match_blocks`")?;
                if g.match_blocks.is_some() {
                    return Err(Diagnostic::new(
                        at,
                        "`init: match_blocks;` is written twice",
                    ));
                }
                if !g.rules.is_empty() {
                    return Err(Diagnostic::new(
                        start,
                        "`init: match_blocks;` pairs the triangles before any rule runs, so it \
                         comes before the rules",
                    ));
                }
                g.match_blocks = Some(at);
                continue;
            }
            let mut r = rule(&mut p, &text_of)?;
            if g.rules.iter().any(|r| !r.init) {
                return Err(Diagnostic::new(
                    start,
                    "`init:` rules run once before the first step, so they come before the other rules",
                ));
            }
            r.init = true;
            g.rules.push(r);
            continue;
        }
        if p.peek_ident("define") {
            g.functions.push(define(&mut p, &g.functions)?);
            continue;
        }
        g.rules.push(rule(&mut p, &text_of)?);
    }
    if g.rules.is_empty() {
        return Err(Diagnostic::new(
            eof,
            "expected at least one rule, e.g. `F(f) -> V(v = avg(f)) || E^3 F^3;`",
        ));
    }
    Ok(g)
}

/// `define name(params) = expr;`, the inline functions of rule files
/// (surface and shape grammars); a name defined above is refused.
pub(crate) fn define(p: &mut Parser, above: &[FunctionDef]) -> R<FunctionDef> {
    let start = p.span_here();
    p.bump();
    let name_span = p.span_here();
    let name = p.name("a function name after `define`")?.text;
    if above.iter().any(|f| f.name == name) {
        return Err(Diagnostic::new(
            name_span,
            format!("function `{name}` is already defined above; give this one another name"),
        ));
    }
    p.expect_punct("(", "after the function name")?;
    let mut params = Vec::new();
    if !p.eat_punct(")") {
        loop {
            let at = p.span_here();
            let param = p.name("a parameter name")?.text;
            if params.contains(&param) {
                return Err(Diagnostic::new(
                    at,
                    format!("`{name}` already has a parameter `{param}`"),
                ));
            }
            params.push(param);
            if p.eat_punct(")") {
                break;
            }
            p.expect_punct(",", "or `)` between parameters")?;
        }
    }
    p.expect_punct("=", "before the function's expression")?;
    let body = p.expr()?;
    p.expect_punct(";", "after the function's expression")?;
    Ok(FunctionDef {
        name,
        params,
        body,
        span: start,
    })
}

/// rule := KIND '(' name [';' cond] ')' [('|' | '||') context] '->' succ ['||' counts] [';']
fn rule(p: &mut Parser, text_of: &impl Fn(Span) -> String) -> R<RuleDef> {
    let start = p.span_here();
    let kind = match p.peek().map(|t| &t.tok) {
        Some(Tok::Ident(k)) if k == "F" => Kind::Face,
        Some(Tok::Ident(k)) if k == "E" => Kind::Edge,
        Some(Tok::Ident(k)) if k == "V" => Kind::Vertex,
        _ => return p.error(
            "a rule starting with F, E or V, `init:`, `define`, `mesh:`, `blocks:`, `creasing:`, \
                 `adaptive;` or `derivation length:`",
        ),
    };
    p.bump();
    p.expect_punct("(", "after the element type")?;
    let name = p.name("the element's name, e.g. `F(f)`")?.text;
    let cond = if p.eat_punct(";") {
        Some(p.expr()?)
    } else {
        None
    };
    p.expect_punct(")", "to close the predecessor")?;
    // The predecessor's context.
    let mut faces = None;
    let mut vertex_context = VertexContext::Any;
    if p.eat_punct("|") || p.eat_punct("||") {
        match kind {
            Kind::Edge => {
                if !p.peek_ident("F") {
                    return p.error(
                        "the faces of the edge, `F` (a boundary edge) or `F^2` (an interior edge)",
                    );
                }
                p.bump();
                faces = Some(power(p)?);
            }
            Kind::Vertex => {
                let w = p.name("`boundary` or `interior`")?.text;
                vertex_context = match w.as_str() {
                    "boundary" => VertexContext::Boundary,
                    "interior" => VertexContext::Interior,
                    _ => {
                        return Err(Diagnostic::new(
                            p.prev_span(),
                            format!(
                            "expected `boundary` or `interior` as a vertex's context, found `{w}`"
                        ),
                        ))
                    }
                };
            }
            Kind::Face => return p.error("`->`: a face rule has no context"),
        }
    }
    p.expect_punct("->", "after the predecessor")?;
    // The successor.
    let succ_span = p.span_here();
    let succ = p.name("the successor, `V` or `E`")?.text;
    let mut assign = None;
    if p.eat_punct("(") {
        let v = p.name("the new vertex's name")?.text;
        p.expect_punct("=", "in the assignment `V(v = ...)`")?;
        let e = p.expr()?;
        p.expect_punct(")", "to close the assignment")?;
        assign = Some((v, e));
    }
    let counts = if p.eat_punct("||") {
        Some(counts(p)?)
    } else {
        None
    };
    let end = p.prev_span();
    p.eat_punct(";");
    let op = match (kind, faces, succ.as_str(), counts) {
        (Kind::Face, None, "V", Some((3, 3))) => Op::FaceSplit,
        (Kind::Edge, Some(2), "V", Some((4, 4))) => Op::EdgeSplit,
        (Kind::Edge, Some(1), "V", Some((3, 2))) => Op::BoundarySplit,
        (Kind::Edge, Some(2), "E", Some((0, 2))) => Op::Flip,
        (Kind::Vertex, _, "V", None) => Op::Vertex,
        _ => {
            return Err(Diagnostic::new(
                start.to(end),
                "this is not one of the rules of paper 000, section 7: expected `F -> V || E^3 F^3`, \
                 `E | F^2 -> V || E^4 F^4`, `E | F -> V || E^3 F^2`, `E | F^2 -> E || F^2` or `V -> V`",
            ))
        }
    };
    if op == Op::Flip && assign.is_some() {
        return Err(Diagnostic::new(
            succ_span,
            "an edge flip makes no vertex, so it has no assignment",
        ));
    }
    let span = start.to(end);
    Ok(RuleDef {
        op,
        name,
        cond,
        vertex_context,
        assign,
        span,
        text: text_of(span),
        init: false,
    })
}
