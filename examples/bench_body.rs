//! Interpreted rule bodies against `symbios`, the Rust L-system crate, on
//! the same rules in the same run (issue 16, item 4).
//! `cargo run --release --example bench_body [-- --runs N]`
//!
//! 1. A guarded, branching parametric system: `A(l,w) : l > 0.01 -> F(l)
//!    [ +(30) A(0.7 l, 0.7 w) ] [ -(25) A(0.6 l, 0.7 w) ] A(0.9 l, 0.9 w)`
//!    from `A(1, 1)` for 11 steps: 795,484 modules (every `A` grows but the
//!    239 whose `l` is 0.01 or less at the last step; worked out in
//!    `branching_count` below and checked against both engines). Parameters
//!    are `float`, lpfg's single precision: the engine rounds every result
//!    to it, `symbios` computes in `f64`; the guard is never near its
//!    threshold, so both make the same word up to that rounding (module
//!    count, symbols and the sum of the `F` lengths are compared).
//! 2. A context-sensitive signal: 200,000 modules `A(1) A(0) A(0) ...`,
//!    every module but the first rewritten by one of two guarded rules with
//!    a left context, `A(x) < A(y) : x > y -> A(0.5 x + y + 1)` and
//!    `A(x) < A(y) : x <= y -> A(0.5 y)`, for 20 steps. Parameters are
//!    `double` here, so both engines compute the same `f64` operations in
//!    the same order and the final words are compared to the bit. (The
//!    values are dyadic fractions far apart: `symbios` compares with a
//!    relative tolerance of 1e-8, the engine exactly, as C does.)
//!
//! Each figure is the best of N runs (5 by default) of a whole derivation:
//! the engine's `subgram::derive` on a loaded program (axiom, steps, the
//! word's allocation) and `symbios`'s `System::derive` on a clone of a
//! system with its rules and axiom set. Parsing is outside the timing on
//! both sides.

mod common;

use std::time::{Duration, Instant};

use subgram::DeriveOptions;

/// The number of modules after `steps` steps of the branching system,
/// computed apart from both engines: each `A` whose `l` exceeds 0.01
/// becomes ten modules, three of them `A`s.
fn branching_count(steps: usize) -> usize {
    let mut apices = vec![1.0f64];
    let mut others = 0;
    for _ in 0..steps {
        let mut next = Vec::with_capacity(apices.len() * 3);
        for &l in &apices {
            if l > 0.01 {
                others += 7;
                next.extend([l * 0.7, l * 0.6, l * 0.9]);
            } else {
                next.push(l);
            }
        }
        apices = next;
    }
    apices.len() + others
}

/// The fastest of `runs` runs of `f` on a fresh copy of `setup`'s value.
fn best_of_with<S: Clone, T>(runs: usize, setup: &S, mut f: impl FnMut(S) -> T) -> (Duration, T) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..runs {
        let s = setup.clone();
        let t = Instant::now();
        let r = f(s);
        best = best.min(t.elapsed());
        last = Some(r);
    }
    (best, last.expect("at least one run"))
}

/// The engine's name of a module as `symbios` writes it.
fn names(s: &str) -> &str {
    match s {
        "SB" => "[",
        "EB" => "]",
        "Left" => "+",
        "Right" => "-",
        other => other,
    }
}

fn report(what: &str, ours: Duration, theirs: Duration) {
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!("{what}");
    println!("  subgram  {:>9.2} ms", ms(ours));
    println!("  symbios  {:>9.2} ms", ms(theirs));
    println!(
        "  subgram / symbios {:.2} (symbios takes {:.2}x subgram's time)",
        ours.as_secs_f64() / theirs.as_secs_f64(),
        theirs.as_secs_f64() / ours.as_secs_f64()
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = common::runs_arg(&args, 5);
    let only = |name: &str| !args.iter().any(|a| a == "--only") || args.iter().any(|a| a == name);

    // `--subgram-only`: the engine alone, for a profile.
    let alone = args.iter().any(|a| a == "--subgram-only");
    if only("branching") {
        let steps = 11;
        let src = format!(
            "module A(float, float);\nderivation length: {steps};\nAxiom: A(1, 1);\n\
             A(l, w) : {{ if (l > 0.01) produce F(l) SB() Left(30) A(l * 0.7, w * 0.7) EB() \
             SB() Right(25) A(l * 0.6, w * 0.7) EB() A(l * 0.9, w * 0.9); }}\n"
        );
        let loaded = subgram::load_str("branching.lsys", &src, &[]).expect("loads");
        let (t_ours, ours) = best_of_with(runs, &(), |()| {
            subgram::derive(&loaded.program, DeriveOptions::default()).expect("derives")
        });
        if alone {
            println!("subgram alone {:.2} ms", t_ours.as_secs_f64() * 1e3);
        } else {
            let mut sys = symbios::System::new();
            sys.max_capacity = 4_000_000;
            sys.add_rule(
                "A(l, w) : l > 0.01 -> F(l) [ +(30) A(l * 0.7, w * 0.7) ] \
             [ -(25) A(l * 0.6, w * 0.7) ] A(l * 0.9, w * 0.9)",
            )
            .expect("symbios parses");
            sys.set_axiom("A(1, 1)").expect("symbios axiom");
            let (t_theirs, theirs) = best_of_with(runs, &sys, |mut s| {
                s.derive(steps).expect("symbios derives");
                s
            });
            let want = branching_count(steps);
            assert_eq!(ours.word.len(), want, "subgram's module count");
            assert_eq!(theirs.state.len(), want, "symbios's module count");
            // The same symbols in the same order, and the same F lengths to
            // single precision.
            let mut sum_ours = 0.0;
            let mut sum_theirs = 0.0;
            for i in 0..want {
                let a = names(loaded.program.alphabet.name(ours.word.sym(i)));
                let v = theirs.state.get_view(i).expect("module");
                let b = theirs.interner.resolve(v.sym).expect("symbol");
                assert_eq!(a, b, "module {i}");
                if a == "F" {
                    sum_ours += ours.word.data(i)[0];
                    sum_theirs += v.params[0];
                }
            }
            assert!((sum_ours - sum_theirs).abs() <= 1e-5 * sum_theirs);
            report(
            &format!(
                "guarded branching system, 11 steps, {want} modules, best of {runs} (parsing not timed)"
            ),
            t_ours,
            t_theirs,
        );
        }
    }

    if only("signal") {
        let (n, steps) = (200_000, 20);
        let mut axiom = String::from("A(1)");
        for _ in 1..n {
            axiom.push_str(" A(0)");
        }
        let src = format!(
            "module A(double);\nderivation length: {steps};\nAxiom: {axiom};\n\
             A(x) < A(y) : {{ if (x > y) produce A(x * 0.5 + y + 1); }}\n\
             A(x) < A(y) : {{ if (x <= y) produce A(y * 0.5); }}\n"
        );
        let loaded = subgram::load_str("signal.lsys", &src, &[]).expect("loads");
        let (t_ours, ours) = best_of_with(runs, &(), |()| {
            subgram::derive(&loaded.program, DeriveOptions::default()).expect("derives")
        });
        if alone {
            println!("subgram alone {:.2} ms", t_ours.as_secs_f64() * 1e3);
        } else {
            let mut sys = symbios::System::new();
            sys.max_capacity = 4_000_000;
            sys.add_rule("A(x) < A(y) : x > y -> A(x * 0.5 + y + 1)")
                .expect("symbios parses");
            sys.add_rule("A(x) < A(y) : x <= y -> A(y * 0.5)")
                .expect("symbios parses");
            sys.set_axiom(&axiom).expect("symbios axiom");
            let (t_theirs, theirs) = best_of_with(runs, &sys, |mut s| {
                s.derive(steps).expect("symbios derives");
                s
            });
            assert_eq!(ours.word.len(), n);
            assert_eq!(theirs.state.len(), n);
            for i in 0..n {
                let v = theirs.state.get_view(i).expect("module");
                assert_eq!(
                    ours.word.data(i)[0].to_bits(),
                    v.params[0].to_bits(),
                    "module {i}"
                );
            }
            report(
            &format!(
                "context-sensitive signal, {n} modules x {steps} steps, best of {runs} (parsing not timed)"
            ),
            t_ours,
            t_theirs,
        );
        }
    }
}
