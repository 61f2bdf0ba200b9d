//! What each predefined module does to the turtle: its command, the
//! circles and spheres of manual 5.5, and the modules that only shape 3D
//! geometry.

use super::turtle::DVec3Axis;

/// What a predefined module does to the turtle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Cmd {
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
    /// `E1`, `E2`, `EA20`: the turtle's frame is sent to the environment.
    Communicate,
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
    pub(super) fn is_dot(self) -> bool {
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

pub(super) fn command(name: &str) -> Cmd {
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
        "E1" | "E2" | "EA20" => Cmd::Communicate,
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
/// turns, sets the pen, answers a query). The communication modules are
/// not among them: the turtle only reports where it met them, for an
/// environment to answer (`draw::coverage` warns about them when a program
/// has none).
pub fn acts_on(name: &str) -> bool {
    !matches!(command(name), Cmd::None | Cmd::Communicate)
}
