//! Random numbers as an lpfg program gets them, bit for bit.
//!
//! * lpfg's `ran(range)` and `sran(seed)` (manual 6.3.2) are `erand48` on a
//!   state of their own: 48 bits that start at 0x330E, and `sran(s)` sets
//!   them to the low 32 bits of `s` (what lpfg's `SeedRan` does). Gillespie
//!   groups draw from a second such state, `SeedGillespie(s)` seeds it.
//! * C's `rand()`/`srand()` and `random()`/`srandom()` are glibc's: one
//!   additive feedback generator (`random_r`'s TYPE_3: 31 words, taps 3
//!   and 31, the first 310 outputs discarded), seeded with 1 until the
//!   program seeds it, `RAND_MAX` 2147483647.
//! * `drand48()`, `lrand48()`, `mrand48()` and `srand48()` are glibc's
//!   shared 48-bit state, which starts at 0 and which `srand48(s)` sets to
//!   `s << 16 | 0x330E` (low 32 bits of `s`).
//!
//! The 48-bit generators are the linear congruence
//! `x ← (0x5DEECE66D · x + 0xB) mod 2^48`; `erand48`/`drand48` return the
//! new `x / 2^48`, `lrand48` its top 31 bits, `mrand48` its top 32 as a
//! signed number.
//!
//! All state lives in a [`Random`] owned by the run's `Env`: runs are
//! independent and a run is reproducible. `--seed N` seeds every
//! generator as if the program began with `sran(N); srand(N);
//! srand48(N); SeedGillespie(N);`.

use super::value::Value;

/// C's `RAND_MAX` in glibc.
pub const RAND_MAX: i64 = 2_147_483_647;

/// The 48-bit linear congruential generator of `erand48` and `drand48`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rand48 {
    x: u64,
}

const MASK48: u64 = (1 << 48) - 1;

impl Rand48 {
    /// The state given as its 48 bits.
    pub fn from_state(x: u64) -> Rand48 {
        Rand48 { x: x & MASK48 }
    }

    /// lpfg's seeding of `ran` and of Gillespie groups: the low 32 bits of
    /// `seed`, the high 16 bits 0.
    pub fn lpfg_seeded(seed: i64) -> Rand48 {
        Rand48::from_state(seed as u64 & 0xFFFF_FFFF)
    }

    /// `srand48(seed)`.
    pub fn srand48(seed: i64) -> Rand48 {
        Rand48::from_state(((seed as u64 & 0xFFFF_FFFF) << 16) | 0x330E)
    }

    fn advance(&mut self) -> u64 {
        self.x = (self.x.wrapping_mul(0x5_DEEC_E66D).wrapping_add(0xB)) & MASK48;
        self.x
    }

    /// `erand48`/`drand48`: uniform in [0, 1), a multiple of 2^-48.
    pub fn next_f64(&mut self) -> f64 {
        self.advance() as f64 / (1u64 << 48) as f64
    }

    /// `lrand48`: uniform in [0, 2^31).
    pub fn next_lrand(&mut self) -> i64 {
        (self.advance() >> 17) as i64
    }

    /// `mrand48`: uniform in [-2^31, 2^31).
    pub fn next_mrand(&mut self) -> i64 {
        i64::from((self.advance() >> 16) as u32 as i32)
    }
}

/// glibc's `random()` (and `rand()`): TYPE_3 additive feedback.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GlibcRandom {
    table: [u32; 31],
    front: usize,
    rear: usize,
}

impl GlibcRandom {
    /// `srandom(seed)` / `srand(seed)`: the low 32 bits; 0 counts as 1.
    pub fn seeded(seed: i64) -> GlibcRandom {
        let seed = seed as u32;
        let mut table = [0u32; 31];
        table[0] = if seed == 0 { 1 } else { seed };
        // r[i] = 16807 · r[i-1] mod (2^31 - 1), by Schrage's method on
        // signed 32-bit words, as glibc computes it.
        for i in 1..31 {
            let prev = table[i - 1] as i32;
            let hi = prev / 127_773;
            let lo = prev % 127_773;
            let mut word = 16_807i32
                .wrapping_mul(lo)
                .wrapping_sub(2_836i32.wrapping_mul(hi));
            if word < 0 {
                word = word.wrapping_add(2_147_483_647);
            }
            table[i] = word as u32;
        }
        let mut g = GlibcRandom {
            table,
            front: 3,
            rear: 0,
        };
        for _ in 0..310 {
            g.next();
        }
        g
    }

    /// The next `random()`: uniform in [0, 2^31).
    pub fn next(&mut self) -> i64 {
        let sum = self.table[self.front].wrapping_add(self.table[self.rear]);
        self.table[self.front] = sum;
        self.front = (self.front + 1) % 31;
        self.rear = (self.rear + 1) % 31;
        i64::from(sum >> 1)
    }
}

/// The random functions a program can call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `ran(range)`: uniform in [0, range).
    Ran,
    /// `sran(seed)`.
    SRan,
    /// `rand()` and `random()`.
    Rand,
    /// `srand(seed)` and `srandom(seed)`.
    SRand,
    Drand48,
    Lrand48,
    Mrand48,
    SRand48,
    /// `GillespieTime()`: the time the run's Gillespie steps have advanced.
    GillespieTime,
    SeedGillespie,
    /// `ResetGillespie()`: the Gillespie time back to 0.
    ResetGillespie,
}

/// Every generator of one run, and the Gillespie time.
#[derive(Clone, Debug, PartialEq)]
pub struct Random {
    ran: Rand48,
    rand: GlibcRandom,
    drand: Rand48,
    /// The generator of Gillespie steps.
    pub gillespie: Rand48,
    /// The sum of the Gillespie steps' waiting times.
    pub gillespie_time: f64,
}

impl Default for Random {
    /// The state lpfg's program starts with.
    fn default() -> Random {
        Random {
            ran: Rand48::from_state(0x330E),
            rand: GlibcRandom::seeded(1),
            drand: Rand48::from_state(0),
            gillespie: Rand48::from_state(0x330E),
            gillespie_time: 0.0,
        }
    }
}

impl Random {
    /// Every generator seeded with `seed` (see the module's documentation),
    /// or lpfg's starting state.
    pub fn new(seed: Option<u32>) -> Random {
        match seed {
            None => Random::default(),
            Some(s) => {
                let s = i64::from(s);
                Random {
                    ran: Rand48::lpfg_seeded(s),
                    rand: GlibcRandom::seeded(s),
                    drand: Rand48::srand48(s),
                    gillespie: Rand48::lpfg_seeded(s),
                    gillespie_time: 0.0,
                }
            }
        }
    }

    /// Calls `op` on checked arguments.
    pub fn call(&mut self, op: Op, args: &[Value]) -> Value {
        let seed = || args.first().map_or(0, Value::as_i64);
        match op {
            Op::Ran => Value::Float(self.ran.next_f64() * args.first().map_or(1.0, Value::as_f64)),
            Op::SRan => {
                self.ran = Rand48::lpfg_seeded(seed());
                Value::Void
            }
            Op::Rand => Value::Int(self.rand.next()),
            Op::SRand => {
                self.rand = GlibcRandom::seeded(seed());
                Value::Void
            }
            Op::Drand48 => Value::Float(self.drand.next_f64()),
            Op::Lrand48 => Value::Int(self.drand.next_lrand()),
            Op::Mrand48 => Value::Int(self.drand.next_mrand()),
            Op::SRand48 => {
                self.drand = Rand48::srand48(seed());
                Value::Void
            }
            Op::GillespieTime => Value::Float(self.gillespie_time),
            Op::SeedGillespie => {
                self.gillespie = Rand48::lpfg_seeded(seed());
                Value::Void
            }
            Op::ResetGillespie => {
                self.gillespie_time = 0.0;
                Value::Void
            }
        }
    }
}

#[cfg(test)]
#[allow(clippy::excessive_precision)] // gcc's "%.17g" output, as printed
mod tests {
    use super::*;

    // The expected numbers below were printed by a C program compiled with
    // gcc against glibc 2.36 on this machine (Debian 12):
    //   srand(s); rand() …; srandom(7); random() …; srand48(7); drand48() …;
    //   lrand48() …; unsigned short x[3] = {0x330E, 0, 0}; erand48(x) …
    // with the seeds written next to each sequence. printf("%.17g") prints
    // a double exactly enough to read it back bit for bit.

    #[test]
    fn rand_is_glibcs() {
        let seq = |seed: i64| {
            let mut g = GlibcRandom::seeded(seed);
            (0..5).map(|_| g.next()).collect::<Vec<_>>()
        };
        let one = [1804289383, 846930886, 1681692777, 1714636915, 1957747793];
        assert_eq!(seq(1), one);
        // glibc seeds 0 as 1.
        assert_eq!(seq(0), one);
        assert_eq!(
            seq(42),
            [71876166, 708592740, 1483128881, 907283241, 442951012]
        );
        assert_eq!(seq(7)[..3], [1045618677, 1863967299, 1272579899]);
        // Unseeded is seed 1.
        let mut r = Random::default();
        assert_eq!(r.call(Op::Rand, &[]), Value::Int(1804289383));
    }

    #[test]
    fn the_48_bit_generators_are_glibcs() {
        let mut d = Rand48::srand48(7);
        let got: Vec<f64> = (0..3).map(|_| d.next_f64()).collect();
        assert_eq!(
            got,
            [0.2664441967654092, 0.68203523019062118, 0.26549059342699977]
        );
        let mut d = Rand48::srand48(7);
        let got: Vec<i64> = (0..3).map(|_| d.next_lrand()).collect();
        assert_eq!(got, [572184555, 1464659504, 570136708]);
        // glibc's drand48 before any srand48: the state is 0, so the first
        // number is 0xB / 2^48.
        let mut r = Random::default();
        assert_eq!(
            r.call(Op::Drand48, &[]),
            Value::Float(3.907985046680551e-14)
        );
        assert_eq!(
            r.call(Op::Drand48, &[]),
            Value::Float(0.00098539467465030839)
        );
    }

    #[test]
    fn ran_is_lpfgs_erand48() {
        // lpfg's unseeded state {0x330E, 0, 0}.
        let mut r = Random::default();
        let got: Vec<Value> = (0..3)
            .map(|_| r.call(Op::Ran, &[Value::Float(1.0)]))
            .collect();
        let want = [
            0.17082803610628972,
            0.74990198048496381,
            0.09637165562356742,
        ];
        assert_eq!(got, want.map(Value::Float));
        // sran(5) and sran(123456789): {s & 0xFFFF, s >> 16 & 0xFFFF, 0}.
        r.call(Op::SRan, &[Value::Int(5)]);
        assert_eq!(
            r.call(Op::Ran, &[Value::Int(2)]),
            Value::Float(2.0 * 0.000447906670316911)
        );
        r.call(Op::SRan, &[Value::Int(123456789)]);
        assert_eq!(
            r.call(Op::Ran, &[Value::Float(1.0)]),
            Value::Float(0.42385683655446371)
        );
        // sran(-1) keeps the low 32 bits.
        r.call(Op::SRan, &[Value::Int(-1)]);
        assert_eq!(
            r.call(Op::Ran, &[Value::Float(1.0)]),
            Value::Float(0.90001112667379601)
        );
    }

    /// `--seed N` is `sran(N); srand(N); srand48(N); SeedGillespie(N)`.
    #[test]
    fn a_seed_seeds_every_generator() {
        let mut seeded = Random::new(Some(42));
        let mut by_hand = Random::default();
        for (op, seed) in [Op::SRan, Op::SRand, Op::SRand48, Op::SeedGillespie]
            .into_iter()
            .zip([42; 4])
        {
            by_hand.call(op, &[Value::Int(seed)]);
        }
        assert_eq!(seeded, by_hand);
        assert_eq!(seeded.call(Op::Rand, &[]), Value::Int(71876166));
    }
}
