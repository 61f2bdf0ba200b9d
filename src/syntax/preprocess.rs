//! The C-like preprocessor: `#include` of the lpfg headers, `#define` with
//! object-like and function-like macros, `#undef`, the conditionals `#if`,
//! `#ifdef`, `#ifndef`, `#elif`, `#else` and `#endif` (the expressions in
//! [`super::ifexpr`]), `#error`, and `-D NAME=VALUE` overrides.
//!
//! A group that a conditional skips may hold anything: its directives other
//! than the conditionals are not run, and what the lexer could not read
//! there is no error. An override wins over the file: a `#define` or
//! `#undef` of its name is ignored.
//!
//! A `#` that starts a line but is not followed by a directive name is left
//! alone: it is the endmarker module, as in `# P(vl) < P(v) > P(vr) : {...}`.

use std::collections::{HashMap, HashSet};

use super::lex::{Lexed, Tok, Token};
use super::span::{Diagnostic, Span};

const DIRECTIVES: &[&str] = &[
    "include", "define", "undef", "ifdef", "ifndef", "if", "elif", "else", "endif", "pragma",
    "error",
];

/// lpfg's own headers: its library is built in, so including them does
/// nothing.
const KNOWN_HEADERS: &[&str] = &["lpfgall.h", "lintrfc.h"];

/// The standard C and C++ headers whose functions programs call: the
/// library is built in, so including one of them (`<string.h>` or, as C's
/// search falls back to them, `"string.h"`) does nothing; a function that
/// subgram lacks is refused where it is called.
const STANDARD_HEADERS: &[&str] = &[
    "math.h", "stdlib.h", "stdio.h", "string.h", "memory.h", "assert.h", "ctype.h", "float.h",
    "limits.h", "time.h", "cmath", "cstdlib", "cstdio", "cstring", "cassert", "cctype", "cfloat",
    "climits", "ctime", "iostream",
];

#[derive(Clone, Debug)]
struct Macro {
    /// Tells a macro's expansions apart from those of an earlier
    /// definition of the same name.
    id: usize,
    params: Option<Vec<String>>,
    body: Vec<Token>,
    /// For each token of the body, the parameter it names, if any: found
    /// once, when the macro is defined.
    uses: Vec<Option<usize>>,
}

impl Macro {
    fn new(id: usize, params: Option<Vec<String>>, body: Vec<Token>) -> Macro {
        // A name given twice means its first parameter.
        let mut index: HashMap<&str, usize> = HashMap::new();
        for (k, p) in params.iter().flatten().enumerate() {
            index.entry(p.as_str()).or_insert(k);
        }
        let uses = body
            .iter()
            .map(|b| match &b.tok {
                Tok::Ident(p) => index.get(p.as_str()).copied(),
                _ => None,
            })
            .collect();
        Macro {
            id,
            params,
            body,
            uses,
        }
    }
}

/// Tokens that macro expansion may produce or pass as arguments in all,
/// so that a runaway expansion stops with a message instead of exhausting
/// memory or time.
pub const EXPANSION_BUDGET: usize = 2_000_000;

/// How deeply macro calls may nest inside macro arguments (`F(F(F(x)))`):
/// each level's arguments are expanded before the level around it.
pub const MAX_MACRO_NESTING: usize = 100;

/// An open conditional: `#if` … `#endif`.
struct Cond {
    /// `#if` and its name, for "without `#endif`".
    span: Span,
    /// The group around it emits tokens.
    outer: bool,
    /// The current group emits tokens.
    active: bool,
    /// A group of this conditional has been taken: later `#elif`s and the
    /// `#else` are skipped.
    taken: bool,
    /// Its `#else` has been seen.
    seen_else: bool,
}

/// Runs the preprocessor over `lexed`. `overrides` are `-D` definitions,
/// already lexed; they replace a `#define` of the same name in the file.
/// What the lexer could not read is an error here unless a conditional
/// skips it.
pub fn preprocess(
    lexed: Lexed,
    overrides: &[(String, Vec<Token>)],
) -> Result<Vec<Token>, Diagnostic> {
    let Lexed { tokens, errors } = lexed;
    let mut errors = errors.into_iter().peekable();
    let mut macros: HashMap<String, Macro> = HashMap::new();
    // Ids of definitions, from 0 up.
    let mut next_id = 0;
    for (name, body) in overrides {
        macros.insert(name.clone(), Macro::new(next_id, None, body.clone()));
        next_id += 1;
    }
    let overridden: HashSet<&str> = overrides.iter().map(|(n, _)| n.as_str()).collect();
    let mut out = Vec::with_capacity(tokens.len());
    let mut expander = Expander {
        budget: EXPANSION_BUDGET,
        nesting: 0,
        disabled: Vec::new(),
    };
    let mut conds: Vec<Cond> = Vec::new();
    // Tokens between directives are expanded together, with the macros
    // defined so far.
    let mut pending: Vec<Token> = Vec::new();
    let mut tokens = tokens.into_iter().enumerate().peekable();
    loop {
        let active = conds.last().is_none_or(|c| c.active);
        // What the lexer could not read before the next token.
        let next = tokens.peek().map_or(usize::MAX, |(i, _)| *i);
        while let Some((_, d)) = errors.next_if(|(k, _)| *k <= next) {
            if active {
                return Err(d);
            }
        }
        let Some((_, t)) = tokens.next() else { break };
        let is_directive = t.tok.is_punct("#")
            && t.line_start
            && tokens.peek().is_some_and(|(_, n)| {
                !n.line_start && matches!(&n.tok, Tok::Ident(s) if DIRECTIVES.contains(&s.as_str()))
            });
        if !is_directive {
            if !active {
                continue;
            }
            if macros.is_empty() {
                // Nothing to expand: straight to the output.
                out.push(t);
            } else {
                pending.push(t);
            }
            continue;
        }
        let hash_span = t.span;
        let (_, name_tok) = tokens.next().expect("peeked");
        let Tok::Ident(name) = &name_tok.tok else {
            unreachable!("checked above")
        };
        let at = hash_span.to(name_tok.span);
        // The directive's tokens run to the end of the line.
        let mut args = Vec::new();
        while let Some((_, a)) = tokens.next_if(|(_, a)| !a.line_start) {
            args.push(a);
        }
        match name.as_str() {
            "if" | "ifdef" | "ifndef" => {
                let value = if !active {
                    false
                } else if name == "if" {
                    if_value(&args, at, "#if", &macros, &mut expander, next_id)?
                } else {
                    let Some(Token {
                        tok: Tok::Ident(m), ..
                    }) = args.first()
                    else {
                        let span = args.first().map_or(at, |a| a.span);
                        return Err(Diagnostic::new(
                            span,
                            format!("expected a macro name after `#{name}`"),
                        ));
                    };
                    macros.contains_key(m) == (name == "ifdef")
                };
                conds.push(Cond {
                    span: at,
                    outer: active,
                    active: value,
                    taken: value,
                    seen_else: false,
                });
            }
            "elif" | "else" => {
                let Some(c) = conds.last_mut() else {
                    return Err(Diagnostic::new(
                        at,
                        format!("`#{name}` without `#if`: no conditional is open here"),
                    ));
                };
                if c.seen_else {
                    return Err(Diagnostic::new(
                        at,
                        format!("`#{name}` after `#else`: the `#else` must be the conditional's last group"),
                    ));
                }
                if name == "else" {
                    c.seen_else = true;
                    c.active = c.outer && !c.taken;
                    c.taken = true;
                } else if c.outer && !c.taken {
                    let v = if_value(&args, at, "#elif", &macros, &mut expander, next_id)?;
                    let c = conds.last_mut().expect("checked above");
                    c.active = v;
                    c.taken = v;
                } else {
                    c.active = false;
                }
            }
            "endif" => {
                if conds.pop().is_none() {
                    return Err(Diagnostic::new(
                        at,
                        "`#endif` without `#if`: no conditional is open here",
                    ));
                }
            }
            _ if !active => {}
            "include" => check_include(at, &args)?,
            "define" => {
                out.extend(expander.expand(std::mem::take(&mut pending), &macros, next_id)?);
                let (mname, params, body) = parse_define(&name_tok, &args)?;
                if !overridden.contains(mname.as_str()) {
                    let id = next_id;
                    next_id += 1;
                    macros.insert(mname, Macro::new(id, params, body));
                }
            }
            "undef" => {
                out.extend(expander.expand(std::mem::take(&mut pending), &macros, next_id)?);
                match args.first() {
                    Some(Token {
                        tok: Tok::Ident(m), ..
                    }) => {
                        if !overridden.contains(m.as_str()) {
                            macros.remove(m);
                        }
                    }
                    other => {
                        return Err(Diagnostic::new(
                            other.map_or(at, |a| a.span),
                            "expected a macro name after `#undef`",
                        ))
                    }
                }
            }
            "error" => {
                let mut text = String::new();
                for a in &args {
                    if a.space_before && !text.is_empty() {
                        text.push(' ');
                    }
                    text += &spelling(&a.tok);
                }
                return Err(Diagnostic::new(at, format!("`#error`: {text}")));
            }
            "pragma" => {}
            other => {
                return Err(Diagnostic::new(
                    at,
                    format!("the preprocessor directive `#{other}` is not supported; use `#define` and `-D` instead"),
                ))
            }
        }
    }
    if let Some(c) = conds.last() {
        return Err(Diagnostic::new(
            c.span,
            "this conditional has no `#endif`: the file ends inside it",
        ));
    }
    out.extend(expander.expand(pending, &macros, next_id)?);
    Ok(out)
}

/// A token as the source spells it, near enough for `#error`'s message.
fn spelling(t: &Tok) -> String {
    match t {
        Tok::Ident(s) => s.clone(),
        Tok::Int(i) => i.to_string(),
        Tok::Float { value, .. } => value.to_string(),
        Tok::Str(s) => format!("\"{s}\""),
        Tok::Punct(p) => p.to_string(),
    }
}

/// Whether the expression of `#if` or `#elif` (`directive`, at `at`) is
/// true: `defined` answered first, the rest macro-expanded, then
/// evaluated as C does.
fn if_value(
    args: &[Token],
    at: Span,
    directive: &str,
    macros: &HashMap<String, Macro>,
    expander: &mut Expander,
    ids: usize,
) -> Result<bool, Diagnostic> {
    // `defined X` and `defined(X)` are answered before expansion, so that
    // X is not expanded.
    let mut toks = Vec::with_capacity(args.len());
    let mut i = 0;
    while i < args.len() {
        let t = &args[i];
        if t.tok.is_ident("defined") {
            let paren = args.get(i + 1).is_some_and(|p| p.tok.is_punct("("));
            let k = i + 1 + usize::from(paren);
            let closed = !paren || args.get(k + 1).is_some_and(|p| p.tok.is_punct(")"));
            if let (
                Some(Token {
                    tok: Tok::Ident(m),
                    span,
                    ..
                }),
                true,
            ) = (args.get(k), closed)
            {
                let end = if paren { args[k + 1].span } else { *span };
                toks.push(Token {
                    tok: Tok::Int(i64::from(macros.contains_key(m))),
                    span: t.span.to(end),
                    ..t.clone()
                });
                i = k + 1 + usize::from(paren);
                continue;
            }
        }
        toks.push(t.clone());
        i += 1;
    }
    let toks = expander.expand(toks, macros, ids)?;
    let v = super::ifexpr::eval(&toks, at, directive, &|m| macros.contains_key(m))?;
    Ok(v != 0)
}

/// A `#define`'s name, parameters (for a function-like macro) and body.
type Define = (String, Option<Vec<String>>, Vec<Token>);

/// `#define NAME body` or `#define NAME(a, b) body`.
fn parse_define(name_tok: &Token, args: &[Token]) -> Result<Define, Diagnostic> {
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
    Ok((mname.clone(), params, body))
}

fn check_include(span: Span, args: &[Token]) -> Result<(), Diagnostic> {
    let mut name = String::new();
    let angled = args.first().is_some_and(|t| t.tok.is_punct("<"));
    for t in args {
        match &t.tok {
            Tok::Ident(s) => name.push_str(s),
            Tok::Str(s) => name.push_str(s),
            Tok::Punct(p) if *p != "<" && *p != ">" => name.push_str(p),
            _ => {}
        }
    }
    if KNOWN_HEADERS.contains(&name.as_str()) || STANDARD_HEADERS.contains(&name.as_str()) {
        Ok(())
    } else {
        let own = if angled {
            ""
        } else {
            "; a program's own header files are not read"
        };
        Err(Diagnostic::new(
            span,
            format!(
                "cannot include `{name}`: only lpfg's headers ({}) and the standard C and C++ headers (<math.h>, <string.h>, <cstdlib>, ...) are available{own}",
                KNOWN_HEADERS.join(", ")
            ),
        ))
    }
}

/// A token on the expander's input, or the end of a macro's expansion.
enum Item {
    /// `true` when the token names a macro that must never expand: it
    /// came out of that macro's own expansion (C's "painted blue").
    Tok(Token, bool),
    /// The expansion of the macro with this id ends here: it may expand
    /// again.
    End(usize),
}

/// Macro expansion as the C preprocessor does it: an expansion is
/// rescanned together with the tokens that follow it (so `#define G INC`
/// then `G(1)` calls `INC`), the arguments of a function-like macro are
/// expanded before they are substituted (so `SQ(SQ(2))` works), and a
/// macro does not expand inside its own expansion. Every token is handled
/// a bounded number of times: the work is linear in the tokens produced.
struct Expander {
    /// Tokens that may still be produced or passed as arguments.
    budget: usize,
    /// How many macro calls' arguments are being expanded, one inside the
    /// other.
    nesting: usize,
    /// By macro id: its expansion is being rescanned.
    disabled: Vec<bool>,
}

impl Expander {
    fn expand(
        &mut self,
        tokens: Vec<Token>,
        macros: &HashMap<String, Macro>,
        ids: usize,
    ) -> Result<Vec<Token>, Diagnostic> {
        if macros.is_empty() || tokens.is_empty() {
            return Ok(tokens);
        }
        // Every id is below the number of definitions made so far; every
        // flag is down again after a rescan.
        if self.disabled.len() < ids {
            self.disabled.resize(ids, false);
        }
        let items = tokens.into_iter().map(|t| Item::Tok(t, false)).collect();
        let out = self.rescan(items, macros)?;
        Ok(out.into_iter().map(|(t, _)| t).collect())
    }

    fn spend(&mut self, tokens: usize, at: Span) -> Result<(), Diagnostic> {
        if tokens > self.budget {
            return Err(Diagnostic::new(
                at,
                format!(
                    "macro expansion is too large: more than {EXPANSION_BUDGET} tokens produced or \
                     passed as arguments; is a macro defined in terms of itself many times over?"
                ),
            ));
        }
        self.budget -= tokens;
        Ok(())
    }

    /// Expands `items`; each output token says whether it is painted.
    fn rescan(
        &mut self,
        items: Vec<Item>,
        macros: &HashMap<String, Macro>,
    ) -> Result<Vec<(Token, bool)>, Diagnostic> {
        // A stack: the next item is at the end.
        let mut input: Vec<Item> = items;
        input.reverse();
        let mut out = Vec::with_capacity(input.len());
        while let Some(item) = input.pop() {
            let (t, painted) = match item {
                Item::End(id) => {
                    self.disabled[id] = false;
                    continue;
                }
                Item::Tok(t, painted) => (t, painted),
            };
            let m = match &t.tok {
                Tok::Ident(name) if !painted => macros.get(name).map(|m| (name, m)),
                _ => None,
            };
            let Some((name, m)) = m else {
                out.push((t, painted));
                continue;
            };
            if self.disabled[m.id] {
                out.push((t, true));
                continue;
            }
            let at_use = |b: &Token| Token {
                span: t.span,
                line_start: false,
                space_before: true,
                ..b.clone()
            };
            let mut expansion: Vec<Item> = match &m.params {
                None => {
                    self.spend(m.body.len(), t.span)?;
                    m.body.iter().map(|b| Item::Tok(at_use(b), false)).collect()
                }
                Some(params) => {
                    // The next token, past the ends of expansions, must
                    // open the arguments.
                    let next = input.iter().rev().find_map(|i| match i {
                        Item::Tok(n, _) => Some(n),
                        Item::End(_) => None,
                    });
                    if !next.is_some_and(|n| n.tok.is_punct("(")) {
                        // A function-like macro's name without arguments.
                        out.push((t, false));
                        continue;
                    }
                    let args = self.arguments(&mut input, &t, name, params.len())?;
                    if self.nesting >= MAX_MACRO_NESTING {
                        return Err(Diagnostic::new(
                            t.span,
                            format!(
                                "macro calls are nested more than {MAX_MACRO_NESTING} levels deep \
                                 in macro arguments; split the expression into simpler parts"
                            ),
                        ));
                    }
                    self.nesting += 1;
                    let mut expanded = Vec::with_capacity(args.len());
                    for a in args {
                        // After an error the expander is not used again.
                        expanded.push(self.rescan(a, macros)?);
                    }
                    self.nesting -= 1;
                    let mut body = Vec::new();
                    for (b, k) in m.body.iter().zip(&m.uses) {
                        match *k {
                            Some(k) => {
                                self.spend(expanded[k].len(), t.span)?;
                                body.extend(
                                    expanded[k].iter().map(|(a, p)| Item::Tok(a.clone(), *p)),
                                );
                            }
                            _ => {
                                self.spend(1, t.span)?;
                                body.push(Item::Tok(at_use(b), false));
                            }
                        }
                    }
                    body
                }
            };
            if let Some(Item::Tok(f, _)) = expansion.first_mut() {
                f.line_start = t.line_start;
            }
            self.disabled[m.id] = true;
            input.push(Item::End(m.id));
            expansion.reverse();
            input.append(&mut expansion);
        }
        Ok(out)
    }

    /// The arguments of a call of the function-like macro `name`, whose
    /// `(` is next on `input`: each a list of tokens, split at the commas
    /// outside parentheses, up to the matching `)`. Expansions that end
    /// on the way let their macros expand again.
    fn arguments(
        &mut self,
        input: &mut Vec<Item>,
        t: &Token,
        name: &str,
        want: usize,
    ) -> Result<Vec<Vec<Item>>, Diagnostic> {
        let mut args: Vec<Vec<Item>> = vec![Vec::new()];
        let mut depth = 0usize;
        let mut open = false;
        loop {
            let (a, painted) = match input.pop() {
                None => {
                    return Err(Diagnostic::new(
                        t.span,
                        format!("unterminated call of macro `{name}`: expected `)`"),
                    ))
                }
                Some(Item::End(id)) => {
                    self.disabled[id] = false;
                    continue;
                }
                Some(Item::Tok(a, painted)) => (a, painted),
            };
            if !open {
                // The `(`, found by the caller.
                open = true;
                continue;
            }
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
            self.spend(1, t.span)?;
            args.last_mut()
                .expect("never empty")
                .push(Item::Tok(a, painted));
        }
        if args.len() == 1 && args[0].is_empty() && want == 0 {
            args.clear();
        }
        if args.len() != want {
            return Err(Diagnostic::new(
                t.span,
                format!(
                    "macro `{name}` takes {want} argument(s) but {} were given",
                    args.len()
                ),
            ));
        }
        Ok(args)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::syntax::lex::{lex, lex_all};
    use crate::syntax::span::FileId;

    /// The expansion of `text`, tokens joined by spaces.
    fn expand(text: &str) -> Result<String, String> {
        let toks = lex_all(FileId(0), text).map_err(|d| d.message)?;
        let out = preprocess(toks, &[]).map_err(|d| d.message)?;
        let words: Vec<String> = out
            .iter()
            .map(|t| match &t.tok {
                Tok::Ident(s) => s.clone(),
                Tok::Int(i) => i.to_string(),
                Tok::Float { value, .. } => value.to_string(),
                Tok::Str(s) => format!("\"{s}\""),
                Tok::Punct(p) => p.to_string(),
            })
            .collect();
        Ok(words.join(" "))
    }

    #[test]
    fn macros_expand_as_in_c() {
        let cases = [
            ("#define N 2\nN + N", "2 + 2"),
            (
                "#define SQ(x) ((x)*(x))\nSQ(SQ(2))",
                "( ( ( ( 2 ) * ( 2 ) ) ) * ( ( ( 2 ) * ( 2 ) ) ) )",
            ),
            // The expansion is rescanned with what follows it.
            ("#define INC(x) x+1\n#define G INC\nG(1)", "1 + 1"),
            // A function-like name without arguments stays.
            ("#define F(x) x\nF + 1", "F + 1"),
            // A macro does not expand inside its own expansion ...
            ("#define A A + 1\nA", "A + 1"),
            ("#define f(x) f(x)\nf(1)", "f ( 1 )"),
            ("#define A B\n#define B A\nA B", "A B"),
            // ... nor once it has been passed over there (painted), even
            // when an argument carries it into another expansion.
            ("#define A A\n#define id(x) x\nid(A)", "A"),
            ("#define f(x) x f\nf(1)(2)", "1 f ( 2 )"),
            // But it does again after its expansion ends.
            ("#define A 1\n#define P(x) x A\nP(A) A", "1 1 1"),
            // Arguments split at top-level commas only.
            ("#define S(a, b) a - b\nS((1, 2), 3)", "( 1 , 2 ) - 3"),
            ("#define Z() 0\nZ()", "0"),
            // A long chain of definitions, each in terms of the one before.
            ("#define D0 7\n#define D1 D0\n#define D2 D1\nD2", "7"),
        ];
        for (text, want) in cases {
            assert_eq!(expand(text).as_deref(), Ok(want), "{text}");
        }
        assert!(expand("#define F(x) x\nF(1")
            .unwrap_err()
            .contains("unterminated call"));
        assert!(expand("#define F(x) x\nF(1, 2)")
            .unwrap_err()
            .contains("takes 1 argument(s) but 2 were given"));
    }

    /// Conditionals as C defines them: one group of each `#if` … `#endif`
    /// is kept, the first whose condition is true, or the `#else`.
    #[test]
    fn conditionals_keep_one_group() {
        let cases = [
            ("#if 1\na\n#else\nb\n#endif", "a"),
            ("#if 0\na\n#else\nb\n#endif", "b"),
            (
                "#if 0\na\n#elif 2 > 1\nb\n#elif 1\nc\n#else\nd\n#endif",
                "b",
            ),
            ("#if 0\na\n#elif 0\nb\n#endif\nz", "z"),
            ("#define N 3\n#if N * 2 == 6\nsix\n#endif", "six"),
            (
                "#define N 3\n#ifdef N\nyes\n#endif\n#ifndef N\nno\n#endif",
                "yes",
            ),
            ("#ifdef N\nyes\n#else\nno\n#endif", "no"),
            ("#define N\n#if defined(N) && !defined M\nok\n#endif", "ok"),
            // Nested: the inner conditional of a skipped group is skipped
            // whole, its `#else` included.
            ("#if 0\n#if 1\na\n#else\nb\n#endif\n#else\nc\n#endif", "c"),
            ("#if 1\n#if 0\na\n#elif 1\nb\n#endif\n#endif", "b"),
            // `#undef` ends a definition.
            (
                "#define N 1\n#undef N\n#ifdef N\na\n#else\nb\n#endif\nN",
                "b N",
            ),
            // A skipped group may hold anything, even what is no token, an
            // unknown directive, an `#error` or a bad `#include`.
            (
                "#if 0\n`é 1abc \"\n#error no\n#include <windows.h>\n#foo\n#endif\nok",
                "ok",
            ),
            ("#ifdef WIN32\n#include <windows.h>\n#endif\nok", "ok"),
            // A definition continued with a backslash.
            ("#define SUM(a, b) \\\n  a + \\\n  b\nSUM(1, 2)", "1 + 2"),
            // A `#define` in a skipped group defines nothing.
            (
                "#if 0\n#define N 1\n#endif\n#ifdef N\nyes\n#else\nno\n#endif",
                "no",
            ),
            // Directives inside a macro's arguments choose its tokens.
            (
                "#define F(x) [x]\nF(\n#if 1\na\n#else\nb\n#endif\n)",
                "[ a ]",
            ),
        ];
        for (text, want) in cases {
            assert_eq!(expand(text).as_deref(), Ok(want), "{text}");
        }
    }

    #[test]
    fn conditional_errors() {
        let cases = [
            ("#if 1\na", "this conditional has no `#endif`"),
            ("#if 0\n#if 1\n#endif", "this conditional has no `#endif`"),
            ("#endif", "`#endif` without `#if`"),
            ("#else", "`#else` without `#if`"),
            ("#elif 1", "`#elif` without `#if`"),
            ("#if 1\n#else\n#elif 1\n#endif", "`#elif` after `#else`"),
            ("#if 1\n#else\n#else\n#endif", "`#else` after `#else`"),
            ("#if\n#endif", "expected an expression after `#if`"),
            ("#if 1 +\n#endif", "expected a number in `#if`"),
            ("#if 1 / 0\n#endif", "division by zero in `#if`"),
            ("#if 0\n#elif 2 % 0\n#endif", "division by zero in `#elif`"),
            ("#ifdef\n#endif", "expected a macro name after `#ifdef`"),
            ("#ifndef 3\n#endif", "expected a macro name after `#ifndef`"),
            ("#undef", "expected a macro name after `#undef`"),
            ("#error N is needed", "`#error`: N is needed"),
            ("#if 1\n`\n#endif", "unexpected character"),
            ("#if 0\n#else\n1abc\n#endif", "not a valid number"),
        ];
        for (text, want) in cases {
            let e = expand(text).unwrap_err();
            assert!(e.contains(want), "{text}: {e}");
        }
    }

    /// `-D` overrides are defined for the conditionals and win over the
    /// file's `#define` and `#undef`.
    #[test]
    fn overrides_meet_conditionals() {
        let run = |text: &str, n: &str| {
            let toks = lex_all(FileId(0), text).unwrap();
            let over = vec![("N".to_string(), lex(FileId(1), n).unwrap())];
            let out = preprocess(toks, &over).unwrap();
            out.iter()
                .map(|t| spelling(&t.tok))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let text = "#ifndef N\n#define N 5\n#endif\n#if N > 4\nbig N\n#else\nsmall N\n#endif";
        assert_eq!(run(text, "7"), "big 7");
        assert_eq!(run(text, "2"), "small 2");
        assert_eq!(run("#undef N\nN", "2"), "2");
    }

    /// Expansion is linear: a chain of 100,000 definitions, each naming
    /// the one before, expands at once (it used to copy the growing list
    /// of macros being expanded at every link).
    #[test]
    fn a_long_chain_of_definitions_is_linear() {
        let n = 100_000;
        let mut text = String::from("#define D0 1\n");
        for i in 1..n {
            text += &format!("#define D{i} D{}\n", i - 1);
        }
        text += &format!("D{}\n", n - 1);
        let start = std::time::Instant::now();
        assert_eq!(expand(&text).as_deref(), Ok("1"));
        assert!(start.elapsed().as_secs() < 10, "{:?}", start.elapsed());
    }

    #[test]
    fn expansion_is_bounded() {
        // Arguments nested past the limit.
        let deep = format!(
            "#define F(x) x\n{}1{}",
            "F(".repeat(MAX_MACRO_NESTING + 1),
            ")".repeat(MAX_MACRO_NESTING + 1)
        );
        let e = expand(&deep).unwrap_err();
        assert!(
            e.contains("nested more than 100 levels deep in macro arguments"),
            "{e}"
        );
        let ok = format!(
            "#define F(x) x\n{}1{}",
            "F(".repeat(MAX_MACRO_NESTING),
            ")".repeat(MAX_MACRO_NESTING)
        );
        assert_eq!(expand(&ok).as_deref(), Ok("1"));
        // Exponential growth stops at the budget.
        let mut text = String::from("#define A0 x\n");
        for i in 1..40 {
            text += &format!("#define A{i} A{0} A{0}\n", i - 1);
        }
        text += "A39\n";
        let e = expand(&text).unwrap_err();
        assert!(e.contains("more than 2000000 tokens"), "{e}");
    }
}
