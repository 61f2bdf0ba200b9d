//! Every class of mistake gets `file:line:col`, the line, a caret and a
//! message that says what was expected or what is wrong.

use subgram::DeriveOptions;

fn load_error(src: &str) -> String {
    match subgram::load_str("bad.lsys", src, &[]) {
        Ok(_) => panic!("the program loaded, but an error was expected"),
        Err(e) => e.to_string(),
    }
}

fn derive_error(src: &str, opts: DeriveOptions) -> String {
    let l = subgram::load_str("bad.lsys", src, &[]).unwrap_or_else(|e| panic!("{e}"));
    match subgram::derive(&l.program, opts) {
        Ok(_) => panic!("the derivation succeeded, but an error was expected"),
        Err(e) => l.error(e).to_string(),
    }
}

const HEAD: &str = "module P(V2f);\nderivation length: 2;\n";

#[test]
fn syntax_error_names_what_was_expected() {
    let got = load_error(&format!(
        "{HEAD}Axiom: P(V2f(0,0))\nP(v) : {{ produce P(v); }}\n"
    ));
    assert_eq!(
        got,
        "bad.lsys:4:6: error: expected a module or the `;` that ends the axiom, found `:`\n  \
         |\n4 | P(v) : { produce P(v); }\n  |      ^"
    );
}

#[test]
fn unclosed_block_points_at_its_brace() {
    let got = load_error(&format!(
        "{HEAD}Axiom: P(V2f(0,0));\nP(v) : {{ produce P(v);\n"
    ));
    assert!(
        got.starts_with("bad.lsys:4:8: error: unclosed `{`"),
        "{got}"
    );
}

#[test]
fn undeclared_module() {
    let got = load_error(&format!("{HEAD}Axiom: P(V2f(0,0)) Q(1);\n"));
    assert_eq!(
        got,
        "bad.lsys:3:20: error: undeclared module `Q`: declare it before use, e.g. `module Q(int);`\n  \
         |\n3 | Axiom: P(V2f(0,0)) Q(1);\n  |                    ^"
    );
}

#[test]
fn parameter_count_differs_from_the_declaration() {
    let got = load_error(&format!(
        "{HEAD}Axiom: P(V2f(0,0));\nP(a, b) : {{ produce P(a); }}\n"
    ));
    // One error, not a cascade about `a` in the body.
    assert_eq!(
        got,
        "bad.lsys:4:1: error: module `P` is declared with 1 parameter(s) (V2f) but 2 are given here\n  \
         |\n4 | P(a, b) : { produce P(a); }\n  | ^"
    );
    let got = load_error(&format!("{HEAD}Axiom: P(V2f(0,0), 1);\n"));
    assert!(
        got.contains("module `P` takes 1 parameter(s), but 2 are given here"),
        "{got}"
    );
}

#[test]
fn type_error_vector_plus_scalar() {
    let got = load_error(&format!(
        "{HEAD}Axiom: P(V2f(0,0));\nP(v) : {{ produce P(v + 1.0); }}\n"
    ));
    assert_eq!(
        got,
        "bad.lsys:4:20: error: type error: cannot apply `+` to V2f and float\n  \
         |\n4 | P(v) : { produce P(v + 1.0); }\n  |                    ^^^^^^^"
    );
}

#[test]
fn type_error_in_a_module_argument() {
    let got = load_error(&format!("{HEAD}Axiom: P(1.5);\n"));
    assert!(
        got.contains("3:10: error: type mismatch in argument of `P`: expected V2f, found float"),
        "{got}"
    );
}

#[test]
fn unknown_identifier() {
    let got = load_error(&format!(
        "{HEAD}Axiom: P(V2f(0,0));\nP(v) : {{ produce P(v * scale); }}\n"
    ));
    assert_eq!(
        got,
        "bad.lsys:4:24: error: unknown identifier `scale`\n  \
         |\n4 | P(v) : { produce P(v * scale); }\n  |                        ^^^^^"
    );
}

#[test]
fn every_diagnostic_is_reported_not_just_the_first() {
    let got = load_error(&format!(
        "{HEAD}Axiom: P(V2f(0,0));\nP(v) : {{ produce P(v * scale); }}\nP(v) : {{ produce Q(v); }}\n"
    ));
    assert!(
        got.contains("4:24: error: unknown identifier `scale`"),
        "{got}"
    );
    assert!(got.contains("5:18: error: undeclared module `Q`"), "{got}");
}

#[test]
fn nan_at_run_time_names_the_production_and_the_step() {
    let got = derive_error(
        "module A(float);\nderivation length: 3;\nAxiom: A(1);\nA(x) : { produce A(x / (x - 1)); }\n",
        DeriveOptions::default(),
    );
    assert_eq!(
        got,
        "bad.lsys:4:18: error: at step 1, production `A(x)`: parameter 1 of this successor module is inf; \
         NaN and infinity are not allowed in a word\n  |\n4 | A(x) : { produce A(x / (x - 1)); }\n  |                  ^"
    );
}

#[test]
fn nan_in_an_affine_stencil_is_caught_too() {
    let got = derive_error(
        "module P(V2f);\nderivation length: 3;\nAxiom: P(V2f(1e308, 0)) P(V2f(1e308, 0));\nP(a) > P(b) -> P(a + b)\n",
        DeriveOptions::default(),
    );
    assert!(
        got.starts_with("bad.lsys:4:1: error: at step 1, production `P(a) > P(b)`"),
        "{got}"
    );
    assert!(got.contains("NaN or infinite"), "{got}");
}

#[test]
fn runaway_growth_is_stopped_by_the_module_limit() {
    let got = derive_error(
        "module A;\nderivation length: 40;\nAxiom: A;\nA() -> A A\n",
        DeriveOptions::default().with_max_modules(1000),
    );
    assert_eq!(
        got,
        "at step 10, the word grew past 1000 modules; raise the limit with --max-modules or derive fewer steps"
    );
}

#[test]
fn an_endless_loop_in_a_body_is_stopped() {
    let got = derive_error(
        "module A(float);\nderivation length: 1;\nAxiom: A(1);\nA(x) : { while (x > 0) x = x + 1; produce A(x); }\n",
        DeriveOptions::default(),
    );
    assert!(
        got.starts_with("bad.lsys:4:10: error: at step 1, production `A(x)`: a loop ran more than"),
        "{got}"
    );
}

#[test]
fn integer_division_by_zero_is_an_error_not_a_crash() {
    let got = derive_error(
        "module A(int);\nderivation length: 1;\nAxiom: A(0);\nA(x) : { produce A(1 / x); }\n",
        DeriveOptions::default(),
    );
    assert!(
        got.contains("at step 1, production `A(x)`: integer division by zero"),
        "{got}"
    );
}

#[test]
fn a_missing_axiom_is_reported() {
    let got = load_error("module A;\nderivation length: 1;\n");
    assert!(got.contains("error: the program has no axiom"), "{got}");
}

#[test]
fn redeclaring_a_predefined_module_is_refused() {
    let got = load_error("module F(float);\nAxiom: F(1);\n");
    assert!(
        got.contains("1:8: error: module `F` is a predefined module and cannot be redeclared"),
        "{got}"
    );
}

#[test]
fn unterminated_comment() {
    let got = load_error("module A; /* no end\nAxiom: A;\n");
    assert!(
        got.starts_with("bad.lsys:1:11: error: unterminated comment"),
        "{got}"
    );
}

#[test]
fn const_locals_and_duplicate_declarations_are_refused() {
    let got = load_error(
        "module A(int);\nderivation length: 1;\nAxiom: A(1);\n\
         A(x) : { const int k = 1; k = 2; produce A(k); }\n",
    );
    assert!(
        got.contains("4:27: error: cannot assign to `k`: it is declared const"),
        "{got}"
    );
    let got = load_error("struct S { float a, a; };\nstruct S { int b; };\nmodule A;\nAxiom: A;\n");
    assert!(
        got.contains("1:21: error: struct `S` already has a field `a`"),
        "{got}"
    );
    assert!(
        got.contains("2:8: error: struct `S` is already declared"),
        "{got}"
    );
}

#[test]
fn deep_nesting_is_refused_with_a_message() {
    let deep = format!(
        "module A(float);\nAxiom: A({}1{});\n",
        "(".repeat(500),
        ")".repeat(500)
    );
    let got = load_error(&deep);
    assert!(
        got.contains("error: this is nested more than 100 levels deep"),
        "{got}"
    );
    // The long line is shown as a window around the column.
    assert!(got.lines().nth(2).unwrap().len() < 200, "{got}");
    let sum = format!(
        "module A(float);\nAxiom: A({});\n",
        vec!["1"; 1000].join("+")
    );
    assert!(load_error(&sum).contains("nested more than 100 levels deep"));
    // Just below the limit, checking and deriving work, on a test thread's
    // ordinary stack.
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

#[test]
fn a_non_finite_derivation_length_is_an_error() {
    let got = derive_error(
        "module A;\nderivation length: 1e400;\nAxiom: A;\n",
        DeriveOptions::default(),
    );
    assert!(
        got.starts_with("bad.lsys:2:1: error: the derivation length is inf"),
        "{got}"
    );
}

#[test]
fn division_by_zero_in_a_control_block_is_located() {
    let got = derive_error(
        "module A;\nint n;\nStart: { n = 1 / n; }\nAxiom: A;\n",
        DeriveOptions::default(),
    );
    assert!(
        got.starts_with("bad.lsys:3:14: error: integer division by zero"),
        "{got}"
    );
}

/// The same on a ring of one kind of module, which takes the engine's
/// uniform fast path.
#[test]
fn nan_on_the_uniform_ring_path_is_caught() {
    let got = derive_error(
        "module P(V2f);\nring L-system: 1;\nderivation length: 3;\n\
         Axiom: P(V2f(1e308, 0)) P(V2f(1e308, 0)) P(V2f(1, 1));\nP(a) > P(b) -> P(a + b) P(b)\n",
        DeriveOptions::default(),
    );
    assert!(
        got.starts_with("bad.lsys:5:1: error: at step 1, production `P(a) > P(b)`"),
        "{got}"
    );
    assert!(got.contains("NaN or infinite"), "{got}");
}
