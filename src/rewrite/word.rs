//! A word: a string of modules, stored flat. Each module is a symbol and a
//! run of `f64` slots holding its parameters (a `V2f` takes two slots, a
//! struct the slots of its fields); the module's kind says how to read them.
//! A derivation step therefore copies plain numbers and allocates nothing
//! per module.

use crate::lang::eval::Emit;
use crate::lang::value::{decode_all, encode, StructDef};
use crate::lang::{Alphabet, Sym, Value};

use super::growth::{Growth, RawWord};

/// Read access to a sequence of modules, used by context matching.
pub trait Seq {
    fn len(&self) -> usize;
    fn sym(&self, i: usize) -> Sym;
    /// The parameter slots of module `i`.
    fn data(&self, i: usize) -> &[f64];
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Word {
    syms: Vec<Sym>,
    /// `starts[i]..starts[i + 1]` are module `i`'s slots.
    starts: Vec<u32>,
    data: Vec<f64>,
}

impl Word {
    pub fn new() -> Word {
        Word {
            syms: Vec::new(),
            starts: vec![0],
            data: Vec::new(),
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
        self.data.clear();
    }

    /// Makes room for `modules` more modules with `slots` more slots.
    pub fn reserve(&mut self, modules: usize, slots: usize) {
        self.syms.reserve(modules);
        self.starts.reserve(modules);
        self.data.reserve(slots);
    }

    /// Empties the word and makes room for `modules` modules and `slots`
    /// slots. A buffer too small is replaced rather than grown, so that the
    /// old contents are not copied.
    pub fn clear_with_capacity(&mut self, modules: usize, slots: usize) {
        fn fit<T>(v: &mut Vec<T>, n: usize) {
            v.clear();
            if v.capacity() < n {
                *v = crate::huge::with_capacity(n);
            }
        }
        fit(&mut self.syms, modules);
        fit(&mut self.starts, modules + 1);
        self.starts.push(0);
        fit(&mut self.data, slots);
    }

    /// The number of parameter slots of all modules together.
    pub fn slot_count(&self) -> usize {
        self.data.len()
    }

    /// Appends a module with parameter values (encoded into slots).
    pub fn push(&mut self, sym: Sym, params: &[Value]) {
        self.syms.push(sym);
        for p in params {
            encode(p, &mut self.data);
        }
        self.starts.push(self.data.len() as u32);
    }

    /// Appends a module with raw slots.
    #[inline]
    pub fn push_raw(&mut self, sym: Sym, slots: &[f64]) {
        self.syms.push(sym);
        self.data.extend_from_slice(slots);
        self.starts.push(self.data.len() as u32);
    }

    /// Appends modules `syms`, module `k` with the next `widths[k]` of
    /// `slots`, as `push_raw` on each in turn.
    #[inline]
    pub fn push_run(&mut self, syms: &[Sym], widths: &[usize], slots: &[f64]) {
        let mut at = self.data.len();
        self.syms.extend(syms.iter().copied());
        self.data.extend(slots.iter().copied());
        self.starts.extend(widths.iter().map(|&w| {
            at += w;
            at as u32
        }));
    }

    /// Appends a module whose slots `fill` writes.
    #[inline(always)]
    pub fn push_with(&mut self, sym: Sym, fill: impl FnOnce(&mut Vec<f64>)) {
        self.syms.push(sym);
        fill(&mut self.data);
        self.starts.push(self.data.len() as u32);
    }

    /// Appends module `i` of `other`.
    #[inline]
    pub fn push_from(&mut self, other: &Word, i: usize) {
        self.push_raw(other.syms[i], other.data(i));
    }

    /// Appends modules `range` of `other`, at once.
    #[inline]
    pub fn push_range(&mut self, other: &Word, range: std::ops::Range<usize>) {
        self.syms.extend_from_slice(&other.syms[range.clone()]);
        let (a, b) = (other.starts[range.start], other.starts[range.end]);
        // As `push_raw` computes each offset: the slot count after it.
        let shift = (self.data.len() as u32).wrapping_sub(a);
        self.data
            .extend_from_slice(&other.data[a as usize..b as usize]);
        self.starts.extend(
            other.starts[range.start + 1..=range.end]
                .iter()
                .map(|&s| s.wrapping_add(shift)),
        );
    }

    /// Appends all modules of each of `parts`, in order, copying the
    /// parts at once on rayon's pool (as `fill_parts` writes): each into
    /// its own stretch of the word's room, the new memory touched first by
    /// the thread that fills it. False, and the word as it was, when the
    /// slots would pass the offsets' `u32` range.
    pub fn append_all(&mut self, parts: &[Word]) -> bool {
        self.append_all_read(parts, None)
    }

    /// [`Word::append_all`], the parts' modules given to `growth`'s reader
    /// as they are written ([`Word::fill_parts`]).
    pub(crate) fn append_all_read(&mut self, parts: &[Word], growth: Option<&Growth>) -> bool {
        let counts: Vec<(usize, usize)> = parts.iter().map(|w| (w.len(), w.data.len())).collect();
        self.fill_parts(&counts, growth, |k, out| out.push_word(&parts[k]))
    }

    /// Appends parts whose sizes are known beforehand, written at once on
    /// rayon's pool straight into place: part `k` gets `counts[k]`
    /// (modules, slots) and `fill(k, writer)` writes them in order. When
    /// every part's `fill` returns true having written exactly its share,
    /// the word holds them all and this returns true; otherwise the word
    /// is left as it was and this returns false.
    ///
    /// With `growth`, its reader reads the word's modules while the parts
    /// are written: the modules the word held at once, and each part's
    /// once it and those before it are written. On return the reader has
    /// let go of the word; when this returns false what it read is given
    /// up.
    pub(crate) fn fill_parts(
        &mut self,
        counts: &[(usize, usize)],
        growth: Option<&Growth>,
        fill: impl Fn(usize, &mut PartWriter<'_>) -> bool + Sync,
    ) -> bool {
        use rayon::prelude::*;
        let modules: usize = counts.iter().map(|c| c.0).sum();
        let slots: usize = counts.iter().map(|c| c.1).sum();
        if self.data.len() + slots > u32::MAX as usize {
            return false;
        }
        self.reserve(modules, slots);
        // However the writing ends (a part's `fill` may panic), the reader
        // lets go of the word before it can change.
        let writing = growth.map(|g| {
            let parts: Vec<usize> = counts.iter().map(|c| c.0).collect();
            g.begin(self.raw(), self.len(), &parts)
        });
        let mut base = self.data.len();
        let (mut syms, mut starts, mut data) = (
            &mut self.syms.spare_capacity_mut()[..modules],
            &mut self.starts.spare_capacity_mut()[..modules],
            &mut self.data.spare_capacity_mut()[..slots],
        );
        let mut writers = Vec::with_capacity(counts.len());
        for &(m, n) in counts {
            let (s, rest) = std::mem::take(&mut syms).split_at_mut(m);
            syms = rest;
            let (o, rest) = std::mem::take(&mut starts).split_at_mut(m);
            starts = rest;
            let (d, rest) = std::mem::take(&mut data).split_at_mut(n);
            data = rest;
            writers.push(PartWriter {
                syms: s,
                starts: o,
                data: d,
                base: base as u32,
                modules: 0,
                slots: 0,
            });
            base += n;
        }
        let write = |(k, mut w): (usize, PartWriter<'_>)| {
            fill(k, &mut w) && w.modules == w.syms.len() && w.slots == w.data.len()
        };
        let whole = match &writing {
            // The reader walks the parts on a core of its own, as the other
            // threads write them in order: each takes the first part that
            // none has taken.
            Some(writing) => {
                let writers: Vec<_> = (writers.into_iter())
                    .map(|w| std::sync::Mutex::new(Some(w)))
                    .collect();
                let next = std::sync::atomic::AtomicUsize::new(0);
                let threads = rayon::current_num_threads().saturating_sub(1).max(1);
                (0..threads)
                    .into_par_iter()
                    .map(|_| {
                        let mut whole = true;
                        loop {
                            let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            let Some(cell) = writers.get(k) else {
                                break whole;
                            };
                            let w = cell.lock().unwrap_or_else(|e| e.into_inner()).take();
                            // The reader is told once the part's writer is
                            // gone, its call returned.
                            let written = w.is_some_and(|w| write((k, w)));
                            if written {
                                writing.part_written(k);
                            }
                            whole &= written;
                        }
                    })
                    .reduce(|| true, |a, b| a & b)
            }
            None => writers
                .into_par_iter()
                .enumerate()
                .map(write)
                .reduce(|| true, |a, b| a & b),
        };
        if let Some(mut writing) = writing {
            if whole {
                writing.keep();
            }
            // Dropped here: the reader lets go of the word before its
            // lengths change.
        }
        if whole {
            // SAFETY: every writer wrote each element of its stretch of the
            // spare capacity (it counts what it wrote, never past the
            // stretch's end, and `whole` says each count reached its
            // stretch's length); the stretches cover the first `modules`
            // (`slots`) places of each array.
            unsafe {
                self.syms.set_len(self.syms.len() + modules);
                self.starts.set_len(self.starts.len() + modules);
                self.data.set_len(self.data.len() + slots);
            }
        }
        whole
    }

    /// Drops modules from the end until `len` remain.
    pub fn truncate(&mut self, len: usize) {
        if len < self.syms.len() {
            self.syms.truncate(len);
            self.starts.truncate(len + 1);
            self.data.truncate(self.starts[len] as usize);
        }
    }

    /// Moves the first `k` modules to the end.
    pub fn rotate_left(&mut self, k: usize) {
        if k == 0 || k >= self.len() {
            return;
        }
        let mut out = Word::new();
        out.reserve(self.len(), self.data.len());
        for i in (k..self.len()).chain(0..k) {
            out.push_from(self, i);
        }
        *self = out;
    }

    /// Reverses the order of the modules (used after a backward step).
    pub fn reverse(&mut self) {
        let mut out = Word::new();
        out.reserve(self.len(), self.data.len());
        for i in (0..self.len()).rev() {
            out.push_from(self, i);
        }
        *self = out;
    }

    pub fn syms(&self) -> &[Sym] {
        &self.syms
    }

    #[inline]
    pub fn sym(&self, i: usize) -> Sym {
        self.syms[i]
    }

    #[inline(always)]
    pub fn data(&self, i: usize) -> &[f64] {
        &self.data[self.starts[i] as usize..self.starts[i + 1] as usize]
    }

    /// The word as borrowed arrays: what the turtle's walk reads.
    pub(crate) fn slices(&self) -> Slices<'_> {
        Slices {
            syms: &self.syms,
            starts: &self.starts,
            data: &self.data,
        }
    }

    /// Where the word's arrays start, for [`Growth`] to read them.
    pub(super) fn raw(&self) -> RawWord {
        RawWord {
            syms: self.syms.as_ptr(),
            starts: self.starts.as_ptr(),
            data: self.data.as_ptr(),
        }
    }

    /// The storage, for engine fast paths that append many modules at once.
    /// Callers keep the invariants: one symbol and one offset per module,
    /// offsets increasing and ending at the slot count.
    pub(crate) fn raw_parts_mut(&mut self) -> (&mut Vec<Sym>, &mut Vec<u32>, &mut Vec<f64>) {
        (&mut self.syms, &mut self.starts, &mut self.data)
    }

    /// The slots of all modules, in order.
    pub fn all_slots(&self) -> &[f64] {
        &self.data
    }

    /// The parameters of module `i` as values.
    pub fn values(&self, i: usize, alphabet: &Alphabet, structs: &[StructDef]) -> Vec<Value> {
        self.slices().values(i, alphabet, structs)
    }

    /// Every module with its parameter values, for output and tests.
    pub fn modules<'a>(
        &'a self,
        alphabet: &'a Alphabet,
        structs: &'a [StructDef],
    ) -> impl Iterator<Item = (Sym, Vec<Value>)> + 'a {
        (0..self.len()).map(move |i| (self.syms[i], self.values(i, alphabet, structs)))
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
    fn data(&self, i: usize) -> &[f64] {
        Word::data(self, i)
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

    fn data(&self, i: usize) -> &[f64] {
        self.0.data(self.0.len() - 1 - i)
    }
}

/// A word's arrays, borrowed: all of a [`Word`] ([`Word::slices`]), or the
/// modules of a step's new word written so far ([`Growth`]). The same
/// invariants: one symbol per module, and one more offset, increasing and
/// ending at the slot count.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slices<'a> {
    pub(super) syms: &'a [Sym],
    pub(super) starts: &'a [u32],
    pub(super) data: &'a [f64],
}

impl<'a> Slices<'a> {
    pub(crate) fn len(&self) -> usize {
        self.syms.len()
    }

    pub(crate) fn syms(&self) -> &'a [Sym] {
        self.syms
    }

    #[inline]
    pub(crate) fn sym(&self, i: usize) -> Sym {
        self.syms[i]
    }

    /// Where each module's slots start, and after the last one the slot
    /// count: one more than the modules.
    pub(crate) fn offsets(&self) -> &'a [u32] {
        self.starts
    }

    pub(crate) fn all_slots(&self) -> &'a [f64] {
        self.data
    }

    /// The first `modules` modules (all of them when there are fewer).
    #[cfg(test)]
    pub(crate) fn prefix(&self, modules: usize) -> Slices<'a> {
        let m = modules.min(self.len());
        Slices {
            syms: &self.syms[..m],
            starts: &self.starts[..=m],
            data: &self.data[..self.starts[m] as usize],
        }
    }

    /// The parameters of module `i` as values.
    pub(crate) fn values(
        &self,
        i: usize,
        alphabet: &Alphabet,
        structs: &[StructDef],
    ) -> Vec<Value> {
        let d = &self.data[self.starts[i] as usize..self.starts[i + 1] as usize];
        decode_all(alphabet.layout(self.syms[i], d.len(), structs), d, structs)
    }
}

/// Writes one part of [`Word::fill_parts`] into its stretch of the new
/// word's arrays, module after module.
pub(crate) struct PartWriter<'a> {
    syms: &'a mut [std::mem::MaybeUninit<Sym>],
    starts: &'a mut [std::mem::MaybeUninit<u32>],
    data: &'a mut [std::mem::MaybeUninit<f64>],
    /// The word's slot count before this part.
    base: u32,
    modules: usize,
    slots: usize,
}

impl PartWriter<'_> {
    /// Writes the modules of `w`, slots and all; false (and nothing
    /// written) when they would pass the part's share.
    pub(crate) fn push_word(&mut self, w: &Word) -> bool {
        self.push_range(w, 0..w.len())
    }

    /// Writes the modules `run` of `w`, slots and all; false (and nothing
    /// written) when they would pass the part's share.
    pub(crate) fn push_range(&mut self, w: &Word, run: std::ops::Range<usize>) -> bool {
        let (lo, hi) = (w.starts[run.start], w.starts[run.end]);
        let (m, s) = (self.modules + run.len(), self.slots + (hi - lo) as usize);
        if m > self.syms.len() || s > self.data.len() {
            return false;
        }
        self.syms[self.modules..m].write_copy_of_slice(&w.syms[run.clone()]);
        // Offsets in this part's share, which `fill_parts` checked to fit.
        let base = self.base + self.slots as u32;
        for (o, &x) in self.starts[self.modules..m]
            .iter_mut()
            .zip(&w.starts[run.start + 1..=run.end])
        {
            o.write(x - lo + base);
        }
        self.data[self.slots..s].write_copy_of_slice(&w.data[lo as usize..hi as usize]);
        self.modules = m;
        self.slots = s;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parts written in place, as runs of another word's modules, make the
    /// word that pushing the same modules one by one makes; a part that
    /// writes less or more than its share leaves the word as it was.
    #[test]
    fn parts_filled_in_place_are_the_pushed_word() {
        let (a, b, c) = (Sym(3), Sym(5), Sym(7));
        let parts: Vec<Vec<(Sym, Vec<f64>)>> = vec![
            vec![(a, vec![1.0, 2.0]), (b, vec![])],
            vec![],
            vec![(c, vec![-0.0]), (a, vec![3.5, f64::MAX]), (b, vec![4.0])],
        ];
        let mut want = Word::new();
        want.push_raw(b, &[9.0]);
        for m in parts.iter().flatten() {
            want.push_raw(m.0, &m.1);
        }
        // The modules to copy from: the parts' after one of slots of its
        // own, so that no run starts at slot 0.
        let mut src = Word::new();
        src.push_raw(c, &[7.0, 8.0]);
        let mut runs = Vec::new();
        for p in &parts {
            let from = src.len();
            for m in p {
                src.push_raw(m.0, &m.1);
            }
            runs.push(from..src.len());
        }
        let counts: Vec<(usize, usize)> = parts
            .iter()
            .map(|p| (p.len(), p.iter().map(|m| m.1.len()).sum()))
            .collect();
        let mut w = Word::new();
        w.push_raw(b, &[9.0]);
        let before = w.clone();
        // The last part a module at a time, the others as whole runs.
        assert!(w.fill_parts(&counts, None, |k, out| match k {
            2 => runs[k].clone().all(|i| out.push_range(&src, i..i + 1)),
            _ => out.push_range(&src, runs[k].clone()),
        }));
        assert_eq!(w, want);
        for i in 0..w.len() {
            assert_eq!(w.data(i), want.data(i));
        }
        // One module short in the last part, then one too many in the first.
        let mut short = before.clone();
        let fill_short = |k: usize, out: &mut PartWriter<'_>| {
            let r = runs[k].clone();
            let end = if k == 2 { r.end - 1 } else { r.end };
            out.push_range(&src, r.start..end)
        };
        assert!(!short.fill_parts(&counts, None, fill_short));
        assert_eq!(short, before);
        let mut long = before.clone();
        let fill_long = |k: usize, out: &mut PartWriter<'_>| {
            out.push_range(&src, runs[k].clone()) && (k != 0 || out.push_range(&src, 0..1))
        };
        assert!(!long.fill_parts(&counts, None, fill_long));
        assert_eq!(long, before);
    }
}
