//! From drawing events and meshes to pictures: fitting the view, then PNG
//! (tiny-skia) or SVG (the svg crate) from the same [`Scene`]. Turtle
//! events are laid out here; [`mesh`] turns a polygon mesh into shaded
//! polygons of a scene.
//!
//! **Layer.** It uses `colour`, `deadline`, `draw`, `files`, `huge`, `lang`,
//! `mesh`, `model`, `rewrite`, `scene3`; it is used by `command`, `curve`,
//! `error`, `export`, `system`. Nothing here names a layer above (see
//! ARCHITECTURE.md, "Layers").

mod ink;
pub mod mesh;
pub mod png;
pub mod raster;
pub mod svg;
pub mod view_file;

pub use crate::colour::{palette, Rgba};
pub use crate::files::atomic::write_atomic;

use glam::{DVec2, DVec3};

use crate::draw::{Event, Pen};

/// The plane the 3D drawing is projected onto, orthographically.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum View {
    /// Looking down the z axis (the default; 2D drawings live here).
    #[default]
    Xy,
    /// Looking along y: x to the right, z up.
    Xz,
    /// Looking along x: y to the right, z up.
    Yz,
}

impl View {
    fn project(self, p: DVec3) -> DVec2 {
        match self {
            View::Xy => DVec2::new(p.x, p.y),
            View::Xz => DVec2::new(p.x, p.z),
            View::Yz => DVec2::new(p.y, p.z),
        }
    }
}

/// Settings of a picture. `Default` is 800×800 on white, 4% margin, xy view.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    pub background: Rgba,
    /// Margin on every side, as a fraction of the smaller image side.
    pub margin: f64,
    pub view: View,
    /// The colours that colour indices choose (a model's colour map or
    /// materials); `None`: the default palette.
    pub palette: Option<std::sync::Arc<[Rgba; 256]>>,
    /// Line widths are in the drawing's units (lpfg's `line style:
    /// polygon` or `cylinder`), not in pixels.
    pub widths_in_units: bool,
    /// Lower the height to what the panels' drawings need (`--each`
    /// without `--size`): wide drawings side by side make a strip, not a
    /// strip in an empty square.
    pub fit_height: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 800,
            background: Rgba(255, 255, 255, 255),
            margin: 0.04,
            view: View::Xy,
            palette: None,
            widths_in_units: false,
            fit_height: false,
        }
    }
}

/// One shape in pixel coordinates (y down).
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// Connected segments with one pen.
    Polyline {
        points: Vec<DVec2>,
        color: Rgba,
        width: f64,
    },
    Disc {
        c: DVec2,
        r: f64,
        color: Rgba,
    },
    Ring {
        c: DVec2,
        r: f64,
        color: Rgba,
        width: f64,
    },
    /// A filled polygon (even-odd rule), with an optional outline stroked
    /// over the fill with round joins.
    Polygon {
        points: Vec<DVec2>,
        color: Rgba,
        outline: Option<Outline>,
    },
}

/// The pen of a polygon's outline: a colour and a width in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outline {
    pub color: Rgba,
    pub width: f64,
}

/// A picture ready for a backend: size, background and items.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub width: u32,
    pub height: u32,
    pub background: Rgba,
    pub items: Vec<Item>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderError {
    pub message: String,
}

impl RenderError {
    pub(crate) fn new(m: impl Into<String>) -> RenderError {
        RenderError { message: m.into() }
    }
}

/// The largest accepted image side, in pixels.
const MAX_SIDE: u32 = 20_000;

/// Refuses an image with a zero side or a side over [`MAX_SIDE`].
fn check_size(width: u32, height: u32) -> Result<(), RenderError> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(RenderError::new(format!(
            "the image size {width}x{height} is out of range: each side must be 1 to {MAX_SIDE} pixels"
        )));
    }
    Ok(())
}

/// A cell of the picture: its left column, top row, width and height in
/// pixels.
type Cell = (f64, f64, f64, f64);

/// The least height of a row of `--each`'s panels whose height is fitted
/// (no `--size`): panels too wide for it are wrapped into more rows.
pub const MIN_PANEL_HEIGHT: f64 = 160.0;

/// The map from drawing-plane coordinates (y up) to pixels (y down): a
/// bounding box scaled uniformly into a cell of the image, with a margin,
/// and centred in it.
#[derive(Clone, Copy, Debug)]
struct Fit {
    scale: f64,
    centre: DVec2,
    mid: DVec2,
}

impl Fit {
    /// Fits the box `lo..hi` into the cell that starts at pixel column `x0`
    /// and is `width`×`height` pixels, leaving `margin` (a fraction of the
    /// cell's smaller side) on every side.
    fn new(lo: DVec2, hi: DVec2, x0: f64, width: f64, height: f64, margin: f64) -> Fit {
        Fit::in_cell(lo, hi, (x0, 0.0, width, height), margin)
    }

    /// [`Fit::new`] into the cell `(x0, y0, width, height)`.
    fn in_cell(lo: DVec2, hi: DVec2, (x0, y0, width, height): Cell, margin: f64) -> Fit {
        let m = margin * width.min(height);
        let avail = DVec2::new(width - 2.0 * m, height - 2.0 * m).max(DVec2::ONE);
        Fit {
            scale: fit_scale(avail, hi - lo),
            centre: (lo + hi) * 0.5,
            mid: DVec2::new(x0 + width * 0.5, y0 + height * 0.5),
        }
    }

    /// The pixel position of a drawing-plane point.
    fn pixel(&self, q: DVec2) -> DVec2 {
        let d = (q - self.centre) * self.scale;
        DVec2::new(self.mid.x + d.x, self.mid.y - d.y)
    }
}

/// Lays out panels side by side: each list of events is fitted into its own
/// cell of equal width. One panel is the usual single picture. With
/// `fit_height`, the picture is as tall as the panels' drawings need, and
/// panels whose drawings would be less than [`MIN_PANEL_HEIGHT`] pixels
/// tall side by side are wrapped into rows (of as many panels as keep
/// them that tall, at least one), read left to right, top to bottom.
pub fn scene(panels: &[Vec<Event>], opts: &RenderOptions) -> Result<Scene, RenderError> {
    check_size(opts.width, opts.height)?;
    if panels.iter().all(|p| p.is_empty()) {
        return Err(nothing_to_draw());
    }
    let n = panels.len().max(1);
    let mut opts = std::borrow::Cow::Borrowed(opts);
    let (mut columns, mut row_h) = (n, opts.height as f64);
    if opts.fit_height {
        let mut boxes = Vec::new();
        for events in panels {
            boxes.extend(panel_bounds(events, opts.view)?);
        }
        let w = opts.width as f64;
        let h = opts.height as f64;
        // The fewest rows whose panels are tall enough (one panel a row at
        // the most).
        for c in (1..=n).rev() {
            let rows = n.div_ceil(c);
            let row = fitted_height(&opts, w / c as f64, boxes.iter().copied()) as f64;
            (columns, row_h) = (c, row);
            if row >= MIN_PANEL_HEIGHT.min(h) || (rows + 1) as f64 * row > MAX_SIDE as f64 {
                break;
            }
        }
        let rows = n.div_ceil(columns);
        opts.to_mut().height = (rows as f64 * row_h).min(MAX_SIDE as f64) as u32;
    }
    let cell_w = opts.width as f64 / columns as f64;
    let mut items = Vec::new();
    for (k, events) in panels.iter().enumerate() {
        let cell = (
            (k % columns) as f64 * cell_w,
            (k / columns) as f64 * row_h,
            cell_w,
            row_h,
        );
        fit_panel(events, &opts, cell, &mut items)?;
    }
    Ok(Scene {
        width: opts.width,
        height: opts.height,
        background: opts.background,
        items,
    })
}

/// The box around `events` in the plane of `view` (discs and rings with
/// their radius): `None` for no events, an error for a coordinate that is
/// not finite. Frames of an animation are laid out in the union of theirs.
pub fn bounds(events: &[Event], view: View) -> Result<Option<(DVec2, DVec2)>, RenderError> {
    panel_bounds(events, view)
}

/// One panel of `events` laid out in the box `lo..hi` of the drawing plane
/// (not the events' own box, as [`scene`] takes): frames that share a box
/// share a camera, so a drawing that grows is not scaled up to fill each
/// frame. An empty list of events is an empty picture.
pub fn scene_within(
    events: &[Event],
    (lo, hi): (DVec2, DVec2),
    opts: &RenderOptions,
) -> Result<Scene, RenderError> {
    check_size(opts.width, opts.height)?;
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(RenderError::new(
            "the drawing has a NaN or infinite coordinate and cannot be fitted",
        ));
    }
    let cell = (0.0, 0.0, opts.width as f64, opts.height as f64);
    let mut layout = Layout::new((lo, hi), cell, opts, Vec::new());
    events.iter().for_each(|e| layout.lay(e));
    Ok(Scene {
        width: opts.width,
        height: opts.height,
        background: opts.background,
        items: layout.finish(),
    })
}

fn nothing_to_draw() -> RenderError {
    RenderError::new(
        "nothing to draw: after interpretation the word has no drawing modules (F, LineTo2f, Circle, ...)",
    )
}

/// The height that panels `cell_w` pixels wide with drawings in `boxes`
/// need: the tallest drawing as the panels are fitted, plus the margins,
/// at most the height asked.
fn fitted_height(
    opts: &RenderOptions,
    cell_w: f64,
    boxes: impl IntoIterator<Item = (DVec2, DVec2)>,
) -> u32 {
    let h = opts.height as f64;
    let mut needed: f64 = 0.0;
    for (lo, hi) in boxes {
        let fit = Fit::new(lo, hi, 0.0, cell_w, h, opts.margin);
        needed = needed.max((hi.y - lo.y) * fit.scale);
    }
    let m = opts.margin * cell_w.min(h);
    (needed + 2.0 * m).ceil().clamp(1.0, h) as u32
}

/// The bounds of a panel's events in the drawing plane (discs and rings
/// with their radius); `None` for no events, an error for a coordinate that
/// is not finite.
fn panel_bounds(events: &[Event], v: View) -> Result<Option<(DVec2, DVec2)>, RenderError> {
    let mut b = Bounds::new(v);
    events.iter().for_each(|e| b.event(e));
    b.get()
}

/// The box around events as they come, in the drawing plane.
pub(crate) struct Bounds {
    view: View,
    lo: DVec2,
    hi: DVec2,
    finite: bool,
    /// Whether any event came.
    any: bool,
}

impl Bounds {
    pub(crate) fn new(view: View) -> Bounds {
        Bounds {
            view,
            lo: DVec2::splat(f64::INFINITY),
            hi: DVec2::splat(f64::NEG_INFINITY),
            finite: true,
            any: false,
        }
    }

    #[inline]
    fn grow(&mut self, p: DVec3, r: f64) {
        self.grow_projected(self.view.project(p), r);
    }

    /// [`Bounds::grow`] by a point already projected onto the view's plane.
    #[inline]
    fn grow_projected(&mut self, p: DVec2, r: f64) {
        self.finite &= p.is_finite() && r.is_finite();
        // Plain comparisons (as `draw::bounds::grown`): a coordinate that is not
        // finite fails `get` whatever the box.
        let (a, b) = (p - r, p + r);
        self.lo = DVec2::select(a.cmplt(self.lo), a, self.lo);
        self.hi = DVec2::select(b.cmpgt(self.hi), b, self.hi);
    }

    fn event(&mut self, e: &Event) {
        self.any = true;
        match e {
            Event::Path { points, .. } | Event::Polygon { points, .. } => {
                points.iter().for_each(|p| self.grow(*p, 0.0))
            }
            Event::Disc { c, r, .. } | Event::Ring { c, r, .. } => self.grow(*c, r.abs()),
            Event::Dot { c, .. } => self.grow(*c, 0.0),
        }
    }

    /// The box, `None` when no event came, or an error for a coordinate
    /// that is not finite.
    pub(crate) fn get(&self) -> Result<Option<(DVec2, DVec2)>, RenderError> {
        if !self.any {
            return Ok(None);
        }
        if !(self.finite && self.lo.is_finite() && self.hi.is_finite()) {
            return Err(RenderError::new(
                "the drawing has a NaN or infinite coordinate and cannot be fitted",
            ));
        }
        Ok(Some((self.lo, self.hi)))
    }
}

/// Where laid-out items go: a [`Scene`]'s list, or a picture painted at
/// once. A polyline comes a point at a time, between `begin` and `end`.
pub(crate) trait Canvas {
    /// A polyline of colour `color` and width `width` (pixels) starts at
    /// `first`.
    fn begin(&mut self, color: Rgba, width: f64, first: DVec2);
    /// The open polyline goes on to `p`.
    fn point(&mut self, p: DVec2);
    /// The open polyline is complete.
    fn end(&mut self);
    /// Any other item (never a polyline).
    fn item(&mut self, item: Item);
}

/// The items of a [`Scene`].
impl Canvas for Vec<Item> {
    fn begin(&mut self, color: Rgba, width: f64, first: DVec2) {
        self.push(Item::Polyline {
            points: vec![first],
            color,
            width,
        });
    }

    #[inline]
    fn point(&mut self, p: DVec2) {
        if let Some(Item::Polyline { points, .. }) = self.last_mut() {
            points.push(p);
        }
    }

    fn end(&mut self) {}

    fn item(&mut self, item: Item) {
        self.push(item);
    }
}

/// How a cell of the picture draws: the map to its pixels, and the
/// colours and widths of pens.
#[derive(Clone, Copy)]
pub(crate) struct Style<'o> {
    fit: Fit,
    opts: &'o RenderOptions,
}

impl Style<'_> {
    /// The colour of index `i`: the model's colour map, or the default
    /// palette.
    fn color(&self, i: i64) -> Rgba {
        match &self.opts.palette {
            Some(p) => p[i.rem_euclid(256) as usize],
            None => palette(i),
        }
    }

    /// A pen's width in pixels.
    fn width(&self, w: f64) -> f64 {
        if self.opts.widths_in_units {
            w * self.fit.scale
        } else {
            w
        }
    }
}

/// Whether a path of colour, width and first point `next` continues the
/// open polyline of colour, width and last point `open`: the same colour
/// and width, and within 1e-9 pixels.
fn joins((c, w, last): (Rgba, f64, DVec2), (color, width, first): (Rgba, f64, DVec2)) -> bool {
    c == color && w == width && last.distance(first) < 1e-9
}

/// Events laid out in pixels in one cell of the picture, handed to a
/// [`Canvas`] as they come: consecutive paths of one colour and width that
/// meet (within 1e-9 pixels) make one polyline, the later path's first
/// point left out.
pub(crate) struct Layout<'o, C> {
    style: Style<'o>,
    canvas: C,
    /// The open polyline's colour, width and last point.
    run: Option<(Rgba, f64, DVec2)>,
}

impl<'o, C: Canvas> Layout<'o, C> {
    /// The layout of events within the box `lo..hi` into `cell` of the
    /// picture.
    pub(crate) fn new(
        (lo, hi): (DVec2, DVec2),
        cell: Cell,
        opts: &'o RenderOptions,
        canvas: C,
    ) -> Self {
        Layout {
            style: Style {
                fit: Fit::in_cell(lo, hi, cell, opts.margin),
                opts,
            },
            canvas,
            run: None,
        }
    }

    fn color(&self, i: i64) -> Rgba {
        self.style.color(i)
    }

    fn width(&self, w: f64) -> f64 {
        self.style.width(w)
    }

    #[inline]
    fn px(&self, p: DVec3) -> DVec2 {
        self.style.fit.pixel(self.style.opts.view.project(p))
    }

    /// A path with `pen` starts at `a` (projected onto the view's plane):
    /// it continues the open polyline, or begins one.
    fn path_from(&mut self, pen: Pen, a: DVec2) {
        let first = self.style.fit.pixel(a);
        let (color, width) = (self.color(pen.color), self.width(pen.width));
        let joined = self
            .run
            .is_some_and(|open| joins(open, (color, width, first)));
        if !joined {
            self.end_run();
            self.canvas.begin(color, width, first);
            self.run = Some((color, width, first));
        }
    }

    /// The open polyline goes on to `p` (projected onto the view's plane).
    #[inline]
    fn point(&mut self, p: DVec2) {
        let q = self.style.fit.pixel(p);
        self.canvas.point(q);
        if let Some(run) = &mut self.run {
            run.2 = q;
        }
    }

    fn end_run(&mut self) {
        if self.run.take().is_some() {
            self.canvas.end();
        }
    }

    fn lay(&mut self, e: &Event) {
        let scale = self.style.fit.scale;
        let item = match e {
            Event::Path { points, pen } => {
                let view = self.style.opts.view;
                if let [first, rest @ ..] = points.as_slice() {
                    self.path_from(*pen, view.project(*first));
                    rest.iter().for_each(|p| self.point(view.project(*p)));
                }
                return;
            }
            Event::Disc { c, r, color } => Item::Disc {
                c: self.px(*c),
                r: r.abs() * scale,
                color: self.color(*color),
            },
            Event::Dot { c, pen } => Item::Disc {
                c: self.px(*c),
                r: self.width(pen.width) * 0.5,
                color: self.color(pen.color),
            },
            Event::Ring { c, r, pen } => Item::Ring {
                c: self.px(*c),
                r: r.abs() * scale,
                color: self.color(pen.color),
                width: self.width(pen.width),
            },
            Event::Polygon { points, color } => Item::Polygon {
                points: points.iter().map(|p| self.px(*p)).collect(),
                color: self.color(*color),
                outline: None,
            },
        };
        self.end_run();
        self.canvas.item(item);
    }

    /// The canvas, the last polyline ended.
    pub(crate) fn finish(mut self) -> C {
        self.end_run();
        self.canvas
    }
}

fn fit_panel(
    events: &[Event],
    opts: &RenderOptions,
    cell: Cell,
    items: &mut Vec<Item>,
) -> Result<(), RenderError> {
    let Some(bounds) = panel_bounds(events, opts.view)? else {
        return Ok(());
    };
    let mut layout = Layout::new(bounds, cell, opts, std::mem::take(items));
    events.iter().for_each(|e| layout.lay(e));
    *items = layout.finish();
    Ok(())
}

/// The scale that fits a drawing of extent `ext` into `avail`, keeping its
/// aspect; a flat extent (a line, a point) fits by its other side, or not
/// at all.
fn fit_scale(avail: DVec2, ext: DVec2) -> f64 {
    match (ext.x > 1e-12, ext.y > 1e-12) {
        (true, true) => (avail.x / ext.x).min(avail.y / ext.y),
        (true, false) => avail.x / ext.x,
        (false, true) => avail.y / ext.y,
        (false, false) => 1.0,
    }
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for RenderError {}
