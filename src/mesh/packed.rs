//! Compact per-element columns for the mesh's largest arrays: flags
//! packed 64 to a word ([`Bits`]), and levels and steps kept in a byte
//! each until one needs more ([`Narrow`]). A large mesh spends most of
//! its memory on per-element arrays, and these hold what a `Vec<bool>` or
//! a `Vec<u32>` would, in an eighth or a quarter of the room.

/// One flag per element, packed 64 to a word. Bits past `len` are kept 0,
/// so two columns with the same flags are equal word for word.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct Bits {
    words: Vec<u64>,
    len: usize,
}

impl Bits {
    /// `len` flags, all `value`.
    pub(crate) fn filled(len: usize, value: bool) -> Bits {
        let mut b = Bits {
            words: vec![if value { u64::MAX } else { 0 }; len.div_ceil(64)],
            len,
        };
        b.clear_tail();
        b
    }

    /// Zeroes the bits of the last word past `len`.
    fn clear_tail(&mut self) {
        if !self.len.is_multiple_of(64) {
            if let Some(w) = self.words.last_mut() {
                *w &= (1u64 << (self.len % 64)) - 1;
            }
        }
    }

    #[inline]
    pub(crate) fn len(&self) -> usize {
        self.len
    }

    /// Flag `i`, which must be below `len` (checked as a slice index is,
    /// to the word).
    #[inline]
    pub(crate) fn get(&self, i: usize) -> bool {
        debug_assert!(i < self.len, "flag {i} of {}", self.len);
        (self.words[i >> 6] >> (i & 63)) & 1 != 0
    }

    /// Flag `i`, false past the end.
    #[inline]
    pub(crate) fn get_or_false(&self, i: usize) -> bool {
        i < self.len && self.get(i)
    }

    #[inline]
    pub(crate) fn set(&mut self, i: usize, value: bool) {
        assert!(i < self.len, "flag {i} of {}", self.len);
        let (w, bit) = (i >> 6, 1u64 << (i & 63));
        if value {
            self.words[w] |= bit;
        } else {
            self.words[w] &= !bit;
        }
    }

    #[inline]
    pub(crate) fn push(&mut self, value: bool) {
        if self.len.is_multiple_of(64) {
            self.words.push(0);
        }
        self.len += 1;
        if value {
            self.set(self.len - 1, true);
        }
    }

    /// Room for `additional` more flags.
    pub(crate) fn reserve(&mut self, additional: usize) {
        let words = (self.len + additional).div_ceil(64) - self.words.len();
        crate::huge::grow(&mut self.words, words);
    }

    /// The bytes the flags take.
    pub(crate) fn bytes(&self) -> usize {
        std::mem::size_of_val(&self.words[..])
    }
}

/// A column of small unsigned numbers (levels, steps): a byte each while
/// every one fits in a byte, widened to `u32` for good, all at once, when
/// a larger one is set. Never wraps: a number above `u8::MAX` widens the
/// column before it is stored.
#[derive(Clone, Debug)]
pub(crate) enum Narrow {
    Small(Vec<u8>),
    Wide(Vec<u32>),
}

impl Default for Narrow {
    fn default() -> Narrow {
        Narrow::Small(Vec::new())
    }
}

impl Narrow {
    /// `len` elements holding `x`.
    pub(crate) fn filled(len: usize, x: u32) -> Narrow {
        match u8::try_from(x) {
            Ok(b) => Narrow::Small(vec![b; len]),
            Err(_) => Narrow::Wide(vec![x; len]),
        }
    }

    #[inline]
    pub(crate) fn len(&self) -> usize {
        match self {
            Narrow::Small(v) => v.len(),
            Narrow::Wide(v) => v.len(),
        }
    }

    #[inline]
    pub(crate) fn get(&self, i: usize) -> u32 {
        match self {
            Narrow::Small(v) => v[i] as u32,
            Narrow::Wide(v) => v[i],
        }
    }

    /// Every element as a `u32`, the room reserved kept.
    fn widen(&mut self) {
        if let Narrow::Small(v) = self {
            let mut w = crate::huge::with_capacity(v.capacity());
            w.extend(v.iter().map(|&x| x as u32));
            *self = Narrow::Wide(w);
        }
    }

    #[inline]
    pub(crate) fn set(&mut self, i: usize, x: u32) {
        match self {
            Narrow::Small(v) => match u8::try_from(x) {
                Ok(b) => v[i] = b,
                Err(_) => {
                    assert!(i < v.len(), "element {i} of {}", v.len());
                    self.widen();
                    self.set(i, x);
                }
            },
            Narrow::Wide(v) => v[i] = x,
        }
    }

    #[inline]
    pub(crate) fn push(&mut self, x: u32) {
        match self {
            Narrow::Small(v) => match u8::try_from(x) {
                Ok(b) => v.push(b),
                Err(_) => {
                    self.widen();
                    self.push(x);
                }
            },
            Narrow::Wide(v) => v.push(x),
        }
    }

    /// Sets every element to `x`.
    pub(crate) fn fill(&mut self, x: u32) {
        *self = Narrow::filled(self.len(), x);
    }

    /// Room for `additional` more elements.
    pub(crate) fn reserve(&mut self, additional: usize) {
        match self {
            Narrow::Small(v) => crate::huge::grow(v, additional),
            Narrow::Wide(v) => crate::huge::grow(v, additional),
        }
    }

    /// The bytes the elements take.
    pub(crate) fn bytes(&self) -> usize {
        match self {
            Narrow::Small(v) => std::mem::size_of_val(&v[..]),
            Narrow::Wide(v) => std::mem::size_of_val(&v[..]),
        }
    }
}

/// Columns are equal when they hold the same numbers, however they are
/// kept.
impl PartialEq for Narrow {
    fn eq(&self, other: &Narrow) -> bool {
        match (self, other) {
            (Narrow::Small(a), Narrow::Small(b)) => a == b,
            (Narrow::Wide(a), Narrow::Wide(b)) => a == b,
            _ => self.len() == other.len() && (0..self.len()).all(|i| self.get(i) == other.get(i)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{Bits, Narrow};

    use crate::testing::xorshift as rng;

    #[test]
    fn bits_hold_what_a_vec_of_bools_holds() {
        let mut next = rng(0x9e37_79b9_7f4a_7c15);
        for start in [0, 1, 63, 64, 65, 130] {
            for value in [false, true] {
                let mut bits = Bits::filled(start, value);
                let mut plain = vec![value; start];
                for _ in 0..2000 {
                    let r = next();
                    match r % 4 {
                        0 | 1 if !plain.is_empty() => {
                            let i = (r >> 8) as usize % plain.len();
                            let b = (r >> 40) & 1 == 1;
                            bits.set(i, b);
                            plain[i] = b;
                        }
                        2 => {
                            let b = (r >> 40) & 1 == 1;
                            bits.push(b);
                            plain.push(b);
                        }
                        _ => bits.reserve((r >> 8) as usize % 100),
                    }
                    assert_eq!(bits.len(), plain.len());
                }
                for (i, &b) in plain.iter().enumerate() {
                    assert_eq!(bits.get(i), b, "flag {i}");
                    assert_eq!(bits.get_or_false(i), b);
                }
                assert!(!bits.get_or_false(plain.len()));
                // Built flag by flag or filled, the same flags are equal.
                let mut again = Bits::filled(0, false);
                plain.iter().for_each(|&b| again.push(b));
                assert_eq!(again, bits);
            }
        }
        let ones = Bits::filled(70, true);
        let mut pushed = Bits::default();
        (0..70).for_each(|_| pushed.push(true));
        assert_eq!(ones, pushed);
        assert_ne!(ones, Bits::filled(71, true));
    }

    #[test]
    fn a_narrow_column_holds_what_a_vec_of_u32_holds_and_widens_before_a_large_number() {
        let mut next = rng(12345);
        let mut col = Narrow::filled(10, 3);
        let mut plain = vec![3u32; 10];
        assert!(matches!(col, Narrow::Small(_)));
        for round in 0..3000 {
            let r = next();
            // Small numbers first; from round 2000 on, some past a byte.
            let x = if round < 2000 {
                (r >> 20) as u32 % 256
            } else {
                (r >> 20) as u32 % 70_000
            };
            if r.is_multiple_of(3) {
                col.push(x);
                plain.push(x);
            } else {
                let i = (r >> 4) as usize % plain.len();
                col.set(i, x);
                plain[i] = x;
            }
            if round == 1999 {
                assert!(matches!(col, Narrow::Small(_)), "no number past a byte yet");
            }
        }
        assert!(matches!(col, Narrow::Wide(_)));
        assert_eq!(col.len(), plain.len());
        for (i, &x) in plain.iter().enumerate() {
            assert_eq!(col.get(i), x);
        }
        // 256 is not stored as 0: the column widens first.
        let mut c = Narrow::filled(2, 255);
        c.set(1, 256);
        assert_eq!((c.get(0), c.get(1)), (255, 256));
        let mut c = Narrow::filled(1, 0);
        c.push(u32::MAX);
        assert_eq!((c.get(0), c.get(1)), (0, u32::MAX));
        // Equality is by value, however kept.
        let mut w = Narrow::filled(3, 300);
        (0..3).for_each(|i| w.set(i, 7));
        assert_eq!(w, Narrow::filled(3, 7));
        assert_ne!(w, Narrow::filled(4, 7));
        c.fill(0);
        assert_eq!(c, Narrow::filled(2, 0));
    }
}
