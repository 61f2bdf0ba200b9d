//! The `subgram` command line: parse arguments, call the library, map errors
//! to exit codes (1 for a problem with the input, 2 for a usage error).

use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

use subgram::{output, Derivation, DeriveOptions};

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
        /// Stop with an error when a word grows past this many modules.
        #[arg(long, default_value_t = subgram::rewrite::derive::DEFAULT_MAX_MODULES)]
        max_modules: usize,
        /// Start the partition into multi-module strict predecessors here.
        #[arg(long, default_value_t = 0)]
        phase: usize,
        /// Print the word after interpretation rules instead.
        #[arg(long)]
        interpreted: bool,
    },
    /// Render an .lsys file's picture to PNG or SVG.
    Render {
        file: String,
        /// The picture: OUT.png or OUT.svg.
        #[arg(short = 'o', long = "output")]
        output: String,
        #[arg(short = 'n', long = "steps")]
        steps: Option<u64>,
        /// Image size in pixels, WIDTHxHEIGHT.
        #[arg(long, default_value = "800x800", value_parser = parse_size)]
        size: (u32, u32),
        /// Draw every step 0..N side by side.
        #[arg(long)]
        each: bool,
        /// white, black, none, #rrggbb.
        #[arg(long, default_value = "white", value_parser = parse_color)]
        background: subgram::render::Rgba,
        /// The projection plane of 3D drawings.
        #[arg(long, value_enum, default_value_t = ViewArg::Xy)]
        view: ViewArg,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
        #[arg(long, default_value_t = subgram::rewrite::derive::DEFAULT_MAX_MODULES)]
        max_modules: usize,
        #[arg(long, default_value_t = 0)]
        phase: usize,
    },
    /// Check an .lsys file and report every diagnostic.
    Check {
        file: String,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum ViewArg {
    Xy,
    Xz,
    Yz,
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
        _ => Err((
            1,
            "error: internal failure (this is a bug in subgram)".to_string(),
        )),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, message)) => {
            eprintln!("{message}");
            ExitCode::from(code)
        }
    }
}

fn run(cli: Cli) -> Result<(), (u8, String)> {
    match cli.command {
        Command::Check { file, define } => {
            let loaded = load(&file, &define)?;
            print_out(&format!(
                "{file}: ok ({} rules, {} module kinds)",
                loaded.program.rules.len(),
                loaded.program.alphabet.kinds.len()
            ))
        }
        Command::Render {
            file,
            output,
            steps,
            size,
            each,
            background,
            view,
            define,
            max_modules,
            phase,
        } => {
            let lower = output.to_ascii_lowercase();
            let svg = if lower.ends_with(".svg") {
                true
            } else if lower.ends_with(".png") {
                false
            } else {
                return Err((
                    2,
                    format!("error: cannot tell the format of `{output}`: name it .png or .svg"),
                ));
            };
            let loaded = load(&file, &define)?;
            check_steps(steps)?;
            let mut derive = DeriveOptions::default()
                .with_max_modules(max_modules)
                .with_phase(phase);
            derive.steps = steps;
            let opts = subgram::FigureOptions {
                derive,
                each,
                draw: Default::default(),
                render: subgram::render::RenderOptions {
                    width: size.0,
                    height: size.1,
                    background,
                    view: match view {
                        ViewArg::Xy => subgram::render::View::Xy,
                        ViewArg::Xz => subgram::render::View::Xz,
                        ViewArg::Yz => subgram::render::View::Yz,
                    },
                    ..Default::default()
                },
            };
            let scene = loaded
                .figure(&opts)
                .map_err(|e| (1, loaded.render_figure_error(&e)))?;
            let bytes = if svg {
                subgram::render::svg::render(&scene).into_bytes()
            } else {
                subgram::render::png::render(&scene)
                    .map_err(|e| (1, format!("error: {}", e.message)))?
            };
            subgram::render::write_atomic(std::path::Path::new(&output), &bytes)
                .map_err(|e| (1, format!("error: cannot write `{output}`: {e}")))
        }
        Command::Derive {
            file,
            steps,
            format,
            define,
            max_modules,
            phase,
            interpreted,
        } => {
            let loaded = load(&file, &define)?;
            check_steps(steps)?;
            let mut opts = DeriveOptions::default()
                .with_max_modules(max_modules)
                .with_phase(phase);
            opts.steps = steps;
            let fail = |e: subgram::DeriveError| (1, loaded.render_derive_error(&e));
            let mut d = Derivation::new(&loaded.program, opts).map_err(fail)?;
            while d.has_next() {
                d.next_step().map_err(fail)?;
            }
            let word = if interpreted {
                d.interpret().map_err(fail)?
            } else {
                d.word.clone()
            };
            let p = &loaded.program;
            let text = match format {
                Format::Text => output::word_text(&word, &p.alphabet, &p.structs),
                Format::Json => {
                    output::word_json(&word, d.ring, d.step, &p.alphabet, &p.structs).to_string()
                }
            };
            print_out(&text)
        }
    }
}

fn load(file: &str, define: &[String]) -> Result<subgram::Loaded, (u8, String)> {
    subgram::load_file(file, define).map_err(|e| {
        let code = match e {
            subgram::LoadError::BadDefine(_) => 2,
            _ => 1,
        };
        (code, e.render())
    })
}

/// Writes a line to stdout; a closed pipe (`subgram derive f | head`) is not an error.
fn print_out(text: &str) -> Result<(), (u8, String)> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{text}").and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err((1, format!("error: cannot write the output: {e}"))),
    }
}

/// `-n` beyond the engine's limit is a usage error.
fn check_steps(steps: Option<u64>) -> Result<(), (u8, String)> {
    match steps {
        Some(n) if n > subgram::rewrite::derive::MAX_STEPS => Err((
            2,
            format!(
                "error: -n {n} is beyond the limit of {} steps",
                subgram::rewrite::derive::MAX_STEPS
            ),
        )),
        _ => Ok(()),
    }
}
