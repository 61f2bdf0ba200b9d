//! The 3D geometry as the walk's sink: what each module makes.

use glam::{DVec3, Vec3};

use super::super::{Round, Shaping, Sink, Turtle};
use super::shapes::triangulate;
use super::tube_log::Op;
use super::{fits, Builder, TINY};
use crate::model::view::{LineStyle, MAX_CONTOUR_SIDES, MIN_CONTOUR_SIDES};

impl Sink for Builder<'_> {
    fn line(&mut self, t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String> {
        if let Some(log) = &mut self.log {
            log.lo = log.lo.min(a).min(b);
            log.hi = log.hi.max(a).max(b);
        }
        match self.style {
            LineStyle::Pixel => match self.pixel_tubes {
                Some(k) => {
                    let scale = self.cur.scale;
                    self.cur.scale = (scale.0 * k, scale.1 * k);
                    self.in_line = true;
                    let made = self.tube(t, a, b);
                    self.in_line = false;
                    self.cur.scale = scale;
                    made
                }
                None => Ok(()),
            },
            LineStyle::Cylinder => match self.cur.gc {
                Some(g) => self.gc_segment(t, g),
                None => self.tube(t, a, b),
            },
            LineStyle::Polygon => {
                // A band of the line's width facing +z, lpfg's default
                // viewer; none for a line along the view.
                let d = b - a;
                let side = d.cross(DVec3::Z);
                if side.length() < TINY * (1.0 + d.length()) {
                    return Ok(());
                }
                let side = side.normalize() * (0.5 * t.pen.width.abs());
                if !fits(a, side.length()) || !fits(b, side.length()) {
                    return Err("draws a band that reaches an infinite coordinate".into());
                }
                let mesh = self.mesh(t.pen.color);
                let m = self.room(mesh, 4, 2)?;
                let base = m.positions.len() as u32;
                for p in [a - side, a + side, b + side, b - side] {
                    m.positions.push(p.as_vec3());
                    m.normals.push(Vec3::Z);
                }
                m.triangles.push([base, base + 1, base + 2]);
                m.triangles.push([base, base + 2, base + 3]);
                Ok(())
            }
        }
    }

    fn round(&mut self, t: &Turtle, kind: Round, r: f64) -> Result<(), String> {
        let w = t.pen.width.abs();
        let r = if kind.is_dot() { 0.5 * t.pen.width } else { r };
        // lpfg draws no circle or sphere of a radius that is not positive.
        if r <= 0.0 {
            return Ok(());
        }
        if !fits(t.pos, r + w) {
            return Err("draws a circle that reaches an infinite coordinate".into());
        }
        let mesh = self.mesh(t.pen.color);
        if matches!(kind, Round::Sphere | Round::Sphere0) {
            return self.sphere(mesh, t, r);
        }
        let front = matches!(
            kind,
            Round::CircleFront | Round::CircleFront0 | Round::CircleFrontB
        );
        // The disc's plane: HL (normal up) or the screen's (normal +z).
        let (x, y, normal) = if front {
            (DVec3::X, DVec3::Y, DVec3::Z)
        } else {
            (t.left, t.head, t.up)
        };
        let n = self.cur.sides.unwrap_or(self.sides).max(3) as usize;
        let at = |radius: f64| -> Vec<DVec3> {
            (0..n)
                .map(|i| {
                    let (s, c) = (std::f64::consts::TAU * i as f64 / n as f64).sin_cos();
                    t.pos + (x * c + y * s) * radius
                })
                .collect()
        };
        if matches!(kind, Round::CircleB | Round::CircleFrontB) {
            let outer = at(r + 0.5 * w);
            let inner = at((r - 0.5 * w).max(0.0));
            self.flat_round(mesh, t.pos, normal, &outer, Some(&inner))
        } else {
            self.flat_round(mesh, t.pos, normal, &at(r), None)
        }
    }

    fn polygon(&mut self, t: &Turtle, points: Vec<DVec3>) -> Result<(), String> {
        // Newell's normal: the polygon's plane, its points counter-clockwise
        // about it.
        let n = points.len();
        let mut normal = DVec3::ZERO;
        for i in 0..n {
            let (p, q) = (points[i], points[(i + 1) % n]);
            normal += DVec3::new(
                (p.y - q.y) * (p.z + q.z),
                (p.z - q.z) * (p.x + q.x),
                (p.x - q.x) * (p.y + q.y),
            );
        }
        if !normal.is_finite() || normal.length() <= TINY {
            // No plane: a polygon without area has nothing to fill.
            return Ok(());
        }
        let normal = normal.normalize();
        if points.iter().any(|p| !fits(*p, 0.0)) {
            return Err("draws a polygon that reaches an infinite coordinate".into());
        }
        let tris = triangulate(&points, normal);
        let mesh = self.mesh(t.pen.color);
        let m = self.room(mesh, n, tris.len())?;
        let base = m.positions.len() as u32;
        m.positions.extend(points.iter().map(|p| p.as_vec3()));
        m.normals.extend(std::iter::repeat_n(normal.as_vec3(), n));
        m.triangles.extend(tris.iter().map(|t| t.map(|i| base + i)));
        Ok(())
    }

    fn surface(
        &mut self,
        t: &Turtle,
        s: &crate::model::Surface,
        scale: DVec3,
    ) -> Result<(), String> {
        // lpfg's s (`sdiv`, the U precision) runs down the rows of control
        // points, t (`tdiv`, V) along a row: its OBJ output of the test
        // surface has them so.
        let def = crate::model::surface::DEFAULT_DIVISIONS;
        let (ds, dt) = s.divisions.unwrap_or((def, def));
        let nv = self.cur.precision.0.unwrap_or(ds).max(1) as usize;
        let nu = self.cur.precision.1.unwrap_or(dt).max(1) as usize;
        let place = super::super::placement(s, t, scale);
        // Tangents map linearly: the placement less its translation.
        let origin = place.point([0.0; 3]);
        let mesh = self.mesh(t.pen.color);
        let per = (nu + 1) * (nv + 1);
        let m = self.room(mesh, per * s.patches.len(), 2 * nu * nv * s.patches.len())?;
        for patch in &s.patches {
            let base = m.positions.len() as u32;
            for j in 0..=nv {
                for i in 0..=nu {
                    let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
                    let (p, _, _) = patch.point_and_tangents(u, v);
                    // Derivatives just inside the patch, where a corner
                    // collapsed to a point still has a plane.
                    let e = 1e-3;
                    let (_, pu, pv) =
                        patch.point_and_tangents(u.clamp(e, 1.0 - e), v.clamp(e, 1.0 - e));
                    let tu = place.point(pu) - origin;
                    let tv = place.point(pv) - origin;
                    let q = place.point(p);
                    if !fits(q, 0.0) {
                        return Err("places a surface at an infinite coordinate".into());
                    }
                    m.positions.push(q.as_vec3());
                    m.normals.push(tu.cross(tv).normalize_or(t.up).as_vec3());
                }
            }
            let row = nu as u32 + 1;
            for j in 0..nv as u32 {
                for i in 0..nu as u32 {
                    let a = base + j * row + i;
                    let (b, c, d) = (a + 1, a + row + 1, a + row);
                    m.triangles.push([a, b, c]);
                    m.triangles.push([a, c, d]);
                }
            }
        }
        Ok(())
    }

    fn push(&mut self) {
        if let Some(log) = &mut self.log {
            log.ops.push(Op::Push);
        }
        // The parent's tube waits on the stack for the parent; the branch
        // starts its own. (One copy of the branch state: it is large.)
        self.stack.push(self.cur);
        self.cur.tube = None;
        self.cur.gc_branch = self.cur.gc.is_some();
    }

    fn pop(&mut self) -> Result<(), String> {
        self.end_tube()?;
        if let Some(log) = &mut self.log {
            log.ops.push(Op::Pop);
        }
        if let Some(b) = self.stack.pop() {
            self.cur = b;
        }
        Ok(())
    }

    fn shape(&mut self, t: &Turtle, cmd: Option<Shaping>, d: &[f64]) -> Result<(), String> {
        let arg = |k: usize| d.get(k).copied().unwrap_or(0.0);
        let contours = self.model.contours.len().max(1);
        let contour = |v: f64| -> Result<usize, String> {
            if v >= 0.0 && (v as usize) < contours {
                Ok(v as usize)
            } else {
                Err(format!(
                    "names contour {v}, but the model has contours 0 to {} (0 is lpfg's circle; `.con` and `.cset` files add the others)",
                    contours - 1
                ))
            }
        };
        let Some(cmd) = cmd else {
            // SetWidth: the contour's scale too, as in lpfg.
            let w = t.pen.width;
            self.cur.scale = (w, w);
            return Ok(());
        };
        let cylinder = self.style == LineStyle::Cylinder;
        match cmd {
            Shaping::StartGC if cylinder => {
                if self.cur.gc_branch {
                    self.cur.gc = None;
                    self.cur.gc_branch = false;
                }
                if self.cur.gc.is_none() {
                    self.end_tube()?;
                    let key = self.key(self.gc_samples());
                    let mut g = self.gc_point(t, key);
                    let mesh = self.mesh(t.pen.color);
                    g.ring = Some((mesh, self.gc_ring(mesh, &g)?));
                    self.gc_cap(t, &g, true)?;
                    self.cur.gc = Some(g);
                }
            }
            Shaping::PointGC => {
                if let Some(g) = self.cur.gc {
                    let mut p = self.gc_point(t, self.key(g.key.samples));
                    p.ring = None;
                    self.cur.gc = Some(p);
                }
            }
            Shaping::EndGC => {
                if let Some(g) = self.cur.gc.take() {
                    self.gc_cap(t, &g, false)?;
                }
            }
            Shaping::StartGC => {}
            Shaping::CurrentContour => {
                self.cur.contour = contour(arg(0))?;
                self.cur.blend = 0.0;
            }
            Shaping::BlendedContour => {
                self.cur.contour = contour(arg(0))?;
                self.cur.contour2 = contour(arg(1))?;
                self.cur.blend = arg(2).clamp(0.0, 1.0) as f32;
            }
            Shaping::ScaleContour => self.cur.scale = (arg(0), arg(1)),
            Shaping::ContourSides => {
                // No effect inside a generalized cylinder (manual 5.8).
                if self.cur.gc.is_none() {
                    let n = arg(0).clamp(MIN_CONTOUR_SIDES as f64, MAX_CONTOUR_SIDES as f64);
                    self.cur.sides = Some(n as u32);
                }
            }
            Shaping::SetUPrecision | Shaping::SetVPrecision => {
                let p = arg(0);
                // Zero goes back to the surface's own (manual 5.7).
                let v = (p >= 1.0)
                    .then(|| p.min(crate::model::view::MAX_SURFACE_DIVISIONS as f64) as u32);
                if cmd == Shaping::SetUPrecision {
                    self.cur.precision.0 = v;
                } else {
                    self.cur.precision.1 = v;
                }
            }
        }
        Ok(())
    }
}
