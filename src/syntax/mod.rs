//! The `.lsys` language as text: lexing, preprocessing, parsing, spans.
//!
//! **Layer.** It uses `files`; it is used by `command`, `curve`, `draw`,
//! `error`, `lang`, `load`, `mesh`, `model`, `production`, `rewrite`, `shape`,
//! `surface`, `system`, `vv`. Nothing here names a layer above (see
//! ARCHITECTURE.md, "Layers").

pub mod ast;
pub mod ifexpr;
pub mod lex;
pub mod parse;
pub mod preprocess;
pub mod source;
pub mod span;

pub use source::SourceError;
pub use span::{write_file_problem, Diagnostic, FileId, SourceFile, SourceMap, Span};
