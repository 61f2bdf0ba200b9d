//! What several commands share: `in_run`, load options, the steps' limit,
//! JSON; outputs written all or none and never over an input
//! (`refuse_overwrite`), and the files a program wrote (`--allow-writes`).

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::deadline::Deadline;
use crate::error::Error;
use crate::lang::ProgramOutput;
use crate::load::{LoadOptions, Precision};
use crate::render;
use crate::rewrite::derive::MAX_STEPS;

pub(super) fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    render::write_atomic(path, bytes).map_err(|e| Error::write(path, e))
}

/// Writes every file or none (see [`crate::files::atomic::write_all_atomic`]).
pub(super) fn write_files(files: &[(&Path, Vec<u8>)]) -> Result<(), Error> {
    let all: Vec<(&Path, &[u8])> = files.iter().map(|(p, b)| (*p, b.as_slice())).collect();
    crate::files::atomic::write_all_atomic(&all).map_err(|(path, e)| Error::write(path, e))
}

pub(super) fn json(value: &impl serde::Serialize) -> Result<String, Error> {
    serde_json::to_string_pretty(value).map_err(|e| Error::Failed(e.to_string()))
}

pub(super) fn load_options(
    defines: &[String],
    double: bool,
    environment: &crate::enviro::Options,
) -> LoadOptions {
    LoadOptions {
        environment: environment.clone(),
        defines: defines.to_vec(),
        precision: if double {
            Precision::Double
        } else {
            Precision::Single
        },
    }
}

/// `-n` beyond the engine's limit is a usage error.
pub(super) fn check_steps(steps: Option<u64>) -> Result<(), Error> {
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
pub(super) fn in_run<T>(
    timeout: Option<Duration>,
    force: Option<bool>,
    work: impl FnOnce() -> Result<T, Error>,
) -> Result<T, Error> {
    let run = crate::files::Run::begin(timeout.map(Deadline::after), force);
    let value = work()?;
    run.commit()?;
    Ok(value)
}

pub(super) fn as_paths(v: &[PathBuf]) -> Vec<&Path> {
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
pub(super) fn same_file(a: &Path, b: &Path) -> bool {
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
pub(super) fn refuse_overwrite(
    outputs: &[&Path],
    inputs: &[&Path],
    force: bool,
) -> Result<(), Error> {
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

/// The folder of `--allow-writes`, checked to be one, and `output` told
/// that the program may write files.
pub(super) fn writes_folder(
    dir: &Option<PathBuf>,
    output: &ProgramOutput,
) -> Result<Option<PathBuf>, Error> {
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
pub(super) fn write_program_files(
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

/// `"; did you mean `.png`?"` when the extension of `path` is a misspelt
/// one of `known` (`.pgn`, `.svgg`), else nothing.
pub(super) fn extension_hint(path: &Path, known: &[&str]) -> String {
    let Some(ext) = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
    else {
        return String::new();
    };
    crate::lang::suggest::nearest(&ext, known.iter().copied())
        .map(|e| format!("; did you mean `.{e}`?"))
        .unwrap_or_default()
}
