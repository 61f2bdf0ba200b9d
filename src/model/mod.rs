//! Model folders: an lpfg program together with the files that vlab's
//! editors made for it, found beside it and read into one [`Model`].
//!
//! * [`find`] decides what a folder (or a `.l` file) holds: the L-system
//!   and its files, from the `specifications` file's `lpfg` command line
//!   when there is one, else `MAIN` or `lsystem.l` and the one file of
//!   each kind beside it.
//! * The readers, one file per family: [`functions`] (`.func`, `.fset`,
//!   `.tset`, `.vset`), [`contours`] (`.con`, `.cset`), [`surface`] (`.s`),
//!   [`colours`] (`.map`, `.mat`), [`view`] (`.v`, `.a`).
//! * [`Model::defines`] names every function, contour and surface with a
//!   number, as lpfg's invisible `-D NAME=N` do; [`Model::call`] evaluates
//!   the accessors (`func`, `tfunc`, `curveX`, `val`, …) for the
//!   interpreter.
//!
//! **Layer.** It uses `files`, `lang`, `syntax`; it is used by `command`,
//! `curve`, `draw`, `error`, `load`, `render`, `shape`, `surface`, `system`.
//! Nothing here names a layer above (see ARCHITECTURE.md, "Layers").

pub mod colours;
pub mod comm;
pub mod contours;
mod error;
pub mod functions;
pub mod surface;
pub mod text;
pub mod view;

use std::path::{Path, PathBuf};

pub use self::error::ModelError;
use self::error::ModelError as Error;
pub use crate::lang::model::{Accessor, ACCESSOR_NAMES};
use crate::lang::value::Value;

pub use colours::Colours;
pub use contours::Contour;
pub use functions::Function;
pub use surface::Surface;

impl Model {
    /// The 256 colours that colour indices choose, when the model has a
    /// colour map or materials.
    pub fn palette(&self) -> Option<[[u8; 3]; 256]> {
        match &self.colours {
            Some(c) => Some(std::array::from_fn(|i| c.colour(i as i64, &self.lights))),
            None if self.lpfg => Some(std::array::from_fn(|i| lpfg_default_colour(i as i64))),
            None => None,
        }
    }

    /// The background its colours give: colour 0 of the map (material 0's
    /// emission), or black for an lpfg program without a colour file, as
    /// lpfg draws it; `None` for subgram's own files without one.
    pub fn background(&self) -> Option<[u8; 3]> {
        match &self.colours {
            Some(c) => Some(c.background()),
            None if self.lpfg => Some(lpfg_default_colour(0)),
            None => None,
        }
    }
}

/// lpfg's colour map when a model has no colour file: index 0 black,
/// every other one white (so lpfg draws white on black).
pub fn lpfg_default_colour(i: i64) -> [u8; 3] {
    if i.rem_euclid(256) == 0 {
        [0, 0, 0]
    } else {
        [255, 255, 255]
    }
}

/// Something about a model file that does not stop the run: a view-file
/// command subgram does not act on. It points into the file's text.
#[derive(Clone, Debug, PartialEq)]
pub struct Note {
    pub file: String,
    pub text: String,
    pub start: usize,
    pub end: usize,
    pub message: String,
}

impl Note {
    pub fn at(file: &str, text: &str, at: std::ops::Range<usize>, message: String) -> Note {
        Note {
            file: file.to_string(),
            text: text.to_string(),
            start: at.start.min(text.len()),
            end: at.end.min(text.len()),
            message,
        }
    }
}

/// Everything a model's files define.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Model {
    /// Functions and parameters, numbered from 1 in lpfg's order: the
    /// `.fset`, the `.tset`, the `.vset`, then each `.func`.
    pub functions: Vec<Function>,
    /// Contours, numbered from 0: lpfg's default circle, then the `.cset`'s
    /// contours, then each `.con`.
    pub contours: Vec<Contour>,
    /// Surfaces, numbered from 0 in the view file's order.
    pub surfaces: Vec<Surface>,
    pub colours: Option<Colours>,
    /// Read as an lpfg program's model ([`Model::read`]: a `.l` file or a
    /// model folder), whose colours default to lpfg's own
    /// ([`lpfg_default_colour`]) where no colour file gives them.
    pub lpfg: bool,
    /// The view file's `line style:` makes widths the model's units.
    pub widths_in_units: bool,
    /// The view file's `line style:`.
    pub line_style: view::LineStyle,
    /// The view file's `contour sides:` (0 in a model made by `default()`:
    /// lpfg's default, [`view::DEFAULT_CONTOUR_SIDES`]).
    pub contour_sides: u32,
    /// The view file's `capped cylinders:`.
    pub capped_cylinders: bool,
    /// The view file's lights.
    pub lights: Vec<view::Light>,
    /// The view file's camera and render mode.
    pub camera: view::ViewCamera,
    /// The communication file (`.e`): the environmental program of an
    /// open L-system.
    pub environment: Option<comm::CommSpec>,
    /// The animation file (`.a`): the frames of an animation.
    pub animation: Option<view::Animation>,
    /// The files read, in order.
    pub files: Vec<PathBuf>,
    pub notes: Vec<Note>,
}

/// The kinds of file a model folder may hold, by extension.
const KINDS: &[&str] = &[
    "v", "a", "fset", "func", "tset", "vset", "cset", "con", "map", "mat", "e",
];

/// A model's L-system and the files it reads.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelFiles {
    pub lsystem: PathBuf,
    /// The files, in the order lpfg's command line gives them (or the
    /// order `.v`, `.a`, `.fset`, `.func`, `.tset`, `.vset`, `.cset`,
    /// `.con`, `.map`, `.mat`, `.e`, then by name).
    pub files: Vec<PathBuf>,
}

fn ext(p: &Path) -> &str {
    p.extension().and_then(|e| e.to_str()).unwrap_or("")
}

/// The `lpfg …` command line of a `specifications` file: its line number,
/// text and the words after `lpfg` with their byte ranges.
fn spec_line(text: &str) -> Option<(usize, &str, Vec<text::Word<'_>>)> {
    for (i, line) in text.lines().enumerate() {
        let ws = text::words(line);
        if ws.first().is_some_and(|w| w.text == "lpfg") {
            return Some((i + 1, line, ws[1..].to_vec()));
        }
    }
    None
}

/// lpfg's options that take values, and how many.
fn option_values(opt: &str) -> usize {
    match opt {
        "-rmode" | "-out" | "-dll" | "-o" => 1,
        "-w" | "-wp" | "-wpr" | "-wr" => 2,
        _ => 0,
    }
}

/// What a model folder or a `.l` file holds. `None` when `input` is a
/// program file that is not an lpfg `.l` file (a `.lsys`): it is read
/// alone.
pub fn find(input: &Path) -> Result<Option<ModelFiles>, Error> {
    // A program in the current folder keeps its files' names bare: the
    // folder is the empty path, listed as `.`.
    let (dir, given) = if input.is_dir() {
        (input.to_path_buf(), None)
    } else if ext(input) == "l" {
        let dir = input.parent().map(Path::to_path_buf).unwrap_or_default();
        (dir, input.file_name().map(PathBuf::from))
    } else {
        return Ok(None);
    };
    let spec_path = dir.join("specifications");
    if spec_path.is_file() {
        let spec = text::read_text(&spec_path)?;
        if let Some((n, line, ws)) = spec_line(&spec) {
            let spec_name = spec_path.display().to_string();
            let mut files = Vec::new();
            let mut lsystem = None;
            let mut skip = 0;
            for w in &ws {
                if skip > 0 {
                    skip -= 1;
                    continue;
                }
                if w.text.starts_with('-') {
                    skip = option_values(w.text);
                    continue;
                }
                let p = dir.join(w.text);
                let missing = || Error::FileAt {
                    path: spec_name.clone(),
                    line: n,
                    text: line.to_string(),
                    start: w.start,
                    end: w.end,
                    message: format!(
                        "the model's lpfg command line names `{}`, but `{}` does not exist",
                        w.text,
                        p.display()
                    ),
                };
                if ext(&p) == "l" {
                    if !p.is_file() {
                        return Err(missing());
                    }
                    lsystem = Some(p);
                } else if KINDS.contains(&ext(&p)) {
                    if !p.is_file() {
                        return Err(missing());
                    }
                    files.push(p);
                }
                // Other words (images, the `.e` file's programs) are not
                // lpfg's input files.
            }
            let lsystem = lsystem.ok_or_else(|| Error::FileAt {
                path: spec_name.clone(),
                line: n,
                text: line.to_string(),
                start: 0,
                end: line.len(),
                message: "the model's lpfg command line names no `.l` file".into(),
            })?;
            // A `.l` file given directly uses the specifications only if
            // they run that file.
            let same = given
                .as_ref()
                .is_none_or(|g| lsystem.file_name() == Some(g.as_os_str()));
            if same {
                return Ok(Some(ModelFiles { lsystem, files }));
            }
        }
    }
    let lsystem = match given {
        Some(g) => dir.join(g),
        None => {
            let main = dir.join("MAIN");
            let named = if main.is_file() {
                let t = text::read_text(&main)?;
                t.split_whitespace().next().map(|n| dir.join(n))
            } else {
                None
            };
            match named {
                Some(p) => p,
                None => {
                    let p = dir.join("lsystem.l");
                    if !p.is_file() {
                        return Err(Error::Usage(format!(
                            "`{}` is a folder without an L-system: expected `lsystem.l`, a `MAIN` file naming the `.l` file, or a `specifications` file with an `lpfg` command line",
                            input.display()
                        )));
                    }
                    p
                }
            }
        }
    };
    // The lone file of each kind; `.func` and `.con` files may be many.
    let mut files = Vec::new();
    let listed = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir.as_path()
    };
    let mut entries: Vec<PathBuf> = std::fs::read_dir(listed)
        .map_err(|e| Error::read(listed, e))?
        .filter_map(|e| e.ok().map(|e| dir.join(e.file_name())))
        .filter(|p| p.is_file())
        .collect();
    entries.sort();
    let has = |k: &str| entries.iter().any(|p| ext(p) == k);
    for k in KINDS {
        // Materials win over a colour map when both are present.
        if *k == "map" && has("mat") {
            continue;
        }
        let of: Vec<&PathBuf> = entries.iter().filter(|p| ext(p) == *k).collect();
        if of.len() > 1 && !matches!(*k, "func" | "con") {
            let names: Vec<String> = of.iter().map(|p| format!("`{}`", p.display())).collect();
            return Err(Error::Usage(format!(
                "the model folder `{}` has {} `.{k}` files ({}): lpfg reads one; name it on the `lpfg` line of a `specifications` file",
                listed.display(),
                of.len(),
                names.join(", ")
            )));
        }
        files.extend(of.into_iter().cloned());
    }
    Ok(Some(ModelFiles { lsystem, files }))
}

impl Model {
    /// Reads a model's files.
    pub fn read(files: &[PathBuf]) -> Result<Model, Error> {
        let mut m = Model {
            contours: vec![Contour::default_circle()],
            lpfg: true,
            ..Model::default()
        };
        let by = |k: &'static str| files.iter().filter(move |p| ext(p) == k);
        let text_of = |p: &PathBuf| -> Result<(String, String), Error> {
            Ok((p.display().to_string(), text::read_text(p)?))
        };
        for p in by("fset") {
            let (n, t) = text_of(p)?;
            m.functions.extend(functions::read_fset(&n, &t)?);
        }
        for p in by("tset") {
            let (n, t) = text_of(p)?;
            m.functions.extend(functions::read_tset(&n, &t)?);
        }
        for p in by("vset") {
            let (n, t) = text_of(p)?;
            m.functions.extend(functions::read_vset(&n, &t)?);
        }
        for p in by("func") {
            let (n, t) = text_of(p)?;
            m.functions.extend(functions::read_func(&n, &t)?);
        }
        for p in by("cset") {
            let (n, t) = text_of(p)?;
            m.contours.extend(contours::read_cset(&n, &t)?);
        }
        for p in by("con") {
            let (n, t) = text_of(p)?;
            m.contours.extend(contours::read_con(&n, &t)?);
        }
        // The last colour file named wins, as on lpfg's command line.
        for p in files.iter().filter(|p| matches!(ext(p), "map" | "mat")) {
            let name = p.display().to_string();
            let bytes = text::read_bytes(p)?;
            m.colours = Some(if ext(p) == "map" {
                colours::read_map(&name, &bytes)?
            } else {
                colours::read_mat(&name, &bytes)?
            });
        }
        for p in by("v") {
            let (n, t) = text_of(p)?;
            let v = view::read_v(&n, &t, &mut m.notes)?;
            m.widths_in_units = v.widths_in_units;
            m.line_style = v.line_style;
            m.contour_sides = v.contour_sides;
            m.capped_cylinders = v.capped_cylinders;
            m.lights = v.lights.clone();
            m.camera = v.camera.clone();
            let dir = p.parent().unwrap_or(Path::new(""));
            for s in &v.surfaces {
                let sp = dir.join(&s.file);
                if !sp.is_file() {
                    let line = t.lines().nth(s.line - 1).unwrap_or("");
                    let base: usize = t.split_inclusive('\n').take(s.line - 1).map(str::len).sum();
                    return Err(Error::FileAt {
                        path: n.clone(),
                        line: s.line,
                        text: line.to_string(),
                        start: s.at.0 - base,
                        end: s.at.1 - base,
                        message: format!("the surface file `{}` does not exist", sp.display()),
                    });
                }
                let stem = sp
                    .file_stem()
                    .and_then(|s| s.to_str())
                    .unwrap_or("")
                    .to_string();
                let mut surf =
                    surface::read_s(&sp.display().to_string(), &stem, &text::read_text(&sp)?)?;
                surf.scale = s.scale;
                surf.divisions = s.divisions;
                m.surfaces.push(surf);
                m.files.push(sp);
            }
        }
        for p in by("a") {
            let (n, t) = text_of(p)?;
            m.animation = Some(view::read_a(&n, &t, &mut m.notes)?);
        }
        for p in by("e") {
            let (_, t) = text_of(p)?;
            // lpfg keeps the last communication file it is given.
            let spec = comm::CommSpec::read(p, &t)?;
            if let Some(message) = spec.communication_note() {
                let line = spec.communication.as_ref().map_or(1, |(l, _)| *l);
                let start: usize = t.lines().take(line - 1).map(|l| l.len() + 1).sum();
                let len = t.lines().nth(line - 1).map_or(0, |l| l.trim_end().len());
                m.notes.push(Note::at(
                    &p.display().to_string(),
                    &t,
                    start..start + len,
                    message,
                ));
            }
            m.environment = Some(spec);
        }
        m.files.extend(files.iter().cloned());
        Ok(m)
    }

    /// The names lpfg defines for the program, each `NAME=N`: functions
    /// from 1, contours and surfaces from 0. A name that is not a C
    /// identifier is left out (a surface file `my-leaf.s`).
    pub fn defines(&self) -> Vec<String> {
        let ident = |s: &str| {
            s.chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
                && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        };
        let mut out = Vec::new();
        for (i, f) in self.functions.iter().enumerate() {
            out.push((f.name.as_str(), i + 1));
        }
        for (i, c) in self.contours.iter().enumerate() {
            out.push((c.name.as_str(), i));
        }
        for (i, s) in self.surfaces.iter().enumerate() {
            out.push((s.name.as_str(), i));
        }
        out.into_iter()
            .filter(|(n, _)| ident(n))
            .map(|(n, i)| format!("{n}={i}"))
            .collect()
    }

    /// The names of the model's functions, for messages.
    fn function_list(&self) -> String {
        if self.functions.is_empty() {
            return "the model has no function: no `.fset`, `.func`, `.tset` or `.vset` file was read".into();
        }
        let names: Vec<String> = self
            .functions
            .iter()
            .enumerate()
            .map(|(i, f)| format!("{} `{}`", i + 1, f.name))
            .collect();
        format!("the model's functions are {}", names.join(", "))
    }

    fn function(&self, who: &str, id: i64) -> Result<&Function, String> {
        usize::try_from(id)
            .ok()
            .and_then(|i| i.checked_sub(1))
            .and_then(|i| self.functions.get(i))
            .ok_or_else(|| {
                format!(
                    "`{who}`: there is no function number {id}: {}",
                    self.function_list()
                )
            })
    }

    fn curve_fn(&self, who: &str, id: i64) -> Result<&Function, String> {
        let f = self.function(who, id)?;
        match f.kind {
            functions::Kind::Curve { .. } => Ok(f),
            functions::Kind::Parameter(_) => Err(format!(
                "`{who}`: `{}` (number {id}) is a parameter of `{}`, read with `val`, not a drawn function",
                f.name, f.file
            )),
        }
    }

    fn contour(&self, who: &str, id: i64) -> Result<&Contour, String> {
        usize::try_from(id)
            .ok()
            .and_then(|i| self.contours.get(i))
            .ok_or_else(|| {
                let names: Vec<String> = self
                    .contours
                    .iter()
                    .enumerate()
                    .map(|(i, c)| format!("{i} `{}`", c.name))
                    .collect();
                format!(
                    "`{who}`: there is no contour number {id}: the model's contours are {}{}",
                    names.join(", "),
                    if self.contours.len() == 1 {
                        " (lpfg's default circle; no `.cset` or `.con` file was read)"
                    } else {
                        ""
                    }
                )
            })
    }

    /// Evaluates accessor `f` on checked arguments.
    pub fn call(&self, f: Accessor, args: &[Value]) -> Result<Value, String> {
        let id = args[0].as_f64();
        let id = if id.is_finite() { id as i64 } else { -1 };
        let x = |i: usize| args[i].as_f64() as f32;
        let float = |v: f32| Value::Float(v as f64);
        let v3 = |p: [f32; 3]| Value::V3(glam::DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
        Ok(match f {
            Accessor::Func => {
                let f = self.curve_fn("func", id)?;
                float(f.value(x(1)).unwrap_or(0.0))
            }
            Accessor::PFunc
            | Accessor::CurveScale
            | Accessor::CurveSetPoint
            | Accessor::CurveRecalculate
            | Accessor::CurveReset => {
                return Err(format!(
                    "`{f:?}` changes the model: it is evaluated by `call_mut`"
                ))
            }
            Accessor::TFunc => {
                let f = self.curve_fn("tfunc", id)?;
                float(f.timeline_value(x(1)).unwrap_or(0.0))
            }
            Accessor::FuncTangent => {
                let f = self.curve_fn("funcTangent", id)?;
                let t = f.tangent(x(1)).unwrap_or([0.0; 2]);
                Value::V2(glam::DVec2::new(t[0] as f64, t[1] as f64))
            }
            Accessor::Val => {
                let f = self.function("val", id)?;
                match f.kind {
                    functions::Kind::Parameter(v) => float(v),
                    functions::Kind::Curve { .. } => {
                        return Err(format!(
                            "`val`: `{}` (number {id}) is a function of `{}`, read with `func`, not a parameter of a `.vset` file",
                            f.name, f.file
                        ))
                    }
                }
            }
            Accessor::CurveX => float(self.contour("curveX", id)?.point(x(1))[0]),
            Accessor::CurveY => float(self.contour("curveY", id)?.point(x(1))[1]),
            Accessor::CurveZ => float(self.contour("curveZ", id)?.point(x(1))[2]),
            Accessor::CurveXY => {
                let p = self.contour("curveXY", id)?.point(x(1));
                Value::V2(glam::DVec2::new(p[0] as f64, p[1] as f64))
            }
            Accessor::CurveXYZ => v3(self.contour("curveXYZ", id)?.point(x(1))),
            Accessor::CurveNormal => v3(self.contour("curveNormal", id)?.normal(x(1))),
        })
    }
}

impl Model {
    /// Evaluates an accessor that changes the model ([`Accessor::changes_the_model`]);
    /// the others as [`Model::call`] does.
    pub fn call_mut(&mut self, f: Accessor, args: &[Value]) -> Result<Value, String> {
        let id = args[0].as_f64();
        let id = if id.is_finite() { id as i64 } else { -1 };
        let x = |i: usize| args[i].as_f64() as f32;
        let editable = |m: &mut Model, who: &str| -> Result<usize, String> {
            m.contour(who, id)?;
            if id == 0 {
                return Err(format!(
                    "`{who}`: contour 0 is lpfg's default circle, which has no control points to change"
                ));
            }
            Ok(id as usize)
        };
        match f {
            Accessor::PFunc => {
                let (lo, hi) = (x(2), x(3));
                if lo == hi {
                    return Err(format!("`pfunc`: the interval [{lo}, {hi}] has no length"));
                }
                self.curve_fn("pfunc", id)?;
                let f = &mut self.functions[id as usize - 1];
                // As lpfg does: the interval stays the function's.
                (f.low, f.up) = (lo, hi);
                Ok(Value::Float(f.timeline_value(x(1)).unwrap_or(0.0) as f64))
            }
            Accessor::CurveScale => {
                let k = editable(self, "curveScale")?;
                self.contours[k].scale([x(1), x(2), x(3)]);
                Ok(Value::Void)
            }
            Accessor::CurveSetPoint => {
                let k = editable(self, "curveSetPoint")?;
                let p = args[1].as_f64();
                let c = &mut self.contours[k];
                let n = c.controls.len();
                let inside = p >= 0.0 && p < n as f64;
                if !(inside && c.set_point(p as usize, [x(2), x(3), x(4)])) {
                    return Err(format!(
                        "`curveSetPoint`: contour `{}` has control points 0 to {} (multiplicities counted{}), not {p}",
                        c.name,
                        n - 1,
                        if c.closed && !c.end_points { ", and the three copies that close it first" } else { "" }
                    ));
                }
                Ok(Value::Void)
            }
            Accessor::CurveRecalculate => {
                let k = editable(self, "curveRecalculate")?;
                self.contours[k].recalculate();
                Ok(Value::Void)
            }
            Accessor::CurveReset => {
                let k = editable(self, "curveReset")?;
                self.contours[k].reset();
                Ok(Value::Void)
            }
            other => self.call(other, args),
        }
    }
}

impl crate::lang::model::ModelData for Model {
    fn call(&self, f: Accessor, args: &[Value]) -> Result<Value, String> {
        Model::call(self, f, args)
    }

    fn call_mut(&mut self, f: Accessor, args: &[Value]) -> Result<Value, String> {
        Model::call_mut(self, f, args)
    }

    fn boxed(&self) -> Box<dyn crate::lang::model::ModelData> {
        Box::new(self.clone())
    }

    fn into_any(self: std::sync::Arc<Self>) -> std::sync::Arc<dyn std::any::Any + Send + Sync> {
        self
    }
}

/// The model of a program that came without a folder: lpfg's default
/// circle alone (contour 0), shared by every such program.
pub fn default_ref() -> crate::lang::model::ModelRef {
    static DEFAULT: std::sync::LazyLock<crate::lang::model::ModelRef> =
        std::sync::LazyLock::new(|| {
            crate::lang::model::ModelRef(std::sync::Arc::new(Model::default()))
        });
    DEFAULT.clone()
}

/// The model `program` runs with: the one its folder gave, or the
/// default one (lpfg's default circle, nothing else) for a program that
/// came without a folder.
pub fn of(program: &crate::lang::Program) -> std::sync::Arc<Model> {
    std::sync::Arc::clone(&program.model.0)
        .into_any()
        .downcast::<Model>()
        .unwrap_or_default()
}
