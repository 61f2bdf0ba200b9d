//! The parser's cursor over the tokens: peeking, eating and expecting
//! tokens and names, the messages for what was found, and the lookahead
//! that tells a declaration.

use crate::syntax::ast::Name;
use crate::syntax::lex::{Tok, Token};
use crate::syntax::span::{Diagnostic, Span};

use super::{PResult, Parser, QUALIFIERS, TYPE_KEYWORDS};

impl<'t> Parser<'t> {
    pub(crate) fn at_end(&self) -> bool {
        self.pos >= self.toks.len()
    }

    pub(crate) fn peek(&self) -> Option<&'t Token> {
        self.toks.get(self.pos)
    }

    pub(crate) fn peek_at(&self, k: usize) -> Option<&'t Token> {
        self.toks.get(self.pos + k)
    }

    pub(crate) fn peek_punct(&self, p: &str) -> bool {
        self.peek().is_some_and(|t| t.tok.is_punct(p))
    }

    pub(crate) fn peek_ident(&self, s: &str) -> bool {
        self.peek().is_some_and(|t| t.tok.is_ident(s))
    }

    pub(crate) fn span_here(&self) -> Span {
        self.peek().map(|t| t.span).unwrap_or(self.eof)
    }

    pub(crate) fn prev_span(&self) -> Span {
        self.pos
            .checked_sub(1)
            .and_then(|i| self.toks.get(i))
            .map(|t| t.span)
            .unwrap_or(self.eof)
    }

    pub(crate) fn bump(&mut self) -> &'t Token {
        let t = &self.toks[self.pos];
        self.pos += 1;
        t
    }

    pub(crate) fn found(&self) -> String {
        match self.peek() {
            Some(t) => t.tok.describe(),
            None => "the end of the file".to_string(),
        }
    }

    pub(crate) fn error<T>(&self, expected: &str) -> PResult<T> {
        Err(Diagnostic::new(
            self.span_here(),
            format!("expected {expected}, found {}", self.found()),
        ))
    }

    pub(crate) fn eat_punct(&mut self, p: &str) -> bool {
        if self.peek_punct(p) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    pub(crate) fn expect_punct(&mut self, p: &str, what: &str) -> PResult<Span> {
        if self.peek_punct(p) {
            Ok(self.bump().span)
        } else {
            self.error(&format!("`{p}` {what}"))
        }
    }

    pub(crate) fn name(&mut self, what: &str) -> PResult<Name> {
        if let Some((at, last)) = self.split_last.take() {
            if at == self.pos {
                self.pos += 1;
                return Ok(last);
            }
        }
        match self.peek() {
            Some(Token {
                tok: Tok::Ident(s),
                span,
                ..
            }) => {
                self.pos += 1;
                Ok(Name {
                    text: s.clone(),
                    span: *span,
                })
            }
            _ => self.error(what),
        }
    }

    pub(crate) fn eat_ident(&mut self, s: &str) -> bool {
        if self.peek_ident(s) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    pub(super) fn is_type_name(&self, s: &str) -> bool {
        TYPE_KEYWORDS.contains(&s) || self.type_names.contains(s)
    }

    /// True when the tokens at the cursor begin a declaration:
    /// `const ...`, `static ...`, `struct Name ...`, `TYPE name`, `TYPE
    /// *name`, or `Name name` (unless `Name` is a module: a production).
    pub(super) fn at_declaration(&self) -> bool {
        match (self.peek().map(|t| &t.tok), self.peek_at(1).map(|t| &t.tok)) {
            (Some(Tok::Ident(a)), _) if QUALIFIERS.contains(&a.as_str()) => true,
            (Some(Tok::Ident(a)), Some(Tok::Ident(_))) => {
                !matches!(
                    a.as_str(),
                    "produce"
                        | "nproduce"
                        | "return"
                        | "else"
                        | "if"
                        | "while"
                        | "do"
                        | "propensity"
                ) && (self.is_type_name(a) || !self.module_names.contains(a))
            }
            (Some(Tok::Ident(a)), Some(Tok::Punct("*" | "&"))) => {
                self.is_type_name(a)
                    && self
                        .peek_at(2)
                        .is_some_and(|t| matches!(t.tok, Tok::Ident(_)))
            }
            _ => false,
        }
    }
}
