//! Interpretation of a word as drawing: the turtle walks the modules and
//! emits renderer-neutral [`Event`]s in 3D. PNG and SVG both draw these
//! events, so the two always agree.

use glam::DVec3;

use crate::lang::value::StructDef;
use crate::lang::{Alphabet, Sym, Value};
use crate::rewrite::Word;

/// The style of a stroke: colour index and width in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pen {
    pub color: i64,
    pub width: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// A straight segment.
    Line { a: DVec3, b: DVec3, pen: Pen },
    /// A filled disc of world radius `r` (`Circle`, `Sphere`).
    Disc { c: DVec3, r: f64, color: i64 },
    /// A filled disc whose diameter is the pen width in pixels (`Circle0`).
    Dot { c: DVec3, pen: Pen },
    /// A circle outline of world radius `r`, stroked with the pen (`CircleB`).
    Ring { c: DVec3, r: f64, pen: Pen },
    /// A filled polygon (`SP() ... PP() ... EP()`).
    Polygon { points: Vec<DVec3>, color: i64 },
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
    Cut,
    Disc,
    Dot,
    Ring,
    StartPolygon,
    PolygonPoint,
    EndPolygon,
    /// `Surface(id, s)`, `Surface3(id, sx, sy, sz)`: a model's Bézier
    /// surface.
    Surface,
    Query(u8),
}

/// The turtle axis a rotation turns about.
#[derive(Clone, Copy, Debug, PartialEq)]
enum DVec3Axis {
    Up,
    Left,
    Head,
}

#[derive(Clone, Copy, Debug)]
struct Turtle {
    pos: DVec3,
    head: DVec3,
    left: DVec3,
    up: DVec3,
    pen: Pen,
}

impl Turtle {
    fn new() -> Turtle {
        Turtle {
            pos: DVec3::ZERO,
            head: DVec3::Y,
            left: DVec3::NEG_X,
            up: DVec3::Z,
            pen: Pen {
                color: 1,
                width: 1.0,
            },
        }
    }

    /// Rotates by `deg` degrees about one of the turtle's own axes.
    fn turn(&mut self, axis: DVec3Axis, deg: f64) {
        let (s, c) = deg.to_radians().sin_cos();
        let rot = |a: DVec3, b: DVec3| (a * c + b * s, b * c - a * s);
        match axis {
            // Left: heading turns towards the left vector.
            DVec3Axis::Up => (self.head, self.left) = rot(self.head, self.left),
            // Up: heading turns towards the up vector.
            DVec3Axis::Left => (self.head, self.up) = rot(self.head, self.up),
            // RollR: left turns towards up.
            DVec3Axis::Head => (self.left, self.up) = rot(self.left, self.up),
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
}

impl Default for DrawOptions {
    fn default() -> Self {
        DrawOptions {
            angle: 90.0,
            step: 1.0,
            model: Default::default(),
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
        "Cut" => Cmd::Cut,
        "Circle" | "CircleFront" | "Sphere" => Cmd::Disc,
        "Circle0" | "CircleFront0" | "Sphere0" => Cmd::Dot,
        "CircleB" | "CircleFrontB" => Cmd::Ring,
        "SP" => Cmd::StartPolygon,
        "PP" => Cmd::PolygonPoint,
        "EP" => Cmd::EndPolygon,
        "Surface" | "Surface3" => Cmd::Surface,
        "GetPos" => Cmd::Query(0),
        "GetHead" => Cmd::Query(1),
        "GetLeft" => Cmd::Query(2),
        "GetUp" => Cmd::Query(3),
        _ => Cmd::None,
    }
}

/// True for lpfg's query modules, which the turtle fills in.
pub fn is_query(name: &str) -> bool {
    matches!(name, "GetPos" | "GetHead" | "GetLeft" | "GetUp")
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

/// Like [`draw`]; also records, for every query module met, the vector it
/// asks for (`GetPos`: position, `GetHead`/`GetLeft`/`GetUp`: the frame).
pub fn draw_with_queries(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    mut queries: Option<&mut Vec<[f64; 3]>>,
) -> Result<Vec<Event>, DrawError> {
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
    let mut t = Turtle::new();
    let mut stack: Vec<Turtle> = Vec::new();
    let mut polygons: Vec<Vec<DVec3>> = Vec::new();
    let mut out = Vec::new();
    let mut i = 0;
    let n = word.len();
    while i < n {
        let sym: Sym = word.sym(i);
        let cmd = cmds[sym.0 as usize];
        let d = word.data(i);
        let arg = |k: usize, default: f64| d.get(k).copied().unwrap_or(default);
        let point = || -> DVec3 {
            match d.len() {
                2 => DVec3::new(d[0], d[1], 0.0),
                3 => DVec3::new(d[0], d[1], d[2]),
                _ => DVec3::ZERO,
            }
        };
        if d.iter().any(|x| !x.is_finite()) && cmd != Cmd::None && !matches!(cmd, Cmd::Query(_)) {
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
                let to = t.pos + t.head * arg(0, opts.step);
                if draw {
                    out.push(Event::Line {
                        a: t.pos,
                        b: to,
                        pen: t.pen,
                    });
                }
                t.pos = to;
                if record {
                    if let Some(p) = polygons.last_mut() {
                        p.push(to);
                    }
                }
            }
            Cmd::MoveTo => t.pos = point(),
            Cmd::MoveRel => t.pos += point(),
            Cmd::LineTo | Cmd::LineRel => {
                let to = if cmd == Cmd::LineTo {
                    point()
                } else {
                    t.pos + point()
                };
                if t.pos.distance(to) >= 1e-5 {
                    out.push(Event::Line {
                        a: t.pos,
                        b: to,
                        pen: t.pen,
                    });
                }
                t.pos = to;
            }
            Cmd::Line => {
                let (a, b) = if d.len() == 4 {
                    (DVec3::new(d[0], d[1], 0.0), DVec3::new(d[2], d[3], 0.0))
                } else {
                    (DVec3::new(d[0], d[1], d[2]), DVec3::new(d[3], d[4], d[5]))
                };
                if a.distance(b) >= 1e-5 {
                    out.push(Event::Line { a, b, pen: t.pen });
                }
                t.pos = b;
            }
            Cmd::Turn(axis, sign) => t.turn(axis, sign * arg(0, opts.angle)),
            Cmd::TurnAround => t.turn(DVec3Axis::Up, 180.0),
            Cmd::SetColor => {
                let c = int_arg();
                if (1..=255).contains(&c) {
                    t.pen.color = c;
                }
            }
            Cmd::IncColor => t.pen.color += 1,
            Cmd::DecColor => t.pen.color -= 1,
            Cmd::SetWidth => t.pen.width = arg(0, 1.0),
            Cmd::Push => stack.push(t),
            Cmd::Pop => {
                if let Some(s) = stack.pop() {
                    t = s;
                }
            }
            Cmd::Cut => {
                // Skip to the end of the current branch.
                let mut depth = 0;
                while i + 1 < n {
                    let name = alphabet.name(word.sym(i + 1));
                    if name == "SB" {
                        depth += 1;
                    } else if name == "EB" {
                        if depth == 0 {
                            break;
                        }
                        depth -= 1;
                    }
                    i += 1;
                }
            }
            Cmd::Disc | Cmd::Ring => {
                let r = arg(0, 1.0);
                if !(t.pos.abs().max_element() + r.abs()).is_finite() {
                    return Err(beyond(
                        word,
                        i,
                        alphabet,
                        structs,
                        "draws a circle that reaches",
                    ));
                }
                out.push(if cmd == Cmd::Disc {
                    Event::Disc {
                        c: t.pos,
                        r,
                        color: t.pen.color,
                    }
                } else {
                    Event::Ring {
                        c: t.pos,
                        r,
                        pen: t.pen,
                    }
                })
            }
            Cmd::Dot => out.push(Event::Dot {
                c: t.pos,
                pen: t.pen,
            }),
            Cmd::Query(q) => {
                if let Some(qs) = queries.as_deref_mut() {
                    let v = [t.pos, t.head, t.left, t.up][q as usize];
                    qs.push([v.x, v.y, v.z]);
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
                surface_events(s, &t, scale, &mut out);
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
                        out.push(Event::Polygon {
                            points,
                            color: t.pen.color,
                        });
                    }
                }
            }
        }
        // Finite parameters can still add up past the largest number.
        if !t.pos.is_finite() {
            return Err(beyond(word, i, alphabet, structs, "moves the turtle to"));
        }
        i += 1;
    }
    Ok(out)
}

/// Each patch of surface `s` as a filled polygon, its outline: the
/// surface's contact point at the turtle, its heading and up vectors on
/// the turtle's, scaled by `scale` × the view file's scale / `SIZE:`.
fn surface_events(s: &crate::model::Surface, t: &Turtle, scale: DVec3, out: &mut Vec<Event>) {
    const STEPS: usize = 8;
    let v = |a: [f64; 3]| DVec3::from_array(a);
    let (h, u) = (
        v(s.heading).normalize_or_zero(),
        v(s.up).normalize_or_zero(),
    );
    let l = u.cross(h);
    let k = scale * (s.scale / s.size);
    let place = |p: [f64; 3]| {
        let q = v(p) - v(s.contact);
        t.pos + t.head * (q.dot(h) * k.y) + t.left * (q.dot(l) * k.x) + t.up * (q.dot(u) * k.z)
    };
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
            points: ring.into_iter().map(place).collect(),
            color: t.pen.color,
        });
    }
}

/// Module `i` took the drawing to an infinite coordinate: which one, with
/// its parameters.
fn beyond(
    word: &Word,
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
