//! [`Error`]: every way the library can fail, with a message that says what
//! is wrong and, where there is a place to point at, where.

use std::fmt;
use std::path::PathBuf;

use crate::syntax::{write_file_problem, Diagnostic, SourceMap};

/// What went wrong. Every variant displays as a message for a person; none
/// starts with `error: ` (a program that prints it adds its own prefix, as
/// the `subgram` binary does for messages that have no location).
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let opts = subgram::LoadOptions::default();
/// let err = subgram::load_text("bad.lsys", "module P;\nAxiom: Q;\n", &opts).unwrap_err();
/// assert!(err.has_location());
/// assert!(err.to_string().starts_with("bad.lsys:2:8: error: undeclared module `Q`"));
/// // It converts into `Box<dyn Error>` with `?`:
/// let ok = subgram::load_text("ok.lsys", "module P;\nAxiom: P;\n", &opts)?;
/// # let _ = ok; Ok(()) }
/// ```
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or written.
    Io {
        path: PathBuf,
        /// True when writing failed, false when reading did.
        write: bool,
        error: std::io::Error,
    },
    /// Problems located in a program's text: everything a check found, or
    /// the rule at fault when a run failed. Displayed as
    /// `file:line:col: error: message`, the line and a caret under the place,
    /// one block per diagnostic.
    Program {
        sources: SourceMap,
        diagnostics: Vec<Diagnostic>,
    },
    /// A data file is malformed or describes something unusable: a mesh, a
    /// contour, a details file. Displayed as `path:line: error: message`
    /// (without `line:` when the whole file is at fault).
    File {
        path: String,
        line: Option<usize>,
        message: String,
    },
    /// A data file's problem at a place in one of its lines: a token of a
    /// mesh file. Displayed as `path:line:col: error: message`, the line
    /// and a caret, as [`Error::Program`]'s diagnostics are.
    FileAt {
        path: String,
        line: usize,
        /// The text of the line (without its newline).
        text: String,
        /// The byte range of `text` that the caret marks.
        start: usize,
        end: usize,
        message: String,
    },
    /// A run failed with nothing in a file to point at: a word that grew
    /// past its limit, a picture with nothing to draw, a contour too short
    /// for the steps asked.
    Failed(String),
    /// The request cannot be carried out as asked: a malformed `-D`, too many
    /// steps, an output name whose format cannot be told, an unknown view,
    /// a surface grammar without a base mesh. The `subgram` binary exits with
    /// 2 for these, with 1 for every other error.
    Usage(String),
}

impl Error {
    /// True when the message begins with the place it is about
    /// (`file:line:col:`, `file:line:` or `file:`), followed by `error:`.
    pub fn has_location(&self) -> bool {
        matches!(
            self,
            Error::Program { .. } | Error::File { .. } | Error::FileAt { .. }
        )
    }

    /// The diagnostics of a [`Error::Program`] error; empty for the others.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            Error::Program { diagnostics, .. } => diagnostics,
            _ => &[],
        }
    }

    /// One diagnostic in `sources`.
    pub(crate) fn at(sources: &SourceMap, diagnostic: Diagnostic) -> Error {
        Error::Program {
            sources: sources.clone(),
            diagnostics: vec![diagnostic],
        }
    }

    pub(crate) fn read(path: impl Into<PathBuf>, error: std::io::Error) -> Error {
        Error::Io {
            path: path.into(),
            write: false,
            error,
        }
    }

    pub(crate) fn write(path: impl Into<PathBuf>, error: std::io::Error) -> Error {
        Error::Io {
            path: path.into(),
            write: true,
            error,
        }
    }

    pub(crate) fn file(path: impl Into<String>, message: impl Into<String>) -> Error {
        Error::File {
            path: path.into(),
            line: None,
            message: message.into(),
        }
    }

    /// A message about the bytes `at` of a data file's `text` (a contour, a
    /// details file), displayed as a program's diagnostics are:
    /// `file:line:col: error: message`, the line and a caret.
    pub(crate) fn in_text(
        name: &str,
        text: &str,
        at: std::ops::Range<usize>,
        message: impl Into<String>,
    ) -> Error {
        let start = at.start.min(text.len());
        if text.len() > u32::MAX as usize {
            // Beyond what a span can address: the line alone.
            return Error::File {
                path: name.to_string(),
                line: Some(
                    1 + text.as_bytes()[..start]
                        .iter()
                        .filter(|&&b| b == b'\n')
                        .count(),
                ),
                message: message.into(),
            };
        }
        let mut end = at.end.clamp(start, text.len());
        // Spans fall on characters; snap any that would not.
        let mut start = start;
        while !text.is_char_boundary(start) {
            start -= 1;
        }
        while !text.is_char_boundary(end) {
            end += 1;
        }
        // The text up to the end of the place's line is all the message shows.
        let cut = text[end..].find('\n').map_or(text.len(), |i| end + i);
        let mut sources = SourceMap::default();
        let file = sources.add(crate::syntax::SourceFile::new(name, &text[..cut]));
        Error::Program {
            sources,
            diagnostics: vec![Diagnostic::new(
                crate::syntax::Span::new(file, start, end),
                message,
            )],
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { path, write, error } => {
                let verb = if *write { "write" } else { "read" };
                write!(f, "cannot {verb} `{}`: {error}", path.display())
            }
            Error::Program {
                sources,
                diagnostics,
            } => sources.render_all(diagnostics, f),
            Error::File {
                path,
                line,
                message,
            } => write_file_problem(f, path, *line, None, message),
            Error::FileAt {
                path,
                line,
                text,
                start,
                end,
                message,
            } => write_file_problem(f, path, Some(*line), Some((text, *start..*end)), message),
            Error::Failed(m) | Error::Usage(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { error, .. } => Some(error),
            _ => None,
        }
    }
}

impl From<crate::syntax::SourceError> for Error {
    fn from(e: crate::syntax::SourceError) -> Error {
        use crate::syntax::SourceError as S;
        match e {
            S::Io { path, error } => Error::read(path, error),
            S::File { path, message } => Error::file(path, message),
            S::Usage(m) => Error::Usage(m),
            S::Program {
                sources,
                diagnostics,
            } => Error::Program {
                sources,
                diagnostics,
            },
        }
    }
}

impl From<crate::model::ModelError> for Error {
    fn from(e: crate::model::ModelError) -> Error {
        use crate::model::ModelError as M;
        match e {
            M::Io { path, error } => Error::read(path, error),
            M::File {
                path,
                line,
                message,
            } => Error::File {
                path,
                line,
                message,
            },
            M::FileAt {
                path,
                line,
                text,
                start,
                end,
                message,
            } => Error::FileAt {
                path,
                line,
                text,
                start,
                end,
                message,
            },
            M::Usage(m) => Error::Usage(m),
        }
    }
}

impl From<crate::files::CommitError> for Error {
    fn from(e: crate::files::CommitError) -> Error {
        use crate::files::CommitError;
        match e {
            CommitError::Late(m) => Error::Failed(m),
            CommitError::Refused(m) => Error::Usage(m),
            CommitError::Write { path, error } => Error::write(path, error),
        }
    }
}

impl From<crate::mesh::MeshFileError> for Error {
    fn from(e: crate::mesh::MeshFileError) -> Error {
        match (e.line, e.place) {
            (Some(line), Some(place)) => Error::FileAt {
                path: e.path,
                line,
                text: place.text,
                start: place.start,
                end: place.end,
                message: e.message,
            },
            (line, _) => Error::File {
                path: e.path,
                line,
                message: e.message,
            },
        }
    }
}

impl From<crate::draw::DrawError> for Error {
    fn from(e: crate::draw::DrawError) -> Error {
        Error::Failed(e.message)
    }
}

impl From<crate::render::RenderError> for Error {
    fn from(e: crate::render::RenderError) -> Error {
        Error::Failed(e.message)
    }
}
