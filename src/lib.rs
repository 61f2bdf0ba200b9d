//! subgram: curves and surfaces specified with L-systems and grammars.
//!
//! A `.lsys` file is an L+C-like program (the language of lpfg): module
//! declarations, an axiom, productions with contexts and C-like bodies.
//! [`load_str`] checks it into a [`Program`]; [`derive`] rewrites its axiom.
//!
//! ```
//! let src = "
//!     V2f v1(0, 0), v2(0, 1), v3(1, 1), v4(1, 0);
//!     module P(V2f);
//!     ring L-system: 1;
//!     derivation length: 2;
//!     Axiom: P(v1) P(v2) P(v3) P(v4);
//!     P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)
//! ";
//! let program = subgram::load_str("chaikin.lsys", src, &[]).unwrap();
//! let derived = subgram::derive(&program.program, Default::default()).unwrap();
//! assert_eq!(derived.word.len(), 16); // 4 points, doubled twice
//! ```

mod atomic;
pub mod draw;
pub mod lang;
pub mod mesh;
pub mod output;
pub mod render;
pub mod reverse;
pub mod rewrite;
pub mod surface;
pub mod syntax;

use std::fmt;
use std::path::Path;

pub use lang::Program;
pub use rewrite::{derive, Derivation, DeriveError, DeriveOptions, Derived, Word};
pub use syntax::{Diagnostic, SourceMap};

use syntax::{lex, parse, preprocess, SourceFile, Span};

/// A checked program together with the sources its spans point into.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub program: Program,
    pub sources: SourceMap,
}

impl Loaded {
    /// Renders a derivation error with the program's source line and caret.
    pub fn render_derive_error(&self, e: &DeriveError) -> String {
        match e.span {
            Some(span) => self.sources.render(span, &e.message),
            None => format!("error: {}", e.message),
        }
    }
}

/// Why a program could not be loaded.
#[derive(Debug)]
pub enum LoadError {
    Io {
        path: String,
        error: std::io::Error,
    },
    /// `-D` was not of the form NAME=VALUE.
    BadDefine(String),
    Diagnostics {
        sources: SourceMap,
        diagnostics: Vec<Diagnostic>,
    },
}

impl LoadError {
    /// Each diagnostic as `file:line:col: error: ...` with its line and caret.
    pub fn render(&self) -> String {
        match self {
            LoadError::Io { path, error } => format!("error: cannot read `{path}`: {error}"),
            LoadError::BadDefine(d) => {
                format!("error: `-D {d}` must have the form NAME=VALUE, e.g. -D STEPS=4")
            }
            LoadError::Diagnostics {
                sources,
                diagnostics,
            } => diagnostics
                .iter()
                .map(|d| sources.render(d.span, &d.message))
                .collect::<Vec<_>>()
                .join("\n\n"),
        }
    }

    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            LoadError::Diagnostics { diagnostics, .. } => diagnostics,
            _ => &[],
        }
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.render())
    }
}

impl std::error::Error for LoadError {}

/// Loads and checks a `.lsys` file. `defines` are `-D NAME=VALUE` overrides.
pub fn load_file(path: impl AsRef<Path>, defines: &[String]) -> Result<Loaded, LoadError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|error| LoadError::Io {
        path: path.display().to_string(),
        error,
    })?;
    load_str(&path.display().to_string(), &text, defines)
}

/// Loads and checks program text. `name` is used in messages.
pub fn load_str(name: &str, text: &str, defines: &[String]) -> Result<Loaded, LoadError> {
    let mut sources = SourceMap::default();
    let main = sources.add(SourceFile::new(name, text));
    let fail = |sources: SourceMap, d: Diagnostic| LoadError::Diagnostics {
        sources,
        diagnostics: vec![d],
    };
    let mut overrides = Vec::new();
    for d in defines {
        let Some((n, v)) = d.split_once('=') else {
            return Err(LoadError::BadDefine(d.clone()));
        };
        let n = n.trim();
        if n.is_empty() || !n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            return Err(LoadError::BadDefine(d.clone()));
        }
        let id = sources.add(SourceFile::new(format!("<-D {n}>"), v));
        let toks = match lex::lex(id, v) {
            Ok(t) => t,
            Err(e) => return Err(fail(sources, e)),
        };
        overrides.push((n.to_string(), toks));
    }
    let tokens = match lex::lex(main, text) {
        Ok(t) => t,
        Err(e) => return Err(fail(sources, e)),
    };
    let tokens = match preprocess::preprocess(tokens, &overrides) {
        Ok(t) => t,
        Err(e) => return Err(fail(sources, e)),
    };
    let eof = Span::new(main, text.len(), text.len());
    let predefined: Vec<&str> = lang::modules::PREDEFINED.iter().map(|(n, _)| *n).collect();
    let file = match parse::parse_file(&tokens, eof, &predefined) {
        Ok(f) => f,
        Err(e) => return Err(fail(sources, e)),
    };
    match lang::compile(&file) {
        Ok(mut program) => {
            fix_missing_spans(&mut program, main);
            Ok(Loaded { program, sources })
        }
        Err(mut diagnostics) => {
            for d in &mut diagnostics {
                if d.span == Span::default() {
                    d.span = eof;
                }
            }
            Err(LoadError::Diagnostics {
                sources,
                diagnostics,
            })
        }
    }
}

fn fix_missing_spans(_program: &mut Program, _main: syntax::FileId) {}

/// Settings of a figure: how far to derive, how to draw, how to render.
#[derive(Clone, Debug, Default)]
pub struct FigureOptions {
    pub derive: DeriveOptions,
    /// Draw every step 0..=N side by side.
    pub each: bool,
    pub draw: draw::DrawOptions,
    pub render: render::RenderOptions,
}

/// Why a figure could not be made; `render` gives the message.
#[derive(Clone, Debug, PartialEq)]
pub enum FigureError {
    Derive(DeriveError),
    Draw(draw::DrawError),
    Render(render::RenderError),
}

impl Loaded {
    /// A figure's message, with a source line and caret where one applies.
    pub fn render_figure_error(&self, e: &FigureError) -> String {
        match e {
            FigureError::Derive(d) => self.render_derive_error(d),
            FigureError::Draw(d) => format!("error: {}", d.message),
            FigureError::Render(r) => format!("error: {}", r.message),
        }
    }

    /// Derives, interprets and lays out the program's picture.
    pub fn figure(&self, opts: &FigureOptions) -> Result<render::Scene, FigureError> {
        let p = &self.program;
        let mut d = Derivation::new(p, opts.derive.clone()).map_err(FigureError::Derive)?;
        let mut draw_opts = opts.draw.clone();
        if let Some(a) = d.angle().map_err(FigureError::Derive)? {
            draw_opts.angle = a;
        }
        let mut panels = Vec::new();
        let mut panel = |d: &mut Derivation| -> Result<(), FigureError> {
            let word = d.interpret().map_err(FigureError::Derive)?;
            let events = draw::draw(&word, &p.alphabet, &p.structs, &draw_opts)
                .map_err(FigureError::Draw)?;
            panels.push(events);
            Ok(())
        };
        if opts.each {
            panel(&mut d)?;
        }
        while d.has_next() {
            d.next_step().map_err(FigureError::Derive)?;
            if opts.each {
                panel(&mut d)?;
            }
        }
        if !opts.each {
            panel(&mut d)?;
        }
        render::scene(&panels, &opts.render).map_err(FigureError::Render)
    }
}
