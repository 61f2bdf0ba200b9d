//! Issue 40, item 6: help with mistakes. A misspelt name gets the nearest
//! known one ("did you mean"), an unbalanced branch in a successor or an
//! axiom is a warning at its bracket, a turtle symbol without `angle:`
//! says what switches the notation on, an error inside a `define` used
//! twice is printed once, and `check` counts what the file holds.

use std::path::Path;
use std::process::Output;

use crate::support::scratch;

fn check(dir: &Path, name: &str, text: &str) -> (Output, String) {
    std::fs::write(dir.join(name), text).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(["check", name])
        .output()
        .unwrap();
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o, all)
}

#[test]
fn misspelt_names_get_the_nearest_known_one() {
    let tmp = scratch("mistakes-names");
    let dir = tmp.path();
    let program = |body: &str| {
        format!(
            "#include <lpfgall.h>\nmodule Apex(float);\nderivation length: 1;\n\
             Axiom: Apex(1);\nApex(vr) : {{\n{body}\n}}\n"
        )
    };
    for (body, at, message) in [
        (
            "  produce Apex(vrr);",
            "t.lsys:6:16",
            "unknown identifier `vrr`; did you mean `vr`?",
        ),
        (
            "  produce Apex(sqtr(vr));",
            "t.lsys:6:16",
            "unknown function `sqtr`; did you mean `sqrt`?",
        ),
        (
            "  produce Apx(vr);",
            "t.lsys:6:11",
            "undeclared module `Apx`: declare it before use, e.g. `module Apx(float);`; did you mean `Apex`?",
        ),
        // Nothing near: no suggestion.
        (
            "  produce Apex(banana);",
            "t.lsys:6:16",
            "unknown identifier `banana`\n",
        ),
    ] {
        let (o, out) = check(dir, "t.lsys", &program(body));
        assert_eq!(o.status.code(), Some(1), "{out}");
        assert!(out.contains(&format!("{at}: error: {message}")), "{body}:\n{out}");
    }
}

#[test]
fn an_unbalanced_branch_is_a_warning_at_its_bracket() {
    let tmp = scratch("mistakes-branches");
    let dir = tmp.path();
    let (o, out) = check(
        dir,
        "b.lsys",
        "angle: 25;\nderivation length: 3;\nAxiom: X;\nX -> F-[[X]+X]+F[+FX-X\nF -> FF\n",
    );
    assert_eq!(o.status.code(), Some(0), "{out}");
    assert!(
        out.contains(
            "b.lsys:4:17: warning: this `[` is never closed: the brackets of the successor do not balance"
        ),
        "{out}"
    );
    let (_, out) = check(dir, "a.lsys", "angle: 25;\nAxiom: F]F;\n");
    assert!(
        out.contains("a.lsys:2:9: warning: this `]` closes no branch: the brackets of the axiom do not balance"),
        "{out}"
    );
    // Balanced: no warning.
    let (_, out) = check(
        dir,
        "ok.lsys",
        "angle: 25;\nAxiom: F[+F][-F]F;\nF -> F[+F]F\n",
    );
    assert!(!out.contains("warning"), "{out}");
}

#[test]
fn a_turtle_symbol_without_angle_says_what_switches_the_notation_on() {
    let tmp = scratch("mistakes-angle");
    let (o, out) = check(
        tmp.path(),
        "k.lsys",
        "derivation length: 2;\nAxiom: F;\nF -> F+F--F+F\n",
    );
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert!(
        out.contains(
            "k.lsys:3:7: error: expected a module (a name, optionally with arguments in parentheses), \
             found `+`; `+` is a turtle command of the single-character notation (The Algorithmic \
             Beauty of Plants), which `angle: DEGREES;` at the start of a line switches on"
        ),
        "{out}"
    );
}

#[test]
fn an_error_in_a_define_used_twice_is_printed_once() {
    let tmp = scratch("mistakes-define");
    // The printed sqrt(3) grammar, whose `alpha` every vertex rule calls.
    let text = std::fs::read_to_string(
        crate::support::root().join("lsystems/surfaces/sqrt3-printed.lsys"),
    )
    .unwrap();
    let good = "define alpha(n) = (4 - 2*cos(2*PI/n)) / 9;";
    assert!(text.contains(good));
    let text = text.replace(good, "define alpha(n) = (4 - 2*cos(2*PI/n)) / 9 + zzz;");
    let (o, out) = check(tmp.path(), "d.lsys", &text);
    assert_eq!(o.status.code(), Some(1), "{out}");
    assert_eq!(out.matches("unknown identifier `zzz`").count(), 1, "{out}");
    assert!(
        out.contains("d.lsys:12:45: error: unknown identifier `zzz` (in `alpha`)"),
        "{out}"
    );
}

#[test]
fn check_counts_what_the_file_holds() {
    let tmp = scratch("mistakes-counts");
    let dir = tmp.path();
    let (_, out) = check(
        dir,
        "two.lsys",
        "#include <lpfgall.h>\nmodule A(int);\nmodule B;\nderivation length: 1;\nAxiom: A(1);\n\
         A(n) : { produce B; }\n",
    );
    assert!(
        out.trim_end()
            .ends_with("two.lsys: ok (1 production, 2 modules of its own)"),
        "{out}"
    );
    let (_, out) = check(
        dir,
        "i.lsys",
        "#include <lpfgall.h>\nmodule A(int);\nderivation length: 1;\nAxiom: A(1);\n\
         A(n) : { produce A(n) A(n); }\ninterpretation:\nA(n) : { produce F(1); }\n",
    );
    assert!(
        out.trim_end()
            .ends_with("i.lsys: ok (1 production, 1 interpretation rule, 1 module of its own)"),
        "{out}"
    );
}

/// A refused output names every format the command writes.
#[test]
fn a_refused_output_lists_what_the_command_writes() {
    let tmp = scratch("mistakes-formats");
    let dir = tmp.path();
    let grammar = crate::support::root().join("lsystems/surfaces/loop.lsys");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args([
            "subdivide",
            "--grammar",
            grammar.to_str().unwrap(),
            "-o",
            "x.jpg",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim_end(),
        "error: cannot tell the format of `x.jpg`: subdivide writes meshes (.obj, .off, .ply, \
         .glb) and pictures (.png, .svg)"
    );
}

/// A misspelt output extension (issue 40, item 6: file kinds) gets the
/// nearest one the command writes; one too far from any gets none.
#[test]
fn a_misspelt_output_extension_is_suggested() {
    let tmp = scratch("mistakes-extension");
    let dir = tmp.path();
    std::fs::write(dir.join("k.lsys"), "angle: 60;\nAxiom: F;\nF -> F+F--F+F\n").unwrap();
    std::fs::write(dir.join("t.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let run = |args: &[&str]| {
        let o = crate::support::subgram_in(dir, args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        String::from_utf8_lossy(&o.stderr).trim_end().to_string()
    };
    assert_eq!(
        run(&["render", "k.lsys", "-o", "k.pgn"]),
        "error: cannot tell the format of `k.pgn`: render writes pictures (.png, .svg), \
         animations (.gif, .apng) and 3D geometry (.obj, .ply, .glb); did you mean `.png`?"
    );
    assert_eq!(
        run(&["mesh", "convert", "t.obj", "t.plyy"]),
        "error: t.plyy: unknown mesh format `.plyy`: expected a file ending in .obj, .off or \
         .ply; did you mean `.ply`?"
    );
    assert_eq!(
        run(&["render", "t.obj", "-o", "t.svgg"]),
        "error: cannot tell the format of `t.svgg`: render draws a mesh as a picture (.png, \
         .svg); `subgram mesh convert` writes it as a mesh; did you mean `.svg`?"
    );
    // `.jpg` is two edits from `.png`: no guess.
    assert!(!run(&["render", "k.lsys", "-o", "k.jpg"]).contains("did you mean"));
}

/// `derive -o FILE` (issue 40, item 7): the word goes to the file, whole,
/// or not at all; never over the program.
#[test]
fn derive_writes_its_word_to_a_file() {
    let tmp = scratch("mistakes-derive-o");
    let dir = tmp.path();
    let koch = "angle: 60;\nderivation length: 1;\nAxiom: F;\nF -> F+F--F+F\n";
    std::fs::write(dir.join("k.lsys"), koch).unwrap();
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
            .current_dir(dir)
            .args(args)
            .output()
            .unwrap()
    };
    let o = run(&["derive", "k.lsys", "-o", "w.txt"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.stdout.is_empty());
    let printed = run(&["derive", "k.lsys"]);
    assert_eq!(std::fs::read(dir.join("w.txt")).unwrap(), printed.stdout);
    let o = run(&["derive", "k.lsys", "-o", "k.lsys"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains(
        "the output `k.lsys` is the program: writing it would replace it; name another output"
    ));
    assert_eq!(std::fs::read_to_string(dir.join("k.lsys")).unwrap(), koch);
    // A derivation that fails leaves no file.
    let o = run(&[
        "derive",
        "k.lsys",
        "-n",
        "20",
        "--max-modules",
        "1000",
        "-o",
        "big.txt",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["k.lsys", "w.txt"]);
}

/// `render` writes a surface grammar's, a vv program's and a shape
/// grammar's 3D file as `subdivide` does (issue 40, item 7): the same
/// bytes (a shape grammar's OBJ names its own MTL).
#[test]
fn render_writes_every_kind_of_system_as_subdivide_does() {
    let tmp = scratch("mistakes-render-3d");
    let dir = tmp.path();
    let root = crate::support::root();
    let run = |args: &[&str]| {
        let o = crate::support::subgram_in(dir, args);
        assert_eq!(
            o.status.code(),
            Some(0),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    };
    for (file, steps, ext) in [
        ("lsystems/surfaces/loop.lsys", "2", "obj"),
        ("lsystems/vv/loop.lsys", "1", "ply"),
        ("lsystems/shapes/building.lsys", "0", "obj"),
        ("lsystems/shapes/building.lsys", "0", "glb"),
    ] {
        let g = root.join(file);
        let g = g.to_str().unwrap();
        let (r, s) = (format!("r.{ext}"), format!("s.{ext}"));
        let mut render = vec!["render", g, "-o", &r];
        let mut subdivide = vec!["subdivide", "--grammar", g, "-o", &s];
        if steps != "0" {
            render.extend(["-n", steps]);
            subdivide.extend(["-n", steps]);
        }
        run(&render);
        run(&subdivide);
        let a = std::fs::read(dir.join(&r)).unwrap();
        let b = std::fs::read(dir.join(&s)).unwrap();
        let a = String::from_utf8_lossy(&a).replace("mtllib r.mtl", "mtllib s.mtl");
        assert!(a == String::from_utf8_lossy(&b), "{file} .{ext} differs");
    }
}
