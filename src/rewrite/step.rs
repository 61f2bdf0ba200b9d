//! One parallel rewriting step over a word: `step(rules, &src, &mut dst)`.
//!
//! Every module of `src` is rewritten from `src` (contexts included); the
//! first rule, in file order, that matches and produces wins; a module no
//! rule rewrites is copied. Strict predecessors of several modules
//! (pseudo-L-systems) partition the word without overlap, starting at the
//! phase. `src` is never mutated.

use glam::{DVec2, DVec3};

use crate::lang::eval::{Emit, Env, Flow, Host, Interp, RuntimeError};
use crate::lang::ir::{Pattern, Program, Rule};
use crate::lang::stencil::Stencil;
use crate::lang::{Sym, Ty, Value};
use crate::syntax::ast::ContextKind;

use super::context::{match_left, match_right, module_matches, Rules};
use super::word::{Reversed, Seq, Word};

/// How one step runs.
#[derive(Clone, Copy, Debug)]
pub struct StepOptions {
    pub ring: bool,
    /// Left to right (`Forward()`, the default) or right to left.
    pub forward: bool,
    /// Where the partition into strict predecessors starts (pseudo-L-systems).
    pub phase: usize,
    /// The step fails once the new word holds more modules than this.
    pub max_modules: usize,
}

/// Why a step failed.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// A rule's body failed; `rule` indexes `Program::rules`.
    Runtime { rule: usize, error: RuntimeError },
    /// The new word outgrew `max_modules`.
    TooLong { limit: usize },
}

/// Rewrites words with a program's rules. Holds buffers reused across steps.
pub struct Rewriter<'p> {
    program: &'p Program,
    interp: Interp<'p>,
    sb: Sym,
    eb: Sym,
    frame: Vec<Value>,
    matched: Vec<usize>,
    new_matched: Vec<usize>,
    tmp: Word,
}

impl<'p> Rewriter<'p> {
    pub fn new(program: &'p Program) -> Rewriter<'p> {
        Rewriter {
            program,
            interp: Interp::new(&program.structs),
            sb: program.alphabet.builtin("SB"),
            eb: program.alphabet.builtin("EB"),
            frame: Vec::new(),
            matched: Vec::new(),
            new_matched: Vec::new(),
            tmp: Word::new(),
        }
    }

    /// One step with the rules `rules` (indices into `Program::rules`, in the
    /// order they are tried). `eligible`, when given, says which modules of
    /// `src` may be rewritten at all; `origin`, when given, receives for each
    /// module of `dst` whether a rule produced it. Returns how many modules
    /// of `src` a rule rewrote.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        rules: &[usize],
        src: &Word,
        dst: &mut Word,
        env: &mut Env,
        opts: &StepOptions,
        eligible: Option<&[bool]>,
        mut origin: Option<&mut Vec<bool>>,
    ) -> Result<usize, StepError> {
        dst.clear();
        if let Some(o) = origin.as_deref_mut() {
            o.clear();
        }
        let n = src.len();
        if n == 0 {
            return Ok(0);
        }
        let phase = opts.phase % n;
        let mut rewritten = 0;
        let mut k = 0;
        while k < n {
            // The scan position; backward steps walk from the right end.
            let i = match (opts.ring, opts.forward) {
                (true, true) => (phase + k) % n,
                (false, true) => k,
                (true, false) => (phase + n - 1 - k) % n,
                (false, false) => n - 1 - k,
            };
            let remaining = n - k;
            let mut used = 0;
            if eligible.is_none_or(|e| e[i]) {
                for &r in rules {
                    let rule = &self.program.rules[r];
                    let len = rule.strict.len();
                    if len > remaining {
                        continue;
                    }
                    // The leftmost module of the strict predecessor.
                    let start = if opts.forward {
                        if !opts.ring && len > 1 && i < phase {
                            continue;
                        }
                        i
                    } else if opts.ring {
                        (i + n - (len - 1)) % n
                    } else if i + 1 < len {
                        continue;
                    } else {
                        i + 1 - len
                    };
                    if self
                        .try_rule(r, rule, src, start, dst, env, opts)
                        .map_err(|error| StepError::Runtime { rule: r, error })?
                    {
                        used = len;
                        break;
                    }
                }
            }
            let produced = used > 0;
            if produced {
                rewritten += used;
            } else {
                used = 1;
                dst.push_from(src, i);
            }
            if let Some(o) = origin.as_deref_mut() {
                o.resize(dst.len(), produced);
            }
            if dst.len() > opts.max_modules {
                return Err(StepError::TooLong {
                    limit: opts.max_modules,
                });
            }
            k += used;
        }
        if !opts.forward {
            dst.reverse();
            if let Some(o) = origin {
                o.reverse();
            }
        }
        Ok(rewritten)
    }

    /// Tries one rule with its strict predecessor starting at `start`.
    /// On success the successor is appended to `dst` (reversed when the step
    /// runs backward) and `true` is returned.
    #[allow(clippy::too_many_arguments)]
    fn try_rule(
        &mut self,
        r: usize,
        rule: &Rule,
        src: &Word,
        start: usize,
        dst: &mut Word,
        env: &mut Env,
        opts: &StepOptions,
    ) -> Result<bool, RuntimeError> {
        let n = src.len();
        let len = rule.strict.len();
        let ctx = Rules {
            sb: self.sb,
            eb: self.eb,
            filter: &rule.filter,
            ring: opts.ring,
        };
        // Cheap test first: the strict predecessor matches exactly.
        for (j, p) in rule.strict.iter().enumerate() {
            let idx = if opts.ring {
                (start + j) % n
            } else {
                start + j
            };
            if idx >= n || !module_matches(src, idx, p) {
                return Ok(false);
            }
        }
        if (!rule.new_left.is_empty() && !opts.forward)
            || (!rule.new_right.is_empty() && opts.forward)
        {
            return Ok(false);
        }
        self.matched.clear();
        let Some(left_end) =
            match_left(src, start as isize - 1, &rule.left, ctx, &mut self.matched)
        else {
            return Ok(false);
        };
        for j in 0..len {
            self.matched.push(if opts.ring {
                (start + j) % n
            } else {
                start + j
            });
        }
        let Some(right_end) = match_right(src, start + len, &rule.right, ctx, &mut self.matched)
        else {
            return Ok(false);
        };
        // New contexts match the part of the new word built so far.
        self.new_matched.clear();
        let new_ctx = Rules { ring: false, ..ctx };
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
            let ok = apply_stencil(st, src, &self.matched, dst);
            if !ok {
                dst.truncate(before);
                return Err(RuntimeError::new(
                    None,
                    "a parameter of the successor is NaN or infinite",
                ));
            }
            if !opts.forward {
                reverse_tail(dst, before, &mut self.tmp);
            }
            return Ok(true);
        }

        // Bind the parameters: slots are allocated in pattern order
        // new-left, left, strict, right, new-right.
        self.frame.clear();
        self.frame.resize(rule.frame_size, Value::Void);
        let left_count = rule.left.len();
        let bind = |frame: &mut Vec<Value>, p: &Pattern, params: &[Value]| {
            for (slot, v) in p.slots.iter().zip(params) {
                frame[*slot as usize] = v.clone();
            }
        };
        for (p, &idx) in rule
            .new_left
            .iter()
            .zip(&self.new_matched[..new_left_count])
        {
            bind(&mut self.frame, p, dst.params(idx));
        }
        let old_pats = rule.left.iter().chain(&rule.strict).chain(&rule.right);
        for (p, &idx) in old_pats.zip(&self.matched) {
            bind(&mut self.frame, p, src.params(idx));
        }
        let rev = Reversed(dst);
        for (p, &idx) in rule
            .new_right
            .iter()
            .zip(&self.new_matched[new_left_count..])
        {
            bind(&mut self.frame, p, rev.params(idx));
        }
        let _ = left_count;

        self.tmp.clear();
        let mut host = WordHost {
            src,
            dst,
            ctx,
            forward: opts.forward,
            left: left_end,
            right: right_end,
            new_left: new_left_end,
            new_right: new_right_end,
        };
        let flow = self
            .interp
            .run(&rule.body, &mut self.frame, env, &mut host, &mut self.tmp)?;
        let _ = r;
        if flow != Flow::Produced {
            return Ok(false);
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
        Ok(true)
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

/// Evaluates a stencil into `dst`. Returns false if a value is not finite.
fn apply_stencil(st: &Stencil, src: &Word, matched: &[usize], dst: &mut Word) -> bool {
    let mut finite = true;
    for (sym, combos) in &st.outputs {
        dst.push_with(*sym, |params| {
            for c in combos {
                let source = |t: u16| {
                    let (k, j) = st.sources[t as usize];
                    &src.params(matched[k as usize])[j as usize]
                };
                let v = match c.ty {
                    Ty::V2 => {
                        let mut acc = DVec2::ZERO;
                        for &(t, w) in &c.terms {
                            if let Value::V2(p) = source(t) {
                                acc += w * *p;
                            }
                        }
                        finite &= acc.is_finite();
                        Value::V2(acc)
                    }
                    Ty::V3 => {
                        let mut acc = DVec3::ZERO;
                        for &(t, w) in &c.terms {
                            if let Value::V3(p) = source(t) {
                                acc += w * *p;
                            }
                        }
                        finite &= acc.is_finite();
                        Value::V3(acc)
                    }
                    _ => {
                        let mut acc = c.constant;
                        for &(t, w) in &c.terms {
                            acc += w * source(t).as_f64();
                        }
                        finite &= acc.is_finite();
                        Value::Float(acc)
                    }
                };
                params.push(v);
            }
        });
    }
    finite
}

/// Answers `InLeftContext` and friends for a body running on a word. Each
/// successful test moves its cursor past the modules it matched.
struct WordHost<'a> {
    src: &'a Word,
    dst: &'a Word,
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
            ..self.ctx
        };
        match kind {
            ContextKind::Left => match match_left(self.src, self.left, pats, self.ctx, &mut idx) {
                Some(p) => {
                    self.left = p;
                    push_params(self.src, &idx, out);
                    true
                }
                None => false,
            },
            ContextKind::Right => match match_right(self.src, self.right, pats, self.ctx, &mut idx)
            {
                Some(p) => {
                    self.right = p;
                    push_params(self.src, &idx, out);
                    true
                }
                None => false,
            },
            ContextKind::NewLeft if self.forward => {
                match match_left(self.dst, self.new_left, pats, new_ctx, &mut idx) {
                    Some(p) => {
                        self.new_left = p;
                        push_params(self.dst, &idx, out);
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
                        push_params(&rev, &idx, out);
                        true
                    }
                    None => false,
                }
            }
            _ => false,
        }
    }
}

fn push_params<S: Seq>(seq: &S, idx: &[usize], out: &mut Vec<Value>) {
    for &i in idx {
        out.extend_from_slice(seq.params(i));
    }
}

impl Emit for &mut Word {
    fn emit(&mut self, sym: Sym, args: &[Value]) {
        self.push(sym, args);
    }
}
