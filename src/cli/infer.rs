//! `subgram infer`: its arguments, and the program printed.

use subgram::command;
use subgram::Error;

use super::args::{parse_timeout, Timeout};
use super::print::print_out;

#[derive(clap::Args)]
pub(super) struct InferCli {
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
}

impl InferCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let InferCli {
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
        } = self;
        subgram::within(timeout.0, || {
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
        })
    }
}
