//! The turtle's walk over a word: the fast loop over the common modules,
//! the full loop over all, a word walked in pieces as it is written, and
//! the errors of a module that takes the drawing to an infinite
//! coordinate.

use glam::DVec3;

use super::commands::{command, Cmd};
use super::turtle::{turned, Cartesian, DVec3Axis};
use super::{tropism, DrawError, DrawOptions, Sink, Turtle, EPSILON};
use crate::lang::value::StructDef;
use crate::lang::{Alphabet, Value};
use crate::rewrite::environment::Frame;
use crate::rewrite::word::Slices;
use crate::rewrite::{TurtleAnswers, Word};

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

/// The turtle's walk over `word`, drawing into `sink`.
pub(crate) fn walk<S: Sink>(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    queries: Option<&mut TurtleAnswers>,
    sink: &mut S,
) -> Result<(), DrawError> {
    walk_loops(word, alphabet, structs, opts, queries, sink, true)
}

/// [`walk`], on both loops when `fast` (the walk), or on the full loop
/// alone (what the tests compare the walk with).
pub(super) fn walk_loops<S: Sink>(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    queries: Option<&mut TurtleAnswers>,
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
        mut queries: Option<&mut TurtleAnswers>,
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
        mut queries: Option<&mut TurtleAnswers>,
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
                                qs.queries.push((i, [v.x, v.y, v.z]));
                            }
                        }
                        Cmd::Communicate => {
                            if let Some(qs) = queries.as_deref_mut() {
                                let v = |v: DVec3| [v.x, v.y, v.z];
                                qs.communication.push((
                                    i,
                                    Frame {
                                        position: v(t.pos),
                                        heading: v(t.head),
                                        left: v(t.left),
                                        up: v(t.up),
                                    },
                                ));
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
    use crate::draw::{Event, Events};

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
