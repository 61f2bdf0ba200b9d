//! Stellar subdivision grammars (paper 000): rules over faces, edges and
//! vertices with levels, run on the half-edge mesh.

pub mod grammar;
pub mod host;
pub mod run;

use std::path::Path;

use crate::syntax::{lex, preprocess, Diagnostic, SourceFile, SourceMap, Span};

pub use run::{Grammar, RunError, StepCounts};

/// Why a grammar could not be loaded: its messages with their sources.
#[derive(Debug)]
pub struct GrammarError {
    pub sources: SourceMap,
    pub diagnostics: Vec<Diagnostic>,
}

impl GrammarError {
    pub fn render(&self) -> String {
        self.diagnostics
            .iter()
            .map(|d| self.sources.render(d.span, &d.message))
            .collect::<Vec<_>>()
            .join("\n\n")
    }
}

/// True when `text` is a surface grammar (it names a base mesh with `mesh:`
/// or holds rules such as `F(f) -> V(...) || E^3 F^3`).
pub fn is_surface_text(text: &str) -> bool {
    text.lines().any(|l| {
        let t = l.trim_start();
        t.starts_with("mesh:")
            || ((t.starts_with("F(") || t.starts_with("E(") || t.starts_with("V("))
                && t.contains("||"))
    })
}

/// Loads a surface grammar from text. `defines` are `-D NAME=VALUE`.
pub fn load_str(name: &str, text: &str, defines: &[String]) -> Result<Grammar, GrammarError> {
    let mut sources = SourceMap::default();
    let main = sources.add(SourceFile::new(name, text));
    let fail = |sources: SourceMap, d: Diagnostic| GrammarError {
        sources,
        diagnostics: vec![d],
    };
    let mut overrides = Vec::new();
    for d in defines {
        let Some((n, v)) = d.split_once('=') else {
            return Err(fail(
                sources,
                Diagnostic::new(
                    Span::default(),
                    format!("`-D {d}` must have the form NAME=VALUE"),
                ),
            ));
        };
        let id = sources.add(SourceFile::new(format!("<-D {n}>"), v));
        match lex::lex(id, v) {
            Ok(t) => overrides.push((n.trim().to_string(), t)),
            Err(e) => return Err(fail(sources, e)),
        }
    }
    let tokens = match lex::lex(main, text).and_then(|t| preprocess::preprocess(t, &overrides)) {
        Ok(t) => t,
        Err(e) => return Err(fail(sources, e)),
    };
    let eof = Span::new(main, text.len(), text.len());
    let text_of = |s: Span| {
        let t = &text[s.start as usize..(s.end as usize).min(text.len())];
        t.split_whitespace().collect::<Vec<_>>().join(" ")
    };
    let file = match grammar::parse(&tokens, eof, text_of) {
        Ok(f) => f,
        Err(e) => return Err(fail(sources, e)),
    };
    run::compile(&file, sources).map_err(|(sources, diagnostics)| GrammarError {
        sources,
        diagnostics,
    })
}

/// Loads a surface grammar file.
pub fn load_file(path: &Path, defines: &[String]) -> Result<Grammar, GrammarError> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        let mut sources = SourceMap::default();
        sources.add(SourceFile::new(path.display().to_string(), ""));
        GrammarError {
            sources,
            diagnostics: vec![Diagnostic::new(
                Span::default(),
                format!("cannot read `{}`: {e}", path.display()),
            )],
        }
    })?;
    load_str(&path.display().to_string(), &text, defines)
}
