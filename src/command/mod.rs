//! The commands of the `subgram` binary, one function each, with their
//! arguments as plain structs. A command returns the text it prints on
//! standard output, if any; it writes its output files whole or not at all,
//! and never over one of its inputs.

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::curve::FigureOptions;
use crate::deadline::{Deadline, DEFAULT_TIMEOUT};
use crate::error::Error;
use crate::lang::ProgramOutput;
use crate::load::{load, LoadOptions, Precision};
use crate::mesh::{self, Mesh, PolygonSoup};
use crate::render::{self, Rgba, Scene, View};
use crate::reverse::{self, Phase, ReverseOptions, Scheme};
use crate::rewrite::derive::{DEFAULT_MAX_MODULES, MAX_STEPS};
use crate::system::{load_mesh, Progress, RunOptions, Surface, System};

/// `subgram check FILE [-D NAME=VALUE]…`: reports every diagnostic, or one
/// line that says what the file holds.
pub fn check(file: &str, defines: &[String], double: bool) -> Result<String, Error> {
    let opts = load_options(defines, double);
    let system = load(file, &opts)?;
    let ok = match &system {
        System::Surface(s) => format!(
            "{file}: ok (a surface grammar of {})",
            counted(s.grammar.rules.len(), "rule", "rules")
        ),
        System::Curve(c) => {
            use crate::syntax::ast::Section;
            let p = &c.program;
            let of = |s: Section| p.rules.iter().filter(|r| r.section == s).count();
            let mut parts = vec![counted(
                of(Section::Productions),
                "production",
                "productions",
            )];
            for (s, one, many) in [
                (
                    Section::Decomposition,
                    "decomposition rule",
                    "decomposition rules",
                ),
                (
                    Section::Interpretation,
                    "interpretation rule",
                    "interpretation rules",
                ),
            ] {
                if of(s) > 0 {
                    parts.push(counted(of(s), one, many));
                }
            }
            // The program's own modules: those it declares, or, in the
            // single-character notation, those its rules and axiom name;
            // not lpfg's predefined ones.
            let own = p.alphabet.kinds.iter().filter(|k| !k.builtin).count();
            parts.push(counted(own, "module of its own", "modules of its own"));
            format!("{file}: ok ({})", parts.join(", "))
        }
        System::Vv(v) => format!(
            "{file}: ok (a vv program of {})",
            counted(v.program.program.functions.len(), "function", "functions")
        ),
        System::Shapes(s) => format!(
            "{file}: ok (a shape grammar of {})",
            counted(s.rules(), "rule", "rules")
        ),
    };
    // Warnings first, each with its line and caret, then the verdict.
    let mut out: Vec<String> = system.warnings();
    out.push(ok);
    Ok(out.join("\n\n"))
}

/// `1 rule`, `2 rules`.
fn counted(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The arguments of `subgram derive`.
#[derive(Clone, Debug)]
pub struct DeriveArgs {
    pub file: String,
    /// `-n`: overrides `derivation length:`.
    pub steps: Option<u64>,
    /// `--format json` instead of text.
    pub json: bool,
    pub defines: Vec<String>,
    /// `--double`: `float` in double precision instead of lpfg's single.
    pub double: bool,
    pub max_modules: usize,
    pub phase: usize,
    /// Print the word after interpretation rules.
    pub interpreted: bool,
    /// Shape grammars: `--max-shapes`, the most shapes a derivation makes.
    pub max_shapes: Option<usize>,
    /// `--seed`: seeds every random number generator (see
    /// [`RunOptions::seed`]).
    pub seed: Option<u32>,
    /// `--timeout`: the command stops with an error after this long.
    pub timeout: Option<Duration>,
    /// `--allow-writes DIR`: the program may write files, under DIR.
    pub allow_writes: Option<PathBuf>,
    /// What the program prints: the caller keeps a clone and prints it.
    pub output: ProgramOutput,
    /// `-o FILE`: the word goes to this file (whole, or not at all)
    /// instead of to `derive_to`'s writer.
    pub word_file: Option<PathBuf>,
}

impl DeriveArgs {
    pub fn new(file: impl Into<String>) -> DeriveArgs {
        DeriveArgs {
            file: file.into(),
            steps: None,
            json: false,
            defines: Vec::new(),
            double: false,
            max_modules: DEFAULT_MAX_MODULES,
            phase: 0,
            interpreted: false,
            max_shapes: None,
            seed: None,
            timeout: Some(DEFAULT_TIMEOUT),
            allow_writes: None,
            output: ProgramOutput::default(),
            word_file: None,
        }
    }
}

/// What `derive` prints: the word (or the mesh's description) for standard
/// output, and the checker's warnings for standard error.
#[derive(Clone, Debug)]
pub struct Printed {
    pub text: String,
    /// Each rendered with `file:line:col: warning:`, the line and a caret.
    pub warnings: Vec<String>,
}

/// `subgram derive`: a curve's final word (or its interpretation) as text
/// or JSON; for a surface grammar, the subdivided mesh's description. The
/// program's warnings come with it.
pub fn derive(a: &DeriveArgs, progress: impl FnMut(Progress)) -> Result<Printed, Error> {
    let mut out = Vec::new();
    let mut warnings = Vec::new();
    derive_to(
        a,
        progress,
        |w| {
            warnings = w.to_vec();
            Ok(())
        },
        &mut out,
    )?;
    let mut text = String::from_utf8(out).map_err(|e| Error::Failed(e.to_string()))?;
    if text.ends_with('\n') {
        text.pop();
    }
    Ok(Printed { text, warnings })
}

/// [`derive()`], the result written to `out` as it is made (a large word is
/// never held as text), followed by a newline. `before` hears the
/// program's warnings once the result is ready and before the first byte
/// of it is written (the binary prints what the program printed, then the
/// warnings, there). A broken pipe ends the writing quietly.
pub fn derive_to(
    a: &DeriveArgs,
    progress: impl FnMut(Progress),
    before: impl FnOnce(&[String]) -> Result<(), Error>,
    out: &mut dyn std::io::Write,
) -> Result<(), Error> {
    in_run(a.timeout, None, || {
        derive_to_in_run(a, progress, before, out)
    })
}

fn derive_to_in_run(
    a: &DeriveArgs,
    progress: impl FnMut(Progress),
    before: impl FnOnce(&[String]) -> Result<(), Error>,
    out: &mut dyn std::io::Write,
) -> Result<(), Error> {
    let deadline = crate::deadline::current();
    if let Some(path) = a.word_file.as_deref() {
        // derive has no --force: its program is never replaced.
        if same_file(path, Path::new(&a.file)) {
            return Err(Error::Usage(format!(
                "the output `{}` is the program: writing it would replace it; name another output",
                path.display()
            )));
        }
    }
    let dir = writes_folder(&a.allow_writes, &a.output)?;
    let system = load(&a.file, &load_options(&a.defines, a.double))?;
    let warnings = system.warnings();
    let before = || before(&warnings);
    let Some(path) = &a.word_file else {
        return derive_out(a, &system, deadline, dir.as_deref(), progress, before, out);
    };
    // Into a temporary beside the file, put in place when the run
    // commits; the derivation's own error comes back as it is.
    let mut failed = None;
    let written = crate::files::atomic::write_atomic_with(path, |w| {
        derive_out(a, &system, deadline, dir.as_deref(), progress, before, w).map_err(|e| {
            failed = Some(e);
            std::io::Error::other("the derivation failed")
        })
    });
    match (written, failed) {
        (_, Some(e)) => Err(e),
        (Err(e), None) => Err(Error::write(path, e)),
        (Ok(()), None) => Ok(()),
    }
}

/// A mesh's counts after `steps` steps, as text or JSON.
fn mesh_counts(
    as_json: bool,
    steps: usize,
    info: &(impl std::fmt::Display + serde::Serialize),
) -> Result<String, Error> {
    if as_json {
        json(info)
    } else {
        Ok(format!(
            "after {steps} step(s):\n{}",
            info.to_string().trim_end()
        ))
    }
}

/// What a write to the output came to: a broken pipe is no error (the
/// reader has what it wanted), anything else is.
fn wrote(r: std::io::Result<()>) -> Result<(), Error> {
    match r {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Error::Failed(format!("cannot write the output: {e}"))),
    }
}

fn derive_out(
    a: &DeriveArgs,
    system: &System,
    deadline: Option<Deadline>,
    dir: Option<&Path>,
    progress: impl FnMut(Progress),
    before: impl FnOnce() -> Result<(), Error>,
    out: &mut dyn std::io::Write,
) -> Result<(), Error> {
    use std::io::Write;
    let mut out = std::io::BufWriter::with_capacity(1 << 16, out);
    let text = derive_text(a, system, deadline, dir, progress, before, &mut out)?;
    wrote(
        out.write_all(text.as_bytes())
            .and_then(|_| out.write_all(b"\n"))
            .and_then(|_| out.flush()),
    )
}

/// The result as text for meshes; for a curve, the word is written to
/// `out` here (after `before`), and the text returned is empty.
fn derive_text(
    a: &DeriveArgs,
    system: &System,
    deadline: Option<Deadline>,
    dir: Option<&Path>,
    progress: impl FnMut(Progress),
    before: impl FnOnce() -> Result<(), Error>,
    out: &mut impl std::io::Write,
) -> Result<String, Error> {
    let opts = RunOptions {
        steps: a.steps,
        max_modules: a.max_modules,
        phase: a.phase,
        seed: a.seed,
        base_mesh: None,
        deadline,
        output: a.output.clone(),
        max_shapes: a.max_shapes,
    };
    match system {
        System::Vv(v) => {
            if a.interpreted {
                return Err(Error::Usage(
                    "--interpreted prints the word after interpretation rules; a vv program has \
                     no word, only its mesh"
                        .into(),
                ));
            }
            let run = v.run(&opts, progress)?;
            // The files the program wrote (`fopen`), never over its inputs.
            let mut inputs = vec![PathBuf::from(&a.file)];
            inputs.extend(v.base_mesh());
            write_program_files(&a.output, dir, &as_paths(&inputs))?;
            before()?;
            mesh_counts(a.json, run.steps as usize, &run.info)
        }
        System::Surface(s) => {
            let run = s.subdivide(&opts, progress)?;
            let info = run.mesh.info();
            before()?;
            mesh_counts(a.json, run.steps, &info)
        }
        System::Shapes(s) => {
            if a.interpreted {
                return Err(Error::Usage(
                    "--interpreted prints the word after interpretation rules; a shape grammar \
                     has no word, only its tree of shapes"
                        .into(),
                ));
            }
            let run = s.derive(&opts)?;
            before()?;
            let counts = run.counts();
            if a.json {
                Ok(format!(
                    "{{\"counts\": {},\n\"shapes\": {}}}",
                    json(&counts)?,
                    s.tree_json(&run)
                ))
            } else {
                Ok(format!(
                    "{}{}shapes: {}\nterminal shapes: {}\nfaces: {}\nsmoothing groups: {}",
                    s.tree_text(&run),
                    s.groups_text(&run),
                    counts.shapes,
                    counts.terminal_shapes,
                    counts.faces,
                    counts.smoothing_groups
                ))
            }
        }
        System::Curve(c) => {
            check_steps(a.steps)?;
            let mut run = c.run(opts.derive_options())?;
            let interpreted = if a.interpreted {
                Some(run.interpreted()?)
            } else {
                None
            };
            write_program_files(&a.output, dir, &[Path::new(&a.file)])?;
            before()?;
            let word = interpreted.as_ref().unwrap_or(run.word());
            wrote(if a.json {
                c.write_word_json(out, word, run.ring(), run.step())
            } else {
                c.write_word_text(out, word)
            })?;
            Ok(String::new())
        }
    }
}

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
            defines: Vec::new(),
            double: false,
            max_modules: DEFAULT_MAX_MODULES,
            phase: 0,
            seed: None,
            timeout: Some(DEFAULT_TIMEOUT),
            force: false,
            allow_writes: None,
            program_output: ProgramOutput::default(),
        }
    }
}

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
    let looks = MeshLooks::of_render(a);
    if mesh::io::Format::from_path(file).is_some() {
        // Found before the mesh is read.
        Picture::from_path(output).map_err(|_| {
            Error::Usage(format!(
                "cannot tell the format of `{}`: render draws a mesh as a picture (.png, .svg); \
                 `subgram mesh convert` writes it as a mesh",
                output.display()
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
                "cannot tell the format of `{}`: render writes pictures (.png, .svg) and 3D \
                 geometry (.obj, .ply, .glb)",
                output.display()
            ))
        })?,
    };
    let system = load(file, &load_options(&a.defines, a.double))?;
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
    let system = crate::load::load_edited(file, text, &load_options(&a.defines, a.double))?;
    let mut warnings = system.warnings();
    let mut a = a.clone();
    a.allow_writes = None;
    a.force = true;
    let mut out = Out::Memory(Vec::new());
    warnings.extend(render_system(
        &a,
        system,
        (&looks, format),
        deadline,
        |_| {},
        &mut out,
    )?);
    let mut files = match out {
        Out::Memory(files) => files,
        Out::Files => Vec::new(),
    };
    if files.is_empty() {
        return Err(Error::Failed("nothing was drawn".into()));
    }
    Ok(Drawn {
        picture: files.swap_remove(0).1,
        warnings,
    })
}

/// The arguments of `subgram infer`.
#[derive(Clone, Debug, Default)]
pub struct InferArgs {
    /// The matrix as text (`;` between rows): a whole matrix, or one old
    /// point's band of rows (closed schemes).
    pub rows: Option<String>,
    /// The matrix from a file (a row per line).
    pub rows_file: Option<String>,
    /// A mask: the weights `a_k` of `new_j = Σ a_{j − arity·i} old_i`.
    pub mask: Option<String>,
    /// New points per old point for a mask (default 2).
    pub arity: Option<usize>,
    /// The matrix has boundary rows: endmarker productions.
    pub open: bool,
    /// A reverse subdivision matrix (each new point from a group of old
    /// points): a pseudo-L-system production.
    pub reverse: bool,
    /// The grouping written out (closed and reverse schemes).
    pub shift: Option<i64>,
    /// List every grouping instead of writing the program.
    pub list: bool,
    /// Open schemes: the ordered short form (first match).
    pub ordered: bool,
    /// Write the program here instead of returning it.
    pub output: Option<String>,
}

/// `subgram infer`: productions from a subdivision matrix (paper 002
/// §5–7). Returns the `.lsys` program (or, with `list`, every grouping),
/// unless it was written to `output`.
pub fn infer(a: &InferArgs) -> Result<String, Error> {
    in_run(None, None, || infer_in_run(a))
}

fn infer_in_run(a: &InferArgs) -> Result<String, Error> {
    use crate::infer;
    let sources = [a.rows.is_some(), a.rows_file.is_some(), a.mask.is_some()];
    if sources.iter().filter(|&&x| x).count() != 1 {
        return Err(Error::Usage(
            "give the scheme once: --rows \"R1; R2; …\", --rows-file FILE or --mask \"a0 a1 …\""
                .into(),
        ));
    }
    if a.open && a.reverse {
        return Err(Error::Usage(
            "--open and --reverse: reverse subdivision of open curves is not inferred; give a closed reverse matrix".into(),
        ));
    }
    let (source, matrix) = if let Some(mask) = &a.mask {
        if a.open || a.reverse {
            return Err(Error::Usage(
                "a mask describes a closed scheme: give the matrix with --rows for --open or --reverse".into(),
            ));
        }
        let arity = a.arity.unwrap_or(2);
        if !(2..=8).contains(&arity) {
            return Err(Error::Usage(format!(
                "--arity {arity}: give 2 to 8 new points per old point"
            )));
        }
        let m = infer::parse_mask("--mask", mask)?;
        if m.len() > 64 {
            return Err(Error::Usage(
                "a mask of more than 64 weights is not inferred".into(),
            ));
        }
        let n = (4 * m.len().div_ceil(arity) + 8).max(16);
        let mut matrix = infer::mask_matrix(&m, arity, n);
        // A mask has no first row: number the shifts from the grouping
        // written by default (the shortest symmetric one), as d = 0.
        let c = infer::infer_closed(&matrix, None)?.chosen;
        let r = matrix.rows.len() as i64;
        matrix.rows.rotate_left(c.rem_euclid(r) as usize);
        let mask = mask.split_whitespace().collect::<Vec<_>>().join(" ");
        (format!("the mask {mask}"), matrix)
    } else {
        let (name, text) = match (&a.rows, &a.rows_file) {
            (Some(r), _) => ("--rows".to_string(), r.clone()),
            (_, Some(f)) => {
                let p = Path::new(f);
                let bytes = reverse::input::read_bounded(p, reverse::input::MAX_INPUT_BYTES)?;
                let text = reverse::input::utf8_text(f, bytes, "a matrix file")?;
                (f.clone(), text)
            }
            _ => unreachable_usage()?,
        };
        let m = infer::parse_matrix(&name, &text)?;
        // A whole closed matrix has a whole number (2 or more) of rows per
        // column; anything else is one old point's band of rows.
        let whole = m.rows.len() >= 2 * m.cols && m.rows.len() % m.cols == 0;
        let m = if a.open || a.reverse || whole {
            m
        } else {
            if a.arity.is_some_and(|r| r != m.rows.len()) {
                return Err(Error::Usage(format!(
                    "--arity {}: the band has {} rows, one per new point of an old point",
                    a.arity.unwrap_or(0),
                    m.rows.len()
                )));
            }
            if m.rows.len() > 8 || m.cols > 64 {
                return Err(Error::Failed(format!(
                    "{name}: {} rows of {} columns are neither a whole closed matrix (each block of rows the one before moved a column) nor a band of one old point's rows (at most 8 rows of 64 columns); use --open for a matrix with boundary rows",
                    m.rows.len(),
                    m.cols
                )));
            }
            infer::band_matrix(&m, (4 * m.cols + 8).max(16))
        };
        let what = if a.rows.is_some() {
            format!(
                "the rows {}",
                text.split_whitespace().collect::<Vec<_>>().join(" ")
            )
        } else {
            format!("the matrix in {name}")
        };
        (what, m)
    };
    let inference = if a.reverse {
        infer::infer_reverse(&matrix, a.shift)?
    } else if a.open {
        if a.shift.is_some() {
            return Err(Error::Usage(
                "--shift chooses among the groupings of a closed scheme; an open one takes the paper's (the ends keep fewer points)".into(),
            ));
        }
        infer::infer_open(&matrix)?
    } else {
        infer::infer_closed(&matrix, a.shift)?
    };
    let text = if a.list {
        inference.report()
    } else {
        inference.lsys(&source, a.ordered)
    };
    match &a.output {
        Some(out) => {
            write_file(Path::new(out), text.as_bytes())?;
            Ok(String::new())
        }
        None => Ok(text),
    }
}

fn unreachable_usage<T>() -> Result<T, Error> {
    Err(Error::Usage(
        "give the scheme with --rows, --rows-file or --mask".into(),
    ))
}

/// How `watch` watches.
#[derive(Clone, Debug)]
pub struct WatchOptions {
    /// How often the files are looked at.
    pub poll: Duration,
    /// Return after this many renders; `None`: until the process stops.
    pub max_renders: Option<usize>,
}

impl Default for WatchOptions {
    fn default() -> Self {
        WatchOptions {
            poll: Duration::from_millis(200),
            max_renders: None,
        }
    }
}

/// What `watch` reports as it goes.
#[derive(Debug)]
pub enum WatchEvent<'a> {
    /// The picture was written, with the program's warnings.
    Rendered {
        output: &'a str,
        seconds: f64,
        warnings: &'a [String],
    },
    /// The render failed; the last picture (if any) is left as it was.
    Failed { error: &'a Error },
    /// Waiting for one of these files to change.
    Watching { files: &'a [PathBuf] },
}

/// A file's identity and state as `watch` compares them: `None` when it
/// cannot be read (a change too: an editor replacing it, or deleting it).
type Stamp = Option<(std::time::SystemTime, u64, u64)>;

fn stamp(path: &Path) -> Stamp {
    let m = std::fs::metadata(path).ok()?;
    #[cfg(unix)]
    let inode = std::os::unix::fs::MetadataExt::ino(&m);
    #[cfg(not(unix))]
    let inode = 0;
    Some((m.modified().ok()?, m.len(), inode))
}

/// `subgram watch`: renders as `render` does, then again whenever the
/// file or one of the files it reads (`System::inputs`: a model's files, a
/// base mesh, included texts) changes. An error is reported and the last
/// picture kept: pictures are written atomically, so a failed render
/// leaves the last good one in place. A usage error (an unknown view, an
/// output format) ends the watch, as no edit of the files can mend it.
pub fn watch(
    a: &RenderArgs,
    w: &WatchOptions,
    mut report: impl FnMut(WatchEvent),
) -> Result<(), Error> {
    let file = PathBuf::from(&a.file);
    let mut files = vec![file.clone()];
    let mut renders = 0;
    loop {
        // What the program reads now; after an error that stops the
        // loading, the files of the last good load (and the file itself).
        if mesh::io::Format::from_path(&file).is_none() {
            // Under the render's time limit: a pipe among the files waits
            // no longer than the render would.
            let loaded = crate::deadline::within(a.timeout, || {
                load(&file, &load_options(&a.defines, a.double))
            });
            if let Ok(system) = loaded {
                files = system.inputs();
                if !files.contains(&file) {
                    files.insert(0, file.clone());
                }
            }
        }
        let before: Vec<Stamp> = files.iter().map(|f| stamp(f)).collect();
        let t = std::time::Instant::now();
        match render(a, |_| {}) {
            Ok(warnings) => report(WatchEvent::Rendered {
                output: &a.output,
                seconds: t.elapsed().as_secs_f64(),
                warnings: &warnings,
            }),
            Err(e @ Error::Usage(_)) => return Err(e),
            Err(error) => report(WatchEvent::Failed { error: &error }),
        }
        renders += 1;
        if w.max_renders.is_some_and(|m| renders >= m) {
            return Ok(());
        }
        report(WatchEvent::Watching { files: &files });
        // A change during the render counts: the stamps are from before it.
        loop {
            std::thread::sleep(w.poll);
            if files.iter().map(|f| stamp(f)).ne(before.iter().cloned()) {
                // Let an editor finish writing before the file is read.
                std::thread::sleep(w.poll.min(Duration::from_millis(50)));
                break;
            }
        }
    }
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
            write_soup_picture(&run.soup, output, looks, out)?;
            Ok(Vec::new())
        }
        System::Curve(c) if wants_solid(a, &c, export.is_some()) => {
            render_solid(a, &c, (looks, format), deadline, out)
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
            let model_background = model.colours.as_ref().map(|m| {
                let [r, g, b] = m.background();
                Rgba(r, g, b, 255)
            });
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
            let figures = match format {
                Picture::Png => c.png_figures(&figure)?,
                Picture::Svg => c.figures(&figure)?.try_map(|s| picture_bytes(s, format))?,
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

/// Whether `render` draws this L-system's 3D geometry (see [`Solidity`]).
fn wants_solid(a: &RenderArgs, c: &crate::Curve, export: bool) -> bool {
    use crate::model::view::{LineStyle, RenderMode};
    let m = &*crate::model::of(&c.program);
    match a.solid {
        _ if export => true,
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
    out: &mut Out,
) -> Result<Vec<String>, Error> {
    use crate::draw::solid::SolidOptions;
    use crate::model::view::LineStyle;
    let output = Path::new(&a.output);
    let file = Path::new(&a.file);
    if a.each {
        return Err(Error::Usage(
            "--each draws the 2D steps side by side; add --lines, or draw one step in 3D".into(),
        ));
    }
    let (opts, dir) = curve_run(a, deadline)?;
    let model = &*crate::model::of(&c.program);
    let (w, h) = looks.size;
    let mut run = c.run(opts.derive_options())?;
    let mut sopts = SolidOptions::default();
    let picture = crate::export::Format::from_path(output).is_none();
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
    let scene = run.solid(&sopts)?;
    write_program_files(&a.program_output, dir.as_deref(), &[file, output])?;
    if crate::export::Format::from_path(output).is_some() {
        if scene.triangle_count() == 0 {
            return Err(Error::Failed(
                "nothing to export: the turtle made no 3D geometry (no lines, surfaces, polygons or spheres)".into(),
            ));
        }
        crate::export::write(&scene, output)?;
        return Ok(Vec::new());
    }
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
    let model_background = model.colours.as_ref().map(|m| {
        let [r, g, b] = m.background();
        Rgba(r, g, b, 255)
    });
    ropts.background = a
        .background
        .or(model_background)
        .unwrap_or(Rgba(255, 255, 255, 255));
    let bytes = match format {
        Picture::Png => crate::render::raster::render_png(&scene, &ropts)?,
        Picture::Svg => crate::render::raster::render_svg(&scene, &ropts)?.into_bytes(),
    };
    out.put(vec![(output.to_path_buf(), bytes)])?;
    Ok(Vec::new())
}

/// The folder of `--allow-writes`, checked to be one, and `output` told
/// that the program may write files.
fn writes_folder(dir: &Option<PathBuf>, output: &ProgramOutput) -> Result<Option<PathBuf>, Error> {
    let Some(dir) = dir else { return Ok(None) };
    if !dir.is_dir() {
        return Err(Error::Usage(format!(
            "--allow-writes {}: not a folder; create it first",
            dir.display()
        )));
    }
    output.allow_writes();
    Ok(Some(dir.clone()))
}

/// Writes the files the program wrote (`fopen`, `fprintf`) under `dir`,
/// all or none, never over one of `inputs`, and never outside `dir`
/// (the paths were checked when opened; a link inside `dir` that leads out
/// is refused here).
fn write_program_files(
    output: &ProgramOutput,
    dir: Option<&Path>,
    inputs: &[&Path],
) -> Result<(), Error> {
    let files = output.files();
    let Some(dir) = dir else { return Ok(()) };
    if files.is_empty() {
        return Ok(());
    }
    let root = dir
        .canonicalize()
        .map_err(|e| Error::Failed(format!("cannot read the folder {}: {e}", dir.display())))?;
    // Every path is checked, links resolved, before any folder is made.
    let mut out: Vec<(PathBuf, Vec<u8>)> = Vec::new();
    let mut folders: Vec<PathBuf> = Vec::new();
    for (name, text) in files {
        let path = root.join(&name);
        let parent = path.parent().unwrap_or(&root).to_path_buf();
        // The deepest folder on the way that exists: it must lie inside
        // the root once its links are resolved; what is missing below it
        // is made of plain names (fopen allows no `..`), so stays inside.
        let mut existing = parent.as_path();
        while std::fs::symlink_metadata(existing).is_err() {
            existing = existing.parent().unwrap_or(&root);
        }
        let real = existing
            .canonicalize()
            .map_err(|e| Error::write(existing, e))?;
        if !real.starts_with(&root) {
            return Err(Error::Failed(format!(
                "the program's file `{name}` would be written outside {}",
                dir.display()
            )));
        }
        if !real.is_dir() {
            return Err(Error::Failed(format!(
                "the program's file `{name}` cannot be written: {} is not a folder",
                existing.display()
            )));
        }
        folders.push(parent);
        out.push((path, text.into_bytes()));
    }
    for parent in &folders {
        crate::files::make_folders(parent).map_err(|e| Error::write(parent, e))?;
    }
    let paths: Vec<&Path> = out.iter().map(|(p, _)| p.as_path()).collect();
    refuse_overwrite(&paths, inputs, false)?;
    let files: Vec<(&Path, Vec<u8>)> = out.iter().map(|(p, b)| (p.as_path(), b.clone())).collect();
    write_files(&files)
}

/// The arguments of `subgram subdivide`.
#[derive(Clone, Debug)]
pub struct SubdivideArgs {
    /// The base mesh; by default the grammar's `mesh:`.
    pub mesh: Option<String>,
    pub grammar: String,
    pub steps: Option<u64>,
    /// `.obj`, `.off`, `.ply`, `.png` or `.svg`.
    pub output: String,
    pub defines: Vec<String>,
    /// For pictures: iso, front, back, left, right, top or bottom.
    pub view: Option<String>,
    /// For pictures: `lit`, `normals` or `reflection`; the last two draw
    /// no edges.
    pub shading: Option<String>,
    /// For pictures: no edges.
    pub no_wireframe: bool,
    /// Shape grammars: seeds the random choice of rules.
    pub seed: Option<u32>,
    /// `--timeout`: the command stops with an error after this long.
    pub timeout: Option<Duration>,
    /// Write the output even over one of the inputs.
    pub force: bool,
    /// What a vv program prints: the caller keeps a clone and prints it.
    pub program_output: ProgramOutput,
}

/// What a `subdivide --grammar` file holds.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Kind {
    Surface,
    Vv,
    Shapes,
}

/// `subgram subdivide`: runs a surface grammar or a vv program on a mesh,
/// or derives a shape grammar, and writes the mesh or its picture. The
/// file is read and lexed once.
pub fn subdivide(a: &SubdivideArgs, progress: impl FnMut(Progress)) -> Result<Vec<String>, Error> {
    in_run(a.timeout, Some(a.force), || subdivide_in_run(a, progress))
}

fn subdivide_in_run(
    a: &SubdivideArgs,
    progress: impl FnMut(Progress),
) -> Result<Vec<String>, Error> {
    // One large mesh: freed working memory goes back at once, not kept
    // under the next step's peak.
    crate::huge::return_freed_memory();
    let deadline = crate::deadline::current();
    let grammar = Path::new(&a.grammar);
    let output = Path::new(&a.output);
    let mut inputs = vec![grammar.to_path_buf()];
    inputs.extend(a.mesh.as_deref().map(PathBuf::from));
    refuse_overwrite(&[output], &as_paths(&inputs), a.force)?;
    let opts = RunOptions {
        steps: a.steps,
        base_mesh: a.mesh.as_ref().map(PathBuf::from),
        deadline,
        output: a.program_output.clone(),
        ..RunOptions::default()
    };
    if Picture::from_path(output).is_err()
        && mesh::io::Format::from_path(output).is_none()
        && !is_glb(output)
    {
        return Err(Error::Usage(format!(
            "cannot tell the format of `{}`: subdivide writes meshes (.obj, .off, .ply, .glb) \
             and pictures (.png, .svg)",
            output.display()
        )));
    }
    let d = crate::render::mesh::MeshView::default();
    if Picture::from_path(output).is_err() && (a.shading.is_some() || a.no_wireframe) {
        let flag = if a.shading.is_some() {
            "--shading"
        } else {
            "--no-wireframe"
        };
        return Err(Error::Usage(format!(
            "`{flag}` is for pictures, and `{}` is not one (name it .png or .svg)",
            output.display()
        )));
    }
    let shading = match a.shading.as_deref() {
        None => d.shading,
        Some(name) => crate::render::mesh::Shading::from_name(name).ok_or_else(|| {
            Error::Usage(format!(
                "`--shading {name}` is not a shading: use lit, normals or reflection"
            ))
        })?,
    };
    let looks = MeshLooks {
        size: (d.width, d.height),
        background: d.background,
        view: a.view.as_deref(),
        wireframe: d.wireframe && !a.no_wireframe && shading == crate::render::mesh::Shading::Lit,
        shading,
    };
    // The file is read and lexed once; its tokens say what it is.
    let text = crate::load::read(grammar)?;
    let front = crate::load::front(&grammar.display().to_string(), text, &a.defines)?;
    let kind = if crate::shape::is_shapes(&front.tokens) {
        Kind::Shapes
    } else if crate::vv::is_vv(&front.tokens) {
        Kind::Vv
    } else {
        Kind::Surface
    };
    // A shape grammar writes its terminal shapes.
    if kind == Kind::Shapes {
        let dir = grammar.parent().unwrap_or(Path::new("")).to_path_buf();
        let g = crate::load::with_stack(move || crate::shape::from_front(front, Some(&dir)))?;
        let shapes = crate::system::Shapes::new(g);
        let opts = RunOptions {
            seed: a.seed,
            ..opts
        };
        // An OBJ's MTL file is written too, never over an input either;
        // the meshes the grammar inserts and its scheme files are inputs.
        inputs.extend(shapes.inputs());
        let mtl = output.with_extension("mtl");
        refuse_overwrite(&[output, &mtl], &as_paths(&inputs), a.force)?;
        let run = shapes.derive(&opts)?;
        return write_shapes(&shapes, &run, output, &looks).map(|()| Vec::new());
    }
    // A vv program subdivides too.
    if kind == Kind::Vv {
        let program = crate::load::with_stack(move || crate::vv::from_front(front))?;
        let v = crate::system::Vv::new(program, Some(grammar));
        if a.mesh.is_none() {
            inputs.extend(v.base_mesh());
            refuse_overwrite(&[output], &as_paths(&inputs), a.force)?;
        }
        let run = v.run(&opts, progress)?;
        if Picture::from_path(output).is_ok() {
            return write_soup_picture(&run.soup, output, &looks, &mut Out::Files)
                .map(|()| Vec::new());
        }
        if is_glb(output) {
            return write_soup_glb(&run.soup, &[], output).map(|()| Vec::new());
        }
        mesh::io::write(output, &run.soup)?;
        return Ok(Vec::new());
    }
    let g = crate::load::with_stack(move || crate::surface::from_front(front))?;
    let surface = Surface::new(g, Some(grammar));
    if a.mesh.is_none() {
        // The grammar's own `mesh:` is an input too.
        inputs.extend(surface.base_mesh());
        refuse_overwrite(&[output], &as_paths(&inputs), a.force)?;
    }
    let run = surface.subdivide(&opts, progress)?;
    if Picture::from_path(output).is_ok() {
        return write_mesh_picture(&run.mesh, output, &looks, &mut Out::Files).map(|()| Vec::new());
    }
    if is_glb(output) {
        return write_soup_glb(&run.mesh.to_quad_soup(), &[], output).map(|()| Vec::new());
    }
    write_mesh(output, &run.mesh, false)
}

/// The output is binary glTF (`.glb`), which meshes are exported to as a
/// 3D scene.
fn is_glb(output: &Path) -> bool {
    crate::export::Format::from_path(output) == Some(crate::export::Format::Glb)
}

/// A polygon mesh as binary glTF: its faces fanned into triangles, one
/// primitive per face colour (the default blue without colours).
fn write_soup_glb(soup: &PolygonSoup, colours: &[Rgba], output: &Path) -> Result<(), Error> {
    let scene = crate::render::mesh::soup_scene3(soup, colours);
    if scene.triangle_count() == 0 {
        return Err(Error::Failed(
            "the mesh has no face of non-zero area to write".into(),
        ));
    }
    crate::export::write_glb(&scene, output)
}

/// Writes `m` to `output` (basic blocks as quads unless `triangles`) with
/// its sharp edges where the format carries them (PLY); a warning for
/// each kind of sharpness the file cannot hold, which would otherwise be
/// lost without a word.
fn write_mesh(output: &Path, m: &Mesh, triangles: bool) -> Result<Vec<String>, Error> {
    let sharp = mesh::io::write_mesh(output, m, triangles)?;
    let ply = mesh::io::Format::from_path(output) == Some(mesh::io::Format::Ply);
    let edges = |n: usize| format!("{n} sharp edge{}", if n == 1 { "" } else { "s" });
    let mut lost = Vec::new();
    if !ply && !sharp.edges.is_empty() {
        lost.push(format!(
            "{} (write .ply, which keeps them)",
            edges(sharp.edges.len())
        ));
    }
    if sharp.edges_left_out > 0 {
        lost.push(format!(
            "{} that are no edges of its polygons (quad diagonals)",
            edges(sharp.edges_left_out)
        ));
    }
    if sharp.vertices_left_out > 0 {
        let n = sharp.vertices_left_out;
        lost.push(format!(
            "{n} sharp vert{} (no mesh format carries them)",
            if n == 1 { "ex" } else { "ices" }
        ));
    }
    let mut warnings: Vec<String> = lost
        .into_iter()
        .map(|what| {
            format!(
                "{}: warning: the file does not keep {what}",
                output.display()
            )
        })
        .collect();
    // A file of creases beside the output is read with it from now on.
    let side = output.with_extension(mesh::io::CREASES_EXTENSION);
    if side.is_file() {
        warnings.push(format!(
            "{}: warning: `{}` beside it, which this command did not write, will be read with \
             it as its creases",
            output.display(),
            side.display()
        ));
    }
    Ok(warnings)
}

/// A shape derivation to `.obj` (with its `.mtl` beside it, both or
/// neither written), `.ply`, `.off`, or a picture.
fn write_shapes(
    shapes: &crate::system::Shapes,
    run: &crate::system::ShapeRun,
    output: &Path,
    looks: &MeshLooks,
) -> Result<(), Error> {
    if Picture::from_path(output).is_ok() {
        return write_shapes_picture(run, output, looks, &mut Out::Files);
    }
    if mesh::io::Format::from_path(output) == Some(mesh::io::Format::Obj) {
        let mtl = output.with_extension("mtl");
        let mtl_name = mtl
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "shapes.mtl".into());
        let (obj, mtl_text) = shapes.obj(run, &mtl_name);
        return write_files(&[(output, obj.into_bytes()), (&mtl, mtl_text.into_bytes())]);
    }
    if run.soup.faces.is_empty() {
        return Err(Error::Failed(
            "the derivation left no terminal shape with faces to write".into(),
        ));
    }
    if is_glb(output) {
        return write_soup_glb(&run.soup, &run.colours, output);
    }
    Ok(mesh::io::write(output, &run.soup)?)
}

/// The terminal shapes, each face in its shape's colour, seen with y up
/// (CityEngine's convention, which shape grammars follow).
fn write_shapes_picture(
    run: &crate::system::ShapeRun,
    output: &Path,
    looks: &MeshLooks,
    out: &mut Out,
) -> Result<(), Error> {
    let format = Picture::from_path(output)?;
    let mut mv = looks.check()?;
    // The mesh views are named for z up; turn them to y up.
    let y_up = |v: glam::DVec3| glam::DVec3::new(v.x, v.z, -v.y);
    mv.direction = y_up(mv.direction);
    mv.up = y_up(mv.up);
    mv.face_colours = run.colours.clone();
    if run.soup.faces.is_empty() {
        return Err(Error::Failed(
            "the derivation left no terminal shape with faces to draw".into(),
        ));
    }
    crate::render::mesh::validate(&run.soup, &mv)?;
    let bytes = match format {
        Picture::Svg => crate::render::mesh::render_svg(&run.soup, &mv).into_bytes(),
        Picture::Png => crate::render::mesh::render_png(&run.soup, &mv)?,
    };
    out.put(vec![(output.to_path_buf(), bytes)])
}

/// `subgram mesh info`: counts, boundary loops, Euler characteristic, genus,
/// valences and levels, as text or JSON.
pub fn mesh_info(file: &str, as_json: bool) -> Result<String, Error> {
    let info = load_mesh(Path::new(file))?.info();
    if as_json {
        json(&info)
    } else {
        Ok(info.to_string().trim_end().to_string())
    }
}

/// `subgram mesh convert`: checks a mesh and writes it in the format of
/// `output`'s extension, basic blocks as quads unless `triangles`. The
/// output may be the input only with `force` (a conversion may lose what
/// subgram does not keep, such as texture coordinates and normals).
pub fn mesh_convert(
    input: &str,
    output: &str,
    triangles: bool,
    force: bool,
) -> Result<Vec<String>, Error> {
    in_run(None, Some(force), || {
        mesh_convert_in_run(input, output, triangles, force)
    })
}

fn mesh_convert_in_run(
    input: &str,
    output: &str,
    triangles: bool,
    force: bool,
) -> Result<Vec<String>, Error> {
    let (input, output) = (Path::new(input), Path::new(output));
    if mesh::io::Format::from_path(output).is_none() {
        // As for pictures: an output whose format cannot be told is a
        // usage error, found before anything is read.
        let ext = output
            .extension()
            .map_or(String::new(), |e| format!(" `.{}`", e.to_string_lossy()));
        return Err(Error::Usage(format!(
            "{}: unknown mesh format{ext}: expected a file ending in .obj, .off or .ply",
            output.display()
        )));
    }
    refuse_overwrite(&[output], &[input], force)?;
    let m = load_mesh(input)?;
    write_mesh(output, &m, triangles)
}

/// The arguments of `subgram reverse`.
#[derive(Clone, Debug)]
pub struct ReverseArgs {
    /// Points (`x y` or CSV), an SVG shape, or a PNG silhouette.
    pub input: String,
    pub steps: usize,
    /// The coarse polygon: `.csv`, `.svg`, or `x y` lines.
    pub output: String,
    /// A scheme file instead of the built-in Chaikin schemes.
    pub scheme: Option<String>,
    pub phase: Phase,
    /// Treat the contour as open.
    pub open: bool,
    /// How a PNG silhouette is read (threshold, which side is the shape).
    pub silhouette: reverse::input::Silhouette,
    /// The picture of input, coarse polygon and reconstruction.
    pub figure: Option<String>,
    /// Return the report (point counts and reconstruction errors).
    pub report: bool,
    /// The report as JSON.
    pub json: bool,
    /// Where to store the details that restore the input exactly.
    pub details: Option<String>,
    /// `--timeout`: the command stops with an error after this long.
    pub timeout: Option<Duration>,
    /// Write the outputs even over one of the inputs.
    pub force: bool,
    /// The size limit of the input file, in bytes.
    pub max_input: u64,
}

impl ReverseArgs {
    pub fn new(input: impl Into<String>, steps: usize, output: impl Into<String>) -> ReverseArgs {
        ReverseArgs {
            input: input.into(),
            steps,
            output: output.into(),
            scheme: None,
            phase: Phase::Auto,
            open: false,
            silhouette: reverse::input::Silhouette::default(),
            figure: None,
            report: false,
            json: false,
            details: None,
            force: false,
            max_input: reverse::input::MAX_INPUT_BYTES,
            timeout: Some(DEFAULT_TIMEOUT),
        }
    }
}

/// `subgram reverse`: reverse-subdivides a contour; returns the report when
/// one was asked for. Everything is computed before anything is written,
/// and the outputs (coarse polygon, details, figure) are written all or
/// none.
pub fn reverse(a: &ReverseArgs) -> Result<Option<String>, Error> {
    in_run(a.timeout, Some(a.force), || reverse_in_run(a))
}

fn reverse_in_run(a: &ReverseArgs) -> Result<Option<String>, Error> {
    let deadline = crate::deadline::current();
    let fig = a
        .figure
        .as_ref()
        .map(|f| Ok::<_, Error>((Path::new(f), Picture::from_path(Path::new(f))?)))
        .transpose()?;
    let input = Path::new(&a.input);
    let mut inputs = vec![input];
    inputs.extend(a.scheme.as_deref().map(Path::new));
    let out = Path::new(&a.output);
    let outputs: Vec<&Path> = [Some(&a.output), a.details.as_ref(), a.figure.as_ref()]
        .into_iter()
        .flatten()
        .map(Path::new)
        .collect();
    refuse_overwrite(&outputs, &inputs, a.force)?;
    let mut contour = reverse::input::read_with(input, a.max_input, &a.silhouette)?;
    if a.open {
        contour.closed = false;
    }
    let mut scheme = match &a.scheme {
        Some(s) => Scheme::from_file(Path::new(s), contour.closed)?,
        None => Scheme::builtin(contour.closed),
    };
    scheme.deadline = deadline;
    let opts = ReverseOptions {
        steps: a.steps,
        phase: a.phase,
        details: a.details.is_some(),
    };
    let r = reverse::reverse(&scheme, &contour, &opts)?;
    let mut files: Vec<(&Path, Vec<u8>)> = vec![(
        out,
        reverse::format_points(&r.coarse, contour.closed, out).into_bytes(),
    )];
    if let (Some(path), Some(d)) = (&a.details, &r.details) {
        let text = serde_json::to_string(d).map_err(|e| Error::Failed(e.to_string()))?;
        files.push((Path::new(path), text.into_bytes()));
    }
    let mut printed = None;
    if a.report || fig.is_some() {
        let rep = reverse::report(&scheme, &contour, &r)?;
        if let Some((path, format)) = fig {
            let rec = scheme.forward(&r.coarse, r.steps.len())?;
            let events = reverse::figure_events(&contour, &r.coarse, &rec);
            let scene = render::scene(&[events], &Default::default())?;
            files.push((path, picture_bytes(&scene, format)?));
        }
        if a.report {
            printed = Some(if a.json { json(&rep)? } else { rep.to_string() });
        }
    }
    write_files(&files)?;
    Ok(printed)
}

/// The arguments of `subgram reconstruct`.
#[derive(Clone, Debug)]
pub struct ReconstructArgs {
    pub coarse: String,
    pub details: String,
    pub output: String,
    /// Restore only this many levels (default: all).
    pub level: Option<usize>,
    /// The scheme the details were made with (default: as recorded).
    pub scheme: Option<String>,
    /// `--timeout`: the command stops with an error after this long.
    pub timeout: Option<Duration>,
    /// Write the output even over one of the inputs.
    pub force: bool,
    /// The size limit of each input file, in bytes.
    pub max_input: u64,
}

/// `subgram reconstruct`: restores a contour from a coarse polygon and its
/// details.
pub fn reconstruct(a: &ReconstructArgs) -> Result<(), Error> {
    in_run(a.timeout, Some(a.force), || reconstruct_in_run(a))
}

fn reconstruct_in_run(a: &ReconstructArgs) -> Result<(), Error> {
    let deadline = crate::deadline::current();
    let (coarse, details, output) = (
        Path::new(&a.coarse),
        Path::new(&a.details),
        Path::new(&a.output),
    );
    let mut inputs = vec![coarse, details];
    inputs.extend(a.scheme.as_deref().map(Path::new));
    refuse_overwrite(&[output], &inputs, a.force)?;
    let d = reverse::DetailsFile::read(details, a.max_input)?;
    let c = reverse::input::read_with_limit(coarse, a.max_input)?;
    let recorded = &d.details.scheme;
    let mut scheme = match &a.scheme {
        Some(s) => Scheme::from_file(Path::new(s), d.details.closed)?,
        None if recorded.starts_with("builtin:") => Scheme::builtin(d.details.closed),
        None => {
            let p = Path::new(recorded);
            refuse_overwrite(&[output], &[p], a.force)?;
            // The scheme the details file names: a problem with it is
            // shown at its name in the details file.
            Scheme::from_file(p, d.details.closed).map_err(|e| match e {
                Error::Io { .. } => d.error(
                    reverse::details::Place::Scheme,
                    format!("the scheme these details were made with: {e}"),
                ),
                e => e,
            })?
        }
    };
    scheme.deadline = deadline;
    let pts = reverse::reconstruct_file(&scheme, &c.points, &d, a.level)?;
    write_files(&[(
        output,
        reverse::format_points(&pts, d.details.closed, output).into_bytes(),
    )])
}

/// A picture format, told by a file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Picture {
    Png,
    Svg,
}

impl Picture {
    /// `.png` or `.svg` (any case); any other name is a usage error.
    pub fn from_path(path: &Path) -> Result<Picture, Error> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(Picture::Png),
            Some("svg") => Ok(Picture::Svg),
            _ => Err(Error::Usage(format!(
                "cannot tell the format of `{}`: name it .png or .svg",
                path.display()
            ))),
        }
    }
}

/// Draws `scene` in `format` and writes it to `path` whole, or not at all.
pub fn write_picture(scene: &Scene, path: &Path, format: Picture) -> Result<(), Error> {
    write_file(path, &picture_bytes(scene, format)?)
}

/// Writes the main view to `output` and each other view that the view
/// file names to `OUTPUT-NAME.EXT` beside it, all or none. Returns a
/// warning for each view that `UseView` activated and the view file does
/// not define (lpfg ignores those too).
fn write_views(
    figures: crate::Figures<Vec<u8>>,
    program: &Path,
    output: &Path,
    force: bool,
    out: &mut Out,
) -> Result<Vec<String>, Error> {
    let names = crate::load::window_names(program);
    let mut files: Vec<(PathBuf, Vec<u8>)> = vec![(output.to_path_buf(), figures.main)];
    let mut warnings = Vec::new();
    for (view, picture) in figures.views {
        let name = usize::try_from(view)
            .ok()
            .and_then(|v| names.get(v))
            .filter(|n| crate::load::is_identifier(n));
        let Some(name) = name else {
            warnings.push(format!(
                "{}: warning: `UseView({view})`: the view file defines no view {view}, so it is not drawn",
                program.display()
            ));
            continue;
        };
        files.push((view_path(output, name), picture));
    }
    let outputs: Vec<&Path> = files.iter().map(|(p, _)| p.as_path()).collect();
    refuse_overwrite(&outputs, &[program], force)?;
    out.put(files)?;
    Ok(warnings)
}

/// `out.png` and view `Top`: `out-Top.png`, in the same folder.
fn view_path(output: &Path, name: &str) -> PathBuf {
    let stem = output.file_stem().unwrap_or_default().to_string_lossy();
    let file = match output.extension() {
        Some(ext) => format!("{stem}-{name}.{}", ext.to_string_lossy()),
        None => format!("{stem}-{name}"),
    };
    output.with_file_name(file)
}

/// `scene` drawn in `format`.
fn picture_bytes(scene: &Scene, format: Picture) -> Result<Vec<u8>, Error> {
    Ok(match format {
        Picture::Svg => render::svg::render(scene).into_bytes(),
        Picture::Png => render::png::render(scene)?,
    })
}

/// Where pictures go: written to their files (atomically, all or none),
/// or kept in memory (`serve` writes nothing).
enum Out {
    Files,
    Memory(Vec<(PathBuf, Vec<u8>)>),
}

impl Out {
    /// Writes, or keeps, every file or none.
    fn put(&mut self, files: Vec<(PathBuf, Vec<u8>)>) -> Result<(), Error> {
        match self {
            Out::Files => {
                let all: Vec<(&Path, &[u8])> = files
                    .iter()
                    .map(|(p, b)| (p.as_path(), b.as_slice()))
                    .collect();
                crate::files::atomic::write_all_atomic(&all)
                    .map_err(|(path, e)| Error::write(path, e))
            }
            Out::Memory(kept) => {
                kept.extend(files);
                Ok(())
            }
        }
    }
}

/// How a mesh is drawn.
struct MeshLooks<'a> {
    size: (u32, u32),
    background: Rgba,
    view: Option<&'a str>,
    wireframe: bool,
    shading: crate::render::mesh::Shading,
}

impl<'a> MeshLooks<'a> {
    /// How `render` draws a mesh: its size (800×800 by default),
    /// background (white by default), view and wireframe, lit.
    fn of_render(a: &'a RenderArgs) -> MeshLooks<'a> {
        MeshLooks {
            size: a.size.unwrap_or((800, 800)),
            background: a.background.unwrap_or(Rgba(255, 255, 255, 255)),
            view: a.view.as_deref(),
            wireframe: a.wireframe,
            shading: crate::render::mesh::Shading::Lit,
        }
    }
}

impl MeshLooks<'_> {
    /// The view: the default one, or a named one.
    fn check(&self) -> Result<crate::render::mesh::MeshView, Error> {
        let mut mv = crate::render::mesh::MeshView {
            width: self.size.0,
            height: self.size.1,
            background: self.background,
            wireframe: self.wireframe,
            shading: self.shading,
            ..Default::default()
        };
        if let Some(name) = self.view {
            let Some((dir, up)) = crate::render::mesh::view_direction(name) else {
                return Err(Error::Usage(format!(
                    "`--view {name}` is not a view of a mesh: use iso, front, back, left, right, top or bottom"
                )));
            };
            mv.direction = dir;
            mv.up = up;
        }
        Ok(mv)
    }
}

/// A mesh's picture, flat-shaded, to `.png` or `.svg`.
fn write_mesh_picture(
    m: &Mesh,
    output: &Path,
    looks: &MeshLooks,
    out: &mut Out,
) -> Result<(), Error> {
    write_soup_picture(&m.to_quad_soup(), output, looks, out)
}

fn write_soup_picture(
    soup: &PolygonSoup,
    output: &Path,
    looks: &MeshLooks,
    out: &mut Out,
) -> Result<(), Error> {
    let format = Picture::from_path(output)?;
    let mv = looks.check()?;
    crate::render::mesh::validate(soup, &mv)?;
    let bytes = match format {
        Picture::Svg => crate::render::mesh::render_svg(soup, &mv).into_bytes(),
        Picture::Png => crate::render::mesh::render_png(soup, &mv)?,
    };
    out.put(vec![(output.to_path_buf(), bytes)])
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    render::write_atomic(path, bytes).map_err(|e| Error::write(path, e))
}

/// Writes every file or none (see [`crate::files::atomic::write_all_atomic`]).
fn write_files(files: &[(&Path, Vec<u8>)]) -> Result<(), Error> {
    let all: Vec<(&Path, &[u8])> = files.iter().map(|(p, b)| (*p, b.as_slice())).collect();
    crate::files::atomic::write_all_atomic(&all).map_err(|(path, e)| Error::write(path, e))
}

fn json(value: &impl serde::Serialize) -> Result<String, Error> {
    serde_json::to_string_pretty(value).map_err(|e| Error::Failed(e.to_string()))
}

fn load_options(defines: &[String], double: bool) -> LoadOptions {
    LoadOptions {
        defines: defines.to_vec(),
        precision: if double {
            Precision::Double
        } else {
            Precision::Single
        },
    }
}

/// `-n` beyond the engine's limit is a usage error.
fn check_steps(steps: Option<u64>) -> Result<(), Error> {
    match steps {
        Some(n) if n > MAX_STEPS => Err(Error::Usage(format!(
            "-n {n} is beyond the limit of {MAX_STEPS} steps"
        ))),
        _ => Ok(()),
    }
}

/// Runs a command's work as one [`Run`](crate::files::Run): under the
/// deadline `timeout` from now (none: no limit), its outputs put in place
/// at the end, all or none, never over a file it read (unless `force` is
/// `Some(true)`; `None` where the command has no `--force`),
/// and not at all once the deadline has passed.
fn in_run<T>(
    timeout: Option<Duration>,
    force: Option<bool>,
    work: impl FnOnce() -> Result<T, Error>,
) -> Result<T, Error> {
    let run = crate::files::Run::begin(timeout.map(Deadline::after), force);
    let value = work()?;
    run.commit()?;
    Ok(value)
}

fn as_paths(v: &[PathBuf]) -> Vec<&Path> {
    v.iter().map(PathBuf::as_path).collect()
}

/// Where a path leads: the file itself when it exists (links and other
/// spellings resolved), else its resolved folder and its name.
fn resolved(p: &Path) -> PathBuf {
    if let Ok(c) = p.canonicalize() {
        return c;
    }
    let parent = p
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    match (parent.canonicalize(), p.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => p.to_path_buf(),
    }
}

/// True when `a` and `b` name one file: the same device and inode where
/// both exist (hard links too), else the same resolved path.
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        use std::os::unix::fs::MetadataExt;
        return (ma.dev(), ma.ino()) == (mb.dev(), mb.ino());
    }
    resolved(a) == resolved(b)
}

/// Before anything is read or written: an output named twice is refused,
/// and so is an output that is one of the command's inputs, unless `force`
/// (a usage error, exit code 2).
fn refuse_overwrite(outputs: &[&Path], inputs: &[&Path], force: bool) -> Result<(), Error> {
    for (k, out) in outputs.iter().enumerate() {
        if let Some(first) = outputs[..k].iter().find(|o| same_file(o, out)) {
            return Err(Error::Usage(format!(
                "`{}` and `{}` are the same output file; name two different files",
                first.display(),
                out.display()
            )));
        }
    }
    if force {
        return Ok(());
    }
    for out in outputs {
        if let Some(input) = inputs.iter().find(|i| same_file(i, out)) {
            let which = if input == out {
                "an input of this command".to_string()
            } else {
                format!("the same file as the input `{}`", input.display())
            };
            return Err(Error::Usage(format!(
                "the output `{}` is {which}: writing it would replace the input; name another output, or add --force to replace it",
                out.display()
            )));
        }
    }
    Ok(())
}

/// The arguments of `subgram analyze`.
#[derive(Clone, Debug, Default)]
pub struct AnalyzeArgs {
    pub file: String,
    /// `--format json` instead of text.
    pub json: bool,
    pub defines: Vec<String>,
    /// `--picture OUT.svg`: the characteristic maps' control nets.
    pub picture: Option<String>,
}

/// `subgram analyze FILE [--format json] [-D NAME=VALUE]…`: what the
/// subdivision scheme in FILE is (see [`crate::analyze`]), as text or JSON.
pub fn analyze(a: &AnalyzeArgs) -> Result<String, Error> {
    in_run(None, None, || analyze_in_run(a))
}

fn analyze_in_run(a: &AnalyzeArgs) -> Result<String, Error> {
    if let Some(out) = &a.picture {
        let out = Path::new(out);
        // analyze has no --force: its one input is never replaced.
        if same_file(out, Path::new(&a.file)) {
            return Err(Error::Usage(format!(
                "the output `{}` is the input: writing it would replace it; name another output",
                out.display()
            )));
        }
        if !out
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("svg"))
        {
            return Err(Error::Usage(format!(
                "--picture writes SVG: name the file `….svg`, not `{}`",
                out.display()
            )));
        }
    }
    let r = crate::analyze::analyze(Path::new(&a.file), &a.defines)?;
    if let Some(out) = &a.picture {
        let svg = r.characteristic_svg().map_err(Error::Usage)?;
        write_file(Path::new(out), svg.as_bytes())?;
    }
    let mut s = if a.json { r.json() } else { r.text() };
    while s.ends_with('\n') {
        s.pop();
    }
    Ok(s)
}
