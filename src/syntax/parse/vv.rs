//! The statements and queries of vertex-vertex programs (paper 001), read
//! as calls of the topology's built-ins.

use crate::syntax::ast::{Expr, ExprKind, Name, SetEditOp, Stmt};
use crate::syntax::lex::Tok;
use crate::syntax::span::Span;

use super::{PResult, Parser};

impl<'t> Parser<'t> {
    /// The statements of the vertex-vertex algebra (paper 001, Tables 1
    /// and 2), when `word` at the cursor starts one:
    ///
    /// ```text
    /// forall NAME in expr stmt        add expr to expr ;
    /// remove expr from expr ;          merge expr with expr ;
    /// synchronize expr ;               make '{' expr {',' expr} '}' nb_of expr ;
    /// erase expr from expr ;           replace expr with expr in expr ;
    /// splice expr (after | before) expr in expr ;
    /// ```
    ///
    /// The editing statements are calls of the topology's built-ins
    /// (`make(v, a, b, c)`, `erase(x, v)`, …). A word followed by `(` or an
    /// assignment is not a keyword here. Out of `stmt_inner`, so that its
    /// frame stays small.
    #[inline(never)]
    pub(super) fn vv_stmt(&mut self, w: &str) -> PResult<Option<Stmt>> {
        let next = self.peek_at(1).map(|t| &t.tok);
        // A constant after the word is a wrong operand of the statement
        // (`add 3 to S`), for the checker to name, not an expression.
        let operand = matches!(
            next,
            Some(Tok::Ident(_) | Tok::Punct("'") | Tok::Int(_) | Tok::Float { .. } | Tok::Str(_))
        ) || (w == "make" && matches!(next, Some(Tok::Punct("{"))));
        if !operand {
            return Ok(None);
        }
        let span = self.span_here();
        let call =
            |name: &str, args: Vec<Expr>, end: Span| Stmt::Expr(call_of(name, span, args, end));
        let s = match w {
            "forall" => {
                self.pos += 1;
                let var = self.name("the loop variable after `forall`")?;
                if !self.eat_ident("in") {
                    return self.error("`in` after `forall x`");
                }
                let set = match self.set_before_edge() {
                    Some(set) => set,
                    None => self.expr()?,
                };
                let body = Box::new(self.stmt_or_end()?);
                return Ok(Some(Stmt::Forall {
                    var,
                    set,
                    body,
                    span,
                }));
            }
            "add" | "remove" | "merge" => {
                self.pos += 1;
                let elem = self.expr()?;
                let (op, word) = match w {
                    "add" => (SetEditOp::Add, "to"),
                    "remove" => (SetEditOp::Remove, "from"),
                    _ => (SetEditOp::Merge, "with"),
                };
                if !self.eat_ident(word) {
                    return self.error(&format!("`{word}` in `{w} ... {word} ...`"));
                }
                // `merge S with T` changes S: the set edited comes first.
                let other = self.expr()?;
                let (elem, set) = if op == SetEditOp::Merge {
                    (other, elem)
                } else {
                    (elem, other)
                };
                Stmt::SetEdit {
                    op,
                    elem,
                    set,
                    span,
                }
            }
            "synchronize" => {
                self.pos += 1;
                let set = self.expr()?;
                call("synchronize", vec![set], self.prev_span())
            }
            "make" => {
                self.pos += 1;
                self.expect_punct(
                    "{",
                    "after `make`: the neighbours, as in `make {a, b, c} nb_of v`",
                )?;
                let mut args = vec![];
                let mut list = self.args("}")?;
                if !self.eat_ident("nb_of") {
                    return self
                        .error("`nb_of` after the neighbour list, as in `make {a, b, c} nb_of v`");
                }
                args.push(self.expr()?);
                args.append(&mut list);
                call("make", args, self.prev_span())
            }
            "erase" => {
                self.pos += 1;
                let x = self.expr()?;
                if !self.eat_ident("from") {
                    return self.error("`from` in `erase x from v`");
                }
                let v = self.expr()?;
                call("erase", vec![x, v], self.prev_span())
            }
            "replace" => {
                self.pos += 1;
                let a = self.expr()?;
                if !self.eat_ident("with") {
                    return self.error("`with` in `replace a with x in v`");
                }
                let x = self.expr()?;
                if !self.eat_ident("in") {
                    return self.error("`in` in `replace a with x in v`");
                }
                let v = self.expr()?;
                call("replace", vec![a, x, v], self.prev_span())
            }
            "splice" => {
                self.pos += 1;
                let x = self.expr()?;
                let name = if self.eat_ident("after") {
                    "splice_after"
                } else if self.eat_ident("before") {
                    "splice_before"
                } else {
                    return self.error("`after` or `before` in `splice x after a in v`");
                };
                let a = self.expr()?;
                if !self.eat_ident("in") {
                    return self.error("`in` in `splice x after a in v`");
                }
                let v = self.expr()?;
                call(name, vec![x, a, v], self.prev_span())
            }
            _ => return Ok(None),
        };
        if !self.peek_punct("}") {
            self.expect_punct(";", &format!("after the `{w}` statement"))?;
        }
        Ok(Some(s))
    }

    /// The set of `forall x in S (x, y)$w = 1;` or `forall y in 'x (x,
    /// y)$w = 1;`: a name (or `'name`) followed by a parenthesis whose
    /// close is followed by `$` is the set, and the parenthesis is the
    /// body's edge, not a call (a property is never a set to go over).
    fn set_before_edge(&mut self) -> Option<Expr> {
        let old = self.peek().is_some_and(|t| t.tok.is_punct("'"));
        let k = old as usize;
        let (name, span) = match self.peek_at(k).map(|t| (&t.tok, t.span)) {
            Some((Tok::Ident(n), span)) => (n.clone(), span),
            _ => return None,
        };
        if !self.peek_at(k + 1).is_some_and(|t| t.tok.is_punct("(")) {
            return None;
        }
        let mut depth = 0usize;
        let mut j = k + 1;
        loop {
            let t = self.peek_at(j)?;
            if t.tok.is_punct("(") {
                depth += 1;
            } else if t.tok.is_punct(")") {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            j += 1;
        }
        if !self.peek_at(j + 1).is_some_and(|t| t.tok.is_punct("$")) {
            return None;
        }
        let start = self.span_here();
        self.pos += k + 1;
        let ident = Expr {
            kind: ExprKind::Ident(name),
            span,
        };
        Some(if old {
            Expr {
                kind: ExprKind::Call(
                    Name {
                        text: "old".into(),
                        span: start,
                    },
                    vec![ident],
                ),
                span: start.to(span),
            }
        } else {
            ident
        })
    }

    /// The query and selection operations of the vertex-vertex algebra,
    /// when one starts at the cursor: `is x in v`, `valence v`, `any in
    /// v`, `nextto x in v`, `prevto x in v`, each a call of the topology's
    /// built-in (`is_in(x, v)`, `valence(v)`, …); their operands are unary
    /// expressions. A word followed by `(` is a plain call.
    #[inline(never)]
    pub(super) fn vv_query(&mut self) -> PResult<Option<Expr>> {
        let Some(Tok::Ident(w)) = self.peek().map(|t| &t.tok) else {
            return Ok(None);
        };
        let name = match w.as_str() {
            "is" => "is_in",
            "valence" => "valence",
            "any" => "any",
            "nextto" => "nextto",
            "prevto" => "prevto",
            _ => return Ok(None),
        };
        let next = self.peek_at(1).map(|t| &t.tok);
        if !matches!(next, Some(Tok::Ident(_)) | Some(Tok::Punct("'"))) {
            return Ok(None);
        }
        let span = self.bump().span;
        let mut args = Vec::new();
        if name != "any" {
            args.push(self.unary()?);
        }
        if name != "valence" && !self.eat_ident("in") {
            return self.error(&format!("`in` in `{w} ... in v`"));
        }
        if name != "valence" {
            args.push(self.unary()?);
        }
        Ok(Some(call_of(name, span, args, self.prev_span())))
    }
}

/// A call of the built-in `name` written from `span` to `end` (vv's
/// statements and queries are calls of the topology's built-ins).
fn call_of(name: &str, span: Span, args: Vec<Expr>, end: Span) -> Expr {
    Expr {
        kind: ExprKind::Call(
            Name {
                text: name.into(),
                span,
            },
            args,
        ),
        span: span.to(end),
    }
}
