//! One language: the same expression means the same thing, and gets the
//! same message, in a curve L-system and in a surface grammar. The
//! expected values are C's (L+C's) arithmetic: integer division truncates
//! towards zero, `%` takes the sign of the dividend, `fabs` is the
//! floating-point absolute value, and integer division by zero is an
//! error.

use std::path::Path;
use std::process::{Command, Output};

use tempfile::TempDir;

use crate::support::scratch;

fn subgram(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A fresh folder holding one triangle, for surface grammars to run on;
/// removed when the returned `TempDir` is dropped.
fn folder(name: &str) -> TempDir {
    let dir = scratch(&format!("one-language-{name}"));
    std::fs::write(
        dir.path().join("tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    dir
}

fn write(dir: &Path, name: &str, body: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, body).unwrap();
    p.to_str().unwrap().to_string()
}

/// The values of `-1 % 3`, `7/2`, `fabs(-2.5)` and `abs(-3)`: in a curve,
/// the parameters of the axiom's module; in a surface grammar, how far
/// a vertex rule moves every vertex.
#[test]
fn the_same_expressions_give_the_same_values() {
    let tmp = folder("values");
    let dir = tmp.path();
    let curve = write(
        dir,
        "c.lsys",
        "module A(float, float, float, float);\nderivation length: 0;\n\
         Axiom: A(-1 % 3, 7/2, fabs(-2.5), abs(-3));\n",
    );
    let o = subgram(&["derive", &curve, "--format", "json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let word: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        word["modules"][0]["params"],
        serde_json::json!([-1.0, 3.0, 2.5, 3.0])
    );

    let surface = write(
        dir,
        "s.lsys",
        "mesh: \"tri.obj\";\nderivation length: 1;\n\
         V(v) -> V(v = v + V3f(-1 % 3, 7/2, fabs(-2.5)) * abs(-3));\n",
    );
    let out = dir.join("out.obj");
    let o = subgram(&[
        "subdivide",
        "--grammar",
        &surface,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let obj = std::fs::read_to_string(&out).unwrap();
    let moved: Vec<Vec<f64>> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect();
    let base = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert_eq!(moved.len(), 3);
    for (p, q) in moved.iter().zip(base) {
        let d: Vec<f64> = p.iter().zip(q).map(|(a, b)| a - b).collect();
        assert_eq!(d, vec![-3.0, 9.0, 7.5], "{obj}");
    }
}

/// The message after the location and the caret's width, for the same
/// subexpression in both kinds of file.
fn message_and_caret(stderr: &str) -> (String, String) {
    let first = stderr.lines().next().unwrap_or_default();
    // `file:line:col: error: message`
    let message = first
        .splitn(4, ':')
        .nth(3)
        .unwrap_or_default()
        .trim()
        .to_string();
    let caret = stderr
        .lines()
        .find(|l| l.contains('^'))
        .map(|l| l.trim().trim_start_matches('|').trim().to_string())
        .unwrap_or_default();
    (message, caret)
}

#[test]
fn integer_division_by_zero_is_the_same_error() {
    let tmp = folder("zero");
    let dir = tmp.path();
    let curve = write(
        dir,
        "c.lsys",
        "module A(float);\nderivation length: 1;\nAxiom: A(1);\nA(x) -> A(x * (1/0));\n",
    );
    let c = subgram(&["derive", &curve]);
    assert_eq!(c.status.code(), Some(1), "{}", text(&c.stderr));
    let surface = write(
        dir,
        "s.lsys",
        "mesh: \"tri.obj\";\nderivation length: 1;\nV(v) -> V(v = v * (1/0));\n",
    );
    let out = dir.join("out.obj");
    let s = subgram(&[
        "subdivide",
        "--grammar",
        &surface,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(s.status.code(), Some(1), "{}", text(&s.stderr));
    assert!(!out.exists(), "a failed run leaves no output");
    let (cm, cc) = message_and_caret(&text(&c.stderr));
    let (sm, sc) = message_and_caret(&text(&s.stderr));
    assert!(
        cm.contains("integer division by zero"),
        "{}",
        text(&c.stderr)
    );
    assert!(
        sm.contains("integer division by zero"),
        "{}",
        text(&s.stderr)
    );
    // Both carets are under `(1/0)`, at its column.
    assert_eq!((cc.as_str(), sc.as_str()), ("^^^^^", "^^^^^"));
    assert!(text(&c.stderr).starts_with(&format!("{curve}:4:15: error:")));
    assert!(text(&s.stderr).starts_with(&format!("{surface}:3:19: error:")));
}

#[test]
fn a_truncating_constant_division_is_the_same_warning() {
    let tmp = folder("truncation");
    let dir = tmp.path();
    let curve = write(
        dir,
        "c.lsys",
        "module A(float);\nderivation length: 1;\nAxiom: A(1);\nA(x) -> A(1/16 * x);\n",
    );
    let surface = write(
        dir,
        "s.lsys",
        "mesh: \"tri.obj\";\nV(v) -> V(v = 1/16 * v);\n",
    );
    let c = subgram(&["check", &curve]);
    let s = subgram(&["check", &surface]);
    assert!(c.status.success() && s.status.success());
    let expected = "warning: `1/16` is 0 in integer arithmetic; write 1.0/16";
    assert!(
        text(&c.stdout).starts_with(&format!("{curve}:4:11: {expected}")),
        "{}",
        text(&c.stdout)
    );
    assert!(
        text(&s.stdout).starts_with(&format!("{surface}:2:15: {expected}")),
        "{}",
        text(&s.stdout)
    );
    // A division of integer variables used as a floating-point number is
    // warned about too: a surface grammar written before the one language
    // meant `(n - 2)/n` as a fraction.
    let vars = write(
        dir,
        "v.lsys",
        "mesh: \"tri.obj\";\ndefine f(v, n) = (n - 2)/n*v;\nV(v) -> V(v = f(v, valence(v)));\n",
    );
    let o = subgram(&["check", &vars]);
    assert!(o.status.success());
    assert!(
        text(&o.stdout).starts_with(&format!(
            "{vars}:2:18: warning: this divides integers, which truncates"
        )),
        "{}",
        text(&o.stdout)
    );
    // A division that does not truncate, or one meant as an integer, is
    // not warned about.
    let quiet = write(
        dir,
        "q.lsys",
        "module A(float, int);\nderivation length: 1;\nAxiom: A(8/2 * 1.5, 7/2);\n",
    );
    let q = subgram(&["check", &quiet]);
    assert!(q.status.success());
    assert!(
        !text(&q.stdout).contains(": warning:"),
        "{}",
        text(&q.stdout)
    );
}

#[test]
fn the_same_type_errors_read_the_same() {
    let tmp = folder("types");
    let dir = tmp.path();
    let curve = write(
        dir,
        "c.lsys",
        "module A(V3d);\nderivation length: 1;\nAxiom: A(V3d(0, 0, 0));\nA(p) -> A(p + 1);\n",
    );
    let surface = write(dir, "s.lsys", "mesh: \"tri.obj\";\nV(v) -> V(v = v + 1);\n");
    let c = subgram(&["check", &curve]);
    let s = subgram(&["check", &surface]);
    let (cm, _) = message_and_caret(&text(&c.stderr));
    let (sm, _) = message_and_caret(&text(&s.stderr));
    // A mesh's positions are doubles: a vertex reads as a `V3d`.
    assert_eq!(cm, "error: type error: cannot apply `+` to V3d and int");
    assert_eq!(sm, cm);
}

/// `i64::MIN / -1` overflows: the interpreter wraps it to `i64::MIN`, as
/// two's-complement hardware does, and the truncation check must not
/// panic on it (it divides exactly, so there is nothing to warn about).
#[test]
fn the_most_negative_integer_divided_by_minus_one_is_checked_without_a_panic() {
    let tmp = folder("overflow");
    let dir = tmp.path();
    let min = "(-9223372036854775807 - 1)";
    let curve = write(
        dir,
        "c.lsys",
        &format!(
            "module A(double);\nderivation length: 1;\nAxiom: A(1);\n\
             A(x) : {{ produce A(x * ({min} / -1)); }}\n"
        ),
    );
    let surface = write(
        dir,
        "s.lsys",
        &format!("mesh: \"tri.obj\";\nV(v) -> V(v = v * ({min} / -1));\n"),
    );
    for f in [&curve, &surface] {
        let o = subgram(&["check", f]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
        assert!(!text(&o.stdout).contains("warning"), "{}", text(&o.stdout));
    }
    let o = subgram(&["derive", &curve, "--format", "json"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let word: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        word["modules"][0]["params"],
        serde_json::json!([-9223372036854775808.0])
    );
}

/// The truncation warning follows a constant division wherever its value
/// is read as a float: through a `define` function's parameter, in a
/// branch of `?:` whose other branch is a float, in a comparison with a
/// float, and under a negation. (Before the one language these were all
/// floating-point divisions: `f(v, 1/16)` moved by 1/16, now by 0.)
/// Positions counted by hand in the line.
#[test]
fn truncation_is_warned_through_parameters_branches_comparisons_and_negations() {
    let tmp = folder("truncation-paths");
    let dir = tmp.path();
    let surface = write(
        dir,
        "s.lsys",
        "mesh: \"tri.obj\";\ndefine f(v, k) = k * v;\n\
         V(v; 1/2 > 0.25) -> V(v = f(v, 1/16) + (new(v) ? 1/4 : 0.5) * v - -(1/8) * v);\n",
    );
    let s = subgram(&["check", &surface]);
    assert!(s.status.success(), "{}", text(&s.stderr));
    let out = text(&s.stdout);
    let warned: Vec<&str> = out.lines().filter(|l| l.contains(": warning:")).collect();
    let expected = [
        "3:6: warning: `1/2` is 0",
        "3:32: warning: `1/16` is 0",
        "3:50: warning: `1/4` is 0",
        "3:68: warning: `1/8` is 0",
    ];
    assert_eq!(warned.len(), expected.len(), "{out}");
    for (w, e) in warned.iter().zip(expected) {
        assert!(w.starts_with(&format!("{surface}:{e}")), "{w}\n{out}");
    }
    // A parameter read as an integer is not warned about.
    let quiet = write(
        dir,
        "q.lsys",
        "mesh: \"tri.obj\";\ndefine f(v, n) = valence(v) > n;\n\
         V(v; f(v, 7/2)) -> V(v = v);\n",
    );
    let q = subgram(&["check", &quiet]);
    assert!(q.status.success());
    assert!(!text(&q.stdout).contains("warning"), "{}", text(&q.stdout));
}
