//! The rewriting semantics the manual and paper 002 define, one property per
//! test, on small programs.

use subgram::DeriveOptions;

use crate::support::*;

fn run(src: &str) -> String {
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    text(&l, &d)
}

fn run_phase(src: &str, phase: usize) -> String {
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default().with_phase(phase));
    text(&l, &d)
}

#[test]
fn rewriting_is_parallel_every_module_sees_the_old_word() {
    // If B saw the new A(2), it would become B(2).
    let out = run(
        "module A(int); module B(int);\nderivation length: 1;\nAxiom: A(1) B(0);\n\
                   A(x) -> A(x+1)\nA(x) < B(y) -> B(x)\n",
    );
    assert_eq!(out, "A(2) B(1)");
}

#[test]
fn ring_contexts_wrap_around() {
    let src = "module A(int);\nring L-system: 1;\nderivation length: 1;\nAxiom: A(1) A(2) A(3);\n\
               A(l) < A(x) > A(r) -> A(100*l + 10*x + r)\n";
    assert_eq!(run(src), "A(312) A(123) A(231)");
    // The same word, open: the ends have no neighbours and are copied.
    assert_eq!(
        run(&src.replace("ring L-system: 1;", "")),
        "A(1) A(123) A(3)"
    );
}

#[test]
fn endmarkers_limit_context_to_the_ends() {
    let src = "module P(int);\nderivation length: 1;\nAxiom: # P(1) P(2) P(3) #;\n\
               # < P(x) -> P(10*x)\nP(x) > # -> P(20*x)\n";
    assert_eq!(run(src), "# P(10) P(2) P(60) #");
}

#[test]
fn first_matching_production_in_file_order_wins() {
    let src = "module A(int);\nderivation length: 1;\nAxiom: A(1);\n\
               A(x) -> A(2)\nA(x) -> A(3)\n";
    assert_eq!(run(src), "A(2)");
}

#[test]
fn a_body_that_does_not_produce_falls_through() {
    let src = "module A(int);\nderivation length: 1;\nAxiom: A(1) A(7);\n\
               A(x) : { if (x > 5) produce A(100); }\n\
               A(x) : { nproduce A(-1); if (x > 5) produce A(200); }\n\
               A(x) : { produce A(x) A(x); }\n";
    // A(1): the first two bodies end without producing; the nproduce of the
    // second is dropped; the third doubles it.
    assert_eq!(run(src), "A(1) A(1) A(100)");
}

#[test]
fn a_module_no_production_rewrites_is_copied() {
    let src = "module A(int); module B;\nderivation length: 3;\nAxiom: B A(1) B;\nA(x) -> A(x+1)\n";
    assert_eq!(run(src), "B A(4) B");
}

#[test]
fn empty_produce_erases_the_module() {
    let src = "module A(int);\nderivation length: 1;\nAxiom: A(1) A(2) A(3);\n\
               A(x) : { if (x == 2) produce; }\n";
    assert_eq!(run(src), "A(1) A(3)");
}

#[test]
fn nproduce_builds_a_successor_incrementally() {
    // The manual's example: A(3,1) becomes B B B C(1).
    let src = "module A(int, float); module B; module C(float);\nderivation length: 1;\n\
               Axiom: A(3, 1);\n\
               A(age, length) : { for (int i = 0; i < age; i++) nproduce B; produce C(length); }\n";
    assert_eq!(run(src), "B B B C(1)");
}

const PAIRS: &str = "module P(int);\nring L-system: 1;\nderivation length: 1;\n\
                     Axiom: P(1) P(2) P(3) P(4);\nP(a) P(b) -> P(10*a + b)\n";

#[test]
fn multi_module_predecessors_partition_from_the_phase() {
    assert_eq!(run_phase(PAIRS, 0), "P(12) P(34)");
    // Phase 1 pairs (2,3) and (4,1); the pair that wraps uses up P(1),
    // which is not rewritten again.
    assert_eq!(run_phase(PAIRS, 1), "P(23) P(41)");
    assert_eq!(run_phase(PAIRS, 4), run_phase(PAIRS, 0));
}

#[test]
fn an_odd_module_left_over_is_rewritten_alone_or_copied() {
    let odd = PAIRS.replace("P(4);", "P(4) P(5);");
    // Phase 0: (1,2) (3,4), and P(5) cannot pair with the used-up P(1).
    assert_eq!(run_phase(&odd, 0), "P(12) P(34) P(5)");
    // Phase 1: (2,3) (4,5), and P(1) is left over; it keeps its place at
    // the start of the ring.
    assert_eq!(run_phase(&odd, 1), "P(1) P(23) P(45)");
    // A single-module production takes the leftover.
    let with_single = format!("{odd}P(a) -> P(-a)\n");
    assert_eq!(run_phase(&with_single, 0), "P(12) P(34) P(-5)");
}

#[test]
fn open_words_start_the_partition_at_the_phase() {
    let open = PAIRS.replace("ring L-system: 1;\n", "");
    assert_eq!(run_phase(&open, 0), "P(12) P(34)");
    assert_eq!(run_phase(&open, 1), "P(1) P(23) P(4)");
}

#[test]
fn right_context_skips_a_branch() {
    let src = "module A; module B; module C;\nderivation length: 1;\nAxiom: A SB C EB B;\n\
               A() > B() -> B\n";
    assert_eq!(run(src), "B SB C EB B");
}

#[test]
fn right_context_cannot_leave_its_branch() {
    let src = "module A; module B; module C;\nderivation length: 1;\nAxiom: SB A EB B;\n\
               A() > B() -> C\n";
    assert_eq!(run(src), "SB A EB B");
}

#[test]
fn a_closing_bracket_in_the_right_context_skips_the_rest_of_the_branch() {
    // Manual, Fig. 3: A > [B] C matches A [B D] C.
    let src = "module A; module B; module C; module D; module X;\nderivation length: 1;\n\
               Axiom: A SB B D EB C;\nA() > SB() B() EB() C() -> X\n";
    assert_eq!(run(src), "X SB B D EB C");
}

#[test]
fn left_context_is_the_parent_across_brackets() {
    // Manual, Figs. 6 and 7: A is the left context of B in `A [B]` and in `A [C] B`.
    let src = "module A; module B; module C; module X;\nderivation length: 1;\n\
               Axiom: A SB B EB SB C EB B;\nA() < B() -> X\n";
    assert_eq!(run(src), "A SB X EB SB C EB X");
}

#[test]
fn ignore_and_consider_hide_modules_from_contexts() {
    let base = "module A; module B; module X; module Y;\nderivation length: 1;\nAxiom: A X Y B;\n";
    assert_eq!(run(&format!("{base}A() < B() -> A\n")), "A X Y B");
    assert_eq!(
        run(&format!("{base}ignore: X Y;\nA() < B() -> A\n")),
        "A X Y A"
    );
    assert_eq!(
        run(&format!("{base}consider: A B;\nA() < B() -> A\n")),
        "A X Y A"
    );
    // `ignore: ;` cancels the filter for the productions after it.
    assert_eq!(
        run(&format!("{base}ignore: X Y;\nignore: ;\nA() < B() -> A\n")),
        "A X Y B"
    );
}

#[test]
fn new_left_context_sees_the_new_word_when_forward() {
    let src = "module A(int); module B(int);\nderivation length: 1;\nAxiom: A(1) B(0) B(0);\n\
               A(x) -> A(x+1)\nA(x) << B(y) -> B(x)\nB(x) << B(y) -> B(x + 10)\n";
    assert_eq!(run(src), "A(2) B(2) B(12)");
}

#[test]
fn new_right_context_sees_the_new_word_when_backward() {
    let src = "module A(int); module B(int);\nStart: { Backward(); }\nderivation length: 1;\n\
               Axiom: B(0) B(0) A(1);\nA(x) -> A(x+1)\nB(y) >> A(x) -> B(x)\nB(y) >> B(x) -> B(x + 10)\n";
    assert_eq!(run(src), "B(12) B(2) A(2)");
    // Forward, the new right context never matches.
    assert_eq!(run(&src.replace("Backward", "Forward")), "B(0) B(0) A(2)");
}

#[test]
fn context_tests_in_bodies_read_like_a_stream() {
    // InLeftContext matches beyond the predecessor's own left context.
    let src = "module A(int); module H(int);\nderivation length: 1;\nAxiom: A(1) A(2) H(3);\n\
               A(y) < H(x) : { int a; if (InLeftContext(A(a))) produce H(a); produce H(0); }\n";
    assert_eq!(run(src), "A(1) A(2) H(1)");
}

#[test]
fn groups_select_productions_and_group_0_is_the_fallback() {
    let src = "module A(int);\nint n;\nStart: { n = 0; }\nStartEach: { UseGroup(n++ % 2 == 0 ? 1 : 2); }\n\
               derivation length: 3;\nAxiom: A(0);\n\
               group 1:\nA(x) : { if (x < 100) produce A(x + 1); }\n\
               group 2:\nA(x) -> A(x * 10)\nendgroup\nA(x) -> A(-1)\n";
    // Steps use groups 1, 2, 1: 0 -> 1 -> 10 -> 11.
    assert_eq!(run(src), "A(11)");
    // In group 1, A(100) does not produce, so group 0's production applies:
    // 100 -> -1 (group 0) -> -10 (group 2) -> -9 (group 1).
    assert_eq!(run(&src.replace("Axiom: A(0)", "Axiom: A(100)")), "A(-9)");
}

#[test]
fn control_blocks_run_in_order_with_step_numbers() {
    let src = "module A(int);\nint trace;\nStart: { trace = 1; }\nStartEach: { trace = trace * 10 + StepNo(); }\n\
               EndEach: { trace = trace * 10 + 9; }\nEnd: { trace = trace * 10 + 5; }\n\
               derivation length: 2;\nAxiom: A(0);\nA(x) -> A(trace)\n";
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    // Start 1; step 1: StartEach (StepNo 1) 11, A(11), EndEach 119;
    // step 2: StartEach (StepNo 2) 1192, A(1192), EndEach 11929; End 119295.
    // lpfg 9bf820d gives the same: A(1192), and End prints 119295.
    assert_eq!(text(&l, &d), "A(1192)");
    assert_eq!(d.env.globals[0], subgram::Value::Int(119295));
}

#[test]
fn decomposition_recurses_to_the_maximum_depth() {
    let src = "module A(int);\nderivation length: 0;\nAxiom: A(10);\n\
               decomposition:\nmaximum depth: 6;\nA(age) : { if (age > 0) produce F(1) A(age-1); }\n";
    // The manual's example: at most 6 F modules, ending with A.
    assert_eq!(run(src), "F(1) F(1) F(1) F(1) F(1) F(1) A(4)");
    // The default depth is 1.
    assert_eq!(run(&src.replace("maximum depth: 6;\n", "")), "F(1) A(9)");
}

#[test]
fn arrow_form_and_block_form_agree() {
    let arrow = "module P(V2f);\nring L-system: 1;\nderivation length: 2;\n\
                 Axiom: P(V2f(0,0)) P(V2f(0,1)) P(V2f(1,1));\n\
                 P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)\n";
    let block = arrow.replace(
        "-> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)",
        ": { produce P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr); }",
    );
    assert_eq!(run(arrow), run(&block));
}

/// The stencil fast path and the interpreter give the same word: a guard
/// that is always true keeps the body off the fast path.
#[test]
fn stencil_and_interpreter_agree() {
    let fast = std::fs::read_to_string(lsys("curves/cubic-22.lsys")).unwrap();
    let slow = fast.replace(
        "P(vl) < P(v) > P(vr) -> P(0.125*vl + 0.75*v + 0.125*vr) P(0.5*v + 0.5*vr)",
        "P(vl) < P(v) > P(vr) : { if (1) produce P(0.125*vl + 0.75*v + 0.125*vr) P(0.5*v + 0.5*vr); }",
    );
    assert_ne!(fast, slow);
    let (a, b) = (load_text(&fast), load_text(&slow));
    assert!(a.program.rules[0].stencil.is_some());
    assert!(b.program.rules[0].stencil.is_none());
    assert_eq!(run(&fast), run(&slow));
}

#[test]
fn define_overrides_replace_the_files_value() {
    let src =
        "#define N 2\nmodule A(int);\nderivation length: N;\nAxiom: A(0);\nA(x) -> A(x + 1)\n";
    let l = subgram::load_str("t.lsys", src, &["N=5".to_string()]).unwrap();
    let d = derive(&l, DeriveOptions::default());
    assert_eq!(text(&l, &d), "A(5)");
}

/// As in C, arguments are substituted as text: `0.5*a` with `a = x + 1`
/// reads `0.5*x + 1`.
#[test]
fn function_like_macros_expand_with_their_arguments() {
    let src = "#define MID(a, b) 0.5*a + 0.5*b\nmodule A(float);\nderivation length: 1;\n\
               Axiom: A(1) A(3);\nA(x) < A(y) -> A(MID(x + 1, y))\n";
    assert_eq!(run(src), "A(1) A(3)");
}

/// `F` is overloaded (`F` and `F(l)`): a stencil whose pattern is `F(x)`
/// rewrites only the `F`s with one parameter, on the fast paths as on the
/// general one: in an open word, in contexts (an `F` without parameters
/// is no `F(a)` context), and on rings of one module kind with and without
/// the pattern's parameters. The expected words are worked out by hand.
#[test]
fn stencils_on_overloaded_modules_match_by_width() {
    let cases = [
        (
            "derivation length: 1;\nAxiom: F F(1) f F F(3);\nF(x) -> F(x/2) F(x/2)\n",
            "F F(0.5) F(0.5) f F F(1.5) F(1.5)",
        ),
        (
            "derivation length: 1;\nAxiom: F(1) F F(2) F(4);\nF(a) < F(x) -> F(a + x)\n",
            "F(1) F F(2) F(6)",
        ),
        (
            "ring L-system: 1;\nderivation length: 2;\nAxiom: F(1) F(2) F(4);\n\
             F(a) < F(x) > F(b) -> F(a + b) F(x)\n",
            "F(5) F(6) F(11) F(1) F(3) F(5) F(8) F(2) F(6) F(3) F(9) F(4)",
        ),
        (
            "ring L-system: 1;\nderivation length: 2;\nAxiom: F F F;\nF(x) -> F(x) F(x)\n",
            "F F F",
        ),
    ];
    for (src, want) in cases {
        let slow = src
            .replace("-> F", ": { if (1) produce F")
            .replace(")\n", "); }\n");
        assert!(load_text(src).program.rules[0].stencil.is_some(), "{src}");
        assert!(
            load_text(&slow).program.rules[0].stencil.is_none(),
            "{slow}"
        );
        assert_eq!(run(src), want, "{src}");
        assert_eq!(run(&slow), want, "{slow}");
    }
}

/// The fast path replays the interpreter's operations: results agree to
/// the last bit, whatever the shape of the affine expression.
#[test]
fn stencils_agree_with_the_interpreter_bit_for_bit() {
    let bodies = [
        "P(vl/3 + v - 0.1*vr) P(-v/3.0 - (1.0/3)*vl)",
        "P(0.25*vl + 0.5*v + 0.25*vl) P(v*0.7 - vr*0.1 + v/7)",
        "P(-(0.3*vl) + 0.9*v) P(v)",
    ];
    for body in bodies {
        let fast = format!(
            "module P(V2f);\nring L-system: 1;\nderivation length: 6;\n\
             Axiom: P(V2f(0.1, 0.7)) P(V2f(1.3, 2.9)) P(V2f(4.1, 3.3)) P(V2f(2.2, -1.7));\n\
             P(vl) < P(v) > P(vr) -> {body}\n"
        );
        let slow = fast.replace(
            &format!("-> {body}"),
            &format!(": {{ if (1) produce {body}; }}"),
        );
        let (a, b) = (load_text(&fast), load_text(&slow));
        assert!(
            a.program.rules[0].stencil.is_some(),
            "{body} is not a stencil"
        );
        assert!(b.program.rules[0].stencil.is_none());
        let (da, db) = (
            derive(&a, Default::default()),
            derive(&b, Default::default()),
        );
        assert_eq!(da.word, db.word, "{body}");
    }
}

/// The phase only moves the partition: a ring without multi-module
/// predecessors derives the same word, in the same order, at any phase.
#[test]
fn the_phase_does_not_rotate_the_word() {
    let src = "module P(int);\nring L-system: 1;\nderivation length: 3;\n\
               Axiom: P(1) P(2) P(3);\nP(a) : { if (a < 100) produce P(a) P(a + 10); }\n";
    let want = run_phase(src, 0);
    for phase in 1..4 {
        assert_eq!(run_phase(src, phase), want, "phase {phase}");
    }
}

/// `derivation length:` is read after `Start` has run: it may use what
/// `Start` computed (the Lychnis model reads its length from a parameter
/// file in `Start`). lpfg 9bf820d derives this program to `A(3)`.
#[test]
fn the_derivation_length_is_read_after_start() {
    let src = "int n;\nStart: { n = 3; }\nderivation length: n;\nmodule A(int);\n\
               Axiom: A(0);\nA(x) : { produce A(x + 1); }\n";
    assert_eq!(run(src), "A(3)");
}

/// `++` and `--` on ints, locals and globals, prefix and postfix, as in C:
/// the postfix form gives the value before, the prefix form the value after.
#[test]
fn increments_and_decrements_give_cs_values() {
    let src = "int g;\nStart: { g = 10; }\nderivation length: 1;\nmodule A(int, int, int, int, int, int);\n\
               Axiom: A(0, 0, 0, 0, 0, 0);\n\
               A(a, b, c, d, e, f) : { int i = 5; a = i++; b = ++i; i--; c = i; \
               d = g--; e = --g; f = g; produce A(a, b, c, d, e, f); }\n";
    // i: 5 -> a 5 (i 6) -> b 7 (i 7) -> 6; g: 10 -> d 10 (g 9) -> e 8.
    assert_eq!(run(src), "A(5, 7, 6, 10, 8, 8)");
}
