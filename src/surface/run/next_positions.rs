//! The second position buffer (paper 000, §7): the positions vertex
//! rules write for the next step, kept as small differences from the
//! current ones, and made current when the step ends.

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::{Mesh, VertexId};

use super::CHUNK;

/// The positions vertex rules write for the next step, by vertex slot,
/// in blocks of [`CHUNK`] slots, filled while the rules run and made
/// current when the step ends. A later rule's point for a vertex replaces
/// an earlier one's.
///
/// A block keeps each written point as its difference from the vertex's
/// current position: per coordinate, the new bits minus the current bits,
/// as integers (wrapping), which gives back the same bits whatever the
/// numbers. A vertex moves little against its coordinates (at three levels
/// of Loop on a sphere, almost every one by less than 2^39 units in the
/// last place), so the
/// differences fit in fewer bytes than a coordinate: each block stores
/// them in the width ([`Block::width`], 1 to 8 bytes) that makes it
/// smallest, and the points whose differences do not fit (a coordinate
/// near 0, which moves by many of its units in the last place) in a list
/// of their own. Vertex rules never move a vertex otherwise, and splits
/// place only the vertices they make, so a written slot's current
/// position is the same when it is written and when the step ends.
#[derive(Debug, Default)]
pub(super) struct NextPositions {
    pub(super) blocks: Vec<Block>,
}

/// The next positions of [`CHUNK`] vertex slots (fewer in the last
/// block): see [`NextPositions`].
#[derive(Debug, Default)]
pub(super) struct Block {
    /// The slots of the block.
    pub(super) len: usize,
    /// Bytes per coordinate's difference in `diffs`; 0 while nothing is
    /// written.
    width: usize,
    /// Three differences a slot, `width` bytes each, little-endian, and
    /// [`Block::PAD`] bytes after them.
    diffs: Vec<u8>,
    /// The slots written.
    written: Vec<u64>,
    /// The written slots whose last point is in `wide`.
    is_wide: Vec<u64>,
    /// Points whose differences do not fit `width` bytes, with their
    /// places in the block, in the order written: a later one for a slot
    /// replaces an earlier one.
    wide: Vec<(u32, DVec3)>,
}

/// The difference of `next`'s coordinates from `cur`'s, as integers: the
/// bits of `next` are `cur`'s plus it, wrapping.
#[inline]
fn bit_difference(cur: DVec3, next: DVec3) -> [i64; 3] {
    let d = |c: f64, n: f64| (n.to_bits() as i64).wrapping_sub(c.to_bits() as i64);
    [d(cur.x, next.x), d(cur.y, next.y), d(cur.z, next.z)]
}

/// `cur` moved by a [`bit_difference`].
#[inline]
fn add_bit_difference(cur: DVec3, d: [i64; 3]) -> DVec3 {
    let a = |c: f64, d: i64| f64::from_bits((c.to_bits() as i64).wrapping_add(d) as u64);
    DVec3::new(a(cur.x, d[0]), a(cur.y, d[1]), a(cur.z, d[2]))
}

/// The fewest bytes that hold each of `d` as a signed number (1 to 8).
#[inline]
fn bytes_needed(d: [i64; 3]) -> usize {
    // A number fits in b bytes when its bits above the lowest 8b - 1 are
    // copies of its sign.
    let bits = d
        .iter()
        .map(|&x| 64 - (x ^ (x >> 63)).leading_zeros() as usize + 1)
        .max()
        .unwrap_or(1);
    bits.div_ceil(8).max(1)
}

#[inline]
fn bit(words: &[u64], i: usize) -> bool {
    (words[i >> 6] >> (i & 63)) & 1 != 0
}

#[inline]
fn set_bit(words: &mut [u64], i: usize, value: bool) {
    if value {
        words[i >> 6] |= 1 << (i & 63);
    } else {
        words[i >> 6] &= !(1 << (i & 63));
    }
}

impl Block {
    /// Bytes a wide point takes in `wide`.
    const WIDE_BYTES: usize = std::mem::size_of::<(u32, DVec3)>();

    /// Bytes after the last difference, so that each is read and written
    /// as the 8 bytes from where it starts.
    const PAD: usize = 8;

    /// The 8 bytes of `diffs` from `at`, as a number.
    #[inline]
    fn word(&self, at: usize) -> u64 {
        let mut b = [0u8; 8];
        b.copy_from_slice(&self.diffs[at..at + 8]);
        u64::from_le_bytes(b)
    }

    /// Grows the block to `len` slots, none of the new ones written.
    fn grow(&mut self, len: usize) {
        if len <= self.len {
            return;
        }
        self.len = len;
        self.written.resize(len.div_ceil(64), 0);
        self.is_wide.resize(len.div_ceil(64), 0);
        if self.width > 0 {
            self.diffs.resize(3 * self.width * len + Self::PAD, 0);
        }
    }

    /// The difference stored for slot `i` (written, not wide).
    #[inline]
    fn stored(&self, i: usize) -> [i64; 3] {
        let w = self.width;
        let at = 3 * w * i;
        // The lowest `w` bytes, sign-extended.
        let shift = 64 - 8 * w as u32;
        std::array::from_fn(|k| ((self.word(at + k * w) << shift) as i64) >> shift)
    }

    /// Stores `d`, which fits `width` bytes, for slot `i`.
    #[inline]
    fn store(&mut self, i: usize, d: [i64; 3]) {
        let w = self.width;
        let at = 3 * w * i;
        // The lowest `w` bytes of each; the bytes after them are kept.
        let mask = u64::MAX >> (64 - 8 * w as u32);
        for (k, &x) in d.iter().enumerate() {
            let o = at + k * w;
            let word = (self.word(o) & !mask) | (x as u64 & mask);
            self.diffs[o..o + 8].copy_from_slice(&word.to_le_bytes());
        }
    }

    /// Records `p` for slot `i`, whose current position is `cur`.
    #[inline]
    fn put(&mut self, i: usize, cur: DVec3, p: DVec3) {
        let d = bit_difference(cur, p);
        set_bit(&mut self.written, i, true);
        let wide = bytes_needed(d) > self.width;
        set_bit(&mut self.is_wide, i, wide);
        if wide {
            self.wide.push((i as u32, p));
        } else {
            self.store(i, d);
        }
    }

    /// Records `points` (places in the block, in increasing order, and
    /// points) given the current positions `cur` of the block's slots,
    /// first widening the block where the points and those written
    /// before take less room that way.
    pub(super) fn write(&mut self, cur: &[DVec3], points: &[(u32, DVec3)]) {
        debug_assert_eq!(cur.len(), self.len);
        if points.is_empty() {
            return;
        }
        // How many points need each width: the new ones and the last
        // of each slot before.
        let mut need = [0usize; 9];
        for &(i, p) in points {
            need[bytes_needed(bit_difference(cur[i as usize], p))] += 1;
        }
        if self.width > 0 {
            for i in 0..self.len {
                if bit(&self.written, i) && !bit(&self.is_wide, i) {
                    need[self.width] += 1;
                }
            }
            for &(i, p) in &self.wide {
                need[bytes_needed(bit_difference(cur[i as usize], p))] += 1;
            }
        }
        // The width that takes the least room from the current one up
        // (the widest that does, where several do).
        let cost =
            |w: usize| 3 * w * self.len + Self::WIDE_BYTES * need[w + 1..].iter().sum::<usize>();
        let best = (self.width.max(1)..=8)
            .rev()
            .min_by_key(|&w| cost(w))
            .unwrap_or(8);
        if best > self.width {
            self.widen(best, cur);
        }
        for &(i, p) in points {
            self.put(i as usize, cur[i as usize], p);
        }
    }

    /// Stores every difference in `width` bytes, more than now, and takes
    /// the wide points that then fit out of `wide`.
    fn widen(&mut self, width: usize, cur: &[DVec3]) {
        let fresh = Block {
            len: self.len,
            width,
            diffs: vec![0; 3 * width * self.len + Self::PAD],
            written: std::mem::take(&mut self.written),
            is_wide: std::mem::take(&mut self.is_wide),
            wide: Vec::new(),
        };
        let old = std::mem::replace(self, fresh);
        if old.width > 0 {
            for i in 0..self.len {
                if bit(&self.written, i) && !bit(&self.is_wide, i) {
                    self.store(i, old.stored(i));
                }
            }
        }
        // The last point of each wide slot, from the end.
        let mut seen = vec![0u64; self.len.div_ceil(64)];
        let mut still = Vec::new();
        for &(i, p) in old.wide.iter().rev() {
            let k = i as usize;
            if bit(&seen, k) || !bit(&self.is_wide, k) {
                continue;
            }
            set_bit(&mut seen, k, true);
            let d = bit_difference(cur[k], p);
            if bytes_needed(d) <= width {
                self.store(k, d);
                set_bit(&mut self.is_wide, k, false);
            } else {
                still.push((i, p));
            }
        }
        still.reverse();
        self.wide = still;
    }

    /// Gives the written slots their points; `pos` holds the block's
    /// current positions.
    fn make_current(&self, pos: &mut [DVec3]) {
        for (i, p) in pos.iter_mut().enumerate().take(self.len) {
            if bit(&self.written, i) && !bit(&self.is_wide, i) {
                *p = add_bit_difference(*p, self.stored(i));
            }
        }
        for &(i, p) in &self.wide {
            if bit(&self.is_wide, i as usize) {
                pos[i as usize] = p;
            }
        }
    }

    /// The bytes the block holds.
    #[cfg(test)]
    fn bytes(&self) -> usize {
        self.diffs.len()
            + 8 * (self.written.len() + self.is_wide.len())
            + Self::WIDE_BYTES * self.wide.len()
    }
}

impl NextPositions {
    /// Room for every vertex slot of `mesh`, none of the new ones written.
    pub(super) fn cover(&mut self, mesh: &Mesh) {
        let n = mesh.v_alive.len();
        let blocks = n.div_ceil(CHUNK);
        let k = self.blocks.len().saturating_sub(1);
        if let Some(last) = self.blocks.last_mut() {
            last.grow((n - k * CHUNK).min(CHUNK));
        }
        while self.blocks.len() < blocks {
            let k = self.blocks.len();
            let mut b = Block::default();
            b.grow((n - k * CHUNK).min(CHUNK));
            self.blocks.push(b);
        }
    }

    /// Records `points` (vertices in increasing order of id, and their
    /// points) given the current positions `pos`.
    pub(super) fn write(&mut self, pos: &[DVec3], points: &[(VertexId, DVec3)]) {
        let mut rest = points;
        while let Some(&(v, _)) = rest.first() {
            let k = v.index() / CHUNK;
            let n = rest
                .iter()
                .position(|(w, _)| w.index() / CHUNK != k)
                .unwrap_or(rest.len());
            let lo = k * CHUNK;
            let block: Vec<(u32, DVec3)> = rest[..n]
                .iter()
                .map(|&(w, p)| ((w.index() - lo) as u32, p))
                .collect();
            let b = &mut self.blocks[k];
            b.write(&pos[lo..lo + b.len], &block);
            rest = &rest[n..];
        }
    }

    /// Gives the written vertices their points.
    pub(super) fn make_current(self, mesh: &mut Mesh) {
        self.blocks
            .par_iter()
            .zip(mesh.pos.par_chunks_mut(CHUNK))
            .for_each(|(b, pos)| b.make_current(pos));
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::{bytes_needed, NextPositions, CHUNK};
    use crate::mesh::{shapes, Mesh, VertexId};

    use crate::testing::xorshift as rng;

    #[test]
    fn bytes_needed_is_the_narrowest_signed_width() {
        let mut next = rng(77);
        let mut xs = vec![
            0i64,
            1,
            -1,
            127,
            128,
            -128,
            -129,
            255,
            256,
            i64::MAX,
            i64::MIN,
        ];
        for b in 1..8 {
            let edge = 1i64 << (8 * b - 1);
            xs.extend([edge - 1, edge, -edge, -edge - 1]);
        }
        xs.extend((0..1000).map(|_| (next() as i64) >> (next() % 64)));
        for x in xs {
            // The smallest b with -2^(8b-1) <= x < 2^(8b-1), in i128.
            let want = (1..=8)
                .find(|&b| {
                    let half = 1i128 << (8 * b - 1);
                    (-half..half).contains(&(x as i128))
                })
                .expect("8 bytes hold any i64");
            assert_eq!(bytes_needed([x, 0, 0]), want, "{x}");
            assert_eq!(bytes_needed([0, x, -1]), want, "{x}");
        }
    }

    /// The next positions against a plain list of the last point written
    /// for each slot: rounds of writes (a round is a vertex rule: some
    /// slots, in id order), with small moves, none, sign changes, zeros
    /// of either sign, huge moves and subnormal numbers, on a mesh that
    /// grows between rounds; every coordinate must come back to the bit.
    #[test]
    fn next_positions_give_back_the_last_point_of_every_slot_to_the_bit() {
        let mut next = rng(0x51_7cc1_b727_220a);
        let mut unit = move || (next() >> 11) as f64 / (1u64 << 53) as f64;
        let mut m = Mesh::from_soup(&shapes::triangle_grid(150, 120)).expect("a grid");
        let n0 = m.v_alive.len();
        assert!(n0 > CHUNK, "more than one block");
        let magnitudes = [1e-300, 1e-9, 0.5, 3.0, 1e6, 1e300];
        for i in 0..n0 {
            let c = |u: f64, k: f64| (u - 0.5) * magnitudes[(k * 6.0) as usize % 6];
            let p = DVec3::new(c(unit(), unit()), c(unit(), unit()), c(unit(), unit()));
            m.set_position(VertexId(i as u32), p);
        }
        m.set_position(VertexId(3), DVec3::new(0.0, -0.0, f64::MIN_POSITIVE / 8.0));
        let mut buf = NextPositions::default();
        let mut plain: Vec<Option<DVec3>> = vec![None; n0];
        for round in 0..5 {
            if round == 2 {
                // New vertices between rules (a split rule's).
                for k in 0..CHUNK + 100 {
                    m.new_vertex(DVec3::splat(k as f64 * 0.25 - 7.0), 1, 1);
                }
                plain.resize(m.v_alive.len(), None);
            }
            buf.cover(&m);
            let share = [0.9, 0.8, 0.5, 0.05, 0.6][round];
            let mut points = Vec::new();
            for (i, last) in plain.iter_mut().enumerate() {
                if unit() >= share {
                    continue;
                }
                let cur = m.position(VertexId(i as u32));
                // The kinds of point: a tiny move, a move as a smoothing
                // step makes, none, a sign change, zeros, a huge move, a
                // subnormal point. The first rounds are mostly tiny
                // moves, then mostly larger ones, so that blocks widen
                // over points that were wide before.
                let weights: [f64; 7] = match round {
                    0 | 3 => [0.93, 0.03, 0.01, 0.01, 0.005, 0.01, 0.005],
                    1 => [0.02, 0.9, 0.02, 0.02, 0.01, 0.02, 0.01],
                    _ => [0.3, 0.3, 0.1, 0.1, 0.05, 0.1, 0.05],
                };
                let mut r = unit();
                let kind = weights
                    .iter()
                    .position(|&w| {
                        r -= w;
                        r < 0.0
                    })
                    .unwrap_or(6);
                let t = unit() - 0.5;
                let p = match kind {
                    0 => cur + cur * t * 1e-12,
                    1 => cur + cur * t * 1e-7,
                    2 => cur,
                    3 => -cur,
                    4 => DVec3::new(0.0, -0.0, cur.z),
                    5 => cur * 1e200 + DVec3::splat(t),
                    _ => DVec3::splat(f64::MIN_POSITIVE * t),
                };
                *last = Some(p);
                points.push((VertexId(i as u32), p));
            }
            buf.write(&m.pos, &points);
        }
        let before = m.pos.clone();
        // Small moves everywhere take fewer bytes than the points.
        buf.make_current(&mut m);
        for (i, (&got, (&was, want))) in m.pos.iter().zip(before.iter().zip(&plain)).enumerate() {
            let want = want.unwrap_or(was);
            assert_eq!(
                got.to_array().map(f64::to_bits),
                want.to_array().map(f64::to_bits),
                "slot {i}"
            );
        }
    }

    /// Writes that move every vertex a little take fewer bytes than the
    /// points would (24 a slot), and one far move among them goes to the
    /// block's list of wide points instead of widening the block.
    #[test]
    fn small_moves_take_fewer_bytes_than_points() {
        let mut m = Mesh::from_soup(&shapes::triangle_grid(150, 120)).expect("a grid");
        let n = m.v_alive.len();
        let mut next = rng(9);
        let mut points: Vec<(VertexId, DVec3)> = (0..n)
            .map(|i| {
                let v = VertexId(i as u32);
                let p = m.position(v) + DVec3::splat(1.0);
                m.set_position(v, p);
                let t = (next() >> 11) as f64 / (1u64 << 53) as f64;
                (v, p * (1.0 + 1e-10 * (t - 0.5)))
            })
            .collect();
        points[5].1 = DVec3::splat(-1e100);
        let mut buf = NextPositions::default();
        buf.cover(&m);
        buf.write(&m.pos, &points);
        let bytes: usize = buf.blocks.iter().map(|b| b.bytes()).sum();
        assert!(bytes < 12 * n, "{bytes} bytes for {n} slots");
        assert_eq!(buf.blocks[0].wide.len(), 1);
        buf.make_current(&mut m);
        for (v, p) in points {
            assert_eq!(
                m.position(v).to_array().map(f64::to_bits),
                p.to_array().map(f64::to_bits)
            );
        }
    }
}
