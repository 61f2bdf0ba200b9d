//! Context matching on words, with lpfg's rules for branches (manual,
//! appendix "Production Matching"), `ignore:`/`consider:` and rings.
//!
//! Right context: a `[` in the word that the pattern does not expect skips the
//! whole branch; a `]` in the pattern skips the rest of the word's branch up
//! to its first unmatched `]`; a `]` in the word ends the match.
//! Left context: `[` is always skipped (the parent lies before it); a `]`
//! skips the whole branch back to its `[`.
//!
//! Skipping a branch is one look-up in a [`Brackets`] table, made once per
//! word, so that a step stays linear however deeply branches nest; without
//! a table (the new word, still being built) the brackets are counted.

use std::cell::OnceCell;

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
    /// The brackets of the word being matched, when it does not change
    /// while it is matched.
    pub brackets: Option<&'a Brackets>,
}

/// No position.
const NONE: u32 = u32::MAX;

/// Where each branch of one word ends, made on first use. Positions are
/// the word's, or, for a ring, those of the word written twice (`0..2n`),
/// so that a branch may run over the ring's seam; a position `p` of a
/// match is `p mod n` in the word.
#[derive(Debug, Default)]
pub struct Brackets {
    /// For a `[`, the position of the `]` that closes it; for a `]`, the
    /// position of the `[` it closes (a `]` of the second copy for a
    /// ring); `NONE` when unmatched.
    partner: OnceCell<Vec<u32>>,
    /// For every position, the first `]` at or after it that closes the
    /// branch it is in.
    close: OnceCell<Vec<u32>>,
}

impl Brackets {
    /// Forgets the last word's tables.
    pub fn clear(&mut self) {
        self.partner.take();
        self.close.take();
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
    if let Some(partner) = r.brackets.and_then(|b| b.partner(seq, &r)) {
        let (off, base) = Brackets::forward_at(pos, n, r.ring);
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
    if let Some(close) = r.brackets.and_then(|b| b.close(seq, &r)) {
        let (off, base) = Brackets::forward_at(pos, n, r.ring);
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
    if let Some(partner) = r.brackets.and_then(|b| b.partner(seq, &r)) {
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

    /// Context matching with the bracket tables finds what counting the
    /// brackets finds, at every position of random words (balanced or
    /// not, deeply nested or not, rings or not), with and without a
    /// filter.
    #[test]
    fn bracket_tables_match_what_counting_finds() {
        let mut state = 0x2545_F491_4F6C_DD1D;
        let ignore_b = Filter::Ignore(vec![B]);
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
                for filter in [&Filter::All, &ignore_b] {
                    let table = Brackets::default();
                    let plain = Rules {
                        sb: SB,
                        eb: EB,
                        filter,
                        ring,
                        brackets: None,
                    };
                    let fast = Rules {
                        brackets: Some(&table),
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
        let table = Brackets::default();
        let r = Rules {
            sb: SB,
            eb: EB,
            filter: &Filter::All,
            ring: false,
            brackets: Some(&table),
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
