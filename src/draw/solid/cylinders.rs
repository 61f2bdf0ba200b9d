//! Generalized cylinders: the current contour swept in the turtle's
//! frames, its sections, segments and caps.

use glam::DVec3;

use super::super::Turtle;
use super::sections::SectionKey;
use super::Builder;
use crate::model::Contour;

/// The last section of a generalized cylinder.
#[derive(Clone, Copy, Debug)]
pub(super) struct GcPoint {
    /// The mesh its ring is in and its first vertex; `None` after
    /// `PointGC`, which moves it without making a ring.
    pub(super) ring: Option<(u32, u32)>,
    pos: DVec3,
    head: DVec3,
    left: DVec3,
    up: DVec3,
    scale: (f64, f64),
    pub(super) key: SectionKey,
}

impl<'m> Builder<'m> {
    /// The section key of the current contour with `samples` samples.
    pub(super) fn key(&self, samples: u32) -> SectionKey {
        SectionKey {
            contour: self.cur.contour,
            contour2: self.cur.contour2,
            blend: self.cur.blend,
            samples,
        }
    }

    /// Contour `id` of the model (checked), 0 lpfg's circle.
    pub(super) fn contour(&self, id: usize) -> std::borrow::Cow<'_, Contour> {
        match self.model.contours.get(id) {
            Some(c) => std::borrow::Cow::Borrowed(c),
            // A model made in code may lack the circle that
            // `Model::read` puts first.
            None => std::borrow::Cow::Owned(Contour::default_circle()),
        }
    }

    /// The samples of a generalized cylinder starting now.
    pub(super) fn gc_samples(&self) -> u32 {
        if let Some(s) = self.cur.sides {
            return s + 1;
        }
        let c = self.contour(self.cur.contour);
        if c.samples_given {
            c.samples as u32
        } else {
            self.sides + 1
        }
    }

    /// A generalized cylinder's section at the turtle: its ring in `mesh`.
    pub(super) fn gc_ring(&mut self, mesh: u32, g: &GcPoint) -> Result<u32, String> {
        let sec = self.section(g.key);
        self.ring(mesh, false, sec, g.pos, g.left, g.up, g.scale)
    }

    pub(super) fn gc_point(&self, t: &Turtle, key: SectionKey) -> GcPoint {
        GcPoint {
            ring: None,
            pos: t.pos,
            head: t.head,
            left: t.left,
            up: t.up,
            scale: self.cur.scale,
            key,
        }
    }

    /// A generalized cylinder's segment to the turtle.
    pub(super) fn gc_segment(&mut self, t: &Turtle, last: GcPoint) -> Result<(), String> {
        let mesh = self.mesh(t.pen.color);
        let key = self.key(last.key.samples);
        let mut next = self.gc_point(t, key);
        let a = match last.ring {
            Some((m, r)) if m == mesh => r,
            // After `PointGC` or a change of colour, the last section's
            // ring in this mesh.
            _ => self.gc_ring(mesh, &last)?,
        };
        let b = self.gc_ring(mesh, &next)?;
        let sec = self.section(key);
        let (n, closed, cw) = {
            let s = &self.sections[sec].1;
            (s.points.len() as u32, s.closed, s.clockwise)
        };
        self.strip(mesh, a, b, n, closed, cw)?;
        next.ring = Some((mesh, b));
        self.cur.gc = Some(next);
        Ok(())
    }

    pub(super) fn gc_cap(&mut self, t: &Turtle, g: &GcPoint, start: bool) -> Result<(), String> {
        if !self.capped {
            return Ok(());
        }
        let mesh = self.mesh(t.pen.color);
        let sec = self.section(g.key);
        self.cap(
            mesh,
            false,
            sec,
            g.pos,
            (g.left, g.up, g.head),
            g.scale,
            start,
        )
    }
}
