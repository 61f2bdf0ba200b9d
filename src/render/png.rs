//! PNG output with tiny-skia: antialiased fills, and strokes with round caps
//! and joins; polylines with a pen of at most a pixel by their ink
//! (`render::ink`, a private module).

use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, PremultipliedColorU8, Stroke,
    Transform,
};

use glam::{DVec2, DVec3};

use crate::draw::{walk, Event, Events, Pen, Walk};
use crate::rewrite::growth::Reader;
use crate::rewrite::word::Slices;

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

/// A scene's pixels, as [`render`] paints them before encoding:
/// premultiplied RGBA, row by row from the top (the frames of an
/// animation are encoded from these).
pub fn image(scene: &Scene) -> Result<super::raster::Image, RenderError> {
    let mut painter = Painter::new(scene.width, scene.height, scene.background)?;
    painter.paint(scene.items.iter().map(|item| match item {
        Item::Polyline {
            points,
            color,
            width,
        } => Piece::Line(points, *color, *width),
        item => Piece::Item(item),
    }));
    Ok(super::raster::Image {
        width: scene.width,
        height: scene.height,
        pixels: painter.pm.take(),
    })
}

/// The PNG of the turtle's 2D drawing of `word` in one cell the size of
/// the picture, as [`render`] makes it from the [`super::scene`] of
/// [`crate::draw::draw`]'s events, to the bit; but with no list of events
/// or items. The turtle walks once, keeping its paths' points (projected
/// onto the view's plane) in one list and finding the drawing's box; the
/// painting then takes each point to its pixel as it inks it.
///
/// Memory beyond the word and the picture is those points, 16 bytes each
/// (two for a line that starts a path, one for a line that continues one,
/// as every line of a curve does), the start and pen of each path (24
/// bytes), and the events that are not paths.
pub fn word(
    word: &crate::rewrite::Word,
    alphabet: &crate::lang::Alphabet,
    structs: &[crate::lang::value::StructDef],
    draw: &crate::draw::DrawOptions,
    opts: &super::RenderOptions,
) -> Result<Vec<u8>, WordError> {
    let mut drawing = Events::new(Drawing::new(opts.view, word.len()));
    walk(word, alphabet, structs, draw, None, &mut drawing)?;
    Ok(finish(drawing.into_inner(), opts)?)
}

/// The turtle's walk of [`word`], reading a word as it grows
/// ([`crate::rewrite::growth::Growth::read_with`]); [`Walked::png`]
/// paints what it drew.
pub(crate) struct WordWalk<'o> {
    alphabet: &'o crate::lang::Alphabet,
    structs: &'o [crate::lang::value::StructDef],
    draw: &'o crate::draw::DrawOptions,
    view: super::View,
    walk: Option<Walk<'o>>,
    drawing: Option<Events<Drawing>>,
    failed: Option<crate::draw::DrawError>,
}

impl<'o> WordWalk<'o> {
    pub(crate) fn new(
        alphabet: &'o crate::lang::Alphabet,
        structs: &'o [crate::lang::value::StructDef],
        draw: &'o crate::draw::DrawOptions,
        view: super::View,
    ) -> WordWalk<'o> {
        WordWalk {
            alphabet,
            structs,
            draw,
            view,
            walk: None,
            drawing: None,
            failed: None,
        }
    }

    /// What the turtle drew of the word read, which was read whole, or
    /// where it failed.
    pub(crate) fn walked(self) -> Result<Walked, crate::draw::DrawError> {
        match (self.failed, self.drawing) {
            (Some(e), _) => Err(e),
            (None, Some(drawing)) => Ok(Walked(drawing.into_inner())),
            // No word was read: the walk of an empty one.
            (None, None) => Ok(Walked(Drawing::new(self.view, 0))),
        }
    }
}

/// The turtle's drawing of a word ([`WordWalk::walked`]), to be painted.
pub(crate) struct Walked(Drawing);

impl Walked {
    /// The PNG that [`word`] makes of the word walked.
    pub(crate) fn png(self, opts: &super::RenderOptions) -> Result<Vec<u8>, RenderError> {
        finish(self.0, opts)
    }
}

impl Reader for WordWalk<'_> {
    fn start(&mut self, total: usize) {
        self.walk = Some(Walk::new(self.alphabet, self.draw, true));
        self.drawing = Some(Events::new(Drawing::new(self.view, total)));
        self.failed = None;
    }

    fn read_so_far(&self) -> usize {
        self.walk.as_ref().map_or(0, Walk::walked)
    }

    fn read(&mut self, word: Slices<'_>) -> bool {
        let (Some(walk), Some(drawing)) = (&mut self.walk, &mut self.drawing) else {
            return false;
        };
        match walk.advance(word, self.alphabet, self.structs, None, drawing) {
            Ok(()) => true,
            Err(e) => {
                self.failed = Some(e);
                false
            }
        }
    }
}

/// Paints the turtle's drawing as [`word`] does once the walk is done.
fn finish(drawing: Drawing, opts: &super::RenderOptions) -> Result<Vec<u8>, RenderError> {
    // After the walk, as `super::scene` checks it after the events are
    // drawn: a failing module is told first.
    super::check_size(opts.width, opts.height)?;
    let Some(bounds) = drawing.bounds.get()? else {
        return Err(super::nothing_to_draw());
    };
    let mut opts = std::borrow::Cow::Borrowed(opts);
    if opts.fit_height {
        let height = super::fitted_height(&opts, opts.width as f64, [bounds]);
        opts.to_mut().height = height;
    }
    let painter = Painter::new(opts.width, opts.height, opts.background)?;
    let cell = (0.0, 0.0, opts.width as f64, opts.height as f64);
    let layout = super::Layout::new(bounds, cell, &opts, painter);
    drawing.paint(layout).encode()
}

/// The turtle's 2D drawing as it walks, compactly: the points of its
/// paths, one path after another, projected onto the view's plane; where
/// each path starts among them, and its pen; the other events; and the box
/// of it all.
struct Drawing {
    view: super::View,
    bounds: super::Bounds,
    points: Vec<DVec2>,
    /// The index of each path's first point, and its pen.
    paths: Vec<(usize, Pen)>,
    /// The events that are not paths, each after the points drawn before
    /// it (and before a path that starts at the same index).
    events: Vec<(usize, Event)>,
}

impl Drawing {
    /// A drawing of a word of `modules` modules: room for a point each is
    /// set aside (taken from the system only as the points come, in huge
    /// pages where the system has them, as the word's own arrays are).
    fn new(view: super::View, modules: usize) -> Drawing {
        Drawing {
            view,
            bounds: super::Bounds::new(view),
            points: crate::huge::with_capacity(modules.saturating_add(1)),
            paths: Vec::new(),
            events: Vec::new(),
        }
    }

    /// Where path `k` ends: the start of the next one, or of none.
    fn end(&self, k: usize) -> usize {
        self.paths.get(k + 1).map_or(self.points.len(), |p| p.0)
    }

    /// The points of the consecutive paths `paths` (not empty), in all.
    fn run_points(&self, paths: std::ops::Range<usize>) -> usize {
        self.end(paths.end - 1) - self.paths[paths.start].0
    }

    /// Paints the drawing as `layout` lays out the events: each run of
    /// thin paths with no event between them is inked at once
    /// ([`PathRun`]), and wider paths and the other events go through the
    /// layout to the painter.
    fn paint(self, mut layout: super::Layout<'_, Painter>) -> Painter {
        let thin = |layout: &super::Layout<'_, Painter>, pen: Pen| {
            Painter::thin(layout.width(pen.width)).is_some()
        };
        // A long run is inked in bands, each of which passes over the
        // chunks of points that lie wholly outside its rows: the chunks
        // are measured for the first such run.
        let chunks = std::cell::OnceCell::new();
        let mut events = self.events.iter().peekable();
        let mut k = 0;
        loop {
            let next_path = self.paths.get(k).map(|p| p.0);
            if let Some((at, e)) = events.next_if(|(at, _)| next_path.is_none_or(|s| *at <= s)) {
                debug_assert!(*at <= self.points.len());
                layout.lay(e);
                continue;
            }
            let Some(&(start, pen)) = self.paths.get(k) else {
                break;
            };
            if !thin(&layout, pen) {
                layout.path_from(pen, self.points[start]);
                for &p in &self.points[start + 1..self.end(k)] {
                    layout.point(p);
                }
                k += 1;
                continue;
            }
            // The run: the thin paths from `k` on, up to the next event
            // or wider path.
            let event = events.peek().map(|(at, _)| *at);
            let mut last = k + 1;
            while let Some(&(s, pen)) = self.paths.get(last) {
                if event.is_some_and(|at| at <= s) || !thin(&layout, pen) {
                    break;
                }
                last += 1;
            }
            layout.end_run();
            let painter = &mut layout.canvas;
            let banded = painter.ink.bands(self.run_points(k..last)) > 1;
            let run = PathRun {
                drawing: &self,
                paths: k..last,
                style: layout.style,
                chunks: banded
                    .then(|| chunks.get_or_init(|| super::ink::Chunks::new(&self.points))),
            };
            painter.ink.paint(&mut painter.pm, &run);
            k = last;
        }
        layout.finish()
    }
}

/// Consecutive thin paths of a [`Drawing`], painted as the layout joins
/// them into lines ([`super::Layout::path_from`]): a path continues the
/// line before it when it has the same colour and width and starts within
/// 1e-9 pixels of the line's end, and then its first point is left out.
struct PathRun<'a> {
    drawing: &'a Drawing,
    paths: std::ops::Range<usize>,
    style: super::Style<'a>,
    /// The drawing's points in chunks, when the run is long enough to be
    /// inked in bands.
    chunks: Option<&'a super::ink::Chunks>,
}

impl super::ink::Run for PathRun<'_> {
    fn points(&self) -> usize {
        self.drawing.run_points(self.paths.clone())
    }

    fn paint(&self, band: &mut super::ink::Band<'_>, pixels: &mut [PremultipliedColorU8]) {
        let (d, style) = (self.drawing, self.style);
        // The open line's colour, width and last point.
        let mut open: Option<(Rgba, f64, DVec2)> = None;
        for k in self.paths.clone() {
            let (start, pen) = d.paths[k];
            let (color, width) = (style.color(pen.color), style.width(pen.width));
            let first = style.fit.pixel(d.points[start]);
            let from = match open {
                Some((c, w, last)) if super::joins((c, w, last), (color, width, first)) => last,
                _ => {
                    if let Some((c, ..)) = open {
                        band.blend(pixels, c);
                    }
                    first
                }
            };
            let pen = Painter::thin(width).unwrap_or(1.0);
            let rest = start + 1..d.end(k);
            // The pixel transform's y depends on a point's y alone, and
            // monotonically, as `lay_chunked` needs.
            let pixel = |q: DVec2| style.fit.pixel(q);
            let last = match self.chunks {
                Some(chunks) => band.lay_chunked(from, &d.points, rest, chunks, pixel, pen),
                None => band.lay(from, d.points[rest].iter().map(|&q| pixel(q)), pen),
            };
            open = Some((color, width, last));
        }
        if let Some((c, ..)) = open {
            band.blend(pixels, c);
        }
    }
}

impl crate::draw::EventSink for Drawing {
    fn path(&mut self, pen: Pen, a: DVec3, b: DVec3) -> Result<(), String> {
        let (a, b) = (self.view.project(a), self.view.project(b));
        self.bounds.any = true;
        self.bounds.grow_projected(a, 0.0);
        self.bounds.grow_projected(b, 0.0);
        self.paths.push((self.points.len(), pen));
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
        self.events.push((self.points.len(), e));
        Ok(())
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
    /// The polyline coming through [`super::Canvas`]: its colour, width
    /// and points so far.
    open: Option<(Rgba, f64, Vec<DVec2>)>,
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
            open: None,
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
            self.ink.paint(&mut self.pm, &run[..]);
            run.clear();
            match piece {
                Piece::Line(points, color, width) => self.stroke(points, color, width),
                Piece::Item(item) => self.item(item),
            }
        }
        self.ink.paint(&mut self.pm, &run[..]);
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

/// Polylines a point at a time, painted whole at their end, and items as
/// they come.
impl super::Canvas for Painter {
    fn begin(&mut self, color: Rgba, width: f64, first: DVec2) {
        self.open = Some((color, width, vec![first]));
    }

    fn point(&mut self, p: DVec2) {
        if let Some((.., points)) = &mut self.open {
            points.push(p);
        }
    }

    fn end(&mut self) {
        if let Some((color, width, points)) = self.open.take() {
            self.paint(std::iter::once(Piece::Line(&points, color, width)));
        }
    }

    fn item(&mut self, item: Item) {
        self.item(&item);
    }
}
