//! Tubes along the turtle's lines: a ring shared at each joint, axes
//! carried by parallel transport, ends and caps, and a tube thinner than a
//! pixel made as its axis, a line.

use glam::{DQuat, DVec3};

use super::super::Turtle;
use super::tube_log::{Op, Seg};
use super::{fits, too_short, Builder, THIN};
use crate::model::view::MIN_CONTOUR_SIDES;
use crate::scene3::Line;

/// A tube segment whose first ring is made and whose last ring waits for
/// the next segment (to be shared at the joint) or for the tube's end.
#[derive(Clone, Copy, Debug)]
pub(super) struct Pending {
    mesh: u32,
    /// The first vertex of its first ring.
    ring: u32,
    end: DVec3,
    /// Unit direction.
    dir: DVec3,
    /// The ring axes carried along the tube, perpendicular to `dir`.
    left: DVec3,
    up: DVec3,
    scale: (f64, f64),
    sides: u32,
}

/// Left and up axes perpendicular to the unit `dir`, as close to the
/// turtle's left as can be, with up = dir × left.
fn axes(dir: DVec3, left: DVec3, up: DVec3) -> (DVec3, DVec3) {
    let l = left - dir * left.dot(dir);
    let l = if l.length() > 1e-6 {
        l.normalize()
    } else {
        // The heading is along the turtle's left: take up's turn.
        let u = up - dir * up.dot(dir);
        if u.length() > 1e-6 {
            u.normalize().cross(dir)
        } else {
            dir.any_orthonormal_vector()
        }
    };
    (l, dir.cross(l))
}

impl<'m> Builder<'m> {
    /// Ends the pending tube of the current branch: its last ring,
    /// perpendicular to its direction, and the cap.
    pub(super) fn end_tube(&mut self) -> Result<(), String> {
        if let Some(log) = &mut self.log {
            log.ops.push(Op::End);
            return Ok(());
        }
        let Some(p) = self.cur.tube.take() else {
            return Ok(());
        };
        let sec = self.circle(p.sides);
        let b = self.ring(p.mesh, true, sec, p.end, p.left, p.up, p.scale)?;
        self.strip(p.mesh, p.ring, b, p.sides, true, true)?;
        if self.capped {
            self.cap(
                p.mesh,
                true,
                sec,
                p.end,
                (p.left, p.up, p.dir),
                p.scale,
                false,
            )?;
        }
        Ok(())
    }

    /// A tube segment from `a` to `b`.
    pub(super) fn tube(&mut self, t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String> {
        let seg = Seg {
            a,
            b,
            left: t.left,
            up: t.up,
            color: t.pen.color,
            scale: self.cur.scale,
            sides: self.cur.sides,
            lines: 0,
        };
        if self.log.is_none() {
            return self.tube_at(&seg);
        }
        self.log_tube(seg)
    }

    /// A tube segment as `seg` gives it.
    pub(super) fn tube_at(&mut self, seg: &Seg) -> Result<(), String> {
        let (a, b) = (seg.a, seg.b);
        if too_short(a, b) {
            return Ok(());
        }
        let d = b - a;
        let dir = d / d.length();
        let scale = seg.scale;
        let mut sides = seg.sides.unwrap_or(self.sides);
        if let Some(px) = self.picture_pixel {
            // The circumference in pixels over 1.5 pixels a side.
            let across = scale.0.abs().max(scale.1.abs()) / px;
            if across < THIN {
                return self.thin(seg.color, a, b, scale.0.abs().max(scale.1.abs()));
            }
            let need = (std::f64::consts::PI * across / 1.5).ceil();
            if need.is_finite() && need < sides as f64 {
                sides = (need as u32).max(MIN_CONTOUR_SIDES);
            }
        }
        let mesh = self.mesh(seg.color);
        let sec = self.circle(sides);
        let joint = self
            .cur
            .tube
            .filter(|p| p.end == a && p.dir.dot(dir) >= 0.0);
        let (ring, left, up) = match joint {
            Some(p) => {
                self.cur.tube = None;
                // The joint's ring, perpendicular to the bisector, its axes
                // carried halfway.
                let n = (p.dir + dir).normalize();
                let half = DQuat::from_rotation_arc(p.dir, n);
                let (jl, ju) = (half * p.left, half * p.up);
                let old_sec = self.circle(p.sides);
                let r = self.ring(p.mesh, true, old_sec, a, jl, ju, p.scale)?;
                self.strip(p.mesh, p.ring, r, p.sides, true, true)?;
                let same = p.mesh == mesh && p.scale == scale && p.sides == sides;
                let start = if same {
                    r
                } else {
                    self.ring(mesh, true, sec, a, jl, ju, scale)?
                };
                let l = DQuat::from_rotation_arc(p.dir, dir) * p.left;
                // Keep the axes unit and perpendicular over long paths.
                let l = (l - dir * l.dot(dir)).normalize_or(l);
                (start, l, dir.cross(l))
            }
            None => {
                self.end_tube()?;
                let (l, u) = axes(dir, seg.left, seg.up);
                let r = self.ring(mesh, true, sec, a, l, u, scale)?;
                if self.capped {
                    self.cap(mesh, true, sec, a, (l, u, dir), scale, true)?;
                }
                (r, l, u)
            }
        };
        self.cur.tube = Some(Pending {
            mesh,
            ring,
            end: b,
            dir,
            left,
            up,
            scale,
            sides,
        });
        Ok(())
    }

    /// A tube thinner than a pixel in a picture: its axis, as a line of
    /// the mesh (see [`TriMesh::lines`]). A tube it follows ends here.
    ///
    /// [`TriMesh::lines`]: crate::scene3::TriMesh::lines
    fn thin(&mut self, color: i64, a: DVec3, b: DVec3, width: f64) -> Result<(), String> {
        self.end_tube()?;
        if !fits(a, 0.0) || !fits(b, 0.0) {
            return Err("makes a cylinder that reaches an infinite coordinate".into());
        }
        let mesh = self.mesh(color);
        let line = Line {
            a: a.as_vec3(),
            b: b.as_vec3(),
            width: width as f32,
        };
        // A line counts as a triangle against the limit.
        let replaying = self.replaying;
        let m = self.room(mesh, 0, 1)?;
        match replaying {
            Some(at) => self.late.push((mesh, at, line)),
            None => m.lines.push(line),
        }
        Ok(())
    }
}
