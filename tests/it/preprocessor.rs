//! The preprocessor's conditionals with `#define` and `-D`, C's literal
//! forms and C's single-precision maths functions, on whole programs. The expected words follow from C's
//! rules for `#if` (one group of each conditional is kept, the first whose
//! condition is true) worked out by hand in each test.

use std::process::Command;

use subgram::{DeriveOptions, Value};

use crate::support::*;

/// The final word of `src` derived with `-D` definitions `defines`.
fn word(src: &str, defines: &[&str]) -> String {
    let defines: Vec<String> = defines.iter().map(|d| d.to_string()).collect();
    let l = match subgram::load_str("test.lsys", src, &defines) {
        Ok(l) => l,
        Err(e) => panic!("the test program does not load:\n{e}"),
    };
    let d = derive(&l, DeriveOptions::default());
    text(&l, &d)
}

/// A program that chooses its axiom and its production by conditionals,
/// some nested, and whose `#ifndef` gives a default that `-D` replaces.
const CHOOSER: &str = r#"
#ifndef STEPS
#define STEPS 2
#endif
#define BRANCHY
module A(int);
module B;
derivation length: STEPS;
#if STEPS >= 3 && defined(BRANCHY)
Axiom: B A(0);
#elif STEPS == 2
Axiom: A(0);
#else
Axiom: B;
#endif
A(n) :
{
#ifdef BRANCHY
#  if STEPS > 2
  produce A(n + 10);
#  else
  produce A(n + 1) B;
#  endif
#else
  produce A(n - 1);
#endif
}
"#;

#[test]
fn conditionals_choose_the_program() {
    // STEPS is 2 (the #ifndef's default): axiom A(0) and A(n) -> A(n+1) B,
    // so after two steps A(0) -> A(1) B -> A(2) B B.
    assert_eq!(word(CHOOSER, &[]), "A(2) B B");
    // -D STEPS=3: axiom B A(0), the production A(n) -> A(n+10), three
    // steps: B A(30).
    assert_eq!(word(CHOOSER, &["STEPS=3"]), "B A(30)");
    // -D STEPS=1: neither 3 nor 2, the #else axiom B, no production for B.
    assert_eq!(word(CHOOSER, &["STEPS=1"]), "B");
    // -D BRANCHY=0 still defines BRANCHY: `defined` asks whether it is
    // defined, not its value, so STEPS=3 gives B A(30) as above.
    assert_eq!(word(CHOOSER, &["STEPS=3", "BRANCHY=0"]), "B A(30)");
}

/// The binary's `-D` reaches `#if`, and a skipped group may hold text that
/// is not L+C at all.
#[test]
fn the_binary_passes_defines_to_conditionals() {
    let tmp = scratch("pre");
    let dir = tmp.path();
    let f = dir.join("p.lsys");
    std::fs::write(
        &f,
        "module A; module B;\n#if LONG\nAxiom: A A A;\n#else\nAxiom: B;\n#endif\n\
         #if 0\nThis is `not` L+C: 1abc, é, #pragma, #foo.\n#endif\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
            .arg("derive")
            .arg(&f)
            .args(args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap().trim().to_string()
    };
    // LONG is unknown, hence 0, without -D.
    assert_eq!(run(&[]), "B");
    assert_eq!(run(&["-D", "LONG=1"]), "A A A");
    assert_eq!(run(&["-D", "LONG=0"]), "B");
}

/// C's literal forms in a program: hexadecimal, octal, integer suffixes,
/// and floats with `f`, whose value is the nearest single-precision number
/// (`0.1f` is 0.100000001490116…, not 0.1).
#[test]
fn c_literals_in_programs() {
    let src = "module I(int); module X(double);\n\
               Axiom: I(0x1F) I(017) I(10L) I(3u) X(1.f) X(.5f) X(1e-3f) X(2.5e1) X(0.1f - 0.1);";
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    let params: Vec<f64> = d
        .word
        .modules(&l.program.alphabet, &l.program.structs)
        .map(|(_, ps)| match ps[0] {
            Value::Int(i) => i as f64,
            Value::Float(f) => f,
            ref other => panic!("{other:?}"),
        })
        .collect();
    let want = [
        31.0,
        15.0,
        10.0,
        3.0,
        1.0,
        0.5,
        f64::from(0.001f32),
        25.0,
        // The float nearest 0.1 is 13421773 / 2^27; minus the double 0.1.
        13421773.0 / 134217728.0 - 0.1,
    ];
    assert_eq!(params, want);
    assert!(params[8] > 1e-9, "0.1f is not rounded to a float");
}

/// C's `float` functions (`expf`, `sqrtf`, …) as lpfg's programs call
/// them: on the argument rounded to a float, giving a float. The expected
/// values are what a C program compiled with gcc (glibc 2.36) printed with
/// "%.17g" for the same calls on float arguments.
#[test]
#[allow(clippy::excessive_precision)]
fn c_float_functions() {
    let src = "module X(double);\n\
               Axiom: X(expf(1)) X(sqrtf(2)) X(sinf(0.5)) X(logf(3.3)) X(powf(0.7, 3.3)) \
               X(atan2f(0.7, 3.3)) X(fmodf(3.3, 0.7));";
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    let got: Vec<f64> = d
        .word
        .modules(&l.program.alphabet, &l.program.structs)
        .map(|(_, ps)| match ps[0] {
            Value::Float(f) => f,
            ref other => panic!("{other:?}"),
        })
        .collect();
    let gcc = [
        2.7182817459106445,
        1.4142135381698608,
        0.47942554950714111,
        1.1939224004745483,
        0.30819353461265564,
        0.20902295410633087,
        0.5,
    ];
    assert_eq!(got, gcc);
    // Not the double functions' values.
    assert_ne!(got[0], std::f64::consts::E);
}
