//! The loop over a range of modules with rules whose strict predecessor
//! is one module ([`rewrite_part`]): the rules by symbol ([`Dispatch`]),
//! a match shared by consecutive rules, runs of modules no rule rewrites
//! copied at once. The lean path runs it over the whole word on this
//! thread; a parallel step runs it on each part.

use std::ops::Range;

use crate::lang::closure;
use crate::lang::eval::Env;
use crate::lang::ir::{Pattern, Program, Rule};
use crate::lang::Sym;
use crate::rewrite::context::{Rules, Tables};
use crate::rewrite::word::Word;

use super::stencil::stencil_into;
use super::try_rule::{match_old, run_forward};
use super::{Rewriter, StepError, StepOptions, DEADLINE_EVERY};

impl<'p> Rewriter<'p> {
    /// Sets up what `rewrite_part` reads beside the word (the rules by
    /// symbol, the compiled bodies' loop limit and deadline) and lends it,
    /// with the machine of the first part and the words of the others.
    pub(super) fn prepare_parts(
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

    /// True when a step can run on the lean path ([`Rewriter::lean_step`]):
    /// forward, every rule's strict predecessor one module without new
    /// contexts, every body a stencil or compiled, no `Cut` to skip, and a
    /// ring scanned from its first module. Such a step scans the word in
    /// order, as the general loop does, so bodies with effects (globals,
    /// random numbers) see the modules in the same order.
    pub(super) fn lean(&self, rules: &[usize], src: &Word, opts: &StepOptions) -> bool {
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
    pub(super) fn lean_step(
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
}

/// What the parts of a parallel step share: the program, its compiled
/// bodies, its rules by symbol and the old word's context tables.
pub(super) struct Shared<'a> {
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
pub(super) struct Dispatch {
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
pub(super) fn rewrite_part(
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
pub(super) fn settle(
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
