//! Tokens of the `.lsys` language, recognised with nom.
//!
//! The lexer keeps two facts the later passes need: whether a token starts a
//! line (preprocessor directives and the one-line arrow form are line based)
//! and whether whitespace precedes it (a function-like `#define NAME(` has no
//! space before the parenthesis).

use nom::{
    branch::alt,
    bytes::complete::{take_until, take_while, take_while1},
    character::complete::{char, digit0, digit1, one_of},
    combinator::{opt, recognize},
    sequence::{pair, tuple},
    IResult,
};

use super::span::{Diagnostic, FileId, Span};

#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    Ident(String),
    Int(i64),
    Float(f64),
    Str(String),
    Punct(&'static str),
}

impl Tok {
    pub fn is_punct(&self, p: &str) -> bool {
        matches!(self, Tok::Punct(q) if *q == p)
    }

    pub fn is_ident(&self, s: &str) -> bool {
        matches!(self, Tok::Ident(q) if q == s)
    }

    /// How the token reads in a message.
    pub fn describe(&self) -> String {
        match self {
            Tok::Ident(s) => format!("`{s}`"),
            Tok::Int(i) => format!("number `{i}`"),
            Tok::Float(f) => format!("number `{f}`"),
            Tok::Str(s) => format!("string \"{s}\""),
            Tok::Punct(p) => format!("`{p}`"),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub tok: Tok,
    pub span: Span,
    /// The first token on its line.
    pub line_start: bool,
    /// Whitespace or a comment comes right before it.
    pub space_before: bool,
}

/// Punctuators, longest first so that `<<` wins over `<`.
const PUNCTS: &[&str] = &[
    "<<=", ">>=", "...", "->", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||", "++", "--", "+=",
    "-=", "*=", "/=", "%=", "::", "(", ")", "{", "}", "[", "]", ",", ";", ":", ".", "?", "<", ">",
    "=", "+", "-", "*", "/", "%", "!", "#", "~", "&", "|", "^", "\\", "@", "$", "'",
];

fn ident(i: &str) -> IResult<&str, &str> {
    recognize(pair(
        take_while1(|c: char| c.is_ascii_alphabetic() || c == '_'),
        take_while(|c: char| c.is_ascii_alphanumeric() || c == '_'),
    ))(i)
}

/// `1`, `1.5`, `.5`, `1.`, `1e-3`, `2.0f`
fn number(i: &str) -> IResult<&str, (&str, bool)> {
    let exponent = recognize(tuple((one_of("eE"), opt(one_of("+-")), digit1)));
    let with_dot = recognize(tuple((digit0, char('.'), digit0)));
    let (rest, text) = recognize(pair(alt((with_dot, digit1)), opt(exponent)))(i)?;
    if text == "." {
        return Err(nom::Err::Error(nom::error::Error::new(
            i,
            nom::error::ErrorKind::Digit,
        )));
    }
    let (rest, suffix) = opt(one_of("fFlLuU"))(rest)?;
    let is_float = text.contains(['.', 'e', 'E']) || matches!(suffix, Some('f' | 'F'));
    Ok((rest, (text, is_float)))
}

fn string_lit(i: &str) -> IResult<&str, &str> {
    let (rest, _) = char('"')(i)?;
    let (rest, body) = take_while(|c| c != '"' && c != '\n')(rest)?;
    let (rest, _) = char('"')(rest)?;
    Ok((rest, body))
}

fn punct(i: &str) -> IResult<&str, &'static str> {
    match PUNCTS.iter().find(|p| i.starts_with(**p)) {
        Some(p) => Ok((&i[p.len()..], p)),
        None => Err(nom::Err::Error(nom::error::Error::new(
            i,
            nom::error::ErrorKind::Tag,
        ))),
    }
}

/// Splits `text` into tokens. Comments and line continuations are whitespace.
pub fn lex(file: FileId, text: &str) -> Result<Vec<Token>, Diagnostic> {
    let mut out = Vec::new();
    let mut rest = text;
    let mut line_start = true;
    let mut space_before = true;
    loop {
        // Whitespace, comments, and backslash-newline continuations.
        loop {
            if let Some(r) = rest
                .strip_prefix("\\\n")
                .or_else(|| rest.strip_prefix("\\\r\n"))
            {
                rest = r;
                space_before = true;
            } else if let Some(c) = rest.chars().next().filter(|c| c.is_whitespace()) {
                if c == '\n' {
                    line_start = true;
                }
                rest = &rest[c.len_utf8()..];
                space_before = true;
            } else if rest.starts_with("//") {
                let end = rest.find('\n').unwrap_or(rest.len());
                rest = &rest[end..];
                space_before = true;
            } else if rest.starts_with("/*") {
                let at = text.len() - rest.len();
                match take_until::<_, _, nom::error::Error<&str>>("*/")(&rest[2..]) {
                    Ok((r, body)) => {
                        if body.contains('\n') {
                            line_start = true;
                        }
                        rest = &r[2..];
                        space_before = true;
                    }
                    Err(_) => {
                        return Err(Diagnostic::new(
                            Span::new(file, at, at + 2),
                            "unterminated comment: expected `*/` before the end of the file",
                        ))
                    }
                }
            } else {
                break;
            }
        }
        if rest.is_empty() {
            return Ok(out);
        }
        let at = text.len() - rest.len();
        let (r, tok) = if let Ok((r, s)) = ident(rest) {
            (r, Tok::Ident(s.to_string()))
        } else if let Ok((r, (s, is_float))) = number(rest) {
            let bad = || {
                Diagnostic::new(
                    Span::new(file, at, at + s.len()),
                    format!("`{s}` is not a valid number"),
                )
            };
            if is_float {
                (r, Tok::Float(s.parse().map_err(|_| bad())?))
            } else {
                (r, Tok::Int(s.parse().map_err(|_| bad())?))
            }
        } else if let Ok((r, s)) = string_lit(rest) {
            (r, Tok::Str(s.to_string()))
        } else if let Ok((r, p)) = punct(rest) {
            (r, Tok::Punct(p))
        } else {
            let c = rest.chars().next().unwrap_or(' ');
            return Err(Diagnostic::new(
                Span::new(file, at, at + c.len_utf8()),
                format!("unexpected character `{c}`"),
            ));
        };
        let end = text.len() - r.len();
        out.push(Token {
            tok,
            span: Span::new(file, at, end),
            line_start,
            space_before,
        });
        rest = r;
        line_start = false;
        space_before = false;
    }
}
