//! [`Rewriter::step`]: the path a step takes (a fast path of stencils, a
//! step in parts, the lean path), and the general loop, which scans the
//! modules one at a time in the word's order: forward or backward, on a
//! ring from its phase, past the branches a `Cut` removes.

use crate::lang::eval::Env;
use crate::rewrite::word::Word;

use super::{Rewriter, StepError, StepOptions, COPIED, DEADLINE_EVERY};

impl<'p> Rewriter<'p> {
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
