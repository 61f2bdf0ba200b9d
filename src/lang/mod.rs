//! The language's meaning: types, values, checking and the interpreter.
//!
//! **Layer.** It uses `deadline`, `syntax`; it is used by `analyze`,
//! `command`, `curve`, `draw`, `load`, `model`, `output`, `production`,
//! `render`, `reverse`, `rewrite`, `shape`, `surface`, `system`, `vv`. Nothing
//! here names a layer above (see ARCHITECTURE.md, "Layers").

pub mod builtins;
pub mod cfmt;
pub mod closure;
pub mod compile;
pub mod eval;
pub mod ir;
pub mod model;
pub mod modules;
pub mod random;
pub mod stdio;
pub mod stencil;
pub mod suggest;
pub mod value;

pub use ir::Program;
pub use modules::{Alphabet, Sym};
pub use stdio::{ProgramOutput, Stream};
pub use value::{Ty, Value};
