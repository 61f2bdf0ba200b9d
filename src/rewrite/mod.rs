//! Rewriting words of modules: storage, context matching, one parallel step,
//! and whole derivations with decomposition and interpretation.
//!
//! **Layer.** It uses `deadline`, `huge`, `lang`, `syntax`; it is used by
//! `analyze`, `command`, `curve`, `draw`, `output`, `production`, `render`,
//! `reverse`, `system`. Nothing here names a layer above (see ARCHITECTURE.md,
//! "Layers").

pub mod context;
pub mod derive;
pub mod environment;
pub mod gillespie;
pub(crate) mod growth;
pub mod step;
pub mod word;

pub use derive::{
    derive, is_query, Derivation, DeriveError, DeriveOptions, Derived, Queries, TurtleAnswers,
};
pub use word::Word;
