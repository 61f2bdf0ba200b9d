//! Thin polylines (a pen of at most one pixel) drawn by the ink they lay
//! down: each segment, cut into pieces of at most half a pixel, adds its
//! area (length times pen width) to the four pixels around each piece's
//! middle, weighted bilinearly; a pixel's coverage is the ink it gathered,
//! at most one; then the path's colour is blended over the picture once
//! per pixel it touched.
//!
//! For a straight line this is exact box coverage across the line (a
//! horizontal line at y = 10.25 covers a quarter of row 9 and three
//! quarters of row 10), and a curve of millions of segments shorter than a
//! pixel costs a few operations per segment. Overlaps within one path do
//! not darken it (a stroke covers a pixel at most once), where drawing each
//! segment as its own antialiased hairline does; and where a dense curve
//! fills a pixel, the pixel is filled. Paths with wider pens are stroked by
//! tiny-skia.

use glam::DVec2;
use tiny_skia::{Pixmap, PremultipliedColorU8};

use super::Rgba;

/// The longest piece a segment is cut into, in pixels.
const PIECE: f64 = 0.5;

/// Runs of thin lines with this many points or more in all are inked in
/// bands of rows, one per thread of rayon's pool.
const PARALLEL_POINTS: usize = 1 << 16;

/// The points of a [`Chunks`] chunk.
const CHUNK: usize = 1024;

/// Thin lines painted one after another (see [`Ink::paint`]).
pub(crate) trait Run: Sync {
    /// How many points the lines have in all.
    fn points(&self) -> usize;
    /// Paints the lines on `band`, in order: a line's ink laid down by
    /// [`Band::lay`], then its colour blended by [`Band::blend`].
    fn paint(&self, band: &mut Band<'_>, pixels: &mut [PremultipliedColorU8]);
}

/// A thin polyline to ink: its points, joined in order, with a pen `pen`
/// pixels wide (at most one), in `color`.
pub(crate) struct Line<'a> {
    pub(crate) points: &'a [DVec2],
    pub(crate) pen: f64,
    pub(crate) color: Rgba,
}

impl Run for [Line<'_>] {
    fn points(&self) -> usize {
        self.iter().map(|l| l.points.len()).sum()
    }

    fn paint(&self, band: &mut Band<'_>, pixels: &mut [PremultipliedColorU8]) {
        for line in self {
            if let [first, rest @ ..] = line.points {
                band.lay(*first, rest.iter().copied(), line.pen);
            }
            band.blend(pixels, line.color);
        }
    }
}

/// The span of y of a long array of points, chunk by chunk, so that a band
/// passes over the chunks that lie wholly above or below its rows without
/// looking at their points ([`Band::lay_chunked`]). Chunk `c` holds the
/// points `c * CHUNK..(c + 1) * CHUNK` and its span also takes in the
/// point before them, so that it covers every segment that ends in it.
pub(crate) struct Chunks {
    spans: Vec<[f64; 2]>,
}

impl Chunks {
    /// The chunks of `points`, measured on rayon's pool.
    pub(crate) fn new(points: &[DVec2]) -> Chunks {
        use rayon::prelude::*;
        let spans = (0..points.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let from = (c * CHUNK).saturating_sub(1);
                let to = ((c + 1) * CHUNK).min(points.len());
                points[from..to]
                    .iter()
                    .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], p| {
                        [lo.min(p.y), hi.max(p.y)]
                    })
            })
            .collect();
        Chunks { spans }
    }
}

/// The ink of one path at a time, over a picture of a given size.
pub(crate) struct Ink {
    width: usize,
    height: usize,
    /// The ink on each pixel, row by row.
    ink: Vec<f32>,
    /// The pixels with ink, each once: a list for each band of rows.
    touched: Vec<Vec<u32>>,
}

impl Ink {
    pub(crate) fn new(width: u32, height: u32) -> Ink {
        Ink {
            width: width as usize,
            height: height as usize,
            ink: vec![0.0; width as usize * height as usize],
            touched: vec![Vec::new()],
        }
    }

    /// How many bands of rows [`Ink::paint`] paints a run of `points`
    /// points in all in: one per thread of rayon's pool for a long run,
    /// else one.
    pub(crate) fn bands(&self, points: usize) -> usize {
        if points >= PARALLEL_POINTS && self.width > 0 {
            rayon::current_num_threads().min(self.height / 16).max(1)
        } else {
            1
        }
    }

    /// Paints the lines of `run` on `pm` one after another: the ink of a
    /// line is laid down, then its colour blended over the pixels it
    /// inked.
    ///
    /// Lines with many points in all are painted in bands of rows at once:
    /// each band walks every segment of every line and keeps the ink that
    /// falls on its rows, then blends its own pixels, line after line.
    /// Every pixel gathers its ink in the order of the segments and takes
    /// the lines' colours in their order, as on one thread, so the picture
    /// is the same to the bit.
    pub(crate) fn paint<R: Run + ?Sized>(&mut self, pm: &mut Pixmap, run: &R) {
        use rayon::prelude::*;
        let (width, height) = (self.width, self.height);
        let bands = self.bands(run.points());
        let rows = height.div_ceil(bands).max(1);
        if self.touched.len() < bands {
            self.touched.resize_with(bands, Vec::new);
        }
        let paint = |b: usize,
                     ink: &mut [f32],
                     touched: &mut Vec<u32>,
                     pixels: &mut [PremultipliedColorU8]| {
            let mut band = Band {
                width,
                height,
                row0: b * rows,
                rows: ink.len() / width.max(1),
                ink,
                touched,
            };
            run.paint(&mut band, pixels);
        };
        let pixels = pm.pixels_mut();
        if bands == 1 {
            paint(0, &mut self.ink, &mut self.touched[0], pixels);
        } else {
            self.ink
                .par_chunks_mut(rows * width)
                .zip(self.touched.par_iter_mut())
                .zip(pixels.par_chunks_mut(rows * width))
                .enumerate()
                .for_each(|(b, ((ink, touched), pixels))| paint(b, ink, touched, pixels));
        }
    }
}

/// The rows `row0..row0 + rows` of the ink, and the pixels among them
/// that have ink.
pub(crate) struct Band<'a> {
    width: usize,
    height: usize,
    row0: usize,
    rows: usize,
    /// The band's rows of [`Ink::ink`].
    ink: &'a mut [f32],
    touched: &'a mut Vec<u32>,
}

impl Band<'_> {
    /// The ink, on the band's rows, of the polyline from `from` through
    /// `points` in order, with a pen `pen` pixels wide; its last point.
    #[inline]
    pub(crate) fn lay(
        &mut self,
        from: DVec2,
        points: impl Iterator<Item = DVec2>,
        pen: f64,
    ) -> DVec2 {
        points.fold(from, |a, b| {
            self.segment(a, b, pen);
            b
        })
    }

    /// As [`Band::lay`] from `from` through `pixel` of `points[range]`,
    /// where `chunks` measures `points`, and `pixel`'s y depends on a
    /// point's y alone and monotonically (either way round): a chunk whose
    /// pixels all lie above or below the band's rows is passed over, its
    /// segments being ones that [`Band::segment`] would leave. The same
    /// ink, to the bit.
    #[inline]
    pub(crate) fn lay_chunked(
        &mut self,
        from: DVec2,
        points: &[DVec2],
        range: std::ops::Range<usize>,
        chunks: &Chunks,
        pixel: impl Fn(DVec2) -> DVec2,
        pen: f64,
    ) -> DVec2 {
        let Some(&second) = points.get(range.clone()).and_then(|r| r.first()) else {
            return from;
        };
        // The first segment starts at `from`, which may lie outside the
        // chunk's span (a line continued from another path).
        let mut last = self.lay(from, std::iter::once(pixel(second)), pen);
        let (top, bottom) = self.reach();
        let mut i = range.start + 1;
        while i < range.end {
            let c = i / CHUNK;
            let end = ((c + 1) * CHUNK).min(range.end);
            let [lo, hi] = chunks.spans[c];
            let (a, b) = (pixel(DVec2::new(0.0, lo)).y, pixel(DVec2::new(0.0, hi)).y);
            let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
            last = if hi < top || lo > bottom {
                pixel(points[end - 1])
            } else {
                self.lay(last, points[i..end].iter().map(|&q| pixel(q)), pen)
            };
            i = end;
        }
        last
    }

    /// The rows of y that a segment must reach for [`Band::segment`] to
    /// ink the band: a segment wholly above the first or below the second
    /// inks none of its rows.
    #[inline(always)]
    fn reach(&self) -> (f64, f64) {
        // A piece's middle at y inks rows floor(y - 0.5) and the one below
        // (nor does a piece clipping keeps of it reach further).
        (self.row0 as f64 - 2.0, (self.row0 + self.rows) as f64 + 2.0)
    }

    /// Blends `color` by the ink's coverage over the band's rows of the
    /// picture, `pixels`, where the ink lies, and clears the ink.
    pub(crate) fn blend(&mut self, pixels: &mut [PremultipliedColorU8], color: Rgba) {
        let alpha = color.3 as f32 / 255.0;
        let src = [color.0 as f32, color.1 as f32, color.2 as f32, 255.0];
        // The colour as an opaque pixel: over itself, at any coverage, it
        // gives itself (each channel comes within 1e-4 of its own value
        // before rounding); an opaque colour at full coverage gives it too.
        let solid = PremultipliedColorU8::from_rgba(color.0, color.1, color.2, 255)
            .expect("an opaque pixel is premultiplied");
        let opaque = color.3 == 255;
        let first = self.row0 * self.width;
        for &i in self.touched.iter() {
            let i = i as usize - first;
            let ink = self.ink[i];
            self.ink[i] = 0.0;
            let p = pixels[i];
            if p == solid {
                continue;
            }
            if opaque && ink >= 1.0 {
                pixels[i] = solid;
                continue;
            }
            if let Some(out) = over(p, src, ink.min(1.0) * alpha) {
                pixels[i] = out;
            }
        }
        self.touched.clear();
    }

    /// The ink of the segment `a`..`b` on the band's rows.
    #[inline(always)]
    fn segment(&mut self, a: DVec2, b: DVec2, pen: f64) {
        let (w, h) = (self.width as f64, self.height as f64);
        let inside = |p: DVec2| p.x >= 0.0 && p.y >= 0.0 && p.x <= w && p.y <= h;
        let (top, bottom) = self.reach();
        if (a.y < top && b.y < top) || (a.y > bottom && b.y > bottom) {
            return;
        }
        let Some((a, b)) = (if inside(a) && inside(b) {
            Some((a, b))
        } else {
            clip(a, b, w, h)
        }) else {
            return;
        };
        let d = b - a;
        let length = d.length();
        if length == 0.0 {
            return;
        }
        if length <= PIECE {
            // One piece (the general case's step is `d / 1.0`, its area
            // `length / 1.0 * pen`: the same numbers without dividing).
            self.splat(a + d * 0.5, (length * pen) as f32);
            return;
        }
        // As many pieces as `PIECE` needs (`ceil` without the call;
        // clipped lengths are a few times the picture's side at most).
        let whole = (length / PIECE) as usize;
        let pieces = whole + usize::from((whole as f64) * PIECE < length);
        let step = d / pieces as f64;
        let area = (length / pieces as f64 * pen) as f32;
        let mut c = a + step * 0.5;
        for _ in 0..pieces {
            self.splat(c, area);
            c += step;
        }
    }

    /// Adds `area` to those of the four pixels whose centres surround `c`
    /// that lie in the band.
    #[inline]
    fn splat(&mut self, c: DVec2, area: f32) {
        // Clipped points lie above -1, so that truncating after adding 2
        // is `floor` (without a call into libm).
        let (fx, fy) = (c.x + 1.5, c.y + 1.5);
        let (x0, y0) = (fx as i64, fy as i64);
        let (tx, ty) = ((fx - x0 as f64) as f32, (fy - y0 as f64) as f32);
        let (x0, y0) = (x0 - 2, y0 - 2);
        let weights = [
            (1.0 - tx) * (1.0 - ty),
            tx * (1.0 - ty),
            (1.0 - tx) * ty,
            tx * ty,
        ];
        let (first, end) = (self.row0 as i64, (self.row0 + self.rows) as i64);
        if x0 >= 0 && y0 >= first && x0 + 1 < self.width as i64 && y0 + 1 < end {
            // All four inside: no bounds to check.
            let i = y0 as usize * self.width + x0 as usize;
            for (k, weight) in weights.into_iter().enumerate() {
                let i = i + (k & 1) + (k >> 1) * self.width;
                self.add(i, area * weight);
            }
            return;
        }
        for (k, weight) in weights.into_iter().enumerate() {
            let (x, y) = (x0 + (k & 1) as i64, y0 + (k >> 1) as i64);
            if x < 0 || y < first || x >= self.width as i64 || y >= end {
                continue;
            }
            self.add(y as usize * self.width + x as usize, area * weight);
        }
    }

    /// Adds `ink` to pixel `i` (of the whole picture), noting the pixel
    /// when it gets its first ink: a piece whose ink is zero (a pen or a
    /// piece so thin that its area rounds to nothing) notes nothing, so
    /// that a pixel is noted once however many of them fall on it.
    #[inline(always)]
    fn add(&mut self, i: usize, ink: f32) {
        let cell = &mut self.ink[i - self.row0 * self.width];
        if *cell == 0.0 && ink > 0.0 {
            self.touched.push(i as u32);
        }
        *cell += ink;
    }
}

/// The part of the segment `a`..`b` within a pixel of the picture
/// `0..w` x `0..h` (Liang and Barsky's clipping), or `None`.
///
/// Where a side of the clip box cuts the segment, that end lies on the
/// side exactly (not at `a + d * t`, which loses the picture's scale when
/// the segment's ends are far away: from -1e17 to 1e17 both cuts fell at
/// the segment's middle and the line vanished), and both ends are kept in
/// the box.
fn clip(a: DVec2, b: DVec2, w: f64, h: f64) -> Option<(DVec2, DVec2)> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let sides = [
        (-d.x, a.x + 1.0),
        (d.x, w + 1.0 - a.x),
        (-d.y, a.y + 1.0),
        (d.y, h + 1.0 - a.y),
    ];
    // The value of the coordinate on each side.
    let on = [-1.0, w + 1.0, -1.0, h + 1.0];
    let mut rs = [f64::NAN; 4];
    for (k, (p, q)) in sides.into_iter().enumerate() {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            rs[k] = r;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if !(t0 <= t1 && t0.is_finite() && t1.is_finite()) {
        return None;
    }
    let (mut s, mut e) = (a + d * t0, a + d * t1);
    for k in 0..4 {
        let entering = sides[k].0 < 0.0;
        let end = if entering && t0 > 0.0 && rs[k] == t0 {
            &mut s
        } else if !entering && t1 < 1.0 && rs[k] == t1 {
            &mut e
        } else {
            continue;
        };
        if k < 2 {
            end.x = on[k];
        } else {
            end.y = on[k];
        }
    }
    let (lo, hi) = (DVec2::splat(-1.0), DVec2::new(w + 1.0, h + 1.0));
    Some((s.clamp(lo, hi), e.clamp(lo, hi)))
}

/// `src` (straight RGB and an alpha of 255) over the premultiplied pixel
/// `p` at coverage `a`, each channel rounded to a byte; `None` where the
/// result would not be premultiplied (it always is).
#[inline(always)]
fn over(p: PremultipliedColorU8, src: [f32; 4], a: f32) -> Option<PremultipliedColorU8> {
    let dst = [p.red(), p.green(), p.blue(), p.alpha()].map(f32::from);
    let mix = |k: usize| super::raster::to_byte(src[k] * a + dst[k] * (1.0 - a));
    let out_a = mix(3);
    PremultipliedColorU8::from_rgba(
        mix(0).min(out_a),
        mix(1).min(out_a),
        mix(2).min(out_a),
        out_a,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Ink {
        /// The pixels noted, band after band.
        fn noted(&self) -> Vec<u32> {
            self.touched.iter().flatten().copied().collect()
        }

        /// The whole picture as one band.
        fn whole(&mut self) -> Band<'_> {
            Band {
                width: self.width,
                height: self.height,
                row0: 0,
                rows: self.height,
                ink: &mut self.ink,
                touched: &mut self.touched[0],
            }
        }

        /// Lays down the ink of `points` on this thread, blending nothing.
        fn polyline(&mut self, points: &[DVec2], pen: f64) {
            if let [first, rest @ ..] = points {
                self.whole().lay(*first, rest.iter().copied(), pen);
            }
        }

        fn blend(&mut self, pm: &mut Pixmap, color: Rgba) {
            self.whole().blend(pm.pixels_mut(), color);
        }
    }

    /// Lines long enough in all to be painted in bands, in pools of one to
    /// four threads: the same picture to the bit, and the ink left clear.
    /// The lines overlap in colours with alpha, so that the order in which
    /// a pixel takes them shows; the longest wanders in and out of the
    /// picture (a spiral, jitter from a generator written here, and long
    /// jumps across it), and the picture's height is not a multiple of the
    /// bands'. One line at a time, laid segment by segment and blended on
    /// this thread, is the reference.
    #[test]
    fn lines_paint_the_same_in_bands() {
        let mut bits = crate::testing::xorshift(0x2545_f491_4f6c_dd1d);
        let mut next = || (bits() >> 11) as f64 / (1u64 << 53) as f64;
        let n = 3 * PARALLEL_POINTS;
        let spiral: Vec<DVec2> = (0..n)
            .map(|i| {
                let t = i as f64 / n as f64;
                let r = 10.0 + 60.0 * t;
                let a = t * 300.0;
                let jitter = DVec2::new(next() - 0.5, next() - 0.5) * 3.0;
                let jump = if i % 997 == 0 {
                    DVec2::new(0.0, 150.0)
                } else {
                    DVec2::ZERO
                };
                DVec2::new(50.0 + r * a.cos(), 45.0 + r * a.sin()) + jitter + jump
            })
            .collect();
        let short: Vec<Vec<DVec2>> = (0..300)
            .map(|_| {
                let a = DVec2::new(next() * 110.0 - 5.0, next() * 100.0 - 5.0);
                (0..1 + (next() * 6.0) as usize)
                    .map(|k| a + DVec2::new(next() - 0.5, next() - 0.5) * 8.0 * k as f64)
                    .collect()
            })
            .collect();
        let mut lines = vec![Line {
            points: &spiral,
            pen: 0.7,
            color: Rgba(200, 30, 60, 180),
        }];
        for (k, points) in short.iter().enumerate() {
            lines.push(Line {
                points,
                pen: [1.0, 0.4, 0.05][k % 3],
                color: Rgba(k as u8, 255 - k as u8, 90, [255, 128, 7][k % 3]),
            });
        }
        let background = tiny_skia::Color::from_rgba8(240, 240, 200, 255);
        let mut reference = Pixmap::new(101, 91).unwrap();
        reference.fill(background);
        let mut ink = Ink::new(101, 91);
        for line in &lines {
            for pair in line.points.windows(2) {
                ink.whole().segment(pair[0], pair[1], line.pen);
            }
            ink.blend(&mut reference, line.color);
        }
        for threads in 1..=4 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut pm = Pixmap::new(101, 91).unwrap();
            pm.fill(background);
            let mut ink = Ink::new(101, 91);
            pool.install(|| ink.paint(&mut pm, &lines[..]));
            assert!(pm == reference, "the picture differs on {threads} threads");
            assert!(ink.noted().is_empty() && ink.ink.iter().all(|&x| x == 0.0));
        }
        // The lines changed the picture, and the later ones show over the
        // spiral.
        let changed = (reference.pixels().iter())
            .filter(|p| (p.red(), p.green(), p.blue()) != (240, 240, 200))
            .count();
        assert!(changed > 3000, "{changed}");
    }

    /// A band's ink and noted pixels, laid by `lay` over every segment
    /// (the reference) and by `lay_chunked`, are the same to the bit: a
    /// wandering line of several chunks that crosses the bands, leaves the
    /// picture and jumps back, taken from starts inside and at the edge of
    /// a chunk, after a first point off the line (a joined path's), under
    /// a transform that turns y over and one that keeps it.
    #[test]
    fn chunks_outside_a_band_are_passed_over_to_the_bit() {
        let mut bits = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15);
        let mut next = || (bits() >> 11) as f64 / (1u64 << 53) as f64;
        // Each chunk keeps near a level of its own, so that the chunks'
        // spans end near the bands' edges as often as not, and the segment
        // that joins two chunks crosses bands that neither chunk reaches.
        let n = 24 * CHUNK + 77;
        let mut level = 0.0;
        let mut x = 30.0;
        let points: Vec<DVec2> = (0..n)
            .map(|i| {
                if i % CHUNK == 0 {
                    level = next() * 100.0 - 15.0;
                }
                x = (x + next() - 0.5).clamp(-5.0, 60.0);
                if i == 3000 {
                    return DVec2::new(-40.0, 200.0);
                }
                DVec2::new(x, level + (next() - 0.5) * 0.6)
            })
            .collect();
        let chunks = Chunks::new(&points);
        let flips: [fn(DVec2) -> DVec2; 2] = [
            |q| DVec2::new(q.x * 1.1 + 2.0, 80.0 - q.y),
            |q| DVec2::new(q.x - 1.0, q.y * 1.01 - 3.0),
        ];
        let (w, h) = (71usize, 83usize);
        // Bands with ink and without.
        let mut inked = [0, 0];
        for pixel in flips {
            for range in [
                1..n,
                CHUNK..n - 5,
                CHUNK + 1..3 * CHUNK + 9,
                2000..2001,
                7..7,
            ] {
                for bands in 1..=4 {
                    let rows = h.div_ceil(bands);
                    for b in 0..bands {
                        let row0 = b * rows;
                        let height = rows.min(h - row0);
                        let mut laid = [(vec![0.0f32; w * height], Vec::new()), Default::default()];
                        laid[1].0 = vec![0.0f32; w * height];
                        let from = DVec2::new(5.5, 40.25);
                        let mut ends = [DVec2::ZERO; 2];
                        for (k, (ink, touched)) in laid.iter_mut().enumerate() {
                            let mut band = Band {
                                width: w,
                                height: h,
                                row0,
                                rows: height,
                                ink,
                                touched,
                            };
                            ends[k] = if k == 0 {
                                band.lay(from, points[range.clone()].iter().map(|&q| pixel(q)), 0.8)
                            } else {
                                band.lay_chunked(from, &points, range.clone(), &chunks, pixel, 0.8)
                            };
                        }
                        let [(ia, na), (ib, nb)] = &laid;
                        let same = ia.iter().zip(ib).all(|(x, y)| x.to_bits() == y.to_bits());
                        assert!(same && na == nb, "{range:?}, band {b} of {bands}");
                        assert_eq!(ends[0], ends[1]);
                        inked[usize::from(!na.is_empty())] += 1;
                    }
                }
            }
        }
        // The line reaches some bands and misses others.
        assert!(inked[0] > 10 && inked[1] > 40, "{inked:?}");
    }

    fn ink_of(points: &[DVec2], pen: f64) -> Ink {
        let mut ink = Ink::new(20, 20);
        ink.polyline(points, pen);
        ink
    }

    #[test]
    fn a_horizontal_line_covers_the_rows_it_crosses_by_area() {
        // A pen of one pixel along y = 10.25 spans y in 9.75..10.75: a
        // quarter of row 9 and three quarters of row 10.
        let ink = ink_of(&[DVec2::new(2.0, 10.25), DVec2::new(18.0, 10.25)], 1.0);
        for x in 4..16 {
            let at = |y: usize| ink.ink[y * 20 + x];
            assert!((at(9) - 0.25).abs() < 1e-5, "{}", at(9));
            assert!((at(10) - 0.75).abs() < 1e-5, "{}", at(10));
            assert_eq!(at(8) + at(11), 0.0);
        }
        // All the ink is the line's area.
        let total: f32 = ink.ink.iter().sum();
        assert!((total - 16.0).abs() < 1e-3, "{total}");
    }

    #[test]
    fn a_thin_pen_lays_down_its_share() {
        let ink = ink_of(&[DVec2::new(3.0, 3.0), DVec2::new(15.0, 12.0)], 0.5);
        let total: f32 = ink.ink.iter().sum();
        // Length 15 (a 9-12-15 triangle) times half a pixel.
        assert!((total - 7.5).abs() < 1e-3, "{total}");
    }

    #[test]
    fn segments_far_outside_are_clipped_not_walked() {
        let far = ink_of(&[DVec2::new(-1e12, 5.5), DVec2::new(1e12, 5.5)], 1.0);
        // Only the 22 pixels of the row (and its margin) inside the picture.
        let total: f32 = far.ink.iter().sum();
        assert!((total - 20.0).abs() < 0.6, "{total}");
        let none = ink_of(&[DVec2::new(-50.0, -50.0), DVec2::new(-10.0, 80.0)], 1.0);
        assert!(none.noted().is_empty());
    }

    #[test]
    fn blending_full_ink_paints_the_colour_and_clears() {
        let mut ink = Ink::new(4, 4);
        let mut pm = Pixmap::new(4, 4).unwrap();
        pm.fill(tiny_skia::Color::WHITE);
        // Two passes over the same pixels: coverage stays at most one.
        ink.polyline(&[DVec2::new(0.0, 1.5), DVec2::new(4.0, 1.5)], 1.0);
        ink.polyline(&[DVec2::new(4.0, 1.5), DVec2::new(0.0, 1.5)], 1.0);
        ink.blend(&mut pm, Rgba(10, 20, 30, 255));
        let p = pm.pixel(2, 1).unwrap();
        assert_eq!((p.red(), p.green(), p.blue(), p.alpha()), (10, 20, 30, 255));
        let q = pm.pixel(2, 2).unwrap();
        assert_eq!((q.red(), q.alpha()), (255, 255));
        assert!(ink.noted().is_empty() && ink.ink.iter().all(|&x| x == 0.0));
    }

    #[test]
    fn pieces_with_no_ink_note_no_pixel() {
        // A pen so thin that each piece's ink rounds to zero in `f32`
        // (1e-50 of a pixel): before, every piece noted its four pixels
        // again (their ink stayed zero), so that a long path noted a pixel
        // over and over; now no pixel is noted, and none is blended.
        let ink = ink_of(&[DVec2::new(2.0, 2.0), DVec2::new(18.0, 18.0)], 1e-50);
        assert!(ink.noted().is_empty(), "{} pixels noted", ink.noted().len());
        // A normal pen notes each pixel once: the diagonal's pieces fall
        // on at most the pixels of the 3-pixel-wide band around it.
        let ink = ink_of(&[DVec2::new(2.0, 2.0), DVec2::new(18.0, 18.0)], 1.0);
        let mut seen = ink.noted();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), ink.noted().len());
        assert!(!seen.is_empty());
    }

    /// The blend's shortcuts (a pixel already the colour, an opaque
    /// colour at full coverage) give what the source-over formula gives,
    /// to the bit: random colours, pixels and coverages, a pixel equal to
    /// the colour in a quarter of them and one channel off it in another
    /// quarter, and full coverage in a third.
    #[test]
    fn the_blends_shortcuts_are_the_formula() {
        let mut bits = crate::testing::xorshift(0x6a09_e667_f3bc_c909);
        let mut byte = || (bits() >> 56) as u8;
        let mut skipped = [0; 2];
        for k in 0..20_000 {
            let alpha = [255, 0, 1, 128, 254][k % 5];
            let color = Rgba(
                byte(),
                byte(),
                byte(),
                if k % 7 == 0 { byte() } else { alpha },
            );
            let solid = PremultipliedColorU8::from_rgba(color.0, color.1, color.2, 255).unwrap();
            let a = byte();
            let p = if k % 4 == 0 {
                solid
            } else if k % 4 == 1 {
                // One channel off the colour's.
                let mut c = [color.0, color.1, color.2];
                c[k % 3] = c[k % 3].wrapping_add(1 + byte() % 3);
                PremultipliedColorU8::from_rgba(c[0], c[1], c[2], 255).unwrap()
            } else {
                PremultipliedColorU8::from_rgba(byte().min(a), byte().min(a), byte().min(a), a)
                    .unwrap()
            };
            let coverage = match k % 6 {
                0 => 1.0,
                1 => 1.0 + byte() as f32 / 7.0,
                2 => 1.0 - f32::EPSILON,
                _ => byte() as f32 / 255.0 + 1e-3,
            };
            let src = [color.0 as f32, color.1 as f32, color.2 as f32, 255.0];
            let expected = over(p, src, coverage.min(1.0) * (color.3 as f32 / 255.0)).unwrap_or(p);
            let mut ink = Ink::new(1, 1);
            ink.ink[0] = coverage;
            ink.touched[0].push(0);
            let mut pixels = [p];
            ink.whole().blend(&mut pixels, color);
            assert!(
                pixels[0] == expected,
                "{color:?} over {:?} at {coverage}",
                (p.red(), p.green(), p.blue(), p.alpha())
            );
            skipped[usize::from(p == solid)] += 1;
        }
        assert!(skipped[1] >= 5000, "{skipped:?}");
    }

    #[test]
    fn blending_is_tiny_skias_source_over() {
        // The ink's blend against tiny-skia filling one pixel with the
        // colour at the coverage's alpha (source-over on premultiplied
        // pixels), over transparent, half-transparent and opaque
        // backgrounds: equal to within one level of rounding.
        let backgrounds = [
            tiny_skia::Color::TRANSPARENT,
            tiny_skia::Color::from_rgba8(200, 40, 90, 128),
            tiny_skia::Color::from_rgba8(255, 255, 255, 255),
        ];
        let mut compared = 0;
        for bg in backgrounds {
            for alpha in [1u8, 77, 128, 254, 255] {
                for coverage in [0.1f32, 0.25, 0.5, 0.77, 1.0, 1.5] {
                    let color = Rgba(30, 200, 120, alpha);
                    let mut ours = Pixmap::new(1, 1).unwrap();
                    ours.fill(bg);
                    let mut theirs = ours.clone();
                    let mut ink = Ink::new(1, 1);
                    ink.ink[0] = coverage;
                    ink.touched[0].push(0);
                    ink.blend(&mut ours, color);
                    let mut paint = tiny_skia::Paint::default();
                    paint.set_color(
                        tiny_skia::Color::from_rgba(
                            30.0 / 255.0,
                            200.0 / 255.0,
                            120.0 / 255.0,
                            alpha as f32 / 255.0 * coverage.min(1.0),
                        )
                        .unwrap(),
                    );
                    let rect = tiny_skia::Rect::from_xywh(0.0, 0.0, 1.0, 1.0).unwrap();
                    theirs.fill_rect(rect, &paint, tiny_skia::Transform::identity(), None);
                    let (p, q) = (ours.pixel(0, 0).unwrap(), theirs.pixel(0, 0).unwrap());
                    let a = [p.red(), p.green(), p.blue(), p.alpha()];
                    let b = [q.red(), q.green(), q.blue(), q.alpha()];
                    for k in 0..4 {
                        assert!(
                            a[k].abs_diff(b[k]) <= 1,
                            "{a:?} against tiny-skia's {b:?} (alpha {alpha}, coverage {coverage})"
                        );
                    }
                    compared += 1;
                }
            }
        }
        assert_eq!(compared, 90);
    }

    #[test]
    fn hostile_points_neither_panic_nor_walk() {
        // NaN and infinite points (which the scene refuses before this),
        // coordinates of 1e300, zero-length segments and points on the
        // border: no panic, and no piece walked outside the clip box.
        let nan = f64::NAN;
        let inf = f64::INFINITY;
        let paths: [&[DVec2]; 6] = [
            &[
                DVec2::new(nan, 1.0),
                DVec2::new(5.0, 5.0),
                DVec2::new(nan, nan),
            ],
            &[
                DVec2::new(inf, 1.0),
                DVec2::new(-inf, 5.0),
                DVec2::new(5.0, inf),
            ],
            &[DVec2::new(1e300, 1e300), DVec2::new(-1e300, -1e300)],
            &[DVec2::new(1e308, 3.0), DVec2::new(-1e308, 3.0)],
            &[DVec2::new(7.0, 7.0), DVec2::new(7.0, 7.0)],
            &[
                DVec2::new(0.0, 0.0),
                DVec2::new(20.0, 0.0),
                DVec2::new(20.0, 20.0),
            ],
        ];
        for (k, points) in paths.iter().enumerate() {
            for pen in [0.3, 1.0] {
                let ink = ink_of(points, pen);
                let total: f32 = ink.ink.iter().sum();
                assert!(total.is_finite(), "path {k}: {total}");
                // At most the area of the longest clipped segments: two
                // sides of the box (22 pixels each) and a diagonal.
                assert!(total <= 3.0 * 22.0 * pen as f32 + 1e-3, "path {k}: {total}");
            }
        }
        // The border path (last) lays down its whole length: 40 pixels
        // of pen, less what falls outside the picture (half the pen along
        // each side, on the outer side of the border lines).
        let ink = ink_of(paths[5], 1.0);
        let total: f32 = ink.ink.iter().sum();
        assert!(total > 19.0 && total < 21.5, "{total}");
    }

    #[test]
    fn far_ends_keep_the_picture_scale() {
        // A row crossing the picture from -1e17 to 1e17 (and from -1e300
        // to 1e300): the clip used to put both cuts at the middle of the
        // segment (a + d * 0.5, the +1 of the box lost against 1e17), and
        // nothing was drawn; now it covers the row as the 1e12 one does.
        for far in [1e17, 1e300] {
            let ink = ink_of(&[DVec2::new(-far, 5.5), DVec2::new(far, 5.5)], 1.0);
            let total: f32 = ink.ink.iter().sum();
            assert!((total - 20.0).abs() < 0.6, "{far}: {total}");
            // The diagonal: through the corners of the box.
            let ink = ink_of(&[DVec2::new(-far, -far), DVec2::new(far, far)], 1.0);
            let total: f32 = ink.ink.iter().sum();
            // 20 * sqrt(2) pixels of pen inside the picture, less the
            // half-pen margins at the two corners.
            assert!(total > 26.0 && total < 29.0, "{far}: {total}");
        }
    }
}
