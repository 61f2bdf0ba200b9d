//! Expressions: assignments, conditionals, binary operators by precedence,
//! unary and postfix operators, primaries, and argument lists.

use crate::syntax::ast::{BinOp, ContextKind, Expr, ExprKind, Name, UnOp};
use crate::syntax::lex::{Tok, Token};
use crate::syntax::span::Diagnostic;

use super::{PResult, Parser};

impl<'t> Parser<'t> {
    pub fn expr(&mut self) -> PResult<Expr> {
        self.assign_expr()
    }

    /// assign := cond [ ('=' | '+=' | '-=' | '*=' | '/=' | '%=' | '<<=' | '>>=') assign ]
    pub(super) fn assign_expr(&mut self) -> PResult<Expr> {
        let outer = self.measure();
        let lhs = self.cond_expr()?;
        let reached = self.reached(outer);
        let op = match self.peek().map(|t| &t.tok) {
            Some(Tok::Punct("=")) => Some(None),
            Some(Tok::Punct("+=")) => Some(Some(BinOp::Add)),
            Some(Tok::Punct("-=")) => Some(Some(BinOp::Sub)),
            Some(Tok::Punct("*=")) => Some(Some(BinOp::Mul)),
            Some(Tok::Punct("/=")) => Some(Some(BinOp::Div)),
            Some(Tok::Punct("%=")) => Some(Some(BinOp::Rem)),
            Some(Tok::Punct("<<=")) => Some(Some(BinOp::Shl)),
            Some(Tok::Punct(">>=")) => Some(Some(BinOp::Shr)),
            _ => None,
        };
        if let Some(op) = op {
            self.wrap(reached, self.span_here())?;
            self.pos += 1;
            self.descend()?;
            let rhs = self.assign_expr()?;
            self.ascend();
            let span = lhs.span.to(rhs.span);
            return Ok(Expr {
                kind: ExprKind::Assign(op, Box::new(lhs), Box::new(rhs)),
                span,
            });
        }
        Ok(lhs)
    }

    /// cond := binary(0) [ '?' expr ':' cond ]
    pub(super) fn cond_expr(&mut self) -> PResult<Expr> {
        let outer = self.measure();
        let c = self.binary(0)?;
        let reached = self.reached(outer);
        if self.peek_punct("?") {
            self.wrap(reached, self.span_here())?;
            self.pos += 1;
            self.descend()?;
            let a = self.expr()?;
            self.expect_punct(":", "in the conditional expression `c ? a : b`")?;
            let b = self.cond_expr()?;
            self.ascend();
            let span = c.span.to(b.span);
            return Ok(Expr {
                kind: ExprKind::Cond(Box::new(c), Box::new(a), Box::new(b)),
                span,
            });
        }
        Ok(c)
    }

    /// Precedence climbing over the C binary operators. A chain `a + b +
    /// c` is a left-deep tree: each operator moves what came before it one
    /// level down.
    fn binary(&mut self, min_prec: u8) -> PResult<Expr> {
        let outer = self.measure();
        let mut lhs = self.unary()?;
        let mut reached = self.reached(outer);
        loop {
            let Some((op, prec)) = self.peek().and_then(|t| binop_of(&t.tok)) else {
                return Ok(lhs);
            };
            if prec < min_prec {
                return Ok(lhs);
            }
            reached = self.wrap(reached, self.span_here())?;
            self.pos += 1;
            let outer = self.measure();
            self.descend()?;
            let rhs = self.binary(prec + 1)?;
            self.ascend();
            reached = reached.max(self.reached(outer));
            let span = lhs.span.to(rhs.span);
            lhs = Expr {
                kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                span,
            };
        }
    }

    /// unary := ('-' | '+' | '!' | '++' | '--') unary | '(' TYPE ')' unary | postfix
    ///
    /// Every operand goes through here, one level below its parent.
    pub(super) fn unary(&mut self) -> PResult<Expr> {
        self.descend()?;
        let r = self.unary_inner();
        self.ascend();
        r
    }

    fn unary_inner(&mut self) -> PResult<Expr> {
        let Some(t) = self.peek() else {
            return self.error("an expression");
        };
        let start = t.span;
        let op = match &t.tok {
            Tok::Punct("-") => Some(UnOp::Neg),
            Tok::Punct("+") => Some(UnOp::Plus),
            Tok::Punct("!") => Some(UnOp::Not),
            _ => None,
        };
        if let Some(op) = op {
            self.pos += 1;
            let e = self.unary()?;
            let span = start.to(e.span);
            return Ok(Expr {
                kind: ExprKind::Unary(op, Box::new(e)),
                span,
            });
        }
        if self.vv {
            if let Some(e) = self.vv_query()? {
                return Ok(e);
            }
        }
        if t.tok.is_punct("++") || t.tok.is_punct("--") {
            self.pos += 1;
            let e = self.unary()?;
            let span = start.to(e.span);
            return Ok(Expr {
                kind: ExprKind::IncDec {
                    target: Box::new(e),
                    delta: if t.tok.is_punct("++") { 1 } else { -1 },
                    prefix: true,
                },
                span,
            });
        }
        // A cast: `(int) expr`
        if t.tok.is_punct("(") {
            if let (
                Some(Token {
                    tok: Tok::Ident(n), ..
                }),
                Some(close),
            ) = (self.peek_at(1), self.peek_at(2))
            {
                if close.tok.is_punct(")") && self.is_type_name(n) {
                    self.pos += 1;
                    let ty = self.type_ref()?;
                    self.pos += 1;
                    let e = self.unary()?;
                    let span = start.to(e.span);
                    return Ok(Expr {
                        kind: ExprKind::Cast(ty, Box::new(e)),
                        span,
                    });
                }
            }
        }
        self.postfix()
    }

    /// postfix := primary { '.' NAME [ '(' args ')' ] | '++' | '--' }, a
    /// left-deep chain like a binary operator's.
    fn postfix(&mut self) -> PResult<Expr> {
        let outer = self.measure();
        let mut e = self.primary()?;
        let mut reached = self.reached(outer);
        loop {
            if self.peek_punct(".")
                || self.peek_punct("++")
                || self.peek_punct("--")
                || self.peek_punct("[")
            {
                reached = self.wrap(reached, self.span_here())?;
            }
            if self.vv && self.peek_punct("$") {
                reached = self.wrap(reached, self.span_here())?;
                self.pos += 1;
                let name = self.name("a property name after `$`, as in `v$pos`")?;
                let span = e.span.to(name.span);
                e = Expr {
                    kind: ExprKind::Prop(Box::new(e), name),
                    span,
                };
            } else if self.peek_punct("[") {
                let (indexed, r) = self.index_of(e)?;
                e = indexed;
                reached = reached.max(r);
            } else if self.eat_punct(".") {
                let name = self.name("a field or method name after `.`")?;
                if self.eat_punct("(") {
                    let outer = self.measure();
                    let args = self.args(")")?;
                    reached = reached.max(self.reached(outer));
                    let span = e.span.to(self.prev_span());
                    e = Expr {
                        kind: ExprKind::Method(Box::new(e), name, args),
                        span,
                    };
                } else {
                    let span = e.span.to(name.span);
                    e = Expr {
                        kind: ExprKind::Field(Box::new(e), name),
                        span,
                    };
                }
            } else if self.peek_punct("++") || self.peek_punct("--") {
                let t = self.bump();
                let span = e.span.to(t.span);
                e = Expr {
                    kind: ExprKind::IncDec {
                        target: Box::new(e),
                        delta: if t.tok.is_punct("++") { 1 } else { -1 },
                        prefix: false,
                    },
                    span,
                };
            } else {
                return Ok(e);
            }
        }
    }

    /// `e[i]`: the index of `e`, at `[`; with the deepest level the index
    /// reached. Out of `postfix`, so that its frame stays small.
    #[inline(never)]
    fn index_of(&mut self, e: Expr) -> PResult<(Expr, usize)> {
        self.pos += 1;
        let outer = self.measure();
        self.descend()?;
        let index = self.expr();
        self.ascend();
        let index = index?;
        let reached = self.reached(outer);
        self.expect_punct("]", "to close the index")?;
        let span = e.span.to(self.prev_span());
        Ok((
            Expr {
                kind: ExprKind::Index(Box::new(e), Box::new(index)),
                span,
            },
            reached,
        ))
    }

    /// primary := NUMBER | STRING | NAME | NAME '(' args ')' | '(' expr ')'
    ///          | InLeftContext '(' pats ')' | ...
    fn primary(&mut self) -> PResult<Expr> {
        let Some(t) = self.peek() else {
            return self.error("an expression");
        };
        let span = t.span;
        let kind = match &t.tok {
            Tok::Int(i) => {
                self.pos += 1;
                ExprKind::Int(*i)
            }
            Tok::Float { value: f, single } => {
                self.pos += 1;
                ExprKind::Float(*f, *single)
            }
            Tok::Str(s) => {
                self.pos += 1;
                ExprKind::Str(s.clone())
            }
            Tok::Punct("'") if self.vv => {
                // `'v`: the vertex as the last `synchronize` left it; `'a[i]`
                // and `'g.v` of a vertex in an array or a struct (`$` and
                // calls bind outside: `'v$pos` is the old position).
                self.pos += 1;
                let outer = self.measure();
                let mut v = self.primary()?;
                let mut reached = self.reached(outer);
                loop {
                    let field = self.peek_punct(".")
                        && matches!(self.peek_at(1).map(|t| &t.tok), Some(Tok::Ident(_)))
                        && !self.peek_at(2).is_some_and(|t| t.tok.is_punct("("));
                    if self.peek_punct("[") {
                        reached = self.wrap(reached, self.span_here())?;
                        let (indexed, r) = self.index_of(v)?;
                        v = indexed;
                        reached = reached.max(r);
                    } else if field {
                        reached = self.wrap(reached, self.span_here())?;
                        self.pos += 1;
                        let name = self.name("a field name after `.`")?;
                        let span = v.span.to(name.span);
                        v = Expr {
                            kind: ExprKind::Field(Box::new(v), name),
                            span,
                        };
                    } else {
                        break;
                    }
                }
                ExprKind::Call(
                    Name {
                        text: "old".into(),
                        span,
                    },
                    vec![v],
                )
            }
            Tok::Punct("(") if self.vv => {
                // `(p, q)`: the directed edge from p to q, as in `(p, q)$w`.
                self.pos += 1;
                let e = self.expr()?;
                if self.eat_punct(",") {
                    let f = self.expr()?;
                    self.expect_punct(")", "to close the edge `(p, q)`")?;
                    ExprKind::Call(
                        Name {
                            text: "edge".into(),
                            span,
                        },
                        vec![e, f],
                    )
                } else {
                    self.expect_punct(")", "to close the parenthesis")?;
                    return Ok(Expr {
                        kind: e.kind,
                        span: span.to(self.prev_span()),
                    });
                }
            }
            Tok::Punct("(") => {
                self.pos += 1;
                let e = self.expr()?;
                self.expect_punct(")", "to close the parenthesis")?;
                return Ok(Expr {
                    kind: e.kind,
                    span: span.to(self.prev_span()),
                });
            }
            Tok::Ident(n)
                if matches!(n.as_str(), "sum" | "avg" | "count")
                    && self.peek_at(1).is_some_and(|t| t.tok.is_punct("("))
                    && self
                        .peek_at(2)
                        .is_some_and(|t| matches!(t.tok, Tok::Ident(_)))
                    && self.peek_at(3).is_some_and(|t| t.tok.is_ident("in")) =>
            {
                // sum(w in ring(v) where l(w) == c)
                let op = self.name("sum, avg or count")?;
                self.pos += 1;
                let var = self.name("a variable name")?;
                self.pos += 1;
                let set = self.expr()?;
                let cond = if self.eat_ident("where") {
                    Some(Box::new(self.expr()?))
                } else {
                    None
                };
                self.expect_punct(")", "to close the sum")?;
                ExprKind::Gather {
                    op,
                    var,
                    set: Box::new(set),
                    cond,
                }
            }
            Tok::Ident(n) => {
                let name = self.name("a name")?;
                let ctx = match n.as_str() {
                    "InLeftContext" => Some(ContextKind::Left),
                    "InRightContext" => Some(ContextKind::Right),
                    "InNewLeftContext" => Some(ContextKind::NewLeft),
                    "InNewRightContext" => Some(ContextKind::NewRight),
                    _ => None,
                };
                if let Some(kind) = ctx {
                    self.expect_punct("(", "after the context test")?;
                    let mut pats = Vec::new();
                    while !self.eat_punct(")") {
                        if self.at_end() {
                            return self.error("`)` to close the context test");
                        }
                        pats.push(self.pat_module()?);
                    }
                    if pats.is_empty() {
                        return Err(Diagnostic::new(
                            name.span,
                            format!("`{n}` needs at least one module to test, e.g. `{n}(A(x))`"),
                        ));
                    }
                    ExprKind::InContext(kind, pats)
                } else if self.eat_punct("(") {
                    let args = self.args(")")?;
                    ExprKind::Call(name, args)
                } else {
                    ExprKind::Ident(n.clone())
                }
            }
            _ => return self.error("an expression"),
        };
        Ok(Expr {
            kind,
            span: span.to(self.prev_span()),
        })
    }

    /// args := [ expr {',' expr} ] CLOSE   (the opening bracket is consumed)
    pub(super) fn args(&mut self, close: &str) -> PResult<Vec<Expr>> {
        let mut args = Vec::new();
        if self.eat_punct(close) {
            return Ok(args);
        }
        loop {
            args.push(self.assign_expr()?);
            if self.eat_punct(close) {
                return Ok(args);
            }
            if !self.peek_punct(",") {
                return self.error(&format!("`,` or `{close}` in the argument list"));
            }
            self.pos += 1;
        }
    }
}

fn binop_of(t: &Tok) -> Option<(BinOp, u8)> {
    let Tok::Punct(p) = t else { return None };
    Some(match *p {
        "||" => (BinOp::Or, 1),
        "&&" => (BinOp::And, 2),
        "|" => (BinOp::BitOr, 3),
        "^" => (BinOp::BitXor, 4),
        "&" => (BinOp::BitAnd, 5),
        "==" => (BinOp::Eq, 6),
        "!=" => (BinOp::Ne, 6),
        "<" => (BinOp::Lt, 7),
        ">" => (BinOp::Gt, 7),
        "<=" => (BinOp::Le, 7),
        ">=" => (BinOp::Ge, 7),
        "<<" => (BinOp::Shl, 8),
        ">>" => (BinOp::Shr, 8),
        "+" => (BinOp::Add, 9),
        "-" => (BinOp::Sub, 9),
        "*" => (BinOp::Mul, 10),
        "/" => (BinOp::Div, 10),
        "%" => (BinOp::Rem, 10),
        _ => return None,
    })
}
