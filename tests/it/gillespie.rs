//! Gillespie groups (manual 7.2): one reaction per step, chosen with
//! probability proportional to its propensity, and the waiting time τ.
//! Expected values are known counts, binomial and exponential bounds
//! computed in each test, and, for the first step, the exact numbers of
//! lpfg's Gillespie generator (`erand48` from the state {0x330E, 0, 0},
//! whose first outputs gcc printed as 0.17082803610628972 and
//! 0.74990198048496381; see `src/lang/random.rs`).
#![allow(clippy::excessive_precision)] // gcc's "%.17g" output, as printed

use subgram::{DeriveOptions, Value};

use crate::support::*;

fn run(src: &str, opts: DeriveOptions) -> (String, Vec<Value>) {
    let l = load_text(src);
    let d = derive(&l, opts);
    (text(&l, &d), d.env.globals.clone())
}

fn float(v: &Value) -> f64 {
    match v {
        Value::Float(f) => *f,
        Value::Int(i) => *i as f64,
        other => panic!("{other:?}"),
    }
}

/// One kind of reaction: each step is exactly one reaction, so after n
/// steps n units have moved, whatever the seed.
#[test]
fn each_step_is_exactly_one_reaction() {
    let src = "module Pool(int, int);\nderivation length: 37;\nStart: { UseGroup(1); }\n\
               Axiom: Pool(100, 0);\nggroup 1:\n\
               Pool(a, b) : { propensity 0.25 * a produce Pool(a - 1, b + 1); }\nendgroup\n";
    for seed in [None, Some(1), Some(99)] {
        let opts = DeriveOptions {
            seed,
            ..DeriveOptions::default()
        };
        assert_eq!(run(src, opts).0, "Pool(63, 37)");
    }
    // Several places: one of them reacts per step, so the counters sum to
    // the number of steps.
    let src = "module A(int);\nderivation length: 25;\nStart: { UseGroup(2); }\n\
               Axiom: A(0) A(0) A(0) A(0);\nggroup 2:\n\
               A(c) : { propensity 1 produce A(c + 1); }\n";
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    let total: i64 = d
        .word
        .modules(&l.program.alphabet, &l.program.structs)
        .map(|(_, ps)| match ps[0] {
            Value::Int(c) => c,
            ref other => panic!("{other:?}"),
        })
        .sum();
    assert_eq!(total, 25);
}

const TWO_REACTIONS: &str = "module S(int, int);\ndouble t;\n\
    Start: { UseGroup(1); }\nEndEach: { t = GillespieTime(); }\n\
    Axiom: S(0, 0);\nggroup 1:\n\
    S(l, r) : {\n  propensity 1 produce S(l + 1, r);\n  propensity 3 produce S(l, r + 1);\n}\n";

/// Propensities 1 and 3: the first reaction happens with probability
/// 1/4. Over n = 4000 steps its count is binomial, mean n/4 = 1000,
/// standard deviation sqrt(n · 1/4 · 3/4) ≈ 27.4; each seed's count must
/// lie within 5 standard deviations. The total propensity is 4 at every
/// step, so the Gillespie time is a sum of n exponential waits of mean
/// 1/4: mean n/4 = 1000, standard deviation sqrt(n)/4 ≈ 15.8, also checked
/// within 5 standard deviations.
#[test]
fn reactions_are_chosen_in_proportion_to_their_propensities() {
    let n = 4000u64;
    let sd_count = (n as f64 * 0.25 * 0.75).sqrt();
    let sd_time = (n as f64).sqrt() / 4.0;
    let mut lefts = Vec::new();
    for seed in [None, Some(1), Some(2), Some(3), Some(4)] {
        let opts = DeriveOptions {
            seed,
            ..DeriveOptions::default().with_steps(n)
        };
        let l = load_text(TWO_REACTIONS);
        let d = derive(&l, opts);
        let ps: Vec<i64> = d
            .word
            .modules(&l.program.alphabet, &l.program.structs)
            .flat_map(|(_, ps)| ps)
            .map(|v| float(&v) as i64)
            .collect();
        let (left, right) = (ps[0], ps[1]);
        assert_eq!(left + right, n as i64, "one reaction per step");
        assert!(
            (left as f64 - n as f64 / 4.0).abs() < 5.0 * sd_count,
            "seed {seed:?}: {left} of {n}"
        );
        let t = float(&d.env.globals[0]);
        assert!(
            (t - n as f64 / 4.0).abs() < 5.0 * sd_time,
            "seed {seed:?}: time {t}"
        );
        lefts.push(left);
    }
    // The seeds give different runs.
    lefts.sort();
    lefts.dedup();
    assert!(lefts.len() > 1, "{lefts:?}");
}

/// The first step, by hand: p = 1 + 3 = 4; χ₁ = 0.17082803610628972, so
/// p·χ₁ ≈ 0.683 is reached by the first reaction's propensity 1: S(1, 0).
/// τ = −ln(1 − χ₂)/p with χ₂ = 0.74990198048496381.
#[test]
fn the_first_step_follows_gillespies_method_exactly() {
    let (word, globals) = run(TWO_REACTIONS, DeriveOptions::default().with_steps(1));
    assert_eq!(word, "S(1, 0)");
    let tau = -(1.0 - 0.74990198048496381f64).ln() / 4.0;
    assert_eq!(float(&globals[0]), tau);
    // lpfg's τ is positive: the manual's ln(1 − χ)/p with the sign that
    // makes time advance.
    assert!(tau > 0.0);
}

/// Contexts are matched as in any step; a module whose productions give
/// no propensity (or zero) never reacts, and with no propensity at all the
/// word and the time stand still.
/// lpfg gives the first word too (A() C() B()).
#[test]
fn contexts_and_zero_propensities() {
    let src = "module A; module B; module C;\nderivation length: 1;\nStart: { UseGroup(1); }\n\
               Axiom: A B B;\nggroup 1:\nA < B : { propensity 1 produce C; }\n\
               B : { propensity 0 produce A; }\n";
    // Only the B after A has a positive propensity.
    assert_eq!(run(src, DeriveOptions::default()).0, "A C B");
    let src = "module A(int);\ndouble t;\nderivation length: 3;\nStart: { UseGroup(1); }\n\
               EndEach: { t = GillespieTime(); }\n\
               Axiom: A(0);\nggroup 1:\nA(n) : { propensity 0 produce A(n + 1); }\n";
    let (word, globals) = run(src, DeriveOptions::default());
    assert_eq!(word, "A(0)");
    assert_eq!(float(&globals[0]), 0.0);
}

/// Modules after a `Cut` in its branch do not react; a group chosen with
/// UseGroup in StartEach alternates with a regular one. lpfg gives both
/// words (SB() Cut() A(0) EB() A(1), and A(10)).
#[test]
fn cut_branches_and_alternating_groups() {
    let src = "module A(int);\nderivation length: 1;\nStart: { UseGroup(1); }\n\
               Axiom: SB() Cut() A(0) EB() A(0);\nggroup 1:\n\
               A(n) : { propensity 1 produce A(n + 1); }\n";
    assert_eq!(run(src, DeriveOptions::default()).0, "SB Cut A(0) EB A(1)");
    // Odd steps: the Gillespie group 1 (one reaction); even steps: the
    // regular group 2 doubles every counter.
    let src = "module A(int);\nint n;\nderivation length: 4;\nStart: { n = 0; }\n\
               StartEach: { n = n + 1; UseGroup(n % 2 == 1 ? 1 : 2); }\n\
               Axiom: A(1);\nggroup 1:\nA(c) : { propensity 1 produce A(c + 1); }\n\
               endgroup\ngroup 2:\nA(c) : { produce A(2 * c); }\n";
    // 1 -> 2 -> 4 -> 5 -> 10
    assert_eq!(run(src, DeriveOptions::default()).0, "A(10)");
}

/// Programs run by lpfg (vlab 9bf820d, built headless by
/// ../shared/tools/lpfg) give these words, to the last printed digit:
/// three places with two reactions each, several productions of a module
/// with contexts, and a run seeded with `SeedGillespie` whose reactions
/// record `GillespieTime()` in the word.
#[test]
fn words_agree_with_lpfg() {
    let three = "#include <lpfgall.h>\nmodule S(int, int);\nderivation length: 20;\n\
        Start: { UseGroup(1); }\nAxiom: S(0, 0) S(0, 0) S(5, 5);\nggroup 1:\n\
        S(l, r) :\n{\n  propensity 1 + 0.1 * r produce S(l + 1, r);\n\
          propensity 3 produce S(l, r + 1);\n}\nendgroup\n";
    assert_eq!(
        run(three, DeriveOptions::default()).0,
        "S(2, 3) S(2, 5) S(8, 10)"
    );
    // Every matching production of a module adds its reactions, contexts
    // included.
    let several = "#include <lpfgall.h>\nmodule A(int);\nmodule B(int);\n\
        derivation length: 6;\nStart: { UseGroup(1); }\nAxiom: A(0) B(0) A(0);\n\
        ggroup 1:\nA(n) : { propensity 1 produce A(n + 1); }\n\
        A(n) : { propensity 2 produce A(n + 10); }\n\
        B(n) > A(m) : { propensity 0.5 produce B(n + 100); }\n\
        B(n) : { propensity 0.25 produce B(n + 1000) A(7); }\nendgroup\n";
    assert_eq!(
        run(several, DeriveOptions::default()).0,
        "A(11) B(100) A(12)"
    );
    let timed = "#include <lpfgall.h>\nmodule S(int, int);\nmodule T(double);\ndouble t;\n\
        derivation length: 30;\nStart: { UseGroup(1); SeedGillespie(11); }\n\
        EndEach: { t = GillespieTime(); }\nAxiom: S(0, 0) T(0);\nggroup 1:\n\
        S(l, r) :\n{\n  propensity 0.7 produce S(l + 1, r) T(GillespieTime());\n\
          propensity 2.5 produce S(l, r + 1);\n}\n\
        T(x) : { propensity 0.2 produce T(x + 1); }\nendgroup\n";
    let l = load_text(timed);
    let d = derive(&l, DeriveOptions::default());
    let params: Vec<f64> = d
        .word
        .modules(&l.program.alphabet, &l.program.structs)
        .flat_map(|(_, ps)| ps)
        .map(|v| float(&v))
        .collect();
    let lpfg = [
        8.0,
        16.0,
        6.918141504050389,
        5.705261415355819,
        4.617231955235017,
        2.6557186817432186,
        4.291484576947559,
        1.1384799482112737,
        0.012506588086982729,
        0.0,
        0.0,
    ];
    assert_eq!(params, lpfg);
}
