//! Whole runs: the points of split rules computed between their splits
//! against the points computed after all of them.

use std::path::PathBuf;

use super::Grammar;
use crate::mesh::{io, shapes, Mesh};

fn grammar(name: &str, text: &str) -> Grammar {
    let front = crate::syntax::source::front(name, text.to_string(), &[]).expect("reads");
    crate::surface::from_front_with(front, true).unwrap_or_else(|e| panic!("{e}"))
}

/// A mesh of `lsystems/meshes`.
fn mesh_file(name: &str) -> Mesh {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/meshes");
    io::read_mesh(&dir.join(name)).expect("a mesh")
}

/// Runs `g` `steps` steps on `mesh`, with the points of split rules
/// computed between their splits where `between` allows it, and after
/// all of them otherwise.
fn run_with(g: &mut Grammar, mesh: &Mesh, steps: usize, between: bool) -> Result<Mesh, String> {
    for r in &mut g.rules {
        r.points_between_splits &= between;
    }
    let mut m = mesh.clone();
    g.run(&mut m, steps, |_| {})
        .map(|()| m)
        .map_err(|e| g.render_error(&e))
}

fn same_bits(a: &Mesh, b: &Mesh) -> bool {
    a == b
        && a.pos
            .iter()
            .zip(&b.pos)
            .all(|(p, q)| p.to_array().map(f64::to_bits) == q.to_array().map(f64::to_bits))
}

/// A split rule's points computed right after each part of its splits
/// give the mesh that computing them after all splits gives, to the
/// bit: Loop, Catmull-Clark, √3, c4 and 4-8 (their `avg(e)` and
/// `avg(f)` split rules compute points between splits) on their own
/// meshes, the bunny and a sphere of two batches. A point that reads a
/// valence, which later splits change, is computed after all of them,
/// and a bad point gives the error it gives after all splits.
#[test]
fn points_between_splits_are_the_points_after_all_splits() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/surfaces");
    let mut between = 0;
    let sphere = Mesh::from_soup(&shapes::icosphere(6)).expect("a sphere");
    for file in [
        "loop.lsys",
        "catmull-clark.lsys",
        "sqrt3.lsys",
        "c4.lsys",
        "four-eight.lsys",
    ] {
        let text = std::fs::read_to_string(dir.join(file)).expect("reads");
        let mut g = grammar(file, &text);
        between += g.rules.iter().filter(|r| r.points_between_splits).count();
        let own = g.mesh.clone().expect("names its mesh").0;
        let own = mesh_file(own.trim_start_matches("../meshes/"));
        // The icosphere's 122,880 edges are eight parts of matches and
        // two batches of points.
        for (mesh, steps) in [(&own, 3), (&mesh_file("bunny.obj"), 1), (&sphere, 1)] {
            let a = run_with(&mut grammar(file, &text), mesh, steps, true);
            let b = run_with(&mut g, mesh, steps, false);
            match (a, b) {
                (Ok(a), Ok(b)) => assert!(same_bits(&a, &b), "{file}"),
                (Err(a), Err(b)) => assert_eq!(a, b, "{file}"),
                (a, b) => panic!("{file}: {:?} and {:?}", a.err(), b.err()),
            }
        }
    }
    assert!(
        between >= 3,
        "{between} rules compute points between splits"
    );
    // A point that reads the new vertex's valence: the splits of the
    // edges after its own raise it, so it waits for all of them (on
    // the sphere, whose edges make two batches).
    let valence = "mesh: \"../meshes/octahedron.obj\";\n\
        E(e) | F^2 -> V(v = avg(e) * (1 + 0.01 * valence(v))) || E^4 F^4;\n";
    let mut g = grammar("valence.lsys", valence);
    assert!(!g.rules[0].points_between_splits && g.rules[0].points_in_place);
    let after = run_with(&mut g, &sphere, 1, true).expect("runs");
    let mut wrong = grammar("valence.lsys", valence);
    wrong.rules[0].points_between_splits = true;
    let early = run_with(&mut wrong, &sphere, 1, true).expect("runs");
    assert!(
        !same_bits(&after, &early),
        "the valences differ between splits"
    );
    // A bad point is the error it is after all splits.
    let bad = "mesh: \"../meshes/bunny.obj\";\n\
        E(e) | F^2 -> V(v = avg(e) / (l(e) - l(e))) || E^4 F^4;\n\
        E(e) | F -> V(v = avg(e)) || E^3 F^2;\n";
    let bunny = mesh_file("bunny.obj");
    let a = run_with(&mut grammar("bad.lsys", bad), &bunny, 1, true);
    let b = run_with(&mut grammar("bad.lsys", bad), &bunny, 1, false);
    assert!(a.is_err());
    assert_eq!(a.err(), b.err());
}
