//! A line reader for vlab's text formats: every word it hands out knows its
//! line and columns, so a malformed file is reported at `file:line:col`
//! with the line and a caret under the word at fault.

use super::error::ModelError as Error;

/// The largest model file read, in bytes. vlab's files are a few kilobytes;
/// a contour or a function with a million points is not a model's.
pub const MAX_MODEL_FILE_BYTES: u64 = 4 << 20;

/// The most control points one function or contour may have (the
/// editors' curves have a few dozen). Sampling costs grow with them: a
/// contour is measured at 1000 points per control point.
pub const MAX_POINTS: usize = 1_000;

/// The most control points (multiplicities counted), parameters or
/// patches one file may hold in all.
pub const MAX_FILE_POINTS: usize = 20_000;

/// Reads a model file whole, refusing one over [`MAX_MODEL_FILE_BYTES`].
pub fn read_bytes(path: &std::path::Path) -> Result<Vec<u8>, Error> {
    use std::io::Read;
    let io = |e| Error::read(path.to_path_buf(), e);
    let file = crate::files::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_MODEL_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_MODEL_FILE_BYTES {
        return Err(Error::file(
            path.display().to_string(),
            format!(
                "the file is larger than {} MiB, which no vlab editor writes",
                MAX_MODEL_FILE_BYTES >> 20
            ),
        ));
    }
    Ok(bytes)
}

/// Reads a model text file: its bytes as text (a byte that is not UTF-8
/// reads as U+FFFD: the formats are ASCII, and such a byte is then refused
/// where a word was expected).
pub fn read_text(path: &std::path::Path) -> Result<String, Error> {
    Ok(String::from_utf8_lossy(&read_bytes(path)?).into_owned())
}

/// One word of a line: its text and its byte range in the line.
#[derive(Clone, Copy, Debug)]
pub struct Word<'a> {
    pub text: &'a str,
    pub start: usize,
    pub end: usize,
}

/// A file's lines, read one after the other.
pub struct Lines<'a> {
    pub path: &'a str,
    lines: Vec<&'a str>,
    /// The lines as messages show them (the file's own text, where the
    /// parsed lines have comments blanked out).
    shown: Vec<&'a str>,
    /// The index of the next line.
    next: usize,
    /// Control points, parameters or patches read so far.
    points: usize,
}

/// The words of `line` with their ranges, split at blanks.
pub fn words(line: &str) -> Vec<Word<'_>> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in line.char_indices() {
        if c.is_whitespace() {
            if let Some(s) = start.take() {
                out.push(Word {
                    text: &line[s..i],
                    start: s,
                    end: i,
                });
            }
        } else if start.is_none() {
            start = Some(i);
        }
    }
    if let Some(s) = start {
        out.push(Word {
            text: &line[s..],
            start: s,
            end: line.len(),
        });
    }
    out
}

impl<'a> Lines<'a> {
    pub fn new(path: &'a str, text: &'a str) -> Lines<'a> {
        Lines::shown_as(path, text, text)
    }

    /// Lines of `parsed`, shown in messages as the same lines of `shown`
    /// (which has the same line breaks).
    pub fn shown_as(path: &'a str, parsed: &'a str, shown: &'a str) -> Lines<'a> {
        Lines {
            path,
            lines: parsed.lines().collect(),
            shown: shown.lines().collect(),
            next: 0,
            points: 0,
        }
    }

    /// Counts `n` more points (or parameters, or patches) of the file; an
    /// error at the line last read when the file holds more than
    /// [`MAX_FILE_POINTS`].
    pub fn spend(&mut self, n: usize, what: &str) -> Result<(), Error> {
        self.points += n;
        if self.points > MAX_FILE_POINTS {
            let len = self.current().trim_end().len();
            return Err(self.error_at(
                0,
                len,
                format!(
                    "the file holds more than {MAX_FILE_POINTS} {what}, more than a model file may"
                ),
            ));
        }
        Ok(())
    }

    /// The number (1-based) of the line last read.
    pub fn line_no(&self) -> usize {
        self.next
    }

    /// The line last read.
    pub fn current(&self) -> &'a str {
        self.next
            .checked_sub(1)
            .and_then(|i| self.lines.get(i))
            .copied()
            .unwrap_or("")
    }

    /// True when every line has been read, or only blank ones are left.
    pub fn at_end(&self) -> bool {
        self.lines[self.next.min(self.lines.len())..]
            .iter()
            .all(|l| l.trim().is_empty())
    }

    /// The next line that is not blank, or an error that says the file
    /// ends where `what` was expected.
    pub fn next_line(&mut self, what: &str) -> Result<&'a str, Error> {
        while self.next < self.lines.len() {
            let l = self.lines[self.next];
            self.next += 1;
            if !l.trim().is_empty() {
                return Ok(l);
            }
        }
        // The caret goes after the last word of the file.
        let message = format!("the file ends where {what} was expected");
        match self.lines.iter().rposition(|l| !l.trim().is_empty()) {
            Some(i) => {
                let n = self.lines[i].trim_end().len();
                let text = self.shown.get(i).copied().unwrap_or("");
                Err(Error::FileAt {
                    path: self.path.to_string(),
                    line: i + 1,
                    text: text.to_string(),
                    start: n,
                    end: n,
                    message,
                })
            }
            None => Err(Error::file(
                self.path,
                format!("the file is empty: {message}"),
            )),
        }
    }

    /// The next line without consuming it (blank lines skipped).
    pub fn peek(&self) -> Option<&'a str> {
        self.lines[self.next.min(self.lines.len())..]
            .iter()
            .find(|l| !l.trim().is_empty())
            .copied()
    }

    /// An error at bytes `start..end` of the line last read.
    pub fn error_at(&self, start: usize, end: usize, message: impl Into<String>) -> Error {
        let text = self
            .next
            .checked_sub(1)
            .and_then(|i| self.shown.get(i))
            .copied()
            .unwrap_or("");
        let (start, end) = if start >= text.len() {
            (text.len(), text.len())
        } else {
            (start, end.max(start + 1).min(text.len()))
        };
        Error::FileAt {
            path: self.path.to_string(),
            line: self.line_no(),
            text: text.to_string(),
            start,
            end,
            message: message.into(),
        }
    }

    /// An error under word `w` of the line last read.
    pub fn error(&self, w: Word<'_>, message: impl Into<String>) -> Error {
        self.error_at(w.start, w.end, message)
    }

    /// An error at the end of the line last read (a word is missing).
    pub fn error_at_end(&self, message: impl Into<String>) -> Error {
        let n = self.current().trim_end().len();
        self.error_at(n, n, message)
    }

    /// The next line, which must start with `key` (such as `points:`); the
    /// words after the key are returned.
    pub fn keyed(&mut self, key: &str) -> Result<Vec<Word<'a>>, Error> {
        let line = self.next_line(&format!("`{key}`"))?;
        let ws = words(line);
        let key_words: Vec<&str> = key.split_whitespace().collect();
        let n = key_words.len();
        let matches = ws.len() >= n
            && ws[..n]
                .iter()
                .zip(&key_words)
                .all(|(w, k)| w.text.eq_ignore_ascii_case(k));
        if !matches {
            let w = ws[0];
            return Err(self.error(w, format!("expected `{key}`, found `{}`", w.text)));
        }
        Ok(ws[n..].to_vec())
    }

    /// The text after `key` on the next line, which must start with it
    /// (`name: leaf_length`), trimmed.
    pub fn keyed_text(&mut self, key: &str) -> Result<(&'a str, usize), Error> {
        let ws = self.keyed(key)?;
        let line = self.current();
        match ws.first() {
            Some(w) => Ok((line[w.start..].trim_end(), w.start)),
            None => Ok(("", line.trim_end().len())),
        }
    }
}

/// Reads word `i` of `ws` as a number; `what` names it in messages.
pub fn number(lines: &Lines<'_>, ws: &[Word<'_>], i: usize, what: &str) -> Result<f64, Error> {
    let Some(w) = ws.get(i) else {
        return Err(lines.error_at_end(format!("expected {what} here, found the end of the line")));
    };
    match w.text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(lines.error(*w, format!("{what} must be a finite number"))),
        Err(_) => Err(lines.error(*w, format!("expected {what}, found `{}`", w.text))),
    }
}

/// Reads word `i` of `ws` as a whole number from `lo` to `hi`.
pub fn count(
    lines: &Lines<'_>,
    ws: &[Word<'_>],
    i: usize,
    what: &str,
    lo: i64,
    hi: i64,
) -> Result<i64, Error> {
    let Some(w) = ws.get(i) else {
        return Err(lines.error_at_end(format!("expected {what} here, found the end of the line")));
    };
    match w.text.parse::<i64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        Ok(v) => Err(lines.error(*w, format!("{what} must be from {lo} to {hi}, not {v}"))),
        Err(_) => Err(lines.error(
            *w,
            format!("expected {what} (a whole number), found `{}`", w.text),
        )),
    }
}

/// Refuses words after the `n` expected ones.
pub fn no_more(lines: &Lines<'_>, ws: &[Word<'_>], n: usize, what: &str) -> Result<(), Error> {
    match ws.get(n) {
        Some(w) => Err(lines.error(*w, format!("unexpected `{}` after {what}", w.text))),
        None => Ok(()),
    }
}
