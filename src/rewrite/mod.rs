//! Rewriting words of modules: storage, context matching, one parallel step,
//! and whole derivations with decomposition and interpretation.

pub mod context;
pub mod derive;
pub mod gillespie;
pub(crate) mod growth;
pub mod step;
pub mod word;

pub use derive::{derive, is_query, Derivation, DeriveError, DeriveOptions, Derived, Queries};
pub use word::Word;
