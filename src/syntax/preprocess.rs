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
    let mut i = 0;
    while i < tokens.len() {
        let t = &tokens[i];
        let is_directive = t.tok.is_punct("#")
            && t.line_start
            && tokens.get(i + 1).is_some_and(|n| {
                !n.line_start && matches!(&n.tok, Tok::Ident(s) if DIRECTIVES.contains(&s.as_str()))
            });
        if !is_directive {
            expand_into(&tokens, &mut i, &macros, &mut out, &mut Vec::new())?;
            continue;
        }
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
                let Some(first) = args.first() else {
                    return Err(Diagnostic::new(
                        name_tok.span,
                        "expected a macro name after `#define`",
                    ));
                };
                let Tok::Ident(mname) = &first.tok else {
                    return Err(Diagnostic::new(
                        first.span,
                        format!("expected a macro name after `#define`, found {}", first.tok.describe()),
                    ));
                };
                let mut body_start = 1;
                let mut params = None;
                if args.get(1).is_some_and(|p| p.tok.is_punct("(") && !p.space_before) {
                    let mut names = Vec::new();
                    let mut j = 2;
                    loop {
                        match args.get(j) {
                            Some(Token { tok: Tok::Punct(")"), .. }) => {
                                j += 1;
                                break;
                            }
                            Some(Token { tok: Tok::Ident(p), .. }) => {
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
                if !overridden.contains(&mname.as_str()) {
                    macros.insert(
                        mname.clone(),
                        Macro {
                            params,
                            body: args[body_start..].to_vec(),
                        },
                    );
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
    Ok(out)
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

/// Copies the token at `*i` into `out`, expanding it if it names a macro.
/// `active` holds the macros being expanded, so a macro never expands itself.
fn expand_into(
    tokens: &[Token],
    i: &mut usize,
    macros: &HashMap<String, Macro>,
    out: &mut Vec<Token>,
    active: &mut Vec<String>,
) -> Result<(), Diagnostic> {
    let t = &tokens[*i];
    *i += 1;
    let Tok::Ident(name) = &t.tok else {
        out.push(t.clone());
        return Ok(());
    };
    let Some(m) = macros.get(name).filter(|_| !active.contains(name)) else {
        out.push(t.clone());
        return Ok(());
    };
    let use_span = t.span;
    let body: Vec<Token> = match &m.params {
        None => m.body.clone(),
        Some(params) => {
            if !tokens.get(*i).is_some_and(|p| p.tok.is_punct("(")) {
                // A function-like macro name without arguments is just a name.
                out.push(t.clone());
                return Ok(());
            }
            *i += 1;
            let mut args: Vec<Vec<Token>> = vec![Vec::new()];
            let mut depth = 0;
            loop {
                let Some(a) = tokens.get(*i) else {
                    return Err(Diagnostic::new(
                        use_span,
                        format!("unterminated call of macro `{name}`: expected `)`"),
                    ));
                };
                *i += 1;
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
                args.last_mut().expect("never empty").push(a.clone());
            }
            if args.len() == 1 && args[0].is_empty() && params.is_empty() {
                args.clear();
            }
            if args.len() != params.len() {
                return Err(Diagnostic::new(
                    use_span,
                    format!(
                        "macro `{name}` takes {} argument(s) but {} were given",
                        params.len(),
                        args.len()
                    ),
                ));
            }
            let mut body = Vec::new();
            for b in &m.body {
                match &b.tok {
                    Tok::Ident(p) if params.contains(p) => {
                        // Textual substitution, as the C preprocessor does.
                        let k = params.iter().position(|q| q == p).expect("contained");
                        body.extend(args[k].iter().cloned());
                    }
                    _ => body.push(b.clone()),
                }
            }
            body
        }
    };
    active.push(name.clone());
    let mut j = 0;
    let mut expanded = Vec::new();
    while j < body.len() {
        expand_into(&body, &mut j, macros, &mut expanded, active)?;
    }
    active.pop();
    let first = out.len();
    for mut e in expanded {
        e.span = use_span;
        e.line_start = false;
        e.space_before = true;
        out.push(e);
    }
    if let Some(f) = out.get_mut(first) {
        f.line_start = t.line_start;
    }
    Ok(())
}
