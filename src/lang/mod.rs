//! The language's meaning: types, values, checking and the interpreter.

pub mod builtins;
pub mod compile;
pub mod eval;
pub mod ir;
pub mod modules;
pub mod stencil;
pub mod value;

pub use ir::Program;
pub use modules::{Alphabet, Sym};
pub use value::{Ty, Value};
