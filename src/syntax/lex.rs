//! Tokens of the `.lsys` language, recognised with nom.
//!
//! The lexer keeps two facts the later passes need: whether a token starts a
//! line (preprocessor directives and the one-line arrow form are line based)
//! and whether whitespace precedes it (a function-like `#define NAME(` has no
//! space before the parenthesis).
//!
//! Numbers are C's: decimal, octal (`017`) and hexadecimal (`0x1F`)
//! integers with `u`/`l` suffixes, floating constants with an exponent and an
//! `f`/`l` suffix. A float with `f` is single precision: its value is the
//! nearest `f32`, and the token says so.
//!
//! A character that starts no token, or a number C would refuse, is not fatal
//! here: [`lex_all`] records it and goes on, and the preprocessor reports it
//! only when it lies outside a group that `#if` skips (a skipped group may
//! hold anything). An unterminated comment is fatal, as in C.

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
    /// A floating constant; `single` when it had an `f`/`F` suffix (C's
    /// `float`), and then `value` is already rounded to the nearest `f32`.
    Float {
        value: f64,
        single: bool,
    },
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
            Tok::Float { value, .. } => format!("number `{value}`"),
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
    // The arrow of paper 003's shape rules (U+21DD); `~>` and `-->` are
    // written with the ASCII punctuators.
    "\u{21DD}",
];

fn ident(i: &str) -> IResult<&str, &str> {
    recognize(pair(
        take_while1(|c: char| c.is_ascii_alphabetic() || c == '_'),
        take_while(|c: char| c.is_ascii_alphanumeric() || c == '_'),
    ))(i)
}

/// A number as C reads it: its digits, its kind and its suffix.
struct Number<'a> {
    /// The digits without the suffix: `0x1F`, `1.5e3`.
    text: &'a str,
    /// A floating constant (a `.` or an exponent).
    float: bool,
    /// The letters after the digits: `f`, `UL`, or what C would refuse.
    suffix: &'a str,
}

/// `1`, `017`, `0x1F`, `10UL`, `1.5`, `.5`, `1.`, `1e-3`, `2.0f`, `1.F`:
/// the digits and then every letter, digit, `_` or `.` that follows, as C's
/// preprocessing number takes them, so that `1abc` is one bad number and
/// not a number and a name.
fn number(i: &str) -> IResult<&str, Number<'_>> {
    let digits = |r: &str| r.find(|c: char| !c.is_ascii_hexdigit()).unwrap_or(r.len());
    if let Some(r) = i.strip_prefix("0x").or_else(|| i.strip_prefix("0X")) {
        if digits(r) > 0 {
            let (text, rest) = i.split_at(2 + digits(r));
            let (rest, suffix) =
                take_while(|c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.')(rest)?;
            return Ok((
                rest,
                Number {
                    text,
                    float: false,
                    suffix,
                },
            ));
        }
    }
    let exponent = recognize(tuple((one_of("eE"), opt(one_of("+-")), digit1)));
    let with_dot = recognize(tuple((digit0, char('.'), digit0)));
    let (rest, text) = recognize(pair(alt((with_dot, digit1)), opt(exponent)))(i)?;
    if text == "." {
        return Err(nom::Err::Error(nom::error::Error::new(
            i,
            nom::error::ErrorKind::Digit,
        )));
    }
    let (rest, suffix) =
        take_while(|c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.')(rest)?;
    Ok((
        rest,
        Number {
            text,
            float: text.contains(['.', 'e', 'E']),
            suffix,
        },
    ))
}

/// C's integer suffixes: an optional `u` and an optional `l` or `ll` (one
/// case), in either order.
fn integer_suffix(s: &str) -> bool {
    let l = match s.find(['u', 'U']) {
        None => s,
        Some(0) => &s[1..],
        Some(k) if k == s.len() - 1 => &s[..k],
        Some(_) => return false,
    };
    matches!(l, "" | "l" | "L" | "ll" | "LL")
}

/// The token of a lexed number, or why C would refuse it.
fn number_token(n: &Number) -> Result<Tok, String> {
    let whole = format!("{}{}", n.text, n.suffix);
    if n.float {
        let single = match n.suffix {
            "" | "l" | "L" => false,
            "f" | "F" => true,
            s => return Err(format!("`{whole}` has the suffix `{s}`, which a floating constant cannot have (C allows `f` and `l`)")),
        };
        let value = if single {
            let v: f32 = n
                .text
                .parse()
                .map_err(|_| format!("`{whole}` is not a valid number"))?;
            if v.is_infinite() {
                return Err(format!(
                    "`{whole}` is too large for a float (the largest is about 3.4e38)"
                ));
            }
            f64::from(v)
        } else {
            let v: f64 = n
                .text
                .parse()
                .map_err(|_| format!("`{whole}` is not a valid number"))?;
            if v.is_infinite() {
                return Err(format!(
                    "`{whole}` is too large for a double (the largest is about 1.8e308)"
                ));
            }
            v
        };
        return Ok(Tok::Float { value, single });
    }
    if !integer_suffix(n.suffix) {
        return Err(
            if n.suffix.starts_with(['f', 'F'])
                && !n.text.starts_with("0x")
                && !n.text.starts_with("0X")
            {
                format!("`{whole}` is not a valid number: the suffix `f` needs a floating constant, as in `{}.f`", n.text)
            } else {
                format!("`{whole}` is not a valid number: `{}` is not a suffix C allows on an integer (`u`, `l`, `ul`, `ll`, `ull`)", n.suffix)
            },
        );
    }
    let too_large = || {
        format!(
            "`{whole}` is too large for an integer (the largest is {})",
            i64::MAX
        )
    };
    let value = if let Some(hex) = n
        .text
        .strip_prefix("0x")
        .or_else(|| n.text.strip_prefix("0X"))
    {
        i64::from_str_radix(hex, 16).map_err(|_| too_large())?
    } else if n.text.len() > 1 && n.text.starts_with('0') {
        if let Some(bad) = n.text.chars().find(|c| !('0'..='7').contains(c)) {
            return Err(format!("`{whole}` is not a valid number: a number that starts with 0 is octal, and `{bad}` is not an octal digit"));
        }
        i64::from_str_radix(&n.text[1..], 8).map_err(|_| too_large())?
    } else {
        n.text.parse().map_err(|_| too_large())?
    };
    Ok(Tok::Int(value))
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

/// True when the `'` that starts `i` is a prime before a name (vv's `'v`,
/// the old state of vertex `v`) or a number (a shape grammar's relative
/// size, `'0.3`): a name or number follows that is not closed by a `'` as
/// a character constant (`'a'`, `'0'`) would be.
fn is_prime(i: &str) -> bool {
    let name = i[1..]
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.'))
        .unwrap_or(i.len() - 1);
    let starts = i[1..]
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.');
    starts && name > 0 && !i[1 + name..].starts_with('\'')
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

/// The tokens of a text, and the places where no token could be made.
#[derive(Clone, Debug, Default)]
pub struct Lexed {
    pub tokens: Vec<Token>,
    /// What could not be lexed, each with the number of tokens before it.
    pub errors: Vec<(usize, Diagnostic)>,
}

/// Splits `text` into tokens; the first thing that is not a token is an
/// error.
pub fn lex(file: FileId, text: &str) -> Result<Vec<Token>, Diagnostic> {
    let lexed = lex_all(file, text)?;
    match lexed.errors.into_iter().next() {
        Some((_, d)) => Err(d),
        None => Ok(lexed.tokens),
    }
}

/// Splits `text` into tokens. Comments and line continuations are
/// whitespace. A character that starts no token or a number C refuses is
/// recorded in [`Lexed::errors`] and skipped; only an unterminated comment
/// stops the lexer.
pub fn lex_all(file: FileId, text: &str) -> Result<Lexed, Diagnostic> {
    let mut errors = Vec::new();
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
            return Ok(Lexed {
                tokens: out,
                errors,
            });
        }
        let at = text.len() - rest.len();
        let (r, tok) = if let Ok((r, s)) = ident(rest) {
            (r, Tok::Ident(s.to_string()))
        } else if let Ok((r, n)) = number(rest) {
            match number_token(&n) {
                Ok(tok) => (r, tok),
                Err(message) => {
                    let end = text.len() - r.len();
                    errors.push((
                        out.len(),
                        Diagnostic::new(Span::new(file, at, end), message),
                    ));
                    rest = r;
                    line_start = false;
                    space_before = false;
                    continue;
                }
            }
        } else if rest.starts_with('\'') && is_prime(rest) {
            // vv's `'v$pos`: the prime before a name, not a character.
            (&rest[1..], Tok::Punct("'"))
        } else if rest.starts_with('\'') {
            match char_lit(rest) {
                Ok((r, code)) => (r, Tok::Int(code)),
                Err((len, message)) => {
                    errors.push((
                        out.len(),
                        Diagnostic::new(Span::new(file, at, at + len), message),
                    ));
                    rest = &rest[len..];
                    line_start = false;
                    space_before = false;
                    continue;
                }
            }
        } else if let Ok((r, s)) = string_lit(rest) {
            (r, Tok::Str(s.to_string()))
        } else if let Ok((r, p)) = punct(rest) {
            (r, Tok::Punct(p))
        } else {
            let c = rest.chars().next().unwrap_or(' ');
            errors.push((
                out.len(),
                Diagnostic::new(
                    Span::new(file, at, at + c.len_utf8()),
                    format!("unexpected character `{c}`"),
                ),
            ));
            rest = &rest[c.len_utf8()..];
            line_start = false;
            space_before = false;
            continue;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn one(text: &str) -> Result<Tok, String> {
        let toks = lex(FileId(0), text).map_err(|d| d.message)?;
        assert_eq!(toks.len(), 1, "{text}: {toks:?}");
        Ok(toks[0].tok.clone())
    }

    /// Character constants (C11 6.4.4.4) are ints: ASCII codes, the
    /// simple escapes, octal and hexadecimal ones.
    #[test]
    fn character_constants() {
        let cases = [
            ("'a'", 97),
            ("' '", 32),
            ("'\\n'", 10),
            ("'\\t'", 9),
            ("'\\0'", 0),
            ("'\\''", 39),
            ("'\\\\'", 92),
            ("'\\\"'", 34),
            ("'\"'", 34),
            ("'\\x41'", 65),
            ("'\\101'", 65),
            ("'\\177'", 127),
        ];
        for (text, want) in cases {
            assert_eq!(one(text), Ok(Tok::Int(want)), "{text}");
        }
        for bad in ["'ab'", "''", "'\\q'", "'\\x123'", "'é'"] {
            assert!(one(bad).is_err(), "{bad}");
        }
        // A `'` before a name that no `'` closes is vv's prime (`'v$pos`),
        // for the parser to accept or refuse.
        let toks = lex(FileId(0), "'a$pos").unwrap();
        assert_eq!(toks[0].tok, Tok::Punct("'"));
        assert_eq!(toks[1].tok, Tok::Ident("a".into()));
    }

    fn float(value: f64, single: bool) -> Tok {
        Tok::Float { value, single }
    }

    /// C's constants (C11 6.4.4.1 and 6.4.4.2): the value and kind of each
    /// form. `0.1f` is the `f32` nearest 0.1: 0.1 × 2^27 = 13421772.8, so
    /// it is 13421773 / 2^27 (0x3DCCCCCD), not the `f64` 0.1.
    #[test]
    fn numbers_as_c_reads_them() {
        let cases = [
            ("1", Tok::Int(1)),
            ("017", Tok::Int(15)),
            ("0", Tok::Int(0)),
            ("0x1F", Tok::Int(31)),
            ("0XfF", Tok::Int(255)),
            ("10L", Tok::Int(10)),
            ("1u", Tok::Int(1)),
            ("10UL", Tok::Int(10)),
            ("7lu", Tok::Int(7)),
            ("3ll", Tok::Int(3)),
            ("3ULL", Tok::Int(3)),
            ("1.5", float(1.5, false)),
            ("1.", float(1.0, false)),
            (".5", float(0.5, false)),
            ("1e5", float(100000.0, false)),
            ("1e-3", float(0.001, false)),
            ("2.5L", float(2.5, false)),
            ("1.f", float(1.0, true)),
            ("1.0f", float(1.0, true)),
            ("2.F", float(2.0, true)),
            (".5f", float(0.5, true)),
            ("1e-3f", float(f64::from(0.001f32), true)),
            ("0.1f", float(13421773.0 / 134217728.0, true)),
            ("017.5", float(17.5, false)),
        ];
        for (text, want) in cases {
            assert_eq!(one(text), Ok(want), "{text}");
        }
        assert_ne!(13421773.0 / 134217728.0, 0.1);
    }

    #[test]
    fn numbers_c_refuses() {
        let cases = [
            (
                "1f",
                "the suffix `f` needs a floating constant, as in `1.f`",
            ),
            ("1abc", "`abc` is not a suffix C allows"),
            ("08", "`8` is not an octal digit"),
            ("1.5x", "which a floating constant cannot have"),
            ("1uu", "not a suffix C allows"),
            ("1lL", "not a suffix C allows"),
            ("1e39f", "too large for a float"),
            ("1e309", "too large for a double"),
            ("99999999999999999999", "too large for an integer"),
            ("0x8000000000000000", "too large for an integer"),
        ];
        for (text, want) in cases {
            let e = one(text).unwrap_err();
            assert!(e.contains(want), "{text}: {e}");
        }
    }

    /// What cannot be lexed is recorded with its place among the tokens,
    /// and lexing goes on.
    #[test]
    fn lex_all_goes_on_after_a_bad_character() {
        let l = lex_all(FileId(0), "a ` b 1x c").unwrap();
        let names: Vec<String> = l.tokens.iter().map(|t| t.tok.describe()).collect();
        assert_eq!(names, ["`a`", "`b`", "`c`"]);
        let at: Vec<usize> = l.errors.iter().map(|(k, _)| *k).collect();
        assert_eq!(at, [1, 2]);
        assert!(lex_all(FileId(0), "a /* b").is_err());
    }
}
