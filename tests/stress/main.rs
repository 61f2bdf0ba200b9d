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
// The child is waited for by `wait4`, which clippy does not see.
#[allow(clippy::zombie_processes)]
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
    let n = 8192usize;
    // A 1-bit grey PNG written here (8 MiB, small beside the tracer's
    // memory, so that the child's peak is its own): white, with 2-pixel
    // black squares everywhere but a 4-pixel frame.
    write_image(&dir.join("board.png"), n, |x, y| {
        let inside = (4..n - 4).contains(&x) && (4..n - 4).contains(&y);
        inside && (x / 2 + y / 2) % 2 == 0
    });
    let (code, err, rss) = trace(dir, "board.png", "board");
    assert!(rss < 1_000_000_000, "peak resident size {rss} bytes; {err}");
    assert!(!err.contains("input size limit"), "{err}");
    // The largest loop is one 2×2 square: a contour of a few points, which
    // reverse subdivision refuses or reduces; either way it ran to the end
    // without running out of memory.
    assert!(matches!(code, Some(0) | Some(1)), "{code:?}: {err}");
    assert!(!err.contains("memory"), "{err}");
}

/// The other worst case: one black serpentine (2-pixel rows joined at
/// alternate ends) whose single outline runs through the whole image,
/// about 33 million points. The tracer keeps no loop's points but the
/// largest's, and refuses an outline past `MAX_CONTOUR_POINTS`: the peak
/// stays under 1 GB too.
#[test]
fn tracing_one_endless_8192_outline_stays_under_1_gb() {
    let tmp = tempfile::Builder::new()
        .prefix("subgram-stress-")
        .tempdir()
        .unwrap();
    let dir = tmp.path();
    let n = 8192usize;
    let black = |x: usize, y: usize| -> bool {
        if !(8..n - 8).contains(&x) || !(8..n - 8).contains(&y) {
            return false;
        }
        let (band, row) = ((y - 8) / 4, (y - 8) % 4);
        if row < 2 {
            return true;
        }
        // The joint to the next band: right for even bands, left for odd.
        if band % 2 == 0 {
            x >= n - 10
        } else {
            x < 10
        }
    };
    write_image(&dir.join("snake.png"), n, black);
    let (code, err, rss) = trace(dir, "snake.png", "serpentine");
    assert!(rss < 1_000_000_000, "peak resident size {rss} bytes; {err}");
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("points, more than the 8388608 a traced contour may have"),
        "{err}"
    );
}

/// Traces `image` (`reverse -n 1`, no time limit) and reports the exit
/// code, standard error and peak resident size, printing them with `label`.
fn trace(dir: &Path, image: &str, label: &str) -> (Option<i32>, String, u64) {
    let args = [
        "reverse",
        image,
        "-n",
        "1",
        "-o",
        "out.csv",
        "--timeout",
        "0",
    ];
    let (code, err, rss, took) = run_measured(dir, &args);
    eprintln!(
        "8192² {label}: exit {code:?}, peak {} MiB, {:.1} s: {err}",
        rss >> 20,
        took.as_secs_f64()
    );
    (code, err, rss)
}

/// Writes an `n`×`n` 1-bit PNG, black where `black(x, y)`.
fn write_image(path: &Path, n: usize, black: impl Fn(usize, usize) -> bool) {
    let mut raw = Vec::with_capacity(n * (n / 8 + 1));
    for y in 0..n {
        raw.push(0); // no filter
        for byte in 0..n / 8 {
            let mut b = 0u8;
            for bit in 0..8 {
                if !black(byte * 8 + bit, y) {
                    b |= 0x80 >> bit;
                }
            }
            raw.push(b);
        }
    }
    std::fs::write(path, png_1bit(n as u32, &raw)).unwrap();
}

/// A PNG of `n`×`n` 1-bit grey pixels from its filtered rows, its image
/// data in stored (uncompressed) deflate blocks.
fn png_1bit(n: u32, raw: &[u8]) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    fn chunk(out: &mut Vec<u8>, kind: &[u8], data: &[u8]) {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let start = out.len();
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
        let crc = crc32(&out[start..]);
        out.extend_from_slice(&crc.to_be_bytes());
    }
    let mut zlib = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = raw.chunks(65_535).collect();
    for (k, b) in blocks.iter().enumerate() {
        zlib.push(u8::from(k + 1 == blocks.len()));
        let len = b.len() as u16;
        zlib.extend_from_slice(&len.to_le_bytes());
        zlib.extend_from_slice(&(!len).to_le_bytes());
        zlib.extend_from_slice(b);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &x in raw {
        a = (a + x as u32) % 65_521;
        b = (b + a) % 65_521;
    }
    zlib.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&n.to_be_bytes());
    ihdr.extend_from_slice(&n.to_be_bytes());
    ihdr.extend_from_slice(&[1, 0, 0, 0, 0]); // 1 bit, grey
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &zlib);
    chunk(&mut out, b"IEND", &[]);
    out
}
