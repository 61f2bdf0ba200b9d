//! `subgram analyze`: the report on a subdivision scheme, and its picture.

use std::path::Path;

use super::common::{in_run, same_file, write_file};
use crate::error::Error;
use crate::Progress;

/// The arguments of `subgram analyze`.
#[derive(Clone, Debug, Default)]
pub struct AnalyzeArgs {
    pub file: String,
    /// `--format json` instead of text.
    pub json: bool,
    pub defines: Vec<String>,
    /// `--picture OUT.svg`: the characteristic maps' control nets.
    pub picture: Option<String>,
    /// `--valences 3,4,12`: a surface grammar measured at these only
    /// (default: all of [`crate::analyze::surface::VALENCES`]).
    pub valences: Option<Vec<usize>>,
}

/// `subgram analyze FILE [--format json] [-D NAME=VALUE]…`: what the
/// subdivision scheme in FILE is (see [`crate::analyze`]), as text or JSON.
pub fn analyze(a: &AnalyzeArgs) -> Result<String, Error> {
    analyze_reporting(a, |_| {})
}

/// [`analyze`], telling `progress` after each valence a surface grammar
/// is measured at (`Progress::valences`).
pub fn analyze_reporting(a: &AnalyzeArgs, progress: impl FnMut(Progress)) -> Result<String, Error> {
    in_run(None, None, || analyze_in_run(a, progress))
}

fn analyze_in_run(a: &AnalyzeArgs, mut progress: impl FnMut(Progress)) -> Result<String, Error> {
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
    let all: Vec<usize> = crate::analyze::surface::VALENCES.collect();
    let ns = a.valences.as_deref().unwrap_or(&all);
    let mut on_valence = |done: usize, of: usize| {
        progress(Progress {
            valences: true,
            step: done,
            steps: of,
            ..Progress::default()
        })
    };
    let r = crate::analyze::analyze_reporting(Path::new(&a.file), &a.defines, ns, &mut on_valence)?;
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
