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
            text,
            line_starts,
        }
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let line = match self.line_starts.binary_search(&offset) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let start = self.line_starts[line];
        let col = self.text[start..offset].chars().count() + 1;
        (line + 1, col)
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

    /// Renders `file:line:col: error: message`, the source line and a caret.
    pub fn render(&self, span: Span, message: &str) -> String {
        self.render_as("error", span, message)
    }

    /// Renders `file:line:col: warning: message`, the line and a caret:
    /// what `check` reports without refusing the program.
    pub fn render_warning(&self, span: Span, message: &str) -> String {
        self.render_as("warning", span, message)
    }

    fn render_as(&self, severity: &str, span: Span, message: &str) -> String {
        let file = self.get(span.file);
        let (line, col) = file.line_col(span.start as usize);
        let full = file.line_text(line);
        // A very long line is shown as a window around the column.
        const WINDOW: usize = 60;
        let chars: Vec<char> = full
            .chars()
            .map(|c| if c.is_control() && c != '\t' { ' ' } else { c })
            .collect();
        let (text, shift) = if chars.len() > 2 * WINDOW + 20 {
            let from = (col - 1).saturating_sub(WINDOW);
            let to = (col - 1 + WINDOW).min(chars.len());
            let mut t: String = chars[from..to].iter().collect();
            let mut shift = from;
            if from > 0 {
                t.insert_str(0, "...");
                shift = from.saturating_sub(3);
            }
            if to < chars.len() {
                t.push_str("...");
            }
            (t, shift)
        } else {
            (chars.iter().collect::<String>(), 0)
        };
        let text = text.as_str();
        let (end_line, end_col) = file.line_col(span.end as usize);
        let width = if end_line == line && end_col > col {
            (end_col - col).min(2 * WINDOW)
        } else {
            1
        };
        let gutter = line.to_string().len();
        let pad: String = text
            .chars()
            .take(col - 1 - shift)
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
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
