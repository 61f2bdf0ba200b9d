//! `subgram mesh info` and `mesh convert`: their arguments, and what they print.

use clap::Subcommand;
use subgram::command;
use subgram::Error;

use super::args::{parse_timeout, Format, Timeout};
use super::print::{print_out, print_warnings};

#[derive(clap::Args)]
pub(super) struct MeshCli {
    #[command(subcommand)]
    command: MeshCommand,
}

#[derive(Subcommand)]
enum MeshCommand {
    /// Counts, boundary loops, Euler characteristic, genus, valences, levels.
    Info(MeshInfoCli),
    /// Check a mesh and write it in another format (.obj, .off, .ply).
    Convert(MeshConvertCli),
}

impl MeshCli {
    pub(super) fn run(self) -> Result<(), Error> {
        match self.command {
            MeshCommand::Info(cli) => cli.run(),
            MeshCommand::Convert(cli) => cli.run(),
        }
    }
}

#[derive(clap::Args)]
pub(super) struct MeshInfoCli {
    file: String,
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
    /// Stop with an error after this many seconds (0: no limit).
    #[arg(long, value_name = "SECONDS", value_parser = parse_timeout,
          default_value_t = Timeout(Some(subgram::DEFAULT_TIMEOUT)))]
    timeout: Timeout,
}

impl MeshInfoCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let MeshInfoCli {
            file,
            format,
            timeout,
        } = self;
        subgram::within(timeout.0, || {
            print_out(&command::mesh_info(&file, matches!(format, Format::Json))?)
        })
    }
}

#[derive(clap::Args)]
pub(super) struct MeshConvertCli {
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
}

impl MeshConvertCli {
    pub(super) fn run(self) -> Result<(), Error> {
        let MeshConvertCli {
            input,
            output,
            triangles,
            force,
            timeout,
        } = self;
        subgram::within(timeout.0, || {
            print_warnings(&command::mesh_convert(&input, &output, triangles, force)?);
            Ok(())
        })
    }
}
