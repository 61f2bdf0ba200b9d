//! The fast path of a ring whose modules are all of one kind and one
//! width: one stencil at every module, neighbours found by index
//! arithmetic, and, away from the ring's seam, kernels compiled for the
//! shape of the stencil's terms.

use std::ops::Range;

use crate::lang::{Sym, Ty};
use crate::rewrite::word::Word;

use super::stencil::{combine_into, rounded};
use super::{Rewriter, StepError, StepOptions, PARALLEL_MODULES};

impl<'p> Rewriter<'p> {
    /// On a ring whose modules are all of one kind and one width, the first
    /// rule whose predecessor is made of that kind rewrites every module.
    /// Returns that rule and the width, when its body is a stencil.
    pub(super) fn uniform_rule(
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
    pub(super) fn uniform_step(
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
}
