//! Context matching on words, with lpfg's rules for branches (manual,
//! appendix "Production Matching"), `ignore:`/`consider:` and rings.
//!
//! Right context: a `[` in the word that the pattern does not expect skips the
//! whole branch; a `]` in the pattern skips the rest of the word's branch up
//! to its first unmatched `]`; a `]` in the word ends the match.
//! Left context: `[` is always skipped (the parent lies before it); a `]`
//! skips the whole branch back to its `[`.
//!
//! Skipping a branch, or a run of modules that `ignore:`/`consider:` skip,
//! is one look-up in [`Tables`] made once per word, so that a step stays
//! linear however deeply branches nest and however long the runs; without
//! tables (the new word, still being built) the modules are walked.

use std::sync::OnceLock as OnceCell;

use crate::lang::ir::{Filter, Pattern};
use crate::lang::Sym;

use super::word::Seq;

/// What context matching needs besides the word and the pattern.
#[derive(Clone, Copy)]
pub struct Rules<'a> {
    pub sb: Sym,
    pub eb: Sym,
    pub filter: &'a Filter,
    pub ring: bool,
    /// The tables of the word being matched, when it does not change
    /// while it is matched.
    pub tables: Option<&'a Tables>,
}

/// No position.
const NONE: u32 = u32::MAX;

/// Where context matching jumps to in one word: each made on first use.
/// Positions are the word's, or, for a ring, those of the word written
/// twice (`0..2n`), so that a branch or a run may cross the ring's seam; a
/// position `p` of a match is `p mod n` in the word.
#[derive(Debug, Default)]
pub struct Tables {
    /// For a `[`, the position of the `]` that closes it; for a `]`, the
    /// position of the `[` it closes (a `]` of the second copy for a
    /// ring); `NONE` when unmatched.
    partner: OnceCell<Vec<u32>>,
    /// For every position, the first `]` at or after it that closes the
    /// branch it is in.
    close: OnceCell<Vec<u32>>,
    /// For one filter (the first asked for), at every position: the first
    /// module at or after it where a right context stops skipping (a
    /// bracket, or a module the filter keeps), and the last one at or
    /// before it where a left context does (a `]`, or a module other than
    /// `[` that the filter keeps).
    runs: OnceCell<Runs>,
}

#[derive(Debug)]
struct Runs {
    filter: Filter,
    next: Vec<u32>,
    prev: Vec<u32>,
}

impl Tables {
    /// Forgets the last word's tables.
    pub fn clear(&mut self) {
        self.partner.take();
        self.close.take();
        self.runs.take();
    }

    /// The runs of `r.filter`, unless the tables hold another filter's.
    fn runs<S: Seq + ?Sized>(&self, seq: &S, r: &Rules) -> Option<&Runs> {
        let len = Self::span(seq, r)?;
        let runs = self.runs.get_or_init(|| {
            let n = seq.len();
            let sym = |p: usize| seq.sym(if p >= n { p - n } else { p });
            let mut next = vec![NONE; len];
            let mut prev = vec![NONE; len];
            let mut at = NONE;
            for p in (0..len).rev() {
                let s = sym(p);
                if s == r.sb || s == r.eb || !r.filter.skips(s) {
                    at = p as u32;
                }
                next[p] = at;
            }
            at = NONE;
            for (p, slot) in prev.iter_mut().enumerate() {
                let s = sym(p);
                if s == r.eb || (s != r.sb && !r.filter.skips(s)) {
                    at = p as u32;
                }
                *slot = at;
            }
            Runs {
                filter: r.filter.clone(),
                next,
                prev,
            }
        });
        (runs.filter == *r.filter).then_some(runs)
    }

    /// The length of the table of `seq`, or `None` for words too long for
    /// 32-bit positions (their brackets are counted instead).
    fn span<S: Seq + ?Sized>(seq: &S, r: &Rules) -> Option<usize> {
        let len = if r.ring { 2 * seq.len() } else { seq.len() };
        (len < NONE as usize).then_some(len)
    }

    fn partner<S: Seq + ?Sized>(&self, seq: &S, r: &Rules) -> Option<&[u32]> {
        let len = Self::span(seq, r)?;
        Some(self.partner.get_or_init(|| {
            let n = seq.len();
            let mut partner = vec![NONE; len];
            let mut open = Vec::new();
            for p in 0..len {
                let s = seq.sym(if p >= n { p - n } else { p });
                if s == r.sb {
                    open.push(p);
                } else if s == r.eb {
                    if let Some(q) = open.pop() {
                        partner[p] = q as u32;
                        partner[q] = p as u32;
                    }
                }
            }
            partner
        }))
    }

    fn close<S: Seq + ?Sized>(&self, seq: &S, r: &Rules) -> Option<&[u32]> {
        let partner = self.partner(seq, r)?;
        Some(self.close.get_or_init(|| {
            let n = seq.len();
            let len = partner.len();
            let mut close = vec![NONE; len];
            for p in (0..len).rev() {
                let s = seq.sym(if p >= n { p - n } else { p });
                let after = |q: usize| close.get(q).copied().unwrap_or(NONE);
                close[p] = if s == r.eb {
                    p as u32
                } else if s == r.sb {
                    match partner[p] {
                        NONE => NONE,
                        m => after(m as usize + 1),
                    }
                } else {
                    after(p + 1)
                };
            }
            close
        }))
    }

    /// Where position `pos` (going forward, which may be past the end of a
    /// ring) lies in the table: the table position and what to add to it.
    fn forward_at(pos: usize, n: usize, ring: bool) -> (usize, usize) {
        let off = if ring { pos % n } else { pos };
        (off, pos - off)
    }
}

/// Past modules that `r.filter` skips, from `pos` on, in one look-up: the
/// first position where a right context stops skipping, or `end` if none
/// comes before it. Only for a pattern whose module the filter keeps,
/// which none of the skipped modules can match; `None` without tables
/// for this filter (the caller then steps one module at a time).
fn skip_run_forward<S: Seq + ?Sized>(seq: &S, pos: usize, end: usize, r: Rules) -> Option<usize> {
    if pos >= end {
        return Some(pos);
    }
    let runs = r.tables?.runs(seq, &r)?;
    let (off, base) = Tables::forward_at(pos, seq.len(), r.ring);
    Some(match runs.next[off] {
        NONE => end,
        q => (base + q as usize).min(end),
    })
}

/// Back past `[` and modules that `r.filter` skips, from `pos` down, in
/// one look-up: the last position where a left context stops skipping, or
/// `floor - 1` if none comes before it. Only for a pattern that is not
/// `[` and whose module the filter keeps; `None` without tables for this
/// filter.
fn skip_run_backward<S: Seq + ?Sized>(
    seq: &S,
    pos: isize,
    floor: isize,
    r: Rules,
) -> Option<isize> {
    if pos < floor {
        return Some(pos);
    }
    let runs = r.tables?.runs(seq, &r)?;
    // Backward, a ring's position is looked up in the second copy.
    let n = seq.len() as isize;
    let off = if r.ring { pos.rem_euclid(n) + n } else { pos };
    Some(match runs.prev[off as usize] {
        NONE => floor - 1,
        q => (pos - off + q as isize).max(floor - 1),
    })
}

/// `pos % n` for `pos < 2n`, without a division.
#[inline]
fn wrap(pos: usize, n: usize) -> usize {
    if pos >= n {
        pos - n
    } else {
        pos
    }
}

/// True when module `i` matches pattern `p` by symbol and, for predefined
/// modules with several overloads, by the overload (its width in slots).
#[inline]
pub fn module_matches<S: Seq + ?Sized>(seq: &S, i: usize, p: &Pattern) -> bool {
    seq.sym(i) == p.sym && p.width.is_none_or(|w| seq.data(i).len() == w)
}

/// Matches `pats` to the right, starting at absolute position `start`.
/// In a ring, positions wrap, and at most one turn is examined. Pushes the
/// matched indices and returns the position after the last match.
#[inline]
pub fn match_right<S: Seq + ?Sized>(
    seq: &S,
    start: usize,
    pats: &[Pattern],
    r: Rules,
    out: &mut Vec<usize>,
) -> Option<usize> {
    let n = seq.len();
    if n == 0 {
        return pats.is_empty().then_some(start);
    }
    // A ring's positions count modulo n: from one turn on at most, so
    // that `wrap` finds every position examined.
    let start = if r.ring && start >= n {
        start % n
    } else {
        start
    };
    let end = if r.ring { start + n } else { n };
    let mut pos = start;
    for p in pats {
        loop {
            if pos >= end {
                return None;
            }
            let i = wrap(pos, n);
            if module_matches(seq, i, p) {
                out.push(i);
                pos += 1;
                break;
            }
            let s = seq.sym(i);
            if s == r.sb {
                pos = skip_branch_forward(seq, pos, end, r)?;
            } else if p.sym == r.eb {
                pos = first_unmatched_eb(seq, pos, end, r)?;
            } else if s == r.eb {
                return None;
            } else if r.filter.skips(s) {
                pos += 1;
                if !r.filter.skips(p.sym) {
                    pos = skip_run_forward(seq, pos, end, r).unwrap_or(pos);
                }
            } else {
                return None;
            }
        }
    }
    Some(pos)
}

/// From a `[` at `pos`, the position after its matching `]`.
fn skip_branch_forward<S: Seq + ?Sized>(
    seq: &S,
    pos: usize,
    end: usize,
    r: Rules,
) -> Option<usize> {
    let n = seq.len();
    if let Some(partner) = r.tables.and_then(|t| t.partner(seq, &r)) {
        let (off, base) = Tables::forward_at(pos, n, r.ring);
        return match partner[off] {
            NONE => None,
            m => Some(base + m as usize + 1).filter(|&q| q <= end),
        };
    }
    let mut depth = 0usize;
    let mut p = pos;
    while p < end {
        let s = seq.sym(p % n);
        if s == r.sb {
            depth += 1;
        } else if s == r.eb {
            depth -= 1;
            if depth == 0 {
                return Some(p + 1);
            }
        }
        p += 1;
    }
    None
}

/// The position of the first `]` at `pos` or after that closes the current branch.
fn first_unmatched_eb<S: Seq + ?Sized>(seq: &S, pos: usize, end: usize, r: Rules) -> Option<usize> {
    let n = seq.len();
    if let Some(close) = r.tables.and_then(|t| t.close(seq, &r)) {
        let (off, base) = Tables::forward_at(pos, n, r.ring);
        return match close[off] {
            NONE => None,
            c => Some(base + c as usize).filter(|&q| q < end),
        };
    }
    let mut depth = 0usize;
    let mut p = pos;
    while p < end {
        let s = seq.sym(p % n);
        if s == r.sb {
            depth += 1;
        } else if s == r.eb {
            if depth == 0 {
                return Some(p);
            }
            depth -= 1;
        }
        p += 1;
    }
    None
}

/// Matches `pats` to the left, the last pattern at absolute position
/// `start` (which may be negative in a ring). Pushes the matched indices in
/// pattern order and returns the position before the first match.
#[inline]
pub fn match_left<S: Seq + ?Sized>(
    seq: &S,
    start: isize,
    pats: &[Pattern],
    r: Rules,
    out: &mut Vec<usize>,
) -> Option<isize> {
    let n = seq.len() as isize;
    if n == 0 {
        return pats.is_empty().then_some(start);
    }
    // A ring's positions count modulo n: from within its first turn, so
    // that every position examined is above -n.
    let start = if r.ring && !(0..n).contains(&start) {
        start.rem_euclid(n)
    } else {
        start
    };
    let floor = if r.ring { start - n + 1 } else { 0 };
    let mark = out.len();
    let mut pos = start;
    for p in pats.iter().rev() {
        loop {
            if pos < floor {
                out.truncate(mark);
                return None;
            }
            let i = if pos < 0 { pos + n } else { pos } as usize;
            if module_matches(seq, i, p) {
                out.push(i);
                pos -= 1;
                break;
            }
            let s = seq.sym(i);
            if s == r.sb || (r.filter.skips(s) && s != r.eb) {
                pos -= 1;
                if p.sym != r.sb && !r.filter.skips(p.sym) {
                    pos = skip_run_backward(seq, pos, floor, r).unwrap_or(pos);
                }
            } else if s == r.eb {
                match skip_branch_backward(seq, pos, floor, r) {
                    Some(q) => pos = q,
                    None => {
                        out.truncate(mark);
                        return None;
                    }
                }
            } else {
                out.truncate(mark);
                return None;
            }
        }
    }
    out[mark..].reverse();
    Some(pos)
}

/// From a `]` at `pos`, the position before its matching `[`.
fn skip_branch_backward<S: Seq + ?Sized>(
    seq: &S,
    pos: isize,
    floor: isize,
    r: Rules,
) -> Option<isize> {
    let n = seq.len() as isize;
    if let Some(partner) = r.tables.and_then(|t| t.partner(seq, &r)) {
        // A ring's `]` is looked up in the second copy, so that its `[`
        // may lie before the seam.
        let off = if r.ring { pos.rem_euclid(n) + n } else { pos };
        return match partner[off as usize] {
            NONE => None,
            m => Some(pos - off + m as isize)
                .filter(|&q| q >= floor)
                .map(|q| q - 1),
        };
    }
    let mut depth = 0usize;
    let mut p = pos;
    while p >= floor {
        let s = seq.sym(p.rem_euclid(n) as usize);
        if s == r.eb {
            depth += 1;
        } else if s == r.sb {
            depth -= 1;
            if depth == 0 {
                return Some(p - 1);
            }
        }
        p -= 1;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rewrite::Word;

    const A: Sym = Sym(1);
    const B: Sym = Sym(2);
    const SB: Sym = Sym(3);
    const EB: Sym = Sym(4);

    /// xorshift64: the same words on every run.
    fn next(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    fn pick(state: &mut u64, from: &[Sym]) -> Sym {
        from[(next(state) % from.len() as u64) as usize]
    }

    fn pattern(sym: Sym) -> Pattern {
        Pattern {
            sym,
            slots: Vec::new(),
            types: Vec::new(),
            width: None,
        }
    }

    /// Context matching with the tables finds what walking the word module
    /// by module finds, at every position of random words (balanced or
    /// not, deeply nested or not, rings or not), with and without a
    /// filter.
    #[test]
    fn tables_match_what_walking_finds() {
        let mut state = 0x2545_F491_4F6C_DD1D;
        let ignore_b = Filter::Ignore(vec![B].into());
        let consider_a = Filter::Consider(vec![A].into());
        for round in 0..400 {
            let n = 1 + (next(&mut state) % 24) as usize;
            // Some words are mostly brackets, to nest deeply.
            let alphabet: &[Sym] = if round % 3 == 0 {
                &[A, SB, SB, EB, EB]
            } else {
                &[A, B, SB, EB]
            };
            let mut word = Word::new();
            for _ in 0..n {
                word.push_raw(pick(&mut state, alphabet), &[]);
            }
            let pats: Vec<Pattern> = (0..1 + next(&mut state) % 3)
                .map(|_| pattern(pick(&mut state, &[A, B, SB, EB])))
                .collect();
            for ring in [false, true] {
                for filter in [&Filter::All, &ignore_b, &consider_a] {
                    let table = Tables::default();
                    let plain = Rules {
                        sb: SB,
                        eb: EB,
                        filter,
                        ring,
                        tables: None,
                    };
                    let fast = Rules {
                        tables: Some(&table),
                        ..plain
                    };
                    // Cursors of a ring reach past one turn either way
                    // (a predecessor that wraps, a second context test).
                    let (right, left) = match ring {
                        true => (0..3 * n, -2 * n as isize..n as isize),
                        false => (0..n + 1, -1..n as isize),
                    };
                    for start in right {
                        let (mut x, mut y) = (Vec::new(), Vec::new());
                        let slow = match_right(&word, start, &pats, plain, &mut x);
                        let quick = match_right(&word, start, &pats, fast, &mut y);
                        assert_eq!((slow, &x), (quick, &y), "right, {word:?} from {start}");
                    }
                    for at in left {
                        let (mut x, mut y) = (Vec::new(), Vec::new());
                        let slow = match_left(&word, at, &pats, plain, &mut x);
                        let quick = match_left(&word, at, &pats, fast, &mut y);
                        assert_eq!((slow, &x), (quick, &y), "left, {word:?} from {at}");
                    }
                }
            }
        }
    }

    /// `ignore: A` and 200,000 A before a B: a context from each A skips
    /// the rest of the run in one look-up, both ways.
    #[test]
    fn skipping_long_runs_is_linear() {
        let n = 200_000;
        let mut word = Word::new();
        word.push_raw(B, &[]);
        for _ in 0..n {
            word.push_raw(A, &[]);
        }
        word.push_raw(B, &[]);
        let table = Tables::default();
        let filter = Filter::Ignore(vec![A].into());
        let r = Rules {
            sb: SB,
            eb: EB,
            filter: &filter,
            ring: false,
            tables: Some(&table),
        };
        let t = std::time::Instant::now();
        let pats = [pattern(B)];
        let mut out = Vec::new();
        for i in 1..=n {
            out.clear();
            assert_eq!(match_right(&word, i + 1, &pats, r, &mut out), Some(n + 2));
            assert_eq!(
                match_left(&word, i as isize - 1, &pats, r, &mut out),
                Some(-1)
            );
        }
        assert!(t.elapsed().as_secs_f64() < 5.0, "{:?}", t.elapsed());
    }

    /// A right context that skips a branch nested 200,000 deep, from every
    /// module of it, takes one look-up each.
    #[test]
    fn skipping_deep_branches_is_linear() {
        let depth = 200_000;
        let mut word = Word::new();
        for _ in 0..depth {
            word.push_raw(A, &[]);
            word.push_raw(SB, &[]);
        }
        for _ in 0..depth {
            word.push_raw(EB, &[]);
        }
        let table = Tables::default();
        let r = Rules {
            sb: SB,
            eb: EB,
            filter: &Filter::All,
            ring: false,
            tables: Some(&table),
        };
        let t = std::time::Instant::now();
        let pats = [pattern(B)];
        let mut out = Vec::new();
        for i in (0..depth).map(|k| 2 * k + 1) {
            assert_eq!(match_right(&word, i, &pats, r, &mut out), None);
        }
        assert!(t.elapsed().as_secs_f64() < 5.0, "{:?}", t.elapsed());
    }
}
