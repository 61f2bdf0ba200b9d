//! `subgram check`: its arguments, and the diagnostics printed.

use subgram::command;
use subgram::Error;

use super::args::{parse_timeout, Timeout};
use super::print::print_out;

#[derive(clap::Args)]
pub(super) struct CheckCli {
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
}

impl CheckCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let CheckCli {
            file,
            define,
            double,
            timeout,
        } = self;
        subgram::within(timeout.0, || {
            print_out(&command::check(&file, &define, double)?)
        })
    }
}
