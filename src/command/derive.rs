//! `subgram derive`: a curve's word (or its interpretation), or a mesh's or
//! a shape tree's description, streamed to a writer or written to a file.

use std::path::{Path, PathBuf};
use std::time::Duration;

use super::common::{
    as_paths, check_steps, in_run, json, load_options, same_file, write_program_files,
    writes_folder,
};
use crate::deadline::{Deadline, DEFAULT_TIMEOUT};
use crate::error::Error;
use crate::lang::ProgramOutput;
use crate::load::load;
use crate::rewrite::derive::DEFAULT_MAX_MODULES;
use crate::system::{Progress, RunOptions, System};

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
    /// How a model's environmental program runs (`--clean-ea20`,
    /// `--env-process`, `--env-timeout`).
    pub environment: crate::enviro::Options,
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
            environment: Default::default(),
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
    let system = load(&a.file, &load_options(&a.defines, a.double, &a.environment))?;
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
            let mut progress = progress;
            let mut run = c.run_reporting(opts.derive_options(), |d| {
                progress(Progress::of_derivation(d))
            })?;
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
