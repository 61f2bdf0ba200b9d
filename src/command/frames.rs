//! Frames of an animation: a system run once, one picture per step (or
//! per frame of the model's `.a` file), every frame seen by one camera,
//! as data (`render -o growth.gif` encodes them; `serve` plays them).

use std::time::Duration;

use glam::{DVec2, Vec3};

use super::picture::{picture_bytes, MeshLooks, Picture};
use super::render::Solidity;
use crate::error::Error;
use crate::mesh::PolygonSoup;
use crate::render::raster::{Image, RasterOptions};
use crate::render::{self, Rgba, Scene, View};
use crate::scene3::Scene3;
use crate::system::{Progress, RunOptions, System};

/// The most frames one animation makes.
pub const MAX_FRAMES: usize = 1000;

/// The most pixels all the frames of one animation hold together: 2 GiB
/// of RGBA.
pub const MAX_FRAME_PIXELS: u64 = (2 << 30) / 4;

/// How [`frames`] runs a system and draws its frames.
#[derive(Clone, Debug)]
pub struct FrameOptions {
    /// The run: `steps` is the last step (else the program's derivation
    /// length), with the seed, the module limit and the deadline, which
    /// covers the drawing too.
    pub run: RunOptions,
    /// Width and height of every frame in pixels.
    pub size: (u32, u32),
    /// The background; `None`: the model's colour 0 (L-systems), else
    /// white.
    pub background: Option<Rgba>,
    /// L-systems: 2D lines or shaded 3D geometry (see [`Solidity`]).
    pub solid: Solidity,
    /// L-systems in 2D: `xy`, `xz` or `yz`; in 3D and meshes: a mesh
    /// view's name (`iso`, `front`, …). `None`: `xy`, or the view file's
    /// camera, or `iso` for meshes.
    pub view: Option<String>,
    /// Meshes: the edges drawn over the faces.
    pub wireframe: bool,
    /// Meshes: one flat shade per face instead of smooth shading.
    pub flat: bool,
    /// Which steps are frames; `None`: the model's animation file (`.a`)
    /// where it has one, else every step 0..=N.
    pub selection: Option<FrameSelection>,
    /// L-systems in 3D: geometry for a viewer or a file (the live page's
    /// playback), with pixel-wide lines as whole tubes and no thin lines,
    /// which only the z-buffer draws.
    pub viewer: bool,
}

impl Default for FrameOptions {
    /// 800×800, the model's or a white background, lines or 3D as the
    /// model asks, wireframe on, smooth shading, the frames the model's
    /// `.a` chooses or every step.
    fn default() -> Self {
        FrameOptions {
            run: RunOptions::default(),
            size: (800, 800),
            background: None,
            solid: Solidity::Auto,
            view: None,
            wireframe: true,
            flat: false,
            selection: None,
            viewer: false,
        }
    }
}

/// The steps that are frames: `first`, `first + step`, … up to `last`
/// (and the run's last step), as lpfg's animation file has them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameSelection {
    pub first: u64,
    /// `None`: the run's last step.
    pub last: Option<u64>,
    /// At least 1.
    pub step: u64,
}

impl Default for FrameSelection {
    /// Every step.
    fn default() -> Self {
        FrameSelection {
            first: 0,
            last: None,
            step: 1,
        }
    }
}

impl FrameSelection {
    /// Whether step `n` is a frame.
    pub fn contains(&self, n: u64) -> bool {
        n >= self.first
            && self.last.is_none_or(|l| n <= l)
            && (n - self.first).is_multiple_of(self.step.max(1))
    }
}

/// One frame's geometry, laid out with the animation's camera.
#[derive(Clone, Debug)]
pub enum FrameGeometry {
    /// A 2D drawing in pixels (an L-system's lines): PNG or SVG through
    /// [`crate::render::png`] and [`crate::render::svg`].
    Flat(Scene),
    /// Shaded 3D geometry (an L-system's tubes and surfaces, a grammar's or
    /// a vv program's mesh) and the z-buffer's settings; every frame's
    /// [`RasterOptions::camera`] is the same.
    Solid(Box<SolidFrame>),
}

/// A 3D frame: its geometry and how [`crate::render::raster`] draws it.
#[derive(Clone, Debug)]
pub struct SolidFrame {
    pub scene: Scene3,
    pub raster: RasterOptions,
}

impl SolidFrame {
    /// Whether the frame has nothing to draw (a plant before its first
    /// line): its picture is the background.
    pub fn is_empty(&self) -> bool {
        self.scene.triangle_count() == 0 && self.scene.line_count() == 0
    }
}

/// One frame: the step it shows and its geometry.
#[derive(Clone, Debug)]
pub struct Frame {
    pub step: u64,
    pub geometry: FrameGeometry,
}

impl Frame {
    /// The frame as a picture file's bytes (PNG or SVG).
    pub fn picture(&self, format: Picture) -> Result<Vec<u8>, Error> {
        Ok(match (&self.geometry, format) {
            (FrameGeometry::Flat(scene), format) => picture_bytes(scene, format)?,
            (FrameGeometry::Solid(s), format) if s.is_empty() => {
                // A step with nothing drawn yet: the background.
                let (width, height) = self.size();
                let blank = Scene {
                    width,
                    height,
                    background: s.raster.background,
                    items: Vec::new(),
                };
                picture_bytes(&blank, format)?
            }
            (FrameGeometry::Solid(s), Picture::Png) => {
                render::raster::render_png(&s.scene, &s.raster)?
            }
            (FrameGeometry::Solid(s), Picture::Svg) => {
                render::raster::render_svg(&s.scene, &s.raster)?.into_bytes()
            }
        })
    }

    /// The frame's pixels (premultiplied RGBA), as its PNG shows them.
    pub fn image(&self) -> Result<Image, Error> {
        Ok(match &self.geometry {
            FrameGeometry::Flat(scene) => render::png::image(scene)?,
            FrameGeometry::Solid(s) if s.is_empty() => {
                // A step with nothing drawn yet: the background.
                let (w, h) = self.size();
                let Rgba(r, g, b, a) = s.raster.background;
                let pre = |c: u8| ((c as u32 * a as u32 + 127) / 255) as u8;
                Image {
                    width: w,
                    height: h,
                    pixels: [pre(r), pre(g), pre(b), a].repeat(w as usize * h as usize),
                }
            }
            FrameGeometry::Solid(s) => render::raster::render(&s.scene, &s.raster)?,
        })
    }

    /// The frame's size in pixels.
    pub fn size(&self) -> (u32, u32) {
        match &self.geometry {
            FrameGeometry::Flat(s) => (s.width, s.height),
            FrameGeometry::Solid(s) => (s.raster.camera.width, s.raster.camera.height),
        }
    }
}

/// The frames of a run, and how the model's animation file says to show
/// them.
#[derive(Clone, Debug)]
pub struct Frames {
    pub frames: Vec<Frame>,
    /// The time between frames that the animation file's `swap interval:`
    /// gives (`None` without one, or 0).
    pub interval: Option<Duration>,
    /// What the animation file asks that the frames do not do (warnings
    /// for the user).
    pub notes: Vec<String>,
}

/// Runs `system` once and draws one frame per step, 0 (the axiom, the
/// base mesh after `init:`, a vv program's mesh after `Start`) to the
/// last (`opts.run.steps`, else the program's derivation length), or per
/// frame that `opts.selection` or the model's `.a` file chooses, all with
/// one camera:
///
/// - an L-system drawn in 2D: every frame laid out in the union of the
///   frames' boxes (a drawing that only grows: the last step's), or the
///   view file's `box:` projected on the view's plane; with the `.a`
///   file's `scale between frames: on`, each frame in its own box;
/// - an L-system drawn in 3D: the view file's camera fitted to the union
///   of the frames' bounds (or its `box:`), its lights;
/// - a surface grammar (one frame per subdivision level) or a vv program
///   (one per step): the mesh's tight fit of every frame's vertices;
/// - a shape grammar: a usage error (its shapes have no steps).
///
/// `progress` hears after each derivation step. The run stops at
/// `opts.run.deadline` (as does the drawing), and the frames are refused
/// before any is drawn when they are more than [`MAX_FRAMES`] or hold
/// more than [`MAX_FRAME_PIXELS`] pixels. The frames' geometry is kept
/// until all are drawn (the common camera needs them all): memory is the
/// sum of the selected steps' drawings, each within the run's limits.
pub fn frames(
    system: &System,
    opts: &FrameOptions,
    mut progress: impl FnMut(Progress),
) -> Result<Frames, Error> {
    // The readers and the z-buffer look at the thread's deadline.
    let _scope = opts.run.deadline.map(|d| crate::deadline::scope(Some(d)));
    match system {
        System::Curve(c) => curve_frames(c, opts, &mut progress),
        System::Surface(s) => {
            let selection = opts.selection.unwrap_or_default();
            let mut soups = Vec::new();
            s.subdivide_each(&opts.run, &mut progress, |step, mesh| {
                if selection.contains(step as u64) {
                    check_count(soups.len() + 1, opts.size)?;
                    let (soup, sharp) = mesh.to_soup_with_sharpness(false);
                    let sharp = sharp.edges.iter().map(|&(a, b, _)| (a, b)).collect();
                    soups.push((step as u64, soup, sharp));
                }
                Ok(())
            })?;
            mesh_frames(soups, opts, false)
        }
        System::Vv(v) => {
            let selection = opts.selection.unwrap_or_default();
            let mut soups = Vec::new();
            let run = v.run_each(
                &opts.run,
                &mut progress,
                |step| selection.contains(step),
                |step, soup| soups.push((step, soup, Vec::new())),
            )?;
            check_count(soups.len(), opts.size)?;
            // The last step's mesh as `End` leaves it (what `render`
            // draws).
            if let Some(last) = soups.last_mut().filter(|(s, ..)| *s == run.steps) {
                last.1 = run.soup;
            }
            // A sheet of cells at the end: its cells in colours all along.
            let cells = soups
                .last()
                .is_some_and(|(_, s, _)| crate::render::mesh::has_cells(s));
            mesh_frames(soups, opts, cells)
        }
        System::Shapes(_) => Err(Error::Usage(
            "a shape grammar has no steps to animate: it draws its terminal shapes once \
             (render it to .png or .svg)"
                .into(),
        )),
    }
}

/// Refuses more than [`MAX_FRAMES`] frames of `size`, or more than
/// [`MAX_FRAME_PIXELS`] pixels in all.
fn check_count(frames: usize, (w, h): (u32, u32)) -> Result<(), Error> {
    let pixels = frames as u64 * w as u64 * h as u64;
    if frames > MAX_FRAMES || pixels > MAX_FRAME_PIXELS {
        return Err(Error::Usage(format!(
            "{frames} frames of {w}x{h} pixels are too many: an animation has at most {MAX_FRAMES} \
             frames and {} GiB of pixels; choose fewer steps (-n, or `step:` in the model's .a \
             file) or a smaller --size",
            (MAX_FRAME_PIXELS * 4) >> 30
        )));
    }
    Ok(())
}

/// The selection and the notes of an L-system's animation file.
fn curve_selection(
    c: &crate::Curve,
    opts: &FrameOptions,
) -> (FrameSelection, Option<Duration>, bool, Vec<String>) {
    let model = c.model();
    let mut notes = Vec::new();
    let Some(a) = model.animation.as_ref() else {
        return (opts.selection.unwrap_or_default(), None, false, notes);
    };
    let selection = opts.selection.unwrap_or(FrameSelection {
        first: a.first_frame,
        last: a.last_frame,
        step: a.step,
    });
    let interval =
        (a.swap_interval > 0.0).then(|| Duration::from_secs_f64(a.swap_interval / 100.0));
    let name = model
        .files
        .iter()
        .find(|f| f.extension().is_some_and(|e| e == "a"))
        .map_or("the animation file".to_string(), |f| {
            f.display().to_string()
        });
    if a.hcenter_between_frames && !a.scale_between_frames {
        notes.push(format!(
            "{name}: warning: `hcenter between frames: on` is not followed: the frames share one camera"
        ));
    }
    if !a.clear_between_frames {
        notes.push(format!(
            "{name}: warning: `clear between frames: off` is not followed: each frame is drawn on its own"
        ));
    }
    if a.display_on_request {
        notes.push(format!(
            "{name}: warning: `display on request: on` is not followed: every frame of `step:` is drawn"
        ));
    }
    (selection, interval, a.scale_between_frames, notes)
}

/// An L-system's frames, in 2D or 3D as `render` would draw it.
fn curve_frames(
    c: &crate::Curve,
    opts: &FrameOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Frames, Error> {
    let (selection, interval, each_fitted, notes) = curve_selection(c, opts);
    let model = c.model();
    let model_background = model.background().map(|[r, g, b]| Rgba(r, g, b, 255));
    let background = opts
        .background
        .or(model_background)
        .unwrap_or(Rgba(255, 255, 255, 255));
    let mut figure = crate::curve::FigureOptions {
        derive: opts.run.derive_options(),
        ..Default::default()
    };
    let on_step = &mut |d: &crate::rewrite::Derivation| progress(Progress::of_derivation(d));
    let p = &c.program;
    // Frames past the limits stop the run at once: the drawing callback
    // fails, and the run's error is replaced by the limit's.
    let refused = std::cell::RefCell::new(None);
    let mut count = 0;
    let mut admit = || {
        count += 1;
        check_count(count, opts.size).map_err(|e| {
            *refused.borrow_mut() = Some(e);
            too_many()
        })
    };
    let frames = if super::render::wants_solid(opts.solid, c) {
        // The interpreted words of the frames, each walked once for its
        // lines' box (a word the turtle cannot draw fails here, with the
        // production that made its module); the geometry once the scale
        // of the whole animation is known.
        let words = c
            .each_step(
                &figure,
                |step, word, draw_opts| {
                    if !selection.contains(step) {
                        return Ok(None);
                    }
                    admit()?;
                    let lines = crate::draw::line_bounds(word, &p.alphabet, &p.structs, draw_opts)?;
                    Ok(Some((step, word.clone(), draw_opts.clone(), lines)))
                },
                on_step,
            )
            .map_err(|e| refused.take().unwrap_or(e))?;
        check_count(words.len(), opts.size)?;
        solid_curve_frames(c, words, opts, background, each_fitted)?
    } else {
        let view = match opts.view.as_deref().unwrap_or("xy") {
            "xy" => View::Xy,
            "xz" => View::Xz,
            "yz" => View::Yz,
            other => {
                return Err(Error::Usage(format!(
                    "`--view {other}` is not a view of an L-system: use xy, xz or yz"
                )))
            }
        };
        figure.render = render::RenderOptions {
            width: opts.size.0,
            height: opts.size.1,
            background,
            view,
            palette: model
                .palette()
                .map(|p| std::sync::Arc::new(p.map(|[r, g, b]| Rgba(r, g, b, 255)))),
            widths_in_units: model.widths_in_units,
            ..Default::default()
        };
        let drawn = c
            .each_step(
                &figure,
                |step, word, draw_opts| {
                    if !selection.contains(step) {
                        return Ok(None);
                    }
                    admit()?;
                    let events = crate::draw::draw(word, &p.alphabet, &p.structs, draw_opts)?;
                    Ok(Some((step, events)))
                },
                on_step,
            )
            .map_err(|e| refused.take().unwrap_or(e))?;
        check_count(drawn.len(), opts.size)?;
        flat_frames(drawn, &figure.render, model.camera.bbox, each_fitted)?
    };
    if frames.is_empty() {
        return Err(no_frames(selection));
    }
    Ok(Frames {
        frames,
        interval,
        notes,
    })
}

/// The error a drawing callback returns to stop a run with too many
/// frames (replaced by [`check_count`]'s message).
fn too_many() -> crate::draw::DrawError {
    crate::draw::DrawError {
        message: "too many frames".into(),
        module: None,
    }
}

fn no_frames(selection: FrameSelection) -> Error {
    Error::Usage(format!(
        "no step is a frame: the first frame is step {}{}, after the run's last step",
        selection.first,
        selection
            .last
            .map_or(String::new(), |l| format!(" and the last {l}"))
    ))
}

/// 2D frames laid out in one box: the view file's `box:`, else the union
/// of the frames' own (each its own with `each_fitted`).
fn flat_frames(
    drawn: Vec<(u64, Vec<crate::draw::Event>)>,
    ropts: &render::RenderOptions,
    bbox: Option<[f64; 6]>,
    each_fitted: bool,
) -> Result<Vec<Frame>, Error> {
    let mut boxes = Vec::with_capacity(drawn.len());
    for (_, events) in &drawn {
        boxes.push(render::bounds(events, ropts.view)?);
    }
    let union = boxes
        .iter()
        .flatten()
        .copied()
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
    let Some(union) = union else {
        return Err(Error::Failed(
            "nothing to draw: after interpretation no frame's word has drawing modules (F, LineTo2f, Circle, ...)"
                .into(),
        ));
    };
    let given = bbox.map(|b| {
        let lo = glam::DVec3::new(b[0], b[2], b[4]);
        let hi = glam::DVec3::new(b[1], b[3], b[5]);
        let project = |p: glam::DVec3| match ropts.view {
            View::Xy => DVec2::new(p.x, p.y),
            View::Xz => DVec2::new(p.x, p.z),
            View::Yz => DVec2::new(p.y, p.z),
        };
        (project(lo).min(project(hi)), project(lo).max(project(hi)))
    });
    drawn
        .into_iter()
        .zip(boxes)
        .map(|((step, events), own)| {
            let within = match (given, each_fitted, own) {
                (Some(b), _, _) => b,
                (None, true, Some(own)) => own,
                _ => union,
            };
            let scene = render::scene_within(&events, within, ropts)?;
            Ok(Frame {
                step,
                geometry: FrameGeometry::Flat(scene),
            })
        })
        .collect()
}

/// A frame's step, its interpreted word, the turtle's settings and the box
/// of its lines.
type StepWord = (
    u64,
    crate::rewrite::Word,
    crate::draw::DrawOptions,
    Option<(glam::DVec3, glam::DVec3)>,
);

/// An L-system's frames in 3D: tubes for pixel-wide lines as wide as a
/// pixel at the animation's scale, the view file's camera fitted to all
/// frames (or each, with `each_fitted`).
fn solid_curve_frames(
    c: &crate::Curve,
    words: Vec<StepWord>,
    opts: &FrameOptions,
    background: Rgba,
    each_fitted: bool,
) -> Result<Vec<Frame>, Error> {
    use crate::draw::solid::SolidOptions;
    use crate::model::view::LineStyle;
    let model = c.model();
    let p = &c.program;
    let (w, h) = opts.size;
    let mut sopts = SolidOptions::default();
    if model.line_style == LineStyle::Pixel {
        let extent = words
            .iter()
            .filter_map(|(.., b)| *b)
            .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)))
            .map_or(f64::NAN, |(lo, hi)| (hi - lo).max_element());
        let units_per_pixel = crate::draw::solid::pixel_of(extent, 0.9 * w.min(h) as f64);
        sopts.pixel_tubes = Some(units_per_pixel);
        if !opts.viewer {
            sopts.picture_pixel = Some(units_per_pixel);
        }
    }
    let mut scenes = Vec::with_capacity(words.len());
    for (step, word, draw_opts, _) in words {
        crate::deadline::check(crate::deadline::current()).map_err(Error::Failed)?;
        let scene = crate::draw::solid::solid(&word, &p.alphabet, &p.structs, &draw_opts, &sopts)
            .map_err(|e| c.drawing_error(e, step))?;
        scenes.push((step, scene));
    }
    let mut camera = model.camera.clone();
    if let Some(name) = opts.view.as_deref().filter(|v| *v != "xy") {
        let Some((d, u)) = crate::render::mesh::view_direction(name) else {
            return Err(Error::Usage(format!(
                "`--view {name}` is not a view of a 3D drawing: use xy (the view file's), iso, front, back, left, right, top or bottom"
            )));
        };
        // The mesh views are named for z up; a plant grows along y.
        let y_up = |v: glam::DVec3| [v.x, v.z, -v.y];
        camera.dir = Some(y_up(d));
        camera.up = Some(y_up(u));
    }
    let union = scenes
        .iter()
        .filter_map(|(_, s)| s.bounds())
        .reduce(|(a, b), (c, d)| (a.min(c), b.max(d)));
    if union.is_none() && model.camera.bbox.is_none() {
        return Err(Error::Failed(
            "nothing to draw: the turtle made no 3D geometry in any frame (no lines, surfaces, polygons or spheres)"
                .into(),
        ));
    }
    let common = camera.raster_options(&model.lights, union, w, h)?;
    scenes
        .into_iter()
        .map(|(step, scene)| {
            let mut raster = match scene.bounds() {
                Some(own) if each_fitted => {
                    camera.raster_options(&model.lights, Some(own), w, h)?
                }
                _ => common.clone(),
            };
            raster.background = background;
            Ok(Frame {
                step,
                geometry: FrameGeometry::Solid(Box::new(SolidFrame { scene, raster })),
            })
        })
        .collect()
}

/// A mesh's frames (a surface grammar's levels with their sharp edges, a
/// vv program's steps): the tight fit of every frame's vertices, the mesh
/// pictures' looks, with `cells` each face in a colour.
#[allow(clippy::type_complexity)]
fn mesh_frames(
    soups: Vec<(u64, PolygonSoup, Vec<(u32, u32)>)>,
    opts: &FrameOptions,
    cells: bool,
) -> Result<Frames, Error> {
    let looks = MeshLooks {
        size: opts.size,
        background: opts.background.unwrap_or(Rgba(255, 255, 255, 255)),
        view: opts.view.as_deref(),
        wireframe: opts.wireframe,
        shading: crate::render::mesh::Shading::Lit,
        flat: opts.flat,
        cells,
    };
    let view = looks.view_of(soups.iter().map(|(_, s, _)| s))?;
    if soups.is_empty() {
        return Err(no_frames(opts.selection.unwrap_or_default()));
    }
    for (_, soup, _) in &soups {
        crate::render::mesh::validate(soup, &view)?;
    }
    let mut points = soups.iter().flat_map(|(_, soup, _)| {
        soup.faces
            .iter()
            .flatten()
            .filter_map(|&i| soup.positions.get(i as usize))
            .map(|p| p.as_vec3())
    });
    let camera = crate::render::mesh::camera(&view, &mut points as &mut dyn Iterator<Item = Vec3>)?;
    let frames = soups
        .into_iter()
        .map(|(step, soup, sharp)| {
            let mut view = view.clone();
            view.sharp_edges = sharp;
            if cells {
                view.face_colours = crate::render::mesh::cell_colours(&soup);
            }
            let (scene, polygons, back) = crate::render::mesh::scene3(&soup, &view);
            let raster = crate::render::mesh::raster_options_with(camera, &view, polygons, back);
            Frame {
                step,
                geometry: FrameGeometry::Solid(Box::new(SolidFrame { scene, raster })),
            }
        })
        .collect();
    Ok(Frames {
        frames,
        interval: None,
        notes: Vec::new(),
    })
}
