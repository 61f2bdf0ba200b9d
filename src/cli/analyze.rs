//! `subgram analyze`: its arguments, and the report printed.

use subgram::command;
use subgram::Error;

use super::args::{parse_timeout, Format, Timeout};
use super::print::{print_out, with_progress};

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
    /// Measure a surface grammar at these valences only (3 to 12, e.g.
    /// 3,4,12; default: all of them).
    #[arg(long, value_name = "N,N,...", value_parser = parse_valences)]
    valences: Option<Valences>,
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
            valences,
            timeout,
        } = self;
        subgram::within(timeout.0, || {
            let args = command::AnalyzeArgs {
                file,
                json: matches!(format, Format::Json),
                defines: define,
                picture,
                valences: valences.map(|v| v.0),
            };
            print_out(&with_progress(|p| command::analyze_reporting(&args, p))?)
        })
    }
}

/// The valences of `--valences`.
#[derive(Clone, Debug)]
struct Valences(Vec<usize>);

/// `3,4,12`: valences from 3 to 12, each once, in any order.
fn parse_valences(s: &str) -> Result<Valences, String> {
    let range = subgram::analyze::surface::VALENCES;
    let (lo, hi) = (range.start(), range.end());
    let mut out = Vec::new();
    for part in s.split(',') {
        let n: usize = part.trim().parse().map_err(|_| {
            format!(
                "expected valences from {lo} to {hi} separated by commas (3,4,12), not `{part}`"
            )
        })?;
        if !range.contains(&n) {
            return Err(format!("valence {n} is outside {lo} to {hi}"));
        }
        if !out.contains(&n) {
            out.push(n);
        }
    }
    Ok(Valences(out))
}
