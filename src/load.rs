//! The one loader: a file is read once, lexed and preprocessed once, its
//! kind is decided from the tokens, and the tokens go to the parser of that
//! kind.

use std::path::{Path, PathBuf};

use crate::curve::Curve;
use crate::error::Error;
use crate::lang;
use crate::surface;
use crate::syntax::lex::{self, Token};
use crate::syntax::{parse, preprocess, FileId, SourceFile, SourceMap, Span};
use crate::system::{Surface, System};

/// Settings of loading.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// `#define` overrides, each `NAME=VALUE` (the binary's `-D`); they win
    /// over the file's own `#define`s and `angle:` values.
    pub defines: Vec<String>,
}

impl LoadOptions {
    /// Adds one `NAME=VALUE` override.
    pub fn define(mut self, name_value: impl Into<String>) -> Self {
        self.defines.push(name_value.into());
        self
    }
}

/// Reads and checks a `.lsys` file: a curve L-system or a surface grammar,
/// told apart by its syntax (a `mesh:` directive, or a rule such as
/// `F(f) -> V(...) || E^3 F^3`, makes a surface grammar).
///
/// ```
/// # fn main() -> Result<(), subgram::Error> {
/// let root = env!("CARGO_MANIFEST_DIR");
/// let opts = subgram::LoadOptions::default();
/// let curve = subgram::load(format!("{root}/lsystems/curves/chaikin-13.lsys"), &opts)?;
/// assert!(matches!(curve, subgram::System::Curve(_)));
/// let loop_ = subgram::load(format!("{root}/lsystems/surfaces/loop.lsys"), &opts)?;
/// assert!(matches!(loop_, subgram::System::Surface(_)));
/// # Ok(()) }
/// ```
pub fn load(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<System, Error> {
    let path = path.as_ref();
    let text = read(path)?;
    let front = front(&path.display().to_string(), text, &opts.defines)?;
    if surface::is_surface(&front.tokens) {
        let grammar = surface::from_front(front)?;
        Ok(System::Surface(Surface::new(grammar, Some(path))))
    } else {
        Ok(System::Curve(curve(front)?))
    }
}

/// Checks program text, as [`load`] does a file; `name` is the file name in
/// messages. A surface grammar's `mesh:` is then relative to the current
/// folder.
pub fn load_text(name: &str, text: &str, opts: &LoadOptions) -> Result<System, Error> {
    let front = front(name, text.to_string(), &opts.defines)?;
    if surface::is_surface(&front.tokens) {
        let grammar = surface::from_front(front)?;
        Ok(System::Surface(Surface::new(grammar, None)))
    } else {
        Ok(System::Curve(curve(front)?))
    }
}

/// Loads a file as a curve L-system, whatever its syntax says; `defines`
/// are `NAME=VALUE` overrides.
pub fn load_file(path: impl AsRef<Path>, defines: &[String]) -> Result<Curve, Error> {
    let path = path.as_ref();
    let text = read(path)?;
    curve(front(&path.display().to_string(), text, defines)?)
}

/// Checks text as a curve L-system; `name` is the file name in messages.
///
/// ```
/// let src = "
///     V2f v1(0, 0), v2(0, 1), v3(1, 1), v4(1, 0);
///     module P(V2f);
///     ring L-system: 1;
///     derivation length: 2;
///     Axiom: P(v1) P(v2) P(v3) P(v4);
///     P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)
/// ";
/// let chaikin = subgram::load_str("chaikin.lsys", src, &[]).unwrap();
/// let derived = chaikin.derive(Default::default()).unwrap();
/// assert_eq!(derived.word.len(), 16); // 4 points, doubled twice
/// ```
pub fn load_str(name: &str, text: &str, defines: &[String]) -> Result<Curve, Error> {
    curve(front(name, text.to_string(), defines)?)
}

pub(crate) fn read(path: &Path) -> Result<String, Error> {
    std::fs::read_to_string(path).map_err(|e| Error::read(PathBuf::from(path), e))
}

/// A program's text after lexing and preprocessing.
pub(crate) struct Front {
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
pub(crate) fn front(name: &str, text: String, defines: &[String]) -> Result<Front, Error> {
    let mut sources = SourceMap::default();
    let main = sources.add(SourceFile::new(name, text));
    let mut overrides = Vec::new();
    for d in defines {
        let bad = || {
            Error::Usage(format!(
                "`-D {d}` must have the form NAME=VALUE, e.g. -D STEPS=4"
            ))
        };
        let (n, v) = d.split_once('=').ok_or_else(bad)?;
        let n = n.trim();
        if n.is_empty() || !n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(bad());
        }
        let id = sources.add(SourceFile::new(format!("<-D {n}>"), v));
        let toks = lex::lex(id, v).map_err(|e| Error::at(&sources, e))?;
        overrides.push((n.to_string(), toks));
    }
    let tokens = lex::lex(main, &sources.get(main).text)
        .and_then(|t| preprocess::preprocess(t, &overrides))
        .map_err(|e| Error::at(&sources, e))?;
    Ok(Front {
        sources,
        main,
        tokens,
    })
}

/// Parses and checks preprocessed tokens as a curve L-system.
pub(crate) fn curve(front: Front) -> Result<Curve, Error> {
    let eof = front.eof();
    let Front {
        sources, tokens, ..
    } = front;
    let predefined: Vec<&str> = lang::modules::PREDEFINED.iter().map(|(n, _)| *n).collect();
    let file = match parse::parse_file(&tokens, eof, &predefined) {
        Ok(f) => f,
        Err(d) => {
            return Err(Error::Program {
                sources,
                diagnostics: vec![d],
            })
        }
    };
    match lang::compile(&file) {
        Ok(program) => Ok(Curve { program, sources }),
        Err(mut diagnostics) => {
            for d in &mut diagnostics {
                if d.span == Span::default() {
                    d.span = eof;
                }
            }
            Err(Error::Program {
                sources,
                diagnostics,
            })
        }
    }
}
