//! A model's Bézier surface drawn by the turtle: where its points lie,
//! and its patches' outlines as filled polygons.

use glam::DVec3;

use super::{Event, Turtle};

/// Where a surface's points go: the surface's contact point at the
/// turtle, its heading and up vectors on the turtle's, scaled by `scale` ×
/// the view file's scale / `SIZE:`.
pub(crate) struct Placement {
    pos: DVec3,
    /// The turtle's heading, left and up, each times its scale.
    axes: [DVec3; 3],
    /// The surface's heading, left and up and its contact point.
    h: DVec3,
    l: DVec3,
    u: DVec3,
    contact: DVec3,
}

impl Placement {
    /// Where the surface's point `p` lies.
    #[inline]
    pub(crate) fn point(&self, p: [f64; 3]) -> DVec3 {
        let q = DVec3::from_array(p) - self.contact;
        self.pos
            + self.axes[0] * q.dot(self.h)
            + self.axes[1] * q.dot(self.l)
            + self.axes[2] * q.dot(self.u)
    }
}

/// The placement of surface `s` drawn by turtle `t` at `scale`.
pub(crate) fn placement(s: &crate::model::Surface, t: &Turtle, scale: DVec3) -> Placement {
    let v = |a: [f64; 3]| DVec3::from_array(a);
    let (h, u) = (
        v(s.heading).normalize_or_zero(),
        v(s.up).normalize_or_zero(),
    );
    let k = scale * (s.scale / s.size);
    Placement {
        pos: t.pos,
        axes: [t.head * k.y, t.left * k.x, t.up * k.z],
        h,
        l: u.cross(h),
        u,
        contact: v(s.contact),
    }
}

/// Each patch of surface `s` as a filled polygon, its outline, placed by
/// [`placement`].
pub(super) fn surface_events(
    s: &crate::model::Surface,
    t: &Turtle,
    scale: DVec3,
    out: &mut Vec<Event>,
) {
    const STEPS: usize = 8;
    let place = placement(s, t, scale);
    for patch in &s.patches {
        // Around the patch: along the first row, down the last column,
        // back along the last row, up the first column.
        let f = |i: usize| i as f64 / STEPS as f64;
        let mut ring = Vec::with_capacity(4 * STEPS);
        ring.extend((0..STEPS).map(|i| patch.point(f(i), 0.0)));
        ring.extend((0..STEPS).map(|i| patch.point(1.0, f(i))));
        ring.extend((0..STEPS).map(|i| patch.point(1.0 - f(i), 1.0)));
        ring.extend((0..STEPS).map(|i| patch.point(0.0, 1.0 - f(i))));
        out.push(Event::Polygon {
            points: ring.into_iter().map(|p| place.point(p)).collect(),
            color: t.pen.color,
        });
    }
}
