//! A program's source: its file read once under the size limit and
//! checked as UTF-8, then lexed and preprocessed with the `-D` overrides
//! into a [`Front`], which the parser of the program's topology takes.
//! [`SourceError`] says why that failed; the crate's `Error` wraps it.

use std::fmt;
use std::path::{Path, PathBuf};

use super::lex::{self, Token};
use super::preprocess;
use super::{Diagnostic, FileId, SourceFile, SourceMap, Span};

/// Why a program's source could not be read, preprocessed, parsed or
/// checked. Each variant displays as the crate's `Error` shows the same
/// problem.
#[derive(Debug)]
#[non_exhaustive]
pub enum SourceError {
    /// The file could not be read.
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    /// The file as a whole cannot be a program (too large).
    File { path: String, message: String },
    /// The request cannot be carried out as asked: a malformed `-D`, a
    /// malformed size limit.
    Usage(String),
    /// Problems located in the program's text.
    Program {
        sources: SourceMap,
        diagnostics: Vec<Diagnostic>,
    },
}

impl SourceError {
    /// One diagnostic in `sources`.
    pub fn at(sources: &SourceMap, diagnostic: Diagnostic) -> SourceError {
        SourceError::Program {
            sources: sources.clone(),
            diagnostics: vec![diagnostic],
        }
    }

    fn read(path: impl Into<PathBuf>, error: std::io::Error) -> SourceError {
        SourceError::Io {
            path: path.into(),
            error,
        }
    }

    fn file(path: impl Into<String>, message: impl Into<String>) -> SourceError {
        SourceError::File {
            path: path.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for SourceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SourceError::Io { path, error } => {
                write!(f, "cannot read `{}`: {error}", path.display())
            }
            SourceError::File { path, message } => {
                super::write_file_problem(f, path, None, None, message)
            }
            SourceError::Usage(m) => f.write_str(m),
            SourceError::Program {
                sources,
                diagnostics,
            } => sources.render_all(diagnostics, f),
        }
    }
}

impl std::error::Error for SourceError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SourceError::Io { error, .. } => Some(error),
            _ => None,
        }
    }
}

/// The largest program file read, in bytes: lpfg programs are a few
/// kilobytes, and the front end holds about fifty bytes per character of a
/// file at worst. The environment variable [`MAX_PROGRAM_SIZE_VAR`] raises
/// (or lowers) it, in mebibytes.
pub const MAX_PROGRAM_BYTES: u64 = 16 << 20;

/// The environment variable that sets the largest program file read, in
/// mebibytes (`SUBGRAM_MAX_PROGRAM_MIB=64`).
pub const MAX_PROGRAM_SIZE_VAR: &str = "SUBGRAM_MAX_PROGRAM_MIB";

/// The limit on a program file's size: [`MAX_PROGRAM_BYTES`], or what
/// [`MAX_PROGRAM_SIZE_VAR`] says.
fn program_size_limit() -> Result<u64, SourceError> {
    match std::env::var(MAX_PROGRAM_SIZE_VAR) {
        Err(std::env::VarError::NotPresent) => Ok(MAX_PROGRAM_BYTES),
        Ok(v) => match v.trim().parse::<u64>() {
            Ok(mib) if mib > 0 && mib <= 1 << 20 => Ok(mib << 20),
            _ => Err(SourceError::Usage(format!(
                "{MAX_PROGRAM_SIZE_VAR}={v}: expected a whole number of mebibytes from 1 to {}",
                1 << 20
            ))),
        },
        Err(std::env::VarError::NotUnicode(v)) => Err(SourceError::Usage(format!(
            "{MAX_PROGRAM_SIZE_VAR}={}: expected a whole number of mebibytes",
            v.to_string_lossy()
        ))),
    }
}

/// Reads a program file, once: its size is checked against the limit
/// before it is read whole (a device or a pipe, which has no size, is read
/// up to the limit and no further), and text that is not UTF-8 is refused
/// at its first bad byte.
pub fn read(path: &Path) -> Result<String, SourceError> {
    let limit = program_size_limit()?;
    let bytes = read_at_most(path, limit)?;
    utf8(&path.display().to_string(), bytes)
}

/// The bytes of `path`, or an error that names `limit` when there are
/// more.
fn read_at_most(path: &Path, limit: u64) -> Result<Vec<u8>, SourceError> {
    use std::io::Read;
    let io = |e| SourceError::read(PathBuf::from(path), e);
    let file = crate::files::open(path).map_err(io)?;
    let size = file.size();
    let too_big = |size: Option<u64>| {
        let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
        let is = match size {
            Some(b) => format!("the file is {:.1} MiB ({b} bytes)", mib(b)),
            None => format!("more than {} MiB were read from it", limit >> 20),
        };
        SourceError::file(
            path.display().to_string(),
            format!(
                "{is}; a program may be at most {} MiB: set {MAX_PROGRAM_SIZE_VAR} to a larger \
                 number of mebibytes to raise the limit",
                limit >> 20
            ),
        )
    };
    if let Some(len) = size.filter(|&len| len > limit) {
        return Err(too_big(Some(len)));
    }
    let expected = size.unwrap_or(0);
    let mut bytes = Vec::with_capacity(expected as usize);
    file.take(limit + 1).read_to_end(&mut bytes).map_err(io)?;
    if bytes.len() as u64 > limit {
        // A file that grew while it was read, or one without a size.
        return Err(too_big(size.map(|_| bytes.len() as u64)));
    }
    Ok(bytes)
}

/// `bytes` as text, or an error located at the first byte that is not
/// UTF-8, shown in the line as a replacement character.
pub fn utf8(name: &str, bytes: Vec<u8>) -> Result<String, SourceError> {
    let e = match String::from_utf8(bytes) {
        Ok(text) => return Ok(text),
        Err(e) => e,
    };
    let at = e.utf8_error().valid_up_to();
    let bad_len = e
        .utf8_error()
        .error_len()
        .unwrap_or(e.as_bytes().len() - at);
    let bad: Vec<String> = e.as_bytes()[at..at + bad_len]
        .iter()
        .map(|b| format!("0x{b:02X}"))
        .collect();
    // The valid prefix is kept as it is; the bad byte becomes U+FFFD.
    let text = String::from_utf8_lossy(e.as_bytes()).into_owned();
    let mut sources = SourceMap::default();
    let file = sources.add(SourceFile::new(name, text));
    let what = if e.utf8_error().error_len().is_none() {
        "the file ends inside a character"
    } else if bad.len() == 1 {
        "the byte"
    } else {
        "the bytes"
    };
    let message = format!(
        "invalid UTF-8 ({what} {}): a program must be UTF-8 text; save the file as UTF-8",
        bad.join(" ")
    );
    let span = Span::new(file, at, at + '\u{FFFD}'.len_utf8());
    Err(SourceError::at(&sources, Diagnostic::new(span, message)))
}

/// A program's text after lexing and preprocessing.
pub struct Front {
    /// The file, then one source per `-D` override.
    pub sources: SourceMap,
    pub main: FileId,
    pub tokens: Vec<Token>,
}

impl Front {
    /// The empty span at the end of the file, for "expected ..., found the
    /// end of the file".
    pub fn eof(&self) -> Span {
        let n = self.sources.get(self.main).text.len();
        Span::new(self.main, n, n)
    }
}

/// Lexes and preprocesses `text` with `defines` (`NAME=VALUE` each).
pub fn front(name: &str, text: String, defines: &[String]) -> Result<Front, SourceError> {
    let mut sources = SourceMap::default();
    let main = sources.add(SourceFile::new(name, text));
    let mut overrides = Vec::new();
    for d in defines {
        let bad = || {
            SourceError::Usage(format!(
                "`-D {d}` must have the form NAME=VALUE, e.g. -D STEPS=4"
            ))
        };
        let (n, v) = d.split_once('=').ok_or_else(bad)?;
        let n = n.trim();
        if n.is_empty() || !n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(bad());
        }
        let id = sources.add(SourceFile::new(format!("<-D {n}>"), v));
        let toks = lex::lex(id, v).map_err(|e| SourceError::at(&sources, e))?;
        overrides.push((n.to_string(), toks));
    }
    let tokens = lex::lex_all(main, &sources.get(main).text)
        .and_then(|t| preprocess::preprocess(t, &overrides))
        .map_err(|e| SourceError::at(&sources, e))?;
    Ok(Front {
        sources,
        main,
        tokens,
    })
}
