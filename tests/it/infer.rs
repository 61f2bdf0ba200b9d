//! `subgram infer` (issue 19, part 1): productions inferred from the
//! subdivision matrices of paper 002 are the paper's own, transcribed here
//! from (13), (17), (18), (20), (22), (23), (25), (26), (28)-(36) and (38),
//! and the programs `infer` writes, run through the engine, equal the
//! matrices applied in the test (tests/it/support.rs builds them).

use glam::DVec2;
use subgram::command::{self, InferArgs};

use crate::support::*;

/// A matrix as `--rows` text: `a b c; d e f`.
fn rows_text(m: &Matrix) -> String {
    m.iter()
        .map(|r| {
            r.iter()
                .map(|w| format!("{w}"))
                .collect::<Vec<_>>()
                .join(" ")
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn infer(a: InferArgs) -> String {
    command::infer(&a).unwrap_or_else(|e| panic!("{e}"))
}

fn rows(m: &Matrix) -> InferArgs {
    InferArgs {
        rows: Some(rows_text(m)),
        ..Default::default()
    }
}

/// The productions of a program: its lines with `->` before
/// `interpretation:`.
fn productions(lsys: &str) -> Vec<String> {
    lsys.split("interpretation:")
        .next()
        .unwrap()
        .lines()
        .filter(|l| l.contains("->") && !l.trim_start().starts_with("//"))
        .map(str::to_string)
        .collect()
}

/// The program's axiom points and its word after one step.
fn one_step(lsys: &str) -> (Vec<DVec2>, Vec<DVec2>) {
    let l = load_text(lsys);
    let before = points(
        &l,
        &derive(
            &l,
            subgram::DeriveOptions {
                steps: Some(0),
                ..Default::default()
            },
        ),
        "P",
    );
    let after = points(
        &l,
        &derive(
            &l,
            subgram::DeriveOptions {
                steps: Some(1),
                ..Default::default()
            },
        ),
        "P",
    );
    (before, after)
}

/// Closed schemes: each shift's production is the paper's, and the program
/// does what the matrix does (up to where the ring starts).
fn closed_forms(m: impl Fn(usize) -> Matrix, forms: &[(i64, &str)]) {
    for &(d, paper) in forms {
        let text = infer(InferArgs {
            shift: Some(d),
            ..rows(&m(8))
        });
        assert_eq!(productions(&text), [paper], "shift {d}:\n{text}");
        let (before, after) = one_step(&text);
        assert_cyclic_eq(&after, &apply(&m(before.len()), &before), 1e-12);
    }
}

#[test]
fn chaikin_13_17_18_and_20() {
    closed_forms(
        chaikin_closed,
        &[
            (
                0,
                "P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)",
            ),
            (
                -1,
                "P(vl) < P(v) -> P(0.75*vl + 0.25*v) P(0.25*vl + 0.75*v)",
            ),
            (1, "P(v) > P(vr) -> P(0.75*v + 0.25*vr) P(0.25*v + 0.75*vr)"),
            // The paper prints (20) for "d = 3"; by its own j ≡ 2i + d the
            // pair (j − 1, j) that (20) takes, 3/4·v_rr + 1/4·v_rrr first,
            // is j = 2i + 5.
            (
                5,
                "P(v) > P(vr) P(vrr) P(vrrr) -> P(0.75*vrr + 0.25*vrrr) P(0.25*vrr + 0.75*vrrr)",
            ),
        ],
    );
}

#[test]
fn cubic_b_spline_22_and_23() {
    closed_forms(
        cubic_closed,
        &[
            (
                0,
                "P(vl) < P(v) > P(vr) -> P(0.125*vl + 0.75*v + 0.125*vr) P(0.5*v + 0.5*vr)",
            ),
            (
                -1,
                "P(vl) < P(v) > P(vr) -> P(0.5*vl + 0.5*v) P(0.125*vl + 0.75*v + 0.125*vr)",
            ),
        ],
    );
}

#[test]
fn four_point_25_and_26() {
    closed_forms(
        four_point_closed,
        &[
            (
                0,
                "P(vl) < P(v) > P(vr) P(vrr) -> P(v) P(-0.0625*vl + 0.5625*v + 0.5625*vr - 0.0625*vrr)",
            ),
            (
                -1,
                "P(vll) P(vl) < P(v) > P(vr) -> P(-0.0625*vll + 0.5625*vl + 0.5625*v - 0.0625*vr) P(v)",
            ),
        ],
    );
}

#[test]
fn the_default_grouping_is_the_papers_symmetric_one_and_every_grouping_is_listed() {
    let text = infer(rows(&chaikin_closed(8)));
    assert_eq!(
        productions(&text),
        ["P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)"]
    );
    let list = infer(InferArgs {
        list: true,
        ..rows(&chaikin_closed(8))
    });
    for (d, shape) in [(-1, "1|1|0"), (0, "1|1|1"), (1, "0|1|1"), (5, "0|1|3")] {
        assert!(
            list.lines()
                .any(|l| l.contains(&format!("d = {d:>3}")) && l.contains(shape)),
            "d = {d} {shape}:\n{list}"
        );
    }
    // The chosen one is marked.
    assert!(list.lines().any(|l| l.starts_with("* d =   0")), "{list}");
}

#[test]
fn a_band_of_one_old_points_rows_and_a_mask_give_the_same_productions() {
    // The example: one old point's two rows over three columns.
    let band = infer(InferArgs {
        rows: Some("1/4 3/4 0; 0 3/4 1/4".into()),
        ..Default::default()
    });
    let mask = infer(InferArgs {
        mask: Some("1/4 3/4 3/4 1/4".into()),
        ..Default::default()
    });
    let want = ["P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)"];
    assert_eq!(productions(&band), want);
    assert_eq!(productions(&mask), want);
    // Masks of the cubic B-spline and the four-point scheme.
    let cubic = infer(InferArgs {
        mask: Some("1/8 1/2 3/4 1/2 1/8".into()),
        ..Default::default()
    });
    let (before, after) = one_step(&cubic);
    assert_cyclic_eq(&after, &apply(&cubic_closed(before.len()), &before), 1e-12);
    let four = infer(InferArgs {
        mask: Some("-1/16 0 9/16 1 9/16 0 -1/16".into()),
        ..Default::default()
    });
    let (before, after) = one_step(&four);
    assert_cyclic_eq(
        &after,
        &apply(&four_point_closed(before.len()), &before),
        1e-12,
    );
}

/// Open Chaikin from matrix (27): the unordered productions (28)-(33) and
/// the ordered (34)-(36), each run equal to the matrix.
#[test]
fn open_chaikin_28_to_36_from_matrix_27() {
    let m = rows_text(&chaikin_open(8));
    let unordered = infer(InferArgs {
        rows: Some(m.clone()),
        open: true,
        ..Default::default()
    });
    assert_eq!(
        productions(&unordered),
        [
            "# < P(v) -> P(v)",
            "# P(vl) < P(v) > P(vr) -> P(0.5*vl + 0.5*v) P(0.75*v + 0.25*vr)",
            "P(vll) P(vl) < P(v) > P(vr) P(vrr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)",
            "P(vl) < P(v) > P(vr) # -> P(0.25*vl + 0.75*v) P(0.5*v + 0.5*vr)",
            "P(v) > # -> P(v)",
            "# -> #",
        ]
    );
    let ordered = infer(InferArgs {
        rows: Some(m),
        open: true,
        ordered: true,
        ..Default::default()
    });
    assert_eq!(
        productions(&ordered),
        [
            "# P(vl) < P(v) > P(vr) -> P(0.5*vl + 0.5*v) P(0.75*v + 0.25*vr)",
            "P(vl) < P(v) > P(vr) # -> P(0.25*vl + 0.75*v) P(0.5*v + 0.5*vr)",
            "P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)",
        ]
    );
    for text in [&unordered, &ordered] {
        let (before, after) = one_step(text);
        assert_eq!(after, apply(&chaikin_open(before.len()), &before), "{text}");
    }
}

/// Reverse Chaikin from matrix (37): production (38), a pseudo-L-system
/// whose strict predecessor is a pair; run, it is the matrix.
#[test]
fn reverse_chaikin_38_from_matrix_37() {
    let text = infer(InferArgs {
        rows: Some(rows_text(&reverse_chaikin_closed(16))),
        reverse: true,
        ..Default::default()
    });
    assert_eq!(
        productions(&text),
        ["P(vl) < P(va) P(vb) > P(vr) -> P(-0.25*vl + 0.75*va + 0.75*vb - 0.25*vr)"]
    );
    let (before, after) = one_step(&text);
    assert_cyclic_eq(
        &after,
        &apply(&reverse_chaikin_closed(before.len()), &before),
        1e-12,
    );
}

#[test]
fn bad_matrices_are_refused_with_their_place_and_reason() {
    let e = |a: InferArgs| command::infer(&a).unwrap_err().to_string();
    let m = e(InferArgs {
        rows: Some("1/4 3/4 0; 0 3/4 y".into()),
        ..Default::default()
    });
    assert!(
        m.starts_with("--rows:1:18: error: expected a number"),
        "{m}"
    );
    // Not a stationary ring: the second block is not the first moved.
    let mut bad = chaikin_closed(8);
    bad[3][0] = 0.5;
    let m = e(rows(&bad));
    assert!(m.contains("row 4 is not row 2 moved one column"), "{m}");
    let m = e(InferArgs {
        rows: Some("1 0; 0 1 0".into()),
        ..Default::default()
    });
    assert!(
        m.contains("this row has 3 entries and the first row 2"),
        "{m}"
    );
    let m = e(InferArgs {
        mask: Some("1/2 1/2".into()),
        rows: Some("1".into()),
        ..Default::default()
    });
    assert!(m.contains("give the scheme once"), "{m}");
    let tmp = scratch("infer");
    let dir = tmp.path();
    let f = dir.join("m.txt");
    std::fs::write(&f, "# Chaikin\n1/4 3/4 0\n0 3/4 1/4x\n").unwrap();
    let m = e(InferArgs {
        rows_file: Some(f.to_string_lossy().into()),
        ..Default::default()
    });
    assert!(
        m.contains("m.txt:3:7: error: expected a number") && m.contains("^"),
        "{m}"
    );
}

/// An open matrix whose first old point keeps no new point (2 rows for 3
/// points: new 1 = old 1, new 2 = old 2) erases it (`produce;`), and each
/// other point takes its left neighbour: one step drops the last point.
/// The program runs.
#[test]
fn a_point_that_keeps_no_new_point_is_erased_by_a_program_that_runs() {
    let text = infer(InferArgs {
        rows: Some("1 0 0; 0 1 0".into()),
        open: true,
        ..Default::default()
    });
    assert!(text.contains("# < P(v) : { produce; }"), "{text}");
    let (before, after) = one_step(&text);
    assert_eq!(after, before[..before.len() - 1]);
}
