//! Stress checks that need an optimised build: run by `.ci/run` as
//! `cargo test --release --test stress`, not by a plain `cargo test`.
//!
//! Issue 44, item 7: the PNG tracer's memory on the worst image it
//! accepts, 8192 × 8192 pixels of 2-pixel squares (every other cell of the
//! marching squares holds a loop), stays under 1 GB: measured as the
//! child's peak resident size, which `wait4` reports for that child alone.

use std::path::Path;
use std::time::{Duration, Instant};

/// Runs the binary in `dir` and returns its exit code, its standard error,
/// its peak resident size in bytes and its wall time.
fn run_measured(dir: &Path, args: &[&str]) -> (Option<i32>, String, u64, Duration) {
    use std::os::unix::process::ExitStatusExt;
    let t = Instant::now();
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(args)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(dir.join("stderr.txt")).unwrap())
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: a zeroed rusage is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: waits for our own child, with valid pointers.
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(r, pid, "wait4");
    let took = t.elapsed();
    let code = std::process::ExitStatus::from_raw(status).code();
    let err = std::fs::read_to_string(dir.join("stderr.txt")).unwrap();
    std::fs::remove_file(dir.join("stderr.txt")).unwrap();
    // ru_maxrss is in kilobytes on Linux.
    (code, err, usage.ru_maxrss as u64 * 1024, took)
}

#[test]
fn tracing_the_worst_8192_image_stays_under_1_gb() {
    let tmp = tempfile::Builder::new()
        .prefix("subgram-stress-")
        .tempdir()
        .unwrap();
    let dir = tmp.path();
    let n = 8192u32;
    let mut pm = tiny_skia::Pixmap::new(n, n).unwrap();
    pm.fill(tiny_skia::Color::WHITE);
    let black = tiny_skia::PremultipliedColorU8::from_rgba(0, 0, 0, 255).unwrap();
    let px = pm.pixels_mut();
    for y in 4..n - 4 {
        for x in 4..n - 4 {
            if (x / 2 + y / 2) % 2 == 0 {
                px[(y * n + x) as usize] = black;
            }
        }
    }
    pm.save_png(dir.join("board.png")).unwrap();
    drop(pm);
    let (code, err, rss, took) = run_measured(
        dir,
        &[
            "reverse",
            "board.png",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--timeout",
            "0",
        ],
    );
    eprintln!(
        "8192² board: exit {code:?}, peak {} MiB, {:.1} s",
        rss >> 20,
        took.as_secs_f64()
    );
    assert!(rss < 1_000_000_000, "peak resident size {rss} bytes; {err}");
    // The largest loop is one 2×2 square: a contour of a few points, which
    // reverse subdivision refuses or reduces; either way it ran to the end
    // without running out of memory.
    assert!(matches!(code, Some(0) | Some(1)), "{code:?}: {err}");
    assert!(!err.contains("memory"), "{err}");
}
