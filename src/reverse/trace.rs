//! Tracing a silhouette in a raster image: marching squares with linear
//! interpolation (sub-pixel contours), segments linked into closed loops.

use std::collections::HashMap;

use glam::DVec2;

/// The iso-contours at `level` of a `w`×`h` field (row-major, one value per
/// pixel centre), as closed loops. The field is padded with `outside` so
/// every contour closes.
pub fn contours(field: &[f64], w: usize, h: usize, level: f64, outside: f64) -> Vec<Vec<DVec2>> {
    let at = |x: isize, y: isize| -> f64 {
        if x < 0 || y < 0 || x >= w as isize || y >= h as isize {
            outside
        } else {
            field[y as usize * w + x as usize]
        }
    };
    // A crossing point is identified by the grid edge it lies on:
    // (x, y, 0) on the horizontal edge (x,y)-(x+1,y), (x, y, 1) on the
    // vertical edge (x,y)-(x,y+1).
    type Key = (isize, isize, u8);
    let point = |k: Key| -> DVec2 {
        let (x, y, d) = k;
        let (x1, y1) = if d == 0 { (x + 1, y) } else { (x, y + 1) };
        let (a, b) = (at(x, y), at(x1, y1));
        let t = if (b - a).abs() < 1e-300 {
            0.5
        } else {
            ((level - a) / (b - a)).clamp(0.0, 1.0)
        };
        DVec2::new(
            x as f64 + t * (x1 - x) as f64,
            y as f64 + t * (y1 - y) as f64,
        )
    };
    // next[from] = to: each cell contributes directed segments with the
    // inside (value < level) on the left, so loops come out consistently.
    let mut next: HashMap<Key, Key> = HashMap::new();
    for y in -1..h as isize {
        for x in -1..w as isize {
            let inside = |x, y| at(x, y) < level;
            let (a, b, c, d) = (
                inside(x, y),
                inside(x + 1, y),
                inside(x + 1, y + 1),
                inside(x, y + 1),
            );
            let case = (a as u8) | (b as u8) << 1 | (c as u8) << 2 | (d as u8) << 3;
            // Edges of the cell: top (x,y)-(x+1,y), right (x+1,y)-(x+1,y+1),
            // bottom (x,y+1)-(x+1,y+1), left (x,y)-(x,y+1).
            let top: Key = (x, y, 0);
            let right: Key = (x + 1, y, 1);
            let bottom: Key = (x, y + 1, 0);
            let left: Key = (x, y, 1);
            let segs: &[(Key, Key)] = match case {
                0 | 15 => &[],
                1 => &[(left, top)],
                2 => &[(top, right)],
                3 => &[(left, right)],
                4 => &[(right, bottom)],
                5 => {
                    // A saddle: decide by the centre value.
                    let centre = (at(x, y) + at(x + 1, y) + at(x + 1, y + 1) + at(x, y + 1)) / 4.0;
                    if centre < level {
                        &[(left, bottom), (right, top)]
                    } else {
                        &[(left, top), (right, bottom)]
                    }
                }
                6 => &[(top, bottom)],
                7 => &[(left, bottom)],
                8 => &[(bottom, left)],
                9 => &[(bottom, top)],
                10 => {
                    let centre = (at(x, y) + at(x + 1, y) + at(x + 1, y + 1) + at(x, y + 1)) / 4.0;
                    if centre < level {
                        &[(top, left), (bottom, right)]
                    } else {
                        &[(top, right), (bottom, left)]
                    }
                }
                11 => &[(bottom, right)],
                12 => &[(right, left)],
                13 => &[(right, top)],
                14 => &[(top, left)],
                _ => &[],
            };
            for &(from, to) in segs {
                next.insert(from, to);
            }
        }
    }
    let mut loops = Vec::new();
    // A fixed order, so that the same image always gives the same contour
    // with the same first point.
    let mut keys: Vec<Key> = next.keys().copied().collect();
    keys.sort_unstable_by_key(|&(x, y, d)| (y, x, d));
    let mut seen: HashMap<Key, bool> = HashMap::new();
    for start in keys {
        if seen.contains_key(&start) {
            continue;
        }
        let mut pts = Vec::new();
        let mut k = start;
        loop {
            seen.insert(k, true);
            pts.push(point(k));
            match next.get(&k) {
                Some(&n) if n == start => break,
                Some(&n) if !seen.contains_key(&n) => k = n,
                _ => break,
            }
        }
        if pts.len() >= 3 {
            loops.push(pts);
        }
    }
    loops
}

/// Twice the signed area of a closed polygon.
pub fn signed_area2(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum()
}
