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
    /// Check an .lsys file and report every diagnostic.
    Check {
        file: String,
        #[arg(short = 'D', value_name = "NAME=VALUE")]
        define: Vec<String>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Format {
    Text,
    Json,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
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
