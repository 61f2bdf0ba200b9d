//! subgram: curves and surfaces specified with L-systems and grammars.
//!
//! A `.lsys` file is either an L+C-like program (the language of lpfg:
//! module declarations, an axiom, productions with contexts and C-like
//! bodies) whose word of modules draws a curve, or a stellar subdivision
//! grammar that rewrites a mesh. [`load`] reads either into a [`System`];
//! [`System::run`] derives the word or subdivides the mesh.
//!
//! ```
//! # fn main() -> Result<(), subgram::Error> {
//! let root = env!("CARGO_MANIFEST_DIR");
//! let file = format!("{root}/lsystems/curves/chaikin-13.lsys");
//! let system = subgram::load(&file, &subgram::LoadOptions::default())?;
//! let subgram::System::Curve(curve) = system else { unreachable!() };
//! let mut run = curve.run(subgram::DeriveOptions::default().with_steps(1))?;
//! assert!(run.text().starts_with("P([")); // the word: P([x, y]) P([x, y]) ...
//! let lines = run.polylines()?;            // the points the turtle draws
//! assert_eq!(lines.len(), 1);
//! # Ok(()) }
//! ```
//!
//! Errors are [`Error`]s; those about a program's text display as
//! `file:line:col: error: message`, the line and a caret under the place.
//!
//! The lower levels stay reachable: [`load_str`] and [`Curve::program`]
//! for a curve's checked program, [`derive()`] and [`Derivation`] for
//! derivations step by step, [`draw`] and [`render`] for pictures, [`mesh`]
//! for meshes and their files, [`surface`] for grammars, [`reverse`] for
//! reverse subdivision, and [`command`] for the binary's commands.

mod colour;
mod curve;
mod deadline;
pub mod enviro;
mod error;
mod files;
mod huge;
mod lang;
mod limits;
mod load;
mod production;
mod rewrite;
mod syntax;
mod system;
#[cfg(test)]
mod testing;
pub mod vv;

pub mod analyze;
pub mod command;
pub mod draw;
pub mod export;
pub mod infer;
pub mod mesh;
pub mod model;
pub mod output;
pub mod render;
pub mod reverse;
pub mod scene3;
#[cfg(feature = "serve")]
pub mod serve;
pub(crate) mod shape;
pub mod surface;

pub use curve::{Curve, CurveRun, FigureOptions, Figures};
pub use deadline::{within, Deadline, DEFAULT_TIMEOUT};
pub use error::Error;
pub use lang::{Program, ProgramOutput, Stream, Value};
pub use load::{
    load, load_edited, load_file, load_file_with, load_str, load_str_with, load_text, LoadOptions,
    Precision,
};
pub use rewrite::derive::{DEFAULT_MAX_MODULES, MAX_STEPS};
pub use rewrite::{derive, Derivation, DeriveError, DeriveOptions, Derived, Word};
pub use syntax::{Diagnostic, FileId, SourceFile, SourceMap, Span};
pub use system::{
    load_mesh, Progress, Run, RunOptions, ShapeCounts, ShapeRun, Shapes, Surface, SurfaceRun,
    System, Vv, VvInfo, VvResult, MAX_SURFACE_STEPS,
};

/// The smoothing groups of a shape grammar's derivation: each group's
/// welded mesh and its subdivision, with the number of protected faces, for
/// `examples/smooth_xcheck.rs --shapes` and its cross-check against CGAL.
#[doc(hidden)]
pub fn shape_groups(path: &std::path::Path, seed: u32) -> Result<Vec<ShapeGroup>, Error> {
    let System::Shapes(s) = load(path, &LoadOptions::default())? else {
        return Err(Error::Usage(format!(
            "{}: not a shape grammar",
            path.display()
        )));
    };
    let opts = shape::ShapeOptions {
        seed,
        keep_meshes: true,
        ..Default::default()
    };
    let never = Deadline::after(std::time::Duration::from_secs(3600));
    let tree = shape::run::derive(&s.grammar, &opts, &never).map_err(|e| s.error(e))?;
    Ok(tree
        .groups
        .into_iter()
        .filter_map(|g| {
            g.meshes.map(|m| ShapeGroup {
                welded: m.0,
                subdivided: m.1,
                protected_faces: g.protected_faces,
                steps: g.steps,
                scheme: g.scheme,
            })
        })
        .collect())
}

/// A smoothing group of [`shape_groups`].
#[doc(hidden)]
pub struct ShapeGroup {
    pub welded: mesh::PolygonSoup,
    pub subdivided: mesh::PolygonSoup,
    pub protected_faces: usize,
    pub steps: usize,
    pub scheme: String,
}

/// Subdivide of a welded smoothing group (`shape::smooth`), for
/// `examples/smooth_xcheck.rs` and its cross-check against CGAL: the
/// grammar of scheme `name` ("sqrt3", "loop", "catmull-clark").
#[doc(hidden)]
pub fn smooth_scheme(name: &str) -> Result<surface::Grammar, String> {
    shape::smooth::scheme(name)
}

/// `steps` steps of `grammar` on `soup` with the given face tags and
/// protected vertices and faces, under the default time limit: the output
/// soup, each output face's tag and each output vertex's input vertex
/// (when it is one, unmoved).
#[doc(hidden)]
#[allow(clippy::type_complexity)] // the three parts of `Smoothed`, for one example
pub fn smooth_subdivide(
    grammar: &surface::Grammar,
    soup: &mesh::PolygonSoup,
    tags: &[u32],
    protected_vertex: &[bool],
    protected_face: &[bool],
    steps: usize,
) -> Result<(mesh::PolygonSoup, Vec<u32>, Vec<Option<u32>>), String> {
    let s = shape::smooth::subdivide(
        grammar,
        soup,
        tags,
        protected_vertex,
        protected_face,
        steps,
        &Deadline::after(DEFAULT_TIMEOUT),
    )?;
    Ok((s.soup, s.tags, s.origin))
}
