//! `subgram subdivide`: its arguments, and the run with its progress bar.

use subgram::command::{self, SubdivideArgs};
use subgram::Error;

use super::args::{parse_timeout, Timeout};
use super::print::{print_program_output, print_warnings, with_progress};

#[derive(clap::Args)]
pub(super) struct SubdivideCli {
    /// The base mesh (.obj, .off, .ply); default: the grammar's `mesh:`.
    mesh: Option<String>,
    #[arg(long)]
    grammar: String,
    #[arg(short = 'n', long = "steps")]
    steps: Option<usize>,
    /// .obj, .off, .ply, .png or .svg
    #[arg(short = 'o', long = "output")]
    output: String,
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    define: Vec<String>,
    /// For pictures: iso, front, back, left, right, top, bottom.
    #[arg(long)]
    view: Option<String>,
    /// For pictures: lit (the default: smooth, from vertex normals), flat
    /// (one shade a face), normals (a normal map) or reflection
    /// (reflection lines); the last two draw no edges.
    #[arg(long)]
    shading: Option<String>,
    /// For pictures: draw the faces without their edges.
    #[arg(long)]
    no_wireframe: bool,
    /// Shape grammars: seed the random choice of rules.
    #[arg(long, value_name = "N")]
    seed: Option<u32>,
    /// Stop with an error after this many seconds (0: no limit).
    #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
          default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
    timeout: Timeout,
    /// Write the output even when it is one of the inputs.
    #[arg(long)]
    force: bool,
    /// Surface grammars (primal, on a closed mesh): move the final
    /// vertices to their limit positions and write their limit normals
    /// (vn in OBJ, nx ny nz in PLY), by the stencils `analyze` measures
    #[arg(long)]
    limit: bool,
    /// Surface grammars on a mesh with texture coordinates (OBJ vt, PLY
    /// texcoord or u v): which are interpolated linearly, OpenSubdiv's
    /// choices: none (smooth everywhere), corners-only, corners-plus1,
    /// corners-plus2, boundaries (the default, as Blender's), all
    #[arg(long, value_name = "CHOICE")]
    fvar_linear: Option<String>,
    /// Subdivide without the base mesh's texture coordinates.
    #[arg(long)]
    no_uvs: bool,
}

impl SubdivideCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let SubdivideCli {
            mesh,
            grammar,
            steps,
            output,
            define,
            view,
            shading,
            no_wireframe,
            seed,
            timeout,
            force,
            limit,
            fvar_linear,
            no_uvs,
        } = self;
        let args = SubdivideArgs {
            mesh,
            grammar,
            steps: steps.map(|n| n as u64),
            output,
            defines: define,
            view,
            shading,
            no_wireframe,
            seed,
            timeout: timeout.0,
            force,
            limit,
            fvar_linear,
            no_uvs,
            program_output: subgram::ProgramOutput::new(),
        };
        let result = with_progress(|p| command::subdivide(&args, p));
        print_program_output(&args.program_output, false)?;
        print_warnings(&result?);
        Ok(())
    }
}
