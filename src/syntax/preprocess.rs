//! The C-like preprocessor: `#include` of the lpfg headers, `#define` with
//! object-like and function-like macros, and `-D NAME=VALUE` overrides.
//!
//! A `#` that starts a line but is not followed by a directive name is left
//! alone: it is the endmarker module, as in `# P(vl) < P(v) > P(vr) : {...}`.

use std::collections::HashMap;

use super::lex::{Tok, Token};
use super::span::{Diagnostic, Span};

const DIRECTIVES: &[&str] = &[
    "include", "define", "undef", "ifdef", "ifndef", "if", "elif", "else", "endif", "pragma",
    "error",
];

/// Headers that stand for lpfg's built-in library and are accepted as no-ops.
const KNOWN_HEADERS: &[&str] = &[
    "lpfgall.h",
    "math.h",
    "stdlib.h",
    "stdio.h",
    "cmath",
    "lintrfc.h",
];

#[derive(Clone, Debug)]
struct Macro {
    params: Option<Vec<String>>,
    body: Vec<Token>,
}

/// Tokens a file's macro expansions may produce in all, so that a
/// runaway expansion stops with a message instead of exhausting memory.
const EXPANSION_BUDGET: usize = 2_000_000;

/// Runs the preprocessor over `tokens`. `overrides` are `-D` definitions,
/// already lexed; they replace a `#define` of the same name in the file.
pub fn preprocess(
    tokens: Vec<Token>,
    overrides: &[(String, Vec<Token>)],
) -> Result<Vec<Token>, Diagnostic> {
    let mut macros: HashMap<String, Macro> = HashMap::new();
    for (name, body) in overrides {
        macros.insert(
            name.clone(),
            Macro {
                params: None,
                body: body.clone(),
            },
        );
    }
    let overridden: Vec<&str> = overrides.iter().map(|(n, _)| n.as_str()).collect();
    let mut out = Vec::with_capacity(tokens.len());
    let mut budget = EXPANSION_BUDGET;
    // Tokens between directives are expanded together, with the macros
    // defined so far.
    let mut pending: Vec<Token> = Vec::new();
    let mut i = 0;
    while i < tokens.len() {
        let t = &tokens[i];
        let is_directive = t.tok.is_punct("#")
            && t.line_start
            && tokens.get(i + 1).is_some_and(|n| {
                !n.line_start && matches!(&n.tok, Tok::Ident(s) if DIRECTIVES.contains(&s.as_str()))
            });
        if !is_directive {
            pending.push(t.clone());
            i += 1;
            continue;
        }
        out.extend(expand(std::mem::take(&mut pending), &macros, &mut budget)?);
        let hash_span = t.span;
        let name_tok = &tokens[i + 1];
        let Tok::Ident(name) = &name_tok.tok else {
            unreachable!("checked above")
        };
        // The directive's tokens run to the end of the line.
        let mut end = i + 2;
        while end < tokens.len() && !tokens[end].line_start {
            end += 1;
        }
        let args = &tokens[i + 2..end];
        match name.as_str() {
            "include" => check_include(hash_span.to(name_tok.span), args)?,
            "define" => {
                let (mname, m) = parse_define(name_tok, args)?;
                if !overridden.contains(&mname.as_str()) {
                    macros.insert(mname, m);
                }
            }
            "undef" => {
                if let Some(Token { tok: Tok::Ident(m), .. }) = args.first() {
                    macros.remove(m);
                }
            }
            "pragma" => {}
            other => {
                return Err(Diagnostic::new(
                    hash_span.to(name_tok.span),
                    format!("the preprocessor directive `#{other}` is not supported; use `#define` and `-D` instead"),
                ))
            }
        }
        i = end;
    }
    out.extend(expand(pending, &macros, &mut budget)?);
    Ok(out)
}

/// `#define NAME body` or `#define NAME(a, b) body`.
fn parse_define(name_tok: &Token, args: &[Token]) -> Result<(String, Macro), Diagnostic> {
    let Some(first) = args.first() else {
        return Err(Diagnostic::new(
            name_tok.span,
            "expected a macro name after `#define`",
        ));
    };
    let Tok::Ident(mname) = &first.tok else {
        return Err(Diagnostic::new(
            first.span,
            format!(
                "expected a macro name after `#define`, found {}",
                first.tok.describe()
            ),
        ));
    };
    let mut body_start = 1;
    let mut params = None;
    if args
        .get(1)
        .is_some_and(|p| p.tok.is_punct("(") && !p.space_before)
    {
        let mut names = Vec::new();
        let mut j = 2;
        loop {
            match args.get(j) {
                Some(Token {
                    tok: Tok::Punct(")"),
                    ..
                }) => {
                    j += 1;
                    break;
                }
                Some(Token {
                    tok: Tok::Ident(p), ..
                }) => {
                    names.push(p.clone());
                    j += 1;
                    if args.get(j).is_some_and(|c| c.tok.is_punct(",")) {
                        j += 1;
                    }
                }
                Some(other) => {
                    return Err(Diagnostic::new(
                        other.span,
                        format!(
                        "expected a parameter name or `)` in the macro's parameter list, found {}",
                        other.tok.describe()
                    ),
                    ))
                }
                None => {
                    return Err(Diagnostic::new(
                        first.span,
                        "unterminated macro parameter list: expected `)`",
                    ))
                }
            }
        }
        body_start = j;
        params = Some(names);
    }
    let body = args[body_start..].to_vec();
    for w in body.windows(2) {
        if w[0].tok.is_punct("#") && w[1].tok.is_punct("#") && !w[1].space_before {
            return Err(Diagnostic::new(
                w[0].span.to(w[1].span),
                "token pasting with `##` is not supported in macros",
            ));
        }
    }
    Ok((mname.clone(), Macro { params, body }))
}

fn check_include(span: Span, args: &[Token]) -> Result<(), Diagnostic> {
    let mut name = String::new();
    for t in args {
        match &t.tok {
            Tok::Ident(s) => name.push_str(s),
            Tok::Str(s) => name.push_str(s),
            Tok::Punct(p) if *p != "<" && *p != ">" => name.push_str(p),
            _ => {}
        }
    }
    if KNOWN_HEADERS.contains(&name.as_str()) {
        Ok(())
    } else {
        Err(Diagnostic::new(
            span,
            format!(
                "cannot include `{name}`: only the built-in headers ({}) are available",
                KNOWN_HEADERS.join(", ")
            ),
        ))
    }
}

/// The names of the macros whose expansion produced a token: a macro is not
/// expanded again inside its own expansion.
type Hide = Vec<String>;

/// Expands macros as the C preprocessor does: an expansion is rescanned
/// together with the tokens that follow it (so `#define G INC` then
/// `G(1)` calls `INC`), and the arguments of a function-like macro are
/// expanded before they are substituted (so `SQ(SQ(2))` works).
fn expand(
    tokens: Vec<Token>,
    macros: &HashMap<String, Macro>,
    budget: &mut usize,
) -> Result<Vec<Token>, Diagnostic> {
    let input = tokens.into_iter().map(|t| (t, Hide::new())).collect();
    expand_hidden(input, macros, budget)
}

fn expand_hidden(
    tokens: Vec<(Token, Hide)>,
    macros: &HashMap<String, Macro>,
    budget: &mut usize,
) -> Result<Vec<Token>, Diagnostic> {
    if macros.is_empty() {
        return Ok(tokens.into_iter().map(|(t, _)| t).collect());
    }
    // A stack: the next token is at the end.
    let mut input: Vec<(Token, Hide)> = tokens.into_iter().rev().collect();
    let mut out = Vec::new();
    while let Some((t, hide)) = input.pop() {
        let Tok::Ident(name) = &t.tok else {
            out.push(t);
            continue;
        };
        let Some(m) = macros.get(name).filter(|_| !hide.contains(name)) else {
            out.push(t);
            continue;
        };
        let mut inner = hide.clone();
        inner.push(name.clone());
        let at_use = |b: &Token| Token {
            span: t.span,
            line_start: false,
            space_before: true,
            ..b.clone()
        };
        let expansion: Vec<(Token, Hide)> = match &m.params {
            None => m.body.iter().map(|b| (at_use(b), inner.clone())).collect(),
            Some(params) => {
                if !input.last().is_some_and(|(n, _)| n.tok.is_punct("(")) {
                    // A function-like macro's name without arguments.
                    out.push(t);
                    continue;
                }
                input.pop();
                let mut args: Vec<Vec<(Token, Hide)>> = vec![Vec::new()];
                let mut depth = 0;
                loop {
                    let Some((a, h)) = input.pop() else {
                        return Err(Diagnostic::new(
                            t.span,
                            format!("unterminated call of macro `{name}`: expected `)`"),
                        ));
                    };
                    match &a.tok {
                        Tok::Punct("(") => depth += 1,
                        Tok::Punct(")") if depth == 0 => break,
                        Tok::Punct(")") => depth -= 1,
                        Tok::Punct(",") if depth == 0 => {
                            args.push(Vec::new());
                            continue;
                        }
                        _ => {}
                    }
                    args.last_mut().expect("never empty").push((a, h));
                }
                if args.len() == 1 && args[0].is_empty() && params.is_empty() {
                    args.clear();
                }
                if args.len() != params.len() {
                    return Err(Diagnostic::new(
                        t.span,
                        format!(
                            "macro `{name}` takes {} argument(s) but {} were given",
                            params.len(),
                            args.len()
                        ),
                    ));
                }
                let mut expanded = Vec::with_capacity(args.len());
                for a in args {
                    expanded.push(expand_hidden(a, macros, budget)?);
                }
                let mut body = Vec::new();
                for b in &m.body {
                    match &b.tok {
                        Tok::Ident(p) if params.contains(p) => {
                            let k = params.iter().position(|q| q == p).expect("contained");
                            body.extend(expanded[k].iter().map(|a| (a.clone(), inner.clone())));
                        }
                        _ => body.push((at_use(b), inner.clone())),
                    }
                }
                body
            }
        };
        if expansion.len() > *budget {
            return Err(Diagnostic::new(
                t.span,
                format!(
                    "macro expansion produced more than {EXPANSION_BUDGET} tokens; is a macro defined in terms of itself many times over?"
                ),
            ));
        }
        *budget -= expansion.len();
        let mut items: Vec<(Token, Hide)> = expansion;
        if let Some((f, _)) = items.first_mut() {
            f.line_start = t.line_start;
        }
        input.extend(items.into_iter().rev());
    }
    Ok(out)
}
