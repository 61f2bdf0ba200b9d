//! `subgram render`: an L-system's 2D figures or shaded 3D geometry, a
//! grammar's or vv program's mesh, or a mesh file, as a picture or a 3D
//! export; `render_edited`, the same in memory for `serve`.

use std::path::{Path, PathBuf};
use std::time::Duration;

use super::animate::{self, Animated};
use super::common::{
    as_paths, check_steps, extension_hint, in_run, load_options, refuse_overwrite,
    write_program_files, writes_folder,
};
use super::frames::FrameOptions;
use super::picture::{
    picture_bytes, write_mesh_picture, write_soup_picture, write_views, MeshLooks, Out, Picture,
};
use super::subdivide::{subdivide_in_run, write_shapes_picture, SubdivideArgs};
use crate::curve::FigureOptions;
use crate::deadline::{Deadline, DEFAULT_TIMEOUT};
use crate::error::Error;
use crate::lang::ProgramOutput;
use crate::load::load;
use crate::mesh;
use crate::render::{self, Rgba, View};
use crate::rewrite::derive::DEFAULT_MAX_MODULES;
use crate::system::{load_mesh, Progress, RunOptions, System};

/// The arguments of `subgram render`.
#[derive(Clone, Debug)]
pub struct RenderArgs {
    /// An `.lsys` file, or a mesh (`.obj`, `.off`, `.ply`) to draw as it is.
    pub file: String,
    /// The picture: `.png` or `.svg`.
    pub output: String,
    pub steps: Option<u64>,
    /// Width and height in pixels; `None`: 800×800, and with `each` the
    /// height the panels' drawings need.
    pub size: Option<(u32, u32)>,
    /// Draw every step 0..=N side by side (curves).
    pub each: bool,
    /// The background; `None`: colour 0 of the model's colour map or
    /// material 0's emission when the program comes with one, else white.
    pub background: Option<Rgba>,
    /// L-systems: draw the turtle's lines in 2D, or its 3D geometry shaded
    /// (tubes, surfaces, generalized cylinders); by default 3D when the
    /// model's view file asks for it.
    pub solid: Solidity,
    /// Curves: xy (the default), xz or yz. Meshes: iso, front, back, left,
    /// right, top or bottom.
    pub view: Option<String>,
    /// Meshes: draw the edges over the faces.
    pub wireframe: bool,
    /// Meshes: one flat shade per face (by default smooth, from vertex
    /// normals).
    pub flat: bool,
    /// Animations (`.gif`, `.png` with `{n}`…): frames a second; `None`:
    /// the model's `swap interval:`, else [`DEFAULT_FPS`].
    pub fps: Option<f64>,
    pub defines: Vec<String>,
    /// `--double`: `float` in double precision instead of lpfg's single.
    pub double: bool,
    pub max_modules: usize,
    pub phase: usize,
    /// `--seed`: seeds every random number generator (see
    /// [`RunOptions::seed`]).
    pub seed: Option<u32>,
    /// `--timeout`: the command stops with an error after this long.
    pub timeout: Option<Duration>,
    /// Write the picture even over one of the inputs.
    pub force: bool,
    /// `--allow-writes DIR`: the program may write files, under DIR.
    pub allow_writes: Option<PathBuf>,
    /// What the program prints: the caller keeps a clone and prints it.
    pub program_output: ProgramOutput,
    /// How a model's environmental program runs (`--clean-ea20`,
    /// `--env-process`, `--env-timeout`).
    pub environment: crate::enviro::Options,
}

impl RenderArgs {
    pub fn new(file: impl Into<String>, output: impl Into<String>) -> RenderArgs {
        RenderArgs {
            solid: Solidity::Auto,
            file: file.into(),
            output: output.into(),
            steps: None,
            size: None,
            each: false,
            background: None,
            view: None,
            wireframe: true,
            flat: false,
            fps: None,
            defines: Vec::new(),
            double: false,
            max_modules: DEFAULT_MAX_MODULES,
            phase: 0,
            seed: None,
            timeout: Some(DEFAULT_TIMEOUT),
            force: false,
            allow_writes: None,
            program_output: ProgramOutput::default(),
            environment: Default::default(),
        }
    }
}

/// Frames a second of an animation when neither `--fps` nor the model's
/// `swap interval:` says.
pub const DEFAULT_FPS: f64 = 4.0;

/// How `render` draws an L-system.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Solidity {
    /// 3D when the model's view file asks for tubes (`line style:
    /// cylinder` or `polygon`) or shading (`render mode: shaded`), or the
    /// output is a 3D file; else the 2D line drawing.
    #[default]
    Auto,
    /// The 2D line drawing.
    Lines,
    /// The shaded 3D geometry.
    Solid,
}

/// `subgram render`: a curve's picture, a surface grammar's subdivided
/// mesh, or a mesh file, as PNG or SVG. Returns the program's warnings.
pub fn render(a: &RenderArgs, progress: impl FnMut(Progress)) -> Result<Vec<String>, Error> {
    in_run(a.timeout, Some(a.force), || render_in_run(a, progress))
}

fn render_in_run(a: &RenderArgs, progress: impl FnMut(Progress)) -> Result<Vec<String>, Error> {
    let deadline = crate::deadline::current();
    let file = Path::new(&a.file);
    let output = Path::new(&a.output);
    refuse_overwrite(&[output], &[file], a.force)?;
    if let Some(format) = Animated::from_path(output)? {
        return animate(a, format, deadline, progress);
    }
    let looks = MeshLooks::of_render(a);
    if mesh::io::Format::from_path(file).is_some() {
        // Found before the mesh is read.
        Picture::from_path(output).map_err(|_| {
            Error::Usage(format!(
                "cannot tell the format of `{}`: render draws a mesh as a picture (.png, .svg); \
                 `subgram mesh convert` writes it as a mesh{}",
                output.display(),
                extension_hint(output, &["png", "svg"])
            ))
        })?;
        write_mesh_picture(&load_mesh(file)?, output, &looks, &mut Out::Files)?;
        return Ok(Vec::new());
    }
    // A 3D file (.obj, .ply, .glb) is an L-system's geometry exported.
    let format = match crate::export::Format::from_path(output) {
        Some(_) => Picture::Png,
        None => Picture::from_path(output).map_err(|_| {
            Error::Usage(format!(
                "cannot tell the format of `{}`: render writes pictures (.png, .svg), animations \
                 (.gif, .apng) and 3D geometry (.obj, .ply, .glb){}",
                output.display(),
                extension_hint(output, &["png", "svg", "gif", "apng", "obj", "ply", "glb"])
            ))
        })?,
    };
    let system = load(file, &load_options(&a.defines, a.double, &a.environment))?;
    let mut warnings = system.warnings();
    warnings.extend(render_system(
        a,
        system,
        (&looks, format),
        deadline,
        progress,
        &mut Out::Files,
    )?);
    Ok(warnings)
}

/// `render` to an animation (`.gif`, `.apng`) or to one still a frame
/// (`{n}` in a `.png` or `.svg` name): [`super::frames()`] encoded, and
/// every file written or none.
fn animate(
    a: &RenderArgs,
    format: Animated,
    deadline: Option<Deadline>,
    progress: impl FnMut(Progress),
) -> Result<Vec<String>, Error> {
    let file = Path::new(&a.file);
    let output = Path::new(&a.output);
    if mesh::io::Format::from_path(file).is_some() {
        return Err(Error::Usage(format!(
            "`{}` is a mesh: it has no steps to animate; render a grammar or an L-system, or \
             the mesh as a .png or .svg",
            file.display()
        )));
    }
    if a.each {
        return Err(Error::Usage(
            "--each draws the steps side by side in one picture; an animation shows them one \
             after the other: leave out --each"
                .into(),
        ));
    }
    if let Some(fps) = a.fps {
        animate::check_fps(fps)?;
    }
    if let Animated::Stills(_) = format {
        animate::check_folder(output)?;
    }
    check_steps(a.steps)?;
    let system = load(file, &load_options(&a.defines, a.double, &a.environment))?;
    let mut warnings = system.warnings();
    let dir = writes_folder(&a.allow_writes, &a.program_output)?;
    let opts = FrameOptions {
        run: RunOptions {
            steps: a.steps,
            max_modules: a.max_modules,
            phase: a.phase,
            seed: a.seed,
            base_mesh: None,
            deadline,
            output: a.program_output.clone(),
            max_shapes: None,
        },
        size: a.size.unwrap_or((800, 800)),
        background: a.background,
        solid: a.solid,
        view: a.view.clone(),
        wireframe: a.wireframe,
        flat: a.flat,
        selection: None,
        viewer: false,
    };
    let frames = super::frames::frames(&system, &opts, progress)?;
    warnings.extend(frames.notes.iter().cloned());
    let fps = match (a.fps, frames.interval) {
        (Some(fps), _) => fps,
        // lpfg's hundredths of a second; faster than a GIF shows, 100.
        (None, Some(t)) => (1.0 / t.as_secs_f64()).min(100.0),
        (None, None) => DEFAULT_FPS,
    };
    let files = animate::files(&frames, format, output, fps)?;
    let mut inputs = system.inputs();
    inputs.push(file.to_path_buf());
    let outputs: Vec<&Path> = files.iter().map(|(p, _)| p.as_path()).collect();
    refuse_overwrite(&outputs, &as_paths(&inputs), a.force)?;
    let mut all = as_paths(&inputs);
    all.extend(outputs.iter().copied());
    write_program_files(&a.program_output, dir.as_deref(), &all)?;
    Out::Files.put(files)?;
    Ok(warnings)
}

/// A picture computed in memory and not written: what `serve` shows.
#[derive(Clone, Debug)]
pub struct Drawn {
    /// The main picture's bytes (SVG or PNG, as `RenderArgs::output`'s
    /// extension says).
    pub picture: Vec<u8>,
    /// The program's warnings.
    pub warnings: Vec<String>,
}

/// Renders as [`render()`] does, with the program's text replaced by `text`
/// (see [`crate::load_edited`]), and writes nothing: the picture
/// comes back in memory. A program's own files (`fopen`) are refused as
/// without `--allow-writes`.
pub fn render_edited(a: &RenderArgs, text: &str) -> Result<Drawn, Error> {
    let deadline = a.timeout.map(Deadline::after);
    // The files the program reads are read under the deadline too.
    let _deadline = crate::deadline::scope(deadline);
    let file = Path::new(&a.file);
    let output = Path::new(&a.output);
    let looks = MeshLooks::of_render(a);
    let format = Picture::from_path(output)?;
    let system = crate::load::load_edited(
        file,
        text,
        &load_options(&a.defines, a.double, &a.environment),
    )?;
    let mut warnings = system.warnings();
    let mut a = a.clone();
    a.allow_writes = None;
    a.force = true;
    let (picture, more) = picture_in_memory(&a, system, (&looks, format), deadline)?;
    warnings.extend(more);
    Ok(Drawn { picture, warnings })
}

/// The main picture `render_system` draws, in memory, and the program's
/// warnings; an error when nothing was drawn.
pub(super) fn picture_in_memory(
    a: &RenderArgs,
    system: System,
    looks: (&MeshLooks, Picture),
    deadline: Option<Deadline>,
) -> Result<(Vec<u8>, Vec<String>), Error> {
    let mut out = Out::Memory(Vec::new());
    let warnings = render_system(a, system, looks, deadline, |_| {}, &mut out)?;
    let mut files = match out {
        Out::Memory(files) => files,
        Out::Files => Vec::new(),
    };
    if files.is_empty() {
        return Err(Error::Failed("nothing was drawn".into()));
    }
    Ok((files.swap_remove(0).1, warnings))
}

fn render_system(
    a: &RenderArgs,
    system: System,
    (looks, format): (&MeshLooks, Picture),
    deadline: Option<Deadline>,
    progress: impl FnMut(Progress),
    out: &mut Out,
) -> Result<Vec<String>, Error> {
    let output = Path::new(&a.output);
    let file = Path::new(&a.file);
    let white = Rgba(255, 255, 255, 255);
    let export = crate::export::Format::from_path(output);
    if export.is_some() && !matches!(system, System::Curve(_)) {
        // A grammar's or a vv program's mesh, or a shape grammar's
        // shapes: written as `subdivide` writes them.
        if a.each {
            return Err(Error::Usage(
                "--each draws the steps of an L-system side by side; it writes no 3D file".into(),
            ));
        }
        if a.allow_writes.is_some() {
            return Err(Error::Usage(format!(
                "--allow-writes: `{}` is written as `subdivide` writes a grammar's mesh, which \
                 writes no program files; render to a picture to keep the program's files",
                output.display()
            )));
        }
        let sa = SubdivideArgs {
            mesh: None,
            grammar: a.file.clone(),
            steps: a.steps,
            output: a.output.clone(),
            defines: a.defines.clone(),
            view: None,
            shading: None,
            no_wireframe: false,
            seed: a.seed,
            timeout: a.timeout,
            force: a.force,
            limit: false,
            fvar_linear: None,
            no_uvs: false,
            program_output: a.program_output.clone(),
        };
        return subdivide_in_run(&sa, progress);
    }
    match system {
        System::Surface(s) => {
            looks.check()?;
            let opts = RunOptions {
                steps: a.steps,
                deadline,
                ..RunOptions::default()
            };
            let run = s.subdivide(&opts, progress)?;
            write_mesh_picture(&run.mesh, output, looks, out)?;
            Ok(Vec::new())
        }
        System::Shapes(s) => {
            looks.check()?;
            if a.each {
                return Err(Error::Usage(
                    "--each draws the steps of an L-system side by side; a shape grammar draws \
                     its terminal shapes"
                        .into(),
                ));
            }
            let opts = RunOptions {
                seed: a.seed,
                deadline,
                ..RunOptions::default()
            };
            let run = s.derive(&opts)?;
            write_shapes_picture(&run, output, looks, out)?;
            Ok(Vec::new())
        }
        System::Vv(v) => {
            looks.check()?;
            if a.each {
                return Err(Error::Usage(
                    "--each draws the steps of an L-system side by side; a vv program draws its \
                     mesh after the last step (`-n` chooses it)"
                        .into(),
                ));
            }
            let dir = writes_folder(&a.allow_writes, &a.program_output)?;
            let opts = RunOptions {
                steps: a.steps,
                seed: a.seed,
                deadline,
                output: a.program_output.clone(),
                ..RunOptions::default()
            };
            let run = v.run(&opts, progress)?;
            let mut inputs = vec![file.to_path_buf(), output.to_path_buf()];
            inputs.extend(v.base_mesh());
            write_program_files(&a.program_output, dir.as_deref(), &as_paths(&inputs))?;
            write_soup_picture(&run.soup, output, &looks.for_vv(&run.soup), out)?;
            Ok(Vec::new())
        }
        System::Curve(c) if export.is_some() || wants_solid(a.solid, &c) => {
            render_solid(a, &c, (looks, format), deadline, progress, out)
        }
        System::Curve(c) => {
            let view = match a.view.as_deref().unwrap_or("xy") {
                "xy" => View::Xy,
                "xz" => View::Xz,
                "yz" => View::Yz,
                other => {
                    return Err(Error::Usage(format!(
                        "`--view {other}` is not a view of an L-system: use xy, xz or yz"
                    )))
                }
            };
            let (opts, dir) = curve_run(a, deadline)?;
            let model = &*crate::model::of(&c.program);
            let palette = model
                .palette()
                .map(|p| std::sync::Arc::new(p.map(|[r, g, b]| Rgba(r, g, b, 255))));
            let model_background = model.background().map(|[r, g, b]| Rgba(r, g, b, 255));
            let figure = FigureOptions {
                derive: opts.derive_options(),
                each: a.each,
                draw: Default::default(),
                render: render::RenderOptions {
                    width: a.size.map_or(800, |s| s.0),
                    height: a.size.map_or(800, |s| s.1),
                    fit_height: a.each && a.size.is_none(),
                    background: a.background.or(model_background).unwrap_or(white),
                    view,
                    palette,
                    widths_in_units: model.widths_in_units,
                    ..Default::default()
                },
            };
            let mut progress = progress;
            let on_step =
                &mut |d: &crate::rewrite::Derivation| progress(Progress::of_derivation(d));
            let figures = match format {
                Picture::Png => c.png_figures_reporting(&figure, on_step)?,
                Picture::Svg => c
                    .figures_reporting(&figure, on_step)?
                    .try_map(|s| picture_bytes(s, format))?,
            };
            write_program_files(&a.program_output, dir.as_deref(), &[file, output])?;
            write_views(figures, Path::new(&a.file), output, a.force, out)
        }
    }
}

/// How `render` runs an L-system: the steps checked, the folder the
/// program may write in, the run's options.
fn curve_run(
    a: &RenderArgs,
    deadline: Option<Deadline>,
) -> Result<(RunOptions, Option<PathBuf>), Error> {
    check_steps(a.steps)?;
    let dir = writes_folder(&a.allow_writes, &a.program_output)?;
    let opts = RunOptions {
        steps: a.steps,
        max_modules: a.max_modules,
        phase: a.phase,
        seed: a.seed,
        base_mesh: None,
        deadline,
        output: a.program_output.clone(),
        max_shapes: None,
    };
    Ok((opts, dir))
}

/// Whether `render` draws this L-system's 3D geometry in a picture (see
/// [`Solidity`]).
pub(super) fn wants_solid(solid: Solidity, c: &crate::Curve) -> bool {
    use crate::model::view::{LineStyle, RenderMode};
    let m = &*crate::model::of(&c.program);
    match solid {
        Solidity::Solid => true,
        Solidity::Lines => false,
        Solidity::Auto => {
            m.line_style != LineStyle::Pixel
                || matches!(
                    m.camera.render_mode,
                    RenderMode::Shaded | RenderMode::Shadows
                )
        }
    }
}

/// An L-system's 3D geometry: exported (`.obj` with its `.mtl`, `.ply`,
/// `.glb`) or drawn by the z-buffer with the view file's camera and
/// lights (`--view` with a mesh view's name turns the camera, y up).
/// Lines in lpfg's `pixel` style become tubes as wide as their pixels at
/// the picture's scale.
fn render_solid(
    a: &RenderArgs,
    c: &crate::Curve,
    (looks, format): (&MeshLooks, Picture),
    deadline: Option<Deadline>,
    progress: impl FnMut(Progress),
    out: &mut Out,
) -> Result<Vec<String>, Error> {
    let output = Path::new(&a.output);
    let file = Path::new(&a.file);
    if a.each {
        return Err(Error::Usage(
            "--each draws the 2D steps side by side; add --lines, or draw one step in 3D".into(),
        ));
    }
    let picture = crate::export::Format::from_path(output).is_none();
    let (scene, dir) = solid_scene(a, c, looks.size, deadline, progress, picture)?;
    write_program_files(&a.program_output, dir.as_deref(), &[file, output])?;
    if !picture {
        if scene.triangle_count() == 0 {
            return Err(Error::Failed(
                "nothing to export: the turtle made no 3D geometry (no lines, surfaces, polygons or spheres)".into(),
            ));
        }
        crate::export::write(&scene, output)?;
        return Ok(Vec::new());
    }
    let (w, h) = looks.size;
    let ropts = solid_raster_options(a, c, &scene, w, h)?;
    let bytes = match format {
        Picture::Png => crate::render::raster::render_png(&scene, &ropts)?,
        Picture::Svg => crate::render::raster::render_svg(&scene, &ropts)?.into_bytes(),
    };
    out.put(vec![(output.to_path_buf(), bytes)])?;
    Ok(Vec::new())
}

/// An L-system's 3D geometry for a picture `size` pixels wide and high
/// (`picture`), or for export and the live page's own view (lines of
/// lpfg's `pixel` style as tubes of that many units, no thin lines), and
/// the folder the program may write in.
pub(super) fn solid_scene(
    a: &RenderArgs,
    c: &crate::Curve,
    (w, h): (u32, u32),
    deadline: Option<Deadline>,
    mut progress: impl FnMut(Progress),
    picture: bool,
) -> Result<(crate::scene3::Scene3, Option<PathBuf>), Error> {
    use crate::draw::solid::SolidOptions;
    use crate::model::view::LineStyle;
    let (opts, dir) = curve_run(a, deadline)?;
    let model = &*crate::model::of(&c.program);
    let mut run = c.run_reporting(opts.derive_options(), |d| {
        progress(Progress::of_derivation(d))
    })?;
    let mut sopts = SolidOptions::default();
    // The picture's scale from the drawing's extent, as the camera will
    // frame it (lpfg's 0.9 of the window by default).
    let fit = 0.9 * w.min(h) as f64;
    if model.line_style == LineStyle::Pixel {
        // Pixel-wide lines are tubes of that many units: the scale first.
        let extent = run
            .line_bounds()?
            .map_or(f64::NAN, |(lo, hi)| (hi - lo).max_element());
        let units_per_pixel = crate::draw::solid::pixel_of(extent, fit);
        sopts.pixel_tubes = Some(units_per_pixel);
        // A picture needs no more sides than its pixels show; an export
        // keeps them all.
        if picture {
            sopts.picture_pixel = Some(units_per_pixel);
        }
    } else if picture {
        // The same scale, found by the walk that makes the geometry.
        sopts.fit_pixels = Some(fit);
    }
    Ok((run.solid(&sopts)?, dir))
}

/// The z-buffer's settings for an L-system's 3D geometry in a picture of
/// `w`×`h`: the view file's camera and lights (`--view` with a mesh
/// view's name turns the camera, y up) and the background.
pub(super) fn solid_raster_options(
    a: &RenderArgs,
    c: &crate::Curve,
    scene: &crate::scene3::Scene3,
    w: u32,
    h: u32,
) -> Result<crate::render::raster::RasterOptions, Error> {
    let model = &*crate::model::of(&c.program);
    let mut camera = model.camera.clone();
    if let Some(name) = a.view.as_deref().filter(|v| *v != "xy") {
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
    let mut ropts = camera.raster_options(&model.lights, scene.bounds(), w, h)?;
    let model_background = model.background().map(|[r, g, b]| Rgba(r, g, b, 255));
    ropts.background = a
        .background
        .or(model_background)
        .unwrap_or(Rgba(255, 255, 255, 255));
    Ok(ropts)
}
