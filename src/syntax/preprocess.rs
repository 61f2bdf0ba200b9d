//! The C-like preprocessor: `#include` of the lpfg headers, `#define` with
//! object-like and function-like macros, and `-D NAME=VALUE` overrides.
//!
//! A `#` that starts a line but is not followed by a directive name is left
//! alone: it is the endmarker module, as in `# P(vl) < P(v) > P(vr) : {...}`.

use std::collections::{HashMap, HashSet};

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

/// The standard C and C++ headers whose functions programs call: the
/// library is built in, so an `#include <...>` of one of them is a no-op
/// (a function that subgram lacks is refused where it is called).
const STANDARD_HEADERS: &[&str] = &[
    "assert.h", "ctype.h", "float.h", "limits.h", "memory.h", "string.h", "time.h", "cassert",
    "cctype", "cfloat", "climits", "cstdio", "cstdlib", "cstring", "ctime", "iostream",
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

/// Runs the preprocessor over `tokens`. `overrides` are `-D` definitions,
/// already lexed; they replace a `#define` of the same name in the file.
pub fn preprocess(
    tokens: Vec<Token>,
    overrides: &[(String, Vec<Token>)],
) -> Result<Vec<Token>, Diagnostic> {
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
    // Tokens between directives are expanded together, with the macros
    // defined so far.
    let mut pending: Vec<Token> = Vec::new();
    let mut tokens = tokens.into_iter().peekable();
    while let Some(t) = tokens.next() {
        let is_directive = t.tok.is_punct("#")
            && t.line_start
            && tokens.peek().is_some_and(|n| {
                !n.line_start && matches!(&n.tok, Tok::Ident(s) if DIRECTIVES.contains(&s.as_str()))
            });
        if !is_directive {
            if macros.is_empty() {
                // Nothing to expand: straight to the output.
                out.push(t);
            } else {
                pending.push(t);
            }
            continue;
        }
        out.extend(expander.expand(std::mem::take(&mut pending), &macros, next_id)?);
        let hash_span = t.span;
        let name_tok = tokens.next().expect("peeked");
        let Tok::Ident(name) = &name_tok.tok else {
            unreachable!("checked above")
        };
        // The directive's tokens run to the end of the line.
        let mut args = Vec::new();
        while let Some(a) = tokens.next_if(|a| !a.line_start) {
            args.push(a);
        }
        match name.as_str() {
            "include" => check_include(hash_span.to(name_tok.span), &args)?,
            "define" => {
                let (mname, params, body) = parse_define(&name_tok, &args)?;
                if !overridden.contains(mname.as_str()) {
                    let id = next_id;
                    next_id += 1;
                    macros.insert(mname, Macro::new(id, params, body));
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
    }
    out.extend(expander.expand(pending, &macros, next_id)?);
    Ok(out)
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
    if KNOWN_HEADERS.contains(&name.as_str())
        || (angled && STANDARD_HEADERS.contains(&name.as_str()))
    {
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
                "cannot include `{name}`: only lpfg's headers ({}) and the standard C and C++ headers (<string.h>, <cstdlib>, ...) are available{own}",
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
    use crate::syntax::lex::lex;
    use crate::syntax::span::FileId;

    /// The expansion of `text`, tokens joined by spaces.
    fn expand(text: &str) -> Result<String, String> {
        let toks = lex(FileId(0), text).map_err(|d| d.message)?;
        let out = preprocess(toks, &[]).map_err(|d| d.message)?;
        let words: Vec<String> = out
            .iter()
            .map(|t| match &t.tok {
                Tok::Ident(s) => s.clone(),
                Tok::Int(i) => i.to_string(),
                Tok::Float(f) => f.to_string(),
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
