//! `subgram derive`: its arguments, and the word streamed to standard output.

use subgram::command::{self, DeriveArgs};
use subgram::Error;

use super::args::{parse_timeout, EnvCli, Format, Timeout};
use super::print::{print_program_output, print_warnings, progress_to, Unbuffered};

#[derive(clap::Args)]
pub(super) struct DeriveCli {
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
    #[command(flatten)]
    environment: EnvCli,
}

impl DeriveCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let DeriveCli {
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
            environment,
        } = self;
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
            environment: environment.options(),
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
}
