//! `subgram analyze`: what a subdivision scheme is, measured through the
//! engine. One step of the scheme is run on impulses (a word or a mesh of
//! points, one coordinate 1 at one point and 0 elsewhere); the outputs are
//! the columns of the subdivision matrix. Nothing here re-implements a
//! scheme: every number comes from the program's own rules.
//!
//! Curves ([`curve`]): stencils, affine invariance, support, the mask and
//! its (1+z) factors, polynomial reproduction and generation, Rioul's
//! Hölder estimate. Surfaces ([`surface`]): the local subdivision matrix
//! around a vertex of each valence (around an n-sided face for dual
//! schemes), its leading eigenvalues, Reif's check and the limit and
//! tangent stencils; [`star`] the same around boundary, crease and corner
//! vertices, side by side. A dual scheme's centres of blocks, which its rules
//! may read, are put at their polygons' centroids with each impulse.
//!
//! **Layer.** It uses `curve`, `deadline`, `error`, `lang`, `load`, `mesh`,
//! `rewrite`, `surface`, `system`; it is used by `command`. Nothing here names
//! a layer above (see ARCHITECTURE.md, "Layers").

pub mod curve;
pub mod limit;
mod num;
pub mod star;
pub mod surface;
mod text;

use std::path::Path;
use std::time::Duration;

use serde::Serialize;

use crate::{load, Deadline, Error, LoadOptions, Precision, System};

pub use curve::CurveReport;
pub use surface::SurfaceReport;

/// The time an analysis may take.
pub const TIMEOUT: Duration = Duration::from_secs(120);

/// What `analyze` found.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub file: String,
    #[serde(flatten)]
    pub scheme: Scheme,
}

/// A curve scheme's or a surface grammar's analysis.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Scheme {
    Curve(Box<CurveReport>),
    Surface(SurfaceReport),
}

/// Loads `path` (in double precision, so that the measured weights are the
/// program's) and analyses it.
pub fn analyze(path: &Path, defines: &[String]) -> Result<Report, Error> {
    let all: Vec<usize> = surface::VALENCES.collect();
    analyze_at(path, defines, &all)
}

/// [`analyze`], a surface grammar at the valences `valences` only (each
/// at least 3; curves ignore them).
pub fn analyze_at(path: &Path, defines: &[String], valences: &[usize]) -> Result<Report, Error> {
    analyze_reporting(path, defines, valences, &mut |_, _| {})
}

/// [`analyze_at`], telling `on_valence` how many valences of how many a
/// surface grammar has been measured at, after each.
pub fn analyze_reporting(
    path: &Path,
    defines: &[String],
    valences: &[usize],
    on_valence: &mut dyn FnMut(usize, usize),
) -> Result<Report, Error> {
    let opts = LoadOptions {
        defines: defines.to_vec(),
        precision: Precision::Double,
        ..Default::default()
    };
    let name = path.display().to_string();
    // `--timeout` where the command set one, else the analysis's own.
    let deadline = crate::deadline::current().unwrap_or_else(|| Deadline::after(TIMEOUT));
    let scheme = match load(path, &opts)? {
        System::Curve(c) => Scheme::Curve(Box::new(curve::analyze(&c, &name, deadline)?)),
        System::Surface(s) => Scheme::Surface(surface::analyze_at(
            &s.grammar, &name, deadline, valences, on_valence,
        )?),
        _ => {
            return Err(Error::File {
                path: name,
                line: None,
                message: "analyze reads curve L-systems and surface grammars; this file is \
                          neither"
                    .into(),
            })
        }
    };
    Ok(Report { file: name, scheme })
}

impl Report {
    /// The report as readable text.
    pub fn text(&self) -> String {
        match &self.scheme {
            Scheme::Curve(c) => text::curve(&self.file, c),
            Scheme::Surface(s) => text::surface(&self.file, s),
        }
    }

    /// The control nets of a surface grammar's characteristic maps as an
    /// SVG picture; an error for a curve scheme or where no valence has
    /// one.
    pub fn characteristic_svg(&self) -> Result<String, String> {
        match &self.scheme {
            Scheme::Curve(_) => Err(format!(
                "{}: a curve scheme; --picture draws the characteristic maps of surface \
                 grammars",
                self.file
            )),
            Scheme::Surface(s) => text::characteristic_svg(&self.file, s).ok_or_else(|| {
                format!(
                    "{}: no valence has a characteristic map to draw (λ1 = λ2 real)",
                    self.file
                )
            }),
        }
    }

    /// The report as JSON.
    pub fn json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{e}"));
        s.push('\n');
        s
    }
}
