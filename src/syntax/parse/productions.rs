//! Productions: predecessors with their context, successors of module
//! calls, and the single-character turtle of `angle:` files.

use crate::syntax::ast::{Block, Body, ModuleCall, Name, PatModule, Production};
use crate::syntax::lex::Tok;
use crate::syntax::span::{Diagnostic, Span};

use super::{PResult, Parser};

impl<'t> Parser<'t> {
    /// production := predecessor ( ':' block | '->' successor )
    /// predecessor := [pats '<<'] [pats '<'] pats ['>' pats] ['>>' pats]
    ///
    /// e.g. `P(vl) < P(v) > P(vr) : { produce ...; }`
    pub(super) fn production(&mut self) -> PResult<Production> {
        let start = self.span_here();
        let mut groups: Vec<Vec<PatModule>> = vec![Vec::new()];
        let mut seps: Vec<(&'static str, Span)> = Vec::new();
        loop {
            let Some(t) = self.peek() else {
                return self.error("`:` after the production's predecessor");
            };
            match &t.tok {
                Tok::Punct(p @ ("<" | ">" | "<<" | ">>")) => {
                    seps.push((p, t.span));
                    groups.push(Vec::new());
                    self.pos += 1;
                }
                Tok::Punct(":") | Tok::Punct("->") => break,
                Tok::Ident(_) | Tok::Punct("#") => {
                    let group = groups.last_mut().expect("non-empty");
                    if let Some(names) = self.abop_split() {
                        group.extend(names.into_iter().map(|name| PatModule {
                            name,
                            params: Vec::new(),
                        }));
                    }
                    let m = self.pat_module()?;
                    groups.last_mut().expect("non-empty").push(m);
                }
                Tok::Punct(p) if self.abop && abop_punct(p).is_some() => {
                    let span = t.span;
                    self.pos += 1;
                    for n in abop_punct(p).expect("checked") {
                        groups.last_mut().expect("non-empty").push(PatModule {
                            name: Name {
                                text: n.to_string(),
                                span,
                            },
                            params: Vec::new(),
                        });
                    }
                }
                _ => {
                    return self.error(
                        "a module, `<`, `>`, `<<`, `>>` or `:` in the production's predecessor",
                    )
                }
            }
        }
        let pred_span = start.to(self.prev_span());
        let mut prod = Production {
            new_left: Vec::new(),
            left: Vec::new(),
            strict: Vec::new(),
            right: Vec::new(),
            new_right: Vec::new(),
            body: Body::Arrow(Vec::new(), pred_span),
            span: pred_span,
        };
        // Assign the groups by their separators, in the fixed order
        // new-left << left < strict > right >> new-right.
        let order = ["<<", "<", "", ">", ">>"];
        let mut slot = 0; // index into order of the current group
        let mut groups = groups.into_iter();
        let mut current = groups.next().expect("one group");
        // The first group is strict unless a `<<` or `<` follows it.
        let first_sep = seps.first().map(|s| s.0);
        slot = match first_sep {
            Some("<<") => 0,
            Some("<") => 1,
            _ => 2,
        }
        .max(slot);
        for (i, (sep, span)) in seps.iter().enumerate() {
            let target = match slot {
                0 => &mut prod.new_left,
                1 => &mut prod.left,
                2 => &mut prod.strict,
                3 => &mut prod.right,
                _ => &mut prod.new_right,
            };
            *target = std::mem::take(&mut current);
            current = groups.next().expect("one group per separator");
            let next_slot = match *sep {
                "<<" => 1,
                "<" => 2,
                ">" => 3,
                ">>" => 4,
                _ => unreachable!(),
            };
            // After `<<`, the next group is left context only if a `<` follows.
            let next_slot = if *sep == "<<" && seps.get(i + 1).map(|s| s.0) != Some("<") {
                2
            } else {
                next_slot
            };
            if next_slot <= slot || (slot < 2 && next_slot > 2) {
                return Err(Diagnostic::new(
                    *span,
                    format!(
                        "unexpected `{sep}`: the predecessor must read `new-left << left < strict > right >> new-right`, each part optional but the strict predecessor"
                    ),
                ));
            }
            slot = next_slot;
        }
        let _ = order;
        let target = match slot {
            0 => &mut prod.new_left,
            1 => &mut prod.left,
            2 => &mut prod.strict,
            3 => &mut prod.right,
            _ => &mut prod.new_right,
        };
        *target = current;
        if prod.strict.is_empty() {
            return Err(Diagnostic::new(
                pred_span,
                "expected a strict predecessor: at least one module between the contexts",
            ));
        }
        if self.eat_punct("->") {
            let arrow = self.prev_span();
            let line_end = self.line_end();
            let succ = self.module_calls_until(line_end)?;
            self.eat_punct(";");
            prod.body = Body::Arrow(succ, arrow);
        } else {
            self.expect_punct(":", "after the predecessor")?;
            if self.peek_punct("{") {
                prod.body = Body::Block(self.block()?);
                self.eat_punct(";");
            } else {
                // `A(t) : produce A(t+1);`: one statement as the body.
                let start = self.span_here();
                let s = self.stmt_or_end()?;
                prod.body = Body::Block(Block {
                    stmts: vec![s],
                    span: start.to(self.prev_span()),
                });
            }
        }
        Ok(prod)
    }

    /// The index of the first token after the current line, at paren depth 0.
    fn line_end(&self) -> usize {
        let mut j = self.pos;
        let mut depth = 0i32;
        while let Some(t) = self.toks.get(j) {
            if j > self.pos && t.line_start && depth == 0 {
                break;
            }
            if t.tok.is_punct("(") {
                depth += 1;
            } else if t.tok.is_punct(")") {
                depth -= 1;
            } else if t.tok.is_punct(";") && depth == 0 {
                break;
            }
            j += 1;
        }
        j
    }

    /// pat-module := NAME [ '(' [NAME {',' NAME}] ')' ] | '#'
    pub(super) fn pat_module(&mut self) -> PResult<PatModule> {
        if self.peek_punct("#") {
            let t = self.bump();
            return Ok(PatModule {
                name: Name {
                    text: "#".into(),
                    span: t.span,
                },
                params: Vec::new(),
            });
        }
        let name = self.name("a module name")?;
        let mut params = Vec::new();
        if self.eat_punct("(") && !self.eat_punct(")") {
            loop {
                params.push(self.name("a parameter name in the module pattern")?);
                if self.eat_punct(")") {
                    break;
                }
                self.expect_punct(",", "or `)` between the pattern's parameters")?;
            }
        }
        Ok(PatModule { name, params })
    }

    /// A module list up to (not including) one of `stops`.
    /// module-call := NAME [ '(' args ')' ] | '#'
    pub(super) fn module_calls(
        &mut self,
        stops: &[&str],
        allow_close: bool,
    ) -> PResult<Vec<ModuleCall>> {
        let mut out = Vec::new();
        loop {
            let Some(t) = self.peek() else {
                return self.error(&format!("`{}`", stops[0]));
            };
            if stops.iter().any(|s| t.tok.is_punct(s)) || (allow_close && t.tok.is_punct("}")) {
                return Ok(out);
            }
            self.module_call_into(&mut out)?;
        }
    }

    fn module_calls_until(&mut self, end: usize) -> PResult<Vec<ModuleCall>> {
        let mut out = Vec::new();
        while self.pos < end {
            self.module_call_into(&mut out)?;
        }
        Ok(out)
    }

    pub(super) fn at_module(&self) -> bool {
        match self.peek().map(|t| &t.tok) {
            Some(Tok::Ident(_)) | Some(Tok::Punct("#")) => true,
            Some(Tok::Punct(p)) => self.abop && abop_punct(p).is_some(),
            _ => false,
        }
    }

    /// In turtle mode, an identifier such as `FX` that names no declared or
    /// predefined module stands for one module per character. Consumes all
    /// characters but the last and returns them; the caller parses the last
    /// one with its arguments.
    fn abop_split(&mut self) -> Option<Vec<Name>> {
        if !self.abop {
            return None;
        }
        let t = self.peek()?;
        let Tok::Ident(s) = &t.tok else { return None };
        if s.len() < 2 || self.whole_names.contains(s) || !s.is_ascii() {
            return None;
        }
        let start = t.span.start as usize;
        let file = t.span.file;
        let names: Vec<Name> = s
            .char_indices()
            .map(|(k, c)| Name {
                text: c.to_string(),
                span: Span::new(file, start + k, start + k + 1),
            })
            .collect();
        // Replace the token by its last character, so the usual parsing of
        // `X(args)` applies to it.
        let last = names.last().cloned()?;
        self.split_last = Some((self.pos, last));
        Some(names[..names.len() - 1].to_vec())
    }

    /// One module, or in turtle mode possibly several (`FX`, `--`).
    pub(super) fn module_call_into(&mut self, out: &mut Vec<ModuleCall>) -> PResult<()> {
        if self.abop {
            if let Some(Tok::Punct(p)) = self.peek().map(|t| &t.tok) {
                if let Some(names) = abop_punct(p) {
                    let span = self.bump().span;
                    for (k, n) in names.iter().enumerate() {
                        let args = if k + 1 == names.len()
                            && self.peek_punct("(")
                            && !self.toks[self.pos].space_before
                        {
                            self.pos += 1;
                            self.args(")")?
                        } else {
                            Vec::new()
                        };
                        out.push(ModuleCall {
                            name: Name {
                                text: n.to_string(),
                                span,
                            },
                            args,
                        });
                    }
                    return Ok(());
                }
            }
            if let Some(names) = self.abop_split() {
                out.extend(names.into_iter().map(|name| ModuleCall {
                    name,
                    args: Vec::new(),
                }));
            }
        }
        out.push(self.module_call()?);
        Ok(())
    }

    fn module_call(&mut self) -> PResult<ModuleCall> {
        if self.peek_punct("#") {
            let t = self.bump();
            return Ok(ModuleCall {
                name: Name {
                    text: "#".into(),
                    span: t.span,
                },
                args: Vec::new(),
            });
        }
        if !matches!(self.peek().map(|t| &t.tok), Some(Tok::Ident(_))) {
            let turtle = match self.peek().map(|t| &t.tok) {
                Some(Tok::Punct(p)) if !self.abop && abop_punct(p).is_some() => Some(p.to_string()),
                _ => None,
            };
            let mut e: PResult<ModuleCall> =
                self.error("a module (a name, optionally with arguments in parentheses)");
            if let (Some(p), Err(d)) = (turtle, e.as_mut()) {
                d.message.push_str(&format!(
                    "; `{p}` is a turtle command of the single-character notation (The \
                     Algorithmic Beauty of Plants), which `angle: DEGREES;` at the start of a \
                     line switches on"
                ));
            }
            return e;
        }
        let name = self.name("a module name")?;
        let args = if self.eat_punct("(") {
            self.args(")")?
        } else {
            Vec::new()
        };
        Ok(ModuleCall { name, args })
    }
}

/// The turtle modules of The Algorithmic Beauty of Plants' characters.
/// A doubled operator such as `--` is lexed as one token and means two.
fn abop_punct(p: &str) -> Option<&'static [&'static str]> {
    Some(match p {
        "+" => &["Left"],
        "-" => &["Right"],
        "++" => &["Left", "Left"],
        "--" => &["Right", "Right"],
        "&" => &["Down"],
        "&&" => &["Down", "Down"],
        "^" => &["Up"],
        "\\" => &["RollL"],
        "/" => &["RollR"],
        "|" => &["TurnAround"],
        "||" => &["TurnAround", "TurnAround"],
        "[" => &["SB"],
        "]" => &["EB"],
        _ => return None,
    })
}
