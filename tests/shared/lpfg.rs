//! The real L+C programs in `$SUBGRAM_SHARED/corpus/lpfg`: every one loads,
//! derives to its stated length, and decomposes and interprets.

use glam::DVec2;
use subgram::{Derivation, DeriveOptions};

use crate::corpus;
use crate::support::*;

const FILES: &[&str] = &[
    "01-quadratic-Koch.l",
    "03-snowflake.l",
    "04-compound.l",
    "05-compound-interp.l",
    "06-compound-param.l",
    "07-fractal-ferns.l",
    "10-recursive.l",
    "12-alternating.l",
    "B-spline.l",
    "InNewContext.l",
    "NewContext.l",
];

#[test]
fn every_corpus_program_derives_to_its_length_and_interprets() {
    for f in FILES {
        let l = load(&corpus(f));
        let mut d = Derivation::new(&l.program, DeriveOptions::default())
            .unwrap_or_else(|e| panic!("{f}: {}", l.error(e)));
        let length = d.length;
        assert!(length >= 1, "{f} states no derivation length");
        while d.has_next() {
            d.next_step()
                .unwrap_or_else(|e| panic!("{f}: {}", l.error(e)));
        }
        assert_eq!(d.step, length, "{f} stopped early");
        let shown = d
            .interpret()
            .unwrap_or_else(|e| panic!("{f}: {}", l.error(e)));
        assert!(!shown.is_empty(), "{f} interprets to nothing");
    }
}

#[test]
fn quadratic_koch_has_8_to_the_4_segments() {
    let l = load(&corpus("01-quadratic-Koch.l"));
    let d = derive(&l, DeriveOptions::default());
    assert_eq!(count(&l, &d, "F"), 8usize.pow(4));
}

#[test]
fn snowflake_has_4_to_the_4_segments() {
    let l = load(&corpus("03-snowflake.l"));
    let d = derive(&l, DeriveOptions::default());
    assert_eq!(count(&l, &d, "F"), 4usize.pow(4));
}

/// B-spline.l alternates a SUBDIVIDE group and two AVERAGE groups
/// (Lane-Riesenfeld); its 32 points are three cubic B-spline steps of the
/// unit square, matrix (21) of paper 002.
#[test]
fn b_spline_equals_three_cubic_steps_of_the_unit_square() {
    let l = load(&corpus("B-spline.l"));
    let d = derive(&l, DeriveOptions::default());
    assert_eq!(d.step, 9);
    let square = [(0., 0.), (0., 1.), (1., 1.), (1., 0.)].map(|(x, y)| DVec2::new(x, y));
    let want = iterate(&square, 3, cubic_closed);
    let got = points(&l, &d, "P");
    assert_eq!(got.len(), 32);
    assert_cyclic_eq(&got, &want, 1e-12);
}

/// 04-compound: A -> F [+A] [-A] F A and F -> F F. Counting by recurrence:
/// a' = 3a, f' = 2f + 2a.
#[test]
fn compound_leaf_counts_follow_the_recurrence() {
    let l = load(&corpus("04-compound.l"));
    let d = derive(&l, DeriveOptions::default());
    let (mut a, mut f) = (1usize, 0usize);
    for _ in 0..4 {
        (a, f) = (3 * a, 2 * f + 2 * a);
    }
    assert_eq!(count(&l, &d, "A"), a);
    assert_eq!(count(&l, &d, "F"), f);
    assert_eq!(count(&l, &d, "SB"), count(&l, &d, "EB"));
}

/// 10-recursive builds the whole fern by recursive interpretation (maximum
/// depth 100). With D = 2: A(t) gives one F when t < D, else M(t-D) A(t-1);
/// M(s) gives I [A(s)] [A(s)] I. So F(t) = 1 for t < 2 and
/// F(t) = 2 + 2 F(t-2) + F(t-1).
#[test]
fn recursive_interpretation_expands_the_whole_fern() {
    let l = load(&corpus("10-recursive.l"));
    let mut d = Derivation::new(&l.program, DeriveOptions::default()).unwrap();
    while d.has_next() {
        d.next_step().unwrap();
    }
    let shown = d.interpret().unwrap();
    let mut f = [0usize; 9];
    for t in 0..9 {
        f[t] = if t < 2 {
            1
        } else {
            2 + 2 * f[t - 2] + f[t - 1]
        };
    }
    let fs = shown
        .syms()
        .iter()
        .filter(|s| l.program.alphabet.name(**s) == "F")
        .count();
    assert_eq!(fs, f[8]);
    // Interpretation does not change the derived word itself.
    assert_eq!(
        text(&l, &derive(&l, DeriveOptions::default())),
        "SetWidth(3) A(8)"
    );
}

/// NewContext.l, two steps, derived by hand with the manual's rules
/// (backward derivation, `>>` matches the new word to the right, `ignore:
/// Right`, branches skipped in right contexts, `Metamer` decomposed after
/// each step):
/// step 1: A(0,40) -> Metamer(40) A(0,-40), decomposed to
///         I{1,1} [Right(40) A(-1,40)] I{1,1} A(0,-40).
/// step 2, right to left: A(0,-40) -> Metamer(-40) A(0,40); the second
/// internode sees Metamer on its new right, no production matches, it is
/// copied; A(-1,40) -> A(0,40); the first internode skips the new branch and
/// matches `>> Internode(idr)`: area 1, length 1.33.
#[test]
fn new_context_pipe_model_matches_a_hand_derivation() {
    let l = load(&corpus("NewContext.l"));
    let d = derive(&l, DeriveOptions::default().with_steps(2));
    assert_eq!(
        text(&l, &d),
        "Internode({1.33, 1}) SB Right(40) A(0, 40) EB Internode({1, 1}) Internode({1, 1}) \
         SB Right(-40) A(-1, -40) EB Internode({1, 1}) A(0, 40)"
    );
}
