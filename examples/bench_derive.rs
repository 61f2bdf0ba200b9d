//! Benchmarks of the rewriting engine against hand-written references,
//! measured in the same run. `cargo run --release --example bench_derive`
//!
//! `--chaikin-only` runs the first only; `--runs N` keeps the best of N runs
//! (10 by default) of the first three.
//!
//! 1. Closed Chaikin (production 13) from a 1,000-point axiom to 1,024,000
//!    points: the engine running the `.lsys` text, in lpfg's single
//!    precision (the default) and in double (`--double`), against two Rust
//!    loops doing the same arithmetic: one over points with `%` per point,
//!    and a tight one over flat buffers of coordinates (`f64`, and `f32` for
//!    single precision) with the ring's seam handled outside the loop.
//! 2. Threads (issue 16, item 6): the last step of the same run (512,000 ->
//!    1,024,000 points) and the whole run, in a pool of one rayon thread and
//!    one of two, alternating, with the best and the median of each and
//!    their speedups; the words are checked to be the same to the bit;
//!    then the tight flat `f64` loop's last step into fresh memory on both
//!    pools (what a second core gives a step that writes fresh memory),
//!    then the same for three branching systems on the general path (a
//!    plant whose rule is a stencil, a guarded body compiled to closures,
//!    and a bush without parameters), about a million modules at the end.
//!    `--threads-only` runs this section only; run it with
//!    `MALLOC_ARENA_MAX=1` (benches/README.md says why).
//! 3. A context-sensitive rewrite without geometry: a signal moving through
//!    a word of a million modules, in million modules per second.
//! 4. The interpreter on a branching word: 50,000 modules, each with a
//!    lateral branch that its right context skips, and a body with a loop
//!    of 20 iterations, in million modules per second.

mod common;

use common::best_of;
use glam::{DVec2, Vec2};
use subgram::DeriveOptions;

fn polygon(n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 1.0 + 0.3 * (7.0 * t).sin();
            DVec2::new(r * t.cos(), r * t.sin())
        })
        .collect()
}

/// The reference: Chaikin with index arithmetic, two reused buffers, on
/// points of either precision: `Vec2` computes as lpfg computes `V2f` (and
/// the engine by default), `DVec2` as the engine with `--double`.
fn chaikin_loop<P, S>(start: &[P], steps: usize) -> Vec<P>
where
    P: Copy + std::ops::Add<Output = P> + std::ops::Mul<S, Output = P>,
    S: Copy + From<f32>,
{
    let (quarter, three_quarters) = (S::from(0.25), S::from(0.75));
    let mut src = start.to_vec();
    let mut dst = Vec::with_capacity(start.len() << steps);
    for _ in 0..steps {
        dst.clear();
        let n = src.len();
        for i in 0..n {
            let vl = src[(i + n - 1) % n];
            let v = src[i];
            let vr = src[(i + 1) % n];
            dst.push(vl * quarter + v * three_quarters);
            dst.push(v * three_quarters + vr * quarter);
        }
        std::mem::swap(&mut src, &mut dst);
    }
    src
}

/// One point's two successors, `0.25·l + 0.75·v` and `0.75·v + 0.25·r`,
/// written as x, y, x, y: the same operations in the same order as the rule.
#[inline(always)]
fn chaikin_cut<T>(out: &mut [T], l: &[T], v: &[T], r: &[T], q: T, t: T)
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Mul<Output = T>,
{
    out[0] = l[0] * q + v[0] * t;
    out[1] = l[1] * q + v[1] * t;
    out[2] = v[0] * t + r[0] * q;
    out[3] = v[1] * t + r[1] * q;
}

/// The tight reference (issue 16): closed Chaikin over a flat buffer of
/// coordinates `x0, y0, x1, y1, …`; the first and the last point, whose
/// neighbours wrap around the ring, are cut outside the loop, so the loop
/// has no `%`; two buffers of the final size, allocated once and swapped.
/// `T = f32` computes as lpfg's `V2f` (each product and sum rounded to
/// single precision), `T = f64` as the engine with `--double`.
fn chaikin_flat<T>(start: &[T], steps: usize) -> Vec<T>
where
    T: Copy + Default + From<f32> + std::ops::Add<Output = T> + std::ops::Mul<Output = T>,
{
    let (q, t) = (T::from(0.25), T::from(0.75));
    let cap = start.len() << steps;
    let mut src = vec![T::default(); cap];
    let mut dst = vec![T::default(); cap];
    src[..start.len()].copy_from_slice(start);
    let mut len = start.len();
    assert!(len >= 4 && len.is_multiple_of(2), "at least two points");
    for _ in 0..steps {
        let (s, d) = (&src[..len], &mut dst[..2 * len]);
        chaikin_cut(&mut d[..4], &s[len - 2..], &s[..2], &s[2..4], q, t);
        let inner = d[4..2 * len - 4]
            .chunks_exact_mut(4)
            .zip(s.chunks_exact(2))
            .zip(s[2..].chunks_exact(2))
            .zip(s[4..].chunks_exact(2));
        for (((o, l), v), r) in inner {
            chaikin_cut(o, l, v, r, q, t);
        }
        chaikin_cut(
            &mut d[2 * len - 4..],
            &s[len - 4..len - 2],
            &s[len - 2..],
            &s[..2],
            q,
            t,
        );
        std::mem::swap(&mut src, &mut dst);
        len *= 2;
    }
    src.truncate(len);
    src
}

fn main() {
    // `--runs N`: more runs for the best time on a busy machine.
    let args: Vec<String> = std::env::args().collect();
    let runs = common::runs_arg(&args, 10);
    let pts = polygon(1000);
    let steps = 10;
    let axiom: Vec<String> = pts
        .iter()
        .map(|p| format!("P(V2f({:?}, {:?}))", p.x, p.y))
        .collect();
    let src = format!(
        "module P(V2f);\nring L-system: 1;\nderivation length: {steps};\nAxiom: {};\n\
         P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)\n",
        axiom.join(" ")
    );
    if args.iter().any(|a| a == "--threads-only") {
        threads(&src, runs);
        return;
    }
    for precision in [subgram::Precision::Single, subgram::Precision::Double] {
        let loaded = subgram::load_str_with("bench.lsys", &src, &[], precision).expect("loads");
        assert!(loaded.program.rules[0].stencil.is_some());
        let (t_engine, derived) = best_of(runs, || {
            subgram::derive(&loaded.program, DeriveOptions::default()).expect("derives")
        });
        // Same arithmetic, same order: the results agree exactly.
        let (t_loop, t_flat, out) = if precision == subgram::Precision::Single {
            let start: Vec<Vec2> = pts.iter().map(|p| p.as_vec2()).collect();
            let (t, reference) = best_of(runs, || chaikin_loop::<Vec2, f32>(&start, steps));
            assert_eq!(derived.word.len(), reference.len());
            for (i, r) in reference.iter().enumerate() {
                assert_eq!(derived.word.data(i), &[r.x as f64, r.y as f64]);
            }
            let flat: Vec<f32> = start.iter().flat_map(|p| [p.x, p.y]).collect();
            let (tf, reference) = best_of(runs, || chaikin_flat::<f32>(&flat, steps));
            assert_eq!(derived.word.len() * 2, reference.len());
            for (i, r) in reference.chunks_exact(2).enumerate() {
                assert_eq!(derived.word.data(i), &[r[0] as f64, r[1] as f64]);
            }
            (t, tf, reference.len() / 2)
        } else {
            let (t, reference) = best_of(runs, || chaikin_loop::<DVec2, f64>(&pts, steps));
            assert_eq!(derived.word.len(), reference.len());
            for (i, r) in reference.iter().enumerate() {
                assert_eq!(derived.word.data(i), &[r.x, r.y]);
            }
            let flat: Vec<f64> = pts.iter().flat_map(|p| [p.x, p.y]).collect();
            let (tf, reference) = best_of(runs, || chaikin_flat::<f64>(&flat, steps));
            assert_eq!(derived.word.len() * 2, reference.len());
            for (i, r) in reference.chunks_exact(2).enumerate() {
                assert_eq!(derived.word.data(i), r);
            }
            (t, tf, reference.len() / 2)
        };
        // The tight loop over `f64` whatever the precision: the issue's
        // yardstick (single precision stores its values as `f64` too).
        let t_flat64 = if precision == subgram::Precision::Single {
            let flat64: Vec<f64> = pts.iter().flat_map(|p| [p.x, p.y]).collect();
            best_of(runs, || chaikin_flat::<f64>(&flat64, steps)).0
        } else {
            t_flat
        };
        let ms = |t: std::time::Duration| t.as_secs_f64() * 1e3;
        let ratio = |t: std::time::Duration| t_engine.as_secs_f64() / t.as_secs_f64();
        let flat_ty = if precision == subgram::Precision::Single {
            "f32"
        } else {
            "f64"
        };
        println!(
            "chaikin 1000 -> {out} points, {precision:?} precision, best of {runs}, the engine on {} thread(s) (RAYON_NUM_THREADS), the loops on one",
            rayon::current_num_threads()
        );
        println!("  loop over points, %      {:>9.2} ms", ms(t_loop));
        println!("  flat {flat_ty} loop, no %     {:>9.2} ms", ms(t_flat));
        if precision == subgram::Precision::Single {
            println!("  flat f64 loop, no %      {:>9.2} ms", ms(t_flat64));
        }
        println!("  engine (.lsys)           {:>9.2} ms", ms(t_engine));
        println!("  ratio engine/loop %      {:>9.2}", ratio(t_loop));
        println!("  ratio engine/flat {flat_ty}    {:>9.2}", ratio(t_flat));
        if precision == subgram::Precision::Single {
            println!("  ratio engine/flat f64    {:>9.2}", ratio(t_flat64));
        }
    }

    if args.iter().any(|a| a == "--chaikin-only") {
        return;
    }
    threads(&src, runs);

    // A signal S travels right through a sea of A modules: S moves one
    // place per step, and every module looks at both neighbours.
    let n = 1_000_000;
    let mut word = String::from("Axiom: S");
    for _ in 1..n {
        word.push_str(" A");
    }
    let src = format!(
        "module A; module S;\nderivation length: 5;\n{word};\n\
         S() < A() > A() -> S\nA() < S() > A() -> A\nA() < A() > S() -> A\n"
    );
    let loaded = subgram::load_str("signal.lsys", &src, &[]).expect("loads");
    let (t, d) = best_of(runs, || {
        subgram::derive(&loaded.program, DeriveOptions::default()).expect("derives")
    });
    assert_eq!(d.word.len(), n);
    let modules = n as f64 * 5.0;
    println!("context-sensitive signal, {n} modules x 5 steps, best of {runs}");
    println!(
        "  {:>9.2} ms, {:.1} million modules/s on one core",
        t.as_secs_f64() * 1e3,
        modules / t.as_secs_f64() / 1e6
    );

    // Interpreted bodies with loops, on a word with a branch after every
    // module: the right context skips it to find the next A.
    let (n, runs) = (50_000, 5);
    let mut word = String::from("Axiom:");
    for i in 0..n {
        word.push_str(&format!(" A({i}) [B]"));
    }
    let src = format!(
        "module A(float); module B;\nangle: 90;\nderivation length: 5;\n{word};\n\
         A(x) > A(y) : {{ float s = 0; for (int i = 0; i < 20; i++) s += i * 0.5; \
         produce A(0.5 * x + 0.5 * y + s * 0.0); }}\n"
    );
    let loaded = subgram::load_str("branches.lsys", &src, &[]).expect("loads");
    let (t, d) = best_of(runs, || {
        subgram::derive(&loaded.program, DeriveOptions::default()).expect("derives")
    });
    assert_eq!(d.word.len(), 4 * n); // A [ B ]
    let modules = n as f64 * 4.0 * 5.0;
    println!("interpreted bodies with loops, branches skipped by contexts, {n} x 4 modules x 5 steps, best of {runs}");
    println!(
        "  {:>9.2} ms, {:.1} million modules/s on one core",
        t.as_secs_f64() * 1e3,
        modules / t.as_secs_f64() / 1e6
    );
}

/// Section 2: the Chaikin run `src` in a pool of 1 and of 2 threads,
/// alternating run by run so that both see the same load; best of `runs`.
fn threads(src: &str, runs: usize) {
    let pools: Vec<rayon::ThreadPool> = [1, 2]
        .iter()
        .map(|&k| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(k)
                .build()
                .expect("a thread pool")
        })
        .collect();
    for precision in [subgram::Precision::Single, subgram::Precision::Double] {
        let loaded = subgram::load_str_with("bench.lsys", src, &[], precision).expect("loads");
        let label = format!("chaikin, {precision:?} precision");
        on_pools(&label, &loaded.program, &pools, runs);
    }
    flat_step_on_pools(&pools, runs);
    // The general path (issue 16, item 6): branching words, which the
    // stencil fast path does not take. A plant whose rule is a stencil
    // (bench_solid's), and the guarded branching system of bench_body,
    // whose body is compiled to closures; 17 and 11 steps, about a
    // million modules at the end.
    let plant = "module A(float, float);\nderivation length: 17;\n\
        Axiom: SetColor(2) A(1, 0.05);\nproduction:\n\
        A(l, w) -> SetWidth(w) F(l) RollR(137.5) SB() Left(32) A(l*0.78, w*0.7) EB() \
        Right(18) A(l*0.86, w*0.8)\n";
    let guarded = "module A(float, float);\nderivation length: 11;\nAxiom: A(1, 1);\n\
        production:\nA(l, w) : { if (l > 0.01) produce F(l) SB() Left(30) A(l * 0.7, w * 0.7) EB() \
        SB() Right(25) A(l * 0.6, w * 0.7) EB() A(l * 0.9, w * 0.9); }\n";
    // A bracketed plant without parameters (lpfg's ABOP bush), 9 steps.
    let bush = "angle: 22.5;\nderivation length: 9;\nAxiom: X;\n\
        X -> F-[[X]+X]+F[+FX]-X\nF -> FF\n";
    for (label, src) in [
        ("branching plant (stencil)", plant),
        ("guarded branching (compiled body)", guarded),
        ("bush, no parameters", bush),
    ] {
        let loaded = subgram::load_str("bench.lsys", src, &[]).expect("loads");
        on_pools(label, &loaded.program, &pools, runs);
    }
}

/// The reference for the last Chaikin step on two threads: the tight flat
/// `f64` loop's last step (512,000 -> 1,024,000 points) written into fresh
/// memory as the engine's step writes its new word (room asked for in huge
/// pages, touched first by the writes), in parts of 65,536 points on the
/// pool, in each pool alternating; its result is checked against
/// `chaikin_flat`. What a second core gives a step bound by writing fresh
/// memory on this machine.
fn flat_step_on_pools(pools: &[rayon::ThreadPool], runs: usize) {
    use std::time::{Duration, Instant};
    const PART: usize = 65_536;
    let start: Vec<f64> = polygon(1000).iter().flat_map(|p| [p.x, p.y]).collect();
    let src = chaikin_flat::<f64>(&start, 9);
    let step = |src: &[f64]| -> Vec<f64> {
        use rayon::prelude::*;
        let n = src.len() / 2;
        let len = 4 * n;
        let mut dst: Vec<f64> = Vec::with_capacity(len);
        #[cfg(target_os = "linux")]
        // SAFETY: the range is `dst`'s own allocation; MADV_HUGEPAGE never
        // changes memory's contents.
        unsafe {
            libc::madvise(dst.as_mut_ptr().cast(), len * 8, libc::MADV_HUGEPAGE);
        }
        let room = &mut dst.spare_capacity_mut()[..len];
        room.par_chunks_mut(4 * PART)
            .enumerate()
            .for_each(|(k, out)| {
                for (j, o) in out.chunks_exact_mut(4).enumerate() {
                    let i = k * PART + j;
                    let l = if i == 0 { n - 1 } else { i - 1 };
                    let r = if i + 1 == n { 0 } else { i + 1 };
                    let (pl, pv, pr) = (&src[2 * l..], &src[2 * i..], &src[2 * r..]);
                    o[0].write(pl[0] * 0.25 + pv[0] * 0.75);
                    o[1].write(pl[1] * 0.25 + pv[1] * 0.75);
                    o[2].write(pv[0] * 0.75 + pr[0] * 0.25);
                    o[3].write(pv[1] * 0.75 + pr[1] * 0.25);
                }
            });
        // SAFETY: the parts cover `room`, and every element of each part
        // was written above.
        unsafe { dst.set_len(len) };
        dst
    };
    assert!(step(&src) == chaikin_flat::<f64>(&start, 10));
    let mut times: [Vec<Duration>; 2] = Default::default();
    for _ in 0..runs {
        for (k, pool) in pools.iter().enumerate() {
            let t = Instant::now();
            let out = pool.install(|| step(&src));
            times[k].push(t.elapsed());
            drop(out);
        }
    }
    for t in &mut times {
        t.sort();
    }
    let ms = |t: Duration| t.as_secs_f64() * 1e3;
    let (b, m) = (|k: usize| times[k][0], |k: usize| times[k][runs / 2]);
    println!(
        "reference: the flat f64 loop's last step {} -> {} points into fresh memory, {runs} runs alternating, 1 vs 2 threads",
        src.len() / 2,
        src.len()
    );
    println!(
        "  best {:>7.2} / {:>7.2} ms (speedup {:.2}), median {:>7.2} / {:>7.2} ms (speedup {:.2})",
        ms(b(0)),
        ms(b(1)),
        b(0).as_secs_f64() / b(1).as_secs_f64(),
        ms(m(0)),
        ms(m(1)),
        m(0).as_secs_f64() / m(1).as_secs_f64()
    );
}

/// The last step and the whole derivation of `program` in each pool (one
/// thread, two), alternating, best of `runs`, with the speedup; the words
/// are checked to be the same to the bit.
fn on_pools(label: &str, program: &subgram::Program, pools: &[rayon::ThreadPool], runs: usize) {
    use std::time::{Duration, Instant};
    // Every run's time, per pool: the best and the median are printed (on
    // a shared machine the best of one pool and the best of the other may
    // come from minutes of different speed; the median of interleaved
    // runs is steadier).
    let (mut last, mut whole): ([Vec<Duration>; 2], [Vec<Duration>; 2]) = Default::default();
    let mut words: Vec<subgram::Word> = Vec::new();
    let mut before = 0;
    for _ in 0..runs {
        for (k, pool) in pools.iter().enumerate() {
            pool.install(|| {
                // The last step alone: the steps before it untimed.
                let mut d =
                    subgram::Derivation::new(program, DeriveOptions::default()).expect("starts");
                while d.step + 1 < d.length {
                    d.next_step().expect("steps");
                }
                before = d.word.len();
                let t = Instant::now();
                d.next_step().expect("steps");
                last[k].push(t.elapsed());
                let t = Instant::now();
                let all = subgram::derive(program, DeriveOptions::default()).expect("derives");
                whole[k].push(t.elapsed());
                assert_eq!(d.word.len(), all.word.len());
                if words.len() < 2 {
                    words.push(all.word);
                }
            });
        }
    }
    // The same word, to the bit, from either pool.
    let bits =
        |w: &subgram::Word| -> Vec<u64> { w.all_slots().iter().map(|x| x.to_bits()).collect() };
    assert_eq!(words[0].syms(), words[1].syms());
    assert_eq!(bits(&words[0]), bits(&words[1]));
    let n = words[0].len();
    let ms = |t: Duration| t.as_secs_f64() * 1e3;
    // (best, median) of a pool's runs.
    let stats = |times: &mut Vec<Duration>| {
        times.sort();
        (times[0], times[times.len() / 2])
    };
    println!("{label}, {runs} runs alternating, 1 vs 2 threads: best, then median");
    for (name, times) in [
        (format!("last step {before} -> {n} modules"), &mut last),
        ("whole run".to_string(), &mut whole),
    ] {
        let [(b1, m1), (b2, m2)] = [stats(&mut times[0]), stats(&mut times[1])];
        println!(
            "  {name:<36} best {:>7.2} / {:>7.2} ms (speedup {:.2}), median {:>7.2} / {:>7.2} ms (speedup {:.2})",
            ms(b1),
            ms(b2),
            b1.as_secs_f64() / b2.as_secs_f64(),
            ms(m1),
            ms(m2),
            m1.as_secs_f64() / m2.as_secs_f64()
        );
    }
}
