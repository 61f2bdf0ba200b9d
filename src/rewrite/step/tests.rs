//! Whole steps: the paths a step takes (in parts, lean, the kernel)
//! against the interpreter on one thread, and their errors.

use super::{Rewriter, StepOptions, PARALLEL_MODULES};
use crate::lang::closure;
use crate::lang::eval::{Env, Interp};
use crate::rewrite::word::Word;

/// A word grown to `steps` steps on one thread, then one more step run
/// by hand: whether `parallel_step` takes it in a pool of `threads`,
/// and the new word (from whichever path ran).
fn last_step(src: &str, steps: u64, threads: usize) -> (bool, Word) {
    let curve = crate::load_str("t.lsys", src, &[]).expect("loads");
    let program = &curve.program;
    let opts = crate::DeriveOptions::default().with_steps(steps);
    let d = crate::derive(program, opts).expect("derives");
    let mut interp = Interp::for_program(program, None);
    let mut env =
        Env::for_program(program, &mut interp, Default::default(), None).expect("an environment");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build();
    // Made here: `closure::set_enabled` holds on this thread.
    let mut rw = Rewriter::new(program);
    pool.expect("a pool").install(|| {
        let rules: Vec<usize> = (0..program.rules.len()).collect();
        let opts = StepOptions {
            ring: false,
            forward: true,
            phase: 0,
            max_modules: usize::MAX,
            deadline: None,
            cut: true,
        };
        let mut dst = Word::new();
        let parallel = rw
            .parallel_step(&rules, &d.word, &mut dst, &mut env, &opts)
            .is_some();
        let mut again = Word::new();
        rw.step(&rules, &d.word, &mut again, &mut env, &opts, None, None)
            .expect("steps");
        if parallel {
            assert_eq!(dst, again, "step() takes the same path");
        }
        (parallel, again)
    })
}

/// Guarded, branching, context-sensitive rules with compiled bodies
/// that read a global: the general path runs them in parts, and the
/// word is the one the interpreter makes on one thread, to the bit.
#[test]
fn pure_bodies_run_in_parts_as_the_interpreter_runs_them() {
    let src = "module A(float, int); module B(float);\n\
         float k = 0.5;\nderivation length: 1;\nAxiom: B(1) F(1) A(1, 0);\n\
         production:\n\
         F(x) < A(l, d) : { if (d % 3 == 2 && l < 0.7) produce F(l) A(l * k, d + 1); \
            else produce F(l) SB() B(x + l) A(l * 0.9, d + 1) EB() A(l * 0.8, d + 2); }\n\
         A(l, d) -> F(l) A(l * 0.6, d + 1) SB() A(l, d + 2) EB()\n\
         B(x) > SB() A(l, d) -> B(x * 0.5 + l)\n";
    let (parallel, two) = last_step(src, 18, 2);
    assert!(two.len() > 2 * PARALLEL_MODULES, "{} modules", two.len());
    assert!(parallel, "the general path ran in parts");
    let (serial, one) = last_step(src, 18, 1);
    assert!(!serial);
    assert!(one == two, "the same word on one thread");
    closure::set_enabled(false);
    let (interpreted, reference) = last_step(src, 18, 2);
    closure::set_enabled(true);
    assert!(!interpreted, "interpreted bodies run on one thread");
    assert!(reference == two, "the interpreter's word");
}

/// A body that stores a global or draws a random number runs on one
/// thread: what it produces depends on the order of the modules.
#[test]
fn bodies_with_effects_run_on_one_thread() {
    for body in [
        "n = n + 1; produce A(l * 0.9) A(l * 0.8);",
        "produce A(l * ran(1)) A(l);",
    ] {
        let src = format!(
            "module A(float);\nint n = 0;\nderivation length: 1;\nAxiom: A(1);\n\
             production:\nA(l) : {{ {body} }}\n"
        );
        let (parallel, _) = last_step(&src, 17, 2);
        assert!(!parallel, "{body}");
    }
    let pure = "module A(float);\nint n = 0;\nderivation length: 1;\nAxiom: A(1);\n\
         production:\nA(l) : { int m = n + 1; produce A(l * 0.9) SB() A(l * m) EB(); }\n";
    assert!(last_step(pure, 16, 2).0, "reading a global is pure");
    // Each part would copy a large array the body does not even read.
    let big = pure.replace("int n = 0;", "int n = 0;\nfloat big[10000];");
    assert!(
        !last_step(&big, 16, 2).0,
        "large globals stay on one thread"
    );
}

/// An overflow in the middle of a long ring, where the kernel computes,
/// is reported by the general path with the production's name.
#[test]
fn an_overflow_inside_a_long_ring_names_the_production() {
    let mut axiom = String::from("Axiom:");
    for i in 0..1000 {
        let x = if i == 700 { "3e38" } else { "1" };
        axiom.push_str(&format!(" P(V2f({x}, 0))"));
    }
    let src = format!(
        "module P(V2f);\nring L-system: 1;\nderivation length: 2;\n{axiom};\n\
         P(vl) < P(v) > P(vr) -> P(0.5*vl + 2*v) P(2*v + 0.5*vr)\n"
    );
    let curve = crate::load_str("t.lsys", &src, &[]).expect("loads");
    assert!(curve.program.rules[0].stencil.is_some());
    let e = crate::derive(&curve.program, Default::default()).expect_err("overflows");
    assert!(e.message.contains("at step 1"), "{}", e.message);
    assert!(e.message.contains("NaN or infinite"), "{}", e.message);
    assert!(e.message.contains("P(vl) < P(v) > P(vr)"), "{}", e.message);
}

/// The final word of `src` derived on one thread, compiled bodies on
/// or off (off: the interpreter on the general loop, the reference),
/// as `(symbol name, parameter bits)`s; or the error's message.
fn derived(src: &str, compiled: bool) -> Result<Vec<(String, Vec<u64>)>, String> {
    derived_within(src, compiled, crate::DeriveOptions::default().max_modules)
}

/// [`derived`] with a limit on the word.
fn derived_within(
    src: &str,
    compiled: bool,
    max_modules: usize,
) -> Result<Vec<(String, Vec<u64>)>, String> {
    closure::set_enabled(compiled);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    let out = pool.expect("a pool").install(|| {
        let curve = crate::load_str("t.lsys", src, &[]).map_err(|e| e.to_string())?;
        let p = &curve.program;
        let opts = crate::DeriveOptions {
            max_modules,
            ..Default::default()
        };
        let d = crate::derive(p, opts).map_err(|e| e.to_string())?;
        Ok((0..d.word.len())
            .map(|i| {
                let name = p.alphabet.name(d.word.sym(i)).to_string();
                (name, d.word.data(i).iter().map(|x| x.to_bits()).collect())
            })
            .collect())
    });
    closure::set_enabled(true);
    out
}

/// Two guarded rules with one left context, as `bench_body`'s signal:
/// on the lean path (the rules tried by symbol, the context matched
/// once for both), the word of a recursion written here, in `double`,
/// to the bit, on a word and on a ring; and the interpreter's.
#[test]
fn guarded_context_rules_on_the_lean_path_give_the_recursion() {
    let (n, steps) = (40, 30);
    for ring in [false, true] {
        let mut axiom = String::from("A(1)");
        for k in 1..n {
            axiom.push_str(&format!(" A({})", (k % 3) as f64 * 0.25));
        }
        let src = format!(
            "module A(double);\n{}derivation length: {steps};\nAxiom: {axiom};\n\
             A(x) < A(y) : {{ if (x > y) produce A(x * 0.5 + y + 1); }}\n\
             A(x) < A(y) : {{ if (x <= y) produce A(y * 0.5); }}\n",
            if ring { "ring L-system: 1;\n" } else { "" }
        );
        let mut a: Vec<f64> = (0..n)
            .map(|k| if k == 0 { 1.0 } else { (k % 3) as f64 * 0.25 })
            .collect();
        for _ in 0..steps {
            a = (0..n)
                .map(|k| {
                    let left = match k {
                        0 if ring => Some(a[n - 1]),
                        0 => None,
                        _ => Some(a[k - 1]),
                    };
                    match left {
                        Some(x) if x > a[k] => x * 0.5 + a[k] + 1.0,
                        Some(_) => a[k] * 0.5,
                        None => a[k],
                    }
                })
                .collect();
        }
        let want: Vec<(String, Vec<u64>)> = a
            .iter()
            .map(|x| ("A".to_string(), vec![x.to_bits()]))
            .collect();
        assert_eq!(derived(&src, true), Ok(want.clone()), "ring {ring}");
        assert_eq!(derived(&src, false), Ok(want), "ring {ring}, interpreted");
    }
}

/// Rules of several symbols, in file order: a rule whose predecessor
/// is the one before it's reuses that match (and its refusal), one
/// after a rule of another predecessor matches again; `ignore:` skips
/// in the context. The word worked out by hand, and the interpreter's.
#[test]
fn rules_by_symbol_keep_file_order_and_shared_matches() {
    let src = "module A(int); module B(int); module C(int);\n\
         derivation length: 1;\n\
         Axiom: A(1) C(0) B(2) A(3) B(4) B(5) A(6) B(5) A(8) B(7) C(0);\n\
         ignore: C;\n\
         A(x) < B(y) : { if (y > 3 && y < 5) produce B(y + x * 10); }\n\
         B(y) : { if (y == 2) produce B(20); }\n\
         A(x) < B(y) : { if (y == 5) produce B(y * 100); }\n\
         A(x) < B(y) : { produce B(x - y); }\n\
         A(x) : { produce A(x + 1) C(x); }\n";
    let int = |s: &str, v: i64| (s.to_string(), vec![v as u64]);
    let want = vec![
        int("A", 2),
        int("C", 1),
        int("C", 0),
        int("B", 20),
        int("A", 4),
        int("C", 3),
        int("B", 34),
        int("B", 5),
        int("A", 7),
        int("C", 6),
        int("B", 500),
        int("A", 9),
        int("C", 8),
        int("B", 1),
        int("C", 0),
    ];
    assert_eq!(derived(src, true), Ok(want.clone()));
    assert_eq!(derived(src, false), Ok(want));
}

/// Errors on the lean path are the general loop's: a NaN in the
/// second module of a successor names that rule, and a word past its
/// limit names the rule that produced last.
#[test]
fn lean_path_errors_name_the_rule() {
    let nan = "module A(double);\nderivation length: 1;\nAxiom: A(1) A(0) A(2);\n\
         A(y) : { if (y > 1) produce A(y); }\n\
         A(x) : { produce A(x) A(1 / x - 1 / x); }\n";
    let e = derived(nan, true).expect_err("a NaN");
    assert_eq!(derived(nan, false), Err(e.clone()));
    assert!(e.contains("NaN"), "{e}");
    assert!(e.contains("A(x)") && !e.contains("A(y)"), "{e}");
    let long = "module A(double); module B(double);\nderivation length: 40;\n\
         Axiom: B(1) A(1);\n\
         B(x) : { produce B(x); }\n\
         A(x) : { if (x < 1e300) produce A(x * 2) A(x * 3); }\n";
    let e = derived_within(long, true, 1000).expect_err("too long");
    assert_eq!(derived_within(long, false, 1000), Err(e.clone()));
    assert!(e.contains("1000") && e.contains("A(x)"), "{e}");
}

/// The second of two rules with one predecessor runs on the
/// parameters its body binds, not on what the first body left in the
/// frame: a first body that stores into a parameter makes the second
/// bind again (worked out by hand: 1 and 2, the first rule producing
/// only where ten times the parameter passes 15); one that stores
/// only into a local of its own leaves the parameters to the next.
#[test]
fn a_body_that_writes_its_parameter_leaves_the_next_rule_the_modules_values() {
    let writes = "module A(double);\nderivation length: 1;\nAxiom: A(1) A(2);\n\
         A(x) : { x = x * 10; if (x > 15) produce A(x); }\n\
         A(x) : { produce A(x + 0.5); }\n";
    let locals = "module A(double);\nderivation length: 1;\nAxiom: A(1) A(2);\n\
         A(x) : { double t = x * 10; if (t > 15) produce A(t); }\n\
         A(y) : { double u = y + 0.5; produce A(u); }\n";
    let a = |x: f64| ("A".to_string(), vec![x.to_bits()]);
    for src in [writes, locals] {
        assert_eq!(derived(src, true), Ok(vec![a(1.5), a(20.0)]), "{src}");
        assert_eq!(derived(src, false), Ok(vec![a(1.5), a(20.0)]), "{src}");
    }
}
