//! `subgram render` and `watch`: their arguments (`RenderCli`, which `watch`
//! takes whole), the render with its progress bar, and what `watch` reports.

use std::time::Duration;

use subgram::command::{self, RenderArgs};
use subgram::Error;

use super::args::{parse_color, parse_size, parse_timeout, Timeout};
use super::print::{print_program_output, print_warnings, with_progress};

// The options of `render` and `watch` (no doc comment: clap would take
// it for the commands' help).
#[derive(clap::Args)]
pub(super) struct RenderCli {
    file: String,
    /// The picture: OUT.png or OUT.svg; an animation of the steps:
    /// OUT.gif or OUT.apng; one still a step: a .png or .svg name with
    /// {N} (or lower-case n) where the step goes, as OUT-{N}.png.
    #[arg(short = 'o', long = "output")]
    output: String,
    #[arg(short = 'n', long = "steps")]
    steps: Option<u64>,
    /// Image size in pixels, WIDTHxHEIGHT [default: 800x800; with
    /// --each, 800 wide and as tall as the panels need].
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Draw every step 0..N side by side.
    #[arg(long)]
    each: bool,
    /// white, black, none, #rrggbb; by default a model's colour 0, else
    /// white.
    #[arg(long, value_parser = parse_color)]
    background: Option<subgram::render::Rgba>,
    /// The projection of 3D drawings: xy, xz or yz for L-systems;
    /// iso, front, back, left, right, top or bottom for meshes.
    #[arg(long)]
    view: Option<String>,
    /// L-systems: draw the 3D geometry shaded (tubes, surfaces, generalized
    /// cylinders) [default: when the model's view file asks for it].
    #[arg(long, conflicts_with = "lines")]
    solid: bool,
    /// L-systems: draw the turtle's lines in 2D.
    #[arg(long)]
    lines: bool,
    /// Meshes: draw the faces without their edges.
    #[arg(long)]
    no_wireframe: bool,
    /// Meshes: one flat shade per face [default: smooth, from vertex
    /// normals].
    #[arg(long)]
    flat: bool,
    /// Animations (.gif, .apng): frames a second [default: the
    /// model's `swap interval:`, else 4].
    #[arg(long, value_name = "N")]
    fps: Option<f64>,
    #[arg(short = 'D', value_name = "NAME=VALUE")]
    define: Vec<String>,
    /// Compute float, V2f and V3f in double precision (lpfg: single).
    #[arg(long)]
    double: bool,
    #[arg(long, default_value_t = subgram::DEFAULT_MAX_MODULES)]
    max_modules: usize,
    #[arg(long, default_value_t = 0)]
    phase: usize,
    /// Seed every random number generator (ran, rand, drand48,
    /// Gillespie groups) as if Start began with sran(N); srand(N);
    /// srand48(N); SeedGillespie(N). Without it, lpfg's starting state.
    #[arg(long, value_name = "N")]
    seed: Option<u32>,
    /// Let the program write files (fopen), under this folder.
    #[arg(long, value_name = "DIR")]
    allow_writes: Option<std::path::PathBuf>,
    /// Stop with an error after this many seconds (0: no limit).
    #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
          default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
    timeout: Timeout,
    /// Write the output even when it is one of the inputs.
    #[arg(long)]
    force: bool,
    #[command(flatten)]
    environment: super::args::EnvCli,
}

impl RenderCli {
    fn into_args(self) -> RenderArgs {
        RenderArgs {
            file: self.file,
            output: self.output,
            steps: self.steps,
            size: self.size,
            each: self.each,
            background: self.background,
            view: self.view,
            wireframe: !self.no_wireframe,
            flat: self.flat,
            fps: self.fps,
            solid: if self.solid {
                command::Solidity::Solid
            } else if self.lines {
                command::Solidity::Lines
            } else {
                command::Solidity::Auto
            },
            defines: self.define,
            double: self.double,
            max_modules: self.max_modules,
            phase: self.phase,
            seed: self.seed,
            timeout: self.timeout.0,
            force: self.force,
            allow_writes: self.allow_writes,
            program_output: subgram::ProgramOutput::new(),
            environment: self.environment.options(),
        }
    }
}

impl RenderCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let args = self.into_args();
        let result = with_progress(|p| command::render(&args, p));
        print_program_output(&args.program_output, false)?;
        print_warnings(&result?);
        Ok(())
    }
}

#[derive(clap::Args)]
pub(super) struct WatchCli {
    #[command(flatten)]
    render: RenderCli,
    /// How often to look at the files, in milliseconds.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(10..=60_000))]
    poll_ms: u64,
    /// Stop after this many renders (for scripts and tests).
    #[arg(long, hide = true)]
    max_renders: Option<usize>,
}

impl WatchCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let WatchCli {
            render,
            poll_ms,
            max_renders,
        } = self;
        let args = render.into_args();
        let opts = command::WatchOptions {
            poll: Duration::from_millis(poll_ms),
            max_renders,
        };
        let mut watched: Vec<std::path::PathBuf> = Vec::new();
        command::watch(&args, &opts, |event| match event {
            command::WatchEvent::Rendered {
                output,
                seconds,
                warnings,
            } => {
                let _ = print_program_output(&args.program_output, false);
                print_warnings(warnings);
                eprintln!("wrote {output} in {seconds:.2} s");
            }
            command::WatchEvent::Failed { error } => {
                let _ = print_program_output(&args.program_output, false);
                if error.has_location() {
                    eprintln!("{error}");
                } else {
                    eprintln!("error: {error}");
                }
                eprintln!("(the last good picture is kept; waiting for a change)");
            }
            command::WatchEvent::Watching { files } => {
                if files != watched.as_slice() {
                    let names: Vec<String> =
                        files.iter().map(|f| f.display().to_string()).collect();
                    eprintln!("watching {} (Ctrl-C to stop)", names.join(", "));
                    watched = files.to_vec();
                }
            }
        })
    }
}
