//! One parallel rewriting step over a word: `step(rules, &src, &mut dst)`.
//!
//! Every module of `src` is rewritten from `src` (contexts included); the
//! first rule, in file order, that matches and produces wins; a module no
//! rule rewrites is copied. Strict predecessors of several modules
//! (pseudo-L-systems) partition the word without overlap, starting at the
//! phase. `src` is never mutated.

use std::ops::Range;

use crate::deadline::Deadline;
use crate::lang::closure;
use crate::lang::eval::{Emit, Env, Flow, Host, Interp, RuntimeError};
use crate::lang::ir::{Pattern, Program, Rule};
use crate::lang::stencil::Stencil;
use crate::lang::value::{decode, decode_all, StructDef};
use crate::lang::{Sym, Ty, Value};
use crate::syntax::ast::ContextKind;

use super::context::{match_left, match_right, module_matches, Rules, Tables};
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
    /// The step fails once this passes.
    pub deadline: Option<Deadline>,
    /// Remove every `Cut` and the rest of its branch, as lpfg's forward
    /// production steps do (manual 5.4): a `Cut` and the modules after it
    /// up to the `EB` that closes its branch (kept), or to the end of the
    /// word, are neither rewritten nor copied. Contexts still see the
    /// whole old word. Decomposition, interpretation and backward steps
    /// leave `Cut` in place.
    pub cut: bool,
}

/// Why a step failed.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// A rule's body failed; `rule` indexes `Program::rules`.
    Runtime { rule: usize, error: RuntimeError },
    /// The new word outgrew `max_modules`; `rule` is the rule that
    /// produced last, if one did.
    TooLong { limit: usize, rule: Option<usize> },
    /// The deadline passed: what it says.
    Timeout(String),
}

impl std::fmt::Display for StepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StepError::Runtime { error, .. } => f.write_str(&error.message),
            StepError::TooLong { limit, .. } => write!(f, "the word grew past {limit} modules"),
            StepError::Timeout(m) => f.write_str(m),
        }
    }
}

/// In an origin, a module copied from the old word (the low bits give its
/// index there), rather than produced by a rule.
pub const COPIED: u32 = 1 << 31;

/// Source modules between two looks at the deadline on the general path.
const DEADLINE_EVERY: usize = 4096;

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

impl std::error::Error for StepError {}

/// Rewrites words with a program's rules. Holds buffers reused across steps.
pub struct Rewriter<'p> {
    program: &'p Program,
    interp: Interp<'p>,
    /// Per rule, its body compiled to closures, where it can be.
    bodies: Vec<Option<closure::Body>>,
    machine: closure::Machine,
    sb: Sym,
    eb: Sym,
    cut: Sym,
    frame: Vec<Value>,
    /// The last step's growth (new length / old length), to size buffers.
    growth: f64,
    /// The fast path found every new slot finite while computing it.
    checked_finite: bool,
    matched: Vec<usize>,
    new_matched: Vec<usize>,
    tmp: Word,
    /// The context tables of the word a step rewrites.
    tables: Tables,
    /// The new words of a parallel step's parts after the first, kept
    /// from step to step so that their memory is reused.
    parts: Vec<Word>,
    /// For each module of the old word, the rule (its place in the step's
    /// list) that rewrites it in a step of stencils in parts, or
    /// `KEEP`.
    choice: Vec<u16>,
    /// The rules of the last step run in parts or on the lean path, by
    /// the symbol of their strict predecessor.
    dispatch: Dispatch,
    /// Where a step written in parts says which of its new word's parts
    /// are written, for a reader on another thread (the turtle walking
    /// the last step's word): set for one step by
    /// [`super::Derivation::next_step_read`].
    pub(crate) reader: Option<std::sync::Arc<super::growth::Growth>>,
}

/// `Rewriter::choice` of a module that no rule rewrites.
const KEEP: u16 = u16::MAX;

impl<'p> Rewriter<'p> {
    pub fn new(program: &'p Program) -> Rewriter<'p> {
        Rewriter {
            program,
            interp: Interp::for_program(program, None),
            bodies: program
                .rules
                .iter()
                .map(|r| closure::compile(r, &program.globals))
                .collect(),
            machine: closure::Machine::default(),
            sb: program.alphabet.builtin("SB"),
            eb: program.alphabet.builtin("EB"),
            cut: program.alphabet.builtin("Cut"),
            frame: Vec::new(),
            growth: 1.0,
            checked_finite: false,
            matched: Vec::new(),
            new_matched: Vec::new(),
            tmp: Word::new(),
            tables: Tables::default(),
            parts: Vec::new(),
            choice: Vec::new(),
            dispatch: Dispatch::default(),
            reader: None,
        }
    }

    /// One step with the rules `rules` (indices into `Program::rules`, in the
    /// order they are tried). `eligible`, when given, says which modules of
    /// `src` may be rewritten at all; `origin`, when given, receives for each
    /// module of `dst` what made it: the index of the rule that produced it,
    /// or [`COPIED`] with the index of the module of `src` it copies.
    /// Returns how many modules of `src` a rule rewrote.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        rules: &[usize],
        src: &Word,
        dst: &mut Word,
        env: &mut Env,
        opts: &StepOptions,
        eligible: Option<&[bool]>,
        mut origin: Option<&mut Vec<u32>>,
    ) -> Result<usize, StepError> {
        dst.clear();
        if let Some(o) = origin.as_deref_mut() {
            o.clear();
        }
        let n = src.len();
        if n == 0 {
            return Ok(0);
        }
        crate::deadline::check(opts.deadline).map_err(StepError::Timeout)?;
        self.interp.deadline = opts.deadline;
        self.tables.clear();
        // Size the new word from the last step's growth, so that it is
        // allocated once instead of doubling its way up; with a quarter
        // more, since growth drifts from step to step (the quadratic Koch
        // island's rises towards 8), and a word one module past its room
        // would be copied into one twice its size. Room never written costs
        // address space, not memory.
        let g = (self.growth * 1.25).clamp(1.0, 64.0);
        let want = ((n as f64 * g) as usize).min(opts.max_modules.saturating_add(1));
        let want_slots =
            ((src.slot_count() as f64 * g) as usize).min(opts.max_modules.saturating_mul(4));
        dst.clear_with_capacity(want, want_slots);
        if eligible.is_none() && origin.is_none() && opts.forward && self.stencils_only(rules, src)
        {
            self.checked_finite = false;
            let rewritten = match self.uniform_rule(rules, src, opts) {
                Some((r, w)) => self.uniform_step(r, w, src, dst, opts)?,
                None => match self.stencil_parts(rules, src, dst, opts) {
                    Some(rewritten) => rewritten,
                    None => self.stencil_step(rules, src, dst, opts)?,
                },
            };
            if self.checked_finite || Self::all_finite(dst) {
                self.growth = dst.len() as f64 / n as f64;
                return Ok(rewritten);
            }
            // Redo the step on the general path, which names the production.
            dst.clear();
        }
        if eligible.is_none() && origin.is_none() {
            if let Some(rewritten) = self.parallel_step(rules, src, dst, env, opts) {
                self.growth = dst.len() as f64 / n as f64;
                return Ok(rewritten);
            }
            if self.lean(rules, src, opts) {
                let rewritten = self.lean_step(rules, src, dst, env, opts)?;
                self.growth = dst.len() as f64 / n as f64;
                return Ok(rewritten);
            }
        }
        let phase = opts.phase % n;
        let mut rewritten = 0;
        let mut k = 0;
        // Where, in the new word, the successors of modules scanned after
        // the scan wrapped from the end of a ring to its start begin.
        let mut wrapped_at = None;
        // The rule that produced last, to blame for a word grown too long.
        let mut last_rule = None;
        let mut scanned: usize = 0;
        // The scan position of the k-th module scanned; backward steps
        // walk from the right end.
        let at = |k: usize| match (opts.ring, opts.forward) {
            (true, true) => wrap(phase + k, n),
            (false, true) => k,
            (true, false) => wrap(phase + n - 1 - k, n),
            (false, false) => n - 1 - k,
        };
        let cut = opts.cut && opts.forward;
        while k < n {
            scanned += 1;
            if scanned.is_multiple_of(DEADLINE_EVERY) {
                crate::deadline::check(opts.deadline).map_err(StepError::Timeout)?;
            }
            let i = at(k);
            if opts.ring && opts.forward && i < phase && wrapped_at.is_none() {
                wrapped_at = Some(dst.len());
            }
            if cut && src.sym(i) == self.cut {
                k = self.end_of_branch(src, k, at);
                continue;
            }
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
                        wrap(i + n - (len - 1), n)
                    } else if i + 1 < len {
                        continue;
                    } else {
                        i + 1 - len
                    };
                    if self.try_rule(r, rule, src, start, dst, env, opts, false)? {
                        used = len;
                        last_rule = Some(r);
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
                let made = match last_rule {
                    Some(r) if produced => r as u32,
                    _ => COPIED | i as u32,
                };
                o.resize(dst.len(), made);
            }
            if dst.len() > opts.max_modules {
                return Err(StepError::TooLong {
                    limit: opts.max_modules,
                    rule: last_rule,
                });
            }
            k += used;
        }
        self.growth = dst.len() as f64 / n as f64;
        if let Some(m) = wrapped_at {
            // Keep the ring's start where it was: the successors of the
            // modules before the phase come first, as with phase 0. A
            // predecessor that wrapped stays at the end.
            dst.rotate_left(m);
            if let Some(o) = origin.as_deref_mut() {
                o.rotate_left(m);
            }
        }
        if !opts.forward {
            dst.reverse();
            if let Some(o) = origin {
                o.reverse();
            }
        }
        Ok(rewritten)
    }

    /// A forward step on rayon's pool, when each module's successor
    /// depends on the old word alone: every rule's strict predecessor is
    /// one module, it has no new context, and its body is a stencil or a
    /// compiled body that stores no global and draws no random number; the
    /// word has `PARALLEL_MODULES` modules or more, and no `Cut` to skip
    /// (a cut's branch may cross the parts). The word is cut into parts,
    /// rewritten at once and joined in order: the first part straight into
    /// `dst`, the others into words kept for the next step. The result is
    /// the same, to the bit, for any number of threads.
    ///
    /// Returns `None` when it does not apply, and also when a part failed:
    /// the step is then run again on one thread, which stops at the first
    /// failure in the word's order and names it as it always did.
    fn parallel_step(
        &mut self,
        rules: &[usize],
        src: &Word,
        dst: &mut Word,
        env: &mut Env,
        opts: &StepOptions,
    ) -> Option<usize> {
        use rayon::prelude::*;
        let n = src.len();
        let threads = rayon::current_num_threads();
        if n < PARALLEL_MODULES || threads == 1 || !opts.forward {
            return None;
        }
        // Stencils read no environment: their parts are written in place.
        if rules
            .iter()
            .all(|&r| self.program.rules[r].stencil.is_some())
        {
            return self.stencil_parts(rules, src, dst, opts);
        }
        let pure = rules.iter().all(|&r| {
            let rule = &self.program.rules[r];
            rule.strict.len() == 1
                && rule.new_left.is_empty()
                && rule.new_right.is_empty()
                && (rule.stencil.is_some() || self.bodies[r].as_ref().is_some_and(|b| b.pure()))
        });
        // Each part runs on its own copy of the environment: not worth it
        // when the globals hold large arrays.
        fn held(v: &Value) -> usize {
            match v {
                Value::Struct(fields) => fields.iter().map(held).sum::<usize>() + 1,
                _ => 1,
            }
        }
        let small = env.globals.iter().map(held).sum::<usize>() <= MAX_COPIED_GLOBALS;
        if !pure || !small || (opts.cut && src.syms().contains(&self.cut)) {
            return None;
        }
        // The first part, written in place, is a little smaller than an
        // even share; the rest is cut finer, so that a thread done early
        // takes some of it.
        let first = n / threads * 3 / 4;
        let rest = threads * 3;
        let bounds: Vec<usize> = std::iter::once(0)
            .chain((0..=rest).map(|k| first + (n - first) * k / rest))
            .collect();
        let g = (self.growth * 1.25).clamp(1.0, 64.0);
        let per_module = src.slot_count() as f64 / n as f64;
        self.parts.resize_with(rest, Word::new);
        for (w, b) in self.parts.iter_mut().zip(bounds[1..].windows(2)) {
            // As the new word's room is sized in `step`, within the limit.
            let want =
                (((b[1] - b[0]) as f64 * g) as usize).min(opts.max_modules.saturating_add(1));
            let slots =
                ((want as f64 * per_module) as usize).min(opts.max_modules.saturating_mul(4));
            w.clear_with_capacity(want, slots);
        }
        let loop_limit = self.interp.loop_limit;
        let reader = self.reader.clone();
        let (sh, machine, parts) = self.prepare_parts(rules, opts);
        let grown = std::sync::atomic::AtomicUsize::new(0);
        let shared_env = env.clone();
        let (head, tail) = rayon::join(
            || rewrite_part(&sh, src, 0..first, dst, env, opts, machine, &grown),
            || {
                parts
                    .par_iter_mut()
                    .zip(bounds[1..].par_windows(2))
                    .map(|(w, b)| {
                        let mut env = shared_env.clone();
                        let mut m = closure::Machine::default();
                        m.loop_limit = loop_limit;
                        m.deadline = opts.deadline;
                        rewrite_part(&sh, src, b[0]..b[1], w, &mut env, opts, &mut m, &grown)
                    })
                    .collect::<Vec<_>>()
            },
        );
        let total = dst.len() + parts.iter().map(Word::len).sum::<usize>();
        let rewritten = std::iter::once(head).chain(tail).sum::<Result<usize, _>>();
        let Some(rewritten) = rewritten.ok().filter(|_| total <= opts.max_modules) else {
            dst.clear();
            return None;
        };
        if !dst.append_all_read(parts, reader.as_deref()) {
            dst.clear();
            return None;
        }
        Some(rewritten)
    }

    /// Sets up what `rewrite_part` reads beside the word (the rules by
    /// symbol, the compiled bodies' loop limit and deadline) and lends it,
    /// with the machine of the first part and the words of the others.
    fn prepare_parts(
        &mut self,
        rules: &[usize],
        opts: &StepOptions,
    ) -> (Shared<'_>, &mut closure::Machine, &mut Vec<Word>) {
        self.dispatch.prepare(self.program, &self.bodies, rules);
        self.machine.loop_limit = self.interp.loop_limit;
        self.machine.deadline = opts.deadline;
        let sh = Shared {
            program: self.program,
            bodies: &self.bodies,
            tables: &self.tables,
            dispatch: &self.dispatch,
            sb: self.sb,
            eb: self.eb,
        };
        (sh, &mut self.machine, &mut self.parts)
    }

    /// A forward step of stencils in parts on rayon's pool, written
    /// straight into `dst`: every rule is a stencil with a one-module
    /// strict predecessor and no new context, so each module's successor
    /// depends on the old word alone and its size on the rule alone. A
    /// first pass matches every module and counts each part's modules and
    /// slots; the second writes each part into its place in the new word
    /// ([`Word::fill_parts`]), with no words on the side to join. The
    /// result is the same, to the bit, for any number of threads, and the
    /// new slots are checked finite.
    ///
    /// Returns `None` when it does not apply, and when a value is not
    /// finite, the word would pass its limit or the deadline passed: the
    /// step then runs on one thread, which names the module and the rule.
    fn stencil_parts(
        &mut self,
        rules: &[usize],
        src: &Word,
        dst: &mut Word,
        opts: &StepOptions,
    ) -> Option<usize> {
        use rayon::prelude::*;
        let n = src.len();
        let threads = rayon::current_num_threads();
        let program = self.program;
        let applies = n >= PARALLEL_MODULES
            && threads > 1
            && opts.forward
            && rules.len() < KEEP as usize
            && rules.iter().all(|&r| {
                let rule = &program.rules[r];
                rule.stencil.is_some()
                    && rule.strict.len() == 1
                    && rule.new_left.is_empty()
                    && rule.new_right.is_empty()
            })
            && !(opts.cut && src.syms().contains(&self.cut));
        if !applies {
            return None;
        }
        // Each rule's successor: its modules and slots.
        let sizes: Vec<(usize, usize)> = rules
            .iter()
            .map(|&r| {
                let st = program.rules[r].stencil.as_ref().expect("checked above");
                (st.outputs.len(), st.slot_count())
            })
            .collect();
        // Parts of `chunk` modules, a few per thread, so that a thread done
        // early takes another; more when a reader walks the word as they
        // are written, so that it starts sooner.
        let per_thread = if self.reader.is_some() { 16 } else { 4 };
        let chunk = n.div_ceil(threads * per_thread);
        let (sb, eb, tables) = (self.sb, self.eb, &self.tables);
        let ctx = |r: usize| Rules {
            sb,
            eb,
            filter: &program.rules[r].filter,
            ring: opts.ring,
            tables: Some(tables),
        };
        // The symbols some rule's predecessor starts with: a module of any
        // other symbol is kept without trying the rules.
        let mut wanted = Vec::new();
        for &r in rules {
            let s = program.rules[r].strict[0].sym.0 as usize;
            if s >= wanted.len() {
                wanted.resize(s + 1, false);
            }
            wanted[s] = true;
        }
        // The first pass: which rule rewrites each module, and each part's
        // size.
        self.choice.resize(n, KEEP);
        let counts: Option<Vec<(usize, usize, usize)>> = self
            .choice
            .par_chunks_mut(chunk)
            .enumerate()
            .map(|(k, choice)| {
                let from = k * chunk;
                let mut matched = Vec::new();
                let (mut modules, mut slots, mut rewritten) = (0, 0, 0);
                for (j, c) in choice.iter_mut().enumerate() {
                    let i = from + j;
                    if j.is_multiple_of(DEADLINE_EVERY) {
                        crate::deadline::check(opts.deadline).ok()?;
                    }
                    *c = KEEP;
                    if wanted.get(src.sym(i).0 as usize) == Some(&true) {
                        for (t, &r) in rules.iter().enumerate() {
                            let rule = &program.rules[r];
                            if match_old(rule, src, i, ctx(r), &mut matched).is_some() {
                                *c = t as u16;
                                break;
                            }
                        }
                    }
                    let (m, s) = match *c {
                        KEEP => (1, src.data(i).len()),
                        t => {
                            rewritten += 1;
                            sizes[t as usize]
                        }
                    };
                    modules += m;
                    slots += s;
                }
                Some((modules, slots, rewritten))
            })
            .collect();
        let counts = counts?;
        let total: usize = counts.iter().map(|c| c.0).sum();
        if total > opts.max_modules {
            return None;
        }
        let sizes_of: Vec<(usize, usize)> = counts.iter().map(|c| (c.0, c.1)).collect();
        let choice = &self.choice;
        dst.clear();
        let written = dst.fill_parts(&sizes_of, self.reader.as_deref(), |k, out| {
            let mut matched = Vec::new();
            let mut scratch = Word::new();
            let from = k * chunk;
            let part = &choice[from..(from + chunk).min(n)];
            let mut j = 0;
            let mut checked = 0;
            while j < part.len() {
                if j >= checked {
                    if crate::deadline::check(opts.deadline).is_err() {
                        return false;
                    }
                    checked = j + DEADLINE_EVERY;
                }
                let i = from + j;
                let ok = match part[j] {
                    KEEP => {
                        // The modules no rule rewrites, copied as a run.
                        let run = part[j..].iter().take_while(|&&c| c == KEEP).count();
                        j += run;
                        out.push_range(src, i..i + run)
                    }
                    t => {
                        let r = rules[t as usize];
                        let rule = &program.rules[r];
                        let st = rule.stencil.as_ref().expect("checked above");
                        scratch.clear();
                        j += 1;
                        match_old(rule, src, i, ctx(r), &mut matched).is_some()
                            && apply_stencil(st, src, &matched, &mut scratch)
                            && out.push_word(&scratch)
                    }
                };
                if !ok {
                    return false;
                }
            }
            true
        });
        if !written {
            dst.clear();
            return None;
        }
        self.checked_finite = true;
        Some(counts.iter().map(|c| c.2).sum())
    }

    /// True when a step can run on the lean path ([`Rewriter::lean_step`]):
    /// forward, every rule's strict predecessor one module without new
    /// contexts, every body a stencil or compiled, no `Cut` to skip, and a
    /// ring scanned from its first module. Such a step scans the word in
    /// order, as the general loop does, so bodies with effects (globals,
    /// random numbers) see the modules in the same order.
    fn lean(&self, rules: &[usize], src: &Word, opts: &StepOptions) -> bool {
        opts.forward
            && (!opts.ring || opts.phase.is_multiple_of(src.len()))
            && rules.iter().all(|&r| {
                let rule = &self.program.rules[r];
                rule.strict.len() == 1
                    && rule.new_left.is_empty()
                    && rule.new_right.is_empty()
                    && (rule.stencil.is_some() || self.bodies[r].is_some())
            })
            && !(opts.cut && src.syms().contains(&self.cut))
    }

    /// A step that [`Rewriter::lean`] admits, on this thread: the loop of
    /// a parallel step's parts ([`rewrite_part`]) over the whole word,
    /// which tries only the rules of each module's symbol, matches a
    /// predecessor that consecutive rules share once, and copies runs of
    /// modules no rule rewrites at once. What it writes and the errors it
    /// gives are the general loop's: the modules are tried in the same
    /// order with the same rules, and a word past its limit blames the
    /// rule that produced last.
    fn lean_step(
        &mut self,
        rules: &[usize],
        src: &Word,
        dst: &mut Word,
        env: &mut Env,
        opts: &StepOptions,
    ) -> Result<usize, StepError> {
        let (sh, machine, _) = self.prepare_parts(rules, opts);
        let grown = std::sync::atomic::AtomicUsize::new(0);
        rewrite_part(&sh, src, 0..src.len(), dst, env, opts, machine, &grown)
    }

    /// Frees the words kept from step to step.
    pub fn release(&mut self) {
        self.parts = Vec::new();
        self.choice = Vec::new();
        self.tmp = Word::new();
        self.tables.clear();
    }

    /// Where the scan goes on after a `Cut` scanned `k`-th: the matching
    /// `EB` of its branch, or the end of the word when there is none. On a
    /// ring scanned from a phase, the end of the word is where the scan
    /// wraps to its first module (lpfg has no phase: the cut never goes
    /// round), and the scan goes on there.
    fn end_of_branch(&self, src: &Word, mut k: usize, at: impl Fn(usize) -> usize) -> usize {
        let mut depth = 0usize;
        k += 1;
        while k < src.len() {
            let j = at(k);
            if j == 0 {
                break;
            }
            let s = src.sym(j);
            if s == self.sb {
                depth += 1;
            } else if s == self.eb {
                if depth == 0 {
                    break;
                }
                depth -= 1;
            }
            k += 1;
        }
        k
    }

    /// True when the step can take the compiled fast path: every rule is a
    /// stencil with a one-module strict predecessor, plain contexts (no
    /// filter; an overloaded module's pattern matches by its width, as on
    /// the general path) and the word has no branches and no `Cut`.
    fn stencils_only(&self, rules: &[usize], src: &Word) -> bool {
        let simple = |p: &Pattern| p.sym != self.sb && p.sym != self.eb;
        let rules_ok = rules.iter().all(|&r| {
            let rule = &self.program.rules[r];
            rule.stencil.is_some()
                && rule.strict.len() == 1
                && rule.filter == crate::lang::ir::Filter::All
                && rule
                    .left
                    .iter()
                    .chain(&rule.strict)
                    .chain(&rule.right)
                    .all(simple)
        });
        // No early exit, so that the scan vectorises.
        rules_ok
            && src.syms().chunks(64).all(|c| {
                c.iter().fold(true, |ok, &s| {
                    ok & (s != self.sb) & (s != self.eb) & (s != self.cut)
                })
            })
    }

    /// On a ring whose modules are all of one kind and one width, the first
    /// rule whose predecessor is made of that kind rewrites every module.
    /// Returns that rule and the width, when its body is a stencil.
    fn uniform_rule(
        &self,
        rules: &[usize],
        src: &Word,
        opts: &StepOptions,
    ) -> Option<(usize, usize)> {
        let n = src.len();
        if !opts.ring || n == 0 || n > opts.max_modules {
            return None;
        }
        let s = src.sym(0);
        let same = |c: &[Sym]| c.iter().fold(true, |ok, &t| ok & (t == s));
        if !src.syms().chunks(64).all(same) || !src.slot_count().is_multiple_of(n) {
            return None;
        }
        let w = src.slot_count() / n;
        if src.data(0).len() != w {
            return None;
        }
        for &r in rules {
            let rule = &self.program.rules[r];
            let all_s = rule
                .left
                .iter()
                .chain(&rule.strict)
                .chain(&rule.right)
                .all(|p| p.sym == s && p.width.is_none_or(|pw| pw == w));
            if rule.strict.len() == 1 && all_s && rule.left.len() <= n && rule.right.len() <= n {
                return rule.stencil.is_some().then_some((r, w));
            }
        }
        None
    }

    /// The fast path for `uniform_rule`: the same stencil at every module,
    /// neighbours found by index arithmetic, slots addressed directly.
    fn uniform_step(
        &mut self,
        r: usize,
        w: usize,
        src: &Word,
        dst: &mut Word,
        opts: &StepOptions,
    ) -> Result<usize, StepError> {
        let rule = &self.program.rules[r];
        let st = rule.stencil.as_ref().expect("checked by uniform_rule");
        let n = src.len();
        let (nl, nr) = (rule.left.len(), rule.right.len());
        let total = nl + 1 + nr;
        let out_per_module: usize = st.outputs.len();
        if n.saturating_mul(out_per_module) > opts.max_modules {
            return Err(StepError::TooLong {
                limit: opts.max_modules,
                rule: Some(r),
            });
        }
        let data = src.all_slots();
        // The new word's exact size is known: allocate it once.
        let slots_per_module = st.slot_count();
        dst.clear_with_capacity(n * out_per_module, n * slots_per_module);
        let (syms, starts, out) = dst.raw_parts_mut();
        // The common case: every term a weighted parameter.
        let plain: Option<Vec<(Sym, Vec<crate::lang::stencil::PlainCombination>)>> = st
            .outputs
            .iter()
            .map(|(sym, combos)| {
                Some((
                    *sym,
                    combos
                        .iter()
                        .map(|c| c.plain())
                        .collect::<Option<Vec<_>>>()?,
                ))
            })
            .collect();
        let mut base = vec![0usize; total];
        if let Some(plain) = plain {
            let mut guard = 0.0;
            // Away from the ring's seam every parameter a term reads sits at
            // a fixed distance from the module's own slots.
            let fixed: Vec<FixedOutput> = plain
                .iter()
                .map(|(sym, combos)| {
                    let cs = combos
                        .iter()
                        .map(|c| {
                            let ts = c
                                .terms
                                .iter()
                                .map(|&(k, off, wt)| {
                                    ((k as isize - nl as isize) * w as isize + off as isize, wt)
                                })
                                .collect();
                            (c.ty, ts)
                        })
                        .collect();
                    (*sym, cs)
                })
                .collect();
            // Symbols and offsets follow a fixed pattern per module: write
            // them in bulk, and only the parameters in the loops below.
            let widths: Vec<usize> = plain
                .iter()
                .map(|(_, cs)| cs.iter().map(|c| c.slots()).sum())
                .collect();
            let pattern: Vec<Sym> = plain.iter().map(|(s, _)| *s).collect();
            // On a long word they are written on rayon's pool, which also
            // shares the first touch of the new pages between the threads.
            use rayon::prelude::*;
            let parallel = n >= PARALLEL_MODULES && rayon::current_num_threads() > 1;
            let mut end = out.len() as u32;
            if pattern.iter().all(|&p| p == pattern[0]) {
                if parallel {
                    syms.par_extend(rayon::iter::repeat_n(pattern[0], n * pattern.len()));
                } else {
                    syms.resize(syms.len() + n * pattern.len(), pattern[0]);
                }
            } else {
                (0..n).for_each(|_| syms.extend_from_slice(&pattern));
            }
            if widths.iter().all(|&wd| wd == widths[0]) {
                // Equal widths: the offsets are an arithmetic sequence.
                let wd = widths[0] as u32;
                let count = (n * widths.len()) as u32;
                if parallel {
                    starts.par_extend((1..=count).into_par_iter().map(|k| end + k * wd));
                } else {
                    starts.extend((1..=count).map(|k| end + k * wd));
                }
                end += count * wd;
            } else {
                for _ in 0..n {
                    for wd in &widths {
                        end += *wd as u32;
                        starts.push(end);
                    }
                }
            }
            let seam_module =
                |i: usize, base: &mut Vec<usize>, out: &mut Vec<f64>, guard: &mut f64| {
                    for (t, b) in base.iter_mut().enumerate() {
                        let j = ring_index(i, t, nl, n);
                        *b = j * w;
                    }
                    for (_, combos) in &plain {
                        for c in combos {
                            let t = &c.terms;
                            match (c.ty.dim(), c.ty.is_single()) {
                                (2, true) => plain_eval::<2, true>(t, data, base, out, guard),
                                (3, true) => plain_eval::<3, true>(t, data, base, out, guard),
                                (_, true) => plain_eval::<1, true>(t, data, base, out, guard),
                                (2, _) => plain_eval::<2, false>(t, data, base, out, guard),
                                (3, _) => plain_eval::<3, false>(t, data, base, out, guard),
                                _ => plain_eval::<1, false>(t, data, base, out, guard),
                            }
                        }
                    }
                };
            let first_inner = nl.min(n);
            let last_inner = n.saturating_sub(nr).max(first_inner);
            for i in 0..first_inner {
                seam_module(i, &mut base, out, &mut guard);
            }
            // `v * 0` is 0 for a finite v and NaN otherwise: a NaN guard
            // without a branch per value.
            let mut g = 0.0;
            let inner = first_inner..last_inner;
            // One shape for every parameter (Chaikin, and every curve scheme
            // of paper 002): a loop compiled for it.
            let kernel = match uniform_shape(&fixed) {
                Some((2, 2, true)) => fixed_kernel::<2, 2, true>,
                Some((2, 3, true)) => fixed_kernel::<2, 3, true>,
                Some((2, 4, true)) => fixed_kernel::<2, 4, true>,
                Some((3, 2, true)) => fixed_kernel::<3, 2, true>,
                Some((3, 3, true)) => fixed_kernel::<3, 3, true>,
                Some((3, 4, true)) => fixed_kernel::<3, 4, true>,
                Some((2, 2, false)) => fixed_kernel::<2, 2, false>,
                Some((2, 3, false)) => fixed_kernel::<2, 3, false>,
                Some((2, 4, false)) => fixed_kernel::<2, 4, false>,
                Some((3, 2, false)) => fixed_kernel::<3, 2, false>,
                Some((3, 3, false)) => fixed_kernel::<3, 3, false>,
                Some((3, 4, false)) => fixed_kernel::<3, 4, false>,
                _ => {
                    |_: &[FixedOutput], _: &[f64], _: usize, _: Range<usize>, _: &mut Vec<f64>| None
                }
            };
            let inner = match kernel(&fixed, data, w, inner.clone(), out) {
                Some(true) => 0..0,
                Some(false) => {
                    g = f64::NAN;
                    0..0
                }
                None => inner,
            };
            for i in inner {
                let at = (i * w) as isize;
                for (_, combos) in &fixed {
                    for (ty, terms) in combos {
                        match (ty.dim(), ty.is_single()) {
                            (2, single) => {
                                let a = if single {
                                    fixed_eval::<2, true>(terms, data, at)
                                } else {
                                    fixed_eval::<2, false>(terms, data, at)
                                };
                                g += a[0] * 0.0 + a[1] * 0.0;
                                out.extend_from_slice(&a);
                            }
                            (3, single) => {
                                let a = if single {
                                    fixed_eval::<3, true>(terms, data, at)
                                } else {
                                    fixed_eval::<3, false>(terms, data, at)
                                };
                                g += a[0] * 0.0 + a[1] * 0.0 + a[2] * 0.0;
                                out.extend_from_slice(&a);
                            }
                            (_, single) => {
                                let a = if single {
                                    fixed_eval::<1, true>(terms, data, at)
                                } else {
                                    fixed_eval::<1, false>(terms, data, at)
                                };
                                g += a[0] * 0.0;
                                out.push(a[0]);
                            }
                        }
                    }
                }
            }
            guard += g;
            for i in last_inner..n {
                seam_module(i, &mut base, out, &mut guard);
            }
            debug_assert_eq!(out.len() as u32, end);
            self.checked_finite = guard == 0.0;
            return Ok(n);
        }
        let mut slices: Vec<&[f64]> = vec![&[]; total];
        for i in 0..n {
            for (t, s) in slices.iter_mut().enumerate() {
                let j = ring_index(i, t, nl, n);
                *s = &data[j * w..j * w + w];
            }
            for (sym, combos) in &st.outputs {
                syms.push(*sym);
                for c in combos {
                    combine_into(c, &slices, out);
                }
                starts.push(out.len() as u32);
            }
        }
        Ok(n)
    }

    /// The fast path: contexts are plain neighbours, bodies are stencils.
    /// Same result as the general path under the conditions of
    /// `stencils_only`.
    fn stencil_step(
        &mut self,
        rules: &[usize],
        src: &Word,
        dst: &mut Word,
        opts: &StepOptions,
    ) -> Result<usize, StepError> {
        let program = self.program;
        let n = src.len();
        // Contexts reach at most n modules either way (as in the general
        // path), so one addition or subtraction wraps a position.
        let at = |pos: isize| -> Option<usize> {
            if opts.ring {
                let n = n as isize;
                Some(if pos < 0 {
                    pos + n
                } else if pos >= n {
                    pos - n
                } else {
                    pos
                } as usize)
            } else if pos >= 0 && (pos as usize) < n {
                Some(pos as usize)
            } else {
                None
            }
        };
        let mut matched = [0usize; 16];
        let mut rewritten = 0;
        let mut last_rule = None;
        for i in 0..n {
            let mut done = false;
            'rules: for &r in rules {
                let rule = &program.rules[r];
                if !module_matches(src, i, &rule.strict[0]) {
                    continue;
                }
                let nl = rule.left.len();
                let total = nl + 1 + rule.right.len();
                if total > matched.len() {
                    continue;
                }
                if opts.ring && (nl > n || rule.right.len() > n) {
                    continue; // the general path cannot match it either
                }
                for (t, p) in rule.left.iter().enumerate() {
                    match at(i as isize - (nl - t) as isize) {
                        Some(j) if module_matches(src, j, p) => matched[t] = j,
                        _ => continue 'rules,
                    }
                }
                matched[nl] = i;
                for (t, p) in rule.right.iter().enumerate() {
                    match at(i as isize + 1 + t as isize) {
                        Some(j) if module_matches(src, j, p) => matched[nl + 1 + t] = j,
                        _ => continue 'rules,
                    }
                }
                let st = rule.stencil.as_ref().expect("checked by stencils_only");
                apply_stencil(st, src, &matched[..total], dst);
                rewritten += 1;
                done = true;
                last_rule = Some(r);
                break;
            }
            settle(done, src, i, dst, opts, last_rule)?;
        }
        Ok(rewritten)
    }

    /// The fast path checks for NaN and infinity once, over the whole new
    /// word; the caller reruns the general path to say where it came from.
    fn all_finite(dst: &Word) -> bool {
        // No early exit, so that the loop vectorises.
        dst.all_slots()
            .chunks(64)
            .all(|c| c.iter().fold(true, |ok, x| ok & x.is_finite()))
    }

    /// Prepares a step on a word that [`Rewriter::step`] did not start (a
    /// Gillespie step, which calls [`Rewriter::try_rule`] itself): the
    /// deadline, and no tables of the last step's word.
    pub(super) fn begin(&mut self, opts: &StepOptions) {
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
    pub(super) fn try_rule(
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

/// The ring position of context slot `t` of module `i`, whose left
/// context has `nl` modules: `i - nl + t` wrapped once either way.
#[inline(always)]
fn ring_index(i: usize, t: usize, nl: usize, n: usize) -> usize {
    let j = i + n + t - nl;
    if j >= 2 * n {
        j - 2 * n
    } else if j >= n {
        j - n
    } else {
        j
    }
}

/// `pos % n` for `pos < 2n`, without a division.
#[inline]
fn wrap(pos: usize, n: usize) -> usize {
    if pos >= n {
        pos - n
    } else {
        pos
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

/// A stencil output away from the ring's seam: its symbol and, per
/// parameter, the type and the terms `(slot distance, weight)`.
type FixedOutput = (Sym, Vec<(Ty, Vec<(isize, f64)>)>);

/// One plain stencil output of `N` components: `Σ w·x` left to right.
#[inline(always)]
fn plain_eval<const N: usize, const SINGLE: bool>(
    terms: &[(u16, u16, f64)],
    data: &[f64],
    base: &[usize],
    out: &mut Vec<f64>,
    guard: &mut f64,
) {
    let mut acc = [0.0; N];
    for (n, &(k, off, w)) in terms.iter().enumerate() {
        let at = base[k as usize] + off as usize;
        let x = &data[at..at + N];
        for i in 0..N {
            let v = rounded::<SINGLE>(w * x[i]);
            acc[i] = if n == 0 {
                v
            } else {
                rounded::<SINGLE>(acc[i] + v)
            };
        }
    }
    for v in acc {
        *guard += v * 0.0;
    }
    out.extend_from_slice(&acc);
}

/// `plain_eval` for a module away from the seam: term `t` reads the slots
/// at `at + delta_t`.
#[inline(always)]
fn fixed_eval<const N: usize, const SINGLE: bool>(
    terms: &[(isize, f64)],
    data: &[f64],
    at: isize,
) -> [f64; N] {
    let r = rounded::<SINGLE>;
    #[inline(always)]
    fn load<const N: usize>(data: &[f64], at: isize, delta: isize) -> &[f64; N] {
        let p = (at + delta) as usize;
        data[p..p + N].try_into().expect("N slots")
    }
    // Two- and three-term sums (every curve scheme of paper 002 but the
    // four-point one) unrolled; the same operations in the same order.
    match *terms {
        [(d0, w0), (d1, w1)] => {
            let (x0, x1) = (load::<N>(data, at, d0), load::<N>(data, at, d1));
            std::array::from_fn(|i| r(r(w0 * x0[i]) + r(w1 * x1[i])))
        }
        [(d0, w0), (d1, w1), (d2, w2)] => {
            let (x0, x1, x2) = (
                load::<N>(data, at, d0),
                load::<N>(data, at, d1),
                load::<N>(data, at, d2),
            );
            std::array::from_fn(|i| r(r(r(w0 * x0[i]) + r(w1 * x1[i])) + r(w2 * x2[i])))
        }
        _ => {
            let mut acc = [0.0; N];
            for (n, &(delta, w)) in terms.iter().enumerate() {
                let x = load::<N>(data, at, delta);
                for i in 0..N {
                    let v = r(w * x[i]);
                    acc[i] = if n == 0 { v } else { r(acc[i] + v) };
                }
            }
            acc
        }
    }
}

/// `(N, T, single)` when every parameter of every output has `N`
/// components, `T` terms and the same precision.
fn uniform_shape(fixed: &[FixedOutput]) -> Option<(usize, usize, bool)> {
    let mut all = fixed
        .iter()
        .flat_map(|(_, cs)| cs)
        .map(|(ty, ts)| (ty.dim(), ts.len(), ty.is_single()));
    let first = all.next()?;
    all.all(|s| s == first).then_some(first)
}

/// A uniform step's inner range runs on rayon's pool from this many modules
/// on; below it, one thread (the pool's start-up would cost more than it
/// saves).
pub(crate) const PARALLEL_MODULES: usize = 1 << 16;

/// The most values the globals may hold for a step to run in parts, each
/// part on its own copy of them.
const MAX_COPIED_GLOBALS: usize = 1 << 12;

/// The modules one parallel task computes: many blocks, so that a task
/// outweighs its scheduling, and few enough that two threads share a step
/// evenly.
const TASK_MODULES: usize = 64 * KERNEL_BLOCK;

/// The modules `fixed_kernel` computes and checks at a time.
const KERNEL_BLOCK: usize = 256;

/// The modules `range` of a uniform step whose parameters all have `N`
/// components and `T` terms: `fixed_eval`'s operations in the same order,
/// appended to `out` a block at a time. Returns whether every value is
/// finite, or `None` when the outputs do not have that shape.
///
/// A range of `PARALLEL_MODULES` or more, on a pool of several threads, is
/// cut into tasks of `TASK_MODULES` that run on rayon's pool, each writing
/// its own part of `out`'s room. Every value depends only on the old word,
/// and the finiteness of the whole is the `&` of the tasks', so the result
/// is the same, to the bit, for any number of threads.
fn fixed_kernel<const N: usize, const T: usize, const SINGLE: bool>(
    fixed: &[FixedOutput],
    data: &[f64],
    w: usize,
    range: Range<usize>,
    out: &mut Vec<f64>,
) -> Option<bool> {
    let mut combos: Vec<[(isize, f64); T]> = Vec::new();
    for (_, cs) in fixed {
        for (ty, ts) in cs {
            if ty.dim() != N || ty.is_single() != SINGLE {
                return None;
            }
            combos.push(ts.as_slice().try_into().ok()?);
        }
    }
    // Every term reads whole groups of `N` slots: address the word as an
    // array of such groups, one bounds check per term.
    if combos.is_empty()
        || !w.is_multiple_of(N)
        || combos.iter().flatten().any(|(d, _)| d % N as isize != 0)
    {
        return None;
    }
    let (groups, _) = data.as_chunks::<N>();
    let per_module = combos.len() * N;
    let wn = w / N;
    if range.len() < PARALLEL_MODULES || rayon::current_num_threads() == 1 {
        // One thread: each block is written in place.
        let mut ok = true;
        for i in range.clone().step_by(KERNEL_BLOCK) {
            let m = (range.end - i).min(KERNEL_BLOCK);
            let from = out.len();
            out.resize(from + m * per_module, 0.0);
            ok &= fixed_block::<N, T, SINGLE>(&combos, groups, wn, i, &mut out[from..]);
        }
        return Some(ok);
    }
    let len = range.len() * per_module;
    out.reserve(len);
    let room = &mut out.spare_capacity_mut()[..len];
    let first = range.start;
    let ok = {
        use rayon::prelude::*;
        room.par_chunks_mut(TASK_MODULES * per_module)
            .enumerate()
            .map(|(k, part)| {
                // The task's blocks are computed in a buffer that stays in
                // the first-level cache, then copied out.
                let mut scratch = vec![0.0; KERNEL_BLOCK * per_module];
                let mut ok = true;
                let from = first + k * TASK_MODULES;
                for (b, dst) in part.chunks_mut(KERNEL_BLOCK * per_module).enumerate() {
                    let block = &mut scratch[..dst.len()];
                    let i = from + b * KERNEL_BLOCK;
                    ok &= fixed_block::<N, T, SINGLE>(&combos, groups, wn, i, block);
                    dst.write_copy_of_slice(block);
                }
                ok
            })
            .reduce(|| true, |a, b| a & b)
    };
    // SAFETY: the tasks wrote every element of `room`, the first `len`
    // elements of `out`'s spare capacity: their parts cover `room`, and
    // each part's blocks cover it and are written whole by
    // `write_copy_of_slice`. A panic would leave before this line, with
    // `out` as it was.
    unsafe { out.set_len(out.len() + len) };
    Some(ok)
}

/// One block of `fixed_kernel`: the slots of the modules from `i` on that
/// fill `block`, which is small enough to stay in the first-level cache
/// while it is filled, then checked. Returns whether every value is finite.
#[inline(always)]
fn fixed_block<const N: usize, const T: usize, const SINGLE: bool>(
    combos: &[[(isize, f64); T]],
    groups: &[[f64; N]],
    wn: usize,
    i: usize,
    block: &mut [f64],
) -> bool {
    let r = rounded::<SINGLE>;
    let c_count = combos.len();
    let m = block.len() / (c_count * N);
    let (groups_out, _) = block.as_chunks_mut::<N>();
    for (c_at, c) in combos.iter().enumerate() {
        // One parameter of every module of the block at a time, with the
        // weights and offsets in registers.
        let ws: [f64; T] = std::array::from_fn(|t| c[t].1);
        let es: [isize; T] = std::array::from_fn(|t| c[t].0 / N as isize);
        for (o, i) in groups_out.chunks_exact_mut(c_count).zip(i..i + m) {
            let at = (i * wn) as isize;
            let x: [&[f64; N]; T] = std::array::from_fn(|t| &groups[(at + es[t]) as usize]);
            o[c_at] = std::array::from_fn(|k| {
                let mut acc = r(ws[0] * x[0][k]);
                for t in 1..T {
                    acc = r(acc + r(ws[t] * x[t][k]));
                }
                acc
            });
        }
    }
    block.iter().fold(true, |ok, x| ok & x.is_finite())
}

/// `x`, rounded to single precision when the stencil computes `float`s:
/// the interpreter rounds every single-precision product and sum.
#[inline(always)]
fn rounded<const SINGLE: bool>(x: f64) -> f64 {
    if SINGLE {
        crate::lang::value::round32(x)
    } else {
        x
    }
}

/// Appends one stencil output, with its type's size and precision.
#[inline(always)]
fn combine_into(c: &crate::lang::stencil::Combination, sources: &[&[f64]], out: &mut Vec<f64>) {
    let t = &c.terms;
    match (c.ty.dim(), c.ty.is_single()) {
        (2, true) => out.extend_from_slice(&combine::<2, true>(t, sources)),
        (3, true) => out.extend_from_slice(&combine::<3, true>(t, sources)),
        (_, true) => out.push(combine::<1, true>(t, sources)[0]),
        (2, _) => out.extend_from_slice(&combine::<2, false>(t, sources)),
        (3, _) => out.extend_from_slice(&combine::<3, false>(t, sources)),
        _ => out.push(combine::<1, false>(t, sources)[0]),
    }
}

/// One stencil output of `N` components, the terms applied left to right.
#[inline(always)]
fn combine<const N: usize, const SINGLE: bool>(
    terms: &[crate::lang::stencil::Term],
    sources: &[&[f64]],
) -> [f64; N] {
    let mut acc = [0.0; N];
    for (n, t) in terms.iter().enumerate() {
        let x: [f64; N] = match t.source {
            Some((k, off)) => {
                let s = &sources[k as usize][off as usize..off as usize + N];
                std::array::from_fn(|i| s[i])
            }
            None => [0.0; N],
        };
        for i in 0..N {
            let v = rounded::<SINGLE>(t.apply(x[i]));
            acc[i] = if n == 0 {
                v
            } else if t.sub {
                rounded::<SINGLE>(acc[i] - v)
            } else {
                rounded::<SINGLE>(acc[i] + v)
            };
        }
    }
    acc
}

/// Matches `rule`'s strict predecessor at `start` and its left and right
/// contexts around it in the old word, pushing the matched modules (left
/// context, strict, right context) onto `matched`. Returns where the left
/// context's match ended and where the right one's did, or `None` when the
/// rule does not apply there.
#[inline]
fn match_old(
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

/// Appends the successor `st` computes from the `matched` modules of
/// `src`; rule `r`'s error, and `dst` as it was, when a value of it is not
/// finite.
#[inline(always)]
fn stencil_into(
    st: &Stencil,
    r: usize,
    src: &Word,
    matched: &[usize],
    dst: &mut Word,
) -> Result<(), StepError> {
    let before = dst.len();
    if apply_stencil(st, src, matched, dst) {
        return Ok(());
    }
    dst.truncate(before);
    Err(StepError::Runtime {
        rule: r,
        error: RuntimeError::new(None, "a parameter of the successor is NaN or infinite"),
    })
}

/// Runs rule `r`'s compiled body on the `matched` modules of `src`, in a
/// forward step: straight into `dst`, taken back when the body does not
/// produce (or fails). Says whether it produced. With `bound`, the
/// machine's frame already holds the parameters, as the body run last on
/// the same modules left them ([`closure::Body::leaves_params_for`]).
#[allow(clippy::too_many_arguments)]
#[inline]
fn run_forward(
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

/// What the parts of a parallel step share: the program, its compiled
/// bodies, its rules by symbol and the old word's context tables.
struct Shared<'a> {
    program: &'a Program,
    bodies: &'a [Option<closure::Body>],
    tables: &'a Tables,
    dispatch: &'a Dispatch,
    sb: Sym,
    eb: Sym,
}

/// A step's rules (all with a one-module strict predecessor) by the symbol
/// of that module, each symbol's in the order they are tried, so that a
/// module tries only the rules that may match it. Each rule also says
/// whether its predecessor (contexts, overload widths and filter) is that
/// of the rule before it in its symbol's list: where it is, the match
/// found (or refused) for that rule holds for this one, and is not made
/// again.
#[derive(Debug, Default)]
struct Dispatch {
    /// The step's rules, as given, that the rest was made for.
    rules: Vec<usize>,
    /// Symbol `s`'s rules are `cands[first[s]..first[s + 1]]`; symbols
    /// past the end have none.
    first: Vec<u32>,
    /// A rule, whether its predecessor is the one before it's, and
    /// whether then its body finds its parameters bound by the body of
    /// the one before it (which ran on the same modules and did not
    /// produce).
    cands: Vec<(usize, bool, bool)>,
    /// Per symbol, whether it has rules.
    has: Vec<bool>,
}

impl Dispatch {
    /// Makes the lists for `rules`, unless they were made for them last.
    fn prepare(&mut self, program: &Program, bodies: &[Option<closure::Body>], rules: &[usize]) {
        if self.rules == rules && !self.first.is_empty() {
            return;
        }
        let sym = |r: usize| program.rules[r].strict.first().map(|p| p.sym.0 as usize);
        let top = rules
            .iter()
            .filter_map(|&r| sym(r))
            .max()
            .map_or(0, |s| s + 1);
        let mut first = vec![0u32; top + 1];
        for &r in rules {
            if let Some(s) = sym(r) {
                first[s + 1] += 1;
            }
        }
        for s in 0..top {
            first[s + 1] += first[s];
        }
        let mut cands = vec![(usize::MAX, false, false); first[top] as usize];
        let mut next: Vec<u32> = first[..top].to_vec();
        // A body that runs: the rule's, unless a stencil runs instead.
        let body = |r: usize| match program.rules[r].stencil {
            Some(_) => None,
            None => bodies[r].as_ref(),
        };
        for &r in rules {
            if let Some(s) = sym(r) {
                let k = next[s] as usize;
                let before = (k > first[s] as usize).then(|| cands[k - 1].0);
                let same =
                    before.is_some_and(|b| same_predecessor(&program.rules[b], &program.rules[r]));
                let bound = same
                    && before
                        .and_then(body)
                        .is_some_and(|b| body(r).is_some_and(|this| b.leaves_params_for(this)));
                cands[k] = (r, same, bound);
                next[s] += 1;
            }
        }
        self.rules = rules.to_vec();
        self.has = first.windows(2).map(|w| w[0] < w[1]).collect();
        self.first = first;
        self.cands = cands;
    }

    /// True when some rule's strict predecessor is a module of symbol `s`.
    #[inline(always)]
    fn rewrites(&self, s: Sym) -> bool {
        self.has.get(s.0 as usize).copied().unwrap_or(false)
    }

    /// The rules whose strict predecessor is a module of symbol `s`.
    #[inline(always)]
    fn of(&self, s: Sym) -> &[(usize, bool, bool)] {
        let s = s.0 as usize;
        match self.first.get(s..s + 2) {
            Some(&[a, b]) => &self.cands[a as usize..b as usize],
            _ => &[],
        }
    }
}

/// True when `a` and `b` match at the same modules: the same contexts and
/// strict predecessor (symbols and overload widths; the parameters' names
/// do not take part) and the same `ignore:`/`consider:` filter.
fn same_predecessor(a: &Rule, b: &Rule) -> bool {
    let same = |x: &[Pattern], y: &[Pattern]| {
        x.len() == y.len()
            && x.iter()
                .zip(y)
                .all(|(p, q)| p.sym == q.sym && p.width == q.width)
    };
    a.filter == b.filter
        && same(&a.new_left, &b.new_left)
        && same(&a.left, &b.left)
        && same(&a.strict, &b.strict)
        && same(&a.right, &b.right)
        && same(&a.new_right, &b.new_right)
}

/// Rewrites the modules `range` of `src` forward into `dst` (appending),
/// with rules whose strict predecessor is one module and that have no new
/// context ([`Rewriter::lean`]; in parts, [`Rewriter::parallel_step`]
/// also asks that successors depend on the old word alone). `grown`
/// sums, across the parts, the modules written so far, reported every
/// [`DEADLINE_EVERY`] modules, so that a runaway step stops near its limit
/// however many parts it has. Returns how many modules a rule rewrote.
#[allow(clippy::too_many_arguments)]
fn rewrite_part(
    sh: &Shared,
    src: &Word,
    range: Range<usize>,
    dst: &mut Word,
    env: &mut Env,
    opts: &StepOptions,
    m: &mut closure::Machine,
    grown: &std::sync::atomic::AtomicUsize,
) -> Result<usize, StepError> {
    use std::sync::atomic::Ordering::Relaxed;
    let mut matched = Vec::new();
    let mut rewritten = 0;
    // The rule that produced last, to blame for a word grown too long.
    let mut last_rule = None;
    let mut reported = dst.len();
    let mut from = range.start;
    while from < range.end {
        crate::deadline::check(opts.deadline).map_err(StepError::Timeout)?;
        let total = grown.fetch_add(dst.len() - reported, Relaxed) + dst.len() - reported;
        reported = dst.len();
        if total > opts.max_modules {
            return Err(StepError::TooLong {
                limit: opts.max_modules,
                rule: None,
            });
        }
        let to = range.end.min(from + DEADLINE_EVERY);
        let mut i = from;
        while i < to {
            let d = sh.dispatch;
            if !d.rewrites(src.sym(i)) {
                // A run of modules that no rule rewrites, copied at once.
                let mut j = i + 1;
                while j < to && !d.rewrites(src.sym(j)) {
                    j += 1;
                }
                dst.push_range(src, i..j);
                if dst.len() > opts.max_modules {
                    return Err(StepError::TooLong {
                        limit: opts.max_modules,
                        rule: last_rule,
                    });
                }
                i = j;
                continue;
            }
            let cands = d.of(src.sym(i));
            let mut produced = false;
            // Whether the last rule tried matched (`matched` holds its
            // match when it did).
            let mut applies = false;
            for &(r, same, bound) in cands {
                let rule = &sh.program.rules[r];
                if !same {
                    let ctx = Rules {
                        sb: sh.sb,
                        eb: sh.eb,
                        filter: &rule.filter,
                        ring: opts.ring,
                        tables: Some(sh.tables),
                    };
                    applies = match_old(rule, src, i, ctx, &mut matched).is_some();
                }
                if !applies {
                    continue;
                }
                produced = match (&rule.stencil, &sh.bodies[r]) {
                    (Some(st), _) => stencil_into(st, r, src, &matched, dst).map(|()| true)?,
                    (None, Some(body)) => {
                        run_forward(body, r, m, &matched, src, dst, env, opts, false, bound)?
                    }
                    (None, None) => unreachable!("the lean path takes no interpreted body"),
                };
                if produced {
                    last_rule = Some(r);
                    break;
                }
            }
            rewritten += produced as usize;
            settle(produced, src, i, dst, opts, last_rule)?;
            i += 1;
        }
        from = to;
    }
    Ok(rewritten)
}

/// After module `i` of `src` was tried: copies it when no rule produced,
/// and fails once `dst` holds more modules than the limit (blaming `rule`,
/// the rule that produced last, when known).
#[inline(always)]
fn settle(
    produced: bool,
    src: &Word,
    i: usize,
    dst: &mut Word,
    opts: &StepOptions,
    rule: Option<usize>,
) -> Result<(), StepError> {
    if !produced {
        dst.push_from(src, i);
    }
    if dst.len() > opts.max_modules {
        return Err(StepError::TooLong {
            limit: opts.max_modules,
            rule,
        });
    }
    Ok(())
}

/// Evaluates a stencil into `dst`. Returns false if a value is not finite.
#[inline(always)]
fn apply_stencil(st: &Stencil, src: &Word, matched: &[usize], dst: &mut Word) -> bool {
    // The slots of the matched modules, looked up once.
    let mut slices: [&[f64]; 8] = [&[]; 8];
    let many: Vec<&[f64]>;
    let sources: &[&[f64]] = if matched.len() <= 8 {
        for (s, &i) in slices.iter_mut().zip(matched) {
            *s = src.data(i);
        }
        &slices[..matched.len()]
    } else {
        many = matched.iter().map(|&i| src.data(i)).collect();
        &many
    };
    let start = dst.slot_count();
    for (sym, combos) in &st.outputs {
        dst.push_with(*sym, |out| {
            for c in combos {
                combine_into(c, sources, out);
            }
        });
    }
    dst.all_slots()[start..].iter().all(|x| x.is_finite())
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Slots of `n` modules of `w` slots, varied and not round.
    fn slots(n: usize, w: usize) -> Vec<f64> {
        (0..n * w)
            .map(|j| crate::lang::value::round32(((j * 7919) % 1013) as f64 / 37.0 - 13.1))
            .collect()
    }

    /// `fixed_kernel` writes what `fixed_eval`, the loop it replaces, writes
    /// module by module: the same operations, so the same bits, across
    /// several blocks, for every shape it is compiled for.
    #[test]
    fn the_kernel_gives_the_bits_of_the_module_by_module_loop() {
        fn check<const N: usize, const T: usize, const SINGLE: bool>() {
            let (nl, nr) = (2usize, 1usize);
            // Modules of one N-vector (Chaikin), and of two with the terms
            // reading either.
            for groups in [1usize, 2] {
                let w = N * groups;
                let n = 700; // the inner range spans three blocks
                let data = slots(n, w);
                let ty = match (N, SINGLE) {
                    (2, true) => Ty::V2,
                    (2, false) => Ty::V2d,
                    (3, true) => Ty::V3,
                    _ => Ty::V3d,
                };
                // Term t reads module t - nl (within the contexts) at the
                // group t % groups, with a weight that is not a power of 2.
                let terms = |s: usize| -> Vec<(isize, f64)> {
                    (0..T)
                        .map(|t| {
                            let k = ((t + s) % (nl + 1 + nr)) as isize - nl as isize;
                            let off = (((t + s) % groups) * N) as isize;
                            (k * w as isize + off, 0.3 + 0.17 * (t + s) as f64)
                        })
                        .collect()
                };
                let fixed: Vec<FixedOutput> = vec![
                    (Sym(0), vec![(ty, terms(0))]),
                    (Sym(0), vec![(ty, terms(1)), (ty, terms(2))]),
                ];
                let range = nl..n - nr;
                let mut got = Vec::new();
                let ok = fixed_kernel::<N, T, SINGLE>(&fixed, &data, w, range.clone(), &mut got);
                assert_eq!(ok, Some(true));
                let mut want = Vec::new();
                for i in range.clone() {
                    for (_, cs) in &fixed {
                        for (_, ts) in cs {
                            want.extend(fixed_eval::<N, SINGLE>(ts, &data, (i * w) as isize));
                        }
                    }
                }
                assert_eq!(got.len(), want.len());
                let same = got
                    .iter()
                    .zip(&want)
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "N {N} T {T} single {SINGLE} groups {groups}");
                // An infinity in the third block is reported; so is an
                // overflow of finite values.
                let mut bad = data.clone();
                bad[600 * w] = f64::INFINITY;
                let mut out = Vec::new();
                let ok = fixed_kernel::<N, T, SINGLE>(&fixed, &bad, w, range.clone(), &mut out);
                assert_eq!(ok, Some(false));
                let mut big = data.clone();
                big[600 * w] = 1e308;
                let huge: Vec<FixedOutput> = vec![(Sym(0), vec![(ty, vec![(0, 1e10); T])])];
                let ok = fixed_kernel::<N, T, SINGLE>(&huge, &big, w, range.clone(), &mut out);
                assert_eq!(ok, Some(false));
            }
            // A range long enough to be cut into tasks, in pools of 2 and 3
            // threads (5 tasks and a short one): the bits of the loop, and
            // a NaN in the last task is reported.
            let w = N;
            let n = PARALLEL_MODULES + TASK_MODULES + 1000;
            let mut data = slots(n, w);
            let ty = match (N, SINGLE) {
                (2, true) => Ty::V2,
                (2, false) => Ty::V2d,
                (3, true) => Ty::V3,
                _ => Ty::V3d,
            };
            let terms: Vec<(isize, f64)> = (0..T)
                .map(|t| ((t as isize - 1) * w as isize, 0.3 + 0.17 * t as f64))
                .collect();
            let fixed: Vec<FixedOutput> = vec![(Sym(0), vec![(ty, terms.clone()), (ty, terms)])];
            let range = 1..n - (T - 1);
            let mut want = Vec::new();
            for i in range.clone() {
                for (_, ts) in &fixed[0].1 {
                    want.extend(fixed_eval::<N, SINGLE>(ts, &data, (i * w) as isize));
                }
            }
            let want: Vec<u64> = want.iter().map(|x| x.to_bits()).collect();
            for threads in [2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .expect("a pool");
                let mut got = vec![7.0];
                let ok = pool.install(|| {
                    fixed_kernel::<N, T, SINGLE>(&fixed, &data, w, range.clone(), &mut got)
                });
                assert_eq!(ok, Some(true));
                assert_eq!(got[0], 7.0, "what was there is kept");
                let got: Vec<u64> = got[1..].iter().map(|x| x.to_bits()).collect();
                assert!(got == want, "N {N} T {T} single {SINGLE} threads {threads}");
            }
            data[(n - 10) * w] = f64::NAN;
            let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build();
            let ok = pool.expect("a pool").install(|| {
                fixed_kernel::<N, T, SINGLE>(&fixed, &data, w, range.clone(), &mut Vec::new())
            });
            assert_eq!(ok, Some(false));
        }
        check::<2, 2, true>();
        check::<2, 3, true>();
        check::<2, 4, true>();
        check::<3, 2, true>();
        check::<3, 3, true>();
        check::<3, 4, true>();
        check::<2, 2, false>();
        check::<2, 3, false>();
        check::<2, 4, false>();
        check::<3, 2, false>();
        check::<3, 3, false>();
        check::<3, 4, false>();
    }

    /// Outputs of another shape are left to the general loop.
    #[test]
    fn the_kernel_declines_other_shapes() {
        let data = slots(10, 3);
        let mut out = Vec::new();
        // Three slots per module do not split into 2-vectors.
        let v2 = vec![(Sym(0), vec![(Ty::V2, vec![(0, 0.5), (3, 0.5)])])];
        assert_eq!(
            fixed_kernel::<2, 2, true>(&v2, &data, 3, 1..9, &mut out),
            None
        );
        // Three terms where the kernel has two; another precision.
        let three = vec![(Sym(0), vec![(Ty::V3, vec![(0, 0.5), (3, 0.5), (-3, 1.0)])])];
        assert_eq!(
            fixed_kernel::<3, 2, true>(&three, &data, 3, 1..9, &mut out),
            None
        );
        assert_eq!(
            fixed_kernel::<3, 3, false>(&three, &data, 3, 1..9, &mut out),
            None
        );
        assert!(out.is_empty());
        assert_eq!(uniform_shape(&three), Some((3, 3, true)));
        let mixed = vec![(
            Sym(0),
            vec![(Ty::V3, vec![(0, 1.0)]), three[0].1[0].clone()],
        )];
        assert_eq!(uniform_shape(&mixed), None);
    }

    /// A word grown to `steps` steps on one thread, then one more step run
    /// by hand: whether `parallel_step` takes it in a pool of `threads`,
    /// and the new word (from whichever path ran).
    fn last_step(src: &str, steps: u64, threads: usize) -> (bool, Word) {
        let curve = crate::load_str("t.lsys", src, &[]).expect("loads");
        let program = &curve.program;
        let opts = crate::DeriveOptions::default().with_steps(steps);
        let d = crate::derive(program, opts).expect("derives");
        let mut interp = Interp::for_program(program, None);
        let mut env = Env::for_program(program, &mut interp, Default::default(), None)
            .expect("an environment");
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
        // Made here: `closure::set_enabled` holds on this thread.
        let mut rw = Rewriter::new(program);
        pool.expect("a pool").install(|| {
            let rules: Vec<usize> = (0..program.rules.len()).collect();
            let opts = StepOptions {
                ring: false,
                forward: true,
                phase: 0,
                max_modules: usize::MAX,
                deadline: None,
                cut: true,
            };
            let mut dst = Word::new();
            let parallel = rw
                .parallel_step(&rules, &d.word, &mut dst, &mut env, &opts)
                .is_some();
            let mut again = Word::new();
            rw.step(&rules, &d.word, &mut again, &mut env, &opts, None, None)
                .expect("steps");
            if parallel {
                assert_eq!(dst, again, "step() takes the same path");
            }
            (parallel, again)
        })
    }

    /// Guarded, branching, context-sensitive rules with compiled bodies
    /// that read a global: the general path runs them in parts, and the
    /// word is the one the interpreter makes on one thread, to the bit.
    #[test]
    fn pure_bodies_run_in_parts_as_the_interpreter_runs_them() {
        let src = "module A(float, int); module B(float);\n\
             float k = 0.5;\nderivation length: 1;\nAxiom: B(1) F(1) A(1, 0);\n\
             production:\n\
             F(x) < A(l, d) : { if (d % 3 == 2 && l < 0.7) produce F(l) A(l * k, d + 1); \
                else produce F(l) SB() B(x + l) A(l * 0.9, d + 1) EB() A(l * 0.8, d + 2); }\n\
             A(l, d) -> F(l) A(l * 0.6, d + 1) SB() A(l, d + 2) EB()\n\
             B(x) > SB() A(l, d) -> B(x * 0.5 + l)\n";
        let (parallel, two) = last_step(src, 18, 2);
        assert!(two.len() > 2 * PARALLEL_MODULES, "{} modules", two.len());
        assert!(parallel, "the general path ran in parts");
        let (serial, one) = last_step(src, 18, 1);
        assert!(!serial);
        assert!(one == two, "the same word on one thread");
        closure::set_enabled(false);
        let (interpreted, reference) = last_step(src, 18, 2);
        closure::set_enabled(true);
        assert!(!interpreted, "interpreted bodies run on one thread");
        assert!(reference == two, "the interpreter's word");
    }

    /// A body that stores a global or draws a random number runs on one
    /// thread: what it produces depends on the order of the modules.
    #[test]
    fn bodies_with_effects_run_on_one_thread() {
        for body in [
            "n = n + 1; produce A(l * 0.9) A(l * 0.8);",
            "produce A(l * ran(1)) A(l);",
        ] {
            let src = format!(
                "module A(float);\nint n = 0;\nderivation length: 1;\nAxiom: A(1);\n\
                 production:\nA(l) : {{ {body} }}\n"
            );
            let (parallel, _) = last_step(&src, 17, 2);
            assert!(!parallel, "{body}");
        }
        let pure = "module A(float);\nint n = 0;\nderivation length: 1;\nAxiom: A(1);\n\
             production:\nA(l) : { int m = n + 1; produce A(l * 0.9) SB() A(l * m) EB(); }\n";
        assert!(last_step(pure, 16, 2).0, "reading a global is pure");
        // Each part would copy a large array the body does not even read.
        let big = pure.replace("int n = 0;", "int n = 0;\nfloat big[10000];");
        assert!(
            !last_step(&big, 16, 2).0,
            "large globals stay on one thread"
        );
    }

    /// An overflow in the middle of a long ring, where the kernel computes,
    /// is reported by the general path with the production's name.
    #[test]
    fn an_overflow_inside_a_long_ring_names_the_production() {
        let mut axiom = String::from("Axiom:");
        for i in 0..1000 {
            let x = if i == 700 { "3e38" } else { "1" };
            axiom.push_str(&format!(" P(V2f({x}, 0))"));
        }
        let src = format!(
            "module P(V2f);\nring L-system: 1;\nderivation length: 2;\n{axiom};\n\
             P(vl) < P(v) > P(vr) -> P(0.5*vl + 2*v) P(2*v + 0.5*vr)\n"
        );
        let curve = crate::load_str("t.lsys", &src, &[]).expect("loads");
        assert!(curve.program.rules[0].stencil.is_some());
        let e = crate::derive(&curve.program, Default::default()).expect_err("overflows");
        assert!(e.message.contains("at step 1"), "{}", e.message);
        assert!(e.message.contains("NaN or infinite"), "{}", e.message);
        assert!(e.message.contains("P(vl) < P(v) > P(vr)"), "{}", e.message);
    }

    /// The final word of `src` derived on one thread, compiled bodies on
    /// or off (off: the interpreter on the general loop, the reference),
    /// as `(symbol name, parameter bits)`s; or the error's message.
    fn derived(src: &str, compiled: bool) -> Result<Vec<(String, Vec<u64>)>, String> {
        derived_within(src, compiled, crate::DeriveOptions::default().max_modules)
    }

    /// [`derived`] with a limit on the word.
    fn derived_within(
        src: &str,
        compiled: bool,
        max_modules: usize,
    ) -> Result<Vec<(String, Vec<u64>)>, String> {
        closure::set_enabled(compiled);
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
        let out = pool.expect("a pool").install(|| {
            let curve = crate::load_str("t.lsys", src, &[]).map_err(|e| e.to_string())?;
            let p = &curve.program;
            let opts = crate::DeriveOptions {
                max_modules,
                ..Default::default()
            };
            let d = crate::derive(p, opts).map_err(|e| e.to_string())?;
            Ok((0..d.word.len())
                .map(|i| {
                    let name = p.alphabet.name(d.word.sym(i)).to_string();
                    (name, d.word.data(i).iter().map(|x| x.to_bits()).collect())
                })
                .collect())
        });
        closure::set_enabled(true);
        out
    }

    /// Two guarded rules with one left context, as `bench_body`'s signal:
    /// on the lean path (the rules tried by symbol, the context matched
    /// once for both), the word of a recursion written here, in `double`,
    /// to the bit, on a word and on a ring; and the interpreter's.
    #[test]
    fn guarded_context_rules_on_the_lean_path_give_the_recursion() {
        let (n, steps) = (40, 30);
        for ring in [false, true] {
            let mut axiom = String::from("A(1)");
            for k in 1..n {
                axiom.push_str(&format!(" A({})", (k % 3) as f64 * 0.25));
            }
            let src = format!(
                "module A(double);\n{}derivation length: {steps};\nAxiom: {axiom};\n\
                 A(x) < A(y) : {{ if (x > y) produce A(x * 0.5 + y + 1); }}\n\
                 A(x) < A(y) : {{ if (x <= y) produce A(y * 0.5); }}\n",
                if ring { "ring L-system: 1;\n" } else { "" }
            );
            let mut a: Vec<f64> = (0..n)
                .map(|k| if k == 0 { 1.0 } else { (k % 3) as f64 * 0.25 })
                .collect();
            for _ in 0..steps {
                a = (0..n)
                    .map(|k| {
                        let left = match k {
                            0 if ring => Some(a[n - 1]),
                            0 => None,
                            _ => Some(a[k - 1]),
                        };
                        match left {
                            Some(x) if x > a[k] => x * 0.5 + a[k] + 1.0,
                            Some(_) => a[k] * 0.5,
                            None => a[k],
                        }
                    })
                    .collect();
            }
            let want: Vec<(String, Vec<u64>)> = a
                .iter()
                .map(|x| ("A".to_string(), vec![x.to_bits()]))
                .collect();
            assert_eq!(derived(&src, true), Ok(want.clone()), "ring {ring}");
            assert_eq!(derived(&src, false), Ok(want), "ring {ring}, interpreted");
        }
    }

    /// Rules of several symbols, in file order: a rule whose predecessor
    /// is the one before it's reuses that match (and its refusal), one
    /// after a rule of another predecessor matches again; `ignore:` skips
    /// in the context. The word worked out by hand, and the interpreter's.
    #[test]
    fn rules_by_symbol_keep_file_order_and_shared_matches() {
        let src = "module A(int); module B(int); module C(int);\n\
             derivation length: 1;\n\
             Axiom: A(1) C(0) B(2) A(3) B(4) B(5) A(6) B(5) A(8) B(7) C(0);\n\
             ignore: C;\n\
             A(x) < B(y) : { if (y > 3 && y < 5) produce B(y + x * 10); }\n\
             B(y) : { if (y == 2) produce B(20); }\n\
             A(x) < B(y) : { if (y == 5) produce B(y * 100); }\n\
             A(x) < B(y) : { produce B(x - y); }\n\
             A(x) : { produce A(x + 1) C(x); }\n";
        let int = |s: &str, v: i64| (s.to_string(), vec![v as u64]);
        let want = vec![
            int("A", 2),
            int("C", 1),
            int("C", 0),
            int("B", 20),
            int("A", 4),
            int("C", 3),
            int("B", 34),
            int("B", 5),
            int("A", 7),
            int("C", 6),
            int("B", 500),
            int("A", 9),
            int("C", 8),
            int("B", 1),
            int("C", 0),
        ];
        assert_eq!(derived(src, true), Ok(want.clone()));
        assert_eq!(derived(src, false), Ok(want));
    }

    /// Errors on the lean path are the general loop's: a NaN in the
    /// second module of a successor names that rule, and a word past its
    /// limit names the rule that produced last.
    #[test]
    fn lean_path_errors_name_the_rule() {
        let nan = "module A(double);\nderivation length: 1;\nAxiom: A(1) A(0) A(2);\n\
             A(y) : { if (y > 1) produce A(y); }\n\
             A(x) : { produce A(x) A(1 / x - 1 / x); }\n";
        let e = derived(nan, true).expect_err("a NaN");
        assert_eq!(derived(nan, false), Err(e.clone()));
        assert!(e.contains("NaN"), "{e}");
        assert!(e.contains("A(x)") && !e.contains("A(y)"), "{e}");
        let long = "module A(double); module B(double);\nderivation length: 40;\n\
             Axiom: B(1) A(1);\n\
             B(x) : { produce B(x); }\n\
             A(x) : { if (x < 1e300) produce A(x * 2) A(x * 3); }\n";
        let e = derived_within(long, true, 1000).expect_err("too long");
        assert_eq!(derived_within(long, false, 1000), Err(e.clone()));
        assert!(e.contains("1000") && e.contains("A(x)"), "{e}");
    }

    /// The second of two rules with one predecessor runs on the
    /// parameters its body binds, not on what the first body left in the
    /// frame: a first body that stores into a parameter makes the second
    /// bind again (worked out by hand: 1 and 2, the first rule producing
    /// only where ten times the parameter passes 15); one that stores
    /// only into a local of its own leaves the parameters to the next.
    #[test]
    fn a_body_that_writes_its_parameter_leaves_the_next_rule_the_modules_values() {
        let writes = "module A(double);\nderivation length: 1;\nAxiom: A(1) A(2);\n\
             A(x) : { x = x * 10; if (x > 15) produce A(x); }\n\
             A(x) : { produce A(x + 0.5); }\n";
        let locals = "module A(double);\nderivation length: 1;\nAxiom: A(1) A(2);\n\
             A(x) : { double t = x * 10; if (t > 15) produce A(t); }\n\
             A(y) : { double u = y + 0.5; produce A(u); }\n";
        let a = |x: f64| ("A".to_string(), vec![x.to_bits()]);
        for src in [writes, locals] {
            assert_eq!(derived(src, true), Ok(vec![a(1.5), a(20.0)]), "{src}");
            assert_eq!(derived(src, false), Ok(vec![a(1.5), a(20.0)]), "{src}");
        }
    }
}
