//! Interpretation of a word as drawing: the turtle walks the modules and
//! emits renderer-neutral [`Event`]s in 3D. PNG and SVG both draw these
//! events, so the two always agree.
//!
//! **Layer.** It uses `colour`, `lang`, `model`, `rewrite`, `scene3`,
//! `syntax`; it is used by `command`, `curve`, `error`, `load`, `render`,
//! `reverse`. Nothing here names a layer above (see ARCHITECTURE.md,
//! "Layers").

pub(crate) mod coverage;
mod queries;
pub mod solid;
pub mod tropism;

pub use queries::QueryTurtle;

use glam::DVec3;

use crate::lang::value::StructDef;
use crate::lang::{Alphabet, Value};
use crate::rewrite::word::Slices;
use crate::rewrite::Word;

/// The style of a stroke: colour index and width in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pen {
    pub color: i64,
    pub width: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// Connected straight segments drawn with one pen: at least two
    /// points. The turtle extends the last path while its lines follow on
    /// with the same pen, so a curve of a million segments is one path.
    Path { points: Vec<DVec3>, pen: Pen },
    /// A filled disc of world radius `r` (`Circle`, `Sphere`).
    Disc { c: DVec3, r: f64, color: i64 },
    /// A filled disc whose diameter is the pen width in pixels (`Circle0`).
    Dot { c: DVec3, pen: Pen },
    /// A circle outline of world radius `r`, stroked with the pen (`CircleB`).
    Ring { c: DVec3, r: f64, pen: Pen },
    /// A filled polygon (`SP() ... PP() ... EP()`).
    Polygon { points: Vec<DVec3>, color: i64 },
}

impl Event {
    /// The straight segments of a path, in order; none for other events.
    pub fn segments(&self) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
        let points: &[DVec3] = match self {
            Event::Path { points, .. } => points,
            _ => &[],
        };
        points.windows(2).map(|w| (w[0], w[1]))
    }
}

/// What a predefined module does to the turtle.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Cmd {
    None,
    Forward {
        draw: bool,
        record: bool,
    },
    MoveTo,
    MoveRel,
    LineTo,
    LineRel,
    Line,
    Turn(DVec3Axis, f64),
    TurnAround,
    SetColor,
    IncColor,
    DecColor,
    SetWidth,
    Push,
    Pop,
    /// Circles, discs and spheres (manual 5.5).
    Round(Round),
    StartPolygon,
    PolygonPoint,
    EndPolygon,
    /// `Surface(id, s)`, `Surface3(id, sx, sy, sz)`: a model's Bézier
    /// surface.
    Surface,
    Query(u8),
    SetHead,
    SetHead3,
    RollToVert,
    /// `RotateXYZ` (`true`: about a global axis) or `RotateHLU`.
    Rotate(bool),
    SetCoordinateSystem,
    Rhombus,
    Triangle,
    /// `SetElasticity(id, e)`, `IncElasticity(id)` (1), `DecElasticity(id)`
    /// (-1).
    SetElasticity(i8),
    /// `Elasticity(e)`: the simple tropism's.
    Elasticity,
    SetTropismDirection,
    /// Modules that only shape 3D geometry (generalized cylinders, their
    /// contours, the precision of surfaces): the walk leaves them to the
    /// sink.
    Shape(Shaping),
}

/// The circles and spheres of manual 5.5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Round {
    /// `Circle(r)`: a disc in the HL plane.
    Circle,
    /// `CircleFront(r)`: a disc in the screen plane.
    CircleFront,
    /// `Sphere(r)`.
    Sphere,
    /// `Circle0()`, `CircleFront0()`, `Sphere0()`: their diameter the line
    /// width.
    Circle0,
    CircleFront0,
    Sphere0,
    /// `CircleB(r)`, `CircleFrontB(r)`: outlines of the line width.
    CircleB,
    CircleFrontB,
}

impl Round {
    /// A circle of the pen's width (`Circle0` and its kin).
    fn is_dot(self) -> bool {
        matches!(self, Round::Circle0 | Round::CircleFront0 | Round::Sphere0)
    }
}

/// The modules of [`Cmd::Shape`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Shaping {
    StartGC,
    PointGC,
    EndGC,
    CurrentContour,
    BlendedContour,
    ScaleContour,
    ContourSides,
    SetUPrecision,
    SetVPrecision,
}

/// The turtle axis a rotation turns about.
#[derive(Clone, Copy, Debug, PartialEq)]
enum DVec3Axis {
    Up,
    Left,
    Head,
}

#[derive(Clone, Debug)]
pub(crate) struct Turtle {
    pos: DVec3,
    head: DVec3,
    left: DVec3,
    up: DVec3,
    pen: Pen,
    /// The elasticity of each of the view file's tropisms, as this turtle
    /// (and the branch it belongs to) set them. Shared with the turtles of
    /// the stack until it changes (a branch copies the turtle).
    elasticity: std::rc::Rc<Vec<f64>>,
    /// The simple tropism (`stropism:`), which `Elasticity` and
    /// `SetTropismDirection3f` change for this turtle.
    simple: tropism::SimpleTropism,
    /// The coordinate system of `MoveTo`, `LineTo` and their kin, which
    /// `SetCoordinateSystem` sets (pushed and popped with the turtle;
    /// shared, as `elasticity` is).
    frame: std::rc::Rc<Cartesian>,
}

/// lpfg's coordinate system for the modules that take points: a point
/// `(x, y, z)` is `origin + scale * (x * -x_axis + y * y_axis + z * z_axis)`.
/// By default `x_axis` is the turtle's first left vector, so that the
/// transformation is the identity.
#[derive(Clone, Copy, Debug)]
struct Cartesian {
    origin: DVec3,
    x_axis: DVec3,
    y_axis: DVec3,
    z_axis: DVec3,
    scale: f64,
}

impl Cartesian {
    /// Where the point `p` of the coordinate system lies. As in lpfg, the
    /// relative modules (`MoveRel`, `LineRel`) add the origin too.
    fn place(&self, p: DVec3) -> DVec3 {
        let p = p * self.scale;
        self.origin - self.x_axis * p.x + self.y_axis * p.y + self.z_axis * p.z
    }
}

/// Lengths below this make lpfg ignore a module (manual 5.1, 5.2).
const EPSILON: f64 = 1e-5;

impl Turtle {
    fn new(elasticity: Vec<f64>, simple: tropism::SimpleTropism) -> Turtle {
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
    fn set_head(&mut self, h: DVec3, u: DVec3) {
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
    fn set_heading(&mut self, h: DVec3) {
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
    fn roll_to_vert(&mut self) {
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
    fn rotate(&mut self, axis: DVec3, deg: f64, global: bool) {
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
fn turned(
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

/// Settings of interpretation.
#[derive(Clone, Debug)]
pub struct DrawOptions {
    /// The angle of `+ - & ^ / \` and of `Left()` without an argument.
    pub angle: f64,
    /// Length of `F` without an argument.
    pub step: f64,
    /// The model the word came with: its surfaces for `Surface`.
    pub model: std::sync::Arc<crate::model::Model>,
    /// What the view file sets for the turtle.
    pub view: TurtleView,
}

impl Default for DrawOptions {
    fn default() -> Self {
        DrawOptions {
            angle: 90.0,
            step: 1.0,
            model: Default::default(),
            view: TurtleView::default(),
        }
    }
}

/// The view file's settings of the turtle (manual 8.1.3, 8.1.4).
#[derive(Clone, Debug, PartialEq)]
pub struct TurtleView {
    /// `corrected rotation:` (default on). Off, `Up`, `Down`, `RollL` and
    /// `RollR` turn the other way, as lpfg's old versions did.
    pub corrected_rotation: bool,
    /// `tropism:`, `torque:` and `stropism:`.
    pub tropisms: tropism::Tropisms,
}

impl Default for TurtleView {
    fn default() -> Self {
        TurtleView {
            corrected_rotation: true,
            tropisms: tropism::Tropisms::default(),
        }
    }
}

/// A problem with a word that cannot be drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawError {
    pub message: String,
    /// The module at fault (counted from 0), when one is.
    pub module: Option<usize>,
}

impl std::fmt::Display for DrawError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for DrawError {}

fn command(name: &str) -> Cmd {
    use DVec3Axis::*;
    match name {
        "F" => Cmd::Forward {
            draw: true,
            record: true,
        },
        "G" => Cmd::Forward {
            draw: true,
            record: false,
        },
        "f" => Cmd::Forward {
            draw: false,
            record: true,
        },
        "g" => Cmd::Forward {
            draw: false,
            record: false,
        },
        "MoveTo" | "MoveTo2f" | "MoveTo2d" | "MoveTo3f" | "MoveTo3d" => Cmd::MoveTo,
        "MoveRel2f" | "MoveRel2d" | "MoveRel3f" | "MoveRel3d" => Cmd::MoveRel,
        "LineTo" | "LineTo2f" | "LineTo2d" | "LineTo3f" | "LineTo3d" => Cmd::LineTo,
        "LineRel2f" | "LineRel2d" | "LineRel3f" | "LineRel3d" => Cmd::LineRel,
        "Line2f" | "Line2d" | "Line3f" | "Line3d" => Cmd::Line,
        "Left" => Cmd::Turn(Up, 1.0),
        "Right" => Cmd::Turn(Up, -1.0),
        "Up" => Cmd::Turn(Left, 1.0),
        "Down" => Cmd::Turn(Left, -1.0),
        "RollR" => Cmd::Turn(Head, 1.0),
        "RollL" => Cmd::Turn(Head, -1.0),
        "TurnAround" => Cmd::TurnAround,
        "SetColor" => Cmd::SetColor,
        "IncColor" => Cmd::IncColor,
        "DecColor" => Cmd::DecColor,
        "SetWidth" => Cmd::SetWidth,
        "SB" => Cmd::Push,
        "EB" => Cmd::Pop,
        "Circle" => Cmd::Round(Round::Circle),
        "CircleFront" => Cmd::Round(Round::CircleFront),
        "Sphere" => Cmd::Round(Round::Sphere),
        "Circle0" => Cmd::Round(Round::Circle0),
        "CircleFront0" => Cmd::Round(Round::CircleFront0),
        "Sphere0" => Cmd::Round(Round::Sphere0),
        "CircleB" => Cmd::Round(Round::CircleB),
        "CircleFrontB" => Cmd::Round(Round::CircleFrontB),
        "StartGC" => Cmd::Shape(Shaping::StartGC),
        "PointGC" => Cmd::Shape(Shaping::PointGC),
        "EndGC" => Cmd::Shape(Shaping::EndGC),
        "CurrentContour" => Cmd::Shape(Shaping::CurrentContour),
        "BlendedContour" => Cmd::Shape(Shaping::BlendedContour),
        "ScaleContour" => Cmd::Shape(Shaping::ScaleContour),
        "ContourSides" => Cmd::Shape(Shaping::ContourSides),
        "SetUPrecision" => Cmd::Shape(Shaping::SetUPrecision),
        "SetVPrecision" => Cmd::Shape(Shaping::SetVPrecision),
        "SP" => Cmd::StartPolygon,
        "PP" => Cmd::PolygonPoint,
        "EP" => Cmd::EndPolygon,
        "Surface" | "Surface3" => Cmd::Surface,
        "GetPos" => Cmd::Query(0),
        "GetHead" => Cmd::Query(1),
        "GetLeft" => Cmd::Query(2),
        "GetUp" => Cmd::Query(3),
        "SetHead" => Cmd::SetHead,
        "SetHead3f" => Cmd::SetHead3,
        "RollToVert" => Cmd::RollToVert,
        "RotateXYZ" | "Rotate" => Cmd::Rotate(true),
        "RotateHLU" => Cmd::Rotate(false),
        "SetCoordinateSystem" => Cmd::SetCoordinateSystem,
        "Rhombus" => Cmd::Rhombus,
        "Triangle" => Cmd::Triangle,
        "SetElasticity" => Cmd::SetElasticity(0),
        "IncElasticity" => Cmd::SetElasticity(1),
        "DecElasticity" => Cmd::SetElasticity(-1),
        "Elasticity" => Cmd::Elasticity,
        "SetTropismDirection3f" => Cmd::SetTropismDirection,
        // `Cut` is not here: lpfg's turtle ignores it, and derivation
        // steps remove it with the rest of its branch.
        _ => Cmd::None,
    }
}

/// True when the turtle acts on the predefined module `name` (draws, moves,
/// turns, sets the pen, answers a query).
pub fn acts_on(name: &str) -> bool {
    command(name) != Cmd::None
}

pub use crate::rewrite::is_query;

/// The sines and cosines of the last four angles turned by: words turn by
/// a few angles over and over (`+(90) ... -(90)`, or a branching angle
/// between rolls of 120° and 240°), and `sin_cos` is most of a turn's cost.
struct TurnCache {
    /// Each angle's bits, its sine and its cosine.
    slots: [(u64, f64, f64); 4],
    next: usize,
}

impl Default for TurnCache {
    fn default() -> Self {
        // Slots start as a NaN angle, with the sine and cosine a NaN has.
        TurnCache {
            slots: [(f64::NAN.to_bits(), f64::NAN, f64::NAN); 4],
            next: 0,
        }
    }
}

impl TurnCache {
    #[inline]
    fn sin_cos(&mut self, deg: f64) -> (f64, f64) {
        let bits = deg.to_bits();
        for &(b, s, c) in &self.slots {
            if b == bits {
                return (s, c);
            }
        }
        self.miss(deg)
    }

    #[cold]
    fn miss(&mut self, deg: f64) -> (f64, f64) {
        let (s, c) = deg.to_radians().sin_cos();
        self.slots[self.next] = (deg.to_bits(), s, c);
        self.next = (self.next + 1) % self.slots.len();
        (s, c)
    }
}

/// What the turtle's walk hands its drawing to: the 2D events of
/// [`draw`], or the 3D geometry of [`solid::solid`]. The walk moves and
/// turns the turtle; a sink only makes what the turtle draws, from the
/// turtle as it stands. An `Err` is a message about the module at hand.
pub(crate) trait Sink {
    /// Whether [`Sink::line`] reads the turtle's position and frame (it
    /// reads its pen in any case): the walk keeps them in registers and
    /// writes them to the turtle only for sinks that read them.
    const LINE_READS_FRAME: bool = true;
    /// A drawn line from `a` to `b` (`F`, `G`, `LineTo`, ...); the turtle
    /// is already at `b`, turned as it is after the module.
    fn line(&mut self, t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String>;
    /// A circle or sphere of radius `r` (the pen's width for the `0`
    /// kinds) at the turtle.
    fn round(&mut self, t: &Turtle, kind: Round, r: f64) -> Result<(), String>;
    /// A filled polygon of three or more points (`SP ... EP`, `Rhombus`,
    /// `Triangle`), drawn by the turtle `t` where it ends.
    fn polygon(&mut self, t: &Turtle, points: Vec<DVec3>) -> Result<(), String>;
    /// Surface `s` of the model at the turtle, scaled by `scale`.
    fn surface(
        &mut self,
        t: &Turtle,
        s: &crate::model::Surface,
        scale: DVec3,
    ) -> Result<(), String>;
    /// `SB`: the turtle was pushed.
    fn push(&mut self) {}
    /// `EB`: the turtle was popped (only when the stack held one).
    fn pop(&mut self) -> Result<(), String> {
        Ok(())
    }
    /// `SetWidth` (after the pen took it) and the modules of
    /// [`Cmd::Shape`], with the module's parameters as numbers (missing
    /// ones 0).
    fn shape(&mut self, _t: &Turtle, _cmd: Option<Shaping>, _d: &[f64]) -> Result<(), String> {
        Ok(())
    }
}

/// Where the turtle's 2D drawing goes, one event at a time: a list of
/// events ([`draw`]), or the compact drawing that `render::png::word`
/// keeps (its paths' points in one list). [`Events`] decides which lines
/// continue a path.
pub(crate) trait EventSink {
    /// A new path: the segment `a`..`b` drawn with `pen`.
    fn path(&mut self, pen: Pen, a: DVec3, b: DVec3) -> Result<(), String>;
    /// The last event, a path, continued to `b`.
    fn continue_to(&mut self, b: DVec3) -> Result<(), String>;
    /// An event that is not a path.
    fn event(&mut self, e: Event) -> Result<(), String>;
}

/// The 2D drawing as renderer-neutral events: a line continues the last
/// event when that is a path with the same pen that ends where the line
/// starts, and starts a path otherwise.
pub(crate) struct Events<E> {
    out: E,
    /// The pen and the end of the last event, when that is a path.
    last: Open,
}

/// The pen and the end of the last event, which a line continues when it is
/// a path (`open`).
#[derive(Clone, Copy)]
struct Open {
    open: bool,
    pen: Pen,
    end: DVec3,
}

impl<E: EventSink> Events<E> {
    pub(crate) fn new(out: E) -> Self {
        Events {
            out,
            last: Open {
                open: false,
                pen: Pen {
                    color: 0,
                    width: 0.0,
                },
                end: DVec3::ZERO,
            },
        }
    }

    pub(crate) fn into_inner(self) -> E {
        self.out
    }

    fn event(&mut self, e: Event) -> Result<(), String> {
        self.last.open = false;
        self.out.event(e)
    }
}

impl<E: EventSink> Sink for Events<E> {
    const LINE_READS_FRAME: bool = false;

    #[inline(always)]
    fn line(&mut self, t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String> {
        let pen = t.pen;
        let joined = self.last.open & (self.last.pen == pen) & (self.last.end == a);
        self.last = Open {
            open: true,
            pen,
            end: b,
        };
        if joined {
            self.out.continue_to(b)
        } else {
            self.out.path(pen, a, b)
        }
    }

    fn round(&mut self, t: &Turtle, kind: Round, r: f64) -> Result<(), String> {
        let c = t.pos;
        self.event(match kind {
            Round::Circle | Round::CircleFront | Round::Sphere => Event::Disc {
                c,
                r,
                color: t.pen.color,
            },
            Round::Circle0 | Round::CircleFront0 | Round::Sphere0 => Event::Dot { c, pen: t.pen },
            Round::CircleB | Round::CircleFrontB => Event::Ring { c, r, pen: t.pen },
        })
    }

    fn polygon(&mut self, t: &Turtle, points: Vec<DVec3>) -> Result<(), String> {
        self.event(Event::Polygon {
            points,
            color: t.pen.color,
        })
    }

    fn surface(
        &mut self,
        t: &Turtle,
        s: &crate::model::Surface,
        scale: DVec3,
    ) -> Result<(), String> {
        let mut polygons = Vec::new();
        surface_events(s, t, scale, &mut polygons);
        polygons.into_iter().try_for_each(|e| self.event(e))
    }
}

/// The events themselves, in order.
impl EventSink for Vec<Event> {
    fn path(&mut self, pen: Pen, a: DVec3, b: DVec3) -> Result<(), String> {
        self.push(Event::Path {
            points: vec![a, b],
            pen,
        });
        Ok(())
    }

    #[inline]
    fn continue_to(&mut self, b: DVec3) -> Result<(), String> {
        if let Some(Event::Path { points, .. }) = self.last_mut() {
            points.push(b);
        }
        Ok(())
    }

    fn event(&mut self, e: Event) -> Result<(), String> {
        self.push(e);
        Ok(())
    }
}

/// The box of the turtle's lines: their end points' least and greatest
/// coordinates.
struct LineBounds(DVec3, DVec3);

impl Sink for LineBounds {
    const LINE_READS_FRAME: bool = false;

    #[inline]
    fn line(&mut self, _t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String> {
        // The walk draws finite lines only.
        (self.0, self.1) = grown(grown((self.0, self.1), a), b);
        Ok(())
    }

    fn round(&mut self, _t: &Turtle, _kind: Round, _r: f64) -> Result<(), String> {
        Ok(())
    }

    fn polygon(&mut self, _t: &Turtle, _points: Vec<DVec3>) -> Result<(), String> {
        Ok(())
    }

    fn surface(
        &mut self,
        _t: &Turtle,
        _s: &crate::model::Surface,
        _scale: DVec3,
    ) -> Result<(), String> {
        Ok(())
    }
}

/// The box around the turtle's lines in `word` (lines only: discs,
/// polygons and surfaces are left out), `None` when it draws no line: what
/// [`draw`]'s paths span, found by the same walk without keeping them.
pub fn line_bounds(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
) -> Result<Option<(DVec3, DVec3)>, DrawError> {
    let mut b = LineBounds(DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    walk(word, alphabet, structs, opts, None, &mut b)?;
    Ok((b.0.x <= b.1.x).then_some((b.0, b.1)))
}

/// Interprets `word` with the turtle and returns the drawing events.
pub fn draw(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
) -> Result<Vec<Event>, DrawError> {
    draw_with_queries(word, alphabet, structs, opts, None)
}

/// Like [`draw`]; also records, for every query module met, its index in
/// `word` and the vector it asks for (`GetPos`: position,
/// `GetHead`/`GetLeft`/`GetUp`: the frame).
pub fn draw_with_queries(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    queries: Option<&mut Vec<(usize, [f64; 3])>>,
) -> Result<Vec<Event>, DrawError> {
    let mut events = Events::new(Vec::new());
    walk(word, alphabet, structs, opts, queries, &mut events)?;
    Ok(events.into_inner())
}

/// The turtle's walk over `word`, drawing into `sink`.
pub(crate) fn walk<S: Sink>(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    queries: Option<&mut Vec<(usize, [f64; 3])>>,
    sink: &mut S,
) -> Result<(), DrawError> {
    walk_loops(word, alphabet, structs, opts, queries, sink, true)
}

/// [`walk`], on both loops when `fast` (the walk), or on the full loop
/// alone (what the tests compare the walk with).
fn walk_loops<S: Sink>(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    queries: Option<&mut Vec<(usize, [f64; 3])>>,
    sink: &mut S,
    fast: bool,
) -> Result<(), DrawError> {
    let mut walk = Walk::new(alphabet, opts, fast);
    walk.advance(word.slices(), alphabet, structs, queries, sink)
}

/// The turtle's walk over a word that may come in pieces: each
/// [`Walk::advance`] walks on from where the last one stopped to the end
/// of the modules it is given, which begin with those it was given before.
/// Walking a word in any number of advances draws what one walk over it
/// draws, to the bit, and fails at the same module with the same message.
pub(crate) struct Walk<'o> {
    opts: &'o DrawOptions,
    /// Each symbol's command.
    cmds: Vec<Cmd>,
    /// The sense of the turns about left and heading.
    sense: f64,
    /// Whether the fast loop walks the common modules.
    fast: bool,
    /// Whether every slot seen so far is finite, and how many were seen.
    all_finite: bool,
    seen_slots: usize,
    /// The turtle between advances; `None` once an advance failed.
    state: Option<Walking<'o>>,
}

impl<'o> Walk<'o> {
    /// A walk, at the start of a word, on both loops when `fast` or on the
    /// full loop alone.
    pub(crate) fn new(alphabet: &Alphabet, opts: &'o DrawOptions, fast: bool) -> Walk<'o> {
        let cmds: Vec<Cmd> = alphabet
            .kinds
            .iter()
            .map(|k| {
                if k.builtin {
                    command(&k.name)
                } else {
                    Cmd::None
                }
            })
            .collect();
        let tropisms = &opts.view.tropisms;
        let field = tropism::Field::new(&tropisms.list);
        Walk {
            opts,
            cmds,
            // lpfg's old rotations turn Up, Down, RollL and RollR the other way.
            sense: if opts.view.corrected_rotation {
                1.0
            } else {
                -1.0
            },
            fast,
            all_finite: true,
            seen_slots: 0,
            state: Some(Walking {
                t: Turtle::new(field.initial(), tropisms.simple),
                stack: Vec::new(),
                polygons: Vec::new(),
                turns: TurnCache::default(),
                field,
                i: 0,
            }),
        }
    }

    /// How many modules the walk has passed.
    pub(crate) fn walked(&self) -> usize {
        self.state.as_ref().map_or(0, |s| s.i)
    }

    /// Walks on to the end of `word`, whose first [`Walk::walked`] modules
    /// are those walked before. After a failure the walk walks no more.
    pub(crate) fn advance<S: Sink>(
        &mut self,
        word: Slices<'_>,
        alphabet: &Alphabet,
        structs: &[StructDef],
        mut queries: Option<&mut Vec<(usize, [f64; 3])>>,
        sink: &mut S,
    ) -> Result<(), DrawError> {
        let Some(mut state) = self.state.take() else {
            return Ok(());
        };
        // Parameters are checked a module at a time only when some number
        // of the word is not finite (one pass over the slots, most words).
        let slots = word.all_slots();
        self.all_finite &= slots
            .get(self.seen_slots..)
            .unwrap_or_default()
            .iter()
            .fold(true, |ok, x| ok & x.is_finite());
        self.seen_slots = self.seen_slots.max(slots.len());
        let walker = Walker {
            word,
            alphabet,
            structs,
            opts: self.opts,
            cmds: &self.cmds,
            sense: self.sense,
            all_finite: self.all_finite,
            hand_back: self.fast,
        };
        // The fast loop walks the common modules; the full loop takes over at
        // any other, and hands back after a run of common ones.
        while state.i < word.len() {
            if self.fast {
                state = walker.run::<S, false>(state, None, sink)?;
            }
            if state.i < word.len() {
                state = walker.run::<S, true>(state, queries.as_deref_mut(), sink)?;
            }
        }
        self.state = Some(state);
        Ok(())
    }
}

/// What the turtle's walk reads: the word and its commands.
struct Walker<'a> {
    word: Slices<'a>,
    alphabet: &'a Alphabet,
    structs: &'a [StructDef],
    opts: &'a DrawOptions,
    /// Each symbol's command.
    cmds: &'a [Cmd],
    /// The sense of the turns about left and heading.
    sense: f64,
    /// Whether every slot of the word is finite.
    all_finite: bool,
    /// Whether the full loop hands the walk back to the fast one.
    hand_back: bool,
}

/// The turtle's walk between its loops: the turtle and what it keeps, and
/// the module it is at.
struct Walking<'t> {
    t: Turtle,
    stack: Vec<Turtle>,
    polygons: Vec<Vec<DVec3>>,
    turns: TurnCache,
    field: tropism::Field<'t>,
    i: usize,
}

/// The full loop hands the walk back to the fast one after this many common
/// modules in a row.
const COMMON_RUN: usize = 32;

impl Cmd {
    /// The commands of the fast loop: the moves, turns, branches and pens
    /// that most words are made of.
    fn common(self) -> bool {
        matches!(
            self,
            Cmd::None
                | Cmd::Forward { .. }
                | Cmd::Turn(..)
                | Cmd::TurnAround
                | Cmd::SetColor
                | Cmd::IncColor
                | Cmd::DecColor
                | Cmd::SetWidth
                | Cmd::Push
                | Cmd::Pop
        )
    }
}

impl Walker<'_> {
    /// The walk from `state`'s module on. The fast loop (`FULL` false)
    /// knows the common modules only, so that the turtle stays in
    /// registers, and stops at the first other module; the full loop knows
    /// them all, and stops after `COMMON_RUN` common modules in a row. Both
    /// stop at the end of the word.
    fn run<'t, S: Sink, const FULL: bool>(
        &self,
        state: Walking<'t>,
        mut queries: Option<&mut Vec<(usize, [f64; 3])>>,
        sink: &mut S,
    ) -> Result<Walking<'t>, DrawError> {
        let Walker {
            word,
            alphabet,
            structs,
            opts,
            cmds,
            sense,
            all_finite,
            hand_back,
        } = *self;
        let Walking {
            mut t,
            mut stack,
            mut polygons,
            mut turns,
            mut field,
            i: start,
        } = state;
        let mut i = start;
        let mut last_other = start;
        // The turtle's frame in locals, which stay in registers; `t` holds
        // it whenever `t` is read.
        let (mut pos, mut head, mut left, mut up) = (t.pos, t.head, t.left, t.up);
        // Whether the simple tropism bends the heading (set with the
        // turtle).
        let mut bends = t.simple.elasticity != 0.0;
        macro_rules! store {
            () => {
                (t.pos, t.head, t.left, t.up) = (pos, head, left, up)
            };
        }
        // A sink's message about module `i`, located.
        let at = |i: usize, message: String| DrawError {
            message: format!(
                "module {} of the interpreted word, `{}`, {message}",
                i + 1,
                alphabet.name(word.sym(i))
            ),
            module: Some(i),
        };
        let (syms, offsets, slots) = (word.syms(), word.offsets(), word.all_slots());
        // A move that takes the turtle past the largest number is an error
        // before anything is drawn from there.
        macro_rules! moved_to {
            ($to:expr) => {{
                let to: DVec3 = $to;
                if !finite3(to) {
                    return Err(beyond(word, i, alphabet, structs, "moves the turtle to"));
                }
                to
            }};
        }
        let from = start.min(syms.len());
        for (&sym, span) in syms[from..].iter().zip(offsets[from..].windows(2)) {
            let cmd = cmds.get(sym.0 as usize).copied().unwrap_or(Cmd::None);
            if FULL {
                if !cmd.common() {
                    last_other = i;
                } else if hand_back && i > last_other + COMMON_RUN {
                    break;
                }
            }
            let d = slots
                .get(span[0] as usize..span[1] as usize)
                .unwrap_or_default();
            let arg = |k: usize, default: f64| d.get(k).copied().unwrap_or(default);
            let point = || -> DVec3 {
                match d.len() {
                    2 => DVec3::new(d[0], d[1], 0.0),
                    3 => DVec3::new(d[0], d[1], d[2]),
                    _ => DVec3::ZERO,
                }
            };
            // An integer parameter is held as its bits, which may read as a
            // NaN (`SetColor(-1)`): only the decoded numbers are checked
            // then.
            if !all_finite
                && d.iter().any(|x| !x.is_finite())
                && cmd != Cmd::None
                && !matches!(cmd, Cmd::Query(_))
                && !word.values(i, alphabet, structs).iter().all(finite)
            {
                return Err(DrawError {
                    message: format!(
                        "module {} of the word, `{}`, has a NaN or infinite parameter and cannot be drawn",
                        i + 1,
                        alphabet.name(sym)
                    ),
                    module: Some(i),
                });
            }
            let int_arg = || match word.values(i, alphabet, structs).first() {
                Some(Value::Int(v)) => *v,
                Some(v) => v.as_f64() as i64,
                None => 0,
            };
            match cmd {
                Cmd::None => {}
                Cmd::Forward { draw, record } => {
                    if field.acts() {
                        (head, left, up) = field.adjusted(head, left, up);
                    }
                    let from = pos;
                    let to = moved_to!(pos + head * arg(0, opts.step));
                    pos = to;
                    if record {
                        if let Some(p) = polygons.last_mut() {
                            p.push(to);
                        }
                    }
                    if bends {
                        (head, left, up) = tropism::bent(&t.simple, head, left, up);
                    }
                    if draw {
                        if S::LINE_READS_FRAME {
                            store!();
                        }
                        sink.line(&t, from, to).map_err(|m| at(i, m))?;
                    }
                }
                Cmd::Turn(axis, sign) => {
                    let sign = match axis {
                        DVec3Axis::Up => sign,
                        DVec3Axis::Left | DVec3Axis::Head => sign * sense,
                    };
                    let deg = sign * arg(0, opts.angle);
                    let (s, c) = turns.sin_cos(deg);
                    (head, left, up) = turned(axis, s, c, (head, left, up));
                }
                Cmd::TurnAround => {
                    let (s, c) = 180f64.to_radians().sin_cos();
                    (head, left, up) = turned(DVec3Axis::Up, s, c, (head, left, up));
                }
                Cmd::SetColor => {
                    let c = int_arg();
                    if (1..=255).contains(&c) {
                        t.pen.color = c;
                    }
                }
                Cmd::IncColor => t.pen.color += 1,
                Cmd::DecColor => t.pen.color -= 1,
                Cmd::SetWidth => {
                    t.pen.width = arg(0, 1.0);
                    store!();
                    sink.shape(&t, None, d).map_err(|m| at(i, m))?;
                }
                Cmd::Push => {
                    store!();
                    stack.push(t.clone());
                    sink.push();
                }
                Cmd::Pop => {
                    if let Some(s) = stack.pop() {
                        t = s;
                        (pos, head, left, up) = (t.pos, t.head, t.left, t.up);
                        bends = t.simple.elasticity != 0.0;
                        field.restore(&t.elasticity);
                        sink.pop().map_err(|m| at(i, m))?;
                    }
                }
                _ => {
                    // The fast loop stops at the first other module; the full
                    // loop takes it from there.
                    if !FULL {
                        break;
                    }
                    store!();
                    match cmd {
                        Cmd::MoveTo => t.pos = moved_to!(t.frame.place(point())),
                        Cmd::MoveRel => t.pos = moved_to!(t.pos + t.frame.place(point())),
                        Cmd::LineTo | Cmd::LineRel => {
                            let to = if cmd == Cmd::LineTo {
                                t.frame.place(point())
                            } else {
                                t.pos + t.frame.place(point())
                            };
                            // lpfg ignores a line shorter than epsilon; a drawn one
                            // moves as `F` does, and so records a polygon vertex.
                            if t.pos.distance(to) >= EPSILON {
                                let from = t.pos;
                                t.pos = moved_to!(to);
                                if let Some(p) = polygons.last_mut() {
                                    p.push(to);
                                }
                                sink.line(&t, from, to).map_err(|m| at(i, m))?;
                            }
                        }
                        Cmd::Line => {
                            let (a, b) = if d.len() == 4 {
                                (DVec3::new(d[0], d[1], 0.0), DVec3::new(d[2], d[3], 0.0))
                            } else {
                                (DVec3::new(d[0], d[1], d[2]), DVec3::new(d[3], d[4], d[5]))
                            };
                            let (a, b) = (t.frame.place(a), t.frame.place(b));
                            // lpfg ignores a line shorter than epsilon altogether.
                            if a.distance(b) >= EPSILON {
                                t.pos = moved_to!(b);
                                if let Some(p) = polygons.last_mut() {
                                    p.push(b);
                                }
                                if a.is_finite() && b.is_finite() {
                                    sink.line(&t, a, b).map_err(|m| at(i, m))?;
                                }
                            }
                        }
                        Cmd::Shape(s) => {
                            // Integer parameters (contour ids, sides) are decoded from
                            // the word; these modules are few.
                            let mut args = [0.0; 3];
                            for (a, v) in args.iter_mut().zip(word.values(i, alphabet, structs)) {
                                *a = match v {
                                    Value::Int(n) => n as f64,
                                    v => v.as_f64(),
                                };
                            }
                            sink.shape(&t, Some(s), &args).map_err(|m| at(i, m))?
                        }
                        Cmd::SetElasticity(sign) => {
                            let id = int_arg();
                            let e = match sign {
                                0 => Some(arg(1, 0.0)),
                                _ => field.stepped(id, f64::from(sign)),
                            };
                            if let Some(e) = e {
                                if field.set(id, e) {
                                    std::rc::Rc::make_mut(&mut t.elasticity)[id as usize] = e;
                                }
                            }
                        }
                        Cmd::Elasticity => t.simple.elasticity = arg(0, 0.0),
                        Cmd::SetTropismDirection => t.simple.direction = point(),
                        Cmd::Round(kind) => {
                            let r = if kind.is_dot() { 0.0 } else { arg(0, 1.0) };
                            if !(t.pos.abs().max_element() + r.abs()).is_finite() {
                                return Err(beyond(
                                    word,
                                    i,
                                    alphabet,
                                    structs,
                                    "draws a circle that reaches",
                                ));
                            }
                            sink.round(&t, kind, r).map_err(|m| at(i, m))?;
                        }
                        Cmd::Query(q) => {
                            if let Some(qs) = queries.as_deref_mut() {
                                let v = [t.pos, t.head, t.left, t.up][q as usize];
                                qs.push((i, [v.x, v.y, v.z]));
                            }
                        }
                        Cmd::Surface => {
                            let id = int_arg();
                            let surface = usize::try_from(id)
                                .ok()
                                .and_then(|k| opts.model.surfaces.get(k));
                            let Some(s) = surface else {
                                return Err(DrawError {
                                    message: format!(
                                        "module {} of the interpreted word, `{}`, draws surface {id}, but the model has {}",
                                        i + 1,
                                        alphabet.name(sym),
                                        match opts.model.surfaces.len() {
                                            0 => "no surface (a view file's `surface:` lines name them)".to_string(),
                                            n => format!("surfaces 0 to {}", n - 1),
                                        }
                                    ),
                                    module: Some(i),
                                });
                            };
                            let scale = if d.len() >= 4 {
                                DVec3::new(d[1], d[2], d[3])
                            } else {
                                DVec3::splat(arg(1, 1.0))
                            };
                            sink.surface(&t, s, scale).map_err(|m| at(i, m))?;
                        }
                        Cmd::SetHead => t.set_head(
                            DVec3::new(arg(0, 0.0), arg(1, 0.0), arg(2, 0.0)),
                            DVec3::new(arg(3, 0.0), arg(4, 0.0), arg(5, 0.0)),
                        ),
                        Cmd::SetHead3 => t.set_heading(point()),
                        Cmd::RollToVert => t.roll_to_vert(),
                        Cmd::Rotate(global) => t.rotate(
                            DVec3::new(arg(0, 0.0), arg(1, 0.0), arg(2, 0.0)),
                            arg(3, 0.0),
                            global,
                        ),
                        Cmd::SetCoordinateSystem => {
                            t.frame = std::rc::Rc::new(Cartesian {
                                origin: t.pos,
                                x_axis: t.left,
                                y_axis: t.head,
                                z_axis: t.up,
                                scale: arg(0, 1.0),
                            })
                        }
                        Cmd::Rhombus | Cmd::Triangle => {
                            // lpfg's shapes in the HL plane, the turtle at the middle
                            // of the bottom edge (Rhombus(length, width),
                            // Triangle(width, height)).
                            let (a, b) = (arg(0, 0.0), arg(1, 0.0));
                            let (p, h, l) = (t.pos, t.head, t.left);
                            let points = if cmd == Cmd::Rhombus {
                                vec![
                                    p,
                                    p + h * (a * 0.5) + l * (b * 0.5),
                                    p + h * a,
                                    p + h * (a * 0.5) - l * (b * 0.5),
                                ]
                            } else {
                                vec![p + l * (a * 0.5), p + h * b, p - l * (a * 0.5)]
                            };
                            if points.iter().any(|q| !q.is_finite()) {
                                return Err(beyond(
                                    word,
                                    i,
                                    alphabet,
                                    structs,
                                    "draws a shape that reaches",
                                ));
                            }
                            sink.polygon(&t, points).map_err(|m| at(i, m))?;
                        }
                        Cmd::StartPolygon => polygons.push(Vec::new()),
                        Cmd::PolygonPoint => {
                            if let Some(p) = polygons.last_mut() {
                                p.push(t.pos);
                            }
                        }
                        Cmd::EndPolygon => {
                            if let Some(points) = polygons.pop() {
                                if points.len() >= 3 {
                                    sink.polygon(&t, points).map_err(|m| at(i, m))?;
                                }
                            }
                        }
                        // The common modules, above.
                        _ => {}
                    }
                    (pos, head, left, up) = (t.pos, t.head, t.left, t.up);
                    bends = t.simple.elasticity != 0.0;
                }
            }
            i += 1;
        }
        store!();
        Ok(Walking {
            t,
            stack,
            polygons,
            turns,
            field,
            i,
        })
    }
}

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
fn surface_events(s: &crate::model::Surface, t: &Turtle, scale: DVec3, out: &mut Vec<Event>) {
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

/// True when every number of `v` is finite.
fn finite(v: &Value) -> bool {
    match v {
        Value::Float(x) => x.is_finite(),
        Value::V2(p) => p.is_finite(),
        Value::V3(p) => p.is_finite(),
        Value::Struct(fs) => fs.iter().all(finite),
        _ => true,
    }
}

/// The box `lo..hi` grown to take in the point `p`, by plain comparisons
/// (glam's `select`): `f64::min` and `max` give the same for finite
/// numbers, but compile to a sequence that also handles a NaN operand (a
/// quarter of a box walk's instructions). A NaN coordinate leaves the box
/// as it is, as with them.
#[inline(always)]
fn grown((lo, hi): (DVec3, DVec3), p: DVec3) -> (DVec3, DVec3) {
    (
        DVec3::select(p.cmplt(lo), p, lo),
        DVec3::select(p.cmpgt(hi), p, hi),
    )
}

/// Whether every coordinate of `p` is finite, without a branch per
/// coordinate: `x * 0` is (signed) 0 for a finite `x` and NaN otherwise.
#[inline(always)]
fn finite3(p: DVec3) -> bool {
    let z = p * 0.0;
    z.x + z.y + z.z == 0.0
}

/// Module `i` took the drawing to an infinite coordinate: which one, with
/// its parameters.
fn beyond(
    word: Slices<'_>,
    i: usize,
    alphabet: &Alphabet,
    structs: &[StructDef],
    what: &str,
) -> DrawError {
    let params: Vec<String> = word
        .values(i, alphabet, structs)
        .iter()
        .map(short)
        .collect();
    let module = match params.is_empty() {
        true => alphabet.name(word.sym(i)).to_string(),
        false => format!("{}({})", alphabet.name(word.sym(i)), params.join(", ")),
    };
    DrawError {
        message: format!(
            "module {} of the interpreted word, `{module}`, {what} an infinite coordinate, which cannot be drawn",
            i + 1
        ),
        module: Some(i),
    }
}

/// A parameter in a message: large and small numbers in exponent form.
fn short(v: &Value) -> String {
    let num = |x: f64| {
        if x != 0.0 && !(1e-6..1e16).contains(&x.abs()) {
            format!("{x:e}")
        } else {
            format!("{x}")
        }
    };
    match v {
        Value::Float(x) => num(*x),
        Value::V2(p) => format!("[{}, {}]", num(p.x), num(p.y)),
        Value::V3(p) => format!("[{}, {}, {}]", num(p.x), num(p.y), num(p.z)),
        Value::Struct(fs) => format!(
            "{{{}}}",
            fs.iter().map(short).collect::<Vec<_>>().join(", ")
        ),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A word of `n` modules drawn from `vocabulary` by `next`, as its
    /// program's axiom.
    fn axiom(vocabulary: &[&str], n: usize, next: &mut impl FnMut() -> u64) -> String {
        (0..n)
            .map(|_| vocabulary[(next() % vocabulary.len() as u64) as usize])
            .collect::<Vec<_>>()
            .join(" ")
    }

    /// The events of `src`'s axiom, or the walk's error: on both loops,
    /// on the full loop alone, and on both loops walking the word in
    /// pieces of 1 to 40 modules drawn by `next` ([`Walk::advance`]).
    fn three_ways(src: &str, next: &mut impl FnMut() -> u64) -> [Result<Vec<Event>, DrawError>; 3] {
        // Double precision: a float parameter may be near the largest
        // double.
        let loaded =
            crate::load_str_with("walk.lsys", src, &[], crate::Precision::Double).expect("loads");
        let p = &loaded.program;
        let word = crate::derive(p, Default::default()).expect("derives").word;
        let opts = DrawOptions::default();
        let [fast, full] = [true, false].map(|fast| {
            let mut events = Events::new(Vec::new());
            walk_loops(
                &word,
                &p.alphabet,
                &p.structs,
                &opts,
                None,
                &mut events,
                fast,
            )
            .map(|()| events.into_inner())
        });
        let mut walk = Walk::new(&p.alphabet, &opts, true);
        let mut events = Events::new(Vec::new());
        let mut upto = 0;
        let pieces = loop {
            upto += 1 + (next() % 40) as usize;
            let piece = word.slices().prefix(upto);
            if let Err(e) = walk.advance(piece, &p.alphabet, &p.structs, None, &mut events) {
                break Err(e);
            }
            assert_eq!(walk.walked(), piece.len());
            if upto >= word.len() {
                break Ok(events.into_inner());
            }
        };
        [fast, full, pieces]
    }

    #[test]
    fn the_fast_loop_and_the_full_loop_draw_alike() {
        // Common modules (moves, turns, branches, pens) mixed with others
        // (absolute moves, circles, polygons, 3D rotations), so that the
        // walk changes loops often, in and out of branches and polygons.
        let vocabulary = [
            "F(1)",
            "F(0.5)",
            "f(2)",
            "G(1)",
            "g(1)",
            "F",
            "Left(30)",
            "Right(45)",
            "Left(90)",
            "Down(20)",
            "Up(15)",
            "RollL(40)",
            "RollR(70)",
            "TurnAround",
            "SB",
            "SB",
            "EB",
            "EB",
            "SetColor(3)",
            "SetColor(-1)",
            "IncColor",
            "DecColor",
            "SetWidth(2)",
            "MoveTo(1, 2, 0)",
            "MoveRel2f(V2f(1, 2))",
            "LineRel3f(V3f(0.5, 0.25, 1))",
            "Circle(1)",
            "CircleB(0.5)",
            "Circle0",
            "SP",
            "PP",
            "EP",
            "Rhombus(1, 0.5)",
            "RollToVert",
            "RotateHLU(V3f(0, 0, 1), 33)",
            "SetHead3f(V3f(0, 1, 1))",
        ];
        // The common modules alone, for long runs of them: the full loop
        // hands back after `COMMON_RUN` in a row.
        let common: Vec<&str> = vocabulary[..23].to_vec();
        let mut next = crate::testing::xorshift(0x5eed_1234);
        let mut cut = crate::testing::xorshift(0xc0ff_ee11);
        for round in 0..40 {
            let n = if round % 2 == 0 { 60 } else { 400 };
            let word = if round % 4 < 2 {
                axiom(&vocabulary, n, &mut next)
            } else {
                // Runs of common modules between the others.
                (0..n / 40)
                    .map(|_| {
                        let run = axiom(&common, 20 + (next() % 60) as usize, &mut next);
                        format!("{} {run}", axiom(&vocabulary[23..], 1, &mut next))
                    })
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            let src = format!("derivation length: 0;\nAxiom: {word};\n");
            let [fast, full, pieces] = three_ways(&src, &mut cut);
            let (fast, full) = (fast.expect("draws"), full.expect("draws"));
            assert!(!fast.is_empty(), "{src}");
            assert_eq!(format!("{fast:?}"), format!("{full:?}"), "{src}");
            assert_eq!(
                format!("{:?}", pieces.expect("draws")),
                format!("{full:?}"),
                "{src}"
            );
        }
    }

    #[test]
    fn a_move_past_the_largest_number_fails_at_the_same_module_on_either_loop() {
        let mut next = crate::testing::xorshift(0x0dd_ba11);
        for (word, says) in [
            (
                "F(1) Left(90) F(1e308) F(1e308) F(1)",
                "infinite coordinate",
            ),
            (
                "F(1) Circle(1) F(1e308) F(1e308) F(1)",
                "infinite coordinate",
            ),
            (
                "SB F(1e308) EB MoveTo(1e308, 0, 0) MoveRel2d(V2d(1e308, 0)) F(1e308) F(1)",
                "infinite coordinate",
            ),
            // An integer held as bits that read as a NaN: in pieces, only
            // the pieces from the one that holds it on see a slot that is
            // not finite.
            (
                "F(1) Left(90) F(2) Right(30) F(1) SetColor(-1) F(1) F(1e308) F(1e308) F(1e308)",
                "infinite coordinate",
            ),
        ] {
            let src = format!("derivation length: 0;\nAxiom: {word};\n");
            for _ in 0..8 {
                let [fast, full, pieces] = three_ways(&src, &mut next);
                let (fast, full) = (fast.unwrap_err(), full.unwrap_err());
                let pieces = pieces.unwrap_err();
                for e in [&fast, &pieces] {
                    assert_eq!(e.module, full.module, "{word}");
                    assert_eq!(e.message, full.message, "{word}");
                }
                assert!(fast.message.contains(says), "{}", fast.message);
            }
        }
    }
}
