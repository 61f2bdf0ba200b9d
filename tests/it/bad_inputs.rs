//! The bad-input corpus: every case runs through the built binary in a
//! fresh temporary directory, and each of these must hold:
//!
//! * the exit code is 1 (a problem with the input) or 2 (a usage error),
//!   and equals the one stored beside the case (`NAME.code`);
//! * stderr, with the temporary directory written `$TMP`, equals
//!   `NAME.expected`;
//! * where the input has lines, the message starts `file:line:col: error:`
//!   and shows the line with a caret under the place, in one of the case's
//!   inputs (a case whose input has no line to point at says so: `no-line:
//!   WHY` in its `.run` file; usage errors, exit code 2, have no place);
//! * no output and no temporary file is left in the directory, and no
//!   input is changed or removed (the listing and the contents before and
//!   after the run are compared);
//! * the run ends within [`LIMIT`]; a run that does not is killed, so a hang
//!   fails this test instead of hanging `cargo test`;
//! * nothing panics or aborts, and nothing runs out of memory: a run may
//!   use at most [`MEMORY`] of data, and an input that would need more must
//!   be refused by a limit of the program before (a run whose stderr says
//!   "out of memory" fails, even with exit code 1).
//!
//! Where the cases live (each folder's README lists its cases and where
//! their expectations came from):
//!
//! * `tests/data/err/NAME.lsys`: curve L-systems and surface grammars; the
//!   first line says how to run the file (`// run: subgram COMMAND ...`, the
//!   file name goes last).
//! * `tests/data/bad/KIND/NAME.EXT` with `NAME.run`: meshes, contours and
//!   details files, which cannot carry a comment line. `NAME.run` holds
//!   `run: COMMAND ...` with `$IN` for the case's file.
//! * [`generated`]: inputs too large to keep as files (megabytes, a sparse
//!   16 GiB file, `/dev/zero`), made by code in this file; their
//!   expectations are in `tests/data/bad/generated/`.
//!
//! A `.run` file (also allowed beside an `.lsys` case, without `run:`) may
//! further hold `with: PATH` (a file copied into the directory too,
//! relative to the case's folder), `no-line: WHY`, `timeout: SECONDS`
//! (`--timeout SECONDS` is added to the command line when the binary's help
//! for that command lists `--timeout`, and only then) and `exit: CODE`, an
//! exit code decided by a person where the binary's is wrong today (it
//! replaces `NAME.code`, and `UPDATE_GOLDEN` leaves it alone).
//!
//! Cases that misbehave today are listed in `tests/data/bad/KNOWN_FAILURES`
//! with the way they misbehave (the names in [`PROBLEMS`]). Such a case still runs
//! (killed after [`SHORT`] when it is recorded as a hang), and the test
//! asserts that it misbehaves exactly as recorded: when it is fixed, or
//! misbehaves differently, the test fails and says so, so that the list is
//! kept true. `UPDATE_GOLDEN=1 cargo test --test it bad_inputs` rewrites
//! every `.expected` and `.code` that differs, for every run that ended with
//! a non-zero exit code and no crash, gives recorded hangs their full time,
//! and removes from KNOWN_FAILURES the cases that now behave; a case that
//! misbehaves differently from its line still fails, for a person to judge.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use crate::golden::{self, Kind};
use crate::support::root;

/// How long a case may run.
const LIMIT: Duration = Duration::from_secs(20);
/// How long a case recorded as a hang runs before it is killed.
const SHORT: Duration = Duration::from_secs(3);
/// The data segment (heap and private mappings) a case may use.
const MEMORY: u64 = 1 << 30;

/// The folder of the non-`.lsys` cases, the known failures and the
/// generated cases' expectations.
const BAD: &str = "tests/data/bad";

// ---------------------------------------------------------------------------
// Cases

/// Where a file of a case's directory comes from.
#[derive(Clone, Debug)]
enum Source {
    /// A file of the repository.
    Copy(PathBuf),
    /// Bytes made in code.
    Bytes(Vec<u8>),
    /// A symbolic link to this path (`/dev/zero`).
    Symlink(PathBuf),
    /// A sparse file of this many zero bytes.
    Sparse(u64),
}

/// One bad input and how to run it.
#[derive(Clone, Debug)]
struct Case {
    /// `err/NAME`, `bad/KIND/NAME` or `generated/NAME`.
    id: String,
    /// The folder of `NAME.expected` and `NAME.code`, relative to the root.
    folder: String,
    stem: String,
    /// The files of the directory, by name; the first is the case's input.
    files: Vec<(String, Source)>,
    /// The arguments after `subgram`.
    args: Vec<String>,
    /// Why the input has no line to point at, if it has none.
    no_line: Option<String>,
    /// `--timeout` to pass where the binary accepts it.
    timeout: Option<String>,
    /// The exit code a person decided on (`exit:` in the `.run` file), which
    /// `UPDATE_GOLDEN` does not rewrite; otherwise `NAME.code` holds it.
    exit: Option<i32>,
}

impl Case {
    fn expected(&self) -> String {
        format!("{}/{}.expected", self.folder, self.stem)
    }

    fn code(&self) -> String {
        format!("{}/{}.code", self.folder, self.stem)
    }
}

/// The keys of a `.run` file.
#[derive(Default)]
struct RunFile {
    run: Option<String>,
    with: Vec<String>,
    no_line: Option<String>,
    timeout: Option<String>,
    exit: Option<i32>,
}

fn parse_run_file(path: &Path) -> Result<RunFile, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut r = RunFile::default();
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let Some((key, value)) = line.split_once(':') else {
            return Err(format!("{}: `{line}` is not `key: value`", path.display()));
        };
        let value = value.trim().to_string();
        match key.trim() {
            "run" => r.run = Some(value),
            "with" => r.with.push(value),
            "no-line" => r.no_line = Some(value),
            "timeout" => r.timeout = Some(value),
            "exit" => {
                r.exit = Some(value.parse().map_err(|_| {
                    format!("{}: `exit: {value}` is not an exit code", path.display())
                })?)
            }
            other => return Err(format!("{}: unknown key `{other}`", path.display())),
        }
    }
    Ok(r)
}

/// The words of a command line (`subgram` dropped), `$IN` replaced.
fn words(command: &str, input: &str) -> Vec<String> {
    command
        .split_whitespace()
        .skip_while(|w| *w == "subgram")
        .map(|w| w.replace("$IN", input))
        .collect()
}

/// The cases of one folder (`tests/data/err` or `tests/data/bad/KIND`).
fn folder_cases(folder: &str) -> Result<Vec<Case>, Vec<String>> {
    let dir = root().join(folder);
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .map_err(|e| vec![format!("{folder}: {e}")])?
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let id_prefix = folder.strip_prefix("tests/data/").unwrap_or(folder);
    let mut cases = Vec::new();
    let mut errors = Vec::new();
    let is_case_input = |n: &String| {
        let (stem, ext) = n.rsplit_once('.').unwrap_or((n, ""));
        !matches!(ext, "run" | "expected" | "code" | "md")
            && (names.contains(&format!("{stem}.run")) || lsys_run_line(&dir.join(n)).is_some())
    };
    for name in names.iter().filter(|n| is_case_input(n)) {
        let stem = name.rsplit_once('.').map_or(name.as_str(), |p| p.0);
        let run_path = dir.join(format!("{stem}.run"));
        let run = if run_path.exists() {
            match parse_run_file(&run_path) {
                Ok(r) => r,
                Err(e) => {
                    errors.push(e);
                    continue;
                }
            }
        } else {
            RunFile::default()
        };
        let args = match (&run.run, lsys_run_line(&dir.join(name))) {
            (Some(r), None) => words(r, name),
            (None, Some(r)) => {
                let mut a = words(&r, name);
                a.push(name.clone());
                a
            }
            (Some(_), Some(_)) => {
                errors.push(format!(
                    "{folder}/{name}: the command is both in its `// run:` line and in {stem}.run"
                ));
                continue;
            }
            (None, None) => {
                errors.push(format!("{folder}/{stem}.run: no `run:` line"));
                continue;
            }
        };
        let mut files = vec![(name.clone(), Source::Copy(dir.join(name)))];
        for w in &run.with {
            let p = dir.join(w);
            let base = p.file_name().unwrap().to_string_lossy().into_owned();
            if !p.is_file() {
                errors.push(format!("{folder}/{stem}.run: `with: {w}` is not a file"));
            }
            files.push((base, Source::Copy(p)));
        }
        cases.push(Case {
            id: format!("{id_prefix}/{stem}"),
            folder: folder.to_string(),
            stem: stem.to_string(),
            files,
            args,
            no_line: run.no_line,
            timeout: run.timeout,
            exit: run.exit,
        });
    }
    // Stray files: expectations or `.run` files without a case.
    for name in &names {
        let Some((stem, ext)) = name.rsplit_once('.') else {
            continue;
        };
        if matches!(ext, "run" | "expected" | "code") && !cases.iter().any(|c| c.stem == stem) {
            errors.push(format!("{folder}/{name}: no case `{stem}` beside it"));
        }
        if ext == "code" && cases.iter().any(|c| c.stem == stem && c.exit.is_some()) {
            errors.push(format!(
                "{folder}/{name}: the case's .run file says `exit:`; remove one of the two"
            ));
        }
    }
    if errors.is_empty() {
        Ok(cases)
    } else {
        Err(errors)
    }
}

/// The command of an `.lsys` case: its first line after `// run: `.
fn lsys_run_line(path: &Path) -> Option<String> {
    if path.extension()? != "lsys" {
        return None;
    }
    let bytes = std::fs::read(path).ok()?;
    let first = bytes.split(|&b| b == b'\n').next()?;
    let first = std::str::from_utf8(first).ok()?;
    first.strip_prefix("// run: ").map(str::to_string)
}

/// The folders of the non-`.lsys` kinds, by the test that runs them.
const MESH_KINDS: &[&str] = &["obj", "off", "ply-ascii", "ply-binary", "creases"];
const CONTOUR_KINDS: &[&str] = &["points", "svg", "png"];
const DETAILS_KINDS: &[&str] = &["details"];
const MODEL_KINDS: &[&str] = &["model"];

// ---------------------------------------------------------------------------
// Generated cases

/// A case made in code: `NAME` with its files and command line.
fn generated_case(
    stem: &str,
    files: Vec<(&str, Source)>,
    command: &str,
    no_line: Option<&str>,
) -> Case {
    let input = files[0].0.to_string();
    Case {
        id: format!("generated/{stem}"),
        folder: format!("{BAD}/generated"),
        stem: stem.to_string(),
        files: files.into_iter().map(|(n, s)| (n.to_string(), s)).collect(),
        args: words(command, &input),
        no_line: no_line.map(str::to_string),
        timeout: None,
        exit: None,
    }
}

fn common(name: &str) -> Source {
    Source::Copy(root().join(BAD).join("common").join(name))
}

/// The cases too large to keep as files. `tests/data/bad/generated/README.md`
/// describes each.
fn generated() -> Vec<Case> {
    let mut out = Vec::new();
    let text = |s: String| Source::Bytes(s.into_bytes());

    // A chain of 30,000 `#define`s, each naming the one before; the file
    // ends with a use of an undeclared module, so it is bad either way.
    let mut s = String::from("// a chain of 30000 defines\n#define D0 1\n");
    for i in 1..30_000 {
        s += &format!("#define D{i} D{}\n", i - 1);
    }
    s += "module A(float);\nAxiom: B(D29999);\n";
    out.push(generated_case(
        "define-chain-30000",
        vec![("define-chain-30000.lsys", text(s))],
        "check $IN",
        None,
    ));

    // `?:` and `=` chains of 400,000 links (about 3 MB): each link is one
    // level of nesting.
    let links = 400_000;
    let s = format!(
        "module A(float);\nAxiom: A({}0);\n",
        "1 ? 2 : ".repeat(links)
    );
    out.push(generated_case(
        "conditional-chain-400000",
        vec![("conditional-chain-400000.lsys", text(s))],
        "check $IN",
        None,
    ));
    let s = format!(
        "module A(float);\nderivation length: 1;\nAxiom: A(1);\nA(x) : {{ float y; y = {}1; produce A(y); }}\n",
        "y = ".repeat(links)
    );
    out.push(generated_case(
        "assignment-chain-400000",
        vec![("assignment-chain-400000.lsys", text(s))],
        "check $IN",
        None,
    ));
    let s = format!(
        "derivation length: 1;\nF(f) -> V(v = avg(f) * ({}1)) || E^3 F^3;\n",
        "1 ? 2 : ".repeat(links)
    );
    out.push(generated_case(
        "surface-conditional-chain-400000",
        vec![
            ("surface-conditional-chain-400000.lsys", text(s)),
            ("tetrahedron.obj", common("tetrahedron.obj")),
        ],
        "subdivide tetrahedron.obj --grammar $IN -o out.obj",
        None,
    ));

    // 200,000 nested arguments of a function-like macro (600 KB).
    let depth = 200_000;
    let s = format!(
        "#define F(x) x\nmodule A(float);\nAxiom: A({}1{});\n",
        "F(".repeat(depth),
        ")".repeat(depth)
    );
    out.push(generated_case(
        "macro-arguments-nested-200000",
        vec![("macro-arguments-nested-200000.lsys", text(s))],
        "check $IN",
        None,
    ));

    // One OBJ polygon of 600,000 vertices on a circle, then a degenerate
    // triangle (three points on a line) that makes the file bad.
    let n = 600_000;
    let mut s = String::with_capacity(n * 30);
    s += "# a polygon of 600000 vertices, then a face of zero area\n";
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        s += &format!("v {:.7} {:.7} 0\n", a.cos(), a.sin());
    }
    s += "v 0 0 1\nv 1 0 1\nv 2 0 1\nf";
    for k in 1..=n {
        s += &format!(" {k}");
    }
    s += &format!("\nf {} {} {}\n", n + 1, n + 2, n + 3);
    out.push(generated_case(
        "obj-polygon-of-600000-vertices",
        vec![("polygon-of-600000-vertices.obj", text(s))],
        "mesh info $IN",
        None,
    ));

    // Sparse files of 16 GiB: too large to read whole.
    let huge = 16u64 << 30;
    for (stem, name, command) in [
        ("sparse-16-gib-lsys", "huge.lsys", "check $IN"),
        ("sparse-16-gib-obj", "huge.obj", "mesh info $IN"),
        (
            "sparse-16-gib-points",
            "huge.txt",
            "reverse $IN -n 1 -o out.csv",
        ),
        (
            "sparse-16-gib-png",
            "huge.png",
            "reverse $IN -n 1 -o out.csv",
        ),
    ] {
        out.push(generated_case(
            stem,
            vec![(name, Source::Sparse(huge))],
            command,
            Some("a file too large to read has no line to point at"),
        ));
    }
    out.push(generated_case(
        "sparse-16-gib-details",
        vec![
            ("huge.json", Source::Sparse(huge)),
            ("coarse.csv", common("coarse.csv")),
        ],
        "reconstruct coarse.csv --details $IN -o out.txt",
        Some("a file too large to read has no line to point at"),
    ));

    // `/dev/zero` under the name of each kind of input: it never ends.
    if Path::new("/dev/zero").exists() {
        for (stem, name, command) in [
            ("dev-zero-as-lsys", "zero.lsys", "check $IN"),
            (
                "dev-zero-as-obj-for-subdivide",
                "zero.obj",
                "subdivide $IN --grammar face-split.lsys -o out.obj",
            ),
            ("dev-zero-as-ply", "zero.ply", "mesh info $IN"),
            (
                "dev-zero-as-points",
                "zero.txt",
                "reverse $IN -n 1 -o out.csv",
            ),
        ] {
            let mut files = vec![(name, Source::Symlink(PathBuf::from("/dev/zero")))];
            if command.contains("face-split.lsys") {
                files.push(("face-split.lsys", common("face-split.lsys")));
            }
            out.push(generated_case(
                stem,
                files,
                command,
                Some("an endless input has no line to point at"),
            ));
        }
        out.push(generated_case(
            "dev-zero-as-details",
            vec![
                ("zero.json", Source::Symlink(PathBuf::from("/dev/zero"))),
                ("coarse.csv", common("coarse.csv")),
            ],
            "reconstruct coarse.csv --details $IN -o out.txt",
            Some("an endless input has no line to point at"),
        ));
    } else {
        eprintln!("bad_inputs: /dev/zero does not exist here; its cases are not run");
    }
    out
}

/// The names of the generated cases (those that need `/dev/zero` last), so
/// that the corpus can be counted without making them.
const GENERATED: &[&str] = &[
    "define-chain-30000",
    "conditional-chain-400000",
    "assignment-chain-400000",
    "surface-conditional-chain-400000",
    "macro-arguments-nested-200000",
    "obj-polygon-of-600000-vertices",
    "sparse-16-gib-lsys",
    "sparse-16-gib-obj",
    "sparse-16-gib-points",
    "sparse-16-gib-png",
    "sparse-16-gib-details",
    "dev-zero-as-lsys",
    "dev-zero-as-obj-for-subdivide",
    "dev-zero-as-ply",
    "dev-zero-as-points",
    "dev-zero-as-details",
];

// ---------------------------------------------------------------------------
// Running

/// How a run ended.
#[derive(Debug)]
enum End {
    Code(i32),
    /// Killed by a signal (an abort, a stack overflow).
    Signal(i32),
    /// Still running at the limit; killed.
    TimedOut(Duration),
}

#[derive(Debug)]
struct Outcome {
    end: End,
    /// With the directory written `$TMP`.
    stderr: String,
    /// Files that were not there before.
    left: Vec<String>,
    /// Inputs changed or removed.
    changed: Vec<String>,
    elapsed: Duration,
}

/// What a file of the directory was: a link's target, or a size and a hash
/// of the contents (sparse and very large files by size only).
#[derive(PartialEq, Debug)]
enum Seen {
    Link(PathBuf),
    File(u64, Option<u64>),
    Other,
}

fn snapshot(dir: &Path) -> BTreeMap<String, Seen> {
    use std::hash::{Hash, Hasher};
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        let meta = std::fs::symlink_metadata(e.path()).unwrap();
        let seen = if meta.file_type().is_symlink() {
            Seen::Link(std::fs::read_link(e.path()).unwrap())
        } else if meta.is_file() {
            let hash = (meta.len() <= 64 << 20).then(|| {
                let mut h = std::collections::hash_map::DefaultHasher::new();
                std::fs::read(e.path()).unwrap().hash(&mut h);
                h.finish()
            });
            Seen::File(meta.len(), hash)
        } else {
            Seen::Other
        };
        out.insert(name, seen);
    }
    out
}

/// The directory a case runs in; its stderr goes beside it.
fn case_dir(case: &Case) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("bad_inputs")
        .join(case.id.replace('/', "__"))
}

/// The case's directory, made empty.
fn fresh_dir(case: &Case) -> PathBuf {
    let dir = case_dir(case);
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Removes what a case's run left in `target/tmp`.
fn clean(case: &Case) {
    let dir = case_dir(case);
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_file(dir.with_extension("stderr"));
}

/// Whether `subgram COMMAND --help` lists `--timeout` (asked once per
/// command).
fn accepts_timeout(command: &[String]) -> bool {
    static SEEN: OnceLock<Mutex<BTreeMap<Vec<String>, bool>>> = OnceLock::new();
    let seen = SEEN.get_or_init(Default::default);
    if let Some(&b) = seen.lock().unwrap().get(command) {
        return b;
    }
    let help = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(command)
        .arg("--help")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).contains("--timeout"))
        .unwrap_or(false);
    seen.lock().unwrap().insert(command.to_vec(), help);
    help
}

fn run(case: &Case, limit: Duration) -> Outcome {
    let dir = fresh_dir(case);
    for (name, source) in &case.files {
        let path = dir.join(name);
        match source {
            Source::Copy(from) => {
                std::fs::copy(from, &path).unwrap_or_else(|e| panic!("{}: {e}", from.display()));
            }
            Source::Bytes(b) => std::fs::write(&path, b).unwrap(),
            #[cfg(unix)]
            Source::Symlink(to) => std::os::unix::fs::symlink(to, &path).unwrap(),
            #[cfg(not(unix))]
            Source::Symlink(_) => unreachable!("only on Unix"),
            Source::Sparse(len) => std::fs::File::create(&path)
                .and_then(|f| f.set_len(*len))
                .unwrap(),
        }
    }
    let before = snapshot(&dir);
    let mut args = case.args.clone();
    if let Some(t) = &case.timeout {
        let command: Vec<String> = args
            .iter()
            .take_while(|w| w.chars().all(|c| c.is_ascii_lowercase()))
            .cloned()
            .collect();
        if accepts_timeout(&command) {
            args.push("--timeout".into());
            args.push(t.clone());
        }
    }
    let err_path = dir.with_extension("stderr");
    let err_file = std::fs::File::create(&err_path).unwrap();
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_subgram"));
    cmd.current_dir(&dir)
        .args(&args)
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(err_file);
    limit_memory(&mut cmd);
    let start = Instant::now();
    let mut child = cmd.spawn().expect("the binary runs");
    let end = loop {
        match child.try_wait().unwrap() {
            Some(status) => break exit_of(status),
            None if start.elapsed() >= limit => {
                let _ = child.kill();
                let _ = child.wait();
                break End::TimedOut(limit);
            }
            None => std::thread::sleep(Duration::from_millis(5)),
        }
    };
    let elapsed = start.elapsed();
    let after = snapshot(&dir);
    let left = after
        .keys()
        .filter(|k| !before.contains_key(*k))
        .cloned()
        .collect();
    let changed = before
        .iter()
        .filter(|(k, v)| after.get(*k) != Some(v))
        .map(|(k, _)| k.clone())
        .collect();
    let raw = std::fs::read(&err_path).unwrap_or_default();
    let mut stderr = String::from_utf8_lossy(&raw).into_owned();
    for d in [dir.canonicalize().ok(), Some(dir.clone())]
        .into_iter()
        .flatten()
    {
        stderr = stderr.replace(&d.display().to_string(), "$TMP");
    }
    Outcome {
        end,
        stderr,
        left,
        changed,
        elapsed,
    }
}

#[cfg(target_os = "linux")]
fn limit_memory(cmd: &mut Command) {
    use std::os::unix::process::CommandExt;
    // SAFETY: setrlimit is async-signal-safe; nothing else runs between
    // fork and exec.
    unsafe {
        cmd.pre_exec(|| {
            let lim = libc::rlimit {
                rlim_cur: MEMORY as libc::rlim_t,
                rlim_max: MEMORY as libc::rlim_t,
            };
            if libc::setrlimit(libc::RLIMIT_DATA, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

#[cfg(not(target_os = "linux"))]
fn limit_memory(_cmd: &mut Command) {}

fn exit_of(status: std::process::ExitStatus) -> End {
    if let Some(c) = status.code() {
        return End::Code(c);
    }
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        if let Some(s) = status.signal() {
            return End::Signal(s);
        }
    }
    End::Signal(-1)
}

// ---------------------------------------------------------------------------
// Judging

/// The ways a case can misbehave, as KNOWN_FAILURES names them.
const PROBLEMS: &[&str] = &[
    "timeout",
    "crash",
    "memory",
    "exit-0",
    "code",
    "stderr",
    "no-location",
    "wrong-file",
    "leftover",
    "input-changed",
];

/// The file that `stderr` points at, when it starts with
/// `file:line:col: error:` and shows a line with a caret under it.
fn located(stderr: &str) -> Option<&str> {
    let first = stderr.lines().next()?;
    let (place, _) = first.split_once(": error: ")?;
    let mut parts = place.rsplitn(3, ':');
    let (col, line, file) = (parts.next(), parts.next(), parts.next());
    let number =
        |s: Option<&str>| s.is_some_and(|s| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()));
    let file = file.filter(|f| !f.is_empty())?;
    if !(number(col) && number(line)) {
        return None;
    }
    let mut shown = false;
    for l in stderr.lines().skip(1) {
        let t = l.trim_start();
        if let Some((n, _)) = t.split_once(" |") {
            shown |= !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit());
        }
        if shown {
            if let Some(rest) = t.strip_prefix('|') {
                if rest.trim_start().starts_with('^') {
                    return Some(file);
                }
            }
        }
    }
    None
}

/// The problems of one run, and what they are in words.
fn judge(case: &Case, o: &Outcome) -> (BTreeSet<&'static str>, Vec<String>) {
    let mut tags = BTreeSet::new();
    let mut why = Vec::new();
    let crashed = o.stderr.contains("panicked at")
        || o.stderr.contains("memory allocation of")
        || o.stderr.contains("has overflowed its stack");
    match o.end {
        End::TimedOut(t) => {
            tags.insert("timeout");
            why.push(format!("still running after {} s; killed", t.as_secs()));
        }
        End::Signal(s) => {
            tags.insert("crash");
            why.push(format!("killed by signal {s}"));
        }
        End::Code(c) if c == 101 || crashed => {
            tags.insert("crash");
            why.push(format!("exit code {c}, a panic or an abort"));
        }
        End::Code(0) => {
            tags.insert("exit-0");
            why.push("exit code 0: the bad input was accepted".into());
        }
        End::Code(c) => {
            if c != 1 && c != 2 {
                tags.insert("code");
                why.push(format!("exit code {c}, not 1 or 2"));
            }
            match case.exit {
                Some(want) if want != c => {
                    tags.insert("code");
                    why.push(format!(
                        "exit code {c}, expected {want} (`exit:` in its .run file)"
                    ));
                }
                Some(_) => {}
                None => {
                    let code = format!("{c}\n");
                    if let Err(e) = golden::compare(case.code(), code.as_bytes(), Kind::Exact) {
                        tags.insert("code");
                        why.push(format!("exit code {c}: {e}"));
                    }
                }
            }
            if let Err(e) = golden::compare(case.expected(), o.stderr.as_bytes(), Kind::Exact) {
                tags.insert("stderr");
                why.push(e);
            }
            let want_code = case
                .exit
                .or_else(|| {
                    std::fs::read_to_string(root().join(case.code()))
                        .ok()
                        .and_then(|s| s.trim().parse::<i32>().ok())
                })
                .unwrap_or(c);
            match located(&o.stderr) {
                None if case.no_line.is_none() && want_code == 1 => {
                    tags.insert("no-location");
                    why.push(
                        "the message does not start with `file:line:col: error:` and show the \
                         line with a caret (mark the case `no-line: WHY` if its input has no \
                         line)"
                            .into(),
                    );
                }
                Some(file)
                    if !case
                        .files
                        .iter()
                        .any(|(name, _)| file.ends_with(name.as_str())) =>
                {
                    tags.insert("wrong-file");
                    why.push(format!(
                        "the message points into `{file}`, which is not one of the inputs"
                    ));
                }
                _ => {}
            }
        }
    }
    if o.stderr.contains("out of memory") || o.stderr.contains("memory allocation of") {
        tags.insert("memory");
        why.push(format!(
            "it ran out of memory (the test allows {} MiB): an input this large must be \
             refused by a limit first",
            MEMORY >> 20
        ));
    }
    if !o.left.is_empty() {
        tags.insert("leftover");
        why.push(format!("left behind: {}", o.left.join(", ")));
    }
    if !o.changed.is_empty() {
        tags.insert("input-changed");
        why.push(format!("changed or removed: {}", o.changed.join(", ")));
    }
    (tags, why)
}

/// A recorded known failure: the sets of problems it may show (one of
/// them, exactly), and what happens in words.
struct Known {
    alternatives: Vec<BTreeSet<String>>,
    note: String,
}

fn known_failures() -> Result<BTreeMap<String, Known>, String> {
    let path = root().join(BAD).join("KNOWN_FAILURES");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = BTreeMap::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut it = line.split_whitespace();
        let (Some(id), Some(tags)) = (it.next(), it.next()) else {
            return Err(format!(
                "KNOWN_FAILURES:{}: expected `CASE PROBLEMS NOTE`",
                i + 1
            ));
        };
        let alternatives: Vec<BTreeSet<String>> = tags
            .split('|')
            .map(|alt| alt.split('+').map(str::to_string).collect())
            .collect();
        for t in alternatives.iter().flatten() {
            if !PROBLEMS.contains(&t.as_str()) {
                return Err(format!(
                    "KNOWN_FAILURES:{}: unknown problem `{t}` (one of {})",
                    i + 1,
                    PROBLEMS.join(", ")
                ));
            }
        }
        let note = it.collect::<Vec<_>>().join(" ");
        if out
            .insert(id.to_string(), Known { alternatives, note })
            .is_some()
        {
            return Err(format!("KNOWN_FAILURES:{}: `{id}` is listed twice", i + 1));
        }
    }
    Ok(out)
}

/// Removes the line of case `id` from KNOWN_FAILURES.
fn prune_known(id: &str) {
    static LOCK: Mutex<()> = Mutex::new(());
    let _guard = LOCK.lock().unwrap();
    let path = root().join(BAD).join("KNOWN_FAILURES");
    let text = std::fs::read_to_string(&path).unwrap();
    let kept: String = text
        .lines()
        .filter(|l| l.split_whitespace().next() != Some(id))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&path, kept).unwrap();
}

/// Runs `cases` (a few at a time) and returns what is wrong.
fn run_cases(what: &str, cases: Vec<Case>) -> Vec<String> {
    let known = match known_failures() {
        Ok(k) => k,
        Err(e) => return vec![e],
    };
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<(usize, Result<String, String>)>> = Mutex::new(Vec::new());
    let workers = std::thread::available_parallelism()
        .map_or(2, |n| n.get())
        .clamp(2, 4);
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(case) = cases.get(i) else { break };
                let r = one_case(case, known.get(&case.id));
                results.lock().unwrap().push((i, r));
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    let (mut passed, mut known_seen) = (0, 0);
    let mut failures = Vec::new();
    for (_, r) in results {
        match r {
            Ok(note) if note.is_empty() => passed += 1,
            Ok(note) => {
                known_seen += 1;
                eprintln!("{note}");
            }
            Err(e) => failures.push(e),
        }
    }
    eprintln!(
        "bad_inputs {what}: {} cases, {passed} as expected, {known_seen} known failures as \
         recorded, {} wrong",
        cases.len(),
        failures.len()
    );
    failures
}

/// Runs one case: `Ok("")` when it behaves, `Ok(note)` when it is a known
/// failure that misbehaves as recorded, `Err` otherwise.
fn one_case(case: &Case, known: Option<&Known>) -> Result<String, String> {
    // A recorded hang is killed early, except when expectations are being
    // rewritten: then every case gets its full time, so that a fix that is
    // merely slow is seen as a fix.
    let hang = known.is_some_and(|k| k.alternatives.iter().any(|a| a.contains("timeout")));
    let o = run(
        case,
        if hang && !golden::updating() {
            SHORT
        } else {
            LIMIT
        },
    );
    let (tags, why) = judge(case, &o);
    let command = format!("subgram {}", case.args.join(" "));
    let shown: Vec<&str> = tags.iter().copied().collect();
    let report = || {
        format!(
            "{}: `{command}` in {:.1} s: {}\n  {}\n  stderr: {}",
            case.id,
            o.elapsed.as_secs_f64(),
            shown.join("+"),
            why.join("\n  "),
            clip(&o.stderr)
        )
    };
    // What a run leaves in target/tmp is kept only where the test fails,
    // for a person to look at (a sparse file never).
    let passed = tags.is_empty();
    let recorded = known.is_some_and(|k| {
        let observed: BTreeSet<String> = tags.iter().map(|t| t.to_string()).collect();
        k.alternatives.contains(&observed)
    });
    let sparse = case
        .files
        .iter()
        .any(|(_, s)| matches!(s, Source::Sparse(_)));
    if passed || recorded || sparse {
        clean(case);
    }
    match known {
        None if passed => Ok(String::new()),
        None => Err(report()),
        Some(_) if passed && golden::updating() => {
            prune_known(&case.id);
            Ok(format!(
                "UPDATE_GOLDEN: {} now behaves; removed it from {BAD}/KNOWN_FAILURES",
                case.id
            ))
        }
        Some(_) if passed => Err(format!(
            "{}: `{command}` now behaves: remove it from {BAD}/KNOWN_FAILURES (and check its \
             .expected and .code, rewritten with UPDATE_GOLDEN=1)",
            case.id
        )),
        Some(k) => {
            if recorded {
                Ok(format!(
                    "known failure {}: {} ({})",
                    case.id,
                    shown.join("+"),
                    k.note
                ))
            } else {
                let recorded: Vec<String> = k
                    .alternatives
                    .iter()
                    .map(|a| a.iter().cloned().collect::<Vec<_>>().join("+"))
                    .collect();
                Err(format!(
                    "{} misbehaves differently from its KNOWN_FAILURES line (recorded {}); \
                     fix the line, or the case:\n{}",
                    case.id,
                    recorded.join(" or "),
                    report()
                ))
            }
        }
    }
}

fn clip(s: &str) -> String {
    let s = s.trim_end();
    if s.is_empty() {
        return "(empty)".into();
    }
    let lines: Vec<&str> = s.lines().take(8).collect();
    let mut out = lines.join("\n          ");
    if out.len() > 1200 {
        out = out.chars().take(1200).collect::<String>() + "…";
    }
    out
}

fn kinds_cases(kinds: &[&str]) -> Result<Vec<Case>, Vec<String>> {
    let mut all = Vec::new();
    let mut errors = Vec::new();
    for k in kinds {
        match folder_cases(&format!("{BAD}/{k}")) {
            Ok(c) => all.extend(c),
            Err(e) => errors.extend(e),
        }
    }
    if errors.is_empty() {
        Ok(all)
    } else {
        Err(errors)
    }
}

fn check(what: &str, cases: Result<Vec<Case>, Vec<String>>) {
    let failures = match cases {
        Ok(cases) => run_cases(what, cases),
        Err(errors) => errors,
    };
    golden::assert_all(failures);
}

// ---------------------------------------------------------------------------
// The tests

#[test]
fn lsys_files_and_surface_grammars() {
    check("err/", folder_cases("tests/data/err"));
}

#[test]
fn meshes() {
    check("meshes", kinds_cases(MESH_KINDS));
}

#[test]
fn contours() {
    check("contours", kinds_cases(CONTOUR_KINDS));
}

#[test]
fn details_files() {
    check("details", kinds_cases(DETAILS_KINDS));
}

#[test]
fn model_files() {
    check("model", kinds_cases(MODEL_KINDS));
}

#[test]
fn generated_inputs() {
    let cases = generated();
    let made: Vec<&str> = cases.iter().map(|c| c.stem.as_str()).collect();
    let listed: Vec<&str> = GENERATED
        .iter()
        .copied()
        .filter(|s| Path::new("/dev/zero").exists() || !s.starts_with("dev-zero-"))
        .collect();
    assert_eq!(made, listed, "GENERATED lists the generated cases in order");
    check("generated", Ok(cases));
}

/// Every folder has its README naming each of its cases, every known
/// failure is a case, and there are enough cases of every kind.
#[test]
fn the_corpus_is_complete() {
    let mut problems = Vec::new();
    let mut ids = BTreeSet::new();
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    let folders: Vec<String> = std::iter::once("tests/data/err".to_string())
        .chain(
            MESH_KINDS
                .iter()
                .chain(CONTOUR_KINDS)
                .chain(DETAILS_KINDS)
                .chain(MODEL_KINDS)
                .map(|k| format!("{BAD}/{k}")),
        )
        .collect();
    let listed = |folder: &str, stems: Vec<String>, problems: &mut Vec<String>| {
        let readme = std::fs::read_to_string(root().join(folder).join("README.md"))
            .unwrap_or_else(|e| panic!("{folder}/README.md: {e}"));
        for s in stems {
            if !readme.contains(&format!("`{s}`")) {
                problems.push(format!("{folder}/README.md does not list `{s}`"));
            }
        }
    };
    for folder in &folders {
        match folder_cases(folder) {
            Ok(cases) => {
                for c in &cases {
                    let kind = if folder.ends_with("/err") {
                        if c.stem.starts_with("surface-") {
                            "lsys (surface grammar)".to_string()
                        } else {
                            "lsys (curve)".to_string()
                        }
                    } else {
                        folder.rsplit('/').next().unwrap().to_string()
                    };
                    *counts.entry(kind).or_default() += 1;
                    ids.insert(c.id.clone());
                }
                listed(
                    folder,
                    cases.iter().map(|c| c.stem.clone()).collect(),
                    &mut problems,
                );
            }
            Err(e) => problems.extend(e),
        }
    }
    // The generated cases, with /dev/zero's whether or not it exists here.
    let stems: Vec<String> = GENERATED.iter().map(|s| s.to_string()).collect();
    *counts.entry("generated".into()).or_default() += stems.len();
    ids.extend(stems.iter().map(|s| format!("generated/{s}")));
    listed(&format!("{BAD}/generated"), stems.clone(), &mut problems);
    let gen_dir = root().join(BAD).join("generated");
    for e in std::fs::read_dir(&gen_dir).unwrap() {
        let name = e.unwrap().file_name().into_string().unwrap();
        if let Some((stem, "expected" | "code")) = name.rsplit_once('.') {
            if !stems.iter().any(|s| s == stem) {
                problems.push(format!(
                    "{BAD}/generated/{name}: no generated case `{stem}`"
                ));
            }
        }
    }
    match known_failures() {
        Ok(k) => {
            for id in k.keys() {
                if !ids.contains(id) {
                    problems.push(format!("KNOWN_FAILURES names `{id}`, which is not a case"));
                }
            }
        }
        Err(e) => problems.push(e),
    }
    let total: usize = counts.values().sum();
    eprintln!("bad_inputs: {total} cases: {counts:?}");
    assert!(total >= 100, "only {total} bad inputs");
    for (kind, &n) in &counts {
        if n < 5 {
            problems.push(format!("only {n} cases of kind {kind}"));
        }
    }
    for kind in MESH_KINDS.iter().chain(CONTOUR_KINDS).chain(DETAILS_KINDS) {
        if !counts.contains_key(*kind) {
            problems.push(format!("no cases of kind {kind}"));
        }
    }
    golden::assert_all(problems);
}
