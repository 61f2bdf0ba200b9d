//! The `subgram` command line: parses arguments, calls one library function
//! per command ([`subgram::command`]), prints what it returns, and maps errors
//! to exit codes (1 for a problem with the input, 2 for a usage error).

use std::process::ExitCode;
use std::time::Duration;

use clap::{Parser, Subcommand, ValueEnum};

use subgram::command::{self, DeriveArgs, RenderArgs, ReverseArgs, SubdivideArgs};
use subgram::{Error, Progress};

#[derive(Parser)]
#[command(
    name = "subgram",
    version,
    about = "Curves and surfaces from L-systems and grammars"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Derive an .lsys file and print the final word.
    Derive {
        file: String,
        /// Number of derivation steps (overrides `derivation length:`).
        #[arg(short = 'n', long = "steps")]
        steps: Option<u64>,
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        /// Override a #define: -D NAME=VALUE (repeatable).
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// Compute float, V2f and V3f in double precision (lpfg: single).
        #[arg(long)]
        double: bool,
        /// Stop with an error when a word grows past this many modules.
        #[arg(long, default_value_t = subgram::DEFAULT_MAX_MODULES)]
        max_modules: usize,
        /// Start the partition into multi-module strict predecessors here.
        #[arg(long, default_value_t = 0)]
        phase: usize,
        /// Print the word after interpretation rules instead.
        #[arg(long)]
        interpreted: bool,
        /// Shape grammars: stop with an error when a derivation makes more
        /// shapes than this (default: SUBGRAM_MAX_SHAPES or 1000000).
        #[arg(long, value_name = "N")]
        max_shapes: Option<usize>,
        /// Seed every random number generator (ran, rand, drand48,
        /// Gillespie groups) as if Start began with sran(N); srand(N);
        /// srand48(N); SeedGillespie(N). Without it, lpfg's starting state.
        #[arg(long, value_name = "N")]
        seed: Option<u32>,
        /// Let the program write files (fopen), under this folder.
        #[arg(long, value_name = "DIR")]
        allow_writes: Option<std::path::PathBuf>,
        /// Write the word (or the mesh's description) to this file instead
        /// of standard output: whole, or not at all.
        #[arg(short = 'o', long = "output", value_name = "FILE")]
        output: Option<std::path::PathBuf>,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
    },
    /// Render an .lsys file's picture to PNG or SVG (in 3D when its model
    /// asks, or with --solid), or export its 3D geometry to OBJ, PLY or GLB
    /// (a grammar's or a vv program's mesh, a shape grammar's shapes, as
    /// `subdivide` writes them).
    Render(RenderCli),
    /// Render, then render again whenever the file or a file it reads
    /// changes (a model's files, a base mesh); an edit with an error keeps
    /// the last good picture and prints the error. Ctrl-C stops.
    Watch {
        #[command(flatten)]
        render: RenderCli,
        /// How often to look at the files, in milliseconds.
        #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(10..=60_000))]
        poll_ms: u64,
        /// Stop after this many renders (for scripts and tests).
        #[arg(long, hide = true)]
        max_renders: Option<usize>,
    },
    /// A live preview page on 127.0.0.1: edit the program, see its picture.
    Serve {
        /// An .lsys file, or an lpfg model folder.
        file: String,
        /// The port (0: any free one).
        #[arg(long, default_value_t = 8080)]
        port: u16,
        /// Let the page write the program back (atomically).
        #[arg(long)]
        save: bool,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// Compute float, V2f and V3f in double precision (lpfg: single).
        #[arg(long)]
        double: bool,
        /// The largest word a render may make.
        #[arg(long, default_value_t = 2_000_000)]
        max_modules: usize,
        /// The longest a render may take, in seconds.
        #[arg(long, value_name = "SECONDS", default_value_t = 10)]
        timeout: u64,
    },
    /// Infer L-system productions from a subdivision matrix or mask
    /// (paper 002, sections 5-7).
    Infer {
        /// The matrix, rows separated by `;`: a whole closed matrix, one old
        /// point's band of rows ("1/4 3/4 0; 0 3/4 1/4"), or with --open a
        /// matrix with boundary rows.
        #[arg(long, allow_hyphen_values = true)]
        rows: Option<String>,
        /// The matrix from a file, a row per line.
        #[arg(long, value_name = "FILE")]
        rows_file: Option<String>,
        /// A mask: "1/4 3/4 3/4 1/4" (new_j = sum a_(j - arity i) old_i).
        #[arg(long, allow_hyphen_values = true)]
        mask: Option<String>,
        /// New points per old point, for a mask [default: 2].
        #[arg(long)]
        arity: Option<usize>,
        /// The matrix has boundary rows: endmarker productions.
        #[arg(long)]
        open: bool,
        /// A reverse subdivision matrix: a pseudo-L-system production.
        #[arg(long)]
        reverse: bool,
        /// The grouping to write (old point i takes new points
        /// a*i+d-a+1 ..= a*i+d); by default the shortest symmetric one.
        #[arg(long, allow_hyphen_values = true)]
        shift: Option<i64>,
        /// List every grouping with its context sizes instead.
        #[arg(long)]
        list: bool,
        /// Open schemes: the short form whose productions apply first to last.
        #[arg(long)]
        ordered: bool,
        /// Write the .lsys file here (atomically) instead of printing it.
        #[arg(short = 'o', long = "output")]
        output: Option<String>,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
    },
    /// Reverse-subdivide a contour into a compact control polygon.
    Reverse {
        /// Points (`x y` or CSV), an SVG shape, or a PNG silhouette.
        input: String,
        #[arg(short = 'n', long = "steps")]
        steps: usize,
        /// The coarse polygon: .csv, .txt or .svg.
        #[arg(short = 'o', long = "output")]
        output: String,
        /// A scheme file (group 1 reverses, group 2 subdivides).
        #[arg(long)]
        scheme: Option<String>,
        /// Which pairing of points: auto (the better), 0 or 1.
        #[arg(long, default_value = "auto", value_parser = parse_phase)]
        phase: subgram::reverse::Phase,
        /// Treat the contour as open (end points kept).
        #[arg(long)]
        open: bool,
        /// A PNG silhouette's shape is the light side (by default the side
        /// that does not touch the image's border, or the smaller one).
        #[arg(long)]
        invert: bool,
        /// A PNG silhouette's grey level between shape and ground, from 0
        /// (black) to 1 (white).
        #[arg(long, default_value_t = 0.5)]
        threshold: f64,
        /// Draw input, coarse polygon and reconstruction: .png or .svg.
        #[arg(long)]
        figure: Option<String>,
        /// Print point counts and reconstruction errors.
        #[arg(long)]
        report: bool,
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        /// Store the details that restore the input exactly.
        #[arg(long)]
        details: Option<String>,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
        /// Write the output even when it is one of the inputs.
        #[arg(long)]
        force: bool,
        /// The size limit of input files: bytes, or with K, M or G (KiB, MiB, GiB).
        #[arg(long, value_name = "SIZE", default_value = "64M", value_parser = parse_byte_size)]
        max_input_size: u64,
    },
    /// Restore a contour from a coarse polygon and its details.
    Reconstruct {
        coarse: String,
        #[arg(long)]
        details: String,
        #[arg(short = 'o', long = "output")]
        output: String,
        /// Restore only this many levels (default: all).
        #[arg(long)]
        level: Option<usize>,
        /// The scheme the details were made with (default: as recorded).
        #[arg(long)]
        scheme: Option<String>,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
        /// Write the output even when it is one of the inputs.
        #[arg(long)]
        force: bool,
        /// The size limit of input files: bytes, or with K, M or G (KiB, MiB, GiB).
        #[arg(long, value_name = "SIZE", default_value = "64M", value_parser = parse_byte_size)]
        max_input_size: u64,
    },
    /// Subdivide a mesh with a surface grammar or a vv program, or derive
    /// a shape grammar's shapes; write the mesh (a shape grammar's .obj
    /// with one group per terminal shape and its .mtl) or its picture.
    Subdivide {
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
        /// For pictures: lit (the default), normals (a normal map) or
        /// reflection (reflection lines); the last two draw no edges.
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
    },
    /// Meshes: information and conversion.
    Mesh {
        #[command(subcommand)]
        command: MeshCommand,
    },
    /// Check an .lsys file and report every diagnostic.
    Check {
        file: String,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// Compute float, V2f and V3f in double precision (lpfg: single).
        #[arg(long)]
        double: bool,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
    },
    /// Analyse a subdivision scheme (a curve L-system or a surface grammar):
    /// stencils, mask, degrees, smoothness; eigenvalues around valences 3 to 12.
    Analyze {
        file: String,
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        /// Also draw the control nets of the characteristic maps (surface
        /// grammars) into this SVG file.
        #[arg(long, value_name = "OUT.svg")]
        picture: Option<String>,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
    },
}

fn parse_phase(s: &str) -> Result<subgram::reverse::Phase, String> {
    match s {
        "auto" => Ok(subgram::reverse::Phase::Auto),
        "0" => Ok(subgram::reverse::Phase::Fixed(0)),
        "1" => Ok(subgram::reverse::Phase::Fixed(1)),
        _ => Err(format!("`{s}` is not a phase: use auto, 0 or 1")),
    }
}

/// `--timeout SECONDS`: the time limit, none for 0.
#[derive(Clone, Copy)]
struct Timeout(Option<Duration>);

impl std::fmt::Display for Timeout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0.map_or(0.0, |d| d.as_secs_f64()))
    }
}

/// `--timeout SECONDS`: a number of seconds, 0 for no limit.
fn parse_timeout(s: &str) -> Result<Timeout, String> {
    let secs: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number of seconds"))?;
    match Duration::try_from_secs_f64(secs) {
        Ok(d) if d.is_zero() => Ok(Timeout(None)),
        Ok(d) => Ok(Timeout(Some(d))),
        Err(_) => Err(format!(
            "`{s}` is not a time limit: give a number of seconds, or 0 for no limit"
        )),
    }
}

/// `1048576`, `512K`, `64M`, `2G` (powers of 1024).
/// The options of `render` and `watch`.
#[derive(clap::Args)]
struct RenderCli {
    file: String,
    /// The picture: OUT.png or OUT.svg.
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
        }
    }
}

fn parse_byte_size(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, unit) = match t.find(|c: char| !c.is_ascii_digit()) {
        Some(i) => t.split_at(i),
        None => (t, ""),
    };
    let shift = match unit.to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        _ => {
            return Err(format!(
                "`{s}` is not a size: write bytes, or a number with K, M or G"
            ))
        }
    };
    let n: u64 = digits
        .parse()
        .map_err(|_| format!("`{s}` is not a size: write bytes, or a number with K, M or G"))?;
    n.checked_mul(1 << shift)
        .filter(|&b| b <= u32::MAX as u64)
        .ok_or_else(|| format!("`{s}` is more than the largest input size, 4G"))
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{s}` is not WIDTHxHEIGHT, e.g. 800x600"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("`{w}` is not a width in pixels"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("`{h}` is not a height in pixels"))?;
    if w == 0 || h == 0 || w > 20_000 || h > 20_000 {
        return Err("each side must be 1 to 20000 pixels".into());
    }
    Ok((w, h))
}

fn parse_color(s: &str) -> Result<subgram::render::Rgba, String> {
    subgram::render::Rgba::parse(s)
        .ok_or_else(|| format!("`{s}` is not a colour: use white, black, none or #rrggbb"))
}

#[derive(Subcommand)]
enum MeshCommand {
    /// Counts, boundary loops, Euler characteristic, genus, valences, levels.
    Info {
        file: String,
        #[arg(long, value_enum, default_value_t = Format::Text)]
        format: Format,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
    },
    /// Check a mesh and write it in another format (.obj, .off, .ply).
    Convert {
        input: String,
        output: String,
        /// Write the triangles, not the quads of basic blocks.
        #[arg(long)]
        triangles: bool,
        /// Write the output even when it is the input (what the format cannot hold is lost).
        #[arg(long)]
        force: bool,
        /// Stop with an error after this many seconds (0: no limit).
        #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
              default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
        timeout: Timeout,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Text,
    Json,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // Deep but legal programs recurse deeply in the checker and the
    // interpreter: give them a large stack rather than a crash.
    let worker = std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || run(cli));
    let result = match worker.map(|h| h.join()) {
        Ok(Ok(r)) => r,
        _ => Err(Error::Failed(
            "internal failure (this is a bug in subgram)".to_string(),
        )),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if e.has_location() {
                eprintln!("{e}");
            } else {
                eprintln!("error: {e}");
            }
            ExitCode::from(if matches!(e, Error::Usage(_)) { 2 } else { 1 })
        }
    }
}

fn run(cli: Cli) -> Result<(), Error> {
    match cli.command {
        Command::Check {
            file,
            define,
            double,
            timeout,
        } => subgram::within(timeout.0, || {
            print_out(&command::check(&file, &define, double)?)
        }),
        Command::Analyze {
            file,
            format,
            define,
            picture,
            timeout,
        } => subgram::within(timeout.0, || {
            print_out(&command::analyze(&command::AnalyzeArgs {
                file,
                json: matches!(format, Format::Json),
                defines: define,
                picture,
            })?)
        }),
        Command::Derive {
            file,
            steps,
            format,
            define,
            double,
            max_modules,
            phase,
            interpreted,
            max_shapes,
            seed,
            timeout,
            allow_writes,
            output,
        } => {
            let json = matches!(format, Format::Json);
            let args = DeriveArgs {
                file,
                steps,
                json,
                defines: define,
                double,
                max_modules,
                phase,
                interpreted,
                max_shapes,
                seed,
                timeout: timeout.0,
                allow_writes,
                output: subgram::ProgramOutput::new(),
                word_file: output,
            };
            // The word is written as it is made. Before it: what the
            // program printed (to standard error when the word is JSON,
            // which must stay whole), then the warnings, the progress bar
            // cleared first.
            let bar = std::cell::RefCell::new(None);
            let done = std::cell::Cell::new(false);
            let mut stdout = Unbuffered::stdout();
            let result = command::derive_to(
                &args,
                |p| progress_to(&bar, p),
                |warnings| {
                    if let Some(b) = bar.borrow_mut().take() {
                        b.finish_and_clear();
                    }
                    done.set(true);
                    print_program_output(&args.output, json)?;
                    print_warnings(warnings);
                    Ok(())
                },
                &mut stdout,
            );
            if let Some(b) = bar.borrow_mut().take() {
                b.finish_and_clear();
            }
            if !done.get() {
                print_program_output(&args.output, json)?;
            }
            result
        }
        Command::Render(cli) => {
            let args = cli.into_args();
            let result = with_progress(|p| command::render(&args, p));
            print_program_output(&args.program_output, false)?;
            print_warnings(&result?);
            Ok(())
        }
        Command::Infer {
            rows,
            rows_file,
            mask,
            arity,
            open,
            reverse,
            shift,
            list,
            ordered,
            output,
            timeout,
        } => subgram::within(timeout.0, || {
            let args = command::InferArgs {
                rows,
                rows_file,
                mask,
                arity,
                open,
                reverse,
                shift,
                list,
                ordered,
                output,
            };
            print_out(&command::infer(&args)?)
        }),
        Command::Serve {
            file,
            port,
            save,
            define,
            double,
            max_modules,
            timeout,
        } => {
            let opts = subgram::serve::ServeOptions {
                path: file.into(),
                port,
                save,
                limits: subgram::serve::Limits {
                    max_modules,
                    timeout: Duration::from_secs(timeout.max(1)),
                    ..Default::default()
                },
                defines: define,
                double,
            };
            let server = subgram::serve::Server::bind(opts)?;
            println!("serving {} (Ctrl-C to stop)", server.url());
            use std::io::Write;
            let _ = std::io::stdout().flush();
            server.run();
            Ok(())
        }
        Command::Watch {
            render,
            poll_ms,
            max_renders,
        } => {
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
        Command::Subdivide {
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
        } => {
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
                program_output: subgram::ProgramOutput::new(),
            };
            let result = with_progress(|p| command::subdivide(&args, p));
            print_program_output(&args.program_output, false)?;
            print_warnings(&result?);
            Ok(())
        }
        Command::Mesh { command } => match command {
            MeshCommand::Info {
                file,
                format,
                timeout,
            } => subgram::within(timeout.0, || {
                print_out(&command::mesh_info(&file, matches!(format, Format::Json))?)
            }),
            MeshCommand::Convert {
                input,
                output,
                triangles,
                force,
                timeout,
            } => subgram::within(timeout.0, || {
                print_warnings(&command::mesh_convert(&input, &output, triangles, force)?);
                Ok(())
            }),
        },
        Command::Reverse {
            input,
            steps,
            output,
            scheme,
            phase,
            open,
            invert,
            threshold,
            figure,
            report,
            format,
            details,
            timeout,
            force,
            max_input_size,
        } => {
            let args = ReverseArgs {
                input,
                steps,
                output,
                scheme,
                phase,
                open,
                silhouette: subgram::reverse::input::Silhouette {
                    threshold,
                    side: if invert {
                        subgram::reverse::input::Side::Light
                    } else {
                        subgram::reverse::input::Side::Auto
                    },
                },
                figure,
                report,
                json: matches!(format, Format::Json),
                details,
                timeout: timeout.0,
                force,
                max_input: max_input_size,
            };
            match command::reverse(&args)? {
                Some(report) => print_out(&report),
                None => Ok(()),
            }
        }
        Command::Reconstruct {
            coarse,
            details,
            output,
            level,
            scheme,
            timeout,
            force,
            max_input_size,
        } => command::reconstruct(&command::ReconstructArgs {
            coarse,
            details,
            output,
            level,
            scheme,
            timeout: timeout.0,
            force,
            max_input: max_input_size,
        }),
    }
}

/// Runs `f` with a progress bar on standard error for surface grammars'
/// steps (shown only on a terminal).
fn with_progress<T>(f: impl FnOnce(&mut dyn FnMut(Progress)) -> T) -> T {
    let bar = std::cell::RefCell::new(None);
    let result = f(&mut |p: Progress| progress_to(&bar, p));
    if let Some(b) = bar.into_inner() {
        b.finish_and_clear();
    }
    result
}

/// Shows `p` on the progress bar in `bar`, made on the first report.
fn progress_to(bar: &std::cell::RefCell<Option<indicatif::ProgressBar>>, p: Progress) {
    let mut bar = bar.borrow_mut();
    let b = bar.get_or_insert_with(|| {
        let b = indicatif::ProgressBar::new(p.steps as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{spinner} step {pos}/{len} {msg} [{elapsed}]")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    b.set_position(p.step as u64);
    b.set_message(format!(
        "{} vertices, {} edges, {} faces",
        p.vertices, p.edges, p.faces
    ));
}

/// Writes what an L+C program printed (`printf`, `fprintf(stderr, …)`):
/// its standard output to ours (or to standard error with `to_stderr`),
/// its standard error to ours.
fn print_program_output(output: &subgram::ProgramOutput, to_stderr: bool) -> Result<(), Error> {
    use std::io::Write;
    for (stream, text) in output.take_text() {
        let r = if stream == subgram::Stream::Stderr || to_stderr {
            let mut e = std::io::stderr().lock();
            e.write_all(text.as_bytes()).and_then(|_| e.flush())
        } else {
            let mut o = std::io::stdout().lock();
            o.write_all(text.as_bytes()).and_then(|_| o.flush())
        };
        match r {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(()),
            Err(e) => {
                return Err(Error::Failed(format!(
                    "cannot write the program's output: {e}"
                )))
            }
        }
    }
    Ok(())
}

/// Writes a program's warnings to stderr, each followed by a blank line.
fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("{w}\n");
    }
}

/// Standard output written straight to its file descriptor: the word
/// comes in chunks of 64 KiB, which `Stdout`'s line buffer would search
/// for line breaks (4% of writing a JSON word of 119 MB). Whatever went
/// through `Stdout` before (what the program printed) is flushed first.
struct Unbuffered {
    #[cfg(unix)]
    file: Option<std::fs::File>,
    flushed: bool,
}

impl Unbuffered {
    fn stdout() -> Unbuffered {
        #[cfg(unix)]
        let file = {
            use std::os::fd::AsFd;
            std::io::stdout()
                .as_fd()
                .try_clone_to_owned()
                .ok()
                .map(std::fs::File::from)
        };
        Unbuffered {
            #[cfg(unix)]
            file,
            flushed: false,
        }
    }
}

impl std::io::Write for Unbuffered {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if !self.flushed {
            std::io::stdout().flush()?;
            self.flushed = true;
        }
        #[cfg(unix)]
        if let Some(f) = &mut self.file {
            return f.write(buf);
        }
        std::io::stdout().write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        std::io::stdout().flush()
    }
}

/// Writes a line to stdout; a closed pipe (`subgram derive f | head`) is not an error.
fn print_out(text: &str) -> Result<(), Error> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{text}").and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Error::Failed(format!("cannot write the output: {e}"))),
    }
}
