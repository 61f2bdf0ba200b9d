//! lpfg's view file (`.v`, manual §8.1) and animation file (`.a`, §8.2).
//!
//! Every command of the manual is recognised. subgram acts on `surface:`
//! (the Bézier surfaces that `Surface(id, s)` draws, numbered from 0 in
//! the order given, with their scale) and `line style:` (with `polygon`
//! or `cylinder`, line widths are in the model's units) and `light:`
//! (materials are lit by the lights, as on a surface facing the viewer),
//! and keeps the camera of the single view (`projection:`, `scale:` /
//! `scale factor:`, `view: 0 …` in its current and deprecated forms,
//! `box: 0 …`, `front distance:`, `back distance:`) and the `render
//! mode:` for the 3D renderer ([`ViewCamera`]), which always tests depth
//! and smooths edges (`z buffer:` and `antialiasing:` are taken as on);
//! the others set up lpfg's OpenGL window (shadows, fonts, …) and are
//! reported as not acted on. The views' names (`window:`) and the turtle's settings
//! (`corrected rotation:`, `tropism:`, `torque:`, `stropism:`) are read by
//! `load::read_view_file`. The animation file (`.a`) chooses the frames of
//! `render -o growth.gif` ([`Animation`]); a still picture ignores it.

use super::error::ModelError as Error;
use super::text::{number, words, Lines};
use super::Note;

/// The commands of §8.1 (including the deprecated ones), as their
/// lower-case keys before the colon.
const VIEW_COMMANDS: &[&str] = &[
    "projection",
    "scale",
    "scale factor",
    "min zoom",
    "max zoom",
    "generate on view change",
    "view",
    "box",
    "window",
    "window border",
    "front distance",
    "back distance",
    "z buffer",
    "render mode",
    "shadow map",
    "light",
    "stationary lights",
    "concave polygons",
    "auto normals",
    "antialiasing",
    "line style",
    "wireframe line width",
    "contour sides",
    "capped cylinders",
    "backface culling",
    "corrected rotation",
    "tropism",
    "torque",
    "stropism",
    "surface",
    "mesh",
    "texture",
    "font",
    "winfont",
    "ps linecap",
    "gradient",
    "initial color",
    "color increment",
    "initial line width",
    "line width increment",
    "tropism direction",
    "initial elasticity",
    "elasticity increment",
    "bsurface",
];

/// Commands that the turtle and the views act on (`load::read_view_file`).
const ACTED_ON_BY_THE_TURTLE: &[&str] = &[
    "window",
    "corrected rotation",
    "tropism",
    "torque",
    "stropism",
];

/// A `surface:` command: the file, its line, the scale.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceRef {
    pub file: String,
    pub line: usize,
    /// The file name's byte range in the view file's text.
    pub at: (usize, usize),
    pub scale: f64,
    /// `sdiv tdiv`: the divisions of each patch along s and t, when given
    /// (both or neither, each 2 to 64 as lpfg takes them).
    pub divisions: Option<(u32, u32)>,
}

/// lpfg's bounds on a surface's divisions along s and t.
pub const MIN_SURFACE_DIVISIONS: i64 = 2;
pub const MAX_SURFACE_DIVISIONS: i64 = 64;

/// What subgram keeps of a view file.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewFile {
    pub surfaces: Vec<SurfaceRef>,
    /// `line style: polygon` or `cylinder`: `SetWidth` is in the model's
    /// units; `pixel` (the default): in pixels.
    pub widths_in_units: bool,
    /// `line style:` itself.
    pub line_style: LineStyle,
    /// `contour sides:` (manual 8.1.3: 16 by default, at least 3).
    pub contour_sides: u32,
    /// `capped cylinders: on` (off by default).
    pub capped_cylinders: bool,
    /// `light:` commands, in order.
    pub lights: Vec<Light>,
    /// The single view's camera and render mode.
    pub camera: ViewCamera,
}

/// How lpfg draws 3D geometry (`render mode:`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RenderMode {
    /// Flat colours, no lighting (lpfg's default).
    #[default]
    Filled,
    Wireframe,
    /// Lit by the lights.
    Shaded,
    /// Lit, with shadows (drawn as `Shaded`: subgram casts no shadows).
    Shadows,
}

/// The camera settings of the view file (§8.1.1) for view 0, each as
/// given (`None`: lpfg's default).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ViewCamera {
    /// `projection: perspective` (parallel by default).
    pub perspective: bool,
    /// The fraction of the window the bounding box fills: `scale:`,
    /// `scale factor:` or `view:`'s `scale:`, the last given.
    pub scale: Option<f64>,
    /// `view:`'s `dir:`, `up:`, `pan:`, `fov:` and `shift:`.
    pub dir: Option<[f64; 3]>,
    pub up: Option<[f64; 3]>,
    pub pan: Option<[f64; 3]>,
    pub fov: Option<f64>,
    pub shift: Option<f64>,
    /// `box:` as xmin xmax ymin ymax zmin zmax.
    pub bbox: Option<[f64; 6]>,
    /// `front distance:` and `back distance:` (they act only together).
    pub front: Option<f64>,
    pub back: Option<f64>,
    pub render_mode: RenderMode,
}

impl Default for ViewFile {
    fn default() -> Self {
        ViewFile {
            surfaces: Vec::new(),
            widths_in_units: false,
            line_style: LineStyle::Pixel,
            contour_sides: DEFAULT_CONTOUR_SIDES,
            capped_cylinders: false,
            lights: Vec::new(),
            camera: ViewCamera::default(),
        }
    }
}

/// lpfg's `contour sides:` when the view file does not say (manual 8.1.3).
pub const DEFAULT_CONTOUR_SIDES: u32 = 16;
/// lpfg's bounds on the sides of a contour (and its samples).
pub const MIN_CONTOUR_SIDES: u32 = 3;
pub const MAX_CONTOUR_SIDES: u32 = 10_000;

/// How lines (`F`) are drawn (manual 8.1.3, `line style:`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LineStyle {
    /// Lines of a width in pixels (the default).
    #[default]
    Pixel,
    /// Flat bands of the line width facing the viewer.
    Polygon,
    /// Cylinders of the line width; generalized cylinders are drawn only
    /// in this style.
    Cylinder,
}

/// A light source of the view file: its direction (towards the light),
/// and its ambient, diffuse and specular colours (each 0 to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub direction: [f64; 3],
    pub ambient: [f64; 3],
    pub diffuse: [f64; 3],
    /// `S:`, white by default.
    pub specular: [f64; 3],
}

impl Default for Light {
    /// lpfg's default light: from the viewer (0 0 1), white.
    fn default() -> Self {
        Light {
            direction: [0.0, 0.0, 1.0],
            ambient: [1.0; 3],
            diffuse: [1.0; 3],
            specular: [1.0; 3],
        }
    }
}

/// Reads the fields of a `light:` command (`V: x y z`, `O: x y z`,
/// `P: x y z e c`, `A:`, `D:`, `S: r g b`, `T: c l q`).
fn light(lines: &Lines<'_>, line: &str, after: usize) -> Result<Light, Error> {
    let ws: Vec<_> = words(&line[after..])
        .into_iter()
        .map(|w| super::text::Word {
            text: w.text,
            start: w.start + after,
            end: w.end + after,
        })
        .collect();
    let mut l = Light::default();
    let mut i = 0;
    while i < ws.len() {
        let w = ws[i];
        let n = match w.text {
            "V:" | "O:" | "A:" | "D:" | "S:" | "T:" => 3,
            "P:" => 5,
            _ => {
                return Err(lines.error(
                    w,
                    format!(
                    "expected a light field `V:`, `O:`, `P:`, `A:`, `D:`, `S:` or `T:`, found `{}`",
                    w.text
                ),
                ))
            }
        };
        let mut v = [0.0; 5];
        for (k, slot) in v.iter_mut().enumerate().take(n) {
            *slot = number(lines, &ws, i + 1 + k, &format!("a value of `{}`", w.text))?;
        }
        match w.text {
            "V:" | "O:" => l.direction = [v[0], v[1], v[2]],
            "A:" => l.ambient = [v[0], v[1], v[2]],
            "D:" => l.diffuse = [v[0], v[1], v[2]],
            "S:" => l.specular = [v[0], v[1], v[2]],
            _ => {}
        }
        i += 1 + n;
    }
    Ok(l)
}

/// The words of `line` after byte `after`, with ranges in the line.
fn words_after(line: &str, after: usize) -> Vec<super::text::Word<'_>> {
    words(&line[after..])
        .into_iter()
        .map(|w| super::text::Word {
            text: w.text,
            start: w.start + after,
            end: w.end + after,
        })
        .collect()
}

/// Reads a camera command (`projection:`, `scale:`, `scale factor:`,
/// `view:`, `box:`, `front distance:`, `back distance:`, `render mode:`)
/// into `camera`; false for any other command. A value lpfg does not know
/// is a note (lpfg reports it and keeps its default); a malformed number
/// is an error at its word. Views other than 0 (multiple views) are left
/// out with a note.
fn camera_command(
    lines: &Lines<'_>,
    line: &str,
    (k, after): (&str, usize),
    camera: &mut ViewCamera,
    note: &mut dyn FnMut((usize, usize), String),
) -> Result<bool, Error> {
    let ws = words_after(line, after);
    let span = |i: usize| {
        ws.get(i)
            .map_or((line.len(), line.len()), |w| (w.start, w.end))
    };
    match k {
        "projection" => match ws.first().map(|w| w.text) {
            Some("parallel") => camera.perspective = false,
            Some("perspective") => camera.perspective = true,
            _ => note(
                span(0),
                "not a projection (`parallel` or `perspective`): the projection stays parallel"
                    .into(),
            ),
        },
        "scale" | "scale factor" => {
            let s = number(lines, &ws, 0, "the scale")?;
            if s.abs() < 1e-4 {
                return Err(lines.error(ws[0], "the scale must not be 0"));
            }
            camera.scale = Some(s);
        }
        "front distance" => camera.front = Some(number(lines, &ws, 0, "the front distance")?),
        "back distance" => camera.back = Some(number(lines, &ws, 0, "the back distance")?),
        "render mode" => match ws.first().map(|w| w.text) {
            Some("filled") => camera.render_mode = RenderMode::Filled,
            Some("wireframe") => camera.render_mode = RenderMode::Wireframe,
            Some("shaded") => camera.render_mode = RenderMode::Shaded,
            Some("shadows") => {
                camera.render_mode = RenderMode::Shadows;
                note(
                    span(0),
                    "subgram casts no shadows: the picture is shaded without them".into(),
                );
            }
            _ => note(
                span(0),
                "not a render mode (`filled`, `wireframe`, `shaded` or `shadows`): it stays \
                 `filled`"
                    .into(),
            ),
        },
        "box" => {
            let id = number(lines, &ws, 0, "the view's number")?;
            let mut b = [0.0; 6];
            for (i, slot) in b.iter_mut().enumerate() {
                *slot = number(
                    lines,
                    &ws,
                    1 + i,
                    "a bound of the box (xmin xmax ymin ymax zmin zmax)",
                )?;
            }
            if id != 0.0 {
                note(span(0), "only view 0 is drawn: this box is left out".into());
            } else if b[0] > b[1] || b[2] > b[3] || b[4] > b[5] {
                return Err(lines.error(
                    ws[1],
                    "the box's bounds must be xmin xmax ymin ymax zmin zmax, each minimum at most \
                     its maximum",
                ));
            } else {
                camera.bbox = Some(b);
            }
        }
        "view" => view_command(lines, &ws, camera, note)?,
        _ => return Ok(false),
    }
    Ok(true)
}

/// `view: id dir: x y z up: x y z pan: x y z fov: f shift: s scale: s`
/// (each part optional), or the deprecated `view: id rx ry rz scale px py
/// pz`: rotations in degrees about x, then y, then z of lpfg's default
/// view (down -z, y up), the scale and the pan.
fn view_command(
    lines: &Lines<'_>,
    ws: &[super::text::Word<'_>],
    camera: &mut ViewCamera,
    note: &mut dyn FnMut((usize, usize), String),
) -> Result<(), Error> {
    let id = number(lines, ws, 0, "the view's number")?;
    let mut c = camera.clone();
    let all_numbers = ws.len() == 8 && ws.iter().all(|w| w.text.parse::<f64>().is_ok());
    if all_numbers {
        let v: Vec<f64> = (1..8)
            .map(|i| number(lines, ws, i, "a value of the view"))
            .collect::<Result<_, _>>()?;
        let q = glam::DQuat::from_rotation_x(v[0].to_radians())
            * glam::DQuat::from_rotation_y(v[1].to_radians())
            * glam::DQuat::from_rotation_z(v[2].to_radians());
        c.dir = Some((q * glam::DVec3::NEG_Z).to_array());
        c.up = Some((q * glam::DVec3::Y).to_array());
        if v[3].abs() < 1e-4 {
            return Err(lines.error(ws[4], "the scale must not be 0"));
        }
        c.scale = Some(v[3]);
        c.pan = Some([v[4], v[5], v[6]]);
    } else {
        let mut i = 1;
        while i < ws.len() {
            let w = ws[i];
            let three = |i: usize, what: &str| -> Result<[f64; 3], Error> {
                Ok([
                    number(lines, ws, i, what)?,
                    number(lines, ws, i + 1, what)?,
                    number(lines, ws, i + 2, what)?,
                ])
            };
            match w.text {
                "dir:" => c.dir = Some(three(i + 1, "a coordinate of the view direction")?),
                "up:" => c.up = Some(three(i + 1, "a coordinate of the up direction")?),
                "pan:" => c.pan = Some(three(i + 1, "a coordinate of the pan")?),
                "fov:" => c.fov = Some(number(lines, ws, i + 1, "the field of view in degrees")?),
                "shift:" => c.shift = Some(number(lines, ws, i + 1, "the camera's distance")?),
                "scale:" => {
                    let s = number(lines, ws, i + 1, "the scale")?;
                    if s.abs() < 1e-4 {
                        return Err(lines.error(ws[i + 1], "the scale must not be 0"));
                    }
                    c.scale = Some(s);
                }
                _ => {
                    return Err(lines.error(
                        w,
                        format!(
                            "expected a part of the view `dir:`, `up:`, `pan:`, `fov:`, `shift:` \
                             or `scale:`, found `{}`",
                            w.text
                        ),
                    ))
                }
            }
            i += if matches!(w.text, "dir:" | "up:" | "pan:") {
                4
            } else {
                2
            };
        }
    }
    if id != 0.0 {
        note(
            (ws[0].start, ws[0].end),
            "only view 0 is drawn: this view is left out".into(),
        );
    } else {
        *camera = c;
    }
    Ok(())
}

/// The text with C and C++ comments blanked out (newlines and byte
/// offsets kept), as the preprocessor that lpfg runs on the file removes
/// them.
fn blank_comments(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                out[i] = b' ';
                i += 1;
            }
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            out[i] = b' ';
            out[i + 1] = b' ';
            i += 2;
            while i < b.len() && !(b[i] == b'*' && b.get(i + 1) == Some(&b'/')) {
                if b[i] != b'\n' {
                    out[i] = b' ';
                }
                i += 1;
            }
            if i < b.len() {
                out[i] = b' ';
                out[i + 1] = b' ';
                i += 2;
            }
        } else {
            i += 1;
        }
    }
    // Blanking replaced whole bytes of comments only, so the text is
    // still UTF-8 wherever it was; a stray byte reads as U+FFFD.
    String::from_utf8_lossy(&out).into_owned()
}

/// The command key of a line (the text before its first colon, lower
/// case, single-spaced) and the byte offset after the colon.
fn key(line: &str) -> Option<(String, usize)> {
    let colon = line.find(':')?;
    let k = line[..colon]
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    Some((k.to_ascii_lowercase(), colon + 1))
}

/// Byte offset of line `n` (0-based) in `text`.
fn line_start(text: &str, n: usize) -> usize {
    text.split_inclusive('\n').take(n).map(str::len).sum()
}

/// Reads a view file: the surfaces, and a note for every command that
/// subgram does not act on or does not know.
pub fn read_v(path: &str, text: &str, notes: &mut Vec<Note>) -> Result<ViewFile, Error> {
    let clean = blank_comments(text);
    let mut lines = Lines::shown_as(path, &clean, text);
    let mut view = ViewFile::default();
    let mut ignored: Vec<(String, usize, usize, usize)> = Vec::new();
    while !lines.at_end() {
        let line = lines.next_line("")?;
        let n = lines.line_no();
        let base = line_start(text, n - 1);
        let first = words(line)[0];
        if first.text.starts_with('#') {
            notes.push(Note::at(
                path,
                text,
                base + first.start..base + first.end,
                "the view file's preprocessor directives are not run: the line is left out".into(),
            ));
            continue;
        }
        let Some((k, after)) = key(line) else {
            return Err(lines.error(
                first,
                "expected a command such as `surface: leaf.s` (a name, a colon, values)",
            ));
        };
        if !VIEW_COMMANDS.contains(&k.as_str()) {
            notes.push(Note::at(
                path,
                text,
                base + first.start..base + after,
                format!(
                    "`{k}:` is not a view-file command that lpfg's manual lists: it is left out"
                ),
            ));
            continue;
        }
        if camera_command(&lines, line, (&k, after), &mut view.camera, &mut |at, m| {
            notes.push(Note::at(path, text, base + at.0..base + at.1, m))
        })? {
            continue;
        }
        if k == "light" {
            view.lights.push(light(&lines, line, after)?);
            // Lights shade the materials' colours; their positions and the
            // shading of curved surfaces are beyond a flat picture.
            continue;
        }
        if k == "contour sides" {
            let ws = words_after(line, after);
            let n = number(&lines, &ws, 0, "the number of sides")?;
            // lpfg clamps the value to its bounds.
            view.contour_sides = n.clamp(MIN_CONTOUR_SIDES as f64, MAX_CONTOUR_SIDES as f64) as u32;
            continue;
        }
        if k == "capped cylinders" {
            let ws = words_after(line, after);
            view.capped_cylinders = match ws.first().map(|w| w.text) {
                Some("on") => true,
                Some("off") => false,
                Some(w) => {
                    return Err(lines.error(ws[0], format!("expected `on` or `off`, found `{w}`")))
                }
                None => return Err(lines.error_at_end("expected `on` or `off`")),
            };
            continue;
        }
        if k == "line style" {
            let ws = words(&line[after..]);
            view.line_style = match ws.first().map(|w| w.text) {
                Some("pixel") => LineStyle::Pixel,
                Some("polygon") => LineStyle::Polygon,
                Some("cylinder") => LineStyle::Cylinder,
                _ => LineStyle::Pixel,
            };
            view.widths_in_units = match ws.first().map(|w| w.text) {
                Some("pixel") => false,
                Some("polygon") | Some("cylinder") => true,
                _ => {
                    // lpfg reports another style (`wireframe` in vlab's
                    // own models) and keeps its default, pixel lines: so
                    // does subgram.
                    let (s, e) = ws.first().map_or((line.len(), line.len()), |w| {
                        (w.start + after, w.end + after)
                    });
                    notes.push(Note::at(
                        path,
                        text,
                        base + s..base + e,
                        "not a line style (`pixel`, `polygon` or `cylinder`): lines are drawn \
                         in pixels, the default, as lpfg draws them"
                            .into(),
                    ));
                    false
                }
            };
            continue;
        }
        if k == "surface" {
            let ws = words(&line[after..]);
            let Some(f) = ws.first() else {
                return Err(lines.error_at_end("expected the surface's file after `surface:`"));
            };
            let shifted: Vec<_> = ws
                .iter()
                .map(|w| super::text::Word {
                    text: w.text,
                    start: w.start + after,
                    end: w.end + after,
                })
                .collect();
            let scale = if shifted.len() > 1 {
                number(&lines, &shifted, 1, "the surface's scale")?
            } else {
                1.0
            };
            // `sdiv tdiv` come together (manual 8.1.5); lpfg keeps its
            // default for a value out of its bounds, and so does subgram.
            let divisions = if shifted.len() > 3 {
                let div = |k: usize, what: &str| -> Result<Option<u32>, Error> {
                    let v = number(&lines, &shifted, k, what)?;
                    let ok = v.fract() == 0.0
                        && (MIN_SURFACE_DIVISIONS as f64..=MAX_SURFACE_DIVISIONS as f64)
                            .contains(&v);
                    Ok(ok.then_some(v as u32))
                };
                let s = div(2, "the surface's divisions along s")?;
                let t = div(3, "the surface's divisions along t")?;
                s.zip(t)
            } else {
                None
            };
            view.surfaces.push(SurfaceRef {
                file: f.text.to_string(),
                line: n,
                at: (base + f.start + after, base + f.end + after),
                scale,
                divisions,
            });
            continue;
        }
        // The turtle's settings and the views' names are read by the
        // loader (`load::read_view_file`), which warns about its own lines.
        if ACTED_ON_BY_THE_TURTLE.contains(&k.as_str()) {
            continue;
        }
        // subgram's 3D pictures always test depth and smooth their edges.
        if matches!(k.as_str(), "z buffer" | "antialiasing") {
            continue;
        }
        ignored.push((k, n, base + first.start, base + after));
    }
    if !ignored.is_empty() {
        let mut seen: Vec<&str> = Vec::new();
        for (k, _, _, _) in &ignored {
            if !seen.contains(&k.as_str()) {
                seen.push(k);
            }
        }
        let (_, _, s, e) = ignored[0];
        let list = seen
            .iter()
            .map(|k| format!("`{k}:`"))
            .collect::<Vec<_>>()
            .join(", ");
        notes.push(Note::at(
            path,
            text,
            s..e,
            format!("subgram does not act on {list}"),
        ));
    }
    Ok(view)
}

/// An animation file's settings (§8.2): which derivation steps are the
/// frames of an animation, and how they are shown.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// `first frame:` (0 by default).
    pub first_frame: u64,
    /// `last frame:`; `None` (or a negative number, as vlab's models
    /// write -1): the derivation length.
    pub last_frame: Option<u64>,
    /// `step:`, the derivation steps between frames (1 by default).
    pub step: u64,
    /// `swap interval:`, the time between frames in hundredths of a
    /// second (0 by default: as fast as the display goes).
    pub swap_interval: f64,
    /// `scale between frames:` (off by default): each frame fitted to
    /// the window on its own.
    pub scale_between_frames: bool,
    /// `hcenter between frames:` (off by default): each frame centred
    /// horizontally on its own.
    pub hcenter_between_frames: bool,
    /// `clear between frames:` (on by default).
    pub clear_between_frames: bool,
    /// `display on request:` (off by default).
    pub display_on_request: bool,
}

impl Default for Animation {
    /// The manual's defaults.
    fn default() -> Self {
        Animation {
            first_frame: 0,
            last_frame: None,
            step: 1,
            swap_interval: 0.0,
            scale_between_frames: false,
            hcenter_between_frames: false,
            clear_between_frames: true,
            display_on_request: false,
        }
    }
}

/// Reads an animation file: `command: value` lines of §8.2. The frame
/// commands are kept ([`Animation`]); `double buffer:` and `new view
/// between frames:` belong to lpfg's window and are only checked.
pub fn read_a(path: &str, text: &str, notes: &mut Vec<Note>) -> Result<Animation, Error> {
    let clean = blank_comments(text);
    let mut lines = Lines::shown_as(path, &clean, text);
    let mut a = Animation::default();
    while !lines.at_end() {
        let line = lines.next_line("")?;
        let n = lines.line_no();
        let first = words(line)[0];
        let Some((k, after)) = key(line) else {
            return Err(lines.error(
                first,
                "expected a command such as `step: 1` (a name, a colon, a value)",
            ));
        };
        let ws = words_after(line, after);
        let frame = |what: &str| -> Result<u64, Error> {
            let v = number(&lines, &ws, 0, what)?;
            if v < 0.0 || v.fract() != 0.0 || v > u32::MAX as f64 {
                return Err(lines.error(ws[0], format!("{what} must be a whole number, 0 or more")));
            }
            Ok(v as u64)
        };
        let switch = || -> Result<bool, Error> {
            match ws.first().map(|w| w.text.to_ascii_lowercase()) {
                Some(w) if w == "on" => Ok(true),
                Some(w) if w == "off" => Ok(false),
                Some(w) => Err(lines.error(ws[0], format!("expected `on` or `off`, found `{w}`"))),
                None => Err(lines.error_at_end("expected `on` or `off`")),
            }
        };
        match k.as_str() {
            "first frame" => a.first_frame = frame("the first frame")?,
            // vlab's models write -1: up to the derivation length.
            "last frame" if number(&lines, &ws, 0, "the last frame")? < 0.0 => a.last_frame = None,
            "last frame" => a.last_frame = Some(frame("the last frame")?),
            "step" => {
                a.step = frame("the step")?;
                if a.step == 0 {
                    return Err(lines.error(ws[0], "the step must be 1 or more"));
                }
            }
            "swap interval" => {
                let t = number(&lines, &ws, 0, "the interval")?;
                if t < 0.0 {
                    return Err(lines.error(ws[0], "the interval must be 0 or more"));
                }
                a.swap_interval = t;
            }
            "scale between frames" => a.scale_between_frames = switch()?,
            "hcenter between frames" => a.hcenter_between_frames = switch()?,
            "clear between frames" => a.clear_between_frames = switch()?,
            "display on request" => a.display_on_request = switch()?,
            "double buffer" | "new view between frames" => {
                switch()?;
            }
            _ => {
                let base = line_start(text, n - 1);
                notes.push(Note::at(
                    path,
                    text,
                    base + first.start..base + after,
                    format!("`{k}:` is not an animation-file command that lpfg's manual lists"),
                ));
            }
        }
    }
    Ok(a)
}
