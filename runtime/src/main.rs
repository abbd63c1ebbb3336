//! `subtess`: the runtime's command line: `subtess tessellate MESH -o OUT [--rate N] [--stats]`
//! and `subtess tables info [FILE]`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use runtime::dual_grid::tessellate_uniform;
use runtime::isolate::isolate;
use runtime::mesh_output::write_obj;
use runtime::obj::read_obj;
use runtime::stencil_table::StencilTable;
use runtime::topology::Mesh;
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
    /// Tessellate a Catmull-Clark mesh (OBJ) with the dual-grid method, uniform rate.
    Tessellate {
        /// Input mesh (OBJ: triangles, quads, n-gons).
        mesh: PathBuf,
        /// Output triangle mesh (.obj).
        #[arg(short = 'o', long = "output")]
        output: PathBuf,
        /// Dual points per face side, 1..=24 (faces of the isolated mesh).
        #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=24))]
        rate: u32,
        /// A stencil table file instead of the embedded default.
        #[arg(long)]
        table: Option<PathBuf>,
        /// Print statistics as JSON on stdout.
        #[arg(long)]
        stats: bool,
    },
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
        Command::Tessellate {
            mesh,
            output,
            rate,
            table,
            stats,
        } => {
            let table = match &table {
                Some(path) => StencilTable::read(path)?,
                None => StencilTable::default_catmull_clark()?,
            };
            let obj = read_obj(&mesh)?;
            let (input, warnings) = Mesh::from_obj(&obj)?;
            for w in warnings {
                eprintln!("warning: {}: {w}", mesh.display());
            }
            let (isolated, patches, steps) = isolate(&input)?;
            let (triangles, time) = tessellate_uniform(&table, &isolated, &patches, rate)?;
            if output.extension().and_then(|e| e.to_str()) != Some("obj") {
                return Err(RuntimeError::Unsupported(format!(
                    "output format of {} (OBJ so far; PLY and glTF are next)",
                    output.display()
                )));
            }
            write_obj(&triangles, &output)?;
            if stats {
                let count = triangles.triangles.len();
                println!(
                    "{{\"triangles\":{count},\"vertices\":{},\"seconds\":{},\"triangles_per_second\":{},\"watertight\":{},\"faces\":{},\"isolation_steps\":{steps},\"rate\":{rate}}}",
                    triangles.positions.len(),
                    time.seconds,
                    count as f64 / time.seconds.max(1e-12),
                    triangles.is_watertight(),
                    isolated.faces(),
                );
            }
            Ok(())
        }
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
