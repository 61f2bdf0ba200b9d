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

/// A character constant, `'a'`, `'\n'`, `'\0'`, `'\x41'`: C's escapes,
/// the value of one ASCII character as an `int`. The error gives how many
/// bytes it covers.
fn char_lit(i: &str) -> Result<(&str, i64), (usize, String)> {
    let body = &i[1..];
    let (code, len) = match body.chars().next() {
        None | Some('\n') | Some('\'') => {
            return Err((1, "expected a character and a closing `'` after `'`".into()))
        }
        Some('\\') => {
            let esc = &body[1..];
            let simple = |c: char| {
                Some(match c {
                    'n' => 10,
                    't' => 9,
                    'r' => 13,
                    'a' => 7,
                    'b' => 8,
                    'f' => 12,
                    'v' => 11,
                    '\\' | '\'' | '"' | '?' => c as i64,
                    _ => return None,
                })
            };
            let octal = esc
                .bytes()
                .take(3)
                .take_while(|b| (b'0'..=b'7').contains(b))
                .count();
            let hex = esc
                .strip_prefix('x')
                .map(|h| h.bytes().take_while(u8::is_ascii_hexdigit).count());
            if octal > 0 {
                let v = i64::from_str_radix(&esc[..octal], 8).unwrap_or(0);
                (v, 1 + octal)
            } else if let Some(n) = hex.filter(|n| (1..=2).contains(n)) {
                let v = i64::from_str_radix(&esc[1..1 + n], 16).unwrap_or(0);
                (v, 2 + n)
            } else if let Some(n) = hex.filter(|n| *n > 2) {
                return Err((
                    3 + n,
                    "a hexadecimal escape in a character constant takes one or two digits".into(),
                ));
            } else if let Some(v) = esc.chars().next().and_then(simple) {
                (v, 2)
            } else {
                let shown: String = esc.chars().take(1).collect();
                return Err((
                    2 + shown.len(),
                    format!("unknown escape `\\{shown}` in a character constant"),
                ));
            }
        }
        Some(c) if c.is_ascii() => (c as i64, 1),
        Some(c) => {
            return Err((
                1 + c.len_utf8(),
                format!("`{c}` is not an ASCII character: a character constant holds one byte"),
            ))
        }
    };
    match body[len..].strip_prefix('\'') {
        Some(r) => Ok((r, code)),
        None => Err((
            1 + len,
            "expected `'` to close the character constant (it holds one character; strings take `\"`)"
                .into(),
        )),
    }
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
        } else if rest.starts_with('\'') {
            let (r, code) = char_lit(rest)
                .map_err(|(len, msg)| Diagnostic::new(Span::new(file, at, at + len.max(1)), msg))?;
            (r, Tok::Int(code))
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
