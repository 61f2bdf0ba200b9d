//! The renderer-neutral drawing events, and the 2D sink that makes them
//! from the turtle's lines, circles, polygons and surfaces.

use glam::DVec3;

use super::surfaces::surface_events;
use super::{Round, Sink, Turtle};

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

/// Where the turtle's 2D drawing goes, one event at a time: a list of
/// events ([`draw`]), or the compact drawing that `render::png::word`
/// keeps (its paths' points in one list). [`Events`] decides which lines
/// continue a path.
///
/// [`draw`]: super::draw
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
