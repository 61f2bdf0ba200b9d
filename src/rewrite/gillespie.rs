//! A derivation step in a Gillespie group (manual 7.2): one reaction in the
//! whole word, chosen by Gillespie's method.
//!
//! Every module is a place where reactions may happen. At each position
//! (skipping what follows a `Cut` in its branch) the group's productions
//! whose strict predecessor starts with that module are tried in file
//! order, all of them, as lpfg does; each one that matches runs its body,
//! and its `propensity P produce W;` statements each add a reaction: the
//! predecessor would become `W`, with propensity `P` (a C `float`). A
//! production that matches but emits nothing ends the search at that
//! position. With `p` the sum of all propensities, reaction `i` is chosen
//! with probability `p_i / p` (the first whose running sum reaches
//! `p · χ₁`), its predecessor is replaced by its successor and every other
//! module stays; then the Gillespie time advances by `τ = −ln(1 − χ₂) / p`
//! (the manual writes `ln(1 − χ)/p`, which is negative; lpfg subtracts it).
//! χ₁ and χ₂ are drawn, in that order, from the run's Gillespie generator
//! (`lang::random`). With `p = 0` nothing happens and no number is drawn.
//!
//! As the manual says, a ring is ignored and new contexts are refused (by
//! the checker). A negative or non-finite propensity is an error here,
//! where lpfg prints a message and takes 0.
//!
//! The successors of all reactions are held at once, before one is chosen:
//! together they count against the word's module limit (`--max-modules`).

use crate::lang::eval::{Env, RuntimeError};
use crate::lang::ir::Program;
use crate::lang::modules::Sym;

use super::step::{Rewriter, StepError, StepOptions, COPIED};
use super::word::Word;

/// One possible reaction: the predecessor `start .. start + len` of the
/// word would become `successor` (a range of the pool), at `propensity`.
struct Reaction {
    start: usize,
    len: usize,
    rule: usize,
    successor: std::ops::Range<usize>,
    propensity: f64,
}

/// Performs one Gillespie step with the group's productions `rules`
/// (indices into `Program::rules`, in file order) from `src` into `dst`.
/// `origin`, when given, receives what made each module of `dst`, as
/// [`Rewriter::step`] gives it. Returns how many modules were rewritten.
#[allow(clippy::too_many_arguments)]
pub fn step(
    rewriter: &mut Rewriter,
    program: &Program,
    rules: &[usize],
    src: &Word,
    dst: &mut Word,
    env: &mut Env,
    opts: &StepOptions,
    origin: Option<&mut Vec<u32>>,
) -> Result<usize, StepError> {
    dst.clear();
    let opts = StepOptions {
        ring: false,
        forward: true,
        ..*opts
    };
    rewriter.begin(&opts);
    let propensity = program.alphabet.builtin("Propensity");
    let cut = program.alphabet.builtin("Cut");
    let (sb, eb) = (
        program.alphabet.builtin("SB"),
        program.alphabet.builtin("EB"),
    );
    let mut pool = Word::new();
    let mut reactions: Vec<Reaction> = Vec::new();
    let n = src.len();
    let mut i = 0;
    while i < n {
        if i % 4096 == 4095 {
            crate::deadline::check(opts.deadline).map_err(StepError::Timeout)?;
        }
        if src.sym(i) == cut {
            i = end_of_branch(src, i, sb, eb) + 1;
            continue;
        }
        for &r in rules {
            let rule = &program.rules[r];
            if rule.strict.first().is_none_or(|p| p.sym != src.sym(i)) {
                continue;
            }
            let before = pool.len();
            if !rewriter.try_rule(r, rule, src, i, &mut pool, env, &opts, true)? {
                continue;
            }
            if pool.len() == before {
                break;
            }
            if pool.sym(before) != propensity {
                return Err(StepError::Runtime {
                    rule: r,
                    error: RuntimeError::new(
                        None,
                        "a production of a Gillespie group must give its successors with \
                         `propensity P produce ...;` (manual 7.2), but this one produced \
                         modules without a propensity",
                    ),
                });
            }
            let mut k = before;
            while k < pool.len() {
                let p = f64::from(pool.data(k).first().copied().unwrap_or(0.0) as f32);
                if !(p >= 0.0 && p.is_finite()) {
                    return Err(StepError::Runtime {
                        rule: r,
                        error: RuntimeError::new(
                            None,
                            format!(
                                "a propensity must be a finite number, 0 or more, but this \
                                 production gave {p}"
                            ),
                        ),
                    });
                }
                let from = k + 1;
                k = from;
                while k < pool.len() && pool.sym(k) != propensity {
                    k += 1;
                }
                reactions.push(Reaction {
                    start: i,
                    len: rule.strict.len(),
                    rule: r,
                    successor: from..k,
                    propensity: p,
                });
            }
            if pool.len() > opts.max_modules {
                return Err(StepError::TooLong {
                    limit: opts.max_modules,
                    rule: Some(r),
                });
            }
        }
        i += 1;
    }
    let sum: f64 = reactions.iter().map(|r| r.propensity).sum();
    let mut chosen = None;
    if sum > 0.0 {
        let mut rnd = sum * env.random.gillespie.next_f64();
        for r in &reactions {
            rnd -= r.propensity;
            if rnd <= 0.0 {
                chosen = Some(r);
                break;
            }
        }
    }
    let mut made = Vec::new();
    match chosen {
        Some(c) => {
            let end = (c.start + c.len).min(n);
            for j in 0..c.start {
                dst.push_from(src, j);
                made.push(COPIED | j as u32);
            }
            for j in c.successor.clone() {
                dst.push_from(&pool, j);
                made.push(c.rule as u32);
            }
            for j in end..n {
                dst.push_from(src, j);
                made.push(COPIED | j as u32);
            }
        }
        None => {
            for j in 0..n {
                dst.push_from(src, j);
                made.push(COPIED | j as u32);
            }
        }
    }
    if dst.len() > opts.max_modules {
        return Err(StepError::TooLong {
            limit: opts.max_modules,
            rule: chosen.map(|c| c.rule),
        });
    }
    if let Some(o) = origin {
        *o = made;
    }
    if sum > 0.0 {
        let chi = env.random.gillespie.next_f64();
        env.random.gillespie_time -= (1.0 - chi).ln() / sum;
    }
    Ok(chosen.map_or(0, |c| c.len))
}

/// The position of the `EB` that ends the branch holding position `i`, or
/// the last position when the branch is the whole word.
fn end_of_branch(w: &Word, i: usize, sb: Sym, eb: Sym) -> usize {
    let mut depth = 0usize;
    for j in i + 1..w.len() {
        let s = w.sym(j);
        if s == sb {
            depth += 1;
        } else if s == eb {
            if depth == 0 {
                return j;
            }
            depth -= 1;
        }
    }
    w.len().saturating_sub(1)
}
