//! Run-time limits (issue 11): a time limit on every command that runs the
//! engine, the module limit wherever a word is built, both named with how
//! to raise them; context matching that stays linear on deep branches; a
//! drawing that overflows names its module, step and file. Each case runs
//! the binary as a user would: exit code 1, the message, no file left.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use subgram::DeriveOptions;

use crate::support::{load_text, lsys, scratch};

/// A folder of its own for one test, removed afterwards.
struct Scratch(tempfile::TempDir);

impl Scratch {
    fn new(name: &str) -> Scratch {
        Scratch(scratch(&format!("limits-{name}")))
    }

    fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.0.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    /// The names of the files in the folder, sorted.
    fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(self.0.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        v.sort();
        v
    }
}

struct Ran {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    took: Duration,
}

/// `subgram ARGS` run in `dir`.
fn subgram(dir: &Path, args: &[&str]) -> Ran {
    let t = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("the binary runs");
    Ran {
        code: o.status.code(),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
        took: t.elapsed(),
    }
}

/// Exit code 1 with `message` on standard error, without a panic.
fn fails_with(r: &Ran, message: &str) {
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(!r.stderr.contains("panicked"), "{}", r.stderr);
    assert!(
        r.stderr.contains(message),
        "wanted {message:?} in:\n{}",
        r.stderr
    );
}

/// Nine million loop iterations per module per step stay under the limit
/// of one body, so only a limit on the whole run stops them.
const ENDLESS: &str = "module A(float);
derivation length: 1000;
Axiom: A(0) A(0) A(0) A(0);
A(x) : { int i = 0; while (i < 9000000) i = i + 1; produce A(x + 1); }
";

#[test]
fn long_loops_in_every_body_stop_at_the_time_limit() {
    let s = Scratch::new("endless");
    s.write("endless.lsys", ENDLESS);
    let r = subgram(s.0.path(), &["derive", "endless.lsys", "--timeout", "1"]);
    fails_with(
        &r,
        "production `A(x)`: the run went past its time limit of 1 s; \
         raise it with --timeout SECONDS (0 for no limit)",
    );
    // Located at the loop that spent the time.
    assert!(r.stderr.starts_with("endless.lsys:4:21: error: at step "));
    assert!(r.stderr.contains("while (i < 9000000)"), "{}", r.stderr);
    assert!(r.took < Duration::from_secs(10), "{:?}", r.took);

    let r = subgram(
        s.0.path(),
        &["render", "endless.lsys", "-o", "out.png", "--timeout", "1"],
    );
    fails_with(&r, "the run went past its time limit of 1 s");
    assert!(r.took < Duration::from_secs(10), "{:?}", r.took);
    assert_eq!(s.files(), ["endless.lsys"]);
}

#[test]
fn the_time_limit_is_a_number_of_seconds() {
    let s = Scratch::new("timeout-arg");
    s.write(
        "a.lsys",
        "module A;\nderivation length: 2;\nAxiom: A;\nA -> A A\n",
    );
    let r = subgram(s.0.path(), &["derive", "a.lsys", "--timeout", "soon"]);
    assert_eq!(r.code, Some(2), "{}", r.stderr);
    assert!(r.stderr.contains("`soon` is not a number of seconds"));
    for ok in ["0", "0.5", "600"] {
        let r = subgram(s.0.path(), &["derive", "a.lsys", "--timeout", ok]);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        assert_eq!(r.stdout.trim(), "A A A A");
    }
}

#[test]
fn subdivide_reverse_and_reconstruct_stop_at_the_time_limit() {
    let s = Scratch::new("timeout-commands");
    let grammar = lsys("surfaces/loop.lsys");
    let mesh = lsys("meshes/octahedron.obj");
    let r = subgram(
        s.0.path(),
        &[
            "subdivide",
            mesh.to_str().unwrap(),
            "--grammar",
            grammar.to_str().unwrap(),
            "-n",
            "8",
            "-o",
            "out.obj",
            "--timeout",
            "0.05",
        ],
    );
    fails_with(
        &r,
        ": the run went past its time limit of 0.05 s; raise it with --timeout SECONDS",
    );
    // At the rule the run had reached, in the grammar's file.
    assert!(r.stderr.contains("loop.lsys:"), "{}", r.stderr);
    assert!(r.stderr.contains(", before rule `"), "{}", r.stderr);
    assert!(r.took < Duration::from_secs(20), "{:?}", r.took);

    // A contour of 20,000 points: reversing it takes many steps.
    let points: String = (0..20_000)
        .map(|i| {
            let t = i as f64 / 20_000.0 * std::f64::consts::TAU;
            format!("{} {}\n", t.cos(), (2.0 * t).sin() * 0.5 + t.sin())
        })
        .collect();
    s.write("in.txt", &points);
    let reverse = |timeout: &str| {
        subgram(
            s.0.path(),
            &[
                "reverse",
                "in.txt",
                "-n",
                "3",
                "-o",
                "coarse.txt",
                "--details",
                "details.json",
                "--figure",
                "figure.svg",
                "--timeout",
                timeout,
            ],
        )
    };
    let r = reverse("0.001");
    fails_with(&r, "the run went past its time limit of 0.001 s");
    assert_eq!(s.files(), ["in.txt"]);

    let r = reverse("600");
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let r = subgram(
        s.0.path(),
        &[
            "reconstruct",
            "coarse.txt",
            "--details",
            "details.json",
            "-o",
            "restored.txt",
            "--timeout",
            "0.001",
        ],
    );
    fails_with(&r, "the run went past its time limit of 0.001 s");
    assert!(!s.files().contains(&"restored.txt".to_string()));
}

/// `A [ A [ ... ] ] C`: each A's right context skips the branch after it,
/// which holds every deeper A. Counting brackets made a step quadratic.
#[test]
fn right_contexts_skip_deep_branches_in_linear_time() {
    let s = Scratch::new("deep");
    let depth = 50_000;
    let mut text = String::from("module A; module B; module C;\nderivation length: 3;\nAxiom:");
    text.push_str(&" A SB()".repeat(depth));
    text.push_str(&" EB()".repeat(depth));
    text.push_str(" C;\nA > C -> B\n");
    s.write("deep.lsys", &text);
    let r = subgram(s.0.path(), &["derive", "deep.lsys", "--timeout", "20"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    // Only the outermost A sees C, past the whole branch.
    assert!(
        r.stdout.starts_with("B SB A SB A SB"),
        "{}",
        &r.stdout[..40]
    );
    assert!(r.stdout.trim_end().ends_with("EB EB C"));
    assert!(r.took < Duration::from_secs(20), "{:?}", r.took);
}

/// `ignore: A` and a run of A between two B: each A's contexts look past
/// the whole run, both ways. Walking it module by module was quadratic.
#[test]
fn contexts_skip_long_runs_of_ignored_modules_in_linear_time() {
    let s = Scratch::new("runs");
    let n = 100_000;
    let text = format!(
        "module A; module B; module C;\nignore: A;\nderivation length: 1;\nAxiom: B{} B;\nB < A > B -> C\n",
        " A".repeat(n)
    );
    s.write("runs.lsys", &text);
    let r = subgram(s.0.path(), &["derive", "runs.lsys", "--timeout", "20"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(r.stdout.trim(), format!("B{} B", " C".repeat(n)));
    assert!(r.took < Duration::from_secs(20), "{:?}", r.took);
}

/// A strict predecessor of two modules that wraps a ring's seam, whose
/// right context then skips ignored modules past the next turn: the scan
/// ran off the word (an index panic).
#[test]
fn a_context_after_a_predecessor_that_wraps_stays_on_the_ring() {
    let s = Scratch::new("wrap");
    s.write(
        "wrap.lsys",
        "module A; module B;\nring L-system: 1;\nignore: A;\nderivation length: 1;\n\
         Axiom: A A A;\nA() A() > B() -> B\n",
    );
    let r = subgram(s.0.path(), &["derive", "wrap.lsys", "--phase", "2"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(r.stdout.trim(), "A A A");
}

#[test]
fn the_axiom_counts_against_the_module_limit() {
    let s = Scratch::new("axiom");
    let text = format!(
        "module A(float);\nderivation length: 1;\nAxiom:{};\n",
        " A(1)".repeat(3000)
    );
    s.write("big.lsys", &text);
    let r = subgram(s.0.path(), &["derive", "big.lsys", "--max-modules", "2000"]);
    // The caret is under the first module past the limit.
    fails_with(
        &r,
        "big.lsys:3:10008: error: the axiom has 3000 modules, more than the limit of 2000; \
         raise the limit with --max-modules",
    );
    assert!(r.stderr.contains("\n  |"), "{}", r.stderr);
    let r = subgram(s.0.path(), &["derive", "big.lsys", "--max-modules", "3000"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

/// One body that produces in a loop: its successor alone would hold 90
/// million modules. The limit stops it at the production.
#[test]
fn a_successor_built_in_a_loop_counts_against_the_module_limit() {
    let s = Scratch::new("successor");
    s.write(
        "loop.lsys",
        "module A; module B;\nderivation length: 1;\nAxiom: A;\n\
         A : { int i = 0; while (i < 9000000) { nproduce B B B B B B B B B B; i = i + 1; } produce A; }\n",
    );
    let r = subgram(
        s.0.path(),
        &["derive", "loop.lsys", "--max-modules", "1000"],
    );
    fails_with(
        &r,
        "loop.lsys:4:1: error: at step 1, production `A()`: the word grew past 1000 modules; \
         raise the limit with --max-modules or derive fewer steps",
    );
    assert!(r.took < Duration::from_secs(10), "{:?}", r.took);
}

/// Decomposition and interpretation build words too.
#[test]
fn decomposition_and_interpretation_count_against_the_module_limit() {
    let s = Scratch::new("sections");
    s.write(
        "decompose.lsys",
        "module A;\nderivation length: 1;\nAxiom: A;\n\
         decomposition:\nmaximum depth: 100;\nA -> A A\n",
    );
    let r = subgram(
        s.0.path(),
        &["derive", "decompose.lsys", "--max-modules", "1000"],
    );
    fails_with(
        &r,
        "decompose.lsys:6:1: error: at step 0, decomposition rule `A()`: the word grew past 1000 modules",
    );
    s.write(
        "interpret.lsys",
        "module A;\nderivation length: 1;\nAxiom: A;\n\
         interpretation:\nmaximum depth: 100;\nA -> A A\n",
    );
    let r = subgram(
        s.0.path(),
        &[
            "derive",
            "interpret.lsys",
            "--interpreted",
            "--max-modules",
            "1000",
        ],
    );
    fails_with(
        &r,
        "interpret.lsys:6:1: error: at step 1, interpretation rule `A()`: the word grew past 1000 modules",
    );
}

/// Every path of a step (the uniform ring, the stencils, the interpreter)
/// names the production that made the word too long.
#[test]
fn the_module_limit_names_the_production_on_every_path() {
    let cases = [
        // One kind on a ring: the uniform stencil path.
        "module P(float);\nring L-system: 1;\nderivation length: 9;\nAxiom: P(1) P(2);\n\
         P(l) < P(x) > P(r) -> P(0.5*l + 0.5*x) P(0.5*x + 0.5*r)\n",
        // Two kinds, no branches: the stencil path.
        "// stencils\nmodule P(float); module Q;\nderivation length: 9;\nAxiom: P(1) Q;\n\
         P(x) -> P(x) P(0.5*x)\n",
        // A body: the interpreter.
        "// a body\nmodule P(float); module Q;\nderivation length: 9;\nAxiom: P(1) Q;\n\
         P(x) : { if (x > 0) produce P(x) P(0.5*x); }\n",
    ];
    for text in cases {
        let l = load_text(text);
        let e =
            subgram::derive(&l.program, DeriveOptions::default().with_max_modules(10)).unwrap_err();
        assert!(e.span.is_some(), "{text}");
        let shown = l.error(e).to_string();
        assert!(
            shown.starts_with("test.lsys:5:1: error: at step ")
                && shown.contains(", production `P(")
                && shown
                    .contains("the word grew past 10 modules; raise the limit with --max-modules"),
            "{shown}"
        );
    }
}

#[test]
fn a_drawing_that_overflows_names_its_module_step_and_maker() {
    let s = Scratch::new("overflow");
    s.write(
        "far.lsys",
        "module A(float);\nderivation length: 2;\nAxiom: A(1e308);\nA(x) -> F(x) A(x)\n",
    );
    // In lpfg's single precision, 1e308 is no float at all: the axiom
    // already holds an infinity.
    let r = subgram(s.0.path(), &["render", "far.lsys", "-o", "far.png"]);
    fails_with(
        &r,
        "far.lsys:3:8: error: parameter 1 of this successor module is inf",
    );
    // In double precision it is a number, and the turtle overflows.
    let r = subgram(
        s.0.path(),
        &["render", "far.lsys", "-o", "far.png", "--double"],
    );
    fails_with(
        &r,
        "far.lsys:4:1: error: at step 2, module 2 of the interpreted word, `F(1e308)`, \
         moves the turtle to an infinite coordinate, which cannot be drawn; \
         production `A(x)` made that module\n  |\n4 | A(x) -> F(x) A(x)\n  | ^^^^",
    );
    // Each step drawn: step 1 draws, step 2 overflows.
    let r = subgram(
        s.0.path(),
        &["render", "far.lsys", "-o", "far.png", "--each", "--double"],
    );
    fails_with(&r, "far.lsys:4:1: error: at step 2, module 2 ");
    s.write(
        "disc.lsys",
        "module A;\nderivation length: 0;\nAxiom: MoveTo2f(V2f(1e308, 0)) Circle(1e308);\n",
    );
    let r = subgram(
        s.0.path(),
        &["render", "disc.lsys", "-o", "disc.svg", "--double"],
    );
    fails_with(
        &r,
        "disc.lsys:3:32: error: at step 0, module 2 of the interpreted word, `Circle(1e308)`, \
         draws a circle that reaches an infinite coordinate, which cannot be drawn; \
         the axiom made that module",
    );
    assert_eq!(s.files(), ["disc.lsys", "far.lsys"]);

    // The library says the same, through an interpretation rule.
    let l = subgram::load_str_with(
        "test.lsys",
        "module A; module B;\nderivation length: 2;\nAxiom: A;\nA -> B A\n\
         interpretation:\nB -> F(1e308)\n",
        &[],
        subgram::Precision::Double,
    )
    .unwrap();
    let mut run = l.run(DeriveOptions::default()).unwrap();
    let e = run.events().unwrap_err().to_string();
    assert!(
        e.starts_with(
            "test.lsys:6:1: error: at step 2, module 2 of the interpreted word, `F(1e308)`, \
             moves the turtle to an infinite coordinate, which cannot be drawn; \
             interpretation rule `B()` made that module"
        ),
        "{e}"
    );
}
