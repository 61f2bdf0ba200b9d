//! The external environmental-program path (src/enviro/external.rs)
//! against a stand-in program that speaks the slave's side of lpfg's
//! protocol (examples/stand_in_env.rs, built once per test run): the
//! answers arrive in the word; each way the program can fail stops the
//! run with a message that names it and what happened, while answers
//! that lpfg cannot use are passed over with a warning, as lpfg passes
//! over them; and afterwards nothing is left: no `.to_field`/`.from_field`
//! file (the model folder holds only what the test wrote), no process (not
//! even a zombie), no SysV semaphore set.
#![cfg(target_os = "linux")]

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use subgram::{Deadline, DeriveOptions, LoadOptions, ProgramOutput, Stream, System};

use crate::support::{root, scratch};

/// The stand-in's binary, built on first use next to the test binary
/// (`target/PROFILE/examples/stand_in_env`).
fn stand_in() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        let exe = std::env::current_exe().expect("the test binary's path");
        // target/PROFILE/deps/it-HASH
        let profile = exe
            .parent()
            .and_then(Path::parent)
            .expect("the test binary lies in target/PROFILE/deps");
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut cmd = Command::new(cargo);
        cmd.args(["build", "--quiet", "--example", "stand_in_env"])
            .current_dir(root());
        if profile.file_name().is_some_and(|n| n == "release") {
            cmd.arg("--release");
        }
        let out = cmd
            .output()
            .unwrap_or_else(|e| panic!("cannot run cargo to build the stand-in: {e}"));
        assert!(
            out.status.success(),
            "cargo build --example stand_in_env failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bin = profile.join("examples").join("stand_in_env");
        assert!(bin.is_file(), "{} was not built", bin.display());
        bin
    })
}

/// A scratch model folder running the stand-in in `mode`, and a second
/// folder for its pid file (the model folder gains no file).
struct Model {
    dir: tempfile::TempDir,
    aside: tempfile::TempDir,
}

impl Model {
    fn new(name: &str, program: &str, mode: &str) -> Model {
        let dir = scratch(&format!("enviro-{name}"));
        let aside = scratch(&format!("enviro-{name}-pid"));
        std::fs::write(dir.path().join("lsystem.l"), program).unwrap();
        let pid = aside.path().join("pid");
        let e = format!(
            "executable: {} {mode} pid-file {}\ncommunication type: files\n\
             turtle position: P: %f %f %f\nturtle heading: H: %f %f %f\n",
            stand_in().display(),
            pid.display()
        );
        std::fs::write(dir.path().join("commfile.e"), e).unwrap();
        Model { dir, aside }
    }

    fn with_executable(name: &str, program: &str, executable: &str) -> Model {
        let dir = scratch(&format!("enviro-{name}"));
        let aside = scratch(&format!("enviro-{name}-pid"));
        std::fs::write(dir.path().join("lsystem.l"), program).unwrap();
        std::fs::write(
            dir.path().join("commfile.e"),
            format!("executable: {executable}\n"),
        )
        .unwrap();
        Model { dir, aside }
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }

    fn curve(&self, timeout: Duration) -> subgram::Curve {
        let mut opts = LoadOptions::default();
        opts.environment.answer_timeout = timeout;
        match subgram::load(self.path(), &opts) {
            Ok(System::Curve(c)) => c,
            Ok(_) => panic!("the model did not load as a curve L-system"),
            Err(e) => panic!("the model does not load:\n{e}"),
        }
    }

    /// Loads and derives the model: the word, or the error's message.
    fn derive(&self, timeout: Duration, deadline: Option<Deadline>) -> Result<String, String> {
        self.derive_noting(timeout, deadline).0
    }

    /// [`Model::derive`], and what the run wrote to standard error (the
    /// derivation's warnings).
    fn derive_noting(
        &self,
        timeout: Duration,
        deadline: Option<Deadline>,
    ) -> (Result<String, String>, String) {
        let c = self.curve(timeout);
        let output = ProgramOutput::new();
        let word = c
            .derive(DeriveOptions {
                deadline,
                output: output.clone(),
                ..DeriveOptions::default()
            })
            .map(|d| c.word_text(&d.word))
            .map_err(|e| e.to_string());
        let errors = output
            .take_text()
            .into_iter()
            .filter(|(s, _)| *s == Stream::Stderr)
            .map(|(_, t)| t)
            .collect();
        (word, errors)
    }

    /// Checks that nothing of the run is left: the folder holds only the
    /// test's two files, the stand-in's process is gone (reaped: a zombie
    /// still has its /proc entry), and no semaphore set of the run's
    /// keys exists. `started`: whether the stand-in ran (and wrote its
    /// pid).
    fn assert_clean(&self, started: bool) {
        let mut names: Vec<String> = std::fs::read_dir(self.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(
            names,
            ["commfile.e", "lsystem.l"],
            "files left in the folder"
        );
        let keys = subgram::enviro::external::keys_used_in(self.path());
        assert!(
            !keys.is_empty(),
            "no key recorded for {}",
            self.path().display()
        );
        if started {
            let pid = std::fs::read_to_string(self.aside.path().join("pid"))
                .expect("the stand-in wrote its pid");
            let pid = pid.trim();
            assert!(
                !Path::new(&format!("/proc/{pid}")).exists(),
                "the stand-in (pid {pid}) is still there"
            );
        }
        let sets = std::fs::read_to_string("/proc/sysvipc/sem").unwrap();
        let live: Vec<i32> = sets
            .lines()
            .skip(1)
            .filter_map(|l| l.split_whitespace().next()?.parse().ok())
            .collect();
        for k in keys {
            assert!(!live.contains(&k), "the semaphore set {k} is left");
        }
    }
}

const ECHO: &str = "#include <lpfgall.h>\nderivation length: 1;\n\
    Axiom: F(2) E1(7) Right(90) F(3) E2(0,0) Left(90) F(1) E1(5);\n";

#[test]
fn echoes_the_turtle_position() {
    // The turtle starts at the origin heading up the y axis: F(2) takes it
    // to (0,2,0), so the first E1 gets x = 0; Right(90) turns it to +x
    // (Left(90) would turn it to -x) and F(3) takes it to (3,2,0): E2 gets
    // (3, 2); Left(90) turns it back up and F(1) takes it to (3,3,0): the
    // second E1 gets 3. The exchange comes before the one step, and no
    // production touches the modules.
    let m = Model::new("echo", ECHO, "echo-position");
    let word = m.derive(Duration::from_secs(30), None).unwrap();
    assert_eq!(
        word,
        "F(2) E1(0) Right(90) F(3) E2(3, 2) Left(90) F(1) E1(3)"
    );
    m.assert_clean(true);
}

#[test]
fn sums_over_three_steps() {
    // One exchange before each of the three steps, the k-th adding k:
    // 1 -> 2 -> 4 -> 7 and 10 -> 11 -> 13 -> 16.
    let src = "#include <lpfgall.h>\nderivation length: 3;\nAxiom: E1(1) F(1) E1(10);\n";
    let m = Model::new("sum", src, "sum");
    assert_eq!(
        m.derive(Duration::from_secs(30), None).unwrap(),
        "E1(7) F(1) E1(16)"
    );
    m.assert_clean(true);
}

/// Derives the echo model with the stand-in in a failing `mode`: the
/// message, after checking that it names the program and that nothing is
/// left.
fn failure(mode: &str, timeout: Duration) -> String {
    let m = Model::new(mode, ECHO, mode);
    let e = m
        .derive(timeout, None)
        .expect_err("the derivation should fail");
    assert!(
        e.contains(&format!("`{}`", stand_in().display())),
        "the message does not name the program:\n{e}"
    );
    assert!(e.contains("before step 1"), "{e}");
    m.assert_clean(true);
    e
}

#[test]
fn a_crash_is_reported_with_its_status() {
    let e = failure("crash", Duration::from_secs(30));
    assert!(e.contains("exited with status 3 before answering"), "{e}");
}

#[test]
fn a_silent_program_is_stopped_at_the_answer_timeout() {
    let t = Instant::now();
    let e = failure("silent", Duration::from_secs(2));
    assert!(e.contains("gave no answer within 2 s"), "{e}");
    assert!(t.elapsed() < Duration::from_secs(10), "{:?}", t.elapsed());
}

/// Derives the echo model with the stand-in answering in `mode` what
/// lpfg cannot use: the run goes on (lpfg passes over such answers, with
/// its "Invalid response received from environment"), the modules keep
/// their values, a warning says what was passed over, and nothing is
/// left. The word and the warning.
fn passed_over(mode: &str) -> (String, String) {
    let m = Model::new(mode, ECHO, mode);
    let (word, warning) = m.derive_noting(Duration::from_secs(30), None);
    let word = word.unwrap_or_else(|e| panic!("the derivation failed:\n{e}"));
    assert!(warning.contains("before step 1"), "{warning}");
    assert!(warning.contains("keep their values"), "{warning}");
    m.assert_clean(true);
    (word, warning)
}

#[test]
fn an_answer_to_a_module_not_sent_is_passed_over() {
    let (word, warning) = passed_over("unknown-module");
    // Three answers, all for module 999999: every module keeps its values.
    assert_eq!(
        word,
        "F(2) E1(7) Right(90) F(3) E2(0, 0) Left(90) F(1) E1(5)"
    );
    assert!(
        warning.contains("answered module 999999, which it was not sent (and 2 more)"),
        "{warning}"
    );
}

#[test]
fn an_answer_with_the_wrong_count_is_passed_over() {
    let (word, warning) = passed_over("wrong-count");
    // Two values for each module: right for the E2 (module 4, which takes
    // them), wrong for the E1s (modules 1 and 7), which keep theirs.
    assert_eq!(
        word,
        "F(2) E1(7) Right(90) F(3) E2(1, 2) Left(90) F(1) E1(5)"
    );
    assert!(
        warning.contains("module 1 (`E1`, which takes 1) with 2 values (and 1 more)"),
        "{warning}"
    );
}

#[test]
fn a_malformed_answer_is_refused() {
    let e = failure("garbage", Duration::from_secs(30));
    assert!(e.contains("wrote a malformed answer"), "{e}");
    assert!(e.contains(".from_field"), "{e}");
    assert!(e.contains("`hello`: expected the module's number"), "{e}");
}

#[test]
fn an_answer_without_control_is_refused() {
    let e = failure("no-control", Duration::from_secs(30));
    assert!(e.contains("without a `Control:` line"), "{e}");
}

#[test]
fn a_program_not_found_is_named_with_the_e_file() {
    let m = Model::with_executable("missing", ECHO, "no-such-program-xyz");
    let e = m.derive(Duration::from_secs(30), None).unwrap_err();
    assert!(e.contains("`no-such-program-xyz`"), "{e}");
    assert!(e.contains("commfile.e:1"), "{e}");
    assert!(e.contains("PATH"), "{e}");
    m.assert_clean(false);
}

#[test]
fn the_deadline_stops_a_silent_program() {
    let m = Model::new("deadline", ECHO, "silent");
    let t = Instant::now();
    let e = m
        .derive(
            Duration::from_secs(30),
            Some(Deadline::after(Duration::from_millis(700))),
        )
        .unwrap_err();
    assert!(t.elapsed() < Duration::from_secs(10), "{:?}", t.elapsed());
    assert!(e.contains("before the run's time limit"), "{e}");
    assert!(e.contains("time limit of 0.7 s"), "{e}");
    m.assert_clean(true);
}

#[test]
fn an_abandoned_derivation_leaves_nothing() {
    // A derivation that fails for a reason of its own after good
    // exchanges: the word outgrows max_modules at step 3 (2 + 2^k modules
    // after step k), after the exchange before it.
    let src = "#include <lpfgall.h>\nmodule A;\nderivation length: 10;\nAxiom: E1(1) F(1) A;\n\
               A : { produce A A; }\n";
    let m = Model::new("abandoned", src, "sum");
    let c = m.curve(Duration::from_secs(30));
    let e = c
        .derive(DeriveOptions::default().with_max_modules(8))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("at step 3") && e.contains("grew past 8 modules"),
        "{e}"
    );
    m.assert_clean(true);

    // A panic while the derivation runs (in the caller's step callback,
    // after the first step): the unwinding drops the environment.
    let m = Model::new("panicked", src, "sum");
    let c = m.curve(Duration::from_secs(30));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let _ = c.run_reporting(DeriveOptions::default(), |_| {
            panic!("a caller's panic, on purpose");
        });
    }));
    assert!(r.is_err());
    m.assert_clean(true);
}

/// Ctrl-C (SIGINT to `subgram derive`) while the program is asked: the
/// command still ends by the signal, as it would without an environment,
/// and the files, the semaphore set and the program are gone.
#[test]
fn ctrl_c_leaves_nothing() {
    use std::os::unix::process::ExitStatusExt;
    let m = Model::new("sigint", ECHO, "silent");
    let mut run = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(["derive", m.path().to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // The stand-in writes its pid once it has started; its command line
    // carries the run's key (`-k KEY`).
    let pid_file = m.aside.path().join("pid");
    let t = Instant::now();
    let pid = loop {
        if let Some(p) = std::fs::read_to_string(&pid_file)
            .ok()
            .filter(|p| p.ends_with('\n') || !p.trim().is_empty())
        {
            break p.trim().to_string();
        }
        assert!(
            t.elapsed() < Duration::from_secs(20),
            "the stand-in never started"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let args = std::fs::read(format!("/proc/{pid}/cmdline")).unwrap();
    let args: Vec<String> = args
        .split(|b| *b == 0)
        .map(|a| String::from_utf8_lossy(a).into_owned())
        .collect();
    let key: i32 = args[args.iter().position(|a| a == "-k").unwrap() + 1]
        .parse()
        .unwrap();
    std::thread::sleep(Duration::from_millis(200));
    let sent = Command::new("kill")
        .args(["-INT", &run.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let t = Instant::now();
    let status = loop {
        if let Some(s) = run.try_wait().unwrap() {
            break s;
        }
        assert!(
            t.elapsed() < Duration::from_secs(10),
            "subgram did not stop"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.signal(), Some(libc_sigint()), "{status}");
    let names: Vec<String> = std::fs::read_dir(m.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names
            .iter()
            .all(|n| !n.starts_with(".to_field") && !n.starts_with(".from_field")),
        "{names:?}"
    );
    assert!(
        !Path::new(&format!("/proc/{pid}")).exists(),
        "the stand-in (pid {pid}) is still there"
    );
    let sets = std::fs::read_to_string("/proc/sysvipc/sem").unwrap();
    assert!(
        sets.lines()
            .skip(1)
            .all(|l| l.split_whitespace().next() != Some(&key.to_string())),
        "the semaphore set {key} is left"
    );
}

/// SIGINT's number on Linux.
fn libc_sigint() -> i32 {
    2
}
