//! One rule tried at one module: its strict predecessor and old contexts
//! matched in the old word, its new contexts in the new word built so far,
//! its body run (a stencil, a compiled body or the interpreter, which asks
//! a [`WordHost`] for contexts) and its successor appended.

use crate::lang::closure;
use crate::lang::eval::{Emit, Env, Flow, Host};
use crate::lang::ir::{Pattern, Rule};
use crate::lang::value::{decode, decode_all, StructDef};
use crate::lang::{Sym, Value};
use crate::rewrite::context::{match_left, match_right, module_matches, Rules};
use crate::rewrite::word::{Reversed, Seq, Word};
use crate::syntax::ast::ContextKind;

use super::stencil::stencil_into;
use super::{Rewriter, StepError, StepOptions};

/// A sink for one module's successor that is full once the new word
/// would hold more than its limit.
struct Successor<'w> {
    word: &'w mut Word,
    room: usize,
}

impl Emit for Successor<'_> {
    fn emit(&mut self, sym: Sym, args: &[Value]) {
        self.word.push(sym, args);
    }

    fn emit_slots(&mut self, sym: Sym, slots: &[f64]) {
        self.word.push_raw(sym, slots);
    }

    fn emit_run(&mut self, syms: &[Sym], widths: &[usize], slots: &[f64]) {
        self.word.push_run(syms, widths, slots);
    }

    fn full(&self) -> bool {
        self.word.len() > self.room
    }
}

impl<'p> Rewriter<'p> {
    /// Prepares a step on a word that [`Rewriter::step`] did not start (a
    /// Gillespie step, which calls [`Rewriter::try_rule`] itself): the
    /// deadline, and no tables of the last step's word.
    pub(in crate::rewrite) fn begin(&mut self, opts: &StepOptions) {
        self.interp.deadline = opts.deadline;
        self.tables.clear();
    }

    /// Tries one rule with its strict predecessor starting at `start`.
    /// On success the successor is appended to `dst` (reversed when the step
    /// runs backward) and `true` is returned. With `any_flow` (a Gillespie
    /// step's reactions) the body applies whenever the predecessor matches,
    /// and everything it emitted is the successor, whether it ended with
    /// `produce` or not.
    #[allow(clippy::too_many_arguments)]
    pub(in crate::rewrite) fn try_rule(
        &mut self,
        r: usize,
        rule: &Rule,
        src: &Word,
        start: usize,
        dst: &mut Word,
        env: &mut Env,
        opts: &StepOptions,
        any_flow: bool,
    ) -> Result<bool, StepError> {
        let ctx = Rules {
            sb: self.sb,
            eb: self.eb,
            filter: &rule.filter,
            ring: opts.ring,
            tables: Some(&self.tables),
        };
        if (!rule.new_left.is_empty() && !opts.forward)
            || (!rule.new_right.is_empty() && opts.forward)
        {
            return Ok(false);
        }
        let Some((left_end, right_end)) = match_old(rule, src, start, ctx, &mut self.matched)
        else {
            return Ok(false);
        };
        // New contexts match the part of the new word built so far.
        self.new_matched.clear();
        let new_ctx = Rules {
            ring: false,
            tables: None,
            ..ctx
        };
        let mut new_left_end = dst.len() as isize - 1;
        let mut new_right_end = 0;
        if !rule.new_left.is_empty() {
            match match_left(
                dst,
                new_left_end,
                &rule.new_left,
                new_ctx,
                &mut self.new_matched,
            ) {
                Some(e) => new_left_end = e,
                None => return Ok(false),
            }
        }
        let new_left_count = self.new_matched.len();
        if !rule.new_right.is_empty() {
            match match_right(
                &Reversed(dst),
                0,
                &rule.new_right,
                new_ctx,
                &mut self.new_matched,
            ) {
                Some(e) => new_right_end = e,
                None => return Ok(false),
            }
        }

        if let Some(st) = &rule.stencil {
            let before = dst.len();
            stencil_into(st, r, src, &self.matched, dst)?;
            if !opts.forward {
                reverse_tail(dst, before, &mut self.tmp);
            }
            return Ok(true);
        }

        if let Some(body) = &self.bodies[r] {
            // The compiled body reads the matched modules' slots itself.
            self.machine.loop_limit = self.interp.loop_limit;
            self.machine.deadline = self.interp.deadline;
            if opts.forward {
                let (m, matched) = (&mut self.machine, &self.matched[..]);
                return run_forward(body, r, m, matched, src, dst, env, opts, any_flow, false);
            }
            let matched = &self.matched;
            self.tmp.clear();
            let mut successor = Successor {
                word: &mut self.tmp,
                room: opts.max_modules.saturating_sub(dst.len()),
            };
            let flow = body
                .run(
                    &mut self.machine,
                    |k| src.data(matched[k]),
                    env,
                    &mut successor,
                )
                .map_err(|error| {
                    if successor.full() {
                        StepError::TooLong {
                            limit: opts.max_modules,
                            rule: Some(r),
                        }
                    } else {
                        StepError::Runtime { rule: r, error }
                    }
                })?;
            return Ok(self.append_successor(flow, any_flow, opts, dst));
        }

        // Bind the parameters: slots are allocated in pattern order
        // new-left, left, strict, right, new-right.
        self.frame.clear();
        self.frame.resize(rule.frame_size, Value::Void);
        let program = self.program;
        let structs = &program.structs[..];
        let bind = |frame: &mut Vec<Value>, p: &Pattern, mut slots: &[f64]| {
            for (slot, ty) in p.slots.iter().zip(&p.types) {
                let (v, used) = decode(*ty, slots, structs);
                frame[*slot as usize] = v;
                slots = slots.get(used..).unwrap_or(&[]);
            }
        };
        for (p, &idx) in rule
            .new_left
            .iter()
            .zip(&self.new_matched[..new_left_count])
        {
            bind(&mut self.frame, p, dst.data(idx));
        }
        let old_pats = rule.left.iter().chain(&rule.strict).chain(&rule.right);
        for (p, &idx) in old_pats.zip(&self.matched) {
            bind(&mut self.frame, p, src.data(idx));
        }
        let rev = Reversed(dst);
        for (p, &idx) in rule
            .new_right
            .iter()
            .zip(&self.new_matched[new_left_count..])
        {
            bind(&mut self.frame, p, rev.data(idx));
        }

        self.tmp.clear();
        let mut host = WordHost {
            src,
            dst,
            structs,
            ctx,
            forward: opts.forward,
            left: left_end,
            right: right_end,
            new_left: new_left_end,
            new_right: new_right_end,
        };
        let mut successor = Successor {
            word: &mut self.tmp,
            room: opts.max_modules.saturating_sub(dst.len()),
        };
        let flow = self
            .interp
            .run(&rule.body, &mut self.frame, env, &mut host, &mut successor)
            .map_err(|error| {
                if successor.full() {
                    StepError::TooLong {
                        limit: opts.max_modules,
                        rule: Some(r),
                    }
                } else {
                    StepError::Runtime { rule: r, error }
                }
            })?;
        Ok(self.append_successor(flow, any_flow, opts, dst))
    }

    /// After a body ran: appends the successor it emitted to `dst` when it
    /// ended with `produce` (or with `any_flow`), and says whether it did.
    fn append_successor(
        &mut self,
        flow: Flow,
        any_flow: bool,
        opts: &StepOptions,
        dst: &mut Word,
    ) -> bool {
        if flow != Flow::Produced && !any_flow {
            return false;
        }
        if opts.forward {
            for j in 0..self.tmp.len() {
                dst.push_from(&self.tmp, j);
            }
        } else {
            for j in (0..self.tmp.len()).rev() {
                dst.push_from(&self.tmp, j);
            }
        }
        true
    }
}

/// Reverses the modules of `w` from `from` on, using `tmp` as scratch.
fn reverse_tail(w: &mut Word, from: usize, tmp: &mut Word) {
    tmp.clear();
    for j in from..w.len() {
        tmp.push_from(w, j);
    }
    w.truncate(from);
    for j in (0..tmp.len()).rev() {
        w.push_from(tmp, j);
    }
}

/// Matches `rule`'s strict predecessor at `start` and its left and right
/// contexts around it in the old word, pushing the matched modules (left
/// context, strict, right context) onto `matched`. Returns where the left
/// context's match ended and where the right one's did, or `None` when the
/// rule does not apply there.
#[inline]
pub(super) fn match_old(
    rule: &Rule,
    src: &Word,
    start: usize,
    ctx: Rules,
    matched: &mut Vec<usize>,
) -> Option<(isize, usize)> {
    let n = src.len();
    let len = rule.strict.len();
    // `(start + j) % n` in a ring, with no division short of the end.
    let at = |j: usize| {
        let k = start + j;
        if ctx.ring && k >= n {
            k % n
        } else {
            k
        }
    };
    // Cheap test first: the strict predecessor matches exactly.
    for (j, p) in rule.strict.iter().enumerate() {
        let idx = at(j);
        if idx >= n || !module_matches(src, idx, p) {
            return None;
        }
    }
    matched.clear();
    // A one-module context next to the predecessor, inside the word, is
    // matched here as `match_left` and `match_right` would match it: its
    // first look finds it.
    let left_end = match &rule.left[..] {
        [] if start > 0 || !ctx.ring => start as isize - 1,
        [p] if start > 0 && module_matches(src, start - 1, p) => {
            matched.push(start - 1);
            start as isize - 2
        }
        _ => match_left(src, start as isize - 1, &rule.left, ctx, matched)?,
    };
    matched.extend((0..len).map(at));
    let after = start + len;
    let right_end = match &rule.right[..] {
        [] if after < n => after,
        [p] if after < n && module_matches(src, after, p) => {
            matched.push(after);
            after + 1
        }
        _ => match_right(src, after, &rule.right, ctx, matched)?,
    };
    Some((left_end, right_end))
}

/// Runs rule `r`'s compiled body on the `matched` modules of `src`, in a
/// forward step: straight into `dst`, taken back when the body does not
/// produce (or fails). Says whether it produced. With `bound`, the
/// machine's frame already holds the parameters, as the body run last on
/// the same modules left them ([`closure::Body::leaves_params_for`]).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn run_forward(
    body: &closure::Body,
    r: usize,
    m: &mut closure::Machine,
    matched: &[usize],
    src: &Word,
    dst: &mut Word,
    env: &mut Env,
    opts: &StepOptions,
    any_flow: bool,
    bound: bool,
) -> Result<bool, StepError> {
    let before = dst.len();
    let mut successor = Successor {
        word: dst,
        room: opts.max_modules,
    };
    let result = if bound {
        body.run_bound(m, env, &mut successor)
    } else {
        body.run(m, |k| src.data(matched[k]), env, &mut successor)
    };
    // The word is full at the same module as on one thread.
    let full = successor.full();
    match result {
        Ok(flow) if flow == Flow::Produced || any_flow => Ok(true),
        Ok(_) => {
            dst.truncate(before);
            Ok(false)
        }
        Err(error) => {
            dst.truncate(before);
            Err(if full {
                StepError::TooLong {
                    limit: opts.max_modules,
                    rule: Some(r),
                }
            } else {
                StepError::Runtime { rule: r, error }
            })
        }
    }
}

/// Answers `InLeftContext` and friends for a body running on a word. Each
/// successful test moves its cursor past the modules it matched.
struct WordHost<'a> {
    src: &'a Word,
    dst: &'a Word,
    structs: &'a [StructDef],
    ctx: Rules<'a>,
    forward: bool,
    left: isize,
    right: usize,
    new_left: isize,
    new_right: usize,
}

impl Host for WordHost<'_> {
    fn in_context(&mut self, kind: ContextKind, pats: &[Pattern], out: &mut Vec<Value>) -> bool {
        let mut idx = Vec::new();
        let new_ctx = Rules {
            ring: false,
            tables: None,
            ..self.ctx
        };
        match kind {
            ContextKind::Left => match match_left(self.src, self.left, pats, self.ctx, &mut idx) {
                Some(p) => {
                    self.left = p;
                    push_params(self.src, &idx, pats, self.structs, out);
                    true
                }
                None => false,
            },
            ContextKind::Right => match match_right(self.src, self.right, pats, self.ctx, &mut idx)
            {
                Some(p) => {
                    self.right = p;
                    push_params(self.src, &idx, pats, self.structs, out);
                    true
                }
                None => false,
            },
            ContextKind::NewLeft if self.forward => {
                match match_left(self.dst, self.new_left, pats, new_ctx, &mut idx) {
                    Some(p) => {
                        self.new_left = p;
                        push_params(self.dst, &idx, pats, self.structs, out);
                        true
                    }
                    None => false,
                }
            }
            ContextKind::NewRight if !self.forward => {
                let rev = Reversed(self.dst);
                match match_right(&rev, self.new_right, pats, new_ctx, &mut idx) {
                    Some(p) => {
                        self.new_right = p;
                        push_params(&rev, &idx, pats, self.structs, out);
                        true
                    }
                    None => false,
                }
            }
            _ => false,
        }
    }
}

/// Decodes the parameters of the matched modules `idx` (one per pattern).
fn push_params<S: Seq>(
    seq: &S,
    idx: &[usize],
    pats: &[Pattern],
    structs: &[StructDef],
    out: &mut Vec<Value>,
) {
    for (&i, p) in idx.iter().zip(pats) {
        out.extend(decode_all(&p.types, seq.data(i), structs));
    }
}
