//! Blocks and statements, with `switch` and its labels.

use crate::syntax::ast::{Block, ModuleCall, Name, Stmt};
use crate::syntax::lex::Tok;
use crate::syntax::span::Diagnostic;

use super::{PResult, Parser};

impl<'t> Parser<'t> {
    /// block := '{' { stmt } '}'
    pub(super) fn block(&mut self) -> PResult<Block> {
        let open = self.expect_punct("{", "to open the block")?;
        let mut stmts = Vec::new();
        loop {
            if self.eat_punct("}") {
                return Ok(Block {
                    stmts,
                    span: open.to(self.prev_span()),
                });
            }
            if self.at_end() {
                return Err(Diagnostic::new(
                    open,
                    "unclosed `{`: expected `}` before the end of the file",
                ));
            }
            stmts.push(self.stmt()?);
        }
    }

    /// True when `propensity` at the cursor starts a Gillespie statement,
    /// not an expression about a variable of that name.
    fn at_propensity(&self) -> bool {
        !self.peek_at(1).is_some_and(|t| {
            ["=", "+=", "-=", "*=", "/=", "++", "--", ".", "[", ";", ","]
                .iter()
                .any(|p| t.tok.is_punct(p))
        })
    }

    fn stmt(&mut self) -> PResult<Stmt> {
        self.descend()?;
        let r = self.stmt_inner();
        self.ascend();
        r
    }

    fn stmt_inner(&mut self) -> PResult<Stmt> {
        let t = self.peek().expect("checked by caller");
        if t.tok.is_punct("{") {
            return Ok(Stmt::Block(self.block()?));
        }
        if t.tok.is_punct(";") {
            self.pos += 1;
            return Ok(Stmt::Empty);
        }
        if let Tok::Ident(w) = &t.tok {
            match w.as_str() {
                "produce" | "nproduce" => {
                    self.pos += 1;
                    let last = w == "produce";
                    let modules = if self.peek_punct("(")
                        && self
                            .peek_at(1)
                            .is_some_and(|t| matches!(t.tok, Tok::Ident(_)))
                        && self.peek_at(2).is_some_and(|t| t.tok.is_punct("("))
                    {
                        // `produce( G(x) );` as in the manual's examples.
                        self.pos += 1;
                        let m = self.module_calls(&[")"], false)?;
                        self.pos += 1;
                        m
                    } else {
                        self.module_calls(&[";"], true)?
                    };
                    // Velho's listings omit the `;` before `}`.
                    if !self.peek_punct("}") {
                        self.expect_punct(";", "after the successor")?;
                    }
                    return Ok(Stmt::Produce {
                        modules,
                        last,
                        span: t.span,
                    });
                }
                "propensity" if self.at_propensity() => {
                    // `propensity E produce W;` (manual 7.2) is lpfg's
                    // `nproduce Propensity(E) W;`: a Gillespie step reads
                    // the reactions back from the successor.
                    self.pos += 1;
                    let value = self.expr()?;
                    if !self.eat_ident("produce") {
                        return self.error("`produce` after the propensity");
                    }
                    let mut modules = vec![ModuleCall {
                        name: Name {
                            text: "Propensity".into(),
                            span: t.span,
                        },
                        args: vec![value],
                    }];
                    modules.extend(self.module_calls(&[";"], true)?);
                    if !self.peek_punct("}") {
                        self.expect_punct(";", "after the successor")?;
                    }
                    return Ok(Stmt::Produce {
                        modules,
                        last: false,
                        span: t.span,
                    });
                }
                "if" => {
                    self.pos += 1;
                    let cond = self.expr()?;
                    let then = Box::new(self.stmt_or_end()?);
                    let els = if self.eat_ident("else") {
                        Some(Box::new(self.stmt_or_end()?))
                    } else {
                        None
                    };
                    return Ok(Stmt::If { cond, then, els });
                }
                "while" => {
                    self.pos += 1;
                    let cond = self.expr()?;
                    let body = Box::new(self.stmt_or_end()?);
                    return Ok(Stmt::While {
                        cond,
                        body,
                        span: t.span,
                    });
                }
                "do" => {
                    self.pos += 1;
                    let body = Box::new(self.stmt_or_end()?);
                    if !self.eat_ident("while") {
                        return self.error("`while` after the body of `do`");
                    }
                    let cond = self.expr()?;
                    self.expect_punct(";", "after `do ... while (...)`")?;
                    return Ok(Stmt::DoWhile {
                        body,
                        cond,
                        span: t.span,
                    });
                }
                "for" => {
                    self.pos += 1;
                    self.expect_punct("(", "after `for`")?;
                    let init = if self.eat_punct(";") {
                        None
                    } else {
                        let s = if self.at_declaration() {
                            Stmt::Decl(self.var_decl()?)
                        } else {
                            Stmt::Expr(self.expr()?)
                        };
                        self.expect_punct(";", "after the loop's initialisation")?;
                        Some(Box::new(s))
                    };
                    let cond = if self.peek_punct(";") {
                        None
                    } else {
                        Some(self.expr()?)
                    };
                    self.expect_punct(";", "after the loop condition")?;
                    let step = if self.peek_punct(")") {
                        None
                    } else {
                        Some(self.expr()?)
                    };
                    self.expect_punct(")", "to close the `for` header")?;
                    let body = Box::new(self.stmt_or_end()?);
                    return Ok(Stmt::For {
                        init,
                        cond,
                        step,
                        body,
                        span: t.span,
                    });
                }
                "return" => {
                    self.pos += 1;
                    let value = if !self.peek_punct(";") && !self.peek_punct("}") {
                        Some(self.expr()?)
                    } else {
                        None
                    };
                    self.eat_punct(";");
                    return Ok(Stmt::Return(value, t.span));
                }
                "switch" | "case" | "default"
                    if w != "default" || self.peek_at(1).is_some_and(|n| n.tok.is_punct(":")) =>
                {
                    return self.switch_part();
                }
                "break" | "continue" => {
                    self.pos += 1;
                    self.expect_punct(";", &format!("after `{w}`"))?;
                    return Ok(if w == "break" {
                        Stmt::Break(t.span)
                    } else {
                        Stmt::Continue(t.span)
                    });
                }
                _ => {}
            }
            if self.vv {
                if let Some(s) = self.vv_stmt(w)? {
                    return Ok(s);
                }
            }
            if self.at_declaration() {
                let d = self.var_decl()?;
                self.expect_punct(";", "after the declaration")?;
                return Ok(Stmt::Decl(d));
            }
        }
        let e = self.expr()?;
        if !self.peek_punct("}") {
            self.expect_punct(";", "after the expression")?;
        }
        Ok(Stmt::Expr(e))
    }

    /// switch := 'switch' expr ( '{' { stmt } '}' | { label } stmt ), whose
    /// labels are statements of the body; or one of those labels. Out of
    /// `stmt_inner`, so that its frame stays small.
    #[inline(never)]
    fn switch_part(&mut self) -> PResult<Stmt> {
        let span = self.bump().span;
        if !self.toks[self.pos - 1].tok.is_ident("switch") {
            self.pos -= 1;
            return self.label();
        }
        let value = self.expr()?;
        let mut body = Vec::new();
        if !self.peek_punct("{") {
            // `switch (n) case 1: stmt;`: labels and one statement.
            while self.peek_ident("case")
                || (self.peek_ident("default")
                    && self.peek_at(1).is_some_and(|t| t.tok.is_punct(":")))
            {
                body.push(self.stmt()?);
            }
            body.push(self.stmt_or_end()?);
            return Ok(Stmt::Switch { value, body, span });
        }
        let open = self.bump().span;
        while !self.eat_punct("}") {
            if self.at_end() {
                return Err(Diagnostic::new(
                    open,
                    "unclosed `{`: expected `}` before the end of the file",
                ));
            }
            body.push(self.stmt()?);
        }
        Ok(Stmt::Switch { value, body, span })
    }

    /// label := 'case' cond ':' | 'default' ':', a statement of a
    /// `switch`'s body. Out of `stmt_inner`, so that its frame stays small.
    #[inline(never)]
    fn label(&mut self) -> PResult<Stmt> {
        let t = self.bump();
        if t.tok.is_ident("default") {
            self.pos += 1;
            return Ok(Stmt::Default(t.span));
        }
        let value = self.cond_expr()?;
        self.expect_punct(":", "after the `case` label's value")?;
        Ok(Stmt::Case(value, t.span))
    }

    pub(super) fn stmt_or_end(&mut self) -> PResult<Stmt> {
        if self.at_end() {
            return self.error("a statement");
        }
        self.stmt()
    }
}
