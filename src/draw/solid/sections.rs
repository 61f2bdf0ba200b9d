//! Cross-sections (lpfg's circle and the model's contours), and the rings,
//! strips and caps that tubes and generalized cylinders are made of.

use glam::DVec3;

use super::{fits, Builder};
use crate::model::view::MIN_CONTOUR_SIDES;

/// A cross-section: its distinct points and unit normals in the plane
/// (x along the turtle's left, y along its up vector).
#[derive(Clone, Debug, Default)]
pub(super) struct Section {
    pub(super) points: Vec<[f64; 2]>,
    normals: Vec<[f64; 2]>,
    pub(super) closed: bool,
    /// The points run clockwise (lpfg's circle does): with them the
    /// triangles below face outwards.
    pub(super) clockwise: bool,
}

impl Section {
    /// lpfg's circle of radius 1 with `sides` sides, from (0, 1)
    /// clockwise.
    fn circle(sides: u32) -> Section {
        let n = sides.max(MIN_CONTOUR_SIDES) as usize;
        let points: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let (s, c) = (std::f64::consts::TAU * i as f64 / n as f64).sin_cos();
                [s, c]
            })
            .collect();
        Section {
            normals: points.clone(),
            points,
            closed: true,
            clockwise: true,
        }
    }

    /// The section of `points` (a closed one without its repeated last
    /// point), normals from its neighbours, outwards for a closed one.
    fn of_points(points: Vec<[f64; 2]>, closed: bool) -> Section {
        let n = points.len();
        // Twice the signed area (shoelace); negative for clockwise.
        let area: f64 = (0..n)
            .map(|i| {
                let (p, q) = (points[i], points[(i + 1) % n]);
                p[0] * q[1] - q[0] * p[1]
            })
            .sum();
        let clockwise = area < 0.0;
        let side = if clockwise { 1.0 } else { -1.0 };
        let normals = (0..n)
            .map(|i| {
                let (prev, next) = if closed {
                    (points[(i + n - 1) % n], points[(i + 1) % n])
                } else {
                    (points[i.saturating_sub(1)], points[(i + 1).min(n - 1)])
                };
                let t = [next[0] - prev[0], next[1] - prev[1]];
                let len = (t[0] * t[0] + t[1] * t[1]).sqrt();
                if len > 0.0 {
                    [-side * t[1] / len, side * t[0] / len]
                } else {
                    [0.0, 0.0]
                }
            })
            .collect();
        Section {
            points,
            normals,
            closed,
            clockwise,
        }
    }
}

/// Which section a generalized cylinder's ring has: contours, blend and
/// the number of samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct SectionKey {
    pub(super) contour: usize,
    pub(super) contour2: usize,
    pub(super) blend: f32,
    pub(super) samples: u32,
}

impl<'m> Builder<'m> {
    pub(super) fn circle(&mut self, sides: u32) -> usize {
        if let Some(k) = self
            .circles
            .iter()
            .position(|s| s.points.len() == sides as usize)
        {
            return k;
        }
        self.circles.push(Section::circle(sides));
        self.circles.len() - 1
    }

    /// The section of `key`, made on first use (a few are kept).
    pub(super) fn section(&mut self, key: SectionKey) -> usize {
        if let Some(k) = self.sections.iter().position(|(k, _)| *k == key) {
            return k;
        }
        if self.sections.len() >= 64 {
            self.sections.clear();
        }
        let sample = |id: usize| {
            let mut c = self.contour(id);
            if c.samples != key.samples as usize {
                c = std::borrow::Cow::Owned(c.resampled(key.samples as usize));
            }
            let mut pts: Vec<[f64; 2]> = c
                .vertices
                .iter()
                .map(|v| [v[0] as f64, v[1] as f64])
                .collect();
            if c.closed && pts.len() > 1 && pts.first() == pts.last() {
                pts.pop();
            }
            (pts, c.closed)
        };
        let (mut pts, closed) = sample(key.contour);
        if key.blend > 0.0 {
            let (other, _) = sample(key.contour2);
            let b = key.blend as f64;
            for (p, q) in pts.iter_mut().zip(&other) {
                *p = [p[0] * (1.0 - b) + q[0] * b, p[1] * (1.0 - b) + q[1] * b];
            }
        }
        self.sections.push((key, Section::of_points(pts, closed)));
        self.sections.len() - 1
    }

    /// Makes a ring of section `sec` (a circle when `tube`) centred at `c`
    /// with axes `l`, `u` scaled by half of `scale`: its first vertex.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn ring(
        &mut self,
        mesh: u32,
        tube: bool,
        sec: usize,
        c: DVec3,
        l: DVec3,
        u: DVec3,
        scale: (f64, f64),
    ) -> Result<u32, String> {
        let (sx, sy) = (0.5 * scale.0.abs(), 0.5 * scale.1.abs());
        if !fits(c, sx.max(sy) * 4.0) {
            return Err("makes a cylinder that reaches an infinite coordinate".into());
        }
        // Normals of a scaled section: the inverse scale (a zero scale
        // keeps the section's own).
        let (nx, ny) = if sx > 0.0 && sy > 0.0 {
            (1.0 / sx, 1.0 / sy)
        } else {
            (1.0, 1.0)
        };
        let (ls, us) = (l * sx, u * sy);
        let (ln, un) = (l * nx, u * ny);
        // The section is lent out of `self` while the mesh grows.
        fn slot<'a>(b: &'a mut Builder<'_>, tube: bool, sec: usize) -> &'a mut Section {
            if tube {
                &mut b.circles[sec]
            } else {
                &mut b.sections[sec].1
            }
        }
        let s = std::mem::take(slot(self, tube, sec));
        // Unit section normals stay unit under a uniform scale.
        let uniform = sx == sy;
        let result = self.room(mesh, s.points.len(), 0).map(|m| {
            let base = m.positions.len() as u32;
            for (p, q) in s.points.iter().zip(&s.normals) {
                m.positions.push((c + ls * p[0] + us * p[1]).as_vec3());
                let n = if uniform {
                    l * q[0] + u * q[1]
                } else {
                    (ln * q[0] + un * q[1]).normalize_or_zero()
                };
                m.normals.push(n.as_vec3());
            }
            base
        });
        *slot(self, tube, sec) = s;
        result
    }

    /// The quads between rings `a` and `b` of `n` points each.
    pub(super) fn strip(
        &mut self,
        mesh: u32,
        a: u32,
        b: u32,
        n: u32,
        closed: bool,
        clockwise: bool,
    ) -> Result<(), String> {
        let quads = if closed { n } else { n.saturating_sub(1) };
        let m = self.room(mesh, 0, 2 * quads as usize)?;
        for i in 0..quads {
            let j = (i + 1) % n;
            let (ai, aj, bi, bj) = (a + i, a + j, b + i, b + j);
            if clockwise {
                m.triangles.push([ai, bj, aj]);
                m.triangles.push([ai, bi, bj]);
            } else {
                m.triangles.push([ai, aj, bj]);
                m.triangles.push([ai, bj, bi]);
            }
        }
        Ok(())
    }

    /// A disc closing the ring of section `sec` at `c`, facing `-h` at a
    /// start and `h` at an end: a fan from the centroid on vertices of
    /// its own.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn cap(
        &mut self,
        mesh: u32,
        tube: bool,
        sec: usize,
        c: DVec3,
        (l, u, h): (DVec3, DVec3, DVec3),
        scale: (f64, f64),
        start: bool,
    ) -> Result<(), String> {
        let s = if tube {
            &self.circles[sec]
        } else {
            &self.sections[sec].1
        };
        if !s.closed {
            return Ok(());
        }
        let (sx, sy) = (0.5 * scale.0.abs(), 0.5 * scale.1.abs());
        let n = s.points.len();
        let pts: Vec<DVec3> = s
            .points
            .iter()
            .map(|p| c + l * (sx * p[0]) + u * (sy * p[1]))
            .collect();
        // The centroid of the section's points, as lpfg takes it.
        let centre = pts.iter().copied().sum::<DVec3>() / n as f64;
        let flip = start != s.clockwise;
        let normal = if start { -h } else { h };
        self.fan(mesh, centre, normal, &pts, flip)
    }
}
