//! The expression of `#if` and `#elif`: a C integer constant expression,
//! evaluated after macro expansion.
//!
//! As in C, `defined NAME` and `defined(NAME)` ask whether a macro is
//! defined, a name that is still there after expansion is 0 (`true` is 1, as
//! in C++, which lpfg compiles), arithmetic is on 64-bit integers and a
//! floating constant or a string is an error. The operators are C's, with
//! C's precedence: `?:`, `||`, `&&`, `|`, `^`, `&`, `== !=`, `< <= > >=`,
//! `<< >>`, `+ -`, `* / %` and the unary `! ~ - +`. Overflow wraps;
//! division by zero is an error.

use super::lex::{Tok, Token};
use super::span::{Diagnostic, Span};

/// How deeply parentheses and operators may nest in one expression, so
/// that a pathological line cannot exhaust the stack.
pub const MAX_DEPTH: usize = 100;

/// Evaluates `tokens`, the expression of the directive at `at` (`#if`,
/// which messages name as `directive`). `defined` answers `defined NAME`.
pub fn eval(
    tokens: &[Token],
    at: Span,
    directive: &str,
    defined: &dyn Fn(&str) -> bool,
) -> Result<i64, Diagnostic> {
    let mut p = Parser {
        tokens,
        pos: 0,
        at,
        directive,
        defined,
        depth: 0,
        dead: 0,
    };
    if tokens.is_empty() {
        return Err(Diagnostic::new(
            at,
            format!("expected an expression after `{directive}`"),
        ));
    }
    let v = p.conditional()?;
    if let Some(t) = p.tokens.get(p.pos) {
        return Err(Diagnostic::new(
            t.span,
            format!(
                "expected an operator or the end of the line in `{directive}`, found {}",
                t.tok.describe()
            ),
        ));
    }
    Ok(v)
}

struct Parser<'a> {
    tokens: &'a [Token],
    pos: usize,
    /// The directive, for an expression that ends too soon.
    at: Span,
    directive: &'a str,
    defined: &'a dyn Fn(&str) -> bool,
    depth: usize,
    /// Inside an operand that C does not evaluate (the right of `0 &&`,
    /// the branch of `?:` not taken): nothing there is an error.
    dead: usize,
}

/// Binary operators with their precedence, loosest first: C's table.
const BINARY: &[(&str, u8)] = &[
    ("||", 1),
    ("&&", 2),
    ("|", 3),
    ("^", 4),
    ("&", 5),
    ("==", 6),
    ("!=", 6),
    ("<", 7),
    ("<=", 7),
    (">", 7),
    (">=", 7),
    ("<<", 8),
    (">>", 8),
    ("+", 9),
    ("-", 9),
    ("*", 10),
    ("/", 10),
    ("%", 10),
];

impl Parser<'_> {
    fn peek_punct(&self) -> Option<&'static str> {
        match self.tokens.get(self.pos).map(|t| &t.tok) {
            Some(Tok::Punct(p)) => Some(p),
            _ => None,
        }
    }

    fn error_here(&self, what: &str) -> Diagnostic {
        match self.tokens.get(self.pos) {
            Some(t) => Diagnostic::new(
                t.span,
                format!(
                    "expected {what} in `{}`, found {}",
                    self.directive,
                    t.tok.describe()
                ),
            ),
            None => {
                let end = self.tokens.last().map_or(self.at, |t| t.span);
                Diagnostic::new(
                    end,
                    format!(
                        "expected {what} in `{}`, found the end of the line",
                        self.directive
                    ),
                )
            }
        }
    }

    fn enter(&mut self) -> Result<(), Diagnostic> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            let span = self.tokens.get(self.pos).map_or(self.at, |t| t.span);
            return Err(Diagnostic::new(
                span,
                format!(
                    "the expression of `{}` nests more than {MAX_DEPTH} levels deep",
                    self.directive
                ),
            ));
        }
        Ok(())
    }

    /// conditional := binary ('?' conditional ':' conditional)?
    fn conditional(&mut self) -> Result<i64, Diagnostic> {
        self.enter()?;
        let c = self.binary(1)?;
        let v = if self.peek_punct() == Some("?") {
            self.pos += 1;
            self.dead += usize::from(c == 0);
            let a = self.conditional()?;
            self.dead -= usize::from(c == 0);
            if self.peek_punct() != Some(":") {
                return Err(self.error_here("`:` of `?:`"));
            }
            self.pos += 1;
            self.dead += usize::from(c != 0);
            let b = self.conditional()?;
            self.dead -= usize::from(c != 0);
            if c != 0 {
                a
            } else {
                b
            }
        } else {
            c
        };
        self.depth -= 1;
        Ok(v)
    }

    /// The binary operators of precedence `min` or tighter, left to right
    /// (precedence climbing). Both sides are always parsed; as in C, the
    /// right of `0 &&` and `1 ||` is not evaluated, so a division by zero
    /// there is no error.
    fn binary(&mut self, min: u8) -> Result<i64, Diagnostic> {
        let mut v = self.unary()?;
        while let Some((op, prec)) = self
            .peek_punct()
            .and_then(|p| BINARY.iter().find(|(o, _)| *o == p))
            .filter(|(_, prec)| *prec >= min)
        {
            let span = self.tokens[self.pos].span;
            self.pos += 1;
            let decided = match *op {
                "||" => v != 0,
                "&&" => v == 0,
                _ => false,
            };
            self.dead += usize::from(decided);
            self.enter()?;
            let w = self.binary(prec + 1)?;
            self.depth -= 1;
            self.dead -= usize::from(decided);
            v = match *op {
                "||" => i64::from(v != 0 || w != 0),
                "&&" => i64::from(v != 0 && w != 0),
                "|" => v | w,
                "^" => v ^ w,
                "&" => v & w,
                "==" => i64::from(v == w),
                "!=" => i64::from(v != w),
                "<" => i64::from(v < w),
                "<=" => i64::from(v <= w),
                ">" => i64::from(v > w),
                ">=" => i64::from(v >= w),
                "<<" => v.wrapping_shl(w as u32),
                ">>" => v.wrapping_shr(w as u32),
                "+" => v.wrapping_add(w),
                "-" => v.wrapping_sub(w),
                "*" => v.wrapping_mul(w),
                "/" | "%" if w == 0 && self.dead > 0 => 0,
                "/" | "%" if w == 0 => {
                    return Err(Diagnostic::new(
                        span,
                        format!("division by zero in `{}`", self.directive),
                    ))
                }
                "/" => v.wrapping_div(w),
                _ => v.wrapping_rem(w),
            };
        }
        Ok(v)
    }

    /// unary := ('!' | '~' | '-' | '+') unary | primary
    fn unary(&mut self) -> Result<i64, Diagnostic> {
        if let Some(op) = self
            .peek_punct()
            .filter(|p| ["!", "~", "-", "+"].contains(p))
        {
            self.pos += 1;
            self.enter()?;
            let v = self.unary()?;
            self.depth -= 1;
            return Ok(match op {
                "!" => i64::from(v == 0),
                "~" => !v,
                "-" => v.wrapping_neg(),
                _ => v,
            });
        }
        self.primary()
    }

    /// primary := INTEGER | NAME | 'defined' NAME | 'defined' '(' NAME ')'
    ///          | '(' conditional ')'
    fn primary(&mut self) -> Result<i64, Diagnostic> {
        let Some(t) = self.tokens.get(self.pos) else {
            return Err(self.error_here("a number"));
        };
        match &t.tok {
            Tok::Int(i) => {
                self.pos += 1;
                Ok(*i)
            }
            Tok::Ident(d) if d == "defined" => {
                self.pos += 1;
                let paren = self.peek_punct() == Some("(");
                if paren {
                    self.pos += 1;
                }
                let Some(Token {
                    tok: Tok::Ident(name),
                    ..
                }) = self.tokens.get(self.pos)
                else {
                    return Err(self.error_here("a macro name after `defined`"));
                };
                self.pos += 1;
                if paren {
                    if self.peek_punct() != Some(")") {
                        return Err(self.error_here("`)` after `defined(NAME`"));
                    }
                    self.pos += 1;
                }
                Ok(i64::from((self.defined)(name)))
            }
            Tok::Ident(name) => {
                self.pos += 1;
                Ok(i64::from(name == "true"))
            }
            Tok::Punct("(") => {
                self.pos += 1;
                let v = self.conditional()?;
                if self.peek_punct() != Some(")") {
                    return Err(self.error_here("`)` to close the parenthesis"));
                }
                self.pos += 1;
                Ok(v)
            }
            Tok::Float { value, .. } => Err(Diagnostic::new(
                t.span,
                format!(
                    "`{}` takes integer constants only, and `{value}` is a floating constant",
                    self.directive
                ),
            )),
            _ => Err(self.error_here("a number, a name or `(`")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::lex::lex;
    use crate::syntax::span::FileId;

    fn ev(text: &str) -> Result<i64, String> {
        let toks = lex(FileId(0), text).map_err(|d| d.message)?;
        eval(&toks, Span::default(), "#if", &|n| n == "DEF").map_err(|d| d.message)
    }

    /// Values worked out by hand with C's rules: precedence, truncating
    /// division, `%` with the sign of the dividend, 0/1 from comparisons
    /// and logic, unknown names 0.
    #[test]
    fn c_integer_expressions() {
        let cases = [
            ("1 + 2 * 3", 7),
            ("(1 + 2) * 3", 9),
            ("7 / 2", 3),
            ("-7 / 2", -3),
            ("-7 % 3", -1),
            ("1 << 4 | 1", 17),
            ("6 & 3 ^ 1", 3), // & binds tighter than ^: 2 ^ 1
            ("~0", -1),
            ("!5", 0),
            ("!0", 1),
            ("3 > 2 == 1", 1),
            ("2 < 1 || 4 >= 4", 1),
            ("1 && 0", 0),
            ("0 ? 10 : 1 ? 20 : 30", 20),
            ("UNKNOWN", 0),
            ("UNKNOWN + 1", 1),
            ("true + true", 2),
            ("false", 0),
            ("defined DEF", 1),
            ("defined(DEF) && !defined(OTHER)", 1),
            ("defined OTHER", 0),
            ("0x10 + 010", 24),
            ("10L * 2u", 20),
            ("- - 3", 3),
            ("1 != 2", 1),
            ("5 <= 4", 0),
            ("9 >> 1", 4),
            ("1 - 1 - 1", -1),
            // Operands C does not evaluate may divide by zero.
            ("0 && 1 / 0", 0),
            ("1 || 1 % 0", 1),
            ("1 ? 2 : 1 / 0", 2),
            ("0 ? 1 / 0 : 3", 3),
        ];
        for (text, want) in cases {
            assert_eq!(ev(text), Ok(want), "{text}");
        }
    }

    #[test]
    fn bad_expressions_are_errors() {
        let cases = [
            ("", "expected an expression after `#if`"),
            (
                "1 +",
                "expected a number in `#if`, found the end of the line",
            ),
            ("(1", "expected `)` to close the parenthesis"),
            ("1 2", "expected an operator or the end of the line"),
            ("1 / 0", "division by zero in `#if`"),
            ("5 % (2 - 2)", "division by zero"),
            ("1.5 > 1", "integer constants only"),
            ("\"a\"", "expected a number, a name or `(`"),
            ("defined", "a macro name after `defined`"),
            ("defined(X", "`)` after `defined(NAME`"),
            ("1 ? 2", "`:` of `?:`"),
        ];
        for (text, want) in cases {
            let e = ev(text).unwrap_err();
            assert!(e.contains(want), "{text}: {e}");
        }
        let deep = format!(
            "{}1{}",
            "(".repeat(MAX_DEPTH + 1),
            ")".repeat(MAX_DEPTH + 1)
        );
        assert!(ev(&deep).unwrap_err().contains("nests more than"));
        let ok = format!(
            "{}1{}",
            "(".repeat(MAX_DEPTH - 1),
            ")".repeat(MAX_DEPTH - 1)
        );
        assert_eq!(ev(&ok), Ok(1));
        let negs = format!("{}1", "!".repeat(MAX_DEPTH + 1));
        assert!(ev(&negs).unwrap_err().contains("nests more than"));
    }
}
