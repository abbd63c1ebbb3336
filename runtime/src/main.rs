//! `subtess`: the runtime's command line. So far: `subtess tables info [FILE]`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use runtime::stencil_table::StencilTable;
use runtime::RuntimeError;

#[derive(Parser)]
#[command(
    name = "subtess",
    version,
    about = "Exact evaluation and tessellation of subdivision surfaces"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Stencil tables.
    Tables {
        #[command(subcommand)]
        command: TablesCommand,
    },
}

#[derive(Subcommand)]
enum TablesCommand {
    /// What a table holds: format, scheme, precision, coverage, size (default: the embedded one).
    Info {
        /// A table file written by `stencilgen tables`.
        file: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<(), RuntimeError> {
    match cli.command {
        Command::Tables {
            command: TablesCommand::Info { file },
        } => {
            let (name, table) = match &file {
                Some(path) => (path.display().to_string(), StencilTable::read(path)?),
                None => (
                    "(embedded default)".to_owned(),
                    StencilTable::default_catmull_clark()?,
                ),
            };
            let index = table.index();
            let weights: u64 = index
                .entries
                .iter()
                .map(|e| u64::from(e.points) * u64::from(e.width))
                .sum();
            println!("table:      {name}");
            println!(
                "format:     version {}, little-endian, checksum {:#018x} (verified)",
                index.version, index.checksum
            );
            println!("scheme:     {}", index.meta.scheme.name());
            println!(
                "boundary:   {}",
                if index.meta.corners {
                    "edge and corner (one-face vertices pinned)"
                } else {
                    "edge only"
                }
            );
            println!("precision:  {}", index.meta.precision);
            println!("covers:     {}", index.coverage());
            println!(
                "sections:   {} (primal and dual grids; positions, d/du, d/dv)",
                index.entries.len()
            );
            println!("weights:    {weights}");
            println!(
                "size:       {} bytes ({:.1} MiB)",
                table.bytes().len(),
                table.bytes().len() as f64 / (1024.0 * 1024.0)
            );
            Ok(())
        }
    }
}
