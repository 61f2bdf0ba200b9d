//! The fuzz targets' inputs replayed on the stable toolchain: every seed
//! (`fuzz/corpus/TARGET/`) and every minimised finding that is fixed
//! (`tests/data/fuzz/TARGET/`) runs through the target's own body, the
//! very file the cargo-fuzz targets call (`fuzz/src/lib.rs`, compiled
//! here as a module), so the paths cannot drift apart. A body must return:
//! a panic fails the test and names the file.
//!
//! Findings that are not fixed yet wait in `tests/data/fuzz/pending/TARGET/`
//! with a line each in `tests/data/fuzz/pending/README.md`. A plain
//! `cargo test` only checks that they are documented; they may hang, abort
//! or exhaust memory, so they run only on request, each in a child process
//! with a time and memory limit:
//!
//! ```sh
//! SUBGRAM_FUZZ_PENDING=1 cargo test fuzz_replay::pending -- --nocapture
//! ```
//!
//! which prints, for each, whether it passes now (then move it to
//! `tests/data/fuzz/TARGET/`, where every `cargo test` replays it).

#[path = "../../fuzz/src/lib.rs"]
mod bodies;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Replayed files are small: seeds are at most libFuzzer's `-max_len` of
/// `fuzz/run.sh` (4096 bytes) and findings are minimised. A larger file is
/// refused rather than replayed, so that a replay stays quick.
const MAX_LEN: usize = 4096;

/// How long a pending finding may run in its child process, and the
/// address space it gets.
const PENDING_SECONDS: u64 = 20;
const PENDING_MEMORY_KB: u64 = 4 * 1024 * 1024;
/// A pending finding that was slow passes when it takes less than this
/// (seconds, debug build).
const PENDING_QUICK: f64 = 1.0;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn body(target: &str) -> bodies::Body {
    bodies::TARGETS
        .iter()
        .find(|(name, _)| *name == target)
        .unwrap_or_else(|| panic!("no fuzz target `{target}` in fuzz/src/lib.rs"))
        .1
}

/// The files of `dir` (none when it does not exist), sorted, without the
/// READMEs.
fn files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut v: Vec<PathBuf> = entries
        .map(|e| e.expect("a readable folder").path())
        .filter(|p| {
            p.is_file()
                && !p
                    .file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("README"))
        })
        .collect();
    v.sort();
    v
}

/// Runs every seed and every fixed finding of `target` through its body.
fn replay(target: &str) {
    let run = body(target);
    let seeds = files(&root().join("fuzz/corpus").join(target));
    assert!(!seeds.is_empty(), "fuzz/corpus/{target}/ has no seeds");
    let findings = files(&root().join("tests/data/fuzz").join(target));
    let mut failed = Vec::new();
    for f in seeds.iter().chain(&findings) {
        let data = std::fs::read(f).unwrap();
        assert!(
            data.len() <= MAX_LEN,
            "{} has {} bytes, more than the {MAX_LEN} replayed: minimise it (cargo fuzz tmin)",
            f.display(),
            data.len()
        );
        if std::panic::catch_unwind(|| run(&data)).is_err() {
            failed.push(f.display().to_string());
        }
    }
    assert!(
        failed.is_empty(),
        "fuzz target {target} panics on:\n  {}",
        failed.join("\n  ")
    );
}

#[test]
fn lsys_check() {
    replay("lsys_check");
}

#[test]
fn lsys_derive() {
    replay("lsys_derive");
}

#[test]
fn mesh_read() {
    replay("mesh_read");
}

#[test]
fn surface_run() {
    replay("surface_run");
}

#[test]
fn contour_reverse() {
    replay("contour_reverse");
}

#[test]
fn details_reconstruct() {
    replay("details_reconstruct");
}

#[test]
fn vv_run() {
    replay("vv_run");
}

#[test]
fn shape_derive() {
    replay("shape_derive");
}

#[test]
fn model_files() {
    replay("model_files");
}

#[test]
fn serve_request() {
    replay("serve_request");
}

/// Every body has a `[[bin]]` in fuzz/Cargo.toml, a target file, seeds and
/// a dictionary, and every folder of findings names a target.
#[test]
fn every_target_is_complete() {
    let manifest = std::fs::read_to_string(root().join("fuzz/Cargo.toml")).unwrap();
    let names: Vec<&str> = bodies::TARGETS.iter().map(|(n, _)| *n).collect();
    for n in &names {
        assert!(
            manifest.contains(&format!("name = \"{n}\"")),
            "fuzz/Cargo.toml has no [[bin]] `{n}`"
        );
        let src = std::fs::read_to_string(root().join(format!("fuzz/fuzz_targets/{n}.rs")))
            .unwrap_or_else(|e| panic!("fuzz/fuzz_targets/{n}.rs: {e}"));
        assert!(
            src.contains(&format!("subgram_fuzz::{n}(data)")),
            "fuzz/fuzz_targets/{n}.rs does not call its body subgram_fuzz::{n}"
        );
        assert!(
            root().join(format!("fuzz/dict/{n}.dict")).is_file(),
            "fuzz/dict/{n}.dict is missing"
        );
    }
    for kind in ["tests/data/fuzz", "tests/data/fuzz/pending"] {
        let Ok(entries) = std::fs::read_dir(root().join(kind)) else {
            continue;
        };
        for e in entries {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if p.is_dir() && name != "pending" {
                assert!(
                    names.contains(&name.as_str()),
                    "{kind}/{name}/ names no fuzz target"
                );
            }
        }
    }
}

/// The pending findings: each has its line in the README, naming it.
fn pending_files() -> Vec<(String, PathBuf)> {
    let dir = root().join("tests/data/fuzz/pending");
    let mut v = Vec::new();
    for (name, _) in bodies::TARGETS {
        for f in files(&dir.join(name)) {
            v.push((name.to_string(), f));
        }
    }
    v
}

#[test]
fn pending_findings_are_documented() {
    let readme = std::fs::read_to_string(root().join("tests/data/fuzz/pending/README.md"))
        .unwrap_or_default();
    for (target, f) in pending_files() {
        let rel = format!("{target}/{}", f.file_name().unwrap().to_string_lossy());
        assert!(
            readme.contains(&format!("`{rel}`")),
            "tests/data/fuzz/pending/README.md does not describe `{rel}`"
        );
        let len = std::fs::metadata(&f).unwrap().len() as usize;
        assert!(len <= MAX_LEN, "{rel} has {len} bytes: minimise it");
    }
}

/// With SUBGRAM_FUZZ_PENDING=1: each pending finding in a child process
/// (this test binary, running `pending_child`), limited in time and
/// memory; prints which pass now (within [`PENDING_QUICK`] seconds, as
/// some findings are only slow). Never fails: pending findings are known.
#[test]
fn pending() {
    if std::env::var_os("SUBGRAM_FUZZ_PENDING").is_none() {
        return;
    }
    let exe = std::env::current_exe().unwrap();
    for (target, f) in pending_files() {
        let start = Instant::now();
        let mut child = Command::new("bash")
            .arg("-c")
            .arg(format!(
                "ulimit -v {PENDING_MEMORY_KB}; exec \"$0\" fuzz_replay::pending_child --exact --test-threads=1"
            ))
            .arg(&exe)
            .env("SUBGRAM_FUZZ_CHILD", format!("{target}:{}", f.display()))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("the test binary runs again");
        let outcome = loop {
            if let Some(status) = child.try_wait().unwrap() {
                let took = start.elapsed().as_secs_f64();
                break if !status.success() {
                    format!("still fails ({status})")
                } else if took > PENDING_QUICK {
                    "runs to the end, but slowly: still slow?".to_string()
                } else {
                    format!("passes now: move it to tests/data/fuzz/{target}/")
                };
            }
            if start.elapsed() > Duration::from_secs(PENDING_SECONDS) {
                let _ = child.kill();
                let _ = child.wait();
                break format!("still runs after {PENDING_SECONDS} s");
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        println!(
            "{target}/{}: {outcome} ({:.1} s)",
            f.file_name().unwrap().to_string_lossy(),
            start.elapsed().as_secs_f64()
        );
    }
}

/// The child of `pending`: runs the one file SUBGRAM_FUZZ_CHILD names
/// (`TARGET:PATH`); without it, nothing.
#[test]
fn pending_child() {
    let Ok(spec) = std::env::var("SUBGRAM_FUZZ_CHILD") else {
        return;
    };
    let (target, path) = spec.split_once(':').unwrap();
    body(target)(&std::fs::read(path).unwrap());
}
