//! Distances from points to a polyline, with a uniform grid over the
//! segments so that large contours are measured in near-linear time.

use glam::DVec2;
use serde::Serialize;

/// Maximum, mean and root-mean-square distance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Error {
    pub max: f64,
    pub mean: f64,
    pub rms: f64,
}

fn point_segment(p: DVec2, a: DVec2, b: DVec2) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance(a + t * ab)
}

/// The distance of each of `points` to the polyline `line` (closed when
/// `closed`), summarised.
pub fn distance(points: &[DVec2], line: &[DVec2], closed: bool) -> Error {
    let n = line.len();
    let segs: Vec<(DVec2, DVec2)> = match n {
        0 => Vec::new(),
        1 => vec![(line[0], line[0])],
        _ => {
            let last = if closed { n } else { n - 1 };
            (0..last).map(|i| (line[i], line[(i + 1) % n])).collect()
        }
    };
    if segs.is_empty() || points.is_empty() {
        return Error {
            max: f64::NAN,
            mean: f64::NAN,
            rms: f64::NAN,
        };
    }
    // A uniform grid over the segments' bounding box, about as many cells
    // as segments, stored flat: cell -> range of segment indices.
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for (a, b) in &segs {
        lo = lo.min(a.min(*b));
        hi = hi.max(a.max(*b));
    }
    let ext = (hi - lo).max(DVec2::splat(1e-12));
    let cell = ((ext.x * ext.y) / segs.len() as f64)
        .sqrt()
        .max(ext.max_element() / 4096.0)
        .max(1e-12);
    let nx = ((ext.x / cell).floor() as usize + 1).min(1 << 13);
    let ny = ((ext.y / cell).floor() as usize + 1).min(1 << 13);
    let key = |p: DVec2| -> (i64, i64) {
        (
            ((p.x - lo.x) / cell).floor() as i64,
            ((p.y - lo.y) / cell).floor() as i64,
        )
    };
    let clamp = |k: (i64, i64)| -> (usize, usize) {
        (
            k.0.clamp(0, nx as i64 - 1) as usize,
            k.1.clamp(0, ny as i64 - 1) as usize,
        )
    };
    let mut count = vec![0u32; nx * ny + 1];
    let cells_of = |a: DVec2, b: DVec2| {
        let (ka, kb) = (clamp(key(a.min(b))), clamp(key(a.max(b))));
        (ka.1..=kb.1).flat_map(move |y| (ka.0..=kb.0).map(move |x| y * nx + x))
    };
    for (a, b) in &segs {
        for c in cells_of(*a, *b) {
            count[c + 1] += 1;
        }
    }
    for i in 1..count.len() {
        count[i] += count[i - 1];
    }
    let mut fill = count.clone();
    let mut index = vec![0u32; count[nx * ny] as usize];
    for (i, (a, b)) in segs.iter().enumerate() {
        for c in cells_of(*a, *b) {
            index[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
    }
    let (mut max, mut sum, mut sum2) = (0.0f64, 0.0, 0.0);
    for &p in points {
        let (cx, cy) = key(p);
        let mut best = f64::INFINITY;
        let mut r = 0i64;
        // Search rings of cells until no closer segment can exist: a cell
        // r + 1 rings away is at least r cells from the point.
        loop {
            for y in cy - r..=cy + r {
                if y < 0 || y >= ny as i64 {
                    continue;
                }
                for x in cx - r..=cx + r {
                    if x < 0 || x >= nx as i64 || ((x - cx).abs() != r && (y - cy).abs() != r) {
                        continue;
                    }
                    let c = y as usize * nx + x as usize;
                    for &i in &index[count[c] as usize..count[c + 1] as usize] {
                        let (a, b) = segs[i as usize];
                        best = best.min(point_segment(p, a, b));
                    }
                }
            }
            let outside =
                cx - r <= 0 && cy - r <= 0 && cx + r >= nx as i64 - 1 && cy + r >= ny as i64 - 1;
            if best <= r as f64 * cell || outside {
                break;
            }
            r += 1;
        }
        max = max.max(best);
        sum += best;
        sum2 += best * best;
    }
    let k = points.len() as f64;
    Error {
        max,
        mean: sum / k,
        rms: (sum2 / k).sqrt(),
    }
}
