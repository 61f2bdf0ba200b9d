//! What the readers share: errors about a file placed on a line and a
//! word of it, the lines of a text, UTF-8, comments, numbers and
//! positions.

use std::ops::Range;

use glam::DVec3;

use crate::mesh::soup::{MeshFileError, Place};

use super::raw::Raw;

/// An error about file `name`, at `line` where one applies, with nothing
/// to show on it (binary data, or the whole file at fault).
pub(super) fn error(name: &str, line: Option<usize>, message: impl Into<String>) -> MeshFileError {
    MeshFileError {
        path: name.to_string(),
        line,
        place: None,
        message: message.into(),
    }
}

/// A recorded line number as an optional one (0 means unknown).
pub(super) fn known(line: usize) -> Option<usize> {
    (line > 0).then_some(line)
}

/// A line of a text file (or of a PLY header): its 1-based number and its
/// text without the newline.
#[derive(Clone, Copy, Debug)]
pub(super) struct Line<'a> {
    pub(super) no: usize,
    pub(super) text: &'a str,
}

impl Line<'_> {
    /// An error about `part` of this line, a slice of its text (a word);
    /// about the whole statement where `part` is not one (a word of OBJ
    /// lines joined by a backslash).
    pub(super) fn at(&self, name: &str, part: &str, message: impl Into<String>) -> MeshFileError {
        let range = match offset_in(self.text, part) {
            Some(start) => start..start + part.len(),
            None => statement(self.text),
        };
        self.at_range(name, range, message)
    }

    /// An error about the whole statement on this line.
    pub(super) fn whole(&self, name: &str, message: impl Into<String>) -> MeshFileError {
        self.at_range(name, statement(self.text), message)
    }

    /// An error just after the last word of this line: where a file ends
    /// too early.
    pub(super) fn end(&self, name: &str, message: impl Into<String>) -> MeshFileError {
        let n = self.text.trim_end().len();
        self.at_range(name, n..n, message)
    }

    fn at_range(
        &self,
        name: &str,
        range: Range<usize>,
        message: impl Into<String>,
    ) -> MeshFileError {
        MeshFileError {
            path: name.to_string(),
            line: Some(self.no),
            place: Some(Place {
                text: self.text.to_string(),
                start: range.start,
                end: range.end,
            }),
            message: message.into(),
        }
    }
}

/// Where `part` starts in `text`, when it is a slice of it.
fn offset_in(text: &str, part: &str) -> Option<usize> {
    let start = (part.as_ptr() as usize).checked_sub(text.as_ptr() as usize)?;
    (start + part.len() <= text.len()).then_some(start)
}

/// The bytes of a line's statement: from its first word to its last one
/// before any comment.
fn statement(text: &str) -> Range<usize> {
    let body = strip_comment(text);
    let start = body.len() - body.trim_start().len();
    start..body.trim_end().len().max(start)
}

/// A text that a mesh was read from, for messages about its faces after
/// it is read: the text and the number of its first line.
#[derive(Clone, Copy)]
pub(super) struct Source<'a> {
    pub(super) text: &'a str,
    pub(super) first: usize,
}

impl<'a> Source<'a> {
    /// Line `no`, if the text holds it (a walk over the text, made for
    /// messages only).
    pub(super) fn line(&self, no: usize) -> Option<Line<'a>> {
        let text = self.text.lines().nth(no.checked_sub(self.first)?)?;
        Some(Line { no, text })
    }

    /// The last line: where a file that ends too early ends.
    pub(super) fn last(&self) -> Line<'a> {
        let (count, text) = self.text.lines().fold((0, ""), |(n, _), l| (n + 1, l));
        Line {
            no: (self.first + count).saturating_sub(1).max(1),
            text,
        }
    }
}

/// `bytes` as UTF-8 text (a leading byte-order mark dropped); `first_line`
/// is the line number the bytes start on.
pub(super) fn utf8<'a>(
    name: &str,
    bytes: &'a [u8],
    first_line: usize,
) -> Result<&'a str, MeshFileError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Err(e) => Err(not_text(
            name,
            bytes,
            e.valid_up_to(),
            first_line,
            "the file is not UTF-8 text (an invalid byte on this line)",
        )),
    }
}

/// An error at byte `bad` of `bytes`, the first byte that is not UTF-8;
/// `first_line` is the line number the bytes start on. The line is shown
/// with the invalid bytes as U+FFFD, the caret under the first.
pub(super) fn not_text(
    name: &str,
    bytes: &[u8],
    bad: usize,
    first_line: usize,
    message: &str,
) -> MeshFileError {
    let good = &bytes[..bad];
    let start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let end = bytes[bad..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |i| bad + i);
    let line = first_line + good.iter().filter(|&&b| b == b'\n').count();
    let text = String::from_utf8_lossy(&bytes[start..end]);
    // The bytes before `bad` are UTF-8, so they keep their offsets.
    let col = bad - start;
    MeshFileError {
        path: name.to_string(),
        line: Some(line),
        place: Some(Place {
            text: text.trim_end_matches('\r').to_string(),
            start: col,
            end: col + '\u{fffd}'.len_utf8(),
        }),
        message: message.to_string(),
    }
}

/// The part of `line` before any `#` comment.
pub(super) fn strip_comment(line: &str) -> &str {
    line.split('#').next().unwrap_or(line)
}

/// A number, or "expected a number, found `tok`" at it.
pub(super) fn parse_number(name: &str, line: &Line, tok: &str) -> Result<f64, MeshFileError> {
    tok.parse::<f64>()
        .map_err(|_| line.at(name, tok, format!("expected a number, found `{tok}`")))
}

/// A whole number that counts `what`.
pub(super) fn parse_count(
    name: &str,
    line: &Line,
    tok: &str,
    what: &str,
) -> Result<usize, MeshFileError> {
    tok.parse::<usize>().map_err(|_| {
        line.at(
            name,
            tok,
            format!("expected the number of {what}, found `{tok}`"),
        )
    })
}

/// A vertex index as written (no base applied).
pub(super) fn parse_index(name: &str, line: &Line, tok: &str) -> Result<i64, MeshFileError> {
    tok.parse::<i64>()
        .map_err(|_| line.at(name, tok, format!("expected a vertex index, found `{tok}`")))
}

/// A position from the first three of `toks` (further values are ignored);
/// `raw` numbers it in messages.
pub(super) fn parse_position<'a>(
    name: &str,
    line: &Line,
    mut toks: impl Iterator<Item = &'a str>,
    raw: &Raw,
) -> Result<DVec3, MeshFileError> {
    let found = [toks.next(), toks.next(), toks.next()];
    let [Some(x), Some(y), Some(z)] = found else {
        let n = found.iter().flatten().count();
        return Err(line.whole(
            name,
            format!("a vertex needs 3 coordinates (x y z), found {n}"),
        ));
    };
    let p = DVec3::new(
        parse_number(name, line, x)?,
        parse_number(name, line, y)?,
        parse_number(name, line, z)?,
    );
    if let Some(k) = (0..3).find(|&k| !p[k].is_finite()) {
        return Err(line.at(name, [x, y, z][k], raw.non_finite(raw.positions.len())));
    }
    Ok(p)
}
