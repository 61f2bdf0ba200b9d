//! What the adversarial pass over vv programs found that is no error: the
//! right answer where a wrong one came out silently. Each program prints
//! what it reads; the expected text is worked out by hand in the test from
//! the definitions (paper 001, §3: `'v` is the state at the last
//! `synchronize`) and the base mesh's numbering. The error cases are in
//! the bad-input corpus (`tests/data/err/vv-*`).

use std::path::PathBuf;
use std::process::Command;

use subgram::{LoadOptions, ProgramOutput, RunOptions, System};

use crate::support::{root, scratch};

fn mesh(name: &str) -> PathBuf {
    root().join("lsystems/meshes").join(name)
}

/// Runs vv program `text` on base mesh `base` and gives what it printed.
fn printed(text: &str, base: &str) -> String {
    let system = subgram::load_text("adv.lsys", text, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let System::Vv(vv) = system else {
        panic!("not a vv program")
    };
    let output = ProgramOutput::new();
    let opts = RunOptions {
        base_mesh: Some(mesh(base)),
        output: output.clone(),
        ..RunOptions::default()
    };
    vv.run(&opts, |_| {}).unwrap_or_else(|e| panic!("{e}"));
    output.take_text().into_iter().map(|(_, t)| t).collect()
}

/// A vertex that only an old neighbourhood lists is still that vertex in
/// a later step: it is not freed, so a new vertex cannot take its slot.
/// Before, x (inserted on edge p0-q0 at step 0, taken out at step 1 after
/// the synchronize) was freed at the end of step 1, the new y of step 2
/// took its id, and `is y in 'p0` was true.
#[test]
fn a_vertex_an_old_neighbourhood_lists_is_not_recycled() {
    let text = r#"
mesh S;
derivation length: 3;
vertex p0;
vertex q0;
vertex x0;
Step: {
  if (StepNo() == 0) {
    forall p in S { p0 = p; break; }
    q0 = any in p0;
    vertex x;
    replace q0 with x in p0;
    replace p0 with x in q0;
    make {p0, q0} nb_of x;
    add x to S;
    x0 = x;
  }
  if (StepNo() == 1) {
    synchronize S;
    replace x0 with q0 in p0;
    replace x0 with p0 in q0;
    remove x0 from S;
    x0 = null;
  }
  if (StepNo() == 2) {
    vertex y;
    printf("%d", is y in 'p0);
    forall q in 'p0
      printf(" %d", valence q);
    printf("\n");
  }
}
"#;
    // At the synchronize of step 1, p0 (a cube corner, valence 3) listed
    // x in q0's place and its two other cube neighbours: 'p0* = {x, a, b}.
    // y is new, so not in 'p0*. x's own list was never edited after
    // `make {p0, q0}`: valence 2; a and b are cube corners: valence 3.
    assert_eq!(printed(text, "cube.obj"), "0 2 3 3\n");
}

/// A vertex that a global holds keeps its neighbours, even those no
/// global holds: before, they were freed at the end of `Start`, the new
/// vertices of the step took their slots, and g's neighbours read the new
/// vertices' positions.
#[test]
fn the_neighbours_of_a_vertex_a_global_holds_are_kept() {
    let text = r#"
mesh S;
vertex g;
Start: {
  vertex a;
  vertex b;
  vertex g0;
  a$pos = V3d(1, 0, 0);
  b$pos = V3d(0, 1, 0);
  make {a, b} nb_of g0;
  g = g0;
}
Step: {
  mesh T;
  for (int i = 0; i < 4; i++) {
    vertex n;
    n$pos = V3d(9, 9, 9);
    add n to T;
  }
  forall q in g
    printf("%g %g\n", q$pos.x, q$pos.y);
}
"#;
    // g's neighbours are a and b, at the positions Start gave them.
    assert_eq!(printed(text, "cube.obj"), "1 0\n0 1\n");
}

/// `('p, q)$w` reads the edge as the last synchronize kept it (it read the
/// current value), and an edge statement may follow `forall x in 'p`
/// without braces (it was read as a call of `'p`).
#[test]
fn old_edge_properties_and_edge_statements_after_forall() {
    let text = r#"
mesh S;
edge float w = 5;
Step: {
  synchronize S;
  forall p in S
    forall q in 'p
      (p, q)$w = ('p, q)$w + 4;
  forall p in S
    forall q in p (p, q)$w += 1;
  float old = 0, now = 0;
  forall p in S
    forall q in p {
      old += ('p, q)$w;
      now += (p, q)$w;
    }
  printf("%g %g\n", old, now);
}
"#;
    // The tetrahedron has 12 directed edges. Old: the default, 5, each:
    // 60. Now: 5 + 4, then + 1: 10 each, 120.
    assert_eq!(printed(text, "tetrahedron.obj"), "60 120\n");
}

/// One name may be a property of a vertex, of an edge and of the mesh:
/// each owner numbers its own (the mesh's took the vertex's number, and
/// `mesh$c` panicked).
#[test]
fn one_name_may_be_a_property_of_each_owner() {
    let text = r#"
mesh S;
vertex float c = 1;
edge float c = 2;
mesh float c = 3;
Step: {
  forall p in S {
    vertex q = any in p;
    printf("%g %g %g\n", p$c, (p, q)$c, mesh$c);
    break;
  }
}
"#;
    assert_eq!(printed(text, "tetrahedron.obj"), "1 2 3\n");
}

/// The valence limit is raised to twice the base mesh's highest valence:
/// on a fan of 1,500 triangles (a centre of valence 1,500, above the
/// default bound of 1000), splicing one more neighbour into the centre is
/// allowed.
#[test]
fn the_valence_limit_makes_room_for_the_base_mesh() {
    let tmp = scratch("vv-adv");
    let dir = tmp.path();
    let n = 1500;
    let mut obj = String::from("v 0 0 0\n");
    for k in 0..n {
        let a = k as f64 * std::f64::consts::TAU / n as f64;
        obj += &format!("v {} {} 0\n", a.cos(), a.sin());
    }
    for k in 0..n {
        obj += &format!("f 1 {} {}\n", k + 2, (k + 1) % n + 2);
    }
    let path = dir.join("fan.obj");
    std::fs::write(&path, obj).unwrap();
    let text = r#"
mesh S;
Step: {
  forall p in S
    if (valence p > 3) {
      vertex x;
      splice x after any in p in p;
      printf("%d ", valence p);
      erase x from p;
      printf("%d\n", valence p);
    }
}
"#;
    let system = subgram::load_text("fan.lsys", text, &LoadOptions::default()).unwrap();
    let System::Vv(vv) = system else {
        panic!("not a vv program")
    };
    let output = ProgramOutput::new();
    let opts = RunOptions {
        base_mesh: Some(path),
        output: output.clone(),
        ..RunOptions::default()
    };
    let r = vv.run(&opts, |_| {});
    if let Err(e) = r {
        panic!("{e}");
    }
    let text: String = output.take_text().into_iter().map(|(_, t)| t).collect();
    // Only the centre has more than 3 neighbours: 1500, one more, back.
    assert_eq!(text, "1501 1500\n");
}

/// `derive` and `render` of a vv program write the files it opened with
/// `--allow-writes` (they were dropped without a word).
#[test]
fn vv_programs_write_their_files_under_allow_writes() {
    let tmp = scratch("vv-adv-w");
    let dir = tmp.path();
    let out = dir.join("out");
    std::fs::create_dir(&out).unwrap();
    let program = dir.join("count.lsys");
    std::fs::copy(mesh("tetrahedron.obj"), dir.join("tetrahedron.obj")).unwrap();
    std::fs::write(
        &program,
        "mesh S = \"tetrahedron.obj\";\n\
         Step: { FILE *f = fopen(\"count.txt\", \"w\"); fprintf(f, \"%d\\n\", size(S)); fclose(f); }\n",
    )
    .unwrap();
    let bin = env!("CARGO_BIN_EXE_subgram");
    let run = |args: &[&str]| {
        let o = Command::new(bin).args(args).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (p, w) = (program.to_str().unwrap(), out.to_str().unwrap());
    run(&["derive", "--allow-writes", w, p]);
    let derived = std::fs::read_to_string(out.join("count.txt"));
    std::fs::remove_file(out.join("count.txt")).ok();
    let png = dir.join("t.png");
    run(&[
        "render",
        "--allow-writes",
        w,
        "-o",
        png.to_str().unwrap(),
        p,
    ]);
    let rendered = std::fs::read_to_string(out.join("count.txt"));
    // The tetrahedron has 4 vertices.
    assert_eq!(derived.ok().as_deref(), Some("4\n"));
    assert_eq!(rendered.ok().as_deref(), Some("4\n"));
}

/// Sets and vertices inside arrays and structs start as an empty set and
/// the null vertex, as plain variables do: they started void, so `add p
/// to sets[1]` did nothing and `corners[0] == null` was false.
#[test]
fn sets_and_vertices_in_arrays_and_structs_start_empty_and_null() {
    let text = r#"
mesh S;
struct Group { mesh m; vertex v; };
mesh global_sets[2];
Group global_group;
Step: {
  mesh sets[2];
  Group group;
  vertex corners[2];
  forall p in S {
    add p to sets[1];
    add p to group.m;
    add p to global_sets[0];
    add p to global_group.m;
  }
  printf("%d %d %d %d %d\n", size(sets[0]), size(sets[1]), size(group.m),
         size(global_sets[0]), size(global_group.m));
  printf("%d %d %d\n", corners[1] == null, group.v == null, global_group.v == null);
}
"#;
    // The cube has 8 vertices; sets[0] got none.
    assert_eq!(printed(text, "cube.obj"), "0 8 8 8 8\n1 1 1\n");
}

/// `--seed` seeds a vv program's random number generators as it seeds a
/// curve's (it was ignored: every seed gave lpfg's starting state).
#[test]
fn seed_seeds_a_vv_program_as_it_seeds_a_curve() {
    let tmp = scratch("vv-adv-s");
    let dir = tmp.path();
    std::fs::copy(mesh("tetrahedron.obj"), dir.join("tetrahedron.obj")).unwrap();
    let draw = r#"printf("%g %d %g\n", ran(1.0), rand(), drand48());"#;
    let vv = dir.join("vv.lsys");
    let curve = dir.join("curve.lsys");
    std::fs::write(
        &vv,
        format!("mesh S = \"tetrahedron.obj\";\nStep: {{ {draw} }}\n"),
    )
    .unwrap();
    std::fs::write(&curve, format!("Start: {{ {draw} }}\nAxiom: F;\n")).unwrap();
    let first_line = |file: &PathBuf, seed: &str| {
        let mut args = vec!["derive", file.to_str().unwrap()];
        if !seed.is_empty() {
            args.extend(["--seed", seed]);
        }
        let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
            .args(&args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .next()
            .unwrap_or_default()
            .to_string()
    };
    let (v7, c7) = (first_line(&vv, "7"), first_line(&curve, "7"));
    let (v8, v_none) = (first_line(&vv, "8"), first_line(&vv, ""));
    let c_none = first_line(&curve, "");
    assert_eq!(v7, c7);
    assert_eq!(v_none, c_none);
    assert_ne!(v7, v8);
    assert_ne!(v7, v_none);
}

/// A vv program is recognised by `mesh NAME` after a `;` too, not only at
/// the start of a line (`int n; mesh S;` was read as a curve, with three
/// errors about an unknown type, the axiom and a module `Step`); a curve
/// that names a variable `mesh` stays a curve.
#[test]
fn a_vv_program_may_declare_its_mesh_after_a_semicolon() {
    let opts = LoadOptions::default();
    let vv = subgram::load_text("a.lsys", "int n; mesh S;\nStep: { n++; }\n", &opts);
    assert!(matches!(vv, Ok(System::Vv(_))), "{:?}", vv.err());
    let curve = "int mesh;\nStart: { mesh = 1; mesh++; }\nAxiom: F(mesh);\n";
    let c = subgram::load_text("b.lsys", curve, &opts);
    assert!(matches!(c, Ok(System::Curve(_))), "{:?}", c.err());
}

/// `'a[i]` and `'g.v` read the old state of a vertex held in an array or
/// a struct (they read as `old(a)[i]`, "`'v` takes a vertex"); `$` still
/// binds outside, so `'a[1]$pos` is the old position.
#[test]
fn old_state_of_a_vertex_in_an_array_or_a_struct() {
    let text = r#"
mesh S;
struct G { vertex v; };
G g;
vertex a[2];
Step: {
  forall p in S { g.v = p; a[1] = p; }
  synchronize S;
  forall p in S
    p$pos = 2 * p$pos;
  printf("%d %d %g %g %g\n", valence 'g.v, valence 'a[1], 'a[1]$pos.x, a[1]$pos.x, 'g.v$pos.y);
}
"#;
    // Both hold the last vertex of S, the cube's eighth, at (1, 1, 1), of
    // valence 3; its position doubles after the synchronize.
    assert_eq!(printed(text, "cube.obj"), "3 3 1 2 1\n");
}
