//! The flat and round shapes: fans, discs and rings, spheres, and
//! polygons cut into triangles.

use glam::DVec3;

use super::super::Turtle;
use super::{Builder, MAX_EAR_CLIPPING};

impl<'m> Builder<'m> {
    /// A fan of triangles from `centre` over the closed loop `pts`, on
    /// vertices of its own, all with the normal `normal`; `flip` turns
    /// every triangle the other way round.
    pub(super) fn fan(
        &mut self,
        mesh: u32,
        centre: DVec3,
        normal: DVec3,
        pts: &[DVec3],
        flip: bool,
    ) -> Result<(), String> {
        let n = pts.len();
        let m = self.room(mesh, n + 1, n)?;
        let base = m.positions.len() as u32;
        m.positions.push(centre.as_vec3());
        m.positions.extend(pts.iter().map(|p| p.as_vec3()));
        m.normals
            .extend(std::iter::repeat_n(normal.as_vec3(), n + 1));
        for i in 0..n as u32 {
            let (p, q) = (base + 1 + i, base + 1 + (i + 1) % n as u32);
            m.triangles
                .push(if flip { [base, q, p] } else { [base, p, q] });
        }
        Ok(())
    }

    /// A fan of `pts` around `centre`, all facing `normal`, or a ring
    /// between `pts` and `inner` when given.
    pub(super) fn flat_round(
        &mut self,
        mesh: u32,
        centre: DVec3,
        normal: DVec3,
        pts: &[DVec3],
        inner: Option<&[DVec3]>,
    ) -> Result<(), String> {
        let n = pts.len();
        let nv = normal.as_vec3();
        match inner {
            None => self.fan(mesh, centre, normal, pts, false)?,
            Some(inner) => {
                let m = self.room(mesh, 2 * n, 2 * n)?;
                let base = m.positions.len() as u32;
                m.positions.extend(pts.iter().map(|p| p.as_vec3()));
                m.positions.extend(inner.iter().map(|p| p.as_vec3()));
                m.normals.extend(std::iter::repeat_n(nv, 2 * n));
                for i in 0..n as u32 {
                    let j = (i + 1) % n as u32;
                    let (o, q) = (base, base + n as u32);
                    m.triangles.push([o + i, q + j, o + j]);
                    m.triangles.push([o + i, q + i, q + j]);
                }
            }
        }
        Ok(())
    }

    pub(super) fn sphere(&mut self, mesh: u32, t: &Turtle, r: f64) -> Result<(), String> {
        let slices = self.cur.sides.unwrap_or(self.sides).max(3) as usize;
        let stacks = slices.div_ceil(2).max(2);
        let (h, l, u) = (t.head, t.left, t.up);
        let c = t.pos;
        let nv = 2 + (stacks - 1) * slices;
        let nt = 2 * slices * (stacks - 1);
        let m = self.room(mesh, nv, nt)?;
        let base = m.positions.len() as u32;
        let mut put = |dir: DVec3| {
            m.positions.push((c + dir * r).as_vec3());
            m.normals.push(dir.as_vec3());
        };
        put(h);
        for k in 1..stacks {
            let (s, co) = (std::f64::consts::PI * k as f64 / stacks as f64).sin_cos();
            for i in 0..slices {
                let (a, b) = (std::f64::consts::TAU * i as f64 / slices as f64).sin_cos();
                put(h * co + (l * a + u * b) * s);
            }
        }
        put(-h);
        let ring = |k: usize, i: usize| base + 1 + (k * slices + i % slices) as u32;
        let last = base + nv as u32 - 1;
        for i in 0..slices {
            m.triangles.push([base, ring(0, i + 1), ring(0, i)]);
            for k in 0..stacks - 2 {
                let (a, b, c2, d) = (
                    ring(k, i),
                    ring(k, i + 1),
                    ring(k + 1, i),
                    ring(k + 1, i + 1),
                );
                m.triangles.push([a, b, d]);
                m.triangles.push([a, d, c2]);
            }
            m.triangles
                .push([last, ring(stacks - 2, i), ring(stacks - 2, i + 1)]);
        }
        Ok(())
    }
}

/// Triangles of the simple polygon `pts` (its points' indices), wound
/// counter-clockwise about `normal`: ear clipping in its plane; a fan from
/// the first point past [`MAX_EAR_CLIPPING`] points or where no ear is
/// left (a polygon that crosses itself).
pub(super) fn triangulate(pts: &[DVec3], normal: DVec3) -> Vec<[u32; 3]> {
    let n = pts.len();
    let mut out = Vec::with_capacity(n.saturating_sub(2));
    let fan = |from: &[u32], out: &mut Vec<[u32; 3]>| {
        for w in from[1..].windows(2) {
            out.push([from[0], w[0], w[1]]);
        }
    };
    let mut idx: Vec<u32> = (0..n as u32).collect();
    if n > MAX_EAR_CLIPPING {
        fan(&idx, &mut out);
        return out;
    }
    let e1 = normal.any_orthonormal_vector();
    let e2 = normal.cross(e1);
    let p2: Vec<[f64; 2]> = pts.iter().map(|p| [p.dot(e1), p.dot(e2)]).collect();
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let inside = |p: [f64; 2], a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0
    };
    while idx.len() > 3 {
        let m = idx.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (
                p2[idx[(i + m - 1) % m] as usize],
                p2[idx[i] as usize],
                p2[idx[(i + 1) % m] as usize],
            );
            cross(a, b, c) > 0.0
                && (0..m)
                    .filter(|&j| j != i && j != (i + m - 1) % m && j != (i + 1) % m)
                    .all(|j| {
                        let p = p2[idx[j] as usize];
                        p == a || p == b || p == c || !inside(p, a, b, c)
                    })
        });
        match ear {
            Some(i) => {
                out.push([idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]]);
                idx.remove(i);
            }
            None => {
                fan(&idx, &mut out);
                return out;
            }
        }
    }
    out.push([idx[0], idx[1], idx[2]]);
    out
}
