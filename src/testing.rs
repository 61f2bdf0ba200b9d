//! What the unit tests share.

/// A small deterministic sequence of numbers (Marsaglia's xorshift with
/// shifts 13, 7, 17) from `seed`, which must not be 0.
pub(crate) fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    }
}
