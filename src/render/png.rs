//! PNG output with tiny-skia: antialiased fills, and strokes with round caps
//! and joins; polylines with a pen of at most a pixel by their ink
//! (`render::ink`, a private module).

use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform,
};

use glam::{DVec2, DVec3};

use crate::draw::{walk, Event, Events, Pen};

use super::{Item, RenderError, Rgba, Scene};

/// An anti-aliased solid paint.
fn paint(c: Rgba) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(c.0, c.1, c.2, c.3));
    p.anti_alias = true;
    p
}

fn stroke(width: f64) -> Stroke {
    Stroke {
        width: width.max(0.0) as f32,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    }
}

/// Rasterises a scene and encodes it as PNG.
pub fn render(scene: &Scene) -> Result<Vec<u8>, RenderError> {
    let mut painter = Painter::new(scene.width, scene.height, scene.background)?;
    painter.paint(scene.items.iter().map(|item| match item {
        Item::Polyline {
            points,
            color,
            width,
        } => Piece::Line(points, *color, *width),
        item => Piece::Item(item),
    }));
    painter.encode()
}

/// The PNG of the turtle's 2D drawing of `word` in one cell the size of
/// the picture, as [`render`] makes it from the [`super::scene`] of
/// [`crate::draw::draw`]'s events, to the bit; but with no list of events
/// or items. The turtle walks once, keeping its lines' points (projected
/// onto the view's plane) in one list and finding the drawing's box; the
/// points are then laid out in pixels where they lie, and painted.
///
/// Memory beyond the word and the picture is those points, 16 bytes each
/// (at most two a line drawn, one a line that continues a path, as every
/// line of a curve does), a mark where each path or other event starts,
/// and the events that are not paths.
pub fn word(
    word: &crate::rewrite::Word,
    alphabet: &crate::lang::Alphabet,
    structs: &[crate::lang::value::StructDef],
    draw: &crate::draw::DrawOptions,
    opts: &super::RenderOptions,
) -> Result<Vec<u8>, WordError> {
    super::check_size(opts.width, opts.height)?;
    let mut drawing = Events::new(Drawing::new(opts.view, word.len()));
    walk(word, alphabet, structs, draw, None, &mut drawing)?;
    let drawing = drawing.into_inner();
    let Some(bounds) = drawing.bounds.get()? else {
        return Err(super::nothing_to_draw().into());
    };
    let mut opts = std::borrow::Cow::Borrowed(opts);
    if opts.fit_height {
        let height = super::fitted_height(&opts, opts.width as f64, [bounds]);
        opts.to_mut().height = height;
    }
    let mut painter = Painter::new(opts.width, opts.height, opts.background)?;
    let laid = drawing.lay_out(bounds, &opts);
    painter.paint(laid.parts.iter().map(|piece| match piece {
        Part::Line(range, color, width) => Piece::Line(&laid.points[range.clone()], *color, *width),
        Part::Item(item) => Piece::Item(item),
    }));
    Ok(painter.encode()?)
}

/// The turtle's 2D drawing as it walks, compactly: the points of its
/// paths, one path after another, projected onto the view's plane; where
/// each path, and each other event, starts among them; and the box of it
/// all.
struct Drawing {
    view: super::View,
    bounds: super::Bounds,
    points: Vec<DVec2>,
    /// What starts before the point at each index.
    starts: Vec<(usize, Start)>,
}

enum Start {
    /// A path drawn with this pen: its first point is the one at the index.
    Path(Pen),
    /// An event that is not a path.
    Event(Event),
}

impl Drawing {
    /// A drawing of a word of `modules` modules: room for a point each is
    /// set aside (and taken from the system only as the points come).
    fn new(view: super::View, modules: usize) -> Drawing {
        Drawing {
            view,
            bounds: super::Bounds::new(view),
            points: Vec::with_capacity(modules.saturating_add(1)),
            starts: Vec::new(),
        }
    }

    /// The drawing laid out in pixels within `bounds`, as
    /// [`super::scene`] lays out the events: each point becomes its pixel
    /// in place, and consecutive paths that [`super::Layout`] joins become
    /// one line (the later path's first point left out).
    fn lay_out(self, bounds: (DVec2, DVec2), opts: &super::RenderOptions) -> Laid {
        let Drawing { points, starts, .. } = self;
        let n = points.len();
        let canvas = Laid {
            points,
            len: 0,
            parts: Vec::new(),
        };
        let mut layout = super::Layout::new(bounds, 0.0, opts.width as f64, opts, canvas);
        // Point `read` is read before any pixel is written over it: each
        // point read writes at most one pixel, at `len <= read`.
        let mut read = 0;
        fn to(layout: &mut super::Layout<'_, Laid>, read: &mut usize, end: usize) {
            while *read < end {
                let p = layout.canvas.points[*read];
                layout.point(p);
                *read += 1;
            }
        }
        for (at, start) in starts {
            to(&mut layout, &mut read, at);
            match start {
                Start::Path(pen) => {
                    let a = layout.canvas.points[read];
                    layout.path_from(pen, a);
                    read += 1;
                }
                Start::Event(e) => layout.lay(&e),
            }
        }
        to(&mut layout, &mut read, n);
        let mut laid = layout.finish();
        laid.points.truncate(laid.len);
        laid
    }
}

impl crate::draw::EventSink for Drawing {
    fn path(&mut self, pen: Pen, a: DVec3, b: DVec3) -> Result<(), String> {
        let (a, b) = (self.view.project(a), self.view.project(b));
        self.bounds.any = true;
        self.bounds.grow_projected(a, 0.0);
        self.bounds.grow_projected(b, 0.0);
        self.starts.push((self.points.len(), Start::Path(pen)));
        self.points.extend([a, b]);
        Ok(())
    }

    #[inline(always)]
    fn continue_to(&mut self, b: DVec3) -> Result<(), String> {
        let b = self.view.project(b);
        self.bounds.grow_projected(b, 0.0);
        self.points.push(b);
        Ok(())
    }

    fn event(&mut self, e: Event) -> Result<(), String> {
        self.bounds.event(&e);
        self.starts.push((self.points.len(), Start::Event(e)));
        Ok(())
    }
}

/// A drawing laid out in pixels: the points of its lines, one line after
/// another, and its lines and other items in order.
struct Laid {
    points: Vec<DVec2>,
    /// The points laid out so far: `points[..len]`.
    len: usize,
    parts: Vec<Part>,
}

/// A part of a [`Laid`] drawing.
enum Part {
    /// A polyline through the points in the range, with its colour and
    /// width in pixels.
    Line(std::ops::Range<usize>, Rgba, f64),
    Item(Item),
}

impl super::Canvas for Laid {
    fn begin(&mut self, color: Rgba, width: f64, first: DVec2) {
        self.parts
            .push(Part::Line(self.len..self.len, color, width));
        self.point(first);
    }

    #[inline]
    fn point(&mut self, p: DVec2) {
        self.points[self.len] = p;
        self.len += 1;
    }

    fn end(&mut self) {
        if let Some(Part::Line(range, ..)) = self.parts.last_mut() {
            range.end = self.len;
        }
    }

    fn item(&mut self, item: Item) {
        self.parts.push(Part::Item(item));
    }
}

/// Why [`word`] made no picture: the turtle's walk failed, or the drawing
/// cannot be pictured.
#[derive(Debug)]
pub enum WordError {
    Draw(crate::draw::DrawError),
    Render(RenderError),
}

impl From<crate::draw::DrawError> for WordError {
    fn from(e: crate::draw::DrawError) -> Self {
        WordError::Draw(e)
    }
}

impl From<RenderError> for WordError {
    fn from(e: RenderError) -> Self {
        WordError::Render(e)
    }
}

/// What a picture is painted from, in order: a polyline (its points,
/// colour and width in pixels), or another item.
enum Piece<'a> {
    Line(&'a [DVec2], Rgba, f64),
    Item(&'a Item),
}

/// A picture being painted.
pub(crate) struct Painter {
    pm: Pixmap,
    ink: super::ink::Ink,
}

impl Painter {
    pub(crate) fn new(width: u32, height: u32, background: Rgba) -> Result<Painter, RenderError> {
        let mut pm = Pixmap::new(width, height)
            .ok_or_else(|| RenderError::new("cannot allocate an image of that size"))?;
        let b = background;
        pm.fill(Color::from_rgba8(b.0, b.1, b.2, b.3));
        Ok(Painter {
            pm,
            ink: super::ink::Ink::new(width, height),
        })
    }

    /// The pen a polyline of `width` pixels is inked with, or `None` when
    /// it is wider than a pixel (a width of 0 is a hairline).
    fn thin(width: f64) -> Option<f64> {
        (width <= 1.0).then_some(if width > 0.0 { width } else { 1.0 })
    }

    /// Paints `pieces` one after another. Each run of thin polylines
    /// between other pieces is inked at once (in bands of rows on rayon's
    /// pool when it is long); wider polylines and other items are painted
    /// by tiny-skia.
    fn paint<'a>(&mut self, pieces: impl Iterator<Item = Piece<'a>>) {
        let mut run = Vec::new();
        for piece in pieces {
            if let Piece::Line(points, color, width) = piece {
                if let Some(pen) = Self::thin(width) {
                    run.push(super::ink::Line { points, pen, color });
                    continue;
                }
            }
            self.ink.paint(&mut self.pm, &run);
            run.clear();
            match piece {
                Piece::Line(points, color, width) => self.stroke(points, color, width),
                Piece::Item(item) => self.item(item),
            }
        }
        self.ink.paint(&mut self.pm, &run);
    }

    /// Paints an item that is not a polyline.
    fn item(&mut self, item: &Item) {
        match item {
            Item::Polyline {
                points,
                color,
                width,
            } => self.paint(std::iter::once(Piece::Line(points, *color, *width))),
            Item::Disc { c, r, color } => {
                if let Some(path) =
                    PathBuilder::from_circle(c.x as f32, c.y as f32, (*r as f32).max(0.25))
                {
                    let id = Transform::identity();
                    self.pm
                        .fill_path(&path, &paint(*color), FillRule::Winding, id, None);
                }
            }
            Item::Ring { c, r, color, width } => {
                if let Some(path) =
                    PathBuilder::from_circle(c.x as f32, c.y as f32, (*r as f32).max(0.25))
                {
                    let id = Transform::identity();
                    self.pm
                        .stroke_path(&path, &paint(*color), &stroke(*width), id, None);
                }
            }
            Item::Polygon {
                points,
                color,
                outline,
            } => {
                let Some(mut pb) = path_through(points) else {
                    return;
                };
                pb.close();
                if let Some(path) = pb.finish() {
                    let id = Transform::identity();
                    self.pm
                        .fill_path(&path, &paint(*color), FillRule::EvenOdd, id, None);
                    if let Some(o) = outline {
                        self.pm
                            .stroke_path(&path, &paint(o.color), &stroke(o.width), id, None);
                    }
                }
            }
        }
    }

    /// Strokes the polyline through `points` with round caps and joins.
    fn stroke(&mut self, points: &[DVec2], color: Rgba, width: f64) {
        if let Some(path) = path_through(points).and_then(PathBuilder::finish) {
            let id = Transform::identity();
            self.pm
                .stroke_path(&path, &paint(color), &stroke(width), id, None);
        }
    }

    fn encode(self) -> Result<Vec<u8>, RenderError> {
        self.pm
            .encode_png()
            .map_err(|e| RenderError::new(format!("cannot encode the PNG: {e}")))
    }
}

/// A path builder through `points` in order, `None` for no points.
fn path_through(points: &[DVec2]) -> Option<PathBuilder> {
    let [first, rest @ ..] = points else {
        return None;
    };
    let mut pb = PathBuilder::new();
    pb.move_to(first.x as f32, first.y as f32);
    for p in rest {
        pb.line_to(p.x as f32, p.y as f32);
    }
    Some(pb)
}
