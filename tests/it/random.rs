//! Random numbers in programs: lpfg's `ran`/`sran`, C's `rand`/`srand`/
//! `RAND_MAX` and `drand48`, and `--seed`. The expected numbers were
//! printed by a C program compiled with gcc against glibc 2.36 on this
//! machine (`srand(42); rand()`, …; for `ran`, `erand48` on lpfg's state
//! `{0x330E, 0, 0}`, which lpfg's `ran` starts from), as in
//! `src/lang/random.rs`'s unit tests.
#![allow(clippy::excessive_precision)] // gcc's "%.17g" output, as printed

use std::process::Command;

use subgram::{DeriveOptions, Value};

use crate::support::*;

/// The parameters of the final word, as numbers.
fn numbers(src: &str, opts: DeriveOptions) -> Vec<f64> {
    let l = load_text(src);
    let d = derive(&l, opts);
    d.word
        .modules(&l.program.alphabet, &l.program.structs)
        .flat_map(|(_, ps)| ps)
        .map(|v| match v {
            Value::Int(i) => i as f64,
            Value::Float(f) => f,
            other => panic!("{other:?}"),
        })
        .collect()
}

const RAND: &str = "module R(int);\nAxiom: R(rand()) R(rand()) R(RAND_MAX);\n";

#[test]
fn rand_starts_as_glibcs_and_follows_srand() {
    // glibc's rand() before any srand() is srand(1)'s sequence.
    assert_eq!(
        numbers(RAND, DeriveOptions::default()),
        [1804289383.0, 846930886.0, 2147483647.0]
    );
    let seeded = format!("Start: {{ srand(42); }}\n{RAND}");
    assert_eq!(
        numbers(&seeded, DeriveOptions::default()),
        [71876166.0, 708592740.0, 2147483647.0]
    );
    // --seed 42 is srand(42) before Start.
    assert_eq!(
        numbers(RAND, DeriveOptions::default().with_seed(42)),
        [71876166.0, 708592740.0, 2147483647.0]
    );
}

#[test]
fn ran_is_lpfgs_and_drand48_is_glibcs() {
    let src = "module X(double);\n\
               Axiom: X(ran(1)) X(ran(10)) X(drand48());\n";
    assert_eq!(
        numbers(src, DeriveOptions::default()),
        [
            0.17082803610628972,
            10.0 * 0.74990198048496381,
            // glibc's drand48 state starts at 0: 0xB / 2^48.
            11.0 / 281474976710656.0,
        ]
    );
    let src = "module X(double);\nStart: { sran(5); srand48(7); }\n\
               Axiom: X(ran(1)) X(drand48()) X(lrand48());\n";
    assert_eq!(
        numbers(src, DeriveOptions::default()),
        [0.000447906670316911, 0.2664441967654092, 1464659504.0]
    );
}

/// A stochastic plant: each apex chooses at random between two
/// successors, so the word depends on every number drawn.
const STOCHASTIC: &str = "module A; module B;\nderivation length: 12;\nAxiom: A;\n\
    A : { if (ran(1) < 0.5) produce A B; else produce B A SB() A EB(); }\n\
    interpretation:\nB : { produce F(1) Left(25); }\n";

fn word(src: &str, opts: DeriveOptions) -> String {
    let l = load_text(src);
    let d = derive(&l, opts);
    text(&l, &d)
}

#[test]
fn a_seed_makes_runs_reproducible() {
    let unseeded = word(STOCHASTIC, DeriveOptions::default());
    assert_eq!(unseeded, word(STOCHASTIC, DeriveOptions::default()));
    let a = word(STOCHASTIC, DeriveOptions::default().with_seed(1));
    assert_eq!(a, word(STOCHASTIC, DeriveOptions::default().with_seed(1)));
    let b = word(STOCHASTIC, DeriveOptions::default().with_seed(2));
    assert_ne!(a, b);
    assert_ne!(a, unseeded);
    // lpfg's ran starts at 0x330E: --seed 13070 (0x330E) is the unseeded run.
    assert_eq!(
        word(STOCHASTIC, DeriveOptions::default().with_seed(0x330E)),
        unseeded
    );
}

#[test]
fn the_binary_takes_a_seed() {
    let tmp = scratch("seed");
    let dir = tmp.path();
    let f = dir.join("stochastic.lsys");
    std::fs::write(&f, STOCHASTIC).unwrap();
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
            .arg("derive")
            .arg(&f)
            .args(args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    assert_eq!(run(&["--seed", "7"]), run(&["--seed", "7"]));
    assert_ne!(run(&["--seed", "7"]), run(&["--seed", "8"]));
    assert_eq!(
        run(&["--seed", "7"]).trim(),
        word(STOCHASTIC, DeriveOptions::default().with_seed(7))
    );
    let render = |seed: &str, name: &str| {
        let png = dir.join(name);
        let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
            .args(["render", f.to_str().unwrap(), "-o", png.to_str().unwrap()])
            .args(["--seed", seed])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read(png).unwrap()
    };
    assert_eq!(render("7", "a.png"), render("7", "b.png"));
    assert_ne!(render("7", "a.png"), render("8", "b.png"));
    let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(["derive", f.to_str().unwrap(), "--seed", "-1"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "a negative seed is a usage error");
}

/// lpfg (vlab 9bf820d, built headless by ../shared/tools/lpfg) prints these
/// words for the same two programs, unseeded and seeded in Start.
#[test]
fn numbers_agree_with_lpfg() {
    let unseeded = "#include <lpfgall.h>\nmodule X(double);\nmodule I(int);\n\
        Axiom: X(ran(1)) X(ran(10)) I(rand()) I(rand()) I(RAND_MAX) X(drand48()) I(lrand48());\n";
    assert_eq!(
        numbers(unseeded, DeriveOptions::default()),
        [
            0.17082803610628972,
            7.499019804849638,
            1804289383.0,
            846930886.0,
            2147483647.0,
            3.907985046680551e-14,
            2116118.0
        ]
    );
    let seeded = "#include <lpfgall.h>\nmodule X(double);\nmodule I(int);\n\
        Start: { sran(5); srand(42); srand48(7); }\n\
        Axiom: X(ran(1)) X(ran(1)) I(rand()) I(rand()) X(drand48()) I(lrand48());\n";
    assert_eq!(
        numbers(seeded, DeriveOptions::default()),
        [
            0.000447906670316911,
            0.655824306910997,
            71876166.0,
            708592740.0,
            0.2664441967654092,
            1464659504.0
        ]
    );
}
