//! lpfg's numbers: `float`, `V2f` and `V3f` are single precision, `double`,
//! `V2d` and `V3d` double, with C's conversions (a `0.02` literal is a
//! `double`; storing into a `float` rounds). `--double` computes every
//! `float` in double precision instead.
//!
//! The expected words come from lpfg itself (vlab commit 9bf820d, built
//! headless with `shared/tools/lpfg`, final string printed by
//! `run_lpfg.sh`), or from the C semantics written out here with Rust's
//! `f32` and `f64`.

use subgram::{DeriveOptions, Precision};

use crate::support::*;

fn words(src: &str, precision: Precision) -> String {
    let l = subgram::load_str_with("p.l", src, &[], precision)
        .unwrap_or_else(|e| panic!("the program does not load:\n{e}"));
    let d = derive(&l, DeriveOptions::default());
    text(&l, &d)
}

/// A time `t + dt` (dt 0.02) stored in a `float` each step reaches 2 one
/// step later than in double precision: the model takes its branch later.
const THRESHOLD: &str = "#define dt 0.02\nderivation length: 101;\n\
    module A(float);\nmodule B(float);\nAxiom: A(0);\n\
    A(t) : { if (t >= 2.0) produce B(t); else produce A(t + dt); }\n";

#[test]
fn a_float_time_crosses_its_threshold_as_in_lpfg() {
    // C: `(float)((double)t + 0.02)` every step, from 0.
    let mut t32 = 0f32;
    let mut t64 = 0f64;
    let (mut b32, mut b64) = (None, None);
    for _ in 0..101 {
        if b32.is_none() {
            if t32 as f64 >= 2.0 {
                b32 = Some(t32);
            } else {
                t32 = (t32 as f64 + 0.02) as f32;
            }
        }
        if b64.is_none() {
            if t64 >= 2.0 {
                b64 = Some(t64);
            } else {
                t64 += 0.02;
            }
        }
    }
    // In single precision the 100th step stops short of 2 (1.9999987), so
    // the 101st step still grows the time.
    assert_eq!(b32, None);
    assert_eq!(format!("A({t32})"), "A(2.0199988)");
    // lpfg 9bf820d prints exactly this word for the program.
    assert_eq!(words(THRESHOLD, Precision::Single), "A(2.0199988)");
    // In double precision the 100th step is past 2, and the 101st branches.
    assert_eq!(
        words(THRESHOLD, Precision::Double),
        format!("B({})", b64.expect("crossed"))
    );
}

/// Vectors and scalars together: `V2f * 1.1` takes a float (lpfg's
/// operator), `sqrt` of a float is a double (C's `<math.h>`, as lpfg
/// calls it), `double` stays double.
#[test]
fn mixed_float_double_and_vector_arithmetic_matches_lpfg_to_the_bit() {
    let src = "derivation length: 30;\nmodule P(V2f);\nmodule S(float);\nmodule D(double);\n\
        module Q(V3f);\nmodule L(float, float);\n\
        Axiom: P(V2f(0.3, 0.7)) S(0.1) D(0.1) Q(V3f(0.2, 0.4, 0.9)) L(0.3, 0.0);\n\
        P(v) : { produce P(v * 1.1 + V2f(0.01, 0.02) / 3.0 - 0.5 * v); }\n\
        S(x) : { float y = x * 1.1 + sqrt(x) / 7; y += 0.013; produce S(y); }\n\
        D(x) : { produce D(x * 1.1 + sqrt(x)/7); }\n\
        Q(p) : { V3f q = p * 0.9; q.x += 0.01; produce Q(q + p * 0.1); }\n\
        L(a, b) : { float c = a * 3; produce L(cos(a) + 0.01, c / 7 + b); }\n";
    // lpfg 9bf820d's final string, parameters as it prints them.
    let lpfg = "P([0.008333398, 0.016666818]) S(35.918842) D(31.507469014450198) \
                Q([0.49999946, 0.39999995, 0.8999998]) L(0.7450495, 9.435987)";
    assert_eq!(words(src, Precision::Single), lpfg);
    // The same program in double precision is another word.
    assert_ne!(words(src, Precision::Double), lpfg);
}

/// The stencil fast path rounds where the interpreter rounds: in single
/// precision, in double (`V2d`), and with `--double`.
#[test]
fn stencils_agree_with_the_interpreter_in_every_precision() {
    let body = "P(vl/3 + v - 0.1*vr) P(-v/3.0 - (1.0/3)*vl + 0.7*vr)";
    for (ty, precision) in [
        ("V2f", Precision::Single),
        ("V2d", Precision::Single),
        ("V2f", Precision::Double),
    ] {
        let fast = format!(
            "module P({ty});\nring L-system: 1;\nderivation length: 7;\n\
             Axiom: P({ty}(0.1, 0.7)) P({ty}(1.3, 2.9)) P({ty}(4.1, 3.3)) P({ty}(2.2, -1.7));\n\
             P(vl) < P(v) > P(vr) -> {body}\n"
        );
        let slow = fast.replace(
            &format!("-> {body}"),
            &format!(": {{ if (1) produce {body}; }}"),
        );
        let load = |s: &str| subgram::load_str_with("s.l", s, &[], precision).unwrap();
        let (a, b) = (load(&fast), load(&slow));
        assert!(a.program.rules[0].stencil.is_some(), "{ty} {precision:?}");
        assert!(b.program.rules[0].stencil.is_none());
        let (da, db) = (
            derive(&a, DeriveOptions::default()),
            derive(&b, DeriveOptions::default()),
        );
        assert_eq!(da.word, db.word, "{ty} {precision:?}");
    }
    // And the precisions differ: single precision is really single.
    let single = words(
        "module P(V2f);\nderivation length: 3;\nAxiom: P(V2f(0.1, 0.7));\nP(v) -> P(0.1*v + v/3)\n",
        Precision::Single,
    );
    let double = words(
        "module P(V2f);\nderivation length: 3;\nAxiom: P(V2f(0.1, 0.7));\nP(v) -> P(0.1*v + v/3)\n",
        Precision::Double,
    );
    assert_ne!(single, double);
}

/// `--double` on the command line.
#[test]
fn the_double_option_computes_floats_in_double() {
    let tmp = scratch("precision");
    let dir = tmp.path();
    let file = dir.join("t.l");
    std::fs::write(&file, THRESHOLD).unwrap();
    let run = |extra: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
            .arg("derive")
            .arg(&file)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success());
        String::from_utf8(o.stdout).unwrap().trim().to_string()
    };
    assert_eq!(run(&[]), "A(2.0199988)");
    assert!(run(&["--double"]).starts_with("B(2.0000000000000"));
}

/// A literal with an `f` suffix is a `float`, as in C: `x * 3.3f` is a
/// product of two floats, rounded to single precision, while `x * 3.3`
/// is computed in double. (lpfg's translator refuses the suffix, so the
/// expected values are C's, written out with Rust's `f32` and `f64`.)
#[test]
fn an_f_suffix_makes_a_float_literal() {
    let src = "derivation length: 1;\nmodule A(double, double, float);\nAxiom: A(0, 0, 0);\n\
               A(a, b, c) : { float x = 0.1f; produce A(x * 3.3f, x * 3.3, 1.f / 3.f + 1e-3f); }\n";
    let x = 0.1f32;
    let c = 1f32 / 3f32 + 1e-3f32;
    assert_eq!(
        words(src, Precision::Single),
        format!("A({}, {}, {})", (x * 3.3f32) as f64, x as f64 * 3.3, c)
    );
}
