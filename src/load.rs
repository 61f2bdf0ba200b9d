//! The one loader: a file is read once, lexed and preprocessed once, its
//! kind is decided from the tokens, and the tokens go to the parser of that
//! kind.

use std::path::{Path, PathBuf};

use crate::curve::Curve;
use crate::error::Error;
use crate::lang;
pub use crate::lang::compile::Precision;
use crate::model::{self, Model};
use crate::production::{Checked, Entry};
use crate::surface;
use crate::syntax::{parse, Diagnostic, SourceFile, Span};
use crate::system::System;

pub(crate) use crate::syntax::source::{front, read, Front};

/// Settings of loading.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// `#define` overrides, each `NAME=VALUE` (the binary's `-D`); they win
    /// over the file's own `#define`s and `angle:` values.
    pub defines: Vec<String>,
    /// What C's `float` is: single precision as in lpfg (the default), or
    /// double (`--double`). Surface grammars compute in double always.
    pub precision: Precision,
    /// How a model's environmental program is run (a `.e` file).
    pub environment: crate::enviro::Options,
}

impl LoadOptions {
    /// Adds one `NAME=VALUE` override.
    pub fn define(mut self, name_value: impl Into<String>) -> Self {
        self.defines.push(name_value.into());
        self
    }
}

/// Reads and checks a `.lsys` file: a curve L-system or a surface grammar,
/// told apart by its syntax (a `mesh:` directive, or a rule such as
/// `F(f) -> V(...) || E^3 F^3`, makes a surface grammar).
///
/// ```
/// # fn main() -> Result<(), subgram::Error> {
/// let root = env!("CARGO_MANIFEST_DIR");
/// let opts = subgram::LoadOptions::default();
/// let curve = subgram::load(format!("{root}/lsystems/curves/chaikin-13.lsys"), &opts)?;
/// assert!(matches!(curve, subgram::System::Curve(_)));
/// let loop_ = subgram::load(format!("{root}/lsystems/surfaces/loop.lsys"), &opts)?;
/// assert!(matches!(loop_, subgram::System::Surface(_)));
/// # Ok(()) }
/// ```
pub fn load(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<System, Error> {
    load_path(path.as_ref(), None, opts).map_err(at_most_some)
}

/// Loads `path` as [`load`] does, with its program's text replaced by
/// `text` (an editor's unsaved buffer): the files beside it (a model's
/// files, the view file, a base mesh) are read from the disk as usual. For
/// a model folder, `text` is its L-system's.
pub fn load_edited(
    path: impl AsRef<Path>,
    text: &str,
    opts: &LoadOptions,
) -> Result<System, Error> {
    load_path(path.as_ref(), Some(text), opts).map_err(at_most_some)
}

/// The L-system file that [`load`] reads for `path`: the model folder's
/// L-system, or the file itself. (`subgram serve` reads it.)
#[cfg(feature = "serve")]
pub fn program_file(path: impl AsRef<Path>) -> Result<PathBuf, Error> {
    let path = path.as_ref();
    Ok(match model::find(path)? {
        Some(files) => files.lsystem,
        None => path.to_path_buf(),
    })
}

fn load_path(path: &Path, edited: Option<&str>, opts: &LoadOptions) -> Result<System, Error> {
    let text_of = |p: &Path| match edited {
        Some(t) => Ok(t.to_string()),
        None => read(p),
    };
    if let Some(files) = model::find(path)? {
        let m = Model::read(&files.files)?;
        let text = text_of(&files.lsystem)?;
        let environment = match &m.environment {
            Some(spec) => Some(crate::enviro::starter(spec, &opts.environment)?),
            None => None,
        };
        let mut c = load_model_file(&files.lsystem, text, m, &opts.defines, opts.precision)?;
        if environment.is_some() {
            // The communication modules get their answers: the warning
            // that they would not is not for this model.
            c.program
                .warnings
                .retain(|d| !crate::draw::coverage::is_environment_warning(&d.message));
        }
        c.environment = environment;
        return Ok(System::Curve(c));
    }
    let text = text_of(path)?;
    let view = read_view_file(path)?;
    let defines = view.defines(&opts.defines);
    let front = front(&path.display().to_string(), text, &defines)?;
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    match checked(front, Some(&dir))? {
        Ok(checked) => Ok(System::checked(checked, Some(path))),
        Err(front) => {
            let mut c = curve(front, opts.precision)?;
            view.give_to(&mut c);
            Ok(System::Curve(c))
        }
    }
}

/// The loader's table: each topology that programs are written for, asked
/// in this order whether a program is its own.
const TOPOLOGIES: [&Entry; 3] = [&surface::ENTRY, &crate::vv::ENTRY, &crate::shape::ENTRY];

/// The program checked by the topology that claims it (`dir`: the folder
/// its relative file names are read from), or its front back when none
/// does: a curve L-system.
fn checked(front: Front, dir: Option<&Path>) -> Result<Result<Checked, Front>, Error> {
    match TOPOLOGIES.iter().find(|t| (t.claims)(&front.tokens)) {
        Some(t) => Ok(Ok(with_stack(move || (t.check)(front, dir))?)),
        None => Ok(Err(front)),
    }
}

/// Loads an lpfg program with its model: the model's names are defined
/// first (`-D` overrides win over them), the program is checked as a
/// curve, and the model goes with it; what the model's files say without
/// refusing the program joins the checker's warnings.
fn load_model_file(
    path: &Path,
    text: String,
    m: Model,
    user: &[String],
    precision: Precision,
) -> Result<Curve, Error> {
    let view = read_view_file(path)?;
    let mut defines = m.defines();
    defines.retain(|d| {
        let name = d.split('=').next().unwrap_or("");
        !user
            .iter()
            .any(|u| u.split('=').next().map(str::trim) == Some(name))
    });
    // The view names, then the user's `-D`s, which win.
    defines.extend(view.defines(user));
    let first_line = text.lines().next().map_or(0, |l| l.trim_end().len());
    let lacks_lpfgall = !includes_lpfgall(&text);
    let front = front(&path.display().to_string(), text, &defines)?;
    let mut c = match curve(front, precision) {
        Ok(c) => c,
        Err(e) => return Err(name_missing_entities(e, &m)),
    };
    if lacks_lpfgall {
        c.program.warnings.insert(
            0,
            Diagnostic::new(
                Span::new(crate::syntax::FileId(0), 0, first_line),
                "no `#include <lpfgall.h>`: lpfg refuses an L+C program without it; \
                 subgram runs it as it is",
            ),
        );
    }
    for note in &m.notes {
        let file = c
            .sources
            .add(SourceFile::new(note.file.clone(), note.text.clone()));
        c.program.warnings.push(Diagnostic::new(
            Span::new(file, note.start, note.end),
            note.message.clone(),
        ));
    }
    c.program.model = lang::model::ModelRef(std::sync::Arc::new(m));
    view.give_to(&mut c);
    Ok(c)
}

/// True when `text` has a line `#include <lpfgall.h>` (or with quotes),
/// which lpfg requires of every L+C program.
fn includes_lpfgall(text: &str) -> bool {
    text.lines().any(|l| {
        let l = l.trim_start();
        l.strip_prefix('#')
            .map(str::trim_start)
            .and_then(|l| l.strip_prefix("include"))
            .is_some_and(|rest| {
                let name = rest.trim().trim_matches(['<', '>', '"']);
                name == "lpfgall.h"
            })
    })
}

/// A check that failed because the program names a function, contour or
/// parameter that no model file defines (`func(leaf_length, x)` with no
/// `leaf_length` in the `.fset`): the diagnostic at that name says so.
fn name_missing_entities(e: Error, m: &Model) -> Error {
    let Error::Program {
        sources,
        mut diagnostics,
    } = e
    else {
        return e;
    };
    for d in &mut diagnostics {
        let text = &sources.get(d.span.file).text;
        let (a, b) = (d.span.start as usize, d.span.end as usize);
        let Some(name) = text.get(a..b) else { continue };
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            continue;
        }
        // The call around the name: `accessor (` just before it.
        let before = text[..a].trim_end();
        let Some(before) = before.strip_suffix('(') else {
            continue;
        };
        let before = before.trim_end();
        let Some(acc) = model::ACCESSOR_NAMES.iter().find(|n| {
            before.ends_with(*n)
                && !before[..before.len() - n.len()]
                    .ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_')
        }) else {
            continue;
        };
        let what = if acc.starts_with("curve") {
            "contour: no `.cset` or `.con` file of the model defines it".to_string()
        } else if *acc == "val" {
            "parameter: no `.vset` file of the model defines it".to_string()
        } else {
            "function: no `.fset`, `.func` or `.tset` file of the model defines it".to_string()
        };
        let read: Vec<String> = m
            .files
            .iter()
            .filter_map(|p| p.file_name().map(|n| format!("`{}`", n.to_string_lossy())))
            .collect();
        d.message = format!(
            "`{name}` names no {what} ({})",
            if read.is_empty() {
                "the model has no files beside the program".to_string()
            } else {
                format!("the files read are {}", read.join(", "))
            }
        );
    }
    Error::Program {
        sources,
        diagnostics,
    }
}

/// What a program takes from the view file beside it (`*.v`, the first by
/// name; manual 8.1): a minimal reading, of the view names and the
/// turtle's settings only.
#[derive(Clone, Debug, Default)]
pub struct ViewFile {
    /// The views by number: the names of the `window:` commands in order
    /// (manual 8.1.1), after an unnamed view 0 when a `view:` command comes
    /// before the first window (lpfg's numbering).
    pub windows: Vec<String>,
    /// `corrected rotation:`, `tropism:`, `torque:` and `stropism:`.
    pub turtle: crate::draw::TurtleView,
    /// The file's name and text, and the lines it could not read (their
    /// byte ranges and what was expected), which are left out.
    file: Option<(String, String)>,
    problems: Vec<(usize, usize, String)>,
}

impl ViewFile {
    /// Gives the turtle settings to `c`, and the lines that could not be
    /// read as warnings at their place in the view file, which joins
    /// `c`'s sources.
    fn give_to(self, c: &mut Curve) {
        c.view = self.turtle;
        let Some((name, text)) = self.file.filter(|_| !self.problems.is_empty()) else {
            return;
        };
        let id = c.sources.add(SourceFile::new(name, text));
        for (start, end, message) in self.problems {
            c.program
                .warnings
                .push(Diagnostic::new(Span::new(id, start, end), message));
        }
        c.program
            .warnings
            .sort_by_key(|d| (d.span.file.0, d.span.start));
    }

    /// The view names defined as their numbers, as lpfg defines them for
    /// the program, then `user`'s `-D`s, which win.
    fn defines(&self, user: &[String]) -> Vec<String> {
        let mut d: Vec<String> = self
            .windows
            .iter()
            .enumerate()
            .filter(|(_, n)| is_identifier(n))
            .map(|(i, n)| format!("{n}={i}"))
            .collect();
        d.extend(user.iter().cloned());
        d
    }
}

/// Reads the view file beside the program at `path` (see [`ViewFile`]);
/// the default when there is none. A tropism command that cannot be read
/// is left out, with a warning at its line (lpfg too says so and goes
/// on).
pub fn read_view_file(path: &Path) -> Result<ViewFile, Error> {
    use crate::draw::tropism::{SimpleTropism, Tropism};
    // A model folder holds its view file; a program has it beside it.
    let dir = if path.is_dir() {
        path
    } else {
        match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        }
    };
    let mut view = ViewFile::default();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(view);
    };
    let mut files: Vec<PathBuf> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "v") && p.is_file())
        // Named as the program is: `view.v` beside `lsystem.l`.
        .map(|p| match path.parent() {
            _ if path.is_dir() => p,
            Some(d) if !d.as_os_str().is_empty() => p,
            _ => p.file_name().map(PathBuf::from).unwrap_or(p),
        })
        .collect();
    files.sort();
    // A model's own view file (the one its `specifications` name) comes
    // before the others.
    if let Ok(Some(model)) = model::find(path) {
        if let Some(i) = files.iter().position(|f| {
            model
                .files
                .iter()
                .any(|m| m.file_name().is_some() && m.file_name() == f.file_name())
        }) {
            files.swap(0, i);
        }
    }
    let Some(file) = files.first() else {
        return Ok(view);
    };
    let text = read(file)?;
    let mut at = 0;
    for raw in text.split_inclusive('\n') {
        let line_start = at;
        at += raw.len();
        let raw = raw.trim_end_matches(['\n', '\r']);
        let line = raw.split("//").next().unwrap_or("").trim();
        let start = line_start + raw.find(line).unwrap_or(0);
        let mut bad = |kind: &str, expected: &str| {
            view.problems.push((
                start,
                start + line.len(),
                format!(
                    "this {kind} cannot be read and is left out (lpfg refuses it too): expected {expected}"
                ),
            ))
        };
        if let Some(rest) = line.strip_prefix("window:") {
            view.windows
                .push(rest.split_whitespace().next().unwrap_or("").to_string());
        } else if line.starts_with("view:") && view.windows.is_empty() {
            view.windows.push(String::new());
        } else if let Some(rest) = line.strip_prefix("corrected rotation:") {
            view.turtle.corrected_rotation = rest.trim() != "off";
        } else if let Some(rest) = line.strip_prefix("tropism:") {
            match Tropism::parse(rest, false) {
                Some(t) => view.turtle.tropisms.list.push(t),
                None => bad("tropism", "`T: x y z` (a vector that is not null), then any of `A: angle` (-180 to 180), `I: intensity` (not 0), `E: elasticity`, `S: step`, with numbers separated by blanks"),
            }
        } else if let Some(rest) = line.strip_prefix("torque:") {
            match Tropism::parse(rest, true) {
                Some(t) => view.turtle.tropisms.list.push(t),
                None => bad("torque", "`T: x y z` (a vector that is not null), then any of `I: intensity` (not 0), `E: elasticity`, `S: step`, with numbers separated by blanks"),
            }
        } else if let Some(rest) = line.strip_prefix("stropism:") {
            match SimpleTropism::parse(rest) {
                Some(t) => view.turtle.tropisms.simple = t,
                None => bad("simple tropism", "`x y z, elasticity`"),
            }
        }
    }
    view.file = Some((file.display().to_string(), text));
    Ok(view)
}

/// The names of the views of the view file beside the program at `path`
/// (see [`ViewFile::windows`]); none when it cannot be read.
pub fn window_names(path: &Path) -> Vec<String> {
    read_view_file(path).map(|v| v.windows).unwrap_or_default()
}

/// True for a C identifier: a view name the program can use.
pub(crate) fn is_identifier(name: &str) -> bool {
    name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && name.chars().next().is_some_and(|c| !c.is_ascii_digit())
}

/// Checks program text, as [`load`] does a file; `name` is the file name in
/// messages. A surface grammar's `mesh:` is then relative to the current
/// folder.
pub fn load_text(name: &str, text: &str, opts: &LoadOptions) -> Result<System, Error> {
    load_text_as(name, text, opts).map_err(at_most_some)
}

fn load_text_as(name: &str, text: &str, opts: &LoadOptions) -> Result<System, Error> {
    let front = front(name, text.to_string(), &opts.defines)?;
    match checked(front, None)? {
        Ok(checked) => Ok(System::checked(checked, None)),
        Err(front) => Ok(System::Curve(curve(front, opts.precision)?)),
    }
}

/// Loads a file as a curve L-system, whatever its syntax says; `defines`
/// are `NAME=VALUE` overrides. The file is read alone: [`load`] reads an
/// lpfg model folder, or a `.l` file with the files beside it.
pub fn load_file(path: impl AsRef<Path>, defines: &[String]) -> Result<Curve, Error> {
    load_file_with(path.as_ref(), defines, Precision::Single)
}

/// [`load_file`] with `float` in the given precision.
pub fn load_file_with(
    path: &Path,
    defines: &[String],
    precision: Precision,
) -> Result<Curve, Error> {
    let text = read(path)?;
    let view = read_view_file(path)?;
    let defines = view.defines(defines);
    let mut c = curve(
        front(&path.display().to_string(), text, &defines)?,
        precision,
    )
    .map_err(at_most_some)?;
    view.give_to(&mut c);
    Ok(c)
}

/// Checks text as a curve L-system; `name` is the file name in messages.
///
/// ```
/// let src = "
///     V2f v1(0, 0), v2(0, 1), v3(1, 1), v4(1, 0);
///     module P(V2f);
///     ring L-system: 1;
///     derivation length: 2;
///     Axiom: P(v1) P(v2) P(v3) P(v4);
///     P(vl) < P(v) > P(vr) -> P(0.25*vl + 0.75*v) P(0.75*v + 0.25*vr)
/// ";
/// let chaikin = subgram::load_str("chaikin.lsys", src, &[]).unwrap();
/// let derived = chaikin.derive(Default::default()).unwrap();
/// assert_eq!(derived.word.len(), 16); // 4 points, doubled twice
/// ```
pub fn load_str(name: &str, text: &str, defines: &[String]) -> Result<Curve, Error> {
    load_str_with(name, text, defines, Precision::Single)
}

/// [`load_str`] with `float` in the given precision.
pub fn load_str_with(
    name: &str,
    text: &str,
    defines: &[String],
    precision: Precision,
) -> Result<Curve, Error> {
    curve(front(name, text.to_string(), defines)?, precision).map_err(at_most_some)
}

/// The most diagnostics a check reports; the count of the others follows
/// them, so that a file with an error on every line does not print
/// megabytes.
pub const MAX_DIAGNOSTICS: usize = 100;

/// `e` with at most [`MAX_DIAGNOSTICS`] diagnostics and a last one, at the
/// first left out, that counts the rest.
fn at_most_some(e: Error) -> Error {
    match e {
        Error::Program {
            sources,
            mut diagnostics,
        } if diagnostics.len() > MAX_DIAGNOSTICS + 1 => {
            let rest = diagnostics.len() - MAX_DIAGNOSTICS;
            let next = diagnostics[MAX_DIAGNOSTICS].span;
            diagnostics.truncate(MAX_DIAGNOSTICS);
            diagnostics.push(Diagnostic::new(
                next,
                format!(
                    "{rest} more errors from here on are not shown (at most {MAX_DIAGNOSTICS} \
                     are); fix the ones above first"
                ),
            ));
            Error::Program {
                sources,
                diagnostics,
            }
        }
        e => e,
    }
}

/// Parses and checks preprocessed tokens as a curve L-system.
pub(crate) fn curve(front: Front, precision: Precision) -> Result<Curve, Error> {
    with_stack(move || check_curve(front, precision))
}

/// Where the front end's recursion runs: parsing and checking descend once
/// per level of nesting (up to the limit of 100 levels, each a chain of a
/// dozen calls), which must not depend on how much stack the caller's
/// thread has (a test thread has 2 MiB, and a debug build's frames are
/// large).
const FRONT_STACK: usize = 64 << 20;

/// Runs `f` on a thread with [`FRONT_STACK`] bytes of stack (reserved, and
/// used as needed), or on this thread when no thread can be made.
pub(crate) fn with_stack<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    let mut f = Some(f);
    // The run's deadline and its list of inputs go with the work: a mesh
    // that a shape grammar inserts is read under the one and noted in the
    // other.
    let deadline = crate::deadline::current();
    let spawned = std::thread::scope(|s| {
        std::thread::Builder::new()
            .name("subgram-check".into())
            .stack_size(FRONT_STACK)
            .spawn_scoped(s, || {
                let _scope = crate::deadline::scope(deadline);
                crate::files::noting_inputs(|| (f.take().expect("not run yet"))())
            })
            .map(|h| h.join())
    });
    match spawned {
        Ok(Ok((v, inputs))) => {
            crate::files::note_inputs(inputs);
            v
        }
        Ok(Err(panic)) => std::panic::resume_unwind(panic),
        Err(_) => (f.take().expect("not run: the thread was not made"))(),
    }
}

fn check_curve(front: Front, precision: Precision) -> Result<Curve, Error> {
    let eof = front.eof();
    let Front {
        sources, tokens, ..
    } = front;
    let predefined: Vec<&str> = lang::modules::PREDEFINED.iter().map(|(n, _)| *n).collect();
    let file = match parse::parse_file(&tokens, eof, &predefined) {
        Ok(f) => f,
        Err(d) => {
            return Err(Error::Program {
                sources,
                diagnostics: vec![d],
            })
        }
    };
    match lang::compile::compile_with(&file, precision) {
        Ok(mut program) => {
            // lpfg's default circle, until a model folder gives more.
            program.model = model::default_ref();
            // What the turtle does not act on is said, not dropped.
            program
                .warnings
                .extend(crate::draw::coverage::warnings(&program));
            program
                .warnings
                .sort_by_key(|d| (d.span.file.0, d.span.start));
            Ok(Curve {
                program,
                sources,
                view: Default::default(),
                environment: None,
            })
        }
        Err(mut diagnostics) => {
            for d in &mut diagnostics {
                if d.span == Span::default() {
                    d.span = eof;
                }
            }
            Err(Error::Program {
                sources,
                diagnostics,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kind(text: &str) -> &'static str {
        let f = front("t.lsys", text.to_string(), &[]).unwrap();
        if surface::is_surface(&f.tokens) {
            "surface"
        } else {
            "curve"
        }
    }

    #[test]
    fn the_kind_comes_from_the_tokens() {
        assert_eq!(kind("mesh: \"cube.obj\";\nV(v) -> V(v = v);\n"), "surface");
        assert_eq!(kind("F(f) -> V(v = avg(f)) || E^3 F^3;\n"), "surface");
        assert_eq!(kind("E(e) | F^2 -> V(v = avg(e)) || E^4 F^4;\n"), "surface");
        // `mesh:` inside a comment or a string is not a directive.
        assert_eq!(
            kind("// mesh: \"cube.obj\";\nmodule A;\nAxiom: A;\n"),
            "curve"
        );
        // C's `||` in a condition, or inside a module's parentheses, and a
        // `||` on a later line do not make a surface rule.
        let curve = "module F(float);\nAxiom: F(1);\nF(x) -> F(x + 1)\n\
                     F(x) : x > 2 || x < 0 -> F(x)\nF(x) -> F(x > 1 || x < 0)\n";
        assert_eq!(kind(curve), "curve");
        assert_eq!(
            kind("module V(float);\nV(x) : { produce V(x) || V(x); }\n"),
            "curve"
        );
        // With `angle:`, `|` turns the turtle around.
        assert_eq!(
            kind("angle: 90;\nAxiom: F(1);\nF(x) -> F(x)||F(x)\n"),
            "curve"
        );
        // The decision is made after preprocessing: a macro can spell the
        // directive, as the grammar's parser will read it.
        assert_eq!(kind("#define M mesh\nM: \"cube.obj\";\n"), "surface");
    }

    #[test]
    fn a_file_is_loaded_as_its_kind() {
        let opts = LoadOptions::default();
        let s = load_text("g.lsys", "F(f) -> V(v = avg(f)) || E^3 F^3;\n", &opts).unwrap();
        assert!(matches!(s, System::Surface(_)));
        let c = load_text("c.lsys", "module A;\nAxiom: A;\n", &opts).unwrap();
        assert!(matches!(c, System::Curve(_)));
    }

    #[test]
    fn defines_are_checked_and_applied() {
        let text = "#define N 2\nmodule A(int);\nAxiom: A(N);\n";
        let opts = LoadOptions::default().define("N=5");
        let System::Curve(c) = load_text("d.lsys", text, &opts).unwrap() else {
            panic!("a curve")
        };
        assert_eq!(c.derive(Default::default()).unwrap().word.len(), 1);
        let run = c.run(Default::default()).unwrap();
        assert_eq!(run.text(), "A(5)");
        for bad in ["N", "=5", "N M=5"] {
            let e = load_text("d.lsys", text, &LoadOptions::default().define(bad)).unwrap_err();
            assert!(matches!(e, Error::Usage(_)), "{bad}: {e:?}");
            assert!(e.to_string().contains("must have the form NAME=VALUE"));
        }
        // A `-D` value that does not lex points into its own source.
        let e = load_text("d.lsys", text, &LoadOptions::default().define("N=`")).unwrap_err();
        assert!(e.to_string().starts_with("<-D N>:1:1: error: "), "{e}");
    }

    #[test]
    fn errors_are_std_errors_without_an_error_prefix() {
        fn read_missing() -> Result<System, Box<dyn std::error::Error>> {
            Ok(load("no/such/file.lsys", &LoadOptions::default())?)
        }
        let e = read_missing().unwrap_err();
        assert!(e.source().is_some(), "the io::Error is the source");
        assert!(e
            .to_string()
            .starts_with("cannot read `no/such/file.lsys`: "));
        // Every diagnostic, each with its line and caret, a blank line between.
        let text = "module A;\nAxiom: B;\nA -> C\n";
        let e = load_text("two.lsys", text, &LoadOptions::default()).unwrap_err();
        assert_eq!(e.diagnostics().len(), 2, "{e}");
        assert!(e.has_location());
        let shown = e.to_string();
        let blocks: Vec<&str> = shown.split("\n\n").collect();
        assert_eq!(blocks.len(), 2, "{shown}");
        assert!(blocks[0].starts_with("two.lsys:2:8: error: "), "{shown}");
        assert!(blocks[1].starts_with("two.lsys:3:6: error: "), "{shown}");
        assert!(blocks
            .iter()
            .all(|b| b.lines().count() == 4 && b.ends_with('^')));
    }

    #[test]
    fn a_failed_run_points_at_the_rule() {
        let text = "module A(float);\nderivation length: 1;\nAxiom: A(1);\n\
                    A(x) : { produce A(x / 0); }\n";
        let c = load_str("r.lsys", text, &[]).unwrap();
        let e = c.derive(Default::default()).unwrap_err();
        let shown = e.to_string();
        assert!(shown.starts_with("r.lsys:4:"), "{shown}");
        assert!(
            shown.contains("\n4 | A(x) : { produce A(x / 0); }\n"),
            "{shown}"
        );
        let too_many = crate::DeriveOptions::default().with_steps(crate::MAX_STEPS + 1);
        assert!(matches!(c.derive(too_many), Err(Error::Usage(_))));
    }
}
