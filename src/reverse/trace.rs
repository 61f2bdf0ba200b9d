//! Tracing a silhouette in a raster image: marching squares with linear
//! interpolation (sub-pixel contours), segments linked into closed loops.
//!
//! The tracer keeps one byte a cell (its marching-squares case) and one bit
//! an edge (seen), never a table of segments, and of the loops only the
//! largest so far (its area, first edge and length; its points are walked
//! again at the end, at most [`MAX_CONTOUR_POINTS`]): an 8192 × 8192 image
//! of any kind (a checkerboard, where every cell holds a segment, or one
//! endless spiral) is traced in about 100 MB beside the image and the
//! result. The deadline is looked at every row and every 65,536 steps along
//! a loop.

use glam::DVec2;

use crate::deadline::{self, Deadline};

/// A crossing point is identified by the grid edge it lies on: (x, y, 0)
/// on the horizontal edge (x,y)-(x+1,y), (x, y, 1) on the vertical edge
/// (x,y)-(x,y+1).
type Key = (isize, isize, u8);

/// The field as the tracer sees it: `w`×`h` values, padded with `outside`.
struct Grid<F> {
    value: F,
    w: isize,
    h: isize,
    level: f64,
    outside: f64,
}

impl<F: Fn(usize, usize) -> f64> Grid<F> {
    fn at(&self, x: isize, y: isize) -> f64 {
        if x < 0 || y < 0 || x >= self.w || y >= self.h {
            self.outside
        } else {
            (self.value)(x as usize, y as usize)
        }
    }

    fn point(&self, k: Key) -> DVec2 {
        let (x, y, d) = k;
        let (x1, y1) = if d == 0 { (x + 1, y) } else { (x, y + 1) };
        let (a, b) = (self.at(x, y), self.at(x1, y1));
        let t = if (b - a).abs() < 1e-300 {
            0.5
        } else {
            ((self.level - a) / (b - a)).clamp(0.0, 1.0)
        };
        DVec2::new(
            x as f64 + t * (x1 - x) as f64,
            y as f64 + t * (y1 - y) as f64,
        )
    }
}

/// The case of a cell from its corners' values (top-left, top-right,
/// bottom-right, bottom-left): which corners lie inside (below the level),
/// and, bit 4, for a saddle, whether the centre does.
fn case(level: f64, a: f64, b: f64, c: f64, d: f64) -> u8 {
    let case = ((a < level) as u8)
        | ((b < level) as u8) << 1
        | ((c < level) as u8) << 2
        | ((d < level) as u8) << 3;
    if case == 5 || case == 10 {
        let centre = (a + b + c + d) / 4.0;
        case | ((centre < level) as u8) << 4
    } else {
        case
    }
}

/// The directed segments of the cell (x, y) with case `code`, the inside
/// on the left, so that loops come out consistently.
fn segments(code: u8, x: isize, y: isize) -> ([(Key, Key); 2], usize) {
    // Edges of the cell: top (x,y)-(x+1,y), right (x+1,y)-(x+1,y+1),
    // bottom (x,y+1)-(x+1,y+1), left (x,y)-(x,y+1).
    let top: Key = (x, y, 0);
    let right: Key = (x + 1, y, 1);
    let bottom: Key = (x, y + 1, 0);
    let left: Key = (x, y, 1);
    let none = (top, top);
    let one = |s: (Key, Key)| ([s, none], 1);
    let centre_inside = code & 16 != 0;
    match code & 15 {
        1 => one((left, top)),
        2 => one((top, right)),
        3 => one((left, right)),
        4 => one((right, bottom)),
        5 if centre_inside => ([(left, bottom), (right, top)], 2),
        5 => ([(left, top), (right, bottom)], 2),
        6 => one((top, bottom)),
        7 => one((left, bottom)),
        8 => one((bottom, left)),
        9 => one((bottom, top)),
        10 if centre_inside => ([(top, left), (bottom, right)], 2),
        10 => ([(top, right), (bottom, left)], 2),
        11 => one((bottom, right)),
        12 => one((right, left)),
        13 => one((right, top)),
        14 => one((top, left)),
        _ => ([none, none], 0),
    }
}

/// The cells' cases, one byte a cell, for the cells (x, y) with x in
/// -1..w and y in -1..h (the padded field's cells).
struct Cells {
    codes: Vec<u8>,
    w: isize,
    h: isize,
}

impl Cells {
    fn code(&self, x: isize, y: isize) -> u8 {
        if x < -1 || y < -1 || x >= self.w || y >= self.h {
            return 0;
        }
        self.codes[((y + 1) * (self.w + 1) + (x + 1)) as usize]
    }

    /// Where the segment that leaves edge `k` goes, if one does: `k` is an
    /// edge of two cells, and a segment of one of them starts on it.
    fn next(&self, k: Key) -> Option<Key> {
        let (x, y, d) = k;
        let cells = if d == 0 {
            [(x, y), (x, y - 1)]
        } else {
            [(x, y), (x - 1, y)]
        };
        // The later cell in the scan order wins, as it did when the
        // segments were kept in a table filled in that order.
        let mut found = None;
        for (cx, cy) in [cells[1], cells[0]] {
            let (segs, n) = segments(self.code(cx, cy), cx, cy);
            for &(from, to) in &segs[..n] {
                if from == k {
                    found = Some(to);
                }
            }
        }
        found
    }
}

/// One bit an edge, for the keys (x, y, d) with x in -1..=w, y in -1..=h.
struct Seen {
    bits: Vec<u64>,
    w: isize,
}

impl Seen {
    fn index(&self, (x, y, d): Key) -> usize {
        (((y + 1) * (self.w + 2) + (x + 1)) * 2 + d as isize) as usize
    }
    fn get(&self, k: Key) -> bool {
        let i = self.index(k);
        self.bits[i / 64] >> (i % 64) & 1 != 0
    }
    fn set(&mut self, k: Key) {
        let i = self.index(k);
        self.bits[i / 64] |= 1 << (i % 64);
    }
}

/// The largest closed loop (by the absolute area it encloses; the last of
/// equals in the scan order) of the iso-contours at `level` of a `w`×`h`
/// field, `value(x, y)` at each pixel centre, padded with `outside` so
/// that every contour closes; `None` when there is none of three points
/// or more. Stops with the deadline's message once `deadline` passes.
pub fn largest_contour(
    value: impl Fn(usize, usize) -> f64,
    w: usize,
    h: usize,
    level: f64,
    outside: f64,
    deadline: Option<Deadline>,
) -> Result<Option<Vec<DVec2>>, String> {
    let g = Grid {
        value,
        w: w as isize,
        h: h as isize,
        level,
        outside,
    };
    let (wi, hi) = (w as isize, h as isize);
    // The cases, row by row, each row of values computed once.
    let mut codes = Vec::with_capacity((w + 1) * (h + 1));
    let row = |y: isize| -> Vec<f64> { (-1..=wi).map(|x| g.at(x, y)).collect() };
    let mut upper = row(-1);
    for y in -1..hi {
        deadline::check(deadline)?;
        let lower = row(y + 1);
        for i in 0..=w {
            codes.push(case(level, upper[i], upper[i + 1], lower[i + 1], lower[i]));
        }
        upper = lower;
    }
    let cells = Cells {
        codes,
        w: wi,
        h: hi,
    };
    let edges = 2 * (w + 2) * (h + 2);
    let mut seen = Seen {
        bits: vec![0; edges.div_ceil(64)],
        w: wi,
    };
    // The largest loop so far: its area, first edge and length. Loops are
    // measured as they are followed and only the largest is walked again
    // for its points, so that an image of one endless outline (a spiral)
    // holds no points but the result's.
    let mut best: Option<(f64, Key, usize)> = None;
    let mut steps: u64 = 0;
    // Loops start at their first edge in the order (y, x, d), so that the
    // same image always gives the same contour with the same first point.
    for y in -1..=hi {
        deadline::check(deadline)?;
        for x in -1..=wi {
            // An edge starts a segment only in the cell below or right of
            // it, or above or left: where those have none (most of an
            // image), there is nothing to follow.
            let quiet = |c: u8| c & 15 == 0 || c & 15 == 15;
            if quiet(cells.code(x, y)) && quiet(cells.code(x - 1, y)) && quiet(cells.code(x, y - 1))
            {
                continue;
            }
            for d in 0..2u8 {
                let start: Key = (x, y, d);
                if seen.get(start) || cells.next(start).is_none() {
                    continue;
                }
                // Twice the signed area, summed in the order
                // `signed_area2` sums it, so equal to it to the bit.
                let first = g.point(start);
                let (mut prev, mut area, mut count) = (first, -0.0f64, 0usize);
                let mut k = start;
                loop {
                    steps += 1;
                    if steps.is_multiple_of(1 << 16) {
                        deadline::check(deadline)?;
                    }
                    seen.set(k);
                    if count > 0 {
                        let p = g.point(k);
                        area += prev.perp_dot(p);
                        prev = p;
                    }
                    count += 1;
                    match cells.next(k) {
                        Some(n) if n == start => break,
                        Some(n) if !seen.get(n) => k = n,
                        _ => break,
                    }
                }
                area += prev.perp_dot(first);
                if count >= 3 {
                    let area = area.abs();
                    if best
                        .as_ref()
                        .is_none_or(|(b, _, _)| area.total_cmp(b).is_ge())
                    {
                        best = Some((area, start, count));
                    }
                }
            }
        }
    }
    let Some((_, start, count)) = best else {
        return Ok(None);
    };
    if count > MAX_CONTOUR_POINTS {
        return Err(format!(
            "the largest outline in the image has {count} points, more than the {MAX_CONTOUR_POINTS} \
             a traced contour may have; scale the image down or simplify the shape"
        ));
    }
    // The same walk again: `next` is a function of the cells, so the same
    // `count` edges from `start`.
    let mut pts = Vec::with_capacity(count);
    let mut k = start;
    for _ in 0..count {
        pts.push(g.point(k));
        k = cells.next(k).unwrap_or(k);
    }
    Ok(Some(pts))
}

/// The most points a traced contour may have (128 MiB of points): an
/// outline a person draws has thousands; an 8192-pixel spiral would have
/// tens of millions.
pub const MAX_CONTOUR_POINTS: usize = 8 << 20;

/// Twice the signed area of a closed polygon.
pub fn signed_area2(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// The tracer as it was: every segment in a table, every loop kept;
    /// the largest by `max_by` (the last of equals).
    fn reference(
        field: &[f64],
        w: usize,
        h: usize,
        level: f64,
        outside: f64,
    ) -> Option<Vec<DVec2>> {
        let g = Grid {
            value: |x: usize, y: usize| field[y * w + x],
            w: w as isize,
            h: h as isize,
            level,
            outside,
        };
        let mut next: HashMap<Key, Key> = HashMap::new();
        for y in -1..h as isize {
            for x in -1..w as isize {
                let code = case(
                    level,
                    g.at(x, y),
                    g.at(x + 1, y),
                    g.at(x + 1, y + 1),
                    g.at(x, y + 1),
                );
                let (segs, n) = segments(code, x, y);
                for &(from, to) in &segs[..n] {
                    next.insert(from, to);
                }
            }
        }
        let mut keys: Vec<Key> = next.keys().copied().collect();
        keys.sort_unstable_by_key(|&(x, y, d)| (y, x, d));
        let mut seen = std::collections::HashSet::new();
        let mut loops = Vec::new();
        for start in keys {
            if seen.contains(&start) {
                continue;
            }
            let mut pts = Vec::new();
            let mut k = start;
            loop {
                seen.insert(k);
                pts.push(g.point(k));
                match next.get(&k) {
                    Some(&n) if n == start => break,
                    Some(&n) if !seen.contains(&n) => k = n,
                    _ => break,
                }
            }
            if pts.len() >= 3 {
                loops.push(pts);
            }
        }
        loops
            .into_iter()
            .max_by(|a, b| signed_area2(a).abs().total_cmp(&signed_area2(b).abs()))
    }

    #[test]
    fn agrees_with_the_table_of_segments() {
        // Random fields with saddles, blobs and shapes touching the frame.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut rand = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for (w, h) in [(1, 1), (2, 3), (7, 5), (16, 16), (31, 9)] {
            for trial in 0..20 {
                let field: Vec<f64> = (0..w * h)
                    .map(|_| {
                        if trial % 2 == 0 {
                            rand()
                        } else {
                            (rand() * 3.0).floor() / 2.0
                        }
                    })
                    .collect();
                let got = largest_contour(|x, y| field[y * w + x], w, h, 0.5, 1.0, None).unwrap();
                assert_eq!(
                    got,
                    reference(&field, w, h, 0.5, 1.0),
                    "{w}x{h} trial {trial}"
                );
            }
        }
    }

    #[test]
    fn a_passed_deadline_stops_the_trace() {
        let d = Deadline::after(std::time::Duration::ZERO);
        let e = largest_contour(|_, _| 0.0, 4, 4, 0.5, 1.0, Some(d)).unwrap_err();
        assert!(e.contains("time limit"), "{e}");
    }
}
