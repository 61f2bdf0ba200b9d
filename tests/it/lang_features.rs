//! The C side of L+C (manual sections 2 and 3): user-defined functions,
//! arrays, enums, static locals, casts, bodies without braces, strings
//! and the standard output. Each test is a small program whose expected
//! word is worked out by hand in the comments (or, where said, is lpfg's
//! own output).

use subgram::{DeriveOptions, ProgramOutput, Stream};

use crate::support::*;

#[test]
fn functions_of_every_return_type() {
    let src = "module A(int, float, V2f, bool);\n\
               struct S { int k; float w; };\n\
               int twice(int n) { return 2 * n; }\n\
               static inline float half(float x) { return x / 2; }\n\
               V2f swapped(V2f p) { return V2f(p.y, p.x); }\n\
               bool positive(float x) { return x > 0; }\n\
               S make(int k) { S s; s.k = k; s.w = k * 1.5; return s; }\n\
               int total = 0;\n\
               void add(int n) { total += n; }\n\
               derivation length: 1;\n\
               Axiom: A(3, 5, V2f(1, 2), false);\n\
               A(n, x, p, b) : { add(n); add(make(4).k); \
                 produce A(twice(n) + total, half(x) + make(2).w, swapped(p), positive(-x)); }\n";
    // twice(3) + total (3 + 4) = 13; half(5) + 2 * 1.5 = 5.5; (2, 1); -5 > 0 is false.
    assert_eq!(run(src), "A(13, 5.5, [2, 1], false)");
}

#[test]
fn recursion_and_mutual_recursion_in_any_order() {
    // isEven is declared before isOdd uses it and defined after; `fact`
    // is called from a global's initialiser; `fib` from a Start block.
    let src = "module A(int, int, int);\n\
               int isEven(int n);\n\
               int isOdd(int n) { if (n == 0) return 0; return isEven(n - 1); }\n\
               int isEven(int n) { if (n == 0) return 1; return isOdd(n - 1); }\n\
               int fact(int n) { return n <= 1 ? 1 : n * fact(n - 1); }\n\
               const int F5 = fact(5);\n\
               int fb = 0;\n\
               Start: { fb = fib(10); }\n\
               int fib(int n) { if (n < 2) return n; return fib(n - 1) + fib(n - 2); }\n\
               derivation length: 1;\n\
               Axiom: A(7, 0, 0);\n\
               A(n, a, b) -> A(isEven(n) * 10 + isOdd(n), F5, fb)\n";
    // 7 is odd: 0 * 10 + 1; 5! = 120; fib(10) = 55.
    assert_eq!(run(src), "A(1, 120, 55)");
}

/// 10,000 nested calls (the limit) run on a test thread's 2 MiB stack:
/// the interpreter moves deep call chains to stack segments of their own.
#[test]
fn recursion_to_the_limit_fits_any_stack_and_one_more_is_an_error() {
    let src = |n: u32| {
        format!(
            "module A(int);\n\
             int depth(int n) {{ if (n == 0) return 0; return 1 + depth(n - 1); }}\n\
             derivation length: 1;\nAxiom: A({n});\nA(n) -> A(depth(n))\n"
        )
    };
    // depth(9999) makes 10,000 nested calls (9999 down to 0).
    assert_eq!(run(&src(9999)), "A(9999)");
    let e = run_error(&src(10_000));
    assert!(e.contains("test.lsys:2:53"), "{e}");
    assert!(e.contains("nest more than 10000 deep"), "{e}");
}

#[test]
fn a_function_that_ends_without_return_is_a_runtime_error_at_its_end() {
    let src = "module A(float);\n\
               float f(float x) {\n  if (x > 0) return x;\n}\n\
               derivation length: 1;\nAxiom: A(-1);\nA(x) -> A(f(x))\n";
    let e = run_error(src);
    assert!(e.contains("test.lsys:4:1"), "{e}");
    assert!(e.contains("`f` reached its end without a `return`"), "{e}");
    // The same function with a positive argument returns.
    assert_eq!(run(&src.replace("A(-1)", "A(2)")), "A(2)");
}

#[test]
fn arrays_global_local_nested_and_zeroed() {
    let src = "module A(int, float, float, V2f);\n\
               int a[3] = {1, 2, 3};\n\
               float m[2][2] = {{1, 0}, {0, 1}};\n\
               V2f pts[4];\n\
               float partial[4] = {7};\n\
               int sizes[] = {4, 5, 6, 7, 8};\n\
               derivation length: 1;\n\
               Axiom: A(0, 0, 0, V2f(0, 0));\n\
               A(i, x, y, p) : {\n\
                 int b[3];\n\
                 b[0] = a[2] * 10; b[1] += 4; b[1]++; ++b[2];\n\
                 a[1] = 20; a[1] += 1;\n\
                 pts[2] = V2f(3, 4); pts[2].y = 9;\n\
                 m[1][0] = m[0][0] + 5;\n\
                 produce A(b[0] + b[1] + b[2] + a[1], m[1][0] + m[1][1] + partial[0] + partial[3], \
                           sizes[4] + pts[0].x, pts[2]);\n\
               }\n";
    // b = {30, 5, 1}, a[1] = 21: 30 + 5 + 1 + 21 = 57; m[1][0] = 6, m[1][1] = 1,
    // partial = {7, 0, 0, 0}: 14; sizes[4] = 8 and pts[0] is zero: 8.
    assert_eq!(run(src), "A(57, 14, 8, [3, 9])");
}

#[test]
fn arrays_in_structs_and_arrays_passed_to_functions() {
    let src = "module A(float, float, int);\n\
               struct S { float v[3]; int n; };\n\
               float sum(float a[], int n) { float s = 0; for (int i = 0; i < n; i++) s += a[i]; return s; }\n\
               void fill(float a[3], float v) { for (int i = 0; i < 3; ++i) a[i] = v * i; }\n\
               void bump(S &s) { s.n++; s.v[0] = 100; }\n\
               void swap(float &x, float &y) { float t = x; x = y; y = t; }\n\
               derivation length: 1;\n\
               Axiom: A(1, 2, 0);\n\
               A(x, y, k) : {\n\
                 S s; s.v[1] = 5; s.n = 1;\n\
                 bump(s);\n\
                 float w[3];\n\
                 fill(w, 2);\n\
                 swap(x, y);\n\
                 produce A(sum(s.v, 3) + sum(w, 3), x * 10 + y, s.n);\n\
               }\n";
    // s.v = {100, 5, 0}: 105; w = {0, 2, 4}: 6; 111. x, y swapped: 21. s.n = 2.
    assert_eq!(run(src), "A(111, 21, 2)");
}

#[test]
fn an_index_out_of_range_is_a_runtime_error_naming_the_line() {
    let read = "module A(int);\nint a[3];\nderivation length: 1;\nAxiom: A(3);\n\
                A(i) -> A(a[i])\n";
    let e = run_error(read);
    assert!(e.contains("test.lsys:5:11"), "{e}");
    assert!(
        e.contains("index 3 is out of range: the array has 3 element(s)"),
        "{e}"
    );
    let write = "module A(int);\nderivation length: 1;\nAxiom: A(-1);\n\
                 A(i) : {\n  float b[2];\n  b[i] = 1;\n  produce A(i);\n}\n";
    let e = run_error(write);
    assert!(e.contains("test.lsys:6:3"), "{e}");
    assert!(e.contains("index -1 is out of range"), "{e}");
}

#[test]
fn enums_casts_and_c_integer_types() {
    let src = "module A(int, int, float, int);\n\
               enum Kind { Apple, Pear = 5, Plum };\n\
               Kind favourite = Plum;\n\
               unsigned int u = 3; long long ll = 4; short s = 2; char c = 65; unsigned char uc = 1;\n\
               derivation length: 1;\nAxiom: A(0, 0, 0, 0);\n\
               A(a, b, x, d) -> A(Apple + Pear + favourite, int(2.7) + (int) 3.9, float(7) / 2 + double(1), \
                                  u + ll + s + c + uc)\n";
    // 0 + 5 + 6 = 11; 2 + 3 = 5; 3.5 + 1 = 4.5; 3 + 4 + 2 + 65 + 1 = 75.
    assert_eq!(run(src), "A(11, 5, 4.5, 75)");
}

#[test]
fn static_locals_keep_their_value_from_call_to_call() {
    // C: a static is initialised once. `next` counts its calls over the
    // whole derivation; the production's own static counts the modules
    // it rewrote.
    let src = "module A(int, int);\n\
               int next() { static int calls = 10; calls++; return calls; }\n\
               derivation length: 2;\nAxiom: A(0, 0) A(0, 0);\n\
               A(x, y) : { static int seen; seen += 1; produce A(next(), seen); }\n";
    // Step 1 rewrites the two modules in order: (11, 1) (12, 2); step 2: (13, 3) (14, 4).
    assert_eq!(run(src), "A(13, 3) A(14, 4)");
}

#[test]
fn bodies_without_braces() {
    let src = "module A(float);\nmodule B;\n\
               derivation length: 3;\nAxiom: A(0) B;\n\
               A(t) : if (t > 1) produce B; else produce A(t + 1);\n\
               B : produce B B;\n";
    // A: 0 -> 1 -> 2 -> B; B doubles three times, once it exists.
    assert_eq!(run(src), "B B B B B B B B B");
}

/// Issue 12, item 10: a variable may be named like a module; modules
/// appear only in predecessors, successors and the axiom.
#[test]
fn variables_may_be_named_like_modules() {
    let src = "module P(V2f);\n\
               V2f a(0, 0), b(1, 0), f(6, 0);\n\
               float F = 2;\n\
               derivation length: 1;\nAxiom: P(a) F(1) f(1);\n\
               P(v) : { V2f Left = f + b; produce P(Left * F) F(F) f(F); }\n";
    assert_eq!(run(src), "P([14, 0]) F(2) f(2) F(1) f(1)");
}

/// Issue 12, item 11: a line that starts with two module names is a
/// production with a context, not a declaration `Type name(...)`.
#[test]
fn a_context_of_several_modules_starts_a_production() {
    let src = "module B;\nmodule P(float);\n\
               derivation length: 1;\nAxiom: B P(1) P(2) P(3);\n\
               B P(vl) < P(v) > P(vr) : { produce P(vl + v + vr); }\n\
               P(v) : { produce P(v * 10); }\n";
    // Only P(2) has B P(..) on its left and P(..) on its right.
    assert_eq!(run(src), "B P(10) P(6) P(30)");
}

#[test]
fn strings_sprintf_and_the_string_functions() {
    let src = "module A(int, int, int, int);\n\
               char buf[64];\n\
               char name[16] = \"leaf\";\n\
               derivation length: 1;\nAxiom: A(0, 0, 0, 0);\n\
               A(a, b, c, d) : {\n\
                 sprintf(buf, \"%s-%03d|%5.2f\", name, 7, 3.14159);\n\
                 strcat(buf, \"!\");\n\
                 char copy[64]; strcpy(copy, buf);\n\
                 produce A(strlen(buf), strcmp(copy, buf), strcmp(name, \"stem\"), buf[5]);\n\
               }\n";
    // "leaf-007| 3.14!" has 15 characters; the copy equals it; "leaf" <
    // "stem"; buf[5] is '0', 48.
    assert_eq!(run(src), "A(15, 0, -1, 48)");
}

#[test]
fn printed_text_goes_to_the_output_and_not_into_the_word() {
    let src = "module A(int);\nderivation length: 2;\n\
               Start: { printf(\"start\\n\"); }\nAxiom: A(1);\n\
               A(n) : { Printf(\"n=%d \", n); fprintf(stderr, \"e%d\", n); produce A(n + 1); }\n";
    let l = load_text(src);
    let out = ProgramOutput::new();
    let d = derive(&l, DeriveOptions::default().with_output(out.clone()));
    assert_eq!(text(&l, &d), "A(3)");
    assert_eq!(
        out.take_text(),
        vec![
            (Stream::Stdout, "start\nn=1 ".to_string()),
            (Stream::Stderr, "e1".to_string()),
            (Stream::Stdout, "n=2 ".to_string()),
            (Stream::Stderr, "e2".to_string()),
        ]
    );
}

#[test]
fn fopen_needs_allow_writes_and_a_path_inside_the_folder() {
    let src = "module A(int);\nderivation length: 1;\nAxiom: A(1);\n\
               A(n) : {\n  FILE *f = fopen(\"NAME\", \"w\");\n  fprintf(f, \"%d\\n\", n);\n  fclose(f);\n  produce A(n);\n}\n";
    let e = run_error(&src.replace("NAME", "out.txt"));
    assert!(e.contains("test.lsys:5:13"), "{e}");
    assert!(e.contains("--allow-writes"), "{e}");

    let tmp = scratch("fopen");
    let dir = tmp.path();
    let file = dir.join("prog.lsys");
    std::fs::write(&file, src.replace("NAME", "sub/out.txt")).unwrap();
    let mut args = subgram::command::DeriveArgs::new(file.to_str().unwrap());
    args.allow_writes = Some(dir.to_path_buf());
    assert_eq!(
        subgram::command::derive(&args, |_| {}).unwrap().text,
        "A(1)"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("sub/out.txt")).unwrap(),
        "1\n"
    );

    std::fs::write(&file, src.replace("NAME", "../escape.txt")).unwrap();
    let e = subgram::command::derive(&args, |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("only inside the --allow-writes folder"), "{e}");
    assert!(!dir.join("../escape.txt").exists());
}

#[test]
fn calls_are_checked_where_they_are_written() {
    let base = "module A(float);\n\
                float f(float x, V2f p) { return x + p.x; }\n\
                derivation length: 1;\nAxiom: A(1);\n";
    let e = load_error(&format!("{base}A(x) -> A(f(x))\n"));
    assert!(e.contains("test.lsys:5:11"), "{e}");
    assert!(
        e.contains("`f` takes 2 argument(s) (float, V2f), but 1 were given"),
        "{e}"
    );
    let e = load_error(&format!("{base}A(x) -> A(f(x, x))\n"));
    assert!(e.contains("test.lsys:5:16"), "{e}");
    assert!(
        e.contains("type mismatch in argument 2 of `f`: expected V2f, found float"),
        "{e}"
    );
    let e = load_error(&format!("{base}A(x) -> A(g(x))\n"));
    assert!(e.contains("unknown function `g`"), "{e}");
    let e = load_error(
        "module A(float);\nV2f g(float x) { return x; }\nderivation length: 1;\nAxiom: A(1);\n",
    );
    assert!(e.contains("test.lsys:2:25"), "{e}");
    assert!(
        e.contains("type mismatch: expected V2f, found float"),
        "{e}"
    );
}

/// The same program run by lpfg (vlab commit 9bf820d, through
/// /work/shared/tools/lpfg/run_lpfg.sh) printed
/// `A(3,4167.502) B(43.5) B(44.5) B(45.5)`. lpfg computes `float` in single
/// precision, so the second parameter is compared to 1e-6 relative.
#[test]
fn functions_agree_with_lpfg() {
    let src = "module A(int, float);\nmodule B(float);\n\
               enum Kind { Apple, Pear = 5, Plum };\n\
               float sq(float x) { return x * x; }\n\
               int fact(int n) { if (n <= 1) return 1; return n * fact(n - 1); }\n\
               int counter() { static int c = 0; c++; return c; }\n\
               int isEven(int n);\n\
               int isOdd(int n) { if (n == 0) return 0; return isEven(n - 1); }\n\
               int isEven(int n) { if (n == 0) return 1; return isOdd(n - 1); }\n\
               V2f mid(V2f a, V2f b) { return (a + b) / 2; }\n\
               void swap(float &a, float &b) { float t = a; a = b; b = t; }\n\
               V2f a(0,0), b(1,0), c(6,0);\n\
               const int N = fact(4);\n\
               derivation length: 3;\nAxiom: A(0, 0);\nproduction:\n\
               A(n, x) : {\n  float p = 1, q = 2;\n  swap(p, q);\n\
                 produce A(n + 1, sq(x) / (x + 1) + x / 2 + counter() * 100 + isEven(n) * 1000 + p * 10) \
                 B(mid(a, c).x + Pear + float(7)/2 + int(2.7) + N + Plum);\n}\n\
               B(x) : produce B(x + 1);\n";
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    let word = text(&l, &d);
    let (head, tail) = word.split_once(") ").unwrap();
    assert_eq!(tail, "B(43.5) B(44.5) B(45.5)");
    let x: f64 = head.trim_start_matches("A(3, ").parse().unwrap();
    assert!(((x - 4167.502) / 4167.502).abs() < 1e-6, "{word}");
}

/// `lsystems/lplusc/table-tree.lsys`: 7 steps of a binary tree make
/// 2^7 - 1 = 127 internodes and 128 apices numbered 127 to 254 (the
/// static counter gave 0 to the axiom, then 1, 2, ... in the order the
/// apices grew); an internode of order 6 is 10 times the product of the
/// ratios 0.82, 0.7, 0.76, 0.66, 0.82, 0.7 (the table read cyclically),
/// 1.6022... long.
#[test]
fn the_table_tree_example() {
    let l = load(&lsys("lplusc/table-tree.lsys"));
    let d = derive(&l, DeriveOptions::default());
    let word = text(&l, &d);
    assert_eq!(word.matches("I(").count(), 127);
    let apices: Vec<&str> = word.split("A(").skip(1).collect();
    assert_eq!(apices.len(), 128);
    assert!(apices[0].starts_with("7, 127)"), "{}", apices[0]);
    assert!(apices[127].starts_with("7, 254)"), "{}", apices[127]);
    let order6 = 10.0 * 0.82 * 0.7 * 0.76 * 0.66 * 0.82 * 0.7;
    let len: f64 = word
        .split("I(")
        .nth(7)
        .and_then(|s| s.split(')').next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    // The program multiplies in single precision (lpfg's `float`): six
    // roundings of at most 2^-24 relative each.
    assert!(
        (len - order6).abs() < 6.0 * order6 * 2f64.powi(-24),
        "{len} {order6}"
    );
}

#[test]
fn typedefs_of_structs_and_enums_and_arrays_of_strings() {
    let src = "typedef struct SegTag { float len; int kind; } Seg;\n\
               typedef enum { Short, Long } Size;\n\
               module A(Seg, int, int);\n\
               const char *names[] = {\"apex\", \"node\"};\n\
               struct SegTag twice(Seg s) { s.len *= 2; return s; }\n\
               Seg first = {1.5, 1};\n\
               derivation length: 1;\nAxiom: A(first, 0, 0);\n\
               A(s, a, b) : { Size z = Long; produce A(twice(s), z, strlen(names[1]) * 10 + strlen(names[0])); }\n";
    // 1.5 doubled; Long is 1; "node" and "apex" have 4 characters each.
    assert_eq!(run(src), "A({3, 1}, 1, 44)");
}

/// A recursion without loops (fib(40) makes about 300 million calls)
/// stops at the run's deadline: calls look at it as loops do.
#[test]
fn a_long_recursion_stops_at_the_deadline() {
    let src = "module A(float);\n\
               float fib(int n) { return n < 2 ? n : fib(n - 1) + fib(n - 2); }\n\
               derivation length: 1;\nAxiom: A(40);\nA(n) -> A(fib(n))\n";
    let l = load_text(src);
    let opts = DeriveOptions::default().with_deadline(Some(subgram::Deadline::after(
        std::time::Duration::from_millis(300),
    )));
    let start = std::time::Instant::now();
    let e = l
        .error(subgram::derive(&l.program, opts).unwrap_err())
        .to_string();
    assert!(e.contains("time limit"), "{e}");
    assert!(e.contains("test.lsys:2:"), "{e}");
    assert!(start.elapsed() < std::time::Duration::from_secs(10));
}

/// `--format json` keeps standard output for the word alone: what the
/// program prints goes to standard error there, and before the word in
/// text mode.
#[test]
fn printed_text_and_the_json_word_do_not_mix() {
    let tmp = scratch("printf");
    let dir = tmp.path();
    let file = dir.join("p.lsys");
    std::fs::write(
        &file,
        "module A(int);\nderivation length: 1;\nAxiom: A(1);\n\
         A(n) : { printf(\"n is %d\\n\", n); fprintf(stderr, \"to stderr\\n\"); produce A(n + 1); }\n",
    )
    .unwrap();
    let run = |json: bool| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"));
        c.arg("derive").arg(&file);
        if json {
            c.args(["--format", "json"]);
        }
        let o = c.output().unwrap();
        assert!(o.status.success());
        (
            String::from_utf8(o.stdout).unwrap(),
            String::from_utf8(o.stderr).unwrap(),
        )
    };
    let (out, err) = run(false);
    assert_eq!(out, "n is 1\nA(2)\n");
    assert_eq!(err, "to stderr\n");
    let (out, err) = run(true);
    let word: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(word["modules"][0]["params"][0], 2);
    assert_eq!(err, "n is 1\nto stderr\n");
}

/// `End` runs after the final derivation step (manual §4.1) on every path
/// a user takes: `derive` and `render` print what it prints. lpfg 9bf820d
/// prints `end after 2 steps` for this program.
#[test]
fn end_runs_after_the_final_step_for_derive_and_render() {
    let tmp = scratch("end");
    let dir = tmp.path();
    let file = dir.join("end.l");
    std::fs::write(
        &file,
        "derivation length: 2;\nint n;\nmodule A;\nStart: { n = 0; }\nEndEach: { n = n + 1; }\n\
         End: { printf(\"end after %d steps\\n\", n); }\nAxiom: A;\nA : { produce A F; }\n",
    )
    .unwrap();
    let run = |args: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
            .args(args)
            .arg(&file)
            .current_dir(dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap()
    };
    assert_eq!(run(&["derive"]), "end after 2 steps\nA F F\n");
    assert_eq!(run(&["render", "-o", "end.png"]), "end after 2 steps\n");
}

// ----- switch, character constants, C++ structs (issue 12, C++ forms) -----

/// Fall-through, `break` leaving the switch, `continue` in a switch going
/// to the loop, `default` in the middle, a character label. By hand, per
/// iteration of the loop (four of them): n = 0 runs `case 0` (+1) and
/// falls into `case 1` (+10), breaks, then +10000: 10011, ×4 = 40044;
/// n = 1: 10010 ×4; n = 2 and n = 7 match no label and start at
/// `default` (+100), fall into `case 3` (+1000) and `continue` before the
/// +10000: 1100 ×4 = 4400; n = 3: 1000 ×4; n = 'a' (97): +5, the end of
/// the switch, +10000: 40020. lpfg 9bf820d prints the same string
/// (`A(0,40044) A(1,40040) A(2,4400) A(3,4000) A(7,4400) A(97,40020)`).
#[test]
fn switch_falls_through_and_break_leaves_it_as_in_c() {
    let src = "module A(int, int);\n\
               derivation length: 1;\n\
               Axiom: A(0, 0) A(1, 0) A(2, 0) A(3, 0) A(7, 0) A('a', 0);\n\
               A(n, m) : {\n\
                 int r = 0;\n\
                 int i;\n\
                 for (i = 0; i < 4; i++) {\n\
                   switch (n) {\n\
                     case 0: r += 1;\n\
                     case 1: r += 10; break;\n\
                     default: r += 100;\n\
                     case 3: r += 1000; continue;\n\
                     case 'a': r += 5;\n\
                   }\n\
                   r += 10000;\n\
                 }\n\
                 produce A(n, r);\n\
               }\n";
    assert_eq!(
        run(src),
        "A(0, 40044) A(1, 40040) A(2, 4400) A(3, 4000) A(7, 4400) A(97, 40020)"
    );
}

/// Switches in a function (with `return` inside, nested, enumerators and
/// a `const int` expression as labels, `default` first), in a Start block,
/// on a bool, and with a single statement as the body. By hand:
/// classify(0): 0 % 4 is Bud, the inner switch has `case 0`: 10;
/// classify(1): Leaf, no inner label, 12; classify(2): Twig - 5 = 2,
/// `break`, 13; classify(3): `default`, 100; classify(5): 5 % 4 = 1,
/// inner `case 5`, 11; classify(6): 2, 13. Then n > 2 (3, 5, 6) adds 1000
/// and falls into `false`'s 20000 (Start set `started` to 1); n = 6 is
/// negated. lpfg 9bf820d prints the same string.
#[test]
fn switch_in_functions_control_blocks_and_on_bools() {
    let src = "enum Organ { Bud, Leaf, Flower };\n\
               const int Twig = 7;\n\
               module A(int, int);\n\
               int started = 0;\n\
               int classify(int n) {\n\
                 switch (n % 4) {\n\
                   default:\n\
                     return 100;\n\
                   case Bud:\n\
                   case Leaf:\n\
                     switch (n) {\n\
                       case 0: return 10;\n\
                       case 5: return 11;\n\
                     }\n\
                     return 12;\n\
                   case Twig - 5:\n\
                     break;\n\
                 }\n\
                 return 13;\n\
               }\n\
               Start: { switch (Twig) { case 7: started = 1; } }\n\
               derivation length: 1;\n\
               Axiom: A(0, 0) A(1, 0) A(2, 0) A(3, 0) A(5, 0) A(6, 0);\n\
               A(n, m) : {\n\
                 int r = classify(n);\n\
                 switch (n > 2) {\n\
                   case true: r += 1000;\n\
                   case false: r += started * 20000;\n\
                 }\n\
                 switch (n) case 6: r = -r;\n\
                 produce A(n, r);\n\
               }\n";
    assert_eq!(
        run(src),
        "A(0, 20010) A(1, 20012) A(2, 20013) A(3, 21100) A(5, 21011) A(6, -21013)"
    );
}

/// A `switch` with no matching label and no `default` runs nothing; a
/// `break` in a loop inside a switch leaves the loop only. By hand: n = 4
/// matches nothing, r stays 0; n = 1 runs the loop, where i = 0 and i = 1
/// add 1 each before the `break` at i = 2, then the case goes on after
/// the loop with +50: 52. lpfg 9bf820d prints the same string.
#[test]
fn switch_without_a_match_and_loops_inside_cases() {
    let src = "module A(int, int);\n\
               derivation length: 1;\n\
               Axiom: A(4, 0) A(1, 0);\n\
               A(n, m) : {\n\
                 int r = 0;\n\
                 switch (n) {\n\
                   case 1: {\n\
                     int i;\n\
                     for (i = 0; i < 10; i++) { if (i == 2) break; r += 1; }\n\
                     r += 50;\n\
                     break;\n\
                   }\n\
                   case 2: r = 99;\n\
                 }\n\
                 produce A(n, r);\n\
               }\n";
    assert_eq!(run(src), "A(4, 0) A(1, 52)");
}

/// Character constants are ints: their ASCII codes ('a' 97, newline 10,
/// NUL 0, quote 39, backslash 92, 'A' 65 in hex and in octal), and
/// arithmetic on them ('z' - 'a' + 1 = 26). lpfg 9bf820d gives the same
/// values for each one but the backslash, which its translator refuses.
#[test]
fn character_constants_are_ints() {
    let src = "module C(int, int, int, int, int, int, int, int);\n\
               derivation length: 1;\n\
               Axiom: C(0, 0, 0, 0, 0, 0, 0, 0);\n\
               C(p1, p2, p3, p4, p5, p6, p7, p8) : {\n\
                 int q = '\\'';\n\
                 char z = 'z';\n\
                 produce C('a', '\\n', '\\0', q, '\\\\', '\\x41', '\\101', z - 'a' + 1);\n\
               }\n";
    assert_eq!(run(src), "C(97, 10, 0, 39, 92, 65, 65, 26)");
}

/// Constructors: `Leaf p;` calls the one without parameters (and the
/// field `bud` is built by `Bud`'s: kind 7, size 0), a parameter hides
/// the field of its name (`length(length * 2)`: 8), the initialiser
/// list's order does not matter, the body runs after it and may `return`
/// early, fields left alone are zero; an enum in the struct gives
/// constants (Small 0, Large 5, Huge 6), also as `Leaf::Large`. By hand:
/// p: grade 0, 1.5, 2, bud 7 and 0; q: 0, 8, 3, 7, 0; r = Leaf(2.5, 11):
/// Huge (6), 2.5, 11, then Small 0 and Huge 6; t = Leaf(1, 3): Large
/// (5), 1, 3, Huge 6, 'A' 65. lpfg 9bf820d prints the same string.
#[test]
fn constructors_and_enums_in_structs() {
    let src = "#include <memory.h>\n#include <string.h>\n#include <cstdlib>\n\
               struct Bud {\n\
                 int kind;\n\
                 float size;\n\
                 Bud() { kind = 7; }\n\
               };\n\
               struct Leaf {\n\
                 enum { Small, Large = 5, Huge } grade;\n\
                 float length;\n\
                 int age;\n\
                 Bud bud;\n\
                 Leaf(void) : length(1.5), age(2) {}\n\
                 Leaf(float length) : length(length * 2) { age = 3; }\n\
                 Leaf(float l, int a) : age(a), length(l) {\n\
                   if (a > 10) { grade = Huge; return; }\n\
                   grade = Leaf::Large;\n\
                 }\n\
               };\n\
               module B(int, float, int, int, float);\n\
               derivation length: 1;\n\
               Axiom: B(0, 0, 0, 0, 0);\n\
               B(x1, x2, x3, x4, x5) : {\n\
                 Leaf p;\n\
                 Leaf q(4);\n\
                 Leaf r = Leaf(2.5, 11);\n\
                 Leaf t = Leaf(1, 3);\n\
                 nproduce B(p.grade, p.length, p.age, p.bud.kind, p.bud.size);\n\
                 nproduce B(q.grade, q.length, q.age, q.bud.kind, q.bud.size);\n\
                 nproduce B(r.grade, r.length, r.age, Leaf::Small, Leaf::Huge);\n\
                 produce B(t.grade, t.length, t.age, Leaf::Huge, 'A');\n\
               }\n";
    assert_eq!(
        run(src),
        "B(0, 1.5, 2, 7, 0) B(0, 8, 3, 7, 0) B(6, 2.5, 11, 0, 6) B(5, 1, 3, 6, 65)"
    );
}

/// The vlab model UserMenu's struct (an enum member and a constructor
/// with an initialiser list) as a module parameter, switched on by a
/// choice: lpfg 9bf820d gives, for choices 0, 1, 2, 3 and 9, the structs
/// {1, 0}, {1, 1}, {4, 0}, {4, 1} and {1, 1} (the last unchanged from
/// `ShapeData()`: BLUE, SD_Circle), for this very program (its string
/// shows the structs as the bytes of two int32s).
#[test]
fn the_user_menu_models_struct_and_switch() {
    let src = "const int BLUE = 1, GREEN = 2, RED = 4;\n\
               struct ShapeData {\n\
                 int colour;\n\
                 enum { SD_Square, SD_Circle } shape;\n\
                 ShapeData(void) : colour(BLUE), shape(SD_Circle) {}\n\
               };\n\
               module Shape(ShapeData, int);\n\
               derivation length: 1;\n\
               Axiom: Shape(ShapeData(), 0) Shape(ShapeData(), 1) Shape(ShapeData(), 2) \
                      Shape(ShapeData(), 3) Shape(ShapeData(), 9);\n\
               Shape(sd, choice) : {\n\
                 switch (choice) {\n\
                 case 0: sd.colour = BLUE; sd.shape = ShapeData::SD_Square; break;\n\
                 case 1: sd.colour = BLUE; sd.shape = ShapeData::SD_Circle; break;\n\
                 case 2: sd.colour = RED; sd.shape = ShapeData::SD_Square; break;\n\
                 case 3: sd.colour = RED; sd.shape = ShapeData::SD_Circle; break;\n\
                 default: break;\n\
                 }\n\
                 produce Shape(sd, choice);\n\
               }\n";
    assert_eq!(
        run(src),
        "Shape({1, 0}, 0) Shape({1, 1}, 1) Shape({4, 0}, 2) Shape({4, 1}, 3) Shape({1, 1}, 9)"
    );
}

/// A struct without constructors: `S()` is zero and `S(a, b)` sets the
/// fields in order; two structs that both declare `None` need `S::None`,
/// and an enumerator outside structs keeps its plain name.
#[test]
fn struct_values_without_constructors_and_scoped_enumerators() {
    let src = "struct P { int a; float b; enum { None, One } k; };\n\
               struct Q { enum { None = 3, Two } k; };\n\
               enum { Solo = 8 };\n\
               module A(P, int, int, int);\n\
               derivation length: 1;\n\
               Axiom: A(P(), 0, 0, 0);\n\
               A(p, x, y, z) -> A(P(2, 0.5, One), P::None, Q::None, Solo + Two)\n";
    // P(2, 0.5, One): {2, 0.5, 1}; P::None 0, Q::None 3; Solo 8 + Two 4.
    assert_eq!(run(src), "A({2, 0.5, 1}, 0, 3, 12)");
    let e = load_error(&src.replace("P::None, Q::None", "None, Q::None"));
    assert!(
        e.contains("more than one struct declares an enumerator `None`: write `Struct::None`"),
        "{e}"
    );
}

/// The standard headers are accepted (their functions are built in), in
/// either form; a program's own header is not.
#[test]
fn standard_headers_are_accepted() {
    let headers = [
        "memory.h", "string.h", "stdlib.h", "stdio.h", "math.h", "cmath", "cstdlib", "cstdio",
        "cstring", "iostream", "assert.h", "time.h",
    ];
    for h in headers {
        let src = format!("#include <{h}>\nmodule A(float);\nAxiom: A(sqrt(4));\n");
        assert_eq!(run(&src), "A(2)", "{h}");
    }
    // As in C, `"string.h"` finds the standard header when no file of
    // the program has that name.
    assert_eq!(
        run("#include \"string.h\"\nmodule A(int);\nAxiom: A(strlen(\"abc\"));\n"),
        "A(3)"
    );
    let e = load_error("#include \"growth.h\"\nmodule A;\nAxiom: A;\n");
    assert!(
        e.contains("a program's own header files are not read"),
        "{e}"
    );
}

/// C++ builds every struct that has a constructor without parameters,
/// wherever one is made without an initialiser: in arrays, as fields of a
/// struct without constructors (itself in a local, a global, or made by
/// `Node()`), and as fields of a `class` with `public:`. By hand, every
/// `Bud` is kind 7, size 0.5; `a(4)` has n 4. lpfg 9bf820d prints the
/// same string. (`nd.w` is not read: C++ leaves it undefined, subgram
/// makes it zero.)
#[test]
fn default_constructors_build_arrays_and_fields() {
    let src = "struct Bud {\n\
                 int kind;\n\
                 float size;\n\
                 Bud() : size(0.5) { kind = 7; }\n\
               };\n\
               struct Node { float w; Bud buds[3]; Bud main; };\n\
               class Apex {\n\
               public:\n\
                 int n;\n\
                 Bud b;\n\
                 Apex(int k) : n(k) {}\n\
               };\n\
               Bud global_buds[2];\n\
               Node gnode;\n\
               module B(int, float, int, float, float);\n\
               derivation length: 1;\n\
               Axiom: B(0, 0, 0, 0, 0);\n\
               B(x1, x2, x3, x4, x5) : {\n\
                 Node nd;\n\
                 Bud bs[2];\n\
                 Apex a(4);\n\
                 nproduce B(nd.buds[2].kind, nd.buds[1].size, nd.main.kind, nd.main.size, bs[1].size);\n\
                 nproduce B(global_buds[1].kind, gnode.main.size, a.n, a.b.size, a.b.kind);\n\
                 produce B(Node().buds[0].kind, 0, 0, 0, 0);\n\
               }\n";
    assert_eq!(
        run(src),
        "B(7, 0.5, 7, 0.5, 0.5) B(7, 0.5, 4, 0.5, 7) B(7, 0, 0, 0, 0)"
    );
}

/// Methods: the body reads and writes the fields by their names, and the
/// variable it is called on keeps what it wrote (also an array element in
/// a field); `const` after the parameters is accepted. By hand: p(3) has
/// area 3 * 3 / 2 = 4.5; grow(1) and grow(0.5) make it 4.5 long and 2
/// old, older(10) 12; its area is then 4.5 * 4.5 / 2 = 10.125. q.b[1]
/// grows from 5 to 7 (age 1), whose area, 24.5, q.a grows by: 25.5;
/// q.b[0] keeps 2. lpfg 9bf820d prints the same string.
#[test]
fn struct_methods_write_back_to_their_variable() {
    let src = "struct Leaf {\n\
                 float length;\n\
                 int age;\n\
                 float area() const { return length * length / 2; }\n\
                 void grow(float by) { length += by; age++; }\n\
                 int older(int years) { age = age + years; return age; }\n\
                 Leaf(float l) : length(l), age(0) {}\n\
               };\n\
               struct Pair { Leaf a; Leaf b[2]; };\n\
               module B(float, int, float, int, float);\n\
               derivation length: 1;\n\
               Axiom: B(0, 0, 0, 0, 0);\n\
               B(x1, x2, x3, x4, x5) : {\n\
                 Leaf p(3);\n\
                 Pair q = { Leaf(1), { Leaf(2), Leaf(5) } };\n\
                 float a0 = p.area();\n\
                 p.grow(1);\n\
                 p.grow(0.5);\n\
                 int o = p.older(10);\n\
                 q.b[1].grow(2);\n\
                 q.a.grow(q.b[1].area());\n\
                 produce B(p.length, p.age, a0, o, p.area()) \
                   B(q.a.length, q.a.age, q.b[1].length, q.b[1].age, q.b[0].length);\n\
               }\n";
    assert_eq!(run(src), "B(4.5, 12, 4.5, 12, 10.125) B(25.5, 1, 7, 1, 2)");
}

/// A module produced inside a `switch` is seen like any other: lpfg's
/// `Label`, which subgram does not draw, is warned about at its place.
#[test]
fn modules_produced_in_a_switch_are_warned_about() {
    let src = "module A(int);\n\
               derivation length: 1;\n\
               Axiom: A(1);\n\
               A(n) : { switch (n) { case 1: produce Label(\"a\") A(2); } }\n";
    let l = load_text(src);
    let warned: Vec<String> = l
        .program
        .warnings
        .iter()
        .map(|d| d.message.clone())
        .collect();
    assert!(
        warned.iter().any(|m| m.contains("`Label` is not drawn")),
        "{warned:?}"
    );
}
