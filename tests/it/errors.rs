//! Every class of mistake gets `file:line:col`, the line, a caret and a
//! message that says what was expected or what is wrong.
//!
//! The bad inputs are files, `tests/data/err/NAME.lsys` (and, for meshes,
//! contours and details files, `tests/data/bad/`); `bad_inputs.rs` runs
//! them all through the binary. This file holds the checks that are not
//! one bad input each.

use subgram::DeriveOptions;

/// The other side of `nesting-of-parentheses.lsys`: just below the limit,
/// checking and deriving work, on a test thread's ordinary stack. Each step
/// adds x 95 times: 1, 95, 95^2.
#[test]
fn nesting_just_below_the_limit_works() {
    let ok = format!(
        "module A(float);\nderivation length: 2;\nAxiom: A({}1{});\nA(x) -> A({})\n",
        "(".repeat(95),
        ")".repeat(95),
        vec!["x"; 95].join("+")
    );
    let l = subgram::load_str("ok.lsys", &ok, &[]).unwrap();
    let d = subgram::derive(&l.program, DeriveOptions::default()).unwrap();
    assert_eq!(
        subgram::output::word_text(&d.word, &l.program.alphabet, &l.program.structs),
        "A(9025)"
    );
}
