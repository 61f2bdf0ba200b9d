//! Pictures of polygon meshes: a flat-shaded orthographic view as PNG or SVG.
//!
//! The mesh is projected along the view direction, fitted into the image
//! with a margin (uniform scale, centred), and its faces are painted back
//! to front (painter's algorithm, by mean depth). Each face gets a flat
//! Lambert shade of a light grey-blue from a key light and a weak fill
//! light that are fixed relative to the viewer, so every view is lit the
//! same way; faces seen from behind (the inside of an open mesh) get a
//! warmer tint. Thin dark edges show the polygons.

use std::fmt::Write;

use glam::{DVec2, DVec3};
use svg::node::element::{Polygon, Rectangle};
use svg::Document;
use tiny_skia::{Color, FillRule, LineCap, LineJoin, PathBuilder, Pixmap, Stroke};

use super::PolygonSoup;
use crate::render::png::paint;
use crate::render::{fit_scale, RenderError, Rgba};

/// The largest accepted image side, in pixels.
const MAX_SIDE: u32 = 20_000;
/// The colour of faces seen from the front (a light grey-blue).
const FRONT_BASE: DVec3 = DVec3::new(0.70, 0.77, 0.88);
/// The colour of faces seen from behind (a light warm grey).
const BACK_BASE: DVec3 = DVec3::new(0.88, 0.76, 0.68);
/// The light every face gets, whatever its orientation.
const AMBIENT: f64 = 0.30;
/// The strength of the key light (upper left, in front of the viewer).
const KEY: f64 = 0.62;
/// The strength of the fill light (lower right, in front of the viewer).
const FILL: f64 = 0.16;
/// Lifts the mid tones of the light (below 1: brighter), so that faces
/// turned from the key light still read clearly.
const GAMMA: f64 = 0.7;
/// The colour of the wireframe edges.
const EDGE: Rgba = Rgba(38, 46, 60, 255);

/// How a mesh is looked at and how the picture is laid out.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshView {
    pub width: u32,
    pub height: u32,
    pub background: Rgba,
    /// Draw the polygon edges as thin dark lines.
    pub wireframe: bool,
    /// The viewing direction, from the eye towards the scene (any length).
    pub direction: DVec3,
    /// The world direction that points up on screen (projected; any length).
    pub up: DVec3,
    /// Margin on every side, as a fraction of the smaller image side.
    pub margin: f64,
}

impl Default for MeshView {
    /// 800×800 on white with edges, the "iso" view, 4% margin.
    fn default() -> Self {
        let (direction, up) = iso();
        MeshView {
            width: 800,
            height: 800,
            background: Rgba(255, 255, 255, 255),
            wireframe: true,
            direction,
            up,
            margin: 0.04,
        }
    }
}

/// The default three-quarter view: from the front (-y), right (+x) and
/// above (+z), with +z up on screen.
fn iso() -> (DVec3, DVec3) {
    (DVec3::new(-1.0, 1.6, -1.1).normalize(), DVec3::Z)
}

/// The named views accepted by `--view`: "front" (looking along +y),
/// "back", "left" (looking along +x), "right", "top" (looking down -z with
/// +y up), "bottom" and "iso" (the default). Returns (direction, up).
pub fn view_direction(name: &str) -> Option<(DVec3, DVec3)> {
    match name.to_ascii_lowercase().as_str() {
        "front" => Some((DVec3::Y, DVec3::Z)),
        "back" => Some((DVec3::NEG_Y, DVec3::Z)),
        "left" => Some((DVec3::X, DVec3::Z)),
        "right" => Some((DVec3::NEG_X, DVec3::Z)),
        "top" => Some((DVec3::NEG_Z, DVec3::Y)),
        "bottom" => Some((DVec3::Z, DVec3::NEG_Y)),
        "iso" => Some(iso()),
        _ => None,
    }
}

/// An orthonormal viewer frame: screen right, screen up, and depth (the
/// viewing direction, larger is farther).
#[derive(Clone, Copy, Debug)]
struct Camera {
    right: DVec3,
    up: DVec3,
    dir: DVec3,
}

impl Camera {
    /// The frame of a view, or None when its direction is zero or not finite.
    /// An `up` parallel to the direction is replaced by another axis.
    fn new(view: &MeshView) -> Option<Camera> {
        let dir = view.direction.try_normalize()?;
        let candidates = [view.up, DVec3::Z, DVec3::Y, DVec3::X];
        let right = candidates
            .iter()
            .find_map(|u| dir.cross(*u).try_normalize())?;
        let up = right.cross(dir);
        Some(Camera { right, up, dir })
    }

    /// The frame of a view, falling back to the default view when the
    /// direction is unusable.
    fn or_default(view: &MeshView) -> Camera {
        Camera::new(view)
            .or_else(|| Camera::new(&MeshView::default()))
            .unwrap_or(Camera {
                right: DVec3::X,
                up: DVec3::Y,
                dir: DVec3::NEG_Z,
            })
    }

    /// Screen-plane coordinates (y up) of a point.
    fn plane(&self, p: DVec3) -> DVec2 {
        DVec2::new(p.dot(self.right), p.dot(self.up))
    }

    /// The unit vector towards the key light.
    fn key_light(&self) -> DVec3 {
        (-0.45 * self.right + 0.75 * self.up - 0.55 * self.dir).normalize()
    }

    /// The unit vector towards the fill light.
    fn fill_light(&self) -> DVec3 {
        (0.6 * self.right - 0.3 * self.up - 0.7 * self.dir).normalize()
    }
}

/// The unit vector towards the key light of a view, in world coordinates:
/// a face whose normal points along it is the brightest.
pub fn light_direction(view: &MeshView) -> DVec3 {
    Camera::or_default(view).key_light()
}

/// The map from screen-plane coordinates to pixels (y down).
#[derive(Clone, Copy, Debug)]
struct Fit {
    scale: f64,
    centre: DVec2,
    mid: DVec2,
}

impl Fit {
    /// Fits the bounding box of `points` (screen plane) into the image.
    fn new(points: impl Iterator<Item = DVec2>, view: &MeshView) -> Fit {
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for p in points.filter(|p| p.is_finite()) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (DVec2::ZERO, DVec2::ZERO);
        }
        let size = DVec2::new(view.width as f64, view.height as f64);
        let fraction = if view.margin.is_finite() {
            view.margin.clamp(0.0, 0.45)
        } else {
            0.04
        };
        let avail = (size - 2.0 * fraction * size.min_element()).max(DVec2::ONE);
        let ext = hi - lo;
        let scale = fit_scale(avail, ext);
        Fit {
            scale,
            centre: (lo + hi) * 0.5,
            mid: size * 0.5,
        }
    }

    /// The pixel position of a screen-plane point.
    fn pixel(&self, q: DVec2) -> DVec2 {
        let d = (q - self.centre) * self.scale;
        DVec2::new(self.mid.x + d.x, self.mid.y - d.y)
    }
}

/// The vertices that faces refer to (valid indices only).
fn used_vertices(soup: &PolygonSoup) -> impl Iterator<Item = DVec3> + '_ {
    soup.faces
        .iter()
        .flatten()
        .filter_map(|&i| soup.positions.get(i as usize).copied())
}

/// The pixel positions of all vertices of `soup` in the picture `view`
/// would draw (y down, origin at the top left corner).
pub fn project(view: &MeshView, soup: &PolygonSoup) -> Vec<DVec2> {
    let cam = Camera::or_default(view);
    let fit = Fit::new(used_vertices(soup).map(|p| cam.plane(p)), view);
    soup.positions
        .iter()
        .map(|&p| fit.pixel(cam.plane(p)))
        .collect()
}

/// Checks that `soup` can be drawn with `view`: a sane image size, a usable
/// direction, at least one face, finite positions and valid indices.
pub fn validate(soup: &PolygonSoup, view: &MeshView) -> Result<(), RenderError> {
    let (w, h) = (view.width, view.height);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(error(format!(
            "the image size {w}x{h} is out of range: each side must be 1 to {MAX_SIDE} pixels"
        )));
    }
    if Camera::new(view).is_none() {
        return Err(error(
            "the view direction must be a finite, non-zero vector",
        ));
    }
    if soup.faces.is_empty() {
        return Err(error("nothing to draw: the mesh has no faces"));
    }
    if let Some(v) = soup.positions.iter().position(|p| !p.is_finite()) {
        let p = soup.positions[v];
        return Err(error(format!(
            "vertex {v}{} has a non-finite position ({}, {}, {})",
            at_line(soup.vertex_line(v)),
            p.x,
            p.y,
            p.z
        )));
    }
    check_indices(soup)
}

/// Every face index must name a vertex.
fn check_indices(soup: &PolygonSoup) -> Result<(), RenderError> {
    let n = soup.positions.len();
    for (f, face) in soup.faces.iter().enumerate() {
        if let Some(&i) = face.iter().find(|&&i| i as usize >= n) {
            return Err(error(format!(
                "face {f}{} refers to vertex {i}, but the mesh has {n} vertices",
                at_line(soup.face_line(f))
            )));
        }
    }
    Ok(())
}

/// " (line N)" when the line is known.
fn at_line(line: Option<usize>) -> String {
    line.map(|l| format!(" (line {l})")).unwrap_or_default()
}

fn error(message: impl Into<String>) -> RenderError {
    RenderError {
        message: message.into(),
    }
}

/// One face ready to paint: its outline in pixels and its flat colour.
#[derive(Clone, Debug)]
struct Shaded {
    points: Vec<DVec2>,
    fill: Rgba,
    depth: f64,
    back: bool,
}

/// The drawable faces of `soup`, shaded and sorted back to front. Faces
/// with fewer than three vertices, invalid indices or zero area are left
/// out.
fn shaded_faces(soup: &PolygonSoup, view: &MeshView) -> Vec<Shaded> {
    let cam = Camera::or_default(view);
    let fit = Fit::new(used_vertices(soup).map(|p| cam.plane(p)), view);
    let mut faces: Vec<Shaded> = soup
        .faces
        .iter()
        .filter_map(|face| shade_face(soup, face, &cam, &fit))
        .collect();
    faces.sort_by(|a, b| b.depth.total_cmp(&a.depth).then(b.back.cmp(&a.back)));
    faces
}

/// The shaded, projected face, or None when it cannot be drawn.
fn shade_face(soup: &PolygonSoup, face: &[u32], cam: &Camera, fit: &Fit) -> Option<Shaded> {
    let corners: Vec<DVec3> = face
        .iter()
        .map(|&i| soup.positions.get(i as usize).copied())
        .collect::<Option<_>>()?;
    if corners.len() < 3 || corners.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let normal = newell_normal(&corners).try_normalize()?;
    let back = normal.dot(cam.dir) > 0.0;
    let seen = if back { -normal } else { normal };
    let depth = corners.iter().map(|p| p.dot(cam.dir)).sum::<f64>() / corners.len() as f64;
    Some(Shaded {
        points: corners.iter().map(|&p| fit.pixel(cam.plane(p))).collect(),
        fill: shade(seen, back, cam),
        depth,
        back,
    })
}

/// Twice the vector area of a polygon (Newell's method): its direction is
/// the normal of the counter-clockwise side, zero for a degenerate face.
fn newell_normal(corners: &[DVec3]) -> DVec3 {
    let origin = corners[0];
    let mut n = DVec3::ZERO;
    for (k, &a) in corners.iter().enumerate() {
        let b = corners[(k + 1) % corners.len()];
        n += (a - origin).cross(b - origin);
    }
    let extent = corners
        .iter()
        .map(|p| (*p - origin).length_squared())
        .fold(0.0, f64::max);
    if n.length_squared() <= 1e-24 * extent * extent {
        DVec3::ZERO
    } else {
        n
    }
}

/// The flat colour of a face whose visible side has unit normal `seen`.
fn shade(seen: DVec3, back: bool, cam: &Camera) -> Rgba {
    let light = AMBIENT
        + KEY * seen.dot(cam.key_light()).max(0.0)
        + FILL * seen.dot(cam.fill_light()).max(0.0);
    let base = if back { BACK_BASE } else { FRONT_BASE };
    let c = (base * light.clamp(0.0, 1.0).powf(GAMMA)).clamp(DVec3::ZERO, DVec3::ONE) * 255.0;
    Rgba(c.x.round() as u8, c.y.round() as u8, c.z.round() as u8, 255)
}

/// The width of edge strokes: thin, growing slowly with the image.
fn edge_width(view: &MeshView) -> f64 {
    (view.width.min(view.height) as f64 / 800.0).clamp(0.6, 3.0)
}

/// The width of the seam-closing stroke drawn in the face colour when the
/// wireframe is off, so antialiased neighbours leave no light cracks.
const SEAM_WIDTH: f64 = 0.7;

/// Renders the mesh as a PNG image.
pub fn render_png(soup: &PolygonSoup, view: &MeshView) -> Result<Vec<u8>, RenderError> {
    validate(soup, view)?;
    let mut pm = Pixmap::new(view.width, view.height)
        .ok_or_else(|| error("cannot allocate an image of that size"))?;
    let b = view.background;
    pm.fill(Color::from_rgba8(b.0, b.1, b.2, b.3));
    let edge_stroke = stroke(if view.wireframe {
        edge_width(view)
    } else {
        SEAM_WIDTH
    });
    for face in shaded_faces(soup, view) {
        paint_face(&mut pm, &face, view.wireframe, &edge_stroke);
    }
    pm.encode_png()
        .map_err(|e| error(format!("cannot encode the PNG: {e}")))
}

/// Fills one face and strokes its outline (edges, or the seam closer).
fn paint_face(pm: &mut Pixmap, face: &Shaded, wireframe: bool, edge_stroke: &Stroke) {
    let mut pb = PathBuilder::new();
    pb.move_to(face.points[0].x as f32, face.points[0].y as f32);
    for p in &face.points[1..] {
        pb.line_to(p.x as f32, p.y as f32);
    }
    pb.close();
    let Some(path) = pb.finish() else {
        return;
    };
    let id = tiny_skia::Transform::identity();
    pm.fill_path(&path, &paint(face.fill), FillRule::EvenOdd, id, None);
    let outline = if wireframe { EDGE } else { face.fill };
    pm.stroke_path(&path, &paint(outline), edge_stroke, id, None);
}

fn stroke(width: f64) -> Stroke {
    Stroke {
        width: width as f32,
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    }
}

/// Renders the mesh as an SVG document that looks like the PNG: one
/// `<polygon>` per drawable face, back to front. It does not check its
/// input (see [`validate`]): faces that cannot be drawn are left out, and a
/// view with an unusable direction is drawn from the default one.
pub fn render_svg(soup: &PolygonSoup, view: &MeshView) -> String {
    let (w, h) = (view.width, view.height);
    let mut doc = Document::new()
        .set("width", w)
        .set("height", h)
        .set("viewBox", format!("0 0 {w} {h}"));
    let b = view.background;
    if b.3 > 0 {
        doc = doc.add(
            Rectangle::new()
                .set("width", "100%")
                .set("height", "100%")
                .set("fill", b.hex())
                .set("fill-opacity", num(b.3 as f64 / 255.0)),
        );
    }
    let (outline_width, wireframe) = if view.wireframe {
        (edge_width(view), true)
    } else {
        (SEAM_WIDTH, false)
    };
    for face in shaded_faces(soup, view) {
        let outline = if wireframe { EDGE } else { face.fill };
        doc = doc.add(
            Polygon::new()
                .set("points", points_attr(&face.points))
                .set("fill", face.fill.hex())
                .set("stroke", outline.hex())
                .set("stroke-width", num(outline_width))
                .set("stroke-linejoin", "round"),
        );
    }
    doc.to_string()
}

/// "x1,y1 x2,y2 ..." with at most two decimals.
fn points_attr(points: &[DVec2]) -> String {
    let mut s = String::with_capacity(points.len() * 14);
    for (k, p) in points.iter().enumerate() {
        let sep = if k == 0 { "" } else { " " };
        let _ = write!(s, "{sep}{},{}", num(p.x), num(p.y));
    }
    s
}

/// A number with at most two decimals and no trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{x:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}
