//! The `liemesh` command line (in the library so that it can be tested like any other code).
//!
//! Exit codes: 0 success, 1 a check failed (e.g. an audit row), 2 bad input or an error
//! (the message on standard error says what was wrong and what to do).

mod audit;
mod batch;
mod bench;
mod mesh;
mod paper;
mod quality;
mod render;

use clap::{Parser, Subcommand};
use std::process::ExitCode;
use thiserror::Error;

pub use bench::{
    fidelity_scan, workload_params, FidelityScan, FIDELITY_CLOSER_GAP, FIDELITY_LIMIT_DEG,
    FIDELITY_MAX_TRIANGLES,
};
pub use mesh::{mesh_invariant, MeshArgs, MeshOutcome};

/// Adaptive meshes of surfaces defined by Lie-algebra invariants.
#[derive(Debug, Parser)]
#[command(name = "liemesh", version, about, long_about = None)]
pub struct Cli {
    /// What to do; without a command, meshes the fig6 preset into `out/`.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
// Parsed once per process: the size of the `Mesh` variant does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Mesh a preset or an invariant file and write the mesh (and a report).
    Mesh(MeshArgs),
    /// Run the accuracy audits (AD prediction order, JVPs, scalar agreement) and print a table.
    Audit(audit::AuditArgs),
    /// Draw a mesh file as a wireframe picture (.png or .svg).
    Render(render::RenderArgs),
    /// Measure fig1..fig6 in both modes and print the quality table.
    Quality(quality::QualityArgs),
    /// Recover the invariant from a mesh file alone (vertex positions and face normals).
    Recover(quality::RecoverArgs),
    /// Reproduce the paper: fig1..fig6 meshes and pictures, and Table 3 side by side.
    Paper(paper::PaperArgs),
    /// Time the performance workloads (issue 6) and print a table or JSON.
    Bench(bench::BenchArgs),
    /// Mesh every invariant file of a folder (or list) in parallel: one mesh + report each.
    Batch(batch::BatchArgs),
}

/// Any error the command line reports (exit code 2).
#[derive(Debug, Error)]
pub enum CliError {
    /// Mesh generation failed.
    #[error(transparent)]
    Mesh(#[from] crate::MeshError),
    /// Reading or writing a mesh failed.
    #[error(transparent)]
    Io(#[from] crate::io::IoError),
    /// The invariant file is invalid.
    #[error(transparent)]
    InvariantFile(#[from] crate::io::invariant_file::InvariantFileError),
    /// The arguments contradict each other or name something unavailable.
    #[error("{0}")]
    Usage(String),
    /// Drawing a picture failed.
    #[error(transparent)]
    Render(#[from] crate::io::render::RenderError),
    /// Writing a report failed.
    #[error("cannot write '{path}': {source}")]
    Write {
        /// The file.
        path: std::path::PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// Parses the process arguments, runs, and turns the result into an exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("liemesh: error: {e}");
            ExitCode::from(2)
        }
    }
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> Result<ExitCode, CliError> {
    match cli.command {
        Some(Command::Mesh(args)) => mesh::run(&args),
        Some(Command::Audit(args)) => audit::run(&args),
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Quality(args)) => quality::run(&args),
        Some(Command::Recover(args)) => quality::recover_cmd(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::Batch(args)) => batch::run(&args),
        Some(Command::Paper(args)) => paper::run(&args),
        None => mesh::run(&MeshArgs::default_job()),
    }
}
