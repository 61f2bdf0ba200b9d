//! The textbook systems of The Algorithmic Beauty of Plants in
//! `lsystems/abop/`, and the single-character turtle they are written with.
//! (The lpfg programs of the shared corpus are checked by the `shared` test
//! target, tests/shared.)

use subgram::DeriveOptions;

use crate::support::*;

/// The textbook systems of The Algorithmic Beauty of Plants, written with
/// the single-character turtle, against the counts in ORACLES.md.
#[test]
fn algorithmic_beauty_of_plants_systems_have_their_known_counts() {
    for (file, fs) in [
        ("abop/koch-snowflake.lsys", 768),
        ("abop/quadratic-koch-island.lsys", 2048),
        ("abop/hilbert.lsys", 1023),
        ("abop/dragon.lsys", 1024),
        ("abop/sierpinski-square.lsys", 1364),
    ] {
        let l = load(&lsys(file));
        let d = derive(&l, DeriveOptions::default());
        assert_eq!(count(&l, &d, "F"), fs, "{file}");
    }
}

/// `F+F[-X]` reads as modules, `--` as two turns, and `angle:` sets the turn.
#[test]
fn single_character_turtle_reads_as_printed() {
    let l = load_text("angle: 30;\nderivation length: 1;\nAxiom: FX;\nX -> X+YF--[F]\n");
    let d = derive(&l, DeriveOptions::default());
    assert_eq!(text(&l, &d), "F X Left Y F Right Right SB F EB");
    // The first F goes up; after `+` the second turns 30 degrees left; after
    // `--` the bracketed one points 30 degrees right of up.
    let mut deriv = subgram::Derivation::new(&l.program, DeriveOptions::default()).unwrap();
    assert_eq!(deriv.angle().unwrap(), Some(30.0));
    let opts = subgram::draw::DrawOptions {
        angle: 30.0,
        ..Default::default()
    };
    let events =
        subgram::draw::draw(&d.word, &l.program.alphabet, &l.program.structs, &opts).unwrap();
    // One path: each line starts where the last ended, `[F]` included.
    assert_eq!(events.len(), 1, "{events:?}");
    let dirs: Vec<glam::DVec3> = events[0].segments().map(|(a, b)| b - a).collect();
    let (s30, c30) = (0.5, 3f64.sqrt() / 2.0);
    let want = [
        glam::DVec3::Y,
        glam::DVec3::new(-s30, c30, 0.0),
        glam::DVec3::new(s30, c30, 0.0),
    ];
    assert_eq!(dirs.len(), 3);
    for (g, w) in dirs.iter().zip(want) {
        assert!(g.abs_diff_eq(w, 1e-12), "{g} != {w}");
    }
}
