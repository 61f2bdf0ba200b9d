//! Small L+C programs on which subgram once disagreed with lpfg, found by
//! the adversarial review of issue 12. Each expected word is lpfg's own
//! final string for the same program (vlab commit 9bf820d, built headless
//! with `shared/tools/lpfg`, printed by `run_lpfg.sh`; the programs had
//! `#include <lpfgall.h>` in front for lpfg), written here in subgram's
//! spelling (`A(1, 2)` for lpfg's `A(1,2)`).

use subgram::{DeriveOptions, Precision};

use crate::support::*;

fn words(src: &str) -> String {
    let l = subgram::load_str_with("p.l", src, &[], Precision::Single)
        .unwrap_or_else(|e| panic!("the program does not load:\n{e}"));
    let d = derive(&l, DeriveOptions::default());
    text(&l, &d)
}

/// Character constants are `int`s with the character's code, escapes
/// included; a digit's character minus `'0'` is its value.
#[test]
fn character_constants_are_their_codes() {
    let src = r#"derivation length: 1;
module A(int, int, int, int, int, float);
Axiom: A(0, 0, 0, 0, 0, 0);
production:
A(a, b, c, d, e, x) : {
  char buf[16]; sprintf(buf, "%d", 4096);
  int ca = 'A', nl = '\n', bs = '\\', q = '\'';
  int digit = buf[1] - '0' + 'z' - 'a';
  produce A(ca, nl, bs, q, digit, 'a' * 0.5);
}
"#;
    // lpfg: A(65,10,92,39,25,48.5)
    assert_eq!(words(src), "A(65, 10, 92, 39, 25, 48.5)");
}

/// `<<` and `>>` are C's shifts inside expressions (also `<<=`, `>>=`),
/// binding tighter than `<` and looser than `+`, while they still separate
/// the new-context parts of a predecessor.
#[test]
fn shifts_are_operators_in_expressions() {
    let src = r#"derivation length: 2;
module A(int, int, int, int, int);
module B(int);
Axiom: B(3) A(1, 256, -7, 5, 3);
production:
B(s) < A(a, b, c, d, e) : {
  int m = d; m <<= 2; m >>= 1;
  produce A(a << s, b >> 2, c >> 1, m, 1 + 2 << e - 1 < 20);
}
B(s) : { produce B(s - 1); }
"#;
    // lpfg: B(1) A(32,16,-2,20,1)
    assert_eq!(words(src), "B(1) A(32, 16, -2, 20, 1)");
}

#[test]
fn shifts_inside_new_context_productions() {
    let src = r#"derivation length: 1;
module A(int);
module B(int);
Axiom: B(1) A(1) SB() A(2) EB() A(3);
production:
B(x) << A(y) : { produce A((x << 4) | (y >> 0)); }
A(y) >> A(z) : { produce A(y + (z << 1)); }
"#;
    // lpfg: B(1) A(17) SB() A(2) EB() A(3)
    assert_eq!(words(src), "B(1) A(17) SB A(2) EB A(3)");
}

/// lpfg's programs call C's maths functions of <math.h>: `sqrt` or `sin`
/// of a `float` is computed and returned in double precision, not as
/// C++'s float overload. In single precision `sqrt(2.0f)` is 1.4142135f
/// and its square less 2 is -2^-23; in double the square less 2 is
/// 2^-51 = 4.44e-16, and 1.41421356237 × 10^7 rounds to the float
/// 14142136.
#[test]
fn maths_functions_of_floats_compute_in_double() {
    let src = r#"derivation length: 1;
module A(float, double, double);
Axiom: A(2, 0, 0);
production:
A(x, y, z) : {
  float h = 0.3;
  produce A(sqrt(x) * 1e7, (sqrt(x) * sqrt(x) - 2) * 1e16, (sin(h) - sin((double)h)) * 1e10);
}
"#;
    // lpfg: A(14142136,4.440892098500626,0)
    assert_eq!(words(src), "A(14142136, 4.440892098500626, 0)");
}

/// `StepNo()` counts the step under way from 1: in the first step's
/// `StartEach`, productions and `EndEach` it is 1, in `Start` 0, in `End`
/// the number of steps taken. lpfg prints, for this program with three
/// steps, `Start 0`, then `StartEach k`, `prod k`, `EndEach k` for k = 1,
/// 2, 3, then `End 3`; the word records the production's values.
#[test]
fn step_numbers_count_the_step_under_way() {
    let src = r#"derivation length: 3;
int at_start = -1, at_each = -1, at_end_each = -1;
module A(int, int, int);
module S(int, int, int);
Start: { at_start = StepNo(); }
StartEach: { at_each = StepNo(); }
EndEach: { at_end_each = StepNo(); }
Axiom: S(0, 0, 0) A(0, 0, 0);
production:
A(a, b, c) : { produce A(StepNo(), a, b); }
S(a, b, c) : { produce S(at_start, at_each, at_end_each); }
"#;
    // lpfg: S(0,3,2) A(3,2,1)
    assert_eq!(words(src), "S(0, 3, 2) A(3, 2, 1)");
}

/// A compound assignment or an increment evaluates its target's index
/// once: `arr[k++] += 10` steps `k` once (it stepped twice, and
/// `arr[++k] *= 3` then indexed past the end). By hand: arr = {1,2,3,4},
/// k = 0; `arr[0] += 10` (k 1); `arr[2] *= 3` (k 2); `arr[2]++` (k 1);
/// `--arr[1]` (k 2): {11, 1, 10, 4}; `fa[2] -= 0.25` gives 2.25, plus
/// fa[1] 1.5 is 3.75, m 1; `s.b[0] <<= 2` is 20, plus i = 1.
#[test]
fn compound_assignment_evaluates_its_index_once() {
    let src = r#"struct S { float a; int b[3]; };
derivation length: 1;
module A(int, int, int, int, int, int, float, int);
Axiom: A(0, 0, 0, 0, 0, 0, 0, 0);
production:
A(a0, a1, a2, a3, k1, k2, fl, j) : {
  int k = 0; int arr[4] = {1, 2, 3, 4};
  arr[k++] += 10; arr[++k] *= 3; arr[k--]++; --arr[k++];
  float fa[3] = {0.5, 1.5, 2.5}; int m = 2; fa[m--] -= 0.25;
  S s; s.b[0] = 5; s.b[1] = 6; s.b[2] = 7; int i = 0; s.b[i++] <<= 2;
  produce A(arr[0], arr[1], arr[2], arr[3], k, m, fa[2] + fa[1], s.b[0] + i);
}
"#;
    // lpfg: A(11,1,10,4,2,1,3.75,21)
    assert_eq!(words(src), "A(11, 1, 10, 4, 2, 1, 3.75, 21)");
}

/// A `char *` or `char []` parameter points at the caller's buffer: what
/// the function writes there with `sprintf`, `strcpy` or `strcat` is the
/// caller's (it was lost). A `const char *` parameter is not written back,
/// even when the function points it elsewhere, and a literal argument is
/// passed as a value. lpfg prints `ab#42 abab x#7` for the `printf`.
#[test]
fn char_pointer_parameters_write_the_callers_buffer() {
    let src = r#"void fill(char* out, const char* what, int n) { sprintf(out, "%s#%d", what, n); what = "changed"; }
void twice(char s[]) { strcat(s, s); }
int len(const char* s) { return strlen(s); }
struct L { char name[16]; int k; };
derivation length: 1;
module A(int, int, int, int);
Axiom: A(0, 0, 0, 0);
production:
A(a, b, c, d) : {
  char buf[32]; char src[8]; strcpy(src, "ab"); L l;
  fill(buf, src, 42); twice(src); fill(l.name, "x", 7);
  produce A(len(buf), len(src), len("literal"), len(l.name));
}
"#;
    // lpfg: A(5,4,7,3)
    assert_eq!(words(src), "A(5, 4, 7, 3)");
}
