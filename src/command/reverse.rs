//! `subgram reverse` and `reconstruct`: a contour reverse-subdivided into
//! a coarse polygon and its details, and restored from them.

use std::path::Path;
use std::time::Duration;

use super::common::{in_run, json, refuse_overwrite, write_files};
use super::picture::{picture_bytes, Picture};
use crate::deadline::DEFAULT_TIMEOUT;
use crate::error::Error;
use crate::render;
use crate::reverse::{self, Phase, ReverseOptions, Scheme};

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
