//! Stencils: a stencil's outputs evaluated into a word (with the rounding
//! of single precision), and the fast path of a step whose rules are all
//! stencils with plain contexts.

use crate::lang::eval::RuntimeError;
use crate::lang::ir::Pattern;
use crate::lang::stencil::Stencil;
use crate::rewrite::context::module_matches;
use crate::rewrite::word::Word;

use super::lean::settle;
use super::{Rewriter, StepError, StepOptions};

impl<'p> Rewriter<'p> {
    /// True when the step can take the compiled fast path: every rule is a
    /// stencil with a one-module strict predecessor, plain contexts (no
    /// filter; an overloaded module's pattern matches by its width, as on
    /// the general path) and the word has no branches and no `Cut`.
    pub(super) fn stencils_only(&self, rules: &[usize], src: &Word) -> bool {
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

    /// The fast path: contexts are plain neighbours, bodies are stencils.
    /// Same result as the general path under the conditions of
    /// `stencils_only`.
    pub(super) fn stencil_step(
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
    pub(super) fn all_finite(dst: &Word) -> bool {
        // No early exit, so that the loop vectorises.
        dst.all_slots()
            .chunks(64)
            .all(|c| c.iter().fold(true, |ok, x| ok & x.is_finite()))
    }
}

/// `x`, rounded to single precision when the stencil computes `float`s:
/// the interpreter rounds every single-precision product and sum.
#[inline(always)]
pub(super) fn rounded<const SINGLE: bool>(x: f64) -> f64 {
    if SINGLE {
        crate::lang::value::round32(x)
    } else {
        x
    }
}

/// Appends one stencil output, with its type's size and precision.
#[inline(always)]
pub(super) fn combine_into(
    c: &crate::lang::stencil::Combination,
    sources: &[&[f64]],
    out: &mut Vec<f64>,
) {
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

/// Appends the successor `st` computes from the `matched` modules of
/// `src`; rule `r`'s error, and `dst` as it was, when a value of it is not
/// finite.
#[inline(always)]
pub(super) fn stencil_into(
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

/// Evaluates a stencil into `dst`. Returns false if a value is not finite.
#[inline(always)]
pub(super) fn apply_stencil(st: &Stencil, src: &Word, matched: &[usize], dst: &mut Word) -> bool {
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
