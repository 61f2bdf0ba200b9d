//! Issue 44: nothing hangs, nothing is overwritten. Every input that is
//! not a regular file (a named pipe with no writer) ends a command at its
//! `--timeout`; the tracer, the C4 pairing and a mesh's picture stop at
//! the limit and write nothing; every output is checked against every
//! file the run read; outputs are put in place all or none; the program
//! files of `--allow-writes` never leave the folder, and a failed run
//! leaves no folder behind.

use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::support::{root, scratch};

fn bin(dir: &Path, args: &[&str]) -> (Output, Duration) {
    let t = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(args)
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    (o, t.elapsed())
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The names in `dir`, sorted (hidden temporaries included).
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn mkfifo(path: &Path) {
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
}

const KOCH: &str = "angle: 60;\nderivation length: 2;\nAxiom: F--F--F;\nF -> F+F--F+F\n";

/// A named pipe nobody writes to, as each kind of input of each command:
/// the command ends within a second or two of its `--timeout`, exit 1,
/// says that nothing came from the pipe, and writes nothing.
#[test]
fn a_pipe_without_a_writer_ends_at_the_timeout() {
    let tmp = scratch("nohang-fifo");
    let dir = tmp.path();
    for name in ["p.lsys", "p.obj", "p.csv", "p.txt"] {
        mkfifo(&dir.join(name));
    }
    // A surface grammar and a vv program whose base mesh is the pipe.
    let surface = std::fs::read_to_string(root().join("lsystems/surfaces/loop.lsys")).unwrap();
    let surface = surface.replace("\"../meshes/octahedron.obj\"", "\"p.obj\"");
    assert!(surface.contains("mesh: \"p.obj\""));
    std::fs::write(dir.join("surface.lsys"), surface).unwrap();
    let vv = std::fs::read_to_string(root().join("lsystems/vv/butterfly.lsys")).unwrap();
    let vv = vv.replace("\"../meshes/octahedron.obj\"", "\"p.obj\"");
    assert!(vv.contains("mesh S = \"p.obj\""));
    std::fs::write(dir.join("vv.lsys"), vv).unwrap();
    let cases: &[&[&str]] = &[
        &["derive", "p.lsys"],
        &["check", "p.lsys"],
        &["render", "p.lsys", "-o", "out.png"],
        &["mesh", "info", "p.obj"],
        &["mesh", "convert", "p.obj", "out.obj"],
        &["derive", "surface.lsys"],
        &["subdivide", "--grammar", "surface.lsys", "-o", "out.obj"],
        &[
            "subdivide",
            "p.obj",
            "--grammar",
            "surface.lsys",
            "-o",
            "out.obj",
        ],
        &["derive", "vv.lsys"],
        &["reverse", "p.csv", "-n", "1", "-o", "out.csv"],
        &["infer", "--rows-file", "p.txt"],
    ];
    let before = names(dir);
    for args in cases {
        let mut args = args.to_vec();
        args.extend(["--timeout", "1"]);
        let (o, took) = bin(dir, &args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(took < Duration::from_secs(4), "{args:?} took {took:?}");
        assert!(
            err.contains("nothing came from this pipe before the run's time limit of 1 s"),
            "{args:?}: {err}"
        );
        assert_eq!(names(dir), before, "{args:?} left files");
    }
}

/// A pipe that a writer fills is read whole: `derive` of a program given
/// through a named pipe gives the program's word.
#[test]
fn a_pipe_with_a_writer_is_read() {
    let tmp = scratch("nohang-fifo-writer");
    let dir = tmp.path();
    let fifo = dir.join("k.lsys");
    mkfifo(&fifo);
    let writer = std::thread::spawn(move || {
        // Opening for writing waits for the reader, as a shell's `>` does.
        std::fs::write(&fifo, KOCH).unwrap();
    });
    let (o, _) = bin(dir, &["derive", "k.lsys", "--timeout", "20"]);
    writer.join().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let word = String::from_utf8_lossy(&o.stdout);
    assert_eq!(word.matches('F').count(), 48, "{word}");
}

/// A fan of `n` triangles around one vertex, as OBJ text.
fn fan_obj(n: usize) -> String {
    let mut obj = String::from("v 0 0 0\n");
    for k in 0..n {
        let a = k as f64 / n as f64 * std::f64::consts::TAU;
        obj.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    for k in 0..n {
        obj.push_str(&format!("f 1 {} {}\n", k + 2, (k + 1) % n + 2));
    }
    obj
}

/// A `side`² PNG of black and white 2-pixel squares in a white frame of 4
/// pixels: a segment in every cell for the tracer.
fn checkerboard(path: &Path, side: u32) {
    let mut pm = tiny_skia::Pixmap::new(side, side).unwrap();
    pm.fill(tiny_skia::Color::WHITE);
    let black = tiny_skia::PremultipliedColorU8::from_rgba(0, 0, 0, 255).unwrap();
    let px = pm.pixels_mut();
    for y in 4..side - 4 {
        for x in 4..side - 4 {
            if (x / 2 + y / 2) % 2 == 0 {
                px[(y * side + x) as usize] = black;
            }
        }
    }
    pm.save_png(path).unwrap();
}

/// A PNG of 2-pixel squares makes the tracer follow a loop in every
/// other cell: `--timeout 1` ends it within a second, and writes nothing.
#[test]
fn tracing_stops_at_the_timeout() {
    let tmp = scratch("nohang-trace");
    let dir = tmp.path();
    checkerboard(&dir.join("board.png"), 2048);
    let (o, took) = bin(
        dir,
        &[
            "reverse",
            "board.png",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--timeout",
            "1",
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(took < Duration::from_secs(3), "{took:?}");
    assert!(
        err.contains("board.png: error: the run went past its time limit of 1 s"),
        "{err}"
    );
    assert_eq!(names(dir), ["board.png"]);
}

/// C4's `init: match_blocks` on a fan of 20,000 triangles around one
/// vertex (an odd fan: one triangle is always left to move, and the
/// searches walk the whole fan): `--timeout 1` stops the pairing.
#[test]
fn pairing_stops_at_the_timeout() {
    let tmp = scratch("nohang-pairing");
    let dir = tmp.path();
    std::fs::write(dir.join("fan.obj"), fan_obj(20_001)).unwrap();
    std::fs::copy(
        root().join("lsystems/surfaces/c4.lsys"),
        dir.join("c4.lsys"),
    )
    .unwrap();
    let before = names(dir);
    let (o, took) = bin(
        dir,
        &[
            "subdivide",
            "fan.obj",
            "--grammar",
            "c4.lsys",
            "-o",
            "out.obj",
            "--timeout",
            "1",
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(took < Duration::from_secs(4), "{took:?}: {err}");
    assert!(err.contains("time limit of 1 s"), "{err}");
    assert_eq!(names(dir), before);
}

/// A mesh's picture: past the limit, no picture (it was written with exit
/// 0 after the limit).
#[test]
fn a_mesh_picture_stops_at_the_timeout() {
    let tmp = scratch("nohang-mesh");
    let dir = tmp.path();
    let n = 300;
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            obj.push_str(&format!("v {i} {j} {}\n", (i * 7 + j * 3) % 11));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            obj.push_str(&format!("f {a} {} {} {}\n", a + 1, a + n + 2, a + n + 1));
        }
    }
    std::fs::write(dir.join("grid.obj"), obj).unwrap();
    let (o, took) = bin(
        dir,
        &["render", "grid.obj", "-o", "out.png", "--timeout", "0.05"],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(took < Duration::from_secs(3), "{took:?}");
    assert!(err.contains("time limit of 0.05 s"), "{err}");
    assert_eq!(names(dir), ["grid.obj"]);
}

/// An output that is an input under another name is refused, and the
/// input stays: the MTL beside an OBJ, and `infer`'s matrix file.
#[test]
fn no_output_replaces_an_input() {
    let tmp = scratch("nohang-inputs");
    let dir = tmp.path();
    std::fs::write(dir.join("x.mtl"), KOCH).unwrap();
    let (o, _) = bin(dir, &["render", "x.mtl", "-o", "x.obj", "--solid"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("the output `x.mtl` is a file this run read: writing it would replace an input; name another output, or add --force"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(dir.join("x.mtl")).unwrap(), KOCH);
    assert_eq!(names(dir), ["x.mtl"]);
    // The same through a link.
    std::os::unix::fs::symlink("x.mtl", dir.join("y.mtl")).unwrap();
    let (o, _) = bin(dir, &["render", "x.mtl", "-o", "y.obj", "--solid"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(dir.join("x.mtl")).unwrap(), KOCH);
    // infer has no --force, and does not offer it.
    let rows = "1/4 3/4 0\n0 3/4 1/4\n";
    std::fs::write(dir.join("m.txt"), rows).unwrap();
    let (o, _) = bin(dir, &["infer", "--rows-file", "m.txt", "-o", "m.txt"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("the output `m.txt` is a file this run read") && !err.contains("--force"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(dir.join("m.txt")).unwrap(), rows);
}

/// When the MTL cannot be written (a folder holds its name), the OBJ that
/// was there before stays as it was: all outputs or none.
#[test]
fn outputs_are_all_or_none() {
    let tmp = scratch("nohang-all-or-none");
    let dir = tmp.path();
    std::fs::write(dir.join("k.lsys"), KOCH).unwrap();
    std::fs::write(dir.join("x.obj"), "old").unwrap();
    std::fs::create_dir(dir.join("x.mtl")).unwrap();
    std::fs::write(dir.join("x.mtl/keep"), "k").unwrap();
    let (o, _) = bin(dir, &["render", "k.lsys", "-o", "x.obj", "--solid"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(dir.join("x.obj")).unwrap(), "old");
    assert_eq!(names(dir), ["k.lsys", "x.mtl", "x.obj"]);
    // Without the folder in the way both are written.
    std::fs::remove_dir_all(dir.join("x.mtl")).unwrap();
    let (o, _) = bin(dir, &["render", "k.lsys", "-o", "x.obj", "--solid"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(names(dir), ["k.lsys", "x.mtl", "x.obj"]);
    assert!(std::fs::read_to_string(dir.join("x.obj"))
        .unwrap()
        .contains("mtllib"));
}

/// A model with two views: when the second view's file cannot be written
/// (a folder holds its name), the main picture that was there before
/// stays as it was (before, it was replaced and the command failed).
#[test]
fn views_are_all_or_none() {
    let tmp = scratch("nohang-views");
    let dir = tmp.path();
    std::fs::write(
        dir.join("view.v"),
        "window: Top 0.0 0.0 1.0 0.5\nwindow: Side 0.0 0.5 0.5 0.5\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("lsystem.l"),
        "module A(int);\nderivation length: 2;\n\
         Start: { UseView(Top); UseView(Side); }\nAxiom: A(1);\n\
         A(x) : { produce F(1) SB() Left(45) A(x+1) EB() A(x+1); }\n",
    )
    .unwrap();
    std::fs::write(dir.join("out.svg"), "old").unwrap();
    std::fs::create_dir(dir.join("out-Side.svg")).unwrap();
    std::fs::write(dir.join("out-Side.svg/keep"), "k").unwrap();
    let (o, _) = bin(dir, &["render", "lsystem.l", "-o", "out.svg"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(dir.join("out.svg")).unwrap(), "old");
    assert_eq!(
        names(dir),
        ["lsystem.l", "out-Side.svg", "out.svg", "view.v"]
    );
}

/// `--allow-writes`: a path through a link that leads out of the folder
/// is refused before any folder is made, there or elsewhere; and a run
/// that fails leaves no folder it made for an earlier file.
#[test]
fn program_files_stay_inside_and_leave_nothing_on_failure() {
    let tmp = scratch("nohang-writes");
    let dir = tmp.path();
    std::fs::create_dir(dir.join("wd")).unwrap();
    std::fs::create_dir(dir.join("elsewhere")).unwrap();
    std::os::unix::fs::symlink("../elsewhere", dir.join("wd/link")).unwrap();
    let program = |second: &str| {
        format!(
            "#include <lpfgall.h>\nderivation length: 1;\nStart: {{\n\
             FILE *f = fopen(\"ok/a.txt\", \"w\"); fprintf(f, \"a\\n\"); fclose(f);\n\
             FILE *g = fopen(\"{second}\", \"w\"); fprintf(g, \"b\\n\"); fclose(g);\n}}\n\
             Axiom: F;\n"
        )
    };
    std::fs::write(dir.join("out.lsys"), program("link/newdir/deeper/x.txt")).unwrap();
    let (o, _) = bin(dir, &["derive", "out.lsys", "--allow-writes", "wd"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the program's file `link/newdir/deeper/x.txt` would be written outside wd"),
        "{err}"
    );
    assert_eq!(names(&dir.join("wd")), ["link"]);
    assert!(names(&dir.join("elsewhere")).is_empty());
    // The second file's folder is a file: the first file's folder goes.
    std::fs::write(dir.join("wd/plain"), "p").unwrap();
    std::fs::write(dir.join("bad.lsys"), program("plain/x.txt")).unwrap();
    let (o, _) = bin(dir, &["derive", "bad.lsys", "--allow-writes", "wd"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(names(&dir.join("wd")), ["link", "plain"]);
    // A good run writes both.
    std::fs::write(dir.join("good.lsys"), program("b/c/x.txt")).unwrap();
    let (o, _) = bin(dir, &["derive", "good.lsys", "--allow-writes", "wd"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(dir.join("wd/ok/a.txt")).unwrap(),
        "a\n"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("wd/b/c/x.txt")).unwrap(),
        "b\n"
    );
}

/// Found in review: `serve` read its program with a plain read (a FIFO
/// held it forever at start), `analyze` kept its own 120 s limit whatever
/// `--timeout` said, and two outputs of one run under one name (`-o` and a
/// program file of `--allow-writes`) lost one silently.
#[test]
fn serve_analyze_and_two_outputs_of_one_name() {
    let tmp = scratch("nohang-review");
    let dir = tmp.path();
    mkfifo(&dir.join("p.lsys"));
    let (o, took) = bin(dir, &["serve", "p.lsys", "--port", "0", "--timeout", "1"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(took < Duration::from_secs(4), "{took:?}");
    assert!(err.contains("nothing came from this pipe"), "{err}");
    let grammar = root().join("lsystems/surfaces/loop.lsys");
    let (o, _) = bin(
        dir,
        &["analyze", grammar.to_str().unwrap(), "--timeout", "0.01"],
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("time limit of 0.01 s"),
        "{}",
        stderr(&o)
    );
    // The program writes `w/word.txt`; `-o w/word.txt` names it too.
    std::fs::create_dir(dir.join("w")).unwrap();
    std::fs::write(
        dir.join("two.lsys"),
        "#include <lpfgall.h>\nderivation length: 1;\nStart: {\n\
         FILE *f = fopen(\"word.txt\", \"w\"); fprintf(f, \"mine\\n\"); fclose(f);\n}\n\
         Axiom: F;\n",
    )
    .unwrap();
    let (o, _) = bin(
        dir,
        &[
            "derive",
            "two.lsys",
            "--allow-writes",
            "w",
            "-o",
            "w/word.txt",
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("are the same output file"), "{err}");
    assert!(
        names(&dir.join("w")).is_empty(),
        "{:?}",
        names(&dir.join("w"))
    );
}

/// Issue 42, item 4: every path whose cost grows with the input looks at
/// the deadline. A limit of a millisecond on inputs that take far longer
/// (the pairing of a 20,000-triangle fan, adaptive 4-8 refinement of a
/// 20,000-triangle grid, with `adaptive;` and `adaptive: incremental;`,
/// and the trace of a 1024² checkerboard): each command fails with the
/// limit's message and writes nothing. Untimed: what is asserted is that
/// the limit is looked at, not how soon (benches/growth.py measures that).
#[test]
fn growing_paths_stop_at_a_tiny_timeout() {
    let tmp = scratch("nohang-growth");
    let dir = tmp.path();
    std::fs::write(dir.join("fan.obj"), fan_obj(20_000)).unwrap();
    // A 100 × 100 grid of quads in [-1, 1]^2 (its quads are the blocks).
    let k = 100;
    let mut grid = String::new();
    for j in 0..=k {
        for i in 0..=k {
            let (x, y) = (
                -1.0 + 2.0 * i as f64 / k as f64,
                -1.0 + 2.0 * j as f64 / k as f64,
            );
            grid.push_str(&format!("v {x} {y} 0\n"));
        }
    }
    for j in 0..k {
        for i in 0..k {
            let a = j * (k + 1) + i + 1;
            grid.push_str(&format!("f {a} {} {} {}\n", a + 1, a + k + 2, a + k + 1));
        }
    }
    std::fs::write(dir.join("grid.obj"), grid).unwrap();
    let adaptive =
        std::fs::read_to_string(root().join("lsystems/surfaces/four-eight-adaptive.lsys")).unwrap();
    std::fs::write(dir.join("adaptive.lsys"), &adaptive).unwrap();
    std::fs::write(
        dir.join("incremental.lsys"),
        adaptive.replace("\nadaptive;\n", "\nadaptive: incremental;\n"),
    )
    .unwrap();
    std::fs::copy(
        root().join("lsystems/surfaces/c4.lsys"),
        dir.join("c4.lsys"),
    )
    .unwrap();
    checkerboard(&dir.join("board.png"), 1024);
    let before = names(dir);
    let sub = |mesh: &'static str, grammar: &'static str, steps: &'static str| {
        vec![
            "subdivide",
            mesh,
            "--grammar",
            grammar,
            "-n",
            steps,
            "-o",
            "out.obj",
        ]
    };
    let runs: Vec<Vec<&str>> = vec![
        sub("fan.obj", "c4.lsys", "0"),
        sub("grid.obj", "adaptive.lsys", "4"),
        sub("grid.obj", "incremental.lsys", "4"),
        vec!["reverse", "board.png", "-n", "1", "-o", "out.csv"],
    ];
    for mut args in runs {
        args.extend(["--timeout", "0.001", "-D", "PX=0", "-D", "R=0.5"]);
        if args[0] == "reverse" {
            args.truncate(args.len() - 4);
        }
        let (o, _) = bin(dir, &args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("time limit of 0.001 s"), "{args:?}: {err}");
        assert_eq!(names(dir), before, "{args:?}");
    }
}
