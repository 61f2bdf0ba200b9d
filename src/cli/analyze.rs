//! `subgram analyze`: its arguments, and the report printed.

use subgram::command;
use subgram::Error;

use super::args::{parse_timeout, Format, Timeout};
use super::print::print_out;

#[derive(clap::Args)]
pub(super) struct AnalyzeCli {
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
}

impl AnalyzeCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let AnalyzeCli {
            file,
            format,
            define,
            picture,
            timeout,
        } = self;
        subgram::within(timeout.0, || {
            print_out(&command::analyze(&command::AnalyzeArgs {
                file,
                json: matches!(format, Format::Json),
                defines: define,
                picture,
            })?)
        })
    }
}
