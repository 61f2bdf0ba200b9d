//! C's standard input and output as L+C programs use it: `printf` (and
//! lpfg's `Printf`), `fprintf` to `stdout`, `stderr` or a file, `puts`,
//! `fopen`/`fclose`, and the string functions `strlen`, `strcmp`, and the
//! formatting behind `sprintf`, `snprintf`, `strcpy`, `strncpy`,
//! `strcat`, `strncat`. A string written into a declared `char` array
//! must fit there with its terminating NUL ([`IoFunc::Fit`]).
//!
//! The library prints nothing itself: what a program prints and the files
//! it writes are collected in a [`ProgramOutput`], which the caller (the
//! `subgram` binary) writes out. A program may open files for writing
//! only when the output allows it (`--allow-writes DIR`), and only at
//! relative paths that stay inside that folder; reading files is refused.

use std::sync::{Arc, Mutex};

use super::cfmt;
use super::value::Value;

/// The C library functions a program calls, as the interpreter runs them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IoFunc {
    /// `printf(fmt, ...)`: to standard output.
    Printf,
    /// `fprintf(f, fmt, ...)`.
    Fprintf,
    /// The string that `sprintf(buf, fmt, ...)` writes into `buf`.
    Format,
    /// `puts(s)`: `s` and a newline to standard output.
    Puts,
    /// `fputs(s, f)`.
    Fputs,
    Fopen,
    Fclose,
    Fflush,
    Strlen,
    Strcmp,
    /// `a` followed by `b`: what `strcat(a, b)` leaves in `a`.
    Concat,
    /// `a` followed by at most `n` characters of `b`: what
    /// `strncat(a, b, n)` leaves in `a`.
    Strncat,
    /// What `strncpy(a, b, n)` leaves in `a`: at most `n` characters of
    /// `b`. With three more arguments (`a`'s declared size, its name and
    /// declaration), a count past the size is refused: `strncpy` always
    /// writes `n` bytes, padding with NULs.
    Strncpy,
    /// What `snprintf(a, size, fmt, ...)` leaves in `a` (its arguments
    /// `a`, `size`, `fmt`, ...): the formatted text cut to `size - 1`
    /// characters; `a` unchanged when `size` is 0.
    Snprintf,
    /// Its first argument, a string that a C string function writes into
    /// a declared `char` array (or an array of such strings), when it
    /// fits there with its terminating NUL; the next arguments are the array's size, the function's name,
    /// the array's name and its declaration, for the error when it does
    /// not ([`overflow`]).
    Fit,
}

/// Where printed text goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    Stdout,
    Stderr,
}

/// The handle `stdout` names; `stderr` is the next one, files follow.
pub const STDOUT: i64 = 1;
pub const STDERR: i64 = 2;
const FIRST_FILE: i64 = 3;

/// A program may print, and write to files, this many bytes in all; past
/// it the run stops with a message (a runaway loop of `printf`s).
pub const MAX_OUTPUT_BYTES: usize = 256 << 20;

/// A program may open this many files in a run.
pub const MAX_FILES: usize = 1024;

/// What a program printed and the files it wrote, shared between the run
/// (which appends) and its caller (which writes it out). Clones share it.
#[derive(Clone, Debug, Default)]
pub struct ProgramOutput(Arc<Mutex<State>>);

#[derive(Debug, Default)]
struct State {
    text: Vec<(Stream, String)>,
    /// Files by path relative to the output folder, with their contents.
    files: Vec<(String, String)>,
    /// Open handles, from [`FIRST_FILE`] on: the file each writes to.
    handles: Vec<Option<usize>>,
    bytes: usize,
    writes_allowed: bool,
}

impl ProgramOutput {
    /// An output that refuses `fopen` for writing.
    pub fn new() -> ProgramOutput {
        ProgramOutput::default()
    }

    /// An output that lets the program write files (which the caller
    /// then writes under its `--allow-writes` folder).
    pub fn allowing_writes() -> ProgramOutput {
        let out = ProgramOutput::default();
        out.state().writes_allowed = true;
        out
    }

    /// Lets the program write files from now on.
    pub fn allow_writes(&self) {
        self.state().writes_allowed = true;
    }

    fn state(&self) -> std::sync::MutexGuard<'_, State> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The text printed so far, in order, each piece with its stream;
    /// taken, so the next call returns only what came after.
    pub fn take_text(&self) -> Vec<(Stream, String)> {
        std::mem::take(&mut self.state().text)
    }

    /// Appends a message of subgram's own to the standard error stream,
    /// among what the program printed (where lpfg prints its messages).
    pub fn message(&self, text: &str) {
        self.state().text.push((Stream::Stderr, text.to_string()));
    }

    /// The files the program wrote: paths relative to the output folder
    /// (checked to stay inside it) and contents.
    pub fn files(&self) -> Vec<(String, String)> {
        self.state().files.clone()
    }

    fn count(&self, st: &mut State, n: usize) -> Result<(), String> {
        st.bytes = st.bytes.saturating_add(n);
        if st.bytes > MAX_OUTPUT_BYTES {
            return Err(format!(
                "the program printed or wrote more than {} MiB; is a loop printing without end?",
                MAX_OUTPUT_BYTES >> 20
            ));
        }
        Ok(())
    }

    /// Appends `s` to the stream or file that handle `h` names.
    fn write(&self, h: i64, s: &str, what: &str) -> Result<(), String> {
        let mut st = self.state();
        self.count(&mut st, s.len())?;
        let stream = match h {
            STDOUT => Stream::Stdout,
            STDERR => Stream::Stderr,
            _ => {
                let file = usize::try_from(h - FIRST_FILE)
                    .ok()
                    .and_then(|k| st.handles.get(k).copied().flatten());
                let Some(file) = file else {
                    return Err(format!(
                        "`{what}` writes to a file that is not open (fopen failed, or it was closed)"
                    ));
                };
                st.files[file].1.push_str(s);
                return Ok(());
            }
        };
        match st.text.last_mut() {
            Some((last, text)) if *last == stream => text.push_str(s),
            _ => st.text.push((stream, s.to_string())),
        }
        Ok(())
    }

    fn open(&self, name: &str, mode: &str) -> Result<i64, String> {
        let mut st = self.state();
        if mode.starts_with('r') {
            return Err(format!(
                "fopen(\"{name}\", \"{mode}\"): reading files from a program is not supported"
            ));
        }
        if !(mode.starts_with('w') || mode.starts_with('a')) {
            return Err(format!(
                "fopen(\"{name}\", \"{mode}\"): the mode must be \"w\" or \"a\""
            ));
        }
        if !st.writes_allowed {
            return Err(format!(
                "fopen(\"{name}\", \"{mode}\") writes a file, which a program may do only when \
                 subgram runs with `--allow-writes DIR` (the file then goes under DIR)"
            ));
        }
        let path = std::path::Path::new(name);
        let inside = !name.is_empty()
            && path.components().all(|c| {
                matches!(
                    c,
                    std::path::Component::Normal(_) | std::path::Component::CurDir
                )
            });
        if !inside {
            return Err(format!(
                "fopen(\"{name}\"): a program may write only inside the --allow-writes folder: \
                 the path must be relative, without `..`"
            ));
        }
        // The path must name a file that can be made: its last part a
        // name (not `.` or a trailing `/`), no NUL byte, no part longer
        // than a file system allows.
        let names_a_file = !matches!(name.rsplit('/').next(), Some("" | "." | ".."));
        if !names_a_file || name.contains('\0') || name.split('/').any(|c| c.len() > 255) {
            return Err(format!(
                "fopen(\"{}\"): the path does not name a file that can be written (it ends \
                 in `/` or `.`, holds a NUL byte, or has a part longer than 255 bytes)",
                name.escape_debug()
            ));
        }
        let file = match st.files.iter().position(|(p, _)| p == name) {
            Some(i) => {
                if mode.starts_with('w') {
                    st.files[i].1.clear();
                }
                i
            }
            None => {
                if st.files.len() >= MAX_FILES {
                    return Err(format!("the program opens more than {MAX_FILES} files"));
                }
                st.files.push((name.to_string(), String::new()));
                st.files.len() - 1
            }
        };
        st.handles.push(Some(file));
        Ok(FIRST_FILE + st.handles.len() as i64 - 1)
    }

    fn close(&self, h: i64) -> i64 {
        let mut st = self.state();
        match usize::try_from(h - FIRST_FILE)
            .ok()
            .and_then(|k| st.handles.get_mut(k))
        {
            Some(slot @ Some(_)) => {
                *slot = None;
                0
            }
            // C's EOF.
            _ => -1,
        }
    }
}

fn text(v: &Value) -> std::borrow::Cow<'_, str> {
    match v {
        Value::Str(s) => std::borrow::Cow::Borrowed(&**s),
        other => std::borrow::Cow::Owned(other.to_string()),
    }
}

/// Runs `f` on checked arguments; an error says what went wrong, for the
/// interpreter to report at the call.
pub fn call(f: IoFunc, args: &[Value], out: &ProgramOutput) -> Result<Value, String> {
    let arg = |i: usize| args.get(i).cloned().unwrap_or(Value::Void);
    Ok(match f {
        IoFunc::Printf => {
            let s = cfmt::format(&text(&arg(0)), &args[1.min(args.len())..])?;
            out.write(STDOUT, &s, "printf")?;
            Value::Int(s.len() as i64)
        }
        IoFunc::Fprintf => {
            let s = cfmt::format(&text(&arg(1)), &args[2.min(args.len())..])?;
            out.write(arg(0).as_i64(), &s, "fprintf")?;
            Value::Int(s.len() as i64)
        }
        IoFunc::Format => {
            let s = cfmt::format(&text(&arg(0)), &args[1.min(args.len())..])?;
            if s.len() > MAX_OUTPUT_BYTES {
                return Err("sprintf makes a string longer than the output limit".into());
            }
            Value::Str(s.into())
        }
        IoFunc::Puts => {
            out.write(STDOUT, &format!("{}\n", text(&arg(0))), "puts")?;
            Value::Int(0)
        }
        IoFunc::Fputs => {
            out.write(arg(1).as_i64(), &text(&arg(0)), "fputs")?;
            Value::Int(0)
        }
        IoFunc::Fopen => Value::Int(out.open(&text(&arg(0)), &text(&arg(1)))?),
        IoFunc::Fclose => Value::Int(out.close(arg(0).as_i64())),
        IoFunc::Fflush => Value::Int(0),
        IoFunc::Strlen => Value::Int(text(&arg(0)).len() as i64),
        IoFunc::Strcmp => Value::Int(match text(&arg(0)).cmp(&text(&arg(1))) {
            std::cmp::Ordering::Less => -1,
            std::cmp::Ordering::Equal => 0,
            std::cmp::Ordering::Greater => 1,
        }),
        IoFunc::Concat => {
            let s = format!("{}{}", text(&arg(0)), text(&arg(1)));
            if s.len() > MAX_OUTPUT_BYTES {
                return Err("strcat makes a string longer than the output limit".into());
            }
            Value::Str(s.into())
        }
        IoFunc::Strncat => {
            let n = count(&arg(2), "strncat's count")?;
            let s = format!("{}{}", text(&arg(0)), prefix(&text(&arg(1)), n));
            if s.len() > MAX_OUTPUT_BYTES {
                return Err("strncat makes a string longer than the output limit".into());
            }
            Value::Str(s.into())
        }
        IoFunc::Strncpy => {
            let n = count(&arg(1), "strncpy's count")?;
            if args.len() > 2 {
                let size = arg(2).as_i64().max(0) as usize;
                if n > size {
                    return Err(format!(
                        "strncpy writes {n} bytes into `{}` (it always writes its count, padding \
                         with NULs), declared `{}` (room for {size} bytes)",
                        text(&arg(3)),
                        text(&arg(4))
                    ));
                }
            }
            Value::Str(prefix(&text(&arg(0)), n).into())
        }
        IoFunc::Snprintf => {
            let size = count(&arg(1), "snprintf's size")?;
            if size == 0 {
                // Nothing is written: `a` keeps its string.
                return Ok(arg(0));
            }
            let s = cfmt::format(&text(&arg(2)), &args[3.min(args.len())..])?;
            Value::Str(prefix(&s, size - 1).into())
        }
        IoFunc::Fit => {
            let s = arg(0);
            let size = arg(1).as_i64().max(0) as usize;
            if let Some(m) = overflow_in(&text(&arg(2)), &s, size, &text(&arg(3)), &text(&arg(4))) {
                return Err(m);
            }
            s
        }
    })
}

/// A count or size given to a C string function (`strncpy`'s `n`): C's
/// `size_t`, so a negative one is refused.
fn count(v: &Value, what: &str) -> Result<usize, String> {
    let n = v.as_i64();
    usize::try_from(n).map_err(|_| format!("{what} is negative ({n})"))
}

/// The first `n` bytes of `s` (fewer where the `n`th falls inside a
/// character of several bytes).
fn prefix(s: &str, n: usize) -> &str {
    if n >= s.len() {
        return s;
    }
    let mut end = n;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

/// [`overflow`] for every string in `v`: an array of `char` arrays
/// (`char names[3][16]`) is checked string by string.
pub fn overflow_in(what: &str, v: &Value, size: usize, name: &str, decl: &str) -> Option<String> {
    match v {
        Value::Str(s) => overflow(what, s, size, name, decl),
        Value::Struct(vs) => vs
            .iter()
            .find_map(|v| overflow_in(what, v, size, name, decl)),
        _ => None,
    }
}

/// The error when `what` (`sprintf`, `` `fill` ``) writes `s` and its
/// terminating NUL into `name`, a `char` array declared `decl` with
/// `size` bytes, and they do not fit; `None` when they do.
pub fn overflow(what: &str, s: &str, size: usize, name: &str, decl: &str) -> Option<String> {
    let len = s.len();
    if len < size {
        return None;
    }
    let chars = |n: usize| {
        if n == 1 {
            "1 character".to_string()
        } else {
            format!("{n} characters")
        }
    };
    Some(format!(
        "{what} writes {} and the terminating NUL into `{name}`, declared `{decl}` (room for {})",
        chars(len),
        chars(size.saturating_sub(1))
    ))
}

/// A string literal's text with C's escapes (`\n`, `\t`, `\\`, `\"`,
/// `\0`…) replaced by the characters they stand for.
pub fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('n') => out.push('\n'),
            Some('t') => out.push('\t'),
            Some('r') => out.push('\r'),
            Some('0') => out.push('\0'),
            Some('a') => out.push('\x07'),
            Some('b') => out.push('\x08'),
            Some('f') => out.push('\x0c'),
            Some('v') => out.push('\x0b'),
            Some(other) => out.push(other),
            None => out.push('\\'),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn printed_text_keeps_its_order_and_stream() {
        let out = ProgramOutput::new();
        let s = |t: &str| Value::Str(t.into());
        call(IoFunc::Printf, &[s("a=%d\n"), Value::Int(1)], &out).unwrap();
        call(IoFunc::Fprintf, &[Value::Int(STDERR), s("e\n")], &out).unwrap();
        call(IoFunc::Puts, &[s("b")], &out).unwrap();
        assert_eq!(
            out.take_text(),
            vec![
                (Stream::Stdout, "a=1\n".to_string()),
                (Stream::Stderr, "e\n".to_string()),
                (Stream::Stdout, "b\n".to_string())
            ]
        );
        assert!(out.take_text().is_empty());
    }

    #[test]
    fn files_need_permission_and_stay_inside() {
        let s = |t: &str| Value::Str(t.into());
        let refused = call(IoFunc::Fopen, &[s("x.txt"), s("w")], &ProgramOutput::new());
        assert!(refused.unwrap_err().contains("--allow-writes"));
        let out = ProgramOutput::allowing_writes();
        for bad in ["../x", "/tmp/x", "a/../../x", ""] {
            let e = call(IoFunc::Fopen, &[s(bad), s("w")], &out).unwrap_err();
            assert!(e.contains("inside"), "{bad}: {e}");
        }
        let h = call(IoFunc::Fopen, &[s("d/x.txt"), s("w")], &out).unwrap();
        call(IoFunc::Fprintf, &[h.clone(), s("%d;"), Value::Int(5)], &out).unwrap();
        assert_eq!(
            call(IoFunc::Fclose, std::slice::from_ref(&h), &out).unwrap(),
            Value::Int(0)
        );
        let after = call(IoFunc::Fprintf, &[h, s("late")], &out).unwrap_err();
        assert!(after.contains("not open"));
        assert_eq!(out.files(), vec![("d/x.txt".to_string(), "5;".to_string())]);
        let r = call(IoFunc::Fopen, &[s("x.txt"), s("r")], &out).unwrap_err();
        assert!(r.contains("reading"));
    }

    #[test]
    fn the_n_forms_cut_and_a_declared_array_takes_what_fits() {
        let out = ProgramOutput::new();
        let s = |t: &str| Value::Str(t.into());
        let n = |k: i64| Value::Int(k);
        assert_eq!(
            call(IoFunc::Strncpy, &[s("abcdef"), n(3)], &out).unwrap(),
            s("abc")
        );
        assert_eq!(
            call(IoFunc::Strncat, &[s("ab"), s("cdef"), n(9)], &out).unwrap(),
            s("abcdef")
        );
        assert_eq!(
            call(
                IoFunc::Snprintf,
                &[s("old"), n(4), s("%d"), n(123456)],
                &out
            )
            .unwrap(),
            s("123")
        );
        // A size of 0 writes nothing.
        assert_eq!(
            call(IoFunc::Snprintf, &[s("old"), n(0), s("%d"), n(1)], &out).unwrap(),
            s("old")
        );
        let e = call(IoFunc::Strncpy, &[s("ab"), n(-1)], &out).unwrap_err();
        assert!(e.contains("negative"), "{e}");
        // A cut does not split a character of several bytes.
        assert_eq!(prefix("aé", 2), "a");
        let fit = |t: &str, size: i64| {
            call(
                IoFunc::Fit,
                &[s(t), n(size), s("strcpy"), s("b"), s("char b[4]")],
                &out,
            )
        };
        assert_eq!(fit("abc", 4).unwrap(), s("abc"));
        assert_eq!(
            fit("abcd", 4).unwrap_err(),
            "strcpy writes 4 characters and the terminating NUL into `b`, declared \
             `char b[4]` (room for 3 characters)"
        );
        assert_eq!(
            overflow("sprintf", "a", 1, "b", "char b[1]").unwrap(),
            "sprintf writes 1 character and the terminating NUL into `b`, declared \
             `char b[1]` (room for 0 characters)"
        );
    }

    #[test]
    fn escapes() {
        assert_eq!(unescape(r#"a\tb\n\\ \"q\""#), "a\tb\n\\ \"q\"");
    }
}
