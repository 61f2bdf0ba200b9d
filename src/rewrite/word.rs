//! A word: a string of modules, stored flat (symbols, parameter offsets and
//! one parameter array) so that a derivation step allocates nothing per module.

use crate::lang::eval::Emit;
use crate::lang::{Sym, Value};

/// Read access to a sequence of modules, used by context matching.
pub trait Seq {
    fn len(&self) -> usize;
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    fn sym(&self, i: usize) -> Sym;
    fn params(&self, i: usize) -> &[Value];
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Word {
    syms: Vec<Sym>,
    /// `starts[i]..starts[i + 1]` are module `i`'s parameters.
    starts: Vec<u32>,
    params: Vec<Value>,
}

impl Word {
    pub fn new() -> Word {
        Word {
            syms: Vec::new(),
            starts: vec![0],
            params: Vec::new(),
        }
    }

    pub fn with_capacity(modules: usize, params: usize) -> Word {
        let mut starts = Vec::with_capacity(modules + 1);
        starts.push(0);
        Word {
            syms: Vec::with_capacity(modules),
            starts,
            params: Vec::with_capacity(params),
        }
    }

    pub fn len(&self) -> usize {
        self.syms.len()
    }

    pub fn is_empty(&self) -> bool {
        self.syms.is_empty()
    }

    pub fn clear(&mut self) {
        self.syms.clear();
        self.starts.truncate(1);
        self.params.clear();
    }

    pub fn push(&mut self, sym: Sym, params: &[Value]) {
        self.syms.push(sym);
        self.params.extend_from_slice(params);
        self.starts.push(self.params.len() as u32);
    }

    /// Appends a module whose parameters are produced by `fill`.
    pub fn push_with(&mut self, sym: Sym, fill: impl FnOnce(&mut Vec<Value>)) {
        self.syms.push(sym);
        fill(&mut self.params);
        self.starts.push(self.params.len() as u32);
    }

    /// Drops modules from the end until `len` remain.
    pub fn truncate(&mut self, len: usize) {
        if len < self.syms.len() {
            self.syms.truncate(len);
            self.starts.truncate(len + 1);
            self.params.truncate(self.starts[len] as usize);
        }
    }

    pub fn syms(&self) -> &[Sym] {
        &self.syms
    }

    /// Appends module `i` of `other`.
    pub fn push_from(&mut self, other: &Word, i: usize) {
        self.push(other.syms[i], other.params(i));
    }

    /// Reverses the order of the modules (used after a backward step).
    pub fn reverse(&mut self) {
        let mut out = Word::with_capacity(self.len(), self.params.len());
        for i in (0..self.len()).rev() {
            out.push_from(self, i);
        }
        *self = out;
    }

    pub fn iter(&self) -> impl Iterator<Item = (Sym, &[Value])> {
        (0..self.len()).map(move |i| (self.syms[i], self.params(i)))
    }

    pub fn params_mut(&mut self) -> &mut Vec<Value> {
        &mut self.params
    }
}

impl Seq for Word {
    fn len(&self) -> usize {
        self.syms.len()
    }

    #[inline]
    fn sym(&self, i: usize) -> Sym {
        self.syms[i]
    }

    #[inline]
    fn params(&self, i: usize) -> &[Value] {
        &self.params[self.starts[i] as usize..self.starts[i + 1] as usize]
    }
}

impl Word {
    #[inline]
    pub fn params(&self, i: usize) -> &[Value] {
        Seq::params(self, i)
    }

    #[inline]
    pub fn sym(&self, i: usize) -> Sym {
        self.syms[i]
    }
}

impl Emit for Word {
    fn emit(&mut self, sym: Sym, args: &[Value]) {
        self.push(sym, args);
    }
}

/// A word read back to front: a backward step builds its new word reversed.
pub struct Reversed<'a>(pub &'a Word);

impl Seq for Reversed<'_> {
    fn len(&self) -> usize {
        self.0.len()
    }

    fn sym(&self, i: usize) -> Sym {
        self.0.sym(self.0.len() - 1 - i)
    }

    fn params(&self, i: usize) -> &[Value] {
        self.0.params(self.0.len() - 1 - i)
    }
}
