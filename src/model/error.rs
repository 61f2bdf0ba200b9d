//! [`ModelError`]: why a model folder or one of its files cannot be used.
//! The crate's `Error` wraps it, variant for variant.

use std::fmt;
use std::path::PathBuf;

use crate::syntax::write_file_problem;

/// A model folder's problem: a file that cannot be read, or what is wrong
/// in one, with its place where there is one to point at.
#[derive(Debug)]
#[non_exhaustive]
pub enum ModelError {
    /// A file could not be read.
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    /// A file is malformed or describes something unusable; `line` where
    /// one line is at fault.
    File {
        path: String,
        line: Option<usize>,
        message: String,
    },
    /// A problem at a place in one of a file's lines: the line's `text`,
    /// and the byte range `start..end` of it that the caret marks.
    FileAt {
        path: String,
        line: usize,
        text: String,
        start: usize,
        end: usize,
        message: String,
    },
    /// The folder cannot be run as asked (an lpfg option subgram does not
    /// take, a file named twice).
    Usage(String),
}

impl ModelError {
    pub(crate) fn read(path: impl Into<PathBuf>, error: std::io::Error) -> ModelError {
        ModelError::Io {
            path: path.into(),
            error,
        }
    }

    pub(crate) fn file(path: impl Into<String>, message: impl Into<String>) -> ModelError {
        ModelError::File {
            path: path.into(),
            line: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for ModelError {
    /// As the crate's `Error` shows the same problem.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ModelError::Io { path, error } => {
                write!(f, "cannot read `{}`: {error}", path.display())
            }
            ModelError::File {
                path,
                line,
                message,
            } => write_file_problem(f, path, *line, None, message),
            ModelError::FileAt {
                path,
                line,
                text,
                start,
                end,
                message,
            } => write_file_problem(f, path, Some(*line), Some((text, *start..*end)), message),
            ModelError::Usage(m) => f.write_str(m),
        }
    }
}

impl std::error::Error for ModelError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ModelError::Io { error, .. } => Some(error),
            _ => None,
        }
    }
}
