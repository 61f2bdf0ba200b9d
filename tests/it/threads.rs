//! Large uniform stencil steps run on rayon's pool (issue 16, item 6): the
//! same word, to the bit, and the same error, whatever the number of
//! threads. A step splits its word into tasks from 65,536 modules on, so
//! the runs here reach 98,304 modules (6 · 2^14), whose last step is cut
//! into tasks of 16,384 modules and a shorter last one, which neither two
//! nor three threads share evenly.

use glam::{DVec3, Vec2};
use subgram::{Derivation, DeriveOptions, Precision, Program, Word};

use crate::support::*;

/// 6 · 2^15 points: the last step reads 98,304 modules.
const STEPS: u64 = 15;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
}

fn bits(w: &Word) -> Vec<u64> {
    w.all_slots().iter().map(|x| x.to_bits()).collect()
}

/// The word after `STEPS` steps in a pool of 1, 2 and 3 threads: all three
/// the same to the bit; returns the first.
fn same_in_every_pool(program: &Program) -> Word {
    let words: Vec<Word> = [1, 2, 3]
        .iter()
        .map(|&k| {
            pool(k).install(|| {
                let opts = DeriveOptions::default().with_steps(STEPS);
                subgram::derive(program, opts).expect("derives").word
            })
        })
        .collect();
    for (k, w) in words.iter().enumerate().skip(1) {
        assert_eq!(w.syms(), words[0].syms(), "{} threads", k + 1);
        assert!(bits(w) == bits(&words[0]), "{} threads", k + 1);
    }
    words.into_iter().next().expect("three words")
}

/// Runs `program` to its last step, replaces the slots of module `at` by
/// NaN before that step, and returns the step's error message, in a pool
/// of `threads`.
fn error_with_nan_at(program: &Program, at: usize, threads: usize) -> String {
    pool(threads).install(|| {
        let opts = DeriveOptions::default().with_steps(STEPS);
        let mut d = Derivation::new(program, opts).expect("starts");
        while d.step + 1 < STEPS {
            d.next_step().expect("steps");
        }
        assert!(d.word.len() >= 65_536, "{} modules", d.word.len());
        let mut w = Word::new();
        for i in 0..d.word.len() {
            let nan = vec![f64::NAN; d.word.data(i).len()];
            let slots = if i == at { &nan[..] } else { d.word.data(i) };
            w.push_raw(d.word.sym(i), slots);
        }
        d.word = w;
        d.next_step().expect_err("a NaN spreads").message
    })
}

/// The error of a NaN is the same in every pool, wherever it sits: at the
/// ring's seam, in the first task, in the middle of a task, in the last
/// (short) one.
fn same_error_in_every_pool(program: &Program) {
    for at in [0, 5, 40_000, 98_300, 98_303] {
        let one = error_with_nan_at(program, at, 1);
        assert!(one.contains("NaN or infinite"), "{one}");
        assert!(one.contains(&format!("at step {STEPS}")), "{one}");
        for k in [2, 3] {
            assert_eq!(error_with_nan_at(program, at, k), one, "NaN at {at}");
        }
    }
}

/// Closed Chaikin (production 13 of paper 002) in lpfg's single precision.
/// Besides agreeing across pools, the word is the one a loop over `f32`
/// points computes: lpfg computes `V2f` in `float`, each product and sum
/// rounded, and the rule's sums run left to right.
#[test]
fn chaikin_13_is_the_same_word_for_any_number_of_threads() {
    let l = load(&lsys("curves/chaikin-13.lsys"));
    let word = same_in_every_pool(&l.program);
    let mut p: Vec<Vec2> = hexagon().iter().map(|v| v.as_vec2()).collect();
    for _ in 0..STEPS {
        let n = p.len();
        p = (0..n)
            .flat_map(|i| {
                let (vl, v, vr) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
                [vl * 0.25 + v * 0.75, v * 0.75 + vr * 0.25]
            })
            .collect();
    }
    assert_eq!(word.len(), 6 << STEPS);
    let want: Vec<u64> = p
        .iter()
        .flat_map(|v| [(v.x as f64).to_bits(), (v.y as f64).to_bits()])
        .collect();
    assert!(bits(&word) == want);
    same_error_in_every_pool(&l.program);
}

/// Closed Chaikin on `V3f` points in double precision. The hexagon's
/// coordinates are small integers and the weights 1/4 and 3/4, so after 15
/// steps every coordinate is a multiple of 2^-30 below 8 in magnitude:
/// about 33 significant bits, which a double holds exactly. Any correct
/// computation, in any order, therefore gives these very bits.
#[test]
fn chaikin_in_3d_double_is_the_same_word_for_any_number_of_threads() {
    let hex: Vec<DVec3> = hexagon()
        .iter()
        .enumerate()
        .map(|(i, v)| DVec3::new(v.x, v.y, (i % 3) as f64 - 1.0))
        .collect();
    let axiom: Vec<String> = hex
        .iter()
        .map(|v| format!("P(V3f({}, {}, {}))", v.x, v.y, v.z))
        .collect();
    let src = format!(
        "module P(V3f);\nring L-system: 1;\nderivation length: 1;\nAxiom: {};\n\
         P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)\n",
        axiom.join(" ")
    );
    let l = subgram::load_str_with("chaikin3.lsys", &src, &[], Precision::Double).expect("loads");
    let word = same_in_every_pool(&l.program);
    let mut p = hex;
    for _ in 0..STEPS {
        let n = p.len();
        p = (0..n)
            .flat_map(|i| {
                let (vl, v, vr) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
                [(vl + 3.0 * v) / 4.0, (3.0 * v + vr) / 4.0]
            })
            .collect();
    }
    assert_eq!(word.len(), 6 << STEPS);
    let want: Vec<u64> = p
        .iter()
        .flat_map(|v| v.to_array().map(f64::to_bits))
        .collect();
    assert!(bits(&word) == want);
    same_error_in_every_pool(&l.program);
}

/// Steps of the binary plant below: the last one reads 131,066 modules,
/// past the size from which the general path cuts a step into parts.
const PLANT_STEPS: u64 = 15;

/// A branching plant whose rule is a stencil (the general path, since the
/// word has branches), as `bench_solid --whole` draws it.
const PLANT: &str = "module A(float, float);\nderivation length: 1;\n\
    Axiom: SetColor(2) A(1, 0.05);\nproduction:\n\
    A(l, w) -> SetWidth(w) F(l) RollR(137.5) SB() Left(32) A(l*0.78, w*0.7) EB() \
    Right(18) A(l*0.86, w*0.8)\n";

/// The plant's word after `steps` steps, computed here from the rule: a
/// module's name and its parameters, each product computed in double and
/// rounded to single precision, as C computes `l*0.78` for a `float l`.
fn plant_by_hand(steps: u64) -> Vec<(&'static str, Vec<f64>)> {
    fn grow(l: f32, w: f32, k: u64, out: &mut Vec<(&'static str, Vec<f64>)>) {
        if k == 0 {
            out.push(("A", vec![l as f64, w as f64]));
            return;
        }
        let (l, w) = (l as f64, w as f64);
        out.push(("SetWidth", vec![w]));
        out.push(("F", vec![l]));
        out.push(("RollR", vec![137.5]));
        out.push(("SB", vec![]));
        out.push(("Left", vec![32.0]));
        grow((l * 0.78) as f32, (w * 0.7) as f32, k - 1, out);
        out.push(("EB", vec![]));
        out.push(("Right", vec![18.0]));
        grow((l * 0.86) as f32, (w * 0.8) as f32, k - 1, out);
    }
    // An `int` parameter's slot holds the integer's bits.
    let mut out = vec![("SetColor", vec![f64::from_bits(2)])];
    grow(1.0, 0.05, steps, &mut out);
    out
}

#[test]
fn a_branching_plant_is_the_same_word_for_any_number_of_threads() {
    let l = load_text(PLANT);
    let words: Vec<Word> = [1, 2, 3]
        .iter()
        .map(|&k| {
            pool(k).install(|| {
                let opts = DeriveOptions::default().with_steps(PLANT_STEPS);
                subgram::derive(&l.program, opts).expect("derives").word
            })
        })
        .collect();
    let want = plant_by_hand(PLANT_STEPS);
    assert_eq!(want.len(), 262_138);
    for (k, w) in words.iter().enumerate() {
        assert_eq!(w.len(), want.len(), "{} threads", k + 1);
        for (i, (name, slots)) in want.iter().enumerate() {
            let got: Vec<u64> = w.data(i).iter().map(|x| x.to_bits()).collect();
            let exp: Vec<u64> = slots.iter().map(|x| x.to_bits()).collect();
            assert!(
                l.program.alphabet.name(w.sym(i)) == *name && got == exp,
                "module {i} with {} threads: {} {:?}, want {name} {slots:?}",
                k + 1,
                l.program.alphabet.name(w.sym(i)),
                w.data(i)
            );
        }
    }
}

/// The error of a step run in parts is the one the step run on one thread
/// gives: the first failing module in the word's order, named with its
/// production, whichever part it falls in and whatever fails after it.
#[test]
fn a_branching_step_fails_alike_for_any_number_of_threads() {
    // A NaN in an `A` of the plant's word: the first (in the first part),
    // one a third of the way, the last (in the last part), and two at once.
    let l = load_text(PLANT);
    let fail = |nth: &[usize], threads: usize| {
        pool(threads).install(|| {
            let opts = DeriveOptions::default().with_steps(PLANT_STEPS);
            let mut d = Derivation::new(&l.program, opts).expect("starts");
            while d.step + 1 < PLANT_STEPS {
                d.next_step().expect("steps");
            }
            let n = d.word.len();
            assert!(n > 131_000, "{n} modules");
            let a = l.program.alphabet.lookup("A").expect("A");
            let mut w = Word::new();
            let mut seen = 0;
            for i in 0..n {
                let mut slots = d.word.data(i).to_vec();
                if d.word.sym(i) == a {
                    if nth.contains(&seen) {
                        slots[1] = f64::NAN;
                    }
                    seen += 1;
                }
                w.push_raw(d.word.sym(i), &slots);
            }
            assert_eq!(seen, 1 << (PLANT_STEPS - 1));
            d.word = w;
            d.next_step().expect_err("a NaN spreads").message
        })
    };
    let last = (1 << (PLANT_STEPS - 1)) - 1;
    for nth in [&[0][..], &[last / 3], &[last], &[1, last]] {
        let one = fail(nth, 1);
        assert!(one.contains("NaN or infinite"), "{one}");
        for k in [2, 3] {
            assert_eq!(fail(nth, k), one, "NaN in the A numbered {nth:?}");
        }
    }
    // An integer division by zero in a compiled body, late in the word,
    // and a word that grows past its limit.
    let div = "module A(int);\nderivation length: 18;\nAxiom: A(0);\nproduction:\n\
        A(i) : { if (i == 100000) produce A(1 / (i - i)); \
        else produce A(2 * i) SB() A(2 * i + 1) EB(); }\n";
    let l = load_text(div);
    let fail = |threads: usize, max: usize| {
        pool(threads).install(|| {
            let opts = DeriveOptions {
                max_modules: max,
                ..DeriveOptions::default()
            };
            let e = subgram::derive(&l.program, opts).expect_err("fails");
            l.error(e).to_string()
        })
    };
    for max in [10_000_000, 200_000] {
        let one = fail(1, max);
        for k in [2, 3] {
            assert_eq!(fail(k, max), one);
        }
        if max == 200_000 {
            assert!(one.contains("200000"), "{one}");
        } else {
            assert!(one.contains("integer division by zero"), "{one}");
        }
    }
}

/// A Koch curve whose rules rewrite the overloaded `F(x)`, one of them
/// with a right context, in a word without branches: the stencil fast
/// path's steps from 65,536 modules on run in parts (the last one reads
/// 98,304 modules and writes 393,216). In pools of 1, 2 and 3 threads the
/// word is the one computed here from the rules: an `F` followed by
/// `Right(a)` takes the first rule, every other `F` the second; `x/3` and
/// `a + 1` are single-precision operations. As a ring, the last `F`'s
/// right context is the first module.
#[test]
fn a_koch_curve_with_contexts_is_the_same_word_for_any_number_of_threads() {
    let rules = "F(x) > Right(a) -> F(x/3) Left(60) F(x/3) Right(a + 1) F(x/3) Left(60) F(x/3)\n\
                 F(x) -> F(x/3) Left(60) F(x/3) Right(120) F(x/3) Left(60) F(x/3)\n";
    for ring in [false, true] {
        let src = format!(
            "{}derivation length: 8;\nAxiom: Right(120) F(1) Right(120) F(1) Right(120) F(1);\n{rules}",
            if ring { "ring L-system: 1;\n" } else { "" }
        );
        let l = load_text(&src);
        assert!(l.program.rules.iter().all(|r| r.stencil.is_some()));
        let want = koch_by_hand(ring);
        assert_eq!(want.len(), 393_216);
        // The wrap matters: the ring's word is not the open one's.
        assert!(want != koch_by_hand(!ring));
        for threads in [1, 2, 3] {
            let w = pool(threads).install(|| {
                subgram::derive(&l.program, DeriveOptions::default())
                    .expect("derives")
                    .word
            });
            assert_eq!(w.len(), want.len(), "{threads} threads, ring {ring}");
            for (i, &(name, x)) in want.iter().enumerate() {
                assert!(
                    l.program.alphabet.name(w.sym(i)) == name
                        && w.data(i).len() == 1
                        && w.data(i)[0].to_bits() == (x as f64).to_bits(),
                    "module {i} with {threads} threads, ring {ring}: {} {:?}, want {name}({x})",
                    l.program.alphabet.name(w.sym(i)),
                    w.data(i)
                );
            }
        }
    }
}

/// The Koch curve of the test above after 8 steps, computed from its rules.
fn koch_by_hand(ring: bool) -> Vec<(&'static str, f32)> {
    let mut want: Vec<(&str, f32)> = [("Right", 120.0), ("F", 1.0)].repeat(3);
    for _ in 0..8 {
        let mut next = Vec::with_capacity(want.len() * 4);
        for (i, &(name, x)) in want.iter().enumerate() {
            if name != "F" {
                next.push((name, x));
                continue;
            }
            let third = (x as f64 / 3.0) as f32;
            let right = if ring {
                want.get((i + 1) % want.len())
            } else {
                want.get(i + 1)
            };
            let turn = match right {
                Some(&("Right", a)) => a + 1.0,
                _ => 120.0,
            };
            next.extend([
                ("F", third),
                ("Left", 60.0),
                ("F", third),
                ("Right", turn),
                ("F", third),
                ("Left", 60.0),
                ("F", third),
            ]);
        }
        want = next;
    }
    want
}
