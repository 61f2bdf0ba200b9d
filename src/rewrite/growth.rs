//! A step's new word, read on another thread while the step writes it.
//!
//! A derivation's last step writes its word in parts on rayon's pool
//! ([`Word::fill_parts`]); the turtle can walk the modules of the finished
//! parts at the front of the word while the later ones are being written,
//! and then walk the rest. [`Growth`] is the meeting place: the writer
//! says which stretch of the new word is finished, the reader walks it.
//!
//! The reader sees the word's arrays only while their memory cannot
//! change: while [`Word::fill_parts`] runs (which writes each place of the
//! word once, and tells the growth which parts are whole), and while the
//! finished word is handed over ([`Growth::hand_over`], which holds the word
//! borrowed until the reader has read it all). Before the word may change
//! (a [`Writing`] dropped, [`Growth::abandon`]) the writer waits for the
//! reader to let go of it.

use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};

use super::word::{Slices, Word};
use crate::lang::Sym;

/// Where a word's three arrays start. Read only through [`Growth`]'s
/// protocol.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RawWord {
    pub(super) syms: *const Sym,
    pub(super) starts: *const u32,
    pub(super) data: *const f64,
}

// SAFETY: a `RawWord` is only addresses; the memory behind it is read
// through `RawWord::slices`, whose callers (in this module) keep the
// protocol that makes the read race-free.
unsafe impl Send for RawWord {}

impl RawWord {
    /// The first `modules` modules of the word.
    ///
    /// # Safety
    /// Those modules must be written (their symbols, their offsets and the
    /// one after the last, and the slots up to that offset), the writes
    /// must happen before this call, and none of that memory may be written
    /// or freed while the slices live.
    unsafe fn slices<'a>(self, modules: usize) -> Slices<'a> {
        // SAFETY: as the caller promises.
        unsafe {
            let syms = std::slice::from_raw_parts(self.syms, modules);
            let starts = std::slice::from_raw_parts(self.starts, modules + 1);
            let data = std::slice::from_raw_parts(self.data, starts[modules] as usize);
            Slices { syms, starts, data }
        }
    }
}

/// What reads a word as it grows ([`Growth::read_with`]).
pub(crate) trait Reader {
    /// A word of `total` modules is coming: forget anything read before.
    fn start(&mut self, total: usize);
    /// How many modules from the word's start have been read.
    fn read_so_far(&self) -> usize;
    /// Reads on to the end of `word`, whose first [`Reader::read_so_far`]
    /// modules are those read before. False when it can read no further.
    fn read(&mut self, word: Slices<'_>) -> bool;
}

/// The writer's side of a growth while [`Word::fill_parts`] writes the
/// word ([`Growth::begin`]). When it is dropped the writer is done with
/// the word's arrays, which may change from then on: the drop waits until
/// the reader lets go of them. The word is given up (the reader starts
/// again on the next one) unless [`Writing::keep`] was called, so a part
/// that panics gives it up too.
pub(super) struct Writing<'g> {
    growth: &'g Growth,
    kept: bool,
}

impl Writing<'_> {
    /// Part `k` is written, all of it, and nothing refers to it but the
    /// word.
    pub(super) fn part_written(&self, k: usize) {
        let g = self.growth;
        let mut s = g.lock();
        if let Some(w) = s.written.get_mut(k) {
            *w = true;
            Growth::advance_ready(&mut s);
            g.changed.notify_all();
        }
    }

    /// Every part is written: the word is kept.
    pub(super) fn keep(&mut self) {
        self.kept = true;
    }
}

impl Drop for Writing<'_> {
    fn drop(&mut self) {
        let g = self.growth;
        let mut s = g.lock();
        s.closing = true;
        while s.reading {
            s = g.wait(s);
        }
        s.closing = false;
        s.raw = None;
        s.restart |= !self.kept;
        g.changed.notify_all();
    }
}

/// Runs `write` on this thread while `read` reads a growth on a thread of
/// its own: what each returned, or the reader's panic (nothing from `read`
/// when no thread could be started, and then nobody reads), for the caller
/// to weigh against what `write` says. However `write` ends, the reader is
/// stopped before this returns or unwinds.
pub(crate) fn alongside<W, R: Send>(
    write: impl FnOnce(&Arc<Growth>) -> W,
    read: impl FnOnce(&Growth) -> R + Send,
) -> (W, Option<std::thread::Result<R>>) {
    struct Stop<'g>(&'g Growth);
    impl Drop for Stop<'_> {
        fn drop(&mut self) {
            self.0.abandon();
        }
    }
    let growth = Arc::new(Growth::default());
    std::thread::scope(|scope| {
        let g = &*growth;
        let reader = std::thread::Builder::new().spawn_scoped(scope, move || read(g));
        let stop = Stop(&growth);
        if reader.is_err() {
            growth.abandon();
        }
        let written = write(&growth);
        drop(stop);
        (written, reader.ok().map(|r| r.join()))
    })
}

/// A step's new word shared between the thread that writes it and one that
/// reads it as it grows.
#[derive(Default)]
pub(crate) struct Growth {
    state: Mutex<State>,
    changed: Condvar,
}

#[derive(Default)]
struct State {
    /// The word's arrays while they may be read, and how many modules from
    /// its start are written.
    raw: Option<RawWord>,
    ready: usize,
    /// How many modules the word will hold.
    total: usize,
    /// The module each part being written ends at, and which are written.
    part_ends: Vec<usize>,
    written: Vec<bool>,
    /// The reader holds slices of the word.
    reading: bool,
    /// The writer waits for the reader to let go: it starts no read.
    closing: bool,
    /// What was read belongs to a word given up: the reader starts again.
    restart: bool,
    /// The word is handed over whole ([`Growth::hand_over`]).
    whole: bool,
    /// The reader has read the whole word, or can read no further, or is
    /// gone.
    done: bool,
    /// The writer gave up: the reader stops.
    abandoned: bool,
}

impl Growth {
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn wait<'g>(&self, s: MutexGuard<'g, State>) -> MutexGuard<'g, State> {
        self.changed.wait(s).unwrap_or_else(PoisonError::into_inner)
    }

    /// The writer starts to write parts of `parts[k]` modules each after
    /// the `base` modules the word at `raw` already holds; it says which are
    /// written, and when it is done, through what this returns.
    pub(super) fn begin(&self, raw: RawWord, base: usize, parts: &[usize]) -> Writing<'_> {
        let mut s = self.lock();
        let mut end = base;
        s.part_ends = parts
            .iter()
            .map(|&m| {
                end += m;
                end
            })
            .collect();
        s.written = vec![false; parts.len()];
        s.total = end;
        s.raw = Some(raw);
        s.ready = base;
        Self::advance_ready(&mut s);
        self.changed.notify_all();
        Writing {
            growth: self,
            kept: false,
        }
    }

    /// Moves `ready` over the written parts at the front.
    fn advance_ready(s: &mut State) {
        let first = s
            .written
            .iter()
            .position(|&w| !w)
            .unwrap_or(s.written.len());
        if let Some(k) = first.checked_sub(1) {
            s.ready = s.ready.max(s.part_ends[k]);
        }
    }

    /// Hands over the finished word: the reader reads the rest of it (all
    /// of it when what it read belonged to a word given up). Returns once
    /// the reader has read it all, can read no further, or is gone.
    pub(crate) fn hand_over(&self, word: &Word) {
        let mut s = self.lock();
        s.raw = Some(word.raw());
        s.ready = word.len();
        s.total = word.len();
        s.written.clear();
        s.part_ends.clear();
        s.whole = true;
        self.changed.notify_all();
        while !s.done && !s.abandoned {
            s = self.wait(s);
        }
        s.raw = None;
    }

    /// Stops the reader, without a word (a hand-over after this returns at
    /// once); returns once it lets go of the word's arrays.
    pub(crate) fn abandon(&self) {
        let mut s = self.lock();
        s.abandoned = true;
        s.closing = true;
        self.changed.notify_all();
        while s.reading {
            s = self.wait(s);
        }
        s.raw = None;
    }

    /// Reads the word with `reader` as it grows, at most `stride` modules
    /// at a time (so that a writer waiting for the reader to let go waits
    /// no longer than that takes), until the word is handed over and read,
    /// or abandoned. True when the reader read a word handed over, all of
    /// it or as far as it could.
    pub(crate) fn read_with(&self, reader: &mut impl Reader, stride: usize) -> bool {
        // Whatever way the reader leaves, the writer waiting for it is told.
        struct Gone<'g>(&'g Growth);
        impl Drop for Gone<'_> {
            fn drop(&mut self) {
                let mut s = self.0.lock();
                s.reading = false;
                s.done = true;
                self.0.changed.notify_all();
            }
        }
        let _gone = Gone(self);
        let (mut started, mut stuck) = (false, false);
        let mut s = self.lock();
        loop {
            if s.abandoned {
                return false;
            }
            if std::mem::take(&mut s.restart) {
                (started, stuck) = (false, false);
            }
            if let Some(raw) = s.raw {
                if !started {
                    reader.start(s.total);
                    started = true;
                }
                let read = reader.read_so_far();
                if !stuck && !s.closing && s.ready > read {
                    let upto = s.ready.min(read.saturating_add(stride.max(1)));
                    s.reading = true;
                    drop(s);
                    // SAFETY: the first `ready` modules are written: by
                    // parts that said so through `Writing::part_written` (under the
                    // lock taken since), or as the word was when
                    // `begin`/`hand_over` gave it. The writer changes or frees
                    // the word only after a `Writing` is dropped or `abandon`, or
                    // after `hand_over` returns, all of which wait until
                    // `reading` is false again.
                    let ok = reader.read(unsafe { raw.slices(upto) });
                    s = self.lock();
                    s.reading = false;
                    stuck |= !ok;
                    self.changed.notify_all();
                    continue;
                }
                if s.whole {
                    return true;
                }
            }
            s = self.wait(s);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader that copies what it reads, checking that each read goes
    /// on from the last and that what it had read is still there.
    #[derive(Default)]
    struct Copying {
        word: Word,
        starts: usize,
        reads: usize,
        /// Fail once this many modules are read.
        fail_at: Option<usize>,
    }

    impl Reader for Copying {
        fn start(&mut self, _total: usize) {
            self.word = Word::new();
            self.starts += 1;
        }

        fn read_so_far(&self) -> usize {
            self.word.len()
        }

        fn read(&mut self, word: Slices<'_>) -> bool {
            let had = self.word.len();
            assert!(word.len() > had, "a read that reads nothing");
            let slots = |i: usize| &word.data[word.starts[i] as usize..word.starts[i + 1] as usize];
            for i in 0..had {
                assert_eq!(word.sym(i), self.word.sym(i));
                assert_eq!(slots(i), self.word.data(i));
            }
            for i in had..word.len() {
                self.word.push_raw(word.sym(i), slots(i));
            }
            self.reads += 1;
            self.fail_at.is_none_or(|at| self.word.len() < at)
        }
    }

    /// Parts of `sizes[k]` modules, module `j` of part `k` holding `j`
    /// slots (of a pattern that `seed` varies).
    fn parts(sizes: &[usize], seed: u32) -> Vec<Word> {
        sizes
            .iter()
            .enumerate()
            .map(|(k, &n)| {
                let mut w = Word::new();
                for j in 0..n {
                    let slots: Vec<f64> = (0..j % 4)
                        .map(|s| (seed as usize * 1000 + k * 100 + j * 10 + s) as f64)
                        .collect();
                    w.push_raw(Sym(((k * 7 + j) % 50) as u16), &slots);
                }
                w
            })
            .collect()
    }

    /// Runs `reader` on a thread of its own while `write` writes and hands
    /// over words on this one; what `read_with` returned, and the reader.
    fn read_while(reader: Copying, write: impl FnOnce(&Growth)) -> (bool, Copying) {
        let ((), read) = alongside(
            |g| write(g),
            move |g| {
                let mut reader = reader;
                (g.read_with(&mut reader, 5), reader)
            },
        );
        match read.expect("a thread to read on") {
            Ok(read) => read,
            Err(panic) => std::panic::resume_unwind(panic),
        }
    }

    /// In pools of one to three threads, with parts of every size (none
    /// among them), a word written in parts with a reader is the word
    /// written without one, and the reader has read it all, in pieces of
    /// at most five modules, having started once.
    #[test]
    fn the_reader_reads_the_word_as_it_is_written() {
        let sizes = [3, 0, 17, 1, 40, 0, 0, 9, 64, 2];
        for threads in 1..=3 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut want = Word::new();
            want.push_raw(Sym(9), &[0.5]);
            let mut w = want.clone();
            want.append_all(&parts(&sizes, 1));
            let (whole, reader) = read_while(Copying::default(), |g| {
                assert!(pool.install(|| w.append_all_read(&parts(&sizes, 1), Some(g))));
                g.hand_over(&w);
            });
            assert!(whole);
            assert_eq!(w, want, "{threads} threads");
            assert_eq!(reader.word, want, "{threads} threads");
            assert_eq!(reader.starts, 1);
            assert!(reader.reads >= want.len() / 5, "{}", reader.reads);
        }
    }

    /// A word whose parts fail is given up: the reader starts again on the
    /// word handed over, another one, and reads just that.
    #[test]
    fn a_word_given_up_is_read_again_from_the_start() {
        let sizes = [10, 10, 10, 10];
        let (whole, reader) = read_while(Copying::default(), |g| {
            let mut w = Word::new();
            let counts: Vec<(usize, usize)> = parts(&sizes, 1)
                .iter()
                .map(|p| (p.len(), p.slot_count()))
                .collect();
            let first = parts(&sizes, 1);
            // The last part writes one module short.
            let written = w.fill_parts(&counts, Some(g), |k, out| match k {
                3 => out.push_range(&first[k], 0..9),
                k => out.push_word(&first[k]),
            });
            assert!(!written);
            assert!(w.is_empty());
            let mut other = Word::new();
            other.append_all(&parts(&[5, 8], 2));
            g.hand_over(&other);
            assert_eq!(other.len(), 13);
        });
        assert!(whole);
        let mut want = Word::new();
        want.append_all(&parts(&[5, 8], 2));
        assert_eq!(reader.word, want);
        assert!(reader.starts >= 1);
    }

    /// A reader that can read no further, one never handed a word, and one
    /// that panics: none keeps the writer waiting; nor does a writer that
    /// panics keep the reader waiting.
    #[test]
    fn the_writer_never_waits_for_a_reader_that_is_done() {
        let mut w = Word::new();
        w.append_all(&parts(&[30, 30], 3));
        let stuck = Copying {
            fail_at: Some(12),
            ..Copying::default()
        };
        let (whole, reader) = read_while(stuck, |g| g.hand_over(&w));
        assert!(whole);
        assert!(
            (12..=16).contains(&reader.word.len()),
            "{}",
            reader.word.len()
        );
        let (whole, reader) = read_while(Copying::default(), |_| {});
        assert!(!whole);
        assert_eq!(reader.reads, 0);
        // A panic in the reader ends its reading: the hand-over returns.
        struct Panics;
        impl Reader for Panics {
            fn start(&mut self, _: usize) {}
            fn read_so_far(&self) -> usize {
                0
            }
            fn read(&mut self, _: Slices<'_>) -> bool {
                panic!("a reader that panics")
            }
        }
        let ((), read) = alongside(|g| g.hand_over(&w), |g| g.read_with(&mut Panics, 5));
        assert!(read.expect("a thread to read on").is_err());
        // A writer that panics stops the reader, which would otherwise wait
        // for it forever.
        let panicked = std::panic::catch_unwind(|| {
            alongside(
                |_| panic!("a writer that panics"),
                |g| g.read_with(&mut Copying::default(), 5),
            )
        });
        assert!(panicked.is_err());
    }

    /// A part that panics after others were read: the reader lets go of
    /// the word before the unwinding frees it (a part of a million modules
    /// has a mapping of its own, which is unmapped when freed).
    #[test]
    fn a_part_that_panics_lets_the_reader_go_before_the_word_is_freed() {
        struct Slow(Copying);
        impl Reader for Slow {
            fn start(&mut self, total: usize) {
                self.0.start(total);
            }
            fn read_so_far(&self) -> usize {
                self.0.read_so_far()
            }
            fn read(&mut self, word: Slices<'_>) -> bool {
                std::thread::sleep(std::time::Duration::from_millis(20));
                self.0.read(word)
            }
        }
        let big = parts(&[1 << 20], 4);
        let counts = [(big[0].len(), big[0].slot_count()), (10, 0)];
        let unwound = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            alongside(
                |g| {
                    let mut w = Word::new();
                    w.fill_parts(&counts, Some(g), |k, out| {
                        if k == 0 {
                            return out.push_word(&big[0]);
                        }
                        std::thread::sleep(std::time::Duration::from_millis(50));
                        panic!("a part that panics")
                    })
                },
                |g| g.read_with(&mut Slow(Copying::default()), 1 << 18),
            )
        }));
        assert!(unwound.is_err());
    }
}
