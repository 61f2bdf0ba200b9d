//! Steps in parts on rayon's pool: a forward step whose successors depend
//! on the old word alone, cut into parts rewritten at once and joined in
//! order, and a step of stencils written straight into its place in the
//! new word. The result is the same, to the bit, for any number of
//! threads.

use crate::lang::closure;
use crate::lang::eval::Env;
use crate::lang::Value;
use crate::rewrite::context::Rules;
use crate::rewrite::word::Word;

use super::lean::rewrite_part;
use super::stencil::apply_stencil;
use super::try_rule::match_old;
use super::{Rewriter, StepOptions, DEADLINE_EVERY, KEEP, PARALLEL_MODULES};

impl<'p> Rewriter<'p> {
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
    pub(super) fn parallel_step(
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
    pub(super) fn stencil_parts(
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
}

/// The most values the globals may hold for a step to run in parts, each
/// part on its own copy of them.
const MAX_COPIED_GLOBALS: usize = 1 << 12;
