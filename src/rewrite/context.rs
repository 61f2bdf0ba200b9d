//! Context matching on words, with lpfg's rules for branches (manual,
//! appendix "Production Matching"), `ignore:`/`consider:` and rings.
//!
//! Right context: a `[` in the word that the pattern does not expect skips the
//! whole branch; a `]` in the pattern skips the rest of the word's branch up
//! to its first unmatched `]`; a `]` in the word ends the match.
//! Left context: `[` is always skipped (the parent lies before it); a `]`
//! skips the whole branch back to its `[`.

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
