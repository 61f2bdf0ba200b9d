//! The `.lsys` language as text: lexing, preprocessing, parsing, spans.

pub mod ast;
pub mod ifexpr;
pub mod lex;
pub mod parse;
pub mod preprocess;
pub mod source;
pub mod span;

pub use source::SourceError;
pub use span::{render_line, Diagnostic, FileId, SourceFile, SourceMap, Span};
