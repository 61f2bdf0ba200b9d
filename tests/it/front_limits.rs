//! The front end's bounds (issue 11): every input it reads has one, and a
//! program that passes it is one the checker and the interpreter can run
//! without exhausting the stack or memory. The small bad inputs are files
//! in `tests/data/err/`; the big ones are generated here, so that the
//! repository does not hold megabytes of chains. Each is run through the
//! binary as a user would, and must end with exit code 1 (2 for a usage
//! error) and a message, in a few seconds, never with a panic or a signal.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use subgram::mesh::{shapes, Mesh};
use subgram::{DeriveOptions, LoadOptions, System};

use crate::support::scratch;

/// Runs the binary with `env` set, and says how long it took.
fn run_with(args: &[&str], env: &[(&str, &str)]) -> (Output, Duration) {
    let start = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .envs(env.iter().copied())
        .output()
        .expect("the binary runs");
    (o, start.elapsed())
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `subgram check FILE` ends with exit code 1 within `limit`, and its
/// message contains `want`.
fn refused(file: &Path, want: &str, limit: Duration) -> String {
    let (o, took) = run_with(&["check", file.to_str().unwrap()], &[]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{}: {err}", file.display());
    assert!(err.contains(want), "{}: {err}", file.display());
    assert!(!err.contains("panicked"), "{err}");
    assert!(took < limit, "{}: {took:?}", file.display());
    err
}

/// Chains of 400,000 links and more in 3 MB files: `=`, `?:` in a curve
/// body and `?:` in a surface grammar's assignment. They used to overflow
/// even the binary's 256 MB stack; the parser now counts each link as a
/// level of nesting and stops at the limit, pointing at the link.
#[test]
fn megabyte_chains_stop_at_the_nesting_limit() {
    let tmp = scratch("front-chains");
    let dir = tmp.path();
    let n = 400_000;
    let cases = [
        (
            "assign.lsys",
            format!(
                "module A(float);\nAxiom: A(1);\nA(x) : {{ float a; a = {}x; produce A(a); }}\n",
                "a = ".repeat(2 * n)
            ),
        ),
        (
            "cond.lsys",
            format!(
                "module A(float);\nAxiom: A(1);\nA(x) -> A({}1)\n",
                "x ? x : ".repeat(n)
            ),
        ),
        (
            "surface.lsys",
            format!(
                "mesh: \"cube.obj\";\nV(v) -> V(v = {}v);\n",
                "valence(v) ? v : ".repeat(n / 2)
            ),
        ),
    ];
    for (name, text) in cases {
        assert!(text.len() > 3_000_000, "{name}: {}", text.len());
        let f = dir.join(name);
        std::fs::write(&f, text).unwrap();
        let err = refused(
            &f,
            "error: this is nested more than 100 levels deep",
            Duration::from_secs(20),
        );
        assert!(err.starts_with(&format!("{}:", f.display())), "{err}");
    }
}

/// 200,000 nested macro calls in a 600 KB file used 8 GB: argument
/// nesting and the tokens that arguments carry are bounded now.
#[test]
fn deeply_nested_macro_arguments_are_refused() {
    let tmp = scratch("front-macro");
    let dir = tmp.path();
    let n = 200_000;
    let f = dir.join("macro.lsys");
    let text = format!(
        "#define F(x) x\nmodule A(float);\nAxiom: A({}1{});\n",
        "F(".repeat(n),
        ")".repeat(n)
    );
    std::fs::write(&f, text).unwrap();
    let err = refused(
        &f,
        "error: macro expansion is too large",
        Duration::from_secs(20),
    );
    assert!(err.starts_with(&format!("{}:3:", f.display())), "{err}");
}

/// A chain of 30,000 `#define`s, each naming the one before, took a
/// minute to check: expansion is linear now.
#[test]
fn a_chain_of_30000_defines_checks_quickly() {
    let tmp = scratch("front-defines");
    let dir = tmp.path();
    let n = 30_000;
    let mut text = String::from("#define D0 1\n");
    for i in 1..n {
        text += &format!("#define D{i} D{}\n", i - 1);
    }
    text += &format!("module A(float);\nAxiom: A(D{});\n", n - 1);
    let f = dir.join("defines.lsys");
    std::fs::write(&f, text).unwrap();
    let (o, took) = run_with(&["derive", f.to_str().unwrap(), "-n", "0"], &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(String::from_utf8_lossy(&o.stdout).trim(), "A(1)");
    assert!(took < Duration::from_secs(10), "{took:?}");
}

/// A device without a size, such as `/dev/zero`, is read up to the limit
/// and no further; a file over the limit is refused before it is read.
/// The message names the limit and the variable that raises it.
#[test]
fn inputs_have_a_size_limit() {
    let raise = "set SUBGRAM_MAX_PROGRAM_MIB to a larger number of mebibytes to raise the limit";
    if Path::new("/dev/zero").exists() {
        let (o, took) = run_with(&["check", "/dev/zero"], &[]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert_eq!(
            stderr(&o).trim(),
            format!(
                "/dev/zero: error: more than 16 MiB were read from it; a program may be at most \
                 16 MiB: {raise}"
            )
        );
        assert!(took < Duration::from_secs(10), "{took:?}");
    }
    let tmp = scratch("front-size");
    let dir = tmp.path();
    let f = dir.join("big.lsys");
    // 2 MiB and a bit of comment after a valid program.
    let mut text = String::from("module A;\nAxiom: A;\n");
    text += &"//345678901234567890123456789012345678901234567890123456789012\n".repeat(32 * 1024);
    std::fs::write(&f, &text).unwrap();
    let size = text.len();
    let big = f.to_str().unwrap();
    let (o, _) = run_with(&["check", big], &[("SUBGRAM_MAX_PROGRAM_MIB", "1")]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(
        stderr(&o).trim(),
        format!(
            "{big}: error: the file is 2.0 MiB ({size} bytes); a program may be at most 1 MiB: \
             {raise}"
        )
    );
    let (o, _) = run_with(&["check", big], &[("SUBGRAM_MAX_PROGRAM_MIB", "3")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (o, _) = run_with(&["check", big], &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    // A variable that says no number is a usage error.
    let (o, _) = run_with(&["check", big], &[("SUBGRAM_MAX_PROGRAM_MIB", "lots")]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("SUBGRAM_MAX_PROGRAM_MIB=lots: expected a whole number"));
}

/// `-D X` without `=`: curves and surface grammars alike, in every
/// command that takes `-D`, exit with 2 and the same message.
#[test]
fn a_define_without_a_value_is_a_usage_error_everywhere() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let curve = root.join("lsystems/curves/chaikin-13.lsys");
    let surface = root.join("lsystems/surfaces/loop.lsys");
    let (curve, surface) = (curve.to_str().unwrap(), surface.to_str().unwrap());
    let tmp = scratch("front-define");
    let dir = tmp.path();
    let png = dir.join("out.png");
    let obj = dir.join("out.obj");
    let (png, obj) = (png.to_str().unwrap(), obj.to_str().unwrap());
    let runs: [&[&str]; 6] = [
        &["check", curve, "-D", "X"],
        &["derive", curve, "-D", "X"],
        &["render", curve, "-o", png, "-D", "X"],
        &["check", surface, "-D", "X"],
        &["derive", surface, "-D", "X"],
        &["subdivide", "--grammar", surface, "-o", obj, "-D", "X"],
    ];
    for args in runs {
        let (o, _) = run_with(args, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert_eq!(
            stderr(&o).trim(),
            "error: `-D X` must have the form NAME=VALUE, e.g. -D STEPS=4",
            "{args:?}"
        );
    }
    assert!(!Path::new(png).exists() && !Path::new(obj).exists());
}

/// The other side of the limit: every kind of nesting, close to the limit,
/// checks and runs on a test thread's ordinary stack (2 MiB), in a debug
/// build. (`nesting_just_below_the_limit_works` in `errors` does the same
/// for parentheses and sums.)
#[test]
fn nesting_close_to_the_limit_runs_on_an_ordinary_stack() {
    let n = 95;
    let bodies = [
        // ?: chain: 1 + 1 + ... with the conditions all true.
        (
            format!("A(x) -> A({}0)", "x > 0 ? x : ".repeat(n / 2 - 2)),
            "A(1)",
        ),
        (
            format!(
                "A(x) : {{ float a; a = {}x + 1; produce A(a); }}",
                "a = ".repeat(n - 3)
            ),
            "A(2)",
        ),
        (format!("A(x) -> A({}x)", "- ".repeat(n - 2)), "A(-1)"),
        (format!("A(x) -> A({}x)", "(float)".repeat(n - 1)), "A(1)"),
        (
            format!("A(x) -> A({}x{})", "fabs(".repeat(n - 1), ")".repeat(n - 1)),
            "A(1)",
        ),
        (
            format!(
                "A(x) : {} produce A(x + 1); {}",
                "{".repeat(n - 1),
                "}".repeat(n - 1)
            ),
            "A(2)",
        ),
    ];
    for (body, want) in bodies {
        let text = format!("module A(float);\nderivation length: 1;\nAxiom: A(1);\n{body}\n");
        let l = subgram::load_str("deep.lsys", &text, &[]).unwrap_or_else(|e| panic!("{e}"));
        let d = subgram::derive(&l.program, DeriveOptions::default())
            .unwrap_or_else(|e| panic!("{}", l.error(e)));
        assert_eq!(
            subgram::output::word_text(&d.word, &l.program.alphabet, &l.program.structs),
            want,
            "{body}"
        );
    }
    // A field chain: a struct nested in itself is not a thing, so the
    // chain is a vector's component read through 90 structs.
    let mut text = String::from("struct S0 { float x; };\n");
    for i in 1..90 {
        text += &format!("struct S{i} {{ S{} x; }};\n", i - 1);
    }
    text += "S89 s;\nmodule A(float);\nderivation length: 1;\nAxiom: A(1);\n";
    text += &format!("A(x) -> A(s{} + 2)\n", ".x".repeat(90));
    let l = subgram::load_str("fields.lsys", &text, &[]).unwrap_or_else(|e| panic!("{e}"));
    let d = subgram::derive(&l.program, DeriveOptions::default())
        .unwrap_or_else(|e| panic!("{}", l.error(e)));
    assert_eq!(
        subgram::output::word_text(&d.word, &l.program.alphabet, &l.program.structs),
        "A(2)"
    );
}

/// A surface grammar's `define` functions nest inside their calls: a
/// chain of them close to the limit runs on the evaluation threads'
/// ordinary stacks; past it, the checker refuses it (the file
/// `surface-nesting-through-inlined-functions.lsys`).
#[test]
fn inlined_functions_close_to_the_limit_run() {
    // Each link is a call, its parameter's binding and a product: 3 levels.
    let links = 30;
    let mut text = String::from("mesh: \"unused.obj\";\ndefine f0(x) = x;\n");
    for i in 1..=links {
        text += &format!("define f{i}(x) = f{}(x) * 1.0;\n", i - 1);
    }
    text += &format!("V(v) -> V(v = f{links}(v));\n");
    let System::Surface(s) = subgram::load_text("deep.lsys", &text, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
    else {
        panic!("a surface grammar")
    };
    let mut mesh = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let before: Vec<_> = mesh.vertices().map(|v| mesh.position(v)).collect();
    s.run_on(&mut mesh, 1, None, |_| {})
        .unwrap_or_else(|e| panic!("{e}"));
    let after: Vec<_> = mesh.vertices().map(|v| mesh.position(v)).collect();
    assert_eq!(after, before);
}

/// Counts that the checker numbers with 16 bits: past 65,535 globals the
/// numbers wrapped and `g0 + g69999` read `g4463` (exit 0, a wrong
/// word); past 65,535 locals the interpreter indexed out of its frame (a
/// panic). Each is now refused once, at the first one too many, and the
/// lookups by name that made large programs quadratic are hashed (70,000
/// modules took 24 s, a struct of 70,000 fields 17 s). The module limit
/// is 65,535 kinds less the predefined ones (98 of them).
#[test]
fn declarations_past_what_16_bits_number_are_refused() {
    let tmp = scratch("front-counts");
    let dir = tmp.path();
    let n = 70_000;
    let mut globals = String::new();
    for i in 0..n {
        globals += &format!("float g{i} = {i};\n");
    }
    globals += &format!("module A(float);\nAxiom: A(g0 + g{});\n", n - 1);
    let mut locals = String::from("module A(float);\nAxiom: A(1);\nA(x) : {\n");
    for i in 0..n {
        locals += &format!("float v{i} = {i};\n");
    }
    locals += &format!("produce A(v0 + v{});\n}}\n", n - 1);
    let mut modules = String::new();
    for i in 0..n {
        modules += &format!("module M{i};\n");
    }
    modules += &format!("Axiom: M0 M{};\n", n - 1);
    let mut fields = String::from("struct S {");
    for i in 0..n {
        fields += &format!(" float f{i};");
    }
    fields += " };\nS s;\nmodule A(float);\nAxiom: A(s.f1);\n";
    let cases = [
        (
            "globals.lsys",
            globals,
            ":65536:7: error: more than 65535 global variables are declared",
        ),
        (
            "locals.lsys",
            locals,
            ":65538:7: error: more than 65535 local variables in one body",
        ),
        (
            "modules.lsys",
            modules,
            ":65436:8: error: more than 65435 modules are declared",
        ),
        (
            "fields.lsys",
            fields,
            ":1:906398: error: more than 65535 fields are declared in struct `S`",
        ),
    ];
    for (name, text, want) in cases {
        let f = dir.join(name);
        std::fs::write(&f, text).unwrap();
        let err = refused(&f, want, Duration::from_secs(20));
        // Once, not once per declaration past the limit, and first.
        assert_eq!(err.matches("error: more than").count(), 1, "{err}");
        assert!(err.starts_with(&format!("{}{want}", f.display())), "{err}");
    }
}

/// A thousand errors on one 2 MB line: rendering a diagnostic costs its
/// window, not its line (this took minutes), and a check reports the
/// first 100 and counts the rest.
#[test]
fn many_errors_on_one_long_line_are_reported_quickly_and_counted() {
    let tmp = scratch("front-errors");
    let dir = tmp.path();
    let f = dir.join("many.lsys");
    let n = 1_000_000;
    std::fs::write(&f, format!("module A;\nAxiom: {};\n", "Q ".repeat(n))).unwrap();
    let err = refused(&f, "error: undeclared module `Q`", Duration::from_secs(20));
    assert_eq!(err.matches(": error: ").count(), 101, "{}", err.len());
    assert!(
        err.contains(
            ":2:208: error: 999900 more errors from here on are not shown (at most 100 are)"
        ),
        "{}",
        &err[err.len() - 400..]
    );
}
