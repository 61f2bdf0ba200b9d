//! PNG output with tiny-skia: antialiased fills, and strokes with round caps
//! and joins; polylines with a pen of at most a pixel by their ink
//! (`render::ink`, a private module).

use tiny_skia::{
    Color, FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform,
};

use glam::DVec2;

use crate::draw::{walk, Events};

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
    for item in &scene.items {
        painter.paint(item);
    }
    painter.encode()
}

/// The PNG of the turtle's 2D drawing of `word` in one cell the size of
/// the picture, as [`render`] makes it from the [`super::scene`] of
/// [`crate::draw::draw`]'s events, to the bit; but painted as the turtle
/// walks, with no list of events or items. The turtle walks twice: once
/// to find the drawing's box, once to lay out and paint each event as it
/// comes. Memory beyond the word is the picture's, the points of the
/// widest pen's open polyline, and a few batches of points on their way
/// to the painting thread.
pub fn word(
    word: &crate::rewrite::Word,
    alphabet: &crate::lang::Alphabet,
    structs: &[crate::lang::value::StructDef],
    draw: &crate::draw::DrawOptions,
    opts: &super::RenderOptions,
) -> Result<Vec<u8>, WordError> {
    super::check_size(opts.width, opts.height)?;
    let mut bounds = Events::new(super::Bounds::new(opts.view));
    walk(word, alphabet, structs, draw, None, &mut bounds)?;
    let Some(bounds) = bounds.into_inner().get()? else {
        return Err(super::nothing_to_draw().into());
    };
    let mut opts = std::borrow::Cow::Borrowed(opts);
    if opts.fit_height {
        let height = super::fitted_height(&opts, opts.width as f64, [bounds]);
        opts.to_mut().height = height;
    }
    let painter = Painter::new(opts.width, opts.height, opts.background)?;
    let drawn = (word, alphabet, structs, draw);
    if rayon::current_num_threads() == 1 {
        return Ok(lay_out(drawn, bounds, &opts, painter)?.encode()?);
    }
    // Two threads: this one walks and lays out, the other paints what
    // was laid out, in order.
    let (batches, painted) = std::sync::mpsc::sync_channel::<Batch>(IN_FLIGHT);
    let (spent, spare) = std::sync::mpsc::channel::<Batch>();
    let painter = std::thread::scope(|scope| {
        let paint = scope.spawn(move || {
            let mut painter = painter;
            for mut batch in painted {
                batch.replay(&mut painter);
                // The painting is over when the walk stops taking batches
                // back.
                let _ = spent.send(batch);
            }
            painter
        });
        let relay = Relay {
            batch: Batch::default(),
            limit: BATCH,
            out: batches,
            spare,
        };
        // A failed walk drops the relay, which ends the painting.
        let walked = lay_out(drawn, bounds, &opts, relay).map(|mut relay| relay.send());
        let painter = paint
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        walked.map(|()| painter)
    })?;
    Ok(painter.encode()?)
}

/// Points in a batch handed from the walk to the painting thread.
const BATCH: usize = 1 << 14;
/// Batches on their way to the painting thread at most.
const IN_FLIGHT: usize = 4;

/// Calls of a [`Canvas`](super::Canvas) in order, with the points of
/// their polylines in one list: a mark at `k` comes after `points[..k]`
/// (a polyline's first point is the one at its `Begin`).
#[derive(Default)]
struct Batch {
    points: Vec<DVec2>,
    marks: Vec<(usize, Mark)>,
}

enum Mark {
    Begin(Rgba, f64),
    End,
    Item(Item),
}

impl Batch {
    /// Makes the calls on `canvas`, in order, and empties the batch.
    fn replay(&mut self, canvas: &mut impl super::Canvas) {
        let mut next = 0;
        for (at, mark) in self.marks.drain(..) {
            for p in &self.points[next..at] {
                canvas.point(*p);
            }
            next = at;
            match mark {
                Mark::Begin(color, width) => {
                    canvas.begin(color, width, self.points[at]);
                    next = at + 1;
                }
                Mark::End => canvas.end(),
                Mark::Item(item) => canvas.item(item),
            }
        }
        for p in &self.points[next..] {
            canvas.point(*p);
        }
        self.points.clear();
    }
}

/// The canvas of the walking thread: batches of calls sent to the
/// painting thread, and batches it painted taken back for reuse.
struct Relay {
    batch: Batch,
    /// The points, or marks, of a full batch.
    limit: usize,
    out: std::sync::mpsc::SyncSender<Batch>,
    spare: std::sync::mpsc::Receiver<Batch>,
}

impl Relay {
    /// Sends the batch on (a full one, or the last).
    #[inline(never)]
    fn send(&mut self) {
        let next = self.spare.try_recv().unwrap_or_default();
        let full = std::mem::replace(&mut self.batch, next);
        // The painting thread takes batches until this one stops; it
        // cannot have stopped before.
        let _ = self.out.send(full);
    }

    /// Sends the batch on when it is full.
    #[inline]
    fn sent_if_full(&mut self) {
        if self.batch.points.len() >= self.limit || self.batch.marks.len() >= self.limit {
            self.send();
        }
    }

    fn mark(&mut self, mark: Mark) {
        self.batch.marks.push((self.batch.points.len(), mark));
        self.sent_if_full();
    }
}

impl super::Canvas for Relay {
    fn begin(&mut self, color: Rgba, width: f64, first: DVec2) {
        let at = self.batch.points.len();
        self.batch.marks.push((at, Mark::Begin(color, width)));
        self.batch.points.push(first);
        self.sent_if_full();
    }

    #[inline]
    fn point(&mut self, p: DVec2) {
        self.batch.points.push(p);
        self.sent_if_full();
    }

    fn end(&mut self) {
        self.mark(Mark::End);
    }

    fn item(&mut self, item: Item) {
        self.mark(Mark::Item(item));
    }
}

/// The turtle's walk over a word, laying its drawing out within `bounds`
/// on `canvas`.
fn lay_out<C: super::Canvas>(
    (word, alphabet, structs, draw): Drawn<'_>,
    bounds: (DVec2, DVec2),
    opts: &super::RenderOptions,
    canvas: C,
) -> Result<C, crate::draw::DrawError> {
    let layout = super::Layout::new(bounds, 0.0, opts.width as f64, opts, canvas);
    let mut events = Events::new(layout);
    walk(word, alphabet, structs, draw, None, &mut events)?;
    Ok(events.into_inner().finish())
}

/// A word and what the turtle needs to draw it.
type Drawn<'a> = (
    &'a crate::rewrite::Word,
    &'a crate::lang::Alphabet,
    &'a [crate::lang::value::StructDef],
    &'a crate::draw::DrawOptions,
);

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

/// A picture being painted: items one after another, and a polyline a
/// point at a time.
pub(crate) struct Painter {
    pm: Pixmap,
    ink: super::ink::Ink,
    open: Option<Open>,
}

/// The polyline being painted: a thin pen's inks each segment as it
/// comes; a wider pen's points wait for tiny-skia to stroke them whole.
enum Open {
    Thin {
        color: Rgba,
        pen: f64,
        last: DVec2,
    },
    Wide {
        color: Rgba,
        width: f64,
        points: Vec<DVec2>,
    },
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

    /// Paints `item` (a long thin polyline in bands on rayon's pool).
    fn paint(&mut self, item: &Item) {
        match item {
            Item::Polyline {
                points,
                color,
                width,
            } => match Self::thin(*width) {
                Some(pen) => {
                    self.ink.polyline(points, pen);
                    self.ink.blend(&mut self.pm, *color);
                }
                None => self.stroke(points, *color, *width),
            },
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

impl super::Canvas for Painter {
    fn begin(&mut self, color: Rgba, width: f64, first: DVec2) {
        self.open = Some(match Self::thin(width) {
            Some(pen) => Open::Thin {
                color,
                pen,
                last: first,
            },
            None => Open::Wide {
                color,
                width,
                points: vec![first],
            },
        });
    }

    #[inline]
    fn point(&mut self, p: DVec2) {
        match &mut self.open {
            Some(Open::Thin { pen, last, .. }) => {
                self.ink.segment(*last, p, *pen);
                *last = p;
            }
            Some(Open::Wide { points, .. }) => points.push(p),
            None => {}
        }
    }

    fn end(&mut self) {
        match self.open.take() {
            Some(Open::Thin { color, .. }) => self.ink.blend(&mut self.pm, color),
            Some(Open::Wide {
                color,
                width,
                points,
            }) => self.stroke(&points, color, width),
            None => {}
        }
    }

    fn item(&mut self, item: Item) {
        self.paint(&item);
    }
}

#[cfg(test)]
mod tests {
    use super::super::Canvas;
    use super::*;

    /// The calls a canvas got, as text.
    #[derive(Default)]
    struct Log(Vec<String>);

    impl Canvas for Log {
        fn begin(&mut self, color: Rgba, width: f64, first: DVec2) {
            self.0.push(format!("begin {color:?} {width} {first}"));
        }
        fn point(&mut self, p: DVec2) {
            self.0.push(format!("point {p}"));
        }
        fn end(&mut self) {
            self.0.push("end".into());
        }
        fn item(&mut self, item: Item) {
            self.0.push(format!("item {item:?}"));
        }
    }

    /// Calls relayed in batches of every small size reach the painting
    /// thread's canvas as they were made: a batch that fills at a
    /// polyline's first point, at its last, or at an item in between.
    #[test]
    fn relayed_calls_arrive_in_order() {
        let mut bits = crate::testing::xorshift(0x9e37_79b9_7f4a_7c15);
        let mut next = |n: u64| bits() % n;
        let calls: Vec<(u64, f64)> = (0..600).map(|i| (next(10), i as f64)).collect();
        let make = |canvas: &mut dyn Canvas| {
            let mut open = false;
            for &(kind, x) in &calls {
                let p = DVec2::new(x, -x);
                match kind {
                    0 | 1 if !open => {
                        canvas.begin(Rgba(kind as u8, 0, 0, 255), x, p);
                        open = true;
                    }
                    0 => {
                        canvas.end();
                        open = false;
                    }
                    1 => canvas.item(Item::Disc {
                        c: p,
                        r: x,
                        color: Rgba(1, 2, 3, 4),
                    }),
                    _ if open => canvas.point(p),
                    _ => {}
                }
            }
            if open {
                canvas.end();
            }
        };
        let mut direct = Log::default();
        make(&mut direct);
        assert!(direct.0.len() > 400, "{}", direct.0.len());
        for limit in 1..=7 {
            let (out, painted) = std::sync::mpsc::sync_channel::<Batch>(IN_FLIGHT);
            let (spent, spare) = std::sync::mpsc::channel::<Batch>();
            let got = std::thread::scope(|scope| {
                let paint = scope.spawn(move || {
                    let mut log = Log::default();
                    for mut batch in painted {
                        batch.replay(&mut log);
                        let _ = spent.send(batch);
                    }
                    log
                });
                let mut relay = Relay {
                    batch: Batch::default(),
                    limit,
                    out,
                    spare,
                };
                make(&mut relay);
                relay.send();
                drop(relay);
                paint.join().unwrap()
            });
            assert_eq!(got.0, direct.0, "batches of {limit}");
        }
    }
}
