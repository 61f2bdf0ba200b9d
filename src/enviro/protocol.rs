//! lpfg's text protocol with an environmental program, both directions.
//!
//! To the program (the file `.to_fieldKEY.0`), one block per
//! communication module, in the word's order:
//!
//! ```text
//! 17 E(0.500000)              id, then the values with `%f`
//!  P: 1.000000 0.000000 2.000000   one line per turtle field the .e asks for
//! Control: 5 0                     after the last block
//! ```
//!
//! (with `following module: on`, the module after it follows on the same
//! line: `17 E(0.500000)F(1.000000)`). From the program (`.from_fieldKEY.0`):
//! lines `ID E(v1,v2,…)` (the values with `%g`), then `Control: F`; the
//! flag 4 in F marks the last chunk. `Control: 9 0` tells the program to
//! exit.

use std::fmt::Write as _;

use crate::lang::cfmt;
use crate::lang::Value;
use crate::model::comm::CommSpec;
use crate::rewrite::environment::{Answer, Query};

/// The line that ends a block of queries.
pub const END_OF_QUERIES: &str = "Control: 5 0\n";
/// The block that asks the program to exit.
pub const EXIT: &str = "Control: 9 0\n";
/// The flag of the last chunk of an answer.
pub const LAST_CHUNK: i64 = 4;

/// A value as lpfg sends it: the module's `float`, printed with `%f`.
pub fn sent(v: f64) -> String {
    format!("{:.6}", v as f32)
}

/// A value as the program reads what lpfg sent: the `%f` text read back
/// into a `float` (what vlab's programs hold).
pub fn as_received(v: f64) -> f32 {
    round6(v as f32)
}

/// `x` printed with `%f` and read back as a `float`. For |x| < 1e9 without
/// formatting: x·10⁶ is exact in `f64` (24 bits times 20), rounded to an
/// integer with ties to even as `printf` rounds, and the six-decimal text
/// of that integer is read back.
pub fn round6(x: f32) -> f32 {
    if x.is_nan() || x.abs() >= 1e9 {
        return format!("{x:.6}").parse::<f32>().unwrap_or(f32::NAN);
    }
    let k = (x as f64 * 1e6).round_ties_even() as i64;
    let (int, frac) = (k.unsigned_abs() / 1_000_000, k.unsigned_abs() % 1_000_000);
    let mut buf = itoa::Buffer::new();
    let mut text = String::with_capacity(20);
    // printf writes the sign of a negative value that rounds to zero
    // (`-0.000000`), and of -0.
    if x.is_sign_negative() {
        text.push('-');
    }
    text.push_str(buf.format(int));
    text.push('.');
    let f = buf.format(frac);
    for _ in f.len()..6 {
        text.push('0');
    }
    text.push_str(f);
    text.parse::<f32>().unwrap_or(f32::NAN)
}

/// The turtle's position as a program reads it from lpfg's text: printed
/// with the `.e` file's format (three conversions) and read back as three
/// `float`s after the text before the first conversion, as vlab's
/// communication library reads it. `None` where nothing is sent or the
/// text does not read back.
pub fn position_as_read(spec: &CommSpec, position: [f64; 3]) -> Option<[f32; 3]> {
    let fmt = spec.position.as_deref()?;
    let skip = fmt.find('%').unwrap_or(0);
    if &fmt[skip..] == "%f %f %f" {
        return Some(position.map(|x| round6(x as f32)));
    }
    let line = cfmt::format(fmt, &position.map(|x| Value::Float(x as f32 as f64))).ok()?;
    let mut words = line.get(skip..)?.split_whitespace();
    let mut p = [0f32; 3];
    for v in &mut p {
        *v = words.next()?.parse::<f32>().ok()?;
    }
    Some(p)
}

/// The text of one step's queries, ending with [`END_OF_QUERIES`].
pub fn queries_text(spec: &CommSpec, queries: &[Query]) -> Result<String, String> {
    let mut out = String::new();
    for q in queries {
        let _ = write!(out, "{} E(", q.id);
        for (i, v) in q.values.iter().enumerate() {
            if i > 0 {
                out.push(',');
            }
            out.push_str(&sent(*v));
        }
        out.push(')');
        if spec.following {
            if let Some(f) = &q.following {
                out.push_str(&f.name);
                if !f.params.is_empty() {
                    out.push('(');
                    for (i, v) in f.params.iter().enumerate() {
                        if i > 0 {
                            out.push(',');
                        }
                        out.push_str(&sent(*v));
                    }
                    out.push(')');
                }
            }
        }
        out.push('\n');
        let fields = [
            (&spec.position, q.frame.position),
            (&spec.heading, q.frame.heading),
            (&spec.left, q.frame.left),
            (&spec.up, q.frame.up),
        ];
        for (fmt, v) in fields {
            if let Some(fmt) = fmt {
                // lpfg's turtle holds `float`s.
                let args = v.map(|x| Value::Float(x as f32 as f64));
                out.push_str(&cfmt::format(fmt, &args)?);
                out.push('\n');
            }
        }
    }
    out.push_str(END_OF_QUERIES);
    Ok(out)
}

/// One chunk of a program's answer: the answers, and whether it was the
/// last chunk.
#[derive(Clone, Debug, PartialEq)]
pub struct Chunk {
    pub answers: Vec<Answer>,
    pub last: bool,
}

/// Reads one chunk of answers. Lines before `Control:` are answers
/// (`ID E(v,…)`; a line `Dend` is passed over); an error names the line.
pub fn read_chunk(text: &str) -> Result<Chunk, String> {
    let mut answers = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim_end_matches('\r');
        let t = line.trim();
        if t.is_empty() || t == "Dend" {
            continue;
        }
        if let Some(rest) = t.strip_prefix("Control:") {
            let flag: i64 = rest
                .split_whitespace()
                .next()
                .and_then(|w| w.parse().ok())
                .ok_or_else(|| format!("line {}: `{line}`: expected `Control: FLAGS`", n + 1))?;
            return Ok(Chunk {
                answers,
                last: flag & LAST_CHUNK != 0,
            });
        }
        answers.push(parse_answer(t).map_err(|why| format!("line {}: `{line}`: {why}", n + 1))?);
    }
    Err("the answer ends without a `Control:` line".into())
}

/// `ID E(v1,v2,…)` (lpfg reads each value as C's `atof` does, into a
/// `float`).
pub fn parse_answer(line: &str) -> Result<Answer, String> {
    let digits = line.bytes().take_while(u8::is_ascii_digit).count();
    let id: u64 = line[..digits]
        .parse()
        .map_err(|_| "expected the module's number first".to_string())?;
    let rest = line[digits..].trim_start();
    let inner = rest
        .strip_prefix("E(")
        .and_then(|r| r.find(')').map(|end| &r[..end]))
        .ok_or_else(|| "expected `E(values)` after the number".to_string())?;
    let mut values = Vec::new();
    for w in inner.split(',') {
        let w = w.trim();
        if w.is_empty() {
            // A value the program left unset (`E(0.5,)`): lpfg's `atof`
            // of nothing, 0.
            values.push(0.0);
            continue;
        }
        let v: f32 = atof(w).ok_or_else(|| format!("`{w}` is not a number"))?;
        values.push(v as f64);
    }
    Ok(Answer { id, values })
}

/// The number at the start of `w`, as C's `atof` reads it (`1.5e3`,
/// `-0`, `inf`, `nan`); `None` when `w` does not start with one.
fn atof(w: &str) -> Option<f32> {
    let lower = w.to_ascii_lowercase();
    for (name, v) in [
        ("-inf", f32::NEG_INFINITY),
        ("inf", f32::INFINITY),
        ("+inf", f32::INFINITY),
        ("nan", f32::NAN),
        ("-nan", f32::NAN),
    ] {
        if lower.starts_with(name) {
            return Some(v);
        }
    }
    // The longest prefix that parses.
    (1..=w.len())
        .rev()
        .filter(|&k| w.is_char_boundary(k))
        .find_map(|k| w[..k].parse::<f64>().ok())
        .map(|v| v as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rewrite::environment::{Following, Frame};

    fn spec(following: bool) -> CommSpec {
        let mut s = CommSpec::read(
            std::path::Path::new("c.e"),
            "executable: prog\nturtle position: P: %f %f %f\nturtle heading: H: %g %g %g\n",
        )
        .unwrap();
        s.following = following;
        s
    }

    #[test]
    fn queries_are_written_as_lpfg_writes_them() {
        let q = Query {
            id: 17,
            values: vec![0.5, 2.0],
            following: Some(Following {
                name: "F".into(),
                params: vec![1.0],
            }),
            frame: Frame {
                position: [1.0, -0.1, 1e-8],
                heading: [0.0, 1.0, 0.0],
                ..Frame::default()
            },
        };
        assert_eq!(
            queries_text(&spec(false), std::slice::from_ref(&q)).unwrap(),
            "17 E(0.500000,2.000000)\n P: 1.000000 -0.100000 0.000000\n H: 0 1 0\nControl: 5 0\n"
        );
        assert!(queries_text(&spec(true), &[q])
            .unwrap()
            .starts_with("17 E(0.500000,2.000000)F(1.000000)\n"));
    }

    #[test]
    fn round6_is_printf_and_read_back() {
        // Ties (exact in binary) go to even, as glibc's printf rounds.
        for x in [
            0.0f32,
            -0.0,
            1.0,
            0.5,
            2.5e-7,
            7.5e-7,
            -2.5e-7,
            1e-7,
            123.45679,
            -0.1,
            3.0e8,
            16777215.0,
            0.3,
            1.2345675,
            9.999999e8,
            2e9,
            f32::INFINITY,
        ] {
            let want = format!("{x:.6}").parse::<f32>().unwrap();
            assert_eq!(round6(x).to_bits(), want.to_bits(), "{x}");
        }
        let mut s = 1u64;
        for _ in 0..100_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = f32::from_bits((s >> 32) as u32);
            if x.is_nan() {
                continue;
            }
            let want = format!("{x:.6}").parse::<f32>().unwrap();
            assert_eq!(round6(x).to_bits(), want.to_bits(), "{x:e}");
        }
    }

    #[test]
    fn answers_are_read_as_lpfg_reads_them() {
        let c = read_chunk("3 E(1)\n12 E(0.25,-1e-3)\nControl: 5\n").unwrap();
        assert!(c.last);
        assert_eq!(
            c.answers[0],
            Answer {
                id: 3,
                values: vec![1.0]
            }
        );
        assert_eq!(c.answers[1].values, vec![0.25, -1e-3f32 as f64]);
        let c = read_chunk("Control: 1\n").unwrap();
        assert!(!c.last && c.answers.is_empty());
        assert!(read_chunk("3 E(1)\n")
            .unwrap_err()
            .contains("without a `Control:`"));
        assert!(read_chunk("x E(1)\nControl: 5\n")
            .unwrap_err()
            .contains("line 1: `x E(1)`: expected the module's number"));
        assert!(read_chunk("4 E(one)\nControl: 5\n")
            .unwrap_err()
            .contains("`one` is not a number"));
    }
}
