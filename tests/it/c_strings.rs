//! C's string functions check the destination's declared size: a string
//! written into `char b[N]` takes at most N - 1 characters and its
//! terminating NUL. One that does not fit is a located error (when the
//! program is checked if its text is known then, else when it runs),
//! never a silent overflow; a `char *` has no declared size and is not
//! checked.

use crate::support::*;

/// A program whose rule for `A(5)` runs `body` (from line 6 on), then
/// produces `out`.
fn rule(body: &str, out: &str) -> String {
    format!(
        "module A(int);\nmodule B(int, int);\nderivation length: 1;\nAxiom: A(5);\n\
         A(n) : {{\n{body}\n  produce {out};\n}}\n"
    )
}

#[test]
fn sprintf_past_the_declared_size_is_an_error_where_it_is_called() {
    // Its arguments are literals: refused when the program is checked.
    let src = rule(
        "  char b[4];\n  sprintf(b, \"%s%s\", \"0123456789\", \"abcdef\");",
        "A(strlen(b))",
    );
    let e = load_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains(
            "sprintf writes 16 characters and the terminating NUL into `b`, \
             declared `char b[4]` (room for 3 characters)"
        ),
        "{e}"
    );
    // A number known when it runs: 12345 has 5 digits.
    let src = rule(
        "  char b[4];\n  sprintf(b, \"%d\", n * 2469);",
        "A(strlen(b))",
    );
    let e = run_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains(
            "sprintf writes 5 characters and the terminating NUL into `b`, \
             declared `char b[4]` (room for 3 characters)"
        ),
        "{e}"
    );
    // The line and a caret under the call.
    assert!(e.contains("sprintf(b, \"%d\", n * 2469);"), "{e}");
    assert!(e.contains('^'), "{e}");
}

#[test]
fn sprintf_that_exactly_fits_runs() {
    // 3 characters and the NUL in `char b[4]`, known before and when it runs.
    let src = rule(
        "  char b[4]; sprintf(b, \"%d\", 123);\n  char c[4]; sprintf(c, \"%d\", n * 199);",
        "B(strlen(b) * 1000 + b[2], strlen(c) * 1000 + c[2])",
    );
    // "123": '3' is 51; "995": '5' is 53.
    assert_eq!(run(&src), "B(3051, 3053)");
}

#[test]
fn strcpy_of_8_characters_into_char_8_is_an_error_and_of_7_runs() {
    let src = rule("  char b[8];\n  strcpy(b, \"abcdefgh\");", "A(strlen(b))");
    let e = load_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains(
            "strcpy writes 8 characters and the terminating NUL into `b`, \
             declared `char b[8]` (room for 7 characters)"
        ),
        "{e}"
    );
    // The same from a variable, when it runs.
    let src = rule(
        "  char src[16] = \"abcdefgh\";\n  char b[8];\n  strcpy(b, src);",
        "A(strlen(b))",
    );
    let e = run_error(&src);
    assert!(e.contains("test.lsys:8:3"), "{e}");
    assert!(
        e.contains("strcpy writes 8 characters and the terminating NUL into `b`"),
        "{e}"
    );
    // 7 characters fit, and are copied.
    let src = rule(
        "  char src[16] = \"abcdefg\";\n  char b[8]; strcpy(b, src);\n  char c[8]; strcpy(c, \"abcdefg\");",
        "B(strlen(b) * 1000 + b[6], strcmp(c, \"abcdefg\"))",
    );
    assert_eq!(run(&src), "B(7103, 0)");
}

#[test]
fn strcat_past_the_declared_size_is_an_error_and_one_that_fits_runs() {
    let src = rule(
        "  char b[8] = \"abcd\";\n  strcat(b, \"efgh\");",
        "A(strlen(b))",
    );
    let e = run_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains(
            "strcat writes 8 characters and the terminating NUL into `b`, \
             declared `char b[8]` (room for 7 characters)"
        ),
        "{e}"
    );
    let src = rule(
        "  char b[8] = \"abcd\";\n  strcat(b, \"efg\");",
        "B(strlen(b), strcmp(b, \"abcdefg\"))",
    );
    assert_eq!(run(&src), "B(7, 0)");
}

#[test]
fn strncpy_with_a_count_past_the_declared_size_is_an_error() {
    // strncpy always writes its count, padding a short string with NULs.
    let src = rule("  char b[4];\n  strncpy(b, \"ab\", 8);", "A(strlen(b))");
    let e = load_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains(
            "strncpy writes 8 bytes into `b` (it always writes its count, padding with NULs), \
             declared `char b[4]` (room for 4 bytes)"
        ),
        "{e}"
    );
    // A count known when it runs.
    let src = rule("  char b[4];\n  strncpy(b, \"ab\", n);", "A(strlen(b))");
    let e = run_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(e.contains("strncpy writes 5 bytes into `b`"), "{e}");
    // A count that fits copies at most that many characters.
    let src = rule(
        "  char b[4]; strncpy(b, \"abcdef\", 3);\n  char c[8]; strncpy(c, \"ab\", 8);",
        "B(strcmp(b, \"abc\"), strcmp(c, \"ab\"))",
    );
    assert_eq!(run(&src), "B(0, 0)");
}

#[test]
fn strncat_and_snprintf_check_what_they_write() {
    // "ab" and 3 of "cdefgh": 5 characters and the NUL in 6.
    let src = rule(
        "  char b[6] = \"ab\";\n  strncat(b, \"cdefgh\", 3);",
        "B(strlen(b), strcmp(b, \"abcde\"))",
    );
    assert_eq!(run(&src), "B(5, 0)");
    let src = rule(
        "  char b[6] = \"ab\";\n  strncat(b, \"cdefgh\", 4);",
        "A(strlen(b))",
    );
    let e = run_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains("strncat writes 6 characters and the terminating NUL into `b`"),
        "{e}"
    );
    // snprintf cuts to its size: within the declared size, it fits.
    let src = rule(
        "  char b[4]; snprintf(b, 4, \"%s\", \"abcdef\");\n  char c[4]; snprintf(c, 8, \"%d\", n);",
        "B(strcmp(b, \"abc\"), strcmp(c, \"5\"))",
    );
    assert_eq!(run(&src), "B(0, 0)");
    // A size past the declared one, and a text longer than the array.
    let src = rule(
        "  char b[4];\n  snprintf(b, 8, \"%d\", n * 2000);",
        "A(strlen(b))",
    );
    let e = run_error(&src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains(
            "snprintf writes 5 characters and the terminating NUL into `b`, \
             declared `char b[4]` (room for 3 characters)"
        ),
        "{e}"
    );
}

#[test]
fn a_char_pointer_has_no_declared_size_and_is_not_checked() {
    let src = "module A(int);\n\
               void fill(char *out, int n) { sprintf(out, \"%d-%d-%d\", n, n, n); }\n\
               derivation length: 1;\nAxiom: A(12345);\n\
               A(n) : {\n  char *p;\n  sprintf(p, \"%s\", \"a string well past any size\");\n  \
               char *q;\n  fill(q, n);\n  produce A(strlen(p) * 100 + strlen(q));\n}\n";
    // 27 characters in `p`; "12345-12345-12345" in `q`.
    assert_eq!(run(src), "A(2717)");
}

#[test]
fn a_function_writing_a_callers_char_array_through_a_pointer_is_checked_at_the_call() {
    let src = "module A(int);\n\
               void fill(char *out, int n) { sprintf(out, \"%d-%d-%d\", n, n, n); }\n\
               derivation length: 1;\nAxiom: A(12345);\n\
               A(n) : {\n  char b[8];\n  fill(b, n);\n  produce A(strlen(b));\n}\n";
    let e = run_error(src);
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains(
            "`fill` writes 17 characters and the terminating NUL into `b`, \
             declared `char b[8]` (room for 7 characters)"
        ),
        "{e}"
    );
    // Room for all of it.
    assert_eq!(run(&src.replace("char b[8]", "char b[18]")), "A(17)");
}

#[test]
fn globals_struct_members_and_arrays_of_char_arrays_are_checked() {
    let head = "module A(int);\nstruct Leaf { int k; char name[4]; };\nchar g[4];\n\
                derivation length: 1;\nAxiom: A(12345);\n";
    let prog = |body: &str| format!("{head}A(n) : {{\n{body}\n  produce A(n);\n}}\n");
    let ok = |body: &str| format!("{head}A(n) : {{\n{body}\n}}\n");
    let e = run_error(&prog("  sprintf(g, \"%d\", n);"));
    assert!(e.contains("test.lsys:7:3"), "{e}");
    assert!(
        e.contains("into `g`, declared `char g[4]` (room for 3 characters)"),
        "{e}"
    );
    let e = run_error(&prog("  Leaf l;\n  sprintf(l.name, \"%d\", n);"));
    assert!(e.contains("test.lsys:8:3"), "{e}");
    assert!(
        e.contains(
            "sprintf writes 5 characters and the terminating NUL into `l.name`, \
             declared `char name[4]`"
        ),
        "{e}"
    );
    let e = run_error(&prog(
        "  char names[2][4];\n  int i = 1;\n  sprintf(names[i], \"%d\", n);",
    ));
    assert!(e.contains("test.lsys:9:3"), "{e}");
    assert!(
        e.contains("into `names[i]`, declared `char names[2][4]` (room for 3 characters)"),
        "{e}"
    );
    // Each fits with 3 characters.
    let ok = ok(
        "  sprintf(g, \"%d\", n / 100);\n  Leaf l; strcpy(l.name, g);\n  \
                  char names[2][4]; strcpy(names[1], l.name);\n  \
                  produce A(strcmp(names[1], \"123\") * 10 + strlen(names[0]));",
    );
    assert_eq!(run(&ok), "A(0)");
}

#[test]
fn an_initializer_or_an_assignment_too_long_for_the_array_is_an_error() {
    let src = rule("  char b[4] = \"toolong\";", "A(strlen(b))");
    let e = load_error(&src);
    assert!(e.contains("test.lsys:6:15"), "{e}");
    assert!(
        e.contains(
            "the initializer writes 7 characters and the terminating NUL into `b`, \
             declared `char b[4]` (room for 3 characters)"
        ),
        "{e}"
    );
    let src = rule(
        "  char s[16]; sprintf(s, \"%d\", n * 1000);\n  char b[4];\n  b = s;",
        "A(strlen(b))",
    );
    let e = run_error(&src);
    assert!(e.contains("test.lsys:8:3"), "{e}");
    assert!(
        e.contains("the assignment writes 4 characters and the terminating NUL into `b`"),
        "{e}"
    );
    // `char s[] = "abc"` is sized by its literal.
    let src = rule("  char s[] = \"abc\";\n  strcat(s, \"d\");", "A(strlen(s))");
    let e = run_error(&src);
    assert!(
        e.contains("declared `char s[4]` (room for 3 characters)"),
        "{e}"
    );
}

#[test]
fn initializer_lists_check_their_char_arrays() {
    let head = "module A(int);\nstruct Leaf { int k; char name[4]; };\n\
                derivation length: 1;\nAxiom: A(1);\n";
    let prog = |body: &str| format!("{head}A(n) : {{\n{body}\n  produce A(n);\n}}\n");
    let e = load_error(&prog("  char names[2][4] = {\"ab\", \"toolong\"};"));
    assert!(e.contains("test.lsys:6:22"), "{e}");
    assert!(
        e.contains(
            "the initializer writes 7 characters and the terminating NUL into `names`, \
             declared `char names[2][4]` (room for 3 characters)"
        ),
        "{e}"
    );
    let e = load_error(&prog("  Leaf l = {1, \"toolong\"};"));
    assert!(e.contains("test.lsys:6:16"), "{e}");
    assert!(
        e.contains("into `name`, declared `char name[4]` (room for 3 characters)"),
        "{e}"
    );
    let ok = prog("  char names[2][4] = {\"ab\", \"abc\"};\n  Leaf l = {1, \"abc\"};");
    assert_eq!(run(&ok), "A(1)");
}
