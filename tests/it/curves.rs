//! Every curve file in `lsystems/curves` against its subdivision matrix,
//! built here from the matrices printed in paper 002.

use glam::DVec2;
use subgram::DeriveOptions;

use crate::support::*;

/// The tolerance against the matrices, which are computed in double
/// precision. The programs compute in lpfg's single precision (`V2f`), yet
/// they agree to 1e-12: the control polygons have small integer
/// coordinates and every mask of paper 002 is a dyadic fraction (1/4, 3/4,
/// 1/8, 9/16, …), so for these few steps every product and sum has fewer
/// than 24 significant bits and single precision computes it exactly.
const EPS: f64 = 1e-12;

fn closed_case(file: &str, steps: usize, m: fn(usize) -> Matrix) {
    let l = load(&lsys(file));
    let d = derive(&l, DeriveOptions::default());
    assert_eq!(d.step as usize, steps);
    assert!(d.ring);
    let want = iterate(&hexagon(), steps, m);
    assert_cyclic_eq(&points(&l, &d, "P"), &want, EPS);
}

#[test]
fn chaikin_13_equals_matrix_8() {
    closed_case("curves/chaikin-13.lsys", 4, chaikin_closed);
}

#[test]
fn chaikin_17_equals_matrix_8() {
    closed_case("curves/chaikin-17.lsys", 4, chaikin_closed);
}

#[test]
fn chaikin_18_equals_matrix_8() {
    closed_case("curves/chaikin-18.lsys", 4, chaikin_closed);
}

#[test]
fn chaikin_20_equals_matrix_8() {
    closed_case("curves/chaikin-20.lsys", 4, chaikin_closed);
}

#[test]
fn cubic_22_equals_matrix_21() {
    closed_case("curves/cubic-22.lsys", 4, cubic_closed);
}

#[test]
fn cubic_23_equals_matrix_21() {
    closed_case("curves/cubic-23.lsys", 4, cubic_closed);
}

#[test]
fn four_point_25_equals_matrix_24() {
    closed_case("curves/fourpoint-25.lsys", 4, four_point_closed);
}

#[test]
fn four_point_26_equals_matrix_24() {
    closed_case("curves/fourpoint-26.lsys", 4, four_point_closed);
}

#[test]
fn four_point_interpolates_its_control_points() {
    let l = load(&lsys("curves/fourpoint-25.lsys"));
    let d = derive(&l, DeriveOptions::default());
    let pts = points(&l, &d, "P");
    for c in hexagon() {
        assert!(pts.iter().any(|p| p.abs_diff_eq(c, EPS)), "{c} is lost");
    }
}

fn open_case(file: &str) {
    let l = load(&lsys(file));
    let d = derive(&l, DeriveOptions::default());
    assert!(!d.ring);
    let want = iterate(&open_polygon(), 4, chaikin_open);
    assert_points_eq(&points(&l, &d, "P"), &want, EPS);
    // The endmarkers survive at both ends.
    let names: Vec<&str> = d
        .word
        .syms()
        .iter()
        .map(|s| l.program.alphabet.name(*s))
        .collect();
    assert_eq!(names.first(), Some(&"#"));
    assert_eq!(names.last(), Some(&"#"));
    assert_eq!(count(&l, &d, "#"), 2);
}

#[test]
fn open_chaikin_full_system_equals_matrix_27() {
    open_case("curves/open-chaikin-full.lsys");
}

#[test]
fn open_chaikin_short_system_equals_matrix_27() {
    open_case("curves/open-chaikin-short.lsys");
}

#[test]
fn reverse_chaikin_38_equals_matrix_37() {
    let l = load(&lsys("curves/reverse-chaikin-38.lsys"));
    let d = derive(&l, DeriveOptions::default());
    let square = [(0., 0.), (0., 1.), (1., 1.), (1., 0.)].map(|(x, y)| DVec2::new(x, y));
    let fine = apply(&chaikin_closed(4), &square);
    let want = apply(&reverse_chaikin_closed(8), &fine);
    assert_points_eq(&points(&l, &d, "P"), &want, EPS);
    assert_points_eq(&points(&l, &d, "P"), &square, EPS);
}

/// Chaikin (13) then reverse Chaikin (38), with the partition aligned to the
/// pairs (13) produced, returns the control polygon exactly.
#[test]
fn chaikin_then_reverse_returns_the_polygon() {
    let forward = load(&lsys("curves/chaikin-13.lsys"));
    for steps in 1..=4u64 {
        let d = derive(&forward, DeriveOptions::default().with_steps(steps));
        let fine = points(&forward, &d, "P");
        let program = format!(
            "module P(V2f);\nring L-system: 1;\nderivation length: {steps};\nAxiom: {};\n\
             P(vl) < P(va) P(vb) > P(vr) -> P(-0.25*vl + 0.75*va + 0.75*vb - 0.25*vr)\n",
            axiom_of(&fine)
        );
        let back = load_text(&program);
        let r = derive(&back, DeriveOptions::default());
        // Exactly, not approximately: the weights are dyadic.
        assert_points_eq(&points(&back, &r, "P"), &hexagon(), 0.0);
    }
}

/// The other partition (phase 1) gives a different coarse curve, equal to
/// matrix (37) applied to the word rotated by one.
#[test]
fn reverse_chaikin_phase_one_takes_the_other_pairs() {
    let l = load(&lsys("curves/reverse-chaikin-38.lsys"));
    let d = derive(&l, DeriveOptions::default().with_phase(1));
    let square = [(0., 0.), (0., 1.), (1., 1.), (1., 0.)].map(|(x, y)| DVec2::new(x, y));
    let mut fine = apply(&chaikin_closed(4), &square);
    fine.rotate_left(1);
    let want = apply(&reverse_chaikin_closed(8), &fine);
    assert_points_eq(&points(&l, &d, "P"), &want, EPS);
    assert!(!points(&l, &d, "P")[0].abs_diff_eq(square[0], 1e-3));
}

/// Program 1 of paper 000 (Velho's printing) is Chaikin on the unit square.
#[test]
fn velho_program_1_is_chaikin() {
    let l = load(&lsys("paper/000-program1.lsys"));
    let d = derive(&l, DeriveOptions::default());
    let square = [(0., 0.), (0., 1.), (1., 1.), (1., 0.)].map(|(x, y)| DVec2::new(x, y));
    assert_cyclic_eq(
        &points(&l, &d, "P"),
        &iterate(&square, 3, chaikin_closed),
        EPS,
    );
}

/// Program 1 of paper 002 runs exactly as printed. The printed body reads
/// `0.25*v1`, and `v1` is the global point (0, 0), so the first new point
/// is 3/4 of the old one; the second follows (13).
#[test]
fn paper_002_program_1_runs_as_printed() {
    let l = load(&lsys("paper/002-program1.lsys"));
    let d = derive(&l, DeriveOptions::default());
    let square = [(0., 0.), (0., 1.), (1., 1.), (1., 0.)].map(|(x, y)| DVec2::new(x, y));
    let as_printed = |n: usize| {
        let mut m = vec![vec![0.0; n]; 2 * n];
        for i in 0..n {
            m[2 * i][i] = 0.75; // + 0.25 * v1, and v1 = (0, 0)
            m[2 * i + 1][i] += 0.75;
            m[2 * i + 1][(i + 1) % n] += 0.25;
        }
        m
    };
    assert_points_eq(&points(&l, &d, "P"), &iterate(&square, 3, as_printed), EPS);
}
