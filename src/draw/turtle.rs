//! The turtle: its position, frame (heading, left, up) and pen, the
//! coordinate system of the modules that take points, and how it turns.

use glam::DVec3;

use super::{tropism, Pen};

/// The turtle axis a rotation turns about.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum DVec3Axis {
    Up,
    Left,
    Head,
}

#[derive(Clone, Debug)]
pub(crate) struct Turtle {
    pub(super) pos: DVec3,
    pub(super) head: DVec3,
    pub(super) left: DVec3,
    pub(super) up: DVec3,
    pub(super) pen: Pen,
    /// The elasticity of each of the view file's tropisms, as this turtle
    /// (and the branch it belongs to) set them. Shared with the turtles of
    /// the stack until it changes (a branch copies the turtle).
    pub(super) elasticity: std::rc::Rc<Vec<f64>>,
    /// The simple tropism (`stropism:`), which `Elasticity` and
    /// `SetTropismDirection3f` change for this turtle.
    pub(super) simple: tropism::SimpleTropism,
    /// The coordinate system of `MoveTo`, `LineTo` and their kin, which
    /// `SetCoordinateSystem` sets (pushed and popped with the turtle;
    /// shared, as `elasticity` is).
    pub(super) frame: std::rc::Rc<Cartesian>,
}

/// lpfg's coordinate system for the modules that take points: a point
/// `(x, y, z)` is `origin + scale * (x * -x_axis + y * y_axis + z * z_axis)`.
/// By default `x_axis` is the turtle's first left vector, so that the
/// transformation is the identity.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cartesian {
    pub(super) origin: DVec3,
    pub(super) x_axis: DVec3,
    pub(super) y_axis: DVec3,
    pub(super) z_axis: DVec3,
    pub(super) scale: f64,
}

impl Cartesian {
    /// Where the point `p` of the coordinate system lies. As in lpfg, the
    /// relative modules (`MoveRel`, `LineRel`) add the origin too.
    pub(super) fn place(&self, p: DVec3) -> DVec3 {
        let p = p * self.scale;
        self.origin - self.x_axis * p.x + self.y_axis * p.y + self.z_axis * p.z
    }
}

/// Lengths below this make lpfg ignore a module (manual 5.1, 5.2).
pub(super) const EPSILON: f64 = 1e-5;

impl Turtle {
    pub(super) fn new(elasticity: Vec<f64>, simple: tropism::SimpleTropism) -> Turtle {
        Turtle {
            elasticity: std::rc::Rc::new(elasticity),
            simple,
            pos: DVec3::ZERO,
            head: DVec3::Y,
            left: DVec3::NEG_X,
            up: DVec3::Z,
            pen: Pen {
                color: 1,
                width: 1.0,
            },
            frame: std::rc::Rc::new(Cartesian {
                origin: DVec3::ZERO,
                x_axis: DVec3::NEG_X,
                y_axis: DVec3::Y,
                z_axis: DVec3::Z,
                scale: 1.0,
            }),
        }
    }

    /// `SetHead(h, u)` (manual 5.2): heading `h` and up `u`, normalised, in
    /// the coordinate system; left is `u x h` and up becomes `h x left`.
    /// Ignored when either is shorter than epsilon or they are parallel.
    pub(super) fn set_head(&mut self, h: DVec3, u: DVec3) {
        if h.length() < EPSILON || u.length() < EPSILON {
            return;
        }
        let linear =
            |v: DVec3| -self.frame.x_axis * v.x + self.frame.y_axis * v.y + self.frame.z_axis * v.z;
        let h = linear(h.normalize());
        let u = linear(u.normalize());
        let left = u.cross(h);
        if left.length() < EPSILON {
            return;
        }
        self.head = h;
        self.left = left;
        self.up = h.cross(left);
    }

    /// `SetHead3f(h)`: the frame turned by the smallest rotation that takes
    /// the heading to `h` (parallel transport); a reversal turns it about
    /// up by 180 degrees.
    pub(super) fn set_heading(&mut self, h: DVec3) {
        if h.length() < EPSILON {
            return;
        }
        let linear = -self.frame.x_axis * h.x + self.frame.y_axis * h.y + self.frame.z_axis * h.z;
        let (old, new) = (self.head.normalize(), linear.normalize());
        let cos = old.dot(new);
        if cos.abs() < 1.0 - EPSILON {
            let q = glam::DQuat::from_axis_angle(old.cross(new).normalize(), cos.acos());
            self.head = q * self.head;
            self.left = q * self.left;
            self.up = q * self.up;
        } else if cos < 0.0 {
            self.turn(DVec3Axis::Up, 180.0);
        }
    }

    /// `RollToVert()`: roll about the heading so that left is horizontal
    /// (`left = Y x H`, normalised; `-X` when the heading is vertical) and
    /// up is `H x left`.
    pub(super) fn roll_to_vert(&mut self) {
        let left = DVec3::Y.cross(self.head);
        self.left = if left.length() < EPSILON {
            DVec3::NEG_X
        } else {
            left.normalize()
        };
        self.up = self.head.cross(self.left);
    }

    /// `RotateXYZ`/`RotateHLU`: the frame turned by `deg` degrees (right
    /// hand) about `axis`, given in global or in turtle (H, L, U)
    /// coordinates. Ignored for an axis shorter than epsilon.
    pub(super) fn rotate(&mut self, axis: DVec3, deg: f64, global: bool) {
        if axis.length() < EPSILON {
            return;
        }
        let axis = match global {
            true => axis,
            false => self.head * axis.x + self.left * axis.y + self.up * axis.z,
        };
        let q = glam::DQuat::from_axis_angle(axis.normalize(), deg.to_radians());
        self.head = q * self.head;
        self.left = q * self.left;
        self.up = q * self.up;
    }

    /// Rotates by `deg` degrees about one of the turtle's own axes.
    fn turn(&mut self, axis: DVec3Axis, deg: f64) {
        let (s, c) = deg.to_radians().sin_cos();
        (self.head, self.left, self.up) = turned(axis, s, c, (self.head, self.left, self.up));
    }
}

/// The frame `(head, left, up)` turned about one of its own axes by the
/// angle whose sine and cosine are `s`, `c`.
#[inline(always)]
pub(super) fn turned(
    axis: DVec3Axis,
    s: f64,
    c: f64,
    (head, left, up): (DVec3, DVec3, DVec3),
) -> (DVec3, DVec3, DVec3) {
    let rot = |a: DVec3, b: DVec3| (a * c + b * s, b * c - a * s);
    match axis {
        // Left: heading turns towards the left vector.
        DVec3Axis::Up => {
            let (h, l) = rot(head, left);
            (h, l, up)
        }
        // Up: heading turns towards the up vector.
        DVec3Axis::Left => {
            let (h, u) = rot(head, up);
            (h, left, u)
        }
        // RollR: left turns towards up.
        DVec3Axis::Head => {
            let (l, u) = rot(left, up);
            (head, l, u)
        }
    }
}
