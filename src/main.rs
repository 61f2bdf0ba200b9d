//! The `subgram` command line: parses arguments, calls one library function
//! per command ([`subgram::command`]), prints what it returns, and maps errors
//! to exit codes (1 for a problem with the input, 2 for a usage error).
//!
//! Each command's arguments and the code that runs it are in the
//! binary's own modules under `src/cli/` (see `cli/mod.rs`).

mod cli;

use std::process::ExitCode;

use clap::Parser;

use subgram::Error;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    // Deep but legal programs recurse deeply in the checker and the
    // interpreter: give them a large stack rather than a crash.
    let worker = std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || cli::run(cli));
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
