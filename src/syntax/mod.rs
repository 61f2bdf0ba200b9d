//! The `.lsys` language as text: lexing, preprocessing, parsing, spans.

pub mod ast;
pub mod ifexpr;
pub mod lex;
pub mod parse;
pub mod preprocess;
pub mod span;

pub use span::{Diagnostic, FileId, SourceFile, SourceMap, Span};
