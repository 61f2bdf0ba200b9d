//! The one golden-file check: an output is compared with an expectation
//! file kept in the repository; with `UPDATE_GOLDEN=1` in the environment,
//! an expectation that does not match is rewritten from the output instead
//! (and one that matches is left alone, so reruns do not churn files).
//!
//! A missing expectation file is a failure, never a silent pass: write it
//! with `UPDATE_GOLDEN=1`, look at it, and say in its folder's README where
//! its values come from (a file the program wrote itself is a regression
//! check only; an independent value belongs in an ordinary test).
//!
//! Three kinds of comparison ([`Kind`]):
//!
//! * [`Kind::Exact`]: text, byte for byte (diagnostics, counts).
//! * [`Kind::Numeric`]: text holding floating-point numbers. Writers put
//!   every float through [`round`]: 10 significant digits (a relative
//!   rounding of at most 5e-11), and magnitudes below 1e-12 written as 0, so
//!   that the files read well and last-bit differences between machines
//!   vanish. Because a value that sits on a rounding boundary can still fall
//!   the other way on another machine, the comparison does not stop at the
//!   text: both texts are split into numbers and the rest; the rest must be
//!   equal, integers (written without `.` or an exponent) must be equal, and
//!   two floats `a`, `b` must agree within `1e-9 * max(1, |a|, |b|)`.
//! * [`Kind::Png`]: pictures that a person looked at: the same size, fewer
//!   than 1 pixel in 200 off by more than 64 in a channel, and a mean
//!   difference under 2 (antialiasing may differ between versions of the
//!   rasteriser).

// Each test binary that includes this file uses its own part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Exact,
    Numeric,
    Png,
}

/// Whether `UPDATE_GOLDEN` asks for expectations to be rewritten.
pub fn updating() -> bool {
    std::env::var("UPDATE_GOLDEN").is_ok_and(|v| !v.is_empty() && v != "0")
}

/// `path` inside the project when it is relative.
fn in_project(path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)
    }
}

/// Compares `actual` with the expectation at `path` (relative to the
/// project root, or absolute); with `UPDATE_GOLDEN=1`, rewrites a missing or
/// differing expectation and succeeds. The error says what differs.
pub fn compare(path: impl AsRef<Path>, actual: &[u8], kind: Kind) -> Result<(), String> {
    let shown = path.as_ref().display().to_string();
    let path = in_project(path.as_ref());
    let outcome = match std::fs::read(&path) {
        Ok(want) => match kind {
            Kind::Exact => compare_exact(&want, actual),
            Kind::Numeric => compare_numeric(&want, actual),
            Kind::Png => compare_png(&want, actual),
        },
        Err(e) => Err(format!("cannot read the expectation: {e}")),
    };
    match outcome {
        Ok(()) => Ok(()),
        Err(_) if updating() => {
            if let Some(dir) = path.parent() {
                std::fs::create_dir_all(dir).map_err(|e| format!("{shown}: {e}"))?;
            }
            std::fs::write(&path, actual).map_err(|e| format!("{shown}: {e}"))?;
            eprintln!("UPDATE_GOLDEN: rewrote {shown}");
            Ok(())
        }
        Err(why) => Err(format!(
            "{shown}: {why}\n(if the new output is right, rerun with UPDATE_GOLDEN=1 to rewrite \
             the expectation, and look at the diff)"
        )),
    }
}

/// [`compare`], panicking with its message.
pub fn check(path: impl AsRef<Path>, actual: &[u8], kind: Kind) {
    if let Err(e) = compare(path, actual, kind) {
        panic!("{e}");
    }
}

/// Panics with every message when any comparison of a batch failed; a batch
/// reports all its differences at once rather than the first.
pub fn assert_all(failures: Vec<String>) {
    if !failures.is_empty() {
        panic!(
            "{} golden file(s) differ:\n\n{}",
            failures.len(),
            failures.join("\n\n")
        );
    }
}

/// `x` to 10 significant digits, with magnitudes below 1e-12 as 0 (and no
/// negative zero); infinities and NaN unchanged.
pub fn round(x: f64) -> f64 {
    if !x.is_finite() {
        return x;
    }
    if x.abs() < 1e-12 {
        return 0.0;
    }
    format!("{x:.9e}")
        .parse()
        .expect("a formatted float parses")
}

/// A JSON value with every float put through [`round`].
pub fn round_json(v: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Number(n) if n.is_f64() => {
            let r = round(n.as_f64().unwrap());
            serde_json::Number::from_f64(r).map_or(Value::Null, Value::Number)
        }
        Value::Array(a) => Value::Array(a.iter().map(round_json).collect()),
        Value::Object(o) => {
            Value::Object(o.iter().map(|(k, v)| (k.clone(), round_json(v))).collect())
        }
        other => other.clone(),
    }
}

/// JSON laid out for line diffs: a top-level object gets one key per line,
/// and an array under such a key one element per line; anything deeper is
/// compact. Floats are rounded with [`round`]. The result is valid JSON.
pub fn json_lines(v: &serde_json::Value) -> String {
    use serde_json::Value;
    let v = round_json(v);
    let compact = |v: &Value| serde_json::to_string(v).unwrap();
    let Value::Object(o) = &v else {
        return compact(&v) + "\n";
    };
    let mut out = String::from("{\n");
    for (i, (k, val)) in o.iter().enumerate() {
        out += &format!("{}: ", compact(&Value::String(k.clone())));
        match val {
            Value::Array(a) if !a.is_empty() => {
                out += "[\n";
                for (j, x) in a.iter().enumerate() {
                    out += &compact(x);
                    out += if j + 1 < a.len() { ",\n" } else { "\n" };
                }
                out += "]";
            }
            other => out += &compact(other),
        }
        out += if i + 1 < o.len() { ",\n" } else { "\n" };
    }
    out + "}\n"
}

fn first_difference(want: &str, got: &str) -> String {
    let (w, g): (Vec<&str>, Vec<&str>) = (want.lines().collect(), got.lines().collect());
    let at = (0..w.len().max(g.len()))
        .find(|&i| w.get(i) != g.get(i))
        .unwrap_or(0);
    let clip = |s: Option<&&str>| match s {
        None => "(no line)".to_string(),
        Some(s) if s.chars().count() > 300 => s.chars().take(300).collect::<String>() + "…",
        Some(s) => s.to_string(),
    };
    format!(
        "first difference at line {} of {} expected, {} actual:\n  expected: {}\n    actual: {}",
        at + 1,
        w.len(),
        g.len(),
        clip(w.get(at)),
        clip(g.get(at))
    )
}

fn utf8(bytes: &[u8], what: &str) -> Result<String, String> {
    String::from_utf8(bytes.to_vec()).map_err(|_| format!("the {what} is not UTF-8 text"))
}

fn compare_exact(want: &[u8], got: &[u8]) -> Result<(), String> {
    if want == got {
        return Ok(());
    }
    let (want, got) = (utf8(want, "expectation")?, utf8(got, "output")?);
    Err(first_difference(&want, &got))
}

/// A piece of text: a number (kept as written) or a run of anything else.
#[derive(Debug, PartialEq)]
pub enum Token<'a> {
    Number(&'a str),
    Other(&'a str),
}

/// Splits text into numbers (`-?digits[.digits][e[+-]digits]`) and the
/// runs between them.
pub fn tokens(s: &str) -> Vec<Token<'_>> {
    let b = s.as_bytes();
    let digits = |mut i: usize| {
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    let mut out = Vec::new();
    let (mut i, mut other) = (0, 0);
    while i < b.len() {
        let start = i;
        let mut j = if b[i] == b'-' { i + 1 } else { i };
        if j < b.len() && b[j].is_ascii_digit() {
            j = digits(j);
            if j + 1 < b.len() && b[j] == b'.' && b[j + 1].is_ascii_digit() {
                j = digits(j + 1);
            }
            if j < b.len() && (b[j] == b'e' || b[j] == b'E') {
                let mut k = j + 1;
                if k < b.len() && (b[k] == b'+' || b[k] == b'-') {
                    k += 1;
                }
                if k < b.len() && b[k].is_ascii_digit() {
                    j = digits(k);
                }
            }
            if other < start {
                out.push(Token::Other(&s[other..start]));
            }
            out.push(Token::Number(&s[start..j]));
            i = j;
            other = j;
        } else {
            i += 1;
        }
    }
    if other < b.len() {
        out.push(Token::Other(&s[other..]));
    }
    out
}

fn is_integer(n: &str) -> bool {
    !n.contains(['.', 'e', 'E'])
}

fn numbers_agree(a: &str, b: &str) -> bool {
    if a == b {
        return true;
    }
    if is_integer(a) || is_integer(b) {
        return false;
    }
    match (a.parse::<f64>(), b.parse::<f64>()) {
        (Ok(x), Ok(y)) => (x - y).abs() <= 1e-9 * x.abs().max(y.abs()).max(1.0),
        _ => false,
    }
}

pub fn compare_numeric(want: &[u8], got: &[u8]) -> Result<(), String> {
    if want == got {
        return Ok(());
    }
    let (want, got) = (utf8(want, "expectation")?, utf8(got, "output")?);
    let (wl, gl): (Vec<&str>, Vec<&str>) = (want.lines().collect(), got.lines().collect());
    if wl.len() != gl.len() {
        return Err(first_difference(&want, &got));
    }
    for (i, (w, g)) in wl.iter().zip(&gl).enumerate() {
        let (wt, gt) = (tokens(w), tokens(g));
        let same = wt.len() == gt.len()
            && wt.iter().zip(&gt).all(|pair| match pair {
                (Token::Number(a), Token::Number(b)) => numbers_agree(a, b),
                (a, b) => a == b,
            });
        if !same {
            return Err(format!(
                "line {} differs beyond 1e-9 relative:\n  expected: {w}\n    actual: {g}",
                i + 1
            ));
        }
    }
    Ok(())
}

fn compare_png(want: &[u8], got: &[u8]) -> Result<(), String> {
    let want = tiny_skia::Pixmap::decode_png(want)
        .map_err(|e| format!("the expectation is not a PNG: {e}"))?;
    let got =
        tiny_skia::Pixmap::decode_png(got).map_err(|e| format!("the output is not a PNG: {e}"))?;
    if (got.width(), got.height()) != (want.width(), want.height()) {
        return Err(format!(
            "size {}x{}, expected {}x{}",
            got.width(),
            got.height(),
            want.width(),
            want.height()
        ));
    }
    let mut total = 0u64;
    let mut far = 0usize;
    for (a, b) in got.pixels().iter().zip(want.pixels()) {
        let m = [
            a.red().abs_diff(b.red()),
            a.green().abs_diff(b.green()),
            a.blue().abs_diff(b.blue()),
        ]
        .into_iter()
        .max()
        .unwrap();
        total += m as u64;
        if m > 64 {
            far += 1;
        }
    }
    let n = got.pixels().len();
    let mean = total as f64 / n as f64;
    if far * 200 >= n {
        return Err(format!("{far} of {n} pixels differ by more than 64"));
    }
    if mean >= 2.0 {
        return Err(format!("mean difference {mean}"));
    }
    Ok(())
}
