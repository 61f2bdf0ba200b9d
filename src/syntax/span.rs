//! Source files, byte spans and the `file:line:col` rendering of diagnostics.

use std::fmt;

/// Index of a file inside a [`SourceMap`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct FileId(pub u32);

/// A half-open byte range `start..end` inside one source file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct Span {
    pub file: FileId,
    pub start: u32,
    pub end: u32,
}

impl Span {
    pub fn new(file: FileId, start: usize, end: usize) -> Span {
        Span {
            file,
            start: start as u32,
            end: end as u32,
        }
    }

    /// The smallest span covering both `self` and `other` (same file assumed).
    pub fn to(self, other: Span) -> Span {
        if self.file != other.file {
            return self;
        }
        Span {
            file: self.file,
            start: self.start.min(other.start),
            end: self.end.max(other.end),
        }
    }
}

/// One loaded source text with its display name.
#[derive(Clone, Debug)]
pub struct SourceFile {
    pub name: String,
    pub text: String,
    line_starts: Vec<usize>,
    /// Every character is one byte: a column is a byte count.
    ascii: bool,
}

impl SourceFile {
    pub fn new(name: impl Into<String>, text: impl Into<String>) -> SourceFile {
        let text = text.into();
        let mut line_starts = vec![0];
        for (i, b) in text.bytes().enumerate() {
            if b == b'\n' {
                line_starts.push(i + 1);
            }
        }
        SourceFile {
            name: name.into(),
            ascii: text.is_ascii(),
            text,
            line_starts,
        }
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = self.boundary(offset);
        let line = match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.line_starts[line];
        let col = if self.ascii {
            offset - start
        } else {
            self.text[start..offset].chars().count()
        };
        (line + 1, col + 1)
    }

    /// `offset` within the text, moved back to a character boundary.
    fn boundary(&self, offset: usize) -> usize {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        offset
    }

    /// The text of 1-based line `line`, without its newline.
    pub fn line_text(&self, line: usize) -> &str {
        let start = self.line_starts[line - 1];
        let end = self
            .line_starts
            .get(line)
            .copied()
            .unwrap_or(self.text.len());
        self.text[start..end].trim_end_matches(['\n', '\r'])
    }
}

/// All texts a program was built from: the `.lsys` file and `-D` overrides.
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: Vec<SourceFile>,
}

impl SourceMap {
    pub fn add(&mut self, file: SourceFile) -> FileId {
        self.files.push(file);
        FileId(self.files.len() as u32 - 1)
    }

    pub fn get(&self, id: FileId) -> &SourceFile {
        &self.files[id.0 as usize]
    }

    /// The names of the texts, in the order they were added.
    pub fn names(&self) -> impl Iterator<Item = &str> + '_ {
        self.files.iter().map(|f| f.name.as_str())
    }

    /// Every diagnostic rendered as [`SourceMap::render`] does, a blank
    /// line between two. A diagnostic that renders as one already shown
    /// (an error inside a macro used twice, placed at the macro's text) is
    /// shown once.
    pub fn render_all(
        &self,
        diagnostics: &[Diagnostic],
        f: &mut std::fmt::Formatter<'_>,
    ) -> std::fmt::Result {
        let mut shown = std::collections::HashSet::new();
        for d in diagnostics {
            if !shown.insert((d.span, d.message.as_str())) {
                continue;
            }
            if shown.len() > 1 {
                f.write_str("\n\n")?;
            }
            f.write_str(&self.render(d.span, &d.message))?;
        }
        Ok(())
    }

    /// Renders `file:line:col: error: message`, the source line and a caret.
    pub fn render(&self, span: Span, message: &str) -> String {
        self.render_as("error", span, message)
    }

    /// Renders `file:line:col: warning: message`, the line and a caret:
    /// what `check` reports without refusing the program.
    pub fn render_warning(&self, span: Span, message: &str) -> String {
        self.render_as("warning", span, message)
    }

    /// The work is proportional to the window shown, not to the line:
    /// many diagnostics on one long line render in linear time.
    fn render_as(&self, severity: &str, span: Span, message: &str) -> String {
        // A very long line is shown as a window around the column.
        const WINDOW: usize = 60;
        let file = self.get(span.file);
        let start = file.boundary(span.start as usize);
        let (line, col) = file.line_col(start);
        let full = file.line_text(line);
        let at = (start - file.line_starts[line - 1]).min(full.len());
        let (before, after) = full.split_at(at);
        let long = full.chars().take(2 * WINDOW + 21).count() > 2 * WINDOW + 20;
        let (from, to) = if long {
            // Up to WINDOW characters before the caret and from it.
            let from = before
                .char_indices()
                .rev()
                .nth(WINDOW - 1)
                .map_or(0, |(i, _)| i);
            let to = after
                .char_indices()
                .nth(WINDOW)
                .map_or(full.len(), |(i, _)| at + i);
            (from, to)
        } else {
            (0, full.len())
        };
        let visible = |s: &str| -> String {
            s.chars()
                .map(|c| if c.is_control() && c != '\t' { ' ' } else { c })
                .collect()
        };
        let lead = visible(&full[from..at]);
        let mut text = String::new();
        if from > 0 {
            text.push_str("...");
        }
        text.push_str(&lead);
        text.push_str(&visible(&full[at..to]));
        if to < full.len() {
            text.push_str("...");
        }
        // The caret's width: the span's characters on this line.
        let end = file.boundary((span.end as usize).max(start));
        let line_end = file.line_starts[line - 1] + full.len();
        let width = if end <= line_end && end > start {
            file.text[start..end].chars().take(2 * WINDOW).count()
        } else {
            1
        };
        let gutter = line.to_string().len();
        let mut pad: String = if from > 0 {
            "   ".into()
        } else {
            String::new()
        };
        pad.extend(lead.chars().map(|c| if c == '\t' { '\t' } else { ' ' }));
        format!(
            "{}:{}:{}: {}: {}\n{:gutter$} |\n{} | {}\n{:gutter$} | {}{}",
            file.name,
            line,
            col,
            severity,
            message,
            "",
            line,
            text,
            "",
            pad,
            "^".repeat(width),
            gutter = gutter
        )
    }
}

/// A located message about a program: what is wrong and where.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub span: Span,
    pub message: String,
}

impl Diagnostic {
    pub fn new(span: Span, message: impl Into<String>) -> Diagnostic {
        Diagnostic {
            span,
            message: message.into(),
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// A data file's problem as every error type shows it: `path: error:
/// message` for the whole file, `path:line: error: message` for one line,
/// and with `at` (the line's text and the bytes the caret marks) the line
/// and a caret ([`render_line`]).
pub fn write_file_problem(
    f: &mut std::fmt::Formatter<'_>,
    path: &str,
    line: Option<usize>,
    at: Option<(&str, std::ops::Range<usize>)>,
    message: &str,
) -> std::fmt::Result {
    match (line, at) {
        (Some(line), Some((text, range))) => {
            f.write_str(&render_line(path, line, text, range, message))
        }
        (Some(line), None) => write!(f, "{path}:{line}: error: {message}"),
        (None, _) => write!(f, "{path}: error: {message}"),
    }
}

/// `path:line:col: error: message`, then `text`, line `line` of the file,
/// and a caret under its bytes `range`: what [`SourceMap::render`] shows
/// for a diagnostic in a program, for a file of which only the one line is
/// at hand. The one renderer draws it from a file of that line alone; the
/// line number is then put back in the three places that show it.
pub fn render_line(
    path: &str,
    line: usize,
    text: &str,
    range: std::ops::Range<usize>,
    message: &str,
) -> String {
    let text = text.split(['\n', '\r']).next().unwrap_or("");
    if u32::try_from(text.len()).is_err() {
        // Spans hold 32-bit offsets: a line of 4 GiB is named, not shown.
        return format!("{path}:{line}: error: {message}");
    }
    let at = |i: usize| {
        (0..=i.min(text.len()))
            .rev()
            .find(|&i| text.is_char_boundary(i))
    };
    let start = at(range.start).unwrap_or(0);
    let end = at(range.end).unwrap_or(start).max(start);
    let mut map = SourceMap::default();
    let file = map.add(SourceFile::new(path, text));
    let shown = map.render(Span::new(file, start, end), message);
    // `path:1:col: ...`, ` |`, `1 | text`, `  | ^`: the gutter is one wide.
    let mut parts = shown.rsplitn(4, '\n');
    let (Some(caret), Some(source), Some(gutter), Some(header)) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return shown;
    };
    let (Some(rest), Some(source), Some(gutter), Some(caret)) = (
        header.strip_prefix(&format!("{path}:1:")),
        source.strip_prefix('1'),
        gutter.strip_prefix(' '),
        caret.strip_prefix(' '),
    ) else {
        return shown;
    };
    let pad = " ".repeat(line.to_string().len());
    format!("{path}:{line}:{rest}\n{pad}{gutter}\n{line}{source}\n{pad}{caret}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line rendered alone reads as the same line rendered in its file.
    #[test]
    fn render_line_is_the_one_rendering() {
        let long = format!("f {}", "12 ".repeat(80));
        let lines = ["v 0 0 0", "\tv 1 x 0", "é v 2 0 0", long.as_str()];
        let mut text = String::new();
        let mut starts = Vec::new();
        for k in 0..1200 {
            starts.push(text.len());
            text.push_str(lines[k % lines.len()]);
            text.push('\n');
        }
        let mut map = SourceMap::default();
        let file = map.add(SourceFile::new("m.obj", text.clone()));
        for k in [0, 1, 2, 3, 9, 10, 98, 99, 1001, 1199] {
            let line = lines[k % lines.len()];
            let ranges = [(0, 1), (4, 5), (3, 3), (200, 203), (2, 200)];
            let fits = |&(a, b): &(usize, usize)| {
                b <= line.len() && line.is_char_boundary(a) && line.is_char_boundary(b)
            };
            for (a, b) in ranges.into_iter().filter(fits) {
                let want = map.render(
                    Span::new(file, starts[k] + a, starts[k] + b),
                    "expected a number",
                );
                let got = render_line("m.obj", k + 1, line, a..b, "expected a number");
                assert_eq!(got, want, "line {} bytes {a}..{b}", k + 1);
            }
        }
    }
}
