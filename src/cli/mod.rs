//! The binary's command line: the `Cli` parser, one `Command` per
//! subcommand, and `run`, which hands each to its module. These modules
//! belong to the binary (`main.rs` declares them), not to the library.
//!
//! - `args.rs`: what several commands' arguments share: `Timeout` and the
//!   value parsers of `--timeout`, `--size`, `--background` and
//!   `--max-input-size`; `Format`.
//! - `print.rs`: printing: the progress bar (`with_progress`,
//!   `progress_to`), what a program printed, warnings, `Unbuffered`
//!   standard output, `print_out`.
//! - `derive.rs`, `render.rs` (`render` and `watch`), `serve.rs`,
//!   `infer.rs`, `reverse.rs` (`reverse` and `reconstruct`),
//!   `subdivide.rs`, `mesh.rs` (`mesh info`, `mesh convert`), `check.rs`,
//!   `analyze.rs`: each command's clap arguments and the code that runs it.
//!
//! `cli` uses the library's public API (`subgram::command` above all) and
//! clap and indicatif; nothing in the library uses it.

mod analyze;
mod args;
mod check;
mod derive;
mod infer;
mod mesh;
mod print;
mod render;
mod reverse;
mod serve;
mod subdivide;

use clap::{Parser, Subcommand};
use subgram::Error;

#[derive(Parser)]
#[command(
    name = "subgram",
    version,
    about = "Curves and surfaces from L-systems and grammars"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Derive an .lsys file and print the final word.
    Derive(derive::DeriveCli),
    /// Render an .lsys file's picture to PNG or SVG (in 3D when its model
    /// asks, or with --solid), or export its 3D geometry to OBJ, PLY or GLB
    /// (a grammar's or a vv program's mesh, a shape grammar's shapes, as
    /// `subdivide` writes them).
    Render(render::RenderCli),
    /// Render, then render again whenever the file or a file it reads
    /// changes (a model's files, a base mesh); an edit with an error keeps
    /// the last good picture and prints the error. Ctrl-C stops.
    Watch(render::WatchCli),
    /// A live preview page on 127.0.0.1: edit the program, see its picture.
    Serve(serve::ServeCli),
    /// `serve`, and its page opened in the default browser (the address
    /// printed where there is none): orbit a plant or a mesh in 3D, play
    /// its growth step by step.
    View(serve::ServeCli),
    /// Infer L-system productions from a subdivision matrix or mask
    /// (paper 002, sections 5-7).
    Infer(infer::InferCli),
    /// Reverse-subdivide a contour into a compact control polygon.
    Reverse(reverse::ReverseCli),
    /// Restore a contour from a coarse polygon and its details.
    Reconstruct(reverse::ReconstructCli),
    /// Subdivide a mesh with a surface grammar or a vv program, or derive
    /// a shape grammar's shapes; write the mesh (a shape grammar's .obj
    /// with one group per terminal shape and its .mtl) or its picture.
    Subdivide(subdivide::SubdivideCli),
    /// Meshes: information and conversion.
    Mesh(mesh::MeshCli),
    /// Check an .lsys file and report every diagnostic.
    Check(check::CheckCli),
    /// Analyse a subdivision scheme (a curve L-system or a surface grammar):
    /// stencils, mask, degrees, smoothness; eigenvalues around valences 3 to 12.
    Analyze(analyze::AnalyzeCli),
}

/// Runs the command `cli` names.
pub(crate) fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Derive(c) => c.run(),
        Command::Render(c) => c.run(),
        Command::Watch(c) => c.run(),
        Command::Serve(c) => c.run(),
        Command::View(c) => c.view(),
        Command::Infer(c) => c.run(),
        Command::Reverse(c) => c.run(),
        Command::Reconstruct(c) => c.run(),
        Command::Subdivide(c) => c.run(),
        Command::Mesh(c) => c.run(),
        Command::Check(c) => c.run(),
        Command::Analyze(c) => c.run(),
    }
}
