//! `subgram reverse` and `reconstruct`: their arguments, and the report printed.

use subgram::command::{self, ReverseArgs};
use subgram::Error;

use super::args::{parse_byte_size, parse_timeout, Format, Timeout};
use super::print::print_out;

#[derive(clap::Args)]
pub(super) struct ReverseCli {
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
}

impl ReverseCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let ReverseCli {
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
        } = self;
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
}

#[derive(clap::Args)]
pub(super) struct ReconstructCli {
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
}

impl ReconstructCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let ReconstructCli {
            coarse,
            details,
            output,
            level,
            scheme,
            timeout,
            force,
            max_input_size,
        } = self;
        command::reconstruct(&command::ReconstructArgs {
            coarse,
            details,
            output,
            level,
            scheme,
            timeout: timeout.0,
            force,
            max_input: max_input_size,
        })
    }
}

fn parse_phase(s: &str) -> Result<subgram::reverse::Phase, String> {
    match s {
        "auto" => Ok(subgram::reverse::Phase::Auto),
        "0" => Ok(subgram::reverse::Phase::Fixed(0)),
        "1" => Ok(subgram::reverse::Phase::Fixed(1)),
        _ => Err(format!("`{s}` is not a phase: use auto, 0 or 1")),
    }
}
