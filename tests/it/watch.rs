//! `subgram watch` (issue 18): a change to the file, or to a file it reads
//! (here a surface grammar's base mesh), renders again; an edit with an
//! error keeps the last good picture.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use subgram::command::{self, RenderArgs, WatchEvent, WatchOptions};

use crate::support::scratch;

/// A triangular bipyramid: apexes of valence 3, an equator of valence 4.
/// Moving each vertex towards its neighbours' centre changes the ratio of
/// its height to its width with the weight (a tetrahedron would only
/// shrink, and its fitted picture would not change).
const BIPYRAMID: &str = "v 0 0 2\nv 0 0 -2\nv 1 0 0\nv -0.5 0.866 0\nv -0.5 -0.866 0\n\
    f 1 3 4\nf 1 4 5\nf 1 5 3\nf 2 4 3\nf 2 5 4\nf 2 3 5\n";

/// The same bipyramid twice as tall: another picture.
const TALLER: &str = "v 0 0 4\nv 0 0 -4\nv 1 0 0\nv -0.5 0.866 0\nv -0.5 -0.866 0\n\
    f 1 3 4\nf 1 4 5\nf 1 5 3\nf 2 4 3\nf 2 5 4\nf 2 3 5\n";

/// A surface grammar that moves every vertex to the centre of its
/// neighbours once: its picture depends on the grammar and on the mesh.
fn grammar(weight: &str) -> String {
    format!(
        "mesh: \"base.obj\";\nderivation length: 1;\nV(v) -> V(v = {weight} * v + (1 - {weight}) * avg(ring(v)));\n"
    )
}

/// What the watcher reported, for the test thread.
#[derive(Debug, PartialEq)]
enum Seen {
    Rendered,
    Failed(String),
    Watching(Vec<PathBuf>),
}

fn write(path: &Path, text: &str) {
    // A new file each time (written aside, renamed in), as editors save.
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

#[test]
fn watch_renders_again_on_a_change_to_the_file_or_its_mesh_and_keeps_the_last_picture_on_error() {
    let tmp = scratch("watch");
    let dir = tmp.path();
    let g = dir.join("smooth.lsys");
    let out = dir.join("smooth.png");
    std::fs::write(dir.join("base.obj"), BIPYRAMID).unwrap();
    std::fs::write(&g, grammar("0.5")).unwrap();
    // The grammar must run as a plain render first.
    let mut args = RenderArgs::new(g.to_str().unwrap(), out.to_str().unwrap());
    args.size = Some((120, 120));
    command::render(&args, |_| {}).unwrap();
    let first = std::fs::read(&out).unwrap();
    std::fs::remove_file(&out).unwrap();

    let (tx, rx) = mpsc::channel();
    let watcher = std::thread::spawn(move || {
        let opts = WatchOptions {
            poll: Duration::from_millis(20),
            max_renders: Some(4),
        };
        command::watch(&args, &opts, |e| {
            let seen = match e {
                WatchEvent::Rendered { .. } => Seen::Rendered,
                WatchEvent::Failed { error } => Seen::Failed(error.to_string()),
                WatchEvent::Watching { files } => Seen::Watching(files.to_vec()),
            };
            tx.send(seen).unwrap();
        })
    });
    let next = || {
        rx.recv_timeout(Duration::from_secs(20))
            .expect("the watcher reports")
    };

    // 1. The first render, then the watch of the grammar and its mesh.
    assert_eq!(next(), Seen::Rendered);
    assert_eq!(std::fs::read(&out).unwrap(), first);
    match next() {
        Seen::Watching(files) => {
            let names: Vec<_> = files
                .iter()
                .map(|f| f.file_name().unwrap().to_owned())
                .collect();
            assert_eq!(names, ["smooth.lsys", "base.obj"], "{files:?}");
        }
        other => panic!("{other:?}"),
    }
    // 2. An edit with an error: the message, with its place, and the last
    // picture left as it was.
    write(&g, &grammar("0.5 +"));
    match next() {
        Seen::Failed(m) => assert!(m.contains("smooth.lsys:3:"), "{m}"),
        other => panic!("{other:?}"),
    }
    assert_eq!(
        std::fs::read(&out).unwrap(),
        first,
        "the last good picture is kept"
    );
    assert!(matches!(next(), Seen::Watching(_)));
    // 3. Mended, with another weight: a new picture.
    write(&g, &grammar("0.9"));
    assert_eq!(next(), Seen::Rendered);
    let mended = std::fs::read(&out).unwrap();
    assert_ne!(mended, first);
    assert!(matches!(next(), Seen::Watching(_)));
    // 4. The base mesh changes, the grammar does not: a new picture again.
    write(&dir.join("base.obj"), TALLER);
    assert_eq!(next(), Seen::Rendered);
    assert_ne!(std::fs::read(&out).unwrap(), mended);
    watcher.join().unwrap().unwrap();
}

/// A usage error cannot be mended by editing the files: it ends the watch
/// with exit code 2, through the binary.
#[test]
fn watch_stops_at_a_usage_error_and_runs_once_through_the_binary() {
    let tmp = scratch("watch-cli");
    let dir = tmp.path();
    let f = dir.join("c.lsys");
    std::fs::copy(crate::support::lsys("curves/chaikin-13.lsys"), &f).unwrap();
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
            .args(["watch", f.to_str().unwrap(), "-o"])
            .arg(dir.join("c.png"))
            .args(extra)
            .output()
            .unwrap()
    };
    let o = run(&["--view", "sideways"]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(!dir.join("c.png").exists());
    let o = run(&["--max-renders", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("wrote "));
    assert!(dir.join("c.png").exists());
}

/// What `watch` watches of a model folder: the L-system and every file of
/// the model that the run reads (functions, timelines, parameters,
/// contours), as `specifications` lists them.
#[test]
fn a_model_folder_s_inputs_are_its_lsystem_and_its_files() {
    let dir = crate::support::root().join("tests/data/models/accessors");
    let system = subgram::load(&dir, &Default::default()).unwrap();
    let mut names: Vec<String> = system
        .inputs()
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut want = vec![
        "blade.con",
        "contours.cset",
        "functions.fset",
        "lone.func",
        "lsystem.l",
        "params.vset",
        "timelines.tset",
    ];
    want.sort();
    assert_eq!(names, want);
}
