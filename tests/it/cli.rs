//! The `subgram` binary: output formats, exit codes, and no panics.

use std::process::{Command, Output};

use crate::support::*;

fn subgram(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn derive_prints_the_final_word() {
    let f = lsys("curves/reverse-chaikin-38.lsys");
    let o = subgram(&["derive", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o).trim(), "P([0, 0]) P([0, 1]) P([1, 1]) P([1, 0])");
}

#[test]
fn derive_json_has_the_documented_shape() {
    let f = lsys("curves/reverse-chaikin-38.lsys");
    let o = subgram(&["derive", f.to_str().unwrap(), "--format", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["ring"], true);
    assert_eq!(v["step"], 1);
    assert_eq!(v["modules"].as_array().unwrap().len(), 4);
    assert_eq!(v["modules"][1]["symbol"], "P");
    assert_eq!(v["modules"][1]["params"], serde_json::json!([[0.0, 1.0]]));
}

/// A large word, written as it is made, is whole JSON: the quadratic Koch
/// island after 5 steps holds 4 * 8^5 = 131,072 `F` (each `F` becomes 8),
/// and the text form says the same.
#[test]
fn a_large_word_streams_as_valid_json_and_text() {
    let f = lsys("abop/quadratic-koch-island.lsys");
    let o = subgram(&["derive", f.to_str().unwrap(), "-n", "5", "--format", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let modules = v["modules"].as_array().unwrap();
    let f_count = modules.iter().filter(|m| m["symbol"] == "F").count();
    assert_eq!(f_count, 4 * 8usize.pow(5));
    assert_eq!(v["step"], 5);
    let o = subgram(&["derive", f.to_str().unwrap(), "-n", "5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.ends_with('\n') && !text.ends_with("\n\n"));
    assert_eq!(
        text.split_whitespace().filter(|m| *m == "F").count(),
        4 * 8usize.pow(5)
    );
    assert_eq!(text.split_whitespace().count(), modules.len());
}

#[test]
fn steps_and_defines_override_the_file() {
    let f = lsys("curves/chaikin-13.lsys");
    let o = subgram(&["derive", f.to_str().unwrap(), "-n", "2", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["modules"].as_array().unwrap().len(), 6 * 4);
    let o = subgram(&[
        "derive",
        f.to_str().unwrap(),
        "-D",
        "STEPS=1",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["modules"].as_array().unwrap().len(), 6 * 2);
}

#[test]
fn check_reports_diagnostics_with_exit_code_1() {
    let tmp = scratch("cli");
    let dir = tmp.path();
    let bad = dir.join("bad.lsys");
    std::fs::write(
        &bad,
        "module P(V2f);\nAxiom: P(V2f(0,0)) Q;\nP(v) : { produce P(v + 1); }\n",
    )
    .unwrap();
    let o = subgram(&["check", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("bad.lsys:2:20: error: undeclared module `Q`"),
        "{err}"
    );
    assert!(
        err.contains("bad.lsys:3:20: error: type error: cannot apply `+` to V2f and int"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    let good = lsys("curves/chaikin-13.lsys");
    let o = subgram(&["check", good.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn usage_errors_exit_with_2() {
    assert_eq!(subgram(&["derive"]).status.code(), Some(2));
    assert_eq!(subgram(&["frobnicate"]).status.code(), Some(2));
    let f = lsys("curves/chaikin-13.lsys");
    let o = subgram(&["derive", f.to_str().unwrap(), "-D", "NOEQUALS"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("must have the form NAME=VALUE"));
    let o = subgram(&["derive", f.to_str().unwrap(), "-n", "many"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn picture_options_with_a_mesh_output_are_usage_errors() {
    let tmp = scratch("cli-shading");
    let dir = tmp.path();
    let out = dir.join("out.obj");
    let g = lsys("surfaces/c4.lsys");
    for flags in [&["--shading", "normals"][..], &["--no-wireframe"][..]] {
        let mut args = vec!["subdivide", "--grammar", g.to_str().unwrap(), "-n", "1"];
        args.extend(flags);
        args.extend(["-o", out.to_str().unwrap()]);
        let o = subgram(&args);
        assert_eq!(o.status.code(), Some(2), "{flags:?}");
        assert!(stderr(&o).contains("is for pictures"), "{}", stderr(&o));
        assert!(!out.exists());
    }
    let png = dir.join("out.png");
    let o = subgram(&[
        "subdivide",
        "--grammar",
        g.to_str().unwrap(),
        "-n",
        "1",
        "--shading",
        "glossy",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("use lit, flat, normals or reflection"));
    assert!(!png.exists());
}

#[test]
fn a_missing_file_is_an_input_error() {
    let o = subgram(&["derive", "no/such/file.lsys"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cannot read `no/such/file.lsys`"));
}

#[test]
fn runaway_derivation_stops_with_a_message() {
    let tmp = scratch("cli-grow");
    let dir = tmp.path();
    let f = dir.join("grow.lsys");
    std::fs::write(
        &f,
        "module A;\nderivation length: 100;\nAxiom: A;\nA() -> A A\n",
    )
    .unwrap();
    let o = subgram(&["derive", f.to_str().unwrap(), "--max-modules", "5000"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("the word grew past 5000 modules"),
        "{}",
        stderr(&o)
    );
}

/// A command whose output is one of its inputs (by another spelling, a
/// symbolic or a hard link too) is refused with exit code 2 and a message
/// that names `--force`, and the input is left as it was; `--force`
/// replaces it.
#[test]
fn an_output_that_is_an_input_is_refused_unless_forced() {
    use crate::reverse::{files_in, run_in};
    let tmp = scratch("overwrite");
    let dir = tmp.path();
    let cube = std::fs::read(lsys("meshes/cube.obj")).unwrap();
    // Texture coordinates and normals that a conversion would drop.
    let mut a = cube.clone();
    a.extend_from_slice(b"vt 0 0\nvn 0 0 1\nusemtl skin\n");
    std::fs::write(dir.join("a.obj"), &a).unwrap();
    std::fs::hard_link(dir.join("a.obj"), dir.join("hard.obj")).unwrap();
    std::os::unix::fs::symlink("a.obj", dir.join("soft.obj")).unwrap();
    std::fs::create_dir_all(dir.join("g/surfaces")).unwrap();
    std::fs::create_dir_all(dir.join("g/meshes")).unwrap();
    std::fs::copy(lsys("surfaces/loop.lsys"), dir.join("g/surfaces/loop.lsys")).unwrap();
    std::fs::copy(
        lsys("meshes/octahedron.obj"),
        dir.join("g/meshes/octahedron.obj"),
    )
    .unwrap();
    let points: String = (0..16)
        .map(|i| format!("{} {}\n", (i as f64).cos(), (i as f64).sin()))
        .collect();
    std::fs::write(dir.join("p.txt"), &points).unwrap();
    let cc = lsys("surfaces/catmull-clark.lsys");
    let cc = cc.to_str().unwrap();
    let refusals: &[(&[&str], &str)] = &[
        (&["subdivide", "a.obj", "--grammar", cc, "-n", "1", "-o", "a.obj"], "the output `a.obj` is an input of this command"),
        (&["mesh", "convert", "a.obj", "a.obj"], "the output `a.obj` is an input of this command"),
        (&["mesh", "convert", "a.obj", "./a.obj"], "the output `./a.obj` is the same file as the input `a.obj`"),
        (&["mesh", "convert", "a.obj", "hard.obj"], "the output `hard.obj` is the same file as the input `a.obj`"),
        (&["mesh", "convert", "a.obj", "soft.obj"], "the output `soft.obj` is the same file as the input `a.obj`"),
        (&["subdivide", "--grammar", "g/surfaces/loop.lsys", "-n", "1", "-o", "g/meshes/octahedron.obj"],
         "the output `g/meshes/octahedron.obj` is the same file as the input `g/surfaces/../meshes/octahedron.obj`"),
        (&["reverse", "p.txt", "-n", "1", "-o", "q.txt", "--details", "p.txt"], "the output `p.txt` is an input of this command"),
        (&["reconstruct", "p.txt", "--details", "d.json", "-o", "p.txt"], "the output `p.txt` is an input of this command"),
        (&["render", "a.obj", "-o", "soft.obj"], "the output `soft.obj` is the same file as the input `a.obj`"),
    ];
    let before = files_in(dir);
    for (args, message) in refusals {
        let r = run_in(dir, args);
        assert_eq!(r.code, Some(2), "{args:?}: {}", r.stderr);
        let want = format!(
            "error: {message}: writing it would replace the input; name another output, or add --force to replace it\n"
        );
        assert_eq!(r.stderr, want, "{args:?}");
        assert_eq!(std::fs::read(dir.join("a.obj")).unwrap(), a, "{args:?}");
        assert_eq!(files_in(dir), before, "{args:?}");
    }
    // Two outputs that are one file are refused even with --force.
    let r = run_in(
        dir,
        &[
            "reverse",
            "p.txt",
            "-n",
            "1",
            "-o",
            "q.txt",
            "--details",
            "./q.txt",
            "--force",
        ],
    );
    assert_eq!(r.code, Some(2), "{}", r.stderr);
    assert!(
        r.stderr
            .contains("`q.txt` and `./q.txt` are the same output file"),
        "{}",
        r.stderr
    );
    // --force replaces the input.
    let r = run_in(dir, &["mesh", "convert", "a.obj", "a.obj", "--force"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let converted = std::fs::read_to_string(dir.join("a.obj")).unwrap();
    assert!(
        !converted.contains("vt "),
        "the conversion drops what it cannot hold"
    );
    let r = run_in(
        dir,
        &[
            "subdivide",
            "a.obj",
            "--grammar",
            cc,
            "-n",
            "1",
            "-o",
            "a.obj",
            "--force",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let r = run_in(
        dir,
        &["reverse", "p.txt", "-n", "1", "-o", "p.txt", "--force"],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(
        std::fs::read_to_string(dir.join("p.txt"))
            .unwrap()
            .lines()
            .count(),
        8
    );
}

/// Nothing silent (issue 12): a predefined module that subgram does not
/// act on is a warning with its first place, from `check` on standard
/// output and from `derive` and `render` on standard error, which still
/// succeed. Modules the turtle draws are not warned about.
#[test]
fn modules_subgram_does_not_draw_are_warned_about_at_their_first_place() {
    let tmp = scratch("cli-unsupported");
    let dir = tmp.path();
    let file = dir.join("leaf.lsys");
    std::fs::write(
        &file,
        "module A(int);\nderivation length: 2;\nAxiom: A(1);\n\
         A(x) : { produce F(1) SB() Left(30) Mesh(0, 1) EB() E1(0) A(x+1); }\n\
         interpretation:\nA(x) : { produce Mesh(1, 2) Label(\"a\") F(1); }\n",
    )
    .unwrap();
    let f = file.to_str().unwrap();
    let check = subgram(&["check", f]);
    assert!(check.status.success(), "{}", stderr(&check));
    let out = stdout(&check);
    let warned: Vec<&str> = out.lines().filter(|l| l.contains(": warning:")).collect();
    assert_eq!(warned.len(), 3, "{out}");
    // Mesh first appears in the production (line 4, column 37), not in
    // the interpretation rule.
    assert!(
        warned[0].starts_with(&format!(
            "{f}:4:37: warning: `Mesh` is not drawn by subgram yet"
        )),
        "{out}"
    );
    assert!(
        warned[1].starts_with(&format!(
            "{f}:4:53: warning: `E1` communicates with an environmental program"
        )),
        "{out}"
    );
    assert!(
        warned[2].starts_with(&format!("{f}:6:29: warning: `Label` is not drawn")),
        "{out}"
    );
    let derive = subgram(&["derive", f]);
    assert!(derive.status.success(), "{}", stderr(&derive));
    assert_eq!(stderr(&derive).matches(": warning:").count(), 3);
    assert!(!stdout(&derive).contains("warning"));
    let png = dir.join("leaf.png");
    let render = subgram(&["render", f, "-o", png.to_str().unwrap()]);
    assert!(render.status.success(), "{}", stderr(&render));
    assert_eq!(stderr(&render).matches(": warning:").count(), 3);
}

/// Views (manual 7.3): `UseView` activates the views that the view file's
/// `window:` commands name (numbered from 0 in their order, so `Top` is
/// view 0, the main view), and the rules after `vgroup Side:` interpret
/// the word for `Side` only. `-o out.svg` writes the main view to out.svg
/// and view `Side` to out-Side.svg; a view the view file does not define
/// is a warning and no file.
#[test]
fn every_view_is_drawn_to_its_own_file() {
    let tmp = scratch("cli-views");
    let dir = tmp.path();
    std::fs::write(
        dir.join("view.v"),
        "window: Top 0.0 0.0 1.0 0.5\nwindow: Side 0.0 0.5 0.5 0.5\n",
    )
    .unwrap();
    let file = dir.join("lsystem.l");
    std::fs::write(
        &file,
        "module A(int);\nderivation length: 2;\n\
         Start: { UseView(Top); UseView(Side); UseView(7); }\nAxiom: A(1);\n\
         A(x) : { produce F(1) SB() Left(45) A(x+1) EB() A(x+1); }\n\
         interpretation:\nvgroup Side:\nA(x) : { produce Circle(0.3); }\nendvgroup\n",
    )
    .unwrap();
    let out = dir.join("out.svg");
    let o = subgram(&[
        "render",
        file.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("`UseView(7)`: the view file defines no view 7, so it is not drawn")
    );
    let main = std::fs::read_to_string(&out).unwrap();
    let side = std::fs::read_to_string(dir.join("out-Side.svg")).unwrap();
    // Two steps of A -> F [+A] A: three segments F; the four A modules
    // are circles in Side only.
    assert_eq!(svg_counts(&main), (3, 0, 0));
    assert_eq!(svg_counts(&side), (3, 4, 0));
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["lsystem.l", "out-Side.svg", "out.svg", "view.v"]);
    // All or none: when one view's file cannot be written (a folder has
    // its name), no file is written.
    let again = dir.join("again.svg");
    std::fs::create_dir(dir.join("again-Side.svg")).unwrap();
    let o = subgram(&[
        "render",
        file.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(!again.exists());
}

/// A tropism of the view file that cannot be read (a null direction, or a
/// vector written with commas, which lpfg's reading refuses too) is left
/// out with a warning at its line, with the line and a caret; the program
/// runs, as lpfg runs it.
#[test]
fn a_bad_tropism_in_the_view_file_is_a_warning_at_its_line() {
    let tmp = scratch("cli-bad-view");
    let dir = tmp.path();
    let view = dir.join("view.v");
    std::fs::write(
        &view,
        "corrected rotation: on
tropism: T: 0 0 0 E: 1
tropism: T: 0,1,0 E: 0.2
",
    )
    .unwrap();
    let file = dir.join("lsystem.l");
    std::fs::write(
        &file,
        "#include <lpfgall.h>
derivation length: 1;
Axiom: F(1);
",
    )
    .unwrap();
    let o = subgram(&["check", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = stdout(&o);
    let v = view.display();
    assert!(
        out.starts_with(&format!(
            "{v}:2:1: warning: this tropism cannot be read and is left out (lpfg refuses it too): expected `T: x y z`"
        )),
        "{out}"
    );
    assert!(
        out.contains("2 | tropism: T: 0 0 0 E: 1\n  | ^^^^^^^^^^^^^^^^^^^^^^"),
        "{out}"
    );
    assert!(
        out.contains(&format!("{v}:3:1: warning: this tropism cannot be read")),
        "{out}"
    );
    let o = subgram(&["derive", file.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(stdout(&o).trim(), "F(1)");
}

/// Writing a creased mesh keeps its sharp edges in PLY (an `edge` element
/// that reading gives back) and says what a file cannot keep (before, both
/// were dropped without a word). Expected values: the source files'
/// own sharpness (creased-cube.ply: six edges, four for ever; the
/// octahedron: five edges and one sharp vertex in its .creases), and after
/// two Catmull-Clark steps the four infinite rim edges split twice, 4 * 2 *
/// 2 = 16 edges, while the finite ones (2 and 0.5) have dropped to 0.
#[test]
fn writing_a_creased_mesh_keeps_or_reports_its_sharpness() {
    use crate::reverse::run_in;
    use subgram::mesh::io::read_mesh;
    let tmp = scratch("write-creases");
    let dir = tmp.path();
    let cube = lsys("meshes/creased-cube.ply");
    let octa = lsys("meshes/creased-octahedron.obj");
    let (cube, octa) = (cube.to_str().unwrap(), octa.to_str().unwrap());
    // The sharpness of every edge, by the positions of its ends.
    let sharp_edges = |m: &subgram::mesh::Mesh| {
        let mut v: Vec<String> = m
            .edges()
            .filter(|&e| m.edge_sharpness(e) > 0.0)
            .map(|e| {
                let (a, b) = m.edge_vertices(e);
                let (mut p, mut q) = (m.position(a).to_array(), m.position(b).to_array());
                if q < p {
                    std::mem::swap(&mut p, &mut q);
                }
                format!("{p:?} {q:?} {}", m.edge_sharpness(e))
            })
            .collect();
        v.sort();
        v
    };
    let source = read_mesh(std::path::Path::new(cube)).unwrap();
    assert_eq!(sharp_edges(&source).len(), 6);
    for triangles in [false, true] {
        let mut args = vec!["mesh", "convert", cube, "c.ply"];
        if triangles {
            args.push("--triangles");
        }
        let r = run_in(dir, &args);
        assert_eq!(r.code, Some(0), "{}", r.stderr);
        assert_eq!(r.stderr, "", "a PLY keeps every sharp edge");
        let back = read_mesh(&dir.join("c.ply")).unwrap();
        assert_eq!(
            sharp_edges(&back),
            sharp_edges(&source),
            "--triangles {triangles}"
        );
    }
    let r = run_in(dir, &["mesh", "convert", cube, "c.obj"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stderr
            .starts_with("c.obj: warning: the file does not keep 6 sharp edges"),
        "{}",
        r.stderr
    );
    let r = run_in(dir, &["mesh", "convert", octa, "o.ply"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stderr
            .starts_with("o.ply: warning: the file does not keep 1 sharp vertex"),
        "{}",
        r.stderr
    );
    assert_eq!(
        sharp_edges(&read_mesh(&dir.join("o.ply")).unwrap()).len(),
        5
    );
    let cc = lsys("surfaces/catmull-clark.lsys");
    let args = [
        "subdivide",
        cube,
        "--grammar",
        cc.to_str().unwrap(),
        "-n",
        "2",
        "-o",
        "s.ply",
    ];
    let r = run_in(dir, &args);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let s = sharp_edges(&read_mesh(&dir.join("s.ply")).unwrap());
    assert_eq!(s.len(), 16);
    assert!(s.iter().all(|e| e.ends_with(" inf")), "{s:?}");
    // A file of creases left beside the output is named: it will be read
    // with the new mesh.
    std::fs::write(dir.join("s.creases"), "e 1 2 inf\n").unwrap();
    let r = run_in(dir, &args);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(
        r.stderr.contains("s.ply: warning: `s.creases` beside it"),
        "{}",
        r.stderr
    );
}

/// `--each` without `--size` sizes the canvas to the panels: four square
/// drawings side by side in 800 pixels are cells of 200, each drawing
/// fitted to 200 − 2 × 8 (the 4% margin of the cell's smaller side), so
/// the picture is 184 + 2 × 8 = 200 pixels tall, not 800 with three
/// quarters empty. `--size` is kept as given.
#[test]
fn render_each_sizes_the_canvas_to_its_panels() {
    let tmp = scratch("each");
    let dir = tmp.path();
    let f = lsys("figures/fig01-chaikin-square.lsys");
    let size = |extra: &[&str], name: &str| {
        let out = dir.join(name);
        let mut args = vec!["render", f.to_str().unwrap(), "--each", "-o"];
        args.push(out.to_str().unwrap());
        args.extend_from_slice(extra);
        let o = subgram(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let pm = tiny_skia::Pixmap::decode_png(&std::fs::read(&out).unwrap()).unwrap();
        (pm.width(), pm.height())
    };
    assert_eq!(size(&[], "strip.png"), (800, 200));
    assert_eq!(size(&["--size", "800x800"], "square.png"), (800, 800));
    assert_eq!(size(&["--size", "400x300"], "given.png"), (400, 300));
    // One tall drawing keeps the default square.
    let tall = lsys("abop/bush.lsys");
    let out = dir.join("one.png");
    let o = subgram(&[
        "render",
        tall.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let pm = tiny_skia::Pixmap::decode_png(&std::fs::read(&out).unwrap()).unwrap();
    assert_eq!((pm.width(), pm.height()), (800, 800));
}

/// `analyze --picture OUT.svg` draws one panel per valence of a surface
/// grammar; a curve scheme, or an output that is the input, is a usage
/// error (exit code 2) that writes nothing.
/// `--valences` takes valences from 3 to 12; anything else is a usage
/// error that says what it expects.
#[test]
fn analyze_valences_are_checked() {
    let f = lsys("surfaces/loop.lsys");
    for (bad, want) in [
        ("2,4", "valence 2 is outside 3 to 12"),
        (
            "3,x",
            "expected valences from 3 to 12 separated by commas (3,4,12), not `x`",
        ),
    ] {
        let o = subgram(&["analyze", f.to_str().unwrap(), "--valences", bad]);
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{bad}: {}", stderr(&o));
    }
    let o = subgram(&[
        "analyze",
        f.to_str().unwrap(),
        "--valences",
        "4",
        "--format",
        "json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["valences"].as_array().unwrap().len(), 1);
    assert_eq!(json["valences"][0]["n"], 4);
}

#[test]
fn analyze_draws_the_characteristic_maps() {
    let tmp = scratch("cli-picture");
    let dir = tmp.path();
    let out = dir.join("loop.svg");
    let f = lsys("surfaces/loop.lsys");
    // Every valence (3..12, the default) in an optimised build; two with
    // `--valences` in a debug one, where each takes seconds.
    let ns = crate::support::valences(&(3..=12).collect::<Vec<_>>(), &[3, 5]);
    let list: Vec<String> = ns.iter().map(|n| n.to_string()).collect();
    let list = list.join(",");
    let mut args = vec![
        "analyze",
        f.to_str().unwrap(),
        "--picture",
        out.to_str().unwrap(),
    ];
    if ns.len() < 10 {
        args.extend(["--valences", &list]);
    }
    let o = subgram(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg"));
    assert_eq!(svg.matches("n = ").count(), ns.len(), "a panel per valence");
    for n in &ns {
        assert!(svg.contains(&format!("n = {n}")), "no panel for {n}");
    }
    assert!(svg.matches("<line").count() > 10);
    let curve = dir.join("curve.svg");
    let c = lsys("curves/cubic-22.lsys");
    let o = subgram(&[
        "analyze",
        c.to_str().unwrap(),
        "--picture",
        curve.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("surface grammars") && !curve.exists());
    let before = std::fs::read(&f).unwrap();
    let o = subgram(&[
        "analyze",
        f.to_str().unwrap(),
        "--picture",
        f.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // analyze has no --force to suggest.
    assert!(
        stderr(&o).contains("is the input") && !stderr(&o).contains("--force"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&f).unwrap(), before);
}
